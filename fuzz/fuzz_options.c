/* Fuzz harness: the option-value parsers every subcommand uses (numbers,
 * vectors, sizes). The input is split at the first NUL into a parser choice
 * and the text. Each must accept a value in range or refuse it, never crash. */
#include "cli.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1 || size > 4096) return 0;
    char *text = malloc(size);
    memcpy(text, data + 1, size - 1);
    text[size - 1] = '\0';
    FILE *saved = stderr;
    stderr = fopen("/dev/null", "w"); /* the parsers complain on stderr */
    double d;
    long l;
    uint64_t u;
    spn_vec3 v;
    int w, h;
    switch (data[0] % 5) {
    case 0: if (cli_double("fuzz", "--x", text, -1e6, 1e6, &d) && !(d >= -1e6 && d <= 1e6)) abort(); break;
    case 1: if (cli_int("fuzz", "--n", text, -5, 5, &l) && (l < -5 || l > 5)) abort(); break;
    case 2: (void)cli_u64("fuzz", "--seed", text, &u); break;
    case 3: if (cli_vec3("fuzz", "--v", text, data[0] & 8, &v) && !spn_v3_finite(v)) abort(); break;
    case 4: if (cli_size("fuzz", "--size", text, 16384, &w, &h) && (w < 1 || h < 1 || w > 16384 || h > 16384)) abort(); break;
    }
    fclose(stderr);
    stderr = saved;
    free(text);
    return 0;
}
