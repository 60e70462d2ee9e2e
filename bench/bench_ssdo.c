// drift bench ssdo: SSAO, GTAO and SSDO (docs/ssdo.md) against the path tracer.
//   (a) --table: the thesis's Table 4.1 for our CPU: ms of SSAO, GTAO, SSDO and SSDO+bounce
//       at 1024x768, 1200x960 and 1600x1200 with 8 and 16 samples, the least of --frames
//       runs each, on --threads threads (default 1), and each one's overhead over SSAO
//   (b) quality at --width x --height: FLIP and RMSE of each technique's radiance against the
//       path-traced reference of the same term (drift_ssdo_reference: environment light with
//       visibility plus one diffuse bounce, at --ref-spp), and of the path tracer itself at
//       1 spp and at the spp that fits SSDO+bounce's time, and of SSAO and GTAO at the largest N
//       (24 .. 128) that fits that time (rows ssao-N.., gtao-N..); ssdo+2layers adds the second
//       depth layer (drift_ssdo_peel, its ray time included). --out DIR writes every image as PNG
//       (the same exposure) and the FLIP maps.
// The G-buffer comes from the hybrid frame's primary pass and is not timed: the techniques'
// inputs are the same for all of them. With --threads 1 (the default) times are the calling
// thread's CPU time (it does all the work), which other processes on the machine do not
// inflate; with more threads they are wall time.
#include "bench.h"
#include "drift/hybrid.h"
#include "drift/image_io.h"
#include "drift/metric.h"
#include "drift/scene_io.h"
#include "drift/ssdo.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

typedef struct ssdo_options {
    const char *scene_path;
    const char *out_dir;
    long width, height, samples, ref_spp, threads, frames;
    double radius, exposure;
    bool json, table, no_quality;
} ssdo_options;

#define O ssdo_options
static const cli_option ssdo_table[] = {
    CLI_SECTION("options:", 0),
    CLI_INT("--width", "W", O, width, 8, 8192, "quality size (default 320x240)"),
    CLI_INT("--height", "H", O, height, 8, 8192, "quality size"),
    CLI_INT("--samples", "N", O, samples, 1, 1024, "N of the quality runs (default 16)"),
    CLI_NUMBER("--radius", "R", O, radius, 1e-9, 1e30,
               "r_max in scene units (default 0.05 x the scene diagonal)"),
    CLI_INT("--ref-spp", "N", O, ref_spp, 1, 1 << 20,
            "samples per pixel of the reference (default 256)"),
    CLI_INT("--threads", "T", O, threads, 0, 256, "worker threads of the timed runs (default 1)"),
    CLI_INT("--frames", "N", O, frames, 1, 100, "the least of N runs per timing (default 3)"),
    CLI_FLAG("--table", O, table, "(a): Table 4.1"),
    CLI_FLAG("--no-quality", O, no_quality, "skip (b)"),
    CLI_STRING("--out", "DIR", O, out_dir, "write PNGs of every image and FLIP map there"),
    CLI_NUMBER("--exposure", "S", O, exposure, -30.0, 30.0, "PNG exposure in stops (default 0)"),
    BENCH_OPTION_JSON(O),
};
#undef O

static const cli_command ssdo_command = {
    .name = "bench ssdo",
    .usage = "usage: drift bench ssdo [SCENE] [options]\n\n"
             "(a) --table: ms of ssao, gtao, ssdo, ssdo+bounce at 1024x768, 1200x960, 1600x1200\n"
             "    with 8 and 16 samples (the thesis's Table 4.1), and the overhead over SSAO;\n"
             "(b) FLIP and RMSE against the path-traced reference of the same term (environment\n"
             "    light with visibility + one diffuse bounce) for every technique and the path\n"
             "    tracer at matched time.\n"
             "SCENE defaults to scenes/ssdo-bunny/ssdo_bunny.json (lit by its environment\n"
             "alone).\n\n",
    CLI_TABLE(ssdo_table),
    CLI_POSITIONAL("SCENE", ssdo_options, scene_path, 1),
    .help_column = 19,
};

// CPU seconds of the calling thread. With --threads 1 the calling thread does all the work
// (the pool has no workers), so this is the run's cost even on a machine that other
// processes load, where wall time is not.
static double cpu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

// The figure a run is timed by: thread CPU ms with one thread, else wall ms.
typedef struct run_clock {
    double wall, cpu;
} run_clock;

static run_clock clock_start(void)
{
    return (run_clock){ drift_time_now(), cpu_now() };
}

// --- SHARED STATE ---

typedef struct bench_state {
    const ssdo_options *o;
    drift_context *ctx;   // all cores: G-buffers and references
    drift_context *timed; // --threads: the techniques
    const char *scene_path;
    drift_scene *scene;
    drift_accel *accel;
    drift_ssdo_env *env;
} bench_state;

// Milliseconds since c: thread CPU with one thread, wall otherwise.
static double elapsed_ms(const bench_state *b, run_clock c)
{
    return drift_context_thread_count(b->timed) == 1 ? 1e3 * (cpu_now() - c.cpu)
                                                     : 1e3 * (drift_time_now() - c.wall);
}

typedef struct variant {
    const char *name;
    drift_ssdo_method method;
    bool bounce, multibounce, layers, plain_sum;
    int32_t steps, divide; // --occlusion-steps, and N / divide directions (equal points at 4/4)
} variant;

static const variant variants[] = {
    { "ssao", DRIFT_SSDO_METHOD_SSAO, false, false, false, false, 1, 1 },
    { "gtao", DRIFT_SSDO_METHOD_GTAO, false, false, false, false, 1, 1 },
    { "gtao+mb", DRIFT_SSDO_METHOD_GTAO, false, true, false, false, 1, 1 },
    { "ssdo", DRIFT_SSDO_METHOD_SSDO, false, false, false, false, 1, 1 },
    { "ssdo-plain", DRIFT_SSDO_METHOD_SSDO, false, false, false, true, 1, 1 },
    { "ssdo+bounce", DRIFT_SSDO_METHOD_SSDO, true, false, false, false, 1, 1 },
    { "ssdo-plain+b", DRIFT_SSDO_METHOD_SSDO, true, false, false, true, 1, 1 },
    { "ssdo+2layers", DRIFT_SSDO_METHOD_SSDO, false, false, true, false, 1, 1 },
    { "ssdo+b+2layers", DRIFT_SSDO_METHOD_SSDO, true, false, true, false, 1, 1 },
    // The march to r_max: N/4 directions x 4 steps (as many depth reads as N points), N/2 x 2,
    // and N x 4.
    { "ssdo-s4/4", DRIFT_SSDO_METHOD_SSDO, false, false, false, false, 4, 4 },
    { "ssdo-s4/4+b", DRIFT_SSDO_METHOD_SSDO, true, false, false, false, 4, 4 },
    { "ssdo-s2/2", DRIFT_SSDO_METHOD_SSDO, false, false, false, false, 2, 2 },
    { "ssdo-s4", DRIFT_SSDO_METHOD_SSDO, false, false, false, false, 4, 1 },
};
#define VARIANT_COUNT (sizeof(variants) / sizeof(variants[0]))

// The G-buffer of a w x h hybrid frame (its primary pass; nothing else is used).
static drift_result make_gbuffer(const bench_state *b, int32_t w, int32_t h,
                                 drift_hybrid **out_frame)
{
    drift_hybrid_params p = { .width = w, .height = h, .light_samples = 1 };
    drift_result r = drift_hybrid_create(b->ctx, b->scene, b->accel, &p, out_frame);
    return r ? r : drift_hybrid_render(*out_frame, &b->scene->camera, NULL);
}

static drift_ssdo_params variant_params(const bench_state *b, const variant *v, long samples)
{
    long n = v->divide > 1 ? (samples / v->divide > 0 ? samples / v->divide : 1) : samples;
    return (drift_ssdo_params){ .method = v->method,
                                .samples = (int32_t)n,
                                .steps = v->steps,
                                .radius = (float)b->o->radius,
                                .bounce = v->bounce,
                                .gtao_multibounce = v->multibounce,
                                .plain_sum = v->plain_sum,
                                // GTAO: 2 slices up to N = 16, then 4 steps a side and N / 8 slices
                                .gtao_slices = samples >= 16 ? (int32_t)(samples / 8) : 2 };
}

// The least total ms of --frames renders of one variant into out; with two layers the ms
// include peeling the second layer (into back, the G-buffer's size).
static drift_result time_variant(const bench_state *b, const drift_gbuffer *g, const variant *v,
                                 long samples, drift_image *back, drift_ssdo_output *out,
                                 double *out_ms)
{
    drift_ssdo_params p = variant_params(b, v, samples);
    *out_ms = HUGE_VAL;
    for (long k = 0; k < b->o->frames; ++k) {
        run_clock c = clock_start();
        drift_result r =
            v->layers ? drift_ssdo_peel(b->timed, b->accel, g, &b->scene->camera, back) : DRIFT_OK;
        drift_ssdo_inputs in = { .gbuffer = g,
                                 .camera = &b->scene->camera,
                                 .back_depth = v->layers ? back : NULL };
        r = r ? r : drift_ssdo_render(b->timed, b->env, &in, &p, out);
        if (r != DRIFT_OK) {
            return r;
        }
        *out_ms = fmin(*out_ms, elapsed_ms(b, c));
    }
    return DRIFT_OK;
}

// --- (a) TABLE 4.1 ---

static const int32_t table_sizes[3][2] = { { 1024, 768 }, { 1200, 960 }, { 1600, 1200 } };
static const variant *const table_variants[4] = { &variants[0], &variants[1], &variants[3],
                                                  &variants[5] };

static drift_result run_table(const bench_state *b, double ms[3][2][4])
{
    for (int s = 0; s < 3; ++s) {
        drift_hybrid *frame = NULL;
        drift_result r = make_gbuffer(b, table_sizes[s][0], table_sizes[s][1], &frame);
        drift_ssdo_output out;
        r = r ? r : drift_ssdo_output_create(b->ctx, table_sizes[s][0], table_sizes[s][1], &out);
        for (int n = 0; r == DRIFT_OK && n < 2; ++n) {
            for (int t = 0; r == DRIFT_OK && t < 4; ++t) {
                r = time_variant(b, drift_hybrid_gbuffer(frame), table_variants[t], n ? 16 : 8,
                                 NULL, &out, &ms[s][n][t]);
            }
        }
        drift_ssdo_output_destroy(b->ctx, &out);
        drift_hybrid_destroy(frame);
        if (r != DRIFT_OK) {
            return r;
        }
    }
    return DRIFT_OK;
}

// --- (b) QUALITY ---

typedef struct quality_row {
    char name[32];
    double ms;
    drift_metric_report vs_full;   // against direct + bounce
    drift_metric_report vs_direct; // against the direct term alone
} quality_row;

static void save_png(const bench_state *b, const char *name, const drift_image *img)
{
    if (!b->o->out_dir) {
        return;
    }
    char path[1024];
    snprintf(path, sizeof(path), "%s/%s.png", b->o->out_dir, name);
    drift_image_save_png(b->ctx, path, img,
                         &(drift_tonemap_params){ .exposure_stops = (float)b->o->exposure });
}

static drift_result score(const bench_state *b, const drift_image *ref_full,
                          const drift_image *ref_direct, const drift_image *img, quality_row *row)
{
    drift_image flip_map = { 0 }, heat = { 0 };
    drift_result r = drift_metric_compare(b->ctx, ref_full, img, &(drift_metric_params){ 0 },
                                          &row->vs_full, &flip_map);
    r = r ? r
          : drift_metric_compare(b->ctx, ref_direct, img, &(drift_metric_params){ 0 },
                                 &row->vs_direct, NULL);
    if (r == DRIFT_OK && b->o->out_dir) {
        save_png(b, row->name, img);
        if (drift_metric_flip_heatmap(b->ctx, &flip_map, &heat) == DRIFT_OK) {
            char name[64];
            snprintf(name, sizeof(name), "%s-flip", row->name);
            save_png(b, name, &heat);
        }
    }
    drift_image_destroy(b->ctx, &heat);
    drift_image_destroy(b->ctx, &flip_map);
    return r;
}

static drift_result run_quality(const bench_state *b, quality_row *rows, size_t *out_count)
{
    const ssdo_options *o = b->o;
    int32_t w = (int32_t)o->width, h = (int32_t)o->height;
    drift_image ref_full = { 0 }, ref_direct = { 0 }, back = { 0 };
    drift_hybrid *frame = NULL;
    drift_ssdo_output out = { 0 };
    size_t count = 0;
    drift_result r = drift_ssdo_reference(b->ctx, b->scene, b->accel, &b->scene->camera, w, h,
                                          (uint32_t)o->ref_spp, 1, true, &ref_full);
    r = r ? r
          : drift_ssdo_reference(b->ctx, b->scene, b->accel, &b->scene->camera, w, h,
                                 (uint32_t)o->ref_spp, 1, false, &ref_direct);
    r = r ? r : make_gbuffer(b, w, h, &frame);
    r = r ? r : drift_ssdo_output_create(b->ctx, w, h, &out);
    r = r ? r : drift_image_create(b->ctx, w, h, 1, &back);
    if (r == DRIFT_OK) {
        save_png(b, "reference", &ref_full);
        save_png(b, "reference-direct", &ref_direct);
    }
    double ssdo_bounce_ms = 0.0;
    for (size_t v = 0; r == DRIFT_OK && v < VARIANT_COUNT; ++v) {
        quality_row *row = &rows[count++];
        snprintf(row->name, sizeof(row->name), "%s", variants[v].name);
        r = time_variant(b, drift_hybrid_gbuffer(frame), &variants[v], o->samples, &back, &out,
                         &row->ms);
        r = r ? r : score(b, &ref_full, &ref_direct, &out.radiance, row);
        if (variants[v].bounce && !variants[v].layers && !variants[v].plain_sum) {
            ssdo_bounce_ms = row->ms;
        }
        if (r == DRIFT_OK && o->out_dir) {
            char name[64];
            snprintf(name, sizeof(name), "%s-visibility", variants[v].name);
            save_png(b, name, &out.visibility);
        }
    }
    // Matched time: SSAO and GTAO at the largest N whose time stays within SSDO+bounce's.
    static const long matched_n[] = { 24, 32, 48, 64, 96, 128 };
    for (size_t v = 0; r == DRIFT_OK && v < 2; ++v) {
        long best = 0;
        double best_ms = 0.0;
        for (size_t k = 0; r == DRIFT_OK && k < sizeof(matched_n) / sizeof(matched_n[0]); ++k) {
            double ms;
            r = time_variant(b, drift_hybrid_gbuffer(frame), &variants[v], matched_n[k], &back,
                             &out, &ms);
            if (r != DRIFT_OK || ms > ssdo_bounce_ms) {
                break;
            }
            best = matched_n[k];
            best_ms = ms;
        }
        if (r == DRIFT_OK && best > 0) {
            quality_row *row = &rows[count++];
            snprintf(row->name, sizeof(row->name), "%s-N%ld", variants[v].name, best);
            r = time_variant(b, drift_hybrid_gbuffer(frame), &variants[v], best, &back, &out,
                             &row->ms);
            row->ms = fmin(row->ms, best_ms);
            r = r ? r : score(b, &ref_full, &ref_direct, &out.radiance, row);
        }
    }
    // The path tracer at 1 spp, and at the spp that fits SSDO+bounce's time when that is more.
    uint32_t spp = 1;
    for (int pass = 0; r == DRIFT_OK && pass < 2; ++pass) {
        drift_image pt = { 0 };
        run_clock c = clock_start();
        r = drift_ssdo_reference(b->timed, b->scene, b->accel, &b->scene->camera, w, h, spp, 7,
                                 true, &pt);
        double ms = elapsed_ms(b, c);
        if (r == DRIFT_OK) {
            quality_row *row = &rows[count++];
            snprintf(row->name, sizeof(row->name), "pt-%uspp", spp);
            row->ms = ms;
            r = score(b, &ref_full, &ref_direct, &pt, row);
        }
        drift_image_destroy(b->ctx, &pt);
        uint32_t fit = (uint32_t)(ssdo_bounce_ms / ms);
        if (fit <= 1) {
            break;
        }
        spp = fit;
    }
    drift_ssdo_output_destroy(b->ctx, &out);
    drift_hybrid_destroy(frame);
    drift_image_destroy(b->ctx, &ref_full);
    drift_image_destroy(b->ctx, &ref_direct);
    drift_image_destroy(b->ctx, &back);
    *out_count = count;
    return r;
}

// --- OUTPUT ---

// The results on stdout: a table, or with --json one JSON object (false: it could not be written).
static bool print_results(const bench_state *b, double ms[3][2][4], const quality_row *rows,
                          size_t count)
{
    const ssdo_options *o = b->o;
    if (o->json) {
        int threads = drift_context_thread_count(b->timed);
        cJSON *root = cJSON_CreateObject();
        cJSON_AddStringToObject(root, "scene", b->scene_path);
        cJSON_AddNumberToObject(root, "threads", threads);
        cJSON_AddStringToObject(root, "clock", threads == 1 ? "thread-cpu" : "wall");
        cJSON_AddNumberToObject(root, "frames", (double)o->frames);
        cli_json_float(root, "radius", (float)o->radius); // the techniques take a float
        if (o->table) {
            cJSON *table = cJSON_AddArrayToObject(root, "table");
            for (int s = 0; s < 3; ++s) {
                for (int n = 0; n < 2; ++n) {
                    cJSON *item = cJSON_CreateObject();
                    cJSON_AddItemToArray(table, item);
                    cJSON_AddNumberToObject(item, "width", table_sizes[s][0]);
                    cJSON_AddNumberToObject(item, "height", table_sizes[s][1]);
                    cJSON_AddNumberToObject(item, "samples", n ? 16 : 8);
                    cJSON *times = cJSON_AddObjectToObject(item, "ms");
                    for (int t = 0; t < 4; ++t) {
                        cli_json_number(times, table_variants[t]->name, ms[s][n][t], 3);
                    }
                }
            }
        }
        if (!o->no_quality) {
            cJSON_AddNumberToObject(root, "width", (double)o->width);
            cJSON_AddNumberToObject(root, "height", (double)o->height);
            cJSON_AddNumberToObject(root, "samples", (double)o->samples);
            cJSON_AddNumberToObject(root, "ref_spp", (double)o->ref_spp);
            cJSON *quality = cJSON_AddArrayToObject(root, "quality");
            for (size_t i = 0; i < count; ++i) {
                cJSON *item = cJSON_CreateObject();
                cJSON_AddItemToArray(quality, item);
                cJSON_AddStringToObject(item, "name", rows[i].name);
                cli_json_number(item, "ms", rows[i].ms, 3);
                cli_json_number(item, "flip", rows[i].vs_full.flip, 5);
                cli_json_number(item, "rmse", rows[i].vs_full.rmse, 5);
                cli_json_number(item, "flip_direct", rows[i].vs_direct.flip, 5);
                cli_json_number(item, "rmse_direct", rows[i].vs_direct.rmse, 5);
            }
        }
        return cli_json_write("bench ssdo", root, NULL);
    }
    printf("%s, %d thread(s), r_max %g\n", b->scene_path, drift_context_thread_count(b->timed),
           o->radius);
    if (o->table) {
        printf("\nTable 4.1 (%s ms, least of %ld):\n%-10s %3s %9s %9s %9s %9s %9s %9s %9s\n",
               drift_context_thread_count(b->timed) == 1 ? "CPU" : "wall", o->frames, "size", "N",
               "ssao", "gtao", "ssdo", "+bounce", "gtao/ao", "ssdo/ao", "bnc/ao");
        for (int s = 0; s < 3; ++s) {
            for (int n = 0; n < 2; ++n) {
                const double *m = ms[s][n];
                printf("%4dx%-5d %3d %9.1f %9.1f %9.1f %9.1f %8.1f%% %8.1f%% %8.1f%%\n",
                       table_sizes[s][0], table_sizes[s][1], n ? 16 : 8, m[0], m[1], m[2], m[3],
                       100.0 * (m[1] / m[0] - 1.0), 100.0 * (m[2] / m[0] - 1.0),
                       100.0 * (m[3] / m[0] - 1.0));
            }
        }
    }
    if (!o->no_quality) {
        printf("\nquality at %ldx%ld, N = %ld, reference %ld spp (FLIP, RMSE vs direct + bounce; "
               "vs direct alone)\n%-14s %9s %8s %8s %8s %8s\n",
               o->width, o->height, o->samples, o->ref_spp, "technique", "ms", "FLIP", "RMSE",
               "FLIP-d", "RMSE-d");
        for (size_t i = 0; i < count; ++i) {
            printf("%-14s %9.2f %8.4f %8.4f %8.4f %8.4f\n", rows[i].name, rows[i].ms,
                   rows[i].vs_full.flip, rows[i].vs_full.rmse, rows[i].vs_direct.flip,
                   rows[i].vs_direct.rmse);
        }
    }
    return true;
}

int drift_bench_ssdo(int argc, char **argv)
{
    ssdo_options o = {
        .width = 320, .height = 240, .samples = 16, .ref_spp = 256, .threads = 1, .frames = 3
    };
    int status = cli_parse(&ssdo_command, argc, argv, &o, NULL);
    if (status != CLI_PARSED) {
        return cli_parse_exit(status);
    }
    // G-buffers and references on all cores (the session); the techniques on --threads.
    bench_state b = { .o = &o };
    cli_session session;
    bool ok =
        bench_open(&session, "bench ssdo", o.scene_path, "scenes/ssdo-bunny/ssdo_bunny.json", 0);
    drift_result r = ok ? DRIFT_OK : DRIFT_ERR_INVALID_ARGUMENT;
    b.ctx = session.ctx;
    b.scene = session.scene;
    b.accel = session.accel;
    b.scene_path = session.scene_path;
    r = r ? r
          : drift_context_create(&(drift_context_desc){ .thread_count = (int)o.threads,
                                                        .logger = cli_stderr_logger(false) },
                                 &b.timed);
    if (r == DRIFT_OK && o.radius == 0.0) {
        o.radius = (double)drift_ssdo_params_resolve(NULL, b.scene).radius;
    }
    double t_env = drift_time_now();
    r = r ? r : drift_ssdo_env_create(b.ctx, b.scene, NULL, &b.env);
    t_env = drift_time_now() - t_env;
    double ms[3][2][4] = { { { 0 } } };
    quality_row rows[VARIANT_COUNT + 4];
    size_t count = 0;
    if (r == DRIFT_OK && !o.json) {
        fprintf(stderr, "pre-filtered environment in %.0f ms\n", 1e3 * t_env);
    }
    r = r || !o.table ? r : run_table(&b, ms);
    r = r || o.no_quality ? r : run_quality(&b, rows, &count);
    if (r == DRIFT_OK) {
        ok = print_results(&b, ms, rows, count);
    } else if (ok) { // (when bench_open failed, it has said why)
        fprintf(stderr, "drift bench ssdo: %s\n", drift_result_string(r));
    }
    drift_ssdo_env_destroy(b.env);
    drift_context_destroy(b.timed);
    cli_session_close(&session);
    return r == DRIFT_OK && ok ? 0 : 1;
}
