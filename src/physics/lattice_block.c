/* Temporal blocking of the lattice step: several Euler or symplectic Euler
 * steps, or the four stages of an RK4 step, to each pass over memory. The
 * pass itself is written once for both precisions in lattice_block_t.h
 * (the schedule, the threads and why the bits stay those of single steps are
 * described there); lattice.c instantiates it for float64, lattice_f32.c for
 * float32. Here: what the two share, the test of whether a pass fits the
 * bands, the per-thread workspaces and the summing of each level's band
 * partials (in band order, as a single-step sweep adds them). */
#include "lattice_rows.h"
#include "world_internal.h"

#include <stdlib.h>
#include <string.h>

void *spn__lattice_arrays(size_t count, size_t n, size_t size, size_t lead, void **first, size_t *pitch)
{
    const size_t per = 64 / size, skip = (per - lead % per) % per, step = (n + per - 1) / per * per;
    if (count && step > (SIZE_MAX / size - per) / count) return NULL;
    const size_t bytes = ((skip + count * step) * size + 63) & ~(size_t)63;
    char *block = aligned_alloc(64, bytes ? bytes : 64);
    if (!block) return NULL;
    memset(block, 0, bytes);
    if (first) *first = block + skip * size;
    if (pitch) *pitch = step;
    return block;
}

bool spn__lattice_block_ready(const spn__lattice *L, int threads, uint32_t K)
{
    /* each thread's run of bands at least 4 K rows, so the ghosts cost at
     * most a quarter (the smallest band: rings / nbands rows, rounded down) */
    const uint32_t per = L->nbands / (uint32_t)threads;
    return K >= 2 && K <= LAT_LEVELS && per >= 1 && per * (L->rings / L->nbands) >= 4 * K;
}

bool spn__lattice_block_alloc(spn__lattice *L, int threads, size_t bytes)
{
    if (L->block_size < bytes || L->nbws < threads) {
        for (int t = 0; t < L->nbws; t++) free(L->bws[t]);
        free(L->bws);
        L->nbws = 0;
        L->block_size = 0;
        if (!(L->bws = calloc((size_t)threads, sizeof *L->bws))) return false;
        for (; L->nbws < threads; L->nbws++)
            if (!(L->bws[L->nbws] = spn__lattice_arrays(1, bytes, 1, 0, NULL, NULL))) return false;
        L->block_size = bytes;
    }
    if (L->npartial_k < L->nbands) {
        free(L->partial_k);
        L->npartial_k = 0;
        if (!(L->partial_k = malloc((size_t)LAT_LEVELS * L->nbands * L_NSUMS * sizeof(double)))) return false;
        L->npartial_k = L->nbands;
    }
    return true;
}

bool spn__lattice_cols_alloc(spn__lattice *L, int threads)
{
    if (L->ncols >= threads) return true;
    double **cols = realloc(L->cols, (size_t)threads * sizeof *cols);
    if (!cols) return false;
    L->cols = cols;
    L->col_stride = ((size_t)L->radials + 15) & ~(size_t)15; /* (float32's padded rows of scratch) */
    for (; L->ncols < threads; L->ncols++)
        if (!(L->cols[L->ncols] = spn__lattice_arrays(COL_COUNT, L->col_stride, sizeof **L->cols, 0, NULL, NULL)))
            return false;
    return true;
}

/* The float64 RK4 pass in AVX2 code on Intel processors with AVX-512,
 * where target_clones would pick its AVX-512 version. On an Intel Xeon
 * (family 6, model 207; 2026-12-04) the AVX2 version took 1M RK4 steps
 * about a tenth faster on one thread (30.3 -> 27.2 CPU ns a spring-step,
 * the minimum of six alternating runs; on two threads no difference stood
 * out of the host's noise), while the explicit passes ran a tenth faster
 * in AVX-512 (symplectic 5.27 -> 4.76), so only RK4 is moved. On AMD's Zen 4
 * (family 25, model 17; 2026-12-04) AVX-512 is the faster: 1M RK4 float64,
 * CPU ns a spring-step, minimum of four alternating runs, 17.7 against
 * AVX2's 18.8 on one thread, 18.5 against 21.7 on two (wall 9.3 against
 * 10.9); and the 5k symplectic step in a build without the AVX-512 clones
 * took 3.43 against 2.97. So AMD keeps it. SPN_RK4_AVX2=1 or 0 in the environment (read at each pass)
 * overrides the choice on any processor with AVX2 and FMA, to compare the two
 * there; every version gives the same bits (tests/test_physics_lattice.c). */
bool spn__lattice_rk4_avx2(void)
{
#if defined(SPN__AVX2)
    if (!__builtin_cpu_supports("avx2") || !__builtin_cpu_supports("fma")) return false;
    const char *e = getenv("SPN_RK4_AVX2");
    if (e && (strcmp(e, "0") == 0 || strcmp(e, "1") == 0)) return e[0] == '1';
    return __builtin_cpu_supports("avx512f") && __builtin_cpu_is("intel");
#else
    return false;
#endif
}

void spn__lattice_block_sums(const spn__lattice *L, uint32_t K, double sums[][L_NSUMS])
{
    const uint32_t nb = L->nbands;
    for (uint32_t s = 0; s < K; s++) {
        for (int k = 0; k < L_NSUMS; k++) sums[s][k] = 0;
        for (uint32_t b = 0; b < nb; b++)
            for (int k = 0; k < L_NSUMS; k++) sums[s][k] += L->partial_k[((size_t)s * nb + b) * L_NSUMS + k];
    }
}
