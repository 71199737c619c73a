/* Sparse Cholesky factorisation of a symmetric positive definite matrix of
 * 3x3 blocks on a particle graph (sparse_chol.c): the implicit step's
 * preconditioner on webs small enough to factor (implicit_mg.c).
 *
 * The input has the layout of the equilibrium system (spn__eq): n block rows,
 * row i's neighbours adj_other[start[i] .. start[i + 1]) (negative: a fixed
 * particle, skipped), a symmetric diagonal block of 6 numbers per row (xx,
 * yy, zz, xy, xz, yz) and a symmetric off-diagonal block of 6 per neighbour
 * entry; several entries between one pair are summed. Both directions of a
 * pair must be present, with the same block.
 *
 * The particles are ordered by minimum degree, the pattern of L is found
 * once (spn__chol_analyze), and each factorisation (spn__chol_factor) fills
 * it again from new values. Everything runs on one thread in a fixed order:
 * the same bits on any thread count. */
#ifndef SPN_SPARSE_CHOL_H
#define SPN_SPARSE_CHOL_H
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

typedef struct spn__chol spn__chol;

/* The ordering and the pattern of L. NULL when out of memory or when L
 * would hold more than max_entries numbers. */
spn__chol *spn__chol_analyze(uint32_t n, const uint32_t *start, const int32_t *adj_other, size_t max_entries);
/* L L^T = A from the values (diag: 6 n, offd: 6 per neighbour entry, in the
 * analysed pattern); false when A is not positive definite (then the factor
 * must not be used until a factorisation succeeds). */
bool spn__chol_factor(spn__chol *c, const double *diag, const double *offd);
/* x = A^-1 b (3 n each; x may be b). */
void spn__chol_solve(const spn__chol *c, const double *b, double *x);
/* The same with particle i's three numbers of b and x at ids[i] (3 ids[i]
 * on): a solve for the rows of a larger vector, without copying them out
 * and back (x may be b). */
void spn__chol_solve_at(const spn__chol *c, const uint32_t *ids, const double *b, double *x);
/* Numbers in L (its diagonal included). */
size_t spn__chol_entries(const spn__chol *c);
void spn__chol_free(spn__chol *c);

#endif
