/* spinneret build: make an orb web with one of the builders of src/web and
 * write it as a web file. Thin over the library: the options fill a builder's
 * definition struct (every parameter is an option, its range checked here or
 * by the builder), --settle brings the web to rest, --frames renders the web
 * being built, spring by spring in construction order. */
#include "cli.h"
#include "frame_pipe.h"

#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const CMD = "build";

static void usage(FILE *out)
{
    fprintf(out,
            "usage: spinneret build [options] -o WEB.json\n"
            "Build an orb web. Lengths in metres; anchors in order around the web.\n\n"
            "  --anchors \"x,y[,z];x,y[,z];...\"  at least 3 (default: the species' site)\n"
            "  --method physical|geometric     Mehla 2005 sec. 5.2, or the Japanese thesis (2011) sec. 3\n"
            "  --species generic|araneus|zilla|argiope|zygiella   a species' web (docs/species.md)\n"
            "  --preset thesis|silk            thread materials (physical: thesis; others: silk)\n"
            "  --seed N                        every random choice (default 1)\n"
            "  --settle                        bring the web to rest before writing\n"
            "  --settle-time S                 at most S simulated seconds (default 30)\n"
            "  --frames DIR                    write PNG frames of the construction into DIR\n"
            "  --frame-count N                 frames of the construction (default 60)\n"
            "  --as-designed                   geometric and species webs: skip the form finding that\n"
            "                                  builds them at rest (faster on big webs; settle them after)\n"
            "  --png FILE                      also render the finished web (PNG, SVG or PDF)\n"
            "  -o, --output FILE               the web file to write (.spnw: binary, else JSON)\n\n"
            "physical (thesis values; 1 thesis unit = 1 mm):\n"
            "  --move-outer M (0.06)  --outer-placement M (0.005)  --outer-rest M (0.002)\n"
            "  --frame-placement M (0.020)  --frame-rest M (0.015)  --spoke-placement M (0.007)\n"
            "  --spoke-rest M (0.003)  --spiral-extension F (0.75)  --frame-bow F (0.04)\n"
            "  --hub-radius M (0.02)  --free-zone M (0.02)  --spiral-density N (5)\n"
            "  --provot STRAIN        lay strands at rest and limit strain (Provot) instead\n\n"
            "geometric (thesis symbols and ranges):\n"
            "  --t [0.1,0.2] (0.15)  --s [0.25,0.30] (0.28)  --u [1,3] (3)  --v [4,8] (8)\n"
            "  --r-min, --r-max [0.3,0.7]  --m [0,0.6] (0.1)  --m-prime [0,0.5] (0.2)  --k [5,45] (15)\n"
            "  --segment M (0.01)\n"
            "  --prestrain F  --capture-prestrain F  --frame-prestrain F  --anchor-prestrain F\n"
            "                         strain radii, capture spiral, frame and moorings are laid at\n"
            "                         (silk: 0.005, 0.3, 0.08, 0.2; thesis: 1.33, 0.75, 0.33, 1.5)\n\n"
            "species (the preset's values unless given):\n"
            "  --size M  --radii N  --mesh-inner M  --mesh-outer M  --hub-offset F  --contraction F\n"
            "  --hub-radius M  --free-zone M  --jitter F (natural variation)  --margin M\n"
            "  --prestrain F  --capture-prestrain F  --frame-prestrain F  --anchor-prestrain F  as geometric\n"
            "  --keep-aux             keep the auxiliary spiral (normally removed)\n");
}

typedef struct opts {
    spn_vec3 anchors[SPN_WEB_MAX_ANCHORS];
    int anchor_count;
    const char *method, *species, *preset, *output, *frames, *png;
    uint64_t seed;
    bool settle, keep_aux, silk;
    double settle_time;
    long frame_count;
    spn_physical_def phys;
    spn_geometric_def geo;
    spn_species_def sp;
} opts;

static bool parse_anchors(const char *text, opts *o)
{
    char *copy = strdup(text), *save = NULL;
    if (!copy) return false;
    o->anchor_count = 0;
    bool ok = true;
    for (char *tok = strtok_r(copy, ";", &save); tok && ok; tok = strtok_r(NULL, ";", &save)) {
        if (o->anchor_count == SPN_WEB_MAX_ANCHORS) {
            cli_usage(CMD, "--anchors: expected 3 to %d anchors, got more", SPN_WEB_MAX_ANCHORS);
            ok = false;
            break;
        }
        char name[32];
        snprintf(name, sizeof name, "--anchors (anchor %d)", o->anchor_count + 1);
        ok = cli_vec3(CMD, name, tok, true, &o->anchors[o->anchor_count]);
        /* Within a thousand kilometres: sums and cross products of anchors stay finite. */
        spn_vec3 a = o->anchors[o->anchor_count++];
        if (ok && !(fabs(a.x) <= CLI_MAX_COORD && fabs(a.y) <= CLI_MAX_COORD && fabs(a.z) <= CLI_MAX_COORD)) {
            cli_usage(CMD, "%s: expected coordinates in [%g, %g] m, got '%s'", name, -CLI_MAX_COORD, CLI_MAX_COORD, tok);
            ok = false;
        }
    }
    free(copy);
    if (ok && o->anchor_count < 3) {
        cli_usage(CMD, "--anchors: expected at least 3 (at most %d) anchors \"x,y[,z];...\", got %d",
                  SPN_WEB_MAX_ANCHORS, o->anchor_count);
        ok = false;
    }
    return ok;
}

enum { O_ANCHORS = 256, O_METHOD, O_SPECIES, O_PRESET, O_SEED, O_SETTLE, O_SETTLE_TIME, O_FRAMES, O_FRAME_COUNT,
       O_PROVOT, O_KEEP_AUX, O_AS_DESIGNED, O_PNG, O_NUM };

/* Numeric options: name, where it goes, range. */
typedef struct num_opt {
    const char *name;
    int which; /* 0 physical, 1 geometric, 2 species */
    size_t offset;
    bool integer;
    double lo, hi;
} num_opt;

#define P(f) 0, offsetof(spn_physical_def, f)
#define G(f) 1, offsetof(spn_geometric_def, f)
#define S(f) 2, offsetof(spn_species_def, f)
static const num_opt nums[] = {
    {"move-outer", P(move_outer), false, 1e-4, 10},         {"outer-placement", P(outer_placement), false, 1e-4, 1},
    {"outer-rest", P(outer_rest), false, 1e-5, 1},          {"frame-placement", P(frame_placement), false, 1e-4, 1},
    {"frame-rest", P(frame_rest), false, 1e-5, 1},          {"spoke-placement", P(spoke_placement), false, 1e-4, 1},
    {"spoke-rest", P(spoke_rest), false, 1e-5, 1},          {"spiral-extension", P(spiral_extension), false, 0, 4},
    {"frame-bow", P(frame_bow), false, 0, 0.25},            {"hub-radius", P(hub_radius), false, 1e-4, 1},
    {"free-zone", P(free_zone), false, 0, 1},               {"spiral-density", P(spiral_density), true, 1, 1000},
    {"t", G(t), false, 0.1, 0.2},                           {"s", G(s), false, 0.25, 0.30},
    {"u", G(u), true, 1, 3},                                {"v", G(v), true, 4, 8},
    {"r-min", G(r_min), false, 0.3, 0.7},                   {"r-max", G(r_max), false, 0.3, 0.7},
    {"m", G(m), false, 0, 0.6},                             {"m-prime", G(m_prime), false, 0, 0.5},
    {"k", G(k), true, 5, 45},                               {"segment", G(segment), false, 1e-4, 1},
    {"prestrain", G(strains.radii), false, 0, 4},           {"capture-prestrain", G(strains.capture), false, 0, 4},
    {"frame-prestrain", G(strains.frame), false, 0, 4},     {"anchor-prestrain", G(strains.anchor), false, 0, 4},
    {"size", S(size), false, 0.02, 5},                      {"radii", S(radii), true, 6, 200},
    {"mesh-inner", S(mesh_inner), false, 1e-4, 0.1},        {"mesh-outer", S(mesh_outer), false, 1e-4, 0.1},
    {"hub-offset", S(hub_offset), false, -0.3, 0.3},        {"contraction", S(contraction), false, 0, 0.6},
    {"jitter", S(jitter), false, 0, 0.3},                   {"margin", S(margin), false, 0, 0.1},
};
/* Options the species presets take too (from the physical builder or the geometric one). */
static const struct {
    const char *name;
    size_t species_offset;
} shared[] = {{"hub-radius", offsetof(spn_species_def, hub_radius)},
              {"free-zone", offsetof(spn_species_def, free_zone)},
              {"prestrain", offsetof(spn_species_def, strains.radii)},
              {"capture-prestrain", offsetof(spn_species_def, strains.capture)},
              {"frame-prestrain", offsetof(spn_species_def, strains.frame)},
              {"anchor-prestrain", offsetof(spn_species_def, strains.anchor)}};
#define NNUM (sizeof nums / sizeof nums[0])

static bool set_num(opts *o, const num_opt *n, const char *text)
{
    char name[40];
    snprintf(name, sizeof name, "--%s", n->name);
    char *base = n->which == 0 ? (char *)&o->phys : n->which == 1 ? (char *)&o->geo : (char *)&o->sp;
    if (n->integer) {
        long v;
        if (!cli_int(CMD, name, text, (long)n->lo, (long)n->hi, &v)) return false;
        *(int *)(base + n->offset) = (int)v;
    } else {
        double v;
        if (!cli_double(CMD, name, text, n->lo, n->hi, &v)) return false;
        *(double *)(base + n->offset) = v;
    }
    for (size_t i = 0; i < sizeof shared / sizeof shared[0]; i++)
        if (strcmp(shared[i].name, n->name) == 0) *(double *)((char *)&o->sp + shared[i].species_offset) = *(double *)(base + n->offset);
    return true;
}

static int parse(int argc, char **argv, opts *o)
{
    struct option lo[NNUM + 16];
    int k = 0;
    const struct option fixed[] = {
        {"anchors", required_argument, NULL, O_ANCHORS}, {"method", required_argument, NULL, O_METHOD},
        {"species", required_argument, NULL, O_SPECIES}, {"preset", required_argument, NULL, O_PRESET},
        {"seed", required_argument, NULL, O_SEED},       {"settle", no_argument, NULL, O_SETTLE},
        {"settle-time", required_argument, NULL, O_SETTLE_TIME}, {"frames", required_argument, NULL, O_FRAMES},
        {"frame-count", required_argument, NULL, O_FRAME_COUNT}, {"provot", required_argument, NULL, O_PROVOT},
        {"keep-aux", no_argument, NULL, O_KEEP_AUX},     {"as-designed", no_argument, NULL, O_AS_DESIGNED},
        {"png", required_argument, NULL, O_PNG},         {"output", required_argument, NULL, 'o'},
        {"help", no_argument, NULL, 'h'}};
    for (size_t i = 0; i < sizeof fixed / sizeof fixed[0]; i++) lo[k++] = fixed[i];
    for (size_t i = 0; i < NNUM; i++) lo[k++] = (struct option){nums[i].name, required_argument, NULL, O_NUM + (int)i};
    lo[k] = (struct option){NULL, 0, NULL, 0};
    opterr = 0;
    for (int c; (c = getopt_long(argc, argv, ":ho:", lo, NULL)) != -1;) {
        switch (c) {
        case 'h': usage(stdout); return -1;
        case 'o': o->output = optarg; break;
        case O_ANCHORS: if (!parse_anchors(optarg, o)) return CLI_EXIT_USAGE; break;
        case O_METHOD: o->method = optarg; break;
        case O_SPECIES: o->species = optarg; break;
        case O_PRESET: o->preset = optarg; break;
        case O_SEED: if (!cli_u64(CMD, "--seed", optarg, &o->seed)) return CLI_EXIT_USAGE; break;
        case O_SETTLE: o->settle = true; break;
        case O_SETTLE_TIME: if (!cli_double(CMD, "--settle-time", optarg, 0.01, 1e4, &o->settle_time)) return CLI_EXIT_USAGE; break;
        case O_FRAMES: o->frames = optarg; break;
        case O_FRAME_COUNT: if (!cli_int(CMD, "--frame-count", optarg, 2, 10000, &o->frame_count)) return CLI_EXIT_USAGE; break;
        case O_PROVOT:
            if (!cli_double(CMD, "--provot", optarg, 0.001, 0.9, &o->phys.provot_max_strain)) return CLI_EXIT_USAGE;
            o->phys.provot = true;
            break;
        case O_KEEP_AUX: o->keep_aux = true; break;
        case O_AS_DESIGNED: o->geo.form_find = o->sp.form_find = false; break;
        case O_PNG: o->png = optarg; break;
        case ':': return cli_usage(CMD, "option '%s' needs a value", argv[optind - 1]);
        case '?': return cli_usage(CMD, "unknown option '%s'", argv[optind - 1]);
        default:
            if (c >= O_NUM && c < O_NUM + (int)NNUM) {
                if (!set_num(o, &nums[c - O_NUM], optarg)) return CLI_EXIT_USAGE;
            }
        }
    }
    if (optind < argc) return cli_usage(CMD, "unexpected argument '%s'", argv[optind]);
    if (!o->output) return cli_usage(CMD, "missing -o FILE");
    return 0;
}

/* The species and the material preset must be known before their values are
 * overridden: `option` is "--species" or "--preset". */
static const char *find_option(int argc, char **argv, const char *option)
{
    const size_t n = strlen(option);
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], option) == 0 && i + 1 < argc) return argv[i + 1];
        if (strncmp(argv[i], option, n) == 0 && argv[i][n] == '=') return argv[i] + n + 1;
    }
    return NULL;
}

/* The thesis' 75-250% over-extension is for its soft springs; silk breaks
 * near 30%. With silk, strands left at the thesis' defaults are laid with a
 * silk web's pre-strain instead: radii 2%, frame 8%, mooring 10%, spiral 30%. */
static void silk_strains(spn_physical_def *p)
{
    spn_physical_def d = spn_physical_def_default();
    if (p->outer_rest == d.outer_rest) p->outer_rest = p->outer_placement / 1.10;
    if (p->frame_rest == d.frame_rest) p->frame_rest = p->frame_placement / 1.08;
    if (p->spoke_rest == d.spoke_rest) p->spoke_rest = p->spoke_placement / 1.02;
    if (p->spiral_extension == d.spiral_extension) p->spiral_extension = 0.3;
}

static spn_status build(opts *o, spn_world **w)
{
    spn_material_preset preset = SPN_MATERIAL_SILK;
    bool physical = o->method && strcmp(o->method, "physical") == 0;
    if (!o->species && !o->method) physical = true;
    if (!o->preset) preset = physical ? SPN_MATERIAL_THESIS : SPN_MATERIAL_SILK;
    else if (spn_material_preset_parse(o->preset, &preset) != SPN_OK) return SPN_ERR_INVALID;
    o->silk = preset == SPN_MATERIAL_SILK;
    spn_web_materials mat = spn_web_materials_preset(preset);
    const spn_vec3 *anchors = o->anchor_count ? o->anchors : NULL;
    if (o->species && !o->method) {
        o->sp.seed = o->seed;
        o->sp.materials = mat;
        o->sp.anchors = anchors;
        o->sp.anchor_count = o->anchor_count;
        o->sp.keep_aux_spiral = o->keep_aux;
        return spn_web_build_species(&o->sp, w);
    }
    if (!anchors) return spn_error(SPN_ERR_INVALID, "--anchors: needed with --method (3 to %d anchors)", SPN_WEB_MAX_ANCHORS);
    if (physical) {
        if (o->silk) silk_strains(&o->phys);
        o->phys.anchors = anchors;
        o->phys.anchor_count = o->anchor_count;
        o->phys.materials = mat;
        o->phys.seed = o->seed;
        return spn_web_build_physical(&o->phys, w);
    }
    o->geo.anchors = anchors;
    o->geo.anchor_count = o->anchor_count;
    o->geo.materials = mat;
    o->geo.seed = o->seed;
    return spn_web_build_geometric(&o->geo, w);
}

/* Frames of the construction: the springs laid so far, framed like the whole web. */
static int frames_done; /* for the message when a signal stops the frames */

typedef struct construction_job {
    const spn_world *w;
    spn_render_def rd;
    int count;
} construction_job;

/* Frame i: the web once (i + 1) / count of it is laid (frame_pipe_fn; any thread). */
static spn_status construction_frame(void *user, int slot, int i, const spn_world *none, uint8_t *rgba)
{
    (void)slot, (void)none;
    const construction_job *j = user;
    spn_world *part = NULL;
    spn_status st = spn_web_construction_state(j->w, (double)(i + 1) / j->count, &part);
    if (st == SPN_OK) st = spn_render_rgba(part, &j->rd, rgba);
    spn_world_destroy(part);
    return st;
}

static spn_status write_frames(const spn_world *w, const char *dir, int count)
{
    construction_job job = {w, spn_render_def_default(), count};
    spn_render_def *rd = &job.rd;
    rd->width = rd->height = 800;
    uint32_t np = spn_world_particle_count(w);
    spn_vec3 lo = spn_world_position(w, 0), hi = lo;
    for (uint32_t i = 0; i < np; i++) {
        spn_vec3 p = spn_world_position(w, i);
        lo = spn_v3(fmin(lo.x, p.x), fmin(lo.y, p.y), fmin(lo.z, p.z));
        hi = spn_v3(fmax(hi.x, p.x), fmax(hi.y, p.y), fmax(hi.z, p.z));
    }
    rd->camera.fixed_bounds = true;
    rd->camera.bounds_min = lo;
    rd->camera.bounds_max = hi;
    spn_frames *fr = NULL;
    spn_status st = spn_frames_open(dir, rd->width, rd->height, 24, &fr);
    if (st != SPN_OK) return st;
    cli_interruptible((uint64_t)count);
    st = frame_pipe_run(fr, count, construction_frame, &job, NULL, &frames_done);
    spn_status cs = spn_frames_close(fr, st == SPN_OK);
    return st == SPN_OK ? cs : st;
}

int cmd_build(int argc, char **argv)
{
    if (cli_wants_help(argc, argv)) {
        usage(stdout);
        return 0;
    }
    opts o;
    memset(&o, 0, sizeof o);
    o.seed = 1;
    o.settle_time = 30;
    o.frame_count = 60;
    o.phys = spn_physical_def_default();
    o.geo = spn_geometric_def_default();
    const char *species = find_option(argc, argv, "--species"), *preset = find_option(argc, argv, "--preset");
    spn_species sp = SPN_SPECIES_GENERIC;
    if (species && spn_species_parse(species, &sp) != SPN_OK) return cli_usage(CMD, "--species: %s", spn_last_error());
    o.sp = spn_species_def_preset(sp);
    spn_material_preset mp;
    if (preset && spn_material_preset_parse(preset, &mp) == SPN_OK) /* else build() says what is wrong */
        o.geo.strains = o.sp.strains = spn_web_strains_preset(mp);
    int rc = parse(argc, argv, &o);
    if (rc) return rc < 0 ? 0 : rc;
    if (o.method && strcmp(o.method, "physical") != 0 && strcmp(o.method, "geometric") != 0)
        return cli_usage(CMD, "--method: expected physical or geometric, got '%s'", o.method);
    if (o.species && o.method) return cli_usage(CMD, "--species builds its own web; leave out --method");
    if (!o.sp.form_find && !o.species && (!o.method || strcmp(o.method, "physical") == 0))
        return cli_usage(CMD, "--as-designed: only geometric and species webs are form-found (the physical builder "
                              "lays its threads as it goes)");
    spn_world *w = NULL;
    spn_status st = build(&o, &w);
    if (st != SPN_OK && strncmp(spn_last_error(), "anchors:", 8) == 0) /* the builder's word for --anchors */
        return cli_usage(CMD, "--%s (expected 3 to %d points around an area in the x-y plane)", spn_last_error(),
                         SPN_WEB_MAX_ANCHORS);
    if (st != SPN_OK) return cli_fail_status(CMD, st);
    if (o.frames) {
        /* The animation shows the auxiliary spiral laid and eaten again, so it
         * is drawn from the same build with that spiral kept. */
        bool keep = o.keep_aux;
        o.keep_aux = true;
        spn_world *anim = NULL;
        st = build(&o, &anim);
        o.keep_aux = keep;
        if (st == SPN_OK) st = write_frames(anim, o.frames, (int)o.frame_count);
        spn_world_destroy(anim);
        if (st == SPN_OK && spn_interrupted()) { /* the frames so far are kept; no web file */
            spn_world_destroy(w);
            return cli_report_interrupt(CMD, (uint64_t)frames_done, (uint64_t)o.frame_count, "the complete frames are kept, no web file written", 0);
        }
        spn_interrupt_graceful(false);
    }
    if (st == SPN_OK && o.settle) {
        spn_settle_report rep;
        /* Silk is far too stiff for explicit steps (DESIGN): settle it implicitly. */
        if (o.silk) spn_world_set_integrator(w, SPN_INTEGRATOR_IMPLICIT);
        st = spn_web_settle(w, o.settle_time, &rep);
        if (st != SPN_OK) {
            spn_world_destroy(w);
            return cli_fail(CMD, "settling failed: %s", spn_last_error());
        }
        if (rep.reason == SPN_SETTLE_CONVERGED && rep.steps == 0)
            fprintf(stderr,
                    "spinneret build: settled to rest as its static equilibrium (%d Newton steps; largest residual "
                    "%.3g N)\n",
                    rep.newton_steps, rep.residual);
        else
            fprintf(stderr, "spinneret build: settled %s after %.3g s%s (largest residual %.3g N)\n",
                    rep.reason == SPN_SETTLE_CONVERGED ? "to rest" : "(time out)", rep.time,
                    rep.newton_steps ? " stepping in time (the static equilibrium fell short)" : "",
                    rep.residual);
    }
    if (st == SPN_OK && o.png) {
        spn_render_def rd = spn_render_def_default();
        rd.width = rd.height = 1000;
        st = spn_render_file(w, &rd, o.png);
    }
    if (st == SPN_OK) st = spn_web_save(w, o.output);
    spn_world_destroy(w);
    return st == SPN_OK ? 0 : cli_fail(CMD, "%s", spn_last_error());
}
