/* spinneret render FILE -o OUT: draw a web to PNG, SVG or PDF with cairo
 * (spn_render_file). The options are shared with `export` (render_options.h). */
#include "render_options.h"

#include <stdio.h>
#include <string.h>

static const char *const CMD = "render";

static void usage(FILE *out)
{
    fprintf(out,
            "usage: spinneret render FILE -o OUT [options]\n"
            "Draw the web in FILE (a web file, or scene:orb, scene:orb:RINGSxRADIALS,\n"
            "scene:chain, scene:cloth) to OUT: .png, .svg or .pdf. Same file and options,\n"
            "same pixels.\n\n"
            "  -o, --output OUT           the picture (required)\n"
            "  -h, --help                 this text\n");
    render_options_help(out);
}

static int parse(int argc, char **argv, render_options *ro, const char **in, const char **out)
{
    static const struct option options[] = {{"output", required_argument, NULL, 'o'},
                                            {"help", no_argument, NULL, 'h'},
                                            RENDER_LONG_OPTIONS,
                                            {NULL, 0, NULL, 0}};
    opterr = 0;
    for (int c; (c = getopt_long(argc, argv, ":o:h", options, NULL)) != -1;) {
        if (c == 'o') *out = optarg;
        else if (c == 'h') return usage(stdout), 0;
        else if (c == ':') return cli_usage(CMD, "%s: missing value", argv[optind - 1]);
        else if (c == '?') return cli_usage(CMD, "unknown option '%s'", argv[optind - 1]);
        else if (render_options_parse(CMD, c, optarg, ro) < 0) return CLI_EXIT_USAGE;
    }
    if (optind >= argc) return cli_usage(CMD, "missing FILE");
    if (optind + 1 < argc) return cli_usage(CMD, "unexpected argument '%s'", argv[optind + 1]);
    *in = argv[optind];
    if (!*out || !**out) return cli_usage(CMD, "-o/--output: the output picture is required");
    const char *ext = cli_extension(*out);
    if (strcmp(ext, "png") != 0 && strcmp(ext, "svg") != 0 && strcmp(ext, "pdf") != 0)
        return cli_usage(CMD, "%s: unknown output type '.%s' (use .png, .svg or .pdf)", *out, ext);
    return -1;
}

int cmd_render(int argc, char **argv)
{
    render_options ro;
    render_options_init(&ro);
    const char *in = NULL, *out = NULL;
    int code = parse(argc, argv, &ro, &in, &out);
    if (code >= 0) return code;
    spn_world *w;
    if ((code = load_world(CMD, in, &w)) != 0) return code;
    render_options_finish(&ro, w);
    spn_status st = spn_render_file(w, &ro.def, out);
    spn_world_destroy(w);
    return st == SPN_OK ? 0 : cli_fail_status(CMD, st);
}
