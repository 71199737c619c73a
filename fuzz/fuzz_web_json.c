/* Fuzz harness: the web file reader, JSON and binary (the seeds hold both).
 * Any bytes must give a world or a clean error with a message, never a crash,
 * a leak or an absurd allocation; a world read must write back both ways. */
#include <spinneret/spinneret.h>

#include <stdlib.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    spn_world *w = NULL;
    spn_status st = spn_web_parse((const char *)data, size, "fuzz.json", &w);
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
