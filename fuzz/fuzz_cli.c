/* Fuzz harness: the whole command line of every subcommand, in process.
 *
 * The input is text: the first line names the subcommand, every further line
 * is one argument (so seeds and crash files read like command lines, and the
 * dictionary of option names, built from each command's --help, splices in
 * whole options). Each command must answer with exit 0, 1 or 2 — never crash,
 * leak, hang, or allocate absurdly (libFuzzer's -malloc_limit_mb, -timeout).
 *
 * Runs in a private temporary folder holding small fixtures (a web file
 * "web.json", a picture "bg.png", a tetrahedron "m.obj" and a scene with it
 * "s.pov"); after each input everything in it is
 * removed and the fixtures are written again, so one input cannot feed the
 * next. PATH is emptied: no ffmpeg or povray is started (their absence is an
 * error path worth fuzzing; the programs themselves are not ours).
 *
 * A crash input is replayed by tests/cli/hostile_found.sh once written to
 * tests/data/bad/hostile_cli/ with its row's appended arguments.
 *
 * Hangs are kept out by the table below, one row per subcommand: every
 * number in the arguments must lie in [-cap, cap] and, unless zero, be at
 * least 1e-3 in size (a 1e-9 s time step over 60 s is a legitimate command
 * that takes hours; the extreme values themselves are walked by
 * tests/cli/hostile_options.sh with a timeout). Extra arguments appended
 * after the fuzzed ones override anything costly (getopt keeps the last). */
#include "cli.h"

#include <spinneret/render.h>

#include <dirent.h>
#include <fcntl.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define SPN_COMMAND(name, fn, summary) int fn(int argc, char **argv);
#include "commands.def"
#undef SPN_COMMAND

typedef struct command {
    const char *name;
    int (*fn)(int argc, char **argv);
} command;

static const command commands[] = {
#define SPN_COMMAND(name, fn, summary) {#name, fn},
#include "commands.def"
#undef SPN_COMMAND
    {NULL, NULL}};

/* How far each command may be pushed: the largest number allowed anywhere in
 * its arguments, and arguments appended after the fuzzed ones. A command
 * without a row gets the default row. */
typedef struct limits {
    const char *name;
    double cap;
    const char *extra[8]; /* NULL-terminated: at most 7 */
} limits;

static const limits table[] = {
    {"info", 1e6, {NULL}},
    {"settle", 200, {NULL}},
    {"build", 200, {"--settle-time", "0.05", "--frame-count", "3", "--size", "0.3"}},
    {"animate", 200, {"--duration", "0.05", "--size", "48x48", "--quiet"}}, /* air: 0.4 s a run, 20x under ASan */
    /* the web's own solver: switched to implicit steps, a fill of 18,728
     * threads on the 3x5 web took over 25 s under the fuzzer's instrumentation */
    {"inscribe", 200, {"--raster", "48", "--max-time", "0.05", "--solver", "symplectic"}},
    {"view", 0, {"--help"}}, /* a window: only its option parser is worth fuzzing */
    {"render", 200, {"--quiet", "--size", "64x64", NULL}}, /* 6 frames of 1200x1200 took 10 s */
    {"export", 200, {"--quiet", NULL}},
    {"shoot", 200, {"--max-time", "0.3", "--quiet", "--size", "64x64"}},
    {"drop", 100, {"--max-time", "0.3", "--size", "64x64", NULL}},
    {"film", 100, {"--max-time", "0.3", NULL}},
    {NULL, 100, {NULL}}, /* default */
};

static const char tetra_obj[] = "v 0 0.5 0\nv 0.1 0.5 0\nv 0 0.6 0\nv 0 0.5 0.1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
static const char tetra_pov[] =
    "camera { location <0, 0.7, -2> look_at <0, 0.4, 0> }\n"
    "#declare Floor = mesh2 {\n  #local spring_system_fixed = true;\n"
    "  vertex_vectors { 4, <-1, 0, -1>, <1, 0, -1>, <1, 0, 1>, <-1, 0, 1> }\n"
    "  face_indices { 2, <0, 2, 1>, <0, 3, 2> }\n}\n"
    "#declare Tetra = mesh2 {\n  #local spring_system_ks = 400;\n  #local spring_system_kb = 400;\n"
    "  #local spring_system_ds = 0.2;\n  #local spring_system_db = 0.2;\n  #local spring_system_mass = 0.1;\n"
    "  #local spring_system_vicinity = 0;\n"
    "  vertex_vectors { 4, <0, 0.5, 0>, <0.1, 0.5, 0>, <0, 0.6, 0>, <0, 0.5, 0.1> }\n"
    "  face_indices { 4, <0, 2, 1>, <0, 1, 3>, <0, 3, 2>, <1, 2, 3> }\n}\n";

enum { MAX_ARGS = 24, MAX_ARG_LEN = 512 };

static char folder[64];
static spn_buffer web_fixture, png_fixture;

static const limits *limits_for(const char *name)
{
    const limits *l = table;
    while (l->name && strcmp(l->name, name) != 0) l++;
    return l;
}

/* False when any number in `arg` is beyond the cap or a tiny non-zero value. */
static bool numbers_within(const char *arg, double cap)
{
    for (const char *p = arg; *p;) {
        if (!strchr("0123456789.", *p) || (p > arg && strchr("0123456789.eE+-", p[-1]))) {
            p++;
            continue;
        }
        char *end;
        double v = fabs(strtod(p, &end));
        if (end == p) {
            p++;
            continue;
        }
        if (!(v <= cap) || (v != 0 && v < 1e-3)) return false;
        p = end;
    }
    /* "inf", "nan" and hex floats go through the parsers' own checks; a
     * hex float can still be huge, so refuse those outright. */
    return !strstr(arg, "0x") && !strstr(arg, "0X");
}

static void write_file(const char *name, const spn_buffer *b)
{
    FILE *fp = fopen(name, "wb");
    if (!fp) abort();
    fwrite(b->data, 1, b->size, fp);
    fclose(fp);
}

static void remove_tree(const char *path)
{
    struct stat st;
    if (lstat(path, &st) != 0) return;
    if (S_ISDIR(st.st_mode)) {
        DIR *d = opendir(path);
        for (struct dirent *e; d && (e = readdir(d));) {
            if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..")) continue;
            char sub[1024];
            snprintf(sub, sizeof sub, "%s/%s", path, e->d_name);
            remove_tree(sub);
        }
        if (d) closedir(d);
        rmdir(path);
    } else {
        unlink(path);
    }
}

static void reset_folder(void)
{
    DIR *d = opendir(".");
    for (struct dirent *e; d && (e = readdir(d));)
        if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) remove_tree(e->d_name);
    if (d) closedir(d);
    write_file("web.json", &web_fixture);
    write_file("bg.png", &png_fixture);
    spn_buffer obj = {(char *)tetra_obj, sizeof tetra_obj - 1, 0}, pov = {(char *)tetra_pov, sizeof tetra_pov - 1, 0};
    write_file("m.obj", &obj);
    write_file("s.pov", &pov);
}

static void slurp(const char *path, spn_buffer *b)
{
    FILE *fp = fopen(path, "rb");
    if (!fp) abort();
    spn_sink sink = spn_sink_buffer(b);
    char chunk[4096];
    for (size_t n; (n = fread(chunk, 1, sizeof chunk, fp)) > 0;) sink.write(sink.ctx, chunk, n);
    fclose(fp);
}

static void remove_folder(void)
{
    if (chdir("/") == 0) remove_tree(folder);
}

static void make_fixtures(void)
{
    snprintf(folder, sizeof folder, "/tmp/spn-fuzz-cli-XXXXXX");
    if (!mkdtemp(folder) || chdir(folder) != 0) abort();
    atexit(remove_folder);
    spn_orb_scene_def od = spn_orb_scene_def_default();
    od.rings = 3;
    od.radials = 5;
    spn_world *w;
    if (spn_scene_orb(NULL, &od, &w) != SPN_OK || spn_web_save(w, "web.json") != SPN_OK) abort();
    spn_render_def rd = spn_render_def_default();
    rd.width = rd.height = 8;
    if (spn_render_file(w, &rd, "bg.png") != SPN_OK) abort();
    spn_world_destroy(w);
    slurp("web.json", &web_fixture);
    slurp("bg.png", &png_fixture);
}

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc, (void)argv;
    /* Worlds of at most 20,000 particles: a builder asked for a 52 m web took
     * 25 s under the sanitizers to reach the program's default limit of 4 million. */
    spn_set_max_particles(20000);
    setenv("PATH", "/nonexistent", 1);
    unsetenv("SPN_FFMPEG");
    make_fixtures();
    return 0;
}

/* Splits the input into lines: words[0] the command, the rest its arguments.
 * Returns the count, or 0 when the input is not a usable command line. */
static int split(const uint8_t *data, size_t size, char *text, char **words)
{
    if (size > MAX_ARGS * MAX_ARG_LEN) return 0;
    memcpy(text, data, size);
    text[size] = '\0';
    if (strlen(text) != size) return 0; /* argv cannot hold a NUL */
    int n = 0;
    for (char *line = text, *next; line && n < MAX_ARGS; line = next) {
        next = strchr(line, '\n');
        if (next) *next++ = '\0';
        if (strlen(line) > MAX_ARG_LEN) return 0;
        words[n++] = line;
    }
    return n;
}

/* Runs one command with stdout and stderr silenced; returns its exit code.
 * stdout is silenced at its descriptor, stderr by swapping the FILE: the
 * sanitizers write their reports to descriptor 2, which must stay open. */
static int run(const command *c, int argc, char **argv)
{
    fflush(stdout);
    int out = dup(1), null = open("/dev/null", O_WRONLY);
    dup2(null, 1);
    FILE *saved = stderr;
    stderr = fopen("/dev/null", "w");
    optind = 0; /* glibc: 0 re-initialises getopt completely */
    int rc = c->fn(argc, argv);
    spn_render_release_caches();
    fflush(stdout);
    fclose(stderr);
    stderr = saved;
    dup2(out, 1);
    close(out), close(null);
    return rc;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char *text = malloc(size + 1);
    char *words[MAX_ARGS + 8];
    int n = split(data, size, text, words);
    const command *c = commands;
    while (n > 0 && c->name && strcmp(c->name, words[0]) != 0) c++;
    if (n == 0 || !c->name) return free(text), -1;
    const limits *lim = limits_for(c->name);
    for (int i = 1; i < n; i++)
        if (!numbers_within(words[i], lim->cap) || strcmp(words[i], "--") == 0) return free(text), -1;
    for (int i = 0; i < 8 && lim->extra[i]; i++) words[n++] = (char *)lim->extra[i];
    words[n] = NULL;
    int rc = run(c, n, words);
    if (rc < 0 || rc > 2) {
        fprintf(stderr, "fuzz_cli: '%s' exited %d (expected 0, 1 or 2)\n", c->name, rc);
        abort();
    }
    reset_folder();
    free(text);
    return 0;
}
