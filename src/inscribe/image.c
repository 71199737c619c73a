/* Image targets (Mehla 2005, ch. 6: "a simple bi-level image containing
 * mainly low frequency content", such as a logo). PNG is read by cairo;
 * PBM and PGM (P1, P2, P4, P5) by the small reader below, which names the
 * line of the first bad token. Dark pixels are ink; transparent pixels none.
 * The image keeps its aspect and is `fit` of the largest size that fits in
 * the capture spiral, where it fits best (spn__fit_box). */
#include "inscribe_internal.h"

#include <cairo.h>
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define PNM_MAX_SIDE 16384

void spn_grey_image_free(spn_grey_image *img)
{
    if (!img) return;
    free(img->pixels);
    memset(img, 0, sizeof *img);
}

typedef struct pnm_reader {
    FILE *fp;
    const char *path;
    int line;       /* line of the next character */
    int token_line; /* line where the last number started */
} pnm_reader;

static int next_char(pnm_reader *r)
{
    int c = fgetc(r->fp);
    if (c == '\n') r->line++;
    return c;
}

/* Read an unsigned decimal, skipping white space and # comments. */
static spn_status read_number(pnm_reader *r, const char *what, long max, long *out)
{
    int c = next_char(r);
    for (;;) {
        while (c != EOF && isspace(c)) c = next_char(r);
        if (c != '#') break;
        while (c != EOF && c != '\n') c = next_char(r);
    }
    if (c == EOF) return spn_error(SPN_ERR_FORMAT, "%s:%d: file ends before the %s", r->path, r->line, what);
    r->token_line = r->line;
    if (!isdigit(c)) return spn_error(SPN_ERR_FORMAT, "%s:%d: %s: expected a number, found '%c'", r->path, r->line, what, c);
    long v = 0;
    while (c != EOF && isdigit(c)) {
        v = v * 10 + (c - '0');
        if (v > max) return spn_error(SPN_ERR_FORMAT, "%s:%d: %s is above %ld", r->path, r->token_line, what, max);
        c = next_char(r);
    }
    if (c != EOF && !isspace(c) && c != '#')
        return spn_error(SPN_ERR_FORMAT, "%s:%d: %s: unexpected '%c' after the number", r->path, r->token_line, what, c);
    if (c == '#') ungetc(c, r->fp);
    *out = v;
    return SPN_OK;
}

/* P1: '0'/'1' digits, white space optional between them. */
static spn_status read_p1(pnm_reader *r, spn_grey_image *img)
{
    size_t n = (size_t)img->width * (size_t)img->height;
    for (size_t i = 0; i < n; i++) {
        int c = next_char(r);
        while (c != EOF && (isspace(c) || c == '#')) {
            if (c == '#')
                while (c != EOF && c != '\n') c = next_char(r);
            else c = next_char(r);
        }
        if (c != '0' && c != '1')
            return spn_error(SPN_ERR_FORMAT, "%s:%d: pixel %zu: expected 0 or 1", r->path, r->line, i);
        img->pixels[i] = c == '1' ? 0 : 255;
    }
    return SPN_OK;
}

static spn_status read_raster(pnm_reader *r, int type, long maxval, spn_grey_image *img)
{
    size_t n = (size_t)img->width * (size_t)img->height;
    if (type == 1) return read_p1(r, img);
    if (type == 2) {
        for (size_t i = 0; i < n; i++) {
            long v;
            char what[48];
            snprintf(what, sizeof what, "pixel %zu", i);
            spn_status st = read_number(r, what, maxval, &v);
            if (st != SPN_OK) return st;
            img->pixels[i] = (uint8_t)lround(255.0 * v / maxval);
        }
        return SPN_OK;
    }
    if (type == 4) {
        size_t row = ((size_t)img->width + 7) / 8;
        for (int j = 0; j < img->height; j++)
            for (size_t b = 0; b < row; b++) {
                int c = fgetc(r->fp);
                if (c == EOF) return spn_error(SPN_ERR_FORMAT, "%s: binary data ends in row %d", r->path, j);
                for (int k = 0; k < 8 && b * 8 + (size_t)k < (size_t)img->width; k++)
                    img->pixels[(size_t)j * (size_t)img->width + b * 8 + (size_t)k] = (c >> (7 - k)) & 1 ? 0 : 255;
            }
        return SPN_OK;
    }
    int bytes = maxval > 255 ? 2 : 1;
    for (size_t i = 0; i < n; i++) {
        int c = fgetc(r->fp), c2 = bytes == 2 ? fgetc(r->fp) : 0;
        if (c == EOF || c2 == EOF) return spn_error(SPN_ERR_FORMAT, "%s: binary data ends at pixel %zu", r->path, i);
        long v = bytes == 2 ? (c << 8 | c2) : c;
        if (v > maxval) return spn_error(SPN_ERR_FORMAT, "%s: pixel %zu is %ld, above maxval %ld", r->path, i, v, maxval);
        img->pixels[i] = (uint8_t)lround(255.0 * v / maxval);
    }
    return SPN_OK;
}

static spn_status read_pnm_header(pnm_reader *r, int *type, long *w, long *h, long *maxval)
{
    int c0 = fgetc(r->fp), c1 = fgetc(r->fp);
    if (c0 != 'P' || (c1 != '1' && c1 != '2' && c1 != '4' && c1 != '5'))
        return spn_error(SPN_ERR_FORMAT, "%s:1: not a PBM or PGM file (expected P1, P2, P4 or P5)", r->path);
    *type = c1 - '0';
    spn_status st = read_number(r, "width", PNM_MAX_SIDE, w);
    if (st == SPN_OK) st = read_number(r, "height", PNM_MAX_SIDE, h);
    if (st == SPN_OK && (*w == 0 || *h == 0))
        st = spn_error(SPN_ERR_FORMAT, "%s:%d: image is %ldx%ld; need a positive width and height", r->path, r->token_line,
                       *w, *h);
    *maxval = 1;
    if (st == SPN_OK && (*type == 2 || *type == 5)) {
        st = read_number(r, "maxval", 65535, maxval);
        if (st == SPN_OK && *maxval == 0)
            st = spn_error(SPN_ERR_FORMAT, "%s:%d: maxval must be positive", r->path, r->token_line);
    }
    return st;
}

spn_status spn_pnm_read(const char *path, spn_grey_image *out)
{
    memset(out, 0, sizeof *out);
    pnm_reader r = {fopen(path, "rb"), path, 1, 1};
    if (!r.fp) return spn_error(SPN_ERR_IO, "%s: cannot read: %s", path, strerror(errno));
    int type = 0;
    long w = 0, h = 0, maxval = 1;
    spn_status st = read_pnm_header(&r, &type, &w, &h, &maxval);
    if (st == SPN_OK) {
        out->width = (int)w;
        out->height = (int)h;
        out->pixels = malloc((size_t)w * (size_t)h);
        if (!out->pixels) st = spn_error(SPN_ERR_NOMEM, "%s: out of memory for %ldx%ld", path, w, h);
    }
    if (st == SPN_OK) st = read_raster(&r, type, maxval, out);
    fclose(r.fp);
    if (st != SPN_OK) spn_grey_image_free(out);
    return st;
}

/* PNG through cairo: grey = luminance, transparent = white (no ink). */
static spn_status read_png(const char *path, spn_grey_image *out)
{
    memset(out, 0, sizeof *out);
    cairo_surface_t *s = cairo_image_surface_create_from_png(path);
    cairo_status_t cs = cairo_surface_status(s);
    if (cs != CAIRO_STATUS_SUCCESS) {
        cairo_surface_destroy(s);
        return spn_error(cs == CAIRO_STATUS_NO_MEMORY ? SPN_ERR_NOMEM : SPN_ERR_FORMAT, "%s: cannot read the PNG: %s",
                         path, cairo_status_to_string(cs));
    }
    cairo_surface_t *rgb = cairo_image_surface_create(CAIRO_FORMAT_RGB24, cairo_image_surface_get_width(s),
                                                      cairo_image_surface_get_height(s));
    cairo_t *cr = cairo_create(rgb);
    cairo_set_source_rgb(cr, 1, 1, 1);
    cairo_paint(cr);
    cairo_set_source_surface(cr, s, 0, 0);
    cairo_paint(cr);
    cairo_destroy(cr);
    cairo_surface_flush(rgb);
    out->width = cairo_image_surface_get_width(rgb);
    out->height = cairo_image_surface_get_height(rgb);
    out->pixels = malloc((size_t)out->width * (size_t)out->height + 1);
    spn_status st = out->pixels ? SPN_OK : spn_error(SPN_ERR_NOMEM, "%s: out of memory", path);
    const unsigned char *d = cairo_image_surface_get_data(rgb);
    int stride = cairo_image_surface_get_stride(rgb);
    for (int j = 0; st == SPN_OK && j < out->height; j++)
        for (int i = 0; i < out->width; i++) {
            uint32_t p;
            memcpy(&p, d + (size_t)j * (size_t)stride + 4 * (size_t)i, 4);
            double lum = 0.2126 * (p >> 16 & 255) + 0.7152 * (p >> 8 & 255) + 0.0722 * (p & 255);
            out->pixels[(size_t)j * (size_t)out->width + (size_t)i] = (uint8_t)lround(lum);
        }
    cairo_surface_destroy(rgb);
    cairo_surface_destroy(s);
    if (st != SPN_OK) spn_grey_image_free(out);
    return st;
}

static spn_status read_image(const char *path, spn_grey_image *img)
{
    FILE *fp = fopen(path, "rb");
    if (!fp) return spn_error(SPN_ERR_IO, "%s: cannot read: %s", path, strerror(errno));
    unsigned char magic[2] = {0, 0};
    size_t got = fread(magic, 1, 2, fp);
    fclose(fp);
    if (got == 2 && magic[0] == 0x89 && magic[1] == 'P') return read_png(path, img);
    if (got == 2 && magic[0] == 'P') return spn_pnm_read(path, img);
    return spn_error(SPN_ERR_FORMAT, "%s: not a PNG, PBM or PGM image", path);
}

/* Bilinear ink (1 - grey) at image coordinates (u, v); 0 outside. */
static double sample_ink(const spn_grey_image *img, double u, double v)
{
    u -= 0.5, v -= 0.5;
    int i = (int)floor(u), j = (int)floor(v);
    double fu = u - i, fv = v - j, sum = 0;
    for (int dj = 0; dj < 2; dj++)
        for (int di = 0; di < 2; di++) {
            int x = i + di, y = j + dj;
            x = x < 0 ? 0 : x >= img->width ? img->width - 1 : x;
            y = y < 0 ? 0 : y >= img->height ? img->height - 1 : y;
            double wgt = (di ? fu : 1 - fu) * (dj ? fv : 1 - fv);
            sum += wgt * (1 - img->pixels[(size_t)y * (size_t)img->width + (size_t)x] / 255.0);
        }
    return sum;
}

spn_status spn_target_image(spn_target *t, const spn_world *w, const char *path, double fit)
{
    if (!(fit > 0 && fit <= 1)) return spn_error(SPN_ERR_INVALID, "fit %g: need 0 < fit <= 1", fit);
    if (!path || !*path) return spn_error(SPN_ERR_INVALID, "image: no file given");
    spn_grey_image img = {0, 0, NULL};
    spn_status st = read_image(path, &img);
    spn_vec3 centre;
    double most; /* metres per image pixel at the largest fitting size */
    if (st == SPN_OK) st = spn__fit_box(w, 0.5 * img.width, 0.5 * img.height, &centre, &most);
    if (st != SPN_OK) {
        spn_grey_image_free(&img);
        return st;
    }
    double k = 1 / (fit * most * t->scale); /* image pixels per target pixel */
    double cx, cy;
    spn_target_to_pixel(t, centre, &cx, &cy);
    for (int j = 0; j < t->height; j++)
        for (int i = 0; i < t->width; i++) {
            double u = (i + 0.5 - cx) * k + 0.5 * img.width, v = (j + 0.5 - cy) * k + 0.5 * img.height;
            if (u < 0 || v < 0 || u > img.width || v > img.height) continue;
            float ink = (float)sample_ink(&img, u, v);
            float *p = &t->ink[(size_t)j * (size_t)t->width + (size_t)i];
            if (ink > *p) *p = ink;
        }
    spn_grey_image_free(&img);
    return SPN_OK;
}
