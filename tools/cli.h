/* Helpers shared by the subcommands: messages, exit codes and parsing of option
 * values with the option and its valid range named in every complaint.
 * Exit codes: 0 success, 1 failure (one line on stderr), 2 usage error. */
#ifndef SPN_CLI_H
#define SPN_CLI_H

#include <spinneret/spinneret.h>

#define CLI_EXIT_FAIL 1
#define CLI_EXIT_USAGE 2

/* "spinneret CMD: message (see 'spinneret CMD --help')" on one line; returns CLI_EXIT_USAGE. */
int cli_usage(const char *cmd, const char *fmt, ...) SPN_PRINTF(2, 3);
/* "spinneret CMD: message"; returns CLI_EXIT_FAIL. */
int cli_fail(const char *cmd, const char *fmt, ...) SPN_PRINTF(2, 3);
/* The library's last error as a failure line. */
int cli_fail_status(const char *cmd, spn_status st);

/* Parse a finite number in [lo, hi]; on failure print a usage line naming
 * `opt` and the range and return false. */
bool cli_double(const char *cmd, const char *opt, const char *text, double lo, double hi, double *out);
bool cli_int(const char *cmd, const char *opt, const char *text, long lo, long hi, long *out);
bool cli_u64(const char *cmd, const char *opt, const char *text, uint64_t *out);
/* "X,Y,Z" (or "X,Y" with z = 0 when allow_2d), all finite. */
bool cli_vec3(const char *cmd, const char *opt, const char *text, bool allow_2d, spn_vec3 *out);
/* "WxH" with 1 <= W, H <= max_side. */
bool cli_size(const char *cmd, const char *opt, const char *text, int max_side, int *w, int *h);
/* Lower-case file extension of a path ("png"), or "" when none. */
const char *cli_extension(const char *path);
/* True when argv has --help or -h (print usage then). */
bool cli_wants_help(int argc, char **argv);

#endif
