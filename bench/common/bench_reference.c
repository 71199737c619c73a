/* Reference equilibrium for the benchmark's sag check: Newton with the exact
 * Hessian and a direct banded Cholesky solve, written here from the public
 * API alone (not the library's solver, which uses conjugate gradients). In
 * the standard web's ring-major numbering a particle's neighbours are at most
 * `radials` ids away, so the band is narrow enough for the 5k web. */
#include "common/bench_common.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct band {
    size_t n, hb;  /* dofs, half-bandwidth */
    double *a;     /* row i holds columns i - hb .. i */
} band;

static double *at(band *b, size_t i, size_t k) { return &b->a[i * (b->hb + 1) + (k + b->hb - i)]; }

static void add(band *b, size_t i, size_t k, double v)
{
    if (k <= i) *at(b, i, k) += v;
}

static int cholesky_solve(band *b, double *x)
{
    size_t n = b->n, hb = b->hb;
    for (size_t i = 0; i < n; i++)
        for (size_t k = i > hb ? i - hb : 0; k <= i; k++) {
            double s = *at(b, i, k);
            size_t p0 = i > hb ? i - hb : 0;
            if (k > hb && k - hb > p0) p0 = k - hb;
            for (size_t p = p0; p < k; p++) s -= *at(b, i, p) * *at(b, k, p);
            if (k < i) *at(b, i, k) = s / *at(b, k, k);
            else if (s > 0) *at(b, i, i) = sqrt(s);
            else return -1;
        }
    for (size_t i = 0; i < n; i++) {
        for (size_t p = i > hb ? i - hb : 0; p < i; p++) x[i] -= *at(b, i, p) * x[p];
        x[i] /= *at(b, i, i);
    }
    for (size_t i = n; i-- > 0;) {
        x[i] /= *at(b, i, i);
        for (size_t p = i > hb ? i - hb : 0; p < i; p++) x[p] -= *at(b, i, p) * x[i];
    }
    return 0;
}

int bench_reference_newton(spn_world *w, spn_vec3 load, double tol, int max_iter)
{
    uint32_t np = spn_world_particle_count(w), ns = spn_world_spring_count(w);
    long *id = malloc(np * sizeof *id);
    size_t n = 0, hb = 0;
    for (uint32_t i = 0; i < np; i++) id[i] = spn_world_is_fixed(w, i) ? -1 : (long)n++;
    for (uint32_t s = 0; s < ns; s++) {
        spn_spring_info si = spn_world_spring(w, s);
        if (id[si.a] >= 0 && id[si.b] >= 0) {
            size_t d = (size_t)labs(id[si.a] - id[si.b]);
            if (d > hb) hb = d;
        }
    }
    band b = {3 * n, 3 * hb + 2, NULL};
    b.a = malloc(b.n * (b.hb + 1) * sizeof *b.a);
    double *f = malloc(b.n * sizeof *f);
    spn_vec3 g = spn_world_get_def(w)->gravity;
    int result = -1;
    for (int it = 0; it <= max_iter && b.a && f; it++) {
        memset(b.a, 0, b.n * (b.hb + 1) * sizeof *b.a);
        for (uint32_t i = 0; i < np; i++)
            if (id[i] >= 0) {
                spn_vec3 fe = spn_v3_add(spn_v3_scale(g, spn_world_mass(w, i)), load);
                memcpy(f + 3 * id[i], &fe, sizeof fe);
            }
        for (uint32_t s = 0; s < ns; s++) {
            spn_spring_info si = spn_world_spring(w, s);
            spn_vec3 l = spn_v3_sub(spn_world_position(w, si.a), spn_world_position(w, si.b));
            double len = spn_v3_len(l), t = si.k * (len - si.rest), u[3] = {l.x / len, l.y / len, l.z / len};
            if (si.broken || (si.tension_only && t < 0)) continue;
            long e[2] = {id[si.a], id[si.b]};
            for (int c = 0; c < 3; c++) {
                if (e[0] >= 0) f[3 * e[0] + c] -= t * u[c];
                if (e[1] >= 0) f[3 * e[1] + c] += t * u[c];
            }
            for (int p = 0; p < 2; p++)
                for (int q = 0; q < 2; q++) {
                    if (e[p] < 0 || e[q] < 0) continue;
                    for (int r = 0; r < 3; r++)
                        for (int c = 0; c < 3; c++) {
                            double h = (si.k - t / len) * u[r] * u[c] + (r == c ? t / len : 0);
                            add(&b, 3 * (size_t)e[p] + r, 3 * (size_t)e[q] + c, p == q ? h : -h);
                        }
                }
        }
        double worst = 0;
        for (size_t i = 0; i < n; i++) worst = fmax(worst, sqrt(f[3 * i] * f[3 * i] + f[3 * i + 1] * f[3 * i + 1] + f[3 * i + 2] * f[3 * i + 2]));
        if (worst <= tol) {
            result = it;
            break;
        }
        if (it == max_iter || cholesky_solve(&b, f) != 0) break;
        for (uint32_t i = 0; i < np; i++)
            if (id[i] >= 0)
                spn_world_set_position(w, i, spn_v3_add(spn_world_position(w, i),
                                                        spn_v3(f[3 * id[i]], f[3 * id[i] + 1], f[3 * id[i] + 2])));
    }
    free(id);
    free(b.a);
    free(f);
    return result;
}
