// drift diff: compares a test image against a reference with MSE, RMSE, relMSE, PSNR, SSIM
// and LDR-FLIP (docs/metrics.md), optionally writing the FLIP error as a magma heat map.
#include "cli.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "drift/image.h"
#include "drift/image_io.h"
#include "drift/metric.h"

static void print_usage(FILE *out)
{
    fprintf(out,
            "usage: drift diff REF TEST [options]\n"
            "\n"
            "Compares TEST against the reference REF (.exr, .png, .jpg, .jpeg, .hdr; same size)\n"
            "and prints one line per metric: mse, rmse, relmse, psnr (dB, peak 1.0), ssim, flip.\n"
            "\n"
            "options:\n"
            "  --heatmap FILE.png  write the per-pixel FLIP error as a magma heat map\n"
            "  --json              print {\"mse\":..,\"rmse\":..,\"relmse\":..,\"psnr\":..,\n"
            "                      \"ssim\":..,\"flip\":..}; psnr is null for identical images\n"
            "  --difftol X         exit with status 1 when FLIP > X\n"
            "  --ppd P             FLIP pixels per degree (default %.2f)\n"
            "  -v, --verbose       more log output\n"
            "  -h, --help          this text\n"
            "\n"
            "exit status: 0 ok, 1 error or FLIP over --difftol, 2 usage error\n",
            DRIFT_METRIC_DEFAULT_PPD);
}

static void print_number(const char *key, double v, bool json, bool last)
{
    if (json) {
        if (isfinite(v)) {
            printf("\"%s\": %.17g%s", key, v, last ? "" : ", ");
        } else {
            printf("\"%s\": null%s", key, last ? "" : ", ");
        }
    } else if (isinf(v) && v > 0.0) {
        printf("%-7s inf\n", key);
    } else {
        printf("%-7s %.9g\n", key, v);
    }
}

int drift_cmd_diff(int argc, char **argv)
{
    const char *paths[2] = { NULL, NULL };
    int path_count = 0;
    const char *heatmap_path = NULL;
    bool json = false, verbose = false, has_tol = false;
    double difftol = 0.0, ppd = 0.0;
    for (int i = 1; i < argc; ++i) {
        const char *a = argv[i];
        if (strcmp(a, "-h") == 0 || strcmp(a, "--help") == 0) {
            print_usage(stdout);
            return 0;
        } else if (strcmp(a, "--json") == 0) {
            json = true;
        } else if (strcmp(a, "-v") == 0 || strcmp(a, "--verbose") == 0) {
            verbose = true;
        } else if (strcmp(a, "--heatmap") == 0) {
            if (!(heatmap_path = cli_next_value("diff", argc, argv, &i))) {
                return 2;
            }
        } else if (strcmp(a, "--difftol") == 0) {
            const char *v = cli_next_value("diff", argc, argv, &i);
            if (!v || !cli_parse_float("diff", "--difftol", v, 0.0, 1.0, &difftol)) {
                return 2;
            }
            has_tol = true;
        } else if (strcmp(a, "--ppd") == 0) {
            const char *v = cli_next_value("diff", argc, argv, &i);
            if (!v || !cli_parse_float("diff", "--ppd", v, 1.0, 2000.0, &ppd)) {
                return 2;
            }
        } else if (a[0] == '-' && a[1] != '\0') {
            fprintf(stderr, "drift diff: unknown option '%s' (see drift diff --help)\n", a);
            return 2;
        } else if (path_count < 2) {
            paths[path_count++] = a;
        } else {
            fprintf(stderr, "drift diff: too many arguments (see drift diff --help)\n");
            return 2;
        }
    }
    if (path_count != 2) {
        print_usage(stderr);
        return 2;
    }

    drift_context *ctx = cli_open_context("diff", 0, verbose);
    if (!ctx) {
        return 1;
    }
    drift_result r = DRIFT_OK;
    int status = 1;
    drift_image ref = { 0 }, test = { 0 }, flip_map = { 0 }, heat = { 0 };
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
    r = drift_metric_compare(ctx, &ref, &test, &(drift_metric_params){ .ppd = ppd }, &rep,
                             heatmap_path ? &flip_map : NULL);
    if (r != DRIFT_OK) {
        fprintf(stderr, "drift diff: %s\n", drift_result_string(r));
        goto done;
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
    if (json) {
        printf("{");
    }
    print_number("mse", rep.mse, json, false);
    print_number("rmse", rep.rmse, json, false);
    print_number("relmse", rep.relmse, json, false);
    print_number("psnr", rep.psnr, json, false);
    print_number("ssim", rep.ssim, json, false);
    print_number("flip", rep.flip, json, true);
    if (json) {
        printf("}\n");
    }
    status = 0;
    if (has_tol && rep.flip > difftol) {
        fprintf(stderr, "drift diff: FLIP %.6f exceeds --difftol %g\n", rep.flip, difftol);
        status = 1;
    }
done:
    drift_image_destroy(ctx, &heat);
    drift_image_destroy(ctx, &flip_map);
    drift_image_destroy(ctx, &test);
    drift_image_destroy(ctx, &ref);
    drift_context_destroy(ctx);
    return status;
}
