// drift render: renders a scene with the reference path tracer.
//
// Reads like the API walk-through: load the scene, build the accel, create the path tracer,
// add samples in passes (progress, checkpoints, Ctrl-C), resolve and write the images.
#include "cli.h"
#include "drift/accel.h"
#include "drift/denoise.h"
#include "drift/glare.h"
#include "drift/image_io.h"
#include "drift/knobs.h"
#include "drift/pt.h"
#include "drift/reflect_edit.h"
#include "drift/scene_io.h"
#include "render.h"

#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define RENDER_DEFAULT_OUT "out/render.exr"

// Set from the SIGINT and SIGTERM handler; the render loop polls it between tiles.
static atomic_bool interrupted;
static volatile sig_atomic_t interrupt_signal;

static void on_sigint(int sig)
{
    interrupt_signal = sig;
    atomic_store(&interrupted, true);
}

const atomic_bool *render_catch_sigint(void)
{
    signal(SIGINT, on_sigint);
    signal(SIGTERM, on_sigint); // schedulers and mpirun stop jobs with SIGTERM
    return &interrupted;
}

int render_interrupt_status(void)
{
    return 128 + (interrupt_signal ? (int)interrupt_signal : SIGINT);
}

// --- OPTIONS ---

// Value readers for the rows below that are more than a number or a name.
static bool parse_tonemap(const char *cmd, const char *flag, const char *v, void *field)
{
    drift_tonemap_operator *op = field;

    static const struct {
        const char *name;
        drift_tonemap_operator op;
    } ops[] = { { "clamp", DRIFT_TONEMAP_CLAMP },
                { "reinhard", DRIFT_TONEMAP_REINHARD },
                { "filmic", DRIFT_TONEMAP_FILMIC } };

    for (size_t i = 0; i < sizeof(ops) / sizeof(ops[0]); ++i) {
        if (strcmp(v, ops[i].name) == 0) {
            *op = ops[i].op;
            return true;
        }
    }
    fprintf(stderr, "drift %s: %s expects clamp, reinhard or filmic, got '%s'\n", cmd, flag, v);
    return false;
}

// --exposure, --ev100 and --camera-exposure each choose the PNG's exposure: one at most.
static bool set_exposure_mode(const char *cmd, const char *flag, render_options *o,
                              render_exposure_mode mode)
{
    if (o->exposure_given) {
        fprintf(stderr,
                "drift %s: %s: give one of --exposure, --ev100 and --camera-exposure, not two\n",
                cmd, flag);
        return false;
    }
    o->exposure_given = true;
    o->exposure_mode = mode;
    return true;
}

static bool parse_exposure(const char *cmd, const char *flag, const char *v, void *field)
{
    render_options *o = field;
    if (strcmp(v, "auto") == 0) {
        return set_exposure_mode(cmd, flag, o, RENDER_EXPOSURE_AUTO);
    }
    char *end = NULL;
    double stops = strtod(v, &end);
    if (end == v || *end != '\0' || !(stops >= -64.0 && stops <= 64.0)) {
        fprintf(stderr, "drift %s: %s expects auto or stops in [-64, 64], got '%s'\n", cmd, flag,
                v);
        return false;
    }
    o->exposure = stops;
    return set_exposure_mode(cmd, flag, o, RENDER_EXPOSURE_STOPS);
}

static bool parse_ev100(const char *cmd, const char *flag, const char *v, void *field)
{
    render_options *o = field;
    char *end = NULL;
    double ev = strtod(v, &end);
    if (end == v || *end != '\0' || !(ev >= -20.0 && ev <= 30.0)) {
        fprintf(stderr, "drift %s: %s expects an EV100 in [-20, 30], got '%s'\n", cmd, flag, v);
        return false;
    }
    o->ev100 = ev;
    return set_exposure_mode(cmd, flag, o, RENDER_EXPOSURE_EV100);
}

static bool parse_camera_exposure(const char *cmd, const char *flag, const char *v, void *field)
{
    render_options *o = field;
    double n, t, iso;
    char tail;
    if (sscanf(v, "%lf,%lf,%lf%c", &n, &t, &iso, &tail) != 3 || !(n > 0.0 && n < 1e3) ||
        !(t > 0.0 && t < 1e5) || !(iso > 0.0 && iso < 1e7)) {
        fprintf(stderr,
                "drift %s: %s expects F-NUMBER,SHUTTER-SECONDS,ISO (all > 0, e.g. 16,0.01,100), "
                "got '%s'\n",
                cmd, flag, v);
        return false;
    }
    o->ev100 = (double)drift_ev100_from_camera((float)n, (float)t, (float)iso);
    return set_exposure_mode(cmd, flag, o, RENDER_EXPOSURE_EV100);
}

static bool parse_debug_sample(const char *cmd, const char *flag, const char *v, void *field)
{
    render_options *o = field;
    char tail;
    if (sscanf(v, "%ld,%ld,%ld%c", &o->debug_x, &o->debug_y, &o->debug_sample, &tail) != 3) {
        fprintf(stderr, "drift %s: %s expects X,Y,S, got '%s'\n", cmd, flag, v);
        return false;
    }
    return true;
}

// --aov [FILE.exr]: the value is taken only when the next argument names an .exr file.
static bool parse_aov(const char *cmd, const char *flag, const char *v, void *field)
{
    (void)cmd;
    (void)flag;
    render_options *o = field;
    o->aov = true;
    o->aov_path = v;
    return true;
}

static bool parse_probe(const char *cmd, const char *flag, const char *v, void *field)
{
    drift_hybrid_params *h = field;
    if (strcmp(v, "object") == 0) {
        h->envmap.per_object = true;
        return true;
    }
    h->envmap.has_probe = true;
    return cli_parse_vec3(cmd, flag, v, true, &h->envmap.probe);
}

static bool parse_ambient(const char *cmd, const char *flag, const char *v, void *field)
{
    drift_hybrid_params *h = field;
    h->has_ambient = true;
    return cli_parse_vec3(cmd, flag, v, true, &h->ambient);
}

// Groups of options (cli_parse's first_in_group): hybrid-only, and refinement-only.
enum {
    GROUP_HYBRID = 1u << 0,
    GROUP_REFINE = 1u << 1
};

#define O render_options
static const cli_option render_table[] = {
    CLI_SECTION("options:", 0),
    CLI_CHOICE("--mode", "MODE", O, hybrid_mode, "reference|hybrid",
               "reference (path tracer, default) or hybrid (the hybrid\n"
               "frame: one sample a pixel plus a technique per effect)"),
    CLI_INT("--spp", "N", O, spp, 1, 1 << 24, "samples per pixel (default 64)"),
    CLI_INT("--seed", "S", O, seed, 0, UINT32_MAX,
            "random seed (default 0); same seed, same image, any threads"),
    CLI_INT("--threads", "T", O, threads, 0, 256, "worker threads (default: all cores)"),
    CLI_INT("--max-depth", "D", O, max_depth, 1, 1024,
            "scattering vertices per path, pbrt's convention: 1 = direct\n"
            "light only (default 8; hybrid: depth of reference reflections\n"
            "and indirect, default 8)"),
    CLI_INT("--width", "W", O, width, 1, DRIFT_IMAGE_MAX_DIMENSION,
            "image size (default: the scene camera's)"),
    CLI_INT("--height", "H", O, height, 1, DRIFT_IMAGE_MAX_DIMENSION,
            "image size (default: the scene camera's)"),
    CLI_STRING("--out", "FILE.exr", O, out_path,
               "output (default out/render.exr); FILE.png is written too"),
    CLI_CHOICE("--denoise", "none|atrous|on|regression|guided", O, denoise,
               "none|atrous|on|regression|guided",
               "reference: on = the feature-guided, variance-guided denoiser\n"
               "(docs/denoiser.md); atrous = the edge-avoiding a-trous filter;\n"
               "regression = the blockwise feature regression it was measured against;\n"
               "--mode hybrid: guided = the hybrid frame plus the path tracer's\n"
               "residual at --spp, filtered (drift_denoise_guided)"),
    CLI_TECHNIQUE("--glare", "T", O, hybrid,
                  "the last pass of either mode, at the camera's angular pitch\n"
                  "(docs/glare.md)"),
    { .name = "--aov",
      .arg = "[FILE.exr]",
      .help = "reference: add albedo.RGB, N.XYZ (normals) and Z (depth) to the EXR;\n"
              "hybrid: write every plane and buffer as layers of FILE.exr",
      .kind = CLI_KIND_CUSTOM,
      .parse = parse_aov,
      .optional_if = ".exr" },
    CLI_CHOICE("--aov-normal", "N|Normal", O, aov_normal, "N|Normal",
               "the --aov normals' layer: N (N.X/N.Y/N.Z, tev and Nuke; default)\n"
               "or Normal (Normal.X/Y/Z, Blender's compositor)"),
    CLI_STRING("--camera", "NAME", O, camera,
               "a glTF scene's camera by name, or by index (default: its first)"),
    CLI_STRING("--environment", "FILE|R,G,B", O, environment,
               "replace the scene's environment by a lat-long image (.hdr, .exr)\n"
               "or a constant colour (glTF files carry no world; docs/scene-format.md)"),
    CLI_NUMBER("--environment-strength", "X", O, environment_strength, 0.0, 1e9,
               "multiplies --environment (default 1)"),
    CLI_STRING("--stats", "FILE.json", O, stats_path,
               "spp, rays traced and milliseconds per phase"),
    CLI_NUMBER("--checkpoint", "SECONDS", O, checkpoint_seconds, 0.0, 1e9,
               "write the image so far and FILE.ckpt beside --out every\n"
               "SECONDS (default 60; 0 = never); Ctrl-C writes FILE.ckpt too"),
    CLI_STRING("--resume", "FILE.ckpt", O, resume_path,
               "reference: continue the render a checkpoint holds (default:\n"
               "FILE.ckpt beside --out when there is one); the end image is\n"
               "the same bits as an uninterrupted render's"),
    CLI_NUMBER("--rank-timeout", "SECONDS", O, rank_timeout, 0.1, 1e9,
               "under mpirun: a rank that sends nothing for SECONDS is taken\n"
               "as hung and the job stops, keeping its work (default 300)"),
    CLI_CUSTOM_ALL("--exposure", "STOPS|auto", parse_exposure,
                   "PNG exposure in stops (default 0), or auto: the mean log\n"
                   "luminance to middle grey (docs/reference-renderer.md)"),
    CLI_CUSTOM_ALL("--ev100", "EV", parse_ev100,
                   "PNG exposure of a camera at EV100 EV (radiance x 683 as cd/m2)"),
    CLI_CUSTOM_ALL("--camera-exposure", "N,T,ISO", parse_camera_exposure,
                   "PNG exposure of f-number N, shutter T seconds, ISO (EV100 from them)"),
    CLI_CUSTOM("--tonemap", "OP", O, tonemap, parse_tonemap,
               "PNG operator: clamp (default), reinhard or filmic (ACES fit)"),
    CLI_STRING("--view", "NAME", O, view,
               "PNG through an OpenColorIO view transform instead of --tonemap\n"
               "(Filmic, Standard, ...: Blender's config by default; docs/colour.md)"),
    CLI_STRING("--display", "NAME", O, display, "--view's display (default: the config's, sRGB)"),
    CLI_STRING("--look", "NAME", O, look, "--view's look (e.g. \"Medium High Contrast\")"),
    CLI_STRING("--ocio-config", "FILE", O, ocio_config,
               "the OpenColorIO config of --view (default: $OCIO, else Blender's)"),
    CLI_CUSTOM_ALL("--debug-sample", "X,Y,S", parse_debug_sample,
                   "trace one sample of one pixel and print its radiance"),
    CLI_STRING("--reflection-edits", "FILE.json", O, edits_path,
               "edit the reflections: sharp, envmap and ISG reflections and the path\n"
               "tracer's first specular bounce follow e(q) (docs/reflection-editing.md)"),
    CLI_CUSTOM_ALL("--animation", "A:B", render_parse_animation,
                   "render frames A to B (time = frame / --fps) of --camera-path,\n"
                   "or of a glTF scene's camera animation;\n"
                   "--out names a pattern, DIR/frame_%04d.exr (docs/temporal.md)"),
    CLI_NUMBER("--fps", "F", O, fps, 1e-3, 1e6,
               "frames a second of --animation (default: the camera path's; glTF 24)"),
    CLI_STRING("--camera-path", "FILE.json", O, camera_path,
               "keyframes of the camera (position, target, fov, aperture, focus),\n"
               "interpolated by centripetal Catmull-Rom (docs/temporal.md)"),
    CLI_STRING("--video", "FILE.mp4", O, video_path,
               "--animation: also encode the PNG frames with ffmpeg when installed"),
    CLI_FLAG("--quiet", O, quiet, "no progress output"),
    CLI_FLAG("--verbose", O, verbose, "more log output"),
    CLI_FLAG("--features", O, print_features,
             "print the scene's features (the chooser's inputs) as JSON; render nothing"),

    CLI_SECTION("hybrid mode (docs/hybrid.md):", GROUP_HYBRID),
    CLI_TECHNIQUES("T", O, hybrid),
    CLI_NUMBER("--budget-ms", "T", O, budget_ms, 1e-3, 1e9,
               "pick the techniques (or the path tracer) expected to give the\n"
               "lowest FLIP within T ms, from the scene's features (docs/corpus.md)"),
    CLI_STRING("--chooser", "FILE", O, chooser_path,
               "--budget-ms's model (default scenes/corpus/chooser.json)"),
    CLI_CHOICE("--budget-probe", "on|off", O, no_budget_probe, "on|off",
               "--budget-ms: first time cheap frames of the scene and scale the\n"
               "model's costs by them and the load average; T counts all after the\n"
               "scene's load: accel, probes, frame; a path-tracer pick then takes\n"
               "samples, denoised, while T lasts (on, the default; the probes'\n"
               "timings vary, so the pick may differ run to run); off: the fitted\n"
               "costs as they are, T the frame's alone, the same pick every run"),
    CLI_NOTE("each technique is listed below; reference = that effect\n"
             "alone path-traced at --spp; aaf: --spp rays a pixel on\n"
             "average (shadows: per area light)"),
    CLI_INT("--frames", "N", O, frames, 1, 100000,
            "render N frames of the view and write the last: its stats\n"
            "are a frame with warm caches (default 1; first_frame_ms in\n"
            "--stats has the first)"),
    CLI_CHOICE("--temporal", "off|on", O, temporal, "off|on",
               "reuse across --animation frames (or --frames N of a still camera:\n"
               "the last, accumulated, is written): reprojection, disocclusion tests,\n"
               "variance-guided accumulation and filtering (docs/temporal.md)"),
    CLI_INT("--temporal-history", "N", O, temporal_settings.max_history, 1, 4096,
            "frames the temporal accumulation averages at most (default 32)"),
    CLI_INT("--temporal-moving-history", "N", O, temporal_settings.moving_history, 1, 4096,
            "frames a pixel that moved averages at most (default 8; a still\n"
            "pixel keeps --temporal-history): a moving history is resampled\n"
            "every frame and a long one blurs (docs/temporal.md)"),
    CLI_INT("--temporal-passes", "N", O, temporal_settings.filter_passes, 0, 8,
            "a-trous passes of the temporal filter (default 3; 0: none)"),
    CLI_CHOICE("--temporal-resample", "bilinear|catmull-rom", O, temporal_settings.history_resample,
               "bilinear|catmull-rom",
               "how the history is read at a pixel's reprojected point: its 2 x 2\n"
               "bilinear taps (default; a moving camera's long history blurs), or\n"
               "its 4 x 4 Catmull-Rom taps clamped to the 2 x 2 range where all\n"
               "16 show the pixel's surface (docs/temporal.md)"),
    CLI_CHOICE("--still-refine", "on|off|progressive", O, still_refine, "off|on|progressive",
               "--temporal on, a still camera: each frame adds a path-traced sample\n"
               "a pixel, denoised and blended in where its error is the lower;\n"
               "progressive: once still, no more hybrid frames, every frame adds\n"
               "--still-spp path-traced samples and the hybrid fades out by sample\n"
               "count (default progressive; docs/temporal.md)"),
    CLI_INT("--still-spp", "N", O, temporal_settings.still_spp, 1, 1 << 16,
            "path-traced samples a pixel each still frame adds (default 1; 4 with\n"
            "--still-refine progressive)"),
    CLI_CHOICE("--moving-refine", "off|path|residual", O, temporal_settings.moving_refine,
               "off|path|residual",
               "--temporal on: every frame adds a path-traced sample a pixel,\n"
               "accumulated through the history's reprojection, filtered and\n"
               "blended in where its error is the lower; residual: the sample\n"
               "minus the hybrid frame is accumulated and added (default off;\n"
               "docs/temporal.md)"),
    CLI_INT("--moving-refine-history", "N", O, temporal_settings.moving_refine_history, 1, 4096,
            "frames the moving refinement's path-traced accumulation averages\n"
            "at most (default 32)"),
    CLI_INT("--moving-refine-scale", "1|2", O, temporal_settings.moving_refine_scale, 1, 2,
            "2: the moving refinement traces its samples at half the width and\n"
            "height (a quarter of the rays), upsampled by the G-buffer (default 1)"),
    CLI_INT("--moving-refine-period", "1|2|4|8|16", O, temporal_settings.moving_refine_period, 1,
            16,
            "P: the moving refinement traces a sample for 1/P of the pixels a\n"
            "frame, each pixel every P frames (a 4x4 Bayer order); the others\n"
            "keep their reprojected history (default 1: every pixel)"),
    CLI_INT("--moving-refine-passes", "N", O, temporal_settings.moving_refine_passes, 1, 8,
            "a-trous passes over the moving refinement's accumulation (default 5)"),
    CLI_CUSTOM("--probe", "X,Y,Z|object", O, hybrid, parse_probe,
               "environment-map probe: a point, or one per reflective mesh\n"
               "(default: the scene's centre)"),
    CLI_CUSTOM("--ambient", "R,G,B", O, hybrid, parse_ambient,
               "ambient radiance (default: the frame's mean direct light)"),
    CLI_NUMBER("--aperture", "R", O, aperture, 0.0, 1e30,
               "lens radius in scene units (default: the scene camera's)"),
    CLI_NUMBER("--focus-distance", "F", O, focus_distance, 1e-30, 1e30,
               "distance to the plane in focus (default: the camera's)"),
    CLI_SECTION("technique knobs (hybrid mode; each family's table, include/drift/knobs.h):",
                GROUP_HYBRID),
    CLI_KNOBS(O, hybrid),

    CLI_SECTION("smart image refinement (hybrid mode; docs/sir.md):", GROUP_HYBRID | GROUP_REFINE),
    CLI_CUSTOM("--refine", "sir", O, refine.enabled, cli_parse_refine,
               "refine the frame by ray tracing, worst estimated error first"),
    CLI_INT("--budget", "N", O, refine.budget, 1, 1L << 30,
            "samples (primary rays) an iteration (default: all pixels)"),
    CLI_INT("--refine-iterations", "N", O, refine.iterations, 1, 1L << 30,
            "stop after N iterations (default: until every error pixel\n"
            "is refined)"),
    CLI_NUMBER("--refine-time", "S", O, refine.seconds, 1e-6, 1e9, "stop after S seconds"),
    CLI_INT("--refine-spp", "N", O, refine.spp, 1, 65536,
            "samples that make a pixel refined (default 16)"),
    CLI_FLAG("--refine-all", O, refine.all, "refine zero-error pixels too, after all the others"),
    CLI_FLAG("--refine-components", O, refine.components,
             "trace only the reflection term where reflection metrics alone flag a pixel"),
    CLI_STRING("--lambda", "FILE", O, refine.lambda_path,
               "combine the metrics with fitted weights (drift refine fit)"),
};
#undef O

static const cli_command render_command = {
    .name = "render",
    .usage =
        "usage: drift render [SCENE] [options]\n"
        "\n"
        "Renders SCENE (a scene or mesh file, below); without SCENE, the built-in Cornell box.\n"
        "Writes a linear EXR and a tone-mapped sRGB PNG beside it.\n"
        "\n",
    .epilogue =
        "\nCtrl-C (or SIGTERM) stops the render and writes what it has, and the checkpoint\n"
        "FILE.ckpt beside --out: exit status 130 (143 after SIGTERM). Running the same\n"
        "command again resumes from it (docs/reliability.md).\n",
    CLI_TABLE(render_table),
    CLI_POSITIONAL("SCENE", render_options, scene_path, 1),
};

int render_parse_options(int argc, char **argv, render_options *o)
{
    *o = (render_options){ .out_path = RENDER_DEFAULT_OUT,
                           .hybrid = drift_hybrid_params_default(),
                           .frames = 1,
                           .spp = 64,
                           .checkpoint_seconds = 60.0,
                           .rank_timeout = 300.0,
                           .debug_x = -1,
                           .debug_y = -1,
                           .debug_sample = -1,
                           .aperture = -1.0,
                           .focus_distance = -1.0,
                           .temporal_settings = { .filter_passes = -1 },
                           .still_refine = 2 };
    const char *first[CLI_GROUP_COUNT] = { 0 };
    cli_knobs_unset(&o->hybrid);
    int status = cli_parse(&render_command, argc, argv, o, first);
    if (status != CLI_PARSED) {
        return status;
    }
    cli_knobs_finish(&o->hybrid, o->refine.enabled);
    // --temporal-passes 0 is no filter (0 in drift_temporal_settings is the default).
    o->temporal_settings.no_filter = o->temporal_settings.filter_passes == 0;
    o->temporal_settings.no_still_refine = o->still_refine == 0;
    o->temporal_settings.still_keeps_hybrid = o->still_refine == 1;
    o->temporal_settings.filter_passes =
        o->temporal_settings.filter_passes > 0 ? o->temporal_settings.filter_passes : 0;
    o->hybrid_option = first[0];
    o->refine.first_option = first[1];
    if (!o->hybrid_mode && o->hybrid_option) {
        fprintf(stderr, "drift render: %s needs --mode hybrid\n", o->hybrid_option);
        return 2;
    }
    if (o->temporal_settings.moving_refine && (!o->temporal || !o->animation)) {
        // It refines a moving camera's frames: without a sequence it would do nothing.
        fprintf(stderr, "drift render: --moving-refine needs --animation A:B and --temporal on\n");
        return 2;
    }
    if (!o->hybrid_mode && o->denoise == 4) {
        fprintf(stderr, "drift render: --denoise guided needs --mode hybrid (the hybrid frame "
                        "guides the path tracer)\n");
        return 2;
    }
    if (o->hybrid_mode && o->denoise && o->denoise != 4) {
        fprintf(stderr, "drift render: --denoise filters the path tracer's image; the "
                        "hybrid frame has its own techniques (drop --mode hybrid or --denoise)\n");
        return 2;
    }
    if (o->hybrid_mode && o->resume_path) {
        fprintf(stderr, "drift render: --resume continues a reference render (drop --mode "
                        "hybrid)\n");
        return 2;
    }
    if (o->hybrid.micro.lighting == 1 && o->hybrid.micro.bounces > 1) {
        fprintf(stderr,
                "drift render: --micro-lighting direct is one bounce; --micro-bounces %d "
                "needs radiosity or photons\n",
                o->hybrid.micro.bounces);
        return 2;
    }
    if (!o->hybrid_mode && o->aov_path) {
        fprintf(stderr, "drift render: --aov FILE needs --mode hybrid (reference mode: --aov "
                        "adds layers to --out)\n");
        return 2;
    }
    if (!render_check_view(o)) {
        return 2;
    }
    size_t len = strlen(o->out_path);
    if (len < 5 || strcmp(o->out_path + len - 4, ".exr") != 0) {
        fprintf(stderr, "drift render: --out must name a .exr file, got '%s'\n", o->out_path);
        return 2;
    }
    return 0;
}

// The reference path tracer: passes of samples with progress, checkpoints and Ctrl-C.
int render_reference(const render_options *o, const cli_session *session)
{
    drift_context *ctx = session->ctx;
    render_reference_run run = { .o = o, .session = session };
    if (o->debug_sample < 0) {
        render_catch_sigint(); // before the checkpoint is read: a signal then still counts
    }
    int exit_code = render_reference_begin(&run);
    if (exit_code != 0) {
        goto done;
    }
    drift_pt *pt = run.pt;
    drift_pt_params params = drift_pt_get_params(pt);

    if (o->debug_sample >= 0) {
        if (o->debug_x >= params.width || o->debug_y >= params.height || o->debug_x < 0 ||
            o->debug_y < 0) {
            fprintf(stderr, "drift render: --debug-sample pixel outside the %dx%d image\n",
                    params.width, params.height);
            exit_code = 2;
            goto done;
        }
        drift_vec3 L = drift_pt_trace_sample(pt, (int32_t)o->debug_x, (int32_t)o->debug_y,
                                             (uint32_t)o->debug_sample);
        printf("pixel (%ld, %ld) sample %ld seed %ld: radiance %.9g %.9g %.9g\n", o->debug_x,
               o->debug_y, o->debug_sample, o->seed, (double)L.x, (double)L.y, (double)L.z);
        goto done;
    }

    // Passes grow until one takes about a second: responsive progress, checkpoints and
    // Ctrl-C, without per-pass overhead dominating small images. Each pass brings every tile
    // `pass` samples nearer the total (tiles of a resumed render start where they were).
    bool tty = isatty(STDERR_FILENO) != 0;
    uint32_t total = (uint32_t)o->spp, done_spp = run.resumed_spp, pass = 1;
    // A budget to fill (--budget-ms, a path-tracer pick): from 1 spp, passes go on while the
    // next one and --denoise's filter (the chooser's estimate from a small frame; else timed
    // once on this image) end by the deadline.
    const bool fill = o->budget_deadline > 0.0;
    if (fill) {
        total = 1u << 16; // the deadline ends it
    }
    double sampling_s = 0.0, reserve_s = -1.0;
    run.target_spp = total;
    run.t_render = drift_time_now();
    run.cpu_render = render_cpu_now();
    double last_checkpoint = run.t_render, last_report = 0.0;
    char spp_text[64];
    snprintf(spp_text, sizeof spp_text, fill ? "samples while --budget-ms lasts" : "%u spp", total);
    if (!o->quiet) {
        fprintf(stderr, "drift render: %s, %dx%d, %s, depth %d, %d threads\n", session->scene_path,
                params.width, params.height, spp_text, params.max_depth,
                drift_context_thread_count(ctx));
    }
    while (done_spp < total) {
        if (fill && done_spp >= 1u) {
            if (reserve_s < 0.0) { // 1.25x its time: the filter's cost varies run to run
                reserve_s = 1.25e-3 * (o->budget_denoise_ms > 0.0 ? o->budget_denoise_ms
                                                                  : render_denoise_ms(ctx, pt, o));
            }
            double per_spp = sampling_s / (double)(done_spp - run.resumed_spp);
            double left = o->budget_deadline - reserve_s - drift_time_now();
            double fits = per_spp > 0.0 ? floor(left / per_spp) : 0.0;
            if (fits < 1.0) {
                total = done_spp; // the budget is spent: this is the render, not a stop
                break;
            }
            pass = fits < (double)pass ? (uint32_t)fits : pass;
        }
        double t0 = drift_time_now();
        drift_result r = drift_pt_render_tiles(pt, NULL, 0, pass, total, &interrupted);
        double dt = drift_time_now() - t0;
        sampling_s += dt;
        if (r == DRIFT_ERR_CANCELLED) {
            break;
        }
        done_spp = drift_pt_sample_count(pt);
        if (dt < 0.5 && pass < (1u << 20)) {
            pass *= 2;
        }
        double now = drift_time_now();
        if (!o->quiet && (tty || now - last_report > 5.0 || done_spp == total)) {
            render_progress(tty, run.resumed_spp, done_spp, total, now - run.t_render,
                            done_spp == total);
            last_report = now;
        }
        if (o->checkpoint_seconds > 0.0 && now - last_checkpoint > o->checkpoint_seconds &&
            done_spp < total) {
            if (render_reference_checkpoint(&run) && !o->quiet) {
                fprintf(stderr, "%sdrift render: checkpoint at %u spp written to %s and %s\n",
                        tty ? "\n" : "", done_spp, o->out_path, run.checkpoint_path);
            }
            last_checkpoint = now;
        }
    }
    run.target_spp = total;
    exit_code = render_reference_finish(&run, atomic_load(&interrupted), drift_time_now());

done:
    drift_pt_destroy(run.pt);
    return exit_code;
}

// The default --out's folder ("out/"), made when it is missing so that `drift render` works in
// an empty directory. A folder the user named must exist (a typo should not make one).
static bool make_default_out_folder(const render_options *o)
{
    if (strcmp(o->out_path, RENDER_DEFAULT_OUT) != 0 || mkdir("out", 0777) == 0 ||
        errno == EEXIST) {
        return true;
    }
    fprintf(stderr, "drift render: cannot make the folder 'out' for --out %s: %s\n", o->out_path,
            strerror(errno));
    return false;
}

int render_open_session(render_options *o, bool outputs_here, cli_session *session)
{
    char png[4096];
    render_png_path(o->out_path, png, sizeof png);
    char checkpoint[4096];
    render_checkpoint_path(o->out_path, checkpoint, sizeof checkpoint);
    const cli_file outputs[] = { { "--out", o->out_path },
                                 { "--out's PNG", png },
                                 { "--stats", o->stats_path },
                                 { "--aov", o->aov_path },
                                 { "--out's checkpoint", o->hybrid_mode ? NULL : checkpoint } };
    const cli_file inputs[] = { { "--lambda", o->refine.lambda_path },
                                { "--reflection-edits", o->edits_path },
                                { "--camera-path", o->camera_path } };
    bool writes = outputs_here && o->debug_sample < 0;
    if (writes && !make_default_out_folder(o)) {
        return 1;
    }
    o->edits = NULL;
    o->hybrid.reflection_edits = NULL;
    if (!cli_session_open(&(cli_session_desc){ .cmd = "render",
                                               .scene_path = o->scene_path,
                                               .camera = o->camera,
                                               .environment = o->environment,
                                               .environment_strength = o->environment_strength,
                                               .threads = (int)o->threads,
                                               .verbose = o->verbose,
                                               .outputs = outputs,
                                               .output_count = writes ? 5 : 0,
                                               .inputs = inputs,
                                               .input_count = 3 },
                          session)) {
        return session->refused ? 2 : 1;
    }
    if (o->edits_path && drift_reflection_edits_load(session->ctx, session->scene, session->accel,
                                                     o->edits_path, &o->edits) != DRIFT_OK) {
        fprintf(stderr, "drift render: cannot apply --reflection-edits %s\n", o->edits_path);
        return 2;
    }
    o->hybrid.reflection_edits = o->edits;
    return 0;
}

void render_close_session(render_options *o, cli_session *session)
{
    drift_reflection_edits_destroy(o->edits);
    o->edits = NULL;
    o->hybrid.reflection_edits = NULL;
    cli_session_close(session);
}

int drift_cmd_render(int argc, char **argv)
{
#ifdef DRIFT_MPI
    if (render_mpi_launched()) { // mpirun -n N drift render ...: tools/distributed
        return render_mpi(argc, argv);
    }
#endif
    render_options o;
    int status = render_parse_options(argc, argv, &o);
    if (status != 0) {
        return status < 0 ? 0 : status;
    }
    if ((o.hybrid_mode && !render_refine_validate(&o)) || !render_sequence_validate(&o)) {
        return 2;
    }
    cli_session session;
    int exit_code = render_open_session(&o, !o.print_features, &session);
    if (exit_code == 0 && o.print_features) {
        exit_code = render_print_features(&session);
        render_close_session(&o, &session);
        return exit_code;
    }
    if (exit_code == 0 && o.budget_ms > 0.0) {
        exit_code = render_choose(&o, &session);
    }
    if (exit_code == 0) {
        exit_code = o.animation     ? render_sequence(&o, &session)
                    : o.hybrid_mode ? render_hybrid(&o, &session)
                                    : render_reference(&o, &session);
    }
    render_close_session(&o, &session);
    return exit_code;
}
