/* The fused explicit step: Euler or symplectic Euler (Mehla 2005, eq. 4.5)
 * in one sweep over the particles that computes the spring forces a chunk at
 * a time and moves each particle as soon as its force is complete, so the
 * per-spring force array is never written to memory and read back.
 *
 * Why it is exact. Internal springs have a < b and are stored sorted by a.
 * Sweeping the particles in order, spring (a, b) is computed with the chunk
 * holding it, before particle a is moved (a moves once all of its springs as
 * end a are done) and before b is (b > a, and a spring with end b = j always
 * comes before j's own run). So every spring sees the state from before the
 * step; its force goes to a per-particle accumulator, +f on a and -f on b.
 *
 * Parallel and deterministic. The particles are cut into fixed blocks of
 * def.parallel_min (at least SPN_BLOCK) particles, whatever the thread count.
 * A spring whose end b lies in a later block (a radial across the cut) is
 * computed first, in a pass over every block's outgoing springs, into w->fs;
 * the sweep of a's block adds it to a, that of b's block subtracts it from b
 * before anything moves. Every sum then runs in a fixed order, so 1 and 2
 * threads give the same bits.
 *
 * Used when nothing external acts (no force callback, no air: those need the
 * whole state before the step) and the world has at least two blocks (a
 * smaller one runs faster in two passes). The results differ from the
 * two-pass step in the order the spring forces are added, nothing else. */
#include "chunk.h"
#include "world_internal.h"

#include <stdlib.h>
#include <string.h>

enum { W_ELASTIC, W_DAMP, W_MV2, W_GAIN, W_MVN2 };

void spn__sweep_free(spn_world *w)
{
    free(w->xout_start);
    free(w->xout);
    free(w->xin_start);
    free(w->xin);
    free(w->facc);
    w->xout_start = w->xout = w->xin_start = w->xin = NULL;
    w->facc = NULL;
    w->sweep_block = 0;
}

/* Blocks and their crossing springs, for the current compiled order. */
static bool prepare(spn_world *w)
{
    uint32_t bsize = w->def.parallel_min > SPN_BLOCK ? w->def.parallel_min : SPN_BLOCK;
    if (w->sweep_block == bsize) return true;
    spn__sweep_free(w);
    const uint32_t nblk = (w->np + bsize - 1) / bsize + 1;
    w->xout_start = calloc(nblk + 1, sizeof *w->xout_start);
    w->xin_start = calloc(nblk + 1, sizeof *w->xin_start);
    w->facc = malloc((w->np ? w->np : 1) * sizeof *w->facc);
    if (!w->xout_start || !w->xin_start || !w->facc) return spn__sweep_free(w), false;
    uint32_t ncross = 0;
    for (uint32_t k = 0; k < w->ns; k++) {
        const uint32_t ba = w->hs[k].a / bsize, bb = spn__end_b(w->hs[k]) / bsize;
        if (ba == bb) continue;
        w->xout_start[ba + 1]++;
        w->xin_start[bb + 1]++;
        ncross++;
    }
    for (uint32_t b = 0; b < nblk; b++) {
        w->xout_start[b + 1] += w->xout_start[b];
        w->xin_start[b + 1] += w->xin_start[b];
    }
    w->xout = malloc((ncross ? ncross : 1) * sizeof *w->xout);
    w->xin = malloc((ncross ? ncross : 1) * sizeof *w->xin);
    if (!w->xout || !w->xin) return spn__sweep_free(w), false;
    uint32_t *fo = calloc(2 * (size_t)nblk, sizeof *fo), *fi = fo + nblk;
    if (!fo) return spn__sweep_free(w), false;
    for (uint32_t k = 0; k < w->ns; k++) {
        const uint32_t ba = w->hs[k].a / bsize, bb = spn__end_b(w->hs[k]) / bsize;
        if (ba == bb) continue;
        w->xout[w->xout_start[ba] + fo[ba]++] = k;
        w->xin[w->xin_start[bb] + fi[bb]++] = k;
    }
    free(fo);
    w->sweep_block = bsize;
    return true;
}

/* Forces of block blk's outgoing springs into fs; their sums into p. */
SPN__KERNEL static void crossing_forces(const spn_world *w, uint32_t blk, double *p)
{
    chunk c;
    spn_vec3 buf[SPN_CHUNK];
    double sums[2] = {0, 0};
    const uint32_t lo = w->xout_start[blk], hi = w->xout_start[blk + 1];
    for (uint32_t s0 = lo; s0 < hi; s0 += SPN_CHUNK) {
        const uint32_t n = hi - s0 < SPN_CHUNK ? hi - s0 : SPN_CHUNK;
        chunk_load_list(&c, w->hs, w->xout + s0, n, w->x, w->v);
        chunk_forces(&c, n, buf);
        chunk_sums(&c, n, sums);
        for (uint32_t j = 0; j < n; j++) w->fs[w->xout[s0 + j]] = buf[j];
    }
    for (int k = 0; k < SPN_NSUMS; k++) p[k] = 0; /* spn__sum_partials adds every slot */
    p[W_ELASTIC] = sums[0], p[W_DAMP] = sums[1];
}

typedef struct sweep_args {
    const spn__spring *restrict hs;
    const uint32_t *restrict a_start;
    const double *restrict mass, *restrict inv_mass;
    const spn_vec3 *restrict fs;
    spn_vec3 *restrict x, *restrict v, *restrict x0, *restrict v0, *restrict facc;
    spn_vec3 g;
    double drag, dt;
    bool symplectic, backup;
} sweep_args;

/* Move particles [i, end) with complete forces; the particle sums into p. */
SPN__INLINE void move(const sweep_args *s, uint32_t i, uint32_t end, double *p)
{
    for (; i < end; i++) {
        const spn_vec3 xi = s->x[i], vi = s->v[i];
        if (s->backup) s->x0[i] = xi, s->v0[i] = vi;
        const double im = s->inv_mass[i];
        if (im == 0) continue;
        const double m = s->mass[i], dm = s->drag * m;
        const spn_vec3 fa = s->facc[i];
        const spn_vec3 f = spn_v3_add(spn__gravity_drag(m, dm, s->g, vi, true), fa);
        const spn_vec3 vn = spn__fma_v3(f, s->dt * im, vi), vm = s->symplectic ? vn : vi;
        const spn_vec3 dx = spn_v3_scale(vm, s->dt);
        s->x[i] = spn__fma_v3(vm, s->dt, xi);
        s->v[i] = vn;
        p[W_MV2] += m * spn_v3_dot(vi, vi);
        p[W_MVN2] += m * spn_v3_dot(vn, vn);
        p[W_GAIN] += m * (0.5 * spn_v3_dot(spn_v3_sub(vn, vi), spn_v3_add(vn, vi)) - spn_v3_dot(s->g, dx));
    }
}

/* Sweep particles [lo, hi): incoming crossing forces, then chunks of the
 * block's springs, each followed by the particles it completes. */
SPN__KERNEL static void sweep_block(const spn_world *w, const sweep_args *s, uint32_t blk, uint32_t lo,
                                    uint32_t hi, double *p)
{
    for (uint32_t i = lo; i < hi; i++) s->facc[i] = spn_v3(0, 0, 0);
    for (uint32_t q = w->xin_start[blk]; q < w->xin_start[blk + 1]; q++) {
        const uint32_t k = w->xin[q], b = spn__end_b(s->hs[k]);
        s->facc[b] = spn_v3_sub(s->facc[b], s->fs[k]);
    }
    chunk c;
    spn_vec3 buf[SPN_CHUNK];
    double sums[2] = {p[W_ELASTIC], p[W_DAMP]};
    double ps[SPN_NSUMS] = {0};
    uint32_t i = lo;
    const uint32_t s_lo = s->a_start[lo], s_hi = s->a_start[hi];
    for (uint32_t s0 = s_lo; s0 < s_hi; s0 += SPN_CHUNK) {
        const uint32_t n = s_hi - s0 < SPN_CHUNK ? s_hi - s0 : SPN_CHUNK;
        chunk_load(&c, s->hs + s0, n, s->x, s->v, hi, hi);
        chunk_forces(&c, n, buf);
        chunk_sums(&c, n, sums);
        /* End a's forces are summed in a register while a stays the same
         * (springs are sorted by a), end b's go straight to the accumulator. */
        uint32_t cur = s->hs[s0].a;
        spn_vec3 acc = {0, 0, 0};
        for (uint32_t j = 0; j < n; j++) {
            const uint32_t a = s->hs[s0 + j].a, b = spn__end_b(s->hs[s0 + j]);
            if (a != cur) {
                s->facc[cur] = spn_v3_add(s->facc[cur], acc);
                cur = a, acc = spn_v3(0, 0, 0);
            }
            if (b < hi) {
                acc = spn_v3_add(acc, buf[j]);
                s->facc[b] = spn_v3_sub(s->facc[b], buf[j]);
            } else {
                acc = spn_v3_add(acc, s->fs[s0 + j]);
            }
        }
        s->facc[cur] = spn_v3_add(s->facc[cur], acc);
        uint32_t end = i;
        while (end < hi && s->a_start[end + 1] <= s0 + n) end++;
        move(s, i, end, ps);
        i = end;
    }
    move(s, i, hi, ps);
    p[W_ELASTIC] = sums[0], p[W_DAMP] = sums[1];
    p[W_MV2] = ps[W_MV2], p[W_GAIN] = ps[W_GAIN], p[W_MVN2] = ps[W_MVN2];
}

bool spn__step_sweep(spn_world *w, double dt, bool symplectic, spn__step_result *r)
{
    /* One block is a small world, its data in cache: there the two-pass step
     * is faster (measured, 5,001 particles: 9.9 against 11.2 CPU ns per
     * spring-step) and the sweep only pays off once memory bounds the step
     * (1,000,001 particles: 17.5 -> 15.9). */
    const uint32_t bmin = w->def.parallel_min > SPN_BLOCK ? w->def.parallel_min : SPN_BLOCK;
    if (w->np < 2 * bmin || !prepare(w)) return false;
    const uint32_t np = w->np, bsize = w->sweep_block, nblk = (np + bsize - 1) / bsize;
    double *partial = w->partial;
    const int threads = nblk > 1 ? spn__threads(w, np) : 1;
    (void)threads; /* (used by an OpenMP pragma only) */
#pragma omp parallel for schedule(static) num_threads(threads)
    for (uint32_t blk = 0; blk < nblk; blk++) crossing_forces(w, blk, partial + (size_t)blk * SPN_NSUMS);
    const sweep_args args = {w->hs, w->a_start, w->mass, w->inv_mass, w->fs, w->x, w->v, w->x0, w->v0, w->facc,
                             w->def.gravity, w->def.drag, dt, symplectic, !w->no_backup};
#pragma omp parallel for schedule(static) num_threads(threads)
    for (uint32_t blk = 0; blk < nblk; blk++) {
        const uint32_t lo = blk * bsize, hi = lo + bsize < np ? lo + bsize : np;
        sweep_block(w, &args, blk, lo, hi, partial + (size_t)blk * SPN_NSUMS);
    }
    double sum[SPN_NSUMS];
    spn__sum_partials(w, nblk, sum);
    r->elastic = sum[W_ELASTIC];
    r->e_before = 0.5 * sum[W_MV2] + sum[W_ELASTIC];
    r->gain_kp = sum[W_GAIN];
    r->work = 0;
    r->dissipated = dt * (sum[W_DAMP] + w->def.drag * sum[W_MV2]);
    r->kinetic = 0.5 * sum[W_MVN2];
    return true;
}
