/* Render options shared by frame-drawing commands (see animate_render.h). */
#include "animate_render.h"

#include <string.h>

void render_usage(FILE *out)
{
    fprintf(out,
            "render options:\n"
            "      --size WxH            frame size in pixels, up to 8192; default 1200x1200\n"
            "      --background FILE     a PNG behind the web (scaled to cover the frame)\n"
            "      --background-rgb R,G,B  plain background, each in [0, 1]; default 0,0,0\n"
            "      --shade R,G,B         thread shade, each in [0, 1]; default 0.85,0.85,0.85\n"
            "      --alpha A             thread opacity in [0, 1]; default 1\n"
            "      --width-scale S       multiplies thread widths, in (0, 100]; default 1\n"
            "      --colour MODE         shade, kind, tension or strain; default shade\n"
            "      --dew                 dew droplets on capture threads\n"
            "      --dew-spacing M       mean droplet spacing [m], in (0, 1]; default 0.004\n"
            "      --dew-radius M        mean droplet radius [m], in (0, 0.1]; default 0.0007\n"
            "      --glow G              soft halo around threads, in [0, 1]; default 0\n"
            "      --margin F            front camera: canvas fraction left around the web, in [0, 0.45]\n"
            "      --eye X,Y,Z           perspective camera at this point (default: front, orthographic)\n"
            "      --target X,Y,Z        perspective camera looks here; default 0,0,0\n"
            "      --fov DEG             perspective vertical field of view, in (1, 170); default 40\n"
            "      --no-legend           no legend for the colour modes\n");
}

static bool rgb(const char *cmd, const char *opt, const char *arg, double out[3])
{
    spn_vec3 v;
    if (!cli_vec3(cmd, opt, arg, false, &v)) return false;
    if (v.x < 0 || v.x > 1 || v.y < 0 || v.y > 1 || v.z < 0 || v.z > 1) {
        cli_usage(cmd, "%s: each component must be in [0, 1], got '%s'", opt, arg);
        return false;
    }
    out[0] = v.x, out[1] = v.y, out[2] = v.z;
    return true;
}

static bool colour_mode(const char *cmd, const char *arg, spn_colour_by *out)
{
    static const char *const names[] = {"shade", "kind", "tension", "strain"};
    for (int i = 0; i < 4; i++)
        if (strcmp(arg, names[i]) == 0) {
            *out = (spn_colour_by)i;
            return true;
        }
    cli_usage(cmd, "--colour: unknown mode '%s' (choose shade, kind, tension or strain)", arg);
    return false;
}

bool render_option(const char *cmd, int code, const char *arg, spn_render_def *d)
{
    switch (code) {
    case RENDER_OPT_SIZE: return cli_size(cmd, "--size", arg, 8192, &d->width, &d->height);
    case RENDER_OPT_BACKGROUND: d->background_png = arg; return true;
    case RENDER_OPT_BACKGROUND_RGB: return rgb(cmd, "--background-rgb", arg, d->background_rgb);
    case RENDER_OPT_SHADE: return rgb(cmd, "--shade", arg, d->shade_rgb);
    case RENDER_OPT_ALPHA: return cli_double(cmd, "--alpha", arg, 0, 1, &d->alpha);
    case RENDER_OPT_WIDTH_SCALE: return cli_double(cmd, "--width-scale", arg, 1e-6, 100, &d->width_scale);
    case RENDER_OPT_COLOUR: return colour_mode(cmd, arg, &d->colour_by);
    case RENDER_OPT_DEW: d->dew.enabled = true; return true;
    case RENDER_OPT_DEW_SPACING: return cli_double(cmd, "--dew-spacing", arg, 1e-6, 1, &d->dew.spacing);
    case RENDER_OPT_DEW_RADIUS: return cli_double(cmd, "--dew-radius", arg, 1e-7, 0.1, &d->dew.radius);
    case RENDER_OPT_GLOW: return cli_double(cmd, "--glow", arg, 0, 1, &d->glow);
    case RENDER_OPT_MARGIN: return cli_double(cmd, "--margin", arg, 0, 0.45, &d->camera.margin);
    case RENDER_OPT_EYE:
        d->camera.kind = SPN_CAMERA_PERSPECTIVE;
        return cli_vec3(cmd, "--eye", arg, false, &d->camera.eye);
    case RENDER_OPT_TARGET: return cli_vec3(cmd, "--target", arg, false, &d->camera.target);
    case RENDER_OPT_FOV: return cli_double(cmd, "--fov", arg, 1.000001, 169.99999, &d->camera.fov_degrees);
    case RENDER_OPT_NO_LEGEND: d->legend = false; return true;
    default: cli_usage(cmd, "unknown option code %d", code); return false;
    }
}
