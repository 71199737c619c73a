/* Compiling a world: the flat arrays the stepping loops read. Springs get
 * an internal order sorted by their lower particle id (a stable counting
 * sort), their hot fields copied into 32-byte records; the CSR adjacency
 * lists each particle's springs in that order; scratch buffers are sized.
 * O(particles + springs), so adding to a world and stepping again stays
 * cheap. Buffers only some integrators need are allocated on first use. */
#include "world_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void spn__free_compiled(spn_world *w)
{
    spn__sweep_free(w);
    spn__lattice_drop(w);
    free(w->adj_start);
    free(w->adj);
    free(w->a_start);
    free(w->b_start);
    free(w->b_adj);
    free(w->hs);
    free(w->hflags);
    free(w->perm);
    free(w->iperm);
    free(w->fs);
    free(w->sdiam);
    free(w->f);
    free(w->fext);
    free(w->x0);
    free(w->v0);
    for (int i = 0; i < SPN_TMP_COUNT; i++) free(w->tmp[i]);
    free(w->fair);
    free(w->wind);
    free(w->air_runs);
    free(w->air_held);
    free(w->cair);
    free(w->jac);
    free(w->pblock);
    free(w->pinv);
    spn__imp_mg_free(w->imp_mg);
    free(w->partial);
    spn__forget_compiled(w);
}

void spn__forget_compiled(spn_world *w)
{
    w->adj_start = w->adj = w->perm = w->iperm = w->a_start = w->b_start = w->b_adj = NULL;
    w->hs = NULL;
    w->hflags = NULL;
    w->fs = w->f = w->fext = w->x0 = w->v0 = w->fair = w->wind = NULL;
    w->sdiam = w->cair = w->partial = w->pblock = w->pinv = NULL;
    w->jac = NULL;
    w->air_runs = NULL;
    w->nair_runs = 0;
    w->air_held = NULL;
    w->air_held_k = NAN;
    w->imp_mg = NULL;
    w->npartial = 0;
    w->sweep_block = 0;
    w->xout_start = w->xout = w->xin_start = w->xin = NULL;
    w->facc = NULL;
    w->lat = NULL;
    for (int i = 0; i < SPN_TMP_COUNT; i++) w->tmp[i] = NULL;
    w->compiled = false;
}

spn__spring spn__hot_spring(const spn_world *w, uint32_t s)
{
    const bool broken = (w->sflags[s] & SPN_SPRING_BROKEN) != 0;
    const uint32_t tonly = (w->sflags[s] & SPN_SPRING_TENSION_ONLY) ? 1u << 31 : 0;
    /* Internal end a is the lower id (a spring's law is symmetric in its ends). */
    const uint32_t a = w->sa[s] < w->sb[s] ? w->sa[s] : w->sb[s], b = w->sa[s] < w->sb[s] ? w->sb[s] : w->sa[s];
    return (spn__spring){a, b | tonly, broken ? 0 : w->k[s], broken ? 0 : w->kd[s], w->rest[s]};
}

static double tag_diameter(const spn_world *w, uint32_t tag)
{
    for (uint32_t i = 0; i < w->ndiam; i++)
        if (w->diam[i].tag == tag) return w->diam[i].diameter;
    return 0;
}

/* Allocate the compiled arrays; false when out of memory. */
static bool alloc_compiled(spn_world *w)
{
    size_t np = w->np ? w->np : 1, ns = w->ns ? w->ns : 1;
    uint32_t nb = spn__blocks(w->np > w->ns ? w->np : w->ns);
    w->npartial = nb ? nb : 1;
    w->adj_start = calloc(np + 1, sizeof *w->adj_start);
    w->adj = malloc(2 * ns * sizeof *w->adj);
    w->a_start = calloc(np + 1, sizeof *w->a_start);
    w->b_start = calloc(np + 1, sizeof *w->b_start);
    w->b_adj = malloc(ns * sizeof *w->b_adj);
    w->hs = malloc(ns * sizeof *w->hs);
    w->hflags = malloc(ns * sizeof *w->hflags);
    w->perm = malloc(ns * sizeof *w->perm);
    w->iperm = malloc(ns * sizeof *w->iperm);
    w->fs = malloc(ns * sizeof *w->fs);
    w->sdiam = malloc(ns * sizeof *w->sdiam);
    w->f = malloc(np * sizeof *w->f);
    w->fext = calloc(np, sizeof *w->fext);
    w->x0 = malloc(np * sizeof *w->x0);
    w->v0 = malloc(np * sizeof *w->v0);
    w->partial = calloc((size_t)w->npartial * SPN_NSUMS, sizeof *w->partial);
    return w->adj_start && w->adj && w->a_start && w->b_start && w->b_adj && w->hs && w->hflags && w->perm && w->iperm && w->fs && w->sdiam && w->f && w->fext && w->x0 && w->v0 && w->partial;
}

/* The runs of particles that end a segment with a diameter (the air is
 * sampled at those), none longer than SPN__AIR_RUN nor crossing a multiple
 * of it, into w->air_runs as (first, last + 1) pairs; `need` has np zeros. */
static bool air_runs(spn_world *w, uint8_t *need)
{
    for (uint32_t s = 0; s < w->ns; s++)
        if (w->sdiam[s] > 0) need[w->hs[s].a] = need[spn__end_b(w->hs[s])] = 1;
    uint32_t n = 0;
    for (int pass = 0; pass < 2; pass++) {
        n = 0;
        for (uint32_t i = 0; i < w->np;) {
            if (!need[i]) {
                i++;
                continue;
            }
            const uint32_t lo = i, edge = (lo / SPN__AIR_RUN + 1) * SPN__AIR_RUN;
            while (i < w->np && i < edge && need[i]) i++;
            if (pass) w->air_runs[2 * n] = lo, w->air_runs[2 * n + 1] = i;
            n++;
        }
        if (!pass && !(w->air_runs = malloc(2 * (size_t)(n ? n : 1) * sizeof *w->air_runs))) return false;
    }
    w->nair_runs = n;
    return true;
}

/* Air buffers, only for worlds with threads that have a diameter. */
static bool alloc_air(spn_world *w)
{
    w->any_diam = false;
    for (uint32_t s = 0; s < w->ns; s++) {
        w->sdiam[s] = tag_diameter(w, w->stag[w->perm[s]]);
        if (w->sdiam[s] > 0) w->any_diam = true;
    }
    if (!w->any_diam) return true;
    w->fair = calloc(w->ns, sizeof *w->fair);
    w->wind = calloc(w->np, sizeof *w->wind);
    w->cair = calloc(w->ns, sizeof *w->cair);
    if (w->air_interval > 0) w->air_held = malloc(9 * (size_t)w->np * sizeof *w->air_held);
    w->air_held_k = NAN; /* (nothing held yet) */
    uint8_t *need = calloc(w->np, 1);
    const bool ok = w->fair && w->wind && w->cair && (w->air_interval == 0 || w->air_held) && need && air_runs(w, need);
    free(need);
    return ok;
}

/* The internal spring order: by lower particle id, ties in public order
 * (counting sort, so it is stable and O(n)); `count` has np + 1 zeros. */
static void order_springs(spn_world *w, uint32_t *count)
{
    for (uint32_t s = 0; s < w->ns; s++) count[(w->sa[s] < w->sb[s] ? w->sa[s] : w->sb[s]) + 1]++;
    for (uint32_t i = 0; i < w->np; i++) count[i + 1] += count[i];
    for (uint32_t s = 0; s < w->ns; s++) w->perm[count[w->sa[s] < w->sb[s] ? w->sa[s] : w->sb[s]]++] = s;
    for (uint32_t k = 0; k < w->ns; k++) {
        uint32_t s = w->perm[k];
        w->iperm[s] = k;
        w->hflags[k] = w->sflags[s];
        w->hs[k] = spn__hot_spring(w, s);
    }
}

/* CSR adjacency by counting sort: each particle's springs in internal order;
 * also the runs of springs by end a and the list by end b the gather reads. */
static void build_adjacency(spn_world *w, uint32_t *fill)
{
    for (uint32_t k = 0; k < w->ns; k++) {
        w->a_start[w->hs[k].a + 1]++;
        w->b_start[spn__end_b(w->hs[k]) + 1]++;
    }
    for (uint32_t i = 0; i < w->np; i++) {
        w->a_start[i + 1] += w->a_start[i];
        w->b_start[i + 1] += w->b_start[i];
    }
    for (uint32_t k = 0; k < w->ns; k++) {
        const uint32_t b = spn__end_b(w->hs[k]);
        w->b_adj[w->b_start[b] + fill[b]++] = k;
    }
    memset(fill, 0, ((size_t)w->np + 1) * sizeof *fill);
    for (uint32_t k = 0; k < w->ns; k++) {
        w->adj_start[w->hs[k].a + 1]++;
        w->adj_start[spn__end_b(w->hs[k]) + 1]++;
    }
    for (uint32_t i = 0; i < w->np; i++) w->adj_start[i + 1] += w->adj_start[i];
    for (uint32_t k = 0; k < w->ns; k++) {
        uint32_t a = w->hs[k].a, b = spn__end_b(w->hs[k]);
        w->adj[w->adj_start[a] + fill[a]++] = k << 1;
        w->adj[w->adj_start[b] + fill[b]++] = (k << 1) | 1u;
    }
}

spn_status spn_world_compile(spn_world *w)
{
    /* (every step, not only the first: spn_world_set_integrator takes any
     * value) */
    spn_status st = spn__check_settings(&w->def);
    if (st != SPN_OK) return st;
    if (w->compiled) return SPN_OK;
    spn__free_compiled(w);
    if (w->np > SPN__END_MASK)
        return spn_error(SPN_ERR_INVALID, "a world steps at most %u particles, not %u", SPN__END_MASK, w->np);
    uint32_t *count = calloc((size_t)w->np + 1, sizeof *count);
    if (!count || !alloc_compiled(w)) {
        free(count);
        spn__free_compiled(w);
        return spn_error(SPN_ERR_NOMEM, "out of memory compiling a world of %u particles and %u springs", w->np, w->ns);
    }
    order_springs(w, count);
    memset(count, 0, ((size_t)w->np + 1) * sizeof *count);
    build_adjacency(w, count);
    free(count);
    spn__lattice_build(w);
    if (!alloc_air(w)) {
        spn__free_compiled(w);
        return spn_error(SPN_ERR_NOMEM, "out of memory for air drag on %u springs", w->ns);
    }
    w->any_limits = false;
    for (uint32_t s = 0; s < w->ns; s++)
        if (w->bmin[s] > 0 || w->bmax[s] < INFINITY) w->any_limits = true;
    w->free_mass = 0;
    for (uint32_t i = 0; i < w->np; i++)
        if (w->inv_mass[i] > 0) w->free_mass += w->mass[i];
    w->compiled = true;
    return SPN_OK;
}

