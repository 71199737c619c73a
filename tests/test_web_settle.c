/* spn_web_settle solves for the rest state before it steps in time: on a web
 * where the static equilibrium converges it is the rest state that stepping
 * reaches, no time passes and every particle is balanced to a hundredth of the
 * lightest one's weight; where the solve falls short the web steps from as it
 * was built, exactly as without the solve; a web whose implicit steps went
 * wrong as built (a 5 cm Zygiella) comes to rest with its steps held to
 * creating no energy; webs that step do so with the multigrid, and come to
 * rest even when the world's CG tolerance is loose; and a web that
 * something else acts on (a force callback, a collider) is never solved
 * for. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "web_checks.h"
#include "web/web_internal.h"

/* Adds nothing: a web with it is settled by stepping only. */
static void no_force(void *user, const spn_world *w, double t, const spn_vec3 *x, const spn_vec3 *v, spn_vec3 *f)
{
    (void)user, (void)w, (void)t, (void)x, (void)v, (void)f;
}

/* A species web as `spinneret build --species ... --settle` settles it (silk:
 * implicit): seed `seed`, `size` metres across (0: the preset's). */
/* A species web as designed (web_as_designed): the webs the stepped
 * settle's tests were written on. */
static spn_world *species_web(spn_species kind, uint64_t seed, double size)
{
    spn_species_def d = spn_species_def_preset(kind);
    web_as_designed(&d.strains, &d.form_find);
    d.seed = seed;
    if (size > 0) d.size = size;
    d.world.integrator = SPN_INTEGRATOR_IMPLICIT;
    spn_world *w = NULL;
    assert_int_equal(spn_web_build_species(&d, &w), SPN_OK);
    return w;
}

static spn_world *physical_web(bool silk)
{
    spn_physical_def d = web_physical_30cm(silk);
    spn_world *w = NULL;
    assert_int_equal(spn_web_build_physical(&d, &w), SPN_OK);
    if (silk) spn_world_set_integrator(w, SPN_INTEGRATOR_IMPLICIT);
    return w;
}

static double lightest_weight(const spn_world *w)
{
    double m = INFINITY;
    for (uint32_t i = 0; i < spn_world_particle_count(w); i++)
        if (!spn_world_is_fixed(w, i)) m = fmin(m, spn_world_mass(w, i));
    return m * spn_v3_len(spn_world_get_def(w)->gravity);
}

static double largest_gap(const spn_world *a, const spn_world *b)
{
    double gap = 0;
    for (uint32_t i = 0; i < spn_world_particle_count(a); i++)
        gap = fmax(gap, spn_v3_len(spn_v3_sub(spn_world_position(a, i), spn_world_position(b, i))));
    return gap;
}

/* The solve's rest state: every particle balanced to a hundredth of the
 * lightest one's weight, at rest, and no time passed. */
static void check_solved(spn_world *w, const spn_settle_report *r)
{
    const double weight = lightest_weight(w);
    assert_int_equal(r->reason, SPN_SETTLE_CONVERGED);
    assert_true(r->newton_steps > 0 && r->newton_steps <= 50);
    assert_true(r->steps == 0 && r->time == 0 && r->kinetic == 0);
    assert_true(r->residual <= 1e-2 * weight);
    assert_true(spn_world_max_residual(w, NULL) <= 1e-2 * weight);
    for (uint32_t i = 0; i < spn_world_particle_count(w); i++)
        assert_true(spn_v3_len(spn_world_velocity(w, i)) == 0);
}

/* The silk web solved, and stepped (a force callback that adds nothing
 * keeps it from the solve): the same rest state. */
static void test_solved_rest_is_stepped_rest(void **state)
{
    (void)state;
    spn_world *solved = physical_web(true), *stepped = spn_world_clone(solved);
    spn_world_set_force_callback(stepped, no_force, NULL);
    spn_settle_report a, b;
    assert_int_equal(spn_web_settle(solved, 20, &a), SPN_OK);
    assert_int_equal(spn_web_settle(stepped, 20, &b), SPN_OK);
    const double gap = largest_gap(solved, stepped);
    print_message("solved: %d Newton steps, residual %.3g N; stepped: %.3g s, %llu steps, residual %.3g N; "
                  "largest gap %.3g m\n",
                  a.newton_steps, a.residual, b.time, (unsigned long long)b.steps, b.residual, gap);
    check_solved(solved, &a);
    assert_int_equal(b.reason, SPN_SETTLE_CONVERGED);
    assert_int_equal(b.newton_steps, 0);
    assert_true(b.steps > 0);
    /* the same rest state: a micrometre on a web 30 cm across (measured
     * 3e-12 m; the thesis' threads, stepped explicitly, 2e-7 m) */
    assert_true(gap < 1e-6);
    spn_world_destroy(solved);
    spn_world_destroy(stepped);
}

/* The thesis' soft threads (an explicit integrator; stepping them to rest
 * takes some 19,000 steps, too slow to repeat here under the sanitizers). */
static void test_solved_rest_thesis_threads(void **state)
{
    (void)state;
    spn_world *w = physical_web(false);
    spn_settle_report r;
    assert_int_equal(spn_web_settle(w, 20, &r), SPN_OK);
    check_solved(w, &r);
    spn_world_destroy(w);
}

/* The smallest strain of an intact thread of kind `tag` (INFINITY: none). */
static double least_strain(const spn_world *w, uint32_t tag)
{
    double least = INFINITY;
    for (uint32_t s = 0; s < spn_world_spring_count(w); s++) {
        spn_spring_info si = spn_world_spring(w, s);
        if (si.tag == tag && !si.broken) least = fmin(least, si.length / si.rest - 1);
    }
    return least;
}

/* Two species webs that used to rest on slack threads and step for seconds
 * (thirty-fourth session; docs/web-builders.md, "Settling"): Argiope's
 * stabilimentum, a solid thread at the radii's strain, pinched the radii it
 * joins and rested at strains of 1e-7; Zygiella's hub, open where the signal
 * thread leaves it, left a fifth of its threads slack. Both are solved now,
 * the band taut (measured: at least 0.21) and no hub thread slack (least
 * strain measured 3e-4). */
static void test_argiope_and_zygiella_are_solved(void **state)
{
    (void)state;
    const struct {
        spn_species kind;
        uint64_t seed;
        uint32_t tag;
        double least;
    } cases[] = {{SPN_SPECIES_ARGIOPE, 1, SPN_THREAD_STABILIMENTUM, 0.1}, {SPN_SPECIES_ZYGIELLA, 2, SPN_THREAD_HUB, 0}};
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        spn_world *w = species_web(cases[c].kind, cases[c].seed, 0);
        spn_settle_report r;
        assert_int_equal(spn_web_settle(w, 30, &r), SPN_OK);
        const double least = least_strain(w, cases[c].tag);
        print_message("%s seed %llu: %d Newton steps, least %s strain %.3g\n", spn_species_name(cases[c].kind),
                      (unsigned long long)cases[c].seed, r.newton_steps, spn_thread_kind_name(cases[c].tag), least);
        check_solved(w, &r);
        assert_true(isfinite(least) && least > cases[c].least);
        spn_world_destroy(w);
    }
}

/* A small generic species web, whose light particles between nearly slack
 * threads the solve does not balance (its residual stalls): the web is
 * stepped from as it was built, bit for bit what stepping alone gives. (If
 * the solver learns to settle this web, pick one it does not; the 6 cm web
 * used until the thirty-third session's mooring threads is now solved, and
 * so is seed 1 at 8 cm since the Newton steps are halved before the shift
 * grows: 24 Newton steps.) */
static void test_unfinished_solve_steps_from_built(void **state)
{
    (void)state;
    spn_world *w = species_web(SPN_SPECIES_GENERIC, 2, 0.10), *alone = spn_world_clone(w);
    spn_world_set_force_callback(alone, no_force, NULL);
    spn_settle_report a, b;
    assert_int_equal(spn_web_settle(w, 3, &a), SPN_OK);
    assert_int_equal(spn_web_settle(alone, 3, &b), SPN_OK);
    print_message("Newton steps %d, then %.3g s stepped (%llu steps); alone %.3g s\n", a.newton_steps, a.time,
                  (unsigned long long)a.steps, b.time);
    /* its residual stops halving after 20 steps: the rounds of 10 give up
     * before the cap of 50 (c9e311e; with one run of 50 it took all 50) */
    assert_true(a.newton_steps >= 10 && a.newton_steps < 50 && a.newton_steps % 10 == 0);
    assert_int_equal(b.newton_steps, 0);
    assert_int_equal(a.reason, SPN_SETTLE_CONVERGED);
    assert_true(a.steps > 0 && a.steps == b.steps);
    assert_true(largest_gap(w, alone) == 0);
    spn_world_destroy(w);
    spn_world_destroy(alone);
}

/* A 5 cm Zygiella web as built before the thirty-third session's mooring
 * threads (tests/data/io/zygiella-5cm-thin-moorings.json: its radii keep
 * little of their pretension at rest): the solve falls short, and until the
 * settle held its implicit steps to creating no energy
 * (spn_world_set_energy_limit) they went wrong on it (CG out of iterations,
 * threads going slack within a step) and it did not come to rest in 30 s
 * (nor 6 cm, nor Zilla seeds 4 and 6). */
static void test_zygiella_comes_to_rest(void **state)
{
    (void)state;
    spn_world *w = NULL;
    assert_int_equal(spn_web_load(SPN_TEST_DATA "/io/zygiella-5cm-thin-moorings.json", &w), SPN_OK);
    spn_world_set_integrator(w, SPN_INTEGRATOR_IMPLICIT);
    spn_settle_report r;
    assert_int_equal(spn_web_settle(w, 30, &r), SPN_OK);
    double strain = 0;
    for (uint32_t s = 0; s < spn_world_spring_count(w); s++) {
        spn_spring_info si = spn_world_spring(w, s);
        if (!si.broken) strain = fmax(strain, si.length / si.rest - 1);
    }
    print_message("Newton steps %d, then %.3g s stepped (%llu steps), residual %.3g N, largest strain %.3g\n",
                  r.newton_steps, r.time, (unsigned long long)r.steps, r.residual, strain);
    assert_int_equal(r.reason, SPN_SETTLE_CONVERGED);
    assert_true(r.steps > 0);
    assert_true(spn_world_max_residual(w, NULL) <= 1e-2 * lightest_weight(w));
    assert_true(strain < 0.5); /* laid at up to 30% (the spiral); the runaway stretched threads 3,000-fold */
    assert_int_equal(spn_world_energy_limit(w), SPN_ENERGY_LIMIT_OFF); /* the setting is the caller's again */
    spn_world_destroy(w);
}

/* Species seed `seed` as `spinneret build --species ... --seed N --settle`
 * settles it, where the solve falls short: settled (30 s at most) and
 * checked at rest, having stepped. */
static spn_world *stepped_to_rest(spn_species kind, uint64_t seed, double cg_tolerance, spn_settle_report *r)
{
    spn_world *w = species_web(kind, seed, 0);
    if (cg_tolerance > 0) assert_int_equal(spn_world_set_solver_tolerance(w, cg_tolerance, 1000), SPN_OK);
    assert_int_equal(spn_web_settle(w, 30, r), SPN_OK);
    print_message("%s seed %llu: Newton steps %d, then %.3g s stepped (%llu steps), residual %.3g N\n",
                  spn_species_name(kind), (unsigned long long)seed, r->newton_steps, r->time,
                  (unsigned long long)r->steps, r->residual);
    assert_int_equal(r->reason, SPN_SETTLE_CONVERGED);
    assert_true(r->newton_steps > 0 && r->steps > 0);
    assert_true(spn_world_max_residual(w, NULL) <= 1e-2 * lightest_weight(w));
    assert_int_equal(spn_world_energy_limit(w), SPN_ENERGY_LIMIT_OFF);
    return w;
}

/* Zilla seed 7: the solve falls short (radii at the hub rest at strains of
 * 1e-8 to 1e-11) and the web steps to rest. Its implicit steps take the
 * cyclic preconditioner (here the multigrid) at a CG tolerance of 1e-6
 * (settle.c, SETTLE_CG_TOLERANCE): 0.5 s of simulated time, where block
 * Jacobi at the world's 1e-10, at the cap of 100 iterations nearly every
 * step, took 3.8 s. The world's own choices are restored. */
static void test_zilla_steps_to_rest_with_the_multigrid(void **state)
{
    (void)state;
    spn_settle_report r;
    spn_world *w = stepped_to_rest(SPN_SPECIES_ZILLA, 7, 0, &r);
    assert_true(r.time <= 1.0);
    assert_int_equal(spn_world_implicit_preconditioner(w), SPN_PRECOND_AUTO);
    assert_true(spn_world_get_def(w)->cg_tolerance == 1e-10);
    spn_world_destroy(w);
}

/* The settle keeps a world's CG tolerance where it is looser than its own
 * 1e-6, and a step whose CG stops at a loose tolerance is taken whole. At
 * 1e-3 such steps kicked Zygiella seed 5 about until it blew up (1,150 N
 * after 30 s of simulated time) before the settle held every step to
 * creating no energy once the web stopped making progress (step_to_rest);
 * now it is at rest in under 2 s. */
static void test_loose_solves_come_to_rest(void **state)
{
    (void)state;
    spn_settle_report r;
    spn_world *w = stepped_to_rest(SPN_SPECIES_ZYGIELLA, 5, 1e-3, &r);
    assert_true(r.time <= 5);
    assert_true(spn_world_get_def(w)->cg_tolerance == 1e-3);
    spn_world_destroy(w);
}

/* A collider acts on the web: never solved for. */
static int by_value(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The median distance a particle moved from `built` to `rested`, over the
 * built web's width. */
static double median_move(const spn_world *built, const spn_world *rested)
{
    const uint32_t n = spn_world_particle_count(built);
    double *d = malloc(n * sizeof *d), lo = INFINITY, hi = -INFINITY;
    assert_non_null(d);
    for (uint32_t i = 0; i < n; i++) {
        const spn_vec3 p = spn_world_position(built, i);
        lo = fmin(lo, p.x), hi = fmax(hi, p.x);
        d[i] = spn_v3_len(spn_v3_sub(p, spn_world_position(rested, i)));
    }
    qsort(d, n, sizeof *d, by_value);
    const double m = d[n / 2] / (hi - lo);
    free(d);
    return m;
}

/* Webs woven with the thesis preset's threads (soft and heavy: a 3 mm spoke
 * of 10 ug at 0.01 N/m) hang taut when laid at the thesis' own strains
 * (spn_web_strains_preset): solved, no radius slack, and at rest the median
 * particle lies under 3% of the web's width from where the design put it.
 * Laid at silk's 2%, as they were until the thirty-sixth session, they
 * sagged below their frame (the median particle 7.6-9.9% of the width from
 * the design, radii slack, the geometric web collapsed onto its lower side)
 * and stepped for 0.6-56 s; now 1.1-1.9%. Argiope's band, then of the
 * spokes' material, curled; it pulls like the capture spiral now. */
static void test_thesis_preset_webs_hang_taut(void **state)
{
    (void)state;
    static const spn_vec3 anchors[3] = {{0, 0.5, 0}, {-0.45, -0.3, 0}, {0.45, -0.3, 0}};
    for (int c = 0; c < 3; c++) {
        spn_world *w = NULL, *designed = NULL;
        for (int pass = 0; pass < 2; pass++) { /* the design (no form finding), then the web */
            spn_world **out = pass ? &w : &designed;
            if (c == 0) {
                spn_geometric_def d = spn_geometric_def_default();
                d.anchors = anchors, d.anchor_count = 3;
                d.materials = spn_web_materials_preset(SPN_MATERIAL_THESIS);
                d.strains = spn_web_strains_preset(SPN_MATERIAL_THESIS);
                d.form_find = pass;
                assert_int_equal(spn_web_build_geometric(&d, out), SPN_OK);
            } else {
                spn_species_def d = spn_species_def_preset(c == 1 ? SPN_SPECIES_ARANEUS : SPN_SPECIES_ARGIOPE);
                d.materials = spn_web_materials_preset(SPN_MATERIAL_THESIS);
                d.strains = spn_web_strains_preset(SPN_MATERIAL_THESIS);
                d.form_find = pass;
                assert_int_equal(spn_web_build_species(&d, out), SPN_OK);
            }
        }
        spn_settle_report r;
        assert_int_equal(spn_web_settle(w, 30, &r), SPN_OK);
        const double move = median_move(designed, w), radius = least_strain(w, SPN_THREAD_RADIUS);
        const double band = least_strain(w, SPN_THREAD_STABILIMENTUM);
        print_message("case %d: %d Newton steps, median %.3g of the width from the design, least radius strain %.3g, "
                      "band %.3g\n",
                      c, r.newton_steps, move, radius, band);
        check_solved(w, &r);
        assert_true(move < 0.03);
        assert_true(radius > 0);
        if (c == 2) assert_true(band > 0);
        spn_world_destroy(designed);
        spn_world_destroy(w);
    }
}

/* Woven silk webs are built at rest (form_find.c): each species web, and
 * geometric webs of three and six anchors, settles by the static equilibrium
 * in at most 3 Newton steps (measured: 2 on every species web of seeds 1-7
 * and on these), moving no particle by more than a micrometre (measured:
 * 4e-7 m at most),
 * and no radius, hub or capture thread rests slack or nearly so (every one
 * at a strain of at least a tenth of the radii's 0.5%; measured: at least
 * 2.6e-3). As designed, without the form finding, the same webs rest with
 * radii at strains of 1e-9 (geometric) and the settle stepped for up to 1.2 s
 * (species) and 18 s (geometric webs) of CPU. */
static void test_woven_webs_are_built_at_rest(void **state)
{
    (void)state;
    static const spn_vec3 three[3] = {{0, 0.5, 0}, {-0.45, -0.3, 0}, {0.45, -0.3, 0}};
    static const spn_vec3 six[6] = {{-0.5, 0.3, 0}, {0, 0.55, 0}, {0.5, 0.3, 0}, {0.45, -0.35, 0}, {-0.1, -0.5, 0}, {-0.5, -0.3, 0}};
    for (int c = 0; c < SPN_SPECIES_COUNT + 2; c++) {
        spn_world *w = NULL;
        if (c < SPN_SPECIES_COUNT) {
            spn_species_def d = spn_species_def_preset((spn_species)c);
            d.seed = 7;
            d.world.integrator = SPN_INTEGRATOR_IMPLICIT;
            assert_int_equal(spn_web_build_species(&d, &w), SPN_OK);
        } else {
            spn_geometric_def d = spn_geometric_def_default();
            d.anchors = c == SPN_SPECIES_COUNT ? three : six;
            d.anchor_count = c == SPN_SPECIES_COUNT ? 3 : 6;
            d.seed = 2;
            d.world.integrator = SPN_INTEGRATOR_IMPLICIT;
            assert_int_equal(spn_web_build_geometric(&d, &w), SPN_OK);
        }
        spn_world *built = spn_world_clone(w);
        assert_non_null(built);
        spn_settle_report r;
        assert_int_equal(spn_web_settle(w, 30, &r), SPN_OK);
        const double gap = largest_gap(built, w);
        double least = INFINITY;
        const uint32_t kinds[3] = {SPN_THREAD_RADIUS, SPN_THREAD_HUB, SPN_THREAD_CAPTURE};
        for (int k = 0; k < 3; k++) least = fmin(least, least_strain(w, kinds[k]));
        print_message("case %d: %d Newton steps, largest move %.3g m, least radius, hub or capture strain %.3g\n", c,
                      r.newton_steps, gap, least);
        check_solved(w, &r);
        assert_true(r.newton_steps <= 3);
        assert_true(gap < 1e-6);
        assert_true(least >= 5e-4);
        spn_world_destroy(built);
        spn_world_destroy(w);
    }
}

/* Sum of |a - b| over positions, rest lengths and stiffnesses: 0 when the
 * two worlds' webs are the same bit for bit (-0 aside). */
static double web_difference(const spn_world *a, const spn_world *b)
{
    assert_int_equal(spn_world_particle_count(a), spn_world_particle_count(b));
    assert_int_equal(spn_world_spring_count(a), spn_world_spring_count(b));
    double d = 0;
    for (uint32_t i = 0; i < spn_world_particle_count(a); i++) {
        d += spn_v3_len(spn_v3_sub(spn_world_position(a, i), spn_world_position(b, i)));
        assert_true(spn_v3_len(spn_world_velocity(a, i)) == 0);
    }
    for (uint32_t s = 0; s < spn_world_spring_count(a); s++) {
        spn_spring_info sa = spn_world_spring(a, s), sb = spn_world_spring(b, s);
        d += fabs(sa.rest - sb.rest) + fabs(sa.k - sb.k);
    }
    return d;
}

/* Where the form finding's solve falls short (here allowed one Newton
 * step, where Zilla seed 2 takes about 15) or the web has more particles
 * than the form finding takes (here the cap set one under the web's), the
 * web is left as designed: positions, rest lengths and stiffnesses the same
 * bits as the web built with form_find off, and its metadata says so
 * ("form_found": 0). The web form-found differs. */
static void test_form_find_falls_back_to_the_design(void **state)
{
    (void)state;
    spn_species_def d = spn_species_def_preset(SPN_SPECIES_ZILLA);
    d.seed = 2;
    d.form_find = false;
    spn_world *designed = NULL, *found = NULL;
    assert_int_equal(spn_web_build_species(&d, &designed), SPN_OK);
    d.form_find = true;
    assert_int_equal(spn_web_build_species(&d, &found), SPN_OK);
    assert_true(web_difference(designed, found) > 1e-3);
    assert_non_null(strstr(spn_world_metadata(found), "\"form_found\": 1"));
    assert_non_null(strstr(spn_world_metadata(designed), "\"form_found\": 0"));
    for (int c = 0; c < 2; c++) {
        const int old_steps = c == 0 ? spn__form_find_set_steps(1) : 0;
        const uint32_t old_max = c == 1 ? spn__form_find_set_max_particles(spn_world_particle_count(designed) - 1) : 0;
        spn_world *w = NULL;
        const spn_status st = spn_web_build_species(&d, &w);
        if (c == 0) spn__form_find_set_steps(old_steps);
        else spn__form_find_set_max_particles(old_max);
        assert_int_equal(st, SPN_OK);
        assert_true(web_difference(designed, w) == 0);
        assert_non_null(strstr(spn_world_metadata(w), "\"form_find\": 1")); /* asked for */
        assert_non_null(strstr(spn_world_metadata(w), "\"form_found\": 0")); /* and not done */
        spn_world_destroy(w);
    }
    spn_world_destroy(designed), spn_world_destroy(found);
}

static void test_collider_keeps_stepping(void **state)
{
    (void)state;
    spn_world *w = physical_web(true);
    assert_int_equal(spn_world_add_plane(w, spn_v3(0, 0, 1), -1, 0, 0), SPN_OK);
    spn_settle_report r;
    assert_int_equal(spn_web_settle(w, 20, &r), SPN_OK);
    assert_int_equal(r.newton_steps, 0);
    assert_true(r.steps > 0);
    assert_int_equal(r.reason, SPN_SETTLE_CONVERGED);
    spn_world_destroy(w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_solved_rest_is_stepped_rest),
        cmocka_unit_test(test_solved_rest_thesis_threads),
        cmocka_unit_test(test_unfinished_solve_steps_from_built),
        cmocka_unit_test(test_zygiella_comes_to_rest),
        cmocka_unit_test(test_argiope_and_zygiella_are_solved),
        cmocka_unit_test(test_zilla_steps_to_rest_with_the_multigrid),
        cmocka_unit_test(test_loose_solves_come_to_rest),
        cmocka_unit_test(test_collider_keeps_stepping),
        cmocka_unit_test(test_thesis_preset_webs_hang_taut),
        cmocka_unit_test(test_woven_webs_are_built_at_rest),
        cmocka_unit_test(test_form_find_falls_back_to_the_design),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
