/* Settling to rest (Juhasz & Bercovici's stabilisation loop, with a residual
 * test added): step until the kinetic energy and the largest static force on
 * a free particle are both under their thresholds, or the time runs out. The
 * residual is evaluated at zero velocity, so damping does not hide a force
 * that is still unbalanced. */
#include "world_internal.h"

#include <math.h>
#include <string.h>

double spn_world_max_residual(spn_world *w, uint32_t *which)
{
    if (spn_world_compile(w) != SPN_OK) return NAN;
    /* v0 is step scratch: free between steps, here the zero velocities. */
    memset(w->v0, 0, w->np * sizeof *w->v0);
    spn__eval e;
    spn__eval_forces(w, w->t, w->x, w->v0, w->f, &e);
    double best = 0;
    uint32_t arg = 0;
    for (uint32_t i = 0; i < w->np; i++) {
        if (w->inv_mass[i] == 0) continue;
        double m = spn_v3_len(w->f[i]);
        if (m > best || !(m == m)) {
            best = m;
            arg = i;
            if (!(m == m)) break;
        }
    }
    if (which) *which = arg;
    return best;
}

spn_settle_def spn_settle_def_default(void)
{
    spn_settle_def d;
    d.dt = 1e-3;
    d.max_kinetic = 1e-9;
    d.max_residual = 1e-6;
    d.max_time = 60;
    d.min_time = 0;
    d.check_interval = 0;
    d.drag = 0;
    return d;
}

spn_status spn_world_settle(spn_world *w, const spn_settle_def *def, spn_settle_report *report)
{
    spn_settle_def d = def ? *def : spn_settle_def_default();
    memset(report, 0, sizeof *report);
    if (!(d.dt > 0) || !isfinite(d.dt)) return spn_error(SPN_ERR_INVALID, "settle: dt must be positive, not %g", d.dt);
    if (!(d.max_time >= 0) || !isfinite(d.max_time))
        return spn_error(SPN_ERR_INVALID, "settle: max_time must be finite and not negative, not %g", d.max_time);
    if (!(d.max_kinetic >= 0) || !(d.max_residual >= 0))
        return spn_error(SPN_ERR_INVALID, "settle: max_kinetic and max_residual must not be negative");
    if (!(d.drag >= 0) || !isfinite(d.drag))
        return spn_error(SPN_ERR_INVALID, "settle: drag must be finite and not negative, not %g", d.drag);
    spn_status st = spn_world_compile(w);
    if (st != SPN_OK) return st;
    const double drag = w->def.drag;
    if (d.drag > drag) w->def.drag = d.drag;
    double interval = d.check_interval > 0 ? d.check_interval : 10 * d.dt;
    double t0 = w->t, next_check = t0 + d.min_time;
    uint64_t steps = 0;
    report->reason = SPN_SETTLE_TIMEOUT;
    for (;;) {
        if (w->t >= next_check - 1e-12 * d.dt) {
            next_check = w->t + interval;
            if (spn__kinetic_energy(w, w->v) <= d.max_kinetic && spn_world_max_residual(w, NULL) <= d.max_residual) {
                report->reason = SPN_SETTLE_CONVERGED;
                break;
            }
        }
        if (w->t - t0 >= d.max_time) break;
        st = spn_world_step(w, d.dt);
        if (st != SPN_OK) break;
        steps++;
    }
    w->def.drag = drag;
    if (st != SPN_OK) return st;
    report->time = w->t - t0;
    report->steps = steps;
    report->kinetic = spn__kinetic_energy(w, w->v);
    report->residual = spn_world_max_residual(w, NULL);
    report->total_energy = spn_world_total_energy(w);
    return SPN_OK;
}
