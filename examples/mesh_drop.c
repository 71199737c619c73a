/* A mesh as a spring system, the smallest complete use of the mesh API (the
 * spring-system documentation's "library usage demonstration"): build an
 * octahedron, let the factory make it springs, drop it on the ground and
 * step until it is still, printing its height now and then. */
#include <spinneret/spinneret.h>

#include <stdio.h>

int main(void)
{
    /* Any triangle mesh will do; spn_mesh_load reads OBJ, PLY and more. */
    spn_vec3 v[6] = {{0.2, 0.5, 0}, {-0.2, 0.5, 0}, {0, 0.7, 0}, {0, 0.3, 0}, {0, 0.5, 0.2}, {0, 0.5, -0.2}};
    uint32_t t[24] = {0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5};
    spn_mesh mesh = {.vertex_count = 6, .triangle_count = 8, .vertices = v, .triangles = t};

    spn_mesh_scene_def def = spn_mesh_scene_def_default();
    def.ground = true; /* y = 0 */
    spn_mesh_scene *scene;
    if (spn_mesh_scene_create(&def, &scene) != SPN_OK) return 1;

    spn_mesh_spring_def springs = spn_mesh_spring_def_default(); /* -SS 1500 -BS 1500 -SD 4 -BD 3 -M 0.5 */
    springs.vicinity = 0.5; /* every pair nearer: here the bends already joined the opposite tips */
    if (spn_mesh_scene_add(scene, &mesh, &springs, NULL) != SPN_OK) {
        fprintf(stderr, "%s\n", spn_last_error());
        return 1;
    }
    const spn_mesh_stats *st = spn_mesh_scene_object_stats(scene, 0);
    printf("%u particles, %u stretch, %u bend, %u vicinity springs\n", st->particles, st->edges, st->bend, st->vicinity);

    spn_world *w = spn_mesh_scene_world(scene);
    double t_now = 0;
    for (int frame = 1; frame <= 300; frame++) {
        if (spn_mesh_scene_advance(scene, 0.01) != SPN_OK) {
            fprintf(stderr, "%s\n", spn_last_error());
            return 1;
        }
        t_now = frame * 0.01;
        if (frame % 25 == 0)
            printf("t = %.2f s: bottom tip at y = %.4f m, kinetic energy %.3g J\n", t_now,
                   spn_world_position(w, 3).y, spn_mesh_scene_kinetic(scene));
        if (t_now > 0.5 && spn_mesh_scene_kinetic(scene) < 1e-4) break;
    }
    double low = spn_world_position(w, 3).y;
    printf("%s at t = %.2f s, resting at y = %.4f m\n",
           spn_mesh_scene_kinetic(scene) < 1e-4 ? "still" : "still moving", t_now, low);
    spn_mesh_scene_destroy(scene);
    return low >= 0 && low < 0.05 ? 0 : 1; /* it must rest on the ground, not under it */
}
