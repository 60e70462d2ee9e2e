// drift bench <name> ...: dispatches to the benchmarks listed in bench.h.
#include "bench.h"
#include "cli.h"

#include <stdio.h>
#include <string.h>

typedef struct bench_entry {
    const char *name;
    int (*run)(int argc, char **argv);
    const char *summary;
} bench_entry;

#define DRIFT__BENCH_ENTRY(name, fn, summary) { name, fn, summary },
static const bench_entry benches[] = { DRIFT_BENCH_LIST(DRIFT__BENCH_ENTRY) };
#undef DRIFT__BENCH_ENTRY

static void print_usage(FILE *out)
{
    fprintf(out, "usage: drift bench <name> [options]\n\nbenchmarks:\n");
    for (size_t i = 0; i < sizeof(benches) / sizeof(benches[0]); ++i) {
        fprintf(out, "  %-10s %s\n", benches[i].name, benches[i].summary);
    }
    fprintf(out, "\n'drift bench <name> --help' describes each one; docs/benchmarks.md has "
                 "recorded figures.\n");
}

int drift_cmd_bench(int argc, char **argv)
{
    if (argc < 2 || strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0) {
        print_usage(argc < 2 ? stderr : stdout);
        return argc < 2 ? 2 : 0;
    }
    for (size_t i = 0; i < sizeof(benches) / sizeof(benches[0]); ++i) {
        if (strcmp(argv[1], benches[i].name) == 0) {
            return benches[i].run(argc - 1, argv + 1);
        }
    }
    fprintf(stderr, "drift bench: unknown benchmark '%s'\n\n", argv[1]);
    print_usage(stderr);
    return 2;
}
