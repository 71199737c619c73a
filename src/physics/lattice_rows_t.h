/* The particle updates of the lattice step, written once for both
 * precisions: lattice_rows.h includes this file with LK_T = double and
 * lattice_rows32.h with LK_T = float, each with LK(name) giving its names
 * and LK_U the unsigned integer of LK_T's width. No include guard, on
 * purpose.
 *
 * The sweeps (lattice_sweep_t.h) and the blocked passes (lattice_block_t.h)
 * of both precisions call these. Every kernel updates a row of the state in
 * place (structure of arrays, positions x or float32 displacements d,
 * velocities v) once the row's forces are complete. Fixed particles are
 * selected out, not skipped, so the loops vectorise; the per-particle terms
 * of the energy sums add into the sum columns (lattice_rows.h) t_mv2,
 * t_gain, t_mvn2, in double. Each expression is the general path's
 * (chunk.h, explicit.c), so the float64 lattice gives its bits. Plain
 * loops for GCC 12 to vectorise; where it would not, the comment says what
 * was changed. */
#if !defined(LK_T) || !defined(LK_U) || !defined(LK) || !defined(LK_SCRATCH)
#error "define LK_T, LK_U, LK(name) and LK_SCRATCH before including lattice_rows_t.h"
#endif

/* A row of n rounded up to whole 64-byte vectors (8 doubles, 16 floats):
 * the pitch of every row array of the lattice (the state, masses, slots and
 * RK4 arrays, the force rows, ghost rows and sum columns), whose padding
 * holds zeros: massless particles that no select moves, at rest, with
 * springs of zero stiffness. The particle loops of LK(row), LK(assemble)
 * and LK(rk4_update) run over it, so that they end on a whole vector
 * instead of a scalar remainder (docs/physics-lattice.md, "Loops over the
 * padding"); what they write there is never read. */
LAT_INLINE uint32_t LK(padded)(uint32_t n)
{
    const uint32_t lanes = 64 / sizeof(LK_T);
    return (n + lanes - 1) & ~(lanes - 1);
}

/* The per-particle sum terms m q (LK_ACC(a, m, q)): float64 adds them
 * straight into the sum columns (LK_S double, a += m q as one fused
 * multiply-add); float32 stores them in its float scratch (lat_cols.scr)
 * and adds them into the columns after the loop (col_addf), so that the
 * loop stays float32. LK_TERMS: the array a kernel writes; LK_DONE: that
 * addition. */
#if LK_SCRATCH
#define LK_S float
#define LK_ACC(a, m, q) ((a) = (m) * (q))
#define LK_TERMS(cs, k) ((cs)->scr[k])
#define LK_DONE(cs, k, n) col_addf((cs)->c[k], (cs)->scr[k], (n))
#else
#define LK_S double
#define LK_ACC(a, m, q) ((a) = fma((m), (q), (a)))
#define LK_TERMS(cs, k) ((cs)->c[k])
#define LK_DONE(cs, k, n) ((void)0)
#endif

/* c ? a : b, bit for bit, through integer masks. GCC 12 if-converts a
 * select that only needs a load on one side (k = on ? kk[j] : 0), or whose
 * result goes back where it was loaded from (x[i] = c ? x[i] + e : x[i]),
 * into masked loads and stores (vmaskmovpd), even with the load hoisted out
 * of the select; AMD processors before Zen 4 run those slowly (the stores as
 * microcode). This form it vectorises as a blend between plain loads and
 * stores. Measured on a Zen 1 (2026-12-02), 5k web, CPU ns a spring-step,
 * fastest of five: RK4 67.0 -> 50.6 (float32 44.9 -> 31.1), symplectic
 * 13.9 -> 11.7 (docs/physics-lattice.md, "Masked loads and stores"). */
LAT_INLINE LK_T LK(pick)(bool c, LK_T a, LK_T b)
{
    LK_U ua, ub;
    memcpy(&ua, &a, sizeof ua), memcpy(&ub, &b, sizeof ub);
    const LK_U m = (LK_U)0 - (LK_U)c, r = (ua & m) | (ub & ~m);
    LK_T d;
    memcpy(&d, &r, sizeof d);
    return d;
}

/* A particle moved: its state and its sum terms, each mf q (mf: its mass,
 * 0 when fixed). */
typedef struct LK(moved) {
    LK_T x[3], v[3], mf, mv2, gain, mvn2;
} LK(moved);

/* One particle of an Euler (sym false) or symplectic Euler step. The
 * update is explicit.c's, with its fused multiply-adds: v' = v + f (dt/m)
 * and x' = x + w dt (w: v' or v) one rounding each. The sum terms use them
 * too (they need not match the general path's bits, only its values), in
 * the order the components are ready. */
LAT_INLINE LK(moved) LK(one)(LK_T fx, LK_T fy, LK_T fz, LK_T im, LK_T m, LK_T xx, LK_T xy, LK_T xz, LK_T vx,
                             LK_T vy, LK_T vz, bool sym, LK_T dt, const LK_T *g)
{
    LK(moved) o;
    const LK_T s = dt * im;
    const bool fr = im != 0;
    o.mf = fr ? m : (LK_T)0;
    const LK_T nx = LK_FMA(fx, s, vx), ny = LK_FMA(fy, s, vy), nz = LK_FMA(fz, s, vz);
    const LK_T wx = sym ? nx : vx, wy = sym ? ny : vy, wz = sym ? nz : vz;
    const LK_T dx = wx * dt, dy = wy * dt, dz = wz * dt;
    o.x[0] = fr ? LK_FMA(wx, dt, xx) : xx, o.x[1] = fr ? LK_FMA(wy, dt, xy) : xy, o.x[2] = fr ? LK_FMA(wz, dt, xz) : xz;
    o.v[0] = fr ? nx : vx, o.v[1] = fr ? ny : vy, o.v[2] = fr ? nz : vz;
    o.mv2 = LK_FMA(vz, vz, LK_FMA(vy, vy, vx * vx));
    o.mvn2 = LK_FMA(nz, nz, LK_FMA(ny, ny, nx * nx));
    o.gain = LK_FMA((LK_T)0.5, LK_FMA(nz - vz, nz + vz, LK_FMA(ny - vy, ny + vy, (nx - vx) * (nx + vx))),
                    -LK_FMA(g[2], dz, LK_FMA(g[1], dy, g[0] * dx)));
    return o;
}

/* An Euler or symplectic row, its force assembled on the fly in the general
 * path's order (gravity and drag, radial out, ring to i + 1, radial in, ring
 * from i - 1; the wrap spring at the two ends) and moved in place. `out` is
 * NULL on the outermost ring. The ends' forces are formed before the loop
 * moves anything. */
LAT_INLINE void LK(row)(uint32_t n, bool sym, LK_T dt, const LK_T *g, LK_T drag, const LK_T *restrict mass,
                        const LK_T *restrict inv_mass, LK_T *restrict xx, LK_T *restrict xy, LK_T *restrict xz,
                        LK_T *restrict vx, LK_T *restrict vy, LK_T *restrict vz, const LK_T *restrict ix,
                        const LK_T *restrict iy, const LK_T *restrict iz, const LK_T *restrict rx,
                        const LK_T *restrict ry, const LK_T *restrict rz, const LK_T *restrict ox,
                        const LK_T *restrict oy, const LK_T *restrict oz, LK_S *restrict t_mv2,
                        LK_S *restrict t_gain, LK_S *restrict t_mvn2)
{
    const uint32_t l = n - 1;
    LK_T e0[3], el[3];
    const LK_T *V[3] = {vx, vy, vz}, *I[3] = {ix, iy, iz}, *R[3] = {rx, ry, rz}, *O[3] = {ox, oy, oz};
    for (int c = 0; c < 3; c++) {
        LK_T f0 = LK_FMA(-(drag * mass[0]), V[c][0], mass[0] * g[c]);
        LK_T fl = LK_FMA(-(drag * mass[l]), V[c][l], mass[l] * g[c]);
        if (ox) f0 += O[c][0], fl += O[c][l];
        e0[c] = ((f0 + R[c][0]) + R[c][l]) - I[c][0];
        el[c] = ((fl - I[c][l]) - R[c][l]) - R[c][l - 1];
    }
#define LK_STORE(i, o)                                                                                                 \
    do {                                                                                                               \
        xx[i] = (o).x[0], xy[i] = (o).x[1], xz[i] = (o).x[2];                                                          \
        vx[i] = (o).v[0], vy[i] = (o).v[1], vz[i] = (o).v[2];                                                          \
        LK_ACC(t_mv2[i], (o).mf, (o).mv2), LK_ACC(t_gain[i], (o).mf, (o).gain), LK_ACC(t_mvn2[i], (o).mf, (o).mvn2);   \
    } while (0)
    /* The loop runs over the whole row, from particle 0, where each of the
     * float64 step's row arrays starts a cache line, so that its vector
     * loads and stores do not straddle two (forty-third session,
     * docs/physics-lattice.md "Rows on cache lines"); the two ends, which
     * take the wrap spring in another order, are put back after it and moved
     * by their own forces. For particle 0 it reads rx[-1], whose result is
     * overwritten: a ring force row is never the first array of its
     * workspace. */
    const uint32_t ends[2] = {0, l};
    LK_T keep[2][6];
    LK_S keep_t[2][3];
    for (int k = 0; k < 2; k++) {
        const uint32_t i = ends[k];
        keep[k][0] = xx[i], keep[k][1] = xy[i], keep[k][2] = xz[i];
        keep[k][3] = vx[i], keep[k][4] = vy[i], keep[k][5] = vz[i];
        keep_t[k][0] = t_mv2[i], keep_t[k][1] = t_gain[i], keep_t[k][2] = t_mvn2[i];
    }
    const LK_T *const rxm = rx - 1, *const rym = ry - 1, *const rzm = rz - 1; /* (i - 1 would wrap at 0) */
    /* (a compiler barrier, no instruction: without it GCC 12 merges the
     * first iteration's loads with the ends' above, and the loop, no
     * longer if-converted, stays scalar in most of its inlined copies) */
    __asm__ __volatile__("" ::: "memory");
    const uint32_t wn = LK(padded)(n);
    if (ox)
        for (uint32_t i = 0; i < wn; i++) {
            const LK_T m = mass[i], dm = drag * m;
            const LK_T fx = (((LK_FMA(-dm, vx[i], m * g[0]) + ox[i]) + rx[i]) - ix[i]) - rxm[i];
            const LK_T fy = (((LK_FMA(-dm, vy[i], m * g[1]) + oy[i]) + ry[i]) - iy[i]) - rym[i];
            const LK_T fz = (((LK_FMA(-dm, vz[i], m * g[2]) + oz[i]) + rz[i]) - iz[i]) - rzm[i];
            const LK(moved) o = LK(one)(fx, fy, fz, inv_mass[i], m, xx[i], xy[i], xz[i], vx[i], vy[i], vz[i], sym, dt, g);
            LK_STORE(i, o);
        }
    else
        for (uint32_t i = 0; i < wn; i++) {
            const LK_T m = mass[i], dm = drag * m;
            const LK_T fx = ((LK_FMA(-dm, vx[i], m * g[0]) + rx[i]) - ix[i]) - rxm[i];
            const LK_T fy = ((LK_FMA(-dm, vy[i], m * g[1]) + ry[i]) - iy[i]) - rym[i];
            const LK_T fz = ((LK_FMA(-dm, vz[i], m * g[2]) + rz[i]) - iz[i]) - rzm[i];
            const LK(moved) o = LK(one)(fx, fy, fz, inv_mass[i], m, xx[i], xy[i], xz[i], vx[i], vy[i], vz[i], sym, dt, g);
            LK_STORE(i, o);
        }
    for (int k = 0; k < 2; k++) {
        const uint32_t i = ends[k];
        xx[i] = keep[k][0], xy[i] = keep[k][1], xz[i] = keep[k][2];
        vx[i] = keep[k][3], vy[i] = keep[k][4], vz[i] = keep[k][5];
        t_mv2[i] = keep_t[k][0], t_gain[i] = keep_t[k][1], t_mvn2[i] = keep_t[k][2];
    }
    for (int k = 0; k < 2; k++) {
        const uint32_t i = ends[k];
        const LK_T *f = k ? el : e0;
        const LK(moved) o =
            LK(one)(f[0], f[1], f[2], inv_mass[i], mass[i], xx[i], xy[i], xz[i], vx[i], vy[i], vz[i], sym, dt, g);
        LK_STORE(i, o);
    }
#undef LK_STORE
}

/* RK4 (Mehla 2005, eqs. 4.16-4.19). The state a stage is evaluated at and
 * the trial state it writes are different arrays (the sweep alternates two),
 * so no restrict pointer below aliases another. */

/* The complete force on a row, component c, in LK(row)'s order. Without
 * drag the loop drops the drag term and its load of v: (drag m) v is then
 * a signed zero for a finite v (a stage that makes v infinite fails the
 * step's energy check either way), and m g - (+-0) is m g bit for bit
 * unless m g is -0, which for a particle with mass needs g = -0 (left to
 * the general loop). A fixed particle of mass 0 may get the other zero, in
 * a force nothing reads. Measured on a Zen 1 (2026-12-03), RK4, CPU ns a
 * spring-step, median of four: 1M float32 24.1 -> 23.1 (two threads, wall,
 * 13.9 -> 13.3), 1M float64 42.0 -> 39.7, 5k float64 36.8 -> 36.0. */
LAT_INLINE void LK(assemble)(uint32_t n, LK_T gc, LK_T drag, const LK_T *restrict mass, const LK_T *restrict vc,
                             const LK_T *restrict in, const LK_T *restrict ring, const LK_T *restrict out,
                             LK_T *restrict f)
{
    const LK_T wrap = ring[n - 1];
    /* (over the whole row from particle 0, which starts a line, as in
     * LK(row); the ends are overwritten below) */
    const LK_T *const rm = ring - 1;
    const uint32_t wn = LK(padded)(n);
    if (drag == 0 && !(gc == 0 && signbit(gc))) {
        if (out)
            for (uint32_t i = 0; i < wn; i++)
                f[i] = ((((mass[i] * gc) + out[i]) + ring[i]) - in[i]) - rm[i];
        else
            for (uint32_t i = 0; i < wn; i++)
                f[i] = (((mass[i] * gc) + ring[i]) - in[i]) - rm[i];
    } else if (out)
        for (uint32_t i = 0; i < wn; i++)
            f[i] = ((((mass[i] * gc - (drag * mass[i]) * vc[i]) + out[i]) + ring[i]) - in[i]) - rm[i];
    else
        for (uint32_t i = 0; i < wn; i++)
            f[i] = (((mass[i] * gc - (drag * mass[i]) * vc[i]) + ring[i]) - in[i]) - rm[i];
    const uint32_t l = n - 1;
    LK_T f0 = mass[0] * gc - (drag * mass[0]) * vc[0], fl = mass[l] * gc - (drag * mass[l]) * vc[l];
    if (out) f0 += out[0], fl += out[l];
    f[0] = ((f0 + ring[0]) + wrap) - in[0];
    f[l] = ((fl - in[l]) - wrap) - ring[l - 1];
}

/* The sum term of a stage but the last: m v^2 of the free particles (its
 * gain and new-energy terms are zero, so they are not summed at all). */
LAT_INLINE void LK(rk4_kin)(uint32_t n, const LK_T *restrict mass, const LK_T *restrict inv_mass,
                            const LK_T *restrict Vx, const LK_T *restrict Vy, const LK_T *restrict Vz,
                            LK_S *restrict t_mv2)
{
    for (uint32_t i = 0; i < n; i++) {
        const LK_T mf = LK(pick)(inv_mass[i] != 0, mass[i], (LK_T)0);
        LK_ACC(t_mv2[i], mf, Vx[i] * Vx[i] + Vy[i] * Vy[i] + Vz[i] * Vz[i]);
    }
}

/* One component of a stage but the last: the weighted sums ax, av and the
 * next trial state xt = xb + h V, vt = vb + h F / m (xb, vb: the step's
 * base; a fixed particle stays there). `stage` is 0, 1 or 2, a constant in
 * each call. The first stage is evaluated at the base state, so its V is
 * vb itself: it leaves ax unwritten and the second stage starts the sum
 * from vb (vb + V wgt, the bits of ax + V wgt with ax = vb), a store and
 * a load fewer per particle and component. A fixed particle's ax and av
 * are summed too, though nothing moves it by them: a select there would be
 * a masked store (LK(pick) above), and the sums are then never left
 * unwritten for LK(rk4_sums) to read (it multiplies them by a mass of 0). */
LAT_INLINE void LK(rk4_stage)(uint32_t n, int stage, LK_T h, LK_T wgt, const LK_T *restrict inv_mass,
                              const LK_T *restrict Vc, const LK_T *restrict Fc, const LK_T *restrict xb,
                              const LK_T *restrict vb, LK_T *restrict xt, LK_T *restrict vt, LK_T *restrict ax,
                              LK_T *restrict av)
{
    for (uint32_t i = 0; i < n; i++) {
        const LK_T im = inv_mass[i], s = h * im;
        const bool fr = im != 0;
        const LK_T vc = Vc[i], fc = Fc[i];
        if (stage == 1)
            ax[i] = vb[i] + vc * wgt;
        else if (stage == 2)
            ax[i] = ax[i] + vc * wgt;
        av[i] = stage == 0 ? fc : av[i] + fc * wgt;
        xt[i] = fr ? xb[i] + vc * h : xb[i];
        vt[i] = fr ? vb[i] + fc * s : vb[i];
    }
}

/* The last stage's sums, from the base state before LK(rk4_last) moves it:
 * m V^2 at the evaluated state, m v'^2 after the step and the gain of
 * kinetic + gravitational energy. A loop of its own: GCC 12 does not
 * vectorise the update and the sums as one loop over two dozen arrays (too
 * many run-time alias checks). */
LAT_INLINE void LK(rk4_sums)(uint32_t n, LK_T h6, const LK_T *g, const LK_T *restrict mass,
                             const LK_T *restrict inv_mass, const LK_T *restrict Vx, const LK_T *restrict Vy,
                             const LK_T *restrict Vz, const LK_T *restrict Fx, const LK_T *restrict Fy,
                             const LK_T *restrict Fz, const LK_T *restrict axx, const LK_T *restrict axy,
                             const LK_T *restrict axz, const LK_T *restrict avx, const LK_T *restrict avy,
                             const LK_T *restrict avz, const LK_T *restrict ux, const LK_T *restrict uy,
                             const LK_T *restrict uz, LK_S *restrict t_mv2, LK_S *restrict t_gain,
                             LK_S *restrict t_mvn2)
{
    for (uint32_t i = 0; i < n; i++) {
        const LK_T im = inv_mass[i], s = h6 * im;
        const LK_T mf = LK(pick)(im != 0, mass[i], (LK_T)0);
        const LK_T vx = Vx[i], vy = Vy[i], vz = Vz[i], wx = ux[i], wy = uy[i], wz = uz[i];
        const LK_T ex = (axx[i] + vx) * h6, ey = (axy[i] + vy) * h6, ez = (axz[i] + vz) * h6;
        const LK_T nx = wx + (avx[i] + Fx[i]) * s, ny = wy + (avy[i] + Fy[i]) * s, nz = wz + (avz[i] + Fz[i]) * s;
        LK_ACC(t_mv2[i], mf, vx * vx + vy * vy + vz * vz);
        LK_ACC(t_mvn2[i], mf, nx * nx + ny * ny + nz * nz);
        LK_ACC(t_gain[i], mf,
               (LK_T)0.5 * ((nx - wx) * (nx + wx) + (ny - wy) * (ny + wy) + (nz - wz) * (nz + wz)) -
                   (g[0] * ex + g[1] * ey + g[2] * ez));
    }
}

/* The last stage, one component: x += h/6 (ax + V), v += h/6 (av + F) / m
 * (the same expressions as LK(rk4_sums)). */
LAT_INLINE void LK(rk4_last)(uint32_t n, LK_T h6, const LK_T *restrict inv_mass, const LK_T *restrict Vc,
                             const LK_T *restrict Fc, const LK_T *restrict axc, const LK_T *restrict avc,
                             LK_T *restrict xc, LK_T *restrict uc)
{
    for (uint32_t i = 0; i < n; i++) {
        const LK_T im = inv_mass[i], s = h6 * im;
        const bool fr = im != 0;
        const LK_T x0 = xc[i], u0 = uc[i];
        const LK_T e = (axc[i] + Vc[i]) * h6, nu = u0 + (avc[i] + Fc[i]) * s;
        xc[i] = LK(pick)(fr, x0 + e, x0);
        uc[i] = LK(pick)(fr, nu, u0);
    }
}

/* ---- a row or the hub moved, with its sum terms (the sweeps of both
 * precisions and the blocked passes; MODE_* from lattice_rows.h) ---- */

/* The hub's force: gravity and drag at its evaluated velocity v (one fused
 * multiply-add when `fused`: the explicit steps, as spn__force_on), then
 * its radial forces in radial order. */
LAT_INLINE void LK(hub_force)(bool fused, uint32_t n, LK_T m, LK_T drag, const LK_T *g, const LK_T *v,
                              LK_T *const *rad, LK_T *f)
{
    const LK_T dm = drag * m;
    for (int c = 0; c < 3; c++) {
        f[c] = fused ? LK_FMA(-dm, v[c], m * g[c]) : m * g[c] - dm * v[c];
        for (uint32_t i = 0; i < n; i++) f[c] += rad[c][i];
    }
}

/* The explicit hub (particle 0 of the state X, V; mass m, inverse im): its
 * force from its n radials, then moved in place; its sum terms into column
 * 0 of cs. */
LAT_INLINE void LK(hub_move)(uint32_t n, bool sym, LK_T dt, const LK_T *g, LK_T drag, LK_T m, LK_T im,
                             LK_T *const *X, LK_T *const *V, LK_T *const *rad, const lat_cols *cs)
{
    const LK_T v[3] = {V[0][0], V[1][0], V[2][0]};
    LK_T f[3];
    LK(hub_force)(true, n, m, drag, g, v, rad, f);
    const LK(moved) o = LK(one)(f[0], f[1], f[2], im, m, X[0][0], X[1][0], X[2][0], v[0], v[1], v[2], sym, dt, g);
    for (int c = 0; c < 3; c++) X[c][0] = o.x[c], V[c][0] = o.v[c];
    cs->c[L_MV2][0] = fma(o.mf, o.mv2, cs->c[L_MV2][0]), cs->c[L_GAIN][0] = fma(o.mf, o.gain, cs->c[L_GAIN][0]);
    cs->c[L_MVN2][0] = fma(o.mf, o.mvn2, cs->c[L_MVN2][0]);
}

/* An explicit row (n particles, state rows X, V, masses from mass and
 * inv_mass) with its forces complete (radial in, ring, radial out or NULL),
 * moved in place; its sum terms into the columns cs. */
LAT_INLINE void LK(row_move)(uint32_t n, bool sym, LK_T dt, const LK_T *g, LK_T drag, const LK_T *mass,
                             const LK_T *inv_mass, LK_T *const *X, LK_T *const *V, LK_T *const *ri,
                             LK_T *const *rg, LK_T *const *ro, const lat_cols *cs)
{
    /* (sym a constant in each call: GCC 12 does not vectorise a select on a
     * run-time bool) */
#define LK_ROW(sym)                                                                                             \
    LK(row)(n, sym, dt, g, drag, mass, inv_mass, X[0], X[1], X[2], V[0], V[1], V[2], ri[0], ri[1], ri[2], rg[0], \
            rg[1], rg[2], ro ? ro[0] : NULL, ro ? ro[1] : NULL, ro ? ro[2] : NULL, LK_TERMS(cs, L_MV2),          \
            LK_TERMS(cs, L_GAIN), LK_TERMS(cs, L_MVN2))
    if (sym) LK_ROW(true);
    else LK_ROW(false);
#undef LK_ROW
    LK_DONE(cs, L_MV2, n), LK_DONE(cs, L_GAIN, n), LK_DONE(cs, L_MVN2, n);
}

/* The rows an RK4 stage reads and writes (3 arrays each, at the row): the
 * velocity it is evaluated at, the step's base state, the next trial state
 * (NULL at the last stage) and the weighted sums. */
typedef struct LK(rk4_rows) {
    const LK_T *V[3];
    LK_T *xb[3], *vb[3], *xt[3], *vt[3], *ax[3], *av[3];
} LK(rk4_rows);

/* The three components of a stage but the last (`stage` 0-2, a constant
 * in each call). Three calls, not a loop: GCC 12 does not vectorise an
 * inlined function with restrict parameters inside a loop. */
LAT_INLINE void LK(rk4_stages)(uint32_t n, int stage, LK_T h, LK_T wgt, const LK_T *inv_mass, const LK(rk4_rows) *R,
                               LK_T *const *F)
{
    LK(rk4_stage)(n, stage, h, wgt, inv_mass, R->V[0], F[0], R->xb[0], R->vb[0], R->xt[0], R->vt[0], R->ax[0],
                  R->av[0]);
    LK(rk4_stage)(n, stage, h, wgt, inv_mass, R->V[1], F[1], R->xb[1], R->vb[1], R->xt[1], R->vt[1], R->ax[1],
                  R->av[1]);
    LK(rk4_stage)(n, stage, h, wgt, inv_mass, R->V[2], F[2], R->xb[2], R->vb[2], R->xt[2], R->vt[2], R->ax[2],
                  R->av[2]);
}

/* n particles of RK4 stage `stage` (0-3; weighted `wgt`, step fraction h,
 * or h = dt / 6 at the last), their force F known and masses from mass and
 * inv_mass; sum terms into the columns cs. n is the hub's 1 or a row's
 * LK(padded)(N): the padding's massless particles stay where they are
 * (zeros) and add nothing to the sums. kin_known: no drag, and the sum
 * of m v^2 at the first stage is known already, so it is not summed. (The
 * last stage's m v'^2 terms are those of the next step's first stage, bit
 * for bit: LK(rk4_sums) forms v' as LK(rk4_last) stores it, the masses
 * and the mass-0 select are the same, and the terms go into the same
 * columns in the same order. The float32 step keeps that sum from step to
 * step inside a call: spn__lat32.mv2.) */
LAT_INLINE void LK(rk4_update)(uint32_t n, int stage, LK_T h, LK_T wgt, LK_T drag, bool kin_known, const LK_T *g,
                               const LK_T *mass, const LK_T *inv_mass, const LK(rk4_rows) *R, LK_T *const *F,
                               const lat_cols *cs)
{
    if (stage < 3) {
        /* m v^2 at a stage's state serves the drag's loss (and, at the first
         * stage, the energy before the step); without drag the later stages
         * skip it, as drag * m v^2 would add exactly zero */
        if ((stage == 0 && !kin_known) || drag != 0) {
            LK(rk4_kin)(n, mass, inv_mass, R->V[0], R->V[1], R->V[2], LK_TERMS(cs, L_MV2));
            LK_DONE(cs, L_MV2, n);
        }
        /* (the stage a constant in each call, so that each copy of the
         * loop stores ax unconditionally or not at all) */
        if (stage == 0)
            LK(rk4_stages)(n, 0, h, wgt, inv_mass, R, F);
        else if (stage == 1)
            LK(rk4_stages)(n, 1, h, wgt, inv_mass, R, F);
        else
            LK(rk4_stages)(n, 2, h, wgt, inv_mass, R, F);
        return;
    }
    LK(rk4_sums)(n, h, g, mass, inv_mass, R->V[0], R->V[1], R->V[2], F[0], F[1], F[2], R->ax[0], R->ax[1],
                 R->ax[2], R->av[0], R->av[1], R->av[2], R->vb[0], R->vb[1], R->vb[2], LK_TERMS(cs, L_MV2),
                 LK_TERMS(cs, L_GAIN), LK_TERMS(cs, L_MVN2));
    LK_DONE(cs, L_MV2, n), LK_DONE(cs, L_GAIN, n), LK_DONE(cs, L_MVN2, n);
    LK(rk4_last)(n, h, inv_mass, R->V[0], F[0], R->ax[0], R->av[0], R->xb[0], R->vb[0]);
    LK(rk4_last)(n, h, inv_mass, R->V[1], F[1], R->ax[1], R->av[1], R->xb[1], R->vb[1]);
    LK(rk4_last)(n, h, inv_mass, R->V[2], F[2], R->ax[2], R->av[2], R->xb[2], R->vb[2]);
}

#undef LK_S
#undef LK_ACC
#undef LK_TERMS
#undef LK_DONE
