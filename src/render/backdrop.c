/* Background images, decoded once and kept: `spinneret animate --background`
 * and the turntable draw the same file behind every frame, and decoding it
 * was most of a frame's cost (a 1200 x 1200 photograph: 66 ms of PNG decoding
 * against 13 ms for drawing the web; scaling it onto the canvas is 3-5 ms).
 * Each thread keeps the last image it decoded (its own, so no two threads
 * ever share a cairo surface; a thread's copy is freed when it ends, the
 * calling thread's by spn_render_release_caches) with the file's bytes. The
 * file is read every time and compared with them (a millisecond for a 2 MB
 * file): a program that writes a new picture to the same path between frames
 * gets it, which a check of the modification time, in steps of the kernel's
 * clock tick, would not promise. */
#include "render_internal.h"

#include <cairo.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/read_file.h"

typedef struct backdrop {
    char *bytes;  /* the PNG file as read */
    size_t size;
    cairo_surface_t *image;
    double luma;
} backdrop;

static pthread_key_t key;
static pthread_once_t key_once = PTHREAD_ONCE_INIT;
static bool have_key;

static void backdrop_free(void *p)
{
    backdrop *b = p;
    if (!b) return;
    cairo_surface_destroy(b->image);
    free(b->bytes);
    free(b);
}

static void make_key(void) { have_key = pthread_key_create(&key, backdrop_free) == 0; }

/* Mean brightness from a coarse grid: chooses how drop rims are lit. */
static double mean_luma(cairo_surface_t *s)
{
    int bw = cairo_image_surface_get_width(s), bh = cairo_image_surface_get_height(s);
    const unsigned char *px = cairo_image_surface_get_data(s);
    int stride = cairo_image_surface_get_stride(s);
    double sum = 0;
    int n = 0;
    for (int y = bh / 32; y < bh; y += bh / 16 + 1)
        for (int x = bw / 32; x < bw; x += bw / 16 + 1, n++) {
            uint32_t v = *(const uint32_t *)(const void *)(px + (size_t)y * stride + (size_t)x * 4);
            sum += (0.2126 * ((v >> 16) & 255) + 0.7152 * ((v >> 8) & 255) + 0.0722 * (v & 255)) / 255.0;
        }
    return n ? sum / n : 0;
}

/* cairo reads the PNG from memory through this. */
typedef struct reader {
    const char *at;
    size_t left;
} reader;

static cairo_status_t read_bytes(void *closure, unsigned char *data, unsigned int length)
{
    reader *r = closure;
    if (length > r->left) return CAIRO_STATUS_READ_ERROR;
    memcpy(data, r->at, length);
    r->at += length;
    r->left -= length;
    return CAIRO_STATUS_SUCCESS;
}

static spn_status decode(const char *path, const char *bytes, size_t size, cairo_surface_t **image)
{
    reader r = {bytes, size};
    cairo_surface_t *s = cairo_image_surface_create_from_png_stream(read_bytes, &r);
    cairo_status_t why = cairo_surface_status(s);
    if (why == CAIRO_STATUS_SUCCESS) {
        *image = s;
        return SPN_OK;
    }
    cairo_surface_destroy(s);
    return spn_error(why == CAIRO_STATUS_READ_ERROR ? SPN_ERR_IO : SPN_ERR_FORMAT, "%s: cannot read background: %s",
                     path, cairo_status_to_string(why));
}

/* True when the file at `path` holds exactly `size` bytes equal to `bytes`:
 * read in pieces and compared as they come, with no buffer of the file's
 * size (a fresh one of 2 MB cost more in page faults than the reading). */
static bool file_holds(const char *path, const char *bytes, size_t size)
{
    FILE *fp = fopen(path, "rb");
    if (!fp) return false;
    char piece[1 << 14];
    size_t at = 0, n;
    bool same = true;
    while (same && (n = fread(piece, 1, sizeof piece, fp)) > 0) {
        same = at + n <= size && memcmp(piece, bytes + at, n) == 0;
        at += n;
    }
    same = same && at == size && !ferror(fp);
    fclose(fp);
    return same;
}

spn_status spn__backdrop_get(const char *path, cairo_surface_t **image, double *luma)
{
    pthread_once(&key_once, make_key);
    backdrop *b = have_key ? pthread_getspecific(key) : NULL;
    if (b && file_holds(path, b->bytes, b->size)) {
        *image = cairo_surface_reference(b->image);
        *luma = b->luma;
        return SPN_OK;
    }
    char *bytes;
    size_t size;
    spn_status st = spn__read_file(path, &bytes, &size);
    if (st != SPN_OK) {
        char why[512]; /* the message, copied out of the buffer spn_error writes */
        snprintf(why, sizeof why, "%s", spn_last_error());
        return spn_error(st, "background: %s", why);
    }
    st = decode(path, bytes, size, image);
    if (st != SPN_OK) {
        free(bytes);
        return st;
    }
    *luma = mean_luma(*image);
    backdrop *fresh = have_key ? calloc(1, sizeof *fresh) : NULL;
    if (fresh && pthread_setspecific(key, fresh) == 0) {
        fresh->bytes = bytes;
        fresh->size = size;
        fresh->image = cairo_surface_reference(*image);
        fresh->luma = *luma;
        backdrop_free(b);
    } else {
        free(fresh);
        free(bytes);
    }
    return SPN_OK;
}

void spn__backdrop_forget(void)
{
    pthread_once(&key_once, make_key);
    if (!have_key) return;
    backdrop_free(pthread_getspecific(key));
    pthread_setspecific(key, NULL);
}
