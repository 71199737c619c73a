/* The explicit integrators: forward Euler (Mehla 2005, eq. 4.5), symplectic
 * (semi-implicit) Euler, and classical fourth-order Runge-Kutta (eqs.
 * 4.16-4.19), the thesis' method.
 *
 * Euler and symplectic Euler are one spring pass and one fused particle pass
 * that gathers the force, updates v and x in place (gravity and drag, v' and
 * x' each one fused multiply-add, fma: one rounding, the same bits on every
 * processor, and about 3% off the lattice step, docs/physics-lattice.md),
 * keeps the old state for a
 * blow-up restore (unless w->no_backup: spn_world_advance keeps one copy per
 * call and replays instead, see step.c), and sums the energy terms the step
 * driver checks. Energy
 * changes are summed per particle (1/2 m (v'-v).(v'+v) - m g.(x'-x)), never
 * as differences of large totals, so they stay accurate far from the origin.
 *
 * External work is the force times the displacement actually taken
 * (fext . (x' - x)); for RK4 it is the RK4 quadrature of the power fext . v
 * over the four stages. Dissipation is the damping and drag power at the
 * evaluated states times the step (the same quadrature for RK4). */
#include "world_internal.h"

#include <string.h>

enum { S_KE_OLD, S_GAIN, S_DAMP, S_WORK, S_KE_NEW };

/* Particles [lo, hi) of an Euler or symplectic Euler step; the block's sums
 * into p[]. Inlined with constant flags below, so the common case (symplectic,
 * no external force, no backup) has no tests in its loop. */
static inline __attribute__((always_inline)) void explicit_block(
    const spn__gather_ctx *restrict c, uint32_t lo, uint32_t hi, double dt, bool symplectic, bool ext, bool air,
    bool backup, spn_vec3 *restrict x, spn_vec3 *restrict v, spn_vec3 *restrict x0, spn_vec3 *restrict v0,
    double *p)
{
    const spn_vec3 g = c->g;
    double ke_old = 0, gain = 0, work = 0, ke_new = 0;
    for (uint32_t i = lo; i < hi; i++) {
        const spn_vec3 xi = x[i], vi = v[i];
        if (backup) x0[i] = xi, v0[i] = vi;
        const double im = c->inv_mass[i];
        if (im == 0) continue;
        /* (external: fext[i], in air with its segments' air forces added here) */
        const spn_vec3 fe = ext ? (air ? spn__air_on(c, i, c->fext[i]) : c->fext[i]) : spn_v3(0, 0, 0);
        const spn_vec3 fs = spn__force_on(c, i, vi, false, true), fi = ext ? spn_v3_add(fs, fe) : fs;
        const spn_vec3 vn = spn__fma_v3(fi, dt * im, vi), vm = symplectic ? vn : vi;
        const spn_vec3 dx = spn_v3_scale(vm, dt);
        x[i] = spn__fma_v3(vm, dt, xi);
        v[i] = vn;
        const double m = c->mass[i];
        ke_old += m * spn_v3_dot(vi, vi);
        ke_new += m * spn_v3_dot(vn, vn);
        gain += m * (0.5 * spn_v3_dot(spn_v3_sub(vn, vi), spn_v3_add(vn, vi)) - spn_v3_dot(g, dx));
        if (ext) work += spn_v3_dot(fe, dx);
    }
    /* sum m v^2 is twice the kinetic energy, and drag dissipates drag m v^2 */
    p[S_KE_OLD] = 0.5 * ke_old, p[S_GAIN] = gain, p[S_DAMP] = c->drag * ke_old, p[S_WORK] = work,
    p[S_KE_NEW] = 0.5 * ke_new;
}

/* One block of the particle pass, compiled in clones like the spring kernels.
 * The flags' common cases get copies of their own: spn_world_advance's
 * steps (no backup) and spn_world_step's, which `spinneret animate` takes,
 * in still air and in air. With the flags as variables the loop kept their
 * tests: the README's physical web, 0.3 s of animation on one thread
 * (spn_animate, alternating runs, Zen 5), still air 0.361-0.376 ->
 * 0.331-0.362 s, in --wind air 1.040-1.093 -> 1.021-1.070. With `air` the
 * segments' air forces are gathered here (spn__air_on) instead of written
 * to fext by spn__external first: 2-3% off a step in air. Both the same
 * bits (fifty-third session). */
SPN__KERNEL static void explicit_range(const spn__gather_ctx *c, uint32_t lo, uint32_t hi, double dt, bool symplectic,
                                       bool ext, bool air, bool backup, spn_vec3 *x, spn_vec3 *v, spn_vec3 *x0,
                                       spn_vec3 *v0, double *p)
{
    if (symplectic && !ext && !backup) explicit_block(c, lo, hi, dt, true, false, false, false, x, v, x0, v0, p);
    else if (symplectic && !ext && backup) explicit_block(c, lo, hi, dt, true, false, false, true, x, v, x0, v0, p);
    else if (symplectic && air && backup) explicit_block(c, lo, hi, dt, true, true, true, true, x, v, x0, v0, p);
    else explicit_block(c, lo, hi, dt, symplectic, ext, air, backup, x, v, x0, v0, p);
}

void spn__step_explicit(spn_world *w, double dt, bool symplectic, spn__step_result *r)
{
    if (spn__lattice_explicit(w, dt, symplectic, r)) return;
    if (!w->force_fn && !spn__air_active(w) && spn__step_sweep(w, dt, symplectic, r)) return;
    spn__eval e;
    spn__spring_pass(w, w->t, w->x, w->v, &e);
    /* (the air's half forces on the ends added in the particle pass, not
     * written to fext first) */
    const bool ext = spn__external_user(w, w->t, w->x, w->v), air = spn__air_active(w);
    const uint32_t np = w->np, nb = spn__blocks(np);
    spn_vec3 *restrict x = w->x, *restrict v = w->v, *restrict x0 = w->x0, *restrict v0 = w->v0;
    double *partial = w->partial;
    const spn__gather_ctx ctx = spn__gather_ctx_of(w);
    const bool backup = !w->no_backup;
#pragma omp parallel for schedule(static) num_threads(spn__threads(w, np))
    for (uint32_t blk = 0; blk < nb; blk++) {
        const uint32_t lo = blk * SPN_BLOCK, hi = lo + SPN_BLOCK < np ? lo + SPN_BLOCK : np;
        const spn__gather_ctx c = ctx;
        double *p = partial + (size_t)blk * SPN_NSUMS;
        explicit_range(&c, lo, hi, dt, symplectic, ext, air, backup, x, v, x0, v0, p);
    }
    double sum[SPN_NSUMS];
    spn__sum_partials(w, nb, sum);
    r->e_before = sum[S_KE_OLD] + e.elastic;
    r->elastic = e.elastic;
    r->gain_kp = sum[S_GAIN];
    r->work = sum[S_WORK];
    r->dissipated = dt * (e.damp_power + sum[S_DAMP]);
    r->kinetic = sum[S_KE_NEW];
}

/* RK4 (eqs. 4.16-4.19) in four fused passes. Stage s evaluates the forces at
 * (X_s, V_s) (stage 0: x, v; then the trial state xt, vt) and, in the same
 * particle pass that gathers them, accumulates the weighted sums
 *   ax = v + 2 V_1 + 2 V_2,  av = f_0 + 2 f_1 + 2 f_2
 * and writes the next trial state xt = x + c h V_s, vt = v + c h f_s / m
 * (in place: particle i's gather reads only its own V_s[i]); the last pass
 * takes x += h/6 (ax + V_3), v += h/6 (av + f_3) / m. The forces go straight
 * from the gather into the update, so no force array is written or read. */
enum { R_KE, R_DAMP, R_EXT, R_GAIN, R_KE_NEW };

typedef struct rk4_ctx {
    spn__gather_ctx c;
    const spn_vec3 *restrict x, *restrict v;
    spn_vec3 *restrict xt, *restrict vt, *restrict ax, *restrict av;
    double h_next, weight, dt;
    int stage;
    bool ext;
} rk4_ctx;

static void rk4_block(const rk4_ctx *k, uint32_t lo, uint32_t hi, double *p)
{
    const spn__gather_ctx *c = &k->c;
    const spn_vec3 *vs = k->stage == 0 ? k->v : k->vt;
    double ke = 0, ep = 0;
    for (uint32_t i = lo; i < hi; i++) {
        const spn_vec3 vi = vs[i];
        const double im = c->inv_mass[i];
        if (im == 0) { /* a fixed particle stays where it is in every stage */
            k->xt[i] = k->x[i], k->vt[i] = k->v[i];
            continue;
        }
        const spn_vec3 f = spn__force_on(c, i, vi, k->ext, false);
        ke += c->mass[i] * spn_v3_dot(vi, vi);
        if (k->ext) ep += spn_v3_dot(c->fext[i], vi);
        if (k->stage == 0) {
            k->ax[i] = vi;
            k->av[i] = f;
        } else {
            k->ax[i] = spn_v3_add(k->ax[i], spn_v3_scale(vi, k->weight));
            k->av[i] = spn_v3_add(k->av[i], spn_v3_scale(f, k->weight));
        }
        k->xt[i] = spn_v3_add(k->x[i], spn_v3_scale(vi, k->h_next));
        k->vt[i] = spn_v3_add(k->v[i], spn_v3_scale(f, k->h_next * im));
    }
    p[R_KE] = 0.5 * ke, p[R_DAMP] = c->drag * ke, p[R_EXT] = ep;
}

/* The last stage: x += h/6 (ax + V_3), v += h/6 (av + f_3) / m. */
static void rk4_last_block(const rk4_ctx *k, spn_vec3 *restrict x, spn_vec3 *restrict v, spn_vec3 *restrict x0,
                           spn_vec3 *restrict v0, bool backup, uint32_t lo, uint32_t hi, double *p)
{
    const spn__gather_ctx *c = &k->c;
    const spn_vec3 gr = c->g;
    const double h6 = k->dt / 6;
    double ke = 0, ep = 0, gain = 0, ke_new = 0;
    for (uint32_t i = lo; i < hi; i++) {
        const spn_vec3 v3 = k->vt[i], xi = x[i], vi = v[i];
        if (backup) x0[i] = xi, v0[i] = vi;
        const double im = c->inv_mass[i];
        if (im == 0) continue;
        const spn_vec3 f = spn__force_on(c, i, v3, k->ext, false);
        const double m = c->mass[i];
        ke += m * spn_v3_dot(v3, v3);
        if (k->ext) ep += spn_v3_dot(c->fext[i], v3);
        const spn_vec3 dx = spn_v3_scale(spn_v3_add(k->ax[i], v3), h6);
        const spn_vec3 vn = spn_v3_add(vi, spn_v3_scale(spn_v3_add(k->av[i], f), h6 * im));
        x[i] = spn_v3_add(xi, dx);
        v[i] = vn;
        ke_new += 0.5 * m * spn_v3_dot(vn, vn);
        gain += 0.5 * m * spn_v3_dot(spn_v3_sub(vn, vi), spn_v3_add(vn, vi)) - m * spn_v3_dot(gr, dx);
    }
    p[R_KE] = 0.5 * ke, p[R_DAMP] = c->drag * ke, p[R_EXT] = ep, p[R_GAIN] = gain, p[R_KE_NEW] = ke_new;
}

spn_status spn__step_rk4(spn_world *w, double dt, spn__step_result *r)
{
    if (spn__lattice_rk4(w, dt, r)) return SPN_OK;
    spn_status st = spn__scratch(w, 4);
    if (st != SPN_OK) return st;
    static const double weight[4] = {1, 2, 2, 1}, frac[4] = {0, 0.5, 0.5, 1};
    const uint32_t np = w->np, nb = spn__blocks(np);
    double *partial = w->partial;
    const bool backup = !w->no_backup;
    rk4_ctx k = {spn__gather_ctx_of(w), w->x, w->v, w->tmp[SPN_TMP_A], w->tmp[SPN_TMP_B], w->tmp[SPN_TMP_C],
                 w->tmp[SPN_TMP_D], 0, 0, dt, 0, false};
    double work = 0, damp = 0, sum[SPN_NSUMS];
    for (int stage = 0; stage < 4; stage++) {
        const double t = w->t + frac[stage] * dt;
        const spn_vec3 *xs = stage ? k.xt : w->x, *vs = stage ? k.vt : w->v;
        spn__eval e;
        spn__spring_pass(w, t, xs, vs, &e);
        k.ext = spn__external(w, t, xs, vs);
        k.stage = stage;
        k.weight = weight[stage];
        k.h_next = stage < 3 ? frac[stage + 1] * dt : 0;
        const rk4_ctx kc = k;
#pragma omp parallel for schedule(static) num_threads(spn__threads(w, np))
        for (uint32_t blk = 0; blk < nb; blk++) {
            const uint32_t lo = blk * SPN_BLOCK, hi = lo + SPN_BLOCK < np ? lo + SPN_BLOCK : np;
            double *p = partial + (size_t)blk * SPN_NSUMS;
            if (stage < 3) rk4_block(&kc, lo, hi, p);
            else rk4_last_block(&kc, w->x, w->v, w->x0, w->v0, backup, lo, hi, p);
        }
        spn__sum_partials(w, nb, sum);
        if (stage == 0) {
            r->e_before = sum[R_KE] + e.elastic;
            r->elastic = e.elastic;
        }
        work += weight[stage] * sum[R_EXT];
        damp += weight[stage] * (e.damp_power + sum[R_DAMP]);
    }
    r->gain_kp = sum[R_GAIN];
    r->kinetic = sum[R_KE_NEW];
    r->work = dt / 6 * work;
    r->dissipated = dt / 6 * damp;
    return SPN_OK;
}
