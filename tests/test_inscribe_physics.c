/* An inscribed web is still a web: settled again (largest residual under the
 * tolerance), every particle connected to an anchor, no dangling thread; and
 * capture threads subdivided into several springs are taken out whole, their
 * inner particles with them. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <spinneret/spinneret.h>

#include "inscribe_util.h"

/* Every particle reaches a fixed one; every free particle has >= 2 threads. */
static void check_hangs_whole(const spn_world *w)
{
    uint32_t np = spn_world_particle_count(w), ns = spn_world_spring_count(w);
    uint32_t *label = malloc(np * sizeof *label), *deg = calloc(np, sizeof *deg);
    for (uint32_t i = 0; i < np; i++) label[i] = spn_world_is_fixed(w, i);
    for (uint32_t s = 0; s < ns; s++) {
        spn_spring_info si = spn_world_spring(w, s);
        deg[si.a]++, deg[si.b]++;
    }
    for (bool changed = true; changed;) { /* relax reachability to a fixed point */
        changed = false;
        for (uint32_t s = 0; s < ns; s++) {
            spn_spring_info si = spn_world_spring(w, s);
            if (label[si.a] != label[si.b]) label[si.a] = label[si.b] = 1, changed = true;
        }
    }
    for (uint32_t i = 0; i < np; i++) {
        assert_int_equal(label[i], 1);
        if (!spn_world_is_fixed(w, i)) assert_true(deg[i] >= 2);
    }
    free(label), free(deg);
}

/* "PIG" on a quarter of the web's area: fewer fill threads, a quicker test. */
static spn_target *pig(const spn_world *w)
{
    spn_target *t = NULL;
    assert_int_equal(spn_target_create(w, 600, &t), SPN_OK);
    spn_text_def td = spn_text_def_default();
    td.text = "PIG";
    td.fit = 0.5;
    assert_int_equal(spn_target_text(t, w, &td), SPN_OK);
    return t;
}

static void test_inscribed_web_is_settled_and_whole(void **state)
{
    (void)state;
    /* Fill adds the most (new masses, split threads); outline doubles threads. */
    const spn_emphasis modes[] = {SPN_EMPHASIS_FILL, SPN_EMPHASIS_OUTLINE};
    for (int m = 0; m < 2; m++) {
        spn_world *w = inscribe_orb();
        spn_target *t = pig(w);
        spn_inscribe_def d = spn_inscribe_def_default();
        d.emphasis = modes[m];
        d.gaps = 5;
        d.settle_def.dt = 1e-3;
        d.settle_def.max_time = 5;
        spn_world_set_integrator(w, SPN_INTEGRATOR_IMPLICIT); /* silk is stiff */
        spn_inscribe_report rep;
        assert_int_equal(spn_inscribe(&w, t, &d, &rep), SPN_OK);
        assert_int_equal(rep.after.reason, SPN_SETTLE_CONVERGED);
        assert_true(spn_world_max_residual(w, NULL) <= d.settle_def.max_residual);
        assert_int_equal(rep.gaps, 5);
        check_hangs_whole(w);
        spn_target_destroy(t);
        spn_world_destroy(w);
    }
}

/* The settle after editing solves for the rest state (settle_solve): no
 * time is stepped, every particle is balanced to a hundredth of the
 * lightest one's weight, and it is the rest state stepping reaches. */
static void test_settle_after_editing_is_solved(void **state)
{
    (void)state;
    spn_world *solved = inscribe_orb();
    spn_world_set_integrator(solved, SPN_INTEGRATOR_IMPLICIT);
    spn_world *stepped = spn_world_clone(solved);
    assert_non_null(stepped);
    spn_target *t = pig(solved);
    spn_inscribe_def d = spn_inscribe_def_default();
    d.gaps = 5;
    d.settle_def.max_time = 20;
    spn_inscribe_report rep;
    assert_int_equal(spn_inscribe(&solved, t, &d, &rep), SPN_OK);
    assert_int_equal(rep.after.reason, SPN_SETTLE_CONVERGED);
    assert_true(rep.after.newton_steps > 0);
    assert_int_equal(rep.after.steps, 0);
    double lightest = INFINITY;
    for (uint32_t i = 0; i < spn_world_particle_count(solved); i++)
        if (!spn_world_is_fixed(solved, i)) lightest = fmin(lightest, spn_world_mass(solved, i));
    double target = 1e-2 * 9.81 * lightest;
    assert_true(target < d.settle_def.max_residual);
    assert_true(spn_world_max_residual(solved, NULL) <= target);
    /* Stepped to the same residual: the same edits, the same rest state,
     * though the implicit steps after editing solve their CG only to 1e-3
     * (the world's own tolerance is back afterwards). */
    const double cg_tolerance = spn_world_get_def(stepped)->cg_tolerance;
    d.settle_solve = false;
    d.settle_def.max_residual = target;
    d.settle_def.max_kinetic = 1e-30;
    spn_inscribe_report rep2;
    assert_int_equal(spn_inscribe(&stepped, t, &d, &rep2), SPN_OK);
    assert_int_equal(rep2.after.reason, SPN_SETTLE_CONVERGED);
    assert_true(rep2.after.steps > 0);
    assert_int_equal(rep2.removed, rep.removed);
    assert_int_equal(rep2.added, rep.added);
    assert_int_equal(spn_world_particle_count(stepped), spn_world_particle_count(solved));
    double apart = 0;
    for (uint32_t i = 0; i < spn_world_particle_count(solved); i++)
        apart = fmax(apart, spn_v3_len(spn_v3_sub(spn_world_position(solved, i), spn_world_position(stepped, i))));
    assert_true(apart < 1e-7); /* measured 1.6e-9 m, at the world's CG tolerance and at 1e-3 alike */
    assert_true(spn_world_get_def(stepped)->cg_tolerance == cg_tolerance);
    spn_target_destroy(t);
    spn_world_destroy(stepped);
    spn_world_destroy(solved);
}

/* The standard web stepped symplectically at the default 1 ms blows up (its
 * stable step is far shorter): such a web settles implicitly and keeps its
 * integrator. At a step it can take, it steps as it is. */
static void test_too_stiff_settles_implicitly(void **state)
{
    (void)state;
    for (int stable = 0; stable < 2; stable++) {
        spn_world *w = inscribe_orb();
        spn_target *t = pig(w);
        spn_inscribe_def d = spn_inscribe_def_default();
        d.settle_solve = false; /* both settles step */
        double reach = SPN_STABLE_REACH * spn_world_stable_step(w, 0);
        assert_true(reach < d.settle_def.dt);
        if (stable) d.settle_def.dt = 0.5 * reach;
        spn_inscribe_report rep;
        assert_int_equal(spn_inscribe(&w, t, &d, &rep), SPN_OK);
        assert_int_equal(spn_world_get_def(w)->integrator, SPN_INTEGRATOR_SYMPLECTIC);
        assert_true(rep.before.steps > 0 && rep.after.steps > 0);
        assert_int_equal(rep.implicit_before, !stable);
        assert_int_equal(rep.implicit_after, !stable);
        assert_int_equal(rep.after.reason, SPN_SETTLE_CONVERGED);
        assert_true(spn_world_max_residual(w, NULL) <= d.settle_def.max_residual);
        check_hangs_whole(w);
        spn_target_destroy(t);
        spn_world_destroy(w);
    }
    /* Told to keep its integrator, it blows up and says so; the web is untouched. */
    spn_world *w = inscribe_orb(), *before = w;
    spn_target *t = pig(w);
    spn_inscribe_def d = spn_inscribe_def_default();
    d.settle_keep_integrator = true;
    assert_int_equal(spn_inscribe(&w, t, &d, NULL), SPN_ERR_UNSTABLE);
    assert_non_null(strstr(spn_last_error(), "blew up"));
    assert_ptr_equal(w, before);
    spn_target_destroy(t);
    spn_world_destroy(w);
}

/* Replace every capture spring by two, through a new particle at its middle. */
static uint32_t subdivide_capture(spn_world **wp)
{
    spn_world *w = *wp;
    uint32_t ns = spn_world_spring_count(w), added = 0;
    bool *remove = calloc(ns * 3 + 1, sizeof *remove);
    for (uint32_t s = 0; s < ns; s++) {
        spn_spring_info si = spn_world_spring(w, s);
        if (si.tag != SPN_THREAD_CAPTURE) continue;
        spn_particle_def p = spn_particle_def_default();
        p.position = spn_v3_scale(spn_v3_add(spn_world_position(w, si.a), spn_world_position(w, si.b)), 0.5);
        p.mass = 1e-9;
        uint32_t mid;
        assert_int_equal(spn_world_add_particle(w, &p, &mid), SPN_OK);
        spn_spring_def d = {si.a, mid, 2 * si.k, 2 * si.kd, si.rest / 2, 0, INFINITY, true, si.tag, 0, 0};
        assert_int_equal(spn_world_add_spring(w, &d, NULL), SPN_OK);
        d.a = mid, d.b = si.b;
        assert_int_equal(spn_world_add_spring(w, &d, NULL), SPN_OK);
        remove[s] = true;
        added++;
    }
    assert_int_equal(spn_world_remove_springs(w, remove), SPN_OK);
    free(remove);
    return added;
}

static double left_third(void *user, double x, double y) { return (void)user, (void)y, x < -0.05 ? 1 : 0; }

/* The left third of *w inscribed, without settling; the report. */
static spn_inscribe_report inscribe_left_third(spn_world **w)
{
    spn_target *t = NULL;
    assert_int_equal(spn_target_create(*w, 1200, &t), SPN_OK);
    spn_target_paint(t, left_third, NULL);
    spn_inscribe_def d = spn_inscribe_def_default();
    d.settle = false;
    spn_inscribe_report rep;
    assert_int_equal(spn_inscribe(w, t, &d, &rep), SPN_OK);
    spn_target_destroy(t);
    return rep;
}

static void test_subdivided_segments_go_whole(void **state)
{
    (void)state;
    spn_world *w = inscribe_orb();
    uint32_t mids = subdivide_capture(&w), np = spn_world_particle_count(w);
    spn_inscribe_report rep = inscribe_left_third(&w);
    assert_int_equal(rep.segments, mids); /* one segment per pair of springs */
    assert_true(rep.removed > 20);
    assert_int_equal(rep.particles_removed, rep.removed); /* each middle particle went with its segment */
    assert_int_equal(spn_world_particle_count(w), np - rep.removed);
    check_hangs_whole(w);
    spn_world_destroy(w);
}

/* Settings made on the world before inscribing, none at its default. */
static int force_user, collide_user, break_user, air_user;
static void no_force(void *user, const spn_world *w, double t, const spn_vec3 *x, const spn_vec3 *v, spn_vec3 *f)
{
    (void)user, (void)w, (void)t, (void)x, (void)v, (void)f;
}
static double no_collision(void *user, uint32_t i, spn_vec3 from, spn_vec3 to, spn_vec3 *normal, double *keep)
{
    (void)user, (void)i, (void)from, (void)to, (void)normal, (void)keep;
    return 1;
}
static void no_break(void *user, uint32_t s, double t, double length) { (void)user, (void)s, (void)t, (void)length; }
static spn_vec3 still_air(void *user, double t, spn_vec3 p) { return (void)user, (void)t, (void)p, spn_v3(0, 0, 0); }

/* An inscription that has to take particles out (the middles of divided
 * capture threads) keeps what was set on the world outside its definition:
 * the particles go in place (spn_world_remove_particles), not by a rebuild. */
static void test_compaction_keeps_the_world_settings(void **state)
{
    (void)state;
    spn_world *w = inscribe_orb();
    subdivide_capture(&w);
    spn_world_set_force_callback(w, no_force, &force_user);
    spn_world_set_collide_callback(w, no_collision, &collide_user);
    spn_world_set_break_callback(w, no_break, &break_user);
    spn_world_set_air(w, still_air, &air_user, 1.1, 1.9e-5);
    spn_world_set_tag_diameter(w, SPN_THREAD_RADIUS, 3e-6);
    assert_int_equal(spn_world_set_tag_hysteresis(w, SPN_THREAD_RADIUS, 0.6, 2e-3), SPN_OK);
    assert_int_equal(spn_world_add_plane(w, spn_v3(0, 1, 0), -0.5, 0.3, 0.4), SPN_OK);
    spn_world_set_lattice(w, false);
    spn_world_set_precision(w, SPN_PRECISION_FLOAT32);
    assert_int_equal(spn_world_set_implicit_preconditioner(w, SPN_PRECOND_MULTIGRID), SPN_OK);
    spn_world_set_time(w, 0.75);
    spn_inscribe_report rep = inscribe_left_third(&w);
    assert_true(rep.particles_removed > 20); /* the compaction did run */
    void *user = NULL;
    assert_ptr_equal(spn_world_force_callback(w, &user), no_force);
    assert_ptr_equal(user, &force_user);
    assert_ptr_equal(spn_world_collide_callback(w, &user), no_collision);
    assert_ptr_equal(user, &collide_user);
    assert_ptr_equal(spn_world_break_callback(w, &user), no_break);
    assert_ptr_equal(user, &break_user);
    double rho = 0, mu = 0, rate0 = 0;
    assert_ptr_equal(spn_world_air(w, &user, &rho, &mu), still_air);
    assert_ptr_equal(user, &air_user);
    assert_true(rho == 1.1 && mu == 1.9e-5);
    assert_true(spn_world_tag_diameter(w, SPN_THREAD_RADIUS) == 3e-6);
    assert_true(fabs(spn_world_tag_hysteresis(w, SPN_THREAD_RADIUS, &rate0) - 0.6) < 1e-15 && rate0 == 2e-3);
    assert_int_equal(spn_world_collider_count(w), 1);
    assert_false(spn_world_lattice_allowed(w));
    assert_int_equal(spn_world_precision(w), SPN_PRECISION_FLOAT32);
    assert_int_equal(spn_world_implicit_preconditioner(w), SPN_PRECOND_MULTIGRID);
    assert_true(spn_world_time(w) == 0.75);
    check_hangs_whole(w);
    spn_world_destroy(w);
}

/* A broken half of a divided capture thread: its middle particle is left
 * with one live thread, which dangles and goes, and the particle goes with
 * its broken spring (the rebuild used to look up the dropped particle's id). */
static void test_broken_half_goes_with_its_particle(void **state)
{
    (void)state;
    spn_world *w = inscribe_orb();
    uint32_t np0 = spn_world_particle_count(w);
    subdivide_capture(&w);
    uint32_t half = SPN_REMOVED;
    for (uint32_t s = 0; s < spn_world_spring_count(w) && half == SPN_REMOVED; s++) {
        spn_spring_info si = spn_world_spring(w, s);
        bool right = spn_world_position(w, si.a).x > 0.05 && spn_world_position(w, si.b).x > 0.05;
        if (si.tag == SPN_THREAD_CAPTURE && right) half = s;
    }
    assert_true(half != SPN_REMOVED);
    assert_true(spn_world_spring(w, half).a >= np0 || spn_world_spring(w, half).b >= np0); /* ends on a middle */
    spn_world_break_spring(w, half);
    spn_inscribe_report rep = inscribe_left_third(&w);
    assert_int_equal(rep.particles_removed, rep.removed + 1);
    for (uint32_t s = 0; s < spn_world_spring_count(w); s++) assert_false(spn_world_spring(w, s).broken);
    check_hangs_whole(w);
    spn_world_destroy(w);
}

static void test_failure_leaves_the_web_alone(void **state)
{
    (void)state;
    spn_world *w = inscribe_orb(), *before = w;
    spn_target *t = NULL;
    assert_int_equal(spn_target_create(w, 200, &t), SPN_OK);
    spn_inscribe_def d = spn_inscribe_def_default();
    d.threshold = 11;
    assert_int_equal(spn_inscribe(&w, t, &d, NULL), SPN_ERR_INVALID);
    assert_non_null(strstr(spn_last_error(), "threshold"));
    assert_ptr_equal(w, before);
    /* A world with no capture spiral has nothing to inscribe. */
    spn_world *chain = NULL;
    assert_int_equal(spn_scene_chain(NULL, spn_v3(0, 0, 0), spn_v3(1, 0, 0), 4, 1, 0.1, 10, 0, &chain), SPN_OK);
    d = spn_inscribe_def_default();
    assert_int_equal(spn_inscribe(&chain, t, &d, NULL), SPN_ERR_INVALID);
    assert_non_null(strstr(spn_last_error(), "capture"));
    spn_world_destroy(chain);
    spn_target_destroy(t);
    spn_world_destroy(w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_inscribed_web_is_settled_and_whole),
        cmocka_unit_test(test_settle_after_editing_is_solved),
        cmocka_unit_test(test_too_stiff_settles_implicitly),
        cmocka_unit_test(test_subdivided_segments_go_whole),
        cmocka_unit_test(test_compaction_keeps_the_world_settings),
        cmocka_unit_test(test_broken_half_goes_with_its_particle),
        cmocka_unit_test(test_failure_leaves_the_web_alone),
    };
    int failed = cmocka_run_group_tests(tests, NULL, NULL);
    spn_render_release_caches(); /* cairo's and fontconfig's font caches */
    return failed;
}
