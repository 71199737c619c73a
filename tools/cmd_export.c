/* spinneret export FILE... -o OUT | --frames DIR: write a web as OBJ, PLY,
 * a POV-Ray scene or a web file (.json or binary .spnw), or one POV scene per input file
 * (DIR/frame_%05d.pov, all framed alike: the film maker's output form). */
#include "render_options.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const CMD = "export";

static void usage(FILE *out)
{
    fprintf(out,
            "usage: spinneret export FILE -o OUT [options]\n"
            "       spinneret export FILE... --frames DIR [options]\n"
            "Write the web in FILE (a web file or scene:orb, ...) to OUT by its extension:\n"
            "  .obj  Wavefront OBJ: threads as polylines (l), an object and group per thread kind\n"
            "  .ply  ASCII PLY: threads as edges with a 'kind' property (the thread tag)\n"
            "  .pov  a complete POV-Ray 3.7 scene: povray +W800 +H800 OUT.pov renders it\n"
            "  .json a web file\n"
            "  .spnw a binary web file (the same content; fast for big webs)\n"
            "With --frames DIR, each FILE becomes DIR/frame_%%05d.pov, all framed by the\n"
            "bounding box of every FILE, ready to render into a film.\n\n"
            "  -o, --output OUT           the exported file\n"
            "      --frames DIR           one POV scene per FILE\n"
            "      --tubes R              OBJ/PLY: threads as tubes of radius R [m]\n"
            "      --sides N              tube sides, 3..64 (default 6)\n"
            "      --thread-radius R      POV: cylinder radius [m] (default: the rendered line width)\n"
            "      --quiet                no progress bar for --frames\n"
            "  -h, --help                 this text\n"
            "The picture options below set the POV camera, background, shades and dew;\n"
            "--dew also adds the drops to OBJ/PLY as spheres (group 'dew').\n");
    render_options_help(out);
}

typedef struct export_options {
    render_options ro;
    spn_export_def def;
    const char *out, *frames;
    bool quiet;
} export_options;

enum { OPT_FRAMES = 400, OPT_TUBES, OPT_SIDES, OPT_THREAD_RADIUS, OPT_QUIET };

static int parse_own(int c, const char *arg, export_options *o)
{
    long sides;
    switch (c) {
    case 'o': o->out = arg; return 1;
    case OPT_FRAMES: o->frames = arg; return 1;
    case OPT_QUIET: o->quiet = true; return 1;
    case OPT_TUBES: return cli_double(CMD, "--tubes", arg, 1e-9, 10, &o->def.tube_radius) ? 1 : -1;
    case OPT_SIDES:
        if (!cli_int(CMD, "--sides", arg, 3, 64, &sides)) return -1;
        o->def.tube_sides = (int)sides;
        return 1;
    case OPT_THREAD_RADIUS: return cli_double(CMD, "--thread-radius", arg, 1e-12, 10, &o->def.pov_thread_radius) ? 1 : -1;
    default: return 0;
    }
}

static int parse_one(int c, const char *arg, void *ctx)
{
    export_options *o = ctx;
    int r = parse_own(c, arg, o);
    return r != 0 ? r : render_options_parse(CMD, c, arg, &o->ro);
}

static int check_output(const export_options *o)
{
    if (o->out && o->frames) return cli_usage(CMD, "give either -o or --frames, not both");
    if (o->frames) return *o->frames ? -1 : cli_usage(CMD, "--frames: the folder is empty");
    if (!o->out || !*o->out) return cli_usage(CMD, "-o/--output (or --frames DIR) is required");
    const char *ext = cli_extension(o->out);
    if (strcmp(ext, "obj") && strcmp(ext, "ply") && strcmp(ext, "pov") && strcmp(ext, "json") && strcmp(ext, "spnw"))
        return cli_usage(CMD, "%s: unknown export type '.%s' (use .obj, .ply, .pov, .json or .spnw)", o->out, ext);
    return -1;
}

static int parse(int argc, char **argv, export_options *o)
{
    static const struct option options[] = {{"output", required_argument, NULL, 'o'},
                                            {"frames", required_argument, NULL, OPT_FRAMES},
                                            {"tubes", required_argument, NULL, OPT_TUBES},
                                            {"sides", required_argument, NULL, OPT_SIDES},
                                            {"thread-radius", required_argument, NULL, OPT_THREAD_RADIUS},
                                            {"quiet", no_argument, NULL, OPT_QUIET},
                                            {"help", no_argument, NULL, 'h'},
                                            RENDER_LONG_OPTIONS,
                                            {NULL, 0, NULL, 0}};
    int r = cli_parse_options(CMD, argc, argv, ":o:h", options, usage, parse_one, o);
    if (r >= 0) return r;
    if (optind >= argc) return cli_usage(CMD, "missing FILE");
    if (!o->frames && optind + 1 < argc) return cli_usage(CMD, "unexpected argument '%s'", argv[optind + 1]);
    return check_output(o);
}

static int export_one(export_options *o, const char *in)
{
    spn_world *w;
    int code = render_load_world(CMD, in, &w);
    if (code) return code;
    render_options_finish(&o->ro, w);
    if ((code = render_options_check(CMD, &o->ro)) >= 0) {
        spn_world_destroy(w);
        return code;
    }
    o->def.render = o->ro.def;
    const char *ext = cli_extension(o->out);
    spn_status st = strcmp(ext, "json") == 0 || strcmp(ext, "spnw") == 0 ? spn_web_save(w, o->out)
                                                                         : spn_export_file(w, &o->def, o->out);
    spn_world_destroy(w);
    return st == SPN_OK ? 0 : cli_fail_status(CMD, st);
}

/* The box around every input, so all frames share one camera. */
static int frame_bounds(char **files, int n, spn_vec3 *lo, spn_vec3 *hi)
{
    for (int i = 0; i < n; i++) {
        spn_world *w;
        int code = render_load_world(CMD, files[i], &w);
        if (code) return code;
        for (uint32_t p = 0; p < spn_world_particle_count(w); p++) {
            spn_vec3 x = spn_world_position(w, p);
            if (i == 0 && p == 0) *lo = *hi = x;
            *lo = spn_v3(fmin(lo->x, x.x), fmin(lo->y, x.y), fmin(lo->z, x.z));
            *hi = spn_v3(fmax(hi->x, x.x), fmax(hi->y, x.y), fmax(hi->z, x.z));
        }
        spn_world_destroy(w);
    }
    return 0;
}

static int export_frames(export_options *o, char **files, int n)
{
    spn_camera *cam = &o->ro.def.camera;
    if (!cam->fixed_bounds) {
        int code = frame_bounds(files, n, &cam->bounds_min, &cam->bounds_max);
        if (code) return code;
        cam->fixed_bounds = true;
    }
    spn_progress *bar = spn_progress_begin("export", (uint64_t)n, o->quiet);
    int i = 0;
    cli_interruptible((uint64_t)n);
    for (; i < n && !spn_interrupted(); i++) {
        spn_world *w;
        int code = render_load_world(CMD, files[i], &w);
        if (code) return spn_progress_end(bar), code;
        if (i == 0) render_options_finish(&o->ro, w); /* the first frame fixes a perspective camera */
        if (i == 0 && (code = render_options_check(CMD, &o->ro)) >= 0) {
            spn_world_destroy(w);
            spn_interrupt_graceful(false);
            return spn_progress_end(bar), code;
        }
        o->def.render = o->ro.def;
        spn_status st = spn_export_pov_frame(w, &o->def, o->frames, i);
        spn_world_destroy(w);
        if (st != SPN_OK) return spn_progress_end(bar), cli_fail_status(CMD, st);
        spn_progress_update(bar, (uint64_t)i + 1);
        spn_interrupt_progress((uint64_t)i + 1, (uint64_t)n);
    }
    spn_progress_end(bar);
    return cli_report_interrupt(CMD, (uint64_t)i, (uint64_t)n, "the complete frames are kept", 0);
}

int cmd_export(int argc, char **argv)
{
    export_options o;
    render_options_init(&o.ro);
    o.def = spn_export_def_default();
    o.out = o.frames = NULL;
    o.quiet = false;
    int code = parse(argc, argv, &o);
    if (code >= 0) return code;
    if (o.frames) return export_frames(&o, argv + optind, argc - optind);
    return export_one(&o, argv[optind]);
}
