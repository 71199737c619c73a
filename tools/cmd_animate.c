/* spinneret animate WEB -o OUT: a web in the thesis' wind, in turbulent air,
 * or struck by prey, rendered frame by frame to a video, a GIF or a folder of
 * PNGs (spn_animate does the physics, the render library the pictures).
 * The camera is fixed for the whole run (framed on the web at rest), so the
 * frames of --frame-range are the same bits as those of a whole run.
 * SIGINT/SIGTERM stop after the current step: finished PNG frames and state
 * files stay, a video or report being written is abandoned. */
#include "cli.h"
#include "frame_pipe.h"
#include "render_options.h"

#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static const char *const CMD = "animate";
#define MAX_IMPACTS 8

static void usage(FILE *out)
{
    fprintf(out,
            "usage: spinneret animate WEB -o OUT [options]\n"
            "Animate WEB (a web file, or scene:orb[:RINGSxRADIALS]) and write OUT: a .mp4, a .gif,\n"
            "or a folder of PNG frames "
            "(frame_00000.png, ...). Frame 0 is the web as loaded.\n\n"
            "  -o, --output OUT        the video, GIF or frame folder (required)\n"
            "      --duration S        seconds, in [0, 3600]; default 5\n"
            "      --fps N             frames per simulated second, in [1, 10000]; default 25\n"
            "      --playback-fps N    frames per second of the video, in [1, 240]; default --fps\n"
            "                          (--fps 400 --playback-fps 25: 16 times slow motion)\n"
            "      --solver NAME       euler, symplectic, rk4, adaptive or implicit; default: WEB's\n"
            "      --substeps N        steps per frame, in [1, 1e7]; default: stable for the solver\n"
            "      --solver-tol R      implicit: CG relative residual, in [1e-14, 0.5]; default the web's (1e-10)\n"
            "      --seed N            seeds the wind; default 1\n"
            "      --frame-range A-B   render frames A..B only (same bits as in a whole run)\n"
            "      --save-states DIR   also write each rendered frame's world as DIR/state_NNNNN.json\n"
            "      --quiet             no progress bar\n\n"
            "wind:\n"
            "      --wind MODEL        none, thesis (Mehla 2005 fig. 5.45) or air; default none\n"
            "      --thesis-mass KG    MASS in WIND = MASS*GRAVITY*GAIN; default 1e-8\n"
            "      --thesis-gain G     default 10\n"
            "      --thesis-random R   factors drawn from [-R, R]; default 3\n"
            "      --thesis-period N   counts between new factors; default 50\n"
            "      --thesis-tick S     simulated seconds per count; default 0.02\n"
            "      --thesis-radians    sin of the counter in radians (default: degrees)\n"
            "      --thesis-falloff F  distance scale alpha = radius * F; default 50\n"
            "      --wind-speed M/S    air: mean speed, in [0, 50]; default 1\n"
            "      --wind-dir X,Y,Z    air: mean direction; default 0,0,-1\n"
            "      --gust G            air: gust strength (std / mean), in [0, 1]; default 0.3\n"
            "      --turbulence T      air: rms turbulence / mean, in [0, 2]; default 0.15\n"
            "      --wind-stop S       air: the wind stops at this time [s]\n\n"
            "prey:\n"
            "      --impact \"X,Y,Z;VX,VY,VZ;MASS;RADIUS\"  a sphere flying into the web (repeatable, up to %d)\n"
            "      --report FILE.json  with --impact: outcome, energy per thread kind, threads broken\n"
            "      --no-breakage       threads never break\n"
            "      --glue N            capture glue strength per droplet [N], in [0, 1]; default 4e-5\n"
            "      --glue-outline F    the prey's sticky outline (legs, wings) in prey radii, in [1, 100];\n"
            "                          capture thread that near its centre glues to it; default 2.5\n"
            "      --prey-gravity      prey fall like pellets (default: they fly)\n\n",
            MAX_IMPACTS);
    render_options_help(out);
    fprintf(out, "  -h, --help              this text\n");
}

typedef struct animate_options {
    const char *input, *output, *report, *states;
    bool quiet;
    double playback_fps;
    spn_anim_def anim;
    render_options ro;
    spn_render_def render; /* ro.def once finished for the loaded web */
    spn_prey_def prey[MAX_IMPACTS];
} animate_options;

static bool frame_range(const char *arg, spn_anim_def *d)
{
    long a, b;
    char tail;
    if (sscanf(arg, "%ld-%ld%c", &a, &b, &tail) != 2 || a < 0 || b < a || b > 10000000) {
        cli_usage(CMD, "--frame-range: expected A-B with 0 <= A <= B, got '%s'", arg);
        return false;
    }
    d->first_frame = (int)a;
    d->last_frame = (int)b;
    return true;
}

static bool wind_model(const char *arg, spn_wind_kind *out)
{
    static const char *const names[] = {"none", "thesis", "air"};
    const int i = cli_choice(arg, names, 3);
    if (i >= 0) {
        *out = (spn_wind_kind)i;
        return true;
    }
    cli_usage(CMD, "--wind: unknown model '%s' (choose none, thesis or air)", arg);
    return false;
}

enum {
    OPT_DURATION = 256, OPT_FPS, OPT_SOLVER, OPT_SUBSTEPS, OPT_SEED, OPT_RANGE, OPT_STATES, OPT_QUIET, OPT_WIND,
    OPT_TMASS, OPT_TGAIN, OPT_TRANDOM, OPT_TPERIOD, OPT_TTICK, OPT_TRAD, OPT_TFALL, OPT_SPEED, OPT_DIR, OPT_GUST,
    OPT_TURB, OPT_STOP, OPT_IMPACT, OPT_REPORT, OPT_NOBREAK, OPT_GLUE, OPT_GLUE_OUTLINE, OPT_PGRAV, OPT_PLAYBACK, OPT_SOLVER_TOL
};

static bool sim_option(int c, const char *arg, animate_options *o)
{
    spn_anim_def *d = &o->anim;
    long n;
    switch (c) {
    case OPT_DURATION: return cli_double(CMD, "--duration", arg, 0, 3600, &d->duration);
    case OPT_FPS: return cli_double(CMD, "--fps", arg, 1, 10000, &d->fps);
    case OPT_PLAYBACK: return cli_double(CMD, "--playback-fps", arg, 1, 240, &o->playback_fps);
    case OPT_SOLVER:
        if (spn_integrator_parse(arg, &d->solver) == SPN_OK) return true;
        cli_usage(CMD, "--solver: %s", spn_last_error());
        return false;
    case OPT_SUBSTEPS:
        if (!cli_int(CMD, "--substeps", arg, 1, 10000000, &n)) return false;
        d->substeps = (int)n;
        return true;
    case OPT_SOLVER_TOL: return cli_double(CMD, "--solver-tol", arg, 1e-14, 0.5, &d->cg_tolerance);
    case OPT_SEED: return cli_u64(CMD, "--seed", arg, &d->seed);
    case OPT_RANGE: return frame_range(arg, d);
    case OPT_WIND: return wind_model(arg, &d->wind);
    case OPT_TMASS: return cli_double(CMD, "--thesis-mass", arg, 0, 1, &d->thesis.mass);
    case OPT_TGAIN: return cli_double(CMD, "--thesis-gain", arg, -1e6, 1e6, &d->thesis.gain);
    case OPT_TRANDOM: return cli_double(CMD, "--thesis-random", arg, 0, 1e3, &d->thesis.random_max);
    case OPT_TPERIOD:
        if (!cli_int(CMD, "--thesis-period", arg, 1, 1000000, &n)) return false;
        d->thesis.period = (int)n;
        return true;
    case OPT_TTICK: return cli_double(CMD, "--thesis-tick", arg, 1e-6, 10, &d->thesis.tick);
    case OPT_TRAD: d->thesis.radians = true; return true;
    case OPT_TFALL: return cli_double(CMD, "--thesis-falloff", arg, 1e-3, 1e6, &d->thesis.falloff);
    default: return false;
    }
}

static bool air_prey_option(int c, const char *arg, animate_options *o)
{
    spn_anim_def *d = &o->anim;
    switch (c) {
    case OPT_SPEED: return cli_double(CMD, "--wind-speed", arg, 0, 50, &d->air.speed);
    case OPT_DIR:
        if (!cli_vec3(CMD, "--wind-dir", arg, false, &d->air.direction)) return false;
        if (spn_v3_len(d->air.direction) > 0) return true;
        cli_usage(CMD, "--wind-dir: the direction must not be zero");
        return false;
    case OPT_GUST: return cli_double(CMD, "--gust", arg, 0, 1, &d->air.gust);
    case OPT_TURB: return cli_double(CMD, "--turbulence", arg, 0, 2, &d->air.turbulence);
    case OPT_STOP: return cli_double(CMD, "--wind-stop", arg, 0, 1e6, &d->wind_stop);
    case OPT_IMPACT:
        if (d->nprey == MAX_IMPACTS) {
            cli_usage(CMD, "--impact: at most %d", MAX_IMPACTS);
            return false;
        }
        if (spn_prey_parse(arg, &o->prey[d->nprey]) != SPN_OK) {
            cli_usage(CMD, "--impact: %s", spn_last_error());
            return false;
        }
        d->nprey++;
        return true;
    case OPT_NOBREAK: d->impact.breakage = false; return true;
    case OPT_GLUE: return cli_double(CMD, "--glue", arg, 0, 1, &d->impact.glue_strength);
    case OPT_GLUE_OUTLINE: return cli_double(CMD, "--glue-outline", arg, 1, 100, &d->impact.glue_outline);
    case OPT_PGRAV: d->impact.prey_gravity = true; return true;
    default: return false;
    }
}

static const struct option long_options[] = {
    {"output", required_argument, NULL, 'o'},    {"duration", required_argument, NULL, OPT_DURATION},
    {"playback-fps", required_argument, NULL, OPT_PLAYBACK},
    {"fps", required_argument, NULL, OPT_FPS},   {"solver", required_argument, NULL, OPT_SOLVER},
    {"substeps", required_argument, NULL, OPT_SUBSTEPS}, {"solver-tol", required_argument, NULL, OPT_SOLVER_TOL}, {"seed", required_argument, NULL, OPT_SEED},
    {"frame-range", required_argument, NULL, OPT_RANGE}, {"save-states", required_argument, NULL, OPT_STATES},
    {"quiet", no_argument, NULL, OPT_QUIET},     {"wind", required_argument, NULL, OPT_WIND},
    {"thesis-mass", required_argument, NULL, OPT_TMASS}, {"thesis-gain", required_argument, NULL, OPT_TGAIN},
    {"thesis-random", required_argument, NULL, OPT_TRANDOM},
    {"thesis-period", required_argument, NULL, OPT_TPERIOD}, {"thesis-tick", required_argument, NULL, OPT_TTICK},
    {"thesis-radians", no_argument, NULL, OPT_TRAD}, {"thesis-falloff", required_argument, NULL, OPT_TFALL},
    {"wind-speed", required_argument, NULL, OPT_SPEED}, {"wind-dir", required_argument, NULL, OPT_DIR},
    {"gust", required_argument, NULL, OPT_GUST}, {"turbulence", required_argument, NULL, OPT_TURB},
    {"wind-stop", required_argument, NULL, OPT_STOP}, {"impact", required_argument, NULL, OPT_IMPACT},
    {"report", required_argument, NULL, OPT_REPORT}, {"no-breakage", no_argument, NULL, OPT_NOBREAK},
    {"glue", required_argument, NULL, OPT_GLUE}, {"glue-outline", required_argument, NULL, OPT_GLUE_OUTLINE},
    {"prey-gravity", no_argument, NULL, OPT_PGRAV},
    RENDER_LONG_OPTIONS,
    {"help", no_argument, NULL, 'h'},            {NULL, 0, NULL, 0}};

/* Fills `o` from argv; returns -1 to go on, else the exit code. */
static int parse_options(int argc, char **argv, animate_options *o)
{
    opterr = 0;
    for (int c; (c = getopt_long(argc, argv, ":o:h", long_options, NULL)) != -1;) {
        bool ok = true;
        switch (c) {
        case 'o': o->output = optarg; break;
        case 'h': usage(stdout); return 0;
        case OPT_STATES: o->states = optarg; break;
        case OPT_QUIET: o->quiet = true; break;
        case OPT_REPORT: o->report = optarg; break;
        case ':': return cli_usage(CMD, "%s: missing value", argv[optind - 1]);
        case '?': return cli_usage(CMD, "unknown option '%s'", argv[optind - 1]);
        default: {
            int r = render_options_parse(CMD, c, optarg, &o->ro);
            if (r < 0) ok = false;
            else if (r == 0) ok = sim_option(c, optarg, o) || (c >= OPT_SPEED && air_prey_option(c, optarg, o));
        }
        }
        if (!ok) return CLI_EXIT_USAGE;
    }
    if (optind != argc - 1) return cli_usage(CMD, optind >= argc ? "missing WEB file" : "one WEB file expected");
    o->input = argv[optind];
    if (!o->output) return cli_usage(CMD, "missing -o OUT");
    if (o->report && o->anim.nprey == 0) return cli_usage(CMD, "--report needs at least one --impact");
    o->anim.prey = o->prey;
    return -1;
}

/* ---- the run ------------------------------------------------------------ */

static volatile sig_atomic_t stop_flag;
static void on_signal(int sig)
{
    (void)sig;
    stop_flag = 1;
}

typedef struct frame_ctx {
    animate_options *o;
    spn_frames *frames;
    spn_progress *bar;
    frame_pipe *pipe;
} frame_ctx;

/* Where the camera puts world point p, and how many pixels a metre there is. */
static bool project(const spn_render_def *d, spn_vec3 p, double *px, double *py, double *scale)
{
    const spn_camera *c = &d->camera;
    if (c->kind == SPN_CAMERA_PERSPECTIVE) {
        spn_vec3 fwd = spn_v3_norm(spn_v3_sub(c->target, c->eye));
        spn_vec3 up = spn_v3_len(c->up) > 0 ? c->up : spn_v3(0, 1, 0);
        spn_vec3 right = spn_v3_norm(spn_v3_cross(fwd, up)), cup = spn_v3_cross(right, fwd);
        spn_vec3 r = spn_v3_sub(p, c->eye);
        double z = spn_v3_dot(r, fwd), focal = 0.5 * d->height / tan(0.5 * c->fov_degrees * SPN_PI / 180);
        if (!(z > 1e-9)) return false;
        *px = 0.5 * d->width + focal * spn_v3_dot(r, right) / z;
        *py = 0.5 * d->height - focal * spn_v3_dot(r, cup) / z;
        *scale = focal / z;
        return true;
    }
    /* Front camera with fixed bounds: the same framing as the renderer's. */
    spn_vec3 lo = c->bounds_min, hi = c->bounds_max;
    double bw = fmax(hi.x - lo.x, 1e-9), bh = fmax(hi.y - lo.y, 1e-9), m = c->margin;
    *scale = fmin(d->width * (1 - 2 * m) / bw, d->height * (1 - 2 * m) / bh);
    *px = 0.5 * d->width + *scale * (p.x - 0.5 * (lo.x + hi.x));
    *py = 0.5 * d->height - *scale * (p.y - 0.5 * (lo.y + hi.y));
    return true;
}

/* The prey as an anti-aliased dark amber disk with a lighter rim. */
static void draw_disk(uint8_t *rgba, int w, int h, double cx, double cy, double r)
{
    static const double body[3] = {70, 45, 20}, rim[3] = {200, 150, 60};
    int x0 = (int)fmax(0, floor(cx - r - 1)), x1 = (int)fmin(w - 1, ceil(cx + r + 1));
    int y0 = (int)fmax(0, floor(cy - r - 1)), y1 = (int)fmin(h - 1, ceil(cy + r + 1));
    for (int y = y0; y <= y1; y++)
        for (int x = x0; x <= x1; x++) {
            double d = hypot(x + 0.5 - cx, y + 0.5 - cy), cover = fmin(1, fmax(0, r + 0.5 - d));
            if (cover <= 0) continue;
            double edge = fmin(1, fmax(0, d - (r - 2.5)));
            uint8_t *q = rgba + 4 * ((size_t)y * w + x);
            for (int k = 0; k < 3; k++) {
                double col = body[k] + (rim[k] - body[k]) * edge;
                q[k] = (uint8_t)lround(q[k] + (col - q[k]) * cover);
            }
            q[3] = (uint8_t)lround(q[3] + (255 - q[3]) * cover);
        }
}

static void draw_prey(const frame_ctx *c, const spn_world *w, uint8_t *rgba)
{
    int k = 0;
    for (uint32_t i = 0; i < spn_world_particle_count(w) && k < c->o->anim.nprey; i++) {
        if (spn_world_particle_tag(w, i) != SPN_PARTICLE_PREY) continue;
        double px, py, scale;
        if (project(&c->o->render, spn_world_position(w, i), &px, &py, &scale))
            draw_disk(rgba, c->o->render.width, c->o->render.height, px, py, fmax(1.5, c->o->prey[k].radius * scale));
        k++;
    }
}

/* Draw one frame (on a frame pipe thread, from a copy; the pipe writes it). */
static spn_status draw_frame(void *user, int slot, int frame, const spn_world *w, uint8_t *rgba)
{
    (void)slot, (void)frame;
    const frame_ctx *c = user;
    spn_status st = spn_render_rgba(w, &c->o->render, rgba);
    if (st == SPN_OK) draw_prey(c, w, rgba);
    return st;
}

static spn_status on_frame(void *user, int frame, const spn_world *w)
{
    frame_ctx *c = user;
    spn_status st = SPN_OK;
    if (c->o->states) {
        size_t n = strlen(c->o->states) + 32;
        char *path = malloc(n);
        if (!path) return spn_error(SPN_ERR_NOMEM, "out of memory");
        snprintf(path, n, "%s/state_%05d.json", c->o->states, frame);
        st = spn_web_save(w, path);
        free(path);
    }
    return st == SPN_OK ? frame_pipe_push(c->pipe, frame, w) : st;
}

static void on_progress(void *user, int frame, int frames)
{
    (void)frames;
    spn_progress_update(((frame_ctx *)user)->bar, (uint64_t)frame + 1);
}

/* Fix the camera on the web at rest, with room for it to billow and swing. */
static void fix_camera(spn_render_def *d, const spn_world *w)
{
    if (d->camera.kind == SPN_CAMERA_PERSPECTIVE) return;
    spn_vec3 lo = spn_v3(INFINITY, INFINITY, INFINITY), hi = spn_v3(-INFINITY, -INFINITY, -INFINITY);
    for (uint32_t i = 0; i < spn_world_particle_count(w); i++) {
        spn_vec3 p = spn_world_position(w, i);
        lo = spn_v3(fmin(lo.x, p.x), fmin(lo.y, p.y), fmin(lo.z, p.z));
        hi = spn_v3(fmax(hi.x, p.x), fmax(hi.y, p.y), fmax(hi.z, p.z));
    }
    if (!(lo.x <= hi.x)) lo = hi = spn_v3(0, 0, 0);
    spn_vec3 pad = spn_v3_scale(spn_v3_sub(hi, lo), 0.04);
    d->camera.fixed_bounds = true;
    d->camera.bounds_min = spn_v3_sub(lo, pad);
    d->camera.bounds_max = spn_v3_add(hi, pad);
}

static spn_status write_report(const char *path, const spn_impact_report *r)
{
    spn_atomic_file f;
    spn_status st = spn_atomic_open(&f, path, true);
    if (st != SPN_OK) return st;
    spn_sink sink = spn_sink_file(f.fp);
    st = spn_impact_report_write(r, &sink);
    if (st != SPN_OK) {
        spn_atomic_abort(&f);
        return st;
    }
    return spn_atomic_commit(&f);
}

static spn_status prepare(animate_options *o, spn_world **w, frame_ctx *c)
{
    render_options_finish(&o->ro, *w);
    o->render = o->ro.def;
    fix_camera(&o->render, *w);
    spn_status st;
    st = spn_render_def_check(&o->render);
    if (st != SPN_OK) return st;
    int frames = spn_anim_frame_count(&o->anim);
    if (o->anim.last_frame >= frames)
        return spn_error(SPN_ERR_INVALID, "--frame-range ends at %d but the run has frames 0..%d", o->anim.last_frame,
                         frames - 1);
    if (o->states && mkdir(o->states, 0777) != 0 && errno != EEXIST)
        return spn_error(SPN_ERR_IO, "%s: cannot create the folder: %s", o->states, strerror(errno));
    double rate = o->playback_fps > 0 ? o->playback_fps : fmin(o->anim.fps, 240);
    st = spn_frames_open(o->output, o->render.width, o->render.height, rate, &c->frames);
    if (st == SPN_OK) spn_frames_set_first_index(c->frames, o->anim.first_frame);
    if (st == SPN_OK) st = frame_pipe_open(&c->pipe, c->frames, frame_pipe_threads(frames), draw_frame, c);
    return st;
}

/* From this many explicit steps a frame (at 25 fps, steps under 4 us: a web
 * of real silk, 145,000 for the README's Araneus web) the run is told that
 * the implicit solver's 2 ms steps exist: it took 110 s of CPU per simulated
 * second on symplectic Euler, 0.6 s on the implicit solver
 * (docs/wind-and-prey.md, "What it costs"). */
#define HINT_STEPS 10000

static void hint_solver(const animate_options *o, const spn_world *w)
{
    const spn_integrator s = o->anim.solver != SPN_INTEGRATOR_COUNT ? o->anim.solver : spn_world_get_def(w)->integrator;
    if (o->quiet || o->anim.substeps > 0 || s == SPN_INTEGRATOR_IMPLICIT || s == SPN_INTEGRATOR_ADAPTIVE) return;
    const int n = spn_anim_stable_substeps(w, o->anim.fps, s, 0);
    if (n < HINT_STEPS) return;
    fprintf(stderr,
            "spinneret %s: %s takes %d steps a frame on this web (its threads are stiff for their mass); "
            "--solver implicit takes %d\n",
            CMD, spn_integrator_name(s), n, spn_anim_stable_substeps(w, o->anim.fps, SPN_INTEGRATOR_IMPLICIT, 0));
}

static int animate_run(animate_options *o)
{
    spn_world *w = NULL;
    int code = render_load_world(CMD, o->input, &w);
    if (code) return code;
    frame_ctx c = {o, NULL, NULL, NULL};
    spn_status st = prepare(o, &w, &c);
    if (st == SPN_OK) hint_solver(o, w);
    spn_anim_report rep;
    memset(&rep, 0, sizeof rep);
    if (st == SPN_OK) {
        struct sigaction sa, old_int, old_term;
        memset(&sa, 0, sizeof sa);
        sa.sa_handler = on_signal;
        sigaction(SIGINT, &sa, &old_int);
        sigaction(SIGTERM, &sa, &old_term);
        int frames = spn_anim_frame_count(&o->anim);
        int last = o->anim.last_frame < 0 ? frames - 1 : o->anim.last_frame;
        c.bar = spn_progress_begin("animate", (uint64_t)last + 1, o->quiet);
        o->anim.stop = &stop_flag;
        o->anim.progress = on_progress;
        o->anim.progress_user = &c;
        st = spn_animate(&w, &o->anim, on_frame, &c, &rep);
        /* the last frame is still being written */
        spn_status pipe_st = frame_pipe_close(c.pipe, NULL);
        c.pipe = NULL;
        if (st == SPN_OK) st = pipe_st;
        spn_progress_end(c.bar);
        sigaction(SIGINT, &old_int, NULL);
        sigaction(SIGTERM, &old_term, NULL);
    }
    bool done = st == SPN_OK && !rep.interrupted;
    /* Interrupted, the complete frames are kept (a shorter video), as every
     * other frame-writing command does; the report needs the whole run. */
    frame_pipe_close(c.pipe, NULL); /* when prepare failed after opening it */
    spn_status close_st = spn_frames_close(c.frames, st == SPN_OK && rep.frames > 0);
    if (st == SPN_OK) st = close_st;
    if (done && st == SPN_OK && o->report) st = write_report(o->report, &rep.impact);
    spn_world_destroy(w);
    if (rep.interrupted) {
        fprintf(stderr, "spinneret %s: interrupted; %d frame(s) finished and kept%s\n", CMD, rep.frames,
                o->report ? ", no report written" : "");
        return 130;
    }
    if (st != SPN_OK) return cli_fail_status(CMD, st);
    if (rep.has_impact && !o->quiet)
        fprintf(stderr, "prey: %s, %u thread(s) broken, %.3g of %.3g J absorbed\n",
                spn_prey_outcome_name(rep.impact.outcome[0]), rep.impact.breaks,
                rep.impact.prey_kinetic_start - rep.impact.prey_kinetic_end, rep.impact.prey_kinetic_start);
    return 0;
}

int cmd_animate(int argc, char **argv)
{
    animate_options o;
    memset(&o, 0, sizeof o);
    o.anim = spn_anim_def_default();
    render_options_init(&o.ro);
    int code = parse_options(argc, argv, &o);
    if (code >= 0) return code;
    return animate_run(&o);
}
