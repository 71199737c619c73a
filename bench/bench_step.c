/* bench_step: nanoseconds per spring per step for each integrator on the
 * standard orb web (spn_scene_orb: hub, rings x radials, outer ring fixed,
 * 2% pre-strain, EA 0.07 N) at about 5,000, 100,000 and 1,000,000
 * particles, on 1 and 2 threads. One JSON line per figure on stdout.
 *
 *   bench_step            the full run (a couple of minutes)
 *   bench_step --quick    the 5,000-particle web only
 *   bench_step --parallel-min N   def.parallel_min = N (default 32,768): the
 *                         size from which loops, and the lattice, use threads
 *   bench_step --integrator NAME  that integrator only
 *   bench_step --size 5k|100k|1M  that web only (e.g. the 1M figures alone,
 *                         repeated, on a shared machine)
 *
 * Explicit steps use dt = 1e-7 s, divided down to inside the stability limit
 * of each web (spn_anim_stable_substeps: the 1M web takes a third of it); the
 * adaptive stepper an outer step of 1e-6 s (its sub-step count is
 * reported); the implicit solver dt = 1e-4 s with its CG iterations
 * reported, as its cost per step is its iteration count times one
 * matrix-vector product. The steps are one spn_world_advance call (explicit
 * and RK4 runs then keep one state copy per call, not per step; on the
 * 100k and 1M webs the lattice path takes them several to a pass over
 * memory, "blocked_steps", docs/physics-lattice.md), 40 explicit and 12 RK4
 * steps on the 1M web, enough that loading the state into the lattice's
 * arrays at the start of the call and back at its end is a small part.
 *
 * What is timed: after one warm-up step (which compiles the world), the
 * same call CALLS + 1 times. The first of them is reported apart
 * ("first_call_ns_per_spring_step", wall): it pays what a world allocates
 * on its first call of that kind and no later one. A lone step takes the
 * float64 path, so a float32 world's first call allocates and fills its
 * float32 state and spring slots (about 80 MB for the 1M web): on this
 * guest that first touch of fresh memory took 0.2 s, as long as the 12 RK4
 * steps themselves. (Until the twenty-seventh session only that first
 * call was timed, which charged the float32 rows, and no float64 row, with
 * their one-time allocation.) "ns_per_spring_step" and
 * "cpu_ns_per_spring_step" are then the call of median wall time among the
 * CALLS after it, "min_ns_per_spring_step" the fastest: wall-clock time of
 * the steps only; the process CPU time (all threads) and the load average
 * are there because on a shared machine the wall clock measures the
 * neighbours too.
 *
 * Euler, symplectic Euler and RK4 run twice: on the default path ("path":
 * "lattice", the stencil step of a regular web, see src/physics/lattice.c)
 * and with the lattice forbidden ("path":"general", the spring-record loops
 * any world takes). Symplectic Euler and RK4 run a third time on the float32
 * lattice step ("precision":"float32", spn_world_set_precision; every other
 * row is "float64").
 *
 * Bandwidth: a lattice row also gives the memory traffic its steps cannot
 * avoid (spn__lattice_step_bytes: every pass reads the state, masses and
 * spring slots once and writes the state once; a model, this VM has no
 * memory counters), per spring-step, and what that is per second of wall
 * time: scripts/bench-table.py sets it against bench_bandwidth's triad on as
 * many threads, the share of the machine's bandwidth the step reaches
 * (issue 10). "pass_mib" is what one pass streams: a web whose pass fits in
 * the caches (the 5k web's 0.8 MiB) runs from them, and its share of the
 * memory's bandwidth says only how little it asks of it. */
#include "common/bench_common.h"

#include "physics/world_internal.h" /* spn__lattice_step_bytes */

#include <spinneret/spinneret.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

typedef struct size_case {
    int rings, radials;
    int steps[SPN_INTEGRATOR_COUNT]; /* per integrator */
} size_case;

static const size_case cases[] = {
    {50, 100, {400, 400, 100, 20, 4}},
    {400, 250, {80, 80, 20, 4, 1}},
    {1000, 1000, {40, 40, 12, 2, 1}},
};

static double step_size(spn_integrator integ)
{
    switch (integ) {
    case SPN_INTEGRATOR_ADAPTIVE: return 1e-6;
    case SPN_INTEGRATOR_IMPLICIT: return 1e-4;
    default: return 1e-7;
    }
}

/* Timed calls after the first (their median is the figure). */
#define CALLS 3

typedef struct timed_call {
    double wall, cpu; /* seconds */
} timed_call;

static int by_wall(const void *a, const void *b)
{
    const double x = ((const timed_call *)a)->wall, y = ((const timed_call *)b)->wall;
    return (x > y) - (x < y);
}

/* One spn_world_advance call of `steps` steps, timed; its report into *r. */
static int timed_advance(spn_world *w, double dt, int steps, timed_call *t, spn_step_report *r)
{
    const double t0 = bench_now(), c0 = bench_cpu_now();
    if (spn_world_advance(w, dt, steps) != SPN_OK) {
        fprintf(stderr, "bench_step: %s\n", spn_last_error());
        return 1;
    }
    t->wall = bench_now() - t0, t->cpu = bench_cpu_now() - c0;
    *r = spn_world_last_step(w);
    return 0;
}

/* Time `steps` steps of one integrator on 1 or 2 threads; print one line. */
static int bench_one(const size_case *c, spn_integrator integ, int threads, bool lattice, spn_precision prec,
                     long parallel_min)
{
    spn_world_def def = spn_world_def_default();
    if (parallel_min > 0) def.parallel_min = (uint32_t)parallel_min;
    def.integrator = integ;
    def.threads = threads;
    def.cg_tolerance = 1e-8;
    spn_orb_scene_def od = spn_orb_scene_def_default();
    od.rings = c->rings;
    od.radials = c->radials;
    spn_world *w;
    if (spn_scene_orb(&def, &od, &w) != SPN_OK) {
        fprintf(stderr, "bench_step: %s\n", spn_last_error());
        return 1;
    }
    spn_world_set_lattice(w, lattice);
    spn_world_set_precision(w, prec);
    double dt = step_size(integ);
    if (integ == SPN_INTEGRATOR_SYMPLECTIC || integ == SPN_INTEGRATOR_RK4) /* inside the stability limit */
        dt /= spn_anim_stable_substeps(w, 1 / dt, integ, 0);
    if (spn_world_step(w, dt) != SPN_OK) {
        fprintf(stderr, "bench_step: %s\n", spn_last_error());
        spn_world_destroy(w);
        return 1;
    }
    const int steps = c->steps[integ];
    timed_call all[1 + CALLS], *calls = all + 1; /* all[0]: the world's first call */
    spn_step_report r;
    for (int k = 0; k < 1 + CALLS; k++)
        if (timed_advance(w, dt, steps, &all[k], &r)) {
            spn_world_destroy(w);
            return 1;
        }
    const timed_call first = all[0];
    /* (every call takes the same path: the counts are the last one's) */
    const long substeps = r.substeps, cg = r.cg_iterations, blocked = r.blocked;
    qsort(calls, CALLS, sizeof *calls, by_wall);
    const double sec = calls[CALLS / 2].wall, cpu = calls[CALLS / 2].cpu;
    double per = 1e9 / ((double)steps * spn_world_spring_count(w));
    double ns_spring_step = sec * per;
    printf("{\"bench\":\"step\",\"scene\":\"orb\",\"integrator\":\"%s\",\"particles\":%u,\"springs\":%u,"
           "\"threads\":%d,\"steps\":%d,\"dt\":%g,\"ns_per_spring_step\":%.3f,\"cpu_ns_per_spring_step\":%.3f,"
           "\"load\":%.2f,\"path\":\"%s\",\"precision\":\"%s\"",
           spn_integrator_name(integ), spn_world_particle_count(w), spn_world_spring_count(w), threads, steps, dt,
           ns_spring_step, cpu * per, bench_load_average(), spn_world_step_path(w),
           prec == SPN_PRECISION_FLOAT32 ? "float32" : "float64");
    printf(",\"min_ns_per_spring_step\":%.3f,\"first_call_ns_per_spring_step\":%.3f,\"calls\":%d", calls[0].wall * per,
           first.wall * per, CALLS);
    if (blocked) printf(",\"blocked_steps\":%ld", blocked);
    const double bytes = spn__lattice_step_bytes(w, steps, (int)blocked); /* per step */
    if (bytes > 0)
        printf(",\"model_bytes_per_spring_step\":%.1f,\"model_gb_per_s\":%.2f,\"pass_mib\":%.2f",
               bytes / spn_world_spring_count(w), bytes * steps / sec * 1e-9,
               spn__lattice_step_bytes(w, 1, 1) / 1048576.0); /* one step, one pass: the pass's own bytes */
    if (integ == SPN_INTEGRATOR_ADAPTIVE)
        printf(",\"substeps_per_step\":%.1f,\"ns_per_spring_substep\":%.3f", (double)substeps / steps,
               ns_spring_step * steps / (double)substeps);
    if (integ == SPN_INTEGRATOR_IMPLICIT)
        printf(",\"cg_iterations_per_step\":%.1f,\"ns_per_spring_cg_iteration\":%.3f,"
               "\"cpu_ns_per_spring_cg_iteration\":%.3f",
               (double)cg / steps, cg ? ns_spring_step * steps / (double)cg : 0.0,
               cg ? cpu * per * steps / (double)cg : 0.0);
    printf("}\n");
    fflush(stdout);
    spn_world_destroy(w);
    return 0;
}

int main(int argc, char **argv)
{
    int ncases = 3;
    long parallel_min = 0; /* 0: the world's default */
    int only = -1;         /* one integrator, or all */
    int first = 0;         /* the first web */
    for (int i = 1; i < argc; i++) {
        char *end = NULL;
        if (strcmp(argv[i], "--quick") == 0) ncases = 1;
        else if (strcmp(argv[i], "--parallel-min") == 0 && i + 1 < argc &&
                 (parallel_min = strtol(argv[++i], &end, 10)) >= 1 && parallel_min <= 0x7fffffffL && *end == 0)
            continue;
        else if (strcmp(argv[i], "--integrator") == 0 && i + 1 < argc) {
            spn_integrator in;
            if (spn_integrator_parse(argv[++i], &in) != SPN_OK) {
                fprintf(stderr, "bench_step: --integrator: %s\n", spn_last_error());
                return 2;
            }
            only = (int)in;
        } else if (strcmp(argv[i], "--size") == 0 && i + 1 < argc) {
            static const char *const names[3] = {"5k", "100k", "1M"};
            const char *name = argv[++i];
            int c = 0;
            while (c < 3 && strcmp(name, names[c]) != 0) c++;
            if (c == 3) {
                fprintf(stderr, "bench_step: --size: '%s' is not 5k, 100k or 1M\n", name);
                return 2;
            }
            first = c, ncases = c + 1;
        } else {
            fprintf(stderr, "usage: bench_step [--quick] [--parallel-min N (1..2^31-1)] [--integrator NAME] "
                            "[--size 5k|100k|1M]\n");
            return 2;
        }
    }
    for (int c = first; c < ncases; c++)
        for (int integ = 0; integ < SPN_INTEGRATOR_COUNT; integ++)
            for (int threads = 1; threads <= 2 && (only < 0 || only == integ); threads++) {
                const spn_integrator in = (spn_integrator)integ;
                if (bench_one(&cases[c], in, threads, true, SPN_PRECISION_FLOAT64, parallel_min)) return 1;
                if ((in == SPN_INTEGRATOR_SYMPLECTIC || in == SPN_INTEGRATOR_RK4) &&
                    bench_one(&cases[c], in, threads, true, SPN_PRECISION_FLOAT32, parallel_min))
                    return 1;
                if (integ <= SPN_INTEGRATOR_RK4 &&
                    bench_one(&cases[c], in, threads, false, SPN_PRECISION_FLOAT64, parallel_min))
                    return 1;
            }
    return 0;
}
