/* The world copy that prey strikes step (spn__world_with_breaks, made by
 * spn_impact_create) carries everything set on the world, not only its
 * spn_world_def: the lattice switch, the float32 precision, the implicit
 * preconditioner, the force, break and collision callbacks with their user
 * pointers, the air with its rho and mu, tag diameters, tag hysteresis,
 * colliders, contacts, metadata, time and the adaptive stepper's next
 * sub-step. Each setting is set to something other than its default; the
 * copy must report the same, and the copy and the original (given the copy's
 * break lengths, the one thing the copy is there to change) must step to the
 * same bits. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include <spinneret/spinneret.h>

#include "anim/anim_internal.h"
#include "world_settings_util.h"

/* A wall at z = 2e-5 that keeps half the normal speed. */
static double wall(void *user, uint32_t i, spn_vec3 from, spn_vec3 to, spn_vec3 *normal, double *keep)
{
    (void)user;
    (void)i;
    const double z = 2e-5;
    if (to.z <= z || from.z > z) return 1;
    *normal = spn_v3(0, 0, -1);
    *keep = 0.5;
    return (z - from.z) / (to.z - from.z);
}

/* Everything settable outside the world's definition, none at its default:
 * a wall to collide with and a pushing contact of the hub on a capture
 * segment, 0.1 mm deep. */
static void set_everything(spn_world *w)
{
    util_set_everything(w, wall, "{\"note\": \"copied\"}");
    uint32_t s = 0;
    while (spn_world_spring(w, s).tag != SPN_THREAD_CAPTURE) s++;
    spn_spring_info in = spn_world_spring(w, s);
    spn_contact c = {0, in.a, in.b, 0.5, spn_v3(0, 0, 1), 1e-3, 1e-4, false, false};
    assert_int_equal(spn_world_set_contacts(w, &c, 1), SPN_OK);
}

/* The same settings (world_settings_util.h) and the same contacts. */
static void same_settings(const spn_world *a, const spn_world *b)
{
    util_same_settings(a, b);
    uint32_t na, nb;
    const spn_contact *ca = spn_world_contacts(a, &na), *cb = spn_world_contacts(b, &nb);
    assert_int_equal(na, nb);
    for (uint32_t k = 0; k < na; k++)
        assert_true(ca[k].p == cb[k].p && ca[k].a == cb[k].a && ca[k].b == cb[k].b && ca[k].u == cb[k].u &&
                    ca[k].k == cb[k].k && ca[k].depth == cb[k].depth && ca[k].pull == cb[k].pull);
}

static void same_state(const spn_world *a, const spn_world *b)
{
    const uint32_t np = spn_world_particle_count(a);
    assert_int_equal(np, spn_world_particle_count(b));
    assert_int_equal(spn_world_spring_count(a), spn_world_spring_count(b));
    assert_memory_equal(spn_world_positions(a), spn_world_positions(b), np * sizeof(spn_vec3));
    assert_memory_equal(spn_world_velocities(a), spn_world_velocities(b), np * sizeof(spn_vec3));
    assert_true(spn_world_time(a) == spn_world_time(b));
    spn_energy ea = spn_world_energy(a), eb = spn_world_energy(b);
    assert_true(ea.external_work == eb.external_work && ea.dissipated == eb.dissipated);
}

/* The copy of `w` the animation makes (breaking strains at `scale`); its
 * springs match w's but for break_max, capped at the kind's breaking strain,
 * which is then written into w so that the two are the same world. */
static spn_world *copy_like_prey(spn_world *w, double scale)
{
    spn_world *c = NULL;
    assert_int_equal(spn__world_with_breaks(w, scale, &c), SPN_OK);
    for (uint32_t s = 0; s < spn_world_spring_count(w); s++) {
        spn_spring_info in = spn_world_spring(w, s), out = spn_world_spring(c, s);
        assert_true(in.a == out.a && in.b == out.b && in.k == out.k && in.kd == out.kd && in.rest == out.rest);
        assert_true(in.tag == out.tag && in.broken == out.broken && in.break_min == out.break_min);
        double strain = spn_thread_breaking_strain(in.tag) * scale;
        double want = isfinite(strain) ? fmin(in.break_max, spn__break_length(in, strain)) : in.break_max;
        assert_true(out.break_max == want);
        assert_int_equal(spn_world_set_spring_breaks(w, s, out.break_min, out.break_max), SPN_OK);
    }
    same_settings(w, c);
    same_state(w, c);
    return c;
}

/* Implicit steps with every setting in play, the copy made before any step. */
static void test_copy_carries_every_setting(void **state)
{
    (void)state;
    spn_world *w = util_small_orb(SPN_INTEGRATOR_IMPLICIT);
    set_everything(w);
    spn_world *c = copy_like_prey(w, 1);
    assert_int_equal(spn_world_implicit_preconditioner(c), SPN_PRECOND_MULTIGRID);
    assert_false(spn_world_lattice_allowed(c));
    assert_int_equal(spn_world_precision(c), SPN_PRECISION_FLOAT32);
    assert_int_equal(spn_world_collider_count(c), 2);
    assert_true(isfinite(spn_world_spring(c, 0).break_max)); /* a radius: now breakable */
    assert_true(fabs(spn_world_tag_hysteresis(c, SPN_THREAD_RADIUS, NULL) - 0.6) < 1e-15);
    for (int k = 0; k < 4; k++) {
        assert_int_equal(spn_world_step(w, 1e-3), SPN_OK);
        assert_int_equal(spn_world_step(c, 1e-3), SPN_OK);
    }
    same_state(w, c);
    assert_true(spn_world_energy(c).external_work != 0); /* the push and the air did act */
    spn_world_destroy(c);
    spn_world_destroy(w);
}

/* A copy made mid-run continues the run: the adaptive stepper's next
 * sub-step, the callbacks, the air and the colliders go on as before. */
static void test_copy_mid_run_steps_on_alike(void **state)
{
    (void)state;
    spn_world *w = util_small_orb(SPN_INTEGRATOR_ADAPTIVE);
    set_everything(w);
    for (int k = 0; k < 3; k++) assert_int_equal(spn_world_step(w, 2e-5), SPN_OK);
    spn_world *c = copy_like_prey(w, 0.5);
    for (int k = 0; k < 5; k++) {
        assert_int_equal(spn_world_step(w, 2e-5), SPN_OK);
        assert_int_equal(spn_world_step(c, 2e-5), SPN_OK);
    }
    same_state(w, c);
    assert_int_equal(spn_world_step_count(w), spn_world_step_count(c));
    spn_world_destroy(c);
    spn_world_destroy(w);
}

/* The lattice stencil and its float32 step: a web of a kind that never
 * breaks keeps both, and the copy takes the same float32 steps. */
static void test_copy_keeps_lattice_and_precision(void **state)
{
    (void)state;
    for (int allow = 0; allow <= 1; allow++) {
        spn_world *w = util_small_orb(SPN_INTEGRATOR_SYMPLECTIC);
        for (uint32_t s = 0; s < spn_world_spring_count(w); s++) spn_world_set_spring_tag(w, s, SPN_THREAD_GENERIC);
        spn_world_set_lattice(w, allow);
        spn_world_set_precision(w, SPN_PRECISION_FLOAT32);
        spn_world *c = copy_like_prey(w, 1);
        assert_int_equal(spn_world_compile(w), SPN_OK);
        assert_int_equal(spn_world_compile(c), SPN_OK);
        assert_string_equal(spn_world_step_path(c), allow ? "lattice" : "general");
        assert_string_equal(spn_world_step_path(c), spn_world_step_path(w));
        spn_world *f64 = spn_world_clone(w);
        spn_world_set_precision(f64, SPN_PRECISION_FLOAT64);
        assert_int_equal(spn_world_advance(w, 1e-6, 16), SPN_OK);
        assert_int_equal(spn_world_advance(c, 1e-6, 16), SPN_OK);
        assert_int_equal(spn_world_advance(f64, 1e-6, 16), SPN_OK);
        same_state(w, c);
        /* float32 did run on the lattice: its bits are not float64's */
        const size_t n = spn_world_particle_count(w) * sizeof(spn_vec3);
        assert_int_equal(memcmp(spn_world_positions(w), spn_world_positions(f64), n) != 0, allow);
        spn_world_destroy(f64);
        spn_world_destroy(c);
        spn_world_destroy(w);
    }
}

/* spn_world_copy_into gives what spn_world_clone gives, into a world that
 * already exists: from an empty one (its arrays grown), again into the same
 * (its arrays kept: the positions stay where they were), then from a smaller
 * web; and the copy steps on as the clone does. */
static void test_copy_into_is_a_clone(void **state)
{
    (void)state;
    spn_world *w = util_small_orb(SPN_INTEGRATOR_IMPLICIT);
    set_everything(w);
    for (int k = 0; k < 3; k++) assert_int_equal(spn_world_step(w, 1e-3), SPN_OK);
    spn_world *dst = spn_world_create(NULL);
    assert_int_equal(spn_world_copy_into(dst, w), SPN_OK);
    const spn_vec3 *kept = spn_world_positions(dst);
    assert_int_equal(spn_world_step(dst, 1e-3), SPN_OK); /* compiled state of its own, dropped by the next copy */
    assert_int_equal(spn_world_copy_into(dst, w), SPN_OK);
    assert_ptr_equal(spn_world_positions(dst), kept);
    spn_world *c = spn_world_clone(w);
    util_same_settings(c, dst);
    same_state(c, dst);
    uint32_t n;
    spn_world_contacts(dst, &n);
    assert_int_equal(n, 0); /* as the clone: contacts are the step's, not copied */
    for (int k = 0; k < 4; k++) {
        assert_int_equal(spn_world_step(c, 1e-3), SPN_OK);
        assert_int_equal(spn_world_step(dst, 1e-3), SPN_OK);
    }
    same_state(c, dst);
    spn_world *small = spn_world_create(NULL);
    spn_particle_def p = spn_particle_def_default();
    assert_int_equal(spn_world_add_particle(small, &p, NULL), SPN_OK);
    assert_int_equal(spn_world_copy_into(dst, small), SPN_OK);
    assert_int_equal(spn_world_particle_count(dst), 1);
    assert_int_equal(spn_world_spring_count(dst), 0);
    assert_int_equal(spn_world_step(dst, 1e-3), SPN_OK);
    assert_true(spn_world_position(dst, 0).y < 0); /* it falls */
    assert_int_equal(spn_world_copy_into(dst, dst), SPN_OK);
    spn_world_destroy(small);
    spn_world_destroy(c);
    spn_world_destroy(dst);
    spn_world_destroy(w);
}

/* Through the animation's own door: prey added to a world keep its settings. */
static void test_prey_world_keeps_settings(void **state)
{
    (void)state;
    spn_world *w = util_small_orb(SPN_INTEGRATOR_IMPLICIT);
    set_everything(w);
    spn_prey_def prey = {.position = spn_v3(0.01, 0.01, 0.02), .velocity = spn_v3(0, 0, -1), .mass = 1e-4,
                         .radius = 2e-3};
    spn_impact_def id = spn_impact_def_default();
    spn_impact *im = NULL;
    assert_int_equal(spn_impact_create(&w, &prey, 1, &id, &im), SPN_OK);
    assert_int_equal(spn_world_implicit_preconditioner(w), SPN_PRECOND_MULTIGRID);
    assert_false(spn_world_lattice_allowed(w));
    assert_int_equal(spn_world_precision(w), SPN_PRECISION_FLOAT32);
    void *user = NULL;
    assert_ptr_equal(spn_world_force_callback(w, &user), util_push);
    assert_ptr_equal(user, &util_force_user);
    double rho = 0;
    assert_ptr_equal(spn_world_air(w, &user, &rho, NULL), util_breeze);
    assert_true(user == &util_air_user && rho == 1.1);
    assert_ptr_equal(spn_world_collide_callback(w, NULL), wall);
    assert_int_equal(spn_world_collider_count(w), 2);
    assert_true(spn_world_tag_diameter(w, SPN_THREAD_CAPTURE) == 1e-5);
    spn_impact_destroy(im);
    spn_world_destroy(w);
}

static void test_break_setter_rejects_nan(void **state)
{
    (void)state;
    spn_world *w = util_small_orb(SPN_INTEGRATOR_SYMPLECTIC);
    assert_int_equal(spn_world_set_spring_breaks(w, 3, NAN, 1), SPN_ERR_INVALID);
    assert_non_null(strstr(spn_last_error(), "spring 3"));
    assert_int_equal(spn_world_set_spring_breaks(w, 3, 0, NAN), SPN_ERR_INVALID);
    assert_true(spn_world_spring(w, 3).break_max == INFINITY);
    /* a break length set on a compiled world is obeyed by the next step */
    assert_int_equal(spn_world_compile(w), SPN_OK);
    spn_spring_info in = spn_world_spring(w, 3);
    assert_int_equal(spn_world_set_spring_breaks(w, 3, 0, in.length * 0.5), SPN_OK);
    assert_int_equal(spn_world_step(w, 1e-6), SPN_OK);
    assert_true(spn_world_spring(w, 3).broken);
    spn_world_destroy(w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_copy_carries_every_setting),
        cmocka_unit_test(test_copy_mid_run_steps_on_alike),
        cmocka_unit_test(test_copy_keeps_lattice_and_precision),
        cmocka_unit_test(test_copy_into_is_a_clone),
        cmocka_unit_test(test_prey_world_keeps_settings),
        cmocka_unit_test(test_break_setter_rejects_nan),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
