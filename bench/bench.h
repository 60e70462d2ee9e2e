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
#define DRIFT_BENCH_LIST(X) \
    X("rays", drift_bench_rays, "rays/s through drift's accel vs raw Embree, one thread")   \
    X("frame", drift_bench_frame, "hybrid frame passes vs the primary-visibility pass")      \
    X("isg", drift_bench_isg, "image space gathering: Table 1 timings, FLIP vs baselines")  \
    X("aaf", drift_bench_aaf, "axis-aligned filtering: RMSE vs spp against plain Monte Carlo") \
    X("sir", drift_bench_sir, "smart image refinement vs pure ray tracing (Table 1)")      \
    X("ism", drift_bench_ism, "imperfect shadow maps and instant radiosity vs the path tracer")

#define DRIFT__BENCH_DECLARE(name, fn, summary) int fn(int argc, char **argv);
DRIFT_BENCH_LIST(DRIFT__BENCH_DECLARE)
#undef DRIFT__BENCH_DECLARE

#endif // DRIFT_BENCH_H
