/* Files: the web file, JSON or binary (docs/web-format.md). Meshes and scenes join here. */
#ifndef SPINNERET_IO_H
#define SPINNERET_IO_H

#include "world.h"

#ifdef __cplusplus
extern "C" {
#endif

/// Current web file format version written by spn_web_save.
#define SPN_WEB_FORMAT_VERSION 1

/// The binary web file's extension: the same content as the JSON file, its
/// columns as raw little-endian numbers (docs/web-format.md, "Binary file").
#define SPN_WEB_BINARY_EXTENSION ".spnw"

/// Write the world as a web file (atomically: temporary file, then rename):
/// the binary file when `path` ends in SPN_WEB_BINARY_EXTENSION, JSON
/// otherwise.
SPN_API spn_status spn_web_save(const spn_world *w, const char *path);
/// Write the JSON web file to a sink.
SPN_API spn_status spn_web_write(const spn_world *w, spn_sink *sink);
/// Write the binary web file to a sink.
SPN_API spn_status spn_web_write_binary(const spn_world *w, spn_sink *sink);
/// Does `path` name a binary web file (its extension)?
SPN_API bool spn_web_path_is_binary(const char *path);
/// Read a web file, JSON or binary (told apart by the content, not the name).
/// On failure *out is NULL and the message names the file, the field and the
/// index of the first bad value.
SPN_API spn_status spn_web_load(const char *path, spn_world **out);
/// Parse a web file of `size` bytes, JSON or binary; `name` is used in
/// messages.
SPN_API spn_status spn_web_parse(const char *text, size_t size, const char *name, spn_world **out);

#ifdef __cplusplus
}
#endif
#endif
