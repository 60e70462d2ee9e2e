// drift bench sir: the paper's Table 1 on our CPU. For each scene and size: the pure ray
// tracer's time for the whole image against SIR's time to the same image (raster frame +
// metrics + sort + tracing the error pixels until each has all its samples), the error
// pixels (count, %), the FLIP of SIR's image against the pure one, and each metric's recall
// and precision against the real error |raster - ray traced| > threshold.
#include "bench.h"
#include "cli.h"
#include "distributed/sweep.h"
#include "drift/accel.h"
#include "drift/hybrid.h"
#include "drift/image_io.h"
#include "drift/metric.h"
#include "drift/refine.h"
#include "drift/scene.h"
#include "drift/scene_io.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_SCENES  8
#define MAX_SIZES   8
#define MAX_VIEWS   16
#define FLIP_TARGET 0.01

typedef struct sir_options {
    const char *scenes[MAX_SCENES];
    int scene_count;
    int32_t widths[MAX_SIZES], heights[MAX_SIZES];
    int size_count;
    long spp, budget, threads, light_samples;
    double threshold;
    double tolerance; // the metrics' tolerances (0: the refiner's default)
    const char *lambda_path;
    const char *figures_dir;
    bool json;
    bool noise_floor;
    bool paper_metrics;
    bool full_res_penumbra;
    bool components;
    int parallax; // --envmap-parallax: 0 none, 1 box (drift_envmap_parallax)
    bool has_target;
    drift_vec3 target; // --target: look here instead of the scene camera's target
    double fov;        // --fov: vertical field of view, degrees (0: the camera's)
    const char *views_path;
    drift_camera_view views[MAX_VIEWS];
    uint32_t view_count; // 0: the one camera (with --target and --fov)
} sir_options;

static bool parse_sizes(const char *cmd, const char *flag, const char *v, void *field)
{
    sir_options *o = field;
    o->size_count = 0;
    const char *p = v;
    while (*p) {
        int w, h, used = 0;
        if (o->size_count == MAX_SIZES || sscanf(p, "%dx%d%n", &w, &h, &used) != 2 || w < 8 ||
            h < 8 || w > 16384 || h > 16384) {
            fprintf(stderr, "drift %s: %s expects WxH[,WxH...] (8..16384), got '%s'\n", cmd, flag,
                    v);
            return false;
        }
        o->widths[o->size_count] = w;
        o->heights[o->size_count++] = h;
        p += used;
        if (*p == ',') {
            ++p;
        } else if (*p) {
            fprintf(stderr, "drift %s: %s expects WxH[,WxH...], got '%s'\n", cmd, flag, v);
            return false;
        }
    }
    return o->size_count > 0;
}

static bool parse_target(const char *cmd, const char *flag, const char *v, void *field)
{
    sir_options *o = field;
    o->has_target = cli_parse_vec3(cmd, flag, v, false, &o->target);
    return o->has_target;
}

#define O sir_options
static const cli_option sir_table[] = {
    CLI_SECTION("options:", 0),
    CLI_CUSTOM_ALL("--sizes", "WxH,...", parse_sizes,
                   "image sizes (default 800x600,1024x768,1920x1080)"),
    CLI_INT("--spp", "N", O, spp, 1, 65536, "samples a pixel in both PRT and SIR (default 4)"),
    CLI_INT("--budget", "N", O, budget, 1, 1L << 30,
            "SIR samples an iteration (default 8192, the paper's ray count)"),
    CLI_INT("--light-samples", "N", O, light_samples, 1, 4096,
            "the raster's samples per area light and environment\n"
            "(default 8, the hybrid frame's)"),
    CLI_NUMBER("--threshold", "T", O, threshold, 1e-6, 1.0,
               "real error: largest display-value channel difference > T (0.02)"),
    CLI_NUMBER("--tolerance", "T", O, tolerance, 1e-4, 1.0,
               "the metrics' tolerances: a pixel whose raster is expected off by less\n"
               "(display values) is not flagged (default 0.01)"),
    CLI_STRING("--lambda", "FILE", O, lambda_path, "also measure the fitted combination"),
    CLI_STRING("--figures", "DIR", O, figures_dir,
               "PNGs per row: raster, pure, sir, combined error, and the\n"
               "recall map (white: real error flagged, red: missed, blue: flagged only),\n"
               "and the raster's error 4x (red: brighter than PRT, green: darker)"),
    CLI_FLAG("--noise-floor", O, noise_floor,
             "also the FLIP between two pure images of different seeds (how\n"
             "close two equally good images are), and a real error must exceed\n"
             "the threshold plus the two pure images' difference at the pixel"),
    CLI_FLAG("--paper-metrics", O, paper_metrics,
             "the paper's metrics alone: reflection metrics unweighted by the raster's\n"
             "expected error, penumbrae ungated, no leak metric (the before of issue 17)"),
    CLI_FLAG("--full-res-penumbra", O, full_res_penumbra,
             "search the penumbra estimate at every pixel, not once a 2 x 2 block"),
    CLI_FLAG("--components", O, components,
             "trace only R at pixels flagged by reflection metrics alone, keeping the\n"
             "raster's E + D there (no shadow rays at their first hit)"),
    CLI_CHOICE("--envmap-parallax", "P", O, parallax, "none|box",
               "the raster's environment-map lookup: none (as seen from the probe) or\n"
               "box (parallax-corrected against the scene's bounds; the default)"),
    CLI_CUSTOM_ALL("--target", "X,Y,Z", parse_target,
                   "look at this point instead of the camera's target (other views,\n"
                   "as the paper's rows are views with more or fewer error pixels)"),
    CLI_NUMBER("--fov", "DEG", O, fov, 0.1, 179.0,
               "vertical field of view (default: the camera's)"),
    CLI_STRING("--views", "FILE", O, views_path,
               "rows for several views of each scene, from JSON:\n"
               "{\"views\": [{\"name\": \"high\", \"position\": [x, y, z],\n"
               "\"target\": [x, y, z], \"fov_y\": degrees, \"aperture_radius\": r}]}\n"
               "(every field but name optional: the scene camera's)"),
    BENCH_OPTION_THREADS(O),
    BENCH_OPTION_JSON(O),
};
#undef O

static const cli_command sir_command = {
    .name = "bench sir",
    .usage = "usage: drift bench sir [SCENE...] [options]\n\n"
             "Table 1 of Amann et al. 2012: pure ray tracing (PRT) time vs SIR time to the same\n"
             "image, error pixels, FLIP of SIR against PRT, and recall/precision of each metric\n"
             "against the real error. The raster is the hybrid frame with PCSS shadows,\n"
             "environment-map reflections and post DOF (second frame: cached maps, as the\n"
             "paper's precomputed environment maps). SCENE defaults to breakfast-room and\n"
             "cornell-glossy (need ../shared); at most " CLI_STR(MAX_SCENES) ".\n\n",
    CLI_TABLE(sir_table),
    CLI_POSITIONAL("SCENE", sir_options, scenes, MAX_SCENES),
    .help_column = 17,
};

static int parse(int argc, char **argv, sir_options *o)
{
    *o = (sir_options){
        .spp = 4, .budget = 8192, .threads = 1, .threshold = 0.02, .parallax = 1 /* box */
    };
    parse_sizes("bench sir", "--sizes", "800x600,1024x768,1920x1080", o);
    int status = cli_parse(&sir_command, argc, argv, o, NULL);
    if (status != CLI_PARSED) {
        return status;
    }
    while (o->scene_count < MAX_SCENES && o->scenes[o->scene_count]) {
        ++o->scene_count;
    }
    if (o->scene_count == 0) {
        o->scenes[0] = DRIFT_SOURCE_DIR "/scenes/breakfast-room/breakfast_room.json";
        o->scenes[1] = DRIFT_SOURCE_DIR "/scenes/cornell-glossy/cornell_glossy.json";
        o->scene_count = 2;
    }
    return 0;
}

// Recall and precision of `flag > 0` against `real > 0`.
typedef struct quality {
    double recall, precision, flagged;
} quality;

static quality measure_quality(const drift_image *flag, const drift_image *real)
{
    uint64_t hit = 0, flagged = 0, truth = 0;
    size_t n = (size_t)flag->width * (size_t)flag->height;
    for (size_t i = 0; i < n; ++i) {
        bool f = flag->pixels[i] > 0.0f, t = real->pixels[i] > 0.0f;
        hit += f && t;
        flagged += f;
        truth += t;
    }
    return (quality){ truth ? (double)hit / (double)truth : 1.0,
                      flagged ? (double)hit / (double)flagged : 1.0, (double)flagged / (double)n };
}

typedef struct ranked_pixel {
    float error;
    bool real;
} ranked_pixel;

static int by_error_descending(const void *a, const void *b)
{
    float ea = ((const ranked_pixel *)a)->error, eb = ((const ranked_pixel *)b)->error;
    return (ea < eb) - (ea > eb);
}

// Precision at recall `recall` along SIR's own order (descending combined error: the pixels
// it refines first): the share of real error among the first pixels that hold that much of
// it. -1 when the flagged pixels never reach it; -2 without memory.
static double precision_at_recall(const drift_image *error, const drift_image *real, double recall)
{
    size_t n = (size_t)error->width * (size_t)error->height, flagged = 0, truth = 0;
    ranked_pixel *ranked = malloc(sizeof *ranked * (n ? n : 1));
    if (!ranked) {
        return -2.0;
    }
    for (size_t i = 0; i < n; ++i) {
        truth += real->pixels[i] > 0.0f;
        if (error->pixels[i] > 0.0f) {
            ranked[flagged++] = (ranked_pixel){ error->pixels[i], real->pixels[i] > 0.0f };
        }
    }
    qsort(ranked, flagged, sizeof *ranked, by_error_descending);
    double result = -1.0;
    size_t hits = 0;
    for (size_t k = 0; k < flagged && truth > 0; ++k) {
        hits += ranked[k].real;
        if ((double)hits >= recall * (double)truth) {
            result = (double)hits / (double)(k + 1);
            break;
        }
    }
    free(ranked);
    return truth == 0 ? 1.0 : result;
}

#define QUALITY_ROWS (DRIFT_METRIC_COUNT + 2)

typedef struct sir_row {
    const char *scene;
    const char *view; // --views name, or "camera"
    int32_t width, height;
    uint64_t error_pixels, real_pixels;
    double error_percent, real_percent;
    double raster_ms, metrics_ms, sort_ms, trace_ms, sir_ms, prt_ms, flip;
    double noise_flip; // FLIP between two pure images of different seeds (-1: not measured)
    double reached_ms; // SIR's time to FLIP <= FLIP_TARGET against PRT (-1: not reached)
    uint64_t sir_rays, prt_rays;
    uint64_t raster_rays, metrics_rays; // the raster frame's, the metrics'
    uint32_t iterations;
    quality q[QUALITY_ROWS]; // the metrics, the averaged sum, lambda (when given)
    double precision_at_90;  // the combined error's precision at recall 0.9, in its order
} sir_row;

static void save_png(drift_context *ctx, const sir_options *o, const char *scene, int32_t w,
                     int32_t h, const char *what, const drift_image *image)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/sir_%s_%dx%d_%s.png", o->figures_dir, scene, w, h, what);
    drift_image_save_png(ctx, path, image, &(drift_tonemap_params){ 0 });
}

// White: real error the combined metric flags; red: real error it misses; blue: flagged
// without real error.
static void save_figures(drift_context *ctx, const sir_options *o, const char *scene,
                         const drift_image *raster, const drift_image *pure,
                         const drift_image *refined, const drift_image *error,
                         const drift_image *real)
{
    int32_t w = raster->width, h = raster->height;
    save_png(ctx, o, scene, w, h, "raster", raster);
    save_png(ctx, o, scene, w, h, "pure", pure);
    save_png(ctx, o, scene, w, h, "sir", refined);
    save_png(ctx, o, scene, w, h, "error", error);
    drift_image map;
    if (drift_image_create(ctx, w, h, 3, &map) != DRIFT_OK) {
        return;
    }
    for (int32_t y = 0; y < h; ++y) {
        for (int32_t x = 0; x < w; ++x) {
            bool f = drift_image_pixel(error, x, y)[0] > 0.0f,
                 t = drift_image_pixel(real, x, y)[0] > 0.0f;
            drift_vec3 c = t ? (f ? drift_vec3_splat(1.0f) : drift_vec3_make(1, 0, 0))
                             : (f ? drift_vec3_make(0, 0, 0.5f) : drift_vec3_splat(0.0f));
            drift_image_set3(&map, x, y, c);
        }
    }
    save_png(ctx, o, scene, w, h, "recall", &map);
    // The sign of the raster's error, 4x: red where the raster is brighter (a leak), green
    // where it is darker.
    for (int32_t y = 0; y < h; ++y) {
        for (int32_t x = 0; x < w; ++x) {
            const float *a = drift_image_pixel(raster, x, y), *b = drift_image_pixel(pure, x, y);
            float d = 4.0f * ((a[0] + a[1] + a[2]) - (b[0] + b[1] + b[2])) / 3.0f;
            drift_image_set3(&map, x, y,
                             drift_vec3_make(d > 0.0f ? d : 0.0f, d < 0.0f ? -d : 0.0f, 0));
        }
    }
    save_png(ctx, o, scene, w, h, "sign", &map);
    drift_image_destroy(ctx, &map);
}

static drift_result run_one(drift_context *ctx, const drift_scene *scene, const drift_accel *accel,
                            const sir_options *o, int32_t w, int32_t h, const float *lambda,
                            sir_row *row)
{
    drift_hybrid_params hp = { .width = w,
                               .height = h,
                               .shadows = DRIFT_SHADOWS_PCSS,
                               .reflections = DRIFT_REFLECTIONS_ENVMAP,
                               .dof = DRIFT_DOF_POST,
                               .envmap = { .parallax = (drift_envmap_parallax)o->parallax },
                               .light_samples = (uint32_t)o->light_samples };
    drift_hybrid *frame = NULL;
    drift_refine *sir = NULL;
    drift_image pure = { 0 }, real = { 0 }, combined = { 0 }, pure_other = { 0 };
    float tolerance = o->paper_metrics ? -1.0f : (float)o->tolerance;
    drift_result r = drift_hybrid_create(ctx, scene, accel, &hp, &frame);
    // Two frames: the first builds the shadow maps and captures the environment maps.
    for (int k = 0; r == DRIFT_OK && k < 2; ++k) {
        r = drift_hybrid_render(frame, &scene->camera, NULL);
    }
    if (r == DRIFT_OK) {
        r = drift_refine_create(ctx, frame,
                                &(drift_refine_params){ .spp = (uint32_t)o->spp,
                                                        .budget = (uint32_t)o->budget,
                                                        .reflection_tolerance = tolerance,
                                                        .leak_tolerance = tolerance,
                                                        .shadow_tolerance = tolerance,
                                                        .full_res_penumbra = o->full_res_penumbra,
                                                        .components = o->components },
                                &sir);
    }
    if (r == DRIFT_OK) {
        r = drift_image_create(ctx, w, h, 3, &pure);
    }
    if (r == DRIFT_OK) {
        r = drift_image_create(ctx, w, h, 1, &real);
    }
    if (r == DRIFT_OK) {
        r = drift_image_create(ctx, w, h, 1, &combined);
    }
    if (r == DRIFT_OK) {
        r = drift_image_create(ctx, w, h, 3, &pure_other);
    }
    if (r != DRIFT_OK) {
        goto done;
    }
    drift_hybrid_stats raster_stats = drift_hybrid_get_stats(frame);
    row->raster_ms = raster_stats.frame_ms;
    for (int p = 0; p < DRIFT_PASS_COUNT; ++p) {
        row->raster_rays += raster_stats.rays[p];
    }
    double t = drift_time_now();
    r = drift_refine_render_pure(sir, (uint32_t)o->spp, &pure, &row->prt_rays, NULL);
    row->prt_ms = 1000.0 * (drift_time_now() - t);
    // SIR's clock runs only while it refines: the FLIP checks along the way (about twenty,
    // at every 5% of the samples to trace) are outside it. reached: the first check at
    // FLIP <= FLIP_TARGET against the pure image.
    t = drift_time_now();
    if (r == DRIFT_OK) {
        r = drift_refine_begin(sir);
    }
    double refine_ms = 1000.0 * (drift_time_now() - t);
    row->reached_ms = -1.0;
    uint64_t step = drift_refine_get_stats(sir).requested * (uint64_t)o->spp / 20u + 1u;
    uint64_t next_check = 0;
    while (r == DRIFT_OK) {
        if (row->reached_ms < 0.0 &&
            (drift_refine_done(sir) || drift_refine_get_stats(sir).samples >= next_check)) {
            double flip = 1.0;
            r = drift_metric_flip(ctx, &pure, drift_refine_image(sir), NULL, &flip, NULL);
            if (flip <= FLIP_TARGET) {
                row->reached_ms = row->raster_ms + refine_ms;
            }
            next_check += step;
        }
        if (r != DRIFT_OK || drift_refine_done(sir)) {
            break;
        }
        t = drift_time_now();
        r = drift_refine_iterate(sir, NULL);
        refine_ms += 1000.0 * (drift_time_now() - t);
    }
    if (r != DRIFT_OK) {
        goto done;
    }
    drift_refine_stats s = drift_refine_get_stats(sir);
    row->width = w;
    row->height = h;
    row->error_pixels = s.error_pixels;
    row->error_percent = 100.0 * (double)s.error_pixels / ((double)w * (double)h);
    row->metrics_ms = s.metrics_ms;
    row->metrics_rays = s.metrics_rays;
    row->sort_ms = s.sort_ms;
    row->trace_ms = s.trace_ms;
    row->sir_ms = row->raster_ms + refine_ms;
    row->sir_rays = s.rays;
    row->iterations = s.iterations;
    r = drift_metric_flip(ctx, &pure, drift_refine_image(sir), NULL, &row->flip, NULL);
    if (r != DRIFT_OK) {
        goto done;
    }
    row->noise_flip = -1.0;
    if (o->noise_floor) {
        drift_refine_params other = { .spp = (uint32_t)o->spp,
                                      .budget = (uint32_t)o->budget,
                                      .seed = 1 };
        r = drift_refine_set_params(sir, &other);
        if (r == DRIFT_OK) {
            r = drift_refine_render_pure(sir, (uint32_t)o->spp, &pure_other, NULL, NULL);
        }
        if (r == DRIFT_OK) {
            r = drift_metric_flip(ctx, &pure, &pure_other, NULL, &row->noise_flip, NULL);
        }
        if (r != DRIFT_OK) {
            goto done;
        }
    }
    // The real error: pixels whose raster value differs from the ray-traced one by more than
    // the threshold (display values) - and, with --noise-floor, by more than the threshold
    // plus what two pure images differ by there: error beyond the estimators' own noise.
    drift_refine_real_error(drift_hybrid_image(frame), &pure, 1.0f, &real);
    size_t n = (size_t)w * (size_t)h;
    if (o->noise_floor) {
        drift_refine_real_error(&pure_other, &pure, 1.0f, &combined);
    } else {
        memset(combined.pixels, 0, sizeof(float) * n);
    }
    for (size_t i = 0; i < n; ++i) {
        real.pixels[i] = real.pixels[i] > (float)o->threshold + combined.pixels[i] ? 1.0f : 0.0f;
        row->real_pixels += real.pixels[i] > 0.0f;
    }
    row->real_percent = 100.0 * (double)row->real_pixels / (double)n;
    for (int m = 0; m < DRIFT_METRIC_COUNT; ++m) {
        row->q[m] = measure_quality(drift_refine_metric_image(sir, (drift_refine_metric)m), &real);
    }
    row->q[DRIFT_METRIC_COUNT] = measure_quality(drift_refine_error(sir), &real);
    row->precision_at_90 = precision_at_recall(drift_refine_error(sir), &real, 0.9);
    if (o->figures_dir) {
        char label[160];
        snprintf(label, sizeof label, "%s%s%s", row->scene, o->view_count ? "_" : "",
                 o->view_count ? row->view : "");
        save_figures(ctx, o, label, drift_hybrid_image(frame), &pure, drift_refine_image(sir),
                     drift_refine_error(sir), &real);
    }
    if (lambda) {
        drift_image metrics[DRIFT_METRIC_COUNT];
        for (int m = 0; m < DRIFT_METRIC_COUNT; ++m) {
            metrics[m] = *drift_refine_metric_image(sir, (drift_refine_metric)m);
        }
        float weights[DRIFT_METRIC_COUNT];
        memcpy(weights, lambda, sizeof weights);
        float sum = 0.0f;
        for (int m = 0; m < DRIFT_METRIC_COUNT; ++m) {
            sum += weights[m];
        }
        for (size_t i = 0; i < n; ++i) {
            float e = 0.0f;
            for (int m = 0; m < DRIFT_METRIC_COUNT; ++m) {
                e += weights[m] * metrics[m].pixels[i];
            }
            combined.pixels[i] = sum > 0.0f && e > 0.0f ? e : 0.0f;
        }
        row->q[DRIFT_METRIC_COUNT + 1] = measure_quality(&combined, &real);
    }
done:
    drift_image_destroy(ctx, &pure);
    drift_image_destroy(ctx, &real);
    drift_image_destroy(ctx, &combined);
    drift_image_destroy(ctx, &pure_other);
    drift_refine_destroy(sir);
    drift_hybrid_destroy(frame);
    return r;
}

static const char *quality_name(int k)
{
    if (k < DRIFT_METRIC_COUNT) {
        return drift_refine_metric_name((drift_refine_metric)k);
    }
    return k == DRIFT_METRIC_COUNT ? "average" : "lambda";
}

static void add_json_row(cJSON *rows, const sir_row *row, bool lambda)
{
    cJSON *r = cJSON_CreateObject();
    cJSON_AddItemToArray(rows, r);
    cJSON_AddStringToObject(r, "scene", row->scene);
    cJSON_AddStringToObject(r, "view", row->view);
    cJSON_AddNumberToObject(r, "width", row->width);
    cJSON_AddNumberToObject(r, "height", row->height);
    cli_json_count(r, "error_pixels", row->error_pixels);
    cli_json_number(r, "error_percent", row->error_percent, 3);
    cli_json_count(r, "real_error_pixels", row->real_pixels);
    cli_json_number(r, "real_error_percent", row->real_percent, 3);
    cli_json_number(r, "raster_ms", row->raster_ms, 2);
    cli_json_number(r, "metrics_ms", row->metrics_ms, 2);
    cli_json_number(r, "sort_ms", row->sort_ms, 2);
    cli_json_number(r, "trace_ms", row->trace_ms, 2);
    cli_json_number(r, "sir_ms", row->sir_ms, 2);
    cli_json_number(r, "prt_ms", row->prt_ms, 2);
    cli_json_number(r, "speedup", row->prt_ms / row->sir_ms, 3);
    cli_json_number(r, "flip", row->flip, 5);
    cli_json_number(r, "noise_flip", row->noise_flip, 5);
    cli_json_number(r, "sir_to_flip_ms", row->reached_ms, 2);
    cli_json_number(r, "speedup_to_flip",
                    row->reached_ms > 0.0 ? row->prt_ms / row->reached_ms : 0.0, 3);
    cJSON_AddBoolToObject(r, "same_image", row->flip <= FLIP_TARGET);
    cli_json_number(r, "precision_at_recall_0_9", row->precision_at_90, 4);
    cli_json_count(r, "iterations", row->iterations);
    cli_json_count(r, "sir_rays", row->sir_rays);
    cli_json_count(r, "prt_rays", row->prt_rays);
    cli_json_count(r, "raster_rays", row->raster_rays);
    cli_json_count(r, "metrics_rays", row->metrics_rays);
    // What refining cannot save: the raster and the metrics, against pure ray tracing.
    cli_json_number(r, "raster_metrics_time_share",
                    (row->raster_ms + row->metrics_ms) / row->prt_ms, 4);
    cli_json_number(r, "raster_metrics_ray_share",
                    row->prt_rays
                        ? (double)(row->raster_rays + row->metrics_rays) / (double)row->prt_rays
                        : 0.0,
                    4);
    cJSON *by_metric = cJSON_AddObjectToObject(r, "quality");
    int count = lambda ? QUALITY_ROWS : QUALITY_ROWS - 1;
    for (int k = 0; k < count; ++k) {
        cJSON *q = cJSON_AddObjectToObject(by_metric, quality_name(k));
        cli_json_number(q, "recall", row->q[k].recall, 4);
        cli_json_number(q, "precision", row->q[k].precision, 4);
        cli_json_number(q, "flagged", row->q[k].flagged, 4);
    }
}

static void print_text_row(const sir_row *row, bool lambda)
{
    printf("%-16s %-10s %5dx%-5d %9llu (%5.2f%%) %9.1f %9.1f %7.2fx %8.5f %s\n", row->scene,
           row->view, row->width, row->height, (unsigned long long)row->error_pixels,
           row->error_percent, row->prt_ms, row->sir_ms, row->prt_ms / row->sir_ms, row->flip,
           row->flip <= FLIP_TARGET ? "yes" : "NO");
    if (row->reached_ms > 0.0) {
        printf("    FLIP <= %.2f after %.1f ms: %.2fx faster than PRT\n", FLIP_TARGET,
               row->reached_ms, row->prt_ms / row->reached_ms);
    } else {
        printf("    FLIP <= %.2f not reached\n", FLIP_TARGET);
    }
    printf("    raster + metrics: %.1f%% of PRT's time, %.1f%% of its rays (%llu + %llu of "
           "%llu)\n",
           100.0 * (row->raster_ms + row->metrics_ms) / row->prt_ms,
           row->prt_rays
               ? 100.0 * (double)(row->raster_rays + row->metrics_rays) / (double)row->prt_rays
               : 0.0,
           (unsigned long long)row->raster_rays, (unsigned long long)row->metrics_rays,
           (unsigned long long)row->prt_rays);
    printf("    raster %.1f + metrics %.1f + sort %.1f + trace %.1f ms, %u iterations; real error "
           "pixels %.2f%%; pure vs pure FLIP %.5f\n    recall/precision:",
           row->raster_ms, row->metrics_ms, row->sort_ms, row->trace_ms, row->iterations,
           row->real_percent, row->noise_flip);
    int rows = lambda ? QUALITY_ROWS : QUALITY_ROWS - 1;
    for (int k = 0; k < rows; ++k) {
        printf(" %s %.3f/%.3f", quality_name(k), row->q[k].recall, row->q[k].precision);
    }
    printf("\n    precision at recall 0.9 in SIR's order: ");
    if (row->precision_at_90 >= 0.0) {
        printf("%.3f\n", row->precision_at_90);
    } else {
        printf("not reached\n");
    }
}

static const char *short_name(const char *path)
{
    const char *slash = strrchr(path, '/');
    return slash ? slash + 1 : path;
}

int drift_bench_sir(int argc, char **argv)
{
    sir_options o;
    int pr = parse(argc, argv, &o);
    if (pr != 0) {
        return cli_parse_exit(pr);
    }
    cli_session session;
    if (!cli_session_open(
            &(cli_session_desc){ .cmd = "bench sir", .threads = (int)o.threads, .no_scene = true },
            &session)) {
        cli_session_close(&session);
        return 1;
    }
    drift_context *ctx = session.ctx;
    drift_result r = DRIFT_OK;
    float lambda[DRIFT_METRIC_COUNT];
    if (o.lambda_path && drift_refine_lambda_load(ctx, o.lambda_path, lambda) != DRIFT_OK) {
        fprintf(stderr, "drift bench sir: --lambda: cannot use %s\n", o.lambda_path);
        cli_session_close(&session);
        return 2;
    }
    if (o.views_path &&
        drift_camera_views_load(ctx, o.views_path, o.views, MAX_VIEWS, &o.view_count) != DRIFT_OK) {
        fprintf(stderr, "drift bench sir: --views: cannot use %s\n", o.views_path);
        cli_session_close(&session);
        return 2;
    }
    int exit_code = 0;
    cJSON *root = NULL, *rows = NULL;
    if (o.json) {
        root = cJSON_CreateObject();
        cJSON_AddNumberToObject(root, "threads", drift_context_thread_count(ctx));
        cJSON_AddNumberToObject(root, "spp", (double)o.spp);
        cJSON_AddNumberToObject(root, "budget", (double)o.budget);
        cli_json_number(root, "threshold", o.threshold, 4);
        cli_json_number(root, "flip_target", FLIP_TARGET, 3);
        rows = cJSON_AddArrayToObject(root, "rows");
    } else {
        printf("%d thread(s), %ld spp, budget %ld samples an iteration, real error > %.3f\n",
               drift_context_thread_count(ctx), o.spp, o.budget, o.threshold);
        printf("%-16s %-10s %-11s %20s %9s %9s %8s %8s %s\n", "scene", "view", "size",
               "error pixels", "PRT ms", "SIR ms", "speedup", "FLIP", "same");
    }
    // Each (scene, view, size) row is a sweep item; under mpirun they spread over the ranks
    // (sweep.h) and rank 0 prints each scene's rows once it has gathered them.
    bool spread = sweep_ranks() > 1;
    for (int s = 0, item = 0; s < o.scene_count && exit_code == 0; ++s) {
        bool loaded = cli_session_load(&session, "bench sir", o.scenes[s], false);
        if (!sweep_gather(NULL, 0, 0, 0, loaded)) {
            exit_code = 1;
            break;
        }
        drift_scene *scene = session.scene;
        if (o.has_target) {
            scene->camera.target = o.target;
        }
        if (o.fov > 0.0) {
            scene->camera.fov_y = (float)(o.fov * 3.14159265358979323846 / 180.0);
        }
        const drift_camera camera = scene->camera;
        int views = (int)(o.view_count ? o.view_count : 1), count = views * o.size_count;
        sir_row *scene_rows = calloc((size_t)count, sizeof *scene_rows);
        bool ok = scene_rows != NULL;
        for (int i = 0; ok && i < count; ++i) {
            int v = i / o.size_count, k = i % o.size_count;
            const drift_camera_view *view = o.view_count ? &o.views[v] : NULL;
            if (!sweep_mine(item + i)) {
                continue;
            }
            scene->camera = camera;
            if (view) {
                drift_camera_view_apply(view, &scene->camera);
            }
            sir_row *row = &scene_rows[i];
            // Named before the run: its figures are saved under these names.
            row->scene = short_name(o.scenes[s]);
            row->view = view ? view->name : "camera";
            r = run_one(ctx, scene, session.accel, &o, o.widths[k], o.heights[k],
                        o.lambda_path ? lambda : NULL, row);
            if (r != DRIFT_OK) {
                fprintf(stderr, "drift bench sir: %s failed: %s\n", o.scenes[s],
                        drift_result_string(r));
                ok = false;
            } else if (!spread) { // one process: each row as soon as it is measured
                if (rows) {
                    add_json_row(rows, row, o.lambda_path != NULL);
                } else {
                    print_text_row(row, o.lambda_path != NULL);
                    fflush(stdout);
                }
            }
        }
        ok = sweep_gather(scene_rows, sizeof *scene_rows, item, count, ok);
        for (int i = 0; ok && spread && sweep_rank() == 0 && i < count; ++i) {
            sir_row *row = &scene_rows[i]; // its names: another rank's pointers mean nothing
            row->scene = short_name(o.scenes[s]);
            row->view = o.view_count ? o.views[i / o.size_count].name : "camera";
            if (rows) {
                add_json_row(rows, row, o.lambda_path != NULL);
            } else {
                print_text_row(row, o.lambda_path != NULL);
            }
        }
        free(scene_rows);
        item += count;
        exit_code = ok ? 0 : 1;
    }
    if (root && (exit_code != 0 || sweep_rank() != 0)) {
        cJSON_Delete(root);
    } else if (root && !cli_json_write("bench sir", root, NULL)) {
        exit_code = 1;
    }
    cli_session_close(&session);
    return exit_code;
}
