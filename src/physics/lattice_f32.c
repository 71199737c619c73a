/* The float32 lattice step: Euler and symplectic Euler (Mehla 2005, eq. 4.5)
 * over a hub + rings x radials web, as lattice.c's sweep, with the springs
 * (eq. 4.14), the force assembly and the update in float32 from end to end.
 * Opt-in (spn_world_set_precision); docs/physics-lattice.md has the accuracy
 * and the measurements.
 *
 * State. For the length of an spn_world_advance call the step keeps its own
 * state, structure of arrays in float32: per particle the displacement d from
 * the float64 position w->x (which stays put as the reference) and the
 * velocity u. Float32 positions would not do: a step moves a particle by
 * v dt ~ 1e-10 m, below the float32 spacing (1.5e-8 m) of a coordinate of
 * 0.15 m, so the increments would be lost. A displacement from a reference
 * a few steps old is small, so its increments keep their digits; every
 * REBASE steps, and at the end of every call (spn__lattice_sync), d is added
 * to w->x in float64 and starts again from zero.
 *
 * Differences. Per spring the reference difference L = x_a - x_b of w->x is
 * taken in float64 and rounded once (relative error 2^-24 of the segment);
 * the step's difference is L + (d_a - d_b). Coordinates rounded to float32
 * before the difference would lose |x| / |L| times more: 1e-3 of a 2% stretch
 * on the 1M web's radials (docs/physics-lattice.md).
 *
 * The sweep is lattice.c's: rows swept outwards, the radials into a row
 * computed from the previous row's state before that row moves, bands fixed
 * whatever the thread count, the radials between bands first, sums added in
 * band order. The rows are read straight from the state arrays (no copies)
 * and moved in place: a row moves only after every spring that reads it has
 * been computed. Every operation is a correctly rounded float32 or float64
 * operation (no FMA: -ffp-contract=off, no approximate reciprocal), so the
 * bits are the same on any thread count and vector width. */
#include "lattice_rows.h"
#include "world_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Steps between two rebases of the float32 displacements onto w->x: a
 * displacement is then at most 64 v dt, and its round-off per step at most
 * 2^-24 of that, 4e-6 of one step's increment. */
#define REBASE 64u

/* Arrays of a thread's workspace, `stride` floats each. */
enum {
    F_RAD = 0,   /* 2 rows x 3: radial force on the inner end */
    F_RING = 6,  /* 2 rows x 3: ring force on the lower end */
    F_HUB = 12,  /* 6: the hub's d and u, replicated along a row */
    F_E = 18,    /* per-spring elastic energy */
    F_P = 19,    /* per-spring damping power */
    F_T = 20,    /* 3: per-particle sum terms */
    F_COUNT = 23
};

struct spn__lat32 {
    size_t np, m;
    float *block;         /* every per-particle and per-slot array below */
    float *d[3], *u[3];   /* displacement from w->x [m] and velocity, per particle */
    float *mass, *inv_mass;
    float *rl[3], *gl[3]; /* reference differences of the radial and ring slots */
    float *rk, *rkd, *rr, *gk, *gkd, *gr;
    float *cut;           /* per band: 3 x N radial forces into its first row */
    uint32_t ncut;
    float **ws;
    int nws;
    size_t stride;
    bool live;            /* the state above is ahead of w->x, w->v */
    bool params_ok;       /* rk .. gr match the lattice's float64 slots */
    uint32_t since;       /* steps since the last rebase */
};

typedef struct a32 {
    const spn__lattice *L;
    spn__lat32 *F;
    float g[3], drag, dt;
    bool sym;
} a32;

void spn__lat32_free(spn__lat32 *F)
{
    if (!F) return;
    for (int t = 0; t < F->nws; t++) free(F->ws[t]);
    free(F->ws), free(F->cut), free(F->block);
    free(F);
}

/* ---- kernels ---- */

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

/* ---- the sweep ---- */

LAT_INLINE void state_rows(const spn__lat32 *F, size_t p0, float **D, float **U)
{
    for (int c = 0; c < 3; c++) D[c] = F->d[c] + p0, U[c] = F->u[c] + p0;
}

LAT_INLINE void finish32(const a32 *a, size_t p0, uint32_t n, float *const *ri, float *const *rg,
                         float *const *ro, float *const *t, double (*acc)[LANES])
{
    const spn__lat32 *F = a->F;
    float *D[3], *U[3];
    state_rows(F, p0, D, U);
    /* (sym a constant in each call: GCC 12 does not vectorise a select on a
     * run-time bool between floats) */
#define ROW32(sym)                                                                                              \
    row32(n, sym, a->dt, a->g, a->drag, F->mass + p0, F->inv_mass + p0, D[0], D[1], D[2], U[0], U[1], U[2], ri[0], \
          ri[1], ri[2], rg[0], rg[1], rg[2], ro ? ro[0] : NULL, ro ? ro[1] : NULL, ro ? ro[2] : NULL, t[0], t[1], t[2])
    if (a->sym) ROW32(true);
    else ROW32(false);
#undef ROW32
    lane_add32(acc[L_MV2], t[0], n);
    lane_add32(acc[L_GAIN], t[1], n);
    lane_add32(acc[L_MVN2], t[2], n);
}

/* The hub: its radial forces in radial order, then its update. */
static void hub32(const a32 *a, float *const *rad, double (*acc)[LANES])
{
    spn__lat32 *F = a->F;
    const uint32_t n = a->L->radials;
    const float m = F->mass[0], dm = a->drag * m;
    float f[3];
    for (int c = 0; c < 3; c++) {
        f[c] = m * a->g[c] - dm * F->u[c][0];
        for (uint32_t i = 0; i < n; i++) f[c] += rad[c][i];
    }
    const moved32 o = one32(f[0], f[1], f[2], F->inv_mass[0], m, F->d[0][0], F->d[1][0], F->d[2][0], F->u[0][0],
                            F->u[1][0], F->u[2][0], a->sym, a->dt, a->g);
    for (int c = 0; c < 3; c++) F->d[c][0] = o.d[c], F->u[c][0] = o.u[c];
    acc[L_MV2][0] += o.mv2, acc[L_GAIN][0] += o.gain, acc[L_MVN2][0] += o.mvn2;
}

/* Radial springs into band b's first row, from the state before the step. */
SPN__KERNEL static void cut32(const a32 *a, float *ws, uint32_t b)
{
    const spn__lattice *L = a->L;
    const spn__lat32 *F = a->F;
    const uint32_t n = L->radials, j = b * L->band_rows;
    float *Da[3], *Ua[3], *Db[3], *Ub[3], *f[3];
    state_rows(F, 1 + (size_t)(j - 1) * n, Da, Ua);
    state_rows(F, 1 + (size_t)j * n, Db, Ub);
    for (int c = 0; c < 3; c++) f[c] = F->cut + ((size_t)b * 3 + c) * n;
    double acc_e[LANES] = {0}, acc_p[LANES] = {0};
    spring_rows(n, Da, Ua, Db, Ub, (float *const *)F->rl, (size_t)j * n, F->rk, F->rkd, F->rr, f, 0,
                ws + F_E * F->stride, ws + F_P * F->stride, acc_e, acc_p);
    double *p = L->partial + (size_t)b * L_NSUMS;
    p[L_ELASTIC] = lane_total(acc_e), p[L_DAMP] = lane_total(acc_p);
}

/* Sweep band b (lattice.c's band_pass on the float32 state). */
SPN__KERNEL static void band32(const a32 *a, float *ws, uint32_t b)
{
    const spn__lattice *L = a->L;
    spn__lat32 *F = a->F;
    const uint32_t n = L->radials, lo = b * L->band_rows;
    const uint32_t hi = lo + L->band_rows < L->rings ? lo + L->band_rows : L->rings;
    const size_t st = F->stride;
    float *RAD[2][3], *RING[2][3], *H[6], *t[3], *cut[3], *next_cut[3];
    for (int c = 0; c < 3; c++) {
        RAD[0][c] = ws + (F_RAD + c) * st, RAD[1][c] = ws + (F_RAD + 3 + c) * st;
        RING[0][c] = ws + (F_RING + c) * st, RING[1][c] = ws + (F_RING + 3 + c) * st;
        t[c] = ws + (F_T + c) * st;
        cut[c] = F->cut + ((size_t)b * 3 + c) * n;
        next_cut[c] = F->cut + ((size_t)(b + 1) * 3 + c) * n;
    }
    for (int c = 0; c < 6; c++) H[c] = ws + (F_HUB + c) * st;
    float *e = ws + F_E * st, *p = ws + F_P * st;
    double acc_e[LANES] = {0}, acc_p[LANES] = {0}, acc[L_NSUMS][LANES] = {{0}};
    int cur = 0;
    float **rad_cur = NULL, **rad_prev = NULL;
    for (uint32_t j = lo; j < hi; j++, cur ^= 1) {
        const size_t s0 = (size_t)j * n, p0 = 1 + s0;
        float *D[3], *U[3];
        state_rows(F, p0, D, U);
        if (j == lo && j > 0) {
            rad_cur = cut; /* computed by cut32; its sums are in the band's partial */
        } else if (j == 0) {
            for (int c = 0; c < 3; c++) {
                const float hd = F->d[c][0], hu = F->u[c][0];
                for (uint32_t i = 0; i < n; i++) H[c][i] = hd, H[3 + c][i] = hu;
            }
            spring_rows(n, H, H + 3, D, U, (float *const *)F->rl, 0, F->rk, F->rkd, F->rr, RAD[cur], 0, e, p, acc_e,
                        acc_p);
            rad_cur = RAD[cur];
            hub32(a, rad_cur, acc);
        } else {
            float *Dp[3], *Up[3];
            state_rows(F, p0 - n, Dp, Up);
            spring_rows(n, Dp, Up, D, U, (float *const *)F->rl, s0, F->rk, F->rkd, F->rr, RAD[cur], 0, e, p, acc_e,
                        acc_p);
            rad_cur = RAD[cur];
        }
        float *D1[3], *U1[3], *Dl[3], *Ul[3];
        state_rows(F, p0 + 1, D1, U1);
        state_rows(F, p0 + n - 1, Dl, Ul);
        spring_rows(n - 1, D, U, D1, U1, (float *const *)F->gl, s0, F->gk, F->gkd, F->gr, RING[cur], 0, e, p, acc_e,
                    acc_p);
        spring_rows(1, D, U, Dl, Ul, (float *const *)F->gl, s0 + n - 1, F->gk, F->gkd, F->gr, RING[cur], n - 1, e, p,
                    acc_e, acc_p);
        if (j > lo) finish32(a, p0 - n, n, rad_prev, RING[cur ^ 1], rad_cur, t, acc);
        rad_prev = rad_cur;
    }
    finish32(a, 1 + (size_t)(hi - 1) * n, n, rad_prev, RING[cur ^ 1], hi < L->rings ? next_cut : NULL, t, acc);
    double *out = L->partial + (size_t)b * L_NSUMS;
    if (b == 0) out[L_ELASTIC] = out[L_DAMP] = 0;
    out[L_ELASTIC] += lane_total(acc_e), out[L_DAMP] += lane_total(acc_p);
    out[L_MV2] = lane_total(acc[L_MV2]), out[L_GAIN] = lane_total(acc[L_GAIN]), out[L_MVN2] = lane_total(acc[L_MVN2]);
}

static int thread_id(void)
{
#ifdef _OPENMP
    return omp_get_thread_num();
#else
    return 0;
#endif
}

static void sweep32(const a32 *a, int threads, double *sum)
{
    const spn__lattice *L = a->L;
    const uint32_t nb = L->nbands;
#pragma omp parallel num_threads(threads)
    {
        float *ws = a->F->ws[thread_id()];
#pragma omp for schedule(static)
        for (uint32_t b = 1; b < nb; b++) cut32(a, ws, b);
#pragma omp for schedule(static)
        for (uint32_t b = 0; b < nb; b++) band32(a, ws, b);
    }
    for (int k = 0; k < L_NSUMS; k++) sum[k] = 0;
    for (uint32_t b = 0; b < nb; b++)
        for (int k = 0; k < L_NSUMS; k++) sum[k] += L->partial[(size_t)b * L_NSUMS + k];
}

/* ---- state: load, reference differences, write-back ---- */

/* The reference differences x_a - x_b of every slot, from w->x. */
static void references(spn_world *w, int threads)
{
    const spn__lattice *L = w->lat;
    spn__lat32 *F = L->f32;
    const uint32_t n = L->radials, rings = L->rings;
    const spn_vec3 *x = w->x;
#pragma omp parallel for schedule(static) num_threads(threads)
    for (uint32_t j = 0; j < rings; j++) {
        const size_t s0 = (size_t)j * n, p0 = 1 + s0;
        for (uint32_t i = 0; i < n; i++) {
            const spn_vec3 in = j ? x[p0 - n + i] : x[0], me = x[p0 + i];
            const spn_vec3 nb = i + 1 < n ? x[p0 + i + 1] : x[p0];
            const spn_vec3 ra = i + 1 < n ? me : x[p0], rb = i + 1 < n ? nb : me;
            F->rl[0][s0 + i] = (float)(in.x - me.x), F->rl[1][s0 + i] = (float)(in.y - me.y);
            F->rl[2][s0 + i] = (float)(in.z - me.z);
            F->gl[0][s0 + i] = (float)(ra.x - rb.x), F->gl[1][s0 + i] = (float)(ra.y - rb.y);
            F->gl[2][s0 + i] = (float)(ra.z - rb.z);
        }
    }
}

/* d into w->x (in float64), u into w->v; with `rebase`, d starts again from
 * zero and the references follow w->x. */
static void write_back(spn_world *w, int threads, bool rebase)
{
    spn__lat32 *F = w->lat->f32;
    const uint32_t np = (uint32_t)F->np;
    spn_vec3 *x = w->x, *v = w->v;
#pragma omp parallel for schedule(static) num_threads(threads)
    for (uint32_t i = 0; i < np; i++) {
        x[i].x += (double)F->d[0][i], x[i].y += (double)F->d[1][i], x[i].z += (double)F->d[2][i];
        v[i] = spn_v3(F->u[0][i], F->u[1][i], F->u[2][i]);
        if (rebase) F->d[0][i] = F->d[1][i] = F->d[2][i] = 0;
    }
    if (rebase) references(w, threads);
    F->since = 0;
    F->live = rebase;
}

static bool alloc_state(spn__lattice *L, size_t np)
{
    const size_t m = (size_t)L->rings * L->radials;
    if (L->f32 && L->f32->np == np) return true;
    spn__lat32_free(L->f32);
    spn__lat32 *F = L->f32 = calloc(1, sizeof *F);
    if (!F || !(F->block = malloc((8 * np + 12 * m) * sizeof *F->block))) return false;
    F->np = np, F->m = m;
    float *q = F->block;
    for (int c = 0; c < 3; c++) F->d[c] = q, q += np, F->u[c] = q, q += np;
    F->mass = q, q += np, F->inv_mass = q, q += np;
    for (int c = 0; c < 3; c++) F->rl[c] = q, q += m, F->gl[c] = q, q += m;
    float **par[6] = {&F->rk, &F->rkd, &F->rr, &F->gk, &F->gkd, &F->gr};
    for (int k = 0; k < 6; k++) *par[k] = q, q += m;
    return true;
}

/* The float32 state from the world's: d = 0, u = v, the spring constants
 * and masses rounded, the references. */
static bool load(spn_world *w, int threads)
{
    spn__lattice *L = w->lat;
    if (!alloc_state(L, w->np)) return false;
    spn__lat32 *F = L->f32;
    const uint32_t np = w->np;
    if (!F->params_ok)
        for (size_t s = 0; s < F->m; s++) {
            F->rk[s] = (float)L->rk[s], F->rkd[s] = (float)L->rkd[s], F->rr[s] = (float)L->rrest[s];
            F->gk[s] = (float)L->gk[s], F->gkd[s] = (float)L->gkd[s], F->gr[s] = (float)L->grest[s];
        }
    F->params_ok = true;
    const spn_vec3 *v = w->v;
    const double *mass = w->mass, *inv_mass = w->inv_mass;
#pragma omp parallel for schedule(static) num_threads(threads)
    for (uint32_t i = 0; i < np; i++) {
        F->mass[i] = (float)mass[i], F->inv_mass[i] = (float)inv_mass[i];
        F->d[0][i] = F->d[1][i] = F->d[2][i] = 0;
        F->u[0][i] = (float)v[i].x, F->u[1][i] = (float)v[i].y, F->u[2][i] = (float)v[i].z;
    }
    references(w, threads);
    F->since = 0;
    F->live = true;
    return true;
}

/* Per-thread workspaces and the cut for this step's bands. */
static bool prepare32(spn__lattice *L, int threads)
{
    spn__lat32 *F = L->f32;
    if (F->ncut != L->nbands) {
        free(F->cut);
        F->ncut = 0;
        if (!(F->cut = malloc((size_t)L->nbands * 3 * L->radials * sizeof *F->cut))) return false;
        F->ncut = L->nbands;
    }
    if (F->nws < threads) {
        float **ws = realloc(F->ws, (size_t)threads * sizeof *ws);
        if (!ws) return false;
        F->ws = ws;
        F->stride = ((size_t)L->radials + 15) & ~(size_t)15;
        for (; F->nws < threads; F->nws++)
            if (!(F->ws[F->nws] = malloc(F_COUNT * F->stride * sizeof **F->ws))) return false;
    }
    return true;
}

bool spn__lat32_explicit(spn_world *w, int threads, double dt, bool symplectic, spn__step_result *r)
{
    spn__lattice *L = w->lat;
    if (!w->no_backup) spn__lattice_sync(w); /* a step with a backup starts from w->x */
    if (!(L->f32 && L->f32->live)) {
        if (!w->no_backup) {
            memcpy(w->x0, w->x, w->np * sizeof *w->x);
            memcpy(w->v0, w->v, w->np * sizeof *w->v);
        }
        if (!load(w, threads)) return false;
    }
    spn__lat32 *F = L->f32;
    if (!prepare32(L, threads)) {
        spn__lattice_sync(w);
        return false;
    }
    a32 a = {L, F, {(float)w->def.gravity.x, (float)w->def.gravity.y, (float)w->def.gravity.z},
             (float)w->def.drag, (float)dt, symplectic};
    double sum[L_NSUMS];
    sweep32(&a, threads, sum);
    r->elastic = sum[L_ELASTIC];
    r->e_before = 0.5 * sum[L_MV2] + sum[L_ELASTIC];
    r->gain_kp = sum[L_GAIN];
    r->work = 0;
    r->dissipated = dt * (sum[L_DAMP] + w->def.drag * sum[L_MV2]);
    r->kinetic = 0.5 * sum[L_MVN2];
    if (++F->since >= REBASE || !w->no_backup) write_back(w, threads, w->no_backup);
    return true;
}

void spn__lattice_sync(spn_world *w)
{
    if (w->lat && w->lat->f32 && w->lat->f32->live) write_back(w, spn__threads(w, w->np), false);
}

void spn__lat32_params_changed(spn__lat32 *F)
{
    if (F) F->params_ok = false;
}

void spn__lattice_discard(spn_world *w)
{
    if (w->lat && w->lat->f32) w->lat->f32->live = false;
}

void spn_world_set_precision(spn_world *w, spn_precision precision)
{
    spn__lattice_sync(w);
    w->precision = precision == SPN_PRECISION_FLOAT32 ? SPN_PRECISION_FLOAT32 : SPN_PRECISION_FLOAT64;
}

spn_precision spn_world_precision(const spn_world *w) { return (spn_precision)w->precision; }
