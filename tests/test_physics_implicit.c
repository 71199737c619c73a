/* Issue 2, tests 3 and 5: equilibria.
 * 3. A chain of 50 segments hung from two fixed ends settles to the catenary
 *    through its ends: largest deviation under 1% of the span.
 * 5. Implicit Euler holds a taut stiff line (k/m = 1e8 s^-2) at dt = 1/60 s
 *    without blowing up, and settles to the same equilibrium as a tiny-step
 *    explicit run, within 1e-6 relative to the sag.
 * And: implicit steps at dt = 1 s bring a loaded taut web to rest down to
 * 1e-12 of its pretension (CG's round-off floor scales as a 2-norm). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdlib.h>
#include <string.h>

#include "physics_util.h"

/* Catenary parameter a with 2 a sinh(span / 2a) = length (bisection). */
static double catenary_a(double span, double length)
{
    double lo = 1e-3 * span, hi = 1e3 * span;
    for (int i = 0; i < 200; i++) {
        double mid = sqrt(lo * hi);
        if (2 * mid * sinh(span / (2 * mid)) > length) lo = mid;
        else hi = mid;
    }
    return sqrt(lo * hi);
}

static void test_catenary(void **state)
{
    (void)state;
    const double span = 1.0, length = 1.2, mass = 1.0;
    const int n = 50;
    spn_world_def def = spn_world_def_default();
    def.integrator = SPN_INTEGRATOR_IMPLICIT;
    def.drag = 5;
    spn_world *w;
    assert_int_equal(spn_scene_chain(&def, spn_v3(-span / 2, 0, 0), spn_v3(span / 2, 0, 0), n, length, mass, 1e6, 0,
                                     &w),
                     SPN_OK);
    /* Start from a parabola so the springs begin near their rest length. */
    for (int i = 1; i < n; i++) {
        spn_vec3 p = spn_world_position(w, (uint32_t)i);
        double s = (double)i / n;
        spn_world_set_position(w, (uint32_t)i, spn_v3(p.x, -1.2 * 0.3 * span * s * (1 - s) * 4 / 1.2, 0));
    }
    spn_settle_def sd = spn_settle_def_default();
    sd.dt = 0.01;
    sd.max_kinetic = 1e-14;
    sd.max_residual = 1e-8;
    sd.max_time = 200;
    spn_settle_report rep;
    assert_int_equal(spn_world_settle(w, &sd, &rep), SPN_OK);
    print_message("settled: %s after %.2f s (%llu steps), residual %.2e N\n",
                  rep.reason == SPN_SETTLE_CONVERGED ? "converged" : "timeout", rep.time,
                  (unsigned long long)rep.steps, rep.residual);
    assert_int_equal(rep.reason, SPN_SETTLE_CONVERGED);
    const double a = catenary_a(span, length), top = a * cosh(span / (2 * a));
    double worst = 0;
    for (int i = 0; i <= n; i++) {
        spn_vec3 p = spn_world_position(w, (uint32_t)i);
        worst = fmax(worst, fabs(p.y - (a * cosh(p.x / a) - top)));
    }
    print_message("largest deviation from the catenary: %.3e of the span\n", worst / span);
    assert_true(worst < 0.01 * span);
    spn_world_destroy(w);
}

/* A line of 10 segments between fixed ends, 1% pre-strained, k/m = 1e8. */
static spn_world *taut_line(spn_integrator integ, double drag)
{
    spn_world_def def = spn_world_def_default();
    def.integrator = integ;
    def.drag = drag;
    spn_world *w;
    const double m = 1e-3, k = 1e5;
    assert_int_equal(spn_scene_chain(&def, spn_v3(0, 0, 0), spn_v3(1, 0, 0), 10, 1 / 1.01, 10 * m, k, 0, &w), SPN_OK);
    return w;
}

static void test_taut_line(void **state)
{
    (void)state;
    spn_world *imp = taut_line(SPN_INTEGRATOR_IMPLICIT, 50);
    spn_world *exp_ = taut_line(SPN_INTEGRATOR_SYMPLECTIC, 50);
    /* The implicit run at 1/60 s: never blows up, never gains energy. */
    double e_prev = spn_world_total_energy(imp);
    for (int i = 0; i < 300; i++) {
        assert_int_equal(spn_world_step(imp, 1.0 / 60), SPN_OK);
        double e = spn_world_total_energy(imp);
        assert_true(e <= e_prev + 1e-12 * fabs(e_prev) + 1e-15);
        e_prev = e;
    }
    /* The same line, explicit at 2e-5 s (w_max h = 0.4), for 1.5 s. */
    for (int i = 0; i < 75000; i++) assert_int_equal(spn_world_step(exp_, 2e-5), SPN_OK);
    double sag = 0, diff = 0;
    for (uint32_t i = 0; i < spn_world_particle_count(imp); i++) {
        spn_vec3 a = spn_world_position(imp, i), b = spn_world_position(exp_, i);
        sag = fmax(sag, fabs(b.y));
        diff = fmax(diff, spn_v3_len(spn_v3_sub(a, b)));
    }
    print_message("sag %.6e m, implicit vs explicit %.3e relative\n", sag, diff / sag);
    assert_true(sag > 1e-5);
    assert_true(diff <= 1e-6 * sag);
    spn_world_destroy(imp);
    spn_world_destroy(exp_);
}

/* The same stiff line stepped by plain explicit Euler at 1/60 s blows up:
 * the step is refused with the step and particle named, and the state kept. */
static void test_explicit_blowup_reported(void **state)
{
    (void)state;
    spn_world *w = taut_line(SPN_INTEGRATOR_EULER, 0);
    spn_world_set_velocity(w, 5, spn_v3(0, 0.01, 0));
    spn_status st = SPN_OK;
    int i;
    for (i = 0; i < 1000 && st == SPN_OK; i++) st = spn_world_step(w, 1.0 / 60);
    assert_int_equal(st, SPN_ERR_UNSTABLE);
    print_message("after %d steps: %s\n", i, spn_last_error());
    assert_non_null(strstr(spn_last_error(), "step"));
    assert_non_null(strstr(spn_last_error(), "particle"));
    for (uint32_t p = 0; p < spn_world_particle_count(w); p++) {
        assert_true(spn_v3_finite(spn_world_position(w, p)));
        assert_true(spn_v3_finite(spn_world_velocity(w, p)));
    }
    assert_int_equal(spn_world_step_count(w), (uint64_t)(i - 1));
    spn_world_destroy(w);
}

static void rest_load(void *user, const spn_world *w, double t, const spn_vec3 *x, const spn_vec3 *v, spn_vec3 *f)
{
    (void)user, (void)t, (void)x, (void)v;
    for (uint32_t i = 0; i < spn_world_particle_count(w); i++)
        if (!spn_world_is_fixed(w, i)) f[i].z += 1e-5;
}

/* Implicit Euler at dt = 1 s as a damped Newton iteration: a 1,001-particle
 * orb web under 10 uN a node out of plane comes to rest, the largest net
 * force under 1e-12 of the pretension, in a few steps. That residual is
 * about a thousand times the round-off of a particle's forces. Before CG's
 * round-off floor was a 2-norm (it was 1e-13 of the sum of |f| over all
 * springs, n times a particle's scale where the residual's norm grows as
 * sqrt(n)), this web stalled near 1.1e-11 after 300 steps, and the 100k web
 * took 237 steps to reach 1e-9. */
static void test_rest_to_round_off(void **state)
{
    (void)state;
    spn_world_def def = spn_world_def_default();
    def.integrator = SPN_INTEGRATOR_IMPLICIT;
    def.gravity = spn_v3(0, 0, 0);
    spn_orb_scene_def od = spn_orb_scene_def_default();
    od.rings = 20, od.radials = 50;
    spn_world *w = NULL;
    assert_int_equal(spn_scene_orb(&def, &od, &w), SPN_OK);
    spn_world_set_force_callback(w, rest_load, NULL);
    const double goal = 1e-12 * od.ea * od.prestrain;
    int steps = 0;
    double residual = spn_world_max_residual(w, NULL);
    while (residual > goal && steps < 30) {
        assert_int_equal(spn_world_step(w, 1.0), SPN_OK);
        steps++;
        residual = spn_world_max_residual(w, NULL);
    }
    print_message("%d steps, residual %.3g of the pretension\n", steps, residual / (od.ea * od.prestrain));
    assert_true(residual <= goal);
    assert_true(steps <= 10);
    spn_world_destroy(w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_catenary),
        cmocka_unit_test(test_taut_line),
        cmocka_unit_test(test_explicit_blowup_reported),
        cmocka_unit_test(test_rest_to_round_off),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
