// drift render: options shared by the reference and the hybrid mode.
#ifndef DRIFT_TOOLS_RENDER_H
#define DRIFT_TOOLS_RENDER_H

#include <stdatomic.h>
#include <stdbool.h>
#include <stddef.h>

#include "drift/hybrid.h"
#include "drift/image.h"

// --refine sir and its options (hybrid mode; tools/render_refine.c, docs/sir.md).
typedef struct render_refine_options {
    const char *first_option; // the first refine option seen (for error messages)
    bool enabled;             // --refine sir
    long budget;              // --budget: samples (primary rays) an iteration; 0 = none given
    long iterations;          // --refine-iterations: 0 = until refined
    double seconds;           // --refine-time: 0 = no limit
    long spp;                 // --refine-spp: samples that make a pixel refined; 0 = default
    bool all;                 // --refine-all: zero-error pixels too, after the others
    const char *lambda_path;  // --lambda FILE: the fitted linear combination
} render_refine_options;

typedef struct render_options {
    const char *scene_path;
    const char *out_path;
    const char *stats_path;
    const char *aov_path; // hybrid: every plane as layers of this EXR
    const char *mode;
    long spp, seed, threads, max_depth, width, height;
    double checkpoint_seconds;
    double exposure;
    drift_tonemap_operator tonemap;
    bool aov;
    bool quiet;
    bool verbose;
    long debug_x, debug_y, debug_sample; // -1: not replaying a sample
    // hybrid mode
    const char *hybrid_option; // the first hybrid-only option seen (for the error message)
    drift_hybrid_params hybrid;
    double aperture, focus_distance; // < 0: the scene camera's
    render_refine_options refine;    // --refine sir (tools/render_refine.c)
} render_options;

// Parses argv[*i] when it is a hybrid-mode option (advancing *i past its value); returns
// false when it is not one. *ok becomes false on a malformed value (message printed).
bool render_parse_hybrid_option(int argc, char **argv, int *i, render_options *o, bool *ok);

// Renders in hybrid mode; returns the process exit code.
int render_hybrid(const render_options *o);

// Parses argv[*i] when it is a --refine option (as render_parse_hybrid_option does).
bool render_parse_refine_option(int argc, char **argv, int *i, render_options *o, bool *ok);
// Checks the refine options go together; prints the usage error and returns false if not.
bool render_refine_validate(const render_options *o);
// Refines the rendered hybrid frame and writes the outputs; returns the exit code.
struct drift_hybrid;
int render_refine_run(drift_context *ctx, const render_options *o, struct drift_hybrid *frame,
                      const char *scene_path);

// FILE.exr -> FILE.png
void render_png_path(const char *exr_path, char *out, size_t size);

// Installs the Ctrl-C handler; the flag it returns becomes true on SIGINT.
const atomic_bool *render_catch_sigint(void);

#endif
