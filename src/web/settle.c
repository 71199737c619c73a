/* Settling a freshly built web. Strands are laid over-extended, so a new web
 * is far from rest. The rest state is where the springs and gravity balance,
 * so it is first solved for directly (spn_world_equilibrium, Newton on the
 * potential). Where that solve does not reach the target, the web steps in
 * time from as it was built: a step the integrator can take, air drag added
 * while the web comes to rest (drag changes the path, not the equilibrium: at
 * rest it exerts nothing), until the largest residual force is a small
 * fraction of a mean particle's weight or thread tension (implicit steps: and
 * a hundredth of the lightest particle's weight) and the kinetic energy is
 * negligible. Implicit steps whose solve stops at its cap are held to
 * creating no energy (spn_world_set_energy_limit), the cap starts at 100
 * CG iterations (step_to_rest), and CG runs with the cyclic or multigrid
 * preconditioner to a tolerance of 1e-6 (SETTLE_CG_TOLERANCE).
 *
 * Why both (measured 2026-12-05, docs/web-builders.md, "Settling"): the solve
 * takes the Araneus and the physical webs to rest in 0.03 to 0.25 s of CPU
 * where stepping took 0.9 to 2.7 s, at the same rest state (1e-11 m apart on
 * the Araneus web); on the other species webs and the geometric web (light
 * particles between nearly slack threads, where the Newton model holds for
 * steps of a few percent) it runs out of Newton steps or stalls. */
#include "web_internal.h"

#include "spinneret/equilibrium.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Newton steps the equilibrium solve may take before the web steps in time
 * instead. Where it reaches rest it does so in 3 to 33 (the physical webs,
 * Araneus seeds 2 and 3, generic seed 4); where it does not it crawls
 * (hundreds of steps cut to a few percent), and 50 bound what that costs
 * (docs/web-builders.md, "Settling"). */
#define SETTLE_NEWTON_STEPS 50
/* The solve goes in rounds of this many Newton steps, and stops when a round
 * has not halved the residual: where it converges it does (Araneus seed 2:
 * 9.8e-4, 1.2e-4, 2.2e-5 N after 10, 20, 30 steps, then 1e-12 at 36); where
 * it crawls it does not (a physical web 1.4 m wide: 5e-3 N at the start,
 * 3.3e-3 after 10 steps, 2.0e-3 after 50), and 50 steps there cost 1.7 s of
 * the 6 s its settle took, and the CLI fuzzer's 25 s limit under the
 * sanitizers. */
#define SETTLE_NEWTON_ROUND 10
/* CG iterations an implicit settling step may take at first. On the
 * species webs below 4,096 particles (block Jacobi) nearly every step hit
 * the default cap of 1,000 (light particles between nearly slack threads),
 * and that was the settle's cost. With unfinished steps held to creating no
 * energy, CPU s of `build --species ... --settle` by cap (1,000 / 300 / 100 /
 * 30; Zen 4): generic seed 3 13.6 / 3.9 / 2.5 / 2.8, Araneus seed 4 1.0 /
 * 0.8 / 0.4 / 0.7, Zygiella seed 3 7.1 / 1.2 / 0.8 / 1.6, Argiope seed 1
 * (multigrid) 7.9 / 6.8 / 5.8 / 6.5 (the cap then doubled only under the
 * rest floor; see step_to_rest). */
#define SETTLE_CG_CAP 100
#define SETTLE_STALE 4 /* intervals without progress before the CG cap doubles (step_to_rest) */
/* The implicit settling steps' preconditioner and CG tolerance (the world's
 * own where it chose a preconditioner, or where its tolerance is looser;
 * both restored after). Only where the web comes to rest matters, not the
 * path, and the settle tests rest on the true forces. Below 4,096 particles
 * the world's auto choice is block Jacobi, which needs few iterations on a
 * moving web, but on a web creeping to rest it hit the cap of 100 at every
 * 5 ms step. Here the cyclic preconditioner (the multigrid on webs other
 * than hub + rings x radials) at 1e-6. CPU s of spn_web_settle, Zen 4, one
 * run each (docs/web-builders.md, "Settling"), before -> now: Zilla seeds
 * 2, 4, 6, 7 2.68 / 0.75 / 0.64 / 5.73 -> 1.24 / 0.69 / 0.85 / 0.56;
 * Zygiella 5 and 7 0.41 / 0.50 -> 0.12 / 0.14; the README's geometric web
 * 5.08 -> 1.27; 20 webs that step, 83 -> 49 s. Rest states within 4e-5 um
 * (Zilla 7) and 0.8 um (geometric) of before. A step whose CG stops at its
 * tolerance is taken whole (SPN_ENERGY_LIMIT_UNFINISHED), and at 1e-5 two
 * geometric webs were kicked about by such steps and never came to rest
 * (at 1e-4 four of ten), until step_to_rest held every step once the web
 * stops making progress. 1e-8: 57 s for the 20. */
#define SETTLE_CG_TOLERANCE 1e-6

static double stable_step(const spn_world *w)
{
    /* Backward Euler is stable at any step; long steps walk the web to its
     * equilibrium in few (if costlier) solves. */
    if (spn_world_get_def(w)->integrator == SPN_INTEGRATOR_IMPLICIT) return 0.005;
    double best = 1e-3;
    uint32_t ns = spn_world_spring_count(w);
    for (uint32_t s = 0; s < ns; s++) {
        spn_spring_info si = spn_world_spring(w, s);
        if (si.broken || !(si.k > 0)) continue;
        double ma = spn_world_is_fixed(w, si.a) ? INFINITY : spn_world_mass(w, si.a);
        double mb = spn_world_is_fixed(w, si.b) ? INFINITY : spn_world_mass(w, si.b);
        double m = fmin(ma, mb);
        if (isfinite(m)) best = fmin(best, 0.35 * sqrt(m / si.k));
    }
    return best;
}

/* Whether the static equilibrium is the rest state stepping would reach:
 * nothing but springs, gravity and damping acts on the web. */
static bool equilibrium_applies(const spn_world *w)
{
    void *user;
    double rho, mu;
    return !spn_world_force_callback(w, &user) && !spn_world_air(w, &user, &rho, &mu) &&
           !spn_world_collide_callback(w, &user) && spn_world_collider_count(w) == 0 &&
           !(spn_world_get_def(w)->provot_max_strain > 0);
}

/* Whether some intact spring lies outside its break limits (breakage on). */
static bool would_break(const spn_world *w)
{
    if (!spn_world_get_def(w)->breakage) return false;
    for (uint32_t s = 0; s < spn_world_spring_count(w); s++) {
        spn_spring_info si = spn_world_spring(w, s);
        if (!si.broken && !(si.length >= si.break_min && si.length <= si.break_max)) return true;
    }
    return false;
}

/* The mass of the lightest free particle (INFINITY when none is free). */
static double lightest_mass(const spn_world *w)
{
    double lightest = INFINITY;
    for (uint32_t i = 0; i < spn_world_particle_count(w); i++)
        if (!spn_world_is_fixed(w, i)) lightest = fmin(lightest, spn_world_mass(w, i));
    return lightest;
}

/* The static equilibrium, in rounds of SETTLE_NEWTON_ROUND steps given up
 * after one that has not halved the residual. Not from where an unfinished
 * solve stopped: on the Argiope web stepping from there had not come to
 * rest after 13 minutes of CPU, against 8 s from the web as built; so an
 * unfinished solve puts the web back. The target is also a hundredth of the
 * lightest particle's weight: the solve sets every velocity to 0, so no
 * kinetic-energy test can catch a particle that would still fall, and with
 * a tension threshold alone (2e-8 N on the species webs, ten times a glue
 * droplet's weight) it called the generic web at rest with three particles
 * afloat between slack threads, 1 mm above where stepping hangs them. */
spn_status spn_web_solve_rest(spn_world *w, double target, int max_steps, bool *solved, spn_settle_report *report)
{
    const double g = spn_v3_len(spn_world_get_def(w)->gravity), lightest = lightest_mass(w);
    if (isfinite(lightest) && g > 0) target = fmin(target, 1e-2 * g * lightest);
    *solved = false;
    memset(report, 0, sizeof *report);
    report->reason = SPN_SETTLE_TIMEOUT;
    if (!equilibrium_applies(w) || max_steps < 1) return SPN_OK;
    int *newton_steps = &report->newton_steps;
    uint32_t np = spn_world_particle_count(w);
    spn_vec3 *x = malloc((np ? np : 1) * sizeof *x), *v = malloc((np ? np : 1) * sizeof *v);
    if (!x || !v) {
        free(x), free(v);
        return spn_error(SPN_ERR_NOMEM, "settle: out of memory");
    }
    for (uint32_t i = 0; i < np; i++) x[i] = spn_world_position(w, i), v[i] = spn_world_velocity(w, i);
    spn_equilibrium_def d = spn_equilibrium_def_default();
    d.tolerance = 0;
    d.abs_tolerance = target;
    d.max_iterations = max_steps < SETTLE_NEWTON_ROUND ? max_steps : SETTLE_NEWTON_ROUND;
    spn_equilibrium_report rep;
    spn_status st;
    double last = INFINITY;
    for (;;) { /* rounds, each from where the last stopped */
        st = spn_world_equilibrium(w, &d, &rep);
        *newton_steps += rep.iterations;
        if (st != SPN_OK || rep.reason != SPN_EQUILIBRIUM_MAX_ITERATIONS || *newton_steps >= max_steps) break;
        if (!(rep.residual < 0.5 * fmin(last, rep.residual_start))) break;
        last = rep.residual;
        if (d.max_iterations > max_steps - *newton_steps) d.max_iterations = max_steps - *newton_steps;
    }
    if (st == SPN_ERR_NOMEM) {
        free(x), free(v);
        return st;
    }
    *solved = st == SPN_OK && rep.reason == SPN_EQUILIBRIUM_CONVERGED && !would_break(w);
    if (*solved) {
        report->reason = SPN_SETTLE_CONVERGED;
        report->residual = spn_world_max_residual(w, NULL);
        report->total_energy = spn_world_total_energy(w);
    } else
        for (uint32_t i = 0; i < np; i++) spn_world_set_position(w, i, x[i]), spn_world_set_velocity(w, i, v[i]);
    free(x), free(v);
    return SPN_OK;
}

/* Implicit steps to rest, one check interval (0.25 s) at a time: CG starts
 * at SETTLE_CG_CAP iterations a step, and the cap doubles, up to the world's
 * own, whenever SETTLE_STALE intervals in a row have not brought the
 * residual under half its last mark: a web that creeps needs the longer
 * solves. From then on every step is also held to creating no energy
 * (SPN_ENERGY_LIMIT_ALWAYS), not only those whose CG ran out: with the
 * multigrid the solves finish, and a thin-moored 5 cm Zygiella web
 * (test_zygiella_comes_to_rest) cycled through the same states, a thread
 * going slack and taut in turn, at a residual of 1e-8 N for all of its 30 s
 * (now at rest after 1.5 s; holding every step from the start instead made
 * Zilla seed 7 and the geometric webs two to ten times slower). The cap's
 * rule (thirty-first session, block Jacobi): Zilla seed 6 crept at 1e-7 to
 * 1e-6 N from 2 to 18 s of simulated time with the cap at 100, and came to
 * rest at 28 s when the cap doubled only under the rest floor; with this
 * rule at 11.9 s (46 s of CPU, was 60), Zilla seed 3 in 5.6 s of CPU (was
 * 9.2). Doubling it after any one interval that had not halved the
 * residual took generic seed 3 from 2.1 to 6.0 s (its early intervals go
 * up and down). */
static spn_status step_to_rest(spn_world *w, const spn_settle_def *def, int cg_cap, spn_settle_report *report)
{
    memset(report, 0, sizeof *report);
    spn_settle_def sd = *def;
    const double tolerance = fmax(spn_world_get_def(w)->cg_tolerance, SETTLE_CG_TOLERANCE);
    int cap = cg_cap < SETTLE_CG_CAP ? cg_cap : SETTLE_CG_CAP;
    double elapsed = 0, mark = INFINITY;
    int stale = 0;
    for (;;) {
        sd.max_time = fmin(def->check_interval, def->max_time - elapsed);
        spn_status st = spn_world_set_solver_tolerance(w, tolerance, cap);
        spn_settle_report part;
        if (st == SPN_OK) st = spn_world_settle(w, &sd, &part);
        if (st != SPN_OK) return st;
        elapsed += part.time;
        report->time += part.time;
        report->steps += part.steps;
        report->reason = part.reason;
        report->kinetic = part.kinetic;
        report->residual = part.residual;
        report->total_energy = part.total_energy;
        if (part.reason == SPN_SETTLE_CONVERGED || elapsed >= def->max_time - 1e-9 * def->dt || part.steps == 0)
            return SPN_OK;
        if (part.residual < 0.5 * mark) {
            mark = part.residual;
            stale = 0;
        } else if (++stale >= SETTLE_STALE) {
            cap = cap < cg_cap / 2 ? 2 * cap : cg_cap;
            st = spn_world_set_energy_limit(w, SPN_ENERGY_LIMIT_ALWAYS);
            if (st != SPN_OK) return st;
            stale = 0;
        }
    }
}

spn_status spn_web_settle(spn_world *w, double max_time, spn_settle_report *report)
{
    double lightest = lightest_mass(w);
    if (!isfinite(lightest)) lightest = 1e-9;
    uint32_t np = spn_world_particle_count(w);
    /* At rest: no particle feels more than a thousandth of a mean particle's
     * weight or a hundred-thousandth of a mean thread tension. */
    double mass = 0, tension = 0;
    for (uint32_t i = 0; i < np; i++) mass += spn_world_mass(w, i);
    uint32_t ns = spn_world_spring_count(w);
    for (uint32_t s = 0; s < ns; s++) tension += spn_world_spring(w, s).tension;
    double floor_force = fmax(1e-3 * 9.81 * mass / (np ? np : 1), 1e-5 * tension / (ns ? ns : 1));
    bool solved; /* to floor_force and a hundredth of the lightest particle's weight */
    spn_status st = spn_web_solve_rest(w, floor_force, SETTLE_NEWTON_STEPS, &solved, report);
    if (st != SPN_OK || solved) return st;
    const int newton_steps = report->newton_steps;
    const bool implicit = spn_world_get_def(w)->integrator == SPN_INTEGRATOR_IMPLICIT;
    spn_settle_def sd = spn_settle_def_default();
    sd.dt = stable_step(w);
    sd.max_time = max_time;
    /* Implicit steps held to creating no energy (below) lose kinetic energy
     * where they are cut, so a web can look at rest while it still creeps:
     * they settle to the solve's target. At the looser floor alone (every
     * step held, in a trial) a Zilla and a Zygiella web stopped 80 um from
     * their rest, at a residual of 1e-8 N. */
    sd.max_residual = implicit ? fmin(floor_force, 1e-2 * 9.81 * lightest) : floor_force;
    sd.max_kinetic = 1e-9 * lightest * 9.81 * 1e-3 * np;
    sd.check_interval = fmax(50 * sd.dt, 0.02);
    /* About critical for the web's slow modes (a few Hz). */
    sd.drag = SPN_SETTLE_DRAG;
    /* A web as built is far from rest, and an implicit step that goes wrong
     * there (threads going slack within it, CG out of iterations) can create
     * energy: on Zilla seed 6 the steps stretched capture threads 3,000-fold
     * and the settle gave up after 30 s with a residual of 666 N. A step
     * whose solve stopped at its cap is held to creating none; one whose solve
     * converged is taken whole, as before (holding those too cut most of the
     * Argiope web's steps 2 to 7 times: seed 1 settled in 15.7 s of CPU, not
     * 6). So a rough step is safe, and CG stops sooner (step_to_rest). */
    const spn_energy_limit limit = spn_world_energy_limit(w);
    const spn_precond pc = spn_world_implicit_preconditioner(w);
    const spn_world_def *def = spn_world_get_def(w);
    const double cg_tolerance = def->cg_tolerance;
    const int cg_cap = def->cg_max_iterations;
    st = spn_world_set_energy_limit(w, SPN_ENERGY_LIMIT_UNFINISHED);
    if (st == SPN_OK && implicit && pc == SPN_PRECOND_AUTO)
        st = spn_world_set_implicit_preconditioner(w, SPN_PRECOND_CYCLIC); /* SETTLE_CG_TOLERANCE */
    if (st == SPN_OK) st = implicit ? step_to_rest(w, &sd, cg_cap, report) : spn_world_settle(w, &sd, report);
    spn_world_set_solver_tolerance(w, cg_tolerance, cg_cap);
    spn_world_set_implicit_preconditioner(w, pc);
    spn_world_set_energy_limit(w, limit);
    report->newton_steps = newton_steps;
    return st;
}
