/* Issue 2, tests 1 and 2: one mass on a spring.
 * 1. The period is 2 pi sqrt(m/k) within 0.5% for symplectic Euler, RK4 and
 *    implicit Euler; RK4's error shrinks ~16x (4th order) when the step halves.
 * 2. With axial damping c the amplitude envelope is exp(-c t / 2m) within 1%. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "physics_util.h"

/* Mean time between upward zero crossings of x - 1, linearly interpolated. */
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
    assert_true(crossings >= 3);
    return (last - first) / (crossings - 1);
}

static void test_period(void **state)
{
    (void)state;
    const double m = 0.5, k = 200, period = 2 * SPN_PI * sqrt(m / k);
    const spn_integrator which[] = {SPN_INTEGRATOR_SYMPLECTIC, SPN_INTEGRATOR_RK4, SPN_INTEGRATOR_IMPLICIT};
    /* Implicit Euler's phase error is (w h)^2 / 3: 100 steps a period gives 0.13%. */
    const double per_period[] = {200, 50, 100};
    for (int i = 0; i < 3; i++) {
        spn_world *w = util_mass_on_spring(which[i], m, k, 0, 0.1);
        double measured = measure_period(w, period / per_period[i], (int)(per_period[i] * 5));
        double err = fabs(measured - period) / period;
        print_message("%-10s period %.6f s, expected %.6f s, error %.4f%%\n", spn_integrator_name(which[i]), measured,
                      period, 100 * err);
        assert_true(err < 0.005);
        spn_world_destroy(w);
    }
}

/* Largest position error of RK4 over 3 periods against A cos(w t). */
static double rk4_error(double dt)
{
    const double m = 0.5, k = 200, a = 0.1, omega = sqrt(k / m);
    spn_world *w = util_mass_on_spring(SPN_INTEGRATOR_RK4, m, k, 0, a);
    int steps = (int)lround(3 * 2 * SPN_PI / omega / dt);
    double worst = 0;
    for (int i = 0; i < steps; i++) {
        assert_int_equal(spn_world_step(w, dt), SPN_OK);
        double t = spn_world_time(w), x = spn_world_position(w, 1).x - 1;
        worst = fmax(worst, fabs(x - a * cos(omega * t)));
    }
    spn_world_destroy(w);
    return worst;
}

static void test_rk4_fourth_order(void **state)
{
    (void)state;
    const double period = 2 * SPN_PI * sqrt(0.5 / 200.0);
    double e1 = rk4_error(period / 16), e2 = rk4_error(period / 32);
    print_message("RK4 error %.3e -> %.3e, ratio %.2f\n", e1, e2, e1 / e2);
    assert_true(e1 / e2 > 13 && e1 / e2 < 19);
}

static void test_damped_envelope(void **state)
{
    (void)state;
    const double m = 0.2, k = 80, c = 0.4, gamma = c / (2 * m);
    spn_world *w = util_mass_on_spring(SPN_INTEGRATOR_RK4, m, k, c, 0.05);
    const double dt = 1e-4;
    /* Successive maxima of x - 1, refined by a parabola through three samples:
     * for x = A e^(-gamma t) cos(wd t + phi) the maxima follow the envelope. */
    double x[3] = {0, 0, spn_world_position(w, 1).x - 1};
    double t0 = -1, a0 = 0;
    int peaks = 0;
    for (int i = 0; i < 60000; i++) {
        assert_int_equal(spn_world_step(w, dt), SPN_OK);
        x[0] = x[1], x[1] = x[2], x[2] = spn_world_position(w, 1).x - 1;
        if (i < 2 || !(x[1] > x[0] && x[1] >= x[2])) continue;
        double den = x[0] - 2 * x[1] + x[2], off = 0.5 * (x[0] - x[2]) / den;
        double tp = spn_world_time(w) - dt + off * dt, ap = x[1] - 0.25 * (x[0] - x[2]) * off;
        if (t0 < 0) {
            t0 = tp, a0 = ap;
            continue;
        }
        double expect = a0 * exp(-gamma * (tp - t0));
        assert_true(fabs(ap - expect) / expect < 0.01);
        peaks++;
    }
    print_message("%d maxima follow exp(-c t / 2m)\n", peaks);
    assert_true(peaks >= 10);
    spn_world_destroy(w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_period),
        cmocka_unit_test(test_rk4_fourth_order),
        cmocka_unit_test(test_damped_envelope),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
