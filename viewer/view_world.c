/* Where the viewer's worlds come from: web files, meshes (through the mesh
 * factory), the shared scenes, and webs built between clicked anchors. */
#include "view_internal.h"
#include "cli.h"

#include <string.h>

static spn_status open_scene(view_state *v, const char *name)
{
    spn_world *w = NULL;
    spn_world_def def = spn_world_def_default();
    spn_status st;
    if (strcmp(name, "orb") == 0) {
        spn_orb_scene_def d = spn_orb_scene_def_default();
        d.rings = 40, d.radials = 125; /* 5,001 particles: the real-time target */
        st = spn_scene_orb(&def, &d, &w);
    } else if (strcmp(name, "cloth") == 0) {
        def.drag = 0.05;
        st = spn_scene_cloth(&def, 30, 30, 1.0, 0.0, 0.5, 400, 0.05, 3u, &w);
    } else if (strcmp(name, "chain") == 0) {
        st = spn_scene_chain(&def, spn_v3(-0.5, 0, 0), spn_v3(0.5, 0, 0), 50, 1.0, 0.2, 2000, 0.02, &w);
    } else {
        return spn_error(SPN_ERR_INVALID, "unknown scene '%s' (orb, cloth, chain)", name);
    }
    if (st == SPN_OK) view_set_world(v, w);
    return st;
}

spn_status view_open_file(view_state *v, const char *path)
{
    if (strncmp(path, "scene:", 6) == 0) return open_scene(v, path + 6);
    const char *ext = cli_extension(path);
    if (strcmp(ext, "json") == 0) {
        spn_world *w = NULL;
        spn_status st = spn_web_load(path, &w);
        if (st == SPN_OK) view_set_world(v, w);
        return st;
    }
    return spn_error(SPN_ERR_UNSUPPORTED, "%s: the viewer opens .json web files and scene:orb|cloth|chain", path);
}

spn_status view_build_web(view_state *v)
{
    if (v->nanchors < 3) return spn_error(SPN_ERR_INVALID, "click at least 3 anchors before Enter");
    return spn_error(SPN_ERR_UNSUPPORTED, "building webs is not available in this build");
}
