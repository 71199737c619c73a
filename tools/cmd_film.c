/* spinneret film: the POV film maker (Juhasz & Bercovici). A POV-Ray scene of
 * mesh2 objects marked with `#local spring_system_*` declarations is
 * simulated (free objects under gravity, colliding with every other object)
 * and written back as one scene per frame, identical to the input except
 * for the vertex coordinates of the simulated objects; --render renders the
 * frames with povray and encodes a movie with ffmpeg. */
#include "cli.h"
#include "frame_dir.h"

#include <spinneret/mesh.h>

#include <getopt.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define CMD "film"

static void usage(void)
{
    printf("usage: spinneret film SCENE.pov [options] -o DIR\n"
           "Simulate the mesh2 objects of a POV-Ray scene and write one scene per frame.\n"
           "Mark objects inside their mesh2 block (see docs/mesh.md):\n"
           "  #local spring_system_fixed = true;          an obstacle (unmarked mesh2 too)\n"
           "  #local spring_system_ks = 600; _kb, _ds, _db, _mass (total, kg), _vicinity (m)\n"
           "  #local spring_system_fixed = false;         simulated\n"
           "  #local spring_system_fixed_vertices = array[2] {0, 20};   pinned vertices\n\n"
           "  -o, --output DIR      frames DIR/frame_00000.pov ...\n"
           "  --max-time S          simulated time [s] (2; 0 writes the scene once)\n"
           "  --fps F               frames per second (25)\n"
           "  --gravity X,Y,Z       [m/s^2] (0,-9.81,0)\n"
           "  --drag D              air drag per unit mass [1/s] (0.5)\n"
           "  --restitution R       contacts, in [0, 1] (0.3)\n"
           "  --friction F          contacts, in [0, 1] (0.5)\n"
           "  --skin D              distance kept from other objects [m] (0.005)\n"
           "  --render              render with povray and encode DIR/movie.mp4 with ffmpeg\n"
           "  --size WxH            render size (480x360)\n"
           "  --movie FILE          the movie's path (implies --render)\n");
}

typedef struct film_opts {
    const char *scene, *out, *movie;
    double max_time, fps;
    spn_mesh_scene_def def;
    bool render;
    int width, height;
} film_opts;

enum { O_MAXT = 256, O_FPS, O_GRAV, O_DRAG, O_REST, O_FRIC, O_SKIN, O_RENDER, O_SIZE, O_MOVIE };

static int parse_option(int c, const char *arg, film_opts *o)
{
    switch (c) {
    case 'o': o->out = arg; return 0;
    case O_MAXT: return cli_double(CMD, "--max-time", arg, 0, 1e5, &o->max_time) ? 0 : CLI_EXIT_USAGE;
    case O_FPS: return cli_double(CMD, "--fps", arg, 0.01, 1000, &o->fps) ? 0 : CLI_EXIT_USAGE;
    case O_GRAV: return cli_vec3(CMD, "--gravity", arg, false, &o->def.world.gravity) ? 0 : CLI_EXIT_USAGE;
    case O_DRAG: return cli_double(CMD, "--drag", arg, 0, 1e3, &o->def.world.drag) ? 0 : CLI_EXIT_USAGE;
    case O_REST: return cli_double(CMD, "--restitution", arg, 0, 1, &o->def.restitution) ? 0 : CLI_EXIT_USAGE;
    case O_FRIC: return cli_double(CMD, "--friction", arg, 0, 1, &o->def.friction) ? 0 : CLI_EXIT_USAGE;
    case O_SKIN: return cli_double(CMD, "--skin", arg, 1e-7, 1, &o->def.skin) ? 0 : CLI_EXIT_USAGE;
    case O_RENDER: o->render = true; return 0;
    case O_SIZE: return cli_size(CMD, "--size", arg, 8192, &o->width, &o->height) ? 0 : CLI_EXIT_USAGE;
    case O_MOVIE: o->movie = arg; o->render = true; return 0;
    default: return cli_usage(CMD, "unknown option");
    }
}

static int parse_args(int argc, char **argv, film_opts *o)
{
    static const struct option opts[] = {
        {"output", required_argument, 0, 'o'},    {"max-time", required_argument, 0, O_MAXT},
        {"fps", required_argument, 0, O_FPS},      {"gravity", required_argument, 0, O_GRAV},
        {"drag", required_argument, 0, O_DRAG},
        {"restitution", required_argument, 0, O_REST}, {"friction", required_argument, 0, O_FRIC},
        {"skin", required_argument, 0, O_SKIN},   {"render", no_argument, 0, O_RENDER},
        {"size", required_argument, 0, O_SIZE},   {"movie", required_argument, 0, O_MOVIE},
        {"help", no_argument, 0, 'h'},            {0, 0, 0, 0}};
    memset(o, 0, sizeof *o);
    o->max_time = 2;
    o->fps = 25;
    o->def = spn_mesh_scene_def_default();
    o->def.friction = 0.5;
    o->def.skin = 0.005;
    o->def.world.drag = 0.5; /* a little air, so pinned cloth comes to hang */
    o->width = 480;
    o->height = 360;
    optind = 1;
    opterr = 0;
    int c;
    while ((c = getopt_long(argc, argv, "o:h", opts, NULL)) != -1) {
        if (c == '?') return cli_usage(CMD, "unknown or incomplete option '%s'", argv[optind - 1]);
        int rc = parse_option(c, optarg, o);
        if (rc) return rc;
    }
    if (optind != argc - 1) return cli_usage(CMD, "expected one scene file");
    o->scene = argv[optind];
    if (!o->out) return cli_usage(CMD, "-o DIR is required");
    if (o->render && !(spn_program_available("povray") && spn_program_available("ffmpeg")))
        return cli_fail(CMD, "--render needs the povray and ffmpeg programs (Debian packages povray, ffmpeg)");
    return 0;
}

typedef struct film_run {
    spn_pov_scene *pov;
    spn_mesh_scene *scene;
    const spn_vec3 **verts; /* per object: its current vertices, NULL for obstacles */
} film_run;

static spn_status write_frame(void *ctx, spn_sink *sink)
{
    film_run *r = ctx;
    spn_world *w = spn_mesh_scene_world(r->scene);
    uint32_t n = spn_pov_scene_object_count(r->pov);
    for (uint32_t i = 0; i < n; i++) {
        const spn_mesh_stats *st = spn_mesh_scene_object_stats(r->scene, i);
        r->verts[i] = st->fixed == st->particles ? NULL : spn_world_positions(w) + st->first_particle;
    }
    return spn_pov_scene_write(r->pov, r->verts, sink);
}

static int build(const film_opts *o, film_run *r)
{
    spn_status st = spn_pov_scene_load(o->scene, &r->pov);
    if (st == SPN_OK) st = spn_mesh_scene_create(&o->def, &r->scene);
    if (st != SPN_OK) return cli_fail_status(CMD, st);
    uint32_t n = spn_pov_scene_object_count(r->pov), free_objects = 0;
    r->verts = calloc(n, sizeof *r->verts);
    if (!r->verts) return cli_fail(CMD, "out of memory");
    for (uint32_t i = 0; i < n; i++) {
        spn_mesh_spring_def d = spn_pov_scene_spring_def(r->pov, i);
        st = spn_mesh_scene_add(r->scene, spn_pov_scene_mesh(r->pov, i), &d, NULL);
        if (st != SPN_OK)
            return cli_fail(CMD, "%s:%d: mesh2: %s", o->scene, spn_pov_scene_object_line(r->pov, i), spn_last_error());
        free_objects += !d.fixed;
    }
    printf("%u mesh2 objects, %u simulated, %u particles, %u springs\n", n, free_objects,
           spn_world_particle_count(spn_mesh_scene_world(r->scene)), spn_world_spring_count(spn_mesh_scene_world(r->scene)));
    return 0;
}

static int run(const film_opts *o, film_run *r)
{
    int rc = build(o, r);
    if (rc) return rc;
    frame_dir dir;
    if (!frame_dir_open(&dir, CMD, o->out, "pov")) return CLI_EXIT_FAIL;
    int frames = (int)floor(o->max_time * o->fps + 1e-9) + 1;
    spn_status st = frame_dir_write(&dir, write_frame, r);
    for (int f = 1; st == SPN_OK && f < frames; f++) {
        st = spn_mesh_scene_advance(r->scene, 1 / o->fps);
        if (st == SPN_OK) st = frame_dir_write(&dir, write_frame, r);
    }
    char movie[4200];
    snprintf(movie, sizeof movie, "%s/movie.mp4", o->out);
    if (st == SPN_OK && o->render)
        st = spn_pov_render_frames(o->out, dir.count, o->width, o->height, o->fps, o->movie ? o->movie : movie);
    if (st != SPN_OK) {
        frame_dir_discard(&dir);
        return cli_fail_status(CMD, st);
    }
    printf("%d frames (%.4g s at %g fps) in %s; %llu contacts; sub-step %.3g s%s%s\n", dir.count,
           (dir.count - 1) / o->fps, o->fps, o->out, (unsigned long long)spn_mesh_scene_contacts(r->scene),
           spn_mesh_scene_substep(r->scene), o->render ? "; movie " : "", o->render ? (o->movie ? o->movie : movie) : "");
    return 0;
}

int cmd_film(int argc, char **argv)
{
    if (cli_wants_help(argc, argv)) {
        usage();
        return 0;
    }
    film_opts o;
    int rc = parse_args(argc, argv, &o);
    film_run r = {0};
    if (!rc) rc = run(&o, &r);
    free(r.verts);
    spn_mesh_scene_destroy(r.scene);
    spn_pov_scene_destroy(r.pov);
    return rc;
}
