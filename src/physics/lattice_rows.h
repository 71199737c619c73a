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
/* Steps a pass of the blocked sweep takes (lattice_block_t.h). */
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
    void **bws;        /* temporal blocking (lattice_block_t.h): per-thread workspaces, */
    int nbws;          /* shared by the two precisions */
    size_t block_size; /* bytes in each */
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

/* Temporal blocking (lattice_block_t.h, helpers in lattice_block.c). */
/* Whether K levels can go as one blocked pass on `threads` threads (each
 * thread's run of bands deep enough for its ghost rows). */
bool spn__lattice_block_ready(const spn__lattice *L, int threads, uint32_t K);
/* Per-thread workspaces of `bytes` each and the per-level band partials;
 * false when out of memory. */
bool spn__lattice_block_alloc(spn__lattice *L, int threads, size_t bytes);
/* Each level's sums from its band partials, in band order. */
void spn__lattice_block_sums(const spn__lattice *L, uint32_t K, double sums[][L_NSUMS]);
/* Up to k float32 Euler or symplectic steps (mode), or one RK4 step, as one
 * blocked pass on `threads` threads (block ready); each step's results
 * into r[], the count done (0: none, nothing done). */
int spn__lat32_block_steps(spn_world *w, int threads, double dt, int mode, int k, spn__step_result *r);

#endif
