/* How well the static-equilibrium preconditioners precondition, measured
 * without a clock (issue 10). A CG count reflects the Newton path as well as
 * the preconditioner: a change that makes the multigrid better can cost a
 * Newton step (the first solve stops at its forcing term elsewhere) and show
 * more CG iterations, and wall times on the shared VM moved by 30-50% within
 * an hour (2026-11-23). This measures the preconditioner M alone: applied as
 * a stationary iteration, e <- e - M^-1 A e, from a fixed pseudo-random
 * error, how much each cycle shrinks the error's energy norm
 * (spn__precond_contraction). The rate of the last cycles is the one the
 * slowest modes set; CG's convergence follows from the eigenvalue 1 - rate
 * of M^-1 A (docs/physics-equilibrium.md, "Thirteenth session").
 *
 * The standard orb web with the load and definition of bench_equilibrium
 * (flat, silk values, T0 spread out of plane, gravity in the plane); two
 * systems: the first Newton system (the flat web) and the one after a
 * Newton step (a hierarchy built at that state; the solver refreshes its
 * first one instead on webs from 200,000 particles). The error is started
 * in the web's plane (x, y) and out of it (z) separately: a flat web's
 * system does not couple the two (a sagging one hardly), so each is its
 * own problem. Multigrid and, for scale, block Jacobi. 32 cycles, the rate
 * of the last 8 (the 100k web's factors still grow after 16), and the
 * largest single factor. The same numbers on every machine and thread
 * count (every sum in a fixed order; checked on 1 and 2 threads). One JSON
 * line each; `--large`: the 1M web only (2 minutes); `--full`: the 5k,
 * 100k and 1M webs. */
#include "common/bench_common.h"
#include "physics/equilibrium_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define CYCLES 32
#define THREADS 2

static void die(const char *what)
{
    fprintf(stderr, "bench_mg_rates: %s: %s\n", what, spn_last_error());
    exit(1);
}

static spn_equilibrium_def definition(const spn_world *w)
{
    spn_equilibrium_def d = spn_equilibrium_def_default();
    d.threads = THREADS;
    d.load = bench_orb_load(w, &d.force_scale);
    return d;
}

/* The rates of one preconditioner on the system at w's current positions. */
static void rates(spn_world *w, const char *scene, const char *system, spn_precond kind)
{
    spn_equilibrium_def d = definition(w);
    d.preconditioner = kind;
    spn__eq e;
    if (spn__eq_init(&e, w, &d) != SPN_OK) die("init");
    uint32_t worst_particle = 0;
    if (!isfinite(spn__eq_assemble(&e, 0, &worst_particle))) die("assemble");
    spn__precond pc = {.kind = kind};
    const double t0 = bench_now();
    if (spn__precond_setup(&pc, &e) != SPN_OK) die("setup");
    const double setup = bench_now() - t0;
    double *work = malloc(9 * (size_t)(e.n ? e.n : 1) * sizeof *work);
    if (!work) die("memory");
    const struct {
        const char *name;
        unsigned bits;
    } parts[] = {{"xy", 3u}, {"z", 4u}};
    for (int k = 0; k < 2; k++) {
        double worst = 0;
        const double rate = spn__precond_contraction(&pc, &e, parts[k].bits, CYCLES, &worst, work);
        printf("{\"bench\":\"mg_rates\",\"scene\":\"%s\",\"system\":\"%s\",\"precond\":\"%s\",\"component\":\"%s\","
               "\"cycles\":%d,\"contraction\":%.4f,\"worst_cycle\":%.4f,\"setup_seconds\":%.3f}\n",
               scene, system, spn_precond_name(kind), parts[k].name, CYCLES, rate, worst, setup);
        fflush(stdout);
    }
    free(work);
    spn__precond_free(&pc);
    spn__eq_free(&e);
}

static void web(const bench_orb_size *size)
{
    char scene[32];
    snprintf(scene, sizeof scene, "orb-%s", size->name);
    spn_world *w = bench_orb(size, THREADS);
    rates(w, scene, "first", SPN_PRECOND_MULTIGRID);
    rates(w, scene, "first", SPN_PRECOND_BLOCK_JACOBI);
    /* one Newton step of the solver itself, then the system there */
    spn_equilibrium_def d = definition(w);
    d.preconditioner = SPN_PRECOND_MULTIGRID;
    d.max_iterations = 1;
    spn_equilibrium_report r;
    if (spn_world_equilibrium(w, &d, &r) != SPN_OK || r.iterations != 1) die("one Newton step");
    rates(w, scene, "second", SPN_PRECOND_MULTIGRID);
    spn_world_destroy(w);
}

int main(int argc, char **argv)
{
    const bool large_only = argc > 1 && strcmp(argv[1], "--large") == 0;
    const bool full = argc > 1 && strcmp(argv[1], "--full") == 0;
    if (!large_only) {
        web(&BENCH_ORB_SIZES[0]);
        web(&BENCH_ORB_SIZES[1]);
    }
    if (large_only || full) web(&BENCH_ORB_SIZES[2]);
    return 0;
}
