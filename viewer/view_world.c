/* Where the viewer's worlds come from: web files and the shared scenes (the
 * same loader as `spinneret render`), meshes through the mesh factory, and
 * webs built between clicked anchors. */
#include "view_internal.h"
#include "cli.h"
#include "render_options.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A mesh becomes a spring object (the mesh factory's defaults) falling onto a
 * floor half its height below it, as in the spring-system real-time demo. */
static int open_mesh(view_state *v, const char *path)
{
    spn_mesh m = {0};
    if (spn_mesh_load(path, &m) != SPN_OK) return cli_fail("view", "%s", spn_last_error());
    spn_world_def wd = spn_world_def_default();
    wd.drag = 0.2;
    spn_world *w = spn_world_create(&wd);
    spn_mesh_spring_def d = spn_mesh_spring_def_default();
    d.total_mass = 1.0;
    spn_mesh_stats stats;
    spn_status st = w ? spn_mesh_add_to_world(w, &m, &d, &stats) : spn_error(SPN_ERR_NOMEM, "out of memory");
    uint32_t *tris = st == SPN_OK ? malloc((size_t)m.triangle_count * 3 * sizeof *tris) : NULL;
    if (st == SPN_OK && !tris) st = spn_error(SPN_ERR_NOMEM, "out of memory");
    if (st == SPN_OK) {
        spn_vec3 lo, hi;
        spn_mesh_bounds(&m, &lo, &hi);
        st = spn_world_add_plane(w, spn_v3(0, 1, 0), lo.y - 0.5 * (hi.y - lo.y), 0.4, 0.3);
        for (uint32_t i = 0; i < 3 * m.triangle_count; i++) tris[i] = stats.first_particle + m.triangles[i];
    }
    uint32_t ntris = m.triangle_count;
    spn_mesh_free(&m);
    if (st != SPN_OK) {
        free(tris);
        spn_world_destroy(w);
        return cli_fail("view", "%s", spn_last_error());
    }
    view_set_world(v, w);
    free(v->tris);
    v->tris = tris;
    v->ntris = ntris;
    v->show_faces = true;
    return 0;
}

int view_open_file(view_state *v, const char *spec)
{
    const char *ext = cli_extension(spec);
    if (strcmp(ext, "obj") == 0 || strcmp(ext, "ply") == 0) return open_mesh(v, spec);
    spn_world *w = NULL;
    int rc = render_load_world("view", spec, &w);
    if (rc == 0) view_set_world(v, w);
    return rc;
}

static spn_vec3 sort_centre;

static int by_angle(const void *pa, const void *pb)
{
    const spn_vec3 *a = pa, *b = pb;
    double ta = atan2(a->y - sort_centre.y, a->x - sort_centre.x);
    double tb = atan2(b->y - sort_centre.y, b->x - sort_centre.x);
    return (ta > tb) - (ta < tb);
}

/* Clicks come in any order; builders want the anchors around the web. */
static void order_anchors(spn_vec3 *a, int n)
{
    spn_vec3 c = spn_v3(0, 0, 0);
    for (int i = 0; i < n; i++) c = spn_v3_add(c, a[i]);
    sort_centre = spn_v3_scale(c, 1.0 / n);
    qsort(a, (size_t)n, sizeof *a, by_angle);
}

spn_status view_build_web(view_state *v)
{
    if (v->nanchors < 3) return spn_error(SPN_ERR_INVALID, "click at least 3 anchors before Enter");
    spn_vec3 anchors[VIEW_MAX_ANCHORS];
    memcpy(anchors, v->anchors, (size_t)v->nanchors * sizeof *anchors);
    order_anchors(anchors, v->nanchors);
    spn_status st = spn_web_check_anchors(anchors, v->nanchors);
    if (st != SPN_OK) return st;
    spn_world *w = NULL;
    if (strcmp(v->opt.method, "physical") == 0) {
        spn_physical_def d = spn_physical_def_default();
        d.anchors = anchors;
        d.anchor_count = v->nanchors;
        d.seed = v->opt.seed;
        st = spn_web_build_physical(&d, &w);
    } else if (strcmp(v->opt.method, "geometric") == 0 && strcmp(v->opt.species, "generic") != 0) {
        return spn_error(SPN_ERR_INVALID, "--species %s needs the species builder: leave --method unset", v->opt.species);
    } else if (strcmp(v->opt.method, "geometric") == 0 && v->opt.method_given) {
        spn_geometric_def d = spn_geometric_def_default();
        d.anchors = anchors;
        d.anchor_count = v->nanchors;
        d.seed = v->opt.seed;
        st = spn_web_build_geometric(&d, &w);
    } else {
        spn_species sp;
        st = spn_species_parse(v->opt.species, &sp);
        if (st != SPN_OK) return st;
        spn_species_def d = spn_species_def_preset(sp);
        d.anchors = anchors;
        d.anchor_count = v->nanchors;
        d.seed = v->opt.seed;
        st = spn_web_build_species(&d, &w);
    }
    if (st != SPN_OK) return st;
    view_set_world(v, w);
    fprintf(stderr, "spinneret view: built a %s web (%u particles, %u springs, seed %llu)\n", v->opt.species,
            spn_world_particle_count(w), spn_world_spring_count(w), (unsigned long long)v->opt.seed);
    return SPN_OK;
}
