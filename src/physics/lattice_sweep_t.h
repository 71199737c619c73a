/* One sweep of the lattice step (lattice.c's file comment), written once for
 * both precisions: lattice.c includes this file with LK_T = double,
 * lattice_f32.c with LK_T = float. No include guard, on purpose.
 *
 * The including file defines LK(name), LK_ARGS (its step arguments, with a
 * member L, the spn__lattice) and, for its precision:
 *   LK(eval)(a, p0, X, V)        row p0 of the evaluated state (3 + 3 arrays)
 *   LK(radials)(a, Xa, Va, Xb, Vb, j, f, cs, hold)
 *                                the radial springs from row a into row j
 *                                (b), forces on the inner end into f, sums
 *                                into the columns cs (lattice_rows.h); if
 *                                `hold`, row j's ring springs follow into
 *                                the same cs, and the sums may wait for them
 *   LK(rings)(a, X, V, j, f, cs, held)
 *                                row j's ring springs, wrap included; `held`:
 *                                the radials into row j were called with hold
 *   LK(hub_state)(a, x, v)       the hub's evaluated state (3 each)
 *   LK(hub)(a, rad, cs)          the hub's force from its radials, and its update
 *   LK(finish)(a, p0, n, ri, rg, ro, F, cs)
 *                                a row whose forces are complete, moved
 *   LK(cut)(a, b, c)             component c of the radial forces into band
 *                                b's first row (a row of N)
 *   LK(pitch)(a)                 the state's row pitch: row j starts at
 *                                particle 1 + j pitch
 *   LK(ws)(a, thread), LK(stride)(a)
 *                                the per-thread workspaces (WS_* arrays)
 * Sums go to each thread's sum columns (L->cols), a band's reduced at its
 * end into its partial in L->partial; those are added in band order. */
#if !defined(LK_T) || !defined(LK) || !defined(LK_ARGS)
#error "define LK_T, LK(name) and LK_ARGS before including lattice_sweep_t.h"
#endif

/* Radial springs into band b's first row, from the state before the step;
 * their sums start the band's partial. */
SPN__KERNEL static void LK(cut_pass)(const LK_ARGS *a, double *cols, uint32_t b)
{
    const spn__lattice *L = a->L;
    const uint32_t n = L->radials, j = lat_band_lo(L, b);
    const size_t P = LK(pitch)(a);
    LK_T *Xa[3], *Va[3], *Xb[3], *Vb[3], *f[3];
    LK(eval)(a, 1 + (size_t)(j - 1) * P, Xa, Va);
    LK(eval)(a, 1 + (size_t)j * P, Xb, Vb);
    for (int c = 0; c < 3; c++) f[c] = LK(cut)(a, b, c);
    const lat_cols cs = col_set(cols, L->col_stride, -1);
    LK(radials)(a, Xa, Va, Xb, Vb, j, f, &cs, false);
    double *p = L->partial + (size_t)b * L_NSUMS;
    p[L_ELASTIC] = col_take(cs.c[L_ELASTIC], n), p[L_DAMP] = col_take(cs.c[L_DAMP], n);
}

/* Sweep band b: rows read straight from the state arrays, each moved in
 * place once every spring that reads it is done. */
SPN__KERNEL static void LK(band_pass)(const LK_ARGS *a, LK_T *ws, double *cols, uint32_t b)
{
    const spn__lattice *L = a->L;
    const uint32_t n = L->radials, lo = lat_band_lo(L, b), hi = lat_band_lo(L, b + 1);
    const size_t P = LK(pitch)(a);
    const size_t st = LK(stride)(a);
    LK_T *RAD[2][3], *RING[2][3], *H[6], *Fw[3], *cut[3], *next_cut[3];
    for (int c = 0; c < 3; c++) {
        RAD[0][c] = ws + (WS_RAD + c) * st, RAD[1][c] = ws + (WS_RAD + 3 + c) * st;
        RING[0][c] = ws + (WS_RING + c) * st, RING[1][c] = ws + (WS_RING + 3 + c) * st;
        Fw[c] = ws + (WS_F + c) * st;
        cut[c] = LK(cut)(a, b, c);
        next_cut[c] = LK(cut)(a, b + 1, c);
    }
    for (int c = 0; c < 6; c++) H[c] = ws + (WS_HUB + c) * st;
    const lat_cols cs = col_set(cols, L->col_stride, 0);
    int cur = 0;
    LK_T **rad_cur = NULL, **rad_prev = NULL;
    for (uint32_t j = lo; j < hi; j++, cur ^= 1) {
        const size_t p0 = 1 + (size_t)j * P;
        LK_T *X[3], *V[3];
        LK(eval)(a, p0, X, V);
        if (j == lo && j > 0) {
            rad_cur = cut; /* computed by the cut pass; its sums are in the band's partial */
        } else if (j == 0) {
            LK_T hx[3], hv[3];
            LK(hub_state)(a, hx, hv);
            for (int c = 0; c < 3; c++)
                for (uint32_t i = 0; i < n; i++) H[c][i] = hx[c], H[3 + c][i] = hv[c];
            LK(radials)(a, H, H + 3, X, V, 0, RAD[cur], &cs, true);
            rad_cur = RAD[cur];
            LK(hub)(a, rad_cur, &cs);
        } else {
            LK_T *Xp[3], *Vp[3];
            LK(eval)(a, p0 - P, Xp, Vp);
            LK(radials)(a, Xp, Vp, X, V, j, RAD[cur], &cs, true);
            rad_cur = RAD[cur];
        }
        LK(rings)(a, X, V, j, RING[cur], &cs, j == 0 || j > lo); /* row lo's radials: the cut pass */
        if (j > lo) LK(finish)(a, p0 - P, n, rad_prev, RING[cur ^ 1], rad_cur, Fw, &cs);
        rad_prev = rad_cur;
    }
    LK(finish)(a, 1 + (size_t)(hi - 1) * P, n, rad_prev, RING[cur ^ 1], hi < L->rings ? next_cut : NULL, Fw, &cs);
    store_band_sums(L->partial + (size_t)b * L_NSUMS, b == 0, &cs, n, L_ALL_SUMS);
}

/* The sweep as a job of spn__lat_run, a share a band: the cut passes,
 * then the bands. */
static void LK(cut_share)(void *ctx, int b, int t)
{
    const LK_ARGS *a = ctx;
    if (b) LK(cut_pass)(a, a->L->cols[t], (uint32_t)b);
}

static void LK(band_share)(void *ctx, int b, int t)
{
    const LK_ARGS *a = ctx;
    LK(band_pass)(a, LK(ws)(a, t), a->L->cols[t], (uint32_t)b);
}

/* One force evaluation and update over the whole lattice; sums into sum[]. */
static void LK(sweep)(const LK_ARGS *a, int threads, double *sum)
{
    const spn__lattice *L = a->L;
    const uint32_t nb = L->nbands;
    spn__lat_run(L, threads, (int)nb, LK(cut_share), LK(band_share), (void *)a);
    for (int k = 0; k < L_NSUMS; k++) sum[k] = 0;
    for (uint32_t b = 0; b < nb; b++)
        for (int k = 0; k < L_NSUMS; k++) sum[k] += L->partial[(size_t)b * L_NSUMS + k];
}
