/* Error state: one message per thread, set by whoever fails first and read by
 * the caller that reports it. Messages are short and name the field or file. */
#include "spinneret/core.h"

#include <stdarg.h>
#include <stdio.h>

static _Thread_local char last_message[1024];

const char *spn_version(void) { return SPN_VERSION_STRING; }

const char *spn_last_error(void) { return last_message; }

spn_status spn_error(spn_status status, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(last_message, sizeof last_message, fmt, ap);
    va_end(ap);
    return status;
}

const char *spn_status_name(spn_status status)
{
    static const char *const names[] = {"ok", "invalid", "io", "format", "nomem",
                                        "unstable", "unsupported", "interrupted"};
    if ((unsigned)status < sizeof names / sizeof names[0]) return names[status];
    return "unknown";
}
