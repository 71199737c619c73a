/* Text targets: the message set in a real font with cairo's text API, which
 * finds the font through fontconfig and draws it with FreeType. The thesis
 * drew its targets in an image editor (ch. 6); here the font, the capital
 * height and the fit into the capture area are chosen by the caller.
 *
 * A font fontconfig does not have is an error, not a silent substitution:
 * the family FreeType actually opened is compared with the one asked for.
 * Layout: the block centred where the largest block of its shape fits in
 * the capture spiral (spn__fit_box), baselines
 * `line_spacing` capital heights apart, each line centred on its ink. */
#include "inscribe_internal.h"

#include <cairo-ft.h>
#include <cairo.h>
#include <ctype.h>
#include <ft2build.h>
#include FT_FREETYPE_H
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#define MAX_LINES 16
#define REFERENCE_PX 100.0

spn_text_def spn_text_def_default(void)
{
    spn_text_def d;
    d.text = NULL;
    d.font = "DejaVu Sans Bold";
    d.fit = 0.9;
    d.height = 0;
    d.line_spacing = 1.45;
    return d;
}

typedef struct font_request {
    char family[128];
    cairo_font_weight_t weight;
    cairo_font_slant_t slant;
} font_request;

/* "DejaVu Sans Bold Oblique" -> family "DejaVu Sans", bold, oblique. */
static spn_status parse_font(const char *name, font_request *f)
{
    size_t n = strlen(name);
    if (n == 0 || n >= sizeof f->family) return spn_error(SPN_ERR_INVALID, "font: name is empty or too long");
    memcpy(f->family, name, n + 1);
    f->weight = CAIRO_FONT_WEIGHT_NORMAL;
    f->slant = CAIRO_FONT_SLANT_NORMAL;
    for (;;) {
        char *sp = strrchr(f->family, ' ');
        if (!sp) break;
        const char *word = sp + 1;
        if (strcasecmp(word, "bold") == 0) f->weight = CAIRO_FONT_WEIGHT_BOLD;
        else if (strcasecmp(word, "italic") == 0) f->slant = CAIRO_FONT_SLANT_ITALIC;
        else if (strcasecmp(word, "oblique") == 0) f->slant = CAIRO_FONT_SLANT_OBLIQUE;
        else if (strcasecmp(word, "regular") != 0 && strcasecmp(word, "book") != 0) break;
        *sp = '\0';
    }
    return SPN_OK;
}

/* Select the font on `cr` and check that FreeType opened that family. */
static spn_status select_font(cairo_t *cr, const char *name)
{
    font_request f;
    spn_status st = parse_font(name, &f);
    if (st != SPN_OK) return st;
    cairo_select_font_face(cr, f.family, f.slant, f.weight);
    cairo_scaled_font_t *sf = cairo_get_scaled_font(cr);
    if (cairo_scaled_font_status(sf) != CAIRO_STATUS_SUCCESS || cairo_scaled_font_get_type(sf) != CAIRO_FONT_TYPE_FT)
        return spn_error(SPN_ERR_UNSUPPORTED, "font '%s': cairo could not open it through FreeType", name);
    FT_Face face = cairo_ft_scaled_font_lock_face(sf);
    if (!face) return spn_error(SPN_ERR_INVALID, "font '%s': FreeType could not open it", name);
    char got[128];
    snprintf(got, sizeof got, "%s", face->family_name ? face->family_name : "?");
    cairo_ft_scaled_font_unlock_face(sf);
    if (strcasecmp(got, f.family) != 0)
        return spn_error(SPN_ERR_INVALID, "font '%s': not installed (fontconfig offered '%s' instead; see fc-list)",
                         name, got);
    return SPN_OK;
}

typedef struct layout {
    int lines;
    const char *start[MAX_LINES];
    int len[MAX_LINES];
    cairo_text_extents_t ext[MAX_LINES];
    double cap;            /* capital height at REFERENCE_PX */
    double width, height;  /* block at REFERENCE_PX */
    double spacing;
} layout;

static spn_status split_lines(const char *text, layout *L)
{
    L->lines = 0;
    const char *p = text;
    bool any_ink = false;
    for (;;) {
        const char *nl = strchr(p, '\n');
        int len = nl ? (int)(nl - p) : (int)strlen(p);
        if (L->lines == MAX_LINES) return spn_error(SPN_ERR_INVALID, "text: more than %d lines", MAX_LINES);
        L->start[L->lines] = p;
        L->len[L->lines++] = len;
        for (int i = 0; i < len; i++) any_ink |= !isspace((unsigned char)p[i]);
        if (!nl) break;
        p = nl + 1;
    }
    if (!any_ink) return spn_error(SPN_ERR_INVALID, "text: empty (nothing to inscribe)");
    return SPN_OK;
}

static void measure(cairo_t *cr, layout *L)
{
    cairo_set_font_size(cr, REFERENCE_PX);
    cairo_text_extents_t h;
    cairo_text_extents(cr, "H", &h);
    L->cap = h.height;
    L->width = 0;
    for (int i = 0; i < L->lines; i++) {
        char buf[1024];
        snprintf(buf, sizeof buf, "%.*s", L->len[i] < 1023 ? L->len[i] : 1023, L->start[i]);
        cairo_text_extents(cr, buf, &L->ext[i]);
        L->width = fmax(L->width, L->ext[i].width);
    }
    L->height = L->cap * (1 + (L->lines - 1) * L->spacing);
}

static void draw_lines(cairo_t *cr, const layout *L, double k, double cx, double cy)
{
    cairo_set_font_size(cr, REFERENCE_PX * k);
    double top = cy - 0.5 * L->height * k;
    for (int i = 0; i < L->lines; i++) {
        char buf[1024];
        snprintf(buf, sizeof buf, "%.*s", L->len[i] < 1023 ? L->len[i] : 1023, L->start[i]);
        double base = top + (L->cap + i * L->spacing * L->cap) * k;
        double left = cx - 0.5 * L->ext[i].width * k - L->ext[i].x_bearing * k;
        cairo_move_to(cr, left, base);
        cairo_show_text(cr, buf);
    }
}

static spn_status check_def(const spn_text_def *d)
{
    if (!d->text) return spn_error(SPN_ERR_INVALID, "text: empty (nothing to inscribe)");
    if (!d->font) return spn_error(SPN_ERR_INVALID, "font: name is empty");
    if (!(d->fit > 0 && d->fit <= 1)) return spn_error(SPN_ERR_INVALID, "fit %g: need 0 < fit <= 1", d->fit);
    if (!(d->height >= 0) || !isfinite(d->height)) return spn_error(SPN_ERR_INVALID, "text height: need >= 0 m");
    if (!(d->line_spacing >= 1 && d->line_spacing <= 4))
        return spn_error(SPN_ERR_INVALID, "line spacing %g: need 1..4 capital heights", d->line_spacing);
    return SPN_OK;
}

/* Scale from reference pixels to target pixels, and the block's centre:
 * `fit` of the largest block that fits in the spiral, or the asked height checked. */
static spn_status text_scale(const layout *L, const spn_text_def *d, const spn_world *w, const spn_target *t,
                             double *k, spn_vec3 *centre)
{
    double most; /* metres per reference pixel at the largest fitting size */
    spn_status st = spn__fit_box(w, 0.5 * L->width, 0.5 * L->height, centre, &most);
    if (st != SPN_OK) return st;
    if (d->height > 0) {
        *k = d->height * t->scale / L->cap;
        if (*k > most * t->scale * 1.0000001)
            return spn_error(SPN_ERR_INVALID,
                             "text height %g m: the text (%.3f x %.3f m) does not fit in the capture spiral "
                             "(at most %.3f m capitals); try --fit",
                             d->height, L->width * *k / t->scale, L->height * *k / t->scale, most * L->cap);
    } else {
        *k = d->fit * most * t->scale;
    }
    if (L->cap * *k < 4)
        return spn_error(SPN_ERR_INVALID, "text: letters would be %.1f pixels tall, too small to inscribe; "
                         "use fewer characters or a larger web", L->cap * *k);
    return SPN_OK;
}

spn_status spn_target_text(spn_target *t, const spn_world *w, const spn_text_def *def)
{
    spn_text_def d = def ? *def : spn_text_def_default();
    spn_status st = check_def(&d);
    layout L;
    if (st == SPN_OK) st = split_lines(d.text, &L);
    if (st != SPN_OK) return st;
    L.spacing = d.line_spacing;
    cairo_surface_t *surf = cairo_image_surface_create(CAIRO_FORMAT_A8, t->width, t->height);
    cairo_t *cr = cairo_create(surf);
    if (cairo_status(cr) != CAIRO_STATUS_SUCCESS) {
        cairo_destroy(cr);
        cairo_surface_destroy(surf);
        return spn_error(SPN_ERR_NOMEM, "text: cannot make a %dx%d raster", t->width, t->height);
    }
    st = select_font(cr, d.font);
    double k = 1;
    spn_vec3 centre = spn_v3(0, 0, 0);
    if (st == SPN_OK) {
        measure(cr, &L);
        st = text_scale(&L, &d, w, t, &k, &centre);
    }
    if (st == SPN_OK) {
        double cx, cy;
        spn_target_to_pixel(t, centre, &cx, &cy);
        draw_lines(cr, &L, k, cx, cy);
        cairo_surface_flush(surf);
        const unsigned char *px = cairo_image_surface_get_data(surf);
        int stride = cairo_image_surface_get_stride(surf);
        for (int j = 0; j < t->height; j++)
            for (int i = 0; i < t->width; i++) {
                float v = px[(size_t)j * (size_t)stride + (size_t)i] / 255.0f;
                float *p = &t->ink[(size_t)j * (size_t)t->width + (size_t)i];
                if (v > *p) *p = v;
            }
    }
    cairo_destroy(cr);
    cairo_surface_destroy(surf);
    return st;
}
