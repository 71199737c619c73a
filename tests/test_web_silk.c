/* Silk webs settle (with the implicit solver; skipped in builds without it):
 * a physical web with measured silk and a Zilla web reach rest, and the
 * settled species web keeps its measures. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "web_checks.h"

static void settle_or_skip(spn_world *w, double max_time)
{
    spn_world_set_integrator(w, SPN_INTEGRATOR_IMPLICIT);
    spn_settle_report rep;
    spn_status st = spn_web_settle(w, max_time, &rep);
    if (st == SPN_ERR_UNSUPPORTED) {
        spn_world_destroy(w);
        skip();
    }
    assert_int_equal(st, SPN_OK);
    assert_int_equal(rep.reason, SPN_SETTLE_CONVERGED);
}

static void test_physical_silk(void **state)
{
    (void)state;
    spn_physical_def d = web_physical_30cm(true);
    spn_world *w = NULL;
    assert_int_equal(spn_web_build_physical(&d, &w), SPN_OK);
    settle_or_skip(w, 3);
    assert_int_equal(web_crossings(w, SPN_THREAD_CAPTURE, SPN_THREAD_CAPTURE), 0);
    spn_world_destroy(w);
}

static void test_species_silk(void **state)
{
    (void)state;
    spn_species_def d = spn_species_def_preset(SPN_SPECIES_ZILLA);
    d.size = 0.08;
    spn_world *w = NULL;
    assert_int_equal(spn_web_build_species(&d, &w), SPN_OK);
    spn_web_measures before, after;
    assert_int_equal(spn_web_measure(w, &before), SPN_OK);
    settle_or_skip(w, 3);
    assert_int_equal(spn_web_measure(w, &after), SPN_OK);
    assert_int_equal(after.radii, before.radii);
    assert_true(fabs(after.capture_area - before.capture_area) < 0.15 * before.capture_area);
    assert_int_equal(web_crossings(w, SPN_THREAD_CAPTURE, SPN_THREAD_CAPTURE), 0);
    spn_world_destroy(w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_physical_silk), cmocka_unit_test(test_species_silk)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
