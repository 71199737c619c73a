/* A whole file into one buffer, for readers that parse from memory (meshes,
 * POV scenes) and for the background cache, which compares a file's bytes
 * with the last ones it decoded. Internal to the library. */
#ifndef SPN_READ_FILE_H
#define SPN_READ_FILE_H

#include "spinneret/core.h"

#include <stddef.h>

/* Read a whole file (NUL-terminated, the NUL not counted in *size); messages
 * name `path`. */
spn_status spn__read_file(const char *path, char **data, size_t *size);

#endif
