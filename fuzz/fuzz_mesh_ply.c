/* Fuzz harness: the PLY mesh reader (spn_mesh_parse_ply). Any bytes give a
 * mesh whose indices and numbers are sound, or a refusal with a message. */
#include "fuzz_mesh.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    spn_mesh m;
    if (spn_mesh_parse_ply((const char *)data, size, "fuzz.ply", &m) == SPN_OK) {
        fuzz_check_mesh(&m);
        spn_mesh_free(&m);
    } else if (m.vertex_count || m.vertices || !spn_last_error()[0]) {
        abort(); /* a refusal leaves a zeroed mesh and says why */
    }
    return 0;
}
