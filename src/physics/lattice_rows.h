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

#include <assert.h>
#include <math.h>
#include <stdint.h>
#include <string.h>

/* Per-band sums: elastic energy, spring damping power, sum m v^2 at the
 * evaluated state, energy gain of the update, sum m v^2 after it. */
enum { L_ELASTIC, L_DAMP, L_MV2, L_GAIN, L_MVN2, L_NSUMS };
#define LANES 8
/* Steps a pass of the blocked sweep takes (lattice_block_t.h). */
#define LAT_LEVELS SPN__LAT_BLOCK_MAX
#define LAT_INLINE static inline __attribute__((always_inline))

/* Arrays of one thread's workspace, `stride` numbers each. */
enum {
    WS_RAD = 0,   /* 2 rows x 3: radial force on the inner end */
    WS_RING = 6,  /* 2 rows x 3: ring force on the lower end */
    WS_HUB = 12,  /* 6: the hub's x and v, replicated along a row */
    WS_F = 18,    /* 3: RK4: the assembled force on the row being moved */
    WS_COUNT = 21
};

/* Sum columns. A band's energy sums are kept per radial i: the terms of its
 * rows add into column i (c[i] += term) in the loop that makes them, and
 * the columns are reduced once, at the band's end (col_take). (Until
 * 2026-11-22 each loop stored its terms and a second loop added them into
 * eight lanes: a chain of dependent additions after every loop, about a
 * ninth of the 5k web's step.) One set per quantity of L_NSUMS (NULL where
 * a kernel does not sum it). */
typedef struct lat_cols {
    double *c[L_NSUMS];
    /* float32 scratch, one row per quantity: the float32 kernels store their
     * terms here, in a loop that stays all float32 (16 lanes wide), and add
     * them into c after it (col_addf) */
    float *scr[L_NSUMS];
    /* float32: a row's ring spring terms (elastic, damping) while its
     * radial springs' are held in scr[L_ELASTIC], scr[L_DAMP], so that one
     * pass adds both (col_join; spring_rows in lattice_rows32.h) */
    float *join[2];
} lat_cols;
/* Per thread: COL_SETS sets, then the cut's two columns. A sweep uses set
 * 0; a blocked pass two per level (sets 2 s and 2 s + 1) and the last for
 * the ghost rows' sums, which are never read (that set alone is not kept
 * zero). */
#define COL_SETS (2 * SPN__LAT_BLOCK_MAX + 1)
#define COL_COUNT (COL_SETS * L_NSUMS + 2 + (L_NSUMS + 2 + 1) / 2)

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

/* m v^2 over the state an RK4 step left: its last stage's L_MVN2 sum,
 * which is the next step's first-stage L_MV2 bit for bit (see
 * LK(rk4_update)). `ok` from that step until the state is loaded again or
 * another integrator steps it. */
typedef struct lat_mv2 {
    double sum;
    bool ok;
} lat_mv2;

/* After an RK4 step's four stages (`known`: its first stage took m v^2
 * from m, kin_known): that sum put into its first stage's sums, the last
 * stage's kept for the next step. */
static inline void lat_mv2_carry(lat_mv2 *m, bool known, double sums[][L_NSUMS])
{
    if (known) sums[0][L_MV2] = m->sum;
    m->sum = sums[3][L_MVN2];
    m->ok = true;
}

/* A governor (lattice.c): what a unit of work (one step, or one blocked
 * pass) costs with each of two choices, ns per particle and level, which is
 * kept, and when the other is tried again. The thread governor of a web
 * that may take threads below parallel_min ("Threads below parallel_min")
 * chooses between one thread (0) and threads (1); the pass governor, on one
 * thread ("One thread: passes or single steps"), between single steps (0)
 * and blocked passes (1). */
typedef struct lat_gov {
    double ns[2];     /* choice [0] (one thread; single steps) and [1] (threads; blocked
                       * passes): the kept choice's running mean over its units, the
                       * other's from its last try */
    double t0;        /* start of the unit being timed [s]; < 0: none */
    double next;      /* the choice not kept is tried from this time [s] */
    double wait[2];   /* ... each choice this long after it was last tried or left [s];
                       * 0 until both choices' first units are in (first) */
    double try_sum;   /* ns of the try under way, summed over its units */
    int try_units;    /* its units so far (0: no try under way) */
    int mode;         /* the unit being timed: choice 0 or 1 */
    int kept;         /* the choice kept between tries */
    int first[2];     /* each choice's units so far, up to LAT_GOV_FIRST (its figure
                       * their minimum: the first pay for workspaces and cold caches) */
} lat_gov;

/* A governor's choice (0 or 1) for the unit starting at `now` [s], and its
 * record of the unit ending at `now` that took `ns` per particle and
 * level. */
int spn__lat_gov_pick(lat_gov *g, double now);
void spn__lat_gov_record(lat_gov *g, double ns, double now);

/* How a blocked pass on threads shares out its bands (lattice_block.c,
 * spn__lattice_split_*): share t takes bands [first[t], first[t + 1]). Even
 * at first; then, from each pass's measured time per row of each share, the
 * bands move toward the faster threads, as two cores of a virtual machine,
 * or a big and a little core, need not run alike. Where the bands go
 * changes no result: every band's rows get the same arithmetic and its sums
 * the same order on any thread. */
typedef struct lat_share_time {
    double ns; /* the share's fronts in the last pass (its own line: each share writes its own) */
    char pad[64 - sizeof(double)];
} lat_share_time;

typedef struct lat_split {
    int shares; /* what first[] is for: shares and bands (0: nothing yet) */
    uint32_t nbands;
    uint32_t *first;      /* shares + 1 band boundaries */
    double *rate;         /* per share: smoothed ns per row (0: not measured) */
    lat_share_time *took; /* per share */
    int hold;             /* tests: >= 0 holds share 0 to this many bands (two shares) */
    bool moved;           /* the last pass ran on a new split: its times are not learnt from */
    /* The rows each share sent its neighbours at the end of the last pass
     * (lattice_block_t.h, LK(send)): valid while `sent_ok`, for a pass of
     * sent_K levels in numbers of sent_size bytes on the boundaries
     * sent_first (shares + 1). */
    uint32_t *sent_first;
    uint32_t sent_K;
    size_t sent_size;
    bool sent_ok;
} lat_split;

struct spn__lattice {
    uint32_t rings, radials;
    /* The float64 arrays' row pitch: radials rounded up to whole 64-byte
     * lines, so that every row starts a line (the state's, masses' and
     * slots'; the float32 step's rows have a pitch of their own,
     * spn__lat32). Particle 1 + j N + i of the world is 1 + j pitch + i
     * here, slot j N + i is j pitch + i. */
    uint32_t pitch;
    size_t nlat; /* numbers in each float64 particle array: 1 + rings pitch */
    double *slots;            /* the block of the six slot arrays below */
    double *rk, *rkd, *rrest; /* radial slots: ring * pitch + i, (ring - 1, i) -> (ring, i) */
    double *gk, *gkd, *grest; /* ring slots: ring * pitch + i, (i, i + 1); i = N - 1: (0, N - 1) */
    uint32_t nbands; /* bands of rows, lat_band_lo */
    double *cut;     /* per band: 3 rows of pitch, the radial forces into its first row (band 0 unused) */
    double *partial; /* per band: L_NSUMS */
    int nws;         /* workspaces allocated (one per thread) */
    double **ws;
    size_t stride;   /* doubles per workspace array (N rounded up) */
    double *state;   /* the float64 state, structure of arrays: x, v by component, nlat each */
    double *masses;  /* the block of mass and inv_mass: the world's, laid out as x, copied at each load */
    double *mass, *inv_mass;
    double *x[3], *v[3];
    bool live;       /* inside spn_world_advance: x, v above are ahead of w->x, w->v */
    lat_mv2 mv2;     /* RK4 without drag: m v^2 of x, v above (lat_mv2) */
    double *rk4;     /* RK4 (on first use): two trial states, 6 x np each, ax, av */
    double *trial[2][6], *ax[3], *av[3];
    void **bws;        /* temporal blocking (lattice_block_t.h): per-thread workspaces, */
    int nbws;          /* shared by the two precisions */
    size_t block_size; /* bytes in each */
    double *partial_k; /* per level and band: L_NSUMS */
    uint32_t npartial_k;
    spn__lat32 *f32; /* the float32 step (on first use) */
    double **cols;   /* per thread: COL_COUNT sum columns of col_stride doubles, zero between uses */
    int ncols;
    size_t col_stride;
    lat_gov gov;                /* below parallel_min: one thread or threads (lattice.c) */
    lat_gov passes;             /* on one thread: single steps or blocked passes (lattice.c) */
    lat_split split;            /* blocked passes on threads: the bands of each share */
    struct spn__lat_team *team; /* open for a spn_world_advance call (lattice_team.c), or NULL */
};

/* Where the world's slot s (ring j, radial i: s = j N + i) sits in slot
 * arrays of rows of `pitch`: j pitch + i (lat_slot: the float64 slots). */
static inline size_t lat_slot_in(const spn__lattice *L, size_t pitch, size_t s)
{
    return s / L->radials * pitch + s % L->radials;
}

static inline size_t lat_slot(const spn__lattice *L, size_t s) { return lat_slot_in(L, L->pitch, s); }

/* Band b's first row (b = nbands: the rings): the rings shared out as
 * evenly as whole rows go, the bands' sizes differing by one at most, so
 * that two threads taking half the bands each take half the rows (the 5k
 * web's 50 rings in eight bands: 6, 6, 7, 6, 6, 6, 6 and 7). */
static inline uint32_t lat_band_lo(const spn__lattice *L, uint32_t b)
{
    return (uint32_t)((uint64_t)b * L->rings / L->nbands);
}

/* The band row j belongs to: the last b with lat_band_lo(b) <= j. */
static inline uint32_t lat_band_of(const spn__lattice *L, uint32_t j)
{
    return (uint32_t)((((uint64_t)j + 1) * L->nbands - 1) / L->rings);
}

/* Row r of the world's particles (0: the hub alone; r > 0: ring r - 1):
 * its first index in the world's arrays, in a lattice state of rows of
 * `pitch` (lat_row: the float64 state's), and its count. */
static inline uint32_t lat_row_in(const spn__lattice *L, size_t pitch, uint32_t r, size_t *world, size_t *lat)
{
    *world = r ? 1 + (size_t)(r - 1) * L->radials : 0;
    *lat = r ? 1 + (size_t)(r - 1) * pitch : 0;
    return r ? L->radials : 1;
}

static inline uint32_t lat_row(const spn__lattice *L, uint32_t r, size_t *world, size_t *lat)
{
    return lat_row_in(L, L->pitch, r, world, lat);
}

/* What a sweep does with a row once its forces are complete. */
enum { MODE_EULER, MODE_SYMPLECTIC, MODE_RK4_STAGE, MODE_RK4_LAST };

typedef struct lat_args {
    const spn__lattice *L;
    const double *ex[3], *ev[3]; /* the state the forces are evaluated at */
    double *tx[3], *tv[3];       /* RK4 stage: the next trial state */
    const double *mass, *inv_mass;
    double g[3], drag, dt, h, weight;
    int mode;                    /* MODE_* above */
    int stage;                   /* RK4: the stage, 0-3 (MODE_RK4_LAST at 3) */
    bool kin_known;              /* RK4 without drag: m v^2 at the step's start is L->mv2 (LK(rk4_update)) */
} lat_args;

#define LK_T double
#define LK_U uint64_t
#define LK(name) name##64
#define LK_FMA fma /* a b + c, one rounding */
#define LK_SCRATCH 0
#include "lattice_rows_t.h"
#undef LK_SCRATCH
#undef LK_FMA
#undef LK_U
#undef LK
#undef LK_T

LAT_INLINE double lane_total(const double *acc)
{
    return ((acc[0] + acc[1]) + (acc[2] + acc[3])) + ((acc[4] + acc[5]) + (acc[6] + acc[7]));
}

/* Column set `set` of a thread's columns, or (set < 0) the cut's two. */
LAT_INLINE lat_cols col_set(double *cols, size_t stride, int set)
{
    lat_cols cs = {{NULL}, {NULL}, {NULL}};
    float *scr = (float *)(cols + ((size_t)COL_SETS * L_NSUMS + 2) * stride); /* after every double column */
    for (int k = 0; k < L_NSUMS; k++) cs.scr[k] = scr + (size_t)k * stride;
    for (int k = 0; k < 2; k++)
        cs.join[k] = scr + (size_t)(L_NSUMS + k) * stride;
    if (set < 0) {
        cs.c[L_ELASTIC] = cols + (size_t)COL_SETS * L_NSUMS * stride;
        cs.c[L_DAMP] = cs.c[L_ELASTIC] + stride;
        return cs;
    }
    for (int k = 0; k < L_NSUMS; k++) cs.c[k] = cols + ((size_t)set * L_NSUMS + k) * stride;
    return cs;
}

/* n float32 terms t added into a sum column c, term i into c[i], like the
 * float64 kernels' terms (col_take sums the whole column). Element by
 * element, not into eight running sums: those were a chain of dependent
 * additions, and GCC 12 left some of the inlined copies scalar and kept the
 * sums on the stack for the tail (i mod 8), about a fifth of the 5k web's
 * float32 symplectic step on a Zen 1 (docs/physics-lattice.md). */
LAT_INLINE void col_addf(double *restrict c, const float *restrict t, uint32_t n)
{
    for (uint32_t i = 0; i < n; i++) c[i] += (double)t[i];
}

/* A row's held radial terms h (n + 1 of them) and its ring terms t (n)
 * added into column c in one pass: (c[i] + h[i]) + t[i], the bits of
 * col_addf(c, h, n + 1) and then col_addf(c, t, n), with one load and store
 * of c fewer per term. */
LAT_INLINE void col_join(double *restrict c, const float *restrict h, const float *restrict t, uint32_t n)
{
    for (uint32_t i = 0; i < n; i++)
        c[i] = (c[i] + (double)h[i]) + (double)t[i];
    c[n] += (double)h[n];
}

/* The sum of column c[0 .. n) (in eight lanes, i mod 8, then lane_total),
 * the column zeroed for its next use, in the same loop. The lanes are eight
 * named sums: GCC 12 kept an array of them scalar (or in memory), and with
 * the memset after it this took 4.1% of a profile of the 1M web's float32
 * RK4 steps (bands of five rows of 1,000), against 2.1% now; float64
 * symplectic 2.0% -> 0.9% (a Zen 1, 2026-12-03). Same sums, same order. */
LAT_INLINE double col_take(double *restrict c, uint32_t n)
{
    double a0 = 0, a1 = 0, a2 = 0, a3 = 0, a4 = 0, a5 = 0, a6 = 0, a7 = 0;
    const uint32_t whole = n / LANES;
    for (uint32_t b = 0; b < whole; b++) {
        double *restrict p = c + (size_t)b * LANES;
        a0 += p[0], a1 += p[1], a2 += p[2], a3 += p[3], a4 += p[4], a5 += p[5], a6 += p[6], a7 += p[7];
        memset(p, 0, LANES * sizeof *p);
    }
    double acc[LANES] = {a0, a1, a2, a3, a4, a5, a6, a7};
    for (uint32_t i = whole * LANES; i < n; i++)
        acc[i % LANES] += c[i], c[i] = 0;
    return lane_total(acc);
}

/* Whether column c[0 .. n) holds only zeros (asserted of the columns a
 * level leaves alone). */
LAT_INLINE bool col_zero(const double *c, uint32_t n)
{
    for (uint32_t i = 0; i < n; i++)
        if (c[i] != 0) return false;
    return true;
}

/* Whether a sweep or a level of a blocked pass sums the springs' elastic
 * energy: RK4 reads it from its first stage only (lat_rk4_result), so its
 * other three stages leave it out (their L_ELASTIC sums stay 0). */
LAT_INLINE bool wants_elastic(int mode, int stage)
{
    return stage == 0 || (mode != MODE_RK4_STAGE && mode != MODE_RK4_LAST);
}

#define L_ALL_SUMS ((1u << L_NSUMS) - 1)

/* The sums (bit k: sum k) a step or RK4 stage of `mode` adds terms to;
 * the others' columns stay zero. An RK4 stage sums the elastic energy at
 * its first stage only (lat_rk4_result reads it there), m v^2 at the first
 * unless carried (kin_known), at every stage with drag, and at the last,
 * with the gain and the new kinetic energy (LK(rk4_update)). */
LAT_INLINE unsigned lat_sums_made(int mode, int stage, bool kin_known, bool drag)
{
    if (mode != MODE_RK4_STAGE && mode != MODE_RK4_LAST) return L_ALL_SUMS;
    unsigned m = 1u << L_DAMP;
    if (wants_elastic(mode, stage)) m |= 1u << L_ELASTIC;
    if ((stage == 0 && !kin_known) || drag || stage == 3) m |= 1u << L_MV2;
    if (stage == 3) m |= 1u << L_GAIN | 1u << L_MVN2;
    return m;
}

/* A band's sums into out (its L_NSUMS partials), from its columns (n
 * wide): the spring energy terms add to what the band's cut put there (the
 * first band has none), the particle terms are the band's own. Only the
 * sums in `made` (lat_sums_made) are taken: the others are zero, as
 * col_take would find them (+0, whose addition changes no bit), and a
 * column costs a pass over it, which at eight bands and four RK4 stages a
 * pass adds up. */
LAT_INLINE void store_band_sums(double *out, bool first, const lat_cols *cs, uint32_t n, unsigned made)
{
    if (first) out[L_ELASTIC] = out[L_DAMP] = 0;
    for (int k = 0; k < L_NSUMS; k++) {
        double v = 0;
        if (made >> k & 1)
            v = col_take(cs->c[k], n);
        else
            assert(col_zero(cs->c[k], n));
        if (k <= L_DAMP)
            out[k] += v;
        else
            out[k] = v;
    }
}

/* Springs j = 0..n-1 from (a[j]) to (b[j]), SoA: force on end a into f, the
 * elastic energy (when `elastic`, a constant in each call) and damping power
 * added into the sum columns ce, cp. The arithmetic of chunk_forces
 * (same bits): a spring is off (no force) at zero length or when slack and
 * tension-only, and then 1/len is replaced by 0 and k by 0, which is what
 * chunk_forces' 0/1 factors give, with selects instead of products. */
LAT_INLINE void springs(bool elastic, uint32_t n, const double *restrict axp, const double *restrict ayp,
                        const double *restrict azp, const double *restrict bxp, const double *restrict byp,
                        const double *restrict bzp, const double *restrict avx, const double *restrict avy,
                        const double *restrict avz, const double *restrict bvx, const double *restrict bvy,
                        const double *restrict bvz, const double *restrict kk, const double *restrict kkd,
                        const double *restrict rr, double *restrict fx, double *restrict fy, double *restrict fz,
                        double *restrict ce, double *restrict cp)
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
        const double k = pick64(on, kk[j], 0), kd = kkd[j];
        const double mag = k * stretch + kd * rate;
        const double s = -mag * inv;
        if (elastic) ce[j] += 0.5 * k * stretch * stretch;
        cp[j] += kd * rate * rate;
        fx[j] = s * lx, fy[j] = s * ly, fz[j] = s * lz;
    }
}

/* Springs from rows a to b of a state (3 arrays each, offsets off_a,
 * off_b) with parameters k, kd, rest, forces into f and sums into the
 * columns cs, both at off_f (the elastic energy if `elastic`). */
LAT_INLINE void springs_rows(uint32_t n, const double *const *ax, const double *const *av, const double *const *bx,
                             const double *const *bv, size_t off_a, size_t off_b, const double *k, const double *kd,
                             const double *rest, double *const *f, size_t off_f, const lat_cols *cs, bool elastic)
{
#define LAT_SPRINGS(elastic)                                                                                           \
    springs(elastic, n, ax[0] + off_a, ax[1] + off_a, ax[2] + off_a, bx[0] + off_b, bx[1] + off_b, bx[2] + off_b,      \
            av[0] + off_a, av[1] + off_a, av[2] + off_a, bv[0] + off_b, bv[1] + off_b, bv[2] + off_b, k, kd, rest,     \
            f[0] + off_f, f[1] + off_f, f[2] + off_f, cs->c[L_ELASTIC] + off_f, cs->c[L_DAMP] + off_f)
    if (elastic) LAT_SPRINGS(true);
    else LAT_SPRINGS(false);
#undef LAT_SPRINGS
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

/* The lattice's arrays (lattice_block.c). A zero-filled block of `count`
 * arrays of n elements of `size` bytes (a divisor of 64), each placed so
 * that its element `lead` starts a 64-byte line: lead 1 for particle
 * arrays, whose rows start at particle 1 + j * radials, 0 for spring slots
 * and row workspaces. *first is array 0, the next `*pitch` elements on (n
 * rounded up to a line); the block (to free()) is returned, NULL when out
 * of memory. With lead 0 array 0 is the block itself, and first and pitch
 * may be NULL. */
void *spn__lattice_arrays(size_t count, size_t n, size_t size, size_t lead, void **first, size_t *pitch);

/* Parallel work (lattice_team.c). A job is two phases run in `shares`
 * shares, first(ctx, share, thread) for every share, then (unless NULL)
 * then(ctx, share, thread) for every share; `thread` is the running
 * thread's number, below the thread count, for per-thread workspaces. */
typedef void (*spn__lat_job)(void *ctx, int share, int thread);
/* A job on up to `threads` threads: on L's team when one is open with that
 * many, else in an OpenMP region of its own (or in order on this thread,
 * for one). */
void spn__lat_run(const spn__lattice *L, int threads, int shares, spn__lat_job first, spn__lat_job then, void *ctx);
/* body(ctx, lo, hi) over [0, count) cut into `threads` contiguous chunks,
 * as a job of spn__lat_run. */
void spn__lat_for(const spn__lattice *L, int threads, size_t count, void (*body)(void *ctx, size_t lo, size_t hi),
                  void *ctx);

/* Temporal blocking (lattice_block_t.h, helpers in lattice_block.c). */
/* Whether K levels can go as one blocked pass on `threads` threads (each
 * thread's run of bands deep enough for its ghost rows). */
bool spn__lattice_block_ready(const spn__lattice *L, int threads, uint32_t K);
/* Per-thread workspaces of `bytes` each and the per-level band partials;
 * false when out of memory. */
bool spn__lattice_block_alloc(spn__lattice *L, int threads, size_t bytes);
/* Each of `threads` threads' sum columns (zeroed), for rows of L->radials;
 * false when out of memory. */
bool spn__lattice_cols_alloc(spn__lattice *L, int threads);
/* Each level's sums from its band partials, in band order. */
void spn__lattice_block_sums(const spn__lattice *L, uint32_t K, double sums[][L_NSUMS]);
/* The split of L's bands over `shares` shares ready (even, if the shares or
 * bands changed); false when out of memory. */
bool spn__lattice_split_ready(spn__lattice *L, int shares);
/* Share t's rows [*R0, *R1) under the split. */
void spn__lattice_split_rows(const spn__lattice *L, int t, uint32_t *R0, uint32_t *R1);
/* After a pass whose shares' fronts took split.took[t].ns: the rates, and
 * a new split where it would shorten the slowest share's part by more than
 * a few percent. */
void spn__lattice_split_update(spn__lattice *L);
/* The rows sent at the end of a pass (lat_split.sent_*): whether a pass of
 * K levels in numbers of `size` bytes may take its ghost rows from them;
 * after a pass on threads, that it sent them; after anything that moved
 * the state (each step, stage or pass, and each load or rebase), that
 * they are stale. */
bool spn__lattice_sent_ready(const spn__lattice *L, uint32_t K, size_t size);
void spn__lattice_sent(spn__lattice *L, uint32_t K, size_t size);
void spn__lattice_state_moved(spn__lattice *L);
/* `bytes` (a multiple of 16, both ends 16-byte aligned) from src to dst
 * past the caches where the processor can (non-temporal stores), then,
 * after the last of a thread's copies, the fence that orders them before
 * what it writes next. */
void spn__lattice_stream(void *restrict dst, const void *restrict src, size_t bytes);
void spn__lattice_stream_fence(void);
/* CLOCK_MONOTONIC in ns (a share's fronts are timed by it). */
double spn__lattice_clock_ns(void);
/* Whether float64 RK4 passes run their AVX2 version (lattice_block_t.h,
 * LK(runner)) on this processor; see lattice_block.c. */
bool spn__lattice_rk4_avx2(void);
/* Up to k float32 Euler or symplectic steps (mode), or one RK4 step, as one
 * blocked pass on `threads` threads (block ready); each step's results
 * into r[], the count done (0: none, nothing done). */
int spn__lat32_block_steps(spn_world *w, int threads, double dt, int mode, int k, spn__step_result *r);

#endif
