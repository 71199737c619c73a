/* Helpers shared by the subcommands: messages, exit codes and parsing of option
 * values with the option and its valid range named in every complaint.
 * Exit codes: 0 success, 1 failure (one line on stderr), 2 usage error. */
#ifndef SPN_CLI_H
#define SPN_CLI_H

#include <getopt.h>
#include <pthread.h>
#include <stdio.h>

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
/* cli_vec3 with every component in [-bound, bound]: keeps differences, cross
 * products and a step's worth of motion finite. Bounds the commands share: */
#define CLI_MAX_COORD 1e6 /* positions [m] */
#define CLI_MAX_ACCEL 1e4 /* accelerations, gravity [m/s^2]: a thousand g */
#define CLI_MAX_SPEED 1e3 /* velocities of bodies and air [m/s] */
#define CLI_MAX_FORCE 1e6 /* forces on a particle [N] */
bool cli_vec3_bounded(const char *cmd, const char *opt, const char *text, double bound, spn_vec3 *out);
/* The index of `text` among names[0..count), or -1 (the caller says what
 * the choices are). */
int cli_choice(const char *text, const char *const *names, int count);
/* "WxH" with 1 <= W, H <= max_side. */
bool cli_size(const char *cmd, const char *opt, const char *text, int max_side, int *w, int *h);
/* Options every subcommand takes, removed from argv before the command sees
 * them: --max-particles N (or --max-particles=N) sets the library's particle
 * limit (spn_set_max_particles). Returns -1 to go on, else an exit code. */
int cli_global_options(const char *cmd, int *argc, char **argv);
#define CLI_GLOBAL_HELP                                                                                     \
    "global options (any command):\n"                                                                       \
    "  --max-particles N   refuse worlds with more than N particles (default 4000000; springs 8 per particle)\n"

/* A long loop that can stop between frames: turn graceful interrupts on
 * (see spinneret/interrupt.h), and after the loop call cli_report_interrupt. */
void cli_interruptible(uint64_t total);
/* When a signal stopped the loop after `done` units: print how far it got and
 * what was kept, and return 128 + the signal; otherwise return `code`. */
int cli_report_interrupt(const char *cmd, uint64_t done, uint64_t total, const char *kept, int code);
/* Start a helper thread (pthread_create's arguments) with the stop signals
 * (SIGINT, SIGTERM, SIGALRM) blocked in it: they reach the main thread,
 * whose handler stops the run between frames, and never cut a helper's
 * write short. pthread_create's result. */
int cli_start_helper(pthread_t *thread, void *(*run)(void *), void *arg);

/* Before a long computation: can `path` be written? (Makes and removes a
 * temporary beside it.) False after printing "cannot write: REASON". */
bool cli_output_writable(const char *cmd, const char *path);

/* One option for a subcommand's parser: `c` as getopt_long returned it,
 * `arg` its value. Returns 1 when it took the option, 0 when it does not know
 * it, -1 on a bad value (it has printed why). */
typedef int (*cli_option_fn)(int c, const char *arg, void *ctx);
/* The option loop the subcommands share: getopt_long over argv (the short
 * options `shortopts` start with ':' so a missing value is told apart), -h
 * and --help print `usage` to stdout, a missing value or an unknown option is
 * a usage error naming it, everything else goes to `one`. Returns -1 to go on
 * (optind at the first operand), 0 after --help, else the exit code. */
int cli_parse_options(const char *cmd, int argc, char **argv, const char *shortopts, const struct option *options,
                      void (*usage)(FILE *), cli_option_fn one, void *ctx);

/* Lower-case file extension of a path ("png"), or "" when none. */
const char *cli_extension(const char *path);
/* True when argv has --help or -h (print usage then). */
bool cli_wants_help(int argc, char **argv);

#endif
