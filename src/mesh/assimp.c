/* Other mesh formats (3DS, glTF, FBX, COLLADA, ...) through assimp's C API,
 * when the library is built with it. Every mesh of the file is merged into
 * one, in the file's coordinates (node transforms are applied by assimp's
 * PreTransformVertices step); polygons are triangulated by assimp. Vertices
 * at the same position are welded here (assimp keeps them apart when their
 * normals differ, as in STL), so neighbouring triangles share edges and the
 * factory can find bend pairs. Our own readers handle OBJ and PLY, because
 * they must name the line of a malformed entry, which assimp does not. */
#include "mesh_internal.h"

#if defined(SPN_HAVE_ASSIMP)
#include <assimp/cimport.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <stdlib.h>
#include <string.h>

static const spn_vec3 *sort_base;

static int cmp_position(const void *pa, const void *pb)
{
    spn_vec3 a = sort_base[*(const uint32_t *)pa], b = sort_base[*(const uint32_t *)pb];
    if (a.x != b.x) return a.x < b.x ? -1 : 1;
    if (a.y != b.y) return a.y < b.y ? -1 : 1;
    if (a.z != b.z) return a.z < b.z ? -1 : 1;
    return (*(const uint32_t *)pa > *(const uint32_t *)pb) - (*(const uint32_t *)pa < *(const uint32_t *)pb);
}

/* Merge vertices with equal positions, keeping first-seen order. */
static spn_status weld(spn_mesh *m)
{
    uint32_t n = m->vertex_count, *order = malloc(n * sizeof *order), *remap = malloc(n * sizeof *remap);
    if (!order || !remap) {
        free(order);
        free(remap);
        return spn_error(SPN_ERR_NOMEM, "out of memory");
    }
    for (uint32_t i = 0; i < n; i++) order[i] = i;
    sort_base = m->vertices; /* qsort has no context argument; loading is not reentrant here */
    qsort(order, n, sizeof *order, cmp_position);
    for (uint32_t i = 0; i < n; i++) {
        uint32_t v = order[i];
        spn_vec3 a = m->vertices[v], b = i > 0 ? m->vertices[order[i - 1]] : a;
        bool same = i > 0 && a.x == b.x && a.y == b.y && a.z == b.z;
        remap[v] = same ? remap[order[i - 1]] : v; /* the run's first has the smallest index */
    }
    uint32_t count = 0, *id = order; /* reuse: new id of each kept vertex */
    for (uint32_t i = 0; i < n; i++)
        if (remap[i] == i) {
            id[i] = count;
            m->vertices[count++] = m->vertices[i];
        }
    for (uint32_t t = 0; t < 3 * m->triangle_count; t++) m->triangles[t] = id[remap[m->triangles[t]]];
    m->vertex_count = count;
    free(order);
    free(remap);
    return SPN_OK;
}

static spn_status copy_meshes(const struct aiScene *sc, const char *path, spn_mesh *out)
{
    uint64_t nv = 0, nt = 0;
    for (unsigned i = 0; i < sc->mNumMeshes; i++) {
        nv += sc->mMeshes[i]->mNumVertices;
        for (unsigned f = 0; f < sc->mMeshes[i]->mNumFaces; f++) nt += sc->mMeshes[i]->mFaces[f].mNumIndices == 3;
    }
    if (nv == 0 || nt == 0 || nv > UINT32_MAX / 2 || nt > UINT32_MAX / 4)
        return spn_error(SPN_ERR_FORMAT, "%s: no triangles found", path);
    out->vertices = malloc(nv * sizeof *out->vertices);
    out->triangles = malloc(3 * nt * sizeof *out->triangles);
    if (!out->vertices || !out->triangles) return spn_error(SPN_ERR_NOMEM, "%s: out of memory", path);
    for (unsigned i = 0; i < sc->mNumMeshes; i++) {
        const struct aiMesh *m = sc->mMeshes[i];
        uint32_t base = out->vertex_count;
        for (unsigned v = 0; v < m->mNumVertices; v++)
            out->vertices[out->vertex_count++] = spn_v3(m->mVertices[v].x, m->mVertices[v].y, m->mVertices[v].z);
        for (unsigned f = 0; f < m->mNumFaces; f++) {
            if (m->mFaces[f].mNumIndices != 3) continue; /* points and lines */
            for (int k = 0; k < 3; k++) out->triangles[3 * out->triangle_count + k] = base + m->mFaces[f].mIndices[k];
            out->triangle_count++;
        }
    }
    spn_status st = weld(out);
    return st == SPN_OK ? spn__mesh_check(out, path) : st;
}

spn_status spn__mesh_load_assimp(const char *path, spn_mesh *out)
{
    const struct aiScene *sc = aiImportFile(path, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                                                      aiProcess_PreTransformVertices | aiProcess_SortByPType);
    if (!sc) return spn_error(SPN_ERR_FORMAT, "%s: cannot import: %s", path, aiGetErrorString());
    spn_status st = copy_meshes(sc, path, out);
    aiReleaseImport(sc);
    if (st != SPN_OK) spn_mesh_free(out);
    return st;
}
#else
typedef int spn__no_assimp; /* ISO C forbids an empty translation unit */
#endif
