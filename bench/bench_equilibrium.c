/* Static equilibrium benchmark (issue 10). The standard orb web with silk
 * values (EA 0.07 N, 2% pre-strain, so every thread starts at the pretension
 * T0 = 1.4 mN), flat as built, gravity in its plane and an out-of-plane load
 * of T0 in all spread over its free particles, solved by
 * spn_world_equilibrium to max|F_i| <= 1e-6 T0 and 1e-9 T0. Every figure:
 *  - the time of the whole call (setup, every Newton step, every solve),
 *    wall and CPU (on a shared machine CPU time is the honest single-thread
 *    figure);
 *  - the residual measured afterwards by an independent float64 routine
 *    (bench_residual), never the solver's own number;
 *  - the hub's sag against a reference: Newton with the exact Hessian and a
 *    direct banded Cholesky solve (5k web only: the band grows with the web);
 *  - when CMake found CHOLMOD, Newton with a CHOLMOD solve timed to the same
 *    tolerances (5k and 100k), the direct method the targets cite.
 * Also the cloth and the hanging chain from the shared scenes.
 * One JSON line per figure, with the one-minute load average at its start
 * (wall time on a shared machine is only meaningful beside it). A figure of
 * the 5k web or the chain is the fastest of RUNS solves ("runs" in its
 * line): one run of 40 ms read 32 to 60 ms CPU on the shared machine. The
 * first run's CPU time is printed too ("cpu_first_seconds"): a cold call in
 * a fresh process, paying the page faults of all its memory. The heap is
 * kept between runs (glibc: M_TOP_PAD, below), so the fastest run measures
 * the solver and not whether the allocator handed the freed memory back to
 * the kernel in between: with glibc's own heuristics that changed with the
 * solver's allocation pattern (the 5k web: no page faults from the 8th run
 * on, or 2,700 in every run, about 4 ms). A large web's solve runs once:
 * its first figure (two threads, 1e-6 T0) comes first and is marked
 * "cold", a one-shot run's figure: every array on pages new to the process,
 * which in this VM cost 0.5-2 GB/s to touch the first time (about 2 GB on the
 * 1M web, 2-4 s of CPU); the same figure is then repeated after the
 * one-thread solve, on memory the process has had (the allocator gives it
 * back and takes it again, which is cheaper), and marked "cold": false.
 * `--quick`: the 5k web only; `--full`: add the 1M web (minutes; what `make
 * bench` runs); `--large`: the 1M web only. */
#include "common/bench_common.h"

#ifdef __GLIBC__
#include <malloc.h>
#endif
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef SPN_HAVE_CHOLMOD
#include "cholmod_reference.inc"
#endif

#define RUNS 10 /* repeats of a small solve */

typedef struct figure {
    const char *scene;
    spn_precond precond;
    int threads;
    double tolerance;
} figure;

/* Scenes solved so far in this process (run: a scene's first solve is "cold"). */
static const char *solved[8];
static int nsolved;

static bool first_solve(const char *scene)
{
    for (int k = 0; k < nsolved; k++)
        if (strcmp(solved[k], scene) == 0) return false;
    if (nsolved < (int)(sizeof solved / sizeof *solved)) solved[nsolved++] = scene;
    return true;
}

typedef struct timing {
    double wall, cpu, load;
    spn_equilibrium_report rep;
} timing;

/* Solve `w` as `f` asks and time it. */
static timing solve(spn_world *w, const figure *f, double t0, spn_vec3 load)
{
    spn_equilibrium_def d = spn_equilibrium_def_default();
    d.preconditioner = f->precond;
    d.threads = f->threads;
    d.tolerance = f->tolerance;
    d.force_scale = t0;
    d.load = load;
    timing t;
    t.load = bench_load_average();
    double c0 = bench_cpu_now(), s0 = bench_now();
    spn_status st = spn_world_equilibrium(w, &d, &t.rep);
    double s1 = bench_now(), c1 = bench_cpu_now();
    if (st != SPN_OK) {
        fprintf(stderr, "bench_equilibrium: %s\n", spn_last_error());
        exit(1);
    }
    t.wall = s1 - s0;
    t.cpu = c1 - c0;
    return t;
}

/* Solve a world from `make` as `f` asks, `runs` times (each on a fresh
 * world), print one line with the fastest run's CPU time (on a shared
 * machine the others measure the neighbours); returns the hub's sag. */
static double run(spn_world *(*make)(int threads), const figure *f, int runs, double t0, spn_vec3 load,
                  double sag_ref)
{
    timing best = {0};
    double first = 0;
    const bool cold = first_solve(f->scene) && runs == 1; /* the figure is that first solve */
    spn_world *w = NULL;
    for (int k = 0; k < runs; k++) {
        if (w) spn_world_destroy(w);
        w = make(f->threads);
        timing t = solve(w, f, t0, load);
        if (k == 0) first = t.cpu;
        if (k == 0 || t.cpu < best.cpu) best = t;
    }
    const spn_equilibrium_report r = best.rep;
    double res = bench_residual(w, load) / t0, sag = spn_world_position(w, 0).z;
    printf("{\"bench\":\"equilibrium\",\"scene\":\"%s\",\"particles\":%u,\"springs\":%u,\"precond\":\"%s\","
           "\"threads\":%d,\"tolerance\":%g,\"converged\":%s,\"runs\":%d,\"seconds\":%.4f,\"cpu_seconds\":%.4f,"
           "\"cpu_first_seconds\":%.4f,\"cold\":%s,\"newton\":%d,\"cg\":%d,\"residual_over_t0\":%.3g,\"ok\":%s,\"load\":%.2f",
           f->scene, spn_world_particle_count(w), spn_world_spring_count(w), spn_precond_name(f->precond),
           f->threads, f->tolerance, r.reason == SPN_EQUILIBRIUM_CONVERGED ? "true" : "false", runs, best.wall,
           best.cpu, first, cold ? "true" : "false", r.iterations, r.cg_iterations, res, res <= f->tolerance ? "true" : "false", best.load);
    if (sag_ref != 0)
        printf(",\"sag_m\":%.9g,\"sag_ref_m\":%.9g,\"sag_rel_error\":%.3g", sag, sag_ref, fabs(sag - sag_ref) / fabs(sag_ref));
    printf("}\n");
    fflush(stdout);
    spn_world_destroy(w);
    return sag;
}

/* The orb web being benchmarked (a function, so run() can build fresh ones). */
static const bench_orb_size *orb_size;
static spn_world *make_orb(int threads) { return bench_orb(orb_size, threads); }

static void orb(const bench_orb_size *size, bool reference, const figure *figs, int nfigs)
{
    double t0 = 0, sag_ref = 0;
    spn_world *w = bench_orb(size, 1);
    spn_vec3 load = bench_orb_load(w, &t0);
    if (reference) {
        double s0 = bench_now(), c0 = bench_cpu_now();
        int it = bench_reference_newton(w, load, 1e-11 * t0, 30);
        double s1 = bench_now(), c1 = bench_cpu_now();
        sag_ref = spn_world_position(w, 0).z;
        printf("{\"bench\":\"equilibrium_reference\",\"scene\":\"orb-%s\",\"method\":\"newton+banded-cholesky\","
               "\"newton\":%d,\"seconds\":%.3f,\"cpu_seconds\":%.3f,\"residual_over_t0\":%.3g,\"sag_m\":%.9g}\n",
               size->name, it, s1 - s0, c1 - c0, bench_residual(w, load) / t0, sag_ref);
        fflush(stdout);
    }
    spn_world_destroy(w);
#ifdef SPN_HAVE_CHOLMOD
    const double tols[2] = {1e-6, 1e-9};
    for (int k = 0; k < 2 && size->rings * size->radials <= 200000; k++) {
        w = bench_orb(size, 1);
        double s0 = bench_now(), c0 = bench_cpu_now();
        int it = bench_cholmod_newton(w, load, tols[k] * t0, 30);
        double s1 = bench_now(), c1 = bench_cpu_now();
        printf("{\"bench\":\"equilibrium_reference\",\"scene\":\"orb-%s\",\"method\":\"newton+cholmod\","
               "\"tolerance\":%g,\"newton\":%d,\"seconds\":%.3f,\"cpu_seconds\":%.3f,\"residual_over_t0\":%.3g,"
               "\"sag_m\":%.9g,\"load\":%.2f}\n",
               size->name, tols[k], it, s1 - s0, c1 - c0, bench_residual(w, load) / t0, spn_world_position(w, 0).z,
               bench_load_average());
        fflush(stdout);
        spn_world_destroy(w);
    }
#endif
    /* the solves under a second are repeated: the fastest of RUNS */
    orb_size = size;
    for (int k = 0; k < nfigs; k++) run(make_orb, &figs[k], size->rings * size->radials <= 20000 ? RUNS : 1, t0, load, sag_ref);
}

static void other_scenes(void)
{
    /* force scale: the heaviest particle's weight (these start without tension) */
    figure f = {"cloth-64x64", SPN_PRECOND_MULTIGRID, 1, 1e-6};
    run(bench_cloth, &f, 1, 0.1 / (64 * 64) * 9.81, spn_v3(0, 0, 0), 0);
    f.scene = "chain-200";
    run(bench_chain, &f, RUNS, 0.1 / 200 * 9.81, spn_v3(0, 0, 0), 0);
}

int main(int argc, char **argv)
{
    bool quick = argc > 1 && strcmp(argv[1], "--quick") == 0, full = argc > 1 && strcmp(argv[1], "--full") == 0;
    bool large_only = argc > 1 && strcmp(argv[1], "--large") == 0;
#ifdef __GLIBC__
    mallopt(M_TOP_PAD, 64 << 20); /* keep freed memory in the heap between repeated solves (file comment) */
#endif
    const spn_precond MG = SPN_PRECOND_MULTIGRID, BJ = SPN_PRECOND_BLOCK_JACOBI, SGS = SPN_PRECOND_SGS;
    const spn_precond CY = SPN_PRECOND_CYCLIC; /* what auto takes on these webs */
    const figure large[] = {{"orb-1M", CY, 2, 1e-6}, {"orb-1M", CY, 1, 1e-6}, {"orb-1M", CY, 2, 1e-6},
                            {"orb-1M", CY, 2, 1e-9}, {"orb-1M", MG, 2, 1e-6}, {"orb-1M", MG, 2, 1e-9}};
    /* the first cold (file comment) */
    if (large_only) {
        orb(&BENCH_ORB_SIZES[2], false, large, (int)(sizeof large / sizeof *large));
        return 0;
    }
    const figure small[] = {{"orb-5k", BJ, 1, 1e-6},  {"orb-5k", SGS, 1, 1e-6}, {"orb-5k", MG, 1, 1e-6},
                            {"orb-5k", BJ, 1, 1e-9},  {"orb-5k", SGS, 1, 1e-9}, {"orb-5k", MG, 1, 1e-9},
                            {"orb-5k", BJ, 2, 1e-6},  {"orb-5k", MG, 2, 1e-6},  {"orb-5k", CY, 1, 1e-6},
                            {"orb-5k", CY, 1, 1e-9},  {"orb-5k", CY, 2, 1e-6}};
    orb(&BENCH_ORB_SIZES[0], true, small, (int)(sizeof small / sizeof *small));
    if (quick) return 0;
    const figure mid[] = {{"orb-100k", BJ, 1, 1e-6}, {"orb-100k", MG, 1, 1e-6}, {"orb-100k", MG, 1, 1e-9},
                          {"orb-100k", MG, 2, 1e-6}, {"orb-100k", CY, 1, 1e-6}, {"orb-100k", CY, 1, 1e-9},
                          {"orb-100k", CY, 2, 1e-6}};
    orb(&BENCH_ORB_SIZES[1], false, mid, (int)(sizeof mid / sizeof *mid));
    if (full) orb(&BENCH_ORB_SIZES[2], false, large, (int)(sizeof large / sizeof *large));
    other_scenes();
    return 0;
}
