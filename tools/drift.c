// drift: command-line entry point. Dispatches to one subcommand per file (tools/cmd_*.c).
#include "cli.h"

#include <stdio.h>
#include <string.h>

typedef struct subcommand {
    const char *name;
    int (*run)(int argc, char **argv);
    const char *summary;
} subcommand;

static const subcommand subcommands[] = {
    { "render", drift_cmd_render, "render a scene (reference path tracer)" },
    { "diff", drift_cmd_diff, "compare two images: MSE, RMSE, relMSE, PSNR, SSIM, FLIP" },
    { "info", drift_cmd_info, "print a scene's triangle, material, light, texture counts" },
    { "bench", drift_cmd_bench, "benchmarks (drift bench --help)" },
    { "view", drift_cmd_view, "interactive viewer: hybrid techniques against the reference" },
    { "refine", drift_cmd_refine, "smart image refinement: fit the metric weights (lambda)" },
    { "glare", drift_cmd_glare, "temporal glare (thesis ch. 8) on an HDR image or sequence" },
};

static void print_usage(FILE *out)
{
    fprintf(out, "usage: drift <command> [options]\n\ncommands:\n");
    for (size_t i = 0; i < sizeof(subcommands) / sizeof(subcommands[0]); ++i) {
        fprintf(out, "  %-8s %s\n", subcommands[i].name, subcommands[i].summary);
    }
    fprintf(out, "\n'drift <command> --help' describes each command.\n");
}

int main(int argc, char **argv)
{
    if (argc < 2 || strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0) {
        print_usage(argc < 2 ? stderr : stdout);
        return argc < 2 ? 2 : 0;
    }
    for (size_t i = 0; i < sizeof(subcommands) / sizeof(subcommands[0]); ++i) {
        if (strcmp(argv[1], subcommands[i].name) == 0) {
            return subcommands[i].run(argc - 1, argv + 1);
        }
    }
    fprintf(stderr, "drift: unknown command '%s'\n\n", argv[1]);
    print_usage(stderr);
    return 2;
}
