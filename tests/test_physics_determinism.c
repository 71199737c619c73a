/* Issue 2, test 8: same inputs, same bits. Every integrator, with air drag
 * and a force callback, on an orb web big enough for the loops to run on
 * several threads: two runs, and 1 vs 2 threads, give bit-identical
 * positions and velocities. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "physics_util.h"

static void poke(void *user, const spn_world *w, double t, const spn_vec3 *x, const spn_vec3 *v, spn_vec3 *f)
{
    (void)user, (void)x, (void)v;
    f[0] = spn_v3_add(f[0], spn_v3(0, 0, 1e-6 * cos(40 * t)));
    (void)w;
}

/* Final state of 12 steps of the 50 x 50 standard web (2,501 particles). */
static spn_vec3 *run(spn_integrator integ, int threads)
{
    spn_world *w = util_breezy_orb(integ, threads);
    assert_non_null(w);
    spn_world_set_force_callback(w, poke, NULL);
    double dt = integ == SPN_INTEGRATOR_IMPLICIT ? 2e-5 : integ == SPN_INTEGRATOR_ADAPTIVE ? 5e-6 : 2e-6;
    for (int i = 0; i < 12; i++) assert_int_equal(spn_world_step(w, dt), SPN_OK);
    return util_take_state(w);
}

static void test_bit_identical(void **state)
{
    (void)state;
    const uint32_t n = spn_orb_scene_particles(50, 50);
    for (int integ = 0; integ < SPN_INTEGRATOR_COUNT; integ++) {
        spn_vec3 *a = run((spn_integrator)integ, 1), *b = run((spn_integrator)integ, 1);
        spn_vec3 *c = run((spn_integrator)integ, 2);
        assert_memory_equal(a, b, 2 * n * sizeof *a);
        assert_memory_equal(a, c, 2 * n * sizeof *a);
        double speed = 0;
        for (uint32_t i = 0; i < n; i++) speed = fmax(speed, spn_v3_len(a[n + i]));
        print_message("%-10s 1 vs 2 threads identical; fastest particle %.3e m/s\n",
                      spn_integrator_name((spn_integrator)integ), speed);
        assert_true(speed > 0);
        free(a), free(b), free(c);
    }
}

/* A clone of a world mid-run (compiled, with solver scratch) continues
 * exactly as the original. */
static void test_clone_continues(void **state)
{
    (void)state;
    for (int integ = 0; integ < SPN_INTEGRATOR_COUNT; integ++) {
        spn_world_def def = spn_world_def_default();
        def.integrator = (spn_integrator)integ;
        spn_world *w;
        assert_int_equal(spn_scene_chain(&def, spn_v3(0, 0, 0), spn_v3(1, 0, 0), 20, 1.1, 0.1, 1e3, 0.1, &w), SPN_OK);
        assert_int_equal(spn_world_add_plane(w, spn_v3(0, 1, 0), -0.1, 0.5, 0.1), SPN_OK);
        for (int i = 0; i < 50; i++) assert_int_equal(spn_world_step(w, 1e-3), SPN_OK);
        spn_world *c = spn_world_clone(w);
        assert_non_null(c);
        for (int i = 0; i < 50; i++) {
            assert_int_equal(spn_world_step(w, 1e-3), SPN_OK);
            assert_int_equal(spn_world_step(c, 1e-3), SPN_OK);
        }
        uint32_t n = spn_world_particle_count(w);
        assert_memory_equal(spn_world_positions(w), spn_world_positions(c), n * sizeof(spn_vec3));
        assert_memory_equal(spn_world_velocities(w), spn_world_velocities(c), n * sizeof(spn_vec3));
        spn_world_destroy(w);
        spn_world_destroy(c);
    }
}

int main(int argc, char **argv)
{
    (void)argc;
    /* Idle OpenMP threads spin by default; on a machine busier than its
     * cores that costs seconds. The runtime reads the policy when it loads,
     * so set it and start again. */
    if (!getenv("OMP_WAIT_POLICY")) {
        setenv("OMP_WAIT_POLICY", "passive", 1);
        execv("/proc/self/exe", argv);
    }
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bit_identical),
        cmocka_unit_test(test_clone_continues),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
