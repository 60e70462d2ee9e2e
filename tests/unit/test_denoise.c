// The edge-avoiding a-trous filter (include/drift/denoise.h): a constant image is a fixed
// point, i.i.d. noise on a flat image loses most of its variance, a step edge in the guides is
// kept, and the output does not depend on the thread count.
#include "drift/denoise.h"
#include "drift/image.h"
#include "drift_test.h"

#include <math.h>
#include <string.h>

#define W 64
#define H 48

static drift_image make_fill(drift_context *ctx, int32_t channels, float r, float g, float b)
{
    drift_image img;
    assert_int_equal(drift_image_create(ctx, W, H, channels, &img), DRIFT_OK);
    const float v[3] = { r, g, b };
    for (int32_t y = 0; y < H; ++y) {
        for (int32_t x = 0; x < W; ++x) {
            for (int c = 0; c < channels; ++c) {
                drift_image_pixel(&img, x, y)[c] = v[c < 3 ? c : 2];
            }
        }
    }
    return img;
}

// Flat guides: albedo 0.5, normal +z, depth 3.
typedef struct guides {
    drift_image albedo, normal, depth;
} guides;

static guides make_flat_guides(drift_context *ctx)
{
    return (guides){ make_fill(ctx, 3, 0.5f, 0.5f, 0.5f), make_fill(ctx, 3, 0.0f, 0.0f, 1.0f),
                     make_fill(ctx, 1, 3.0f, 0.0f, 0.0f) };
}

static void destroy_guides(drift_context *ctx, guides *g)
{
    drift_image_destroy(ctx, &g->albedo);
    drift_image_destroy(ctx, &g->normal);
    drift_image_destroy(ctx, &g->depth);
}

// Mean 0.4, i.i.d. uniform noise of amplitude 0.3 per channel.
static drift_image make_noise(drift_context *ctx, uint32_t seed)
{
    drift_image img = make_fill(ctx, 3, 0.0f, 0.0f, 0.0f);
    for (int32_t y = 0; y < H; ++y) {
        for (int32_t x = 0; x < W; ++x) {
            for (int c = 0; c < 3; ++c) {
                uint32_t i = seed ^ (uint32_t)((y * W + x) * 3 + c) * 2654435761u;
                drift_image_pixel(&img, x, y)[c] = 0.4f + 0.6f * (test_hash_unit(i) - 0.5f);
            }
        }
    }
    return img;
}

static double variance(const drift_image *img, int32_t x0, int32_t x1)
{
    double sum = 0.0, sum2 = 0.0;
    long n = 0;
    for (int32_t y = 0; y < img->height; ++y) {
        for (int32_t x = x0; x < x1; ++x) {
            for (int c = 0; c < 3; ++c) {
                double v = (double)drift_image_pixel(img, x, y)[c];
                sum += v;
                sum2 += v * v;
                ++n;
            }
        }
    }
    double mean = sum / (double)n;
    return sum2 / (double)n - mean * mean;
}

static void test_denoise_constant_image_is_unchanged(void **state)
{
    (void)state;
    drift_context *ctx = test_context(2, NULL);
    drift_image color = make_fill(ctx, 3, 0.25f, 0.5f, 2.0f);
    guides g = make_flat_guides(ctx);
    drift_image out;
    assert_int_equal(drift_denoise_atrous(ctx, &color, &g.albedo, &g.normal, &g.depth, NULL, &out),
                     DRIFT_OK);
    assert_int_equal(out.width, W);
    assert_int_equal(out.height, H);
    assert_int_equal(out.channels, 3);
    for (int32_t y = 0; y < H; ++y) {
        for (int32_t x = 0; x < W; ++x) {
            for (int c = 0; c < 3; ++c) {
                float want = drift_image_pixel(&color, x, y)[c];
                float got = drift_image_pixel(&out, x, y)[c];
                assert_true(fabsf(got - want) <= 1e-6f * want);
            }
        }
    }
    drift_image_destroy(ctx, &out);
    // Without guides too.
    assert_int_equal(drift_denoise_atrous(ctx, &color, NULL, NULL, NULL, NULL, &out), DRIFT_OK);
    assert_true(fabsf(drift_image_pixel(&out, 5, 7)[2] - 2.0f) <= 2e-6f);
    drift_image_destroy(ctx, &out);
    destroy_guides(ctx, &g);
    drift_image_destroy(ctx, &color);
    drift_context_destroy(ctx);
}

static void test_denoise_noise_variance_falls(void **state)
{
    (void)state;
    drift_context *ctx = test_context(2, NULL);
    drift_image color = make_noise(ctx, 11);
    guides g = make_flat_guides(ctx);
    drift_image out;
    assert_int_equal(drift_denoise_atrous(ctx, &color, &g.albedo, &g.normal, &g.depth, NULL, &out),
                     DRIFT_OK);
    double before = variance(&color, 0, W), after = variance(&out, 0, W);
    print_message("noise variance %.3g -> %.3g (x%.1f)\n", before, after, before / after);
    assert_true(before > 0.02);
    assert_true(after * 20.0 < before);
    drift_image_destroy(ctx, &out);
    destroy_guides(ctx, &g);
    drift_image_destroy(ctx, &color);
    drift_context_destroy(ctx);
}

// Noise over two halves of different brightness, with the step in the depth and normal guides
// only at column W/2: after filtering, each side keeps its own mean right up to the edge, and
// the noise falls on both sides.
static void test_denoise_guide_step_edge_stays_sharp(void **state)
{
    (void)state;
    drift_context *ctx = test_context(2, NULL);
    drift_image color = make_noise(ctx, 5);
    guides g = make_flat_guides(ctx);
    const int32_t edge = W / 2;
    for (int32_t y = 0; y < H; ++y) {
        for (int32_t x = edge; x < W; ++x) {
            float *c = drift_image_pixel(&color, x, y);
            for (int k = 0; k < 3; ++k) {
                c[k] = 0.1f * c[k]; // right side: mean 0.04
            }
            drift_image_pixel(&g.depth, x, y)[0] = 6.0f;
            float *n = drift_image_pixel(&g.normal, x, y);
            n[0] = 1.0f;
            n[1] = 0.0f;
            n[2] = 0.0f;
        }
    }
    drift_image out;
    assert_int_equal(drift_denoise_atrous(ctx, &color, &g.albedo, &g.normal, &g.depth, NULL, &out),
                     DRIFT_OK);
    // Column means next to the edge.
    double left = 0.0, right = 0.0;
    for (int32_t y = 0; y < H; ++y) {
        for (int c = 0; c < 3; ++c) {
            left += (double)drift_image_pixel(&out, edge - 1, y)[c];
            right += (double)drift_image_pixel(&out, edge, y)[c];
        }
    }
    left /= 3.0 * H;
    right /= 3.0 * H;
    print_message("column means at the edge: %.4f | %.4f\n", left, right);
    assert_true(fabs(left - 0.4) < 0.02);
    assert_true(fabs(right - 0.04) < 0.004);
    assert_true(variance(&out, 0, edge) * 10.0 < variance(&color, 0, edge));
    assert_true(variance(&out, edge, W) * 10.0 < variance(&color, edge, W));
    drift_image_destroy(ctx, &out);
    // The same image with flat guides and no colour weight blurs across the edge: the guides
    // are what keep it.
    guides flat = make_flat_guides(ctx);
    drift_denoise_params blur = { .disable_color = true };
    assert_int_equal(
        drift_denoise_atrous(ctx, &color, &flat.albedo, &flat.normal, &flat.depth, &blur, &out),
        DRIFT_OK);
    float blurred = drift_image_pixel(&out, edge, H / 2)[1];
    assert_true(blurred > 0.1f);
    drift_image_destroy(ctx, &out);
    destroy_guides(ctx, &flat);
    destroy_guides(ctx, &g);
    drift_image_destroy(ctx, &color);
    drift_context_destroy(ctx);
}

static void test_denoise_bit_identical_for_any_thread_count(void **state)
{
    (void)state;
    drift_image outs[3];
    const int threads[3] = { 1, 2, 5 };
    drift_context *ctxs[3];
    for (int t = 0; t < 3; ++t) {
        ctxs[t] = test_context(threads[t], NULL);
        drift_image color = make_noise(ctxs[t], 3);
        guides g = make_flat_guides(ctxs[t]);
        for (int32_t y = 0; y < H; ++y) {
            for (int32_t x = 0; x < W; ++x) {
                drift_image_pixel(&g.depth, x, y)[0] = 2.0f + 0.05f * (float)x;
                drift_image_pixel(&g.albedo, x, y)[0] = 0.2f + 0.01f * (float)y;
            }
        }
        assert_int_equal(
            drift_denoise_atrous(ctxs[t], &color, &g.albedo, &g.normal, &g.depth, NULL, &outs[t]),
            DRIFT_OK);
        destroy_guides(ctxs[t], &g);
        drift_image_destroy(ctxs[t], &color);
    }
    for (int t = 1; t < 3; ++t) {
        for (int32_t y = 0; y < H; ++y) {
            assert_memory_equal(drift_image_pixel(&outs[0], 0, y),
                                drift_image_pixel(&outs[t], 0, y), W * 3 * sizeof(float));
        }
    }
    for (int t = 0; t < 3; ++t) {
        drift_image_destroy(ctxs[t], &outs[t]);
        drift_context_destroy(ctxs[t]);
    }
}

static void test_denoise_rejects_bad_arguments(void **state)
{
    (void)state;
    test_log_capture capture = { 0 };
    drift_context *ctx = test_context(1, &capture);
    drift_image color = make_fill(ctx, 3, 1.0f, 1.0f, 1.0f);
    drift_image small;
    assert_int_equal(drift_image_create(ctx, W / 2, H, 1, &small), DRIFT_OK);
    drift_image out;
    assert_int_equal(drift_denoise_atrous(ctx, &color, NULL, NULL, &small, NULL, &out),
                     DRIFT_ERR_INVALID_ARGUMENT);
    assert_null(out.pixels);
    drift_denoise_params bad = { .iterations = 11 };
    assert_int_equal(drift_denoise_atrous(ctx, &color, NULL, NULL, NULL, &bad, &out),
                     DRIFT_ERR_INVALID_ARGUMENT);
    drift_image_destroy(ctx, &small);
    drift_image_destroy(ctx, &color);
    drift_context_destroy(ctx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_denoise_constant_image_is_unchanged),
        cmocka_unit_test(test_denoise_noise_variance_falls),
        cmocka_unit_test(test_denoise_guide_step_edge_stays_sharp),
        cmocka_unit_test(test_denoise_bit_identical_for_any_thread_count),
        cmocka_unit_test(test_denoise_rejects_bad_arguments),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
