// Smart Image Refinement: a budget covering every pixel gives the pure ray-traced image bit
// for bit; a scene with nothing the raster approximates has zero error everywhere (and the
// raster matches the ray tracer there); the sort is stable and refines every non-zero error
// pixel before any zero one; the lambda fit is never worse than the averaged sum on its own
// training views, and its file round-trips.
#include "drift/accel.h"
#include "drift/hybrid.h"
#include "drift/refine.h"
#include "drift/scene.h"
#include "drift/view.h"
#include "drift_test.h"
#include "refine/refine_tests.h"
#include "sir/sir.h"
#include "test_rig.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PI_F 3.14159265f

rig rig_begin(void)
{
    rig r = { .ctx = test_context(2, NULL) };
    assert_int_equal(drift_scene_create(r.ctx, &r.scene), DRIFT_OK);
    return r;
}

// The hybrid techniques SIR refines: shadow maps, environment maps, post DOF, no indirect.
const drift_hybrid_params raster_params = { .shadows = DRIFT_SHADOWS_PCSS,
                                            .reflections = DRIFT_REFLECTIONS_ENVMAP,
                                            .dof = DRIFT_DOF_POST,
                                            .envmap.size = 32,
                                            .shadow_map.size = 256 };

void rig_commit_raster(rig *r, const drift_hybrid_params *raster, const drift_refine_params *params)
{
    assert_int_equal(drift_scene_commit(r->scene), DRIFT_OK);
    assert_int_equal(drift_accel_create(r->ctx, r->scene, &(drift_accel_desc){ 0 }, &r->accel),
                     DRIFT_OK);
    assert_int_equal(drift_hybrid_create(r->ctx, r->scene, r->accel, raster, &r->frame), DRIFT_OK);
    assert_int_equal(drift_hybrid_render(r->frame, &r->scene->camera, NULL), DRIFT_OK);
    assert_int_equal(drift_refine_create(r->ctx, r->frame, params, &r->sir), DRIFT_OK);
    assert_int_equal(drift_refine_begin(r->sir), DRIFT_OK);
}

void rig_commit(rig *r, const drift_refine_params *params)
{
    rig_commit_raster(r, &raster_params, params);
}

void rig_destroy(rig *r)
{
    drift_refine_destroy(r->sir);
    drift_hybrid_destroy(r->frame);
    drift_accel_destroy(r->accel);
    drift_scene_destroy(r->scene);
    drift_context_destroy(r->ctx);
}

// Axis-aligned box [lo, hi] with outward-facing triangles.
static void add_box(drift_scene *scene, drift_vec3 lo, drift_vec3 hi, uint32_t material)
{
    const float p[] = { lo.x, lo.y, lo.z, hi.x, lo.y, lo.z, hi.x, hi.y, lo.z, lo.x, hi.y, lo.z,
                        lo.x, lo.y, hi.z, hi.x, lo.y, hi.z, hi.x, hi.y, hi.z, lo.x, hi.y, hi.z };
    const uint32_t idx[] = { 0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                             3, 6, 2, 3, 7, 6, 0, 4, 7, 0, 7, 3, 1, 2, 6, 1, 6, 5 };
    test_add_mesh(scene, p, 8, idx, 12, material);
}

// Every effect SIR refines: a mirror and a glossy sphere (reflections), a box on a floor under
// a quad light (penumbrae), depth edges seen through a lens.
void build_effects_scene(rig *r, int32_t width, int32_t height, drift_vec3 eye)
{
    uint32_t white = test_add_material(r->scene, drift_material_make(drift_vec3_splat(0.6f)));
    uint32_t glossy =
        test_add_material(r->scene, (drift_material){ .type = DRIFT_MATERIAL_DEFAULT,
                                                      .diffuse = { 0.2f, 0.3f, 0.2f },
                                                      .specular = { 0.5f, 0.5f, 0.5f },
                                                      .exponent = 60.0f,
                                                      .diffuse_texture = DRIFT_INVALID_INDEX });
    uint32_t mirror =
        test_add_material(r->scene, (drift_material){ .type = DRIFT_MATERIAL_MIRROR,
                                                      .specular = { 0.9f, 0.9f, 0.9f },
                                                      .diffuse_texture = DRIFT_INVALID_INDEX });
    test_add_floor(r->scene, 4.0f, 0.0f, white);
    add_box(r->scene, drift_vec3_make(-1.6f, 0.0f, 0.2f), drift_vec3_make(-0.9f, 0.9f, 0.9f),
            white);
    test_add_sphere(r->scene, drift_vec3_make(0.2f, 0.5f, 0.0f), 0.5f, 48, 24, mirror);
    test_add_sphere(r->scene, drift_vec3_make(1.3f, 0.4f, 0.6f), 0.4f, 48, 24, glossy);
    assert_int_equal(drift_scene_add_light(r->scene,
                                           &(drift_light){ .type = DRIFT_LIGHT_QUAD,
                                                           .position = { -0.8f, 3.0f, -0.3f },
                                                           .edge_u = { 0.6f, 0, 0 },
                                                           .edge_v = { 0, 0, 0.6f }, // emits down
                                                           .color = { 12, 12, 12 } },
                                           NULL),
                     DRIFT_OK);
    r->scene->camera = drift_camera_look_at(eye, drift_vec3_make(0.0f, 0.4f, 0.2f),
                                            drift_vec3_make(0, 1, 0), 0.9f, width, height);
    r->scene->camera.aperture_radius = 0.05f;
    r->scene->camera.focus_distance = 4.0f;
}

uint32_t test_spp(void)
{
    double s = 4.0 * test_intensity();
    return s < 1.0 ? 1u : (uint32_t)s;
}

static void assert_images_equal(const drift_image *a, const drift_image *b)
{
    for (int32_t y = 0; y < a->height; ++y) {
        for (int32_t x = 0; x < a->width; ++x) {
            for (int c = 0; c < 3; ++c) {
                float va = drift_image_pixel(a, x, y)[c], vb = drift_image_pixel(b, x, y)[c];
                if (memcmp(&va, &vb, sizeof va) != 0) {
                    fail_msg("pixel (%d, %d) channel %d: %.9g != %.9g", x, y, c, (double)va,
                             (double)vb);
                }
            }
        }
    }
}

// --- FULL BUDGET = PURE RAY TRACING ---

static void run_to_pure(uint32_t budget_divisor)
{
    rig r = rig_begin();
    const int32_t w = 40, h = 30;
    build_effects_scene(&r, w, h, drift_vec3_make(0.5f, 2.2f, -3.5f));
    uint32_t spp = test_spp();
    drift_refine_params params = { .spp = spp,
                                   .visit_spp = budget_divisor > 1 ? 2 : 0,
                                   .refine_zero_error = true,
                                   .budget = (uint32_t)(w * h) * spp / budget_divisor };
    rig_commit(&r, &params);
    drift_image pure;
    assert_int_equal(drift_image_create(r.ctx, w, h, 3, &pure), DRIFT_OK);
    assert_int_equal(drift_refine_render_pure(r.sir, spp, &pure, NULL, NULL), DRIFT_OK);
    uint32_t iterations = 0;
    while (!drift_refine_done(r.sir)) {
        assert_int_equal(drift_refine_iterate(r.sir, NULL), DRIFT_OK);
        assert_true(++iterations < 10000);
    }
    if (budget_divisor == 1) {
        assert_int_equal(iterations, 1); // the budget covered every pixel's samples at once
    } else {
        assert_true(iterations >= budget_divisor);
    }
    drift_refine_stats st = drift_refine_get_stats(r.sir);
    assert_true(st.error_pixels > 0 && st.error_pixels < (uint64_t)(w * h));
    assert_int_equal(st.refined, (uint64_t)(w * h));
    assert_int_equal(st.samples, (uint64_t)(w * h) * spp);
    assert_images_equal(drift_refine_image(r.sir), &pure);
    drift_image_destroy(r.ctx, &pure);
    rig_destroy(&r);
}

static void test_full_budget_gives_pure_image(void **state)
{
    (void)state;
    run_to_pure(1);
}

static void test_many_small_budgets_give_pure_image(void **state)
{
    (void)state;
    run_to_pure(7);
}

// Without refine_zero_error, error pixels become the pure image and zero-error pixels keep
// the raster's value.
static void test_error_pixels_only(void **state)
{
    (void)state;
    rig r = rig_begin();
    const int32_t w = 40, h = 30;
    build_effects_scene(&r, w, h, drift_vec3_make(0.5f, 2.2f, -3.5f));
    uint32_t spp = test_spp();
    rig_commit(&r, &(drift_refine_params){ .spp = spp, .budget = 97 });
    drift_image pure;
    assert_int_equal(drift_image_create(r.ctx, w, h, 3, &pure), DRIFT_OK);
    assert_int_equal(drift_refine_render_pure(r.sir, spp, &pure, NULL, NULL), DRIFT_OK);
    while (!drift_refine_done(r.sir)) {
        assert_int_equal(drift_refine_iterate(r.sir, NULL), DRIFT_OK);
    }
    const drift_image *out = drift_refine_image(r.sir), *raster = drift_hybrid_image(r.frame);
    const drift_image *error = drift_refine_error(r.sir);
    for (int32_t y = 0; y < h; ++y) {
        for (int32_t x = 0; x < w; ++x) {
            const drift_image *want = drift_image_pixel(error, x, y)[0] > 0.0f ? &pure : raster;
            for (int c = 0; c < 3; ++c) {
                assert_true(drift_image_pixel(out, x, y)[c] == drift_image_pixel(want, x, y)[c]);
            }
        }
    }
    drift_image_destroy(r.ctx, &pure);
    rig_destroy(&r);
}

// --- ZERO ERROR ---

// A diffuse floor seen from straight above through a lens focused on it, under a point light:
// no reflective material, no depth discontinuity, no area light. Every metric is zero, and the
// raster agrees with the ray tracer (so the metrics are right to say so).
static void test_zero_error_scene(void **state)
{
    (void)state;
    rig r = rig_begin();
    uint32_t white = test_add_material(r.scene, drift_material_make(drift_vec3_splat(0.5f)));
    test_add_floor(r.scene, 100.0f, 0.0f, white);
    r.scene->camera = drift_camera_look_at(drift_vec3_make(0, 3, 0), drift_vec3_make(0, 0, 0),
                                           drift_vec3_make(0, 0, 1), 0.8f, 32, 24);
    r.scene->camera.aperture_radius = 0.1f;
    r.scene->camera.focus_distance = 3.0f;
    assert_int_equal(drift_scene_add_light(r.scene,
                                           &(drift_light){ .type = DRIFT_LIGHT_POINT,
                                                           .position = { 0.5f, 5.0f, 0.2f },
                                                           .color = { 20, 20, 20 } },
                                           NULL),
                     DRIFT_OK);
    rig_commit(&r, &(drift_refine_params){ .spp = 4 });
    drift_refine_stats st = drift_refine_get_stats(r.sir);
    assert_int_equal(st.error_pixels, 0);
    for (int m = 0; m < DRIFT_METRIC_COUNT; ++m) {
        const drift_image *e = drift_refine_metric_image(r.sir, (drift_refine_metric)m);
        for (int32_t i = 0; i < 32 * 24; ++i) {
            assert_true(e->pixels[i] == 0.0f);
        }
    }
    assert_int_equal(drift_refine_iterate(r.sir, NULL), DRIFT_OK);
    assert_true(drift_refine_done(r.sir));
    assert_int_equal(drift_refine_get_stats(r.sir).samples, 0);
    // The raster is right where the metrics say so: the pure image (one sample suffices for
    // a point light on a plane in focus) matches it closely.
    drift_image pure;
    assert_int_equal(drift_image_create(r.ctx, 32, 24, 3, &pure), DRIFT_OK);
    assert_int_equal(drift_refine_render_pure(r.sir, 4, &pure, NULL, NULL), DRIFT_OK);
    const drift_image *raster = drift_hybrid_image(r.frame);
    for (int32_t y = 2; y < 22; ++y) {
        for (int32_t x = 2; x < 30; ++x) {
            float a = drift_image_pixel(raster, x, y)[0], b = drift_image_pixel(&pure, x, y)[0];
            assert_true(b > 0.0f);
            assert_near(a / b, 1.0, 0.02);
        }
    }
    drift_image_destroy(r.ctx, &pure);
    rig_destroy(&r);
}

// The same metrics notice each effect when it is there.
static void test_metrics_see_effects(void **state)
{
    (void)state;
    rig r = rig_begin();
    build_effects_scene(&r, 64, 48, drift_vec3_make(0.5f, 2.2f, -3.5f));
    rig_commit(&r, &(drift_refine_params){ .spp = 1 });
    for (int m = 0; m < DRIFT_METRIC_COUNT; ++m) {
        const drift_image *e = drift_refine_metric_image(r.sir, (drift_refine_metric)m);
        float max = 0.0f;
        for (int32_t i = 0; i < 64 * 48; ++i) {
            assert_true(e->pixels[i] >= 0.0f && e->pixels[i] <= 1.0f);
            max = fmaxf(max, e->pixels[i]);
        }
        if (max <= 0.0f) {
            fail_msg("metric %s is zero everywhere",
                     drift_refine_metric_name((drift_refine_metric)m));
        }
    }
    rig_destroy(&r);
}

// The penumbra estimate is conservative: every pixel from which the quad light is partly
// hidden (by ray-traced visibility of an 8 x 8 grid of its points) is flagged, up to 5%, by the
// shadow map's estimate itself (before the metric's dilation) and by the ungated metric.
static void test_shadow_metric_conservative(void **state)
{
    (void)state;
    rig r = rig_begin();
    const int32_t w = 64, h = 48;
    build_effects_scene(&r, w, h, drift_vec3_make(0.5f, 2.2f, -3.5f));
    rig_commit(&r, &(drift_refine_params){ .shadow_tolerance = -1.0f }); // the estimate ungated
    const drift_gbuffer *g = drift_hybrid_gbuffer(r.frame);
    const drift_image *shadow = drift_refine_metric_image(r.sir, DRIFT_METRIC_SHADOW);
    uint32_t partial = 0, flagged = 0, estimated = 0, umbra = 0, lit_unflagged = 0;
    const drift_shadow_map *map = drift_realtime_shadow_map(drift_hybrid_frame(r.frame), 0);
    assert_non_null(map);
    for (int32_t y = 0; y < h; ++y) {
        for (int32_t x = 0; x < w; ++x) {
            const drift_surface *s = &g->surfaces[(size_t)y * (size_t)w + (size_t)x];
            if (s->material == DRIFT_INVALID_INDEX) {
                continue;
            }
            int visible = 0, facing = 0;
            for (int j = 0; j < 8; ++j) {
                for (int i = 0; i < 8; ++i) {
                    drift_vec3 q = drift_vec3_make(-0.8f + 0.6f * ((float)i + 0.5f) / 8.0f, 3.0f,
                                                   -0.3f + 0.6f * ((float)j + 0.5f) / 8.0f);
                    drift_vec3 d = drift_vec3_sub(q, s->position);
                    float len = drift_vec3_length(d);
                    d = drift_vec3_scale(d, 1.0f / len);
                    if (drift_vec3_dot(d, s->ng) <= 0.0f) {
                        continue;
                    }
                    ++facing;
                    drift_ray ray = { .origin = drift_offset_origin(s->position, s->ng, d),
                                      .dir = d,
                                      .tmin = 0.0f,
                                      .tmax = len * 0.999f };
                    visible += !drift_accel_occluded(r.accel, &ray);
                }
            }
            float e = drift_image_pixel(shadow, x, y)[0];
            if (facing == 64 && visible > 0 && visible < 64) {
                ++partial;
                flagged += e > 0.0f;
                estimated += drift_shadow_map_penumbra(map, s->position, s->ng) > 0.0f;
            }
            umbra += facing == 64 && visible == 0;
            lit_unflagged += facing == 64 && visible == 64 && e == 0.0f;
        }
    }
    // The scene has all three: penumbra, umbra (under the box and the spheres) and full light.
    assert_true(partial > 20 && umbra > 0 && lit_unflagged > 0);
    if ((double)flagged < 0.95 * (double)partial || (double)estimated < 0.95 * (double)partial) {
        fail_msg("penumbra recall: metric %u, estimate %u of %u", flagged, estimated, partial);
    }
    rig_destroy(&r);
}

// Share of the surface pixels the shadow metric flags, the effects scene at width x height
// with a 64-texel shadow map.
static double shadow_flagged_share(int32_t width, int32_t height)
{
    rig r = rig_begin();
    build_effects_scene(&r, width, height, drift_vec3_make(0.5f, 2.2f, -3.5f));
    drift_hybrid_params raster = raster_params;
    raster.shadow_map.size = 64;
    rig_commit_raster(&r, &raster, NULL);
    const drift_gbuffer *g = drift_hybrid_gbuffer(r.frame);
    const drift_image *shadow = drift_refine_metric_image(r.sir, DRIFT_METRIC_SHADOW);
    uint32_t surface = 0, flagged = 0;
    for (int32_t y = 0; y < height; ++y) {
        for (int32_t x = 0; x < width; ++x) {
            if (g->surfaces[(size_t)y * (size_t)width + (size_t)x].material !=
                DRIFT_INVALID_INDEX) {
                ++surface;
                flagged += drift_image_pixel(shadow, x, y)[0] > 0.0f;
            }
        }
    }
    rig_destroy(&r);
    return (double)flagged / (double)surface;
}

// The shadow metric's dilation covers the coarseness of the shadow-map taps, a band of the
// same world width at any image size: doubling the resolution keeps the flagged share (a
// fixed pixel radius would cover half the band and flag visibly less).
static void test_shadow_dilation_follows_resolution(void **state)
{
    (void)state;
    double coarse = shadow_flagged_share(100, 75), fine = shadow_flagged_share(200, 150);
    if (fine < 0.93 * coarse) {
        fail_msg("flagged share %.4f at 200x150 against %.4f at 100x75", fine, coarse);
    }
}

// A pillar lit from one side: the two faces the camera sees face away from the quad light, so
// nothing on them is lit, by raster or ray tracer, and the shadow metric flags none of them
// (the light's corners are all below the receiver's horizon), beyond the dilation's 2 pixels
// from their edges. The shadow map alone would call their edges penumbra: their texels border
// the lit faces.
static void test_shadow_metric_skips_unlit(void **state)
{
    (void)state;
    rig r = rig_begin();
    const int32_t w = 48, h = 36;
    uint32_t white = test_add_material(r.scene, drift_material_make(drift_vec3_splat(0.6f)));
    test_add_floor(r.scene, 4.0f, 0.0f, white);
    add_box(r.scene, drift_vec3_make(-0.5f, 0.0f, 0.0f), drift_vec3_make(0.5f, 2.0f, 1.0f), white);
    assert_int_equal(drift_scene_add_light(r.scene,
                                           &(drift_light){ .type = DRIFT_LIGHT_QUAD,
                                                           .position = { 1.2f, 2.6f, 0.2f },
                                                           .edge_u = { 0.6f, 0, 0 },
                                                           .edge_v = { 0, 0, 0.6f },
                                                           .color = { 12, 12, 12 } },
                                           NULL),
                     DRIFT_OK);
    r.scene->camera = drift_camera_look_at(drift_vec3_make(-2.5f, 1.2f, -2.0f),
                                           drift_vec3_make(-0.5f, 1.1f, 0.0f),
                                           drift_vec3_make(0, 1, 0), 0.7f, w, h);
    rig_commit(&r, NULL);
    const drift_gbuffer *g = drift_hybrid_gbuffer(r.frame);
    const drift_image *shadow = drift_refine_metric_image(r.sir, DRIFT_METRIC_SHADOW);
    uint32_t dark = 0;
    for (int32_t y = 2; y < h - 2; ++y) {
        for (int32_t x = 2; x < w - 2; ++x) {
            bool inside = true; // the 5 x 5 neighbourhood is all on the two dark faces
            for (int32_t v = y - 2; inside && v <= y + 2; ++v) {
                for (int32_t u = x - 2; inside && u <= x + 2; ++u) {
                    const drift_surface *s = &g->surfaces[(size_t)v * (size_t)w + (size_t)u];
                    inside = s->material != DRIFT_INVALID_INDEX && s->position.y > 0.01f &&
                             (fabsf(s->position.x + 0.5f) < 1e-3f || fabsf(s->position.z) < 1e-3f);
                }
            }
            if (inside) {
                ++dark;
                if (drift_image_pixel(shadow, x, y)[0] != 0.0f) {
                    fail_msg("pixel (%d, %d) gets no light but is flagged", x, y);
                }
            }
        }
    }
    assert_true(dark > 100);
    rig_destroy(&r);
}

// The hierarchical blocker search (regions the min-depth mip proves free are not tapped) gives
// exactly the exhaustive search's estimate, for the frame's quad light, a sphere light (all six
// cube faces) and a directional light with an angular radius (orthographic map), at the
// G-buffer's points and at random points and normals; with a tighter light size too. And the
// finest levels' texel tests flag every point their taps flag (and few more).
static void check_hierarchical_matches(const drift_shadow_map *map, const drift_gbuffer *g,
                                       int32_t w, int32_t h, uint32_t *ones, uint32_t *zeros,
                                       uint32_t *extra)
{
    uint32_t state = 12345u;
    for (int32_t k = 0; k < w * h + 3000; ++k) {
        drift_vec3 p, n;
        if (k < w * h) {
            const drift_surface *s = &g->surfaces[k];
            if (s->material == DRIFT_INVALID_INDEX) {
                continue;
            }
            p = s->position;
            n = s->ng;
        } else {
            float u[6];
            for (int i = 0; i < 6; ++i) {
                state = state * 1664525u + 1013904223u;
                u[i] = (float)(state >> 8) / 16777216.0f;
            }
            p = drift_vec3_make(-2.0f + 4.0f * u[0], 1.5f * u[1], -2.0f + 4.0f * u[2]);
            n = drift_vec3_normalize(drift_vec3_make(u[3] - 0.5f, u[4] - 0.3f, u[5] - 0.5f));
        }
        for (int tight = 0; tight < 2; ++tight) {
            float size = tight ? 0.2f : 0.0f;
            float fast = drift_shadow_map_penumbra_query(
                map, p, n, &(drift_penumbra_query){ .light_size = size });
            float full = drift_shadow_map_penumbra_query(
                map, p, n, &(drift_penumbra_query){ .light_size = size, .exhaustive = true });
            if (fast != full) {
                fail_msg("point %d (tight %d): hierarchical %g, exhaustive %g", k, tight,
                         (double)fast, (double)full);
            }
            // Testing every texel of the finest levels flags every point the taps flag.
            float taps = drift_shadow_map_penumbra_query(
                map, p, n,
                &(drift_penumbra_query){
                    .light_size = size, .exhaustive = true, .taps_only = true });
            if (taps > 0.0f && full == 0.0f) {
                fail_msg("point %d (tight %d): texel levels miss the taps' penumbra", k, tight);
            }
            if (k < w * h) { // surfaces the camera sees
                extra[0] += full > 0.0f && taps == 0.0f;
                extra[1] += full > 0.0f;
            }
            *ones += full > 0.0f;
            *zeros += full == 0.0f;
        }
    }
}

static void test_hierarchical_search_matches_exhaustive(void **state)
{
    (void)state;
    rig r = rig_begin();
    const int32_t w = 48, h = 36;
    build_effects_scene(&r, w, h, drift_vec3_make(0.5f, 2.2f, -3.5f));
    rig_commit(&r, NULL);
    const drift_gbuffer *g = drift_hybrid_gbuffer(r.frame);
    const drift_raster_light lights[2] = {
        { .type = DRIFT_LIGHT_SPHERE, .centre = { 0.3f, 1.8f, 0.4f }, .radius = 0.25f },
        { .type = DRIFT_LIGHT_DIRECTIONAL, .direction = { 0.3f, -1.0f, 0.2f }, .radius = 0.05f },
    };
    uint32_t ones = 0, zeros = 0, extra[2] = { 0, 0 };
    check_hierarchical_matches(drift_realtime_shadow_map(drift_hybrid_frame(r.frame), 0), g, w, h,
                               &ones, &zeros, extra);
    for (int l = 0; l < 2; ++l) {
        drift_shadow_map *map = NULL;
        drift_shadow_map_params params = { .size = 128, .bias_texels = 1.5f };
        assert_int_equal(
            drift_shadow_map_build(r.ctx, r.scene, r.accel, &lights[l], &params, &map, NULL),
            DRIFT_OK);
        check_hierarchical_matches(map, g, w, h, &ones, &zeros, extra);
        drift_shadow_map_destroy(r.ctx, map);
    }
    assert_true(ones > 500 && zeros > 500); // both answers occur: the comparison means something
    // On the surfaces the camera sees, the texel levels add few flags (random points and
    // normals, receivers in mid-air, get more).
    print_message("penumbra: %u seen points flagged (3 lights), %u by the texel levels alone\n",
                  extra[1], extra[0]);
    assert_true(extra[0] * 20u < extra[1]);
    rig_destroy(&r);
}

// --- SORT ---

static void test_radix_sort_stable_and_complete(void **state)
{
    (void)state;

    enum {
        N = 5000
    };

    uint16_t *keys = malloc(sizeof(uint16_t) * N);
    uint32_t *order = malloc(sizeof(uint32_t) * N), *scratch = malloc(sizeof(uint32_t) * N);
    assert_non_null(keys);
    assert_non_null(order);
    assert_non_null(scratch);
    for (uint32_t i = 0; i < N; ++i) {
        // Few distinct errors, many ties, a third exactly zero.
        float e = i % 3 == 0 ? 0.0f : (float)(1 + (int)(test_hash_unit(i) * 9.0f)) / 9.0f;
        if (i % 7 == 1) {
            e = 1e-9f; // tiny, still non-zero
        }
        keys[i] = (uint16_t)drift_refine_encode_error(e);
    }
    drift_refine_radix_sort(keys, N, order, scratch);
    bool *seen = calloc(N, sizeof(bool));
    assert_non_null(seen);
    for (uint32_t i = 0; i < N; ++i) {
        assert_false(seen[order[i]]);
        seen[order[i]] = true;
        if (i > 0) {
            assert_true(keys[order[i - 1]] <= keys[order[i]]);
            if (keys[order[i - 1]] == keys[order[i]]) {
                assert_true(order[i - 1] < order[i]); // stable: ties keep scanline order
            }
        }
    }
    // Descending error, zero last.
    assert_true(drift_refine_encode_error(1.0f) < drift_refine_encode_error(0.5f));
    assert_true(drift_refine_encode_error(1e-9f) < DRIFT_REFINE_ZERO_KEY);
    assert_int_equal(drift_refine_encode_error(0.0f), DRIFT_REFINE_ZERO_KEY);
    free(seen);
    free(keys);
    free(order);
    free(scratch);
}

// While any pixel with non-zero error lacks samples, no zero-error pixel gets any; and a pixel
// is never visited while a strictly larger error waits for its first sample.
static void test_refines_errors_first(void **state)
{
    (void)state;
    rig r = rig_begin();
    const int32_t w = 40, h = 30;
    build_effects_scene(&r, w, h, drift_vec3_make(0.5f, 2.2f, -3.5f));
    rig_commit(&r, &(drift_refine_params){ .spp = 2, .budget = 53, .refine_zero_error = true });
    const drift_image *error = drift_refine_error(r.sir);
    drift_image samples_plane = { 0 };
    for (uint32_t i = 0;; ++i) {
        const char *name;
        const drift_image *img;
        assert_true(drift_refine_plane(r.sir, i, &name, &img));
        if (strcmp(name, "refine.samples") == 0) {
            samples_plane = *img;
            break;
        }
    }
    bool zero_started = false;
    while (!drift_refine_done(r.sir)) {
        assert_int_equal(drift_refine_iterate(r.sir, NULL), DRIFT_OK);
        bool error_waiting = false;
        float min_visited = 2.0f, max_waiting = -1.0f;
        for (int32_t i = 0; i < w * h; ++i) {
            float e = error->pixels[i], n = samples_plane.pixels[i];
            if (e > 0.0f && n < 2.0f) {
                error_waiting = true;
            }
            if (e == 0.0f && n > 0.0f) {
                zero_started = true;
                assert_false(error_waiting);
            }
            if (n > 0.0f) {
                min_visited = fminf(min_visited, e);
            } else {
                max_waiting = fmaxf(max_waiting, e);
            }
        }
        // Every visited pixel's error key is at least as high as every unvisited one's.
        assert_true(drift_refine_encode_error(min_visited) <=
                        drift_refine_encode_error(max_waiting) ||
                    max_waiting < 0.0f);
        for (int32_t i = 0; zero_started && i < w * h; ++i) {
            if (error->pixels[i] > 0.0f) {
                assert_true(samples_plane.pixels[i] == 2.0f);
            }
        }
    }
    assert_true(zero_started);
    rig_destroy(&r);
}

// --- LAMBDA ---

static void test_lambda_fit_not_worse_than_average(void **state)
{
    (void)state;

    enum {
        VIEWS = 3
    };

    const drift_vec3 eyes[VIEWS] = { { 0.5f, 2.2f, -3.5f },
                                     { -2.0f, 1.5f, -3.0f },
                                     { 2.5f, 2.8f, -2.0f } };
    rig rigs[VIEWS];
    drift_image real[VIEWS], pure[VIEWS];
    drift_refine_view views[VIEWS];
    for (int v = 0; v < VIEWS; ++v) {
        rigs[v] = rig_begin();
        build_effects_scene(&rigs[v], 40, 30, eyes[v]);
        rig_commit(&rigs[v], &(drift_refine_params){ .spp = 2 });
        assert_int_equal(drift_image_create(rigs[v].ctx, 40, 30, 3, &pure[v]), DRIFT_OK);
        assert_int_equal(drift_image_create(rigs[v].ctx, 40, 30, 1, &real[v]), DRIFT_OK);
        assert_int_equal(drift_refine_render_pure(rigs[v].sir, test_spp(), &pure[v], NULL, NULL),
                         DRIFT_OK);
        drift_refine_real_error(drift_hybrid_image(rigs[v].frame), &pure[v], 0.1f, &real[v]);
        views[v].real_error = &real[v];
        for (int m = 0; m < DRIFT_METRIC_COUNT; ++m) {
            views[v].metrics[m] = drift_refine_metric_image(rigs[v].sir, (drift_refine_metric)m);
        }
    }
    float average[DRIFT_METRIC_COUNT], lambda[DRIFT_METRIC_COUNT];
    for (int m = 0; m < DRIFT_METRIC_COUNT; ++m) {
        average[m] = 1.0f / DRIFT_METRIC_COUNT;
    }
    double cost;
    drift_refine_fit_lambda(views, VIEWS, 200, 3, lambda, &cost);
    double average_cost = drift_refine_lambda_cost(views, VIEWS, average);
    assert_true(cost <= average_cost);
    assert_near(cost, drift_refine_lambda_cost(views, VIEWS, lambda), 1e-12);
    // The real error is not flat, so there is something to fit.
    assert_true(average_cost > 0.0);

    char path[1024];
    test_out_path(path, "refine_lambda.json");
    assert_int_equal(drift_refine_lambda_save(rigs[0].ctx, path, lambda), DRIFT_OK);
    float loaded[DRIFT_METRIC_COUNT];
    assert_int_equal(drift_refine_lambda_load(rigs[0].ctx, path, loaded), DRIFT_OK);
    for (int m = 0; m < DRIFT_METRIC_COUNT; ++m) {
        assert_near(loaded[m], lambda[m], 1e-6);
    }
    for (int v = 0; v < VIEWS; ++v) {
        drift_image_destroy(rigs[v].ctx, &pure[v]);
        drift_image_destroy(rigs[v].ctx, &real[v]);
        rig_destroy(&rigs[v]);
    }
}

static void test_rejects_bad_input(void **state)
{
    (void)state;
    rig r = rig_begin();
    build_effects_scene(&r, 16, 12, drift_vec3_make(0.5f, 2.2f, -3.5f));
    rig_commit(&r, NULL);
    drift_refine *other = NULL;
    drift_refine_params bad = { .max_depth = -1 };
    assert_int_equal(drift_refine_create(r.ctx, r.frame, &bad, &other), DRIFT_ERR_INVALID_ARGUMENT);
    assert_null(other);
    bad = (drift_refine_params){ .combine = DRIFT_COMBINE_LAMBDA, .lambda = { -1.0f } };
    assert_int_equal(drift_refine_set_params(r.sir, &bad), DRIFT_ERR_INVALID_ARGUMENT);
    float lambda[DRIFT_METRIC_COUNT];
    assert_int_equal(drift_refine_lambda_load(r.ctx, "/nonexistent/lambda.json", lambda),
                     DRIFT_ERR_IO);
    char path[1024];
    test_out_path(path, "refine_bad_lambda.json");
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    fputs("{\"lambda\": {\"reflection1\": 0.5}}", f);
    fclose(f);
    assert_int_equal(drift_refine_lambda_load(r.ctx, path, lambda), DRIFT_ERR_PARSE);
    assert_int_equal(drift_refine_metric_parse("shadow"), DRIFT_METRIC_SHADOW);
    assert_int_equal(drift_refine_metric_parse("nope"), -1);
    rig_destroy(&r);
}

// --- VIEWER ---

// A refining view lists the refiner's planes after the frame's and shows the combined error as
// a heat map: black exactly where the error is zero (the pixels SIR never traces).
static void test_view_refines_while_still(void **state)
{
    (void)state;
    rig r = rig_begin();
    build_effects_scene(&r, 40, 30, drift_vec3_make(0.5f, 2.2f, -3.5f));
    rig_commit(&r, NULL);
    drift_view *view = NULL;
    assert_int_equal(drift_view_create(r.ctx, r.scene, r.accel,
                                       &(drift_view_desc){ .hybrid = raster_params,
                                                           .refine = true,
                                                           .refine_budget = 40 * 30 * 16,
                                                           .hide_overlay = true },
                                       &view),
                     DRIFT_OK);
    assert_int_equal(drift_view_frame(view, NULL), DRIFT_OK);
    bool seen_error = false, seen_mask = false;
    for (int i = 0; i < 64; ++i) {
        drift_view_handle_event(view, &(drift_view_event){ .type = DRIFT_VIEW_EVENT_KEY,
                                                           .key = DRIFT_VIEW_KEY_NEXT_BUFFER });
        assert_int_equal(drift_view_frame(view, NULL), DRIFT_OK);
        const char *name = drift_view_get_state(view).buffer_name;
        seen_error = seen_error || strcmp(name, "error.combined") == 0;
        seen_mask = seen_mask || strcmp(name, "refine.mask") == 0;
        if (strcmp(name, "error.combined") == 0) {
            // The heat map: zero error black, some pixel coloured.
            const uint8_t *px = drift_view_pixels(view);
            const drift_image *e = drift_refine_error(r.sir);
            bool coloured = false;
            for (int32_t k = 0; k < 40 * 30; ++k) {
                if (e->pixels[k] == 0.0f) {
                    assert_true(px[3 * k] == 0 && px[3 * k + 1] == 0 && px[3 * k + 2] == 0);
                } else {
                    coloured = coloured || px[3 * k] || px[3 * k + 1] || px[3 * k + 2];
                }
            }
            assert_true(coloured);
        }
    }
    assert_true(seen_error && seen_mask);
    drift_view_destroy(view);
    rig_destroy(&r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_full_budget_gives_pure_image),
        cmocka_unit_test(test_many_small_budgets_give_pure_image),
        cmocka_unit_test(test_error_pixels_only),
        cmocka_unit_test(test_zero_error_scene),
        cmocka_unit_test(test_metrics_see_effects),
        cmocka_unit_test(test_shadow_metric_conservative),
        cmocka_unit_test(test_hierarchical_search_matches_exhaustive),
        cmocka_unit_test(test_shadow_metric_skips_unlit),
        cmocka_unit_test(test_shadow_dilation_follows_resolution),
        cmocka_unit_test(test_glossy_plane_not_flagged),
        cmocka_unit_test(test_glossy_room_refined_in_error_order),
        cmocka_unit_test(test_component_refinement_cheaper_and_close),
        cmocka_unit_test(test_half_res_penumbra_keeps_flags),
        cmocka_unit_test(test_leak_metric_finds_seams),
        cmocka_unit_test(test_radix_sort_stable_and_complete),
        cmocka_unit_test(test_refines_errors_first),
        cmocka_unit_test(test_lambda_fit_not_worse_than_average),
        cmocka_unit_test(test_rejects_bad_input),
        cmocka_unit_test(test_view_refines_while_still),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
