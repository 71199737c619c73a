/* The spring world's construction: bad particles and springs are refused with
 * a message naming what is wrong (the analytic checks are in test_physics_*). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>
#include <spinneret/spinneret.h>

static void test_bad_additions_refused(void **state)
{
    (void)state;
    spn_world *w = spn_world_create(NULL);
    spn_particle_def p = spn_particle_def_default();
    p.mass = -1;
    assert_int_equal(spn_world_add_particle(w, &p, NULL), SPN_ERR_INVALID);
    p.mass = 1;
    p.position.x = NAN;
    assert_int_equal(spn_world_add_particle(w, &p, NULL), SPN_ERR_INVALID);
    spn_spring_def s = spn_spring_def_default();
    s.a = 0;
    s.b = 1;
    assert_int_equal(spn_world_add_spring(w, &s, NULL), SPN_ERR_INVALID);
    assert_non_null(strstr(spn_last_error(), "does not exist"));
    spn_world_destroy(w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bad_additions_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
