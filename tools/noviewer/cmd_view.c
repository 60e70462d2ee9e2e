// drift view in a build without SDL2 (it was not found, or -DDRIFT_VIEWER=OFF): the command
// stays in `drift --help` and says how to get the window.
#include "cli.h"

#include <stdio.h>

int drift_cmd_view(int argc, char **argv)
{
    (void)argc;
    (void)argv;
    fprintf(stderr, "drift view: this drift was built without the viewer (SDL2 was not found, "
                    "or -DDRIFT_VIEWER=OFF); install libsdl2-dev (scripts/install-deps.sh) and "
                    "configure again\n");
    return 1;
}
