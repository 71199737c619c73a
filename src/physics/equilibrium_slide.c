/* Thread-slide correction for the equilibrium multigrid's finest level.
 *
 * Why: a taut net of threads without diagonals (rings x radials) has soft
 * modes that no thread stretches in: a thread sliding along itself, which
 * only shears the threads crossing it (their transverse stiffness T/l, about
 * 1/prestrain = 50 times weaker than the axial EA/l). A ring sliding along
 * itself is a rigid rotation of that ring, and rings rotating by different
 * amounts twist the web. Measured (stationary V-cycles on A x = 0, 5k web,
 * the last Newton system): the error the V-cycle leaves is exactly this,
 * tangential, nearly uniform along each ring and smooth from ring to ring,
 * reduced by only ~0.9 a cycle; with level 1 solved exactly, still 0.82.
 * Aggregates that translate rigidly cannot follow a rotation without
 * stretching the radials between neighbouring rings' aggregates, so the
 * coarse levels do not see these modes as soft.
 *
 * What: one coarse unknown per thread line (equilibrium_lines.c) of two or
 * more particles: its particles displaced along the line's tangent, by 1
 * (a uniform slide) or by a tent, 0 one node beyond either end and 1 in the
 * middle, whichever stretches the web less for its size (z^T A z / z^T z
 * of the first Newton system). A ring slides uniformly: it turns. A radial
 * of the orb web, held at the hub and at the frame, cannot slide uniformly
 * without stretching its end springs, and the tent is the cheaper shape by
 * a factor of about 2.7 there. The V-cycle leaves, with uniform slides, an
 * error of radial displacements smooth from hub to frame and waving 11-14
 * times round the web (the 1M web, stationary cycles), and the spectrum of
 * the preconditioned system a tail of a dozen eigenvalues from 0.03 to 0.11
 * (Lanczos from CG): the radials' tents took the 1M web from 47 to 37 CG
 * and 100k from 24 to 21 (1e-6 T0; 71 -> 64 and 38 -> 35 at 1e-9). The
 * coarse matrix C = Z^T A Z (Z: the slide vectors as columns) is assembled
 * spring by spring from the projected Hessian blocks and factored densely
 * (lines: 164 on the 5k web, 649 at 100k, 1,999 at 1M). The correction
 * x += Z C^-1 Z^T (b - A x) is applied before and after the aggregation
 * multigrid's coarse correction, so the V-cycle stays symmetric.
 * Every sum runs in a fixed order: the same bits for any thread count. */
#include "core/big_alloc.h"
#include "equilibrium_bsr.h"
#include "equilibrium_internal.h"
#include "world_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Lines above which the dense C (8 N^2 bytes, N^3 / 3 to factor) costs
 * more than it saves: 2,000 on the 1M web is 32 MB and 2.7 GFlop a
 * factorisation (0.35 s; refactored every Newton step there). */
#define SLIDE_MAX 3000u
/* Free particles from which the assembly and the correction use threads. */
#define SLIDE_PAR_MIN 16384u
static inline int slide_team(const spn__eq *e) { return e->n < SLIDE_PAR_MIN ? 1 : e->threads; }
/* Parts of the particles that Z^T (b - A x) sums separately from
 * SLIDE_PAR_MIN particles (then adds in order): fixed, so the same bits on
 * any team; below, one, in particle order. */
#define SLIDE_PARTS 16u
static inline uint32_t slide_parts(const spn__eq *e) { return e->n < SLIDE_PAR_MIN ? 1 : SLIDE_PARTS; }

struct spn__slide {
    uint32_t nz;        /* coarse unknowns: lines of two or more particles */
    uint32_t *pstart;   /* n + 1: a free particle's entries */
    uint32_t *pcol;     /* per entry: its line's coarse unknown */
    double *ptan;       /* 3 per entry: the line's unit tangent at the particle */
    double *c;          /* nz x nz: C, then its Cholesky factor (lower, row-major) */
    double *w;          /* nz */
    double *wpart;      /* nz per part (slide_parts): its particles' share of Z^T (b - A x) */
};

void spn__slide_free(spn__slide *S)
{
    if (!S) return;
    free(S->pstart), free(S->pcol), free(S->ptan), free(S->c), free(S->w), free(S->wpart);
    free(S);
}

/* Unit tangent of line nodes [k0, k1) at node k, from its neighbours on the line. */
static void tangent(const spn__eq *e, const uint32_t *node, uint32_t k0, uint32_t k1, uint32_t k, double *t)
{
    uint32_t a = node[k > k0 ? k - 1 : k], b = node[k + 1 < k1 ? k + 1 : k];
    double len = 0;
    for (int c = 0; c < 3; c++) {
        t[c] = e->x[3 * (size_t)b + c] - e->x[3 * (size_t)a + c];
        len += t[c] * t[c];
    }
    len = sqrt(len);
    for (int c = 0; c < 3; c++) t[c] = len > 0 ? t[c] / len : 0;
}

/* A slide's weight at node t of a line of len nodes: 1 (uniform), or a tent
 * that is 0 one node beyond either end and 1 in the middle. */
static double slide_weight(bool tent, uint32_t t, uint32_t len)
{
    if (!tent) return 1;
    double x = (double)(t + 1) / (len + 1);
    return x < 0.5 ? 2 * x : 2 * (1 - x);
}

/* True when the tent slide of line nodes [k0, k1) stretches the web less
 * for its size (z^T A z / z^T z) than the uniform slide, both from each
 * spring at a line node. tan: the line's unit tangents, 3 a node; at[p]:
 * particle p's node when it is on the line, else UINT32_MAX (a spring
 * between two of the line's nodes is met from both ends, half each time). */
static bool tent_is_softer(const spn__eq *e, const uint32_t *node, const uint32_t *at, uint32_t k0, uint32_t k1,
                           const double *tan)
{
    const uint32_t len = k1 - k0;
    double energy[2] = {0, 0}, norm[2] = {0, 0}; /* uniform, tent */
    for (uint32_t k = k0; k < k1; k++) {
        const double *t = tan + 3 * (size_t)(k - k0), w = slide_weight(true, k - k0, len);
        norm[0] += 1, norm[1] += w * w;
        const uint32_t i = node[k];
        for (uint32_t j = e->adj_start[i]; j < e->adj_start[i + 1]; j++) {
            const int32_t o = e->adj_other[j];
            const double *h = e->hs + 6 * (size_t)(e->adj[j] >> 1);
            double du[3] = {t[0], t[1], t[2]}, dt[3] = {w * t[0], w * t[1], w * t[2]}, part = 1;
            if (o >= 0 && at[o] != UINT32_MAX) {
                const double *to = tan + 3 * (size_t)(at[o] - k0), wo = slide_weight(true, at[o] - k0, len);
                for (int c = 0; c < 3; c++) du[c] -= to[c], dt[c] -= wo * to[c];
                part = 0.5;
            }
            double hu[3], ht[3];
            spn__sym_mul(h, du, hu);
            spn__sym_mul(h, dt, ht);
            energy[0] += part * (du[0] * hu[0] + du[1] * hu[1] + du[2] * hu[2]);
            energy[1] += part * (dt[0] * ht[0] + dt[1] * ht[1] + dt[2] * ht[2]);
        }
    }
    return energy[1] * norm[0] < energy[0] * norm[1];
}

/* Each line of two or more particles: its shape (tent_is_softer), then its
 * entries written, the shape's weight times the unit tangent at each node,
 * into the places `slot` gives them in their particles' lists, with the
 * line's coarse unknown `unknown[l]`. The lines are shared out over the
 * team: each thread with its own scratch, each line's entries its own (the
 * same on any team). False: out of memory. */
static bool fill_slides(spn__slide *S, const spn__eq *e, const uint32_t *start, const uint32_t *node, uint32_t count,
                        const uint32_t *slot, const uint32_t *unknown)
{
    uint32_t longest = 0;
    for (uint32_t l = 0; l < count; l++)
        if (start[l + 1] - start[l] > longest) longest = start[l + 1] - start[l];
    int bad = 0;
#pragma omp parallel num_threads(slide_team(e)) reduction(+ : bad)
    {
        uint32_t *at = malloc((e->n ? e->n : 1) * sizeof *at);
        double *tan = malloc(3 * (size_t)(longest ? longest : 1) * sizeof *tan);
        bad += !at || !tan;
        for (uint32_t i = 0; at && i < e->n; i++) at[i] = UINT32_MAX;
#pragma omp for schedule(dynamic, 16)
        for (uint32_t l = 0; l < count; l++) {
            const uint32_t k0 = start[l], k1 = start[l + 1];
            if (k1 - k0 < 2 || !at || !tan) continue;
            for (uint32_t k = k0; k < k1; k++) {
                at[node[k]] = k;
                tangent(e, node, k0, k1, k, tan + 3 * (size_t)(k - k0));
            }
            const bool tent = tent_is_softer(e, node, at, k0, k1, tan);
            for (uint32_t k = k0; k < k1; k++) {
                const double w = slide_weight(tent, k - k0, k1 - k0);
                double *t = S->ptan + 3 * (size_t)slot[k];
                for (int c = 0; c < 3; c++) t[c] = tan[3 * (size_t)(k - k0) + c] * w;
                S->pcol[slot[k]] = unknown[l];
                at[node[k]] = UINT32_MAX;
            }
        }
        free(at), free(tan);
    }
    return bad == 0;
}

spn__slide *spn__slide_build(const spn__eq *e, const spn__lines *L)
{
    uint32_t count, total, nz = 0;
    const uint32_t *start, *node;
    spn__lines_nodes(L, &count, &start, &node);
    total = start[count];
    spn__slide *S = calloc(1, sizeof *S);
    if (!S) return NULL;
    S->pstart = spn__big_calloc((size_t)e->n + 1, sizeof *S->pstart);
    S->pcol = spn__big_alloc((total ? total : 1) * sizeof *S->pcol);
    S->ptan = spn__big_alloc(3 * (size_t)(total ? total : 1) * sizeof *S->ptan);
    uint32_t *fill = calloc(e->n ? e->n : 1, sizeof *fill), *slot = malloc((total ? total : 1) * sizeof *slot);
    uint32_t *unknown = malloc((count ? count : 1) * sizeof *unknown);
    bool ok = S->pstart && S->pcol && S->ptan && fill && slot && unknown;
    /* a particle's entries in the order of its lines; a line's unknown its
     * rank among the lines of two or more particles */
    for (uint32_t l = 0; ok && l < count; l++)
        if (start[l + 1] - start[l] >= 2)
            for (uint32_t k = start[l]; k < start[l + 1]; k++) S->pstart[node[k] + 1]++;
    for (uint32_t i = 0; ok && i < e->n; i++) S->pstart[i + 1] += S->pstart[i];
    for (uint32_t l = 0; ok && l < count; l++) {
        if (start[l + 1] - start[l] < 2) continue;
        for (uint32_t k = start[l]; k < start[l + 1]; k++) slot[k] = S->pstart[node[k]] + fill[node[k]]++;
        unknown[l] = nz++;
    }
    ok = ok && fill_slides(S, e, start, node, count, slot, unknown);
    free(fill), free(slot), free(unknown);
    S->nz = nz;
    if (!ok || nz > SLIDE_MAX || nz == 0) {
        spn__slide_free(S);
        return NULL;
    }
    S->c = spn__big_alloc((nz ? (size_t)nz * nz : 1) * sizeof *S->c);
    S->w = spn__big_alloc((nz ? nz : 1) * sizeof *S->w);
    S->wpart = malloc((size_t)slide_parts(e) * (nz ? nz : 1) * sizeof *S->wpart);
    if (!S->c || !S->w || !S->wpart) {
        spn__slide_free(S);
        return NULL;
    }
    return S;
}

/* C += sign * t_i^T H t_j over the entries of particles a (sign +) and b
 * (sign -), in C's rows [r0, r1) only. */
static void add_spring(spn__slide *S, const double *h, uint32_t a, int64_t b, uint32_t r0, uint32_t r1)
{
    const uint32_t nz = S->nz;
    uint32_t ia0 = S->pstart[a], ia1 = S->pstart[a + 1];
    uint32_t ib0 = b >= 0 ? S->pstart[b] : 0, ib1 = b >= 0 ? S->pstart[b + 1] : 0;
    for (int side_i = 0; side_i < 2; side_i++) {
        uint32_t i0 = side_i ? ib0 : ia0, i1 = side_i ? ib1 : ia1;
        for (uint32_t i = i0; i < i1; i++) {
            if (S->pcol[i] < r0 || S->pcol[i] >= r1) continue;
            double ht[3];
            spn__sym_mul(h, S->ptan + 3 * (size_t)i, ht);
            double *row = S->c + (size_t)S->pcol[i] * nz;
            for (int side_j = 0; side_j < 2; side_j++) {
                uint32_t j0 = side_j ? ib0 : ia0, j1 = side_j ? ib1 : ia1;
                double sign = side_i == side_j ? 1 : -1;
                for (uint32_t j = j0; j < j1; j++) {
                    const double *t = S->ptan + 3 * (size_t)j;
                    row[S->pcol[j]] += sign * (ht[0] * t[0] + ht[1] * t[1] + ht[2] * t[2]);
                }
            }
        }
    }
}

/* C is assembled in bands of rows, a band per thread: each thread reads
 * every spring and adds only into its own rows, so each entry still sums
 * its springs in their order (the same bits on any thread count) and no two
 * threads write one row. One thread took 0.17 s of the 1M web's 0.29 s
 * a Newton step here, mostly waiting on the scattered rows of C. */
bool spn__slide_factor(spn__slide *S, const spn__eq *e)
{
    const size_t N = S->nz;
    double *f = S->c;
    const int nt = slide_team(e);
#pragma omp parallel num_threads(nt)
    {
        const uint32_t t = (uint32_t)spn__thread_num(), team = (uint32_t)spn__thread_count();
        const uint32_t r0 = (uint32_t)(N * t / team), r1 = (uint32_t)(N * (t + 1) / team);
        memset(f + (size_t)r0 * N, 0, (size_t)(r1 - r0) * N * sizeof *f);
        for (uint32_t s = 0; s < e->m; s++)
            add_spring(S, e->hs + 6 * (size_t)s, e->sa[s], e->sb[s] < e->n ? (int64_t)e->sb[s] : -1, r0, r1);
        if (e->lambda > 0)
            for (uint32_t p = 0; p < e->n; p++) {
                double h[6] = {e->lambda * e->kscale[p], e->lambda * e->kscale[p], e->lambda * e->kscale[p], 0, 0, 0};
                add_spring(S, h, p, -1, r0, r1);
            }
    }
    /* a line whose slide stretches nothing and shears nothing (a free thread
     * end to end) would make C singular: a relative shift keeps it factorable */
    double big = 0;
    for (size_t k = 0; k < N; k++) big = fmax(big, f[k * N + k]);
    for (size_t k = 0; k < N; k++) f[k * N + k] += 1e-12 * big;
    return spn__dense_cholesky(f, N, nt);
}

/* Z^T (b - A x) in one pass: each part of the particles (whole groups of
 * the product's lanes) forms its rows of A x, turns them into r = b - A x
 * while they are in cache, and adds t . r_p into its own sums, in particle
 * order; the parts' sums are then added in order. Before, r was written by
 * the product, subtracted from b in a second pass and gathered a third time
 * by coarse unknown (a radial's particles are a ring apart). */
static void project_residual(const spn__slide *S, const spn__eq *e, const double *b, const double *x, double *r)
{
    const uint32_t N = S->nz, W = SPN__EQ_LANES, groups = (e->n + W - 1) / W, parts = slide_parts(e);
    const int nt = slide_team(e) < (int)parts ? slide_team(e) : (int)parts;
    (void)nt;
#pragma omp parallel for schedule(static) num_threads(nt)
    for (uint32_t k = 0; k < parts; k++) {
        const uint32_t g0 = (uint32_t)((uint64_t)groups * k / parts), g1 = (uint32_t)((uint64_t)groups * (k + 1) / parts);
        const uint32_t p1 = W * g1 < e->n ? W * g1 : e->n;
        double *wk = S->wpart + (size_t)k * N;
        memset(wk, 0, N * sizeof *wk);
        spn__eq_matvec_mg_rows(e, g0, g1, x, r);
        for (uint32_t p = W * g0; p < p1; p++) {
            double *rp = r + 3 * (size_t)p;
            const double *bp = b + 3 * (size_t)p;
            rp[0] = bp[0] - rp[0], rp[1] = bp[1] - rp[1], rp[2] = bp[2] - rp[2];
            for (uint32_t q = S->pstart[p]; q < S->pstart[p + 1]; q++) {
                const double *t = S->ptan + 3 * (size_t)q;
                wk[S->pcol[q]] += t[0] * rp[0] + t[1] * rp[1] + t[2] * rp[2];
            }
        }
    }
    double *w = S->w;
    memcpy(w, S->wpart, N * sizeof *w);
    for (uint32_t k = 1; k < parts; k++)
        for (uint32_t z = 0; z < N; z++) w[z] += S->wpart[(size_t)k * N + z];
}

void spn__slide_correct(const spn__slide *S, const spn__eq *e, const double *b, double *x, double *r)
{
    const size_t N = S->nz;
    double *w = S->w;
    project_residual(S, e, b, x, r);
    spn__dense_cholesky_solve(S->c, N, w, w, slide_team(e));
#pragma omp parallel for schedule(static) num_threads(slide_team(e))
    for (uint32_t p = 0; p < e->n; p++)
        for (uint32_t q = S->pstart[p]; q < S->pstart[p + 1]; q++) {
            const double *t = S->ptan + 3 * (size_t)q, y = w[S->pcol[q]];
            double *xp = x + 3 * (size_t)p;
            xp[0] += y * t[0], xp[1] += y * t[1], xp[2] += y * t[2];
        }
}
