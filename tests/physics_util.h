/* Small worlds shared by the physics tests (header-only, static). */
#ifndef SPN_TEST_PHYSICS_UTIL_H
#define SPN_TEST_PHYSICS_UTIL_H

#include <math.h>
#include <spinneret/spinneret.h>

/* A fixed particle at the origin and a free one of mass m at (rest + x0, 0, 0),
 * joined by a spring of stiffness k, damping kd, rest length 1; no gravity. */
static inline spn_world *util_mass_on_spring(spn_integrator integ, double m, double k, double kd, double x0)
{
    spn_world_def def = spn_world_def_default();
    def.gravity = spn_v3(0, 0, 0);
    def.integrator = integ;
    def.threads = 1;
    spn_world *w = spn_world_create(&def);
    spn_particle_def p = spn_particle_def_default();
    p.fixed = true;
    spn_world_add_particle(w, &p, NULL);
    p.fixed = false;
    p.mass = m;
    p.position = spn_v3(1 + x0, 0, 0);
    spn_world_add_particle(w, &p, NULL);
    spn_spring_def s = spn_spring_def_default();
    s.a = 0;
    s.b = 1;
    s.k = k;
    s.kd = kd;
    s.rest = 1;
    spn_world_add_spring(w, &s, NULL);
    return w;
}

/* Energy in play: kinetic + elastic + gravitational. */
static inline double util_energy(const spn_world *w) { return spn_world_total_energy(w); }

#endif
