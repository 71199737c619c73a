/* The row kernels of the float64 lattice step (lattice.c): the spring
 * stencil over structure-of-arrays rows, and (from lattice_rows_t.h) the
 * force assembly and the Euler / symplectic Euler / RK4 updates. Header-only
 * so that each target_clones version of the sweep inlines its own copy.
 * Plain loops over contiguous arrays, written for GCC 12 to vectorise; where
 * it would not, the comment says what was changed. Every per-element
 * expression is the one the general path uses, so the bits do not depend on
 * the vector width. */
#ifndef SPN_PHYSICS_LATTICE_ROWS_H
#define SPN_PHYSICS_LATTICE_ROWS_H

#include "world_internal.h"

#include <math.h>
#include <string.h>

/* Per-band sums: elastic energy, spring damping power, sum m v^2 at the
 * evaluated state, energy gain of the update, sum m v^2 after it. */
enum { L_ELASTIC, L_DAMP, L_MV2, L_GAIN, L_MVN2, L_NSUMS };
#define LANES 8
/* Steps a pass of the blocked sweep takes (lattice_block.c). */
#define LAT_LEVELS SPN__LAT_BLOCK_MAX
#define LAT_INLINE static inline __attribute__((always_inline))

/* Arrays of one thread's workspace, `stride` doubles each. */
enum {
    WS_RAD = 0,   /* 2 rows x 3: radial force on the inner end */
    WS_RING = 6,  /* 2 rows x 3: ring force on the lower end */
    WS_HUB = 12,  /* 6: the hub's x and v, replicated along a row */
    WS_E = 18,    /* per-spring elastic energy (scratch) */
    WS_P = 19,    /* per-spring damping power (scratch) */
    WS_T = 20,    /* 3: per-particle sum terms (scratch) */
    WS_F = 23,    /* 3: RK4: the assembled force on the row being moved */
    WS_COUNT = 26
};

/* The float32 step's state and arrays (lattice_f32.c). */
typedef struct spn__lat32 spn__lat32;
void spn__lat32_free(spn__lat32 *F);
/* A slot's k, kd or rest changed: convert them again before the next step. */
void spn__lat32_params_changed(spn__lat32 *F);
/* The float32 state is ahead of w->x, w->v (inside an spn_world_advance call). */
bool spn__lat32_live(const spn__lat32 *F);
/* The float32 state into w->x, w->v, if it is ahead of them. */
void spn__lat32_sync(spn_world *w);
/* Forget the float32 state (w->x, w->v are being restored). */
void spn__lat32_discard(spn__lat32 *F);
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
    double *state;   /* the float64 state, structure of arrays: x, v by component, np each */
    double *x[3], *v[3];
    bool live;       /* inside spn_world_advance: x, v above are ahead of w->x, w->v */
    double *rk4;     /* RK4 (on first use): two trial states, 6 x np each, ax, av */
    double *trial[2][6], *ax[3], *av[3];
    double **bws;      /* temporal blocking (lattice_block.c): per-thread workspaces */
    int nbws;
    size_t block_size; /* doubles in each */
    double *partial_k; /* per level and band: L_NSUMS */
    uint32_t npartial_k;
    spn__lat32 *f32; /* the float32 step (on first use) */
};

/* What a sweep does with a row once its forces are complete. */
enum { MODE_EULER, MODE_SYMPLECTIC, MODE_RK4_STAGE, MODE_RK4_LAST };

typedef struct lat_args {
    const spn__lattice *L;
    const double *ex[3], *ev[3]; /* the state the forces are evaluated at */
    double *tx[3], *tv[3];       /* RK4 stage: the next trial state */
    const double *mass, *inv_mass;
    double g[3], drag, dt, h, weight;
    int mode;
    bool first;                  /* RK4: stage 0 */
} lat_args;

#define LK_T double
#define LK(name) name##64
#include "lattice_rows_t.h"
#undef LK
#undef LK_T

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

/* Springs from rows a to b of a state (3 arrays each, offsets off_a,
 * off_b) with parameters k, kd, rest, forces into f; sums into acc. */
LAT_INLINE void springs_rows(uint32_t n, const double *const *ax, const double *const *av, const double *const *bx,
                             const double *const *bv, size_t off_a, size_t off_b, const double *k, const double *kd,
                             const double *rest, double *const *f, size_t off_f, double *e, double *p,
                             double *acc_e, double *acc_p)
{
    springs(n, ax[0] + off_a, ax[1] + off_a, ax[2] + off_a, bx[0] + off_b, bx[1] + off_b, bx[2] + off_b,
            av[0] + off_a, av[1] + off_a, av[2] + off_a, bv[0] + off_b, bv[1] + off_b, bv[2] + off_b, k, kd, rest,
            f[0] + off_f, f[1] + off_f, f[2] + off_f, e, p);
    lane_add64(acc_e, e, n);
    lane_add64(acc_p, p, n);
}


/* The hub's force: gravity and drag at its evaluated velocity v, then its
 * radial forces in radial order. */
LAT_INLINE void lat_hub_force(const lat_args *a, const double *v, double *const *rad, double *f)
{
    const uint32_t n = a->L->radials;
    const double m = a->mass[0], dm = a->drag * m;
    for (int c = 0; c < 3; c++) {
        f[c] = m * a->g[c] - dm * v[c];
        for (uint32_t i = 0; i < n; i++) f[c] += rad[c][i];
    }
}

/* The explicit hub: its radial forces (in radial order) added to gravity and
 * drag, then moved in place; its sum terms into acc. */
LAT_INLINE void lat_hub_move(const lat_args *a, double *const *rad, double (*acc)[LANES])
{
    const spn__lattice *L = a->L;
    const double v[3] = {L->v[0][0], L->v[1][0], L->v[2][0]};
    double f[3];
    lat_hub_force(a, v, rad, f);
    const moved64 o = one64(f[0], f[1], f[2], a->inv_mass[0], a->mass[0], L->x[0][0], L->x[1][0], L->x[2][0],
                            v[0], v[1], v[2], a->mode == MODE_SYMPLECTIC, a->dt, a->g);
    for (int c = 0; c < 3; c++) L->x[c][0] = o.x[c], L->v[c][0] = o.v[c];
    acc[L_MV2][0] += o.mv2, acc[L_GAIN][0] += o.gain, acc[L_MVN2][0] += o.mvn2;
}

/* An explicit row (particles p0 .., state arrays X, V) with its forces
 * complete (radial in, ring, radial out or NULL), moved in place; its sum
 * terms through t into acc. */
LAT_INLINE void lat_row_move(const lat_args *a, size_t p0, uint32_t n, double *const *X, double *const *V,
                             double *const *ri, double *const *rg, double *const *ro, double *const *t,
                             double (*acc)[LANES])
{
    /* (sym a constant in each call: GCC 12 does not vectorise a select on a
     * run-time bool) */
#define ROW64(sym)                                                                                              \
    row64(n, sym, a->dt, a->g, a->drag, a->mass + p0, a->inv_mass + p0, X[0], X[1], X[2], V[0], V[1], V[2], ri[0], \
          ri[1], ri[2], rg[0], rg[1], rg[2], ro ? ro[0] : NULL, ro ? ro[1] : NULL, ro ? ro[2] : NULL, t[0], t[1], t[2])
    if (a->mode == MODE_SYMPLECTIC) ROW64(true);
    else ROW64(false);
#undef ROW64
    lane_add64(acc[L_MV2], t[0], n);
    lane_add64(acc[L_GAIN], t[1], n);
    lane_add64(acc[L_MVN2], t[2], n);
}

/* The rows an RK4 stage reads and writes (3 arrays each, at the row): the
 * velocity it is evaluated at, the step's base state, the next trial state
 * and the weighted sums. */
typedef struct rk4_rows {
    const double *V[3];
    double *xb[3], *vb[3], *xt[3], *vt[3], *ax[3], *av[3];
} rk4_rows;

/* Particles p0 .. p0+n-1 of an RK4 stage (a->mode, first, h, weight), their
 * force F known; sum terms through t into acc. */
LAT_INLINE void lat_rk4_update(const lat_args *a, size_t p0, uint32_t n, const rk4_rows *R, double *const *F,
                               double *const *t, double (*acc)[LANES])
{
    const double *m = a->mass + p0, *im = a->inv_mass + p0;
    if (a->mode == MODE_RK4_STAGE) {
        /* m v^2 at a stage's state serves the drag's loss (and, at the first
         * stage, the energy before the step); without drag the later stages
         * skip it, as drag * m v^2 would add exactly zero */
        if (a->first || a->drag != 0) {
            rk4_kin64(n, m, im, R->V[0], R->V[1], R->V[2], t[0]);
            lane_add64(acc[L_MV2], t[0], n);
        }
        /* (three calls, not a loop: GCC 12 does not vectorise an inlined
         * function with restrict parameters inside a loop) */
        rk4_stage64(n, a->first, a->h, a->weight, im, R->V[0], F[0], R->xb[0], R->vb[0], R->xt[0], R->vt[0],
                    R->ax[0], R->av[0]);
        rk4_stage64(n, a->first, a->h, a->weight, im, R->V[1], F[1], R->xb[1], R->vb[1], R->xt[1], R->vt[1],
                    R->ax[1], R->av[1]);
        rk4_stage64(n, a->first, a->h, a->weight, im, R->V[2], F[2], R->xb[2], R->vb[2], R->xt[2], R->vt[2],
                    R->ax[2], R->av[2]);
    } else {
        rk4_sums64(n, a->h, a->g, m, im, R->V[0], R->V[1], R->V[2], F[0], F[1], F[2], R->ax[0], R->ax[1], R->ax[2],
                   R->av[0], R->av[1], R->av[2], R->vb[0], R->vb[1], R->vb[2], t[0], t[1], t[2]);
        rk4_last64(n, a->h, im, R->V[0], F[0], R->ax[0], R->av[0], R->xb[0], R->vb[0]);
        rk4_last64(n, a->h, im, R->V[1], F[1], R->ax[1], R->av[1], R->xb[1], R->vb[1]);
        rk4_last64(n, a->h, im, R->V[2], F[2], R->ax[2], R->av[2], R->xb[2], R->vb[2]);
        lane_add64(acc[L_MV2], t[0], n);
        lane_add64(acc[L_GAIN], t[1], n);
        lane_add64(acc[L_MVN2], t[2], n);
    }
}

/* An Euler or symplectic step's results from its sweep's sums. */
static inline void lat_explicit_result(const double *sum, double dt, double drag, spn__step_result *r)
{
    r->elastic = sum[L_ELASTIC];
    r->e_before = 0.5 * sum[L_MV2] + sum[L_ELASTIC];
    r->gain_kp = sum[L_GAIN];
    r->work = 0;
    r->dissipated = dt * (sum[L_DAMP] + drag * sum[L_MV2]);
    r->kinetic = 0.5 * sum[L_MVN2];
}

/* An RK4 step's results from its four stages' sums: the energy before from
 * the first, the losses weighted 1, 2, 2, 1, the gain and new energy from
 * the last. */
static inline void lat_rk4_result(double sums[4][L_NSUMS], double dt, double drag, spn__step_result *r)
{
    static const double weight[4] = {1, 2, 2, 1};
    double damp = 0;
    for (int s = 0; s < 4; s++) damp += weight[s] * (sums[s][L_DAMP] + drag * sums[s][L_MV2]);
    r->e_before = 0.5 * sums[0][L_MV2] + sums[0][L_ELASTIC];
    r->elastic = sums[0][L_ELASTIC];
    r->gain_kp = sums[3][L_GAIN];
    r->kinetic = 0.5 * sums[3][L_MVN2];
    r->work = 0;
    r->dissipated = dt / 6 * damp;
}

/* Whether K explicit steps can go as one blocked pass on `threads` threads
 * (each thread's run of bands deep enough for its ghost rows). */
bool spn__lattice_block_ready(const spn__lattice *L, int threads, uint32_t K);
/* K levels (2 .. LAT_LEVELS) in one blocked pass over the state in L->x,
 * L->v: K explicit steps, or (rk4) the four stages of one RK4 step; la[s]
 * the arguments of level s + 1, the sums of each into sums[s]. False when
 * out of memory (nothing done). */
bool spn__lattice_block(spn__lattice *L, const lat_args *la, bool rk4, int threads, uint32_t K,
                        double sums[][L_NSUMS]);

#endif
