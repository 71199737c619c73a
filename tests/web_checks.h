/* Structural checks of built webs shared by the web tests. */
#ifndef SPN_TEST_WEB_CHECKS_H
#define SPN_TEST_WEB_CHECKS_H

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <spinneret/spinneret.h>

/* Every particle reaches a fixed particle through intact springs. */
static inline bool web_all_anchored(const spn_world *w)
{
    uint32_t np = spn_world_particle_count(w), ns = spn_world_spring_count(w);
    bool *seen = calloc(np, 1);
    uint32_t *stack = malloc(np * sizeof *stack), top = 0;
    for (uint32_t i = 0; i < np; i++)
        if (spn_world_is_fixed(w, i)) seen[i] = true, stack[top++] = i;
    /* Repeated sweeps: simple and fine for test sizes. */
    bool changed = true;
    while (changed) {
        changed = false;
        for (uint32_t s = 0; s < ns; s++) {
            spn_spring_info si = spn_world_spring(w, s);
            if (si.broken) continue;
            if (seen[si.a] != seen[si.b]) seen[si.a] = seen[si.b] = true, changed = true;
        }
    }
    bool all = true;
    for (uint32_t i = 0; i < np; i++) all &= seen[i];
    free(seen);
    free(stack);
    return all;
}

static inline bool seg_cross(spn_vec3 a, spn_vec3 b, spn_vec3 c, spn_vec3 d)
{
    double d1 = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
    double d2 = (b.x - a.x) * (d.y - a.y) - (b.y - a.y) * (d.x - a.x);
    double d3 = (d.x - c.x) * (a.y - c.y) - (d.y - c.y) * (a.x - c.x);
    double d4 = (d.x - c.x) * (b.y - c.y) - (d.y - c.y) * (b.x - c.x);
    return ((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0));
}

/* Pairs of springs of kind `ka` and kind `kb` that cross away from their
 * ends. Springs of kind kb are binned on a grid so the check stays linear. */
static inline int web_crossings(const spn_world *w, uint32_t ka, uint32_t kb)
{
    enum { G = 64 };
    uint32_t ns = spn_world_spring_count(w);
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (uint32_t i = 0; i < spn_world_particle_count(w); i++) {
        spn_vec3 p = spn_world_position(w, i);
        lo[0] = fmin(lo[0], p.x), lo[1] = fmin(lo[1], p.y), hi[0] = fmax(hi[0], p.x), hi[1] = fmax(hi[1], p.y);
    }
    double cw = (hi[0] - lo[0]) / G + 1e-12, ch = (hi[1] - lo[1]) / G + 1e-12;
    uint32_t *count = calloc(G * G + 1, sizeof *count), *start, *items;
#define CELLS(S, ...)                                                                                    \
    do {                                                                                                 \
        spn_vec3 pa_ = spn_world_position(w, (S).a), pb_ = spn_world_position(w, (S).b);                \
        int x0 = (int)((fmin(pa_.x, pb_.x) - lo[0]) / cw), x1 = (int)((fmax(pa_.x, pb_.x) - lo[0]) / cw); \
        int y0 = (int)((fmin(pa_.y, pb_.y) - lo[1]) / ch), y1 = (int)((fmax(pa_.y, pb_.y) - lo[1]) / ch); \
        if (x1 >= G) x1 = G - 1;                                                                         \
        if (y1 >= G) y1 = G - 1;                                                                         \
        for (int cy = y0; cy <= y1; cy++)                                                                \
            for (int cx = x0; cx <= x1; cx++) {                                                          \
                int cell = cy * G + cx;                                                                  \
                __VA_ARGS__;                                                                              \
            }                                                                                            \
    } while (0)
    for (uint32_t s = 0; s < ns; s++) {
        spn_spring_info si = spn_world_spring(w, s);
        if (si.tag == kb) CELLS(si, count[cell + 1]++);
    }
    for (int c = 0; c < G * G; c++) count[c + 1] += count[c];
    start = malloc((G * G + 1) * sizeof *start);
    memcpy(start, count, (G * G + 1) * sizeof *start);
    items = malloc((count[G * G] + 1) * sizeof *items);
    for (uint32_t s = 0; s < ns; s++) {
        spn_spring_info si = spn_world_spring(w, s);
        if (si.tag == kb) CELLS(si, items[start[cell]++] = s);
    }
    int n = 0;
    for (uint32_t s = 0; s < ns; s++) {
        spn_spring_info p = spn_world_spring(w, s);
        if (p.tag != ka) continue;
        spn_vec3 a = spn_world_position(w, p.a), b = spn_world_position(w, p.b);
        CELLS(p, {
            for (uint32_t k = count[cell]; k < count[cell + 1]; k++) {
                uint32_t q_id = items[k];
                if (ka == kb && q_id <= s) continue;
                spn_spring_info q = spn_world_spring(w, q_id);
                if (q.a == p.a || q.a == p.b || q.b == p.a || q.b == p.b) continue;
                /* A pair sharing several cells is counted once: in the first shared cell. */
                spn_vec3 c = spn_world_position(w, q.a), d = spn_world_position(w, q.b);
                int qx = (int)((fmin(c.x, d.x) - lo[0]) / cw), qy = (int)((fmin(c.y, d.y) - lo[1]) / ch);
                int px = (int)((fmin(a.x, b.x) - lo[0]) / cw), py = (int)((fmin(a.y, b.y) - lo[1]) / ch);
                if (cx != (qx > px ? qx : px) || cy != (qy > py ? qy : py)) continue;
                if (seg_cross(a, b, c, d)) n++;
            }
        });
    }
#undef CELLS
    free(count);
    free(start);
    free(items);
    return n;
}

static inline uint32_t web_count(const spn_world *w, uint32_t kind)
{
    uint32_t n = 0, ns = spn_world_spring_count(w);
    for (uint32_t s = 0; s < ns; s++) n += spn_world_spring(w, s).tag == kind;
    return n;
}

/* Capture threads run between neighbouring radii: walk every capture chain
 * from one radius junction to the next and check that the two radii (found
 * by angle round the hub particle) are neighbours. Returns the bad pieces. */
static inline int web_capture_off_neighbours(const spn_world *w)
{
    uint32_t np = spn_world_particle_count(w), ns = spn_world_spring_count(w), hub = UINT32_MAX;
    for (uint32_t i = 0; i < np; i++)
        if (spn_world_particle_tag(w, i) == SPN_PARTICLE_HUB) hub = i;
    if (hub == UINT32_MAX) return -1;
    spn_vec3 h = spn_world_position(w, hub);
    double *ang = malloc(ns * sizeof *ang);
    int nr = 0;
    bool *on_radius = calloc(np, 1);
    int *cap_deg = calloc(np, sizeof *cap_deg);
    for (uint32_t s = 0; s < ns; s++) {
        spn_spring_info si = spn_world_spring(w, s);
        if (si.tag == SPN_THREAD_RADIUS || si.tag == SPN_THREAD_SIGNAL) {
            on_radius[si.a] = on_radius[si.b] = true;
            if (si.a == hub || si.b == hub) {
                spn_vec3 o = spn_world_position(w, si.a == hub ? si.b : si.a);
                ang[nr++] = atan2(o.y - h.y, o.x - h.x);
            }
        }
        if (si.tag == SPN_THREAD_CAPTURE) cap_deg[si.a]++, cap_deg[si.b]++;
    }
    /* Index of the radius nearest in angle. */
#define NEAREST(P, OUT)                                                                    \
    do {                                                                                   \
        spn_vec3 q_ = spn_world_position(w, (P));                                          \
        double a_ = atan2(q_.y - h.y, q_.x - h.x), best_ = 10;                             \
        for (int r_ = 0; r_ < nr; r_++) {                                                  \
            double d_ = fabs(remainder(a_ - ang[r_], 2 * SPN_PI));                         \
            if (d_ < best_) best_ = d_, (OUT) = r_;                                        \
        }                                                                                  \
    } while (0)
    /* Sort radii by angle so neighbours are adjacent indices. */
    for (int a = 1; a < nr; a++)
        for (int b = a; b > 0 && ang[b] < ang[b - 1]; b--) {
            double t = ang[b];
            ang[b] = ang[b - 1], ang[b - 1] = t;
        }
    int bad = 0;
    for (uint32_t s = 0; s < ns; s++) {
        spn_spring_info si = spn_world_spring(w, s);
        if (si.tag != SPN_THREAD_CAPTURE || !on_radius[si.a]) continue;
        /* Walk from the junction si.a through si.b until the next junction. */
        uint32_t prev = si.a, cur = si.b;
        int guard = 0;
        while (!on_radius[cur] && guard++ < 1000) {
            uint32_t next = UINT32_MAX;
            for (uint32_t t = 0; t < ns && next == UINT32_MAX; t++) {
                spn_spring_info ti = spn_world_spring(w, t);
                if (ti.tag != SPN_THREAD_CAPTURE) continue;
                if (ti.a == cur && ti.b != prev) next = ti.b;
                else if (ti.b == cur && ti.a != prev) next = ti.a;
            }
            if (next == UINT32_MAX) break;
            prev = cur, cur = next;
        }
        if (!on_radius[cur]) {
            bad++;
            continue;
        }
        int ra = 0, rb = 0;
        NEAREST(si.a, ra);
        NEAREST(cur, rb);
        int d = abs(ra - rb);
        if (d != 1 && d != nr - 1) bad++;
    }
#undef NEAREST
    free(ang);
    free(on_radius);
    free(cap_deg);
    return bad;
}

/* Mehla's physical web 30 cm across, with the thesis' threads or (silk) with
 * silk laid at a silk web's pre-strains, as `spinneret build --method physical
 * --preset silk` lays it. */
static inline spn_physical_def web_physical_30cm(bool silk)
{
    static const spn_vec3 an[4] = {{-0.14, 0.15, 0}, {0.15, 0.13, 0}, {0.13, -0.15, 0}, {-0.15, -0.12, 0}};
    spn_physical_def d = spn_physical_def_default();
    d.anchors = an;
    d.anchor_count = 4;
    d.move_outer = 0.02;
    if (silk) {
        d.materials = spn_web_materials_preset(SPN_MATERIAL_SILK);
        d.outer_rest = d.outer_placement / 1.10;
        d.frame_rest = d.frame_placement / 1.08;
        d.spoke_rest = d.spoke_placement / 1.02;
        d.spiral_extension = 0.3;
    }
    return d;
}

/* A woven web as designed, laid at the strains silk webs were laid at until
 * the thirty-sixth session (radii 2%, capture 30%, frame 8%, moorings 20%),
 * without the form finding: the web every species build gave before, far
 * from rest, for the tests of the solve and of the stepped settle (form
 * finding leaves a web at rest as built). */
static inline void web_as_designed(spn_web_strains *strains, bool *form_find)
{
    strains->radii = 0.02, strains->capture = 0.3, strains->frame = 0.08, strains->anchor = 0.2;
    *form_find = false;
}

#endif
