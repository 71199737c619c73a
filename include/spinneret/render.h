/* Rendering: a world drawn with cairo to PNG, SVG, PDF or an RGBA buffer, and
 * frame sequences (PNG folder, or MP4/GIF through the ffmpeg program).
 * Renderers only read the world. Thread kinds (spring tags) choose each
 * thread's width and shade; unknown tags get a default. */
#ifndef SPINNERET_RENDER_H
#define SPINNERET_RENDER_H

#include "world.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum spn_camera_kind {
    SPN_CAMERA_FRONT = 0,   ///< orthographic, looking along -z, framing the web's bounding box
    SPN_CAMERA_PERSPECTIVE  ///< pinhole at `eye` looking at `target`
} spn_camera_kind;

typedef struct spn_camera {
    spn_camera_kind kind;
    spn_vec3 eye, target, up;  ///< perspective: up defaults to (0, 1, 0)
    double fov_degrees;        ///< perspective: vertical field of view, default 40
    double margin;             ///< front: fraction of the canvas left around the web, default 0.05
    bool fixed_bounds;         ///< front: use `bounds_min`/`bounds_max` instead of the world's box
    spn_vec3 bounds_min, bounds_max; ///< (animations frame every frame the same way)
} spn_camera;

typedef enum spn_colour_by {
    SPN_COLOUR_SHADE = 0,   ///< the grey shade per thread kind (the thesis' look)
    SPN_COLOUR_KIND,        ///< a distinct colour per thread kind, with a legend
    SPN_COLOUR_TENSION,     ///< colour scale of each spring's tension, with a legend
    SPN_COLOUR_STRAIN       ///< colour scale of each spring's strain, with a legend
} spn_colour_by;

typedef struct spn_dew_def {
    bool enabled;
    double spacing;         ///< mean distance between droplets along capture threads [m]
    double radius;          ///< mean droplet radius [m]
    double radius_jitter;   ///< relative spread of radii, 0..1
    uint64_t seed;
} spn_dew_def;

typedef struct spn_render_def {
    int width, height;             ///< pixels, default 1200 x 1200
    spn_camera camera;
    const char *background_png;    ///< NULL: plain background colour
    double background_rgb[3];      ///< 0..1, default black (0, 0, 0)
    double shade_rgb[3];           ///< thread shade 0..1, default (0.85, 0.85, 0.85)
    double alpha;                  ///< thread opacity 0..1, default 1
    double width_scale;            ///< multiplies every thread width, default 1
    spn_colour_by colour_by;
    spn_dew_def dew;
    bool legend;                   ///< draw the legend for colour_by modes, default true
} spn_render_def;

SPN_API spn_render_def spn_render_def_default(void);

/// Render to a file; the type comes from the extension (.png, .svg, .pdf).
/// Written atomically; on failure no file is left.
SPN_API spn_status spn_render_file(const spn_world *w, const spn_render_def *def, const char *path);
/// Render into `rgba` (width * height * 4 bytes, row-major, R G B A, not premultiplied).
SPN_API spn_status spn_render_rgba(const spn_world *w, const spn_render_def *def, uint8_t *rgba);

/// A sequence of frames written as DIR/frame_%05d.png, or piped into ffmpeg for
/// .mp4 (H.264) and .gif (palette-optimised). Closing with commit = false, or a
/// failure, leaves no partial video.
typedef struct spn_frames spn_frames;
SPN_API spn_status spn_frames_open(const char *out, int width, int height, double fps, spn_frames **frames);
/// Number to give the first frame written (for --frame-range); default 0.
SPN_API void spn_frames_set_first_index(spn_frames *frames, int index);
SPN_API spn_status spn_frames_add(spn_frames *frames, const uint8_t *rgba);
SPN_API spn_status spn_frames_close(spn_frames *frames, bool commit);

#ifdef __cplusplus
}
#endif
#endif
