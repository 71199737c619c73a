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
    const lat_args *la;       /* per level: the step's arguments (RK4: the stage's) */
    const spn__lattice *L;
    bool rk4;
    uint32_t R0, R1, K;       /* own rows [R0, R1), levels */
    double *ghost[2 * LAT_LEVELS][6];
    double *hub[6], *e, *p, *t[3], *F[3];
    /* RK4: the trial state of levels 1-3 by row mod 4 and the weighted sums
     * ax, av by row mod 8 (a row's live for at most 2 and 5 fronts), and
     * the hub's */
    double *trial[LAT_LEVELS - 1][4][6], *sums[8][6];
    double hub_trial[LAT_LEVELS - 1][6], hub_sums[6];
    double dummy[L_NSUMS + 4][LANES];
    level lv[LAT_LEVELS];
} block;

/* Row j's x and v arrays: the state for own rows, a ghost buffer else. */
static void row_ptrs(const block *B, uint32_t j, double **X, double **V)
{
    const spn__lattice *L = B->L;
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

/* Row j at level s - 1, the state the forces of level s are taken at: the
 * state itself, or an RK4 trial state. */
static void eval_ptrs(const block *B, uint32_t s, uint32_t j, double **X, double **V)
{
    if (!B->rk4 || s == 1) {
        row_ptrs(B, j, X, V);
        return;
    }
    double *const *T = B->trial[s - 2][j % 4];
    for (int c = 0; c < 3; c++) X[c] = T[c], V[c] = T[3 + c];
}

/* Lowest and one past the highest row this block steps at level s. */
static uint32_t low(const block *B, uint32_t s) { return B->R0 ? B->R0 - B->K + s : 0; }

static uint32_t high(const block *B, uint32_t s)
{
    const uint32_t rings = B->L->rings;
    return B->R1 == rings ? rings : B->R1 + B->K - s;
}

/* Band b's sums at level s (index s - 1) into its partial, as cut_pass and
 * band_pass leave them. */
static void store_level(const block *B, double *partial, uint32_t s, uint32_t b)
{
    level *lv = (level *)&B->lv[s - 1];
    const int q = (int)(b & 1);
    const spn__lattice *L = B->L;
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
    const lat_args *a = &B->la[s - 1];
    const spn__lattice *L = B->L;
    level *lv = &B->lv[s - 1];
    const uint32_t n = L->radials, rings = L->rings, hi = high(B, s);
    const int cur = lv->cur;
    double *X[3], *V[3], *Xp[3], *Vp[3];
    if (j < rings) {
        eval_ptrs(B, s, j, X, V);
        const size_t s0 = (size_t)j * n;
        const bool mine = own(B, j) && j < hi;
        const int q = (int)(band_of(L, j) & 1);
        const bool cut = j > 0 && j % L->band_rows == 0;
        double *ae = mine ? (cut ? lv->cut_e[q] : lv->acc_e[q]) : B->dummy[0];
        double *ap = mine ? (cut ? lv->cut_p[q] : lv->acc_p[q]) : B->dummy[1];
        if (j == 0) {
            double hx[3], hv[3];
            const bool base = !B->rk4 || s == 1;
            for (int c = 0; c < 3; c++) {
                hx[c] = base ? L->x[c][0] : B->hub_trial[s - 2][c];
                hv[c] = base ? L->v[c][0] : B->hub_trial[s - 2][3 + c];
                for (uint32_t i = 0; i < n; i++) B->hub[c][i] = hx[c], B->hub[3 + c][i] = hv[c];
            }
            springs_rows(n, (const double *const *)B->hub, (const double *const *)B->hub + 3,
                         (const double *const *)X, (const double *const *)V, 0, 0, L->rk, L->rkd, L->rrest,
                         lv->rad[cur], 0, B->e, B->p, ae, ap);
            if (B->rk4) {
                double f[3], *Fp[3] = {f, f + 1, f + 2};
                lat_hub_force(a, hv, lv->rad[cur], f);
                rk4_rows R;
                for (int c = 0; c < 3; c++) {
                    R.V[c] = &hv[c], R.xb[c] = &L->x[c][0], R.vb[c] = &L->v[c][0];
                    R.xt[c] = s < 4 ? &B->hub_trial[s - 1][c] : NULL;
                    R.vt[c] = s < 4 ? &B->hub_trial[s - 1][3 + c] : NULL;
                    R.ax[c] = &B->hub_sums[c], R.av[c] = &B->hub_sums[3 + c];
                }
                lat_rk4_update(a, 0, 1, &R, Fp, B->t, lv->acc[q]);
            } else {
                lat_hub_move(a, lv->rad[cur], lv->acc[q]);
            }
        } else {
            eval_ptrs(B, s, j - 1, Xp, Vp);
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
        const bool mine = own(B, r);
        const uint32_t b = band_of(L, r);
        double(*acc)[LANES] = mine ? lv->acc[b & 1] : B->dummy + 2;
        double *const *ro = j < rings ? lv->rad[cur] : NULL;
        row_ptrs(B, r, Xp, Vp);
        if (B->rk4) {
            double *EX[3], *EV[3];
            eval_ptrs(B, s, r, EX, EV);
            rk4_rows R;
            for (int c = 0; c < 3; c++) {
                assemble64(n, a->g[c], a->drag, a->mass + p0, EV[c], lv->rad_prev[c], lv->ring[cur ^ 1][c],
                           ro ? ro[c] : NULL, B->F[c]);
                R.V[c] = EV[c], R.xb[c] = Xp[c], R.vb[c] = Vp[c];
                R.xt[c] = s < 4 ? B->trial[s - 1][r % 4][c] : NULL;
                R.vt[c] = s < 4 ? B->trial[s - 1][r % 4][3 + c] : NULL;
                R.ax[c] = B->sums[r % 8][c], R.av[c] = B->sums[r % 8][3 + c];
            }
            lat_rk4_update(a, p0, n, &R, B->F, B->t, acc);
        } else {
            lat_row_move(a, p0, n, Xp, Vp, lv->rad_prev, lv->ring[cur ^ 1], ro, B->t, acc);
        }
        const uint32_t band_end = (b + 1) * L->band_rows < rings ? (b + 1) * L->band_rows : rings;
        if (mine && r + 1 == band_end) store_level(B, partial, s, b);
    }
    lv->rad_prev = lv->rad[cur];
    lv->cur ^= 1;
}

/* The workspace of one thread, stride doubles per array. */
static size_t block_doubles(size_t stride)
{
    const size_t levels = 12 * LAT_LEVELS, ghosts = 12 * LAT_LEVELS, rk4 = 6 * 4 * (LAT_LEVELS - 1) + 6 * 8;
    return (levels + ghosts + rk4 + 14) * stride;
}

static void block_init(block *B, const lat_args *la, bool rk4, double *ws, uint32_t R0, uint32_t R1, uint32_t K)
{
    const size_t st = la->L->stride;
    memset(B, 0, sizeof *B);
    B->la = la, B->L = la->L, B->rk4 = rk4, B->R0 = R0, B->R1 = R1, B->K = K;
    double *q = ws;
    for (uint32_t s = 0; s < LAT_LEVELS; s++)
        for (int r = 0; r < 2; r++)
            for (int c = 0; c < 3; c++) B->lv[s].rad[r][c] = q, q += st, B->lv[s].ring[r][c] = q, q += st;
    for (uint32_t g = 0; g < 2 * LAT_LEVELS; g++)
        for (int c = 0; c < 6; c++) B->ghost[g][c] = q, q += st;
    for (uint32_t s = 0; s + 1 < LAT_LEVELS; s++)
        for (int r = 0; r < 4; r++)
            for (int c = 0; c < 6; c++) B->trial[s][r][c] = q, q += st;
    for (int r = 0; r < 8; r++)
        for (int c = 0; c < 6; c++) B->sums[r][c] = q, q += st;
    for (int c = 0; c < 6; c++) B->hub[c] = q, q += st;
    B->e = q, q += st, B->p = q, q += st;
    for (int c = 0; c < 3; c++) B->t[c] = q, q += st, B->F[c] = q, q += st;
}

/* Level 0 of the ghost rows, from the state before anyone moves it. */
static void copy_ghosts(block *B)
{
    const spn__lattice *L = B->L;
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

bool spn__lattice_block(spn__lattice *L, const lat_args *la, bool rk4, int threads, uint32_t K,
                        double sums[][L_NSUMS])
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
        block_init(&B, la, rk4, L->bws[t], R0, R1, K);
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
