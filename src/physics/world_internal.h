/* The spring world's private layout. Particle and spring fields live in
 * separate flat arrays (structure of arrays): the stepping loops read only the
 * hot ones (positions, velocities, inverse masses, spring ends, stiffness,
 * rest lengths). A CSR adjacency (particle -> incident springs, in spring id
 * order) lets forces be gathered per particle without atomics, so each sum is
 * done in a fixed order and the result is the same with any thread count.
 *
 * Reductions (energies, dot products) are summed per block of SPN_BLOCK items
 * into a partial array, then the partials are added serially in block order:
 * the blocks do not depend on the number of threads, so neither do the bits. */
#ifndef SPN_WORLD_INTERNAL_H
#define SPN_WORLD_INTERNAL_H

#include "spinneret/world.h"

#include "core/kernel.h"

#include <math.h>

#ifdef _OPENMP
#include <omp.h>
#endif

/* The calling thread's number in its OpenMP team (0 without OpenMP). */
static inline int spn__thread_num(void)
{
#ifdef _OPENMP
    return omp_get_thread_num();
#else
    return 0;
#endif
}

/* The size of the calling thread's OpenMP team (1 without OpenMP). */
static inline int spn__thread_count(void)
{
#ifdef _OPENMP
    return omp_get_num_threads();
#else
    return 1;
#endif
}

#define SPN_SPRING_TENSION_ONLY 1u
#define SPN_SPRING_BROKEN 2u

/* Items per reduction block; fixed so sums do not depend on the thread count. */
#define SPN_BLOCK 1024u
/* Partial sums kept per block. */
#define SPN_NSUMS 6
/* Particles a batch air function samples in one call at most (forces.c):
 * a share of the threads' work. */
#define SPN__AIR_RUN 512u

/* Per-particle scratch buffers, allocated on first use (see spn__scratch). */
enum {
    SPN_TMP_A, SPN_TMP_B, SPN_TMP_C, SPN_TMP_D, SPN_TMP_E, SPN_TMP_F, SPN_TMP_G,
    SPN_TMP_COUNT
};

typedef struct spn_collider {
    int kind;   /* 0 plane, 1 sphere */
    spn_vec3 p; /* plane normal or sphere centre */
    double d;   /* plane offset (n.x = d on the plane) or sphere radius */
    double restitution, friction;
} spn_collider;

/* Silk hysteresis of one thread kind (hysteresis.c). */
typedef struct spn_tag_hysteresis {
    uint32_t tag;
    double eta, rate0;
} spn_tag_hysteresis;

typedef struct spn_tag_diameter {
    uint32_t tag;
    double diameter;
} spn_tag_diameter;

/* The hot fields of one spring, in the compiled (internal) order: 32 bytes.
 * The top bit of `bt` is the tension-only flag (read it with spn__end_b /
 * spn__tension_only), and a broken spring has k = kd = 0 here (its public k
 * and kd are kept), so the force loop needs no flag array. Particles are
 * therefore limited to 2^31 - 1. */
/* A hub + rings x radials web recognised at compile time (lattice.c). */
typedef struct spn__lattice spn__lattice;

typedef struct spn__spring {
    uint32_t a;
    uint32_t bt; /* end b | tension-only << 31 (named apart so a plain `.b` does not compile) */
    double k, kd, rest;
} spn__spring;

#define SPN__END_MASK 0x7fffffffu
static inline uint32_t spn__end_b(spn__spring s) { return s.bt & SPN__END_MASK; }
static inline bool spn__tension_only(spn__spring s) { return (s.bt >> 31) != 0; }

/* A spring's energy change 1/2 k (e1^2 - e0^2) as its extension goes from e0
 * to e1, as a product so a small move is not lost to cancellation; de is
 * e1 - e0, taken by the caller as exactly as it can. A tension-only spring
 * stores nothing while slack. The equilibrium's line search and the implicit
 * step's energy limit both use it. */
static inline double spn__spring_energy_change(double k, bool tension_only, double e0, double e1, double de)
{
    if (tension_only && !(e0 > 0 && e1 > 0)) {
        e0 = e0 > 0 ? e0 : 0;
        e1 = e1 > 0 ? e1 : 0;
        de = e1 - e0;
    }
    return 0.5 * k * de * (e1 + e0);
}

/* What one force evaluation measured at its state (x, v). */
typedef struct spn__eval {
    double elastic;     /* sum 1/2 k stretch^2 (intact, non-slack springs) */
    double kinetic;     /* sum 1/2 m v^2 over free particles */
    double damp_power;  /* power removed by spring damping and viscous drag [W] */
    double ext_power;   /* power of external forces (callback + air), sum fext . v */
} spn__eval;

/* Implicit Euler's per-spring Jacobian data (see implicit.c). */
typedef struct spn__jac {
    spn_vec3 u;    /* unit direction a - b */
    double axial;  /* coefficient of u (u . d) */
    double iso;    /* coefficient of d (transverse stiffness, kept >= 0) */
    double air;    /* air-drag velocity coupling, applied to p_a + p_b */
} spn__jac;

struct spn_world {
    spn_world_def def;

    /* particles */
    uint32_t np, cap_p;
    spn_vec3 *x, *v;
    double *mass, *inv_mass;
    uint32_t *ptag;

    /* springs */
    uint32_t ns, cap_s;
    uint32_t *sa, *sb;
    double *k, *kd, *rest, *bmin, *bmax;
    uint8_t *sflags;
    uint32_t *stag, *sstage, *sorder;

    /* compiled data: valid while `compiled`. Springs are stepped in an
     * internal order, sorted by their lower particle id (so consecutive
     * springs touch nearby particles); perm / iperm map between internal and
     * public ids, and everything indexed per spring below (fs, jac, ...) is
     * in internal order. The public arrays above stay the reference; the
     * setters write both. */
    bool compiled;
    spn__spring *hs;      /* hot spring records, internal order */
    uint8_t *hflags;      /* spring flags, internal order */
    uint32_t *perm;       /* internal -> public spring id */
    uint32_t *iperm;      /* public -> internal spring id */
    uint32_t *adj_start;  /* np + 1 */
    uint32_t *adj;        /* spring id << 1 | (1 if the particle is end b) */
    uint32_t *a_start;    /* np + 1: internal end a is the lower particle id, so particle i's
                           * springs as end a are the contiguous run [a_start[i], a_start[i+1]) */
    uint32_t *b_start;    /* np + 1, into b_adj */
    uint32_t *b_adj;      /* springs with the particle as end b, internal order */
    spn_vec3 *fs;         /* per-spring force on end a (scratch) */
    double *sdiam;        /* per-spring diameter for air drag */
    bool any_diam;        /* some spring has a diameter */
    bool any_limits;      /* some spring has a break length */
    double free_mass;     /* total mass of the free particles */
    spn_vec3 *f, *fext;   /* per-particle total and external force */
    spn_vec3 *x0, *v0;    /* state before the step (restored on blow-up) */
    bool no_backup;       /* explicit and RK4 steps leave x0, v0 alone (spn_world_advance) */
    /* the fused explicit sweep (sweep.c), built on first use */
    uint32_t sweep_block;            /* particles per block (0: not built) */
    uint32_t *xout_start, *xout;     /* per block: springs whose end b is in a later block */
    uint32_t *xin_start, *xin;       /* per block: springs whose end b is in it, end a before it */
    spn_vec3 *facc;                  /* per-particle spring force accumulator */
    spn__lattice *lat;               /* the stencil step of a regular orb web (NULL: none) */
    bool lattice_off;                /* spn_world_set_lattice(w, false) */
    bool lattice_unblocked;          /* spn__lattice_set_unblocked (tests) */
    bool lattice_passes_held;        /* spn__lattice_hold_passes (tests) */
    uint8_t precision;               /* spn_precision: float32 lattice steps when set */
    spn_vec3 *tmp[SPN_TMP_COUNT]; /* per-particle scratch, allocated on demand */
    spn_vec3 *fair;       /* per-spring air force (on demand) */
    spn_vec3 *wind;       /* air velocity at each particle that ends a segment with a diameter (on demand) */
    uint32_t *air_runs;   /* those particles: runs (first, last + 1), in pieces of SPN__AIR_RUN */
    uint32_t nair_runs;
    float *air_held;         /* spn_world_set_air_resolution: the particles' cells q, 3 np numbers (the
                              * air taken at (q + 1/2) spacing), the air there at the interval's start
                              * a and at its end b, 3 np each (on demand) */
    double air_held_k;       /* the interval (t / air_interval, floored) air_held's samples are of; NAN: none */
    double *cair;         /* per-spring linear air-drag coefficient (on demand) */
    spn__jac *jac;        /* implicit: per-spring Jacobian (on demand) */
    double *pblock;       /* implicit: per-particle diagonal 3x3 block of A, 6 each (on demand) */
    double *pinv;         /* implicit: their inverses where block Jacobi is wanted (spn__implicit_invert) */
    struct spn__imp_mg *imp_mg; /* implicit: the multigrid preconditioner (implicit_mg.c, on demand) */
    uint32_t imp_refuse;  /* spn__imp_mg_refuse (tests) */
    uint8_t imp_refuse_pc; /* spn__imp_mg_refuse_setup (tests) */
    uint8_t implicit_pc;  /* implicit preconditioner: 0 auto, 1 block Jacobi, 2 multigrid, 3 cyclic */
    double imp_bj_long;   /* auto: the shortest step at which block Jacobi took more than
                           * SPN__IMPLICIT_BJ_MAX CG iterations (0: none yet); from it up, the multigrid */
    uint8_t energy_limit; /* implicit: which steps may not create energy (spn_energy_limit) */
    double *partial;      /* SPN_NSUMS per block */
    uint32_t npartial;    /* blocks the partial array holds */

    /* time and statistics */
    double t;
    uint64_t steps;
    spn_step_report last;
    double external_work, dissipated;
    double adaptive_dt;   /* next sub-step the adaptive stepper tries (0: the outer step) */
    double adaptive_floor; /* the adaptive stepper's floor in its last outer step (adaptive.c) */

    /* callbacks */
    spn_force_fn force_fn;
    void *force_user;
    spn_break_fn break_fn;
    void *break_user;
    spn_collide_fn collide_fn;
    void *collide_user;
    spn_air_fn air_fn;
    spn_air_batch_fn air_batch; /* NULL: a call of air_fn a segment */
    void *air_user;
    double air_rho, air_mu;
    bool air_pure;      /* air_fn may be called from several threads (spn_world_set_air_pure) */
    double air_interval, air_spacing; /* spn_world_set_air_resolution (0: every sample exact) */
    spn_tag_diameter *diam;
    uint32_t ndiam;

    spn_collider *colliders;
    uint32_t ncolliders;

    /* silk hysteresis per tag (hysteresis.c) and the implicit solver's
     * contacts (contact.c); a clone copies the first, not the second */
    spn_tag_hysteresis *hyst;
    uint32_t nhyst;
    spn_contact *contacts;
    uint32_t ncontacts, cap_contacts;

    char *metadata;
};

/* ---- compile.c ---- */

/* Free every compiled array (the world goes back to construction mode). */
void spn__free_compiled(spn_world *w);
/* Clear every compiled-array pointer without freeing (after freeing them, or
 * in a copy whose pointers still alias the original's). One list for both. */
void spn__forget_compiled(spn_world *w);
/* Public spring s's hot record (flags folded in, see spn__spring). */
spn__spring spn__hot_spring(const spn_world *w, uint32_t s);
/* For tests: particle i's position and velocity and spring s's rest length
 * written without the setters' checks (an index out of range: that part
 * left), to plant a value no public route makes, a NaN, and test the
 * refusal of a writer or solve that reads it. */
void spn__world_plant(spn_world *w, uint32_t i, spn_vec3 x, spn_vec3 v, uint32_t s, double rest);

/* ---- forces.c ---- */

/* Threads for a loop over n items (1 below def.parallel_min). */
int spn__threads(const spn_world *w, uint32_t n);
/* The world's settings (spn_world_def) checked, each field in its range;
 * SPN_ERR_INVALID naming the first that is not (spn_world_compile calls
 * it: spn_world_create keeps whatever it is given). */
spn_status spn__check_settings(const spn_world_def *d);
/* Ensure the first `count` per-particle scratch buffers exist. */
spn_status spn__scratch(spn_world *w, int count);
/* Sum the SPN_NSUMS partials of `blocks` blocks in block order into out[]. */
void spn__sum_partials(const spn_world *w, uint32_t blocks, double *out);
/* Spring record `from` into slot `to` (to <= from: compacting the list),
 * its ends renumbered to a, b. */
static inline void spn__move_spring(spn_world *w, uint32_t from, uint32_t to, uint32_t a, uint32_t b)
{
    w->sa[to] = a, w->sb[to] = b;
    w->k[to] = w->k[from], w->kd[to] = w->kd[from], w->rest[to] = w->rest[from];
    w->bmin[to] = w->bmin[from], w->bmax[to] = w->bmax[from];
    w->sflags[to] = w->sflags[from], w->stag[to] = w->stag[from];
    w->sstage[to] = w->sstage[from], w->sorder[to] = w->sorder[from];
}

static inline uint32_t spn__blocks(uint32_t n) { return (n + SPN_BLOCK - 1) / SPN_BLOCK; }

/* True when air drag acts on some segment. */
bool spn__air_active(const spn_world *w);
/* Spring pass at (x, v): w->fs per spring (and w->fair with air); returns the
 * elastic energy and the spring damping power through `e`. */
void spn__spring_pass(spn_world *w, double t, const spn_vec3 *x, const spn_vec3 *v, spn__eval *e);
/* The external forces at (x, v) into w->fext: the user callback, then air
 * (the air part needs spn__spring_pass first). False when there are none. */
bool spn__external(spn_world *w, double t, const spn_vec3 *x, const spn_vec3 *v);
/* spn__external without the air's half forces on the ends: w->fext holds
 * the force callback's (zeros without one); the caller adds the air's
 * (spn__air_on) in spn__external's order. */
bool spn__external_user(spn_world *w, double t, const spn_vec3 *x, const spn_vec3 *v);
/* Gather the total force on every particle into f: gravity, viscous drag,
 * springs (w->fs), w->fext when `has_ext`. Adds kinetic energy, drag power and
 * external power of the state to `e`. */
void spn__gather(spn_world *w, const spn_vec3 *x, const spn_vec3 *v, bool has_ext, spn_vec3 *f, spn__eval *e);
/* The whole force evaluation: the three above in order. */
void spn__eval_forces(spn_world *w, double t, const spn_vec3 *x, const spn_vec3 *v, spn_vec3 *f, spn__eval *e);

double spn__elastic_energy(const spn_world *w, const spn_vec3 *x);
double spn__kinetic_energy(const spn_world *w, const spn_vec3 *v);
double spn__gravity_energy(const spn_world *w, const spn_vec3 *x);

/* What the gather reads, copied out of the world into locals so the
 * compiler knows stores to positions and velocities cannot change them
 * (otherwise it reloads every pointer from the world on every particle). */
/* a s + b, each component one fused multiply-add (the explicit steps'
 * update: v' = v + f dt/m, x' = x + v' dt). */
SPN__INLINE spn_vec3 spn__fma_v3(spn_vec3 a, double s, spn_vec3 b)
{
    return spn_v3(fma(a.x, s, b.x), fma(a.y, s, b.y), fma(a.z, s, b.z));
}

typedef struct spn__gather_ctx {
    const uint32_t *restrict a_start, *restrict b_start, *restrict b_adj;
    const spn_vec3 *restrict fs, *restrict fext;
    const double *restrict mass, *restrict inv_mass;
    spn_vec3 g;
    double drag;
    /* the air's forces on the segments and the signed adjacency (spn__air_on) */
    const uint32_t *restrict adj_start, *restrict adj;
    const spn_vec3 *restrict fair;
} spn__gather_ctx;

static inline spn__gather_ctx spn__gather_ctx_of(const spn_world *w)
{
    spn__gather_ctx c = {w->a_start, w->b_start, w->b_adj, w->fs,       w->fext,   w->mass,
                         w->inv_mass, w->def.gravity, w->def.drag, w->adj_start, w->adj, w->fair};
    return c;
}

/* fe plus half of each of particle i's segments' air forces, in adjacency
 * order (spn__external into fext, the explicit step in its particle pass). */
SPN__INLINE spn_vec3 spn__air_on(const spn__gather_ctx *c, uint32_t i, spn_vec3 fe)
{
    for (uint32_t j = c->adj_start[i]; j < c->adj_start[i + 1]; j++)
        fe = spn_v3_add(fe, spn_v3_scale(c->fair[c->adj[j] >> 1], 0.5));
    return fe;
}

/* Gravity and viscous drag on a particle of mass m at velocity v,
 * m g - (drag m) v (dm = drag m): one fused multiply-add a component when
 * `fused` (the explicit steps: explicit.c, sweep.c; the lattice's explicit
 * rows give the same bits), two roundings otherwise (RK4, the evaluations
 * of the other steppers). */
SPN__INLINE spn_vec3 spn__gravity_drag(double m, double dm, spn_vec3 g, spn_vec3 v, bool fused)
{
    if (fused) return spn_v3(fma(-dm, v.x, m * g.x), fma(-dm, v.y, m * g.y), fma(-dm, v.z, m * g.z));
    return spn_v3(m * g.x - dm * v.x, m * g.y - dm * v.y, m * g.z - dm * v.z);
}

/* Net force on particle i: gravity and viscous drag (spn__gravity_drag,
 * fused or not), its springs (from fs: first those it is end a of, a
 * contiguous run, then those it is end b of, in internal order) and, when
 * `has_ext`, fext[i]. */
SPN__INLINE spn_vec3 spn__force_on(const spn__gather_ctx *c, uint32_t i, spn_vec3 vi, bool has_ext, bool fused)
{
    const double m = c->mass[i];
    spn_vec3 fi = spn__gravity_drag(m, c->drag * m, c->g, vi, fused);
    for (uint32_t s = c->a_start[i], end = c->a_start[i + 1]; s < end; s++) {
        const spn_vec3 fe = c->fs[s];
        fi.x += fe.x, fi.y += fe.y, fi.z += fe.z;
    }
    for (uint32_t j = c->b_start[i], end = c->b_start[i + 1]; j < end; j++) {
        const spn_vec3 fe = c->fs[c->b_adj[j]];
        fi.x -= fe.x, fi.y -= fe.y, fi.z -= fe.z;
    }
    if (has_ext) fi = spn_v3_add(fi, c->fext[i]);
    return fi;
}

/* ---- step.c ---- */

/* What an integrator reports to the step driver, for the blow-up check and
 * the energy accounting. */
typedef struct spn__step_result {
    double e_before;   /* kinetic + elastic + gravitational before the step */
    double gain_kp;    /* change of kinetic + gravitational energy over the step */
    double work;       /* work of the external forces over the step */
    double dissipated; /* damping and drag losses over the step */
    double kinetic;    /* kinetic energy after the step (NaN/inf: blown up) */
    double elastic;    /* elastic energy before the step */
} spn__step_result;

/* ---- sweep.c ---- */

/* The fused Euler / symplectic Euler step, for worlds with no force callback
 * and no air; false (nothing done) when out of memory for its buffers. */
bool spn__step_sweep(spn_world *w, double dt, bool symplectic, spn__step_result *r);
void spn__sweep_free(spn_world *w);

/* ---- lattice.c ---- */

/* Recognise a hub + rings x radials web in the compiled world (w->lat, or
 * NULL when the springs are anything else). */
void spn__lattice_build(spn_world *w);
/* Forget the lattice: the general path steps the world from now on. */
void spn__lattice_drop(spn_world *w);
/* Public spring s changed its stiffness, rest length or broke. */
void spn__lattice_spring_changed(spn_world *w, uint32_t s);
/* The explicit step and RK4 as stencils over the lattice; false (nothing
 * done) when the world has no lattice, a force callback or air, or when out
 * of memory for its buffers. */
bool spn__lattice_explicit(spn_world *w, double dt, bool symplectic, spn__step_result *r);
bool spn__lattice_rk4(spn_world *w, double dt, spn__step_result *r);
/* Steps of a replayable advance on a lattice web as passes over memory
 * that each take several levels (up to k, at most SPN__LAT_BLOCK_MAX,
 * explicit steps, or the four stages of one RK4 step); the count of steps
 * done (0: take single steps), results in r[]. */
#define SPN__LAT_BLOCK_MAX 4
int spn__lattice_block_steps(spn_world *w, double dt, int k, spn__step_result *r);
/* The threads a replayable advance's lattice steps would take (the team
 * worth opening for it), 1 when none or when the lattice does not apply. */
int spn__lattice_team_threads(spn_world *w);
/* body(w, ctx) on this thread with a team of `threads` open for the
 * lattice's parallel work (lattice_team.c); its status. */
spn_status spn__lattice_team_call(spn_world *w, int threads, spn_status (*body)(spn_world *, void *), void *ctx);
/* The open team's size, 0 when none. */
int spn__lattice_team_size(const spn_world *w);
/* Tests: how long a team's waiting threads spin (pause-spins) and yield
 * before a worker sleeps; negative restores the default. Set between
 * calls only. */
void spn__lat_team_set_patience(int spins, int yields);
/* The memory traffic a lattice step cannot avoid, in bytes per step, over
 * an spn_world_advance call of `steps` steps of which `blocked` were taken in
 * blocked passes (spn_step_report.blocked); a model (lattice.c). 0 when the
 * world's steps do not take the lattice. */
double spn__lattice_step_bytes(const spn_world *w, int steps, int blocked);
/* For tests: every lattice step of an spn_world_advance call taken alone
 * (`single`), not in blocked passes, for a reference to hold the passes'
 * bits against; false again lets them run. */
void spn__lattice_set_unblocked(spn_world *w, bool single);
/* For tests: on one thread, blocked passes taken wherever they apply
 * (`held`), instead of as the pass governor (lattice.c) picks between them
 * and single steps; false lets it pick again. */
void spn__lattice_hold_passes(spn_world *w, bool held);
/* Tests: blocked passes on two threads give share 0 the first `bands`
 * bands from the next pass on (where that leaves each share its rows),
 * instead of moving the split by the shares' speeds; -1 lets it move. */
void spn__lattice_split_hold(spn_world *w, int bands);
/* For tests: the lattice's thread governor (lattice.c) set to keep choosing
 * threads (or one thread) below parallel_min, as if it had measured them
 * faster; false when the world has no lattice. */
bool spn__lattice_gov_prefer(spn_world *w, bool threads);
/* The float32 lattice step (lattice_f32.c) keeps its own state during an
 * spn_world_advance call; w->x and w->v are behind it until this writes them
 * back (a no-op when it holds nothing). Called at the end of every call. */
void spn__lattice_sync(spn_world *w);
/* Forget the float32 state without writing it (the caller restores x, v). */
void spn__lattice_discard(spn_world *w);

/* ---- integrators (explicit.c, adaptive.c, implicit.c) ---- */

void spn__step_explicit(spn_world *w, double dt, bool symplectic, spn__step_result *r);
spn_status spn__step_rk4(spn_world *w, double dt, spn__step_result *r);
spn_status spn__step_adaptive(spn_world *w, double dt, spn__step_result *r);
/* The longest stable step of the world's springs (stable_step.c), times
 * reach (1: the bound itself), with `extra_stiffness` added per particle;
 * sums: 2 np doubles of scratch. INFINITY when nothing bounds it (no
 * free particle with a spring or drag). */
double spn__stable_step(const spn_world *w, double reach, double extra_stiffness, double *sums);
spn_status spn__step_implicit(spn_world *w, double dt, spn__step_result *r);

/* ---- hysteresis.c, contact.c ---- */

/* Set each hysteretic spring's damping coefficient in the hot records from
 * the state, for a step of dt (kd plus the hysteresis secant). */
void spn__hysteresis_prepare(spn_world *w, double dt);
/* Free / duplicate (into a fresh clone) the hysteresis table and contacts. */
void spn__silk_free(spn_world *w);
bool spn__silk_clone(spn_world *c, const spn_world *w);
/* Implicit solver (implicit.c): the inverse of a symmetric 3x3 block (xx,
 * yy, zz, xy, xz, yz). */
void spn__invert_sym3(const double a[6], double out[6]);
/* Block Jacobi's inverses (w->pblock into w->pinv; a fixed particle's 0):
 * of every particle (local NULL), or of those whose local[i] is not below n
 * (outside a preconditioner's system). */
void spn__implicit_invert(spn_world *w, const int32_t *local, uint32_t n);
/* The multigrid preconditioner of the implicit step (implicit_mg.c). Auto
 * uses it from this many particles and this step [s]: below, a step needs too
 * few block-Jacobi iterations for the cycle's cost to pay (measured on the
 * 20k web: break-even near 2e-3 s; docs/physics-implicit-mg.md). */
#define SPN__IMPLICIT_MG_MIN 4096u
#define SPN__IMPLICIT_MG_DT 5e-3
/* ... and on any web, at any step, once block Jacobi has taken more than
 * this many CG iterations in a step (at that step's length and longer; that
 * step's solve goes on with it from there): past about a hundred the
 * V-cycle's few iterations cost less whatever the tolerance and the web's
 * size (docs/physics-implicit-mg.md, "Stiff webs"), but for a small web's
 * steps with contacts. */
#define SPN__IMPLICIT_BJ_MAX 100
/* Where auto takes the multigrid on a web that is no lattice, a web of at
 * most this many free particles is factorised instead (sparse_chol.c): the
 * factor of one step's matrix preconditions the steps after it until it
 * costs more than a new one would (docs/physics-implicit-mg.md, "A
 * factorised preconditioner", "When to factorise again"). */
#define SPN__IMPLICIT_DIRECT_MAX 65536u
/* What a factorisation costs, in CG iterations, for that reckoning: about
 * 12 measured on the Araneus and the 0.5 m Zilla web (2 ms against 0.17,
 * 29 against 2.3); 8 gave the faster steps on both and on the 1 m web. */
#define SPN__IMPLICIT_FACTOR_PRICE 8u
/* A factor outrun within the step after its own has the next steps
 * factorise at their start, up to this many in a row. */
#define SPN__IMPLICIT_HOLD_MAX 16u
typedef struct spn__imp_mg spn__imp_mg;
void spn__imp_mg_free(spn__imp_mg *m);
/* After w->jac and w->pblock are built for step h: (re)build or refresh the
 * hierarchy, and invert the blocks of the particles outside it; false when
 * the step should use block Jacobi (whose inverses are then still to form). */
bool spn__imp_mg_prepare(spn_world *w, double h);
/* z = M^-1 r over all particles (fixed rows 0). */
void spn__imp_mg_apply(const spn_world *w, const spn_vec3 *r, spn_vec3 *z);
/* A solve with the preconditioner took `iterations` CG iterations (since
 * it took over): with a factor kept, whether the next step factorises. */
void spn__imp_mg_solved(spn_world *w, int iterations);
/* Mid-solve, `iterations` into it: whether a factor of an earlier step has
 * cost this solve more than a factorisation would (spn__imp_mg_refactor). */
bool spn__imp_mg_restart_due(const spn_world *w, int iterations);
/* Mid-solve: the factor of an earlier step replaced by this step's (or,
 * if that fails, by block Jacobi for the rest of the solve); false when
 * there is none to replace. CG must start again from where it is. */
bool spn__imp_mg_refactor(spn_world *w);
/* The factorisations made for the implicit step so far (0 without a factor). */
uint32_t spn__imp_mg_factorisations(const spn_world *w);
/* For tests: the next n factorisations of the implicit step's factor are
 * refused, as of a matrix not positive definite (they are still made and
 * counted), for the fallbacks to be driven on a matrix that is definite. */
void spn__imp_mg_refuse(spn_world *w, uint32_t n);
/* For tests: the next factorisation of the cyclic preconditioner's line
 * systems (SPN__REFUSE_CYCLIC) and the next V-cycle set-up
 * (SPN__REFUSE_VCYCLE) refused, as of a matrix not positive definite (each
 * still made), to drive the fallbacks after them: cyclic -> V-cycle -> block
 * Jacobi. */
enum { SPN__REFUSE_CYCLIC = 1, SPN__REFUSE_VCYCLE = 2 };
void spn__imp_mg_refuse_setup(spn_world *w, unsigned which);
/* Every contact active, before a step's first solve. */
void spn__contact_begin(spn_world *w);
/* The active contacts' part of the implicit system: their forces and
 * h^2 K v0 into the right-hand side b, their blocks added to the diagonal
 * blocks pblock (the springs' part, from build_rhs). */
void spn__contact_system(spn_world *w, double h, spn_vec3 *b, double *pblock);
/* ap += A_contacts p; returns p . A_contacts p. */
double spn__contact_apply(const spn_world *w, double h, const spn_vec3 *p, spn_vec3 *ap);
/* After a solve for dv: drop the contacts that end on the wrong side; true
 * when any was dropped (solve again). */
bool spn__contact_release(spn_world *w, double h, const spn_vec3 *dv);

/* ---- constraints.c ---- */

/* Built-in colliders and the collision callback after a step; returns the
 * energy removed. */
double spn__collide(spn_world *w, double dt);
/* Provot deformation limits; returns the energy removed. */
double spn__provot(spn_world *w, double dt);
/* Break the springs that left [min, max]; returns how many broke. */
int spn__check_breakage(spn_world *w);

#endif
