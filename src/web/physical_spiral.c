/* The spiral of the physical construction (Mehla 2005, figs. 5.15 and 5.16).
 * A spiral thread goes from a mass on one spoke to the closest mass on the
 * next spoke, and on round the web. The initial spiral starts threads on the
 * first spoke, from the frame inward; the processed spiral then starts threads
 * on the spoke with the most masses not yet covered, and repeats while any
 * spoke has more than SPIRAL_DENSITY uncovered masses. Threads stop short of
 * the hub (the free zone), so the hub stays distinct.
 * Rules that keep the spiral a spiral (the thesis does not state them; its
 * figures obey them): a mass is joined by one spiral thread at most; between
 * two neighbouring spokes, segments keep their order along both spokes (so no
 * two spiral segments cross); a thread ends where the closest free mass is
 * much farther than the closest mass (it would have to jump a turn). */
#include "physical_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct pair_list {
    int *a, *b;
    int n, cap;
} pair_list;

typedef struct spiral {
    spn__physical *b;
    int ns;
    int **idx;       /* per spoke: indices into spoke ids usable by the spiral, frame end first */
    int *count;
    bool **covered;
    pair_list *pairs; /* segments between spoke s and s + 1, as positions in idx */
} spiral;

static spn_vec3 mass_pos(const spiral *sp, int s, int k)
{
    return spn_world_position(sp->b->wv.w, sp->b->spokes[s].ids[sp->idx[s][k]]);
}

static bool crosses(const pair_list *pl, int a, int c)
{
    for (int i = 0; i < pl->n; i++)
        if ((long)(a - pl->a[i]) * (c - pl->b[i]) < 0) return true;
    return false;
}

static bool add_pair(spn__physical *b, pair_list *pl, int a, int c)
{
    if (pl->n == pl->cap) {
        int cap = pl->cap ? 2 * pl->cap : 16;
        int *na = realloc(pl->a, (size_t)cap * sizeof *na);
        if (na) pl->a = na;
        int *nb = na ? realloc(pl->b, (size_t)cap * sizeof *nb) : NULL;
        if (!na || !nb) {
            b->wv.st = spn_error(SPN_ERR_NOMEM, "out of memory");
            return false;
        }
        pl->b = nb;
        pl->cap = cap;
    }
    pl->a[pl->n] = a;
    pl->b[pl->n++] = c;
    return true;
}

/* One spiral thread from mass k of spoke s, round and inward until it must stop. */
static void thread(spiral *sp, int s, int k)
{
    spn__physical *b = sp->b;
    const spn_physical_def *d = b->def;
    sp->covered[s][k] = true;
    for (long steps = 0; steps < 400L * sp->ns && b->wv.st == SPN_OK; steps++) {
        int t = (s + 1) % sp->ns;
        spn_vec3 p = mass_pos(sp, s, k);
        double nearest = INFINITY, bestd = INFINITY;
        int best = -1;
        for (int c = 0; c < sp->count[t]; c++) {
            double dd = spn_v3_len(spn_v3_sub(mass_pos(sp, t, c), p));
            nearest = fmin(nearest, dd);
            if (dd < bestd && !sp->covered[t][c] && !crosses(&sp->pairs[s], k, c)) bestd = dd, best = c;
        }
        if (best < 0 || bestd > 1.5 * nearest + 0.5 * d->spoke_placement) return;
        uint32_t ia = b->spokes[s].ids[sp->idx[s][k]], ib = b->spokes[t].ids[sp->idx[t][best]];
        spn__spring(&b->wv, ia, ib, SPN_THREAD_CAPTURE, SPN_STAGE_CAPTURE,
                    d->provot ? bestd : bestd / (1 + d->spiral_extension));
        if (!add_pair(b, &sp->pairs[s], k, best)) return;
        sp->covered[t][best] = true;
        s = t;
        k = best;
    }
}

static bool setup(spiral *sp, spn__physical *b)
{
    memset(sp, 0, sizeof *sp);
    sp->b = b;
    sp->ns = b->nspokes;
    sp->idx = calloc((size_t)sp->ns, sizeof *sp->idx);
    sp->count = calloc((size_t)sp->ns, sizeof *sp->count);
    sp->covered = calloc((size_t)sp->ns, sizeof *sp->covered);
    sp->pairs = calloc((size_t)sp->ns, sizeof *sp->pairs);
    if (!sp->idx || !sp->count || !sp->covered || !sp->pairs) return false;
    double inner = b->def->hub_radius + b->def->free_zone;
    for (int s = 0; s < sp->ns; s++) {
        const spn__spoke *k = &b->spokes[s];
        sp->idx[s] = malloc((size_t)k->n * sizeof **sp->idx);
        sp->covered[s] = calloc((size_t)k->n, sizeof **sp->covered);
        if (!sp->idx[s] || !sp->covered[s]) return false;
        /* Not the frame mass itself, not the ring mass, nothing inside the free zone. */
        for (int j = 1; j < k->n - 1; j++)
            if (spn_v3_len(spn_v3_sub(spn_world_position(b->wv.w, k->ids[j]), b->hub)) >= inner)
                sp->idx[s][sp->count[s]++] = j;
    }
    return true;
}

static void teardown(spiral *sp)
{
    for (int s = 0; s < sp->ns; s++) {
        if (sp->idx) free(sp->idx[s]);
        if (sp->covered) free(sp->covered[s]);
        if (sp->pairs) free(sp->pairs[s].a), free(sp->pairs[s].b);
    }
    free(sp->idx);
    free(sp->count);
    free(sp->covered);
    free(sp->pairs);
}

static int uncovered(const spiral *sp, int s)
{
    int n = 0;
    for (int k = 0; k < sp->count[s]; k++) n += !sp->covered[s][k];
    return n;
}

void spn__physical_spiral(spn__physical *b)
{
    if (b->nspokes < 3) {
        b->wv.st = spn_error(SPN_ERR_INVALID, "the web has %d spokes; the frame is too small for its placement lengths",
                             b->nspokes);
        return;
    }
    spiral sp;
    if (!setup(&sp, b)) {
        teardown(&sp);
        b->wv.st = spn_error(SPN_ERR_NOMEM, "out of memory");
        return;
    }
    /* Initial spiral (fig. 5.15): from a first spoke chosen by the seed. */
    int first = (int)spn_rng_below(&b->rng, (uint32_t)sp.ns);
    for (int k = 0; k < sp.count[first] && b->wv.st == SPN_OK; k++)
        if (!sp.covered[first][k]) thread(&sp, first, k);
    /* Processed spiral (fig. 5.16). Every pass covers at least one mass, so it ends. */
    while (b->wv.st == SPN_OK) {
        int best = 0;
        for (int s = 1; s < sp.ns; s++)
            if (uncovered(&sp, s) > uncovered(&sp, best)) best = s;
        if (uncovered(&sp, best) <= b->def->spiral_density) break;
        for (int k = 0; k < sp.count[best] && b->wv.st == SPN_OK; k++)
            if (!sp.covered[best][k]) thread(&sp, best, k);
    }
    teardown(&sp);
}
