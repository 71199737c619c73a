#include "cli.h"

#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <ctype.h>

static void vprint(const char *cmd, const char *hint, const char *fmt, va_list ap)
{
    fprintf(stderr, "spinneret%s%s: ", cmd ? " " : "", cmd ? cmd : "");
    vfprintf(stderr, fmt, ap);
    if (hint) fprintf(stderr, " (see 'spinneret %s --help')", hint);
    fputc('\n', stderr);
}

/* One line: the complaint, then where the options are explained. */
int cli_usage(const char *cmd, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vprint(cmd, cmd ? cmd : "", fmt, ap);
    va_end(ap);
    return CLI_EXIT_USAGE;
}

int cli_fail(const char *cmd, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vprint(cmd, NULL, fmt, ap);
    va_end(ap);
    return CLI_EXIT_FAIL;
}

int cli_fail_status(const char *cmd, spn_status st)
{
    const char *msg = spn_last_error();
    if (st == SPN_ERR_INVALID) return cli_usage(cmd, "%s", *msg ? msg : "invalid input");
    return cli_fail(cmd, "%s", *msg ? msg : spn_status_name(st));
}

bool cli_double(const char *cmd, const char *opt, const char *text, double lo, double hi, double *out)
{
    char *end = NULL;
    errno = 0;
    double v = text ? strtod(text, &end) : NAN;
    if (!text || end == text || *end != '\0' || !isfinite(v) || v < lo || v > hi) {
        cli_usage(cmd, "%s: expected a number in [%g, %g], got '%s'", opt, lo, hi, text ? text : "");
        return false;
    }
    *out = v;
    return true;
}

bool cli_int(const char *cmd, const char *opt, const char *text, long lo, long hi, long *out)
{
    char *end = NULL;
    errno = 0;
    long v = text ? strtol(text, &end, 10) : 0;
    if (!text || end == text || *end != '\0' || errno == ERANGE || v < lo || v > hi) {
        cli_usage(cmd, "%s: expected a whole number in [%ld, %ld], got '%s'", opt, lo, hi, text ? text : "");
        return false;
    }
    *out = v;
    return true;
}

bool cli_u64(const char *cmd, const char *opt, const char *text, uint64_t *out)
{
    char *end = NULL;
    errno = 0;
    unsigned long long v = (text && *text != '-') ? strtoull(text, &end, 10) : 0;
    if (!text || *text == '-' || end == text || *end != '\0' || errno == ERANGE) {
        cli_usage(cmd, "%s: expected a whole number in [0, 18446744073709551615], got '%s'", opt, text ? text : "");
        return false;
    }
    *out = (uint64_t)v;
    return true;
}

bool cli_vec3(const char *cmd, const char *opt, const char *text, bool allow_2d, spn_vec3 *out)
{
    double c[3] = {0, 0, 0};
    int n = 0;
    const char *p = text ? text : "";
    while (n < 3) {
        char *end = NULL;
        double v = strtod(p, &end);
        if (end == p || !isfinite(v)) break;
        c[n++] = v;
        while (isspace((unsigned char)*end)) end++;
        if (*end != ',') {
            p = end;
            break;
        }
        p = end + 1;
    }
    if (*p != '\0' || n < (allow_2d ? 2 : 3)) {
        cli_usage(cmd, "%s: expected %s of finite numbers, got '%s'", opt, allow_2d ? "X,Y or X,Y,Z" : "X,Y,Z",
                  text ? text : "");
        return false;
    }
    *out = spn_v3(c[0], c[1], c[2]);
    return true;
}

bool cli_vec3_bounded(const char *cmd, const char *opt, const char *text, double bound, spn_vec3 *out)
{
    spn_vec3 v;
    if (!cli_vec3(cmd, opt, text, false, &v)) return false;
    if (!(fabs(v.x) <= bound && fabs(v.y) <= bound && fabs(v.z) <= bound)) {
        cli_usage(cmd, "%s: expected X,Y,Z with each in [%g, %g], got '%s'", opt, -bound, bound, text);
        return false;
    }
    *out = v;
    return true;
}

int cli_choice(const char *text, const char *const *names, int count)
{
    for (int i = 0; i < count; i++)
        if (strcmp(text, names[i]) == 0) return i;
    return -1;
}

bool cli_size(const char *cmd, const char *opt, const char *text, int max_side, int *w, int *h)
{
    char *end = NULL;
    long a = text ? strtol(text, &end, 10) : 0, b = 0;
    bool ok = text && end != text && (*end == 'x' || *end == 'X');
    if (ok) {
        const char *q = end + 1;
        b = strtol(q, &end, 10);
        ok = end != q && *end == '\0';
    }
    if (!ok || a < 1 || b < 1 || a > max_side || b > max_side) {
        cli_usage(cmd, "%s: expected WxH with each side in [1, %d], got '%s'", opt, max_side, text ? text : "");
        return false;
    }
    *w = (int)a;
    *h = (int)b;
    return true;
}

const char *cli_extension(const char *path)
{
    static char ext[16];
    const char *dot = strrchr(path, '.');
    const char *slash = strrchr(path, '/');
    if (!dot || (slash && dot < slash) || strlen(dot + 1) >= sizeof ext) return "";
    size_t i = 0;
    for (const char *p = dot + 1; *p; p++) ext[i++] = (char)tolower((unsigned char)*p);
    ext[i] = '\0';
    return ext;
}

bool cli_wants_help(int argc, char **argv)
{
    for (int i = 1; i < argc; i++)
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) return true;
    return false;
}

static bool max_particles(const char *cmd, const char *text)
{
    long n;
    if (!cli_int(cmd, "--max-particles", text, 1, (long)UINT32_MAX - 1, &n)) return false;
    spn_set_max_particles((uint32_t)n);
    return true;
}

int cli_global_options(const char *cmd, int *argc, char **argv)
{
    static const char opt[] = "--max-particles";
    int out = 0;
    for (int i = 0; i < *argc; i++) {
        if (strcmp(argv[i], "--") == 0) { /* operands from here on */
            while (i < *argc) argv[out++] = argv[i++];
            break;
        }
        if (strncmp(argv[i], opt, sizeof opt - 1) != 0 || (argv[i][sizeof opt - 1] && argv[i][sizeof opt - 1] != '=')) {
            argv[out++] = argv[i];
            continue;
        }
        const char *value = argv[i][sizeof opt - 1] == '=' ? argv[i] + sizeof opt : (i + 1 < *argc ? argv[++i] : NULL);
        if (!value) return cli_usage(cmd, "--max-particles: missing value");
        if (!max_particles(cmd, value)) return CLI_EXIT_USAGE;
    }
    argv[out] = NULL;
    *argc = out;
    return -1;
}

void cli_interruptible(uint64_t total)
{
    spn_interrupt_progress(0, total);
    spn_interrupt_graceful(true);
}

int cli_start_helper(pthread_t *thread, void *(*run)(void *), void *arg)
{
    sigset_t stops, old;
    sigemptyset(&stops);
    sigaddset(&stops, SIGINT);
    sigaddset(&stops, SIGTERM);
    sigaddset(&stops, SIGALRM);
    pthread_sigmask(SIG_BLOCK, &stops, &old); /* the new thread inherits the mask */
    int started = pthread_create(thread, NULL, run, arg);
    pthread_sigmask(SIG_SETMASK, &old, NULL);
    return started;
}

int cli_report_interrupt(const char *cmd, uint64_t done, uint64_t total, const char *kept, int code)
{
    int sig = spn_interrupted();
    spn_interrupt_graceful(false);
    if (!sig) return code;
    fprintf(stderr, "spinneret %s: interrupted (%s) after %llu of %llu; %s\n", cmd, spn_signal_name(sig),
            (unsigned long long)done, (unsigned long long)total, kept);
    return 128 + sig;
}

bool cli_output_writable(const char *cmd, const char *path)
{
    spn_atomic_file f;
    if (spn_atomic_open(&f, path, false) != SPN_OK) {
        cli_fail(cmd, "%s", spn_last_error());
        return false;
    }
    spn_atomic_abort(&f);
    return true;
}

int cli_parse_options(const char *cmd, int argc, char **argv, const char *shortopts, const struct option *options,
                      void (*usage)(FILE *), cli_option_fn one, void *ctx)
{
    opterr = 0;
    for (int c; (c = getopt_long(argc, argv, shortopts, options, NULL)) != -1;) {
        if (c == 'h') return usage(stdout), 0;
        if (c == ':') return cli_usage(cmd, "%s: missing value", argv[optind - 1]);
        int r = c == '?' ? 0 : one(c, optarg, ctx);
        if (r == 0) return cli_usage(cmd, "unknown option '%s'", argv[optind - 1]);
        if (r < 0) return CLI_EXIT_USAGE;
    }
    return -1;
}
