/* Benchmark scenes and the independent equilibrium check (bench_common.h). */
#include "common/bench_common.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

const bench_orb_size BENCH_ORB_SIZES[3] = {{"5k", 40, 125}, {"100k", 250, 400}, {"1M", 1000, 1000}};

static spn_world *or_die(spn_status st, spn_world *w)
{
    if (st != SPN_OK) {
        fprintf(stderr, "bench: %s\n", spn_last_error());
        exit(1);
    }
    return w;
}

spn_world *bench_orb(const bench_orb_size *size, int threads)
{
    spn_world_def wd = spn_world_def_default();
    wd.threads = threads;
    spn_orb_scene_def d = spn_orb_scene_def_default();
    d.rings = size->rings;
    d.radials = size->radials;
    spn_world *w = NULL;
    spn_status st = spn_scene_orb(&wd, &d, &w);
    return or_die(st, w);
}

spn_vec3 bench_orb_load(const spn_world *w, double *t0)
{
    spn_orb_scene_def od = spn_orb_scene_def_default();
    const double tension = od.ea * od.prestrain;
    uint32_t nf = 0;
    for (uint32_t i = 0; i < spn_world_particle_count(w); i++) nf += !spn_world_is_fixed(w, i);
    if (t0) *t0 = tension;
    return spn_v3(0, 0, tension / (nf ? nf : 1));
}

spn_world *bench_cloth(int threads)
{
    spn_world_def wd = spn_world_def_default();
    wd.threads = threads;
    spn_world *w = NULL;
    spn_status st = spn_scene_cloth(&wd, 64, 64, 1.0, 0.0, 0.1, 500, 0.01, 15u, &w);
    return or_die(st, w);
}

spn_world *bench_chain(int threads)
{
    spn_world_def wd = spn_world_def_default();
    wd.threads = threads;
    spn_world *w = NULL;
    spn_status st = spn_scene_chain(&wd, spn_v3(-0.5, 0, 0), spn_v3(0.5, 0, 0), 200, 1.2, 0.1, 1e4, 0, &w);
    return or_die(st, w);
}

double bench_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

double bench_cpu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

double bench_load_average(void)
{
    double load = -1;
    FILE *fp = fopen("/proc/loadavg", "r");
    if (fp) {
        if (fscanf(fp, "%lf", &load) != 1) load = -1;
        fclose(fp);
    }
    return load;
}

double bench_residual(const spn_world *w, spn_vec3 load)
{
    uint32_t np = spn_world_particle_count(w), ns = spn_world_spring_count(w);
    const spn_vec3 *x = spn_world_positions(w);
    spn_vec3 g = spn_world_get_def(w)->gravity;
    spn_vec3 *f = malloc((np ? np : 1) * sizeof *f);
    if (!f) return NAN;
    for (uint32_t i = 0; i < np; i++) f[i] = spn_v3_add(spn_v3_scale(g, spn_world_mass(w, i)), load);
    for (uint32_t s = 0; s < ns; s++) {
        spn_spring_info si = spn_world_spring(w, s);
        if (si.broken) continue;
        spn_vec3 l = spn_v3_sub(x[si.a], x[si.b]);
        double len = sqrt(spn_v3_dot(l, l));
        double t = si.k * (len - si.rest);
        if (!(len > 0) || (t < 0 && si.tension_only)) continue;
        spn_vec3 fa = spn_v3_scale(l, -t / len);
        f[si.a] = spn_v3_add(f[si.a], fa);
        f[si.b] = spn_v3_sub(f[si.b], fa);
    }
    double worst = 0;
    for (uint32_t i = 0; i < np; i++)
        if (!spn_world_is_fixed(w, i)) worst = fmax(worst, sqrt(spn_v3_dot(f[i], f[i])));
    free(f);
    return worst;
}
