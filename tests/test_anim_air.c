/* Air on threads: the drag on one straight segment is 1/2 rho C_d d L |u_n| u_n
 * from the normal component of the wind only (none when the wind runs along
 * it), and the air's power on it is that force times its ends' velocities
 * (spn_world_air_power); a web in steady air settles to a deflected shape
 * whose deflection grows with wind speed, and comes back to rest when the
 * wind stops; the turbulent field has the rms and the zero divergence it is
 * built with. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <spinneret/spinneret.h>

static spn_air_field *steady(double speed, spn_vec3 dir)
{
    spn_air_def d = spn_air_def_default();
    d.speed = speed;
    d.direction = dir;
    d.gust = 0;
    d.turbulence = 0;
    spn_air_field *air;
    assert_int_equal(spn_air_create(&d, &air), SPN_OK);
    return air;
}

/* A radius segment 2 cm long along x between two free particles of SEG_MASS,
 * without gravity. */
#define SEG_MASS 1e-3
static spn_world *segment(void)
{
    spn_world_def wd = spn_world_def_default();
    wd.gravity = spn_v3(0, 0, 0);
    spn_world *w = spn_world_create(&wd);
    spn_particle_def p = spn_particle_def_default();
    p.mass = SEG_MASS;
    spn_spring_def s = spn_spring_def_default();
    p.position = spn_v3(0, 0, 0);
    assert_int_equal(spn_world_add_particle(w, &p, &s.a), SPN_OK);
    p.position = spn_v3(0.02, 0, 0);
    assert_int_equal(spn_world_add_particle(w, &p, &s.b), SPN_OK);
    s.k = 1;
    s.tag = SPN_THREAD_RADIUS;
    assert_int_equal(spn_world_add_spring(w, &s, NULL), SPN_OK);
    return w;
}

/* One step from rest of a free segment along x in wind `u`: the velocity each
 * end gains, divided by dt and multiplied by its mass, is the force on it. */
static spn_vec3 force_on_end(spn_vec3 wind_dir, double speed)
{
    spn_world *w = segment();
    spn_air_field *air = steady(speed, wind_dir);
    spn_air_attach(air, w);
    const double dt = 1e-6;
    assert_int_equal(spn_world_step(w, dt), SPN_OK);
    spn_vec3 f = spn_v3_scale(spn_world_velocity(w, 0), SEG_MASS / dt);
    spn_world_destroy(w);
    spn_air_destroy(air);
    return f;
}

static void test_segment_drag_formula(void **state)
{
    (void)state;
    const double rho = 1.204, mu = 1.81e-5, d = spn_thread_diameter(SPN_THREAD_RADIUS), L = 0.02, speed = 2;
    /* Wind at 30 degrees to the segment: only the normal part, speed sin 30. */
    double a = SPN_PI / 6;
    spn_vec3 dir = spn_v3(cos(a), 0, sin(a));
    spn_vec3 f = force_on_end(dir, speed);
    double un = speed * sin(a), re = rho * un * d / mu;
    double expect = 0.5 * 0.5 * rho * spn_cylinder_drag_coefficient(re) * d * L * un * un; /* half per end */
    printf("# drag per end %.6g N, formula %.6g N (Re %.3g)\n", f.z, expect, re);
    assert_true(fabs(f.z - expect) <= 1e-6 * expect);
    assert_true(fabs(f.x) <= 1e-9 * expect); /* nothing along the segment */
    assert_true(fabs(f.y) <= 1e-9 * expect);
    /* Along the segment: no force at all. */
    spn_vec3 g = force_on_end(spn_v3(1, 0, 0), speed);
    assert_true(spn_v3_len(g) == 0);
}

/* The air's power on a segment along x, its free end moving at vz, in a
 * steady wind of 2 m/s along z, against 1/2 rho C_d d L |u| u (v_a + v_b) / 2
 * from the formula, u = 2 minus its midpoint's speed: each end takes half the
 * force at its own velocity, and a fixed end (at rest) none. */
static void power_on_segment(double vz, bool fixed_end, double *power, double *expect)
{
    spn_world *w = segment();
    assert_true(spn_world_air_power(w) == 0); /* no air yet */
    spn_air_field *air = steady(2, spn_v3(0, 0, 1));
    spn_air_attach(air, w);
    if (fixed_end)
        spn_world_set_fixed(w, 0, true);
    else
        assert_int_equal(spn_world_set_velocity(w, 0, spn_v3(0, 0, vz)), SPN_OK);
    assert_int_equal(spn_world_set_velocity(w, 1, spn_v3(0, 0, vz)), SPN_OK);
    *power = spn_world_air_power(w);
    const double v0 = spn_world_velocity(w, 0).z, v1 = spn_world_velocity(w, 1).z;
    const double rho = 1.204, mu = 1.81e-5, d = spn_thread_diameter(SPN_THREAD_RADIUS), L = 0.02;
    const double u = 2 - (v0 + v1) / 2, re = rho * fabs(u) * d / mu;
    const double force = 0.5 * rho * spn_cylinder_drag_coefficient(re) * d * L * fabs(u) * u;
    *expect = force * ((fixed_end ? 0 : v0) + v1) / 2;
    spn_world_destroy(w);
    spn_air_destroy(air);
}

static void test_air_power(void **state)
{
    (void)state;
    const double vz[] = {0.5, 3, -1, 2};
    for (int i = 0; i < 4; i++)
        for (int fixed = 0; fixed < 2; fixed++) {
            double power, expect;
            power_on_segment(vz[i], fixed, &power, &expect);
            printf("# segment at %g m/s in 2 m/s air%s: power %.6g W, formula %.6g W\n", vz[i],
                   fixed ? ", one end fixed" : "", power, expect);
            assert_true(fabs(power - expect) <= 1e-12 * fabs(expect));
            assert_true(vz[i] == 2 && !fixed ? power == 0 : fabs(power) > 1e-9); /* the air drives or brakes it */
        }
}

/* The hub's deflection along the wind after `wind_time` of steady wind, and
 * after a further `calm_time` without it. */
static void deflect(double speed, double *during, double *after)
{
    spn_world *w = NULL;
    assert_int_equal(spn_web_load(SPN_TEST_DATA "/anim/orb.json", &w), SPN_OK);
    spn_world_set_drag(w, 30); /* settle faster; the equilibrium does not depend on it */
    spn_anim_def ad = spn_anim_def_default();
    ad.wind = SPN_WIND_AIR;
    ad.air.speed = speed;
    ad.air.direction = spn_v3(0, 0, -1);
    ad.air.gust = 0;
    ad.air.turbulence = 0;
    ad.fps = 20;
    ad.duration = 0.6;
    ad.wind_stop = after ? 0.6 : -1;
    spn_anim_report rep;
    assert_int_equal(spn_animate(&w, &ad, NULL, NULL, &rep), SPN_OK);
    *during = -spn_world_position(w, 0).z;
    if (after) {
        ad.wind = SPN_WIND_NONE;
        assert_int_equal(spn_animate(&w, &ad, NULL, NULL, &rep), SPN_OK);
        *after = -spn_world_position(w, 0).z;
    }
    spn_world_destroy(w);
}

static void test_web_billows_with_speed(void **state)
{
    (void)state;
    double d1, d2, d4, back;
    deflect(1, &d1, NULL);
    deflect(2, &d2, NULL);
    deflect(4, &d4, &back);
    printf("# hub deflection: %.3g mm at 1 m/s, %.3g mm at 2 m/s, %.3g mm at 4 m/s, %.3g mm after the wind\n",
           d1 * 1e3, d2 * 1e3, d4 * 1e3, back * 1e3);
    assert_true(d1 > 1e-4);
    assert_true(d2 > 1.3 * d1);
    assert_true(d4 > 1.3 * d2);
    assert_true(fabs(back) < 0.05 * d4);
}

static void test_turbulence_statistics(void **state)
{
    (void)state;
    spn_air_def d = spn_air_def_default();
    d.speed = 3;
    d.turbulence = 0.2;
    d.gust = 0;
    spn_air_field *air;
    assert_int_equal(spn_air_create(&d, &air), SPN_OK);
    /* rms of each component over many points and times ~ 0.2 * 3 = 0.6 m/s. */
    spn_rng rng;
    spn_rng_seed(&rng, 7);
    double sum2[3] = {0, 0, 0}, div = 0, h = 1e-5;
    const int n = 4000;
    for (int i = 0; i < n; i++) {
        spn_vec3 p = spn_v3(spn_rng_range(&rng, -5, 5), spn_rng_range(&rng, -5, 5), spn_rng_range(&rng, -5, 5));
        double t = spn_rng_range(&rng, 0, 100);
        spn_vec3 u = spn_v3_sub(spn_air_velocity(air, t, p), spn_air_mean(air, t));
        sum2[0] += u.x * u.x, sum2[1] += u.y * u.y, sum2[2] += u.z * u.z;
        /* central differences: the truncation error stays far below the gradients (~k u ~ 10 1/s) */
        double dudx = (spn_air_velocity(air, t, spn_v3(p.x + h, p.y, p.z)).x -
                       spn_air_velocity(air, t, spn_v3(p.x - h, p.y, p.z)).x) / (2 * h);
        double dvdy = (spn_air_velocity(air, t, spn_v3(p.x, p.y + h, p.z)).y -
                       spn_air_velocity(air, t, spn_v3(p.x, p.y - h, p.z)).y) / (2 * h);
        double dwdz = (spn_air_velocity(air, t, spn_v3(p.x, p.y, p.z + h)).z -
                       spn_air_velocity(air, t, spn_v3(p.x, p.y, p.z - h)).z) / (2 * h);
        div = fmax(div, fabs(dudx + dvdy + dwdz));
    }
    double rms = sqrt((sum2[0] + sum2[1] + sum2[2]) / (3.0 * n));
    printf("# turbulence rms %.3f m/s (target 0.6), largest divergence %.2g 1/s\n", rms, div);
    assert_true(fabs(rms - 0.6) < 0.15);
    assert_true(div < 1e-2);
    /* The cached grid (five nodes per smallest eddy, as the runner makes it)
     * interpolates the exact field closely. */
    assert_int_equal(spn_air_set_grid(air, spn_v3(-0.2, -0.2, -0.1), spn_v3(0.2, 0.2, 0.1), 15, 15, 8, 5e-3), SPN_OK);
    assert_int_equal(spn_air_prepare(air, 1.0, 1.001), SPN_OK);
    double err = 0;
    for (int i = 0; i < 200; i++) {
        spn_vec3 p = spn_v3(spn_rng_range(&rng, -0.2, 0.2), spn_rng_range(&rng, -0.2, 0.2), spn_rng_range(&rng, -0.1, 0.1));
        double t = spn_rng_range(&rng, 1.0, 1.005);
        spn_vec3 e = spn_v3_sub(spn_air_sample(air, t, p), spn_air_velocity(air, t, p));
        err += spn_v3_dot(e, e) / 200;
    }
    err = sqrt(err / 3);
    printf("# grid interpolation error %.3g m/s rms per component\n", err);
    assert_true(err < 0.1 * 0.6);
    /* At its nodes and slice times the grid is the exact field (a slice is
     * filled from each axis' cosines and sines, not a cosine per node),
     * also late in a run, where the phases are large: at 2,000 s the field
     * has moved 2 km, some 1e5 radians of the shortest mode, whose rounding
     * alone is 1e-11 radians either way */
    const double times[2] = {1.0, 2000.0}, within[2] = {1e-12, 1e-9};
    for (int c = 0; c < 2; c++) {
        assert_int_equal(spn_air_prepare(air, times[c], times[c]), SPN_OK);
        double gap = 0;
        for (int k = 0; k < 8; k++)
            for (int j = 0; j < 15; j++)
                for (int i = 0; i < 15; i++) {
                    spn_vec3 p = spn_v3(-0.2 + 0.4 * i / 14, -0.2 + 0.4 * j / 14, -0.1 + 0.2 * k / 7);
                    const spn_vec3 e = spn_v3_sub(spn_air_sample(air, times[c], p), spn_air_velocity(air, times[c], p));
                    gap = fmax(gap, spn_v3_len(e));
                }
        printf("# t = %g s: grid nodes within %.2g m/s of the exact field\n", times[c], gap);
        assert_true(gap < within[c]);
    }
    spn_air_destroy(air);
}

/* n points of spn_air_sample_batch against spn_air_sample, bit for bit,
 * each run of `runs` lengths starting where the last ended (so the vector
 * loop's tails and starts fall everywhere). */
static void same_as_samples(spn_air_field *air, double t, const spn_vec3 *p, size_t n)
{
    spn_vec3 *out = malloc(n * sizeof *out);
    assert_non_null(out);
    static const size_t runs[] = {1, 7, 8, 9, 0, 3, 16, 33, 5, 64, 2};
    for (size_t at = 0, r = 0; at < n; r++) {
        size_t len = runs[r % (sizeof runs / sizeof *runs)];
        if (len > n - at) len = n - at;
        spn_air_sample_batch(air, t, p + at, out + at, len);
        at += len;
    }
    for (size_t i = 0; i < n; i++) {
        const spn_vec3 one = spn_air_sample(air, t, p[i]);
        if (memcmp(&one, &out[i], sizeof one) != 0)
            fail_msg("t %.17g, point %zu (%g, %g, %g): batch (%.17g, %.17g, %.17g) against (%.17g, %.17g, %.17g)", t, i,
                     p[i].x, p[i].y, p[i].z, out[i].x, out[i].y, out[i].z, one.x, one.y, one.z);
    }
    free(out);
}

/* spn_air_sample_batch is spn_air_sample point by point, to the bit: on the
 * grid at the prepared times (a step's start, end and midpoint) and at
 * another time between its slices, at points inside the box, outside it
 * (clamped), on its faces and NaN; and exact (no grid, or a time whose
 * slices are not ready), where both evaluate the field itself. */
static void test_batch_samples_same_bits(void **state)
{
    (void)state;
    spn_air_def d = spn_air_def_default();
    d.speed = 2;
    d.turbulence = 0.3;
    spn_air_field *air;
    assert_int_equal(spn_air_create(&d, &air), SPN_OK);
    enum { N = 3000 };
    spn_vec3 *p = malloc(N * sizeof *p);
    assert_non_null(p);
    spn_rng rng;
    spn_rng_seed(&rng, 11);
    const spn_vec3 lo = spn_v3(-0.3, -0.25, -0.1), hi = spn_v3(0.3, 0.25, 0.12);
    for (int i = 0; i < N; i++) { /* most inside, some up to half the box beyond it */
        const double s = i % 5 ? 1.0 : 2.0;
        p[i] = spn_v3(s * spn_rng_range(&rng, lo.x, hi.x), s * spn_rng_range(&rng, lo.y, hi.y),
                      s * spn_rng_range(&rng, lo.z, hi.z));
    }
    p[0] = lo, p[1] = hi, p[2] = spn_v3(hi.x, lo.y, hi.z), p[3] = spn_v3(NAN, 0, 0), p[4] = spn_v3(0, NAN, NAN);
    p[5] = spn_v3(INFINITY, -INFINITY, 0);
    same_as_samples(air, 1.0, p, 40); /* no grid: the field itself */
    assert_int_equal(spn_air_set_grid(air, lo, hi, 17, 13, 9, 5e-3), SPN_OK);
    const double t0 = 1.0, t1 = 1.0 + 7e-3;
    assert_int_equal(spn_air_prepare(air, t0, t1), SPN_OK);
    const double times[4] = {t0, t1, 0.5 * (t0 + t1), t0 + 0.3 * (t1 - t0)};
    for (int k = 0; k < 4; k++) same_as_samples(air, times[k], p, N);
    same_as_samples(air, 50.0, p, 40); /* slices not ready: the field itself */
    printf("# %d points at 4 times on a 17 x 13 x 9 grid, and exact: the batch gives the samples' bits\n", N);
    free(p);
    spn_air_destroy(air);
}

/* A slice fills only the grid rows the samples have touched, ROW_MARGIN
 * more on each side (wind_air.c): the values there are the bits of a
 * slice filled whole; a point beyond them takes the exact field until the
 * next spn_air_prepare, which fills its rows too. */
static void test_slices_fill_the_rows_sampled(void **state)
{
    (void)state;
    spn_air_def d = spn_air_def_default();
    d.turbulence = 0.3;
    spn_air_field *lazy, *whole;
    assert_int_equal(spn_air_create(&d, &lazy), SPN_OK);
    assert_int_equal(spn_air_create(&d, &whole), SPN_OK);
    const spn_vec3 lo = spn_v3(-0.3, -0.3, -0.3), hi = spn_v3(0.3, 0.3, 0.3);
    assert_int_equal(spn_air_set_grid(lazy, lo, hi, 20, 20, 20, 5e-3), SPN_OK);
    assert_int_equal(spn_air_set_grid(whole, lo, hi, 20, 20, 20, 5e-3), SPN_OK);
    enum { N = 400 };
    spn_vec3 p[N], a[N], b[N];
    spn_rng rng;
    spn_rng_seed(&rng, 5);
    for (int i = 0; i < N; i++) /* a sheet: a band of y, a few rows of z */
        p[i] = spn_v3(spn_rng_range(&rng, -0.3, 0.3), spn_rng_range(&rng, -0.1, 0.1), spn_rng_range(&rng, -0.01, 0.01));
    /* the first slices whole, then samples on the sheet */
    assert_int_equal(spn_air_prepare(lazy, 1.0, 1.001), SPN_OK);
    spn_air_sample_batch(lazy, 1.0, p, a, N);
    /* ten slices on: new slices, filled for the sheet's rows only */
    const double t = 1.05;
    assert_int_equal(spn_air_prepare(lazy, t, t + 1e-3), SPN_OK);
    assert_int_equal(spn_air_prepare(whole, t, t + 1e-3), SPN_OK);
    spn_air_sample_batch(lazy, t, p, a, N);
    spn_air_sample_batch(whole, t, p, b, N);
    assert_memory_equal(a, b, sizeof a);
    /* a point far off the sheet: the field itself, in a batch and alone */
    const spn_vec3 q[2] = {spn_v3(0.1, 0.25, 0.2), spn_v3(-0.2, -0.25, -0.25)};
    spn_vec3 u[2], w[2];
    spn_air_sample_batch(lazy, t, q, u, 2);
    for (int i = 0; i < 2; i++) {
        const spn_vec3 exact = spn_air_velocity(lazy, t, q[i]), one = spn_air_sample(lazy, t, q[i]);
        assert_memory_equal(&u[i], &exact, sizeof exact);
        assert_memory_equal(&one, &exact, sizeof exact);
    }
    /* the next prepare fills their rows: interpolated as a whole slice is */
    assert_int_equal(spn_air_prepare(lazy, t, t + 1e-3), SPN_OK);
    spn_air_sample_batch(lazy, t, q, u, 2);
    spn_air_sample_batch(whole, t, q, w, 2);
    assert_memory_equal(u, w, sizeof u);
    assert_false(memcmp(&u[0], &(spn_vec3){0, 0, 0}, sizeof u[0]) == 0);
    printf("# slices filled for the rows sampled: the bits of whole slices; off them the exact field\n");
    spn_air_destroy(lazy);
    spn_air_destroy(whole);
}

/* A web in turbulent air stepped on 1 and 2 threads: the samples of a
 * pure air function (spn_air_attach declares spn_air_sample so) are taken
 * on the world's threads, and the states are the same bits as on one
 * thread, as with the samples taken serially, and as with one call of the
 * air function a segment instead of its batch (`batch` false); the air
 * moved the web. The spring pass takes threads for its 1,600 segments here
 * (parallel_min 1,024). `speed` 0: still air. */
static double *air_run(int threads, bool pure, bool batch, double speed, uint32_t *n)
{
    spn_world_def wd = spn_world_def_default();
    wd.threads = threads;
    wd.parallel_min = 1024;
    spn_orb_scene_def od = spn_orb_scene_def_default();
    od.rings = 20, od.radials = 40;
    spn_world *w = NULL;
    assert_int_equal(spn_scene_orb(&wd, &od, &w), SPN_OK);
    spn_air_def d = spn_air_def_default();
    d.speed = speed;
    spn_air_field *air;
    assert_int_equal(spn_air_create(&d, &air), SPN_OK);
    assert_int_equal(spn_air_set_grid(air, spn_v3(-0.3, -0.3, -0.15), spn_v3(0.3, 0.3, 0.15), 21, 21, 11, 5e-3),
                     SPN_OK);
    spn_air_attach(air, w);
    if (!pure) spn_world_set_air_pure(w, false);
    if (!batch) spn_world_set_air_batch(w, NULL);
    const double dt = 0.5 * spn_world_stable_step(w, 0);
    for (int i = 0; i < 300; i++) {
        const double t = spn_world_time(w);
        assert_int_equal(spn_air_prepare_held(air, t, t + dt), SPN_OK);
        assert_int_equal(spn_world_step(w, dt), SPN_OK);
    }
    *n = spn_world_particle_count(w);
    double *s = malloc(6 * (size_t)*n * sizeof *s);
    assert_non_null(s);
    for (uint32_t i = 0; i < *n; i++) {
        const spn_vec3 x = spn_world_position(w, i), v = spn_world_velocity(w, i);
        memcpy(s + 6 * (size_t)i, (double[6]){x.x, x.y, x.z, v.x, v.y, v.z}, 6 * sizeof *s);
    }
    spn_world_destroy(w);
    spn_air_destroy(air);
    return s;
}

static void test_air_on_threads(void **state)
{
    (void)state;
    uint32_t n;
    double *one = air_run(1, true, true, 3, &n), *two = air_run(2, true, true, 3, &n),
           *serial = air_run(2, false, true, 3, &n), *points = air_run(2, true, false, 3, &n),
           *still = air_run(2, true, true, 0, &n);
    const size_t bytes = 6 * (size_t)n * sizeof *one;
    assert_memory_equal(one, two, bytes);
    assert_memory_equal(two, serial, bytes);
    assert_memory_equal(two, points, bytes);
    double moved = 0;
    for (size_t i = 0; i < 6 * (size_t)n; i++) moved = fmax(moved, fabs(one[i] - still[i]));
    printf("# air on 1 and 2 threads, in batches and point by point: same bits; largest change the air made %.3g\n",
           moved);
    assert_true(moved > 0);
    free(one), free(two), free(serial), free(points), free(still);
}

/* The velocities one step from rest gives the 20 x 40 orb web in turbulent
 * air at t = 12.3 ms (the step's other forces the same in every case, so
 * their differences are the air's): `how` 0 on a grid at the field's
 * resolution (spn_air_attach on a grid: each particle's air at the centre
 * of its cell of a sixteenth of the grid's, blended between the slices'
 * times), 1 on the grid at each particle at the step's time, 2 the field
 * itself. */
static spn_vec3 *first_step(int how, uint32_t *n)
{
    spn_orb_scene_def od = spn_orb_scene_def_default();
    od.rings = 20, od.radials = 40;
    spn_world_def wd = spn_world_def_default();
    spn_world *w = NULL;
    assert_int_equal(spn_scene_orb(&wd, &od, &w), SPN_OK);
    spn_air_field *air;
    spn_air_def d = spn_air_def_default();
    d.speed = 3;
    assert_int_equal(spn_air_create(&d, &air), SPN_OK);
    if (how < 2)
        assert_int_equal(
            spn_air_set_grid(air, spn_v3(-0.3, -0.3, -0.15), spn_v3(0.3, 0.3, 0.15), 21, 21, 11, 5e-3), SPN_OK);
    spn_air_attach(air, w);
    double interval, spacing;
    spn_world_air_resolution(w, &interval, &spacing);
    assert_true(how < 2 ? interval == 5e-3 && fabs(spacing - 0.03 / 16) < 1e-15 : interval == 0 && spacing == 0);
    if (how == 1) assert_int_equal(spn_world_set_air_resolution(w, 0, 0), SPN_OK);
    const double t = 0.0123, dt = 1e-7;
    spn_world_set_time(w, t);
    assert_int_equal(spn_air_prepare_held(air, t, t + dt), SPN_OK);
    assert_int_equal(spn_world_step(w, dt), SPN_OK);
    *n = spn_world_particle_count(w);
    spn_vec3 *v = malloc(*n * sizeof *v);
    assert_non_null(v);
    for (uint32_t i = 0; i < *n; i++) v[i] = spn_world_velocity(w, i);
    spn_world_destroy(w);
    spn_air_destroy(air);
    return v;
}

static double rms_apart(const spn_vec3 *a, const spn_vec3 *b, uint32_t n)
{
    double s = 0;
    for (uint32_t i = 0; i < n; i++) s += spn_v3_dot(spn_v3_sub(a[i], b[i]), spn_v3_sub(a[i], b[i]));
    return sqrt(s / n);
}

/* The field's resolution costs the web's air a fraction of what the grid
 * itself costs it: sampled at cells of a sixteenth of the grid's, the air's
 * forces move from the grid's at the particles by about a fifth of the
 * grid's own distance from the field (docs/physics.md, "Air drag on
 * threads"). */
static void test_air_at_the_resolution(void **state)
{
    (void)state;
    uint32_t n;
    spn_vec3 *held = first_step(0, &n), *grid = first_step(1, &n), *exact = first_step(2, &n), *still;
    const double off = rms_apart(held, grid, n), grid_off = rms_apart(grid, exact, n);
    {
        spn_orb_scene_def od = spn_orb_scene_def_default();
        od.rings = 20, od.radials = 40;
        spn_world_def wd = spn_world_def_default();
        spn_world *w = NULL;
        assert_int_equal(spn_scene_orb(&wd, &od, &w), SPN_OK);
        spn_world_set_time(w, 0.0123);
        assert_int_equal(spn_world_step(w, 1e-7), SPN_OK);
        still = malloc(n * sizeof *still);
        assert_non_null(still);
        for (uint32_t i = 0; i < n; i++) still[i] = spn_world_velocity(w, i);
        spn_world_destroy(w);
    }
    const double air = rms_apart(exact, still, n);
    printf("# one step's air (rms velocity %.3g m/s): the grid %.3g from the field, at the resolution %.3g from the "
           "grid (%.2f of it)\n",
           air, grid_off, off, off / grid_off);
    assert_true(grid_off > 0 && grid_off < 0.2 * air);
    assert_true(off > 0 && off < 0.35 * grid_off);
    free(held), free(grid), free(exact), free(still);
}

/* spn_air_def.stop: from that time on the air is still (the mean, the
 * field and its samples, on a grid or not, alone or in a batch, are zero);
 * before it, a field that stops gives the bits of one that never does. */
static bool is_zero(spn_vec3 u) { return u.x == 0 && u.y == 0 && u.z == 0; }

static void test_air_stops(void **state)
{
    (void)state;
    spn_air_def d = spn_air_def_default();
    d.speed = 2;
    d.turbulence = 0.3;
    spn_air_field *goes, *stops;
    assert_int_equal(spn_air_create(&d, &goes), SPN_OK);
    d.stop = 1.0;
    assert_int_equal(spn_air_create(&d, &stops), SPN_OK);
    enum { N = 200 };
    spn_vec3 p[N], a[N], b[N];
    spn_rng rng;
    spn_rng_seed(&rng, 3);
    for (int i = 0; i < N; i++)
        p[i] = spn_v3(spn_rng_range(&rng, -0.3, 0.3), spn_rng_range(&rng, -0.3, 0.3), spn_rng_range(&rng, -0.1, 0.1));
    const spn_vec3 lo = spn_v3(-0.3, -0.3, -0.1), hi = spn_v3(0.3, 0.3, 0.1);
    for (int grid = 0; grid < 2; grid++) {
        if (grid) {
            assert_int_equal(spn_air_set_grid(goes, lo, hi, 13, 13, 5, 5e-3), SPN_OK);
            assert_int_equal(spn_air_set_grid(stops, lo, hi, 13, 13, 5, 5e-3), SPN_OK);
        }
        const double times[5] = {0.99, 0.998, 1.0, 1.002, 30.0};
        for (int k = 0; k < 5; k++) {
            const double t = times[k];
            assert_int_equal(spn_air_prepare(goes, t, t + 1e-3), SPN_OK);
            assert_int_equal(spn_air_prepare(stops, t, t + 1e-3), SPN_OK);
            spn_air_sample_batch(goes, t, p, a, N);
            spn_air_sample_batch(stops, t, p, b, N);
            if (t < 1.0) {
                assert_memory_equal(a, b, sizeof a);
                assert_true(spn_v3_len(a[0]) > 0.5);
                continue;
            }
            assert_true(spn_v3_len(a[0]) > 0.5); /* (the other field still blows) */
            assert_true(is_zero(spn_air_mean(stops, t)));
            for (int i = 0; i < N; i++) {
                assert_true(is_zero(b[i]));
                assert_true(is_zero(spn_air_sample(stops, t, p[i])));
                assert_true(is_zero(spn_air_velocity(stops, t, p[i])));
            }
        }
    }
    printf("# a field that stops at 1 s: its bits before, still air from then on, on a grid and without\n");
    spn_air_destroy(goes);
    spn_air_destroy(stops);
}

static void test_rejects_bad_air(void **state)
{
    (void)state;
    spn_air_def d = spn_air_def_default();
    spn_air_field *air = NULL;
    d.direction = spn_v3(0, 0, 0);
    assert_int_equal(spn_air_create(&d, &air), SPN_ERR_INVALID);
    assert_non_null(strstr(spn_last_error(), "direction"));
    d = spn_air_def_default();
    d.speed = -1;
    assert_int_equal(spn_air_create(&d, &air), SPN_ERR_INVALID);
    d = spn_air_def_default();
    d.small_scale = 2;
    assert_int_equal(spn_air_create(&d, &air), SPN_ERR_INVALID);
    d = spn_air_def_default();
    d.stop = NAN;
    assert_int_equal(spn_air_create(&d, &air), SPN_ERR_INVALID);
    assert_non_null(strstr(spn_last_error(), "stop"));
    assert_null(air);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_segment_drag_formula),
        cmocka_unit_test(test_air_power),
        cmocka_unit_test(test_web_billows_with_speed),
        cmocka_unit_test(test_turbulence_statistics),
        cmocka_unit_test(test_batch_samples_same_bits),
        cmocka_unit_test(test_slices_fill_the_rows_sampled),
        cmocka_unit_test(test_air_on_threads),
        cmocka_unit_test(test_air_at_the_resolution),
        cmocka_unit_test(test_air_stops),
        cmocka_unit_test(test_rejects_bad_air),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
