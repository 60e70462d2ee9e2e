// Placeholder until the bench subcommand lands; it fails loudly rather than pretend.
#include "cli.h"

#include <stdio.h>

int drift_cmd_bench(int argc, char **argv)
{
    (void)argc;
    (void)argv;
    fprintf(stderr, "drift bench: not implemented yet\n");
    return 1;
}
