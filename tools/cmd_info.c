// Placeholder until the info subcommand lands; it fails loudly rather than pretend.
#include "cli.h"

#include <stdio.h>

int drift_cmd_info(int argc, char **argv)
{
    (void)argc;
    (void)argv;
    fprintf(stderr, "drift info: not implemented yet\n");
    return 1;
}
