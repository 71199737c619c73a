/* Exporters for the tools artists already use: OBJ and PLY (threads as
 * polylines, or as tube meshes), and complete POV-Ray 3.7 scenes. They read
 * the world through the same drawing callbacks as the renderer
 * (spn_draw_world), so strands, kinds and dew match the pictures. */
#ifndef SPINNERET_EXPORT_H
#define SPINNERET_EXPORT_H

#include "render.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct spn_export_def {
    double tube_radius;     ///< OBJ/PLY: 0 writes threads as polylines; > 0 as tubes of this radius [m]
    int tube_sides;         ///< OBJ/PLY tubes: sides of each tube, 3..64, default 6
    int dew_segments;       ///< OBJ/PLY: dew spheres get this many segments around, 4..64, default 10
    double pov_thread_radius; ///< POV: cylinder radius [m]; 0 (default): each kind's line width
                              ///< as it would be drawn at render.width x render.height pixels
    spn_render_def render;  ///< camera, size (aspect), background, shade, alpha, width_scale, dew
} spn_export_def;

SPN_API spn_export_def spn_export_def_default(void);

/// Kind number given to dew spheres in OBJ/PLY exports (group "dew").
#define SPN_EXPORT_DEW_KIND 65535u

/// Wavefront OBJ: one `v` per particle (polylines, in particle order, so
/// vertex i + 1 is particle i) and `l` elements per strand, or tube faces;
/// one object (`o`) and group (`g`) per thread kind, named after the kind.
SPN_API spn_status spn_export_obj(const spn_world *w, const spn_export_def *def, spn_sink *sink);
/// ASCII PLY: vertices (double x y z), and edges (polylines) or faces
/// (tubes), each with a `kind` property holding the thread tag.
SPN_API spn_status spn_export_ply(const spn_world *w, const spn_export_def *def, spn_sink *sink);
/// A complete POV-Ray 3.7 scene: camera and lights framing the web,
/// background colour or image, threads as cylinder chains merged per kind,
/// dew drops as water spheres. Renders with `povray +W800 +H800 FILE.pov`.
SPN_API spn_status spn_export_pov(const spn_world *w, const spn_export_def *def, spn_sink *sink);
/// Export by extension (.obj, .ply, .pov), written atomically.
SPN_API spn_status spn_export_file(const spn_world *w, const spn_export_def *def, const char *path);
/// One POV scene of an animation: DIR/frame_%05d.pov (the folder is made if
/// missing). Fix def->render.camera's bounds so every frame is framed alike.
SPN_API spn_status spn_export_pov_frame(const spn_world *w, const spn_export_def *def, const char *dir, int index);

#ifdef __cplusplus
}
#endif
#endif
