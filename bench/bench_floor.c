/* bench_floor: what this machine's floating-point units can do at most, so
 * that a step's time can be set against the least its arithmetic could take
 * here (issue 10's float64 targets are absolute, the machines under them
 * are not: Zen 4 with AVX-512 one session, Zen 3 with AVX2 the next).
 *
 * Three primitives, each over arrays that stay in the L1 cache, compiled as
 * the stepping kernels are (the same clones, -ffp-contract=off,
 * -fno-math-errno, -fno-trapping-math), best of several repetitions on one
 * thread, one JSON line each:
 *
 *   dependent_add  x = x + d, each add waiting for the last: the latency of
 *                  an add (3 cycles on AMD Zen 2-4, 4 on Intel since
 *                  Skylake), a proxy for the clock the core runs at
 *   sqrt_div       y = b / sqrt(a), independent elements: the square root
 *                  and the division every float64 spring evaluation needs
 *                  (its length and 1 / length, correctly rounded as the
 *                  general path's bits require)
 *   mul_add        a tree of 13 multiplies and 10 adds per element, every
 *                  level independent across elements: the rate of plain
 *                  float64 arithmetic when nothing waits (ns per flop)
 *
 * and then, from them, the least a spring-step of the lattice's symplectic
 * Euler step can take on one thread ("spring_step"): its divider work and
 * its arithmetic, each as if the other were free (the larger is the
 * floor). SPRING_FLOPS is counted by hand from the kernels, not measured,
 * in operations (a fused multiply-add, one instruction on the multiply
 * pipes, counts as one): springs() in src/physics/lattice_rows.h (32 per
 * spring: 14 adds and subtractions, 18 multiplies) and the row update with
 * its force assembly and sum terms in src/physics/lattice_rows_t.h (47 per
 * particle since its multiply-adds were fused, 66 before; a particle per
 * two springs: 23.5, rounded up). Selects, compares and the energy columns'
 * loads and stores are not counted, so the floor is optimistic. The RK4
 * step's floor counts only its four evaluations of the spring law. */
#include "common/bench_common.h"
#include "physics/world_internal.h" /* SPN__KERNEL: the kernels' clones */

#include <math.h>
#include <stdint.h>
#include <stdio.h>

#define LEN 1024 /* three arrays of 8 KiB: the L1 cache of any x86-64 */
#define REPEAT 7
#define SPRING_FLOPS 56     /* symplectic Euler, a spring-step (65 before the fused update) */
#define SPRING_LAW_FLOPS 32 /* springs() alone */

static double a[LEN], b[LEN], y[LEN];

/* Keeps the compiler from dropping or merging repetitions. */
static void touch(void *p) { __asm__ volatile("" : : "r"(p) : "memory"); }

SPN__KERNEL static void sqrt_div(uint32_t n, const double *restrict num, const double *restrict den,
                                 double *restrict out)
{
    for (uint32_t i = 0; i < n; i++)
        out[i] = num[i] / sqrt(den[i]);
}

SPN__KERNEL static void mul_add(uint32_t n, const double *restrict in, double *restrict out)
{
    for (uint32_t i = 0; i < n; i++) {
        const double x = in[i];
        const double p1 = x * 1.01 + 0.1, p2 = x * 0.99 + 0.2, p3 = x * 1.02 + 0.3, p4 = x * 0.98 + 0.4;
        const double p5 = x * 1.03 + 0.5, p6 = x * 0.97 + 0.6, p7 = x * 1.04 + 0.7, p8 = x * 0.96 + 0.8;
        out[i] = (p1 * p2 + p3 * p4) * (p5 * p6 + p7 * p8);
    }
}

static double dependent_adds(long n)
{
    volatile double step = 1e-300; /* read once: the compiler cannot fold the chain */
    const double d = step;
    double x = 1.0;
    for (long i = 0; i < n; i++)
        x = x + d;
    return x;
}

/* Best seconds of REPEAT runs of `reps` calls of kernel k. */
static double best_of(int k, long reps)
{
    double best = 1e30;
    for (int r = 0; r < REPEAT; r++) {
        double t0 = bench_now();
        if (k == 0) {
            volatile double sink = dependent_adds(reps);
            (void)sink;
        } else
            for (long j = 0; j < reps; j++) {
                if (k == 1)
                    sqrt_div(LEN, b, a, y);
                else
                    mul_add(LEN, a, y);
                touch(y);
            }
        double t = bench_now() - t0;
        if (t < best) best = t;
    }
    return best;
}

/* The floor of a spring-step that takes `evals` square roots and divisions
 * and `flops` other operations a spring: the larger of the two, each as if
 * the other were free. */
static void spring_floor(const char *integrator, int evals, int flops, double div_ns, double flop_ns, double load)
{
    const double divider = evals * div_ns, arith = flops * flop_ns;
    printf("{\"bench\":\"floor\",\"kernel\":\"spring_step\",\"integrator\":\"%s\",\"flops_per_spring\":%d,"
           "\"divider_ns\":%.3f,\"arithmetic_ns\":%.3f,\"ns_per_spring_step\":%.3f,\"load\":%.2f}\n",
           integrator, flops, divider, arith, arith > divider ? arith : divider, load);
}

int main(void)
{
    for (uint32_t i = 0; i < LEN; i++)
        a[i] = 0.5 + 0.5 * i / LEN, b[i] = 2.0 - 0.25 * i / LEN;
    const long adds = 200000000, reps = 100000;
    const double add_ns = best_of(0, adds) / adds * 1e9;
    const double div_ns = best_of(1, reps) / ((double)reps * LEN) * 1e9;
    const double flop_ns = best_of(2, reps) / ((double)reps * LEN * 23) * 1e9;
    const double load = bench_load_average();
    printf("{\"bench\":\"floor\",\"kernel\":\"dependent_add\",\"ns_per_op\":%.4f,\"ghz_if_3_cycles\":%.2f,"
           "\"load\":%.2f}\n",
           add_ns, 3.0 / add_ns, load);
    printf("{\"bench\":\"floor\",\"kernel\":\"sqrt_div\",\"ns_per_op\":%.4f,\"load\":%.2f}\n", div_ns, load);
    printf("{\"bench\":\"floor\",\"kernel\":\"mul_add\",\"ns_per_op\":%.5f,\"gflops\":%.1f,\"load\":%.2f}\n", flop_ns,
           1.0 / flop_ns, load);
    spring_floor("symplectic", 1, SPRING_FLOPS, div_ns, flop_ns, load);
    /* RK4 evaluates every spring four times: four square roots and
     * divisions, and at least the spring law's flops four times (its stage
     * updates not counted) */
    spring_floor("rk4", 4, 4 * SPRING_LAW_FLOPS, div_ns, flop_ns, load);
    return 0;
}
