// drift bench frontier --corpus (issue 40): the frontier over many scenes in one table, scene x
// budget, each cell the lowest-FLIP row within the budget among drift's (hybrid frames) and
// the path tracer's (plain, a-trous, and at 1/2 and 1/4 resolution upsampled), a summary line
// a budget, an SVG grid. And the reduced-resolution path-tracer rows themselves, which the
// single-scene bench lists too: where one sample a pixel does not fit a budget, a user renders
// fewer pixels and upsamples, so no cell is ever empty.
#include "bench_frontier.h"
#include "drift/denoise.h"
#include "drift/image_io.h"
#include "drift/pt.h"
#include "scene_features.h"

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#define MAX_SCENES 64

// --- THE PATH TRACER AT REDUCED RESOLUTION ---

static drift_result copy_image(drift_context *ctx, const drift_image *src, drift_image *out)
{
    drift_result r = drift_image_create(ctx, src->width, src->height, src->channels, out);
    for (int32_t y = 0; r == DRIFT_OK && y < src->height; ++y) {
        memcpy(drift_image_pixel(out, 0, y), drift_image_pixel(src, 0, y),
               (size_t)src->width * (size_t)src->channels * sizeof(float));
    }
    return r;
}

// The path tracer's beauty, albedo, normal and depth (aov[0..3], new images) at w x h.
static drift_result pt_aovs(frontier_state *b, int32_t w, int32_t h, uint32_t spp,
                            int32_t max_depth, uint32_t components, drift_image aov[4])
{
    drift_pt_params params = {
        .width = w, .height = h, .seed = 1u, .max_depth = max_depth, .components = components
    };
    drift_pt *pt = NULL;
    drift_result r = drift_pt_create(b->ctx, b->scene, b->accel, &params, &pt);
    r = r ? r : drift_pt_render_samples(pt, spp, NULL);
    for (int k = 0; k < 4 && r == DRIFT_OK; ++k) {
        drift_image img;
        r = drift_pt_resolve(pt, (drift_pt_aov)k, &img);
        r = r ? r : copy_image(b->ctx, &img, &aov[k]);
    }
    drift_pt_destroy(pt);
    return r;
}

static void destroy_aovs(drift_context *ctx, drift_image aov[4])
{
    for (int k = 0; k < 4; ++k) {
        drift_image_destroy(ctx, &aov[k]);
    }
}

static drift_vec3 lerp3(drift_vec3 a, drift_vec3 b, float t)
{
    return drift_vec3_fma(drift_vec3_scale(a, 1.0f - t), b, t);
}

static drift_vec3 bilinear(const drift_image *low, double u, double v)
{
    u = fmin(fmax(u, 0.0), (double)low->width - 1.0);
    v = fmin(fmax(v, 0.0), (double)low->height - 1.0);
    int32_t x0 = (int32_t)u, y0 = (int32_t)v;
    int32_t x1 = x0 + 1 < low->width ? x0 + 1 : x0, y1 = y0 + 1 < low->height ? y0 + 1 : y0;
    float fx = (float)(u - x0), fy = (float)(v - y0);
    drift_vec3 a = lerp3(drift_image_get3(low, x0, y0), drift_image_get3(low, x1, y0), fx);
    drift_vec3 c = lerp3(drift_image_get3(low, x0, y1), drift_image_get3(low, x1, y1), fx);
    return lerp3(a, c, fy);
}

static float luminance(drift_vec3 c)
{
    return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z;
}

// `low` (with its albedo, normal, depth) up to guide's size: bilinear without a guide;
// with one, joint-bilateral (Kopf et al. 2007) over the 4 x 4 low-resolution neighbours,
// weighted by distance, normal, depth and albedo likeness to the full-resolution pixel, the
// radiance demodulated by the albedo where both have one (texture detail comes back).
static drift_result upsample(drift_context *ctx, const drift_image *low, const drift_image *la,
                             const drift_image *ln, const drift_image *ld,
                             const drift_image guide[4], int32_t w, int32_t h, drift_image *out)
{
    drift_result r = drift_image_create(ctx, w, h, 3, out);
    double f = (double)w / (double)low->width;
    for (int32_t y = 0; r == DRIFT_OK && y < h; ++y) {
        for (int32_t x = 0; x < w; ++x) {
            double u = (x + 0.5) / f - 0.5, v = (y + 0.5) / f - 0.5;
            drift_vec3 plain = bilinear(low, u, v);
            if (!guide) {
                drift_image_set3(out, x, y, plain);
                continue;
            }
            drift_vec3 ap = drift_image_get3(&guide[1], x, y),
                       np = drift_image_get3(&guide[2], x, y);
            float zp = drift_image_pixel(&guide[3], x, y)[0];
            bool demod_p = luminance(ap) > 0.02f;
            drift_vec3 sum = drift_vec3_splat(0.0f);
            float wsum = 0.0f;
            for (int32_t qy = (int32_t)floor(v) - 1; qy <= (int32_t)floor(v) + 2; ++qy) {
                for (int32_t qx = (int32_t)floor(u) - 1; qx <= (int32_t)floor(u) + 2; ++qx) {
                    if (qx < 0 || qy < 0 || qx >= low->width || qy >= low->height) {
                        continue;
                    }
                    float zq = drift_image_pixel(ld, qx, qy)[0];
                    if ((zp > 0.0f) != (zq > 0.0f)) {
                        continue; // a miss and a hit
                    }
                    drift_vec3 aq = drift_image_get3(la, qx, qy);
                    float d2 = (float)((qx - u) * (qx - u) + (qy - v) * (qy - v));
                    float wn = fmaxf(drift_vec3_dot(np, drift_image_get3(ln, qx, qy)), 0.0f);
                    wn *= wn;
                    wn *= wn;
                    float wz = zp > 0.0f ? expf(-fabsf(zp - zq) / (0.05f * zp)) : 1.0f;
                    drift_vec3 da = drift_vec3_sub(ap, aq);
                    float wa = expf(-(fabsf(da.x) + fabsf(da.y) + fabsf(da.z)) / 0.3f);
                    float wgt = expf(-0.5f * d2) * wn * wz * wa;
                    drift_vec3 c = drift_image_get3(low, qx, qy);
                    if (demod_p && luminance(aq) > 0.02f) {
                        c = drift_vec3_make(c.x / fmaxf(aq.x, 0.01f), c.y / fmaxf(aq.y, 0.01f),
                                            c.z / fmaxf(aq.z, 0.01f));
                        c = drift_vec3_mul(c, ap);
                    }
                    sum = drift_vec3_fma(sum, c, wgt);
                    wsum += wgt;
                }
            }
            drift_image_set3(out, x, y, wsum > 1e-6f ? drift_vec3_scale(sum, 1.0f / wsum) : plain);
        }
    }
    return r;
}

drift_result frontier_low_res_rows(frontier_state *b, double limit_ms)
{
    const frontier_options *o = b->o;
    const int32_t size = (int32_t)o->size;
    drift_image guide[4] = { 0 };
    // The full-resolution guide: camera rays alone (emission, depth 1), its time counted.
    double t0 = drift_time_now();
    drift_result r = pt_aovs(b, size, size, 1, 1, DRIFT_PT_COMPONENT_EMISSION, guide);
    double guide_ms = (drift_time_now() - t0) * 1e3;
    for (int32_t f = 2; f <= 4 && r == DRIFT_OK; f *= 2) {
        int32_t lw = size / f > 0 ? size / f : 1;
        // --max-spp caps the same cost as the full-resolution path tracer's: f^2 x its spp.
        const long max_spp = o->max_spp > 0 ? o->max_spp * f * f : 1024;
        for (uint32_t spp = 1; spp <= 1024 && spp <= max_spp && r == DRIFT_OK; spp *= 2) {
            double render_ms[100], filter_ms[100], up_ms[2][2][100];
            drift_image low[4] = { 0 }, den = { 0 };
            drift_image outs[2][2] = { { { 0 } } }; // [denoised][guided]
            for (long k = 0; k < o->runs && r == DRIFT_OK; ++k) {
                destroy_aovs(b->ctx, low);
                drift_image_destroy(b->ctx, &den);
                t0 = drift_time_now();
                r = pt_aovs(b, lw, lw, spp, 8, 0, low);
                render_ms[k] = (drift_time_now() - t0) * 1e3;
                t0 = drift_time_now();
                r = r ? r
                      : drift_denoise_atrous(b->ctx, &low[0], &low[1], &low[2], &low[3], NULL,
                                             &den);
                filter_ms[k] = (drift_time_now() - t0) * 1e3;
                for (int d = 0; d < 2 && r == DRIFT_OK; ++d) {
                    for (int g = 0; g < 2 && r == DRIFT_OK; ++g) {
                        drift_image_destroy(b->ctx, &outs[d][g]);
                        t0 = drift_time_now();
                        r = upsample(b->ctx, d ? &den : &low[0], &low[1], &low[2], &low[3],
                                     g ? guide : NULL, size, size, &outs[d][g]);
                        up_ms[d][g][k] = (drift_time_now() - t0) * 1e3;
                    }
                }
            }
            double ms = r == DRIFT_OK ? frontier_median(render_ms, o->runs) : 0.0;
            double fms = r == DRIFT_OK ? frontier_median(filter_ms, o->runs) : 0.0;
            for (int d = 0; d < 2 && r == DRIFT_OK; ++d) {
                for (int g = 0; g < 2 && r == DRIFT_OK; ++g) {
                    char name[96];
                    snprintf(name, sizeof name, "1/%d res %u spp %s", f, spp,
                             g ? "joint-bilateral" : "bilinear");
                    double total = ms + (d ? fms : 0.0) + frontier_median(up_ms[d][g], o->runs) +
                                   (g ? guide_ms : 0.0);
                    r = frontier_add_row(b, d ? FAMILY_PT_LOW_ATROUS : FAMILY_PT_LOW, name, total,
                                         &outs[d][g]);
                }
            }
            destroy_aovs(b->ctx, low);
            drift_image_destroy(b->ctx, &den);
            for (int d = 0; d < 2; ++d) {
                for (int g = 0; g < 2; ++g) {
                    drift_image_destroy(b->ctx, &outs[d][g]);
                }
            }
            if (ms > limit_ms) {
                break;
            }
        }
    }
    destroy_aovs(b->ctx, guide);
    return r;
}

// --- THE CORPUS ---

// One (scene, budget) cell: the best drift row and the best path-tracer row (any kind) within
// the budget, and the winner between them.
typedef struct corpus_cell {
    char drift[96], pt[96];
    char pt_family[16];
    double drift_flip, pt_flip, drift_ms, pt_ms; // flip < 0: no row within the budget
} corpus_cell;

typedef struct corpus_scene {
    char path[4096];
    char name[64];
    corpus_cell cells[MAX_BUDGETS];
} corpus_scene;

static bool has_scene_extension(const char *name)
{
    const char *exts[] = { ".json", ".glb", ".gltf", ".obj", ".ply", ".ply.gz" };
    size_t n = strlen(name);
    for (size_t k = 0; k < sizeof exts / sizeof *exts; ++k) {
        size_t e = strlen(exts[k]);
        if (n > e && strcmp(name + n - e, exts[k]) == 0) {
            return true;
        }
    }
    return false;
}

static int compare_scene_path(const void *a, const void *b)
{
    return strcmp(((const corpus_scene *)a)->path, ((const corpus_scene *)b)->path);
}

// The scenes of --corpus: a list file (one path a line, relative to the list's folder; '#'
// starts a comment), a folder holding corpus.txt (what scripts/corpus/build.sh writes), or a
// folder whose scene files are taken in name order.
static int read_corpus(const char *path, corpus_scene *scenes, int max)
{
    struct stat st;
    if (stat(path, &st) != 0) {
        fprintf(stderr, "drift bench frontier: --corpus %s: no such file or folder\n", path);
        return -1;
    }
    char list[4096];
    snprintf(list, sizeof list, "%s", path);
    if (S_ISDIR(st.st_mode)) {
        int len = snprintf(list, sizeof list, "%s/corpus.txt", path);
        if (len < 0 || (size_t)len >= sizeof list || stat(list, &st) != 0) {
            DIR *dir = opendir(path);
            int n = 0;
            for (struct dirent *e = dir ? readdir(dir) : NULL; e && n < max; e = readdir(dir)) {
                if (e->d_name[0] != '.' && has_scene_extension(e->d_name)) {
                    int plen =
                        snprintf(scenes[n].path, sizeof scenes->path, "%s/%s", path, e->d_name);
                    n += plen > 0 && (size_t)plen < sizeof scenes->path;
                }
            }
            if (dir) {
                closedir(dir);
            }
            qsort(scenes, (size_t)n, sizeof *scenes, compare_scene_path);
            return n;
        }
    }
    FILE *f = fopen(list, "r");
    if (!f) {
        fprintf(stderr, "drift bench frontier: --corpus: cannot read %s\n", list);
        return -1;
    }
    char dir[4096];
    snprintf(dir, sizeof dir, "%s", list);
    char *slash = strrchr(dir, '/');
    if (slash) {
        slash[1] = '\0';
    } else {
        dir[0] = '\0';
    }
    char line[4096];
    int n = 0, line_no = 0;
    while (fgets(line, sizeof line, f)) {
        ++line_no;
        line[strcspn(line, "\r\n#")] = '\0';
        char *t = line;
        while (*t == ' ' || *t == '\t') {
            ++t;
        }
        if (!*t) {
            continue;
        }
        if (n >= max) {
            fprintf(stderr, "drift bench frontier: %s:%d: more than %d scenes\n", list, line_no,
                    max);
            fclose(f);
            return -1;
        }
        int len = snprintf(scenes[n].path, sizeof scenes->path, "%s%s", t[0] == '/' ? "" : dir, t);
        if (len < 0 || (size_t)len >= sizeof scenes->path || stat(scenes[n].path, &st) != 0) {
            fprintf(stderr, "drift bench frontier: %s:%d: no scene %s\n", list, line_no,
                    scenes[n].path);
            fclose(f);
            return -1;
        }
        ++n;
    }
    fclose(f);
    return n;
}

// The file name without its folder and extension: the table's scene column.
static void scene_name(const char *path, char *out, size_t size)
{
    const char *base = strrchr(path, '/');
    base = base ? base + 1 : path;
    size_t length = strcspn(base, "."); // a long name is cut to the column's width
    length = length < size - 1 ? length : size - 1;
    memcpy(out, base, length);
    out[length] = '\0';
}

static bool is_pt_family(row_family f)
{
    return f == FAMILY_PT || f == FAMILY_PT_ATROUS || f == FAMILY_PT_DENOISE ||
           f == FAMILY_PT_LOW || f == FAMILY_PT_LOW_ATROUS;
}

static void fill_cells(const frontier_state *b, corpus_scene *cs)
{
    const frontier_options *o = b->o;
    for (int k = 0; k < o->budget_count; ++k) {
        corpus_cell *c = &cs->cells[k];
        c->drift_flip = c->pt_flip = -1.0;
        double budget = (double)o->budgets[k];
        for (int i = 0; i < b->row_count; ++i) {
            const frontier_row *row = &b->rows[i];
            if (row->ms > budget) {
                continue;
            }
            bool pt = is_pt_family(row->family);
            double *best = pt ? &c->pt_flip : &c->drift_flip;
            if (*best < 0.0 || row->flip < *best) {
                *best = row->flip;
                snprintf(pt ? c->pt : c->drift, sizeof c->pt, "%s", row->name);
                *(pt ? &c->pt_ms : &c->drift_ms) = row->ms;
                if (pt) {
                    snprintf(c->pt_family, sizeof c->pt_family, "%s", family_names[row->family]);
                }
            }
        }
    }
}

// One scene's rows: reference, the path tracer (full and reduced resolution), hybrid frames.
static drift_result corpus_scene_rows(frontier_options *o, corpus_scene *cs, int index, int count)
{
    frontier_state *b = calloc(1, sizeof *b);
    cli_session session;
    if (!b || !bench_open(&session, "bench frontier", cs->path, NULL, o->threads)) {
        free(b);
        cli_session_close(&session);
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    b->ctx = session.ctx;
    b->scene = session.scene;
    b->accel = session.accel;
    b->o = o;
    const double max_budget = (double)o->budgets[o->budget_count - 1];
    char ref_path[4096];
    bool cached = false;
    double t0 = drift_time_now();
    fprintf(stderr, "drift bench frontier: [%d/%d] %s: reference...\n", index + 1, count, cs->name);
    drift_result r = frontier_reference_image(b, cs->path, &cached, ref_path, sizeof ref_path);
    fprintf(stderr, "drift bench frontier: [%d/%d] %s: reference %s (%s, %.1f s); rows...\n",
            index + 1, count, cs->name, ref_path, cached ? "cached" : "rendered",
            drift_time_now() - t0);
    r = r ? r : frontier_guide_frame(b);
    for (long spp = 1; r == DRIFT_OK; spp *= 2) {
        double ms = 0.0;
        r = frontier_pt_rows(b, spp, &ms);
        if ((o->max_spp > 0 && spp * 2 > o->max_spp) || (o->max_spp == 0 && ms > max_budget) ||
            spp >= (1 << 16)) {
            break;
        }
    }
    r = r ? r : frontier_low_res_rows(b, max_budget);
    r = r ? r : frontier_hybrid_rows(b, 2.0 * max_budget);
    for (int g = 0; g < FRONTIER_GUIDES; ++g) {
        drift_image_destroy(b->ctx, &b->guide[g]);
        drift_image_destroy(b->ctx, &b->guide_indirect[g]);
    }
    if (r == DRIFT_OK) {
        fill_cells(b, cs);
        fprintf(stderr, "drift bench frontier: [%d/%d] %s: %d rows in %.1f s\n", index + 1, count,
                cs->name, b->row_count, drift_time_now() - t0);
    }
    if (r == DRIFT_OK && o->json) {
        // Every row, for the chooser's fit (scripts/chooser): printed as one JSON line.
        cJSON *root = cJSON_CreateObject();
        cJSON_AddStringToObject(root, "scene", cs->path);
        cJSON_AddNumberToObject(root, "size", (double)o->size);
        double features[SCENE_FEATURE_COUNT];
        scene_features(b->ctx, b->scene, b->accel, features);
        cJSON *fs = cJSON_AddObjectToObject(root, "features");
        for (int k = 0; k < SCENE_FEATURE_COUNT; ++k) {
            cli_json_number(fs, scene_feature_name(k), features[k], 4);
        }
        cJSON *rows = cJSON_AddArrayToObject(root, "rows");
        for (int i = 0; i < b->row_count; ++i) {
            cJSON *row = cJSON_CreateObject();
            cJSON_AddItemToArray(rows, row);
            cJSON_AddStringToObject(row, "family", family_names[b->rows[i].family]);
            cJSON_AddStringToObject(row, "name", b->rows[i].name);
            cli_json_number(row, "ms", b->rows[i].ms, 3);
            cli_json_number(row, "flip", b->rows[i].flip, 6);
        }
        char *text = cJSON_PrintUnformatted(root);
        if (text) {
            printf("%s\n", text);
            fflush(stdout); // a scene's line whole, for whoever reads it as the bench goes
            free(text);
        }
        cJSON_Delete(root);
    }
    drift_image_destroy(b->ctx, &b->reference);
    free(b);
    cli_session_close(&session);
    return r;
}

static bool write_grid_svg(const frontier_options *o, const corpus_scene *scenes, int n,
                           const char *path)
{
    FILE *f = fopen(path, "w");
    if (!f) {
        fprintf(stderr, "drift bench frontier: cannot write %s\n", path);
        return false;
    }
    const double cw = 110, ch = 26, left = 150, top = 50;
    double w = left + cw * o->budget_count + 20, h = top + ch * n + 40;
    fprintf(f,
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\" "
            "font-family=\"sans-serif\" font-size=\"11\">\n<rect width=\"100%%\" "
            "height=\"100%%\" fill=\"white\"/>\n<text x=\"10\" y=\"20\" font-size=\"13\">"
            "drift vs the best path tracer, FLIP of the winner (blue: drift wins, red: the path "
            "tracer), %ld x %ld</text>\n",
            w, h, o->size, o->size);
    for (int k = 0; k < o->budget_count; ++k) {
        fprintf(f, "<text x=\"%.0f\" y=\"%.0f\" text-anchor=\"middle\">%ld ms</text>\n",
                left + cw * (k + 0.5), top - 8, o->budgets[k]);
    }
    for (int i = 0; i < n; ++i) {
        fprintf(f, "<text x=\"%.0f\" y=\"%.0f\" text-anchor=\"end\">%s</text>\n", left - 8,
                top + ch * (i + 0.65), scenes[i].name);
        for (int k = 0; k < o->budget_count; ++k) {
            const corpus_cell *c = &scenes[i].cells[k];
            bool drift = c->drift_flip >= 0.0 && (c->pt_flip < 0.0 || c->drift_flip < c->pt_flip);
            double flip = drift ? c->drift_flip : c->pt_flip;
            fprintf(
                f,
                "<rect x=\"%.0f\" y=\"%.0f\" width=\"%.0f\" height=\"%.0f\" fill=\"%s\" "
                "stroke=\"white\"><title>drift %s %.4f; pt %s %s %.4f</title></rect>"
                "<text x=\"%.0f\" y=\"%.0f\" text-anchor=\"middle\" fill=\"white\">%.3f</text>\n",
                left + cw * k, top + ch * i, cw, ch, drift ? "#1f63c6" : "#c62f1f", c->drift,
                c->drift_flip, c->pt_family, c->pt, c->pt_flip, left + cw * (k + 0.5),
                top + ch * (i + 0.65), flip);
        }
    }
    fprintf(f, "</svg>\n");
    return fclose(f) == 0;
}

int frontier_corpus(frontier_options *o)
{
    corpus_scene *scenes = calloc(MAX_SCENES, sizeof *scenes);
    int n = scenes ? read_corpus(o->corpus_path, scenes, MAX_SCENES) : -1;
    if (n <= 0) {
        if (n == 0) {
            fprintf(stderr, "drift bench frontier: --corpus %s holds no scene\n", o->corpus_path);
        }
        free(scenes);
        return n == 0 ? 2 : 1;
    }
    for (int i = 0; i < n; ++i) {
        scene_name(scenes[i].path, scenes[i].name, sizeof scenes[i].name);
        if (corpus_scene_rows(o, &scenes[i], i, n) != DRIFT_OK) {
            fprintf(stderr, "drift bench frontier: %s failed\n", scenes[i].path);
            free(scenes);
            return 1;
        }
    }
    if (o->svg_path && !write_grid_svg(o, scenes, n, o->svg_path)) {
        free(scenes);
        return 1;
    }
    FILE *out = o->json ? stderr : stdout;
    fprintf(out,
            "# drift bench frontier --corpus %s: %d scenes at %ldx%ld, reference %ld spp, "
            "median of %ld runs; each cell: the winner within the budget (drift: a hybrid frame; "
            "pt: the path tracer plain, + a-trous, or at 1/2 or 1/4 resolution upsampled) and "
            "its FLIP\n\n| scene |",
            o->corpus_path, n, o->size, o->size, o->ref_spp, o->runs);
    for (int k = 0; k < o->budget_count; ++k) {
        fprintf(out, " %ld ms |", o->budgets[k]);
    }
    fprintf(out, "\n|---|");
    for (int k = 0; k < o->budget_count; ++k) {
        fprintf(out, "---|");
    }
    fprintf(out, "\n");
    for (int i = 0; i < n; ++i) {
        fprintf(out, "| %s |", scenes[i].name);
        for (int k = 0; k < o->budget_count; ++k) {
            const corpus_cell *c = &scenes[i].cells[k];
            bool drift = c->drift_flip >= 0.0 && (c->pt_flip < 0.0 || c->drift_flip < c->pt_flip);
            if (drift) {
                fprintf(out, " **drift** %s %.3f |", c->drift, c->drift_flip);
            } else if (c->pt_flip >= 0.0) {
                fprintf(out, " %s %s %.3f |", c->pt_family, c->pt, c->pt_flip);
            } else {
                fprintf(out, " (nothing within) |");
            }
        }
        fprintf(out, "\n");
    }
    fprintf(out, "\n| budget | drift wins | geometric mean of drift's FLIP / the best pt's |\n"
                 "|---|---|---|\n");
    for (int k = 0; k < o->budget_count; ++k) {
        int wins = 0, both = 0;
        double log_sum = 0.0;
        for (int i = 0; i < n; ++i) {
            const corpus_cell *c = &scenes[i].cells[k];
            wins += c->drift_flip >= 0.0 && (c->pt_flip < 0.0 || c->drift_flip < c->pt_flip);
            if (c->drift_flip > 0.0 && c->pt_flip > 0.0) {
                log_sum += log(c->drift_flip / c->pt_flip);
                ++both;
            }
        }
        fprintf(out, "| %ld ms | %d / %d (%.0f%%) | ", o->budgets[k], wins, n, 100.0 * wins / n);
        if (both > 0) {
            fprintf(out, "%.3f (%d cells) |\n", exp(log_sum / both), both);
        } else {
            fprintf(out, "— |\n");
        }
    }
    free(scenes);
    return 0;
}
