// drift render: options shared by the reference and the hybrid mode.
#ifndef DRIFT_TOOLS_RENDER_H
#define DRIFT_TOOLS_RENDER_H

#include "cli.h"
#include "drift/hybrid.h"
#include "drift/image.h"

#include <stdatomic.h>
#include <stdbool.h>
#include <stddef.h>

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
    bool hybrid_mode;     // --mode hybrid (else reference)
    long frames;          // hybrid: frames rendered of the one view (the last is written)
    long spp, seed, threads, max_depth, width, height;
    double checkpoint_seconds;
    double exposure;
    drift_tonemap_operator tonemap;
    bool aov;
    bool denoise; // --denoise atrous (reference mode)
    bool quiet;
    bool verbose;
    long debug_x, debug_y, debug_sample; // -1: not replaying a sample
    // hybrid mode
    const char *hybrid_option; // the first hybrid-only option seen (for the error message)
    drift_hybrid_params hybrid;
    double aperture, focus_distance; // < 0: the scene camera's
    render_refine_options refine;    // --refine sir (tools/render_refine.c)
    const char *edits_path;          // --reflection-edits FILE.json (docs/reflection-editing.md)
} render_options;

// Renders in hybrid mode with the session's scene; returns the process exit code.
int render_hybrid(const render_options *o, const cli_session *session);

// The --stats object's first fields (scene, mode, width, height); the caller adds the rest
// and writes it with cli_json_write.
cJSON *render_stats_begin(const render_options *o, const cli_session *session, const char *mode,
                          int width, int height);

// Checks the refine options go together; prints the usage error and returns false if not.
bool render_refine_validate(const render_options *o);
// Refines the rendered hybrid frame and writes the outputs; returns the exit code.
struct drift_hybrid;
int render_refine_run(const render_options *o, const cli_session *session,
                      struct drift_hybrid *frame);

// Writes `image` to --out (EXR) and its PNG beside it (--exposure, --tonemap).
drift_result render_write_image(drift_context *ctx, const render_options *o,
                                const drift_image *image);
// Writes the refiner's planes (sir may be NULL), then every plane of the frame, as the
// layers of one EXR.
struct drift_refine;
drift_result render_write_aov(drift_context *ctx, const char *path,
                              const struct drift_hybrid *frame, const struct drift_refine *sir);

// FILE.exr -> FILE.png
void render_png_path(const char *exr_path, char *out, size_t size);

// Installs the Ctrl-C handler; the flag it returns becomes true on SIGINT or SIGTERM.
const atomic_bool *render_catch_sigint(void);
// The exit status of an interrupted run: 128 + the signal (130 SIGINT, 143 SIGTERM).
int render_interrupt_status(void);

#endif
