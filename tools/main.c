/* spinneret: one program, subcommands dispatched from tools/commands.def. */
#include "cli.h"

#include <spinneret/render.h>

#include <stdio.h>
#include <string.h>

#define SPN_COMMAND(name, fn, summary) int fn(int argc, char **argv);
#include "commands.def"
#undef SPN_COMMAND

typedef struct command {
    const char *name;
    int (*fn)(int argc, char **argv);
    const char *summary;
} command;

static const command commands[] = {
#define SPN_COMMAND(name, fn, summary) {#name, fn, summary},
#include "commands.def"
#undef SPN_COMMAND
    {NULL, NULL, NULL}};

static void usage(FILE *out)
{
    fprintf(out, "usage: spinneret COMMAND [options]\n"
                 "       spinneret COMMAND --help\n"
                 "       spinneret --version\n\ncommands:\n");
    for (const command *c = commands; c->name; c++) fprintf(out, "  %-10s %s\n", c->name, c->summary);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        usage(stderr);
        return CLI_EXIT_USAGE;
    }
    if (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0 || strcmp(argv[1], "help") == 0) {
        usage(stdout);
        return 0;
    }
    if (strcmp(argv[1], "--version") == 0) {
        printf("spinneret %s\n", spn_version());
        return 0;
    }
    for (const command *c = commands; c->name; c++)
        if (strcmp(argv[1], c->name) == 0) {
            int rc = c->fn(argc - 1, argv + 1);
            spn_render_release_caches(); /* font caches: keeps leak checkers quiet */
            return rc;
        }
    fprintf(stderr, "spinneret: unknown command '%s'\n", argv[1]);
    usage(stderr);
    return CLI_EXIT_USAGE;
}
