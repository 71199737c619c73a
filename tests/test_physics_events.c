/* Issue 2, tests 6 and 7: breakage, tension-only springs, collisions.
 * 6. A spring pulled past its maximum breaks exactly once and the callback
 *    fires once with its id; a tension-only spring under compression exerts
 *    no force.
 * 7. A particle dropped on a plane never passes it; restitution 0.5 halves
 *    its speed. Also spheres and the per-particle collision callback. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "physics_util.h"

typedef struct breaks {
    int count;
    uint32_t id;
    double length;
} breaks;

static void on_break(void *user, uint32_t s, double t, double length)
{
    (void)t;
    breaks *b = user;
    b->count++;
    b->id = s;
    b->length = length;
}

static void test_breaks_once(void **state)
{
    (void)state;
    /* Two hanging masses; the second spring (id 1) can hold 1.05 m. */
    spn_world *w = spn_world_create(NULL);
    spn_particle_def p = spn_particle_def_default();
    p.fixed = true;
    spn_world_add_particle(w, &p, NULL);
    p.fixed = false;
    p.mass = 0.1;
    p.position = spn_v3(0, -1, 0);
    spn_world_add_particle(w, &p, NULL);
    p.position = spn_v3(0, -2, 0);
    spn_world_add_particle(w, &p, NULL);
    spn_spring_def s = spn_spring_def_default();
    s.a = 0, s.b = 1, s.k = 1000, s.kd = 0.5, s.rest = 1;
    spn_world_add_spring(w, &s, NULL);
    s.a = 1, s.b = 2, s.k = 5, s.break_max = 1.05;
    uint32_t id;
    spn_world_add_spring(w, &s, &id);
    assert_int_equal(id, 1);
    breaks b = {0, 99, 0};
    spn_world_set_break_callback(w, on_break, &b);
    int total = 0;
    for (int i = 0; i < 2000; i++) {
        assert_int_equal(spn_world_step(w, 1e-3), SPN_OK);
        total += spn_world_last_step(w).breaks;
    }
    assert_int_equal(b.count, 1);
    assert_int_equal(total, 1);
    assert_int_equal(b.id, 1);
    assert_true(b.length > 1.05 && b.length < 1.06);
    spn_spring_info info = spn_world_spring(w, 1);
    assert_true(info.broken);
    assert_true(info.tension == 0);
    /* Broken: the lower mass falls freely (a = g). */
    spn_vec3 v0 = spn_world_velocity(w, 2);
    assert_int_equal(spn_world_step(w, 1e-3), SPN_OK);
    double a = (spn_world_velocity(w, 2).y - v0.y) / 1e-3;
    assert_true(fabs(a + 9.81) < 1e-9);
    assert_false(spn_world_spring(w, 0).broken);
    spn_world_destroy(w);
}

static void test_tension_only(void **state)
{
    (void)state;
    for (int slack = 0; slack < 2; slack++) {
        spn_world *w = util_mass_on_spring(SPN_INTEGRATOR_SYMPLECTIC, 1, 100, 0, -0.2);
        if (slack) {
            /* rebuild with a tension-only spring */
            bool remove[1] = {true};
            spn_world_remove_springs(w, remove);
            spn_spring_def s = spn_spring_def_default();
            s.a = 0, s.b = 1, s.k = 100, s.rest = 1, s.tension_only = true;
            spn_world_add_spring(w, &s, NULL);
        }
        assert_int_equal(spn_world_step(w, 1e-3), SPN_OK);
        double vx = spn_world_velocity(w, 1).x;
        if (slack) {
            assert_true(vx == 0);
            assert_true(spn_world_spring(w, 0).tension == 0);
            assert_true(spn_world_energy(w).elastic == 0);
        } else {
            assert_true(fabs(vx - 100 * 0.2 * 1e-3) < 1e-12); /* pushes back */
        }
        spn_world_destroy(w);
    }
}

static spn_world *dropper(double height, spn_integrator integ)
{
    spn_world_def def = spn_world_def_default();
    def.integrator = integ;
    spn_world *w = spn_world_create(&def);
    spn_particle_def p = spn_particle_def_default();
    p.position = spn_v3(0, height, 0);
    spn_world_add_particle(w, &p, NULL);
    return w;
}

static void test_plane_bounce(void **state)
{
    (void)state;
    const double h = 1.0, dt = 1e-5, impact = sqrt(2 * 9.81 * h);
    spn_world *w = dropper(h, SPN_INTEGRATOR_SYMPLECTIC);
    assert_int_equal(spn_world_add_plane(w, spn_v3(0, 1, 0), 0, 0.5, 0), SPN_OK);
    double prev_v = 0, rebound = 0;
    for (int i = 0; i < 100000 && rebound == 0; i++) {
        assert_int_equal(spn_world_step(w, dt), SPN_OK);
        spn_vec3 x = spn_world_position(w, 0), v = spn_world_velocity(w, 0);
        assert_true(x.y >= 0);
        if (prev_v < 0 && v.y > 0) rebound = v.y / -prev_v;
        prev_v = v.y;
    }
    print_message("rebound speed ratio %.5f (impact %.4f m/s)\n", rebound, impact);
    assert_true(fabs(rebound - 0.5) < 0.005);
    spn_world_destroy(w);

    /* Huge steps, every integrator: never below the plane, even a tilted one. */
    for (int integ = 0; integ < SPN_INTEGRATOR_COUNT; integ++) {
        w = dropper(h, (spn_integrator)integ);
        spn_vec3 n = spn_v3_norm(spn_v3(0.3, 1, 0));
        assert_int_equal(spn_world_add_plane(w, n, -0.2, 0.5, 0.3), SPN_OK);
        for (int i = 0; i < 200; i++) {
            assert_int_equal(spn_world_step(w, 0.05), SPN_OK);
            assert_true(spn_v3_dot(n, spn_world_position(w, 0)) >= -0.2 - 1e-12);
        }
        spn_world_destroy(w);
    }
}

static void test_sphere_and_friction(void **state)
{
    (void)state;
    spn_world *w = dropper(1.0, SPN_INTEGRATOR_SYMPLECTIC);
    spn_world_set_position(w, 0, spn_v3(0.05, 1, 0));
    assert_int_equal(spn_world_add_sphere(w, spn_v3(0, 0, 0), 0.5, 0, 1), SPN_OK);
    for (int i = 0; i < 3000; i++) {
        assert_int_equal(spn_world_step(w, 1e-3), SPN_OK);
        assert_true(spn_v3_len(spn_world_position(w, 0)) >= 0.5 - 1e-12);
    }
    /* Full friction, no restitution: it stopped on top of the sphere. */
    spn_vec3 x = spn_world_position(w, 0);
    assert_true(x.y > 0.49);
    assert_true(spn_v3_len(spn_world_velocity(w, 0)) < 0.02);
    assert_int_equal(spn_world_add_sphere(w, spn_v3(0, 0, 0), -1, 0, 0), SPN_ERR_INVALID);
    assert_int_equal(spn_world_add_plane(w, spn_v3(0, 1, 0), 0, 1.5, 0), SPN_ERR_INVALID);
    spn_world_destroy(w);
}

/* A floor at y = 0 by callback: stop at the surface and keep 50%. */
static double floor_cb(void *user, uint32_t i, spn_vec3 from, spn_vec3 to, spn_vec3 *normal, double *keep)
{
    (void)i;
    int *calls = user;
    ++*calls;
    if (to.y >= 0) return 1;
    *normal = spn_v3(0, 1, 0);
    *keep = 0.5;
    return from.y / (from.y - to.y);
}

static void test_collide_callback(void **state)
{
    (void)state;
    spn_world *w = dropper(1.0, SPN_INTEGRATOR_RK4);
    int calls = 0;
    spn_world_set_collide_callback(w, floor_cb, &calls);
    double prev_v = 0, rebound = 0;
    for (int i = 0; i < 100000 && rebound == 0; i++) {
        assert_int_equal(spn_world_step(w, 1e-5), SPN_OK);
        spn_vec3 v = spn_world_velocity(w, 0);
        assert_true(spn_world_position(w, 0).y >= 0);
        if (prev_v < 0 && v.y > 0) rebound = v.y / -prev_v;
        prev_v = v.y;
    }
    assert_true(calls > 0);
    assert_true(fabs(rebound - 0.5) < 0.005);
    spn_world_destroy(w);
}

/* Springs are stepped in an internal order; setters by public id after the
 * world compiled must reach the stepping copies. Springs added in an order
 * the internal sort changes: s0 = (1, 2), s1 = (0, 1). */
static void test_setters_after_compile(void **state)
{
    (void)state;
    spn_world_def def = spn_world_def_default();
    def.gravity = spn_v3(0, -10, 0);
    spn_world *w = spn_world_create(&def);
    spn_particle_def p = spn_particle_def_default();
    p.fixed = true;
    spn_world_add_particle(w, &p, NULL);
    p.fixed = false;
    p.position = spn_v3(0, -1, 0);
    spn_world_add_particle(w, &p, NULL);
    p.position = spn_v3(0, -2, 0);
    spn_world_add_particle(w, &p, NULL);
    spn_spring_def s = spn_spring_def_default();
    s.a = 1, s.b = 2, s.k = 100, s.rest = 1;
    spn_world_add_spring(w, &s, NULL);
    s.a = 0, s.b = 1;
    spn_world_add_spring(w, &s, NULL);
    const double dt = 1e-6;
    assert_int_equal(spn_world_step(w, dt), SPN_OK);
    /* Shorten s0 by 0.1: it pulls particle 2 up with k * 0.1 = 10 N, against its weight. */
    spn_world_set_spring_rest(w, 0, 0.9);
    spn_vec3 v0 = spn_world_velocity(w, 2);
    assert_int_equal(spn_world_step(w, dt), SPN_OK);
    double a = (spn_world_velocity(w, 2).y - v0.y) / dt;
    assert_true(fabs(a - (-10 + 100 * 0.1)) < 1e-3);
    /* Soften s0 to nothing: particle 2 falls freely. */
    spn_world_set_spring_stiffness(w, 0, 0, 0);
    v0 = spn_world_velocity(w, 2);
    assert_int_equal(spn_world_step(w, dt), SPN_OK);
    assert_true(fabs((spn_world_velocity(w, 2).y - v0.y) / dt + 10) < 1e-6);
    /* Break s1 by hand: particle 1 falls freely too, and no callback fires. */
    breaks b = {0, 0, 0};
    spn_world_set_break_callback(w, on_break, &b);
    spn_world_break_spring(w, 1);
    v0 = spn_world_velocity(w, 1);
    assert_int_equal(spn_world_step(w, dt), SPN_OK);
    assert_true(fabs((spn_world_velocity(w, 1).y - v0.y) / dt + 10) < 1e-6);
    assert_int_equal(b.count, 0);
    assert_true(spn_world_spring(w, 1).broken);
    spn_world_destroy(w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_breaks_once),
        cmocka_unit_test(test_tension_only),
        cmocka_unit_test(test_plane_bounce),
        cmocka_unit_test(test_sphere_and_friction),
        cmocka_unit_test(test_collide_callback),
        cmocka_unit_test(test_setters_after_compile),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
