/* The step driver: integrate, then collide, limit deformation (Provot), check
 * for a blow-up, and only then commit the time and break springs.
 *
 * Blow-up: a non-finite position or velocity, or an energy jump. The
 * integrator reports the change of kinetic + gravitational energy over the
 * step (summed per particle, so it is accurate), the elastic energy before it
 * and the external work. The step created energy from nothing if
 *   gain = dKE + dPE - E_elastic,before - W_external
 * is positive (the new elastic energy is at least zero, so this is a lower
 * bound of the energy created); it has blown up when the gain exceeds
 * def.energy_jump times the energy in play (KE + elastic before, plus |W|
 * and what gravity gives in one step, M g^2 dt^2).
 * The world then gets back the state from before the step, and the message
 * names the step and the particle (first non-finite one, or the fastest).
 *
 * Breakage is checked after the step is accepted, so nothing changes the
 * graph in the middle of a step, and each spring breaks, and is reported, once. */
#include "world_internal.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* The particle to name in a blow-up: the first non-finite one, or the one
 * with the largest kinetic energy. */
static uint32_t culprit(const spn_world *w, bool *nonfinite)
{
    uint32_t best = 0;
    double top = -1;
    for (uint32_t i = 0; i < w->np; i++) {
        if (!spn_v3_finite(w->x[i]) || !spn_v3_finite(w->v[i])) {
            *nonfinite = true;
            return i;
        }
        double e = w->mass[i] * spn_v3_dot(w->v[i], w->v[i]);
        if (w->inv_mass[i] > 0 && e > top) {
            top = e;
            best = i;
        }
    }
    *nonfinite = false;
    return best;
}

static spn_status blew_up(spn_world *w, double dt, double gain)
{
    bool nonfinite;
    uint32_t i = culprit(w, &nonfinite);
    memcpy(w->x, w->x0, w->np * sizeof *w->x);
    memcpy(w->v, w->v0, w->np * sizeof *w->v);
    if (nonfinite)
        return spn_error(SPN_ERR_UNSTABLE,
                         "simulation blew up at step %llu (t = %g s, %s, dt = %g s): particle %u is not finite",
                         (unsigned long long)w->steps + 1, w->t + dt, spn_integrator_name(w->def.integrator), dt, i);
    char jump[64], advice[320];
    if (isfinite(gain)) snprintf(jump, sizeof jump, "energy jumped by %g J", gain);
    else snprintf(jump, sizeof jump, "energy overflowed");
    /* The adaptive stepper shortens its sub-steps by itself: if it blew up
     * after sub-steps at its floor (only it counts them), the floor was too
     * long, and a shorter outer step would not help. */
    if (w->last.floored > 0)
        snprintf(advice, sizeof advice,
                 "%d sub-steps gained energy at the adaptive stepper's floor of %g s (dt_min, or the springs' "
                 "stable step where shorter; callback, air and collider forces are not in that bound): "
                 "set dt_min under %g s or use the implicit solver",
                 w->last.floored, w->adaptive_floor, w->adaptive_floor);
    else snprintf(advice, sizeof advice, "try a smaller step or the implicit solver");
    return spn_error(SPN_ERR_UNSTABLE,
                     "simulation blew up at step %llu (t = %g s, %s, dt = %g s): %s, fastest particle %u; %s",
                     (unsigned long long)w->steps + 1, w->t + dt, spn_integrator_name(w->def.integrator), dt, jump, i,
                     advice);
}

static spn_status integrate(spn_world *w, double dt, spn__step_result *r)
{
    switch (w->def.integrator) {
    case SPN_INTEGRATOR_EULER: spn__step_explicit(w, dt, false, r); return SPN_OK;
    case SPN_INTEGRATOR_SYMPLECTIC: spn__step_explicit(w, dt, true, r); return SPN_OK;
    case SPN_INTEGRATOR_RK4: return spn__step_rk4(w, dt, r);
    case SPN_INTEGRATOR_ADAPTIVE: return spn__step_adaptive(w, dt, r);
    case SPN_INTEGRATOR_IMPLICIT: return spn__step_implicit(w, dt, r);
    default: return spn_error(SPN_ERR_INVALID, "integrator %d does not exist", (int)w->def.integrator);
    }
}

/* The rest of a step once the integrator has moved the state and reported
 * r: the blow-up check, collisions, deformation limits, the energy books,
 * time and breakage. Without a backup (w->no_backup) a blow-up leaves the
 * broken state in place and returns SPN_ERR_UNSTABLE with no message:
 * spn_world_advance restores and replays. */
static spn_status accept(spn_world *w, double dt, const spn__step_result *r)
{
    double gain = r->gain_kp - r->elastic - r->work;
    /* Energy in play; gravity alone gives m g^2 dt^2 per step (forward
     * Euler gains half of that from rest). */
    double g2 = spn_v3_dot(w->def.gravity, w->def.gravity);
    double scale = r->e_before + fabs(r->work) + w->free_mass * g2 * dt * dt;
    if (!isfinite(r->kinetic) || !isfinite(r->gain_kp) || gain > w->def.energy_jump * scale + 1e-300)
        return w->no_backup ? SPN_ERR_UNSTABLE : blew_up(w, dt, gain);
    double lost = 0;
    if (w->ncolliders || w->collide_fn) lost += spn__collide(w, dt);
    if (w->def.provot_max_strain > 0) lost += spn__provot(w, dt);
    w->external_work += r->work;
    w->dissipated += r->dissipated + lost;
    w->t += dt;
    w->steps++;
    w->last.breaks = spn__check_breakage(w);
    return SPN_OK;
}

static void reset_last(spn_world *w, double dt)
{
    memset(&w->last, 0, sizeof w->last);
    w->last.dt = dt;
    w->last.substeps = 1;
}

/* One step of a compiled world (see accept for a blow-up). */
static spn_status step_once(spn_world *w, double dt)
{
    reset_last(w, dt);
    spn__step_result r;
    memset(&r, 0, sizeof r);
    if (w->nhyst) spn__hysteresis_prepare(w, dt);
    spn_status st = integrate(w, dt, &r);
    return st != SPN_OK ? st : accept(w, dt, &r);
}

/* Up to `left` steps of a replayable run as one blocked lattice pass, each
 * then accepted in turn; the steps accepted in *done (all, or up to the one
 * that blew up, whose status is returned). 0 steps when no blocked pass
 * applies. */
static spn_status block_steps(spn_world *w, double dt, int left, int *done)
{
    *done = 0;
    spn__step_result r[SPN__LAT_BLOCK_MAX];
    memset(r, 0, sizeof r);
    const int k = spn__lattice_block_steps(w, dt, left, r);
    for (int q = 0; q < k; q++) {
        reset_last(w, dt);
        spn_status st = accept(w, dt, &r[q]);
        if (st != SPN_OK) return st;
        ++*done;
    }
    return SPN_OK;
}

static spn_status check_dt(double dt)
{
    if (!(dt > 0) || !isfinite(dt)) return spn_error(SPN_ERR_INVALID, "time step must be positive and finite, not %g", dt);
    return SPN_OK;
}

spn_status spn_world_step(spn_world *w, double dt)
{
    spn_status st = check_dt(dt);
    if (st == SPN_OK) st = spn_world_compile(w);
    if (st != SPN_OK) return st;
    return step_once(w, dt);
}

/* Steps that a replay from a saved state reproduces exactly, with nothing
 * outside x and v touched: explicit and RK4 steps with no callbacks, no
 * colliders, no Provot limits and no spring that can break. */
static bool replayable(const spn_world *w)
{
    const spn_integrator in = w->def.integrator;
    if (in != SPN_INTEGRATOR_EULER && in != SPN_INTEGRATOR_SYMPLECTIC && in != SPN_INTEGRATOR_RK4) return false;
    if (w->force_fn || (w->air_fn && w->any_diam) || w->collide_fn || w->ncolliders) return false;
    return !(w->def.provot_max_strain > 0) && !(w->def.breakage && w->any_limits);
}

static void add_step(spn_step_report *total, const spn_step_report *last)
{
    total->substeps += last->substeps;
    total->halvings += last->halvings;
    total->cuts += last->cuts;
    total->floored += last->floored;
    total->cg_iterations += last->cg_iterations;
    total->breaks += last->breaks;
}

/* An spn_world_advance call's steps (advance_steps). */
typedef struct {
    double dt;
    int n;
    bool replay;
    spn_step_report total;
} advance_run;

/* The steps of an advance call, the state at its start in x0 and v0 when
 * replayable (spn_world_advance). */
static spn_status advance_steps(spn_world *w, void *ctx)
{
    advance_run *a = ctx;
    const double dt = a->dt, t0 = w->t, work0 = w->external_work, diss0 = w->dissipated;
    const uint64_t steps0 = w->steps;
    spn_step_report *total = &a->total;
    spn_status st = SPN_OK;
    for (int j = 0; j < a->n;) {
        int done = 0;
        st = a->replay ? block_steps(w, dt, a->n - j, &done) : SPN_OK;
        j += done, total->substeps += done, total->blocked += done; /* (one sub-step each, no breaks) */
        if (st == SPN_OK && done == 0) {
            st = step_once(w, dt);
            if (st == SPN_OK) j++, add_step(total, &w->last);
        }
        if (st == SPN_ERR_UNSTABLE && w->no_backup) {
            spn__lattice_discard(w);
            memcpy(w->x, w->x0, w->np * sizeof *w->x);
            memcpy(w->v, w->v0, w->np * sizeof *w->v);
            w->t = t0, w->external_work = work0, w->dissipated = diss0, w->steps = steps0;
            for (int q = 0; q < j; q++) step_once(w, dt);
            w->no_backup = false;
            st = step_once(w, dt);
            if (st == SPN_OK) j++, add_step(total, &w->last);
        }
        if (st != SPN_OK) break;
    }
    return st;
}

/* Replayable runs keep one copy of the state per call, in x0 and v0, instead
 * of one per step. On a blow-up at step j the world goes back to that copy,
 * replays the j good steps (bit-identical: same world, same calls) and takes
 * step j again with a backup, which fails as before and restores the state
 * from before it, with the usual message. A replayable run on the lattice
 * with threads keeps them as a team for the whole call (lattice_team.c). */
spn_status spn_world_advance(spn_world *w, double dt, int n)
{
    spn_status st = check_dt(dt);
    if (st != SPN_OK) return st;
    if (n < 1) return spn_error(SPN_ERR_INVALID, "spn_world_advance: step count must be at least 1, not %d", n);
    st = spn_world_compile(w);
    if (st != SPN_OK) return st;
    advance_run a = {.dt = dt, .n = n, .replay = n > 1 && replayable(w), .total = {.dt = dt}};
    if (a.replay) {
        memcpy(w->x0, w->x, w->np * sizeof *w->x);
        memcpy(w->v0, w->v, w->np * sizeof *w->v);
        w->no_backup = true;
        st = spn__lattice_team_call(w, spn__lattice_team_threads(w), advance_steps, &a);
    } else {
        st = advance_steps(w, &a);
    }
    spn__lattice_sync(w);
    w->no_backup = false;
    w->last = a.total;
    return st;
}

spn_energy spn_world_energy(const spn_world *w)
{
    spn_energy e;
    e.kinetic = spn__kinetic_energy(w, w->v);
    e.elastic = spn__elastic_energy(w, w->x);
    e.gravitational = spn__gravity_energy(w, w->x);
    e.external_work = w->external_work;
    e.dissipated = w->dissipated;
    return e;
}

double spn_world_total_energy(const spn_world *w)
{
    spn_energy e = spn_world_energy(w);
    return e.kinetic + e.elastic + e.gravitational;
}
