/* The contact step schedule (spn_impact_step_limit, src/anim/impact_contact.c)
 * against its rules, worked out by hand for a prey of radius R = 4 mm by a
 * straight thread at rest along x (so 3% of R is 0.12 mm):
 * - far and closing in at 1 m/s: 0.8 of the gap over the closing speed;
 * - near and closing in: never below 3% of R over the closing speed;
 * - touching: 3% of R over the prey's speed, whichever way it moves;
 * - moving away from the thread, or past it sideways: no limit (the frame's
 *   step), even a hair from the thread;
 * - two prey: the stricter one. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <spinneret/spinneret.h>

#define R 0.004

/* A 10 cm thread of 20 segments along x, ends fixed, at rest, no gravity. */
static spn_world *thread(void)
{
    spn_world_def d = spn_world_def_default();
    d.gravity = spn_v3(0, 0, 0);
    d.integrator = SPN_INTEGRATOR_IMPLICIT;
    spn_world *w = spn_world_create(&d);
    for (int i = 0; i <= 20; i++) {
        spn_particle_def p = spn_particle_def_default();
        p.position = spn_v3(-0.05 + 0.005 * i, 0, 0);
        p.mass = 1e-10;
        p.fixed = i == 0 || i == 20;
        assert_int_equal(spn_world_add_particle(w, &p, NULL), SPN_OK);
    }
    for (uint32_t i = 0; i < 20; i++) {
        spn_spring_def s = spn_spring_def_default();
        s.a = i, s.b = i + 1, s.rest = 0.005, s.k = 14;
        s.tag = SPN_THREAD_RADIUS;
        assert_int_equal(spn_world_add_spring(w, &s, NULL), SPN_OK);
    }
    return w;
}

static void near(double got, double want)
{
    if (!(fabs(got - want) <= 1e-9 * want)) fail_msg("step limit %.12g s, expected %.12g s", got, want);
}

/* The limit for prey at these places and velocities, asked with step dt. */
static double limit(const spn_prey_def *prey, int n, double dt)
{
    spn_world *w = thread();
    spn_impact_def def = spn_impact_def_default();
    spn_impact *im = NULL;
    assert_int_equal(spn_impact_create(&w, prey, n, &def, &im), SPN_OK);
    double h = spn_impact_step_limit(im, w, dt);
    spn_impact_destroy(im);
    spn_world_destroy(w);
    return h;
}

static double one(double z, spn_vec3 v, double dt)
{
    spn_prey_def p = {{0.012, 0, z}, v, 2e-4, R};
    return limit(&p, 1, dt);
}

static void test_closing_in(void **state)
{
    (void)state;
    /* gap 46 mm at 1 m/s: 0.8 * 0.046 s */
    near(one(0.05, spn_v3(0, 0, -1), 1), 0.8 * 0.046);
    /* the frame's step when that is shorter */
    near(one(0.05, spn_v3(0, 0, -1), 0.01), 0.01);
    /* gap 1 mm at 2 m/s: 0.8 mm of travel */
    near(one(R + 0.001, spn_v3(0, 0, -2), 1), 0.0008 / 2);
    /* gap 0.05 mm: 3% of R, not 0.8 of the gap */
    near(one(R + 0.00005, spn_v3(0, 0, -2), 1), 0.03 * R / 2);
    /* closing at 45 degrees: the closing speed counts */
    near(one(0.05, spn_v3(0, 1, -1), 1), 0.8 * 0.046);
}

static void test_touching(void **state)
{
    (void)state;
    near(one(0.002, spn_v3(0, 0, -1), 1), 0.03 * R);
    /* leaving, or sliding along, still touching: the prey's own speed */
    near(one(0.002, spn_v3(0, 0, 0.5), 1), 0.03 * R / 0.5);
    near(one(0.002, spn_v3(3, 0, 0), 1), 0.03 * R / 3);
    /* at rest in contact: no limit */
    near(one(0.002, spn_v3(0, 0, 0), 0.05), 0.05);
}

static void test_moving_away(void **state)
{
    (void)state;
    /* a hair from the thread, leaving at 5 m/s, or flying past it sideways
     * (gliding along it, the segments ahead close in end-on: fine steps) */
    near(one(R + 1e-5, spn_v3(0, 0, 5), 0.05), 0.05);
    near(one(R + 1e-5, spn_v3(0, 5, 0), 0.05), 0.05);
    near(one(-R - 1e-5, spn_v3(0, 0, -5), 0.05), 0.05);
}

static void test_two_prey(void **state)
{
    (void)state;
    spn_prey_def p[2] = {{{0.012, 0, 0.05}, {0, 0, 5}, 2e-4, R}, {{-0.02, 0, -0.01}, {0, 0, 1}, 2e-4, R}};
    near(limit(p, 2, 1), 0.8 * 0.006);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_closing_in),
        cmocka_unit_test(test_touching),
        cmocka_unit_test(test_moving_away),
        cmocka_unit_test(test_two_prey),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
