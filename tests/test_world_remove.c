/* spn_world_remove_particles: particles leave a world in place. What is
 * checked, against answers known apart from the function:
 *  - every setting made outside spn_world_def survives (read back through the
 *    getters: callbacks and user pointers, air, tag diameters and hysteresis,
 *    colliders, lattice switch, precision, preconditioner, metadata, time,
 *    energy ledger, contacts renumbered);
 *  - survivors keep their state bit for bit at the id "old id minus removed
 *    ids below it", which the maps report; a spring goes exactly when one of
 *    its ends goes, the rest keep every field;
 *  - the energy of what remains, and its next steps, are those of a world
 *    built directly from the survivors; the energy removed is the removed
 *    particles' kinetic energy and the removed springs' elastic energy;
 *  - bad ids fail with a message naming the entry and change nothing. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <spinneret/spinneret.h>

#include "world_settings_util.h"

static double no_collision(void *user, uint32_t i, spn_vec3 from, spn_vec3 to, spn_vec3 *normal, double *keep)
{
    (void)user, (void)i, (void)from, (void)to, (void)normal, (void)keep;
    return 1;
}

/* Particles removed by the tests (unsorted on purpose); none is particle 50
 * or an end of the first capture spring, which carry the contact (50 sits
 * above removed ids, so its renumbering shows). */
static const uint32_t gone[] = {40, 7, 66, 25};
enum { NGONE = sizeof gone / sizeof gone[0] };

static bool is_gone(uint32_t i)
{
    for (int k = 0; k < NGONE; k++)
        if (gone[k] == i) return true;
    return false;
}

/* A survivor's new id: its old id minus the removed ids below it. */
static uint32_t new_id(uint32_t i)
{
    uint32_t below = 0;
    for (int k = 0; k < NGONE; k++) below += gone[k] < i;
    return i - below;
}

static spn_contact hub_contact(const spn_world *w)
{
    uint32_t s = 0;
    while (spn_world_spring(w, s).tag != SPN_THREAD_CAPTURE) s++;
    spn_spring_info in = spn_world_spring(w, s);
    assert_false(is_gone(in.a) || is_gone(in.b));
    spn_contact c = {50, in.a, in.b, 0.5, spn_v3(0, 0, 1), 1e-3, 1e-4, false, false};
    return c;
}

/* Everything settable outside the world's definition, none at its default,
 * and a contact of the hub on a capture segment. */
static void set_everything(spn_world *w)
{
    util_set_everything(w, no_collision, "{\"note\": \"kept\"}");
    spn_contact c = hub_contact(w);
    assert_int_equal(spn_world_set_contacts(w, &c, 1), SPN_OK);
}

/* The same settings (world_settings_util.h), step count and energy ledger. */
static void same_settings(const spn_world *a, const spn_world *b)
{
    util_same_settings(a, b);
    assert_int_equal(spn_world_step_count(a), spn_world_step_count(b));
    spn_energy ea = spn_world_energy(a), eb = spn_world_energy(b);
    assert_true(ea.external_work == eb.external_work && ea.dissipated == eb.dissipated);
}

/* Survivor i of `before` is particle pmap[i] of `after`, bit for bit. */
static void survivors_kept(const spn_world *before, const spn_world *after, const uint32_t *pmap)
{
    uint32_t np = spn_world_particle_count(before), kept = 0;
    for (uint32_t i = 0; i < np; i++) {
        if (is_gone(i)) {
            assert_int_equal(pmap[i], SPN_REMOVED);
            continue;
        }
        uint32_t j = new_id(i);
        assert_int_equal(pmap[i], j);
        spn_particle_def p = spn_world_particle_def(before, i), q = spn_world_particle_def(after, j);
        assert_memory_equal(&p.position, &q.position, sizeof p.position);
        assert_memory_equal(&p.velocity, &q.velocity, sizeof p.velocity);
        assert_true(p.mass == q.mass && p.fixed == q.fixed && p.tag == q.tag);
        kept++;
    }
    assert_int_equal(spn_world_particle_count(after), kept);
}

/* A spring goes when an end goes; the rest keep order and fields. */
static void springs_kept(const spn_world *before, const spn_world *after, const uint32_t *smap)
{
    uint32_t ns = spn_world_spring_count(before), kept = 0;
    for (uint32_t s = 0; s < ns; s++) {
        spn_spring_info in = spn_world_spring(before, s);
        if (is_gone(in.a) || is_gone(in.b)) {
            assert_int_equal(smap[s], SPN_REMOVED);
            continue;
        }
        assert_int_equal(smap[s], kept);
        spn_spring_info out = spn_world_spring(after, kept++);
        assert_true(out.a == new_id(in.a) && out.b == new_id(in.b));
        assert_true(in.k == out.k && in.kd == out.kd && in.rest == out.rest && in.break_min == out.break_min &&
                    in.break_max == out.break_max && in.tension_only == out.tension_only &&
                    in.broken == out.broken && in.tag == out.tag && in.stage == out.stage && in.order == out.order);
        assert_true(in.length == out.length);
    }
    assert_int_equal(spn_world_spring_count(after), kept);
    assert_true(kept < ns); /* the removed particles did have springs */
}

/* Mid-run (implicit steps with every setting in play), then more steps. */
static void test_removal_keeps_settings_and_state(void **state)
{
    (void)state;
    spn_world *w = util_small_orb(SPN_INTEGRATOR_IMPLICIT);
    set_everything(w);
    for (int k = 0; k < 3; k++) assert_int_equal(spn_world_step(w, 1e-3), SPN_OK);
    spn_world *before = spn_world_clone(w);
    uint32_t n0;
    const spn_contact c0 = spn_world_contacts(w, &n0)[0];
    uint32_t *pmap = malloc(spn_world_particle_count(w) * sizeof *pmap);
    uint32_t *smap = malloc(spn_world_spring_count(w) * sizeof *smap);
    assert_int_equal(spn_world_remove_particles(w, gone, NGONE, pmap, smap), SPN_OK);
    same_settings(before, w);
    survivors_kept(before, w, pmap);
    springs_kept(before, w, smap);
    uint32_t n1;
    const spn_contact *c1 = spn_world_contacts(w, &n1);
    assert_int_equal(n1, 1);
    assert_true(c1->p == pmap[c0.p] && c1->a == pmap[c0.a] && c1->b == pmap[c0.b]);
    assert_true(c1->u == c0.u && c1->k == c0.k && c1->depth == c0.depth && c1->pull == c0.pull);
    /* It compiles again and goes on stepping with its callbacks. */
    double work = spn_world_energy(w).external_work;
    for (int k = 0; k < 3; k++) assert_int_equal(spn_world_step(w, 1e-3), SPN_OK);
    assert_true(spn_world_energy(w).external_work != work);
    free(pmap), free(smap);
    spn_world_destroy(before);
    spn_world_destroy(w);
}

/* The reference: a new world given only the survivors and their springs. */
static spn_world *built_from_survivors(const spn_world *w)
{
    spn_world *c = spn_world_create(spn_world_get_def(w));
    for (uint32_t i = 0; i < spn_world_particle_count(w); i++) {
        if (is_gone(i)) continue;
        spn_particle_def p = spn_world_particle_def(w, i);
        assert_int_equal(spn_world_add_particle(c, &p, NULL), SPN_OK);
    }
    for (uint32_t s = 0; s < spn_world_spring_count(w); s++) {
        spn_spring_info si = spn_world_spring(w, s);
        if (is_gone(si.a) || is_gone(si.b)) continue;
        spn_spring_def d = {new_id(si.a), new_id(si.b), si.k, si.kd, si.rest, si.break_min, si.break_max,
                            si.tension_only, si.tag, si.stage, si.order};
        assert_int_equal(spn_world_add_spring(c, &d, NULL), SPN_OK);
    }
    return c;
}

/* What the removed particles and springs held: kinetic and elastic energy. */
static void removed_energy(const spn_world *w, double *kinetic, double *elastic)
{
    *kinetic = *elastic = 0;
    for (uint32_t i = 0; i < spn_world_particle_count(w); i++) {
        spn_vec3 v = spn_world_velocity(w, i);
        if (is_gone(i)) *kinetic += 0.5 * spn_world_mass(w, i) * spn_v3_dot(v, v);
    }
    for (uint32_t s = 0; s < spn_world_spring_count(w); s++) {
        spn_spring_info si = spn_world_spring(w, s);
        if ((is_gone(si.a) || is_gone(si.b)) && si.k > 0) *elastic += si.tension * si.tension / (2 * si.k);
    }
}

static void test_energy_is_that_of_the_survivors(void **state)
{
    (void)state;
    spn_world *w = util_small_orb(SPN_INTEGRATOR_SYMPLECTIC);
    for (uint32_t i = 0; i < spn_world_particle_count(w); i++)
        if (!spn_world_is_fixed(w, i)) spn_world_set_velocity(w, i, spn_v3(1e-3 * sin(i), 0, 2e-3 * cos(3.0 * i)));
    spn_world *ref = built_from_survivors(w);
    spn_energy e0 = spn_world_energy(w);
    double gone_kinetic, gone_elastic;
    removed_energy(w, &gone_kinetic, &gone_elastic);
    assert_true(gone_kinetic > 0 && gone_elastic > 0);
    assert_int_equal(spn_world_remove_particles(w, gone, NGONE, NULL, NULL), SPN_OK);
    spn_energy e1 = spn_world_energy(w), er = spn_world_energy(ref);
    assert_true(e1.kinetic == er.kinetic && e1.elastic == er.elastic && e1.gravitational == er.gravitational);
    assert_true(fabs(e0.kinetic - gone_kinetic - e1.kinetic) <= 1e-12 * e0.kinetic);
    assert_true(fabs(e0.elastic - gone_elastic - e1.elastic) <= 1e-12 * e0.elastic);
    /* ...and the same motion from here on. */
    assert_int_equal(spn_world_advance(w, 1e-5, 20), SPN_OK);
    assert_int_equal(spn_world_advance(ref, 1e-5, 20), SPN_OK);
    const size_t n = spn_world_particle_count(w) * sizeof(spn_vec3);
    assert_int_equal(spn_world_particle_count(w), spn_world_particle_count(ref));
    assert_memory_equal(spn_world_positions(w), spn_world_positions(ref), n);
    assert_memory_equal(spn_world_velocities(w), spn_world_velocities(ref), n);
    spn_world_destroy(ref);
    spn_world_destroy(w);
}

/* The world after a refused call is the world before it. */
static void unchanged(const spn_world *w, const spn_world *before, const uint32_t *pmap)
{
    uint32_t np = spn_world_particle_count(before), ns = spn_world_spring_count(before);
    assert_int_equal(spn_world_particle_count(w), np);
    assert_int_equal(spn_world_spring_count(w), ns);
    assert_memory_equal(spn_world_positions(w), spn_world_positions(before), np * sizeof(spn_vec3));
    for (uint32_t s = 0; s < ns; s++)
        assert_true(spn_world_spring(w, s).a == spn_world_spring(before, s).a &&
                    spn_world_spring(w, s).b == spn_world_spring(before, s).b);
    uint32_t nc;
    assert_int_equal(spn_world_contacts(w, &nc)[0].p, 5);
    assert_int_equal(nc, 1);
    for (uint32_t i = 0; i < np; i++) assert_int_equal(pmap[i], 0xabababab);
}

static void test_bad_ids_change_nothing(void **state)
{
    (void)state;
    spn_world *w = util_small_orb(SPN_INTEGRATOR_SYMPLECTIC), *before = spn_world_clone(w);
    spn_contact c = hub_contact(w);
    c.p = 5;
    assert_int_equal(spn_world_set_contacts(w, &c, 1), SPN_OK);
    uint32_t np = spn_world_particle_count(w);
    uint32_t *pmap = malloc(np * sizeof *pmap);
    memset(pmap, 0xab, np * sizeof *pmap);
    const struct {
        uint32_t ids[3], count;
        const char *says;
    } bad[] = {
        {{3, 999, 4}, 3, "ids[1] = 999 does not exist (the world has 73 particles)"},
        {{3, 8, 3}, 3, "ids[2] = 3 repeats ids[0]"},
        {{3, 5, 9}, 3, "ids[1] = 5 is used by contact 0"},
    };
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        assert_int_equal(spn_world_remove_particles(w, bad[k].ids, bad[k].count, pmap, NULL), SPN_ERR_INVALID);
        assert_non_null(strstr(spn_last_error(), bad[k].says));
        unchanged(w, before, pmap);
    }
    assert_int_equal(spn_world_remove_particles(w, NULL, 2, pmap, NULL), SPN_ERR_INVALID);
    assert_non_null(strstr(spn_last_error(), "ids is NULL"));
    unchanged(w, before, pmap);
    free(pmap);
    spn_world_destroy(before);
    spn_world_destroy(w);
}

/* None: the maps are the identity and nothing changes. All: an empty world,
 * which can be built on again. A compiled lattice web: compiled again. */
static void test_none_all_and_compiled(void **state)
{
    (void)state;
    spn_world *w = util_small_orb(SPN_INTEGRATOR_SYMPLECTIC);
    assert_int_equal(spn_world_compile(w), SPN_OK);
    assert_string_equal(spn_world_step_path(w), "lattice");
    uint32_t np = spn_world_particle_count(w), ns = spn_world_spring_count(w);
    uint32_t *pmap = malloc(np * sizeof *pmap), *smap = malloc(ns * sizeof *smap);
    assert_int_equal(spn_world_remove_particles(w, NULL, 0, pmap, smap), SPN_OK);
    for (uint32_t i = 0; i < np; i++) assert_int_equal(pmap[i], i);
    for (uint32_t s = 0; s < ns; s++) assert_int_equal(smap[s], s);
    assert_int_equal(spn_world_spring_count(w), ns);
    /* One rim particle out: the stencil no longer fits, the general path steps. */
    const uint32_t rim = np - 1;
    assert_int_equal(spn_world_remove_particles(w, &rim, 1, NULL, NULL), SPN_OK);
    assert_int_equal(spn_world_compile(w), SPN_OK);
    assert_string_equal(spn_world_step_path(w), "general");
    assert_int_equal(spn_world_advance(w, 1e-6, 4), SPN_OK);
    uint32_t *all = malloc(np * sizeof *all);
    for (uint32_t i = 0; i < np - 1; i++) all[i] = np - 2 - i;
    assert_int_equal(spn_world_remove_particles(w, all, np - 1, NULL, NULL), SPN_OK);
    assert_int_equal(spn_world_particle_count(w), 0);
    assert_int_equal(spn_world_spring_count(w), 0);
    spn_particle_def p = spn_particle_def_default();
    assert_int_equal(spn_world_add_particle(w, &p, NULL), SPN_OK);
    assert_int_equal(spn_world_step(w, 1e-3), SPN_OK);
    assert_true(spn_world_velocity(w, 0).y < 0); /* it falls */
    free(pmap), free(smap), free(all);
    spn_world_destroy(w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_removal_keeps_settings_and_state),
        cmocka_unit_test(test_energy_is_that_of_the_survivors),
        cmocka_unit_test(test_bad_ids_change_nothing),
        cmocka_unit_test(test_none_all_and_compiled),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
