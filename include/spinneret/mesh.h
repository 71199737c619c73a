/* Any triangle mesh as a spring system (Juhasz & Bercovici, "Spring Systems"):
 * the mesh factory, mesh files (OBJ, PLY; other formats through assimp when
 * built with it), collisions of particles with triangle meshes, a small
 * driver that steps a world of mesh objects with collisions (`drop`, `film`),
 * and POV-Ray mesh2 scenes read, simulated and written back (`film`).
 *
 * Units SI, y up. Springs carry the thread kinds SPN_THREAD_STRETCH (edges),
 * SPN_THREAD_BEND (across two triangles) and SPN_THREAD_VICINITY (near
 * vertices) from web.h. */
#ifndef SPINNERET_MESH_H
#define SPINNERET_MESH_H

#include "world.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- triangle meshes ------------------------------------------------- */

/// A triangle mesh. Groups come from OBJ `g`/`o` lines (group 0 is the
/// unnamed default group); a vertex belongs to every group whose triangles use it.
typedef struct spn_mesh {
    uint32_t vertex_count;
    uint32_t triangle_count;
    spn_vec3 *vertices;        ///< vertex_count positions
    uint32_t *triangles;       ///< 3 * triangle_count vertex indices
    uint32_t *triangle_group;  ///< triangle_count group ids (NULL: all in group 0)
    uint32_t group_count;      ///< entries in group_names (0 when no groups)
    char **group_names;
} spn_mesh;

/// Release the arrays of a mesh and zero it (safe on a zeroed mesh).
SPN_API void spn_mesh_free(spn_mesh *m);
/// A deep copy of `src` into `dst`.
SPN_API spn_status spn_mesh_copy(spn_mesh *dst, const spn_mesh *src);
/// Read a mesh file: .obj and .ply with our readers (malformed files are
/// refused with the file and line named); other extensions through assimp
/// when the library was built with it. On failure *out is zeroed.
SPN_API spn_status spn_mesh_load(const char *path, spn_mesh *out);
/// Parse Wavefront OBJ text (v and f lines; polygons are refused, not split).
/// `name` is used in messages.
SPN_API spn_status spn_mesh_parse_obj(const char *text, size_t size, const char *name, spn_mesh *out);
/// Parse a PLY file (ascii, binary_little_endian or binary_big_endian).
SPN_API spn_status spn_mesh_parse_ply(const char *data, size_t size, const char *name, spn_mesh *out);
/// Write a mesh as OBJ (v and f lines) to a sink.
SPN_API spn_status spn_mesh_write_obj(const spn_mesh *m, spn_sink *sink);
/// Id of a group by name, or UINT32_MAX when there is none.
SPN_API uint32_t spn_mesh_group(const spn_mesh *m, const char *name);
/// Axis-aligned bounds of the vertices.
SPN_API void spn_mesh_bounds(const spn_mesh *m, spn_vec3 *lo, spn_vec3 *hi);

/* ---- the mesh factory -------------------------------------------------- */

/// How a mesh becomes springs. Start from spn_mesh_spring_def_default().
typedef struct spn_mesh_spring_def {
    double stretch_k, stretch_kd;   ///< edge springs [N/m], [N s/m]; default 1500, 4
    double bend_k, bend_kd;         ///< across adjacent triangles; default 1500, 3
    double vicinity_k, vicinity_kd; ///< near-vertex springs; default: the bend values
    double vicinity;                ///< join vertices nearer than this [m]; 0: none (default)
    double vertex_mass;             ///< kg per vertex, default 0.5 (used when total_mass is 0)
    double total_mass;              ///< > 0: this mass spread over vertices by triangle area
    bool fixed;                     ///< the whole object is fixed (an obstacle)
    const bool *fixed_vertices;     ///< optional: vertex_count flags, true = fixed
    const char *fixed_group;        ///< optional: the vertices of this group are fixed
    spn_vec3 velocity;              ///< initial velocity of the free vertices
    uint32_t particle_tag;          ///< tag for the particles (default 0)
} spn_mesh_spring_def;

SPN_API spn_mesh_spring_def spn_mesh_spring_def_default(void);

/// What the factory made.
typedef struct spn_mesh_stats {
    uint32_t first_particle; ///< particle id of vertex 0; vertex i is first_particle + i
    uint32_t particles, fixed;
    uint32_t edges;          ///< distinct edges = stretch springs
    uint32_t bend_pairs;     ///< pairs of triangles sharing an edge
    uint32_t bend;           ///< bend springs made (pairs whose opposite vertices were not joined yet)
    uint32_t vicinity;       ///< vicinity springs made (near pairs not joined yet)
} spn_mesh_stats;

/// Add a mesh to a world: a particle per vertex, then stretch, bend and
/// vicinity springs, never two springs on the same pair of vertices.
/// Degenerate triangles (repeated vertex) are refused with their index.
SPN_API spn_status spn_mesh_add_to_world(spn_world *w, const spn_mesh *m, const spn_mesh_spring_def *def,
                                         spn_mesh_stats *stats);

/* ---- a world of mesh objects with collisions ------------------------- */

typedef struct spn_mesh_scene spn_mesh_scene;

typedef struct spn_mesh_scene_def {
    spn_world_def world;     ///< gravity, integrator (default symplectic) ...
    double restitution;      ///< mesh contacts: kept fraction of normal speed, default 0.3
    double friction;         ///< mesh contacts: removed fraction of tangential speed, default 0.2
    double skin;             ///< particles stay this far from triangles [m], default 0.003
    double max_substep;      ///< largest sub-step [s], default 1e-3; smaller when stiffness needs it
    bool ground;             ///< a ground plane y = ground_y, default false
    double ground_y;
    double ground_restitution, ground_friction; ///< default 0.5, 0.2
} spn_mesh_scene_def;

SPN_API spn_mesh_scene_def spn_mesh_scene_def_default(void);
SPN_API spn_status spn_mesh_scene_create(const spn_mesh_scene_def *def, spn_mesh_scene **out);
SPN_API void spn_mesh_scene_destroy(spn_mesh_scene *s);
/// Add a mesh as a new object (its id in `object`). Free vertices collide
/// with the triangles of every other object, never with their own.
SPN_API spn_status spn_mesh_scene_add(spn_mesh_scene *s, const spn_mesh *m, const spn_mesh_spring_def *def,
                                      uint32_t *object);
SPN_API spn_world *spn_mesh_scene_world(spn_mesh_scene *s);
SPN_API uint32_t spn_mesh_scene_object_count(const spn_mesh_scene *s);
SPN_API const spn_mesh_stats *spn_mesh_scene_object_stats(const spn_mesh_scene *s, uint32_t object);
/// The object's mesh with its vertices at their current positions.
SPN_API spn_status spn_mesh_scene_object_mesh(const spn_mesh_scene *s, uint32_t object, spn_mesh *out);
/// Advance by dt in sub-steps small enough for the stiffest spring (explicit
/// stability) and resolve collisions after each sub-step.
SPN_API spn_status spn_mesh_scene_advance(spn_mesh_scene *s, double dt);
/// The sub-step the scene uses [s].
SPN_API double spn_mesh_scene_substep(spn_mesh_scene *s);
/// Kinetic energy of the free particles [J].
SPN_API double spn_mesh_scene_kinetic(const spn_mesh_scene *s);
/// Contacts resolved so far (particle against triangle).
SPN_API uint64_t spn_mesh_scene_contacts(const spn_mesh_scene *s);

/* ---- POV-Ray scenes ---------------------------------------------------- */

/// A POV-Ray 3.7 scene with mesh2 objects marked by the film maker's
/// `#local spring_system_*` declarations. The text is kept; only the numbers
/// of the vertex vectors of simulated objects are replaced when written.
typedef struct spn_pov_scene spn_pov_scene;

/// Parse a scene. Refused with the line: #include, spring_system_* outside a
/// mesh2, missing braces, non-numeric or non-finite vectors, bad face indices.
SPN_API spn_status spn_pov_scene_load(const char *path, spn_pov_scene **out);
SPN_API spn_status spn_pov_scene_parse(const char *text, size_t size, const char *name, spn_pov_scene **out);
SPN_API void spn_pov_scene_destroy(spn_pov_scene *p);
SPN_API uint32_t spn_pov_scene_object_count(const spn_pov_scene *p);
/// Object `i`'s mesh and its factory settings from the declarations
/// (spring_system_mass is the object's total mass, spread by area).
SPN_API const spn_mesh *spn_pov_scene_mesh(const spn_pov_scene *p, uint32_t i);
SPN_API spn_mesh_spring_def spn_pov_scene_spring_def(const spn_pov_scene *p, uint32_t i);
/// Line of the object's `mesh2` keyword.
SPN_API int spn_pov_scene_object_line(const spn_pov_scene *p, uint32_t i);
/// Write the scene with object i's vertices replaced by vertices[i] (an array
/// of object_count arrays; a NULL entry keeps that object's text).
SPN_API spn_status spn_pov_scene_write(const spn_pov_scene *p, const spn_vec3 *const *vertices, spn_sink *sink);

/// A simple POV-Ray view for scenes we write ourselves (the drop program).
typedef struct spn_pov_view_def {
    spn_vec3 eye, target;   ///< camera
    double angle_degrees;   ///< horizontal field of view, default 45
    bool ground;            ///< a checkered plane y = ground_y
    double ground_y;
} spn_pov_view_def;

/// A view whose camera frames the box [lo, hi] from the front, a little above.
SPN_API spn_pov_view_def spn_pov_view_frame(spn_vec3 lo, spn_vec3 hi);
/// Write a complete POV-Ray scene (camera, lights, optional ground) with each
/// mesh as a mesh2: mesh 0 smooth-shaded in blue (the simulated model), the
/// others flat in wood brown (obstacles).
SPN_API spn_status spn_pov_write_meshes(const spn_mesh *meshes, uint32_t count, const spn_pov_view_def *view,
                                        spn_sink *sink);

/// Render POV files DIR/frame_00000.pov ... (count of them) with the povray
/// program into PNGs beside them, then encode `movie` (NULL: none) with ffmpeg.
/// SPN_ERR_UNSUPPORTED when a program is missing.
SPN_API spn_status spn_pov_render_frames(const char *dir, int count, int width, int height, double fps,
                                         const char *movie);
/// True when `program` is found on PATH.
SPN_API bool spn_program_available(const char *program);

#ifdef __cplusplus
}
#endif
#endif
