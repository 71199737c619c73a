/* spn_world_equilibrium: Newton's method on the total potential of a spring
 * world (springs, gravity, a constant load), for webs at rest.
 *
 * Each iteration solves (H + lambda K) p = f by preconditioned conjugate
 * gradients, H the Hessian projected to positive semi-definite per spring
 * (equilibrium_system.c), K the particles' summed spring stiffness, f the net
 * force; then a backtracking line search on the energy (Armijo) picks the step.
 *  - lambda (a Levenberg-Marquardt shift) is 0 on a taut web, so the step is
 *    the Newton step and convergence is quadratic; it grows when the system is
 *    singular (slack or compressed threads leave a particle without transverse
 *    stiffness) or when the line search had to cut the step, and shrinks again
 *    after full steps.
 *  - The linear solves are inexact (Eisenstat & Walker 1996, choice 2): the
 *    relative CG tolerance follows the square of the residual's decrease, and
 *    is never tighter than what the final tolerance needs.
 *  - Near the answer the energy change of a step drops under rounding; a step
 *    whose change is within the rounding estimate is accepted, and the force
 *    residual (not the energy) decides convergence.
 * Invariant: the world is written only at the end and only with finite values. */
#include "core/big_alloc.h"
#include "equilibrium_internal.h"
#include "world_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define LAMBDA_FIRST 1e-6 /* first shift when the plain Newton system fails */
#define LAMBDA_MAX 1e8
#define ARMIJO 1e-4
#define AUTO_MULTIGRID 1000u /* free particles from which multigrid is the faster (docs/physics-equilibrium.md: the standard web ties at 1k, the species webs 1.5-7x faster from 1.8k) */
/* A step that fails the energy test is tried at halves of its length down
 * to 1 / 2^HALVINGS before the shift grows and the Newton step is solved
 * again. Why: on a woven web an early full step can overshoot where a
 * thread's tension-only law or its geometry bends the energy, and each
 * shifted retry cost a preconditioner set-up and a solve (a Zilla web's form
 * finding, 406k particles: six retries in a row after the second step, 16
 * Newton steps, 16 s; halving first: one step at half length, 7 Newton
 * steps, 11 s). The shift still grows after a halved step (the model was
 * wrong), so the trust region stays. An energy per halving costs one pass
 * over the springs. */
#define HALVINGS 4
#define SLACK_CAP 1.0   /* a step may take a taut silk thread (to first order) at most to slack */
#define SLACK_FLOOR 0.01 /* ... but is never cut below this fraction */
#define ETA0 0.1         /* the first solve's CG tolerance: a rough first step went slack wholesale */
#define ETA_MAX 0.5      /* the loosest CG tolerance */
/* With multigrid a decade of the linear residual costs a few cycles, and a
 * Newton step (assembly, line factors) about as much as a cycle: tighter
 * solves, fewer Newton steps (100k web: 4 steps, 54 CG -> 3 steps, 44 CG).
 * 0.01 until 2026-11-22; with the hubs relaxed (relax_hub) 0.003 takes the
 * standard web to 1e-6 T0 in one Newton step fewer: 100k 3 steps, 21 CG ->
 * 2, 22; 1M 3, 37 -> 2, 34 (0.002: 5k 12 -> 16 CG). */
#define ETA0_MG 0.003
#define ETA_MAX_MG 0.1
/* The multigrid hierarchy is built from the first Newton system and kept. A
 * shifted solve (slack or buckling threads) that needed more CG iterations
 * than this says it no longer fits, and the next step builds it again: the
 * 64 x 64 hammock took 10,472 CG iterations and 30 s with it kept, 725 and
 * 3 s with this. A taut web's late, tight solves also take more, but there a
 * new hierarchy did not help (measured at 100k), so they keep it. */
#define MG_REBUILD_CG 40
/* The cyclic preconditioner under SPN_PRECOND_AUTO: taken on any lattice
 * web, given up for the multigrid when a solve needs CYC_GIVE_UP
 * iterations. On the standard web it takes 1-3 a Newton step, 7-15 under a
 * point load of 4-256 T0 (docs/physics-equilibrium.md, "The cyclic
 * preconditioner"). Until the twenty-second session it was taken only when
 * the radial count had no prime factor above 1,000, as far as measured then
 * (the transform did a prime p by a direct DFT, p operations an element);
 * the transform now takes a length with a large prime factor by Bluestein's
 * chirp (fft.h), a few times N log N for any N: 40 x 1009 settles in 0.08 s
 * against the multigrid's 1.1 s. */
#define CYC_GIVE_UP 60
#define STALL_LIMIT 5 /* iterations in a row that lower neither energy nor residual */
/* Hubs: particles spring-joined to more than HUB_MIN_NEIGHBOURS others and to
 * HUB_FACTOR times the mean (the standard web's hub, where every radial ends). Each accepted
 * Newton step is followed by up to HUB_STEPS local Newton steps on each hub
 * alone, its neighbours held (relax_hub). */
#define HUB_MIN_NEIGHBOURS 64
#define HUB_FACTOR 8.0
#define HUB_STEPS 3

static const char *const PRECOND_NAMES[SPN_PRECOND_COUNT] = {"jacobi", "block-jacobi", "multigrid", "sgs", "auto",
                                                                   "cyclic"};

const char *spn_precond_name(spn_precond p)
{
    return (unsigned)p < SPN_PRECOND_COUNT ? PRECOND_NAMES[p] : "unknown";
}

spn_status spn_precond_parse(const char *name, spn_precond *out)
{
    for (int i = 0; i < SPN_PRECOND_COUNT; i++)
        if (name && strcmp(name, PRECOND_NAMES[i]) == 0) {
            *out = (spn_precond)i;
            return SPN_OK;
        }
    return spn_error(SPN_ERR_INVALID, "unknown preconditioner '%s' (jacobi, block-jacobi, multigrid, sgs, cyclic or auto)",
                     name ? name : "(null)");
}

const char *spn_equilibrium_reason_name(spn_equilibrium_reason r)
{
    switch (r) {
    case SPN_EQUILIBRIUM_CONVERGED: return "converged";
    case SPN_EQUILIBRIUM_MAX_ITERATIONS: return "max-iterations";
    case SPN_EQUILIBRIUM_STALLED: return "stalled";
    }
    return "unknown";
}

spn_equilibrium_def spn_equilibrium_def_default(void)
{
    spn_equilibrium_def d;
    memset(&d, 0, sizeof d);
    d.tolerance = 1e-6;
    d.abs_tolerance = 0;
    d.force_scale = 0;
    d.max_iterations = 200;
    d.max_cg_iterations = 5000;
    d.preconditioner = SPN_PRECOND_AUTO;
    d.gravity = true;
    d.load = spn_v3(0, 0, 0);
    d.loads = NULL;
    d.threads = 0;
    return d;
}

static spn_status check_def(const spn_world *w, const spn_equilibrium_def *d)
{
    if (!(d->tolerance >= 0) || !isfinite(d->tolerance))
        return spn_error(SPN_ERR_INVALID, "equilibrium: tolerance must be finite and >= 0 (got %g)", d->tolerance);
    if (!(d->abs_tolerance >= 0) || !isfinite(d->abs_tolerance))
        return spn_error(SPN_ERR_INVALID, "equilibrium: abs_tolerance must be finite and >= 0 (got %g)",
                         d->abs_tolerance);
    if (!isfinite(d->force_scale))
        return spn_error(SPN_ERR_INVALID, "equilibrium: force_scale must be finite (got %g)", d->force_scale);
    if (d->max_iterations < 0 || d->max_cg_iterations < 1)
        return spn_error(SPN_ERR_INVALID, "equilibrium: max_iterations must be >= 0 and max_cg_iterations >= 1");
    if ((unsigned)d->preconditioner >= SPN_PRECOND_COUNT)
        return spn_error(SPN_ERR_INVALID, "equilibrium: preconditioner %d is not one of the %d kinds",
                         (int)d->preconditioner, SPN_PRECOND_COUNT);
    if (d->threads < 0) return spn_error(SPN_ERR_INVALID, "equilibrium: threads must be >= 0 (got %d)", d->threads);
    if (!spn_v3_finite(d->load)) return spn_error(SPN_ERR_INVALID, "equilibrium: load is not finite");
    for (uint32_t i = 0; i < spn_world_particle_count(w); i++) {
        if (d->loads && !spn_v3_finite(d->loads[i]))
            return spn_error(SPN_ERR_INVALID, "equilibrium: loads[%u] is not finite", i);
        if (!spn_v3_finite(spn_world_position(w, i)))
            return spn_error(SPN_ERR_UNSTABLE, "equilibrium: particle %u has a non-finite position", i);
    }
    return SPN_OK;
}

/* The largest spring tension, else the largest external force, else 1 N. */
static double auto_force_scale(const spn__eq *e)
{
    double t = 0;
    for (uint32_t s = 0; s < e->m; s++) {
        const double *a = e->x + 3 * (size_t)e->sa[s], *b = e->x + 3 * (size_t)e->sb[s];
        double l = sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
        t = fmax(t, e->k[s] * (l - e->rest[s]));
    }
    if (t > 0) return t;
    for (uint32_t i = 0; i < e->n; i++) {
        const double *f = e->fext + 3 * (size_t)i;
        t = fmax(t, sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]));
    }
    t = fmax(t, e->iso_force);
    return t > 0 ? t : 1;
}

typedef struct newton {
    spn__eq e;
    spn__precond pc;
    double *p, *work;
    uint32_t *hubs, nhubs;
    bool auto_cyclic; /* cyclic chosen by SPN_PRECOND_AUTO: the multigrid takes over if it does badly */
    double lambda, target, residual, eta, eta_max, energy_change;
    uint32_t worst;
    int max_cg, stalls;
    spn_status status; /* SPN_OK, or the failure that ended the run */
    spn_equilibrium_report rep;
} newton;

static double grow_lambda(double lambda) { return lambda > 0 ? 10 * lambda : LAMBDA_FIRST; }

/* The CG tolerance for the next solve (Eisenstat-Walker choice 2, safeguarded),
 * never tighter than the target asks for. */
static double forcing(const newton *nt, double previous_residual)
{
    double ratio = nt->residual / previous_residual;
    double eta = 0.9 * ratio * ratio, safe = 0.9 * nt->eta * nt->eta;
    if (safe > 0.1) eta = fmax(eta, safe);
    /* under a Levenberg shift the model is rough anyway: no tight solves */
    return fmin(nt->lambda > 0 ? ETA_MAX : nt->eta_max, eta);
}

/* Take the line-search positions as the current ones (or back): the fixed
 * particles sit in both arrays, and only free ones are ever written. */
static void swap_positions(spn__eq *e)
{
    double *t = e->x;
    e->x = e->xtrial;
    e->xtrial = t;
}

/* The local particle (free or fixed) at the other end of spring s from i. */
static inline uint32_t other_end(const spn__eq *e, uint32_t s, uint32_t i)
{
    return e->sa[s] == i ? e->sb[s] : e->sa[s];
}

/* The particles spring-joined to particle i, each counted once (a pair
 * joined by several springs is one); mark: per local particle, the last
 * particle that counted it. */
static uint32_t neighbours(const spn__eq *e, uint32_t i, uint32_t *mark)
{
    uint32_t count = 0;
    for (uint32_t j = e->adj_start[i]; j < e->adj_start[i + 1]; j++) {
        const uint32_t s = e->adj[j] >> 1, o = other_end(e, s, i);
        count += mark[o] != i;
        mark[o] = i;
    }
    return count;
}

/* The hubs (see HUB_MIN_NEIGHBOURS), in particle order; false: out of memory.
 * Neighbours, not springs, count: a web with every thread doubled is the
 * web with threads twice as stiff, and is solved the same way. */
static bool find_hubs(newton *nt)
{
    const spn__eq *e = &nt->e;
    const int team = e->n < 32768u ? 1 : e->threads;
    const size_t nl = e->nl ? e->nl : 1;
    uint32_t *count = malloc((e->n ? e->n : 1) * sizeof *count), *marks = malloc((size_t)team * nl * sizeof *marks);
    if (!count || !marks) {
        free(count), free(marks);
        return false;
    }
    for (size_t k = 0; k < (size_t)team * nl; k++) marks[k] = UINT32_MAX;
    uint64_t total = 0; /* an integer sum: the same in any order */
    (void)team;
#pragma omp parallel for schedule(static) reduction(+ : total) num_threads(team)
    for (uint32_t i = 0; i < e->n; i++) total += count[i] = neighbours(e, i, marks + (size_t)spn__thread_num() * nl);
    free(marks);
    const double least = fmax(HUB_MIN_NEIGHBOURS, HUB_FACTOR * (e->n ? (double)total / e->n : 0));
    nt->nhubs = 0;
    for (uint32_t i = 0; i < e->n; i++) nt->nhubs += count[i] > least;
    if (nt->nhubs && !(nt->hubs = malloc(nt->nhubs * sizeof *nt->hubs))) {
        free(count);
        return false;
    }
    uint32_t k = 0;
    for (uint32_t i = 0; i < e->n; i++)
        if (count[i] > least) nt->hubs[k++] = i;
    free(count);
    return true;
}

/* Particle i's net force at e->x and its stiffness (the projected blocks of
 * its springs), its neighbours held. */
static void hub_terms(const spn__eq *e, uint32_t i, double f[3], double h[6])
{
    for (int c = 0; c < 3; c++) f[c] = e->fext[3 * (size_t)i + c];
    for (int c = 0; c < 6; c++) h[c] = 0;
    for (uint32_t j = e->adj_start[i]; j < e->adj_start[i + 1]; j++) {
        double fs[3], hs[6];
        spn__eq_spring_terms(e, e->adj[j] >> 1, fs, hs);
        const double sign = (e->adj[j] & 1u) ? -1 : 1; /* the force on end a; i is end b */
        for (int c = 0; c < 3; c++) f[c] += sign * fs[c];
        for (int c = 0; c < 6; c++) h[c] += hs[c];
    }
}

/* The energy change of moving particle i by dx, its neighbours held. */
static double hub_energy_delta(const spn__eq *e, uint32_t i, const double dx[3])
{
    const double *xi = e->x + 3 * (size_t)i;
    double de = 0;
    for (uint32_t j = e->adj_start[i]; j < e->adj_start[i + 1]; j++) {
        const uint32_t s = e->adj[j] >> 1;
        const double *xo = e->x + 3 * (size_t)other_end(e, s, i);
        double l0 = 0, l1 = 0;
        for (int c = 0; c < 3; c++) {
            const double a = xi[c] - xo[c], b = a + dx[c];
            l0 += a * a, l1 += b * b;
        }
        de += spn__eq_length_energy(e, s, sqrt(l0), sqrt(l1));
    }
    for (int c = 0; c < 3; c++) de -= e->fext[3 * (size_t)i + c] * dx[c];
    return de;
}

/* Local Newton steps on hub i, its neighbours held, each kept only if it
 * lowers the energy; returns the energy change. Why: a Newton step's error
 * is largest where many threads meet. The standard web's first segments
 * of its 1,000 radials are 0.15 mm long, so the hub's step turns each of them
 * and the turns' second-order stretch adds up there: after the first
 * Newton step the hub's residual was 1.7e-3 T0, every other particle's at
 * most 2.3e-4 (its linear residual), and that one particle cost the 1M and
 * 100k webs a Newton step (docs/physics-equilibrium.md, eleventh session). */
static double relax_hub(spn__eq *e, uint32_t i)
{
    double change = 0;
    for (int step = 0; step < HUB_STEPS; step++) {
        double f[3], h[6], inv[6], dx[3];
        hub_terms(e, i, f, h);
        if (!spn__sym_inverse(h, inv)) break;
        spn__sym_mul(inv, f, dx);
        const double de = hub_energy_delta(e, i, dx);
        if (!(de < 0)) break;
        for (int c = 0; c < 3; c++) e->x[3 * (size_t)i + c] += dx[c];
        change += de;
    }
    return change;
}

/* The multigrid instead of the cyclic preconditioner from now on (auto). */
static void to_multigrid(newton *nt)
{
    spn__cyc_free(nt->pc.cyc);
    nt->pc.cyc = NULL;
    nt->pc.kind = SPN_PRECOND_MULTIGRID;
    nt->rep.preconditioner = SPN_PRECOND_MULTIGRID;
    nt->auto_cyclic = false;
}

/* One Newton iteration. Returns 1 to go on, 0 when stalled. */
static int newton_iteration(newton *nt)
{
    spn__eq *e = &nt->e;
    size_t n3 = 3 * (size_t)e->n;
    spn_status st = spn__precond_setup(&nt->pc, e);
    if (st == SPN_ERR_NOMEM) {
        nt->status = st;
        return 0;
    }
    if (st != SPN_OK) { /* a particle without stiffness, or a coarse level not positive definite */
        nt->lambda = grow_lambda(nt->lambda);
        nt->residual = spn__eq_assemble(e, nt->lambda, &nt->worst);
        return nt->lambda < LAMBDA_MAX;
    }
    memset(nt->p, 0, n3 * sizeof *nt->p);
    /* |r|_inf <= |r|_2: a linear residual under half the target is all the step can use */
    const int cap = nt->auto_cyclic && nt->max_cg > CYC_GIVE_UP ? CYC_GIVE_UP : nt->max_cg;
    int cg = spn__eq_pcg(e, &nt->pc, nt->p, nt->eta, 0.5 * nt->target, cap, nt->work);
    nt->rep.cg_iterations += cg > 0 ? cg : 0;
    if (nt->auto_cyclic && (cg < 0 || cg >= CYC_GIVE_UP)) to_multigrid(nt); /* from the next step on */
    if (nt->pc.kind == SPN_PRECOND_MULTIGRID && (cg < 0 || (cg > MG_REBUILD_CG && nt->lambda > 0))) {
        spn__mg_free(nt->pc.mg);
        nt->pc.mg = NULL;
    }
    double slope = cg < 0 ? 0 : spn__eq_dot(e, e->f, nt->p);
    if (!(slope > 0)) { /* not a descent direction: the system needs a shift */
        nt->lambda = grow_lambda(nt->lambda);
        nt->residual = spn__eq_assemble(e, nt->lambda, &nt->worst);
        return nt->lambda < LAMBDA_MAX;
    }
    /* Along the web's soft in-plane modes a Newton step can be long enough to
     * leave threads slack, and a slack thread has no stiffness for the next
     * model: cut the step where the first taut thread would go slack. */
    double step = fmax(SLACK_FLOOR, spn__eq_slack_limit(e, nt->p, SLACK_CAP));
    if (step < 1) {
        for (size_t i = 0; i < n3; i++) nt->p[i] *= step;
        slope *= step;
    }
    /* CG from zero keeps p^T A p = f^T p, so the model predicts a drop of slope (1 - step / 2) */
    double de = spn__eq_energy_delta(e, nt->p, 1), rho = isfinite(de) ? -de / (slope * (1 - 0.5 * step)) : -1;
    bool armijo = de <= -ARMIJO * slope, rounding = fabs(de) <= e->noise;
    for (int h = 1; h <= HALVINGS && !armijo && !rounding; h++) { /* shorter steps along p (HALVINGS) */
        const double a = ldexp(1.0, -h), da = spn__eq_energy_delta(e, nt->p, a);
        if (!(da <= -ARMIJO * a * slope)) continue;
        for (size_t i = 0; i < n3; i++) nt->p[i] *= a;
        slope *= a, de = da;
        armijo = true;
        rho = 0; /* the model was wrong at full length: the shift grows (below) */
        nt->rep.backtracks++;
    }
    if (!armijo && !rounding) { /* the model was wrong: shift and retry */
        nt->rep.backtracks++;
        nt->lambda = fmax(LAMBDA_FIRST, 4 * nt->lambda);
        nt->residual = spn__eq_assemble(e, nt->lambda, &nt->worst);
        return nt->lambda < LAMBDA_MAX;
    }
    if (!armijo) rho = 1; /* the energy cannot tell: the residual decides below */
    double previous = nt->residual, lambda = nt->lambda;
    if (rho > 0.75) nt->lambda = nt->lambda > 1e-9 ? nt->lambda / 3 : 0;
    else if (rho < 0.25) nt->lambda = fmax(LAMBDA_FIRST, 2 * nt->lambda);
    swap_positions(e);
    double relaxed = 0;
    for (uint32_t k = 0; k < nt->nhubs; k++) relaxed += relax_hub(e, nt->hubs[k]);
    nt->residual = spn__eq_assemble(e, nt->lambda, &nt->worst);
    if (!armijo && !(nt->residual < previous)) { /* a step lost in rounding that did not help: undo */
        swap_positions(e);
        nt->lambda = lambda;
        nt->residual = spn__eq_assemble(e, nt->lambda, &nt->worst);
        return ++nt->stalls < STALL_LIMIT;
    }
    nt->energy_change += de + relaxed;
    nt->stalls = 0;
    nt->eta = forcing(nt, previous);
    return 1;
}

static void run(newton *nt, const spn_equilibrium_def *d)
{
    spn__eq *e = &nt->e;
    nt->rep.force_scale = d->force_scale > 0 ? d->force_scale : auto_force_scale(e);
    nt->target = fmax(d->abs_tolerance, d->tolerance * nt->rep.force_scale);
    nt->max_cg = d->max_cg_iterations;
    bool mg = nt->pc.kind == SPN_PRECOND_MULTIGRID || nt->pc.kind == SPN_PRECOND_CYCLIC;
    nt->eta = mg ? ETA0_MG : ETA0;
    nt->eta_max = mg ? ETA_MAX_MG : ETA_MAX;
    nt->residual = spn__eq_assemble(e, 0, &nt->worst);
    nt->rep.residual_start = fmax(nt->residual, e->iso_force);
    nt->rep.reason = SPN_EQUILIBRIUM_MAX_ITERATIONS;
    while (isfinite(nt->residual)) {
        if (nt->residual <= nt->target && nt->lambda == 0) {
            nt->rep.reason = SPN_EQUILIBRIUM_CONVERGED;
            break;
        }
        if (nt->residual <= nt->target) { /* measured with a shifted diagonal: drop the shift */
            nt->lambda = 0;
            nt->residual = spn__eq_assemble(e, 0, &nt->worst);
            continue;
        }
        if (nt->rep.iterations >= d->max_iterations) break;
        nt->rep.iterations++;
        if (!newton_iteration(nt)) {
            nt->rep.reason = SPN_EQUILIBRIUM_STALLED;
            break;
        }
        if (nt->status != SPN_OK) break;
    }
    if (e->iso_force > nt->residual || e->n == 0) {
        nt->residual = fmax(nt->residual, e->iso_force);
        if (e->iso_force > nt->target) nt->rep.reason = SPN_EQUILIBRIUM_STALLED;
        nt->worst = UINT32_MAX;
    }
}

/* Copy the result into the world, if it is finite; fill the report. */
static spn_status write_back(newton *nt, spn_world *w, spn_equilibrium_report *report)
{
    spn__eq *e = &nt->e;
    for (size_t c = 0; c < 3 * (size_t)e->n; c++)
        if (!isfinite(e->x[c]))
            return spn_error(SPN_ERR_UNSTABLE, "equilibrium: particle %u reached a non-finite position",
                             e->world_id[c / 3]);
    if (!isfinite(nt->residual))
        return spn_error(SPN_ERR_UNSTABLE, "equilibrium: the residual force became non-finite");
    double moved = 0;
    for (uint32_t i = 0; i < e->n; i++) {
        uint32_t id = e->world_id[i];
        spn_vec3 x = spn_v3(e->x[3 * i], e->x[3 * i + 1], e->x[3 * i + 2]);
        moved = fmax(moved, spn_v3_len(spn_v3_sub(x, spn_world_position(w, id))));
        spn_world_set_position(w, id, x);
        spn_world_set_velocity(w, id, spn_v3(0, 0, 0));
    }
    nt->rep.residual = nt->residual;
    nt->rep.energy_change = nt->energy_change;
    nt->rep.max_displacement = moved;
    nt->rep.worst = nt->worst == UINT32_MAX ? e->iso_worst : (e->n ? e->world_id[nt->worst] : 0);
    if (report) *report = nt->rep;
    return SPN_OK;
}

/* Resolve SPN_PRECOND_AUTO, and build the cyclic preconditioner's lattice
 * where it is asked for or chosen. */
static spn_status choose_preconditioner(newton *nt)
{
    const char *why = NULL;
    if (nt->pc.kind == SPN_PRECOND_CYCLIC) {
        nt->pc.cyc = spn__cyc_build(&nt->e, &why);
        if (!nt->pc.cyc)
            return spn_error(strcmp(why, "out of memory") == 0 ? SPN_ERR_NOMEM : SPN_ERR_INVALID,
                             "equilibrium: the cyclic preconditioner needs a hub + rings x radials web: %s", why);
        return SPN_OK;
    }
    if (nt->pc.kind != SPN_PRECOND_AUTO) return SPN_OK;
    nt->pc.cyc = spn__cyc_build(&nt->e, &why);
    if (nt->pc.cyc) {
        nt->pc.kind = SPN_PRECOND_CYCLIC;
        nt->auto_cyclic = true;
        return SPN_OK;
    }
    spn__cyc_free(nt->pc.cyc);
    nt->pc.cyc = NULL;
    /* the crossover measured on the standard web (bench_equilibrium) */
    nt->pc.kind = nt->e.n < AUTO_MULTIGRID ? SPN_PRECOND_BLOCK_JACOBI : SPN_PRECOND_MULTIGRID;
    return SPN_OK;
}

spn_status spn_world_equilibrium(spn_world *w, const spn_equilibrium_def *def, spn_equilibrium_report *report)
{
    spn_equilibrium_def d = def ? *def : spn_equilibrium_def_default();
    if (report) memset(report, 0, sizeof *report);
    if (!w) return spn_error(SPN_ERR_INVALID, "equilibrium: world is NULL");
    spn_status st = check_def(w, &d);
    if (st != SPN_OK) return st;
    newton nt;
    memset(&nt, 0, sizeof nt);
    nt.pc.kind = d.preconditioner;
    st = spn__eq_init(&nt.e, w, &d);
    if (st != SPN_OK) return st;
    if (!find_hubs(&nt)) {
        spn__eq_free(&nt.e);
        return spn_error(SPN_ERR_NOMEM, "equilibrium: out of memory");
    }
    st = choose_preconditioner(&nt);
    if (st != SPN_OK) {
        free(nt.hubs);
        spn__eq_free(&nt.e);
        return st;
    }
    nt.rep.preconditioner = nt.pc.kind;
    size_t n3 = 3 * (size_t)(nt.e.n ? nt.e.n : 1);
    nt.p = spn__big_alloc(n3 * sizeof *nt.p);
    nt.work = spn__big_alloc(4 * n3 * sizeof *nt.work);
    if (!nt.p || !nt.work) {
        st = spn_error(SPN_ERR_NOMEM, "equilibrium: out of memory");
    } else {
        run(&nt, &d);
        st = nt.status != SPN_OK ? nt.status : write_back(&nt, w, report);
    }
    free(nt.p);
    free(nt.work);
    free(nt.hubs);
    spn__precond_free(&nt.pc);
    spn__eq_free(&nt.e);
    return st;
}
