/* The spring world's construction and setters: bad particles, springs and
 * settings are refused with a message naming what is wrong (the analytic
 * checks are in test_physics_*). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
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

/* The setters refuse what the constructors refuse (spn_world_add_particle,
 * spn_world_add_spring, a web file's world settings): a negative or
 * non-finite mass, stiffness, damping or drag, a non-finite gravity; each
 * with SPN_ERR_INVALID and a message naming the particle or spring and the
 * field, and nothing changed: the values read back are the old ones, and the
 * world (compiled, so its stepping copy of the springs counts too) steps as a
 * clone made before the refusals does, bit for bit. */
static void expect_refused(spn_status st, const char *who, const char *field)
{
    assert_int_equal(st, SPN_ERR_INVALID);
    if (who) assert_non_null(strstr(spn_last_error(), who));
    assert_non_null(strstr(spn_last_error(), field));
}

/* A world made from settings out of range is made (spn_world_create keeps
 * what it is given) but will not step: the step names the field, and the
 * state is as it was. An integrator set out of range later is caught the
 * same way. */
static void test_bad_world_def_refused(void **state)
{
    (void)state;
    for (int field = 0; field < 13; field++) {
        spn_world_def wd = spn_world_def_default();
        const char *name = NULL;
        switch (field) {
        case 0: wd.gravity.y = NAN, name = "gravity"; break;
        case 1: wd.drag = -0.5, name = "drag"; break;
        case 2: wd.drag = INFINITY, name = "drag"; break;
        case 3: wd.integrator = (spn_integrator)SPN_INTEGRATOR_COUNT, name = "integrator"; break;
        case 4: wd.threads = -2, name = "threads"; break;
        case 5: wd.dt_min = 0, name = "dt_min"; break;
        case 6: wd.dt_factor = 1, name = "dt_factor"; break;
        case 7: wd.energy_jump = NAN, name = "energy_jump"; break;
        case 8: wd.cg_tolerance = 0, name = "cg_tolerance"; break;
        case 9: wd.cg_max_iterations = 0, name = "cg_max_iterations"; break;
        case 10: wd.provot_max_strain = -0.1, name = "provot_max_strain"; break;
        case 11: wd.provot_iterations = -1, name = "provot_iterations"; break;
        default: name = "integrator"; break; /* set after, below */
        }
        spn_world *w = spn_world_create(&wd);
        assert_non_null(w);
        spn_particle_def p = spn_particle_def_default();
        p.fixed = true;
        assert_int_equal(spn_world_add_particle(w, &p, NULL), SPN_OK);
        p.fixed = false, p.position = spn_v3(1, 0, 0), p.velocity = spn_v3(0, 1, 0);
        assert_int_equal(spn_world_add_particle(w, &p, NULL), SPN_OK);
        spn_spring_def s = spn_spring_def_default();
        s.a = 0, s.b = 1;
        assert_int_equal(spn_world_add_spring(w, &s, NULL), SPN_OK);
        if (field == 12) {
            assert_int_equal(spn_world_step(w, 1e-3), SPN_OK);
            spn_world_set_integrator(w, (spn_integrator)-1);
        }
        const spn_vec3 x = spn_world_positions(w)[1];
        expect_refused(spn_world_step(w, 1e-3), "world settings", name);
        expect_refused(spn_world_advance(w, 1e-3, 10), "world settings", name);
        const spn_vec3 y = spn_world_positions(w)[1];
        assert_memory_equal(&x, &y, sizeof x);
        spn_world_destroy(w);
    }
}

/* The setters refuse what the constructors refuse, naming the particle or
 * spring and the field, and leave the world as it was: it then steps as its
 * clone does. */
static void test_bad_settings_refused(void **state)
{
    (void)state;
    spn_world_def wd = spn_world_def_default();
    wd.drag = 0.5;
    spn_world *w = spn_world_create(&wd);
    assert_non_null(w);
    spn_particle_def p = spn_particle_def_default();
    p.mass = 2e-3;
    for (int i = 0; i < 3; i++) {
        p.position = spn_v3(i, 0, 0);
        p.fixed = i == 0;
        assert_int_equal(spn_world_add_particle(w, &p, NULL), SPN_OK);
    }
    spn_spring_def s = spn_spring_def_default();
    s.k = 3.5, s.kd = 0.25;
    for (uint32_t i = 0; i < 2; i++) {
        s.a = i, s.b = i + 1;
        assert_int_equal(spn_world_add_spring(w, &s, NULL), SPN_OK);
    }
    assert_int_equal(spn_world_step(w, 1e-3), SPN_OK);
    spn_world *c = spn_world_clone(w);
    assert_non_null(c);
    const double bad[] = {-1e-9, -INFINITY, INFINITY, NAN};
    for (size_t b = 0; b < sizeof bad / sizeof *bad; b++) {
        for (uint32_t i = 0; i < 2; i++) { /* particle 0 is fixed: still fixed after */
            char who[32];
            snprintf(who, sizeof who, "particle %u:", i);
            expect_refused(spn_world_set_mass(w, i, bad[b]), who, "mass");
        }
        expect_refused(spn_world_set_spring_stiffness(w, 1, bad[b], 0.25), "spring 1:", "stiffness k");
        expect_refused(spn_world_set_spring_stiffness(w, 1, 3.5, bad[b]), "spring 1:", "damping kd");
        expect_refused(spn_world_set_drag(w, bad[b]), NULL, "drag");
        expect_refused(spn_world_set_spring_rest(w, 1, bad[b]), "spring 1:", "rest length");
        if (!isfinite(bad[b])) {
            expect_refused(spn_world_set_gravity(w, spn_v3(0, bad[b], 0)), NULL, "gravity");
            expect_refused(spn_world_set_gravity(w, spn_v3(bad[b], -9.81, 0)), NULL, "gravity");
            expect_refused(spn_world_set_position(w, 1, spn_v3(0, 0, bad[b])), "particle 1:", "position");
            expect_refused(spn_world_set_velocity(w, 2, spn_v3(bad[b], 0, 0)), "particle 2:", "velocity");
        }
    }
    /* a fixed particle does not move: no velocity but 0 */
    expect_refused(spn_world_set_velocity(w, 0, spn_v3(0, 1e-12, 0)), "particle 0 is fixed", "velocity");
    assert_int_equal(spn_world_set_velocity(w, 0, spn_v3(0, 0, 0)), SPN_OK);
    assert_true(spn_world_mass(w, 0) == 2e-3 && spn_world_is_fixed(w, 0));
    assert_true(spn_world_mass(w, 1) == 2e-3 && !spn_world_is_fixed(w, 1));
    const spn_spring_def d = spn_world_spring_def(w, 1);
    assert_true(d.k == 3.5 && d.kd == 0.25 && d.rest == spn_world_spring_def(c, 1).rest);
    const spn_world_def *got = spn_world_get_def(w);
    assert_true(got->drag == 0.5 && got->gravity.x == 0 && got->gravity.y == -9.81 && got->gravity.z == 0);
    for (int i = 0; i < 3; i++) {
        assert_int_equal(spn_world_step(w, 1e-3), SPN_OK);
        assert_int_equal(spn_world_step(c, 1e-3), SPN_OK);
    }
    assert_memory_equal(spn_world_positions(w), spn_world_positions(c), 3 * sizeof(spn_vec3));
    assert_memory_equal(spn_world_velocities(w), spn_world_velocities(c), 3 * sizeof(spn_vec3));
    /* the edges are accepted: zero mass (fixed), stiffness, damping and drag */
    assert_int_equal(spn_world_set_mass(w, 2, 0), SPN_OK);
    assert_true(spn_world_is_fixed(w, 2));
    assert_int_equal(spn_world_set_mass(w, 2, 3e-3), SPN_OK);
    assert_true(spn_world_mass(w, 2) == 3e-3 && !spn_world_is_fixed(w, 2));
    assert_int_equal(spn_world_set_spring_stiffness(w, 1, 0, 0), SPN_OK);
    assert_int_equal(spn_world_set_spring_rest(w, 1, 0), SPN_OK);
    assert_int_equal(spn_world_set_position(w, 0, spn_v3(-1, 0, 0)), SPN_OK); /* an anchor moved by hand */
    assert_true(spn_world_position(w, 0).x == -1 && spn_world_is_fixed(w, 0));
    assert_int_equal(spn_world_set_drag(w, 0), SPN_OK);
    assert_int_equal(spn_world_set_gravity(w, spn_v3(0, 0, -1)), SPN_OK);
    assert_true(spn_world_get_def(w)->drag == 0 && spn_world_get_def(w)->gravity.z == -1);
    spn_world_destroy(c);
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
        cmocka_unit_test(test_bad_world_def_refused),
        cmocka_unit_test(test_bad_settings_refused),
        cmocka_unit_test(test_particle_def_round_trip),
        cmocka_unit_test(test_spring_def_round_trip),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
