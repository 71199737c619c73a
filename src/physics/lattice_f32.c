/* The float32 lattice step: Euler, symplectic Euler (Mehla 2005, eq. 4.5)
 * and RK4 (eqs. 4.16-4.19) over a hub + rings x radials web, as lattice.c's
 * sweep, with the springs (eq. 4.14), the force assembly and the updates in
 * float32 from end to end (kernels in lattice_rows32.h).
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
 * The sweep is lattice.c's, from the same source (lattice_sweep_t.h): rows
 * swept outwards, the radials into a row computed from the previous row's
 * state before that row moves, bands fixed whatever the thread count, the
 * radials between bands first, sums added in band order. The rows are read
 * straight from the state arrays (no copies) and moved in place: a row
 * moves only after every spring that reads it has been computed. On big
 * webs, inside spn_world_advance, several steps (or an RK4 step's four
 * stages) go to one pass over memory as in float64, from the same source
 * again (lattice_block_t.h); a pass never spans a rebase, so its bits are
 * those of single steps. Every operation is a correctly rounded float32 or
 * float64 operation (the fused multiply-adds of the update are written out,
 * fmaf, one rounding each; the compiler fuses nothing else:
 * -ffp-contract=off; no approximate reciprocal), so the bits are the same
 * on any thread count and vector width. */
#include "lattice_rows32.h"
#include "world_internal.h"

#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Steps between two rebases of the float32 displacements onto w->x: a
 * displacement is then at most 64 v dt, and its round-off per step at most
 * 2^-24 of that, 4e-6 of one step's increment. */
#define REBASE 64u

/* A thread's workspace: lattice_rows.h's WS_* arrays, `stride` floats each. */

struct spn__lat32 {
    size_t np; /* the world's particles */
    /* Rows of `pitch` floats, the radials rounded up to whole 64-byte lines,
     * each starting a line (as the float64 state's, lattice_rows.h): world
     * particle 1 + j N + i is 1 + j pitch + i in the per-particle arrays
     * (nlat floats each), slot j N + i is j pitch + i (m floats each). */
    uint32_t pitch;
    size_t nlat, m;
    float *block, *slots; /* the per-particle and the per-slot arrays below */
    float *d[3], *u[3];   /* displacement from w->x [m] and velocity, per particle */
    float *mass, *inv_mass;
    float *rl[3], *gl[3]; /* reference differences of the radial and ring slots */
    float *rk, *rkd, *rr, *gk, *gkd, *gr;
    float *cut; /* per band: 3 rows of pitch, the radial forces into its first row */
    uint32_t ncut;
    float **ws;
    int nws;
    size_t stride;
    float *rk4;           /* RK4 (on first use): two trial states, 6 x nlat each, ax, av */
    float *trial[2][6];   /* trial displacement and velocity, by component */
    float *ax[3], *av[3]; /* weighted sums of the stages' velocities and forces */
    bool live;            /* the state above is ahead of w->x, w->v */
    bool params_ok;       /* rk .. gr match the lattice's float64 slots */
    uint32_t since;       /* steps since the last rebase */
    lat_mv2 mv2;          /* RK4 without drag: m v^2 of the state above (lat_mv2) */
};

typedef struct a32 {
    const spn__lattice *L;
    spn__lat32 *F;
    const float *ed[3], *eu[3]; /* the state the forces are evaluated at */
    float *td[3], *tu[3];       /* RK4 stage: the next trial state */
    float g[3], drag, dt, h, weight;
    int mode;                   /* MODE_* (lattice_rows.h) */
    int stage;                  /* RK4: the stage, 0-3 (MODE_RK4_LAST at 3) */
    bool kin_known;             /* RK4 without drag: m v^2 at the step's start is F->mv2 (LK(rk4_update)) */
} a32;

void spn__lat32_free(spn__lat32 *F)
{
    if (!F) return;
    for (int t = 0; t < F->nws; t++) free(F->ws[t]);
    free(F->ws), free(F->cut), free(F->block), free(F->slots), free(F->rk4);
    free(F);
}

/* ---- the sweep ---- */

/* Row p0 of the evaluated state. */
LAT_INLINE void eval_rows(const a32 *a, size_t p0, float **D, float **U)
{
    for (int c = 0; c < 3; c++) D[c] = (float *)a->ed[c] + p0, U[c] = (float *)a->eu[c] + p0;
}

/* Particles p0 .. p0+n-1 of an RK4 stage, their force F (3 arrays) known
 * (n: the hub's 1 or a row's padded length, LK(rk4_update)). */
LAT_INLINE void rk4_update(const a32 *a, size_t p0, uint32_t n, float *const *F,
                           const lat_cols *cs)
{
    const spn__lat32 *S = a->F;
    rk4_rows32 R;
    for (int c = 0; c < 3; c++) {
        R.V[c] = a->eu[c] + p0, R.xb[c] = S->d[c] + p0, R.vb[c] = S->u[c] + p0;
        R.xt[c] = a->td[c] ? a->td[c] + p0 : NULL, R.vt[c] = a->tu[c] ? a->tu[c] + p0 : NULL;
        R.ax[c] = S->ax[c] + p0, R.av[c] = S->av[c] + p0;
    }
    rk4_update32(n, a->stage, a->h, a->weight, a->drag, a->kin_known, a->g, S->mass + p0, S->inv_mass + p0, &R, F, cs);
}

LAT_INLINE void finish32(const a32 *a, size_t p0, uint32_t n, float *const *ri, float *const *rg,
                         float *const *ro, float *const *Fw, const lat_cols *cs)
{
    const spn__lat32 *F = a->F;
    if (a->mode == MODE_RK4_STAGE || a->mode == MODE_RK4_LAST) {
        for (int c = 0; c < 3; c++)
            assemble32(n, a->g[c], a->drag, F->mass + p0, a->eu[c] + p0, ri[c], rg[c], ro ? ro[c] : NULL, Fw[c]);
        rk4_update(a, p0, padded32(n), Fw, cs);
        return;
    }
    float *D[3], *U[3];
    for (int c = 0; c < 3; c++) D[c] = F->d[c] + p0, U[c] = F->u[c] + p0;
    row_move32(n, a->mode == MODE_SYMPLECTIC, a->dt, a->g, a->drag, F->mass + p0, F->inv_mass + p0, D, U, ri, rg,
               ro, cs);
}

/* The hub: its radial forces in radial order, then its update. */
static void hub32(const a32 *a, float *const *rad, const lat_cols *cs)
{
    spn__lat32 *F = a->F;
    const uint32_t n = a->L->radials;
    if (a->mode != MODE_RK4_STAGE && a->mode != MODE_RK4_LAST) {
        hub_move32(n, a->mode == MODE_SYMPLECTIC, a->dt, a->g, a->drag, F->mass[0], F->inv_mass[0], F->d, F->u, rad,
                   cs);
        return;
    }
    const float v[3] = {a->eu[0][0], a->eu[1][0], a->eu[2][0]};
    float f[3], *Fp[3] = {f, f + 1, f + 2};
    hub_force32(false, n, F->mass[0], a->drag, a->g, v, rad, f);
    rk4_update(a, 0, 1, Fp, cs);
}

/* The sweep (lattice_sweep_t.h) on the float32 state: a spring's
 * difference is its slot's reference difference plus the displacements'. */
LAT_INLINE void radials32(const a32 *a, float *const *Da, float *const *Ua, float *const *Db, float *const *Ub,
                          uint32_t j, float *const *f, const lat_cols *cs, bool hold)
{
    const spn__lat32 *F = a->F;
    /* (over the padding too: padded32, lattice_rows_t.h) */
    spring_rows(padded32(a->L->radials), Da, Ua, Db, Ub, (float *const *)F->rl, (size_t)j * F->pitch, F->rk, F->rkd,
                F->rr, f, 0, cs, wants_elastic(a->mode, a->stage), hold ? SUMS_HOLD : SUMS_ADD);
}

LAT_INLINE void rings32(const a32 *a, float *const *D, float *const *U, uint32_t j, float *const *f, const lat_cols *cs,
                        bool held)
{
    const spn__lat32 *F = a->F;
    const uint32_t n = a->L->radials;
    const size_t s0 = (size_t)j * F->pitch;
    float *D1[3], *U1[3], *Dl[3], *Ul[3]; /* the row from its second and its last particle */
    for (int c = 0; c < 3; c++) D1[c] = D[c] + 1, U1[c] = U[c] + 1, Dl[c] = D[c] + n - 1, Ul[c] = U[c] + n - 1;
    const bool el = wants_elastic(a->mode, a->stage);
    spring_rows(n - 1, D, U, D1, U1, (float *const *)F->gl, s0, F->gk, F->gkd, F->gr, f, 0, cs, el,
                held ? SUMS_JOIN : SUMS_ADD);
    spring_rows(1, D, U, Dl, Ul, (float *const *)F->gl, s0 + n - 1, F->gk, F->gkd, F->gr, f, n - 1, cs, el, SUMS_ADD);
}

LAT_INLINE void hub_state32(const a32 *a, float *x, float *v)
{
    for (int c = 0; c < 3; c++) x[c] = a->ed[c][0], v[c] = a->eu[c][0];
}

static float *cut32(const a32 *a, uint32_t b, int c) { return a->F->cut + ((size_t)b * 3 + (size_t)c) * a->F->pitch; }
static size_t pitch32(const a32 *a) { return a->F->pitch; }
static float *ws32(const a32 *a, int thread) { return a->F->ws[thread]; }
static size_t stride32(const a32 *a) { return a->F->stride; }

#define LK_T float
#define LK(name) name##32
#define LK_ARGS a32
#define eval32 eval_rows
#include "lattice_sweep_t.h"
#undef eval32

/* The blocked pass (lattice_block_t.h) on the float32 state. */
static void state32(const a32 *a, float **D, float **U)
{
    for (int c = 0; c < 3; c++) D[c] = a->F->d[c], U[c] = a->F->u[c];
}

static const float *mass32(const a32 *a) { return a->F->mass; }
static const float *inv_mass32(const a32 *a) { return a->F->inv_mass; }

#include "lattice_block_t.h"
#undef LK_ARGS
#undef LK
#undef LK_T

/* ---- state: load, reference differences, write-back ---- */

/* The reference differences x_a - x_b of every slot, from w->x. */
static void reference_rows(void *ctx, size_t lo, size_t hi)
{
    const spn_world *w = ctx;
    const spn__lattice *L = w->lat;
    spn__lat32 *F = L->f32;
    const uint32_t n = L->radials;
    const spn_vec3 *x = w->x;
    for (uint32_t j = (uint32_t)lo; j < hi; j++) {
        const size_t s0 = (size_t)j * F->pitch, p0 = 1 + (size_t)j * n; /* slots; the world's row */
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

static void references(spn_world *w, int threads) { spn__lat_for(w->lat, threads, w->lat->rings, reference_rows, w); }

/* write_back's arguments, for its job. */
typedef struct {
    spn_world *w;
    bool rebase;
} write_job;

/* Rows [lo, hi) (lat_row_in) of the float32 state into the world's. */
static void write_rows(void *ctx, size_t lo, size_t hi)
{
    const write_job *j = ctx;
    const spn__lattice *L = j->w->lat;
    spn__lat32 *F = L->f32;
    spn_vec3 *x = j->w->x, *v = j->w->v;
    for (uint32_t r = (uint32_t)lo; r < hi; r++) {
        size_t to, from;
        const uint32_t count = lat_row_in(L, F->pitch, r, &to, &from);
        for (uint32_t k = 0; k < count; k++) {
            const size_t i = to + k, q = from + k;
            x[i].x += (double)F->d[0][q], x[i].y += (double)F->d[1][q], x[i].z += (double)F->d[2][q];
            v[i] = spn_v3(F->u[0][q], F->u[1][q], F->u[2][q]);
            if (j->rebase) F->d[0][q] = F->d[1][q] = F->d[2][q] = 0;
        }
    }
}

/* d into w->x (in float64), u into w->v; with `rebase`, d starts again from
 * zero and the references follow w->x. */
static void write_back(spn_world *w, int threads, bool rebase)
{
    spn__lat32 *F = w->lat->f32;
    write_job job = {w, rebase};
    spn__lat_for(w->lat, threads, (size_t)w->lat->rings + 1, write_rows, &job);
    if (rebase) references(w, threads);
    spn__lattice_state_moved(w->lat); /* (a rebase moves d to zero) */
    F->since = 0;
    F->live = rebase;
}

static bool alloc_state(spn__lattice *L, size_t np)
{
    const uint32_t rp = padded32(L->radials);
    const size_t m = (size_t)L->rings * rp, nlat = 1 + m;
    if (L->f32 && L->f32->np == np) return true;
    spn__lat32_free(L->f32);
    spn__lat32 *F = L->f32 = calloc(1, sizeof *F);
    void *first, *sfirst;
    size_t pitch, spitch;
    if (!F || !(F->block = spn__lattice_arrays(8, nlat, sizeof(float), 1, &first, &pitch)) ||
        !(F->slots = spn__lattice_arrays(12, m, sizeof(float), 0, &sfirst, &spitch)))
        return false;
    F->np = np, F->pitch = rp, F->nlat = nlat, F->m = m;
    float *q = first;
    for (int c = 0; c < 3; c++)
        F->d[c] = q, q += pitch, F->u[c] = q, q += pitch;
    F->mass = q, q += pitch, F->inv_mass = q;
    q = sfirst;
    for (int c = 0; c < 3; c++)
        F->rl[c] = q, q += spitch, F->gl[c] = q, q += spitch;
    float **par[6] = {&F->rk, &F->rkd, &F->rr, &F->gk, &F->gkd, &F->gr};
    for (int k = 0; k < 6; k++)
        *par[k] = q, q += spitch;
    return true;
}

/* Rows [lo, hi) (lat_row_in): masses and velocities rounded, displacements
 * zero. */
static void load_rows(void *ctx, size_t lo, size_t hi)
{
    const spn_world *w = ctx;
    const spn__lattice *L = w->lat;
    spn__lat32 *F = L->f32;
    const spn_vec3 *v = w->v;
    const double *mass = w->mass, *inv_mass = w->inv_mass;
    for (uint32_t r = (uint32_t)lo; r < hi; r++) {
        size_t from, to;
        const uint32_t count = lat_row_in(L, F->pitch, r, &from, &to);
        for (uint32_t k = 0; k < count; k++) {
            const size_t i = from + k, q = to + k;
            F->mass[q] = (float)mass[i], F->inv_mass[q] = (float)inv_mass[i];
            F->d[0][q] = F->d[1][q] = F->d[2][q] = 0;
            F->u[0][q] = (float)v[i].x, F->u[1][q] = (float)v[i].y, F->u[2][q] = (float)v[i].z;
        }
    }
}

/* The float32 state from the world's: d = 0, u = v, the spring constants
 * and masses rounded, the references. */
static bool load(spn_world *w, int threads)
{
    spn__lattice *L = w->lat;
    if (!alloc_state(L, w->np)) return false;
    spn__lat32 *F = L->f32;
    if (!F->params_ok)
        for (size_t s = 0; s < (size_t)L->rings * L->radials; s++) {
            const size_t d = lat_slot(L, s), e = lat_slot_in(L, F->pitch, s);
            F->rk[e] = (float)L->rk[d], F->rkd[e] = (float)L->rkd[d], F->rr[e] = (float)L->rrest[d];
            F->gk[e] = (float)L->gk[d], F->gkd[e] = (float)L->gkd[d], F->gr[e] = (float)L->grest[d];
        }
    F->params_ok = true;
    spn__lat_for(L, threads, (size_t)L->rings + 1, load_rows, w);
    references(w, threads);
    spn__lattice_state_moved(L);
    F->since = 0;
    F->live = true;
    F->mv2.ok = false;
    return true;
}

/* Per-thread workspaces and the cut for this step's bands. */
static bool prepare32(spn__lattice *L, int threads)
{
    spn__lat32 *F = L->f32;
    if (F->ncut != L->nbands) {
        free(F->cut);
        F->ncut = 0;
        if (!(F->cut = spn__lattice_arrays((size_t)L->nbands * 3, F->pitch, sizeof *F->cut, 0, NULL, NULL)))
            return false;
        F->ncut = L->nbands;
    }
    if (F->nws < threads) {
        float **ws = realloc(F->ws, (size_t)threads * sizeof *ws);
        if (!ws) return false;
        F->ws = ws;
        F->stride = padded32(L->radials);
        for (; F->nws < threads; F->nws++)
            if (!(F->ws[F->nws] = spn__lattice_arrays(WS_COUNT, F->stride, sizeof **F->ws, 0, NULL, NULL)))
                return false;
    }
    return spn__lattice_cols_alloc(L, threads);
}

/* The float32 state ready for a step (loaded unless a call already holds
 * it), the workspaces and, for RK4, its arrays; the step's arguments in a.
 * False, with w->x and w->v up to date, when out of memory. */
static bool begin(spn_world *w, int threads, double dt, bool rk4, a32 *a)
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
    if (rk4 && !F->rk4) {
        void *first;
        size_t pitch;
        if (!(F->rk4 = spn__lattice_arrays(18, F->nlat, sizeof(float), 1, &first, &pitch))) {
            spn__lattice_sync(w);
            return false;
        }
        float *q = first;
        for (int k = 0; k < 6; k++)
            F->trial[0][k] = q + k * pitch, F->trial[1][k] = q + (6 + k) * pitch;
        for (int c = 0; c < 3; c++)
            F->ax[c] = q + (12 + c) * pitch, F->av[c] = q + (15 + c) * pitch;
    }
    if (!prepare32(L, threads)) {
        spn__lattice_sync(w);
        return false;
    }
    memset(a, 0, sizeof *a);
    a->L = L, a->F = F;
    a->g[0] = (float)w->def.gravity.x, a->g[1] = (float)w->def.gravity.y, a->g[2] = (float)w->def.gravity.z;
    a->drag = (float)w->def.drag, a->dt = (float)dt;
    for (int c = 0; c < 3; c++) a->ed[c] = F->d[c], a->eu[c] = F->u[c];
    return true;
}

/* Before an RK4 step: whether its first stage can take m v^2 from the step
 * before (lattice_rows_t.h, LK(rk4_update)). A debug build checks the
 * carried sum against the state (to float32's round-off: the carry is
 * meant to be bit-exact, but a stale one is what this would catch). */
static bool mv2_known(const spn_world *w)
{
    const spn__lat32 *F = w->lat->f32;
    if (!F->mv2.ok || w->def.drag != 0) return false;
#ifndef NDEBUG
    double mv2 = 0;
    for (size_t i = 0; i < F->nlat; i++) /* (the rows' padding: inv_mass 0) */
        if (F->inv_mass[i] != 0)
            mv2 += (double)F->mass[i] * ((double)F->u[0][i] * F->u[0][i] + (double)F->u[1][i] * F->u[1][i] +
                                         (double)F->u[2][i] * F->u[2][i]);
    assert(fabs(mv2 - F->mv2.sum) <= 1e-4 * mv2 + 1e-300);
#endif
    return true;
}

/* After a step: rebase every REBASE steps, write back after a step with a
 * backup (spn_world_step, or a run that does not replay). */
static void end(spn_world *w, int threads)
{
    spn__lat32 *F = w->lat->f32;
    if (++F->since >= REBASE || !w->no_backup) write_back(w, threads, w->no_backup);
}

bool spn__lat32_explicit(spn_world *w, int threads, double dt, bool symplectic, spn__step_result *r)
{
    a32 a;
    if (!begin(w, threads, dt, false, &a)) return false;
    a.mode = symplectic ? MODE_SYMPLECTIC : MODE_EULER;
    w->lat->f32->mv2.ok = false;
    double sum[L_NSUMS];
    sweep32(&a, threads, sum);
    spn__lattice_state_moved(w->lat);
    lat_explicit_result(sum, dt, w->def.drag, r);
    end(w, threads);
    return true;
}

/* RK4 as lattice.c's: four sweeps, stage s evaluated at the trial state of
 * stage s - 1 and writing the next one into the other trial array. */
bool spn__lat32_rk4(spn_world *w, int threads, double dt, spn__step_result *r)
{
    a32 a;
    if (!begin(w, threads, dt, true, &a)) return false;
    spn__lat32 *F = w->lat->f32;
    static const float weight[4] = {1, 2, 2, 1}, frac[4] = {0, 0.5f, 0.5f, 1};
    double sums[4][L_NSUMS];
    const bool known = mv2_known(w);
    a.kin_known = known;
    for (int stage = 0; stage < 4; stage++) {
        float *const *from = F->trial[(stage + 1) % 2], *const *to = F->trial[stage % 2];
        for (int c = 0; c < 3; c++) {
            a.ed[c] = stage ? from[c] : F->d[c], a.eu[c] = stage ? from[3 + c] : F->u[c];
            a.td[c] = to[c], a.tu[c] = to[3 + c];
        }
        a.mode = stage < 3 ? MODE_RK4_STAGE : MODE_RK4_LAST;
        a.stage = stage;
        a.weight = weight[stage];
        a.h = stage < 3 ? frac[stage + 1] * (float)dt : (float)dt / 6;
        sweep32(&a, threads, sums[stage]);
    }
    spn__lattice_state_moved(w->lat);
    lat_mv2_carry(&F->mv2, known, sums);
    lat_rk4_result(sums, dt, w->def.drag, r);
    end(w, threads);
    return true;
}

/* Blocked passes (lattice_block_t.h; lattice.c decides when). A pass never
 * spans a rebase: the rebase changes the references the springs are formed
 * from, so the steps of a pass are the single steps' only if they all come
 * between the same two rebases, after the same number of steps. */
int spn__lat32_block_steps(spn_world *w, int threads, double dt, int mode, int k, spn__step_result *r)
{
    const bool rk4 = mode == MODE_RK4_STAGE || mode == MODE_RK4_LAST;
    const spn__lat32 *F0 = w->lat->f32;
    if (!rk4 && F0 && F0->live && k > (int)(REBASE - F0->since)) k = (int)(REBASE - F0->since);
    const uint32_t levels = rk4 ? 4 : (uint32_t)k;
    a32 la[LAT_LEVELS];
    if (levels < 2 || !begin(w, threads, dt, false, &la[0])) return 0;
    const bool known = rk4 && mv2_known(w);
    la[0].kin_known = known;
    static const float weight[4] = {1, 2, 2, 1}, frac[4] = {0, 0.5f, 0.5f, 1};
    for (uint32_t s = 0; s < levels; s++) {
        la[s] = la[0];
        la[s].mode = rk4 ? (s < 3 ? MODE_RK4_STAGE : MODE_RK4_LAST) : mode;
        la[s].stage = rk4 ? (int)s : 0;
        la[s].weight = weight[s % 4];
        la[s].h = s < 3 ? frac[s + 1] * (float)dt : (float)dt / 6;
    }
    double sums[LAT_LEVELS][L_NSUMS];
    if (!block_pass32(w->lat, la, rk4, threads, levels, sums)) return 0;
    const int steps = rk4 ? 1 : k;
    spn__lat32 *F = w->lat->f32;
    if (rk4) {
        lat_mv2_carry(&F->mv2, known, sums);
        lat_rk4_result(sums, dt, w->def.drag, &r[0]);
    } else {
        F->mv2.ok = false;
        for (int q = 0; q < k; q++)
            lat_explicit_result(sums[q], dt, w->def.drag, &r[q]);
    }
    F->since += (uint32_t)steps;
    if (F->since >= REBASE) write_back(w, threads, true); /* (as `end` after the pass's last step) */
    return steps;
}

void spn__lat32_sync(spn_world *w)
{
    if (w->lat && w->lat->f32 && w->lat->f32->live) write_back(w, spn__threads(w, w->np), false);
}

bool spn__lat32_live(const spn__lat32 *F) { return F && F->live; }

void spn__lat32_params_changed(spn__lat32 *F)
{
    if (F) F->params_ok = false;
}

void spn__lat32_discard(spn__lat32 *F)
{
    if (F) F->live = false;
}

void spn_world_set_precision(spn_world *w, spn_precision precision)
{
    spn__lattice_sync(w);
    w->precision = precision == SPN_PRECISION_FLOAT32 ? SPN_PRECISION_FLOAT32 : SPN_PRECISION_FLOAT64;
}

spn_precision spn_world_precision(const spn_world *w) { return (spn_precision)w->precision; }
