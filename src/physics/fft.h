/* A batched complex FFT for internal use (fft.c): many sequences of one
 * length n transformed together, stored split (real and imaginary parts in
 * separate arrays) and by rows, so that the columns of a row are the same
 * element of successive sequences and every loop runs along them. Results
 * are the same bits whichever columns a call covers. */
#ifndef SPN_FFT_H
#define SPN_FFT_H

#include <stddef.h>
#include <stdint.h>

typedef struct spn__fft spn__fft;

/* A plan for transforms of length n >= 1: its factors (radix 4, 2, 3, 5
 * butterflies written out, any other prime factor by a direct DFT of that
 * length) and twiddle tables. NULL when out of memory or n == 0. */
spn__fft *spn__fft_plan(uint32_t n);
void spn__fft_free(spn__fft *p);
uint32_t spn__fft_length(const spn__fft *p);

/* The largest prime factor of n (1 for n == 1): the caller's cost estimate. */
uint32_t spn__fft_largest_factor(uint32_t n);

/* Transform, in place, the columns b0 <= b < b1 of a batch of complex
 * sequences stored split by rows: element k of sequence b is
 * re[k * stride + b] + i im[k * stride + b], k = 0..n-1.
 * sign -1: X_j = sum_k x_k exp(-2 pi i j k / n); sign +1: exp(+2 pi i j k / n);
 * unnormalised either way. tre, tim: scratch of at least n * stride doubles
 * each (only columns b0..b1-1 are touched in every array). Columns are
 * independent, so two threads may run disjoint column ranges of the same
 * arrays at once. */
void spn__fft_run(const spn__fft *p, int sign, double *re, double *im, size_t stride, size_t b0, size_t b1, double *tre,
                  double *tim);

#endif
