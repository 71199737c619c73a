/* `spinneret view`: the real-time viewer. Opens a web file or a mesh (or an
 * empty canvas in build mode), steps the world at real-time pace with the
 * chosen solver and draws it every frame. With --headless-frames the clock
 * advances 1/60 s per frame whatever the wall clock says, so scripted runs
 * are repeatable. */
#include "view_internal.h"
#include "cli.h"

#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

void view_set_world(view_state *v, spn_world *w)
{
    view_wind_release(v);
    spn_world_destroy(v->world);
    v->world = w;
    if (!w) return;
    v->base_gravity = spn_world_get_def(w)->gravity;
    if (spn_v3_len(v->base_gravity) == 0) v->base_gravity = spn_v3(0, -9.81, 0);
    spn_world_set_integrator(w, v->opt.solver);
    /* A live view needs a plausible step each frame, not a converged one:
     * 1e-3 cuts CG work several-fold (~500 -> tens of iterations in wind). */
    spn_world_set_solver_tolerance(w, 1e-3, 200);
    v->grabbed = -1;
    if (!v->opt.build_mode) view_frame_camera(v); /* a built web stays where it was clicked */
    view_wind_update(v);
}

void view_step(view_state *v, double frame_dt)
{
    if (!v->world) return;
    v->stepped_frames++;
    int n = (int)ceil(frame_dt / v->opt.dt - 1e-9);
    if (n < 1) n = 1;
    double t0 = now_seconds();
    view_wind_prepare(v, spn_world_time(v->world), spn_world_time(v->world) + frame_dt);
    for (int i = 0; i < n; i++) {
        spn_status st = spn_world_step(v->world, frame_dt / n);
        if (st != SPN_OK) {
            fprintf(stderr, "spinneret view: %s; paused (press s to stop motion, then space)\n", spn_last_error());
            v->paused = true;
            break;
        }
    }
    double ms = (now_seconds() - t0) * 1e3;
    v->sim_ms = v->stepped_frames == 1 ? ms : 0.9 * v->sim_ms + 0.1 * ms;
    v->sim_ms_total += ms;
}

static void usage(FILE *out)
{
    fprintf(out,
            "usage: spinneret view [FILE] [options]\n"
            "Simulate and draw a web file (.json) or a mesh (.obj, .ply) live; with no FILE\n"
            "(or --build) click anchor points on an empty canvas and press Enter to build a web.\n"
            "  --build               build mode\n"
            "  --size WxH            window size (default 1000x800)\n"
            "  --solver NAME         euler, symplectic, rk4, adaptive, implicit (default implicit)\n"
            "  --dt S                simulation sub-step in seconds (default: 1/60 for implicit,\n"
            "                        which is stable at a step per frame; 1/2000 for the others)\n"
            "  --background FILE     PNG shown behind the web (F5)\n"
            "  --species NAME        build mode: web species (default generic)\n"
            "  --method NAME         build mode: physical (Mehla) or geometric (the 2011 thesis);\n"
            "                        default: the species builder (geometric frame, species' radii and spiral)\n"
            "  --seed N              build mode: seed (n picks a new one)\n"
            "  --headless-frames N   run N frames at 1/60 s each, then quit\n"
            "  --screenshot FILE     write a PNG of the last frame\n"
            "  --script FILE         timed events: TIME click X Y | drag X0 Y0 X1 Y1 S | key NAME |\n"
            "                        screenshot PATH | quit\n"
            "Keys: h shows them all in the window.\n");
}

static int parse_args(int argc, char **argv, view_opts *o)
{
    static const struct option longs[] = {
        {"build", no_argument, NULL, 'b'},         {"size", required_argument, NULL, 'S'},
        {"solver", required_argument, NULL, 'v'},  {"dt", required_argument, NULL, 't'},
        {"background", required_argument, NULL, 'B'}, {"species", required_argument, NULL, 'p'},
        {"method", required_argument, NULL, 'm'},  {"seed", required_argument, NULL, 's'},
        {"headless-frames", required_argument, NULL, 'H'}, {"screenshot", required_argument, NULL, 'o'},
        {"script", required_argument, NULL, 'x'},  {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0}};
    optind = 1;
    int c;
    long n;
    while ((c = getopt_long(argc, argv, "h", longs, NULL)) != -1) {
        switch (c) {
        case 'b': o->build_mode = true; break;
        case 'S': if (!cli_size("view", "--size", optarg, 8192, &o->width, &o->height)) return 2; break;
        case 'v':
            if (spn_integrator_parse(optarg, &o->solver) != SPN_OK) return cli_usage("view", "--solver: %s", spn_last_error());
            break;
        case 't': if (!cli_double("view", "--dt", optarg, 1e-7, 0.1, &o->dt)) return 2; break;
        case 'B': o->background = optarg; break;
        case 'p': o->species = optarg; break;
        case 'm':
            if (strcmp(optarg, "physical") != 0 && strcmp(optarg, "geometric") != 0)
                return cli_usage("view", "--method: expected physical or geometric, got '%s'", optarg);
            o->method = optarg;
            o->method_given = true;
            break;
        case 's': if (!cli_u64("view", "--seed", optarg, &o->seed)) return 2; break;
        case 'H': if (!cli_int("view", "--headless-frames", optarg, 1, 1000000, &n)) return 2; o->headless_frames = (int)n; break;
        case 'o': o->screenshot = optarg; break;
        case 'x': o->script = optarg; break;
        case 'h': usage(stdout); return -1;
        default: return cli_usage("view", "unknown option");
        }
    }
    if (optind < argc) o->file = argv[optind++];
    if (optind < argc) return cli_usage("view", "unexpected argument '%s'", argv[optind]);
    if (!o->file) o->build_mode = true;
    if (o->file && o->build_mode) return cli_usage("view", "--build takes no FILE");
    if (o->screenshot && !o->headless_frames && !o->script)
        return cli_usage("view", "--screenshot needs --headless-frames or --script");
    return 0;
}

static void quiet_glfw_error(int code, const char *text) { (void)code, (void)text; }

static void view_init_state(view_state *v)
{
    v->show_edges = true;
    v->show_background = true;
    v->gravity_on = true;
    v->wind_strength = 2.0;
    v->fov = 40;
    v->grabbed = -1;
    v->active_drag = -1;
    v->base_gravity = spn_v3(0, -9.81, 0);
    v->distance = 1;
}

static void run_loop(view_state *v)
{
    double start = glfwGetTime(), last = start, fps_t = start;
    uint64_t fps_frames = 0;
    while (!v->quit && !glfwWindowShouldClose(v->win)) {
        v->sim_time = v->opt.headless_frames > 0 ? (double)v->frames / 60.0 : glfwGetTime() - start;
        view_update_camera(v);
        view_run_script(v);
        if (!v->paused || v->single_step) view_step(v, 1.0 / 60.0);
        v->single_step = false;
        view_draw(v);
        if (v->opt.headless_frames > 0 && v->frames + 1 >= (uint64_t)v->opt.headless_frames) break;
        glfwSwapBuffers(v->win);
        glfwPollEvents();
        v->frames++;
        fps_frames++;
        double t = glfwGetTime();
        if (t - fps_t >= 0.5) {
            v->fps = fps_frames / (t - fps_t);
            fps_frames = 0;
            fps_t = t;
        }
        last = t;
    }
    (void)last;
}

int spn_view_main(int argc, char **argv)
{
    static view_state state;
    view_state *v = &state;
    memset(v, 0, sizeof *v);
    view_init_state(v);
    v->opt.width = 1000;
    v->opt.height = 800;
    v->opt.solver = SPN_INTEGRATOR_IMPLICIT;
    v->opt.dt = 1.0 / 240.0;
    v->opt.seed = 1;
    v->opt.species = "generic";
    v->opt.method = "geometric";
    v->opt.dt = 0;
    int rc = parse_args(argc, argv, &v->opt);
    if (rc) return rc < 0 ? 0 : rc;
    if (v->opt.dt == 0) v->opt.dt = v->opt.solver == SPN_INTEGRATOR_IMPLICIT ? 1.0 / 60.0 : 1.0 / 2000.0;
    if (v->opt.script && view_load_script(v, v->opt.script) != SPN_OK) return cli_fail("view", "%s", spn_last_error());

    glfwSetErrorCallback(quiet_glfw_error);
    if (!glfwInit())
        return cli_fail("view", "no display: set DISPLAY, or run it under xvfb-run (Debian package xvfb)");
    glfwWindowHint(GLFW_SAMPLES, 4);
    v->win = glfwCreateWindow(v->opt.width, v->opt.height, "spinneret view", NULL, NULL);
    if (!v->win) {
        glfwTerminate();
        return cli_fail("view", "cannot open an OpenGL window on this display");
    }
    glfwMakeContextCurrent(v->win);
    glfwSwapInterval(v->opt.headless_frames > 0 ? 0 : 1);
    view_install_callbacks(v);
    glfwGetFramebufferSize(v->win, &v->fb_w, &v->fb_h);

    int code = 0;
    if (v->opt.background && view_load_background(v, v->opt.background) != SPN_OK)
        code = cli_fail("view", "%s", spn_last_error());
    if (code == 0 && v->opt.file) code = view_open_file(v, v->opt.file);
    if (code == 0) {
        if (!v->world) view_frame_camera(v);
        run_loop(v);
        if (v->opt.screenshot) {
            view_draw(v);
            if (view_screenshot(v, v->opt.screenshot) != SPN_OK) code = cli_fail("view", "%s", spn_last_error());
        }
        if (v->exit_code) code = v->exit_code;
        if (v->opt.headless_frames > 0 && v->stepped_frames > 0)
            fprintf(stderr, "spinneret view: %llu frames simulated, %.2f ms of simulation per frame on average "
                            "(real time allows 16.7)\n",
                    (unsigned long long)v->stepped_frames, v->sim_ms_total / (double)v->stepped_frames);
    }
    view_set_world(v, NULL);
    free(v->tris);
    glfwDestroyWindow(v->win);
    glfwTerminate();
    return code;
}
