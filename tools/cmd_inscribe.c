/* spinneret inscribe WEB (--text TEXT | --image FILE) -o OUT: write a message
 * into a web the way Charlotte does (Mehla 2005, ch. 6), on the library's
 * spn_inscribe. Bad input fails before anything is written; every output is
 * written atomically. */
#include "cli.h"

#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const CMD = "inscribe";

static void usage(FILE *out)
{
    fprintf(out,
            "usage: spinneret inscribe WEB (--text TEXT | --image FILE) -o OUT [options]\n"
            "Inscribe a message into the web in WEB: capture-spiral segments the message\n"
            "covers are taken out (thesis scores 1-10 above --threshold), emphasis threads\n"
            "are put in, and the web is settled again before OUT (a web file) is written.\n\n"
            "target\n"
            "      --text TEXT        a line of text (repeat for more lines; \"\\n\" also breaks)\n"
            "      --font NAME        font, default \"DejaVu Sans Bold\" (must be installed)\n"
            "      --fit F            F of the largest size that fits in the capture spiral, (0, 1]; default 0.9\n"
            "      --text-height M    capital height [m] instead of --fit (must still fit)\n"
            "      --line-spacing F   baseline distance in capital heights, [1, 4]; default 1.45\n"
            "      --image FILE       PNG, PBM or PGM; dark pixels are the message\n"
            "      --raster PX        size of the comparison rasters, [16, 8192]; default 1200\n"
            "method\n"
            "      --threshold N      remove segments scoring above N, [0, 10]; default 8\n"
            "      --emphasis MODE    none, crosshatch, fill or outline; default none\n"
            "      --fill-spacing M   fill: distance between attachments [m]; default capture radius / 80\n"
            "      --gaps N           also take out N random capture segments (fig. 6.18)\n"
            "      --seed N           for fill and gaps; default 1\n"
            "settling (before scoring and after editing)\n"
            "      --solver NAME      euler, symplectic, rk4, adaptive or implicit (default: WEB's, or\n"
            "                         implicit where WEB's explicit one cannot take --dt)\n"
            "      --dt S             time step [s]; default 1e-3\n"
            "      --tol N            residual force threshold [N]; default 1e-6\n"
            "      --max-time S       simulated time allowed per settle [s]; default 60\n"
            "      --drag D           air drag [1/s] at least this while settling, [0, 1e6]; default 20\n"
            "      --no-settle        edit the web as it is, without settling\n"
            "      --no-solve         after editing, step to rest without solving for it first\n"
            "output\n"
            "  -o, --output OUT       the inscribed web file (required; .spnw: binary, else JSON)\n"
            "      --render PNG       also render the result (default render settings)\n"
            "      --overlay PNG      the dilated target over the web before inscription (figs. 6.3, 6.10)\n"
            "  -h, --help             this text\n");
}

typedef struct inscribe_options {
    const char *input, *output, *image, *solver, *render, *overlay;
    char *text;               /* lines joined with '\n' (owned) */
    int raster;
    spn_text_def text_def;
    spn_inscribe_def def;
} inscribe_options;

/* Append a --text line, turning the two characters "\n" into a line break. */
static bool add_text(inscribe_options *o, const char *line)
{
    size_t old = o->text ? strlen(o->text) : 0, n = strlen(line);
    char *t = realloc(o->text, old + n + 2);
    if (!t) return false;
    if (old) t[old++] = '\n';
    for (size_t i = 0; i < n; i++) {
        if (line[i] == '\\' && line[i + 1] == 'n') t[old++] = '\n', i++;
        else t[old++] = line[i];
    }
    t[old] = '\0';
    o->text = t;
    return true;
}

enum {
    OPT_TEXT = 256, OPT_FONT, OPT_FIT, OPT_HEIGHT, OPT_SPACING, OPT_IMAGE, OPT_RASTER, OPT_THRESHOLD, OPT_EMPHASIS,
    OPT_FILL, OPT_GAPS, OPT_SEED, OPT_SOLVER, OPT_DT, OPT_TOL, OPT_MAX_TIME, OPT_DRAG, OPT_NO_SETTLE, OPT_NO_SOLVE,
    OPT_RENDER, OPT_OVERLAY
};

static bool take_option(int c, const char *arg, inscribe_options *o)
{
    long v;
    switch (c) {
    case 'o': o->output = arg; return true;
    case OPT_TEXT: return add_text(o, arg);
    case OPT_FONT: o->text_def.font = arg; return true;
    case OPT_FIT: return cli_double(CMD, "--fit", arg, 1e-3, 1, &o->text_def.fit);
    case OPT_HEIGHT: return cli_double(CMD, "--text-height", arg, 1e-6, 1e3, &o->text_def.height);
    case OPT_SPACING: return cli_double(CMD, "--line-spacing", arg, 1, 4, &o->text_def.line_spacing);
    case OPT_IMAGE: o->image = arg; return true;
    case OPT_RASTER: return cli_int(CMD, "--raster", arg, 16, 8192, &v) && (o->raster = (int)v, true);
    case OPT_THRESHOLD: return cli_int(CMD, "--threshold", arg, 0, 10, &v) && (o->def.threshold = (int)v, true);
    case OPT_EMPHASIS:
        if (spn_emphasis_parse(arg, &o->def.emphasis) == SPN_OK) return true;
        cli_usage(CMD, "--emphasis: %s", spn_last_error());
        return false;
    case OPT_FILL: return cli_double(CMD, "--fill-spacing", arg, 1e-6, 10, &o->def.fill_spacing);
    case OPT_GAPS: return cli_int(CMD, "--gaps", arg, 0, 100000000, &v) && (o->def.gaps = (int)v, true);
    case OPT_SEED: return cli_u64(CMD, "--seed", arg, &o->def.seed);
    case OPT_SOLVER: o->solver = arg; return true;
    case OPT_DT: return cli_double(CMD, "--dt", arg, 1e-9, 1, &o->def.settle_def.dt);
    case OPT_TOL: return cli_double(CMD, "--tol", arg, 0, 1e6, &o->def.settle_def.max_residual);
    case OPT_MAX_TIME: return cli_double(CMD, "--max-time", arg, 1e-9, 1e7, &o->def.settle_def.max_time);
    case OPT_DRAG: return cli_double(CMD, "--drag", arg, 0, 1e6, &o->def.settle_def.drag);
    case OPT_NO_SETTLE: o->def.settle = false; return true;
    case OPT_NO_SOLVE: o->def.settle_solve = false; return true;
    case OPT_RENDER: o->render = arg; return true;
    case OPT_OVERLAY: o->overlay = arg; return true;
    default: return false;
    }
}

static int parse_one(int c, const char *arg, void *o) { return take_option(c, arg, o) ? 1 : -1; }

/* Fills `o` from argv; returns -1 to go on, else the exit code. */
static int parse_options(int argc, char **argv, inscribe_options *o)
{
    static const struct option options[] = {
        {"output", required_argument, NULL, 'o'}, {"text", required_argument, NULL, OPT_TEXT},
        {"font", required_argument, NULL, OPT_FONT}, {"fit", required_argument, NULL, OPT_FIT},
        {"text-height", required_argument, NULL, OPT_HEIGHT}, {"line-spacing", required_argument, NULL, OPT_SPACING},
        {"image", required_argument, NULL, OPT_IMAGE}, {"raster", required_argument, NULL, OPT_RASTER},
        {"threshold", required_argument, NULL, OPT_THRESHOLD}, {"emphasis", required_argument, NULL, OPT_EMPHASIS},
        {"fill-spacing", required_argument, NULL, OPT_FILL}, {"gaps", required_argument, NULL, OPT_GAPS},
        {"seed", required_argument, NULL, OPT_SEED}, {"solver", required_argument, NULL, OPT_SOLVER},
        {"dt", required_argument, NULL, OPT_DT}, {"tol", required_argument, NULL, OPT_TOL},
        {"max-time", required_argument, NULL, OPT_MAX_TIME}, {"no-settle", no_argument, NULL, OPT_NO_SETTLE},
        {"drag", required_argument, NULL, OPT_DRAG},         {"no-solve", no_argument, NULL, OPT_NO_SOLVE},
        {"render", required_argument, NULL, OPT_RENDER}, {"overlay", required_argument, NULL, OPT_OVERLAY},
        {"help", no_argument, NULL, 'h'}, {NULL, 0, NULL, 0}};
    int r = cli_parse_options(CMD, argc, argv, ":o:h", options, usage, parse_one, o);
    if (r >= 0) return r;
    if (optind >= argc) return cli_usage(CMD, "missing WEB (the web file to inscribe)");
    if (optind + 1 < argc) return cli_usage(CMD, "unexpected argument '%s'", argv[optind + 1]);
    o->input = argv[optind];
    if (!o->output || !*o->output) return cli_usage(CMD, "-o/--output: the output file is required");
    if (!o->text && !o->image && o->def.gaps == 0) return cli_usage(CMD, "give --text or --image (or --gaps)");
    if (o->text && o->image) return cli_usage(CMD, "--text and --image: give one target, not both");
    spn_integrator integ;
    if (o->solver && spn_integrator_parse(o->solver, &integ) != SPN_OK)
        return cli_usage(CMD, "--solver: %s", spn_last_error());
    return -1;
}

static spn_status make_target(const inscribe_options *o, const spn_world *w, spn_target **t)
{
    spn_status st = spn_target_create(w, o->raster, t);
    if (st != SPN_OK) return st;
    if (o->text) {
        spn_text_def td = o->text_def;
        td.text = o->text;
        st = spn_target_text(*t, w, &td);
    } else if (o->image) {
        st = spn_target_image(*t, w, o->image, o->text_def.fit);
    }
    if (st != SPN_OK) spn_target_destroy(*t), *t = NULL;
    return st;
}

static void print_report(const spn_inscribe_report *r, const spn_inscribe_def *d)
{
    fprintf(stderr, "inscribe: %u capture segments scored; scores", r->segments);
    for (int s = 1; s <= 10; s++) fprintf(stderr, " %d:%d", s, r->score_histogram[s]);
    fprintf(stderr, "\n  removed %u (score > %d), random gaps %u, emphasis %s: %u threads added, %u split\n",
            r->removed, d->threshold, r->gaps, spn_emphasis_name(d->emphasis), r->added, r->split);
    fprintf(stderr, "  cleaned %u dangling or unanchored threads, %u particles left without thread\n", r->pruned,
            r->particles_removed);
    if (r->implicit_before || r->implicit_after)
        fprintf(stderr,
                "  stepped implicitly (%s%s%s): the web's own solver cannot take steps of %g s on its stiffest "
                "threads\n",
                r->implicit_before ? "before scoring" : "", r->implicit_before && r->implicit_after ? " and " : "",
                r->implicit_after ? "after editing" : "", d->settle_def.dt);
    if (d->settle && r->after.reason == SPN_SETTLE_CONVERGED && r->after.steps == 0 && r->after.newton_steps > 0)
        fprintf(stderr, "  settled: solved for the rest state (%d Newton steps), largest residual %.3g N\n",
                r->after.newton_steps, r->after.residual);
    else if (d->settle)
        fprintf(stderr, "  settled: %s after %g s simulated%s, largest residual %.3g N (tolerance %g)\n",
                r->after.reason == SPN_SETTLE_CONVERGED ? "converged" : "timed out", r->after.time,
                r->after.newton_steps > 0 ? " (the rest state's solve fell short)" : "", r->after.residual,
                d->settle_def.max_residual);
}

/* The overlay shows the target over the web as it was (the thesis' source
 * image, figs. 6.3 and 6.10), so one sees which segments it covers. */
static spn_status write_outputs(const inscribe_options *o, const spn_world *w, const spn_world *source,
                                const spn_target *t)
{
    spn_status st = spn_web_save(w, o->output);
    if (st == SPN_OK && o->overlay) st = spn_inscribe_overlay(source, t, o->overlay);
    if (st == SPN_OK && o->render) {
        spn_render_def rd = spn_render_def_default();
        st = spn_render_file(w, &rd, o->render);
    }
    return st;
}

int cmd_inscribe(int argc, char **argv)
{
    inscribe_options o = {0};
    o.raster = 1200;
    o.text_def = spn_text_def_default();
    o.def = spn_inscribe_def_default();
    int code = parse_options(argc, argv, &o);
    if (code >= 0) return free(o.text), code;

    spn_world *w = NULL, *source = NULL;
    spn_target *t = NULL;
    spn_inscribe_report report;
    spn_status st = spn_web_load(o.input, &w);
    if (st == SPN_OK && o.solver) {
        spn_integrator integ = SPN_INTEGRATOR_SYMPLECTIC;
        spn_integrator_parse(o.solver, &integ);
        spn_world_set_integrator(w, integ);
        o.def.settle_keep_integrator = true; /* a solver named is the one that steps */
    }
    if (st == SPN_OK) st = make_target(&o, w, &t);
    if (st == SPN_OK && o.overlay && !(source = spn_world_clone(w))) st = spn_error(SPN_ERR_NOMEM, "out of memory");
    if (st == SPN_OK) st = spn_inscribe(&w, t, &o.def, &report);
    if (st == SPN_OK) print_report(&report, &o.def);
    if (st == SPN_OK) st = write_outputs(&o, w, source, t);
    spn_target_destroy(t);
    spn_world_destroy(source);
    spn_world_destroy(w);
    free(o.text);
    if (st != SPN_OK) return cli_fail(CMD, "%s", spn_last_error());
    fprintf(stderr, "  wrote %s\n", o.output);
    return 0;
}
