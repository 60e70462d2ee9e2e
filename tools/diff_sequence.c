// drift diff --frames A:B: per-frame LDR-FLIP of a test sequence against its reference frames,
// and the temporal error, the flicker a viewer sees that the reference does not have:
//   e_k(p)        = Y(srgb(test_k(p))) - Y(srgb(ref_k(p)))        (display values in [0, 1])
//   temporal_k    = mean_p |e_k(p) - e_{k-1}(p)|                  (k > A)
// A sequence that is wrong the same way in every frame has no temporal error; noise that
// changes from frame to frame does. Printed per frame and as means, as JSON with --json, and
// as an SVG plot with --plot.
#include "diff_sequence.h"

#include "cli.h"
#include "drift/image.h"
#include "drift/image_io.h"
#include "drift/metric.h"
#include "frame_pattern.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct frame_result {
    long frame;
    double flip, temporal; // temporal: NAN for the first frame
} frame_result;

// The display luminance difference test - reference per pixel (sRGB values, clamped).
static void display_error(const drift_image *ref, const drift_image *test, uint8_t *ref8,
                          uint8_t *test8, float *out)
{
    drift_tonemap_params tm = { 0 };
    drift_image_tonemap(ref, &tm, ref8);
    drift_image_tonemap(test, &tm, test8);
    size_t n = (size_t)ref->width * (size_t)ref->height;
    for (size_t i = 0; i < n; ++i) {
        drift_vec3 d = drift_vec3_make((float)test8[3 * i] - (float)ref8[3 * i],
                                       (float)test8[3 * i + 1] - (float)ref8[3 * i + 1],
                                       (float)test8[3 * i + 2] - (float)ref8[3 * i + 2]);
        out[i] = drift_luminance(d) / 255.0f;
    }
}

static bool write_plot(const char *path, const frame_result *r, size_t count)
{
    FILE *f = fopen(path, "w");
    if (!f) {
        return false;
    }
    const double w = 640.0, h = 320.0, m = 40.0;
    double top = 1e-6;
    for (size_t k = 0; k < count; ++k) {
        top = fmax(top, r[k].flip);
        top = isnan(r[k].temporal) ? top : fmax(top, r[k].temporal);
    }
    fprintf(f,
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%g\" height=\"%g\" "
            "font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%%\" height=\"100%%\" "
            "fill=\"white\"/>\n<line x1=\"%g\" y1=\"%g\" x2=\"%g\" y2=\"%g\" stroke=\"black\"/>\n"
            "<line x1=\"%g\" y1=\"%g\" x2=\"%g\" y2=\"%g\" stroke=\"black\"/>\n"
            "<text x=\"%g\" y=\"%g\">%.3g</text><text x=\"%g\" y=\"%g\">frame %ld .. %ld</text>\n",
            w, h, m, h - m, w - m, h - m, m, m, m, h - m, 2.0, m, top, w / 2 - 40, h - 10,
            r[0].frame, r[count - 1].frame);
    static const char *const colours[2] = { "#1f77b4", "#d62728" };
    static const char *const names[2] = { "FLIP", "temporal error" };
    for (int series = 0; series < 2; ++series) {
        fprintf(f, "<polyline fill=\"none\" stroke=\"%s\" stroke-width=\"1.5\" points=\"",
                colours[series]);
        for (size_t k = 0; k < count; ++k) {
            double v = series ? r[k].temporal : r[k].flip;
            if (isnan(v)) {
                continue;
            }
            double x = m + (w - 2 * m) * (count > 1 ? (double)k / (double)(count - 1) : 0.5);
            fprintf(f, "%.1f,%.1f ", x, h - m - (h - 2 * m) * v / top);
        }
        fprintf(f, "\"/>\n<text x=\"%g\" y=\"%g\" fill=\"%s\">%s</text>\n", w - m - 110.0,
                m + 16.0 * series, colours[series], names[series]);
    }
    fprintf(f, "</svg>\n");
    return fclose(f) == 0;
}

int diff_sequence(const diff_sequence_options *o)
{
    frame_pattern rp, tp;
    if (!frame_pattern_find(o->ref_pattern, &rp) || !frame_pattern_find(o->test_pattern, &tp)) {
        fprintf(stderr, "drift diff: --frames needs REF and TEST with one frame number each, "
                        "%%04d or %%d (e.g. ref/frame_%%04d.exr)\n");
        return 2;
    }
    const cli_file plot = { "--plot", o->plot_path };
    if (!cli_check_writable("diff", &plot, 1)) {
        return 1;
    }
    cli_session session;
    if (!cli_session_open(
            &(cli_session_desc){ .cmd = "diff", .verbose = o->verbose, .no_scene = true },
            &session)) {
        cli_session_close(&session);
        return 1;
    }
    drift_context *ctx = session.ctx;
    size_t count = (size_t)(o->last - o->first + 1);
    frame_result *results = calloc(count, sizeof *results);
    uint8_t *ref8 = NULL, *test8 = NULL;
    float *err = NULL, *prev_err = NULL;
    int status = 1;
    size_t nonfinite_total = 0;
    int32_t width = 0, height = 0;
    if (!results) {
        goto done;
    }
    for (long k = o->first; k <= o->last; ++k) {
        char paths[2][4096];
        frame_pattern_format(o->ref_pattern, &rp, k, paths[0], sizeof paths[0]);
        frame_pattern_format(o->test_pattern, &tp, k, paths[1], sizeof paths[1]);
        drift_image ref = { 0 }, test = { 0 };
        drift_result r = drift_image_load(ctx, paths[0], &ref);
        if (r == DRIFT_OK) {
            r = drift_image_load(ctx, paths[1], &test);
        }
        bool ok = r == DRIFT_OK;
        if (!ok) {
            fprintf(stderr, "drift diff: cannot load frame %ld ('%s', '%s'): %s\n", k, paths[0],
                    paths[1], drift_result_string(r));
        } else if (ref.width != test.width || ref.height != test.height ||
                   (width && (ref.width != width || ref.height != height))) {
            fprintf(stderr, "drift diff: frame %ld: sizes differ ('%s' %dx%d, '%s' %dx%d)\n", k,
                    paths[0], ref.width, ref.height, paths[1], test.width, test.height);
            ok = false;
        }
        if (ok && !ref8) {
            width = ref.width;
            height = ref.height;
            size_t n = (size_t)width * (size_t)height;
            ref8 = malloc(3 * n);
            test8 = malloc(3 * n);
            err = malloc(n * sizeof *err);
            prev_err = malloc(n * sizeof *prev_err);
            ok = ref8 && test8 && err && prev_err;
        }
        drift_metric_report rep = { 0 };
        size_t nonfinite = 0;
        if (ok) {
            r = cli_compare_images(ctx, &ref, &test, o->ppd, &rep, NULL, &nonfinite);
            nonfinite_total += nonfinite;
            if (r != DRIFT_OK) {
                fprintf(stderr, "drift diff: frame %ld: %s\n", k, drift_result_string(r));
                ok = false;
            }
        }
        frame_result *fr = &results[k - o->first];
        if (ok) {
            display_error(&ref, &test, ref8, test8, err);
            fr->frame = k;
            fr->flip = rep.flip;
            fr->temporal = (double)NAN;
            if (k > o->first) {
                size_t n = (size_t)width * (size_t)height;
                double sum = 0.0;
                for (size_t i = 0; i < n; ++i) {
                    sum += fabs((double)err[i] - (double)prev_err[i]);
                }
                fr->temporal = sum / (double)n;
            }
            float *swap = err;
            err = prev_err;
            prev_err = swap;
        }
        drift_image_destroy(ctx, &test);
        drift_image_destroy(ctx, &ref);
        if (!ok) {
            goto done;
        }
    }
    double mean_flip = 0.0, mean_temporal = 0.0, max_flip = 0.0;
    for (size_t k = 0; k < count; ++k) {
        mean_flip += results[k].flip / (double)count;
        max_flip = fmax(max_flip, results[k].flip);
        if (k > 0) {
            mean_temporal += results[k].temporal / (double)(count - 1);
        }
    }
    if (o->json) {
        cJSON *root = cJSON_CreateObject();
        cJSON *frames = cJSON_AddArrayToObject(root, "frames");
        for (size_t k = 0; k < count; ++k) {
            cJSON *e = cJSON_CreateObject();
            cJSON_AddItemToArray(frames, e);
            cJSON_AddNumberToObject(e, "frame", (double)results[k].frame);
            cli_json_number(e, "flip", results[k].flip, -1);
            if (k > 0) {
                cli_json_number(e, "temporal_error", results[k].temporal, -1);
            } else {
                cJSON_AddNullToObject(e, "temporal_error");
            }
        }
        cli_json_number(root, "mean_flip", mean_flip, -1);
        cli_json_number(root, "max_flip", max_flip, -1);
        cli_json_number(root, "mean_temporal_error", mean_temporal, -1);
        cli_json_count(root, "nonfinite", nonfinite_total);
        if (!cli_json_write("diff", root, NULL)) {
            goto done;
        }
    } else {
        for (size_t k = 0; k < count; ++k) {
            printf("frame %-6ld flip %.6f", results[k].frame, results[k].flip);
            if (k > 0) {
                printf("  temporal_error %.6f", results[k].temporal);
            }
            printf("\n");
        }
        printf("mean_flip           %.9g\nmax_flip            %.9g\nmean_temporal_error "
               "%.9g\nnonfinite           %zu\n",
               mean_flip, max_flip, mean_temporal, nonfinite_total);
    }
    if (o->plot_path && !write_plot(o->plot_path, results, count)) {
        fprintf(stderr, "drift diff: cannot write --plot %s\n", o->plot_path);
        goto done;
    }
    status = nonfinite_total > 0 && !o->ignore_nonfinite ? 1 : 0;
    if (status == 0 && o->difftol >= 0.0 && mean_flip > o->difftol) {
        fprintf(stderr, "drift diff: mean FLIP %.6f exceeds --difftol %g\n", mean_flip, o->difftol);
        status = 1;
    }
done:
    free(prev_err);
    free(err);
    free(test8);
    free(ref8);
    free(results);
    cli_session_close(&session);
    return status;
}
