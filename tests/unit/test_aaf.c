// Axis-aligned filtering (src/hybrid/aaf_*.c) against the reference path tracer and against
// properties: the error falls as spp grows (the filter shrinks with samples) and beats plain
// Monte Carlo at equal spp; full light and full shadow stay exactly 1 and 0; beta grows with
// the receiver-to-occluder distance and n(x) peaks at contact edges; the separable filter
// stays close to the exact 2-D filter on a smooth penumbra; the sample budget holds its mean.
// ctest-labels: quality slow
#include "aaf/aaf.h"
#include "drift/accel.h"
#include "drift/hybrid.h"
#include "drift/pt.h"
#include "drift/scene.h"
#include "drift_test.h"
#include "test_rig.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

// The path tracer's truth of a term (seed 1234).
static drift_image render_pt(test_rig *r, uint32_t components, int32_t max_depth, uint32_t spp,
                             drift_pt **pt)
{
    return test_rig_render_pt(r, components, max_depth, spp, 1234, pt);
}

// Horizontal square of half size `half` centred at (x, h, z).
static void add_square(drift_scene *scene, float x, float h, float z, float half, uint32_t material)
{
    test_add_quad(scene, drift_vec3_make(x - half, h, z - half), drift_vec3_make(2 * half, 0, 0),
                  drift_vec3_make(0, 0, 2 * half), material);
}

// A 1x1 quad light at height 3 centred over the origin, emitting down.
static void add_light(drift_scene *scene)
{
    test_add_quad_light(scene, drift_vec3_make(-0.5f, 3.0f, -0.5f), drift_vec3_make(1, 0, 0),
                        drift_vec3_make(0, 0, 1), 5.0f);
}

enum {
    W = 64,
    H = 48
};

// A floor under the light with a low square (h 0.6, x < 0), a high one (h 1.2, x > 0) and a
// wall standing on the floor at z = -1.2 (a contact edge), seen from below the light. Large
// enough (96x72) that the penumbrae span a few pixels; the convergence test, which measures
// the whole image's error, takes 64x48.
enum {
    SW = 96,
    SH = 72
};

static void build_shadow_scene_at(test_rig *r, int32_t width, int32_t height)
{
    uint32_t white;
    drift_material m = drift_material_make(drift_vec3_splat(0.6f));
    assert_int_equal(drift_scene_add_material(r->scene, &m, &white), DRIFT_OK);
    add_square(r->scene, 0.0f, 0.0f, 0.0f, 4.0f, white);
    add_square(r->scene, -1.2f, 0.6f, 0.0f, 0.3f, white);
    add_square(r->scene, 0.7f, 1.2f, 0.0f, 0.2f, white);
    test_add_quad(r->scene, drift_vec3_make(-0.4f, 0.0f, -1.2f), drift_vec3_make(0.8f, 0, 0),
                  drift_vec3_make(0, 0.6f, 0), white);
    add_light(r->scene);
    // Over the wall's far side, so the floor behind its foot is in view.
    r->scene->camera =
        drift_camera_look_at(drift_vec3_make(0, 2.5f, -1.25f), drift_vec3_make(0, 0, -1.24f),
                             drift_vec3_make(0, 0, 1), 1.4f, width, height);
}

static void build_shadow_scene(test_rig *r)
{
    build_shadow_scene_at(r, SW, SH);
}

// The shadow frame's error against the path-traced direct light falls as spp grows, and at
// low equal spp AAF beats plain Monte Carlo with the same sampler.
static void test_shadows_converge(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    build_shadow_scene_at(&r, 64, 48);
    test_rig_commit(&r);
    drift_pt *pt = NULL;
    uint32_t truth_spp = (uint32_t)(512 * test_intensity());
    drift_image truth = render_pt(&r, DRIFT_PT_COMPONENT_EMISSION | DRIFT_PT_COMPONENT_DIRECT, 1,
                                  truth_spp < 256 ? 256 : truth_spp, &pt);
    const uint32_t spps[3] = { 4, 16, 64 };
    double aaf[3], plain[3];
    for (int k = 0; k < 3; ++k) {
        test_rig_frame(
            &r, &(drift_hybrid_params){ .shadows = DRIFT_SHADOWS_AAF, .spp = spps[k], .seed = 3 });
        aaf[k] = test_rmse(r.ctx, drift_hybrid_image(r.frame), &truth);
        test_rig_frame(&r, &(drift_hybrid_params){ .shadows = DRIFT_SHADOWS_AAF,
                                                   .spp = spps[k],
                                                   .seed = 3,
                                                   .aaf.uniform = true,
                                                   .aaf.unfiltered = true });
        plain[k] = test_rmse(r.ctx, drift_hybrid_image(r.frame), &truth);
    }
    print_message("shadows rmse aaf %g %g %g, plain MC %g %g %g\n", aaf[0], aaf[1], aaf[2],
                  plain[0], plain[1], plain[2]);
    assert_true(aaf[1] < 0.9 * aaf[0]);
    assert_true(aaf[2] < 0.9 * aaf[1]);
    // At 64 spp the penumbrae of this small image are well sampled and the filter's bias
    // matches its gain (docs/aaf.md): AAF ties plain Monte Carlo there.
    assert_true(aaf[0] < 0.75 * plain[0]);
    assert_true(aaf[1] < 0.75 * plain[1]);
    assert_true(aaf[2] < 1.1 * plain[2]);
    drift_pt_destroy(pt);
    test_rig_destroy(&r);
}

// Regions on the floor (y = 0) of the shadow scene.
typedef enum region {
    REGION_NONE,
    REGION_LOW,
    REGION_HIGH,
    REGION_CONTACT
} region;

static region floor_region(drift_vec3 p)
{
    if (fabsf(p.y) > 1e-3f) {
        return REGION_NONE;
    }
    if (p.z < -1.2f && p.z > -1.35f && fabsf(p.x) < 0.35f) {
        return REGION_CONTACT; // just behind the wall's foot, away from the light
    }
    if (fabsf(p.z) < 0.8f) {
        return p.x < -0.2f ? REGION_LOW : (p.x > 0.2f ? REGION_HIGH : REGION_NONE);
    }
    return REGION_NONE;
}

// The frame's direct-light plane, copied (the frame is replaced by the next render).
static drift_image direct_plane(test_rig *r)
{
    return test_image_copy(r->ctx, test_rig_plane(r, "direct"));
}

// On the Cornell box at 4 spp AAF's shadows have well under plain Monte Carlo's error and
// their mean is the reference's (issue 17). With beta and n(x) from each pixel's own sparse
// rays the contacts were biased: at 64x64 the RMSE ratio was 1.30 and the mean 0.9979 of the
// reference (now 1.87 and 1.0008; the 160x120 bench's equal-error ratio 1.73x -> 6.95x).
static void test_shadows_at_4_spp_on_the_cornell_box(void **state)
{
    (void)state;
    const int32_t w = 64;
    test_rig r = test_rig_load(2, "scenes/cornell-box/cornell_box.json", w);
    uint32_t truth_spp = (uint32_t)(256 * test_intensity());
    test_rig_frame(&r, &(drift_hybrid_params){ .width = w,
                                               .height = w,
                                               .shadows = DRIFT_SHADOWS_REFERENCE,
                                               .spp = truth_spp < 256 ? 256 : truth_spp,
                                               .light_samples = 64,
                                               .seed = 9 });
    drift_image truth = direct_plane(&r);
    double error[2] = { 0.0, 0.0 }, mean = 0.0;
    const uint32_t seeds = 2;
    for (uint32_t seed = 1; seed <= seeds; ++seed) {
        for (int method = 0; method < 2; ++method) {
            test_rig_frame(&r, &(drift_hybrid_params){ .width = w,
                                                       .height = w,
                                                       .shadows = DRIFT_SHADOWS_AAF,
                                                       .spp = 4,
                                                       .light_samples = 64,
                                                       .seed = seed,
                                                       .aaf.uniform = method == 1,
                                                       .aaf.unfiltered = method == 1 });
            drift_image test = direct_plane(&r);
            double e = test_rmse(r.ctx, &test, &truth);
            error[method] += e * e / seeds;
            if (method == 0) {
                mean +=
                    drift_image_mean_luminance(&test) / drift_image_mean_luminance(&truth) / seeds;
            }
            drift_image_destroy(r.ctx, &test);
        }
    }
    double aaf = sqrt(error[0]), plain = sqrt(error[1]);
    print_message("4 spp rmse aaf %g plain MC %g (ratio %g); mean / reference %g\n", aaf, plain,
                  plain / aaf, mean);
    assert_true(aaf < 0.65 * plain);
    assert_true(fabs(mean - 1.0) < 0.0015);
    drift_image_destroy(r.ctx, &truth);
    test_rig_destroy(&r);
}

// beta grows with the receiver-to-occluder distance (the high square's penumbra is wider
// than the low one's, which is wider than the wall's foot), and the sample rate n(x) is
// highest at the hard contact edge.
static void test_beta_and_rate_follow_the_geometry(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    build_shadow_scene(&r);
    test_rig_commit(&r);
    test_rig_frame(&r,
                   &(drift_hybrid_params){ .shadows = DRIFT_SHADOWS_AAF, .spp = 16, .seed = 2 });
    const drift_gbuffer *g = drift_hybrid_gbuffer(r.frame);
    const drift_image *beta = test_rig_plane(&r, "light0.aaf.beta"),
                      *spp = test_rig_plane(&r, "light0.aaf.spp");
    double beta_sum[4] = { 0 }, spp_sum[4] = { 0 };
    int count[4] = { 0 };
    for (int y = 0; y < SH; ++y) {
        for (int x = 0; x < SW; ++x) {
            region k = floor_region(drift_image_get3(&g->position, x, y));
            float b = drift_image_pixel(beta, x, y)[0];
            if (k == REGION_NONE || !(b > 0.0f)) {
                continue;
            }
            beta_sum[k] += (double)b;
            spp_sum[k] += (double)drift_image_pixel(spp, x, y)[0];
            ++count[k];
        }
    }
    for (int k = REGION_LOW; k <= REGION_CONTACT; ++k) {
        assert_true(count[k] > 0);
        beta_sum[k] /= count[k];
        spp_sum[k] /= count[k];
    }
    print_message("beta low %g high %g contact %g; n low %g high %g contact %g\n", beta_sum[1],
                  beta_sum[2], beta_sum[3], spp_sum[1], spp_sum[2], spp_sum[3]);
    assert_true(beta_sum[REGION_HIGH] > 1.5 * beta_sum[REGION_LOW]);
    assert_true(beta_sum[REGION_LOW] > beta_sum[REGION_CONTACT]);
    assert_true(spp_sum[REGION_CONTACT] > spp_sum[REGION_LOW]);
    assert_true(spp_sum[REGION_LOW] > spp_sum[REGION_HIGH]);
    test_rig_destroy(&r);
}

// A plane in full light keeps S = 1 exactly; a plane under a roof that hides the whole light
// keeps S = 0 exactly (both are flat: no pixel is filtered; the filter's own exactness on
// constant images is checked in test_separable_filter_close_to_exact).
static void test_full_light_and_full_shadow_are_exact(void **state)
{
    (void)state;
    for (int roofed = 0; roofed < 2; ++roofed) {
        test_rig r = test_rig_begin(2);
        drift_material m = drift_material_make(drift_vec3_splat(0.5f));
        uint32_t white;
        assert_int_equal(drift_scene_add_material(r.scene, &m, &white), DRIFT_OK);
        add_square(r.scene, 0.0f, 0.0f, 0.0f, 4.0f, white);
        if (roofed) {
            add_square(r.scene, 0.0f, 1.5f, 0.0f, 20.0f, white);
        }
        add_light(r.scene);
        r.scene->camera =
            drift_camera_look_at(drift_vec3_make(0, 1.2f, -0.01f), drift_vec3_make(0, 0, 0),
                                 drift_vec3_make(0, 0, 1), 1.0f, W, H);
        test_rig_commit(&r);
        test_rig_frame(
            &r, &(drift_hybrid_params){ .shadows = DRIFT_SHADOWS_AAF, .spp = 16, .seed = 4 });
        const drift_image *s = test_rig_plane(&r, "light0.shadow"),
                          *beta = test_rig_plane(&r, "light0.aaf.beta");
        int filtered = 0;
        for (int y = 0; y < H; ++y) {
            for (int x = 0; x < W; ++x) {
                assert_true(drift_image_pixel(s, x, y)[0] == (roofed ? 0.0f : 1.0f));
                filtered += drift_image_pixel(beta, x, y)[0] > 0.0f;
            }
        }
        assert_int_equal(filtered, 0);
        test_rig_destroy(&r);
    }
}

// A pixel is kept at its sparse rays (flat, exactly 0 or 1) only on the word of enough rays:
// a lit square two pixels across, floating over the shadow scene (its pixels have few
// neighbours on their surface, so the 2 sparse rays a pixel at 4 spp are all there is), takes
// at least --spp samples a pixel, as plain sampling would give it, and stays exactly lit. It
// was flat on 2 rays: at 4 spp the Breakfast Room's small surfaces held a third of AAF's error
// that way (docs/aaf.md).
static void test_few_rays_do_not_make_a_pixel_flat(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    build_shadow_scene(&r);
    uint32_t white;
    drift_material m = drift_material_make(drift_vec3_splat(0.6f));
    assert_int_equal(drift_scene_add_material(r.scene, &m, &white), DRIFT_OK);
    const float height = 2.0f, half = 0.01f; // 0.5 below the camera: about 2 x 2 pixels
    add_square(r.scene, 0.2f, height, -1.1f, half, white);
    test_rig_commit(&r);
    const uint32_t spp = 4;
    assert_true(drift_aaf_shadow_sparse_count(spp) < spp);
    test_rig_frame(&r,
                   &(drift_hybrid_params){ .shadows = DRIFT_SHADOWS_AAF, .spp = spp, .seed = 5 });
    const drift_gbuffer *g = drift_hybrid_gbuffer(r.frame);
    const drift_image *taken = test_rig_plane(&r, "light0.aaf.spp"),
                      *shadow = test_rig_plane(&r, "light0.shadow");
    int pixels = 0;
    for (int y = 0; y < SH; ++y) {
        for (int x = 0; x < SW; ++x) {
            if (drift_image_pixel(&g->material_id, x, y)[0] < 0.0f ||
                fabsf(drift_image_get3(&g->position, x, y).y - height) > 1e-3f) {
                continue;
            }
            ++pixels;
            assert_true(drift_image_pixel(taken, x, y)[0] >= (float)spp);
            assert_true(drift_image_pixel(shadow, x, y)[0] == 1.0f);
        }
    }
    print_message("%d pixels on the small square\n", pixels);
    assert_true(pixels >= 1 && pixels <= 6);
    test_rig_destroy(&r);
}

// The separable filter (eq. 3.7) against the exact 2-D filter (eq. 3.2) on a smooth, curved
// penumbra with a slowly varying beta: the largest difference stays under 0.02 (visibility
// units) and the mean under 0.002, while the filter itself moves values by far more.
static void test_separable_filter_close_to_exact(void **state)
{
    (void)state;
    drift_context *ctx = test_context(2, NULL);

    enum {
        FW = 160,
        FH = 120
    };

    drift_gbuffer g;
    assert_int_equal(drift_gbuffer_create(ctx, FW, FH, &g), DRIFT_OK);
    drift_image in, sep, exact, scratch, beta, footprint;
    assert_int_equal(drift_image_create(ctx, FW, FH, 1, &in), DRIFT_OK);
    assert_int_equal(drift_image_create(ctx, FW, FH, 1, &sep), DRIFT_OK);
    assert_int_equal(drift_image_create(ctx, FW, FH, 1, &exact), DRIFT_OK);
    assert_int_equal(drift_image_create(ctx, FW, FH, 1, &scratch), DRIFT_OK);
    assert_int_equal(drift_image_create(ctx, FW, FH, 1, &beta), DRIFT_OK);
    assert_int_equal(drift_image_create(ctx, FW, FH, 1, &footprint), DRIFT_OK);
    const float pixel = 0.01f;
    for (int y = 0; y < FH; ++y) {
        for (int x = 0; x < FW; ++x) {
            drift_image_set3(&g.position, x, y,
                             drift_vec3_make((float)x * pixel, 0.0f, (float)y * pixel));
            drift_image_set3(&g.normal, x, y, drift_vec3_make(0, 1, 0));
            drift_image_pixel(&g.depth, x, y)[0] = 1.0f;
            drift_image_pixel(&g.material_id, x, y)[0] = 0.0f;
            drift_image_pixel(&footprint, x, y)[0] = pixel;
            // A curved edge whose penumbra widens to the right, beta following it.
            float edge = 60.0f + 12.0f * sinf((float)y / 15.0f);
            float width = 6.0f + 0.08f * (float)x;
            float t = ((float)x - edge) / width;
            t = t < 0.0f ? 0.0f : (t > 1.0f ? 1.0f : t);
            drift_image_pixel(&in, x, y)[0] = t * t * (3.0f - 2.0f * t);
            // beta varies along both axes, so the two passes see different betas.
            drift_image_pixel(&beta, x, y)[0] =
                0.25f * width * pixel * (1.0f + 0.3f * sinf((float)y / 9.0f + (float)x / 23.0f));
        }
    }
    drift_aaf_filter_desc desc = {
        .beta = &beta, .footprint = &footprint, .gbuffer = &g, .max_radius = DRIFT_AAF_MAX_RADIUS
    };
    assert_int_equal(drift_aaf_filter_separable(ctx, &desc, &in, &scratch, &sep), DRIFT_OK);
    assert_int_equal(drift_aaf_filter_exact(ctx, &desc, &in, &exact), DRIFT_OK);
    double max_diff = 0.0, sum_diff = 0.0, max_change = 0.0;
    for (int y = 0; y < FH; ++y) {
        for (int x = 0; x < FW; ++x) {
            double a = (double)drift_image_pixel(&sep, x, y)[0];
            double b = (double)drift_image_pixel(&exact, x, y)[0];
            max_diff = fmax(max_diff, fabs(a - b));
            sum_diff += fabs(a - b);
            max_change = fmax(max_change, fabs(b - (double)drift_image_pixel(&in, x, y)[0]));
        }
    }
    double mean_diff = sum_diff / (FW * FH);
    print_message("separable vs exact: max %g mean %g (filter changes up to %g)\n", max_diff,
                  mean_diff, max_change);
    assert_true(max_diff < 0.02);
    assert_true(mean_diff < 0.002);
    assert_true(max_change > 0.05);
    // Constant images stay exactly constant through both filters (a normalised sum).
    for (int value = 0; value < 2; ++value) {
        for (int y = 0; y < FH; ++y) {
            for (int x = 0; x < FW; ++x) {
                drift_image_pixel(&in, x, y)[0] = (float)value;
            }
        }
        assert_int_equal(drift_aaf_filter_separable(ctx, &desc, &in, &scratch, &sep), DRIFT_OK);
        assert_int_equal(drift_aaf_filter_exact(ctx, &desc, &in, &exact), DRIFT_OK);
        for (int y = 0; y < FH; ++y) {
            for (int x = 0; x < FW; ++x) {
                assert_true(drift_image_pixel(&sep, x, y)[0] == (float)value);
                assert_true(drift_image_pixel(&exact, x, y)[0] == (float)value);
            }
        }
    }
    drift_image *images[] = { &in, &sep, &exact, &scratch, &beta, &footprint };
    for (size_t i = 0; i < sizeof images / sizeof *images; ++i) {
        drift_image_destroy(ctx, images[i]);
    }
    drift_gbuffer_destroy(ctx, &g);
    drift_context_destroy(ctx);
}

// The budget: the mean count over the active pixels is the target, no count passes the cap
// or falls under the sparse count, and a pixel that wants adaptive samples gets at least the
// target (they come from the flat pixels, not from other penumbra pixels) and at least 3/4 of
// the adaptive pixels' mean (with two thirds of the pixels flat, 30 of their 40: n(x) alone
// left some at 16 while others took the cap).
static void test_budget_keeps_the_mean(void **state)
{
    (void)state;

    enum {
        N = 4000
    };

    float *want = malloc(sizeof(float) * N);
    uint32_t *counts = malloc(sizeof(uint32_t) * N);
    assert_non_null(want);
    assert_non_null(counts);
    uint32_t adaptive = 0;
    for (int i = 0; i < N; ++i) {
        want[i] = i % 3 != 0 ? 0.0f
                             : 1.0f + 200.0f * test_hash_unit((uint32_t)i) *
                                          test_hash_unit((uint32_t)i + N);
        adaptive += want[i] > 0.0f;
    }
    drift_aaf_allocate(want, N, N, 4, 16, 128, 7, counts);
    double mean_adaptive = (16.0 * N - 4.0 * (N - adaptive)) / adaptive;
    double sum = 0.0;
    uint32_t most = 0;
    for (int i = 0; i < N; ++i) {
        assert_true(counts[i] >= 4 && counts[i] <= 128);
        if (want[i] == 0.0f) {
            assert_int_equal(counts[i], 4);
        } else {
            assert_true(counts[i] >= 16);
            assert_true(counts[i] >= (uint32_t)floor(0.75 * mean_adaptive));
        }
        most = counts[i] > most ? counts[i] : most;
        sum += counts[i];
    }
    assert_near(sum / N, 16.0, 0.2);
    assert_true(most > (uint32_t)ceil(mean_adaptive)); // n(x) still places the rest
    free(want);
    free(counts);
}

// Indirect light of a closed room lit by a quad light: AAF's error against the path-traced
// first-diffuse-bounce light falls as spp grows and beats plain Monte Carlo at equal spp.
static void test_indirect_converges(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    drift_material m = drift_material_make(drift_vec3_make(0.7f, 0.6f, 0.5f));
    drift_material red = drift_material_make(drift_vec3_make(0.7f, 0.1f, 0.1f));
    uint32_t white, reddish;
    assert_int_equal(drift_scene_add_material(r.scene, &m, &white), DRIFT_OK);
    assert_int_equal(drift_scene_add_material(r.scene, &red, &reddish), DRIFT_OK);
    test_add_open_room(r.scene, 1.5f, white, reddish);
    add_square(r.scene, 0.3f, 0.8f, 0.2f, 0.4f, white);
    add_light(r.scene);
    r.scene->camera =
        drift_camera_look_at(drift_vec3_make(0, 1.5f, -1.45f), drift_vec3_make(0, 0.8f, 0.5f),
                             drift_vec3_make(0, 1, 0), 1.4f, W, H);
    test_rig_commit(&r);
    drift_pt *pt = NULL;
    uint32_t truth_spp = (uint32_t)(256 * test_intensity());
    drift_image truth =
        render_pt(&r, DRIFT_PT_COMPONENT_DIFFUSE, 2, truth_spp < 256 ? 256 : truth_spp, &pt);
    const uint32_t spps[3] = { 4, 16, 64 };
    double aaf[3], plain[3];
    for (int k = 0; k < 3; ++k) {
        drift_hybrid_params p = { .indirect = DRIFT_INDIRECT_AAF, .spp = spps[k], .seed = 5 };
        test_rig_frame(&r, &p);
        aaf[k] = test_rmse(r.ctx, test_rig_plane(&r, "indirect"), &truth);
        p.aaf.uniform = p.aaf.unfiltered = true;
        test_rig_frame(&r, &p);
        plain[k] = test_rmse(r.ctx, test_rig_plane(&r, "indirect"), &truth);
    }
    print_message("indirect rmse aaf %g %g %g, plain MC %g %g %g\n", aaf[0], aaf[1], aaf[2],
                  plain[0], plain[1], plain[2]);
    assert_true(aaf[1] < 0.9 * aaf[0]);
    assert_true(aaf[2] < 0.9 * aaf[1]);
    for (int k = 0; k < 3; ++k) {
        assert_true(aaf[k] < plain[k]);
    }
    drift_pt_destroy(pt);
    test_rig_destroy(&r);
}

// An open corner (issue 17): a floor, a back wall, a red side wall and a low table, no
// ceiling, under a small quad light and a dim constant environment, so most bounce rays
// escape and a pixel's few sparse rays may all escape.
static void build_open_scene(test_rig *r, int32_t width, int32_t height)
{
    uint32_t white = test_add_material(r->scene, drift_material_make(drift_vec3_splat(0.7f)));
    uint32_t red =
        test_add_material(r->scene, drift_material_make(drift_vec3_make(0.7f, 0.12f, 0.1f)));
    test_add_floor(r->scene, 2.0f, 0.0f, white);
    test_add_quad(r->scene, drift_vec3_make(-2, 0, -1), drift_vec3_make(4, 0, 0),
                  drift_vec3_make(0, 2, 0), white); // back wall, facing +z
    test_add_quad(r->scene, drift_vec3_make(-1, 0, -1), drift_vec3_make(0, 2, 0),
                  drift_vec3_make(0, 0, 3), red); // side wall, facing +x
    add_square(r->scene, -0.3f, 0.4f, -0.3f, 0.25f, white);
    test_add_quad_light(r->scene, drift_vec3_make(0.0f, 2.5f, 0.0f), drift_vec3_make(0.4f, 0, 0),
                        drift_vec3_make(0, 0, 0.4f), 40.0f);
    r->scene->environment =
        (drift_environment){ .color = drift_vec3_splat(0.1f), .texture = DRIFT_INVALID_INDEX };
    r->scene->camera =
        drift_camera_look_at(drift_vec3_make(1.2f, 1.4f, 2.5f), drift_vec3_make(-0.3f, 0.3f, -0.5f),
                             drift_vec3_make(0, 1, 0), 1.0f, width, height);
}

// In the open scene AAF's indirect light keeps the path tracer's mean at 16 spp: beta and n(x)
// must not depend on the samples they filter (a pixel whose rays all escaped was left dark,
// unfiltered and without adaptive samples: 23-28% too dark on the open plant scene).
static void test_indirect_mean_in_an_open_scene(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    build_open_scene(&r, 80, 60);
    test_rig_commit(&r);
    drift_pt *pt = NULL;
    uint32_t truth_spp = (uint32_t)(128 * test_intensity());
    drift_image truth =
        render_pt(&r, DRIFT_PT_COMPONENT_DIFFUSE, 2, truth_spp < 64 ? 64 : truth_spp, &pt);
    drift_hybrid_params p = { .indirect = DRIFT_INDIRECT_AAF, .spp = 16, .seed = 5 };
    test_rig_frame(&r, &p);
    double aaf =
        drift_image_mean_rgb(test_rig_plane(&r, "indirect")) / drift_image_mean_rgb(&truth);
    p.aaf.uniform = p.aaf.unfiltered = true;
    test_rig_frame(&r, &p);
    double plain =
        drift_image_mean_rgb(test_rig_plane(&r, "indirect")) / drift_image_mean_rgb(&truth);
    print_message("open scene indirect mean / reference: aaf %.4f, plain MC %.4f\n", aaf, plain);
    assert_true(fabs(plain - 1.0) < 0.02); // the reference and the sampler agree
    assert_true(fabs(aaf - 1.0) < 0.02);
    drift_pt_destroy(pt);
    test_rig_destroy(&r);
}

// Mean of a plane over the pixels that took samples (> 0), as `drift bench aaf` reports.
static double mean_taken(const drift_image *image)
{
    double sum = 0.0;
    size_t count = 0;
    for (int32_t y = 0; y < image->height; ++y) {
        for (int32_t x = 0; x < image->width; ++x) {
            float v = drift_image_pixel(image, x, y)[0];
            if (v > 0.0f) {
                sum += (double)v;
                ++count;
            }
        }
    }
    return count ? sum / (double)count : 0.0;
}

// The shadows' average spp over the pixels the light reaches is the nominal one within 1%,
// also where surfaces face away from the light (the back of the table, the walls' far sides
// are not in view, but the table's underside is), and 4 spp keeps an adaptive pass.
static void test_shadow_spp_is_nominal(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    build_open_scene(&r, 64, 48);
    // The table's underside, seen from a low camera: lit by nothing from the light.
    r.scene->camera = drift_camera_look_at(drift_vec3_make(1.2f, 0.25f, 2.0f),
                                           drift_vec3_make(-0.3f, 0.4f, -0.5f),
                                           drift_vec3_make(0, 1, 0), 1.0f, 64, 48);
    add_square(r.scene, 0.4f, 0.5f, 0.6f, 0.3f, 0); // facing up: its underside faces the camera
    test_rig_commit(&r);
    const uint32_t spps[3] = { 16, 8, 4 };
    for (int k = 0; k < 3; ++k) {
        test_rig_frame(
            &r, &(drift_hybrid_params){ .shadows = DRIFT_SHADOWS_AAF, .spp = spps[k], .seed = 3 });
        const drift_image *taken = test_rig_plane(&r, "light0.aaf.spp");
        double mean = mean_taken(taken);
        float most = 0.0f;
        for (int32_t y = 0; y < taken->height; ++y) {
            for (int32_t x = 0; x < taken->width; ++x) {
                most = fmaxf(most, drift_image_pixel(taken, x, y)[0]);
            }
        }
        print_message("shadows at %u spp: %.3f taken on average, %g at most\n", spps[k], mean,
                      (double)most);
        assert_true(fabs(mean / spps[k] - 1.0) < 0.01);
        assert_true(most > (float)spps[k]); // an adaptive pass ran
    }
    test_rig_destroy(&r);
}

// --aaf-sampler random: independent uniform numbers, a pure function of (key, pixel, sample,
// dimension); the Sobol default stratifies a pixel's samples, the random stream does not have
// to (its mean and variance are those of U(0,1), its dimensions uncorrelated).
static void test_random_sampler_is_uniform_and_independent(void **state)
{
    (void)state;
    const int n = 8192;
    double sx = 0.0, sxx = 0.0, sy = 0.0, sxy = 0.0, sz = 0.0, sxz = 0.0;
    for (int k = 0; k < n; ++k) {
        drift_aaf_sampler s =
            drift_aaf_sampler_make(7, (uint32_t)(k % 97), (uint32_t)(k / 97), true);
        drift_vec2 a = drift_aaf_next2(&s), b = drift_aaf_next2(&s);
        drift_aaf_sampler again =
            drift_aaf_sampler_make(7, (uint32_t)(k % 97), (uint32_t)(k / 97), true);
        drift_vec2 a2 = drift_aaf_next2(&again);
        assert_true(a.x == a2.x && a.y == a2.y);
        assert_true(a.x >= 0.0f && a.x < 1.0f && a.y >= 0.0f && a.y < 1.0f);
        double x = (double)a.x, y = (double)a.y, z = (double)b.x;
        sx += x;
        sxx += x * x;
        sy += y;
        sxy += x * y;
        sz += z;
        sxz += x * z;
    }
    double mx = sx / n, my = sy / n, mz = sz / n, var = sxx / n - mx * mx;
    assert_true(fabs(mx - 0.5) < 0.01 && fabs(my - 0.5) < 0.01 && fabs(mz - 0.5) < 0.01);
    assert_true(fabs(var - 1.0 / 12.0) < 0.005);
    assert_true(fabs((sxy / n - mx * my) / var) < 0.05); // the two halves of a pair
    assert_true(fabs((sxz / n - mx * mz) / var) < 0.05); // two dimensions
    // Sobol: 16 samples of a pixel fall one in each sixteenth; 16 random ones rarely do.
    int sobol_strata = 0, random_strata = 0;
    bool sobol_seen[16] = { false }, random_seen[16] = { false };
    for (uint32_t k = 0; k < 16; ++k) {
        drift_aaf_sampler a = drift_aaf_sampler_make(7, 3, k, false);
        drift_aaf_sampler b = drift_aaf_sampler_make(7, 3, k, true);
        int i = (int)(16.0f * drift_aaf_next2(&a).x), j = (int)(16.0f * drift_aaf_next2(&b).x);
        sobol_strata += !sobol_seen[i];
        random_strata += !random_seen[j];
        sobol_seen[i] = random_seen[j] = true;
    }
    assert_int_equal(sobol_strata, 16);
    assert_true(random_strata < 16);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_shadows_converge),
        cmocka_unit_test(test_shadows_at_4_spp_on_the_cornell_box),
        cmocka_unit_test(test_beta_and_rate_follow_the_geometry),
        cmocka_unit_test(test_full_light_and_full_shadow_are_exact),
        cmocka_unit_test(test_few_rays_do_not_make_a_pixel_flat),
        cmocka_unit_test(test_separable_filter_close_to_exact),
        cmocka_unit_test(test_budget_keeps_the_mean),
        cmocka_unit_test(test_indirect_converges),
        cmocka_unit_test(test_random_sampler_is_uniform_and_independent),
        cmocka_unit_test(test_indirect_mean_in_an_open_scene),
        cmocka_unit_test(test_shadow_spp_is_nominal),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
