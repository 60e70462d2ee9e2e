// drift render: renders a scene with the reference path tracer.
//
// Reads like the API walk-through: load the scene, build the accel, create the path tracer,
// add samples in passes (progress, checkpoints, Ctrl-C), resolve and write the images.
#include "cli.h"
#include "drift/accel.h"
#include "drift/denoise.h"
#include "drift/glare.h"
#include "drift/image_io.h"
#include "drift/pt.h"
#include "drift/reflect_edit.h"
#include "drift/scene_io.h"
#include "render.h"

#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

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

static bool parse_envmap_parallax(const char *cmd, const char *flag, const char *v, void *field)
{
    drift_hybrid_params *h = field;
    if (strcmp(v, "none") == 0) {
        h->envmap.parallax = DRIFT_ENVMAP_PARALLAX_NONE;
    } else if (strcmp(v, "box") == 0) {
        h->envmap.parallax = DRIFT_ENVMAP_PARALLAX_BOX;
    } else {
        fprintf(stderr, "drift %s: %s expects none or box, got '%s'\n", cmd, flag, v);
        return false;
    }
    return true;
}

static bool parse_ambient(const char *cmd, const char *flag, const char *v, void *field)
{
    drift_hybrid_params *h = field;
    h->has_ambient = true;
    return cli_parse_vec3(cmd, flag, v, true, &h->ambient);
}

// ISG sample counts are k x k grids on the disk: 9, 25, 49, 81 (any square up to 1024).
static bool parse_isg_count(const char *cmd, const char *flag, const char *v, void *field)
{
    long n = 0;
    if (!cli_parse_int(cmd, flag, v, 1, 1024, &n)) {
        return false;
    }
    long k = 1;
    while (k * k < n) {
        ++k;
    }
    if (k * k != n) {
        fprintf(stderr, "drift %s: %s expects a perfect square (9, 25, 49, 81, ...), got '%s'\n",
                cmd, flag, v);
        return false;
    }
    *(int32_t *)field = (int32_t)n;
    return true;
}

// --micro-density: the share of pixels that gather, as 1, 1/4 or 1/16 (the grid's spacing).
static bool parse_micro_density(const char *cmd, const char *flag, const char *v, void *field)
{
    static const char *const names[] = { "1", "1/4", "1/16" };
    static const int32_t spacing[] = { 1, 2, 4 };
    for (int i = 0; i < 3; ++i) {
        if (strcmp(v, names[i]) == 0) {
            *(int32_t *)field = spacing[i];
            return true;
        }
    }
    fprintf(stderr, "drift %s: %s expects 1, 1/4 or 1/16, got '%s'\n", cmd, flag, v);
    return false;
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
      .help = "reference: add albedo, normal and depth layers to the EXR;\n"
              "hybrid: write every plane and buffer as layers of FILE.exr",
      .kind = CLI_KIND_CUSTOM,
      .parse = parse_aov,
      .optional_if = ".exr" },
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
    CLI_CUSTOM_ALL("--debug-sample", "X,Y,S", parse_debug_sample,
                   "trace one sample of one pixel and print its radiance"),
    CLI_STRING("--reflection-edits", "FILE.json", O, edits_path,
               "edit the reflections: sharp, envmap and ISG reflections and the path\n"
               "tracer's first specular bounce follow e(q) (docs/reflection-editing.md)"),
    CLI_FLAG("--quiet", O, quiet, "no progress output"),
    CLI_FLAG("--verbose", O, verbose, "more log output"),

    CLI_SECTION("hybrid mode (docs/hybrid.md):", GROUP_HYBRID),
    CLI_TECHNIQUES("T", O, hybrid),
    CLI_NOTE("each technique is listed below; reference = that effect\n"
             "alone path-traced at --spp; aaf: --spp rays a pixel on\n"
             "average (shadows: per area light)"),
    CLI_INT("--frames", "N", O, frames, 1, 100000,
            "render N frames of the view and write the last: its stats\n"
            "are a frame with warm caches (default 1; first_frame_ms in\n"
            "--stats has the first)"),
    CLI_INT("--light-samples", "N", O, hybrid.light_samples, 1, 4096,
            "samples per area light for unshadowed light, and the environment's\n"
            "shadow rays a pixel (default 2; docs/frontier.md#the-defaults)"),
    CLI_INT("--aa", "N", O, hybrid.aa, 1, 4096,
            "anti-aliasing: the whole frame N times, each through a\n"
            "stratified sub-pixel offset with its own seed, averaged (the\n"
            "path tracer's box pixel filter; default 1 = pixel centres);\n"
            "hard shadows aim at a stratified point of the light a pass\n"
            "(soft shadows), ISM gathers 1/N of one frame's VPLs a pass"),
    CLI_INT("--shadow-map-size", "N", O, hybrid.shadow_map.size, 1, 8192,
            "texels a cube face (default 512)"),
    CLI_NUMBER("--shadow-bias", "B", O, hybrid.shadow_map.bias, 1e-3, 1e3,
               "shadow-map depth bias in texel footprints (default 1.5)"),
    CLI_INT("--pcf-kernel", "K", O, hybrid.shadow_map.pcf_kernel, 1, 63,
            "PCF texels across (default 3)"),
    CLI_INT("--envmap-size", "N", O, hybrid.envmap.size, 1, 4096,
            "texels a cube face (default 128)"),
    CLI_CUSTOM("--probe", "X,Y,Z|object", O, hybrid, parse_probe,
               "environment-map probe: a point, or one per reflective mesh\n"
               "(default: the scene's centre)"),
    CLI_CUSTOM("--envmap-parallax", "none|box", O, hybrid, parse_envmap_parallax,
               "environment-map lookup: none (along the reflected direction,\n"
               "as seen from the probe) or box (parallax-corrected against the\n"
               "scene's bounding box, a local cube map; default none)"),
    CLI_CUSTOM("--ambient", "R,G,B", O, hybrid, parse_ambient,
               "ambient radiance (default: the frame's mean direct light)"),
    CLI_NUMBER("--aperture", "R", O, aperture, 0.0, 1e30,
               "lens radius in scene units (default: the scene camera's)"),
    CLI_NUMBER("--focus-distance", "F", O, focus_distance, 1e-30, 1e30,
               "distance to the plane in focus (default: the camera's)"),
    CLI_CUSTOM("--isg-search", "N", O, hybrid.isg.search, parse_isg_count,
               "image space gathering (docs/isg.md): parameter-search"),
    CLI_CUSTOM("--isg-gather", "M", O, hybrid.isg.gather, parse_isg_count,
               "and gather samples, perfect squares (default 25 and 49)"),
    CLI_NUMBER("--isg-sigma", "S", O, hybrid.isg.sigma, 1e-30, 1e30,
               "range sigma of eq. 6 and 10, squared scene units\n"
               "(default (0.02 x scene extent)^2)"),
    CLI_NUMBER("--blur-radius", "R", O, hybrid.isg.blur_radius, 1e-30, 1024.0,
               "disk radius in pixels of the blur baselines (default 4)"),
    CLI_INT("--isg-layers", "1|2", O, hybrid.isg.layers, 1, 2,
            "2: a second depth layer behind objects for --dof isg"),
    CLI_CHOICE("--isg-range", "full|plane", O, hybrid.isg.range_plane, "full|plane",
               "l of the range functions: world distance (default, the\n"
               "paper) or distance to the centre's tangent plane"),
    CLI_INT("--aaf-max-spp", "N", O, hybrid.aaf.max_spp, 1, 65536,
            "cap on AAF's adaptive samples a pixel (default 8 x spp)"),
    CLI_CHOICE("--aaf-sampling", "M", O, hybrid.aaf.uniform, "adaptive|uniform",
               "adaptive (default) or uniform: spp in every pixel"),
    CLI_CHOICE("--aaf-filter", "on|off", O, hybrid.aaf.unfiltered, "on|off",
               "off: AAF's unfiltered estimate (with uniform: plain MC)"),
    CLI_CHOICE("--aaf-sampler", "S", O, hybrid.aaf.random, "sobol|random",
               "sobol (default: Owen-scrambled Sobol) or random (independent\n"
               "uniform numbers, the paper's Monte Carlo)"),
    CLI_INT("--occlusion-samples", "N", O, hybrid.occlusion_settings.samples, 1, 1024,
            "--occlusion ssao|gtao|ssdo (docs/ssdo.md): samples a pixel\n"
            "(default 16; ssdo 4, marched by --occlusion-steps)"),
    CLI_NUMBER("--occlusion-radius", "R", O, hybrid.occlusion_settings.radius, 1e-30, 1e30,
               "r_max in scene units (default 0.05 x scene extent)"),
    CLI_CHOICE("--ssdo-bounce", "off|on", O, hybrid.occlusion_settings.bounce, "off|on",
               "on: SSDO's one indirect bounce (when --indirect is none)"),
    CLI_INT("--occlusion-layers", "1|2", O, hybrid.occlusion_settings.layers, 1, 2,
            "2: a second depth layer (one more ray a pixel) behind thin\n"
            "objects (default 1)"),
    CLI_CHOICE("--occlusion-fade", "on|off", O, hybrid.occlusion_settings.no_fade, "on|off",
               "off: occluders near r_max count fully (default on)"),
    CLI_CHOICE("--occlusion-blur", "on|off", O, hybrid.occlusion_settings.no_blur, "on|off",
               "off: no geometry-aware blur of the sample sets (default on)"),
    CLI_INT("--occlusion-cameras", "N", O, hybrid.occlusion_settings.cameras, 0, 5,
            "additional depth-only cameras at half size that find occluders\n"
            "outside the image (ssao, ssdo, contact shadows; default 0)"),
    CLI_INT("--occlusion-steps", "K", O, hybrid.occlusion_settings.steps, 1, 64,
            "points on each ssao/ssdo sample direction: 1 the thesis's\n"
            "point test (ssao default), more a march to r_max (a ray\n"
            "test; ssdo default 4)"),
    CLI_CHOICE("--env-interleave", "off|on", O, hybrid.environment_interleave, "off|on",
               "on: a quarter of the environment's --light-samples shadow rays a\n"
               "pixel, interleaved over 2 x 2 pixels and gathered back over 3 x 3\n"
               "of the same surface (default off; docs/hybrid.md)"),
    CLI_INT("--env-scale", "N", O, hybrid.environment_scale, 1, 2,
            "2: one pixel in 2 x 2 traces the environment's shadow rays, the\n"
            "others take the traced ones on their surface (default 2, or 1\n"
            "with --env-interleave on; 1: every pixel; docs/hybrid.md)"),
    CLI_INT("--env-filter", "N", O, hybrid.environment_filter, 0, 10,
            "N passes of the edge-avoiding a-trous filter over the\n"
            "environment's direct light, guided by the G-buffer (default 4;\n"
            "0: none; docs/hybrid.md)"),
    CLI_CHOICE("--contact-shadows", "off|on", O, hybrid.shadow_map.contact_shadows, "off|on",
               "on: --shadows pcf|pcss march each lit pixel's shadow-map bias\n"
               "toward the light in screen space (thesis §4.5; default off)"),
    CLI_INT("--contact-samples", "N", O, hybrid.shadow_map.contact_samples, 1, 1024,
            "points on each contact-shadow march (default 8)"),
    CLI_INT("--ism-vpls", "N", O, hybrid.ism.vpls, 1, 65536,
            "instant radiosity (--indirect ism|ir, docs/ism.md): light\n"
            "paths, one first-bounce VPL each (default 1024)"),
    CLI_CHOICE("--ism-vpl-importance", "off|on", O, hybrid.ism.vpl_importance, "off|on",
               "on: keep candidate VPLs with probability by their contribution\n"
               "to the view, divided by it (Georgiev & Slusallek 2010;\n"
               "default off)"),
    CLI_CHOICE("--ism-near-field", "on|off", O, hybrid.ism.no_near_field, "on|off",
               "off: no near-field compensation (short rays from a quarter of the\n"
               "pixels give back the light of surfaces nearer than the VPLs'\n"
               "clamp; default on)"),
    CLI_INT("--ism-gather-scale", "N", O, hybrid.ism.gather_scale, 1, 4,
            "1: every pixel gathers the VPLs; 2 or 4: one pixel in 2x2 or\n"
            "4x4 does, its irradiance upsampled to the others (default 2;\n"
            "docs/ism.md)"),
    CLI_INT("--ism-map-size", "N", O, hybrid.ism.map_size, 4, 1024,
            "texels a side of each VPL's imperfect shadow map (default 64)"),
    CLI_INT("--ism-points", "N", O, hybrid.ism.points_per_vpl, 16, 1 << 20,
            "scene points splatted into each map (default 1024)"),
    CLI_INT("--ism-later-paths", "N", O, hybrid.ism.later_paths, 1, 65536,
            "of the --ism-vpls paths, how many go on past their first VPL\n"
            "(default a quarter; at most all of them; docs/ism.md)"),
    CLI_INT("--micro-points", "N", O, hybrid.micro.points, 2, 1 << 22,
            "micro-rendering (--indirect micro, --reflections micro,\n"
            "docs/micro.md): scene points in the hierarchy, rounded up to\n"
            "a power of two (default 65536)"),
    CLI_INT("--micro-size", "K", O, hybrid.micro.buffer_size, 4, 32,
            "each gather's micro-buffer is K x K pixels (default 16)"),
    CLI_CUSTOM("--micro-density", "1|1/4|1/16", O, hybrid.micro.density, parse_micro_density,
               "gather at every pixel, 1/4 or 1/16 of them and upsample\n"
               "bilaterally (default 1)"),
    CLI_INT("--micro-bounces", "N", O, hybrid.micro.bounces, 1, 8,
            "light bounces the micro-buffers gather: the points hold\n"
            "direct light plus N - 1 bounces (default 1)"),
    CLI_CHOICE("--micro-lighting", "MODE", O, hybrid.micro.lighting,
               "auto|direct|radiosity|photons",
               "auto, direct, radiosity or photons: how the points get\n"
               "bounces 2..N, by Jacobi gathers over the hierarchy or a\n"
               "photon map (caustics included); direct is one bounce; auto\n"
               "(default): direct for one bounce, else radiosity"),

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
        "Renders SCENE (a drift .json scene, or .obj/.gltf/.glb/.ply[.gz]); without SCENE, the\n"
        "built-in Cornell box. Writes a linear EXR and a tone-mapped sRGB PNG beside it.\n"
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
    *o = (render_options){ .out_path = "out/render.exr",
                           .hybrid = drift_hybrid_params_recommended(),
                           .frames = 1,
                           .spp = 64,
                           .checkpoint_seconds = 60.0,
                           .rank_timeout = 300.0,
                           .debug_x = -1,
                           .debug_y = -1,
                           .debug_sample = -1,
                           .aperture = -1.0,
                           .focus_distance = -1.0 };
    const char *first[CLI_GROUP_COUNT] = { 0 };
    // Whether --indirect is given decides its default (see --refine below).
    o->hybrid.techniques[DRIFT_EFFECT_INDIRECT] = CLI_TECHNIQUE_UNSET;
    o->hybrid.environment_scale = 0; // unset: decided below (interleaving takes every pixel)
    int status = cli_parse(&render_command, argc, argv, o, first);
    if (status != CLI_PARSED) {
        return status;
    }
    // SIR's tracer has no indirect light (docs/sir.md): a refined frame starts from none.
    if (o->hybrid.techniques[DRIFT_EFFECT_INDIRECT] == CLI_TECHNIQUE_UNSET) {
        o->hybrid.indirect =
            o->refine.enabled ? DRIFT_INDIRECT_NONE : drift_hybrid_params_recommended().indirect;
    }
    if (o->hybrid.environment_scale == 0) {
        o->hybrid.environment_scale = o->hybrid.environment_interleave
                                          ? 1
                                          : drift_hybrid_params_recommended().environment_scale;
    }
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
    bool feature = o->denoise >= 2; // --denoise on|regression: drift_denoise_feature
    if (feature || o->aov) {        // the images stay the pt's until its next render call
        if ((r = drift_pt_resolve(pt, DRIFT_PT_AOV_VARIANCE, &variance)) != DRIFT_OK ||
            (r = drift_pt_resolve(pt, DRIFT_PT_AOV_FEATURE_ALBEDO, &f_albedo)) != DRIFT_OK ||
            (r = drift_pt_resolve(pt, DRIFT_PT_AOV_FEATURE_NORMAL, &f_normal)) != DRIFT_OK ||
            (r = drift_pt_resolve(pt, DRIFT_PT_AOV_FEATURE_DEPTH, &f_depth)) != DRIFT_OK) {
            return r;
        }
    }
    if (o->denoise) { // before glare (the last pass)
        double t_denoise = drift_time_now();
        if (feature) {
            uint32_t lowest, highest;
            render_spp_range(pt, &lowest, &highest);
            drift_denoise_inputs in = {
                &beauty, &f_albedo, &f_normal, &f_depth, &variance, lowest
            };
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
    if (o->hybrid.glare != DRIFT_GLARE_NONE) {
        if ((r = apply_glare(ctx, o, fov_y, &beauty, &glared)) != DRIFT_OK) {
            drift_image_destroy(ctx, &denoised);
            return r;
        }
        beauty = glared; // the glare's copy, destroyed below
    }
    drift_image_layer layers[9] = { { NULL, &beauty } };
    uint32_t layer_count = 1;
    if (o->aov) {
        if ((r = drift_pt_resolve(pt, DRIFT_PT_AOV_ALBEDO, &albedo)) != DRIFT_OK ||
            (r = drift_pt_resolve(pt, DRIFT_PT_AOV_NORMAL, &normal)) != DRIFT_OK ||
            (r = drift_pt_resolve(pt, DRIFT_PT_AOV_DEPTH, &depth)) != DRIFT_OK) {
            drift_image_destroy(ctx, &glared);
            drift_image_destroy(ctx, &denoised);
            return r;
        }
        layers[1] = (drift_image_layer){ "albedo", &albedo };
        layers[2] = (drift_image_layer){ "normal", &normal };
        layers[3] = (drift_image_layer){ "depth", &depth };
        // The feature-guided denoiser's inputs (drift/pt.h, DRIFT_PT_AOV_VARIANCE on).
        layers[4] = (drift_image_layer){ "variance", &variance };
        layers[5] = (drift_image_layer){ "feature_albedo", &f_albedo };
        layers[6] = (drift_image_layer){ "feature_normal", &f_normal };
        layers[7] = (drift_image_layer){ "feature_depth", &f_depth };
        layer_count = 8;
    }
    uint32_t lowest, highest;
    render_spp_range(pt, &lowest, &highest);
    char spp_text[64], note[256];
    drift_image_attribute attributes[2] = { { "drift.spp", spp_text }, { "drift.spp_note", note } };
    uint32_t attribute_count = 1;
    snprintf(spp_text, sizeof spp_text, "%u", lowest);
    if (lowest != highest && r == DRIFT_OK) {
        snprintf(spp_text, sizeof spp_text, "%u..%u", lowest, highest);
        snprintf(note, sizeof note,
                 "interrupted: tiles of %dx%d pixels hold %u to %u samples; the spp layer has "
                 "each pixel's count",
                 DRIFT_PT_TILE_SIZE, DRIFT_PT_TILE_SIZE, lowest, highest);
        attribute_count = 2;
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
        r = drift_image_save_exr_attributes(ctx, exr_path, layers, layer_count, attributes,
                                            attribute_count);
    }
    if (r == DRIFT_OK) {
        drift_tonemap_params tonemap = render_png_tonemap(o, &beauty);
        r = drift_image_save_png(ctx, png_path, &beauty, &tonemap);
    }
    drift_image_destroy(ctx, &spp);
    drift_image_destroy(ctx, &glared); // NULL-safe on a zero image
    drift_image_destroy(ctx, &denoised);
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
                               .reflection_edits = o->hybrid.reflection_edits };
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
static int render_reference(const render_options *o, const cli_session *session)
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
                                { "--reflection-edits", o->edits_path } };
    bool writes = outputs_here && o->debug_sample < 0;
    o->edits = NULL;
    o->hybrid.reflection_edits = NULL;
    if (!cli_session_open(&(cli_session_desc){ .cmd = "render",
                                               .scene_path = o->scene_path,
                                               .threads = (int)o->threads,
                                               .verbose = o->verbose,
                                               .outputs = outputs,
                                               .output_count = writes ? 5 : 0,
                                               .inputs = inputs,
                                               .input_count = 2 },
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
    if (o.hybrid_mode && !render_refine_validate(&o)) {
        return 2;
    }
    cli_session session;
    int exit_code = render_open_session(&o, true, &session);
    if (exit_code == 0) {
        exit_code = o.hybrid_mode ? render_hybrid(&o, &session) : render_reference(&o, &session);
    }
    render_close_session(&o, &session);
    return exit_code;
}
