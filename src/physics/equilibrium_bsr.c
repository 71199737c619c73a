/* Block sparse rows with 3x3 blocks (equilibrium_bsr.h): products for the
 * Galerkin coarse operators P^T (A P), the transpose, products with vectors
 * and a Gauss-Seidel sweep. Products go row by row with a marker array per
 * thread (Gustavson's algorithm), in two passes: the count of each row,
 * then its columns and values together; each row's entries appear in the
 * order its terms are met, so the same inputs give the same bits for any
 * thread count. The Galerkin product computes only the blocks on and above
 * the diagonal and mirrors the rest (C = P^T A P is symmetric): half the
 * block arithmetic of the setup's largest product. */
#include "core/big_alloc.h"
#include "equilibrium_bsr.h"
#include "equilibrium_internal.h"
#include "world_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Threads by work, not rows: a coarse level's rows are few and long (the
 * 1M web's level 3: 5,326 rows of 145 blocks), and until 2026-11-22 a
 * threshold of 16,384 rows kept the setup's densest products and those
 * levels' products with vectors on one thread. Loops over a matrix's blocks
 * share out from SPN__BSR_PAR_MIN blocks (equilibrium_bsr.h), matrix
 * products from PAR_MIN_PRODUCTS block products. Rows are independent, so
 * any team gives the same bits. */
#define PAR_MIN_PRODUCTS 1e6

void spn__bsr_free(spn__bsr *a)
{
    free(a->start);
    free(a->col);
    free(a->val);
    free(a->fval);
    memset(a, 0, sizeof *a);
}

/* In place: float k goes to bytes [4k, 4k + 4), which only doubles already
 * read (those below k / 2 + 1) occupy, so the values need no second buffer;
 * the tail is then given back. A new float array beside the doubles, as
 * before, added 430 MB of fresh pages to the 1M web's setup (page faults:
 * docs/physics-equilibrium.md). The floats pass through a small buffer and
 * memcpy, which may write over memory the doubles were read from. */
void spn__bsr_round(spn__bsr *a)
{
    enum { BATCH = 512 };
    const size_t n = 9 * (size_t)a->start[a->rows];
    unsigned char *bytes = (unsigned char *)a->val;
    float batch[BATCH];
    for (size_t k = 0; k < n; k += BATCH) {
        size_t m = n - k < BATCH ? n - k : BATCH;
        for (size_t j = 0; j < m; j++) batch[j] = (float)a->val[k + j];
        memcpy(bytes + k * sizeof(float), batch, m * sizeof(float));
    }
    /* + 1: a block's last row is read four floats wide (9 n doubles hold 18 n floats) */
    const float zero = 0;
    memcpy(bytes + n * sizeof(float), &zero, sizeof zero);
    float *f = realloc(a->val, (n + 1) * sizeof *f); /* shrinks in place */
    a->fval = f ? f : (float *)(void *)bytes;
    a->val = NULL;
}

/* The number of distinct columns of row i of A B (mark: per column, the
 * last row that saw it). */
static uint32_t row_count(const spn__bsr *a, const spn__bsr *b, uint32_t i, bool diag_first, uint32_t *mark)
{
    uint32_t cnt = 0;
    if (diag_first) {
        mark[i] = i;
        cnt++;
    }
    for (uint32_t p = a->start[i]; p < a->start[i + 1]; p++) {
        uint32_t k = a->col[p] - b->base;
        for (uint32_t q = b->start[k]; q < b->start[k + 1]; q++) {
            uint32_t j = b->col[q];
            if (mark[j] == i) continue;
            mark[j] = i;
            cnt++;
        }
    }
    return cnt;
}

/* The block sums of row i of C = A B, its columns already placed (pos[j]:
 * where column j is in this row). upper: only the blocks with column >= i
 * (C is known to be symmetric; the rest are mirrored afterwards), which
 * halves the Galerkin product's block arithmetic. */
static void row_sums(const spn__bsr *a, const spn__bsr *b, spn__bsr *c, uint32_t i, bool upper, const uint32_t *pos)
{
    double ta[9];
    for (uint32_t p = a->start[i]; p < a->start[i + 1]; p++) {
        const double *ab = spn__bsr_block(a, p, ta);
        uint32_t k = a->col[p] - b->base;
        for (uint32_t q = b->start[k]; q < b->start[k + 1]; q++) {
            uint32_t j = b->col[q];
            if (!upper || j >= i) spn__blk_mul_add(ab, b->val + 9 * (size_t)q, c->val + 9 * (size_t)pos[j]);
        }
    }
}

/* Numbers a block of the AVX paths' sums takes (three rows of four lanes;
 * defined in every build, since the scalar fallbacks share their sizes). */
enum { ACC = 12 };

#if SPN__AVX
/* acc += a b on 256-bit vectors, a given as its nine numbers broadcast and
 * the sums of a block of C kept as three rows of four lanes (ACC doubles,
 * 32-byte aligned; the fourth lane is a spare that is never read out): row
 * r of acc plus a_r0 b_0 + a_r1 b_1 + a_r2 b_2, rows of b as vectors.
 * Products and sums in the same order as spn__blk_mul_add, no fused
 * multiply-add: the same bits. Whole, aligned, non-overlapping vectors
 * matter: the next product into the same block finds its sums in the
 * store buffer. (Until 2026-11-22 the sums were read and written in C's
 * own nine numbers, rows overlapping by a lane: each load then needed two
 * stores, could not be forwarded and waited for them to reach the cache;
 * 60 ns a product on the 1M web's level 0.) */
/* acc += a b with b's three rows already in vectors (a macro: vectors passed
 * to a function would depend on the clone's instruction set, -Wpsabi). */
#define BLK_MUL_ADD_ROWS(a, b0, b1, b2, acc)                                                                           \
    do {                                                                                                             \
        __m256d c0 = _mm256_load_pd(acc), c1 = _mm256_load_pd((acc) + 4), c2 = _mm256_load_pd((acc) + 8);          \
        c0 = _mm256_add_pd(c0, _mm256_mul_pd((a)[0], b0));                                                           \
        c1 = _mm256_add_pd(c1, _mm256_mul_pd((a)[3], b0));                                                           \
        c2 = _mm256_add_pd(c2, _mm256_mul_pd((a)[6], b0));                                                           \
        c0 = _mm256_add_pd(c0, _mm256_mul_pd((a)[1], b1));                                                           \
        c1 = _mm256_add_pd(c1, _mm256_mul_pd((a)[4], b1));                                                           \
        c2 = _mm256_add_pd(c2, _mm256_mul_pd((a)[7], b1));                                                           \
        c0 = _mm256_add_pd(c0, _mm256_mul_pd((a)[2], b2));                                                           \
        c1 = _mm256_add_pd(c1, _mm256_mul_pd((a)[5], b2));                                                           \
        c2 = _mm256_add_pd(c2, _mm256_mul_pd((a)[8], b2));                                                           \
        _mm256_store_pd(acc, c0);                                                                                    \
        _mm256_store_pd((acc) + 4, c1);                                                                              \
        _mm256_store_pd((acc) + 8, c2);                                                                              \
    } while (0)

__attribute__((target("avx"))) static inline void blk_mul_add_avx(const __m256d *a, const double *restrict b,
                                                                   double *restrict acc)
{
    __m256d b0 = _mm256_loadu_pd(b), b1 = _mm256_loadu_pd(b + 3);
    __m256d b2 = _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(b + 6)), _mm_load_sd(b + 8), 1);
    BLK_MUL_ADD_ROWS(a, b0, b1, b2, acc);
}

/* row_sums with blk_mul_add_avx (a block of A broadcast once for the row
 * of B it multiplies: a third of the instructions), into acc, ACC numbers
 * a block of the row from its first, then copied out to C's nine. */
__attribute__((target("avx"))) static void row_sums_avx(const spn__bsr *a, const spn__bsr *b, spn__bsr *c, uint32_t i,
                                                        bool upper, const uint32_t *pos, double *restrict acc)
{
    const uint32_t q0 = c->start[i - c->base], cnt = c->start[i - c->base + 1] - q0;
    memset(acc, 0, ACC * (size_t)cnt * sizeof *acc);
    double ta[9];
    for (uint32_t p = a->start[i]; p < a->start[i + 1]; p++) {
        const double *ab = spn__bsr_block(a, p, ta);
        __m256d av[9];
        for (int k = 0; k < 9; k++) av[k] = _mm256_broadcast_sd(ab + k);
        uint32_t k = a->col[p] - b->base;
        for (uint32_t q = b->start[k]; q < b->start[k + 1]; q++) {
            uint32_t j = b->col[q];
            if (!upper || j >= i) blk_mul_add_avx(av, b->val + 9 * (size_t)q, acc + ACC * (size_t)(pos[j] - q0));
        }
    }
    double *cv = c->val + 9 * (size_t)q0;
    for (uint32_t t = 0; t < cnt; t++)
        for (int r = 0; r < 3; r++) memcpy(cv + 9 * (size_t)t + 3 * r, acc + ACC * (size_t)t + 4 * r, 3 * sizeof *cv);
}
#endif

/* Row i of C = A B: its columns in the order met (mark as in row_count;
 * pos[j]: where column j went). */
static void row_cols(const spn__bsr *a, const spn__bsr *b, spn__bsr *c, uint32_t i, bool diag_first, uint32_t *mark,
                     uint32_t *pos)
{
    uint32_t cnt = c->start[i - c->base];
    if (diag_first) {
        mark[i] = i;
        pos[i] = cnt;
        c->col[cnt++] = i;
    }
    for (uint32_t p = a->start[i]; p < a->start[i + 1]; p++) {
        const uint32_t k = a->col[p] - b->base;
        for (uint32_t q = b->start[k]; q < b->start[k + 1]; q++) {
            uint32_t j = b->col[q];
            if (mark[j] == i) continue;
            mark[j] = i;
            pos[j] = cnt;
            c->col[cnt++] = j;
        }
    }
}

/* The sums of row i of C = A B, its columns in place (pos; acc: the AVX
 * path's workspace, ACC numbers a block). */
static void row_sums_of(const spn__bsr *a, const spn__bsr *b, spn__bsr *c, uint32_t i, bool upper, double *acc,
                        const uint32_t *pos)
{
#if SPN__AVX
    if (acc) {
        row_sums_avx(a, b, c, i, upper, pos, acc);
        return;
    }
#else
    (void)acc;
#endif
    const uint32_t q0 = c->start[i - c->base], q1 = c->start[i - c->base + 1];
    memset(c->val + 9 * (size_t)q0, 0, 9 * (size_t)(q1 - q0) * sizeof *c->val);
    row_sums(a, b, c, i, upper, pos);
}

/* Row i of C = A B, columns and sums. */
static void row_values(const spn__bsr *a, const spn__bsr *b, spn__bsr *c, uint32_t i, bool diag_first, bool upper,
                       double *acc, uint32_t *mark, uint32_t *pos)
{
    row_cols(a, b, c, i, diag_first, mark, pos);
    row_sums_of(a, b, c, i, upper, acc, pos);
}

/* The blocks below the diagonal of a structurally symmetric C from those
 * above it: C_ij = C_ji^T (row j found by a scan: rows are short), in its
 * float64 values or, once rounded, its float32 ones. */
static void mirror_lower(spn__bsr *c, int threads)
{
    (void)threads; /* (used by OpenMP pragmas only) */
#pragma omp parallel for schedule(static) num_threads(spn__bsr_team(c, threads))
    for (uint32_t i = 0; i < c->rows; i++)
        for (uint32_t q = c->start[i]; q < c->start[i + 1]; q++) {
            uint32_t j = c->col[q], t = c->start[j];
            if (j >= i) continue;
            while (c->col[t] != i) t++;
            if (c->val) SPN__BLK_TRANSPOSE(c->val + 9 * (size_t)q, c->val + 9 * (size_t)t);
            else SPN__BLK_TRANSPOSE(c->fval + 9 * (size_t)q, c->fval + 9 * (size_t)t);
        }
}

/* The widest row of a square or rectangular pattern (1 at least). */
static uint32_t widest_row(const spn__bsr *m)
{
    uint32_t w = 1;
    for (uint32_t i = 0; i < m->rows; i++) w = m->start[i + 1] - m->start[i] > w ? m->start[i + 1] - m->start[i] : w;
    return w;
}

/* lasting: C outlives the setup (huge pages: spn__big_alloc); otherwise
 * it is a temporary read once (A P), on plain malloc, since in a VM
 * that hands huge pages out fresh from the host their first touch costs
 * 4x that of small pages (docs/physics-equilibrium.md). */
static bool mul(const spn__bsr *a, const spn__bsr *b, spn__bsr *c, bool diag_first, bool upper, bool lasting,
                int threads)
{
    void *(*alloc)(size_t) = lasting ? spn__big_alloc : malloc;
    memset(c, 0, sizeof *c);
    c->rows = a->rows;
    c->cols = b->cols;
    /* the block products of A B, estimated from B's mean row (rows of A
     * vary, hence dynamic chunks); from PAR_MIN_PRODUCTS: the 5k web's
     * level-0 A P (65,000) took 18.4 -> 22.3 ms wall on two threads when
     * shared. Only the team hangs on it: where long rows of A meet long rows
     * of B it undercounts (the 1M web's level 1 before the hub rule of
     * equilibrium_mg.c: 10.6M estimated, 72M counted) */
    const double products = (double)a->start[a->rows] * b->start[b->rows] / (b->rows ? b->rows : 1);
    int nt = products < PAR_MIN_PRODUCTS ? 1 : threads;
    size_t per = b->cols ? b->cols : 1;
    c->start = lasting ? spn__big_calloc((size_t)a->rows + 1, sizeof *c->start)
                       : calloc((size_t)a->rows + 1, sizeof *c->start);
    uint32_t *marks = malloc(2 * (size_t)nt * per * sizeof *marks);
    if (!c->start || !marks) goto fail;
    for (size_t t = 0; t < (size_t)nt * per; t++) marks[t] = UINT32_MAX;
#pragma omp parallel for schedule(dynamic, 64) num_threads(nt)
    for (uint32_t i = 0; i < a->rows; i++)
        c->start[i + 1] = row_count(a, b, i, diag_first, marks + (size_t)spn__thread_num() * per);
    for (uint32_t i = 0; i < a->rows; i++) c->start[i + 1] += c->start[i];
    size_t nnz = c->start[a->rows];
    c->col = alloc((nnz ? nnz : 1) * sizeof *c->col);
    c->val = alloc(9 * (nnz ? nnz : 1) * sizeof *c->val);
    if (!c->col || !c->val) goto fail;
    for (size_t t = 0; t < (size_t)nt * per; t++) marks[t] = UINT32_MAX;
    double *accs = NULL;
    size_t acc_per = 0;
#if SPN__AVX
    if (spn__have_avx()) {
        acc_per = ACC * (size_t)widest_row(c); /* a multiple of 4 doubles: each thread's part stays 32-byte aligned */
        accs = aligned_alloc(32, (size_t)nt * acc_per * sizeof *accs);
        if (!accs) goto fail;
    }
#endif
#pragma omp parallel for schedule(dynamic, 64) num_threads(nt)
    for (uint32_t i = 0; i < a->rows; i++) {
        size_t t = (size_t)spn__thread_num();
        uint32_t *mark = marks + t * per;
        row_values(a, b, c, i, diag_first, upper, accs ? accs + t * acc_per : NULL, mark, mark + (size_t)nt * per);
    }
    free(accs);
    free(marks);
    if (upper) mirror_lower(c, threads);
    return true;
fail:
    free(marks);
    spn__bsr_free(c);
    return false;
}

bool spn__bsr_mul(const spn__bsr *a, const spn__bsr *b, spn__bsr *c, bool diag_first, int threads)
{
    return mul(a, b, c, diag_first, false, false, threads);
}

bool spn__bsr_galerkin(const spn__bsr *r, const spn__bsr *ap, spn__bsr *c, int threads)
{
    return mul(r, ap, c, true, true, true, threads);
}

/* Coarse rows a chunk of spn__bsr_galerkin_ap has, and how much its chunks'
 * windows of A P may add up to, in blocks, against A P itself before it
 * forms A P whole instead (webs numbered so that an aggregate's neighbours
 * are far apart in it). */
#define GALERKIN_CHUNK 4096u
#define WINDOW_SLACK 1.5
/* On a team, chunks of fewer rows: at least CHUNKS_PER_THREAD a thread, of
 * GALERKIN_CHUNK_MIN rows or more. With 4,096 rows the 1M web's level 2
 * (5,326 coarse rows) made two chunks, of 4,096 and 1,230 rows, and level 3
 * (646) one, so that one thread did most of those products alone. Each row
 * of C is formed the same way whatever chunk holds it: the same bits. */
#define CHUNKS_PER_THREAD 8u
#define GALERKIN_CHUNK_MIN 64u

static uint32_t galerkin_chunk(uint32_t rows, int threads)
{
    if (threads <= 1) return GALERKIN_CHUNK;
    uint32_t c = rows / (CHUNKS_PER_THREAD * (uint32_t)threads);
    return c < GALERKIN_CHUNK_MIN ? GALERKIN_CHUNK_MIN : c > GALERKIN_CHUNK ? GALERKIN_CHUNK : c;
}

/* The rows of A P that rows [i0, i1) of R read: [*lo, *hi], or lo > hi
 * when those rows are empty. */
static void window_of(const spn__bsr *r, uint32_t i0, uint32_t i1, uint32_t *lo, uint32_t *hi)
{
    *lo = UINT32_MAX, *hi = 0;
    for (uint32_t q = r->start[i0]; q < r->start[i1]; q++) {
        *lo = r->col[q] < *lo ? r->col[q] : *lo;
        *hi = r->col[q] > *hi ? r->col[q] : *hi;
    }
}

/* Row i of C = A B when C's pattern is already in place. */
static void row_known(const spn__bsr *a, const spn__bsr *b, spn__bsr *c, uint32_t i, double *acc, uint32_t *pos)
{
    for (uint32_t q = c->start[i - c->base]; q < c->start[i - c->base + 1]; q++) pos[c->col[q]] = q;
    row_sums_of(a, b, c, i, false, acc, pos);
}

/* Why: A P of the 1M web's finest level is 350 MB, written once and read
 * once by R (A P); in a VM that backs fresh pages slowly (about 7 us each,
 * docs/physics-equilibrium.md) touching it cost more than computing it.
 * A P's pattern is formed whole (4 bytes a block); its values only chunk
 * by chunk of C's rows, over the range of A P's rows that the chunk's rows
 * of R read (aggregates are numbered in the order of their roots, so that
 * range is the chunk's own particles and a ring or so either side). */
bool spn__bsr_galerkin_ap(const spn__bsr *a, const spn__bsr *p, const spn__bsr *r, spn__bsr *c, int threads)
{
    const uint32_t n = a->rows, nc = p->cols, rows = r->rows;
    const double products = (double)a->start[n] * p->start[p->rows] / (p->rows ? p->rows : 1);
    const int nt = products < PAR_MIN_PRODUCTS ? 1 : threads;
    const uint32_t chunk = galerkin_chunk(rows, nt), chunks = (rows + chunk - 1) / chunk;
    const size_t per = nc ? nc : 1;
    spn__bsr ap = {.rows = n, .cols = nc};
    uint32_t *marks = malloc(2 * (size_t)nt * per * sizeof *marks), *range = malloc(2 * (size_t)(chunks + 1) * sizeof *range);
    uint32_t *wstart = NULL;
    double *wval = NULL, *accs = NULL;
    bool ok = false;
    memset(c, 0, sizeof *c);
    ap.start = calloc((size_t)n + 1, sizeof *ap.start);
    if (!marks || !range || !ap.start) goto done;
    /* A P's pattern */
    for (size_t t = 0; t < (size_t)nt * per; t++) marks[t] = UINT32_MAX;
#pragma omp parallel for schedule(dynamic, 64) num_threads(nt)
    for (uint32_t i = 0; i < n; i++) ap.start[i + 1] = row_count(a, p, i, false, marks + (size_t)spn__thread_num() * per);
    for (uint32_t i = 0; i < n; i++) ap.start[i + 1] += ap.start[i];
    const size_t nnz = ap.start[n];
    ap.col = malloc((nnz ? nnz : 1) * sizeof *ap.col);
    if (!ap.col) goto done;
    for (size_t t = 0; t < (size_t)nt * per; t++) marks[t] = UINT32_MAX;
#pragma omp parallel for schedule(dynamic, 64) num_threads(nt)
    for (uint32_t i = 0; i < n; i++) {
        uint32_t *mark = marks + (size_t)spn__thread_num() * per;
        row_cols(a, p, &ap, i, false, mark, mark + (size_t)nt * per);
    }
    /* each chunk's range of A P's rows [lo, hi] */
    size_t total = 0, wide_rows = 1, wide_nnz = 1;
    for (uint32_t ch = 0; ch < chunks; ch++) {
        uint32_t lo, hi;
        const uint32_t i0 = ch * chunk, i1 = i0 + chunk < rows ? i0 + chunk : rows;
        window_of(r, i0, i1, &lo, &hi);
        if (lo > hi) lo = 1, hi = 0; /* no entries: an empty window */
        range[2 * ch] = lo, range[2 * ch + 1] = hi;
        if (lo > hi) continue;
        const size_t wr = (size_t)hi - lo + 1, wn = ap.start[hi + 1] - ap.start[lo];
        total += wn;
        wide_rows = wr > wide_rows ? wr : wide_rows;
        wide_nnz = wn > wide_nnz ? wn : wide_nnz;
    }
    if ((double)total > WINDOW_SLACK * (double)nnz) { /* A P whole, then the plain product */
        ap.val = malloc(9 * (nnz ? nnz : 1) * sizeof *ap.val);
        if (!ap.val) goto done;
        const uint32_t widest = widest_row(&ap);
#if SPN__AVX
        if (spn__have_avx() && !(accs = aligned_alloc(32, (size_t)nt * ACC * widest * sizeof *accs))) goto done;
#endif
#pragma omp parallel for schedule(dynamic, 64) num_threads(nt)
        for (uint32_t i = 0; i < n; i++) {
            const size_t t = (size_t)spn__thread_num();
            row_known(a, p, &ap, i, accs ? accs + t * ACC * widest : NULL, marks + ((size_t)nt + t) * per);
        }
        ok = spn__bsr_galerkin(r, &ap, c, threads);
        goto done;
    }
    /* C's pattern, from A P's */
    c->rows = rows, c->cols = nc;
    c->start = spn__big_calloc((size_t)rows + 1, sizeof *c->start);
    if (!c->start) goto done;
    for (size_t t = 0; t < (size_t)nt * per; t++) marks[t] = UINT32_MAX;
#pragma omp parallel for schedule(dynamic, 64) num_threads(nt)
    for (uint32_t i = 0; i < rows; i++) c->start[i + 1] = row_count(r, &ap, i, true, marks + (size_t)spn__thread_num() * per);
    for (uint32_t i = 0; i < rows; i++) c->start[i + 1] += c->start[i];
    const size_t cnnz = c->start[rows];
    c->col = spn__big_alloc((cnnz ? cnnz : 1) * sizeof *c->col);
    c->val = spn__big_alloc(9 * (cnnz ? cnnz : 1) * sizeof *c->val);
    const uint32_t widest_c = widest_row(c), widest_ap = widest_row(&ap);
    const size_t acc_per = ACC * (size_t)(widest_c > widest_ap ? widest_c : widest_ap); /* 32-byte multiples */
    wstart = malloc((size_t)nt * (wide_rows + 1) * sizeof *wstart);
    wval = malloc((size_t)nt * 9 * wide_nnz * sizeof *wval);
    if (!c->col || !c->val || !wstart || !wval) goto done;
#if SPN__AVX
    if (spn__have_avx() && !(accs = aligned_alloc(32, (size_t)nt * acc_per * sizeof *accs))) goto done;
#endif
    for (size_t t = 0; t < (size_t)nt * per; t++) marks[t] = UINT32_MAX;
#pragma omp parallel for schedule(dynamic, 1) num_threads(nt)
    for (uint32_t ch = 0; ch < chunks; ch++) {
        const size_t t = (size_t)spn__thread_num();
        uint32_t *mark = marks + t * per, *pos = marks + ((size_t)nt + t) * per;
        double *acc = accs ? accs + t * acc_per : NULL;
        const uint32_t lo = range[2 * ch], hi = range[2 * ch + 1];
        spn__bsr win = {.rows = hi + 1, .cols = nc, .base = lo};
        if (lo <= hi) {
            win.start = wstart + t * (wide_rows + 1);
            for (uint32_t k = lo; k <= hi + 1; k++) win.start[k - lo] = ap.start[k] - ap.start[lo];
            win.col = ap.col + ap.start[lo];
            win.val = wval + t * 9 * wide_nnz;
            for (uint32_t k = lo; k <= hi; k++) row_known(a, p, &win, k, acc, pos);
        }
        const uint32_t i0 = ch * chunk, i1 = i0 + chunk < rows ? i0 + chunk : rows;
        for (uint32_t i = i0; i < i1; i++) row_values(r, &win, c, i, true, true, acc, mark, pos);
    }
    mirror_lower(c, threads);
    ok = true;
done:
    if (!ok) spn__bsr_free(c);
    spn__bsr_free(&ap);
    free(marks), free(range), free(wstart), free(wval), free(accs);
    return ok;
}

/* Scratch of one thread of spn__bsr_galerkin_refresh: the window of A P's
 * rows a chunk of C reads (wstart, wcol, wval; grown as needed), gathered:
 * rows lists them in the order R's rows first read them and slot[k] is row
 * k's place in it (UINT32_MAX when not in the window). Also the positions of
 * a row's columns (pos, stamped by seen), and a row of C's sums. */
typedef struct refresh_scratch {
    uint32_t *seen, *pos, stamp;
    uint32_t *rows, *slot, nrows;
    uint32_t *wstart, *wcol;
    double *wval, *acc; /* blocks of `stride` numbers, 32-byte aligned */
    size_t wcap, vcap, acap, stride;
} refresh_scratch;

/* p with room for need elements of size bytes (cap: its room), or NULL
 * (p is then unchanged and still owned by the caller). */
static void *grown(void *p, size_t *cap, size_t need, size_t size)
{
    if (need <= *cap) return p;
    size_t c = *cap ? *cap : 1024;
    while (c < need) c *= 2;
    void *q = realloc(p, c * size);
    if (q) *cap = c;
    return q;
}

/* The same for blocks of doubles kept 32-byte aligned (the AVX sums load
 * them whole); the old contents are copied. */
static double *grown_blocks(double *p, size_t *cap, size_t need, size_t stride)
{
    if (need <= *cap) return p;
    size_t c = *cap ? *cap : 1024;
    while (c < need) c *= 2;
    double *q = aligned_alloc(32, c * stride * sizeof *q); /* stride * 8 bytes: a multiple of 32 when stride is ACC */
    if (!q) return NULL;
    if (p) memcpy(q, p, *cap * stride * sizeof *q);
    free(p);
    *cap = c;
    return q;
}

/* Room in s's window for need blocks. */
static bool window_room(refresh_scratch *s, size_t need)
{
    uint32_t *wcol = grown(s->wcol, &s->wcap, need, sizeof *s->wcol);
    if (!wcol) return false;
    s->wcol = wcol;
    double *wval = grown_blocks(s->wval, &s->vcap, need, s->stride);
    if (!wval) return false;
    s->wval = wval;
    return true;
}

/* Row k of A P into s's window from block wn on: its columns in the order
 * met, a new column's block zeroed (pos: where it went). Returns the blocks
 * it took, or UINT32_MAX out of memory. */
static uint32_t window_cols(const spn__bsr *a, const spn__bsr *p, uint32_t k, size_t wn, refresh_scratch *s)
{
    size_t bound = 0;
    for (uint32_t q = a->start[k]; q < a->start[k + 1]; q++) bound += p->start[a->col[q] + 1] - p->start[a->col[q]];
    if (!window_room(s, wn + bound)) return UINT32_MAX;
    const uint32_t stamp = ++s->stamp;
    size_t w = wn;
    for (uint32_t q = a->start[k]; q < a->start[k + 1]; q++)
        for (uint32_t t = p->start[a->col[q]]; t < p->start[a->col[q] + 1]; t++) {
            const uint32_t J = p->col[t];
            if (s->seen[J] == stamp) continue;
            s->seen[J] = stamp;
            s->pos[J] = (uint32_t)w;
            s->wcol[w] = J;
            memset(s->wval + s->stride * w, 0, s->stride * sizeof *s->wval);
            w++;
        }
    return (uint32_t)(w - wn);
}

/* The rows of A P that rows [i0, i1) of R read, into s->rows and s->slot
 * (the previous chunk's slots cleared first).
 * Why gathered, not the range between the least and greatest: where
 * aggregates mix particles numbered far apart (a species web's radii and
 * capture spiral), that range is most of A P for every chunk, and each
 * refresh formed A P about once per chunk: 205 s for a 406k-particle web's
 * form finding, memory growing with it. */
static void gather_rows(const spn__bsr *r, uint32_t i0, uint32_t i1, refresh_scratch *s)
{
    for (uint32_t j = 0; j < s->nrows; j++) s->slot[s->rows[j]] = UINT32_MAX;
    s->nrows = 0;
    for (uint32_t q = r->start[i0]; q < r->start[i1]; q++)
        if (s->slot[r->col[q]] == UINT32_MAX) {
            s->slot[r->col[q]] = s->nrows;
            s->rows[s->nrows++] = r->col[q];
        }
}

/* The gathered rows of A P into s's window, each block summed over A's then
 * P's entries in their order (spn__blk_mul_add): a row's sums are the same
 * whichever chunk forms it. */
static bool refresh_window(const spn__bsr *a, const spn__bsr *p, refresh_scratch *s)
{
    size_t wn = 0;
    for (uint32_t j = 0; j < s->nrows; j++) {
        const uint32_t k = s->rows[j];
        s->wstart[j] = (uint32_t)wn;
        const uint32_t cnt = window_cols(a, p, k, wn, s);
        if (cnt == UINT32_MAX) return false;
        double ta[9], tp[9];
        for (uint32_t q = a->start[k]; q < a->start[k + 1]; q++) {
            const double *ab = spn__bsr_block(a, q, ta);
            for (uint32_t t = p->start[a->col[q]]; t < p->start[a->col[q] + 1]; t++)
                spn__blk_mul_add(ab, spn__bsr_block(p, t, tp), s->wval + 9 * (size_t)s->pos[p->col[t]]);
        }
        wn += cnt;
    }
    s->wstart[s->nrows] = (uint32_t)wn;
    return true;
}

/* Row I of C's sums (the blocks on and above the diagonal) from the window,
 * then rounded into C. */
static bool refresh_row(const spn__bsr *r, spn__bsr *c, uint32_t I, refresh_scratch *s)
{
    const uint32_t q0 = c->start[I], q1 = c->start[I + 1];
    double *acc = grown_blocks(s->acc, &s->acap, (size_t)(q1 - q0), s->stride);
    if (!acc) return false;
    s->acc = acc;
    for (uint32_t q = q0; q < q1; q++) s->pos[c->col[q]] = q - q0;
    memset(acc, 0, 9 * (size_t)(q1 - q0) * sizeof *acc);
    double tr[9];
    for (uint32_t q = r->start[I]; q < r->start[I + 1]; q++) {
        const double *rb = spn__bsr_block(r, q, tr);
        const uint32_t i = s->slot[r->col[q]];
        for (uint32_t t = s->wstart[i]; t < s->wstart[i + 1]; t++)
            if (s->wcol[t] >= I) spn__blk_mul_add(rb, s->wval + 9 * (size_t)t, acc + 9 * (size_t)s->pos[s->wcol[t]]);
    }
    for (uint32_t q = q0; q < q1; q++)
        if (c->col[q] >= I)
            for (int k = 0; k < 9; k++) c->fval[9 * (size_t)q + k] = (float)acc[9 * (size_t)(q - q0) + k];
    return true;
}

#if SPN__AVX
/* blk_mul_add_avx with b a float32 block (its rows read four floats wide:
 * the fourth lane meets the spare lane of acc; a float block's last row
 * reads the spare float that ends every fval). */
__attribute__((target("avx"))) static inline void blk_mul_add_avx_f(const __m256d *a, const float *restrict b,
                                                                     double *restrict acc)
{
    __m256d b0 = _mm256_cvtps_pd(_mm_loadu_ps(b)), b1 = _mm256_cvtps_pd(_mm_loadu_ps(b + 3));
    __m256d b2 = _mm256_cvtps_pd(_mm_loadu_ps(b + 6));
    BLK_MUL_ADD_ROWS(a, b0, b1, b2, acc);
}

/* blk_mul_add_avx with b in the sums' own layout (ACC numbers, rows four wide). */
__attribute__((target("avx"))) static inline void blk_mul_add_avx_acc(const __m256d *a, const double *restrict b,
                                                                       double *restrict acc)
{
    __m256d b0 = _mm256_load_pd(b), b1 = _mm256_load_pd(b + 4), b2 = _mm256_load_pd(b + 8);
    BLK_MUL_ADD_ROWS(a, b0, b1, b2, acc);
}

/* refresh_window on 256-bit vectors, the window's blocks in ACC layout (P
 * in float32, as the built hierarchy keeps it; the same order of sums). */
__attribute__((target("avx"))) static bool refresh_window_avx(const spn__bsr *a, const spn__bsr *p, refresh_scratch *s)
{
    size_t wn = 0;
    for (uint32_t j = 0; j < s->nrows; j++) {
        const uint32_t k = s->rows[j];
        s->wstart[j] = (uint32_t)wn;
        const uint32_t cnt = window_cols(a, p, k, wn, s);
        if (cnt == UINT32_MAX) return false;
        double ta[9];
        for (uint32_t q = a->start[k]; q < a->start[k + 1]; q++) {
            const double *ab = spn__bsr_block(a, q, ta);
            __m256d av[9];
            for (int m = 0; m < 9; m++) av[m] = _mm256_broadcast_sd(ab + m);
            for (uint32_t t = p->start[a->col[q]]; t < p->start[a->col[q] + 1]; t++)
                blk_mul_add_avx_f(av, p->fval + 9 * (size_t)t, s->wval + ACC * (size_t)s->pos[p->col[t]]);
        }
        wn += cnt;
    }
    s->wstart[s->nrows] = (uint32_t)wn;
    return true;
}

__attribute__((target("avx"))) static bool refresh_row_avx(const spn__bsr *r, spn__bsr *c, uint32_t I, refresh_scratch *s)
{
    const uint32_t q0 = c->start[I], q1 = c->start[I + 1];
    double *acc = grown_blocks(s->acc, &s->acap, (size_t)(q1 - q0), ACC);
    if (!acc) return false;
    s->acc = acc;
    for (uint32_t q = q0; q < q1; q++) s->pos[c->col[q]] = q - q0;
    memset(acc, 0, ACC * (size_t)(q1 - q0) * sizeof *acc);
    double tr[9];
    for (uint32_t q = r->start[I]; q < r->start[I + 1]; q++) {
        const double *rb = spn__bsr_block(r, q, tr);
        __m256d av[9];
        for (int m = 0; m < 9; m++) av[m] = _mm256_broadcast_sd(rb + m);
        const uint32_t i = s->slot[r->col[q]];
        for (uint32_t t = s->wstart[i]; t < s->wstart[i + 1]; t++)
            if (s->wcol[t] >= I) blk_mul_add_avx_acc(av, s->wval + ACC * (size_t)t, acc + ACC * (size_t)s->pos[s->wcol[t]]);
    }
    for (uint32_t q = q0; q < q1; q++)
        if (c->col[q] >= I)
            for (int m = 0; m < 9; m++) c->fval[9 * (size_t)q + m] = (float)acc[ACC * (size_t)(q - q0) + 4 * (m / 3) + m % 3];
    return true;
}
#endif

/* The scratch of every thread of spn__bsr_galerkin_refresh, kept between
 * calls on one level (its `keep` argument). */
struct spn__bsr_refresh {
    int threads;
    uint32_t n, nc, widest;
    refresh_scratch s[];
};

static void scratch_free(refresh_scratch *s)
{
    free(s->seen), free(s->pos), free(s->slot), free(s->rows), free(s->wstart), free(s->wcol), free(s->wval), free(s->acc);
    memset(s, 0, sizeof *s);
}

void spn__bsr_refresh_free(spn__bsr_refresh *k)
{
    if (!k) return;
    for (int t = 0; t < k->threads; t++) scratch_free(&k->s[t]);
    free(k);
}

/* s ready for a refresh of a level of n rows and nc coarse ones whose
 * chunks read at most widest rows of R (stride: numbers a window block). A
 * scratch kept from an earlier call keeps its window and sums: they were
 * grown to that call's needs, which are this one's (the patterns are the
 * same), and growing them again each Newton step cost a copy and fresh
 * pages each time. */
static bool scratch_ready(refresh_scratch *s, uint32_t n, uint32_t nc, uint32_t widest, size_t stride)
{
    if (s->seen && s->stride == stride) {
        if (s->stamp < UINT32_MAX - n) return true; /* the stamps of one call: at most n */
        for (uint32_t k = 0; k < nc; k++) s->seen[k] = 0;
        s->stamp = 0;
        return true;
    }
    scratch_free(s);
    s->stride = stride;
    s->seen = malloc((nc ? nc : 1) * sizeof *s->seen);
    s->pos = malloc((nc ? nc : 1) * sizeof *s->pos);
    s->slot = malloc((n ? n : 1) * sizeof *s->slot);
    s->rows = malloc(((size_t)widest + 1) * sizeof *s->rows);
    s->wstart = malloc(((size_t)widest + 2) * sizeof *s->wstart);
    if (!(s->seen && s->pos && s->slot && s->rows && s->wstart)) return false;
    for (uint32_t k = 0; k < nc; k++) s->seen[k] = 0;
    for (uint32_t k = 0; k < n; k++) s->slot[k] = UINT32_MAX;
    return true;
}

bool spn__bsr_galerkin_refresh(const spn__bsr *a, const spn__bsr *p, const spn__bsr *r, spn__bsr *c, int threads,
                               spn__bsr_refresh **keep)
{
    const uint32_t n = a->rows, nc = p->cols, rows = r->rows;
    const double products = (double)a->start[a->rows] * p->start[p->rows] / (p->rows ? p->rows : 1);
    const int nt = products < PAR_MIN_PRODUCTS ? 1 : threads;
    const uint32_t chunk = galerkin_chunk(rows, nt), chunks = (rows + chunk - 1) / chunk;
    /* the vector path reads P's float32 blocks straight (the hierarchy's P once built) */
    const bool avx = SPN__AVX && spn__have_avx() && p->fval != NULL;
    uint32_t widest = 0; /* the most entries of R a chunk's rows have: a bound on its window's rows */
    for (uint32_t ch = 0; ch < chunks; ch++) {
        const uint32_t i0 = ch * chunk, i1 = i0 + chunk < rows ? i0 + chunk : rows;
        if (r->start[i1] - r->start[i0] > widest) widest = r->start[i1] - r->start[i0];
    }
    spn__bsr_refresh *k = keep ? *keep : NULL;
    if (k && !(k->threads == nt && k->n == n && k->nc == nc && k->widest == widest)) {
        spn__bsr_refresh_free(k); /* another level's or team's: not this call's */
        k = *keep = NULL;
    }
    if (!k) {
        k = calloc(1, sizeof *k + (size_t)nt * sizeof *k->s);
        if (!k) return false;
        k->threads = nt, k->n = n, k->nc = nc, k->widest = widest;
    }
    int bad = 0;
#pragma omp parallel num_threads(nt) reduction(+ : bad)
    {
        refresh_scratch *s = &k->s[spn__thread_num()];
        bool ok = scratch_ready(s, n, nc, widest, avx ? ACC : 9);
#pragma omp for schedule(dynamic, 1)
        for (uint32_t ch = 0; ch < chunks; ch++) {
            const uint32_t i0 = ch * chunk, i1 = i0 + chunk < rows ? i0 + chunk : rows;
            if (!ok) continue;
            gather_rows(r, i0, i1, s);
#if SPN__AVX
            if (avx) {
                ok = refresh_window_avx(a, p, s);
                for (uint32_t I = i0; ok && I < i1; I++) ok = refresh_row_avx(r, c, I, s);
                continue;
            }
#endif
            ok = refresh_window(a, p, s);
            for (uint32_t I = i0; ok && I < i1; I++) ok = refresh_row(r, c, I, s);
        }
        bad += !ok;
    }
    if (keep && !bad) *keep = k;
    else {
        spn__bsr_refresh_free(k);
        if (keep) *keep = NULL;
    }
    if (bad) return false;
    mirror_lower(c, threads);
    return true;
}

bool spn__bsr_transpose(const spn__bsr *a, spn__bsr *t, uint32_t **perm_out)
{
    memset(t, 0, sizeof *t);
    t->rows = a->cols;
    t->cols = a->rows;
    size_t nnz = a->start[a->rows];
    t->start = spn__big_calloc((size_t)t->rows + 1, sizeof *t->start);
    t->col = spn__big_alloc((nnz ? nnz : 1) * sizeof *t->col);
    uint32_t *perm = malloc((nnz ? nnz : 1) * sizeof *perm), *fill = calloc(t->rows ? t->rows : 1, sizeof *fill);
    if (!t->start || !t->col || !perm || !fill) {
        free(perm);
        free(fill);
        spn__bsr_free(t);
        return false;
    }
    for (size_t p = 0; p < nnz; p++) t->start[a->col[p] + 1]++;
    for (uint32_t r = 0; r < t->rows; r++) t->start[r + 1] += t->start[r];
    for (uint32_t i = 0; i < a->rows; i++) /* rows of A in order: each row of T sorted by column */
        for (uint32_t p = a->start[i]; p < a->start[i + 1]; p++) {
            uint32_t q = t->start[a->col[p]] + fill[a->col[p]]++;
            t->col[q] = i;
            perm[q] = p;
        }
    free(fill);
    t->tsrc = a;
    t->tperm = perm;
    *perm_out = perm;
    return true;
}

bool spn__bsr_transpose_round(spn__bsr *t, int threads)
{
    const uint32_t nnz = t->start[t->rows];
    const double *src = t->tsrc->val;
    const uint32_t *perm = t->tperm;
    float *d = spn__big_alloc((9 * (size_t)nnz + 1) * sizeof *d);
    if (!d) return false;
    (void)threads;
#pragma omp parallel for schedule(static) num_threads(nnz < SPN__BSR_PAR_MIN ? 1 : threads)
    for (uint32_t q = 0; q < nnz; q++) {
        const double *s = src + 9 * (size_t)perm[q];
        float *o = d + 9 * (size_t)q;
        o[0] = (float)s[0], o[1] = (float)s[3], o[2] = (float)s[6];
        o[3] = (float)s[1], o[4] = (float)s[4], o[5] = (float)s[7];
        o[6] = (float)s[2], o[7] = (float)s[5], o[8] = (float)s[8];
    }
    d[9 * (size_t)nnz] = 0; /* the spare a float block's last row reads */
    t->fval = d;
    t->tsrc = NULL;
    t->tperm = NULL;
    return true;
}

/* Row j's blocks and columns asked into the cache ahead of a backward
 * Gauss-Seidel sweep. The sweep reads each row's blocks upward but the rows
 * downward, and the hardware's prefetcher, which follows the forward sweep
 * from row to row, starts again at every row: measured on the 1M web (35
 * V-cycles, two threads) the backward sweeps of levels 1-3 took 0.18, 0.14
 * and 0.03 s against 0.12, 0.05 and 0.015 s forward; with row i - 1 asked
 * for while row i is summed, 0.13-0.14, 0.10 and 0.03 s (two or four rows
 * ahead: no better). The same bits: a prefetch changes no value. */
static inline void prefetch_row(const spn__bsr *a, uint32_t j)
{
    const size_t size = a->val ? 9 * sizeof(double) : 9 * sizeof(float);
    const char *v = a->val ? (const char *)a->val : (const char *)a->fval;
    if (!v) return;
    const char *p0 = v + size * a->start[j], *p1 = v + size * a->start[j + 1];
    for (const char *q = p0; q < p1; q += 64) __builtin_prefetch(q);
    __builtin_prefetch(a->col + a->start[j]);
}

/* Block rows times a vector: s = sum over the row's blocks from entry p0 of
 * A_ij x_j. Each of the nine products of a block has its own running sums
 * over the row (lane sums, as a 256-bit register holds them), two of them,
 * for the row's even and odd blocks, added at the end (the additions into
 * one sum wait on each other; two sums overlap: on the 1M web's coarse
 * levels, up to 145 blocks a row, the solve 29.3 -> 28.1 s), and a row's
 * three numbers are (s_r0 + s_r1) + s_r2 at the end: the scalar loop and the
 * AVX one add in this same order, so the bits do not depend on which runs.
 * (The sums in block order, m0 v0 + m1 v1 + m2 v2 added to s each block,
 * took half as many vector instructions again with AVX but would give other
 * bits on a machine without it.) */
static inline void row_sum_split(const spn__bsr *a, uint32_t i, uint32_t p0, const double *x, const double *xo,
                                 uint32_t lo, uint32_t span, double *s)
{
    double l[2][9] = {{0, 0, 0, 0, 0, 0, 0, 0, 0}, {0, 0, 0, 0, 0, 0, 0, 0, 0}};
    for (uint32_t p = p0; p < a->start[i + 1]; p++) {
        const uint32_t c = a->col[p];
        const double *v = (c - lo < span ? x : xo) + 3 * (size_t)c;
        double m[9], *o = l[(p - p0) & 1u];
        for (int k = 0; k < 9; k++) m[k] = a->val ? a->val[9 * (size_t)p + k] : (double)a->fval[9 * (size_t)p + k];
        for (int r = 0; r < 3; r++) {
            o[3 * r] += m[3 * r] * v[0];
            o[3 * r + 1] += m[3 * r + 1] * v[1];
            o[3 * r + 2] += m[3 * r + 2] * v[2];
        }
    }
    for (int r = 0; r < 3; r++)
        s[r] = (l[0][3 * r] + l[1][3 * r] + (l[0][3 * r + 1] + l[1][3 * r + 1])) + (l[0][3 * r + 2] + l[1][3 * r + 2]);
}

static inline void row_sum(const spn__bsr *a, uint32_t i, uint32_t p0, const double *x, double *s)
{
    row_sum_split(a, i, p0, x, x, 0, UINT32_MAX, s);
}

#if SPN__AVX
/* One block's three rows as vectors: the first two read four numbers wide
 * (the spare lane meets a zero in v), the last in two and one from doubles,
 * four wide from floats (fval has a spare number at its end). */
#define ROWS_D(m, r0, r1, r2)                                                                                        \
    __m256d r0 = _mm256_loadu_pd(m), r1 = _mm256_loadu_pd((m) + 3);                                                 \
    __m256d r2 = _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd((m) + 6)), _mm_load_sd((m) + 8), 1)
#define ROWS_F(m, r0, r1, r2)                                                                                        \
    __m256d r0 = _mm256_cvtps_pd(_mm_loadu_ps(m)), r1 = _mm256_cvtps_pd(_mm_loadu_ps((m) + 3));                     \
    __m256d r2 = _mm256_cvtps_pd(_mm_loadu_ps((m) + 6))

#define ROW_SUM_AVX(T, ROWS)                                                                                            \
    __m256d l0 = _mm256_setzero_pd(), l1 = l0, l2 = l0, k0 = l0, k1 = l0, k2 = l0;                                   \
    uint32_t p = p0;                                                                                                 \
    const uint32_t p1 = a->start[i + 1];                                                                             \
    for (; p < p1; p++) {                                                                                            \
        const T *m = vals + 9 * (size_t)p;                                                                           \
        const double *v = SRC_OF(a->col[p]) + 3 * (size_t)a->col[p];                                                 \
        __m256d v4 = _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(v)), _mm_load_sd(v + 2), 1);          \
        ROWS(m, m0, m1, m2);                                                                                         \
        l0 = _mm256_add_pd(l0, _mm256_mul_pd(m0, v4));                                                               \
        l1 = _mm256_add_pd(l1, _mm256_mul_pd(m1, v4));                                                               \
        l2 = _mm256_add_pd(l2, _mm256_mul_pd(m2, v4));                                                               \
        if (++p == p1) break;                                                                                        \
        m = vals + 9 * (size_t)p, v = SRC_OF(a->col[p]) + 3 * (size_t)a->col[p];                                     \
        v4 = _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(v)), _mm_load_sd(v + 2), 1);                  \
        ROWS(m, n0, n1, n2);                                                                                         \
        k0 = _mm256_add_pd(k0, _mm256_mul_pd(n0, v4));                                                               \
        k1 = _mm256_add_pd(k1, _mm256_mul_pd(n1, v4));                                                               \
        k2 = _mm256_add_pd(k2, _mm256_mul_pd(n2, v4));                                                               \
    }                                                                                                                \
    l0 = _mm256_add_pd(l0, k0), l1 = _mm256_add_pd(l1, k1), l2 = _mm256_add_pd(l2, k2);                              \
    double t[12];                                                                                                    \
    _mm256_storeu_pd(t, l0), _mm256_storeu_pd(t + 4, l1), _mm256_storeu_pd(t + 8, l2);                               \
    for (int r = 0; r < 3; r++) s[r] = (t[4 * r] + t[4 * r + 1]) + t[4 * r + 2]

/* the vector column c is read from: x inside [lo, lo + span), xo outside */
#define SRC_OF(c) ((c) - lo < span ? x : xo)

/* row_sum_split on 256-bit vectors: lanes (m_r0 v0, m_r1 v1, m_r2 v2, 0). */
__attribute__((target("avx"))) static inline void row_sum_split_avx(const spn__bsr *a, uint32_t i, uint32_t p0,
                                                                     const double *x, const double *xo, uint32_t lo,
                                                                     uint32_t span, double *s)
{
    if (a->val) {
        const double *vals = a->val;
        ROW_SUM_AVX(double, ROWS_D);
    } else {
        const float *vals = a->fval;
        ROW_SUM_AVX(float, ROWS_F);
    }
}

/* row_sum on 256-bit vectors (xo = x: the compiler drops the choice) */
__attribute__((target("avx"))) static inline void row_sum_avx(const spn__bsr *a, uint32_t i, uint32_t p0,
                                                               const double *x, double *s)
{
    row_sum_split_avx(a, i, p0, x, x, 0, UINT32_MAX, s);
}

/* y = A x (add: y += A x) on rows [r0, r1), or r = b - A x when b is given. */
__attribute__((target("avx"))) static void rows_avx(const spn__bsr *a, const double *b, const double *x, double *y,
                                                    bool add, int threads)
{
    (void)threads; /* (used by OpenMP pragmas only) */
#pragma omp parallel for schedule(static) num_threads(spn__bsr_team(a, threads))
    for (uint32_t i = 0; i < a->rows; i++) {
        double s[3], *o = y + 3 * (size_t)i;
        row_sum_avx(a, i, a->start[i], x, s);
        if (b) o[0] = b[3 * i] - s[0], o[1] = b[3 * i + 1] - s[1], o[2] = b[3 * i + 2] - s[2];
        else if (add) o[0] += s[0], o[1] += s[1], o[2] += s[2];
        else o[0] = s[0], o[1] = s[1], o[2] = s[2];
    }
}

__attribute__((target("avx"))) static void gauss_seidel_part_avx(const spn__bsr *a, const double *dinv,
                                                                 const double *b, double *x, const double *xo,
                                                                 uint32_t lo, uint32_t hi, bool forward)
{
    for (uint32_t k = lo; k < hi; k++) {
        uint32_t i = forward ? k : hi - 1 - (k - lo);
        double s[3];
        if (!forward && i > lo) prefetch_row(a, i - 1);
        row_sum_split_avx(a, i, a->start[i] + 1, x, xo, lo, hi - lo, s); /* the diagonal is first */
        s[0] = b[3 * i] - s[0], s[1] = b[3 * i + 1] - s[1], s[2] = b[3 * i + 2] - s[2];
        spn__sym_mul(dinv + 6 * (size_t)i, s, x + 3 * (size_t)i);
    }
}
#endif

static void rows(const spn__bsr *a, const double *b, const double *x, double *y, bool add, int threads)
{
#if SPN__AVX
    if (spn__have_avx()) {
        rows_avx(a, b, x, y, add, threads);
        return;
    }
#endif
#pragma omp parallel for schedule(static) num_threads(spn__bsr_team(a, threads))
    for (uint32_t i = 0; i < a->rows; i++) {
        double s[3], *o = y + 3 * (size_t)i;
        row_sum(a, i, a->start[i], x, s);
        if (b) o[0] = b[3 * i] - s[0], o[1] = b[3 * i + 1] - s[1], o[2] = b[3 * i + 2] - s[2];
        else if (add) o[0] += s[0], o[1] += s[1], o[2] += s[2];
        else o[0] = s[0], o[1] = s[1], o[2] = s[2];
    }
}

void spn__bsr_apply(const spn__bsr *a, const double *x, double *y, bool add, int threads)
{
    rows(a, NULL, x, y, add, threads);
}

void spn__bsr_residual(const spn__bsr *a, const double *b, const double *x, double *r, int threads)
{
    rows(a, b, x, r, false, threads);
}

static void gauss_seidel_part(const spn__bsr *a, const double *dinv, const double *b, double *x, const double *xo,
                              uint32_t lo, uint32_t hi, bool forward)
{
#if SPN__AVX
    if (spn__have_avx()) {
        gauss_seidel_part_avx(a, dinv, b, x, xo, lo, hi, forward);
        return;
    }
#endif
    for (uint32_t k = lo; k < hi; k++) {
        uint32_t i = forward ? k : hi - 1 - (k - lo);
        double s[3];
        if (!forward && i > lo) prefetch_row(a, i - 1);
        row_sum_split(a, i, a->start[i] + 1, x, xo, lo, hi - lo, s); /* the diagonal is first */
        s[0] = b[3 * i] - s[0], s[1] = b[3 * i + 1] - s[1], s[2] = b[3 * i + 2] - s[2];
        spn__sym_mul(dinv + 6 * (size_t)i, s, x + 3 * (size_t)i);
    }
}

uint32_t spn__bsr_gs_parts(const spn__bsr *a)
{
    uint32_t k = 1;
    while (2 * k <= SPN__BSR_GS_MAX_PARTS && (uint64_t)a->rows >= 2 * (uint64_t)k * SPN__BSR_GS_PART_ROWS) k *= 2;
    return k;
}

void spn__bsr_gauss_seidel(const spn__bsr *a, const double *dinv, const double *b, double *x, bool forward,
                           double *scratch, int threads)
{
    const uint32_t n = a->rows, parts = spn__bsr_gs_parts(a);
    if (parts == 1) {
        gauss_seidel_part(a, dinv, b, x, x, 0, n, forward);
        return;
    }
    /* the other parts' values as they were when the sweep began */
    memcpy(scratch, x, 3 * (size_t)n * sizeof *x);
    const int team = threads < (int)parts ? threads : (int)parts;
    (void)team; /* (used by an OpenMP pragma only) */
#pragma omp parallel for schedule(static) num_threads(team)
    for (uint32_t q = 0; q < parts; q++)
        gauss_seidel_part(a, dinv, b, x, scratch, (uint32_t)((uint64_t)n * q / parts),
                          (uint32_t)((uint64_t)n * (q + 1) / parts), forward);
}

/* Sum of a[q] b[q], q < n, in four running sums (fixed order, so the same
 * bits every time): the additions of one sum wait on each other, four
 * overlap. The slide matrix of the 1M web (1,999 rows) is factored in a
 * quarter of the time. */
static double dot4(const double *a, const double *b, size_t n)
{
    double s0 = 0, s1 = 0, s2 = 0, s3 = 0;
    size_t q = 0;
    for (; q + 4 <= n; q += 4) {
        s0 += a[q] * b[q];
        s1 += a[q + 1] * b[q + 1];
        s2 += a[q + 2] * b[q + 2];
        s3 += a[q + 3] * b[q + 3];
    }
    for (; q < n; q++) s0 += a[q] * b[q];
    return (s0 + s1) + (s2 + s3);
}

/* Four numbers on one vector (GCC vector extension: SSE2 pairs, AVX, ...;
 * elementwise IEEE operations, so the same bits as the scalar code). */
typedef double spn__v4 __attribute__((vector_size(4 * sizeof(double))));

/* (a macro, not a function: a vector returned by value would depend on the
 * clone's instruction set, -Wpsabi) */
#define LOAD4(v, p) memcpy(&(v), (p), sizeof(v))

/* Row i's entries in columns k0 .. k0 + 3 (k0 a multiple of 4, those
 * columns' diagonal in d), from the four columns' running sums over the
 * row's first k0 numbers (s, lane l: the products of q = l mod 4): dot4's
 * sum, its remainder being the entries just found. */
static void panel_finish(double *row, const double *const *b, size_t k0, const spn__v4 *s, const double *d)
{
    for (size_t r = 0; r < 4; r++) {
        double t = s[r][0];
        for (size_t q = k0; q < k0 + r; q++) t += row[q] * b[r][q];
        const double dot = (t + s[r][1]) + (s[r][2] + s[r][3]);
        row[k0 + r] = (row[k0 + r] - dot) / d[r];
    }
}

/* Rows i and j (below the panel of columns k0 .. k0 + 3; j = i for one row
 * alone): the four
 * columns of each share the loop over [0, k0), keeping dot4's four running
 * sums (so dot4's bits), and the panel's rows are read once for two rows,
 * each row once for four columns, instead of eight times. */
SPN__KERNEL static void panel_rows(double *f, size_t n, size_t i, size_t j, size_t k0, const double *d)
{
    const double *a = f + i * n, *c = f + j * n, *b[4] = {f + k0 * n, f + (k0 + 1) * n, f + (k0 + 2) * n, f + (k0 + 3) * n};
    spn__v4 s[4] = {{0, 0, 0, 0}, {0, 0, 0, 0}, {0, 0, 0, 0}, {0, 0, 0, 0}}, t[4];
    memcpy(t, s, sizeof t);
    for (size_t q = 0; q < k0; q += 4) {
        spn__v4 u, v, w0, w1, w2, w3;
        LOAD4(u, a + q), LOAD4(v, c + q), LOAD4(w0, b[0] + q), LOAD4(w1, b[1] + q), LOAD4(w2, b[2] + q),
            LOAD4(w3, b[3] + q);
        s[0] += u * w0, s[1] += u * w1, s[2] += u * w2, s[3] += u * w3;
        t[0] += v * w0, t[1] += v * w1, t[2] += v * w2, t[3] += v * w3;
    }
    panel_finish(f + i * n, b, k0, s, d);
    if (j != i) panel_finish(f + j * n, b, k0, t, d);
}

/* Cholesky L L^T of the dense symmetric n x n matrix f (row-major; L into
 * its lower triangle), column by column in panels of four: a panel's own
 * rows first, then every row below it four columns at a time
 * (panel_row), pairs of rows shared among the threads from DENSE_PAR_MIN
 * rows (each pair depends only on the finished panel). The same bits as one
 * column at a time with dot4, on any thread count (the matrix of thread
 * slides: 1,999 rows on the 1M web, once a Newton step). False if f is not
 * positive definite. */
#define DENSE_PAR_MIN 512u

bool spn__dense_cholesky(double *f, size_t n, int threads)
{
    const int nt = n < DENSE_PAR_MIN ? 1 : threads;
    (void)nt; /* (used by OpenMP pragmas only) */
    for (size_t k0 = 0; k0 < n; k0 += 4) {
        const size_t k1 = k0 + 4 <= n ? k0 + 4 : n;
        double d[4];
        for (size_t k = k0; k < k1; k++) {
            double dk = f[k * n + k] - dot4(f + k * n, f + k * n, k);
            if (!(dk > 0)) return false;
            dk = sqrt(dk);
            f[k * n + k] = d[k - k0] = dk;
            for (size_t i = k + 1; i < k1; i++) f[i * n + k] = (f[i * n + k] - dot4(f + i * n, f + k * n, k)) / dk;
        }
        if (k1 - k0 < 4) break; /* the last, narrower panel has no rows below it */
        const size_t pairs = (n - k1 + 1) / 2;
#pragma omp parallel for schedule(static) num_threads(n - k1 < 64 ? 1 : nt)
        for (size_t p = 0; p < pairs; p++) {
            const size_t i = k1 + 2 * p;
            panel_rows(f, n, i, i + 1 < n ? i + 1 : i, k0, d);
        }
    }
    return true;
}

/* The threaded solve's rows a block (a multiple of dot4's four lanes), and
 * the order below which it stays on one thread. */
#define SOLVE_BLOCK 128u
#define SOLVE_PAR_MIN 512u

/* dot4's four running sums carried on over [q0, q1), both multiples of 4 */
static inline void dot4_lanes(const double *a, const double *b, size_t q0, size_t q1, double *s)
{
    double s0 = s[0], s1 = s[1], s2 = s[2], s3 = s[3];
    for (size_t q = q0; q < q1; q += 4) {
        s0 += a[q] * b[q];
        s1 += a[q + 1] * b[q + 1];
        s2 += a[q + 2] * b[q + 2];
        s3 += a[q + 3] * b[q + 3];
    }
    s[0] = s0, s[1] = s1, s[2] = s2, s[3] = s3;
}

/* On a team, in blocks of SOLVE_BLOCK rows, with the one-thread loops' bits.
 * L y = b: the team sums each block row's four lanes over the columns of
 * the blocks before (the first iterations of its dot4), then one thread
 * finishes the rows in order. L^T x = y: one thread finishes a block's rows
 * from the last, then the team subtracts them from the entries before the
 * block, each entry's subtractions still in descending row order. The 1M
 * web's slides (1,999 unknowns, twice a V-cycle): 6.9-7.8 -> 4.3 ms a
 * cycle on two threads. */
void spn__dense_cholesky_solve(const double *f, size_t n, const double *b, double *x, int threads)
{
    const int nt = n < SOLVE_PAR_MIN ? 1 : threads;
    if (nt < 2) {
        for (size_t i = 0; i < n; i++) x[i] = (b[i] - dot4(f + i * n, x, i)) / f[i * n + i]; /* L y = b */
        for (size_t i = n; i-- > 0;) { /* L^T x = y by rows of L (contiguous), not its columns */
            x[i] /= f[i * n + i];
            for (size_t q = 0; q < i; q++) x[q] -= f[i * n + q] * x[i];
        }
        return;
    }
    double lanes[4 * SOLVE_BLOCK];
#pragma omp parallel num_threads(nt)
    {
        const size_t t = (size_t)spn__thread_num(), team = (size_t)spn__thread_count();
        for (size_t i0 = 0; i0 < n; i0 += SOLVE_BLOCK) {
            const size_t i1 = i0 + SOLVE_BLOCK < n ? i0 + SOLVE_BLOCK : n, rows = i1 - i0;
            for (size_t i = i0 + rows * t / team; i < i0 + rows * (t + 1) / team; i++) {
                double *s = lanes + 4 * (i - i0);
                s[0] = s[1] = s[2] = s[3] = 0;
                dot4_lanes(f + i * n, x, 0, i0, s);
            }
#pragma omp barrier
#pragma omp single
            for (size_t i = i0; i < i1; i++) {
                double *s = lanes + 4 * (i - i0);
                const size_t q4 = i & ~(size_t)3;
                dot4_lanes(f + i * n, x, i0, q4, s);
                double s0 = s[0];
                for (size_t q = q4; q < i; q++) s0 += f[i * n + q] * x[q];
                x[i] = (b[i] - ((s0 + s[1]) + (s[2] + s[3]))) / f[i * n + i];
            }
        }
        for (size_t i1 = n; i1 > 0;) {
            const size_t i0 = i1 > SOLVE_BLOCK ? i1 - SOLVE_BLOCK : 0;
#pragma omp single
            for (size_t i = i1; i-- > i0;) {
                x[i] /= f[i * n + i];
                for (size_t q = i0; q < i; q++) x[q] -= f[i * n + q] * x[i];
            }
            const size_t q0 = i0 * t / team, q1 = i0 * (t + 1) / team;
            for (size_t i = i1; i-- > i0;)
                for (size_t q = q0; q < q1; q++) x[q] -= f[i * n + q] * x[i];
#pragma omp barrier
            i1 = i0;
        }
    }
}
