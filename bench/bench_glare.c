// drift bench glare: the thesis's Table 8.2 on this CPU (Ritschel 2009, §8.6) and the cost of
// the whole glare pass per frame.
//   (a) per PSF size N in {256, 512, 1024}: milliseconds of the aperture (eye update, pose and
//       rasterising at 2N with coverage, box-downsampled), the diffraction (P E, one N x N FFT,
//       |F|^2, normalise, fftshift) and the display step (the 32-wavelength chromatic sum to
//       XYZ and RGB), the least of --frames runs each; the thesis's "display" also drew the
//       result, which here is the convolution, timed apart:
//   (b) the convolution of a 1920x1080 frame with the N x N RGB PSF (zero-padded FFTs);
//   (c) drift_glare_apply per frame, dynamic mode, PSF 256, on 640x480 (the hybrid frame's
//       size), 512x512 and 1024x1024 images of 16 lights on a dim field, and the billboard
//       path at 640x480.
// One thread: nothing in src/glare runs in parallel yet.
#include "bench.h"
#include "cli.h"
#include "drift/glare.h"
#include "glare/glare_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void print_help(FILE *out)
{
    fprintf(out, "usage: drift bench glare [--frames N] [--sizes N,N,...] [--no-convolution]\n"
                 "                         [--json]\n\n"
                 "(a) aperture, diffraction and display ms per PSF size (Table 8.2 of the "
                 "thesis;\n"
                 "    2x2 supersampling, 32 wavelengths), (b) the convolution of a 1920x1080 "
                 "frame\n"
                 "    with that PSF, (c) ms a frame of drift_glare_apply (dynamic, PSF 256) on "
                 "640x480,\n"
                 "    512^2 and 1024^2 images. One thread.\n\n"
                 "  --frames N        the least of N runs per figure (default 3)\n"
                 "  --sizes LIST      PSF sizes (default 256,512,1024)\n"
                 "  --no-convolution  skip (b) and (c)\n"
                 "  --json            one JSON object on stdout\n");
}

static double least(double a, double b)
{
    return a < b ? a : b;
}

typedef struct phase_ms {
    int32_t n;
    double aperture, diffraction, display, convolution;
} phase_ms;

static drift_result time_size(drift_context *ctx, int32_t n, int32_t frames, bool convolution,
                              phase_ms *out)
{
    drift_glare_params p = drift_glare_params_resolve(
        &(drift_glare_params){ .mode = DRIFT_GLARE_MODE_DYNAMIC, .psf_size = n, .seed = 1 });
    drift__glare_scene scene;
    drift_result r = drift__glare_scene_create(ctx, &p, &scene);
    if (r != DRIFT_OK) {
        return r;
    }
    size_t nn = (size_t)n * (size_t)n, m = (size_t)n * 2;
    float *hires = malloc(m * m * sizeof(float)), *ap = malloc(nn * sizeof(float));
    float *mono = malloc(nn * sizeof(float)), *rgb = malloc(nn * 3 * sizeof(float));
    drift__cpx *scratch = malloc(2 * nn * sizeof(drift__cpx)), *e = malloc(nn * sizeof(*e));
    void *taps = malloc(drift__glare_psf_rgb_scratch(n, 1.0));
    drift__glare_fft *fft = NULL;
    drift__glare_eye_state *eye = malloc(sizeof(*eye));
    if (!hires || !ap || !mono || !rgb || !scratch || !e || !eye || !taps ||
        drift__glare_fft_create(ctx, n, n, false, &fft) != DRIFT_OK) {
        r = DRIFT_ERR_OUT_OF_MEMORY;
        goto done;
    }
    drift__glare_fresnel_table(n, p.aperture_width_mm, DRIFT_GLARE_LAMBDA_REF_NM,
                               p.fresnel_distance_mm, e);
    drift__glare_eye_init(eye, &p);
    *out = (phase_ms){ .n = n, 1e30, 1e30, 1e30, 1e30 };
    for (int32_t f = 0; f < frames; ++f) {
        double t0 = drift_time_now();
        drift__glare_eye_step(eye, &p, 1.0, f ? 1.0 / 30.0 : 0.0, true);
        drift__glare_scene_pose(&scene, eye, &p);
        drift__glare_aperture_desc ad = { .pupil_mm = eye->pub.pupil_mm,
                                          .closure = eye->pub.blink,
                                          .lids = true,
                                          .disks = scene.disks,
                                          .disk_count = scene.disk_count,
                                          .lines = scene.lines,
                                          .line_count = scene.line_count };
        drift__glare_aperture_draw(&ad, n, 2, p.aperture_width_mm, hires, ap);
        double t1 = drift_time_now();
        drift__glare_psf_mono(fft, ap, e, n, scratch, mono, NULL);
        double t2 = drift_time_now();
        drift__glare_psf_rgb(mono, n, 32, 1.0, n, taps, rgb);
        double t3 = drift_time_now();
        out->aperture = least(out->aperture, 1e3 * (t1 - t0));
        out->diffraction = least(out->diffraction, 1e3 * (t2 - t1));
        out->display = least(out->display, 1e3 * (t3 - t2));
    }
    if (convolution) {
        drift_image frame = { 0 }, res = { 0 };
        drift__glare_conv conv = { 0 };
        if ((r = drift_image_create(ctx, 1920, 1080, 3, &frame)) != DRIFT_OK ||
            (r = drift_image_create(ctx, 1920, 1080, 3, &res)) != DRIFT_OK) {
            drift_image_destroy(ctx, &frame);
            goto done;
        }
        for (int32_t f = 0; f < frames && r == DRIFT_OK; ++f) {
            double t0 = drift_time_now();
            r = drift__glare_convolve(ctx, &conv, &frame, rgb, n, true, &res);
            out->convolution = least(out->convolution, 1e3 * (drift_time_now() - t0));
        }
        drift_image_destroy(ctx, &res);
        drift__glare_conv_release(ctx, &conv);
        drift_image_destroy(ctx, &frame);
    } else {
        out->convolution = NAN;
    }
done:
    drift__glare_fft_destroy(ctx, fft);
    free(eye);
    free(taps);
    free(e);
    free(scratch);
    free(rgb);
    free(mono);
    free(ap);
    free(hires);
    drift__glare_scene_destroy(ctx, &scene);
    return r;
}

static drift_result time_apply(drift_context *ctx, int32_t width, int32_t height, int32_t frames,
                               drift_glare_method method, double *out_ms)
{
    drift_glare *g = NULL;
    drift_image in = { 0 }, out = { 0 };
    drift_result r = drift_glare_create(
        ctx, &(drift_glare_params){ .mode = DRIFT_GLARE_MODE_DYNAMIC, .seed = 1, .method = method },
        &g);
    if (r == DRIFT_OK) {
        r = drift_image_create(ctx, width, height, 3, &in);
    }
    if (r == DRIFT_OK) {
        r = drift_image_create(ctx, width, height, 3, &out);
    }
    // A dim frame with 16 small bright lights.
    for (int32_t y = 0; r == DRIFT_OK && y < height; ++y) {
        for (int32_t x = 0; x < width; ++x) {
            drift_image_set3(&in, x, y, (drift_vec3){ 0.2f, 0.2f, 0.2f });
        }
    }
    for (int32_t i = 0; r == DRIFT_OK && i < 16; ++i) {
        drift_image_set3(&in, width * (i % 4 + 1) / 5, height * (i / 4 + 1) / 5,
                         (drift_vec3){ 1e3f, 1e3f, 1e3f });
    }
    *out_ms = 1e30;
    for (int32_t f = 0; f < frames + 1 && r == DRIFT_OK; ++f) {
        double t0 = drift_time_now();
        r = drift_glare_apply_to(g, &in, f ? 1.0 / 30.0 : 0.0, &out);
        if (f > 0) { // the first frame also makes the FFT plans
            *out_ms = least(*out_ms, 1e3 * (drift_time_now() - t0));
        }
    }
    drift_image_destroy(ctx, &out);
    drift_image_destroy(ctx, &in);
    drift_glare_destroy(g);
    return r;
}

int drift_bench_glare(int argc, char **argv)
{
    long frames = 3;
    bool json = false, convolution = true;
    int32_t sizes[8] = { 256, 512, 1024 }, size_count = 3;
    for (int i = 1; i < argc; ++i) {
        const char *a = argv[i];
        if (strcmp(a, "-h") == 0 || strcmp(a, "--help") == 0) {
            print_help(stdout);
            return 0;
        } else if (strcmp(a, "--json") == 0) {
            json = true;
        } else if (strcmp(a, "--no-convolution") == 0) {
            convolution = false;
        } else if (strcmp(a, "--frames") == 0) {
            const char *v = cli_next_value("bench glare", argc, argv, &i);
            if (!v || !cli_parse_int("bench glare", "--frames", v, 1, 1000, &frames)) {
                return 2;
            }
        } else if (strcmp(a, "--sizes") == 0) {
            const char *v = cli_next_value("bench glare", argc, argv, &i);
            if (!v) {
                return 2;
            }
            size_count = 0;
            char buf[256];
            snprintf(buf, sizeof(buf), "%s", v);
            for (char *tok = strtok(buf, ","); tok; tok = strtok(NULL, ",")) {
                long s = 0;
                if (size_count == 8 ||
                    !cli_parse_int("bench glare", "--sizes", tok, 16, 4096, &s) ||
                    (s & (s - 1)) != 0) {
                    fprintf(stderr, "drift bench glare: --sizes takes up to 8 powers of two\n");
                    return 2;
                }
                sizes[size_count++] = (int32_t)s;
            }
        } else {
            fprintf(stderr, "drift bench glare: unknown option '%s'\n", a);
            return 2;
        }
    }
    cli_session session;
    if (!cli_session_open(
            &(cli_session_desc){ .cmd = "bench glare", .threads = 1, .no_scene = true },
            &session)) {
        return 1;
    }
    drift_context *ctx = session.ctx;
    phase_ms rows[8];
    double apply_ms[3] = { NAN, NAN, NAN }, billboard_ms = NAN;
    const int32_t apply_sizes[3][2] = { { 640, 480 }, { 512, 512 }, { 1024, 1024 } };
    drift_result r = DRIFT_OK;
    for (int32_t i = 0; i < size_count && r == DRIFT_OK; ++i) {
        r = time_size(ctx, sizes[i], (int32_t)frames, convolution, &rows[i]);
    }
    for (int32_t i = 0; i < 3 && convolution && r == DRIFT_OK; ++i) {
        r = time_apply(ctx, apply_sizes[i][0], apply_sizes[i][1], (int32_t)frames,
                       DRIFT_GLARE_METHOD_CONVOLUTION, &apply_ms[i]);
    }
    if (convolution && r == DRIFT_OK) {
        r = time_apply(ctx, 640, 480, (int32_t)frames, DRIFT_GLARE_METHOD_BILLBOARD, &billboard_ms);
    }
    if (r != DRIFT_OK) {
        fprintf(stderr, "drift bench glare: %s\n", drift_result_string(r));
        cli_session_close(&session);
        return 1;
    }
    if (json) {
        printf("{\"threads\": 1, \"supersample\": 2, \"wavelengths\": 32, \"sizes\": [");
        for (int32_t i = 0; i < size_count; ++i) {
            const phase_ms *p = &rows[i];
            printf("%s{\"n\": %d, \"aperture_ms\": %.3f, \"diffraction_ms\": %.3f, "
                   "\"display_ms\": %.3f, \"overall_ms\": %.3f, \"convolution_1080p_ms\": ",
                   i ? ", " : "", (int)p->n, p->aperture, p->diffraction, p->display,
                   p->aperture + p->diffraction + p->display);
            if (isfinite(p->convolution)) {
                printf("%.3f}", p->convolution);
            } else {
                printf("null}");
            }
        }
        printf("], \"apply_ms\": {");
        for (int32_t i = 0; i < 3; ++i) {
            printf("%s\"%dx%d\": ", i ? ", " : "", (int)apply_sizes[i][0], (int)apply_sizes[i][1]);
            isfinite(apply_ms[i]) ? printf("%.3f", apply_ms[i]) : printf("null");
        }
        printf("}, \"billboard_640x480_ms\": ");
        isfinite(billboard_ms) ? printf("%.3f", billboard_ms) : printf("null");
        printf("}\n");
    } else {
        printf("glare, one thread, 2x2 supersampling, 32 wavelengths (least of %ld)\n", frames);
        printf("%6s %10s %12s %10s %10s %16s\n", "N", "aperture", "diffraction", "display",
               "overall", "conv 1920x1080");
        for (int32_t i = 0; i < size_count; ++i) {
            const phase_ms *p = &rows[i];
            printf("%6d %8.1f ms %9.1f ms %7.1f ms %7.1f ms %13.1f ms\n", (int)p->n, p->aperture,
                   p->diffraction, p->display, p->aperture + p->diffraction + p->display,
                   p->convolution);
        }
        if (convolution) {
            printf("drift_glare_apply (dynamic, PSF 256): %.1f ms at 640x480, %.1f ms at 512x512, "
                   "%.1f ms at 1024x1024\n",
                   apply_ms[0], apply_ms[1], apply_ms[2]);
            printf("billboards (dynamic, PSF 256, 16 lights): %.1f ms at 640x480\n", billboard_ms);
        }
    }
    cli_session_close(&session);
    return 0;
}
