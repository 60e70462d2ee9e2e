// drift bench ism: imperfect shadow maps and instant radiosity (src/ism) against the path
// tracer, on the diffuse indirect term I (DRIFT_PT_COMPONENT_DIFFUSE at max depth 2, the
// frame's `--indirect reference`). For each VPL count: ism and ir (exact ray visibility)
// milliseconds and stage breakdown, RMSE of I against a path-traced reference, and FLIP of the
// frame they make with the reference's other terms (emission + direct), next to the path
// tracer's own I at a list of spp (its time is that of whole paths, as the frame would pay).
#include "bench.h"
#include "distributed/sweep.h"
#include "drift/accel.h"
#include "drift/hybrid.h"
#include "drift/image_io.h"
#include "drift/ism.h"
#include "drift/metric.h"
#include "drift/pt.h"
#include "drift/scene_io.h"
#include "ism/ism_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_LIST 16

typedef struct ism_options {
    const char *scene_path, *png_dir;
    long size, height, threads, ref_spp, points, map, block, repeat;
    long vpls[MAX_LIST], spps[MAX_LIST];
    int vpl_count, spp_count;
    bool no_ir, no_ism, classic, json;
} ism_options;

// --vpls and --spp: `field` is the options.
static bool parse_counts(const char *cmd, const char *flag, const char *value, void *field)
{
    ism_options *o = field;
    bool vpls = strcmp(flag, "--vpls") == 0;
    return bench_parse_list(cmd, flag, value, 1, 1 << 20, MAX_LIST, vpls ? o->vpls : o->spps,
                            vpls ? &o->vpl_count : &o->spp_count);
}

#define O ism_options
static const cli_option ism_table[] = {
    CLI_SECTION("options:", 0),
    CLI_INT("--size", "N", O, size, 8, 4096, "N x N pixels (default 400)"),
    CLI_INT("--height", "H", O, height, 8, 4096,
            "N x H pixels instead (e.g. --size 640 --height 480)"),
    CLI_INT("--threads", "T", O, threads, 1, 256, "worker threads (default 2)"),
    CLI_CUSTOM_ALL("--vpls", "LIST", parse_counts,
                   "comma-separated VPL counts (default 64,256,1024)"),
    CLI_CUSTOM_ALL("--spp", "LIST", parse_counts, "the path tracer's spp (default 1,2,4)"),
    CLI_INT("--ref-spp", "N", O, ref_spp, 1, 1 << 20, "reference samples a pixel (default 256)"),
    CLI_INT("--points", "P", O, points, 1, 1 << 20, "points per VPL (default 1024)"),
    CLI_INT("--map", "N", O, map, 4, 1024, "ISM side (default 64)"),
    CLI_INT("--block", "B", O, block, 1, 64, "interleaving block (default 4)"),
    CLI_INT("--repeat", "R", O, repeat, 0, 1000,
            "after each ism and ir row's first frame, R warm frames; the row\n"
            "reports the fastest of them (default 0: the first frame)"),
    CLI_FLAG("--no-ir", O, no_ir, "skip the ray-traced baseline"),
    CLI_FLAG("--no-ism", O, no_ism, "skip the ism rows (e.g. to profile ir alone)"),
    CLI_FLAG("--classic", O, classic,
             "after each ism row, time exact (ray-cast) paraboloid maps for the\n"
             "same VPLs: the classic shadow maps ISMs replace (row sm)"),
    CLI_STRING("--png", "DIR", O, png_dir,
               "write each row's frame (reference terms + I) as DIR/<row>_<count>.png,\n"
               "I alone 3 stops up as DIR/<row>_<count>_indirect.png, and the\n"
               "VPLs and one ISM tile of the last ism row"),
    BENCH_OPTION_JSON(O),
};
#undef O

static const cli_command ism_command = {
    .name = "bench ism",
    .usage = "usage: drift bench ism [SCENE] [options]\n\n"
             "ism and ir (src/ism) against the path tracer on the diffuse indirect term I: a\n"
             "Markdown table (docs/benchmarks.md), or with --json one JSON object. SCENE\n"
             "defaults to scenes/cornell-box/cornell_box.json.\n\n",
    CLI_TABLE(ism_table),
    CLI_POSITIONAL("SCENE", ism_options, scene_path, 1),
    .help_column = 15,
};

// out = x + y (three channels, all the same size): a frame from the reference's other terms
// and an indirect term.
static void add_images(drift_image *out, const drift_image *x, const drift_image *y)
{
    for (int32_t j = 0; j < out->height; ++j) {
        for (int32_t i = 0; i < out->width; ++i) {
            drift_image_set3(out, i, j,
                             drift_vec3_add(drift_image_get3(x, i, j), drift_image_get3(y, i, j)));
        }
    }
}

typedef struct bench_state {
    drift_context *ctx;
    drift_scene *scene;
    drift_accel *accel;
    const ism_options *o;
    drift_image ref_indirect, ref_rest, ref_frame;
    drift_image last_ism; // the last ism row's I, for the ir row of the same VPLs
    cJSON *rows;          // --json: the rows go here instead of stdout
} bench_state;

// One row's figures, made by the rank that renders it (mpirun, sweep.h) and printed by rank
// 0; name[0] == 0: a row the options leave out.
typedef struct ism_row {
    char name[8];
    long count;
    double ms, rmse, flip;
    double nrmse_vs_ism; // ir rows: the NRMSE of the ism I against it (< 0: none)
    bool has_stats;      // an ism or ir row: st and first_ms (its ms is the fastest warm one)
    drift_ism_stats st;
    double first_ms;
    char detail[320];
} ism_row;

// The row `name`'s own figures (its errors come later, measure).
static ism_row make_row(const char *name, long count, double ms, const char *detail,
                        const drift_ism_stats *st)
{
    ism_row row = { .count = count, .ms = ms, .nrmse_vs_ism = -1.0, .has_stats = st != NULL };
    snprintf(row.name, sizeof row.name, "%s", name);
    snprintf(row.detail, sizeof row.detail, "%s", detail);
    if (st) {
        row.st = *st;
    }
    return row;
}

static drift_result copy_image(drift_context *ctx, const drift_image *src, drift_image *out)
{
    drift_result r = drift_image_create(ctx, src->width, src->height, 3, out);
    if (r == DRIFT_OK) {
        add_images(out, src, out); // a copy: the new image is zero
    }
    return r;
}

// The path tracer's image of `components` at spp; `together` (a reference): rendered by every
// rank at once (sweep_pt_render), *together saying whether every rank's part went well.
static drift_result pt_image(bench_state *b, uint32_t components, long spp, drift_image *out,
                             double *out_ms, bool *together)
{
    drift_pt *pt = NULL;
    drift_pt_params params = { .width = (int32_t)b->o->size,
                               .height = (int32_t)b->o->height,
                               .seed = (uint32_t)spp * 7u + components,
                               .max_depth = 2,
                               .components = components,
                               .pixel_centre = true,
                               .pinhole = true };
    drift_result r = drift_pt_create(b->ctx, b->scene, b->accel, &params, &pt);
    double t0 = drift_time_now();
    if (together) {
        *together = sweep_pt_render(pt, (uint32_t)spp, *together && r == DRIFT_OK);
    } else if (r == DRIFT_OK) {
        r = drift_pt_render_samples(pt, (uint32_t)spp, NULL);
    }
    if (out_ms) {
        *out_ms = (drift_time_now() - t0) * 1e3;
    }
    drift_image img;
    if (r == DRIFT_OK) {
        r = drift_pt_resolve(pt, DRIFT_PT_AOV_BEAUTY, &img);
    }
    if (r == DRIFT_OK) {
        r = drift_image_create(b->ctx, img.width, img.height, 3, out);
    }
    if (r == DRIFT_OK) {
        for (int32_t y = 0; y < img.height; ++y) {
            for (int32_t x = 0; x < img.width; ++x) {
                drift_image_set3(out, x, y, drift_image_get3(&img, x, y));
            }
        }
    }
    drift_pt_destroy(pt);
    return r;
}

// RMSE of `test` against `ref` over ref's mean (all channels); 0 for a black reference.
static double nrmse(drift_context *ctx, const drift_image *ref, const drift_image *test)
{
    double mse = 0.0, sum = 0.0;
    drift_metric_mse(ctx, ref, test, &mse);
    for (int32_t y = 0; y < ref->height; ++y) {
        for (int32_t x = 0; x < ref->width; ++x) {
            drift_vec3 c = drift_image_get3(ref, x, y);
            sum += (double)(c.x + c.y + c.z) / 3.0;
        }
    }
    double mean = sum / ((double)ref->width * (double)ref->height);
    return mean > 0.0 ? sqrt(mse) / mean : 0.0;
}

// A row's errors: I's RMSE against the reference, and FLIP of ref_rest + I against ref_frame.
static void measure(const bench_state *b, ism_row *row, const drift_image *indirect)
{
    drift_image frame;
    if (drift_image_create(b->ctx, indirect->width, indirect->height, 3, &frame) != DRIFT_OK) {
        return;
    }
    add_images(&frame, &b->ref_rest, indirect);
    double mse = 0.0;
    drift_metric_report rep = { 0 };
    drift_metric_mse(b->ctx, &b->ref_indirect, indirect, &mse);
    drift_metric_compare(b->ctx, &b->ref_frame, &frame, &(drift_metric_params){ 0 }, &rep, NULL);
    row->rmse = sqrt(mse);
    row->flip = rep.flip;
    drift_image_destroy(b->ctx, &frame);
}

// One row printed or (--json) added to b->rows; with --png its images (rank 0 has them all
// then) written.
static void emit(bench_state *b, const ism_row *row, const drift_image *indirect)
{
    if (b->rows) {
        cJSON *j = cJSON_CreateObject();
        cJSON_AddItemToArray(b->rows, j);
        cJSON_AddStringToObject(j, "what", row->name);
        cJSON_AddNumberToObject(j, "count", (double)row->count);
        cli_json_number(j, "ms", row->ms, 3);
        cli_json_number(j, "rmse_indirect", row->rmse, 6);
        cli_json_number(j, "flip_frame", row->flip, 6);
        if (row->nrmse_vs_ism >= 0.0) {
            cli_json_number(j, "nrmse_ism_vs_ir", row->nrmse_vs_ism, 6);
        }
        if (row->has_stats) {
            const drift_ism_stats *st = &row->st;
            static const char *const stages[] = { "vpls",      "points", "splat",
                                                  "pull_push", "gather", "blur" };
            static const int stage_index[] = { DRIFT_ISM_STAGE_VPLS,   DRIFT_ISM_STAGE_POINTS,
                                               DRIFT_ISM_STAGE_SPLAT,  DRIFT_ISM_STAGE_PULL_PUSH,
                                               DRIFT_ISM_STAGE_GATHER, DRIFT_ISM_STAGE_BLUR };
            cJSON_AddNumberToObject(j, "vpls", st->vpl_count);
            cJSON *stage_ms = cJSON_AddObjectToObject(j, "stage_ms");
            for (size_t k = 0; k < sizeof stages / sizeof *stages; ++k) {
                cli_json_number(stage_ms, stages[k], st->ms[stage_index[k]], 3);
            }
            cli_json_number(j, "holes", st->hole_fraction, 4);
            cli_json_number(j, "first_ms", row->first_ms, 3);
        }
    } else {
        printf("| %-4s | %5ld | %8.1f | %.4f | %.4f | %s", row->name, row->count, row->ms,
               row->rmse, row->flip, row->detail);
        if (row->nrmse_vs_ism >= 0.0) {
            printf("; ism's NRMSE against it %.4f", row->nrmse_vs_ism);
        }
        printf(" |\n");
        fflush(stdout);
    }
    drift_image frame;
    if (b->o->png_dir && indirect->pixels &&
        drift_image_create(b->ctx, indirect->width, indirect->height, 3, &frame) == DRIFT_OK) {
        add_images(&frame, &b->ref_rest, indirect);
        char path[1024];
        snprintf(path, sizeof path, "%s/%.7s_%ld.png", b->o->png_dir, row->name, row->count);
        drift_image_save_png(b->ctx, path, &frame, &(drift_tonemap_params){ 0 });
        // I alone, 3 stops up, where the indirect light's own artifacts show.
        snprintf(path, sizeof path, "%s/%.7s_%ld_indirect.png", b->o->png_dir, row->name,
                 row->count);
        drift_image_save_png(b->ctx, path, indirect,
                             &(drift_tonemap_params){ .exposure_stops = 3.0f });
        drift_image_destroy(b->ctx, &frame);
    }
}

typedef struct classic_job {
    const drift_accel *accel;
    const drift_vpl *vpls;
    int32_t n;
    float *maps; // one n x n map per thread: only the build is timed
} classic_job;

static void classic_maps(size_t begin, size_t end, int thread, void *user)
{
    classic_job *job = user;
    float *depth = job->maps + (size_t)thread * (size_t)job->n * (size_t)job->n;
    for (size_t j = begin; j < end; ++j) {
        drift_frame frame = drift_frame_from_normal(job->vpls[j].normal);
        drift__ism_exact_map(depth, job->n, job->accel, job->vpls[j].position, &frame);
    }
}

// Row sm: exact paraboloid maps for the ism row's VPLs, one Embree ray a texel (the CPU's
// classic shadow maps; the thesis rasterises the scene into each), timed against the ISM
// build (splat + pull-push). Its image is the ism row's: only the build differs.
static ism_row classic_row(bench_state *b, const drift_ism *ism, const drift_ism_stats *st,
                           long count)
{
    uint32_t vpl_count = 0;
    const drift_vpl *vpls = drift_ism_vpls(ism, &vpl_count);
    int32_t n = (int32_t)b->o->map;
    classic_job job = { .accel = b->accel, .vpls = vpls, .n = n };
    job.maps =
        malloc((size_t)drift_context_thread_count(b->ctx) * (size_t)n * (size_t)n * sizeof(float));
    if (!job.maps) {
        return make_row("sm", count, 0.0, "out of memory", NULL);
    }
    double t0 = drift_time_now();
    drift_parallel_for(b->ctx, vpl_count, 1, classic_maps, &job);
    double ms = (drift_time_now() - t0) * 1e3;
    free(job.maps);
    double ism_ms = st->ms[DRIFT_ISM_STAGE_SPLAT] + st->ms[DRIFT_ISM_STAGE_PULL_PUSH];
    char detail[256];
    snprintf(detail, sizeof detail,
             "%u exact %dx%d maps, %.0f rays; %.1fx the ISM build (splat + pull-push %.1f ms)",
             vpl_count, n, n, (double)vpl_count * (double)n * (double)n * (double)DRIFT_PI / 4.0,
             ism_ms > 0.0 ? ms / ism_ms : 0.0, ism_ms);
    return make_row("sm", count, ms, detail, NULL);
}

// Under mpirun the two references are rendered by every rank together (sweep_pt_render), then
// the rows are sweep items over the ranks (sweep.h): item i is the pt row of the i-th spp,
// and after those one item per VPL count (its ism, sm and ir rows: ir is measured against
// that ism). With --png rank 0 renders every row, since it alone writes files.
static int row_owner(const ism_options *o, int item)
{
    return o->png_dir ? 0 : item % sweep_ranks();
}

// The rows in order: ref, the pt rows, then ism, sm, ir for each VPL count.
#define ISM_ROWS (1 + MAX_LIST + 3 * MAX_LIST)

int drift_bench_ism(int argc, char **argv)
{
    ism_options o = { .size = 400,
                      .threads = 2,
                      .ref_spp = 256,
                      .points = 1024,
                      .map = 64,
                      .block = 4,
                      .vpls = { 64, 256, 1024 },
                      .vpl_count = 3,
                      .spps = { 1, 2, 4 },
                      .spp_count = 3 };
    int status = cli_parse(&ism_command, argc, argv, &o, NULL);
    if (status != CLI_PARSED) {
        return cli_parse_exit(status);
    }
    o.height = o.height ? o.height : o.size;
    status = 1;
    bench_state b = { .o = &o };
    cli_session session;
    cJSON *root = NULL;
    drift_result r = DRIFT_OK;
    bool opened = bench_open(&session, "bench ism", o.scene_path,
                             "scenes/cornell-box/cornell_box.json", o.threads);
    if (!sweep_gather(NULL, 0, 0, 0, opened)) { // under mpirun: every rank, or none, goes on
        cli_session_close(&session);
        return 1;
    }
    b.ctx = session.ctx;
    b.scene = session.scene;
    b.accel = session.accel;
    static ism_row rows[ISM_ROWS];
    memset(rows, 0, sizeof rows);
    drift_image images[ISM_ROWS] = { 0 };
    int owners[ISM_ROWS] = { 0 };
    int pt_first = 1, vpl_first = 1 + o.spp_count, row_count = vpl_first + 3 * o.vpl_count;
    owners[0] = 0;
    for (int i = 0; i < o.spp_count; ++i) {
        owners[pt_first + i] = row_owner(&o, i);
    }
    for (int c = 0; c < o.vpl_count; ++c) {
        for (int k = 0; k < 3; ++k) {
            owners[vpl_first + 3 * c + k] = row_owner(&o, o.spp_count + c);
        }
    }
    drift_hybrid *frame = NULL;
    drift_hybrid_params hp = { .width = (int32_t)o.size, .height = (int32_t)o.height };
    r = drift_hybrid_create(b.ctx, b.scene, b.accel, &hp, &frame);
    if (r == DRIFT_OK) {
        r = drift_hybrid_render(frame, &b.scene->camera, NULL);
    }
    // The two references by every rank together (their tiles over the ranks), then the rows.
    bool ok = r == DRIFT_OK;
    drift_result r1 =
        pt_image(&b, DRIFT_PT_COMPONENT_DIFFUSE, o.ref_spp, &b.ref_indirect, NULL, &ok);
    drift_result r2 = pt_image(
        &b, DRIFT_PT_COMPONENT_EMISSION | DRIFT_PT_COMPONENT_DIRECT | DRIFT_PT_COMPONENT_SPECULAR,
        o.ref_spp, &b.ref_rest, NULL, &ok);
    r = r ? r : (r1 ? r1 : r2);
    for (int i = 0; i < o.spp_count && ok && r == DRIFT_OK; ++i) {
        if (owners[pt_first + i] != sweep_rank()) {
            continue;
        }
        double ms;
        r = pt_image(&b, DRIFT_PT_COMPONENT_DIFFUSE, o.spps[i], &images[pt_first + i], &ms, NULL);
        rows[pt_first + i] = make_row("pt", o.spps[i], ms, "spp, max depth 2", NULL);
    }
    for (int v = 0; v < 2 * o.vpl_count && ok && r == DRIFT_OK; ++v) {
        bool ir = v % 2 == 1;
        int slot = vpl_first + 3 * (v / 2) + (ir ? 2 : 0);
        if ((ir && o.no_ir) || (!ir && o.no_ism) || owners[slot] != sweep_rank()) {
            continue;
        }
        drift_ism_params ip = { .visibility =
                                    ir ? DRIFT_ISM_VISIBILITY_RAYS : DRIFT_ISM_VISIBILITY_ISM,
                                .vpl_count = (uint32_t)o.vpls[v / 2],
                                .points_per_vpl = (uint32_t)o.points,
                                .map_size = (int32_t)o.map,
                                .block_size = (int32_t)o.block,
                                // The VPL gather alone: the compensation needs a frame.
                                .no_near_field = true };
        drift_ism *ism = NULL;
        r = drift_ism_create(b.ctx, b.scene, b.accel, &ip, &ism);
        r = r ? r : drift_ism_render(ism, drift_hybrid_gbuffer(frame), &b.scene->camera, NULL);
        if (r != DRIFT_OK) {
            drift_ism_destroy(ism);
            break;
        }
        drift_ism_stats st = drift_ism_get_stats(ism);
        double first_ms = st.total_ms;
        // Warm frames: the same VPLs and maps again (nothing is cached across renders but
        // the points and the buffers); the fastest stands for the row under a noisy load.
        for (long k = 0; k < o.repeat && r == DRIFT_OK; ++k) {
            r = drift_ism_render(ism, drift_hybrid_gbuffer(frame), &b.scene->camera, NULL);
            drift_ism_stats again = drift_ism_get_stats(ism);
            st = again.total_ms < st.total_ms || k == 0 ? again : st;
        }
        r = r ? r : copy_image(b.ctx, drift_ism_indirect(ism), &images[slot]);
        if (r != DRIFT_OK) {
            drift_ism_destroy(ism);
            break;
        }
        char detail[320];
        snprintf(detail, sizeof detail,
                 "%u VPLs; vpls %.1f, points %.1f, splat %.1f, pull-push %.1f, gather %.1f, "
                 "blur %.1f ms; holes %.3f; first frame %.1f ms%s",
                 st.vpl_count, st.ms[DRIFT_ISM_STAGE_VPLS], st.ms[DRIFT_ISM_STAGE_POINTS],
                 st.ms[DRIFT_ISM_STAGE_SPLAT], st.ms[DRIFT_ISM_STAGE_PULL_PUSH],
                 st.ms[DRIFT_ISM_STAGE_GATHER], st.ms[DRIFT_ISM_STAGE_BLUR], st.hole_fraction,
                 first_ms, o.repeat > 0 ? "; fastest warm frame" : "");
        rows[slot] = make_row(ir ? "ir" : "ism", o.vpls[v / 2], st.total_ms, detail, &st);
        rows[slot].first_ms = first_ms;
        // Fig. 5.8's error: the ism I against the ir I of the same VPLs (exact visibility),
        // RMSE over ir's mean.
        rows[slot].nrmse_vs_ism =
            ir && b.last_ism.pixels ? nrmse(b.ctx, drift_ism_indirect(ism), &b.last_ism) : -1.0;
        drift_image_destroy(b.ctx, &b.last_ism);
        if (!ir) {
            r = copy_image(b.ctx, drift_ism_indirect(ism), &b.last_ism);
        }
        if (r == DRIFT_OK && o.classic && !ir) { // its image is the ism row's
            rows[slot + 1] = classic_row(&b, ism, &st, o.vpls[v / 2]);
            r = copy_image(b.ctx, drift_ism_indirect(ism), &images[slot + 1]);
        }
        if (o.png_dir && !ir && v == 2 * o.vpl_count - 2) {
            char path[1024];
            snprintf(path, sizeof path, "%s/ism_vpls.png", o.png_dir);
            drift_image_save_png(b.ctx, path, drift_ism_plane_named(ism, "ism.vpls"),
                                 &(drift_tonemap_params){ 0 });
            // One ISM tile, depth over the scene diagonal (white far, black empty).
            const drift_image *tile = drift_ism_plane_named(ism, "ism.tile");
            drift_image grey;
            if (tile &&
                drift_image_create(b.ctx, tile->width, tile->height, 3, &grey) == DRIFT_OK) {
                drift_vec3 ext = drift_vec3_sub(b.scene->bounds.max, b.scene->bounds.min);
                float diag = drift_vec3_length(ext);
                for (int32_t y = 0; y < tile->height; ++y) {
                    for (int32_t x = 0; x < tile->width; ++x) {
                        float d = drift_image_pixel(tile, x, y)[0] / diag;
                        drift_image_set3(&grey, x, y, drift_vec3_splat(d));
                    }
                }
                snprintf(path, sizeof path, "%s/ism_tile.png", o.png_dir);
                drift_image_save_png(b.ctx, path, &grey, &(drift_tonemap_params){ 0 });
                drift_image_destroy(b.ctx, &grey);
            }
        }
        drift_ism_destroy(ism);
    }
    // Each rank measures its own rows, rank 0 gathers them.
    ok = ok && r == DRIFT_OK;
    ok = ok &&
         drift_image_create(b.ctx, (int32_t)o.size, (int32_t)o.height, 3, &b.ref_frame) == DRIFT_OK;
    if (ok) {
        add_images(&b.ref_frame, &b.ref_rest, &b.ref_indirect);
        rows[0] = make_row("ref", o.ref_spp, 0.0, "the reference against itself", NULL);
        r = copy_image(b.ctx, &b.ref_indirect, &images[0]);
        ok = r == DRIFT_OK;
    }
    for (int k = 0; ok && k < row_count; ++k) {
        if (owners[k] == sweep_rank() && rows[k].name[0]) {
            measure(&b, &rows[k], &images[k]);
        }
    }
    if (!sweep_gather_owned(rows, sizeof *rows, row_count, owners, ok)) {
        goto done;
    }
    drift_hybrid_stats hs = drift_hybrid_get_stats(frame);
    if (o.json) {
        root = cJSON_CreateObject();
        cJSON_AddStringToObject(root, "scene", session.scene_path);
        cJSON_AddNumberToObject(root, "size", (double)o.size);
        cJSON_AddNumberToObject(root, "height", (double)o.height);
        cJSON_AddNumberToObject(root, "threads", drift_context_thread_count(b.ctx));
        cJSON_AddNumberToObject(root, "ref_spp", (double)o.ref_spp);
        cli_json_number(root, "gbuffer_ms", hs.ms[DRIFT_PASS_PRIMARY], 3);
        b.rows = cJSON_AddArrayToObject(root, "rows");
    } else {
        printf("# %s at %ldx%ld, %d threads; reference %ld spp; G-buffer %.1f ms (not in the "
               "rows)\n",
               session.scene_path, o.size, o.height, drift_context_thread_count(b.ctx), o.ref_spp,
               hs.ms[DRIFT_PASS_PRIMARY]);
        printf("| what | count | ms | RMSE of I | FLIP of frame | detail |\n"
               "|---|---|---|---|---|---|\n");
    }
    for (int k = 0; k < row_count; ++k) {
        if (rows[k].name[0]) {
            emit(&b, &rows[k], &images[k]);
        }
    }
    status = !root || cli_json_write("bench ism", root, NULL) ? 0 : 1;
    root = NULL; // cli_json_write destroys it
done:
    if (r != DRIFT_OK) {
        fprintf(stderr, "drift bench ism: %s\n", drift_result_string(r));
    }
    cJSON_Delete(root);
    for (int k = 0; k < ISM_ROWS; ++k) {
        drift_image_destroy(b.ctx, &images[k]);
    }
    drift_image_destroy(b.ctx, &b.ref_indirect);
    drift_image_destroy(b.ctx, &b.ref_rest);
    drift_image_destroy(b.ctx, &b.ref_frame);
    drift_image_destroy(b.ctx, &b.last_ism);
    drift_hybrid_destroy(frame);
    cli_session_close(&session);
    return status;
}
