/* Buffered output to a sink for the web file writers (web_write.c,
 * web_binary.c): a million-particle web is tens of millions of small pieces,
 * and a sink call for each was a fifth of the JSON writer's time. */
#include "io_internal.h"

void spn__out_init(spn__out *o, spn_sink *sink)
{
    o->sink = sink;
    o->st = SPN_OK;
    o->used = 0;
}

static void flush(spn__out *o)
{
    if (o->st == SPN_OK && o->used) o->st = o->sink->write(o->sink->ctx, o->buf, o->used);
    o->used = 0;
}

void spn__out_put(spn__out *o, const void *data, size_t n)
{
    if (o->st != SPN_OK) return;
    if (o->used + n > sizeof o->buf) {
        flush(o);
        if (n > sizeof o->buf) { /* a long piece (metadata, a header) goes straight through */
            if (o->st == SPN_OK) o->st = o->sink->write(o->sink->ctx, data, n);
            return;
        }
    }
    memcpy(o->buf + o->used, data, n);
    o->used += n;
}

unsigned char *spn__out_room(spn__out *o, size_t n)
{
    if (o->used + n > sizeof o->buf) flush(o);
    unsigned char *p = (unsigned char *)o->buf + o->used;
    o->used += n;
    return p;
}

spn_status spn__out_finish(spn__out *o)
{
    flush(o);
    return o->st;
}
