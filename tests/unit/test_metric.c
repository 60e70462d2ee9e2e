#include "drift/image.h"
#include "drift/math.h"
#include "drift/metric.h"
#include "drift_test.h"

#include <math.h>
#include <string.h>

// Smooth-ish random texture in [0.05, 0.95]: a product of hashed values on a coarse grid and
// per-pixel jitter, so SSIM and FLIP see structure rather than a flat field.
static drift_image make_texture(drift_context *ctx, int32_t w, int32_t h, uint32_t seed)
{
    drift_image img;
    assert_int_equal(drift_image_create(ctx, w, h, 3, &img), DRIFT_OK);
    for (int32_t y = 0; y < h; ++y) {
        for (int32_t x = 0; x < w; ++x) {
            for (int c = 0; c < 3; ++c) {
                uint32_t coarse = drift_hash_combine(seed, (uint32_t)((y / 4) * 1000 + x / 4));
                float v = 0.7f * test_hash_unit(coarse + (uint32_t)c) +
                          0.3f * test_hash_unit(seed ^ (uint32_t)((y * w + x) * 3 + c));
                drift_image_pixel(&img, x, y)[c] = 0.05f + 0.9f * v;
            }
        }
    }
    return img;
}

// Left half `lo`, right half `hi`, the step at column `edge`.
static drift_image make_edge(drift_context *ctx, int32_t w, int32_t h, int32_t edge, float lo,
                             float hi)
{
    drift_image img;
    assert_int_equal(drift_image_create(ctx, w, h, 3, &img), DRIFT_OK);
    for (int32_t y = 0; y < h; ++y) {
        for (int32_t x = 0; x < w; ++x) {
            for (int c = 0; c < 3; ++c) {
                drift_image_pixel(&img, x, y)[c] = x < edge ? lo : hi;
            }
        }
    }
    return img;
}

static void test_metric_identical_images_have_zero_error(void **state)
{
    (void)state;
    drift_context *ctx = test_context(3, NULL);
    drift_image a = make_texture(ctx, 37, 29, 1);
    drift_metric_report rep;
    drift_image map;
    assert_int_equal(drift_metric_compare(ctx, &a, &a, NULL, &rep, &map), DRIFT_OK);
    assert_true(rep.mse == 0.0);
    assert_true(rep.rmse == 0.0);
    assert_true(rep.relmse == 0.0);
    assert_true(isinf(rep.psnr) && rep.psnr > 0.0);
    assert_true(rep.ssim == 1.0);
    assert_true(rep.flip == 0.0);
    assert_int_equal(map.channels, 1);
    assert_int_equal(map.width, 37);
    for (int32_t i = 0; i < 37 * 29; ++i) {
        assert_true(map.pixels[i] == 0.0f);
    }
    drift_image_destroy(ctx, &map);
    drift_image_destroy(ctx, &a);
    drift_context_destroy(ctx);
}

static void test_metric_hand_computed_mse_psnr_relmse(void **state)
{
    (void)state;
    drift_context *ctx = test_context(1, NULL);
    drift_image ref, test;
    assert_int_equal(drift_image_create(ctx, 2, 1, 3, &ref), DRIFT_OK);
    assert_int_equal(drift_image_create(ctx, 2, 1, 3, &test), DRIFT_OK);
    // ref = (0,0,0) (1,1,1); test = (0.5,0,0) (1,1,0.75)
    float r[6] = { 0, 0, 0, 1, 1, 1 }, t[6] = { 0.5f, 0, 0, 1, 1, 0.75f };
    memcpy(ref.pixels, r, sizeof(r));
    memcpy(test.pixels, t, sizeof(t));
    // Squared errors 0.25 and 0.0625 over 6 values.
    double mse_expected = (0.25 + 0.0625) / 6.0;
    double rel_expected = (0.25 / 0.01 + 0.0625 / 1.01) / 6.0;
    double mse, relmse, psnr;
    assert_int_equal(drift_metric_mse(ctx, &ref, &test, &mse), DRIFT_OK);
    assert_int_equal(drift_metric_relmse(ctx, &ref, &test, &relmse), DRIFT_OK);
    assert_int_equal(drift_metric_psnr(ctx, &ref, &test, &psnr), DRIFT_OK);
    assert_near(mse, mse_expected, 1e-12);
    assert_near(relmse, rel_expected, 1e-12);
    assert_near(psnr, 10.0 * log10(1.0 / mse_expected), 1e-9);
    assert_near(psnr, 12.8330, 1e-4); // 10 log10(6 / 0.3125)
    drift_metric_report rep;
    assert_int_equal(drift_metric_compare(ctx, &ref, &test, NULL, &rep, NULL), DRIFT_OK);
    assert_near(rep.rmse, sqrt(mse_expected), 1e-12);
    // relMSE is against the reference: swapping the arguments changes it.
    assert_int_equal(drift_metric_relmse(ctx, &test, &ref, &relmse), DRIFT_OK);
    assert_near(relmse, (0.25 / 0.26 + 0.0625 / (0.5625 + 0.01)) / 6.0, 1e-12);
    drift_image_destroy(ctx, &ref);
    drift_image_destroy(ctx, &test);
    drift_context_destroy(ctx);
}

static void test_metric_ssim_of_offset_image_is_below_one(void **state)
{
    (void)state;
    drift_context *ctx = test_context(2, NULL);
    drift_image a = make_texture(ctx, 40, 30, 7);
    drift_image b = make_texture(ctx, 40, 30, 7);
    for (int32_t i = 0; i < 40 * 30 * 3; ++i) {
        b.pixels[i] = a.pixels[i] * 0.5f + 0.2f; // constant offset plus contrast loss
    }
    double ssim = 0.0;
    assert_int_equal(drift_metric_ssim(ctx, &a, &b, &ssim), DRIFT_OK);
    assert_true(ssim < 0.99);
    assert_true(ssim > 0.0);
    // A pure offset keeps structure: still below 1, but above the contrast-loss case.
    for (int32_t i = 0; i < 40 * 30 * 3; ++i) {
        b.pixels[i] = a.pixels[i] + 0.05f;
    }
    double ssim_offset = 0.0;
    assert_int_equal(drift_metric_ssim(ctx, &a, &b, &ssim_offset), DRIFT_OK);
    assert_true(ssim_offset < 1.0);
    assert_true(ssim_offset > ssim);
    drift_image_destroy(ctx, &a);
    drift_image_destroy(ctx, &b);
    drift_context_destroy(ctx);
}

static void test_metric_flip_shifted_edge_beats_equal_mse_fine_noise(void **state)
{
    (void)state;
    drift_context *ctx = test_context(2, NULL);
    const int32_t n = 64;
    drift_image ref = make_edge(ctx, n, n, n / 2, 0.2f, 0.8f);
    drift_image shifted = make_edge(ctx, n, n, n / 2 + 1, 0.2f, 0.8f);
    double mse_shift = 0.0;
    assert_int_equal(drift_metric_mse(ctx, &ref, &shifted, &mse_shift), DRIFT_OK);
    // Uniform-amplitude noise at the finest scale (sign alternating like a checkerboard), with
    // the same MSE as the shifted edge. FLIP's contrast sensitivity filters remove most of it;
    // the moved edge is a feature change FLIP must flag.
    drift_image noisy = make_edge(ctx, n, n, n / 2, 0.2f, 0.8f);
    float amp = (float)sqrt(mse_shift);
    for (int32_t y = 0; y < n; ++y) {
        for (int32_t x = 0; x < n; ++x) {
            for (int c = 0; c < 3; ++c) {
                drift_image_pixel(&noisy, x, y)[c] += ((x + y) & 1) ? -amp : amp;
            }
        }
    }
    double mse_noise = 0.0, flip_shift = 0.0, flip_noise = 0.0;
    assert_int_equal(drift_metric_mse(ctx, &ref, &noisy, &mse_noise), DRIFT_OK);
    assert_near(mse_noise, mse_shift, 1e-6);
    assert_int_equal(drift_metric_flip(ctx, &ref, &shifted, NULL, &flip_shift, NULL), DRIFT_OK);
    assert_int_equal(drift_metric_flip(ctx, &ref, &noisy, NULL, &flip_noise, NULL), DRIFT_OK);
    assert_true(flip_shift > 5.0 * flip_noise);
    // SSIM, a structural but not perceptually filtered metric, ranks them the other way.
    double ssim_shift = 0.0, ssim_noise = 0.0;
    assert_int_equal(drift_metric_ssim(ctx, &ref, &shifted, &ssim_shift), DRIFT_OK);
    assert_int_equal(drift_metric_ssim(ctx, &ref, &noisy, &ssim_noise), DRIFT_OK);
    assert_true(ssim_noise < ssim_shift);
    drift_image_destroy(ctx, &ref);
    drift_image_destroy(ctx, &shifted);
    drift_image_destroy(ctx, &noisy);
    drift_context_destroy(ctx);
}

static void test_metric_flip_in_unit_range_and_symmetric(void **state)
{
    (void)state;
    drift_context *ctx = test_context(2, NULL);
    drift_image a = make_texture(ctx, 33, 21, 11);
    drift_image b = make_texture(ctx, 33, 21, 12);
    // HDR and invalid values must not leave [0, 1] either: FLIP clamps to display range.
    b.pixels[0] = 50.0f;
    b.pixels[4] = -3.0f;
    b.pixels[8] = NAN;
    double ab = 0.0, ba = 0.0;
    drift_image map_ab, map_ba;
    assert_int_equal(drift_metric_flip(ctx, &a, &b, NULL, &ab, &map_ab), DRIFT_OK);
    assert_int_equal(drift_metric_flip(ctx, &b, &a, NULL, &ba, &map_ba), DRIFT_OK);
    assert_true(ab > 0.05 && ab < 1.0);
    assert_near(ab, ba, 1e-9);
    for (int32_t i = 0; i < 33 * 21; ++i) {
        assert_true(map_ab.pixels[i] >= 0.0f && map_ab.pixels[i] <= 1.0f);
        assert_near(map_ab.pixels[i], map_ba.pixels[i], 1e-6);
    }
    // Black against white is close to the largest error.
    drift_image black = make_edge(ctx, 16, 16, 0, 0.0f, 0.0f);
    drift_image white = make_edge(ctx, 16, 16, 0, 1.0f, 1.0f);
    double bw = 0.0;
    assert_int_equal(drift_metric_flip(ctx, &black, &white, NULL, &bw, NULL), DRIFT_OK);
    assert_true(bw > 0.9 && bw <= 1.0);
    drift_image_destroy(ctx, &black);
    drift_image_destroy(ctx, &white);
    drift_image_destroy(ctx, &map_ab);
    drift_image_destroy(ctx, &map_ba);
    drift_image_destroy(ctx, &a);
    drift_image_destroy(ctx, &b);
    drift_context_destroy(ctx);
}

static void test_metric_bit_identical_for_any_thread_count(void **state)
{
    (void)state;
    drift_metric_report reps[3];
    int threads[3] = { 1, 2, 5 };
    for (int t = 0; t < 3; ++t) {
        drift_context *ctx = test_context(threads[t], NULL);
        drift_image a = make_texture(ctx, 45, 38, 3);
        drift_image b = make_texture(ctx, 45, 38, 4);
        assert_int_equal(drift_metric_compare(ctx, &a, &b, NULL, &reps[t], NULL), DRIFT_OK);
        drift_image_destroy(ctx, &a);
        drift_image_destroy(ctx, &b);
        drift_context_destroy(ctx);
    }
    for (int t = 1; t < 3; ++t) {
        assert_memory_equal(&reps[0], &reps[t], sizeof(drift_metric_report));
    }
}

static void test_metric_rejects_size_mismatch_and_bad_ppd(void **state)
{
    (void)state;
    test_log_capture cap = { 0 };
    drift_context *ctx = test_context(1, &cap);
    drift_image a = make_texture(ctx, 8, 8, 1);
    drift_image b = make_texture(ctx, 8, 9, 1);
    drift_metric_report rep = { .mse = 5.0 };
    assert_int_equal(drift_metric_compare(ctx, &a, &b, NULL, &rep, NULL),
                     DRIFT_ERR_INVALID_ARGUMENT);
    assert_true(rep.mse == 0.0);
    assert_int_equal(cap.last_code, DRIFT_ERR_INVALID_ARGUMENT);
    double flip = 0.0;
    drift_image map = { .width = 3 };
    assert_int_equal(
        drift_metric_flip(ctx, &a, &a, &(drift_metric_params){ .ppd = -1.0 }, &flip, &map),
        DRIFT_ERR_INVALID_ARGUMENT);
    assert_null(map.pixels);
    assert_int_equal(map.width, 0);
    drift_metric_params p = drift_metric_params_resolve(&(drift_metric_params){ 0 });
    assert_near(p.ppd, DRIFT_METRIC_DEFAULT_PPD, 1e-12);
    drift_image_destroy(ctx, &a);
    drift_image_destroy(ctx, &b);
    drift_context_destroy(ctx);
}

static void test_metric_heatmap_uses_magma_endpoints(void **state)
{
    (void)state;
    drift_context *ctx = test_context(1, NULL);
    drift_image err;
    assert_int_equal(drift_image_create(ctx, 3, 1, 1, &err), DRIFT_OK);
    err.pixels[0] = 0.0f;
    err.pixels[1] = 1.0f;
    err.pixels[2] = 7.0f; // clamped
    drift_image heat;
    assert_int_equal(drift_metric_flip_heatmap(ctx, &err, &heat), DRIFT_OK);
    uint8_t rgb[9];
    drift_image_tonemap(&heat, NULL, rgb);
    // magma[0] = (0.001462, 0.000466, 0.013866), magma[255] = (0.987053, 0.991438, 0.749504).
    uint8_t expected[9] = { 0, 0, 4, 252, 253, 191, 252, 253, 191 };
    assert_memory_equal(rgb, expected, 9);
    drift_image_destroy(ctx, &heat);
    drift_image_destroy(ctx, &err);
    drift_context_destroy(ctx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_metric_identical_images_have_zero_error),
        cmocka_unit_test(test_metric_hand_computed_mse_psnr_relmse),
        cmocka_unit_test(test_metric_ssim_of_offset_image_is_below_one),
        cmocka_unit_test(test_metric_flip_shifted_edge_beats_equal_mse_fine_noise),
        cmocka_unit_test(test_metric_flip_in_unit_range_and_symmetric),
        cmocka_unit_test(test_metric_bit_identical_for_any_thread_count),
        cmocka_unit_test(test_metric_rejects_size_mismatch_and_bad_ppd),
        cmocka_unit_test(test_metric_heatmap_uses_magma_endpoints),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
