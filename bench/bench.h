// drift bench: benchmarks behind `drift bench <name> ...` (bench/bench_main.c dispatches).
//
// To add one: write bench/bench_<name>.c with `int drift_bench_<name>(int argc, char **argv)`
// and add a line to DRIFT_BENCH_LIST below. Each entry point takes the arguments after its
// own name (argv[0] is the name), prints its own --help, and returns the process exit
// status: 0 success, 1 failure, 2 usage error. Benchmarks may call Embree directly (to
// compare against drift); the library itself never does outside src/accel.
#ifndef DRIFT_BENCH_H
#define DRIFT_BENCH_H

// X(name, function, one-line summary)
#define DRIFT_BENCH_LIST(X)                                                                      \
    X("rays", drift_bench_rays, "rays/s through drift's accel vs raw Embree, one thread")        \
    X("frame", drift_bench_frame, "hybrid frame passes vs the primary-visibility pass")          \
    X("isg", drift_bench_isg, "image space gathering: Table 1 timings, FLIP vs baselines")       \
    X("aaf", drift_bench_aaf, "axis-aligned filtering: RMSE vs spp against plain Monte Carlo")   \
    X("sir", drift_bench_sir, "smart image refinement vs pure ray tracing (Table 1)")            \
    X("glare", drift_bench_glare, "temporal glare: Table 8.2 phases, convolution, ms a frame")   \
    X("ssdo", drift_bench_ssdo,                                                                  \
      "SSAO, GTAO, SSDO(+bounce): Table 4.1 ms, FLIP vs the path tracer")                        \
    X("ism", drift_bench_ism, "imperfect shadow maps and instant radiosity vs the path tracer")  \
    X("micro", drift_bench_micro, "micro-rendering: rate vs K, density, points; NRMS vs the pt") \
    X("micro-bounces", drift_bench_micro_bounces,                                                \
      "micro-rendering's points lit by radiosity or photons: NRMS, FLIP vs the pt, 1-3 bounces") \
    X("frontier", drift_bench_frontier,                                                          \
      "equal-time frontier: pt, pt + a-trous, hybrid rows vs a whole-frame reference")           \
    X("redit", drift_bench_redit, "reflection editing: edit-field Mpixel/s vs constraints")      \
    X("cycles", drift_bench_cycles,                                                              \
      "drift's path tracer vs Blender Cycles: process and render s, FLIP, equal-error ratio")

#include "cli.h"

#define DRIFT__BENCH_DECLARE(name, fn, summary) int fn(int argc, char **argv);
DRIFT_BENCH_LIST(DRIFT__BENCH_DECLARE)
#undef DRIFT__BENCH_DECLARE

// Option rows every benchmark has (T: its options struct, with `long threads; bool json;`).
#define BENCH_OPTION_THREADS(T) \
    CLI_INT("--threads", "T", T, threads, 0, 256, "worker threads (default 1: per-thread figures)")
#define BENCH_OPTION_JSON(T) CLI_FLAG("--json", T, json, "one JSON object on stdout")

// Opens the context and the scene `scene_path` (NULL: DRIFT_SOURCE_DIR/`default_scene`, a
// path in the repository) with its accel (cli_session_open); close it with
// cli_session_close whatever this returns.
bool bench_open(cli_session *s, const char *cmd, const char *scene_path, const char *default_scene,
                long threads);

// A list option ("--vpls 64,256,1024"): 1 to `max` comma-separated integers in [lo, hi] into
// out[0 .. *count - 1]. Otherwise prints "drift <cmd>: <flag> expects 1 to <max>
// comma-separated integers in [lo, hi], got '<text>'", leaves *count and out as they were
// and returns false.
bool bench_parse_list(const char *cmd, const char *flag, const char *text, long lo, long hi,
                      int max, long *out, int *count);

// The frontier's whole-frame path tracer (drift bench frontier, drift report's sir cell): every
// effect, max depth 8, `spp` samples a pixel from `seed`; its RGB into a new *out, its rays
// (camera, shadow, bounce) into *rays when not NULL. The reference: the same at a fixed seed.
drift_result bench_frontier_path_trace(drift_context *ctx, const drift_scene *scene,
                                       const drift_accel *accel, int32_t width, int32_t height,
                                       uint32_t spp, uint32_t seed, const atomic_bool *cancel,
                                       drift_image *out, uint64_t *rays);
drift_result bench_frontier_reference(drift_context *ctx, const drift_scene *scene,
                                      const drift_accel *accel, int32_t width, int32_t height,
                                      uint32_t spp, drift_image *out);

#endif // DRIFT_BENCH_H
