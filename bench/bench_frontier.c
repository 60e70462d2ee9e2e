// drift bench frontier: the equal-time frontier (issue 21). Every row renders the whole frame
// and is compared with one converged path-traced image of the whole frame (all effects, max
// depth 8, the path tracer's pixel filter): the path tracer at 1, 2, 4, ... spp, the same
// images through the edge-avoiding a-trous filter (drift/denoise.h), and hybrid frames built
// from the technique table (shadows x indirect, VPL counts and AAF spp swept, max depth 8).
// --svg plots FLIP against ms with the Pareto front; every row names its budget band.
// Each row's milliseconds are the frontier_median of --runs renders; then, per budget, the row with
// the lowest FLIP within it (the Pareto front) and whether a hybrid row beats both the plain
// and the denoised path tracer there. The reference is cached as an EXR keyed by scene, size,
// spp and max depth, so reruns reuse it. docs/frontier.md has the measured table.
#include "bench_frontier.h"

#include "bench.h"
#include "drift/accel.h"
#include "drift/denoise.h"
#include "drift/hybrid.h"
#include "drift/image_io.h"
#include "drift/metric.h"
#include "drift/pt.h"
#include "drift/refine.h"
#include "drift/scene_io.h"
#include "render.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

const char *const family_names[FAMILY_COUNT] = { "pt",         "pt+atrous", "hybrid",
                                                 "sir",        "pt-low",    "pt-low+atrous",
                                                 "pt+denoise", "hybrid+pt" };

static bool parse_budgets(const char *cmd, const char *flag, const char *value, void *field)
{
    frontier_options *o = field;
    if (strcmp(flag, "--vpls") == 0) {
        return bench_parse_list(cmd, flag, value, 1, 1 << 16, MAX_BUDGETS, o->vpls, &o->vpl_count);
    }
    if (strcmp(flag, "--sir-iterations") == 0) {
        return bench_parse_list(cmd, flag, value, 1, 1 << 20, MAX_BUDGETS, o->sir, &o->sir_count);
    }
    if (strcmp(flag, "--aa") == 0) {
        return bench_parse_list(cmd, flag, value, 1, 4096, MAX_BUDGETS, o->aa, &o->aa_count);
    }
    if (strcmp(flag, "--light-samples") == 0) {
        return bench_parse_list(cmd, flag, value, 1, 4096, MAX_BUDGETS, o->light_samples,
                                &o->light_sample_count);
    }
    if (strcmp(flag, "--aaf-spp") == 0) {
        return bench_parse_list(cmd, flag, value, 1, 1024, MAX_BUDGETS, o->aaf_spps,
                                &o->aaf_spp_count);
    }
    return bench_parse_list(cmd, flag, value, 1, 1000000, MAX_BUDGETS, o->budgets,
                            &o->budget_count);
}

#define O frontier_options
static const cli_option frontier_table[] = {
    CLI_SECTION("options:", 0),
    CLI_CUSTOM_ALL("--budgets", "LIST", parse_budgets,
                   "frame budgets in ms (default 50,100,250,500,1000,2000)"),
    CLI_CUSTOM_ALL("--vpls", "LIST", parse_budgets,
                   "VPL counts of the ism and ir rows (default 16,64,256,1024)"),
    CLI_CUSTOM_ALL("--aaf-spp", "LIST", parse_budgets, "spp of the AAF rows (default 1,2,4)"),
    CLI_CUSTOM_ALL("--sir-iterations", "LIST", parse_budgets,
                   "SIR rows refine for these iterations (default 1,4,16)"),
    CLI_CUSTOM_ALL("--aa", "LIST", parse_budgets,
                   "anti-aliasing passes of every hybrid row (default 1,4)"),
    CLI_CUSTOM_ALL("--light-samples", "LIST", parse_budgets,
                   "unshadowed-light samples of every hybrid row (default 8; 1 or 2\n"
                   "fit a frame of the plants into 100 ms, docs/frontier.md)"),
    CLI_INT("--near-field-off-vpls", "N", O, near_field_off_vpls, 0, 1 << 16,
            "ism and ir rows of at most N VPLs run without the near-field\n"
            "compensation too (default 256: below it the VPLs its rays cost\n"
            "can be worth more, docs/frontier.md; 0 = never)"),
    CLI_INT("--half-gather-vpls", "N", O, half_gather_vpls, 0, 1 << 16,
            "ism and ir rows of at least N VPLs also gather at one pixel in\n"
            "2 x 2 (--ism-gather-scale 2; default 256: the gather is then most\n"
            "of the indirect pass, docs/ism.md; 0 = never)"),
    CLI_INT("--env-filter", "N", O, env_filter, 0, 10,
            "on a scene with an environment, every hybrid row also with N\n"
            "a-trous passes over the environment's direct light, its shadow\n"
            "rays at one pixel in 2 x 2 (named ef N; drift render's\n"
            "--env-filter N --env-scale 2; default 4, 0 = never)"),
    CLI_INT("--size", "N", O, size, 4, 4096, "N x N pixels (default 400)"),
    CLI_INT("--threads", "T", O, threads, 0, 256, "worker threads (default 2)"),
    CLI_INT("--ref-spp", "N", O, ref_spp, 1, 1 << 20, "reference samples a pixel (default 512)"),
    CLI_INT("--runs", "N", O, runs, 1, 100,
            "renders a row, the frontier_median is its ms (default 3)"),
    CLI_INT("--max-spp", "N", O, max_spp, 1, 1 << 16,
            "the path tracer's largest spp (default: until a render exceeds the\n"
            "largest budget); at 1/f resolution, f^2 x N"),
    CLI_STRING("--cache", "DIR", O, cache_dir, "where the reference is cached (default out)"),
    CLI_STRING("--corpus", "DIR|LIST", O, corpus_path,
               "every scene of a folder (or a file listing one a line,\n"
               "scripts/corpus/build.sh): one table scene x budget"),
    CLI_STRING("--csv", "FILE", O, csv_path, "every row as CSV"),
    CLI_STRING("--svg", "FILE", O, svg_path,
               "the plot: FLIP against ms per family, the Pareto front and the budgets"),
    BENCH_OPTION_JSON(O),
};
#undef O

static const cli_command frontier_command = {
    .name = "bench frontier",
    .usage =
        "usage: drift bench frontier [SCENE] [options]\n\n"
        "The equal-time frontier: the path tracer, the path tracer + a-trous and hybrid\n"
        "technique combinations against one converged path-traced image of the whole\n"
        "frame; every row's frontier_median ms, FLIP and RMSE, then per budget the lowest FLIP\n"
        "within it. SCENE defaults to scenes/cornell-box/cornell_box.json.\n\n",
    CLI_TABLE(frontier_table),
    CLI_POSITIONAL("SCENE", frontier_options, scene_path, 1),
    .help_column = 15,
};

static int compare_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

double frontier_median(double *v, long n)
{
    qsort(v, (size_t)n, sizeof *v, compare_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

static int compare_long(const void *a, const void *b)
{
    long x = *(const long *)a, y = *(const long *)b;
    return (x > y) - (x < y);
}

static drift_pt_params pt_params(const frontier_options *o, uint32_t seed)
{
    return (drift_pt_params){ .width = (int32_t)o->size,
                              .height = (int32_t)o->size,
                              .seed = seed,
                              .max_depth = FRONTIER_DEPTH };
}

// A copy of the first three channels of `src` into a new image.
static drift_result copy_rgb(drift_context *ctx, const drift_image *src, drift_image *out)
{
    drift_result r = drift_image_create(ctx, src->width, src->height, 3, out);
    for (int32_t y = 0; r == DRIFT_OK && y < src->height; ++y) {
        for (int32_t x = 0; x < src->width; ++x) {
            drift_image_set3(out, x, y, drift_image_get3(src, x, y));
        }
    }
    return r;
}

// FNV-1a of the scene path: the cache key's scene part.
static uint32_t hash_text(const char *s)
{
    uint32_t h = 2166136261u;
    for (; *s; ++s) {
        h = (h ^ (uint8_t)*s) * 16777619u;
    }
    return h;
}

drift_result bench_frontier_path_trace(drift_context *ctx, const drift_scene *scene,
                                       const drift_accel *accel, int32_t width, int32_t height,
                                       uint32_t spp, uint32_t seed, const atomic_bool *cancel,
                                       drift_image *out, uint64_t *rays)
{
    return render_whole_frame_pt(ctx, scene, accel, width, height, spp, seed, cancel, out, rays);
}

drift_result bench_frontier_reference(drift_context *ctx, const drift_scene *scene,
                                      const drift_accel *accel, int32_t width, int32_t height,
                                      uint32_t spp, drift_image *out)
{
    return render_whole_frame_reference(ctx, scene, accel, width, height, spp, out);
}

// Loads the cached reference or renders and caches it; *cached says which.
drift_result frontier_reference_image(frontier_state *b, const char *scene_path, bool *cached,
                                      char *path, size_t path_size)
{
    const frontier_options *o = b->o;
    const char *base = strrchr(scene_path, '/');
    base = base ? base + 1 : scene_path;
    snprintf(path, path_size, "%s/frontier-ref-%.40s-%08x-%ld-%ldspp-d%d.exr", o->cache_dir, base,
             hash_text(scene_path), o->size, o->ref_spp, FRONTIER_DEPTH);
    drift_image loaded;
    struct stat st;
    if (stat(path, &st) == 0 && drift_image_load(b->ctx, path, &loaded) == DRIFT_OK) {
        bool fits = loaded.width == o->size && loaded.height == o->size && loaded.channels >= 3;
        drift_result r = fits ? copy_rgb(b->ctx, &loaded, &b->reference) : DRIFT_OK;
        drift_image_destroy(b->ctx, &loaded);
        if (fits && r == DRIFT_OK) {
            *cached = true;
            return DRIFT_OK;
        }
        drift_image_destroy(b->ctx, &b->reference);
    }
    *cached = false;
    drift_result r =
        bench_frontier_reference(b->ctx, b->scene, b->accel, (int32_t)o->size, (int32_t)o->size,
                                 (uint32_t)o->ref_spp, &b->reference);
    if (r == DRIFT_OK) {
        // The folder and its parents (mkdir -p).
        char dir[4096];
        snprintf(dir, sizeof dir, "%s", o->cache_dir);
        for (char *c = dir + 1; *c; ++c) {
            if (*c == '/') {
                *c = '\0';
                mkdir(dir, 0777);
                *c = '/';
            }
        }
        if (mkdir(o->cache_dir, 0777) != 0 && errno != EEXIST) {
            fprintf(stderr, "drift bench frontier: cannot create %s (reference not cached)\n",
                    o->cache_dir);
            return DRIFT_OK;
        }
        drift_image_layer layer = { NULL, &b->reference };
        if (drift_image_save_exr(b->ctx, path, &layer, 1) != DRIFT_OK) {
            fprintf(stderr, "drift bench frontier: cannot write %s (reference not cached)\n", path);
        }
    }
    return r;
}

drift_result frontier_add_row(frontier_state *b, row_family family, const char *name, double ms,
                              const drift_image *image)
{
    if (b->row_count >= MAX_ROWS) {
        return DRIFT_OK;
    }
    drift_metric_report rep = { 0 };
    drift_result r =
        drift_metric_compare(b->ctx, &b->reference, image, &(drift_metric_params){ 0 }, &rep, NULL);
    if (r != DRIFT_OK) {
        return r;
    }
    frontier_row *row = &b->rows[b->row_count++];
    snprintf(row->name, sizeof row->name, "%s", name);
    row->family = family;
    row->ms = ms;
    row->flip = rep.flip;
    row->rmse = rep.rmse;
    if (!b->o->json) {
        fprintf(stderr, "  %-10s %-40s %9.1f ms  FLIP %.4f  RMSE %.4f\n", family_names[family],
                name, ms, rep.flip, rep.rmse);
    }
    return DRIFT_OK;
}

// The path tracer at `spp` (frontier_median of --runs fresh renders), then the same image through
// the a-trous filter and through the feature-guided denoiser, drift_denoise_feature (their ms:
// the render's plus the filter's frontier_median). *out_ms: the render's.
drift_result frontier_pt_rows(frontier_state *b, long spp, double *out_ms)
{
    const frontier_options *o = b->o;
    double render_ms[100], filter_ms[100], feature_ms[100];
    drift_result r = DRIFT_OK;
    drift_image plain = { 0 }, denoised = { 0 }, featured = { 0 };
    for (long k = 0; k < o->runs && r == DRIFT_OK; ++k) {
        drift_pt_params params = pt_params(o, 1u);
        drift_pt *pt = NULL;
        r = drift_pt_create(b->ctx, b->scene, b->accel, &params, &pt);
        double t0 = drift_time_now();
        r = r ? r : drift_pt_render_samples(pt, (uint32_t)spp, NULL);
        render_ms[k] = (drift_time_now() - t0) * 1e3;
        drift_image beauty, albedo, normal, depth;
        r = r ? r : drift_pt_resolve(pt, DRIFT_PT_AOV_BEAUTY, &beauty);
        r = r ? r : drift_pt_resolve(pt, DRIFT_PT_AOV_ALBEDO, &albedo);
        r = r ? r : drift_pt_resolve(pt, DRIFT_PT_AOV_NORMAL, &normal);
        r = r ? r : drift_pt_resolve(pt, DRIFT_PT_AOV_DEPTH, &depth);
        drift_image_destroy(b->ctx, &denoised);
        t0 = drift_time_now();
        r = r ? r
              : drift_denoise_atrous(b->ctx, &beauty, &albedo, &normal, &depth, NULL, &denoised);
        filter_ms[k] = (drift_time_now() - t0) * 1e3;
        drift_image var, f_albedo, f_normal, f_depth;
        r = r ? r : drift_pt_resolve(pt, DRIFT_PT_AOV_VARIANCE, &var);
        r = r ? r : drift_pt_resolve(pt, DRIFT_PT_AOV_FEATURE_ALBEDO, &f_albedo);
        r = r ? r : drift_pt_resolve(pt, DRIFT_PT_AOV_FEATURE_NORMAL, &f_normal);
        r = r ? r : drift_pt_resolve(pt, DRIFT_PT_AOV_FEATURE_DEPTH, &f_depth);
        drift_image direct, direct_var, indirect_var;
        r = r ? r : drift_pt_resolve(pt, DRIFT_PT_AOV_DIRECT, &direct);
        r = r ? r : drift_pt_resolve(pt, DRIFT_PT_AOV_DIRECT_VARIANCE, &direct_var);
        r = r ? r : drift_pt_resolve(pt, DRIFT_PT_AOV_INDIRECT_VARIANCE, &indirect_var);
        drift_image_destroy(b->ctx, &featured);
        drift_denoise_inputs in = { &beauty,       &f_albedo, &f_normal,   &f_depth,     &var,
                                    (uint32_t)spp, &direct,   &direct_var, &indirect_var };
        t0 = drift_time_now();
        r = r ? r : drift_denoise_feature(b->ctx, &in, NULL, &featured, NULL);
        feature_ms[k] = (drift_time_now() - t0) * 1e3;
        if (r == DRIFT_OK && b->guide[0].pixels && k == o->runs - 1) {
            // The last run's image and its own render's ms (the guided filters timed once)
            r = frontier_guided_rows(b, spp, render_ms[k], &in);
        }
        drift_image_destroy(b->ctx, &plain);
        r = r ? r : copy_rgb(b->ctx, &beauty, &plain);
        drift_pt_destroy(pt);
    }
    if (r == DRIFT_OK) {
        double ms = frontier_median(render_ms, o->runs), fms = frontier_median(filter_ms, o->runs),
               dms = frontier_median(feature_ms, o->runs);
        char name[64];
        snprintf(name, sizeof name, "%ld spp", spp);
        r = frontier_add_row(b, FAMILY_PT, name, ms, &plain);
        r = r ? r : frontier_add_row(b, FAMILY_PT_ATROUS, name, ms + fms, &denoised);
        r = r ? r : frontier_add_row(b, FAMILY_PT_DENOISE, name, ms + dms, &featured);
        *out_ms = ms;
    }
    drift_image_destroy(b->ctx, &plain);
    drift_image_destroy(b->ctx, &denoised);
    drift_image_destroy(b->ctx, &featured);
    return r;
}

// The row with the lowest FLIP among `family` (-1: any) within `budget` ms; -1 if none.
int frontier_best_within(const frontier_state *b, int family, double budget)
{
    int best = -1;
    for (int i = 0; i < b->row_count; ++i) {
        const frontier_row *row = &b->rows[i];
        bool drift = row->family == FAMILY_HYBRID || row->family == FAMILY_SIR ||
                     row->family == FAMILY_HYBRID_PT;
        if (row->ms <= budget &&
            (family == -1 || (int)row->family == family || (family == FAMILY_DRIFT && drift)) &&
            (best < 0 || row->flip < b->rows[best].flip)) {
            best = i;
        }
    }
    return best;
}

static void add_best(cJSON *item, const char *key, const frontier_state *b, int i)
{
    if (i < 0) {
        cJSON_AddNullToObject(item, key);
        return;
    }
    cJSON *o = cJSON_AddObjectToObject(item, key);
    cJSON_AddStringToObject(o, "family", family_names[b->rows[i].family]);
    cJSON_AddStringToObject(o, "name", b->rows[i].name);
    cli_json_number(o, "ms", b->rows[i].ms, 2);
    cli_json_number(o, "flip", b->rows[i].flip, 5);
}

static void print_best(const frontier_state *b, int i)
{
    if (i < 0) {
        printf(" — |");
    } else {
        printf(" %s %s (%.0f ms, %.3f) |", family_names[b->rows[i].family], b->rows[i].name,
               b->rows[i].ms, b->rows[i].flip);
    }
}

// Whether the best hybrid row within the budget has a lower FLIP than the best plain and the
// best denoised path-tracer rows within it (a family with no row there counts as beaten).
static bool hybrid_wins(const frontier_state *b, int h, int pt, int dn)
{
    return h >= 0 && (pt < 0 || b->rows[h].flip < b->rows[pt].flip) &&
           (dn < 0 || b->rows[h].flip < b->rows[dn].flip);
}

// Whether no other row is at most as slow and strictly closer (the ms -> lowest FLIP front).
static bool on_front(const frontier_state *b, int i)
{
    for (int k = 0; k < b->row_count; ++k) {
        if (k != i && b->rows[k].ms <= b->rows[i].ms && b->rows[k].flip < b->rows[i].flip) {
            return false;
        }
    }
    return true;
}

// The budget band a row's ms falls in: the smallest budget that holds it (-1: over them all).
static int budget_band(const frontier_options *o, double ms)
{
    for (int k = 0; k < o->budget_count; ++k) {
        if (ms <= (double)o->budgets[k]) {
            return k;
        }
    }
    return -1;
}

// FLIP against ms (log axis): a dot per row coloured by family, the Pareto front as a staircase
// with its rows named, and the budgets as dashed verticals.
static bool write_svg(const frontier_state *b, const char *path, const char *scene)
{
    const frontier_options *o = b->o;
    double xmin = HUGE_VAL, xmax = 0.0, ymax = 0.0;
    for (int i = 0; i < b->row_count; ++i) {
        xmin = fmin(xmin, fmax(b->rows[i].ms, 1e-3));
        xmax = fmax(xmax, b->rows[i].ms);
        ymax = fmax(ymax, b->rows[i].flip);
    }
    for (int k = 0; k < o->budget_count; ++k) {
        xmin = fmin(xmin, (double)o->budgets[k]);
        xmax = fmax(xmax, (double)o->budgets[k]);
    }
    double lx0 = floor(log10(xmin)), lx1 = ceil(log10(xmax));
    lx1 = lx1 > lx0 ? lx1 : lx0 + 1.0;
    double y1 = ceil(fmax(ymax, 0.05) * 10.0) / 10.0;
    const double W = 760, H = 480, left = 60, right = 20, top = 40, bottom = 50;
    FILE *f = fopen(path, "w");
    if (!f) {
        fprintf(stderr, "drift bench frontier: cannot write %s\n", path);
        return false;
    }
#define PX(v) (left + (log10(fmax(v, 1e-3)) - lx0) / (lx1 - lx0) * (W - left - right))
#define PY(v) (top + (y1 - (v)) / y1 * (H - top - bottom))
    fprintf(f,
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\" "
            "font-family=\"sans-serif\" font-size=\"11\">\n<rect width=\"100%%\" "
            "height=\"100%%\" fill=\"white\"/>\n",
            W, H);
    const char *base = strrchr(scene, '/');
    fprintf(f,
            "<text x=\"%.0f\" y=\"20\" font-size=\"14\">FLIP vs frame ms: %s, %ldx%ld, "
            "%d threads, reference %ld spp</text>\n",
            left, base ? base + 1 : scene, o->size, o->size, drift_context_thread_count(b->ctx),
            o->ref_spp);
    for (double d = lx0; d <= lx1; d += 1.0) {
        for (int m = 1; m < 10 && d + log10(m) <= lx1; ++m) {
            double v = pow(10.0, d) * m, x = PX(v);
            fprintf(f, "<line x1=\"%.1f\" y1=\"%.0f\" x2=\"%.1f\" y2=\"%.0f\" stroke=\"%s\"/>\n", x,
                    top, x, H - bottom, m == 1 ? "#ccc" : "#eee");
            if (m == 1) {
                fprintf(f, "<text x=\"%.1f\" y=\"%.0f\" text-anchor=\"middle\">%g</text>\n", x,
                        H - bottom + 16, v);
            }
        }
    }
    for (double v = 0.0; v <= y1 + 1e-9; v += 0.05) {
        double y = PY(v);
        fprintf(f,
                "<line x1=\"%.0f\" y1=\"%.1f\" x2=\"%.0f\" y2=\"%.1f\" stroke=\"#eee\"/>\n"
                "<text x=\"%.0f\" y=\"%.1f\" text-anchor=\"end\">%.2f</text>\n",
                left, y, W - right, y, left - 6, y + 4, v);
    }
    for (int k = 0; k < o->budget_count; ++k) {
        double x = PX((double)o->budgets[k]);
        fprintf(f,
                "<line x1=\"%.1f\" y1=\"%.0f\" x2=\"%.1f\" y2=\"%.0f\" stroke=\"#888\" "
                "stroke-dasharray=\"4 4\"/><text x=\"%.1f\" y=\"%.0f\" text-anchor=\"middle\" "
                "fill=\"#555\">%ld ms</text>\n",
                x, top, x, H - bottom, x, top - 4, o->budgets[k]);
    }
    fprintf(f,
            "<rect x=\"%.0f\" y=\"%.0f\" width=\"%.0f\" height=\"%.0f\" fill=\"none\" "
            "stroke=\"black\"/>\n<text x=\"%.0f\" y=\"%.0f\" text-anchor=\"middle\">frame ms "
            "(log)</text>\n<text x=\"16\" y=\"%.0f\" transform=\"rotate(-90 16 %.0f)\" "
            "text-anchor=\"middle\">FLIP against the converged path tracer</text>\n",
            left, top, W - left - right, H - top - bottom, (left + W - right) / 2, H - 12,
            (top + H - bottom) / 2, (top + H - bottom) / 2);
    // The front, slowest-first order not needed: sort the front's rows by ms.
    int front[MAX_ROWS], n = 0;
    for (int i = 0; i < b->row_count; ++i) {
        if (on_front(b, i)) {
            int at = n++;
            while (at > 0 && b->rows[front[at - 1]].ms > b->rows[i].ms) {
                front[at] = front[at - 1];
                at--;
            }
            front[at] = i;
        }
    }
    fprintf(f, "<polyline fill=\"none\" stroke=\"black\" stroke-width=\"1.5\" points=\"");
    for (int k = 0; k < n; ++k) {
        const frontier_row *row = &b->rows[front[k]];
        if (k > 0) {
            fprintf(f, "%.1f,%.1f ", PX(row->ms), PY(b->rows[front[k - 1]].flip));
        }
        fprintf(f, "%.1f,%.1f ", PX(row->ms), PY(row->flip));
    }
    fprintf(f, "\"/>\n");
    static const char *const colours[FAMILY_COUNT] = { "#c62f1f", "#e08a1e", "#1f63c6", "#2f9e44",
                                                       "#9c4dc4", "#c44d8f", "#8a3ffc", "#0a8a8a" };
    for (int i = 0; i < b->row_count; ++i) {
        const frontier_row *row = &b->rows[i];
        fprintf(f,
                "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"3.5\" fill=\"%s\" fill-opacity=\"0.75\">"
                "<title>%s %s: %.1f ms, FLIP %.4f</title></circle>\n",
                PX(row->ms), PY(row->flip), colours[row->family], family_names[row->family],
                row->name, row->ms, row->flip);
    }
    for (int k = 0; k < n; ++k) {
        const frontier_row *row = &b->rows[front[k]];
        fprintf(f,
                "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"5\" fill=\"none\" stroke=\"black\"/>"
                "<text x=\"%.1f\" y=\"%.1f\" transform=\"rotate(-30 %.1f %.1f)\">%s %s</text>\n",
                PX(row->ms), PY(row->flip), PX(row->ms) + 6, PY(row->flip) - 6, PX(row->ms) + 6,
                PY(row->flip) - 6, family_names[row->family], row->name);
    }
    for (int m = 0; m < FAMILY_COUNT; ++m) {
        double ly = top + 16 + 16 * m;
        fprintf(f,
                "<circle cx=\"%.0f\" cy=\"%.0f\" r=\"4\" fill=\"%s\"/><text x=\"%.0f\" "
                "y=\"%.0f\">%s</text>\n",
                W - right - 130, ly, colours[m], W - right - 120, ly + 4, family_names[m]);
    }
    fprintf(f,
            "<line x1=\"%.0f\" y1=\"%.0f\" x2=\"%.0f\" y2=\"%.0f\" stroke=\"black\"/>"
            "<text x=\"%.0f\" y=\"%.0f\">Pareto front</text>\n",
            W - right - 136, top + 64, W - right - 124, top + 64, W - right - 120, top + 68);
#undef PX
#undef PY
    fprintf(f, "</svg>\n");
    return fclose(f) == 0;
}

static bool write_csv(const frontier_state *b, const char *path)
{
    FILE *f = fopen(path, "w");
    if (!f) {
        fprintf(stderr, "drift bench frontier: cannot write %s\n", path);
        return false;
    }
    fprintf(f, "family,name,ms,flip,rmse,budget_ms,pareto\n");
    for (int i = 0; i < b->row_count; ++i) {
        const frontier_row *row = &b->rows[i];
        int band = budget_band(b->o, row->ms);
        fprintf(f, "%s,%s,%.3f,%.6f,%.6f,", family_names[row->family], row->name, row->ms,
                row->flip, row->rmse);
        if (band >= 0) {
            fprintf(f, "%ld", b->o->budgets[band]);
        }
        fprintf(f, ",%d\n", on_front(b, i) ? 1 : 0);
    }
    return fclose(f) == 0;
}

int drift_bench_frontier(int argc, char **argv)
{
    frontier_options o = { .size = 400,
                           .threads = 2,
                           .ref_spp = 512,
                           .runs = 3,
                           .cache_dir = "out",
                           .budgets = { 50, 100, 250, 500, 1000, 2000 },
                           .budget_count = 6,
                           .vpls = { 16, 64, 256, 1024 },
                           .vpl_count = 4,
                           .aaf_spps = { 1, 2, 4 },
                           .aaf_spp_count = 3,
                           .aa = { 1, 4 },
                           .aa_count = 2,
                           .light_samples = { DEFAULT_LIGHT_SAMPLES },
                           .light_sample_count = 1,
                           .sir = { 1, 4, 16 },
                           .sir_count = 3,
                           .near_field_off_vpls = 256,
                           .half_gather_vpls = 256,
                           .env_filter = 4 };
    int status = cli_parse(&frontier_command, argc, argv, &o, NULL);
    if (status != CLI_PARSED) {
        return cli_parse_exit(status);
    }
    qsort(o.budgets, (size_t)o.budget_count, sizeof *o.budgets, compare_long);
    if (o.corpus_path) {
        if (o.scene_path) {
            fprintf(stderr, "drift bench frontier: give SCENE or --corpus, not both\n");
            return 2;
        }
        return frontier_corpus(&o);
    }
    status = 1;
    frontier_state *b = calloc(1, sizeof *b);
    cli_session session;
    if (!b || !bench_open(&session, "bench frontier", o.scene_path,
                          "scenes/cornell-box/cornell_box.json", o.threads)) {
        free(b);
        cli_session_close(&session);
        return 1;
    }
    b->ctx = session.ctx;
    b->scene = session.scene;
    b->accel = session.accel;
    b->o = &o;
    const double max_budget = (double)o.budgets[o.budget_count - 1];
    bool cached = false;
    char ref_path[4096];
    double t0 = drift_time_now();
    drift_result r =
        frontier_reference_image(b, session.scene_path, &cached, ref_path, sizeof ref_path);
    double ref_s = drift_time_now() - t0;
    if (r == DRIFT_OK && !o.json) {
        fprintf(stderr, "drift bench frontier: reference %s (%s, %.1f s)\n", ref_path,
                cached ? "cached" : "rendered", ref_s);
    }
    r = r ? r : frontier_guide_frame(b);
    // The path tracer at 1, 2, 4, ... spp until a render is over the largest budget.
    for (long spp = 1; r == DRIFT_OK; spp *= 2) {
        double ms = 0.0;
        r = frontier_pt_rows(b, spp, &ms);
        if ((o.max_spp > 0 && spp * 2 > o.max_spp) || (o.max_spp == 0 && ms > max_budget) ||
            spp >= (1 << 16)) {
            break;
        }
    }
    r = r ? r : frontier_low_res_rows(b, max_budget);
    r = r ? r : frontier_hybrid_rows(b, 2.0 * max_budget);
    r = r ? r : frontier_sir_rows(b, 2.0 * max_budget);
    for (int g = 0; g < FRONTIER_GUIDES; ++g) {
        drift_image_destroy(b->ctx, &b->guide[g]);
        drift_image_destroy(b->ctx, &b->guide_indirect[g]);
    }
    if (r != DRIFT_OK) {
        fprintf(stderr, "drift bench frontier: %s\n", drift_result_string(r));
        goto done;
    }
    if ((o.csv_path && !write_csv(b, o.csv_path)) ||
        (o.svg_path && !write_svg(b, o.svg_path, session.scene_path))) {
        goto done;
    }
    if (o.json) {
        cJSON *root = cJSON_CreateObject();
        cJSON_AddStringToObject(root, "scene", session.scene_path);
        cJSON_AddNumberToObject(root, "size", (double)o.size);
        cJSON_AddNumberToObject(root, "threads", drift_context_thread_count(b->ctx));
        cJSON_AddNumberToObject(root, "ref_spp", (double)o.ref_spp);
        cJSON_AddNumberToObject(root, "max_depth", FRONTIER_DEPTH);
        cJSON_AddNumberToObject(root, "runs", (double)o.runs);
        cJSON_AddStringToObject(root, "reference", ref_path);
        cJSON_AddBoolToObject(root, "reference_cached", cached);
        cJSON *rows = cJSON_AddArrayToObject(root, "rows");
        for (int i = 0; i < b->row_count; ++i) {
            cJSON *row = cJSON_CreateObject();
            cJSON_AddItemToArray(rows, row);
            cJSON_AddStringToObject(row, "family", family_names[b->rows[i].family]);
            cJSON_AddStringToObject(row, "name", b->rows[i].name);
            cli_json_number(row, "ms", b->rows[i].ms, 3);
            cli_json_number(row, "flip", b->rows[i].flip, 6);
            cli_json_number(row, "rmse", b->rows[i].rmse, 6);
            int band = budget_band(&o, b->rows[i].ms);
            if (band >= 0) {
                cJSON_AddNumberToObject(row, "budget_ms", (double)o.budgets[band]);
            } else {
                cJSON_AddNullToObject(row, "budget_ms");
            }
            cJSON_AddBoolToObject(row, "pareto", on_front(b, i));
        }
        cJSON *front = cJSON_AddArrayToObject(root, "front");
        for (int k = 0; k < o.budget_count; ++k) {
            double budget = (double)o.budgets[k];
            int best = frontier_best_within(b, -1, budget),
                pt = frontier_best_within(b, FAMILY_PT, budget),
                at = frontier_best_within(b, FAMILY_PT_ATROUS, budget),
                dn = frontier_best_within(b, FAMILY_PT_DENOISE, budget),
                h = frontier_best_within(b, FAMILY_DRIFT, budget);
            cJSON *item = cJSON_CreateObject();
            cJSON_AddItemToArray(front, item);
            cJSON_AddNumberToObject(item, "budget_ms", budget);
            add_best(item, "best", b, best);
            add_best(item, "pt", b, pt);
            add_best(item, "pt_atrous", b, at);
            add_best(item, "pt_denoise", b, dn);
            add_best(item, "hybrid", b, h);
            cJSON_AddBoolToObject(item, "hybrid_beats_both", hybrid_wins(b, h, pt, dn));
        }
        if (!cli_json_write("bench frontier", root, NULL)) {
            goto done;
        }
    } else {
        printf(
            "# %s at %ldx%ld, %d threads; reference %ld spp, max depth %d; frontier_median of %ld "
            "runs\n\n",
            session.scene_path, o.size, o.size, drift_context_thread_count(b->ctx), o.ref_spp,
            FRONTIER_DEPTH, o.runs);
        printf("| family | row | ms | FLIP | RMSE | budget | front |\n"
               "|---|---|---|---|---|---|---|\n");
        for (int i = 0; i < b->row_count; ++i) {
            int band = budget_band(&o, b->rows[i].ms);
            printf("| %s | %s | %.1f | %.4f | %.4f | ", family_names[b->rows[i].family],
                   b->rows[i].name, b->rows[i].ms, b->rows[i].flip, b->rows[i].rmse);
            if (band >= 0) {
                printf("%ld", o.budgets[band]);
            } else {
                printf("over");
            }
            printf(" | %s |\n", on_front(b, i) ? "yes" : "");
        }
        printf("\n| budget ms | front (lowest FLIP) | best pt | best pt+atrous | best pt+denoise | "
               "best drift (hybrid or sir) | drift beats pt and pt+denoise |\n"
               "|---|---|---|---|---|---|---|\n");
        for (int k = 0; k < o.budget_count; ++k) {
            double budget = (double)o.budgets[k];
            int pt = frontier_best_within(b, FAMILY_PT, budget),
                at = frontier_best_within(b, FAMILY_PT_ATROUS, budget),
                dn = frontier_best_within(b, FAMILY_PT_DENOISE, budget),
                h = frontier_best_within(b, FAMILY_DRIFT, budget);
            printf("| %ld |", o.budgets[k]);
            print_best(b, frontier_best_within(b, -1, budget));
            print_best(b, pt);
            print_best(b, at);
            print_best(b, dn);
            print_best(b, h);
            printf(" %s |\n", hybrid_wins(b, h, pt, dn) ? "yes" : "no");
        }
    }
    status = 0;
done:
    drift_image_destroy(b->ctx, &b->reference);
    free(b);
    cli_session_close(&session);
    return status;
}
