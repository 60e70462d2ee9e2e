// drift refine fit SCENE --out lambda.json: the paper's per-scene pre-process for the linear
// combination of the SIR metrics. Renders several views around the scene camera (raster and
// pure ray tracing), takes the real error |raster - ray traced| of each, and keeps the best of
// `trials` random lambda tuples (the averaged sum is the first candidate).
#include "cli.h"
#include "drift/accel.h"
#include "drift/hybrid.h"
#include "drift/refine.h"
#include "drift/scene.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_VIEWS        32
#define REAL_ERROR_SCALE 0.1f // display-value difference that counts as full error

typedef struct fit_options {
    const char *scene_path, *out_path;
    long views, width, height, spp, trials, threads, seed;
    double degrees;
} fit_options;

#define O fit_options
static const cli_option fit_table[] = {
    CLI_SECTION("options:", 0),
    CLI_STRING("--out", "LAMBDA.json", O, out_path, "where the weights go (required)"),
    CLI_INT("--views", "N", O, views, 1, MAX_VIEWS,
            "views orbiting the camera's target (default 4)"),
    CLI_NUMBER("--degrees", "D", O, degrees, 0.0, 180.0,
               "the orbit spans +-D degrees (default 20)"),
    CLI_INT("--width", "W", O, width, 1, 8192, "view size (default 160x120)"),
    CLI_INT("--height", "H", O, height, 1, 8192, "view size"),
    CLI_INT("--spp", "N", O, spp, 1, 65536, "samples a pixel of the pure ray tracer (default 8)"),
    CLI_INT("--trials", "N", O, trials, 0, 10000000, "random lambda tuples tried (default 2000)"),
    CLI_INT("--threads", "T", O, threads, 0, 256, "worker threads (default: all cores)"),
    CLI_INT("--seed", "S", O, seed, 0, 0xffffffffL, "seed of the views and trials (default 0)"),
};
#undef O

static const cli_command fit_command = {
    .name = "refine fit",
    .usage =
        "usage: drift refine fit [SCENE] --out LAMBDA.json [options]\n\n"
        "Fits the weights lambda of SIR's linear metric combination for one scene (the\n"
        "paper's pre-process): N views orbiting the scene camera's target over +-D degrees,\n"
        "each rendered by the hybrid frame (PCSS, envmap, post DOF) and by the pure ray\n"
        "tracer at --spp, at W x H; the best of --trials random tuples against the real\n"
        "error is written as {\"lambda\": {...}} for `drift render ... --refine sir --lambda`.\n\n",
    CLI_TABLE(fit_table),
    CLI_POSITIONAL("SCENE", fit_options, scene_path, 1),
};

static int parse(int argc, char **argv, fit_options *o)
{
    *o = (fit_options){
        .views = 4, .width = 160, .height = 120, .spp = 8, .trials = 2000, .degrees = 20.0
    };
    int status = cli_parse(&fit_command, argc, argv, o, NULL);
    if (status != CLI_PARSED) {
        return status;
    }
    if (!o->out_path) {
        fprintf(stderr, "drift refine fit: --out LAMBDA.json is required\n");
        return 2;
    }
    return 0;
}

// View k of n: the scene camera turned about its target by an angle spread over +-degrees.
static drift_camera orbit(const drift_camera *camera, long k, long n, double degrees)
{
    double t = n > 1 ? 2.0 * (double)k / (double)(n - 1) - 1.0 : 0.0;
    float angle = (float)(t * degrees * 3.14159265358979323846 / 180.0);
    drift_vec3 d = drift_vec3_sub(camera->position, camera->target);
    drift_vec3 up = drift_vec3_normalize(camera->up);
    // Rodrigues' rotation of d about up.
    drift_vec3 rotated =
        drift_vec3_add(drift_vec3_add(drift_vec3_scale(d, cosf(angle)),
                                      drift_vec3_scale(drift_vec3_cross(up, d), sinf(angle))),
                       drift_vec3_scale(up, drift_vec3_dot(up, d) * (1.0f - cosf(angle))));
    drift_camera c = *camera;
    c.position = drift_vec3_add(camera->target, rotated);
    return c;
}

typedef struct fit_view {
    drift_hybrid *frame;
    drift_refine *sir;
    drift_image pure, real;
} fit_view;

static int fit(const fit_options *o)
{
    fit_view views[MAX_VIEWS] = { 0 };
    drift_refine_view training[MAX_VIEWS];
    int exit_code = 1;
    drift_result r = DRIFT_OK;
    cli_session session;
    if (!cli_session_open(&(cli_session_desc){ .cmd = "refine fit",
                                               .scene_path = o->scene_path,
                                               .threads = (int)o->threads },
                          &session)) {
        goto done;
    }
    drift_context *ctx = session.ctx;
    const drift_scene *scene = session.scene;
    drift_hybrid_params hp = { .width = (int32_t)o->width,
                               .height = (int32_t)o->height,
                               .shadows = DRIFT_SHADOWS_PCSS,
                               .reflections = DRIFT_REFLECTIONS_ENVMAP,
                               .dof = DRIFT_DOF_POST,
                               .seed = (uint32_t)o->seed };
    for (long k = 0; k < o->views; ++k) {
        fit_view *v = &views[k];
        drift_camera camera = orbit(&scene->camera, k, o->views, o->degrees);
        r = drift_hybrid_create(ctx, scene, session.accel, &hp, &v->frame);
        if (r == DRIFT_OK) {
            r = drift_hybrid_render(v->frame, &camera, NULL);
        }
        if (r == DRIFT_OK) {
            r = drift_refine_create(ctx, v->frame,
                                    &(drift_refine_params){ .seed = (uint32_t)o->seed }, &v->sir);
        }
        if (r == DRIFT_OK) {
            r = drift_refine_begin(v->sir);
        }
        if (r == DRIFT_OK) {
            r = drift_image_create(ctx, hp.width, hp.height, 3, &v->pure);
        }
        if (r == DRIFT_OK) {
            r = drift_image_create(ctx, hp.width, hp.height, 1, &v->real);
        }
        if (r == DRIFT_OK) {
            r = drift_refine_render_pure(v->sir, (uint32_t)o->spp, &v->pure, NULL, NULL);
        }
        if (r != DRIFT_OK) {
            fprintf(stderr, "drift refine fit: view %ld failed: %s\n", k, drift_result_string(r));
            goto done;
        }
        drift_refine_real_error(drift_hybrid_image(v->frame), &v->pure, REAL_ERROR_SCALE, &v->real);
        training[k].real_error = &v->real;
        for (int m = 0; m < DRIFT_METRIC_COUNT; ++m) {
            training[k].metrics[m] = drift_refine_metric_image(v->sir, (drift_refine_metric)m);
        }
    }
    float average[DRIFT_METRIC_COUNT], lambda[DRIFT_METRIC_COUNT];
    for (int m = 0; m < DRIFT_METRIC_COUNT; ++m) {
        average[m] = 1.0f / DRIFT_METRIC_COUNT;
    }
    double cost;
    drift_refine_fit_lambda(training, (uint32_t)o->views, (uint32_t)o->trials, (uint32_t)o->seed,
                            lambda, &cost);
    double average_cost = drift_refine_lambda_cost(training, (uint32_t)o->views, average);
    if (drift_refine_lambda_save(ctx, o->out_path, lambda) != DRIFT_OK) {
        goto done;
    }
    printf("wrote %s: mean |E - real| %.5f (averaged sum %.5f) over %ld views of %ldx%ld\n",
           o->out_path, cost, average_cost, o->views, o->width, o->height);
    for (int m = 0; m < DRIFT_METRIC_COUNT; ++m) {
        printf("  %-12s %.4f\n", drift_refine_metric_name((drift_refine_metric)m),
               (double)lambda[m]);
    }
    exit_code = 0;
done:
    for (long k = 0; k < o->views; ++k) {
        drift_image_destroy(session.ctx, &views[k].pure);
        drift_image_destroy(session.ctx, &views[k].real);
        drift_refine_destroy(views[k].sir);
        drift_hybrid_destroy(views[k].frame);
    }
    cli_session_close(&session);
    return exit_code;
}

int drift_cmd_refine(int argc, char **argv)
{
    if (argc < 2 || strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0) {
        cli_print_help(&fit_command, argc < 2 ? stderr : stdout);
        return argc < 2 ? 2 : 0;
    }
    if (strcmp(argv[1], "--help-markdown") == 0) { // docs/reference/cli.md
        cli_print_markdown(&fit_command, stdout);
        return 0;
    }
    if (strcmp(argv[1], "fit") != 0) {
        fprintf(stderr, "drift refine: unknown action '%s' (actions: fit)\n", argv[1]);
        return 2;
    }
    fit_options o;
    int pr = parse(argc - 1, argv + 1, &o);
    if (pr != 0) {
        return cli_parse_exit(pr);
    }
    return fit(&o);
}
