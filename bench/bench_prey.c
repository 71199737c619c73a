/* bench_prey: CPU seconds per simulated second of an animation of the
 * 20,001-particle orb web (scene:orb:100x200, the soak's web) on the implicit
 * solver in gusty air, as `make soak` runs it (steps of 0.05 s, CG tolerance
 * 1e-3, 3 m/s wind, gust 0.6, turbulence 0.3), in three cases:
 * - wind: no prey;
 * - strike: a 0.2 g prey of radius 4 mm at 2 m/s, its surface 1 mm in front
 *   of the web among the capture rings, from the moment it touches;
 * - rest: the same prey at rest with its centre in the web's plane (the
 *   threads through it start inside, at no force) while the web sways;
 * - pass: the same prey at 8 m/s, which breaks through and flies on, over
 *   the soak's first half-second frame.
 * A case runs until its simulated span ends or a wall-clock budget is spent
 * (the runner's stop flag), and reports the simulated time it reached, its
 * steps and CPU time: the step schedule near prey (spn_impact_step_limit,
 * runner.c) is what the strike and rest figures measure.
 *
 *   bench_prey [BUDGET_S [CASES]]   (default 20 s of wall time per case;
 *                                   CASES e.g. "strike,rest": only those) */
#include "common/bench_common.h"

#include <spinneret/spinneret.h>

#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static volatile sig_atomic_t stop_flag;

static void on_alarm(int sig)
{
    (void)sig;
    stop_flag = 1;
}

static spn_world *soak_web(void)
{
    spn_world_def def = spn_world_def_default();
    def.integrator = SPN_INTEGRATOR_IMPLICIT;
    def.threads = 1;
    spn_orb_scene_def od = spn_orb_scene_def_default();
    od.rings = 100, od.radials = 200;
    spn_world *w = NULL;
    if (spn_scene_orb(&def, &od, &w) != SPN_OK) {
        fprintf(stderr, "bench_prey: %s\n", spn_last_error());
        exit(1);
    }
    return w;
}

static void run(const char *name, const spn_prey_def *prey, double span, unsigned budget)
{
    spn_world *w = soak_web();
    spn_anim_def ad = spn_anim_def_default();
    ad.fps = 1 / span; /* one frame: the span */
    ad.duration = span;
    ad.substeps = (int)(span / 0.05 + 0.5) > 0 ? (int)(span / 0.05 + 0.5) : 1;
    ad.solver = SPN_INTEGRATOR_IMPLICIT;
    ad.cg_tolerance = 1e-3;
    ad.wind = SPN_WIND_AIR;
    ad.air.speed = 3, ad.air.gust = 0.6, ad.air.turbulence = 0.3;
    ad.prey = prey;
    ad.nprey = prey ? 1 : 0;
    ad.stop = &stop_flag;
    stop_flag = 0;
    signal(SIGALRM, on_alarm);
    alarm(budget);
    double c0 = bench_cpu_now(), t0 = bench_now();
    spn_anim_report rep;
    spn_status st = spn_animate(&w, &ad, NULL, NULL, &rep);
    double cpu = bench_cpu_now() - c0, wall = bench_now() - t0, sim = spn_world_time(w);
    alarm(0);
    if (st != SPN_OK) {
        fprintf(stderr, "bench_prey: %s: %s\n", name, spn_last_error());
        exit(1);
    }
    double speed = 0;
    if (prey) speed = spn_v3_len(spn_world_velocity(w, spn_world_particle_count(w) - 1));
    printf("{\"bench\":\"prey\",\"case\":\"%s\",\"particles\":%u,\"simulated_s\":%.6g,\"steps\":%llu,"
           "\"mean_step_s\":%.3g,\"cpu_s\":%.3f,\"wall_s\":%.3f,\"cpu_per_simulated_s\":%.4g,\"prey_speed\":%.3g,"
           "\"outcome\":\"%s\",\"finished\":%s,\"load\":%.2f}\n",
           name, spn_world_particle_count(w), sim, (unsigned long long)rep.steps,
           rep.steps ? sim / (double)rep.steps : 0, cpu, wall, sim > 0 ? cpu / sim : 0, speed,
           prey ? spn_prey_outcome_name(rep.impact.outcome[0]) : "-", rep.interrupted ? "false" : "true",
           bench_load_average());
    fflush(stdout);
    spn_world_destroy(w);
}

int main(int argc, char **argv)
{
    unsigned budget = argc > 1 ? (unsigned)atoi(argv[1]) : 20;
    if (budget < 1) budget = 1;
    const double R = 0.004, m = 2e-4;
    /* among the capture rings, 6 cm from the hub, between radials */
    const spn_vec3 at = {0.045, 0.04, 0};
    spn_prey_def strike = {{at.x, at.y, -(R + 0.001)}, {0, 0, 2}, m, R};
    spn_prey_def rest = {at, {0, 0, 0}, m, R};
    spn_prey_def pass = {{at.x, at.y, -(R + 0.001)}, {0, 0, 8}, m, R};
    const char *only = argc > 2 ? argv[2] : "";
    if (!*only || strstr(only, "wind")) run("wind", NULL, 0.5, budget);
    if (!*only || strstr(only, "strike")) run("strike", &strike, 0.05, budget);
    if (!*only || strstr(only, "rest")) run("rest", &rest, 0.5, budget);
    if (!*only || strstr(only, "pass")) run("pass", &pass, 0.5, budget);
    return 0;
}
