// Image space gathering's filter (isg/isg.h) on synthetic images: normalized weights (a constant
// image stays constant), the fallback when every sample is rejected, variance that falls with
// the gather's sample count, less stipple with interleaved rotations.
#include "drift/image.h"
#include "drift_test.h"
#include "isg/isg.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static float range_one(const void *user, int32_t x, int32_t y)
{
    (void)user;
    return 0.25f + test_hash_unit((uint32_t)(x * 131 + y)); // arbitrary positive weights
}

static float range_none(const void *user, int32_t x, int32_t y)
{
    (void)user;
    (void)x;
    (void)y;
    return 0.0f;
}

static void test_constant_image_stays_constant(void **state)
{
    (void)state;
    drift_context *ctx = test_context(1, NULL);
    drift_image image;
    assert_int_equal(drift_image_create(ctx, 32, 32, 3, &image), DRIFT_OK);
    for (size_t i = 0; i < 3u * 32u * 32u; ++i) {
        image.pixels[i] = 0.3f + 0.1f * (float)(i % 3);
    }
    static drift_isg_pattern pattern;
    drift_isg_pattern_make(81, DRIFT_ISG_DISK, &pattern);
    for (uint32_t k = 0; k < 50; ++k) {
        drift_isg_kernel kernel = {
            &pattern, drift_isg_jitter_make(k), drift_vec2_make(9.0f, 5.0f), range_one, NULL, NULL
        };
        float out[3];
        int32_t x = (int32_t)(k % 32), y = (int32_t)((k * 7) % 32);
        assert_true(drift_isg_filter(&kernel, &image, 0, 3, x, y, out) > 0.0f);
        for (int c = 0; c < 3; ++c) {
            assert_true(out[c] == 0.3f + 0.1f * (float)c);
        }
    }
    drift_image_destroy(ctx, &image);
    drift_context_destroy(ctx);
}

static void test_all_rejected_falls_back_to_centre(void **state)
{
    (void)state;
    drift_context *ctx = test_context(1, NULL);
    drift_image image;
    assert_int_equal(drift_image_create(ctx, 8, 8, 1, &image), DRIFT_OK);
    for (size_t i = 0; i < 64; ++i) {
        image.pixels[i] = (float)i;
    }
    image.pixels[3 * 8 + 3] = INFINITY; // an occluder distance of "none"
    static drift_isg_pattern pattern;
    drift_isg_pattern_make(25, DRIFT_ISG_RECT, &pattern);
    drift_isg_kernel kernel = {
        &pattern, drift_isg_jitter_make(7), drift_vec2_make(3.0f, 3.0f), range_none, NULL, NULL
    };
    float out;
    assert_true(drift_isg_filter(&kernel, &image, 0, 1, 4, 4, &out) == 0.0f);
    assert_true(out == 36.0f);
    assert_true(drift_isg_filter(&kernel, &image, 0, 1, 3, 3, &out) == 0.0f);
    assert_true(isinf(out) && !isnan(out));
    drift_image_destroy(ctx, &image);
    drift_context_destroy(ctx);
}

static float range_unit(const void *user, int32_t x, int32_t y)
{
    (void)user;
    (void)x;
    (void)y;
    return 1.0f;
}

// Variance over per-pixel rotations of the gather at one pixel of a noise image.
static double gather_variance(const drift_image *image, uint32_t count)
{
    static drift_isg_pattern pattern;
    drift_isg_pattern_make(count, DRIFT_ISG_DISK, &pattern);
    uint32_t trials = (uint32_t)(400.0 * test_intensity());
    double sum = 0.0, sum2 = 0.0;
    for (uint32_t k = 0; k < trials; ++k) {
        drift_isg_kernel kernel = { &pattern,
                                    drift_isg_jitter_make(drift_hash_u32(k)),
                                    drift_vec2_make(12.0f, 12.0f),
                                    range_unit,
                                    NULL,
                                    NULL };
        float out;
        drift_isg_filter(&kernel, image, 0, 1, 32, 32, &out);
        sum += (double)out;
        sum2 += (double)out * (double)out;
    }
    double mean = sum / trials;
    return sum2 / trials - mean * mean;
}

// The noise of the gather over a shadow edge (its value less its mean over rotations), seen
// through a 3 x 3 box (what the eye integrates): the per-pixel rotation's stipple.
// Interleaved rotations (neighbours take evenly spread angles) leave less of it than white
// ones at the same cost.
static double stipple(const drift_image *image, bool interleaved)
{
    static drift_isg_pattern pattern;
    drift_isg_pattern_make(9, DRIFT_ISG_DISK, &pattern);

    enum {
        N = 40,
        ANGLES = 64
    };

    static float error[N][N];
    for (int32_t y = 0; y < N; ++y) {
        for (int32_t x = 0; x < N; ++x) {
            uint32_t pixel = (uint32_t)(y * N + x);
            drift_isg_jitter jitter = interleaved ? drift_isg_jitter_at(99, x, y)
                                                  : drift_isg_jitter_make(drift_hash_u32(pixel));
            drift_isg_kernel kernel = { &pattern,   jitter, drift_vec2_make(6.0f, 6.0f),
                                        range_unit, NULL,   NULL };
            float a, mean = 0.0f;
            drift_isg_filter(&kernel, image, 0, 1, x + 12, y + 12, &a);
            for (int k = 0; k < ANGLES; ++k) {
                float angle = 2.0f * 3.14159265f * ((float)k + 0.5f) / ANGLES, b;
                kernel.jitter.cos_a = cosf(angle);
                kernel.jitter.sin_a = sinf(angle);
                drift_isg_filter(&kernel, image, 0, 1, x + 12, y + 12, &b);
                mean += b / ANGLES;
            }
            error[y][x] = a - mean;
        }
    }
    double sum2 = 0.0;
    int count = 0;
    for (int32_t y = 1; y + 1 < N; ++y) {
        for (int32_t x = 1; x + 1 < N; ++x) {
            float box = 0.0f;
            for (int32_t j = -1; j <= 1; ++j) {
                for (int32_t i = -1; i <= 1; ++i) {
                    box += error[y + j][x + i] / 9.0f;
                }
            }
            sum2 += (double)box * (double)box;
            ++count;
        }
    }
    return sqrt(sum2 / count);
}

static void test_interleaved_rotation_less_stipple(void **state)
{
    (void)state;
    drift_context *ctx = test_context(1, NULL);
    drift_image image;
    assert_int_equal(drift_image_create(ctx, 64, 64, 1, &image), DRIFT_OK);
    for (int32_t y = 0; y < 64; ++y) {
        for (int32_t x = 0; x < 64; ++x) {
            // A diagonal shadow edge: every gather near it straddles it.
            drift_image_pixel(&image, x, y)[0] = (float)((x + y / 2) % 16 < 8);
        }
    }
    double white = stipple(&image, false), interleaved = stipple(&image, true);
    print_message("stipple after a 3x3 box: white %g, interleaved %g\n", white, interleaved);
    assert_true(interleaved < 0.85 * white); // 0.78x measured
    drift_image_destroy(ctx, &image);
    drift_context_destroy(ctx);
}

static void test_more_gather_samples_lower_variance(void **state)
{
    (void)state;
    drift_context *ctx = test_context(1, NULL);
    drift_image image;
    assert_int_equal(drift_image_create(ctx, 64, 64, 1, &image), DRIFT_OK);
    for (uint32_t i = 0; i < 64u * 64u; ++i) {
        image.pixels[i] = test_hash_unit(i);
    }
    double v9 = gather_variance(&image, 9), v25 = gather_variance(&image, 25);
    double v81 = gather_variance(&image, 81);
    print_message("gather variance: 9 %.3g, 25 %.3g, 81 %.3g\n", v9, v25, v81);
    assert_true(v25 < 0.8 * v9);
    assert_true(v81 < 0.8 * v25);
    drift_image_destroy(ctx, &image);
    drift_context_destroy(ctx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_constant_image_stays_constant),
        cmocka_unit_test(test_all_rejected_falls_back_to_centre),
        cmocka_unit_test(test_more_gather_samples_lower_variance),
        cmocka_unit_test(test_interleaved_rotation_less_stipple),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
