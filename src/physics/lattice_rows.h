/* The row kernels of the lattice step (lattice.c): the spring stencil over
 * structure-of-arrays rows, the force assembly in the gather's order, and the
 * Euler / symplectic Euler / RK4 updates. Header-only so that each
 * target_clones version of the sweep inlines its own copy. Plain loops over
 * contiguous arrays, written for GCC 12 to vectorise; where it would not, the
 * comment says what was changed. Every per-element expression is the one the
 * general path uses, so the bits do not depend on the vector width. */
#ifndef SPN_PHYSICS_LATTICE_ROWS_H
#define SPN_PHYSICS_LATTICE_ROWS_H

#include "world_internal.h"

#include <math.h>
#include <string.h>

/* Per-band sums: elastic energy, spring damping power, sum m v^2 at the
 * evaluated state, energy gain of the update, sum m v^2 after it. */
enum { L_ELASTIC, L_DAMP, L_MV2, L_GAIN, L_MVN2, L_NSUMS };
#define LANES 8
#define LAT_INLINE static inline __attribute__((always_inline))

/* Arrays of one thread's workspace, each N doubles (see ws_array). */
enum {
    WS_X = 0,     /* 2 rows x 3: pre-step positions of the previous and current row */
    WS_V = 6,     /* 2 rows x 3: velocities */
    WS_RAD = 12,  /* 2 rows x 3: radial force on the inner end */
    WS_RING = 18, /* 2 rows x 3: ring force on the lower end */
    WS_F = 24,    /* 3: assembled force on the row being moved */
    WS_E = 27,    /* per-spring elastic energy (scratch) */
    WS_P = 28,    /* per-spring damping power (scratch) */
    WS_Q = 29,    /* a third per-particle sum term (scratch) */
    WS_B = 30,    /* 6: RK4's base state x, v of the row being moved, SoA */
    WS_COUNT = 36
};

/* The float32 step's state and arrays (lattice_f32.c). */
typedef struct spn__lat32 spn__lat32;
void spn__lat32_free(spn__lat32 *F);
/* A slot's k, kd or rest changed: convert them again before the next step. */
void spn__lat32_params_changed(spn__lat32 *F);
/* The float32 state is ahead of w->x, w->v (inside an spn_world_advance call). */
bool spn__lat32_live(const spn__lat32 *F);
/* One float32 Euler or symplectic step over the lattice on `threads`
 * threads; false (nothing done, w->x and w->v up to date) when out of memory. */
bool spn__lat32_explicit(spn_world *w, int threads, double dt, bool symplectic, spn__step_result *r);
/* One float32 RK4 step over the lattice, likewise. */
bool spn__lat32_rk4(spn_world *w, int threads, double dt, spn__step_result *r);

struct spn__lattice {
    uint32_t rings, radials;
    double *rk, *rkd, *rrest; /* radial slots: ring * N + i, (ring - 1, i) -> (ring, i) */
    double *gk, *gkd, *grest; /* ring slots: ring * N + i, (i, i + 1); i = N - 1: (0, N - 1) */
    uint32_t band_rows, nbands;
    double *cut;     /* per band: 3 x N radial forces into its first row (band 0 unused) */
    double *partial; /* per band: L_NSUMS */
    int nws;         /* workspaces allocated (one per thread) */
    double **ws;
    size_t stride;   /* doubles per workspace array (N rounded up) */
    double *rk4;     /* RK4: 12 arrays of np (xt, vt, ax, av by component), on first use */
    spn__lat32 *f32; /* the float32 step (on first use) */
};

/* What an update does with a row once its forces are complete. */
enum { MODE_EULER, MODE_SYMPLECTIC, MODE_RK4_STAGE, MODE_RK4_LAST };

typedef struct lat_args {
    const spn__lattice *L;
    const spn_vec3 *xs, *vs;          /* the state the forces are evaluated at */
    spn_vec3 *x, *v, *x0, *v0;        /* the world's state (and its backup) */
    const double *sx[3], *sv[3];      /* RK4: the state as SoA arrays (sx[0] NULL: xs, vs) */
    double *xt[3], *vt[3], *ax[3], *av[3]; /* RK4: trial state and weighted sums, SoA */
    const double *mass, *inv_mass;
    spn_vec3 g;
    double drag, dt, h_next, weight;
    int mode, stage;
    bool backup;
} lat_args;

LAT_INLINE void lane_add(double *restrict acc, const double *restrict e, uint32_t n)
{
    uint32_t i = 0;
    for (; i + LANES <= n; i += LANES)
        for (int l = 0; l < LANES; l++) acc[l] += e[i + l];
    for (; i < n; i++) acc[i % LANES] += e[i];
}

LAT_INLINE double lane_total(const double *acc)
{
    return ((acc[0] + acc[1]) + (acc[2] + acc[3])) + ((acc[4] + acc[5]) + (acc[6] + acc[7]));
}

/* A band's sums into out (its L_NSUMS partials): the spring energy terms
 * add up over the band's sweeps from the first band's reset, the particle
 * terms are the last sweep's. */
LAT_INLINE void store_band_sums(double *out, bool first, const double *acc_e, const double *acc_p,
                                double acc[L_NSUMS][LANES])
{
    if (first) out[L_ELASTIC] = out[L_DAMP] = 0;
    out[L_ELASTIC] += lane_total(acc_e), out[L_DAMP] += lane_total(acc_p);
    out[L_MV2] = lane_total(acc[L_MV2]), out[L_GAIN] = lane_total(acc[L_GAIN]), out[L_MVN2] = lane_total(acc[L_MVN2]);
}

/* Springs j = 0..n-1 from (a[j]) to (b[j]), SoA: force on end a into f, the
 * elastic energy and damping power into e, p. The arithmetic of chunk_forces
 * (same bits): a spring is off (no force) at zero length or when slack and
 * tension-only, and then 1/len is replaced by 0 and k by 0, which is what
 * chunk_forces' 0/1 factors give, with selects instead of products. */
LAT_INLINE void springs(uint32_t n, const double *restrict axp, const double *restrict ayp,
                        const double *restrict azp, const double *restrict bxp, const double *restrict byp,
                        const double *restrict bzp, const double *restrict avx, const double *restrict avy,
                        const double *restrict avz, const double *restrict bvx, const double *restrict bvy,
                        const double *restrict bvz, const double *restrict kk, const double *restrict kkd,
                        const double *restrict rr, double *restrict fx, double *restrict fy, double *restrict fz,
                        double *restrict e, double *restrict p)
{
    for (uint32_t j = 0; j < n; j++) {
        const double lx = axp[j] - bxp[j], ly = ayp[j] - byp[j], lz = azp[j] - bzp[j];
        const double ux = avx[j] - bvx[j], uy = avy[j] - bvy[j], uz = avz[j] - bvz[j];
        const double d2 = lx * lx + ly * ly + lz * lz;
        const double len = sqrt(d2);
        const double rs = rr[j];
        const double stretch = len - fabs(rs);
        const bool on = len > 0 && !(stretch < 0 && rs < 0);
        const double inv = on ? 1 / len : 0;
        const double rate = (ux * lx + uy * ly + uz * lz) * inv;
        const double k = on ? kk[j] : 0, kd = kkd[j];
        const double mag = k * stretch + kd * rate;
        const double s = -mag * inv;
        e[j] = 0.5 * k * stretch * stretch;
        p[j] = kd * rate * rate;
        fx[j] = s * lx, fy[j] = s * ly, fz[j] = s * lz;
    }
}

/* Springs from row buffers a to b (each 3 arrays of stride st) with
 * parameters k, kd, rest, forces into f; sums into acc. */
LAT_INLINE void springs_rows(uint32_t n, double *const *ax, double *const *av, double *const *bx,
                             double *const *bv, size_t off_a, size_t off_b, const double *k, const double *kd,
                             const double *rest, double *const *f, size_t off_f, double *e, double *p,
                             double *acc_e, double *acc_p)
{
    springs(n, ax[0] + off_a, ax[1] + off_a, ax[2] + off_a, bx[0] + off_b, bx[1] + off_b, bx[2] + off_b,
            av[0] + off_a, av[1] + off_a, av[2] + off_a, bv[0] + off_b, bv[1] + off_b, bv[2] + off_b, k, kd, rest,
            f[0] + off_f, f[1] + off_f, f[2] + off_f, e, p);
    lane_add(acc_e, e, n);
    lane_add(acc_p, p, n);
}

/* n particles' state (AoS) into SoA buffers. Restrict parameters, not
 * restrict locals: GCC 12 vectorises the strided accesses only then. */
LAT_INLINE void deinterleave(uint32_t n, const spn_vec3 *restrict xs, const spn_vec3 *restrict vs,
                             double *restrict x0, double *restrict x1, double *restrict x2, double *restrict v0,
                             double *restrict v1, double *restrict v2)
{
    for (uint32_t i = 0; i < n; i++) {
        x0[i] = xs[i].x, x1[i] = xs[i].y, x2[i] = xs[i].z;
        v0[i] = vs[i].x, v1[i] = vs[i].y, v2[i] = vs[i].z;
    }
}

/* Row j of the evaluated state into SoA buffers. */
LAT_INLINE void load_row(const lat_args *a, uint32_t j, double *const *X, double *const *V)
{
    const uint32_t n = a->L->radials;
    const size_t p0 = 1 + (size_t)j * n;
    if (!a->sx[0]) {
        deinterleave(n, a->xs + p0, a->vs + p0, X[0], X[1], X[2], V[0], V[1], V[2]);
        return;
    }
    for (int c = 0; c < 3; c++) {
        memcpy(X[c], a->sx[c] + p0, n * sizeof *X[c]);
        memcpy(V[c], a->sv[c] + p0, n * sizeof *V[c]);
    }
}

/* Particle p of the evaluated state. */
static inline void state_of(const lat_args *a, size_t p, spn_vec3 *x, spn_vec3 *v)
{
    if (!a->sx[0]) {
        *x = a->xs[p], *v = a->vs[p];
        return;
    }
    *x = spn_v3(a->sx[0][p], a->sx[1][p], a->sx[2][p]);
    *v = spn_v3(a->sv[0][p], a->sv[1][p], a->sv[2][p]);
}

/* The updates below move particles whose state at the evaluation is (X, V)
 * (SoA) and whose complete force is known. Fixed particles are selected out,
 * not skipped, so the loops vectorise; the per-particle terms of the sums go
 * to t_mv2, t_gain, t_mvn2 and from there, in a fixed order, to the band's
 * lane accumulators. */

/* One particle of an Euler or symplectic Euler step, on values (the loops
 * do the loads and stores, so they vectorise). A fixed particle is selected
 * out, not skipped. */
typedef struct moved {
    double x[3], v[3], mv2, gain, mvn2;
} moved;

LAT_INLINE moved explicit_one(double fx, double fy, double fz, double im, double m, double xx, double xy, double xz,
                              double vx, double vy, double vz, bool sym, double dt, spn_vec3 g)
{
    moved o;
    const double s = dt * im;
    const bool fr = im != 0;
    const double mf = fr ? m : 0;
    const double nx = vx + fx * s, ny = vy + fy * s, nz = vz + fz * s;
    const double dx = (sym ? nx : vx) * dt, dy = (sym ? ny : vy) * dt, dz = (sym ? nz : vz) * dt;
    o.x[0] = fr ? xx + dx : xx, o.x[1] = fr ? xy + dy : xy, o.x[2] = fr ? xz + dz : xz;
    o.v[0] = fr ? nx : vx, o.v[1] = fr ? ny : vy, o.v[2] = fr ? nz : vz;
    o.mv2 = mf * (vx * vx + vy * vy + vz * vz);
    o.mvn2 = mf * (nx * nx + ny * ny + nz * nz);
    o.gain = mf * (0.5 * ((nx - vx) * (nx + vx) + (ny - vy) * (ny + vy) + (nz - vz) * (nz + vz)) -
                   (g.x * dx + g.y * dy + g.z * dz));
    return o;
}

#define STORE_MOVED(i, o)                                                                                       \
    do {                                                                                                        \
        x[i].x = (o).x[0], x[i].y = (o).x[1], x[i].z = (o).x[2];                                                \
        v[i].x = (o).v[0], v[i].y = (o).v[1], v[i].z = (o).v[2];                                                \
        t_mv2[i] = (o).mv2, t_gain[i] = (o).gain, t_mvn2[i] = (o).mvn2;                                         \
    } while (0)

/* An Euler or symplectic Euler row with the force assembled on the fly (as
 * assemble_c, same order) instead of through F: one pass, not four. */
LAT_INLINE void explicit_row(uint32_t n, bool sym, bool backup, double dt, spn_vec3 g, double drag,
                             const double *restrict mass, const double *restrict inv_mass,
                             const double *restrict Xx, const double *restrict Xy, const double *restrict Xz,
                             const double *restrict Vx, const double *restrict Vy, const double *restrict Vz,
                             const double *restrict ix, const double *restrict iy, const double *restrict iz,
                             const double *restrict rx, const double *restrict ry, const double *restrict rz,
                             const double *restrict ox, const double *restrict oy, const double *restrict oz,
                             spn_vec3 *restrict x, spn_vec3 *restrict v, spn_vec3 *restrict x0,
                             spn_vec3 *restrict v0, double *restrict t_mv2, double *restrict t_gain,
                             double *restrict t_mvn2)
{
    if (backup)
        for (uint32_t i = 0; i < n; i++) {
            x0[i].x = Xx[i], x0[i].y = Xy[i], x0[i].z = Xz[i];
            v0[i].x = Vx[i], v0[i].y = Vy[i], v0[i].z = Vz[i];
        }
    const uint32_t l = n - 1;
    double e0[3], el[3];
    const double gc[3] = {g.x, g.y, g.z};
    const double *V[3] = {Vx, Vy, Vz}, *I[3] = {ix, iy, iz}, *R[3] = {rx, ry, rz}, *O[3] = {ox, oy, oz};
    for (int c = 0; c < 3; c++) {
        double f0 = mass[0] * gc[c] - (drag * mass[0]) * V[c][0], fl = mass[l] * gc[c] - (drag * mass[l]) * V[c][l];
        if (ox) f0 += O[c][0], fl += O[c][l];
        e0[c] = ((f0 + R[c][0]) + R[c][l]) - I[c][0];
        el[c] = ((fl - I[c][l]) - R[c][l]) - R[c][l - 1];
    }
    if (ox)
        for (uint32_t i = 1; i < l; i++) {
            const double m = mass[i], dm = drag * m;
            const double fx = ((((m * g.x - dm * Vx[i]) + ox[i]) + rx[i]) - ix[i]) - rx[i - 1];
            const double fy = ((((m * g.y - dm * Vy[i]) + oy[i]) + ry[i]) - iy[i]) - ry[i - 1];
            const double fz = ((((m * g.z - dm * Vz[i]) + oz[i]) + rz[i]) - iz[i]) - rz[i - 1];
            const moved o =
                explicit_one(fx, fy, fz, inv_mass[i], m, Xx[i], Xy[i], Xz[i], Vx[i], Vy[i], Vz[i], sym, dt, g);
            STORE_MOVED(i, o);
        }
    else
        for (uint32_t i = 1; i < l; i++) {
            const double m = mass[i], dm = drag * m;
            const double fx = (((m * g.x - dm * Vx[i]) + rx[i]) - ix[i]) - rx[i - 1];
            const double fy = (((m * g.y - dm * Vy[i]) + ry[i]) - iy[i]) - ry[i - 1];
            const double fz = (((m * g.z - dm * Vz[i]) + rz[i]) - iz[i]) - rz[i - 1];
            const moved o =
                explicit_one(fx, fy, fz, inv_mass[i], m, Xx[i], Xy[i], Xz[i], Vx[i], Vy[i], Vz[i], sym, dt, g);
            STORE_MOVED(i, o);
        }
    const uint32_t ends[2] = {0, l};
    for (int k = 0; k < 2; k++) {
        const uint32_t i = ends[k];
        const double *f = k ? el : e0;
        const moved o = explicit_one(f[0], f[1], f[2], inv_mass[i], mass[i], Xx[i], Xy[i], Xz[i], Vx[i], Vy[i], Vz[i],
                                     sym, dt, g);
        STORE_MOVED(i, o);
    }
}

/* RK4 stage sums: m v^2 of the free particles (no gain or new energy yet). */
LAT_INLINE void rk4_mv2(uint32_t n, const double *restrict mass, const double *restrict inv_mass,
                        const double *restrict Vx, const double *restrict Vy, const double *restrict Vz,
                        double *restrict t_mv2, double *restrict t_gain, double *restrict t_mvn2)
{
    for (uint32_t i = 0; i < n; i++) {
        t_mv2[i] = (inv_mass[i] != 0 ? mass[i] : 0) * (Vx[i] * Vx[i] + Vy[i] * Vy[i] + Vz[i] * Vz[i]);
        t_gain[i] = t_mvn2[i] = 0;
    }
}

/* An RK4 stage but the last: the weighted sums ax, av and the next trial
 * state xt = x + h V, vt = v + h F / m (a fixed particle stays at x, v). */
LAT_INLINE void update_rk4_stage(uint32_t n, bool first, double h, double wgt, const double *restrict mass,
                                 const double *restrict inv_mass, const double *restrict Vc,
                                 const double *restrict Fc, const double *restrict xb, const double *restrict vb,
                                 double *restrict xt, double *restrict vt, double *restrict ax,
                                 double *restrict av)
{
    (void)mass;
    for (uint32_t i = 0; i < n; i++) {
        const double im = inv_mass[i], s = h * im;
        const bool fr = im != 0;
        const double vc = Vc[i], fc = Fc[i], xc = xb[i], wc = vb[i];
        ax[i] = fr ? (first ? vc : ax[i] + vc * wgt) : ax[i];
        av[i] = fr ? (first ? fc : av[i] + fc * wgt) : av[i];
        xt[i] = fr ? xc + vc * h : xc;
        vt[i] = fr ? wc + fc * s : wc;
    }
}

/* The last RK4 stage: x += h/6 (ax + V), v += h/6 (av + F) / m. */
LAT_INLINE void update_rk4_last(uint32_t n, bool backup, double h6, spn_vec3 g, const double *restrict mass,
                                const double *restrict inv_mass, const double *restrict Vx,
                                const double *restrict Vy, const double *restrict Vz, const double *restrict Fx,
                                const double *restrict Fy, const double *restrict Fz, const double *restrict axx,
                                const double *restrict axy, const double *restrict axz, const double *restrict avx,
                                const double *restrict avy, const double *restrict avz, const double *restrict bxx,
                                const double *restrict bxy, const double *restrict bxz, const double *restrict bvx,
                                const double *restrict bvy, const double *restrict bvz, spn_vec3 *restrict x,
                                spn_vec3 *restrict v,
                                spn_vec3 *restrict x0, spn_vec3 *restrict v0, double *restrict t_mv2,
                                double *restrict t_gain, double *restrict t_mvn2)
{
    if (backup) {
        memcpy(x0, x, n * sizeof *x);
        memcpy(v0, v, n * sizeof *v);
    }
    for (uint32_t i = 0; i < n; i++) {
        const double im = inv_mass[i], s = h6 * im;
        const bool fr = im != 0;
        const double mf = fr ? mass[i] : 0;
        const double vx = Vx[i], vy = Vy[i], vz = Vz[i];
        const double xx = bxx[i], xy = bxy[i], xz = bxz[i], wx = bvx[i], wy = bvy[i], wz = bvz[i];
        const double dx = (axx[i] + vx) * h6, dy = (axy[i] + vy) * h6, dz = (axz[i] + vz) * h6;
        const double nx = wx + (avx[i] + Fx[i]) * s, ny = wy + (avy[i] + Fy[i]) * s, nz = wz + (avz[i] + Fz[i]) * s;
        x[i].x = fr ? xx + dx : xx, x[i].y = fr ? xy + dy : xy, x[i].z = fr ? xz + dz : xz;
        v[i].x = fr ? nx : wx, v[i].y = fr ? ny : wy, v[i].z = fr ? nz : wz;
        t_mv2[i] = mf * (vx * vx + vy * vy + vz * vz);
        t_mvn2[i] = mf * (nx * nx + ny * ny + nz * nz);
        t_gain[i] = mf * (0.5 * ((nx - wx) * (nx + wx) + (ny - wy) * (ny + wy) + (nz - wz) * (nz + wz)) -
                          (g.x * dx + g.y * dy + g.z * dz));
    }
}

/* Update particles p0 .. p0+n-1 as the mode says; sums into acc. */
LAT_INLINE void update(const lat_args *a, size_t p0, uint32_t n, double *const *X, double *const *V,
                       double *const *F, double *const *t, double *const *B, double (*acc)[LANES])
{
    const double *mass = a->mass + p0, *inv_mass = a->inv_mass + p0;
    /* RK4 reads the base state x, v: as SoA first (GCC 12 does not vectorise
     * a loop that both reads and writes the interleaved arrays). */
    if (a->mode == MODE_RK4_STAGE || a->mode == MODE_RK4_LAST)
        deinterleave(n, a->x + p0, a->v + p0, B[0], B[1], B[2], B[3], B[4], B[5]);
    switch (a->mode) {
    case MODE_EULER:
    case MODE_SYMPLECTIC: { /* the hub; rows go through explicit_row */
        spn_vec3 *x = a->x + p0, *v = a->v + p0;
        double *t_mv2 = t[0], *t_gain = t[1], *t_mvn2 = t[2];
        for (uint32_t i = 0; i < n; i++) {
            if (a->backup) {
                a->x0[p0 + i] = spn_v3(X[0][i], X[1][i], X[2][i]);
                a->v0[p0 + i] = spn_v3(V[0][i], V[1][i], V[2][i]);
            }
            const moved o = explicit_one(F[0][i], F[1][i], F[2][i], inv_mass[i], mass[i], X[0][i], X[1][i], X[2][i],
                                         V[0][i], V[1][i], V[2][i], a->mode == MODE_SYMPLECTIC, a->dt, a->g);
            STORE_MOVED(i, o);
        }
        break;
    }
    case MODE_RK4_STAGE:
        /* One component at a time, and the sum term apart: GCC 12 does not
         * vectorise one loop over all those arrays. */
        rk4_mv2(n, mass, inv_mass, V[0], V[1], V[2], t[0], t[1], t[2]);
        /* (three calls, not a loop: GCC 12 does not vectorise an inlined
         * function with restrict parameters inside a loop) */
        update_rk4_stage(n, a->stage == 0, a->h_next, a->weight, mass, inv_mass, V[0], F[0], B[0], B[3],
                         a->xt[0] + p0, a->vt[0] + p0, a->ax[0] + p0, a->av[0] + p0);
        update_rk4_stage(n, a->stage == 0, a->h_next, a->weight, mass, inv_mass, V[1], F[1], B[1], B[4],
                         a->xt[1] + p0, a->vt[1] + p0, a->ax[1] + p0, a->av[1] + p0);
        update_rk4_stage(n, a->stage == 0, a->h_next, a->weight, mass, inv_mass, V[2], F[2], B[2], B[5],
                         a->xt[2] + p0, a->vt[2] + p0, a->ax[2] + p0, a->av[2] + p0);
        break;
    default:
        update_rk4_last(n, a->backup, a->dt / 6, a->g, mass, inv_mass, V[0], V[1], V[2], F[0], F[1], F[2],
                        a->ax[0] + p0, a->ax[1] + p0, a->ax[2] + p0, a->av[0] + p0, a->av[1] + p0, a->av[2] + p0,
                        B[0], B[1], B[2], B[3], B[4], B[5], a->x + p0, a->v + p0, a->x0 + p0, a->v0 + p0, t[0], t[1],
                        t[2]);
    }
    lane_add(acc[L_MV2], t[0], n);
    lane_add(acc[L_GAIN], t[1], n);
    lane_add(acc[L_MVN2], t[2], n);
}

/* The complete force on row q: gravity and drag, then (see the file comment)
 * radial out (ro, NULL on the outermost ring), ring to i + 1 and wrap as the
 * lower end, radial in (ri), wrap and ring from i - 1 as the upper end. */
LAT_INLINE void assemble_c(uint32_t n, double gc, double drag, const double *restrict mass,
                           const double *restrict vc, const double *restrict in, const double *restrict ring,
                           const double *restrict out, double *restrict f)
{
    const double wrap = ring[n - 1];
    if (out)
        for (uint32_t i = 1; i + 1 < n; i++)
            f[i] = ((((mass[i] * gc - (drag * mass[i]) * vc[i]) + out[i]) + ring[i]) - in[i]) - ring[i - 1];
    else
        for (uint32_t i = 1; i + 1 < n; i++)
            f[i] = (((mass[i] * gc - (drag * mass[i]) * vc[i]) + ring[i]) - in[i]) - ring[i - 1];
    const uint32_t l = n - 1;
    double f0 = mass[0] * gc - (drag * mass[0]) * vc[0], fl = mass[l] * gc - (drag * mass[l]) * vc[l];
    if (out) f0 += out[0], fl += out[l];
    f[0] = ((f0 + ring[0]) + wrap) - in[0];
    f[l] = ((fl - in[l]) - wrap) - ring[l - 1];
}

LAT_INLINE void assemble(const lat_args *a, size_t p0, uint32_t n, double *const *V, double *const *ri,
                         double *const *rg, const double *const *ro, double *const *F)
{
    const double g[3] = {a->g.x, a->g.y, a->g.z};
    for (int c = 0; c < 3; c++)
        assemble_c(n, g[c], a->drag, a->mass + p0, V[c], ri[c], rg[c], ro ? ro[c] : NULL, F[c]);
}

/* Row q (particles p0 ..) complete: its force, then its update. */
LAT_INLINE void finish_row(const lat_args *a, size_t p0, uint32_t n, double *const *X, double *const *V,
                           double *const *ri, double *const *rg, const double *const *ro, double *const *F,
                           double *const *t, double *const *B, double (*acc)[LANES])
{
    if (a->mode == MODE_EULER || a->mode == MODE_SYMPLECTIC) {
        explicit_row(n, a->mode == MODE_SYMPLECTIC, a->backup, a->dt, a->g, a->drag, a->mass + p0,
                     a->inv_mass + p0, X[0], X[1], X[2], V[0], V[1], V[2], ri[0], ri[1], ri[2], rg[0], rg[1], rg[2],
                     ro ? ro[0] : NULL, ro ? ro[1] : NULL, ro ? ro[2] : NULL, a->x + p0, a->v + p0, a->x0 + p0,
                     a->v0 + p0, t[0], t[1], t[2]);
        lane_add(acc[L_MV2], t[0], n);
        lane_add(acc[L_GAIN], t[1], n);
        lane_add(acc[L_MVN2], t[2], n);
        return;
    }
    assemble(a, p0, n, V, ri, rg, ro, F);
    update(a, p0, n, X, V, F, t, B, acc);
}

LAT_INLINE void rows_of(double *ws, size_t st, int base, int row, double **out)
{
    for (int c = 0; c < 3; c++) out[c] = ws + (size_t)(base + 3 * row + c) * st;
}

#endif
