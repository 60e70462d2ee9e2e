// drift bench <name> ...: dispatches to the benchmarks listed in bench.h (DRIFT_BENCH_LIST).
#include "bench.h"
#include "cli.h"

#include <stdio.h>
#include <string.h>

#define DRIFT__BENCH_ENTRY(name, fn, summary) { name, fn, summary },
static const cli_subcommand benches[] = { DRIFT_BENCH_LIST(DRIFT__BENCH_ENTRY) };
#undef DRIFT__BENCH_ENTRY

bool bench_open(cli_session *s, const char *cmd, const char *scene_path, const char *default_scene,
                long threads)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", DRIFT_SOURCE_DIR, default_scene);
    return cli_session_open(&(cli_session_desc){ .cmd = cmd,
                                                 .scene_path = scene_path ? scene_path : path,
                                                 .threads = (int)threads },
                            s);
}

int drift_cmd_bench(int argc, char **argv)
{
    return cli_dispatch("bench", "benchmarks",
                        "'drift bench <name> --help' describes each one; docs/benchmarks.md has "
                        "recorded figures.\n",
                        benches, sizeof benches / sizeof *benches, argc, argv);
}
