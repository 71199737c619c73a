/* Fill emphasis (Mehla 2005, ch. 6, fig. 6.13): "random attachments between
 * the masses within the letters", like the extra silk of the St Andrews Cross
 * spider. The thesis could only join existing masses, which sit on the radii
 * and are far apart compared with a letter's stroke; here the letters get
 * their own masses, so the spiral density inside the text is set by
 * `spacing`, not by the web:
 *   - one node per grid cell of side `spacing`, jittered, kept where the
 *     (undilated) message is;
 *   - each node tied to its right and lower neighbours and to one random
 *     diagonal neighbour, when the whole thread lies inside the message;
 *   - the web threads that cross the message (radii, frame, the spiral that
 *     stayed) are split where they pass near a node, and the new mass is tied
 *     to that node: that is how the fill hangs from the web.
 * Pieces of a split thread keep its material (k scales with 1 / length).
 * Nodes not tied to the web are cleaned away afterwards (spn__clean).
 * Fill threads are laid at rest length and resist compression (see spn__fill).
 * New threads are SPN_THREAD_INSCRIPTION, which renderers shade apart. */
#include "inscribe_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define TINY_MASS 1e-15

typedef struct grid {
    double x0, y0, h;  /* origin (lower left) and cell side [m] */
    int nx, ny;
    uint32_t *node;    /* particle id per cell, UINT32_MAX when none */
} grid;

static bool inside(const spn_target *t, spn_vec3 p) { return spn_target_ink_at(t, p) >= 0.5; }

static bool thread_inside(const spn_target *t, spn_vec3 a, spn_vec3 b)
{
    for (int k = 0; k <= 6; k++)
        if (!inside(t, spn_v3_add(a, spn_v3_scale(spn_v3_sub(b, a), k / 6.0)))) return false;
    return true;
}

/* The message's bounding box in world coordinates; false when it has no ink. */
static bool ink_box(const spn_target *t, double *x0, double *y0, double *x1, double *y1)
{
    int i0 = t->width, i1 = -1, j0 = t->height, j1 = -1;
    for (int j = 0; j < t->height; j++)
        for (int i = 0; i < t->width; i++)
            if (t->ink[(size_t)j * (size_t)t->width + (size_t)i] >= 0.5f) {
                i0 = i < i0 ? i : i0, i1 = i > i1 ? i : i1;
                j0 = j < j0 ? j : j0, j1 = j > j1 ? j : j1;
            }
    if (i1 < 0) return false;
    *x0 = t->x0 + i0 / t->scale, *x1 = t->x0 + (i1 + 1) / t->scale;
    *y1 = t->y0 - j0 / t->scale, *y0 = t->y0 - (j1 + 1) / t->scale;
    return true;
}

static spn_status add_mass(spn_world *w, spn_vec3 p, double mass, uint32_t *id)
{
    spn_particle_def d = spn_particle_def_default();
    d.position = p;
    d.mass = mass > TINY_MASS ? mass : TINY_MASS;
    d.tag = SPN_PARTICLE_SPIRAL;
    return spn_world_add_particle(w, &d, id);
}

static spn_status place_nodes(spn_world *w, const spn_target *t, grid *g, spn_rng *rng)
{
    double x1, y1;
    if (!ink_box(t, &g->x0, &g->y0, &x1, &y1)) return SPN_OK;
    g->nx = (int)ceil((x1 - g->x0) / g->h), g->ny = (int)ceil((y1 - g->y0) / g->h);
    g->node = malloc(((size_t)g->nx * (size_t)g->ny + 1) * sizeof *g->node);
    if (!g->node) return spn_error(SPN_ERR_NOMEM, "out of memory");
    spn_status st = SPN_OK;
    for (int j = 0; j < g->ny; j++)
        for (int i = 0; i < g->nx; i++) {
            double u = spn_rng_range(rng, 0.2, 0.8), v = spn_rng_range(rng, 0.2, 0.8);
            spn_vec3 p = spn_v3(g->x0 + (i + u) * g->h, g->y0 + (j + v) * g->h, 0);
            uint32_t *cell = &g->node[(size_t)j * (size_t)g->nx + (size_t)i];
            *cell = UINT32_MAX;
            if (st == SPN_OK && inside(t, p)) st = add_mass(w, p, 0, cell);
        }
    return st;
}

static uint32_t node_at(const grid *g, int i, int j)
{
    if (i < 0 || j < 0 || i >= g->nx || j >= g->ny) return UINT32_MAX;
    return g->node[(size_t)j * (size_t)g->nx + (size_t)i];
}

static spn_status tie_nodes(spn_world *w, const spn_target *t, const grid *g, const spn__material *m, spn_rng *rng,
                            uint32_t *added)
{
    spn_status st = SPN_OK;
    for (int j = 0; j < g->ny && st == SPN_OK; j++)
        for (int i = 0; i < g->nx && st == SPN_OK; i++) {
            uint32_t a = node_at(g, i, j);
            if (a == UINT32_MAX) continue;
            int diag = spn_rng_below(rng, 2) ? 1 : -1;
            uint32_t nb[3] = {node_at(g, i + 1, j), node_at(g, i, j + 1), node_at(g, i + diag, j + 1)};
            for (int k = 0; k < 3 && st == SPN_OK; k++) {
                if (nb[k] == UINT32_MAX || !thread_inside(t, spn_world_position(w, a), spn_world_position(w, nb[k])))
                    continue;
                st = spn__add_thread(w, m, a, nb[k], SPN_THREAD_INSCRIPTION);
                if (st == SPN_OK) (*added)++;
            }
        }
    return st;
}

/* The node nearest to p within one cell side, or UINT32_MAX; none when the
 * nearest is closer than 0.35 of a side (a very short tie would be very stiff). */
static uint32_t nearest_node(const spn_world *w, const grid *g, spn_vec3 p)
{
    int ci = (int)floor((p.x - g->x0) / g->h), cj = (int)floor((p.y - g->y0) / g->h);
    uint32_t best = UINT32_MAX;
    double bd = g->h;
    for (int j = cj - 1; j <= cj + 1; j++)
        for (int i = ci - 1; i <= ci + 1; i++) {
            uint32_t n = node_at(g, i, j);
            if (n == UINT32_MAX) continue;
            spn_vec3 d = spn_v3_sub(spn_world_position(w, n), p);
            double dist = hypot(d.x, d.y);
            if (dist < bd) bd = dist, best = n;
        }
    return bd < 0.35 * g->h ? UINT32_MAX : best;
}

/* Split spring s at the parameters u[0..n) (increasing) and tie each new mass to node[k]. */
static spn_status split_and_tie(spn_world *w, uint32_t s, const double *u, const uint32_t *node, int n,
                                const spn__material *m, uint32_t *added)
{
    spn_spring_info si = spn_world_spring(w, s);
    spn_vec3 a = spn_world_position(w, si.a), b = spn_world_position(w, si.b);
    uint32_t prev = si.a;
    double uprev = 0;
    spn_status st = SPN_OK;
    for (int k = 0; k <= n && st == SPN_OK; k++) {
        double uk = k < n ? u[k] : 1, frac = uk - uprev;
        uint32_t cur = si.b;
        if (k < n) {
            double unext = k + 1 < n ? u[k + 1] : 1;
            st = add_mass(w, spn_v3_add(a, spn_v3_scale(spn_v3_sub(b, a), uk)), 0.5 * m->density * si.rest * (unext - uprev),
                          &cur);
        }
        spn_spring_def d = {prev, cur, si.k / frac, si.kd / frac, si.rest * frac, si.break_min * frac,
                            si.break_max * frac, si.tension_only, si.tag, si.stage, si.order};
        if (st == SPN_OK) st = spn_world_add_spring(w, &d, NULL);
        if (st == SPN_OK && k < n) st = spn__add_thread(w, m, cur, node[k], SPN_THREAD_INSCRIPTION);
        if (st == SPN_OK && k < n) (*added)++;
        prev = cur, uprev = uk;
    }
    return st;
}

/* Where spring s passes through the message near nodes: parameters and nodes, one per node. */
static int attachments(const spn_world *w, const spn_target *t, const grid *g, uint32_t s, double *u, uint32_t *node,
                       int max)
{
    spn_spring_info si = spn_world_spring(w, s);
    spn_vec3 a = spn_world_position(w, si.a), b = spn_world_position(w, si.b);
    double len = spn_v3_len(spn_v3_sub(b, a));
    int steps = (int)ceil(2 * len / g->h), n = 0;
    for (int k = 1; k < steps && n < max; k++) {
        double uk = (double)k / steps;
        spn_vec3 p = spn_v3_add(a, spn_v3_scale(spn_v3_sub(b, a), uk));
        /* Not too near the thread's ends: a very short piece would be very stiff. */
        if (!inside(t, p) || uk * len < 0.4 * g->h || (1 - uk) * len < 0.4 * g->h) continue;
        uint32_t q = nearest_node(w, g, p);
        if (q == UINT32_MAX || (n > 0 && node[n - 1] == q) || (n > 0 && (uk - u[n - 1]) * len < 0.4 * g->h)) continue;
        u[n] = uk, node[n++] = q;
    }
    return n;
}

static spn_status hang_from_web(spn_world *w, const spn_target *t, const grid *g, uint32_t ns0,
                                const spn__material *m, uint32_t *added, uint32_t *split)
{
    enum { MAX_ATTACH = 256 };
    double u[MAX_ATTACH];
    uint32_t node[MAX_ATTACH];
    bool *remove = calloc((size_t)ns0 + 1, sizeof *remove);
    if (!remove) return spn_error(SPN_ERR_NOMEM, "out of memory");
    spn_status st = SPN_OK;
    for (uint32_t s = 0; s < ns0 && st == SPN_OK; s++) {
        spn_spring_info si = spn_world_spring(w, s);
        if (si.broken || si.tag == SPN_THREAD_INSCRIPTION) continue;
        int n = attachments(w, t, g, s, u, node, MAX_ATTACH);
        if (n == 0) continue;
        st = split_and_tie(w, s, u, node, n, m, added);
        remove[s] = true;
        (*split)++;
    }
    if (st == SPN_OK) {
        uint32_t ns = spn_world_spring_count(w);
        bool *all = calloc((size_t)ns + 1, sizeof *all);
        if (!all) st = spn_error(SPN_ERR_NOMEM, "out of memory");
        else {
            memcpy(all, remove, (size_t)ns0 * sizeof *all);
            st = spn_world_remove_springs(w, all);
            free(all);
        }
    }
    free(remove);
    return st;
}

spn_status spn__fill(spn_world *w, const spn_target *t, const spn__material *m, double spacing, uint64_t seed,
                     uint32_t *added, uint32_t *split)
{
    if (!(spacing > 0)) return spn_error(SPN_ERR_INVALID, "fill spacing: need > 0 m");
    spn_rng rng;
    spn_rng_seed(&rng, seed);
    /* Resisting compression, like the matted silk of a stabilimentum: a net
     * of tension-only threads with a free edge has no stiffness and folds up
     * under the slightest load (we watched the letters crumple). A fifth of
     * the web's pre-strain keeps every fill thread in tension, so a node on
     * two nearly straight threads still has a sideways stiffness (at zero
     * tension it has none, and settling crawls). */
    spn__material fm = *m;
    fm.prestrain = 0.2 * m->prestrain;
    fm.tension_only = false;
    m = &fm;
    uint32_t ns0 = spn_world_spring_count(w);
    grid g = {0, 0, spacing, 0, 0, NULL};
    spn_status st = place_nodes(w, t, &g, &rng);
    if (st == SPN_OK && g.node) st = tie_nodes(w, t, &g, m, &rng, added);
    if (st == SPN_OK && g.node) st = hang_from_web(w, t, &g, ns0, m, added, split);
    free(g.node);
    return st;
}
