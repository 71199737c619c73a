/* Fuzz harness: the web file reader, JSON and binary (the seeds hold both).
 * Any bytes must give a world or a clean error with a message, never a crash,
 * a leak or an absurd allocation; a world read must write back both ways.
 * JSON text must read the same with its columns taken from the text
 * (web_lift.c) as all through cJSON: the same message, or the same world. */
#include <spinneret/spinneret.h>

#include "io/io_internal.h"

#include <stdlib.h>
#include <string.h>

/* The same outcome with and without the columns taken from the text. */
static void same_either_way(const char *text, size_t size, spn_status st, const spn_world *w)
{
    char msg[1024];
    strncpy(msg, spn_last_error(), sizeof msg - 1);
    msg[sizeof msg - 1] = 0;
    spn_world *plain = NULL;
    if (spn__web_parse_json(text, size, "fuzz.json", false, &plain) != st) abort();
    if (st != SPN_OK) {
        if (strncmp(msg, spn_last_error(), sizeof msg - 1) != 0) abort();
        return;
    }
    spn_buffer a = {0}, b = {0};
    spn_sink sink = spn_sink_buffer(&a);
    if (spn_web_write(w, &sink) != SPN_OK) abort();
    sink = spn_sink_buffer(&b);
    if (spn_web_write(plain, &sink) != SPN_OK) abort();
    if (a.size != b.size || memcmp(a.data, b.data, a.size) != 0) abort();
    spn_buffer_free(&a);
    spn_buffer_free(&b);
    spn_world_destroy(plain);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    spn_world *w = NULL;
    spn_status st = spn_web_parse((const char *)data, size, "fuzz.json", &w);
    if (!spn__web_is_binary(data, size)) same_either_way((const char *)data, size, st, w);
    if (st == SPN_OK) {
        if (!w) abort();
        /* A loaded world must be usable: compile, measure, write back. */
        spn_world_compile(w);
        (void)spn_world_total_energy(w);
        spn_buffer buf = {0};
        spn_sink sink = spn_sink_buffer(&buf);
        if (spn_web_write(w, &sink) != SPN_OK) abort();
        spn_buffer_free(&buf);
        /* and as a binary file, which must read back */
        spn_buffer bin = {0};
        sink = spn_sink_buffer(&bin);
        if (spn_web_write_binary(w, &sink) != SPN_OK) abort();
        spn_world *back = NULL;
        if (spn_web_parse(bin.data, bin.size, "fuzz.spnw", &back) != SPN_OK) abort();
        spn_world_destroy(back);
        spn_buffer_free(&bin);
        spn_world_destroy(w);
    } else if (w || !spn_last_error()[0]) {
        abort(); /* a failure must leave no world and say why */
    }
    return 0;
}
