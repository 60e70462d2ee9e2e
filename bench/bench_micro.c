// drift bench micro: micro-rendering (src/micro) against the path tracer on the diffuse
// indirect term I (DRIFT_PT_COMPONENT_DIFFUSE at max depth 2, the frame's `--indirect
// reference`). Three sweeps, each row with milliseconds by stage, gathers and gather samples
// (micro-buffer pixels) a second, and RMSE / NRMS of I against the reference:
//   size     the micro-buffer's K at every-pixel density (Fig. 6.17)
//   density  1, 1/4 and 1/16 of the pixels gathering, bilaterally upsampled (Fig. 6.15)
//   points   nodes visited a gather as the hierarchy's points double (Fig. 6.18; --csv)
// Under mpirun the reference's tiles, then the rows, are spread over the ranks (sweep.h).
#include "bench.h"
#include "distributed/sweep.h"
#include "drift/accel.h"
#include "drift/hybrid.h"
#include "drift/metric.h"
#include "drift/micro.h"
#include "drift/pt.h"
#include "drift/scene_io.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_LIST 16

typedef struct micro_options {
    const char *scene_path, *csv_path;
    long size, threads, ref_spp, points, light_samples;
    long sizes[MAX_LIST], densities[MAX_LIST], scaling[MAX_LIST];
    int size_count, density_count, scaling_count;
    bool json;
} micro_options;

// --sizes, --densities and --scaling: `field` is the options.
static bool parse_lists(const char *cmd, const char *flag, const char *value, void *field)
{
    micro_options *o = field;
    if (strcmp(flag, "--sizes") == 0) {
        return bench_parse_list(cmd, flag, value, 4, 32, MAX_LIST, o->sizes, &o->size_count);
    }
    if (strcmp(flag, "--scaling") == 0) {
        return bench_parse_list(cmd, flag, value, 1, 22, MAX_LIST, o->scaling, &o->scaling_count);
    }
    long d[MAX_LIST];
    int n = 0;
    if (!bench_parse_list(cmd, flag, value, 1, 16, MAX_LIST, d, &n)) {
        return false;
    }
    for (int i = 0; i < n; ++i) {
        if (d[i] != 1 && d[i] != 4 && d[i] != 16) {
            fprintf(stderr,
                    "drift %s: %s expects 1, 4 or 16 (one gather in that many pixels), "
                    "got '%s'\n",
                    cmd, flag, value);
            return false;
        }
    }
    memcpy(o->densities, d, sizeof d);
    o->density_count = n;
    return true;
}

#define O micro_options
static const cli_option micro_table[] = {
    CLI_SECTION("options:", 0),
    CLI_INT("--size", "N", O, size, 8, 4096, "N x N pixels (default 128)"),
    BENCH_OPTION_THREADS(O),
    CLI_INT("--ref-spp", "N", O, ref_spp, 1, 1 << 20, "reference samples a pixel (default 1024)"),
    CLI_INT("--points", "P", O, points, 2, 1 << 22,
            "scene points of the size and density sweeps (default 65536)"),
    CLI_INT("--light-samples", "N", O, light_samples, 1, 1024,
            "light samples a leaf and side (default 4)"),
    CLI_CUSTOM_ALL("--sizes", "LIST", parse_lists, "micro-buffer sizes K (default 8,16,24)"),
    CLI_CUSTOM_ALL("--densities", "LIST", parse_lists,
                   "one gather in 1, 4 or 16 pixels (default 1,4,16), at K = 16"),
    CLI_CUSTOM_ALL("--scaling", "LIST", parse_lists,
                   "log2 of the point counts of the scaling sweep (default\n"
                   "16,17,18,19,20)"),
    CLI_STRING("--csv", "FILE", O, csv_path,
               "the scaling sweep as CSV: points,nodes_visited,hierarchy_ms,gather_ms"),
    BENCH_OPTION_JSON(O),
};
#undef O

static const cli_command micro_command = {
    .name = "bench micro",
    .usage = "usage: drift bench micro [SCENE] [options]\n\n"
             "micro-rendering (src/micro) against the path tracer on the diffuse indirect term\n"
             "I: a Markdown table (docs/benchmarks.md), or with --json one JSON object. SCENE\n"
             "defaults to scenes/cornell-box/cornell_box.json.\n\n",
    CLI_TABLE(micro_table),
    CLI_POSITIONAL("SCENE", micro_options, scene_path, 1),
    .help_column = 17,
};

typedef struct row {
    const char *sweep;
    long value;
    int32_t k, density;
    uint32_t points;
} row;

// One row's figures: computed by the rank that renders it (mpirun, sweep.h), printed by rank 0.
typedef struct row_figures {
    double create_ms, total_ms, stage_ms[DRIFT_MICRO_STAGE_COUNT];
    double gathers, gathers_per_s, samples_per_s, visited, cast, rmse, nrms;
} row_figures;

// One micro render of the frame's G-buffer: its figures but the errors (measure_row), and a
// copy of its I.
static drift_result render_row(cli_session *s, const micro_options *o, drift_hybrid *frame,
                               const row *w, row_figures *f, drift_image *out)
{
    drift_micro *m = NULL;
    drift_micro_params mp = { .point_count = w->points,
                              .buffer_size = w->k,
                              .density = w->density,
                              .light_samples = (int32_t)o->light_samples };
    double t0 = drift_time_now();
    drift_result r = drift_micro_create(s->ctx, s->scene, s->accel, &mp, &m);
    double create_ms = (drift_time_now() - t0) * 1e3;
    if (r == DRIFT_OK) {
        r = drift_micro_render(m, drift_hybrid_gbuffer(frame), &s->scene->camera,
                               DRIFT_MICRO_LOBE_DIFFUSE);
    }
    const drift_image *img = r == DRIFT_OK ? drift_micro_result(m) : NULL;
    if (img) {
        r = drift_image_create(s->ctx, img->width, img->height, img->channels, out);
    }
    if (r != DRIFT_OK) {
        drift_micro_destroy(m);
        return r;
    }
    memcpy(out->pixels, img->pixels,
           sizeof(float) * (size_t)img->channels * (size_t)img->width * (size_t)img->height);
    drift_micro_stats st = drift_micro_get_stats(m);
    double gather_ms = st.ms[DRIFT_MICRO_STAGE_GATHER];
    *f = (row_figures){ .create_ms = create_ms, .total_ms = st.total_ms };
    memcpy(f->stage_ms, st.ms, sizeof f->stage_ms);
    f->gathers = (double)st.gathers;
    f->gathers_per_s = gather_ms > 0.0 ? (double)st.gathers * 1e3 / gather_ms : 0.0;
    f->samples_per_s = f->gathers_per_s * (double)w->k * (double)w->k;
    f->visited = st.gathers ? (double)st.nodes_visited / (double)st.gathers : 0.0;
    f->cast = st.gathers ? (double)st.cast_gathers / (double)st.gathers : 0.0;
    drift_micro_destroy(m);
    return DRIFT_OK;
}

static void measure_row(cli_session *s, const drift_image *ref, const drift_image *img,
                        row_figures *f)
{
    double mse = 0.0;
    drift_metric_mse(s->ctx, ref, img, &mse);
    f->rmse = sqrt(mse);
    f->nrms = f->rmse / drift_image_mean_luminance(ref);
}

// A row's figures added to `rows` (JSON) or printed, and to the CSV.
static void emit_row(const row *w, const row_figures *f, cJSON *rows, FILE *csv)
{
    double gather_ms = f->stage_ms[DRIFT_MICRO_STAGE_GATHER];
    if (rows) {
        cJSON *j = cJSON_CreateObject();
        cJSON_AddItemToArray(rows, j);
        cJSON_AddStringToObject(j, "sweep", w->sweep);
        cJSON_AddNumberToObject(j, "k", w->k);
        cJSON_AddNumberToObject(j, "density", w->density * w->density);
        cJSON_AddNumberToObject(j, "points", w->points);
        cli_json_number(j, "create_ms", f->create_ms, 3);
        cli_json_number(j, "ms", f->total_ms, 3);
        cJSON *stage_ms = cJSON_AddObjectToObject(j, "stage_ms");
        for (int k = 0; k < DRIFT_MICRO_STAGE_COUNT; ++k) {
            cli_json_number(stage_ms, drift_micro_stage_name((drift_micro_stage)k), f->stage_ms[k],
                            3);
        }
        cJSON_AddNumberToObject(j, "gathers", f->gathers);
        cli_json_number(j, "gathers_per_s", f->gathers_per_s, 1);
        cli_json_number(j, "gather_samples_per_s", f->samples_per_s, 1);
        cli_json_number(j, "nodes_visited", f->visited, 1);
        cli_json_number(j, "ray_cast_share", f->cast, 4);
        cli_json_number(j, "rmse", f->rmse, 6);
        cli_json_number(j, "nrms", f->nrms, 6);
    } else {
        printf("| %-7s | %2d | 1/%-2d | %7u | %8.1f | %5.1f / %6.1f / %8.1f / %5.1f | %8.0f | "
               "%6.2f | %6.0f | %.3f | %.4f |\n",
               w->sweep, w->k, w->density * w->density, w->points, f->total_ms,
               f->stage_ms[DRIFT_MICRO_STAGE_HIERARCHY], f->stage_ms[DRIFT_MICRO_STAGE_LIGHTING],
               gather_ms, f->stage_ms[DRIFT_MICRO_STAGE_UPSAMPLE], f->gathers_per_s,
               f->samples_per_s * 1e-6, f->visited, f->cast, f->nrms);
    }
    if (csv) {
        fprintf(csv, "%u,%.1f,%.3f,%.3f\n", w->points, f->visited,
                f->stage_ms[DRIFT_MICRO_STAGE_HIERARCHY], gather_ms);
    }
}

int drift_bench_micro(int argc, char **argv)
{
    micro_options o = { .size = 128,
                        .threads = 1,
                        .ref_spp = 1024,
                        .points = 65536,
                        .light_samples = 4,
                        .sizes = { 8, 16, 24 },
                        .size_count = 3,
                        .densities = { 1, 4, 16 },
                        .density_count = 3,
                        .scaling = { 16, 17, 18, 19, 20 },
                        .scaling_count = 5 };
    int status = cli_parse(&micro_command, argc, argv, &o, NULL);
    if (status != CLI_PARSED) {
        return cli_parse_exit(status);
    }
    status = 1;
    cli_session s;
    bool opened = bench_open(&s, "bench micro", o.scene_path, "scenes/cornell-box/cornell_box.json",
                             o.threads);
    if (!sweep_gather(NULL, 0, 0, 0, opened)) { // under mpirun: every rank, or none, goes on
        cli_session_close(&s);
        return 1;
    }
    // The sweeps' rows, in order.
    row list[3 * MAX_LIST];
    int count = 0;
    for (int i = 0; i < o.size_count; ++i) {
        list[count++] = (row){ "size", o.sizes[i], (int32_t)o.sizes[i], 1, (uint32_t)o.points };
    }
    for (int i = 0; i < o.density_count; ++i) {
        int32_t spacing = o.densities[i] == 1 ? 1 : (o.densities[i] == 4 ? 2 : 4);
        list[count++] = (row){ "density", o.densities[i], 16, spacing, (uint32_t)o.points };
    }
    for (int i = 0; i < o.scaling_count; ++i) {
        list[count++] = (row){ "points", o.scaling[i], 16, 4, 1u << o.scaling[i] };
    }
    row_figures figures[3 * MAX_LIST] = { 0 };
    drift_image images[3 * MAX_LIST] = { 0 };
    drift_hybrid *frame = NULL;
    drift_pt *pt = NULL;
    drift_image ref = { 0 }; // owned by the pt
    cJSON *root = NULL, *rows = NULL;
    FILE *csv = NULL;
    drift_hybrid_params hp = { .width = (int32_t)o.size, .height = (int32_t)o.size };
    drift_result r = drift_hybrid_create(s.ctx, s.scene, s.accel, &hp, &frame);
    r = r ? r : drift_hybrid_render(frame, &s.scene->camera, NULL);
    // The reference by every rank together (tiles over the ranks, sweep.h), then the rows,
    // sweep item i row i, each measured by its rank and gathered by rank 0.
    drift_pt_params pp = { .width = (int32_t)o.size,
                           .height = (int32_t)o.size,
                           .seed = 99,
                           .max_depth = 2,
                           .components = DRIFT_PT_COMPONENT_DIFFUSE,
                           .pixel_centre = true,
                           .pinhole = true };
    r = r ? r : drift_pt_create(s.ctx, s.scene, s.accel, &pp, &pt);
    bool ok = sweep_pt_render(pt, (uint32_t)o.ref_spp, r == DRIFT_OK);
    r = r || !ok ? r : drift_pt_resolve(pt, DRIFT_PT_AOV_BEAUTY, &ref);
    for (int i = 0; i < count && ok && r == DRIFT_OK; ++i) {
        if (sweep_mine(i)) {
            r = render_row(&s, &o, frame, &list[i], &figures[i], &images[i]);
            measure_row(&s, &ref, &images[i], &figures[i]);
        }
    }
    if (!sweep_gather(figures, sizeof *figures, 0, count, ok && r == DRIFT_OK)) {
        goto done;
    }
    if (o.csv_path) {
        csv = fopen(o.csv_path, "w");
        if (!csv) {
            fprintf(stderr, "drift bench micro: cannot write '%s'\n", o.csv_path);
            goto done;
        }
        fprintf(csv, "points,nodes_visited,hierarchy_ms,gather_ms\n");
    }
    if (o.json) {
        root = cJSON_CreateObject();
        cJSON_AddStringToObject(root, "scene", s.scene_path);
        cJSON_AddNumberToObject(root, "size", (double)o.size);
        cJSON_AddNumberToObject(root, "threads", drift_context_thread_count(s.ctx));
        cJSON_AddNumberToObject(root, "ref_spp", (double)o.ref_spp);
        rows = cJSON_AddArrayToObject(root, "rows");
    } else {
        printf("# %s at %ldx%ld, %d threads; reference %ld spp (max depth 2, DIFFUSE)\n",
               s.scene_path, o.size, o.size, drift_context_thread_count(s.ctx), o.ref_spp);
        printf("| sweep | K | density | points | ms | hierarchy / lighting / gather / "
               "upsample ms | gathers/s | M samples/s | nodes a gather | ray-cast share | "
               "NRMS of I |\n|---|---|---|---|---|---|---|---|---|---|---|\n");
    }
    for (int i = 0; i < count; ++i) {
        emit_row(&list[i], &figures[i], rows, strcmp(list[i].sweep, "points") == 0 ? csv : NULL);
    }
    status = !root || cli_json_write("bench micro", root, NULL) ? 0 : 1;
    root = NULL; // cli_json_write destroys it
done:
    if (r != DRIFT_OK) {
        fprintf(stderr, "drift bench micro: %s\n", drift_result_string(r));
    }
    if (csv && fclose(csv) != 0) {
        status = 1;
    }
    cJSON_Delete(root);
    for (int i = 0; i < count; ++i) {
        drift_image_destroy(s.ctx, &images[i]);
    }
    drift_pt_destroy(pt);
    drift_hybrid_destroy(frame);
    cli_session_close(&s);
    return status;
}
