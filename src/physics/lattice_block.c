/* Several Euler or symplectic Euler steps of the float64 lattice in one pass
 * over memory (temporal blocking). A web of a million particles keeps
 * 160 bytes per particle in play (state, spring slots, masses), far more
 * than the caches, so one step per pass is bound by memory bandwidth (4.4 ns
 * per spring on two threads against 3.7 of arithmetic). Here a pass takes
 * the state LAT_LEVELS steps forward: each row is read from memory once per
 * block, and the rows in flight stay in the caches.
 *
 * The schedule. One row step, op(s, j), is lattice.c's loop body at level
 * s (the state after s steps of the block): the radial springs into row j
 * and the ring springs of row j at level s - 1, then row j - 1 moved to level
 * s. It needs rows j - 1 and j at level s - 1 and moves row j - 1 in place,
 * so it must come after op(s - 1, j + 1) (which brought row j to level s - 1)
 * and after op(s, j - 1). Fronts J = 0, 1, ... run op(s, J - s + 1) for
 * s = 1 .. K in that order: a wavefront K rows deep.
 *
 * Threads. Each thread takes a contiguous run of bands. It needs the rows
 * within K of its run from its neighbours at every level before they move,
 * so it copies those ghost rows (level 0) into its own buffers first, and,
 * after a barrier, steps them along privately: the rows it may step at level
 * s shrink by one at each side per level (a trapezoid), and at level K they
 * are its own rows exactly. Ghost rows are stepped twice (by each side),
 * 2 K rows per boundary.
 *
 * Same bits. Every particle gets the same arithmetic as in one-step sweeps,
 * so the trajectory is bit-identical to K single steps whatever the thread
 * count. The energy sums of each step are kept per band and per level, in
 * the order of lattice.c's band_pass (the first row's radial springs, the
 * "cut", summed apart), so they are bit-identical too. */
#include "lattice_rows.h"
#include "world_internal.h"

#include <stdlib.h>
#include <string.h>

/* Per level: the two latest rows' radial and ring forces, the lane sums of
 * two bands (the band whose springs and the band whose particles are being
 * summed differ at a band's first row) and of the current band's cut. */
typedef struct level {
    double *rad[2][3], *ring[2][3];
    double **rad_prev;
    int cur;
    double acc_e[2][LANES], acc_p[2][LANES], cut_e[2][LANES], cut_p[2][LANES], acc[2][L_NSUMS][LANES];
} level;

typedef struct block {
    const lat_args *a;
    uint32_t R0, R1, K;       /* own rows [R0, R1), levels */
    double *ghost[2 * LAT_LEVELS][6];
    double *hub[6], *e, *p, *t[3];
    double dummy[L_NSUMS + 4][LANES];
    level lv[LAT_LEVELS];
} block;

/* Row j's x and v arrays: the state for own rows, a ghost buffer else. */
static void row_ptrs(const block *B, uint32_t j, double **X, double **V)
{
    const spn__lattice *L = B->a->L;
    if (j >= B->R0 && j < B->R1) {
        const size_t p0 = 1 + (size_t)j * L->radials;
        for (int c = 0; c < 3; c++) X[c] = L->x[c] + p0, V[c] = L->v[c] + p0;
        return;
    }
    const uint32_t g = j < B->R0 ? j - (B->R0 - B->K) : B->K + (j - B->R1);
    for (int c = 0; c < 3; c++) X[c] = B->ghost[g][c], V[c] = B->ghost[g][3 + c];
}

static uint32_t band_of(const spn__lattice *L, uint32_t j) { return j / L->band_rows; }

static bool own(const block *B, uint32_t j) { return j >= B->R0 && j < B->R1; }

/* Lowest and one past the highest row this block steps at level s. */
static uint32_t low(const block *B, uint32_t s) { return B->R0 ? B->R0 - B->K + s : 0; }

static uint32_t high(const block *B, uint32_t s)
{
    const uint32_t rings = B->a->L->rings;
    return B->R1 == rings ? rings : B->R1 + B->K - s;
}

/* Band b's sums at level s (index s - 1) into its partial, as cut_pass and
 * band_pass leave them. */
static void store_level(const block *B, double *partial, uint32_t s, uint32_t b)
{
    level *lv = (level *)&B->lv[s - 1];
    const int q = (int)(b & 1);
    const spn__lattice *L = B->a->L;
    double *out = partial + ((size_t)(s - 1) * L->nbands + b) * L_NSUMS;
    if (b) out[L_ELASTIC] = lane_total(lv->cut_e[q]), out[L_DAMP] = lane_total(lv->cut_p[q]);
    store_band_sums(out, b == 0, lv->acc_e[q], lv->acc_p[q], lv->acc[q]);
    memset(lv->acc_e[q], 0, sizeof lv->acc_e[q]), memset(lv->acc_p[q], 0, sizeof lv->acc_p[q]);
    memset(lv->cut_e[q], 0, sizeof lv->cut_e[q]), memset(lv->cut_p[q], 0, sizeof lv->cut_p[q]);
    memset(lv->acc[q], 0, sizeof lv->acc[q]);
}

/* op(s, j): see the file comment. (Inlined into run_block, so that each
 * target_clones version of it vectorises its own copy.) */
LAT_INLINE void op(block *B, double *partial, uint32_t s, uint32_t j)
{
    const lat_args *a = B->a;
    const spn__lattice *L = a->L;
    level *lv = &B->lv[s - 1];
    const uint32_t n = L->radials, rings = L->rings, hi = high(B, s);
    const int cur = lv->cur;
    double *X[3], *V[3], *Xp[3], *Vp[3];
    if (j < rings) row_ptrs(B, j, X, V);
    if (j < rings) {
        const size_t s0 = (size_t)j * n;
        const bool mine = own(B, j) && j < hi;
        const int q = (int)(band_of(L, j) & 1);
        const bool cut = j > 0 && j % L->band_rows == 0;
        double *ae = mine ? (cut ? lv->cut_e[q] : lv->acc_e[q]) : B->dummy[0];
        double *ap = mine ? (cut ? lv->cut_p[q] : lv->acc_p[q]) : B->dummy[1];
        if (j == 0) {
            for (int c = 0; c < 3; c++) {
                const double hx = L->x[c][0], hv = L->v[c][0];
                for (uint32_t i = 0; i < n; i++) B->hub[c][i] = hx, B->hub[3 + c][i] = hv;
            }
            springs_rows(n, (const double *const *)B->hub, (const double *const *)B->hub + 3,
                         (const double *const *)X, (const double *const *)V, 0, 0, L->rk, L->rkd, L->rrest,
                         lv->rad[cur], 0, B->e, B->p, ae, ap);
            lat_hub_move(a, lv->rad[cur], lv->acc[q]);
        } else {
            row_ptrs(B, j - 1, Xp, Vp);
            springs_rows(n, (const double *const *)Xp, (const double *const *)Vp, (const double *const *)X,
                         (const double *const *)V, 0, 0, L->rk + s0, L->rkd + s0, L->rrest + s0, lv->rad[cur], 0,
                         B->e, B->p, ae, ap);
        }
        if (j < hi) {
            double *re = mine ? lv->acc_e[q] : B->dummy[0], *rp = mine ? lv->acc_p[q] : B->dummy[1];
            springs_rows(n - 1, (const double *const *)X, (const double *const *)V, (const double *const *)X,
                         (const double *const *)V, 0, 1, L->gk + s0, L->gkd + s0, L->grest + s0, lv->ring[cur], 0,
                         B->e, B->p, re, rp);
            springs_rows(1, (const double *const *)X, (const double *const *)V, (const double *const *)X,
                         (const double *const *)V, 0, n - 1, L->gk + s0 + n - 1, L->gkd + s0 + n - 1,
                         L->grest + s0 + n - 1, lv->ring[cur], n - 1, B->e, B->p, re, rp);
        }
    }
    if (j > low(B, s)) {
        const uint32_t r = j - 1;
        const size_t p0 = 1 + (size_t)r * n;
        row_ptrs(B, r, Xp, Vp);
        const bool mine = own(B, r);
        const uint32_t b = band_of(L, r);
        double(*acc)[LANES] = mine ? lv->acc[b & 1] : B->dummy + 2;
        lat_row_move(a, p0, n, Xp, Vp, lv->rad_prev, lv->ring[cur ^ 1], j < rings ? lv->rad[cur] : NULL, B->t, acc);
        const uint32_t band_end = (b + 1) * L->band_rows < rings ? (b + 1) * L->band_rows : rings;
        if (mine && r + 1 == band_end) store_level(B, partial, s, b);
    }
    lv->rad_prev = lv->rad[cur];
    lv->cur ^= 1;
}

/* The workspace of one thread for K levels, stride doubles per array. */
static size_t block_doubles(size_t stride) { return (size_t)(12 * LAT_LEVELS + 12 * LAT_LEVELS + 11) * stride; }

static void block_init(block *B, const lat_args *a, double *ws, uint32_t R0, uint32_t R1, uint32_t K)
{
    const size_t st = a->L->stride;
    memset(B, 0, sizeof *B);
    B->a = a, B->R0 = R0, B->R1 = R1, B->K = K;
    double *q = ws;
    for (uint32_t s = 0; s < LAT_LEVELS; s++)
        for (int r = 0; r < 2; r++)
            for (int c = 0; c < 3; c++) B->lv[s].rad[r][c] = q, q += st, B->lv[s].ring[r][c] = q, q += st;
    for (uint32_t g = 0; g < 2 * LAT_LEVELS; g++)
        for (int c = 0; c < 6; c++) B->ghost[g][c] = q, q += st;
    for (int c = 0; c < 6; c++) B->hub[c] = q, q += st;
    B->e = q, q += st, B->p = q, q += st;
    for (int c = 0; c < 3; c++) B->t[c] = q, q += st;
}

/* Level 0 of the ghost rows, from the state before anyone moves it. */
static void copy_ghosts(block *B)
{
    const spn__lattice *L = B->a->L;
    const uint32_t n = L->radials;
    for (uint32_t g = 0; g < 2 * B->K; g++) {
        const uint32_t j = g < B->K ? B->R0 - B->K + g : B->R1 + (g - B->K);
        if ((g < B->K && !B->R0) || (g >= B->K && j >= L->rings)) continue;
        const size_t p0 = 1 + (size_t)j * n;
        for (int c = 0; c < 3; c++) {
            memcpy(B->ghost[g][c], L->x[c] + p0, n * sizeof(double));
            memcpy(B->ghost[g][3 + c], L->v[c] + p0, n * sizeof(double));
        }
    }
}

SPN__KERNEL static void run_block(block *B, double *partial)
{
    const uint32_t K = B->K, first = low(B, 1), last = high(B, K) + K - 1;
    for (uint32_t J = first; J <= last; J++)
        for (uint32_t s = 1; s <= K; s++) {
            if (J + 1 < s) break;
            const uint32_t j = J + 1 - s;
            if (j >= low(B, s) && j <= high(B, s)) op(B, partial, s, j);
        }
}

bool spn__lattice_block_ready(const spn__lattice *L, int threads, uint32_t K)
{
    /* each thread's run of bands at least 4 K rows, so the ghosts cost at
     * most a quarter */
    const uint32_t per = L->nbands / (uint32_t)threads;
    return K >= 2 && K <= LAT_LEVELS && per >= 1 && per * L->band_rows >= 4 * K;
}

bool spn__lattice_block(spn__lattice *L, const lat_args *a, int threads, uint32_t K, double sums[][L_NSUMS])
{
    const size_t need = block_doubles(L->stride);
    if (L->block_size < need || L->nbws < threads) {
        for (int t = 0; t < L->nbws; t++) free(L->bws[t]);
        free(L->bws);
        L->nbws = 0;
        L->block_size = 0;
        if (!(L->bws = calloc((size_t)threads, sizeof *L->bws))) return false;
        for (; L->nbws < threads; L->nbws++)
            if (!(L->bws[L->nbws] = malloc(need * sizeof(double)))) return false;
        L->block_size = need;
    }
    if (L->npartial_k < L->nbands) {
        free(L->partial_k);
        L->npartial_k = 0;
        if (!(L->partial_k = malloc((size_t)LAT_LEVELS * L->nbands * L_NSUMS * sizeof(double)))) return false;
        L->npartial_k = L->nbands;
    }
    const uint32_t nb = L->nbands;
#pragma omp parallel num_threads(threads)
    {
        const int t = spn__thread_num();
        const uint32_t b0 = (uint32_t)((uint64_t)nb * (uint32_t)t / (uint32_t)threads);
        const uint32_t b1 = (uint32_t)((uint64_t)nb * (uint32_t)(t + 1) / (uint32_t)threads);
        const uint32_t R0 = b0 * L->band_rows, R1 = b1 * L->band_rows < L->rings ? b1 * L->band_rows : L->rings;
        block B;
        block_init(&B, a, L->bws[t], R0, R1, K);
        copy_ghosts(&B);
#pragma omp barrier
        run_block(&B, L->partial_k);
    }
    for (uint32_t s = 0; s < K; s++) {
        for (int k = 0; k < L_NSUMS; k++) sums[s][k] = 0;
        for (uint32_t b = 0; b < nb; b++)
            for (int k = 0; k < L_NSUMS; k++) sums[s][k] += L->partial_k[((size_t)s * nb + b) * L_NSUMS + k];
    }
    return true;
}
