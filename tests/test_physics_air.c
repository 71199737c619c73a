/* Air drag on threads and Provot deformation limits.
 * - C_d(Re) follows Lamb's Oseen result at low Re and White's correlation
 *   above, continuously between.
 * - A segment across a steady wind feels 1/2 rho C_d d L U^2, half on each
 *   end; along the wind it feels nothing.
 * - A taut thread in wind settles to the same shape under implicit and
 *   tiny-step explicit integration, and implicit stays stable at 1/60 s.
 * - Provot limits keep every spring within (1 + max_strain) of its rest. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "physics_util.h"

static void test_drag_coefficient(void **state)
{
    (void)state;
    /* Lamb (1911) below Re = 0.5, White above Re = 2. */
    double re[] = {1e-4, 1e-2, 0.3};
    for (int i = 0; i < 3; i++) {
        double lamb = 8 * SPN_PI / (re[i] * (2.002 - log(re[i])));
        assert_true(fabs(spn_cylinder_drag_coefficient(re[i]) - lamb) < 1e-12 * lamb);
    }
    /* Lamb's law against its closed form with libm's log from the smallest
     * subnormal Re up: the code's own logarithm (ln_pos, forces.c, which
     * vectorises) differs from libm's by an ulp or two at most */
    double lamb_far = 0;
    for (double r = 4.9e-324; r <= 0.5; r *= r < 1e-300 ? 3 : 1.0011) {
        const double lamb = 8 * SPN_PI / (r * (2.002 - log(r)));
        lamb_far = fmax(lamb_far, fabs(spn_cylinder_drag_coefficient(r) / lamb - 1));
    }
    printf("# Lamb's law within %.2g of its closed form with libm's log\n", lamb_far);
    assert_true(lamb_far < 1e-15);
    assert_true(fabs(spn_cylinder_drag_coefficient(1000) - (1 + 10 / pow(1000, 2.0 / 3))) < 1e-12);
    /* Measured values (Tritton 1959; Wieselsberger): C_d(10) ~ 2.8-3.0, C_d(100) ~ 1.4-1.5, C_d(1e4) ~ 1.1-1.2. */
    assert_true(spn_cylinder_drag_coefficient(10) > 2.5 && spn_cylinder_drag_coefficient(10) < 3.3);
    assert_true(spn_cylinder_drag_coefficient(100) > 1.3 && spn_cylinder_drag_coefficient(100) < 1.6);
    assert_true(spn_cylinder_drag_coefficient(1e4) > 1.0 && spn_cylinder_drag_coefficient(1e4) < 1.3);
    /* Between them the logarithms blended linearly in ln Re: the closed
     * form, which the code evaluates as a series (forces.c), to round-off */
    double far = 0;
    for (double r = 0.5; r <= 2; r *= 1.0007) {
        const double lamb = 8 * SPN_PI / (r * (2.002 - log(r))), white = 1 + 10 / pow(r, 2.0 / 3);
        const double s = (log(r) - log(0.5)) / log(4), blend = lamb * exp(s * log(white / lamb));
        far = fmax(far, fabs(spn_cylinder_drag_coefficient(r) / blend - 1));
    }
    printf("# blend of Lamb and White within %.2g of its closed form\n", far);
    assert_true(far < 4e-15);
    /* Continuous and decreasing across the blend. */
    double prev = spn_cylinder_drag_coefficient(0.3);
    for (double r = 0.3; r < 3; r *= 1.001) {
        double c = spn_cylinder_drag_coefficient(r);
        assert_true(c <= prev && c > 0.97 * prev);
        prev = c;
    }
    assert_true(spn_cylinder_drag_coefficient(0) == 0);
}

static spn_vec3 steady(void *user, double t, spn_vec3 p)
{
    (void)t, (void)p;
    return *(const spn_vec3 *)user;
}

/* n particles of mass m, len apart along x, without gravity, joined in a
 * row by springs of k 1 at rest, tagged 7 (the last `plain` tagged 8). */
static spn_world *row_of_segments(int n, double len, double m, int plain)
{
    spn_world_def def = spn_world_def_default();
    def.gravity = spn_v3(0, 0, 0);
    spn_world *w = spn_world_create(&def);
    spn_particle_def p = spn_particle_def_default();
    p.mass = m;
    for (int i = 0; i < n; i++) {
        p.position = spn_v3(i * len, 0, 0);
        assert_int_equal(spn_world_add_particle(w, &p, NULL), SPN_OK);
    }
    spn_spring_def s = spn_spring_def_default();
    s.k = 1;
    for (int i = 0; i + 1 < n; i++) {
        s.a = (uint32_t)i, s.b = (uint32_t)i + 1, s.tag = i + 1 < n - plain ? 7 : 8;
        assert_int_equal(spn_world_add_spring(w, &s, NULL), SPN_OK);
    }
    return w;
}

static void test_segment_force(void **state)
{
    (void)state;
    const double d = 3e-6, rho = 1.2, mu = 1.8e-5, len = 0.01, m = 1e-7, dt = 1e-9;
    spn_vec3 winds[2] = {spn_v3(0, 0, 2), spn_v3(2, 0, 0)};
    for (int c = 0; c < 2; c++) {
        spn_world *w = row_of_segments(2, len, m, 0);
        spn_world_set_air(w, steady, &winds[c], rho, mu);
        spn_world_set_tag_diameter(w, 7, d);
        assert_int_equal(spn_world_step(w, dt), SPN_OK);
        double u = 2, cd = spn_cylinder_drag_coefficient(rho * u * d / mu);
        double expect = c == 0 ? 0.5 * rho * cd * d * len * u * u : 0;
        for (uint32_t i = 0; i < 2; i++) {
            spn_vec3 f = spn_v3_scale(spn_world_velocity(w, i), m / dt);
            assert_true(fabs(f.z - expect / 2) <= 1e-6 * (expect + 1e-30));
            assert_true(fabs(f.x) < 1e-15 && fabs(f.y) < 1e-15);
        }
        spn_world_destroy(w);
    }
}

/* An air function that keeps where it was asked: w_z = 2 + (x / 0.01)^2,
 * so 2 and 3 m/s at the ends of a 1 cm segment along x, 2.25 at its
 * midpoint. */
typedef struct asked {
    int n;
    spn_vec3 at[8];
} asked;

static spn_vec3 curved(void *user, double t, spn_vec3 p)
{
    (void)t;
    asked *a = user;
    if (a->n < 8) a->at[a->n] = p;
    a->n++;
    const double q = p.x / 0.01;
    return spn_v3(0, 0, 2 + q * q);
}

/* The air is taken at the particles that end a segment with a diameter,
 * once each a force evaluation, and a segment feels the mean of its ends'
 * air relative to them (docs/physics.md, "Air drag on threads"): here 2.5
 * m/s, where the midpoint's air would give 2.25. A particle whose segments
 * have no diameter is not asked about. */
static void test_air_at_the_ends(void **state)
{
    (void)state;
    const double d = 3e-6, rho = 1.2, mu = 1.8e-5, len = 0.01, m = 1e-7, dt = 1e-9;
    spn_world *w = row_of_segments(3, len, m, 1); /* (the second segment, tag 8, has no diameter) */
    spn_world_set_integrator(w, SPN_INTEGRATOR_SYMPLECTIC);
    asked a = {0};
    spn_world_set_air(w, curved, &a, rho, mu);
    spn_world_set_tag_diameter(w, 7, d);
    assert_int_equal(spn_world_step(w, dt), SPN_OK);
    assert_int_equal(a.n, 2);
    assert_true(a.at[0].x == 0 && a.at[1].x == len);
    const double u = 2.5, cd = spn_cylinder_drag_coefficient(rho * u * d / mu);
    const double half = 0.25 * rho * cd * d * len * u * u;
    for (uint32_t i = 0; i < 3; i++) {
        const spn_vec3 f = spn_v3_scale(spn_world_velocity(w, i), m / dt);
        const double expect = i < 2 ? half : 0;
        assert_true(fabs(f.z - expect) <= 1e-6 * half);
        assert_true(fabs(f.x) < 1e-15 && fabs(f.y) < 1e-15);
    }
    spn_world_destroy(w);
}

/* An air function linear in time and in x, that keeps where and when it
 * was asked: w_z = 2 + 100 t + 10 x. */
typedef struct asked_when {
    int n;
    spn_vec3 at[16];
    double t[16];
} asked_when;

static spn_vec3 linear(void *user, double t, spn_vec3 p)
{
    asked_when *a = user;
    if (a->n < 16) a->at[a->n] = p, a->t[a->n] = t;
    a->n++;
    return spn_v3(0, 0, 2 + 100 * t + 10 * p.x);
}

/* Calls k to k + n - 1 were at time t, at the centres of the cells (of 3
 * mm) cx[0..n) along x, the first along y and z. */
static void asked_at(const asked_when *a, int k, int n, double t, const double *cx)
{
    for (int i = 0; i < n; i++) {
        assert_true(a->t[k + i] == t);
        assert_true(fabs(a->at[k + i].x - (cx[i] + 0.5) * 3e-3) < 1e-15);
        assert_true(fabs(a->at[k + i].y - 1.5e-3) < 1e-15 && fabs(a->at[k + i].z - 1.5e-3) < 1e-15);
    }
}

/* Under spn_world_set_air_resolution (5 ms, 3 mm) a particle's air is taken
 * at the centre of its 3 mm cell at the two ends of the 5 ms interval the
 * step is in, and blended between them: for air linear in time, the air at
 * the cell's centre at the step's time. It is taken again only when the
 * interval changes (the next one: only its end, the start being the end
 * held) or a particle changes cell (that particle alone), and what a
 * particle feels is a function of its position and the time: a copy of the
 * world, which holds nothing, steps to the same bits. */
static void test_air_resolution(void **state)
{
    (void)state;
    const double d = 3e-6, rho = 1.2, mu = 1.8e-5, len = 0.01, m = 1e-7, dt = 1e-9;
    spn_world *w = row_of_segments(2, len, m, 0);
    spn_world_set_integrator(w, SPN_INTEGRATOR_SYMPLECTIC);
    asked_when a = {0};
    spn_world_set_air(w, linear, &a, rho, mu);
    spn_world_set_tag_diameter(w, 7, d);
    assert_int_equal(spn_world_set_air_resolution(w, 5e-3, 3e-3), SPN_OK);
    spn_world_set_time(w, 0.0123);
    assert_int_equal(spn_world_step(w, dt), SPN_OK);
    assert_int_equal(a.n, 4); /* both ends of interval 2 at both particles */
    const double cells[2] = {0, 3}, moved[1] = {4};
    asked_at(&a, 0, 2, 2 * 5e-3, cells);
    asked_at(&a, 2, 2, 3 * 5e-3, cells);
    const double u = 2 + 100 * 0.0123 + 10 * (0.5 * (0.5 + 3.5) * 3e-3); /* the ends' mean */
    const double half = 0.25 * rho * spn_cylinder_drag_coefficient(rho * u * d / mu) * d * len * u * u;
    for (uint32_t i = 0; i < 2; i++) {
        const spn_vec3 f = spn_v3_scale(spn_world_velocity(w, i), m / dt);
        assert_true(fabs(f.z - half) <= 1e-6 * half);
    }
    assert_int_equal(spn_world_step(w, dt), SPN_OK);
    assert_int_equal(a.n, 4); /* the same cells and interval: nothing asked */
    spn_world_set_time(w, 0.0151);
    assert_int_equal(spn_world_step(w, dt), SPN_OK);
    assert_int_equal(a.n, 6); /* the next interval: its end */
    asked_at(&a, 4, 2, 4 * 5e-3, cells);
    assert_int_equal(spn_world_set_position(w, 1, spn_v3(0.0125, 0, 0)), SPN_OK);
    assert_int_equal(spn_world_step(w, dt), SPN_OK);
    assert_int_equal(a.n, 8); /* particle 1 in a new cell: both ends there */
    asked_at(&a, 6, 1, 3 * 5e-3, moved);
    asked_at(&a, 7, 1, 4 * 5e-3, moved);
    spn_world *copy = spn_world_clone(w);
    assert_non_null(copy);
    for (int i = 0; i < 3; i++) {
        assert_int_equal(spn_world_step(w, dt), SPN_OK);
        assert_int_equal(spn_world_step(copy, dt), SPN_OK);
    }
    for (uint32_t i = 0; i < 2; i++) {
        const spn_vec3 xa = spn_world_position(w, i), xb = spn_world_position(copy, i);
        const spn_vec3 va = spn_world_velocity(w, i), vb = spn_world_velocity(copy, i);
        assert_memory_equal(&xa, &xb, sizeof xa);
        assert_memory_equal(&va, &vb, sizeof va);
    }
    spn_world_set_time(w, 0.05);
    const int before = a.n;
    assert_int_equal(spn_world_step(w, dt), SPN_OK);
    assert_int_equal(a.n - before, 4); /* an interval further on: everything */
    spn_world_destroy(copy);
    spn_world_destroy(w);
}

/* The resolution takes two positive finite numbers or two zeros, and
 * spn_world_set_air clears it. */
static void test_air_resolution_rejects(void **state)
{
    (void)state;
    spn_world *w = row_of_segments(2, 0.01, 1e-7, 0);
    const double bad[][2] = {{-1, 1e-3}, {5e-3, 0}, {0, 3e-3}, {NAN, 1e-3}, {5e-3, INFINITY}, {5e-3, -2e-3}};
    assert_int_equal(spn_world_set_air_resolution(w, 5e-3, 3e-3), SPN_OK);
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        assert_int_equal(spn_world_set_air_resolution(w, bad[i][0], bad[i][1]), SPN_ERR_INVALID);
        assert_non_null(strstr(spn_last_error(), "air resolution"));
        double dt, h;
        spn_world_air_resolution(w, &dt, &h);
        assert_true(dt == 5e-3 && h == 3e-3); /* unchanged */
    }
    asked_when a = {0};
    spn_world_set_air(w, linear, &a, 1.2, 1.8e-5);
    double dt = 1, h = 1;
    spn_world_air_resolution(w, &dt, &h);
    assert_true(dt == 0 && h == 0);
    assert_int_equal(spn_world_set_air_resolution(w, 0, 0), SPN_OK);
    spn_world_destroy(w);
}

/* A taut 20-segment silk-like thread across a 2 m/s wind. */
static spn_world *thread_in_wind(spn_integrator integ, spn_vec3 *wind)
{
    spn_world_def def = spn_world_def_default();
    def.integrator = integ;
    def.drag = 20;
    spn_world *w;
    assert_int_equal(spn_scene_chain(&def, spn_v3(0, 0, 0), spn_v3(0.2, 0, 0), 20, 0.2 / 1.01, 2e-7, 5, 0, &w),
                     SPN_OK);
    for (uint32_t s = 0; s < spn_world_spring_count(w); s++) spn_world_set_spring_tag(w, s, 3);
    spn_world_set_air(w, steady, wind, 1.2, 1.8e-5);
    spn_world_set_tag_diameter(w, 3, 3e-6);
    return w;
}

static void test_thread_in_wind(void **state)
{
    (void)state;
    spn_vec3 wind = spn_v3(0, 0, 2);
    spn_world *imp = thread_in_wind(SPN_INTEGRATOR_IMPLICIT, &wind);
    spn_world *ex = thread_in_wind(SPN_INTEGRATOR_SYMPLECTIC, &wind);
    for (int i = 0; i < 300; i++) assert_int_equal(spn_world_step(imp, 1.0 / 60), SPN_OK);
    for (int i = 0; i < 60000; i++) assert_int_equal(spn_world_step(ex, 1e-5), SPN_OK);
    double bow = 0, diff = 0;
    for (uint32_t i = 0; i < spn_world_particle_count(imp); i++) {
        spn_vec3 a = spn_world_position(imp, i), b = spn_world_position(ex, i);
        bow = fmax(bow, b.z);
        diff = fmax(diff, spn_v3_len(spn_v3_sub(a, b)));
    }
    print_message("thread bows %.3e m downwind; implicit vs explicit %.2e relative\n", bow, diff / bow);
    assert_true(bow > 1e-5);
    assert_true(diff < 1e-4 * bow);
    spn_energy e = spn_world_energy(ex);
    assert_true(e.external_work > 0);
    spn_world_destroy(imp);
    spn_world_destroy(ex);
}

/* Largest strain of a soft chain (it would stretch far under gravity) after
 * 2 s, with the given Provot limit. */
static double chain_strain(double limit)
{
    spn_world_def def = spn_world_def_default();
    def.provot_max_strain = limit;
    def.provot_iterations = 50;
    spn_world *w;
    assert_int_equal(spn_scene_chain(&def, spn_v3(0, 0, 0), spn_v3(1, 0, 0), 10, 1.0, 1.0, 20, 0.5, &w), SPN_OK);
    for (int i = 0; i < 2000; i++) assert_int_equal(spn_world_step(w, 1e-3), SPN_OK);
    double worst = 0;
    for (uint32_t s = 0; s < spn_world_spring_count(w); s++) {
        spn_spring_info info = spn_world_spring(w, s);
        worst = fmax(worst, info.length / info.rest - 1);
    }
    spn_world_destroy(w);
    return worst;
}

static void test_provot(void **state)
{
    (void)state;
    double free_strain = chain_strain(0), limited = chain_strain(0.1);
    print_message("largest strain: %.4f free, %.6f with Provot limit 0.1\n", free_strain, limited);
    assert_true(free_strain > 0.2);
    assert_true(limited <= 0.1 * 1.01); /* Provot does not promise exactness */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_drag_coefficient),
        cmocka_unit_test(test_segment_force),
        cmocka_unit_test(test_air_at_the_ends),
        cmocka_unit_test(test_air_resolution),
        cmocka_unit_test(test_air_resolution_rejects),
        cmocka_unit_test(test_thread_in_wind),
        cmocka_unit_test(test_provot),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
