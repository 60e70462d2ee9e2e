// test_ism, part: the gather and its blur and upsampling, slices, determinism, VPL importance,
// growing maps, rigid motion, bounces and parameters (the test list is in tests/unit/test_ism.c).
#include "ism_tests.h"

// Spec §3.5 test 8 in the form the implementation allows: with 1 x 1 blocks and no blur, the
// indirect light at a pixel is exactly kd / pi sum_j Phi_j cos cos / (pi max(d^2, d_min^2))
// over every VPL (visibility off), recomputed here from the VPL list.
void test_gather_equals_the_formula(void **state)
{
    (void)state;
    test_rig r = cornell_rig(1, 16);
    drift_ism *ism = render_ism(&r, &(drift_ism_params){ .visibility = DRIFT_ISM_VISIBILITY_NONE,
                                                         .vpl_count = 64,
                                                         .block_size = 1 });
    const drift_gbuffer *gb = drift_hybrid_gbuffer(r.frame);
    drift_ism_params p = drift_ism_get_params(ism);
    uint32_t count;
    const drift_vpl *vpls = drift_ism_vpls(ism, &count);
    assert_true(count > 32);
    for (int32_t y = 1; y < 16; y += 5) {
        for (int32_t x = 2; x < 16; x += 4) {
            drift_vec3 xp = drift_image_get3(&gb->position, x, y);
            drift_vec3 n = drift_image_get3(&gb->normal, x, y);
            double e = 0.0;
            for (uint32_t j = 0; j < count; ++j) {
                drift_vec3 d = drift_vec3_sub(vpls[j].position, xp);
                double d2 = (double)drift_vec3_dot(d, d), len = sqrt(d2);
                double cx = (double)drift_vec3_dot(n, d) / len;
                double cj = -(double)drift_vec3_dot(vpls[j].normal, d) / len;
                if (cx > 0.0 && cj > 0.0) {
                    double dmin2 = (double)p.clamp_distance * (double)p.clamp_distance;
                    e += (double)drift_luminance(vpls[j].flux) * cx * cj / fmax(d2, dmin2);
                }
            }
            double kd = (double)drift_image_get3(&gb->albedo, x, y).y;
            double expected = kd / (double)DRIFT_PI * e / (double)DRIFT_PI;
            // The albedo is grey per channel pair only on white surfaces: compare luminance
            // on pixels whose albedo is grey.
            drift_vec3 a = drift_image_get3(&gb->albedo, x, y);
            if (fabsf(a.x - a.y) < 1e-6f && fabsf(a.y - a.z) < 1e-6f) {
                double got =
                    (double)drift_luminance(drift_image_get3(drift_ism_indirect(ism), x, y));
                assert_near(got, expected, 1e-4 * expected + 1e-9);
            }
        }
    }
    drift_ism_destroy(ism);
    test_rig_destroy(&r);
}

// Whether G-buffer pixel (u, v) has a surface and passes the blur's tests against pixel (x, y):
// its normal within blur_normal of (x, y)'s, its position within blur_plane of (x, y)'s plane.
static bool passes_blur_tests(const drift_gbuffer *gb, const drift_ism_params *p, int32_t x,
                              int32_t y, int32_t u, int32_t v)
{
    if (u < 0 || v < 0 || u >= gb->width || v >= gb->height ||
        drift_image_pixel(&gb->material_id, u, v)[0] < 0.0f) {
        return false;
    }
    drift_vec3 c = drift_image_get3(&gb->position, x, y);
    drift_vec3 n = drift_image_get3(&gb->normal, x, y);
    drift_vec3 q = drift_image_get3(&gb->position, u, v);
    float plane = fabsf(drift_vec3_dot(n, drift_vec3_sub(q, c)));
    return drift_vec3_dot(n, drift_image_get3(&gb->normal, u, v)) >= p->blur_normal &&
           plane <= p->blur_plane;
}

// The largest channel difference of `got` from `expected`, relative to expected's luminance.
static double relative_difference(drift_vec3 got, drift_vec3 expected)
{
    double scale = 1e-6 + (double)drift_luminance(expected);
    double d = fmax(fabs((double)(got.x - expected.x)), fabs((double)(got.y - expected.y)));
    return fmax(d, fabs((double)(got.z - expected.z))) / scale;
}

// The blur is the documented window average: at every pixel, I = kd / pi times the mean of the
// irradiance ("ism.irradiance") over the B x B window of pixels with a surface whose normal is
// within blur_normal and whose position within blur_plane of the centre's plane, recomputed here
// pixel by pixel for an even and an odd block (the vectorised rows' edges included).
void test_blur_is_the_window_average(void **state)
{
    (void)state;
    test_rig r = cornell_rig(2, 37);
    const drift_gbuffer *gb = drift_hybrid_gbuffer(r.frame);
    int32_t blocks[2] = { 4, 5 };
    for (int k = 0; k < 2; ++k) {
        int32_t b = blocks[k];
        drift_ism *ism = render_ism(&r, &(drift_ism_params){ .vpl_count = 64, .block_size = b });
        drift_ism_params p = drift_ism_get_params(ism);
        const drift_image *e = drift_ism_plane_named(ism, "ism.irradiance");
        const drift_image *out = drift_ism_indirect(ism);
        double worst = 0.0;
        for (int32_t y = 0; y < gb->height; ++y) {
            for (int32_t x = 0; x < gb->width; ++x) {
                drift_vec3 expected = drift_vec3_splat(0.0f);
                if (drift_image_pixel(&gb->material_id, x, y)[0] >= 0.0f) {
                    drift_vec3 sum = drift_vec3_splat(0.0f);
                    float weight = 0.0f;
                    for (int32_t v = y - b / 2; v < y - b / 2 + b; ++v) {
                        for (int32_t u = x - b / 2; u < x - b / 2 + b; ++u) {
                            if (passes_blur_tests(gb, &p, x, y, u, v)) {
                                sum = drift_vec3_add(sum, drift_image_get3(e, u, v));
                                weight += 1.0f;
                            }
                        }
                    }
                    assert_true(weight >= 1.0f); // the centre passes its own tests
                    expected =
                        drift_vec3_scale(drift_vec3_mul(drift_image_get3(&gb->albedo, x, y), sum),
                                         DRIFT_INV_PI / weight);
                }
                worst = fmax(worst, relative_difference(drift_image_get3(out, x, y), expected));
            }
        }
        printf("block %d: worst relative difference %.2e\n", b, worst);
        assert_true(worst < 1e-4);
        drift_ism_destroy(ism);
    }
    test_rig_destroy(&r);
}

// Gathering at one pixel in 2 x 2 is the documented upsampling rule. With every pixel
// gathering every VPL (block 1, no blur) at 1 x 1, its "ism.irradiance" is each pixel's exact
// E; at scale 2 every pixel must be the bilinear mean of the E of its four nearest cells'
// centres that pass the blur's tests (or the ring of twelve around them), times its albedo, and
// a pixel none passes its own exact E (the fallback, counted in the stats), recomputed here
// pixel by pixel at an odd size (a last cell of one pixel); the boxes' edges give both the
// ring and the fallback a few pixels. The default interleaved render at scale 2 keeps the mean
// of scale 1 within 2% (at 41 x 41 the few blocks a wall has put it 5% off).
void test_gather_scale_upsamples_by_the_blur_tests(void **state)
{
    (void)state;
    test_rig r = cornell_rig(2, 65);
    const drift_gbuffer *gb = drift_hybrid_gbuffer(r.frame);
    drift_ism_params p = {
        .visibility = DRIFT_ISM_VISIBILITY_NONE, .vpl_count = 64, .block_size = 1, .no_blur = true
    };
    drift_ism *full = render_ism(&r, &p);
    p.gather_scale = 2;
    drift_ism *half = render_ism(&r, &p);
    p = drift_ism_get_params(half);
    const drift_image *e = drift_ism_plane_named(full, "ism.irradiance");
    const drift_image *out = drift_ism_indirect(half);
    assert_int_equal(drift_ism_plane_named(half, "ism.irradiance")->width, 33);
    double worst = 0.0;
    uint64_t fallbacks = 0, ring_pixels = 0;
    int32_t cells = (gb->width + 1) / 2;
    for (int32_t y = 0; y < gb->height; ++y) {
        for (int32_t x = 0; x < gb->width; ++x) {
            drift_vec3 expected = drift_vec3_splat(0.0f);
            if (drift_image_pixel(&gb->material_id, x, y)[0] >= 0.0f) {
                float fx = (float)(x - 1) / 2.0f, fy = (float)(y - 1) / 2.0f;
                int32_t i0 = (int32_t)floorf(fx), j0 = (int32_t)floorf(fy);
                drift_vec3 sum = drift_vec3_splat(0.0f);
                float weight = 0.0f;
                for (int ring = 0; ring < 2 && weight == 0.0f; ++ring) {
                    for (int32_t j = j0 - ring; j <= j0 + 1 + ring; ++j) {
                        for (int32_t i = i0 - ring; i <= i0 + 1 + ring; ++i) {
                            bool inner = i >= i0 && i <= i0 + 1 && j >= j0 && j <= j0 + 1;
                            if ((ring == 1 && inner) || i < 0 || j < 0 || i >= cells ||
                                j >= cells) {
                                continue;
                            }
                            int32_t u = 2 * i + 1 < gb->width ? 2 * i + 1 : gb->width - 1;
                            int32_t v = 2 * j + 1 < gb->height ? 2 * j + 1 : gb->height - 1;
                            if (!passes_blur_tests(gb, &p, x, y, u, v)) {
                                continue;
                            }
                            float w = 1.0f;
                            if (ring == 0) {
                                w = (i == i0 ? 1.0f - (fx - (float)i0) : fx - (float)i0) *
                                        (j == j0 ? 1.0f - (fy - (float)j0) : fy - (float)j0) +
                                    1e-3f;
                            }
                            sum = drift_vec3_fma(sum, drift_image_get3(e, u, v), w);
                            weight += w;
                        }
                    }
                    ring_pixels += ring == 1 && weight > 0.0f;
                }
                drift_vec3 irradiance = drift_vec3_scale(sum, 1.0f / weight);
                if (weight == 0.0f) {
                    irradiance = drift_image_get3(e, x, y);
                    ++fallbacks;
                }
                expected = drift_vec3_scale(
                    drift_vec3_mul(drift_image_get3(&gb->albedo, x, y), irradiance), DRIFT_INV_PI);
            }
            worst = fmax(worst, relative_difference(drift_image_get3(out, x, y), expected));
        }
    }
    printf("scale 2: worst relative difference %.2e, %llu pixels from the ring, %llu fallback "
           "pixels\n",
           worst, (unsigned long long)ring_pixels, (unsigned long long)fallbacks);
    assert_true(worst < 1e-4);
    assert_true(ring_pixels > 0 && fallbacks > 0);
    assert_int_equal(drift_ism_get_stats(half).fallback_pixels, fallbacks);
    drift_ism_destroy(full);
    drift_ism_destroy(half);
    // The default interleaved gather with its blur, at both scales.
    double mean[2];
    for (int k = 0; k < 2; ++k) {
        drift_ism *ism =
            render_ism(&r, &(drift_ism_params){ .vpl_count = 256, .gather_scale = 1 + k });
        mean[k] = drift_image_mean_luminance(drift_ism_indirect(ism));
        drift_ism_destroy(ism);
    }
    printf("mean at scale 2 / scale 1: %.4f\n", mean[1] / mean[0]);
    assert_true(fabs(mean[1] / mean[0] - 1.0) < 0.02);
    test_rig_destroy(&r);
}

// The length scale of the defaults (drift_scene_extent) is the reflecting geometry's: a pure
// emitter far outside (a sun 100 m off a 10 m floor) does not stretch ISM's clamp distance,
// while the same sphere made to reflect does, and so does every mesh when none reflects.
void test_extent_ignores_a_distant_pure_emitter(void **state)
{
    (void)state;
    for (int reflects = 0; reflects < 2; ++reflects) {
        test_rig r = test_rig_begin(1);
        uint32_t white = test_add_material(r.scene, drift_material_make(drift_vec3_splat(0.5f)));
        drift_material glow = drift_material_make(drift_vec3_splat(reflects ? 0.5f : 0.0f));
        glow.emission = drift_vec3_splat(100.0f);
        test_add_floor(r.scene, 5.0f, 0.0f, white);
        test_add_sphere(r.scene, drift_vec3_make(100, 50, 0), 1.0f, 16, 8,
                        test_add_material(r.scene, glow));
        test_rig_commit(&r);
        float all = drift_vec3_length(drift_vec3_sub(r.scene->bounds.max, r.scene->bounds.min));
        float want = reflects ? all : sqrtf(200.0f); // the floor's 10 x 10 diagonal
        float clamp = drift_ism_params_resolve(NULL, r.scene).clamp_distance;
        print_message("sphere %s: bounds' diagonal %g, extent %g, ISM clamp %g\n",
                      reflects ? "reflects" : "a pure emitter", (double)all,
                      (double)drift_scene_extent(r.scene), (double)clamp);
        assert_near(drift_scene_extent(r.scene), want, 1e-3 * (double)want);
        assert_near(clamp, 0.1 * (double)want, 1e-3 * (double)want);
        assert_true(reflects || drift_scene_extent(r.scene) < 0.2f * all);
        test_rig_destroy(&r);
    }
}

// drift_ism_render_slice: the mean of the n slices' images of one G-buffer is the full
// render's (each VPL is gathered in one slice at n times its light; the gather, the blur and
// the upsampling are linear), at gather scales 1 and 2 with their fallback pixels; a later
// slice keeps the VPLs and maps (no VPL stage) and a bad slice is refused.
void test_slices_average_to_the_full_render(void **state)
{
    (void)state;
    test_rig r = cornell_rig(2, 40);
    const drift_gbuffer *gb = drift_hybrid_gbuffer(r.frame);
    for (int32_t scale = 1; scale <= 2; ++scale) {
        drift_ism_params p = {
            .vpl_count = 256, .max_depth = 3, .gather_scale = scale, .no_near_field = true
        };
        drift_ism *full = NULL, *sliced = NULL;
        assert_int_equal(drift_ism_create(r.ctx, r.scene, r.accel, &p, &full), DRIFT_OK);
        assert_int_equal(drift_ism_create(r.ctx, r.scene, r.accel, &p, &sliced), DRIFT_OK);
        assert_int_equal(drift_ism_render(full, gb, &r.scene->camera, NULL), DRIFT_OK);
        const drift_image *want = drift_ism_indirect(full);
        size_t floats = (size_t)want->width * (size_t)want->height * 3;
        double *mean = calloc(floats, sizeof *mean);
        assert_non_null(mean);
        const uint32_t slices = 4;
        for (uint32_t k = 0; k < slices; ++k) {
            assert_int_equal(drift_ism_render_slice(sliced, gb, &r.scene->camera, NULL, k, slices),
                             DRIFT_OK);
            drift_ism_stats st = drift_ism_get_stats(sliced);
            assert_int_equal(st.vpl_count, drift_ism_get_stats(full).vpl_count);
            if (k > 0) {
                assert_true(st.ms[DRIFT_ISM_STAGE_VPLS] == 0.0 &&
                            st.ms[DRIFT_ISM_STAGE_SPLAT] == 0.0); // the lights were kept
            }
            const float *px = drift_ism_indirect(sliced)->pixels;
            for (size_t i = 0; i < floats; ++i) {
                mean[i] += (double)px[i] / slices;
            }
        }
        double worst = 0.0, sum = 0.0;
        for (size_t i = 0; i < floats; ++i) {
            worst = fmax(worst, fabs(mean[i] - (double)want->pixels[i]) /
                                    (1e-4 + fabs((double)want->pixels[i])));
            sum += (double)want->pixels[i];
        }
        printf("scale %d: the mean of %u slices against the full render: worst relative "
               "difference %.2e (%llu fallback pixels)\n",
               scale, slices, worst, (unsigned long long)drift_ism_get_stats(full).fallback_pixels);
        assert_true(sum > 1.0); // there is indirect light to compare
        assert_true(worst < 1e-3);
        // One slice alone is not the full image: each gathers its own quarter.
        assert_int_equal(drift_ism_render_slice(sliced, gb, &r.scene->camera, NULL, 1, slices),
                         DRIFT_OK);
        assert_memory_not_equal(drift_ism_indirect(sliced)->pixels, want->pixels,
                                floats * sizeof(float));
        assert_int_equal(drift_ism_render_slice(sliced, gb, &r.scene->camera, NULL, 4, 4),
                         DRIFT_ERR_INVALID_ARGUMENT);
        assert_int_equal(drift_ism_render_slice(sliced, gb, &r.scene->camera, NULL, 0, 0),
                         DRIFT_ERR_INVALID_ARGUMENT);
        free(mean);
        drift_ism_destroy(full);
        drift_ism_destroy(sliced);
    }
    test_rig_destroy(&r);
}

// The same seed gives bit-identical indirect light on 1 and 2 threads, with and without the
// near-field compensation.
void test_ism_is_deterministic(void **state)
{
    (void)state;
    test_rig r1 = cornell_rig(1, 24), r2 = cornell_rig(2, 24);
    drift_ism_params p = { .vpl_count = 64, .max_depth = 3, .seed = 3 };
    drift_ism *a = render_ism(&r1, &p), *b = render_ism(&r2, &p);
    const drift_image *ia = drift_ism_indirect(a), *ib = drift_ism_indirect(b);
    assert_memory_equal(ia->pixels, ib->pixels, 24 * 24 * 3 * sizeof(float));
    drift_ism_destroy(a);
    drift_ism_destroy(b);
    // And with the near-field compensation's rays, fed any direct image (here the albedo).
    const drift_gbuffer *g1 = drift_hybrid_gbuffer(r1.frame), *g2 = drift_hybrid_gbuffer(r2.frame);
    assert_int_equal(drift_ism_create(r1.ctx, r1.scene, r1.accel, &p, &a), DRIFT_OK);
    assert_int_equal(drift_ism_create(r2.ctx, r2.scene, r2.accel, &p, &b), DRIFT_OK);
    assert_int_equal(drift_ism_render(a, g1, &r1.scene->camera, &g1->albedo), DRIFT_OK);
    assert_int_equal(drift_ism_render(b, g2, &r2.scene->camera, &g2->albedo), DRIFT_OK);
    assert_true(drift_ism_get_stats(a).near_field_rays > 0);
    ia = drift_ism_indirect(a);
    ib = drift_ism_indirect(b);
    assert_memory_equal(ia->pixels, ib->pixels, 24 * 24 * 3 * sizeof(float));
    drift_ism_destroy(a);
    drift_ism_destroy(b);
    test_rig_destroy(&r1);
    test_rig_destroy(&r2);
}

// VPL importance (Georgiev & Slusallek 2010) on the Cornell box, where every VPL lights the
// view: the indirect image's mean is unchanged within 4% (accepted VPLs are divided by
// their acceptance probability), and the same for 1 and 2 threads.
void test_vpl_importance_is_unbiased(void **state)
{
    (void)state;
    test_rig r1 = cornell_rig(1, 24), r2 = cornell_rig(2, 24);
    drift_ism_params off = { .visibility = DRIFT_ISM_VISIBILITY_RAYS,
                             .vpl_count = 2048,
                             .max_depth = 3,
                             .block_size = 1,
                             .seed = 5 };
    drift_ism_params on = off;
    on.vpl_importance = true;
    drift_ism *a = render_ism(&r2, &off), *b = render_ism(&r2, &on), *c = render_ism(&r1, &on);
    double ratio = drift_image_mean_luminance(drift_ism_indirect(b)) /
                   drift_image_mean_luminance(drift_ism_indirect(a));
    printf("importance on / off mean: %.4f\n", ratio);
    assert_true(ratio > 0.96 && ratio < 1.04);
    assert_memory_equal(drift_ism_indirect(b)->pixels, drift_ism_indirect(c)->pixels,
                        24 * 24 * 3 * sizeof(float));
    drift_ism_destroy(a);
    drift_ism_destroy(b);
    drift_ism_destroy(c);
    test_rig_destroy(&r1);
    test_rig_destroy(&r2);
}

// A closed box lit by a point light, seen only at points on its floor (normals up): VPLs on
// the floor light none of them. Importance keeps floor VPLs
// with p = 0.1 only: their share falls to under 0.3 of what it is without.
void test_vpl_importance_keeps_useful_vpls(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    add_closed_box(r.scene, 0.5f);
    drift_light l = { .type = DRIFT_LIGHT_POINT,
                      .color = drift_vec3_splat(2.0f),
                      .position = drift_vec3_make(0.0f, 0.9f, 0.0f) };
    assert_int_equal(drift_scene_add_light(r.scene, &l, NULL), DRIFT_OK);
    test_rig_commit(&r);
    drift_vec3 pos[16], nrm[16];
    for (int i = 0; i < 16; ++i) {
        pos[i] = drift_vec3_make(-0.75f + 0.1f * (float)i, -0.999f, 0.1f * (float)(i % 4));
        nrm[i] = drift_vec3_make(0, 1, 0);
    }
    double useful[2];
    for (int on = 0; on < 2; ++on) {
        drift_ism_params p = drift_ism_params_resolve(
            &(drift_ism_params){ .vpl_count = 512, .max_depth = 2, .vpl_importance = on }, r.scene);
        drift_vpl *vpls = NULL;
        uint32_t count = 0, n = 0;
        assert_int_equal(drift__ism_generate_vpls_for(r.ctx, r.scene, r.accel, &p, pos, nrm, 16,
                                                      &vpls, &count, NULL),
                         DRIFT_OK);
        for (uint32_t j = 0; j < count; ++j) {
            n += vpls[j].position.y > -0.99f; // not on the floor
        }
        useful[on] = count ? (double)n / (double)count : 0.0;
        drift_free(r.ctx, vpls);
    }
    printf("useful VPLs off %.3f on %.3f\n", useful[0], useful[1]);
    assert_true(1.0 - useful[1] < 0.3 * (1.0 - useful[0]));
    test_rig_destroy(&r);
}

// The atlas and the scene points hold the VPLs a render made (at most one round of paths), not
// the bound over eight rounds (which sampled 14M points at 1024 VPLs, depth 8), and growing
// them changes no pixel: point i is the same Sobol sample whatever the count.
void test_maps_grow_without_changing_the_image(void **state)
{
    (void)state;
    test_rig r = cornell_rig(2, 24);
    drift_ism_params p = { .vpl_count = 64, .max_depth = 4, .seed = 5, .no_near_field = true };
    drift_ism *lazy = render_ism(&r, &p), *big = NULL;
    drift_ism_params resolved = drift_ism_params_resolve(&p, r.scene);
    uint32_t one_round = 64 + 2 * resolved.later_vpl_count;
    assert_true(drift__ism_map_capacity(lazy) <= one_round);
    assert_true(drift__ism_max_vpls(&resolved) > 2 * one_round);
    assert_int_equal(drift_ism_create(r.ctx, r.scene, r.accel, &p, &big), DRIFT_OK);
    assert_int_equal(drift__ism_reserve(big, drift__ism_max_vpls(&resolved)), DRIFT_OK);
    assert_int_equal(drift__ism_map_capacity(big), drift__ism_max_vpls(&resolved));
    assert_int_equal(drift_ism_render(big, drift_hybrid_gbuffer(r.frame), &r.scene->camera, NULL),
                     DRIFT_OK);
    const drift_image *a = drift_ism_indirect(lazy), *b = drift_ism_indirect(big);
    assert_memory_equal(a->pixels, b->pixels, 24 * 24 * 3 * sizeof(float));
    drift_ism_destroy(lazy);
    drift_ism_destroy(big);
    test_rig_destroy(&r);
}

// A closed box with a block inside and a point light, all shifted by `shift`, seen by a camera
// shifted alike.
static void build_shifted_scene(test_rig *r, drift_vec3 shift)
{
    uint32_t m = test_add_material(r->scene, drift_material_make(drift_vec3_splat(0.6f)));
    drift_vec3 ex = { 2, 0, 0 }, ey = { 0, 2, 0 }, ez = { 0, 0, 2 };
    drift_vec3 o = drift_vec3_add(drift_vec3_make(-1, -1, -1), shift);
    test_add_quad(r->scene, o, ez, ex, m);
    test_add_quad(r->scene, drift_vec3_add(o, ey), ex, ez, m);
    test_add_quad(r->scene, o, ex, ey, m);
    test_add_quad(r->scene, o, ey, ez, m);
    test_add_quad(r->scene, drift_vec3_add(o, ex), ez, ey, m);
    // A vertical 0.8 x 1 panel standing on the floor in the middle.
    test_add_quad(r->scene, drift_vec3_add(drift_vec3_make(-0.4f, -1, 0), shift),
                  drift_vec3_make(0.8f, 0, 0), drift_vec3_make(0, 1, 0), m);
    drift_light l = { .type = DRIFT_LIGHT_POINT,
                      .color = drift_vec3_splat(1.0f),
                      .position = drift_vec3_add(drift_vec3_make(0.3f, 0.6f, -0.5f), shift) };
    assert_int_equal(drift_scene_add_light(r->scene, &l, NULL), DRIFT_OK);
    r->scene->camera = drift_camera_look_at(drift_vec3_add(drift_vec3_make(0, 0, 0.95f), shift),
                                            drift_vec3_add(drift_vec3_make(0, -0.3f, -1), shift),
                                            drift_vec3_make(0, 1, 0), 1.4f, 32, 32);
    test_rig_commit(r);
    test_rig_frame(r, &(drift_hybrid_params){ .width = 32, .height = 32 });
}

// Spec §3.5 test 9: moving scene, light and camera rigidly leaves the image unchanged up to
// floating-point rounding (which may flip a few ISM texels: a small NRMSE, not bit equality).
void test_rigid_motion_leaves_the_image(void **state)
{
    (void)state;
    test_rig a = test_rig_begin(2), b = test_rig_begin(2);
    build_shifted_scene(&a, drift_vec3_splat(0.0f));
    build_shifted_scene(&b, drift_vec3_make(0.75f, -0.5f, 0.25f));
    drift_ism_params p = { .vpl_count = 128, .block_size = 2 };
    drift_ism *ia = render_ism(&a, &p), *ib = render_ism(&b, &p);
    double e = test_nrmse(a.ctx, drift_ism_indirect(ia), drift_ism_indirect(ib));
    assert_true(e < 0.02);
    drift_ism_destroy(ia);
    drift_ism_destroy(ib);
    test_rig_destroy(&a);
    test_rig_destroy(&b);
}

// Spec §3.5 test 7 on the image: 1, 2 and 3 bounces give monotonically brighter images with
// shrinking increments.
void test_bounces_add_shrinking_light(void **state)
{
    (void)state;
    test_rig r = cornell_rig(2, 24);
    double mean[3];
    for (int d = 0; d < 3; ++d) {
        drift_ism *ism = render_ism(
            &r,
            &(drift_ism_params){ .vpl_count = 512, .later_vpl_count = 512, .max_depth = 2 + d });
        mean[d] = drift_image_mean_luminance(drift_ism_indirect(ism));
        drift_ism_destroy(ism);
    }
    assert_true(mean[1] > mean[0] && mean[2] > mean[1]);
    assert_true(mean[2] - mean[1] < mean[1] - mean[0]);
    test_rig_destroy(&r);
}

// Out-of-range parameters are refused with DRIFT_ERR_INVALID_ARGUMENT and a logged reason;
// a render has its diagnostic planes (the tile only with ISM visibility) and stats.
void test_parameters_and_planes(void **state)
{
    (void)state;
    test_log_capture log = { 0 };
    test_rig r = cornell_rig(1, 16);
    drift_context *ctx = test_context(1, &log);
    drift_ism_params bad[] = {
        { .visibility = DRIFT_ISM_VISIBILITY_COUNT },
        { .map_size = 2 },
        { .block_size = -1 },
        { .max_depth = -3 },
        { .splat_scale = -1.0f },
        { .max_path_rounds = 100 },
        { .block_size = 4, .near_field_stride = 3 },
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        drift_ism *ism = (drift_ism *)&log;
        assert_int_equal(drift_ism_create(ctx, r.scene, r.accel, &bad[i], &ism),
                         DRIFT_ERR_INVALID_ARGUMENT);
        assert_null(ism);
    }
    assert_true(log.errors >= 7);
    // The compensation on (the default) without its direct image: an error, not a wide clamp
    // that gives nothing back.
    drift_ism *strict = NULL;
    assert_int_equal(
        drift_ism_create(ctx, r.scene, r.accel, &(drift_ism_params){ .vpl_count = 32 }, &strict),
        DRIFT_OK);
    assert_int_equal(
        drift_ism_render(strict, drift_hybrid_gbuffer(r.frame), &r.scene->camera, NULL),
        DRIFT_ERR_INVALID_ARGUMENT);
    drift_ism_destroy(strict);
    drift_ism *ism = render_ism(&r, &(drift_ism_params){ .vpl_count = 32 });
    assert_non_null(drift_ism_plane_named(ism, "ism.irradiance"));
    assert_non_null(drift_ism_plane_named(ism, "ism.vpls"));
    assert_non_null(drift_ism_plane_named(ism, "ism.near_field"));
    assert_non_null(drift_ism_plane_named(ism, "ism.tile"));
    assert_null(drift_ism_plane_named(ism, "ism.nothing"));
    drift_ism_stats st = drift_ism_get_stats(ism);
    assert_true(st.vpl_count > 0 && st.splats > 0 && st.shadow_rays == 0);
    drift_ism_destroy(ism);
    ism = render_ism(
        &r, &(drift_ism_params){ .vpl_count = 32, .visibility = DRIFT_ISM_VISIBILITY_RAYS });
    assert_null(drift_ism_plane_named(ism, "ism.tile"));
    assert_true(drift_ism_get_stats(ism).shadow_rays > 0);
    drift_ism_destroy(ism);
    drift_context_destroy(ctx);
    test_rig_destroy(&r);
}
