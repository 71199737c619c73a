/* bench_implicit_mg: CG iterations and CPU time per implicit step on the soak's
 * web (scene:orb:100x200, 20,001 particles) in a gusty breeze, with the
 * cyclic (auto's choice on this rings x radials web), the block-Jacobi and the
 * multigrid preconditioner, at dt 0.05 s, 1/60 s and 2e-4 s.
 * One JSON line per preconditioner and step size (one thread).
 *
 *   bench_implicit_mg [STEPS [TOL [RINGS RADIALS [DT]]]]   (default 12, 1e-3 as the soak, 100 x 200) */
#include <spinneret/spinneret.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static double cpu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static spn_vec3 gusts(void *user, double t, spn_vec3 p)
{
    (void)user;
    return spn_v3(0.1 * sin(3 * p.x), 0, 0.8 + 0.5 * sin(2 * t + 7 * p.y));
}

static int run(spn_precond pc, double dt, double tol, int steps, int rings, int radials)
{
    spn_world_def def = spn_world_def_default();
    def.integrator = SPN_INTEGRATOR_IMPLICIT;
    def.threads = 1;
    spn_orb_scene_def od = spn_orb_scene_def_default();
    od.rings = rings, od.radials = radials;
    spn_world *w;
    if (spn_scene_orb(&def, &od, &w) != SPN_OK || spn_world_set_implicit_preconditioner(w, pc) != SPN_OK ||
        spn_world_set_solver_tolerance(w, tol, 1000) != SPN_OK)
        return 1;
    spn_world_set_air(w, gusts, NULL, 1.2, 1.8e-5);
    spn_world_set_tag_diameter(w, SPN_THREAD_CAPTURE, 3e-6);
    spn_world_set_tag_diameter(w, SPN_THREAD_RADIUS, 4e-6);
    long cg = 0, cg_first = 0;
    double cpu0 = cpu_now(), cpu_first = 0;
    for (int s = 0; s < steps; s++) {
        double c = cpu_now();
        if (spn_world_step(w, dt) != SPN_OK) {
            fprintf(stderr, "bench_implicit_mg: %s\n", spn_last_error());
            return 1;
        }
        if (s == 0) cpu_first = cpu_now() - c, cg_first = spn_world_last_step(w).cg_iterations;
        cg += spn_world_last_step(w).cg_iterations;
    }
    double cpu = cpu_now() - cpu0;
    printf("{\"particles\":%u,\"precond\":\"%s\",\"dt\":%.6g,\"tol\":%g,\"steps\":%d,\"cg_per_step\":%.1f,"
           "\"cpu_s_per_step\":%.4f,\"first_step_cg\":%ld,\"first_step_cpu_s\":%.4f}\n",
           spn_world_particle_count(w), spn_precond_name(pc), dt, tol, steps, (double)cg / steps, cpu / steps, cg_first,
           cpu_first);
    fflush(stdout);
    spn_world_destroy(w);
    return 0;
}

int main(int argc, char **argv)
{
    int steps = argc > 1 ? atoi(argv[1]) : 12;
    double tol = argc > 2 ? atof(argv[2]) : 1e-3;
    int rings = argc > 4 ? atoi(argv[3]) : 100, radials = argc > 4 ? atoi(argv[4]) : 200;
    /* 2e-4 s: the runner's split step while a prey is in contact (it moves a tenth of its radius a step) */
    const double dts[3] = {0.05, 1.0 / 60, 2e-4};
    int rc = 0;
    int nd = 3;
    double dts_arg[1];
    const double *dl = dts;
    if (argc > 5) dts_arg[0] = atof(argv[5]), dl = dts_arg, nd = 1; /* one step size of your own */
    for (int d = 0; d < nd; d++) {
        rc |= run(SPN_PRECOND_CYCLIC, dl[d], tol, steps, rings, radials);
        rc |= run(SPN_PRECOND_MULTIGRID, dl[d], tol, steps, rings, radials);
        rc |= run(SPN_PRECOND_BLOCK_JACOBI, dl[d], tol, steps, rings, radials);
    }
    return rc;
}
