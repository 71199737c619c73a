/* Settling a freshly built web. Strands are laid over-extended, so a new web
 * is far from rest; this picks a step the integrator can take, adds air drag
 * while the web comes to rest (drag changes the path, not the equilibrium:
 * at rest it exerts nothing) and stops when the largest residual force is a
 * small fraction of the lightest particle's weight. */
#include "web_internal.h"

#include <math.h>

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

spn_status spn_web_settle(spn_world *w, double max_time, spn_settle_report *report)
{
    double drag = spn_world_get_def(w)->drag, lightest = INFINITY;
    uint32_t np = spn_world_particle_count(w);
    for (uint32_t i = 0; i < np; i++)
        if (!spn_world_is_fixed(w, i)) lightest = fmin(lightest, spn_world_mass(w, i));
    if (!isfinite(lightest)) lightest = 1e-9;
    /* At rest: no particle feels more than a thousandth of a mean particle's
     * weight or a hundred-thousandth of a mean thread tension. */
    double mass = 0, tension = 0;
    for (uint32_t i = 0; i < np; i++) mass += spn_world_mass(w, i);
    uint32_t ns = spn_world_spring_count(w);
    for (uint32_t s = 0; s < ns; s++) tension += spn_world_spring(w, s).tension;
    double floor_force = fmax(1e-3 * 9.81 * mass / (np ? np : 1), 1e-5 * tension / (ns ? ns : 1));
    spn_settle_def sd = spn_settle_def_default();
    sd.dt = stable_step(w);
    sd.max_time = max_time;
    sd.max_residual = floor_force;
    sd.max_kinetic = 1e-9 * lightest * 9.81 * 1e-3 * np;
    sd.check_interval = fmax(50 * sd.dt, 0.02);
    /* About critical for the web's slow modes (a few Hz). */
    spn_world_set_drag(w, fmax(drag, 20.0));
    spn_status st = spn_world_settle(w, &sd, report);
    spn_world_set_drag(w, drag);
    return st;
}
