/* Shared by the mesh reader harnesses: what every mesh a reader accepts must
 * satisfy, and a use of it (springs, bounds, OBJ written back), so a mesh
 * that parses but breaks its consumers is caught too. */
#ifndef SPN_FUZZ_MESH_H
#define SPN_FUZZ_MESH_H

#include <spinneret/spinneret.h>

#include <stdlib.h>

static void fuzz_check_mesh(const spn_mesh *m)
{
    for (uint32_t i = 0; i < m->vertex_count; i++)
        if (!spn_v3_finite(m->vertices[i])) abort(); /* readers refuse non-finite numbers */
    for (uint32_t t = 0; t < 3 * m->triangle_count; t++)
        if (m->triangles[t] >= m->vertex_count) abort();
    for (uint32_t t = 0; m->triangle_group && t < m->triangle_count; t++)
        if (m->triangle_group[t] > m->group_count) abort();
    spn_vec3 lo, hi;
    spn_mesh_bounds(m, &lo, &hi);
    spn_world *w = spn_world_create(NULL);
    spn_mesh_spring_def def = spn_mesh_spring_def_default();
    spn_mesh_stats stats;
    if (spn_mesh_add_to_world(w, m, &def, &stats) == SPN_OK) {
        if (spn_world_particle_count(w) != m->vertex_count) abort();
        spn_world_compile(w);
    }
    spn_world_destroy(w);
    spn_buffer buf = {0};
    spn_sink sink = spn_sink_buffer(&buf);
    if (spn_mesh_write_obj(m, &sink) != SPN_OK) abort();
    spn_buffer_free(&buf);
}

#endif
