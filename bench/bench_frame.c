// drift bench frame: what a hybrid frame costs against its primary-visibility pass, in one
// run. The target: hard shadows + sharp reflections + post depth of field at 640x480
// on the Cornell box with a glossy bunny cost at most 4x the primary pass.
#include "bench.h"
#include "bench_frame_floors.h"
#include "cli.h"
#include "drift/accel.h"
#include "drift/hybrid.h"
#include "drift/scene_io.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct frame_options {
    const char *scene_path;
    const char *passes; // --passes: the passes --floors times (NULL: all)
    long width, height, frames, threads;
    bool json, floors;
} frame_options;

// The configurations measured; the first is the target frame.
typedef struct frame_config {
    const char *name;
    drift_hybrid_params params;
} frame_config;

#define O frame_options
static const cli_option frame_table[] = {
    CLI_SECTION("options:", 0),
    CLI_INT("--width", "W", O, width, 1, DRIFT_IMAGE_MAX_DIMENSION,
            "frame size (default 640x480; 1920x1080 with --floors)"),
    CLI_INT("--height", "H", O, height, 1, DRIFT_IMAGE_MAX_DIMENSION, "frame size"),
    CLI_INT("--frames", "N", O, frames, 1, 1000,
            "frames per configuration after one warm-up frame (default 5); with --floors, "
            "runs of each pass (the least is kept)"),
    CLI_FLAG("--floors", O, floors,
             "each image pass (compose, post DOF, ISG, a-trous, glare convolution) as a multiple "
             "of its bandwidth floor, the copy bandwidth measured in the same run"),
    CLI_STRING("--passes", "LIST", O, passes,
               "with --floors, time only these passes (comma-separated names as printed, e.g. "
               "'post dof,glare conv'; default all)"),
    BENCH_OPTION_THREADS(O),
    BENCH_OPTION_JSON(O),
};
#undef O

static const cli_command frame_command = {
    .name = "bench frame",
    .usage = "usage: drift bench frame [SCENE] [options]\n\n"
             "Renders hybrid frames and reports the median milliseconds of the primary pass and\n"
             "of the whole frame for several technique sets; the first, hard shadows + sharp\n"
             "reflections + post DOF, is the one the 4x target is about. SCENE defaults to\n"
             "scenes/cornell-bunny/cornell_bunny.json (needs ../shared).\n\n",
    CLI_TABLE(frame_table),
    CLI_POSITIONAL("SCENE", frame_options, scene_path, 1),
};

static int compare_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(double *v, long n)
{
    qsort(v, (size_t)n, sizeof *v, compare_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

typedef struct frame_result {
    double frame_ms;
    double pass_ms[DRIFT_PASS_COUNT]; // the primary pass is pass_ms[DRIFT_PASS_PRIMARY]
} frame_result;

static drift_result measure(drift_context *ctx, const drift_scene *scene, const drift_accel *accel,
                            const frame_options *o, const frame_config *config, frame_result *out)
{
    drift_hybrid_params params = config->params;
    params.width = (int32_t)o->width;
    params.height = (int32_t)o->height;
    drift_hybrid *frame = NULL;
    drift_result r = drift_hybrid_create(ctx, scene, accel, &params, &frame);
    double *total = calloc((size_t)o->frames, sizeof(double));
    double *passes = calloc((size_t)o->frames * DRIFT_PASS_COUNT, sizeof(double));
    if (r == DRIFT_OK && (!total || !passes)) {
        r = DRIFT_ERR_OUT_OF_MEMORY;
    }
    // Frame 0 warms caches and builds the cached maps; frames 1..N are measured.
    for (long k = 0; r == DRIFT_OK && k <= o->frames; ++k) {
        r = drift_hybrid_render(frame, &scene->camera, NULL);
        if (r != DRIFT_OK || k == 0) {
            continue;
        }
        drift_hybrid_stats s = drift_hybrid_get_stats(frame);
        total[k - 1] = s.frame_ms;
        for (int p = 0; p < DRIFT_PASS_COUNT; ++p) {
            passes[(size_t)p * (size_t)o->frames + (size_t)(k - 1)] = s.ms[p];
        }
    }
    if (r == DRIFT_OK) {
        out->frame_ms = median(total, o->frames);
        for (int p = 0; p < DRIFT_PASS_COUNT; ++p) {
            out->pass_ms[p] = median(passes + (size_t)p * (size_t)o->frames, o->frames);
        }
    }
    free(total);
    free(passes);
    drift_hybrid_destroy(frame);
    return r;
}

int drift_bench_frame(int argc, char **argv)
{
    frame_options o = { .frames = 0, .threads = 1 };
    int status = cli_parse(&frame_command, argc, argv, &o, NULL);
    if (status != CLI_PARSED) {
        return cli_parse_exit(status);
    }
    o.width = o.width ? o.width : (o.floors ? 1920 : 640);
    o.height = o.height ? o.height : (o.floors ? 1080 : 480);
    o.frames = o.frames ? o.frames : 5;
    // The documented target first, then every real-time row of the technique table alone
    // (path-traced rows cost what --spp says: drift bench aaf and isg measure those).
    frame_config configs[64] = { { "hard+sharp+post",
                                   { .shadows = DRIFT_SHADOWS_HARD,
                                     .reflections = DRIFT_REFLECTIONS_SHARP,
                                     .dof = DRIFT_DOF_POST } } };
    static char names[64][48];
    int config_count = 1;
    for (int e = 0; e < DRIFT_EFFECT_COUNT; ++e) {
        for (int t = 0; t < drift_technique_count((drift_effect)e) && config_count < 64; ++t) {
            if (drift_technique_path_traced((drift_effect)e, t) || (t == 0 && e != 0)) {
                continue; // path-traced, or another effect's default: the frame of `shadows hard`
            }
            snprintf(names[config_count], sizeof names[config_count], "%s %s",
                     drift_effect_name((drift_effect)e), drift_technique_name((drift_effect)e, t));
            configs[config_count].name = names[config_count];
            drift_hybrid_params_set_technique(&configs[config_count].params, (drift_effect)e, t);
            ++config_count;
        }
    }
    int exit_code = 1;
    cli_session session;
    if (!bench_open(&session, "bench frame", o.scene_path,
                    "scenes/cornell-bunny/cornell_bunny.json", o.threads)) {
        goto done;
    }
    drift_context *ctx = session.ctx;
    const char *scene_path = session.scene_path;
    if (o.floors) {
        exit_code = bench_frame_floors(ctx, session.scene, session.accel, scene_path,
                                       &(bench_floor_options){ .width = o.width,
                                                               .height = o.height,
                                                               .repeats = o.frames,
                                                               .json = o.json,
                                                               .passes = o.passes });
        goto done;
    }
    drift_result r = DRIFT_OK;
    frame_result results[sizeof configs / sizeof *configs];
    memset(results, 0, sizeof results);
    for (int c = 0; c < config_count; ++c) {
        r = measure(ctx, session.scene, session.accel, &o, &configs[c], &results[c]);
        if (r != DRIFT_OK) {
            fprintf(stderr, "drift bench frame: %s failed: %s\n", configs[c].name,
                    drift_result_string(r));
            goto done;
        }
    }
    if (o.json) {
        cJSON *root = cJSON_CreateObject();
        cJSON_AddStringToObject(root, "scene", scene_path);
        cJSON_AddNumberToObject(root, "width", (double)o.width);
        cJSON_AddNumberToObject(root, "height", (double)o.height);
        cJSON_AddNumberToObject(root, "threads", drift_context_thread_count(ctx));
        cJSON_AddNumberToObject(root, "frames", (double)o.frames);
        cJSON *array = cJSON_AddArrayToObject(root, "configs");
        for (int c = 0; c < config_count; ++c) {
            double primary = results[c].pass_ms[DRIFT_PASS_PRIMARY];
            cJSON *item = cJSON_CreateObject();
            cJSON_AddItemToArray(array, item);
            cJSON_AddStringToObject(item, "name", configs[c].name);
            cli_json_number(item, "primary_ms", primary, 3);
            cli_json_number(item, "frame_ms", results[c].frame_ms, 3);
            cli_json_number(item, "ratio", results[c].frame_ms / primary, 3);
            cJSON *passes = cJSON_AddObjectToObject(item, "passes");
            for (int p = 0; p < DRIFT_PASS_COUNT; ++p) {
                cli_json_number(passes, drift_hybrid_pass_name((drift_hybrid_pass)p),
                                results[c].pass_ms[p], 3);
            }
        }
        if (!cli_json_write("bench frame", root, NULL)) {
            goto done;
        }
    } else {
        printf("%s, %ldx%ld, %d thread(s), median of %ld frames\n", scene_path, o.width, o.height,
               drift_context_thread_count(ctx), o.frames);
        printf("%-18s %12s %12s %8s\n", "techniques", "primary ms", "frame ms", "ratio");
        for (int c = 0; c < config_count; ++c) {
            double primary = results[c].pass_ms[DRIFT_PASS_PRIMARY];
            printf("%-18s %12.2f %12.2f %7.2fx\n", configs[c].name, primary, results[c].frame_ms,
                   results[c].frame_ms / primary);
        }
        printf("\npasses of %s (ms):", configs[0].name);
        for (int p = 0; p < DRIFT_PASS_COUNT; ++p) {
            if (results[0].pass_ms[p] > 0.0) {
                printf(" %s %.2f", drift_hybrid_pass_name((drift_hybrid_pass)p),
                       results[0].pass_ms[p]);
            }
        }
        printf("\ntarget: %s frame <= 4x primary: %s\n", configs[0].name,
               results[0].frame_ms <= 4.0 * results[0].pass_ms[DRIFT_PASS_PRIMARY] ? "met"
                                                                                   : "NOT met");
    }
    exit_code = 0;
done:
    cli_session_close(&session);
    return exit_code;
}
