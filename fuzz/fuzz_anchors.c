/* Fuzz harness: the anchor list of `spinneret build --anchors "x,y[,z];..."`.
 * The text goes to the build command's own parser (it is static in
 * tools/cmd_build.c) with no output named, so every input ends in a usage
 * error right after parsing (exit 2) — nothing is built. Any other exit code,
 * a crash or a read past the text is a bug. */
#include "cli.h"

#include <fcntl.h>
#include <getopt.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

int cmd_build(int argc, char **argv);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size > 4096 || memchr(data, 0, size)) return -1; /* argv cannot hold a NUL */
    /* "--anchors=TEXT": as a separate argument "-h" would be taken for --help. */
    char *text = malloc(size + 11);
    memcpy(text, "--anchors=", 10);
    memcpy(text + 10, data, size);
    text[size + 10] = '\0';
    char *argv[] = {"build", "--method", "geometric", text, NULL};
    int err = dup(2), null = open("/dev/null", O_WRONLY);
    dup2(null, 2);
    optind = 0;
    int rc = cmd_build(4, argv);
    dup2(err, 2);
    close(err), close(null);
    free(text);
    if (rc != CLI_EXIT_USAGE) abort(); /* -o is missing: always a usage error */
    return 0;
}
