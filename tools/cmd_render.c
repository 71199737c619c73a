/* spinneret render FILE -o OUT: draw a web to PNG, SVG or PDF with cairo
 * (spn_render_file). With --turntable N, a perspective camera circles the web
 * and the frames go to a video or a PNG folder (spn_frames_*). The picture
 * options are shared with `export` (render_options.h). */
#include "frame_pipe.h"
#include "render_options.h"

#include <stdio.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

static const char *const CMD = "render";

static void usage(FILE *out)
{
    fprintf(out,
            "usage: spinneret render FILE -o OUT [options]\n"
            "       spinneret render FILE -o OUT.mp4|OUT.gif|DIR --turntable N [options]\n"
            "Draw the web in FILE (a web file, or scene:orb, scene:orb:RINGSxRADIALS,\n"
            "scene:chain, scene:cloth) to OUT: .png, .svg or .pdf. Same file and options,\n"
            "same pixels.\n\n"
            "  -o, --output OUT           the picture (required)\n"
            "      --turntable N          N frames of a camera swinging around the web, to .mp4\n"
            "                             or .gif (needs the ffmpeg program) or a folder of PNGs\n"
            "      --fps F                turntable frames per second, 1..120 (default 24)\n"
            "      --quiet                no progress bar\n"
            "  -h, --help                 this text\n");
    render_options_help(out);
}

typedef struct cmd_options {
    render_options ro;
    const char *in, *out;
    long turntable;
    double fps;
    bool quiet;
} cmd_options;

enum { OPT_TURNTABLE = 400, OPT_FPS, OPT_QUIET };

static int parse_one(int c, const char *arg, void *ctx)
{
    cmd_options *o = ctx;
    switch (c) {
    case 'o': o->out = arg; return 1;
    case OPT_TURNTABLE: return cli_int(CMD, "--turntable", arg, 1, 100000, &o->turntable) ? 1 : -1;
    case OPT_FPS: return cli_double(CMD, "--fps", arg, 1, 120, &o->fps) ? 1 : -1;
    case OPT_QUIET: o->quiet = true; return 1;
    default: return render_options_parse(CMD, c, arg, &o->ro);
    }
}

static int check_output(const cmd_options *o)
{
    if (!o->out || !*o->out) return cli_usage(CMD, "-o/--output: the output picture is required");
    const char *ext = cli_extension(o->out);
    if (o->turntable > 0) {
        if (*ext && strcmp(ext, "mp4") != 0 && strcmp(ext, "gif") != 0)
            return cli_usage(CMD, "%s: a turntable goes to .mp4, .gif or a folder, not '.%s'", o->out, ext);
        return -1;
    }
    if (strcmp(ext, "png") != 0 && strcmp(ext, "svg") != 0 && strcmp(ext, "pdf") != 0)
        return cli_usage(CMD, "%s: unknown output type '.%s' (use .png, .svg or .pdf)", o->out, ext);
    return -1;
}

static int parse(int argc, char **argv, cmd_options *o)
{
    static const struct option options[] = {{"output", required_argument, NULL, 'o'},
                                            {"turntable", required_argument, NULL, OPT_TURNTABLE},
                                            {"fps", required_argument, NULL, OPT_FPS},
                                            {"quiet", no_argument, NULL, OPT_QUIET},
                                            {"help", no_argument, NULL, 'h'},
                                            RENDER_LONG_OPTIONS,
                                            {NULL, 0, NULL, 0}};
    int r = cli_parse_options(CMD, argc, argv, ":o:h", options, usage, parse_one, o);
    if (r >= 0) return r;
    if (optind >= argc) return cli_usage(CMD, "missing FILE");
    if (optind + 1 < argc) return cli_usage(CMD, "unexpected argument '%s'", argv[optind + 1]);
    o->in = argv[optind];
    return check_output(o);
}

typedef struct turntable_job {
    const cmd_options *o;
    const spn_world *w;
    double swing;
} turntable_job;

/* Frame i of the turntable (frame_pipe_fn: any thread; the web is only
 * read). The camera swings from -yaw to +yaw and back (a planar web seen
 * edge-on shows nothing, so it does not go all the way round). */
static spn_status turntable_frame(void *user, int slot, int i, const spn_world *none, uint8_t *rgba)
{
    (void)slot, (void)none;
    const turntable_job *j = user;
    spn_render_def d = j->o->ro.def;
    double yaw = j->swing * sin(2 * SPN_PI * (double)i / (double)j->o->turntable);
    spn_camera cam = spn_camera_orbit(j->w, yaw, j->o->ro.pitch, d.camera.fov_degrees);
    d.camera.eye = cam.eye;
    d.camera.target = cam.target;
    return spn_render_rgba(j->w, &d, rgba);
}

static int turntable(cmd_options *o, const spn_world *w)
{
    spn_render_def *d = &o->ro.def;
    d->camera.kind = SPN_CAMERA_PERSPECTIVE;
    spn_frames *frames;
    if (spn_frames_open(o->out, d->width, d->height, o->fps, &frames) != SPN_OK)
        return cli_fail(CMD, "%s", spn_last_error());
    const int count = (int)o->turntable;
    spn_progress *bar = spn_progress_begin("render", (uint64_t)count, o->quiet);
    turntable_job job = {o, w, o->ro.yaw != 0 ? o->ro.yaw : 25};
    int done = 0;
    cli_interruptible((uint64_t)count);
    spn_status st = frame_pipe_run(frames, count, turntable_frame, &job, bar, &done);
    spn_progress_end(bar);
    if (st != SPN_OK) {
        spn_interrupt_graceful(false);
        spn_frames_close(frames, false);
        return cli_fail_status(CMD, st);
    }
    /* Interrupted or not, the complete frames are kept (a shorter video). */
    int code = spn_frames_close(frames, true) == SPN_OK ? 0 : cli_fail(CMD, "%s", spn_last_error());
    return cli_report_interrupt(CMD, (uint64_t)done, (uint64_t)count,
                                code ? "nothing kept" : "the complete frames are kept", code);
}

int cmd_render(int argc, char **argv)
{
    cmd_options o;
    memset(&o, 0, sizeof o);
    render_options_init(&o.ro);
    o.fps = 24;
    int code = parse(argc, argv, &o);
    if (code >= 0) return code;
    spn_world *w;
    if ((code = render_load_world(CMD, o.in, &w)) != 0) return code;
    render_options_finish(&o.ro, w);
    if ((code = render_options_check(CMD, &o.ro)) >= 0) {
        spn_world_destroy(w);
        return code;
    }
    if (o.turntable > 0) {
        code = turntable(&o, w);
    } else {
        spn_status st = spn_render_file(w, &o.ro.def, o.out);
        code = st == SPN_OK ? 0 : cli_fail_status(CMD, st);
    }
    spn_world_destroy(w);
    spn_render_release_caches();
    return code;
}
