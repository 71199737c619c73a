/* The float32 lattice step (src/physics/lattice_f32.c) checked against
 * float64 and against an analytic answer:
 *  - the standard orb web stepped both ways stays within the bound its
 *    force error gives (positions relative to the web's size and to the
 *    distance moved, total energy, energy dissipated), with symplectic
 *    Euler and with RK4, and its damping's books on a web of several bands;
 *  - a mass on eight pre-strained springs oscillates at the frequency of its
 *    small-amplitude stiffness, sum k cos^2 + (T / L) sin^2, in float32 as in
 *    float64;
 *  - same bits on 1 and 2 threads and run to run; a blow-up leaves the state
 *    spn_world_advance promises; the general path and the default are
 *    untouched (bit-identical to float64).
 *
 * The bound on the web. A spring's difference vector is exact to 2^-24 of
 * its length, so its stretch (2% of the length) carries ~2^-24 * 3 / 0.02 =
 * 1.5e-5 relative error at worst and its force likewise. Over a run the
 * trajectories part by that relative force error times the motion, and by
 * its phase drift in the fastest modes (frequency error ~1e-5 times omega t):
 * for the 0.2 ms run below, a few 1e-5 of the distance moved. Measured:
 * 1.3e-6 of it. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <spinneret/spinneret.h>

static spn_world *orb(spn_integrator integ, int rings, int radials, int threads, uint32_t parallel_min,
                      spn_precision precision)
{
    spn_world_def def = spn_world_def_default();
    def.integrator = integ;
    def.threads = threads;
    if (parallel_min) def.parallel_min = parallel_min;
    spn_orb_scene_def od = spn_orb_scene_def_default();
    od.rings = rings;
    od.radials = radials;
    spn_world *w;
    assert_int_equal(spn_scene_orb(&def, &od, &w), SPN_OK);
    spn_world_set_precision(w, precision);
    assert_int_equal(spn_world_compile(w), SPN_OK);
    assert_string_equal(spn_world_step_path(w), "lattice");
    return w;
}

static double max_gap(const spn_world *a, const spn_world *b)
{
    double top = 0;
    for (uint32_t i = 0; i < spn_world_particle_count(a); i++)
        top = fmax(top, spn_v3_len(spn_v3_sub(spn_world_position(a, i), spn_world_position(b, i))));
    return top;
}

static bool same_bits(const spn_world *a, const spn_world *b)
{
    const size_t n = spn_world_particle_count(a) * sizeof(spn_vec3);
    return !memcmp(spn_world_positions(a), spn_world_positions(b), n) &&
           !memcmp(spn_world_velocities(a), spn_world_velocities(b), n);
}

/* The 961-particle web (20 rings x 48 radials, radius 0.15 m) sagging and
 * ringing under gravity from its flat pre-strained start, 2,000 steps of
 * 1e-7 s in calls of 250 (so with rebases inside and between calls). */
static void orb_against_float64(spn_integrator integ)
{
    spn_world *w64 = orb(integ, 20, 48, 1, 0, SPN_PRECISION_FLOAT64);
    spn_world *w32 = orb(integ, 20, 48, 1, 0, SPN_PRECISION_FLOAT32);
    spn_world *start = spn_world_clone(w64);
    assert_int_equal(spn_world_precision(w32), SPN_PRECISION_FLOAT32);
    for (int k = 0; k < 8; k++) {
        assert_int_equal(spn_world_advance(w64, 1e-7, 250), SPN_OK);
        assert_int_equal(spn_world_advance(w32, 1e-7, 250), SPN_OK);
    }
    const double moved = max_gap(w64, start), gap = max_gap(w64, w32);
    const double radius = 0.15;
    assert_true(moved > 1e-5); /* the web did move: 5.7e-4 m */
    assert_false(same_bits(w64, w32)); /* and the float32 path did run */
    assert_true(gap < 2e-5 * moved);   /* measured 1.3e-6 of it */
    assert_true(gap < 1e-8 * radius);  /* 3.4e-10 m */
    const spn_energy e64 = spn_world_energy(w64), e32 = spn_world_energy(w32);
    const double scale = e64.kinetic + e64.elastic;
    /* measured 9e-9 and 3e-9 of the energy in play */
    assert_true(fabs(spn_world_total_energy(w64) - spn_world_total_energy(w32)) < 1e-7 * scale);
    assert_true(fabs(e64.elastic - e32.elastic) < 1e-7 * scale);
    /* the damping's books, a term per spring and step: measured 9.7e-7
     * (symplectic) and 2.2e-7 (RK4) of the energy dissipated; half of one
     * radial spring's term a row lost gives 7.4e-3 */
    assert_true(fabs(e32.dissipated - e64.dissipated) < 1e-5 * e64.dissipated);
    spn_world_destroy(start);
    spn_world_destroy(w64);
    spn_world_destroy(w32);
}

static void test_orb_against_float64(void **state)
{
    (void)state;
    orb_against_float64(SPN_INTEGRATOR_SYMPLECTIC);
    orb_against_float64(SPN_INTEGRATOR_RK4);
}

/* The damping's books of the float32 step against float64's on a web of
 * several bands: 12 rings x 512 radials from def.parallel_min 256, so bands
 * of eight rows, the second band's first radial springs summed apart (the
 * cut) and some steps taken in blocked passes (which test_physics_lattice
 * checks bit for bit against single float32 steps); 800 steps in calls of
 * 8. Measured 5.3e-6 (symplectic) and 5.6e-6 (RK4) of the energy
 * dissipated; half of one radial spring's term a row lost gives 9.4e-4. */
static void test_books_in_bands(void **state)
{
    (void)state;
    const spn_integrator integs[] = {SPN_INTEGRATOR_SYMPLECTIC, SPN_INTEGRATOR_RK4};
    for (int i = 0; i < 2; i++) {
        spn_world *w64 = orb(integs[i], 12, 512, 1, 256, SPN_PRECISION_FLOAT64);
        spn_world *w32 = orb(integs[i], 12, 512, 1, 256, SPN_PRECISION_FLOAT32);
        for (int k = 0; k < 100; k++) {
            assert_int_equal(spn_world_advance(w64, 1e-7, 8), SPN_OK);
            assert_int_equal(spn_world_advance(w32, 1e-7, 8), SPN_OK);
        }
        assert_false(same_bits(w64, w32)); /* the float32 path did run */
        const double d64 = spn_world_energy(w64).dissipated, d32 = spn_world_energy(w32).dissipated;
        print_message("%s: dissipated %.6e J, float32 off by %.2e of it\n", spn_integrator_name(integs[i]), d64,
                      fabs(d32 / d64 - 1));
        assert_true(d64 > 1e-9); /* 2.0e-9 J */
        assert_true(fabs(d32 - d64) < 5e-5 * d64);
        spn_world_destroy(w64);
        spn_world_destroy(w32);
    }
}

/* One ring of 8 fixed particles at 0.15 m, the hub free on its 8 radials
 * (2% pre-strain, no damping, no gravity), pushed by delta along x. Small
 * in-plane motion of the hub sees the stiffness K = sum over its springs of
 * k cos^2(theta) + (T / L) sin^2(theta); x(t) = delta cos(sqrt(K / m) t). */
static void run_star(spn_integrator integ, spn_precision precision, double *x_out, int samples, int per_sample, double *omega, double *dt)
{
    spn_world_def def = spn_world_def_default();
    def.gravity = spn_v3(0, 0, 0);
    def.integrator = integ;
    spn_orb_scene_def od = spn_orb_scene_def_default();
    od.rings = 1;
    od.radials = 8;
    od.damping_ratio = 0;
    spn_world *w;
    assert_int_equal(spn_scene_orb(&def, &od, &w), SPN_OK);
    spn_world_set_precision(w, precision);
    double K = 0;
    for (uint32_t s = 0; s < spn_world_spring_count(w); s++) {
        const spn_spring_info sp = spn_world_spring(w, s);
        if (sp.a != 0 && sp.b != 0) continue;
        const spn_vec3 d = spn_v3_sub(spn_world_position(w, sp.a), spn_world_position(w, sp.b));
        const double c2 = d.x * d.x / spn_v3_dot(d, d);
        K += sp.k * c2 + sp.tension / sp.length * (1 - c2);
    }
    *omega = sqrt(K / spn_world_mass(w, 0));
    *dt = 2 * SPN_PI / *omega / 2000;
    const double delta = 1e-3 * 0.15;
    spn_world_set_position(w, 0, spn_v3(delta, 0, 0));
    assert_int_equal(spn_world_compile(w), SPN_OK);
    assert_string_equal(spn_world_step_path(w), "lattice");
    for (int k = 0; k < samples; k++) {
        assert_int_equal(spn_world_advance(w, *dt, per_sample), SPN_OK);
        x_out[k] = spn_world_position(w, 0).x;
    }
    spn_world_destroy(w);
}

static void test_mass_on_springs(void **state)
{
    (void)state;
    enum { SAMPLES = 200, PER = 50 }; /* 5 periods of 2,000 steps */
    double x32[SAMPLES], x64[SAMPLES], omega, dt;
    run_star(SPN_INTEGRATOR_SYMPLECTIC, SPN_PRECISION_FLOAT64, x64, SAMPLES, PER, &omega, &dt);
    run_star(SPN_INTEGRATOR_SYMPLECTIC, SPN_PRECISION_FLOAT32, x32, SAMPLES, PER, &omega, &dt);
    const double delta = 1e-3 * 0.15;
    double worst64 = 0, worst32 = 0, apart = 0;
    for (int k = 0; k < SAMPLES; k++) {
        const double exact = delta * cos(omega * dt * PER * (k + 1));
        worst64 = fmax(worst64, fabs(x64[k] - exact));
        worst32 = fmax(worst32, fabs(x32[k] - exact));
        apart = fmax(apart, fabs(x32[k] - x64[k]));
    }
    /* symplectic Euler's own error: an amplitude ripple of omega dt / 2 =
     * 1.6e-3 of delta, and a phase drift of (omega dt)^2 / 24 per radian */
    assert_true(worst64 < 3e-3 * delta);
    assert_true(worst32 < 3e-3 * delta);
    /* float32 itself: each rebase rounds the reference differences (2^-24 of
     * L = 0.15 m), a force bias of ~k 2^-24 L per spring that moves the
     * hub's equilibrium by ~2^-24 L k / K = 3e-9 m, 2e-5 of delta: measured
     * 2.6e-5 */
    assert_true(apart < 1e-4 * delta);
    /* RK4's own error is ~(omega dt)^4: what is left is float32's */
    run_star(SPN_INTEGRATOR_RK4, SPN_PRECISION_FLOAT32, x32, SAMPLES, PER, &omega, &dt);
    worst32 = 0;
    for (int k = 0; k < SAMPLES; k++) worst32 = fmax(worst32, fabs(x32[k] - delta * cos(omega * dt * PER * (k + 1))));
    assert_true(worst32 < 1e-4 * delta); /* measured 7e-6 */
}

/* Bands on two threads give the bits of one thread, and a second run the
 * bits of the first. Bands are at least SPN_BLOCK (1,024) particles, so the
 * web is 12 rings of 512 (parallel_min 256: six bands of two rows, too thin
 * for blocked passes, which test_physics_lattice checks: the single-step
 * sweep on two threads). */
static void test_threads_and_runs(void **state)
{
    (void)state;
    spn_world *a = orb(SPN_INTEGRATOR_SYMPLECTIC, 12, 512, 1, 256, SPN_PRECISION_FLOAT32);
    spn_world *b = orb(SPN_INTEGRATOR_SYMPLECTIC, 12, 512, 2, 256, SPN_PRECISION_FLOAT32);
    spn_world *c = orb(SPN_INTEGRATOR_SYMPLECTIC, 12, 512, 1, 256, SPN_PRECISION_FLOAT32);
    for (int k = 0; k < 3; k++) {
        assert_int_equal(spn_world_advance(a, 1e-7, 200), SPN_OK);
        assert_int_equal(spn_world_advance(b, 1e-7, 200), SPN_OK);
        assert_int_equal(spn_world_advance(c, 1e-7, 200), SPN_OK);
    }
    assert_int_equal(spn_world_last_step(b).blocked, 0);
    assert_true(same_bits(a, b));
    assert_true(same_bits(a, c));
    spn_world *r1 = orb(SPN_INTEGRATOR_RK4, 12, 512, 1, 256, SPN_PRECISION_FLOAT32);
    spn_world *r2 = orb(SPN_INTEGRATOR_RK4, 12, 512, 2, 256, SPN_PRECISION_FLOAT32);
    assert_int_equal(spn_world_advance(r1, 1e-7, 150), SPN_OK);
    assert_int_equal(spn_world_advance(r2, 1e-7, 150), SPN_OK);
    assert_int_equal(spn_world_last_step(r2).blocked, 0);
    assert_true(same_bits(r1, r2));
    spn_world_destroy(r1);
    spn_world_destroy(r2);
    /* forward Euler takes the float32 path too */
    spn_world *e64 = orb(SPN_INTEGRATOR_EULER, 20, 16, 1, 0, SPN_PRECISION_FLOAT64);
    spn_world *e32 = orb(SPN_INTEGRATOR_EULER, 20, 16, 1, 0, SPN_PRECISION_FLOAT32);
    assert_int_equal(spn_world_advance(e64, 1e-7, 100), SPN_OK);
    assert_int_equal(spn_world_advance(e32, 1e-7, 100), SPN_OK);
    assert_false(same_bits(e64, e32));
    assert_true(max_gap(e64, e32) < 1e-9);
    spn_world_destroy(a);
    spn_world_destroy(b);
    spn_world_destroy(c);
    spn_world_destroy(e64);
    spn_world_destroy(e32);
}

/* Per-step calls take float64 steps (a lone float32 step would cost more
 * than a float64 one), one advance call float32 ones: close, not
 * bit-identical. A blow-up inside an advance call leaves the steps before
 * it, as a shorter call would. */
static void test_calls_and_blow_up(void **state)
{
    (void)state;
    spn_world *a = orb(SPN_INTEGRATOR_SYMPLECTIC, 20, 16, 1, 0, SPN_PRECISION_FLOAT32);
    spn_world *b = orb(SPN_INTEGRATOR_SYMPLECTIC, 20, 16, 1, 0, SPN_PRECISION_FLOAT32);
    assert_int_equal(spn_world_advance(a, 1e-7, 300), SPN_OK);
    for (int k = 0; k < 300; k++) assert_int_equal(spn_world_step(b, 1e-7), SPN_OK);
    assert_false(same_bits(a, b));
    assert_true(max_gap(a, b) < 1e-9); /* measured 4.7e-11 m */
    assert_int_equal(spn_world_step_count(a), 300);

    /* a step far beyond the web's stability limit (~3e-5 s) */
    spn_world *c = spn_world_clone(a), *d = spn_world_clone(a);
    const spn_status st = spn_world_advance(c, 1e-4, 50);
    assert_int_equal(st, SPN_ERR_UNSTABLE);
    const uint64_t good = spn_world_step_count(c) - 300;
    assert_true(good >= 1 && good < 50); /* 14 */
    assert_int_equal(spn_world_advance(d, 1e-4, (int)good), SPN_OK);
    assert_true(same_bits(c, d));
    for (uint32_t i = 0; i < spn_world_particle_count(c); i++) {
        assert_true(spn_v3_finite(spn_world_position(c, i)));
        assert_true(spn_v3_finite(spn_world_velocity(c, i)));
    }
    spn_world_destroy(a);
    spn_world_destroy(b);
    spn_world_destroy(c);
    spn_world_destroy(d);
}

/* What float32 does not touch: the default, the general path. */
static void test_untouched(void **state)
{
    (void)state;
    spn_world_def def = spn_world_def_default();
    spn_world *w = spn_world_create(&def);
    assert_int_equal(spn_world_precision(w), SPN_PRECISION_FLOAT64);
    spn_world_destroy(w);
    const spn_integrator integ[2] = {SPN_INTEGRATOR_RK4, SPN_INTEGRATOR_SYMPLECTIC};
    for (int k = 0; k < 2; k++) {
        spn_world *a = orb(integ[k], 10, 16, 1, 0, SPN_PRECISION_FLOAT64);
        spn_world *b = orb(integ[k], 10, 16, 1, 0, SPN_PRECISION_FLOAT32);
        spn_world_set_lattice(a, false);
        spn_world_set_lattice(b, false);
        assert_int_equal(spn_world_advance(a, 1e-7, 100), SPN_OK);
        assert_int_equal(spn_world_advance(b, 1e-7, 100), SPN_OK);
        assert_true(same_bits(a, b));
        spn_world *c = spn_world_clone(b);
        assert_int_equal(spn_world_precision(c), SPN_PRECISION_FLOAT32);
        spn_world_destroy(a);
        spn_world_destroy(b);
        spn_world_destroy(c);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_orb_against_float64), cmocka_unit_test(test_books_in_bands),
        cmocka_unit_test(test_mass_on_springs),     cmocka_unit_test(test_threads_and_runs),
        cmocka_unit_test(test_calls_and_blow_up),   cmocka_unit_test(test_untouched),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
