/* bench_matvec: the implicit solver's one choice measured. Its CG applies
 * A = M - h df/dv - h^2 df/dx once per iteration; this times that product
 * matrix-free (as src/physics/implicit.c does: a spring pass over the 48-byte
 * Jacobian records, then the gather) against an assembled block-sparse
 * matrix (per particle row, a symmetric 3x3 diagonal block and one 3x3 block
 * per incident spring with its column), on the standard orb web after one
 * implicit step. Both products are checked equal to 1e-12. One JSON line per
 * web size, single-threaded, CPU time.
 *
 *   bench_matvec [--quick] */
#include "physics/world_internal.h"
#include <spinneret/scenes.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double cpu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Symmetric 3x3 (xx, yy, zz, xy, xz, yz) times p. */
static inline spn_vec3 sym_mul(const double *b, spn_vec3 p)
{
    return spn_v3(b[0] * p.x + b[3] * p.y + b[4] * p.z, b[3] * p.x + b[1] * p.y + b[5] * p.z,
                  b[4] * p.x + b[5] * p.y + b[2] * p.z);
}

/* The block of spring s (iso I + axial u u^T), as 6 numbers. */
static void spring_block(const spn__jac *j, double *b)
{
    const spn_vec3 u = j->u;
    b[0] = j->iso + j->axial * u.x * u.x, b[1] = j->iso + j->axial * u.y * u.y, b[2] = j->iso + j->axial * u.z * u.z;
    b[3] = j->axial * u.x * u.y, b[4] = j->axial * u.x * u.z, b[5] = j->axial * u.y * u.z;
}

typedef struct bsr {
    double *diag;     /* 6 per particle */
    double *blocks;   /* 6 per adjacency entry (the negated spring block) */
    uint32_t *col;    /* column per adjacency entry */
} bsr;

static void assemble(const spn_world *w, double mdiag, bsr *a)
{
    for (uint32_t i = 0; i < w->np; i++) {
        double *d = a->diag + 6 * (size_t)i;
        for (int c = 0; c < 6; c++) d[c] = c < 3 ? w->mass[i] * mdiag : 0;
        for (uint32_t k = w->adj_start[i]; k < w->adj_start[i + 1]; k++) {
            const uint32_t e = w->adj[k], s = e >> 1;
            double b[6];
            spring_block(&w->jac[s], b);
            for (int c = 0; c < 6; c++) {
                d[c] += b[c];
                a->blocks[6 * (size_t)k + c] = -b[c];
            }
            a->col[k] = (e & 1u) ? w->hs[s].a : spn__end_b(w->hs[s]);
        }
    }
}

static void bsr_apply(const spn_world *w, const bsr *a, const spn_vec3 *p, spn_vec3 *y)
{
    for (uint32_t i = 0; i < w->np; i++) {
        spn_vec3 yi = sym_mul(a->diag + 6 * (size_t)i, p[i]);
        for (uint32_t k = w->adj_start[i]; k < w->adj_start[i + 1]; k++)
            yi = spn_v3_add(yi, sym_mul(a->blocks + 6 * (size_t)k, p[a->col[k]]));
        y[i] = yi;
    }
}

/* The matrix-free product, as implicit.c's apply() (without fixed rows and air). */
static void free_apply(spn_world *w, double mdiag, const spn_vec3 *p, spn_vec3 *y)
{
    for (uint32_t s = 0; s < w->ns; s++) {
        const spn__jac *j = &w->jac[s];
        const spn_vec3 d = spn_v3_sub(p[w->hs[s].a], p[spn__end_b(w->hs[s])]);
        w->fs[s] = spn_v3_add(spn_v3_scale(d, j->iso), spn_v3_scale(j->u, j->axial * spn_v3_dot(j->u, d)));
    }
    for (uint32_t i = 0; i < w->np; i++) {
        spn_vec3 yi = spn_v3_scale(p[i], w->mass[i] * mdiag);
        for (uint32_t k = w->adj_start[i]; k < w->adj_start[i + 1]; k++) {
            const uint32_t e = w->adj[k];
            yi = (e & 1u) ? spn_v3_sub(yi, w->fs[e >> 1]) : spn_v3_add(yi, w->fs[e >> 1]);
        }
        y[i] = yi;
    }
}

static int run(int rings, int radials, int reps)
{
    spn_world_def def = spn_world_def_default();
    def.integrator = SPN_INTEGRATOR_IMPLICIT;
    def.threads = 1;
    def.cg_max_iterations = 5;
    spn_orb_scene_def od = spn_orb_scene_def_default();
    od.rings = rings, od.radials = radials;
    spn_world *w;
    if (spn_scene_orb(&def, &od, &w) != SPN_OK || spn_world_step(w, 1e-4) != SPN_OK) {
        fprintf(stderr, "bench_matvec: %s\n", spn_last_error());
        return 1;
    }
    const uint32_t np = w->np, nadj = w->adj_start[np];
    const double mdiag = 1 + 1e-4 * w->def.drag;
    spn_vec3 *p = malloc(np * sizeof *p), *y1 = malloc(np * sizeof *y1), *y2 = malloc(np * sizeof *y2);
    bsr a = {malloc(6 * (size_t)np * sizeof(double)), malloc(6 * (size_t)nadj * sizeof(double)),
             malloc((size_t)nadj * sizeof(uint32_t))};
    if (!p || !y1 || !y2 || !a.diag || !a.blocks || !a.col) return 1;
    for (uint32_t i = 0; i < np; i++) p[i] = spn_v3(sin(i * 0.1), cos(i * 0.37), sin(i * 0.71));
    double t0 = cpu_now();
    assemble(w, mdiag, &a);
    double t_asm = cpu_now() - t0;
    t0 = cpu_now();
    for (int r = 0; r < reps; r++) free_apply(w, mdiag, p, y1);
    double t_free = (cpu_now() - t0) / reps;
    t0 = cpu_now();
    for (int r = 0; r < reps; r++) bsr_apply(w, &a, p, y2);
    double t_bsr = (cpu_now() - t0) / reps;
    double worst = 0, scale = 0;
    for (uint32_t i = 0; i < np; i++) {
        worst = fmax(worst, spn_v3_len(spn_v3_sub(y1[i], y2[i])));
        scale = fmax(scale, spn_v3_len(y1[i]));
    }
    const double per = 1e9 / w->ns;
    printf("{\"bench\":\"matvec\",\"scene\":\"orb\",\"particles\":%u,\"springs\":%u,\"threads\":1,"
           "\"matrix_free_ns_per_spring\":%.3f,\"assembled_ns_per_spring\":%.3f,\"assembly_ns_per_spring\":%.3f,"
           "\"bytes_per_spring_matrix_free\":%zu,\"bytes_per_spring_assembled\":%zu,\"agree\":%s}\n",
           np, w->ns, t_free * per, t_bsr * per, t_asm * per, sizeof(spn__jac) + sizeof(spn_vec3),
           (size_t)(2 * (6 * sizeof(double) + sizeof(uint32_t))), worst <= 1e-12 * scale ? "true" : "false");
    free(p), free(y1), free(y2), free(a.diag), free(a.blocks), free(a.col);
    spn_world_destroy(w);
    return worst <= 1e-12 * scale ? 0 : 1;
}

int main(int argc, char **argv)
{
    int quick = argc > 1 && strcmp(argv[1], "--quick") == 0;
    if (run(50, 100, 400)) return 1;
    if (quick) return 0;
    if (run(400, 250, 20)) return 1;
    return run(1000, 1000, 3);
}
