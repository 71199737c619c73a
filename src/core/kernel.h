/* SPN__KERNEL: a loop compiled for several instruction sets; SPN__INLINE:
 * a helper such a loop calls. */
#ifndef SPN_CORE_KERNEL_H
#define SPN_CORE_KERNEL_H

/* A kernel also compiled for AVX-512 and for AVX2 with FMA (x86-64-v3),
 * chosen when the program loads (GCC on x86-64 with ifunc support). Every
 * operation is correctly rounded at any vector width, so all versions give
 * the same bits: -ffp-contract=off keeps the compiler from fusing a multiply
 * and an add on its own, and the fused multiply-adds the source asks for
 * (fma(), the explicit steps' particle update) are exact roundings too. The
 * two clones do them in one instruction; the default version calls libm's
 * fma, correct and slow, on the processors from before 2013 that lack it. */
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__) && !defined(SPN_NO_CLONES)
#define SPN__KERNEL __attribute__((target_clones("avx512f", "arch=x86-64-v3", "default")))
/* One version of a kernel, for code that picks the version itself at run
 * time (spn__lattice_rk4_avx2): SPN__AVX2 compiles a function for AVX2 and
 * FMA. */
#define SPN__AVX2 __attribute__((target("avx2,fma")))
#else
#define SPN__KERNEL
#endif

/* A helper of the kernels: inlined into each caller at every optimisation
 * level, so that each SPN__KERNEL version gets its own copy, with that
 * version's vectors and fused multiply-adds. A helper left out of line is
 * compiled once, as the default version: SSE2 loops and a libm call for
 * each fma(). GCC 12 at -O2 left chunk_forces and spn__force_on out of line
 * (the general path's 5k symplectic step 27.5 ns a spring-step against 14.3
 * at -O3; Zen 5, 2026-12-07). */
#define SPN__INLINE static inline __attribute__((always_inline))

#endif
