/* A batched complex FFT for internal use (fft.c): many sequences of one
 * length n transformed together, stored split (real and imaginary parts in
 * separate arrays) and by rows, so that the columns of a row are the same
 * element of successive sequences and every loop runs along them. Results
 * are the same bits whichever columns a call covers. */
#ifndef SPN_FFT_H
#define SPN_FFT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

typedef struct spn__fft spn__fft;

/* How a plan transforms: by its factors (radix 4, 2, 3, 5 butterflies
 * written out, any other prime factor p by a direct DFT of that length, p
 * operations an element), or by Bluestein's chirp transform (a convolution
 * done by two transforms of a length m >= 2 n - 1 with no factor above 5:
 * a few times n log n whatever n's factors). AUTO takes the one estimated
 * cheaper. */
typedef enum { SPN__FFT_AUTO, SPN__FFT_RADIX, SPN__FFT_CHIRP } spn__fft_kind;

/* A plan for transforms of length n >= 1 (its twiddle tables, and for a
 * chirp plan the chirp, its spectrum and the plan of length m). NULL when
 * out of memory or n == 0. spn__fft_plan(n) is spn__fft_plan_kind(n, SPN__FFT_AUTO). */
spn__fft *spn__fft_plan(uint32_t n);
spn__fft *spn__fft_plan_kind(uint32_t n, spn__fft_kind kind);
void spn__fft_free(spn__fft *p);
uint32_t spn__fft_length(const spn__fft *p);
bool spn__fft_is_chirp(const spn__fft *p);
/* Rows of scratch spn__fft_run needs in each of tre, tim: n, or 2 m for a chirp plan. */
size_t spn__fft_scratch_rows(const spn__fft *p);

/* Transform, in place, the columns b0 <= b < b1 of a batch of complex
 * sequences stored split by rows: element k of sequence b is
 * re[k * stride + b] + i im[k * stride + b], k = 0..n-1.
 * sign -1: X_j = sum_k x_k exp(-2 pi i j k / n); sign +1: exp(+2 pi i j k / n);
 * unnormalised either way. tre, tim: scratch of at least
 * spn__fft_scratch_rows(p) * stride doubles each (only columns b0..b1-1 are touched in every array). Columns are
 * independent, so two threads may run disjoint column ranges of the same
 * arrays at once. */
void spn__fft_run(const spn__fft *p, int sign, double *re, double *im, size_t stride, size_t b0, size_t b1, double *tre,
                  double *tim);

#endif
