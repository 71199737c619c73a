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

/* A particle's definition read back from the world adds the same particle
 * again, with the state it has now (what copying a world relies on). */
static void test_particle_def_round_trip(void **state)
{
    (void)state;
    spn_world *w = spn_world_create(NULL);
    spn_particle_def p = spn_particle_def_default();
    p.position = spn_v3(1, 2, 3);
    p.mass = 2e-3;
    p.tag = 7;
    assert_int_equal(spn_world_add_particle(w, &p, NULL), SPN_OK);
    p.fixed = true;
    p.tag = 8;
    assert_int_equal(spn_world_add_particle(w, &p, NULL), SPN_OK);
    spn_world_set_velocity(w, 0, spn_v3(0, 0, 4));
    spn_particle_def a = spn_world_particle_def(w, 0), b = spn_world_particle_def(w, 1);
    assert_true(a.position.x == 1 && a.position.y == 2 && a.position.z == 3);
    assert_true(a.velocity.z == 4 && a.mass == 2e-3 && !a.fixed && a.tag == 7);
    assert_true(b.fixed && b.tag == 8);
    spn_world *c = spn_world_create(NULL);
    assert_int_equal(spn_world_add_particle(c, &b, NULL), SPN_OK);
    assert_true(spn_world_is_fixed(c, 0) && spn_world_particle_tag(c, 0) == 8);
    spn_world_destroy(c);
    spn_world_destroy(w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bad_additions_refused),
        cmocka_unit_test(test_particle_def_round_trip),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
