/* The explicit integrators: forward Euler (Mehla 2005, eq. 4.5), symplectic
 * (semi-implicit) Euler, and classical fourth-order Runge-Kutta (eqs.
 * 4.16-4.19), the thesis' method.
 *
 * Euler and symplectic Euler are one spring pass and one fused particle pass
 * that gathers the force, updates v and x in place, keeps the old state for a
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
    const spn__gather_ctx *restrict c, uint32_t lo, uint32_t hi, double dt, bool symplectic, bool ext, bool backup,
    spn_vec3 *restrict x, spn_vec3 *restrict v, spn_vec3 *restrict x0, spn_vec3 *restrict v0, double *p)
{
    const spn_vec3 g = c->g;
    double ke_old = 0, gain = 0, work = 0, ke_new = 0;
    for (uint32_t i = lo; i < hi; i++) {
        const spn_vec3 xi = x[i], vi = v[i];
        if (backup) x0[i] = xi, v0[i] = vi;
        const double im = c->inv_mass[i];
        if (im == 0) continue;
        const spn_vec3 fi = spn__force_on(c, i, vi, ext);
        const spn_vec3 vn = spn_v3_add(vi, spn_v3_scale(fi, dt * im));
        const spn_vec3 dx = spn_v3_scale(symplectic ? vn : vi, dt);
        x[i] = spn_v3_add(xi, dx);
        v[i] = vn;
        const double m = c->mass[i];
        ke_old += m * spn_v3_dot(vi, vi);
        ke_new += m * spn_v3_dot(vn, vn);
        gain += m * (0.5 * spn_v3_dot(spn_v3_sub(vn, vi), spn_v3_add(vn, vi)) - spn_v3_dot(g, dx));
        if (ext) work += spn_v3_dot(c->fext[i], dx);
    }
    /* sum m v^2 is twice the kinetic energy, and drag dissipates drag m v^2 */
    p[S_KE_OLD] = 0.5 * ke_old, p[S_GAIN] = gain, p[S_DAMP] = c->drag * ke_old, p[S_WORK] = work,
    p[S_KE_NEW] = 0.5 * ke_new;
}

void spn__step_explicit(spn_world *w, double dt, bool symplectic, spn__step_result *r)
{
    spn__eval e;
    spn__spring_pass(w, w->t, w->x, w->v, &e);
    const bool ext = spn__external(w, w->t, w->x, w->v);
    const uint32_t np = w->np, nb = spn__blocks(np);
    spn_vec3 *restrict x = w->x, *restrict v = w->v, *restrict x0 = w->x0, *restrict v0 = w->v0;
    double *partial = w->partial;
    const spn__gather_ctx ctx = spn__gather_ctx_of(w);
    const bool backup = !w->no_backup, fast = symplectic && !ext && !backup;
#pragma omp parallel for schedule(static) num_threads(spn__threads(w, np))
    for (uint32_t blk = 0; blk < nb; blk++) {
        const uint32_t lo = blk * SPN_BLOCK, hi = lo + SPN_BLOCK < np ? lo + SPN_BLOCK : np;
        const spn__gather_ctx c = ctx;
        double *p = partial + (size_t)blk * SPN_NSUMS;
        if (fast) explicit_block(&c, lo, hi, dt, true, false, false, x, v, x0, v0, p);
        else explicit_block(&c, lo, hi, dt, symplectic, ext, backup, x, v, x0, v0, p);
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

/* One RK4 stage's state: xt = x + h vprev, vt = v + h f / m (f from the
 * previous stage), accumulating weight c of the previous stage first. */
static void rk4_stage(spn_world *w, double h, double c, bool first)
{
    spn_vec3 *xt = w->tmp[SPN_TMP_A], *vt = w->tmp[SPN_TMP_B], *ax = w->tmp[SPN_TMP_C], *av = w->tmp[SPN_TMP_D];
    const spn_vec3 *x = w->x, *v = w->v, *f = w->f;
    const uint32_t np = w->np;
#pragma omp parallel for schedule(static) num_threads(spn__threads(w, np))
    for (uint32_t i = 0; i < np; i++) {
        const spn_vec3 vprev = first ? v[i] : vt[i];
        if (first) {
            ax[i] = vprev;
            av[i] = f[i];
        } else {
            ax[i] = spn_v3_add(ax[i], spn_v3_scale(vprev, c));
            av[i] = spn_v3_add(av[i], spn_v3_scale(f[i], c));
        }
        const double im = w->inv_mass[i];
        xt[i] = im > 0 ? spn_v3_add(x[i], spn_v3_scale(vprev, h)) : x[i];
        vt[i] = im > 0 ? spn_v3_add(v[i], spn_v3_scale(f[i], h * im)) : v[i];
    }
}

/* x += dt/6 (sum of weighted stage velocities), v likewise with forces. */
static void rk4_finish(spn_world *w, double dt, spn__step_result *r)
{
    const spn_vec3 *vt = w->tmp[SPN_TMP_B], *ax = w->tmp[SPN_TMP_C], *av = w->tmp[SPN_TMP_D], *f = w->f;
    spn_vec3 *x = w->x, *v = w->v, *x0 = w->x0, *v0 = w->v0;
    const spn_vec3 g = w->def.gravity;
    const uint32_t np = w->np, nb = spn__blocks(np);
    double *partial = w->partial;
    const bool backup = !w->no_backup;
#pragma omp parallel for schedule(static) num_threads(spn__threads(w, np))
    for (uint32_t blk = 0; blk < nb; blk++) {
        const uint32_t lo = blk * SPN_BLOCK, hi = lo + SPN_BLOCK < np ? lo + SPN_BLOCK : np;
        double gain = 0, ke_new = 0;
        for (uint32_t i = lo; i < hi; i++) {
            const spn_vec3 xi = x[i], vi = v[i];
            if (backup) x0[i] = xi, v0[i] = vi;
            const double im = w->inv_mass[i];
            if (im == 0) continue;
            const spn_vec3 dx = spn_v3_scale(spn_v3_add(ax[i], vt[i]), dt / 6);
            const spn_vec3 vn = spn_v3_add(vi, spn_v3_scale(spn_v3_add(av[i], f[i]), dt / 6 * im));
            x[i] = spn_v3_add(xi, dx);
            v[i] = vn;
            const double m = w->mass[i];
            ke_new += 0.5 * m * spn_v3_dot(vn, vn);
            gain += 0.5 * m * spn_v3_dot(spn_v3_sub(vn, vi), spn_v3_add(vn, vi)) - m * spn_v3_dot(g, dx);
        }
        partial[(size_t)blk * SPN_NSUMS + S_GAIN] = gain;
        partial[(size_t)blk * SPN_NSUMS + S_KE_NEW] = ke_new;
    }
    double sum[SPN_NSUMS];
    spn__sum_partials(w, nb, sum);
    r->gain_kp = sum[S_GAIN];
    r->kinetic = sum[S_KE_NEW];
}

spn_status spn__step_rk4(spn_world *w, double dt, spn__step_result *r)
{
    spn_status st = spn__scratch(w, 4);
    if (st != SPN_OK) return st;
    static const double weight[4] = {1, 2, 2, 1}, frac[4] = {0, 0.5, 0.5, 1};
    double work = 0, damp = 0;
    spn__eval e;
    spn__eval_forces(w, w->t, w->x, w->v, w->f, &e);
    r->e_before = e.kinetic + e.elastic;
    r->elastic = e.elastic;
    work += e.ext_power;
    damp += e.damp_power;
    for (int stage = 1; stage < 4; stage++) {
        double h = frac[stage] * dt;
        rk4_stage(w, h, weight[stage - 1], stage == 1);
        spn__eval_forces(w, w->t + h, w->tmp[SPN_TMP_A], w->tmp[SPN_TMP_B], w->f, &e);
        work += weight[stage] * e.ext_power;
        damp += weight[stage] * e.damp_power;
    }
    rk4_finish(w, dt, r);
    r->work = dt / 6 * work;
    r->dissipated = dt / 6 * damp;
    return SPN_OK;
}
