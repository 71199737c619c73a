/* The energy-stable adaptive stepper of Juhasz & Bercovici ("Spring
 * Systems", section Solver). An outer step is split into sub-steps; each
 * sub-step is a symplectic Euler step that must not gain energy beyond the
 * work of the external forces:
 *   dE = dKE + dPE_gravity + dE_elastic <= W_external  (+ a round-off margin).
 * W_external is taken by the trapezoid rule, the external forces at the
 * sub-step's start and at its end (which the energy check evaluates anyway)
 * over its displacement. The original takes the forces at the start only,
 * which overstates a restoring force's work by 1/2 K dx^2: a stiff
 * conservative callback (a tether) then passes an unstable sub-step's gain
 * off as work, and the stepper accepts it at any length. The trapezoid rule
 * is exact for a force linear in position.
 * A sub-step that gains more is undone and retried with the step divided by
 * def.dt_factor, down to a floor: def.dt_min, or less where the springs'
 * stable step is shorter (spring_floor below). A sub-step at the floor is
 * taken as it is, and counted in spn_step_report.floored, so that a blow-up
 * it leads to can say that the floor, not the outer step, is too long. After
 * an accepted sub-step the next one tries the step times dt_factor, and the
 * last accepted size carries over to the next outer step.
 *
 * Why symplectic Euler: its energy change for a spring is
 * 1/2 k h^2 (v'^2 - w^2 x^2)-like, negative near the turning points and
 * small, so damping can pay for it at a moderate step; forward Euler gains
 * 1/2 m h^2 |a|^2 at every turning point, where damping removes nothing, and
 * would always fall to the floor.
 *
 * As in the original, the forces at the end of an accepted sub-step (computed
 * for its energy check: the elastic energy shares the spring pass's square
 * roots) are the forces the next sub-step starts from. The user force
 * callback is therefore also called for trial states that are rejected. */
#include "world_internal.h"

#include <math.h>
#include <string.h>

enum { S_GAIN, S_WORK, S_DRAG };

/* Pointer swap of two per-particle buffers. */
static void swap_buf(spn_vec3 **a, spn_vec3 **b)
{
    spn_vec3 *t = *a;
    *a = *b;
    *b = t;
}

/* Trial symplectic Euler sub-step of size h from the current forces; keeps
 * the state in the backup buffers. Sums the KE+PE change and the work. */
static void trial(spn_world *w, double h, bool ext, double *gain, double *work)
{
    spn_vec3 *x = w->x, *v = w->v, *xs = w->tmp[SPN_TMP_A], *vs = w->tmp[SPN_TMP_B];
    const spn_vec3 *f = w->f, *fext = w->fext, g = w->def.gravity;
    const uint32_t np = w->np, nb = spn__blocks(np);
    double *partial = w->partial;
#pragma omp parallel for schedule(static) num_threads(spn__threads(w, np))
    for (uint32_t blk = 0; blk < nb; blk++) {
        const uint32_t lo = blk * SPN_BLOCK, hi = lo + SPN_BLOCK < np ? lo + SPN_BLOCK : np;
        double dkp = 0, wk = 0;
        for (uint32_t i = lo; i < hi; i++) {
            const spn_vec3 vi = v[i];
            xs[i] = x[i];
            vs[i] = vi;
            const double im = w->inv_mass[i];
            if (im == 0) continue;
            const spn_vec3 vn = spn_v3_add(vi, spn_v3_scale(f[i], h * im));
            const spn_vec3 dx = spn_v3_scale(vn, h);
            x[i] = spn_v3_add(x[i], dx);
            v[i] = vn;
            const double m = w->mass[i];
            dkp += 0.5 * m * spn_v3_dot(spn_v3_sub(vn, vi), spn_v3_add(vn, vi)) - m * spn_v3_dot(g, dx);
            if (ext) wk += spn_v3_dot(fext[i], dx);
        }
        partial[(size_t)blk * SPN_NSUMS + S_GAIN] = dkp;
        partial[(size_t)blk * SPN_NSUMS + S_WORK] = wk;
    }
    double sum[SPN_NSUMS];
    spn__sum_partials(w, nb, sum);
    *gain = sum[S_GAIN];
    *work = sum[S_WORK];
}

/* The work of the external forces at the end of a trial sub-step of size h
 * (w->fext: the forces at its end state) over its displacement, as trial()
 * formed it (v' h). With trial()'s work at the start, the trapezoid rule. */
static double end_work(spn_world *w, double h)
{
    const spn_vec3 *v = w->v, *fext = w->fext;
    const uint32_t np = w->np, nb = spn__blocks(np);
    double *partial = w->partial;
#pragma omp parallel for schedule(static) num_threads(spn__threads(w, np))
    for (uint32_t blk = 0; blk < nb; blk++) {
        const uint32_t lo = blk * SPN_BLOCK, hi = lo + SPN_BLOCK < np ? lo + SPN_BLOCK : np;
        double wk = 0;
        for (uint32_t i = lo; i < hi; i++)
            if (w->inv_mass[i] != 0) wk += spn_v3_dot(fext[i], spn_v3_scale(v[i], h));
        partial[(size_t)blk * SPN_NSUMS + S_WORK] = wk;
    }
    double sum[SPN_NSUMS];
    spn__sum_partials(w, nb, sum);
    return sum[S_WORK];
}

static void undo(spn_world *w)
{
    memcpy(w->x, w->tmp[SPN_TMP_A], w->np * sizeof *w->x);
    memcpy(w->v, w->tmp[SPN_TMP_B], w->np * sizeof *w->v);
}

/* Forces and energies at the current state into the spare buffers; the
 * caller keeps them (swap) or drops them. */
static bool eval_spare(spn_world *w, double t, spn__eval *e)
{
    swap_buf(&w->fext, &w->tmp[SPN_TMP_D]);
    spn__spring_pass(w, t, w->x, w->v, e);
    bool ext = spn__external(w, t, w->x, w->v);
    spn__gather(w, w->x, w->v, ext, w->tmp[SPN_TMP_C], e);
    return ext;
}

/* The floor, once a sub-step would go under def.dt_min (or 1e-12 dt when
 * that is not positive): the shorter of that and SPN_STABLE_REACH of the
 * springs' stable step (stable_step.c; the animation runner's margin for
 * symplectic Euler), so that sub-steps at the floor stay stable whatever
 * dt_min says. Computed at most once an outer step (a pass over springs and
 * particles, no square roots of lengths), and only when the step gets that
 * short. */
static double spring_floor(spn_world *w, double base)
{
    if (spn__scratch(w, SPN_TMP_E + 1) != SPN_OK) return base; /* the floor given, as before */
    return fmin(base, spn__stable_step(w, SPN_STABLE_REACH, 0, (double *)w->tmp[SPN_TMP_E]));
}

spn_status spn__step_adaptive(spn_world *w, double dt, spn__step_result *r)
{
    spn_status st = spn__scratch(w, 4);
    if (st != SPN_OK) return st;
    memcpy(w->x0, w->x, w->np * sizeof *w->x);
    memcpy(w->v0, w->v, w->np * sizeof *w->v);
    spn__eval cur;
    spn__eval_forces(w, w->t, w->x, w->v, w->f, &cur);
    bool ext = w->force_fn || spn__air_active(w);
    r->e_before = cur.kinetic + cur.elastic;
    r->elastic = cur.elastic;
    const double factor = w->def.dt_factor > 1 ? w->def.dt_factor : 2;
    double floor = w->def.dt_min > 0 ? w->def.dt_min : 1e-12 * dt;
    bool floor_known = false; /* floor is spring_floor's */
    double h = w->adaptive_dt > 0 ? w->adaptive_dt : dt;
    double done = 0, gain_kp = 0, work = 0, lost = 0;
    int substeps = 0, halvings = 0, floored = 0;
    while (done < dt) {
        bool capped = h >= dt - done;
        double hh = capped ? dt - done : h;
        double dkp, wk;
        trial(w, hh, ext, &dkp, &wk);
        spn__eval next;
        eval_spare(w, w->t + done + hh, &next);
        if (ext) wk = 0.5 * (wk + end_work(w, hh));
        double gain = dkp + (next.elastic - cur.elastic) - wk;
        double margin = 1e-12 * (cur.kinetic + cur.elastic + fabs(wk)) + 1e-300;
        if (!(gain <= margin)) { /* also when gain is NaN */
            if (!floor_known && hh / factor < floor) floor = spring_floor(w, floor), floor_known = true;
            if (hh > floor) {
                undo(w);
                swap_buf(&w->fext, &w->tmp[SPN_TMP_D]);
                h = hh / factor > floor ? hh / factor : floor;
                halvings++;
                continue;
            }
            floored++;
        }
        swap_buf(&w->f, &w->tmp[SPN_TMP_C]);
        gain_kp += dkp;
        work += wk;
        lost += hh * cur.damp_power;
        cur = next;
        done = capped ? dt : done + hh;
        substeps++;
        if (!isfinite(gain)) break;
        if (!capped) h = hh * factor;
    }
    w->adaptive_dt = h;
    w->adaptive_floor = floor;
    w->last.substeps = substeps;
    w->last.halvings = halvings;
    w->last.floored = floored;
    r->gain_kp = gain_kp;
    r->work = work;
    r->dissipated = lost;
    r->kinetic = cur.kinetic;
    return SPN_OK;
}
