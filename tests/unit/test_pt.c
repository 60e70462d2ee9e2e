// Reference path tracer against closed forms and invariants: white furnace, a plane under
// a constant sky, irradiance from sphere and disk lights, thin lens vs pinhole, bit-identical
// images for any thread count, and 1/sqrt(spp) convergence.
#include "drift_test.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "drift/accel.h"
#include "drift/pt.h"
#include "drift/scene.h"

#define M_PI 3.14159265358979323846

typedef struct rig {
    drift_context *ctx;
    drift_scene *scene;
    drift_accel *accel;
    drift_pt *pt;
} rig;

static void rig_finish(rig *r, const drift_pt_params *params)
{
    assert_int_equal(drift_scene_commit(r->scene), DRIFT_OK);
    assert_int_equal(drift_accel_create(r->ctx, r->scene, &(drift_accel_desc){ 0 }, &r->accel),
                     DRIFT_OK);
    assert_int_equal(drift_pt_create(r->ctx, r->scene, r->accel, params, &r->pt), DRIFT_OK);
}

static void rig_destroy(rig *r)
{
    drift_pt_destroy(r->pt);
    drift_accel_destroy(r->accel);
    drift_scene_destroy(r->scene);
    drift_context_destroy(r->ctx);
}

static rig rig_begin(int threads)
{
    rig r = { .ctx = test_context(threads, NULL) };
    assert_int_equal(drift_scene_create(r.ctx, &r.scene), DRIFT_OK);
    return r;
}

// Axis-aligned box [-h, h]^3 with triangles facing inward.
static void add_inward_box(drift_scene *scene, float h, uint32_t material)
{
    const float p[] = { -h, -h, -h, h, -h, -h, h, h, -h, -h, h, -h,
                        -h, -h, h,  h, -h, h,  h, h, h,  -h, h, h };
    // Each face wound so that its normal points into the box.
    const uint32_t idx[] = { 0, 1, 2, 0, 2, 3, 4, 7, 6, 4, 6, 5, 0, 4, 5, 0, 5, 1,
                             3, 2, 6, 3, 6, 7, 0, 3, 7, 0, 7, 4, 1, 5, 6, 1, 6, 2 };
    test_add_mesh(scene, p, 8, idx, 12, material);
}

static void add_floor(drift_scene *scene, float half, uint32_t material)
{
    const float p[] = { -half, 0, -half, half, 0, -half, half, 0, half, -half, 0, half };
    const uint32_t idx[] = { 0, 2, 1, 0, 3, 2 }; // normal +y
    test_add_mesh(scene, p, 4, idx, 2, material);
}

static double image_mean(const drift_image *img, int channel)
{
    double sum = 0.0;
    for (int y = 0; y < img->height; ++y) {
        for (int x = 0; x < img->width; ++x) {
            sum += (double)drift_image_pixel(img, x, y)[channel];
        }
    }
    return sum / ((double)img->width * img->height);
}

static drift_image render(rig *r, uint32_t spp)
{
    assert_int_equal(drift_pt_render_samples(r->pt, spp, NULL), DRIFT_OK);
    drift_image img;
    assert_int_equal(drift_pt_resolve(r->pt, DRIFT_PT_AOV_BEAUTY, &img), DRIFT_OK);
    assert_int_equal(drift_pt_get_stats(r->pt).nan_samples, 0);
    return img;
}

// --- CLOSED FORMS ---

// A closed enclosure with albedo a whose walls all emit Le has radiance Le / (1 - a)
// everywhere; each estimator (MIS, NEE only, BSDF sampling only) must reproduce it.
static void test_pt_white_furnace(void **state)
{
    (void)state;
    const float albedo = 0.5f, le = 1.0f;
    const drift_pt_params variants[] = {
        { .width = 16, .height = 16, .max_depth = 64 },
        { .width = 16, .height = 16, .max_depth = 64, .disable_mis = true },
        { .width = 16, .height = 16, .max_depth = 64, .disable_nee = true },
    };
    for (int v = 0; v < 3; ++v) {
        rig r = rig_begin(2);
        drift_material m = drift_material_make(drift_vec3_splat(albedo));
        m.emission = drift_vec3_splat(le);
        uint32_t mat;
        assert_int_equal(drift_scene_add_material(r.scene, &m, &mat), DRIFT_OK);
        add_inward_box(r.scene, 1.0f, mat);
        r.scene->camera = drift_camera_look_at(drift_vec3_make(0, 0, 0.5f), drift_vec3_make(0.2f, 0.1f, -1),
                                               drift_vec3_make(0, 1, 0), 1.2f, 16, 16);
        rig_finish(&r, &variants[v]);
        drift_image img = render(&r, (uint32_t)(64 * test_intensity()));
        double mean = image_mean(&img, 1);
        double expected = (double)le / (1.0 - (double)albedo);
        if (fabs(mean - expected) > 0.02 * expected) {
            fail_msg("furnace variant %d: mean radiance %.4f, expected %.4f", v, mean, expected);
        }
        rig_destroy(&r);
    }
}

// An infinite-looking diffuse plane under a constant sky: L = albedo * sky.
static void test_pt_plane_under_constant_environment(void **state)
{
    (void)state;
    const float albedo = 0.6f, sky = 0.5f;
    rig r = rig_begin(2);
    uint32_t mat;
    assert_int_equal(drift_scene_add_material(r.scene, &(drift_material){ .diffuse = drift_vec3_splat(albedo),
                                                                          .diffuse_texture = DRIFT_INVALID_INDEX },
                                              &mat),
                     DRIFT_OK);
    add_floor(r.scene, 1e4f, mat);
    r.scene->environment = (drift_environment){ .color = drift_vec3_splat(sky),
                                                .texture = DRIFT_INVALID_INDEX };
    r.scene->camera = drift_camera_look_at(drift_vec3_make(0, 1, 0), drift_vec3_make(0, 0, -0.01f),
                                           drift_vec3_make(0, 0, -1), 0.5f, 8, 8);
    rig_finish(&r, &(drift_pt_params){ .max_depth = 4 });
    drift_image img = render(&r, (uint32_t)(256 * test_intensity()));
    double expected = (double)(albedo * sky);
    for (int c = 0; c < 3; ++c) {
        double mean = image_mean(&img, c);
        if (fabs(mean - expected) > 0.01 * expected) {
            fail_msg("plane radiance %.5f, expected %.5f", mean, expected);
        }
    }
    rig_destroy(&r);
}

// Radiance of a diffuse plane at the point below an area light, seen through a narrow
// camera: L = albedo / pi * E with E in closed form.
static double render_point_below_light(const drift_light *light, float albedo)
{
    rig r = rig_begin(2);
    uint32_t mat;
    assert_int_equal(drift_scene_add_material(r.scene, &(drift_material){ .diffuse = drift_vec3_splat(albedo),
                                                                          .diffuse_texture = DRIFT_INVALID_INDEX },
                                              &mat),
                     DRIFT_OK);
    add_floor(r.scene, 100.0f, mat);
    assert_int_equal(drift_scene_add_light(r.scene, light, NULL), DRIFT_OK);
    // Look at the origin from the side, below the light, with a 0.2 degree field of view.
    r.scene->camera = drift_camera_look_at(drift_vec3_make(5, 0.5f, 0), drift_vec3_make(0, 0, 0),
                                           drift_vec3_make(0, 1, 0), 0.0035f, 3, 3);
    rig_finish(&r, &(drift_pt_params){ .max_depth = 1 });
    drift_image img = render(&r, (uint32_t)(1024 * test_intensity()));
    double value = (double)drift_image_pixel(&img, 1, 1)[0];
    rig_destroy(&r);
    return value;
}

static void test_pt_sphere_light_irradiance(void **state)
{
    (void)state;
    const double radius = 0.5, height = 2.0, radiance = 4.0, albedo = 0.5;
    drift_light l = { .type = DRIFT_LIGHT_SPHERE,
                      .position = { 0, (float)height, 0 },
                      .radius = (float)radius,
                      .color = drift_vec3_splat((float)radiance) };
    double expected = albedo / M_PI * (M_PI * radiance * (radius / height) * (radius / height));
    double got = render_point_below_light(&l, (float)albedo);
    if (fabs(got - expected) > 0.01 * expected) {
        fail_msg("sphere light: radiance %.5f, closed form %.5f", got, expected);
    }
}

static void test_pt_disk_light_irradiance(void **state)
{
    (void)state;
    const double radius = 1.0, height = 2.0, radiance = 3.0, albedo = 0.8;
    drift_light l = { .type = DRIFT_LIGHT_DISK,
                      .position = { 0, (float)height, 0 },
                      .direction = { 0, -1, 0 },
                      .radius = (float)radius,
                      .color = drift_vec3_splat((float)radiance) };
    double expected = albedo / M_PI * (M_PI * radiance * radius * radius / (height * height + radius * radius));
    double got = render_point_below_light(&l, (float)albedo);
    if (fabs(got - expected) > 0.01 * expected) {
        fail_msg("disk light: radiance %.5f, closed form %.5f", got, expected);
    }
}

// --- CAMERA ---

static void test_pt_thin_lens_focuses_on_the_focus_plane(void **state)
{
    (void)state;
    drift_camera cam = drift_camera_look_at(drift_vec3_make(0, 0, 5), drift_vec3_make(0, 0, 0),
                                            drift_vec3_make(0, 1, 0), 0.7f, 64, 48);
    drift_camera lens = cam;
    lens.aperture_radius = 0.3f;
    lens.focus_distance = 4.0f;
    for (int i = 0; i < 50; ++i) {
        float fx = 3.5f + (float)i, fy = 40.0f - 0.5f * (float)i;
        drift_ray pin = drift_camera_ray(&cam, 64, 48, fx, fy, drift_vec2_make(0.5f, 0.5f));
        // Zero aperture ignores the lens sample: identical rays.
        drift_ray pin2 = drift_camera_ray(&cam, 64, 48, fx, fy, drift_vec2_make(0.1f, 0.9f));
        assert_memory_equal(&pin, &pin2, sizeof(pin));
        // Every lens ray passes through the pinhole ray's point on the focus plane.
        float t_focus = 4.0f / pin.dir.z * -1.0f;
        drift_vec3 focus = drift_vec3_fma(pin.origin, pin.dir, t_focus);
        drift_ray thin = drift_camera_ray(&lens, 64, 48, fx, fy, drift_vec2_make(0.9f, 0.2f));
        float t = (focus.z - thin.origin.z) / thin.dir.z;
        drift_vec3 at = drift_vec3_fma(thin.origin, thin.dir, t);
        assert_true(drift_vec3_length(drift_vec3_sub(at, focus)) < 1e-4f);
        assert_true(drift_vec3_length(drift_vec3_sub(thin.origin, pin.origin)) > 1e-3f);
    }
}

static drift_scene *small_box_scene(rig *r, float aperture)
{
    drift_material white = drift_material_make(drift_vec3_splat(0.7f));
    drift_material red = drift_material_make(drift_vec3_make(0.7f, 0.1f, 0.1f));
    drift_material glossy = drift_material_make(drift_vec3_splat(0.2f));
    glossy.specular = drift_vec3_splat(0.6f);
    glossy.exponent = 40.0f;
    uint32_t w, rd, g;
    assert_int_equal(drift_scene_add_material(r->scene, &white, &w), DRIFT_OK);
    assert_int_equal(drift_scene_add_material(r->scene, &red, &rd), DRIFT_OK);
    assert_int_equal(drift_scene_add_material(r->scene, &glossy, &g), DRIFT_OK);
    add_inward_box(r->scene, 1.0f, w);
    const float p[] = { -0.4f, -0.99f, -0.4f, 0.4f, -0.99f, -0.4f, 0.0f, -0.2f, 0.0f };
    const uint32_t idx[] = { 0, 1, 2 };
    test_add_mesh(r->scene, p, 3, idx, 1, g);
    const float q[] = { -0.99f, -1, -1, -0.99f, -1, 1, -0.99f, 1, 1 };
    test_add_mesh(r->scene, q, 3, idx, 1, rd);
    assert_int_equal(drift_scene_add_light(r->scene,
                                           &(drift_light){ .type = DRIFT_LIGHT_QUAD,
                                                           .position = { -0.3f, 0.98f, -0.3f },
                                                           .edge_u = { 0.6f, 0, 0 },
                                                           .edge_v = { 0, 0, 0.6f },
                                                           .color = { 8, 8, 8 } },
                                           NULL),
                     DRIFT_OK);
    r->scene->camera = drift_camera_look_at(drift_vec3_make(0, 0, 0.95f), drift_vec3_make(0, -0.2f, 0),
                                            drift_vec3_make(0, 1, 0), 1.4f, 24, 24);
    r->scene->camera.aperture_radius = aperture;
    return r->scene;
}

static void test_pt_zero_aperture_equals_pinhole(void **state)
{
    (void)state;
    drift_image images[2];
    rig rigs[2];
    for (int i = 0; i < 2; ++i) {
        rigs[i] = rig_begin(2);
        // A lens far smaller than a pixel's footprint is a pinhole in all but rounding.
        small_box_scene(&rigs[i], i == 0 ? 0.0f : 1e-7f);
        rig_finish(&rigs[i], &(drift_pt_params){ .seed = 3 });
        images[i] = render(&rigs[i], 16);
    }
    double diff = 0.0, mean = image_mean(&images[0], 0);
    for (int y = 0; y < 24; ++y) {
        for (int x = 0; x < 24; ++x) {
            diff += fabs((double)(drift_image_pixel(&images[0], x, y)[0] -
                                  drift_image_pixel(&images[1], x, y)[0]));
        }
    }
    diff /= 24.0 * 24.0;
    assert_true(diff < 1e-3 * mean);
    rig_destroy(&rigs[0]);
    rig_destroy(&rigs[1]);
}

// --- INVARIANTS ---

static void test_pt_bit_identical_for_any_thread_count(void **state)
{
    (void)state;
    const int thread_counts[] = { 1, 2, 5 };
    float *first = NULL;
    size_t bytes = 24 * 24 * 3 * sizeof(float);
    for (int i = 0; i < 3; ++i) {
        rig r = rig_begin(thread_counts[i]);
        small_box_scene(&r, 0.02f);
        rig_finish(&r, &(drift_pt_params){ .seed = 11 });
        // Two passes of different sizes: the pass split must not matter either.
        assert_int_equal(drift_pt_render_samples(r.pt, (uint32_t)(1 + i), NULL), DRIFT_OK);
        drift_image img = render(&r, (uint32_t)(8 - (1 + i)));
        if (!first) {
            first = test_malloc(bytes);
            memcpy(first, img.pixels, bytes);
        } else {
            assert_memory_equal(first, img.pixels, bytes);
        }
        rig_destroy(&r);
    }
    // A different seed gives a different image (the seed is used).
    rig r = rig_begin(2);
    small_box_scene(&r, 0.02f);
    rig_finish(&r, &(drift_pt_params){ .seed = 12 });
    drift_image img = render(&r, 8);
    assert_true(memcmp(first, img.pixels, bytes) != 0);
    rig_destroy(&r);
    test_free(first);
}

static double rmse(const drift_image *a, const drift_image *b)
{
    double sum = 0.0;
    for (int y = 0; y < a->height; ++y) {
        for (int x = 0; x < a->width; ++x) {
            for (int c = 0; c < 3; ++c) {
                double d = (double)(drift_image_pixel(a, x, y)[c] - drift_image_pixel(b, x, y)[c]);
                sum += d * d;
            }
        }
    }
    return sqrt(sum / (3.0 * a->width * a->height));
}

// RMSE against a high-spp reference falls as 1/sqrt(spp): x16 samples, about /4 error.
static void test_pt_converges_as_inverse_sqrt_spp(void **state)
{
    (void)state;
    rig ref = rig_begin(2);
    small_box_scene(&ref, 0.0f);
    rig_finish(&ref, &(drift_pt_params){ .seed = 1000 });
    drift_image reference = render(&ref, (uint32_t)(2048 * test_intensity()));
    double errors[3];
    const uint32_t spp[3] = { 4, 16, 64 };
    rig r = rig_begin(2);
    small_box_scene(&r, 0.0f);
    rig_finish(&r, &(drift_pt_params){ .seed = 1 });
    uint32_t done = 0;
    for (int i = 0; i < 3; ++i) {
        drift_image img = render(&r, spp[i] - done);
        done = spp[i];
        errors[i] = rmse(&img, &reference);
    }
    double ratio = errors[0] / errors[2];
    if (!(errors[0] > errors[1] && errors[1] > errors[2]) || ratio < 2.5 || ratio > 7.0) {
        fail_msg("RMSE at 4/16/64 spp: %.4f %.4f %.4f (ratio 4->64: %.2f, expected about 4)",
                 errors[0], errors[1], errors[2], ratio);
    }
    rig_destroy(&r);
    rig_destroy(&ref);
}

static void test_pt_cancel_flag_stops_and_reports(void **state)
{
    (void)state;
    rig r = rig_begin(2);
    small_box_scene(&r, 0.0f);
    rig_finish(&r, &(drift_pt_params){ 0 });
    atomic_bool cancel;
    atomic_init(&cancel, true);
    assert_int_equal(drift_pt_render_samples(r.pt, 4, &cancel), DRIFT_ERR_CANCELLED);
    assert_int_equal(drift_pt_sample_count(r.pt), 0);
    rig_destroy(&r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_pt_white_furnace),
        cmocka_unit_test(test_pt_plane_under_constant_environment),
        cmocka_unit_test(test_pt_sphere_light_irradiance),
        cmocka_unit_test(test_pt_disk_light_irradiance),
        cmocka_unit_test(test_pt_thin_lens_focuses_on_the_focus_plane),
        cmocka_unit_test(test_pt_zero_aperture_equals_pinhole),
        cmocka_unit_test(test_pt_bit_identical_for_any_thread_count),
        cmocka_unit_test(test_pt_converges_as_inverse_sqrt_spp),
        cmocka_unit_test(test_pt_cancel_flag_stops_and_reports),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
