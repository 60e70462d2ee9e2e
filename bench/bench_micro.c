// drift bench micro: micro-rendering (src/micro) against the path tracer on the diffuse
// indirect term I (DRIFT_PT_COMPONENT_DIFFUSE at max depth 2, the frame's `--indirect
// reference`). Three sweeps, each row with milliseconds by stage, gathers and gather samples
// (micro-buffer pixels) a second, and RMSE / NRMS of I against the reference:
//   size     the micro-buffer's K at every-pixel density (Fig. 6.17)
//   density  1, 1/4 and 1/16 of the pixels gathering, bilaterally upsampled (Fig. 6.15)
//   points   nodes visited a gather as the hierarchy's points double (Fig. 6.18; --csv)
#include "bench.h"
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

static double mean_luminance(const drift_image *img)
{
    double sum = 0.0;
    for (int32_t y = 0; y < img->height; ++y) {
        for (int32_t x = 0; x < img->width; ++x) {
            sum += (double)drift_luminance(drift_image_get3(img, x, y));
        }
    }
    return sum / ((double)img->width * (double)img->height);
}

typedef struct row {
    const char *sweep;
    long value;
    int32_t k, density;
    uint32_t points;
} row;

// One micro render of the frame's G-buffer; adds its row to `rows` (JSON) or prints it.
static drift_result run_row(cli_session *s, const micro_options *o, drift_hybrid *frame,
                            const drift_image *ref, const row *w, cJSON *rows, FILE *csv)
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
    if (r != DRIFT_OK) {
        drift_micro_destroy(m);
        return r;
    }
    drift_micro_stats st = drift_micro_get_stats(m);
    double mse = 0.0;
    drift_metric_mse(s->ctx, ref, drift_micro_result(m), &mse);
    double rmse = sqrt(mse), nrms = rmse / mean_luminance(ref);
    double gather_ms = st.ms[DRIFT_MICRO_STAGE_GATHER];
    double gathers_per_s = gather_ms > 0.0 ? (double)st.gathers * 1e3 / gather_ms : 0.0;
    double samples_per_s = gathers_per_s * (double)w->k * (double)w->k;
    double visited = st.gathers ? (double)st.nodes_visited / (double)st.gathers : 0.0;
    double cast = st.gathers ? (double)st.cast_gathers / (double)st.gathers : 0.0;
    if (rows) {
        cJSON *j = cJSON_CreateObject();
        cJSON_AddItemToArray(rows, j);
        cJSON_AddStringToObject(j, "sweep", w->sweep);
        cJSON_AddNumberToObject(j, "k", w->k);
        cJSON_AddNumberToObject(j, "density", w->density * w->density);
        cJSON_AddNumberToObject(j, "points", w->points);
        cli_json_number(j, "create_ms", create_ms, 3);
        cli_json_number(j, "ms", st.total_ms, 3);
        cJSON *stage_ms = cJSON_AddObjectToObject(j, "stage_ms");
        for (int k = 0; k < DRIFT_MICRO_STAGE_COUNT; ++k) {
            cli_json_number(stage_ms, drift_micro_stage_name((drift_micro_stage)k), st.ms[k], 3);
        }
        cJSON_AddNumberToObject(j, "gathers", (double)st.gathers);
        cli_json_number(j, "gathers_per_s", gathers_per_s, 1);
        cli_json_number(j, "gather_samples_per_s", samples_per_s, 1);
        cli_json_number(j, "nodes_visited", visited, 1);
        cli_json_number(j, "ray_cast_share", cast, 4);
        cli_json_number(j, "rmse", rmse, 6);
        cli_json_number(j, "nrms", nrms, 6);
    } else {
        printf("| %-7s | %2d | 1/%-2d | %7u | %8.1f | %5.1f / %6.1f / %8.1f / %5.1f | %8.0f | "
               "%6.2f | %6.0f | %.3f | %.4f |\n",
               w->sweep, w->k, w->density * w->density, w->points, st.total_ms,
               st.ms[DRIFT_MICRO_STAGE_HIERARCHY], st.ms[DRIFT_MICRO_STAGE_LIGHTING], gather_ms,
               st.ms[DRIFT_MICRO_STAGE_UPSAMPLE], gathers_per_s, samples_per_s * 1e-6, visited,
               cast, nrms);
        fflush(stdout);
    }
    if (csv) {
        fprintf(csv, "%u,%.1f,%.3f,%.3f\n", w->points, visited, st.ms[DRIFT_MICRO_STAGE_HIERARCHY],
                gather_ms);
    }
    drift_micro_destroy(m);
    return DRIFT_OK;
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
    if (!bench_open(&s, "bench micro", o.scene_path, "scenes/cornell-box/cornell_box.json",
                    o.threads)) {
        cli_session_close(&s);
        return 1;
    }
    drift_hybrid *frame = NULL;
    drift_pt *pt = NULL;
    drift_image ref = { 0 };
    cJSON *root = NULL, *rows = NULL;
    FILE *csv = NULL;
    drift_hybrid_params hp = { .width = (int32_t)o.size, .height = (int32_t)o.size };
    drift_result r = drift_hybrid_create(s.ctx, s.scene, s.accel, &hp, &frame);
    r = r ? r : drift_hybrid_render(frame, &s.scene->camera, NULL);
    drift_pt_params pp = { .width = (int32_t)o.size,
                           .height = (int32_t)o.size,
                           .seed = 99,
                           .max_depth = 2,
                           .components = DRIFT_PT_COMPONENT_DIFFUSE,
                           .pixel_centre = true,
                           .pinhole = true };
    r = r ? r : drift_pt_create(s.ctx, s.scene, s.accel, &pp, &pt);
    r = r ? r : drift_pt_render_samples(pt, (uint32_t)o.ref_spp, NULL);
    r = r ? r : drift_pt_resolve(pt, DRIFT_PT_AOV_BEAUTY, &ref);
    if (r == DRIFT_OK && o.csv_path) {
        csv = fopen(o.csv_path, "w");
        if (!csv) {
            fprintf(stderr, "drift bench micro: cannot write '%s'\n", o.csv_path);
            goto done;
        }
        fprintf(csv, "points,nodes_visited,hierarchy_ms,gather_ms\n");
    }
    if (r == DRIFT_OK) {
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
    }
    for (int i = 0; i < o.size_count && r == DRIFT_OK; ++i) {
        row w = { "size", o.sizes[i], (int32_t)o.sizes[i], 1, (uint32_t)o.points };
        r = run_row(&s, &o, frame, &ref, &w, rows, NULL);
    }
    for (int i = 0; i < o.density_count && r == DRIFT_OK; ++i) {
        int32_t spacing = o.densities[i] == 1 ? 1 : (o.densities[i] == 4 ? 2 : 4);
        row w = { "density", o.densities[i], 16, spacing, (uint32_t)o.points };
        r = run_row(&s, &o, frame, &ref, &w, rows, NULL);
    }
    for (int i = 0; i < o.scaling_count && r == DRIFT_OK; ++i) {
        row w = { "points", o.scaling[i], 16, 4, 1u << o.scaling[i] };
        r = run_row(&s, &o, frame, &ref, &w, rows, csv);
    }
    if (r == DRIFT_OK) {
        status = !root || cli_json_write("bench micro", root, NULL) ? 0 : 1;
        root = NULL; // cli_json_write destroys it
    }
done:
    if (r != DRIFT_OK) {
        fprintf(stderr, "drift bench micro: %s\n", drift_result_string(r));
    }
    if (csv && fclose(csv) != 0) {
        status = 1;
    }
    cJSON_Delete(root);
    drift_pt_destroy(pt);
    drift_hybrid_destroy(frame);
    cli_session_close(&s);
    return status;
}
