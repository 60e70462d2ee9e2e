// drift bench <name> ...: dispatches to the benchmarks listed in bench.h (DRIFT_BENCH_LIST).
#include "bench.h"
#include "cli.h"

#include <stdio.h>
#include <string.h>

#define DRIFT__BENCH_ENTRY(name, fn, summary) { name, fn, summary },
static const cli_subcommand benches[] = { DRIFT_BENCH_LIST(DRIFT__BENCH_ENTRY) };
#undef DRIFT__BENCH_ENTRY

int drift_cmd_bench(int argc, char **argv)
{
    return cli_dispatch("bench", "benchmarks",
                        "'drift bench <name> --help' describes each one; docs/benchmarks.md has "
                        "recorded figures.\n",
                        benches, sizeof benches / sizeof *benches, argc, argv);
}
