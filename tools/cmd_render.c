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
    CLI_CHOICE("--denoise", "none|atrous|on|regression", O, denoise, "none|atrous|on|regression",
               "reference: on = the feature-guided, variance-guided denoiser\n"
               "(docs/denoiser.md); atrous = the edge-avoiding a-trous filter;\n"
               "regression = the blockwise feature regression it was measured against"),
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
    CLI_INT("--temporal-passes", "N", O, temporal_settings.filter_passes, 0, 8,
            "a-trous passes of the temporal filter (default 3; 0: none)"),
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
                           .temporal_settings = { .filter_passes = -1 } };
    const char *first[CLI_GROUP_COUNT] = { 0 };
    cli_knobs_unset(&o->hybrid);
    int status = cli_parse(&render_command, argc, argv, o, first);
    if (status != CLI_PARSED) {
        return status;
    }
    cli_knobs_finish(&o->hybrid, o->refine.enabled);
    // --temporal-passes 0 is no filter (0 in drift_temporal_settings is the default).
    o->temporal_settings.no_filter = o->temporal_settings.filter_passes == 0;
    o->temporal_settings.filter_passes =
        o->temporal_settings.filter_passes > 0 ? o->temporal_settings.filter_passes : 0;
    o->hybrid_option = first[0];
    o->refine.first_option = first[1];
    if (!o->hybrid_mode && o->hybrid_option) {
        fprintf(stderr, "drift render: %s needs --mode hybrid\n", o->hybrid_option);
        return 2;
    }
    if (o->hybrid_mode && o->denoise) {
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

drift_tonemap_params render_png_tonemap(const render_options *o, const drift_image *image)
{
    float stops = (float)o->exposure;
    if (o->exposure_mode == RENDER_EXPOSURE_AUTO) {
        stops = drift_image_auto_exposure(image);
    } else if (o->exposure_mode == RENDER_EXPOSURE_EV100) {
        stops = drift_exposure_from_ev100((float)o->ev100);
    }
    if (o->exposure_mode != RENDER_EXPOSURE_STOPS && !o->quiet) {
        fprintf(stderr, "drift render: PNG exposure %+.2f stops (%s)\n", (double)stops,
                o->exposure_mode == RENDER_EXPOSURE_AUTO ? "auto" : "EV100");
    }
    return (drift_tonemap_params){ .exposure_stops = stops, .op = o->tonemap };
}

// FILE.exr -> FILE.png
void render_png_path(const char *exr_path, char *out, size_t size)
{
    snprintf(out, size, "%.*s.png", (int)(strlen(exr_path) - 4), exr_path);
}

// The path tracer's image through the eye into *out, a new image (--glare static|dynamic in
// reference mode: one frame, the eye at t = 0). The pt's own image is left as it is.
static drift_result apply_glare(drift_context *ctx, const render_options *o, float fov_y,
                                const drift_image *image, drift_image *out)
{
    // The PSF at the camera's angular pitch, as the hybrid frame's glare pass does.
    double aspect = (double)image->width / (double)image->height;
    double fov_x = 2.0 * atan(aspect * tan(0.5 * (double)fov_y));
    drift_glare *glare = NULL;
    drift_glare_params params = { .mode = o->hybrid.glare == DRIFT_GLARE_DYNAMIC
                                              ? DRIFT_GLARE_MODE_DYNAMIC
                                              : DRIFT_GLARE_MODE_STATIC,
                                  .seed = (uint32_t)o->seed,
                                  .image_fov = fov_x };
    drift_result r = drift_glare_create(ctx, &params, &glare);
    if (r == DRIFT_OK) {
        r = drift_glare_apply(glare, image, 0.0, out);
    }
    drift_glare_destroy(glare);
    return r;
}

// The lowest and highest sample count of the pt's tiles (they differ after an interruption).
void render_spp_range(const drift_pt *pt, uint32_t *lowest, uint32_t *highest)
{
    *lowest = UINT32_MAX;
    *highest = 0;
    for (uint32_t t = 0; t < drift_pt_tile_count(pt); ++t) {
        uint32_t n = drift_pt_tile_sample_count(pt, t);
        *lowest = n < *lowest ? n : *lowest;
        *highest = n > *highest ? n : *highest;
    }
}

// The EXR (beauty, --aov layers; an "spp" layer of each pixel's sample count when the tiles
// hold different counts) and the PNG beside it, to the paths given (staged by the caller).
static drift_result write_images(drift_context *ctx, drift_pt *pt, const render_options *o,
                                 float fov_y, const char *exr_path, const char *png_path,
                                 double *out_denoise_ms)
{
    drift_image beauty, albedo, normal, depth;
    drift_result r = drift_pt_resolve(pt, DRIFT_PT_AOV_BEAUTY, &beauty);
    if (r != DRIFT_OK) {
        return r;
    }
    drift_image denoised = { 0 }, glared = { 0 }, spp = { 0 };
    drift_image variance = { 0 }, f_albedo = { 0 }, f_normal = { 0 }, f_depth = { 0 };
    drift_image direct = { 0 }, direct_var = { 0 }, indirect_var = { 0 };
    bool feature = o->denoise >= 2; // --denoise on|regression: drift_denoise_feature
    if (feature || o->aov) {        // the images stay the pt's until its next render call
        if ((r = drift_pt_resolve(pt, DRIFT_PT_AOV_VARIANCE, &variance)) != DRIFT_OK ||
            (r = drift_pt_resolve(pt, DRIFT_PT_AOV_FEATURE_ALBEDO, &f_albedo)) != DRIFT_OK ||
            (r = drift_pt_resolve(pt, DRIFT_PT_AOV_FEATURE_NORMAL, &f_normal)) != DRIFT_OK ||
            (r = drift_pt_resolve(pt, DRIFT_PT_AOV_FEATURE_DEPTH, &f_depth)) != DRIFT_OK ||
            (r = drift_pt_resolve(pt, DRIFT_PT_AOV_DIRECT, &direct)) != DRIFT_OK ||
            (r = drift_pt_resolve(pt, DRIFT_PT_AOV_DIRECT_VARIANCE, &direct_var)) != DRIFT_OK ||
            (r = drift_pt_resolve(pt, DRIFT_PT_AOV_INDIRECT_VARIANCE, &indirect_var)) != DRIFT_OK) {
            return r;
        }
    }
    if (o->denoise) { // before glare (the last pass)
        double t_denoise = drift_time_now();
        if (feature) {
            uint32_t lowest, highest;
            render_spp_range(pt, &lowest, &highest);
            drift_denoise_inputs in = { &beauty, &f_albedo, &f_normal,   &f_depth,     &variance,
                                        lowest,  &direct,   &direct_var, &indirect_var };
            drift_denoise_feature_params fp = { .method = o->denoise == 3
                                                              ? DRIFT_DENOISE_REGRESSION
                                                              : DRIFT_DENOISE_VARIANCE_GUIDED };
            r = drift_denoise_feature(ctx, &in, &fp, &denoised, NULL);
        } else if ((r = drift_pt_resolve(pt, DRIFT_PT_AOV_ALBEDO, &albedo)) == DRIFT_OK &&
                   (r = drift_pt_resolve(pt, DRIFT_PT_AOV_NORMAL, &normal)) == DRIFT_OK &&
                   (r = drift_pt_resolve(pt, DRIFT_PT_AOV_DEPTH, &depth)) == DRIFT_OK) {
            r = drift_denoise_atrous(ctx, &beauty, &albedo, &normal, &depth, NULL, &denoised);
        }
        if (r != DRIFT_OK) {
            return r;
        }
        beauty = denoised; // destroyed below
        *out_denoise_ms = 1e3 * (drift_time_now() - t_denoise);
    }
    drift_image upsampled = { 0 };
    const bool upsample = o->upsample_width > 0 && o->upsample_height > 0;
    if (upsample) { // the chooser's reduced-resolution pick (tools/render_choose.c)
        r = render_upsample_bilinear(ctx, &beauty, (int32_t)o->upsample_width,
                                     (int32_t)o->upsample_height, &upsampled);
        if (r != DRIFT_OK) {
            drift_image_destroy(ctx, &denoised);
            return r;
        }
        beauty = upsampled; // destroyed below
    }
    if (o->hybrid.glare != DRIFT_GLARE_NONE) {
        if ((r = apply_glare(ctx, o, fov_y, &beauty, &glared)) != DRIFT_OK) {
            drift_image_destroy(ctx, &denoised);
            drift_image_destroy(ctx, &upsampled);
            return r;
        }
        beauty = glared; // the glare's copy, destroyed below
    }
    drift_image_layer layers[12] = { { NULL, &beauty } };
    uint32_t layer_count = 1;
    if (o->aov && !upsample) { // the AOVs are at the low resolution: left out
        if ((r = drift_pt_resolve(pt, DRIFT_PT_AOV_ALBEDO, &albedo)) != DRIFT_OK ||
            (r = drift_pt_resolve(pt, DRIFT_PT_AOV_NORMAL, &normal)) != DRIFT_OK ||
            (r = drift_pt_resolve(pt, DRIFT_PT_AOV_DEPTH, &depth)) != DRIFT_OK) {
            drift_image_destroy(ctx, &glared);
            drift_image_destroy(ctx, &denoised);
            return r;
        }
        // The names tev, Nuke and Blender's compositor take as theirs: Z, N.XYZ, albedo.RGB.
        layers[1] = (drift_image_layer){ "albedo", &albedo };
        layers[2] = (drift_image_layer){ o->aov_normal ? "Normal" : "N", &normal };
        layers[3] = (drift_image_layer){ NULL, &depth };
        // The feature-guided denoiser's inputs (drift/pt.h, DRIFT_PT_AOV_VARIANCE on).
        layers[4] = (drift_image_layer){ "variance", &variance };
        layers[5] = (drift_image_layer){ "feature_albedo", &f_albedo };
        layers[6] = (drift_image_layer){ "feature_normal", &f_normal };
        layers[7] = (drift_image_layer){ "feature_depth", &f_depth };
        layers[8] = (drift_image_layer){ "direct", &direct };
        layers[9] = (drift_image_layer){ "direct_variance", &direct_var };
        layers[10] = (drift_image_layer){ "indirect_variance", &indirect_var };
        layer_count = 11;
    }
    uint32_t lowest, highest;
    render_spp_range(pt, &lowest, &highest);
    char spp_text[64], note[256], depth_text[32], seed_text[32];
    snprintf(depth_text, sizeof depth_text, "%d", (int)drift_pt_get_params(pt).max_depth);
    snprintf(seed_text, sizeof seed_text, "%ld", o->seed);
    // The render's settings, for whoever opens the file later (drift.spp_note last: optional).
    drift_image_attribute attributes[5] = {
        { "drift.scene", o->scene_path ? o->scene_path : cli_default_scene_path() },
        { "drift.max_depth", depth_text },
        { "drift.seed", seed_text },
        { "drift.spp", spp_text },
        { "drift.spp_note", note },
    };
    uint32_t attribute_count = 4;
    snprintf(spp_text, sizeof spp_text, "%u", lowest);
    if (lowest != highest && r == DRIFT_OK && !upsample) {
        snprintf(spp_text, sizeof spp_text, "%u..%u", lowest, highest);
        snprintf(note, sizeof note,
                 "interrupted: tiles of %dx%d pixels hold %u to %u samples; the spp layer has "
                 "each pixel's count",
                 DRIFT_PT_TILE_SIZE, DRIFT_PT_TILE_SIZE, lowest, highest);
        attribute_count = 5;
        r = drift_image_create(ctx, beauty.width, beauty.height, 1, &spp);
        for (uint32_t t = 0; r == DRIFT_OK && t < drift_pt_tile_count(pt); ++t) {
            drift_pt_tile rect = drift_pt_tile_rect(pt, t);
            float n = (float)drift_pt_tile_sample_count(pt, t);
            for (int32_t y = rect.y0; y < rect.y1; ++y) {
                for (int32_t x = rect.x0; x < rect.x1; ++x) {
                    *drift_image_pixel(&spp, x, y) = n;
                }
            }
        }
        layers[layer_count++] = (drift_image_layer){ "spp", &spp };
    }
    if (r == DRIFT_OK) {
        // One entry a layer of the --aov file (then the spp layer): beauty, albedo, N, Z,
        // variance, feature_albedo, feature_normal, feature_depth, direct, direct_variance,
        // indirect_variance.
        const char *const channels[12] = { NULL,    NULL, "X,Y,Z", "Z",  NULL, NULL,
                                           "X,Y,Z", NULL, NULL,    NULL, NULL, NULL };
        r = drift_image_save_exr_channels(ctx, exr_path, layers, layer_count,
                                          layer_count > 1 && o->aov ? channels : NULL, attributes,
                                          attribute_count);
    }
    if (r == DRIFT_OK) {
        r = render_save_png(ctx, o, png_path, &beauty);
    }
    drift_image_destroy(ctx, &spp);
    drift_image_destroy(ctx, &glared); // NULL-safe on a zero image
    drift_image_destroy(ctx, &denoised);
    drift_image_destroy(ctx, &upsampled);
    return r;
}

static cJSON *reference_stats(const render_reference_run *run, double t_rendered, double t_written)
{
    const render_options *o = run->o;
    const cli_session *session = run->session;
    const drift_pt *pt = run->pt;
    drift_pt_stats s = drift_pt_get_stats(pt);
    drift_pt_params p = drift_pt_get_params(pt);
    cJSON *root = render_stats_begin(o, session, "reference", p.width, p.height);
    uint32_t lowest, highest;
    render_spp_range(pt, &lowest, &highest);
    cli_json_count(root, "spp", lowest);
    if (lowest != highest) { // interrupted: say each tile's count
        cli_json_count(root, "spp_max", highest);
        cJSON_AddNumberToObject(root, "tile_size", DRIFT_PT_TILE_SIZE);
        cJSON *tiles = cJSON_AddArrayToObject(root, "tile_spp");
        for (uint32_t t = 0; t < drift_pt_tile_count(pt); ++t) {
            cJSON_AddItemToArray(tiles, cJSON_CreateNumber(drift_pt_tile_sample_count(pt, t)));
        }
    }
    cli_json_count(root, "resumed_from_spp", run->resumed_spp);
    cli_json_count(root, "seed", p.seed);
    cJSON_AddNumberToObject(root, "max_depth", p.max_depth);
    cJSON_AddNumberToObject(root, "threads", drift_context_thread_count(session->ctx));
    if (run->ranks > 0) {
        cJSON_AddNumberToObject(root, "ranks", run->ranks);
    }
    cli_json_count(root, "nan_samples", s.nan_samples);
    cJSON *rays = cJSON_AddObjectToObject(root, "rays");
    cli_json_count(rays, "camera", s.camera_rays);
    cli_json_count(rays, "shadow", s.shadow_rays);
    cli_json_count(rays, "bounce", s.bounce_rays);
    cli_json_count(rays, "total", s.camera_rays + s.shadow_rays + s.bounce_rays);
    cJSON *ms = cJSON_AddObjectToObject(root, "milliseconds");
    cli_json_number(ms, "load", 1e3 * (session->t_loaded - session->t_start), 3);
    cli_json_number(ms, "accel", 1e3 * (session->t_built - session->t_loaded), 3);
    cli_json_number(ms, "render", 1e3 * (t_rendered - run->t_render), 3);
    cli_json_number(ms, "write", 1e3 * (t_written - t_rendered), 3);
    if (run->o->denoise) {
        // The filter runs as the image is written: part of "write", what a denoised frame adds
        // to "render".
        cli_json_number(ms, "denoise", run->denoise_ms, 3);
    }
    cli_json_number(ms, "total", 1e3 * (t_written - session->t_start), 3);
    return root;
}

cJSON *render_stats_begin(const render_options *o, const cli_session *session, const char *mode,
                          int width, int height)
{
    cJSON *root = cJSON_CreateObject();
    (void)o;
    cJSON_AddStringToObject(root, "scene", session->scene_path);
    cJSON_AddStringToObject(root, "mode", mode);
    cJSON_AddNumberToObject(root, "width", width);
    cJSON_AddNumberToObject(root, "height", height);
    return root;
}

void render_progress(bool tty, uint32_t first, uint32_t done, uint32_t total, double elapsed,
                     bool final)
{
    double fraction = total ? (double)done / (double)total : 1.0;
    double run = total > first ? (double)(done - first) / (double)(total - first) : 1.0;
    double eta = run > 0.0 ? elapsed * (1.0 - run) / run : 0.0;
    if (tty) {
        char bar[41];
        int filled = (int)(fraction * 40.0);
        for (int i = 0; i < 40; ++i) {
            bar[i] = i < filled ? '#' : '.';
        }
        bar[40] = '\0';
        fprintf(stderr, "\r[%s] %5.1f%%  %u/%u spp  %.1fs elapsed  ETA %.1fs ", bar,
                100.0 * fraction, done, total, elapsed, eta);
        if (final) {
            fputc('\n', stderr);
        }
    } else {
        fprintf(stderr, "drift render: %u/%u spp (%.0f%%), %.1fs elapsed, ETA %.1fs\n", done, total,
                100.0 * fraction, elapsed, eta);
    }
    fflush(stderr);
}

int render_reference_begin(render_reference_run *run)
{
    const render_options *o = run->o;
    const cli_session *session = run->session;
    drift_pt_params params = { .width = (int32_t)o->width,
                               .height = (int32_t)o->height,
                               .seed = (uint32_t)o->seed,
                               .max_depth = (int32_t)o->max_depth,
                               .reflection_edits = o->hybrid.reflection_edits,
                               .texture_filter_spp = (uint32_t)o->spp };
    drift_result r =
        drift_pt_create(session->ctx, session->scene, session->accel, &params, &run->pt);
    if (r != DRIFT_OK) {
        fprintf(stderr, "drift render: %s\n", drift_result_string(r));
        return 1;
    }
    render_checkpoint_path(o->out_path, run->checkpoint_path, sizeof run->checkpoint_path);
    if (o->debug_sample >= 0) {
        return 0;
    }
    if (!render_checkpoint_key(session, run->pt, run->o->edits_path, run->key, sizeof run->key)) {
        return 1;
    }
    // --resume FILE, or the checkpoint beside --out when there is one.
    const char *resume = o->resume_path;
    if (!resume && access(run->checkpoint_path, F_OK) == 0) {
        resume = run->checkpoint_path;
    }
    if (resume) {
        int status = render_checkpoint_read(resume, run->key, run->pt, (uint32_t)o->spp);
        if (status != 0) {
            return status;
        }
        uint32_t highest;
        render_spp_range(run->pt, &run->resumed_spp, &highest);
        if (!o->quiet) {
            fprintf(stderr, "drift render: resuming from %s (tiles at %u to %u spp)\n", resume,
                    run->resumed_spp, highest);
        }
    }
    return 0;
}

// --out, its PNG and --stats (final) or the first two (checkpoint), all or none.
static bool write_outputs(render_reference_run *run, bool final, double t_rendered)
{
    const render_options *o = run->o;
    char png[4096];
    render_png_path(o->out_path, png, sizeof png);
    render_stage stage = { 0 };
    const char *exr_temp = render_stage_add(&stage, o->out_path);
    const char *png_temp = render_stage_add(&stage, png);
    drift_result r = write_images(run->session->ctx, run->pt, o, run->session->scene->camera.fov_y,
                                  exr_temp, png_temp, &run->denoise_ms);
    if (r != DRIFT_OK) {
        fprintf(stderr, "drift render: cannot write %s: %s; nothing written\n", o->out_path,
                drift_result_string(r));
        render_stage_abort(&stage);
        return false;
    }
    if (final && o->stats_path) {
        const char *stats_temp = render_stage_add(&stage, o->stats_path);
        if (!cli_json_write("render", reference_stats(run, t_rendered, drift_time_now()),
                            stats_temp)) {
            fprintf(stderr, "drift render: nothing written\n");
            render_stage_abort(&stage);
            return false;
        }
    }
    return render_stage_commit(&stage);
}

bool render_reference_checkpoint(render_reference_run *run)
{
    bool ok = render_checkpoint_write(run->checkpoint_path, run->key, run->pt);
    return write_outputs(run, false, 0.0) && ok;
}

int render_reference_finish(render_reference_run *run, bool cancelled, double t_rendered)
{
    const render_options *o = run->o;
    bool tty = isatty(STDERR_FILENO) != 0;
    uint32_t lowest, highest;
    render_spp_range(run->pt, &lowest, &highest);
    bool complete = lowest >= (uint32_t)o->spp;
    if (!complete) {
        bool saved = render_checkpoint_write(run->checkpoint_path, run->key, run->pt);
        fprintf(stderr, "%sdrift render: %s at %u spp%s; writing what was rendered%s%s%s\n",
                tty && !o->quiet ? "\n" : "", cancelled ? "interrupted" : "stopped", lowest,
                lowest != highest ? " (tiles hold different counts, up to the most; the EXR's "
                                    "spp layer has each pixel's)"
                                  : "",
                saved ? "; run the same command to resume from " : "",
                saved ? run->checkpoint_path : "", saved ? "" : "");
    }
    if (!write_outputs(run, true, t_rendered)) {
        // Keep the work (a full disk): the checkpoint a resumed or stopped run has, else one
        // written now; the same command writes the images from it once there is room.
        bool kept = access(run->checkpoint_path, F_OK) == 0 ||
                    render_checkpoint_write(run->checkpoint_path, run->key, run->pt);
        if (kept) {
            fprintf(stderr,
                    "drift render: the render is kept in %s; run the same command to "
                    "write it\n",
                    run->checkpoint_path);
        }
        return 1;
    }
    if (complete && access(run->checkpoint_path, F_OK) == 0 && unlink(run->checkpoint_path) != 0) {
        fprintf(stderr, "drift render: warning: cannot remove the finished checkpoint %s\n",
                run->checkpoint_path);
    }
    drift_pt_stats stats = drift_pt_get_stats(run->pt);
    if (stats.nan_samples > 0) {
        fprintf(stderr, "drift render: warning: %llu samples were not finite and were dropped\n",
                (unsigned long long)stats.nan_samples);
    }
    char png[4096];
    render_png_path(o->out_path, png, sizeof png);
    drift_pt_params params = drift_pt_get_params(run->pt);
    char spp[64];
    snprintf(spp, sizeof spp, lowest == highest ? "%u spp" : "%u..%u spp", lowest, highest);
    printf("wrote %s and %s (%s, %dx%d) in %.2f s (render %.2f s)\n", o->out_path, png, spp,
           params.width, params.height, drift_time_now() - run->session->t_start,
           t_rendered - run->t_render);
    return cancelled ? render_interrupt_status() : complete ? 0 : 1;
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
    run.t_render = drift_time_now();
    double last_checkpoint = run.t_render, last_report = 0.0;
    if (!o->quiet) {
        fprintf(stderr, "drift render: %s, %dx%d, %u spp, depth %d, %d threads\n",
                session->scene_path, params.width, params.height, total, params.max_depth,
                drift_context_thread_count(ctx));
    }
    while (done_spp < total) {
        double t0 = drift_time_now();
        drift_result r = drift_pt_render_tiles(pt, NULL, 0, pass, total, &interrupted);
        double dt = drift_time_now() - t0;
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
