/* The spring world's construction and a first analytic check: a mass on a
 * spring oscillates with period 2 pi sqrt(m/k). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>
#include <spinneret/spinneret.h>

static spn_world *mass_on_spring(spn_integrator integ, double m, double k, double x0)
{
    spn_world_def def = spn_world_def_default();
    def.gravity = spn_v3(0, 0, 0);
    def.integrator = integ;
    spn_world *w = spn_world_create(&def);
    spn_particle_def p = spn_particle_def_default();
    p.fixed = true;
    uint32_t a, b;
    assert_int_equal(spn_world_add_particle(w, &p, &a), SPN_OK);
    p.fixed = false;
    p.mass = m;
    p.position = spn_v3(1 + x0, 0, 0);
    assert_int_equal(spn_world_add_particle(w, &p, &b), SPN_OK);
    spn_spring_def s = spn_spring_def_default();
    s.a = a;
    s.b = b;
    s.k = k;
    s.rest = 1;
    assert_int_equal(spn_world_add_spring(w, &s, NULL), SPN_OK);
    return w;
}

/* Time between successive upward zero crossings of x - 1, interpolated. */
static double measure_period(spn_world *w, double dt, int steps)
{
    double prev = spn_world_position(w, 1).x - 1, first = -1, last = -1;
    int crossings = 0;
    for (int i = 0; i < steps; i++) {
        assert_int_equal(spn_world_step(w, dt), SPN_OK);
        double cur = spn_world_position(w, 1).x - 1;
        if (prev < 0 && cur >= 0) {
            double t = spn_world_time(w) - dt + dt * (-prev) / (cur - prev);
            if (first < 0) first = t;
            last = t;
            crossings++;
        }
        prev = cur;
    }
    assert_true(crossings >= 2);
    return (last - first) / (crossings - 1);
}

static void test_period_symplectic_and_rk4(void **state)
{
    (void)state;
    const double m = 0.5, k = 200, expect = 2 * SPN_PI * sqrt(m / k);
    spn_integrator which[] = {SPN_INTEGRATOR_SYMPLECTIC, SPN_INTEGRATOR_RK4};
    for (int i = 0; i < 2; i++) {
        spn_world *w = mass_on_spring(which[i], m, k, 0.1);
        double period = measure_period(w, expect / 200, 4000);
        assert_true(fabs(period - expect) / expect < 0.005);
        spn_world_destroy(w);
    }
}

static void test_bad_additions_refused(void **state)
{
    (void)state;
    spn_world *w = spn_world_create(NULL);
    spn_particle_def p = spn_particle_def_default();
    p.mass = -1;
    assert_int_equal(spn_world_add_particle(w, &p, NULL), SPN_ERR_INVALID);
    p.mass = 1;
    p.position.x = NAN;
    assert_int_equal(spn_world_add_particle(w, &p, NULL), SPN_ERR_INVALID);
    spn_spring_def s = spn_spring_def_default();
    s.a = 0;
    s.b = 1;
    assert_int_equal(spn_world_add_spring(w, &s, NULL), SPN_ERR_INVALID);
    assert_non_null(strstr(spn_last_error(), "does not exist"));
    spn_world_destroy(w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_period_symplectic_and_rk4),
        cmocka_unit_test(test_bad_additions_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
