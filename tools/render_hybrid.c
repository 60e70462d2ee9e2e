// drift render --mode hybrid: one hybrid frame with a technique per effect, written as EXR
// and PNG, with every plane (--aov FILE.exr) and per-pass milliseconds and rays (--stats).
#include "cli.h"
#include "drift/image_io.h"
#include "drift/knobs.h"
#include "drift/refine.h"
#include "render.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

// A stage's label: an effect's stage names its technique ("indirect ism").
static void render_stage_label(const drift_hybrid_params *p, const char *stage, char *out,
                               size_t size)
{
    for (int e = 0; e < DRIFT_EFFECT_COUNT; ++e) {
        if (strcmp(stage, drift_effect_name((drift_effect)e)) == 0) {
            snprintf(out, size, "%s %s", stage,
                     drift_technique_name((drift_effect)e,
                                          drift_hybrid_params_technique(p, (drift_effect)e)));
            return;
        }
    }
    snprintf(out, size, "%s", stage);
}

// --temporal on's frames: their count, the wall time of them all (rendering, reuse and still
// refinement), of each (the first holds the techniques' set-up) and the path-traced samples
// the refinement gathered.
typedef struct temporal_stats {
    long frames;
    double ms;
    uint32_t still_samples;
    cJSON *frame_ms;     // an array, handed to the stats object
    cJSON *frame_cpu_ms; // each frame's CPU time, all threads (a loaded machine's fairer clock)
} temporal_stats;

static bool write_stats(const render_options *o, const cli_session *session,
                        const drift_hybrid *frame, const drift_hybrid_stats *first, double t_done,
                        const temporal_stats *temporal, const char *path)
{
    double first_frame_ms = first->frame_ms;
    drift_hybrid_params p = drift_hybrid_get_params(frame);
    drift_hybrid_stats s = drift_hybrid_get_stats(frame);
    cJSON *root = render_stats_begin(o, session, "hybrid", p.width, p.height);
    cJSON *techniques = cJSON_AddObjectToObject(root, "techniques");
    for (int e = 0; e < DRIFT_EFFECT_COUNT; ++e) {
        cJSON_AddStringToObject(techniques, drift_effect_name((drift_effect)e),
                                drift_technique_name((drift_effect)e, drift_hybrid_params_technique(
                                                                          &p, (drift_effect)e)));
    }
    // --spp counts only where a chosen technique path-traces (reference, aaf, ...): a
    // real-time frame takes one sample a pixel ('aa' passes of it).
    bool path_traced = false;
    for (int e = 0; e < DRIFT_EFFECT_COUNT; ++e) {
        path_traced |= drift_technique_path_traced(
            (drift_effect)e, drift_hybrid_params_technique(&p, (drift_effect)e));
    }
    if (path_traced) {
        cli_json_count(root, "spp", p.spp);
    }
    // Every knob of the knob table as the frame resolved it (drift/knobs.h): the options
    // --KNOB VALUE that render this frame again.
    cJSON *knobs = cJSON_AddObjectToObject(root, "knobs");
    for (int k = 0; k < drift_knob_count(); ++k) {
        const drift_knob *knob = drift_knob_get(k);
        double value = drift_knob_value(&p, k);
        char text[64];
        drift_knob_format(knob, value, text, sizeof text);
        if (knob->type == DRIFT_KNOB_CHOICE || strcmp(text, "auto") == 0) {
            cJSON_AddStringToObject(knobs, knob->name, text);
        } else {
            cJSON_AddNumberToObject(knobs, knob->name, value);
        }
    }
    cli_json_count(root, "seed", p.seed);
    cli_json_count(root, "aa", p.aa ? p.aa : 1);
    cJSON_AddNumberToObject(root, "max_depth", p.max_depth);
    cJSON_AddNumberToObject(root, "threads", drift_context_thread_count(session->ctx));
    if (temporal) {
        cJSON *t = cJSON_AddObjectToObject(root, "temporal");
        cli_json_count(t, "frames", (uint64_t)temporal->frames);
        cli_json_number(t, "frames_ms", temporal->ms, 3);
        cli_json_count(t, "still_samples", temporal->still_samples);
        cJSON_AddItemReferenceToObject(t, "frame_ms", temporal->frame_ms);
        cJSON_AddItemReferenceToObject(t, "frame_cpu_ms", temporal->frame_cpu_ms);
    }
    uint64_t total_rays = 0;
    cJSON *passes = cJSON_AddObjectToObject(root, "passes");
    for (int k = 0; k < DRIFT_PASS_COUNT; ++k) {
        total_rays += s.rays[k];
        cJSON *pass = cJSON_AddObjectToObject(passes, drift_hybrid_pass_name((drift_hybrid_pass)k));
        cli_json_number(pass, "ms", s.ms[k], 3);
        cli_json_count(pass, "rays", s.rays[k]);
    }
    cli_json_count(root, "rays", total_rays);
    // Each effect's chosen technique, its own work (without the inputs rows share).
    cJSON *effects = cJSON_AddObjectToObject(root, "effect_ms");
    for (int e = 0; e < DRIFT_EFFECT_COUNT; ++e) {
        cli_json_number(effects, drift_effect_name((drift_effect)e), s.effect_ms[e], 3);
    }
    // The frame's stages: each timed once, none inside another; they add up to the frame.
    cJSON *stages = cJSON_AddObjectToObject(root, "stages");
    const char *stage_name;
    double stage_ms;
    for (uint32_t k = 0; drift_hybrid_stats_stage(&s, k, &stage_name, &stage_ms); ++k) {
        char label[64];
        render_stage_label(&p, stage_name, label, sizeof label);
        cli_json_number(stages, label, stage_ms, 3);
    }
    // What the frame did, as each chosen row's family reports it (its samples and set-up).
    cJSON *counts = cJSON_AddObjectToObject(root, "counts");
    const char *count_name;
    double count_value;
    for (uint32_t k = 0; drift_hybrid_stats_count(&s, k, &count_name, &count_value); ++k) {
        cJSON_AddNumberToObject(counts, count_name, count_value);
    }
    // The first frame by pass and by effect (ISM's points, VPLs and maps are the indirect
    // effect's), and with --frames > 1 what it spent over the warm last frame: the set-up the
    // frame pays once (scene points, shadow maps, probes, techniques' state).
    cJSON *first_frame = cJSON_AddObjectToObject(root, "first_frame");
    cJSON *setup = o->frames > 1 ? cJSON_AddObjectToObject(root, "setup_ms") : NULL;
    const char *groups[] = { "passes", "effect_ms" };
    for (int g = 0; g < 2; ++g) {
        cJSON *firsts = cJSON_AddObjectToObject(first_frame, groups[g]);
        cJSON *extras = setup ? cJSON_AddObjectToObject(setup, groups[g]) : NULL;
        int count = g == 0 ? DRIFT_PASS_COUNT : DRIFT_EFFECT_COUNT;
        for (int k = 0; k < count; ++k) {
            const char *name = g == 0 ? drift_hybrid_pass_name((drift_hybrid_pass)k)
                                      : drift_effect_name((drift_effect)k);
            double at_first = g == 0 ? first->ms[k] : first->effect_ms[k];
            double warm = g == 0 ? s.ms[k] : s.effect_ms[k];
            cli_json_number(firsts, name, at_first, 3);
            if (extras) {
                cli_json_number(extras, name, at_first > warm ? at_first - warm : 0.0, 3);
            }
        }
    }
    if (setup) {
        cli_json_number(setup, "frame", first->frame_ms - s.frame_ms, 3);
    }
    cJSON *ms = cJSON_AddObjectToObject(root, "milliseconds");
    cli_json_number(ms, "load", 1e3 * (session->t_loaded - session->t_start), 3);
    cli_json_number(ms, "accel", 1e3 * (session->t_built - session->t_loaded), 3);
    cli_json_number(ms, "frame", s.frame_ms, 3);
    cli_json_number(ms, "first_frame", first_frame_ms, 3);
    cJSON_AddNumberToObject(root, "frames", (double)o->frames);
    cli_json_number(ms, "total", 1e3 * (t_done - session->t_start), 3);
    return cli_json_write("render", root, path);
}

drift_result render_write_aov(drift_context *ctx, const char *path, const drift_hybrid *frame,
                              const drift_refine *sir, const char *normal_layer)
{
    const char *name;
    const drift_image *image;
    uint32_t hybrid_count = 0, refine_count = 0;
    while (drift_hybrid_plane(frame, hybrid_count, &name, &image)) {
        ++hybrid_count;
    }
    while (sir && drift_refine_plane(sir, refine_count, &name, &image)) {
        ++refine_count;
    }
    uint32_t count = hybrid_count + refine_count;
    drift_image_layer *layers = calloc(count, sizeof *layers);
    const char **channels = calloc(count, sizeof *channels);
    if (!layers || !channels) {
        free(layers);
        free(channels);
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    for (uint32_t i = 0; i < refine_count; ++i) {
        drift_refine_plane(sir, i, &layers[i].name, &layers[i].image);
    }
    for (uint32_t i = 0; i < hybrid_count; ++i) {
        drift_image_layer *l = &layers[refine_count + i];
        drift_hybrid_plane(frame, i, &l->name, &l->image);
        // The G-buffer's depth and normal under the names tev, Nuke and Blender's compositor
        // take as theirs (Z, N.X/N.Y/N.Z or with --aov-normal Normal Blender's Normal.X/Y/Z),
        // as the path tracer's --aov file has them.
        if (strcmp(l->name, "depth") == 0) {
            l->name = NULL;
            channels[refine_count + i] = "Z";
        } else if (strcmp(l->name, "normal") == 0) {
            l->name = normal_layer;
            channels[refine_count + i] = "X,Y,Z";
        }
    }
    drift_result r = drift_image_save_exr_channels(ctx, path, layers, count, channels, NULL, 0);
    free(layers);
    free(channels);
    return r;
}

bool render_stage_hybrid_images(drift_context *ctx, const render_options *o,
                                const drift_image *image, const drift_hybrid *frame,
                                const drift_refine *sir, render_stage *stage)
{
    char png[4096];
    render_png_path(o->out_path, png, sizeof png);
    const char *exr_temp = render_stage_add(stage, o->out_path);
    const char *png_temp = render_stage_add(stage, png);
    const char *aov_temp = render_stage_add(stage, o->aov_path);
    drift_result r = drift_image_save_exr(ctx, exr_temp, &(drift_image_layer){ NULL, image }, 1);
    if (r == DRIFT_OK) {
        r = render_save_png(ctx, o, png_temp, image);
    }
    if (r == DRIFT_OK && aov_temp) {
        r = render_write_aov(ctx, aov_temp, frame, sir, o->aov_normal ? "Normal" : "N");
    }
    if (r != DRIFT_OK) {
        fprintf(stderr, "drift render: cannot write the images: %s; nothing written\n",
                drift_result_string(r));
        render_stage_abort(stage);
        return false;
    }
    return true;
}

int render_hybrid(const render_options *o, const cli_session *session)
{
    drift_context *ctx = session->ctx;
    drift_scene *scene = session->scene;
    const char *scene_path = session->scene_path;
    drift_hybrid *frame = NULL;
    drift_temporal *temporal = NULL;  // --temporal on (--frames: a still camera's sequence)
    drift_still_refine *still = NULL; // and its refinement toward the path tracer
    cJSON *frame_ms = NULL;           // --temporal on: each frame's wall time
    cJSON *frame_cpu_ms = NULL;       // and CPU time
    drift_image guided = { 0 };       // --denoise guided's image
    drift_result r = DRIFT_OK;
    int exit_code = 1;
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
    if (o->max_depth > 0) {
        params.max_depth = (int32_t)o->max_depth;
    }
    r = drift_hybrid_create(ctx, scene, session->accel, &params, &frame);
    if (r != DRIFT_OK) {
        fprintf(stderr, "drift render: %s\n", drift_result_string(r));
        exit_code = r == DRIFT_ERR_INVALID_ARGUMENT ? 2 : 1;
        goto done;
    }
    params = drift_hybrid_get_params(frame);
    if (!o->quiet) {
        char techniques[512] = "";
        for (int e = 0, n = 0; e < DRIFT_EFFECT_COUNT && n < (int)sizeof techniques; ++e) {
            n += snprintf(techniques + n, sizeof techniques - (size_t)n, ", %s %s",
                          drift_effect_name((drift_effect)e),
                          drift_technique_name((drift_effect)e, drift_hybrid_params_technique(
                                                                    &params, (drift_effect)e)));
        }
        fprintf(stderr, "drift render: hybrid frame of %s, %dx%d%s, %d threads\n", scene_path,
                params.width, params.height, techniques, drift_context_thread_count(ctx));
        if (params.dof == DRIFT_DOF_REFERENCE) {
            fprintf(stderr,
                    "drift render: --dof reference path-traces every enabled effect "
                    "through the lens at %u spp\n",
                    params.spp);
        }
    }
    // Frames after the first reuse what the frame keeps (shadow maps, probes, the techniques'
    // state slots): the last frame's stats are the interactive cost.
    // --temporal on: the frames are a still camera's sequence with temporal reuse (the
    // viewer's), and the last frame's accumulated image is written.
    drift_hybrid_stats first = { 0 };
    if (o->temporal) {
        r = drift_temporal_create(ctx, params.width, params.height, &o->temporal_settings,
                                  &temporal);
        if (r == DRIFT_OK && !o->temporal_settings.no_still_refine &&
            drift_still_refine_applies(&params)) {
            r = drift_still_refine_create(
                ctx, scene, session->accel, params.width, params.height,
                &(drift_still_refine_settings){ .seed = (uint32_t)o->seed,
                                                .max_depth = (int32_t)o->max_depth,
                                                .spp = o->temporal_settings.still_spp,
                                                .keeps_hybrid =
                                                    o->temporal_settings.still_keeps_hybrid },
                &still);
        }
    }
    double t_frames = drift_time_now();
    frame_ms = cJSON_CreateArray();
    frame_cpu_ms = cJSON_CreateArray();
    for (long k = 0; k < o->frames && r == DRIFT_OK; ++k) {
        double t_frame = drift_time_now(), cpu_frame = render_cpu_now();
        drift_camera camera = scene->camera;
        // --still-refine progressive: once the camera stands, no more hybrid frames.
        if (!still || drift_still_refine_needs_hybrid(still, &scene->camera)) {
            if (temporal) {
                r = drift_temporal_prepare(frame, (uint32_t)o->seed, (uint32_t)k, &camera);
            }
            r = r == DRIFT_OK ? drift_hybrid_render(frame, &camera, render_catch_sigint()) : r;
            if (r == DRIFT_OK && temporal) {
                r = drift_temporal_apply(temporal, drift_hybrid_gbuffer(frame), &camera,
                                         drift_hybrid_image(frame));
            }
        }
        if (r == DRIFT_OK && still) {
            r = drift_still_refine_apply(still, &scene->camera, drift_temporal_image(temporal),
                                         render_catch_sigint());
        }
        if (k == 0) {
            first = drift_hybrid_get_stats(frame);
        }
        cJSON_AddItemToArray(frame_ms,
                             cJSON_CreateNumber(round(1e6 * (drift_time_now() - t_frame)) / 1e3));
        cJSON_AddItemToArray(frame_cpu_ms,
                             cJSON_CreateNumber(round(1e6 * (render_cpu_now() - cpu_frame)) / 1e3));
    }
    temporal_stats timing = { .frames = o->frames,
                              .ms = 1e3 * (drift_time_now() - t_frames),
                              .still_samples = drift_still_refine_samples(still),
                              .frame_ms = frame_ms,
                              .frame_cpu_ms = frame_cpu_ms };
    if (r == DRIFT_ERR_CANCELLED) {
        fprintf(stderr, "drift render: interrupted; a hybrid frame is all or nothing, nothing "
                        "written\n");
        exit_code = render_interrupt_status();
        goto done;
    }
    if (r != DRIFT_OK) {
        fprintf(stderr, "drift render: the hybrid frame failed: %s\n", drift_result_string(r));
        goto done;
    }
    if (o->refine.enabled) {
        exit_code = render_refine_run(o, session, frame);
        goto done;
    }
    // --out, its PNG, --aov and --stats: all written, or none.
    render_stage stage = { 0 };
    const drift_image *image = still      ? drift_still_refine_image(still)
                               : temporal ? drift_temporal_image(temporal)
                                          : drift_hybrid_image(frame);
    if (o->denoise == 4) { // --denoise guided: the frame guides the path tracer's samples
        r = render_guided_image(o, session, image, drift_hybrid_plane_named(frame, "indirect"),
                                &guided);
        if (r != DRIFT_OK) {
            fprintf(stderr, "drift render: --denoise guided: %s\n", drift_result_string(r));
            goto done;
        }
        image = &guided;
    }
    if (!render_stage_hybrid_images(ctx, o, image, frame, NULL, &stage)) {
        goto done;
    }
    double t_done = drift_time_now();
    if (o->stats_path && !write_stats(o, session, frame, &first, t_done, temporal ? &timing : NULL,
                                      render_stage_add(&stage, o->stats_path))) {
        fprintf(stderr, "drift render: nothing written\n");
        render_stage_abort(&stage);
        goto done;
    }
    if (!render_stage_commit(&stage)) {
        goto done;
    }
    if (!o->quiet) {
        // The frame's stages (they add up to the frame), then the rays of each pass.
        drift_hybrid_stats s = drift_hybrid_get_stats(frame);
        const char *name;
        double ms;
        for (uint32_t k = 0; drift_hybrid_stats_stage(&s, k, &name, &ms); ++k) {
            char label[64];
            render_stage_label(&params, name, label, sizeof label);
            if (ms > 0.0) {
                fprintf(stderr, "  %-22s %9.2f ms\n", label, ms);
            }
        }
        fprintf(stderr, "  %-22s %9.2f ms\n", "frame", s.frame_ms);
        for (int k = 0; k < DRIFT_PASS_COUNT; ++k) {
            if (s.rays[k] > 0) {
                fprintf(stderr, "  %-22s %12llu rays\n",
                        drift_hybrid_pass_name((drift_hybrid_pass)k),
                        (unsigned long long)s.rays[k]);
            }
        }
        // Then what the frame did, family by family.
        double value;
        for (uint32_t k = 0; drift_hybrid_stats_count(&s, k, &name, &value); ++k) {
            fprintf(stderr, "  %-34s %12.6g\n", name, value);
        }
    }
    char png[4096];
    render_png_path(o->out_path, png, sizeof png);
    printf("wrote %s and %s (hybrid, %dx%d) in %.2f s (frame %.1f ms)\n", o->out_path, png,
           params.width, params.height, t_done - session->t_start,
           drift_hybrid_get_stats(frame).frame_ms);
    exit_code = 0;
done:
    drift_image_destroy(ctx, &guided);
    cJSON_Delete(frame_ms);
    cJSON_Delete(frame_cpu_ms);
    drift_still_refine_destroy(still);
    drift_temporal_destroy(temporal);
    drift_hybrid_destroy(frame);
    return exit_code;
}
