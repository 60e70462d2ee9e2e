// drift bench isg: image space gathering against the paper's Table 1 and against the
// baselines of each effect.
//   (a) timing: milliseconds of the ISG pass at --width x --height (default 1024x768, the
//       paper's) for search x gather in {9, 25, 49, 81}^2, per effect, and the base time
//       (the rest of the frame with ISG on: primary, U_l, the sharp buffers, composition)
//   (b) quality at --qwidth x --qheight: FLIP and RMSE of the final image against the
//       `reference` technique of the same effect at --ref-spp, with every other effect the
//       same in both, for every real-time row of the effect in the technique table (ISG,
//       its blur baselines, the real-time rows), with each technique's own milliseconds (the
//       stage and inputs that technique adds) so the times can be matched; then isg-9x9 (ISG
//       at 9 x 9 samples, its cheapest) for every effect, isg-2layers (with the second depth
//       layer) for depth of field. Depth of field's focused frame has reference (path-traced)
//       shadows so that only depth of field differs from the lens reference.
#include "bench.h"
#include "cli.h"
#include "distributed/sweep.h"
#include "drift/accel.h"
#include "drift/hybrid.h"
#include "drift/metric.h"
#include "drift/scene_io.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct isg_options {
    const char *scene_path;
    long width, height, qwidth, qheight, ref_spp, threads, search, gather, frames;
    double aperture;
    bool json, skip_table, skip_quality;
} isg_options;

#define O isg_options
static const cli_option isg_table[] = {
    CLI_SECTION("options:", 0),
    CLI_INT("--width", "W", O, width, 1, DRIFT_IMAGE_MAX_DIMENSION,
            "timing size (default 1024x768)"),
    CLI_INT("--height", "H", O, height, 1, DRIFT_IMAGE_MAX_DIMENSION, "timing size"),
    CLI_INT("--qwidth", "W", O, qwidth, 1, DRIFT_IMAGE_MAX_DIMENSION,
            "quality size (default 320x240)"),
    CLI_INT("--qheight", "H", O, qheight, 1, DRIFT_IMAGE_MAX_DIMENSION, "quality size"),
    CLI_INT("--ref-spp", "N", O, ref_spp, 1, 1 << 20,
            "samples per pixel of the references (default 256)"),
    CLI_INT("--search", "N", O, search, 1, 1024, "ISG samples of the quality runs (default 25"),
    CLI_INT("--gather", "M", O, gather, 1, 1024, "and 49)"),
    CLI_INT("--frames", "N", O, frames, 1, 100,
            "timing: the least of N frames per cell (default 1)"),
    CLI_NUMBER("--aperture", "A", O, aperture, 0.0, 1e30,
               "lens radius for the DOF runs (default: the scene camera's; when\n"
               "it has none, 1% of the scene diagonal, focused on the surface\n"
               "at the image centre)"),
    BENCH_OPTION_THREADS(O),
    CLI_FLAG("--no-table", O, skip_table, "skip part (a)"),
    CLI_FLAG("--no-quality", O, skip_quality, "skip part (b)"),
    BENCH_OPTION_JSON(O),
};
#undef O

static const cli_command isg_command = {
    .name = "bench isg",
    .usage = "usage: drift bench isg [SCENE] [options]\n\n"
             "(a) ms of the ISG pass for search x gather in {9,25,49,81}^2 per effect, and the\n"
             "    base time of the rest of the frame (the paper's Table 1);\n"
             "(b) FLIP and RMSE against each effect's reference technique for ISG and baselines.\n"
             "SCENE defaults to scenes/cornell-glossy/cornell_glossy.json.\n\n",
    CLI_TABLE(isg_table),
    CLI_POSITIONAL("SCENE", isg_options, scene_path, 1),
};

typedef struct bench_ctx {
    drift_context *ctx;
    drift_scene *scene;
    const drift_accel *accel;
    const isg_options *o;
} bench_ctx;

// Renders one frame of `params` (after one warm-up frame when `warm`), returns its stats.
static drift_result render(const bench_ctx *b, drift_hybrid_params params, bool warm,
                           drift_hybrid_stats *out_stats, drift_image *out_copy)
{
    drift_hybrid *frame = NULL;
    drift_result r = drift_hybrid_create(b->ctx, b->scene, b->accel, &params, &frame);
    for (int k = 0; r == DRIFT_OK && k < (warm ? 2 : 1); ++k) {
        r = drift_hybrid_render(frame, &b->scene->camera, NULL);
    }
    if (r == DRIFT_OK) {
        *out_stats = drift_hybrid_get_stats(frame);
        if (out_copy) {
            const drift_image *img = drift_hybrid_image(frame);
            r = drift_image_create(b->ctx, img->width, img->height, 3, out_copy);
            if (r == DRIFT_OK) {
                memcpy(out_copy->pixels, img->pixels,
                       sizeof(float) * 3 * (size_t)img->width * (size_t)img->height);
            }
        }
    }
    drift_hybrid_destroy(frame);
    return r;
}

static const int counts[4] = { 9, 25, 49, 81 };

static drift_hybrid_params effect_params(drift_effect effect, int technique)
{
    drift_hybrid_params p = { .shadows = DRIFT_SHADOWS_HARD };
    if (effect == DRIFT_EFFECT_DOF) {
        p.shadows =
            DRIFT_SHADOWS_REFERENCE; // only the depth of field differs from the lens reference
    }
    drift_hybrid_params_set_technique(&p, effect, technique);
    return p;
}

static int isg_technique(drift_effect effect)
{
    return drift_technique_parse(effect, "isg");
}

// (a) The paper's Table 1 for one effect: rows gather, columns search. Its 16 cells are sweep
// items first .. first + 15, over the ranks under mpirun (sweep.h): this rank's cells into
// cells (the ISG pass's ms, the rest of the frame's), gathered by timing_collect.
static drift_result timing_render(const bench_ctx *b, drift_effect effect, int first,
                                  double cells[16][2])
{
    const isg_options *o = b->o;
    drift_hybrid_params p = effect_params(effect, isg_technique(effect));
    if (effect == DRIFT_EFFECT_DOF) {
        p.shadows = DRIFT_SHADOWS_HARD; // timing only: no path tracing
    }
    p.width = (int32_t)o->width;
    p.height = (int32_t)o->height;
    drift_result r = DRIFT_OK;
    for (int c = 0; c < 16 && r == DRIFT_OK; ++c) {
        if (!sweep_mine(first + c)) {
            continue;
        }
        p.isg.search = counts[c % 4];
        p.isg.gather = counts[c / 4];
        // The least of N frames: other processes on the machine only ever add time.
        cells[c][0] = cells[c][1] = HUGE_VAL;
        for (long k = 0; k < o->frames && r == DRIFT_OK; ++k) {
            drift_hybrid_stats st;
            r = render(b, p, false, &st, NULL);
            if (r == DRIFT_OK) {
                cells[c][0] = fmin(cells[c][0], st.ms[DRIFT_PASS_ISG]);
                cells[c][1] = fmin(cells[c][1], st.frame_ms - st.ms[DRIFT_PASS_ISG]);
            }
        }
    }
    return r;
}

static bool timing_collect(int first, double cells[16][2], bool ok, double table[4][4],
                           double *out_base)
{
    if (!sweep_gather(cells, sizeof cells[0], first, 16, ok)) {
        return false;
    }
    *out_base = HUGE_VAL;
    for (int c = 0; c < 16; ++c) {
        table[c / 4][c % 4] = cells[c][0];
        *out_base = fmin(*out_base, cells[c][1]);
    }
    return true;
}

// The milliseconds a technique of an effect adds to the frame: its row's stage (its pass, and
// D's sum after a shadow row) and the shared inputs only rows of that effect ask for (the
// hard-shadow buffer and the shadow maps; the sharp mirror rays and the probes).
static double technique_ms(drift_effect effect, const drift_hybrid_stats *s)
{
    double ms = s->effect_ms[effect];
    if (effect == DRIFT_EFFECT_SHADOWS) {
        ms += s->ms[DRIFT_PASS_HARD_SHADOWS] + s->ms[DRIFT_PASS_SHADOW_MAPS];
    } else if (effect == DRIFT_EFFECT_REFLECTIONS) {
        ms += s->ms[DRIFT_PASS_REFLECTIONS] + s->ms[DRIFT_PASS_ENVMAP];
    }
    return ms;
}

typedef struct quality_row {
    const char *technique;
    double flip, rmse, ms;
} quality_row;

#define MAX_ROWS 12

// A row of (b): a technique of the effect, or one of ISG's variants.
typedef enum quality_variant {
    QUALITY_PLAIN,  // the technique at the bench's settings
    QUALITY_CHEAP,  // "isg-9x9": ISG at its cheapest sample counts, the time-matched variant
    QUALITY_LAYERS, // "isg-2layers": ISG's depth of field with the second depth layer
} quality_variant;

typedef struct quality_entry {
    const char *name;
    int technique;
    quality_variant variant;
} quality_entry;

// (b)'s rows for an effect, from the technique table: every real-time row of the effect (the
// path-traced ones are the reference's kind: drift bench aaf measures those), then ISG's
// variants. The same list on every rank.
static int quality_entries(drift_effect effect, quality_entry out[MAX_ROWS])
{
    int n = 0;
    for (int t = 0; t < drift_technique_count(effect) && n < MAX_ROWS; ++t) {
        if (!drift_technique_path_traced(effect, t)) {
            out[n++] = (quality_entry){ drift_technique_name(effect, t), t, QUALITY_PLAIN };
        }
    }
    int isg = isg_technique(effect);
    if (n < MAX_ROWS) {
        out[n++] = (quality_entry){ "isg-9x9", isg, QUALITY_CHEAP };
    }
    if (effect == DRIFT_EFFECT_DOF && n < MAX_ROWS) {
        out[n++] = (quality_entry){ "isg-2layers", isg, QUALITY_LAYERS };
    }
    return n;
}

// (b) for one effect: the reference, then every technique against it. Under mpirun the
// reference is rendered by one rank (effect ordinal mod N) while the others render the
// techniques' frames (quality_render); quality_compare then shares the reference with every
// rank, each compares its own frames, and rank 0 gathers the rows.
typedef struct quality_run {
    int ref_owner, count;
    quality_entry entries[MAX_ROWS];
    int owners[MAX_ROWS];
    drift_image reference, tests[MAX_ROWS];
    double ms[MAX_ROWS];
} quality_run;

static drift_result quality_render(const bench_ctx *b, drift_effect effect, int ordinal,
                                   quality_run *q)
{
    const isg_options *o = b->o;
    q->ref_owner = ordinal % sweep_ranks();
    q->count = quality_entries(effect, q->entries);
    for (int t = 0; t < q->count; ++t) {
        q->owners[t] = sweep_owner_besides(q->ref_owner, t);
    }
    drift_hybrid_params ref = effect_params(effect, drift_technique_parse(effect, "reference"));
    ref.width = (int32_t)o->qwidth;
    ref.height = (int32_t)o->qheight;
    ref.spp = (uint32_t)o->ref_spp;
    drift_hybrid_stats st = { 0 };
    drift_result r = DRIFT_OK;
    if (q->ref_owner == sweep_rank()) {
        r = render(b, ref, false, &st, &q->reference);
    }
    for (int t = 0; r == DRIFT_OK && t < q->count; ++t) {
        if (q->owners[t] != sweep_rank()) {
            continue;
        }
        bool cheap = q->entries[t].variant == QUALITY_CHEAP;
        bool layers = q->entries[t].variant == QUALITY_LAYERS;
        drift_hybrid_params p = effect_params(effect, q->entries[t].technique);
        p.isg.layers = layers ? 2 : 1;
        p.width = ref.width;
        p.height = ref.height;
        p.spp = ref.spp; // the DOF runs' path-traced shadows
        p.isg.search = cheap ? 9 : (int32_t)o->search;
        p.isg.gather = cheap ? 9 : (int32_t)o->gather;
        // Warm for timing (shadow maps and probes are cached), except around path tracing.
        r = render(b, p, effect != DRIFT_EFFECT_DOF, &st, &q->tests[t]);
        q->ms[t] = r == DRIFT_OK ? technique_ms(effect, &st) : 0.0;
    }
    return r;
}

static bool quality_compare(const bench_ctx *b, quality_run *q, bool ok, quality_row *rows,
                            int *out_count)
{
    int32_t dims[3] = { q->reference.width, q->reference.height, q->reference.channels };
    ok = sweep_share(dims, sizeof dims, q->ref_owner, ok);
    if (ok && q->ref_owner != sweep_rank()) {
        ok = drift_image_create(b->ctx, dims[0], dims[1], dims[2], &q->reference) == DRIFT_OK;
    }
    size_t bytes = sizeof(float) * (size_t)dims[0] * (size_t)dims[1] * (size_t)dims[2];
    ok = sweep_share(q->reference.pixels, ok ? bytes : 0, q->ref_owner, ok);
    for (int t = 0; ok && t < q->count; ++t) {
        if (q->owners[t] != sweep_rank()) {
            continue;
        }
        drift_metric_report rep;
        ok = drift_metric_compare(b->ctx, &q->reference, &q->tests[t], &(drift_metric_params){ 0 },
                                  &rep, NULL) == DRIFT_OK;
        rows[t] = (quality_row){ NULL, rep.flip, rep.rmse, q->ms[t] };
    }
    drift_image_destroy(b->ctx, &q->reference);
    for (int t = 0; t < MAX_ROWS; ++t) {
        drift_image_destroy(b->ctx, &q->tests[t]);
    }
    *out_count = 0;
    if (!sweep_gather_owned(rows, sizeof *rows, q->count, q->owners, ok)) {
        return false;
    }
    for (int t = 0; t < q->count; ++t) { // names here: a pointer from another rank means nothing
        rows[t].technique = q->entries[t].name;
    }
    *out_count = q->count;
    return true;
}

static const drift_effect effects[3] = { DRIFT_EFFECT_SHADOWS, DRIFT_EFFECT_REFLECTIONS,
                                         DRIFT_EFFECT_DOF };

static bool print_json(const bench_ctx *b, double tables[3][4][4], const double base[3],
                       quality_row rows[3][MAX_ROWS], const int row_count[3], const char *path)
{
    const isg_options *o = b->o;
    cJSON *root = cJSON_CreateObject();
    cJSON_AddStringToObject(root, "scene", path);
    cJSON_AddNumberToObject(root, "threads", drift_context_thread_count(b->ctx));
    const char *const keys[] = { "frames",  "width",   "height", "qwidth",
                                 "qheight", "ref_spp", "search", "gather" };
    const long values[] = { o->frames,  o->width,   o->height, o->qwidth,
                            o->qheight, o->ref_spp, o->search, o->gather };
    for (size_t k = 0; k < sizeof keys / sizeof *keys; ++k) {
        cJSON_AddNumberToObject(root, keys[k], (double)values[k]);
    }
    cJSON *by_effect = cJSON_AddObjectToObject(root, "effects");
    for (int e = 0; e < 3; ++e) {
        cJSON *effect = cJSON_AddObjectToObject(by_effect, drift_effect_name(effects[e]));
        if (!o->skip_table) {
            cli_json_number(effect, "base_ms", base[e], 3);
            cJSON *isg = cJSON_AddArrayToObject(effect, "isg_ms");
            for (int g = 0; g < 4; ++g) {
                cJSON *row = cJSON_CreateObject();
                cJSON_AddItemToArray(isg, row);
                cJSON_AddNumberToObject(row, "gather", counts[g]);
                cJSON *ms = cJSON_AddArrayToObject(row, "search_ms");
                for (int s = 0; s < 4; ++s) {
                    cJSON_AddItemToArray(ms,
                                         cJSON_CreateNumber(round(tables[e][g][s] * 1e3) / 1e3));
                }
            }
        }
        if (!o->skip_quality) {
            cJSON *quality = cJSON_AddArrayToObject(effect, "quality");
            for (int t = 0; t < row_count[e]; ++t) {
                cJSON *row = cJSON_CreateObject();
                cJSON_AddItemToArray(quality, row);
                cJSON_AddStringToObject(row, "technique", rows[e][t].technique);
                cli_json_number(row, "flip", rows[e][t].flip, 5);
                cli_json_number(row, "rmse", rows[e][t].rmse, 5);
                cli_json_number(row, "ms", rows[e][t].ms, 3);
            }
        }
    }
    return cli_json_write("bench isg", root, NULL);
}

static void print_text(const bench_ctx *b, double tables[3][4][4], const double base[3],
                       quality_row rows[3][MAX_ROWS], const int row_count[3], const char *path)
{
    const isg_options *o = b->o;
    int threads = drift_context_thread_count(b->ctx);
    printf("%s, %d thread(s)\n", path, threads);
    for (int e = 0; e < 3; ++e) {
        printf("\n== %s ==\n", drift_effect_name(effects[e]));
        if (!o->skip_table) {
            printf("ISG pass ms at %ldx%ld, rows gather, columns search (base %.1f ms)\n", o->width,
                   o->height, base[e]);
            printf("%8s %9d %9d %9d %9d\n", "", 9, 25, 49, 81);
            for (int g = 0; g < 4; ++g) {
                printf("%8d %9.1f %9.1f %9.1f %9.1f\n", counts[g], tables[e][g][0], tables[e][g][1],
                       tables[e][g][2], tables[e][g][3]);
            }
        }
        if (!o->skip_quality) {
            printf("quality at %ldx%ld vs reference at %ld spp (isg %ld x %ld)\n", o->qwidth,
                   o->qheight, o->ref_spp, o->search, o->gather);
            printf("%-10s %9s %9s %9s\n", "technique", "FLIP", "RMSE", "ms");
            for (int t = 0; t < row_count[e]; ++t) {
                printf("%-10s %9.4f %9.4f %9.1f\n", rows[e][t].technique, rows[e][t].flip,
                       rows[e][t].rmse, rows[e][t].ms);
            }
        }
    }
}

int drift_bench_isg(int argc, char **argv)
{
    isg_options o = { .width = 1024,
                      .height = 768,
                      .qwidth = 320,
                      .qheight = 240,
                      .ref_spp = 256,
                      .threads = 1,
                      .search = 25,
                      .gather = 49,
                      .frames = 1,
                      .aperture = -1.0 };
    int status = cli_parse(&isg_command, argc, argv, &o, NULL);
    if (status != CLI_PARSED) {
        return cli_parse_exit(status);
    }
    int exit_code = 1;
    cli_session session;
    bool opened = bench_open(&session, "bench isg", o.scene_path,
                             "scenes/cornell-glossy/cornell_glossy.json", o.threads);
    if (!sweep_gather(NULL, 0, 0, 0, opened)) { // under mpirun: every rank, or none, goes on
        goto done;
    }
    drift_context *ctx = session.ctx;
    drift_scene *scene = session.scene;
    const drift_accel *accel = session.accel;
    const char *scene_path = session.scene_path;
    drift_result r = DRIFT_OK;
    if (o.aperture >= 0.0) {
        scene->camera.aperture_radius = (float)o.aperture;
    } else if (!(scene->camera.aperture_radius > 0.0f)) {
        // A scene without a lens: 1% of its diagonal, focused on what the image centre sees.
        scene->camera.aperture_radius =
            0.01f * drift_vec3_length(drift_vec3_sub(scene->bounds.max, scene->bounds.min));
        drift_camera pinhole = scene->camera;
        pinhole.aperture_radius = 0.0f;
        drift_ray ray = drift_camera_ray(&pinhole, 2, 2, 1.0f, 1.0f, drift_vec2_make(0.5f, 0.5f));
        drift_hit hit;
        if (drift_accel_intersect(accel, &ray, &hit)) {
            drift_vec3 forward =
                drift_vec3_normalize(drift_vec3_sub(scene->camera.target, scene->camera.position));
            scene->camera.focus_distance = hit.t * drift_vec3_dot(ray.dir, forward);
        }
    }
    bench_ctx b = { ctx, scene, accel, &o };
    static double tables[3][4][4];
    double base[3] = { 0.0, 0.0, 0.0 };
    static quality_row rows[3][MAX_ROWS];
    int row_count[3] = { 0, 0, 0 };
    // Every rank's renders first (timing cells, references, technique frames), then the
    // comparisons and gathers, so that no rank waits for another's reference before its own.
    static double cells[3][16][2];
    static quality_run runs[3];
    for (int e = 0; e < 3 && r == DRIFT_OK; ++e) {
        if (!o.skip_table) {
            r = timing_render(&b, effects[e], 16 * e, cells[e]);
        }
        if (!o.skip_quality && r == DRIFT_OK) {
            r = quality_render(&b, effects[e], e, &runs[e]);
        }
    }
    bool ok = r == DRIFT_OK;
    for (int e = 0; e < 3; ++e) {
        if (!o.skip_table) {
            ok = timing_collect(16 * e, cells[e], ok, tables[e], &base[e]) && ok;
        }
        if (!o.skip_quality) {
            ok = quality_compare(&b, &runs[e], ok, rows[e], &row_count[e]) && ok;
        }
    }
    if (r == DRIFT_OK && !ok) {
        r = DRIFT_ERR_CANCELLED; // on another rank, named by rank 0
    }
    if (r != DRIFT_OK) {
        fprintf(stderr, "drift bench isg: %s\n", drift_result_string(r));
        goto done;
    }
    if (sweep_rank() != 0) { // rank 0 prints the figures it gathered
        exit_code = 0;
    } else if (o.json) {
        exit_code = print_json(&b, tables, base, rows, row_count, scene_path) ? 0 : 1;
    } else {
        print_text(&b, tables, base, rows, row_count, scene_path);
        exit_code = 0;
    }
done:
    cli_session_close(&session);
    return exit_code;
}
