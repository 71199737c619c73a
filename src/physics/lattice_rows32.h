/* The row kernels of the float32 lattice step (lattice_f32.c): the spring
 * stencil, the force assembly and the Euler / symplectic Euler / RK4 updates
 * of lattice_rows.h in float32 (the updates from lattice_rows_t.h), over rows of the float32 state (displacements
 * d from the float64 positions, velocities u). Header-only so that each
 * target_clones version of the sweep inlines its own copy. Plain loops over
 * contiguous float arrays for GCC 12 to vectorise at full width (16 lanes
 * with AVX-512); where it would not, the comment says what was changed. */
#ifndef SPN_PHYSICS_LATTICE_ROWS32_H
#define SPN_PHYSICS_LATTICE_ROWS32_H

#include "lattice_rows.h"

#include <math.h>

#define LK_T float
#define LK_U uint32_t
#define LK(name) name##32
#define LK_FMA fmaf /* a b + c, one rounding */
#define LK_SCRATCH 1
#include "lattice_rows_t.h"
#undef LK_SCRATCH
#undef LK_FMA
#undef LK_U
#undef LK
#undef LK_T

/* Springs j = 0..n-1 from a to b: chunk.h's expression in float32, the
 * difference as L + (d_a - d_b); force on end a into f, elastic energy
 * (when `elastic`, a constant in each call) and damping power into e, p
 * (float32 scratch). */
LAT_INLINE void springs32(bool elastic, uint32_t n, const float *restrict dax, const float *restrict day,
                          const float *restrict daz, const float *restrict dbx, const float *restrict dby,
                          const float *restrict dbz, const float *restrict uax, const float *restrict uay,
                          const float *restrict uaz, const float *restrict ubx, const float *restrict uby,
                          const float *restrict ubz, const float *restrict Lx, const float *restrict Ly,
                          const float *restrict Lz, const float *restrict kk, const float *restrict kkd,
                          const float *restrict rr, float *restrict fx, float *restrict fy, float *restrict fz,
                          float *restrict e, float *restrict p)
{
    for (uint32_t j = 0; j < n; j++) {
        const float lx = Lx[j] + (dax[j] - dbx[j]), ly = Ly[j] + (day[j] - dby[j]), lz = Lz[j] + (daz[j] - dbz[j]);
        const float ux = uax[j] - ubx[j], uy = uay[j] - uby[j], uz = uaz[j] - ubz[j];
        const float len = sqrtf(lx * lx + ly * ly + lz * lz);
        const float rs = rr[j];
        const float stretch = len - fabsf(rs);
        const bool on = len > 0 && !(stretch < 0 && rs < 0);
        const float inv = on ? 1.0f / len : 0.0f;
        const float rate = (ux * lx + uy * ly + uz * lz) * inv;
        const float k = pick32(on, kk[j], 0.0f), kd = kkd[j];
        const float s = -(k * stretch + kd * rate) * inv;
        if (elastic) e[j] = 0.5f * k * stretch * stretch;
        p[j] = kd * rate * rate;
        fx[j] = s * lx, fy[j] = s * ly, fz[j] = s * lz;
    }
}

/* What spring_rows does with its sum terms: adds them into the columns
 * (SUMS_ADD); leaves them in the scratch, held for the ring springs of the
 * same row (SUMS_HOLD, a row's radial springs); or adds them together with
 * the held terms, in one pass (SUMS_JOIN, the ring springs but the wrap).
 * The columns get the same bits either way (col_join). */
typedef enum { SUMS_ADD, SUMS_HOLD, SUMS_JOIN } lat_sums;

/* Springs between rows (3 arrays each, already offset) a and b; forces
 * into f and sums into the columns cs, both at off_f (the elastic energy
 * if `elastic`: wants_elastic in lattice_rows.h), as `how` says; a joined
 * call has one spring fewer than the held one. */
LAT_INLINE void spring_rows(uint32_t n, float *const *da, float *const *ua, float *const *db, float *const *ub,
                            float *const *L, size_t s0, const float *k, const float *kd, const float *rest,
                            float *const *f, size_t off_f, const lat_cols *cs, bool elastic, lat_sums how)
{
    float *te = how == SUMS_JOIN ? cs->join[0] : cs->scr[L_ELASTIC];
    float *tp = how == SUMS_JOIN ? cs->join[1] : cs->scr[L_DAMP];
#define LAT_SPRINGS(elastic)                                                                                           \
    springs32(elastic, n, da[0], da[1], da[2], db[0], db[1], db[2], ua[0], ua[1], ua[2], ub[0], ub[1], ub[2],          \
              L[0] + s0, L[1] + s0, L[2] + s0, k + s0, kd + s0, rest + s0, f[0] + off_f, f[1] + off_f, f[2] + off_f,   \
              te, tp)
    if (elastic)
        LAT_SPRINGS(true);
    else
        LAT_SPRINGS(false);
#undef LAT_SPRINGS
    if (how == SUMS_HOLD) return;
    if (how == SUMS_JOIN) {
        if (elastic) col_join(cs->c[L_ELASTIC], cs->scr[L_ELASTIC], te, n);
        col_join(cs->c[L_DAMP], cs->scr[L_DAMP], tp, n);
        return;
    }
    if (elastic) col_addf(cs->c[L_ELASTIC], te, n);
    col_addf(cs->c[L_DAMP], tp, n);
}

#endif
