// drift bench <name> ...: dispatches to the benchmarks listed in bench.h (DRIFT_BENCH_LIST).
#include "bench.h"
#include "cli.h"
#include "distributed/sweep.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
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

bool bench_parse_list(const char *cmd, const char *flag, const char *text, long lo, long hi,
                      int max, long *out, int *count)
{
    return cli_parse_list(cmd, flag, text, lo, hi, max, out, count);
}

int drift_cmd_bench(int argc, char **argv)
{
    sweep_begin(); // mpirun -n N drift bench ...: the sweeps' renders over the ranks
    static const char *const spread[] = { "aaf", "isg", "sir", "micro", "micro-bounces", "ism" };
    bool spreads = false;
    for (size_t k = 0; argc >= 2 && k < sizeof spread / sizeof *spread; ++k) {
        spreads = spreads || strcmp(argv[1], spread[k]) == 0;
    }
    if (!spreads && sweep_rank() != 0) {
        return sweep_end(0); // a bench that does not spread runs on rank 0 alone
    }
    int status = cli_dispatch("bench", "benchmarks",
                              "'drift bench <name> --help' describes each one; docs/benchmarks.md "
                              "has recorded figures.\n",
                              benches, sizeof benches / sizeof *benches, argc, argv);
    return sweep_end(status);
}
