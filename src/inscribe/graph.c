/* Graph edits that keep an inscribed web physical: threads put in are made
 * of the web's own capture silk (stiffness EA / rest, mass shared by the ends,
 * laid with the web's pre-strain), and after threads are taken out nothing is
 * left hanging: a free particle with a single thread is a dangling end, so
 * that thread goes too (repeatedly); threads no longer connected to a fixed
 * particle go; particles left with no thread are taken out of the world in
 * place (spn_world_remove_particles), so it keeps every setting made on it.
 * Invariant after spn__clean: every free particle has at least two threads
 * and a path of threads to a fixed particle. */
#include "inscribe_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

spn_status spn__graph_build(const spn_world *w, const bool *skip, spn__graph *g)
{
    memset(g, 0, sizeof *g);
    g->np = spn_world_particle_count(w);
    g->ns = spn_world_spring_count(w);
    g->start = calloc((size_t)g->np + 1, sizeof *g->start);
    g->edge = malloc(((size_t)g->ns * 2 + 1) * sizeof *g->edge);
    if (!g->start || !g->edge) {
        spn__graph_free(g);
        return spn_error(SPN_ERR_NOMEM, "out of memory");
    }
    for (uint32_t s = 0; s < g->ns; s++) {
        spn_spring_info si = spn_world_spring(w, s);
        if ((skip && skip[s]) || si.broken) continue;
        g->start[si.a + 1]++, g->start[si.b + 1]++;
    }
    for (uint32_t i = 0; i < g->np; i++) g->start[i + 1] += g->start[i];
    uint32_t *fill = malloc(((size_t)g->np + 1) * sizeof *fill);
    if (!fill) {
        spn__graph_free(g);
        return spn_error(SPN_ERR_NOMEM, "out of memory");
    }
    memcpy(fill, g->start, (size_t)g->np * sizeof *fill);
    for (uint32_t s = 0; s < g->ns; s++) {
        spn_spring_info si = spn_world_spring(w, s);
        if ((skip && skip[s]) || si.broken) continue;
        g->edge[fill[si.a]++] = s;
        g->edge[fill[si.b]++] = s;
    }
    free(fill);
    return SPN_OK;
}

void spn__graph_free(spn__graph *g)
{
    free(g->start);
    free(g->edge);
    memset(g, 0, sizeof *g);
}

uint32_t spn__other_end(const spn_world *w, uint32_t s, uint32_t p)
{
    spn_spring_info si = spn_world_spring(w, s);
    return si.a == p ? si.b : si.a;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(double *v, size_t n, double fallback)
{
    if (n == 0) return fallback;
    qsort(v, n, sizeof *v, cmp_double);
    return v[n / 2];
}

spn__material spn__capture_material(const spn_world *w)
{
    spn__material m = {0.07, 1e-6, 0.02, 0.02, true};
    uint32_t ns = spn_world_spring_count(w), np = spn_world_particle_count(w), n = 0;
    double *ea = malloc(((size_t)ns + 1) * sizeof *ea), *pre = malloc(((size_t)ns + 1) * sizeof *pre);
    double *zeta = malloc(((size_t)ns + 1) * sizeof *zeta);
    double rest_total = 0, mass_total = 0;
    for (uint32_t s = 0; s < ns; s++) {
        spn_spring_info si = spn_world_spring(w, s);
        if (!si.broken) rest_total += si.rest;
        if (!ea || !pre || !zeta || si.tag != SPN_THREAD_CAPTURE || si.broken || !(si.rest > 0)) continue;
        ea[n] = si.k * si.rest;
        pre[n] = si.length / si.rest - 1;
        zeta[n++] = si.kd; /* converted below, once the density is known */
    }
    for (uint32_t i = 0; i < np; i++) mass_total += spn_world_mass(w, i);
    if (rest_total > 0 && mass_total > 0) m.density = mass_total / rest_total;
    if (ea && pre && zeta && n > 0) {
        uint32_t k = 0;
        for (uint32_t s = 0; s < ns; s++) {
            spn_spring_info si = spn_world_spring(w, s);
            if (si.tag != SPN_THREAD_CAPTURE || si.broken || !(si.rest > 0)) continue;
            zeta[k++] = si.kd / (2 * sqrt(si.k * m.density * si.rest));
        }
        m.ea = median(ea, n, m.ea);
        m.prestrain = fmax(0, median(pre, n, m.prestrain));
        m.damping = median(zeta, n, m.damping);
    }
    free(ea), free(pre), free(zeta);
    return m;
}

spn_status spn__add_thread(spn_world *w, const spn__material *m, uint32_t a, uint32_t b, uint32_t tag)
{
    double len = spn_v3_len(spn_v3_sub(spn_world_position(w, a), spn_world_position(w, b)));
    if (!(len > 0)) return SPN_OK; /* coincident particles: nothing to lay */
    spn_spring_def d = spn_spring_def_default();
    d.a = a, d.b = b;
    d.rest = len / (1 + m->prestrain);
    d.k = m->ea / d.rest;
    double mseg = m->density * d.rest;
    d.kd = m->damping * 2 * sqrt(d.k * mseg);
    d.tension_only = m->tension_only;
    d.tag = tag;
    d.stage = tag;
    d.order = spn_world_spring_count(w);
    spn_status st = spn_world_add_spring(w, &d, NULL);
    for (int e = 0; e < 2 && st == SPN_OK; e++) {
        uint32_t p = e ? b : a;
        if (!spn_world_is_fixed(w, p)) st = spn_world_set_mass(w, p, spn_world_mass(w, p) + 0.5 * mseg);
    }
    return st;
}

/* Mark dangling threads dead until none is left: a free particle with one live thread. */
static void prune_dangling(const spn_world *w, const spn__graph *g, bool *dead, uint32_t *pruned)
{
    uint32_t *deg = calloc(g->np ? g->np : 1, sizeof *deg);
    uint32_t *queue = malloc(((size_t)g->np + 1) * sizeof *queue);
    if (!deg || !queue) goto done;
    uint32_t head = 0, tail = 0;
    for (uint32_t i = 0; i < g->np; i++) {
        for (uint32_t e = g->start[i]; e < g->start[i + 1]; e++) deg[i] += !dead[g->edge[e]];
        if (deg[i] == 1 && !spn_world_is_fixed(w, i)) queue[tail++] = i;
    }
    while (head < tail) {
        uint32_t p = queue[head++];
        if (deg[p] != 1) continue;
        for (uint32_t e = g->start[p]; e < g->start[p + 1]; e++) {
            uint32_t s = g->edge[e];
            if (dead[s]) continue;
            dead[s] = true;
            (*pruned)++;
            deg[p]--;
            uint32_t q = spn__other_end(w, s, p);
            if (--deg[q] == 1 && !spn_world_is_fixed(w, q)) queue[tail++] = q;
        }
    }
done:
    free(deg);
    free(queue);
}

/* Mark dead every live thread not connected to a fixed particle; `reach` gets reachability. */
static spn_status prune_unanchored(const spn_world *w, const spn__graph *g, bool *dead, bool *reach, uint32_t *pruned)
{
    uint32_t *stack = malloc(((size_t)g->np + 1) * sizeof *stack), top = 0;
    if (!stack) return spn_error(SPN_ERR_NOMEM, "out of memory");
    for (uint32_t i = 0; i < g->np; i++) {
        reach[i] = spn_world_is_fixed(w, i);
        if (reach[i]) stack[top++] = i;
    }
    while (top > 0) {
        uint32_t p = stack[--top];
        for (uint32_t e = g->start[p]; e < g->start[p + 1]; e++) {
            if (dead[g->edge[e]]) continue;
            uint32_t q = spn__other_end(w, g->edge[e], p);
            if (!reach[q]) reach[q] = true, stack[top++] = q;
        }
    }
    free(stack);
    for (uint32_t s = 0; s < g->ns; s++) {
        spn_spring_info si = spn_world_spring(w, s);
        if (!dead[s] && !si.broken && !reach[si.a]) dead[s] = true, (*pruned)++;
    }
    return SPN_OK;
}

spn_status spn__clean(spn_world *w, const bool *remove, uint32_t *pruned, uint32_t *particles_removed)
{
    uint32_t np = spn_world_particle_count(w), ns = spn_world_spring_count(w), dropped = 0;
    bool *dead = calloc((size_t)ns + 1, sizeof *dead), *reach = calloc((size_t)np + 1, sizeof *reach);
    uint32_t *drop = malloc(((size_t)np + 1) * sizeof *drop);
    spn__graph g = {0, 0, NULL, NULL};
    spn_status st = dead && reach && drop ? spn__graph_build(w, NULL, &g) : spn_error(SPN_ERR_NOMEM, "out of memory");
    if (st == SPN_OK) {
        for (uint32_t s = 0; s < ns; s++) dead[s] = remove && remove[s];
        prune_dangling(w, &g, dead, pruned);
        st = prune_unanchored(w, &g, dead, reach, pruned);
    }
    if (st == SPN_OK) {
        /* Particles with no live thread (free ones only: anchors stay). */
        for (uint32_t i = 0; i < np; i++) {
            bool live = false;
            for (uint32_t e = g.start[i]; e < g.start[i + 1] && !live; e++) live = !dead[g.edge[e]];
            if (!live && !spn_world_is_fixed(w, i)) drop[dropped++] = i;
        }
        /* In place, so the world keeps its callbacks, colliders and the rest;
         * the dropped particles' broken springs go with them. */
        st = spn_world_remove_springs(w, dead);
        if (st == SPN_OK) st = spn_world_remove_particles(w, drop, dropped, NULL, NULL);
    }
    spn__graph_free(&g);
    if (st == SPN_OK) *particles_removed += dropped;
    free(dead);
    free(reach);
    free(drop);
    return st;
}
