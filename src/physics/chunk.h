/* Chunks of springs for the force loops (forces.c, sweep.c): a loop
 * gathers each spring's end differences and constants into small arrays,
 * a branch-free loop over them computes the forces (vectorised), a third sums
 * the energy terms in a fixed order. Header-only so both users inline it. */
#ifndef SPN_PHYSICS_CHUNK_H
#define SPN_PHYSICS_CHUNK_H

#include "world_internal.h"

#include <math.h>
#include <string.h>

/* The spring pass works on chunks of SPN_CHUNK springs in three loops: a
 * gather of each spring's end differences (l = x_a - x_b, u = v_a - v_b) and
 * constants into small arrays, the force arithmetic over those arrays (no
 * indirection and no branches, so the compiler vectorises it, square roots
 * and divisions included), and the sums of the block. Each spring's
 * arithmetic is the same expression whatever the vector width, so the bits do
 * not depend on it. Broken springs have k = kd = 0 in the hot records, so they
 * cost the same as any other and need no flag. */
#define SPN_CHUNK 128

typedef struct chunk {
    double lx[SPN_CHUNK], ly[SPN_CHUNK], lz[SPN_CHUNK];
    double ux[SPN_CHUNK], uy[SPN_CHUNK], uz[SPN_CHUNK];
    double k[SPN_CHUNK], kd[SPN_CHUNK], rest[SPN_CHUNK], tonly[SPN_CHUNK];
    double s[SPN_CHUNK], e[SPN_CHUNK], p[SPN_CHUNK];
    /* (u_a - v_a) + (u_b - v_b), u the air velocity at each end, where
     * chunk_load_ends is given the air (twice the air's velocity relative
     * to the segment, forces.c) */
    double wx[SPN_CHUNK], wy[SPN_CHUNK], wz[SPN_CHUNK];
} chunk;

/* Four numbers on one vector (AVX; SSE2 pairs in the default version),
 * elementwise IEEE operations; passed by pointer (the default version has
 * no AVX registers to pass them in, -Wpsabi). */
typedef double chunk_v4 __attribute__((vector_size(4 * sizeof(double))));

/* The x, y, z of the four vectors q[0..3] (a particle's three numbers and
 * one after them each) into ox, oy, oz [0..3]: a transpose in shuffles
 * (__builtin_shufflevector: GCC from 12 and clang, which the fuzzers use). */
SPN__INLINE void chunk_v4_columns(const chunk_v4 q[4], double *restrict ox, double *restrict oy,
                                  double *restrict oz)
{
    const chunk_v4 t0 = __builtin_shufflevector(q[0], q[1], 0, 4, 2, 6);
    const chunk_v4 t1 = __builtin_shufflevector(q[0], q[1], 1, 5, 3, 7);
    const chunk_v4 t2 = __builtin_shufflevector(q[2], q[3], 0, 4, 2, 6);
    const chunk_v4 t3 = __builtin_shufflevector(q[2], q[3], 1, 5, 3, 7);
    const chunk_v4 cx = __builtin_shufflevector(t0, t2, 0, 1, 4, 5);
    const chunk_v4 cz = __builtin_shufflevector(t0, t2, 2, 3, 6, 7);
    const chunk_v4 cy = __builtin_shufflevector(t1, t3, 0, 1, 4, 5);
    memcpy(ox, &cx, sizeof cx), memcpy(oy, &cy, sizeof cy), memcpy(oz, &cz, sizeof cz);
}

/* Spring sp into slot j of the chunk, its ends' numbers one at a time
 * (chunk_load_ends). */
SPN__INLINE void chunk_load_one(chunk *restrict c, uint32_t j, spn__spring sp, const spn_vec3 *restrict x,
                                const spn_vec3 *restrict v, uint32_t b_limit, const spn_vec3 *restrict air)
{
    const uint32_t a = sp.a, b0 = spn__end_b(sp), b = b0 < b_limit ? b0 : a;
    const spn_vec3 xa = x[a], xb = x[b], va = v[a], vb = v[b];
    c->lx[j] = xa.x - xb.x, c->ly[j] = xa.y - xb.y, c->lz[j] = xa.z - xb.z;
    c->ux[j] = va.x - vb.x, c->uy[j] = va.y - vb.y, c->uz[j] = va.z - vb.z;
    if (air) {
        const spn_vec3 wa = air[a], wb = air[b];
        c->wx[j] = (wa.x - va.x) + (wb.x - vb.x);
        c->wy[j] = (wa.y - va.y) + (wb.y - vb.y);
        c->wz[j] = (wa.z - va.z) + (wb.z - vb.z);
    }
    c->k[j] = sp.k, c->kd[j] = sp.kd, c->rest[j] = sp.rest;
    c->tonly[j] = (double)spn__tension_only(sp);
}

/* Springs hs[0..n) into the chunk, and with `air` (per particle; NULL in
 * each call or in none) their ends' air velocities relative to them,
 * summed. A spring whose end b is at or past b_limit is loaded as if both
 * ends were a (no force; the caller has its force from elsewhere and must
 * not read b: another thread may be moving it). Four springs at a time
 * read each end's x, v (and air) as one 4-wide load, which takes the number
 * after it too: only where that is below `end` (np, or the first particle
 * another thread may write); other springs one at a time. The same
 * operations either way, so the same bits. */
SPN__INLINE void chunk_load_ends(chunk *restrict c, const spn__spring *restrict hs, uint32_t n,
                                 const spn_vec3 *restrict x, const spn_vec3 *restrict v, uint32_t b_limit,
                                 const spn_vec3 *restrict air, uint32_t end)
{
    uint32_t j = 0;
    for (; j + 4 <= n; j += 4) {
        uint32_t a[4], b[4], top = 0;
        for (int q = 0; q < 4; q++) {
            const spn__spring sp = hs[j + q];
            const uint32_t b0 = spn__end_b(sp);
            a[q] = sp.a, b[q] = b0 < b_limit ? b0 : sp.a;
            top = a[q] > top ? a[q] : top;
            top = b[q] > top ? b[q] : top;
        }
        if (top + 1 >= end) {
            for (uint32_t q = 0; q < 4; q++) chunk_load_one(c, j + q, hs[j + q], x, v, b_limit, air);
            continue;
        }
        chunk_v4 l[4], u[4], w[4];
        for (int q = 0; q < 4; q++) {
            chunk_v4 xa, xb, va, vb, wa, wb;
            memcpy(&xa, x + a[q], sizeof xa), memcpy(&xb, x + b[q], sizeof xb);
            memcpy(&va, v + a[q], sizeof va), memcpy(&vb, v + b[q], sizeof vb);
            l[q] = xa - xb, u[q] = va - vb;
            if (air) {
                memcpy(&wa, air + a[q], sizeof wa), memcpy(&wb, air + b[q], sizeof wb);
                w[q] = (wa - va) + (wb - vb);
            }
        }
        chunk_v4_columns(l, c->lx + j, c->ly + j, c->lz + j);
        chunk_v4_columns(u, c->ux + j, c->uy + j, c->uz + j);
        if (air) chunk_v4_columns(w, c->wx + j, c->wy + j, c->wz + j);
        for (int q = 0; q < 4; q++) {
            const spn__spring sp = hs[j + q];
            c->k[j + q] = sp.k, c->kd[j + q] = sp.kd, c->rest[j + q] = sp.rest;
            c->tonly[j + q] = (double)spn__tension_only(sp);
        }
    }
    for (; j < n; j++) chunk_load_one(c, j, hs[j], x, v, b_limit, air);
}

/* chunk_load_ends without the air. */
SPN__INLINE void chunk_load(chunk *restrict c, const spn__spring *restrict hs, uint32_t n,
                            const spn_vec3 *restrict x, const spn_vec3 *restrict v, uint32_t b_limit, uint32_t end)
{
    chunk_load_ends(c, hs, n, x, v, b_limit, NULL, end);
}

/* Force on end a of each spring of the chunk, into fs; the elastic energy,
 * and damping power of each into c->e, c->p. */
SPN__INLINE void chunk_forces(chunk *restrict c, uint32_t n, spn_vec3 *restrict fs)
{
    for (uint32_t j = 0; j < n; j++) {
        const double lx = c->lx[j], ly = c->ly[j], lz = c->lz[j];
        const double d2 = lx * lx + ly * ly + lz * lz;
        const double len = sqrt(d2);
        const double stretch = len - c->rest[j];
        /* No force from a zero-length spring or a slack tension-only one:
         * a 0/1 factor rather than a branch, so the loop vectorises. */
        const double slack = (double)(stretch < 0) * c->tonly[j];
        const double on = (double)(len > 0) * (1 - slack);
        const double inv = on / (len + (1 - on)); /* 1/len, or 0 when off (never 0/0) */
        const double rate = (c->ux[j] * lx + c->uy[j] * ly + c->uz[j] * lz) * inv; /* d|l|/dt */
        const double k = c->k[j] * on, kd = c->kd[j];
        const double mag = k * stretch + kd * rate;
        c->s[j] = -mag * inv;
        c->e[j] = 0.5 * k * stretch * stretch;
        c->p[j] = kd * rate * rate;
    }
    for (uint32_t j = 0; j < n; j++) {
        const double sj = c->s[j];
        fs[j].x = sj * c->lx[j], fs[j].y = sj * c->ly[j], fs[j].z = sj * c->lz[j];
    }
}

/* Adds the chunk's sums to out[0..1], four independent partial sums each
 * (a fixed order, whatever the vector width of the loop above). */
SPN__INLINE void chunk_sums(const chunk *restrict c, uint32_t n, double *out)
{
    double e0 = 0, e1 = 0, e2 = 0, e3 = 0, p0 = 0, p1 = 0, p2 = 0, p3 = 0;
    uint32_t j = 0;
    for (; j + 4 <= n; j += 4) {
        e0 += c->e[j], e1 += c->e[j + 1], e2 += c->e[j + 2], e3 += c->e[j + 3];
        p0 += c->p[j], p1 += c->p[j + 1], p2 += c->p[j + 2], p3 += c->p[j + 3];
    }
    for (; j < n; j++) e0 += c->e[j], p0 += c->p[j];
    out[0] += (e0 + e1) + (e2 + e3);
    out[1] += (p0 + p1) + (p2 + p3);
}


/* Springs list[0..n) (internal ids) into the chunk. */
SPN__INLINE void chunk_load_list(chunk *restrict c, const spn__spring *restrict hs, const uint32_t *restrict list,
                                   uint32_t n, const spn_vec3 *restrict x, const spn_vec3 *restrict v)
{
    for (uint32_t j = 0; j < n; j++) {
        const spn__spring sp = hs[list[j]];
        const uint32_t a = sp.a, b = spn__end_b(sp);
        const spn_vec3 xa = x[a], xb = x[b], va = v[a], vb = v[b];
        c->lx[j] = xa.x - xb.x, c->ly[j] = xa.y - xb.y, c->lz[j] = xa.z - xb.z;
        c->ux[j] = va.x - vb.x, c->uy[j] = va.y - vb.y, c->uz[j] = va.z - vb.z;
        c->k[j] = sp.k, c->kd[j] = sp.kd, c->rest[j] = sp.rest;
        c->tonly[j] = (double)spn__tension_only(sp);
    }
}

#endif
