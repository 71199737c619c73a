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

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

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
        L->split.sent_ok = false; /* (the rows sent were in the workspaces) */
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
    L->col_stride = ((size_t)L->radials + 15) & ~(size_t)15; /* padded32(radials): float32's scratch rows */
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

/* ---- the split of the bands over a pass's shares (lat_split) ---- */

/* Rows each share keeps: with its ghost rows costing at most a quarter of
 * them at any level count, as spn__lattice_block_ready asks of an even
 * split. */
#define SPLIT_MIN_ROWS (4 * LAT_LEVELS)
/* Weight of a pass's time per row in a share's rate, the time first held
 * within a factor of 2 of the rate: some 20 passes (each about 50 us on
 * the 5k web) to follow a core that slows down, while a pass that a
 * preempted core made slow moves no band. */
#define SPLIT_GAIN 0.05
/* A new split is taken when it would shorten the slowest share's part by
 * more than this: moving a band makes its rows' cache lines move to the
 * other core, so small gains, or a pass's noise, do not move one. */
#define SPLIT_MARGIN 0.92

static void split_even(lat_split *S)
{
    for (int t = 0; t <= S->shares; t++)
        S->first[t] = (uint32_t)((uint64_t)S->nbands * (uint64_t)t / (uint64_t)S->shares);
    for (int t = 0; t < S->shares; t++)
        S->rate[t] = 0;
}

bool spn__lattice_split_ready(spn__lattice *L, int shares)
{
    lat_split *S = &L->split;
    if (S->shares == shares && S->nbands == L->nbands) return true;
    if (S->shares != shares) {
        free(S->first), free(S->rate), free(S->took);
        S->shares = 0;
        /* (first: the boundaries, then as many for a proposal, then the
         * boundaries of the last rows sent) */
        S->first = malloc(3 * ((size_t)shares + 1) * sizeof *S->first);
        S->rate = malloc((size_t)shares * sizeof *S->rate);
        S->took = aligned_alloc(64, (size_t)shares * sizeof *S->took);
        if (!S->first || !S->rate || !S->took) return false;
        memset(S->took, 0, (size_t)shares * sizeof *S->took);
    }
    S->shares = shares, S->nbands = L->nbands;
    S->sent_first = S->first + 2 * ((size_t)shares + 1);
    S->sent_ok = false;
    split_even(S);
    return true;
}

bool spn__lattice_sent_ready(const spn__lattice *L, uint32_t K, size_t size)
{
    const lat_split *S = &L->split;
    return S->sent_ok && S->sent_K == K && S->sent_size == size &&
           memcmp(S->sent_first, S->first, ((size_t)S->shares + 1) * sizeof *S->first) == 0;
}

void spn__lattice_sent(spn__lattice *L, uint32_t K, size_t size)
{
    lat_split *S = &L->split;
    memcpy(S->sent_first, S->first, ((size_t)S->shares + 1) * sizeof *S->first);
    S->sent_K = K, S->sent_size = size, S->sent_ok = true;
}

void spn__lattice_state_moved(spn__lattice *L) { L->split.sent_ok = false; }

void spn__lattice_stream(void *restrict dst, const void *restrict src, size_t bytes)
{
#if defined(__SSE2__)
    __m128i *d = dst;
    const __m128i *s = src;
    for (size_t i = 0; i < bytes / 16; i++) _mm_stream_si128(d + i, _mm_load_si128(s + i));
#else
    memcpy(dst, src, bytes);
#endif
}

void spn__lattice_stream_fence(void)
{
#if defined(__SSE2__)
    _mm_sfence();
#endif
}

void spn__lattice_split_rows(const spn__lattice *L, int t, uint32_t *R0, uint32_t *R1)
{
    *R0 = lat_band_lo(L, L->split.first[t]), *R1 = lat_band_lo(L, L->split.first[t + 1]);
}

/* Rows of bands [b0, b1). */
static uint32_t band_rows(const spn__lattice *L, uint32_t b0, uint32_t b1)
{
    return lat_band_lo(L, b1) - lat_band_lo(L, b0);
}

void spn__lattice_split_update(spn__lattice *L)
{
    lat_split *S = &L->split;
    const int T = S->shares;
    const uint32_t nb = S->nbands;
    if (T < 2) return;
    if (S->moved) {
        /* (the bands that moved were cold in their new share's caches) */
        S->moved = false;
        return;
    }
    double worst = 0, speed = 0;
    for (int t = 0; t < T; t++) {
        const double rows = band_rows(L, S->first[t], S->first[t + 1]), per = S->took[t].ns / rows;
        const double r = S->rate[t];
        if (!(per > 0)) return; /* (a share not timed) */
        S->rate[t] = r > 0 ? r + SPLIT_GAIN * (fmin(fmax(per, 0.5 * r), 2 * r) - r) : per;
        if (S->rate[t] * rows > worst) worst = S->rate[t] * rows;
        speed += 1 / S->rate[t];
    }
    uint32_t *next = S->first + T + 1;
    if (S->hold >= 0) {
        if (T != 2 || S->hold < 1 || (uint32_t)S->hold >= nb || band_rows(L, 0, (uint32_t)S->hold) < SPLIT_MIN_ROWS ||
            band_rows(L, (uint32_t)S->hold, nb) < SPLIT_MIN_ROWS)
            return;
        S->first[1] = (uint32_t)S->hold;
        return;
    }
    /* each boundary where the shares before it would take their part of
     * the rows at their speeds, at the nearest band boundary that leaves
     * every share its rows */
    next[0] = 0, next[T] = nb;
    double ahead = 0;
    for (int t = 1; t < T; t++) {
        ahead += 1 / S->rate[t - 1];
        const double row = L->rings * ahead / speed;
        uint32_t best = 0;
        double dist = 0;
        for (uint32_t b = next[t - 1] + 1; b < nb; b++) {
            if (band_rows(L, next[t - 1], b) < SPLIT_MIN_ROWS) continue;
            if (band_rows(L, b, nb) < SPLIT_MIN_ROWS * (uint32_t)(T - t)) break;
            const double d = fabs(lat_band_lo(L, b) - row);
            if (!best || d < dist) best = b, dist = d;
        }
        if (!best) return;
        next[t] = best;
    }
    double longest = 0;
    for (int t = 0; t < T; t++) {
        const double part = S->rate[t] * band_rows(L, next[t], next[t + 1]);
        if (part > longest) longest = part;
    }
    if (longest < SPLIT_MARGIN * worst) {
        memcpy(S->first, next, ((size_t)T + 1) * sizeof *next);
        S->moved = true;
    }
}

void spn__lattice_split_hold(spn_world *w, int bands)
{
    if (w->lat) w->lat->split.hold = bands;
}

double spn__lattice_clock_ns(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec * 1e9 + (double)t.tv_nsec;
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
