/* Triangle meshes: ownership, checks, loading by file type, OBJ output, and the
 * small helpers the mesh part shares (file reading, growth, a pair set).
 * Invariant of a finished spn_mesh: every index < vertex_count, every
 * coordinate finite, no triangle repeats a vertex (spn__mesh_check). */
#include "mesh_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

void spn_mesh_free(spn_mesh *m)
{
    if (!m) return;
    free(m->vertices);
    free(m->triangles);
    free(m->triangle_group);
    for (uint32_t g = 0; g < m->group_count; g++) free(m->group_names[g]);
    free(m->group_names);
    memset(m, 0, sizeof *m);
}

static void *dup_bytes(const void *src, size_t size)
{
    if (!src || size == 0) return NULL;
    void *d = malloc(size);
    if (d) memcpy(d, src, size);
    return d;
}

spn_status spn_mesh_copy(spn_mesh *dst, const spn_mesh *src)
{
    memset(dst, 0, sizeof *dst);
    dst->vertex_count = src->vertex_count;
    dst->triangle_count = src->triangle_count;
    dst->vertices = dup_bytes(src->vertices, src->vertex_count * sizeof *src->vertices);
    dst->triangles = dup_bytes(src->triangles, 3 * (size_t)src->triangle_count * sizeof *src->triangles);
    dst->triangle_group = dup_bytes(src->triangle_group, src->triangle_count * sizeof *src->triangle_group);
    bool ok = (dst->vertices || !src->vertex_count) && (dst->triangles || !src->triangle_count) &&
              (dst->triangle_group || !src->triangle_group);
    if (ok && src->group_count) {
        dst->group_names = calloc(src->group_count, sizeof *dst->group_names);
        ok = dst->group_names != NULL;
        for (uint32_t g = 0; ok && g < src->group_count; g++) {
            dst->group_names[g] = dup_bytes(src->group_names[g], strlen(src->group_names[g]) + 1);
            dst->group_count = g + 1;
            ok = dst->group_names[g] != NULL;
        }
    }
    if (!ok) {
        spn_mesh_free(dst);
        return spn_error(SPN_ERR_NOMEM, "mesh copy: out of memory");
    }
    return SPN_OK;
}

bool spn__grow(void **arr, uint32_t *cap, uint32_t need, size_t elem)
{
    if (need <= *cap) return true;
    size_t n = *cap ? *cap : 64;
    while (n < need) n *= 2;
    if (n > UINT32_MAX) return false;
    void *p = realloc(*arr, n * elem);
    if (!p) return false;
    *arr = p;
    *cap = (uint32_t)n;
    return true;
}

spn_status spn__mesh_add_group(spn_mesh *m, const char *name, size_t len, uint32_t *id)
{
    for (uint32_t g = 0; g < m->group_count; g++)
        if (strlen(m->group_names[g]) == len && memcmp(m->group_names[g], name, len) == 0) {
            *id = g;
            return SPN_OK;
        }
    char **names = realloc(m->group_names, (m->group_count + 1) * sizeof *names);
    if (!names) return spn_error(SPN_ERR_NOMEM, "out of memory");
    m->group_names = names;
    char *s = malloc(len + 1);
    if (!s) return spn_error(SPN_ERR_NOMEM, "out of memory");
    memcpy(s, name, len);
    s[len] = '\0';
    names[m->group_count] = s;
    *id = m->group_count++;
    return SPN_OK;
}

uint32_t spn_mesh_group(const spn_mesh *m, const char *name)
{
    for (uint32_t g = 0; g < m->group_count; g++)
        if (strcmp(m->group_names[g], name) == 0) return g;
    return UINT32_MAX;
}

spn_status spn__mesh_check(const spn_mesh *m, const char *name)
{
    if (m->vertex_count == 0) return spn_error(SPN_ERR_FORMAT, "%s: no vertices", name);
    if (m->triangle_count == 0) return spn_error(SPN_ERR_FORMAT, "%s: no triangles", name);
    for (uint32_t i = 0; i < m->vertex_count; i++)
        if (!spn_v3_finite(m->vertices[i]))
            return spn_error(SPN_ERR_FORMAT, "%s: vertex %u is not finite", name, i);
    for (uint32_t t = 0; t < m->triangle_count; t++) {
        const uint32_t *v = m->triangles + 3 * t;
        for (int k = 0; k < 3; k++)
            if (v[k] >= m->vertex_count)
                return spn_error(SPN_ERR_FORMAT, "%s: triangle %u: vertex index %u out of range (%u vertices)",
                                 name, t, v[k], m->vertex_count);
        if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2])
            return spn_error(SPN_ERR_FORMAT, "%s: triangle %u repeats a vertex", name, t);
    }
    return SPN_OK;
}

void spn_mesh_bounds(const spn_mesh *m, spn_vec3 *lo, spn_vec3 *hi)
{
    spn_vec3 a = spn_v3(INFINITY, INFINITY, INFINITY), b = spn_v3(-INFINITY, -INFINITY, -INFINITY);
    for (uint32_t i = 0; i < m->vertex_count; i++) {
        spn_vec3 p = m->vertices[i];
        a = spn_v3(fmin(a.x, p.x), fmin(a.y, p.y), fmin(a.z, p.z));
        b = spn_v3(fmax(b.x, p.x), fmax(b.y, p.y), fmax(b.z, p.z));
    }
    if (!m->vertex_count) a = b = spn_v3(0, 0, 0);
    *lo = a;
    *hi = b;
}

spn_status spn_mesh_load(const char *path, spn_mesh *out)
{
    memset(out, 0, sizeof *out);
    const char *dot = strrchr(path, '.');
    const char *ext = dot && !strchr(dot, '/') ? dot + 1 : "";
    bool obj = strcasecmp(ext, "obj") == 0, ply = strcasecmp(ext, "ply") == 0;
    if (!obj && !ply) {
#if defined(SPN_HAVE_ASSIMP)
        return spn__mesh_load_assimp(path, out);
#else
        return spn_error(SPN_ERR_UNSUPPORTED, "%s: only .obj and .ply meshes can be read (built without assimp)", path);
#endif
    }
    char *data;
    size_t size;
    spn_status st = spn__read_file(path, &data, &size);
    if (st != SPN_OK) return st;
    st = obj ? spn_mesh_parse_obj(data, size, path, out) : spn_mesh_parse_ply(data, size, path, out);
    free(data);
    return st;
}

spn_status spn_mesh_write_obj(const spn_mesh *m, spn_sink *sink)
{
    spn_status st = spn_sink_printf(sink, "# spinneret mesh: %u vertices, %u triangles\n", m->vertex_count,
                                    m->triangle_count);
    for (uint32_t i = 0; st == SPN_OK && i < m->vertex_count; i++)
        st = spn_sink_printf(sink, "v %.9g %.9g %.9g\n", m->vertices[i].x, m->vertices[i].y, m->vertices[i].z);
    for (uint32_t t = 0; st == SPN_OK && t < m->triangle_count; t++) {
        const uint32_t *v = m->triangles + 3 * t;
        st = spn_sink_printf(sink, "f %u %u %u\n", v[0] + 1, v[1] + 1, v[2] + 1);
    }
    return st;
}

/* ---- a set of unordered pairs ------------------------------------------ */

#define PAIR_EMPTY UINT64_MAX

static uint64_t pair_key(uint32_t a, uint32_t b)
{
    return a < b ? ((uint64_t)a << 32 | b) : ((uint64_t)b << 32 | a);
}

static size_t pair_hash(uint64_t k, size_t mask)
{
    k ^= k >> 33;
    k *= 0xff51afd7ed558ccdULL;
    k ^= k >> 33;
    return (size_t)k & mask;
}

bool spn__pair_set_init(spn_pair_set *s, size_t expected)
{
    size_t cap = 64;
    while (cap < 2 * expected) cap *= 2;
    s->keys = malloc(cap * sizeof *s->keys);
    s->cap = s->keys ? cap : 0;
    s->count = 0;
    for (size_t i = 0; i < s->cap; i++) s->keys[i] = PAIR_EMPTY;
    return s->keys != NULL;
}

void spn__pair_set_free(spn_pair_set *s)
{
    free(s->keys);
    memset(s, 0, sizeof *s);
}

static bool pair_set_put(spn_pair_set *s, uint64_t k)
{
    size_t mask = s->cap - 1, i = pair_hash(k, mask);
    while (s->keys[i] != PAIR_EMPTY) {
        if (s->keys[i] == k) return false;
        i = (i + 1) & mask;
    }
    s->keys[i] = k;
    s->count++;
    return true;
}

bool spn__pair_set_insert(spn_pair_set *s, uint32_t a, uint32_t b, bool *oom)
{
    if (2 * (s->count + 1) > s->cap) {
        spn_pair_set bigger;
        if (!spn__pair_set_init(&bigger, s->cap)) {
            *oom = true;
            return false;
        }
        for (size_t i = 0; i < s->cap; i++)
            if (s->keys[i] != PAIR_EMPTY) pair_set_put(&bigger, s->keys[i]);
        spn__pair_set_free(s);
        *s = bigger;
    }
    return pair_set_put(s, pair_key(a, b));
}
