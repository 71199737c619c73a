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
    double glow;                   ///< soft halo around threads 0..1, default 0 (the thesis look)
    double sheen;                  ///< glints where a thread reflects the light 0..1, default 0
    spn_vec3 light;                ///< direction towards the (distant) light, default (-0.4, 0.5, -0.75):
                                   ///< a low sun behind the web, which makes silk glint in arcs
    bool smooth;                   ///< draw strands as centripetal Catmull-Rom curves through their
                                   ///< particles instead of straight segments, default false
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
/// Frames drawn on several threads: spn_frames_encode turns a picture into the
/// bytes the sequence stores (a frame's PNG file for a folder, the RGBA itself
/// for a video) into a new buffer `*bytes` (free it with free()). It only reads
/// the sequence's settings, so several threads may encode at once.
/// spn_frames_add_encoded then adds them as the next frame, in order, one
/// thread at a time: the same file or video as spn_frames_add of the picture.
SPN_API spn_status spn_frames_encode(const spn_frames *frames, const uint8_t *rgba, uint8_t **bytes, size_t *size);
SPN_API spn_status spn_frames_add_encoded(spn_frames *frames, const uint8_t *bytes, size_t size);
SPN_API spn_status spn_frames_close(spn_frames *frames, bool commit);


/* ---- additions (render helper) ----------------------------------------- */

/// Line width [px on a 1200 px canvas] and grey factor of a thread kind; unknown
/// tags get the generic style. The shade drawn is shade_rgb * factor.
SPN_API double spn_thread_kind_width(uint32_t tag);
SPN_API double spn_thread_kind_shade(uint32_t tag);

/* ---- drawing callbacks ------------------------------------------------- *
 * The web is emitted as strands (one smooth path each: consecutive springs of
 * one kind chained through particles of degree 2 for that kind), beads (dew
 * droplets) and labels (the legend). Cairo, the viewer and the exporters
 * implement the table; all coordinates are world coordinates. */

/// A chain of springs of one kind, drawn as one path.
typedef struct spn_strand {
    uint32_t kind;               ///< thread tag of every spring in the strand
    uint32_t count;              ///< points (springs + 1, or springs when closed)
    const spn_vec3 *points;      ///< world positions
    const uint32_t *particles;   ///< particle id of each point
    const uint32_t *springs;     ///< spring id of each segment (count - 1, or count when closed)
    bool closed;                 ///< the last point joins the first
    double width;                ///< line width [px on a 1200 px canvas], width_scale applied
    double rgb[3];               ///< colour of the whole strand (shade or kind colour)
    const double *segment_rgb;   ///< colour_by tension/strain: 3 values per segment, else NULL
    double alpha;                ///< opacity 0..1
    const double *segment_glint; ///< sheen > 0: specular glint 0..1 per segment, else NULL
} spn_strand;

/// A dew droplet: a small water sphere.
typedef struct spn_bead {
    spn_vec3 centre;
    double radius;               ///< [m]
    uint32_t strand_kind;        ///< the kind of thread it sits on
} spn_bead;

/// One row of the legend: a colour swatch and its text. Row 0 is the title
/// (its swatch unused).
typedef struct spn_label {
    const char *text;
    double rgb[3];
    int row;
    int rows;                    ///< rows in this legend
} spn_label;

typedef struct spn_draw_fns {
    spn_status (*strand)(void *user, const spn_strand *strand);  ///< may be NULL
    spn_status (*bead)(void *user, const spn_bead *bead);        ///< may be NULL
    spn_status (*label)(void *user, const spn_label *label);     ///< may be NULL
} spn_draw_fns;

/// Emit the world through `fns`: strands first (heavier kinds first, so fine
/// threads lie on top), then dew beads when def->dew.enabled, then the legend
/// when def->legend and a colour_by mode asks for one. Stops at the first
/// callback that fails and returns its status.
SPN_API spn_status spn_draw_world(const spn_world *w, const spn_render_def *def, const spn_draw_fns *fns, void *user);

/// Defaults for dew: spacing 6 mm, radius 1.3 mm, jitter 0.35, seed 1, disabled
/// (heavy morning dew on a web some 30 cm across: drops of a few pixels at 1200 px).
SPN_API spn_dew_def spn_dew_def_default(void);

/// Check a render definition; SPN_ERR_INVALID naming the first bad field.
SPN_API spn_status spn_render_def_check(const spn_render_def *def);

/// A perspective camera looking at the centre of the web's bounding box from
/// `yaw_degrees` to the right and `pitch_degrees` above the front (+z) view,
/// far enough back that the whole box fits in the vertical field of view.
SPN_API spn_camera spn_camera_orbit(const spn_world *w, double yaw_degrees, double pitch_degrees, double fov_degrees);

/// Width and height of a PNG file, reading it fully so a damaged file is
/// refused here (SPN_ERR_IO: unreadable, SPN_ERR_FORMAT: not a PNG).
SPN_API spn_status spn_png_size(const char *path, int *width, int *height);

/// Is the ffmpeg program on PATH (or $SPN_FFMPEG)? Frame sequences to .mp4/.gif need it.
SPN_API bool spn_frames_have_ffmpeg(void);
/// Render `w` with `def` (its size must be the sequence's) and add it as the
/// next frame: the one call an animation loop needs.
SPN_API spn_status spn_frames_add_world(spn_frames *frames, const spn_world *w, const spn_render_def *def);
/// The frame size a sequence was opened with.
SPN_API void spn_frames_size(const spn_frames *frames, int *width, int *height);

/// Release the font and surface caches cairo and fontconfig keep for the
/// life of the process (legend text fills them) and the calling thread's
/// decoded background image (each thread keeps the last one it drew, until it
/// ends), so leak checkers see a clean exit. Call once, just before exiting,
/// when nothing else uses cairo; the commands that draw do.
SPN_API void spn_render_release_caches(void);

/* ---- progress on stderr ------------------------------------------------ */

/// A one-line progress bar on stderr, shown only when stderr is a terminal
/// and `quiet` is false (animating commands pass their --quiet). NULL-safe:
/// every function accepts the NULL that begin returns when it shows nothing.
typedef struct spn_progress spn_progress;
SPN_API spn_progress *spn_progress_begin(const char *label, uint64_t total, bool quiet);
SPN_API void spn_progress_update(spn_progress *progress, uint64_t done);
/// Finish the line and free the bar.
SPN_API void spn_progress_end(spn_progress *progress);

#ifdef __cplusplus
}
#endif
#endif
