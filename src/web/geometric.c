/* The geometric construction (Japanese graduation thesis 2011, sec. 3): the
 * frame of geometric_frame.c (eqs. 3.1-3.16), radii from every arch and side
 * radius end to G, and the capture spiral of K turns laid on the radii
 * (3.17, 3.18). The thesis' spiral equations are garbled in the text; what
 * they say in words is kept: turn k of K lies at a fixed fraction of each
 * radius, turns step inward as the spiral passes the last radius (the -0.05
 * of i = n), and the spiral stays outside a hub zone set by m + m'. Here the
 * step is spread evenly over the turn, so the thread is a true spiral:
 *   H_{k,f} = (1 - l) E_f + l G,  l = l_out + (l_in - l_out) ((k-1) + f/F) / K
 * with E_f the outer end of radius f, l_out = 0.04 (just inside the frame)
 * and l_in = 1 - (m + m') (the hub and free zone around G).
 * The lines are then divided into springs of at most `segment` metres with the
 * thread materials (DESIGN), laid prestrained so the web settles taut. */
#include "geometric_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

spn_geometric_def spn_geometric_def_default(void)
{
    spn_geometric_def d;
    memset(&d, 0, sizeof d);
    d.materials = spn_web_materials_preset(SPN_MATERIAL_SILK);
    d.t = 0.15;
    d.s = 0.28;
    d.u = 3;
    d.v = 8;
    d.r_min = 0.3;
    d.r_max = 0.7;
    d.m = 0.1;
    d.m_prime = 0.2;
    d.k = 15;
    d.segment = 0.01;
    d.strains = spn_web_strains_preset(SPN_MATERIAL_SILK);
    d.form_find = true;
    d.seed = 1;
    d.world = spn_world_def_default();
    return d;
}

static spn_status range(const char *name, double v, double lo, double hi)
{
    if (!(v >= lo && v <= hi)) return spn_error(SPN_ERR_INVALID, "%s = %g is outside the thesis' range [%g, %g]", name, v, lo, hi);
    return SPN_OK;
}

static spn_status check_def(const spn_geometric_def *d)
{
    spn_status st = spn_web_check_anchors(d->anchors, d->anchor_count);
    if (st == SPN_OK) st = range("t", d->t, 0.1, 0.2);
    if (st == SPN_OK) st = range("s", d->s, 0.25, 0.30);
    if (st == SPN_OK) st = range("U", d->u, 1, 3);
    if (st == SPN_OK) st = range("V", d->v, 4, 8);
    if (st == SPN_OK) st = range("r_min", d->r_min, 0.3, 0.7);
    if (st == SPN_OK) st = range("r_max", d->r_max, d->r_min, 0.7);
    if (st == SPN_OK) st = range("m", d->m, 0, 0.6);
    if (st == SPN_OK) st = range("m_prime", d->m_prime, 0, 0.5);
    if (st == SPN_OK) st = range("K", d->k, 5, 45);
    if (st == SPN_OK && !(d->segment > 0)) st = spn_error(SPN_ERR_INVALID, "segment must be positive");
    if (st == SPN_OK) st = spn__web_check_strains(&d->strains);
    if (st == SPN_OK && d->m + d->m_prime > 0.9)
        st = spn_error(SPN_ERR_INVALID, "m + m_prime = %g leaves no room for the capture spiral", d->m + d->m_prime);
    return st;
}

/* Frame threads: anchor threads, sides and arches. Returns radius ends in order. */
static int lay_frame(spn__layout *l, const spn__geo_frame *f, uint32_t *ends)
{
    int n = f->n, ne = 0;
    uint32_t pp[SPN_WEB_MAX_ANCHORS], side_ids[SPN_WEB_MAX_ANCHORS][SPN__GEO_MAX_ON_LINE + 2];
    for (int i = 0; i < n; i++) {
        uint32_t line[2] = {spn__lay_point(l, f->p[i], SPN_PARTICLE_ANCHOR, true),
                            spn__lay_point(l, f->pp[i], SPN_PARTICLE_FRAME, false)};
        pp[i] = line[1];
        spn__lay_line(l, line, 2, SPN_THREAD_ANCHOR, SPN_STAGE_FRAME);
    }
    for (int i = 0; i < n; i++)
        for (int k = 0; k < f->ns[i]; k++) side_ids[i][k] = spn__lay_point(l, f->side[i][k], SPN_PARTICLE_FRAME, false);
    for (int i = 0; i < n; i++) {
        int j = (i + 1) % n, c = f->ns[i];
        uint32_t line[SPN__GEO_MAX_ON_LINE + 4];
        line[0] = pp[i];
        memcpy(line + 1, side_ids[i], (size_t)c * sizeof *line);
        line[c + 1] = pp[j];
        spn__lay_line(l, line, (size_t)c + 2, SPN_THREAD_FRAME, SPN_STAGE_FRAME);
    }
    for (int i = 0; i < n; i++) {
        int h = (i + n - 1) % n, c = f->na[i];
        uint32_t line[SPN__GEO_MAX_ON_LINE + 2];
        line[0] = side_ids[h][f->ns[h] - 1];
        for (int k = 1; k < c - 1; k++) line[k] = spn__lay_point(l, f->arch[i][k], SPN_PARTICLE_FRAME, false);
        line[c - 1] = side_ids[i][0];
        spn__lay_line(l, line, (size_t)c, SPN_THREAD_FRAME, SPN_STAGE_FRAME);
        for (int k = 1; k < c - 1; k++) ends[ne++] = line[k];
        for (int k = 1; k < f->ns[i] - 1; k++) ends[ne++] = side_ids[i][k];
    }
    return ne;
}

static void lay_radii_and_spiral(spn__layout *l, const spn_geometric_def *d, spn_vec3 g, const uint32_t *ends, int nf)
{
    uint32_t hub = spn__lay_point(l, g, SPN_PARTICLE_HUB, false);
    int k_turns = d->k;
    double l_out = 0.04, l_in = 1 - (d->m + d->m_prime);
    uint32_t *h = malloc((size_t)k_turns * (size_t)nf * sizeof *h);
    uint32_t *radius = malloc(((size_t)k_turns + 2) * sizeof *radius);
    if (!h || !radius) {
        free(h), free(radius);
        l->failed = true;
        return;
    }
    for (int k = 0; k < k_turns; k++)
        for (int f = 0; f < nf; f++) {
            double lam = l_out + (l_in - l_out) * (k + (double)f / nf) / k_turns;
            h[k * nf + f] = spn__lay_point(l, spn__lerp(l->pt[ends[f]], g, lam), SPN_PARTICLE_SPIRAL, false);
        }
    /* Radii are laid from the hub outward, as the spider lays them. */
    for (int f = 0; f < nf && !l->failed; f++) {
        radius[0] = hub;
        for (int k = 0; k < k_turns; k++) radius[1 + k] = h[(k_turns - 1 - k) * nf + f];
        radius[k_turns + 1] = ends[f];
        spn__lay_line(l, radius, (size_t)k_turns + 2, SPN_THREAD_RADIUS, SPN_STAGE_RADII);
    }
    /* The capture spiral, from the frame inward. */
    spn__lay_line(l, h, (size_t)k_turns * (size_t)nf, SPN_THREAD_CAPTURE, SPN_STAGE_CAPTURE);
    free(h);
    free(radius);
}

spn_status spn_web_build_geometric(const spn_geometric_def *def, spn_world **out)
{
    *out = NULL;
    spn_status st = check_def(def);
    if (st != SPN_OK) return st;
    spn_rng rng;
    spn_rng_seed(&rng, def->seed);
    spn__geo_params gp = {def->t, def->s, def->r_min, def->r_max, def->m, def->u, def->v};
    spn__geo_frame f;
    spn__geo_frame_make(def->anchors, def->anchor_count, &gp, &rng, &f);
    spn__layout l;
    memset(&l, 0, sizeof l);
    uint32_t ends[SPN_WEB_MAX_ANCHORS * (2 * SPN__GEO_MAX_ON_LINE)];
    int nf = lay_frame(&l, &f, ends);
    lay_radii_and_spiral(&l, def, f.g, ends, nf);
    double pre[SPN_WEB_KINDS];
    spn__web_prestrains(&def->strains, pre);
    spn__weaver wv;
    spn_world_def wd = def->world;
    wd.seed = def->seed;
    if (spn__weaver_init(&wv, &wd, &def->materials) == SPN_OK) spn__layout_weave(&l, &wv, def->segment, pre, true);
    spn__layout_free(&l);
    spn__meta m;
    spn__meta_begin(&m, "geometric", def->seed, def->anchors, def->anchor_count);
    spn__meta_materials(&m, &def->materials);
    spn__meta_num(&m, "t", def->t);
    spn__meta_num(&m, "s", def->s);
    spn__meta_num(&m, "U", def->u);
    spn__meta_num(&m, "V", def->v);
    spn__meta_num(&m, "r_min", def->r_min);
    spn__meta_num(&m, "r_max", def->r_max);
    spn__meta_num(&m, "m", def->m);
    spn__meta_num(&m, "m_prime", def->m_prime);
    spn__meta_num(&m, "K", def->k);
    spn__meta_num(&m, "G_x", f.g.x);
    spn__meta_num(&m, "G_y", f.g.y);
    spn__meta_num(&m, "segment", def->segment);
    st = spn__woven_finish(&wv, &m, &def->strains, def->form_find, out);
    spn__meta_free(&m);
    return st;
}
