/* The spring system's product y = A p for spn_world_equilibrium's CG and its
 * multigrid (equilibrium_system.c assembles A): row by row over each free
 * particle's adjacency, each row summing its diagonal block and then its
 * off-diagonal blocks in adjacency order, so every row is its own sum and
 * any thread count gives the same bits.
 *
 * Rows go eight at a time, side by side: a copy of the blocks (made at
 * assembly) holds slot t of a group of eight rows as entry t of each, so the
 * 3x3 products of the eight rows run as plain loops over the lanes, which
 * the compiler vectorises, with each lane's sums in the scalar row order (a
 * row with fewer entries is padded with zero blocks on its own column). A
 * group with a row of more than SPN__EQ_LANE_SLOTS entries (a hub) goes row
 * by row. Measured on the 1M web: 31.7 -> 29.3 s for the whole solve, the
 * same bits; below 32,768 particles it replaced a spring-by-spring product
 * (each block read once, but scattering into y, so on one thread only),
 * which on the 1M web was slower still (33.5 s). */
#include "core/big_alloc.h"
#include "equilibrium_internal.h"
#include "world_internal.h"

#include <stdlib.h>

#define PAR_MIN 32768u /* rows below which the product runs on one thread */
/* Rows from which the multigrid's residuals use float32 blocks (see
 * spn__eq_matvec_mg); below, the product is in cache and not bound by them. */
#define MATVEC32_MIN 32768u

#ifdef _OPENMP /* (used by OpenMP pragmas only) */
static inline int team(const spn__eq *e, uint32_t items) { return items < PAR_MIN ? 1 : e->threads; }
#endif

/* The lane layout of the product (see matvec_lanes): slot t of group g holds
 * entry t of each of its rows; a row with fewer entries is padded with a
 * zero block on its own column. */
spn_status spn__eq_build_lanes(spn__eq *e)
{
    const uint32_t n = e->n, W = SPN__EQ_LANES, groups = (n + W - 1) / W;
    e->lane_start = spn__big_alloc(((size_t)groups + 1) * sizeof *e->lane_start);
    e->lane_by_row = spn__big_alloc(groups ? groups : 1);
    if (!e->lane_start || !e->lane_by_row) return SPN_ERR_NOMEM;
    e->lane_start[0] = 0;
    for (uint32_t g = 0; g < groups; g++) {
        uint32_t longest = 0;
        for (uint32_t i = W * g; i < W * g + W && i < n; i++)
            if (e->adj_start[i + 1] - e->adj_start[i] > longest) longest = e->adj_start[i + 1] - e->adj_start[i];
        e->lane_by_row[g] = longest > SPN__EQ_LANE_SLOTS;
        e->lane_start[g + 1] = e->lane_start[g] + (e->lane_by_row[g] ? 0 : longest);
    }
    const size_t slots = e->lane_start[groups] ? e->lane_start[groups] : 1;
    e->lane_col = spn__big_alloc(W * slots * sizeof *e->lane_col);
    e->lane_val = spn__big_calloc(6 * W * slots, sizeof *e->lane_val);
    e->lane_diag = spn__big_calloc(6 * W * (size_t)(groups ? groups : 1), sizeof *e->lane_diag);
    if (!e->lane_col || !e->lane_val || !e->lane_diag) return SPN_ERR_NOMEM;
    for (uint32_t g = 0; g < groups; g++)
        for (uint32_t q = 0; q < W; q++) {
            const uint32_t i = W * g + q;
            for (uint32_t t = 0; t < e->lane_start[g + 1] - e->lane_start[g]; t++) {
                const uint32_t j = i < n ? e->adj_start[i] + t : 0;
                const bool on = i < n && j < e->adj_start[i + 1];
                e->lane_col[W * (size_t)(e->lane_start[g] + t) + q] = on ? e->adj_col[j] : (int32_t)(i < n ? i : 0);
            }
        }
    return SPN_OK;
}

/* The float32 copy of the lanes, made when the multigrid first asks for it
 * (spn__precond_setup) and kept up to date by every later store. Why not
 * with the lanes: only the multigrid's residuals read it, and on the 1M web
 * it is 132 MB that the cyclic preconditioner (what auto takes there) never
 * read but every assembly wrote: the 1M solve 2.86-3.05 -> 2.67-2.82 s wall,
 * peak 1.21 -> 1.10 GB (two threads, two runs each, alternating). Rounded
 * from the float64 lanes as they stand, which is what the stores since the
 * last assembly would have written: the same floats. */
spn_status spn__eq_lanes32(spn__eq *e)
{
    const uint32_t n = e->n, W = SPN__EQ_LANES, groups = (n + W - 1) / W;
    if (n < MATVEC32_MIN || e->lane_val32) return SPN_OK;
    const size_t vals = 6 * W * (size_t)(e->lane_start[groups] ? e->lane_start[groups] : 1);
    const size_t diags = 6 * W * (size_t)(groups ? groups : 1);
    e->lane_val32 = spn__big_alloc(vals * sizeof *e->lane_val32);
    e->lane_diag32 = spn__big_alloc(diags * sizeof *e->lane_diag32);
    if (!e->lane_val32 || !e->lane_diag32) {
        free(e->lane_val32), free(e->lane_diag32);
        e->lane_val32 = NULL, e->lane_diag32 = NULL;
        return SPN_ERR_NOMEM;
    }
#pragma omp parallel for schedule(static) num_threads(team(e, n))
    for (size_t k = 0; k < vals; k++) e->lane_val32[k] = (float)e->lane_val[k];
    for (size_t k = 0; k < diags; k++) e->lane_diag32[k] = (float)e->lane_diag[k];
    return SPN_OK;
}

/* Row i's diagonal and off-diagonal blocks into the lane layout. */
void spn__eq_lanes_store(spn__eq *e, uint32_t i)
{
    const uint32_t W = SPN__EQ_LANES, g = i / W, q = i % W, slot0 = e->lane_start[g];
    if (e->lane_by_row[g]) return;
    for (int f = 0; f < 6; f++) {
        const size_t k = (6 * (size_t)g + f) * W + q;
        e->lane_diag[k] = e->diag[6 * (size_t)i + f];
        if (e->lane_diag32) e->lane_diag32[k] = (float)e->lane_diag[k];
    }
    for (uint32_t j = e->adj_start[i]; j < e->adj_start[i + 1]; j++) {
        double tmp[6];
        const double *o = spn__eq_offd(e, j, tmp);
        for (int f = 0; f < 6; f++) {
            const size_t k = (6 * (size_t)(slot0 + j - e->adj_start[i]) + f) * W + q;
            e->lane_val[k] = o[f];
            if (e->lane_val32) e->lane_val32[k] = (float)e->lane_val[k];
        }
    }
}

/* Row i of A p: the diagonal block, then the row's off-diagonal blocks
 * stored in adjacency order (a fixed neighbour's entry is zero and points at
 * the row itself, so the loop has no branch). */
static inline void matvec_row(const spn__eq *e, uint32_t i, const double *restrict p, double *restrict y)
{
    const uint32_t *start = e->adj_start;
    const int32_t *col = e->adj_col;
    const double *d = e->diag + 6 * (size_t)i, *pi = p + 3 * (size_t)i;
    /* scalars, not an array: a copy out of a stack array stalls on store forwarding */
    double a0 = d[0] * pi[0] + d[3] * pi[1] + d[4] * pi[2];
    double a1 = d[3] * pi[0] + d[1] * pi[1] + d[5] * pi[2];
    double a2 = d[4] * pi[0] + d[5] * pi[1] + d[2] * pi[2];
    for (uint32_t j = start[i]; j < start[i + 1]; j++) {
        double tmp[6];
        const double *h = spn__eq_offd(e, j, tmp), *v = p + 3 * (size_t)col[j];
        a0 += h[0] * v[0] + h[3] * v[1] + h[4] * v[2];
        a1 += h[3] * v[0] + h[1] * v[1] + h[5] * v[2];
        a2 += h[4] * v[0] + h[5] * v[1] + h[2] * v[2];
    }
    y[3 * (size_t)i] = a0;
    y[3 * (size_t)i + 1] = a1;
    y[3 * (size_t)i + 2] = a2;
}

/* Rows [8 g, 8 g + 8) of A p, side by side: each row's sums in matvec_row's
 * order (the padding adds zeros), on all eight at once as plain loops over
 * the lanes, which the compiler turns into vector instructions. Written
 * once for the blocks in float64 (lane_val, lane_diag: CG's product) and
 * in float32 (lane_val32, lane_diag32: the multigrid's residuals, below);
 * sums in float64 either way. */
#define MATVEC_LANES(NAME, T, VAL, DIAG)                                                                         \
    SPN__KERNEL static void NAME(const spn__eq *e, uint32_t g, const double *restrict p, double *restrict y)     \
    {                                                                                                            \
        enum { W = SPN__EQ_LANES };                                                                              \
        const uint32_t i0 = W * g;                                                                               \
        const T *d = e->DIAG + 6 * W * (size_t)g;                                                                \
        double a0[W], a1[W], a2[W], v0[W], v1[W], v2[W];                                                         \
        for (uint32_t q = 0; q < W; q++) {                                                                       \
            const double *v = p + 3 * (size_t)(i0 + q < e->n ? i0 + q : 0);                                      \
            v0[q] = v[0], v1[q] = v[1], v2[q] = v[2];                                                            \
        }                                                                                                        \
        for (uint32_t q = 0; q < W; q++) {                                                                       \
            a0[q] = ((double)d[q] * v0[q] + (double)d[3 * W + q] * v1[q]) + (double)d[4 * W + q] * v2[q];        \
            a1[q] = ((double)d[3 * W + q] * v0[q] + (double)d[W + q] * v1[q]) + (double)d[5 * W + q] * v2[q];    \
            a2[q] = ((double)d[4 * W + q] * v0[q] + (double)d[5 * W + q] * v1[q]) + (double)d[2 * W + q] * v2[q]; \
        }                                                                                                        \
        for (uint32_t t = e->lane_start[g]; t < e->lane_start[g + 1]; t++) {                                     \
            const int32_t *col = e->lane_col + W * (size_t)t;                                                    \
            const T *h = e->VAL + 6 * W * (size_t)t;                                                             \
            for (uint32_t q = 0; q < W; q++) {                                                                   \
                const double *v = p + 3 * (size_t)col[q];                                                        \
                v0[q] = v[0], v1[q] = v[1], v2[q] = v[2];                                                        \
            }                                                                                                    \
            for (uint32_t q = 0; q < W; q++) {                                                                   \
                a0[q] += ((double)h[q] * v0[q] + (double)h[3 * W + q] * v1[q]) + (double)h[4 * W + q] * v2[q];   \
                a1[q] += ((double)h[3 * W + q] * v0[q] + (double)h[W + q] * v1[q]) + (double)h[5 * W + q] * v2[q]; \
                a2[q] +=                                                                                         \
                    ((double)h[4 * W + q] * v0[q] + (double)h[5 * W + q] * v1[q]) + (double)h[2 * W + q] * v2[q]; \
            }                                                                                                    \
        }                                                                                                        \
        for (uint32_t q = 0; q < W && i0 + q < e->n; q++) {                                                      \
            double *o = y + 3 * (size_t)(i0 + q);                                                                \
            o[0] = a0[q], o[1] = a1[q], o[2] = a2[q];                                                            \
        }                                                                                                        \
    }

MATVEC_LANES(matvec_lanes, double, lane_val, lane_diag)
MATVEC_LANES(matvec_lanes32, float, lane_val32, lane_diag32)
#undef MATVEC_LANES

/* Rows of the groups [g0, g1) of A p: by lanes (float64 or float32
 * blocks), or row by row where a group has a hub row. */
static void matvec_groups(const spn__eq *e, uint32_t g0, uint32_t g1, bool f32, const double *p, double *y)
{
    const uint32_t W = SPN__EQ_LANES;
    for (uint32_t g = g0; g < g1; g++) {
        if (!e->lane_by_row[g]) {
            if (f32) matvec_lanes32(e, g, p, y);
            else matvec_lanes(e, g, p, y);
            continue;
        }
        for (uint32_t i = g * W; i < g * W + W && i < e->n; i++)
            matvec_row(e, i, p, y);
    }
}

/* y = A p and p . y, in fixed chunks of rows added in order. */
double spn__eq_matvec_dot(const spn__eq *e, const double *p, double *y)
{
    const uint32_t n = e->n, nchunks = e->nchunks, W = SPN__EQ_LANES;
#pragma omp parallel for schedule(static) num_threads(team(e, n))
    for (uint32_t c = 0; c < nchunks; c++) {
        uint32_t begin = c * SPN__EQ_CHUNK, end = (c + 1) * SPN__EQ_CHUNK < n ? (c + 1) * SPN__EQ_CHUNK : n;
        matvec_groups(e, begin / W, (end + W - 1) / W, false, p, y);
        double s0 = 0, s1 = 0, s2 = 0;
        for (uint32_t i = begin; i < end; i++) {
            const double *pi = p + 3 * (size_t)i, *yi = y + 3 * (size_t)i;
            s0 += yi[0] * pi[0];
            s1 += yi[1] * pi[1];
            s2 += yi[2] * pi[2];
        }
        e->partial[c] = s0 + s1 + s2;
    }
    double sum = 0;
    for (uint32_t c = 0; c < nchunks; c++) sum += e->partial[c];
    return sum;
}

void spn__eq_matvec(const spn__eq *e, const double *p, double *y) { (void)spn__eq_matvec_dot(e, p, y); }

/* y = A p for the multigrid's residuals (the thread slides' two and the
 * one it restricts): from MATVEC32_MIN rows with the blocks rounded to
 * float32, sums in float64. Its line smoother already reads the blocks in
 * float32; CG's own product stays float64. The float32 blocks are half the
 * bytes of a product that is bound by them: measured 2026-11-22 on the
 * 100k web, a product 4.3% -> 2.7% of the solve's samples. On the small
 * species webs, whose slack threads leave more than one resting shape,
 * it changed the Newton path and the shape reached (araneus: 111 -> 70
 * Newton steps, 0.66 mm from block Jacobi's answer instead of 3.6 um), so
 * they keep the float64 product. */
void spn__eq_matvec_mg(const spn__eq *e, const double *p, double *y)
{
    if (!e->lane_val32) {
        spn__eq_matvec(e, p, y);
        return;
    }
    const uint32_t n = e->n, W = SPN__EQ_LANES, groups = (n + W - 1) / W;
#pragma omp parallel for schedule(static) num_threads(team(e, n))
    for (uint32_t g = 0; g < groups; g++) matvec_groups(e, g, g + 1, true, p, y);
}

void spn__eq_matvec_mg_rows(const spn__eq *e, uint32_t g0, uint32_t g1, const double *p, double *y)
{
    matvec_groups(e, g0, g1, e->lane_val32 != NULL, p, y);
}
