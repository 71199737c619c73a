/* Wavefront OBJ reader: `v` and `f` lines (plus `g`/`o` for groups); normals,
 * texture coordinates, materials and smoothing groups are skipped. Faces must
 * be triangles: polygons are refused rather than split, so a model is never
 * silently changed. Every complaint names the file and the line. Indices may
 * be negative (relative to the vertices read so far), as the format allows. */
#include "mesh_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct obj_reader {
    const char *name;
    int line;
    spn_mesh *m;
    uint32_t cap_v, cap_t, cap_g;
    uint32_t group;
} obj_reader;

/* The next whitespace-separated word in [*p, end) as a NUL-terminated copy. */
static bool next_word(const char **p, const char *end, char *word, size_t size)
{
    const char *s = *p;
    while (s < end && (*s == ' ' || *s == '\t' || *s == '\r')) s++;
    const char *e = s;
    while (e < end && *e != ' ' && *e != '\t' && *e != '\r') e++;
    *p = e;
    if (e == s) return false;
    size_t n = (size_t)(e - s) < size - 1 ? (size_t)(e - s) : size - 1;
    memcpy(word, s, n);
    word[n] = '\0';
    return true;
}

static spn_status read_vertex(obj_reader *r, const char *p, const char *end)
{
    char word[128];
    double c[3];
    for (int k = 0; k < 3; k++) {
        if (!next_word(&p, end, word, sizeof word))
            return spn_error(SPN_ERR_FORMAT, "%s:%d: vertex needs 3 coordinates, found %d", r->name, r->line, k);
        char *stop;
        c[k] = strtod(word, &stop);
        if (*stop != '\0')
            return spn_error(SPN_ERR_FORMAT, "%s:%d: vertex coordinate '%s' is not a number", r->name, r->line, word);
        if (!isfinite(c[k]))
            return spn_error(SPN_ERR_FORMAT, "%s:%d: vertex coordinate '%s' is not finite", r->name, r->line, word);
    }
    spn_mesh *m = r->m;
    if (!spn__grow((void **)&m->vertices, &r->cap_v, m->vertex_count + 1, sizeof *m->vertices))
        return spn_error(SPN_ERR_NOMEM, "%s: out of memory", r->name);
    m->vertices[m->vertex_count++] = spn_v3(c[0], c[1], c[2]);
    return SPN_OK;
}

/* "i", "i/t", "i//n" or "i/t/n": the vertex index, made 0-based. */
static spn_status face_index(obj_reader *r, const char *word, uint32_t *out)
{
    char *stop;
    long i = strtol(word, &stop, 10);
    if (stop == word || (*stop != '\0' && *stop != '/'))
        return spn_error(SPN_ERR_FORMAT, "%s:%d: face vertex '%s' is not an index", r->name, r->line, word);
    long n = (long)r->m->vertex_count;
    long idx = i > 0 ? i - 1 : n + i;
    if (i == 0 || idx < 0 || idx >= n)
        return spn_error(SPN_ERR_FORMAT, "%s:%d: face vertex index %ld out of range (%ld vertices so far)", r->name,
                         r->line, i, n);
    *out = (uint32_t)idx;
    return SPN_OK;
}

static spn_status read_face(obj_reader *r, const char *p, const char *end)
{
    char word[128];
    uint32_t v[3];
    int n = 0;
    while (next_word(&p, end, word, sizeof word)) {
        if (n == 3)
            return spn_error(SPN_ERR_FORMAT, "%s:%d: face has more than 3 vertices; only triangles are supported "
                             "(triangulate the model first)", r->name, r->line);
        spn_status st = face_index(r, word, &v[n]);
        if (st != SPN_OK) return st;
        n++;
    }
    if (n < 3) return spn_error(SPN_ERR_FORMAT, "%s:%d: face has %d vertices, needs 3", r->name, r->line, n);
    if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2])
        return spn_error(SPN_ERR_FORMAT, "%s:%d: face repeats a vertex", r->name, r->line);
    spn_mesh *m = r->m;
    if (!spn__grow((void **)&m->triangles, &r->cap_t, 3 * (m->triangle_count + 1), sizeof *m->triangles) ||
        !spn__grow((void **)&m->triangle_group, &r->cap_g, m->triangle_count + 1, sizeof *m->triangle_group))
        return spn_error(SPN_ERR_NOMEM, "%s: out of memory", r->name);
    memcpy(m->triangles + 3 * m->triangle_count, v, sizeof v);
    m->triangle_group[m->triangle_count++] = r->group;
    return SPN_OK;
}

static spn_status read_group(obj_reader *r, const char *p, const char *end)
{
    while (p < end && (*p == ' ' || *p == '\t')) p++;
    while (end > p && (end[-1] == ' ' || end[-1] == '\t' || end[-1] == '\r')) end--;
    return spn__mesh_add_group(r->m, p, (size_t)(end - p), &r->group);
}

static spn_status read_line(obj_reader *r, const char *p, const char *end)
{
    char key[16];
    if (!next_word(&p, end, key, sizeof key) || key[0] == '#') return SPN_OK;
    if (strcmp(key, "v") == 0) return read_vertex(r, p, end);
    if (strcmp(key, "f") == 0) return read_face(r, p, end);
    if (strcmp(key, "g") == 0 || strcmp(key, "o") == 0) return read_group(r, p, end);
    return SPN_OK; /* vn, vt, usemtl, mtllib, s, l ...: not needed for springs */
}

spn_status spn_mesh_parse_obj(const char *text, size_t size, const char *name, spn_mesh *out)
{
    memset(out, 0, sizeof *out);
    obj_reader r = {name, 0, out, 0, 0, 0, 0};
    spn_status st = spn__mesh_add_group(out, "", 0, &r.group);
    const char *p = text, *end = text + size;
    while (st == SPN_OK && p < end) {
        const char *eol = memchr(p, '\n', (size_t)(end - p));
        if (!eol) eol = end;
        r.line++;
        st = read_line(&r, p, eol);
        p = eol + 1;
    }
    if (st == SPN_OK) st = spn__mesh_check(out, name);
    if (st != SPN_OK) spn_mesh_free(out);
    return st;
}
