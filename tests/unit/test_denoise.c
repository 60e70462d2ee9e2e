// The edge-avoiding a-trous filter (include/drift/denoise.h): a constant image is a fixed
// point, i.i.d. noise on a flat image loses most of its variance, a step edge in the guides is
// kept, one pass is the header's formula evaluated directly (either kernel), and the output
// depends neither on the thread count nor on earlier calls (the planes the context keeps).
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

// One pass of the filter written straight from drift/denoise.h's formulas, in double
// precision and with libm's exp, at pixel (x, y): the vectorised filter must agree with it.
static void reference_pass(const drift_image *color, const guides *g, int radius,
                           double sigma_color, int32_t x, int32_t y, double out[3])
{
    static const double b3[5] = { 1.0 / 16, 1.0 / 4, 3.0 / 8, 1.0 / 4, 1.0 / 16 };
    static const double b1[3] = { 1.0 / 4, 1.0 / 2, 1.0 / 4 };
    const double *kernel = radius == 1 ? b1 : b3;
    // Demodulated colour (the albedo guide is above the 1e-3 floor everywhere here).
#define DEMOD(px, py, c) \
    ((double)drift_image_pixel(color, px, py)[c] / (double)drift_image_pixel(&g->albedo, px, py)[c])
#define LUM(px, py) \
    fabs(0.2126 * DEMOD(px, py, 0) + 0.7152 * DEMOD(px, py, 1) + 0.0722 * DEMOD(px, py, 2))
    double sum[3] = { 0, 0, 0 }, wsum = 0;
    const float *np = drift_image_pixel(&g->normal, x, y),
                *ap = drift_image_pixel(&g->albedo, x, y);
    double zp = drift_image_pixel(&g->depth, x, y)[0];
    for (int dy = -radius; dy <= radius; ++dy) {
        for (int dx = -radius; dx <= radius; ++dx) {
            int32_t qx = x + dx, qy = y + dy;
            if (qx < 0 || qy < 0 || qx >= W || qy >= H) {
                continue;
            }
            const float *nq = drift_image_pixel(&g->normal, qx, qy);
            const float *aq = drift_image_pixel(&g->albedo, qx, qy);
            double zq = drift_image_pixel(&g->depth, qx, qy)[0];
            double dot = (double)np[0] * (double)nq[0] + (double)np[1] * (double)nq[1] +
                         (double)np[2] * (double)nq[2];
            double e = fabs(zp - zq) / (0.1 * zp), da = 0, dc = 0;
            for (int c = 0; c < 3; ++c) {
                double d_albedo = (double)ap[c] - (double)aq[c];
                da += d_albedo * d_albedo;
                double d = DEMOD(x, y, c) - DEMOD(qx, qy, c);
                dc += d * d;
            }
            double mean = 0.5 * (LUM(x, y) + LUM(qx, qy)) + 1e-2;
            e += da / (0.1 * 0.1) + dc / (sigma_color * sigma_color * mean * mean);
            double w = kernel[dx + radius] * kernel[dy + radius];
            if (dx != 0 || dy != 0) {
                w = e > 30.0 ? 0.0 : w * pow(fmax(dot, 0.0), 128.0) * exp(-e);
            }
            for (int c = 0; c < 3; ++c) {
                sum[c] += w * DEMOD(qx, qy, c);
            }
            wsum += w;
        }
    }
    for (int c = 0; c < 3; ++c) {
        out[c] = sum[c] / wsum * (double)ap[c];
    }
#undef LUM
#undef DEMOD
}

// Random colour over random guides (depth, albedo and a normal tilted up to ~10 degrees, so
// that every weight is between 0 and 1): one pass of either kernel equals the formulas of
// drift/denoise.h evaluated directly, to 1e-4 relative.
static void test_denoise_one_pass_is_the_formula(void **state)
{
    (void)state;
    drift_context *ctx = test_context(2, NULL);
    drift_image color = make_noise(ctx, 5);
    guides g = make_flat_guides(ctx);
    for (int32_t y = 0; y < H; ++y) {
        for (int32_t x = 0; x < W; ++x) {
            uint32_t i = (uint32_t)(y * W + x) * 2654435761u;
            float tx = 0.15f * (test_hash_unit(i ^ 1u) - 0.5f);
            float ty = 0.15f * (test_hash_unit(i ^ 2u) - 0.5f);
            float *n = drift_image_pixel(&g.normal, x, y);
            float len = sqrtf(tx * tx + ty * ty + 1.0f);
            n[0] = tx / len, n[1] = ty / len, n[2] = 1.0f / len;
            for (int c = 0; c < 3; ++c) {
                drift_image_pixel(&g.albedo, x, y)[c] = 0.4f + 0.1f * test_hash_unit(i ^ (3u + c));
            }
            drift_image_pixel(&g.depth, x, y)[0] = 3.0f + 0.1f * test_hash_unit(i ^ 7u);
        }
    }
    for (int radius = 1; radius <= 2; ++radius) {
        drift_image out;
        drift_denoise_params params = { .iterations = 1,
                                        .sigma_color = 4.0f,
                                        .small_kernel = radius == 1 };
        assert_int_equal(
            drift_denoise_atrous(ctx, &color, &g.albedo, &g.normal, &g.depth, &params, &out),
            DRIFT_OK);
        double worst = 0.0, moved = 0.0;
        for (int32_t y = 0; y < H; ++y) {
            for (int32_t x = 0; x < W; ++x) {
                double want[3];
                reference_pass(&color, &g, radius, 4.0, x, y, want);
                for (int c = 0; c < 3; ++c) {
                    double got = drift_image_pixel(&out, x, y)[c];
                    worst = fmax(worst, fabs(got - want[c]) / want[c]);
                    moved = fmax(moved, fabs(want[c] - (double)drift_image_pixel(&color, x, y)[c]));
                }
            }
        }
        print_message("%dx%d kernel: worst relative difference from the formula %.3g (the "
                      "filter moves pixels by up to %.3g)\n",
                      2 * radius + 1, 2 * radius + 1, worst, moved);
        assert_true(moved > 0.05); // the weights do mix
        assert_true(worst < 1e-4);
        drift_image_destroy(ctx, &out);
    }
    destroy_guides(ctx, &g);
    drift_image_destroy(ctx, &color);
    drift_context_destroy(ctx);
}

// The 3x3 kernel: a constant image stays, and noise on a flat image falls as with the 5x5.
static void test_denoise_small_kernel_smooths(void **state)
{
    (void)state;
    drift_context *ctx = test_context(2, NULL);
    drift_image color = make_noise(ctx, 13), flat = make_fill(ctx, 3, 0.25f, 0.5f, 2.0f);
    guides g = make_flat_guides(ctx);
    drift_denoise_params params = { .iterations = 4, .small_kernel = true, .disable_color = true };
    drift_image out;
    assert_int_equal(
        drift_denoise_atrous(ctx, &color, &g.albedo, &g.normal, &g.depth, &params, &out), DRIFT_OK);
    double before = variance(&color, 0, W), after = variance(&out, 0, W);
    print_message("3x3, 4 passes: noise variance %.3g -> %.3g (x%.1f)\n", before, after,
                  before / after);
    assert_true(after * 20.0 < before);
    drift_image_destroy(ctx, &out);
    assert_int_equal(
        drift_denoise_atrous(ctx, &flat, &g.albedo, &g.normal, &g.depth, &params, &out), DRIFT_OK);
    assert_true(fabsf(drift_image_pixel(&out, 9, 3)[1] - 0.5f) <= 1e-6f);
    drift_image_destroy(ctx, &out);
    destroy_guides(ctx, &g);
    drift_image_destroy(ctx, &color);
    drift_image_destroy(ctx, &flat);
    drift_context_destroy(ctx);
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

// The context keeps the filter's planes between calls (core/scratch.h): a call after others
// (a larger image, another kernel) leaves the same image as the first call on that context.
static void test_denoise_kept_planes_change_nothing(void **state)
{
    (void)state;
    drift_context *ctx = test_context(2, NULL);
    drift_image color = make_noise(ctx, 21), other = make_noise(ctx, 22), first, again, big;
    guides g = make_flat_guides(ctx);
    for (int32_t y = 0; y < H; ++y) {
        for (int32_t x = 0; x < W; ++x) {
            drift_image_pixel(&g.depth, x, y)[0] = x < W / 2 ? 2.0f : 0.0f; // misses on the right
        }
    }
    assert_int_equal(
        drift_denoise_atrous(ctx, &color, &g.albedo, &g.normal, &g.depth, NULL, &first), DRIFT_OK);
    drift_denoise_params small = { .small_kernel = true, .iterations = 3 };
    assert_int_equal(drift_denoise_atrous(ctx, &other, NULL, NULL, NULL, &small, &again), DRIFT_OK);
    drift_image_destroy(ctx, &again);
    drift_image wide;
    assert_int_equal(drift_image_create(ctx, 2 * W, H, 3, &wide), DRIFT_OK);
    assert_int_equal(drift_denoise_atrous(ctx, &wide, NULL, NULL, NULL, NULL, &big), DRIFT_OK);
    assert_int_equal(
        drift_denoise_atrous(ctx, &color, &g.albedo, &g.normal, &g.depth, NULL, &again), DRIFT_OK);
    for (int32_t y = 0; y < H; ++y) {
        assert_memory_equal(drift_image_pixel(&first, 0, y), drift_image_pixel(&again, 0, y),
                            W * 3 * sizeof(float));
    }
    drift_image_destroy(ctx, &big);
    drift_image_destroy(ctx, &wide);
    drift_image_destroy(ctx, &again);
    drift_image_destroy(ctx, &first);
    destroy_guides(ctx, &g);
    drift_image_destroy(ctx, &other);
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
        cmocka_unit_test(test_denoise_one_pass_is_the_formula),
        cmocka_unit_test(test_denoise_small_kernel_smooths),
        cmocka_unit_test(test_denoise_rejects_bad_arguments),
        cmocka_unit_test(test_denoise_kept_planes_change_nothing),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
