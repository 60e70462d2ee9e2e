// Shared pieces of the drift command-line tool: subcommand entry points, option parsing
// helpers that reject malformed numbers, and a logger that prints to stderr.
#ifndef DRIFT_TOOLS_CLI_H
#define DRIFT_TOOLS_CLI_H

#include "drift/core.h"
#include "drift/hybrid.h"

#include <stdbool.h>
#include <stdint.h>

// Subcommands. Each takes the arguments after its own name (argv[0] is the subcommand) and
// returns the process exit status: 0 success, 1 failure, 2 usage error.
int drift_cmd_render(int argc, char **argv);
int drift_cmd_diff(int argc, char **argv);
int drift_cmd_info(int argc, char **argv);
int drift_cmd_bench(int argc, char **argv);
int drift_cmd_view(int argc, char **argv);
int drift_cmd_refine(int argc, char **argv); // drift refine fit (tools/cmd_refine.c)
int drift_cmd_glare(int argc, char **argv);  // temporal glare on HDR images (tools/cmd_glare.c)

// Option values: print "drift <cmd>: <flag> expects ..." and return false when malformed or
// out of [lo, hi].
bool cli_parse_int(const char *cmd, const char *flag, const char *text, long lo, long hi,
                   long *out);
bool cli_parse_float(const char *cmd, const char *flag, const char *text, double lo, double hi,
                     double *out);
// A technique name for `effect` (drift_technique_parse) into *out; otherwise prints
// "drift <cmd>: <flag> expects one of <the techniques>, got '<text>'" and returns false.
bool cli_parse_technique(const char *cmd, drift_effect effect, const char *flag, const char *text,
                         int *out);
// Returns argv[*i + 1] and advances *i, or prints a usage error and returns NULL.
const char *cli_next_value(const char *cmd, int argc, char **argv, int *i);

// A logger that prints warnings and errors (and info with verbose) as
// "drift: FILE:LINE: level: message" on stderr.
drift_logger cli_stderr_logger(bool verbose);

// A context with `threads` worker threads (0: one a core) and the stderr logger, or NULL after
// printing "drift <cmd>: <why>".
drift_context *cli_open_context(const char *cmd, int threads, bool verbose);

// Directory of the built-in default scene (the repository's scenes/ folder).
const char *cli_default_scene_path(void);

// Loads the scene at `path` (NULL: the default scene) and builds its ray-tracing structure,
// printing "drift <cmd>: ..." on failure (the scene's problem is already logged). On success
// *out_loaded_time is the drift_time_now() between the two steps (for phase timings; may be
// NULL). Either out pointer holds NULL on failure; free with drift_accel_destroy and
// drift_scene_destroy.
struct drift_scene;
struct drift_accel;
bool cli_open_scene(drift_context *ctx, const char *cmd, const char *path,
                    struct drift_scene **out_scene, struct drift_accel **out_accel,
                    double *out_loaded_time);

#endif
