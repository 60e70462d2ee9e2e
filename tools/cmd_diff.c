// drift diff: compares a test image against a reference with MSE, RMSE, relMSE, PSNR, SSIM
// and LDR-FLIP (docs/metrics.md), optionally writing the FLIP error as a magma heat map.
#include "cli.h"
#include "diff_sequence.h"
#include "drift/image.h"
#include "drift/image_io.h"
#include "drift/metric.h"
#include "frame_pattern.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

typedef struct diff_options {
    const char *paths[2]; // REF TEST
    const char *heatmap_path;
    const char *mask_path; // --mask: per-object metrics over its pixels
    bool json, verbose, ignore_nonfinite;
    double difftol; // < 0: none
    double ppd;     // 0: DRIFT_METRIC_DEFAULT_PPD
    bool frames;    // --frames A:B: REF and TEST are frame patterns (tools/diff_sequence.c)
    long first, last;
    const char *plot_path;
} diff_options;

static bool parse_frames(const char *cmd, const char *flag, const char *v, void *field)
{
    diff_options *o = field;
    o->frames = frame_range_parse(cmd, flag, v, &o->first, &o->last);
    return o->frames;
}

#define O diff_options
static const cli_option diff_table[] = {
    CLI_SECTION("options:", 0),
    CLI_STRING("--heatmap", "FILE.png", O, heatmap_path,
               "write the per-pixel FLIP error as a magma heat map"),
    CLI_STRING("--mask", "FILE", O, mask_path,
               "compare only the pixels where FILE's first channel is >= 0.5\n"
               "(an object's coverage, bench/cycles/gltf_object_masks.py):\n"
               "flip is the mean of the whole image's per-pixel FLIP there,\n"
               "mse, rmse, relmse and psnr are theirs, ssim is left out, and\n"
               "mask_pixels and luminance (TEST's mean luminance / REF's)\n"
               "are added"),
    CLI_FLAG("--json", O, json,
             "print {\"mse\":..,\"rmse\":..,\"relmse\":..,\"psnr\":..,\n"
             "\"ssim\":..,\"flip\":..,\"nonfinite\":..}; psnr is null for identical\n"
             "images"),
    CLI_FLAG("--ignore-nonfinite", O, ignore_nonfinite,
             "accept NaN or infinite pixels (exit 0): the metrics are over the\n"
             "finite pixels (without it such pixels make the exit status 1)"),
    CLI_NUMBER("--difftol", "X", O, difftol, 0.0, 1.0, "exit with status 1 when FLIP > X"),
    CLI_NUMBER("--ppd", "P", O, ppd, 1.0, 2000.0,
               "FLIP pixels per degree (default " CLI_STR(DRIFT_METRIC_DEFAULT_PPD) ")"),
    CLI_CUSTOM_ALL("--frames", "A:B", parse_frames,
                   "REF and TEST are frame patterns (frame_%04d.exr): per-frame\n"
                   "FLIP and the temporal error, the frame-to-frame change of\n"
                   "TEST - REF (docs/temporal.md)"),
    CLI_STRING("--plot", "FILE.svg", O, plot_path,
               "--frames: per-frame FLIP and temporal error as an SVG plot"),
    CLI_FLAG("-v, --verbose", O, verbose, "more log output"),
};
#undef O

static const cli_command diff_command = {
    .name = "diff",
    .usage = "usage: drift diff REF TEST [options]\n"
             "\n"
             "Compares TEST against the reference REF (.exr, .png, .jpg, .jpeg, .hdr; same size)\n"
             "and prints one line per metric: mse, rmse, relmse, psnr (dB, peak 1.0), ssim, flip,\n"
             "and nonfinite: the pixels that are NaN or infinite in either image.\n"
             "\n",
    .epilogue =
        "\nexit status: 0 ok, 1 error, FLIP over --difftol or NaN/infinite pixels (without\n"
        "--ignore-nonfinite), 2 usage error\n",
    CLI_TABLE(diff_table),
    CLI_POSITIONAL("REF TEST", diff_options, paths, 2),
    .help_column = 22,
};

// The metrics over the pixels of `mask` whose first channel is >= 0.5 (drift diff --mask): FLIP
// as the mean of the whole image's map there (its filters see the object's surroundings, as
// they do in the full image), the per-pixel errors of metric.c, and the mean luminance ratio.
// Returns the number of pixels selected.
static size_t masked_report(const drift_image *ref, const drift_image *test,
                            const drift_image *flip_map, const drift_image *mask,
                            drift_metric_report *rep, double *lum_ratio)
{
    double se = 0.0, rel = 0.0, flip = 0.0, lum_ref = 0.0, lum_test = 0.0;
    size_t n = 0;
    for (int32_t y = 0; y < ref->height; ++y) {
        for (int32_t x = 0; x < ref->width; ++x) {
            if (!(drift_image_pixel(mask, x, y)[0] >= 0.5f)) {
                continue;
            }
            drift_vec3 r = drift_image_get3(ref, x, y), t = drift_image_get3(test, x, y);
            const float rc[3] = { r.x, r.y, r.z }, tc[3] = { t.x, t.y, t.z };
            for (int c = 0; c < 3; ++c) {
                double d = (double)tc[c] - (double)rc[c];
                se += d * d;
                rel += d * d / ((double)rc[c] * (double)rc[c] + 0.01);
            }
            flip += (double)drift_image_pixel(flip_map, x, y)[0];
            lum_ref += (double)drift_luminance(r);
            lum_test += (double)drift_luminance(t);
            ++n;
        }
    }
    if (n == 0) {
        return 0;
    }
    rep->mse = se / (3.0 * (double)n);
    rep->rmse = sqrt(rep->mse);
    rep->relmse = rel / (3.0 * (double)n);
    rep->psnr = rep->mse > 0.0 ? 10.0 * log10(1.0 / rep->mse) : HUGE_VAL;
    rep->ssim = (double)NAN;
    rep->flip = flip / (double)n;
    *lum_ratio = lum_ref > 0.0 ? lum_test / lum_ref : (double)NAN;
    return n;
}

static void print_number(const char *key, double v)
{
    if (isinf(v) && v > 0.0) {
        printf("%-7s inf\n", key);
    } else {
        printf("%-7s %.9g\n", key, v);
    }
}

int drift_cmd_diff(int argc, char **argv)
{
    diff_options o = { .difftol = -1.0 };
    int status = cli_parse(&diff_command, argc, argv, &o, NULL);
    if (status != CLI_PARSED) {
        return cli_parse_exit(status);
    }
    if (!o.paths[1]) {
        cli_print_help(&diff_command, stderr);
        return 2;
    }
    if (o.frames || o.plot_path) {
        if (!o.frames || o.heatmap_path || o.mask_path) {
            fprintf(stderr, "drift diff: %s\n",
                    o.frames ? "--heatmap and --mask are for one image pair, not --frames"
                             : "--plot needs --frames A:B");
            return 2;
        }
        return diff_sequence(&(diff_sequence_options){ .ref_pattern = o.paths[0],
                                                       .test_pattern = o.paths[1],
                                                       .first = o.first,
                                                       .last = o.last,
                                                       .ppd = o.ppd,
                                                       .difftol = o.difftol,
                                                       .json = o.json,
                                                       .verbose = o.verbose,
                                                       .ignore_nonfinite = o.ignore_nonfinite,
                                                       .plot_path = o.plot_path });
    }
    const char *paths[2] = { o.paths[0], o.paths[1] };
    const char *heatmap_path = o.heatmap_path;
    const cli_file inputs[3] = { { "REF", paths[0] },
                                 { "TEST", paths[1] },
                                 { "--mask", o.mask_path } };
    const cli_file heatmap = { "--heatmap", heatmap_path };
    if (!cli_check_outputs("diff", inputs, o.mask_path ? 3 : 2, &heatmap, 1)) {
        return 2;
    }
    if (!cli_check_writable("diff", &heatmap, 1)) {
        return 1;
    }
    cli_session session;
    if (!cli_session_open(
            &(cli_session_desc){ .cmd = "diff", .verbose = o.verbose, .no_scene = true },
            &session)) {
        cli_session_close(&session);
        return 1;
    }
    drift_context *ctx = session.ctx;
    drift_result r = DRIFT_OK;
    status = 1;
    drift_image ref = { 0 }, test = { 0 }, flip_map = { 0 }, heat = { 0 }, mask = { 0 };
    drift_metric_report rep;
    if ((r = drift_image_load(ctx, paths[0], &ref)) != DRIFT_OK) {
        fprintf(stderr, "drift diff: cannot load reference '%s': %s\n", paths[0],
                drift_result_string(r));
        goto done;
    }
    if ((r = drift_image_load(ctx, paths[1], &test)) != DRIFT_OK) {
        fprintf(stderr, "drift diff: cannot load test image '%s': %s\n", paths[1],
                drift_result_string(r));
        goto done;
    }
    if (ref.width != test.width || ref.height != test.height) {
        fprintf(stderr, "drift diff: sizes differ: '%s' is %dx%d, '%s' is %dx%d\n", paths[0],
                ref.width, ref.height, paths[1], test.width, test.height);
        goto done;
    }
    if (o.mask_path) {
        if ((r = drift_image_load(ctx, o.mask_path, &mask)) != DRIFT_OK) {
            fprintf(stderr, "drift diff: cannot load mask '%s': %s\n", o.mask_path,
                    drift_result_string(r));
            goto done;
        }
        if (mask.width != ref.width || mask.height != ref.height) {
            fprintf(stderr, "drift diff: the mask '%s' is %dx%d, the images %dx%d\n", o.mask_path,
                    mask.width, mask.height, ref.width, ref.height);
            goto done;
        }
    }
    size_t pixels = (size_t)ref.width * (size_t)ref.height, nonfinite = 0;
    r = cli_compare_images(ctx, &ref, &test, o.ppd, &rep,
                           heatmap_path || o.mask_path ? &flip_map : NULL, &nonfinite);
    if (r != DRIFT_OK && nonfinite == pixels) {
        fprintf(stderr, "drift diff: every pixel of '%s' or '%s' is NaN or infinite\n", paths[0],
                paths[1]);
        goto done;
    }
    if (r != DRIFT_OK) {
        fprintf(stderr, "drift diff: %s\n", drift_result_string(r));
        goto done;
    }
    if (nonfinite > 0) {
        fprintf(stderr,
                "drift diff: %zu of %zu pixels are NaN or infinite in '%s' or '%s'; the metrics "
                "are over the %zu finite pixels (ssim and flip with the others set to 0 in "
                "both)%s\n",
                nonfinite, pixels, paths[0], paths[1], pixels - nonfinite,
                o.ignore_nonfinite ? "" : "; exit status 1 (--ignore-nonfinite accepts them)");
    }
    if (heatmap_path) {
        r = drift_metric_flip_heatmap(ctx, &flip_map, &heat);
        if (r == DRIFT_OK) {
            r = drift_image_save_png(ctx, heatmap_path, &heat, NULL);
        }
        if (r != DRIFT_OK) {
            fprintf(stderr, "drift diff: cannot write heat map '%s': %s\n", heatmap_path,
                    drift_result_string(r));
            goto done;
        }
    }
    size_t mask_pixels = 0;
    double lum_ratio = 0.0;
    if (o.mask_path) {
        mask_pixels = masked_report(&ref, &test, &flip_map, &mask, &rep, &lum_ratio);
        if (mask_pixels == 0) {
            fprintf(stderr, "drift diff: the mask '%s' selects no pixel (none is >= 0.5)\n",
                    o.mask_path);
            goto done;
        }
    }
    const char *const keys[7] = { "mse", "rmse", "relmse", "psnr", "ssim", "flip", "luminance" };
    const double values[7] = { rep.mse,  rep.rmse, rep.relmse, rep.psnr,
                               rep.ssim, rep.flip, lum_ratio };
    cJSON *root = o.json ? cJSON_CreateObject() : NULL;
    for (int k = 0; k < 7; ++k) {
        if ((k == 4 && o.mask_path) || (k == 6 && !o.mask_path)) {
            continue; // no SSIM map to average over a mask; the ratio only with one
        }
        if (root) {
            cli_json_number(root, keys[k], values[k], -1);
        } else {
            print_number(keys[k], values[k]);
        }
    }
    if (root) {
        cli_json_count(root, "nonfinite", nonfinite);
        if (o.mask_path) {
            cli_json_count(root, "mask_pixels", mask_pixels);
        }
    } else {
        printf("%-7s %zu\n", "nonfinite", nonfinite);
        if (o.mask_path) {
            printf("%-7s %zu\n", "mask_pixels", mask_pixels);
        }
    }
    if (root && !cli_json_write("diff", root, NULL)) {
        goto done;
    }
    status = nonfinite > 0 && !o.ignore_nonfinite ? 1 : 0;
    if (status == 0 && o.difftol >= 0.0 && rep.flip > o.difftol) {
        fprintf(stderr, "drift diff: FLIP %.6f exceeds --difftol %g\n", rep.flip, o.difftol);
        status = 1;
    }
done:
    drift_image_destroy(ctx, &mask);
    drift_image_destroy(ctx, &heat);
    drift_image_destroy(ctx, &flip_map);
    drift_image_destroy(ctx, &test);
    drift_image_destroy(ctx, &ref);
    cli_session_close(&session);
    return status;
}
