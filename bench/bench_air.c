/* bench_air: what turbulent air costs an animation.
 * - fill: one time slice of the air field's cached grid (spn_air_prepare),
 *   the grid the animation runner makes at most (48^3 nodes) and a small
 *   one, 64 modes: milliseconds of CPU a slice;
 * - sample: spn_air_sample at random points inside the grid, ns a call;
 *   sample_batch: spn_air_sample_batch at the same points, 512 a call (as a
 *   world takes them), ns a point;
 * - web: a species web (Araneus, seed 1; 1,924 particles) animated for
 *   0.2 s on the implicit solver (its 2 ms substeps), in still air and in
 *   the default wind (`spinneret animate web.json --solver implicit
 *   --wind air`): CPU seconds per simulated second, and the CG iterations
 *   a step (one world stepped as the runner steps it);
 * - web explicit: the same web on symplectic Euler at its stable step, 2,000
 *   steps, still and in wind: ns a spring-step.
 *
 *   bench_air [--quick]   (--quick: the web figures only at 0.05 s) */
#include "anim/anim_internal.h" /* spn__air_grid_over_web: the runner's grid */
#include "common/bench_common.h"

#include <spinneret/spinneret.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void fail(const char *what)
{
    fprintf(stderr, "bench_air: %s: %s\n", what, spn_last_error());
    exit(1);
}

static spn_air_field *make_air(void)
{
    spn_air_def d = spn_air_def_default();
    spn_air_field *air = NULL;
    if (spn_air_create(&d, &air) != SPN_OK) fail("air");
    return air;
}

static void bench_fill(int n, double load)
{
    spn_air_field *air = make_air();
    if (spn_air_set_grid(air, spn_v3(-0.5, -0.5, -0.5), spn_v3(0.5, 0.5, 0.5), n, n, n, 5e-3) != SPN_OK)
        fail("grid");
    const int slices = n > 32 ? 32 : 256, warm = 8;
    /* each window [t, t] needs slices floor(t / dt) and the next: one new a
     * call. The first few calls fill fresh slice buffers, and touching new
     * pages costs more than the filling on this VM: they are not timed. */
    for (int i = 0; i < warm; i++) spn_air_prepare(air, (i + 0.5) * 5e-3, (i + 0.5) * 5e-3);
    double c0 = bench_cpu_now();
    for (int i = warm; i < warm + slices; i++) spn_air_prepare(air, (i + 0.5) * 5e-3, (i + 0.5) * 5e-3);
    double cpu = bench_cpu_now() - c0;
    printf("{\"bench\":\"air\",\"case\":\"fill\",\"nodes\":%d,\"modes\":64,\"ms_per_slice\":%.3f,\"load\":%.2f}\n",
           n * n * n, 1e3 * cpu / slices, load);
    /* sampling inside the grid between two filled slices, at random points
     * (drawn first), one call a point and then in batches of a world's run */
    spn_air_prepare(air, 3.2e-3, 3.2e-3);
    spn_rng rng;
    spn_rng_seed(&rng, 3);
    enum { POINTS = 1 << 14, ROUNDS = 64, RUN = 512 };
    spn_vec3 *p = malloc(POINTS * sizeof *p), *u = malloc(POINTS * sizeof *u);
    if (!p || !u) fail("points");
    for (int i = 0; i < POINTS; i++) {
        const double x = spn_rng_range(&rng, -0.5, 0.5), y = spn_rng_range(&rng, -0.5, 0.5);
        p[i] = spn_v3(x, y, spn_rng_range(&rng, -0.5, 0.5));
    }
    for (int batch = 0; batch < 2; batch++) {
        spn_vec3 sum = spn_v3(0, 0, 0);
        c0 = bench_cpu_now();
        for (int r = 0; r < ROUNDS; r++) {
            if (batch)
                for (int i = 0; i < POINTS; i += RUN) spn_air_sample_batch(air, 3.2e-3, p + i, u + i, RUN);
            else
                for (int i = 0; i < POINTS; i++) u[i] = spn_air_sample(air, 3.2e-3, p[i]);
            sum = spn_v3_add(sum, u[r]);
        }
        cpu = bench_cpu_now() - c0;
        printf("{\"bench\":\"air\",\"case\":\"%s\",\"nodes\":%d,\"ns_per_sample\":%.1f,\"check\":%.3g,"
               "\"load\":%.2f}\n",
               batch ? "sample_batch" : "sample", n * n * n, 1e9 * cpu / ((double)POINTS * ROUNDS),
               sum.x + sum.y + sum.z, load);
    }
    free(p), free(u);
    spn_air_destroy(air);
}

static spn_world *species_web(void)
{
    spn_species_def d = spn_species_def_preset(SPN_SPECIES_ARANEUS);
    spn_world *w = NULL;
    if (spn_web_build_species(&d, &w) != SPN_OK) fail("species web");
    return w;
}

static void bench_web(bool wind, double span, double load)
{
    spn_world *w = species_web();
    spn_anim_def ad = spn_anim_def_default();
    ad.duration = span;
    ad.solver = SPN_INTEGRATOR_IMPLICIT;
    ad.wind = wind ? SPN_WIND_AIR : SPN_WIND_NONE;
    spn_anim_report rep;
    double c0 = bench_cpu_now();
    if (spn_animate(&w, &ad, NULL, NULL, &rep) != SPN_OK) fail("animate");
    double cpu = bench_cpu_now() - c0;
    printf("{\"bench\":\"air\",\"case\":\"web\",\"particles\":%u,\"solver\":\"implicit\",\"wind\":\"%s\","
           "\"steps\":%llu,"
           "\"cpu_s_per_sim_s\":%.3f,\"load\":%.2f}\n",
           spn_world_particle_count(w), wind ? "air" : "none", (unsigned long long)rep.steps, cpu / span, load);
    spn_world_destroy(w);
}

/* The web stepped as the runner steps it (air attached, the runner's grid
 * over its box, spn__air_grid_over_web; slices prepared before each step),
 * for its CG iterations a step. */
static spn_air_field *attach_air(spn_world *w)
{
    spn_air_field *air = make_air();
    if (spn__air_grid_over_web(air, w, spn_air_def_default().small_scale) != SPN_OK) fail("grid");
    spn_air_attach(air, w); /* (on the grid: its resolution) */
    return air;
}

static void bench_web_cg(bool wind, int steps, double load)
{
    spn_world *w = species_web();
    spn_world_set_integrator(w, SPN_INTEGRATOR_IMPLICIT);
    spn_air_field *air = wind ? attach_air(w) : NULL;
    long cg = 0;
    double c0 = bench_cpu_now();
    for (int i = 0; i < steps; i++) {
        double t = spn_world_time(w);
        if (air) spn_air_prepare_held(air, t, t + 2e-3);
        if (spn_world_step(w, 2e-3) != SPN_OK) fail("step");
        cg += spn_world_last_step(w).cg_iterations;
    }
    double cpu = bench_cpu_now() - c0;
    printf("{\"bench\":\"air\",\"case\":\"web_steps\",\"solver\":\"implicit\",\"dt\":2e-3,\"wind\":\"%s\",\"steps\":%d,"
           "\"cg_per_step\":%.1f,\"ms_per_step\":%.3f,\"load\":%.2f}\n",
           wind ? "air" : "none", steps, (double)cg / steps, 1e3 * cpu / steps, load);
    spn_air_destroy(air);
    spn_world_destroy(w);
}

static void bench_web_explicit(bool wind, double load)
{
    spn_world *w = species_web();
    spn_world_set_integrator(w, SPN_INTEGRATOR_SYMPLECTIC);
    spn_air_field *air = wind ? attach_air(w) : NULL;
    const double dt = SPN_STABLE_REACH * spn_world_stable_step(w, 0);
    const int steps = 2000;
    double c0 = bench_cpu_now();
    for (int i = 0; i < steps; i++) {
        double t = spn_world_time(w);
        if (air) spn_air_prepare_held(air, t, t + dt);
        if (spn_world_step(w, dt) != SPN_OK) fail("step");
    }
    double cpu = bench_cpu_now() - c0;
    printf("{\"bench\":\"air\",\"case\":\"web_explicit\",\"solver\":\"symplectic\",\"dt\":%.3g,\"wind\":\"%s\","
           "\"ns_per_spring_step\":%.1f,\"load\":%.2f}\n",
           dt, wind ? "air" : "none", 1e9 * cpu / steps / spn_world_spring_count(w), load);
    spn_air_destroy(air);
    spn_world_destroy(w);
}

int main(int argc, char **argv)
{
    const bool quick = argc > 1 && strcmp(argv[1], "--quick") == 0;
    const double load = bench_load_average();
    bench_fill(48, load);
    bench_fill(16, load);
    for (int wind = 0; wind < 2; wind++) bench_web(wind, quick ? 0.05 : 0.2, load);
    for (int wind = 0; wind < 2; wind++) bench_web_cg(wind, quick ? 25 : 100, load);
    for (int wind = 0; wind < 2; wind++) bench_web_explicit(wind, load);
    return 0;
}
