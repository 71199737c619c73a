/* A species web. The frame comes from the geometric construction (Japanese
 * thesis, eqs. 3.1-3.16); the rest follows how orb weavers build
 * (Zschokke 2002; Mehla 2005 ch. 3):
 *   - the hub sits above the frame's centre by hub_offset of its height, so
 *     the web is larger below the hub than above;
 *   - radii leave the hub at evenly spread angles (jittered) and end on the
 *     frame, splitting frame and arch threads where they meet them;
 *   - a tight hub spiral inside hub_radius, then the free zone (radii only);
 *   - an auxiliary spiral laid from the hub outward, removed as the capture
 *     spiral goes in (kept only on request);
 *   - the capture spiral from the frame inward: its gap grows from
 *     mesh_inner at the free zone to mesh_outer at the edge; where a radius is
 *     too short for the current turn the thread does not reach it, so above
 *     the hub there are fewer turns and below it partial turns that turn back
 *     (Zschokke 2011);
 *   - Zygiella: two open sectors round a signal thread running from the hub
 *     through the frame to a retreat; Argiope: a zig-zag stabilimentum above
 *     and below the hub.
 * Invariants: every point on a radius is ordered by distance from the hub;
 * capture segments join neighbouring radii at decreasing distance, so no two
 * of them cross. */
#include "geometric_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define MAX_RADII 256

typedef struct hit {
    int line, seg; /* boundary line (0 .. 2n-1: arch i = 2i, side i = 2i + 1) and segment */
    double tau;
    uint32_t id;
} hit;

typedef struct on_radius {
    double rho;
    uint32_t id;
} on_radius;

typedef struct sweb {
    const spn_species_def *d;
    spn_rng rng;
    spn__geo_frame f;
    spn__layout l;
    spn_vec3 hub;
    int nr;
    double angle[MAX_RADII], len[MAX_RADII];
    spn_vec3 dir[MAX_RADII];
    hit hits[MAX_RADII];
    on_radius *on[MAX_RADII];
    int non[MAX_RADII], capon[MAX_RADII];
    int signal; /* radius replaced by the signal thread, or -1 */
} sweb;

static const spn_vec3 *line_points(const sweb *w, int line, int *count)
{
    int i = line / 2;
    *count = line % 2 ? w->f.ns[i] : w->f.na[i];
    return line % 2 ? w->f.side[i] : w->f.arch[i];
}

/* Ray from the hub at `dir` against the boundary (arches and sides). */
static bool cast(const sweb *w, spn_vec3 dir, hit *h, double *dist)
{
    double best = INFINITY;
    for (int line = 0; line < 2 * w->f.n; line++) {
        int c;
        const spn_vec3 *p = line_points(w, line, &c);
        for (int s = 0; s + 1 < c; s++) {
            spn_vec3 e = spn_v3_sub(p[s + 1], p[s]), o = spn_v3_sub(p[s], w->hub);
            double den = dir.x * e.y - dir.y * e.x;
            if (fabs(den) < 1e-15) continue;
            double t = (o.x * e.y - o.y * e.x) / den, u = (o.x * dir.y - o.y * dir.x) / den;
            if (t > 0 && u >= 0 && u <= 1 && t < best) {
                best = t;
                h->line = line, h->seg = s, h->tau = u;
            }
        }
    }
    *dist = best;
    return isfinite(best);
}

static void add_on(sweb *w, int r, double rho, uint32_t id)
{
    on_radius *p = realloc(w->on[r], ((size_t)w->non[r] + 1) * sizeof *p);
    if (!p) {
        w->l.failed = true;
        return;
    }
    w->on[r] = p;
    p[w->non[r]].rho = rho;
    p[w->non[r]++].id = id;
}

static uint32_t point_on(sweb *w, int r, double rho, uint32_t tag)
{
    /* Threads meeting a radius almost at one place share the junction: a
     * segment of a few micrometres of dragline would be stiffer than the rest
     * of the web by orders of magnitude and stall any solver. */
    for (int k = 0; k < w->non[r]; k++)
        if (fabs(w->on[r][k].rho - rho) < 0.25 * w->d->mesh_inner) return w->on[r][k].id;
    uint32_t id = spn__lay_point(&w->l, spn_v3_add(w->hub, spn_v3_scale(w->dir[r], rho)), tag, false);
    add_on(w, r, rho, id);
    return id;
}

static void place_radii(sweb *w)
{
    const spn_species_def *d = w->d;
    int nr = d->radii + (int)lround(spn_rng_normal(&w->rng) * 0.04 * d->radii);
    int lo = (int)floor(d->radii * 0.88), hi = (int)ceil(d->radii * 1.12);
    w->nr = nr < lo ? lo : nr > hi ? hi : nr;
    if (w->nr > MAX_RADII) w->nr = MAX_RADII;
    double a0 = spn_rng_uniform(&w->rng) * 2 * SPN_PI, step = 2 * SPN_PI / w->nr;
    for (int r = 0; r < w->nr; r++) {
        w->angle[r] = a0 + step * (r + 0.25 * d->jitter / 0.08 * spn_rng_range(&w->rng, -0.5, 0.5));
        w->dir[r] = spn_v3(cos(w->angle[r]), sin(w->angle[r]), 0);
    }
}

static void lay_frame_lines(sweb *w)
{
    int n = w->f.n;
    uint32_t pp[SPN_WEB_MAX_ANCHORS];
    for (int i = 0; i < n; i++) {
        uint32_t a[2] = {spn__lay_point(&w->l, w->f.p[i], SPN_PARTICLE_ANCHOR, true),
                         spn__lay_point(&w->l, w->f.pp[i], SPN_PARTICLE_FRAME, false)};
        pp[i] = a[1];
        spn__lay_line(&w->l, a, 2, SPN_THREAD_ANCHOR, SPN_STAGE_FRAME);
    }
    /* Boundary vertices are shared: arch i ends where side i starts, and so on. */
    uint32_t corner_in[SPN_WEB_MAX_ANCHORS], corner_out[SPN_WEB_MAX_ANCHORS];
    for (int i = 0; i < n; i++) {
        corner_out[i] = spn__lay_point(&w->l, w->f.side[i][0], SPN_PARTICLE_FRAME, false);
        corner_in[(i + 1) % n] = spn__lay_point(&w->l, w->f.side[i][w->f.ns[i] - 1], SPN_PARTICLE_FRAME, false);
    }
    for (int line = 0; line < 2 * n; line++) {
        int i = line / 2, c;
        const spn_vec3 *p = line_points(w, line, &c);
        uint32_t *ids = malloc(((size_t)c + 2 + (size_t)w->nr) * sizeof *ids);
        if (!ids) {
            w->l.failed = true;
            return;
        }
        size_t k = 0;
        if (line % 2) ids[k++] = pp[i];
        for (int s = 0; s < c; s++) {
            if (s == 0) ids[k++] = line % 2 ? corner_out[i] : corner_in[i];
            else if (s == c - 1) ids[k++] = line % 2 ? corner_in[(i + 1) % n] : corner_out[i];
            else ids[k++] = spn__lay_point(&w->l, p[s], SPN_PARTICLE_FRAME, false);
            if (s == c - 1) break;
            /* Radius ends on this segment, in order along it. */
            for (;;) {
                int best = -1;
                for (int r = 0; r < w->nr; r++)
                    if (w->hits[r].line == line && w->hits[r].seg == s && w->hits[r].id == UINT32_MAX &&
                        (best < 0 || w->hits[r].tau < w->hits[best].tau))
                        best = r;
                if (best < 0) break;
                w->hits[best].id = spn__lay_point(&w->l, spn__lerp(p[s], p[s + 1], w->hits[best].tau), SPN_PARTICLE_FRAME, false);
                ids[k++] = w->hits[best].id;
            }
        }
        if (line % 2) ids[k++] = pp[(i + 1) % n];
        spn__lay_line(&w->l, ids, k, SPN_THREAD_FRAME, SPN_STAGE_FRAME);
        free(ids);
    }
}

/* A spiral as a sequence of crossings on consecutive radii, rho falling by
 * gap(rho) per turn; runs of crossings that exist become threads. */
typedef double (*gap_fn)(const sweb *w, double rho);

static double capture_gap(const sweb *w, double rho)
{
    const spn_species_def *d = w->d;
    double inner = d->hub_radius + d->free_zone, outer = 0;
    for (int r = 0; r < w->nr; r++) outer = fmax(outer, w->len[r]);
    double u = (rho - inner) / fmax(outer - inner, 1e-9);
    return d->mesh_inner + (d->mesh_outer - d->mesh_inner) * fmin(fmax(u, 0), 1);
}

static bool open_between(const sweb *w, int r)
{
    return w->signal >= 0 && (r == w->signal || (r + 1) % w->nr == w->signal);
}

static void lay_spiral(sweb *w, double from, double to, gap_fn gap, double scale, uint32_t kind, uint32_t stage)
{
    size_t cap = 1024, n = 0;
    uint32_t *run = malloc(cap * sizeof *run);
    if (!run) {
        w->l.failed = true;
        return;
    }
    bool inward = to < from;
    /* Zygiella's open sectors are open of the spirals laid in them; the hub
     * goes round whole (the signal thread is one of its radii). */
    bool whole = kind == SPN_THREAD_HUB;
    double rho = from, turn_jitter = 1;
    for (long step = 0; !w->l.failed; step++) {
        int r = (int)(step % w->nr);
        if (r == 0) turn_jitter = 1 + w->d->jitter * spn_rng_range(&w->rng, -0.5, 0.5);
        if (inward ? rho < to : rho > to) break;
        bool fits = rho < w->len[r] - w->d->margin && (r != w->signal || whole);
        if (fits) {
            if (n == cap) {
                uint32_t *p = realloc(run, (cap *= 2) * sizeof *p);
                if (!p) break;
                run = p;
            }
            /* A little irregularity per crossing, as a spider's legs measure it;
             * well under half a gap, so turns keep their order on every radius. */
            double wobble = 0.12 * w->d->jitter / 0.08 * gap(w, rho) * spn_rng_range(&w->rng, -1, 1);
            run[n++] = point_on(w, r, rho + wobble, SPN_PARTICLE_SPIRAL);
            if (kind == SPN_THREAD_CAPTURE) w->capon[r]++;
        }
        if (!fits || (!whole && open_between(w, r))) {
            spn__lay_line(&w->l, run, n, kind, stage);
            n = 0;
        }
        double g = gap(w, rho) * scale * turn_jitter / w->nr;
        rho += inward ? -g : g;
    }
    spn__lay_line(&w->l, run, n, kind, stage);
    free(run);
}

static double hub_gap(const sweb *w, double rho)
{
    (void)rho;
    return w->d->hub_radius / (w->d->species == SPN_SPECIES_ZILLA ? 12 : 5);
}

static double aux_gap(const sweb *w, double rho) { return 4 * capture_gap(w, rho); }

static void lay_radius_lines(sweb *w)
{
    uint32_t hub = spn__lay_point(&w->l, w->hub, SPN_PARTICLE_HUB, false);
    for (int r = 0; r < w->nr && !w->l.failed; r++) {
        /* Order the points on this radius from the hub outward. */
        for (int a = 1; a < w->non[r]; a++)
            for (int b = a; b > 0 && w->on[r][b].rho < w->on[r][b - 1].rho; b--) {
                on_radius t = w->on[r][b];
                w->on[r][b] = w->on[r][b - 1];
                w->on[r][b - 1] = t;
            }
        uint32_t *ids = malloc(((size_t)w->non[r] + 3) * sizeof *ids);
        if (!ids) {
            w->l.failed = true;
            return;
        }
        size_t k = 0;
        ids[k++] = hub;
        for (int j = 0; j < w->non[r]; j++) ids[k++] = w->on[r][j].id;
        ids[k++] = w->hits[r].id;
        bool signal = r == w->signal;
        if (signal) {
            spn_vec3 retreat = spn_v3_add(w->hub, spn_v3_scale(w->dir[r], w->len[r] + 0.3 * w->d->size));
            ids[k++] = spn__lay_point(&w->l, retreat, SPN_PARTICLE_ANCHOR, true);
        }
        spn__lay_line(&w->l, ids, k, signal ? SPN_THREAD_SIGNAL : SPN_THREAD_RADIUS,
                      signal ? SPN_STAGE_DECORATION : SPN_STAGE_RADII);
        free(ids);
    }
}

/* Argiope: a zig-zag band straddling the radius nearest straight down (and up). */
static void lay_stabilimentum(sweb *w, double toward)
{
    int best = 0;
    for (int r = 1; r < w->nr; r++)
        if (cos(w->angle[r] - toward) > cos(w->angle[best] - toward)) best = r;
    int a = (best + w->nr - 1) % w->nr, b = (best + 1) % w->nr;
    double from = w->d->hub_radius * 1.2, to = fmin(w->len[a], w->len[b]) * 0.55, step = w->d->mesh_inner * 0.7;
    /* A web too small for a band beside its hub gets none (until 2026-12-05
     * the negative count went to malloc as a size, and Argiope webs under
     * 5.5 cm failed with "out of memory"). */
    if (!(to > from)) return;
    size_t n = 0, cap = (size_t)((to - from) / step) + 2;
    uint32_t *zz = malloc(cap * sizeof *zz);
    if (!zz) {
        w->l.failed = true;
        return;
    }
    for (double rho = from; rho < to && n < cap; rho += step, n++) {
        double wobble = 1 + 0.15 * spn_rng_range(&w->rng, -1, 1);
        zz[n] = point_on(w, n % 2 ? a : b, rho * wobble > from ? rho * wobble : rho, SPN_PARTICLE_GENERIC);
    }
    spn__lay_line(&w->l, zz, n, SPN_THREAD_STABILIMENTUM, SPN_STAGE_DECORATION);
    free(zz);
}

/* Frame threads pulled in by the radii curve smoothly toward the hub (the
 * contraction of the Japanese thesis, sec. 3.4): each side and arch becomes a
 * parabola whose middle has moved `contraction` of the way toward G. The
 * thesis' jittered radius ends are kept for the geometric method, where
 * radii end there; here radii end where they meet the curve. */
static void smooth_line(spn_vec3 *pts, int *count, int want, spn_vec3 g, double sag_fraction)
{
    spn_vec3 a = pts[0], b = pts[*count - 1], mid = spn__lerp(a, b, 0.5);
    spn_vec3 chord = spn_v3_norm(spn_v3_sub(b, a)), in = spn_v3_sub(g, mid);
    in = spn_v3_sub(in, spn_v3_scale(chord, spn_v3_dot(in, chord)));
    double sag = sag_fraction * spn_v3_len(in);
    in = spn_v3_norm(in);
    for (int k = 0; k < want; k++) {
        double u = (double)k / (want - 1);
        pts[k] = spn_v3_add(spn__lerp(a, b, u), spn_v3_scale(in, 4 * u * (1 - u) * sag));
    }
    *count = want;
}

static void smooth_frame(sweb *w)
{
    double m = w->d->contraction;
    for (int i = 0; i < w->f.n; i++) {
        smooth_line(w->f.side[i], &w->f.ns[i], 12, w->f.g, 0.6 * m);
        smooth_line(w->f.arch[i], &w->f.na[i], 6, w->f.g, 0.5 * m);
    }
}

static spn_status check_def(const spn_species_def *d)
{
    if (d->anchors) {
        spn_status st = spn_web_check_anchors(d->anchors, d->anchor_count);
        if (st != SPN_OK) return st;
    } else if (!(d->size > 0.01 && d->size < 10)) return spn_error(SPN_ERR_INVALID, "size must be in (0.01, 10) m");
    if (d->radii < 6 || d->radii > 200) return spn_error(SPN_ERR_INVALID, "radii must be in [6, 200]");
    if (!(d->mesh_inner > 0 && d->mesh_outer >= d->mesh_inner))
        return spn_error(SPN_ERR_INVALID, "mesh widths must be positive, outer not below inner");
    if (!(d->hub_radius > 0 && d->free_zone >= 0 && d->margin >= 0))
        return spn_error(SPN_ERR_INVALID, "hub_radius must be positive, free_zone and margin not negative");
    if (!(d->hub_offset >= -0.3 && d->hub_offset <= 0.3)) return spn_error(SPN_ERR_INVALID, "hub_offset must be in [-0.3, 0.3]");
    if (!(d->contraction >= 0 && d->contraction <= 0.6)) return spn_error(SPN_ERR_INVALID, "contraction must be in [0, 0.6]");
    if (!(d->segment > 0)) return spn_error(SPN_ERR_INVALID, "segment must be positive");
    return spn__web_check_strains(&d->strains);
}

static void weave(sweb *w)
{
    const spn_species_def *d = w->d;
    /* Hub above the frame's centre. */
    double ymin = INFINITY, ymax = -INFINITY;
    for (int i = 0; i < w->f.n; i++) ymin = fmin(ymin, w->f.pp[i].y), ymax = fmax(ymax, w->f.pp[i].y);
    w->hub = spn_v3_add(w->f.g, spn_v3(0, (d->hub_offset + d->jitter * 0.3 * spn_rng_range(&w->rng, -1, 1) * d->hub_offset) * (ymax - ymin), 0));
    place_radii(w);
    w->signal = -1;
    for (int r = 0; r < w->nr; r++) {
        if (!cast(w, w->dir[r], &w->hits[r], &w->len[r])) {
            w->l.failed = true;
            return;
        }
        w->hits[r].id = UINT32_MAX;
        if (d->open_sector > 0 && (w->signal < 0 || cos(w->angle[r] - d->open_sector_angle) >
                                                         cos(w->angle[w->signal] - d->open_sector_angle)))
            w->signal = r;
    }
    lay_frame_lines(w);
    double inner = d->hub_radius + d->free_zone, outer = 0;
    for (int r = 0; r < w->nr; r++) outer = fmax(outer, w->len[r]);
    /* Lines may be added out of building order: the weaver lays them by stage. */
    lay_spiral(w, d->hub_radius * 0.3, d->hub_radius, hub_gap, 1, SPN_THREAD_HUB, SPN_STAGE_RADII);
    if (d->aux_spiral) lay_spiral(w, inner, outer, aux_gap, 1, SPN_THREAD_AUX_SPIRAL, SPN_STAGE_AUX_SPIRAL);
    lay_spiral(w, outer - d->margin, inner, capture_gap, 1, SPN_THREAD_CAPTURE, SPN_STAGE_CAPTURE);
    if (d->stabilimentum) {
        lay_stabilimentum(w, -SPN_PI / 2);
        lay_stabilimentum(w, SPN_PI / 2);
    }
    lay_radius_lines(w);
}

spn_status spn_web_build_species(const spn_species_def *def, spn_world **out)
{
    *out = NULL;
    spn_status st = check_def(def);
    if (st != SPN_OK) return st;
    sweb *w = calloc(1, sizeof *w);
    if (!w) return spn_error(SPN_ERR_NOMEM, "out of memory");
    w->d = def;
    /* Each species draws its own site and variation from the same seed. */
    spn_rng_seed(&w->rng, def->seed * 0x9E3779B97F4A7C15ull + (uint64_t)def->species);
    spn_vec3 site[8];
    const spn_vec3 *anchors = def->anchors;
    int count = def->anchor_count;
    if (!anchors) {
        count = 4 + (int)spn_rng_below(&w->rng, 3);
        double squash = def->species == SPN_SPECIES_ZILLA ? 1.0 : 1.1;
        spn__site_anchors(&w->rng, count, def->size, def->size * squash, site);
        anchors = site;
    }
    spn__geo_params gp = {0.15, 0.28, 0.3, 0.7, def->contraction, 3, 8};
    spn__geo_frame_make(anchors, count, &gp, &w->rng, &w->f);
    smooth_frame(w);
    weave(w);
    double pre[SPN_WEB_KINDS];
    spn__web_prestrains(&def->strains, pre);
    spn__weaver wv;
    spn_world_def wd = def->world;
    wd.seed = def->seed;
    if (spn__weaver_init(&wv, &wd, &def->materials) == SPN_OK)
        spn__layout_weave(&w->l, &wv, def->segment, pre, def->keep_aux_spiral);
    spn__meta m;
    spn__meta_begin(&m, "species", def->seed, anchors, count);
    spn__meta_str(&m, "species", spn_species_name(def->species));
    spn__meta_materials(&m, &def->materials);
    spn__meta_num(&m, "radii", w->nr);
    spn__meta_num(&m, "hub_x", w->hub.x);
    spn__meta_num(&m, "hub_y", w->hub.y);
    spn__meta_num(&m, "hub_radius", def->hub_radius);
    spn__meta_num(&m, "free_zone", def->free_zone);
    spn__meta_num(&m, "mesh_inner", def->mesh_inner);
    spn__meta_num(&m, "mesh_outer", def->mesh_outer);
    spn__meta_num(&m, "hub_offset", def->hub_offset);
    spn__meta_num(&m, "contraction", def->contraction);
    spn__meta_num(&m, "aux_spiral", def->aux_spiral);
    spn__meta_num(&m, "open_sector", def->open_sector);
    spn__meta_num(&m, "stabilimentum", def->stabilimentum);
    spn__meta_num(&m, "jitter", def->jitter);
    st = spn__woven_finish(&wv, &m, &def->strains, def->form_find, out);
    spn__meta_free(&m);
    for (int r = 0; r < MAX_RADII; r++) free(w->on[r]);
    spn__layout_free(&w->l);
    free(w);
    return st;
}
