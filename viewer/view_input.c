/* Input: keys (the spring-system demo's F1-F5, r, s, g, and ours), the mouse
 * (pick and drag a particle, orbit, zoom; click anchors in build mode), and
 * scripts: timed events read from a file so the viewer can drive itself
 * under Xvfb in the tests. Script lines, '#' starts a comment:
 *   TIME click X Y                    left click at window pixel (X, Y)
 *   TIME drag X0 Y0 X1 Y1 SECONDS     press, move in a straight line, release
 *   TIME key NAME                     F1..F5, Enter, Space, Backspace, Escape, or a character
 *   TIME screenshot PATH
 *   TIME quit
 * TIME is the viewer clock in seconds (1/60 s per frame when headless). */
#include "view_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const struct {
    const char *name;
    int key;
} key_names[] = {{"F1", GLFW_KEY_F1},       {"F2", GLFW_KEY_F2},         {"F3", GLFW_KEY_F3},
                 {"F4", GLFW_KEY_F4},       {"F5", GLFW_KEY_F5},         {"Enter", GLFW_KEY_ENTER},
                 {"Space", GLFW_KEY_SPACE}, {"Backspace", GLFW_KEY_BACKSPACE}, {"Escape", GLFW_KEY_ESCAPE}};

int view_key_from_name(const char *name)
{
    for (size_t i = 0; i < sizeof key_names / sizeof key_names[0]; i++)
        if (strcmp(name, key_names[i].name) == 0) return key_names[i].key;
    if (strlen(name) != 1) return -1;
    char c = name[0];
    if (c >= 'a' && c <= 'z') return GLFW_KEY_A + (c - 'a');
    if (c == '.') return GLFW_KEY_PERIOD;
    if (c == '[') return GLFW_KEY_LEFT_BRACKET;
    if (c == ']') return GLFW_KEY_RIGHT_BRACKET;
    return -1;
}

static void apply_gravity(view_state *v)
{
    spn_vec3 g = v->gravity_on ? v->base_gravity : spn_v3(0, 0, 0);
    if (v->gravity_reversed) g = spn_v3_scale(g, -1);
    if (v->world) spn_world_set_gravity(v->world, g);
}

static void stop_motion(view_state *v)
{
    if (!v->world) return;
    for (uint32_t i = 0; i < spn_world_particle_count(v->world); i++) spn_world_set_velocity(v->world, i, spn_v3(0, 0, 0));
}

static void take_screenshot(view_state *v)
{
    char path[64];
    snprintf(path, sizeof path, "spinneret-view-%04llu.png", (unsigned long long)v->frames);
    view_draw(v);
    if (view_screenshot(v, path) == SPN_OK) fprintf(stderr, "spinneret view: wrote %s\n", path);
    else fprintf(stderr, "spinneret view: %s\n", spn_last_error());
}

void view_key(view_state *v, int key)
{
    switch (key) {
    case GLFW_KEY_F1: v->show_vertices = !v->show_vertices; break;
    case GLFW_KEY_F2: v->show_edges = !v->show_edges; break;
    case GLFW_KEY_F3: v->show_energy = !v->show_energy; break;
    case GLFW_KEY_F4: v->show_faces = !v->show_faces; break;
    case GLFW_KEY_F5: v->show_background = !v->show_background; break;
    case GLFW_KEY_R: v->gravity_reversed = !v->gravity_reversed; apply_gravity(v); break;
    case GLFW_KEY_G: v->gravity_on = !v->gravity_on; apply_gravity(v); break;
    case GLFW_KEY_S: stop_motion(v); break;
    case GLFW_KEY_SPACE: v->paused = !v->paused; break;
    case GLFW_KEY_PERIOD: v->paused = true; v->single_step = true; break;
    case GLFW_KEY_W: v->wind_on = !v->wind_on; view_wind_update(v); break;
    case GLFW_KEY_LEFT_BRACKET: v->wind_strength = fmax(0.0, v->wind_strength / 1.25); view_wind_update(v); break;
    case GLFW_KEY_RIGHT_BRACKET: v->wind_strength = fmin(50.0, v->wind_strength * 1.25 + 0.01); view_wind_update(v); break;
    case GLFW_KEY_D: v->show_dew = !v->show_dew; break;
    case GLFW_KEY_H: v->show_help = !v->show_help; break;
    case GLFW_KEY_P: take_screenshot(v); break;
    case GLFW_KEY_BACKSPACE: if (v->opt.build_mode && !v->world && v->nanchors > 0) v->nanchors--; break;
    case GLFW_KEY_ENTER:
        if (v->opt.build_mode && !v->world && view_build_web(v) != SPN_OK)
            fprintf(stderr, "spinneret view: %s\n", spn_last_error());
        break;
    case GLFW_KEY_N:
        if (v->opt.build_mode && v->nanchors >= 3) {
            v->opt.seed++;
            if (view_build_web(v) != SPN_OK) fprintf(stderr, "spinneret view: %s\n", spn_last_error());
        }
        break;
    case GLFW_KEY_ESCAPE: v->quit = true; break;
    default: break;
    }
}

static int pick_particle(view_state *v, double x, double y)
{
    if (!v->world) return -1;
    int best = -1;
    double best_d2 = 14.0 * 14.0;
    for (uint32_t i = 0; i < spn_world_particle_count(v->world); i++) {
        double sx, sy;
        if (!view_project(v, spn_world_position(v->world, i), &sx, &sy)) continue;
        double d2 = (sx - x) * (sx - x) + (sy - y) * (sy - y);
        if (d2 < best_d2) {
            best_d2 = d2;
            best = (int)i;
        }
    }
    return best;
}

void view_mouse_button(view_state *v, int button, bool press, double x, double y)
{
    v->mouse_x = x;
    v->mouse_y = y;
    if (!press) {
        if (v->grabbed >= 0 && !v->grabbed_was_fixed) spn_world_set_fixed(v->world, (uint32_t)v->grabbed, false);
        v->grabbed = -1;
        v->orbiting = false;
        return;
    }
    if (button == GLFW_MOUSE_BUTTON_LEFT && v->opt.build_mode && !v->world) {
        if (v->nanchors < VIEW_MAX_ANCHORS) v->anchors[v->nanchors++] = view_unproject(v, x, y, v->centre);
        return;
    }
    int i = button == GLFW_MOUSE_BUTTON_LEFT ? pick_particle(v, x, y) : -1;
    if (i < 0) {
        v->orbiting = true;
        return;
    }
    /* A grabbed particle follows the mouse kinematically; its threads pull
     * the rest of the web, which answers physically. */
    v->grabbed = i;
    v->grabbed_was_fixed = spn_world_is_fixed(v->world, (uint32_t)i);
    v->grab_plane_point = spn_world_position(v->world, (uint32_t)i);
    v->grab_prev = v->grab_plane_point;
    spn_world_set_fixed(v->world, (uint32_t)i, true);
}

void view_mouse_move(view_state *v, double x, double y)
{
    double dx = x - v->mouse_x, dy = y - v->mouse_y;
    v->mouse_x = x;
    v->mouse_y = y;
    if (v->grabbed >= 0) {
        /* a point that is not finite (a degenerate camera): the particle stays */
        spn_vec3 p = view_unproject(v, x, y, v->grab_plane_point);
        if (spn_world_set_position(v->world, (uint32_t)v->grabbed, p) == SPN_OK) v->grab_plane_point = p;
    } else if (v->orbiting) {
        v->yaw -= dx * 0.008;
        v->pitch = fmax(-1.5, fmin(1.5, v->pitch + dy * 0.008));
    }
}

static void on_key(GLFWwindow *win, int key, int scancode, int action, int mods)
{
    (void)scancode, (void)mods;
    if (action == GLFW_PRESS) view_key(glfwGetWindowUserPointer(win), key);
}

static void on_button(GLFWwindow *win, int button, int action, int mods)
{
    (void)mods;
    double x, y;
    glfwGetCursorPos(win, &x, &y);
    view_mouse_button(glfwGetWindowUserPointer(win), button, action == GLFW_PRESS, x, y);
}

static void on_move(GLFWwindow *win, double x, double y) { view_mouse_move(glfwGetWindowUserPointer(win), x, y); }

static void on_scroll(GLFWwindow *win, double dx, double dy)
{
    (void)dx;
    view_state *v = glfwGetWindowUserPointer(win);
    v->distance *= pow(0.9, dy);
}

void view_install_callbacks(view_state *v)
{
    glfwSetWindowUserPointer(v->win, v);
    glfwSetKeyCallback(v->win, on_key);
    glfwSetMouseButtonCallback(v->win, on_button);
    glfwSetCursorPosCallback(v->win, on_move);
    glfwSetScrollCallback(v->win, on_scroll);
}

static spn_status parse_event(const char *path, int line, char *text, view_event *ev)
{
    char verb[32] = "", arg[256] = "";
    int n = 0;
    if (sscanf(text, "%lf %31s%n", &ev->time, verb, &n) < 2 || !isfinite(ev->time) || ev->time < 0)
        return spn_error(SPN_ERR_FORMAT, "%s:%d: expected 'TIME EVENT ...' with TIME >= 0", path, line);
    const char *rest = text + n;
    if (strcmp(verb, "click") == 0) {
        ev->kind = VIEW_EV_CLICK;
        if (sscanf(rest, "%lf %lf", &ev->a[0], &ev->a[1]) != 2)
            return spn_error(SPN_ERR_FORMAT, "%s:%d: click needs X Y", path, line);
    } else if (strcmp(verb, "drag") == 0) {
        ev->kind = VIEW_EV_DRAG;
        if (sscanf(rest, "%lf %lf %lf %lf %lf", &ev->a[0], &ev->a[1], &ev->a[2], &ev->a[3], &ev->a[4]) != 5 ||
            !(ev->a[4] > 0))
            return spn_error(SPN_ERR_FORMAT, "%s:%d: drag needs X0 Y0 X1 Y1 SECONDS (> 0)", path, line);
    } else if (strcmp(verb, "key") == 0) {
        ev->kind = VIEW_EV_KEY;
        if (sscanf(rest, "%255s", arg) != 1 || (ev->key = view_key_from_name(arg)) < 0)
            return spn_error(SPN_ERR_FORMAT, "%s:%d: unknown key '%s'", path, line, arg);
    } else if (strcmp(verb, "screenshot") == 0) {
        ev->kind = VIEW_EV_SCREENSHOT;
        if (sscanf(rest, "%255s", ev->path) != 1)
            return spn_error(SPN_ERR_FORMAT, "%s:%d: screenshot needs a path", path, line);
    } else if (strcmp(verb, "quit") == 0) {
        ev->kind = VIEW_EV_QUIT;
    } else {
        return spn_error(SPN_ERR_FORMAT, "%s:%d: unknown event '%s' (click, drag, key, screenshot, quit)", path, line,
                         verb);
    }
    return SPN_OK;
}

spn_status view_load_script(view_state *v, const char *path)
{
    FILE *fp = fopen(path, "r");
    if (!fp) return spn_error(SPN_ERR_IO, "%s: cannot read the script", path);
    char text[512];
    int line = 0;
    spn_status st = SPN_OK;
    while (st == SPN_OK && fgets(text, sizeof text, fp)) {
        line++;
        char *hash = strchr(text, '#');
        if (hash) *hash = '\0';
        if (strspn(text, " \t\r\n") == strlen(text)) continue;
        if (v->nevents == VIEW_MAX_EVENTS) {
            st = spn_error(SPN_ERR_FORMAT, "%s:%d: more than %d events", path, line, VIEW_MAX_EVENTS);
            break;
        }
        view_event *ev = &v->events[v->nevents];
        st = parse_event(path, line, text, ev);
        if (st == SPN_OK && v->nevents > 0 && ev->time < v->events[v->nevents - 1].time)
            st = spn_error(SPN_ERR_FORMAT, "%s:%d: events must be in time order", path, line);
        if (st == SPN_OK) v->nevents++;
    }
    fclose(fp);
    return st;
}

static void continue_drag(view_state *v)
{
    const view_event *ev = &v->events[v->active_drag];
    double f = (v->sim_time - ev->time) / ev->a[4];
    if (f >= 1) {
        view_mouse_move(v, ev->a[2], ev->a[3]);
        view_mouse_button(v, GLFW_MOUSE_BUTTON_LEFT, false, ev->a[2], ev->a[3]);
        v->active_drag = -1;
        return;
    }
    view_mouse_move(v, ev->a[0] + f * (ev->a[2] - ev->a[0]), ev->a[1] + f * (ev->a[3] - ev->a[1]));
}

void view_run_script(view_state *v)
{
    if (v->active_drag >= 0) continue_drag(v);
    while (v->next_event < v->nevents && v->events[v->next_event].time <= v->sim_time + 1e-9) {
        view_event *ev = &v->events[v->next_event++];
        switch (ev->kind) {
        case VIEW_EV_CLICK:
            view_mouse_button(v, GLFW_MOUSE_BUTTON_LEFT, true, ev->a[0], ev->a[1]);
            view_mouse_button(v, GLFW_MOUSE_BUTTON_LEFT, false, ev->a[0], ev->a[1]);
            break;
        case VIEW_EV_DRAG:
            v->mouse_x = ev->a[0];
            v->mouse_y = ev->a[1];
            view_mouse_button(v, GLFW_MOUSE_BUTTON_LEFT, true, ev->a[0], ev->a[1]);
            v->active_drag = (int)(ev - v->events);
            break;
        case VIEW_EV_KEY: view_key(v, ev->key); break;
        case VIEW_EV_SCREENSHOT:
            view_draw(v);
            if (view_screenshot(v, ev->path) != SPN_OK) {
                fprintf(stderr, "spinneret view: %s\n", spn_last_error());
                v->exit_code = 1;
            }
            break;
        case VIEW_EV_QUIT: v->quit = true; break;
        }
    }
}
