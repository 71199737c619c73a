/* Charlotte's-web inscription, Mehla 2005, ch. 6. The web is settled, drawn
 * to the source raster, source and target are dilated (7x7), every capture
 * segment — the thread from a mass on one radius to a mass on the next — is
 * scored from the ink of both images in its 5-pixel band (fig. 6.9), and the
 * segments scoring above the threshold are taken out. The emphasis modes of
 * figs. 6.12-6.14 and the random gaps of fig. 6.18 follow; then dangling or
 * unanchored threads are cleaned away and the web is settled again.
 *
 * A capture segment is a chain of capture springs between junctions (particles
 * with another kind of thread, a fork, or fixed): the standard web has one
 * spring per segment, a builder may subdivide it. A chain is scored as a
 * whole and taken out whole, so no piece of it is left dangling.
 * Invariant: the caller's world is untouched unless everything succeeds. */
#include "inscribe_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

static const char *const emphasis_names[] = {"none", "crosshatch", "fill", "outline"};

const char *spn_emphasis_name(spn_emphasis e)
{
    return (unsigned)e < 4 ? emphasis_names[e] : "?";
}

spn_status spn_emphasis_parse(const char *name, spn_emphasis *out)
{
    for (int i = 0; i < 4; i++)
        if (name && strcasecmp(name, emphasis_names[i]) == 0) return *out = (spn_emphasis)i, SPN_OK;
    return spn_error(SPN_ERR_INVALID, "emphasis '%s': choose none, crosshatch, fill or outline", name ? name : "");
}

spn_inscribe_def spn_inscribe_def_default(void)
{
    spn_inscribe_def d;
    d.threshold = 8;
    d.emphasis = SPN_EMPHASIS_NONE;
    d.gaps = 0;
    d.fill_spacing = 0;
    d.seed = 1;
    d.settle = true;
    d.settle_def = spn_settle_def_default();
    /* README's physical web, "PIG" filled, the settle after editing (implicit,
     * 1 ms steps): 4.22 s of simulated time with the web's own drag of 1 s^-1
     * (74 s of CPU), 0.47 s with 20 (8.2 s), and closer to the rest state
     * (4 mm from it against 10). */
    d.settle_def.drag = SPN_SETTLE_DRAG;
    d.settle_solve = true;
    d.settle_keep_integrator = false;
    return d;
}

/* Per-spring band sums and the chains capture springs belong to. */
typedef struct scoring {
    uint32_t ns;
    double *src, *tgt;    /* band ink per spring (capture only) */
    uint32_t *chain;      /* chain id per capture spring, UINT32_MAX otherwise */
    uint32_t nchains;
    double *csrc, *ctgt;  /* per chain */
    float *dilated;       /* the dilated target */
} scoring;

static void scoring_free(scoring *sc)
{
    free(sc->src), free(sc->tgt), free(sc->chain), free(sc->csrc), free(sc->ctgt), free(sc->dilated);
    memset(sc, 0, sizeof *sc);
}

static uint32_t find(uint32_t *parent, uint32_t i)
{
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
}

/* Union capture springs through interior particles: free, exactly two threads, both capture. */
static spn_status build_chains(const spn_world *w, scoring *sc)
{
    spn__graph g;
    spn_status st = spn__graph_build(w, NULL, &g);
    uint32_t *parent = malloc(((size_t)sc->ns + 1) * sizeof *parent), *id = malloc(((size_t)sc->ns + 1) * sizeof *id);
    if (st == SPN_OK && (!parent || !id)) st = spn_error(SPN_ERR_NOMEM, "out of memory");
    for (uint32_t s = 0; st == SPN_OK && s < sc->ns; s++) parent[s] = s, id[s] = UINT32_MAX;
    for (uint32_t p = 0; st == SPN_OK && p < g.np; p++) {
        if (g.start[p + 1] - g.start[p] != 2 || spn_world_is_fixed(w, p)) continue;
        uint32_t s0 = g.edge[g.start[p]], s1 = g.edge[g.start[p] + 1];
        if (spn_world_spring(w, s0).tag != SPN_THREAD_CAPTURE || spn_world_spring(w, s1).tag != SPN_THREAD_CAPTURE)
            continue;
        parent[find(parent, s0)] = find(parent, s1);
    }
    sc->nchains = 0;
    for (uint32_t s = 0; st == SPN_OK && s < sc->ns; s++) {
        if (sc->chain[s] == UINT32_MAX) continue; /* not capture */
        uint32_t r = find(parent, s);
        if (id[r] == UINT32_MAX) id[r] = sc->nchains++;
        sc->chain[s] = id[r];
    }
    free(parent), free(id);
    spn__graph_free(&g); /* safe after a failed build: it leaves g empty */
    return st;
}

static spn_status score_world(const spn_world *w, const spn_target *t, scoring *sc)
{
    memset(sc, 0, sizeof *sc);
    sc->ns = spn_world_spring_count(w);
    size_t n = (size_t)sc->ns + 1;
    sc->src = calloc(n, sizeof(double)), sc->tgt = calloc(n, sizeof(double));
    sc->chain = malloc(n * sizeof(uint32_t));
    float *source = spn__raster_alloc(t);
    sc->dilated = spn__raster_alloc(t);
    spn_status st = sc->src && sc->tgt && sc->chain && source && sc->dilated ? SPN_OK
                                                                              : spn_error(SPN_ERR_NOMEM, "out of memory");
    if (st == SPN_OK) st = spn__raster_web(w, t, source);
    if (st == SPN_OK) {
        memcpy(sc->dilated, t->ink, (size_t)t->width * (size_t)t->height * sizeof(float));
        st = spn__dilate(source, t->width, t->height, SPN__DILATE_RADIUS);
    }
    if (st == SPN_OK) st = spn__dilate(sc->dilated, t->width, t->height, SPN__DILATE_RADIUS);
    for (uint32_t s = 0; st == SPN_OK && s < sc->ns; s++) {
        spn_spring_info si = spn_world_spring(w, s);
        bool capture = si.tag == SPN_THREAD_CAPTURE && !si.broken;
        sc->chain[s] = capture ? 0 : UINT32_MAX;
        if (!capture) continue;
        spn_vec3 a = spn_world_position(w, si.a), b = spn_world_position(w, si.b);
        sc->src[s] = spn__band_sum(t, source, a, b, NULL);
        sc->tgt[s] = spn__band_sum(t, sc->dilated, a, b, NULL);
    }
    free(source);
    if (st == SPN_OK) st = build_chains(w, sc);
    if (st == SPN_OK) {
        sc->csrc = calloc((size_t)sc->nchains + 1, sizeof(double));
        sc->ctgt = calloc((size_t)sc->nchains + 1, sizeof(double));
        if (!sc->csrc || !sc->ctgt) st = spn_error(SPN_ERR_NOMEM, "out of memory");
    }
    for (uint32_t s = 0; st == SPN_OK && s < sc->ns; s++)
        if (sc->chain[s] != UINT32_MAX) sc->csrc[sc->chain[s]] += sc->src[s], sc->ctgt[sc->chain[s]] += sc->tgt[s];
    if (st != SPN_OK) scoring_free(sc);
    return st;
}

spn_status spn_inscribe_scores(const spn_world *w, const spn_target *t, uint8_t *scores)
{
    scoring sc;
    spn_status st = score_world(w, t, &sc);
    if (st != SPN_OK) return st;
    for (uint32_t s = 0; s < sc.ns; s++) {
        uint32_t c = sc.chain[s];
        scores[s] = c == UINT32_MAX ? 0 : (uint8_t)spn__score(sc.csrc[c], sc.ctgt[c]);
    }
    scoring_free(&sc);
    return SPN_OK;
}

/* Ratio of a would-be thread a -> b: its dilated band is all source ink. */
static double candidate_ratio(const spn_world *w, const spn_target *t, const scoring *sc, uint32_t a, uint32_t b)
{
    double n = 0, tg = spn__band_sum(t, sc->dilated, spn_world_position(w, a), spn_world_position(w, b), &n);
    return n > 0 ? tg / n : 0;
}

static bool joined(const spn_world *w, const spn__graph *g, uint32_t a, uint32_t b)
{
    for (uint32_t e = g->start[a]; e < g->start[a + 1]; e++)
        if (spn__other_end(w, g->edge[e], a) == b) return true;
    return false;
}

/* Ends of each chain: the junction particles (for single springs, a and b). */
typedef struct chain_ends {
    uint32_t a, b;
} chain_ends;

static chain_ends *find_chain_ends(const spn_world *w, const scoring *sc, const spn__graph *g)
{
    chain_ends *ends = malloc(((size_t)sc->nchains + 1) * sizeof *ends);
    if (!ends) return NULL;
    for (uint32_t c = 0; c < sc->nchains; c++) ends[c].a = ends[c].b = UINT32_MAX;
    for (uint32_t s = 0; s < sc->ns; s++) {
        uint32_t c = sc->chain[s];
        if (c == UINT32_MAX) continue;
        spn_spring_info si = spn_world_spring(w, s);
        for (int e = 0; e < 2; e++) {
            uint32_t p = e ? si.b : si.a;
            bool interior = g->start[p + 1] - g->start[p] == 2 && !spn_world_is_fixed(w, p);
            if (interior) {
                uint32_t s0 = g->edge[g->start[p]], s1 = g->edge[g->start[p] + 1];
                interior = sc->chain[s0] == c && sc->chain[s1] == c;
            }
            if (interior) continue;
            if (ends[c].a == UINT32_MAX) ends[c].a = p;
            else if (ends[c].a != p) ends[c].b = p;
        }
    }
    return ends;
}

/* Cross-hatch (fig. 6.12): from the first mass of each segment to the two
 * masses beside the second one along its radius; kept where they score above
 * the threshold, i.e. inside the message. */
static spn_status crosshatch(spn_world *w, const spn_target *t, const scoring *sc, const spn__graph *g,
                             const spn__material *m, double keep_ratio, uint32_t *added)
{
    chain_ends *ends = find_chain_ends(w, sc, g);
    if (!ends) return spn_error(SPN_ERR_NOMEM, "out of memory");
    spn_status st = SPN_OK;
    for (uint32_t c = 0; c < sc->nchains && st == SPN_OK; c++) {
        uint32_t a = ends[c].a, b = ends[c].b;
        if (a == UINT32_MAX || b == UINT32_MAX) continue;
        for (uint32_t e = g->start[b]; e < g->start[b + 1] && st == SPN_OK; e++) {
            if (spn_world_spring(w, g->edge[e]).tag != SPN_THREAD_RADIUS) continue;
            uint32_t q = spn__other_end(w, g->edge[e], b);
            if (q == a || joined(w, g, a, q) || candidate_ratio(w, t, sc, a, q) < keep_ratio) continue;
            st = spn__add_thread(w, m, a, q, SPN_THREAD_INSCRIPTION);
            if (st == SPN_OK) (*added)++;
        }
    }
    free(ends);
    return st;
}

/* Outline (fig. 6.14): threads the dilated message touches but does not
 * cover (the ones that stay, around the letters) are doubled with inscription silk. */
static spn_status outline(spn_world *w, const spn_target *t, const scoring *sc, const bool *remove,
                          const spn__material *m, double keep_ratio, uint32_t *added)
{
    spn_status st = SPN_OK;
    for (uint32_t s = 0; s < sc->ns && st == SPN_OK; s++) {
        spn_spring_info si = spn_world_spring(w, s);
        if (remove[s] || si.broken || (si.tag != SPN_THREAD_CAPTURE && si.tag != SPN_THREAD_RADIUS)) continue;
        double r = candidate_ratio(w, t, sc, si.a, si.b);
        if (r < 0.1 || r >= keep_ratio) continue;
        st = spn__add_thread(w, m, si.a, si.b, SPN_THREAD_INSCRIPTION);
        if (st == SPN_OK) (*added)++;
    }
    return st;
}

/* Random gaps (fig. 6.18): whole capture segments taken out anywhere. */
static void random_gaps(const scoring *sc, bool *remove, int gaps, uint64_t seed, uint32_t *taken)
{
    bool *gone = calloc((size_t)sc->nchains + 1, sizeof *gone);
    uint32_t *open = malloc(((size_t)sc->nchains + 1) * sizeof *open), n = 0;
    if (!gone || !open) goto done;
    for (uint32_t s = 0; s < sc->ns; s++)
        if (sc->chain[s] != UINT32_MAX && remove[s]) gone[sc->chain[s]] = true;
    for (uint32_t c = 0; c < sc->nchains; c++)
        if (!gone[c]) open[n++] = c;
    spn_rng rng;
    spn_rng_seed(&rng, seed ^ 0x9e3779b97f4a7c15ull);
    for (int k = 0; k < gaps && n > 0; k++) {
        uint32_t i = spn_rng_below(&rng, n);
        gone[open[i]] = true;
        open[i] = open[--n];
        (*taken)++;
    }
    for (uint32_t s = 0; s < sc->ns; s++)
        if (sc->chain[s] != UINT32_MAX && gone[sc->chain[s]]) remove[s] = true;
done:
    free(gone);
    free(open);
}

static spn_status check_def(const spn_inscribe_def *d)
{
    if (d->threshold < 0 || d->threshold > 10) return spn_error(SPN_ERR_INVALID, "threshold %d: need 0..10", d->threshold);
    if ((unsigned)d->emphasis > SPN_EMPHASIS_OUTLINE) return spn_error(SPN_ERR_INVALID, "emphasis %d: unknown", d->emphasis);
    if (d->gaps < 0) return spn_error(SPN_ERR_INVALID, "gaps %d: need >= 0", d->gaps);
    if (!(d->fill_spacing >= 0) || !isfinite(d->fill_spacing))
        return spn_error(SPN_ERR_INVALID, "fill spacing %g: need >= 0 m", d->fill_spacing);
    return SPN_OK;
}

/* The settle after editing may first solve for the rest state: the edited
 * web is near it, and stepping there took most of an inscription's time
 * (README's physical web, implicit: cross-hatch 23 s, outline 11 s, fill 74 s
 * of CPU) or blew up (symplectic at the default 1 ms). The solve's target is
 * also a hundredth of the lightest particle's weight (spn_web_solve_rest's
 * own): it sets every velocity to 0, so only the residual can tell a
 * particle that would still fall. Where the solve crawls it gives up early
 * (a round of 10 Newton steps that does not halve the residual), and the web
 * steps: a dark fill on README's web, its light threads slack between
 * attachments, wandered between 1e-6 and 4e-9 N for 300 steps (10 s),
 * against a target of 3e-11 N. */
#define SOLVE_STEPS 100

/* The CG tolerance of the implicit steps to rest after editing (the world's
 * own, default 1e-10, where it is looser; restored after). Only where the web
 * comes to rest matters, not the path: README's physical web, "PIG" filled,
 * 9.5 -> 4.7 s of CPU, 0.36 um from where 1e-10 stops; the standard orb web
 * (tests/data/inscribe/orb.json) 21.3 -> 3.3 s, 26 um (1e-4: 5.5 and 5.3 s;
 * 1e-2: 4.0 and 2.0 s, 13-39 um). The settle before scoring keeps the
 * world's, so what is edited does not change. Settling species webs
 * (spn_web_settle, a residual target of a hundredth of a particle's weight)
 * is another matter: at 1e-3 Zilla seed 2 timed out. */
#define SETTLE_CG_TOLERANCE 1e-3

/* Whether the web's explicit integrator cannot take the settle's step: its
 * stiffest threads would blow it up (the standard orb web at the default
 * 1 ms, symplectic: at the second step; README's physical web once filled,
 * at the 84th). Such a web settles with the implicit integrator. */
static bool too_stiff(const spn_world *w, double dt)
{
    spn_integrator in = spn_world_get_def(w)->integrator;
    if (in != SPN_INTEGRATOR_EULER && in != SPN_INTEGRATOR_SYMPLECTIC && in != SPN_INTEGRATOR_RK4) return false;
    double reach = in == SPN_INTEGRATOR_RK4 ? SPN_STABLE_REACH_RK4 : SPN_STABLE_REACH;
    return dt > reach * spn_world_stable_step(w, 0);
}

static spn_status settle(spn_world *w, const spn_inscribe_def *d, bool after, spn_settle_report *rep, bool *implicit)
{
    if (!d->settle) return SPN_OK;
    bool solved = false;
    spn_status st = after && d->settle_solve ? spn_web_solve_rest(w, d->settle_def.max_residual, SOLVE_STEPS, &solved, rep) : SPN_OK;
    if (st == SPN_OK && !solved) {
        const int newton_steps = rep->newton_steps; /* the solve's, else 0 (spn_inscribe zeroes the reports) */
        const spn_integrator own = spn_world_get_def(w)->integrator;
        *implicit = !d->settle_keep_integrator && too_stiff(w, d->settle_def.dt);
        if (*implicit) spn_world_set_integrator(w, SPN_INTEGRATOR_IMPLICIT);
        const spn_world_def *wd = spn_world_get_def(w);
        const double cg_tolerance = wd->cg_tolerance;
        const int cg_cap = wd->cg_max_iterations;
        if (after && SETTLE_CG_TOLERANCE > cg_tolerance)
            st = spn_world_set_solver_tolerance(w, SETTLE_CG_TOLERANCE, cg_cap);
        if (st == SPN_OK) st = spn_world_settle(w, &d->settle_def, rep);
        spn_world_set_solver_tolerance(w, cg_tolerance, cg_cap);
        spn_world_set_integrator(w, own);
        *implicit = *implicit && rep->steps > 0; /* a web at rest already took no step */
        rep->newton_steps = newton_steps; /* those the solve took before it fell short */
    }
    if (st != SPN_OK) return st;
    for (uint32_t i = 0; i < spn_world_particle_count(w); i++) spn_world_set_velocity(w, i, spn_v3(0, 0, 0));
    return SPN_OK;
}

/* Scores, removal mask, cross-hatch / outline threads and gaps on the settled web `w`. */
static spn_status edit_segments(spn_world *w, const spn_target *t, const spn_inscribe_def *d, const spn__material *m,
                                bool **remove_out, spn_inscribe_report *rep)
{
    scoring sc;
    spn_status st = score_world(w, t, &sc);
    if (st != SPN_OK) return st;
    bool *remove = calloc((size_t)sc.ns + 1, sizeof *remove);
    if (!remove) st = spn_error(SPN_ERR_NOMEM, "out of memory");
    bool *gone = calloc((size_t)sc.nchains + 1, sizeof *gone);
    if (st == SPN_OK && !gone) st = spn_error(SPN_ERR_NOMEM, "out of memory");
    rep->segments = sc.nchains;
    for (uint32_t c = 0; st == SPN_OK && c < sc.nchains; c++) {
        int score = spn__score(sc.csrc[c], sc.ctgt[c]);
        rep->score_histogram[score]++;
        gone[c] = score > d->threshold;
        rep->removed += gone[c];
    }
    for (uint32_t s = 0; st == SPN_OK && s < sc.ns; s++) remove[s] = sc.chain[s] != UINT32_MAX && gone[sc.chain[s]];
    free(gone);
    if (st == SPN_OK && d->gaps > 0) random_gaps(&sc, remove, d->gaps, d->seed, &rep->gaps);
    double keep_ratio = (d->threshold + 1) / 10.0;
    if (st == SPN_OK && d->emphasis == SPN_EMPHASIS_CROSSHATCH) {
        spn__graph g;
        st = spn__graph_build(w, NULL, &g);
        if (st == SPN_OK) st = crosshatch(w, t, &sc, &g, m, keep_ratio, &rep->added);
        spn__graph_free(&g);
    }
    if (st == SPN_OK && d->emphasis == SPN_EMPHASIS_OUTLINE) st = outline(w, t, &sc, remove, m, keep_ratio, &rep->added);
    uint32_t ns0 = sc.ns;
    scoring_free(&sc);
    if (st == SPN_OK) {
        /* Threads just added are kept: extend the mask to the new spring count. */
        uint32_t ns = spn_world_spring_count(w);
        bool *grown = realloc(remove, ((size_t)ns + 1) * sizeof *grown);
        if (!grown) st = spn_error(SPN_ERR_NOMEM, "out of memory");
        else {
            for (uint32_t s = ns0; s < ns; s++) grown[s] = false;
            remove = grown;
        }
    }
    if (st != SPN_OK) free(remove), remove = NULL;
    *remove_out = remove;
    return st;
}

static double default_fill_spacing(const spn_world *w)
{
    spn_capture_area area;
    if (spn_capture_area_of(w, &area) != SPN_OK) return 0.0025;
    return area.radius / 80;
}

spn_status spn_inscribe(spn_world **wp, const spn_target *t, const spn_inscribe_def *def, spn_inscribe_report *report)
{
    spn_inscribe_def d = def ? *def : spn_inscribe_def_default();
    spn_inscribe_report rep;
    memset(&rep, 0, sizeof rep);
    spn_status st = check_def(&d);
    spn_capture_area area;
    if (st == SPN_OK) st = spn_capture_area_of(*wp, &area);
    if (st != SPN_OK) return st;
    spn_world *w = spn_world_clone(*wp);
    if (!w) return spn_error(SPN_ERR_NOMEM, "out of memory");
    spn__material m = spn__capture_material(w);
    bool *remove = NULL;
    st = settle(w, &d, false, &rep.before, &rep.implicit_before);
    if (st == SPN_OK) st = edit_segments(w, t, &d, &m, &remove, &rep);
    if (st == SPN_OK) st = spn__clean(w, remove, &rep.pruned, &rep.particles_removed);
    free(remove);
    if (st == SPN_OK && d.emphasis == SPN_EMPHASIS_FILL) {
        double spacing = d.fill_spacing > 0 ? d.fill_spacing : default_fill_spacing(w);
        st = spn__fill(w, t, &m, spacing, d.seed, &rep.added, &rep.split);
        if (st == SPN_OK) st = spn__clean(w, NULL, &rep.pruned, &rep.particles_removed);
    }
    if (st == SPN_OK) st = settle(w, &d, true, &rep.after, &rep.implicit_after);
    if (st != SPN_OK) {
        spn_world_destroy(w);
        return st;
    }
    spn_world_destroy(*wp);
    *wp = w;
    if (report) *report = rep;
    return SPN_OK;
}
