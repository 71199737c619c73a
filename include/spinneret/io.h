/* Files: the JSON web file (docs/web-format.md). Meshes and scenes join here. */
#ifndef SPINNERET_IO_H
#define SPINNERET_IO_H

#include "world.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Current web file format version written by spn_web_save.
#define SPN_WEB_FORMAT_VERSION 1

/// Write the world as a web file (atomically: temporary file, then rename).
SPN_API spn_status spn_web_save(const spn_world *w, const char *path);
/// Write the web file to a sink.
SPN_API spn_status spn_web_write(const spn_world *w, spn_sink *sink);
/// Read a web file. On failure *out is NULL and the message names the file,
/// the field and the index of the first bad value.
SPN_API spn_status spn_web_load(const char *path, spn_world **out);
/// Parse web file text of `size` bytes; `name` is used in messages.
SPN_API spn_status spn_web_parse(const char *text, size_t size, const char *name, spn_world **out);

#ifdef __cplusplus
}
#endif
#endif
