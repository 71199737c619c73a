/* PLY reader (ascii, binary_little_endian, binary_big_endian): the `vertex`
 * element's x, y, z and the `face` element's vertex_indices (or vertex_index)
 * list; other elements and properties are skipped. Faces must be triangles.
 * ASCII complaints name the line; binary ones the element and its index. */
#include "mesh_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

enum { T_I8, T_U8, T_I16, T_U16, T_I32, T_U32, T_F32, T_F64, T_BAD };
static const char *const type_names[][2] = {{"char", "int8"},     {"uchar", "uint8"},  {"short", "int16"},
                                            {"ushort", "uint16"}, {"int", "int32"},    {"uint", "uint32"},
                                            {"float", "float32"}, {"double", "float64"}};
static const int type_size[] = {1, 1, 2, 2, 4, 4, 4, 8};

#define PLY_MAX_PROPS 32

typedef struct ply_prop {
    int type, count_type; /* count_type != T_BAD: a list */
    char name[48];
} ply_prop;

typedef struct ply_elem {
    char name[48];
    uint32_t count;
    int nprops;
    ply_prop props[PLY_MAX_PROPS];
} ply_elem;

typedef struct ply_reader {
    const char *name;
    const char *p, *end;
    int line;
    int format; /* 0 ascii, 1 little endian, 2 big endian */
    int nelems;
    ply_elem elems[8];
} ply_reader;

static int parse_type(const char *s)
{
    for (int t = 0; t < T_BAD; t++)
        if (strcmp(s, type_names[t][0]) == 0 || strcmp(s, type_names[t][1]) == 0) return t;
    return T_BAD;
}

/* Copy the next header line into buf; false at the end of the data. */
static bool header_line(ply_reader *r, char *buf, size_t size)
{
    if (r->p >= r->end) return false;
    const char *eol = memchr(r->p, '\n', (size_t)(r->end - r->p));
    if (!eol) eol = r->end;
    size_t n = (size_t)(eol - r->p) < size - 1 ? (size_t)(eol - r->p) : size - 1;
    memcpy(buf, r->p, n);
    buf[n] = '\0';
    if (n && buf[n - 1] == '\r') buf[n - 1] = '\0';
    r->p = eol < r->end ? eol + 1 : eol;
    r->line++;
    return true;
}

static spn_status header_property(ply_reader *r, char *rest)
{
    if (r->nelems == 0) return spn_error(SPN_ERR_FORMAT, "%s:%d: property before any element", r->name, r->line);
    ply_elem *e = &r->elems[r->nelems - 1];
    if (e->nprops == PLY_MAX_PROPS) return spn_error(SPN_ERR_FORMAT, "%s:%d: too many properties", r->name, r->line);
    ply_prop *pr = &e->props[e->nprops];
    char t1[32] = "", t2[32] = "", t3[48] = "", t4[48] = "";
    int n = sscanf(rest, "%31s %31s %47s %47s", t1, t2, t3, t4);
    if (n >= 1 && strcmp(t1, "list") == 0) {
        if (n != 4) return spn_error(SPN_ERR_FORMAT, "%s:%d: malformed list property", r->name, r->line);
        pr->count_type = parse_type(t2);
        pr->type = parse_type(t3);
        memcpy(pr->name, t4, sizeof pr->name);
        if (pr->count_type == T_BAD || pr->count_type >= T_F32)
            return spn_error(SPN_ERR_FORMAT, "%s:%d: list count type '%s' is not an integer type", r->name, r->line,
                             t2);
    } else {
        if (n != 2) return spn_error(SPN_ERR_FORMAT, "%s:%d: malformed property line", r->name, r->line);
        pr->count_type = T_BAD;
        pr->type = parse_type(t1);
        memcpy(pr->name, t2, sizeof t2);
    }
    if (pr->type == T_BAD) return spn_error(SPN_ERR_FORMAT, "%s:%d: unknown property type", r->name, r->line);
    e->nprops++;
    return SPN_OK;
}

static spn_status read_header(ply_reader *r)
{
    char buf[256];
    if (!header_line(r, buf, sizeof buf) || strcmp(buf, "ply") != 0)
        return spn_error(SPN_ERR_FORMAT, "%s:1: not a PLY file (first line must be 'ply')", r->name);
    bool have_format = false;
    while (header_line(r, buf, sizeof buf)) {
        char key[32] = "";
        if (sscanf(buf, "%31s", key) != 1 || strcmp(key, "comment") == 0 || strcmp(key, "obj_info") == 0) continue;
        if (strcmp(key, "end_header") == 0) {
            if (!have_format) return spn_error(SPN_ERR_FORMAT, "%s:%d: no format line", r->name, r->line);
            return SPN_OK;
        }
        if (strcmp(key, "format") == 0) {
            char f[40] = "";
            sscanf(buf, "%*s %39s", f);
            r->format = strcmp(f, "ascii") == 0 ? 0 : strcmp(f, "binary_little_endian") == 0 ? 1
                      : strcmp(f, "binary_big_endian") == 0 ? 2 : -1;
            if (r->format < 0) return spn_error(SPN_ERR_FORMAT, "%s:%d: unknown format '%s'", r->name, r->line, f);
            have_format = true;
        } else if (strcmp(key, "element") == 0) {
            if (r->nelems == 8) return spn_error(SPN_ERR_FORMAT, "%s:%d: too many elements", r->name, r->line);
            ply_elem *e = &r->elems[r->nelems];
            memset(e, 0, sizeof *e);
            long count = -1;
            if (sscanf(buf, "%*s %47s %ld", e->name, &count) != 2 || count < 0 || count > (long)UINT32_MAX / 4)
                return spn_error(SPN_ERR_FORMAT, "%s:%d: malformed element line", r->name, r->line);
            e->count = (uint32_t)count;
            r->nelems++;
        } else if (strcmp(key, "property") == 0) {
            spn_status st = header_property(r, buf + 8);
            if (st != SPN_OK) return st;
        } else {
            return spn_error(SPN_ERR_FORMAT, "%s:%d: unknown header keyword '%s'", r->name, r->line, key);
        }
    }
    return spn_error(SPN_ERR_FORMAT, "%s: header has no end_header", r->name);
}

/* One value: ASCII words are taken from the current line [*lp, lend). */
typedef struct value_src {
    ply_reader *r;
    const char *lp, *lend;
} value_src;

static bool read_value(value_src *s, int type, double *out)
{
    ply_reader *r = s->r;
    if (r->format == 0) {
        while (s->lp < s->lend && (*s->lp == ' ' || *s->lp == '\t' || *s->lp == '\r')) s->lp++;
        if (s->lp >= s->lend) return false;
        char word[64];
        const char *e = s->lp;
        while (e < s->lend && *e != ' ' && *e != '\t' && *e != '\r') e++;
        size_t n = (size_t)(e - s->lp) < sizeof word - 1 ? (size_t)(e - s->lp) : sizeof word - 1;
        memcpy(word, s->lp, n);
        word[n] = '\0';
        s->lp = e;
        char *stop;
        *out = strtod(word, &stop);
        return *stop == '\0';
    }
    int size = type_size[type];
    if (r->end - r->p < size) return false;
    unsigned char b[8];
    for (int i = 0; i < size; i++) b[i] = (unsigned char)r->p[r->format == 1 ? i : size - 1 - i];
    r->p += size;
    uint64_t u = 0;
    for (int i = size - 1; i >= 0; i--) u = u << 8 | b[i];
    switch (type) {
    case T_I8: *out = (int8_t)u; break;
    case T_U8: *out = (uint8_t)u; break;
    case T_I16: *out = (int16_t)u; break;
    case T_U16: *out = (uint16_t)u; break;
    case T_I32: *out = (int32_t)u; break;
    case T_U32: *out = (uint32_t)u; break;
    case T_F32: { uint32_t w = (uint32_t)u; float f; memcpy(&f, &w, 4); *out = f; break; }
    default: { double d; memcpy(&d, &u, 8); *out = d; break; }
    }
    return true;
}

static void next_body_line(value_src *s)
{
    ply_reader *r = s->r;
    if (r->format != 0) return;
    const char *eol = memchr(r->p, '\n', (size_t)(r->end - r->p));
    if (!eol) eol = r->end;
    s->lp = r->p;
    s->lend = eol;
    r->p = eol < r->end ? eol + 1 : eol;
    r->line++;
}

/* Where the complaint points: the line (ascii) or the element index (binary). */
static spn_status bad_item(ply_reader *r, const ply_elem *e, uint32_t i, const char *what)
{
    if (r->format == 0) return spn_error(SPN_ERR_FORMAT, "%s:%d: %s %u: %s", r->name, r->line, e->name, i, what);
    return spn_error(SPN_ERR_FORMAT, "%s: %s %u: %s", r->name, e->name, i, what);
}

static spn_status read_elem(ply_reader *r, const ply_elem *e, spn_mesh *m)
{
    bool is_vertex = strcmp(e->name, "vertex") == 0, is_face = strcmp(e->name, "face") == 0;
    for (uint32_t i = 0; i < e->count; i++) {
        value_src s = {r, NULL, NULL};
        next_body_line(&s);
        if (r->format == 0 && s.lp >= r->end) return bad_item(r, e, i, "missing (file ends early)");
        double xyz[3] = {NAN, NAN, NAN};
        for (int k = 0; k < e->nprops; k++) {
            const ply_prop *pr = &e->props[k];
            double v = NAN, count = 1;
            if (pr->count_type != T_BAD && !read_value(&s, pr->count_type, &count))
                return bad_item(r, e, i, "missing or malformed values");
            bool indices = is_face && (strcmp(pr->name, "vertex_indices") == 0 || strcmp(pr->name, "vertex_index") == 0);
            if (indices && count != 3) return bad_item(r, e, i, "face is not a triangle (only triangles are supported)");
            if (!(count >= 0 && count < 1e6)) return bad_item(r, e, i, "bad list count");
            for (int c = 0; c < (int)count; c++) {
                if (!read_value(&s, pr->type, &v)) return bad_item(r, e, i, "missing or malformed values");
                if (indices) {
                    if (!(v >= 0 && v < m->vertex_count && v == floor(v))) return bad_item(r, e, i, "vertex index out of range");
                    m->triangles[3 * i + c] = (uint32_t)v;
                }
            }
            if (is_vertex && pr->name[1] == '\0' && pr->name[0] >= 'x' && pr->name[0] <= 'z') xyz[pr->name[0] - 'x'] = v;
        }
        if (r->format == 0 && s.lp < s.lend && strspn(s.lp, " \t\r") < (size_t)(s.lend - s.lp))
            return bad_item(r, e, i, "extra values on the line");
        if (is_vertex) {
            m->vertices[i] = spn_v3(xyz[0], xyz[1], xyz[2]);
            if (!spn_v3_finite(m->vertices[i])) return bad_item(r, e, i, "coordinate missing or not finite");
        }
    }
    return SPN_OK;
}

static spn_status check_elements(ply_reader *r, spn_mesh *m)
{
    bool vertex = false, face = false;
    for (int k = 0; k < r->nelems; k++) {
        if (strcmp(r->elems[k].name, "vertex") == 0) {
            vertex = true;
            m->vertex_count = r->elems[k].count;
        } else if (strcmp(r->elems[k].name, "face") == 0) {
            if (!vertex) return spn_error(SPN_ERR_FORMAT, "%s: face element before vertex element", r->name);
            face = true;
            m->triangle_count = r->elems[k].count;
        }
    }
    if (!vertex || !face) return spn_error(SPN_ERR_FORMAT, "%s: needs a vertex and a face element", r->name);
    m->vertices = calloc(m->vertex_count ? m->vertex_count : 1, sizeof *m->vertices);
    m->triangles = calloc(3 * (size_t)(m->triangle_count ? m->triangle_count : 1), sizeof *m->triangles);
    if (!m->vertices || !m->triangles) return spn_error(SPN_ERR_NOMEM, "%s: out of memory", r->name);
    return SPN_OK;
}

spn_status spn_mesh_parse_ply(const char *data, size_t size, const char *name, spn_mesh *out)
{
    memset(out, 0, sizeof *out);
    ply_reader *r = calloc(1, sizeof *r);
    if (!r) return spn_error(SPN_ERR_NOMEM, "out of memory");
    r->name = name;
    r->p = data;
    r->end = data + size;
    spn_status st = read_header(r);
    if (st == SPN_OK) st = check_elements(r, out);
    for (int k = 0; st == SPN_OK && k < r->nelems; k++) st = read_elem(r, &r->elems[k], out);
    if (st == SPN_OK) st = spn__mesh_check(out, name);
    free(r);
    if (st != SPN_OK) spn_mesh_free(out);
    return st;
}
