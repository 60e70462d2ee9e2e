// drift render: options shared by the reference and the hybrid mode.
#ifndef DRIFT_TOOLS_RENDER_H
#define DRIFT_TOOLS_RENDER_H

#include "cli.h"
#include "drift/hybrid.h"
#include "drift/image.h"
#include "drift/temporal.h"

#include <stdatomic.h>
#include <stdbool.h>
#include <stddef.h>
#include <time.h>

// The process's CPU seconds, all threads: the render's CPU time in --stats, which a shared
// machine's load changes much less than its wall time (drift bench cycles).
static inline double render_cpu_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

// --refine sir and its options (hybrid mode; tools/render_refine.c, docs/sir.md).
typedef struct render_refine_options {
    const char *first_option; // the first refine option seen (for error messages)
    bool enabled;             // --refine sir
    long budget;              // --budget: samples (primary rays) an iteration; 0 = none given
    long iterations;          // --refine-iterations: 0 = until refined
    double seconds;           // --refine-time: 0 = no limit
    long spp;                 // --refine-spp: samples that make a pixel refined; 0 = default
    bool all;                 // --refine-all: zero-error pixels too, after the others
    bool components;          // --refine-components: only R where reflection metrics alone
    const char *lambda_path;  // --lambda FILE: the fitted linear combination
} render_refine_options;

// How the PNG's exposure is chosen (one of --exposure, --ev100, --camera-exposure).
typedef enum render_exposure_mode {
    RENDER_EXPOSURE_STOPS = 0, // --exposure STOPS (default 0)
    RENDER_EXPOSURE_AUTO,      // --exposure auto: mean log luminance to middle grey
    RENDER_EXPOSURE_EV100,     // --ev100 EV or --camera-exposure N,T,ISO
} render_exposure_mode;

typedef struct render_options {
    const char *scene_path;
    const char *out_path;
    const char *stats_path;
    const char *aov_path;                 // hybrid: every plane as layers of this EXR
    const char *resume_path;              // reference: --resume FILE.ckpt
    struct drift_reflection_edits *edits; // --reflection-edits, loaded by render_open_session
    bool hybrid_mode;                     // --mode hybrid (else reference)
    long frames; // hybrid: frames rendered of the one view (the last is written)
    long spp, seed, threads, max_depth, width, height;
    double checkpoint_seconds;
    double rank_timeout; // mpirun: seconds a rank may send nothing before it counts as hung
    double exposure;     // PNG stops (--exposure STOPS)
    render_exposure_mode exposure_mode;
    bool exposure_given; // one of the three exposure options was seen
    double ev100;        // --ev100, or from --camera-exposure
    drift_tonemap_operator tonemap;
    const char *view, *display, *look, *ocio_config; // --view ...: the PNG through OpenColorIO
    bool aov;
    int aov_normal; // --aov-normal: 0 N (N.X/N.Y/N.Z), 1 Normal (Blender's Normal.X/Y/Z)
    int denoise;    // --denoise: 0 none, 1 atrous, 2 on (drift_denoise_feature), 3 regression,
                    // 4 guided (--mode hybrid: drift_denoise_guided)
    bool quiet;
    bool verbose;
    long debug_x, debug_y, debug_sample; // -1: not replaying a sample
    // hybrid mode
    const char *hybrid_option; // the first hybrid-only option seen (for the error message)
    drift_hybrid_params hybrid;
    double aperture, focus_distance; // < 0: the scene camera's
    render_refine_options refine;    // --refine sir (tools/render_refine.c)
    const char *edits_path;          // --reflection-edits FILE.json (docs/reflection-editing.md)
    double budget_ms;                // --budget-ms T: the chooser picks (tools/render_choose.c)
    const char *chooser_path;        // --chooser FILE: its model (default: the repository's)
    bool no_budget_probe;            // --budget-probe off: the fitted costs as they are
    bool print_features;             // --features: the scene's features as JSON, then exit
    // --budget-ms with the probes on and a path-tracer pick: drift_time_now() by which the
    // render (its samples and its --denoise) should be done; it takes 1 spp and adds samples
    // until then (0: none, --spp as given; --spp stays the pick's, the footprint textures are
    // filtered for)
    double budget_deadline;
    double budget_denoise_ms; // the chooser's estimate of --denoise's filter at this size
    long upsample_width, upsample_height; // > 0: the chooser's path tracer at reduced
                                          // resolution, written upsampled to this size
    // sequences (tools/render_sequence.c, docs/temporal.md)
    bool animation; // --animation A:B given: frames A..B, --out a %04d pattern
    long frame_first, frame_last;
    double fps;                  // --fps; 0: the camera path's (24 unless it says)
    const char *camera_path;     // --camera-path F.json
    const char *camera;          // --camera NAME: a glTF scene's camera
    const char *environment;     // --environment FILE|R,G,B: replaces the scene's environment
    double environment_strength; // --environment-strength X (0: 1)
    const char *video_path;      // --video FILE.mp4 (ffmpeg, when installed)
    bool temporal;               // --temporal on: reuse across frames (hybrid, drift/temporal.h)
    drift_temporal_settings temporal_settings;
    long still_refine; // --still-refine off|on|progressive (0, 1, 2: temporal_settings)
} render_options;

// drift render's options from argv: 0, 2 after a usage error (message printed), -1 after
// --help.
int render_parse_options(int argc, char **argv, render_options *o);
// Opens the context, scene and accel and loads --reflection-edits into o->hybrid; with
// outputs_here, refuses outputs that name an input and checks each can be written. Returns 0,
// or the exit status (message printed); render_close_session in both cases.
// --budget-ms: picks the techniques, or the path tracer, for the loaded scene (0 or an exit
// status); --features prints the chooser's inputs. tools/render_choose.c.
int render_choose(render_options *o, const cli_session *session);

// --budget-ms's probes (tools/render_choose_probe.c): one-shot frames of the loaded scene at
// w x h, their CPU ms (all threads, set-up included): the path tracer at 1 spp, the median of
// three, and given `base_hybrid`, one hybrid frame of it.
typedef struct render_probe {
    double pixels;    // the probes' frame
    double pt_ms;     // CPU ms; < 0: the probe failed
    double hybrid_ms; // CPU ms of create and first frame; < 0: not run or failed
    // Wall ms of writing an image as EXR and PNG: fixed plus per pixel (< 0: not measured)
    double write_fixed_ms, write_per_pixel_ms;
    double spent_ms; // the probes' own wall time, all of it
} render_probe;

void render_choose_probe(const cli_session *session, int32_t w, int32_t h,
                         const drift_hybrid_params *base_hybrid, render_probe *out);
// Times writing 64² and 128² images as EXR and PNG (both removed): out->write_fixed_ms and
// write_per_pixel_ms, what a budget that fills T leaves for the frame's writes.
void render_choose_probe_writes(const cli_session *session, render_probe *out);
// Wall ms of --denoise's filter (o->denoise) on a 1-spp path-traced 96² frame of the scene,
// per pixel: what a budget that fills T keeps for the frame's filter (< 0: failed).
double render_choose_probe_denoise(const cli_session *session, const render_options *o);
int render_print_features(const cli_session *session);
// `low` (3 channels or more) bilinearly up to w x h (a new image, 3 channels): the chooser's
// path tracer at 1/2 or 1/4 resolution, as drift bench frontier's rows upsample it.
drift_result render_upsample_bilinear(drift_context *ctx, const drift_image *low, int32_t w,
                                      int32_t h, drift_image *out);

int render_open_session(render_options *o, bool outputs_here, cli_session *session);
void render_close_session(render_options *o, cli_session *session);

// mpirun -n N drift render (tools/distributed/render_mpi.c, built with -DDRIFT_MPI=ON):
// whether this process was started by mpirun, and the distributed render.
bool render_mpi_launched(void);
int render_mpi(int argc, char **argv);

// Renders in hybrid mode with the session's scene; returns the process exit code.
int render_hybrid(const render_options *o, const cli_session *session);
// --denoise guided: the path tracer at --spp, combined with the hybrid frame `guide` (and its
// indirect plane, NULL: none) by drift_denoise_guided into *out, a new image
// (render_guided.c).
drift_result render_guided_image(const render_options *o, const cli_session *session,
                                 const drift_image *guide, const drift_image *guide_indirect,
                                 drift_image *out);
// The reference path tracer's image of the session's scene camera, written to --out.
int render_reference(const render_options *o, const cli_session *session);

// --- SEQUENCES (tools/render_sequence.c) ---

// --animation A:B (frame numbers, 0 <= A <= B).
bool render_parse_animation(const char *cmd, const char *flag, const char *v, void *field);
// Checks the sequence options go together (--out's frame pattern, --camera-path needs
// --animation); prints the usage error and returns false if not.
bool render_sequence_validate(const render_options *o);
// Renders frames A..B (either mode) and writes each; returns the exit code.
int render_sequence(const render_options *o, cli_session *session);

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

// The PNG's tone mapping for `image` (--exposure, --ev100, --camera-exposure, --tonemap).
drift_tonemap_params render_png_tonemap(const render_options *o, const drift_image *image);
// Writes the PNG of `image`: tone-mapped (render_png_tonemap) or, with --view, through the
// OpenColorIO config's view transform after the same exposure.
drift_result render_save_png(drift_context *ctx, const render_options *o, const char *path,
                             const drift_image *image);
// --view and its options checked (the config read, the names found); false: message printed.
bool render_check_view(const render_options *o);
// Writes the refiner's planes (sir may be NULL), then every plane of the frame, as the
// layers of one EXR; the normals as layer `normal_layer` ("N" or Blender's "Normal", from
// --aov-normal).
struct drift_refine;
drift_result render_write_aov(drift_context *ctx, const char *path,
                              const struct drift_hybrid *frame, const struct drift_refine *sir,
                              const char *normal_layer);
struct render_stage;
// Stages `image` as --out (EXR) and its PNG (--exposure, --tonemap), and with --aov the planes
// (render_write_aov). On failure says so, removes what was staged and returns false; on
// success the caller stages --stats and commits.
bool render_stage_hybrid_images(drift_context *ctx, const render_options *o,
                                const drift_image *image, const struct drift_hybrid *frame,
                                const struct drift_refine *sir, struct render_stage *stage);

// FILE.exr -> FILE.png
void render_png_path(const char *exr_path, char *out, size_t size);

// --- REFERENCE RENDERS (tools/cmd_render.c; tools/distributed drives the same steps) ---

typedef struct render_reference_run {
    const render_options *o;
    const cli_session *session;
    struct drift_pt *pt;
    uint32_t resumed_spp; // the lowest tile count the checkpoint held (0: a fresh render)
    int ranks;            // processes that rendered (0: not distributed)
    double t_render;      // drift_time_now() when rendering began
    double cpu_render;    // render_cpu_now() then (0: not taken; the stats leave it out)
    double cpu_rendered;  // and when rendering ended
    double denoise_ms;    // --denoise's filter, within the write (the stats' "denoise")
    uint32_t target_spp;  // the samples it set out to take: --spp, or more to fill a budget
    char key[1024];       // render_checkpoint_key
    char checkpoint_path[4096];
} render_reference_run;

// Creates the pt and loads the checkpoint to resume (--resume, or FILE.ckpt beside --out);
// returns 0 or the exit status (message printed).
int render_reference_begin(render_reference_run *run);
// Writes FILE.ckpt and the images so far (all or none); false after a message.
bool render_reference_checkpoint(render_reference_run *run);
// The milliseconds --denoise takes on the pt's image as it is now (0 without --denoise): what
// a budget must keep for it after the samples.
double render_denoise_ms(drift_context *ctx, struct drift_pt *pt, const render_options *o);
// Writes the outputs (all or none) and, when tiles are short of --spp, the checkpoint, and
// says so; removes the checkpoint of a finished render. Returns the exit status.
int render_reference_finish(render_reference_run *run, bool cancelled, double t_rendered);
// The EXR (beauty, --aov layers; an "spp" layer of each pixel's sample count when the tiles
// hold different counts) and the PNG beside it, to the paths given (tools/render_images.c).
drift_result render_write_images(drift_context *ctx, struct drift_pt *pt, const render_options *o,
                                 float fov_y, const char *exr_path, const char *png_path,
                                 double *out_denoise_ms);
// The lowest and highest sample count of the pt's tiles.
void render_spp_range(const struct drift_pt *pt, uint32_t *lowest, uint32_t *highest);
// One progress line (a bar on a terminal): done of total spp, `first` where this run began.
void render_progress(bool tty, uint32_t first, uint32_t done, uint32_t total, double elapsed,
                     bool final);

// --- REFERENCE RENDERS: CHECKPOINTS, RESUME, STAGED OUTPUTS (tools/render_checkpoint.c) ---

struct drift_pt;
// FILE.exr -> FILE.ckpt, the checkpoint beside --out.
void render_checkpoint_path(const char *exr_path, char *out, size_t size);
// The key a checkpoint must match to be resumed: drift's version, the scene's content (every
// file it read), image size, seed, depth, tile size; "name value" lines. False (message
// printed) when a scene file cannot be read.
bool render_checkpoint_key(const cli_session *session, const struct drift_pt *pt,
                           const char *edits_path, char *key, size_t size);
// Writes every tile's state to `path` (temp file, then rename). Prints the reason on failure.
bool render_checkpoint_write(const char *path, const char *key, const struct drift_pt *pt);
// Loads a checkpoint into the pt: 0 on success; 2 (message printed, pt unchanged or partly
// loaded) when the file cannot be read, is not a checkpoint, is cut short, belongs to
// another render (the first differing key line is named) or holds more than `spp` samples.
int render_checkpoint_read(const char *path, const char *key, struct drift_pt *pt, uint32_t spp);

// A run's outputs, written to "<path>.stage-PID" first and renamed over their targets
// together once every one was written (render_stage_commit), or all removed.
typedef struct render_staged_file {
    char path[4096]; // a copy: the caller's string need not outlive the stage
    char temp[4096];
} render_staged_file;

typedef struct render_stage {
    size_t count;
    render_staged_file files[8];
} render_stage;

// Returns the temporary path to write `path` to (NULL stays NULL).
const char *render_stage_add(render_stage *s, const char *path);
bool render_stage_commit(render_stage *s);
void render_stage_abort(render_stage *s);

// Installs the Ctrl-C handler; the flag it returns becomes true on SIGINT or SIGTERM.
const atomic_bool *render_catch_sigint(void);
// The exit status of an interrupted run: 128 + the signal (130 SIGINT, 143 SIGTERM).
int render_interrupt_status(void);

// The equal-time frontier's whole-frame path tracer (drift bench frontier, drift report's
// cells; tools/render_whole_frame.c): every effect, max depth RENDER_WHOLE_FRAME_DEPTH,
// `spp` samples a pixel from `seed`; its RGB into a new *out, its rays (camera, shadow,
// bounce) into *rays when not NULL. The reference: the same at RENDER_WHOLE_FRAME_REF_SEED.
#define RENDER_WHOLE_FRAME_DEPTH    8
#define RENDER_WHOLE_FRAME_REF_SEED 0x5eedu
drift_result render_whole_frame_pt(drift_context *ctx, const drift_scene *scene,
                                   const drift_accel *accel, int32_t width, int32_t height,
                                   uint32_t spp, uint32_t seed, const atomic_bool *cancel,
                                   drift_image *out, uint64_t *rays);
drift_result render_whole_frame_reference(drift_context *ctx, const drift_scene *scene,
                                          const drift_accel *accel, int32_t width, int32_t height,
                                          uint32_t spp, drift_image *out);

#endif
