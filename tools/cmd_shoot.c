/* spinneret shoot --from X,Y,Z --to X,Y,Z -o OUT: fire a web-shooting strand
 * (spn_shot, include/spinneret/shoot.h) and record it at a fixed frame rate.
 * OUT .json: the polyline, phase, character and camera shake of every frame,
 * for other tools. OUT .mp4/.gif or a folder: rendered frames from a 3D
 * perspective camera that frames the whole shot, with the character as a
 * marker and a faint ground grid; the camera shakes with the shot's shake.
 * Every shot parameter is an option, each with its range. */
#include "cmd_shoot.h"

#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const CMD = "shoot";

/* A numeric option bound to a field of the definition. */
typedef struct num_opt {
    const char *name;
    double *field;
    double lo, hi;
    const char *help;
} num_opt;

typedef struct shoot_options {
    spn_shot_def def;
    const char *output;
    bool have_from, have_to;
    double max_time, points, hills;
    video_options video;
} shoot_options;

enum { NUM_OPTS = 27 };

static void bind_numbers(shoot_options *o, num_opt *t)
{
    spn_shot_def *d = &o->def;
    const num_opt table[NUM_OPTS] = {
        {"speed", &d->speed, 0.01, 1e5, "launch speed [m/s]"},
        {"noise", &d->noise_amplitude, 0, 0.5, "noise amplitude, fraction of the distance"},
        {"hills", &o->hills, 2, 16, "random points per noise curve (2: one hill)"},
        {"points", &o->points, 4, 1024, "strand resolution (polyline points)"},
        {"blend", &d->blend, 0, 0.95, "velocity factor: 0 pure pull, higher carries on"},
        {"taut", &d->taut, 0.5, 1, "THWAP: taut length / distance"},
        {"wave-speed", &d->wave_speed, 0.1, 1e4, "THWAP: recoil wave speed [m/s]"},
        {"snap-time", &d->snap_time, 0, 10, "THWAP: time a stretch takes to tighten [s]"},
        {"hold-time", &d->hold_time, 0, 10, "THWAP: hold after the wave reaches the hand [s]"},
        {"shake", &d->shake_amplitude, 0, 1e3, "camera shake at contact"},
        {"shake-decay", &d->shake_decay, 1e-3, 10, "camera shake time constant [s]"},
        {"density", &d->linear_density, 1e-4, 10, "strand mass per length [kg/m]"},
        {"damping", &d->damping_ratio, 0, 1, "segment damping, fraction of critical"},
        {"wave-damping", &d->wave_damping, 0, 1000, "damping of ringing [1/s]"},
        {"sway-damping", &d->sway_damping, 0, 1000, "damping relative to a rigid swing [1/s]"},
        {"mass", &d->character_mass, 0.1, 1e4, "WHOOSH: character mass [kg]"},
        {"stretch", &d->stretch, 0.005, 0.5, "WHOOSH: strain under the character's weight"},
        {"follow-through", &d->follow_through, 0, 1, "WHOOSH: release after regaining this part of the drop"},
        {"swing-time", &d->whoosh_max_time, 0, 60, "WHOOSH: release at the latest after [s]"},
        {"zipp-time", &d->zipp_time, 0, 60, "ZIPP: the strand is gone after [s]"},
        {"slack", &d->slack, 0, 2, "ZIPP: rest length grows by this fraction"},
        {"air-drag", &d->air_drag, 0, 100, "ZIPP: air drag [1/s]"},
        {"fps", &o->video.fps, 1, 240, "frames per second"},
        {"max-time", &o->max_time, 0.1, 600, "stop recording after [s]"},
        {NULL, NULL, 0, 0, NULL},
    };
    memcpy(t, table, sizeof table);
}

static void usage(FILE *out)
{
    shoot_options o;
    memset(&o, 0, sizeof o);
    o.def = spn_shot_def_default();
    o.video.fps = 60, o.max_time = 30, o.points = o.def.points, o.hills = o.def.noise_points;
    num_opt t[NUM_OPTS];
    bind_numbers(&o, t);
    fprintf(out, "usage: spinneret shoot --from X,Y,Z --to X,Y,Z -o OUT [options]\n"
                 "Shoot a web strand: THWIP (flight), THWAP (snap taut), WHOOSH (swing), ZIPP (release).\n"
                 "OUT: .json (every frame's polyline), .mp4, .gif, or a folder of PNG frames.\n\n"
                 "  -o, --output OUT           required\n"
                 "      --from X,Y,Z           the hand [m] (required)\n"
                 "      --to X,Y,Z             the target [m] (required)\n"
                 "      --phases thwip|all     stop at contact, or play all four; default all\n"
                 "      --auto-speed           out of reach: use the least speed that reaches\n"
                 "      --seed N               noise seed; default 1\n"
                 "      --gravity X,Y,Z        [m/s^2]; default 0,-9.81,0\n"
                 "      --velocity X,Y,Z       WHOOSH: character velocity at the swing [m/s]; default 0,0,0\n"
                 "      --drift X,Y,Z          ZIPP: air velocity [m/s]; default 0,0,1\n"
                 "      --size WxH             video frame size, sides in [1, 4096]; default 960x540\n"
                 "      --eye X,Y,Z            video: camera position [m]; default: framing the shot\n"
                 "      --look-at X,Y,Z        video: the point looked at [m]; default: the shot's centre\n"
                 "      --quiet                no progress bar\n");
    for (const num_opt *n = t; n->name; n++) {
        char name[32];
        snprintf(name, sizeof name, "%s V", n->name);
        fprintf(out, "      --%-20s %s, in [%g, %g]; default %g\n", name, n->help, n->lo, n->hi, *n->field);
    }
    fprintf(out, "  -h, --help                 this text\n");
}

enum { OPT_FROM = 256, OPT_TO, OPT_PHASES, OPT_AUTO, OPT_SEED, OPT_GRAVITY, OPT_VELOCITY, OPT_DRIFT, OPT_SIZE,
       OPT_QUIET, OPT_EYE, OPT_LOOK, OPT_NUM };

static int parse_other(int c, const char *arg, shoot_options *o)
{
    bool ok = true;
    switch (c) {
    case 'o': o->output = arg; break;
    case OPT_FROM: ok = o->have_from = cli_vec3_bounded(CMD, "--from", arg, CLI_MAX_COORD, &o->def.origin); break;
    case OPT_TO: ok = o->have_to = cli_vec3_bounded(CMD, "--to", arg, CLI_MAX_COORD, &o->def.target); break;
    case OPT_AUTO: o->def.auto_speed = true; break;
    case OPT_QUIET: o->video.quiet = true; break;
    case OPT_EYE: ok = o->video.have_eye = cli_vec3_bounded(CMD, "--eye", arg, CLI_MAX_COORD, &o->video.eye); break;
    case OPT_LOOK: ok = o->video.have_look = cli_vec3_bounded(CMD, "--look-at", arg, CLI_MAX_COORD, &o->video.look); break;
    case OPT_SEED: ok = cli_u64(CMD, "--seed", arg, &o->def.seed); break;
    case OPT_GRAVITY: ok = cli_vec3_bounded(CMD, "--gravity", arg, CLI_MAX_ACCEL, &o->def.gravity); break;
    case OPT_VELOCITY: ok = cli_vec3_bounded(CMD, "--velocity", arg, CLI_MAX_SPEED, &o->def.character_velocity); break;
    case OPT_DRIFT: ok = cli_vec3_bounded(CMD, "--drift", arg, CLI_MAX_SPEED, &o->def.drift); break;
    case OPT_SIZE: ok = cli_size(CMD, "--size", arg, 4096, &o->video.width, &o->video.height); break;
    case OPT_PHASES:
        if (strcmp(arg, "thwip") == 0) o->def.all_phases = false;
        else if (strcmp(arg, "all") == 0) o->def.all_phases = true;
        else return cli_usage(CMD, "--phases: expected thwip or all, got '%s'", arg), -1;
        break;
    default: return 0;
    }
    return ok ? 1 : -1;
}

typedef struct shoot_parse {
    shoot_options *o;
    const num_opt *t;
} shoot_parse;

/* One option (cli_option_fn): a number from the table, or one of the others. */
static int parse_one(int c, const char *arg, void *ctx)
{
    shoot_parse *p = ctx;
    if (c < OPT_NUM || c >= OPT_NUM + NUM_OPTS) return parse_other(c, arg, p->o);
    const num_opt *n = &p->t[c - OPT_NUM];
    char name[40];
    snprintf(name, sizeof name, "--%s", n->name);
    return cli_double(CMD, name, arg, n->lo, n->hi, n->field) ? 1 : -1;
}

/* Fills `o` from argv; returns -1 to go on, else the exit code. */
static int parse_options(int argc, char **argv, shoot_options *o)
{
    num_opt t[NUM_OPTS];
    bind_numbers(o, t);
    struct option options[NUM_OPTS + 16] = {
        {"output", required_argument, NULL, 'o'},      {"from", required_argument, NULL, OPT_FROM},
        {"to", required_argument, NULL, OPT_TO},         {"phases", required_argument, NULL, OPT_PHASES},
        {"auto-speed", no_argument, NULL, OPT_AUTO},     {"seed", required_argument, NULL, OPT_SEED},
        {"gravity", required_argument, NULL, OPT_GRAVITY}, {"velocity", required_argument, NULL, OPT_VELOCITY},
        {"drift", required_argument, NULL, OPT_DRIFT},   {"size", required_argument, NULL, OPT_SIZE},
        {"quiet", no_argument, NULL, OPT_QUIET},         {"help", no_argument, NULL, 'h'},
        {"eye", required_argument, NULL, OPT_EYE},       {"look-at", required_argument, NULL, OPT_LOOK},
    };
    int k = 14;
    for (int i = 0; t[i].name; i++) options[k++] = (struct option){t[i].name, required_argument, NULL, OPT_NUM + i};
    options[k] = (struct option){NULL, 0, NULL, 0};
    shoot_parse p = {o, t};
    int r = cli_parse_options(CMD, argc, argv, ":o:h", options, usage, parse_one, &p);
    if (r >= 0) return r;
    if (optind < argc) return cli_usage(CMD, "unexpected argument '%s'", argv[optind]);
    if (!o->have_from) return cli_usage(CMD, "--from: the hand position is required");
    if (!o->have_to) return cli_usage(CMD, "--to: the target position is required");
    if (!o->output || !*o->output) return cli_usage(CMD, "-o/--output: the output is required");
    if (o->video.have_eye && o->video.have_look &&
        spn_v3_len(spn_v3_sub(o->video.eye, o->video.look)) < 1e-9)
        return cli_usage(CMD, "--eye and --look-at must differ");
    if (o->points != floor(o->points)) return cli_usage(CMD, "--points: expected a whole number, got %g", o->points);
    if (o->hills != floor(o->hills)) return cli_usage(CMD, "--hills: expected a whole number, got %g", o->hills);
    o->def.points = (int)o->points;
    o->def.noise_points = (int)o->hills;
    return -1;
}

static bool grow(recording *r)
{
    uint32_t cap = r->cap ? 2 * r->cap : 256;
    void *p[7] = {realloc(r->strand, (size_t)cap * r->n * sizeof *r->strand),
                  realloc(r->character, cap * sizeof *r->character), realloc(r->t, cap * sizeof *r->t),
                  realloc(r->alpha, cap * sizeof *r->alpha), realloc(r->shake, cap * sizeof *r->shake),
                  realloc(r->count, cap * sizeof *r->count), realloc(r->phase, cap * sizeof *r->phase)};
    if (p[0]) r->strand = p[0];
    if (p[1]) r->character = p[1];
    if (p[2]) r->t = p[2];
    if (p[3]) r->alpha = p[3];
    if (p[4]) r->shake = p[4];
    if (p[5]) r->count = p[5];
    if (p[6]) r->phase = p[6];
    for (int i = 0; i < 7; i++)
        if (!p[i]) return false;
    r->cap = cap;
    return true;
}

static void record_frame(recording *r, const spn_shot *s)
{
    uint32_t f = r->frames++;
    const spn_vec3 *p;
    r->count[f] = spn_shot_strand(s, &p);
    memcpy(r->strand + (size_t)f * r->n, p, r->n * sizeof *p);
    r->character[f] = spn_shot_character(s);
    r->t[f] = spn_shot_time(s);
    r->alpha[f] = spn_shot_strand_alpha(s);
    r->shake[f] = spn_shot_camera_shake(s);
    r->phase[f] = spn_shot_phase_now(s);
}

static void recording_free(recording *r)
{
    free(r->strand);
    free(r->character);
    free(r->t);
    free(r->alpha);
    free(r->shake);
    free(r->count);
    free(r->phase);
}

/* Run the shot to its end (or max_time) and keep every frame. */
static int record(const shoot_options *o, spn_shot *s, recording *r)
{
    r->n = (uint32_t)o->def.points;
    const uint32_t limit = (uint32_t)ceil(o->max_time * o->video.fps) + 1;
    for (uint32_t k = 0; k < limit; k++) {
        if ((size_t)(r->frames + 1) * r->n > 20000000u)
            return cli_fail(CMD, "more than 2e7 recorded points by frame %u: lower --fps, --points or --max-time", k);
        if (r->frames == r->cap && !grow(r)) return cli_fail(CMD, "out of memory recording frame %u", k);
        if (k > 0) {
            spn_status st = spn_shot_step(s, 1.0 / o->video.fps);
            if (st != SPN_OK) return cli_fail_status(CMD, st);
        }
        record_frame(r, s);
        if (spn_shot_phase_now(s) == SPN_SHOT_DONE) break;
    }
    return 0;
}

int cmd_shoot(int argc, char **argv)
{
    shoot_options o;
    memset(&o, 0, sizeof o);
    o.def = spn_shot_def_default();
    o.video.fps = 60, o.max_time = 30, o.points = o.def.points, o.hills = o.def.noise_points;
    o.video.width = 960, o.video.height = 540;
    int rc = parse_options(argc, argv, &o);
    if (rc >= 0) return rc;
    const char *ext = cli_extension(o.output);
    bool json = strcmp(ext, "json") == 0;
    if (!json && *ext && strcmp(ext, "mp4") != 0 && strcmp(ext, "gif") != 0)
        return cli_usage(CMD, "%s: output must be .json, .mp4, .gif or a folder (no extension)", o.output);
    spn_shot *s = NULL;
    spn_status st = spn_shot_create(&o.def, &s);
    if (st != SPN_OK) return cli_fail_status(CMD, st);
    const spn_ballistic *b = spn_shot_path(s);
    fprintf(stderr, "shoot: speed %.4g m/s (least %.4g), elevation %.2f deg, contact at %.4g s\n", b->speed,
            b->min_speed, b->elevation * 180 / SPN_PI, b->flight_time);
    recording r;
    memset(&r, 0, sizeof r);
    rc = record(&o, s, &r);
    if (rc == 0) {
        fprintf(stderr, "shoot: %u frames at %g fps (%.3g s), ended in %s\n", r.frames, o.video.fps, r.t[r.frames - 1],
                spn_shot_phase_name(r.phase[r.frames - 1]));
        rc = json ? shoot_write_json(CMD, o.output, s, &r, o.video.fps) : shoot_write_video(CMD, o.output, &r, &o.video);
    }
    recording_free(&r);
    spn_shot_destroy(s);
    return rc;
}
