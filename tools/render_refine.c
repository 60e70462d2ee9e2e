// drift render --mode hybrid --refine sir: Smart Image Refinement of the hybrid frame. Parses
// the refine options, runs iterations of `--budget` samples until the image is refined or
// an iteration/time limit, and writes the refined image (EXR + PNG), every plane of the frame
// and of the refiner with --aov, and the refinement's figures with --stats.
#include "cli.h"
#include "render.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "drift/image_io.h"
#include "drift/refine.h"

bool render_parse_refine_option(int argc, char **argv, int *i, render_options *o, bool *ok)
{
    static const char *const names[] = { "--refine",     "--budget",     "--refine-iterations",
                                         "--refine-time", "--refine-spp", "--lambda",
                                         "--refine-all" };
    const char *a = argv[*i];
    int which = -1;
    for (int k = 0; k < (int)(sizeof names / sizeof *names); ++k) {
        which = strcmp(a, names[k]) == 0 ? k : which;
    }
    if (which < 0) {
        return false;
    }
    render_refine_options *r = &o->refine;
    if (!o->hybrid_option) {
        o->hybrid_option = a; // refinement needs the hybrid frame
    }
    if (which != 0 && !r->first_option) {
        r->first_option = a;
    }
    if (which == 6) {
        r->all = true;
        return true;
    }
    const char *v = cli_next_value("render", argc, argv, i);
    if (!v) {
        *ok = false;
        return true;
    }
    switch (which) {
    case 0:
        if (strcmp(v, "sir") != 0) {
            fprintf(stderr, "drift render: --refine expects 'sir', got '%s'\n", v);
            *ok = false;
        }
        r->enabled = true;
        break;
    case 1:
        *ok = cli_parse_int("render", a, v, 1, 1L << 30, &r->budget);
        break;
    case 2:
        *ok = cli_parse_int("render", a, v, 1, 1L << 30, &r->iterations);
        break;
    case 3:
        *ok = cli_parse_float("render", a, v, 1e-6, 1e9, &r->seconds);
        break;
    case 4:
        *ok = cli_parse_int("render", a, v, 1, 65536, &r->spp);
        break;
    case 5:
        r->lambda_path = v;
        break;
    default:
        break;
    }
    return true;
}

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

static drift_result write_aov(drift_context *ctx, const char *path, const drift_hybrid *frame,
                              const drift_refine *sir)
{
    const char *name;
    const drift_image *image;
    uint32_t hybrid_count = 0, refine_count = 0;
    while (drift_hybrid_plane(frame, hybrid_count, &name, &image)) {
        ++hybrid_count;
    }
    while (drift_refine_plane(sir, refine_count, &name, &image)) {
        ++refine_count;
    }
    drift_image_layer *layers = calloc(hybrid_count + refine_count, sizeof *layers);
    if (!layers) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    for (uint32_t i = 0; i < refine_count; ++i) {
        drift_refine_plane(sir, i, &layers[i].name, &layers[i].image);
    }
    for (uint32_t i = 0; i < hybrid_count; ++i) {
        drift_hybrid_plane(frame, i, &layers[refine_count + i].name, &layers[refine_count + i].image);
    }
    drift_result r = drift_image_save_exr(ctx, path, layers, hybrid_count + refine_count);
    free(layers);
    return r;
}

static drift_result write_stats(const render_options *o, const char *scene_path,
                                const drift_hybrid *frame, const drift_refine *sir,
                                double refine_ms)
{
    char tmp[4096];
    snprintf(tmp, sizeof tmp, "%s.tmp%ld", o->stats_path, (long)getpid());
    FILE *f = fopen(tmp, "w");
    if (!f) {
        fprintf(stderr, "drift render: cannot write %s\n", o->stats_path);
        return DRIFT_ERR_IO;
    }
    drift_hybrid_params p = drift_hybrid_get_params(frame);
    drift_refine_stats s = drift_refine_get_stats(sir);
    uint64_t pixels = (uint64_t)p.width * (uint64_t)p.height;
    fprintf(f, "{\n  \"scene\": \"%s\",\n  \"mode\": \"hybrid\",\n  \"refine\": \"sir\",\n", scene_path);
    fprintf(f, "  \"width\": %d,\n  \"height\": %d,\n  \"raster_ms\": %.3f,\n", p.width, p.height,
            drift_hybrid_get_stats(frame).frame_ms);
    fprintf(f, "  \"error_pixels\": %llu,\n  \"error_percent\": %.4f,\n",
            (unsigned long long)s.error_pixels, 100.0 * (double)s.error_pixels / (double)pixels);
    fprintf(f, "  \"requested\": %llu,\n  \"refined\": %llu,\n  \"done\": %s,\n",
            (unsigned long long)s.requested, (unsigned long long)s.refined,
            drift_refine_done(sir) ? "true" : "false");
    fprintf(f, "  \"iterations\": %u,\n  \"samples\": %llu,\n  \"rays\": %llu,\n", s.iterations,
            (unsigned long long)s.samples, (unsigned long long)s.rays);
    fprintf(f, "  \"milliseconds\": { \"metrics\": %.3f, \"sort\": %.3f, \"trace\": %.3f, "
               "\"refine\": %.3f }\n}\n",
            s.metrics_ms, s.sort_ms, s.trace_ms, refine_ms);
    bool ok = fclose(f) == 0;
    if (!ok || rename(tmp, o->stats_path) != 0) {
        remove(tmp);
        fprintf(stderr, "drift render: cannot write %s\n", o->stats_path);
        return DRIFT_ERR_IO;
    }
    return DRIFT_OK;
}

int render_refine_run(drift_context *ctx, const render_options *o, drift_hybrid *frame,
                      const char *scene_path)
{
    const render_refine_options *ro = &o->refine;
    drift_refine_params params = { .budget = (uint32_t)ro->budget,
                                   .spp = (uint32_t)ro->spp,
                                   .refine_zero_error = ro->all,
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
        if (ro->iterations > 0 && drift_refine_get_stats(sir).iterations >= (uint32_t)ro->iterations) {
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
    const drift_image *image = drift_refine_image(sir);
    drift_result w = drift_image_save_exr(ctx, o->out_path, &(drift_image_layer){ NULL, image }, 1);
    char png[4096];
    render_png_path(o->out_path, png, sizeof png);
    if (w == DRIFT_OK) {
        w = drift_image_save_png(
            ctx, png, image,
            &(drift_tonemap_params){ .exposure_stops = (float)o->exposure, .op = o->tonemap });
    }
    if (w == DRIFT_OK && o->aov_path) {
        w = write_aov(ctx, o->aov_path, frame, sir);
    }
    if (w == DRIFT_OK && o->stats_path) {
        w = write_stats(o, scene_path, frame, sir, refine_ms);
    }
    if (w != DRIFT_OK) {
        fprintf(stderr, "drift render: cannot write the outputs: %s\n", drift_result_string(w));
        goto done;
    }
    drift_refine_stats s = drift_refine_get_stats(sir);
    drift_hybrid_params p = drift_hybrid_get_params(frame);
    double percent = 100.0 * (double)s.error_pixels / ((double)p.width * (double)p.height);
    printf("wrote %s and %s (hybrid + sir, %dx%d): %llu error pixels (%.2f%%), %llu/%llu "
           "refined in %u iterations, %llu samples, %llu rays, raster %.1f ms, refine %.1f ms\n",
           o->out_path, png, p.width, p.height, (unsigned long long)s.error_pixels, percent,
           (unsigned long long)s.refined, (unsigned long long)s.requested, s.iterations,
           (unsigned long long)s.samples, (unsigned long long)s.rays,
           drift_hybrid_get_stats(frame).frame_ms, refine_ms);
    exit_code = r == DRIFT_ERR_CANCELLED ? 130 : 0;
done:
    drift_refine_destroy(sir);
    return exit_code;
}
