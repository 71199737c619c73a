/* The weaver and the layout: how every builder turns threads into springs.
 * Thread material follows DESIGN: a segment of rest length r gets k = EA / r,
 * its mass (linear density * r) is shared by its two ends, and its damping is
 * a fraction of critical for that segment, so dividing a thread more finely
 * does not change how it behaves. Every spring carries its thread kind (tag),
 * construction stage and a running construction order.
 * Invariant: the first failure sticks in wv->st and later calls do nothing. */
#include "web_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

spn_status spn__weaver_init(spn__weaver *wv, const spn_world_def *def, const spn_web_materials *mat)
{
    memset(wv, 0, sizeof *wv);
    wv->mat = *mat;
    wv->w = spn_world_create(def);
    wv->st = wv->w ? SPN_OK : spn_error(SPN_ERR_NOMEM, "out of memory");
    return wv->st;
}

static bool grow_mass(spn__weaver *wv, uint32_t id)
{
    if (id < wv->mass_cap) return true;
    size_t cap = wv->mass_cap ? wv->mass_cap : 1024;
    while (cap <= id) cap *= 2;
    double *p = realloc(wv->mass, cap * sizeof *p);
    if (!p) {
        wv->st = spn_error(SPN_ERR_NOMEM, "out of memory");
        return false;
    }
    memset(p + wv->mass_cap, 0, (cap - wv->mass_cap) * sizeof *p);
    wv->mass = p;
    wv->mass_cap = cap;
    return true;
}

uint32_t spn__particle(spn__weaver *wv, spn_vec3 p, bool fixed, uint32_t tag)
{
    if (wv->st != SPN_OK) return 0;
    spn_particle_def d = spn_particle_def_default();
    d.position = p;
    d.fixed = fixed;
    d.mass = 1; /* replaced at finish; 0 would mean fixed */
    d.tag = tag;
    uint32_t id = 0;
    wv->st = spn_world_add_particle(wv->w, &d, &id);
    if (wv->st == SPN_OK) grow_mass(wv, id);
    return id;
}

uint32_t spn__spring(spn__weaver *wv, uint32_t a, uint32_t b, uint32_t kind, uint32_t stage, double rest)
{
    if (wv->st != SPN_OK) return 0;
    const spn_thread_material *m = &wv->mat.kind[kind < SPN_WEB_KINDS ? kind : 0];
    spn_spring_def s = spn_spring_def_default();
    s.a = a;
    s.b = b;
    s.rest = rest;
    s.k = m->ea / rest;
    double seg = m->linear_density * rest;
    s.kd = m->damping_ratio * 2 * sqrt(s.k * seg / 2);
    s.tension_only = true;
    s.tag = kind;
    s.stage = stage;
    s.order = wv->order++;
    uint32_t id = 0;
    wv->st = spn_world_add_spring(wv->w, &s, &id);
    if (wv->st == SPN_OK) {
        wv->mass[a] += seg / 2;
        wv->mass[b] += seg / 2;
    }
    return id;
}

spn_status spn__chain(spn__weaver *wv, uint32_t a, uint32_t b, int n, double rest, uint32_t kind, uint32_t stage,
                      uint32_t ptag, uint32_t **ids)
{
    if (wv->st != SPN_OK) return wv->st;
    if (n < 1) n = 1;
    uint32_t *out = ids ? malloc(((size_t)n + 1) * sizeof *out) : NULL;
    if (ids && !out) return wv->st = spn_error(SPN_ERR_NOMEM, "out of memory");
    spn_vec3 pa = spn_world_position(wv->w, a), pb = spn_world_position(wv->w, b);
    uint32_t prev = a;
    if (out) out[0] = a;
    for (int i = 1; i <= n && wv->st == SPN_OK; i++) {
        uint32_t cur = i == n ? b : spn__particle(wv, spn__lerp(pa, pb, (double)i / n), false, ptag);
        spn__spring(wv, prev, cur, kind, stage, rest);
        if (out) out[i] = cur;
        prev = cur;
    }
    if (ids) {
        if (wv->st == SPN_OK) *ids = out;
        else free(out);
    }
    return wv->st;
}

spn_status spn__weaver_finish(spn__weaver *wv, const char *metadata, spn_world **out)
{
    *out = NULL;
    if (wv->st != SPN_OK) {
        spn_status failed = wv->st;
        spn__weaver_abort(wv);
        return failed;
    }
    uint32_t np = spn_world_particle_count(wv->w);
    double smallest = INFINITY;
    for (uint32_t i = 0; i < np; i++)
        if (wv->mass[i] > 0 && wv->mass[i] < smallest) smallest = wv->mass[i];
    if (!isfinite(smallest)) smallest = 1e-9;
    spn_status st = SPN_OK;
    for (uint32_t i = 0; i < np && st == SPN_OK; i++) {
        bool fixed = spn_world_is_fixed(wv->w, i);
        /* A particle no spring reaches (none should remain) still needs a mass. */
        st = spn_world_set_mass(wv->w, i, wv->mass[i] > 0 ? wv->mass[i] : smallest);
        if (fixed) spn_world_set_fixed(wv->w, i, true);
    }
    if (st == SPN_OK && metadata) st = spn_world_set_metadata(wv->w, metadata);
    if (st != SPN_OK) {
        spn__weaver_abort(wv);
        return st;
    }
    free(wv->mass);
    *out = wv->w;
    memset(wv, 0, sizeof *wv);
    return SPN_OK;
}

void spn__weaver_abort(spn__weaver *wv)
{
    spn_world_destroy(wv->w);
    free(wv->mass);
    wv->w = NULL;
    wv->mass = NULL;
}

/* ---- layout ------------------------------------------------------------ */

uint32_t spn__lay_point(spn__layout *l, spn_vec3 p, uint32_t tag, bool fixed)
{
    if (l->failed) return 0;
    if (l->np == l->pcap) {
        size_t cap = l->pcap ? l->pcap * 2 : 256;
        spn_vec3 *pt = realloc(l->pt, cap * sizeof *pt);
        if (pt) l->pt = pt;
        uint32_t *tg = realloc(l->ptag, cap * sizeof *tg);
        if (tg) l->ptag = tg;
        bool *fx = realloc(l->pfixed, cap * sizeof *fx);
        if (fx) l->pfixed = fx;
        if (!pt || !tg || !fx) {
            l->failed = true;
            return 0;
        }
        l->pcap = cap;
    }
    l->pt[l->np] = p;
    l->ptag[l->np] = tag;
    l->pfixed[l->np] = fixed;
    return (uint32_t)l->np++;
}

void spn__lay_line(spn__layout *l, const uint32_t *idx, size_t n, uint32_t kind, uint32_t stage)
{
    if (l->failed || n < 2) return;
    if (l->nl == l->lcap) {
        size_t cap = l->lcap ? l->lcap * 2 : 128;
        spn__line *p = realloc(l->lines, cap * sizeof *p);
        if (!p) {
            l->failed = true;
            return;
        }
        l->lines = p;
        l->lcap = cap;
    }
    spn__line *ln = &l->lines[l->nl];
    ln->idx = malloc(n * sizeof *ln->idx);
    if (!ln->idx) {
        l->failed = true;
        return;
    }
    memcpy(ln->idx, idx, n * sizeof *idx);
    ln->n = n;
    ln->kind = kind;
    ln->stage = stage;
    l->nl++;
}

void spn__layout_free(spn__layout *l)
{
    for (size_t i = 0; i < l->nl; i++) free(l->lines[i].idx);
    free(l->lines);
    free(l->pt);
    free(l->ptag);
    free(l->pfixed);
    memset(l, 0, sizeof *l);
}

spn_status spn__layout_weave(const spn__layout *l, spn__weaver *wv, double segment,
                             const double prestrain[SPN_WEB_KINDS], bool keep_aux)
{
    if (l->failed) return wv->st = spn_error(SPN_ERR_NOMEM, "out of memory");
    /* Mooring threads are laid of several strands (Wirth & Barth 1992: they
     * carry the web's highest tensions). As one strand of the anchor
     * material (silk: 5 um) they let the frame's corners in until the radii
     * kept a tenth or less of their pretension, and the settle crawled on
     * the near-slack hub (docs/web-builders.md, "Settling": Zilla seed 6 in
     * 47 s of CPU, its hub threads at a strain of 6e-9; with four strands
     * and the mooring prestrain of spn__web_prestrains, 0.65 s). */
    spn_thread_material *mooring = &wv->mat.kind[SPN_THREAD_ANCHOR];
    mooring->ea *= SPN__MOORING_STRANDS;
    mooring->linear_density *= SPN__MOORING_STRANDS;
    mooring->diameter *= sqrt(SPN__MOORING_STRANDS);
    /* Points become particles only when a line uses them. */
    if (l->nl == 0) return wv->st;
    uint32_t *pid = malloc((l->np ? l->np : 1) * sizeof *pid);
    if (!pid) return wv->st = spn_error(SPN_ERR_NOMEM, "out of memory");
    for (size_t i = 0; i < l->np; i++) pid[i] = UINT32_MAX;
    /* By stage, as the spider builds; within the radii stage the radii before the hub spiral. */
    for (size_t pass = 0; pass < 2 * (size_t)SPN_STAGE_COUNT * l->nl && wv->st == SPN_OK; pass++) {
        size_t li = pass % l->nl, round = pass / l->nl;
        const spn__line *ln = &l->lines[li];
        bool radial = ln->kind == SPN_THREAD_RADIUS || ln->kind == SPN_THREAD_SIGNAL;
        if (ln->stage != round / 2 || radial != (round % 2 == 0)) continue;
        double pre = prestrain[ln->kind < SPN_WEB_KINDS ? ln->kind : 0];
        for (size_t j = 0; j < ln->n; j++) {
            uint32_t p = ln->idx[j];
            if (pid[p] == UINT32_MAX) pid[p] = spn__particle(wv, l->pt[p], l->pfixed[p], l->ptag[p]);
            if (j == 0) continue;
            uint32_t a = pid[ln->idx[j - 1]], b = pid[p];
            double d = spn_v3_len(spn_v3_sub(l->pt[ln->idx[j - 1]], l->pt[p]));
            if (!(d > 1e-9)) continue;
            /* The auxiliary spiral is temporary: one spring per piece, so that
             * removing it leaves no particles hanging in the air. */
            int n = ln->kind == SPN_THREAD_AUX_SPIRAL ? 1 : (int)ceil(d / segment);
            spn__chain(wv, a, b, n, d / n / (1 + pre), ln->kind, ln->stage, SPN_PARTICLE_GENERIC, NULL);
        }
    }
    free(pid);
    if (wv->st != SPN_OK || keep_aux) return wv->st;
    uint32_t ns = spn_world_spring_count(wv->w);
    bool *rm = calloc(ns ? ns : 1, sizeof *rm);
    if (!rm) return wv->st = spn_error(SPN_ERR_NOMEM, "out of memory");
    bool any = false;
    for (uint32_t s = 0; s < ns; s++) {
        rm[s] = spn_world_spring(wv->w, s).tag == SPN_THREAD_AUX_SPIRAL;
        any |= rm[s];
    }
    if (any) {
        /* The spider eats the auxiliary spiral as the capture spiral goes in:
         * its silk (mass) goes with it. */
        for (uint32_t s = 0; s < ns; s++) {
            if (!rm[s]) continue;
            spn_spring_info si = spn_world_spring(wv->w, s);
            double seg = wv->mat.kind[SPN_THREAD_AUX_SPIRAL].linear_density * si.rest;
            wv->mass[si.a] -= seg / 2;
            wv->mass[si.b] -= seg / 2;
        }
        wv->st = spn_world_remove_springs(wv->w, rm);
    }
    free(rm);
    return wv->st;
}

/* ---- metadata ------------------------------------------------------------ */

void spn__meta_begin(spn__meta *m, const char *builder, uint64_t seed, const spn_vec3 *anchors, int count)
{
    memset(m, 0, sizeof *m);
    m->sink = spn_sink_buffer(&m->buf);
    spn_sink_printf(&m->sink, "{\"builder\": \"%s\", \"seed\": %llu, \"anchors\": [", builder,
                    (unsigned long long)seed);
    for (int i = 0; i < count; i++)
        spn_sink_printf(&m->sink, "%s[%.9g, %.9g, %.9g]", i ? ", " : "", anchors[i].x, anchors[i].y, anchors[i].z);
    spn_sink_printf(&m->sink, "], \"parameters\": {");
}

void spn__meta_num(spn__meta *m, const char *key, double v)
{
    spn_sink_printf(&m->sink, "%s\"%s\": %.9g", m->fields++ ? ", " : "", key, v);
}

void spn__meta_str(spn__meta *m, const char *key, const char *v)
{
    spn_sink_printf(&m->sink, "%s\"%s\": \"%s\"", m->fields++ ? ", " : "", key, v);
}

void spn__meta_materials(spn__meta *m, const spn_web_materials *mat)
{
    spn_sink_printf(&m->sink, "%s\"materials\": {", m->fields++ ? ", " : "");
    int first = 1;
    for (uint32_t k = 1; k < SPN_WEB_KINDS; k++) {
        const spn_thread_material *t = &mat->kind[k];
        spn_sink_printf(&m->sink, "%s\"%s\": {\"ea\": %.6g, \"linear_density\": %.6g, \"diameter\": %.6g, \"damping_ratio\": %.6g}",
                        first ? "" : ", ", spn_thread_kind_name(k), t->ea, t->linear_density, t->diameter, t->damping_ratio);
        first = 0;
    }
    spn_sink_printf(&m->sink, "}");
}

/* The weaver numbers particles as it lays threads: a capture spiral's turn
 * ties to radii laid long before, so a quarter of a 1 m Zilla web's springs
 * join the two halves of the numbering. Stepped on two threads (each takes
 * a contiguous half), every such spring moves data between the cores every
 * step: the general path's symplectic step took 23.5 ns a spring-step on
 * two threads against 11.7-16 on one, RK4 92 against 48-54. Numbered
 * octant by octant around the centroid, in the weaver's order within each,
 * 2% of the springs cross: 8.3 and 32.7 ns on two threads. The weaver's
 * order inside an octant keeps the multigrid's aggregates along the
 * threads: the settle's solve took 28 CG against 27 (a Z-order curve, which
 * crosses 1%, took 33). Octants by the signs of dx, dy and which is larger:
 * no libm, so the same numbering everywhere. Springs keep their order (the
 * construction order of build --frames). docs/physics.md, "Particle order". */
static int octant(spn_vec3 p, double cx, double cy)
{
    const double dx = p.x - cx, dy = p.y - cy;
    return (dy < 0) << 2 | (dx < 0) << 1 | (fabs(dx) < fabs(dy));
}

spn_status spn__web_number_by_place(spn_world *w)
{
    const uint32_t np = spn_world_particle_count(w);
    uint32_t *order = malloc((np ? np : 1) * sizeof *order);
    if (!order) return spn_error(SPN_ERR_NOMEM, "out of memory numbering a web of %u particles", np);
    double cx = 0, cy = 0;
    for (uint32_t i = 0; i < np; i++) {
        const spn_vec3 p = spn_world_position(w, i);
        cx += p.x, cy += p.y;
    }
    if (np) cx /= np, cy /= np;
    uint32_t start[9] = {0};
    for (uint32_t i = 0; i < np; i++) start[octant(spn_world_position(w, i), cx, cy) + 1]++;
    for (int k = 0; k < 8; k++) start[k + 1] += start[k];
    for (uint32_t i = 0; i < np; i++) order[start[octant(spn_world_position(w, i), cx, cy)]++] = i;
    spn_status st = spn_world_reorder_particles(w, order);
    free(order);
    return st;
}

spn_status spn__woven_finish(spn__weaver *wv, spn__meta *m, const spn_web_strains *s, bool form_find, spn_world **out)
{
    spn__meta_num(m, "prestrain", s->radii);
    spn__meta_num(m, "capture_prestrain", s->capture);
    spn__meta_num(m, "frame_prestrain", s->frame);
    spn__meta_num(m, "anchor_prestrain", s->anchor);
    spn__meta_num(m, "form_find", form_find);
    spn_status st = spn__weaver_finish(wv, NULL, out);
    /* numbered from the design, so a web and its design (form_find off) share
     * the numbering */
    if (st == SPN_OK) st = spn__web_number_by_place(*out);
    bool found = false;
    if (st == SPN_OK && form_find) {
        double pre[SPN_WEB_KINDS];
        spn__web_prestrains(s, pre);
        st = spn__web_form_find(*out, pre, &found);
    }
    /* form_found: whether the web was laid on the shape found (0 where it was
     * left as designed: not asked for, the solve fell short, or too big) */
    spn__meta_num(m, "form_found", found);
    if (st == SPN_OK) st = spn_world_set_metadata(*out, spn__meta_end(m));
    if (st != SPN_OK && *out) {
        spn_world_destroy(*out);
        *out = NULL;
    }
    return st;
}

const char *spn__meta_end(spn__meta *m)
{
    spn_sink_printf(&m->sink, "}}");
    return m->buf.data ? m->buf.data : "{}";
}

void spn__meta_free(spn__meta *m) { spn_buffer_free(&m->buf); }

/* ---- geometry ------------------------------------------------------------- */

double spn__cross2(spn_vec3 a, spn_vec3 b, spn_vec3 c)
{
    return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

bool spn__segments_cross(spn_vec3 a, spn_vec3 b, spn_vec3 c, spn_vec3 d)
{
    double d1 = spn__cross2(a, b, c), d2 = spn__cross2(a, b, d);
    double d3 = spn__cross2(c, d, a), d4 = spn__cross2(c, d, b);
    return ((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0));
}

spn_vec3 spn__lerp(spn_vec3 a, spn_vec3 b, double t) { return spn_v3_add(a, spn_v3_scale(spn_v3_sub(b, a), t)); }

void spn__site_anchors(spn_rng *rng, int n, double width, double height, spn_vec3 *out)
{
    /* Twigs around the web: evenly spread in angle, jittered, a little
     * farther out than the web itself, the first one up and to the left. */
    double start = SPN_PI / 2 + SPN_PI / n + spn_rng_range(rng, -0.2, 0.2);
    for (int i = 0; i < n; i++) {
        double a = start + 2 * SPN_PI * i / n + spn_rng_range(rng, -0.35, 0.35) * SPN_PI / n;
        double r = spn_rng_range(rng, 0.62, 0.8);
        out[i] = spn_v3(r * width * cos(a), r * height * sin(a), 0);
    }
}

void spn__web_prestrains(const spn_web_strains *s, double pre[SPN_WEB_KINDS])
{
    for (int k = 0; k < SPN_WEB_KINDS; k++) pre[k] = s->radii;
    /* Argiope's loose stabilimentum band pulls like capture silk and is laid
     * like it (spn_web_materials_preset). */
    pre[SPN_THREAD_CAPTURE] = pre[SPN_THREAD_STABILIMENTUM] = s->capture;
    pre[SPN_THREAD_FRAME] = s->frame;
    pre[SPN_THREAD_ANCHOR] = s->anchor;
}

spn_status spn__web_check_strains(const spn_web_strains *s)
{
    const char *names[4] = {"radii", "capture", "frame", "anchor"};
    const double v[4] = {s->radii, s->capture, s->frame, s->anchor};
    for (int i = 0; i < 4; i++)
        if (!(v[i] >= 0 && v[i] <= 4))
            return spn_error(SPN_ERR_INVALID, "strains.%s = %g is outside [0, 4] (length over rest, minus 1)", names[i],
                             v[i]);
    return SPN_OK;
}
