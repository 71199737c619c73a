/* The implicit step with the multigrid preconditioner (implicit_mg.c):
 * 1. it solves the same system as block Jacobi: after steps of a 2,501-particle
 *    web in a breeze, velocities agree to what the CG tolerance allows, while
 *    CG needs a fraction of block Jacobi's iterations;
 * 2. the same with a prey particle held by contacts, and after a spring breaks
 *    between steps (the hierarchy rebuilt for the new spring set);
 * 3. 1 vs 2 threads give bit-identical states;
 * 4. preconditioners the step does not have are refused, naming the choices;
 * 5. auto at short steps on a big web: the cyclic preconditioner on a rings
 *    x radials web; on one that is no lattice block Jacobi (bit for bit)
 *    until a step takes it over a hundred iterations, then, that step
 *    included, (up to SPN__IMPLICIT_DIRECT_MAX particles) the factor of a
 *    step's matrix;
 *    the same on a small web (1,201 particles); a solve on the cyclic
 *    preconditioner past a hundred iterations is not handed over (auto's
 *    steps are the cyclic one's, bit for bit);
 * 6. that factor: kept while its steps cost less than their average since it
 *    was made; after one is outrun within a step, made at the start of the
 *    next steps; made again at a change of step; the same bits on one
 *    thread and two;
 * 7. a change of preconditioner mid-run takes effect at the next step;
 * 8. that factor refused (forced by spn__imp_mg_refuse: with valid inputs
 *    the matrix is positive definite, and only round-off could make it
 *    fail): in the middle of a solve block Jacobi finishes it and the next
 *    step factorises again; at the start of a step after a refusal
 *    mid-solve, or in the first step (its first factorisation), the factor
 *    is dropped and the V-cycle takes over; the steps agree with block
 *    Jacobi's;
 * 9. the fallbacks after it (forced by spn__imp_mg_refuse_setup): the cyclic
 *    preconditioner refused, the V-cycle's steps; the V-cycle refused,
 *    block Jacobi's; both, or the factor and the V-cycle, block Jacobi's;
 *    each bit for bit the steps of the one asked for from the same state. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdlib.h>
#include <string.h>

#include "physics/world_internal.h"
#include "physics_util.h"

enum { PLAIN, CONTACT, BREAK };

/* A 0.2 g body at velocity v pressing on the middle of spring `s` (a contact). */
static void hold_body(spn_world *w, uint32_t s, spn_vec3 v)
{
    spn_spring_info sp = spn_world_spring(w, s);
    spn_vec3 mid = spn_v3_scale(spn_v3_add(spn_world_position(w, sp.a), spn_world_position(w, sp.b)), 0.5);
    spn_particle_def p = spn_particle_def_default();
    p.mass = 2e-4;
    p.position = spn_v3_add(mid, spn_v3(0, 0, -1e-4));
    uint32_t id;
    assert_int_equal(spn_world_add_particle(w, &p, &id), SPN_OK);
    spn_world_set_velocity(w, id, v);
    spn_contact c = {id, sp.a, sp.b, 0.5, spn_v3(0, 0, -1), 5, 1e-5, false, false};
    assert_int_equal(spn_world_set_contacts(w, &c, 1), SPN_OK);
}

static spn_world *make(spn_precond pc, int threads, int what)
{
    spn_world *w = util_breezy_orb(SPN_INTEGRATOR_IMPLICIT, threads);
    assert_non_null(w);
    assert_int_equal(spn_world_set_implicit_preconditioner(w, pc), SPN_OK);
    assert_int_equal(spn_world_set_solver_tolerance(w, 1e-10, 1000), SPN_OK);
    if (what == CONTACT) hold_body(w, 1200, spn_v3(0, 0, 1));
    return w;
}

/* Steps at dt 0.05 s; returns the state (positions, velocities) and the CG iterations. */
static spn_vec3 *run(spn_precond pc, int threads, int what, long *cg)
{
    spn_world *w = make(pc, threads, what);
    *cg = 0;
    for (int i = 0; i < 4; i++) {
        if (what == BREAK && i == 2) spn_world_break_spring(w, 1200);
        assert_int_equal(spn_world_step(w, 0.05), SPN_OK);
        *cg += spn_world_last_step(w).cg_iterations;
    }
    return util_take_state(w);
}

/* The largest velocity difference between two states of n particles (as
 * util_take_state lays them out), and b's largest speed into *vmax. */
static double velocity_gap(const spn_vec3 *a, const spn_vec3 *b, uint32_t n, double *vmax)
{
    double dv = 0;
    *vmax = 0;
    for (uint32_t i = n; i < 2 * n; i++) {
        dv = fmax(dv, spn_v3_len(spn_v3_sub(a[i], b[i])));
        *vmax = fmax(*vmax, spn_v3_len(b[i]));
    }
    return dv;
}

static void compare(spn_precond pc, int what)
{
    long cg_mg, cg_bj;
    spn_vec3 *a = run(pc, 1, what, &cg_mg), *b = run(SPN_PRECOND_BLOCK_JACOBI, 1, what, &cg_bj);
    const uint32_t n = spn_orb_scene_particles(50, 50) + (what == CONTACT);
    double vmax;
    const double dv = velocity_gap(a, b, n, &vmax);
    print_message("case %d: CG %ld (%s) vs %ld (block Jacobi); max |dv| %.2e of max |v| %.2e\n", what, cg_mg,
                  spn_precond_name(pc), cg_bj, dv, vmax);
    assert_true(vmax > 0);
    /* CG stops at relative residual 1e-10; the error is at most that times
     * the condition number of A (about 1e5 here, h^2 k / m over the mass
     * ratios), so 1e-6 of the velocity scale is a wide margin that a wrong
     * matrix in the preconditioner would not meet (CG would not converge) */
    assert_true(dv <= 1e-6 * vmax);
    assert_true(cg_mg * 4 < cg_bj);
    free(a), free(b);
}

static void test_matches_block_jacobi(void **state) { (void)state, compare(SPN_PRECOND_MULTIGRID, PLAIN); }
static void test_contact(void **state) { (void)state, compare(SPN_PRECOND_MULTIGRID, CONTACT); }
static void test_break(void **state) { (void)state, compare(SPN_PRECOND_MULTIGRID, BREAK); }
/* The cyclic preconditioner on the same rings x radials web: in a breeze, with
 * a prey held by contacts (a particle past the lattice), and after a break
 * (no longer a lattice: the multigrid takes over) */
static void test_cyclic_matches_block_jacobi(void **state)
{
    (void)state;
    compare(SPN_PRECOND_CYCLIC, PLAIN);
    compare(SPN_PRECOND_CYCLIC, CONTACT);
    compare(SPN_PRECOND_CYCLIC, BREAK);
}

/* auto at short steps on a web of 5,001 particles. A rings x radials web
 * takes the cyclic preconditioner (block Jacobi needs some 175 iterations a
 * step there at dt 1e-4 s). The same web with a spring broken is no
 * lattice: at dt 1e-5 s, where block Jacobi needs a few tens of iterations,
 * it keeps block Jacobi, bit for bit; at 1e-4 s its first step is block
 * Jacobi's until that takes more than a hundred iterations
 * (SPN__IMPLICIT_BJ_MAX), and the factor's from there on, the steps after
 * it too (a web this small is factorised instead of given the V-cycle).
 * `broken`: break spring 1200 first; `steps` steps of dt. */
/* A rings x radials web on the implicit solver, flat, CG to 1e-10
 * (threads: spn_world_def.threads). */
static spn_world *orb_web(int rings, int radials, int threads)
{
    spn_world_def wd = spn_world_def_default();
    wd.integrator = SPN_INTEGRATOR_IMPLICIT;
    wd.threads = threads;
    spn_orb_scene_def od = spn_orb_scene_def_default();
    od.rings = rings, od.radials = radials;
    spn_world *w = NULL;
    assert_int_equal(spn_scene_orb(&wd, &od, &w), SPN_OK);
    assert_int_equal(spn_world_set_solver_tolerance(w, 1e-10, 1000), SPN_OK);
    return w;
}

/* web_steps below; `held`: a 0.2 g body pressing on spring 600 by a contact. */
static spn_vec3 *web_steps_held(int rings, int radials, spn_precond pc, bool broken, bool held, double dt, int steps,
                                long *cg)
{
    spn_world *w = orb_web(rings, radials, 0);
    assert_int_equal(spn_world_set_implicit_preconditioner(w, pc), SPN_OK);
    if (broken) spn_world_break_spring(w, 1200);
    if (held) hold_body(w, 600, spn_v3(0, 0, 0));
    *cg = 0;
    for (int i = 0; i < steps; i++) {
        assert_int_equal(spn_world_step(w, dt), SPN_OK);
        *cg += spn_world_last_step(w).cg_iterations;
    }
    return util_take_state(w);
}

static spn_vec3 *web_steps(int rings, int radials, spn_precond pc, bool broken, double dt, int steps, long *cg)
{
    return web_steps_held(rings, radials, pc, broken, false, dt, steps, cg);
}

static spn_vec3 *short_steps(spn_precond pc, bool broken, double dt, int steps, long *cg)
{
    return web_steps(40, 125, pc, broken, dt, steps, cg);
}

/* A first step's CG iterations: auto's (cg_auto) block Jacobi's until
 * past SPN__IMPLICIT_BJ_MAX, then the fresh factor's or V-cycle's few,
 * against block Jacobi's own (cg_bj) on a step that takes it far past. */
static void expect_switched(long cg_auto, long cg_bj)
{
    assert_true(cg_bj > SPN__IMPLICIT_BJ_MAX + SPN__IMPLICIT_FACTOR_PRICE);
    assert_true(cg_auto > SPN__IMPLICIT_BJ_MAX && cg_auto <= SPN__IMPLICIT_BJ_MAX + SPN__IMPLICIT_FACTOR_PRICE);
}

static void test_auto_at_short_steps(void **state)
{
    (void)state;
    const uint32_t n = spn_orb_scene_particles(40, 125);
    long cg_auto, cg_bj;
    spn_vec3 *a = short_steps(SPN_PRECOND_AUTO, false, 1e-4, 3, &cg_auto),
             *b = short_steps(SPN_PRECOND_BLOCK_JACOBI, false, 1e-4, 3, &cg_bj);
    double vmax;
    double dv = velocity_gap(a, b, n, &vmax);
    print_message("lattice, dt 1e-4: CG %ld (auto) vs %ld (block Jacobi); max |dv| %.2e of %.2e\n", cg_auto, cg_bj, dv,
                  vmax);
    assert_true(vmax > 0);
    assert_true(dv <= 1e-6 * vmax);
    assert_true(cg_auto * 10 < cg_bj);
    free(a), free(b);
    /* no lattice, a step block Jacobi takes in few iterations: block Jacobi */
    a = short_steps(SPN_PRECOND_AUTO, true, 1e-5, 3, &cg_auto), b = short_steps(SPN_PRECOND_BLOCK_JACOBI, true, 1e-5, 3, &cg_bj);
    print_message("no lattice, dt 1e-5: CG %ld (auto) vs %ld (block Jacobi)\n", cg_auto, cg_bj);
    assert_true(cg_bj <= 3 * SPN__IMPLICIT_BJ_MAX);
    assert_int_equal(cg_auto, cg_bj);
    assert_memory_equal(a, b, 2 * n * sizeof *a);
    free(a), free(b);
    /* no lattice, a step that takes block Jacobi over a hundred: block
     * Jacobi's until then, then the factor */
    a = short_steps(SPN_PRECOND_AUTO, true, 1e-4, 1, &cg_auto), b = short_steps(SPN_PRECOND_BLOCK_JACOBI, true, 1e-4, 1, &cg_bj);
    expect_switched(cg_auto, cg_bj);
    dv = velocity_gap(a, b, n, &vmax);
    assert_true(dv <= 1e-6 * vmax);
    free(a), free(b);
    const long first_auto = cg_auto, first_bj = cg_bj;
    a = short_steps(SPN_PRECOND_AUTO, true, 1e-4, 3, &cg_auto), b = short_steps(SPN_PRECOND_BLOCK_JACOBI, true, 1e-4, 3, &cg_bj);
    dv = velocity_gap(a, b, n, &vmax);
    print_message("no lattice, dt 1e-4: CG %ld (auto; its first step %ld) vs %ld (block Jacobi; %ld); max |dv| %.2e of "
                  "%.2e\n",
                  cg_auto, first_auto, cg_bj, first_bj, dv, vmax);
    assert_true(dv <= 1e-6 * vmax);
    assert_true((cg_auto - first_auto) * 4 < cg_bj - first_bj); /* steps 2 and 3 */
    free(a), free(b);
}

/* w refused as `which` says (spn__imp_mg_refuse_setup; 0: nothing) and its
 * clone given preconditioner pc take `steps` steps of dt: the same
 * iterations and bits at every step (the refused preconditioners fall back
 * in the order cyclic, V-cycle, block Jacobi, and each fallback is what
 * asking for it gives). Returns the most CG iterations a step took. */
static long same_steps(spn_world *w, unsigned which, spn_precond pc, double dt, int steps)
{
    spn_world *ref = spn_world_clone(w);
    assert_non_null(ref);
    assert_int_equal(spn_world_set_implicit_preconditioner(ref, pc), SPN_OK);
    spn__imp_mg_refuse_setup(w, which);
    const uint32_t n = spn_world_particle_count(w);
    long cg = 0, longest = 0;
    for (int i = 0; i < steps; i++) {
        assert_int_equal(spn_world_step(w, dt), SPN_OK);
        assert_int_equal(spn_world_step(ref, dt), SPN_OK);
        assert_int_equal(spn_world_last_step(w).cg_iterations, spn_world_last_step(ref).cg_iterations);
        assert_memory_equal(spn_world_positions(w), spn_world_positions(ref), n * sizeof(spn_vec3));
        assert_memory_equal(spn_world_velocities(w), spn_world_velocities(ref), n * sizeof(spn_vec3));
        cg += spn_world_last_step(w).cg_iterations;
        if (spn_world_last_step(w).cg_iterations > longest) longest = spn_world_last_step(w).cg_iterations;
    }
    print_message("refused %u: %d steps as %s's, CG %ld, at most %ld a step\n", which, steps, spn_precond_name(pc), cg,
                  longest);
    spn_world_destroy(w), spn_world_destroy(ref);
    return longest;
}

/* auto's solve on a preconditioner past SPN__IMPLICIT_BJ_MAX iterations is
 * left alone: the block-Jacobi hand-over at the 101st iteration is for a
 * solve on block Jacobi only. The 5,001-particle rings x radials web with
 * its springs in one quadrant three times as stiff (out of balance: the
 * cyclic preconditioner, exact for the rings' average, needs over a
 * hundred iterations by the fifth step of 1e-4 s) takes the same CG
 * counts and bits under auto as under the cyclic preconditioner asked
 * for. Until 8c82767, auto restarted such a solve at its 101st iteration
 * (150 and 178 iterations at the last two steps against 144 and 170). */
static void test_auto_long_solve_on_a_preconditioner(void **state)
{
    (void)state;
    spn_world *w = orb_web(40, 125, 0);
    for (uint32_t s = 0, ns = spn_world_spring_count(w); s < ns; s++) {
        const spn_spring_info sp = spn_world_spring(w, s);
        const spn_vec3 a = spn_world_position(w, sp.a);
        if (a.x > 0 && a.y > 0) assert_int_equal(spn_world_set_spring_stiffness(w, s, 3 * sp.k, sp.kd), SPN_OK);
    }
    assert_int_equal(spn_world_set_implicit_preconditioner(w, SPN_PRECOND_AUTO), SPN_OK);
    const long longest = same_steps(w, 0, SPN_PRECOND_CYCLIC, 1e-4, 6);
    assert_true(longest > SPN__IMPLICIT_BJ_MAX + 1); /* the case is reached */
    assert_true(longest < 1000);                     /* and the solves finish */
}

/* The same rule on a web under SPN__IMPLICIT_MG_MIN particles, which auto
 * otherwise leaves to block Jacobi: a species web in wind took 646
 * iterations a step there, against 23 with the multigrid (bench/bench_air.c)
 * and 4-6 with the factor. Here 20 x 60 with a spring broken at dt 1e-4 s:
 * block Jacobi 133-142 a step; auto's first step is block Jacobi's for 101
 * iterations and the factor's for the rest, the others the factor's (3
 * each; the multigrid took 12-13). */
static void test_auto_on_a_small_web(void **state)
{
    (void)state;
    const uint32_t n = spn_orb_scene_particles(20, 60);
    assert_true(n < SPN__IMPLICIT_MG_MIN);
    long cg_auto, cg_bj;
    spn_vec3 *a = web_steps(20, 60, SPN_PRECOND_AUTO, true, 1e-4, 1, &cg_auto),
             *b = web_steps(20, 60, SPN_PRECOND_BLOCK_JACOBI, true, 1e-4, 1, &cg_bj);
    expect_switched(cg_auto, cg_bj);
    free(a), free(b);
    const long first_auto = cg_auto, first_bj = cg_bj;
    a = web_steps(20, 60, SPN_PRECOND_AUTO, true, 1e-4, 4, &cg_auto);
    b = web_steps(20, 60, SPN_PRECOND_BLOCK_JACOBI, true, 1e-4, 4, &cg_bj);
    double vmax;
    const double dv = velocity_gap(a, b, n, &vmax);
    print_message("small web, dt 1e-4: CG %ld (auto; first step %ld) vs %ld (block Jacobi; %ld); max |dv| %.2e of "
                  "%.2e\n",
                  cg_auto, first_auto, cg_bj, first_bj, dv, vmax);
    assert_true(vmax > 0);
    assert_true(dv <= 1e-6 * vmax);
    assert_true((cg_auto - first_auto) * 4 < cg_bj - first_bj); /* steps 2 to 4 */
    free(a), free(b);
    /* With a body held by a contact, the factor too: it holds the web's
     * matrix without the contact's couplings, which CG then builds in a few
     * iterations (test_anim_strike 17 s -> 1.2 s, its solves no longer
     * stopped at 1,000). On the web with a spring broken and on the lattice
     * web, whose steps without contacts take the cyclic preconditioner. */
    for (int broken = 1; broken >= 0; broken--) {
        const double dt = broken ? 1e-4 : 2e-4; /* (the lattice web at 1e-4 s: block Jacobi's 80 a step) */
        a = web_steps_held(20, 60, SPN_PRECOND_AUTO, broken, true, dt, 1, &cg_auto);
        b = web_steps_held(20, 60, SPN_PRECOND_BLOCK_JACOBI, broken, true, dt, 1, &cg_bj);
        free(a), free(b);
        const long held_auto = cg_auto, held_bj = cg_bj;
        a = web_steps_held(20, 60, SPN_PRECOND_AUTO, broken, true, dt, 3, &cg_auto);
        b = web_steps_held(20, 60, SPN_PRECOND_BLOCK_JACOBI, broken, true, dt, 3, &cg_bj);
        const double gap = velocity_gap(a, b, n + 1, &vmax);
        print_message("small web%s with a contact, dt %g: CG %ld (auto; first step %ld) vs %ld (block Jacobi; %ld); "
                      "max |dv| %.2e of %.2e\n",
                      broken ? "" : " (lattice)", dt, cg_auto, held_auto, cg_bj, held_bj, gap, vmax);
        assert_true(cg_bj > 3 * SPN__IMPLICIT_BJ_MAX);
        assert_true(vmax > 0);
        assert_true(gap <= 1e-6 * vmax);
        assert_true((cg_auto - held_auto) * 4 < cg_bj - held_bj); /* steps 2 and 3 */
        free(a), free(b);
    }
}

static void test_threads_bit_identical(void **state)
{
    (void)state;
    long cg1, cg2;
    const uint32_t n = spn_orb_scene_particles(50, 50) + 1;
    spn_vec3 *a = run(SPN_PRECOND_MULTIGRID, 1, CONTACT, &cg1), *b = run(SPN_PRECOND_MULTIGRID, 2, CONTACT, &cg2);
    assert_int_equal(cg1, cg2);
    assert_memory_equal(a, b, 2 * n * sizeof *a);
    free(a), free(b);
}

/* A change of preconditioner takes effect at the next step: two steps with
 * the multigrid, then the cyclic preconditioner on the world and on a clone
 * of it (which builds its hierarchy afresh); both take the same two steps,
 * bit for bit. Kept, the multigrid's hierarchy went on serving the cyclic
 * choice (79 CG iterations over the two steps against 10). */
/* auto on a web that is no lattice and small enough to factorise
 * (SPN__IMPLICIT_DIRECT_MAX): from the step after block Jacobi took over a
 * hundred iterations, CG is preconditioned by the factor of a step's own
 * matrix (sparse_chol.c), kept for the steps after it while a step costs
 * no more than the average since the factorisation, its price included
 * (else the next step factorises), while a solve on it has not run the
 * price past that average (else it factorises and goes on), and until the
 * step length changes. The 20 x 60 web with a spring broken, falling from
 * flat: 24 steps of 1e-4 s, then 3 of 2e-4 s. The states agree with block
 * Jacobi's to what the tolerance allows; no step takes more than three
 * prices (block Jacobi 137 a step, the multigrid 12-13); the
 * factor serves two steps or more on average; the change of step
 * factorises at once; one thread and two give the same bits and counts. */
typedef struct factor_run {
    spn_vec3 *state;
    long cg_first, cg_rest, cg_max, cg_after_change;
    uint32_t factorisations, factorisations_before_change;
} factor_run;

enum { FACTOR_STEPS = 24, FACTOR_AFTER = 3 };

/* The 20 x 60 web on the implicit solver, flat, spring 1200 broken (so it
 * is no lattice), CG to 1e-10. */
static spn_world *broken_web(int threads)
{
    spn_world *w = orb_web(20, 60, threads);
    spn_world_break_spring(w, 1200);
    return w;
}

static factor_run factor_steps(spn_precond pc, int threads)
{
    spn_world *w = broken_web(threads);
    assert_int_equal(spn_world_set_implicit_preconditioner(w, pc), SPN_OK);
    factor_run r = {0};
    for (int i = 0; i < FACTOR_STEPS + FACTOR_AFTER; i++) {
        if (i == FACTOR_STEPS) r.factorisations_before_change = spn__imp_mg_factorisations(w);
        assert_int_equal(spn_world_step(w, i < FACTOR_STEPS ? 1e-4 : 2e-4), SPN_OK);
        const long cg = spn_world_last_step(w).cg_iterations;
        if (i == 0) r.cg_first = cg;
        else if (i < FACTOR_STEPS) r.cg_rest += cg, r.cg_max = cg > r.cg_max ? cg : r.cg_max;
        else if (i == FACTOR_STEPS) r.cg_after_change = cg;
    }
    r.factorisations = spn__imp_mg_factorisations(w);
    r.state = util_take_state(w); /* (destroys w) */
    return r;
}

static void test_factor_on_a_small_web(void **state)
{
    (void)state;
    const uint32_t n = spn_orb_scene_particles(20, 60);
    factor_run a = factor_steps(SPN_PRECOND_AUTO, 1), b = factor_steps(SPN_PRECOND_BLOCK_JACOBI, 1);
    double vmax;
    const double dv = velocity_gap(a.state, b.state, n, &vmax);
    print_message("factor: first step %ld CG (block Jacobi's %ld), steps 2-%d %ld, at most %ld (block Jacobi %ld), "
                  "the step after the change %ld; %u factorisations (%u before the change); max |dv| %.2e of %.2e\n",
                  a.cg_first, b.cg_first, FACTOR_STEPS, a.cg_rest, a.cg_max, b.cg_rest, a.cg_after_change,
                  a.factorisations, a.factorisations_before_change, dv, vmax);
    expect_switched(a.cg_first, b.cg_first);
    assert_true(vmax > 0);
    assert_true(dv <= 1e-6 * vmax);
    assert_true(a.cg_max <= 3 * SPN__IMPLICIT_FACTOR_PRICE);
    /* one in the first step, then at most every other step */
    assert_true(a.factorisations_before_change >= 1 && 2 * (a.factorisations_before_change - 1) <= FACTOR_STEPS - 1);
    assert_true(a.factorisations > a.factorisations_before_change);
    assert_true(a.cg_after_change <= 2);
    assert_int_equal(b.factorisations, 0);
    factor_run c = factor_steps(SPN_PRECOND_AUTO, 2);
    assert_int_equal(c.cg_first + c.cg_rest + c.cg_after_change, a.cg_first + a.cg_rest + a.cg_after_change);
    assert_int_equal(c.factorisations, a.factorisations);
    assert_memory_equal(c.state, a.state, 2 * n * sizeof *a.state);
    free(a.state), free(b.state), free(c.state);
}

/* A factor outrun within the step after its own (the 20 x 60 web falling,
 * steps of 1e-4 s: the factor of step 4 is outrun in step 5, refactored
 * mid-solve after some 18 iterations): the next step factorises at its
 * start and takes one or two; outrun again in the step after that, the
 * next two do; then a kept factor serves, and the factor is kept again. */
static void test_factor_hold(void **state)
{
    (void)state;
    spn_world *w = broken_web(1);
    enum { STEPS = 16 };
    long cg[STEPS];
    bool made[STEPS];
    uint32_t before = 0;
    for (int i = 0; i < STEPS; i++) {
        assert_int_equal(spn_world_step(w, 1e-4), SPN_OK);
        cg[i] = spn_world_last_step(w).cg_iterations;
        made[i] = spn__imp_mg_factorisations(w) > before;
        before = spn__imp_mg_factorisations(w);
        print_message("%ld%s ", cg[i], made[i] ? "*" : "");
    }
    print_message("\n");
    spn_world_destroy(w);
    int a = 1; /* the first step outrun: it factorised after more than a price of iterations */
    while (a < STEPS - 5 && !(made[a] && cg[a] > (long)SPN__IMPLICIT_FACTOR_PRICE)) a++;
    assert_true(a < STEPS - 5);
    assert_true(made[a + 1] && cg[a + 1] <= 2);
    assert_true(made[a + 2] && cg[a + 2] > (long)SPN__IMPLICIT_FACTOR_PRICE); /* tried, outrun again */
    assert_true(made[a + 3] && cg[a + 3] <= 2 && made[a + 4] && cg[a + 4] <= 2);
    int kept = 0;
    for (int i = a + 5; i < STEPS; i++) kept += !made[i];
    assert_true(kept >= 3);
}

/* The factor with a prey held by a contact, on a web that is no lattice
 * and big enough that auto does not keep block Jacobi for steps with
 * contacts (5,001 particles, a spring broken, dt 1e-4 s): the contacts'
 * diagonal blocks are in the factor and their couplings are not, as in the
 * V-cycle; CG still solves the whole system. Velocities agree with block
 * Jacobi's to what the tolerance allows, and the steps after the first take
 * a fraction of its iterations. */
static void test_factor_with_a_contact(void **state)
{
    (void)state;
    const uint32_t n = spn_orb_scene_particles(40, 125) + 1;
    assert_true(n > SPN__IMPLICIT_MG_MIN && n < SPN__IMPLICIT_DIRECT_MAX);
    long cg_auto, cg_bj, first_auto, first_bj;
    spn_vec3 *a = web_steps_held(40, 125, SPN_PRECOND_AUTO, true, true, 1e-4, 1, &first_auto),
             *b = web_steps_held(40, 125, SPN_PRECOND_BLOCK_JACOBI, true, true, 1e-4, 1, &first_bj);
    free(a), free(b);
    a = web_steps_held(40, 125, SPN_PRECOND_AUTO, true, true, 1e-4, 4, &cg_auto);
    b = web_steps_held(40, 125, SPN_PRECOND_BLOCK_JACOBI, true, true, 1e-4, 4, &cg_bj);
    double vmax;
    const double dv = velocity_gap(a, b, n, &vmax);
    print_message("factor with a contact: CG %ld (auto; first step %ld) vs %ld (block Jacobi; first %ld); max |dv| "
                  "%.2e of %.2e\n",
                  cg_auto, first_auto, cg_bj, first_bj, dv, vmax);
    expect_switched(first_auto, first_bj);
    assert_true(vmax > 0);
    assert_true(dv <= 1e-6 * vmax);
    assert_true((cg_auto - first_auto) * 4 < cg_bj - first_bj); /* steps 2 to 4 */
    free(a), free(b);
}

/* The held body's rows kept exact on the factor (prey_rows): the same web
 * and body, each step a little longer than the last, so that each
 * factorises its own matrix. On a fresh factor the only couplings CG would
 * build are the contact's, and the Schur complement of the body's rows
 * holds them: one iteration a step, where CG took 4 building them itself
 * (one contact; a prey on many segments took one a contact or so).
 * Velocities agree with block Jacobi's. */
static void test_factor_keeps_the_prey_rows(void **state)
{
    (void)state;
    const uint32_t n = spn_orb_scene_particles(40, 125) + 1;
    spn_vec3 *s[2];
    long most = 0, total[2] = {0, 0};
    uint32_t made = 0;
    for (int k = 0; k < 2; k++) {
        spn_world *w = orb_web(40, 125, 0);
        assert_int_equal(
            spn_world_set_implicit_preconditioner(w, k ? SPN_PRECOND_BLOCK_JACOBI : SPN_PRECOND_AUTO), SPN_OK);
        spn_world_break_spring(w, 1200);
        hold_body(w, 600, spn_v3(0, 0, 0));
        for (int i = 0; i < 5; i++) {
            assert_int_equal(spn_world_step(w, 1e-4 * (1 + 0.01 * i)), SPN_OK);
            const long cg = spn_world_last_step(w).cg_iterations;
            total[k] += cg;
            if (k == 0 && i > 0 && cg > most) most = cg;
        }
        if (k == 0) made = spn__imp_mg_factorisations(w);
        s[k] = util_take_state(w);
    }
    double vmax;
    const double dv = velocity_gap(s[0], s[1], n, &vmax);
    print_message("factor keeping the prey's rows: steps 2-5 at most %ld CG each, %u factorisations; %ld in all "
                  "against block Jacobi's %ld; max |dv| %.2e of %.2e\n",
                  most, made, total[0], total[1], dv, vmax);
    assert_true(made >= 5);   /* each step factorised */
    assert_true(most <= 2);
    assert_true(vmax > 0);
    assert_true(dv <= 1e-6 * vmax);
    free(s[0]), free(s[1]);
}

/* The refused factor's tests: broken_web, as in test_factor_on_a_small_web
 * (a spring broken, falling from flat, steps of 1e-4 s, one thread) after
 * `steps` steps. */
static spn_world *refusal_web(int steps)
{
    spn_world *w = broken_web(1);
    for (int i = 0; i < steps; i++) assert_int_equal(spn_world_step(w, 1e-4), SPN_OK);
    return w;
}

/* One step of 1e-4 s of w and of a clone of it with preconditioner pc, from
 * the same state: w's CG iterations and its factorisations after the step,
 * the clone's iterations, the largest velocity difference and the clone's
 * largest speed. */
typedef struct refusal_step {
    long cg, cg_ref;
    uint32_t factorisations;
    double dv, vmax;
} refusal_step;

static refusal_step step_against(spn_world *w, spn_precond pc)
{
    spn_world *ref = spn_world_clone(w);
    assert_non_null(ref);
    assert_int_equal(spn_world_set_implicit_preconditioner(ref, pc), SPN_OK);
    assert_int_equal(spn_world_step(w, 1e-4), SPN_OK);
    assert_int_equal(spn_world_step(ref, 1e-4), SPN_OK);
    const uint32_t n = spn_world_particle_count(w);
    refusal_step r = {spn_world_last_step(w).cg_iterations, spn_world_last_step(ref).cg_iterations,
                      spn__imp_mg_factorisations(w), 0, 0};
    const spn_vec3 *v = spn_world_velocities(w), *vr = spn_world_velocities(ref);
    for (uint32_t i = 0; i < n; i++) {
        r.dv = fmax(r.dv, spn_v3_len(spn_v3_sub(v[i], vr[i])));
        r.vmax = fmax(r.vmax, spn_v3_len(vr[i]));
    }
    spn_world_destroy(ref);
    return r;
}

/* A refusal is forced (spn__imp_mg_refuse): with valid inputs the step's
 * matrix is positive definite (M (1 + h drag) plus damping, air, contact and
 * spring terms that are each positive semi-definite: a compressed spring's
 * negative transverse term is clamped to 0, a slack tension-only one is left
 * out), and the setters refuse the negative masses, damping and drag that
 * made one that is not, so only round-off could make the factor fail.
 *
 * For the refusal to come mid-solve the step must run a factor it kept
 * past the restart (spn__imp_mg_restart_due: a factorisation's price past
 * the average step since that factor was made): the radii's stiffness
 * times 10 after the second step (valid values; the live springs are the
 * same, so the factor is kept; the second step's 9 iterations did not mark
 * it stale). The stiffening keeps the step far past the restart (block
 * Jacobi's 122 iterations) should the trajectory change. */
static void stiffen_radii(spn_world *w)
{
    for (uint32_t s = 0; s < spn_world_spring_count(w); s++) {
        const spn_spring_def d = spn_world_spring_def(w, s);
        if (d.tag == SPN_THREAD_RADIUS) assert_int_equal(spn_world_set_spring_stiffness(w, s, 10 * d.k, d.kd), SPN_OK);
    }
}

/* In the middle of a solve. After 2 steps the web holds the factor made
 * during the first step's solve, which the third keeps (prepare makes none);
 * the radii stiffened, its solve reaches the restart, the
 * factorisation of its own matrix is refused, and block Jacobi finishes
 * the solve (CG begun again): one factorisation in the step, the factor
 * kept (a refusal at the start of the step would have dropped it), more
 * than half block Jacobi's own iterations where a factor of the step's own
 * matrix finishes in one or two. The step after factorises at its start and takes one or two
 * iterations. Both agree with block Jacobi's step from the same state to
 * what the tolerance allows (as in test_matches_block_jacobi). */
static void test_factor_refused_mid_solve(void **state)
{
    (void)state;
    spn_world *w = refusal_web(2);
    const uint32_t before = spn__imp_mg_factorisations(w);
    assert_true(before >= 1);
    stiffen_radii(w);
    spn__imp_mg_refuse(w, 1);
    refusal_step a = step_against(w, SPN_PRECOND_BLOCK_JACOBI);
    refusal_step b = step_against(w, SPN_PRECOND_BLOCK_JACOBI);
    print_message("refused mid-solve: CG %ld (block Jacobi %ld), factorisations %u -> %u, max |dv| %.2e of %.2e; "
                  "the step after: CG %ld (block Jacobi %ld), factorisations %u, max |dv| %.2e of %.2e\n",
                  a.cg, a.cg_ref, before, a.factorisations, a.dv, a.vmax, b.cg, b.cg_ref, b.factorisations, b.dv,
                  b.vmax);
    assert_true(a.cg_ref > SPN__IMPLICIT_BJ_MAX && a.cg_ref < 1000);
    assert_int_equal(a.factorisations, before + 1);
    assert_true(a.cg > a.cg_ref / 2 && a.cg > 4 * SPN__IMPLICIT_FACTOR_PRICE); /* block Jacobi's, not a factor's */
    assert_true(a.vmax > 0);
    assert_true(a.dv <= 1e-6 * a.vmax);
    assert_int_equal(b.factorisations, before + 2);
    assert_true(b.cg <= 2);
    assert_true(b.dv <= 1e-6 * b.vmax);
    spn_world_destroy(w);
}

/* At the start of a step. (1) After a refusal mid-solve (as in
 * test_factor_refused_mid_solve, two factorisations refused): the next
 * step's factorisation is refused too and the factor dropped (the count
 * reads 0), the V-cycle does that step and the one after in a fraction of
 * block Jacobi's iterations, no factor is made again, and the steps agree
 * with block Jacobi's. (Where the V-cycle refuses the matrix too, in its
 * line factors, block Jacobi does the steps: test_fallbacks.) (2) A
 * refusal of the first factorisation, which the first step makes when its
 * block Jacobi solve passes SPN__IMPLICIT_BJ_MAX iterations: the count
 * reads 0, the V-cycle finishes that step, which agrees with block
 * Jacobi's, and does the steps after it in a fraction of block Jacobi's
 * iterations, with no factor made again. */
static void test_factor_refused_at_a_step(void **state)
{
    (void)state;
    spn_world *w = refusal_web(2);
    stiffen_radii(w);
    spn__imp_mg_refuse(w, 2);
    refusal_step a = step_against(w, SPN_PRECOND_BLOCK_JACOBI);
    assert_true(a.factorisations >= 1); /* refused mid-solve, kept */
    refusal_step b = step_against(w, SPN_PRECOND_BLOCK_JACOBI);
    refusal_step c = step_against(w, SPN_PRECOND_BLOCK_JACOBI);
    print_message("refused again at the next step: CG %ld (block Jacobi %ld), factorisations %u -> %u, max |dv| "
                  "%.2e of %.2e; the step after: CG %ld (block Jacobi %ld), factorisations %u, max |dv| %.2e of %.2e\n",
                  b.cg, b.cg_ref, a.factorisations, b.factorisations, b.dv, b.vmax, c.cg, c.cg_ref, c.factorisations,
                  c.dv, c.vmax);
    assert_true(b.cg_ref > SPN__IMPLICIT_BJ_MAX && b.cg_ref < 1000);
    assert_int_equal(b.factorisations, 0);
    assert_true(b.cg * 4 < b.cg_ref);
    assert_true(b.vmax > 0);
    assert_true(b.dv <= 1e-6 * b.vmax);
    assert_int_equal(c.factorisations, 0);
    assert_true(c.cg * 4 < c.cg_ref);
    assert_true(c.dv <= 1e-6 * c.vmax);
    spn_world_destroy(w);

    w = refusal_web(0);
    spn__imp_mg_refuse(w, 1);
    refusal_step d = step_against(w, SPN_PRECOND_BLOCK_JACOBI);
    print_message("refused in the first step: CG %ld (block Jacobi %ld), factorisations %u, max |dv| %.2e of %.2e\n",
                  d.cg, d.cg_ref, d.factorisations, d.dv, d.vmax);
    assert_int_equal(d.factorisations, 0);
    assert_true(d.cg > SPN__IMPLICIT_BJ_MAX && d.cg < d.cg_ref);
    assert_true(d.vmax > 0);
    assert_true(d.dv <= 1e-6 * d.vmax);
    for (int i = 0; i < 2; i++) {
        refusal_step e = step_against(w, SPN_PRECOND_BLOCK_JACOBI);
        print_message("the step after: CG %ld (block Jacobi %ld), max |dv| %.2e of %.2e\n", e.cg, e.cg_ref, e.dv,
                      e.vmax);
        assert_int_equal(e.factorisations, 0);
        assert_true(e.cg * 4 < e.cg_ref);
        assert_true(e.dv <= 1e-6 * e.vmax);
    }
    spn_world_destroy(w);
}

/* The preconditioners that can refuse a step's matrix, refused by force
 * (with valid inputs the matrix is positive definite; see stiffen_radii):
 * on the 2,501-particle rings x radials web in a breeze the cyclic one's
 * refusal leaves the V-cycle, the V-cycle's block Jacobi, and both block
 * Jacobi; on the small web that is no lattice (test_factor_refused_at_a_step)
 * the factor and then the V-cycle refused when the first step's block
 * Jacobi passes SPN__IMPLICIT_BJ_MAX leave block Jacobi, which goes on as if
 * nothing had been tried. A refusal that did not take would fail the bit comparison: each
 * preconditioner's CG takes its own path. */
static void test_fallbacks(void **state)
{
    (void)state;
    same_steps(make(SPN_PRECOND_CYCLIC, 1, PLAIN), SPN__REFUSE_CYCLIC, SPN_PRECOND_MULTIGRID, 0.05, 3);
    same_steps(make(SPN_PRECOND_MULTIGRID, 1, PLAIN), SPN__REFUSE_VCYCLE, SPN_PRECOND_BLOCK_JACOBI, 0.05, 3);
    same_steps(make(SPN_PRECOND_CYCLIC, 1, PLAIN), SPN__REFUSE_CYCLIC | SPN__REFUSE_VCYCLE,
               SPN_PRECOND_BLOCK_JACOBI, 0.05, 3);
    spn_world *w = refusal_web(0);
    spn__imp_mg_refuse(w, 1);
    same_steps(w, SPN__REFUSE_VCYCLE, SPN_PRECOND_BLOCK_JACOBI, 1e-4, 3);
}

static void test_change_takes_effect(void **state)
{
    (void)state;
    spn_world *a = make(SPN_PRECOND_MULTIGRID, 1, PLAIN);
    for (int i = 0; i < 2; i++) assert_int_equal(spn_world_step(a, 0.05), SPN_OK);
    spn_world *b = spn_world_clone(a);
    assert_non_null(b);
    long cg_a = 0, cg_b = 0;
    assert_int_equal(spn_world_set_implicit_preconditioner(a, SPN_PRECOND_CYCLIC), SPN_OK);
    assert_int_equal(spn_world_set_implicit_preconditioner(b, SPN_PRECOND_CYCLIC), SPN_OK);
    for (int i = 0; i < 2; i++) {
        assert_int_equal(spn_world_step(a, 0.05), SPN_OK);
        assert_int_equal(spn_world_step(b, 0.05), SPN_OK);
        cg_a += spn_world_last_step(a).cg_iterations, cg_b += spn_world_last_step(b).cg_iterations;
    }
    print_message("after the change: CG %ld (world) vs %ld (clone)\n", cg_a, cg_b);
    assert_int_equal(cg_a, cg_b);
    const uint32_t n = spn_world_particle_count(a);
    spn_vec3 *sa = util_take_state(a), *sb = util_take_state(b);
    assert_memory_equal(sa, sb, 2 * n * sizeof *sa);
    free(sa), free(sb);
}

static void test_refused(void **state)
{
    (void)state;
    spn_world *w = make(SPN_PRECOND_AUTO, 1, PLAIN);
    assert_int_equal(spn_world_set_implicit_preconditioner(w, SPN_PRECOND_SGS), SPN_ERR_INVALID);
    assert_non_null(strstr(spn_last_error(), "multigrid"));
    assert_int_equal(spn_world_set_implicit_preconditioner(w, SPN_PRECOND_COUNT), SPN_ERR_INVALID);
    spn_world_destroy(w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_matches_block_jacobi),
        cmocka_unit_test(test_contact),
        cmocka_unit_test(test_break),
        cmocka_unit_test(test_threads_bit_identical),
        cmocka_unit_test(test_refused),
        cmocka_unit_test(test_cyclic_matches_block_jacobi),
        cmocka_unit_test(test_auto_at_short_steps),
        cmocka_unit_test(test_auto_long_solve_on_a_preconditioner),
        cmocka_unit_test(test_auto_on_a_small_web),
        cmocka_unit_test(test_factor_on_a_small_web),
        cmocka_unit_test(test_factor_hold),
        cmocka_unit_test(test_factor_with_a_contact),
        cmocka_unit_test(test_factor_keeps_the_prey_rows),
        cmocka_unit_test(test_factor_refused_mid_solve),
        cmocka_unit_test(test_factor_refused_at_a_step),
        cmocka_unit_test(test_fallbacks),
        cmocka_unit_test(test_change_takes_effect),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
