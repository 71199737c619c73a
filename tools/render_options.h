/* Options shared by `render` and `export` (and any command that draws a web):
 * picture size, camera, background, shade, alpha, widths, dew, colouring; and
 * where a world comes from (a web file, or a built-in scene "scene:orb"). */
#ifndef SPN_RENDER_OPTIONS_H
#define SPN_RENDER_OPTIONS_H

#include "cli.h"

#include <getopt.h>

enum {
    RO_SIZE = 300, RO_CAMERA, RO_EYE, RO_TARGET, RO_UP, RO_FOV, RO_MARGIN, RO_BACKGROUND, RO_BACKGROUND_COLOR,
    RO_SHADE, RO_ALPHA, RO_WIDTH_SCALE, RO_GLOW, RO_DEW, RO_DEW_SPACING, RO_DEW_RADIUS, RO_DEW_JITTER, RO_DEW_SEED,
    RO_COLOUR_BY, RO_NO_LEGEND, RO_YAW, RO_PITCH, RO_SHEEN, RO_LIGHT, RO_SMOOTH
};

/* Entries for a getopt_long table (append {NULL, 0, NULL, 0} after your own). */
#define RENDER_LONG_OPTIONS                                                                                          \
    {"size", required_argument, NULL, RO_SIZE}, {"camera", required_argument, NULL, RO_CAMERA},                     \
    {"eye", required_argument, NULL, RO_EYE}, {"target", required_argument, NULL, RO_TARGET},                       \
    {"up", required_argument, NULL, RO_UP}, {"fov", required_argument, NULL, RO_FOV},                               \
    {"yaw", required_argument, NULL, RO_YAW}, {"pitch", required_argument, NULL, RO_PITCH},                         \
    {"margin", required_argument, NULL, RO_MARGIN}, {"background", required_argument, NULL, RO_BACKGROUND},         \
    {"background-color", required_argument, NULL, RO_BACKGROUND_COLOR},                                            \
    {"background-colour", required_argument, NULL, RO_BACKGROUND_COLOR},                                           \
    {"shade", required_argument, NULL, RO_SHADE}, {"alpha", required_argument, NULL, RO_ALPHA},                     \
    {"width-scale", required_argument, NULL, RO_WIDTH_SCALE}, {"glow", required_argument, NULL, RO_GLOW},           \
    {"dew", no_argument, NULL, RO_DEW}, {"dew-spacing", required_argument, NULL, RO_DEW_SPACING},                   \
    {"dew-radius", required_argument, NULL, RO_DEW_RADIUS}, {"dew-jitter", required_argument, NULL, RO_DEW_JITTER}, \
    {"dew-seed", required_argument, NULL, RO_DEW_SEED}, {"colour-by", required_argument, NULL, RO_COLOUR_BY},       \
    {"color-by", required_argument, NULL, RO_COLOUR_BY}, {"no-legend", no_argument, NULL, RO_NO_LEGEND},          \
    {"sheen", required_argument, NULL, RO_SHEEN}, {"light", required_argument, NULL, RO_LIGHT},                     \
    {"smooth", no_argument, NULL, RO_SMOOTH}

typedef struct render_options {
    spn_render_def def;
    bool eye_set, target_set;
    double yaw, pitch;
} render_options;

void render_options_init(render_options *o);
/* Handle getopt code `c`: 1 when handled, 0 when not a render option,
 * -1 after printing a usage line for a bad value. */
int render_options_parse(const char *cmd, int c, const char *arg, render_options *o);
/* Settle what depends on the world: the perspective camera's default eye and
 * target frame the web. */
void render_options_finish(render_options *o, const spn_world *w);
/* The help text for these options. */
void render_options_help(FILE *out);

/* Load a world from a web file, or build a shared scene: "scene:orb",
 * "scene:orb:RINGSxRADIALS", "scene:chain", "scene:cloth". Returns 0, or
 * prints the failure (naming the file) and returns the exit code. */
int render_load_world(const char *cmd, const char *spec, spn_world **w);

#endif
