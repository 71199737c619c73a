/* Taking particles out of a world in place (spn_world_remove_particles).
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

#include <stdlib.h>

/* The first ids[] entry naming particle p (for the duplicate message). */
static uint32_t first_entry(const uint32_t *ids, uint32_t p)
{
    uint32_t k = 0;
    while (ids[k] != p) k++;
    return k;
}

/* Mark the removed particles in map (SPN_REMOVED; others 0); SPN_ERR_INVALID
 * naming the ids[] entry that is out of range or a duplicate. */
static spn_status mark_removed(const spn_world *w, const uint32_t *ids, uint32_t count, uint32_t *map)
{
    for (uint32_t k = 0; k < count; k++) {
        const uint32_t p = ids[k];
        if (p >= w->np)
            return spn_error(SPN_ERR_INVALID, "remove particles: ids[%u] = %u does not exist (the world has %u particles)",
                             k, p, w->np);
        if (map[p] == SPN_REMOVED)
            return spn_error(SPN_ERR_INVALID, "remove particles: ids[%u] = %u repeats ids[%u]", k, p,
                             first_entry(ids, p));
        map[p] = SPN_REMOVED;
    }
    return SPN_OK;
}

/* A contact on a removed particle cannot be kept as it is: refuse. */
static spn_status check_contacts(const spn_world *w, const uint32_t *ids, const uint32_t *map)
{
    for (uint32_t c = 0; c < w->ncontacts; c++) {
        const uint32_t ends[3] = {w->contacts[c].p, w->contacts[c].a, w->contacts[c].b};
        for (int e = 0; e < 3; e++)
            if (map[ends[e]] == SPN_REMOVED)
                return spn_error(SPN_ERR_INVALID,
                                 "remove particles: ids[%u] = %u is used by contact %u; change the contacts "
                                 "(spn_world_set_contacts) first",
                                 first_entry(ids, ends[e]), ends[e], c);
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
    uint32_t *map = calloc((size_t)w->np + 1, sizeof *map);
    if (!map) return spn_error(SPN_ERR_NOMEM, "out of memory removing particles from a world of %u", w->np);
    spn_status st = mark_removed(w, ids, count, map);
    if (st == SPN_OK) st = check_contacts(w, ids, map);
    if (st != SPN_OK) {
        free(map);
        return st;
    }
    const uint32_t np_before = w->np;
    compact_particles(w, map);
    compact_springs(w, map, spring_map);
    for (uint32_t c = 0; c < w->ncontacts; c++) {
        spn_contact *ct = &w->contacts[c];
        ct->p = map[ct->p], ct->a = map[ct->a], ct->b = map[ct->b];
    }
    if (particle_map)
        for (uint32_t i = 0; i < np_before; i++) particle_map[i] = map[i];
    free(map);
    /* The compiled arrays hold old ids and sizes: drop them (the next step
     * compiles), as spn_world_compile would before rebuilding anyway. */
    spn__free_compiled(w);
    return SPN_OK;
}
