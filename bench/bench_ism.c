// drift bench ism: imperfect shadow maps and instant radiosity (src/ism) against the path
// tracer, on the diffuse indirect term I (DRIFT_PT_COMPONENT_DIFFUSE at max depth 2, the
// frame's `--indirect reference`). For each VPL count: ism and ir (exact ray visibility)
// milliseconds and stage breakdown, RMSE of I against a path-traced reference, and FLIP of the
// frame they make with the reference's other terms (emission + direct), next to the path
// tracer's own I at a list of spp (its time is that of whole paths, as the frame would pay).
#include "bench.h"
#include "drift/accel.h"
#include "drift/hybrid.h"
#include "drift/image_io.h"
#include "drift/ism.h"
#include "drift/metric.h"
#include "drift/pt.h"
#include "drift/scene_io.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_LIST 16

typedef struct ism_options {
    const char *scene_path, *png_dir;
    long size, threads, ref_spp, points, map, block;
    long vpls[MAX_LIST], spps[MAX_LIST];
    int vpl_count, spp_count;
    bool no_ir;
} ism_options;

static void print_help(FILE *out)
{
    fprintf(
        out,
        "usage: drift bench ism [SCENE] [--size N] [--threads T] [--vpls LIST] [--spp LIST]\n"
        "                       [--ref-spp N] [--points P] [--map N] [--block B] [--no-ir]\n"
        "                       [--png DIR]\n\n"
        "ism and ir (src/ism) against the path tracer on the diffuse indirect term I.\n\n"
        "  SCENE        default scenes/cornell-box/cornell_box.json\n"
        "  --size N     N x N pixels (default 400)\n"
        "  --threads T  worker threads (default 2)\n"
        "  --vpls LIST  comma-separated VPL counts (default 64,256,1024)\n"
        "  --spp LIST   the path tracer's spp (default 1,2,4)\n"
        "  --ref-spp N  reference samples a pixel (default 256)\n"
        "  --points P   points per VPL (default 1024); --map N ISM side (default 64)\n"
        "  --block B    interleaving block (default 4)\n"
        "  --no-ir      skip the ray-traced baseline\n"
        "  --png DIR    write each row's frame (reference terms + I) as DIR/<row>_<count>.png,\n"
        "               I alone 3 stops up as DIR/<row>_<count>_indirect.png, and the\n"
        "               VPLs and one ISM tile of the last ism row\n");
}

static bool parse_long(const char *s, long lo, long hi, long *out)
{
    char *end;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (errno || *end || v < lo || v > hi) {
        return false;
    }
    *out = v;
    return true;
}

static bool parse_list(const char *s, long *out, int *count)
{
    char buf[256];
    if (strlen(s) >= sizeof buf) {
        return false;
    }
    strcpy(buf, s);
    *count = 0;
    for (char *tok = strtok(buf, ","); tok; tok = strtok(NULL, ",")) {
        if (*count >= MAX_LIST || !parse_long(tok, 1, 1 << 20, &out[*count])) {
            return false;
        }
        (*count)++;
    }
    return *count > 0;
}

static int parse(int argc, char **argv, ism_options *o)
{
    *o = (ism_options){ .scene_path = DRIFT_SOURCE_DIR "/scenes/cornell-box/cornell_box.json",
                        .size = 400,
                        .threads = 2,
                        .ref_spp = 256,
                        .points = 1024,
                        .map = 64,
                        .block = 4,
                        .vpls = { 64, 256, 1024 },
                        .vpl_count = 3,
                        .spps = { 1, 2, 4 },
                        .spp_count = 3 };
    for (int i = 1; i < argc; ++i) {
        const char *a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        bool ok = true;
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            print_help(stdout);
            return 0;
        } else if (strcmp(a, "--no-ir") == 0) {
            o->no_ir = true;
            continue;
        } else if (a[0] != '-') {
            o->scene_path = a;
            continue;
        } else if (!v) {
            ok = false;
        } else if (strcmp(a, "--size") == 0) {
            ok = parse_long(v, 8, 4096, &o->size);
        } else if (strcmp(a, "--threads") == 0) {
            ok = parse_long(v, 1, 256, &o->threads);
        } else if (strcmp(a, "--ref-spp") == 0) {
            ok = parse_long(v, 1, 1 << 20, &o->ref_spp);
        } else if (strcmp(a, "--points") == 0) {
            ok = parse_long(v, 1, 1 << 20, &o->points);
        } else if (strcmp(a, "--map") == 0) {
            ok = parse_long(v, 4, 1024, &o->map);
        } else if (strcmp(a, "--block") == 0) {
            ok = parse_long(v, 1, 64, &o->block);
        } else if (strcmp(a, "--vpls") == 0) {
            ok = parse_list(v, o->vpls, &o->vpl_count);
        } else if (strcmp(a, "--spp") == 0) {
            ok = parse_list(v, o->spps, &o->spp_count);
        } else if (strcmp(a, "--png") == 0) {
            o->png_dir = v;
        } else {
            ok = false;
        }
        if (!ok) {
            fprintf(stderr, "drift bench ism: bad option or value: %s %s\n", a, v ? v : "");
            print_help(stderr);
            return 2;
        }
        i++;
    }
    return -1;
}

typedef struct bench_state {
    drift_context *ctx;
    drift_scene *scene;
    drift_accel *accel;
    const ism_options *o;
    drift_image ref_indirect, ref_rest, ref_frame;
} bench_state;

static drift_result pt_image(bench_state *b, uint32_t components, long spp, drift_image *out,
                             double *out_ms)
{
    drift_pt *pt = NULL;
    drift_pt_params params = { .width = (int32_t)b->o->size,
                               .height = (int32_t)b->o->size,
                               .seed = (uint32_t)spp * 7u + components,
                               .max_depth = 2,
                               .components = components,
                               .pixel_centre = true,
                               .pinhole = true };
    drift_result r = drift_pt_create(b->ctx, b->scene, b->accel, &params, &pt);
    double t0 = drift_time_now();
    if (r == DRIFT_OK) {
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

// Prints one row: I's RMSE against the reference, and FLIP of ref_rest + I against ref_frame.
static void report(bench_state *b, const char *name, long count, double ms, const char *detail,
                   const drift_image *indirect)
{
    drift_image frame;
    if (drift_image_create(b->ctx, indirect->width, indirect->height, 3, &frame) != DRIFT_OK) {
        return;
    }
    for (int32_t y = 0; y < frame.height; ++y) {
        for (int32_t x = 0; x < frame.width; ++x) {
            drift_image_set3(&frame, x, y,
                             drift_vec3_add(drift_image_get3(&b->ref_rest, x, y),
                                            drift_image_get3(indirect, x, y)));
        }
    }
    double mse = 0.0;
    drift_metric_report rep = { 0 };
    drift_metric_mse(b->ctx, &b->ref_indirect, indirect, &mse);
    drift_metric_compare(b->ctx, &b->ref_frame, &frame, &(drift_metric_params){ 0 }, &rep, NULL);
    printf("| %-4s | %5ld | %8.1f | %.4f | %.4f | %s |\n", name, count, ms, sqrt(mse), rep.flip,
           detail);
    fflush(stdout);
    if (b->o->png_dir) {
        char path[1024];
        snprintf(path, sizeof path, "%s/%s_%ld.png", b->o->png_dir, name, count);
        drift_image_save_png(b->ctx, path, &frame, &(drift_tonemap_params){ 0 });
        // I alone, 3 stops up, where the indirect light's own artifacts show.
        snprintf(path, sizeof path, "%s/%s_%ld_indirect.png", b->o->png_dir, name, count);
        drift_image_save_png(b->ctx, path, indirect,
                             &(drift_tonemap_params){ .exposure_stops = 3.0f });
    }
    drift_image_destroy(b->ctx, &frame);
}

int drift_bench_ism(int argc, char **argv)
{
    ism_options o;
    int status = parse(argc, argv, &o);
    if (status >= 0) {
        return status;
    }
    status = 0;
    bench_state b = { .o = &o };
    drift_result r =
        drift_context_create(&(drift_context_desc){ .thread_count = (int)o.threads }, &b.ctx);
    if (r == DRIFT_OK) {
        r = drift_scene_load(b.ctx, o.scene_path, &b.scene);
    }
    if (r == DRIFT_OK) {
        r = drift_accel_create(b.ctx, b.scene, &(drift_accel_desc){ 0 }, &b.accel);
    }
    drift_hybrid *frame = NULL;
    if (r == DRIFT_OK) {
        drift_hybrid_params hp = { .width = (int32_t)o.size, .height = (int32_t)o.size };
        r = drift_hybrid_create(b.ctx, b.scene, b.accel, &hp, &frame);
    }
    if (r == DRIFT_OK) {
        r = drift_hybrid_render(frame, &b.scene->camera, NULL);
    }
    if (r == DRIFT_OK) {
        r = pt_image(&b, DRIFT_PT_COMPONENT_DIFFUSE, o.ref_spp, &b.ref_indirect, NULL);
    }
    if (r == DRIFT_OK) {
        r = pt_image(&b,
                     DRIFT_PT_COMPONENT_EMISSION | DRIFT_PT_COMPONENT_DIRECT |
                         DRIFT_PT_COMPONENT_SPECULAR,
                     o.ref_spp, &b.ref_rest, NULL);
    }
    if (r == DRIFT_OK) {
        r = drift_image_create(b.ctx, (int32_t)o.size, (int32_t)o.size, 3, &b.ref_frame);
    }
    if (r != DRIFT_OK) {
        fprintf(stderr, "drift bench ism: %s\n", drift_result_string(r));
        status = 1;
        goto done;
    }
    for (int32_t y = 0; y < b.ref_frame.height; ++y) {
        for (int32_t x = 0; x < b.ref_frame.width; ++x) {
            drift_image_set3(&b.ref_frame, x, y,
                             drift_vec3_add(drift_image_get3(&b.ref_rest, x, y),
                                            drift_image_get3(&b.ref_indirect, x, y)));
        }
    }
    drift_hybrid_stats hs = drift_hybrid_get_stats(frame);
    printf("# %s at %ldx%ld, %ld threads; reference %ld spp; G-buffer %.1f ms (not in the rows)\n",
           o.scene_path, o.size, o.size, o.threads, o.ref_spp, hs.ms[DRIFT_PASS_PRIMARY]);
    printf(
        "| what | count | ms | RMSE of I | FLIP of frame | detail |\n|---|---|---|---|---|---|\n");
    report(&b, "ref", o.ref_spp, 0.0, "the reference against itself", &b.ref_indirect);
    for (int i = 0; i < o.spp_count && status == 0; ++i) {
        drift_image img;
        double ms;
        if (pt_image(&b, DRIFT_PT_COMPONENT_DIFFUSE, o.spps[i], &img, &ms) != DRIFT_OK) {
            status = 1;
            break;
        }
        report(&b, "pt", o.spps[i], ms, "spp, max depth 2", &img);
        drift_image_destroy(b.ctx, &img);
    }
    for (int v = 0; v < 2 * o.vpl_count && status == 0; ++v) {
        bool ir = v % 2 == 1;
        if (ir && o.no_ir) {
            continue;
        }
        drift_ism_params ip = { .visibility =
                                    ir ? DRIFT_ISM_VISIBILITY_RAYS : DRIFT_ISM_VISIBILITY_ISM,
                                .vpl_count = (uint32_t)o.vpls[v / 2],
                                .points_per_vpl = (uint32_t)o.points,
                                .map_size = (int32_t)o.map,
                                .block_size = (int32_t)o.block };
        drift_ism *ism = NULL;
        if (drift_ism_create(b.ctx, b.scene, b.accel, &ip, &ism) != DRIFT_OK ||
            drift_ism_render(ism, drift_hybrid_gbuffer(frame), &b.scene->camera) != DRIFT_OK) {
            drift_ism_destroy(ism);
            status = 1;
            break;
        }
        drift_ism_stats st = drift_ism_get_stats(ism);
        char detail[256];
        snprintf(detail, sizeof detail,
                 "%u VPLs; vpls %.1f, points %.1f, splat %.1f, pull-push %.1f, gather %.1f, "
                 "blur %.1f ms; holes %.3f",
                 st.vpl_count, st.ms[DRIFT_ISM_STAGE_VPLS], st.ms[DRIFT_ISM_STAGE_POINTS],
                 st.ms[DRIFT_ISM_STAGE_SPLAT], st.ms[DRIFT_ISM_STAGE_PULL_PUSH],
                 st.ms[DRIFT_ISM_STAGE_GATHER], st.ms[DRIFT_ISM_STAGE_BLUR], st.hole_fraction);
        report(&b, ir ? "ir" : "ism", o.vpls[v / 2], st.total_ms, detail, drift_ism_indirect(ism));
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
done:
    drift_image_destroy(b.ctx, &b.ref_indirect);
    drift_image_destroy(b.ctx, &b.ref_rest);
    drift_image_destroy(b.ctx, &b.ref_frame);
    drift_hybrid_destroy(frame);
    drift_accel_destroy(b.accel);
    drift_scene_destroy(b.scene);
    drift_context_destroy(b.ctx);
    return status;
}
