/* Shared between the files of src/render: strands (springs chained into
 * paths), dew placement, the camera and colour scales. */
#ifndef SPN_RENDER_INTERNAL_H
#define SPN_RENDER_INTERNAL_H

#include "spinneret/render.h"

/* ---- strands ----------------------------------------------------------- */

/* One chain of springs of one kind. `first` indexes spn__strands.points,
 * .particles and .springs (a closed strand has as many springs as points; an
 * open one one fewer, its springs entry at first + count - 1 unused). */
typedef struct spn__chain {
    uint32_t kind;
    uint32_t first, count;
    bool closed;
} spn__chain;

typedef struct spn__strands {
    spn__chain *chains;
    uint32_t chain_count;
    spn_vec3 *points;
    uint32_t *particles;
    uint32_t *springs;
    uint32_t point_count;
} spn__strands;

/* Chain the intact springs of `w` into strands, kind by kind, in a fixed order
 * (kinds by drawing rank, then by lowest spring id), so output is deterministic. */
spn_status spn__strands_build(const spn_world *w, spn__strands *out);
void spn__strands_free(spn__strands *s);

/* Drawing rank of a kind: heavy structural threads first, fine ones on top. */
int spn__kind_rank(uint32_t tag);
/* A distinct colour per kind (for colour_by kind). */
void spn__kind_colour(uint32_t tag, double rgb[3]);
/* A perceptually ordered colour scale: t in [0, 1] -> rgb. */
void spn__scale_colour(double t, double rgb[3]);

/* ---- dew --------------------------------------------------------------- */

typedef struct spn__bead_list {
    spn_bead *beads;
    size_t count, capacity;
} spn__bead_list;

/* Droplets along the capture strands of `s`, from def's spacing, radius,
 * jitter and seed. Appends to `out`. */
spn_status spn__dew_place(const spn__strands *s, const spn_dew_def *def, spn__bead_list *out);
void spn__bead_list_free(spn__bead_list *list);

/* ---- camera ------------------------------------------------------------ */

/* A world-to-pixel mapping for a canvas of width x height. */
typedef struct spn__view {
    spn_camera_kind kind;
    double width, height;
    /* front: px = ox + scale * x, py = oy - scale * y */
    double scale, ox, oy;
    /* perspective: basis and focal length in pixels */
    spn_vec3 eye, right, up, forward;
    double focal;
    double px_per_ref;   /* canvas pixels per reference pixel (1200 px canvas) */
} spn__view;

/* Set up the view; the front camera frames the world's bounding box. */
spn_status spn__view_setup(const spn_world *w, const spn_render_def *def, spn__view *view);
/* Project a world point; false when it is behind the camera. `depth` (may be
 * NULL) gets the distance along the view direction (front: 1). */
bool spn__view_project(const spn__view *view, spn_vec3 p, double *x, double *y, double *depth);

/* Bounding box of the particles that carry at least one intact spring (all
 * particles when there are no springs). False for an empty world. */
bool spn__world_bounds(const spn_world *w, spn_vec3 *lo, spn_vec3 *hi);

/* ---- cairo backend ----------------------------------------------------- */

typedef struct _cairo cairo_t;
typedef struct _cairo_surface cairo_surface_t;
/* Draw the world onto `cr` (a canvas of def->width x def->height). */
spn_status spn__cairo_draw(const spn_world *w, const spn_render_def *def, cairo_t *cr);
/* A dew drop of radius r px at (x, y): a water lens showing the background
 * `bg` (NULL: a plain one of brightness bg_luma) upside down, with a rim,
 * a caustic and a specular highlight. bg_map = {scale, x offset, y offset}
 * of the background image on the canvas. */
void spn__cairo_water_drop(cairo_t *cr, double x, double y, double r, double bg_luma, cairo_surface_t *bg,
                           const double bg_map[3]);

/* ---- background images (backdrop.c) -------------------------------------- */

/* The PNG at `path`, decoded (or this thread's copy from the last call with
 * the same unchanged file): a new reference for the caller to destroy, and
 * its mean brightness 0..1. */
spn_status spn__backdrop_get(const char *path, cairo_surface_t **image, double *luma);
/* Free this thread's decoded background. */
void spn__backdrop_forget(void);

/* ---- PNG files (png_write.c) -------------------------------------------- */

/* Pixels to write: RGBA bytes (straight alpha), or cairo ARGB32 words
 * (premultiplied, native byte order), `stride` bytes a row. */
typedef struct spn__png_pixels {
    const uint8_t *data;
    int width, height;
    size_t stride;
    bool premultiplied;
} spn__png_pixels;

/* zlib levels: frames want speed, pictures size (png_write.c says why). */
#define SPN__PNG_LEVEL_FRAME 1
#define SPN__PNG_LEVEL_PICTURE 6

/* Write `src` to `path` (a temporary renamed into place); an opaque picture
 * as RGB, else RGBA. */
spn_status spn__png_write(const spn__png_pixels *src, int level, const char *path);
/* The same PNG in memory: a new buffer *bytes (free()) of *size bytes. */
spn_status spn__png_encode_memory(const spn__png_pixels *src, int level, uint8_t **bytes, size_t *size);
/* cairo ARGB32 words to straight RGB (channels 3) or RGBA (4) bytes. */
void spn__unpremultiply_row(const uint32_t *src, int width, uint8_t *out, int channels);

#endif
