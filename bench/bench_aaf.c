// drift bench aaf: axis-aligned filtering against plain Monte Carlo with the same sampler
// (the paper's Figs. 3.6 and 4.2): RMSE of the effect's term (the frame's `direct` plane for
// shadows, `indirect` for indirect light, `reflections` for the glossy specular buffer)
// against a reference rendered by the path tracer at
// --ref-spp, over a list of average spp; the equal-error sample ratio (the spp plain MC needs
// to reach AAF's error, interpolated on the log-log curve); and the filter's milliseconds
// against the sampling's at 640x480 (Tables 3.1 and 4.1). Writes CSV and an SVG plot.
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

#define MAX_SPPS 16

typedef struct aaf_options {
    const char *scene_path;
    const char *csv_path, *svg_path;
    long width, height, ref_spp, threads, timing_width, timing_height, timing_spp, light_samples;
    long spps[MAX_SPPS], mc_spps[MAX_SPPS];
    int spp_count, mc_spp_count;
    int effect; // --effect: shadows, indirect, both, reflections
    bool shadows, indirect, reflections, json;
    bool random;         // --sampler random: AAF and plain MC both take independent random numbers
    bool ref_plain;      // --ref plain: the reference is plain MC's own estimate at --ref-spp
    bool aaf_unfiltered; // --aaf-filter off: AAF's rows without the filter (its samples alone)
} aaf_options;

// --spp and --mc-spp: an increasing list of 2..MAX_SPPS counts into that list and its count.
static bool parse_spp_list(const char *cmd, const char *flag, const char *v, void *field)
{
    aaf_options *o = field;
    bool mc = strcmp(flag, "--mc-spp") == 0;
    long spps[MAX_SPPS];
    int count = 0;
    if (!bench_parse_list(cmd, flag, v, 1, 65536, MAX_SPPS, spps, &count)) {
        return false;
    }
    bool increasing = count >= 2;
    for (int k = 1; increasing && k < count; ++k) {
        increasing = spps[k] > spps[k - 1];
    }
    if (!increasing) {
        fprintf(stderr, "drift %s: %s expects an increasing list of 2 or more counts, got '%s'\n",
                cmd, flag, v);
        return false;
    }
    memcpy(mc ? o->mc_spps : o->spps, spps, (size_t)count * sizeof *spps);
    *(mc ? &o->mc_spp_count : &o->spp_count) = count;
    return true;
}

static bool parse_size(const char *cmd, const char *flag, const char *v, void *field)
{
    aaf_options *o = field;
    char tail;
    if (sscanf(v, "%ldx%ld%c", &o->timing_width, &o->timing_height, &tail) != 2 ||
        o->timing_width < 1 || o->timing_height < 1 ||
        o->timing_width > DRIFT_IMAGE_MAX_DIMENSION ||
        o->timing_height > DRIFT_IMAGE_MAX_DIMENSION) {
        fprintf(stderr, "drift %s: %s expects WxH, got '%s'\n", cmd, flag, v);
        return false;
    }
    return true;
}

#define O aaf_options
static const cli_option aaf_table[] = {
    CLI_SECTION("options:", 0),
    CLI_CHOICE("--effect", "E", O, effect, "shadows|indirect|both|reflections",
               "shadows (default), indirect, both (those two) or reflections\n"
               "(the specular buffer, --reflections aaf)"),
    CLI_CUSTOM_ALL("--spp", "LIST", parse_spp_list,
                   "comma-separated average spp (default 4,8,16,32,64)"),
    CLI_CUSTOM_ALL("--mc-spp", "LIST", parse_spp_list,
                   "plain Monte Carlo's spp (default: --spp); longer lists avoid\n"
                   "extrapolating the equal-error ratio"),
    CLI_INT("--light-samples", "N", O, light_samples, 1, 4096,
            "samples of U_l's sampled lobes (default 256: keeps the\n"
            "unshadowed light's own noise under the shadows' error)"),
    CLI_CHOICE("--sampler", "S", O, random, "sobol|random",
               "sobol (default) or random, for AAF and plain MC alike: random is\n"
               "the paper's traditional Monte Carlo (Fig. 3.6)"),
    CLI_INT("--ref-spp", "N", O, ref_spp, 1, 1 << 20, "reference samples a pixel (default 4096)"),
    CLI_CHOICE("--ref", "R", O, ref_plain, "path|plain",
               "path (default): the effect's term path-traced; plain: plain MC's own\n"
               "estimate at --ref-spp (the same unshadowed light: only the sampler's\n"
               "error is left where the hybrid's U_l differs from the path tracer)"),
    CLI_CHOICE("--aaf-filter", "F", O, aaf_unfiltered, "on|off",
               "on (default); off: AAF's rows keep their adaptive samples but skip\n"
               "the filter (how much of the ratio is where the samples go)"),
    CLI_INT("--width", "W", O, width, 1, DRIFT_IMAGE_MAX_DIMENSION,
            "error images (default 160x120)"),
    CLI_INT("--height", "H", O, height, 1, DRIFT_IMAGE_MAX_DIMENSION, "error images"),
    CLI_CUSTOM_ALL("--timing-size", "WxH", parse_size, "timing frame (default 640x480)"),
    CLI_INT("--timing-spp", "N", O, timing_spp, 1, 65536, "timing frame's spp (default 16)"),
    BENCH_OPTION_THREADS(O),
    CLI_STRING("--csv", "FILE", O, csv_path,
               "effect,method,spp,actual_spp,rmse,sampling_ms,filter_ms rows"),
    CLI_STRING("--svg", "FILE", O, svg_path, "the log-log plot"),
    BENCH_OPTION_JSON(O),
};
#undef O

static const cli_command aaf_command = {
    .name = "bench aaf",
    .usage = "usage: drift bench aaf [SCENE] [options]\n\n"
             "RMSE of AAF and of plain Monte Carlo (same sampler: uniform spp, no filter) against\n"
             "a path-traced reference of the effect's term, for each average spp; the equal-error\n"
             "sample ratio; and filter vs sampling milliseconds of one AAF frame. SCENE defaults\n"
             "to scenes/grids/grids.json (needs ../shared).\n\n",
    CLI_TABLE(aaf_table),
    CLI_POSITIONAL("SCENE", aaf_options, scene_path, 1),
};

static int parse(int argc, char **argv, aaf_options *o)
{
    *o = (aaf_options){ .width = 160,
                        .height = 120,
                        .ref_spp = 4096,
                        .threads = 1,
                        .timing_width = 640,
                        .timing_height = 480,
                        .timing_spp = 16,
                        .light_samples = 256,
                        .spps = { 4, 8, 16, 32, 64 },
                        .spp_count = 5 };
    int status = cli_parse(&aaf_command, argc, argv, o, NULL);
    if (status != CLI_PARSED) {
        return status;
    }
    o->shadows = o->effect == 0 || o->effect == 2;
    o->indirect = o->effect == 1 || o->effect == 2;
    o->reflections = o->effect == 3;
    if (o->mc_spp_count == 0) {
        memcpy(o->mc_spps, o->spps, sizeof o->spps);
        o->mc_spp_count = o->spp_count;
    }
    return 0;
}

// --- MEASURING ---

typedef struct point {
    double spp, actual_spp, rmse, sampling_ms, filter_ms;
    double mean_ratio; // the term's mean over the image against the reference's
} point;

typedef struct curve {
    drift_effect effect;
    point aaf[MAX_SPPS], plain[MAX_SPPS];
    int count, plain_count;
    double ratio[MAX_SPPS]; // equal-error sample ratio at each AAF point
    bool extrapolated[MAX_SPPS];
    double timing_sampling_ms, timing_filter_ms, timing_frame_ms;
} curve;

// Mean of the n(x) planes over pixels that took samples: the spp the frame really spent.
static double actual_spp(const drift_hybrid *frame, drift_effect effect)
{
    double sum = 0.0;
    size_t count = 0;
    const char *name;
    const drift_image *image;
    const char *suffix = effect == DRIFT_EFFECT_SHADOWS    ? ".aaf.spp"
                         : effect == DRIFT_EFFECT_INDIRECT ? "indirect.aaf.spp"
                                                           : "reflections.aaf.spp";
    for (uint32_t i = 0; drift_hybrid_plane(frame, i, &name, &image); ++i) {
        size_t n = strlen(name), m = strlen(suffix);
        if (n < m || strcmp(name + n - m, suffix) != 0 ||
            (effect == DRIFT_EFFECT_SHADOWS && strncmp(name, "light", 5) != 0)) {
            continue;
        }
        for (int32_t y = 0; y < image->height; ++y) {
            for (int32_t x = 0; x < image->width; ++x) {
                float v = drift_image_pixel(image, x, y)[0];
                if (v > 0.0f) {
                    sum += (double)v;
                    ++count;
                }
            }
        }
    }
    return count ? sum / (double)count : 0.0;
}

static drift_hybrid_params effect_params(drift_effect effect, int technique, const aaf_options *o,
                                         long spp)
{
    drift_hybrid_params p = { .width = (int32_t)o->width,
                              .height = (int32_t)o->height,
                              .spp = (uint32_t)spp,
                              .seed = 11,
                              .light_samples = (uint32_t)o->light_samples,
                              .aaf.random = o->random };
    drift_hybrid_params_set_technique(&p, effect, technique);
    return p;
}

static drift_result render(drift_context *ctx, const drift_scene *scene, const drift_accel *accel,
                           const drift_hybrid_params *params, drift_hybrid **frame)
{
    drift_hybrid_destroy(*frame);
    *frame = NULL;
    drift_result r = drift_hybrid_create(ctx, scene, accel, params, frame);
    return r == DRIFT_OK ? drift_hybrid_render(*frame, &scene->camera, NULL) : r;
}

// log spp at which the plain curve reaches `error`, linear in log-log between its points
// (extrapolated from the nearest two outside them).
static double equal_error_spp(const point *plain, int count, double error, bool *extrapolated)
{
    int k = 0;
    while (k + 2 < count && plain[k + 1].rmse > error) {
        ++k;
    }
    double x0 = log(plain[k].actual_spp), x1 = log(plain[k + 1].actual_spp);
    double y0 = log(plain[k].rmse), y1 = log(plain[k + 1].rmse);
    double y = log(error);
    *extrapolated = error > plain[0].rmse || error < plain[count - 1].rmse;
    if (y1 == y0) {
        return exp(x1);
    }
    return exp(x0 + (y - y0) * (x1 - x0) / (y1 - y0));
}

// One effect's sweep under mpirun (sweep.h): its reference is rendered by one rank (effect
// ordinal mod N) while the other ranks render AAF's and plain MC's points and the timing
// frame in turn; the reference's term is then shared with every rank, each compares its own
// points, and rank 0 gathers them. One process renders everything itself.
typedef struct effect_run {
    drift_effect effect;
    const char *term;
    int aaf;
    int ref_owner;                  // the rank rendering the reference
    drift_hybrid *ref;              // there
    drift_image truth;              // the reference's term, on every rank after sharing
    drift_image tests[2][MAX_SPPS]; // this rank's points' term (0: AAF, 1: plain MC)
    int owners[2][MAX_SPPS];        // each point's rank
    int timing_owner;
    double timing[3]; // sampling, filter, frame ms
} effect_run;

static drift_result copy_plane(drift_context *ctx, const drift_image *plane, drift_image *out)
{
    if (!plane) {
        return DRIFT_ERR_INVALID_ARGUMENT; // the term's plane is missing
    }
    drift_result r = drift_image_create(ctx, plane->width, plane->height, plane->channels, out);
    if (r == DRIFT_OK) {
        memcpy(out->pixels, plane->pixels,
               sizeof(float) * (size_t)plane->channels * (size_t)plane->width *
                   (size_t)plane->height);
    }
    return r;
}

// Phase 1: this rank's renders of the effect (the reference, or its points and timing).
static drift_result measure_render(drift_context *ctx, const drift_scene *scene,
                                   const drift_accel *accel, const aaf_options *o, int ordinal,
                                   effect_run *e, curve *out)
{
    drift_effect effect = e->effect;
    e->term = effect == DRIFT_EFFECT_SHADOWS    ? "direct"
              : effect == DRIFT_EFFECT_INDIRECT ? "indirect"
                                                : "reflections";
    e->aaf = drift_technique_parse(effect, "aaf"); // the effect's rows in the table
    int reference = drift_technique_parse(effect, "reference");
    *out = (curve){ .effect = effect, .count = o->spp_count, .plain_count = o->mc_spp_count };
    e->ref_owner = ordinal % sweep_ranks();
    int most = o->spp_count > o->mc_spp_count ? o->spp_count : o->mc_spp_count;
    for (int k = 0; k < most; ++k) { // AAF's and plain MC's points in turn, by spp
        e->owners[0][k] = sweep_owner_besides(e->ref_owner, 2 * k);
        e->owners[1][k] = sweep_owner_besides(e->ref_owner, 2 * k + 1);
    }
    e->timing_owner = sweep_owner_besides(e->ref_owner, 2 * most);
    int me = sweep_rank();
    drift_result r = DRIFT_OK;
    drift_hybrid *frame = NULL;
    drift_hybrid_params p;
    if (e->ref_owner == me) {
        p = effect_params(effect, o->ref_plain ? e->aaf : reference, o, o->ref_spp);
        p.aaf.uniform = p.aaf.unfiltered = o->ref_plain;
        r = render(ctx, scene, accel, &p, &e->ref);
    }
    for (int k = 0; r == DRIFT_OK && k < most; ++k) {
        for (int method = 0; r == DRIFT_OK && method < 2; ++method) {
            if (k >= (method == 0 ? o->spp_count : o->mc_spp_count) || e->owners[method][k] != me) {
                continue;
            }
            long spp = method == 0 ? o->spps[k] : o->mc_spps[k];
            p = effect_params(effect, e->aaf, o, spp);
            p.aaf.uniform = p.aaf.unfiltered = method == 1;
            p.aaf.unfiltered = p.aaf.unfiltered || o->aaf_unfiltered;
            r = render(ctx, scene, accel, &p, &frame);
            if (r == DRIFT_OK) {
                r = copy_plane(ctx, drift_hybrid_plane_named(frame, e->term), &e->tests[method][k]);
            }
            if (r != DRIFT_OK) {
                break;
            }
            drift_hybrid_stats s = drift_hybrid_get_stats(frame);
            point *pt = method == 0 ? &out->aaf[k] : &out->plain[k];
            *pt = (point){ .spp = (double)spp,
                           .actual_spp = actual_spp(frame, effect),
                           .sampling_ms = s.ms[DRIFT_PASS_AAF_SAMPLING],
                           .filter_ms = s.ms[DRIFT_PASS_AAF_FILTER] };
            if (!(pt->actual_spp > 0.0)) {
                pt->actual_spp = pt->spp;
            }
        }
    }
    if (r == DRIFT_OK && e->timing_owner == me) {
        p = effect_params(effect, e->aaf, o, o->timing_spp);
        p.width = (int32_t)o->timing_width;
        p.height = (int32_t)o->timing_height;
        r = render(ctx, scene, accel, &p, &frame);
        if (r == DRIFT_OK) {
            drift_hybrid_stats s = drift_hybrid_get_stats(frame);
            e->timing[0] = s.ms[DRIFT_PASS_AAF_SAMPLING];
            e->timing[1] = s.ms[DRIFT_PASS_AAF_FILTER];
            e->timing[2] = s.frame_ms;
        }
    }
    drift_hybrid_destroy(frame);
    return r;
}

// Phase 2 (every rank, after every effect's phase 1): the reference's term to every rank,
// the errors of this rank's points, everything to rank 0; the equal-error ratios there.
static drift_result measure_compare(drift_context *ctx, const aaf_options *o, effect_run *e,
                                    bool ok, curve *out)
{
    int me = sweep_rank();
    int32_t dims[3] = { 0, 0, 0 };
    if (ok && e->ref_owner == me) {
        drift_result r = copy_plane(ctx, drift_hybrid_plane_named(e->ref, e->term), &e->truth);
        ok = r == DRIFT_OK;
        if (ok) {
            dims[0] = e->truth.width;
            dims[1] = e->truth.height;
            dims[2] = e->truth.channels;
        }
    }
    ok = sweep_share(dims, sizeof dims, e->ref_owner, ok);
    if (ok && e->ref_owner != me) {
        ok = drift_image_create(ctx, dims[0], dims[1], dims[2], &e->truth) == DRIFT_OK;
    }
    size_t floats = (size_t)dims[0] * (size_t)dims[1] * (size_t)dims[2];
    ok = sweep_share(e->truth.pixels, ok ? floats * sizeof(float) : 0, e->ref_owner, ok);
    double truth_mean = ok ? drift_image_mean_rgb(&e->truth) : 0.0;
    for (int k = 0; ok && k < MAX_SPPS; ++k) {
        for (int method = 0; ok && method < 2; ++method) {
            if (k >= (method == 0 ? o->spp_count : o->mc_spp_count) || e->owners[method][k] != me) {
                continue;
            }
            const drift_image *test = &e->tests[method][k];
            point *pt = method == 0 ? &out->aaf[k] : &out->plain[k];
            double mse = 0.0;
            ok = drift_metric_mse(ctx, &e->truth, test, &mse) == DRIFT_OK;
            pt->rmse = sqrt(mse);
            pt->mean_ratio = truth_mean > 0.0 ? drift_image_mean_rgb(test) / truth_mean : 1.0;
        }
    }
    ok = sweep_gather_owned(out->aaf, sizeof *out->aaf, o->spp_count, e->owners[0], ok);
    ok =
        sweep_gather_owned(out->plain, sizeof *out->plain, o->mc_spp_count, e->owners[1], ok) && ok;
    ok = sweep_gather_owned(e->timing, sizeof e->timing, 1, &e->timing_owner, ok) && ok;
    if (!ok) {
        return DRIFT_ERR_INVALID_ARGUMENT; // here or on another rank (named by rank 0)
    }
    out->timing_sampling_ms = e->timing[0];
    out->timing_filter_ms = e->timing[1];
    out->timing_frame_ms = e->timing[2];
    for (int k = 0; me == 0 && k < o->spp_count; ++k) {
        double spp =
            equal_error_spp(out->plain, o->mc_spp_count, out->aaf[k].rmse, &out->extrapolated[k]);
        out->ratio[k] = spp / out->aaf[k].actual_spp;
    }
    return DRIFT_OK;
}

static void effect_run_free(drift_context *ctx, effect_run *e)
{
    drift_hybrid_destroy(e->ref);
    drift_image_destroy(ctx, &e->truth);
    for (int m = 0; m < 2; ++m) {
        for (int k = 0; k < MAX_SPPS; ++k) {
            drift_image_destroy(ctx, &e->tests[m][k]);
        }
    }
}

// --- OUTPUT ---

static bool write_csv(const char *path, const curve *curves, int count)
{
    FILE *f = fopen(path, "w");
    if (!f) {
        fprintf(stderr, "drift bench aaf: cannot write %s\n", path);
        return false;
    }
    fprintf(f, "effect,method,spp,actual_spp,rmse,sampling_ms,filter_ms\n");
    for (int c = 0; c < count; ++c) {
        for (int method = 0; method < 2; ++method) {
            for (int k = 0; k < (method == 0 ? curves[c].count : curves[c].plain_count); ++k) {
                const point *p = method == 0 ? &curves[c].aaf[k] : &curves[c].plain[k];
                fprintf(f, "%s,%s,%.0f,%.3f,%.6g,%.3f,%.3f\n", drift_effect_name(curves[c].effect),
                        method == 0 ? "aaf" : "plain_mc", p->spp, p->actual_spp, p->rmse,
                        p->sampling_ms, p->filter_ms);
            }
        }
    }
    return fclose(f) == 0;
}

// A log-log plot: one panel, both effects, AAF solid and plain MC dashed.
static bool write_svg(const char *path, const char *scene, const curve *curves, int count)
{
    double xmin = HUGE_VAL, xmax = 0.0, ymin = HUGE_VAL, ymax = 0.0;
    for (int c = 0; c < count; ++c) {
        for (int k = 0; k < MAX_SPPS; ++k) {
            const point *pts[2] = { &curves[c].aaf[k], &curves[c].plain[k] };
            for (int m = 0; m < 2; ++m) {
                if (k >= (m == 0 ? curves[c].count : curves[c].plain_count)) {
                    continue;
                }
                xmin = fmin(xmin, pts[m]->actual_spp);
                xmax = fmax(xmax, pts[m]->actual_spp);
                ymin = fmin(ymin, pts[m]->rmse);
                ymax = fmax(ymax, pts[m]->rmse);
            }
        }
    }
    // Whole decades around the data.
    double lx0 = floor(log10(xmin)), lx1 = ceil(log10(xmax)), ly0 = floor(log10(ymin)),
           ly1 = ceil(log10(ymax));
    lx1 = lx1 > lx0 ? lx1 : lx0 + 1.0;
    ly1 = ly1 > ly0 ? ly1 : ly0 + 1.0;
    const double W = 560, H = 400, left = 70, right = 20, top = 40, bottom = 50;
    FILE *f = fopen(path, "w");
    if (!f) {
        fprintf(stderr, "drift bench aaf: cannot write %s\n", path);
        return false;
    }
#define PX(v) (left + (log10(v) - lx0) / (lx1 - lx0) * (W - left - right))
#define PY(v) (top + (ly1 - log10(v)) / (ly1 - ly0) * (H - top - bottom))
    fprintf(f,
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\" "
            "font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%%\" height=\"100%%\" "
            "fill=\"white\"/>\n",
            W, H);
    const char *base = strrchr(scene, '/');
    fprintf(f, "<text x=\"%.0f\" y=\"20\" font-size=\"14\">RMSE vs average spp: %s</text>\n", left,
            base ? base + 1 : scene);
    for (double d = lx0; d <= lx1; d += 1.0) {
        double x = PX(pow(10.0, d));
        fprintf(f,
                "<line x1=\"%.1f\" y1=\"%.0f\" x2=\"%.1f\" y2=\"%.0f\" stroke=\"#ddd\"/>\n"
                "<text x=\"%.1f\" y=\"%.0f\" text-anchor=\"middle\">%g</text>\n",
                x, top, x, H - bottom, x, H - bottom + 16, pow(10.0, d));
    }
    for (double d = ly0; d <= ly1; d += 1.0) {
        double y = PY(pow(10.0, d));
        fprintf(f,
                "<line x1=\"%.0f\" y1=\"%.1f\" x2=\"%.0f\" y2=\"%.1f\" stroke=\"#ddd\"/>\n"
                "<text x=\"%.0f\" y=\"%.1f\" text-anchor=\"end\">1e%.0f</text>\n",
                left, y, W - right, y, left - 6, y + 4, d);
    }
    fprintf(f,
            "<rect x=\"%.0f\" y=\"%.0f\" width=\"%.0f\" height=\"%.0f\" fill=\"none\" "
            "stroke=\"black\"/>\n",
            left, top, W - left - right, H - top - bottom);
    fprintf(f,
            "<text x=\"%.0f\" y=\"%.0f\" text-anchor=\"middle\">average samples per pixel</text>\n",
            (left + W - right) / 2, H - 12);
    fprintf(f,
            "<text x=\"16\" y=\"%.0f\" transform=\"rotate(-90 16 %.0f)\" "
            "text-anchor=\"middle\">RMSE</text>\n",
            (top + H - bottom) / 2, (top + H - bottom) / 2);
    static const char *const colours[] = { "#1f63c6", "#c62f1f" };
    for (int c = 0; c < count; ++c) {
        for (int m = 0; m < 2; ++m) {
            const char *colour = colours[m];
            fprintf(f, "<polyline fill=\"none\" stroke=\"%s\" stroke-width=\"2\"%s points=\"",
                    colour,
                    curves[c].effect != DRIFT_EFFECT_SHADOWS ? " stroke-dasharray=\"6 4\"" : "");
            int n = m == 0 ? curves[c].count : curves[c].plain_count;
            for (int k = 0; k < n; ++k) {
                const point *p = m == 0 ? &curves[c].aaf[k] : &curves[c].plain[k];
                fprintf(f, "%.1f,%.1f ", PX(p->actual_spp), PY(p->rmse));
            }
            fprintf(f, "\"/>\n");
            for (int k = 0; k < n; ++k) {
                const point *p = m == 0 ? &curves[c].aaf[k] : &curves[c].plain[k];
                fprintf(f, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"3\" fill=\"%s\"/>\n",
                        PX(p->actual_spp), PY(p->rmse), colour);
            }
            double ly = top + 16 + 16 * (2 * c + m);
            fprintf(f,
                    "<line x1=\"%.0f\" y1=\"%.0f\" x2=\"%.0f\" y2=\"%.0f\" stroke=\"%s\" "
                    "stroke-width=\"2\"%s/>"
                    "<text x=\"%.0f\" y=\"%.0f\">%s %s</text>\n",
                    W - right - 190, ly, W - right - 160, ly, colour,
                    curves[c].effect != DRIFT_EFFECT_SHADOWS ? " stroke-dasharray=\"6 4\"" : "",
                    W - right - 154, ly + 4, drift_effect_name(curves[c].effect),
                    m == 0 ? "AAF" : "plain MC");
        }
    }
#undef PX
#undef PY
    fprintf(f, "</svg>\n");
    return fclose(f) == 0;
}

static bool print_json(const aaf_options *o, const char *scene_path, int threads,
                       const curve *curves, int count)
{
    cJSON *root = cJSON_CreateObject();
    cJSON_AddStringToObject(root, "scene", scene_path);
    cJSON_AddNumberToObject(root, "width", (double)o->width);
    cJSON_AddNumberToObject(root, "height", (double)o->height);
    cJSON_AddNumberToObject(root, "ref_spp", (double)o->ref_spp);
    cJSON_AddStringToObject(root, "reference", o->ref_plain ? "plain" : "path");
    cJSON_AddBoolToObject(root, "aaf_filter", !o->aaf_unfiltered);
    cJSON_AddNumberToObject(root, "threads", threads);
    cJSON_AddNumberToObject(root, "light_samples", (double)o->light_samples);
    cJSON_AddStringToObject(root, "sampler", o->random ? "random" : "sobol");
    cJSON *effects = cJSON_AddArrayToObject(root, "effects");
    for (int c = 0; c < count; ++c) {
        const curve *cv = &curves[c];
        cJSON *effect = cJSON_CreateObject();
        cJSON_AddItemToArray(effects, effect);
        cJSON_AddStringToObject(effect, "effect", drift_effect_name(cv->effect));
        cJSON *aaf = cJSON_AddArrayToObject(effect, "aaf");
        for (int k = 0; k < cv->count; ++k) {
            cJSON *item = cJSON_CreateObject();
            cJSON_AddItemToArray(aaf, item);
            cli_json_number(item, "spp", cv->aaf[k].spp, 0);
            cli_json_number(item, "actual_spp", cv->aaf[k].actual_spp, 3);
            cli_json_number(item, "rmse", cv->aaf[k].rmse, -1);
            cli_json_number(item, "equal_error_ratio", cv->ratio[k], 3);
            cli_json_number(item, "mean_ratio", cv->aaf[k].mean_ratio, 4);
            cJSON_AddBoolToObject(item, "extrapolated", cv->extrapolated[k]);
        }
        cJSON *plain = cJSON_AddArrayToObject(effect, "plain_mc");
        for (int k = 0; k < cv->plain_count; ++k) {
            cJSON *item = cJSON_CreateObject();
            cJSON_AddItemToArray(plain, item);
            cli_json_number(item, "spp", cv->plain[k].spp, 0);
            cli_json_number(item, "rmse", cv->plain[k].rmse, -1);
            cli_json_number(item, "mean_ratio", cv->plain[k].mean_ratio, 4);
        }
        cJSON *timing = cJSON_AddObjectToObject(effect, "timing");
        cJSON_AddNumberToObject(timing, "width", (double)o->timing_width);
        cJSON_AddNumberToObject(timing, "height", (double)o->timing_height);
        cJSON_AddNumberToObject(timing, "spp", (double)o->timing_spp);
        cli_json_number(timing, "sampling_ms", cv->timing_sampling_ms, 3);
        cli_json_number(timing, "filter_ms", cv->timing_filter_ms, 3);
        cli_json_number(timing, "frame_ms", cv->timing_frame_ms, 3);
        cli_json_number(timing, "filter_fraction", cv->timing_filter_ms / cv->timing_frame_ms, 4);
    }
    return cli_json_write("bench aaf", root, NULL);
}

static void print_text(const aaf_options *o, const char *scene_path, int threads,
                       const curve *curves, int count)
{
    printf("%s, %ldx%ld, reference %ld spp (%s), %d thread(s), %s sampler%s\n", scene_path,
           o->width, o->height, o->ref_spp, o->ref_plain ? "plain MC" : "path-traced", threads,
           o->random ? "random" : "sobol", o->aaf_unfiltered ? ", AAF's filter off" : "");
    for (int c = 0; c < count; ++c) {
        const curve *cv = &curves[c];
        printf("\n%s\n%8s %10s %12s %10s %9s\n", drift_effect_name(cv->effect), "spp", "aaf spp",
               "aaf rmse", "ratio", "mean/ref");
        for (int k = 0; k < cv->count; ++k) {
            printf("%8.0f %10.2f %12.4g %9.2fx %9.4f%s\n", cv->aaf[k].spp, cv->aaf[k].actual_spp,
                   cv->aaf[k].rmse, cv->ratio[k], cv->aaf[k].mean_ratio,
                   cv->extrapolated[k] ? " (extrapolated)" : "");
        }
        printf("plain MC (rmse, mean/ref):");
        for (int k = 0; k < cv->plain_count; ++k) {
            printf(" %.0f spp %.4g %.4f%s", cv->plain[k].spp, cv->plain[k].rmse,
                   cv->plain[k].mean_ratio, k + 1 < cv->plain_count ? "," : "\n");
        }
        printf("timing %ldx%ld at %ld spp: sampling %.1f ms, filter %.1f ms, frame %.1f ms "
               "(filter %.1f%% of the frame)\n",
               o->timing_width, o->timing_height, o->timing_spp, cv->timing_sampling_ms,
               cv->timing_filter_ms, cv->timing_frame_ms,
               100.0 * cv->timing_filter_ms / cv->timing_frame_ms);
    }
}

int drift_bench_aaf(int argc, char **argv)
{
    aaf_options o;
    int status = parse(argc, argv, &o);
    if (status != 0) {
        return cli_parse_exit(status);
    }
    int exit_code = 1;
    cli_session session;
    bool opened =
        bench_open(&session, "bench aaf", o.scene_path, "scenes/grids/grids.json", o.threads);
    if (!sweep_gather(NULL, 0, 0, 0, opened)) { // under mpirun: every rank, or none, goes on
        goto done;
    }
    drift_context *ctx = session.ctx;
    const char *scene_path = session.scene_path;
    drift_result r = DRIFT_OK;
    curve curves[3];
    static effect_run runs[3];
    int count = 0;
    drift_effect effects[3] = { DRIFT_EFFECT_SHADOWS, DRIFT_EFFECT_INDIRECT,
                                DRIFT_EFFECT_REFLECTIONS };
    bool wanted[3] = { o.shadows, o.indirect, o.reflections };
    for (int e = 0; e < 3; ++e) { // every rank's renders first, then the comparisons
        if (wanted[e]) {
            runs[count].effect = effects[e];
            if (r == DRIFT_OK) {
                r = measure_render(ctx, session.scene, session.accel, &o, count, &runs[count],
                                   &curves[count]);
            }
            ++count;
        }
    }
    for (int c = 0; c < count; ++c) {
        drift_result compared = measure_compare(ctx, &o, &runs[c], r == DRIFT_OK, &curves[c]);
        if (r == DRIFT_OK && compared != DRIFT_OK) {
            r = DRIFT_ERR_CANCELLED; // another rank failed: rank 0 named it
        }
    }
    for (int c = 0; c < count; ++c) {
        effect_run_free(ctx, &runs[c]);
    }
    if (r != DRIFT_OK) {
        if (r != DRIFT_ERR_CANCELLED) {
            fprintf(stderr, "drift bench aaf: %s\n", drift_result_string(r));
        }
        goto done;
    }
    int threads = drift_context_thread_count(ctx);
    if (sweep_rank() != 0) { // rank 0 prints and writes the figures it gathered
        exit_code = 0;
        goto done;
    }
    if (o.json) {
        if (!print_json(&o, scene_path, threads, curves, count)) {
            goto done;
        }
    } else {
        print_text(&o, scene_path, threads, curves, count);
    }
    if ((o.csv_path && !write_csv(o.csv_path, curves, count)) ||
        (o.svg_path && !write_svg(o.svg_path, scene_path, curves, count))) {
        goto done;
    }
    exit_code = 0;
done:
    cli_session_close(&session);
    return exit_code;
}
