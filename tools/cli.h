// Shared pieces of the drift command-line tool: subcommand entry points, option value
// parsers that reject malformed numbers, a logger that prints to stderr, and the one place
// that opens and closes a command's context, scene and accel (cli_session). Option tables
// are in cli_options.h, the JSON writer in cli_json.h.
#ifndef DRIFT_TOOLS_CLI_H
#define DRIFT_TOOLS_CLI_H

#include "cli_json.h"
#include "cli_options.h"
#include "drift/core.h"
#include "drift/hybrid.h"

#include <stdbool.h>
#include <stdint.h>

// The subcommands of `drift`, X(name, function, one-line summary). To add one: write
// tools/cmd_<name>.c with `int drift_cmd_<name>(int argc, char **argv)` and add its line here
// (the prototype and tools/drift.c's dispatch table come from it). Each takes the arguments
// after its own name (argv[0] is the subcommand) and returns the process exit status: 0
// success, 1 failure, 2 usage error. Benchmarks are listed in bench/bench.h.
#define DRIFT_COMMAND_LIST(X)                                                                \
    X("render", drift_cmd_render, "render a scene (reference path tracer or hybrid frame)")  \
    X("diff", drift_cmd_diff, "compare two images: MSE, RMSE, relMSE, PSNR, SSIM, FLIP")     \
    X("info", drift_cmd_info, "print a scene's triangle, material, light, texture counts")   \
    X("bench", drift_cmd_bench, "benchmarks (drift bench --help)")                           \
    X("view", drift_cmd_view, "interactive viewer: hybrid techniques against the reference") \
    X("refine", drift_cmd_refine, "smart image refinement: fit the metric weights (lambda)") \
    X("glare", drift_cmd_glare, "temporal glare (thesis ch. 8) on an HDR image or sequence") \
    X("report", drift_cmd_report, "one HTML page: every technique against the reference")

#define DRIFT__COMMAND_DECLARE(name, fn, summary) int fn(int argc, char **argv);
DRIFT_COMMAND_LIST(DRIFT__COMMAND_DECLARE)
#undef DRIFT__COMMAND_DECLARE

// A name -> entry point table (drift's commands, drift bench's benchmarks).
typedef struct cli_subcommand {
    const char *name;
    int (*run)(int argc, char **argv);
    const char *summary;
} cli_subcommand;

// Runs the entry of `table` that argv[1] names with argv + 1. Without one, or with --help,
// prints "usage: drift <cmd> <name> [options]" and the `heading` list (stderr and status 2
// when missing or unknown; stdout and 0 after --help), then `footer`.
int cli_dispatch(const char *cmd, const char *heading, const char *footer,
                 const cli_subcommand *table, size_t count, int argc, char **argv);

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
// X,Y,Z (or, with `scalar`, one number for all three), finite; otherwise prints
// "drift <cmd>: <flag> expects X,Y,Z, got '<text>'" and returns false.
bool cli_parse_vec3(const char *cmd, const char *flag, const char *text, bool scalar,
                    drift_vec3 *out);
// --refine sir (render and view): sets the bool at `field`, or prints
// "drift <cmd>: <flag> expects 'sir', got '<value>'" and returns false.
bool cli_parse_refine(const char *cmd, const char *flag, const char *value, void *field);
// Returns argv[*i + 1] and advances *i, or prints a usage error and returns NULL.
const char *cli_next_value(const char *cmd, int argc, char **argv, int *i);

// drift diff's comparison of TEST against REF (same size): the pixels NaN or infinite in
// either are set to 0 in both (*nonfinite counts them) and MSE and relMSE are means over
// the others; then drift_metric_compare. DRIFT_ERR_INVALID_ARGUMENT when the sizes differ or
// every pixel is masked. `drift report` uses it so that its numbers equal drift diff's.
struct drift_metric_report;
drift_result cli_compare_images(drift_context *ctx, drift_image *ref, drift_image *test, double ppd,
                                struct drift_metric_report *rep, drift_image *flip_map,
                                size_t *nonfinite);

// A logger that prints warnings and errors (and info with verbose) as
// "drift: FILE:LINE: level: message" on stderr.
drift_logger cli_stderr_logger(bool verbose);

// Directory of the built-in default scene (the repository's scenes/ folder).
const char *cli_default_scene_path(void);

// A file a command reads or writes, and the option (or argument) that named it.
typedef struct cli_file {
    const char *flag; // "--stats", "SCENE", "the scene's texture"
    const char *path;
} cli_file;

// Refuses to write over an input: fails unless every output is a different file from every
// input and from every other output. Files are compared by identity, not by spelling: the
// device and inode of a file that exists (hard links, symbolic links and "./x" are the same
// file), else those of the folder it would be made in plus its name. Prints "drift <cmd>:
// <flag> 'path' is <flag> 'path'; nothing written" for the first clash and returns false
// (the caller exits with status 2). NULL paths are skipped.
bool cli_check_outputs(const char *cmd, const cli_file *inputs, size_t input_count,
                       const cli_file *outputs, size_t output_count);

// Checks before any work that each output can be made: its folder exists and is writable
// and the name is not a folder. Prints "drift <cmd>: cannot write <flag> 'path': <the OS
// reason>; nothing written" for the first that cannot and returns false (exit status 1).
bool cli_check_writable(const char *cmd, const cli_file *outputs, size_t output_count);

// What a command opens: a context, and unless told otherwise the scene and its ray-tracing
// structure. Zero is the default: all cores, the built-in Cornell box, scene and accel.
typedef struct cli_session_desc {
    const char *cmd;        // "render", "bench isg": in messages
    const char *scene_path; // NULL: default_scene
    const char *camera;     // a glTF scene's camera by name or index (NULL: its first)
    // --environment: an image file (lat-long) or R,G,B that replaces the scene's environment,
    // times environment_strength (0 is taken as 1); NULL: the scene's own.
    const char *environment;
    double environment_strength;
    const char *default_scene; // NULL: cli_default_scene_path()
    int threads;               // worker threads; 0: one a core
    bool verbose;              // info-level log messages too
    bool no_scene;             // the context only (load scenes later with cli_session_load)
    bool no_accel;             // the scene without its ray-tracing structure
    // The files the command will write and the other files it reads (--lambda): once the
    // scene is loaded, cli_check_outputs refuses outputs that name the scene, its mesh files
    // or textures, an input or each other (the session then has `refused` set: exit 2), and
    // cli_check_writable those that cannot be made (exit 1), before the accel is built.
    const cli_file *outputs;
    size_t output_count;
    const cli_file *inputs;
    size_t input_count;
} cli_session_desc;

struct drift_scene;
struct drift_accel;

typedef struct cli_session {
    drift_context *ctx;
    struct drift_scene *scene;
    struct drift_accel *accel;
    const char *scene_path; // the scene loaded (the default resolved; points into `path`)
    double t_start;         // drift_time_now() at open, after loading and after the accel:
    double t_loaded;        // for phase timings
    double t_built;
    bool refused;            // an output names an input (cli_session_desc's outputs): exit status 2
    const char *camera;      // cli_session_desc's camera, for every load
    const char *environment; // cli_session_desc's environment and strength, for every load
    double environment_strength;
    char **scene_inputs; // the files the scene load read (drift_scene_load_inputs)
    size_t scene_input_count;
    char path[4096];
} cli_session;

// Opens what `desc` asks for into *s, printing "drift <cmd>: ..." on failure (the scene's
// problem is already logged by the context's logger). Call cli_session_close in both cases.
bool cli_session_open(const cli_session_desc *desc, cli_session *s);
// Replaces the session's scene (and accel unless no_accel) by the one at `path`.
bool cli_session_load(cli_session *s, const char *cmd, const char *path, bool no_accel);
// Destroys the accel, the scene and the context (each may be NULL); *s becomes zero.
void cli_session_close(cli_session *s);

// FNV-1a, the content hash of checkpoints and report caches (not cryptographic: it tells an
// edited file from the one a result was made from).
// A technique no option chose yet: set before cli_parse where a default depends on other
// options (--refine sir starts from --indirect none).
#define CLI_TECHNIQUE_UNSET (-1)

// A list option ("--vpls 64,256,1024"): 1 to `max` comma-separated integers in [lo, hi] into
// out[0 .. *count - 1]. Otherwise prints "drift <cmd>: <flag> expects 1 to <max>
// comma-separated integers in [lo, hi], got '<text>'", leaves *count and out as they were
// and returns false.
bool cli_parse_list(const char *cmd, const char *flag, const char *text, long lo, long hi, int max,
                    long *out, int *count);

// The two defaults that depend on other options, around cli_parse of a command with
// CLI_KNOBS: cli_knobs_unset marks --indirect and --env-scale as not given (params holds
// drift_hybrid_params_default()); cli_knobs_finish gives them their value: --indirect none
// under --refine sir (SIR's tracer has no indirect light, docs/sir.md), else the default
// technique; --env-scale 1 with --env-interleave on (interleaving takes every pixel), else
// the row's default.
void cli_knobs_unset(drift_hybrid_params *params);
void cli_knobs_finish(drift_hybrid_params *params, bool refine);

#define CLI_FNV_BASIS 0xcbf29ce484222325ull
uint64_t cli_fnv1a(uint64_t h, const void *data, size_t size);
// cli_fnv1a of the files' contents in order, a NUL between files; false (errno set) when one
// cannot be read. NULL paths are skipped.
bool cli_hash_files(const char *const *paths, size_t count, uint64_t *out);

#endif
