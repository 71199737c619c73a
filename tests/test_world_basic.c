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

/* A spring's definition read back adds the same spring again, with every
 * field as it is now; broken is asked apart (a definition has no such
 * field). */
static void test_spring_def_round_trip(void **state)
{
    (void)state;
    spn_world *w = spn_world_create(NULL);
    spn_particle_def p = spn_particle_def_default();
    for (int i = 0; i < 3; i++) {
        p.position = spn_v3(i, 0, 0);
        assert_int_equal(spn_world_add_particle(w, &p, NULL), SPN_OK);
    }
    spn_spring_def s = spn_spring_def_default();
    s.a = 2, s.b = 1, s.k = 3.5, s.kd = 0.25, s.rest = 0.75, s.break_min = 0.125, s.break_max = 4;
    s.tension_only = true, s.tag = 6, s.stage = 2, s.order = 9;
    assert_int_equal(spn_world_add_spring(w, &s, NULL), SPN_OK);
    s.a = 0, s.tension_only = false, s.break_max = INFINITY;
    assert_int_equal(spn_world_add_spring(w, &s, NULL), SPN_OK);
    spn_world_set_spring_rest(w, 0, 0.5);
    spn_world_break_spring(w, 1);
    const spn_spring_def a = spn_world_spring_def(w, 0), b = spn_world_spring_def(w, 1);
    assert_true(a.a == 2 && a.b == 1 && a.k == 3.5 && a.kd == 0.25 && a.rest == 0.5);
    assert_true(a.break_min == 0.125 && a.break_max == 4 && a.tension_only);
    assert_true(a.tag == 6 && a.stage == 2 && a.order == 9);
    assert_true(b.a == 0 && !b.tension_only && isinf(b.break_max));
    assert_false(spn_world_spring_is_broken(w, 0));
    assert_true(spn_world_spring_is_broken(w, 1));
    /* the same fields as spn_world_spring reports */
    const spn_spring_info info = spn_world_spring(w, 0);
    assert_true(info.a == a.a && info.b == a.b && info.k == a.k && info.rest == a.rest && info.order == a.order);
    assert_true(info.length == 1);
    spn_world_destroy(w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bad_additions_refused),
        cmocka_unit_test(test_particle_def_round_trip),
        cmocka_unit_test(test_spring_def_round_trip),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
