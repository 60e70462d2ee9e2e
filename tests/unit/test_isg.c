// Image space gathering against closed forms and properties: contact hardening that follows
// eq. 8, the limits L -> 0 (hard shadow), theta_max -> 0 (sharp reflection) and zero aperture
// (identity), one gather per light, depth of field that spreads a blurred foreground without
// bleeding an in-focus one, and the second depth layer (the gather filter itself:
// test_isg_filter.c).
// ctest-labels: quality
#include "drift/accel.h"
#include "drift/hybrid.h"
#include "drift/scene.h"
#include "drift_test.h"
#include "isg/isg.h"
#include "test_rig.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

// Axis-aligned rectangle [x0, x1] x [z0, z1] at height y, facing +y.
static void add_rect(drift_scene *scene, float x0, float x1, float z0, float z1, float y,
                     uint32_t material)
{
    const float p[] = { x0, y, z0, x1, y, z0, x1, y, z1, x0, y, z1 };
    const uint32_t idx[] = { 0, 2, 1, 0, 3, 2 };
    test_add_mesh(scene, p, 4, idx, 2, material);
}

// --- SOFT SHADOWS ---

// A floor, a half plane x < 0 at height h above it, and a sphere light of radius L at
// (-2, H, 0): the hard shadow's edge lies at x = 2h / (H - h) on the floor, seen from above.
#define LIGHT_HEIGHT 4.0f
#define SHADOW_W     200
#define SHADOW_H     100

static void build_occluder(test_rig *r, float h, float light_radius)
{
    uint32_t white = test_add_material(r->scene, drift_material_make(drift_vec3_splat(0.5f)));
    add_rect(r->scene, -10.0f, 10.0f, -10.0f, 10.0f, 0.0f, white);
    add_rect(r->scene, -6.0f, 0.0f, -6.0f, 6.0f, h, white);
    assert_int_equal(
        drift_scene_add_light(r->scene,
                              &(drift_light){ .type = DRIFT_LIGHT_SPHERE,
                                              .position = { -2.0f, LIGHT_HEIGHT, 0.0f },
                                              .radius = light_radius,
                                              .color = { 5, 5, 5 } },
                              NULL),
        DRIFT_OK);
    r->scene->camera =
        drift_camera_look_at(drift_vec3_make(0.75f, 8.0f, 0.0f), drift_vec3_make(0.75f, 0.0f, 0.0f),
                             drift_vec3_make(0.0f, 0.0f, 1.0f), 0.25f, SHADOW_W, SHADOW_H);
}

// Fraction of the unit disk beyond x = t (the shadow a disk-shaped gather makes of a step).
static double disk_beyond(double t)
{
    return (acos(t) - t * sqrt(1.0 - t * t)) / 3.14159265358979323846;
}

// The offset t where the disk-blurred step crosses 10%: the 10-90% width is 2 t R.
static double disk_t10(void)
{
    double lo = 0.0, hi = 1.0;
    for (int i = 0; i < 60; ++i) {
        double mid = 0.5 * (lo + hi);
        if (disk_beyond(mid) > 0.1) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    return 0.5 * (lo + hi);
}

// The 10-90% width in scene units of the shadow across x on the floor, from the shadow plane
// averaged over the middle rows.
static double measured_penumbra(const test_rig *r)
{
    const drift_image *shadow = test_rig_plane(r, "light0.shadow");
    const drift_gbuffer *g = drift_hybrid_gbuffer(r->frame);
    double profile[SHADOW_W], xs[SHADOW_W];
    for (int x = 0; x < SHADOW_W; ++x) {
        double sum = 0.0;
        int n = 0;
        for (int y = SHADOW_H / 4; y < 3 * SHADOW_H / 4; ++y) {
            sum += (double)drift_image_pixel(shadow, x, y)[0];
            ++n;
        }
        profile[x] = sum / n;
        xs[x] = (double)drift_image_pixel(&g->position, x, SHADOW_H / 2)[0];
    }
    // Walk from the lit side (largest x) toward the shadow; floor pixels only (y = 0).
    int step = xs[SHADOW_W - 1] > xs[0] ? -1 : 1;
    int start = step < 0 ? SHADOW_W - 1 : 0;
    double x90 = NAN, x10 = NAN;
    for (int x = start; x + step >= 0 && x + step < SHADOW_W; x += step) {
        if (fabsf(drift_image_pixel(&g->position, x + step, SHADOW_H / 2)[1]) > 1e-3f) {
            break; // the occluder
        }
        double a = profile[x], b = profile[x + step];
        if (isnan(x90) && a >= 0.9 && b < 0.9) {
            x90 = xs[x] + (xs[x + step] - xs[x]) * (a - 0.9) / (a - b);
        }
        if (isnan(x10) && a >= 0.1 && b < 0.1) {
            x10 = xs[x] + (xs[x + step] - xs[x]) * (a - 0.1) / (a - b);
        }
    }
    if (isnan(x90) || isnan(x10)) {
        for (int x = 0; x < SHADOW_W; ++x) {
            print_message("%d x %.3f y %.3f s %.3f\n", x, xs[x],
                          (double)drift_image_pixel(&g->position, x, SHADOW_H / 2)[1], profile[x]);
        }
    }
    assert_false(isnan(x90));
    assert_false(isnan(x10));
    return fabs(x90 - x10);
}

static void test_contact_hardening_follows_eq8(void **state)
{
    (void)state;
    const float light_radius = 0.5f, heights[] = { 0.5f, 1.0f, 1.5f };
    double previous = 0.0;
    for (int i = 0; i < 3; ++i) {
        test_rig r = test_rig_begin(2);
        build_occluder(&r, heights[i], light_radius);
        test_rig_commit(&r);
        // The tangent-plane range: the world distance would also weigh the floor down over
        // the penumbra (docs/isg.md); eq. 8 is what is under test.
        test_rig_frame(&r, &(drift_hybrid_params){ .shadows = DRIFT_SHADOWS_ISG,
                                                   .isg.search = 49,
                                                   .isg.gather = 81,
                                                   .isg.range_plane = true });
        double width = measured_penumbra(&r);
        // Eq. 8: the occluder distance d and light distance D along the ray share the ratio
        // h / H, so R_s = L h / (H - h).
        double rs = (double)drift_isg_penumbra(light_radius, heights[i], LIGHT_HEIGHT);
        assert_near(rs, light_radius * heights[i] / (LIGHT_HEIGHT - heights[i]), 1e-6);
        double expected = 2.0 * disk_t10() * rs;
        print_message("h %.2f: penumbra 10-90%% %.4f, eq. 8 predicts %.4f\n", (double)heights[i],
                      width, expected);
        assert_true(fabs(width - expected) <= 0.2 * expected);
        assert_true(width > previous * 1.3); // grows with the occluder's height
        previous = width;
        test_rig_destroy(&r);
    }
}

static void test_point_like_light_gives_hard_shadow(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    build_occluder(&r, 1.0f, 1e-4f);
    test_rig_commit(&r);
    test_rig_frame(&r, &(drift_hybrid_params){ .shadows = DRIFT_SHADOWS_ISG });
    const drift_image *hard = test_rig_plane(&r, "light0.hard_shadow");
    const drift_image *shadow = test_rig_plane(&r, "light0.shadow");
    int shadowed = 0;
    for (int y = 0; y < SHADOW_H; ++y) {
        for (int x = 0; x < SHADOW_W; ++x) {
            assert_true(drift_image_pixel(shadow, x, y)[0] == drift_image_pixel(hard, x, y)[0]);
            shadowed += drift_image_pixel(hard, x, y)[0] == 0.0f;
        }
    }
    assert_true(shadowed > 100);
    // The same light at full size does soften the shadow (the test can fail).
    test_rig r2 = test_rig_begin(2);
    build_occluder(&r2, 1.0f, 0.5f);
    test_rig_commit(&r2);
    test_rig_frame(&r2, &(drift_hybrid_params){ .shadows = DRIFT_SHADOWS_ISG });
    int partial = 0;
    shadow = test_rig_plane(&r2, "light0.shadow");
    for (int y = 0; y < SHADOW_H; ++y) {
        for (int x = 0; x < SHADOW_W; ++x) {
            float v = drift_image_pixel(shadow, x, y)[0];
            partial += v > 0.0f && v < 1.0f;
        }
    }
    assert_true(partial > 200);
    test_rig_destroy(&r2);
    test_rig_destroy(&r);
}

// Two lights: each gets its own search and gather. A point-sized second light keeps its hard
// shadow bit for bit while the first light's shadow softens.
static void test_each_light_gathers_its_own_shadow(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    build_occluder(&r, 1.0f, 0.5f);
    assert_int_equal(
        drift_scene_add_light(r.scene,
                              &(drift_light){ .type = DRIFT_LIGHT_SPHERE,
                                              .position = { -4.0f, LIGHT_HEIGHT, 0.0f },
                                              .radius = 1e-4f,
                                              .color = { 5, 5, 5 } },
                              NULL),
        DRIFT_OK);
    test_rig_commit(&r);
    test_rig_frame(&r, &(drift_hybrid_params){ .shadows = DRIFT_SHADOWS_ISG });
    const drift_image *hard1 = test_rig_plane(&r, "light1.hard_shadow"),
                      *shadow1 = test_rig_plane(&r, "light1.shadow");
    const drift_image *shadow0 = test_rig_plane(&r, "light0.shadow");
    int partial0 = 0, shadowed1 = 0;
    for (int y = 0; y < SHADOW_H; ++y) {
        for (int x = 0; x < SHADOW_W; ++x) {
            assert_true(drift_image_pixel(shadow1, x, y)[0] == drift_image_pixel(hard1, x, y)[0]);
            shadowed1 += drift_image_pixel(hard1, x, y)[0] == 0.0f;
            float v = drift_image_pixel(shadow0, x, y)[0];
            partial0 += v > 0.0f && v < 1.0f;
        }
    }
    assert_true(shadowed1 > 100);
    assert_true(partial0 > 200);
    test_rig_destroy(&r);
}

// --- GLOSSY REFLECTIONS ---

// A glossy floor of Phong exponent n under a red box, a point light, a camera looking down
// at an angle: returns the RMS difference between the ISG and sharp reflection planes.
static double reflection_difference(float exponent)
{
    test_rig r = test_rig_begin(2);
    uint32_t floor =
        test_add_material(r.scene, (drift_material){ .diffuse = { 0.2f, 0.2f, 0.2f },
                                                     .specular = { 0.6f, 0.6f, 0.6f },
                                                     .exponent = exponent,
                                                     .diffuse_texture = DRIFT_INVALID_INDEX });
    uint32_t red =
        test_add_material(r.scene, drift_material_make(drift_vec3_make(0.8f, 0.1f, 0.1f)));
    add_rect(r.scene, -5.0f, 5.0f, -5.0f, 5.0f, 0.0f, floor);
    const float p[] = { -0.5f, 0.0f, 0.0f, 0.5f, 0.0f, 0.0f, 0.5f, 1.0f, 0.0f, -0.5f, 1.0f, 0.0f };
    const uint32_t idx[] = { 0, 1, 2, 0, 2, 3 };
    test_add_mesh(r.scene, p, 4, idx, 2, red); // a wall facing the camera, standing on the floor
    assert_int_equal(drift_scene_add_light(r.scene,
                                           &(drift_light){ .type = DRIFT_LIGHT_POINT,
                                                           .position = { 0.0f, 3.0f, -2.0f },
                                                           .color = { 20, 20, 20 } },
                                           NULL),
                     DRIFT_OK);
    r.scene->camera =
        drift_camera_look_at(drift_vec3_make(0.0f, 1.0f, -3.0f), drift_vec3_make(0.0f, 0.0f, 0.0f),
                             drift_vec3_make(0.0f, 1.0f, 0.0f), 0.8f, 64, 48);
    test_rig_commit(&r);
    test_rig_frame(&r, &(drift_hybrid_params){ .reflections = DRIFT_REFLECTIONS_SHARP });
    drift_image sharp;
    assert_int_equal(drift_image_create(r.ctx, 64, 48, 3, &sharp), DRIFT_OK);
    memcpy(sharp.pixels, test_rig_plane(&r, "reflections")->pixels, sizeof(float) * 3 * 64 * 48);
    test_rig_frame(&r, &(drift_hybrid_params){ .reflections = DRIFT_REFLECTIONS_ISG });
    const drift_image *isg = test_rig_plane(&r, "reflections");
    double sum = 0.0;
    for (size_t i = 0; i < 3u * 64u * 48u; ++i) {
        double d = (double)isg->pixels[i] - (double)sharp.pixels[i];
        assert_false(isnan(d));
        sum += d * d;
    }
    drift_image_destroy(r.ctx, &sharp);
    test_rig_destroy(&r);
    return sqrt(sum / (3.0 * 64.0 * 48.0));
}

static void test_narrow_lobe_gives_sharp_reflection(void **state)
{
    (void)state;
    double wide = reflection_difference(50.0f);
    double narrow = reflection_difference(2000.0f);
    double mirror_like = reflection_difference(1e7f);
    print_message("reflection rms vs sharp: n=50 %.5f, n=2000 %.5f, n=1e7 %.5f\n", wide, narrow,
                  mirror_like);
    assert_true(wide > 0.0);
    assert_true(narrow < wide);
    assert_true(mirror_like == 0.0);
}

static void test_gloss_support_eq13(void **state)
{
    (void)state;
    // tan alpha = E tan theta / (e + E): E = e halves tan theta; E -> infinity gives theta.
    assert_near(tan((double)drift_isg_gloss_alpha(0.3f, 2.0f, 2.0f)), 0.5 * tan(0.3), 1e-6);
    assert_near(drift_isg_gloss_alpha(0.3f, 2.0f, INFINITY), 0.3, 1e-6);
    assert_near(drift_isg_gloss_alpha(0.0f, 2.0f, 1.0f), 0.0, 0.0);
    // Eq. 8, and no penumbra without an occluder.
    assert_near(drift_isg_penumbra(0.5f, 1.0f, 3.0f), 0.25, 1e-6);
    assert_near(drift_isg_penumbra(0.5f, INFINITY, 3.0f), 0.0, 0.0);
}

// At a grazing view of a Phong-100 floor the gather's support is about eq. 13's alpha on screen,
// not alpha cos(theta_incident) (eq. 14, for half-vector lobes): drift's Phong lobe is a cone
// about the mirror direction, which a flat reflector shows undistorted. With the cosine the
// floor of the open glossy room under-blurred about 5x (issue 17).
static void test_gloss_support_at_grazing_view(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    const float exponent = 100.0f;
    uint32_t floor =
        test_add_material(r.scene, (drift_material){ .diffuse = { 0.2f, 0.2f, 0.2f },
                                                     .specular = { 0.6f, 0.6f, 0.6f },
                                                     .exponent = exponent,
                                                     .diffuse_texture = DRIFT_INVALID_INDEX });
    uint32_t red =
        test_add_material(r.scene, drift_material_make(drift_vec3_make(0.8f, 0.1f, 0.1f)));
    add_rect(r.scene, -5.0f, 5.0f, -5.0f, 5.0f, 0.0f, floor);
    const float p[] = { -5.0f, 0.0f, 2.0f, 5.0f, 0.0f, 2.0f, 5.0f, 3.0f, 2.0f, -5.0f, 3.0f, 2.0f };
    const uint32_t idx[] = { 0, 1, 2, 0, 2, 3 };
    test_add_mesh(r.scene, p, 4, idx, 2, red); // a wall across the view, behind the floor
    assert_int_equal(drift_scene_add_light(r.scene,
                                           &(drift_light){ .type = DRIFT_LIGHT_POINT,
                                                           .position = { 0.0f, 3.0f, -2.0f },
                                                           .color = { 20, 20, 20 } },
                                           NULL),
                     DRIFT_OK);
    drift_camera *c = &r.scene->camera;
    *c = drift_camera_look_at(drift_vec3_make(0.0f, 0.5f, -3.0f), drift_vec3_make(0.0f, 0.2f, 2.0f),
                              drift_vec3_make(0.0f, 1.0f, 0.0f), 0.8f, 64, 48);
    test_rig_commit(&r);
    test_rig_frame(&r, &(drift_hybrid_params){ .reflections = DRIFT_REFLECTIONS_ISG });
    const drift_image *search = test_rig_plane(&r, "isg.reflection");
    double theta = acos(pow(0.1, 1.0 / ((double)exponent + 1.0))); // 90% of the Phong lobe
    double fov_x = 2.0 * atan(tan(0.5 * (double)c->fov_y) * 64.0 / 48.0);
    double scale = fmax(64.0 / fov_x, 48.0 / (double)c->fov_y);
    int checked = 0;
    for (int32_t y = 30; y < 48; y += 4) {
        int32_t x = 32;
        float reflected = drift_image_pixel(search, x, y)[0];
        float radius = drift_image_pixel(search, x, y)[1];
        // The floor point the pixel sees, and its eye distance.
        drift_ray ray = drift_camera_ray(c, 64, 48, (float)x + 0.5f, (float)y + 0.5f,
                                         drift_vec2_make(0.5f, 0.5f));
        if (!isfinite(reflected) || !(ray.dir.y < 0.0f)) {
            continue;
        }
        float t = -ray.origin.y / ray.dir.y;
        drift_vec3 p0 = drift_vec3_fma(ray.origin, ray.dir, t);
        float cos_incident = -ray.dir.y;
        double alpha = (double)drift_isg_gloss_alpha(
            (float)theta, drift_vec3_length(drift_vec3_sub(c->position, p0)), reflected);
        print_message("y %d: cos_i %.3f, radius %.3f px, eq. 13 %.3f px\n", y, (double)cos_incident,
                      (double)radius, alpha * scale);
        assert_true(cos_incident < 0.5f); // grazing
        // Within 15%: the gather's support is now the cone over the rate at which the
        // reflected points turn per pixel, measured on the G-buffer (isg_reflections.c), which
        // also sees the eye distance change from pixel to pixel at grazing view; eq. 13 takes
        // e as constant. The cosine of eq. 14 would make it 0.17-0.45x.
        assert_near((double)radius, alpha * scale, 0.15 * alpha * scale);
        ++checked;
    }
    assert_true(checked >= 3);
    test_rig_destroy(&r);
}

// --- DEPTH OF FIELD ---

// A far white wall and a near dark quad over half the view, evenly lit.
static void build_dof(test_rig *r, float aperture)
{
    uint32_t white = test_add_material(r->scene, drift_material_make(drift_vec3_splat(0.8f)));
    uint32_t dark =
        test_add_material(r->scene, drift_material_make(drift_vec3_make(0.05f, 0.05f, 0.4f)));
    const float wall[] = { -20, -20, 10, 20, -20, 10, 20, 20, 10, -20, 20, 10 };
    const float near[] = { -5, -5, 2, 0, -5, 2, 0, 5, 2, -5, 5, 2 };
    const uint32_t idx[] = { 0, 2, 1, 0, 3, 2 };
    test_add_mesh(r->scene, wall, 4, idx, 2, white);
    test_add_mesh(r->scene, near, 4, idx, 2, dark);
    assert_int_equal(drift_scene_add_light(r->scene,
                                           &(drift_light){ .type = DRIFT_LIGHT_DIRECTIONAL,
                                                           .direction = { 0.0f, 0.0f, 1.0f },
                                                           .color = { 3, 3, 3 } },
                                           NULL),
                     DRIFT_OK);
    r->scene->camera =
        drift_camera_look_at(drift_vec3_make(0, 0, -0.001f), drift_vec3_make(0, 0, 10),
                             drift_vec3_make(0, 1, 0), 0.9f, 64, 48);
    r->scene->camera.aperture_radius = aperture;
    r->scene->camera.focus_distance = 10.0f;
}

static void test_zero_aperture_dof_is_identity(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    build_dof(&r, 0.0f);
    test_rig_commit(&r);
    test_rig_frame(&r, &(drift_hybrid_params){ .dof = DRIFT_DOF_ISG });
    assert_memory_equal(test_rig_plane(&r, "focus")->pixels, test_rig_plane(&r, "final")->pixels,
                        sizeof(float) * 3 * 64 * 48);
    r.scene->camera.aperture_radius = 0.5f;
    test_rig_frame(&r, &(drift_hybrid_params){ .dof = DRIFT_DOF_ISG });
    assert_true(memcmp(test_rig_plane(&r, "focus")->pixels, test_rig_plane(&r, "final")->pixels,
                       sizeof(float) * 3 * 64 * 48) != 0);
    test_rig_destroy(&r);
}

// The blurred near quad (one side) spreads over the in-focus wall (right of the edge), and the
// wall far from the edge stays sharp.
// Focus on the near quad and blur the wall: the in-focus quad must not bleed onto the blurred
// wall beside it (nor with post DOF, whose taps are weighed by their own circle since issue 17;
// before, its error there was 0.37).
static void test_dof_in_focus_foreground_does_not_bleed(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    build_dof(&r, 0.5f);
    r.scene->camera.focus_distance = 2.0f;
    test_rig_commit(&r);
    const drift_gbuffer *g = NULL;
    int y = 24, edge = -1;
    float isg_err = 0.0f, post_err = 0.0f;
    for (int pass = 0; pass < 2; ++pass) {
        test_rig_frame(&r, &(drift_hybrid_params){ .dof = pass ? DRIFT_DOF_POST : DRIFT_DOF_ISG,
                                                   .isg.search = 81,
                                                   .isg.gather = 81 });
        g = drift_hybrid_gbuffer(r.frame);
        for (int x = 1; x < 64 && edge < 0; ++x) {
            if (fabsf(drift_image_pixel(&g->depth, x - 1, y)[0] -
                      drift_image_pixel(&g->depth, x, y)[0]) > 1.0f) {
                edge = x;
            }
        }
        assert_true(edge > 4 && edge < 60);
        int side = drift_image_pixel(&g->depth, edge, y)[0] > 5.0f ? 1 : -1;
        int wall = edge + 2 * side;
        float in_focus = drift_image_get3(test_rig_plane(&r, "focus"), wall + 6 * side, y).x;
        float got = drift_image_get3(test_rig_plane(&r, "final"), wall, y).x;
        *(pass ? &post_err : &isg_err) = fabsf(got - in_focus) / in_focus;
    }
    print_message("wall beside an in-focus quad: isg error %.4f, post %.4f\n", (double)isg_err,
                  (double)post_err);
    assert_true(isg_err < 0.05f);
    assert_true(post_err < 0.05f);
    test_rig_destroy(&r);
}

static void test_dof_foreground_spreads(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    build_dof(&r, 0.5f);
    test_rig_commit(&r);
    test_rig_frame(
        &r, &(drift_hybrid_params){ .dof = DRIFT_DOF_ISG, .isg.search = 81, .isg.gather = 81 });
    const drift_image *focus = test_rig_plane(&r, "focus"), *final = test_rig_plane(&r, "final");
    const drift_image *coc = test_rig_plane(&r, "coc");
    const drift_gbuffer *g = drift_hybrid_gbuffer(r.frame);
    // Find the edge in the middle row: the first wall pixel after a near-quad pixel.
    int y = 24, edge = -1;
    for (int x = 1; x < 64 && edge < 0; ++x) {
        float z0 = drift_image_pixel(&g->depth, x - 1, y)[0],
              z1 = drift_image_pixel(&g->depth, x, y)[0];
        if (fabsf(z0 - z1) > 1.0f) {
            edge = x;
        }
    }
    assert_true(edge > 4 && edge < 60);
    bool wall_right = drift_image_pixel(&g->depth, edge, y)[0] > 5.0f;
    int side = wall_right ? 1 : -1;
    float c_near = drift_image_pixel(coc, edge - side, y)[0];
    assert_true(c_near > 3.0f);
    // One pixel into the wall: mixed with the near quad's blur spreading over it.
    drift_vec3 in_focus = drift_image_get3(focus, edge + side, y);
    drift_vec3 blurred = drift_image_get3(final, edge + side, y);
    print_message("edge %d side %d c_near %.2f wall %.4f -> %.4f (search radius %.2f)\n", edge,
                  side, (double)c_near, (double)in_focus.x, (double)blurred.x,
                  (double)drift_image_pixel(test_rig_plane(&r, "isg.dof"), edge + side, y)[0]);
    // Pulled toward the near quad's colour by at least a tenth of the way.
    float near_colour = drift_image_get3(focus, edge - 4 * side, y).x;
    assert_true(fabsf(blurred.x - near_colour) < 0.9f * fabsf(in_focus.x - near_colour));
    // Far from the edge the wall (CoC 0) is untouched.
    int far = wall_right ? 62 : 1;
    drift_vec3 a = drift_image_get3(focus, far, y), b = drift_image_get3(final, far, y);
    assert_near(a.x, b.x, 1e-6 * (double)a.x);
    test_rig_destroy(&r);
}

// Post DOF's shared-tap tiles (the default) against the lens. build_dof's near quad before a
// wall that recedes from 6 to 28 m across the view (circles that vary within the tiles), under
// a point light (shading that varies over every tile: flat tiles are copied by both paths). The
// lens's own blur is the path tracer's frame through the lens less its frame through a pinhole;
// the pass's is its frame less the focused frame: the rms of their difference (lighting apart)
// with shared taps is no larger than per pixel, to 15% and 1e-3 (the two are one model; their
// small differences go either way), with the near quad blurred (focus at 10 m: circles of 0 to
// 1.7 px on the wall, 10 on the quad) and with the wall blurred (focus on the quad: 8 to 11.5
// px). Printed beside it, the lens's blur itself (the error of no pass at all): the one-layer
// gather hardly beats it with the quad blurred (the quad's rim stays sharp over the in-focus
// wall) and not at all with the wall blurred (the smooth wall hardly changes; the error is at
// the quad's edge), so the bound is relative.
static void test_post_dof_shared_tiles_match_the_lens_as_per_pixel_does(void **state)
{
    (void)state;
    const float focus[] = { 10.0f, 2.0f };
    const int32_t count = 3 * 64 * 48;
    uint32_t spp = (uint32_t)(256.0 * test_intensity());
    for (int f = 0; f < 2; ++f) {
        test_rig r = test_rig_begin(2);
        uint32_t white = test_add_material(r.scene, drift_material_make(drift_vec3_splat(0.8f)));
        uint32_t dark =
            test_add_material(r.scene, drift_material_make(drift_vec3_make(0.05f, 0.05f, 0.4f)));
        const float wall[] = { -6, -20, 4, 20, -20, 30, 20, 20, 30, -6, 20, 4 }; // z = 10 + x
        const float near[] = { -5, -5, 2, 0, -5, 2, 0, 5, 2, -5, 5, 2 };
        const uint32_t idx[] = { 0, 2, 1, 0, 3, 2 };
        test_add_mesh(r.scene, wall, 4, idx, 2, white);
        test_add_mesh(r.scene, near, 4, idx, 2, dark);
        assert_int_equal(drift_scene_add_light(r.scene,
                                               &(drift_light){ .type = DRIFT_LIGHT_POINT,
                                                               .position = { 2.0f, 2.0f, 1.0f },
                                                               .color = { 40.0f, 40.0f, 40.0f } },
                                               NULL),
                         DRIFT_OK);
        r.scene->camera =
            drift_camera_look_at(drift_vec3_make(0, 0, -0.001f), drift_vec3_make(0, 0, 10),
                                 drift_vec3_make(0, 1, 0), 0.9f, 64, 48);
        r.scene->camera.focus_distance = focus[f];
        test_rig_commit(&r);
        float *lens = malloc(sizeof(float) * (size_t)count * 4), *pinhole = lens + count;
        float *passes[2] = { lens + 2 * count, lens + 3 * count }; // shared, per pixel
        assert_non_null(lens);
        test_rig_frame(&r, &(drift_hybrid_params){ .dof = DRIFT_DOF_REFERENCE, .spp = spp });
        memcpy(pinhole, test_rig_plane(&r, "final")->pixels, sizeof(float) * (size_t)count);
        r.scene->camera.aperture_radius = 0.5f;
        test_rig_commit(&r);
        test_rig_frame(&r, &(drift_hybrid_params){ .dof = DRIFT_DOF_REFERENCE, .spp = spp });
        memcpy(lens, test_rig_plane(&r, "final")->pixels, sizeof(float) * (size_t)count);
        double err[2], apart = 0.0;
        for (int per_pixel = 0; per_pixel < 2; ++per_pixel) {
            test_rig_frame(&r, &(drift_hybrid_params){ .dof = DRIFT_DOF_POST,
                                                       .post_dof.per_pixel = per_pixel });
            const float *final = test_rig_plane(&r, "final")->pixels;
            const float *focused = test_rig_plane(&r, "focus")->pixels;
            double sum = 0.0;
            for (int32_t i = 0; i < count; ++i) {
                double d = ((double) final[i] - (double)focused[i]) -
                           ((double)lens[i] - (double)pinhole[i]);
                sum += d * d;
                passes[per_pixel][i] = final[i];
            }
            err[per_pixel] = sqrt(sum / (double)count);
        }
        double blur = 0.0; // the lens's blur itself: the error of no pass at all
        for (int32_t i = 0; i < count; ++i) {
            apart = fmax(apart, fabs((double)passes[0][i] - (double)passes[1][i]));
            blur += ((double)lens[i] - (double)pinhole[i]) * ((double)lens[i] - (double)pinhole[i]);
        }
        blur = sqrt(blur / (double)count);
        print_message("post DOF's blur against the lens's, focus %g: rms %.4f with shared "
                      "tiles, %.4f per pixel (the two %.3g apart at most; the blur %.4f)\n",
                      (double)focus[f], err[0], err[1], apart, blur);
        assert_true(apart > 1e-4); // the shared path ran
        assert_true(err[0] <= 1.15 * err[1] + 1e-3);
        free(lens);
        test_rig_destroy(&r);
    }
}

// A thin near bar, blurred, in front of an in-focus wall with a red stripe hidden behind the
// bar: the lens sees the stripe through the blurred bar, the one-layer gather cannot.
static double bar_error(int layers, const drift_image *reference, test_rig *r)
{
    test_rig_frame(
        r, &(drift_hybrid_params){
               .dof = DRIFT_DOF_ISG, .isg.search = 49, .isg.gather = 81, .isg.layers = layers });
    const drift_gbuffer *g = drift_hybrid_gbuffer(r->frame);
    const drift_image *final = test_rig_plane(r, "final");
    double sum = 0.0;
    int n = 0;
    for (int y = 8; y < 40; ++y) {
        for (int x = 0; x < 64; ++x) {
            if (drift_image_pixel(&g->depth, x, y)[0] > 3.0f) {
                continue; // the bar's pixels only
            }
            for (int c = 0; c < 3; ++c) {
                double d = (double)drift_image_pixel(final, x, y)[c] -
                           (double)drift_image_pixel(reference, x, y)[c];
                sum += d * d;
            }
            ++n;
        }
    }
    assert_true(n > 100);
    return sqrt(sum / (3.0 * n));
}

static void test_second_layer_sees_behind_blurred_bar(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    uint32_t white = test_add_material(r.scene, drift_material_make(drift_vec3_splat(0.8f)));
    uint32_t red =
        test_add_material(r.scene, drift_material_make(drift_vec3_make(0.9f, 0.05f, 0.05f)));
    uint32_t dark = test_add_material(r.scene, drift_material_make(drift_vec3_splat(0.05f)));
    const uint32_t idx[] = { 0, 2, 1, 0, 3, 2 };
    const float wall[] = { -20, -20, 10, 20, -20, 10, 20, 20, 10, -20, 20, 10 };
    const float stripe[] = {
        -0.5f, -20, 9.99f, 0.5f, -20, 9.99f, 0.5f, 20, 9.99f, -0.5f, 20, 9.99f
    };
    const float bar[] = { -0.15f, -5, 2, 0.15f, -5, 2, 0.15f, 5, 2, -0.15f, 5, 2 };
    test_add_mesh(r.scene, wall, 4, idx, 2, white);
    test_add_mesh(r.scene, stripe, 4, idx, 2, red);
    test_add_mesh(r.scene, bar, 4, idx, 2, dark);
    assert_int_equal(drift_scene_add_light(r.scene,
                                           &(drift_light){ .type = DRIFT_LIGHT_DIRECTIONAL,
                                                           .direction = { 0.45f, 0.0f, 0.89f },
                                                           .color = { 3, 3, 3 } },
                                           NULL),
                     DRIFT_OK);
    r.scene->camera =
        drift_camera_look_at(drift_vec3_make(0, 0, -0.001f), drift_vec3_make(0, 0, 10),
                             drift_vec3_make(0, 1, 0), 0.9f, 64, 48);
    r.scene->camera.aperture_radius = 0.3f;
    r.scene->camera.focus_distance = 10.0f;
    test_rig_commit(&r);
    uint32_t spp = (uint32_t)(128.0 * test_intensity());
    test_rig_frame(&r, &(drift_hybrid_params){ .dof = DRIFT_DOF_REFERENCE, .spp = spp });
    drift_image reference;
    assert_int_equal(drift_image_create(r.ctx, 64, 48, 3, &reference), DRIFT_OK);
    memcpy(reference.pixels, test_rig_plane(&r, "final")->pixels, sizeof(float) * 3 * 64 * 48);
    double one = bar_error(1, &reference, &r), two = bar_error(2, &reference, &r);
    print_message("DOF rms error over the blurred bar: 1 layer %.4f, 2 layers %.4f\n", one, two);
    assert_true(two < 0.8 * one);
    drift_image_destroy(r.ctx, &reference);
    test_rig_destroy(&r);
}

static void test_rejects_bad_counts(void **state)
{
    (void)state;
    assert_true(drift_isg_count_valid(9) && drift_isg_count_valid(81) && drift_isg_count_valid(1));
    assert_false(drift_isg_count_valid(10) || drift_isg_count_valid(0) ||
                 drift_isg_count_valid(1025));
    test_rig r = test_rig_begin(2);
    build_occluder(&r, 1.0f, 0.5f);
    test_rig_commit(&r);
    assert_int_equal(drift_hybrid_create(r.ctx, r.scene, r.accel,
                                         &(drift_hybrid_params){ .isg.search = 10 }, &r.frame),
                     DRIFT_ERR_INVALID_ARGUMENT);
    assert_null(r.frame);
    assert_int_equal(drift_technique_parse(DRIFT_EFFECT_SHADOWS, "isg"), DRIFT_SHADOWS_ISG);
    assert_int_equal(drift_technique_parse(DRIFT_EFFECT_REFLECTIONS, "isg"), DRIFT_REFLECTIONS_ISG);
    assert_int_equal(drift_technique_parse(DRIFT_EFFECT_DOF, "isg"), DRIFT_DOF_ISG);
    assert_string_equal(drift_hybrid_pass_name(DRIFT_PASS_ISG), "isg");
    test_rig_destroy(&r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_contact_hardening_follows_eq8),
        cmocka_unit_test(test_point_like_light_gives_hard_shadow),
        cmocka_unit_test(test_each_light_gathers_its_own_shadow),
        cmocka_unit_test(test_narrow_lobe_gives_sharp_reflection),
        cmocka_unit_test(test_gloss_support_eq13),
        cmocka_unit_test(test_gloss_support_at_grazing_view),
        cmocka_unit_test(test_zero_aperture_dof_is_identity),
        cmocka_unit_test(test_dof_foreground_spreads),
        cmocka_unit_test(test_dof_in_focus_foreground_does_not_bleed),
        cmocka_unit_test(test_post_dof_shared_tiles_match_the_lens_as_per_pixel_does),
        cmocka_unit_test(test_second_layer_sees_behind_blurred_bar),
        cmocka_unit_test(test_rejects_bad_counts),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
