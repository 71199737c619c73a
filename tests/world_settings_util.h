/* A world with every setting made outside its spn_world_def changed from the
 * default, and the check that two worlds have the same settings, for the
 * tests of operations that must keep them (the prey's world copy, taking
 * particles out). Header-only, static; include after <cmocka.h>. */
#ifndef SPN_TEST_WORLD_SETTINGS_UTIL_H
#define SPN_TEST_WORLD_SETTINGS_UTIL_H

#include <math.h>
#include <spinneret/spinneret.h>

/* User pointers: only their addresses matter. */
static int util_force_user, util_break_user, util_collide_user, util_air_user;

/* A small sideways push, varying in space and time. */
static void util_push(void *user, const spn_world *w, double t, const spn_vec3 *x, const spn_vec3 *v, spn_vec3 *f)
{
    (void)user, (void)v;
    for (uint32_t i = 0; i < spn_world_particle_count(w); i++)
        f[i] = spn_v3_add(f[i], spn_v3(0, 0, 2e-9 * (1 + sin(30 * x[i].x + 200 * t))));
}

static void util_on_break(void *user, uint32_t s, double t, double length)
{
    (void)user, (void)s, (void)t, (void)length;
}

static spn_vec3 util_breeze(void *user, double t, spn_vec3 p)
{
    (void)user;
    return spn_v3(0.1 * sin(3 * p.x), 0, 0.8 + 0.3 * sin(5 * t + 7 * p.y));
}

/* The standard web, 6 rings x 12 radials (73 particles), one thread. */
static spn_world *util_small_orb(spn_integrator integ)
{
    spn_world_def def = spn_world_def_default();
    def.integrator = integ;
    def.threads = 1;
    spn_orb_scene_def od = spn_orb_scene_def_default();
    od.rings = 6;
    od.radials = 12;
    spn_world *w = NULL;
    assert_int_equal(spn_scene_orb(&def, &od, &w), SPN_OK);
    return w;
}

/* Every setting but the contacts away from its default: the collision
 * callback `collide` (with util_collide_user) and the metadata given. */
static void util_set_everything(spn_world *w, spn_collide_fn collide, const char *metadata)
{
    spn_world_set_lattice(w, false);
    spn_world_set_precision(w, SPN_PRECISION_FLOAT32);
    assert_int_equal(spn_world_set_implicit_preconditioner(w, SPN_PRECOND_MULTIGRID), SPN_OK);
    spn_world_set_force_callback(w, util_push, &util_force_user);
    spn_world_set_break_callback(w, util_on_break, &util_break_user);
    spn_world_set_collide_callback(w, collide, &util_collide_user);
    spn_world_set_air(w, util_breeze, &util_air_user, 1.1, 1.9e-5);
    assert_int_equal(spn_world_set_air_resolution(w, 4e-3, 2e-3), SPN_OK);
    spn_world_set_tag_diameter(w, SPN_THREAD_CAPTURE, 1e-5);
    spn_world_set_tag_diameter(w, SPN_THREAD_RADIUS, 3e-6);
    assert_int_equal(spn_world_set_tag_hysteresis(w, SPN_THREAD_RADIUS, 0.6, 2e-3), SPN_OK);
    assert_int_equal(spn_world_add_plane(w, spn_v3(0, 1, 0), -0.2, 0.3, 0.4), SPN_OK);
    assert_int_equal(spn_world_add_sphere(w, spn_v3(0, 0, 0.05), 0.01, 0.5, 0.1), SPN_OK);
    assert_int_equal(spn_world_set_metadata(w, metadata), SPN_OK);
    spn_world_set_time(w, 0.25);
    spn_world_set_gravity(w, spn_v3(0, -9.7, 0.1));
    spn_world_set_drag(w, 0.5);
    assert_int_equal(spn_world_set_solver_tolerance(w, 1e-9, 400), SPN_OK);
}

/* a and b have the same definition and the same settings outside it (the
 * contacts apart: their ids may differ), metadata and time. */
static void util_same_settings(const spn_world *a, const spn_world *b)
{
    const spn_world_def *da = spn_world_get_def(a), *db = spn_world_get_def(b);
    assert_memory_equal(da, db, sizeof *da);
    assert_int_equal(spn_world_lattice_allowed(a), spn_world_lattice_allowed(b));
    assert_int_equal(spn_world_precision(a), spn_world_precision(b));
    assert_int_equal(spn_world_implicit_preconditioner(a), spn_world_implicit_preconditioner(b));
    void *ua = NULL, *ub = NULL;
    assert_ptr_equal(spn_world_force_callback(a, &ua), spn_world_force_callback(b, &ub));
    assert_ptr_equal(ua, ub);
    assert_ptr_equal(spn_world_break_callback(a, &ua), spn_world_break_callback(b, &ub));
    assert_ptr_equal(ua, ub);
    assert_ptr_equal(spn_world_collide_callback(a, &ua), spn_world_collide_callback(b, &ub));
    assert_ptr_equal(ua, ub);
    double rho_a, rho_b, mu_a, mu_b;
    assert_ptr_equal(spn_world_air(a, &ua, &rho_a, &mu_a), spn_world_air(b, &ub, &rho_b, &mu_b));
    assert_ptr_equal(ua, ub);
    assert_true(rho_a == rho_b && mu_a == mu_b);
    double ia, ib, sa, sb;
    spn_world_air_resolution(a, &ia, &sa), spn_world_air_resolution(b, &ib, &sb);
    assert_true(ia == ib && sa == sb);
    for (uint32_t tag = 0; tag <= SPN_THREAD_SHOT; tag++) {
        double ra, rb;
        assert_true(spn_world_tag_diameter(a, tag) == spn_world_tag_diameter(b, tag));
        assert_true(spn_world_tag_hysteresis(a, tag, &ra) == spn_world_tag_hysteresis(b, tag, &rb) && ra == rb);
    }
    assert_int_equal(spn_world_collider_count(a), spn_world_collider_count(b));
    assert_string_equal(spn_world_metadata(a), spn_world_metadata(b));
    assert_true(spn_world_time(a) == spn_world_time(b));
}

#endif
