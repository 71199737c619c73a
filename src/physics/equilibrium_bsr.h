/* Block sparse rows (3x3 blocks) for the equilibrium multigrid: the matrices
 * of every level, the prolongators and their transposes.
 *
 * A block is 9 doubles, row-major. In a square level matrix the diagonal
 * block is the first of its row (the smoothers and the coarse solve find it
 * there). Every loop writes only its own rows, and every row is summed in a
 * fixed order, so results are the same bits for any thread count. */
#ifndef SPN_EQUILIBRIUM_BSR_H
#define SPN_EQUILIBRIUM_BSR_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* 256-bit vector paths (the Galerkin products, the coarse levels' row sums,
 * the line sweep) for GCC and Clang on x86-64, chosen at run time so the
 * build needs no -march; each does the scalar code's operations in the same
 * order, without fused multiply-adds, so both give the same bits. Build with
 * -DSPN_NO_AVX to leave them out. */
#if defined(__GNUC__) && defined(__x86_64__) && !defined(SPN_NO_AVX)
#define SPN__AVX 1
#include <immintrin.h>
static inline bool spn__have_avx(void) { return __builtin_cpu_supports("avx"); }
#else
#define SPN__AVX 0
static inline bool spn__have_avx(void) { return false; }
#endif

typedef struct spn__bsr {
    uint32_t rows, cols;
    uint32_t *start; /* rows + 1 */
    uint32_t *col;   /* start[rows] */
    double *val;     /* 9 * start[rows], or NULL once rounded to fval */
    float *fval;     /* 9 * start[rows] + 1 (spn__bsr_round), or NULL */
    /* neither: a transpose's values read from its source (spn__bsr_transpose),
     * block k being the transpose of tsrc's float64 block tperm[k] */
    const struct spn__bsr *tsrc;
    const uint32_t *tperm;
    /* a window onto rows [base, rows) of a larger matrix: row r is stored
     * as row r - base (0 for a whole matrix; spn__bsr_galerkin_ap) */
    uint32_t base;
    /* or, with no val, fval or tsrc: block k formed on demand, blk(blk_ctx,
     * k, tmp) (the finest level of a spring system, from its springs:
     * equilibrium_mg.c) */
    const double *(*blk)(const void *blk_ctx, size_t k, double *tmp);
    const void *blk_ctx;
} spn__bsr;

/* d = s^T for 3x3 blocks (nine numbers, row-major) of either precision */
#define SPN__BLK_TRANSPOSE(d, s)                                                                                     \
    ((d)[0] = (s)[0], (d)[1] = (s)[3], (d)[2] = (s)[6], (d)[3] = (s)[1], (d)[4] = (s)[4], (d)[5] = (s)[7],        \
     (d)[6] = (s)[2], (d)[7] = (s)[5], (d)[8] = (s)[8])

/* Block p's nine numbers: from val, from blk, from fval, or from a
 * transpose's source (tsrc, tperm: spn__bsr_transpose) through tmp. */
static inline const double *spn__bsr_block(const spn__bsr *m, size_t p, double *tmp)
{
    if (m->val) return m->val + 9 * p;
    if (m->blk) return m->blk(m->blk_ctx, p, tmp);
    if (m->fval) {
        for (int k = 0; k < 9; k++) tmp[k] = m->fval[9 * p + k];
        return tmp;
    }
    const double *s = m->tsrc->val + 9 * (size_t)m->tperm[p];
    SPN__BLK_TRANSPOSE(tmp, s);
    return tmp;
}

void spn__bsr_free(spn__bsr *a);
/* Blocks from which a loop over a matrix's rows shares them out. */
#define SPN__BSR_PAR_MIN 65536.0
/* The team for a loop over the rows of a: threads, or 1 below SPN__BSR_PAR_MIN blocks. */
static inline int spn__bsr_team(const spn__bsr *a, int threads)
{
    return (double)a->start[a->rows] < SPN__BSR_PAR_MIN ? 1 : threads;
}
/* Pattern and values of C = A B (C's square-matrix diagonal first when
 * diag_first), a temporary (plain malloc). false on out of memory. (The
 * setup forms A P through spn__bsr_galerkin_ap; the tests keep this as its
 * reference.) */
bool spn__bsr_mul(const spn__bsr *a, const spn__bsr *b, spn__bsr *c, bool diag_first, int threads);
/* The Galerkin product C = R (A P), R = P^T, A symmetric: diagonal first,
 * the blocks above the diagonal computed and those below mirrored from them
 * (C exactly symmetric). false on out of memory. */
bool spn__bsr_galerkin(const spn__bsr *r, const spn__bsr *ap, spn__bsr *c, int threads);
/* The same from A and P, without holding all of A P: C's rows go in chunks,
 * each with the rows of A P it reads computed into a window that is used
 * again (every row of A P is its own sum, so the same bits as forming A P
 * whole and calling spn__bsr_galerkin, which it falls back to when the
 * windows would overlap too much). */
bool spn__bsr_galerkin_ap(const spn__bsr *a, const spn__bsr *p, const spn__bsr *r, spn__bsr *c, int threads);
/* C's values again from A's current ones, C = R (A P) with the patterns of
 * C, P and R kept (the hierarchy of a later Newton step), C's rows in
 * chunks, each forming just the rows of A P its rows of R read: C's blocks are
 * written as float32 (fval; C must have been rounded), the blocks of A, P
 * and R read in whatever form they have (spn__bsr_block). Each row of C is
 * summed in a fixed order: the same bits on any team. keep: NULL, or where
 * the threads' scratch (the windows of A P, the row sums) is kept for the
 * next call on the same level, created on the first; free it with
 * spn__bsr_refresh_free. false on out of memory. */
typedef struct spn__bsr_refresh spn__bsr_refresh;
bool spn__bsr_galerkin_refresh(const spn__bsr *a, const spn__bsr *p, const spn__bsr *r, spn__bsr *c, int threads,
                               spn__bsr_refresh **keep);
void spn__bsr_refresh_free(spn__bsr_refresh *keep);
/* T = A^T (A in float64): its pattern, and perm[k], the entry of A that
 * T's entry k comes from. T's values are read from A through perm (no copy:
 * the Galerkin product is the only reader of R = P^T in float64) until
 * spn__bsr_transpose_round gives T its own float32 blocks; A must outlive
 * that, and perm too. */
bool spn__bsr_transpose(const spn__bsr *a, spn__bsr *t, uint32_t **perm);
/* T's blocks rounded to float32 from its source (as spn__bsr_round would
 * from a float64 copy: the same floats); false on out of memory. */
bool spn__bsr_transpose_round(spn__bsr *t, int threads);
/* Replace the values by float32 copies (val becomes fval): the multigrid's levels
 * below the finest, its prolongators and restrictions, once built, are only
 * multiplied by vectors, and a preconditioner does not need them exact (see
 * equilibrium_mg.c). The products below read either; their sums stay float64.
 * Done in place: it needs no memory. */
void spn__bsr_round(spn__bsr *a);
/* y = A x (add: y += A x). */
void spn__bsr_apply(const spn__bsr *a, const double *x, double *y, bool add, int threads);
/* r = b - A x. */
void spn__bsr_residual(const spn__bsr *a, const double *b, const double *x, double *r, int threads);
/* One block Gauss-Seidel sweep in place, rows in order (forward) or reverse;
 * dinv: 6 per row, the inverted (symmetric) diagonal blocks.
 *
 * A matrix of 2 SPN__BSR_GS_PART_ROWS rows or more is swept in parts (a
 * power of two of them, at most SPN__BSR_GS_MAX_PARTS, each at least
 * SPN__BSR_GS_PART_ROWS rows), each part on its own and in parallel: a row
 * reads its own part's values as the sweep leaves them and the other parts'
 * as they were when it began (copied into scratch, 3 rows doubles). The parts
 * depend only on the matrix, so the result is the same bits on any team. */
#define SPN__BSR_GS_PART_ROWS 2048u
#define SPN__BSR_GS_MAX_PARTS 8u
uint32_t spn__bsr_gs_parts(const spn__bsr *a);
void spn__bsr_gauss_seidel(const spn__bsr *a, const double *dinv, const double *b, double *x, bool forward,
                           double *scratch, int threads);

/* Dense Cholesky A = L L^T in place: f is n x n row-major, its lower
 * triangle read and overwritten with L. False when A is not positive
 * definite. (The multigrid's coarsest level and the thread slides.) */
bool spn__dense_cholesky(double *f, size_t n, int threads);
/* Solves L L^T x = b with a factor from spn__dense_cholesky; x may be b.
 * The same bits on any team (threads). */
void spn__dense_cholesky_solve(const double *f, size_t n, const double *b, double *x, int threads);

static inline void spn__blk_mul_vec(const double *m, const double *v, double *o)
{
    o[0] = m[0] * v[0] + m[1] * v[1] + m[2] * v[2];
    o[1] = m[3] * v[0] + m[4] * v[1] + m[5] * v[2];
    o[2] = m[6] * v[0] + m[7] * v[1] + m[8] * v[2];
}
/* c += a b. The sums are formed in locals and c written once: with c
 * possibly aliasing a or b the compiler would otherwise load and store c
 * nine times (the Galerkin products of the multigrid's setup, where this is
 * the inner loop, ran 1.6x slower that way). c must not alias a or b. */
static inline void spn__blk_mul_add(const double *restrict a, const double *restrict b, double *restrict c)
{
    for (int r = 0; r < 3; r++) {
        const double a0 = a[3 * r], a1 = a[3 * r + 1], a2 = a[3 * r + 2];
        double c0 = c[3 * r], c1 = c[3 * r + 1], c2 = c[3 * r + 2];
        c0 += a0 * b[0];
        c1 += a0 * b[1];
        c2 += a0 * b[2];
        c0 += a1 * b[3];
        c1 += a1 * b[4];
        c2 += a1 * b[5];
        c0 += a2 * b[6];
        c1 += a2 * b[7];
        c2 += a2 * b[8];
        c[3 * r] = c0, c[3 * r + 1] = c1, c[3 * r + 2] = c2;
    }
}

#endif
