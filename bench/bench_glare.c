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

#define MAX_SIZES 8

typedef struct glare_options {
    long frames;
    long sizes[MAX_SIZES];
    int size_count;
    bool no_convolution, json;
} glare_options;

// --sizes: up to MAX_SIZES powers of two in [16, 4096]; `field` is the options.
static bool parse_sizes(const char *cmd, const char *flag, const char *value, void *field)
{
    glare_options *o = field, next = *o;
    if (!bench_parse_list(cmd, flag, value, 16, 4096, MAX_SIZES, next.sizes, &next.size_count)) {
        return false;
    }
    for (int i = 0; i < next.size_count; ++i) {
        if ((next.sizes[i] & (next.sizes[i] - 1)) != 0) {
            fprintf(stderr, "drift %s: %s expects powers of two, got %ld in '%s'\n", cmd, flag,
                    next.sizes[i], value);
            return false;
        }
    }
    *o = next;
    return true;
}

#define O glare_options
static const cli_option glare_table[] = {
    CLI_SECTION("options:", 0),
    CLI_INT("--frames", "N", O, frames, 1, 1000, "the least of N runs per figure (default 3)"),
    CLI_CUSTOM_ALL("--sizes", "LIST", parse_sizes,
                   "PSF sizes, up to " CLI_STR(MAX_SIZES) " powers of two (default 256,512,1024)"),
    CLI_FLAG("--no-convolution", O, no_convolution, "skip (b) and (c)"),
    BENCH_OPTION_JSON(O),
};
#undef O

static const cli_command glare_command = {
    .name = "bench glare",
    .usage = "usage: drift bench glare [options]\n\n"
             "(a) aperture, diffraction and display ms per PSF size (Table 8.2 of the thesis;\n"
             "    2x2 supersampling, 32 wavelengths), (b) the convolution of a 1920x1080 frame\n"
             "    with that PSF, (c) ms a frame of drift_glare_apply (dynamic, PSF 256) on\n"
             "    640x480, 512^2 and 1024^2 images. One thread.\n\n",
    CLI_TABLE(glare_table),
    .help_column = 20,
};

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
        out->convolution = (double)NAN;
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
    glare_options o = { .frames = 3, .sizes = { 256, 512, 1024 }, .size_count = 3 };
    int status = cli_parse(&glare_command, argc, argv, &o, NULL);
    if (status != CLI_PARSED) {
        return cli_parse_exit(status);
    }
    const bool convolution = !o.no_convolution;
    const int32_t frames = (int32_t)o.frames;
    cli_session session;
    if (!cli_session_open(
            &(cli_session_desc){ .cmd = "bench glare", .threads = 1, .no_scene = true },
            &session)) {
        return 1;
    }
    drift_context *ctx = session.ctx;
    phase_ms rows[MAX_SIZES];
    double apply_ms[3] = { (double)NAN, (double)NAN, (double)NAN }, billboard_ms = (double)NAN;
    const int32_t apply_sizes[3][2] = { { 640, 480 }, { 512, 512 }, { 1024, 1024 } };
    drift_result r = DRIFT_OK;
    for (int i = 0; i < o.size_count && r == DRIFT_OK; ++i) {
        r = time_size(ctx, (int32_t)o.sizes[i], frames, convolution, &rows[i]);
    }
    for (int32_t i = 0; i < 3 && convolution && r == DRIFT_OK; ++i) {
        r = time_apply(ctx, apply_sizes[i][0], apply_sizes[i][1], frames,
                       DRIFT_GLARE_METHOD_CONVOLUTION, &apply_ms[i]);
    }
    if (convolution && r == DRIFT_OK) {
        r = time_apply(ctx, 640, 480, frames, DRIFT_GLARE_METHOD_BILLBOARD, &billboard_ms);
    }
    if (r != DRIFT_OK) {
        fprintf(stderr, "drift bench glare: %s\n", drift_result_string(r));
        cli_session_close(&session);
        return 1;
    }
    if (o.json) {
        cJSON *root = cJSON_CreateObject();
        cJSON_AddNumberToObject(root, "threads", 1);
        cJSON_AddNumberToObject(root, "supersample", 2);
        cJSON_AddNumberToObject(root, "wavelengths", 32);
        cJSON *array = cJSON_AddArrayToObject(root, "sizes");
        for (int i = 0; i < o.size_count; ++i) {
            const phase_ms *p = &rows[i];
            cJSON *item = cJSON_CreateObject();
            cJSON_AddItemToArray(array, item);
            cJSON_AddNumberToObject(item, "n", p->n);
            cli_json_number(item, "aperture_ms", p->aperture, 3);
            cli_json_number(item, "diffraction_ms", p->diffraction, 3);
            cli_json_number(item, "display_ms", p->display, 3);
            cli_json_number(item, "overall_ms", p->aperture + p->diffraction + p->display, 3);
            cli_json_number(item, "convolution_1080p_ms", p->convolution, 3);
        }
        cJSON *apply = cJSON_AddObjectToObject(root, "apply_ms");
        for (int i = 0; i < 3; ++i) {
            char key[32];
            snprintf(key, sizeof key, "%dx%d", (int)apply_sizes[i][0], (int)apply_sizes[i][1]);
            cli_json_number(apply, key, apply_ms[i], 3);
        }
        cli_json_number(root, "billboard_640x480_ms", billboard_ms, 3);
        if (!cli_json_write("bench glare", root, NULL)) {
            cli_session_close(&session);
            return 1;
        }
    } else {
        printf("glare, one thread, 2x2 supersampling, 32 wavelengths (least of %d)\n", (int)frames);
        printf("%6s %10s %12s %10s %10s %16s\n", "N", "aperture", "diffraction", "display",
               "overall", "conv 1920x1080");
        for (int i = 0; i < o.size_count; ++i) {
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
