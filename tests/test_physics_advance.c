/* spn_world_advance and spn_world_set_solver_tolerance (issue 10).
 *
 * advance(dt, n) must give the same bits as n calls of spn_world_step, with
 * every integrator, with and without callbacks (the replayable path keeps one
 * copy of the state per call, the other path one per step). A blow-up inside
 * an advance must leave the world exactly where spn_world_step leaves it: the
 * good steps taken, the state from before the failing step, the same message.
 * The solver tolerance setter rejects bad values by name and a looser
 * tolerance takes fewer CG iterations. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdlib.h>
#include <string.h>

#include "physics_util.h"

static spn_world *web(spn_integrator integ, int threads)
{
    spn_world *w = util_orb(integ, threads, 20, 30);
    assert_non_null(w);
    /* start from a disturbed state so every step moves something */
    for (uint32_t i = 0; i < spn_world_particle_count(w); i += 7)
        if (!spn_world_is_fixed(w, i)) spn_world_set_velocity(w, i, spn_v3(0, 0, 1e-3 * (double)(i % 5)));
    return w;
}

static void poke(void *user, const spn_world *w, double t, const spn_vec3 *x, const spn_vec3 *v, spn_vec3 *f)
{
    (void)user, (void)x, (void)v, (void)w;
    f[3] = spn_v3_add(f[3], spn_v3(0, 0, 1e-6 * cos(40 * t)));
}

static void assert_same_state(const spn_world *a, const spn_world *b)
{
    uint32_t n = spn_world_particle_count(a);
    assert_int_equal(n, spn_world_particle_count(b));
    assert_memory_equal(spn_world_positions(a), spn_world_positions(b), n * sizeof(spn_vec3));
    assert_memory_equal(spn_world_velocities(a), spn_world_velocities(b), n * sizeof(spn_vec3));
    assert_true(spn_world_time(a) == spn_world_time(b));
    assert_int_equal(spn_world_step_count(a), spn_world_step_count(b));
    spn_energy ea = spn_world_energy(a), eb = spn_world_energy(b);
    assert_true(ea.dissipated == eb.dissipated && ea.external_work == eb.external_work);
}

static void test_advance_equals_steps(void **state)
{
    (void)state;
    for (int integ = 0; integ < SPN_INTEGRATOR_COUNT; integ++)
        for (int cb = 0; cb < 2; cb++) {
            const double dt = integ == SPN_INTEGRATOR_IMPLICIT ? 2e-5 : integ == SPN_INTEGRATOR_ADAPTIVE ? 5e-6 : 2e-6;
            spn_world *a = web((spn_integrator)integ, 1), *b = web((spn_integrator)integ, 2);
            if (cb) {
                spn_world_set_force_callback(a, poke, NULL);
                spn_world_set_force_callback(b, poke, NULL);
            }
            for (int i = 0; i < 9; i++) assert_int_equal(spn_world_step(a, dt), SPN_OK);
            assert_int_equal(spn_world_advance(b, dt, 9), SPN_OK);
            assert_same_state(a, b);
            assert_true(spn_world_last_step(b).substeps >= 9);
            spn_world_destroy(a);
            spn_world_destroy(b);
        }
}

/* A chain far past its explicit stability limit blows up within a few steps. */
static spn_world *unstable_chain(void)
{
    spn_world_def def = spn_world_def_default();
    def.integrator = SPN_INTEGRATOR_EULER;
    def.threads = 1;
    spn_world *w;
    assert_int_equal(spn_scene_chain(&def, spn_v3(0, 0, 0), spn_v3(1, 0, 0), 10, 1.2, 0.1, 1e4, 0, &w), SPN_OK);
    for (uint32_t i = 1; i < 10; i++) spn_world_set_position(w, i, spn_v3(0.1 * i, -0.2 * sin(SPN_PI * i / 10), 0));
    return w;
}

static void test_advance_blow_up_like_step(void **state)
{
    (void)state;
    const double dt = 1.0 / 60;
    spn_world *a = unstable_chain(), *b = unstable_chain();
    spn_status st = SPN_OK;
    int good = 0;
    for (; good < 60; good++)
        if ((st = spn_world_step(a, dt)) != SPN_OK) break;
    assert_int_equal(st, SPN_ERR_UNSTABLE);
    assert_true(good >= 1); /* the replay path has steps to replay */
    char msg[512];
    snprintf(msg, sizeof msg, "%s", spn_last_error());
    assert_int_equal(spn_world_advance(b, dt, 60), SPN_ERR_UNSTABLE);
    assert_string_equal(spn_last_error(), msg);
    assert_same_state(a, b);
    assert_int_equal((int)spn_world_step_count(b), good);
    print_message("blow-up at step %d: %s\n", good + 1, msg);
    spn_world_destroy(a);
    spn_world_destroy(b);
}

static void test_advance_bad_input(void **state)
{
    (void)state;
    spn_world *w = unstable_chain();
    assert_int_equal(spn_world_advance(w, 1e-3, 0), SPN_ERR_INVALID);
    assert_non_null(strstr(spn_last_error(), "step count"));
    assert_int_equal(spn_world_advance(w, -1, 3), SPN_ERR_INVALID);
    assert_non_null(strstr(spn_last_error(), "time step"));
    assert_int_equal(spn_world_step_count(w), 0);
    spn_world_destroy(w);
}

static void test_solver_tolerance(void **state)
{
    (void)state;
    spn_world *w = web(SPN_INTEGRATOR_IMPLICIT, 1);
    assert_int_equal(spn_world_set_solver_tolerance(w, 0, 10), SPN_ERR_INVALID);
    assert_non_null(strstr(spn_last_error(), "cg_tolerance"));
    assert_int_equal(spn_world_set_solver_tolerance(w, 1e-6, 0), SPN_ERR_INVALID);
    assert_non_null(strstr(spn_last_error(), "cg_max_iterations"));
    assert_true(spn_world_get_def(w)->cg_tolerance == 1e-10); /* unchanged by a refused call */

    /* block Jacobi: on this regular web the cyclic preconditioner (auto's
     * choice) is exact, and CG stops after one iteration at either tolerance */
    assert_int_equal(spn_world_set_implicit_preconditioner(w, SPN_PRECOND_BLOCK_JACOBI), SPN_OK);
    spn_world *loose = spn_world_clone(w);
    assert_int_equal(spn_world_set_implicit_preconditioner(loose, SPN_PRECOND_BLOCK_JACOBI), SPN_OK);
    assert_int_equal(spn_world_set_solver_tolerance(loose, 1e-3, 1000), SPN_OK);
    assert_int_equal(spn_world_step(w, 1e-3), SPN_OK);
    assert_int_equal(spn_world_step(loose, 1e-3), SPN_OK);
    int tight = spn_world_last_step(w).cg_iterations, few = spn_world_last_step(loose).cg_iterations;
    print_message("CG iterations: tolerance 1e-10 %d, 1e-3 %d\n", tight, few);
    assert_true(few < tight);

    assert_int_equal(spn_world_set_solver_tolerance(loose, 1e-10, 3), SPN_OK);
    assert_int_equal(spn_world_step(loose, 1e-3), SPN_OK);
    assert_true(spn_world_last_step(loose).cg_iterations <= 3);
    spn_world_destroy(w);
    spn_world_destroy(loose);
}

static void zero_force(void *user, const spn_world *w, double t, const spn_vec3 *x, const spn_vec3 *v, spn_vec3 *f)
{
    (void)user, (void)w, (void)t, (void)x, (void)v, (void)f;
}

/* The fused sweep (worlds of two blocks or more, nothing external) against the
 * two-pass step (forced by a force callback that adds nothing): the same
 * physics up to the order of the force sums; and bit-identical on 1 and 2
 * threads with the web cut into three blocks. */
static spn_world *sweep_web(int threads, bool two_pass, spn_integrator integ)
{
    spn_world_def def = spn_world_def_default();
    def.integrator = integ;
    def.threads = threads;
    def.parallel_min = 256; /* blocks of 1024 particles: 3 on this web */
    spn_orb_scene_def od = spn_orb_scene_def_default();
    od.rings = 50;
    od.radials = 50;
    spn_world *w;
    assert_int_equal(spn_scene_orb(&def, &od, &w), SPN_OK);
    for (uint32_t i = 0; i < spn_world_particle_count(w); i += 3)
        if (!spn_world_is_fixed(w, i)) spn_world_set_velocity(w, i, spn_v3(0, 0, 1e-3 * (double)(i % 7)));
    if (two_pass) spn_world_set_force_callback(w, zero_force, NULL);
    /* forward Euler gains energy every step: fewer steps, before it runs away */
    assert_int_equal(spn_world_advance(w, 2e-6, integ == SPN_INTEGRATOR_EULER ? 10 : 200), SPN_OK);
    return w;
}

static void test_sweep(void **state)
{
    (void)state;
    for (int integ = SPN_INTEGRATOR_EULER; integ <= SPN_INTEGRATOR_SYMPLECTIC; integ++) {
        spn_world *one = sweep_web(1, false, (spn_integrator)integ), *two = sweep_web(2, false, (spn_integrator)integ);
        spn_world *ref = sweep_web(1, true, (spn_integrator)integ);
        assert_same_state(one, two);
        const uint32_t n = spn_world_particle_count(one);
        const spn_vec3 *a = spn_world_positions(one), *b = spn_world_positions(ref);
        const spn_vec3 *va = spn_world_velocities(one), *vb = spn_world_velocities(ref);
        double dx = 0, dv = 0, vmax = 0;
        for (uint32_t i = 0; i < n; i++) {
            dx = fmax(dx, spn_v3_len(spn_v3_sub(a[i], b[i])));
            dv = fmax(dv, spn_v3_len(spn_v3_sub(va[i], vb[i])));
            vmax = fmax(vmax, spn_v3_len(vb[i]));
        }
        print_message("%s sweep vs two-pass: |dx| %.2e m, |dv| %.2e m/s (v up to %.2e)\n",
                      spn_integrator_name((spn_integrator)integ), dx, dv, vmax);
        assert_true(dx < 1e-13);
        assert_true(dv < 1e-9 * vmax);
        spn_energy e1 = spn_world_energy(one), e2 = spn_world_energy(ref);
        assert_true(fabs(e1.dissipated - e2.dissipated) <= 1e-9 * fabs(e2.dissipated));
        spn_world_destroy(one);
        spn_world_destroy(two);
        spn_world_destroy(ref);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_advance_equals_steps),
        cmocka_unit_test(test_advance_blow_up_like_step),
        cmocka_unit_test(test_advance_bad_input),
        cmocka_unit_test(test_solver_tolerance),
        cmocka_unit_test(test_sweep),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
