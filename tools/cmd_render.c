// Placeholder until the render subcommand lands; it fails loudly rather than pretend.
#include "cli.h"

#include <stdio.h>

int drift_cmd_render(int argc, char **argv)
{
    (void)argc;
    (void)argv;
    fprintf(stderr, "drift render: not implemented yet\n");
    return 1;
}
