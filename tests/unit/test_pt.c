// Reference path tracer against closed forms and invariants: white furnace, a plane under
// a constant sky, irradiance from sphere and disk lights, thin lens vs pinhole, bit-identical
// images for any thread count, 1/sqrt(spp) convergence, and the image split into components
// (emission, direct, specular, diffuse) with pixel-centre, pinhole and camera overrides.
#include "drift/accel.h"
#include "drift/pt.h"
#include "drift/scene.h"
#include "drift_test.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define M_PI 3.14159265358979323846

typedef struct rig {
    drift_context *ctx;
    drift_scene *scene;
    drift_accel *accel;
    drift_pt *pt;
} rig;

// Commits the scene and builds the accel; rig_finish also makes the rig's pt.
static void rig_build(rig *r)
{
    assert_int_equal(drift_scene_commit(r->scene), DRIFT_OK);
    assert_int_equal(drift_accel_create(r->ctx, r->scene, &(drift_accel_desc){ 0 }, &r->accel),
                     DRIFT_OK);
}

static void rig_finish(rig *r, const drift_pt_params *params)
{
    rig_build(r);
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
        r.scene->camera =
            drift_camera_look_at(drift_vec3_make(0, 0, 0.5f), drift_vec3_make(0.2f, 0.1f, -1),
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
    assert_int_equal(
        drift_scene_add_material(r.scene,
                                 &(drift_material){ .diffuse = drift_vec3_splat(albedo),
                                                    .diffuse_texture = DRIFT_INVALID_INDEX },
                                 &mat),
        DRIFT_OK);
    add_floor(r.scene, 1e4f, mat);
    r.scene->environment =
        (drift_environment){ .color = drift_vec3_splat(sky), .texture = DRIFT_INVALID_INDEX };
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
    assert_int_equal(
        drift_scene_add_material(r.scene,
                                 &(drift_material){ .diffuse = drift_vec3_splat(albedo),
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
    double expected =
        albedo / M_PI * (M_PI * radiance * radius * radius / (height * height + radius * radius));
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
    r->scene->camera =
        drift_camera_look_at(drift_vec3_make(0, 0, 0.95f), drift_vec3_make(0, -0.2f, 0),
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

// Tiles rendered one at a time, in reverse order, in uneven pieces, their state moved to a
// second pt and back (what a checkpoint and an MPI rank do), give the bits of one render.
static void test_pt_tiles_moved_between_pts_are_bit_identical(void **state)
{
    (void)state;
    const drift_pt_params params = { .seed = 5, .width = 40, .height = 24 };
    rig whole = rig_begin(2);
    small_box_scene(&whole, 0.02f);
    rig_finish(&whole, &params);
    drift_image expected = render(&whole, 6);

    rig r = rig_begin(1), other = rig_begin(3);
    small_box_scene(&r, 0.02f);
    small_box_scene(&other, 0.02f);
    rig_finish(&r, &params);
    rig_finish(&other, &params);
    uint32_t tiles = drift_pt_tile_count(r.pt);
    assert_int_equal(tiles, 6); // 3 x 2, the right and bottom ones cut
    drift_pt_tile last = drift_pt_tile_rect(r.pt, tiles - 1);
    assert_true(last.x1 == 40 && last.y1 == 24 && last.x1 - last.x0 == 8);
    uint8_t *scratch = test_malloc(drift_pt_tile_state_size(r.pt, 0));
    for (uint32_t t = tiles; t-- > 0;) {
        assert_int_equal(drift_pt_render_tiles(r.pt, &t, 1, 1 + t % 3, 6, NULL), DRIFT_OK);
        assert_int_equal(drift_pt_tile_sample_count(r.pt, t), 1 + t % 3);
        drift_pt_tile_get_state(r.pt, t, scratch);
        drift_pt_tile_set_state(other.pt, t, scratch);
        assert_int_equal(drift_pt_render_tiles(other.pt, &t, 1, 100, 6, NULL), DRIFT_OK);
        drift_pt_tile_get_state(other.pt, t, scratch);
        drift_pt_tile_set_state(r.pt, t, scratch);
    }
    assert_int_equal(drift_pt_sample_count(r.pt), 6);
    drift_image got;
    assert_int_equal(drift_pt_resolve(r.pt, DRIFT_PT_AOV_BEAUTY, &got), DRIFT_OK);
    assert_memory_equal(expected.pixels, got.pixels, 40 * 24 * 3 * sizeof(float));
    uint32_t outside = tiles;
    assert_int_equal(drift_pt_render_tiles(r.pt, &outside, 1, 1, 7, NULL),
                     DRIFT_ERR_INVALID_ARGUMENT);
    test_free(scratch);
    rig_destroy(&other);
    rig_destroy(&r);
    rig_destroy(&whole);
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

// --- COMPONENTS ---

// An image copied out of its pt: channels floats a pixel, rows packed.
typedef struct plain_image {
    int32_t width, height, channels;
    float *v;
} plain_image;

static plain_image plain_copy(const drift_image *img)
{
    plain_image out = { img->width, img->height, img->channels, NULL };
    size_t row = (size_t)img->width * (size_t)img->channels;
    out.v = test_malloc(row * (size_t)img->height * sizeof(float));
    for (int32_t y = 0; y < img->height; ++y) {
        memcpy(out.v + (size_t)y * row, drift_image_pixel(img, 0, y), row * sizeof(float));
    }
    return out;
}

static size_t plain_size(const plain_image *img)
{
    return (size_t)img->width * (size_t)img->height * (size_t)img->channels;
}

static double plain_mean(const plain_image *img)
{
    double sum = 0.0;
    for (size_t i = 0; i < plain_size(img); ++i) {
        sum += (double)img->v[i];
    }
    return sum / (double)plain_size(img);
}

static bool plain_identical(const plain_image *a, const plain_image *b)
{
    return plain_size(a) == plain_size(b) && memcmp(a->v, b->v, plain_size(a) * sizeof(float)) == 0;
}

// Renders `spp` samples of a built rig's scene with `params` (a pt of its own) and copies out
// one AOV.
static plain_image render_aov(rig *r, const drift_pt_params *params, uint32_t spp, drift_pt_aov aov)
{
    drift_pt *pt = NULL;
    assert_int_equal(drift_pt_create(r->ctx, r->scene, r->accel, params, &pt), DRIFT_OK);
    assert_int_equal(drift_pt_render_samples(pt, spp, NULL), DRIFT_OK);
    assert_int_equal(drift_pt_get_stats(pt).nan_samples, 0);
    drift_image img;
    assert_int_equal(drift_pt_resolve(pt, aov, &img), DRIFT_OK);
    plain_image out = plain_copy(&img);
    drift_pt_destroy(pt);
    return out;
}

// small_box_scene (a diffuse + glossy triangle, a quad light on the ceiling) plus an emissive
// triangle the camera sees on the back wall and, with `mirror`, a mirror on the right wall.
static void component_scene(rig *r, bool mirror)
{
    small_box_scene(r, 0.0f);
    drift_material lamp = drift_material_make(drift_vec3_splat(0.0f));
    lamp.emission = drift_vec3_make(3.0f, 2.5f, 2.0f);
    uint32_t l;
    assert_int_equal(drift_scene_add_material(r->scene, &lamp, &l), DRIFT_OK);
    const uint32_t idx[] = { 0, 1, 2 };
    const float lp[] = { -0.7f, 0.3f, -0.98f, -0.2f, 0.3f, -0.98f, -0.45f, 0.7f, -0.98f }; // +z
    test_add_mesh(r->scene, lp, 3, idx, 1, l);
    if (mirror) {
        drift_material m = drift_material_make(drift_vec3_splat(0.0f));
        m.type = DRIFT_MATERIAL_MIRROR;
        m.specular = drift_vec3_splat(0.9f);
        uint32_t mi;
        assert_int_equal(drift_scene_add_material(r->scene, &m, &mi), DRIFT_OK);
        const float mp[] = { 0.99f, -0.6f, -0.9f, 0.99f, -0.6f, 0.2f, 0.99f, 0.6f, -0.35f }; // -x
        test_add_mesh(r->scene, mp, 3, idx, 1, mi);
    }
}

static const uint32_t single_components[4] = { DRIFT_PT_COMPONENT_EMISSION,
                                               DRIFT_PT_COMPONENT_DIRECT,
                                               DRIFT_PT_COMPONENT_SPECULAR,
                                               DRIFT_PT_COMPONENT_DIFFUSE };

// Each path's light goes to exactly one component (the continuing light shared between
// specular and diffuse by the lobes), so the four single-component images sum to the full
// image of the same seed. Counting a contribution twice or dropping one breaks the sum.
static void test_pt_components_sum_to_the_full_image(void **state)
{
    (void)state;
    rig r = rig_begin(2);
    component_scene(&r, true);
    rig_build(&r);
    const uint32_t spp = 8;
    for (int centre = 0; centre < 2; ++centre) {
        drift_pt_params params = {
            .width = 24, .height = 24, .seed = 5, .pixel_centre = centre == 1
        };
        plain_image full = render_aov(&r, &params, spp, DRIFT_PT_AOV_BEAUTY);
        params.components = DRIFT_PT_COMPONENT_ALL;
        plain_image all = render_aov(&r, &params, spp, DRIFT_PT_AOV_BEAUTY);
        assert_true(plain_identical(&full, &all)); // 0 and ALL are the same: no split
        plain_image parts[4];
        for (int c = 0; c < 4; ++c) {
            params.components = single_components[c];
            parts[c] = render_aov(&r, &params, spp, DRIFT_PT_AOV_BEAUTY);
            // Every component carries light in this scene: the split is not degenerate.
            if (!(plain_mean(&parts[c]) > 1e-3 * plain_mean(&full))) {
                fail_msg("component %u: mean %g of a full mean %g", single_components[c],
                         plain_mean(&parts[c]), plain_mean(&full));
            }
        }
        if (centre == 1) {
            // Where every sample's first hit is the mirror (albedo exactly its 0.9), all light
            // is specular; where it is a white diffuse wall (0.7), none is.
            plain_image albedo = render_aov(&r, &params, 1, DRIFT_PT_AOV_ALBEDO);
            int mirror_pixels = 0, lit_mirror_pixels = 0, wall_pixels = 0;
            for (size_t i = 0; i < plain_size(&full); ++i) {
                if (albedo.v[i] == 0.9f) {
                    mirror_pixels++;
                    lit_mirror_pixels += parts[2].v[i] > 0.0f;
                    assert_true(parts[0].v[i] == 0.0f && parts[1].v[i] == 0.0f &&
                                parts[3].v[i] == 0.0f);
                } else if (albedo.v[i] == 0.7f) {
                    wall_pixels++;
                    assert_true(parts[2].v[i] == 0.0f);
                }
            }
            assert_true(mirror_pixels > 10 && lit_mirror_pixels > 10 && wall_pixels > 10);
            test_free(albedo.v);
        }
        for (size_t i = 0; i < plain_size(&full); ++i) {
            double sum = 0.0;
            for (int c = 0; c < 4; ++c) {
                sum += (double)parts[c].v[i];
            }
            double expected = (double)full.v[i];
            if (fabs(sum - expected) > 1e-4 * fabs(expected) + 1e-6) {
                fail_msg("pixel centre %d, value %zu: components sum to %.7g, full image %.7g",
                         centre, i, sum, expected);
            }
        }
        for (int c = 0; c < 4; ++c) {
            test_free(parts[c].v);
        }
        test_free(all.v);
        test_free(full.v);
    }
    rig_destroy(&r);
}

// With max_depth 1 a path is the emission it sees plus its first vertex's direct light, so
// DIRECT = full - EMISSION, and nothing is left for SPECULAR or DIFFUSE (no mirror here).
// drift_pt_trace_sample returns what the components select.
static void test_pt_direct_is_the_first_bounce_without_emission(void **state)
{
    (void)state;
    rig r = rig_begin(2);
    component_scene(&r, false);
    rig_build(&r);
    drift_pt_params params = { .width = 24, .height = 24, .seed = 8, .max_depth = 1 };
    const uint32_t spp = 8;
    plain_image full = render_aov(&r, &params, spp, DRIFT_PT_AOV_BEAUTY);
    params.components = DRIFT_PT_COMPONENT_EMISSION;
    plain_image emission = render_aov(&r, &params, spp, DRIFT_PT_AOV_BEAUTY);
    params.components = DRIFT_PT_COMPONENT_DIRECT;
    plain_image direct = render_aov(&r, &params, spp, DRIFT_PT_AOV_BEAUTY);
    params.components = DRIFT_PT_COMPONENT_SPECULAR | DRIFT_PT_COMPONENT_DIFFUSE;
    plain_image rest = render_aov(&r, &params, spp, DRIFT_PT_AOV_BEAUTY);
    assert_true(plain_mean(&direct) > 0.1 * plain_mean(&full));
    assert_true(plain_mean(&emission) > 0.0);
    for (size_t i = 0; i < plain_size(&full); ++i) {
        double expected = (double)full.v[i] - (double)emission.v[i];
        if (fabs((double)direct.v[i] - expected) > 1e-4 * (double)full.v[i] + 1e-6) {
            fail_msg("value %zu: direct %.7g, full - emission %.7g", i, (double)direct.v[i],
                     expected);
        }
        assert_true(rest.v[i] == 0.0f);
    }
    // One sample replayed equals the one-sample image, component by component.
    params.components = DRIFT_PT_COMPONENT_DIRECT;
    drift_pt *pt = NULL;
    assert_int_equal(drift_pt_create(r.ctx, r.scene, r.accel, &params, &pt), DRIFT_OK);
    assert_int_equal(drift_pt_render_samples(pt, 1, NULL), DRIFT_OK);
    drift_image img;
    assert_int_equal(drift_pt_resolve(pt, DRIFT_PT_AOV_BEAUTY, &img), DRIFT_OK);
    for (int32_t y = 0; y < 24; y += 5) {
        for (int32_t x = 0; x < 24; x += 3) {
            drift_vec3 v = drift_pt_trace_sample(pt, x, y, 0);
            const float *px = drift_image_pixel(&img, x, y);
            assert_true(v.x == px[0] && v.y == px[1] && v.z == px[2]);
        }
    }
    drift_pt_destroy(pt);
    test_free(rest.v);
    test_free(direct.v);
    test_free(emission.v);
    test_free(full.v);
    rig_destroy(&r);
}

static void test_pt_rejects_unknown_components(void **state)
{
    (void)state;
    rig r = rig_begin(1);
    component_scene(&r, false);
    rig_build(&r);
    drift_pt *pt = NULL;
    assert_int_equal(
        drift_pt_create(r.ctx, r.scene, r.accel, &(drift_pt_params){ .components = 16 }, &pt),
        DRIFT_ERR_INVALID_ARGUMENT);
    assert_null(pt);
    rig_destroy(&r);
}

// Every camera ray through the pixel centre: the first-hit distance to a tilted plane is the
// centre ray's at every pixel, for one sample and for four (no jitter averages in).
static void test_pt_pixel_centre_samples_go_through_the_pixel_centre(void **state)
{
    (void)state;
    rig r = rig_begin(2);
    uint32_t mat;
    assert_int_equal(
        drift_scene_add_material(r.scene,
                                 &(drift_material){ .diffuse = drift_vec3_splat(0.5f),
                                                    .diffuse_texture = DRIFT_INVALID_INDEX },
                                 &mat),
        DRIFT_OK);
    add_floor(r.scene, 100.0f, mat);
    const int32_t w = 16, h = 12;
    r.scene->camera = drift_camera_look_at(drift_vec3_make(0.3f, 3, 3), drift_vec3_make(0, 0, 0),
                                           drift_vec3_make(0, 1, 0), 0.8f, w, h);
    rig_build(&r);
    const uint32_t spps[2] = { 1, 4 };
    for (int i = 0; i < 2; ++i) {
        plain_image depth = render_aov(
            &r, &(drift_pt_params){ .width = w, .height = h, .max_depth = 1, .pixel_centre = true },
            spps[i], DRIFT_PT_AOV_DEPTH);
        for (int32_t y = 0; y < h; ++y) {
            for (int32_t x = 0; x < w; ++x) {
                drift_ray c = drift_camera_ray(&r.scene->camera, w, h, (float)x + 0.5f,
                                               (float)y + 0.5f, drift_vec2_make(0.5f, 0.5f));
                double t = -(double)c.origin.y / (double)c.dir.y; // the plane y = 0
                double got = (double)depth.v[(size_t)y * (size_t)w + (size_t)x];
                if (fabs(got - t) > 1e-4 * t) {
                    fail_msg("%u spp, pixel %d,%d: depth %.6f, through the centre %.6f", spps[i], x,
                             y, got, t);
                }
            }
        }
        test_free(depth.v);
    }
    // Negative control: with pixel jitter the one-sample depths leave the centre's.
    plain_image jittered = render_aov(
        &r, &(drift_pt_params){ .width = w, .height = h, .max_depth = 1 }, 1, DRIFT_PT_AOV_DEPTH);
    double worst = 0.0;
    for (int32_t y = 0; y < h; ++y) {
        for (int32_t x = 0; x < w; ++x) {
            drift_ray c = drift_camera_ray(&r.scene->camera, w, h, (float)x + 0.5f, (float)y + 0.5f,
                                           drift_vec2_make(0.5f, 0.5f));
            double t = -(double)c.origin.y / (double)c.dir.y;
            double got = (double)jittered.v[(size_t)y * (size_t)w + (size_t)x];
            worst = fmax(worst, fabs(got - t) / t);
        }
    }
    assert_true(worst > 1e-3);
    test_free(jittered.v);
    rig_destroy(&r);
}

// pinhole = true on a camera with an aperture renders exactly what the zero-aperture camera
// renders (the lens sample is still drawn, and ignored).
static void test_pt_pinhole_flag_ignores_the_aperture(void **state)
{
    (void)state;
    rig lens = rig_begin(2), pin = rig_begin(2);
    small_box_scene(&lens, 0.05f);
    lens.scene->camera.focus_distance = 0.6f;
    small_box_scene(&pin, 0.0f);
    pin.scene->camera.focus_distance = 0.6f;
    rig_build(&lens);
    rig_build(&pin);
    const drift_pt_params params = { .seed = 4 };
    plain_image expected = render_aov(&pin, &params, 4, DRIFT_PT_AOV_BEAUTY);
    plain_image got =
        render_aov(&lens, &(drift_pt_params){ .seed = 4, .pinhole = true }, 4, DRIFT_PT_AOV_BEAUTY);
    plain_image blurred = render_aov(&lens, &params, 4, DRIFT_PT_AOV_BEAUTY);
    assert_true(plain_identical(&expected, &got));
    assert_false(plain_identical(&expected, &blurred)); // the aperture matters without the flag
    test_free(blurred.v);
    test_free(got.v);
    test_free(expected.v);
    rig_destroy(&pin);
    rig_destroy(&lens);
}

// params.camera replaces the scene camera (its width and height are not used): the same image
// as a scene whose camera it is.
static void test_pt_camera_override_equals_the_scene_camera(void **state)
{
    (void)state;
    drift_camera other =
        drift_camera_look_at(drift_vec3_make(0.4f, 0.3f, 0.9f), drift_vec3_make(-0.2f, -0.5f, 0.0f),
                             drift_vec3_make(0, 1, 0), 1.1f, 7, 5);
    other.aperture_radius = 0.03f;
    other.focus_distance = 1.2f;
    rig a = rig_begin(2), b = rig_begin(2);
    small_box_scene(&a, 0.0f);
    small_box_scene(&b, 0.0f);
    drift_camera own = a.scene->camera;
    b.scene->camera = other;
    b.scene->camera.width = 24; // the size comes from the params either way
    b.scene->camera.height = 20;
    rig_build(&a);
    rig_build(&b);
    plain_image overridden =
        render_aov(&a, &(drift_pt_params){ .width = 24, .height = 20, .seed = 9, .camera = &other },
                   4, DRIFT_PT_AOV_BEAUTY);
    plain_image expected = render_aov(
        &b, &(drift_pt_params){ .width = 24, .height = 20, .seed = 9 }, 4, DRIFT_PT_AOV_BEAUTY);
    plain_image scene_camera =
        render_aov(&a, &(drift_pt_params){ .width = 24, .height = 20, .seed = 9, .camera = &own },
                   4, DRIFT_PT_AOV_BEAUTY);
    plain_image defaulted = render_aov(
        &a, &(drift_pt_params){ .width = 24, .height = 20, .seed = 9 }, 4, DRIFT_PT_AOV_BEAUTY);
    assert_true(plain_identical(&overridden, &expected));
    assert_true(plain_identical(&scene_camera, &defaulted)); // NULL is the scene camera
    assert_false(plain_identical(&overridden, &defaulted));  // the override is used
    test_free(defaulted.v);
    test_free(scene_camera.v);
    test_free(expected.v);
    test_free(overridden.v);
    rig_destroy(&b);
    rig_destroy(&a);
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
        cmocka_unit_test(test_pt_tiles_moved_between_pts_are_bit_identical),
        cmocka_unit_test(test_pt_converges_as_inverse_sqrt_spp),
        cmocka_unit_test(test_pt_cancel_flag_stops_and_reports),
        cmocka_unit_test(test_pt_components_sum_to_the_full_image),
        cmocka_unit_test(test_pt_direct_is_the_first_bounce_without_emission),
        cmocka_unit_test(test_pt_rejects_unknown_components),
        cmocka_unit_test(test_pt_pixel_centre_samples_go_through_the_pixel_centre),
        cmocka_unit_test(test_pt_pinhole_flag_ignores_the_aperture),
        cmocka_unit_test(test_pt_camera_override_equals_the_scene_camera),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
