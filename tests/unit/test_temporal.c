// Frames in time: temporal reuse (drift/temporal.h) against closed forms (camera paths are
// test_camera_path.c): a reprojection under a known camera
// move, a disocclusion behind a sphere, and a still camera converging to the reference.
#include "drift/accel.h"
#include "drift/camera_path.h"
#include "drift/hybrid.h"
#include "drift/pt.h"
#include "drift/temporal.h"
#include "drift/view.h"
#include "drift_test.h"
#include "test_rig.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

// --- REPROJECTION ---

// A camera looking straight down at a floor lit by a low point light (a steep gradient), moved
// sideways by exactly `pixels` pixel footprints: the history reprojected into the second frame
// is the first frame shifted, and for a whole number of pixels it equals the second frame.
static void reprojection_case(float pixels, double tolerance_scale)
{
    test_rig r = test_rig_begin(2);
    uint32_t white = test_add_material(r.scene, drift_material_make(drift_vec3_splat(0.6f)));
    test_add_floor(r.scene, 100.0f, 0.0f, white);
    drift_light light = { .type = DRIFT_LIGHT_POINT,
                          .position = drift_vec3_make(0.3f, 0.4f, 0.2f),
                          .color = drift_vec3_splat(1.0f) };
    assert_int_equal(drift_scene_add_light(r.scene, &light, NULL), DRIFT_OK);
    const int w = 48, h = 32;
    const float height = 3.0f, fov = 0.8f;
    r.scene->camera = drift_camera_look_at(drift_vec3_make(0, height, 0), drift_vec3_make(0, 0, 0),
                                           drift_vec3_make(0, 0, 1), fov, w, h);
    test_rig_commit(&r);
    test_rig_frame(&r, &(drift_hybrid_params){ .width = w, .height = h });
    drift_temporal *t = NULL;
    assert_int_equal(
        drift_temporal_create(r.ctx, w, h, &(drift_temporal_settings){ .no_filter = true }, &t),
        DRIFT_OK);
    drift_camera a = r.scene->camera;
    assert_int_equal(drift_hybrid_render(r.frame, &a, NULL), DRIFT_OK);
    assert_int_equal(
        drift_temporal_apply(t, drift_hybrid_gbuffer(r.frame), &a, drift_hybrid_image(r.frame)),
        DRIFT_OK);
    drift_image first;
    assert_int_equal(drift_image_create(r.ctx, w, h, 3, &first), DRIFT_OK);
    memcpy(first.pixels, drift_hybrid_image(r.frame)->pixels, sizeof(float) * 3 * w * h);
    // One pixel spans 2 height tan(fov / 2) / h world units on the floor.
    float footprint = 2.0f * height * tanf(0.5f * fov) / (float)h;
    drift_camera b = a;
    drift_camera_frame fa = drift_camera_frame_make(&a, w, h);
    drift_vec3 shift = drift_vec3_scale(fa.u, pixels * footprint);
    b.position = drift_vec3_add(a.position, shift);
    b.target = drift_vec3_add(a.target, shift);
    assert_int_equal(drift_hybrid_render(r.frame, &b, NULL), DRIFT_OK);
    const drift_gbuffer *g = drift_hybrid_gbuffer(r.frame);
    const drift_image *second = drift_hybrid_image(r.frame);
    assert_int_equal(drift_temporal_apply(t, g, &b, second), DRIFT_OK);
    const drift_image *out = drift_temporal_image(t);
    const drift_image *len = drift_temporal_history(t);
    int checked = 0;
    for (int y = 1; y < h - 1; ++y) {
        for (int x = 1; x < w - 1; ++x) {
            // The camera moved +u: a point seen at x now was seen at x + pixels before.
            assert_near(drift_image_pixel(&g->motion, x, y)[0], pixels, 1e-3);
            assert_near(drift_image_pixel(&g->motion, x, y)[1], 0.0, 1e-3);
            float qx = (float)x + pixels;
            if (qx <= -1.0f || qx >= (float)w) {
                assert_near(drift_image_pixel(len, x, y)[0], 1.0, 0.0); // off screen before
                continue;
            }
            if (qx < 0.0f || qx > (float)(w - 1)) {
                continue; // one of the two taps was on screen
            }
            assert_near(drift_image_pixel(len, x, y)[0], 2.0, 1e-5);
            // out = (history + current) / 2 with no filter.
            double hist = 2.0 * (double)drift_image_pixel(out, x, y)[0] -
                          (double)drift_image_pixel(second, x, y)[0];
            int x0 = (int)floorf(qx) < w - 1 ? (int)floorf(qx) : w - 2;
            double f = (double)(qx - (float)x0);
            double expected = (1.0 - f) * (double)drift_image_pixel(&first, x0, y)[0] +
                              f * (double)drift_image_pixel(&first, x0 + 1, y)[0];
            assert_near(hist, expected, 1e-3 * expected);
            // Within the pixel's filter of the truth (the second frame at x).
            double cur = (double)drift_image_pixel(second, x, y)[0];
            double spread = fabs((double)drift_image_pixel(second, x + 1, y)[0] - cur) +
                            fabs((double)drift_image_pixel(second, x - 1, y)[0] - cur);
            assert_true(fabs(hist - cur) <= tolerance_scale * spread + 1e-4 * cur);
            ++checked;
        }
    }
    assert_true(checked > (w - 2) * (h - 2) / 2);
    drift_image_destroy(r.ctx, &first);
    drift_temporal_destroy(t);
    test_rig_destroy(&r);
}

static void test_reprojection_whole_pixels(void **state)
{
    (void)state;
    reprojection_case(3.0f, 0.0); // exact: the history is the frame itself
}

static void test_reprojection_subpixel(void **state)
{
    (void)state;
    reprojection_case(-1.5f, 0.5); // within the bilinear filter
}

// --temporal-resample: a noiseless frame (a floor under a point light near it, hard shadows)
// panned by half a pixel a frame for 16 frames. Each frame is exact, so the accumulated
// history should be the last frame itself; what differs is the resampling's blur, applied
// once a frame. The bilinear taps' error grows with the frames; Catmull-Rom's must stay at
// most half of it.
static double pan_history_error_lengths(int resample, int32_t moving_history, int frames, float pan,
                                        float *out_length)
{
    test_rig r = test_rig_begin(2);
    uint32_t white = test_add_material(r.scene, drift_material_make(drift_vec3_splat(0.6f)));
    test_add_floor(r.scene, 100.0f, 0.0f, white);
    drift_light light = { .type = DRIFT_LIGHT_POINT,
                          .position = drift_vec3_make(0.1f, 0.05f, 0.0f),
                          .color = drift_vec3_splat(0.05f) };
    assert_int_equal(drift_scene_add_light(r.scene, &light, NULL), DRIFT_OK);
    const int w = 48, h = 32;
    const float height = 1.0f, fov = 0.8f;
    r.scene->camera = drift_camera_look_at(drift_vec3_make(0, height, 0), drift_vec3_make(0, 0, 0),
                                           drift_vec3_make(0, 0, 1), fov, w, h);
    test_rig_commit(&r);
    test_rig_frame(&r, &(drift_hybrid_params){ .width = w, .height = h });
    drift_temporal *t = NULL;
    assert_int_equal(
        drift_temporal_create(r.ctx, w, h,
                              &(drift_temporal_settings){ .no_filter = true,
                                                          .history_resample = resample,
                                                          .moving_history = moving_history },
                              &t),
        DRIFT_OK);
    drift_camera cam = r.scene->camera;
    float footprint = 2.0f * height * tanf(0.5f * fov) / (float)h;
    drift_camera_frame fa = drift_camera_frame_make(&cam, w, h);
    drift_vec3 step = drift_vec3_scale(fa.u, pan * footprint);
    double error = 0.0;
    for (int k = 0; k < frames; ++k) {
        assert_int_equal(drift_hybrid_render(r.frame, &cam, NULL), DRIFT_OK);
        assert_int_equal(drift_temporal_apply(t, drift_hybrid_gbuffer(r.frame), &cam,
                                              drift_hybrid_image(r.frame)),
                         DRIFT_OK);
        if (k == frames - 1) {
            // The pixels whose whole history stayed on screen (the pan runs 8 pixels).
            const drift_image *out = drift_temporal_image(t), *cur = drift_hybrid_image(r.frame);
            double sum = 0.0;
            int n = 0;
            for (int y = 2; y < h - 2; ++y) {
                for (int x = 2; x < w - 12; ++x) {
                    double d = (double)drift_image_pixel(out, x, y)[0] -
                               (double)drift_image_pixel(cur, x, y)[0];
                    sum += d * d;
                    ++n;
                }
            }
            error = sqrt(sum / n);
            *out_length = drift_image_pixel(drift_temporal_history(t), w / 2, h / 2)[0];
        }
        cam.position = drift_vec3_add(cam.position, step);
        cam.target = drift_vec3_add(cam.target, step);
    }
    drift_temporal_destroy(t);
    test_rig_destroy(&r);
    return error;
}

// The history under a half-pixel pan a frame, 16 frames, both at the old cap of 32 frames.
static double pan_history_error(int resample)
{
    float length;
    return pan_history_error_lengths(resample, 32, 16, 0.5f, &length);
}

// A moving pixel's history stops at moving_history frames (8 by default), a still one's runs
// on to max_history; and the shorter history blurs less under the pan (the reason for it).
static void test_moving_history_caps(void **state)
{
    (void)state;
    float moving8 = 0.0f, moving32 = 0.0f, still = 0.0f;
    double e8 = pan_history_error_lengths(0, 0, 20, 0.5f, &moving8);
    double e32 = pan_history_error_lengths(0, 32, 20, 0.5f, &moving32);
    pan_history_error_lengths(0, 0, 20, 0.0f, &still);
    print_message("history length after 20 frames: panning %g (moving_history 8), %g (32); "
                  "still %g; pan error %.5f / %.5f\n",
                  (double)moving8, (double)moving32, (double)still, e8, e32);
    assert_near(moving8, 8.0, 1e-3);
    assert_near(moving32, 20.0, 1e-3);
    assert_near(still, 20.0, 1e-3);
    assert_true(e8 < e32);
}

static void test_history_resample_sharp(void **state)
{
    (void)state;
    double bilinear = pan_history_error(0), catmull_rom = pan_history_error(1);
    if (getenv("DRIFT_TEST_VERBOSE")) {
        printf("history RMSE after 16 half-pixel pans: bilinear %.5f, catmull-rom %.5f\n", bilinear,
               catmull_rom);
    }
    assert_true(bilinear > 1e-4); // the case has detail to lose
    assert_true(catmull_rom < 0.5 * bilinear);
}

// --- DISOCCLUSION ---

// A sphere above a floor; the camera moves sideways. Floor points the sphere hid from the first
// camera (the segment from it to the point crosses the sphere) restart their history; floor
// points both cameras saw keep it.
static void test_disocclusion(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    uint32_t white = test_add_material(r.scene, drift_material_make(drift_vec3_splat(0.5f)));
    uint32_t red =
        test_add_material(r.scene, drift_material_make(drift_vec3_make(0.6f, 0.1f, 0.1f)));
    test_add_floor(r.scene, 100.0f, 0.0f, white);
    const drift_vec3 centre = drift_vec3_make(0.0f, 1.0f, 0.0f);
    const float radius = 0.6f;
    test_add_sphere(r.scene, centre, radius, 48, 24, red);
    drift_light light = { .type = DRIFT_LIGHT_POINT,
                          .position = drift_vec3_make(0, 6, 0),
                          .color = drift_vec3_splat(10.0f) };
    assert_int_equal(drift_scene_add_light(r.scene, &light, NULL), DRIFT_OK);
    const int w = 48, h = 48;
    r.scene->camera = drift_camera_look_at(drift_vec3_make(0, 4, 0), drift_vec3_make(0, 0, 0),
                                           drift_vec3_make(0, 0, 1), 1.0f, w, h);
    test_rig_commit(&r);
    test_rig_frame(&r, &(drift_hybrid_params){ .width = w, .height = h });
    drift_temporal *t = NULL;
    assert_int_equal(drift_temporal_create(r.ctx, w, h, NULL, &t), DRIFT_OK);
    drift_camera a = r.scene->camera, b = a;
    b.position = drift_vec3_add(a.position, drift_vec3_make(1.0f, 0, 0));
    b.target = drift_vec3_add(a.target, drift_vec3_make(1.0f, 0, 0));
    for (int k = 0; k < 2; ++k) {
        const drift_camera *cam = k ? &b : &a;
        assert_int_equal(drift_hybrid_render(r.frame, cam, NULL), DRIFT_OK);
        assert_int_equal(drift_temporal_apply(t, drift_hybrid_gbuffer(r.frame), cam,
                                              drift_hybrid_image(r.frame)),
                         DRIFT_OK);
    }
    const drift_gbuffer *g = drift_hybrid_gbuffer(r.frame);
    const drift_image *len = drift_temporal_history(t);
    drift_camera_frame fa = drift_camera_frame_make(&a, w, h);
    int hidden = 0, kept = 0;
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            if (drift_image_pixel(&g->material_id, x, y)[0] != (float)white) {
                continue;
            }
            drift_vec3 p = drift_image_get3(&g->position, x, y);
            drift_vec2 film;
            if (!drift_camera_frame_project(&fa, p, &film) || film.x < 2.0f || film.y < 2.0f ||
                film.x > (float)w - 2.0f || film.y > (float)h - 2.0f) {
                continue; // outside the first frame
            }
            // The distance from the sphere's centre to the segment a -> p.
            drift_vec3 d = drift_vec3_sub(p, a.position);
            float s = drift_clampf(drift_vec3_dot(drift_vec3_sub(centre, a.position), d) /
                                       drift_vec3_dot(d, d),
                                   0.0f, 1.0f);
            float dist =
                drift_vec3_length(drift_vec3_sub(drift_vec3_fma(a.position, d, s), centre));
            float n = drift_image_pixel(len, x, y)[0];
            if (dist < radius - 0.1f) {
                assert_near(n, 1.0, 0.0);
                ++hidden;
            } else if (dist > radius + 0.1f) {
                assert_near(n, 2.0, 1e-5);
                ++kept;
            }
        }
    }
    assert_true(hidden > 20);
    assert_true(kept > 200);
    drift_temporal_destroy(t);
    test_rig_destroy(&r);
}

// --- CONVERGENCE ---

// A still camera over a box lit by a point light, indirect light path-traced at 1 spp with a
// new seed each frame: the accumulated frame's error against the same frame at 512 spp falls
// with the frames (within 10 % noise from one check to the next) and ends below a third of
// the first frame's; the filtered one starts and ends below the unfiltered one.
static void add_lit_box(test_rig *r, int w)
{
    uint32_t white = test_add_material(r->scene, drift_material_make(drift_vec3_splat(0.7f)));
    const float p[] = { -1, -1, -1, 1, -1, -1, 1, 1, -1, -1, 1, -1,
                        -1, -1, 1,  1, -1, 1,  1, 1, 1,  -1, 1, 1 };
    const uint32_t idx[] = { 0, 1, 2, 0, 2, 3, 4, 7, 6, 4, 6, 5, 0, 4, 5, 0, 5, 1,
                             3, 2, 6, 3, 6, 7, 0, 3, 7, 0, 7, 4, 1, 5, 6, 1, 6, 2 };
    test_add_mesh(r->scene, p, 8, idx, 12, white);
    drift_light light = { .type = DRIFT_LIGHT_POINT,
                          .position = drift_vec3_make(0.2f, 0.8f, 0.1f),
                          .color = drift_vec3_splat(2.0f) };
    assert_int_equal(drift_scene_add_light(r->scene, &light, NULL), DRIFT_OK);
    r->scene->camera = drift_camera_look_at(drift_vec3_make(0, 0, 0.95f), drift_vec3_make(0, 0, 0),
                                            drift_vec3_make(0, 1, 0), 1.6f, w, w);
    test_rig_commit(r);
}

static void test_still_camera_converges(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    const int w = 24;
    add_lit_box(&r, w);
    drift_hybrid_params params = {
        .width = w, .height = w, .indirect = DRIFT_INDIRECT_REFERENCE, .spp = 512
    };
    test_rig_frame(&r, &params);
    drift_image reference;
    assert_int_equal(drift_image_create(r.ctx, w, w, 3, &reference), DRIFT_OK);
    memcpy(reference.pixels, drift_hybrid_image(r.frame)->pixels, sizeof(float) * 3 * w * w);
    params.spp = 1;
    double first[2] = { 0 }, last[2] = { 0 };
    for (int filtered = 0; filtered < 2; ++filtered) {
        drift_temporal *t = NULL;
        assert_int_equal(drift_temporal_create(
                             r.ctx, w, w, &(drift_temporal_settings){ .no_filter = !filtered }, &t),
                         DRIFT_OK);
        double prev_error = INFINITY;
        for (int k = 1; k <= 32; ++k) {
            params.seed = (uint32_t)k;
            assert_int_equal(drift_hybrid_set_params(r.frame, &params), DRIFT_OK);
            assert_int_equal(drift_hybrid_render(r.frame, &r.scene->camera, NULL), DRIFT_OK);
            assert_int_equal(drift_temporal_apply(t, drift_hybrid_gbuffer(r.frame),
                                                  &r.scene->camera, drift_hybrid_image(r.frame)),
                             DRIFT_OK);
            if ((k & (k - 1)) == 0) { // 1, 2, 4, 8, 16, 32
                double e = test_rmse(r.ctx, drift_temporal_image(t), &reference);
                if (k == 1) {
                    first[filtered] = e;
                }
                last[filtered] = e;
                if (getenv("DRIFT_TEST_VERBOSE")) {
                    fprintf(stderr, "filtered %d frames %d error %g\n", filtered, k, e);
                }
                if (!(e <= 1.1 * prev_error) && (!filtered || k > 4)) {
                    fail_msg("filtered %d: error %g after %d frames, %g before", filtered, e, k,
                             prev_error);
                }
                prev_error = e;
            }
        }
        drift_temporal_destroy(t);
    }
    assert_true(last[0] < first[0] / 3.0);
    assert_true(first[1] < first[0]);
    assert_true(last[1] < first[1]);
    drift_image_destroy(r.ctx, &reference);
    test_rig_destroy(&r);
}

// Mean absolute difference of a view's framebuffer from `ref`, in sRGB levels.
static double view_error(const drift_view *view, const uint8_t *ref, int w)
{
    const uint8_t *px = drift_view_pixels(view);
    double err = 0.0;
    for (int i = 0; i < 3 * w * w; ++i) {
        err += fabs((double)px[i] - (double)ref[i]) / (3.0 * w * w);
    }
    return err;
}

// The viewer with temporal reuse: a still camera's framebuffer after 16 frames is nearer the
// converged frame's (8 x 64 spp over the pixel) than one frame's is, by more than half.
static void test_view_converges(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    const int w = 24;
    add_lit_box(&r, w);
    drift_view_desc desc = { .width = w,
                             .height = w,
                             .hide_overlay = true,
                             .hybrid = { .indirect = DRIFT_INDIRECT_REFERENCE, .spp = 1 } };
    drift_view *views[3] = { NULL, NULL, NULL };
    desc.temporal = true;
    // The history alone (the refinement toward the path tracer is test_view_still_refines').
    desc.temporal_settings.no_still_refine = true;
    assert_int_equal(drift_view_create(r.ctx, r.scene, r.accel, &desc, &views[0]), DRIFT_OK);
    desc.temporal = false;
    assert_int_equal(drift_view_create(r.ctx, r.scene, r.accel, &desc, &views[1]), DRIFT_OK);
    // The converged frame through the pixel's box filter, as the temporal frames' sub-pixel
    // offsets average it: 8 anti-aliasing passes of 64 samples.
    desc.hybrid.spp = 64;
    desc.hybrid.aa = 8;
    assert_int_equal(drift_view_create(r.ctx, r.scene, r.accel, &desc, &views[2]), DRIFT_OK);
    for (int k = 0; k < 16; ++k) {
        assert_int_equal(drift_view_frame(views[0], NULL), DRIFT_OK);
    }
    assert_int_equal(drift_view_frame(views[1], NULL), DRIFT_OK);
    assert_int_equal(drift_view_frame(views[2], NULL), DRIFT_OK);
    double err[2] = { 0.0, 0.0 };
    const uint8_t *ref = drift_view_pixels(views[2]);
    for (int v = 0; v < 2; ++v) {
        err[v] = view_error(views[v], ref, w);
    }
    if (getenv("DRIFT_TEST_VERBOSE")) {
        fprintf(stderr, "temporal view error %g, one frame %g (sRGB levels)\n", err[0], err[1]);
    }
    if (!(err[0] < 0.5 * err[1])) {
        fail_msg("temporal view error %g, one frame %g (sRGB levels)", err[0], err[1]);
    }
    for (int v = 0; v < 3; ++v) {
        drift_view_destroy(views[v]);
    }
    test_rig_destroy(&r);
}

// Still refinement in the viewer: the hybrid (indirect light path-traced to depth 2 in a closed
// white box) is biased against the path tracer (depth 8); after 16 still frames the refined
// framebuffer is nearer the converged path tracer's than the temporal history alone, which
// converges to the hybrid's mean. `progressive`: --still-refine progressive (no hybrid frames
// once still, 4 path-traced samples a frame, the hybrid faded out by sample count).
static void view_still_refines(int moving_refine, bool progressive)
{
    test_rig r = test_rig_begin(2);
    const int w = 24;
    add_lit_box(&r, w);
    drift_view_desc desc = { .width = w,
                             .height = w,
                             .hide_overlay = true,
                             .temporal = true,
                             .temporal_settings = { .moving_refine = moving_refine,
                                                    .still_keeps_hybrid = !progressive },
                             .hybrid = { .indirect = DRIFT_INDIRECT_REFERENCE, .spp = 1 } };
    drift_view *views[3] = { NULL, NULL, NULL };
    assert_int_equal(drift_view_create(r.ctx, r.scene, r.accel, &desc, &views[0]), DRIFT_OK);
    desc.temporal_settings = (drift_temporal_settings){ .no_still_refine = true };
    assert_int_equal(drift_view_create(r.ctx, r.scene, r.accel, &desc, &views[1]), DRIFT_OK);
    // The path tracer, converged over the pixel's box filter: the same frame to depth 8.
    desc.temporal = false;
    desc.hybrid = (drift_hybrid_params){
        .indirect = DRIFT_INDIRECT_REFERENCE, .spp = 128, .aa = 8, .max_depth = 8
    };
    assert_int_equal(drift_view_create(r.ctx, r.scene, r.accel, &desc, &views[2]), DRIFT_OK);
    assert_int_equal(drift_view_frame(views[2], NULL), DRIFT_OK);
    const uint8_t *ref = drift_view_pixels(views[2]);
    double err[2][17] = { { 0.0 } };
    for (int k = 1; k <= 16; ++k) {
        for (int v = 0; v < 2; ++v) {
            assert_int_equal(drift_view_frame(views[v], NULL), DRIFT_OK);
            err[v][k] = view_error(views[v], ref, w);
        }
        if (getenv("DRIFT_TEST_VERBOSE")) {
            fprintf(stderr,
                    "moving %d progressive %d frames %d: refined %g, history alone %g (sRGB "
                    "levels)\n",
                    moving_refine, (int)progressive, k, err[0][k], err[1][k]);
        }
    }
    // Falling with the frames within noise (each of 2, 4, 8, 16 at most 10% above the one
    // before), and well below the hybrid's bias at the end.
    for (int k = 2; k <= 16; k *= 2) {
        if (!(err[0][k] <= 1.1 * err[0][k / 2])) {
            fail_msg("refined error %g after %d frames, %g after %d", err[0][k], k, err[0][k / 2],
                     k / 2);
        }
    }
    if (!(err[0][16] < 0.5 * err[1][16])) {
        fail_msg("refined error %g, history alone %g (sRGB levels)", err[0][16], err[1][16]);
    }
    for (int v = 0; v < 3; ++v) {
        drift_view_destroy(views[v]);
    }
    test_rig_destroy(&r);
}

// The still refinement alone, and fed by the moving refinement (the viewer chains them).
static void test_view_still_refines(void **state)
{
    (void)state;
    view_still_refines(0, false);
    view_still_refines(1, false);
    view_still_refines(0, true);
    view_still_refines(1, true);
}

// --- MOVING REFINEMENT ---

// The lit box's camera at frame k of a known move: a slow pan to the right.
static drift_camera moving_camera(int k, int w)
{
    drift_vec3 eye = drift_vec3_make(-0.15f + 0.02f * (float)k, 0.05f, 0.9f);
    return drift_camera_look_at(eye, drift_vec3_add(eye, drift_vec3_make(0.1f, 0, -1)),
                                drift_vec3_make(0, 1, 0), 1.6f, w, w);
}

// The path tracer to depth 8 through `cam`, `spp` samples a pixel (the reference).
static drift_image moving_reference(test_rig *r, const drift_camera *cam, int w)
{
    drift_pt *pt = NULL;
    assert_int_equal(
        drift_pt_create(r->ctx, r->scene, r->accel,
                        &(drift_pt_params){ .width = w, .height = w, .seed = 99, .camera = cam },
                        &pt),
        DRIFT_OK);
    assert_int_equal(drift_pt_render_samples(pt, 512, NULL), DRIFT_OK);
    drift_image beauty;
    assert_int_equal(drift_pt_resolve(pt, DRIFT_PT_AOV_BEAUTY, &beauty), DRIFT_OK);
    drift_image out = test_image_copy(r->ctx, &beauty);
    drift_pt_destroy(pt);
    return out;
}

// Runs `frames` frames of the move (or of its first frame's camera standing, `still`) through
// the temporal reuse and the moving refinement (mode 1 path, 2 residual, 3 path at half size;
// 0 none), a sample for each pixel every `period` frames, and returns a copy of the last shown
// image; errors[k] (may be NULL) gets frame k's RMSE against the reference where refs[k] is set.
static drift_image run_moving_with(test_rig *r, int w, int mode, int period, bool still, int frames,
                                   const drift_image *refs, double *errors)
{
    drift_hybrid_params params = {
        .width = w, .height = w, .indirect = DRIFT_INDIRECT_REFERENCE, .spp = 1
    };
    test_rig_frame(r, &params);
    drift_temporal *t = NULL;
    drift_moving_refine *m = NULL;
    assert_int_equal(drift_temporal_create(r->ctx, w, w, &(drift_temporal_settings){ 0 }, &t),
                     DRIFT_OK);
    if (mode) {
        assert_int_equal(
            drift_moving_refine_create(r->ctx, r->scene, r->accel, t,
                                       &(drift_moving_refine_settings){ .seed = 5,
                                                                        .residual = mode == 2,
                                                                        .scale = mode == 3 ? 2 : 1,
                                                                        .period = period },
                                       &m),
            DRIFT_OK);
    }
    const drift_image *shown = NULL;
    for (int k = 0; k < frames; ++k) {
        drift_camera cam = moving_camera(still ? 0 : k, w), jittered = cam;
        assert_int_equal(drift_temporal_prepare(r->frame, 1, (uint32_t)k, &jittered), DRIFT_OK);
        assert_int_equal(drift_hybrid_render(r->frame, &jittered, NULL), DRIFT_OK);
        const drift_gbuffer *g = drift_hybrid_gbuffer(r->frame);
        assert_int_equal(drift_temporal_apply(t, g, &jittered, drift_hybrid_image(r->frame)),
                         DRIFT_OK);
        shown = drift_temporal_image(t);
        if (m) {
            assert_int_equal(
                drift_moving_refine_apply(m, g, &cam, drift_hybrid_image(r->frame), shown, NULL),
                DRIFT_OK);
            shown = drift_moving_refine_image(m);
        }
        if (errors && refs[k].pixels) {
            errors[k] = test_rmse(r->ctx, shown, &refs[k]);
        }
    }
    drift_image out = test_image_copy(r->ctx, shown);
    drift_moving_refine_destroy(m);
    drift_temporal_destroy(t);
    return out;
}

static drift_image run_moving(test_rig *r, int w, int mode, int frames, const drift_image *refs,
                              double *errors)
{
    return run_moving_with(r, w, mode, 1, false, frames, refs, errors);
}

// A static box under a known camera move, the hybrid biased (indirect light to the hybrid's
// depth, the reference to depth 8): the refined image's error against each frame's
// path-traced reference falls with the frames (4, 8, 16, 24: each at most 10% above the one
// before, the last below 0.8 of the fourth frame's) and ends below 0.7 of the temporal
// history's alone, for the path and the residual forms and the half-size path samples, and
// the residual and path forms with a sample for each pixel every 4 frames (--moving-refine-period
// 4; modes 4 and 5 here).
static void test_moving_refine_converges(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    const int w = 24, frames = 25;
    add_lit_box(&r, w);
    drift_image refs[25];
    memset(refs, 0, sizeof refs);
    static const int checks[] = { 4, 8, 16, 24 };
    for (int i = 0; i < 4; ++i) {
        drift_camera cam = moving_camera(checks[i], w);
        refs[checks[i]] = moving_reference(&r, &cam, w);
    }
    double plain[25] = { 0 };
    drift_image last = run_moving(&r, w, 0, frames, refs, plain);
    drift_image_destroy(r.ctx, &last);
    for (int mode = 1; mode <= 5; ++mode) {
        double e[25] = { 0 };
        int form = mode == 4 ? 2 : mode == 5 ? 1 : mode;
        last = run_moving_with(&r, w, form, mode >= 4 ? 4 : 1, false, frames, refs, e);
        drift_image_destroy(r.ctx, &last);
        if (getenv("DRIFT_TEST_VERBOSE")) {
            for (int i = 0; i < 4; ++i) {
                fprintf(stderr, "mode %d frame %d: refined %g, history alone %g\n", mode, checks[i],
                        e[checks[i]], plain[checks[i]]);
            }
        }
        for (int i = 1; i < 4; ++i) {
            if (!(e[checks[i]] <= 1.1 * e[checks[i - 1]])) {
                fail_msg("mode %d: error %g at frame %d, %g at %d", mode, e[checks[i]], checks[i],
                         e[checks[i - 1]], checks[i - 1]);
            }
        }
        if (!(e[24] < 0.8 * e[4]) || !(e[24] < 0.7 * plain[24])) {
            fail_msg("mode %d: error %g at frame 24, %g at 4, history alone %g", mode, e[24], e[4],
                     plain[24]);
        }
    }
    for (int i = 0; i < 4; ++i) {
        drift_image_destroy(r.ctx, &refs[checks[i]]);
    }
    test_rig_destroy(&r);
}

// The same move's refined frames are bit-identical for 1 and 2 threads (the residual form,
// the path form at half size, and the residual form a sample for each pixel every 4 frames).
static void test_moving_refine_threads(void **state)
{
    (void)state;
    const int w = 20;
    size_t bytes = sizeof(float) * 3 * (size_t)(w * w);
    float *out[2][3];
    for (int i = 0; i < 2; ++i) {
        test_rig r = test_rig_begin(i + 1);
        add_lit_box(&r, w);
        for (int mode = 2; mode <= 4; ++mode) {
            drift_image last = run_moving_with(&r, w, mode == 4 ? 2 : mode, mode == 4 ? 4 : 1,
                                               false, 6, NULL, NULL);
            out[i][mode - 2] = malloc(bytes);
            assert_non_null(out[i][mode - 2]);
            memcpy(out[i][mode - 2], last.pixels, bytes);
            drift_image_destroy(r.ctx, &last);
        }
        test_rig_destroy(&r);
    }
    for (int k = 0; k < 3; ++k) {
        assert_memory_equal(out[0][k], out[1][k], bytes);
        free(out[0][k]);
        free(out[1][k]);
    }
}

// A standing camera with a sample for each pixel every 4 frames still converges to the
// reference. A single frame's error swings by up to 2x about its trend here (the blend of a
// noisy one-sample hybrid, at every period), so the checks are on window means: frames 4-7,
// 8-15, 16-31, 32-63, each mean at most 10% above the one before, the last below 0.6 of the
// first and below 0.7 of the temporal history's alone (the hybrid's bias, which the history
// cannot average), for the path and the residual forms.
static void test_moving_refine_period_still(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);

    enum {
        FRAMES = 64
    };

    const int w = 24;
    add_lit_box(&r, w);
    drift_image refs[FRAMES];
    drift_camera cam = moving_camera(0, w);
    drift_image ref = moving_reference(&r, &cam, w);
    for (int k = 0; k < FRAMES; ++k) {
        refs[k] = ref;
    }
    static const int windows[5] = { 4, 8, 16, 32, 64 };
    double plain[FRAMES] = { 0 }, plain_last = 0.0;
    drift_image last = run_moving_with(&r, w, 0, 1, true, FRAMES, refs, plain);
    drift_image_destroy(r.ctx, &last);
    for (int k = 32; k < 64; ++k) {
        plain_last += plain[k] / 32.0;
    }
    for (int form = 1; form <= 2; ++form) {
        double e[FRAMES] = { 0 }, mean[4] = { 0 };
        last = run_moving_with(&r, w, form, 4, true, FRAMES, refs, e);
        drift_image_destroy(r.ctx, &last);
        for (int i = 0; i < 4; ++i) {
            for (int k = windows[i]; k < windows[i + 1]; ++k) {
                mean[i] += e[k] / (double)(windows[i + 1] - windows[i]);
            }
            if (getenv("DRIFT_TEST_VERBOSE")) {
                fprintf(stderr, "still, period 4, form %d, frames %d-%d: refined %g\n", form,
                        windows[i], windows[i + 1] - 1, mean[i]);
            }
        }
        for (int i = 1; i < 4; ++i) {
            if (!(mean[i] <= 1.1 * mean[i - 1])) {
                fail_msg("form %d: mean error %g over frames %d-%d, %g before", form, mean[i],
                         windows[i], windows[i + 1] - 1, mean[i - 1]);
            }
        }
        if (!(mean[3] < 0.6 * mean[0]) || !(mean[3] < 0.7 * plain_last)) {
            fail_msg("form %d: mean error %g over frames 32-63, %g over 4-7, history alone %g",
                     form, mean[3], mean[0], plain_last);
        }
    }
    drift_image_destroy(r.ctx, &ref);
    test_rig_destroy(&r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_reprojection_whole_pixels),
        cmocka_unit_test(test_reprojection_subpixel),
        cmocka_unit_test(test_history_resample_sharp),
        cmocka_unit_test(test_moving_history_caps),
        cmocka_unit_test(test_disocclusion),
        cmocka_unit_test(test_still_camera_converges),
        cmocka_unit_test(test_view_converges),
        cmocka_unit_test(test_view_still_refines),
        cmocka_unit_test(test_moving_refine_converges),
        cmocka_unit_test(test_moving_refine_threads),
        cmocka_unit_test(test_moving_refine_period_still),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
