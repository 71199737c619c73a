/* Where the viewer's worlds come from: web files and the shared scenes (the
 * same loader as `spinneret render`), meshes through the mesh factory, and
 * webs built between clicked anchors. */
#include "view_internal.h"
#include "cli.h"
#include "render_options.h"

#include <string.h>

int view_open_file(view_state *v, const char *spec)
{
    spn_world *w = NULL;
    int rc = render_load_world("view", spec, &w);
    if (rc == 0) view_set_world(v, w);
    return rc;
}

spn_status view_build_web(view_state *v)
{
    if (v->nanchors < 3) return spn_error(SPN_ERR_INVALID, "click at least 3 anchors before Enter");
    return spn_error(SPN_ERR_UNSUPPORTED, "building webs is not available in this build");
}
