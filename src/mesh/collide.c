/* Particles against triangles (the collision callback of Juhasz & Bercovici,
 * made concrete): after each sub-step, every free particle's move x0 -> x is
 * swept against the triangles of the other objects. A triangle is two-sided:
 * the particle stays on the side it came from, at least `skin` away from the
 * plane. Because the whole segment is tested, not just its end, a fast
 * particle cannot pass through a thin table between two steps (no tunnelling
 * at any step size). The response keeps the tangential move (sliding), puts
 * the particle back on the skin, and changes only the velocity relative to
 * the triangle: normal part reversed times restitution, tangential part
 * reduced by friction (the same rule as the world's planes).
 * Candidates come from a hash grid over triangle boxes, rebuilt whenever any
 * object moves (free against free, as the film maker needs). Particles of an
 * object never test their own triangles: self-collision is not handled. */
#include "mesh_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define NO_OWNER UINT32_MAX
#define MAX_CELLS 512 /* a box covering more cells is kept in the `big` list */

struct spn_tri_collider {
    double skin, restitution, friction;
    uint32_t ntri, cap_tri, cap_obj;
    uint32_t *tri, *tri_obj; /* 3 particle ids per triangle; its object */
    bool built;
    bool *obj_moving; /* per object id */
    uint32_t nobj_cap, nobj;
    bool follow; /* the grid holds moving triangles: rebuild every sub-step */
    uint32_t *active, nactive; /* triangles some particle can hit */
    uint32_t *owner, cap_owner;
    /* hash grid: cell size, bucket CSR over triangles, per-triangle boxes */
    double cell;
    uint32_t mask, nbig, cap_grid;
    uint32_t *start, *items, *big, *stamp, query;
    size_t cap_items;
    spn_vec3 *lo, *hi;
};

spn_tri_collider *spn__tri_collider_create(double skin, double restitution, double friction)
{
    spn_tri_collider *c = calloc(1, sizeof *c);
    if (!c) return NULL;
    c->skin = skin;
    c->restitution = restitution;
    c->friction = friction;
    return c;
}

void spn__tri_collider_destroy(spn_tri_collider *c)
{
    if (!c) return;
    free(c->tri);
    free(c->tri_obj);
    free(c->owner);
    free(c->obj_moving);
    free(c->active);
    free(c->start);
    free(c->items);
    free(c->big);
    free(c->stamp);
    free(c->lo);
    free(c->hi);
    free(c);
}

spn_status spn__tri_collider_add(spn_tri_collider *c, const uint32_t *tris, uint32_t count, uint32_t first_particle,
                                 uint32_t object, bool moving)
{
    uint32_t n = c->ntri + count;
    if (!spn__grow((void **)&c->tri, &c->cap_tri, 3 * n, sizeof *c->tri) ||
        !spn__grow((void **)&c->tri_obj, &c->cap_obj, n, sizeof *c->tri_obj))
        return spn_error(SPN_ERR_NOMEM, "collisions: out of memory");
    for (uint32_t t = 0; t < count; t++) {
        for (int k = 0; k < 3; k++) c->tri[3 * (c->ntri + t) + k] = first_particle + tris[3 * t + k];
        c->tri_obj[c->ntri + t] = object;
    }
    c->ntri = n;
    if (!spn__grow((void **)&c->obj_moving, &c->nobj_cap, object + 1, sizeof *c->obj_moving))
        return spn_error(SPN_ERR_NOMEM, "collisions: out of memory");
    c->obj_moving[object] = moving;
    if (object + 1 > c->nobj) c->nobj = object + 1;
    c->built = false;
    free(c->lo);
    free(c->hi);
    free(c->big);
    free(c->active);
    c->lo = c->hi = NULL;
    c->big = c->active = NULL;
    c->cell = 0;
    free(c->stamp);
    c->stamp = calloc(n, sizeof *c->stamp);
    c->query = 0;
    return c->stamp ? SPN_OK : spn_error(SPN_ERR_NOMEM, "collisions: out of memory");
}

spn_status spn__tri_collider_set_owner(spn_tri_collider *c, uint32_t first, uint32_t count, uint32_t object)
{
    uint32_t old = c->cap_owner;
    if (!spn__grow((void **)&c->owner, &c->cap_owner, first + count, sizeof *c->owner))
        return spn_error(SPN_ERR_NOMEM, "collisions: out of memory");
    for (uint32_t i = old; i < c->cap_owner; i++) c->owner[i] = NO_OWNER;
    for (uint32_t i = 0; i < count; i++) c->owner[first + i] = object;
    return SPN_OK;
}

/* ---- the grid ------------------------------------------------------------ */

static int64_t cell_of(const spn_tri_collider *c, double x) { return (int64_t)floor(x / c->cell); }

static uint32_t bucket(const spn_tri_collider *c, int64_t x, int64_t y, int64_t z)
{
    uint64_t h = (uint64_t)x * 73856093u ^ (uint64_t)y * 19349663u ^ (uint64_t)z * 83492791u;
    h ^= h >> 29;
    return (uint32_t)(h * 0x9e3779b97f4a7c15ULL >> 32) & c->mask;
}

static double box_cells(const spn_tri_collider *c, spn_vec3 lo, spn_vec3 hi)
{
    return (double)(cell_of(c, hi.x) - cell_of(c, lo.x) + 1) * (double)(cell_of(c, hi.y) - cell_of(c, lo.y) + 1) *
           (double)(cell_of(c, hi.z) - cell_of(c, lo.z) + 1);
}

/* Call fn for each bucket of the cells covering [lo, hi]. */
#define FOR_CELLS(c, lo, hi, body)                                                            \
    for (int64_t cx = cell_of(c, (lo).x); cx <= cell_of(c, (hi).x); cx++)                     \
        for (int64_t cy = cell_of(c, (lo).y); cy <= cell_of(c, (hi).y); cy++)                 \
            for (int64_t cz = cell_of(c, (lo).z); cz <= cell_of(c, (hi).z); cz++) {           \
                uint32_t b_ = bucket(c, cx, cy, cz);                                          \
                body                                                                          \
            }

/* Only triangles that a free particle of another object can reach go into
 * the grid: with one moving object (a cloth over a table) its own triangles
 * are left out, the grid holds obstacles only and is built once. True when
 * the grid must follow moving triangles (rebuilt every sub-step). */
static bool select_active(spn_tri_collider *c, uint32_t nobj)
{
    uint32_t moving = 0, last = 0;
    for (uint32_t o = 0; o < nobj; o++)
        if (c->obj_moving[o]) moving++, last = o;
    bool follow = false;
    c->nactive = 0;
    for (uint32_t t = 0; t < c->ntri; t++) {
        uint32_t o = c->tri_obj[t];
        if (moving == 0 || (moving == 1 && last == o)) continue;
        c->active[c->nactive++] = t;
        follow |= c->obj_moving[o];
    }
    return follow;
}

static void triangle_boxes(spn_tri_collider *c, const spn_vec3 *x)
{
    for (uint32_t q = 0; q < c->nactive; q++) {
        uint32_t t = c->active[q];
        spn_vec3 a = x[c->tri[3 * t]], b = x[c->tri[3 * t + 1]], d = x[c->tri[3 * t + 2]];
        double s = c->skin;
        c->lo[t] = spn_v3(fmin(a.x, fmin(b.x, d.x)) - s, fmin(a.y, fmin(b.y, d.y)) - s, fmin(a.z, fmin(b.z, d.z)) - s);
        c->hi[t] = spn_v3(fmax(a.x, fmax(b.x, d.x)) + s, fmax(a.y, fmax(b.y, d.y)) + s, fmax(a.z, fmax(b.z, d.z)) + s);
    }
    if (c->cell > 0) return;
    double sum = 0; /* the cell is chosen once: the mean triangle box side */
    for (uint32_t q = 0; q < c->nactive; q++) {
        spn_vec3 e = spn_v3_sub(c->hi[c->active[q]], c->lo[c->active[q]]);
        sum += fmax(e.x, fmax(e.y, e.z));
    }
    c->cell = fmax(sum / (c->nactive ? c->nactive : 1), 4 * c->skin);
    if (!(c->cell > 0)) c->cell = 1;
}

static bool build(spn_tri_collider *c, const spn_vec3 *x)
{
    if (!c->lo) {
        c->lo = malloc((c->ntri + 1) * sizeof *c->lo);
        c->hi = malloc((c->ntri + 1) * sizeof *c->hi);
        c->big = malloc((c->ntri + 1) * sizeof *c->big);
        c->active = malloc((c->ntri + 1) * sizeof *c->active);
        if (!c->lo || !c->hi || !c->big || !c->active) return false;
        c->follow = select_active(c, c->nobj);
    }
    triangle_boxes(c, x);
    size_t entries = 0;
    for (uint32_t q = 0; q < c->nactive; q++) {
        uint32_t t = c->active[q];
        double n = box_cells(c, c->lo[t], c->hi[t]);
        if (n <= MAX_CELLS) entries += (size_t)n;
    }
    uint32_t size = 64;
    while (size < 2 * entries && size < (1u << 30)) size *= 2;
    if (size + 1 > c->cap_grid) {
        free(c->start);
        c->start = malloc((size + 1) * sizeof *c->start);
        c->cap_grid = c->start ? size + 1 : 0;
    }
    if (entries > c->cap_items) {
        free(c->items);
        c->items = malloc(entries * sizeof *c->items);
        c->cap_items = c->items ? entries : 0;
    }
    if (!c->start || (entries && !c->items)) return false;
    c->mask = size - 1;
    memset(c->start, 0, (size + 1) * sizeof *c->start);
    c->nbig = 0;
    for (uint32_t q = 0; q < c->nactive; q++) {
        uint32_t t = c->active[q];
        if (box_cells(c, c->lo[t], c->hi[t]) > MAX_CELLS) c->big[c->nbig++] = t;
        else FOR_CELLS(c, c->lo[t], c->hi[t], c->start[b_ + 1]++;)
    }
    for (uint32_t b = 0; b < size; b++) c->start[b + 1] += c->start[b];
    for (uint32_t q = c->nactive; q-- > 0;) { /* fill backwards: each bucket ends up in triangle order */
        uint32_t t = c->active[q];
        if (box_cells(c, c->lo[t], c->hi[t]) <= MAX_CELLS) FOR_CELLS(c, c->lo[t], c->hi[t], c->items[--c->start[b_ + 1]] = t;)
    }
    /* start[b + 1] was decremented to the bucket's beginning: shift back. */
    memmove(c->start, c->start + 1, size * sizeof *c->start);
    c->start[size] = (uint32_t)entries;
    c->built = true;
    return true;
}

/* ---- one particle ------------------------------------------------------- */

typedef struct contact {
    double t;      /* where along the move the skin is reached */
    uint32_t tri;
    spn_vec3 n;    /* unit normal on the particle's side */
    double a1;     /* end distance from the plane along n */
} contact;

/* Does the move x0 -> x1 come within skin of triangle t (on x0's side)? */
static bool test_triangle(const spn_tri_collider *c, const spn_vec3 *x, uint32_t t, spn_vec3 x0, spn_vec3 x1,
                          contact *out)
{
    spn_vec3 a = x[c->tri[3 * t]], b = x[c->tri[3 * t + 1]], d = x[c->tri[3 * t + 2]];
    spn_vec3 n = spn_v3_cross(spn_v3_sub(b, a), spn_v3_sub(d, a));
    double len = spn_v3_len(n);
    if (!(len > 0)) return false;
    n = spn_v3_scale(n, 1 / len);
    double d0 = spn_v3_dot(n, spn_v3_sub(x0, a)), d1 = spn_v3_dot(n, spn_v3_sub(x1, a));
    if (d0 < 0 || (d0 == 0 && d1 > 0)) {
        n = spn_v3_scale(n, -1);
        d0 = -d0;
        d1 = -d1;
    }
    if (d1 >= c->skin) return false;
    double tt = d0 > c->skin ? (d0 - c->skin) / (d0 - d1) : 0;
    spn_vec3 p = spn_v3_add(x0, spn_v3_scale(spn_v3_sub(x1, x0), tt));
    p = spn_v3_sub(p, spn_v3_scale(n, spn_v3_dot(n, spn_v3_sub(p, a))));
    /* Barycentric coordinates of p; a margin of a skin keeps seams closed. */
    spn_vec3 e1 = spn_v3_sub(b, a), e2 = spn_v3_sub(d, a), ep = spn_v3_sub(p, a);
    double d11 = spn_v3_dot(e1, e1), d12 = spn_v3_dot(e1, e2), d22 = spn_v3_dot(e2, e2);
    double dp1 = spn_v3_dot(ep, e1), dp2 = spn_v3_dot(ep, e2), den = d11 * d22 - d12 * d12;
    double v = (d22 * dp1 - d12 * dp2) / den, w = (d11 * dp2 - d12 * dp1) / den;
    double tol = c->skin / sqrt(fmax(d11, d22));
    if (v < -tol || w < -tol || v + w > 1 + tol) return false;
    out->t = tt;
    out->tri = t;
    out->n = n;
    out->a1 = d1;
    return true;
}

typedef struct segment {
    spn_vec3 x0, x1, lo, hi; /* the move and its box grown by the skin */
} segment;

static inline void consider(spn_tri_collider *c, const spn_vec3 *x, uint32_t p, uint32_t t, const segment *sg,
                            contact *best)
{
    if (c->stamp[t] == c->query) return;
    c->stamp[t] = c->query;
    const spn_vec3 lo = c->lo[t], hi = c->hi[t]; /* boxes first: most candidates end here */
    if (sg->hi.x < lo.x || sg->lo.x > hi.x || sg->hi.y < lo.y || sg->lo.y > hi.y || sg->hi.z < lo.z || sg->lo.z > hi.z)
        return;
    spn_vec3 x0 = sg->x0, x1 = sg->x1;
    if (c->owner && p < c->cap_owner && c->owner[p] != NO_OWNER && c->owner[p] == c->tri_obj[t]) return;
    contact k;
    if (test_triangle(c, x, t, x0, x1, &k) && k.t < best->t) *best = k;
}

static bool find_contact(spn_tri_collider *c, const spn_vec3 *x, uint32_t p, spn_vec3 x0, spn_vec3 x1, contact *best)
{
    if (++c->query == 0) { /* the stamps wrapped: start over */
        memset(c->stamp, 0, c->ntri * sizeof *c->stamp);
        c->query = 1;
    }
    best->t = INFINITY;
    double s = c->skin;
    segment sg = {x0, x1, spn_v3(fmin(x0.x, x1.x) - s, fmin(x0.y, x1.y) - s, fmin(x0.z, x1.z) - s),
                  spn_v3(fmax(x0.x, x1.x) + s, fmax(x0.y, x1.y) + s, fmax(x0.z, x1.z) + s)};
    if (box_cells(c, sg.lo, sg.hi) > MAX_CELLS) {
        for (uint32_t q = 0; q < c->nactive; q++) consider(c, x, p, c->active[q], &sg, best);
    } else {
        FOR_CELLS(c, sg.lo, sg.hi, for (uint32_t q = c->start[b_]; q < c->start[b_ + 1]; q++) consider(c, x, p, c->items[q], &sg, best);)
        for (uint32_t q = 0; q < c->nbig; q++) consider(c, x, p, c->big[q], &sg, best);
    }
    return best->t < INFINITY;
}

static void respond(const spn_tri_collider *c, spn_world *w, uint32_t p, const contact *k, spn_vec3 x1)
{
    const spn_vec3 *v = spn_world_velocities(w);
    spn_vec3 vt = spn_v3(0, 0, 0);
    for (int j = 0; j < 3; j++) vt = spn_v3_add(vt, spn_v3_scale(v[c->tri[3 * k->tri + j]], 1.0 / 3));
    spn_world_set_position(w, p, spn_v3_add(x1, spn_v3_scale(k->n, c->skin - k->a1)));
    spn_vec3 vr = spn_v3_sub(v[p], vt);
    double vn = spn_v3_dot(vr, k->n);
    if (vn >= 0) return;
    spn_vec3 tang = spn_v3_sub(vr, spn_v3_scale(k->n, vn));
    vr = spn_v3_sub(spn_v3_scale(tang, 1 - c->friction), spn_v3_scale(k->n, vn * c->restitution));
    spn_world_set_velocity(w, p, spn_v3_add(vt, vr));
}

uint64_t spn__tri_collider_resolve(spn_tri_collider *c, spn_world *w, const spn_vec3 *x0)
{
    if (c->ntri == 0) return 0;
    const spn_vec3 *x = spn_world_positions(w);
    if ((c->follow || !c->built) && !build(c, x)) return 0;
    if (c->nactive == 0) return 0;
    uint64_t contacts = 0;
    uint32_t np = spn_world_particle_count(w);
    for (uint32_t p = 0; p < np; p++) {
        if (spn_world_is_fixed(w, p)) continue;
        /* A push-out can reach a neighbouring triangle (a concave corner): retest. */
        for (int pass = 0; pass < 3; pass++) {
            contact k = {0};
            spn_vec3 x1 = x[p];
            if (!find_contact(c, x, p, x0[p], x1, &k)) break;
            respond(c, w, p, &k, x1);
            contacts++;
        }
    }
    return contacts;
}
