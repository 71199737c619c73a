/* Prey striking the standard orb web (capture rings made compliant like
 * capture silk, settled under gravity): a slow strike is stopped without
 * breakage, a much faster one breaks threads and passes through, and in both
 * the energy is accounted for within 2% of the strike's kinetic energy
 * (kinetic + elastic + dissipated + broken + air). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>
#include <spinneret/spinneret.h>

/* The standard web gives every thread dragline stiffness; real capture silk
 * is about a thousand times more compliant (E ~ 3 MPa against 10 GPa,
 * Gosline et al. 1999), which is what leaves the radii to stop the prey. */
static void capture_silk(spn_world *w)
{
    for (uint32_t s = 0; s < spn_world_spring_count(w); s++) {
        spn_spring_info in = spn_world_spring(w, s);
        if (in.tag == SPN_THREAD_CAPTURE) spn_world_set_spring_stiffness(w, s, in.k * 1e-3, in.kd * 0.03);
    }
}

/* Let the pre-strained web sag under gravity and come to rest (implicit steps
 * and a strong viscous drag, both removed after), as `spinneret settle` would. */
static void settle(spn_world *w)
{
    spn_world_set_integrator(w, SPN_INTEGRATOR_IMPLICIT);
    spn_world_set_drag(w, 200);
    spn_settle_def sd = spn_settle_def_default();
    sd.dt = 1e-3;
    sd.max_time = 1;
    sd.max_kinetic = 1e-12;
    spn_settle_report sr;
    assert_int_equal(spn_world_settle(w, &sd, &sr), SPN_OK);
    assert_int_equal(sr.reason, SPN_SETTLE_CONVERGED);
    spn_world_set_drag(w, 0);
    spn_world_set_integrator(w, SPN_INTEGRATOR_SYMPLECTIC);
    for (uint32_t i = 0; i < spn_world_particle_count(w); i++) spn_world_set_velocity(w, i, spn_v3(0, 0, 0));
    spn_world_set_time(w, 0);
}

static spn_anim_report strike(double speed, double mass, double duration)
{
    spn_orb_scene_def od = spn_orb_scene_def_default();
    spn_world *w = NULL;
    assert_int_equal(spn_scene_orb(NULL, &od, &w), SPN_OK);
    capture_silk(w);
    settle(w);
    spn_prey_def prey = {{0.012, 0.007, 0.01}, {0, 0, -speed}, mass, 0.005};
    spn_anim_def ad = spn_anim_def_default();
    ad.duration = duration;
    ad.fps = 100;
    ad.prey = &prey;
    ad.nprey = 1;
    spn_anim_report rep;
    assert_int_equal(spn_animate(&w, &ad, NULL, NULL, &rep), SPN_OK);
    const spn_impact_report *r = &rep.impact;
    printf("# speed %g: %s, breaks %u, KE %.3g -> %.3g J, balance error %.3g%%, air %.3g, substeps %d\n", speed,
           spn_prey_outcome_name(r->outcome[0]), r->breaks, r->prey_kinetic_start, r->prey_kinetic_end,
           100 * r->balance_error / r->prey_kinetic_start, -r->air_work, rep.substeps);
    printf("#   strike over at %.3f s: of %.3g J lost,", r->strike_time, r->strike_prey_kinetic_lost);
    for (int i = 0; i < r->nkinds; i++)
        printf(" %s %.0f%%", spn_thread_kind_name(r->kinds[i].tag), 100 * r->strike_absorbed[i] / r->strike_prey_kinetic_lost);
    printf(", air %.0f%%\n", 100 * r->strike_air / r->strike_prey_kinetic_lost);
    for (int i = 0; i < r->nkinds; i++)
        printf("#   %s: elastic %.3g damping %.3g plastic %.3g broken %.3g (%u)\n", spn_thread_kind_name(r->kinds[i].tag),
               r->kinds[i].elastic, r->kinds[i].damping, r->kinds[i].plastic, r->kinds[i].broken, r->kinds[i].breaks);
    spn_world_destroy(w);
    return rep;
}

/* Share of the prey's lost energy held by thread kind `tag` when the strike ended. */
static double strike_share(const spn_impact_report *r, uint32_t tag)
{
    for (int i = 0; i < r->nkinds; i++)
        if (r->kinds[i].tag == tag) return r->strike_absorbed[i] / r->strike_prey_kinetic_lost;
    return 0;
}

static void test_slow_strike_is_stopped(void **state)
{
    (void)state;
    spn_anim_report rep = strike(0.5, 2e-4, 0.3);
    assert_true(rep.has_impact);
    /* Stopped: the web arrests the flight. A linear, lightly damped web then
     * gives the energy back (bounced); held or thrown back, it never passes. */
    assert_true(rep.impact.outcome[0] == SPN_PREY_STOPPED || rep.impact.outcome[0] == SPN_PREY_BOUNCED ||
                rep.impact.outcome[0] == SPN_PREY_HELD);
    assert_int_equal(rep.impact.breaks, 0);
    assert_true(rep.impact.balance_error <= 0.02 * rep.impact.prey_kinetic_start);
    /* Sensenig et al. 2012: the radii take most of the work of stopping prey,
     * the capture spiral and the air little. */
    const spn_impact_report *r = &rep.impact;
    assert_true(r->strike_time > 0);
    double radii = strike_share(r, SPN_THREAD_RADIUS), capture = strike_share(r, SPN_THREAD_CAPTURE);
    assert_true(radii > 0.5);
    assert_true(radii > 3 * capture);
    assert_true(radii > 3 * r->strike_air / r->strike_prey_kinetic_lost);
}

static void test_fast_strike_breaks_through(void **state)
{
    (void)state;
    spn_anim_report rep = strike(8, 2e-4, 0.1);
    assert_int_equal(rep.impact.outcome[0], SPN_PREY_PASSED);
    assert_true(rep.impact.breaks >= 2);
    assert_true(rep.impact.balance_error <= 0.02 * rep.impact.prey_kinetic_start);
}

/* The physical builder's threads are laid 75-250% over-extended (Mehla 2005)
 * and settle taut far past any silk's breaking strain from their rest
 * lengths. Struck, the web keeps them: they break at their strain past the
 * length they have when the prey comes (spn__break_length), where before
 * every radius broke at the first step. A slow prey is held with no radius
 * broken; a fast one tears a hole round the strike (its thesis silk is soft),
 * goes through, and the rest of the web holds. */
static void test_overextended_web_keeps_its_threads(void **state)
{
    (void)state;
    static const spn_vec3 anchors[4] = {{-0.4, 0.42, 0}, {0.42, 0.38, 0}, {0.4, -0.45, 0}, {-0.42, -0.38, 0}};
    const double speeds[2] = {0.5, 8};
    for (int i = 0; i < 2; i++) {
        spn_physical_def d = spn_physical_def_default();
        d.anchors = anchors;
        d.anchor_count = 4;
        spn_world *w = NULL;
        assert_int_equal(spn_web_build_physical(&d, &w), SPN_OK);
        spn_settle_report sr;
        assert_int_equal(spn_web_settle(w, 5, &sr), SPN_OK);
        uint32_t past = 0, intact = 0;
        for (uint32_t s = 0; s < spn_world_spring_count(w); s++) {
            const spn_spring_info in = spn_world_spring(w, s);
            intact += !in.broken;
            past += in.tag == SPN_THREAD_RADIUS && in.length > in.rest * (1 + spn_thread_breaking_strain(in.tag));
        }
        assert_true(past > 100); /* the case is reached: radii past the silk's breaking strain */
        spn_prey_def prey = {{0.01, 0.01, 0.02}, {0, 0, -speeds[i]}, 2e-4, 0.005};
        spn_anim_def ad = spn_anim_def_default();
        ad.duration = 0.05;
        ad.fps = 100;
        ad.prey = &prey;
        ad.nprey = 1;
        spn_anim_report rep;
        assert_int_equal(spn_animate(&w, &ad, NULL, NULL, &rep), SPN_OK);
        uint32_t radii = 0;
        for (int k = 0; k < rep.impact.nkinds; k++)
            if (rep.impact.kinds[k].tag == SPN_THREAD_RADIUS) radii = rep.impact.kinds[k].breaks;
        printf("# physical web (%u radius segments past 27%% strain), prey at %g m/s: %s, %u of %u springs broken "
               "(%u radius), at most %.3g m from the strike, web radius %.3g m\n",
               past, speeds[i], spn_prey_outcome_name(rep.impact.outcome[0]), rep.impact.breaks, intact, radii,
               rep.impact.break_distance_max, rep.impact.web_radius);
        assert_true(rep.impact.outcome[0] != SPN_PREY_MISSED);
        if (i == 0) {
            assert_true(rep.impact.outcome[0] != SPN_PREY_PASSED);
            assert_int_equal(radii, 0);
            assert_true(rep.impact.breaks <= 10);
        } else {
            /* through, though the threads it tore trail it (not "stopped" at 7.6 m/s) */
            assert_int_equal(rep.impact.outcome[0], SPN_PREY_PASSED);
            assert_true(rep.impact.breaks >= 10 && rep.impact.breaks * 20 < intact);
            assert_true(radii * 20 < past);
            assert_true(rep.impact.break_distance_max < 0.5 * rep.impact.web_radius);
        }
        spn_world_destroy(w);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_slow_strike_is_stopped),
        cmocka_unit_test(test_fast_strike_breaks_through),
        cmocka_unit_test(test_overextended_web_keeps_its_threads),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
