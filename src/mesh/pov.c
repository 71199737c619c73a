/* The film maker's scene: a POV-Ray 3.7 file whose mesh2 objects carry the
 * declarations of Juhasz & Bercovici's POV film maker:
 *   #local spring_system_fixed = true;            (an obstacle)
 *   #local spring_system_ks = 600; ... _kb _ds _db _mass _vicinity
 *   #local spring_system_fixed = false;           (simulated)
 * plus our extension `#local spring_system_fixed_vertices = array[n] {i, ...};`
 * (pinned vertices, for the documentation's 2- and 4-point movies).
 * An unmarked mesh2 is an obstacle. The rest of the scene is never
 * interpreted: the writer copies the text and replaces only the coordinate
 * numbers of vertex_vectors, so camera, lights and textures stay byte for byte.
 * Refused, with the line: #include, spring_system_* outside a mesh2,
 * transformations inside a mesh2 (vertices must be world coordinates),
 * unbalanced braces, non-numeric or non-finite vectors, non-triangle faces,
 * face indices out of range, counts that disagree with the vectors given. */
#include "pov_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct pov_object {
    int line;
    spn_mesh mesh;
    size_t *ranges; /* 6 per vertex: byte start, end of x, y, z */
    bool marked, fixed, have[6];
    double value[6]; /* ks kb ds db mass vicinity */
    bool *fixed_vertices;
    uint32_t *pins, npins;
    int pins_line;
} pov_object;

struct spn_pov_scene {
    char *text;
    size_t size;
    char *name;
    pov_object *obj;
    uint32_t nobj;
};

static const char *const mark_names[6] = {"ks", "kb", "ds", "db", "mass", "vicinity"};

typedef struct parser {
    pov_lexer lx;
    const char *name;
    size_t t; /* current token */
} parser;

static const pov_token *tok(const parser *p) { return &p->lx.tok[p->t]; }
static bool is(const parser *p, const char *w) { return spn__pov_is(&p->lx, p->t, w); }

static spn_status fail_at(const parser *p, const char *what)
{
    const pov_token *k = tok(p);
    if (k->kind == POV_END) return spn_error(SPN_ERR_FORMAT, "%s:%d: %s, found the end of the file", p->name, k->line, what);
    int len = (int)(k->end - k->start) > 40 ? 40 : (int)(k->end - k->start);
    return spn_error(SPN_ERR_FORMAT, "%s:%d: %s, found '%.*s'", p->name, k->line, what, len, p->lx.text + k->start);
}

static spn_status expect(parser *p, const char *w, const char *what)
{
    if (!is(p, w)) return fail_at(p, what);
    p->t++;
    return SPN_OK;
}

/* A number with an optional sign; its byte range in *start, *end. */
static spn_status number(parser *p, double *out, size_t *start, size_t *end)
{
    size_t s = tok(p)->start;
    bool neg = false;
    if (is(p, "-") || is(p, "+")) {
        neg = is(p, "-");
        p->t++;
    }
    if (tok(p)->kind != POV_NUMBER) return fail_at(p, "expected a number");
    double v = strtod(p->lx.text + tok(p)->start, NULL);
    if (!isfinite(v)) return fail_at(p, "number is not finite");
    *out = neg ? -v : v;
    if (start) *start = s;
    if (end) *end = tok(p)->end;
    p->t++;
    return SPN_OK;
}

static spn_status count_header(parser *p, const char *block, uint32_t *count)
{
    double n = 0;
    spn_status st = expect(p, "{", "expected '{'");
    if (st == SPN_OK) st = number(p, &n, NULL, NULL);
    if (st != SPN_OK) return st;
    if (!(n >= 0 && n == floor(n) && n < 1e8))
        return spn_error(SPN_ERR_FORMAT, "%s:%d: %s count must be a whole number", p->name, tok(p)->line, block);
    *count = (uint32_t)n;
    return st;
}

static spn_status vertex_vectors(parser *p, pov_object *o)
{
    int line = tok(p)->line;
    p->t++;
    uint32_t n;
    spn_status st = count_header(p, "vertex_vectors", &n);
    if (st != SPN_OK) return st;
    o->mesh.vertices = malloc((n ? n : 1) * sizeof *o->mesh.vertices);
    o->ranges = malloc(6 * (size_t)(n ? n : 1) * sizeof *o->ranges);
    if (!o->mesh.vertices || !o->ranges) return spn_error(SPN_ERR_NOMEM, "out of memory");
    for (uint32_t i = 0; i < n; i++) {
        double c[3];
        st = expect(p, ",", "expected ',' between vectors");
        if (st == SPN_OK) st = expect(p, "<", "expected '<' to start a vertex vector");
        for (int k = 0; k < 3 && st == SPN_OK; k++) {
            if (k) st = expect(p, ",", "expected ',' between coordinates");
            if (st == SPN_OK) st = number(p, &c[k], &o->ranges[6 * i + 2 * k], &o->ranges[6 * i + 2 * k + 1]);
        }
        if (st == SPN_OK) st = expect(p, ">", "expected '>' after 3 coordinates");
        if (st != SPN_OK) return st;
        o->mesh.vertices[i] = spn_v3(c[0], c[1], c[2]);
        o->mesh.vertex_count = i + 1;
    }
    if (is(p, ",")) p->t++;
    if (!is(p, "}"))
        return spn_error(SPN_ERR_FORMAT, "%s:%d: vertex_vectors (line %d) declares %u vectors but has more, or misses '}'",
                         p->name, tok(p)->line, line, n);
    p->t++;
    return SPN_OK;
}

static spn_status face(parser *p, pov_object *o, uint32_t *v)
{
    spn_status st = expect(p, "<", "expected '<' to start a face");
    for (int k = 0; k < 3 && st == SPN_OK; k++) {
        double x;
        int line = tok(p)->line;
        if (k) st = expect(p, ",", "expected ',' between face indices");
        if (st == SPN_OK) st = number(p, &x, NULL, NULL);
        if (st == SPN_OK && !(x >= 0 && x == floor(x) && x < o->mesh.vertex_count))
            return spn_error(SPN_ERR_FORMAT, "%s:%d: face index %g out of range (%u vertices)", p->name, line, x,
                             o->mesh.vertex_count);
        v[k] = (uint32_t)x;
    }
    if (st == SPN_OK && is(p, ","))
        return spn_error(SPN_ERR_FORMAT, "%s:%d: face has more than 3 indices; mesh2 faces are triangles", p->name,
                         tok(p)->line);
    if (st == SPN_OK) st = expect(p, ">", "expected '>' after 3 face indices");
    if (st == SPN_OK && (v[0] == v[1] || v[1] == v[2] || v[0] == v[2]))
        return spn_error(SPN_ERR_FORMAT, "%s:%d: face repeats a vertex", p->name, tok(p)->line);
    /* optional texture indices: one or three numbers */
    while (st == SPN_OK && is(p, ",") && p->lx.tok[p->t + 1].kind == POV_NUMBER) p->t += 2;
    return st;
}

static spn_status face_indices(parser *p, pov_object *o)
{
    int line = tok(p)->line;
    if (!o->mesh.vertices)
        return spn_error(SPN_ERR_FORMAT, "%s:%d: face_indices before vertex_vectors", p->name, line);
    p->t++;
    uint32_t n;
    spn_status st = count_header(p, "face_indices", &n);
    if (st != SPN_OK) return st;
    o->mesh.triangles = malloc(3 * (size_t)(n ? n : 1) * sizeof *o->mesh.triangles);
    if (!o->mesh.triangles) return spn_error(SPN_ERR_NOMEM, "out of memory");
    for (uint32_t i = 0; i < n && st == SPN_OK; i++) {
        st = expect(p, ",", "expected ',' between faces");
        if (st == SPN_OK) st = face(p, o, o->mesh.triangles + 3 * i);
        o->mesh.triangle_count = i + 1;
    }
    if (st != SPN_OK) return st;
    if (is(p, ",")) p->t++;
    if (!is(p, "}"))
        return spn_error(SPN_ERR_FORMAT, "%s:%d: face_indices (line %d) declares %u faces but has more, or misses '}'",
                         p->name, tok(p)->line, line, n);
    p->t++;
    return SPN_OK;
}

static spn_status pins(parser *p, pov_object *o)
{
    double n, x;
    o->pins_line = tok(p)->line;
    spn_status st = expect(p, "array", "spring_system_fixed_vertices: expected 'array[n] {i, ...}'");
    if (st == SPN_OK) st = expect(p, "[", "expected '['");
    if (st == SPN_OK) st = number(p, &n, NULL, NULL);
    if (st == SPN_OK) st = expect(p, "]", "expected ']'");
    if (st == SPN_OK) st = expect(p, "{", "expected '{'");
    if (st != SPN_OK) return st;
    if (!(n >= 1 && n < 1e7 && n == floor(n))) return fail_at(p, "array size must be a positive whole number");
    o->pins = malloc((size_t)n * sizeof *o->pins);
    if (!o->pins) return spn_error(SPN_ERR_NOMEM, "out of memory");
    for (uint32_t i = 0; i < (uint32_t)n && st == SPN_OK; i++) {
        if (i) st = expect(p, ",", "expected ','");
        if (st == SPN_OK) st = number(p, &x, NULL, NULL);
        if (st == SPN_OK && !(x >= 0 && x == floor(x) && x < 4e9)) return fail_at(p, "expected a vertex index");
        o->pins[o->npins++] = (uint32_t)x;
    }
    return st == SPN_OK ? expect(p, "}", "expected '}' to close the array") : st;
}

/* #local spring_system_NAME = VALUE ; (p at the directive) */
static spn_status declaration(parser *p, pov_object *o)
{
    p->t++;
    size_t nt = p->t;
    const char *w = p->lx.text + tok(p)->start + 14; /* after "spring_system_" */
    size_t len = tok(p)->end - tok(p)->start - 14;
    p->t++;
    spn_status st = expect(p, "=", "expected '='");
    if (st != SPN_OK) return st;
    o->marked = true;
    if (len == 5 && memcmp(w, "fixed", 5) == 0) {
        bool t = is(p, "true") || is(p, "on") || is(p, "yes") || is(p, "1");
        if (!t && !is(p, "false") && !is(p, "off") && !is(p, "no") && !is(p, "0"))
            return fail_at(p, "spring_system_fixed must be true or false");
        o->fixed = t;
        p->t++;
    } else if (len == 14 && memcmp(w, "fixed_vertices", 14) == 0) {
        st = pins(p, o);
    } else {
        int k = 0;
        while (k < 6 && !(strlen(mark_names[k]) == len && memcmp(mark_names[k], w, len) == 0)) k++;
        if (k == 6) {
            p->t = nt;
            return fail_at(p, "unknown declaration (spring_system_ fixed, ks, kb, ds, db, mass, vicinity, fixed_vertices)");
        }
        st = number(p, &o->value[k], NULL, NULL);
        if (st == SPN_OK && o->value[k] < 0) return fail_at(p, "spring_system values must not be negative");
        o->have[k] = true;
    }
    if (st == SPN_OK && is(p, ";")) p->t++;
    return st;
}

static bool is_spring_word(const parser *p, size_t t)
{
    const pov_token *k = &p->lx.tok[t];
    return k->kind == POV_WORD && k->end - k->start > 14 && memcmp(p->lx.text + k->start, "spring_system_", 14) == 0;
}

static spn_status mesh2_item(parser *p, pov_object *o, int depth)
{
    static const char *const transforms[] = {"translate", "rotate", "scale", "matrix", "transform"};
    if (depth == 1 && is(p, "vertex_vectors")) return vertex_vectors(p, o);
    if (depth == 1 && is(p, "face_indices")) return face_indices(p, o);
    if ((is(p, "#local") || is(p, "#declare")) && is_spring_word(p, p->t + 1)) return declaration(p, o);
    if (is_spring_word(p, p->t)) return fail_at(p, "spring_system_ names must be set with #local NAME = VALUE;");
    for (int k = 0; depth == 1 && k < 5; k++)
        if (is(p, transforms[k]))
            return fail_at(p, "transformations inside a simulated scene's mesh2 are not supported "
                              "(give the vertices in world coordinates)");
    if (is(p, "#include")) return fail_at(p, "#include is not supported (put the whole scene in one file)");
    p->t++;
    return SPN_OK;
}

static spn_status finish_object(parser *p, pov_object *o)
{
    if (!o->mesh.vertices || !o->mesh.triangles)
        return spn_error(SPN_ERR_FORMAT, "%s:%d: mesh2 needs vertex_vectors and face_indices", p->name, o->line);
    if (!o->marked) o->fixed = true;
    for (int k = 0; !o->fixed && k < 6; k++)
        if (!o->have[k])
            return spn_error(SPN_ERR_FORMAT, "%s:%d: simulated mesh2 misses spring_system_%s (needs ks, kb, ds, db, mass, vicinity)",
                             p->name, o->line, mark_names[k]);
    if (!o->fixed && !(o->value[4] > 0))
        return spn_error(SPN_ERR_FORMAT, "%s:%d: spring_system_mass must be positive", p->name, o->line);
    if (o->npins) {
        o->fixed_vertices = calloc(o->mesh.vertex_count, sizeof *o->fixed_vertices);
        if (!o->fixed_vertices) return spn_error(SPN_ERR_NOMEM, "out of memory");
        for (uint32_t i = 0; i < o->npins; i++) {
            if (o->pins[i] >= o->mesh.vertex_count)
                return spn_error(SPN_ERR_FORMAT, "%s:%d: fixed vertex %u out of range (%u vertices)", p->name,
                                 o->pins_line, o->pins[i], o->mesh.vertex_count);
            o->fixed_vertices[o->pins[i]] = true;
        }
    }
    return spn__mesh_check(&o->mesh, p->name);
}

static spn_status mesh2(parser *p, spn_pov_scene *sc)
{
    pov_object *grown = realloc(sc->obj, (sc->nobj + 1) * sizeof *grown);
    if (!grown) return spn_error(SPN_ERR_NOMEM, "out of memory");
    sc->obj = grown;
    pov_object *o = &sc->obj[sc->nobj++];
    memset(o, 0, sizeof *o);
    o->line = tok(p)->line;
    p->t++;
    spn_status st = expect(p, "{", "expected '{' after mesh2");
    int depth = 1;
    while (st == SPN_OK && depth > 0) {
        if (tok(p)->kind == POV_END)
            return spn_error(SPN_ERR_FORMAT, "%s:%d: mesh2 is never closed (missing '}')", p->name, o->line);
        if (is(p, "{")) depth++;
        if (is(p, "}")) depth--;
        if (depth == 0) p->t++;
        else if (is(p, "{") || is(p, "}")) p->t++;
        else st = mesh2_item(p, o, depth);
    }
    return st == SPN_OK ? finish_object(p, o) : st;
}

/* The whole file: mesh2 objects, and braces balanced everywhere. */
static spn_status scene(parser *p, spn_pov_scene *sc)
{
    int *open = NULL, nopen = 0, cap = 0;
    spn_status st = SPN_OK;
    while (st == SPN_OK && tok(p)->kind != POV_END) {
        if (is(p, "#include")) st = fail_at(p, "#include is not supported (put the whole scene in one file)");
        else if (is(p, "mesh2")) st = mesh2(p, sc);
        else if (is_spring_word(p, p->t))
            st = fail_at(p, "spring_system_ declaration outside a mesh2: only mesh2 objects can be simulated");
        else if (is(p, "{")) {
            if (nopen == cap) {
                int *g = realloc(open, (size_t)(cap = cap ? 2 * cap : 16) * sizeof *g);
                if (!g) st = spn_error(SPN_ERR_NOMEM, "out of memory");
                else open = g;
            }
            if (st == SPN_OK) open[nopen++] = tok(p)->line;
            p->t++;
        } else if (is(p, "}")) {
            if (nopen == 0) st = fail_at(p, "'}' without a matching '{'");
            nopen--;
            p->t++;
        } else
            p->t++;
    }
    if (st == SPN_OK && nopen > 0)
        st = spn_error(SPN_ERR_FORMAT, "%s:%d: '{' is never closed (missing '}')", p->name, open[nopen - 1]);
    free(open);
    return st;
}

void spn_pov_scene_destroy(spn_pov_scene *sc)
{
    if (!sc) return;
    for (uint32_t i = 0; i < sc->nobj; i++) {
        spn_mesh_free(&sc->obj[i].mesh);
        free(sc->obj[i].ranges);
        free(sc->obj[i].fixed_vertices);
        free(sc->obj[i].pins);
    }
    free(sc->obj);
    free(sc->text);
    free(sc->name);
    free(sc);
}

spn_status spn_pov_scene_parse(const char *text, size_t size, const char *name, spn_pov_scene **out)
{
    *out = NULL;
    spn_pov_scene *sc = calloc(1, sizeof *sc);
    if (!sc) return spn_error(SPN_ERR_NOMEM, "out of memory");
    sc->text = malloc(size + 1);
    sc->name = malloc(strlen(name) + 1);
    if (!sc->text || !sc->name) {
        spn_pov_scene_destroy(sc);
        return spn_error(SPN_ERR_NOMEM, "out of memory");
    }
    memcpy(sc->text, text, size);
    sc->text[size] = '\0';
    sc->size = size;
    strcpy(sc->name, name);
    parser p = {.name = sc->name};
    spn_status st = spn__pov_lex(&p.lx, sc->text, size, sc->name);
    if (st == SPN_OK) st = scene(&p, sc);
    if (st == SPN_OK && sc->nobj == 0) st = spn_error(SPN_ERR_FORMAT, "%s: no mesh2 objects", name);
    spn__pov_lexer_free(&p.lx);
    if (st != SPN_OK) {
        spn_pov_scene_destroy(sc);
        return st;
    }
    *out = sc;
    return SPN_OK;
}

spn_status spn_pov_scene_load(const char *path, spn_pov_scene **out)
{
    char *data;
    size_t size;
    *out = NULL;
    spn_status st = spn__read_file(path, &data, &size);
    if (st != SPN_OK) return st;
    st = spn_pov_scene_parse(data, size, path, out);
    free(data);
    return st;
}

uint32_t spn_pov_scene_object_count(const spn_pov_scene *sc) { return sc->nobj; }
const spn_mesh *spn_pov_scene_mesh(const spn_pov_scene *sc, uint32_t i) { return &sc->obj[i].mesh; }
int spn_pov_scene_object_line(const spn_pov_scene *sc, uint32_t i) { return sc->obj[i].line; }

spn_mesh_spring_def spn_pov_scene_spring_def(const spn_pov_scene *sc, uint32_t i)
{
    const pov_object *o = &sc->obj[i];
    spn_mesh_spring_def d = spn_mesh_spring_def_default();
    d.fixed = o->fixed;
    if (o->fixed) return d;
    d.stretch_k = o->value[0];
    d.bend_k = o->value[1];
    d.stretch_kd = o->value[2];
    d.bend_kd = o->value[3];
    d.total_mass = o->value[4];
    d.vicinity = o->value[5];
    d.fixed_vertices = o->fixed_vertices;
    return d;
}

spn_status spn_pov_scene_write(const spn_pov_scene *sc, const spn_vec3 *const *vertices, spn_sink *sink)
{
    size_t at = 0;
    spn_status st = SPN_OK;
    for (uint32_t i = 0; st == SPN_OK && i < sc->nobj; i++) {
        const pov_object *o = &sc->obj[i];
        if (!vertices || !vertices[i]) continue;
        for (uint32_t v = 0; st == SPN_OK && v < o->mesh.vertex_count; v++) {
            const double c[3] = {vertices[i][v].x, vertices[i][v].y, vertices[i][v].z};
            for (int k = 0; st == SPN_OK && k < 3; k++) {
                size_t s = o->ranges[6 * v + 2 * k], e = o->ranges[6 * v + 2 * k + 1];
                st = sink->write(sink->ctx, sc->text + at, s - at);
                if (st == SPN_OK) st = spn_sink_printf(sink, "%.9g", c[k] == 0 ? 0.0 : c[k]);
                at = e;
            }
        }
    }
    if (st == SPN_OK) st = sink->write(sink->ctx, sc->text + at, sc->size - at);
    return st;
}
