// drift bench micro-bounces: micro-rendering's points lit for more than one bounce (src/micro
// radiosity.c, photons.c) against the path tracer's diffuse indirect term with as many bounces
// (DRIFT_PT_COMPONENT_DIFFUSE at max depth bounces + 1). One row a (bounces, lighting): the
// milliseconds by stage (the lighting split into the direct light and the further bounces),
// photons stored, NRMS, LDR-FLIP and the mean's ratio to the reference. The one-bounce
// `direct` row is repeated against each reference: what the extra bounces add. Under mpirun
// each reference's tiles, then the rows, are spread over the ranks (sweep.h).
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

#define MAX_LIST 8

typedef struct bounces_options {
    const char *scene_path;
    long size, threads, ref_spp, points, k, density, photons;
    long bounces[MAX_LIST];
    int bounce_count;
    bool json;
} bounces_options;

static bool parse_bounces(const char *cmd, const char *flag, const char *value, void *field)
{
    bounces_options *o = field;
    return bench_parse_list(cmd, flag, value, 1, 8, MAX_LIST, o->bounces, &o->bounce_count);
}

#define O bounces_options
static const cli_option bounces_table[] = {
    CLI_SECTION("options:", 0),
    CLI_INT("--size", "N", O, size, 8, 4096, "N x N pixels (default 64)"),
    BENCH_OPTION_THREADS(O),
    CLI_INT("--ref-spp", "N", O, ref_spp, 1, 1 << 20, "reference samples a pixel (default 1024)"),
    CLI_INT("--points", "P", O, points, 2, 1 << 22, "scene points (default 16384)"),
    CLI_INT("--micro-size", "K", O, k, 4, 32, "the final gather's K (default 16)"),
    CLI_INT("--density", "D", O, density, 1, 4, "one gather a D x D block (1, 2 or 4; default 1)"),
    CLI_INT("--photons", "N", O, photons, 1, 1 << 24, "photon paths (default 262144)"),
    CLI_CUSTOM_ALL("--bounces", "LIST", parse_bounces, "bounce counts (default 1,2,3)"),
    BENCH_OPTION_JSON(O),
};
#undef O

static const cli_command bounces_command = {
    .name = "bench micro-bounces",
    .usage = "usage: drift bench micro-bounces [SCENE] [options]\n\n"
             "micro-rendering with the points lit by direct light, radiosity or a photon map,\n"
             "against the path tracer's diffuse indirect light of as many bounces: a Markdown\n"
             "table (docs/benchmarks.md), or with --json one JSON object. SCENE defaults to\n"
             "scenes/cornell-box/cornell_box.json.\n\n",
    CLI_TABLE(bounces_table),
    CLI_POSITIONAL("SCENE", bounces_options, scene_path, 1),
    .help_column = 17,
};

// One row's figures: made by the rank that renders its bounce count (mpirun, sweep.h),
// printed by rank 0.
typedef struct bounce_row {
    int32_t bounces, ref_bounces, lighting;
    drift_micro_stats st;
    double nrms, flip, ratio;
} bounce_row;

static drift_result run_row(cli_session *s, const bounces_options *o, drift_hybrid *frame,
                            const drift_image *ref, int32_t bounces, int32_t ref_bounces,
                            drift_micro_lighting lighting, bounce_row *out)
{
    drift_micro *m = NULL;
    drift_micro_params mp = { .point_count = (uint32_t)o->points,
                              .buffer_size = (int32_t)o->k,
                              .density = (int32_t)o->density,
                              .lighting = lighting,
                              .bounces = bounces,
                              .photon_count = (uint32_t)o->photons };
    drift_result r = drift_micro_create(s->ctx, s->scene, s->accel, &mp, &m);
    if (r == DRIFT_OK) {
        r = drift_micro_render(m, drift_hybrid_gbuffer(frame), &s->scene->camera,
                               DRIFT_MICRO_LOBE_DIFFUSE);
    }
    drift_metric_report rep = { 0 };
    if (r == DRIFT_OK) {
        r = drift_metric_compare(s->ctx, ref, drift_micro_result(m), &(drift_metric_params){ 0 },
                                 &rep, NULL);
    }
    if (r != DRIFT_OK) {
        drift_micro_destroy(m);
        return r;
    }
    double mean = drift_image_mean_luminance(ref);
    *out = (bounce_row){ .bounces = bounces,
                         .ref_bounces = ref_bounces,
                         .lighting = (int32_t)lighting,
                         .st = drift_micro_get_stats(m),
                         .nrms = rep.rmse / mean,
                         .flip = rep.flip,
                         .ratio = drift_image_mean_luminance(drift_micro_result(m)) / mean };
    drift_micro_destroy(m);
    return DRIFT_OK;
}

static void emit_row(const bounce_row *w, cJSON *rows)
{
    const drift_micro_stats *st = &w->st;
    const char *lighting = drift_micro_lighting_name((drift_micro_lighting)w->lighting);
    if (rows) {
        cJSON *j = cJSON_CreateObject();
        cJSON_AddItemToArray(rows, j);
        cJSON_AddNumberToObject(j, "reference_bounces", w->ref_bounces);
        cJSON_AddNumberToObject(j, "bounces", w->bounces);
        cJSON_AddStringToObject(j, "lighting", lighting);
        cli_json_number(j, "ms", st->total_ms, 3);
        cJSON *stage_ms = cJSON_AddObjectToObject(j, "stage_ms");
        for (int k = 0; k < DRIFT_MICRO_STAGE_COUNT; ++k) {
            cli_json_number(stage_ms, drift_micro_stage_name((drift_micro_stage)k), st->ms[k], 3);
        }
        cli_json_number(j, "direct_ms", st->direct_ms, 3);
        cli_json_number(j, "bounces_ms", st->bounces_ms, 3);
        cJSON_AddNumberToObject(j, "photons", (double)st->photons);
        cli_json_number(j, "nrms", w->nrms, 6);
        cli_json_number(j, "flip", w->flip, 6);
        cli_json_number(j, "mean_ratio", w->ratio, 4);
    } else {
        printf("| %d | %-9s | %d | %8.1f | %6.1f / %6.1f / %8.1f / %8.1f / %5.1f | %7llu | %.4f | "
               "%.4f | %.3f |\n",
               w->ref_bounces, lighting, w->bounces, st->total_ms,
               st->ms[DRIFT_MICRO_STAGE_HIERARCHY], st->direct_ms, st->bounces_ms,
               st->ms[DRIFT_MICRO_STAGE_GATHER], st->ms[DRIFT_MICRO_STAGE_UPSAMPLE],
               (unsigned long long)st->photons, w->nrms, w->flip, w->ratio);
    }
}

int drift_bench_micro_bounces(int argc, char **argv)
{
    bounces_options o = { .size = 64,
                          .threads = 1,
                          .ref_spp = 1024,
                          .points = 16384,
                          .k = 16,
                          .density = 1,
                          .photons = 262144,
                          .bounces = { 1, 2, 3 },
                          .bounce_count = 3 };
    int status = cli_parse(&bounces_command, argc, argv, &o, NULL);
    if (status != CLI_PARSED) {
        return cli_parse_exit(status);
    }
    if (o.density == 3) {
        fprintf(stderr, "drift bench micro-bounces: --density expects 1, 2 or 4, got 3\n");
        return 2;
    }
    status = 1;
    cli_session s;
    bool opened = bench_open(&s, "bench micro-bounces", o.scene_path,
                             "scenes/cornell-box/cornell_box.json", o.threads);
    if (!sweep_gather(NULL, 0, 0, 0, opened)) { // under mpirun: every rank, or none, goes on
        cli_session_close(&s);
        return 1;
    }
    drift_hybrid *frame = NULL;
    cJSON *root = NULL, *rows = NULL;
    drift_hybrid_params hp = { .width = (int32_t)o.size, .height = (int32_t)o.size };
    drift_result r = drift_hybrid_create(s.ctx, s.scene, s.accel, &hp, &frame);
    r = r ? r : drift_hybrid_render(frame, &s.scene->camera, NULL);
    // Each bounce count's reference by every rank together (its tiles over the ranks,
    // sweep.h), then its up to 3 rows as sweep items, numbered over all the counts.
    bounce_row results[MAX_LIST * 3];
    memset(results, 0, sizeof results);
    bool ok = r == DRIFT_OK;
    int items = 0;
    for (int i = 0; i < o.bounce_count; ++i) {
        int32_t b = (int32_t)o.bounces[i];
        drift_pt *pt = NULL;
        drift_image ref = { 0 }; // owned by the pt
        drift_pt_params pp = { .width = (int32_t)o.size,
                               .height = (int32_t)o.size,
                               .seed = 99,
                               .max_depth = b + 1,
                               .components = DRIFT_PT_COMPONENT_DIFFUSE,
                               .pixel_centre = true,
                               .pinhole = true };
        r = r ? r : drift_pt_create(s.ctx, s.scene, s.accel, &pp, &pt);
        ok = sweep_pt_render(pt, (uint32_t)o.ref_spp, ok && r == DRIFT_OK);
        r = r || !ok ? r : drift_pt_resolve(pt, DRIFT_PT_AOV_BEAUTY, &ref);
        static const drift_micro_lighting lightings[3] = { DRIFT_MICRO_LIGHTING_DIRECT,
                                                           DRIFT_MICRO_LIGHTING_RADIOSITY,
                                                           DRIFT_MICRO_LIGHTING_PHOTONS };
        for (int k = 0; k < (b > 1 ? 3 : 1); ++k, ++items) {
            if (ok && r == DRIFT_OK && sweep_mine(items)) {
                r = run_row(&s, &o, frame, &ref, k == 0 ? 1 : b, b, lightings[k], &results[items]);
            }
        }
        drift_pt_destroy(pt);
    }
    if (r != DRIFT_OK) {
        fprintf(stderr, "drift bench micro-bounces: %s\n", drift_result_string(r));
    }
    if (!sweep_gather(results, sizeof *results, 0, items, ok && r == DRIFT_OK)) {
        goto done;
    }
    if (o.json) {
        root = cJSON_CreateObject();
        cJSON_AddStringToObject(root, "scene", s.scene_path);
        cJSON_AddNumberToObject(root, "size", (double)o.size);
        cJSON_AddNumberToObject(root, "threads", drift_context_thread_count(s.ctx));
        cJSON_AddNumberToObject(root, "ref_spp", (double)o.ref_spp);
        cJSON_AddNumberToObject(root, "points", (double)o.points);
        cJSON_AddNumberToObject(root, "k", (double)o.k);
        rows = cJSON_AddArrayToObject(root, "rows");
    } else {
        printf("# %s at %ldx%ld, %d threads; references %ld spp (DIFFUSE, max depth "
               "bounces + 1); %ld points, K = %ld, 1/%ld density, %ld photon paths\n",
               s.scene_path, o.size, o.size, drift_context_thread_count(s.ctx), o.ref_spp, o.points,
               o.k, o.density * o.density, o.photons);
        printf("| reference bounces | lighting | bounces | ms | hierarchy / direct / bounces / "
               "gather / upsample ms | photons | NRMS | FLIP | mean / reference |\n"
               "|---|---|---|---|---|---|---|---|---|\n");
    }
    for (int k = 0; k < items; ++k) {
        emit_row(&results[k], rows);
    }
    status = !root || cli_json_write("bench micro-bounces", root, NULL) ? 0 : 1;
    root = NULL; // cli_json_write destroys it
done:
    cJSON_Delete(root);
    drift_hybrid_destroy(frame);
    cli_session_close(&s);
    return status;
}
