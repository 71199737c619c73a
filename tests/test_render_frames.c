/* Frame sequences: numbered PNGs that read back to the frames written (RGB
 * when opaque, RGBA with straight alpha when not; rows unfiltered for line
 * art, filtered "up" for a photograph; a write that fails leaves nothing),
 * MP4 and GIF through ffmpeg that decode back to the colour written, nothing
 * left on an abandoned encode, and a clear refusal when ffmpeg is missing. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "common/scratch.h"

#include <cairo.h>
#include <png.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>
#include <zlib.h>
#include <spinneret/spinneret.h>

static char folder[512];

static int setup(void **state)
{
    (void)state;
    return spn_test_scratch_make(folder, sizeof folder, "frames_test");
}

static int teardown(void **state)
{
    (void)state;
    return spn_test_scratch_remove(folder);
}

static uint8_t *solid(int w, int h, uint8_t r, uint8_t g, uint8_t b)
{
    uint8_t *px = malloc((size_t)w * h * 4);
    for (int i = 0; i < w * h; i++) px[4 * i] = r, px[4 * i + 1] = g, px[4 * i + 2] = b, px[4 * i + 3] = 255;
    return px;
}

static void test_png_folder(void **state)
{
    (void)state;
    char dir[600], path[700];
    snprintf(dir, sizeof dir, "%s/png", folder);
    spn_frames *f;
    assert_int_equal(spn_frames_open(dir, 32, 16, 25, &f), SPN_OK);
    spn_frames_set_first_index(f, 5);
    for (int i = 0; i < 3; i++) {
        uint8_t *px = solid(32, 16, (uint8_t)(40 * i), 100, 200);
        assert_int_equal(spn_frames_add(f, px), SPN_OK);
        free(px);
    }
    assert_int_equal(spn_frames_close(f, true), SPN_OK);
    for (int i = 0; i < 3; i++) {
        snprintf(path, sizeof path, "%s/frame_%05d.png", dir, 5 + i);
        cairo_surface_t *s = cairo_image_surface_create_from_png(path);
        assert_int_equal(cairo_surface_status(s), CAIRO_STATUS_SUCCESS);
        assert_int_equal(cairo_image_surface_get_width(s), 32);
        uint32_t v = *(uint32_t *)cairo_image_surface_get_data(s);
        assert_int_equal((v >> 16) & 255, 40 * i);
        assert_int_equal(v & 255, 200);
        cairo_surface_destroy(s);
    }
    snprintf(path, sizeof path, "%s/frame_%05d.png", dir, 8);
    assert_int_equal(access(path, F_OK), -1);
}

/* A PNG file's colour type and each row's filter byte (IDAT inflated). */
static void png_rows(const char *path, int w, int h, int *colour_type, uint8_t *filters)
{
    FILE *fp = fopen(path, "rb");
    assert_non_null(fp);
    fseek(fp, 0, SEEK_END);
    long n = ftell(fp);
    rewind(fp);
    uint8_t *file = malloc((size_t)n), *idat = malloc((size_t)n);
    assert_int_equal(fread(file, 1, (size_t)n, fp), (size_t)n);
    fclose(fp);
    size_t idat_len = 0;
    for (long at = 8; at + 12 <= n;) {
        uint32_t len = (uint32_t)file[at] << 24 | (uint32_t)file[at + 1] << 16 | (uint32_t)file[at + 2] << 8 | file[at + 3];
        const uint8_t *type = file + at + 4, *data = file + at + 8;
        if (memcmp(type, "IHDR", 4) == 0) *colour_type = data[9];
        if (memcmp(type, "IDAT", 4) == 0) memcpy(idat + idat_len, data, len), idat_len += len;
        at += 12 + (long)len;
    }
    int channels = *colour_type == 6 ? 4 : 3;
    uLongf raw_len = (uLongf)h * (1 + (uLongf)w * channels);
    uint8_t *raw = malloc(raw_len);
    assert_int_equal(uncompress(raw, &raw_len, idat, idat_len), Z_OK);
    assert_int_equal(raw_len, (uLongf)h * (1 + (uLongf)w * channels));
    for (int y = 0; y < h; y++) filters[y] = raw[(size_t)y * (1 + (size_t)w * channels)];
    free(raw);
    free(idat);
    free(file);
}

/* A pixel hash: the same noise every run. */
static uint8_t noise(uint32_t i)
{
    i = (i ^ 61) ^ (i >> 16);
    i *= 9;
    i ^= i >> 4;
    i *= 0x27d4eb2d;
    return (uint8_t)(i >> 15);
}

static void write_one(const char *name, int w, int h, const uint8_t *px, char *path, size_t path_size)
{
    char dir[600];
    snprintf(dir, sizeof dir, "%s/%s", folder, name);
    spn_frames *f;
    assert_int_equal(spn_frames_open(dir, w, h, 25, &f), SPN_OK);
    assert_int_equal(spn_frames_add(f, px), SPN_OK);
    assert_int_equal(spn_frames_close(f, true), SPN_OK);
    snprintf(path, path_size, "%s/frame_00000.png", dir);
}

/* Line art on a flat colour is written unfiltered, a photograph (no pixel
 * like its neighbour) filtered "up"; both opaque, so RGB, and both read back
 * to the pixels written. */
static void test_png_filters(void **state)
{
    (void)state;
    enum { W = 97, H = 64 };
    uint8_t *lines = solid(W, H, 10, 10, 30), *photo = malloc((size_t)W * H * 4);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            uint8_t *p = lines + ((size_t)y * W + x) * 4;
            if (x == y || x == 3 * y / 2 || y == 40) p[0] = p[1] = p[2] = 220;
            uint8_t *q = photo + ((size_t)y * W + x) * 4;
            for (int c = 0; c < 3; c++) q[c] = (uint8_t)(40 + x + y + (noise((uint32_t)(y * W + x) * 3 + c) & 15));
            q[3] = 255;
        }
    const uint8_t *pictures[2] = {lines, photo};
    const char *names[2] = {"lines", "photo"};
    for (int k = 0; k < 2; k++) {
        char path[700];
        write_one(names[k], W, H, pictures[k], path, sizeof path);
        int colour_type = -1;
        uint8_t filters[H];
        png_rows(path, W, H, &colour_type, filters);
        assert_int_equal(colour_type, PNG_COLOR_TYPE_RGB);
        for (int y = 0; y < H; y++) assert_int_equal(filters[y], k == 0 ? PNG_FILTER_VALUE_NONE : PNG_FILTER_VALUE_UP);
        cairo_surface_t *s = cairo_image_surface_create_from_png(path);
        assert_int_equal(cairo_surface_status(s), CAIRO_STATUS_SUCCESS);
        const uint8_t *data = cairo_image_surface_get_data(s);
        int stride = cairo_image_surface_get_stride(s);
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++) {
                uint32_t v = *(const uint32_t *)(const void *)(data + (size_t)y * stride + (size_t)x * 4);
                const uint8_t *p = pictures[k] + ((size_t)y * W + x) * 4;
                assert_int_equal(v, 0xff000000u | (uint32_t)p[0] << 16 | (uint32_t)p[1] << 8 | p[2]);
            }
        cairo_surface_destroy(s);
    }
    free(lines);
    free(photo);
}

/* Frames with see-through pixels keep them: RGBA, straight alpha, exact. */
static void test_png_alpha(void **state)
{
    (void)state;
    enum { W = 40, H = 24 };
    uint8_t *px = malloc((size_t)W * H * 4);
    for (int i = 0; i < W * H; i++)
        for (int c = 0; c < 4; c++) px[4 * i + c] = noise((uint32_t)(4 * i + c));
    char path[700];
    write_one("alpha", W, H, px, path, sizeof path);
    png_image image;
    memset(&image, 0, sizeof image);
    image.version = PNG_IMAGE_VERSION;
    assert_true(png_image_begin_read_from_file(&image, path));
    assert_int_equal(image.format & PNG_FORMAT_FLAG_ALPHA, PNG_FORMAT_FLAG_ALPHA);
    image.format = PNG_FORMAT_RGBA;
    uint8_t *back = malloc(PNG_IMAGE_SIZE(image));
    assert_true(png_image_finish_read(&image, NULL, back, 0, NULL));
    assert_memory_equal(back, px, (size_t)W * H * 4);
    free(back);
    free(px);
}

/* A write that fails part way (here the file size limit, as a full disk
 * would) is an I/O error naming the frame, and leaves no file behind. Run in
 * a child, whose limit ends with it. */
static void test_png_write_error(void **state)
{
    (void)state;
    enum { W = 256, H = 256 };
    char dir[600];
    snprintf(dir, sizeof dir, "%s/full", folder);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        signal(SIGXFSZ, SIG_IGN);
        struct rlimit lim = {4096, 4096};
        setrlimit(RLIMIT_FSIZE, &lim);
        uint8_t *px = malloc((size_t)W * H * 4);
        for (int i = 0; i < W * H * 4; i++) px[i] = i % 4 == 3 ? 255 : noise((uint32_t)i);
        spn_frames *f;
        if (spn_frames_open(dir, W, H, 25, &f) != SPN_OK) _exit(2);
        spn_status st = spn_frames_add(f, px);
        bool named = strstr(spn_last_error(), "frame_00000.png: cannot write") != NULL;
        spn_frames_close(f, true);
        _exit(st == SPN_ERR_IO && named ? 0 : 3);
    }
    int status = 0;
    assert_int_equal(waitpid(pid, &status, 0), pid);
    assert_true(WIFEXITED(status));
    assert_int_equal(WEXITSTATUS(status), 0);
    char cmd[800];
    snprintf(cmd, sizeof cmd, "test -z \"$(ls -A '%s')\"", dir);
    assert_int_equal(system(cmd), 0);
}

/* A world straight into a sequence; a picture of the wrong size is refused. */
static void test_add_world(void **state)
{
    (void)state;
    char dir[600], path[700];
    snprintf(dir, sizeof dir, "%s/world", folder);
    spn_world *w;
    assert_int_equal(spn_scene_orb(NULL, NULL, &w), SPN_OK);
    spn_render_def d = spn_render_def_default();
    d.width = 40;
    d.height = 30;
    spn_frames *f;
    assert_int_equal(spn_frames_open(dir, 40, 30, 25, &f), SPN_OK);
    assert_int_equal(spn_frames_add_world(f, w, &d), SPN_OK);
    d.width = 41;
    assert_int_equal(spn_frames_add_world(f, w, &d), SPN_ERR_INVALID);
    assert_int_equal(spn_frames_close(f, true), SPN_OK);
    snprintf(path, sizeof path, "%s/frame_00000.png", dir);
    assert_int_equal(access(path, F_OK), 0);
    snprintf(path, sizeof path, "%s/frame_00001.png", dir);
    assert_int_equal(access(path, F_OK), -1);
    spn_world_destroy(w);
}

/* The whole of a file; its size in *n. */
static uint8_t *slurp(const char *path, size_t *n)
{
    FILE *fp = fopen(path, "rb");
    assert_non_null(fp);
    fseek(fp, 0, SEEK_END);
    *n = (size_t)ftell(fp);
    rewind(fp);
    uint8_t *b = malloc(*n ? *n : 1);
    assert_int_equal(fread(b, 1, *n, fp), *n);
    fclose(fp);
    return b;
}

/* Frames encoded apart (as threads drawing frames at once do) and added in
 * order give the files spn_frames_add writes, byte for byte; an encoded
 * frame of the wrong size is refused by a video. */
static void test_encoded(void **state)
{
    (void)state;
    enum { W = 64, H = 40 };
    char dir[2][600], path[2][1300];
    uint8_t *px[3];
    for (int i = 0; i < 3; i++) {
        px[i] = malloc((size_t)W * H * 4);
        for (int k = 0; k < W * H * 4; k++) px[i][k] = k % 4 == 3 ? (uint8_t)(i == 2 ? 128 : 255) : noise((uint32_t)(k + 77 * i));
    }
    for (int v = 0; v < 2; v++) {
        snprintf(dir[v], sizeof dir[v], "%s/enc%d", folder, v);
        spn_frames *f;
        assert_int_equal(spn_frames_open(dir[v], W, H, 25, &f), SPN_OK);
        uint8_t *bytes[3];
        size_t size[3];
        if (v == 1) /* all encoded first, in reverse, then added in order */
            for (int i = 2; i >= 0; i--) assert_int_equal(spn_frames_encode(f, px[i], &bytes[i], &size[i]), SPN_OK);
        for (int i = 0; i < 3; i++) {
            if (v == 0) {
                assert_int_equal(spn_frames_add(f, px[i]), SPN_OK);
            } else {
                assert_true(size[i] > 8 && memcmp(bytes[i], "\x89PNG", 4) == 0);
                assert_int_equal(spn_frames_add_encoded(f, bytes[i], size[i]), SPN_OK);
                free(bytes[i]);
            }
        }
        assert_int_equal(spn_frames_close(f, true), SPN_OK);
    }
    for (int i = 0; i < 3; i++) {
        size_t n[2];
        uint8_t *b[2];
        for (int v = 0; v < 2; v++) {
            snprintf(path[v], sizeof path[v], "%s/frame_%05d.png", dir[v], i);
            b[v] = slurp(path[v], &n[v]);
        }
        assert_int_equal(n[0], n[1]);
        assert_memory_equal(b[0], b[1], n[0]);
        free(b[0]), free(b[1]), free(px[i]);
    }
    if (spn_frames_have_ffmpeg()) {
        snprintf(path[0], sizeof path[0], "%s/enc.mp4", folder);
        spn_frames *f;
        assert_int_equal(spn_frames_open(path[0], 32, 32, 10, &f), SPN_OK);
        uint8_t *one = solid(32, 32, 10, 20, 30), *bytes;
        size_t size;
        assert_int_equal(spn_frames_encode(f, one, &bytes, &size), SPN_OK);
        assert_int_equal(size, 32 * 32 * 4);
        assert_memory_equal(bytes, one, size);
        assert_int_equal(spn_frames_add_encoded(f, bytes, size - 4), SPN_ERR_INVALID);
        assert_non_null(strstr(spn_last_error(), "bytes"));
        assert_int_equal(spn_frames_add_encoded(f, bytes, size), SPN_OK);
        free(bytes), free(one);
        assert_int_equal(spn_frames_close(f, true), SPN_OK);
    }
}

/* Decode the first frame of a video with ffmpeg; its middle pixel. */
static void first_pixel(const char *video, int w, int h, int rgb[3])
{
    char cmd[900];
    snprintf(cmd, sizeof cmd, "ffmpeg -loglevel error -i '%s' -frames:v 1 -f rawvideo -pix_fmt rgb24 -", video);
    FILE *p = popen(cmd, "r");
    assert_non_null(p);
    size_t n = (size_t)w * h * 3;
    uint8_t *buf = malloc(n);
    size_t got = fread(buf, 1, n, p);
    pclose(p);
    assert_true(got >= n / 2);
    size_t mid = ((size_t)(h / 2) * w + w / 2) * 3;
    for (int c = 0; c < 3; c++) rgb[c] = buf[mid + c];
    free(buf);
}

static void encode(const char *name, int w, int h, bool commit, spn_status want_close)
{
    char path[700];
    snprintf(path, sizeof path, "%s/%s", folder, name);
    spn_frames *f;
    assert_int_equal(spn_frames_open(path, w, h, 10, &f), SPN_OK);
    uint8_t *px = solid(w, h, 200, 60, 30);
    for (int i = 0; i < 8; i++) assert_int_equal(spn_frames_add(f, px), SPN_OK);
    free(px);
    assert_int_equal(spn_frames_close(f, commit), want_close);
}

static void test_video(void **state)
{
    (void)state;
    if (!spn_frames_have_ffmpeg()) {
        printf("skipped: ffmpeg is not installed\n");
        skip();
    }
    char path[700];
    encode("clip.mp4", 65, 49, true, SPN_OK); /* odd sides: padded for yuv420p */
    snprintf(path, sizeof path, "%s/clip.mp4", folder);
    int rgb[3];
    first_pixel(path, 66, 50, rgb);
    assert_true(abs(rgb[0] - 200) < 12 && abs(rgb[1] - 60) < 12 && abs(rgb[2] - 30) < 12);
    encode("clip.gif", 40, 30, true, SPN_OK);
    snprintf(path, sizeof path, "%s/clip.gif", folder);
    FILE *fp = fopen(path, "rb");
    char head[6];
    assert_non_null(fp);
    assert_int_equal(fread(head, 1, 6, fp), 6);
    fclose(fp);
    assert_memory_equal(head, "GIF89a", 6);
    first_pixel(path, 40, 30, rgb);
    assert_true(abs(rgb[0] - 200) < 12 && abs(rgb[1] - 60) < 12 && abs(rgb[2] - 30) < 12);
    /* Abandoned: no file, and no temporary left beside it. */
    encode("gone.mp4", 32, 32, false, SPN_OK);
    snprintf(path, sizeof path, "%s/gone.mp4", folder);
    assert_int_equal(access(path, F_OK), -1);
    char cmd[800];
    snprintf(cmd, sizeof cmd, "ls '%s' | grep -q tmp", folder);
    assert_int_not_equal(system(cmd), 0);
}

static void test_missing_ffmpeg(void **state)
{
    (void)state;
    char path[700];
    snprintf(path, sizeof path, "%s/none.mp4", folder);
    setenv("SPN_FFMPEG", "/nonexistent/ffmpeg", 1);
    spn_frames *f = NULL;
    assert_false(spn_frames_have_ffmpeg());
    assert_int_equal(spn_frames_open(path, 32, 32, 10, &f), SPN_ERR_UNSUPPORTED);
    assert_null(f);
    assert_non_null(strstr(spn_last_error(), "ffmpeg"));
    assert_non_null(strstr(spn_last_error(), "PNG"));
    assert_int_equal(access(path, F_OK), -1);
    unsetenv("SPN_FFMPEG");
}

static void test_bad_arguments(void **state)
{
    (void)state;
    char path[700];
    snprintf(path, sizeof path, "%s/bad", folder);
    spn_frames *f = NULL;
    assert_int_equal(spn_frames_open(path, 0, 10, 10, &f), SPN_ERR_INVALID);
    assert_int_equal(spn_frames_open(path, 10, 10, 0, &f), SPN_ERR_INVALID);
    assert_int_equal(spn_frames_open("", 10, 10, 10, &f), SPN_ERR_INVALID);
    assert_null(f);
    /* The progress bar stays silent when asked to, and is NULL-safe. */
    spn_progress *p = spn_progress_begin("x", 10, true);
    assert_null(p);
    spn_progress_update(p, 5);
    spn_progress_end(p);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_png_folder), cmocka_unit_test(test_png_filters), cmocka_unit_test(test_png_alpha),
        cmocka_unit_test(test_png_write_error), cmocka_unit_test(test_add_world), cmocka_unit_test(test_encoded), cmocka_unit_test(test_video), cmocka_unit_test(test_missing_ffmpeg),
        cmocka_unit_test(test_bad_arguments)};
    return cmocka_run_group_tests(tests, setup, teardown);
}
