// drift bench sir: the paper's Table 1 on our CPU. For each scene and size: the pure ray
// tracer's time for the whole image against SIR's time to the same image (raster frame +
// metrics + sort + tracing the error pixels until each has all its samples), the error
// pixels (count, %), the FLIP of SIR's image against the pure one, and each metric's recall
// and precision against the real error |raster - ray traced| > threshold.
#include "bench.h"
#include "cli.h"
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
    const char *lambda_path;
    const char *figures_dir;
    bool json;
    bool noise_floor;
    bool has_target;
    drift_vec3 target; // --target: look here instead of the scene camera's target
    double fov;        // --fov: vertical field of view, degrees (0: the camera's)
    const char *views_path;
    drift_camera_view views[MAX_VIEWS];
    uint32_t view_count; // 0: the one camera (with --target and --fov)
} sir_options;

static void print_help(FILE *out)
{
    fprintf(
        out,
        "usage: drift bench sir [SCENE...] [--sizes WxH,...] [--spp N] [--budget N]\n"
        "                       [--threshold T] [--lambda FILE] [--threads T] [--json]\n"
        "                       [--light-samples N] [--views FILE]\n\n"
        "Table 1 of Amann et al. 2012: pure ray tracing (PRT) time vs SIR time to the same\n"
        "image, error pixels, FLIP of SIR against PRT, and recall/precision of each metric\n"
        "against the real error. The raster is the hybrid frame with PCSS shadows,\n"
        "environment-map reflections and post DOF (second frame: cached maps, as the\n"
        "paper's precomputed environment maps).\n\n"
        "  SCENE         default: breakfast-room and cornell-glossy (need ../shared)\n"
        "  --sizes       default 800x600,1024x768,1920x1080\n"
        "  --spp N       samples a pixel in both PRT and SIR (default 4)\n"
        "  --budget N    SIR samples an iteration (default 8192, the paper's ray count)\n"
        "  --light-samples N  the raster's samples per area light and environment\n"
        "                (default 8, the hybrid frame's)\n"
        "  --threshold T real error: largest display-value channel difference > T (0.02)\n"
        "  --lambda FILE also measure the fitted combination\n"
        "  --figures DIR PNGs per row: raster, pure, sir, combined error, and the\n"
        "                recall map (white: real error flagged, red: missed, blue: flagged only)\n"
        "  --noise-floor also the FLIP between two pure images of different seeds (how\n"
        "                close two equally good images are), and a real error must exceed\n"
        "                the threshold plus the two pure images' difference at the pixel\n"
        "  --target X,Y,Z  look at this point instead of the camera's target (other views,\n"
        "                as the paper's rows are views with more or fewer error pixels)\n"
        "  --fov DEG     vertical field of view (default: the camera's)\n"
        "  --views FILE  rows for several views of each scene, from JSON:\n"
        "                {\"views\": [{\"name\": \"high\", \"position\": [x, y, z],\n"
        "                \"target\": [x, y, z], \"fov_y\": degrees, \"aperture_radius\": r}]}\n"
        "                (every field but name optional: the scene camera's)\n"
        "  --threads T   worker threads (default 1: per-thread figures)\n"
        "  --json        one JSON object on stdout\n");
}

static bool parse_sizes(const char *v, sir_options *o)
{
    o->size_count = 0;
    const char *p = v;
    while (*p) {
        int w, h, used = 0;
        if (o->size_count == MAX_SIZES || sscanf(p, "%dx%d%n", &w, &h, &used) != 2 || w < 8 ||
            h < 8 || w > 16384 || h > 16384) {
            fprintf(stderr, "drift bench sir: --sizes expects WxH[,WxH...] (8..16384), got '%s'\n",
                    v);
            return false;
        }
        o->widths[o->size_count] = w;
        o->heights[o->size_count++] = h;
        p += used;
        if (*p == ',') {
            ++p;
        } else if (*p) {
            fprintf(stderr, "drift bench sir: --sizes expects WxH[,WxH...], got '%s'\n", v);
            return false;
        }
    }
    return o->size_count > 0;
}

static int parse(int argc, char **argv, sir_options *o)
{
    *o = (sir_options){ .spp = 4, .budget = 8192, .threads = 1, .threshold = 0.02 };
    parse_sizes("800x600,1024x768,1920x1080", o);
    for (int i = 1; i < argc; ++i) {
        const char *a = argv[i], *v = NULL;
        bool ok = true;
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            print_help(stdout);
            return -1;
        } else if (strcmp(a, "--json") == 0) {
            o->json = true;
        } else if (strcmp(a, "--sizes") == 0) {
            ok = (v = cli_next_value("bench sir", argc, argv, &i)) && parse_sizes(v, o);
        } else if (strcmp(a, "--spp") == 0) {
            ok = (v = cli_next_value("bench sir", argc, argv, &i)) &&
                 cli_parse_int("bench sir", a, v, 1, 65536, &o->spp);
        } else if (strcmp(a, "--budget") == 0) {
            ok = (v = cli_next_value("bench sir", argc, argv, &i)) &&
                 cli_parse_int("bench sir", a, v, 1, 1L << 30, &o->budget);
        } else if (strcmp(a, "--light-samples") == 0) {
            ok = (v = cli_next_value("bench sir", argc, argv, &i)) &&
                 cli_parse_int("bench sir", a, v, 1, 4096, &o->light_samples);
        } else if (strcmp(a, "--threshold") == 0) {
            ok = (v = cli_next_value("bench sir", argc, argv, &i)) &&
                 cli_parse_float("bench sir", a, v, 1e-6, 1.0, &o->threshold);
        } else if (strcmp(a, "--lambda") == 0) {
            ok = (o->lambda_path = cli_next_value("bench sir", argc, argv, &i)) != NULL;
        } else if (strcmp(a, "--target") == 0) {
            float x = 0.0f, y = 0.0f, z = 0.0f;
            char tail;
            ok = (v = cli_next_value("bench sir", argc, argv, &i)) &&
                 sscanf(v, "%f,%f,%f%c", &x, &y, &z, &tail) == 3;
            if (v && !ok) {
                fprintf(stderr, "drift bench sir: --target expects X,Y,Z, got '%s'\n", v);
            }
            o->target = drift_vec3_make(x, y, z);
            o->has_target = ok;
        } else if (strcmp(a, "--fov") == 0) {
            ok = (v = cli_next_value("bench sir", argc, argv, &i)) &&
                 cli_parse_float("bench sir", a, v, 0.1, 179.0, &o->fov);
        } else if (strcmp(a, "--views") == 0) {
            ok = (o->views_path = cli_next_value("bench sir", argc, argv, &i)) != NULL;
        } else if (strcmp(a, "--noise-floor") == 0) {
            o->noise_floor = true;
        } else if (strcmp(a, "--figures") == 0) {
            ok = (o->figures_dir = cli_next_value("bench sir", argc, argv, &i)) != NULL;
        } else if (strcmp(a, "--threads") == 0) {
            ok = (v = cli_next_value("bench sir", argc, argv, &i)) &&
                 cli_parse_int("bench sir", a, v, 0, 256, &o->threads);
        } else if (a[0] == '-') {
            fprintf(stderr, "drift bench sir: unknown option '%s'\n", a);
            ok = false;
        } else if (o->scene_count < MAX_SCENES) {
            o->scenes[o->scene_count++] = a;
        } else {
            fprintf(stderr, "drift bench sir: at most %d scenes\n", MAX_SCENES);
            ok = false;
        }
        if (!ok) {
            return 2;
        }
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
    uint32_t iterations;
    quality q[QUALITY_ROWS]; // the metrics, the averaged sum, lambda (when given)
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
                               .light_samples = (uint32_t)o->light_samples };
    drift_hybrid *frame = NULL;
    drift_refine *sir = NULL;
    drift_image pure = { 0 }, real = { 0 }, combined = { 0 }, pure_other = { 0 };
    drift_result r = drift_hybrid_create(ctx, scene, accel, &hp, &frame);
    // Two frames: the first builds the shadow maps and captures the environment maps.
    for (int k = 0; r == DRIFT_OK && k < 2; ++k) {
        r = drift_hybrid_render(frame, &scene->camera, NULL);
    }
    if (r == DRIFT_OK) {
        r = drift_refine_create(
            ctx, frame,
            &(drift_refine_params){ .spp = (uint32_t)o->spp, .budget = (uint32_t)o->budget }, &sir);
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
    row->raster_ms = drift_hybrid_get_stats(frame).frame_ms;
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

static void print_json_row(const sir_row *row, bool first, bool lambda)
{
    printf("%s{\"scene\": \"%s\", \"view\": \"%s\", \"width\": %d, \"height\": %d, "
           "\"error_pixels\": %llu, "
           "\"error_percent\": %.3f, \"real_error_pixels\": %llu, \"real_error_percent\": %.3f, "
           "\"raster_ms\": %.2f, \"metrics_ms\": %.2f, \"sort_ms\": %.2f, \"trace_ms\": %.2f, "
           "\"sir_ms\": %.2f, \"prt_ms\": %.2f, \"speedup\": %.3f, \"flip\": %.5f, "
           "\"noise_flip\": %.5f, \"sir_to_flip_ms\": %.2f, \"speedup_to_flip\": %.3f, "
           "\"same_image\": %s, \"iterations\": %u, \"sir_rays\": %llu, \"prt_rays\": %llu, "
           "\"quality\": {",
           first ? "" : ", ", row->scene, row->view, row->width, row->height,
           (unsigned long long)row->error_pixels, row->error_percent,
           (unsigned long long)row->real_pixels, row->real_percent, row->raster_ms, row->metrics_ms,
           row->sort_ms, row->trace_ms, row->sir_ms, row->prt_ms, row->prt_ms / row->sir_ms,
           row->flip, row->noise_flip, row->reached_ms,
           row->reached_ms > 0.0 ? row->prt_ms / row->reached_ms : 0.0,
           row->flip <= FLIP_TARGET ? "true" : "false", row->iterations,
           (unsigned long long)row->sir_rays, (unsigned long long)row->prt_rays);
    int rows = lambda ? QUALITY_ROWS : QUALITY_ROWS - 1;
    for (int k = 0; k < rows; ++k) {
        printf("%s\"%s\": {\"recall\": %.4f, \"precision\": %.4f, \"flagged\": %.4f}",
               k ? ", " : "", quality_name(k), row->q[k].recall, row->q[k].precision,
               row->q[k].flagged);
    }
    printf("}}");
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
    printf("    raster %.1f + metrics %.1f + sort %.1f + trace %.1f ms, %u iterations; real error "
           "pixels %.2f%%; pure vs pure FLIP %.5f\n    recall/precision:",
           row->raster_ms, row->metrics_ms, row->sort_ms, row->trace_ms, row->iterations,
           row->real_percent, row->noise_flip);
    int rows = lambda ? QUALITY_ROWS : QUALITY_ROWS - 1;
    for (int k = 0; k < rows; ++k) {
        printf(" %s %.3f/%.3f", quality_name(k), row->q[k].recall, row->q[k].precision);
    }
    printf("\n");
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
        return pr < 0 ? 0 : pr;
    }
    drift_context *ctx = cli_open_context("bench sir", (int)o.threads, false);
    if (!ctx) {
        return 1;
    }
    drift_result r = DRIFT_OK;
    float lambda[DRIFT_METRIC_COUNT];
    if (o.lambda_path && drift_refine_lambda_load(ctx, o.lambda_path, lambda) != DRIFT_OK) {
        fprintf(stderr, "drift bench sir: --lambda: cannot use %s\n", o.lambda_path);
        drift_context_destroy(ctx);
        return 2;
    }
    if (o.views_path &&
        drift_camera_views_load(ctx, o.views_path, o.views, MAX_VIEWS, &o.view_count) != DRIFT_OK) {
        fprintf(stderr, "drift bench sir: --views: cannot use %s\n", o.views_path);
        drift_context_destroy(ctx);
        return 2;
    }
    int exit_code = 0;
    bool first = true;
    if (o.json) {
        printf("{\"threads\": %d, \"spp\": %ld, \"budget\": %ld, \"threshold\": %.4f, "
               "\"flip_target\": %.3f, \"rows\": [",
               drift_context_thread_count(ctx), o.spp, o.budget, o.threshold, FLIP_TARGET);
    } else {
        printf("%d thread(s), %ld spp, budget %ld samples an iteration, real error > %.3f\n",
               drift_context_thread_count(ctx), o.spp, o.budget, o.threshold);
        printf("%-16s %-10s %-11s %20s %9s %9s %8s %8s %s\n", "scene", "view", "size",
               "error pixels", "PRT ms", "SIR ms", "speedup", "FLIP", "same");
    }
    for (int s = 0; s < o.scene_count && exit_code == 0; ++s) {
        drift_scene *scene = NULL;
        drift_accel *accel = NULL;
        if (!cli_open_scene(ctx, "bench sir", o.scenes[s], &scene, &accel, NULL)) {
            exit_code = 1;
            break;
        }
        if (o.has_target) {
            scene->camera.target = o.target;
        }
        if (o.fov > 0.0) {
            scene->camera.fov_y = (float)(o.fov * 3.14159265358979323846 / 180.0);
        }
        const drift_camera camera = scene->camera;
        for (uint32_t v = 0; v < (o.view_count ? o.view_count : 1) && exit_code == 0; ++v) {
            const drift_camera_view *view = o.view_count ? &o.views[v] : NULL;
            scene->camera = camera;
            if (view) {
                drift_camera_view_apply(view, &scene->camera);
            }
            for (int k = 0; k < o.size_count; ++k) {
                sir_row row = { .scene = short_name(o.scenes[s]),
                                .view = view ? view->name : "camera" };
                r = run_one(ctx, scene, accel, &o, o.widths[k], o.heights[k],
                            o.lambda_path ? lambda : NULL, &row);
                if (r != DRIFT_OK) {
                    fprintf(stderr, "drift bench sir: %s failed: %s\n", o.scenes[s],
                            drift_result_string(r));
                    exit_code = 1;
                    break;
                }
                if (o.json) {
                    print_json_row(&row, first, o.lambda_path != NULL);
                } else {
                    print_text_row(&row, o.lambda_path != NULL);
                }
                first = false;
                fflush(stdout);
            }
        }
        drift_accel_destroy(accel);
        drift_scene_destroy(scene);
    }
    if (o.json) {
        printf("]}\n");
    }
    drift_context_destroy(ctx);
    return exit_code;
}
