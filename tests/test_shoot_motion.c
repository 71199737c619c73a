/* A shot through its phases: the head reaches the target when the path says,
 * the strand keeps a sane length and never crosses itself, nothing pops at a
 * phase change, the look does not depend on the frame rate, the camera shake
 * decays as defined, and bad definitions are refused by name. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>
#include <spinneret/spinneret.h>

static spn_shot *make(const spn_shot_def *def)
{
    spn_shot *s = NULL;
    spn_status st = spn_shot_create(def, &s);
    if (st != SPN_OK) print_error("%s\n", spn_last_error());
    assert_int_equal(st, SPN_OK);
    return s;
}

static double dist(spn_vec3 a, spn_vec3 b) { return spn_v3_len(spn_v3_sub(a, b)); }

static double polyline_length(const spn_vec3 *p, uint32_t n)
{
    double l = 0;
    for (uint32_t i = 1; i < n; i++) l += dist(p[i], p[i - 1]);
    return l;
}

static void test_head_reaches_target_on_time(void **state)
{
    (void)state;
    spn_shot_def def = spn_shot_def_default();
    spn_shot *s = make(&def);
    const double T = spn_shot_path(s)->flight_time;
    assert_true(fabs(spn_shot_contact_time(s) - T) == 0);
    const spn_vec3 *p;
    while (spn_shot_phase_now(s) == SPN_SHOT_THWIP) {
        assert_int_equal(spn_shot_step(s, 1.0 / 60), SPN_OK);
        uint32_t n = spn_shot_strand(s, &p);
        assert_int_equal(n, (uint32_t)def.points);
        assert_true(dist(p[0], def.origin) == 0);
        if (spn_shot_phase_now(s) == SPN_SHOT_THWIP) {
            /* In flight the head is on the noisy path and short of the target. */
            assert_true(dist(p[n - 1], spn_shot_head_path(s, spn_shot_time(s))) < 1e-12);
            assert_true(dist(p[n - 1], def.target) > 1e-6);
        }
    }
    assert_true(fabs(spn_shot_phase_start(s, SPN_SHOT_THWAP) - T) < 1e-12);
    /* The head is pinned at the target from contact on. */
    uint32_t n = spn_shot_strand(s, &p);
    assert_true(dist(p[n - 1], def.target) < 1e-9);
    spn_shot_destroy(s);

    /* Thwip only: the shot ends at contact with the head on the target. */
    def.all_phases = false;
    s = make(&def);
    spn_vec3 last = def.origin;
    while (spn_shot_phase_now(s) != SPN_SHOT_DONE) {
        assert_int_equal(spn_shot_step(s, 0.01), SPN_OK);
        if (spn_shot_strand(s, &p)) last = p[def.points - 1];
    }
    assert_true(fabs(spn_shot_phase_start(s, SPN_SHOT_DONE) - T) < 1e-12);
    assert_true(dist(spn_shot_head_path(s, T), def.target) < 1e-9);
    assert_true(dist(last, def.origin) > 0);
    spn_shot_destroy(s);
}

/* Squared distance between segments ab and cd (closest points, clamped). */
static double seg_dist2(spn_vec3 a, spn_vec3 b, spn_vec3 c, spn_vec3 d)
{
    spn_vec3 u = spn_v3_sub(b, a), v = spn_v3_sub(d, c), w = spn_v3_sub(a, c);
    double A = spn_v3_dot(u, u), B = spn_v3_dot(u, v), C = spn_v3_dot(v, v), D = spn_v3_dot(u, w),
           E = spn_v3_dot(v, w), den = A * C - B * B;
    double sn = den > 1e-18 ? (B * E - C * D) / den : 0;
    sn = fmin(fmax(sn, 0), 1);
    double tn = C > 0 ? (B * sn + E) / C : 0;
    if (tn < 0 || tn > 1) {
        tn = fmin(fmax(tn, 0), 1);
        sn = A > 0 ? fmin(fmax((B * tn - D) / A, 0), 1) : 0;
    }
    spn_vec3 q = spn_v3_sub(spn_v3_add(a, spn_v3_scale(u, sn)), spn_v3_add(c, spn_v3_scale(v, tn)));
    return spn_v3_dot(q, q);
}

/* Smallest distance between segments that share no point, after merging
 * the points still sitting in the hand. */
static double self_clearance(const spn_vec3 *p, uint32_t n)
{
    spn_vec3 q[1024];
    uint32_t m = 0;
    for (uint32_t i = 0; i < n; i++)
        if (m == 0 || dist(p[i], q[m - 1]) > 0) q[m++] = p[i];
    double best = INFINITY;
    for (uint32_t i = 0; i + 1 < m; i++)
        for (uint32_t j = i + 2; j + 1 < m; j++) best = fmin(best, seg_dist2(q[i], q[i + 1], q[j], q[j + 1]));
    return sqrt(best);
}

static void test_length_bounds_and_no_crossing(void **state)
{
    (void)state;
    for (uint64_t seed = 1; seed <= 5; seed++) {
        spn_shot_def def = spn_shot_def_default();
        def.seed = seed;
        def.noise_amplitude = 0.08;
        spn_shot *s = make(&def);
        const double D = dist(def.origin, def.target);
        double flown = 0, worst_clear = INFINITY, lo_ratio = INFINITY, hi_ratio = 0;
        spn_vec3 head_prev = def.origin;
        while (spn_shot_phase_now(s) != SPN_SHOT_DONE) {
            spn_shot_phase ph = spn_shot_phase_now(s);
            assert_int_equal(spn_shot_step(s, 1.0 / 60), SPN_OK);
            const spn_vec3 *p;
            uint32_t n = spn_shot_strand(s, &p);
            if (n == 0) break;
            double len = polyline_length(p, n);
            if (ph == SPN_SHOT_THWIP && spn_shot_phase_now(s) == SPN_SHOT_THWIP) {
                /* Spun along the head's path: no shorter than the chord to the head,
                 * no longer than the path flown plus 25%. */
                flown += dist(p[n - 1], head_prev);
                head_prev = p[n - 1];
                assert_true(len >= dist(p[0], p[n - 1]) - 1e-9);
                assert_true(len <= 1.25 * flown + 1e-9);
            } else if (ph == SPN_SHOT_THWAP || ph == SPN_SHOT_WHOOSH) {
                lo_ratio = fmin(lo_ratio, len / D);
                hi_ratio = fmax(hi_ratio, len / D);
            }
            if (ph != SPN_SHOT_ZIPP) worst_clear = fmin(worst_clear, self_clearance(p, n));
        }
        /* Attached, the strand stays between a taut chord and the chord
         * stretched by three times the static stretch (the swing's peak load). */
        print_message("seed %llu: length/D in [%.3f, %.3f], clearance %.3g m\n", (unsigned long long)seed, lo_ratio,
                      hi_ratio, worst_clear);
        assert_true(lo_ratio >= def.taut * 0.999);
        assert_true(hi_ratio <= 1 + 3 * def.stretch + 0.1);
        assert_true(worst_clear > 1e-3);
        spn_shot_destroy(s);
    }
}

/* Step with a small dt through the whole shot; at every phase change, the
 * largest move of any strand point and of the character in that step must be
 * no bigger than in the steps around it: nothing pops. */
static void test_handovers_are_continuous(void **state)
{
    (void)state;
    spn_shot_def def = spn_shot_def_default();
    def.points = 32;
    spn_shot *s = make(&def);
    const double dt = 2e-4;
    static spn_vec3 prev[32];
    const spn_vec3 *p;
    spn_shot_strand(s, &p);
    memcpy(prev, p, sizeof prev);
    spn_vec3 cprev = spn_shot_character(s);
    double moves[3] = {0, 0, 0}, cmoves[3] = {0, 0, 0};
    int pending = -1, checked = 0;
    spn_shot_phase was = spn_shot_phase_now(s);
    while (was != SPN_SHOT_DONE) {
        assert_int_equal(spn_shot_step(s, dt), SPN_OK);
        spn_shot_phase now = spn_shot_phase_now(s);
        uint32_t n = spn_shot_strand(s, &p);
        double move = 0;
        for (uint32_t i = 0; i < n; i++) move = fmax(move, dist(p[i], prev[i]));
        double cmove = dist(spn_shot_character(s), cprev);
        moves[0] = moves[1], moves[1] = moves[2], moves[2] = move;
        cmoves[0] = cmoves[1], cmoves[1] = cmoves[2], cmoves[2] = cmove;
        if (pending == 0) {
            /* moves[1] is the step with the change; compare with both sides. */
            double around = fmax(moves[0], moves[2]), caround = fmax(cmoves[0], cmoves[2]);
            print_message("handover %d: strand moved %.3g m (around %.3g), character %.3g m (around %.3g)\n", checked,
                          moves[1], around, cmoves[1], caround);
            assert_true(moves[1] <= 1.5 * around + 1e-6);
            assert_true(cmoves[1] <= 1.5 * caround + 1e-6);
            checked++;
        }
        pending--;
        if (now != was && now != SPN_SHOT_DONE) pending = 0;
        if (now == SPN_SHOT_DONE) assert_true(spn_shot_strand_alpha(s) == 0);
        if (n) memcpy(prev, p, n * sizeof *p);
        cprev = spn_shot_character(s);
        if (now == SPN_SHOT_ZIPP) assert_true(spn_shot_strand_alpha(s) <= 1);
        was = now;
    }
    assert_int_equal(checked, 3);
    spn_shot_destroy(s);
}

static void test_fading_out_before_gone(void **state)
{
    (void)state;
    spn_shot *s = make(NULL);
    double alpha_before = 1;
    while (spn_shot_phase_now(s) != SPN_SHOT_DONE) {
        alpha_before = spn_shot_strand_alpha(s);
        assert_int_equal(spn_shot_step(s, 1.0 / 60), SPN_OK);
    }
    assert_true(alpha_before < 0.01);
    const spn_vec3 *p;
    assert_int_equal(spn_shot_strand(s, &p), 0);
    spn_shot_destroy(s);
}

static void state_at(double dt, double t, spn_vec3 *out, uint32_t n)
{
    spn_shot *s = make(NULL);
    while (spn_shot_time(s) < t - 1e-12) assert_int_equal(spn_shot_step(s, fmin(dt, t - spn_shot_time(s))), SPN_OK);
    const spn_vec3 *p;
    assert_int_equal(spn_shot_strand(s, &p), n);
    memcpy(out, p, n * sizeof *p);
    spn_shot_destroy(s);
}

static void test_thwip_independent_of_frame_rate(void **state)
{
    (void)state;
    enum { N = 48 };
    static spn_vec3 a[N], b[N], c[N];
    state_at(1.0 / 60, 0.2, a, N);
    state_at(1.0 / 240, 0.2, b, N);
    state_at(0.07, 0.2, c, N);
    for (int i = 0; i < N; i++) {
        assert_true(dist(a[i], b[i]) < 1e-9);
        assert_true(dist(a[i], c[i]) < 1e-9);
    }
}

/* Whatever the frame time, every shot ends: time always advances, also when a
 * phase ends a rounding error after a frame (this once hung a shot). */
static void test_every_frame_rate_reaches_the_end(void **state)
{
    (void)state;
    const double dts[] = {1.0 / 60, 1.0 / 30, 1.0 / 144, 0.1, 0.0123};
    for (size_t k = 0; k < sizeof dts / sizeof dts[0]; k++)
        for (int i = 0; i < 16; i++) {
            spn_shot_def def = spn_shot_def_default();
            def.speed = 22;
            def.points = 12;
            def.seed = (uint64_t)i + 1;
            def.target.z = 0.25 * i;
            spn_shot *s = make(&def);
            long steps = 0, cap = (long)(30 / dts[k]);
            while (spn_shot_phase_now(s) != SPN_SHOT_DONE && steps < cap) {
                double t0 = spn_shot_time(s);
                assert_int_equal(spn_shot_step(s, dts[k]), SPN_OK);
                assert_true(fabs(spn_shot_time(s) - (t0 + dts[k])) < 1e-12);
                steps++;
            }
            assert_int_equal(spn_shot_phase_now(s), SPN_SHOT_DONE);
            spn_shot_destroy(s);
        }
}

static void test_camera_shake_decays(void **state)
{
    (void)state;
    spn_shot_def def = spn_shot_def_default();
    def.shake_amplitude = 2;
    def.shake_decay = 0.1;
    spn_shot *s = make(&def);
    const double T = spn_shot_contact_time(s);
    assert_int_equal(spn_shot_step(s, T * 0.9), SPN_OK);
    assert_true(spn_shot_camera_shake(s) == 0);
    assert_int_equal(spn_shot_step(s, T * 0.1 + 0.1), SPN_OK);
    assert_true(fabs(spn_shot_camera_shake(s) - 2 * exp(-1)) < 1e-9);
    spn_shot_destroy(s);
}

static void test_deterministic_and_seeded(void **state)
{
    (void)state;
    enum { N = 48 };
    static spn_vec3 a[N], b[N];
    spn_shot_def def = spn_shot_def_default();
    for (int run = 0; run < 3; run++) {
        def.seed = run == 2 ? 99 : 5;
        spn_shot *s = make(&def);
        for (int k = 0; k < 90; k++) assert_int_equal(spn_shot_step(s, 1.0 / 60), SPN_OK);
        const spn_vec3 *p;
        spn_shot_strand(s, &p);
        if (run == 0) memcpy(a, p, sizeof a);
        if (run == 1) assert_memory_equal(a, p, sizeof a);
        if (run == 2) memcpy(b, p, sizeof b);
        spn_shot_destroy(s);
    }
    assert_true(memcmp(a, b, sizeof a) != 0);
}

static void test_bad_definitions_named(void **state)
{
    (void)state;
    spn_shot *s = (spn_shot *)&s;
    spn_shot_def def = spn_shot_def_default();
    def.points = 2;
    assert_int_equal(spn_shot_create(&def, &s), SPN_ERR_INVALID);
    assert_null(s);
    assert_non_null(strstr(spn_last_error(), "points"));
    def = spn_shot_def_default();
    def.blend = 1.5;
    assert_int_equal(spn_shot_create(&def, &s), SPN_ERR_INVALID);
    assert_non_null(strstr(spn_last_error(), "blend"));
    def = spn_shot_def_default();
    def.stretch = NAN;
    assert_int_equal(spn_shot_create(&def, &s), SPN_ERR_INVALID);
    assert_non_null(strstr(spn_last_error(), "stretch"));
    def = spn_shot_def_default();
    def.speed = 5;
    assert_int_equal(spn_shot_create(&def, &s), SPN_ERR_INVALID);
    assert_non_null(strstr(spn_last_error(), "out of reach"));
    def.auto_speed = true;
    assert_int_equal(spn_shot_create(&def, &s), SPN_OK);
    assert_int_equal(spn_shot_step(s, 0), SPN_ERR_INVALID);
    assert_non_null(strstr(spn_last_error(), "dt"));
    spn_shot_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_head_reaches_target_on_time),
        cmocka_unit_test(test_length_bounds_and_no_crossing),
        cmocka_unit_test(test_handovers_are_continuous),
        cmocka_unit_test(test_fading_out_before_gone),
        cmocka_unit_test(test_thwip_independent_of_frame_rate),
        cmocka_unit_test(test_every_frame_rate_reaches_the_end),
        cmocka_unit_test(test_camera_shake_decays),
        cmocka_unit_test(test_deterministic_and_seeded),
        cmocka_unit_test(test_bad_definitions_named),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
