// drift render --animation A:B: frames A..B of a camera path (--camera-path, or a glTF scene's
// camera animation) and of a glTF scene's node animation (its meshes and lights moved each
// frame, the accel rebuilt and the hybrid frame's per-scene state remade), each written to
// --out's pattern (DIR/frame_%04d.exr and its PNG), with per-frame stats, temporal reuse in
// hybrid mode (--temporal on, drift/temporal.h) and an MP4 through ffmpeg (--video).
#include "cli.h"
#include "drift/accel.h"
#include "drift/camera_path.h"
#include "drift/glare.h"
#include "drift/image_io.h"
#include "drift/scene_io.h"
#include "drift/temporal.h"
#include "frame_pattern.h"
#include "render.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/wait.h>
#include <unistd.h>

bool render_parse_animation(const char *cmd, const char *flag, const char *v, void *field)
{
    render_options *o = field;
    o->animation = frame_range_parse(cmd, flag, v, &o->frame_first, &o->frame_last);
    return o->animation;
}

// A glTF scene file (.gltf, .glb, either .gz): --animation without --camera-path plays its
// camera animation.
static bool is_gltf(const char *path)
{
    size_t n = path ? strlen(path) : 0;
    if (n > 3 && strcmp(path + n - 3, ".gz") == 0) {
        n -= 3;
    }
    return (n > 5 && strncasecmp(path + n - 5, ".gltf", 5) == 0) ||
           (n > 4 && strncasecmp(path + n - 4, ".glb", 4) == 0);
}

bool render_sequence_validate(const render_options *o)
{
    frame_pattern p;
    if (!o->animation) {
        const char *given = o->camera_path  ? "--camera-path"
                            : o->video_path ? "--video"
                            : o->fps > 0.0  ? "--fps"
                                            : NULL;
        if (given) {
            fprintf(stderr, "drift render: %s needs --animation A:B\n", given);
            return false;
        }
        if (o->temporal && o->refine.enabled) {
            // Without --animation, --temporal on reuses across --frames N of a still camera.
            fprintf(stderr, "drift render: --temporal on is for --animation A:B or --frames N; "
                            "--refine refines one frame\n");
            return false;
        }
        return true;
    }
    if (!frame_pattern_find(o->out_path, &p)) {
        fprintf(stderr,
                "drift render: --animation needs --out with one frame number, %%04d or %%d "
                "(e.g. out/frame_%%04d.exr), got '%s'\n",
                o->out_path);
        return false;
    }
    if (!o->camera_path && !is_gltf(o->scene_path)) {
        fprintf(stderr, "drift render: --animation needs --camera-path FILE.json, or a glTF "
                        "scene (.gltf, .glb) whose camera is animated (docs/temporal.md)\n");
        return false;
    }
    if (o->aov_path || o->refine.enabled || o->resume_path || o->debug_sample >= 0) {
        fprintf(stderr, "drift render: --animation renders frames; --aov FILE, --refine, "
                        "--resume and --debug-sample are for one frame\n");
        return false;
    }
    return true;
}

// Encodes the frames' PNGs with ffmpeg when it is installed; a warning otherwise.
static void encode_video(const render_options *o, double fps)
{
    char png_pattern[4096], rate[32], start[32];
    render_png_path(o->out_path, png_pattern, sizeof png_pattern);
    snprintf(rate, sizeof rate, "%g", fps);
    snprintf(start, sizeof start, "%ld", o->frame_first);
    if (system("command -v ffmpeg >/dev/null 2>&1") != 0) {
        fprintf(stderr, "drift render: ffmpeg is not installed: no %s (the frames are written)\n",
                o->video_path);
        return;
    }
    pid_t pid = fork();
    if (pid == 0) {
        char *argv[] = { "ffmpeg",
                         "-loglevel",
                         "error",
                         "-y",
                         "-framerate",
                         rate,
                         "-start_number",
                         start,
                         "-i",
                         png_pattern,
                         "-vf",
                         "pad=ceil(iw/2)*2:ceil(ih/2)*2",
                         "-pix_fmt",
                         "yuv420p",
                         (char *)o->video_path,
                         NULL };
        execvp("ffmpeg", argv);
        _exit(127);
    }
    int status = 0;
    if (pid < 0 || waitpid(pid, &status, 0) < 0 || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        fprintf(stderr, "drift render: ffmpeg could not encode %s\n", o->video_path);
    } else if (!o->quiet) {
        fprintf(stderr, "drift render: wrote %s\n", o->video_path);
    }
}

typedef struct sequence_run {
    const render_options *o;
    cli_session *session;
    drift_camera_path path;
    bool still_camera;           // a glTF whose nodes move but whose camera does not
    drift_scene_animation *anim; // a glTF scene's moving meshes and lights, or NULL
    double fps;
    drift_hybrid *frame;
    drift_temporal *temporal;
    drift_moving_refine *moving; // every frame refines toward reprojected path-traced samples
    drift_still_refine *still;   // a camera that stands refines toward the path tracer
    // --glare static|dynamic: applied here, after the temporal reuse, with the sequence's time
    // step 1 / fps (the hybrid frame's own glare pass steps by the wall clock)
    drift_glare *glare;
    drift_image glared;
    double frame_t0, frame_cpu0; // this frame's start (wall, CPU): its time before writing
    cJSON *stats;                // the --stats object
    cJSON *frames;               // its "frames" array
} sequence_run;

static int finish_frame(sequence_run *s, long k, const drift_camera *camera,
                        const drift_image *image, const char *out_path, cJSON *entry,
                        double temporal_ms);

// One hybrid frame of the sequence: rendered, reused (--temporal) and written.
static int hybrid_frame(sequence_run *s, long k, const drift_camera *camera, const char *out_path,
                        cJSON *entry)
{
    const render_options *o = s->o;
    drift_camera cam = *camera;
    uint32_t index = (uint32_t)(k - o->frame_first);
    // --still-refine progressive: a standing camera's frames go to the path tracer alone.
    if (s->still && !drift_still_refine_needs_hybrid(s->still, camera)) {
        cJSON_AddBoolToObject(entry, "hybrid", false);
        const drift_image *start =
            s->moving ? drift_moving_refine_image(s->moving) : drift_temporal_image(s->temporal);
        return finish_frame(s, k, camera, start, out_path, entry, 0.0);
    }
    if (s->temporal) {
        // A new seed and sub-pixel offset a frame: the history averages independent samples
        // over the pixel's box filter, as the path tracer does (the viewer's set-up).
        cam.film_shift_x = 0.0f;
        cam.film_shift_y = 0.0f;
        uint32_t base = (uint32_t)o->seed + (uint32_t)o->frame_first;
        if (drift_temporal_prepare(s->frame, base, index, &cam) != DRIFT_OK) {
            return 1;
        }
    }
    drift_result r = drift_hybrid_render(s->frame, &cam, render_catch_sigint());
    if (r == DRIFT_ERR_CANCELLED) {
        fprintf(stderr,
                "drift render: interrupted at frame %ld; the frames before it are "
                "written\n",
                k);
        return render_interrupt_status();
    }
    if (r != DRIFT_OK) {
        fprintf(stderr, "drift render: frame %ld failed: %s\n", k, drift_result_string(r));
        return 1;
    }
    const drift_image *image = drift_hybrid_image(s->frame);
    const drift_image *raw = image;
    double temporal_ms = 0.0;
    if (s->temporal) {
        double t0 = drift_time_now();
        r = drift_temporal_apply(s->temporal, drift_hybrid_gbuffer(s->frame), &cam, image);
        temporal_ms = 1e3 * (drift_time_now() - t0);
        if (r != DRIFT_OK) {
            fprintf(stderr, "drift render: temporal reuse failed: %s\n", drift_result_string(r));
            return 1;
        }
        image = drift_temporal_image(s->temporal);
    }
    if (s->moving) {
        // The camera before its jitter (the path tracer jitters its own samples).
        double t0 = drift_time_now();
        r = drift_moving_refine_apply(s->moving, drift_hybrid_gbuffer(s->frame), camera, raw, image,
                                      render_catch_sigint());
        cli_json_number(entry, "moving_refine_ms", 1e3 * (drift_time_now() - t0), 3);
        if (r != DRIFT_OK) {
            fprintf(stderr, "drift render: moving refinement failed: %s\n", drift_result_string(r));
            return r == DRIFT_ERR_CANCELLED ? render_interrupt_status() : 1;
        }
        image = drift_moving_refine_image(s->moving);
    }
    return finish_frame(s, k, camera, image, out_path, entry, temporal_ms);
}

// The rest of a frame: the still refinement, the glare, the files and the stats.
static int finish_frame(sequence_run *s, long k, const drift_camera *camera,
                        const drift_image *image, const char *out_path, cJSON *entry,
                        double temporal_ms)
{
    const render_options *o = s->o;
    drift_context *ctx = s->session->ctx;
    drift_result r = DRIFT_OK;
    if (s->still) {
        // The camera before its jitter: frames where it stands refine (the viewer's).
        r = drift_still_refine_apply(s->still, camera, image, render_catch_sigint());
        if (r != DRIFT_OK) {
            fprintf(stderr, "drift render: still refinement failed: %s\n", drift_result_string(r));
            return r == DRIFT_ERR_CANCELLED ? render_interrupt_status() : 1;
        }
        image = drift_still_refine_image(s->still);
        cJSON_AddNumberToObject(entry, "still_samples", drift_still_refine_samples(s->still));
    }
    if (s->glare) {
        double dt = k > o->frame_first ? 1.0 / s->fps : 0.0;
        r = drift_glare_apply_to(s->glare, image, dt, &s->glared);
        if (r != DRIFT_OK) {
            fprintf(stderr, "drift render: glare failed: %s\n", drift_result_string(r));
            return 1;
        }
        image = &s->glared;
    }
    // The frame's time without writing its files (what the viewer would spend on it).
    cli_json_number(entry, "render_ms", 1e3 * (drift_time_now() - s->frame_t0), 3);
    cli_json_number(entry, "render_cpu_ms", 1e3 * (render_cpu_now() - s->frame_cpu0), 3);
    render_options fo = *o;
    fo.out_path = out_path;
    fo.aov_path = NULL;
    render_stage stage = { 0 };
    if (!render_stage_hybrid_images(ctx, &fo, image, s->frame, NULL, &stage) ||
        !render_stage_commit(&stage)) {
        return 1;
    }
    if (cJSON_IsFalse(cJSON_GetObjectItemCaseSensitive(entry, "hybrid"))) {
        return 0; // no hybrid frame: its stats would be the last one's
    }
    drift_hybrid_stats st = drift_hybrid_get_stats(s->frame);
    cli_json_number(entry, "frame_ms", st.frame_ms, 3);
    cli_json_number(entry, "temporal_ms", temporal_ms, 3);
    uint64_t rays = 0;
    for (int p = 0; p < DRIFT_PASS_COUNT; ++p) {
        rays += st.rays[p];
    }
    cli_json_count(entry, "rays", rays);
    return 0;
}

// Poses the glTF scene's moving meshes and lights at `time`; when they moved, a new accel over
// them and the hybrid frame's per-scene state remade (drift_hybrid_scene_changed).
static int pose_scene(sequence_run *s, long k, double time, cJSON *entry)
{
    cli_session *session = s->session;
    double t0 = drift_time_now();
    bool moved = false;
    drift_result r = drift_scene_animation_pose(s->anim, time, &moved);
    drift_accel *accel = NULL;
    if (r == DRIFT_OK && moved) {
        r = drift_accel_create(session->ctx, session->scene, &(drift_accel_desc){ 0 }, &accel);
        if (r == DRIFT_OK && s->frame) {
            r = drift_hybrid_scene_changed(s->frame, accel);
        }
        if (r == DRIFT_OK) {
            drift_accel_destroy(session->accel);
            session->accel = accel;
        } else {
            drift_accel_destroy(accel);
        }
    }
    if (r == DRIFT_OK && s->frame) {
        // The meshes' moves since the last frame, for the motion vectors (temporal reuse).
        uint32_t n = session->scene->mesh_count;
        float *motion = drift_alloc(session->ctx, sizeof(float) * 12 * ((size_t)n + 1));
        r = motion ? drift_scene_animation_motion(s->anim, motion, n) : DRIFT_ERR_OUT_OF_MEMORY;
        if (r == DRIFT_OK) {
            r = drift_hybrid_set_mesh_motion(s->frame, motion, n);
        }
        drift_free(session->ctx, motion);
    }
    cJSON_AddBoolToObject(entry, "scene_moved", moved);
    cli_json_number(entry, "scene_ms", 1e3 * (drift_time_now() - t0), 3);
    if (r != DRIFT_OK) {
        fprintf(stderr, "drift render: cannot pose the scene at frame %ld: %s\n", k,
                drift_result_string(r));
        return 1;
    }
    return 0;
}

static int run_frames(sequence_run *s)
{
    const render_options *o = s->o;
    drift_scene *scene = s->session->scene;
    drift_camera base = scene->camera;
    if (o->aperture >= 0.0) {
        base.aperture_radius = (float)o->aperture;
    }
    if (o->focus_distance > 0.0) {
        base.focus_distance = (float)o->focus_distance;
    }
    frame_pattern pattern;
    frame_pattern_find(o->out_path, &pattern); // validated
    double total_ms = 0.0;
    for (long k = o->frame_first; k <= o->frame_last; ++k) {
        char out_path[4096];
        frame_pattern_format(o->out_path, &pattern, k, out_path, sizeof out_path);
        double time = (double)k / s->fps;
        drift_camera cam = s->still_camera ? base : drift_camera_path_eval(&s->path, &base, time);
        cJSON *entry = cJSON_CreateObject();
        cJSON_AddItemToArray(s->frames, entry);
        cJSON_AddNumberToObject(entry, "frame", (double)k);
        cli_json_number(entry, "time", time, 6);
        cJSON_AddStringToObject(entry, "out", out_path);
        double t0 = drift_time_now(), cpu0 = render_cpu_now();
        s->frame_t0 = t0;
        s->frame_cpu0 = cpu0;
        int status = s->anim ? pose_scene(s, k, time, entry) : 0;
        if (status != 0) {
            return status;
        }
        if (o->hybrid_mode) {
            status = hybrid_frame(s, k, &cam, out_path, entry);
        } else {
            render_options fo = *o;
            fo.out_path = out_path;
            fo.stats_path = NULL;
            fo.quiet = true;
            scene->camera = cam;
            status = render_reference(&fo, s->session);
            scene->camera = base;
        }
        double ms = 1e3 * (drift_time_now() - t0);
        cli_json_number(entry, "ms", ms, 3);
        cli_json_number(entry, "cpu_ms", 1e3 * (render_cpu_now() - cpu0), 3); // all threads
        total_ms += ms;
        if (status != 0) {
            return status;
        }
        if (!o->quiet) {
            fprintf(stderr, "drift render: frame %ld (t = %.3f s) %.1f ms -> %s\n", k, time, ms,
                    out_path);
        }
    }
    long count = o->frame_last - o->frame_first + 1;
    cli_json_number(s->stats, "mean_frame_ms", total_ms / (double)count, 3);
    return 0;
}

int render_sequence(const render_options *o, cli_session *session)
{
    drift_context *ctx = session->ctx;
    sequence_run s = { .o = o, .session = session };
    int exit_code = 1;
    // A glTF scene's node animation moves its meshes and lights (src/io/scene_gltf_anim_nodes.c).
    if (is_gltf(o->scene_path) &&
        drift_scene_animation_from_gltf(ctx, o->scene_path, session->scene, &s.anim) != DRIFT_OK) {
        fprintf(stderr, "drift render: cannot play the animation of %s\n", o->scene_path);
        return 2;
    }
    if (s.anim && o->temporal) {
        fprintf(stderr, "drift render: warning: --temporal follows moving objects by their "
                        "motion vectors, but light that changes with them (their shadows, "
                        "what they reflect) lags in the history (docs/temporal.md)\n");
    }
    if (!o->camera_path && s.anim && !drift_scene_animation_camera_moves(s.anim)) {
        s.still_camera = true; // objects move, the camera stands
        s.path.fps = o->fps > 0.0 ? o->fps : 24.0;
    } else if (!o->camera_path) {
        // The scene's own glTF camera animation, sampled at each frame (src/io/scene_gltf_anim.c).
        s.fps = o->fps > 0.0 ? o->fps : 24.0;
        if (drift_camera_path_from_gltf(ctx, o->scene_path, NULL, s.fps, o->frame_first,
                                        o->frame_last, &s.path) != DRIFT_OK) {
            fprintf(stderr, "drift render: cannot play the camera animation of %s\n",
                    o->scene_path);
            drift_scene_animation_destroy(s.anim);
            return 2;
        }
    } else if (drift_camera_path_load(ctx, o->camera_path, &s.path) != DRIFT_OK) {
        fprintf(stderr, "drift render: cannot read --camera-path %s\n", o->camera_path);
        drift_scene_animation_destroy(s.anim);
        return 2;
    }
    s.fps = o->fps > 0.0 ? o->fps : s.path.fps;
    s.stats = render_stats_begin(o, session, o->hybrid_mode ? "hybrid" : "reference",
                                 (int)(o->width ? o->width : session->scene->camera.width),
                                 (int)(o->height ? o->height : session->scene->camera.height));
    cJSON_AddStringToObject(s.stats, "camera_path",
                            o->camera_path   ? o->camera_path
                            : s.still_camera ? "still"
                                             : "gltf");
    cJSON_AddNumberToObject(s.stats, "moving_meshes", drift_scene_animation_mesh_count(s.anim));
    cJSON_AddNumberToObject(s.stats, "moving_lights", drift_scene_animation_light_count(s.anim));
    cli_json_number(s.stats, "fps", s.fps, 6);
    cJSON_AddNumberToObject(s.stats, "first_frame", (double)o->frame_first);
    cJSON_AddNumberToObject(s.stats, "last_frame", (double)o->frame_last);
    cJSON_AddNumberToObject(s.stats, "threads", drift_context_thread_count(ctx));
    cJSON_AddBoolToObject(s.stats, "temporal", o->temporal);
    s.frames = cJSON_AddArrayToObject(s.stats, "frames");
    if (o->hybrid_mode) {
        drift_hybrid_params params = o->hybrid;
        params.width = (int32_t)o->width;
        params.height = (int32_t)o->height;
        params.seed = (uint32_t)o->seed;
        params.spp = (uint32_t)o->spp;
        if (o->max_depth > 0) {
            params.max_depth = (int32_t)o->max_depth;
        }
        drift_glare_technique glare = params.glare;
        params.glare = DRIFT_GLARE_NONE; // the sequence's own, below
        drift_result r =
            drift_hybrid_create(ctx, session->scene, session->accel, &params, &s.frame);
        if (r != DRIFT_OK) {
            fprintf(stderr, "drift render: %s\n", drift_result_string(r));
            exit_code = r == DRIFT_ERR_INVALID_ARGUMENT ? 2 : 1;
            goto done;
        }
        params = drift_hybrid_get_params(s.frame);
        if (glare != DRIFT_GLARE_NONE) {
            // The PSF at the camera's angular pitch, as the hybrid frame's glare pass makes it.
            double aspect = (double)params.width / (double)params.height;
            double fov_x = 2.0 * atan(aspect * tan(0.5 * (double)session->scene->camera.fov_y));
            drift_glare_params gp = { .mode = glare == DRIFT_GLARE_DYNAMIC
                                                  ? DRIFT_GLARE_MODE_DYNAMIC
                                                  : DRIFT_GLARE_MODE_STATIC,
                                      .seed = params.seed,
                                      .image_fov = fov_x };
            if ((r = drift_glare_create(ctx, &gp, &s.glare)) != DRIFT_OK ||
                (r = drift_image_create(ctx, params.width, params.height, 3, &s.glared)) !=
                    DRIFT_OK) {
                fprintf(stderr, "drift render: glare: %s\n", drift_result_string(r));
                goto done;
            }
        }
        if (o->temporal &&
            (r = drift_temporal_create(ctx, params.width, params.height, &o->temporal_settings,
                                       &s.temporal)) != DRIFT_OK) {
            fprintf(stderr, "drift render: %s\n", drift_result_string(r));
            exit_code = r == DRIFT_ERR_INVALID_ARGUMENT ? 2 : 1;
            goto done;
        }
        // A moving scene changes under the path tracer's accumulation: no refinement there
        // (the moving refinement reprojects by the camera's and the meshes' motion vectors,
        // but light that changes with the meshes would lag, as the history's does).
        if (o->temporal && o->temporal_settings.moving_refine && !s.anim &&
            drift_still_refine_applies(&params) &&
            (r = drift_moving_refine_create(
                 ctx, session->scene, session->accel, s.temporal,
                 &(drift_moving_refine_settings){
                     .seed = (uint32_t)o->seed + 0x9e3779b9u,
                     .max_depth = (int32_t)o->max_depth,
                     .max_history = o->temporal_settings.moving_refine_history,
                     .residual = o->temporal_settings.moving_refine == 2,
                     .scale = o->temporal_settings.moving_refine_scale,
                     .period = o->temporal_settings.moving_refine_period,
                     .filter_passes = o->temporal_settings.moving_refine_passes },
                 &s.moving)) != DRIFT_OK) {
            fprintf(stderr, "drift render: %s\n", drift_result_string(r));
            goto done;
        }
        if (o->temporal && !o->temporal_settings.no_still_refine && !s.anim &&
            drift_still_refine_applies(&params) &&
            (r = drift_still_refine_create(
                 ctx, session->scene, session->accel, params.width, params.height,
                 &(drift_still_refine_settings){ .seed = (uint32_t)o->seed,
                                                 .max_depth = (int32_t)o->max_depth,
                                                 .spp = o->temporal_settings.still_spp,
                                                 .keeps_hybrid =
                                                     o->temporal_settings.still_keeps_hybrid },
                 &s.still)) != DRIFT_OK) {
            fprintf(stderr, "drift render: %s\n", drift_result_string(r));
            goto done;
        }
    }
    exit_code = run_frames(&s);
    if (exit_code == 0 && o->stats_path) {
        cli_json_number(s.stats, "total_ms", 1e3 * (drift_time_now() - session->t_start), 3);
        exit_code = cli_json_write("render", s.stats, o->stats_path) ? 0 : 1;
        s.stats = NULL; // written (and freed) by cli_json_write
    }
    if (exit_code == 0 && o->video_path) {
        encode_video(o, s.fps);
    }
    if (exit_code == 0) {
        printf("wrote frames %ld to %ld of %s (%s%s)\n", o->frame_first, o->frame_last, o->out_path,
               o->hybrid_mode ? "hybrid" : "reference", o->temporal ? ", temporal" : "");
    }
done:
    cJSON_Delete(s.stats);
    drift_still_refine_destroy(s.still);
    drift_moving_refine_destroy(s.moving);
    drift_temporal_destroy(s.temporal);
    drift_glare_destroy(s.glare);
    drift_image_destroy(ctx, &s.glared);
    drift_hybrid_destroy(s.frame);
    drift_camera_path_free(ctx, &s.path);
    drift_scene_animation_destroy(s.anim);
    return exit_code;
}
