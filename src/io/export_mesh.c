/* OBJ and PLY export: the web as a mesh that Blender, Houdini and Maya import
 * directly.
 *
 * Polylines (default): the vertices are the particles in id order (so an
 * importer's vertex i is particle i) and each strand becomes one polyline
 * (OBJ `l`, PLY edges), closed strands repeating their first vertex.
 * Tubes: each strand is swept by a ring of `tube_sides` vertices at every
 * point, oriented by a rotation-minimising (parallel-transport) frame so the
 * tube does not twist, with quads between rings and a cap at each open end.
 * Dew beads become small UV spheres of kind SPN_EXPORT_DEW_KIND.
 * Elements are grouped by kind in drawing order: one OBJ object/group per
 * kind, a `kind` property on PLY edges and faces. */
#include "export_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct elem {
    size_t first;      /* into mesh.idx */
    uint32_t count;
    uint32_t kind;
    bool line;         /* polyline, else a face */
} elem;

typedef struct mesh {
    spn_vec3 *v;
    size_t nv, cv;
    uint32_t *idx;
    size_t ni, ci;
    elem *el;
    size_t ne, ce;
    bool failed;
} mesh;

static bool reserve(void **p, size_t *cap, size_t need, size_t size)
{
    if (need <= *cap) return true;
    size_t c = *cap ? *cap : 256;
    while (c < need) c *= 2;
    void *q = realloc(*p, c * size);
    if (!q) return false;
    *p = q;
    *cap = c;
    return true;
}

static uint32_t add_vertex(mesh *m, spn_vec3 p)
{
    if (!reserve((void **)&m->v, &m->cv, m->nv + 1, sizeof *m->v)) {
        m->failed = true;
        return 0;
    }
    m->v[m->nv] = p;
    return (uint32_t)m->nv++;
}

/* Start an element; push its indices with add_index. */
static void begin_elem(mesh *m, uint32_t kind, bool line)
{
    if (!reserve((void **)&m->el, &m->ce, m->ne + 1, sizeof *m->el)) {
        m->failed = true;
        return;
    }
    elem e = {m->ni, 0, kind, line};
    m->el[m->ne++] = e;
}

static void add_index(mesh *m, uint32_t i)
{
    if (m->failed || !reserve((void **)&m->idx, &m->ci, m->ni + 1, sizeof *m->idx)) {
        m->failed = true;
        return;
    }
    m->idx[m->ni++] = i;
    m->el[m->ne - 1].count++;
}

static void add_quad(mesh *m, uint32_t kind, uint32_t a, uint32_t b, uint32_t c, uint32_t d)
{
    begin_elem(m, kind, false);
    add_index(m, a);
    add_index(m, b);
    add_index(m, c);
    add_index(m, d);
}

static void polylines(mesh *m, const spn_world *w, const spn__xscene *x)
{
    uint32_t np = spn_world_particle_count(w);
    const spn_vec3 *pos = spn_world_positions(w);
    for (uint32_t i = 0; i < np; i++) add_vertex(m, pos[i]);
    for (size_t s = 0; s < x->strand_count; s++) {
        const spn__xstrand *t = &x->strands[s];
        begin_elem(m, t->kind, true);
        for (uint32_t i = 0; i < t->count; i++) add_index(m, x->particles[t->first + i]);
        if (t->closed) add_index(m, x->particles[t->first]);
    }
}

/* Any unit vector perpendicular to t. */
static spn_vec3 perpendicular(spn_vec3 t)
{
    spn_vec3 a = fabs(t.x) < 0.9 ? spn_v3(1, 0, 0) : spn_v3(0, 1, 0);
    return spn_v3_norm(spn_v3_cross(t, a));
}

static spn_vec3 tangent(const spn_vec3 *p, uint32_t n, uint32_t i, bool closed)
{
    uint32_t prev = i > 0 ? i - 1 : (closed ? n - 1 : 0), next = i + 1 < n ? i + 1 : (closed ? 0 : n - 1);
    spn_vec3 t = spn_v3_norm(spn_v3_sub(p[next], p[prev]));
    return spn_v3_len(t) > 0 ? t : spn_v3(1, 0, 0);
}

static void tube(mesh *m, const spn__xstrand *t, const spn_vec3 *p, double r, int sides)
{
    uint32_t n = t->count, base = (uint32_t)m->nv;
    spn_vec3 normal = perpendicular(tangent(p, n, 0, t->closed));
    for (uint32_t i = 0; i < n; i++) {
        spn_vec3 tg = tangent(p, n, i, t->closed);
        /* Parallel transport: project the last normal onto the new normal plane. */
        spn_vec3 nn = spn_v3_sub(normal, spn_v3_scale(tg, spn_v3_dot(normal, tg)));
        normal = spn_v3_len(nn) > 1e-9 ? spn_v3_norm(nn) : perpendicular(tg);
        spn_vec3 bi = spn_v3_cross(tg, normal);
        for (int k = 0; k < sides; k++) {
            double a = 2 * SPN_PI * k / sides;
            add_vertex(m, spn_v3_add(p[i], spn_v3_add(spn_v3_scale(normal, r * cos(a)), spn_v3_scale(bi, r * sin(a)))));
        }
    }
    uint32_t rings = t->closed ? n : n - 1;
    for (uint32_t i = 0; i < rings; i++)
        for (int k = 0; k < sides; k++) {
            uint32_t i2 = (i + 1) % n, k2 = (uint32_t)(k + 1) % (uint32_t)sides;
            add_quad(m, t->kind, base + i * sides + k, base + i * sides + k2, base + i2 * sides + k2,
                     base + i2 * sides + k);
        }
    if (t->closed) return;
    begin_elem(m, t->kind, false);
    for (int k = sides - 1; k >= 0; k--) add_index(m, base + (uint32_t)k);
    begin_elem(m, t->kind, false);
    for (int k = 0; k < sides; k++) add_index(m, base + (n - 1) * sides + (uint32_t)k);
}

/* A UV sphere: `seg` around, seg / 2 rings from pole to pole. */
static void sphere(mesh *m, spn_vec3 c, double r, int seg)
{
    int rings = seg / 2 < 2 ? 2 : seg / 2;
    uint32_t top = add_vertex(m, spn_v3(c.x, c.y + r, c.z)), first = (uint32_t)m->nv;
    for (int j = 1; j < rings; j++) {
        double th = SPN_PI * j / rings;
        for (int k = 0; k < seg; k++) {
            double ph = 2 * SPN_PI * k / seg;
            add_vertex(m, spn_v3(c.x + r * sin(th) * cos(ph), c.y + r * cos(th), c.z + r * sin(th) * sin(ph)));
        }
    }
    uint32_t bottom = add_vertex(m, spn_v3(c.x, c.y - r, c.z)), s = (uint32_t)seg;
    for (uint32_t k = 0; k < s; k++) {
        uint32_t k2 = (k + 1) % s, last = first + (uint32_t)(rings - 2) * s;
        begin_elem(m, SPN_EXPORT_DEW_KIND, false);
        add_index(m, top), add_index(m, first + k2), add_index(m, first + k);
        for (uint32_t j = 0; j + 2 < (uint32_t)rings; j++)
            add_quad(m, SPN_EXPORT_DEW_KIND, first + j * s + k, first + j * s + k2, first + (j + 1) * s + k2,
                     first + (j + 1) * s + k);
        begin_elem(m, SPN_EXPORT_DEW_KIND, false);
        add_index(m, bottom), add_index(m, last + k), add_index(m, last + k2);
    }
}

static spn_status build_mesh(const spn_world *w, const spn_export_def *def, mesh *m)
{
    memset(m, 0, sizeof *m);
    spn_status st = spn__export_check(def);
    spn__xscene x;
    if (st == SPN_OK) st = spn__xscene_collect(w, &def->render, &x);
    if (st != SPN_OK) return st;
    if (def->tube_radius > 0) {
        for (size_t s = 0; s < x.strand_count; s++)
            tube(m, &x.strands[s], x.points + x.strands[s].first, def->tube_radius, def->tube_sides);
    } else {
        polylines(m, w, &x);
    }
    for (size_t b = 0; b < x.bead_count; b++) sphere(m, x.beads[b].centre, x.beads[b].radius, def->dew_segments);
    spn__xscene_free(&x);
    if (m->failed) return spn_error(SPN_ERR_NOMEM, "export: out of memory");
    return SPN_OK;
}

static void free_mesh(mesh *m)
{
    free(m->v);
    free(m->idx);
    free(m->el);
}

static void label(uint32_t kind, char *buf, size_t n)
{
    if (kind == SPN_EXPORT_DEW_KIND) snprintf(buf, n, "dew");
    else spn__kind_label(kind, buf, n);
}

static spn_status write_obj(const spn_world *w, const mesh *m, spn_sink *sink)
{
    spn_status st = spn_sink_printf(sink,
                                    "# Spinneret web: %u particles, %u springs; units metres, y up\n"
                                    "# one object and group per thread kind\n",
                                    spn_world_particle_count(w), spn_world_spring_count(w));
    for (size_t i = 0; i < m->nv && st == SPN_OK; i++)
        st = spn_sink_printf(sink, "v %.9g %.9g %.9g\n", m->v[i].x, m->v[i].y, m->v[i].z);
    char name[48];
    for (size_t e = 0; e < m->ne && st == SPN_OK; e++) {
        const elem *el = &m->el[e];
        if (e == 0 || el->kind != m->el[e - 1].kind) {
            label(el->kind, name, sizeof name);
            st = spn_sink_printf(sink, "o %s\ng %s\n", name, name);
        }
        if (st == SPN_OK) st = sink->write(sink->ctx, el->line ? "l" : "f", 1);
        for (uint32_t k = 0; k < el->count && st == SPN_OK; k++)
            st = spn_sink_printf(sink, " %u", m->idx[el->first + k] + 1);
        if (st == SPN_OK) st = sink->write(sink->ctx, "\n", 1);
    }
    return st;
}

static size_t edge_count(const mesh *m)
{
    size_t n = 0;
    for (size_t e = 0; e < m->ne; e++)
        if (m->el[e].line && m->el[e].count > 1) n += m->el[e].count - 1;
    return n;
}

static spn_status write_ply(const mesh *m, spn_sink *sink)
{
    size_t edges = edge_count(m), faces = 0;
    for (size_t e = 0; e < m->ne; e++) faces += !m->el[e].line;
    spn_status st = spn_sink_printf(sink,
                                    "ply\nformat ascii 1.0\ncomment Spinneret web; units metres, y up\n"
                                    "comment kind: thread tag (web.h spn_thread_kind), %u: dew\n"
                                    "element vertex %zu\nproperty double x\nproperty double y\nproperty double z\n",
                                    SPN_EXPORT_DEW_KIND, m->nv);
    if (st == SPN_OK && faces)
        st = spn_sink_printf(sink, "element face %zu\nproperty list uchar uint vertex_indices\nproperty uint kind\n",
                             faces);
    if (st == SPN_OK && edges)
        st = spn_sink_printf(sink, "element edge %zu\nproperty uint vertex1\nproperty uint vertex2\nproperty uint kind\n",
                             edges);
    if (st == SPN_OK) st = spn_sink_printf(sink, "end_header\n");
    for (size_t i = 0; i < m->nv && st == SPN_OK; i++)
        st = spn_sink_printf(sink, "%.9g %.9g %.9g\n", m->v[i].x, m->v[i].y, m->v[i].z);
    for (size_t e = 0; e < m->ne && st == SPN_OK; e++) {
        const elem *el = &m->el[e];
        if (el->line) continue;
        st = spn_sink_printf(sink, "%u", el->count);
        for (uint32_t k = 0; k < el->count && st == SPN_OK; k++) st = spn_sink_printf(sink, " %u", m->idx[el->first + k]);
        if (st == SPN_OK) st = spn_sink_printf(sink, " %u\n", el->kind);
    }
    for (size_t e = 0; e < m->ne && st == SPN_OK; e++) {
        const elem *el = &m->el[e];
        for (uint32_t k = 0; el->line && k + 1 < el->count && st == SPN_OK; k++)
            st = spn_sink_printf(sink, "%u %u %u\n", m->idx[el->first + k], m->idx[el->first + k + 1], el->kind);
    }
    return st;
}

spn_status spn_export_obj(const spn_world *w, const spn_export_def *def, spn_sink *sink)
{
    mesh m;
    spn_status st = build_mesh(w, def, &m);
    if (st == SPN_OK) st = write_obj(w, &m, sink);
    free_mesh(&m);
    return st;
}

spn_status spn_export_ply(const spn_world *w, const spn_export_def *def, spn_sink *sink)
{
    mesh m;
    spn_status st = build_mesh(w, def, &m);
    if (st == SPN_OK) st = write_ply(&m, sink);
    free_mesh(&m);
    return st;
}
