/* Preconditioned conjugate gradients for one Newton step of the equilibrium
 * solver (A p = f, A the projected Hessian over free particles), and the
 * simple preconditioners: Jacobi (the diagonal) and block Jacobi (each
 * particle's 3x3 diagonal block inverted, which undoes the local anisotropy
 * of silk: a thread is ~50x stiffer along itself than across). The multigrid
 * preconditioner lives in equilibrium_mg.c.
 *
 * Every sum is a fixed-order block reduction (spn__eq_dot), so the iterates
 * are the same bits for any thread count. */
#include "core/big_alloc.h"
#include "equilibrium_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define PAR_MIN 32768u

#ifdef _OPENMP /* (used by OpenMP pragmas only) */
static inline int team(const spn__eq *e) { return e->n < PAR_MIN ? 1 : e->threads; }
#endif

spn_status spn__precond_setup(spn__precond *pc, spn__eq *e)
{
    const uint32_t n = e->n;
    if (!pc->inv) {
        pc->inv = spn__big_alloc(6 * (size_t)(n ? n : 1) * sizeof *pc->inv);
        if (!pc->inv) return spn_error(SPN_ERR_NOMEM, "equilibrium: out of memory");
    }
    int bad = 0;
    bool block = pc->kind != SPN_PRECOND_JACOBI;
#pragma omp parallel for schedule(static) num_threads(team(e)) reduction(+ : bad)
    for (uint32_t i = 0; i < n; i++) {
        const double *d = e->diag + 6 * (size_t)i;
        double *inv = pc->inv + 6 * (size_t)i;
        if (block) {
            if (!spn__sym_inverse(d, inv)) bad++;
        } else if (d[0] > 0 && d[1] > 0 && d[2] > 0) {
            inv[0] = 1 / d[0];
            inv[1] = 1 / d[1];
            inv[2] = 1 / d[2];
            inv[3] = inv[4] = inv[5] = 0;
        } else {
            bad++;
        }
    }
    if (bad) return SPN_ERR_UNSTABLE; /* a particle without stiffness: the caller shifts the diagonal */
    if (pc->kind == SPN_PRECOND_MULTIGRID) {
        if (spn__eq_lanes32(e) != SPN_OK) return spn_error(SPN_ERR_NOMEM, "equilibrium: out of memory");
        return spn__mg_setup(&pc->mg, e, pc->inv);
    }
    if (pc->kind == SPN_PRECOND_CYCLIC) return spn__cyc_factor(pc->cyc, e) ? SPN_OK : SPN_ERR_UNSTABLE;
    return SPN_OK;
}

/* Symmetric block Gauss-Seidel, M = (D + L) D^-1 (D + U) in particle order:
 * a forward sweep solves (D + L) y = r, a backward one (D + U) z = D y.
 * Sequential by nature (so it runs on one thread and gives the same bits). */
void spn__sgs_apply(const spn__eq *e, const double *inv, const double *r, double *z)
{
    const uint32_t n = e->n;
    const uint32_t *start = e->adj_start;
    const int32_t *col = e->adj_col;
    for (uint32_t i = 0; i < n; i++) {
        double acc[3] = {r[3 * i], r[3 * i + 1], r[3 * i + 2]};
        for (uint32_t j = start[i]; j < start[i + 1]; j++) {
            uint32_t c = (uint32_t)col[j];
            if (c >= i) continue;
            double t[3], o[6];
            spn__sym_mul(spn__eq_offd(e, j, o), z + 3 * (size_t)c, t);
            acc[0] -= t[0], acc[1] -= t[1], acc[2] -= t[2];
        }
        spn__sym_mul(inv + 6 * (size_t)i, acc, z + 3 * (size_t)i);
    }
    /* z now holds y; (D + U) z = D y  <=>  z_i = y_i - D_i^-1 sum_{j > i} A_ij z_j */
    for (uint32_t i = n; i-- > 0;) {
        double acc[3] = {0, 0, 0};
        for (uint32_t j = start[i]; j < start[i + 1]; j++) {
            uint32_t c = (uint32_t)col[j];
            if (c <= i) continue;
            double t[3], o[6];
            spn__sym_mul(spn__eq_offd(e, j, o), z + 3 * (size_t)c, t);
            acc[0] += t[0], acc[1] += t[1], acc[2] += t[2];
        }
        double d[3];
        spn__sym_mul(inv + 6 * (size_t)i, acc, d);
        z[3 * i] -= d[0], z[3 * i + 1] -= d[1], z[3 * i + 2] -= d[2];
    }
}

void spn__precond_apply(const spn__precond *pc, const spn__eq *e, const double *r, double *z)
{
    if (pc->kind == SPN_PRECOND_SGS) {
        spn__sgs_apply(e, pc->inv, r, z);
        return;
    }
    if (pc->kind == SPN_PRECOND_MULTIGRID && pc->mg) {
        spn__mg_apply(pc->mg, e, r, z);
        return;
    }
    if (pc->kind == SPN_PRECOND_CYCLIC) {
        spn__cyc_apply(pc->cyc, e, r, z);
        return;
    }
    const uint32_t n = e->n;
#pragma omp parallel for schedule(static) num_threads(team(e))
    for (uint32_t i = 0; i < n; i++) spn__sym_mul(pc->inv + 6 * (size_t)i, r + 3 * (size_t)i, z + 3 * (size_t)i);
}

void spn__precond_free(spn__precond *pc)
{
    free(pc->inv);
    spn__mg_free(pc->mg);
    spn__cyc_free(pc->cyc);
    pc->inv = NULL;
    pc->mg = NULL;
    pc->cyc = NULL;
}

double spn__precond_contraction(const spn__precond *pc, const spn__eq *e, unsigned components, int cycles,
                                double *worst, double *work)
{
    const size_t n3 = 3 * (size_t)e->n;
    double *x = work, *y = work + n3, *z = work + 2 * n3;
    uint64_t s = 0x9E3779B97F4A7C15ull; /* xorshift64: the same start on every machine */
    for (size_t i = 0; i < n3; i++) {
        s ^= s << 13, s ^= s >> 7, s ^= s << 17;
        x[i] = (components >> (i % 3)) & 1u ? (double)(s >> 11) / 9007199254740992.0 - 0.5 : 0;
    }
    const int tail = cycles / 4 > 0 ? cycles / 4 : 1;
    double energy = spn__eq_matvec_dot(e, x, y), log_sum = 0;
    *worst = 0;
    for (int c = 0; c < cycles; c++) {
        spn__precond_apply(pc, e, y, z); /* y = A x from the last energy */
        for (size_t i = 0; i < n3; i++) x[i] -= z[i];
        const double next = spn__eq_matvec_dot(e, x, y);
        const double factor = energy > 0 ? sqrt(fmax(next, 0) / energy) : 0;
        *worst = fmax(*worst, factor);
        if (c >= cycles - tail) log_sum += log(fmax(factor, 1e-300));
        energy = next;
    }
    return exp(log_sum / tail);
}

/* z = M^-1 r; returns r . z (block preconditioners fused in one pass). */
static double precond_dot(const spn__precond *pc, const spn__eq *e, const double *r, double *z)
{
    if ((pc->kind == SPN_PRECOND_MULTIGRID && pc->mg) || pc->kind == SPN_PRECOND_SGS || pc->kind == SPN_PRECOND_CYCLIC) {
        spn__precond_apply(pc, e, r, z);
        return spn__eq_dot(e, r, z);
    }
    const uint32_t n = e->n, nchunks = e->nchunks;
#pragma omp parallel for schedule(static) num_threads(team(e))
    for (uint32_t c = 0; c < nchunks; c++) {
        uint32_t end = (c + 1) * SPN__EQ_CHUNK < n ? (c + 1) * SPN__EQ_CHUNK : n;
        double s0 = 0, s1 = 0, s2 = 0;
        for (uint32_t i = c * SPN__EQ_CHUNK; i < end; i++) {
            const double *ri = r + 3 * (size_t)i, *h = pc->inv + 6 * (size_t)i;
            /* scalars: writing z and reading it back would stall on store forwarding */
            double z0 = h[0] * ri[0] + h[3] * ri[1] + h[4] * ri[2];
            double z1 = h[3] * ri[0] + h[1] * ri[1] + h[5] * ri[2];
            double z2 = h[4] * ri[0] + h[5] * ri[1] + h[2] * ri[2];
            z[3 * (size_t)i] = z0, z[3 * (size_t)i + 1] = z1, z[3 * (size_t)i + 2] = z2;
            s0 += ri[0] * z0;
            s1 += ri[1] * z1;
            s2 += ri[2] * z2;
        }
        e->partial[c] = s0 + s1 + s2;
    }
    double sum = 0;
    for (uint32_t c = 0; c < nchunks; c++) sum += e->partial[c];
    return sum;
}

/* y = x + b y */
static void xpby(const spn__eq *e, const double *x, double b, double *y)
{
    const uint32_t n3 = 3 * e->n;
#pragma omp parallel for schedule(static) num_threads(team(e))
    for (uint32_t i = 0; i < n3; i++) y[i] = x[i] + b * y[i];
}

/* The block preconditioners in one pass with the update: p += alpha d,
 * r -= alpha q, z = M^-1 r; returns r . r and sets *rz = r . z, *rmax2 the
 * largest |r_i|^2 of a particle. */
static double update_precond(const spn__precond *pc, const spn__eq *e, double alpha, const double *d,
                             const double *q, double *p, double *r, double *z, double *rz, double *rmax2)
{
    const uint32_t n = e->n, nchunks = e->nchunks;
    double *part = e->partial;
#pragma omp parallel for schedule(static) num_threads(team(e))
    for (uint32_t c = 0; c < nchunks; c++) {
        uint32_t end = (c + 1) * SPN__EQ_CHUNK < n ? (c + 1) * SPN__EQ_CHUNK : n;
        double rr = 0, rzs = 0, big = 0;
        for (uint32_t i = c * SPN__EQ_CHUNK; i < end; i++) {
            size_t k = 3 * (size_t)i;
            const double *h = pc->inv + 6 * (size_t)i;
            p[k] += alpha * d[k], p[k + 1] += alpha * d[k + 1], p[k + 2] += alpha * d[k + 2];
            double r0 = r[k] - alpha * q[k], r1 = r[k + 1] - alpha * q[k + 1], r2 = r[k + 2] - alpha * q[k + 2];
            double z0 = h[0] * r0 + h[3] * r1 + h[4] * r2;
            double z1 = h[3] * r0 + h[1] * r1 + h[5] * r2;
            double z2 = h[4] * r0 + h[5] * r1 + h[2] * r2;
            r[k] = r0, r[k + 1] = r1, r[k + 2] = r2;
            z[k] = z0, z[k + 1] = z1, z[k + 2] = z2;
            double ri = r0 * r0 + r1 * r1 + r2 * r2;
            rr += ri;
            big = ri > big ? ri : big;
            rzs += r0 * z0 + r1 * z1 + r2 * z2;
        }
        part[3 * c] = rr;
        part[3 * c + 1] = rzs;
        part[3 * c + 2] = big;
    }
    double rr = 0, rzs = 0, big = 0;
    for (uint32_t c = 0; c < nchunks; c++) {
        rr += part[3 * c];
        rzs += part[3 * c + 1];
        big = part[3 * c + 2] > big ? part[3 * c + 2] : big;
    }
    *rz = rzs;
    *rmax2 = big;
    return rr;
}

/* The largest |r_i|^2 of a particle. */
static double max_particle2(const spn__eq *e, const double *r)
{
    double big = 0;
    for (uint32_t i = 0; i < e->n; i++) {
        const double *ri = r + 3 * (size_t)i;
        double s = ri[0] * ri[0] + ri[1] * ri[1] + ri[2] * ri[2];
        big = s > big ? s : big;
    }
    return big;
}

/* Two stopping tests: the relative one (|r|_2 <= eta |f|_2, the Newton
 * forcing term) and the absolute one on the largest particle residual
 * (|r_i| <= floor for every i), the norm the caller's target is in. The
 * latter was |r|_2 <= floor before, up to sqrt(n) times stricter than the
 * target needs: on the 5k web at 1e-6 T0 the last Newton solve took 283
 * block-Jacobi iterations with it and 242 without (462 -> 421 in all;
 * multigrid 26 -> 25; at 1e-9 T0 716 -> 611 and 37 -> 35). */
int spn__eq_pcg(const spn__eq *e, const spn__precond *pc, double *p, double eta, double floor, int max_iter,
                double *work)
{
    const size_t n3 = 3 * (size_t)e->n;
    double *r = work, *z = work + n3, *d = work + 2 * n3, *q = work + 3 * n3;
    double bnorm = sqrt(spn__eq_dot(e, e->f, e->f));
    if (!(bnorm > 0)) {
        memset(p, 0, n3 * sizeof *p);
        return 0;
    }
    double stop = eta * bnorm, floor2 = floor * floor;
    /* warm start: r = f - A p */
    spn__eq_matvec(e, p, r);
    for (size_t i = 0; i < n3; i++) r[i] = e->f[i] - r[i];
    if (sqrt(spn__eq_dot(e, r, r)) <= stop || max_particle2(e, r) <= floor2) return 0;
    double rz = precond_dot(pc, e, r, z);
    memcpy(d, z, n3 * sizeof *d);
    /* Jacobi and block Jacobi are applied in the same pass as the update */
    bool fused = pc->kind == SPN_PRECOND_JACOBI || pc->kind == SPN_PRECOND_BLOCK_JACOBI;
    for (int it = 0; it < max_iter; it++) {
        double dq = spn__eq_matvec_dot(e, d, q);
        if (!(dq > 0)) return -1;
        double alpha = rz / dq, rz_new = 0, rr, rmax2;
        if (fused) {
            rr = update_precond(pc, e, alpha, d, q, p, r, z, &rz_new, &rmax2);
            if (sqrt(rr) <= stop || rmax2 <= floor2) return it + 1;
        } else {
            rr = spn__eq_update(e, alpha, d, q, p, r, &rmax2);
            if (sqrt(rr) <= stop || rmax2 <= floor2) return it + 1;
            rz_new = precond_dot(pc, e, r, z);
        }
        if (!(rz_new > 0)) return it + 1;
        xpby(e, z, rz_new / rz, d);
        rz = rz_new;
    }
    return max_iter;
}
