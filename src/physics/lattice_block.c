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
     * most a quarter */
    const uint32_t per = L->nbands / (uint32_t)threads;
    return K >= 2 && K <= LAT_LEVELS && per >= 1 && per * L->band_rows >= 4 * K;
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
    L->col_stride = ((size_t)L->radials + 7) & ~(size_t)7;
    for (; L->ncols < threads; L->ncols++)
        if (!(L->cols[L->ncols] = spn__lattice_arrays(COL_COUNT, L->col_stride, sizeof **L->cols, 0, NULL, NULL)))
            return false;
    return true;
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
