/* The row kernels of the float32 lattice step (lattice_f32.c): the spring
 * stencil, the force assembly and the Euler / symplectic Euler / RK4 updates
 * of lattice_rows.h in float32, over rows of the float32 state (displacements
 * d from the float64 positions, velocities u). Header-only so that each
 * target_clones version of the sweep inlines its own copy. Plain loops over
 * contiguous float arrays for GCC 12 to vectorise at full width (16 lanes
 * with AVX-512); where it would not, the comment says what was changed. */
#ifndef SPN_PHYSICS_LATTICE_ROWS32_H
#define SPN_PHYSICS_LATTICE_ROWS32_H

#include "lattice_rows.h"

#include <math.h>


/* Springs j = 0..n-1 from a to b: chunk.h's expression in float32, the
 * difference as L + (d_a - d_b); force on end a into f, energy and damping
 * power into e, p. */
LAT_INLINE void springs32(uint32_t n, const float *restrict dax, const float *restrict day,
                          const float *restrict daz, const float *restrict dbx, const float *restrict dby,
                          const float *restrict dbz, const float *restrict uax, const float *restrict uay,
                          const float *restrict uaz, const float *restrict ubx, const float *restrict uby,
                          const float *restrict ubz, const float *restrict Lx, const float *restrict Ly,
                          const float *restrict Lz, const float *restrict kk, const float *restrict kkd,
                          const float *restrict rr, float *restrict fx, float *restrict fy, float *restrict fz,
                          float *restrict e, float *restrict p)
{
    for (uint32_t j = 0; j < n; j++) {
        const float lx = Lx[j] + (dax[j] - dbx[j]), ly = Ly[j] + (day[j] - dby[j]), lz = Lz[j] + (daz[j] - dbz[j]);
        const float ux = uax[j] - ubx[j], uy = uay[j] - uby[j], uz = uaz[j] - ubz[j];
        const float len = sqrtf(lx * lx + ly * ly + lz * lz);
        const float rs = rr[j];
        const float stretch = len - fabsf(rs);
        const bool on = len > 0 && !(stretch < 0 && rs < 0);
        const float inv = on ? 1.0f / len : 0.0f;
        const float rate = (ux * lx + uy * ly + uz * lz) * inv;
        const float k = on ? kk[j] : 0.0f, kd = kkd[j];
        const float s = -(k * stretch + kd * rate) * inv;
        e[j] = 0.5f * k * stretch * stretch;
        p[j] = kd * rate * rate;
        fx[j] = s * lx, fy[j] = s * ly, fz[j] = s * lz;
    }
}

LAT_INLINE void lane_add32(double *restrict acc, const float *restrict e, uint32_t n)
{
    uint32_t i = 0;
    for (; i + LANES <= n; i += LANES)
        for (int l = 0; l < LANES; l++) acc[l] += (double)e[i + l];
    for (; i < n; i++) acc[i % LANES] += (double)e[i];
}

/* Springs between rows (3 arrays each, already offset) a and b. */
LAT_INLINE void spring_rows(uint32_t n, float *const *da, float *const *ua, float *const *db, float *const *ub,
                            float *const *L, size_t s0, const float *k, const float *kd, const float *rest,
                            float *const *f, size_t off_f, float *e, float *p, double *acc_e, double *acc_p)
{
    springs32(n, da[0], da[1], da[2], db[0], db[1], db[2], ua[0], ua[1], ua[2], ub[0], ub[1], ub[2], L[0] + s0,
              L[1] + s0, L[2] + s0, k + s0, kd + s0, rest + s0, f[0] + off_f, f[1] + off_f, f[2] + off_f, e, p);
    lane_add32(acc_e, e, n);
    lane_add32(acc_p, p, n);
}

typedef struct moved32 {
    float d[3], u[3], mv2, gain, mvn2;
} moved32;

/* explicit_one (lattice_rows.h) in float32. */
LAT_INLINE moved32 one32(float fx, float fy, float fz, float im, float m, float dx, float dy, float dz, float vx,
                         float vy, float vz, bool sym, float dt, const float *g)
{
    moved32 o;
    const float s = dt * im;
    const bool fr = im != 0;
    const float mf = fr ? m : 0.0f;
    const float nx = vx + fx * s, ny = vy + fy * s, nz = vz + fz * s;
    const float ex = (sym ? nx : vx) * dt, ey = (sym ? ny : vy) * dt, ez = (sym ? nz : vz) * dt;
    o.d[0] = fr ? dx + ex : dx, o.d[1] = fr ? dy + ey : dy, o.d[2] = fr ? dz + ez : dz;
    o.u[0] = fr ? nx : vx, o.u[1] = fr ? ny : vy, o.u[2] = fr ? nz : vz;
    o.mv2 = mf * (vx * vx + vy * vy + vz * vz);
    o.mvn2 = mf * (nx * nx + ny * ny + nz * nz);
    o.gain = mf * (0.5f * ((nx - vx) * (nx + vx) + (ny - vy) * (ny + vy) + (nz - vz) * (nz + vz)) -
                   (g[0] * ex + g[1] * ey + g[2] * ez));
    return o;
}

#define STORE32(i, o)                                                                                           \
    do {                                                                                                        \
        dx[i] = (o).d[0], dy[i] = (o).d[1], dz[i] = (o).d[2];                                                   \
        ux[i] = (o).u[0], uy[i] = (o).u[1], uz[i] = (o).u[2];                                                   \
        t_mv2[i] = (o).mv2, t_gain[i] = (o).gain, t_mvn2[i] = (o).mvn2;                                         \
    } while (0)

/* A row with its forces complete (radial in, ring, radial out or NULL),
 * assembled in explicit_row's order, moved in place. The two ends (the wrap
 * spring) go after the loop, from forces formed before it. */
LAT_INLINE void row32(uint32_t n, bool sym, float dt, const float *g, float drag, const float *restrict mass,
                      const float *restrict inv_mass, float *restrict dx, float *restrict dy, float *restrict dz,
                      float *restrict ux, float *restrict uy, float *restrict uz, const float *restrict ix,
                      const float *restrict iy, const float *restrict iz, const float *restrict rx,
                      const float *restrict ry, const float *restrict rz, const float *restrict ox,
                      const float *restrict oy, const float *restrict oz, float *restrict t_mv2,
                      float *restrict t_gain, float *restrict t_mvn2)
{
    const uint32_t l = n - 1;
    float e0[3], el[3];
    const float *V[3] = {ux, uy, uz}, *I[3] = {ix, iy, iz}, *R[3] = {rx, ry, rz}, *O[3] = {ox, oy, oz};
    for (int c = 0; c < 3; c++) {
        float f0 = mass[0] * g[c] - (drag * mass[0]) * V[c][0], fl = mass[l] * g[c] - (drag * mass[l]) * V[c][l];
        if (ox) f0 += O[c][0], fl += O[c][l];
        e0[c] = ((f0 + R[c][0]) + R[c][l]) - I[c][0];
        el[c] = ((fl - I[c][l]) - R[c][l]) - R[c][l - 1];
    }
    if (ox)
        for (uint32_t i = 1; i < l; i++) {
            const float m = mass[i], dm = drag * m;
            const float fx = ((((m * g[0] - dm * ux[i]) + ox[i]) + rx[i]) - ix[i]) - rx[i - 1];
            const float fy = ((((m * g[1] - dm * uy[i]) + oy[i]) + ry[i]) - iy[i]) - ry[i - 1];
            const float fz = ((((m * g[2] - dm * uz[i]) + oz[i]) + rz[i]) - iz[i]) - rz[i - 1];
            const moved32 o = one32(fx, fy, fz, inv_mass[i], m, dx[i], dy[i], dz[i], ux[i], uy[i], uz[i], sym, dt, g);
            STORE32(i, o);
        }
    else
        for (uint32_t i = 1; i < l; i++) {
            const float m = mass[i], dm = drag * m;
            const float fx = (((m * g[0] - dm * ux[i]) + rx[i]) - ix[i]) - rx[i - 1];
            const float fy = (((m * g[1] - dm * uy[i]) + ry[i]) - iy[i]) - ry[i - 1];
            const float fz = (((m * g[2] - dm * uz[i]) + rz[i]) - iz[i]) - rz[i - 1];
            const moved32 o = one32(fx, fy, fz, inv_mass[i], m, dx[i], dy[i], dz[i], ux[i], uy[i], uz[i], sym, dt, g);
            STORE32(i, o);
        }
    const uint32_t ends[2] = {0, l};
    for (int k = 0; k < 2; k++) {
        const uint32_t i = ends[k];
        const float *f = k ? el : e0;
        const moved32 o =
            one32(f[0], f[1], f[2], inv_mass[i], mass[i], dx[i], dy[i], dz[i], ux[i], uy[i], uz[i], sym, dt, g);
        STORE32(i, o);
    }
}


/* RK4 (lattice_rows.h's update_rk4_stage, rk4_mv2, update_rk4_last and
 * assemble_c in float32). The state a stage is evaluated at and the trial
 * state it writes are different arrays (lattice_f32.c alternates two), so
 * no restrict pointer below aliases another. */

/* The complete force on a row, component c, in assemble_c's order. */
LAT_INLINE void assemble32(uint32_t n, float gc, float drag, const float *restrict mass, const float *restrict vc,
                           const float *restrict in, const float *restrict ring, const float *restrict out,
                           float *restrict f)
{
    const float wrap = ring[n - 1];
    if (out)
        for (uint32_t i = 1; i + 1 < n; i++)
            f[i] = ((((mass[i] * gc - (drag * mass[i]) * vc[i]) + out[i]) + ring[i]) - in[i]) - ring[i - 1];
    else
        for (uint32_t i = 1; i + 1 < n; i++)
            f[i] = (((mass[i] * gc - (drag * mass[i]) * vc[i]) + ring[i]) - in[i]) - ring[i - 1];
    const uint32_t l = n - 1;
    float f0 = mass[0] * gc - (drag * mass[0]) * vc[0], fl = mass[l] * gc - (drag * mass[l]) * vc[l];
    if (out) f0 += out[0], fl += out[l];
    f[0] = ((f0 + ring[0]) + wrap) - in[0];
    f[l] = ((fl - in[l]) - wrap) - ring[l - 1];
}

/* Sum terms of a stage but the last: m v^2 of the free particles. */
LAT_INLINE void rk4_mv2_32(uint32_t n, const float *restrict mass, const float *restrict inv_mass,
                           const float *restrict Vx, const float *restrict Vy, const float *restrict Vz,
                           float *restrict t_mv2, float *restrict t_gain, float *restrict t_mvn2)
{
    for (uint32_t i = 0; i < n; i++) {
        t_mv2[i] = (inv_mass[i] != 0 ? mass[i] : 0.0f) * (Vx[i] * Vx[i] + Vy[i] * Vy[i] + Vz[i] * Vz[i]);
        t_gain[i] = t_mvn2[i] = 0;
    }
}

/* One component of a stage but the last: the weighted sums ax, av and the
 * next trial state td = d + h V, tu = u + h F / m (d, u: the step's base). */
LAT_INLINE void rk4_stage32(uint32_t n, bool first, float h, float wgt, const float *restrict inv_mass,
                            const float *restrict Vc, const float *restrict Fc, const float *restrict db,
                            const float *restrict ub, float *restrict td, float *restrict tu, float *restrict ax,
                            float *restrict av)
{
    for (uint32_t i = 0; i < n; i++) {
        const float im = inv_mass[i], s = h * im;
        const bool fr = im != 0;
        const float vc = Vc[i], fc = Fc[i];
        ax[i] = fr ? (first ? vc : ax[i] + vc * wgt) : ax[i];
        av[i] = fr ? (first ? fc : av[i] + fc * wgt) : av[i];
        td[i] = fr ? db[i] + vc * h : db[i];
        tu[i] = fr ? ub[i] + fc * s : ub[i];
    }
}

/* The last stage's sums, from the state before its update (so before
 * rk4_last32 below): m V^2 at the evaluated state, m u'^2 after the step and
 * the gain of kinetic + gravitational energy. A loop of its own: GCC 12 does
 * not vectorise the inlined update and sums as one loop over two dozen arrays
 * (too many run-time alias checks). */
LAT_INLINE void rk4_sums32(uint32_t n, float h6, const float *g, const float *restrict mass,
                           const float *restrict inv_mass, const float *restrict Vx, const float *restrict Vy,
                           const float *restrict Vz, const float *restrict Fx, const float *restrict Fy,
                           const float *restrict Fz, const float *restrict axx, const float *restrict axy,
                           const float *restrict axz, const float *restrict avx, const float *restrict avy,
                           const float *restrict avz, const float *restrict ux, const float *restrict uy,
                           const float *restrict uz, float *restrict t_mv2, float *restrict t_gain,
                           float *restrict t_mvn2)
{
    for (uint32_t i = 0; i < n; i++) {
        const float im = inv_mass[i], s = h6 * im;
        const float mf = im != 0 ? mass[i] : 0.0f;
        const float vx = Vx[i], vy = Vy[i], vz = Vz[i], wx = ux[i], wy = uy[i], wz = uz[i];
        const float ex = (axx[i] + vx) * h6, ey = (axy[i] + vy) * h6, ez = (axz[i] + vz) * h6;
        const float nx = wx + (avx[i] + Fx[i]) * s, ny = wy + (avy[i] + Fy[i]) * s, nz = wz + (avz[i] + Fz[i]) * s;
        t_mv2[i] = mf * (vx * vx + vy * vy + vz * vz);
        t_mvn2[i] = mf * (nx * nx + ny * ny + nz * nz);
        t_gain[i] = mf * (0.5f * ((nx - wx) * (nx + wx) + (ny - wy) * (ny + wy) + (nz - wz) * (nz + wz)) -
                          (g[0] * ex + g[1] * ey + g[2] * ez));
    }
}

/* The last stage, one component: d += h/6 (ax + V), u += h/6 (av + F) / m
 * (the same expressions as rk4_sums32). */
LAT_INLINE void rk4_last32(uint32_t n, float h6, const float *restrict inv_mass, const float *restrict Vc,
                           const float *restrict Fc, const float *restrict axc, const float *restrict avc,
                           float *restrict dc, float *restrict uc)
{
    for (uint32_t i = 0; i < n; i++) {
        const float im = inv_mass[i], s = h6 * im;
        const bool fr = im != 0;
        const float e = (axc[i] + Vc[i]) * h6, nu = uc[i] + (avc[i] + Fc[i]) * s;
        dc[i] = fr ? dc[i] + e : dc[i];
        uc[i] = fr ? nu : uc[i];
    }
}

#endif
