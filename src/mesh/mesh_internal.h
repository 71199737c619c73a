/* Shared between the files of the mesh part. */
#ifndef SPN_MESH_INTERNAL_H
#define SPN_MESH_INTERNAL_H

#include "core/read_file.h"
#include "spinneret/mesh.h"

/* Grow *arr (element size `elem`) so that it holds at least `need` elements. */
bool spn__grow(void **arr, uint32_t *cap, uint32_t need, size_t elem);
/* Add a group name to a mesh being built; its id in *id. */
spn_status spn__mesh_add_group(spn_mesh *m, const char *name, size_t len, uint32_t *id);
/* Check indices and coordinates of a finished mesh; messages name `name`. */
spn_status spn__mesh_check(const spn_mesh *m, const char *name);
#if defined(SPN_HAVE_ASSIMP)
spn_status spn__mesh_load_assimp(const char *path, spn_mesh *out);
#endif

/* Set of unordered vertex pairs (open addressing on a 64-bit key). */
typedef struct spn_pair_set {
    uint64_t *keys;
    size_t cap, count;
} spn_pair_set;
bool spn__pair_set_init(spn_pair_set *s, size_t expected);
void spn__pair_set_free(spn_pair_set *s);
/* Insert {a, b}; true when it was not there. Sets *oom on allocation failure. */
bool spn__pair_set_insert(spn_pair_set *s, uint32_t a, uint32_t b, bool *oom);

/* Collisions of particles with the triangles of other objects (collide.c). */
typedef struct spn_tri_collider spn_tri_collider;
spn_tri_collider *spn__tri_collider_create(double skin, double restitution, double friction);
void spn__tri_collider_destroy(spn_tri_collider *c);
/* Triangles over world particle ids, all of object `object`. */
spn_status spn__tri_collider_add(spn_tri_collider *c, const uint32_t *tris, uint32_t count, uint32_t first_particle,
                                 uint32_t object, bool moving);
/* Particle p belongs to `object` (particles of one object never hit its own triangles). */
spn_status spn__tri_collider_set_owner(spn_tri_collider *c, uint32_t first, uint32_t count, uint32_t object);
/* Resolve the moves x0 -> x of the world's free particles; returns contacts. */
uint64_t spn__tri_collider_resolve(spn_tri_collider *c, spn_world *w, const spn_vec3 *x0);

#endif
