/* The exporters' view of a web: what spn_draw_world emits (strands in drawing
 * order, dew beads), copied into flat arrays the writers can walk twice
 * (once to count, once to write). Also the checks and the by-extension
 * dispatch shared by every exporter. */
#include "export_internal.h"
#include "spinneret/web.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static bool grow(void **p, size_t *cap, size_t need, size_t elem)
{
    if (need <= *cap) return true;
    size_t c = *cap ? *cap : 64;
    while (c < need) c *= 2;
    void *q = realloc(*p, c * elem);
    if (!q) return false;
    *p = q;
    *cap = c;
    return true;
}

static spn_status on_strand(void *user, const spn_strand *s)
{
    spn__xscene *x = user;
    size_t cap = x->point_cap;
    if (!grow((void **)&x->strands, &x->strand_cap, x->strand_count + 1, sizeof *x->strands) ||
        !grow((void **)&x->points, &cap, x->point_count + s->count, sizeof *x->points) ||
        !grow((void **)&x->particles, &x->point_cap, x->point_count + s->count, sizeof *x->particles))
        return spn_error(SPN_ERR_NOMEM, "export: out of memory");
    spn__xstrand t = {s->kind, x->point_count, s->count, s->closed, s->width, {s->rgb[0], s->rgb[1], s->rgb[2]}, s->alpha};
    x->strands[x->strand_count++] = t;
    for (uint32_t i = 0; i < s->count; i++) {
        spn_vec3 p = s->points[i];
        x->points[x->point_count] = p;
        x->particles[x->point_count++] = s->particles[i];
        if (!x->any) x->lo = x->hi = p;
        x->any = true;
        x->lo = spn_v3(fmin(x->lo.x, p.x), fmin(x->lo.y, p.y), fmin(x->lo.z, p.z));
        x->hi = spn_v3(fmax(x->hi.x, p.x), fmax(x->hi.y, p.y), fmax(x->hi.z, p.z));
    }
    return SPN_OK;
}

static spn_status on_bead(void *user, const spn_bead *b)
{
    spn__xscene *x = user;
    if (!grow((void **)&x->beads, &x->bead_cap, x->bead_count + 1, sizeof *x->beads))
        return spn_error(SPN_ERR_NOMEM, "export: out of memory");
    x->beads[x->bead_count++] = *b;
    return SPN_OK;
}

spn_status spn__xscene_collect(const spn_world *w, const spn_render_def *def, spn__xscene *out)
{
    memset(out, 0, sizeof *out);
    spn_draw_fns fns = {on_strand, on_bead, NULL};
    spn_status st = spn_draw_world(w, def, &fns, out);
    if (st != SPN_OK) spn__xscene_free(out);
    return st;
}

void spn__xscene_free(spn__xscene *s)
{
    free(s->strands);
    free(s->points);
    free(s->particles);
    free(s->beads);
    memset(s, 0, sizeof *s);
}

void spn__kind_label(uint32_t tag, char *buf, size_t size)
{
    const char *name = spn_thread_kind_name(tag);
    if (name) {
        /* File formats want identifiers: aux-spiral -> aux_spiral. */
        snprintf(buf, size, "%s", name);
        for (char *p = buf; *p; p++)
            if (!isalnum((unsigned char)*p)) *p = '_';
    } else {
        snprintf(buf, size, "tag_%u", tag);
    }
}

spn_export_def spn_export_def_default(void)
{
    spn_export_def d;
    memset(&d, 0, sizeof d);
    d.tube_radius = 0;
    d.tube_sides = 6;
    d.dew_segments = 10;
    d.pov_thread_radius = 0;
    d.render = spn_render_def_default();
    return d;
}

spn_status spn__export_check(const spn_export_def *d)
{
    if (!(d->tube_radius >= 0 && isfinite(d->tube_radius)))
        return spn_error(SPN_ERR_INVALID, "export: tube_radius must be 0 or a positive length, got %g", d->tube_radius);
    if (d->tube_sides < 3 || d->tube_sides > 64)
        return spn_error(SPN_ERR_INVALID, "export: tube_sides must be in [3, 64], got %d", d->tube_sides);
    if (d->dew_segments < 4 || d->dew_segments > 64)
        return spn_error(SPN_ERR_INVALID, "export: dew_segments must be in [4, 64], got %d", d->dew_segments);
    if (!(d->pov_thread_radius >= 0 && isfinite(d->pov_thread_radius)))
        return spn_error(SPN_ERR_INVALID, "export: pov_thread_radius must be 0 or a positive length, got %g",
                         d->pov_thread_radius);
    return spn_render_def_check(&d->render);
}

typedef spn_status (*writer_fn)(const spn_world *, const spn_export_def *, spn_sink *);

static writer_fn writer_for(const char *path)
{
    const char *dot = strrchr(path, '.'), *slash = strrchr(path, '/');
    if (!dot || (slash && dot < slash) || strlen(dot) != 4) return NULL;
    char ext[4];
    for (int i = 0; i < 3; i++) ext[i] = (char)tolower((unsigned char)dot[1 + i]);
    ext[3] = '\0';
    if (strcmp(ext, "obj") == 0) return spn_export_obj;
    if (strcmp(ext, "ply") == 0) return spn_export_ply;
    if (strcmp(ext, "pov") == 0) return spn_export_pov;
    return NULL;
}

spn_status spn_export_file(const spn_world *w, const spn_export_def *def, const char *path)
{
    writer_fn fn = path ? writer_for(path) : NULL;
    if (!fn) return spn_error(SPN_ERR_INVALID, "%s: unknown export type (use .obj, .ply or .pov)", path ? path : "(null)");
    spn_status st = spn__export_check(def);
    if (st != SPN_OK) return st;
    /* Write to memory first: a failure leaves no file at all. */
    spn_buffer buf = {0};
    spn_sink sink = spn_sink_buffer(&buf);
    st = fn(w, def, &sink);
    spn_atomic_file f;
    if (st == SPN_OK) st = spn_atomic_open(&f, path, true);
    if (st == SPN_OK) {
        if (buf.size && fwrite(buf.data, 1, buf.size, f.fp) != buf.size) {
            st = spn_error(SPN_ERR_IO, "%s: write failed: %s", path, strerror(errno));
            spn_atomic_abort(&f);
        } else {
            st = spn_atomic_commit(&f);
        }
    }
    spn_buffer_free(&buf);
    return st;
}

spn_status spn_export_pov_frame(const spn_world *w, const spn_export_def *def, const char *dir, int index)
{
    if (!dir || !*dir) return spn_error(SPN_ERR_INVALID, "export: frame folder is empty");
    if (index < 0) return spn_error(SPN_ERR_INVALID, "export: frame index must be >= 0, got %d", index);
    if (mkdir(dir, 0777) != 0 && errno != EEXIST)
        return spn_error(SPN_ERR_IO, "%s: cannot make folder: %s", dir, strerror(errno));
    size_t n = strlen(dir) + 32;
    char *path = malloc(n);
    if (!path) return spn_error(SPN_ERR_NOMEM, "out of memory");
    snprintf(path, n, "%s/frame_%05d.pov", dir, index);
    spn_status st = spn_export_file(w, def, path);
    free(path);
    return st;
}
