/* Linearised backward Euler after Baraff & Witkin, "Large Steps in Cloth
 * Simulation" (SIGGRAPH 1998), section 3: one Newton step per time step,
 *   (M - h df/dv - h^2 df/dx) dv = h (f0 + h df/dx v0),
 *   v1 = v0 + dv,  x1 = x0 + h v1,
 * solved by conjugate gradients with a block-Jacobi preconditioner (the
 * inverse of each particle's 3x3 diagonal block) or, on large webs, the
 * equilibrium solver's multigrid (implicit_mg.c).
 * Fixed particles are filtered out (their rows and columns are the identity
 * with a zero right-hand side: their dv stays exactly 0).
 *
 * Spring Jacobian for l = x_a - x_b, L = |l|, u = l / L, rest r:
 *   df_a/dx_a = -k [ (1 - tau) u u^T + tau I ],  tau = 1 - r / L,
 * and df_a/dx_b = -df_a/dx_a. For a compressed spring tau < 0 makes the
 * matrix indefinite; tau is clamped at 0 (the negative transverse term
 * dropped), which keeps the system positive definite and CG applicable.
 * Slack tension-only and broken springs contribute nothing. Axial damping
 * gives df_a/dv_a = -kd u u^T; viscous drag -drag m I; air drag on a segment
 * -(c / 4) (I - u u^T) on each end and between them (c from the drag law at
 * the current relative air speed, the derivative of |u_n| frozen). The
 * damping force's dependence on x is left out (it is not symmetric and would
 * break CG; Baraff & Witkin drop that part too).
 *
 * Matrix-free: per spring we keep u and three coefficients (48 bytes) and
 * apply A as one spring pass plus one gather, the same fixed-order pattern
 * as the forces, so results do not depend on the thread count. An assembled
 * block-sparse matrix (symmetric 3x3 blocks, 104 bytes per spring) measured
 * slower per product at every web size and costs 60-108 ns per spring to
 * assemble each step (bench/bench_matvec.c, docs/physics.md).
 *
 * The fixed points of the step are exactly f(x) = 0 at v = 0, so a run
 * settles to the true equilibrium whatever the step. */
#include "world_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

enum { T_DV = SPN_TMP_A, T_R, T_Z, T_P, T_AP, T_B };

/* Per-spring Jacobian and the stiffness term of the right-hand side,
 * h^2 K (v_a - v_b), into w->fs. */
static void build_jacobian(spn_world *w, double h)
{
    const uint32_t ns = w->ns;
    const bool air = spn__air_active(w);
    const spn_vec3 *x = w->x, *v = w->v;
#pragma omp parallel for schedule(static) num_threads(spn__threads(w, ns))
    for (uint32_t s = 0; s < ns; s++) {
        spn__jac j = {{0, 0, 0}, 0, 0, 0};
        spn_vec3 g = {0, 0, 0};
        const spn__spring sp = w->hs[s];
        const uint32_t a = sp.a, b = spn__end_b(sp);
        const spn_vec3 l = spn_v3_sub(x[a], x[b]);
        const double len = spn_v3_len(l);
        if (len > 0 && !(w->hflags[s] & SPN_SPRING_BROKEN)) {
            j.u = spn_v3_scale(l, 1 / len);
            const double rest = sp.rest, k = sp.k;
            const bool slack = len < rest && (w->hflags[s] & SPN_SPRING_TENSION_ONLY);
            if (!slack) {
                const double tau = len > rest ? 1 - rest / len : 0;
                const double h2k = h * h * k;
                j.axial = h * sp.kd + h2k * (1 - tau);
                j.iso = h2k * tau;
                const spn_vec3 dv = spn_v3_sub(v[a], v[b]);
                g = spn_v3_add(spn_v3_scale(j.u, -h2k * (1 - tau) * spn_v3_dot(j.u, dv)), spn_v3_scale(dv, -j.iso));
            }
            if (air) j.air = h * w->cair[s] / 4;
        }
        w->jac[s] = j;
        w->fs[s] = g;
    }
}

/* Inverse of the symmetric 3x3 block (xx, yy, zz, xy, xz, yz), by cofactors. */
void spn__invert_sym3(const double a[6], double out[6])
{
    const double xx = a[0], yy = a[1], zz = a[2], xy = a[3], xz = a[4], yz = a[5];
    const double c0 = yy * zz - yz * yz, c1 = xx * zz - xz * xz, c2 = xx * yy - xy * xy;
    const double c3 = xz * yz - xy * zz, c4 = xy * yz - xz * yy, c5 = xy * xz - xx * yz;
    const double det = xx * c0 + xy * c3 + xz * c4;
    const double inv = 1 / det;
    out[0] = c0 * inv, out[1] = c1 * inv, out[2] = c2 * inv;
    out[3] = c3 * inv, out[4] = c4 * inv, out[5] = c5 * inv;
}

/* Particle i's diagonal block of A: mass (scaled by 1 + h drag) plus its
 * springs' Jacobian blocks. */
static void block_of(const spn_world *w, uint32_t i, double m_scale, double d[6])
{
    const double m = w->mass[i] * m_scale;
    d[0] = d[1] = d[2] = m;
    d[3] = d[4] = d[5] = 0;
    for (uint32_t k = w->adj_start[i]; k < w->adj_start[i + 1]; k++) {
        const spn__jac *j = &w->jac[w->adj[k] >> 1];
        const double iso = j->iso + j->air, ax = j->axial - j->air;
        const spn_vec3 u = j->u;
        d[0] += iso + ax * u.x * u.x, d[1] += iso + ax * u.y * u.y, d[2] += iso + ax * u.z * u.z;
        d[3] += ax * u.x * u.y, d[4] += ax * u.x * u.z, d[5] += ax * u.y * u.z;
    }
}

/* Right-hand side b = h f + h^2 K v, and each particle's 3x3 diagonal block
 * of A (block Jacobi's: a strand's node is stiff along the thread and soft
 * across it, which a scalar diagonal cannot see; inverted where wanted,
 * spn__implicit_invert, after the solve has chosen its preconditioner). */
static void build_rhs(spn_world *w, double h)
{
    const uint32_t np = w->np;
    spn_vec3 *b = w->tmp[T_B];
    double *blocks = w->pblock;
    const double m_scale = 1 + h * w->def.drag;
#pragma omp parallel for schedule(static) num_threads(spn__threads(w, np))
    for (uint32_t i = 0; i < np; i++) {
        double *d = blocks + 6 * (size_t)i;
        if (w->inv_mass[i] == 0) {
            b[i] = spn_v3(0, 0, 0);
            for (int c = 0; c < 6; c++) d[c] = 0;
            continue;
        }
        spn_vec3 bi = spn_v3_scale(w->f[i], h);
        block_of(w, i, m_scale, d);
        for (uint32_t k = w->adj_start[i]; k < w->adj_start[i + 1]; k++) {
            const uint32_t e = w->adj[k], s = e >> 1;
            bi = (e & 1u) ? spn_v3_sub(bi, w->fs[s]) : spn_v3_add(bi, w->fs[s]);
        }
        b[i] = bi;
    }
    if (w->ncontacts) spn__contact_system(w, h, b, blocks);
}

void spn__implicit_invert(spn_world *w, const int32_t *local, uint32_t n)
{
    const uint32_t np = w->np;
    const double *blocks = w->pblock;
    double *minv = w->pinv;
#pragma omp parallel for schedule(static) num_threads(spn__threads(w, np))
    for (uint32_t i = 0; i < np; i++) {
        if (local && (uint32_t)local[i] < n) continue; /* (-1: none) */
        double *mi = minv + 6 * (size_t)i;
        if (w->inv_mass[i] == 0)
            for (int c = 0; c < 6; c++) mi[c] = 0;
        else spn__invert_sym3(blocks + 6 * (size_t)i, mi);
    }
}

/* Per-spring product into fs (and fair with air): the force of the spring's
 * Jacobian on end a for the relative move d = p_a - p_b. */
static void apply_springs(spn_world *w, const spn_vec3 *restrict p, bool air)
{
    const uint32_t ns = w->ns;
    const spn__jac *restrict jac = w->jac;
    const spn__spring *restrict hs = w->hs;
    spn_vec3 *restrict fs = w->fs, *restrict fair = w->fair;
#pragma omp parallel for schedule(static) num_threads(spn__threads(w, ns))
    for (uint32_t s = 0; s < ns; s++) {
        const spn__jac j = jac[s];
        const spn_vec3 pa = p[hs[s].a], pb = p[spn__end_b(hs[s])];
        const spn_vec3 d = spn_v3_sub(pa, pb);
        fs[s] = spn_v3_add(spn_v3_scale(d, j.iso), spn_v3_scale(j.u, j.axial * spn_v3_dot(j.u, d)));
        if (air) {
            const spn_vec3 q = spn_v3_add(pa, pb);
            fair[s] = spn_v3_scale(spn_v3_sub(q, spn_v3_scale(j.u, spn_v3_dot(j.u, q))), j.air);
        }
    }
}

/* Ap = A p (fixed rows zero); returns p . Ap summed in block order. Without
 * air the gather reads a particle's springs as end a as one contiguous run
 * (added) and those as end b through b_adj (subtracted); air drag couples
 * both ends with the same sign and goes through the signed adjacency. */
static double apply(spn_world *w, double h, const spn_vec3 *restrict p, spn_vec3 *restrict ap)
{
    const uint32_t np = w->np, nb = spn__blocks(np);
    const bool air = spn__air_active(w);
    apply_springs(w, p, air);
    const double diag = 1 + h * w->def.drag;
    const spn__gather_ctx c = spn__gather_ctx_of(w);
    const uint32_t *restrict adj_start = w->adj_start, *restrict adj = w->adj;
    const spn_vec3 *restrict fs = w->fs, *restrict fair = w->fair;
    double *partial = w->partial;
#pragma omp parallel for schedule(static) num_threads(spn__threads(w, np))
    for (uint32_t blk = 0; blk < nb; blk++) {
        const uint32_t lo = blk * SPN_BLOCK, hi = lo + SPN_BLOCK < np ? lo + SPN_BLOCK : np;
        double dot = 0;
        for (uint32_t i = lo; i < hi; i++) {
            if (c.inv_mass[i] == 0) {
                ap[i] = spn_v3(0, 0, 0);
                continue;
            }
            const spn_vec3 pi = p[i];
            spn_vec3 y = spn_v3_scale(pi, c.mass[i] * diag);
            if (!air) {
                for (uint32_t s = c.a_start[i], end = c.a_start[i + 1]; s < end; s++)
                    y.x += fs[s].x, y.y += fs[s].y, y.z += fs[s].z;
                for (uint32_t k = c.b_start[i], end = c.b_start[i + 1]; k < end; k++) {
                    const spn_vec3 fe = fs[c.b_adj[k]];
                    y.x -= fe.x, y.y -= fe.y, y.z -= fe.z;
                }
            } else {
                for (uint32_t k = adj_start[i]; k < adj_start[i + 1]; k++) {
                    const uint32_t e = adj[k], s = e >> 1;
                    y = (e & 1u) ? spn_v3_sub(y, fs[s]) : spn_v3_add(y, fs[s]);
                    y = spn_v3_add(y, fair[s]);
                }
            }
            ap[i] = y;
            dot += spn_v3_dot(pi, y);
        }
        partial[(size_t)blk * SPN_NSUMS] = dot;
    }
    double sum = 0;
    for (uint32_t blk = 0; blk < nb; blk++) sum += partial[(size_t)blk * SPN_NSUMS];
    if (w->ncontacts) sum += spn__contact_apply(w, h, p, ap);
    return sum;
}

/* dv += alpha p; r -= alpha Ap; z = M^-1 r (block Jacobi inline, or the
 * multigrid after the loop). Returns r.z and r.r via out. */
static void cg_update(spn_world *w, double alpha, bool mg, double *rz, double *rr)
{
    spn_vec3 *dv = w->tmp[T_DV], *r = w->tmp[T_R], *z = w->tmp[T_Z];
    const spn_vec3 *p = w->tmp[T_P], *ap = w->tmp[T_AP];
    const double *minv = w->pinv;
    const uint32_t np = w->np, nb = spn__blocks(np);
    double *partial = w->partial;
#pragma omp parallel for schedule(static) num_threads(spn__threads(w, np))
    for (uint32_t blk = 0; blk < nb; blk++) {
        const uint32_t lo = blk * SPN_BLOCK, hi = lo + SPN_BLOCK < np ? lo + SPN_BLOCK : np;
        double a = 0, c = 0;
        for (uint32_t i = lo; i < hi; i++) {
            dv[i] = spn_v3_add(dv[i], spn_v3_scale(p[i], alpha));
            const spn_vec3 ri = spn_v3_sub(r[i], spn_v3_scale(ap[i], alpha));
            r[i] = ri;
            c += spn_v3_dot(ri, ri);
            if (mg) continue;
            const double *m = minv + 6 * (size_t)i;
            const spn_vec3 zi = spn_v3(m[0] * ri.x + m[3] * ri.y + m[4] * ri.z, m[3] * ri.x + m[1] * ri.y + m[5] * ri.z,
                                       m[4] * ri.x + m[5] * ri.y + m[2] * ri.z);
            z[i] = zi;
            a += spn_v3_dot(ri, zi);
        }
        partial[(size_t)blk * SPN_NSUMS] = a;
        partial[(size_t)blk * SPN_NSUMS + 1] = c;
    }
    if (mg) {
        spn__imp_mg_apply(w, r, z);
#pragma omp parallel for schedule(static) num_threads(spn__threads(w, np))
        for (uint32_t blk = 0; blk < nb; blk++) {
            const uint32_t lo = blk * SPN_BLOCK, hi = lo + SPN_BLOCK < np ? lo + SPN_BLOCK : np;
            double a = 0;
            for (uint32_t i = lo; i < hi; i++) a += spn_v3_dot(r[i], z[i]);
            partial[(size_t)blk * SPN_NSUMS] = a;
        }
    }
    double sum[SPN_NSUMS];
    spn__sum_partials(w, nb, sum);
    *rz = sum[0];
    *rr = sum[1];
}

/* p = z + beta p */
static void cg_direction(spn_world *w, double beta)
{
    spn_vec3 *p = w->tmp[T_P];
    const spn_vec3 *z = w->tmp[T_Z];
    const uint32_t np = w->np;
#pragma omp parallel for schedule(static) num_threads(spn__threads(w, np))
    for (uint32_t i = 0; i < np; i++) p[i] = spn_v3_add(z[i], spn_v3_scale(p[i], beta));
}

/* The round-off scale of the forces as a 2-norm, to compare with the CG
 * residual's: a particle's net force is a sum of its springs' forces and its
 * weight, each rounded at about an ulp of its magnitude, so the scale is
 * sqrt(sum over particles of (sum of their |f|)^2), taken here as
 * sqrt(2 sum_s |f_s|^2 + sum_i (m_i |g|)^2): each spring at its two ends,
 * the cross terms left out. (The sum of |f_s| over the web, which this
 * replaced, grows n times with the web where a 2-norm grows sqrt(n) times:
 * on the 100k web CG stopped at a fifteenth of a 1e-9 T0 residual and rest
 * took 237 implicit steps instead of 8.) Read from w->fs before the solve
 * uses it as scratch; summed in order, so the same bits on any thread count. */
static double force_round_off_scale(const spn_world *w)
{
    double s2 = 0, g2 = spn_v3_dot(w->def.gravity, w->def.gravity);
    for (uint32_t s = 0; s < w->ns; s++) s2 += 2 * spn_v3_dot(w->fs[s], w->fs[s]);
    for (uint32_t i = 0; i < w->np; i++)
        if (w->inv_mass[i] > 0) s2 += w->mass[i] * w->mass[i] * g2;
    return sqrt(s2);
}

/* Auto, on any web: block Jacobi past SPN__IMPLICIT_BJ_MAX iterations sends
 * this step length and longer ones to the multigrid or the factor
 * (spn__imp_mg_prepare; in the middle of a solve, that solve too). False
 * when the preconditioner is not auto's choice. */
static bool bj_took_long(spn_world *w, double h)
{
    if (w->implicit_pc != 0) return false;
    if (!(w->imp_bj_long > 0 && w->imp_bj_long <= h)) w->imp_bj_long = h;
    return true;
}

/* Preconditioned CG for A dv = b from dv = 0; returns the iterations. It
 * stops at relative residual def.cg_tolerance, or when the residual is down
 * to the round-off of the forces themselves (h times 1e-13 of their scale,
 * force_round_off_scale): at rest b is itself round-off and no tolerance
 * relative to it could be met. *unfinished: it stopped short of that (at
 * def.cg_max_iterations, or a breakdown). */
static int solve(spn_world *w, double h, double scale, bool *unfinished)
{
    bool mg = spn__imp_mg_prepare(w, h);
    if (!mg) spn__implicit_invert(w, NULL, 0); /* block Jacobi: every block (a switch to mg keeps them) */
    int mg_from = 0; /* the iteration at which prepare's preconditioner took over */
    const uint32_t np = w->np;
    spn_vec3 *dv = w->tmp[T_DV], *r = w->tmp[T_R], *z = w->tmp[T_Z], *p = w->tmp[T_P];
    memset(dv, 0, np * sizeof *dv);
    memcpy(r, w->tmp[T_B], np * sizeof *r);
    double rz, rr;
    memset(p, 0, np * sizeof *p);
    memset(w->tmp[T_AP], 0, np * sizeof *p);
    cg_update(w, 0, mg, &rz, &rr); /* z = M^-1 r and the norms */
    memcpy(p, z, np * sizeof *p);
    const double floor = 1e-13 * h * scale;
    double stop = w->def.cg_tolerance * w->def.cg_tolerance * rr;
    if (stop < floor * floor) stop = floor * floor;
    int it = 0;
    while (it < w->def.cg_max_iterations && rr > stop && rz > 0) {
        double pap = apply(w, h, p, w->tmp[T_AP]);
        if (!(pap > 0)) break;
        double rz_old = rz;
        cg_update(w, rz / pap, mg, &rz, &rr);
        it++;
        if (rr <= stop) break;
        bool restart;
        if (mg) /* a factor kept from an earlier step outrun: this step's */
            restart = spn__imp_mg_restart_due(w, it - mg_from) && spn__imp_mg_refactor(w);
        else /* block Jacobi outrun: auto's choice (prepare declines a small web's steps with contacts) */
            restart = mg = it == SPN__IMPLICIT_BJ_MAX + 1 && bj_took_long(w, h) && spn__imp_mg_prepare(w, h);
        if (restart) {
            mg_from = it;
            cg_update(w, 0, mg, &rz, &rr); /* z from the new preconditioner; dv and r as they are */
            memcpy(p, z, np * sizeof *p);
            continue;
        }
        cg_direction(w, rz / rz_old);
    }
    *unfinished = rr > stop;
    if (mg) spn__imp_mg_solved(w, it - mg_from);
    else if (it > SPN__IMPLICIT_BJ_MAX) bj_took_long(w, h);
    return it;
}

/* v = v0 + dv, x = x0 + h v; the energy sums of the step. */
static void finish(spn_world *w, double h, bool ext, spn__step_result *r)
{
    const spn_vec3 *dv = w->tmp[T_DV], g = w->def.gravity;
    const uint32_t np = w->np, nb = spn__blocks(np);
    const double drag = w->def.drag;
    double *partial = w->partial;
#pragma omp parallel for schedule(static) num_threads(spn__threads(w, np))
    for (uint32_t blk = 0; blk < nb; blk++) {
        const uint32_t lo = blk * SPN_BLOCK, hi = lo + SPN_BLOCK < np ? lo + SPN_BLOCK : np;
        double gain = 0, ke = 0, work = 0, damp = 0;
        for (uint32_t i = lo; i < hi; i++) {
            if (w->inv_mass[i] == 0) continue;
            const spn_vec3 vi = w->v[i], vn = spn_v3_add(vi, dv[i]), dx = spn_v3_scale(vn, h);
            w->x[i] = spn_v3_add(w->x[i], dx);
            w->v[i] = vn;
            const double m = w->mass[i], vn2 = spn_v3_dot(vn, vn);
            gain += 0.5 * m * spn_v3_dot(dv[i], spn_v3_add(vn, vi)) - m * spn_v3_dot(g, dx);
            ke += 0.5 * m * vn2;
            damp += drag * m * vn2;
            if (ext) work += spn_v3_dot(w->fext[i], dx);
        }
        double *pp = partial + (size_t)blk * SPN_NSUMS;
        pp[0] = gain, pp[1] = ke, pp[2] = work, pp[3] = damp;
    }
    double sum[SPN_NSUMS];
    spn__sum_partials(w, nb, sum);
    double spring_damp = 0; /* axial damping power at the new velocities */
    for (uint32_t s = 0; s < w->ns; s++) {
        const spn__spring *sp = &w->hs[s];
        const double rate = spn_v3_dot(w->jac[s].u, spn_v3_sub(w->v[sp->a], w->v[spn__end_b(*sp)]));
        spring_damp += sp->kd * rate * rate;
    }
    r->gain_kp = sum[0];
    r->kinetic = sum[1];
    r->work = sum[2];
    r->dissipated = h * (sum[3] + spring_damp);
}

/* The mechanical energy (kinetic, elastic, gravitational) the step would
 * create at a fraction alpha of its move, x1 = x0 + alpha h (v0 + dv) and
 * v1 = alpha (v0 + dv), net of the external forces' work; its round-off
 * scale in *noise: 1e-12 of the terms summed, and the work of the forces'
 * own round-off (1e-13 of force_round_off_scale, as the CG stop takes it)
 * over the move, which bounds what a step CG left at dv = 0 (the web at
 * rest to round-off) can gain. Each spring's change is taken as a product
 * (spn__spring_energy_change) of its length change, found without
 * cancellation, so a step of a web near rest is not lost against the web's
 * whole energy. The per-particle moves go to
 * tmp[T_R], free once the solve is done. Summed in block order: the same
 * bits on any thread count. */
static double step_energy_gain(spn_world *w, double h, double alpha, bool ext, double force_scale, double *noise)
{
    const spn_vec3 *dv = w->tmp[T_DV], *v0 = w->v, *x = w->x, g = w->def.gravity;
    spn_vec3 *dx = w->tmp[T_R];
    const uint32_t np = w->np, ns = w->ns, nbp = spn__blocks(np), nbs = spn__blocks(ns);
    double *partial = w->partial;
#pragma omp parallel for schedule(static) num_threads(spn__threads(w, np))
    for (uint32_t blk = 0; blk < nbp; blk++) {
        const uint32_t lo = blk * SPN_BLOCK, hi = lo + SPN_BLOCK < np ? lo + SPN_BLOCK : np;
        double gain = 0, size = 0, move2 = 0;
        for (uint32_t i = lo; i < hi; i++) {
            if (w->inv_mass[i] == 0) {
                dx[i] = spn_v3(0, 0, 0);
                continue;
            }
            const spn_vec3 v1 = spn_v3_scale(spn_v3_add(v0[i], dv[i]), alpha);
            const spn_vec3 d = spn_v3_scale(v1, h);
            dx[i] = d;
            move2 += spn_v3_dot(d, d);
            const double m = w->mass[i];
            /* 1/2 m (|v1|^2 - |v0|^2) as a product, v1 - v0 taken directly */
            const double kin = 0.5 * m * spn_v3_dot(spn_v3_sub(v1, v0[i]), spn_v3_add(v1, v0[i]));
            const double grav = -m * spn_v3_dot(g, d), work = ext ? spn_v3_dot(w->fext[i], d) : 0;
            gain += kin + grav - work;
            size += fabs(kin) + fabs(grav) + fabs(work);
        }
        partial[(size_t)blk * SPN_NSUMS] = gain;
        partial[(size_t)blk * SPN_NSUMS + 1] = size;
        partial[(size_t)blk * SPN_NSUMS + 2] = move2;
    }
    double sum[SPN_NSUMS], gain, size, move;
    spn__sum_partials(w, nbp, sum);
    gain = sum[0], size = sum[1], move = sqrt(sum[2]);
    const spn__spring *hs = w->hs;
#pragma omp parallel for schedule(static) num_threads(spn__threads(w, ns))
    for (uint32_t blk = 0; blk < nbs; blk++) {
        const uint32_t lo = blk * SPN_BLOCK, hi = lo + SPN_BLOCK < ns ? lo + SPN_BLOCK : ns;
        double de = 0, dabs = 0;
        for (uint32_t s = lo; s < hi; s++) {
            const spn__spring sp = hs[s];
            const uint32_t a = sp.a, b = spn__end_b(sp);
            const spn_vec3 l0 = spn_v3_sub(x[a], x[b]), d = spn_v3_sub(dx[a], dx[b]), l1 = spn_v3_add(l0, d);
            const double len0 = spn_v3_len(l0), len1 = spn_v3_len(l1), sum_len = len0 + len1;
            /* |l1| - |l0| = (2 l0.d + d.d) / (|l1| + |l0|), without cancellation */
            const double dlen = sum_len > 0 ? (2 * spn_v3_dot(l0, d) + spn_v3_dot(d, d)) / sum_len : 0;
            const double e0 = len0 - sp.rest;
            const double u = spn__spring_energy_change(sp.k, spn__tension_only(sp), e0, e0 + dlen, dlen);
            de += u;
            dabs += fabs(u);
        }
        partial[(size_t)blk * SPN_NSUMS] = de;
        partial[(size_t)blk * SPN_NSUMS + 1] = dabs;
    }
    spn__sum_partials(w, nbs, sum);
    gain += sum[0], size += sum[1];
    *noise = 1e-12 * size + 1e-13 * force_scale * move;
    return gain;
}

/* Halvings of a step's move that may be tried before the step is taken as
 * it is (the 30th leaves a billionth of the move). */
#define IMPLICIT_CUTS 30

/* A passive web's mechanical energy cannot grow: damping and drag only take
 * energy out, and backward Euler solved exactly only loses more. The single
 * linearised step can create energy where the model is wrong: a thread that
 * goes slack within the step, or a solve that ran out of CG iterations (on
 * a Zilla web as built, with particles of 1e-11 kg, every 5 ms step hit the
 * 1,000 cap, and the steps stretched capture threads 3,000-fold within 30
 * simulated seconds). So the move is halved, keeping its direction, until
 * it creates no energy beyond round-off; a short enough move along a
 * descent direction always passes, and the kinetic energy falls with it.
 * A step that passes whole keeps its bits. Only where asked for
 * (spn_world_set_energy_limit): in an animation a halved move slows the whole
 * web, and in test_anim_strike's thread it took a slow prey's bounce (its
 * ledger's unbooked share went from 0.2% to 26%); and where asked for only
 * after an unfinished solve, only then. dv is rescaled in place; returns
 * the halvings, and in *lost the mechanical energy the step takes out net
 * of the external work (what the books count as dissipated after a cut).
 * Not with contacts: a prey pushing the web does work no term here counts. */
static int limit_to_energy(spn_world *w, double h, bool ext, double force_scale, double *lost)
{
    double alpha = 1, noise, gain;
    int cuts = 0;
    while ((gain = step_energy_gain(w, h, alpha, ext, force_scale, &noise)) > noise && cuts < IMPLICIT_CUTS) {
        alpha *= 0.5;
        cuts++;
    }
    *lost = -gain;
    if (cuts == 0) return 0;
    spn_vec3 *dv = w->tmp[T_DV];
    const spn_vec3 *v0 = w->v;
    const uint32_t np = w->np;
#pragma omp parallel for schedule(static) num_threads(spn__threads(w, np))
    for (uint32_t i = 0; i < np; i++)
        if (w->inv_mass[i] != 0) dv[i] = spn_v3_sub(spn_v3_scale(spn_v3_add(v0[i], dv[i]), alpha), v0[i]);
    return cuts;
}

spn_status spn__step_implicit(spn_world *w, double h, spn__step_result *r)
{
    spn_status st = spn__scratch(w, 6);
    if (st != SPN_OK) return st;
    if (!w->pblock && !(w->pblock = malloc((w->np ? w->np : 1) * 6 * sizeof *w->pblock)))
        return spn_error(SPN_ERR_NOMEM, "out of memory for the implicit solver (%u particles)", w->np);
    if (!w->pinv && !(w->pinv = malloc((w->np ? w->np : 1) * 6 * sizeof *w->pinv)))
        return spn_error(SPN_ERR_NOMEM, "out of memory for the implicit solver (%u particles)", w->np);
    if (!w->jac && !(w->jac = malloc((w->ns ? w->ns : 1) * sizeof *w->jac)))
        return spn_error(SPN_ERR_NOMEM, "out of memory for the implicit solver (%u springs)", w->ns);
    memcpy(w->x0, w->x, w->np * sizeof *w->x);
    memcpy(w->v0, w->v, w->np * sizeof *w->v);
    spn__eval e;
    spn__eval_forces(w, w->t, w->x, w->v, w->f, &e);
    bool ext = w->force_fn || spn__air_active(w);
    r->e_before = e.kinetic + e.elastic;
    r->elastic = e.elastic;
    const double scale = force_round_off_scale(w);
    build_jacobian(w, h);
    if (w->ncontacts) spn__contact_begin(w);
    build_rhs(w, h);
    bool unfinished;
    w->last.cg_iterations = solve(w, h, scale, &unfinished);
    /* One-sided contacts (contact.c): drop those the solve left pulling. */
    for (int round = 0; round < 4 && w->ncontacts && spn__contact_release(w, h, w->tmp[T_DV]); round++) {
        build_jacobian(w, h); /* the solve used fs as scratch */
        build_rhs(w, h);
        w->last.cg_iterations += solve(w, h, scale, &unfinished);
    }
    double lost = 0;
    const bool limit = w->energy_limit == SPN_ENERGY_LIMIT_ALWAYS ||
                       (w->energy_limit == SPN_ENERGY_LIMIT_UNFINISHED && unfinished);
    w->last.cuts = limit && !w->ncontacts ? limit_to_energy(w, h, ext, scale, &lost) : 0;
    finish(w, h, ext, r);
    if (w->last.cuts) r->dissipated = lost; /* the books close exactly: no estimate of drag and damping */
    return SPN_OK;
}
