// drift bench redit: the cost of reflection editing (thesis §7.6; docs/reflection-editing.md).
//   (a) Mpixel/s of the edit field e(q) = R_a(q) r(q) over the reflective pixels of the scene's
//       view, for 1 -> 32 constraints placed on them (the thesis: 24.5 -> 18.5 Mpixel/s on a
//       GTX 260): the least of --frames runs each, on --threads threads (default 1);
//   (b) the milliseconds of a hybrid frame with sharp reflections, unedited and edited with
//       the most constraints of (a) (the least of --frames frames, after a warm-up frame).
#include "bench.h"
#include "cli.h"
#include "drift/hybrid.h"
#include "drift/reflect_edit.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_COUNTS 16

typedef struct redit_options {
    const char *scene_path[1];
    long width, height, frames, threads;
    long counts[MAX_COUNTS];
    int count_count;
    bool json;
} redit_options;

static bool parse_counts(const char *cmd, const char *flag, const char *value, void *field)
{
    redit_options *o = field;
    return bench_parse_list(cmd, flag, value, 1, DRIFT_EDIT_MAX_CONSTRAINTS, MAX_COUNTS, o->counts,
                            &o->count_count);
}

#define O redit_options
static const cli_option redit_table[] = {
    CLI_SECTION("options:", 0),
    CLI_INT("--width", "W", O, width, 1, 8192, "image width (default 320)"),
    CLI_INT("--height", "H", O, height, 1, 8192, "image height (default 240)"),
    CLI_CUSTOM_ALL("--constraints", "LIST", parse_counts,
                   "constraint counts (default 1,2,4,8,16,32)"),
    CLI_INT("--frames", "N", O, frames, 1, 1000, "the least of N runs per figure (default 5)"),
    BENCH_OPTION_THREADS(O),
    BENCH_OPTION_JSON(O),
};
#undef O

static const cli_command redit_command = {
    .name = "bench redit",
    .usage = "usage: drift bench redit [SCENE] [options]\n\n"
             "(a) Mpixel/s of the reflection-edit field over the reflective pixels of SCENE's\n"
             "    view (default scenes/edit-teapot) against the number of constraints, (b) ms of\n"
             "    a hybrid frame with sharp reflections, unedited and edited.\n\n",
    CLI_TABLE(redit_table),
    CLI_POSITIONAL("SCENE", redit_options, scene_path, 1),
    .help_column = 22,
};

// The G-buffer of the view: surfaces (reflective ones kept) and their reflections r(q).
typedef struct reflective_pixels {
    drift_edit_point *points;
    drift_vec3 *r;
    size_t count;
} reflective_pixels;

static bool gather_pixels(const cli_session *s, int32_t width, int32_t height,
                          reflective_pixels *out)
{
    size_t pixels = (size_t)width * (size_t)height;
    out->points = malloc(pixels * sizeof(drift_edit_point));
    out->r = malloc(pixels * sizeof(drift_vec3));
    out->count = 0;
    if (!out->points || !out->r) {
        return false;
    }
    drift_camera_frame frame = drift_camera_frame_make(&s->scene->camera, width, height);
    frame.camera.aperture_radius = 0.0f;
    for (int32_t y = 0; y < height; ++y) {
        for (int32_t x = 0; x < width; ++x) {
            drift_ray ray = drift_camera_frame_ray(&frame, (float)x + 0.5f, (float)y + 0.5f,
                                                   drift_vec2_make(0.5f, 0.5f));
            drift_hit hit;
            if (!drift_accel_intersect(s->accel, &ray, &hit) || hit.mesh == DRIFT_INVALID_INDEX) {
                continue;
            }
            drift_surface surf = drift_scene_surface(s->scene, &ray, &hit);
            if (surf.material == DRIFT_INVALID_INDEX ||
                drift_vec3_is_zero(s->scene->materials[surf.material].specular)) {
                continue;
            }
            out->points[out->count] = drift_edit_point_from_surface(&surf);
            out->r[out->count] = drift_vec3_reflect(drift_vec3_neg(ray.dir), surf.ns);
            out->count++;
        }
    }
    return out->count > 0;
}

// N constraints on pixels spread over the reflective ones, each leaning its ray a little.
static drift_result make_edits(const cli_session *s, const reflective_pixels *px, long n,
                               drift_reflection_edits **out)
{
    drift_result r = drift_reflection_edits_create(s->ctx, s->scene, s->accel, out);
    for (long i = 0; i < n && r == DRIFT_OK; ++i) {
        size_t k = (size_t)((double)(i + 0.5) / (double)n * (double)px->count) % px->count;
        // A golden-ratio walk over the pixels (not a row) so the constraints spread in 2-D.
        k = (size_t)fmod((double)k * 0.618033988749895 * 7.0, (double)px->count);
        const drift_edit_point *p = &px->points[k];
        float a = 2.0f * DRIFT_PI * (float)i * 0.618034f;
        drift_vec3 lean = drift_vec3_make(0.15f * cosf(a), 0.1f, 0.15f * sinf(a));
        drift_vec3 e = drift_vec3_normalize(drift_vec3_add(px->r[k], lean));
        drift_reflection_constraint c = { .mesh = p->mesh,
                                          .point = p->position,
                                          .target = drift_vec3_fma(p->position, e, 1.0f),
                                          .view = s->scene->camera.position };
        r = drift_reflection_edits_add_constraint(*out, &c);
    }
    return r == DRIFT_OK ? drift_reflection_edits_commit(*out) : r;
}

typedef struct field_job {
    const drift_reflection_edits *edits;
    const reflective_pixels *px;
    float *sink; // per chunk: keeps the work from being optimised away
} field_job;

static void field_range(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    field_job *job = user;
    float sum = 0.0f;
    for (size_t i = begin; i < end; ++i) {
        sum += drift_reflection_edits_direction(job->edits, &job->px->points[i], job->px->r[i]).x;
    }
    job->sink[begin / 1024] = sum;
}

static double time_field(const cli_session *s, const drift_reflection_edits *edits,
                         const reflective_pixels *px, long frames, float *sink)
{
    field_job job = { edits, px, sink };
    double best = HUGE_VAL;
    for (long f = 0; f < frames; ++f) {
        double t = drift_time_now();
        drift_parallel_for(s->ctx, px->count, 1024, field_range, &job);
        best = fmin(best, drift_time_now() - t);
    }
    return best;
}

static drift_result time_frame(const cli_session *s, int32_t width, int32_t height,
                               const drift_reflection_edits *edits, long frames, double *out_ms)
{
    drift_hybrid_params params = { .width = width,
                                   .height = height,
                                   .reflections = DRIFT_REFLECTIONS_SHARP,
                                   .reflection_edits = edits };
    drift_hybrid *frame = NULL;
    drift_result r = drift_hybrid_create(s->ctx, s->scene, s->accel, &params, &frame);
    *out_ms = HUGE_VAL;
    for (long f = 0; f <= frames && r == DRIFT_OK; ++f) {
        r = drift_hybrid_render(frame, &s->scene->camera, NULL);
        if (f > 0) { // the first frame warms the caches
            *out_ms = fmin(*out_ms, drift_hybrid_get_stats(frame).frame_ms);
        }
    }
    drift_hybrid_destroy(frame);
    return r;
}

int drift_bench_redit(int argc, char **argv)
{
    redit_options o = { .width = 320,
                        .height = 240,
                        .frames = 5,
                        .threads = 1,
                        .counts = { 1, 2, 4, 8, 16, 32 },
                        .count_count = 6 };
    int status = cli_parse(&redit_command, argc, argv, &o, NULL);
    if (status != CLI_PARSED) {
        return cli_parse_exit(status);
    }
    cli_session session;
    if (!bench_open(&session, "bench redit", o.scene_path[0], "scenes/edit-teapot/edit_teapot.json",
                    o.threads)) {
        cli_session_close(&session);
        return 1;
    }
    int32_t width = (int32_t)o.width, height = (int32_t)o.height;
    reflective_pixels px = { 0 };
    double field_s[MAX_COUNTS];
    double plain_ms = 0.0, edited_ms = 0.0;
    int exit_code = 1;
    float *sink = NULL;
    drift_reflection_edits *last = NULL;
    if (!gather_pixels(&session, width, height, &px)) {
        fprintf(stderr, "drift bench redit: no reflective pixels in the view\n");
        goto done;
    }
    sink = calloc(px.count / 1024 + 1, sizeof(float));
    if (!sink) {
        goto done;
    }
    drift_result r = DRIFT_OK;
    for (int i = 0; i < o.count_count && r == DRIFT_OK; ++i) {
        drift_reflection_edits_destroy(last);
        last = NULL;
        r = make_edits(&session, &px, o.counts[i], &last);
        if (r == DRIFT_OK) {
            field_s[i] = time_field(&session, last, &px, o.frames, sink);
        }
    }
    if (r == DRIFT_OK) {
        r = time_frame(&session, width, height, NULL, o.frames, &plain_ms);
    }
    if (r == DRIFT_OK) {
        r = time_frame(&session, width, height, last, o.frames, &edited_ms);
    }
    if (r != DRIFT_OK) {
        fprintf(stderr, "drift bench redit: %s\n", drift_result_string(r));
        goto done;
    }
    int threads = drift_context_thread_count(session.ctx);
    if (o.json) {
        cJSON *root = cJSON_CreateObject();
        cJSON_AddStringToObject(root, "scene", session.scene_path);
        cJSON_AddNumberToObject(root, "width", width);
        cJSON_AddNumberToObject(root, "height", height);
        cJSON_AddNumberToObject(root, "threads", threads);
        cli_json_count(root, "reflective_pixels", px.count);
        cJSON *rows = cJSON_AddArrayToObject(root, "field");
        for (int i = 0; i < o.count_count; ++i) {
            cJSON *row = cJSON_CreateObject();
            cJSON_AddNumberToObject(row, "constraints", (double)o.counts[i]);
            cli_json_number(row, "ms", 1e3 * field_s[i], 3);
            cli_json_number(row, "mpixel_per_s", (double)px.count / field_s[i] * 1e-6, 3);
            cJSON_AddItemToArray(rows, row);
        }
        cli_json_number(root, "frame_ms_unedited", plain_ms, 3);
        cli_json_number(root, "frame_ms_edited", edited_ms, 3);
        if (!cli_json_write("bench redit", root, NULL)) {
            goto done;
        }
    } else {
        printf("drift bench redit: %s, %dx%d, %zu reflective pixels, %d thread%s\n",
               session.scene_path, width, height, px.count, threads, threads == 1 ? "" : "s");
        printf("(a) edit field e(q)\n    constraints        ms   Mpixel/s\n");
        for (int i = 0; i < o.count_count; ++i) {
            printf("    %11ld %9.3f %10.3f\n", o.counts[i], 1e3 * field_s[i],
                   (double)px.count / field_s[i] * 1e-6);
        }
        printf("(b) hybrid frame, sharp reflections: unedited %.2f ms, edited (%ld constraints) "
               "%.2f ms\n",
               plain_ms, o.counts[o.count_count - 1], edited_ms);
    }
    exit_code = 0;

done:
    drift_reflection_edits_destroy(last);
    free(sink);
    free(px.points);
    free(px.r);
    cli_session_close(&session);
    return exit_code;
}
