/* spinneret drop: the spring-system documentation's example program (Juhasz &
 * Bercovici's SpringAppEx) in our conventions. A triangle model becomes a
 * spring system (the mesh factory), falls under gravity onto a ground plane and
 * any fixed obstacles, and a state is written per frame until the kinetic
 * energy falls under the threshold (stable) or the maximum time passes. The
 * original's options -SS -BS -SD -BD -M -V -T -DT -MINT -MAXT are accepted as
 * `-SS=1500` or `-SS 1500` (any case) beside our long options. */
#include "cli.h"
#include "frame_dir.h"

#include <spinneret/mesh.h>

#include <getopt.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#define CMD "drop"
#define MAX_OBSTACLES 8

static void usage(void)
{
    printf("usage: spinneret drop MODEL.obj|MODEL.ply [options] -o OUT\n"
           "Drop a triangle model made of springs onto the ground; write a state per frame.\n\n"
           "factory (the documentation's short forms in brackets, as -SS=1500 or -SS 1500):\n"
           "  --stretch-stiffness K [-SS]  edge springs [N/m] (1500)\n"
           "  --bend-stiffness K [-BS]     across adjacent triangles [N/m] (1500)\n"
           "  --stretch-damping D [-SD]    [N s/m] (4)\n"
           "  --bend-damping D [-BD]       [N s/m] (3)\n"
           "  --mass M [-M]                mass of each vertex [kg] (0.5)\n"
           "  --total-mass M               instead: the model's mass, spread by triangle area\n"
           "  --vicinity R [-V]            also join vertices nearer than R [m] (0.3; 0: none)\n"
           "  --fix-group NAME             fix the vertices of an OBJ group\n"
           "  --fix I,J,...                fix these vertices (0-based, in file order)\n"
           "simulation:\n"
           "  --threshold E [-T]           stable when kinetic energy < E [J] (0.01)\n"
           "  --frame-interval S [-DT]     time between frames [s] (0.03)\n"
           "  --min-time S [-MINT]         do not test stability before this time [s] (0.1)\n"
           "  --max-time S [-MAXT]         stop after this time [s] (15.3)\n"
           "  --quiet-time S               stable only after the energy stayed under the\n"
           "                               threshold this long (0.2; a ball at the top of\n"
           "                               its bounce is still for an instant only)\n"
           "  --gravity X,Y,Z              [m/s^2] (0,-9.81,0)\n"
           "  --ground Y | --no-ground     ground plane height (0)\n"
           "  --restitution R --friction F contacts, in [0, 1] (0.5, 0.2)\n"
           "  --obstacle FILE              a fixed mesh to collide with (repeatable)\n"
           "  --translate X,Y,Z            move the model first\n"
           "  --velocity X,Y,Z             initial velocity [m/s]\n"
           "output:\n"
           "  -o, --output DIR             folder of frames: frame_00000.obj ... (or .pov)\n"
           "  --pov                        POV-Ray scenes instead of OBJ\n"
           "  --render                     render the POV frames to PNG with povray\n"
           "  --size WxH                   render size (480x360)\n"
           "  --movie FILE.mp4             render and encode a movie with ffmpeg (implies --pov)\n"
           "  --video FILE.mp4|.gif        draw the edges with our renderer (cairo) into a video,\n"
           "                               no povray needed (frames are still written to -o)\n");
}

typedef struct drop_opts {
    spn_mesh_spring_def spring;
    spn_mesh_scene_def scene;
    double threshold, frame_dt, min_time, max_time, quiet_time;
    spn_vec3 translate;
    const char *obstacles[MAX_OBSTACLES];
    int nobst;
    const char *fix_list, *model, *out, *movie, *video;
    bool pov, render;
    int width, height;
} drop_opts;

enum { O_SS = 256, O_BS, O_SD, O_BD, O_MASS, O_TOTAL, O_VIC, O_FIXG, O_FIX, O_T, O_DT, O_MINT, O_MAXT, O_GRAV, O_GROUND,
       O_NOGROUND, O_REST, O_FRIC, O_OBST, O_TRANS, O_VEL, O_POV, O_RENDER, O_SIZE, O_MOVIE, O_QUIET, O_VIDEO };

static const struct option long_opts[] = {
    {"stretch-stiffness", required_argument, 0, O_SS}, {"bend-stiffness", required_argument, 0, O_BS},
    {"stretch-damping", required_argument, 0, O_SD},   {"bend-damping", required_argument, 0, O_BD},
    {"mass", required_argument, 0, O_MASS},            {"total-mass", required_argument, 0, O_TOTAL},
    {"vicinity", required_argument, 0, O_VIC},         {"fix-group", required_argument, 0, O_FIXG},
    {"fix", required_argument, 0, O_FIX},              {"threshold", required_argument, 0, O_T},
    {"frame-interval", required_argument, 0, O_DT},    {"min-time", required_argument, 0, O_MINT},
    {"max-time", required_argument, 0, O_MAXT},        {"gravity", required_argument, 0, O_GRAV},
    {"ground", required_argument, 0, O_GROUND},        {"no-ground", no_argument, 0, O_NOGROUND},
    {"restitution", required_argument, 0, O_REST},     {"friction", required_argument, 0, O_FRIC},
    {"obstacle", required_argument, 0, O_OBST},        {"translate", required_argument, 0, O_TRANS},
    {"velocity", required_argument, 0, O_VEL},         {"pov", no_argument, 0, O_POV},
    {"render", no_argument, 0, O_RENDER},              {"size", required_argument, 0, O_SIZE},
    {"movie", required_argument, 0, O_MOVIE},          {"output", required_argument, 0, 'o'},
    {"quiet-time", required_argument, 0, O_QUIET},      {"video", required_argument, 0, O_VIDEO},
    {"help", no_argument, 0, 'h'},                     {0, 0, 0, 0}};

/* The documentation's short forms, rewritten to long options. */
static const struct { const char *key, *name; } legacy[] = {
    {"SS", "stretch-stiffness"}, {"BS", "bend-stiffness"}, {"SD", "stretch-damping"}, {"BD", "bend-damping"},
    {"M", "mass"}, {"V", "vicinity"}, {"T", "threshold"}, {"DT", "frame-interval"}, {"MINT", "min-time"},
    {"MAXT", "max-time"}};

static char **rewrite_legacy(int argc, char **argv)
{
    char **out = calloc((size_t)argc + 1, sizeof *out);
    for (int i = 0; out && i < argc; i++) {
        const char *a = argv[i], *eq = strchr(a, '=');
        size_t klen = eq ? (size_t)(eq - a - 1) : strlen(a) - 1;
        const char *name = NULL;
        for (size_t k = 0; i > 0 && a[0] == '-' && a[1] != '-' && k < sizeof legacy / sizeof legacy[0]; k++)
            if (strlen(legacy[k].key) == klen && strncasecmp(a + 1, legacy[k].key, klen) == 0) name = legacy[k].name;
        size_t n = strlen(a) + 32;
        out[i] = malloc(n);
        if (!out[i]) continue;
        if (name) snprintf(out[i], n, "--%s%s", name, eq ? eq : "");
        else snprintf(out[i], n, "%s", a);
    }
    return out;
}

static bool parse_number_opt(int c, const char *arg, drop_opts *o)
{
    struct { int c; const char *name; double lo, hi; double *dst; } t[] = {
        {O_SS, "--stretch-stiffness", 0, 1e12, &o->spring.stretch_k}, {O_BS, "--bend-stiffness", 0, 1e12, &o->spring.bend_k},
        {O_SD, "--stretch-damping", 0, 1e9, &o->spring.stretch_kd},   {O_BD, "--bend-damping", 0, 1e9, &o->spring.bend_kd},
        {O_MASS, "--mass", 1e-12, 1e9, &o->spring.vertex_mass},      {O_TOTAL, "--total-mass", 1e-12, 1e12, &o->spring.total_mass},
        {O_VIC, "--vicinity", 0, 1e6, &o->spring.vicinity},           {O_T, "--threshold", 0, 1e12, &o->threshold},
        {O_DT, "--frame-interval", 1e-6, 1e3, &o->frame_dt},          {O_MINT, "--min-time", 0, 1e6, &o->min_time},
        {O_MAXT, "--max-time", 0, 1e6, &o->max_time},                 {O_GROUND, "--ground", -1e6, 1e6, &o->scene.ground_y},
        {O_REST, "--restitution", 0, 1, &o->scene.restitution},       {O_FRIC, "--friction", 0, 1, &o->scene.friction}};
    for (size_t k = 0; k < sizeof t / sizeof t[0]; k++)
        if (t[k].c == c) return cli_double(CMD, t[k].name, arg, t[k].lo, t[k].hi, t[k].dst);
    return false;
}

static int parse_option(int c, const char *arg, drop_opts *o)
{
    switch (c) {
    case 'o': o->out = arg; return 0;
    case O_FIXG: o->spring.fixed_group = arg; return 0;
    case O_FIX: o->fix_list = arg; return 0;
    case O_GRAV: return cli_vec3(CMD, "--gravity", arg, false, &o->scene.world.gravity) ? 0 : CLI_EXIT_USAGE;
    case O_NOGROUND: o->scene.ground = false; return 0;
    case O_TRANS: return cli_vec3(CMD, "--translate", arg, false, &o->translate) ? 0 : CLI_EXIT_USAGE;
    case O_VEL: return cli_vec3(CMD, "--velocity", arg, false, &o->spring.velocity) ? 0 : CLI_EXIT_USAGE;
    case O_POV: o->pov = true; return 0;
    case O_RENDER: o->render = o->pov = true; return 0;
    case O_SIZE: return cli_size(CMD, "--size", arg, 8192, &o->width, &o->height) ? 0 : CLI_EXIT_USAGE;
    case O_MOVIE: o->movie = arg; o->render = o->pov = true; return 0;
    case O_VIDEO: o->video = arg; return 0;
    case O_QUIET: return cli_double(CMD, "--quiet-time", arg, 0, 1e6, &o->quiet_time) ? 0 : CLI_EXIT_USAGE;
    case O_OBST:
        if (o->nobst == MAX_OBSTACLES) return cli_usage(CMD, "--obstacle: at most %d obstacles", MAX_OBSTACLES);
        o->obstacles[o->nobst++] = arg;
        return 0;
    default:
        if (c == O_GROUND) o->scene.ground = true;
        if (c >= O_SS && c <= O_FRIC) return parse_number_opt(c, arg, o) ? 0 : CLI_EXIT_USAGE;
        return cli_usage(CMD, "unknown option");
    }
}

static int parse_args(int argc, char **argv, drop_opts *o)
{
    memset(o, 0, sizeof *o);
    o->spring = spn_mesh_spring_def_default();
    o->spring.vicinity = 0.3;
    o->scene = spn_mesh_scene_def_default();
    o->scene.ground = true;
    o->scene.restitution = o->scene.ground_restitution = 0.5;
    o->threshold = 0.01;
    o->frame_dt = 0.03;
    o->min_time = 0.1;
    o->max_time = 15.3;
    o->quiet_time = 0.2;
    o->width = 480;
    o->height = 360;
    optind = 1;
    opterr = 0;
    int c;
    while ((c = getopt_long(argc, argv, "o:h", long_opts, NULL)) != -1) {
        if (c == '?') return cli_usage(CMD, "unknown or incomplete option '%s'", argv[optind - 1]);
        int rc = parse_option(c, optarg, o);
        if (rc) return rc;
    }
    o->scene.ground_restitution = o->scene.restitution;
    o->scene.ground_friction = o->scene.friction;
    if (optind != argc - 1) return cli_usage(CMD, "expected one model file");
    o->model = argv[optind];
    if (!o->out) return cli_usage(CMD, "-o OUT is required");
    if (o->render && !spn_program_available("povray"))
        return cli_fail(CMD, "--render and --movie need the povray program (Debian package povray)");
    if ((o->movie || o->video) && !spn_program_available("ffmpeg"))
        return cli_fail(CMD, "--movie and --video need the ffmpeg program (Debian package ffmpeg)");
    return 0;
}

/* --fix I,J,...: flags per vertex. */
static int fixed_flags(const drop_opts *o, uint32_t n, bool **flags)
{
    *flags = NULL;
    if (!o->fix_list) return 0;
    *flags = calloc(n, sizeof **flags);
    if (!*flags) return cli_fail(CMD, "out of memory");
    const char *p = o->fix_list;
    while (*p) {
        char *end;
        long i = strtol(p, &end, 10);
        if (end == p || i < 0 || i >= (long)n || (*end && *end != ','))
            return cli_usage(CMD, "--fix: expected vertex indices in [0, %u) separated by commas, got '%s'", n, o->fix_list);
        (*flags)[i] = true;
        p = *end ? end + 1 : end;
    }
    return 0;
}

typedef struct drop_run {
    drop_opts *o;
    spn_mesh_scene *scene;
    spn_mesh *meshes; /* model, then obstacles */
    uint32_t nmesh;
    spn_pov_view_def view;
    frame_dir dir;
    double lowest;
    spn_frames *video;
    uint8_t *rgba;
} drop_run;

/* Lines on the ground, 0.25 m apart around the target, so the bounce shows. */
static spn_status ground_lines(spn_world *w, spn_vec3 centre, double y)
{
    spn_status st = SPN_OK;
    for (int k = -6; st == SPN_OK && k <= 6; k++)
        for (int axis = 0; st == SPN_OK && axis < 2; axis++) {
            spn_particle_def p = spn_particle_def_default();
            uint32_t a, b;
            p.fixed = true;
            double u = 0.25 * k;
            p.position = axis ? spn_v3(centre.x + u, y, centre.z - 1.5) : spn_v3(centre.x - 1.5, y, centre.z + u);
            st = spn_world_add_particle(w, &p, &a);
            p.position = axis ? spn_v3(centre.x + u, y, centre.z + 1.5) : spn_v3(centre.x + 1.5, y, centre.z + u);
            if (st == SPN_OK) st = spn_world_add_particle(w, &p, &b);
            spn_spring_def d = spn_spring_def_default();
            d.a = a;
            d.b = b;
            d.tag = SPN_THREAD_FRAME;
            if (st == SPN_OK) st = spn_world_add_spring(w, &d, NULL);
        }
    return st;
}

/* A frame of the video: the scene's stretch springs (the mesh edges) drawn by
 * the renderer from the POV camera's place. */
static spn_status video_frame(drop_run *r)
{
    spn_world *sw = spn_mesh_scene_world(r->scene), *w = spn_world_create(NULL);
    if (!w) return spn_error(SPN_ERR_NOMEM, "out of memory");
    spn_status st = SPN_OK;
    for (uint32_t i = 0; st == SPN_OK && i < spn_world_particle_count(sw); i++) {
        spn_particle_def p = spn_particle_def_default();
        p.position = spn_world_position(sw, i);
        p.fixed = true;
        st = spn_world_add_particle(w, &p, NULL);
    }
    for (uint32_t s = 0; st == SPN_OK && s < spn_world_spring_count(sw); s++) {
        spn_spring_info in = spn_world_spring(sw, s);
        if (in.tag != SPN_THREAD_STRETCH) continue;
        spn_spring_def d = spn_spring_def_default();
        d.a = in.a;
        d.b = in.b;
        d.tag = SPN_THREAD_CAPTURE; /* the renderer's finest thread */
        st = spn_world_add_spring(w, &d, NULL);
    }
    if (st == SPN_OK && r->o->scene.ground) st = ground_lines(w, r->view.target, r->o->scene.ground_y);
    spn_render_def def = spn_render_def_default();
    def.width = r->o->width;
    def.height = r->o->height;
    def.camera.kind = SPN_CAMERA_PERSPECTIVE;
    def.camera.eye = r->view.eye;
    def.camera.target = r->view.target;
    def.camera.fov_degrees = 2 * atan(tan(r->view.angle_degrees * SPN_PI / 360) * def.height / def.width) * 180 / SPN_PI;
    def.background_rgb[0] = 0.08, def.background_rgb[1] = 0.09, def.background_rgb[2] = 0.11;
    if (st == SPN_OK) st = spn_render_rgba(w, &def, r->rgba);
    if (st == SPN_OK) st = spn_frames_add(r->video, r->rgba);
    spn_world_destroy(w);
    return st;
}

static spn_status write_frame(void *ctx, spn_sink *sink)
{
    drop_run *r = ctx;
    spn_mesh now;
    spn_status st = spn_mesh_scene_object_mesh(r->scene, 0, &now);
    if (st != SPN_OK) return st;
    for (uint32_t i = 0; i < now.vertex_count; i++) r->lowest = fmin(r->lowest, now.vertices[i].y);
    if (r->video) st = video_frame(r);
    if (st != SPN_OK) {
        spn_mesh_free(&now);
        return st;
    }
    if (r->o->pov) {
        spn_mesh saved = r->meshes[0];
        r->meshes[0] = now;
        st = spn_pov_write_meshes(r->meshes, r->nmesh, &r->view, sink);
        r->meshes[0] = saved;
    } else {
        st = spn_mesh_write_obj(&now, sink);
    }
    spn_mesh_free(&now);
    return st;
}

static int build(drop_run *r)
{
    drop_opts *o = r->o;
    r->meshes = calloc(1 + (size_t)o->nobst, sizeof *r->meshes);
    if (!r->meshes) return cli_fail(CMD, "out of memory");
    for (int i = 0; i <= o->nobst; i++) {
        spn_status st = spn_mesh_load(i == 0 ? o->model : o->obstacles[i - 1], &r->meshes[i]);
        if (st != SPN_OK) return cli_fail_status(CMD, st);
        r->nmesh++;
    }
    for (uint32_t v = 0; v < r->meshes[0].vertex_count; v++)
        r->meshes[0].vertices[v] = spn_v3_add(r->meshes[0].vertices[v], o->translate);
    bool *flags;
    int rc = fixed_flags(o, r->meshes[0].vertex_count, &flags);
    o->spring.fixed_vertices = flags;
    spn_status st = rc ? SPN_OK : spn_mesh_scene_create(&o->scene, &r->scene);
    if (!rc && st == SPN_OK) st = spn_mesh_scene_add(r->scene, &r->meshes[0], &o->spring, NULL);
    spn_mesh_spring_def fixed = spn_mesh_spring_def_default();
    fixed.fixed = true;
    for (uint32_t i = 1; !rc && st == SPN_OK && i < r->nmesh; i++) st = spn_mesh_scene_add(r->scene, &r->meshes[i], &fixed, NULL);
    free(flags);
    o->spring.fixed_vertices = NULL;
    if (rc) return rc;
    if (st != SPN_OK) return cli_fail_status(CMD, st);
    spn_vec3 lo, hi, a, b;
    spn_mesh_bounds(&r->meshes[0], &lo, &hi);
    for (uint32_t i = 1; i < r->nmesh; i++) {
        spn_mesh_bounds(&r->meshes[i], &a, &b);
        lo = spn_v3(fmin(lo.x, a.x), fmin(lo.y, a.y), fmin(lo.z, a.z));
        hi = spn_v3(fmax(hi.x, b.x), fmax(hi.y, b.y), fmax(hi.z, b.z));
    }
    if (o->scene.ground) lo.y = fmin(lo.y, o->scene.ground_y);
    r->view = spn_pov_view_frame(lo, hi);
    r->view.ground = o->scene.ground;
    r->view.ground_y = o->scene.ground_y;
    return 0;
}

/* Advance frame by frame; *stable tells why it stopped. */
static spn_status simulate(drop_run *r, bool *stable, double *t, double *ke)
{
    const drop_opts *o = r->o;
    spn_status st = frame_dir_write(&r->dir, write_frame, r);
    *stable = false;
    *t = 0;
    *ke = spn_mesh_scene_kinetic(r->scene);
    double quiet_since = -1; /* when the energy last fell under the threshold */
    while (st == SPN_OK && *t < o->max_time - 1e-12) {
        double dt = fmin(o->frame_dt, o->max_time - *t);
        st = spn_mesh_scene_advance(r->scene, dt);
        *t += dt;
        if (st == SPN_OK) st = frame_dir_write(&r->dir, write_frame, r);
        *ke = spn_mesh_scene_kinetic(r->scene);
        if (*t < o->min_time || *ke >= o->threshold) {
            quiet_since = -1;
            continue;
        }
        if (quiet_since < 0) quiet_since = *t;
        if (*t - quiet_since >= o->quiet_time - 1e-12) {
            *stable = true;
            break;
        }
    }
    return st;
}

static int run(drop_run *r)
{
    drop_opts *o = r->o;
    int rc = build(r);
    if (rc) return rc;
    if (!frame_dir_open(&r->dir, CMD, o->out, o->pov ? "pov" : "obj")) return CLI_EXIT_FAIL;
    r->lowest = INFINITY;
    bool stable;
    double t, ke;
    spn_status st = SPN_OK;
    if (o->video) {
        r->rgba = malloc((size_t)o->width * (size_t)o->height * 4);
        st = r->rgba ? spn_frames_open(o->video, o->width, o->height, 1 / o->frame_dt, &r->video)
                     : spn_error(SPN_ERR_NOMEM, "out of memory");
    }
    if (st == SPN_OK) st = simulate(r, &stable, &t, &ke);
    if (r->video) {
        spn_status vs = spn_frames_close(r->video, st == SPN_OK);
        r->video = NULL;
        if (st == SPN_OK) st = vs;
    }
    if (st == SPN_OK && o->render)
        st = spn_pov_render_frames(o->out, r->dir.count, o->width, o->height, 1 / o->frame_dt, o->movie);
    if (st != SPN_OK) {
        frame_dir_discard(&r->dir);
        return cli_fail_status(CMD, st);
    }
    const spn_mesh_stats *ms = spn_mesh_scene_object_stats(r->scene, 0);
    printf("model: %u vertices (%u fixed), %u stretch, %u bend, %u vicinity springs; sub-step %.3g s\n",
           ms->particles, ms->fixed, ms->edges, ms->bend, ms->vicinity, spn_mesh_scene_substep(r->scene));
    printf("%s at t = %.4g s: kinetic energy %.4g J %s threshold %.4g J\n", stable ? "stable" : "max time reached", t,
           ke, stable ? "<" : ">=", o->threshold);
    printf("lowest point y = %.4g m; %llu contacts with obstacles; %d frames in %s\n", r->lowest,
           (unsigned long long)spn_mesh_scene_contacts(r->scene), r->dir.count, o->out);
    return 0;
}

int cmd_drop(int argc, char **argv)
{
    if (cli_wants_help(argc, argv)) {
        usage();
        return 0;
    }
    char **args = rewrite_legacy(argc, argv);
    if (!args) return cli_fail(CMD, "out of memory");
    drop_opts o;
    int rc = parse_args(argc, args, &o);
    drop_run r;
    memset(&r, 0, sizeof r);
    r.o = &o;
    if (!rc) rc = run(&r);
    spn_mesh_scene_destroy(r.scene);
    for (uint32_t i = 0; i < r.nmesh; i++) spn_mesh_free(&r.meshes[i]);
    free(r.meshes);
    free(r.rgba);
    for (int i = 0; i < argc; i++) free(args[i]);
    free(args);
    return rc;
}
