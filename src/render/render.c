/* Rendering to files and buffers: checks the definition, picks the cairo
 * surface from the file extension (.png, .svg, .pdf), draws, and writes
 * atomically (temporary beside the target, renamed on success).
 * The image path renders into an ARGB32 surface first, so every failure
 * (a bad background, a bad camera) happens before any file exists. */
#include "render_internal.h"

#include <cairo-pdf.h>
#include <cairo-svg.h>
#include <cairo.h>
#include <ctype.h>
#include <math.h>
#include <string.h>

#define MAX_SIDE 16384
#define MAX_PIXELS (100.0 * 1000 * 1000) /* 400 MB of ARGB: beyond that, render in tiles */

spn_dew_def spn_dew_def_default(void)
{
    spn_dew_def d = {false, 6e-3, 1.3e-3, 0.35, 1};
    return d;
}

spn_render_def spn_render_def_default(void)
{
    spn_render_def d;
    memset(&d, 0, sizeof d);
    d.width = d.height = 1200;
    d.camera.kind = SPN_CAMERA_FRONT;
    d.camera.eye = spn_v3(0, 0, 1);
    d.camera.target = spn_v3(0, 0, 0);
    d.camera.up = spn_v3(0, 1, 0);
    d.camera.fov_degrees = 40;
    d.camera.margin = 0.05;
    d.background_png = NULL;
    d.shade_rgb[0] = d.shade_rgb[1] = d.shade_rgb[2] = 0.85;
    d.alpha = 1;
    d.width_scale = 1;
    d.colour_by = SPN_COLOUR_SHADE;
    d.dew = spn_dew_def_default();
    d.legend = true;
    d.glow = 0;
    d.sheen = 0;
    d.light = spn_v3(-0.4, 0.5, -0.75);
    d.smooth = false;
    return d;
}

static bool in01(double v) { return v >= 0 && v <= 1; }

static spn_status check_rgb(const double *rgb, const char *field)
{
    for (int i = 0; i < 3; i++)
        if (!in01(rgb[i]))
            return spn_error(SPN_ERR_INVALID, "render: %s[%d] must be in [0, 1], got %g", field, i, rgb[i]);
    return SPN_OK;
}

static spn_status check_camera(const spn_camera *c)
{
    if (!(c->margin >= 0 && c->margin < 0.5))
        return spn_error(SPN_ERR_INVALID, "render: camera.margin must be in [0, 0.5), got %g", c->margin);
    if (c->kind == SPN_CAMERA_PERSPECTIVE) {
        if (!(c->fov_degrees > 0 && c->fov_degrees < 180))
            return spn_error(SPN_ERR_INVALID, "render: camera.fov_degrees must be in (0, 180), got %g", c->fov_degrees);
        if (!spn_v3_finite(c->eye) || !spn_v3_finite(c->target) || !spn_v3_finite(c->up))
            return spn_error(SPN_ERR_INVALID, "render: camera eye, target and up must be finite");
        /* Finite points can still be too far apart for a finite distance
         * (1e300 each way): the POV export would write inf. */
        double dist = spn_v3_len(spn_v3_sub(c->target, c->eye));
        if (!(dist > 0) || !isfinite(dist))
            return spn_error(SPN_ERR_INVALID, "render: camera eye and target must be apart by a finite distance");
    } else if (c->kind != SPN_CAMERA_FRONT) {
        return spn_error(SPN_ERR_INVALID, "render: camera.kind %d is unknown", (int)c->kind);
    }
    if (c->fixed_bounds && (!spn_v3_finite(c->bounds_min) || !spn_v3_finite(c->bounds_max)))
        return spn_error(SPN_ERR_INVALID, "render: camera bounds must be finite");
    return SPN_OK;
}

static spn_status check_dew(const spn_dew_def *d)
{
    if (!d->enabled) return SPN_OK;
    if (!(d->spacing > 0 && isfinite(d->spacing)))
        return spn_error(SPN_ERR_INVALID, "render: dew.spacing must be a positive length, got %g", d->spacing);
    if (!(d->radius > 0 && isfinite(d->radius)))
        return spn_error(SPN_ERR_INVALID, "render: dew.radius must be a positive length, got %g", d->radius);
    if (!in01(d->radius_jitter))
        return spn_error(SPN_ERR_INVALID, "render: dew.radius_jitter must be in [0, 1], got %g", d->radius_jitter);
    return SPN_OK;
}

spn_status spn_render_def_check(const spn_render_def *d)
{
    if (d->width < 1 || d->height < 1 || d->width > MAX_SIDE || d->height > MAX_SIDE)
        return spn_error(SPN_ERR_INVALID, "render: size must be between 1x1 and %dx%d, got %dx%d", MAX_SIDE, MAX_SIDE,
                         d->width, d->height);
    if ((double)d->width * d->height > MAX_PIXELS)
        return spn_error(SPN_ERR_INVALID, "render: %dx%d is more than %.0f million pixels", d->width, d->height,
                         MAX_PIXELS / 1e6);
    spn_status st = check_rgb(d->background_rgb, "background_rgb");
    if (st == SPN_OK) st = check_rgb(d->shade_rgb, "shade_rgb");
    if (st != SPN_OK) return st;
    if (!in01(d->alpha)) return spn_error(SPN_ERR_INVALID, "render: alpha must be in [0, 1], got %g", d->alpha);
    if (!in01(d->glow)) return spn_error(SPN_ERR_INVALID, "render: glow must be in [0, 1], got %g", d->glow);
    if (!in01(d->sheen)) return spn_error(SPN_ERR_INVALID, "render: sheen must be in [0, 1], got %g", d->sheen);
    if (!spn_v3_finite(d->light) || spn_v3_len(d->light) == 0)
        return spn_error(SPN_ERR_INVALID, "render: light must be a finite, non-zero direction");
    if (!(d->width_scale > 0 && d->width_scale <= 1000))
        return spn_error(SPN_ERR_INVALID, "render: width_scale must be in (0, 1000], got %g", d->width_scale);
    if ((unsigned)d->colour_by > SPN_COLOUR_STRAIN)
        return spn_error(SPN_ERR_INVALID, "render: colour_by %d is unknown", (int)d->colour_by);
    st = check_camera(&d->camera);
    if (st == SPN_OK) st = check_dew(&d->dew);
    return st;
}

/* Draw into a new ARGB32 surface. */
static spn_status render_image(const spn_world *w, const spn_render_def *def, cairo_surface_t **out)
{
    spn_status st = spn_render_def_check(def);
    if (st != SPN_OK) return st;
    cairo_surface_t *s = cairo_image_surface_create(CAIRO_FORMAT_ARGB32, def->width, def->height);
    if (cairo_surface_status(s) != CAIRO_STATUS_SUCCESS) {
        cairo_surface_destroy(s);
        return spn_error(SPN_ERR_NOMEM, "render: cannot make a %dx%d image", def->width, def->height);
    }
    cairo_t *cr = cairo_create(s);
    st = spn__cairo_draw(w, def, cr);
    cairo_destroy(cr);
    cairo_surface_flush(s);
    if (st != SPN_OK) cairo_surface_destroy(s);
    else *out = s;
    return st;
}

spn_status spn_render_rgba(const spn_world *w, const spn_render_def *def, uint8_t *rgba)
{
    cairo_surface_t *s = NULL;
    spn_status st = render_image(w, def, &s);
    if (st != SPN_OK) return st;
    const unsigned char *data = cairo_image_surface_get_data(s);
    size_t stride = (size_t)cairo_image_surface_get_stride(s);
    for (int y = 0; y < def->height; y++)
        spn__unpremultiply_row((const uint32_t *)(const void *)(data + (size_t)y * stride), def->width,
                               rgba + (size_t)y * def->width * 4, 4);
    cairo_surface_destroy(s);
    return SPN_OK;
}

typedef enum out_type { OUT_PNG, OUT_SVG, OUT_PDF, OUT_UNKNOWN } out_type;

static out_type type_of(const char *path)
{
    const char *dot = strrchr(path, '.'), *slash = strrchr(path, '/');
    if (!dot || (slash && dot < slash)) return OUT_UNKNOWN;
    char ext[8] = {0};
    for (int i = 0; i < 7 && dot[i + 1]; i++) ext[i] = (char)tolower((unsigned char)dot[i + 1]);
    if (strlen(dot + 1) > 7) return OUT_UNKNOWN;
    return strcmp(ext, "png") == 0 ? OUT_PNG : strcmp(ext, "svg") == 0 ? OUT_SVG : strcmp(ext, "pdf") == 0 ? OUT_PDF
                                                                                                         : OUT_UNKNOWN;
}

static spn_status write_png(const spn_world *w, const spn_render_def *def, const char *path)
{
    cairo_surface_t *s = NULL;
    spn_status st = render_image(w, def, &s);
    if (st != SPN_OK) return st;
    spn__png_pixels px = {cairo_image_surface_get_data(s), def->width, def->height,
                          (size_t)cairo_image_surface_get_stride(s), true};
    st = spn__png_write(&px, SPN__PNG_LEVEL_PICTURE, path);
    cairo_surface_destroy(s);
    return st;
}

/* cairo's own file output loses write errors (a full disk gave a truncated
 * PDF and success), so vector output goes through our stream, whose errors
 * spn_atomic_commit sees. */
static cairo_status_t write_stream(void *closure, const unsigned char *data, unsigned int length)
{
    return fwrite(data, 1, length, (FILE *)closure) == length ? CAIRO_STATUS_SUCCESS : CAIRO_STATUS_WRITE_ERROR;
}

static spn_status write_vector(const spn_world *w, const spn_render_def *def, const char *path, out_type type)
{
    spn_status st = spn_render_def_check(def);
    spn_atomic_file f;
    if (st == SPN_OK) st = spn_atomic_open(&f, path, true);
    if (st != SPN_OK) return st;
    cairo_surface_t *s = type == OUT_SVG ? cairo_svg_surface_create_for_stream(write_stream, f.fp, def->width, def->height)
                                         : cairo_pdf_surface_create_for_stream(write_stream, f.fp, def->width, def->height);
    cairo_t *cr = cairo_create(s);
    st = spn__cairo_draw(w, def, cr);
    cairo_destroy(cr);
    cairo_surface_finish(s);
    if (st == SPN_OK && cairo_surface_status(s) != CAIRO_STATUS_SUCCESS)
        st = spn_error(SPN_ERR_IO, "%s: cannot write: %s", path, cairo_status_to_string(cairo_surface_status(s)));
    cairo_surface_destroy(s);
    if (st == SPN_OK) return spn_atomic_commit(&f);
    spn_atomic_abort(&f);
    return st;
}

spn_status spn_render_file(const spn_world *w, const spn_render_def *def, const char *path)
{
    out_type type = path ? type_of(path) : OUT_UNKNOWN;
    if (type == OUT_UNKNOWN)
        return spn_error(SPN_ERR_INVALID, "%s: unknown output type (use .png, .svg or .pdf)", path ? path : "(null)");
    return type == OUT_PNG ? write_png(w, def, path) : write_vector(w, def, path, type);
}

spn_status spn_png_size(const char *path, int *width, int *height)
{
    if (!path || !*path) return spn_error(SPN_ERR_INVALID, "image path is empty");
    cairo_surface_t *s = cairo_image_surface_create_from_png(path);
    cairo_status_t cs = cairo_surface_status(s);
    if (cs != CAIRO_STATUS_SUCCESS) {
        cairo_surface_destroy(s);
        return spn_error(cs == CAIRO_STATUS_FILE_NOT_FOUND || cs == CAIRO_STATUS_READ_ERROR ? SPN_ERR_IO : SPN_ERR_FORMAT,
                         "%s: cannot read image: %s", path, cairo_status_to_string(cs));
    }
    *width = cairo_image_surface_get_width(s);
    *height = cairo_image_surface_get_height(s);
    cairo_surface_destroy(s);
    return SPN_OK;
}

#if defined(__GNUC__)
/* fontconfig is cairo's dependency, not ours: resolved at run time if loaded. */
extern void FcFini(void) __attribute__((weak));
#endif

void spn_render_release_caches(void)
{
    spn__backdrop_forget();
    cairo_debug_reset_static_data();
#if defined(__GNUC__)
    if (FcFini) FcFini();
#endif
}
