// drift render --mode hybrid --refine sir: Smart Image Refinement of the hybrid frame. Checks
// the refine options (tools/cmd_render.c's table reads them), runs iterations of `--budget` samples
// until the image is refined or an iteration/time limit, and writes the refined image (EXR + PNG),
// every plane of the frame and of the refiner with --aov, and the refinement's figures with
// --stats.
#include "cli.h"
#include "drift/image_io.h"
#include "drift/refine.h"
#include "render.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

bool render_refine_validate(const render_options *o)
{
    const render_refine_options *r = &o->refine;
    if (!r->enabled && r->first_option) {
        fprintf(stderr, "drift render: %s needs --refine sir\n", r->first_option);
        return false;
    }
    if (r->iterations > 0 && r->seconds > 0.0) {
        fprintf(stderr, "drift render: give --refine-iterations or --refine-time, not both\n");
        return false;
    }
    if (r->enabled && o->hybrid.dof == DRIFT_DOF_REFERENCE) {
        fprintf(stderr, "drift render: --refine sir refines a rasterized frame; --dof reference "
                        "is already path-traced\n");
        return false;
    }
    return true;
}

static bool write_stats(const render_options *o, const cli_session *session,
                        const drift_hybrid *frame, const drift_refine *sir, double refine_ms,
                        const char *path)
{
    drift_hybrid_params p = drift_hybrid_get_params(frame);
    drift_refine_stats s = drift_refine_get_stats(sir);
    uint64_t pixels = (uint64_t)p.width * (uint64_t)p.height;
    cJSON *root = render_stats_begin(o, session, "hybrid", p.width, p.height);
    cJSON_AddStringToObject(root, "refine", "sir");
    cli_json_number(root, "raster_ms", drift_hybrid_get_stats(frame).frame_ms, 3);
    cli_json_count(root, "error_pixels", s.error_pixels);
    cli_json_number(root, "error_percent", 100.0 * (double)s.error_pixels / (double)pixels, 4);
    cli_json_count(root, "requested", s.requested);
    cli_json_count(root, "refined", s.refined);
    cJSON_AddBoolToObject(root, "done", drift_refine_done(sir));
    cli_json_count(root, "iterations", s.iterations);
    cli_json_count(root, "samples", s.samples);
    cli_json_count(root, "rays", s.rays);
    cli_json_count(root, "metrics_rays", s.metrics_rays);
    cJSON *ms = cJSON_AddObjectToObject(root, "milliseconds");
    cli_json_number(ms, "metrics", s.metrics_ms, 3);
    cli_json_number(ms, "sort", s.sort_ms, 3);
    cli_json_number(ms, "trace", s.trace_ms, 3);
    cli_json_number(ms, "refine", refine_ms, 3);
    return cli_json_write("render", root, path);
}

int render_refine_run(const render_options *o, const cli_session *session, drift_hybrid *frame)
{
    drift_context *ctx = session->ctx;
    const render_refine_options *ro = &o->refine;
    drift_refine_params params = { .budget = (uint32_t)ro->budget,
                                   .spp = (uint32_t)ro->spp,
                                   .refine_zero_error = ro->all,
                                   .components = ro->components,
                                   .seed = (uint32_t)o->seed };
    if (ro->lambda_path) {
        if (drift_refine_lambda_load(ctx, ro->lambda_path, params.lambda) != DRIFT_OK) {
            fprintf(stderr, "drift render: --lambda: cannot use %s\n", ro->lambda_path);
            return 2;
        }
        params.combine = DRIFT_COMBINE_LAMBDA;
    }
    if (drift_hybrid_get_params(frame).indirect != DRIFT_INDIRECT_NONE && !o->quiet) {
        fprintf(stderr, "drift render: note: the SIR ray tracer has no indirect light; refined "
                        "pixels lose the frame's indirect term\n");
    }
    drift_refine *sir = NULL;
    drift_result r = drift_refine_create(ctx, frame, &params, &sir);
    if (r != DRIFT_OK) {
        fprintf(stderr, "drift render: %s\n", drift_result_string(r));
        return r == DRIFT_ERR_INVALID_ARGUMENT ? 2 : 1;
    }
    int exit_code = 1;
    double start = drift_time_now();
    r = drift_refine_begin(sir);
    const atomic_bool *cancel = render_catch_sigint();
    while (r == DRIFT_OK && !drift_refine_done(sir)) {
        if (ro->iterations > 0 &&
            drift_refine_get_stats(sir).iterations >= (uint32_t)ro->iterations) {
            break;
        }
        if (ro->seconds > 0.0 && drift_time_now() - start >= ro->seconds) {
            break;
        }
        r = drift_refine_iterate(sir, cancel);
    }
    double refine_ms = 1000.0 * (drift_time_now() - start);
    if (r == DRIFT_ERR_CANCELLED) {
        fprintf(stderr, "drift render: interrupted; writing the image refined so far\n");
    } else if (r != DRIFT_OK) {
        fprintf(stderr, "drift render: refinement failed: %s\n", drift_result_string(r));
        goto done;
    }
    // --out, its PNG, --aov and --stats: all written, or none.
    render_stage stage = { 0 };
    if (!render_stage_hybrid_images(ctx, o, drift_refine_image(sir), frame, sir, &stage)) {
        goto done;
    }
    if (o->stats_path &&
        !write_stats(o, session, frame, sir, refine_ms, render_stage_add(&stage, o->stats_path))) {
        fprintf(stderr, "drift render: nothing written\n");
        render_stage_abort(&stage);
        goto done;
    }
    if (!render_stage_commit(&stage)) {
        goto done;
    }
    char png[4096];
    render_png_path(o->out_path, png, sizeof png);
    drift_refine_stats s = drift_refine_get_stats(sir);
    drift_hybrid_params p = drift_hybrid_get_params(frame);
    double percent = 100.0 * (double)s.error_pixels / ((double)p.width * (double)p.height);
    printf("wrote %s and %s (hybrid + sir, %dx%d): %llu error pixels (%.2f%%), %llu/%llu "
           "refined in %u iterations, %llu samples, %llu rays, raster %.1f ms, refine %.1f ms\n",
           o->out_path, png, p.width, p.height, (unsigned long long)s.error_pixels, percent,
           (unsigned long long)s.refined, (unsigned long long)s.requested, s.iterations,
           (unsigned long long)s.samples, (unsigned long long)s.rays,
           drift_hybrid_get_stats(frame).frame_ms, refine_ms);
    exit_code = r == DRIFT_ERR_CANCELLED ? render_interrupt_status() : 0;
done:
    drift_refine_destroy(sir);
    return exit_code;
}
