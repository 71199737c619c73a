/* Spokes and hub of the physical construction (Mehla 2005, fig. 5.10).
 * Primary spokes join the middle mass of each inner-frame side to the frame
 * mass farthest from it; near-parallel duplicates (opposite sides choosing
 * each other) are laid once. The hub is the least-squares crossing point of
 * the primaries; a ring of hub strands joins each primary where it leaves a
 * circle of hub_radius, and the primaries' pieces inside become hub threads.
 * Secondary spokes run from every other inner-frame mass to the closest ring
 * mass whose line crosses no spoke already laid.
 * Invariant on return: b->spokes lists every spoke from its frame end to the
 * ring, sorted counter-clockwise by the angle of its frame end. */
#include "physical_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static spn_vec3 pos(const spn__physical *b, uint32_t id) { return spn_world_position(b->wv.w, id); }

static void push_spoke(spn__physical *b, uint32_t *ids, int n)
{
    if (b->wv.st != SPN_OK) return;
    if (b->nspokes == b->spoke_cap) {
        int cap = b->spoke_cap ? 2 * b->spoke_cap : 64;
        spn__spoke *p = realloc(b->spokes, (size_t)cap * sizeof *p);
        if (!p) {
            free(ids);
            b->wv.st = spn_error(SPN_ERR_NOMEM, "out of memory");
            return;
        }
        b->spokes = p;
        b->spoke_cap = cap;
    }
    spn_vec3 d = spn_v3_sub(pos(b, ids[0]), b->hub);
    b->spokes[b->nspokes].ids = ids;
    b->spokes[b->nspokes].n = n;
    b->spokes[b->nspokes].angle = atan2(d.y, d.x);
    b->nspokes++;
}

typedef struct primary {
    uint32_t *ids;
    int n;
    uint32_t first_spring;
    spn_vec3 dir;
} primary;

static int lay_primaries(spn__physical *b, spn__spoke_fn lay, primary *pr)
{
    int n = b->def->anchor_count, np = 0;
    for (int i = 0; i < n && b->wv.st == SPN_OK; i++) {
        uint32_t mid = b->side[i][b->side_n[i] / 2], far = mid;
        spn_vec3 pm = pos(b, mid), through = spn_v3_norm(spn_v3_sub(b->centre, pm));
        double best = -INFINITY;
        for (int j = 0; j < n; j++) {
            if (j == i) continue;
            for (int k = 0; k < b->side_n[j]; k++) {
                /* Farthest along the line through the centre, not merely farthest:
                 * on a square the farthest mass is a corner and the primaries
                 * would miss each other instead of crossing at the hub. */
                spn_vec3 q = spn_v3_sub(pos(b, b->side[j][k]), pm);
                double along = spn_v3_dot(q, through), off = spn_v3_len(spn_v3_sub(q, spn_v3_scale(through, along)));
                double score = along - 4 * off;
                if (score > best) best = score, far = b->side[j][k];
            }
        }
        spn_vec3 dir = spn_v3_norm(spn_v3_sub(pos(b, far), pos(b, mid)));
        bool dup = far == mid;
        for (int p = 0; p < np; p++)
            if (fabs(spn_v3_cross(dir, pr[p].dir).z) < sin(25 * SPN_PI / 180)) dup = true;
        if (dup) continue;
        pr[np].first_spring = spn_world_spring_count(b->wv.w);
        pr[np].dir = dir;
        pr[np].ids = lay(b, mid, far, SPN_THREAD_RADIUS, &pr[np].n);
        if (b->wv.st == SPN_OK) np++;
    }
    return np;
}

/* Least-squares crossing of the primary lines. */
static spn_vec3 crossing(const spn__physical *b, const primary *pr, int np)
{
    double a11 = 0, a12 = 0, a22 = 0, r1 = 0, r2 = 0, z = 0;
    for (int p = 0; p < np; p++) {
        spn_vec3 o = pos(b, pr[p].ids[0]), d = pr[p].dir;
        double m11 = 1 - d.x * d.x, m12 = -d.x * d.y, m22 = 1 - d.y * d.y;
        a11 += m11, a12 += m12, a22 += m22;
        r1 += m11 * o.x + m12 * o.y;
        r2 += m12 * o.x + m22 * o.y;
        z += o.z / np;
    }
    double det = a11 * a22 - a12 * a12;
    if (np < 2 || fabs(det) < 1e-9) return spn__lerp(pos(b, pr[0].ids[0]), pos(b, pr[0].ids[pr[0].n - 1]), 0.5);
    return spn_v3((a22 * r1 - a12 * r2) / det, (a11 * r2 - a12 * r1) / det, z);
}

typedef struct ring_mass {
    uint32_t id;
    double angle;
} ring_mass;

static int by_angle(const void *x, const void *y)
{
    double a = ((const ring_mass *)x)->angle, c = ((const ring_mass *)y)->angle;
    return (a > c) - (a < c);
}

static int spoke_by_angle(const void *x, const void *y)
{
    double a = ((const spn__spoke *)x)->angle, c = ((const spn__spoke *)y)->angle;
    return (a > c) - (a < c);
}

/* Split each primary at the hub circle into two spokes; the ring masses. */
static int split_primaries(spn__physical *b, primary *pr, int np, ring_mass *ring)
{
    double r = b->def->hub_radius;
    int nr = 0;
    for (int p = 0; p < np && b->wv.st == SPN_OK; p++) {
        int lo = 0, hi = pr[p].n - 1;
        while (lo < pr[p].n - 1 && spn_v3_len(spn_v3_sub(pos(b, pr[p].ids[lo + 1]), b->hub)) >= r) lo++;
        while (hi > lo + 1 && spn_v3_len(spn_v3_sub(pos(b, pr[p].ids[hi - 1]), b->hub)) >= r) hi--;
        if (hi <= lo) hi = lo + 1 < pr[p].n ? lo + 1 : lo;
        for (int k = lo; k < hi; k++) spn_world_set_spring_tag(b->wv.w, pr[p].first_spring + (uint32_t)k, SPN_THREAD_HUB);
        uint32_t *a = malloc(((size_t)lo + 1) * sizeof *a), *c = malloc(((size_t)(pr[p].n - hi)) * sizeof *c);
        if (!a || !c) {
            free(a), free(c);
            b->wv.st = spn_error(SPN_ERR_NOMEM, "out of memory");
            return nr;
        }
        memcpy(a, pr[p].ids, ((size_t)lo + 1) * sizeof *a);
        for (int k = 0; k < pr[p].n - hi; k++) c[k] = pr[p].ids[pr[p].n - 1 - k];
        int ends[2] = {lo, hi};
        for (int e = 0; e < 2; e++) {
            spn_vec3 d = spn_v3_sub(pos(b, pr[p].ids[ends[e]]), b->hub);
            ring[nr].id = pr[p].ids[ends[e]];
            ring[nr++].angle = atan2(d.y, d.x);
        }
        push_spoke(b, a, lo + 1);
        push_spoke(b, c, pr[p].n - hi);
    }
    return nr;
}

/* Hub strands round the ring, laid on a circle about the hub with masses a
 * third of the spoke spacing apart: every mass can take secondary spokes, so
 * the spokes fan in evenly instead of in a few bundles with gaps between. */
static uint32_t *lay_ring(spn__physical *b, ring_mass *ring, int nr, int *count)
{
    const spn_physical_def *d = b->def;
    qsort(ring, (size_t)nr, sizeof *ring, by_angle);
    double place = d->spoke_placement / 3, ratio = d->provot ? 1 : d->spoke_rest / d->spoke_placement;
    size_t cap = 64, n = 0;
    uint32_t *all = malloc(cap * sizeof *all);
    for (int i = 0; i < nr && all && b->wv.st == SPN_OK; i++) {
        uint32_t a = ring[i].id, c = ring[(i + 1) % nr].id;
        if (a == c) continue; /* two primaries leave the hub at one mass */
        double t0 = ring[i].angle, t1 = ring[(i + 1) % nr].angle;
        if (t1 <= t0) t1 += 2 * SPN_PI;
        double r0 = spn_v3_len(spn_v3_sub(pos(b, a), b->hub)), r1 = spn_v3_len(spn_v3_sub(pos(b, c), b->hub));
        int k = (int)lround((t1 - t0) * 0.5 * (r0 + r1) / place);
        if (k < 1) k = 1;
        uint32_t prev = a;
        for (int j = 1; j <= k && b->wv.st == SPN_OK; j++) {
            double u = (double)j / k, t = t0 + u * (t1 - t0), r = r0 + u * (r1 - r0);
            uint32_t cur = j == k ? c : spn__particle(&b->wv, spn_v3_add(b->hub, spn_v3(r * cos(t), r * sin(t), 0)), false,
                                                     SPN_PARTICLE_HUB);
            double len = spn_v3_len(spn_v3_sub(pos(b, cur), pos(b, prev)));
            spn__spring(&b->wv, prev, cur, SPN_THREAD_HUB, SPN_STAGE_RADII, len * ratio);
            if (n + 1 >= cap) {
                uint32_t *grown = realloc(all, (cap *= 2) * sizeof *grown);
                if (!grown) break;
                all = grown;
            }
            all[n++] = prev;
            prev = cur;
        }
    }
    if (!all && b->wv.st == SPN_OK) b->wv.st = spn_error(SPN_ERR_NOMEM, "out of memory");
    *count = (int)n;
    return all;
}

static bool crosses_spokes(const spn__physical *b, spn_vec3 f, spn_vec3 h)
{
    for (int s = 0; s < b->nspokes; s++) {
        const spn__spoke *sp = &b->spokes[s];
        if (spn__segments_cross(f, h, pos(b, sp->ids[0]), pos(b, sp->ids[sp->n - 1]))) return true;
    }
    return false;
}

static bool is_primary_end(const primary *pr, int np, uint32_t id)
{
    for (int p = 0; p < np; p++)
        if (pr[p].ids[0] == id || pr[p].ids[pr[p].n - 1] == id) return true;
    return false;
}

static void lay_secondaries(spn__physical *b, spn__spoke_fn lay, const primary *pr, int np, const uint32_t *ring,
                            int nring)
{
    for (int i = 0; i < b->def->anchor_count && b->wv.st == SPN_OK; i++)
        for (int j = 0; j < b->side_n[i] - 1 && b->wv.st == SPN_OK; j++) {
            uint32_t f = b->side[i][j];
            if (is_primary_end(pr, np, f)) continue;
            spn_vec3 pf = pos(b, f);
            int best = -1;
            double bestd = INFINITY;
            for (int r = 0; r < nring; r++) {
                double dd = spn_v3_len(spn_v3_sub(pos(b, ring[r]), pf));
                if (dd < bestd && !crosses_spokes(b, pf, pos(b, ring[r]))) bestd = dd, best = r;
            }
            if (best < 0) continue; /* boxed in by its neighbours: the spider skips it too */
            int k = 0;
            uint32_t *ids = lay(b, f, ring[best], SPN_THREAD_RADIUS, &k);
            if (ids) push_spoke(b, ids, k);
        }
}

void spn__physical_spokes(spn__physical *b, spn__spoke_fn lay)
{
    int n = b->def->anchor_count;
    primary *pr = calloc((size_t)n, sizeof *pr);
    ring_mass *ring = calloc(2 * (size_t)n, sizeof *ring);
    if (!pr || !ring) {
        free(pr), free(ring);
        b->wv.st = spn_error(SPN_ERR_NOMEM, "out of memory");
        return;
    }
    int np = lay_primaries(b, lay, pr);
    if (np > 0 && b->wv.st == SPN_OK) {
        b->hub = crossing(b, pr, np);
        int nr = split_primaries(b, pr, np, ring);
        int nring = 0;
        uint32_t *ringids = nr >= 2 ? lay_ring(b, ring, nr, &nring) : NULL;
        if (ringids) lay_secondaries(b, lay, pr, np, ringids, nring);
        free(ringids);
        for (int s = 0; s < b->nspokes; s++) {
            spn_vec3 d = spn_v3_sub(pos(b, b->spokes[s].ids[0]), b->hub);
            b->spokes[s].angle = atan2(d.y, d.x);
        }
        qsort(b->spokes, (size_t)b->nspokes, sizeof *b->spokes, spoke_by_angle);
    }
    for (int p = 0; p < np; p++) free(pr[p].ids);
    free(pr);
    free(ring);
}

void spn__physical_free(spn__physical *b)
{
    for (int i = 0; i < SPN_WEB_MAX_ANCHORS; i++) free(b->side[i]);
    for (int s = 0; s < b->nspokes; s++) free(b->spokes[s].ids);
    free(b->spokes);
    if (b->wv.w) spn__weaver_abort(&b->wv);
}
