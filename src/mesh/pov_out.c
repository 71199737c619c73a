/* POV-Ray output: whole scenes of meshes for the drop program (mesh2 with
 * smooth normals for the model), and rendering of frame folders with the
 * povray program, then a movie with ffmpeg. povray's default I/O security
 * only lets it write below its working directory, so it is run from inside
 * the frame folder with relative names. Programs are started with fork/exec
 * and an argument vector (no shell), so paths need no quoting. */
#include "mesh_internal.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

spn_pov_view_def spn_pov_view_frame(spn_vec3 lo, spn_vec3 hi)
{
    spn_pov_view_def v;
    memset(&v, 0, sizeof v);
    spn_vec3 c = spn_v3_scale(spn_v3_add(lo, hi), 0.5);
    double r = 0.5 * spn_v3_len(spn_v3_sub(hi, lo));
    if (!(r > 0)) r = 1;
    v.angle_degrees = 45;
    double dist = 1.15 * r / tan(0.5 * v.angle_degrees * SPN_PI / 180);
    v.target = c;
    v.eye = spn_v3_add(c, spn_v3(0.35 * dist, 0.45 * dist, -dist));
    v.ground = true;
    v.ground_y = 0;
    return v;
}

static void vertex_normals(const spn_mesh *m, spn_vec3 *n)
{
    memset(n, 0, m->vertex_count * sizeof *n);
    for (uint32_t t = 0; t < m->triangle_count; t++) {
        const uint32_t *v = m->triangles + 3 * t;
        spn_vec3 f = spn_v3_cross(spn_v3_sub(m->vertices[v[1]], m->vertices[v[0]]),
                                  spn_v3_sub(m->vertices[v[2]], m->vertices[v[0]]));
        for (int k = 0; k < 3; k++) n[v[k]] = spn_v3_add(n[v[k]], f); /* area-weighted */
    }
    for (uint32_t i = 0; i < m->vertex_count; i++) {
        n[i] = spn_v3_norm(n[i]);
        if (spn_v3_len(n[i]) == 0) n[i] = spn_v3(0, 1, 0);
    }
}

static spn_status write_vectors(spn_sink *s, const char *block, const spn_vec3 *v, uint32_t n)
{
    spn_status st = spn_sink_printf(s, "  %s { %u", block, n);
    for (uint32_t i = 0; st == SPN_OK && i < n; i++)
        st = spn_sink_printf(s, ",%s<%.7g, %.7g, %.7g>", i % 3 ? " " : "\n    ", v[i].x, v[i].y, v[i].z);
    return st == SPN_OK ? spn_sink_printf(s, "\n  }\n") : st;
}

static spn_status write_mesh2(spn_sink *s, const spn_mesh *m, bool smooth, const char *texture)
{
    spn_status st = spn_sink_printf(s, "mesh2 {\n");
    if (st == SPN_OK) st = write_vectors(s, "vertex_vectors", m->vertices, m->vertex_count);
    if (st == SPN_OK && smooth) {
        spn_vec3 *n = malloc(m->vertex_count * sizeof *n);
        if (!n) return spn_error(SPN_ERR_NOMEM, "out of memory");
        vertex_normals(m, n);
        st = write_vectors(s, "normal_vectors", n, m->vertex_count);
        free(n);
    }
    if (st == SPN_OK) st = spn_sink_printf(s, "  face_indices { %u", m->triangle_count);
    for (uint32_t t = 0; st == SPN_OK && t < m->triangle_count; t++) {
        const uint32_t *v = m->triangles + 3 * t;
        st = spn_sink_printf(s, ",%s<%u, %u, %u>", t % 4 ? " " : "\n    ", v[0], v[1], v[2]);
    }
    if (st == SPN_OK) st = spn_sink_printf(s, "\n  }\n  %s\n}\n\n", texture);
    return st;
}

spn_status spn_pov_write_meshes(const spn_mesh *meshes, uint32_t count, const spn_pov_view_def *view, spn_sink *sink)
{
    const spn_pov_view_def *v = view;
    spn_status st = spn_sink_printf(sink,
        "// written by spinneret drop\n#version 3.7;\nglobal_settings { assumed_gamma 1.0 }\n"
        "camera { location <%.6g, %.6g, %.6g> look_at <%.6g, %.6g, %.6g> angle %.6g }\n"
        "light_source { <%.6g, %.6g, %.6g> color rgb 1 }\n"
        "light_source { <%.6g, %.6g, %.6g> color rgb 0.35 shadowless }\n"
        "background { color rgb <0.75, 0.82, 0.9> }\n\n",
        v->eye.x, v->eye.y, v->eye.z, v->target.x, v->target.y, v->target.z, v->angle_degrees,
        v->eye.x + 2, v->eye.y + 4, v->eye.z - 1, v->eye.x - 4, v->eye.y + 1, v->eye.z);
    if (st == SPN_OK && v->ground)
        st = spn_sink_printf(sink, "plane { y, %.6g texture { pigment { checker color rgb 0.9 color rgb 0.55 "
                                   "scale 0.25 } finish { diffuse 0.8 } } }\n\n", v->ground_y);
    for (uint32_t i = 0; st == SPN_OK && i < count; i++)
        st = write_mesh2(sink, &meshes[i], i == 0,
                         i == 0 ? "texture { pigment { color rgb <0.2, 0.4, 0.9> } finish { phong 0.6 diffuse 0.8 } }"
                                : "texture { pigment { color rgb <0.55, 0.35, 0.2> } finish { diffuse 0.8 } }");
    return st;
}

bool spn_program_available(const char *program)
{
    const char *path = getenv("PATH");
    if (!path) return false;
    size_t n = strlen(program);
    while (*path) {
        const char *colon = strchr(path, ':');
        size_t len = colon ? (size_t)(colon - path) : strlen(path);
        char buf[4096];
        if (len + n + 2 < sizeof buf) {
            memcpy(buf, path, len);
            buf[len] = '/';
            memcpy(buf + len + 1, program, n + 1);
            if (access(buf, X_OK) == 0) return true;
        }
        path += len + (colon ? 1 : 0);
    }
    return false;
}

/* Start argv[0] with its output discarded, from `dir` (NULL: here); its
 * pid, or -1. */
static pid_t start(char *const argv[], const char *dir)
{
    pid_t pid = fork();
    if (pid == 0) {
        int null = open("/dev/null", O_WRONLY);
        if (null >= 0) {
            dup2(null, 1);
            dup2(null, 2);
        }
        if (dir && chdir(dir) != 0) _exit(127);
        execvp(argv[0], argv);
        _exit(127);
    }
    return pid;
}

/* Wait for `pid` (-1: it never started); its exit status, or -1. */
static int finish(pid_t pid)
{
    if (pid < 0) return -1;
    int status;
    while (waitpid(pid, &status, 0) < 0)
        if (errno != EINTR) return -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/* Run argv[0] to its end; exit status or -1. */
static int run(char *const argv[], const char *dir) { return finish(start(argv, dir)); }

/* Exactly `count` frames: older frames with higher numbers may lie in the folder. */
static spn_status encode_movie(const char *dir, int count, double fps, const char *movie)
{
    spn_atomic_file f;
    spn_status st = spn_atomic_open(&f, movie, false);
    if (st != SPN_OK) return st;
    char rate[32], frames[32], pattern[4200];
    snprintf(rate, sizeof rate, "%g", fps);
    snprintf(frames, sizeof frames, "%d", count);
    snprintf(pattern, sizeof pattern, "%s/frame_%%05d.png", dir);
    char *argv[] = {"ffmpeg", "-y", "-loglevel", "error", "-framerate", rate, "-i", pattern, "-frames:v", frames, "-vf",
                    "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-pix_fmt", "yuv420p", f.tmp_path, NULL};
    if (run(argv, NULL) != 0) {
        spn_atomic_abort(&f);
        return spn_error(SPN_ERR_IO, "%s: ffmpeg failed to encode the frames of %s", movie, dir);
    }
    return spn_atomic_commit(&f);
}

/* povray processes run at once by spn_pov_render_frames. */
#define POV_JOBS 6

spn_status spn_pov_render_frames(const char *dir, int count, int width, int height, double fps, const char *movie)
{
    if (!spn_program_available("povray"))
        return spn_error(SPN_ERR_UNSUPPORTED, "rendering needs the povray program (Debian package povray)");
    if (movie && !spn_program_available("ffmpeg"))
        return spn_error(SPN_ERR_UNSUPPORTED, "a movie needs the ffmpeg program (Debian package ffmpeg)");
    if (width < 1 || height < 1 || width > 8192 || height > 8192)
        return spn_error(SPN_ERR_INVALID, "render size %dx%d out of range", width, height);
    char w[32], h[32];
    snprintf(w, sizeof w, "+W%d", width);
    snprintf(h, sizeof h, "+H%d", height);
    /* POV_JOBS frames at once, waited for in the order they were started:
     * a povray process spends most of its time idle (a 320x240 frame of the
     * drop: 0.78 s of wall time for 0.2 s of CPU), so one after another the
     * demo's 51 frames took 41 s; frames take about as long as each other,
     * so waiting for the oldest loses little. Only our own children are
     * waited for (no waitpid(-1): the program may have others). */
    pid_t jobs[POV_JOBS];
    int started = 0, done = 0, failed = -1;
    while (done < started || (started < count && failed < 0)) {
        if (started < count && failed < 0 && started - done < POV_JOBS) {
            char in[64], out[64];
            snprintf(in, sizeof in, "+Iframe_%05d.pov", started);
            snprintf(out, sizeof out, "+Oframe_%05d.png", started);
            char *argv[] = {"povray", in, out, w, h, "+FN", "-D", "-V", "+A0.3", NULL};
            jobs[started % POV_JOBS] = start(argv, dir);
            started++;
            continue;
        }
        if (finish(jobs[done % POV_JOBS]) != 0 && failed < 0) failed = done;
        done++;
    }
    if (failed >= 0) return spn_error(SPN_ERR_IO, "%s/frame_%05d.pov: povray failed to render it", dir, failed);
    return movie ? encode_movie(dir, count, fps, movie) : SPN_OK;
}
