/* Render options for commands that draw frames (animate): one table of long
 * options, one handler and one usage text, so every such command spells the
 * camera, colours, background and dew the same way. Option codes start at
 * RENDER_OPT_BASE; a command appends RENDER_LONG_OPTIONS to its own table and
 * hands unknown codes to render_option(). */
#ifndef SPN_ANIMATE_RENDER_H
#define SPN_ANIMATE_RENDER_H

#include <getopt.h>
#include <stdio.h>

#include "cli.h"

#define RENDER_OPT_BASE 1000

enum {
    RENDER_OPT_SIZE = RENDER_OPT_BASE,
    RENDER_OPT_BACKGROUND,
    RENDER_OPT_BACKGROUND_RGB,
    RENDER_OPT_SHADE,
    RENDER_OPT_ALPHA,
    RENDER_OPT_WIDTH_SCALE,
    RENDER_OPT_COLOUR,
    RENDER_OPT_DEW,
    RENDER_OPT_DEW_SPACING,
    RENDER_OPT_DEW_RADIUS,
    RENDER_OPT_GLOW,
    RENDER_OPT_MARGIN,
    RENDER_OPT_EYE,
    RENDER_OPT_TARGET,
    RENDER_OPT_FOV,
    RENDER_OPT_NO_LEGEND,
    RENDER_OPT_END
};

#define RENDER_LONG_OPTIONS                                                                                        \
    {"size", required_argument, NULL, RENDER_OPT_SIZE},                                                            \
        {"background", required_argument, NULL, RENDER_OPT_BACKGROUND},                                            \
        {"background-rgb", required_argument, NULL, RENDER_OPT_BACKGROUND_RGB},                                    \
        {"shade", required_argument, NULL, RENDER_OPT_SHADE}, {"alpha", required_argument, NULL, RENDER_OPT_ALPHA}, \
        {"width-scale", required_argument, NULL, RENDER_OPT_WIDTH_SCALE},                                          \
        {"colour", required_argument, NULL, RENDER_OPT_COLOUR}, {"dew", no_argument, NULL, RENDER_OPT_DEW},        \
        {"dew-spacing", required_argument, NULL, RENDER_OPT_DEW_SPACING},                                          \
        {"dew-radius", required_argument, NULL, RENDER_OPT_DEW_RADIUS},                                            \
        {"glow", required_argument, NULL, RENDER_OPT_GLOW}, {"margin", required_argument, NULL, RENDER_OPT_MARGIN}, \
        {"eye", required_argument, NULL, RENDER_OPT_EYE}, {"target", required_argument, NULL, RENDER_OPT_TARGET},  \
        {"fov", required_argument, NULL, RENDER_OPT_FOV}, {"no-legend", no_argument, NULL, RENDER_OPT_NO_LEGEND}

/* Apply option `code` with `arg` to `def`. Returns false after printing a
 * usage line when the value is bad. `def` starts from spn_render_def_default(). */
bool render_option(const char *cmd, int code, const char *arg, spn_render_def *def);
/* The options' help text. */
void render_usage(FILE *out);

#endif
