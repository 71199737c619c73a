/* Shared between the equilibrium files: the static problem extracted from a
 * world (free particles first, fixed ones after), the per-spring Hessian
 * blocks, the PCG solver and the preconditioners.
 *
 * Vectors over free particles are double[3 n] (x, y, z interleaved). A
 * symmetric 3x3 block is stored as 6 doubles: xx, yy, zz, xy, xz, yz.
 * Reductions go through fixed blocks of particles (SPN__EQ_CHUNK) summed in
 * order, so every result is the same bits for any thread count. */
#ifndef SPN_EQUILIBRIUM_INTERNAL_H
#define SPN_EQUILIBRIUM_INTERNAL_H

#include "spinneret/equilibrium.h"

#define SPN__EQ_CHUNK 512u
#define SPN__EQ_LANES 8u      /* divides SPN__EQ_CHUNK */
#define SPN__EQ_LANE_SLOTS 8u

typedef struct spn__mg spn__mg;
typedef struct spn__cyc spn__cyc;

typedef struct spn__eq {
    uint32_t n;        /* free particles: local ids 0..n-1 */
    uint32_t nl;       /* local particles: free, then fixed ones touched by a spring */
    uint32_t *world_id; /* nl: local -> world particle id */
    uint32_t np_world;  /* the world's particles (the lattice test of equilibrium_cyclic.c) */
    double *x;         /* 3 nl: positions (fixed ones never change) */
    double *fext;      /* 3 n: gravity + load */
    double *xtrial;    /* 3 n: line-search positions */

    uint32_t m;        /* springs with a free end, not broken */
    uint32_t m_free;   /* the first m_free join two free particles; the rest have a (free) and b fixed */
    uint32_t *sa, *sb; /* local ids */
    double *k, *rest;
    uint8_t *tonly;

    /* free particle -> incident springs, in spring order: spring id << 1 | (1 if end b) */
    uint32_t *adj_start, *adj;
    int32_t *adj_other; /* the other end's local free id, or -1 when fixed */
    int32_t *adj_col;   /* the same, but the row itself when fixed (its block is zero) */

    /* per Newton iteration */
    double *hs;   /* 6 m: projected Hessian block of each spring */
    double *fs;   /* 3 m: force on end a */
    double *diag; /* 6 n: diagonal blocks (springs + shift) */
    /* 6 per adjacency entry: the row's off-diagonal block, or NULL when it
     * is -H_s of the entry's spring (0 to a fixed end) and read through
     * spn__eq_offd from hs (equilibrium: the blocks were a second copy of hs,
     * 192 MB on the 1M web); implicit_mg.c stores its own */
    double *offd;
    /* The product's copy of diag and offd: rows in groups of SPN__EQ_LANES
     * side by side (equilibrium_system.c); a group with a row of more than
     * SPN__EQ_LANE_SLOTS entries (a hub) has no slots and goes row by row. */
    uint32_t *lane_start; /* groups + 1: the group's slots */
    uint8_t *lane_by_row; /* per group: 1 when it goes row by row */
    int32_t *lane_col;    /* SPN__EQ_LANES per slot: adj_col, or the row itself past a row's end */
    double *lane_val;     /* 6 SPN__EQ_LANES per slot: entry f of lane q at (6 slot + f) LANES + q */
    double *lane_diag;    /* 6 SPN__EQ_LANES per group, likewise */
    float *lane_val32, *lane_diag32; /* the same rounded to float32 once the multigrid asks (spn__eq_lanes32), or NULL */
    double *kscale; /* n: sum of incident k, the scale of the Levenberg shift */
    double lambda;  /* the shift of the last assembly */
    double *f;    /* 3 n: net force = -gradient */
    double noise; /* rounding scale of an energy difference [J] */
    double xmax;  /* largest |coordinate| at the start [m] */
    double iso_force;   /* largest external force on a free particle without springs [N] */
    uint32_t iso_worst; /* ... its world id */

    int threads;
    uint32_t nchunks;
    double *partial; /* nchunks * 4 */
} spn__eq;

/* Adjacency entry j's off-diagonal block (6 numbers): offd's, or -H_s
 * (0 to a fixed end) written into tmp. */
static inline const double *spn__eq_offd(const spn__eq *e, uint32_t j, double *tmp)
{
    if (e->offd) return e->offd + 6 * (size_t)j;
    const double *h = e->hs + 6 * (size_t)(e->adj[j] >> 1), keep = e->adj_other[j] >= 0 ? -1 : 0;
    for (int c = 0; c < 6; c++) tmp[c] = keep * h[c];
    return tmp;
}

/* Build the problem from the world; SPN_ERR_NOMEM or SPN_OK. */
spn_status spn__eq_init(spn__eq *e, const spn_world *w, const spn_equilibrium_def *def);
void spn__eq_free(spn__eq *e);

/* Forces and Hessian blocks at e->x, diagonal shifted by lambda * kscale.
 * Returns the largest |f_i| and its local id in *worst. */
double spn__eq_assemble(spn__eq *e, double lambda, uint32_t *worst);
/* Spring s at e->x: its force on end a (fs, 3) and its projected Hessian
 * block (h, 6), as spn__eq_assemble forms them; returns the scale of the
 * rounding in its energy difference. */
double spn__eq_spring_terms(const spn__eq *e, uint32_t s, double *fs, double *h);
/* Energy change of spring s from length l0 to l1 (a tension-only spring
 * holds none while slack). */
double spn__eq_length_energy(const spn__eq *e, uint32_t s, double l0, double l1);
/* Energy change of moving the free particles from x to x + alpha p; the
 * trial positions are left in e->xtrial. */
double spn__eq_energy_delta(spn__eq *e, const double *p, double alpha);
/* The largest step along p (<= 1) that shortens no taut tension-only spring,
 * to first order, by more than cap times its stretch. */
double spn__eq_slack_limit(const spn__eq *e, const double *p, double cap);
/* The product's lane copy of diag and offd (equilibrium_product.c): its
 * layout, made once; row i's blocks copied in after each assembly. */
spn_status spn__eq_build_lanes(spn__eq *e);
/* The lanes' float32 copy (lane_val32) from MATVEC32_MIN rows, made on first
 * call (the multigrid's); then kept by spn__eq_lanes_store. */
spn_status spn__eq_lanes32(spn__eq *e);
void spn__eq_lanes_store(spn__eq *e, uint32_t i);
/* y = A p over free particles; the _dot form also returns p . y
 * (equilibrium_product.c). */
void spn__eq_matvec(const spn__eq *e, const double *p, double *y);
double spn__eq_matvec_dot(const spn__eq *e, const double *p, double *y);
/* y = A p for the multigrid's residuals: float32 blocks on large webs. */
void spn__eq_matvec_mg(const spn__eq *e, const double *p, double *y);
/* The same on the rows of groups [g0, g1) of SPN__EQ_LANES rows, on the
 * calling thread: each row the same bits as in spn__eq_matvec_mg. */
void spn__eq_matvec_mg_rows(const spn__eq *e, uint32_t g0, uint32_t g1, const double *p, double *y);
/* p += alpha d, r -= alpha q; returns r . r and sets *rmax2 to the largest
 * |r_i|^2 of a particle. */
double spn__eq_update(const spn__eq *e, double alpha, const double *d, const double *q, double *p, double *r,
                      double *rmax2);
/* Fixed-order sum of a . b over 3 n entries. */
double spn__eq_dot(const spn__eq *e, const double *a, const double *b);

/* Preconditioner: z = M^-1 r. */
typedef struct spn__precond {
    spn_precond kind;
    double *inv; /* 6 n: inverted diagonal blocks (or the diagonal) */
    spn__mg *mg;
    spn__cyc *cyc; /* SPN_PRECOND_CYCLIC: built by the caller, factored by setup */
} spn__precond;

spn_status spn__precond_setup(spn__precond *pc, spn__eq *e);
void spn__precond_apply(const spn__precond *pc, const spn__eq *e, const double *r, double *z);
void spn__precond_free(spn__precond *pc);
/* Symmetric block Gauss-Seidel with the inverted diagonal blocks inv. */
void spn__sgs_apply(const spn__eq *e, const double *inv, const double *r, double *z);

/* The preconditioner M as a stationary iteration, e <- e - M^-1 A e, from a
 * fixed pseudo-random error on the chosen components (bit 0 x, bit 1 y,
 * bit 2 z; the others zero): how much each cycle shrinks the error's energy
 * norm |e|_A. Returns the geometric mean of the factors of the last
 * cycles / 4 cycles (the asymptotic rate, which the slowest modes set: for
 * a symmetric V-cycle the smallest eigenvalue of M^-1 A is about 1 minus
 * it, and CG's iterations grow as its inverse square root), and in *worst
 * the largest single factor (below 1 for every cycle when M is a
 * convergent symmetric smoother-based cycle). A measure of the
 * preconditioner that depends neither on the machine nor on the Newton
 * path that a CG count also reflects (bench/bench_mg_rates.c,
 * docs/physics-equilibrium.md). work: 3 x 3n doubles; cycles >= 1. */
double spn__precond_contraction(const spn__precond *pc, const spn__eq *e, unsigned components, int cycles,
                                double *worst, double *work);

/* Solve A p = f until |A p - f|_2 <= eta |f|_2 or every particle's
 * |(A p - f)_i| <= floor, p the first guess.
 * Returns the iterations used, or -1 when A showed non-positive curvature. */
int spn__eq_pcg(const spn__eq *e, const spn__precond *pc, double *p, double eta, double floor, int max_iter,
                double *work);

/* Symmetric 3x3 block helpers (6-double layout). */
static inline void spn__sym_mul(const double *h, const double *v, double *out)
{
    out[0] = h[0] * v[0] + h[3] * v[1] + h[4] * v[2];
    out[1] = h[3] * v[0] + h[1] * v[1] + h[5] * v[2];
    out[2] = h[4] * v[0] + h[5] * v[1] + h[2] * v[2];
}
/* The full 3x3 (row by row) of a symmetric block's six numbers. */
static inline void spn__sym_full(const double *h, double *m)
{
    m[0] = h[0], m[1] = h[3], m[2] = h[4];
    m[3] = h[3], m[4] = h[1], m[5] = h[5];
    m[6] = h[4], m[7] = h[5], m[8] = h[2];
}
/* Inverse of a symmetric 3x3 block; false when it is not positive definite. */
bool spn__sym_inverse(const double *h, double *inv);

/* Multigrid (equilibrium_mg.c): built from the assembled system. */
spn_status spn__mg_setup(spn__mg **mg, const spn__eq *e, const double *inv0);
void spn__mg_apply(const spn__mg *mg, const spn__eq *e, const double *r, double *z);
void spn__mg_free(spn__mg *mg);
/* Free particles from which a later Newton step forms the multigrid's coarse
 * levels again (200,000; equilibrium_mg.c); returns the old value. For the
 * tests, which cannot afford such webs; not to be changed during a solve. */
uint32_t spn__mg_set_refresh_min(uint32_t free_particles);
/* Level l of a built hierarchy: its rows, its blocks and its longest row's
 * blocks (for tests and diagnostics); false when there is no level l. */
bool spn__mg_level(const spn__mg *mg, int l, uint32_t *rows, uint32_t *blocks, uint32_t *longest);

/* Cyclic preconditioner (equilibrium_cyclic.c): the exact solve of the
 * rotational average of a hub + rings x radials web's system. build: NULL
 * when the web is not such a lattice (*why says what breaks it) or out of
 * memory; factor: per Newton step, false when the average is not definite. */
spn__cyc *spn__cyc_build(const spn__eq *e, const char **why);
bool spn__cyc_factor(spn__cyc *C, const spn__eq *e);
void spn__cyc_apply(const spn__cyc *C, const spn__eq *e, const double *r, double *z);
void spn__cyc_free(spn__cyc *C);
/* The last factored system's spread about its average: sqrt(sum |X - mean|^2
 * / sum |X|^2) over its blocks in local frames (0 for a symmetric web). */
double spn__cyc_asymmetry(const spn__cyc *C);

/* Thread-line smoother (equilibrium_lines.c) over level 0 of the multigrid. */
typedef struct spn__lines spn__lines;
struct spn__bsr;
spn__lines *spn__lines_build(const spn__eq *e, const struct spn__bsr *a0);
bool spn__lines_factor(spn__lines *L, const spn__eq *e, int threads);
void spn__lines_sweep(const spn__lines *L, const double *b, double *x, bool forward, int threads);
void spn__lines_free(spn__lines *L);
/* The lines' particles: line l is node[start[l] .. start[l + 1]). */
void spn__lines_nodes(const spn__lines *L, uint32_t *count, const uint32_t **start, const uint32_t **node);

/* Thread-slide correction (equilibrium_slide.c) on level 0 of the multigrid. */
typedef struct spn__slide spn__slide;
spn__slide *spn__slide_build(const spn__eq *e, const spn__lines *L);
/* C = Z^T A Z from the spring system's blocks and shift; false if not positive definite. */
bool spn__slide_factor(spn__slide *S, const spn__eq *e);
/* x += Z C^-1 Z^T (b - A x), A x from spn__eq_matvec_mg; r (3 n) is
 * scratch, left holding b - A x at the x it was given. */
void spn__slide_correct(const spn__slide *S, const spn__eq *e, const double *b, double *x, double *r);
void spn__slide_free(spn__slide *S);

#endif
