/* Fuzz harness: the POV-Ray mesh2 scene reader (spn_pov_scene_parse), then
 * every object through the factory and the scene written back with its
 * vertices moved, as `film` does. */
#include "fuzz_mesh.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    spn_pov_scene *p = NULL;
    if (spn_pov_scene_parse((const char *)data, size, "fuzz.pov", &p) != SPN_OK) {
        if (p || !spn_last_error()[0]) abort();
        return 0;
    }
    uint32_t n = spn_pov_scene_object_count(p);
    const spn_vec3 **moved = calloc(n ? n : 1, sizeof *moved);
    for (uint32_t i = 0; i < n; i++) {
        const spn_mesh *m = spn_pov_scene_mesh(p, i);
        fuzz_check_mesh(m);
        (void)spn_pov_scene_spring_def(p, i);
        moved[i] = m->vertices;
    }
    spn_buffer buf = {0};
    spn_sink sink = spn_sink_buffer(&buf);
    if (spn_pov_scene_write(p, moved, &sink) != SPN_OK) abort();
    spn_buffer_free(&buf);
    free(moved);
    spn_pov_scene_destroy(p);
    return 0;
}
