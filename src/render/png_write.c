/* PNG files through libpng: pictures (spn_render_file) and animation frames
 * (spn_frames_add into a folder).
 *
 * cairo's own writer compresses at zlib level 6 and lets libpng try all five
 * row filters on every row. On a 1200 x 1200 frame of a species web (thin
 * light lines on a plain background) that took 48 ms, more than the drawing
 * (30 ms), and writing frames was half of what `spinneret animate` cost on a
 * web at rest. Line art on a flat colour compresses best unfiltered (the rows
 * repeat, and deflate finds them; a filter turns each line's edges into two
 * runs of differences); a photograph behind the web wants the "up" filter. So
 * the writer looks at the picture: when at least half of a sample of pixels
 * equal their left neighbour it writes rows unfiltered, else filtered "up".
 * Frames are compressed at level 1 (12 ms for that frame, 0.6% larger than
 * level 6 unfiltered, smaller than cairo's), pictures at level 6.
 * Pixels come straight (RGBA bytes) or premultiplied (cairo's ARGB32 words);
 * an opaque picture is written as RGB, as cairo did. */
#include "render_internal.h"

#include <png.h>
#include <setjmp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* One row of `src` as straight RGB or RGBA bytes. */
static void row_bytes(const spn__png_pixels *src, int y, bool alpha, uint8_t *out)
{
    const uint8_t *row = src->data + (size_t)y * src->stride;
    int channels = alpha ? 4 : 3;
    if (!src->premultiplied && alpha) {
        memcpy(out, row, (size_t)src->width * 4);
    } else if (!src->premultiplied) {
        for (int x = 0; x < src->width; x++) memcpy(out + (size_t)x * 3, row + (size_t)x * 4, 3);
    } else {
        spn__unpremultiply_row((const uint32_t *)(const void *)row, src->width, out, channels);
    }
}

static uint8_t alpha_at(const spn__png_pixels *src, const uint8_t *row, int x)
{
    return src->premultiplied ? (uint8_t)(((const uint32_t *)(const void *)row)[x] >> 24) : row[(size_t)x * 4 + 3];
}

static bool opaque(const spn__png_pixels *src)
{
    for (int y = 0; y < src->height; y++) {
        const uint8_t *row = src->data + (size_t)y * src->stride;
        for (int x = 0; x < src->width; x++)
            if (alpha_at(src, row, x) != 255) return false;
    }
    return true;
}

/* True when at least half of the pixels of every eighth row repeat their
 * left neighbour: flat colour with lines, best left unfiltered. */
static bool mostly_flat(const spn__png_pixels *src)
{
    size_t same = 0, seen = 0;
    for (int y = 0; y < src->height; y += 8) {
        const uint8_t *row = src->data + (size_t)y * src->stride;
        for (int x = 1; x < src->width; x++) same += memcmp(row + (size_t)x * 4, row + (size_t)x * 4 - 4, 4) == 0;
        seen += (size_t)src->width - 1;
    }
    return 2 * same >= seen;
}

typedef struct png_failure {
    jmp_buf jump;
    char message[160];
} png_failure;

static void on_error(png_structp png, png_const_charp message)
{
    png_failure *fail = png_get_error_ptr(png);
    snprintf(fail->message, sizeof fail->message, "%s", message);
    longjmp(fail->jump, 1);
}

static void on_warning(png_structp png, png_const_charp message)
{
    (void)png;
    (void)message;
}

/* A PNG growing in memory (spn__png_encode_memory). glibc's open_memstream
 * zero-fills each larger buffer: on a turntable of dew frames that cost more
 * than the compression. */
typedef struct png_memory {
    uint8_t *data;
    size_t size, capacity;
} png_memory;

static void memory_write(png_structp png, png_bytep bytes, png_size_t n)
{
    png_memory *m = png_get_io_ptr(png);
    if (n > m->capacity - m->size) {
        size_t cap = m->capacity ? m->capacity : 65536;
        while (n > cap - m->size) {
            if (cap > SIZE_MAX / 2) png_error(png, "out of memory");
            cap *= 2;
        }
        uint8_t *grown = realloc(m->data, cap);
        if (!grown) png_error(png, "out of memory");
        m->data = grown, m->capacity = cap;
    }
    memcpy(m->data + m->size, bytes, n);
    m->size += n;
}

static void memory_flush(png_structp png) { (void)png; }

/* Everything libpng does, between one setjmp and its cleanup, into the file
 * `fp` or else into memory `mem`. No local that outlives a longjmp changes
 * after the setjmp (`row`, `png` and `info` are set before it). */
static spn_status encode(const spn__png_pixels *src, int level, FILE *fp, png_memory *mem, const char *path)
{
    uint8_t *row = malloc((size_t)src->width * 4);
    png_failure fail;
    fail.message[0] = 0;
    png_structp png = row ? png_create_write_struct(PNG_LIBPNG_VER_STRING, &fail, on_error, on_warning) : NULL;
    png_infop info = png ? png_create_info_struct(png) : NULL;
    if (!info) {
        png_destroy_write_struct(&png, NULL);
        free(row);
        return spn_error(SPN_ERR_NOMEM, "%s: out of memory", path);
    }
    spn_status st = SPN_OK;
    if (setjmp(fail.jump) == 0) {
        bool alpha = !opaque(src);
        int filter = mostly_flat(src) ? PNG_FILTER_NONE : PNG_FILTER_UP;
        if (fp) png_init_io(png, fp);
        else png_set_write_fn(png, mem, memory_write, memory_flush);
        png_set_IHDR(png, info, (png_uint_32)src->width, (png_uint_32)src->height, 8,
                     alpha ? PNG_COLOR_TYPE_RGB_ALPHA : PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
                     PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
        png_set_compression_level(png, level);
        png_set_filter(png, PNG_FILTER_TYPE_BASE, filter);
        png_write_info(png, info);
        for (int y = 0; y < src->height; y++) {
            row_bytes(src, y, alpha, row);
            png_write_row(png, row);
        }
        png_write_end(png, info);
    } else {
        st = spn_error(SPN_ERR_IO, "%s: cannot write: %s", path, fail.message);
    }
    png_destroy_write_struct(&png, &info);
    free(row);
    return st;
}

spn_status spn__png_write(const spn__png_pixels *src, int level, const char *path)
{
    spn_atomic_file f;
    spn_status st = spn_atomic_open(&f, path, true);
    if (st != SPN_OK) return st;
    st = encode(src, level, f.fp, NULL, path);
    if (st == SPN_OK) return spn_atomic_commit(&f);
    spn_atomic_abort(&f);
    return st;
}

spn_status spn__png_encode_memory(const spn__png_pixels *src, int level, uint8_t **bytes, size_t *size)
{
    png_memory m = {NULL, 0, 0};
    spn_status st = encode(src, level, NULL, &m, "frame");
    if (st != SPN_OK) {
        free(m.data);
        m.data = NULL, m.size = 0;
    }
    *bytes = m.data, *size = m.size;
    return st;
}

void spn__unpremultiply_row(const uint32_t *src, int width, uint8_t *out, int channels)
{
    for (int x = 0; x < width; x++) {
        uint32_t v = src[x];
        unsigned a = v >> 24;
        unsigned c[3] = {(v >> 16) & 255, (v >> 8) & 255, v & 255};
        uint8_t *o = out + (size_t)x * (size_t)channels;
        if (a == 255) {
            for (int i = 0; i < 3; i++) o[i] = (uint8_t)c[i];
        } else {
            for (int i = 0; i < 3; i++) o[i] = (uint8_t)(a ? (c[i] * 255 + a / 2) / a : 0);
        }
        if (channels == 4) o[3] = (uint8_t)a;
    }
}
