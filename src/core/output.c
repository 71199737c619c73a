/* Outputs: atomic files (temporary beside the target, renamed on success) and
 * byte sinks, so every writer can target a file, memory or a test. */
#define _POSIX_C_SOURCE 200809L
#include "spinneret/core.h"

#include "core_internal.h"

#include <errno.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static char *dup_string(const char *s)
{
    size_t n = strlen(s) + 1;
    char *d = malloc(n);
    if (d) memcpy(d, s, n);
    return d;
}

spn_status spn_atomic_open(spn_atomic_file *f, const char *path, bool open_stream)
{
    memset(f, 0, sizeof *f);
    if (!path || !*path) return spn_error(SPN_ERR_INVALID, "output path is empty");
    size_t n = strlen(path) + 32;
    f->path = dup_string(path);
    f->tmp_path = malloc(n);
    if (!f->path || !f->tmp_path) {
        spn_atomic_abort(f);
        return spn_error(SPN_ERR_NOMEM, "out of memory");
    }
    /* Keep the extension last: tools such as cairo or ffmpeg pick the format from it. */
    const char *slash = strrchr(path, '/');
    const char *base = slash ? slash + 1 : path;
    snprintf(f->tmp_path, n, "%.*s.tmp%ld-%s", (int)(base - path), path, (long)getpid(), base);
    spn__temp_track(f->tmp_path);
    /* Without a stream the temporary is still made (and closed): a missing or
     * read-only folder is named here, with the system's reason, rather than
     * by the writer that later fails with a vaguer message. */
    f->fp = fopen(f->tmp_path, "wb");
    if (!f->fp) {
        spn_status st = spn_error(SPN_ERR_IO, "%s: cannot write: %s", path, strerror(errno));
        spn__temp_untrack(f->tmp_path);
        free(f->path);
        free(f->tmp_path);
        memset(f, 0, sizeof *f);
        return st;
    }
    if (!open_stream) {
        fclose(f->fp);
        f->fp = NULL;
    }
    return SPN_OK;
}

spn_status spn_atomic_commit(spn_atomic_file *f)
{
    spn_status st = SPN_OK;
    if (f->fp) {
        int bad = ferror(f->fp) | fflush(f->fp);
        bad |= fclose(f->fp);
        f->fp = NULL;
        if (bad) st = spn_error(SPN_ERR_IO, "%s: write failed: %s", f->path, strerror(errno));
    }
    if (st == SPN_OK && rename(f->tmp_path, f->path) != 0)
        st = spn_error(SPN_ERR_IO, "%s: cannot write: %s", f->path, strerror(errno));
    if (st != SPN_OK) remove(f->tmp_path);
    spn__temp_untrack(f->tmp_path);
    free(f->path);
    free(f->tmp_path);
    memset(f, 0, sizeof *f);
    return st;
}

void spn_atomic_abort(spn_atomic_file *f)
{
    if (f->fp) fclose(f->fp);
    if (f->tmp_path) remove(f->tmp_path);
    spn__temp_untrack(f->tmp_path);
    free(f->path);
    free(f->tmp_path);
    memset(f, 0, sizeof *f);
}

static spn_status file_write(void *ctx, const void *data, size_t size)
{
    if (fwrite(data, 1, size, (FILE *)ctx) != size) return spn_error(SPN_ERR_IO, "write failed: %s", strerror(errno));
    return SPN_OK;
}

spn_sink spn_sink_file(FILE *fp)
{
    spn_sink s = {file_write, fp};
    return s;
}

static spn_status buffer_write(void *ctx, const void *data, size_t size)
{
    spn_buffer *b = ctx;
    if (b->size + size + 1 > b->capacity) {
        size_t cap = b->capacity ? b->capacity : 256;
        while (cap < b->size + size + 1) cap *= 2;
        char *p = realloc(b->data, cap);
        if (!p) return spn_error(SPN_ERR_NOMEM, "out of memory");
        b->data = p;
        b->capacity = cap;
    }
    memcpy(b->data + b->size, data, size);
    b->size += size;
    b->data[b->size] = '\0';
    return SPN_OK;
}

spn_sink spn_sink_buffer(spn_buffer *buf)
{
    spn_sink s = {buffer_write, buf};
    return s;
}

void spn_buffer_free(spn_buffer *buf)
{
    free(buf->data);
    memset(buf, 0, sizeof *buf);
}

spn_status spn_sink_printf(spn_sink *sink, const char *fmt, ...)
{
    char small[512];
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(small, sizeof small, fmt, ap);
    va_end(ap);
    if (n < 0) return spn_error(SPN_ERR_INVALID, "bad format");
    if ((size_t)n < sizeof small) return sink->write(sink->ctx, small, (size_t)n);
    char *big = malloc((size_t)n + 1);
    if (!big) return spn_error(SPN_ERR_NOMEM, "out of memory");
    va_start(ap, fmt);
    vsnprintf(big, (size_t)n + 1, fmt, ap);
    va_end(ap);
    spn_status st = sink->write(sink->ctx, big, (size_t)n);
    free(big);
    return st;
}
