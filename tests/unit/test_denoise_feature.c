// The feature-guided denoiser (drift_denoise_feature, include/drift/denoise.h) on synthetic
// inputs whose noise-free image and noise variance are known: a checker-textured plane under
// a constant light, each pixel the mean of n samples of irradiance E (1 + s g), g ~ N(0, 1).
// The denoised error is below the noisy one, texture edges keep their contrast, the variance
// estimate finds the true variance, the output does not depend on the thread count, and
// non-finite inputs are counted and taken as 0; the same with the direct light apart (a shadow
// edge kept). Also the path tracer's variance AOV against the samples replayed one by one, and
// its direct AOV against the beauty (all of it at one bounce).
#include "drift/denoise.h"
#include "drift/image.h"
#include "drift/pt.h"
#include "drift/scene_io.h"
#include "drift_test.h"
#include "test_rig.h"

#include <math.h>
#include <string.h>

#define W        64
#define H        48
#define E        0.5f // the constant irradiance
#define CHECKER  8    // checker squares of 8 pixels, albedo 0.2 and 0.8
#define NSAMPLES 4

static float checker_albedo(int32_t x, int32_t y)
{
    return ((x / CHECKER + y / CHECKER) & 1) ? 0.8f : 0.2f;
}

static float gaussian(uint32_t i)
{
    float u1 = test_hash_unit(i * 2u + 1u), u2 = test_hash_unit(i * 2u + 2u);
    u1 = u1 > 1e-7f ? u1 : 1e-7f;
    return sqrtf(-2.0f * logf(u1)) * cosf(6.2831853f * u2);
}

typedef struct synthetic {
    drift_image color, albedo, normal, depth, variance, truth;
} synthetic;

// n samples a pixel of relative noise s; the variance image is the pt's estimate (the
// samples' unbiased luminance variance over n). textured: the checker, else albedo 0.5.
static synthetic make_synthetic(drift_context *ctx, bool textured, uint32_t n, float s,
                                uint32_t seed)
{
    synthetic v;
    assert_int_equal(drift_image_create(ctx, W, H, 3, &v.color), DRIFT_OK);
    assert_int_equal(drift_image_create(ctx, W, H, 3, &v.albedo), DRIFT_OK);
    assert_int_equal(drift_image_create(ctx, W, H, 3, &v.normal), DRIFT_OK);
    assert_int_equal(drift_image_create(ctx, W, H, 1, &v.depth), DRIFT_OK);
    assert_int_equal(drift_image_create(ctx, W, H, 1, &v.variance), DRIFT_OK);
    assert_int_equal(drift_image_create(ctx, W, H, 3, &v.truth), DRIFT_OK);
    for (int32_t y = 0; y < H; ++y) {
        for (int32_t x = 0; x < W; ++x) {
            float a = textured ? checker_albedo(x, y) : 0.5f;
            double sum = 0.0, sum2 = 0.0;
            for (uint32_t k = 0; k < n; ++k) {
                uint32_t i = seed * 7919u + ((uint32_t)(y * W + x) * 64u + k);
                double lum = (double)(a * E * (1.0f + s * gaussian(i)));
                sum += lum;
                sum2 += lum * lum;
            }
            double mean = sum / n;
            double var = n > 1 ? (sum2 - n * mean * mean) / (n - 1) / n : 0.0;
            for (int c = 0; c < 3; ++c) {
                drift_image_pixel(&v.color, x, y)[c] = (float)mean;
                drift_image_pixel(&v.albedo, x, y)[c] = a;
                drift_image_pixel(&v.normal, x, y)[c] = c == 2 ? 1.0f : 0.0f;
                drift_image_pixel(&v.truth, x, y)[c] = a * E;
            }
            *drift_image_pixel(&v.depth, x, y) = 3.0f;
            *drift_image_pixel(&v.variance, x, y) = (float)(var > 0.0 ? var : 0.0);
        }
    }
    return v;
}

static void destroy_synthetic(drift_context *ctx, synthetic *v)
{
    drift_image *all[6] = { &v->color, &v->albedo, &v->normal, &v->depth, &v->variance, &v->truth };
    for (int i = 0; i < 6; ++i) {
        drift_image_destroy(ctx, all[i]);
    }
}

static drift_denoise_inputs inputs_of(const synthetic *v, uint32_t n)
{
    return (drift_denoise_inputs){ .color = &v->color,
                                   .albedo = &v->albedo,
                                   .normal = &v->normal,
                                   .depth = &v->depth,
                                   .variance = &v->variance,
                                   .sample_count = n };
}

static double mse(const drift_image *a, const drift_image *b)
{
    double sum = 0.0;
    for (int32_t y = 0; y < H; ++y) {
        for (int32_t x = 0; x < W; ++x) {
            for (int c = 0; c < 3; ++c) {
                double d = (double)(drift_image_pixel(a, x, y)[c] - drift_image_pixel(b, x, y)[c]);
                sum += d * d;
            }
        }
    }
    return sum / (W * H * 3);
}

// Mean over every horizontal checker edge (x = 8k - 1 | 8k) of the image's step over the
// truth's step, (right - left) / (right_true - left_true), on the green channel.
static double edge_contrast(const drift_image *img, const drift_image *truth)
{
    double sum = 0.0;
    int count = 0;
    for (int32_t y = 0; y < H; ++y) {
        for (int32_t x = CHECKER; x < W; x += CHECKER) {
            double d =
                (double)(drift_image_pixel(img, x, y)[1] - drift_image_pixel(img, x - 1, y)[1]);
            double t =
                (double)(drift_image_pixel(truth, x, y)[1] - drift_image_pixel(truth, x - 1, y)[1]);
            sum += d / t;
            ++count;
        }
    }
    return sum / count;
}

// Both methods: the error falls below the noisy input's, and the checker's edges keep their
// contrast within 10 % (the stated bound: demodulation filters the irradiance only).
static void test_denoise_feature_textured_plane(void **state)
{
    (void)state;
    drift_context *ctx = test_context(2, NULL);
    synthetic v = make_synthetic(ctx, true, NSAMPLES, 1.0f, 1);
    double noisy = mse(&v.color, &v.truth);
    for (int m = 0; m < DRIFT_DENOISE_METHOD_COUNT; ++m) {
        drift_image out;
        drift_denoise_inputs in = inputs_of(&v, NSAMPLES);
        drift_denoise_feature_params p = { .method = (drift_denoise_method)m };
        assert_int_equal(drift_denoise_feature(ctx, &in, &p, &out, NULL), DRIFT_OK);
        double denoised = mse(&out, &v.truth), contrast = edge_contrast(&out, &v.truth);
        print_message("method %d: mse %.3g -> %.3g (x%.3f), edge contrast %.3f\n", m, noisy,
                      denoised, denoised / noisy, contrast);
        assert_true(denoised < 0.25 * noisy);
        assert_true(fabs(contrast - 1.0) <= 0.1);
        drift_image_destroy(ctx, &out);
    }
    destroy_synthetic(ctx, &v);
    drift_context_destroy(ctx);
}

// REGRESSION_RESIDUAL on the checker lit by a smooth quadratic irradiance E(x, y) =
// 0.2 + 0.5 (x / W)^2 + 0.3 y / H, which the block fit's features span. Noise-free (variance
// 0, 16 samples): the output is the input within 1e-4 relative (the residual's filter keeps
// what the ridge-biased fit misses). With noise (4 samples, s = 1): the error falls below a
// quarter of the noisy input's and below VARIANCE_GUIDED's, whose luminance weight breaks a
// gradient into patches.
static void test_denoise_feature_regression_residual_gradient(void **state)
{
    (void)state;
    drift_context *ctx = test_context(2, NULL);
    for (int noisy = 0; noisy < 2; ++noisy) {
        uint32_t n = noisy ? NSAMPLES : 16u;
        synthetic v = make_synthetic(ctx, true, n, noisy ? 1.0f : 0.0f, 9);
        for (int32_t y = 0; y < H; ++y) {
            for (int32_t x = 0; x < W; ++x) {
                float xs = (float)x / W, g = (0.2f + 0.5f * xs * xs + 0.3f * (float)y / H) / E;
                for (int c = 0; c < 3; ++c) {
                    drift_image_pixel(&v.color, x, y)[c] *= g;
                    drift_image_pixel(&v.truth, x, y)[c] *= g;
                }
                *drift_image_pixel(&v.variance, x, y) *= g * g;
            }
        }
        drift_denoise_inputs in = inputs_of(&v, n);
        drift_image out[2];
        for (int m = 0; m < 2; ++m) {
            drift_denoise_feature_params p = { .method = m ? DRIFT_DENOISE_REGRESSION_RESIDUAL
                                                           : DRIFT_DENOISE_VARIANCE_GUIDED };
            assert_int_equal(drift_denoise_feature(ctx, &in, &p, &out[m], NULL), DRIFT_OK);
        }
        if (!noisy) {
            double worst = 0.0;
            for (int32_t y = 0; y < H; ++y) {
                for (int32_t x = 0; x < W; ++x) {
                    const float *o = drift_image_pixel(&out[1], x, y);
                    const float *t = drift_image_pixel(&v.truth, x, y);
                    worst = fmax(worst, fabs((double)(o[1] / t[1]) - 1.0));
                }
            }
            print_message("noise-free gradient: worst relative error %.2g\n", worst);
            assert_true(worst <= 1e-4);
        } else {
            double e0 = mse(&v.color, &v.truth), e_vg = mse(&out[0], &v.truth),
                   e_rr = mse(&out[1], &v.truth);
            print_message("noisy gradient: mse %.3g, variance-guided %.3g, regression + residual "
                          "%.3g\n",
                          e0, e_vg, e_rr);
            assert_true(e_rr < 0.25 * e0);
            assert_true(e_rr < e_vg);
        }
        drift_image_destroy(ctx, &out[0]);
        drift_image_destroy(ctx, &out[1]);
        destroy_synthetic(ctx, &v);
    }
    drift_context_destroy(ctx);
}

// Stage 4 against the truth: at 1 sample (no variance image) the spatial estimate of the
// demodulated irradiance's variance is (E s)^2; at 16 samples the per-pixel estimates, over
// the albedo squared, average (E s)^2 / 16. Within 10 %.
static void test_denoise_feature_variance_estimate(void **state)
{
    (void)state;
    drift_context *ctx = test_context(2, NULL);
    const float s = 0.4f;
    const uint32_t counts[2] = { 1, 16 };
    for (int i = 0; i < 2; ++i) {
        synthetic v = make_synthetic(ctx, i == 1, counts[i], s, 2);
        drift_denoise_inputs in = inputs_of(&v, counts[i]);
        if (counts[i] == 1) {
            in.variance = NULL;
        }
        drift_image out;
        drift_denoise_report report;
        assert_int_equal(drift_denoise_feature(ctx, &in, NULL, &out, &report), DRIFT_OK);
        double truth = (double)(E * s) * (double)(E * s) / counts[i];
        print_message("%u spp: variance %.4g, true %.4g\n", counts[i], report.mean_variance, truth);
        assert_true(fabs(report.mean_variance / truth - 1.0) < 0.1);
        drift_image_destroy(ctx, &out);
        destroy_synthetic(ctx, &v);
    }
    drift_context_destroy(ctx);
}

static void test_denoise_feature_bit_identical_for_any_thread_count(void **state)
{
    (void)state;
    const int threads[3] = { 1, 2, 5 };
    for (int m = 0; m < DRIFT_DENOISE_METHOD_COUNT; ++m) {
        drift_image outs[3];
        drift_context *ctxs[3];
        for (int t = 0; t < 3; ++t) {
            ctxs[t] = test_context(threads[t], NULL);
            synthetic v = make_synthetic(ctxs[t], true, 2, 1.0f, 3);
            drift_denoise_inputs in = inputs_of(&v, 2);
            drift_denoise_feature_params p = { .method = (drift_denoise_method)m };
            assert_int_equal(drift_denoise_feature(ctxs[t], &in, &p, &outs[t], NULL), DRIFT_OK);
            destroy_synthetic(ctxs[t], &v);
        }
        for (int t = 1; t < 3; ++t) {
            assert_memory_equal(outs[0].pixels, outs[t].pixels, (size_t)W * H * 3 * sizeof(float));
        }
        for (int t = 0; t < 3; ++t) {
            drift_image_destroy(ctxs[t], &outs[t]);
            drift_context_destroy(ctxs[t]);
        }
    }
}

// NaN and infinite inputs are taken as 0, counted in the report and in one warning; the
// output is finite.
static void test_denoise_feature_nonfinite_inputs(void **state)
{
    (void)state;
    test_log_capture capture = { 0 };
    drift_context *ctx = test_context(2, &capture);
    synthetic v = make_synthetic(ctx, true, 4, 0.5f, 4);
    for (int i = 0; i < 5; ++i) {
        drift_image_pixel(&v.color, 3 + 7 * i, 5)[1] = NAN;
    }
    drift_image_pixel(&v.color, 10, 10)[0] = INFINITY;
    drift_image_pixel(&v.color, 11, 10)[2] = -INFINITY;
    drift_image_pixel(&v.normal, 20, 20)[0] = NAN;
    *drift_image_pixel(&v.variance, 30, 30) = INFINITY;
    drift_denoise_inputs in = inputs_of(&v, 4);
    drift_image out;
    drift_denoise_report report;
    assert_int_equal(drift_denoise_feature(ctx, &in, NULL, &out, &report), DRIFT_OK);
    assert_int_equal(report.nonfinite, 9);
    assert_int_equal(capture.warnings, 1);
    for (int32_t y = 0; y < H; ++y) {
        for (int32_t x = 0; x < W; ++x) {
            for (int c = 0; c < 3; ++c) {
                assert_true(isfinite(drift_image_pixel(&out, x, y)[c]));
            }
        }
    }
    drift_image_destroy(ctx, &out);
    destroy_synthetic(ctx, &v);
    drift_context_destroy(ctx);
}

static void test_denoise_feature_rejects_bad_arguments(void **state)
{
    (void)state;
    test_log_capture capture = { 0 };
    drift_context *ctx = test_context(1, &capture);
    synthetic v = make_synthetic(ctx, false, 1, 0.1f, 5);
    drift_image small, out;
    assert_int_equal(drift_image_create(ctx, W / 2, H, 1, &small), DRIFT_OK);
    drift_denoise_inputs in = inputs_of(&v, 1);
    in.depth = &small;
    assert_int_equal(drift_denoise_feature(ctx, &in, NULL, &out, NULL), DRIFT_ERR_INVALID_ARGUMENT);
    assert_null(out.pixels);
    in = inputs_of(&v, 1);
    drift_denoise_feature_params bad = { .iterations = 11 };
    assert_int_equal(drift_denoise_feature(ctx, &in, &bad, &out, NULL), DRIFT_ERR_INVALID_ARGUMENT);
    bad = (drift_denoise_feature_params){ .residual_block = 7 }; // odd: no half-block origin
    assert_int_equal(drift_denoise_feature(ctx, &in, &bad, &out, NULL), DRIFT_ERR_INVALID_ARGUMENT);
    assert_int_equal(capture.errors, 3);
    drift_image_destroy(ctx, &small);
    destroy_synthetic(ctx, &v);
    drift_context_destroy(ctx);
}

// The path tracer's variance AOV is the samples' unbiased luminance variance over n: replayed
// one by one with drift_pt_trace_sample on a small Cornell box.
static void test_denoise_feature_pt_variance_aov(void **state)
{
    (void)state;
    const int32_t w = 16;
    const uint32_t n = 6;
    test_rig r = test_rig_begin(2);
    char path[1024];
    drift_scene_destroy(r.scene);
    assert_int_equal(drift_scene_load(r.ctx,
                                      test_repo_path(path, "scenes/cornell-box/cornell_box.json"),
                                      &r.scene),
                     DRIFT_OK);
    assert_int_equal(drift_accel_create(r.ctx, r.scene, &(drift_accel_desc){ 0 }, &r.accel),
                     DRIFT_OK);
    drift_pt *pt = NULL;
    assert_int_equal(drift_pt_create(r.ctx, r.scene, r.accel,
                                     &(drift_pt_params){ .width = w, .height = w, .seed = 3 }, &pt),
                     DRIFT_OK);
    assert_int_equal(drift_pt_render_samples(pt, n, NULL), DRIFT_OK);
    drift_image var;
    assert_int_equal(drift_pt_resolve(pt, DRIFT_PT_AOV_VARIANCE, &var), DRIFT_OK);
    int nonzero = 0;
    for (int32_t y = 0; y < w; ++y) {
        for (int32_t x = 0; x < w; ++x) {
            double sum = 0.0, sum2 = 0.0;
            for (uint32_t s = 0; s < n; ++s) {
                double l = (double)drift_luminance(drift_pt_trace_sample(pt, x, y, s));
                sum += l;
                sum2 += l * l;
            }
            double mean = sum / n, expect = (sum2 - n * mean * mean) / (n - 1) / n;
            double got = (double)*drift_image_pixel(&var, x, y);
            assert_true(fabs(got - expect) <= 1e-4 * expect + 1e-7);
            nonzero += got > 0.0;
        }
    }
    assert_true(nonzero > w * w / 4);
    drift_pt_destroy(pt);
    test_rig_destroy(&r);
}

// The direct part filtered apart (drift_denoise_inputs.direct): a noise-free direct light
// with a shadow edge at x = W/2 (Ed = 0 left, 1 right) plus a noisy indirect (Ei (1 + s g),
// NSAMPLES samples) on the checker. The error falls below the noisy input's, the shadow edge
// keeps its contrast within 10 %, the output is bit-identical for 1 and 3 threads, and a
// direct part without its variances is refused.
static void test_denoise_feature_direct_apart(void **state)
{
    (void)state;
    static float first[W * H * 3]; // the 1-thread output
    drift_image out[2];
    for (int t = 0; t < 2; ++t) {
        test_log_capture capture = { 0 };
        drift_context *ctx = test_context(t == 0 ? 1 : 3, &capture);
        synthetic v = make_synthetic(ctx, true, NSAMPLES, 1.0f, 6); // the indirect part
        drift_image direct, direct_var;
        assert_int_equal(drift_image_create(ctx, W, H, 3, &direct), DRIFT_OK);
        assert_int_equal(drift_image_create(ctx, W, H, 1, &direct_var), DRIFT_OK);
        for (int32_t y = 0; y < H; ++y) {
            for (int32_t x = 0; x < W; ++x) {
                float d = x >= W / 2 ? checker_albedo(x, y) : 0.0f;
                for (int c = 0; c < 3; ++c) {
                    drift_image_pixel(&direct, x, y)[c] = d;
                    drift_image_pixel(&v.color, x, y)[c] += d;
                    drift_image_pixel(&v.truth, x, y)[c] += d;
                }
                *drift_image_pixel(&direct_var, x, y) = 0.0f;
            }
        }
        drift_denoise_inputs in = inputs_of(&v, NSAMPLES);
        in.direct = &direct;
        in.direct_variance = &direct_var;
        in.indirect_variance = &v.variance;
        assert_int_equal(drift_denoise_feature(ctx, &in, NULL, &out[t], NULL), DRIFT_OK);
        double noisy = mse(&v.color, &v.truth), denoised = mse(&out[t], &v.truth);
        double step = 0.0, step_true = 0.0;
        for (int32_t y = 0; y < H; ++y) {
            step += (double)(drift_image_pixel(&out[t], W / 2, y)[1] -
                             drift_image_pixel(&out[t], W / 2 - 1, y)[1]);
            step_true += (double)(drift_image_pixel(&v.truth, W / 2, y)[1] -
                                  drift_image_pixel(&v.truth, W / 2 - 1, y)[1]);
        }
        print_message("direct apart: mse %.3g -> %.3g (x%.3f), shadow edge contrast %.3f\n", noisy,
                      denoised, denoised / noisy, step / step_true);
        assert_true(denoised < 0.25 * noisy);
        assert_true(fabs(step / step_true - 1.0) <= 0.1);
        in.indirect_variance = NULL;
        drift_image none;
        assert_int_equal(drift_denoise_feature(ctx, &in, NULL, &none, NULL),
                         DRIFT_ERR_INVALID_ARGUMENT);
        assert_int_equal(capture.errors, 1);
        if (t == 0) {
            memcpy(first, out[t].pixels, sizeof first);
        } else {
            assert_memory_equal(first, out[t].pixels, sizeof first);
        }
        drift_image_destroy(ctx, &out[t]);
        drift_image_destroy(ctx, &direct);
        drift_image_destroy(ctx, &direct_var);
        destroy_synthetic(ctx, &v);
        drift_context_destroy(ctx);
    }
}

// With one bounce (max_depth 1) all of the light is direct: the pt's direct AOV is its beauty,
// bit for bit; at depth 8 the direct part is at most the beauty and the rest's variance is
// finite and somewhere above 0.
static void test_denoise_feature_pt_direct_aov(void **state)
{
    (void)state;
    const int32_t w = 16;
    test_rig r = test_rig_begin(2);
    char path[1024];
    drift_scene_destroy(r.scene);
    assert_int_equal(drift_scene_load(r.ctx,
                                      test_repo_path(path, "scenes/cornell-box/cornell_box.json"),
                                      &r.scene),
                     DRIFT_OK);
    assert_int_equal(drift_accel_create(r.ctx, r.scene, &(drift_accel_desc){ 0 }, &r.accel),
                     DRIFT_OK);
    for (int32_t depth = 1; depth <= 8; depth += 7) {
        drift_pt *pt = NULL;
        drift_pt_params pp = { .width = w, .height = w, .seed = 5, .max_depth = depth };
        assert_int_equal(drift_pt_create(r.ctx, r.scene, r.accel, &pp, &pt), DRIFT_OK);
        assert_int_equal(drift_pt_render_samples(pt, 4, NULL), DRIFT_OK);
        drift_image beauty, direct, rest_var;
        assert_int_equal(drift_pt_resolve(pt, DRIFT_PT_AOV_BEAUTY, &beauty), DRIFT_OK);
        assert_int_equal(drift_pt_resolve(pt, DRIFT_PT_AOV_DIRECT, &direct), DRIFT_OK);
        assert_int_equal(drift_pt_resolve(pt, DRIFT_PT_AOV_INDIRECT_VARIANCE, &rest_var), DRIFT_OK);
        int rest = 0;
        for (int32_t y = 0; y < w; ++y) {
            for (int32_t x = 0; x < w; ++x) {
                const float *b = drift_image_pixel(&beauty, x, y);
                const float *d = drift_image_pixel(&direct, x, y);
                float v = *drift_image_pixel(&rest_var, x, y);
                assert_true(isfinite(v) && v >= 0.0f);
                for (int c = 0; c < 3; ++c) {
                    if (depth == 1) {
                        assert_true(b[c] == d[c]);
                    } else {
                        assert_true(d[c] <= b[c] * (1.0f + 1e-5f) + 1e-6f);
                    }
                }
                rest += v > 0.0f;
            }
        }
        assert_true(depth == 1 ? rest == 0 : rest > w * w / 4);
        drift_pt_destroy(pt);
    }
    test_rig_destroy(&r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_denoise_feature_textured_plane),
        cmocka_unit_test(test_denoise_feature_regression_residual_gradient),
        cmocka_unit_test(test_denoise_feature_variance_estimate),
        cmocka_unit_test(test_denoise_feature_bit_identical_for_any_thread_count),
        cmocka_unit_test(test_denoise_feature_nonfinite_inputs),
        cmocka_unit_test(test_denoise_feature_rejects_bad_arguments),
        cmocka_unit_test(test_denoise_feature_pt_variance_aov),
        cmocka_unit_test(test_denoise_feature_direct_apart),
        cmocka_unit_test(test_denoise_feature_pt_direct_aov),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
