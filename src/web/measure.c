/* Web measures (what `spinneret info` reports for an orb web). Threads are
 * read from their tags. The hub is the particle most radius threads meet (for
 * the physical web, the centroid of the hub ring); radii are the radius
 * chains that reach it, counted as the radius springs touching the hub region.
 * Turns above and below: capture segments crossing the vertical line through
 * the hub. Mesh width: gaps between successive crossings along that line,
 * split into the inner and outer half of the capture zone. Capture area: the
 * polygon of the outermost capture crossings by angle minus the inner hole.
 * All lengths are current lengths. */
#include "web_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static spn_vec3 find_hub(spn_world *w)
{
    uint32_t np = spn_world_particle_count(w), ns = spn_world_spring_count(w);
    spn_vec3 c = spn_v3(0, 0, 0);
    int n = 0;
    for (uint32_t i = 0; i < np; i++)
        if (spn_world_particle_tag(w, i) == SPN_PARTICLE_HUB) c = spn_v3_add(c, spn_world_position(w, i)), n++;
    if (n) return spn_v3_scale(c, 1.0 / n);
    for (uint32_t s = 0; s < ns; s++) {
        spn_spring_info si = spn_world_spring(w, s);
        if (si.tag != SPN_THREAD_HUB) continue;
        c = spn_v3_add(c, spn_v3_add(spn_world_position(w, si.a), spn_world_position(w, si.b)));
        n += 2;
    }
    if (n) return spn_v3_scale(c, 1.0 / n);
    for (uint32_t i = 0; i < np; i++) c = spn_v3_add(c, spn_world_position(w, i));
    return np ? spn_v3_scale(c, 1.0 / np) : c;
}

/* Radii: radius springs with an end within the hub zone, grouped by angle. */
static int count_radii(spn_world *w, spn_vec3 hub, double zone)
{
    uint32_t ns = spn_world_spring_count(w);
    double *ang = malloc((ns ? ns : 1) * sizeof *ang);
    if (!ang) return 0;
    int n = 0;
    for (uint32_t s = 0; s < ns; s++) {
        spn_spring_info si = spn_world_spring(w, s);
        if (si.tag != SPN_THREAD_RADIUS && si.tag != SPN_THREAD_SIGNAL) continue;
        spn_vec3 a = spn_world_position(w, si.a), b = spn_world_position(w, si.b);
        double da = spn_v3_len(spn_v3_sub(a, hub)), db = spn_v3_len(spn_v3_sub(b, hub));
        spn_vec3 in = da < db ? a : b, outp = da < db ? b : a;
        double din = fmin(da, db);
        if (din > zone || fmax(da, db) <= zone) continue; /* it must cross the zone's edge outward */
        (void)in;
        ang[n++] = atan2(outp.y - hub.y, outp.x - hub.x);
    }
    qsort(ang, (size_t)n, sizeof *ang, cmp_double);
    int radii = 0;
    for (int i = 0; i < n; i++)
        if (i == 0 || ang[i] - ang[i - 1] > 1e-3) radii++;
    if (n > 1 && ang[0] + 2 * SPN_PI - ang[n - 1] <= 1e-3) radii--;
    free(ang);
    return radii;
}

/* Capture crossings of the vertical through the hub: signed y offsets. */
static int vertical_crossings(spn_world *w, spn_vec3 hub, double *ys)
{
    uint32_t ns = spn_world_spring_count(w);
    int n = 0;
    for (uint32_t s = 0; s < ns; s++) {
        spn_spring_info si = spn_world_spring(w, s);
        if (si.tag != SPN_THREAD_CAPTURE || si.broken) continue;
        spn_vec3 a = spn_world_position(w, si.a), b = spn_world_position(w, si.b);
        if ((a.x - hub.x) * (b.x - hub.x) > 0 || a.x == b.x) continue;
        double t = (hub.x - a.x) / (b.x - a.x);
        ys[n++] = a.y + t * (b.y - a.y) - hub.y;
    }
    qsort(ys, (size_t)n, sizeof *ys, cmp_double);
    return n;
}

static void mesh_widths(const double *ys, int n, spn_web_measures *m)
{
    /* Gaps between successive crossings on each side, split by distance. */
    double si = 0, so = 0;
    int ni = 0, no = 0;
    for (int side = 0; side < 2; side++) {
        double prev = NAN, lo = INFINITY, hi = 0;
        for (int i = 0; i < n; i++) {
            double d = fabs(ys[i]);
            if ((ys[i] > 0) != (side == 0)) continue;
            lo = fmin(lo, d), hi = fmax(hi, d);
        }
        double mid = (lo + hi) / 2;
        for (int k = 0; k < n; k++) {
            int i = side == 0 ? k : n - 1 - k;
            if ((ys[i] > 0) != (side == 0)) continue;
            double d = fabs(ys[i]);
            if (!isnan(prev)) {
                double g = fabs(d - prev);
                if ((d + prev) / 2 < mid) si += g, ni++;
                else so += g, no++;
            }
            prev = d;
        }
    }
    m->mesh_inner = ni ? si / ni : 0;
    m->mesh_outer = no ? so / no : 0;
}

static void capture_extent(spn_world *w, spn_vec3 hub, spn_web_measures *m)
{
    enum { BINS = 72 };
    double outer[BINS] = {0}, inner[BINS];
    for (int i = 0; i < BINS; i++) inner[i] = INFINITY;
    uint32_t ns = spn_world_spring_count(w);
    bool any = false;
    for (uint32_t s = 0; s < ns; s++) {
        spn_spring_info si = spn_world_spring(w, s);
        if (si.tag != SPN_THREAD_CAPTURE) continue;
        uint32_t ends[2] = {si.a, si.b};
        for (int e = 0; e < 2; e++) {
            spn_vec3 p = spn_v3_sub(spn_world_position(w, ends[e]), hub);
            int bin = (int)floor((atan2(p.y, p.x) + SPN_PI) / (2 * SPN_PI) * BINS) % BINS;
            double r = hypot(p.x, p.y);
            outer[bin] = fmax(outer[bin], r);
            inner[bin] = fmin(inner[bin], r);
            any = true;
        }
    }
    if (!any) return;
    double area = 0, top = 0, bottom = 0, fz = INFINITY;
    for (int i = 0; i < BINS; i++) {
        if (!isfinite(inner[i])) continue;
        area += 0.5 * (2 * SPN_PI / BINS) * (outer[i] * outer[i] - inner[i] * inner[i]);
        double a = -SPN_PI + (i + 0.5) * 2 * SPN_PI / BINS;
        top = fmax(top, outer[i] * sin(a));
        bottom = fmax(bottom, -outer[i] * sin(a));
        fz = fmin(fz, inner[i]);
    }
    m->capture_area = area;
    m->asymmetry = bottom > 0 ? top / bottom : 0;
    m->free_zone = isfinite(fz) ? fz : 0;
}

spn_status spn_web_measure(spn_world *w, spn_web_measures *m)
{
    memset(m, 0, sizeof *m);
    uint32_t np = spn_world_particle_count(w), ns = spn_world_spring_count(w);
    for (uint32_t i = 0; i < np; i++) m->total_mass += spn_world_mass(w, i);
    for (uint32_t s = 0; s < ns; s++) {
        spn_spring_info si = spn_world_spring(w, s);
        if (si.tag < SPN_WEB_KINDS) {
            m->silk_length[si.tag] += si.length;
            m->springs_per_kind[si.tag]++;
        }
        m->total_length += si.length;
    }
    m->hub = find_hub(w);
    double zone = INFINITY;
    /* The hub zone reaches the first free-zone gap: the innermost capture point. */
    for (uint32_t s = 0; s < ns; s++) {
        spn_spring_info si = spn_world_spring(w, s);
        if (si.tag == SPN_THREAD_CAPTURE)
            zone = fmin(zone, spn_v3_len(spn_v3_sub(spn_world_position(w, si.a), m->hub)));
    }
    if (!isfinite(zone)) zone = 0.02;
    m->radii = count_radii(w, m->hub, zone * 0.98);
    double *ys = malloc((ns ? ns : 1) * sizeof *ys);
    if (!ys) return spn_error(SPN_ERR_NOMEM, "out of memory");
    int n = vertical_crossings(w, m->hub, ys);
    for (int i = 0; i < n; i++) m->turns_above += ys[i] > 0, m->turns_below += ys[i] < 0;
    mesh_widths(ys, n, m);
    free(ys);
    capture_extent(w, m->hub, m);
    /* The free zone is the gap between the hub (its mesh or ring) and the
     * innermost capture turn, not the distance from the hub's centre. */
    double hub_reach = 0;
    for (uint32_t s = 0; s < ns; s++) {
        spn_spring_info si = spn_world_spring(w, s);
        if (si.tag != SPN_THREAD_HUB) continue;
        hub_reach = fmax(hub_reach, fmax(spn_v3_len(spn_v3_sub(spn_world_position(w, si.a), m->hub)),
                                         spn_v3_len(spn_v3_sub(spn_world_position(w, si.b), m->hub))));
    }
    if (m->free_zone > 0) m->free_zone = fmax(0, m->free_zone - hub_reach);
    m->max_residual = np ? spn_world_max_residual(w, NULL) : 0;
    return SPN_OK;
}

spn_status spn_web_measures_write(const spn_web_measures *m, bool json, spn_sink *k)
{
    spn_status st = SPN_OK;
    if (json) {
        st = spn_sink_printf(k,
                             "{\"radii\": %d, \"turns_above\": %d, \"turns_below\": %d, \"mesh_inner\": %.6g, "
                             "\"mesh_outer\": %.6g, \"hub\": [%.6g, %.6g, %.6g], \"asymmetry\": %.4g, "
                             "\"capture_area\": %.6g, \"free_zone\": %.6g, \"total_length\": %.6g, "
                             "\"total_mass\": %.6g, \"max_residual\": %.6g, \"silk_length\": {",
                             m->radii, m->turns_above, m->turns_below, m->mesh_inner, m->mesh_outer, m->hub.x, m->hub.y,
                             m->hub.z, m->asymmetry, m->capture_area, m->free_zone, m->total_length, m->total_mass,
                             m->max_residual);
        int first = 1;
        for (int t = 0; t < SPN_WEB_KINDS && st == SPN_OK; t++) {
            if (!m->springs_per_kind[t]) continue;
            st = spn_sink_printf(k, "%s\"%s\": %.6g", first ? "" : ", ", spn_thread_kind_name((uint32_t)t), m->silk_length[t]);
            first = 0;
        }
        return st == SPN_OK ? spn_sink_printf(k, "}}") : st;
    }
    st = spn_sink_printf(k,
                         "radii          %d\nturns          %d above the hub, %d below\n"
                         "mesh width     %.3g mm inner, %.3g mm outer\nhub            (%.4g, %.4g) m\n"
                         "asymmetry      %.3g (hub-to-top / hub-to-bottom)\ncapture area   %.4g m^2\n"
                         "free zone      %.3g mm\ntotal mass     %.4g mg\nlargest residual %.3g N\n",
                         m->radii, m->turns_above, m->turns_below, m->mesh_inner * 1e3, m->mesh_outer * 1e3, m->hub.x,
                         m->hub.y, m->asymmetry, m->capture_area, m->free_zone * 1e3, m->total_mass * 1e6,
                         m->max_residual);
    for (int t = 0; t < SPN_WEB_KINDS && st == SPN_OK; t++)
        if (m->springs_per_kind[t])
            st = spn_sink_printf(k, "silk %-9s %.4g m in %u springs\n", spn_thread_kind_name((uint32_t)t), m->silk_length[t],
                                 m->springs_per_kind[t]);
    return st;
}
