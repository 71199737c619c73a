/* spn_world_reorder_particles and spn_world_locality_order: particles
 * numbered anew in place. What is checked, against answers known apart from
 * the functions:
 *  - every setting made outside spn_world_def survives; each particle keeps
 *    its state and fields bit for bit under its new id; springs keep their
 *    ids, order and fields, their ends renumbered; contacts too;
 *  - the renumbered world steps as the original (implicit steps with every
 *    setting and a contact: the same trajectory to rounding, only the order
 *    of a particle's force sum changes), and numbered back it steps bit for
 *    bit as the original;
 *  - bad orders fail with a message naming the entry and change nothing;
 *  - the locality order is a permutation that puts particles near in space
 *    near in number, and refuses a position that is not finite;
 *  - a woven web (species builder) comes numbered by place: few springs
 *    join the two halves of its numbering (a quarter did before). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <spinneret/spinneret.h>

#include "physics/world_internal.h" /* spn__world_plant */

#include "world_settings_util.h"

static double no_collision(void *user, uint32_t i, spn_vec3 from, spn_vec3 to, spn_vec3 *normal, double *keep)
{
    (void)user, (void)i, (void)from, (void)to, (void)normal, (void)keep;
    return 1;
}

/* The reverse numbering with the first two swapped: no particle keeps its id
 * (an odd count would leave the middle one in place). */
static uint32_t *scrambled(uint32_t n)
{
    uint32_t *order = malloc(n * sizeof *order);
    assert_non_null(order);
    for (uint32_t k = 0; k < n; k++) order[k] = n - 1 - k;
    const uint32_t t = order[0];
    order[0] = order[1], order[1] = t;
    return order;
}

/* A small orb web mid-run with every setting away from its default and a
 * contact of particle 50 on the first capture spring. */
static spn_world *busy_web(void)
{
    spn_world *w = util_small_orb(SPN_INTEGRATOR_IMPLICIT);
    util_set_everything(w, no_collision, "{\"note\": \"kept\"}");
    uint32_t s = 0;
    while (spn_world_spring(w, s).tag != SPN_THREAD_CAPTURE) s++;
    spn_spring_info in = spn_world_spring(w, s);
    spn_contact c = {50, in.a, in.b, 0.5, spn_v3(0, 0, 1), 1e-3, 1e-4, false, false};
    assert_int_equal(spn_world_set_contacts(w, &c, 1), SPN_OK);
    for (int k = 0; k < 3; k++) assert_int_equal(spn_world_step(w, 1e-3), SPN_OK);
    uint32_t n;
    spn_world_contacts(w, &n);
    assert_int_equal(n, 1);
    return w;
}

static void test_reorder_keeps_settings_and_state(void **state)
{
    (void)state;
    spn_world *w = busy_web(), *before = busy_web(); /* (a clone would have no contacts) */
    const uint32_t np = spn_world_particle_count(w), ns = spn_world_spring_count(w);
    uint32_t *order = scrambled(np), *new_id = malloc(np * sizeof *new_id);
    assert_non_null(new_id);
    for (uint32_t k = 0; k < np; k++) new_id[order[k]] = k;
    assert_int_equal(spn_world_reorder_particles(w, order), SPN_OK);
    util_same_settings(before, w);
    assert_int_equal(spn_world_particle_count(w), np);
    for (uint32_t k = 0; k < np; k++) {
        spn_particle_def p = spn_world_particle_def(before, order[k]), q = spn_world_particle_def(w, k);
        assert_memory_equal(&p.position, &q.position, sizeof p.position);
        assert_memory_equal(&p.velocity, &q.velocity, sizeof p.velocity);
        assert_true(p.mass == q.mass && p.fixed == q.fixed && p.tag == q.tag);
    }
    assert_int_equal(spn_world_spring_count(w), ns);
    for (uint32_t s = 0; s < ns; s++) {
        spn_spring_info in = spn_world_spring(before, s), out = spn_world_spring(w, s);
        assert_true(out.a == new_id[in.a] && out.b == new_id[in.b]);
        assert_true(in.k == out.k && in.kd == out.kd && in.rest == out.rest && in.tag == out.tag &&
                    in.stage == out.stage && in.order == out.order && in.length == out.length);
    }
    uint32_t n0, n1;
    const spn_contact c0 = spn_world_contacts(before, &n0)[0], c1 = spn_world_contacts(w, &n1)[0];
    assert_int_equal(n0, n1);
    assert_true(c1.p == new_id[c0.p] && c1.a == new_id[c0.a] && c1.b == new_id[c0.b]);
    spn_world_destroy(before);
    spn_world_destroy(w);
    free(order), free(new_id);
}

/* Steps of the original, of the renumbered world and of the world numbered
 * back: the second within rounding of the first, the third bit for bit. */
static void test_renumbered_world_steps_the_same(void **state)
{
    (void)state;
    spn_world *a = busy_web(), *b = busy_web(), *c = busy_web();
    /* CG to the round-off of the forces (not busy_web's 1e-9), so that the
     * numberings differ by rounding only, not by where CG stopped: at 1e-9
     * the kinetic energies differed by up to 3.5e-9 of themselves */
    spn_world *all[3] = {a, b, c};
    for (int k = 0; k < 3; k++) assert_int_equal(spn_world_set_solver_tolerance(all[k], 1e-13, 400), SPN_OK);
    const uint32_t np = spn_world_particle_count(a);
    uint32_t *order = scrambled(np), *back = malloc(np * sizeof *back);
    assert_non_null(back);
    for (uint32_t k = 0; k < np; k++) back[order[k]] = k;
    assert_int_equal(spn_world_reorder_particles(b, order), SPN_OK);
    assert_int_equal(spn_world_reorder_particles(c, order), SPN_OK);
    assert_int_equal(spn_world_reorder_particles(c, back), SPN_OK);
    /* the original numbered as it is: it compiles again too. (With this
     * web's settings, air, hysteresis and a contact among them, a world
     * compiled again mid-run steps a few bits apart from one that was not,
     * as after spn_world_remove_particles; plain worlds do not.) */
    for (uint32_t k = 0; k < np; k++) back[k] = k;
    assert_int_equal(spn_world_reorder_particles(a, back), SPN_OK);
    for (int k = 0; k < 20; k++) {
        assert_int_equal(spn_world_step(a, 1e-3), SPN_OK);
        assert_int_equal(spn_world_step(b, 1e-3), SPN_OK);
        assert_int_equal(spn_world_step(c, 1e-3), SPN_OK);
    }
    double gap = 0, moved = 0;
    for (uint32_t k = 0; k < np; k++) {
        gap = fmax(gap, spn_v3_len(spn_v3_sub(spn_world_position(a, order[k]), spn_world_position(b, k))));
        moved = fmax(moved, spn_v3_len(spn_world_velocity(a, order[k])) * 20 * 1e-3);
        spn_vec3 pa = spn_world_position(a, k), pc = spn_world_position(c, k);
        spn_vec3 va = spn_world_velocity(a, k), vc = spn_world_velocity(c, k);
        assert_memory_equal(&pa, &pc, sizeof pa);
        assert_memory_equal(&va, &vc, sizeof va);
    }
    print_message("largest gap %.3g m (a particle moves up to %.3g m in the run)\n", gap, moved);
    assert_true(moved > 0);
    /* implicit steps: a different sum order changes CG's iterates by
     * rounding only (measured: 8e-16 m, and 4e-12 of the kinetic energy) */
    assert_true(gap <= 1e-11 * moved);
    spn_energy ea = spn_world_energy(a), eb = spn_world_energy(b);
    assert_true(fabs(ea.kinetic - eb.kinetic) <= 1e-10 * fabs(ea.kinetic) + 1e-18);
    spn_world_destroy(a), spn_world_destroy(b), spn_world_destroy(c);
    free(order), free(back);
}

static void test_bad_orders_change_nothing(void **state)
{
    (void)state;
    spn_world *w = busy_web(), *before = busy_web();
    const uint32_t np = spn_world_particle_count(w);
    uint32_t *order = scrambled(np);
    assert_int_equal(spn_world_reorder_particles(w, NULL), SPN_ERR_INVALID);
    assert_non_null(strstr(spn_last_error(), "order is NULL"));
    order[7] = np; /* out of range */
    assert_int_equal(spn_world_reorder_particles(w, order), SPN_ERR_INVALID);
    assert_non_null(strstr(spn_last_error(), "order[7]"));
    order[7] = order[3]; /* a repeat */
    assert_int_equal(spn_world_reorder_particles(w, order), SPN_ERR_INVALID);
    assert_non_null(strstr(spn_last_error(), "order[7]"));
    assert_non_null(strstr(spn_last_error(), "repeats order[3]"));
    for (uint32_t k = 0; k < np; k++) {
        spn_vec3 p = spn_world_position(before, k), q = spn_world_position(w, k);
        assert_memory_equal(&p, &q, sizeof p);
    }
    for (uint32_t s = 0; s < spn_world_spring_count(w); s++) {
        spn_spring_info in = spn_world_spring(before, s), out = spn_world_spring(w, s);
        assert_true(in.a == out.a && in.b == out.b);
    }
    spn_world_destroy(before);
    spn_world_destroy(w);
    free(order);
}

/* The mean distance between particles next to each other in a numbering. */
static double mean_step(const spn_world *w, const uint32_t *order)
{
    const uint32_t np = spn_world_particle_count(w);
    double sum = 0;
    for (uint32_t k = 1; k < np; k++)
        sum += spn_v3_len(spn_v3_sub(spn_world_position(w, order[k]), spn_world_position(w, order[k - 1])));
    return sum / (np - 1);
}

static void test_locality_order(void **state)
{
    (void)state;
    spn_world_def def = spn_world_def_default();
    spn_orb_scene_def od = spn_orb_scene_def_default();
    od.rings = 40, od.radials = 125;
    spn_world *w = NULL;
    assert_int_equal(spn_scene_orb(&def, &od, &w), SPN_OK);
    const uint32_t np = spn_world_particle_count(w);
    uint32_t *order = malloc(np * sizeof *order), *shuffled = malloc(np * sizeof *shuffled);
    bool *seen = calloc(np, sizeof *seen);
    assert_true(order && shuffled && seen);
    assert_int_equal(spn_world_locality_order(w, order), SPN_OK);
    for (uint32_t k = 0; k < np; k++) {
        assert_true(order[k] < np && !seen[order[k]]);
        seen[order[k]] = true;
    }
    /* a fixed scramble of the ids (multiplying by a number prime to np) */
    for (uint32_t k = 0; k < np; k++) shuffled[k] = (uint32_t)(((uint64_t)k * 7919u) % np);
    const double near = mean_step(w, order), far = mean_step(w, shuffled);
    print_message("mean step along the locality order %.3g m, along a scramble %.3g m\n", near, far);
    assert_true(near * 10 < far);
    spn__world_plant(w, 9, spn_v3(NAN, 0, 0), spn_v3(0, 0, 0), UINT32_MAX, 0);
    assert_int_equal(spn_world_locality_order(w, order), SPN_ERR_INVALID);
    assert_non_null(strstr(spn_last_error(), "particle 9"));
    assert_int_equal(spn_world_locality_order(w, NULL), SPN_ERR_INVALID);
    spn_world_destroy(w);
    free(order), free(shuffled), free(seen);
}

/* A woven web comes numbered by place: on two threads each takes half the
 * numbering, and few springs join the halves (the weaver's own order: 32%
 * on this web, measured before the builders renumbered). */
static void test_woven_web_numbered_by_place(void **state)
{
    (void)state;
    spn_species_def d = spn_species_def_preset(SPN_SPECIES_ARANEUS);
    d.seed = 3;
    spn_world *w = NULL;
    assert_int_equal(spn_web_build_species(&d, &w), SPN_OK);
    const uint32_t np = spn_world_particle_count(w), ns = spn_world_spring_count(w), half = np / 2;
    uint32_t cross = 0;
    for (uint32_t s = 0; s < ns; s++) {
        spn_spring_info si = spn_world_spring(w, s);
        cross += (si.a < half) != (si.b < half);
    }
    print_message("%u of %u springs join the two halves of the numbering\n", cross, ns);
    assert_true(cross * 20 < ns);
    spn_world_destroy(w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_reorder_keeps_settings_and_state),
        cmocka_unit_test(test_renumbered_world_steps_the_same),
        cmocka_unit_test(test_bad_orders_change_nothing),
        cmocka_unit_test(test_locality_order),
        cmocka_unit_test(test_woven_web_numbered_by_place),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
