/* Static equilibrium benchmark (issue 10): the standard orb web with silk
 * values, flat as built, under an out-of-plane load spread over its free
 * particles, solved by spn_world_equilibrium to max|F_i| <= 1e-6 and 1e-9 of
 * the pretension T0 = EA * prestrain. The residual is checked by an
 * independent float64 routine (bench_residual); the time is the whole call,
 * setup included. One JSON line per figure. */
#include "common/bench_common.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int main(int argc, char **argv)
{
    int size = argc > 1 ? atoi(argv[1]) : 0;
    spn_precond pc = SPN_PRECOND_BLOCK_JACOBI;
    if (argc > 2) spn_precond_parse(argv[2], &pc);
    int threads = argc > 3 ? atoi(argv[3]) : 1;
    double loadf = argc > 4 ? atof(argv[4]) : 1.0;
    double tol = argc > 5 ? atof(argv[5]) : 1e-6;
    spn_world *w = bench_orb(&BENCH_ORB_SIZES[size], threads);
    spn_orb_scene_def od = spn_orb_scene_def_default();
    double t0f = od.ea * od.prestrain;
    uint32_t nfree = 0;
    for (uint32_t i = 0; i < spn_world_particle_count(w); i++) nfree += !spn_world_is_fixed(w, i);
    spn_equilibrium_def d = spn_equilibrium_def_default();
    d.preconditioner = pc;
    d.threads = threads;
    d.tolerance = tol;
    d.force_scale = t0f;
    d.load = spn_v3(0, 0, loadf * t0f / nfree);
    spn_equilibrium_report r;
    double c0 = bench_cpu_now(), t0 = bench_now();
    spn_status st = spn_world_equilibrium(w, &d, &r);
    double t1 = bench_now(), c1 = bench_cpu_now();
    double res = bench_residual(w, d.load);
    printf("{\"size\":\"%s\",\"precond\":\"%s\",\"st\":%d,\"reason\":\"%s\",\"seconds\":%.4f,\"cpu\":%.4f,\"newton\":%d,\"cg\":%d,\"bt\":%d,"
           "\"res_rel\":%.3g,\"indep_rel\":%.3g,\"hub_z\":%.6g}\n",
           BENCH_ORB_SIZES[size].name, spn_precond_name(pc), st, spn_equilibrium_reason_name(r.reason), t1 - t0, c1 - c0,
           r.iterations, r.cg_iterations, r.backtracks, r.residual / t0f, res / t0f, spn_world_position(w, 0).z);
    spn_world_destroy(w);
    return 0;
}
