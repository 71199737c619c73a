/* `spinneret view`: the real-time viewer lives in viewer/ and is built only
 * when GLFW and OpenGL are found; without them this says how to get it. */
#include "cli.h"

#ifdef SPN_HAVE_VIEWER
int spn_view_main(int argc, char **argv);
int cmd_view(int argc, char **argv) { return spn_view_main(argc, argv); }
#else
int cmd_view(int argc, char **argv)
{
    (void)argc, (void)argv;
    return cli_fail("view", "this build has no viewer: install libglfw3-dev and libgl-dev "
                            "(make deps does), then rebuild");
}
#endif
