/* The cyclic preconditioner of the equilibrium solver (equilibrium_cyclic.c).
 * On a web that is the same under a turn by 2 pi / N its Newton system is
 * exactly the rotational average the preconditioner solves, so M^-1 (K x)
 * must give x back to rounding: that checks the frames, the transforms, the
 * modes' block Thomas sweeps and the hub's Schur complement together, for
 * even and odd radial counts, a fixed hub and a fixed ring in the middle.
 * Then whole solves: the same rest as the multigrid on a web that gravity in
 * its plane makes asymmetric, the same bits on two threads, what AUTO
 * chooses, and the message for a web that is no lattice. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <spinneret/spinneret.h>

#include "physics/equilibrium_internal.h"

static spn_world *orb(int rings, int radials, int threads)
{
    spn_world_def wd = spn_world_def_default();
    wd.threads = threads;
    spn_orb_scene_def d = spn_orb_scene_def_default();
    d.rings = rings;
    d.radials = radials;
    spn_world *w = NULL;
    assert_int_equal(spn_scene_orb(&wd, &d, &w), SPN_OK);
    return w;
}

/* |M^-1 K x - x| / |x| for a fixed pseudo-random x, at the web as built
 * (flat and symmetric), without gravity; *asym the system's spread. */
static double round_trip(spn_world *w, double *asym)
{
    spn_equilibrium_def d = spn_equilibrium_def_default();
    d.gravity = false;
    spn__eq e;
    assert_int_equal(spn__eq_init(&e, w, &d), SPN_OK);
    uint32_t worst;
    assert_true(isfinite(spn__eq_assemble(&e, 0, &worst)));
    const char *why = NULL;
    spn__precond pc = {.kind = SPN_PRECOND_CYCLIC};
    pc.cyc = spn__cyc_build(&e, &why);
    assert_non_null(pc.cyc);
    assert_int_equal(spn__precond_setup(&pc, &e), SPN_OK);
    *asym = spn__cyc_asymmetry(pc.cyc);
    const size_t n3 = 3 * (size_t)e.n;
    double *x = malloc(n3 * sizeof *x), *y = malloc(n3 * sizeof *y), *z = malloc(n3 * sizeof *z);
    assert_true(x && y && z);
    uint64_t s = 0x243F6A8885A308D3ull;
    for (size_t i = 0; i < n3; i++) {
        s ^= s << 13, s ^= s >> 7, s ^= s << 17;
        x[i] = (double)(s >> 11) / 9007199254740992.0 - 0.5;
    }
    spn__eq_matvec(&e, x, y);
    spn__precond_apply(&pc, &e, y, z);
    double err = 0, size = 0;
    for (size_t i = 0; i < n3; i++)
        err += (z[i] - x[i]) * (z[i] - x[i]), size += x[i] * x[i];
    free(x), free(y), free(z);
    spn__precond_free(&pc);
    spn__eq_free(&e);
    return sqrt(err / size);
}

static void test_exact_on_a_symmetric_web(void **state)
{
    (void)state;
    /* radials: even, odd (an odd count of real sequences too), a prime
     * factor the transform takes by a direct DFT, the fewest there can be */
    const int cases[][2] = {{12, 20}, {11, 15}, {6, 14}, {5, 3}, {9, 4}, {30, 125}};
    for (size_t c = 0; c < sizeof cases / sizeof *cases; c++) {
        spn_world *w = orb(cases[c][0], cases[c][1], 1);
        double asym, err = round_trip(w, &asym);
        print_message("rings %d radials %d: |M^-1 K x - x| / |x| = %.2e, asymmetry %.2e\n", cases[c][0], cases[c][1],
                      err, asym);
        assert_true(err < 1e-9);
        assert_true(asym < 1e-6);
        spn_world_destroy(w);
    }
}

static void test_exact_with_a_fixed_hub_or_ring(void **state)
{
    (void)state;
    spn_world *w = orb(10, 16, 1);
    spn_world_set_fixed(w, 0, true); /* the hub held: no mode carries it */
    double asym, err = round_trip(w, &asym);
    print_message("fixed hub: %.2e\n", err);
    assert_true(err < 1e-9);
    spn_world_destroy(w);
    w = orb(10, 16, 1);
    for (uint32_t i = 0; i < 16; i++)
        spn_world_set_fixed(w, 1 + 4 * 16 + i, true); /* ring 4 held: two chains */
    err = round_trip(w, &asym);
    print_message("fixed ring 4: %.2e\n", err);
    assert_true(err < 1e-9);
    spn_world_destroy(w);
    w = orb(10, 16, 1);
    for (uint32_t i = 0; i < 16; i++)
        spn_world_set_fixed(w, 1 + i, true); /* ring 0 held: the hub alone */
    err = round_trip(w, &asym);
    print_message("fixed ring 0: %.2e\n", err);
    assert_true(err < 1e-9);
    spn_world_destroy(w);
}

static spn_equilibrium_def loaded(const spn_world *w, spn_precond pc, double *t0)
{
    spn_orb_scene_def od = spn_orb_scene_def_default();
    uint32_t nf = 0;
    for (uint32_t i = 0; i < spn_world_particle_count(w); i++)
        nf += !spn_world_is_fixed(w, i);
    spn_equilibrium_def d = spn_equilibrium_def_default();
    *t0 = od.ea * od.prestrain;
    d.load = spn_v3(0, 0, *t0 / nf); /* the benchmark's load: T0 in all, out of plane */
    d.force_scale = *t0;
    d.tolerance = 1e-9;
    d.preconditioner = pc;
    return d;
}

/* Gravity in the plane pulls the upper threads tighter than the lower: the
 * system is no longer its average, and CG corrects the difference. */
static void test_settles_where_the_multigrid_does(void **state)
{
    (void)state;
    double t0;
    spn_world *a = orb(30, 64, 1), *b = orb(30, 64, 1);
    spn_equilibrium_def d = loaded(a, SPN_PRECOND_CYCLIC, &t0);
    spn_equilibrium_report ra, rb;
    assert_int_equal(spn_world_equilibrium(a, &d, &ra), SPN_OK);
    d.preconditioner = SPN_PRECOND_MULTIGRID;
    assert_int_equal(spn_world_equilibrium(b, &d, &rb), SPN_OK);
    print_message("cyclic %d Newton %d CG, multigrid %d Newton %d CG\n", ra.iterations, ra.cg_iterations, rb.iterations,
                  rb.cg_iterations);
    assert_int_equal(ra.reason, SPN_EQUILIBRIUM_CONVERGED);
    assert_int_equal(ra.preconditioner, SPN_PRECOND_CYCLIC);
    assert_true(ra.residual <= 1e-9 * t0);
    const double sag = fabs(spn_world_position(b, 0).z);
    assert_true(sag > 1e-5);
    double apart = 0;
    for (uint32_t i = 0; i < spn_world_particle_count(a); i++)
        apart = fmax(apart, spn_v3_len(spn_v3_sub(spn_world_position(a, i), spn_world_position(b, i))));
    print_message("apart %.3g m of a sag of %.3g m\n", apart, sag);
    assert_true(apart < 1e-5 * sag);
    spn_world_destroy(a), spn_world_destroy(b);
}

/* 33,025 free particles: the transforms, modes and rotations on two threads */
static void test_same_bits_with_two_threads(void **state)
{
    (void)state;
    double t0;
    spn_world *a = orb(130, 256, 1), *b = orb(130, 256, 2);
    spn_equilibrium_def d = loaded(a, SPN_PRECOND_CYCLIC, &t0);
    d.tolerance = 1e-6;
    spn_equilibrium_report ra, rb;
    d.threads = 1;
    assert_int_equal(spn_world_equilibrium(a, &d, &ra), SPN_OK);
    d.threads = 2;
    assert_int_equal(spn_world_equilibrium(b, &d, &rb), SPN_OK);
    assert_int_equal(ra.reason, SPN_EQUILIBRIUM_CONVERGED);
    assert_int_equal(ra.cg_iterations, rb.cg_iterations);
    const uint32_t np = spn_world_particle_count(a);
    assert_memory_equal(spn_world_positions(a), spn_world_positions(b), np * sizeof(spn_vec3));
    spn_world_destroy(a), spn_world_destroy(b);
}

static void test_auto_takes_it_on_lattices_only(void **state)
{
    (void)state;
    double t0;
    spn_world *w = orb(20, 40, 1);
    spn_equilibrium_def d = loaded(w, SPN_PRECOND_AUTO, &t0);
    spn_equilibrium_report r;
    assert_int_equal(spn_world_equilibrium(w, &d, &r), SPN_OK);
    assert_int_equal(r.preconditioner, SPN_PRECOND_CYCLIC);
    spn_world_destroy(w);
    /* 17 and 997 radials: primes the transform takes by a direct DFT, which
     * still pays (auto takes it) */
    const int primes[2] = {17, 997};
    for (int k = 0; k < 2; k++) {
        w = orb(k ? 3 : 20, primes[k], 1);
        d = loaded(w, SPN_PRECOND_AUTO, &t0);
        assert_int_equal(spn_world_equilibrium(w, &d, &r), SPN_OK);
        assert_int_equal(r.preconditioner, SPN_PRECOND_CYCLIC);
        assert_int_equal(r.reason, SPN_EQUILIBRIUM_CONVERGED);
        spn_world_destroy(w);
    }
    /* 1,009 radials, prime (a chirp transform): auto takes it too, and it
     * settles where the multigrid does */
    w = orb(3, 1009, 1);
    spn_world *m = orb(3, 1009, 1);
    d = loaded(w, SPN_PRECOND_AUTO, &t0);
    assert_int_equal(spn_world_equilibrium(w, &d, &r), SPN_OK);
    assert_int_equal(r.preconditioner, SPN_PRECOND_CYCLIC);
    assert_int_equal(r.reason, SPN_EQUILIBRIUM_CONVERGED);
    d.preconditioner = SPN_PRECOND_MULTIGRID;
    assert_int_equal(spn_world_equilibrium(m, &d, &r), SPN_OK);
    assert_int_equal(r.reason, SPN_EQUILIBRIUM_CONVERGED);
    double apart = 0, sag = 0;
    for (uint32_t i = 0; i < spn_world_particle_count(w); i++) {
        const spn_vec3 p = spn_world_position(w, i), q = spn_world_position(m, i);
        apart = fmax(apart, fabs(p.x - q.x) + fabs(p.y - q.y) + fabs(p.z - q.z));
        sag = fmax(sag, fabs(q.z));
    }
    assert_true(sag > 0);
    assert_true(apart < 1e-6 * sag);
    spn_world_destroy(m);
    spn_world_destroy(w);
    /* a cloth is no lattice: auto takes another, an explicit request is refused by name */
    spn_world_def wd = spn_world_def_default();
    assert_int_equal(spn_scene_cloth(&wd, 12, 12, 1.0, 0.0, 0.1, 500, 0.01, 15u, &w), SPN_OK);
    d = spn_equilibrium_def_default();
    assert_int_equal(spn_world_equilibrium(w, &d, &r), SPN_OK);
    assert_int_not_equal(r.preconditioner, SPN_PRECOND_CYCLIC);
    const spn_vec3 before = spn_world_position(w, 5);
    d.preconditioner = SPN_PRECOND_CYCLIC;
    assert_int_equal(spn_world_equilibrium(w, &d, &r), SPN_ERR_INVALID);
    assert_non_null(strstr(spn_last_error(), "cyclic preconditioner needs a hub + rings x radials web"));
    const spn_vec3 after = spn_world_position(w, 5);
    assert_memory_equal(&before, &after, sizeof before); /* nothing moved */
    spn_world_destroy(w);
    spn_precond p;
    assert_int_equal(spn_precond_parse("cyclic", &p), SPN_OK);
    assert_int_equal(p, SPN_PRECOND_CYCLIC);
    assert_string_equal(spn_precond_name(SPN_PRECOND_CYCLIC), "cyclic");
}

/* Far from its average: a prey of 16 T0 half way out pulls the web into a
 * cone around it (measured: 33 Newton steps and 257 CG, the multigrid 40
 * and 191).
 * CG corrects the difference; the rest is the multigrid's. */
static void test_a_heavy_prey_off_the_hub(void **state)
{
    (void)state;
    double t0;
    spn_world *a = orb(20, 40, 1), *b = orb(20, 40, 1);
    spn_vec3 *loads = calloc(spn_world_particle_count(a), sizeof *loads);
    assert_non_null(loads);
    spn_equilibrium_def d = loaded(a, SPN_PRECOND_AUTO, &t0);
    loads[1 + 10 * 40 + 7] = spn_v3(0, 0, 16 * t0);
    d.loads = loads;
    d.tolerance = 1e-8;
    spn_equilibrium_report ra, rb;
    assert_int_equal(spn_world_equilibrium(a, &d, &ra), SPN_OK);
    d.preconditioner = SPN_PRECOND_MULTIGRID;
    assert_int_equal(spn_world_equilibrium(b, &d, &rb), SPN_OK);
    print_message("prey of 16 T0: auto (%s) %d Newton %d CG; multigrid %d Newton %d CG\n",
                  spn_precond_name(ra.preconditioner), ra.iterations, ra.cg_iterations, rb.iterations,
                  rb.cg_iterations);
    assert_int_equal(ra.reason, SPN_EQUILIBRIUM_CONVERGED);
    assert_int_equal(rb.reason, SPN_EQUILIBRIUM_CONVERGED);
    assert_int_equal(ra.preconditioner, SPN_PRECOND_CYCLIC);
    assert_true(ra.max_displacement > 1e-3);
    double apart = 0;
    for (uint32_t i = 0; i < spn_world_particle_count(a); i++)
        apart = fmax(apart, spn_v3_len(spn_v3_sub(spn_world_position(a, i), spn_world_position(b, i))));
    print_message("apart %.3g m of a move of %.3g m\n", apart, ra.max_displacement);
    assert_true(apart < 1e-5 * ra.max_displacement);
    free(loads);
    spn_world_destroy(a), spn_world_destroy(b);
}

/* Thrown off their rings by up to 2 mm, many threads start slack: the
 * Levenberg shift's path, where the average has no rotation to follow. */
static void test_a_slack_jittered_lattice(void **state)
{
    (void)state;
    double t0;
    spn_world *a = orb(20, 40, 1);
    uint64_t s = 0x9E3779B97F4A7C15ull;
    for (uint32_t i = 1; i < spn_world_particle_count(a); i++) {
        if (spn_world_is_fixed(a, i)) continue;
        s ^= s << 13, s ^= s >> 7, s ^= s << 17;
        const double u = (double)(s >> 11) / 9007199254740992.0 - 0.5, v = (double)((s >> 3) & 0xffff) / 65536.0 - 0.5;
        spn_world_set_position(a, i, spn_v3_add(spn_world_position(a, i), spn_v3(0.004 * u, 0.004 * v, 0)));
    }
    spn_equilibrium_def d = loaded(a, SPN_PRECOND_CYCLIC, &t0);
    spn_equilibrium_report r;
    assert_int_equal(spn_world_equilibrium(a, &d, &r), SPN_OK);
    print_message("jittered web: %d Newton %d CG\n", r.iterations, r.cg_iterations);
    assert_int_equal(r.reason, SPN_EQUILIBRIUM_CONVERGED);
    spn_world_destroy(a);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_exact_on_a_symmetric_web),
        cmocka_unit_test(test_exact_with_a_fixed_hub_or_ring),
        cmocka_unit_test(test_settles_where_the_multigrid_does),
        cmocka_unit_test(test_same_bits_with_two_threads),
        cmocka_unit_test(test_auto_takes_it_on_lattices_only),
        cmocka_unit_test(test_a_heavy_prey_off_the_hub),
        cmocka_unit_test(test_a_slack_jittered_lattice),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
