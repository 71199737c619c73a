/* Small worlds shared by the physics tests (header-only, static). */
#ifndef SPN_TEST_PHYSICS_UTIL_H
#define SPN_TEST_PHYSICS_UTIL_H

#include <math.h>
#include <stdlib.h>
#include <string.h>
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

/* A light wind over a web: steady along z, varying in space and time. */
static inline spn_vec3 util_breeze(void *user, double t, spn_vec3 p)
{
    (void)user;
    return spn_v3(0.1 * sin(3 * p.x), 0, 0.8 + 0.3 * sin(5 * t + 7 * p.y));
}

/* The standard web of rings x radials, split across `threads` even at
 * test sizes (parallel_min 256); NULL if it cannot be made. */
static inline spn_world *util_orb(spn_integrator integ, int threads, int rings, int radials)
{
    spn_world_def def = spn_world_def_default();
    def.integrator = integ;
    def.threads = threads;
    def.parallel_min = 256;
    spn_orb_scene_def od = spn_orb_scene_def_default();
    od.rings = rings;
    od.radials = radials;
    spn_world *w = NULL;
    return spn_scene_orb(&def, &od, &w) == SPN_OK ? w : NULL;
}

/* The 50 x 50 standard web (2,501 particles) in util_breeze, with silk
 * diameters. */
static inline spn_world *util_breezy_orb(spn_integrator integ, int threads)
{
    spn_world *w = util_orb(integ, threads, 50, 50);
    if (!w) return NULL;
    spn_world_set_air(w, util_breeze, NULL, 1.2, 1.8e-5);
    spn_world_set_tag_diameter(w, SPN_THREAD_CAPTURE, 3e-6);
    spn_world_set_tag_diameter(w, SPN_THREAD_RADIUS, 4e-6);
    return w;
}

/* Positions then velocities of every particle, in one malloc'd array (the
 * caller frees it), and the world destroyed: the end state of a run. */
static inline spn_vec3 *util_take_state(spn_world *w)
{
    uint32_t n = spn_world_particle_count(w);
    spn_vec3 *out = malloc(2 * n * sizeof *out);
    if (out) {
        memcpy(out, spn_world_positions(w), n * sizeof *out);
        memcpy(out + n, spn_world_velocities(w), n * sizeof *out);
    }
    spn_world_destroy(w);
    return out;
}

#endif
