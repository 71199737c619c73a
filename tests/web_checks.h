/* Structural checks of built webs shared by the web tests. */
#ifndef SPN_TEST_WEB_CHECKS_H
#define SPN_TEST_WEB_CHECKS_H

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <spinneret/spinneret.h>

/* Every particle reaches a fixed particle through intact springs. */
static inline bool web_all_anchored(const spn_world *w)
{
    uint32_t np = spn_world_particle_count(w), ns = spn_world_spring_count(w);
    bool *seen = calloc(np, 1);
    uint32_t *stack = malloc(np * sizeof *stack), top = 0;
    for (uint32_t i = 0; i < np; i++)
        if (spn_world_is_fixed(w, i)) seen[i] = true, stack[top++] = i;
    /* Repeated sweeps: simple and fine for test sizes. */
    bool changed = true;
    while (changed) {
        changed = false;
        for (uint32_t s = 0; s < ns; s++) {
            spn_spring_info si = spn_world_spring(w, s);
            if (si.broken) continue;
            if (seen[si.a] != seen[si.b]) seen[si.a] = seen[si.b] = true, changed = true;
        }
    }
    bool all = true;
    for (uint32_t i = 0; i < np; i++) all &= seen[i];
    free(seen);
    free(stack);
    return all;
}

static inline bool seg_cross(spn_vec3 a, spn_vec3 b, spn_vec3 c, spn_vec3 d)
{
    double d1 = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
    double d2 = (b.x - a.x) * (d.y - a.y) - (b.y - a.y) * (d.x - a.x);
    double d3 = (d.x - c.x) * (a.y - c.y) - (d.y - c.y) * (a.x - c.x);
    double d4 = (d.x - c.x) * (b.y - c.y) - (d.y - c.y) * (b.x - c.x);
    return ((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0));
}

/* Pairs of springs of kind `a` and kind `b` that cross away from their ends. */
static inline int web_crossings(const spn_world *w, uint32_t ka, uint32_t kb)
{
    uint32_t ns = spn_world_spring_count(w);
    uint32_t *ia = malloc(ns * sizeof *ia), *ib = malloc(ns * sizeof *ib), na = 0, nb = 0;
    for (uint32_t s = 0; s < ns; s++) {
        uint32_t t = spn_world_spring(w, s).tag;
        if (t == ka) ia[na++] = s;
        if (t == kb) ib[nb++] = s;
    }
    int n = 0;
    for (uint32_t i = 0; i < na; i++) {
        spn_spring_info p = spn_world_spring(w, ia[i]);
        spn_vec3 a = spn_world_position(w, p.a), b = spn_world_position(w, p.b);
        for (uint32_t j = 0; j < nb; j++) {
            if (ka == kb && ib[j] <= ia[i]) continue;
            spn_spring_info q = spn_world_spring(w, ib[j]);
            if (q.a == p.a || q.a == p.b || q.b == p.a || q.b == p.b) continue;
            if (seg_cross(a, b, spn_world_position(w, q.a), spn_world_position(w, q.b))) n++;
        }
    }
    free(ia);
    free(ib);
    return n;
}

static inline uint32_t web_count(const spn_world *w, uint32_t kind)
{
    uint32_t n = 0, ns = spn_world_spring_count(w);
    for (uint32_t s = 0; s < ns; s++) n += spn_world_spring(w, s).tag == kind;
    return n;
}

#endif
