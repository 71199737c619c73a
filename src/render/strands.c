/* Strands: the springs of a world chained into paths, so a thread is drawn as
 * one stroke through its particles and its joints show neither dots (round
 * caps overlapping under alpha) nor gaps.
 *
 * For each thread kind, springs of that kind form a graph over the particles.
 * A particle of degree 2 in that graph is a joint inside a strand; any other
 * degree (an end, or a junction such as the hub where many radii meet) ends
 * strands. Open chains are walked first from their ends, then what is left are
 * pure cycles (a ring of capture spiral), emitted as closed strands.
 * Invariants: every intact spring lies in exactly one strand; broken springs
 * and springs joining a particle to itself are not drawn; the order depends
 * only on the world (kind rank, then spring ids), never on memory. */
#include "render_internal.h"

#include <stdlib.h>
#include <string.h>

/* Springs of one kind as an adjacency list: for particle p, its springs are
 * adj[start[p] .. start[p+1]) in increasing spring id. */
typedef struct kind_graph {
    uint32_t *start;
    uint32_t *adj;
    uint32_t *a, *b;   /* spring endpoints, indexed by spring id */
    bool *visited;     /* by spring id */
} kind_graph;

typedef struct builder {
    spn__strands *out;   /* arrays sized for the worst case: 2 points per spring */
} builder;

static int compare_kinds(const void *x, const void *y)
{
    uint32_t a = *(const uint32_t *)x, b = *(const uint32_t *)y;
    int ra = spn__kind_rank(a), rb = spn__kind_rank(b);
    if (ra != rb) return ra < rb ? -1 : 1;
    return a < b ? -1 : a > b;
}

static uint32_t degree(const kind_graph *g, uint32_t p) { return g->start[p + 1] - g->start[p]; }

static void push_point(builder *bd, uint32_t particle, uint32_t spring, const spn_vec3 *pos)
{
    spn__strands *s = bd->out;
    s->points[s->point_count] = pos[particle];
    s->particles[s->point_count] = particle;
    s->springs[s->point_count] = spring;
    s->point_count++;
}

/* The first unvisited spring at particle p, or UINT32_MAX. */
static uint32_t next_spring(const kind_graph *g, uint32_t p)
{
    for (uint32_t i = g->start[p]; i < g->start[p + 1]; i++)
        if (!g->visited[g->adj[i]]) return g->adj[i];
    return UINT32_MAX;
}

/* Walk from particle p along spring s while joints have degree 2. */
static void walk(builder *bd, kind_graph *g, uint32_t kind, uint32_t p, uint32_t s, const spn_vec3 *pos)
{
    spn__chain c = {kind, bd->out->point_count, 0, false};
    uint32_t start = p;
    for (;;) {
        g->visited[s] = true;
        push_point(bd, p, s, pos);
        p = g->a[s] == p ? g->b[s] : g->a[s];
        if (p == start && degree(g, p) == 2) {
            c.closed = true;
            break;
        }
        if (degree(g, p) != 2) break;
        s = next_spring(g, p);
        if (s == UINT32_MAX) break;
    }
    if (!c.closed) push_point(bd, p, UINT32_MAX, pos);
    c.count = bd->out->point_count - c.first;
    bd->out->chains[bd->out->chain_count++] = c;
}

static spn_status build_kind(builder *bd, const spn_world *w, uint32_t kind, const uint32_t *ids, uint32_t n,
                             kind_graph *g)
{
    uint32_t np = spn_world_particle_count(w);
    const spn_vec3 *pos = spn_world_positions(w);
    memset(g->start, 0, (np + 1) * sizeof *g->start);
    for (uint32_t i = 0; i < n; i++) {
        g->start[g->a[ids[i]] + 1]++;
        g->start[g->b[ids[i]] + 1]++;
    }
    for (uint32_t p = 0; p < np; p++) g->start[p + 1] += g->start[p];
    uint32_t *fill = malloc((np + 1) * sizeof *fill);
    if (!fill) return spn_error(SPN_ERR_NOMEM, "render: out of memory");
    memcpy(fill, g->start, (np + 1) * sizeof *fill);
    for (uint32_t i = 0; i < n; i++) {
        g->adj[fill[g->a[ids[i]]]++] = ids[i];
        g->adj[fill[g->b[ids[i]]]++] = ids[i];
    }
    free(fill);
    for (uint32_t i = 0; i < n; i++) {
        uint32_t s = ids[i];
        if (g->visited[s]) continue;
        if (degree(g, g->a[s]) != 2) walk(bd, g, kind, g->a[s], s, pos);
        else if (degree(g, g->b[s]) != 2) walk(bd, g, kind, g->b[s], s, pos);
    }
    for (uint32_t i = 0; i < n; i++)
        if (!g->visited[ids[i]]) walk(bd, g, kind, g->a[ids[i]], ids[i], pos);
    return SPN_OK;
}

/* Intact springs grouped by kind: sorted by (kind rank, kind, id). */
typedef struct tagged {
    uint32_t kind, id;
} tagged;

static int compare_tagged(const void *x, const void *y)
{
    const tagged *a = x, *b = y;
    int k = compare_kinds(&a->kind, &b->kind);
    if (k) return k;
    return a->id < b->id ? -1 : a->id > b->id;
}

static spn_status alloc_all(spn__strands *out, kind_graph *g, uint32_t np, uint32_t ns, tagged **list)
{
    memset(out, 0, sizeof *out);
    g->start = malloc(((size_t)np + 1) * sizeof *g->start);
    g->adj = malloc(((size_t)ns * 2 + 1) * sizeof *g->adj);
    g->a = malloc(((size_t)ns + 1) * sizeof *g->a);
    g->b = malloc(((size_t)ns + 1) * sizeof *g->b);
    g->visited = calloc((size_t)ns + 1, sizeof *g->visited);
    *list = malloc(((size_t)ns + 1) * sizeof **list);
    out->chains = malloc(((size_t)ns + 1) * sizeof *out->chains);
    out->points = malloc(((size_t)ns * 2 + 1) * sizeof *out->points);
    out->particles = malloc(((size_t)ns * 2 + 1) * sizeof *out->particles);
    out->springs = malloc(((size_t)ns * 2 + 1) * sizeof *out->springs);
    if (!g->start || !g->adj || !g->a || !g->b || !g->visited || !*list || !out->chains || !out->points ||
        !out->particles || !out->springs)
        return spn_error(SPN_ERR_NOMEM, "render: out of memory for %u springs", ns);
    return SPN_OK;
}

static void free_graph(kind_graph *g, tagged *list)
{
    free(g->start);
    free(g->adj);
    free(g->a);
    free(g->b);
    free(g->visited);
    free(list);
}

spn_status spn__strands_build(const spn_world *w, spn__strands *out)
{
    uint32_t np = spn_world_particle_count(w), ns = spn_world_spring_count(w);
    kind_graph g;
    tagged *list = NULL;
    spn_status st = alloc_all(out, &g, np, ns, &list);
    uint32_t n = 0;
    for (uint32_t s = 0; s < ns && st == SPN_OK; s++) {
        spn_spring_info info = spn_world_spring(w, s);
        g.a[s] = info.a;
        g.b[s] = info.b;
        if (info.broken || info.a == info.b) continue;
        list[n].kind = info.tag;
        list[n++].id = s;
    }
    if (st == SPN_OK) qsort(list, n, sizeof *list, compare_tagged);
    builder bd = {out};
    uint32_t *ids = st == SPN_OK ? malloc(((size_t)n + 1) * sizeof *ids) : NULL;
    if (st == SPN_OK && !ids) st = spn_error(SPN_ERR_NOMEM, "render: out of memory");
    for (uint32_t i = 0; i < n && st == SPN_OK;) {
        uint32_t j = i, kind = list[i].kind;
        while (j < n && list[j].kind == kind) {
            ids[j - i] = list[j].id;
            j++;
        }
        st = build_kind(&bd, w, kind, ids, j - i, &g);
        i = j;
    }
    free(ids);
    free_graph(&g, list);
    if (st != SPN_OK) spn__strands_free(out);
    return st;
}

void spn__strands_free(spn__strands *s)
{
    free(s->chains);
    free(s->points);
    free(s->particles);
    free(s->springs);
    memset(s, 0, sizeof *s);
}
