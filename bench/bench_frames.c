/* bench_frames: what a frame of an animation costs besides the physics.
 * The Araneus web (seed 1; 1,924 particles) drawn at 1,200 x 1,200, the
 * size `spinneret animate` uses by default, three ways: plain (the default
 * look), with dew, glow and sheen, and over a photograph-like background
 * (smooth colour with pixel noise, 1,200 pixels square, written first as a
 * PNG through the frame writer). For each: milliseconds of CPU to draw
 * (spn_render_rgba, the background decoded once per thread after the
 * first frame) and to write a frame (spn_frames_add into a PNG folder: the
 * filter choice, zlib level 1 and the file), and the bytes of a frame.
 * One thread. docs/render.md, "Frames and video".
 *
 *   bench_frames [--quick]   (--quick: 3 frames a case instead of 10) */
#include "common/bench_common.h"

#include <spinneret/spinneret.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

enum { SIDE = 1200 };

static void fail(const char *what)
{
    fprintf(stderr, "bench_frames: %s: %s\n", what, spn_last_error());
    exit(1);
}

/* A smooth gradient with +-6 of noise per channel: what a photograph gives
 * a PNG coder (little repeats, neighbours alike). */
static void write_photo(const char *dir)
{
    uint8_t *px = malloc((size_t)SIDE * SIDE * 4);
    if (!px) fail("memory");
    spn_rng rng;
    spn_rng_seed(&rng, 5);
    for (int y = 0; y < SIDE; y++)
        for (int x = 0; x < SIDE; x++) {
            uint8_t *p = px + ((size_t)y * SIDE + x) * 4;
            const int base[3] = {60 + x / 8, 90 + y / 10, 140 + (x + y) / 30};
            for (int c = 0; c < 3; c++) {
                int v = base[c] + (int)spn_rng_below(&rng, 13) - 6;
                p[c] = (uint8_t)(v < 0 ? 0 : v > 255 ? 255 : v);
            }
            p[3] = 255;
        }
    spn_frames *f;
    if (spn_frames_open(dir, SIDE, SIDE, 25, &f) != SPN_OK || spn_frames_add(f, px) != SPN_OK ||
        spn_frames_close(f, true) != SPN_OK)
        fail("background");
    free(px);
}

static long file_size(const char *path)
{
    struct stat sb;
    return stat(path, &sb) == 0 ? (long)sb.st_size : -1;
}

static void bench_case(const char *name, const spn_world *w, const spn_render_def *d, const char *dir, int frames,
                       double load)
{
    uint8_t *px = malloc((size_t)SIDE * SIDE * 4);
    spn_frames *f;
    if (!px || spn_frames_open(dir, SIDE, SIDE, 25, &f) != SPN_OK) fail("frames");
    if (spn_render_rgba(w, d, px) != SPN_OK) fail(name); /* the first: a background is decoded here */
    double draw = 0, write = 0;
    for (int i = 0; i < frames; i++) {
        double c0 = bench_cpu_now();
        if (spn_render_rgba(w, d, px) != SPN_OK) fail(name);
        double c1 = bench_cpu_now();
        if (spn_frames_add(f, px) != SPN_OK) fail(name);
        draw += c1 - c0;
        write += bench_cpu_now() - c1;
    }
    if (spn_frames_close(f, true) != SPN_OK) fail(name);
    char path[600];
    snprintf(path, sizeof path, "%s/frame_00000.png", dir);
    printf("{\"bench\":\"frames\",\"case\":\"%s\",\"width\":%d,\"height\":%d,\"draw_ms\":%.2f,\"write_ms\":%.2f,"
           "\"bytes\":%ld,\"load\":%.2f}\n",
           name, SIDE, SIDE, 1e3 * draw / frames, 1e3 * write / frames, file_size(path), load);
    free(px);
}

int main(int argc, char **argv)
{
    const bool quick = argc > 1 && strcmp(argv[1], "--quick") == 0;
    const int frames = quick ? 3 : 10;
    char root[] = "/tmp/bench_frames_XXXXXX";
    if (!mkdtemp(root)) fail("temporary folder");
    spn_species_def sd = spn_species_def_preset(SPN_SPECIES_ARANEUS);
    spn_world *w = NULL;
    if (spn_web_build_species(&sd, &w) != SPN_OK) fail("species web");
    char dir[4][600];
    const char *names[4] = {"photo", "plain", "dew", "over_photo"};
    for (int i = 0; i < 4; i++) snprintf(dir[i], sizeof dir[i], "%s/%s", root, names[i]);
    write_photo(dir[0]);
    char photo[700];
    snprintf(photo, sizeof photo, "%s/frame_00000.png", dir[0]);
    const double load = bench_load_average();
    spn_render_def d = spn_render_def_default();
    bench_case("plain", w, &d, dir[1], frames, load);
    spn_render_def dew = d;
    dew.dew.enabled = true;
    dew.glow = 0.5;
    dew.sheen = 0.5;
    bench_case("dew, glow, sheen", w, &dew, dir[2], frames, load);
    spn_render_def over = d;
    over.background_png = photo;
    bench_case("over a photograph", w, &over, dir[3], frames, load);
    spn_world_destroy(w);
    spn_render_release_caches();
    char cmd[200];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", root);
    return system(cmd) == 0 ? 0 : 1;
}
