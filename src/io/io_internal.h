/* Shared between the files of src/io: the web file's name and limits, and
 * small helpers for numbers and messages. */
#ifndef SPN_IO_INTERNAL_H
#define SPN_IO_INTERNAL_H

#include "spinneret/io.h"

#define SPN__WEB_FORMAT_NAME "spinneret-web"
/* Integers up to 2^53 survive a JSON number (a double) exactly. */
#define SPN__MAX_EXACT_INT 9007199254740992ull
/* Largest particle or spring count a web file may claim, and the largest file
 * read: beyond these a claim is refused before anything is allocated. */
#define SPN__WEB_MAX_COUNT 100000000u
#define SPN__WEB_MAX_BYTES ((size_t)1 << 30)

/* `v` with the fewest digits (15, 16 or 17) that read back to the same bits. */
void spn__format_double(char out[40], double v);
/* Put "prefix: " before the last error message; returns `status`. */
spn_status spn__error_prefix(spn_status status, const char *prefix);

#endif
