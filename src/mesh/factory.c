/* The mesh factory (Juhasz & Bercovici, "Spring Systems", Mesh Factory): a
 * mass point per vertex; a stretch spring per edge; a bend spring per pair of
 * triangles sharing an edge, joining the two vertices opposite that edge; a
 * vicinity spring per pair of vertices nearer than a threshold. Every spring
 * rests at its initial length, so the mesh as given is the rest shape.
 * Invariants: at most one spring per vertex pair (a pair set is consulted in
 * the order stretch, bend, vicinity); near pairs are found with a hash grid of
 * cell size = threshold, so the cost follows the number of near pairs, not
 * the square of the vertex count. Results do not depend on hash order: the
 * grid is only used to list candidates of each vertex, in vertex order. */
#include "mesh_internal.h"

#include "spinneret/web.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

spn_mesh_spring_def spn_mesh_spring_def_default(void)
{
    spn_mesh_spring_def d;
    memset(&d, 0, sizeof d);
    d.stretch_k = 1500;
    d.stretch_kd = 4;
    d.bend_k = 1500;
    d.bend_kd = 3;
    d.vicinity_k = -1; /* negative: take the bend values */
    d.vicinity_kd = -1;
    d.vertex_mass = 0.5;
    return d;
}

static spn_status check_def(const spn_mesh_spring_def *d)
{
    const double v[] = {d->stretch_k, d->stretch_kd, d->bend_k, d->bend_kd, d->vicinity, d->vertex_mass, d->total_mass};
    const char *names[] = {"stretch_k", "stretch_kd", "bend_k", "bend_kd", "vicinity", "vertex_mass", "total_mass"};
    for (int i = 0; i < 7; i++)
        if (!(v[i] >= 0) || !isfinite(v[i]))
            return spn_error(SPN_ERR_INVALID, "mesh factory: %s must be finite and >= 0, got %g", names[i], v[i]);
    if (!(d->vertex_mass > 0) && !(d->total_mass > 0) && !d->fixed)
        return spn_error(SPN_ERR_INVALID, "mesh factory: vertex_mass or total_mass must be positive");
    return SPN_OK;
}

/* Mass of each vertex: a third of the area of each incident triangle, scaled
 * to the total; vertices used by no triangle get the mean share. */
static void area_masses(const spn_mesh *m, double total, double *mass)
{
    double sum = 0;
    memset(mass, 0, m->vertex_count * sizeof *mass);
    for (uint32_t t = 0; t < m->triangle_count; t++) {
        const uint32_t *v = m->triangles + 3 * t;
        spn_vec3 e1 = spn_v3_sub(m->vertices[v[1]], m->vertices[v[0]]);
        spn_vec3 e2 = spn_v3_sub(m->vertices[v[2]], m->vertices[v[0]]);
        double a = 0.5 * spn_v3_len(spn_v3_cross(e1, e2));
        for (int k = 0; k < 3; k++) mass[v[k]] += a / 3;
        sum += a;
    }
    double mean = total / m->vertex_count;
    for (uint32_t i = 0; i < m->vertex_count; i++)
        mass[i] = sum > 0 && mass[i] > 0 ? total * mass[i] / sum : mean;
    /* Renormalise so unreferenced vertices do not add mass beyond the total. */
    double s2 = 0;
    for (uint32_t i = 0; i < m->vertex_count; i++) s2 += mass[i];
    for (uint32_t i = 0; i < m->vertex_count; i++) mass[i] *= total / s2;
}

static spn_status add_particles(spn_world *w, const spn_mesh *m, const spn_mesh_spring_def *d, spn_mesh_stats *st)
{
    double *mass = malloc(m->vertex_count * sizeof *mass);
    if (!mass) return spn_error(SPN_ERR_NOMEM, "mesh factory: out of memory");
    if (d->total_mass > 0) area_masses(m, d->total_mass, mass);
    else
        for (uint32_t i = 0; i < m->vertex_count; i++) mass[i] = d->vertex_mass;
    uint32_t group = d->fixed_group ? spn_mesh_group(m, d->fixed_group) : UINT32_MAX;
    bool *in_group = calloc(m->vertex_count, sizeof *in_group);
    if (!in_group) {
        free(mass);
        return spn_error(SPN_ERR_NOMEM, "mesh factory: out of memory");
    }
    for (uint32_t t = 0; group != UINT32_MAX && t < m->triangle_count; t++)
        if (m->triangle_group && m->triangle_group[t] == group)
            for (int k = 0; k < 3; k++) in_group[m->triangles[3 * t + k]] = true;
    spn_status s = SPN_OK;
    st->first_particle = spn_world_particle_count(w);
    for (uint32_t i = 0; s == SPN_OK && i < m->vertex_count; i++) {
        spn_particle_def p = spn_particle_def_default();
        p.position = m->vertices[i];
        p.mass = mass[i] > 0 ? mass[i] : d->vertex_mass;
        p.fixed = d->fixed || in_group[i] || (d->fixed_vertices && d->fixed_vertices[i]);
        p.velocity = p.fixed ? spn_v3(0, 0, 0) : d->velocity;
        p.tag = d->particle_tag;
        s = spn_world_add_particle(w, &p, NULL);
        st->particles++;
        st->fixed += p.fixed;
    }
    free(mass);
    free(in_group);
    return s;
}

static spn_status add_spring(spn_world *w, const spn_mesh_stats *st, uint32_t a, uint32_t b, double k, double kd,
                             uint32_t tag)
{
    spn_spring_def s = spn_spring_def_default();
    s.a = st->first_particle + a;
    s.b = st->first_particle + b;
    s.k = k;
    s.kd = kd;
    s.rest = -1;
    s.tag = tag;
    s.order = spn_world_spring_count(w);
    return spn_world_add_spring(w, &s, NULL);
}

/* An edge of a triangle with the vertex opposite it; sorted by (lo, hi). */
typedef struct half_edge {
    uint32_t lo, hi, opposite;
} half_edge;

static int cmp_half_edge(const void *pa, const void *pb)
{
    const half_edge *a = pa, *b = pb;
    if (a->lo != b->lo) return a->lo < b->lo ? -1 : 1;
    if (a->hi != b->hi) return a->hi < b->hi ? -1 : 1;
    return (a->opposite > b->opposite) - (a->opposite < b->opposite);
}

static spn_status add_edges_and_bends(spn_world *w, const spn_mesh *m, const spn_mesh_spring_def *d,
                                      spn_pair_set *set, spn_mesh_stats *st)
{
    size_t n = 3 * (size_t)m->triangle_count;
    half_edge *he = malloc(n * sizeof *he);
    if (!he) return spn_error(SPN_ERR_NOMEM, "mesh factory: out of memory");
    for (uint32_t t = 0; t < m->triangle_count; t++)
        for (int k = 0; k < 3; k++) {
            uint32_t a = m->triangles[3 * t + k], b = m->triangles[3 * t + (k + 1) % 3];
            he[3 * t + k] = (half_edge){a < b ? a : b, a < b ? b : a, m->triangles[3 * t + (k + 2) % 3]};
        }
    qsort(he, n, sizeof *he, cmp_half_edge);
    spn_status s = SPN_OK;
    bool oom = false;
    for (size_t i = 0; s == SPN_OK && i < n; i++)
        if (i == 0 || he[i].lo != he[i - 1].lo || he[i].hi != he[i - 1].hi) {
            spn__pair_set_insert(set, he[i].lo, he[i].hi, &oom);
            st->edges++;
            s = add_spring(w, st, he[i].lo, he[i].hi, d->stretch_k, d->stretch_kd, SPN_THREAD_STRETCH);
        }
    /* Bends after every edge, so an opposite pair that is also an edge (a
     * tetrahedron) stays a single stretch spring. */
    for (size_t i = 0; s == SPN_OK && i < n; i++)
        for (size_t j = i + 1; s == SPN_OK && j < n && he[j].lo == he[i].lo && he[j].hi == he[i].hi; j++) {
            st->bend_pairs++;
            if (he[i].opposite == he[j].opposite || !spn__pair_set_insert(set, he[i].opposite, he[j].opposite, &oom))
                continue;
            st->bend++;
            s = add_spring(w, st, he[i].opposite, he[j].opposite, d->bend_k, d->bend_kd, SPN_THREAD_BEND);
        }
    free(he);
    if (oom) return spn_error(SPN_ERR_NOMEM, "mesh factory: out of memory");
    return s;
}

/* Hash grid of vertices: cell_start/cell_items in CSR form over hashed cells. */
typedef struct point_grid {
    double cell;
    uint32_t mask;
    uint32_t *start, *items;
} point_grid;

static uint32_t cell_hash(int64_t x, int64_t y, int64_t z, uint32_t mask)
{
    uint64_t h = (uint64_t)x * 73856093u ^ (uint64_t)y * 19349663u ^ (uint64_t)z * 83492791u;
    h ^= h >> 29;
    return (uint32_t)(h * 0x9e3779b97f4a7c15ULL >> 32) & mask;
}

static uint32_t point_cell(const point_grid *g, spn_vec3 p, int dx, int dy, int dz)
{
    return cell_hash((int64_t)floor(p.x / g->cell) + dx, (int64_t)floor(p.y / g->cell) + dy,
                     (int64_t)floor(p.z / g->cell) + dz, g->mask);
}

static bool point_grid_build(point_grid *g, const spn_mesh *m, double cell)
{
    uint32_t size = 64;
    while (size < 2 * m->vertex_count) size *= 2;
    g->cell = cell;
    g->mask = size - 1;
    g->start = calloc(size + 1, sizeof *g->start);
    g->items = malloc(m->vertex_count * sizeof *g->items);
    if (!g->start || !g->items) return false;
    for (uint32_t i = 0; i < m->vertex_count; i++) g->start[point_cell(g, m->vertices[i], 0, 0, 0) + 1]++;
    for (uint32_t c = 0; c < size; c++) g->start[c + 1] += g->start[c];
    uint32_t *fill = malloc(size * sizeof *fill);
    if (!fill) return false;
    memcpy(fill, g->start, size * sizeof *fill);
    for (uint32_t i = 0; i < m->vertex_count; i++) g->items[fill[point_cell(g, m->vertices[i], 0, 0, 0)]++] = i;
    free(fill);
    return true;
}

static spn_status add_vicinity(spn_world *w, const spn_mesh *m, const spn_mesh_spring_def *d, spn_pair_set *set,
                               spn_mesh_stats *st)
{
    point_grid g = {0};
    spn_status s = SPN_OK;
    bool oom = !point_grid_build(&g, m, d->vicinity);
    double k = d->vicinity_k >= 0 ? d->vicinity_k : d->bend_k, kd = d->vicinity_kd >= 0 ? d->vicinity_kd : d->bend_kd;
    double r2 = d->vicinity * d->vicinity;
    for (uint32_t i = 0; !oom && s == SPN_OK && i < m->vertex_count; i++)
        for (int c = 0; c < 27 && s == SPN_OK; c++) {
            uint32_t cell = point_cell(&g, m->vertices[i], c % 3 - 1, c / 3 % 3 - 1, c / 9 - 1);
            /* Different offsets can hash to one bucket: visit each bucket once. */
            bool seen = false;
            for (int e = 0; e < c && !seen; e++) seen = point_cell(&g, m->vertices[i], e % 3 - 1, e / 3 % 3 - 1, e / 9 - 1) == cell;
            for (uint32_t q = g.start[cell]; !seen && q < g.start[cell + 1] && s == SPN_OK; q++) {
                uint32_t j = g.items[q];
                if (j <= i) continue;
                spn_vec3 dd = spn_v3_sub(m->vertices[j], m->vertices[i]);
                if (spn_v3_dot(dd, dd) >= r2 || !spn__pair_set_insert(set, i, j, &oom)) continue;
                st->vicinity++;
                s = add_spring(w, st, i, j, k, kd, SPN_THREAD_VICINITY);
            }
        }
    free(g.start);
    free(g.items);
    if (oom) return spn_error(SPN_ERR_NOMEM, "mesh factory: out of memory");
    return s;
}

spn_status spn_mesh_add_to_world(spn_world *w, const spn_mesh *m, const spn_mesh_spring_def *def,
                                 spn_mesh_stats *stats)
{
    spn_mesh_spring_def d = def ? *def : spn_mesh_spring_def_default();
    spn_mesh_stats st;
    memset(&st, 0, sizeof st);
    spn_status s = check_def(&d);
    if (s == SPN_OK) s = spn__mesh_check(m, "mesh");
    if (s == SPN_OK && d.fixed_group && spn_mesh_group(m, d.fixed_group) == UINT32_MAX)
        s = spn_error(SPN_ERR_INVALID, "mesh factory: no group named '%s'", d.fixed_group);
    if (s != SPN_OK) return s;
    spn_pair_set set;
    if (!spn__pair_set_init(&set, 4 * (size_t)m->triangle_count))
        return spn_error(SPN_ERR_NOMEM, "mesh factory: out of memory");
    s = add_particles(w, m, &d, &st);
    if (s == SPN_OK) s = add_edges_and_bends(w, m, &d, &set, &st);
    if (s == SPN_OK && d.vicinity > 0) s = add_vicinity(w, m, &d, &set, &st);
    spn__pair_set_free(&set);
    if (stats) *stats = st;
    return s;
}
