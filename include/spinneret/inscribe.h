/* Charlotte's-web inscription (Mehla 2005, chapter 6): a message (text set in
 * a real font, or a bi-level / grey image) is written into a physical orb web
 * by taking capture-spiral segments out where the message lies, optionally
 * adding inscription threads that emphasise it, and settling the web again.
 *
 * Flow: make a target raster framed on the web (spn_target_create, then
 * spn_target_text / spn_target_image / spn_target_paint), then call
 * spn_inscribe. The target is "ink": 0 = nothing, 1 = message, one float per
 * pixel, in the same frame as the raster of the web it is compared against.
 * See docs/inscription.md for how the thesis' score is read. */
#ifndef SPINNERET_INSCRIBE_H
#define SPINNERET_INSCRIBE_H

#include "world.h"

#ifdef __cplusplus
extern "C" {
#endif

/// A raster of ink in world coordinates: pixel (i, j) has its centre at
/// x = x0 + (i + 0.5) / scale, y = y0 - (j + 0.5) / scale (row 0 on top).
typedef struct spn_target spn_target;

/// Where the capture spiral lies: a circle centred on the capture threads
/// that stays inside them in every direction (text and images are fitted into it).
typedef struct spn_capture_area {
    spn_vec3 centre;
    double radius;      ///< [m]
    double inner;       ///< radius of the free zone around the hub [m]
    uint32_t segments;  ///< capture springs found
} spn_capture_area;

/// The capture area of a web; SPN_ERR_INVALID when it has no SPN_THREAD_CAPTURE springs.
SPN_API spn_status spn_capture_area_of(const spn_world *w, spn_capture_area *out);

/// An empty target framed on the web's bounding box (x-y plane, a 4 % margin),
/// its longer side `size` pixels (16..8192; 1200 matches the default render).
SPN_API spn_status spn_target_create(const spn_world *w, int size, spn_target **out);
SPN_API void spn_target_destroy(spn_target *t);
/// Pixel size and the ink array (width * height floats, row 0 on top).
SPN_API const float *spn_target_ink(const spn_target *t, int *width, int *height);
/// World -> pixel (fractional) and scale [px/m].
SPN_API void spn_target_to_pixel(const spn_target *t, spn_vec3 p, double *px, double *py);
SPN_API double spn_target_scale(const spn_target *t);
/// Ink at a world point (nearest pixel; 0 outside).
SPN_API double spn_target_ink_at(const spn_target *t, spn_vec3 p);
/// Fraction of pixels with ink >= 0.5.
SPN_API double spn_target_coverage(const spn_target *t);

/// Paint ink from a function of world (x, y) (tests, procedural targets):
/// each pixel gets max(its ink, fn(x, y)) clamped to [0, 1].
typedef double (*spn_ink_fn)(void *user, double x, double y);
SPN_API void spn_target_paint(spn_target *t, spn_ink_fn fn, void *user);

/// Text set in a real font through cairo and FreeType (fontconfig finds it).
typedef struct spn_text_def {
    const char *text;      ///< lines separated by '\n'; not empty
    const char *font;      ///< "Family [Bold] [Italic|Oblique]", default "DejaVu Sans Bold"
    double fit;            ///< fraction of the largest size that fits in the capture spiral, default 0.9
    double height;         ///< > 0: capital height [m] instead of fitting; must still fit
    double line_spacing;   ///< baseline distance in capital heights, default 1.45
} spn_text_def;

SPN_API spn_text_def spn_text_def_default(void);
/// Set the text where the largest block of its shape fits in the capture
/// spiral, at `fit` of that size. Errors: empty text, a font that
/// fontconfig does not have (no silent substitution), text that cannot fit.
SPN_API spn_status spn_target_text(spn_target *t, const spn_world *w, const spn_text_def *def);

/// Place an image file (PNG through cairo; PBM/PGM P1/P2/P4/P5), dark = ink,
/// transparent = no ink, placed like text: where the largest image of its
/// aspect fits in the capture spiral, at `fit` (0 < fit <= 1) of that size.
/// Errors name the file (and line for PNM).
SPN_API spn_status spn_target_image(spn_target *t, const spn_world *w, const char *path, double fit);

/// A grey image: 0 black .. 255 white.
typedef struct spn_grey_image {
    int width, height;
    uint8_t *pixels;
} spn_grey_image;
/// Read a PBM or PGM file (P1, P2, P4, P5; maxval up to 65535).
SPN_API spn_status spn_pnm_read(const char *path, spn_grey_image *out);
SPN_API void spn_grey_image_free(spn_grey_image *img);

typedef enum spn_emphasis {
    SPN_EMPHASIS_NONE = 0,   ///< the thesis' plain method (fig 6.11)
    SPN_EMPHASIS_CROSSHATCH, ///< extra spiral segments to two more masses, kept inside (fig 6.12)
    SPN_EMPHASIS_FILL,       ///< random attachments inside the letters, shaded darker (fig 6.13)
    SPN_EMPHASIS_OUTLINE     ///< threads around the letters strengthened (fig 6.14)
} spn_emphasis;

/// "none", "crosshatch", "fill", "outline".
SPN_API const char *spn_emphasis_name(spn_emphasis e);
SPN_API spn_status spn_emphasis_parse(const char *name, spn_emphasis *out);

typedef struct spn_inscribe_def {
    int threshold;         ///< remove segments whose score (1..10) is above this, default 8
    spn_emphasis emphasis; ///< default SPN_EMPHASIS_NONE
    int gaps;              ///< random capture segments taken out anywhere (fig 6.18), default 0
    double fill_spacing;   ///< fill: distance between attachments [m]; 0 = capture radius / 80
    uint64_t seed;         ///< for fill and gaps, default 1
    bool settle;           ///< settle before scoring and after editing, default true
    spn_settle_def settle_def; ///< default spn_settle_def_default() with drag SPN_SETTLE_DRAG
    /// After editing, solve for the rest state first (spn_web_solve_rest, to
    /// settle_def.max_residual and a hundredth of the lightest particle's
    /// weight) and step with settle_def only where that falls short; default
    /// true. The settle before scoring always steps (docs/inscription.md).
    bool settle_solve;
    /// Step with the web's own integrator even where it cannot take
    /// settle_def.dt (a blow-up is then reported); default false: such a
    /// settle steps implicitly (report.implicit_before / implicit_after).
    /// `spinneret inscribe --solver NAME` sets it.
    bool settle_keep_integrator;
} spn_inscribe_def;

SPN_API spn_inscribe_def spn_inscribe_def_default(void);

typedef struct spn_inscribe_report {
    uint32_t segments;     ///< capture segments scored (mass to mass)
    uint32_t removed;      ///< capture segments taken out by their score
    uint32_t gaps;         ///< capture segments taken out at random
    uint32_t added;        ///< inscription springs put in
    uint32_t split;        ///< web springs split to carry fill attachments
    uint32_t pruned;       ///< springs taken out because they were left dangling or unanchored
    uint32_t particles_removed; ///< particles left with no thread, taken out
    int score_histogram[11];    ///< segments per score (index 1..10)
    spn_settle_report before, after;
    /// The settle stepped with the implicit integrator: the web's own explicit
    /// one could not take settle_def.dt (spn_world_stable_step); the web keeps
    /// its integrator. False when the settle took no step.
    bool implicit_before, implicit_after;
} spn_inscribe_report;

/// Score every capture segment against the target (thesis fig 6.9, our
/// reading in docs/inscription.md): `scores` gets spring_count entries, the
/// score 1..10 of each capture spring and 0 for other springs.
SPN_API spn_status spn_inscribe_scores(const spn_world *w, const spn_target *t, uint8_t *scores);

/// Inscribe the target into *w. The edits are made on a copy (spn_world_clone)
/// that replaces *w on success, so pass its address; particles left without
/// threads are taken out of it in place (spn_world_remove_particles: ids
/// change), and it keeps every setting of *w (callbacks, air, colliders, tag
/// diameters and hysteresis, lattice switch, precision, preconditioner,
/// metadata) but contacts, which spn_world_clone does not copy.
/// On failure *w is unchanged.
SPN_API spn_status spn_inscribe(spn_world **w, const spn_target *t, const spn_inscribe_def *def,
                                spn_inscribe_report *report);

/// The target over the web (figs 6.3, 6.10): the web dark on white, the
/// dilated target in translucent red, as a PNG of the target's size.
SPN_API spn_status spn_inscribe_overlay(const spn_world *w, const spn_target *t, const char *path);

#ifdef __cplusplus
}
#endif
#endif
