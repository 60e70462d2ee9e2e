// drift render --mode hybrid: one hybrid frame with a technique per effect, written as EXR
// and PNG, with every plane (--aov FILE.exr) and per-pass milliseconds and rays (--stats).
#include "cli.h"
#include "render.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "drift/accel.h"
#include "drift/image_io.h"
#include "drift/scene_io.h"

static bool parse_vec3(const char *flag, const char *v, drift_vec3 *out)
{
    float a, b, c;
    char tail;
    int n = sscanf(v, "%f,%f,%f%c", &a, &b, &c, &tail);
    if (n == 1) {
        b = c = a; // one value: grey
    }
    if ((n != 1 && n != 3) || !drift_vec3_is_finite(drift_vec3_make(a, b, c))) {
        fprintf(stderr, "drift render: %s expects X,Y,Z (or one number), got '%s'\n", flag, v);
        return false;
    }
    *out = drift_vec3_make(a, b, c);
    return true;
}

// ISG sample counts are k x k grids on the disk: 9, 25, 49, 81 (any square up to 1024).
static bool parse_isg_count(const char *flag, const char *v, int32_t *out)
{
    long n = 0;
    if (!cli_parse_int("render", flag, v, 1, 1024, &n)) {
        return false;
    }
    long k = 1;
    while (k * k < n) {
        ++k;
    }
    if (k * k != n) {
        fprintf(stderr, "drift render: %s expects a perfect square (9, 25, 49, 81, ...), got '%s'\n",
                flag, v);
        return false;
    }
    *out = (int32_t)n;
    return true;
}

bool render_parse_hybrid_option(int argc, char **argv, int *i, render_options *o, bool *ok)
{
    static const char *const effects[DRIFT_EFFECT_COUNT] = { "--shadows", "--reflections",
                                                             "--dof", "--indirect" };
    static const char *const others[] = { "--light-samples", "--shadow-map-size", "--pcf-kernel",
                                          "--envmap-size",   "--probe",           "--ambient",
                                          "--aperture",      "--focus-distance",
                                          "--isg-search",    "--isg-gather",      "--isg-sigma",
                                          "--blur-radius",   "--isg-layers",      "--isg-range",
                                          "--aaf-max-spp",   "--aaf-sampling",    "--aaf-filter",
                                          "--aaf-sampler" };
    if (render_parse_refine_option(argc, argv, i, o, ok)) {
        return true; // --refine sir and its options (tools/render_refine.c)
    }
    const char *a = argv[*i];
    int effect = -1, other = -1;
    for (int k = 0; k < DRIFT_EFFECT_COUNT; ++k) {
        effect = strcmp(a, effects[k]) == 0 ? k : effect;
    }
    for (int k = 0; k < (int)(sizeof others / sizeof *others); ++k) {
        other = strcmp(a, others[k]) == 0 ? k : other;
    }
    if (effect < 0 && other < 0) {
        return false;
    }
    if (!o->hybrid_option) {
        o->hybrid_option = a;
    }
    const char *v = cli_next_value("render", argc, argv, i);
    if (!v) {
        *ok = false;
        return true;
    }
    drift_hybrid_params *h = &o->hybrid;
    long n = 0;
    int t = 0;
    if (effect >= 0) {
        *ok = cli_parse_technique("render", (drift_effect)effect, a, v, &t);
        drift_hybrid_params_set_technique(h, (drift_effect)effect, t);
        return true;
    }
    switch (other) {
    case 0:
        *ok = cli_parse_int("render", a, v, 1, 4096, &n);
        h->light_samples = (uint32_t)n;
        break;
    case 1:
        *ok = cli_parse_int("render", a, v, 1, 8192, &n);
        h->shadow_map_size = (int32_t)n;
        break;
    case 2:
        *ok = cli_parse_int("render", a, v, 1, 63, &n);
        h->pcf_kernel = (int32_t)n;
        break;
    case 3:
        *ok = cli_parse_int("render", a, v, 1, 4096, &n);
        h->envmap_size = (int32_t)n;
        break;
    case 4:
        if (strcmp(v, "object") == 0) {
            h->probe_per_object = true;
        } else {
            *ok = parse_vec3(a, v, &h->probe);
            h->has_probe = true;
        }
        break;
    case 5:
        *ok = parse_vec3(a, v, &h->ambient);
        h->has_ambient = true;
        break;
    case 6:
        *ok = cli_parse_float("render", a, v, 0.0, 1e30, &o->aperture);
        break;
    case 7:
        *ok = cli_parse_float("render", a, v, 1e-30, 1e30, &o->focus_distance);
        break;
    case 8:
    case 9:
        *ok = parse_isg_count(a, v, other == 8 ? &h->isg_search : &h->isg_gather);
        break;
    case 10:
    case 11: {
        double value = 0.0;
        *ok = cli_parse_float("render", a, v, 1e-30, other == 10 ? 1e30 : 1024.0, &value);
        *(other == 10 ? &h->isg_sigma : &h->blur_radius) = (float)value;
        break;
    }
    case 12:
        *ok = cli_parse_int("render", a, v, 1, 2, &n);
        h->isg_layers = (int32_t)n;
        break;
    case 13:
        *ok = strcmp(v, "full") == 0 || strcmp(v, "plane") == 0;
        h->isg_range_plane = strcmp(v, "plane") == 0;
        if (!*ok) {
            fprintf(stderr, "drift render: %s expects full or plane, got '%s'\n", a, v);
        }
        break;
    case 14:
        *ok = cli_parse_int("render", a, v, 1, 65536, &n);
        h->aaf_max_spp = (uint32_t)n;
        break;
    case 15:
        *ok = strcmp(v, "adaptive") == 0 || strcmp(v, "uniform") == 0;
        h->aaf_uniform = strcmp(v, "uniform") == 0;
        if (!*ok) {
            fprintf(stderr, "drift render: --aaf-sampling expects adaptive or uniform, got '%s'\n", v);
        }
        break;
    case 16:
        *ok = strcmp(v, "on") == 0 || strcmp(v, "off") == 0;
        h->aaf_unfiltered = strcmp(v, "off") == 0;
        if (!*ok) {
            fprintf(stderr, "drift render: --aaf-filter expects on or off, got '%s'\n", v);
        }
        break;
    case 17:
        *ok = strcmp(v, "sobol") == 0 || strcmp(v, "random") == 0;
        h->aaf_random = strcmp(v, "random") == 0;
        if (!*ok) {
            fprintf(stderr, "drift render: --aaf-sampler expects sobol or random, got '%s'\n", v);
        }
        break;
    default:
        break;
    }
    return true;
}

static drift_result write_stats(const render_options *o, const char *scene_path,
                                const drift_hybrid *frame, double ms_load, double ms_accel,
                                double ms_total, int threads)
{
    char tmp[4096];
    snprintf(tmp, sizeof tmp, "%s.tmp%ld", o->stats_path, (long)getpid());
    FILE *f = fopen(tmp, "w");
    if (!f) {
        fprintf(stderr, "drift render: cannot write %s\n", o->stats_path);
        return DRIFT_ERR_IO;
    }
    drift_hybrid_params p = drift_hybrid_get_params(frame);
    drift_hybrid_stats s = drift_hybrid_get_stats(frame);
    fprintf(f, "{\n  \"scene\": \"%s\",\n  \"mode\": \"hybrid\",\n  \"width\": %d,\n  \"height\": %d,\n",
            scene_path, p.width, p.height);
    fprintf(f, "  \"techniques\": { \"shadows\": \"%s\", \"reflections\": \"%s\", \"dof\": \"%s\", "
               "\"indirect\": \"%s\" },\n",
            drift_technique_name(DRIFT_EFFECT_SHADOWS, p.shadows),
            drift_technique_name(DRIFT_EFFECT_REFLECTIONS, p.reflections),
            drift_technique_name(DRIFT_EFFECT_DOF, p.dof),
            drift_technique_name(DRIFT_EFFECT_INDIRECT, p.indirect));
    fprintf(f, "  \"spp\": %u,\n  \"seed\": %u,\n  \"max_depth\": %d,\n  \"threads\": %d,\n",
            p.spp, p.seed, p.max_depth, threads);
    uint64_t total_rays = 0;
    fprintf(f, "  \"passes\": {\n");
    for (int k = 0; k < DRIFT_PASS_COUNT; ++k) {
        total_rays += s.rays[k];
        fprintf(f, "    \"%s\": { \"ms\": %.3f, \"rays\": %llu }%s\n",
                drift_hybrid_pass_name((drift_hybrid_pass)k), s.ms[k],
                (unsigned long long)s.rays[k], k + 1 < DRIFT_PASS_COUNT ? "," : "");
    }
    fprintf(f, "  },\n  \"rays\": %llu,\n", (unsigned long long)total_rays);
    fprintf(f, "  \"milliseconds\": { \"load\": %.3f, \"accel\": %.3f, \"frame\": %.3f, "
               "\"total\": %.3f }\n}\n",
            ms_load, ms_accel, s.frame_ms, ms_total);
    bool ok = fclose(f) == 0;
    if (!ok || rename(tmp, o->stats_path) != 0) {
        remove(tmp);
        fprintf(stderr, "drift render: cannot write %s\n", o->stats_path);
        return DRIFT_ERR_IO;
    }
    return DRIFT_OK;
}

static drift_result write_aov(drift_context *ctx, const char *path, const drift_hybrid *frame)
{
    const char *name;
    const drift_image *image;
    uint32_t count = 0;
    while (drift_hybrid_plane(frame, count, &name, &image)) {
        ++count;
    }
    drift_image_layer *layers = calloc(count, sizeof *layers);
    if (!layers) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    for (uint32_t i = 0; i < count; ++i) {
        drift_hybrid_plane(frame, i, &layers[i].name, &layers[i].image);
    }
    drift_result r = drift_image_save_exr(ctx, path, layers, count);
    free(layers);
    return r;
}

static drift_result write_outputs(drift_context *ctx, const render_options *o,
                                  const drift_hybrid *frame)
{
    const drift_image *final = drift_hybrid_image(frame);
    drift_result r = drift_image_save_exr(ctx, o->out_path, &(drift_image_layer){ NULL, final }, 1);
    if (r == DRIFT_OK) {
        char png[4096];
        render_png_path(o->out_path, png, sizeof png);
        r = drift_image_save_png(
            ctx, png, final,
            &(drift_tonemap_params){ .exposure_stops = (float)o->exposure, .op = o->tonemap });
    }
    if (r == DRIFT_OK && o->aov_path) {
        r = write_aov(ctx, o->aov_path, frame);
    }
    if (r != DRIFT_OK) {
        fprintf(stderr, "drift render: cannot write the images: %s\n", drift_result_string(r));
    }
    return r;
}

int render_hybrid(const render_options *o)
{
    if (!render_refine_validate(o)) {
        return 2;
    }
    double t_start = drift_time_now();
    drift_context *ctx = cli_open_context("render", (int)o->threads, o->verbose);
    if (!ctx) {
        return 1;
    }
    drift_result r = DRIFT_OK;
    const char *scene_path = o->scene_path ? o->scene_path : cli_default_scene_path();
    drift_scene *scene = NULL;
    drift_accel *accel = NULL;
    drift_hybrid *frame = NULL;
    int exit_code = 1;
    double t_loaded = 0.0;
    if (!cli_open_scene(ctx, "render", scene_path, &scene, &accel, &t_loaded)) {
        goto done;
    }
    double t_accel = drift_time_now();
    if (o->aperture >= 0.0) {
        scene->camera.aperture_radius = (float)o->aperture;
    }
    if (o->focus_distance > 0.0) {
        scene->camera.focus_distance = (float)o->focus_distance;
    }
    drift_hybrid_params params = o->hybrid;
    params.width = (int32_t)o->width;
    params.height = (int32_t)o->height;
    params.seed = (uint32_t)o->seed;
    params.spp = (uint32_t)o->spp;
    params.max_depth = (int32_t)o->max_depth;
    r = drift_hybrid_create(ctx, scene, accel, &params, &frame);
    if (r != DRIFT_OK) {
        fprintf(stderr, "drift render: %s\n", drift_result_string(r));
        exit_code = r == DRIFT_ERR_INVALID_ARGUMENT ? 2 : 1;
        goto done;
    }
    params = drift_hybrid_get_params(frame);
    if (!o->quiet) {
        fprintf(stderr, "drift render: hybrid frame of %s, %dx%d, shadows %s, reflections %s, "
                        "dof %s, indirect %s, %d threads\n",
                scene_path, params.width, params.height,
                drift_technique_name(DRIFT_EFFECT_SHADOWS, params.shadows),
                drift_technique_name(DRIFT_EFFECT_REFLECTIONS, params.reflections),
                drift_technique_name(DRIFT_EFFECT_DOF, params.dof),
                drift_technique_name(DRIFT_EFFECT_INDIRECT, params.indirect),
                drift_context_thread_count(ctx));
        if (params.dof == DRIFT_DOF_REFERENCE) {
            fprintf(stderr, "drift render: --dof reference path-traces every enabled effect "
                            "through the lens at %u spp\n", params.spp);
        }
    }
    r = drift_hybrid_render(frame, &scene->camera, render_catch_sigint());
    if (r == DRIFT_ERR_CANCELLED) {
        fprintf(stderr, "drift render: interrupted; a hybrid frame is all or nothing, nothing "
                        "written\n");
        exit_code = 130;
        goto done;
    }
    if (r != DRIFT_OK) {
        fprintf(stderr, "drift render: the hybrid frame failed: %s\n", drift_result_string(r));
        goto done;
    }
    if (o->refine.enabled) {
        exit_code = render_refine_run(ctx, o, frame, scene_path);
        goto done;
    }
    if (write_outputs(ctx, o, frame) != DRIFT_OK) {
        goto done;
    }
    double t_done = drift_time_now();
    if (o->stats_path && write_stats(o, scene_path, frame, 1e3 * (t_loaded - t_start),
                                     1e3 * (t_accel - t_loaded), 1e3 * (t_done - t_start),
                                     drift_context_thread_count(ctx)) != DRIFT_OK) {
        goto done;
    }
    if (!o->quiet) {
        drift_hybrid_stats s = drift_hybrid_get_stats(frame);
        for (int k = 0; k < DRIFT_PASS_COUNT; ++k) {
            if (s.ms[k] > 0.0) {
                fprintf(stderr, "  %-14s %9.2f ms %12llu rays\n",
                        drift_hybrid_pass_name((drift_hybrid_pass)k), s.ms[k],
                        (unsigned long long)s.rays[k]);
            }
        }
    }
    char png[4096];
    render_png_path(o->out_path, png, sizeof png);
    printf("wrote %s and %s (hybrid, %dx%d) in %.2f s (frame %.1f ms)\n", o->out_path, png,
           params.width, params.height, t_done - t_start, drift_hybrid_get_stats(frame).frame_ms);
    exit_code = 0;
done:
    drift_hybrid_destroy(frame);
    drift_accel_destroy(accel);
    drift_scene_destroy(scene);
    drift_context_destroy(ctx);
    return exit_code;
}
