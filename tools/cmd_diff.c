// Placeholder until the diff subcommand lands; it fails loudly rather than pretend.
#include "cli.h"

#include <stdio.h>

int drift_cmd_diff(int argc, char **argv)
{
    (void)argc;
    (void)argv;
    fprintf(stderr, "drift diff: not implemented yet\n");
    return 1;
}
