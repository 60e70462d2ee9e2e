// The hybrid-guided denoiser (drift_denoise_guided, include/drift/denoise.h) on a synthetic
// frame whose truth is known: a checker-textured plane lit by E(x, y), a smooth gradient with a
// hard-edged shadow (a 20 x 14 box at 0.1 E). The guide is the truth biased as a hybrid frame
// is: its lighting 25 % too bright outside the shadow and 0.05 E too bright inside it, but
// noise-free and with the shadow's edge in place. The path tracer's mean of n samples has
// relative noise s / sqrt(n) (Gaussian) and its variance image the true variance of the mean.
// Each variant: RESIDUAL, REGRESSION, and RESIDUAL with the direct part apart.
// Properties: (1) at 4 spp each variant is closer to the truth than the plain feature denoiser on
// the same samples, and keeps the shadow's edge (within 0.8-1.3 of its step, where the plain
// denoiser keeps ~0.4); (2) at 4096 spp the guide's bias is gone from
// the output (within 2 %, where the guide is 25 % off); (3) a noise-free path tracer with a
// guide equal to the truth comes back as the truth; bad arguments are refused.
#include "drift/denoise.h"
#include "drift/image.h"
#include "drift_test.h"
#include "test_rig.h"

#include <math.h>

#define W       64
#define H       48
#define E       0.5f
#define CHECKER 8

static float gaussian(uint32_t i)
{
    float u1 = test_hash_unit(i * 2u + 1u), u2 = test_hash_unit(i * 2u + 2u);
    u1 = u1 > 1e-7f ? u1 : 1e-7f;
    return sqrtf(-2.0f * logf(u1)) * cosf(6.2831853f * u2);
}

static bool in_shadow(int32_t x, int32_t y)
{
    return x >= 22 && x < 42 && y >= 17 && y < 31;
}

// The true irradiance: a gradient, the shadow at a tenth of it.
static float irradiance(int32_t x, int32_t y)
{
    float g = E * (0.6f + 0.6f * (float)x / W + 0.3f * (float)y / H);
    return in_shadow(x, y) ? 0.1f * g : g;
}

// direct: 0.7 of the colour (and of its variance 0.49, the rest's 0.09); the guide's indirect
// part 0.3 of the guide: for the split residual.
typedef struct frame {
    drift_image color, albedo, normal, depth, variance, truth, guide;
    drift_image direct, direct_variance, indirect_variance, guide_indirect;
} frame;

#define PLANES 11

static frame make_frame(drift_context *ctx, uint32_t n, float s, float bias_scale,
                        float bias_shadow, uint32_t seed)
{
    frame v;
    drift_image *all[PLANES] = {
        &v.color,         &v.albedo, &v.normal, &v.depth,           &v.variance,
        &v.truth,         &v.guide,  &v.direct, &v.direct_variance, &v.indirect_variance,
        &v.guide_indirect
    };
    const int channels[PLANES] = { 3, 3, 3, 1, 1, 3, 3, 3, 1, 1, 3 };
    for (int i = 0; i < PLANES; ++i) {
        assert_int_equal(drift_image_create(ctx, W, H, channels[i], all[i]), DRIFT_OK);
    }
    for (int32_t y = 0; y < H; ++y) {
        for (int32_t x = 0; x < W; ++x) {
            float a = ((x / CHECKER + y / CHECKER) & 1) ? 0.8f : 0.2f;
            float e = irradiance(x, y);
            float noise = s / sqrtf((float)n) * gaussian(seed * 7919u + (uint32_t)(y * W + x));
            float guide = in_shadow(x, y) ? e + bias_shadow * E : e * bias_scale;
            for (int c = 0; c < 3; ++c) {
                drift_image_pixel(&v.color, x, y)[c] = a * e * (1.0f + noise);
                drift_image_pixel(&v.truth, x, y)[c] = a * e;
                drift_image_pixel(&v.guide, x, y)[c] = a * guide;
                drift_image_pixel(&v.direct, x, y)[c] = 0.7f * a * e * (1.0f + noise);
                drift_image_pixel(&v.guide_indirect, x, y)[c] = 0.3f * a * guide;
                drift_image_pixel(&v.albedo, x, y)[c] = a;
                drift_image_pixel(&v.normal, x, y)[c] = c == 2 ? 1.0f : 0.0f;
            }
            *drift_image_pixel(&v.depth, x, y) = 3.0f;
            float sd = a * e * s;
            *drift_image_pixel(&v.variance, x, y) = sd * sd / (float)n;
            *drift_image_pixel(&v.direct_variance, x, y) = 0.49f * sd * sd / (float)n;
            *drift_image_pixel(&v.indirect_variance, x, y) = 0.09f * sd * sd / (float)n;
        }
    }
    return v;
}

static void destroy_frame(drift_context *ctx, frame *v)
{
    drift_image *all[PLANES] = {
        &v->color,         &v->albedo, &v->normal, &v->depth,           &v->variance,
        &v->truth,         &v->guide,  &v->direct, &v->direct_variance, &v->indirect_variance,
        &v->guide_indirect
    };
    for (int i = 0; i < PLANES; ++i) {
        drift_image_destroy(ctx, all[i]);
    }
}

static drift_denoise_inputs inputs_of(const frame *v, uint32_t n)
{
    return (drift_denoise_inputs){ .color = &v->color,
                                   .albedo = &v->albedo,
                                   .normal = &v->normal,
                                   .depth = &v->depth,
                                   .variance = &v->variance,
                                   .sample_count = n };
}

// Variant m: 0 RESIDUAL, 1 REGRESSION, 2 RESIDUAL with the direct part apart.
#define VARIANTS 3

static drift_result guided(drift_context *ctx, const frame *v, uint32_t n, int m, drift_image *out)
{
    drift_denoise_inputs in = inputs_of(v, n);
    if (m == 2) {
        in.direct = &v->direct;
        in.direct_variance = &v->direct_variance;
        in.indirect_variance = &v->indirect_variance;
    }
    return drift_denoise_guided(ctx, &in, &v->guide, m == 2 ? &v->guide_indirect : NULL,
                                m == 1 ? DRIFT_GUIDE_REGRESSION : DRIFT_GUIDE_RESIDUAL, NULL, out,
                                NULL);
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

// The mean of the image's demodulated green over a region (shadow or lit), over the truth's.
static double region_ratio(const frame *v, const drift_image *img, bool shadow)
{
    double sum = 0.0, truth = 0.0;
    for (int32_t y = 0; y < H; ++y) {
        for (int32_t x = 0; x < W; ++x) {
            if (in_shadow(x, y) == shadow) {
                sum += (double)drift_image_pixel(img, x, y)[1];
                truth += (double)drift_image_pixel(&v->truth, x, y)[1];
            }
        }
    }
    return sum / truth;
}

// The shadow's edge: mean over the box's left and right edges of the image's step between
// the pixel inside and the one outside, over the truth's (1: the edge is kept sharp).
static double shadow_edge(const frame *v, const drift_image *img)
{
    double sum = 0.0;
    int count = 0;
    for (int32_t y = 18; y < 30; ++y) {
        const int32_t pairs[2][2] = { { 21, 22 }, { 42, 41 } }; // outside, inside
        for (int k = 0; k < 2; ++k) {
            const float *ao = drift_image_pixel(&v->albedo, pairs[k][0], y);
            const float *ai = drift_image_pixel(&v->albedo, pairs[k][1], y);
            double o = (double)(drift_image_pixel(img, pairs[k][0], y)[1] / ao[1]);
            double i = (double)(drift_image_pixel(img, pairs[k][1], y)[1] / ai[1]);
            double to = (double)irradiance(pairs[k][0], y), ti = (double)irradiance(pairs[k][1], y);
            sum += (o - i) / (to - ti);
            ++count;
        }
    }
    return sum / count;
}

static void test_denoise_guided_beats_the_plain_denoiser_at_few_samples(void **state)
{
    (void)state;
    drift_context *ctx = test_context(2, NULL);
    frame v = make_frame(ctx, 4, 1.5f, 1.25f, 0.05f, 3);
    drift_denoise_inputs in = inputs_of(&v, 4);
    drift_image plain, out;
    assert_int_equal(drift_denoise_feature(ctx, &in, NULL, &plain, NULL), DRIFT_OK);
    double e_noisy = mse(&v.color, &v.truth), e_guide = mse(&v.guide, &v.truth),
           e_plain = mse(&plain, &v.truth);
    print_message("4 spp: mse noisy %.3g, guide %.3g, plain denoiser %.3g (shadow edge %.2f)\n",
                  e_noisy, e_guide, e_plain, shadow_edge(&v, &plain));
    for (int m = 0; m < VARIANTS; ++m) {
        assert_int_equal(guided(ctx, &v, 4, m, &out), DRIFT_OK);
        double e = mse(&out, &v.truth), edge = shadow_edge(&v, &out);
        print_message("  variant %d: mse %.3g, shadow edge %.2f\n", m, e, edge);
        assert_true(e < 0.7 * e_plain);
        assert_true(e < e_guide);
        assert_true(edge > 0.8 && edge < 1.3); // the residual has its own step there
        drift_image_destroy(ctx, &out);
    }
    drift_image_destroy(ctx, &plain);
    destroy_frame(ctx, &v);
    drift_context_destroy(ctx);
}

static void test_denoise_guided_bias_does_not_survive_many_samples(void **state)
{
    (void)state;
    drift_context *ctx = test_context(2, NULL);
    frame v = make_frame(ctx, 4096, 1.5f, 1.25f, 0.05f, 5);
    print_message("4096 spp: the guide's lit / shadow means over the truth %.3f / %.3f\n",
                  region_ratio(&v, &v.guide, false), region_ratio(&v, &v.guide, true));
    for (int m = 0; m < VARIANTS; ++m) {
        drift_image out;
        assert_int_equal(guided(ctx, &v, 4096, m, &out), DRIFT_OK);
        double lit = region_ratio(&v, &out, false), shadow = region_ratio(&v, &out, true);
        print_message("  variant %d: lit %.4f, shadow %.4f\n", m, lit, shadow);
        assert_true(fabs(lit - 1.0) < 0.02);
        assert_true(fabs(shadow - 1.0) < 0.02);
        drift_image_destroy(ctx, &out);
    }
    destroy_frame(ctx, &v);
    drift_context_destroy(ctx);
}

static void test_denoise_guided_exact_guide_and_bad_arguments(void **state)
{
    (void)state;
    test_log_capture capture = { 0 };
    drift_context *ctx = test_context(2, &capture);
    frame v = make_frame(ctx, 16, 0.0f, 1.0f, 0.0f, 7); // no noise, the guide is the truth
    drift_denoise_inputs in = inputs_of(&v, 16);
    for (int m = 0; m < VARIANTS; ++m) {
        drift_image out;
        assert_int_equal(guided(ctx, &v, 16, m, &out), DRIFT_OK);
        double worst = 0.0;
        for (int32_t y = 0; y < H; ++y) {
            for (int32_t x = 0; x < W; ++x) {
                double o = (double)drift_image_pixel(&out, x, y)[1],
                       t = (double)drift_image_pixel(&v.truth, x, y)[1];
                worst = fmax(worst, fabs(o / t - 1.0));
            }
        }
        print_message("exact guide, variant %d: worst relative error %.2g\n", m, worst);
        assert_true(worst < 1e-3);
        drift_image_destroy(ctx, &out);
    }
    drift_image small, out;
    assert_int_equal(drift_image_create(ctx, W / 2, H, 3, &small), DRIFT_OK);
    assert_int_equal(
        drift_denoise_guided(ctx, &in, &small, NULL, DRIFT_GUIDE_RESIDUAL, NULL, &out, NULL),
        DRIFT_ERR_INVALID_ARGUMENT);
    assert_null(out.pixels);
    assert_int_equal(
        drift_denoise_guided(ctx, &in, &v.guide, NULL, DRIFT_GUIDE_MODE_COUNT, NULL, &out, NULL),
        DRIFT_ERR_INVALID_ARGUMENT);
    // REGRESSION with a direct part; a signed colour with a direct part in the plain
    // denoiser (its split would clamp the rest).
    in.direct = &v.direct;
    in.direct_variance = &v.direct_variance;
    in.indirect_variance = &v.indirect_variance;
    assert_int_equal(
        drift_denoise_guided(ctx, &in, &v.guide, NULL, DRIFT_GUIDE_REGRESSION, NULL, &out, NULL),
        DRIFT_ERR_INVALID_ARGUMENT);
    drift_denoise_feature_params signed_params = { .signed_color = true };
    assert_int_equal(drift_denoise_feature(ctx, &in, &signed_params, &out, NULL),
                     DRIFT_ERR_INVALID_ARGUMENT);
    assert_int_equal(capture.errors, 4);
    drift_image_destroy(ctx, &small);
    destroy_frame(ctx, &v);
    drift_context_destroy(ctx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_denoise_guided_beats_the_plain_denoiser_at_few_samples),
        cmocka_unit_test(test_denoise_guided_bias_does_not_survive_many_samples),
        cmocka_unit_test(test_denoise_guided_exact_guide_and_bad_arguments),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
