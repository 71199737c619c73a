/* The real-time viewer's private state. One window, one world: the main loop
 * (view_main.c) steps the world at real-time pace and draws it
 * (view_draw.c); keys, the mouse and scripted events (view_input.c) change
 * the state here. Scripts drive the viewer headless so tests can run it. */
#ifndef SPN_VIEW_INTERNAL_H
#define SPN_VIEW_INTERNAL_H

#include <spinneret/spinneret.h>

#include <GLFW/glfw3.h>

#define VIEW_MAX_ANCHORS 64
#define VIEW_MAX_EVENTS 1024

typedef enum view_event_kind {
    VIEW_EV_CLICK,      /* x y: left click at window pixel (x, y) */
    VIEW_EV_DRAG,       /* x0 y0 x1 y1 seconds: press, move, release */
    VIEW_EV_KEY,        /* a key name */
    VIEW_EV_SCREENSHOT, /* a path */
    VIEW_EV_QUIT
} view_event_kind;

typedef struct view_event {
    double time;
    view_event_kind kind;
    double a[5];
    int key;
    char path[256];
} view_event;

typedef struct view_opts {
    const char *file;         /* web file or mesh; NULL: build mode */
    bool build_mode;
    int width, height;
    spn_integrator solver;
    double dt;                /* simulation sub-step [s] */
    int headless_frames;      /* > 0: run this many frames at fixed pace, then quit */
    const char *screenshot;   /* written when the run ends */
    const char *script;
    const char *background;   /* PNG for F5 and build mode */
    uint64_t seed;
    const char *species;
    const char *method;
    bool method_given;        /* --method was on the command line */
} view_opts;

struct view_state {
    view_opts opt;
    GLFWwindow *win;
    spn_world *world;
    /* mesh faces (F4), when the file was a mesh */
    uint32_t *tris;
    uint32_t ntris;

    /* what is drawn */
    bool show_vertices, show_edges, show_energy, show_faces, show_background, show_dew, show_help;
    /* simulation switches */
    bool paused, single_step, gravity_on, gravity_reversed, wind_on;
    double wind_strength;     /* mean wind speed [m/s] */
    spn_air_field *air;       /* while the wind blows */
    spn_vec3 base_gravity;

    /* camera: orbit around `centre` */
    spn_vec3 centre;
    double distance, yaw, pitch, fov;
    double mvp[16];           /* column-major, for picking */
    int fb_w, fb_h;

    /* mouse */
    bool orbiting, dragging;
    double mouse_x, mouse_y;
    int grabbed;              /* particle id or -1 */
    bool grabbed_was_fixed;
    spn_vec3 grab_plane_point, grab_prev;

    /* build mode */
    spn_vec3 anchors[VIEW_MAX_ANCHORS];
    int nanchors;

    /* script */
    view_event events[VIEW_MAX_EVENTS];
    int nevents, next_event;
    int active_drag;          /* index of the scripted drag under way, or -1 */

    /* time and readout */
    double sim_time;          /* viewer clock [s] (fixed 1/60 per frame headless) */
    uint64_t frames;
    double fps, sim_ms;
    uint64_t stepped_frames;  /* frames in which the world was stepped */
    double sim_ms_total;
    unsigned bg_texture;
    int bg_w, bg_h;
    unsigned text_texture;
    bool quit;
    int exit_code;
};

typedef struct view_state view_state;

/* view_draw.c */
void view_draw(view_state *v);
void view_frame_camera(view_state *v);
/* Recompute the matrices used for picking (before input is handled). */
void view_update_camera(view_state *v);
bool view_project(const view_state *v, spn_vec3 p, double *sx, double *sy);
/* The point under window pixel (x, y) on the plane through `on` facing the camera. */
spn_vec3 view_unproject(const view_state *v, double x, double y, spn_vec3 on);
spn_status view_screenshot(view_state *v, const char *path);
spn_status view_load_background(view_state *v, const char *path);

/* view_world.c */
/* Open a web file, mesh or scene:NAME; 0, or an exit code after printing why. */
int view_open_file(view_state *v, const char *spec);

/* view_input.c */
void view_install_callbacks(view_state *v);
void view_key(view_state *v, int key);
void view_mouse_button(view_state *v, int button, bool press, double x, double y);
void view_mouse_move(view_state *v, double x, double y);
spn_status view_load_script(view_state *v, const char *path);
void view_run_script(view_state *v);
int view_key_from_name(const char *name);

/* view_wind.c */
void view_wind_update(view_state *v);            /* after toggling, a new strength or a new world */
void view_wind_prepare(view_state *v, double t0, double t1);
void view_wind_release(view_state *v);

/* view_main.c */
spn_status view_build_web(view_state *v);
void view_set_world(view_state *v, spn_world *w);
void view_step(view_state *v, double frame_dt);

#endif
