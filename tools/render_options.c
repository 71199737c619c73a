/* Options shared by the commands that draw or export a web; see render_options.h. */
#include "render_options.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

void render_options_init(render_options *o)
{
    memset(o, 0, sizeof *o);
    o->def = spn_render_def_default();
    o->yaw = 25;
    o->pitch = 12;
}

static bool colour(const char *cmd, const char *opt, const char *arg, double rgb[3])
{
    double c[3];
    int used = 0;
    bool ok = sscanf(arg, "%lf,%lf,%lf%n", &c[0], &c[1], &c[2], &used) == 3 && arg[used] == '\0';
    for (int i = 0; ok && i < 3; i++) ok = c[i] >= 0 && c[i] <= 1; /* false for NaN too */
    if (!ok) {
        cli_usage(cmd, "%s: expected R,G,B with each in [0, 1], got '%s'", opt, arg);
        return false;
    }
    rgb[0] = c[0], rgb[1] = c[1], rgb[2] = c[2];
    return true;
}

static bool camera_kind(const char *cmd, const char *arg, spn_camera_kind *kind)
{
    if (strcmp(arg, "front") == 0) *kind = SPN_CAMERA_FRONT;
    else if (strcmp(arg, "persp") == 0 || strcmp(arg, "perspective") == 0) *kind = SPN_CAMERA_PERSPECTIVE;
    else return cli_usage(cmd, "--camera: expected front or persp, got '%s'", arg), false;
    return true;
}

static bool colour_by(const char *cmd, const char *arg, spn_colour_by *by)
{
    static const char *const names[] = {"shade", "kind", "tension", "strain"};
    const int i = cli_choice(arg, names, 4);
    if (i >= 0) {
        *by = (spn_colour_by)i;
        return true;
    }
    cli_usage(cmd, "--colour-by: expected tension, strain, kind or shade, got '%s'", arg);
    return false;
}

static bool background(const char *cmd, const char *arg, spn_render_def *d)
{
    int w, h;
    if (spn_png_size(arg, &w, &h) != SPN_OK) {
        cli_usage(cmd, "--background: %s", spn_last_error());
        return false;
    }
    d->background_png = arg;
    return true;
}

static bool light(const char *cmd, const char *arg, spn_vec3 *dir)
{
    if (!cli_vec3(cmd, "--light", arg, false, dir)) return false;
    if (spn_v3_len(*dir) > 0 && isfinite(spn_v3_len(*dir))) return true;
    cli_usage(cmd, "--light: expected a direction X,Y,Z (not 0,0,0, length finite), got '%s'", arg);
    return false;
}

static bool size(const char *cmd, const char *arg, spn_render_def *d)
{
    if (!cli_size(cmd, "--size", arg, 16384, &d->width, &d->height)) return false;
    if ((double)d->width * d->height <= RO_MAX_PIXELS) return true;
    cli_usage(cmd, "--size: expected WxH of at most %.0f million pixels (each side in [1, 16384]), got '%s'",
              RO_MAX_PIXELS / 1e6, arg);
    return false;
}

static bool parse_dew(const char *cmd, int c, const char *arg, spn_dew_def *dew)
{
    dew->enabled = true;
    switch (c) {
    case RO_DEW: return true;
    case RO_DEW_SPACING: return cli_double(cmd, "--dew-spacing", arg, 1e-6, 10, &dew->spacing);
    case RO_DEW_RADIUS: return cli_double(cmd, "--dew-radius", arg, 1e-7, 1, &dew->radius);
    case RO_DEW_JITTER: return cli_double(cmd, "--dew-jitter", arg, 0, 1, &dew->radius_jitter);
    default: return cli_u64(cmd, "--dew-seed", arg, &dew->seed);
    }
}

int render_options_parse(const char *cmd, int c, const char *arg, render_options *o)
{
    spn_render_def *d = &o->def;
    bool ok = true;
    switch (c) {
    case RO_SIZE: ok = size(cmd, arg, d); break;
    case RO_CAMERA: ok = camera_kind(cmd, arg, &d->camera.kind); break;
    case RO_EYE: ok = o->eye_set = cli_vec3_bounded(cmd, "--eye", arg, CLI_MAX_COORD, &d->camera.eye); break;
    case RO_TARGET: ok = o->target_set = cli_vec3_bounded(cmd, "--target", arg, CLI_MAX_COORD, &d->camera.target); break;
    case RO_UP: ok = cli_vec3_bounded(cmd, "--up", arg, CLI_MAX_COORD, &d->camera.up); break;
    case RO_FOV: ok = cli_double(cmd, "--fov", arg, 1, 170, &d->camera.fov_degrees); break;
    case RO_YAW: ok = cli_double(cmd, "--yaw", arg, -360, 360, &o->yaw); break;
    case RO_PITCH: ok = cli_double(cmd, "--pitch", arg, -89, 89, &o->pitch); break;
    case RO_MARGIN: ok = cli_double(cmd, "--margin", arg, 0, 0.45, &d->camera.margin); break;
    case RO_BACKGROUND: ok = background(cmd, arg, d); break;
    case RO_BACKGROUND_COLOR: ok = colour(cmd, "--background-color", arg, d->background_rgb); break;
    case RO_SHADE: ok = colour(cmd, "--shade", arg, d->shade_rgb); break;
    case RO_ALPHA: ok = cli_double(cmd, "--alpha", arg, 0, 1, &d->alpha); break;
    case RO_WIDTH_SCALE: ok = cli_double(cmd, "--width-scale", arg, 0.01, 100, &d->width_scale); break;
    case RO_GLOW: ok = cli_double(cmd, "--glow", arg, 0, 1, &d->glow); break;
    case RO_SHEEN: ok = cli_double(cmd, "--sheen", arg, 0, 1, &d->sheen); break;
    case RO_LIGHT: ok = light(cmd, arg, &d->light); break;
    case RO_DEW: case RO_DEW_SPACING: case RO_DEW_RADIUS: case RO_DEW_JITTER: case RO_DEW_SEED:
        ok = parse_dew(cmd, c, arg, &d->dew);
        break;
    case RO_COLOUR_BY: ok = colour_by(cmd, arg, &d->colour_by); break;
    case RO_NO_LEGEND: d->legend = false; break;
    case RO_SMOOTH: d->smooth = true; break;
    default: return 0;
    }
    return ok ? 1 : -1;
}

void render_options_finish(render_options *o, const spn_world *w)
{
    spn_camera *c = &o->def.camera;
    if (c->kind != SPN_CAMERA_PERSPECTIVE || o->eye_set) return;
    spn_camera orbit = spn_camera_orbit(w, o->yaw, o->pitch, c->fov_degrees);
    if (o->target_set) {
        /* Keep the orbit's direction and distance, around the given target. */
        orbit.eye = spn_v3_add(orbit.eye, spn_v3_sub(c->target, orbit.target));
        orbit.target = c->target;
    }
    c->eye = orbit.eye;
    c->target = orbit.target;
}

int render_options_check(const char *cmd, const render_options *o)
{
    const spn_camera *c = &o->def.camera;
    if (c->kind != SPN_CAMERA_PERSPECTIVE) return -1;
    spn_vec3 forward = spn_v3_sub(c->target, c->eye);
    double dist = spn_v3_len(forward);
    if (!(dist > 0) || !isfinite(dist))
        return cli_usage(cmd, "--eye, --target: expected two different points, got the eye at the target");
    spn_vec3 up = spn_v3_len(c->up) > 0 ? c->up : spn_v3(0, 1, 0);
    if (!(spn_v3_len(spn_v3_cross(spn_v3_norm(forward), spn_v3_norm(up))) > 1e-9))
        return cli_usage(cmd, "--up: expected a direction not along the line from --eye to --target");
    return -1;
}

void render_options_help(FILE *out)
{
    fprintf(out,
            "picture:\n"
            "      --size WxH             pixels, each side 1..16384 (default 1200x1200)\n"
            "      --camera front|persp   orthographic front view framing the web (default),\n"
            "                             or a perspective camera\n"
            "      --eye X,Y,Z            perspective: camera position [m] (default: from --yaw/--pitch)\n"
            "      --target X,Y,Z         perspective: point looked at (default: the web's centre)\n"
            "      --up X,Y,Z             perspective: up direction (default 0,1,0)\n"
            "      --fov DEG              perspective: vertical field of view, 1..170 (default 40)\n"
            "      --yaw DEG, --pitch DEG perspective without --eye: view from this far right / above (25, 12)\n"
            "      --margin F             front: fraction of the canvas left around the web, 0..0.45 (0.05)\n"
            "      --background FILE.png  image behind the web, scaled to cover the canvas and cropped\n"
            "      --background-color R,G,B   plain background, each 0..1 (default 0,0,0)\n"
            "look:\n"
            "      --shade R,G,B          thread grey, each 0..1 (default 0.85,0.85,0.85); the thesis\n"
            "                             used 0.86,0.88,0.87 and 0.69,0.71,0.73\n"
            "      --alpha A              thread opacity 0..1 (default 1; the thesis used 0.7)\n"
            "      --width-scale S        multiply every thread width, 0.01..100 (default 1)\n"
            "      --glow G               soft halo around threads, 0..1 (default 0)\n"
            "      --sheen S              glints where threads reflect the light, 0..1 (default 0)\n"
            "      --light X,Y,Z          direction towards the light (default -0.4,0.5,-0.75: a low\n"
            "                             sun behind the web)\n"
            "      --smooth               strands as smooth curves through their particles\n"
            "      --colour-by MODE       tension, strain or kind: colour scale with a legend\n"
            "      --no-legend            no legend for --colour-by\n"
            "dew (droplets on the capture spiral):\n"
            "      --dew                  bead the capture threads with water drops\n"
            "      --dew-spacing M        mean distance between drops [m] (default 0.006)\n"
            "      --dew-radius M         mean drop radius [m] (default 0.0013)\n"
            "      --dew-jitter F         relative spread of radii and gaps, 0..1 (default 0.35)\n"
            "      --dew-seed N           seed for the drops (default 1)\n");
}

/* A built-in scene; 0 or an exit code. */
static int load_scene(const char *cmd, const char *spec, spn_world **w)
{
    spn_status st;
    if (strncmp(spec, "orb", 3) == 0 && (spec[3] == '\0' || spec[3] == ':')) {
        spn_orb_scene_def od = spn_orb_scene_def_default();
        int rings = od.rings, radials = od.radials;
        if (spec[3] == ':' && !cli_size(cmd, "scene:orb:RINGSxRADIALS", spec + 4, 1000, &rings, &radials))
            return CLI_EXIT_USAGE;
        od.rings = rings;
        od.radials = radials;
        st = spn_scene_orb(NULL, &od, w);
    } else if (strcmp(spec, "chain") == 0) {
        st = spn_scene_chain(NULL, spn_v3(-0.5, 0, 0), spn_v3(0.5, 0, 0), 40, 1.2, 0.01, 100, 0.01, w);
    } else if (strcmp(spec, "cloth") == 0) {
        st = spn_scene_cloth(NULL, 20, 20, 1, 0, 0.1, 100, 0.01, 3, w);
    } else {
        return cli_usage(cmd, "unknown scene 'scene:%s' (scene:orb, scene:orb:RINGSxRADIALS, scene:chain, scene:cloth)",
                         spec);
    }
    return st == SPN_OK ? 0 : cli_fail(cmd, "scene:%s: %s", spec, spn_last_error());
}

int render_load_world(const char *cmd, const char *spec, spn_world **w)
{
    *w = NULL;
    if (strncmp(spec, "scene:", 6) == 0) return load_scene(cmd, spec + 6, w);
    if (spn_web_load(spec, w) != SPN_OK) return cli_fail(cmd, "%s", spn_last_error());
    return 0;
}
