/* The lattice (stencil) step of a regular orb web against the general path:
 * it is recognised from the springs alone, gives bit-identical trajectories
 * for Euler, symplectic Euler and RK4 (the same per-spring arithmetic and the
 * same order of force sums on a web numbered like spn_scene_orb), hands over
 * to the general path when a spring breaks (by hand or at its break length)
 * with the trajectories still identical, follows stiffness and rest-length
 * changes, and gives the same bits on 1 and 2 threads; big webs' blocked
 * passes give the bits of single steps, in float64 and in float32; the
 * benchmark's traffic model counts what docs/physics-lattice.md says. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <spinneret/spinneret.h>

#include "physics/lattice_rows.h"    /* lat_gov, spn__lat_gov_pick, spn__lat_run */
#include "physics/world_internal.h" /* spn__lattice_step_bytes, _gov_prefer, _set_unblocked, _hold_passes */

/* The standard web with a disturbed state: random velocities (seeded), one
 * free particle pinned mid-web, viscous drag, so damping, slack tension-only
 * springs, fixed particles and drag all take part. */
static spn_world *disturbed_orb(spn_integrator integ, int rings, int radials, int threads, uint32_t parallel_min,
                                bool lattice)
{
    spn_world_def def = spn_world_def_default();
    def.integrator = integ;
    def.threads = threads;
    def.drag = 3;
    if (parallel_min) def.parallel_min = parallel_min;
    spn_orb_scene_def od = spn_orb_scene_def_default();
    od.rings = rings;
    od.radials = radials;
    spn_world *w;
    assert_int_equal(spn_scene_orb(&def, &od, &w), SPN_OK);
    spn_rng rng;
    spn_rng_seed(&rng, 7);
    for (uint32_t i = 0; i < spn_world_particle_count(w); i++)
        if (!spn_world_is_fixed(w, i))
            spn_world_set_velocity(w, i, spn_v3(0.05 * spn_rng_normal(&rng), 0.05 * spn_rng_normal(&rng),
                                                0.2 * spn_rng_normal(&rng)));
    spn_world_set_fixed(w, 1 + (uint32_t)radials + 3, true);
    spn_world_set_lattice(w, lattice);
    /* blocked passes on one thread wherever they apply, so that the tests
     * can count them (test_pass_governor lets the governor pick) */
    spn__lattice_hold_passes(w, true);
    assert_int_equal(spn_world_compile(w), SPN_OK);
    assert_string_equal(spn_world_step_path(w), lattice ? "lattice" : "general");
    return w;
}

/* The 40 x 50 web of most tests below, on the float32 step if asked
 * (spn_world_set_precision). */
static spn_world *web_2k(spn_integrator integ, int threads, uint32_t parallel_min, bool f32)
{
    spn_world *w = disturbed_orb(integ, 40, 50, threads, parallel_min, true);
    if (f32) spn_world_set_precision(w, SPN_PRECISION_FLOAT32);
    return w;
}

static void assert_same_state(const spn_world *a, const spn_world *b)
{
    const uint32_t n = spn_world_particle_count(a);
    assert_int_equal(n, spn_world_particle_count(b));
    assert_memory_equal(spn_world_positions(a), spn_world_positions(b), n * sizeof(spn_vec3));
    assert_memory_equal(spn_world_velocities(a), spn_world_velocities(b), n * sizeof(spn_vec3));
}

/* The same state and the same energy lost, bit for bit. */
static void assert_same_run(const spn_world *a, const spn_world *b)
{
    assert_same_state(a, b);
    spn_energy ea = spn_world_energy(a), eb = spn_world_energy(b);
    assert_memory_equal(&ea.dissipated, &eb.dissipated, sizeof(double));
}

/* The same change in a and b: spring s 10% shorter at rest, spring s + 1
 * twice as stiff (each from a's values). */
static void change_springs(spn_world *a, spn_world *b, uint32_t s)
{
    spn_spring_info info = spn_world_spring(a, s);
    spn_world_set_spring_rest(a, s, 0.9 * info.rest);
    spn_world_set_spring_rest(b, s, 0.9 * info.rest);
    spn_world_set_spring_stiffness(a, s + 1, 2 * info.k, info.kd);
    spn_world_set_spring_stiffness(b, s + 1, 2 * info.k, info.kd);
}

static double fastest(const spn_world *w)
{
    double top = 0;
    for (uint32_t i = 0; i < spn_world_particle_count(w); i++) top = fmax(top, spn_v3_len(spn_world_velocity(w, i)));
    return top;
}

/* Both paths, single steps (with the blow-up backup) then one advance call
 * (without it): the same bits, for each explicit integrator, with viscous
 * drag and without it (the lattice's RK4 force then skips the drag term). */
static void test_same_trajectory(void **state)
{
    (void)state;
    const spn_integrator integs[] = {SPN_INTEGRATOR_EULER, SPN_INTEGRATOR_SYMPLECTIC, SPN_INTEGRATOR_RK4};
    for (int q = 0; q < 6; q++) {
        const int k = q % 3;
        const bool still = q >= 3; /* disturbed_orb's drag taken off */
        spn_world *lat = disturbed_orb(integs[k], 9, 13, 1, 0, true);
        spn_world *gen = disturbed_orb(integs[k], 9, 13, 1, 0, false);
        if (still) spn_world_set_drag(lat, 0), spn_world_set_drag(gen, 0);
        const double dt = integs[k] == SPN_INTEGRATOR_EULER ? 2e-7 : 2e-6;
        for (int i = 0; i < 20; i++) {
            assert_int_equal(spn_world_step(lat, dt), SPN_OK);
            assert_int_equal(spn_world_step(gen, dt), SPN_OK);
        }
        assert_int_equal(spn_world_advance(lat, dt, 200), SPN_OK);
        assert_int_equal(spn_world_advance(gen, dt, 200), SPN_OK);
        assert_same_state(lat, gen);
        assert_string_equal(spn_world_step_path(lat), "lattice");
        /* the energy bookkeeping agrees to round-off too */
        spn_energy el = spn_world_energy(lat), eg = spn_world_energy(gen);
        assert_true(fabs(el.dissipated - eg.dissipated) <= 1e-9 * fabs(eg.dissipated));
        assert_true(eg.dissipated > 0);
        print_message("%-10s %s: lattice = general after 220 steps, fastest %.3g m/s\n", spn_integrator_name(integs[k]),
                      still ? "no drag" : "drag", fastest(lat));
        assert_true(fastest(lat) > 0.01);
        spn_world_destroy(lat);
        spn_world_destroy(gen);
    }
}

/* Gravity and drag, m g - (drag m) v, are one fused multiply-add in both
 * paths' explicit steps. On the web above the one rounding less is lost
 * in the step: the springs' forces are far larger, and v is far larger
 * than its change. Here the springs are a millionth as stiff, gravity has
 * three components and the drag is so strong (drag dt = 0.2) that the
 * particles fall near their terminal speed g / drag, where (drag m) v is
 * as large as m g and v changes by about itself in a step: each step's
 * velocity then carries the last bit of that sum. */
static void test_same_gravity_and_drag(void **state)
{
    (void)state;
    const spn_integrator integs[] = {SPN_INTEGRATOR_EULER, SPN_INTEGRATOR_SYMPLECTIC, SPN_INTEGRATOR_RK4};
    for (int k = 0; k < 3; k++) {
        spn_world *w[2];
        for (int p = 0; p < 2; p++) {
            w[p] = disturbed_orb(integs[k], 9, 13, 1, 0, p == 0);
            spn_world_set_gravity(w[p], spn_v3(0.7, -9.81, 0.4));
            spn_world_set_drag(w[p], 1e5);
            for (uint32_t s = 0; s < spn_world_spring_count(w[p]); s++) {
                const spn_spring_info info = spn_world_spring(w[p], s);
                spn_world_set_spring_stiffness(w[p], s, 1e-6 * info.k, 1e-6 * info.kd);
            }
            for (uint32_t i = 0; i < spn_world_particle_count(w[p]); i++)
                spn_world_set_velocity(w[p], i, spn_v3_scale(spn_world_velocity(w[p], i), 2e-3));
        }
        for (int i = 0; i < 50; i++) {
            assert_int_equal(spn_world_step(w[0], 2e-6), SPN_OK);
            assert_int_equal(spn_world_step(w[1], 2e-6), SPN_OK);
        }
        assert_string_equal(spn_world_step_path(w[0]), "lattice");
        assert_same_state(w[0], w[1]);
        spn_world_destroy(w[0]);
        spn_world_destroy(w[1]);
    }
}

/* Several bands (parallel_min small): 1 and 2 threads give the same bits,
 * and the same as the general path. */
static void test_bands_and_threads(void **state)
{
    (void)state;
    const spn_integrator integs[] = {SPN_INTEGRATOR_SYMPLECTIC, SPN_INTEGRATOR_RK4};
    for (int k = 0; k < 2; k++) {
        spn_world *one = disturbed_orb(integs[k], 40, 50, 1, 256, true);
        spn_world *two = disturbed_orb(integs[k], 40, 50, 2, 256, true);
        spn_world *gen = disturbed_orb(integs[k], 40, 50, 1, 256, false);
        for (int i = 0; i < 30; i++) {
            assert_int_equal(spn_world_step(one, 2e-6), SPN_OK);
            assert_int_equal(spn_world_step(two, 2e-6), SPN_OK);
            assert_int_equal(spn_world_step(gen, 2e-6), SPN_OK);
        }
        assert_same_state(one, two);
        assert_same_state(one, gen);
        spn_world_destroy(one);
        spn_world_destroy(two);
        spn_world_destroy(gen);
    }
}

/* Advance one (1 thread) and two (2 threads) by `steps` in one call each,
 * `blocked` of them in passes, and check them bit for bit against ref (which
 * the caller has stepped the same way without passes): state, energy books,
 * and that the web moved. */
static void assert_passes_match(spn_world *one, spn_world *two, const spn_world *ref, double dt, int steps,
                                int blocked)
{
    assert_int_equal(spn_world_advance(one, dt, steps), SPN_OK);
    assert_int_equal(spn_world_last_step(one).blocked, blocked);
    assert_int_equal(spn_world_advance(two, dt, steps), SPN_OK);
    assert_int_equal(spn_world_last_step(two).blocked, blocked);
    assert_same_run(one, ref);
    assert_same_run(two, ref);
    assert_true(fastest(one) > 0.01);
}

/* A step far too long on two threads: spn_world_advance's pass blows up,
 * the run is replayed, and the message and the state are those of single
 * steps (spn_world_step) up to the same step. */
static void assert_blowup_replayed(void)
{
    spn_world *blk = disturbed_orb(SPN_INTEGRATOR_SYMPLECTIC, 40, 50, 2, 256, true);
    spn_world *ref = disturbed_orb(SPN_INTEGRATOR_SYMPLECTIC, 40, 50, 2, 256, true);
    const double big = 6e-5;
    int failed_at = -1;
    for (int i = 0; i < 400 && failed_at < 0; i++)
        if (spn_world_step(ref, big) != SPN_OK) failed_at = i;
    assert_true(failed_at > 0);
    char want[512];
    snprintf(want, sizeof want, "%s", spn_last_error());
    assert_int_equal(spn_world_advance(blk, big, 400), SPN_ERR_UNSTABLE);
    assert_string_equal(spn_last_error(), want);
    assert_same_state(blk, ref);
    print_message("blow-up at step %d in both: %s\n", failed_at + 1, want);
    spn_world_destroy(blk);
    spn_world_destroy(ref);
}

/* Steps several to a pass over memory (spn_world_advance on a web of at
 * least def.parallel_min particles, lattice_block.c: four explicit steps or
 * the four stages of an RK4 step to a pass): the same bits as single steps, in the state and in the energy books, on 1 and 2 threads, and a
 * blow-up inside a pass found at the same step as without passes. */
static void test_blocked_passes(void **state)
{
    (void)state;
    const spn_integrator integs[] = {SPN_INTEGRATOR_EULER, SPN_INTEGRATOR_SYMPLECTIC, SPN_INTEGRATOR_RK4};
    for (int k = 0; k < 3; k++) {
        const double dt = integs[k] == SPN_INTEGRATOR_EULER ? 2e-7 : 2e-6;
        /* explicit: 7 passes of 4 steps, 1 single step; RK4: a pass a step */
        const int blocked = integs[k] == SPN_INTEGRATOR_RK4 ? 29 : 28;
        spn_world *one = disturbed_orb(integs[k], 40, 50, 1, 256, true);
        spn_world *two = disturbed_orb(integs[k], 40, 50, 2, 256, true);
        spn_world *ref = disturbed_orb(integs[k], 40, 50, 1, 256, true);
        for (int i = 0; i < 29; i++) assert_int_equal(spn_world_step(ref, dt), SPN_OK);
        assert_passes_match(one, two, ref, dt, 29, blocked);
        /* a spring changed between calls reaches the blocked passes */
        change_springs(one, ref, 1234);
        assert_int_equal(spn_world_advance(one, dt, 8), SPN_OK);
        assert_int_equal(spn_world_last_step(one).blocked, 8);
        for (int i = 0; i < 8; i++) assert_int_equal(spn_world_step(ref, dt), SPN_OK);
        assert_same_state(one, ref);
        spn_world_destroy(one);
        spn_world_destroy(two);
        spn_world_destroy(ref);
    }
    /* a step far too long: the pass blows up, the run is replayed and the
     * message names the same step as single steps give */
    assert_blowup_replayed();
}

/* A replayable advance on two threads keeps them as a team for the call
 * (lattice_team.c). With no patience its workers sleep on the condition
 * variable after every job and are woken for the next: the bits are still
 * those of single steps on one thread, explicit, RK4 and float32, through a
 * governor that switches between one thread and two, and a blow-up's
 * replay. (A lost wake-up would hang here.) */
static void test_team_asleep_between_jobs(void **state)
{
    (void)state;
    spn__lat_team_set_patience(0, 0);
    const spn_integrator integs[] = {SPN_INTEGRATOR_SYMPLECTIC, SPN_INTEGRATOR_RK4};
    for (int k = 0; k < 2; k++)
        for (int f32 = 0; f32 < 2; f32++) {
            spn_world *one = web_2k(integs[k], 1, 256, f32), *two = web_2k(integs[k], 2, 256, f32);
            spn_world *ref = web_2k(integs[k], 1, 256, f32);
            spn__lattice_set_unblocked(ref, true);
            const int blocked = integs[k] == SPN_INTEGRATOR_RK4 ? 29 : 28;
            assert_int_equal(spn_world_advance(ref, 2e-6, 29), SPN_OK);
            assert_passes_match(one, two, ref, 2e-6, 29, blocked);
            spn_world_destroy(one);
            spn_world_destroy(two);
            spn_world_destroy(ref);
        }
    /* the governor's choices, one thread and two, inside one team's calls */
    spn_world *two = disturbed_orb(SPN_INTEGRATOR_SYMPLECTIC, 40, 50, 2, 8192, true);
    spn_world *one = disturbed_orb(SPN_INTEGRATOR_SYMPLECTIC, 40, 50, 1, 8192, true);
    spn__lattice_set_unblocked(one, true);
    for (int call = 0; call < 4; call++) {
        assert_true(spn__lattice_gov_prefer(two, call % 2 == 0));
        assert_int_equal(spn_world_advance(two, 2e-6, 9), SPN_OK);
        assert_int_equal(spn_world_advance(one, 2e-6, 9), SPN_OK);
        assert_same_state(two, one);
    }
    spn_world_destroy(two);
    spn_world_destroy(one);
    /* a blow-up inside the team: replayed, the same step named */
    assert_blowup_replayed();
    spn__lat_team_set_patience(-1, -1);
}

/* What the jobs of spn__lat_run did: each share's runs of each phase, any
 * second-phase share that began before every first-phase share was done,
 * any thread number out of range. */
typedef struct {
    int shares, threads;
    atomic_int first_done, bad;
    atomic_int first[40], then[40];
    atomic_int covered[1000];
} job_log;

static void log_first(void *p, int s, int t)
{
    job_log *j = p;
    if (t < 0 || t >= j->threads) atomic_store(&j->bad, 1);
    atomic_fetch_add(&j->first[s], 1);
    atomic_fetch_add(&j->first_done, 1);
}

static void log_then(void *p, int s, int t)
{
    job_log *j = p;
    if (t < 0 || t >= j->threads || atomic_load(&j->first_done) != j->shares) atomic_store(&j->bad, 1);
    atomic_fetch_add(&j->then[s], 1);
}

static void log_range(void *p, size_t lo, size_t hi)
{
    job_log *j = p;
    for (size_t i = lo; i < hi; i++) atomic_fetch_add(&j->covered[i], 1);
}

/* Jobs of every shape on threads (the team's size, fewer, one) and loops of
 * spn__lat_for: each share of each phase once, the second phase after the
 * whole first, every index once. */
static void check_jobs(const spn_world *w, int threads)
{
    const int shares[] = {1, 2, 3, 5, 40};
    for (int k = 0; k < 5; k++)
        for (int with_then = 0; with_then < 2; with_then++) {
            job_log *j = calloc(1, sizeof *j);
            assert_non_null(j);
            j->shares = shares[k], j->threads = threads;
            spn__lat_run(w->lat, threads, shares[k], log_first, with_then ? log_then : NULL, j);
            assert_int_equal(atomic_load(&j->bad), 0);
            for (int s = 0; s < shares[k]; s++) {
                assert_int_equal(atomic_load(&j->first[s]), 1);
                assert_int_equal(atomic_load(&j->then[s]), with_then);
            }
            free(j);
        }
    const size_t counts[] = {0, 1, 7, 1000};
    for (int k = 0; k < 4; k++) {
        job_log *j = calloc(1, sizeof *j);
        assert_non_null(j);
        spn__lat_for(w->lat, threads, counts[k], log_range, j);
        for (size_t i = 0; i < 1000; i++) assert_int_equal(atomic_load(&j->covered[i]), i < counts[k]);
        free(j);
    }
}

static spn_status team_body(spn_world *w, void *ctx)
{
    (void)ctx;
    assert_int_equal(spn__lattice_team_size(w), 2);
    check_jobs(w, 2);
    check_jobs(w, 1);
    return SPN_ERR_INVALID; /* passed back */
}

/* spn__lat_run and spn__lat_for outside a team (an OpenMP region each, or
 * in order on one thread) and inside one, with the workers spinning and
 * with them asleep between jobs. */
static void test_team_jobs(void **state)
{
    (void)state;
    spn_world *w = disturbed_orb(SPN_INTEGRATOR_SYMPLECTIC, 9, 13, 2, 0, true);
    assert_int_equal(spn_world_advance(w, 2e-6, 2), SPN_OK); /* the lattice built */
    assert_non_null(w->lat);
    check_jobs(w, 2);
    check_jobs(w, 1);
    assert_int_equal(spn__lattice_team_size(w), 0);
    for (int patience = 0; patience < 2; patience++) {
        if (!patience) spn__lat_team_set_patience(0, 0);
        assert_int_equal(spn__lattice_team_call(w, 2, team_body, NULL), SPN_ERR_INVALID);
        spn__lat_team_set_patience(-1, -1);
    }
    assert_int_equal(spn__lattice_team_size(w), 0);
    spn_world_destroy(w);
}

/* The float64 RK4 pass in each of its versions (SPN_RK4_AVX2=0: the one
 * target_clones picks, AVX-512 where the processor has it; 1: AVX2 code,
 * where it has that; lattice_block.c): the bits of single steps, on 1 and
 * 2 threads. */
static void test_rk4_pass_versions(void **state)
{
    (void)state;
    const double dt = 2e-6;
    spn_world *ref = disturbed_orb(SPN_INTEGRATOR_RK4, 40, 50, 1, 256, true);
    for (int i = 0; i < 29; i++) assert_int_equal(spn_world_step(ref, dt), SPN_OK);
    const char *const version[2] = {"0", "1"};
    for (int v = 0; v < 2; v++) {
        assert_int_equal(setenv("SPN_RK4_AVX2", version[v], 1), 0);
        spn_world *one = disturbed_orb(SPN_INTEGRATOR_RK4, 40, 50, 1, 256, true);
        spn_world *two = disturbed_orb(SPN_INTEGRATOR_RK4, 40, 50, 2, 256, true);
        assert_passes_match(one, two, ref, dt, 29, 29);
        spn_world_destroy(one);
        spn_world_destroy(two);
    }
    assert_int_equal(unsetenv("SPN_RK4_AVX2"), 0);
    spn_world_destroy(ref);
}

/* The float32 step's blocked passes (lattice_block_t.h instantiated for
 * float): the bits of float32 single-step sweeps, in the state and in the
 * energy books, on 1 and 2 threads, across a rebase of the float32
 * displacements (every 64 steps) inside a call, and a blow-up inside a pass
 * replayed to the same step and message. Single float32 steps come from
 * spn_world_advance only (spn_world_step takes float64 ones), so the
 * reference is the same web at parallel_min 8192 on one thread, held to
 * single steps (spn__lattice_set_unblocked), with the same bands as at 256
 * (SPN_BLOCK particles: an eighth of either parallel_min and a quarter of
 * the web are below it), which fix the order of the energy sums. */
static void test_blocked_passes_float32(void **state)
{
    (void)state;
    const spn_integrator integs[] = {SPN_INTEGRATOR_EULER, SPN_INTEGRATOR_SYMPLECTIC, SPN_INTEGRATOR_RK4};
    for (int k = 0; k < 3; k++) {
        const double dt = integs[k] == SPN_INTEGRATOR_EULER ? 2e-7 : 2e-6;
        /* explicit: 17 passes of 4 steps (a rebase after the 16th), 1 single
         * step; RK4: a pass a step */
        const int blocked = integs[k] == SPN_INTEGRATOR_RK4 ? 69 : 68;
        spn_world *one = web_2k(integs[k], 1, 256, true);
        spn_world *two = web_2k(integs[k], 2, 256, true);
        spn_world *ref = web_2k(integs[k], 1, 8192, true);
        spn__lattice_set_unblocked(ref, true);
        assert_int_equal(spn_world_advance(ref, dt, 69), SPN_OK);
        assert_int_equal(spn_world_last_step(ref).blocked, 0);
        assert_passes_match(one, two, ref, dt, 69, blocked);
        /* a spring changed between calls reaches the float32 passes */
        change_springs(one, ref, 1234);
        assert_int_equal(spn_world_advance(one, dt, 8), SPN_OK);
        assert_int_equal(spn_world_last_step(one).blocked, 8);
        assert_int_equal(spn_world_advance(ref, dt, 8), SPN_OK);
        assert_same_state(one, ref);
        spn_world_destroy(one);
        spn_world_destroy(two);
        spn_world_destroy(ref);
    }
    /* a step far too long: the float32 pass blows up, the run is replayed
     * and ends as the unblocked run does, at the same step, with the same
     * message, in the same state */
    spn_world *blk = web_2k(SPN_INTEGRATOR_SYMPLECTIC, 2, 256, true);
    spn_world *ref = web_2k(SPN_INTEGRATOR_SYMPLECTIC, 1, 8192, true);
    spn__lattice_set_unblocked(ref, true);
    const double big = 5e-5; /* (float32 overflows sooner than float64: at step 10) */
    assert_int_equal(spn_world_advance(ref, big, 400), SPN_ERR_UNSTABLE);
    const uint64_t good = spn_world_step_count(ref);
    assert_true(good > 0 && good % 4 != 0); /* the failing step is inside a pass */
    char want[512];
    snprintf(want, sizeof want, "%s", spn_last_error());
    assert_int_equal(spn_world_advance(blk, big, 400), SPN_ERR_UNSTABLE);
    assert_string_equal(spn_last_error(), want);
    assert_int_equal(spn_world_step_count(blk), good);
    assert_same_state(blk, ref);
    print_message("float32 blow-up at step %llu in both: %s\n", (unsigned long long)good + 1, want);
    spn_world_destroy(blk);
    spn_world_destroy(ref);
}

/* The thread governor's choices (lattice.c) on made-up timings (ns per
 * particle and level, a unit 0.1 ms): three units of threads first, then
 * three of one thread, each figured by its fastest (the first ones are
 * cold), then the faster kept; the other tried 2 ms later over up to 8 units and given
 * up once it cannot win; a unit slowed by chance not switching, a stalled
 * one switching at once; each choice's wait doubling while its tries lose
 * (to 4 s) and halving when one wins. */
static void test_governor_choices(void **state)
{
    (void)state;
    lat_gov g;
    memset(&g, 0, sizeof g);
    double t = 100;
    const double cold[2][3] = {{9.0, 3.0, 3.5}, {60.0, 2.5, 2.0}};
    for (int m = 1; m >= 0; m--)
        for (int i = 0; i < 3; i++) {
            assert_int_equal(spn__lat_gov_pick(&g, t), m);
            spn__lat_gov_record(&g, cold[m][i], t += 1e-4);
        }
    assert_true(g.ns[0] == 3.0 && g.ns[1] == 2.0);
    for (int i = 0; i < 5; i++) { /* threads faster: kept, no try within 2 ms */
        assert_int_equal(spn__lat_gov_pick(&g, t), 1);
        spn__lat_gov_record(&g, 2.0, t += 1e-4);
    }
    assert_int_equal(g.kept, 1);
    t = g.next;
    for (int i = 0; i < 6; i++) { /* the try of one thread: 6 x 3 > 8 x 2, lost */
        assert_int_equal(spn__lat_gov_pick(&g, t), 0);
        spn__lat_gov_record(&g, 3.0, t += 1e-4);
    }
    assert_int_equal(g.try_units, 0);
    assert_true(g.wait[0] == 4e-3 && g.next == t + 4e-3);
    assert_int_equal(spn__lat_gov_pick(&g, t), 1);
    /* a unit ten times slower by chance does not switch; its mean comes back */
    spn__lat_gov_record(&g, 20.0, t += 1e-3);
    assert_int_equal(spn__lat_gov_pick(&g, t), 1);
    for (int i = 0; i < 30; i++) spn__lat_gov_record(&g, 2.0, t += 1e-5);
    assert_true(g.ns[1] < 2.1);
    /* the machine gets busy: one stalled unit on threads switches to one,
     * and threads are tried again 2 ms later */
    assert_int_equal(spn__lat_gov_pick(&g, t), 1);
    spn__lat_gov_record(&g, 400.0, t += 1e-4);
    assert_int_equal(g.kept, 0);
    assert_true(g.next == t + 2e-3);
    assert_int_equal(spn__lat_gov_pick(&g, t), 0);
    spn__lat_gov_record(&g, 3.0, t += 1e-4);
    /* tries of threads stall and stop at their first unit; their wait
     * doubles up to 4 s */
    double wait = g.wait[1];
    for (int i = 0; i < 20; i++) {
        assert_int_equal(spn__lat_gov_pick(&g, g.next - 1e-4), 0); /* not yet */
        t = g.next;
        assert_int_equal(spn__lat_gov_pick(&g, t), 1);
        spn__lat_gov_record(&g, 400.0, t += 1e-2);
        assert_true(g.wait[1] == (2 * wait < 4.0 ? 2 * wait : 4.0));
        wait = g.wait[1];
        assert_int_equal(g.try_units, 0);
        assert_int_equal(spn__lat_gov_pick(&g, t), 0);
        spn__lat_gov_record(&g, 3.0, t += 1e-4);
    }
    assert_true(g.wait[1] == 4.0);
    /* a try won by chance: threads kept, their wait halved; the stall that
     * follows sends them back for 2 s, not 2 ms */
    t = g.next;
    for (int i = 0; i < 8; i++) {
        assert_int_equal(spn__lat_gov_pick(&g, t), 1);
        spn__lat_gov_record(&g, 2.0, t += 1e-4);
    }
    assert_int_equal(g.kept, 1);
    assert_true(g.wait[1] == 2.0);
    assert_int_equal(spn__lat_gov_pick(&g, t), 1);
    spn__lat_gov_record(&g, 400.0, t += 1e-2);
    assert_int_equal(g.kept, 0);
    assert_true(g.next == t + 2.0);
    /* the machine quietens: the next try wins, and threads stay */
    t = g.next;
    for (int i = 0; i < 8; i++) {
        assert_int_equal(spn__lat_gov_pick(&g, t), 1);
        spn__lat_gov_record(&g, 2.0, t += 1e-4);
    }
    assert_int_equal(g.kept, 1);
    assert_true(g.wait[1] == 1.0);
    for (int i = 0; i < 10; i++) {
        assert_int_equal(spn__lat_gov_pick(&g, t), 1);
        spn__lat_gov_record(&g, 2.0, t += 1e-4);
    }
}

/* A web between parallel_min / 8 and parallel_min particles on two threads:
 * the governor's either choice, switched between calls, gives the bits of
 * single steps on one thread, in the state and the energy books; either
 * choice takes the steps in blocked passes. */
static void test_governor_same_bits(void **state)
{
    (void)state;
    const spn_integrator integs[] = {SPN_INTEGRATOR_SYMPLECTIC, SPN_INTEGRATOR_RK4};
    for (int k = 0; k < 2; k++) {
        /* 2,001 particles, parallel_min 8,192: threads from 1,024 */
        spn_world *two = disturbed_orb(integs[k], 40, 50, 2, 8192, true);
        spn_world *one = disturbed_orb(integs[k], 40, 50, 1, 8192, true);
        spn__lattice_set_unblocked(one, true);
        for (int call = 0; call < 6; call++) {
            const bool threads = call % 2 == 0;
            assert_true(spn__lattice_gov_prefer(two, threads));
            assert_int_equal(spn_world_advance(two, 2e-6, 8), SPN_OK);
            assert_int_equal(spn_world_last_step(two).blocked, 8);
            assert_int_equal(spn_world_advance(one, 2e-6, 8), SPN_OK);
            assert_int_equal(spn_world_last_step(one).blocked, 0);
            assert_same_run(two, one);
        }
        /* and as it chooses by itself */
        assert_int_equal(spn_world_advance(two, 2e-6, 40), SPN_OK);
        assert_int_equal(spn_world_advance(one, 2e-6, 40), SPN_OK);
        assert_same_state(two, one);
        assert_true(fastest(one) > 0.01);
        spn_world_destroy(two);
        spn_world_destroy(one);
    }
}

/* On one thread the pass governor (lattice.c, "One thread: passes or
 * single steps") times an explicit step's blocked passes against single
 * steps and keeps the faster. Its first unit is a pass and its second a
 * single step, so a first call takes some steps each way; whatever it
 * picks in the calls after, the bits are those of single steps, in the
 * state and the energy books, float64 and float32. RK4 takes every step it
 * can in passes, and so does a web the thread governor keeps on one
 * thread. */
static void test_pass_governor(void **state)
{
    (void)state;
    const spn_integrator integs[] = {SPN_INTEGRATOR_SYMPLECTIC, SPN_INTEGRATOR_RK4};
    for (int k = 0; k < 2; k++)
        for (int f32 = 0; f32 < 2; f32++) {
            spn_world *one = web_2k(integs[k], 1, 256, f32), *ref = web_2k(integs[k], 1, 256, f32);
            spn__lattice_hold_passes(one, false);
            spn__lattice_set_unblocked(ref, true);
            for (int call = 0; call < 4; call++) {
                assert_int_equal(spn_world_advance(one, 2e-6, 28), SPN_OK);
                const int blocked = spn_world_last_step(one).blocked;
                if (integs[k] == SPN_INTEGRATOR_RK4) {
                    assert_int_equal(blocked, 28);
                } else if (call == 0) {
                    /* the first pass (4 steps), then a single step: 28 in
                     * passes only if that were skipped */
                    assert_true(blocked >= 4);
                    assert_true(blocked <= 27);
                }
                assert_int_equal(spn_world_advance(ref, 2e-6, 28), SPN_OK);
                assert_int_equal(spn_world_last_step(ref).blocked, 0);
                assert_same_run(one, ref);
            }
            assert_true(fastest(one) > 0.01);
            spn_world_destroy(one);
            spn_world_destroy(ref);
        }
    /* where the thread governor puts a unit on one thread, it stays a pass */
    spn_world *two = disturbed_orb(SPN_INTEGRATOR_SYMPLECTIC, 40, 50, 2, 8192, true);
    spn__lattice_hold_passes(two, false);
    assert_true(spn__lattice_gov_prefer(two, false));
    for (int call = 0; call < 2; call++) {
        assert_int_equal(spn_world_advance(two, 2e-6, 28), SPN_OK);
        assert_int_equal(spn_world_last_step(two).blocked, 28);
    }
    spn_world_destroy(two);
}

/* Where the bands of a blocked pass on two threads go (lat_split: share 0
 * held to 2, 3, 5 or 6 of the web's 8 bands, then left to follow the
 * threads' speeds) changes no bit of the trajectory or of the energy
 * books: against one thread, explicit and RK4, float64 and float32. */
static void test_split_same_bits(void **state)
{
    (void)state;
    const spn_integrator integs[] = {SPN_INTEGRATOR_SYMPLECTIC, SPN_INTEGRATOR_RK4};
    const int holds[] = {2, 3, 5, 6, -1};
    for (int k = 0; k < 4; k++) {
        /* 4,001 particles, parallel_min 8,192: threads from 1,024, and
         * eight bands of 10 rings (a share keeps 16 rows: 2 to 6 bands) */
        spn_world *two = disturbed_orb(integs[k % 2], 80, 50, 2, 8192, true);
        spn_world *one = disturbed_orb(integs[k % 2], 80, 50, 1, 8192, true);
        if (k >= 2) {
            spn_world_set_precision(two, SPN_PRECISION_FLOAT32);
            spn_world_set_precision(one, SPN_PRECISION_FLOAT32);
        }
        assert_true(spn__lattice_gov_prefer(two, true));
        for (int h = 0; h < 5; h++) {
            if (h) {
                /* a particle of the rows the shares sent each other at the end
                 * of the last call moved by hand: the next call's first pass
                 * (on that split) takes its ghost rows from the state again */
                uint32_t R0, R1;
                spn__lattice_split_rows(two->lat, 1, &R0, &R1);
                const uint32_t p = 1 + R0 * 50 + 7;
                const spn_vec3 v = spn_v3_add(spn_world_velocity(one, p), spn_v3(0, 0, 0.01));
                spn_world_set_velocity(two, p, v);
                spn_world_set_velocity(one, p, v);
            }
            spn__lattice_split_hold(two, holds[h]);
            assert_int_equal(spn_world_advance(two, 2e-6, 24), SPN_OK);
            assert_int_equal(spn_world_last_step(two).blocked, 24);
            assert_int_equal(two->lat->nbands, 8);
            if (holds[h] >= 0) assert_int_equal(two->lat->split.first[1], holds[h]);
            assert_int_equal(spn_world_advance(one, 2e-6, 24), SPN_OK);
            assert_same_run(two, one);
        }
        assert_true(fastest(one) > 0.01);
        spn_world_destroy(two);
        spn_world_destroy(one);
    }
}

/* The split's rule (spn__lattice_split_update) on made-up times: shares
 * that run alike keep their even split, through a pass that one of them
 * lost to a preempted core; a share whose rows take half as long again
 * gives up bands until the two parts take about as long, and takes them
 * back when the two run alike again. */
static void run_split(spn__lattice *L, double per_row0, double per_row1, int passes)
{
    for (int p = 0; p < passes; p++) {
        uint32_t R0, R1;
        for (int t = 0; t < 2; t++) {
            spn__lattice_split_rows(L, t, &R0, &R1);
            L->split.took[t].ns = (t ? per_row1 : per_row0) * (R1 - R0);
        }
        spn__lattice_split_update(L);
    }
}

static void test_split_follows_speed(void **state)
{
    (void)state;
    spn__lattice L;
    memset(&L, 0, sizeof L);
    L.rings = 80, L.nbands = 8, L.split.hold = -1;
    assert_true(spn__lattice_split_ready(&L, 2));
    assert_int_equal(L.split.first[0], 0);
    assert_int_equal(L.split.first[1], 4);
    assert_int_equal(L.split.first[2], 8);
    run_split(&L, 1000, 1000, 20);
    assert_int_equal(L.split.first[1], 4);
    run_split(&L, 1000, 10000, 1); /* one slow pass */
    assert_int_equal(L.split.first[1], 4);
    run_split(&L, 1000, 1000, 20);
    assert_int_equal(L.split.first[1], 4);
    /* share 1 half as slow again: its 40 rows take 60,000 against share
     * 0's 40,000; at band 5 its 30 take 45,000, share 0's 50 50,000 */
    run_split(&L, 1000, 1500, 40);
    assert_int_equal(L.split.first[1], 5);
    uint32_t R0, R1;
    spn__lattice_split_rows(&L, 1, &R0, &R1);
    assert_int_equal(R0, 50);
    assert_int_equal(R1, 80);
    run_split(&L, 1000, 1000, 40);
    assert_int_equal(L.split.first[1], 4);
    /* never below a share's 16 rows: share 0 ten times as slow keeps 2 bands */
    run_split(&L, 10000, 1000, 60);
    assert_int_equal(L.split.first[1], 2);
    /* the split starts again even when the bands change */
    L.nbands = 4;
    assert_true(spn__lattice_split_ready(&L, 2));
    assert_int_equal(L.split.first[1], 2);
    free(L.split.first), free(L.split.rate), free(L.split.took);
}

/* Changing a spring keeps the lattice in step; breaking one hands over to the
 * general path, and the trajectories stay identical through both. */
static void test_changes_and_break(void **state)
{
    (void)state;
    spn_world *lat = disturbed_orb(SPN_INTEGRATOR_SYMPLECTIC, 9, 13, 1, 0, true);
    spn_world *gen = disturbed_orb(SPN_INTEGRATOR_SYMPLECTIC, 9, 13, 1, 0, false);
    assert_int_equal(spn_world_advance(lat, 2e-6, 50), SPN_OK);
    assert_int_equal(spn_world_advance(gen, 2e-6, 50), SPN_OK);
    const uint32_t s = 40;
    change_springs(lat, gen, s);
    assert_string_equal(spn_world_step_path(lat), "lattice");
    assert_int_equal(spn_world_advance(lat, 2e-6, 50), SPN_OK);
    assert_int_equal(spn_world_advance(gen, 2e-6, 50), SPN_OK);
    assert_same_state(lat, gen);
    spn_world_break_spring(lat, s);
    spn_world_break_spring(gen, s);
    assert_string_equal(spn_world_step_path(lat), "general");
    assert_int_equal(spn_world_advance(lat, 2e-6, 50), SPN_OK);
    assert_int_equal(spn_world_advance(gen, 2e-6, 50), SPN_OK);
    assert_same_state(lat, gen);
    spn_world_destroy(lat);
    spn_world_destroy(gen);
}

/* A hub + rings x radials web built by hand (rings added before radials, a
 * break length on one radial, no gravity but an outward pull through the
 * initial velocities): recognised from its springs, stepped on the lattice
 * until the radial snaps at its break length, then on the general path. */
static spn_world *hand_web(bool lattice)
{
    const int rings = 4, radials = 6;
    spn_world_def def = spn_world_def_default();
    def.gravity = spn_v3(0, 0, 0);
    def.threads = 1;
    spn_world *w = spn_world_create(&def);
    spn_particle_def p = spn_particle_def_default();
    p.mass = 1e-3;
    p.velocity = spn_v3(0, 0, 3); /* the hub flies out of the plane */
    assert_int_equal(spn_world_add_particle(w, &p, NULL), SPN_OK);
    p.velocity = spn_v3(0, 0, 0);
    for (int j = 0; j < rings; j++)
        for (int i = 0; i < radials; i++) {
            double a = 2 * SPN_PI * i / radials, r = 0.1 * (j + 1);
            p.position = spn_v3(r * cos(a), r * sin(a), 0);
            p.fixed = j == rings - 1;
            assert_int_equal(spn_world_add_particle(w, &p, NULL), SPN_OK);
        }
    spn_spring_def s = spn_spring_def_default();
    s.k = 50;
    s.kd = 0.01;
    for (int j = 0; j < rings; j++)
        for (int i = 0; i < radials; i++) {
            s.a = 1u + (uint32_t)(j * radials + i);
            s.b = 1u + (uint32_t)(j * radials + (i + 1) % radials);
            assert_int_equal(spn_world_add_spring(w, &s, NULL), SPN_OK);
        }
    for (int i = 0; i < radials; i++)
        for (int j = 0; j < rings; j++) {
            s.a = j ? 1u + (uint32_t)((j - 1) * radials + i) : 0;
            s.b = 1u + (uint32_t)(j * radials + i);
            s.break_max = i == 2 && j == 0 ? 0.103 : INFINITY;
            assert_int_equal(spn_world_add_spring(w, &s, NULL), SPN_OK);
        }
    spn_world_set_lattice(w, lattice);
    assert_int_equal(spn_world_compile(w), SPN_OK);
    return w;
}

static void test_hand_built_and_breakage(void **state)
{
    (void)state;
    spn_world *lat = hand_web(true), *gen = hand_web(false);
    assert_string_equal(spn_world_step_path(lat), "lattice");
    int breaks = 0, lattice_steps = 0;
    for (int i = 0; i < 400; i++) {
        lattice_steps += strcmp(spn_world_step_path(lat), "lattice") == 0;
        assert_int_equal(spn_world_step(lat, 1e-4), SPN_OK);
        assert_int_equal(spn_world_step(gen, 1e-4), SPN_OK);
        breaks += spn_world_last_step(lat).breaks;
        assert_int_equal(spn_world_last_step(lat).breaks, spn_world_last_step(gen).breaks);
    }
    print_message("hand-built web: %d lattice steps, then general; %d break\n", lattice_steps, breaks);
    assert_int_equal(breaks, 1);
    assert_true(lattice_steps > 0 && lattice_steps < 400);
    assert_string_equal(spn_world_step_path(lat), "general");
    /* Same web, same steps: the same bits on both sides of the break (the
     * numbering differs from spn_scene_orb's spring order only in which
     * springs are added first, which the lattice sums do not follow: so
     * round-off apart, not bit-identical). */
    double worst = 0;
    for (uint32_t i = 0; i < spn_world_particle_count(lat); i++)
        worst = fmax(worst, spn_v3_len(spn_v3_sub(spn_world_position(lat, i), spn_world_position(gen, i))));
    print_message("largest position difference %.3g m\n", worst);
    assert_true(worst < 1e-12);
    spn_world_destroy(lat);
    spn_world_destroy(gen);
}

/* Not a lattice: an extra spring, a chain, a force callback. */
static void poke(void *user, const spn_world *w, double t, const spn_vec3 *x, const spn_vec3 *v, spn_vec3 *f)
{
    (void)user, (void)w, (void)t, (void)x, (void)v, (void)f;
}

static void test_not_a_lattice(void **state)
{
    (void)state;
    spn_world_def def = spn_world_def_default();
    spn_world *w;
    assert_int_equal(spn_scene_orb(&def, NULL, &w), SPN_OK);
    assert_int_equal(spn_world_compile(w), SPN_OK);
    assert_string_equal(spn_world_step_path(w), "lattice");
    spn_world_set_force_callback(w, poke, NULL);
    assert_string_equal(spn_world_step_path(w), "general");
    spn_world_set_force_callback(w, NULL, NULL);
    spn_world_set_integrator(w, SPN_INTEGRATOR_IMPLICIT);
    assert_string_equal(spn_world_step_path(w), "general");
    spn_world_set_integrator(w, SPN_INTEGRATOR_RK4);
    assert_string_equal(spn_world_step_path(w), "lattice");
    spn_spring_def s = spn_spring_def_default();
    s.a = 1, s.b = 30;
    assert_int_equal(spn_world_add_spring(w, &s, NULL), SPN_OK);
    assert_int_equal(spn_world_compile(w), SPN_OK);
    assert_string_equal(spn_world_step_path(w), "general");
    spn_world_destroy(w);
    assert_int_equal(spn_scene_chain(&def, spn_v3(0, 0, 0), spn_v3(1, 0, 0), 20, 1, 1e-3, 100, 0, &w), SPN_OK);
    assert_int_equal(spn_world_compile(w), SPN_OK);
    assert_string_equal(spn_world_step_path(w), "general");
    spn_world_destroy(w);
}

/* spn__lattice_step_bytes on a 4 x 8 web (33 particles, 32 slots of each
 * kind), counted by hand from its definition: a pass reads the state (6
 * values a particle), the masses (2) and the slots (k, kd, rest of both
 * kinds: 6 a slot; float32 also 6 reference differences) and writes the
 * state; a blocked pass takes up to 4 explicit steps or one RK4 step; an RK4
 * step taken stage by stage moves 17 states and reads masses and slots 4
 * times. */
static void test_traffic_model(void **state)
{
    (void)state;
    spn_world_def def = spn_world_def_default();
    def.integrator = SPN_INTEGRATOR_SYMPLECTIC;
    spn_orb_scene_def od = spn_orb_scene_def_default();
    od.rings = 4;
    od.radials = 8;
    spn_world *w;
    assert_int_equal(spn_scene_orb(&def, &od, &w), SPN_OK);
    assert_int_equal(spn_world_compile(w), SPN_OK);
    assert_string_equal(spn_world_step_path(w), "lattice");
    const double st = 6 * 33 * 8, fixed = (2 * 33 + 6 * 32) * 8, pass = fixed + 2 * st; /* 1584, 2064, 5232 */
    assert_true(spn__lattice_step_bytes(w, 10, 0) == pass);
    assert_true(spn__lattice_step_bytes(w, 10, 8) == (2 * pass + 2 * pass) / 10); /* 8 steps in 2 passes */
    assert_true(spn__lattice_step_bytes(w, 3, 3) == pass / 3);                   /* a pass of 3 */
    assert_true(spn__lattice_step_bytes(w, 10, 11) == 0);                         /* not a count */
    spn_world_set_integrator(w, SPN_INTEGRATOR_RK4);
    assert_true(spn__lattice_step_bytes(w, 2, 0) == 4 * fixed + 17 * st);
    assert_true(spn__lattice_step_bytes(w, 2, 2) == pass);
    spn_world_set_precision(w, SPN_PRECISION_FLOAT32);
    assert_true(spn__lattice_step_bytes(w, 1, 1) == (2 * 33 + 12 * 32) * 4 + 2 * 6 * 33 * 4);
    spn_world_set_lattice(w, false);
    assert_true(spn__lattice_step_bytes(w, 1, 0) == 0);
    spn_world_destroy(w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_same_trajectory),   cmocka_unit_test(test_same_gravity_and_drag),
        cmocka_unit_test(test_bands_and_threads), cmocka_unit_test(test_blocked_passes),
        cmocka_unit_test(test_team_jobs),         cmocka_unit_test(test_team_asleep_between_jobs),
        cmocka_unit_test(test_rk4_pass_versions), cmocka_unit_test(test_blocked_passes_float32),
        cmocka_unit_test(test_governor_choices),  cmocka_unit_test(test_governor_same_bits),
        cmocka_unit_test(test_pass_governor),
        cmocka_unit_test(test_split_same_bits),   cmocka_unit_test(test_split_follows_speed),
        cmocka_unit_test(test_changes_and_break), cmocka_unit_test(test_hand_built_and_breakage),
        cmocka_unit_test(test_not_a_lattice),     cmocka_unit_test(test_traffic_model),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
