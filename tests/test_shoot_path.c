/* The shot's path and noise against independent answers: the arc passes
 * through both points, its elevation is the smaller root of the quadratic in
 * tan(theta), the least speed is where the roots meet; the noise starts and
 * ends at 0, spans [-1, 1], has 1-3 extrema and a bounded second difference. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>
#include <spinneret/spinneret.h>

static const double G = 9.81;

/* The two roots of G x^2 T^2 - 2 v^2 x T + (G x^2 + 2 y v^2) = 0, T = tan(theta),
 * written out plainly (the library uses a different, cancellation-free form). */
static void roots(double x, double y, double v, double *lo, double *hi)
{
    double v2 = v * v, d = v2 * v2 - G * (G * x * x + 2 * y * v2);
    assert_true(d >= 0);
    *lo = atan((v2 - sqrt(d)) / (G * x));
    *hi = atan((v2 + sqrt(d)) / (G * x));
}

static void check_through(const spn_ballistic *b)
{
    spn_vec3 p0 = spn_ballistic_position(b, 0), p1 = spn_ballistic_position(b, b->flight_time);
    assert_true(spn_v3_len(spn_v3_sub(p0, b->origin)) < 1e-9);
    assert_true(spn_v3_len(spn_v3_sub(p1, b->target)) < 1e-9);
    assert_true(b->flight_time > 0);
}

static void test_arc_through_points_at_smaller_root(void **state)
{
    (void)state;
    const struct {
        spn_vec3 o, t;
        double v;
    } cases[] = {
        {{0, 0, 0}, {20, 0, 0}, 20},     {{0, 1.5, 0}, {10, 9, 0}, 40},  {{0, 0, 0}, {10, -5, 0}, 12},
        {{1, 2, 3}, {-7, 4, 11}, 25},    {{0, 0, 0}, {0.5, 30, 0}, 40},  {{0, 0, 0}, {300, 40, -200}, 90},
        {{0, 50, 0}, {3, 0, 4}, 5},      {{0, 0, 0}, {1e-3, 1e-3, 0}, 1},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        spn_ballistic b;
        assert_int_equal(spn_ballistic_solve(cases[i].o, cases[i].t, spn_v3(0, -G, 0), cases[i].v, false, &b), SPN_OK);
        check_through(&b);
        spn_vec3 d = spn_v3_sub(cases[i].t, cases[i].o);
        double x = hypot(d.x, d.z), lo, hi;
        roots(x, d.y, cases[i].v, &lo, &hi);
        assert_true(fabs(b.elevation - lo) < 1e-9);
        assert_true(b.elevation <= hi);
        assert_true(fabs(spn_v3_len(b.velocity) - cases[i].v) < 1e-9 * cases[i].v);
    }
}

static void test_level_range_formula(void **state)
{
    (void)state;
    /* On level ground R = v^2 sin(2 theta) / g, so theta = asin(g R / v^2) / 2. */
    spn_ballistic b;
    assert_int_equal(spn_ballistic_solve(spn_v3(0, 0, 0), spn_v3(30, 0, 0), spn_v3(0, -G, 0), 25, false, &b), SPN_OK);
    assert_true(fabs(b.elevation - 0.5 * asin(G * 30 / (25.0 * 25))) < 1e-12);
    assert_true(fabs(b.flight_time - 30 / (25 * cos(b.elevation))) < 1e-12);
}

static void test_vertical_and_sideways_gravity(void **state)
{
    (void)state;
    spn_ballistic b;
    /* Straight up: the smaller root of 10 = 20 t - g t^2 / 2. */
    assert_int_equal(spn_ballistic_solve(spn_v3(0, 0, 0), spn_v3(0, 10, 0), spn_v3(0, -G, 0), 20, false, &b), SPN_OK);
    check_through(&b);
    assert_true(fabs(b.flight_time - (20 - sqrt(400 - 2 * G * 10)) / G) < 1e-12);
    assert_true(fabs(b.elevation - SPN_PI / 2) < 1e-12);
    /* Gravity along -z: the same shot turned, same flight time. */
    spn_ballistic c;
    assert_int_equal(spn_ballistic_solve(spn_v3(0, 0, 0), spn_v3(0, 0, 10), spn_v3(0, 0, -G), 20, false, &c), SPN_OK);
    check_through(&c);
    assert_true(fabs(c.flight_time - b.flight_time) < 1e-12);
    /* No gravity: a straight line at the speed given. */
    assert_int_equal(spn_ballistic_solve(spn_v3(0, 0, 0), spn_v3(3, 4, 0), spn_v3(0, 0, 0), 10, false, &c), SPN_OK);
    check_through(&c);
    assert_true(fabs(c.flight_time - 0.5) < 1e-12);
}

static void test_unreachable_and_auto_speed(void **state)
{
    (void)state;
    spn_vec3 o = spn_v3(0, 0, 0), t = spn_v3(40, 10, 0), g = spn_v3(0, -G, 0);
    double x = 40, y = 10, vmin = sqrt(G * (y + hypot(x, y)));
    assert_true(fabs(spn_ballistic_min_speed(o, t, g) - vmin) < 1e-12);
    spn_ballistic b;
    assert_int_equal(spn_ballistic_solve(o, t, g, vmin * 0.99, false, &b), SPN_ERR_INVALID);
    assert_non_null(strstr(spn_last_error(), "out of reach"));
    assert_non_null(strstr(spn_last_error(), "needs at least"));
    assert_int_equal(spn_ballistic_solve(o, t, g, vmin * 0.5, true, &b), SPN_OK);
    assert_true(fabs(b.speed - vmin) < 1e-12);
    check_through(&b);
    /* At the least speed the roots meet at theta = 45 deg + half the elevation of the target. */
    assert_true(fabs(b.elevation - (SPN_PI / 4 + 0.5 * atan2(y, x))) < 1e-6);
    /* Reachable: auto speed keeps the speed given. */
    assert_int_equal(spn_ballistic_solve(o, t, g, vmin * 2, true, &b), SPN_OK);
    assert_true(b.speed == vmin * 2);
}

static void test_bad_path_inputs(void **state)
{
    (void)state;
    spn_ballistic b;
    spn_vec3 g = spn_v3(0, -G, 0);
    assert_int_equal(spn_ballistic_solve(spn_v3(NAN, 0, 0), spn_v3(1, 0, 0), g, 10, false, &b), SPN_ERR_INVALID);
    assert_non_null(strstr(spn_last_error(), "origin"));
    assert_int_equal(spn_ballistic_solve(spn_v3(0, 0, 0), spn_v3(1, 0, 0), g, 0, false, &b), SPN_ERR_INVALID);
    assert_non_null(strstr(spn_last_error(), "speed"));
    assert_int_equal(spn_ballistic_solve(spn_v3(1, 1, 1), spn_v3(1, 1, 1), g, 10, false, &b), SPN_ERR_INVALID);
    assert_non_null(strstr(spn_last_error(), "target"));
}

/* Local extrema: sign changes of the first difference (flat steps skipped). */
static int extrema(const double *y, int n)
{
    int count = 0, last = 0;
    for (int i = 1; i < n; i++) {
        double d = y[i] - y[i - 1];
        int sgn = d > 0 ? 1 : d < 0 ? -1 : 0;
        if (sgn == 0) continue;
        if (last != 0 && sgn != last) count++;
        last = sgn;
    }
    return count;
}

enum { SAMPLES = 1024 };

static void test_noise_over_a_thousand_seeds(void **state)
{
    (void)state;
    static double y[SAMPLES];
    const double h2 = 1.0 / ((SAMPLES - 1.0) * (SAMPLES - 1.0));
    spn_shot_def def = spn_shot_def_default();
    int hist[8] = {0};
    double worst_d2 = 0;
    for (uint64_t seed = 0; seed < 1000; seed++) {
        spn_rng rng;
        spn_rng_seed(&rng, seed);
        assert_int_equal(spn_smooth_noise(&rng, def.noise_points, y, SAMPLES), SPN_OK);
        assert_true(y[0] == 0 && y[SAMPLES - 1] == 0);
        double big = 0;
        for (int i = 0; i < SAMPLES; i++) big = fmax(big, fabs(y[i]));
        assert_true(big <= 1 && big > 1 - 1e-12);
        int e = extrema(y, SAMPLES);
        assert_true(e >= 1 && e <= 3);
        hist[e]++;
        for (int i = 1; i + 1 < SAMPLES; i++) worst_d2 = fmax(worst_d2, fabs(y[i + 1] - 2 * y[i] + y[i - 1]) / h2);
    }
    /* Smoothness: |y''| stays below that of two full sine hills, (2 pi)^2 ~ 39.5
     * (measured 38.4); rough noise on this grid would reach ~1e5. */
    print_message("noise, n=%d: extrema 1:%d 2:%d 3:%d, max |y''| %.1f\n", def.noise_points, hist[1], hist[2], hist[3],
                  worst_d2);
    assert_true(worst_d2 < 4 * SPN_PI * SPN_PI);
}

static void test_noise_two_points_is_one_hill(void **state)
{
    (void)state;
    /* Two points: a linear ramp, integrated three times and tilted, is the
     * quartic x^2 (1 - x)^2 up to sign: one hill, peak at the middle. */
    static double y[SAMPLES];
    spn_rng rng;
    spn_rng_seed(&rng, 7);
    assert_int_equal(spn_smooth_noise(&rng, 2, y, SAMPLES), SPN_OK);
    double sign = y[SAMPLES / 2] > 0 ? 1 : -1;
    for (int i = 0; i < SAMPLES; i++) {
        double x = (double)i / (SAMPLES - 1), q = 16 * x * x * (1 - x) * (1 - x);
        assert_true(fabs(sign * y[i] - q) < 1e-5);
    }
}

static void test_noise_bad_inputs(void **state)
{
    (void)state;
    double y[16];
    spn_rng rng;
    spn_rng_seed(&rng, 1);
    assert_int_equal(spn_smooth_noise(&rng, 1, y, 16), SPN_ERR_INVALID);
    assert_non_null(strstr(spn_last_error(), "points"));
    assert_int_equal(spn_smooth_noise(&rng, 8, y, 4), SPN_ERR_INVALID);
    assert_non_null(strstr(spn_last_error(), "samples"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_arc_through_points_at_smaller_root),
        cmocka_unit_test(test_level_range_formula),
        cmocka_unit_test(test_vertical_and_sideways_gravity),
        cmocka_unit_test(test_unreachable_and_auto_speed),
        cmocka_unit_test(test_bad_path_inputs),
        cmocka_unit_test(test_noise_over_a_thousand_seeds),
        cmocka_unit_test(test_noise_two_points_is_one_hill),
        cmocka_unit_test(test_noise_bad_inputs),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
