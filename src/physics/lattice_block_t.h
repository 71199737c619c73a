/* Several Euler or symplectic Euler steps of the lattice, or the four stages
 * of an RK4 step, in one pass over memory (temporal blocking), written once
 * for both precisions: lattice.c includes this file with LK_T = double,
 * lattice_f32.c with LK_T = float, each after lattice_sweep_t.h. No include
 * guard, on purpose.
 *
 * Why. A web of a million particles keeps 160 bytes per particle in play
 * (state, spring slots, masses; 80 in float32), far more than the caches,
 * so one step per pass is bound by memory bandwidth. Here a pass takes the
 * state K = LAT_LEVELS levels forward: each row is read from memory once per
 * pass, and the rows in flight stay in the caches.
 *
 * The schedule. One row step, op(s, j), is the sweep's loop body at level s
 * (the state after s steps of the pass, or the RK4 stage s): the radial
 * springs into row j and the ring springs of row j at level s - 1, then row
 * j - 1 moved to level s. It needs rows j - 1 and j at level s - 1 and moves
 * row j - 1 in place, so it must come after op(s - 1, j + 1) (which brought
 * row j to level s - 1) and after op(s, j - 1). Fronts J = 0, 1, ... run
 * op(s, J - s + 1) for s = 1 .. K in that order: a wavefront K rows deep.
 * RK4 keeps its trial states and weighted sums only for the rows in flight
 * (by row mod 4 and mod 8).
 *
 * Threads. Each thread takes a contiguous run of bands. It needs the rows
 * within K of its run from its neighbours at every level before they move,
 * so it copies those ghost rows (level 0) into its own buffers first (from
 * the state at a call's first pass, then from the rows each neighbour sent
 * it at the end of the pass before, LK(send)), and,
 * after a barrier, steps them along privately: the rows it may step at level
 * s shrink by one at each side per level (a trapezoid), and at level K they
 * are its own rows exactly. Ghost rows are stepped twice (by each side),
 * 2 K rows per boundary.
 *
 * Same bits. Every particle gets the same arithmetic as in one-step sweeps
 * (the same row kernels, lattice_rows_t.h, and spring hooks), so the
 * trajectory is bit-identical to K single steps whatever the thread count.
 * The energy sums of each step are kept per band and per level, in the
 * order of lattice_sweep_t.h's band_pass (the first row's radial springs,
 * the "cut", summed apart), so they are bit-identical too.
 *
 * The including file defines LK_T, LK(name), LK_ARGS (its step arguments:
 * members L, g, drag, dt, h, weight, mode, stage, in LK_T where they are
 * numbers) and, besides lattice_sweep_t.h's LK(radials), LK(rings) and
 * LK(stride):
 *   LK(state)(a, X, V)   the state arrays (3 + 3, whole; float32:
 *                        displacements and velocities)
 *   LK(mass)(a), LK(inv_mass)(a)   the masses (whole arrays) */
#if !defined(LK_T) || !defined(LK) || !defined(LK_ARGS)
#error "define LK_T, LK(name) and LK_ARGS before including lattice_block_t.h"
#endif

/* Per level: the two latest rows' radial and ring forces, the sum columns
 * of two bands (the band whose springs and the band whose particles are
 * being summed differ at a band's first row) and the sums of their cuts. */
typedef struct LK(level) {
    LK_T *rad[2][3], *ring[2][3];
    LK_T **rad_prev;
    int cur;
    lat_cols band[2];
    double cut_e[2], cut_p[2];
} LK(level);

typedef struct LK(block) {
    const LK_ARGS *la;        /* per level: the step's arguments (RK4: the stage's) */
    const spn__lattice *L;
    bool rk4;
    uint32_t R0, R1, K;       /* own rows [R0, R1), levels */
    LK_T *X[3], *V[3];        /* the state */
    const LK_T *mass, *inv_mass;
    LK_T *ghost[2 * LAT_LEVELS][6];
    LK_T *hub[6], *F[3];
    /* RK4: the trial state of levels 1-3 by row mod 4 and the weighted sums
     * ax, av by row mod 8 (a row's live for at most 2 and 5 fronts), and
     * the hub's */
    LK_T *trial[LAT_LEVELS - 1][4][6], *sums[8][6];
    LK_T hub_trial[LAT_LEVELS - 1][6], hub_sums[6];
    lat_cols dummy, cut; /* the ghost rows' sums (never read), a cut's before it is summed */
    LK(level) lv[LAT_LEVELS];
} LK(block);

/* Row j's x and v arrays: the state for own rows, a ghost buffer else. */
static void LK(row_ptrs)(const LK(block) *B, uint32_t j, LK_T **X, LK_T **V)
{
    if (j >= B->R0 && j < B->R1) {
        const size_t p0 = 1 + (size_t)j * LK(pitch)(B->la);
        for (int c = 0; c < 3; c++) X[c] = B->X[c] + p0, V[c] = B->V[c] + p0;
        return;
    }
    const uint32_t g = j < B->R0 ? j - (B->R0 - B->K) : B->K + (j - B->R1);
    for (int c = 0; c < 3; c++) X[c] = B->ghost[g][c], V[c] = B->ghost[g][3 + c];
}

static bool LK(own)(const LK(block) *B, uint32_t j) { return j >= B->R0 && j < B->R1; }

/* Row j at level s - 1, the state the forces of level s are taken at: the
 * state itself, or an RK4 trial state. */
static void LK(eval_ptrs)(const LK(block) *B, uint32_t s, uint32_t j, LK_T **X, LK_T **V)
{
    if (!B->rk4 || s == 1) {
        LK(row_ptrs)(B, j, X, V);
        return;
    }
    LK_T *const *T = B->trial[s - 2][j % 4];
    for (int c = 0; c < 3; c++) X[c] = T[c], V[c] = T[3 + c];
}

/* Lowest and one past the highest row this block steps at level s. */
static uint32_t LK(low)(const LK(block) *B, uint32_t s) { return B->R0 ? B->R0 - B->K + s : 0; }

static uint32_t LK(high)(const LK(block) *B, uint32_t s)
{
    const uint32_t rings = B->L->rings;
    return B->R1 == rings ? rings : B->R1 + B->K - s;
}

/* Band b's sums at level s (index s - 1) into its partial, as cut_pass and
 * band_pass leave them. */
static void LK(store_level)(LK(block) *B, double *partial, uint32_t s, uint32_t b)
{
    LK(level) *lv = &B->lv[s - 1];
    const int q = (int)(b & 1);
    const spn__lattice *L = B->L;
    const LK_ARGS *a = &B->la[s - 1];
    double *out = partial + ((size_t)(s - 1) * L->nbands + b) * L_NSUMS;
    if (b) out[L_ELASTIC] = lv->cut_e[q], out[L_DAMP] = lv->cut_p[q];
    store_band_sums(out, b == 0, &lv->band[q], L->radials,
                    lat_sums_made(a->mode, a->stage, a->kin_known, a->drag != 0));
}

/* The hub at level s: its radial springs into ring 0 (forces into rad),
 * then its update; sums into the columns cs. */
LAT_INLINE void LK(block_hub)(LK(block) *B, uint32_t s, LK_T *const *X, LK_T *const *V, LK_T *const *rad,
                              const lat_cols *cs, bool hold)
{
    const LK_ARGS *a = &B->la[s - 1];
    const uint32_t n = B->L->radials;
    LK_T hx[3], hv[3];
    const bool base = !B->rk4 || s == 1;
    for (int c = 0; c < 3; c++) {
        hx[c] = base ? B->X[c][0] : B->hub_trial[s - 2][c];
        hv[c] = base ? B->V[c][0] : B->hub_trial[s - 2][3 + c];
        for (uint32_t i = 0; i < n; i++) B->hub[c][i] = hx[c], B->hub[3 + c][i] = hv[c];
    }
    LK(radials)(a, B->hub, B->hub + 3, X, V, 0, rad, cs, hold);
    if (!B->rk4) {
        LK(hub_move)(n, a->mode == MODE_SYMPLECTIC, a->dt, a->g, a->drag, B->mass[0], B->inv_mass[0], B->X, B->V,
                     rad, cs);
        return;
    }
    LK_T f[3], *Fp[3] = {f, f + 1, f + 2};
    LK(hub_force)(false, n, B->mass[0], a->drag, a->g, hv, rad, f);
    LK(rk4_rows) R;
    for (int c = 0; c < 3; c++) {
        R.V[c] = &hv[c], R.xb[c] = &B->X[c][0], R.vb[c] = &B->V[c][0];
        R.xt[c] = s < 4 ? &B->hub_trial[s - 1][c] : NULL;
        R.vt[c] = s < 4 ? &B->hub_trial[s - 1][3 + c] : NULL;
        R.ax[c] = &B->hub_sums[c], R.av[c] = &B->hub_sums[3 + c];
    }
    LK(rk4_update)(1, a->stage, a->h, a->weight, a->drag, a->kin_known, a->g, B->mass, B->inv_mass, &R, Fp, cs);
}

/* Row r (particles from p0) moved to level s, its forces complete (radial
 * in ri, ring rg, radial out ro or NULL); sum terms into the columns cs. */
LAT_INLINE void LK(block_move)(LK(block) *B, uint32_t s, uint32_t r, LK_T *const *ri, LK_T *const *rg,
                               LK_T *const *ro, const lat_cols *cs)
{
    const LK_ARGS *a = &B->la[s - 1];
    const uint32_t n = B->L->radials;
    const size_t p0 = 1 + (size_t)r * LK(pitch)(a);
    LK_T *X[3], *V[3];
    LK(row_ptrs)(B, r, X, V);
    if (!B->rk4) {
        LK(row_move)(n, a->mode == MODE_SYMPLECTIC, a->dt, a->g, a->drag, B->mass + p0, B->inv_mass + p0, X, V, ri,
                     rg, ro, cs);
        return;
    }
    LK_T *EX[3], *EV[3];
    LK(eval_ptrs)(B, s, r, EX, EV);
    LK(rk4_rows) R;
    for (int c = 0; c < 3; c++) {
        LK(assemble)(n, a->g[c], a->drag, B->mass + p0, EV[c], ri[c], rg[c], ro ? ro[c] : NULL, B->F[c]);
        R.V[c] = EV[c], R.xb[c] = X[c], R.vb[c] = V[c];
        R.xt[c] = s < 4 ? B->trial[s - 1][r % 4][c] : NULL;
        R.vt[c] = s < 4 ? B->trial[s - 1][r % 4][3 + c] : NULL;
        R.ax[c] = B->sums[r % 8][c], R.av[c] = B->sums[r % 8][3 + c];
    }
    LK(rk4_update)(LK(padded)(n), a->stage, a->h, a->weight, a->drag, a->kin_known, a->g, B->mass + p0,
                   B->inv_mass + p0, &R, B->F, cs);
}

/* op(s, j): see the file comment. (Inlined into run_block, so that each
 * target_clones version of it vectorises its own copy.) */
LAT_INLINE void LK(op)(LK(block) *B, double *partial, uint32_t s, uint32_t j)
{
    const LK_ARGS *a = &B->la[s - 1];
    const spn__lattice *L = B->L;
    LK(level) *lv = &B->lv[s - 1];
    const uint32_t rings = L->rings, hi = LK(high)(B, s);
    const int cur = lv->cur;
    if (j < rings) {
        LK_T *X[3], *V[3];
        LK(eval_ptrs)(B, s, j, X, V);
        const bool mine = LK(own)(B, j) && j < hi;
        const uint32_t bj = lat_band_of(L, j);
        const int q = (int)(bj & 1);
        const bool cut = j > 0 && j == lat_band_lo(L, bj);
        const lat_cols *own = mine ? &lv->band[q] : &B->dummy;
        const bool held = j < hi && !(mine && cut); /* the ring springs follow, into the same columns */
        if (j == 0) {
            LK(block_hub)(B, s, X, V, lv->rad[cur], own, held);
        } else {
            LK_T *Xp[3], *Vp[3];
            LK(eval_ptrs)(B, s, j - 1, Xp, Vp);
            LK(radials)(a, Xp, Vp, X, V, j, lv->rad[cur], mine && cut ? &B->cut : own, held);
            if (mine && cut) {
                const bool el = wants_elastic(a->mode, a->stage);
                assert(el || col_zero(B->cut.c[L_ELASTIC], L->radials));
                lv->cut_e[q] = el ? col_take(B->cut.c[L_ELASTIC], L->radials) : 0;
                lv->cut_p[q] = col_take(B->cut.c[L_DAMP], L->radials);
            }
        }
        if (j < hi) LK(rings)(a, X, V, j, lv->ring[cur], own, held);
    }
    if (j > LK(low)(B, s)) {
        const uint32_t r = j - 1, b = lat_band_of(L, r);
        const bool mine = LK(own)(B, r);
        LK(block_move)(B, s, r, lv->rad_prev, lv->ring[cur ^ 1], j < rings ? lv->rad[cur] : NULL,
                       mine ? &lv->band[b & 1] : &B->dummy);
        if (mine && r + 1 == lat_band_lo(L, b + 1)) LK(store_level)(B, partial, s, b);
    }
    lv->rad_prev = lv->rad[cur];
    lv->cur ^= 1;
}

/* The arrays of a share's workspace before its sent rows (LK(sent)), as
 * LK(block_init) lays them out: per level two rows of radial and of ring
 * forces (12), the ghost rows (2 LAT_LEVELS rows of 6), RK4's trial
 * states (4 rows of 6 for each level but the last) and weighted sums (8
 * rows of 6), the hub's row (6) and the assembled force (3). */
#define LK_SENT_AT (12 * LAT_LEVELS + 6 * 2 * LAT_LEVELS + 6 * 4 * (LAT_LEVELS - 1) + 6 * 8 + 6 + 3)

/* The workspace of one thread, stride numbers per array. */
static size_t LK(block_numbers)(size_t stride) { return (LK_SENT_AT + 12 * LAT_LEVELS) * stride; }

/* Array c (x, y, z, then v) of row g of the rows a share sends its
 * neighbours, in its workspace ws: g < K its first K rows (for the share
 * below), g >= K its last K (for the share above). */
static LK_T *LK(sent)(void *ws, size_t stride, uint32_t g, int c)
{
    return (LK_T *)ws + (LK_SENT_AT + (size_t)g * 6 + (size_t)c) * stride;
}

static void LK(block_init)(LK(block) *B, const LK_ARGS *la, bool rk4, LK_T *ws, double *cols, uint32_t R0,
                           uint32_t R1, uint32_t K)
{
    const size_t st = LK(stride)(la);
    memset(B, 0, sizeof *B);
    B->la = la, B->L = la->L, B->rk4 = rk4, B->R0 = R0, B->R1 = R1, B->K = K;
    LK(state)(la, B->X, B->V);
    B->mass = LK(mass)(la), B->inv_mass = LK(inv_mass)(la);
    LK_T *q = ws;
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
    for (int c = 0; c < 3; c++) B->F[c] = q, q += st;
    assert(q == ws + (size_t)LK_SENT_AT * st); /* (the sent rows follow, LK(sent)) */
    const size_t cst = B->L->col_stride;
    B->dummy = col_set(cols, cst, COL_SETS - 1), B->cut = col_set(cols, cst, -1);
    for (uint32_t s = 0; s < LAT_LEVELS; s++)
        for (int r = 0; r < 2; r++) B->lv[s].band[r] = col_set(cols, cst, 2 * (int)s + r);
}

/* Level 0 of the ghost rows: from the state before anyone moves it, or
 * (ws non-NULL: the share's workspaces, spn__lattice_sent_ready) from the
 * rows its neighbours sent at the end of the pass before, the same numbers
 * (a debug build checks them against the state). */
static void LK(copy_ghosts)(LK(block) *B, int t, void *const *ws)
{
    const spn__lattice *L = B->L;
    const uint32_t n = L->radials;
    const size_t st = LK(stride)(B->la);
    for (uint32_t g = 0; g < 2 * B->K; g++) {
        const uint32_t j = g < B->K ? B->R0 - B->K + g : B->R1 + (g - B->K);
        if ((g < B->K && !B->R0) || (g >= B->K && j >= L->rings)) continue;
        const size_t p0 = 1 + (size_t)j * LK(pitch)(B->la);
        for (int c = 0; c < 6; c++) {
            const LK_T *row = (c < 3 ? B->X[c] : B->V[c - 3]) + p0;
            if (ws) {
                /* (the share below sent its last K rows as its rows K .. 2 K -
                 * 1, the share above its first K as its rows 0 .. K - 1) */
                const LK_T *from =
                    g < B->K ? LK(sent)(ws[t - 1], st, g + B->K, c) : LK(sent)(ws[t + 1], st, g - B->K, c);
                assert(memcmp(from, row, n * sizeof(LK_T)) == 0);
                row = from;
            }
            memcpy(B->ghost[g][c], row, n * sizeof(LK_T));
        }
    }
}

/* The end of a pass on threads: this share's first and last K rows (those
 * its neighbours step as ghost rows), the state the next pass starts from,
 * into its workspace ws for them (LK(copy_ghosts)). Why not let them read
 * the rows from the state, as the first pass does: their reads leave this
 * share's lines of those rows shared between the cores, and its first
 * writes to them in the next pass's fronts then wait for the other core
 * to give them up (some 4 us a pass of the 5k web on the Zen 5, the
 * forty-seventh session, docs/physics-lattice.md). Sent past the caches,
 * the copies cost this core no such wait either. */
static void LK(send)(const LK(block) *B, void *ws)
{
    const spn__lattice *L = B->L;
    const size_t st = LK(stride)(B->la), bytes = LK(padded)(L->radials) * sizeof(LK_T);
    for (uint32_t g = 0; g < 2 * B->K; g++) {
        if ((g < B->K && !B->R0) || (g >= B->K && B->R1 >= L->rings)) continue;
        LK_T *X[3], *V[3]; /* (an own row: the state's) */
        LK(row_ptrs)(B, g < B->K ? B->R0 + g : B->R1 - 2 * B->K + g, X, V);
        for (int c = 0; c < 6; c++) spn__lattice_stream(LK(sent)(ws, st, g, c), c < 3 ? X[c] : V[c - 3], bytes);
    }
    spn__lattice_stream_fence();
}

/* This block's pass, front by front. Inlined into each version of
 * run_block below. */
LAT_INLINE void LK(fronts)(LK(block) *B, double *partial)
{
    const uint32_t K = B->K, first = LK(low)(B, 1), last = LK(high)(B, K) + K - 1;
    for (uint32_t J = first; J <= last; J++)
        for (uint32_t s = 1; s <= K; s++) {
            if (J + 1 < s) break;
            const uint32_t j = J + 1 - s;
            if (j >= LK(low)(B, s) && j <= LK(high)(B, s)) LK(op)(B, partial, s, j);
        }
}

SPN__KERNEL static void LK(run_block)(LK(block) *B, double *partial) { LK(fronts)(B, partial); }

/* The same in AVX2 code alone, where the including file defines
 * LK_RK4_AVX2 (float64): its RK4 passes on the processors
 * spn__lattice_rk4_avx2 names run this instead of the AVX-512 version
 * target_clones would pick. Same bits, as every version gives. */
#if defined(LK_RK4_AVX2) && defined(SPN__AVX2)
SPN__AVX2 static void LK(avx2_block)(LK(block) *B, double *partial) { LK(fronts)(B, partial); }
#endif

/* The version of run_block a pass (rk4 or not) runs. */
static void (*LK(runner)(bool rk4))(LK(block) *, double *)
{
#if defined(LK_RK4_AVX2) && defined(SPN__AVX2)
    if (rk4 && spn__lattice_rk4_avx2()) return LK(avx2_block);
#else
    (void)rk4;
#endif
    return LK(run_block);
}

/* A pass as a job of spn__lat_run, a share a thread's run of bands: the
 * ghost copies, then the fronts. */
typedef struct LK(pass) {
    const spn__lattice *L;
    const LK_ARGS *la;
    bool rk4;
    uint32_t K;
    int threads;
    bool sent; /* the ghost rows from what the shares sent (spn__lattice_sent_ready) */
    void (*run)(LK(block) *, double *);
} LK(pass);

/* Share t's block: its run of bands (L->split), on its workspace and sum
 * columns. */
static void LK(share_block)(const LK(pass) *P, int t, LK(block) *B)
{
    const spn__lattice *L = P->L;
    uint32_t R0, R1;
    spn__lattice_split_rows(L, t, &R0, &R1);
    LK(block_init)(B, P->la, P->rk4, (LK_T *)L->bws[t], L->cols[t], R0, R1, P->K);
}

static void LK(ghost_share)(void *ctx, int t, int thread)
{
    (void)thread;
    const LK(pass) *P = ctx;
    LK(block) B;
    LK(share_block)(P, t, &B);
    LK(copy_ghosts)(&B, t, P->sent ? P->L->bws : NULL);
}

static void LK(front_share)(void *ctx, int t, int thread)
{
    (void)thread;
    const LK(pass) *P = ctx;
    LK(block) B;
    LK(share_block)(P, t, &B);
    const double t0 = P->threads > 1 ? spn__lattice_clock_ns() : 0;
    P->run(&B, P->L->partial_k);
    if (P->threads > 1) {
        P->L->split.took[t].ns = spn__lattice_clock_ns() - t0;
        LK(send)(&B, P->L->bws[t]);
    }
}

/* K levels (2 .. LAT_LEVELS, spn__lattice_block_ready) in one pass over the
 * state on `threads` threads: K explicit steps, or (rk4) the four stages of
 * one RK4 step; la[s] the arguments of level s + 1, the sums of each into
 * sums[s]. False when out of memory (nothing done). */
static bool LK(block_pass)(spn__lattice *L, const LK_ARGS *la, bool rk4, int threads, uint32_t K,
                           double sums[][L_NSUMS])
{
    if (!spn__lattice_block_alloc(L, threads, LK(block_numbers)(LK(stride)(la)) * sizeof(LK_T)) ||
        !spn__lattice_cols_alloc(L, threads) || !spn__lattice_split_ready(L, threads))
        return false;
    LK(pass) P = {L, la, rk4, K, threads, threads > 1 && spn__lattice_sent_ready(L, K, sizeof(LK_T)),
                  LK(runner)(rk4)};
    spn__lat_run(L, threads, threads, LK(ghost_share), LK(front_share), &P);
    spn__lattice_state_moved(L);
    if (threads > 1) {
        spn__lattice_sent(L, K, sizeof(LK_T)); /* (before the split moves) */
        spn__lattice_split_update(L);
    }
    spn__lattice_block_sums(L, K, sums);
    return true;
}
