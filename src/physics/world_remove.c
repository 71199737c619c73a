/* Taking particles out of a world in place (spn_world_remove_particles), and
 * numbering them anew (spn_world_reorder_particles).
 *
 * Why in place: a world carries much that its spn_world_def does not hold
 * (callbacks and their user pointers, air, colliders, tag diameters and
 * hysteresis, the lattice switch, precision, the implicit preconditioner,
 * contacts, metadata, time, the energy ledger, the adaptive stepper's next
 * sub-step). Rebuilding a world from its particles and springs loses all of
 * it; compacting the arrays of the same world loses none.
 *
 * The caller names the particles to remove by id (not a mask): a selection is
 * what callers have, and a list can be checked entry by entry (range,
 * duplicates) where a mask's length cannot. Invariants after a successful call:
 *  - survivors keep their order and every field bit for bit; the new id of a
 *    survivor is its old id minus the number of removed ids below it;
 *  - a spring goes exactly when one of its ends goes; the others keep their
 *    order and fields, renumbered densely, their ends renumbered as above;
 *  - contacts keep their order with their particle ids renumbered (a contact
 *    on a removed particle is refused: its meaning would change);
 *  - the compiled arrays are freed, so the next step compiles again.
 * Every check, and the one allocation, comes before the first write: a call
 * that fails leaves the world as it was. Built-in colliders are planes and
 * spheres fixed in space, tied to no particle, so they never stop a removal. */
#include "world_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define NOT_LISTED UINT32_MAX

/* map[p] = k for each entry list[k] naming particle p, NOT_LISTED for the
 * particles no entry names (map: particle_count entries); SPN_ERR_INVALID
 * naming the entry (`what`: the call, `name`: the list) that is out of range
 * or repeats an earlier one. The ids of spn_world_remove_particles and the
 * order of spn_world_reorder_particles. */
static spn_status index_entries(const spn_world *w, const uint32_t *list, uint32_t count, uint32_t *map,
                                const char *what, const char *name)
{
    for (uint32_t i = 0; i < w->np; i++) map[i] = NOT_LISTED;
    for (uint32_t k = 0; k < count; k++) {
        const uint32_t p = list[k];
        if (p >= w->np)
            return spn_error(SPN_ERR_INVALID, "%s: %s[%u] = %u does not exist (the world has %u particles)", what, name, k,
                             p, w->np);
        if (map[p] != NOT_LISTED)
            return spn_error(SPN_ERR_INVALID, "%s: %s[%u] = %u repeats %s[%u]", what, name, k, p, name, map[p]);
        map[p] = k;
    }
    return SPN_OK;
}

/* Contacts' particle ids through map (old id -> new). */
static void renumber_contacts(spn_world *w, const uint32_t *map)
{
    for (uint32_t c = 0; c < w->ncontacts; c++) {
        spn_contact *ct = &w->contacts[c];
        ct->p = map[ct->p], ct->a = map[ct->a], ct->b = map[ct->b];
    }
}

/* A contact on a removed particle cannot be kept as it is: refuse (map as
 * index_entries leaves it: each removed particle's ids[] entry). */
static spn_status check_contacts(const spn_world *w, const uint32_t *map)
{
    for (uint32_t c = 0; c < w->ncontacts; c++) {
        const uint32_t ends[3] = {w->contacts[c].p, w->contacts[c].a, w->contacts[c].b};
        for (int e = 0; e < 3; e++)
            if (map[ends[e]] != NOT_LISTED)
                return spn_error(SPN_ERR_INVALID,
                                 "remove particles: ids[%u] = %u is used by contact %u; change the contacts "
                                 "(spn_world_set_contacts) first",
                                 map[ends[e]], ends[e], c);
    }
    return SPN_OK;
}

/* Survivors move down to their new ids; map[old] becomes the new id. */
static void compact_particles(spn_world *w, uint32_t *map)
{
    uint32_t n = 0;
    for (uint32_t i = 0; i < w->np; i++) {
        if (map[i] == SPN_REMOVED) continue;
        map[i] = n;
        w->x[n] = w->x[i];
        w->v[n] = w->v[i];
        w->mass[n] = w->mass[i];
        w->inv_mass[n] = w->inv_mass[i];
        w->ptag[n] = w->ptag[i];
        n++;
    }
    w->np = n;
}

/* Springs with a removed end go; the rest move down with renumbered ends. */
static void compact_springs(spn_world *w, const uint32_t *map, uint32_t *spring_map)
{
    uint32_t n = 0;
    for (uint32_t s = 0; s < w->ns; s++) {
        const uint32_t a = map[w->sa[s]], b = map[w->sb[s]];
        if (spring_map) spring_map[s] = (a == SPN_REMOVED || b == SPN_REMOVED) ? SPN_REMOVED : n;
        if (a == SPN_REMOVED || b == SPN_REMOVED) continue;
        spn__move_spring(w, s, n, a, b);
        n++;
    }
    w->ns = n;
}

spn_status spn_world_remove_particles(spn_world *w, const uint32_t *ids, uint32_t count, uint32_t *particle_map,
                                      uint32_t *spring_map)
{
    if (count > 0 && !ids) return spn_error(SPN_ERR_INVALID, "remove particles: ids is NULL for %u particles", count);
    uint32_t *map = malloc(((size_t)w->np + 1) * sizeof *map);
    if (!map) return spn_error(SPN_ERR_NOMEM, "out of memory removing particles from a world of %u", w->np);
    spn_status st = index_entries(w, ids, count, map, "remove particles", "ids");
    if (st == SPN_OK) st = check_contacts(w, map);
    if (st != SPN_OK) {
        free(map);
        return st;
    }
    for (uint32_t i = 0; i < w->np; i++) map[i] = map[i] == NOT_LISTED ? 0 : SPN_REMOVED; /* compact_particles' marks */
    const uint32_t np_before = w->np;
    compact_particles(w, map);
    compact_springs(w, map, spring_map);
    renumber_contacts(w, map);
    if (particle_map)
        for (uint32_t i = 0; i < np_before; i++) particle_map[i] = map[i];
    free(map);
    /* The compiled arrays hold old ids and sizes: drop them (the next step
     * compiles), as spn_world_compile would before rebuilding anyway. */
    spn__free_compiled(w);
    return SPN_OK;
}

/* ---- renumbering (spn_world_reorder_particles) ---------------------------- */

/* Each array of n elements of `size` bytes put in the new order: out[k] =
 * in[order[k]], through scratch (n * size bytes). */
static void permute(void *a, const uint32_t *order, uint32_t n, size_t size, unsigned char *scratch)
{
    const unsigned char *in = a;
    for (uint32_t k = 0; k < n; k++) memcpy(scratch + (size_t)k * size, in + (size_t)order[k] * size, size);
    memcpy(a, scratch, (size_t)n * size);
}

spn_status spn_world_reorder_particles(spn_world *w, const uint32_t *order)
{
    if (!w) return spn_error(SPN_ERR_INVALID, "reorder particles: world is NULL");
    if (!order && w->np) return spn_error(SPN_ERR_INVALID, "reorder particles: order is NULL for %u particles", w->np);
    const uint32_t np = w->np;
    uint32_t *map = malloc(((size_t)np + 1) * sizeof *map);
    unsigned char *scratch = malloc(((size_t)np + 1) * sizeof(spn_vec3));
    if (!map || !scratch) {
        free(map), free(scratch);
        return spn_error(SPN_ERR_NOMEM, "out of memory renumbering a world of %u particles", np);
    }
    /* map[p]: the new id of old particle p (np entries, none repeated: every id) */
    spn_status st = index_entries(w, order, np, map, "reorder particles", "order");
    if (st != SPN_OK) {
        free(map), free(scratch);
        return st;
    }
    permute(w->x, order, np, sizeof *w->x, scratch);
    permute(w->v, order, np, sizeof *w->v, scratch);
    permute(w->mass, order, np, sizeof *w->mass, scratch);
    permute(w->inv_mass, order, np, sizeof *w->inv_mass, scratch);
    permute(w->ptag, order, np, sizeof *w->ptag, scratch);
    for (uint32_t s = 0; s < w->ns; s++) w->sa[s] = map[w->sa[s]], w->sb[s] = map[w->sb[s]];
    renumber_contacts(w, map);
    free(map), free(scratch);
    spn__free_compiled(w);
    return SPN_OK;
}

/* x's low 21 bits spread to every third bit. */
static uint64_t spread3(uint64_t x)
{
    x &= 0x1fffff;
    x = (x | x << 32) & 0x1f00000000ffffull;
    x = (x | x << 16) & 0x1f0000ff0000ffull;
    x = (x | x << 8) & 0x100f00f00f00f00full;
    x = (x | x << 4) & 0x10c30c30c30c30c3ull;
    x = (x | x << 2) & 0x1249249249249249ull;
    return x;
}

typedef struct keyed {
    uint64_t key;
    uint32_t id;
} keyed;

static int by_key(const void *pa, const void *pb)
{
    const keyed *a = pa, *b = pb;
    if (a->key != b->key) return a->key < b->key ? -1 : 1;
    return a->id < b->id ? -1 : a->id > b->id;
}

spn_status spn_world_locality_order(const spn_world *w, uint32_t *order)
{
    if (!w || !order) return spn_error(SPN_ERR_INVALID, "locality order: %s is NULL", w ? "order" : "world");
    const uint32_t np = w->np;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t i = 0; i < np; i++) {
        const double c[3] = {w->x[i].x, w->x[i].y, w->x[i].z};
        for (int d = 0; d < 3; d++) {
            if (!isfinite(c[d]))
                return spn_error(SPN_ERR_INVALID, "locality order: particle %u has a position that is not finite", i);
            lo[d] = fmin(lo[d], c[d]), hi[d] = fmax(hi[d], c[d]);
        }
    }
    keyed *k = malloc(((size_t)np + 1) * sizeof *k);
    if (!k) return spn_error(SPN_ERR_NOMEM, "out of memory ordering %u particles", np);
    const double cells = (double)((1u << 21) - 1);
    for (uint32_t i = 0; i < np; i++) {
        const double c[3] = {w->x[i].x, w->x[i].y, w->x[i].z};
        uint64_t key = 0;
        for (int d = 0; d < 3; d++) {
            const double span = hi[d] - lo[d];
            const uint64_t q = span > 0 ? (uint64_t)((c[d] - lo[d]) / span * cells) : 0;
            key |= spread3(q) << d;
        }
        k[i] = (keyed){key, i};
    }
    qsort(k, np, sizeof *k, by_key);
    for (uint32_t i = 0; i < np; i++) order[i] = k[i].id;
    free(k);
    return SPN_OK;
}
