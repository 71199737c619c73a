/* Memory bandwidth probe (STREAM-style copy and triad) so that other figures
 * can be stated as a fraction of what this machine can move. Arrays of 32 Mi
 * doubles (256 MiB each) are far larger than any cache; bytes counted as
 * STREAM does (copy: 16 B per element, triad: 24 B; write-allocate traffic
 * not counted). Best of several repetitions, for 1 thread and for all.
 * One JSON line per figure; first the sizes of the caches a pass may stay in
 * (Linux: the L2 of one core and the last level, as sysfs gives them; what a
 * figure measures depends on whether its pass fits). A guest without sysfs's
 * cache directory (the Zen 5 VM) gets its L2 from sysconf, which glibc reads
 * from the processor; its L3 stays unknown (0), because what the processor
 * says there can be the whole socket's (that guest: 508 MiB, where one core
 * reaches its CCD's 32), and a pass would be counted as fitting that does
 * not. */
#include "common/bench_common.h"

#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#define N (32u << 20)
#define REPEAT 6

/* cpu0's cache `index`'s sysfs `field` (its first line) into buf; false when absent. */
static bool cache_field(int index, const char *field, char *buf, int size)
{
    char path[96];
    snprintf(path, sizeof path, "/sys/devices/system/cpu/cpu0/cache/index%d/%s", index, field);
    FILE *f = fopen(path, "r");
    bool ok = f && fgets(buf, size, f) != NULL;
    if (f) fclose(f);
    return ok;
}

/* KiB of cpu0's unified cache of `level` ("1024K" in sysfs), or 0 when unknown;
 * without sysfs the L2 from sysconf (above). */
static long cache_kib(int level)
{
    char lv[16], type[32], size[32];
    for (int i = 0; cache_field(i, "level", lv, sizeof lv); i++)
        if (atoi(lv) == level && cache_field(i, "type", type, sizeof type) && strncmp(type, "Unified", 7) == 0 &&
            cache_field(i, "size", size, sizeof size))
            return atol(size);
#ifdef _SC_LEVEL2_CACHE_SIZE
    if (level == 2) {
        long bytes = sysconf(_SC_LEVEL2_CACHE_SIZE);
        return bytes > 0 ? bytes / 1024 : 0;
    }
#endif
    return 0;
}

static double best_of(int kernel, int threads, double *a, const double *b, const double *c)
{
    (void)threads; /* without OpenMP every loop runs on one thread */
    double best = 1e30;
    for (int r = 0; r < REPEAT; r++) {
        double t0 = bench_now();
        if (kernel == 0) {
#pragma omp parallel for schedule(static) num_threads(threads)
            for (uint32_t i = 0; i < N; i++) a[i] = b[i];
        } else {
#pragma omp parallel for schedule(static) num_threads(threads)
            for (uint32_t i = 0; i < N; i++) a[i] = b[i] + 3.0 * c[i];
        }
        double t = bench_now() - t0;
        if (t < best) best = t;
    }
    return best;
}

int main(int argc, char **argv)
{
    (void)argv;
    int max_threads = 1;
#ifdef _OPENMP
    max_threads = omp_get_max_threads();
#endif
    double *a = malloc(N * sizeof *a), *b = malloc(N * sizeof *b), *c = malloc(N * sizeof *c);
    if (!a || !b || !c) {
        fprintf(stderr, "bench_bandwidth: out of memory\n");
        return 1;
    }
    /* first touch in parallel, so pages land where the threads run */
#pragma omp parallel for schedule(static) num_threads(max_threads)
    for (uint32_t i = 0; i < N; i++) a[i] = 0, b[i] = 1, c[i] = 2;
    printf("{\"bench\":\"caches\",\"l2_kib_per_core\":%ld,\"l3_kib\":%ld}\n", cache_kib(2), cache_kib(3));
    const char *names[2] = {"copy", "triad"};
    const double bytes[2] = {16.0 * N, 24.0 * N};
    int counts[2] = {1, max_threads};
    for (int t = 0; t < (max_threads > 1 && argc < 2 ? 2 : 1); t++)
        for (int k = 0; k < 2; k++) {
            double s = best_of(k, counts[t], a, b, c);
            printf("{\"bench\":\"bandwidth\",\"kernel\":\"%s\",\"threads\":%d,\"mib_per_array\":%u,"
                   "\"gb_per_s\":%.2f}\n",
                   names[k], counts[t], (unsigned)(N * sizeof(double) >> 20), bytes[k] / s * 1e-9);
            fflush(stdout);
        }
    free(a);
    free(b);
    free(c);
    return 0;
}
