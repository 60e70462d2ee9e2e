// The hybrid frame against closed forms and the reference path tracer: G-buffer planes of a
// plane and a sphere, reference effects summing to the full path tracer, the hard-shadow
// buffer's distances, environment-map reflections of a mirror sphere at its probe, post DOF
// with a pinhole, and determinism across thread counts.
// ctest-labels: quality slow
#include "drift/accel.h"
#include "drift/hybrid.h"
#include "drift/metric.h"
#include "drift/pt.h"
#include "drift/scene.h"
#include "drift_test.h"
#include "raster/raster.h"
#include "test_rig.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PI_F 3.14159265f
#define M_PI 3.14159265358979323846

// Axis-aligned box [-h, h]^3 with triangles facing inward.
static void add_room(drift_scene *scene, float h, uint32_t material)
{
    const float p[] = { -h, -h, -h, h, -h, -h, h, h, -h, -h, h, -h,
                        -h, -h, h,  h, -h, h,  h, h, h,  -h, h, h };
    const uint32_t idx[] = { 0, 1, 2, 0, 2, 3, 4, 7, 6, 4, 6, 5, 0, 4, 5, 0, 5, 1,
                             3, 2, 6, 3, 6, 7, 0, 3, 7, 0, 7, 4, 1, 5, 6, 1, 6, 2 };
    test_add_mesh(scene, p, 8, idx, 12, material);
}

static void add_point_light(drift_scene *scene, drift_vec3 position, drift_vec3 intensity)
{
    drift_light light = { .type = DRIFT_LIGHT_POINT, .position = position, .color = intensity };
    assert_int_equal(drift_scene_add_light(scene, &light, NULL), DRIFT_OK);
}

static drift_vec3 pixel3(const drift_image *img, int x, int y)
{
    return drift_image_get3(img, x, y);
}

// --- G-BUFFER ---

// A camera looking straight down at a floor: depth = height, position on the plane, normal +y.
static void test_gbuffer_plane(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    uint32_t white = test_add_material(r.scene, drift_material_make(drift_vec3_splat(0.5f)));
    test_add_floor(r.scene, 100.0f, 0.0f, white);
    const float height = 3.0f;
    r.scene->camera = drift_camera_look_at(drift_vec3_make(0, height, 0), drift_vec3_make(0, 0, 0),
                                           drift_vec3_make(0, 0, 1), 0.8f, 48, 32);
    add_point_light(r.scene, drift_vec3_make(0, 5, 0), drift_vec3_splat(1));
    test_rig_commit(&r);
    test_rig_frame(&r, &(drift_hybrid_params){ 0 });
    const drift_gbuffer *g = drift_hybrid_gbuffer(r.frame);
    for (int y = 0; y < g->height; ++y) {
        for (int x = 0; x < g->width; ++x) {
            drift_ray ray = drift_camera_ray(&r.scene->camera, 48, 32, (float)x + 0.5f,
                                             (float)y + 0.5f, drift_vec2_make(0.5f, 0.5f));
            float t = height / -ray.dir.y;
            drift_vec3 expected = drift_vec3_fma(ray.origin, ray.dir, t);
            drift_vec3 pos = pixel3(&g->position, x, y);
            assert_near(drift_image_pixel(&g->depth, x, y)[0], height, 1e-4);
            assert_near(pos.x, expected.x, 1e-4);
            assert_near(pos.y, 0.0, 1e-5);
            assert_near(pos.z, expected.z, 1e-4);
            assert_near(pixel3(&g->normal, x, y).y, 1.0, 1e-6);
            assert_near(pixel3(&g->geometric_normal, x, y).y, 1.0, 1e-6);
            assert_near(pixel3(&g->albedo, x, y).x, 0.5, 1e-6);
            assert_near(drift_image_pixel(&g->material_id, x, y)[0], (float)white, 0.0);
            assert_near(drift_image_pixel(&g->gloss, x, y)[0], 0.5 * M_PI, 1e-6);
        }
    }
    test_rig_destroy(&r);
}

// A sphere seen from outside: the ray-sphere intersection in closed form.
static void test_gbuffer_sphere(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    uint32_t glossy =
        test_add_material(r.scene, (drift_material){ .type = DRIFT_MATERIAL_DEFAULT,
                                                     .diffuse = { 0.2f, 0.2f, 0.2f },
                                                     .specular = { 0.5f, 0.5f, 0.5f },
                                                     .exponent = 100.0f,
                                                     .diffuse_texture = DRIFT_INVALID_INDEX });
    const drift_vec3 c = drift_vec3_make(0.3f, -0.2f, 5.0f);
    const float radius = 1.0f;
    test_add_sphere(r.scene, c, radius, 192, 96, glossy);
    r.scene->camera = drift_camera_look_at(drift_vec3_make(0, 0, 0), drift_vec3_make(0, 0, 1),
                                           drift_vec3_make(0, 1, 0), 0.5f, 64, 64);
    add_point_light(r.scene, drift_vec3_make(0, 5, 0), drift_vec3_splat(1));
    test_rig_commit(&r);
    test_rig_frame(&r, &(drift_hybrid_params){ 0 });
    const drift_gbuffer *g = drift_hybrid_gbuffer(r.frame);
    int hits = 0, misses = 0;
    // Tessellation with 192x96 facets: the flat facets lie within r (1 - cos(pi/96)) of the sphere.
    const double position_tolerance = 1.5 * (double)radius * (1.0 - cos(M_PI / 96.0));
    for (int y = 0; y < g->height; ++y) {
        for (int x = 0; x < g->width; ++x) {
            drift_ray ray = drift_camera_ray(&r.scene->camera, 64, 64, (float)x + 0.5f,
                                             (float)y + 0.5f, drift_vec2_make(0.5f, 0.5f));
            drift_vec3 oc = drift_vec3_sub(ray.origin, c);
            float b = drift_vec3_dot(oc, ray.dir);
            float disc = b * b - (drift_vec3_dot(oc, oc) - radius * radius);
            float id = drift_image_pixel(&g->material_id, x, y)[0];
            // Skip the rim, where facets and sphere disagree on hit or miss.
            if (disc < 0.02f) {
                misses += disc < 0.0f && id < 0.0f;
                continue;
            }
            float t = -b - sqrtf(disc);
            drift_vec3 p = drift_vec3_fma(ray.origin, ray.dir, t);
            drift_vec3 n = drift_vec3_scale(drift_vec3_sub(p, c), 1.0f / radius);
            assert_near(id, (float)glossy, 0.0);
            // Along the ray, a facet's offset from the sphere grows as 1/cos(incidence).
            double cos_i = fmax(0.1, -(double)drift_vec3_dot(ray.dir, n));
            assert_near(drift_image_pixel(&g->depth, x, y)[0], p.z, position_tolerance / cos_i);
            drift_vec3 pos = pixel3(&g->position, x, y);
            assert_near(drift_vec3_length(drift_vec3_sub(pos, p)), 0.0, position_tolerance / cos_i);
            // Interpolated normals stay within the facet's angle of the true normal.
            assert_true(drift_vec3_dot(pixel3(&g->normal, x, y), n) > cosf(PI_F / 96.0f));
            assert_near(drift_image_pixel(&g->gloss, x, y)[1], 100.0, 0.0);
            ++hits;
        }
    }
    assert_true(hits > 500);
    assert_true(misses > 500);
    test_rig_destroy(&r);
}

// --- EFFECT ISOLATION ---

// A small room with a quad light, a glossy sphere and a mirror sphere.
static void build_room(test_rig *r, int32_t size)
{
    uint32_t white =
        test_add_material(r->scene, drift_material_make(drift_vec3_make(0.7f, 0.6f, 0.5f)));
    uint32_t glossy =
        test_add_material(r->scene, (drift_material){ .diffuse = { 0.3f, 0.1f, 0.1f },
                                                      .specular = { 0.5f, 0.5f, 0.5f },
                                                      .exponent = 40.0f,
                                                      .diffuse_texture = DRIFT_INVALID_INDEX });
    uint32_t mirror =
        test_add_material(r->scene, (drift_material){ .type = DRIFT_MATERIAL_MIRROR,
                                                      .specular = { 0.9f, 0.9f, 0.9f },
                                                      .diffuse_texture = DRIFT_INVALID_INDEX });
    add_room(r->scene, 2.0f, white);
    test_add_sphere(r->scene, drift_vec3_make(-0.7f, -1.3f, 0.3f), 0.6f, 192, 96, glossy);
    test_add_sphere(r->scene, drift_vec3_make(0.8f, -1.4f, -0.2f), 0.5f, 192, 96, mirror);
    assert_int_equal(drift_scene_add_light(r->scene,
                                           &(drift_light){ .type = DRIFT_LIGHT_QUAD,
                                                           .position = { -0.5f, 1.95f, -0.5f },
                                                           .edge_u = { 1, 0, 0 },
                                                           .edge_v = { 0, 0, 1 }, // emits down
                                                           .color = { 8, 8, 8 } },
                                           NULL),
                     DRIFT_OK);
    r->scene->camera =
        drift_camera_look_at(drift_vec3_make(0, 0, -1.9f), drift_vec3_make(0, -0.8f, 0),
                             drift_vec3_make(0, 1, 0), 1.3f, size, size);
}

static drift_image render_pt(test_rig *r, const drift_pt_params *params, uint32_t spp,
                             drift_pt **pt)
{
    assert_int_equal(drift_pt_create(r->ctx, r->scene, r->accel, params, pt), DRIFT_OK);
    assert_int_equal(drift_pt_render_samples(*pt, spp, NULL), DRIFT_OK);
    drift_image img;
    assert_int_equal(drift_pt_resolve(*pt, DRIFT_PT_AOV_BEAUTY, &img), DRIFT_OK);
    return img;
}

// Every effect set to `reference` is the reference render itself, split by components and
// summed again by the composition: same seed, same paths, so equal to rounding.
static void test_all_reference_equals_path_tracer(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    build_room(&r, 40);
    test_rig_commit(&r);
    const uint32_t spp = 8;
    test_rig_frame(&r, &(drift_hybrid_params){ .shadows = DRIFT_SHADOWS_REFERENCE,
                                               .reflections = DRIFT_REFLECTIONS_REFERENCE,
                                               .indirect = DRIFT_INDIRECT_REFERENCE,
                                               .spp = spp,
                                               .seed = 5 });
    drift_pt *pt = NULL;
    drift_image truth = render_pt(&r,
                                  &(drift_pt_params){ .width = 40,
                                                      .height = 40,
                                                      .seed = 5,
                                                      .max_depth = 2,
                                                      .pixel_centre = true,
                                                      .pinhole = true },
                                  spp, &pt);
    const drift_image *img = drift_hybrid_image(r.frame);
    double sum = 0.0;
    for (int y = 0; y < 40; ++y) {
        for (int x = 0; x < 40; ++x) {
            drift_vec3 a = pixel3(img, x, y), b = pixel3(&truth, x, y);
            assert_near(a.x, b.x, 1e-4 * fabs((double)b.x) + 1e-5);
            assert_near(a.y, b.y, 1e-4 * fabs((double)b.y) + 1e-5);
            assert_near(a.z, b.z, 1e-4 * fabs((double)b.z) + 1e-5);
            sum += (double)b.x;
        }
    }
    assert_true(sum > 1.0); // the room is lit
    drift_pt_destroy(pt);
    test_rig_destroy(&r);
}

static double flip_of(test_rig *r, const drift_image *truth, const drift_image *img)
{
    drift_metric_report rep;
    assert_int_equal(
        drift_metric_compare(r->ctx, truth, img, &(drift_metric_params){ 0 }, &rep, NULL),
        DRIFT_OK);
    return rep.flip;
}

// The anti-aliasing passes converge to the path tracer's pixel filter: an all-reference frame
// against the path tracer with jittered film samples (an independent seed) at the same
// samples a pixel, direct light only so that the noise stays small (two path tracers of
// other seeds differ by FLIP ~0.005 here). One pass traces every sample through the pixel
// centre, so the light's and the spheres' edges stay aliased against the box filter (~0.023);
// 16 passes through stratified sub-pixel offsets close that gap (issue 21: within 0.01).
static void test_aa_converges_to_pixel_filter(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    const int32_t size = 40;
    build_room(&r, size);
    test_rig_commit(&r);
    uint32_t total = (uint32_t)(256 * test_intensity());
    total = total < 256 ? 256 : total;
    drift_pt *pt = NULL;
    drift_image truth =
        render_pt(&r,
                  &(drift_pt_params){
                      .width = size, .height = size, .seed = 77, .max_depth = 1, .pinhole = true },
                  total, &pt);
    const uint32_t passes[2] = { 1, 16 };
    double flip[2];
    for (int k = 0; k < 2; ++k) {
        test_rig_frame(&r, &(drift_hybrid_params){ .shadows = DRIFT_SHADOWS_REFERENCE,
                                                   .reflections = DRIFT_REFLECTIONS_REFERENCE,
                                                   .indirect = DRIFT_INDIRECT_REFERENCE,
                                                   .spp = total / passes[k],
                                                   .aa = passes[k],
                                                   .max_depth = 1,
                                                   .seed = 5 });
        flip[k] = flip_of(&r, &truth, drift_hybrid_image(r.frame));
    }
    print_message("all-reference FLIP against the jittered path tracer: 1 pass %.4f, %u passes "
                  "%.4f (%u samples a pixel)\n",
                  flip[0], passes[1], flip[1], total);
    assert_true(flip[0] > 0.01); // pixel centres alone are off the pixel filter
    assert_true(flip[1] < 0.01);
    drift_pt_destroy(pt);
    test_rig_destroy(&r);
}

// Reference shadows alone converge to the direct-lighting render, emission plus direct light
// (an independent seed at many samples): the error falls as samples grow. (Light seen in the
// mirror belongs to reflections, so the truth is the pt's EMISSION | DIRECT components.)
static void test_reference_shadows_converge(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    build_room(&r, 32);
    test_rig_commit(&r);
    drift_pt *pt = NULL;
    uint32_t truth_spp = (uint32_t)(512 * test_intensity());
    drift_image truth = render_pt(
        &r,
        &(drift_pt_params){ .width = 32,
                            .height = 32,
                            .seed = 99,
                            .max_depth = 1,
                            .pixel_centre = true,
                            .pinhole = true,
                            .components = DRIFT_PT_COMPONENT_EMISSION | DRIFT_PT_COMPONENT_DIRECT },
        truth_spp < 64 ? 64 : truth_spp, &pt);
    double errors[3];
    const uint32_t spps[3] = { 2, 8, 32 };
    for (int k = 0; k < 3; ++k) {
        test_rig_frame(&r, &(drift_hybrid_params){
                               .shadows = DRIFT_SHADOWS_REFERENCE, .spp = spps[k], .seed = 1 });
        errors[k] = test_rmse(r.ctx, drift_hybrid_image(r.frame), &truth);
    }
    print_message("reference shadows rmse %g %g %g\n", errors[0], errors[1], errors[2]);
    assert_true(errors[1] < 0.75 * errors[0]);
    assert_true(errors[2] < 0.75 * errors[1]);
    drift_pt_destroy(pt);
    test_rig_destroy(&r);
}

// --- SHARP BUFFERS ---

// A floor under a point light with a square occluder at height h: where the occluder blocks
// the light, the hard-shadow buffer reports it at the distance of the crossing of y = h, and
// the light's distance everywhere. The light stands to the side so the camera above sees the
// shadow. The distances are traced for a row that reads them (`isg`); `hard` alone traces
// any-hit rays and leaves 0 in shadow.
static void test_hard_shadow_buffer_distances(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    uint32_t white = test_add_material(r.scene, drift_material_make(drift_vec3_splat(0.5f)));
    test_add_floor(r.scene, 10.0f, 0.0f, white);
    const float h = 1.0f, light_height = 4.0f, light_x = 2.0f;
    const float occ[] = { -0.5f, h, -0.5f, 0.5f, h, -0.5f, 0.5f, h, 0.5f, -0.5f, h, 0.5f };
    const uint32_t occ_idx[] = { 0, 2, 1, 0, 3, 2 };
    test_add_mesh(r.scene, occ, 4, occ_idx, 2, white);
    add_point_light(r.scene, drift_vec3_make(light_x, light_height, 0), drift_vec3_splat(10));
    r.scene->camera = drift_camera_look_at(drift_vec3_make(0, 8, -0.01f), drift_vec3_make(0, 0, 0),
                                           drift_vec3_make(0, 1, 0), 0.6f, 32, 32);
    test_rig_commit(&r);
    for (int any_hit = 0; any_hit < 2; ++any_hit) {
        test_rig_frame(&r, &(drift_hybrid_params){ .shadows = any_hit ? DRIFT_SHADOWS_HARD
                                                                      : DRIFT_SHADOWS_ISG });
        const drift_gbuffer *g = drift_hybrid_gbuffer(r.frame);
        const drift_image *hard = test_rig_plane(&r, "light0.hard_shadow");
        int shadowed = 0, lit = 0;
        for (int y = 0; y < 32; ++y) {
            for (int x = 0; x < 32; ++x) {
                drift_vec3 p = pixel3(&g->position, x, y);
                if (fabsf(p.y) > 1e-3f) {
                    continue; // the occluder itself
                }
                const float *v = drift_image_pixel(hard, x, y);
                drift_vec3 to_light = drift_vec3_sub(drift_vec3_make(light_x, light_height, 0), p);
                float dist = drift_vec3_length(to_light);
                assert_near(v[2], dist, 1e-4 * (double)dist);
                // Where the ray toward the light crosses y = h, inside the square or not.
                drift_vec3 cross = drift_vec3_fma(p, to_light, h / to_light.y);
                bool inside = fabsf(cross.x) < 0.49f && fabsf(cross.z) < 0.49f;
                bool outside = fabsf(cross.x) > 0.51f || fabsf(cross.z) > 0.51f;
                if (inside) {
                    assert_near(v[0], 0.0, 0.0);
                    assert_near(v[1], any_hit ? 0.0f : dist * h / to_light.y, 1e-3);
                    ++shadowed;
                } else if (outside) {
                    assert_near(v[0], 1.0, 0.0);
                    assert_true(isinf(v[1]));
                    ++lit;
                }
            }
        }
        assert_true(shadowed > 10);
        assert_true(lit > 100);
    }
    test_rig_destroy(&r);
}

// --- ENVIRONMENT MAP ---

// Mean relative difference over the mirror's pixels between the sharp reflection and the
// environment-map reflection rendered with params p.
static double envmap_difference(test_rig *r, const drift_hybrid_params *p, const drift_image *sharp,
                                uint32_t mirror)
{
    assert_int_equal(drift_hybrid_set_params(r->frame, p), DRIFT_OK);
    assert_int_equal(drift_hybrid_render(r->frame, &r->scene->camera, NULL), DRIFT_OK);
    const drift_gbuffer *g = drift_hybrid_gbuffer(r->frame);
    const drift_image *env = test_rig_plane(r, "reflections");
    double diff = 0.0, total = 0.0;
    int pixels = 0;
    for (int y = 0; y < g->height; ++y) {
        for (int x = 0; x < g->width; ++x) {
            if (drift_image_pixel(&g->material_id, x, y)[0] != (float)mirror) {
                continue;
            }
            drift_vec3 a = pixel3(sharp, x, y), b = pixel3(env, x, y);
            diff +=
                fabs((double)(a.x - b.x)) + fabs((double)(a.y - b.y)) + fabs((double)(a.z - b.z));
            total += (double)(a.x + a.y + a.z);
            ++pixels;
        }
    }
    assert_true(pixels > 300);
    assert_true(total > 0.0);
    return diff / total;
}

// A small mirror sphere at its own probe sees what the probe sees: its environment-map
// reflection matches the ray-traced one up to the parallax of its radius.
static void test_envmap_mirror_sphere_matches_ray_traced(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    uint32_t white =
        test_add_material(r.scene, drift_material_make(drift_vec3_make(0.7f, 0.5f, 0.3f)));
    uint32_t mirror =
        test_add_material(r.scene, (drift_material){ .type = DRIFT_MATERIAL_MIRROR,
                                                     .specular = { 1, 1, 1 },
                                                     .diffuse_texture = DRIFT_INVALID_INDEX });
    add_room(r.scene, 10.0f, white);
    const drift_vec3 centre = drift_vec3_make(0.3f, -0.5f, 0.2f);
    test_add_sphere(r.scene, centre, 0.05f, 192, 96, mirror);
    assert_int_equal(drift_scene_add_light(r.scene,
                                           &(drift_light){ .type = DRIFT_LIGHT_QUAD,
                                                           .position = { -3, 9.9f, -3 },
                                                           .edge_u = { 6, 0, 0 },
                                                           .edge_v = { 0, 0, 6 },
                                                           .color = { 5, 5, 5 } },
                                           NULL),
                     DRIFT_OK);
    r.scene->camera =
        drift_camera_look_at(drift_vec3_add(centre, drift_vec3_make(0.1f, 0.05f, -0.3f)), centre,
                             drift_vec3_make(0, 1, 0), 0.35f, 48, 48);
    test_rig_commit(&r);
    drift_hybrid_params p = { .reflections = DRIFT_REFLECTIONS_SHARP,
                              .envmap.per_object = true,
                              .envmap.size = 256,
                              .light_samples = 64 };
    test_rig_frame(&r, &p);
    drift_image sharp;
    assert_int_equal(drift_image_create(r.ctx, 48, 48, 3, &sharp), DRIFT_OK);
    memcpy(sharp.pixels, test_rig_plane(&r, "reflections")->pixels, sizeof(float) * 3 * 48 * 48);
    p.reflections = DRIFT_REFLECTIONS_ENVMAP;
    double at_probe = envmap_difference(&r, &p, &sharp, mirror);
    // The same lookup from a probe far from the sphere sees the room from elsewhere.
    p.envmap.per_object = false;
    p.envmap.has_probe = true;
    p.envmap.probe = drift_vec3_make(6, 6, 6);
    double far_away = envmap_difference(&r, &p, &sharp, mirror);
    print_message("envmap vs sharp: relative difference %g at the probe, %g from afar\n", at_probe,
                  far_away);
    // At the probe: texel interpolation of the light's edges at 256^2 and the per-pixel
    // light samples account for a few percent.
    assert_true(at_probe < 0.04);
    assert_true(far_away > 3.0 * at_probe);
    drift_image_destroy(r.ctx, &sharp);
    test_rig_destroy(&r);
}

// --- DEPTH OF FIELD ---

static void test_post_dof_pinhole_is_identity(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    build_room(&r, 32);
    r.scene->camera.aperture_radius = 0.0f;
    test_rig_commit(&r);
    test_rig_frame(&r, &(drift_hybrid_params){ .dof = DRIFT_DOF_NONE });
    drift_image none;
    assert_int_equal(drift_image_create(r.ctx, 32, 32, 3, &none), DRIFT_OK);
    memcpy(none.pixels, drift_hybrid_image(r.frame)->pixels, sizeof(float) * 3 * 32 * 32);
    test_rig_frame(&r, &(drift_hybrid_params){ .dof = DRIFT_DOF_POST });
    assert_memory_equal(none.pixels, drift_hybrid_image(r.frame)->pixels,
                        sizeof(float) * 3 * 32 * 32);
    // With an aperture the same frame does change.
    r.scene->camera.aperture_radius = 0.2f;
    test_rig_frame(&r, &(drift_hybrid_params){ .dof = DRIFT_DOF_POST });
    assert_true(
        memcmp(none.pixels, drift_hybrid_image(r.frame)->pixels, sizeof(float) * 3 * 32 * 32) != 0);
    drift_image_destroy(r.ctx, &none);
    test_rig_destroy(&r);
}

// --- DETERMINISM ---

static void render_room_with_threads(int threads, drift_shadow_technique shadows, float *out)
{
    test_rig r = test_rig_begin(threads);
    build_room(&r, 24);
    r.scene->camera.aperture_radius = 0.05f;
    r.scene->camera.focus_distance = 2.0f;
    test_rig_commit(&r);
    test_rig_frame(&r, &(drift_hybrid_params){ .shadows = shadows,
                                               .reflections = DRIFT_REFLECTIONS_SHARP,
                                               .dof = DRIFT_DOF_POST,
                                               .indirect = DRIFT_INDIRECT_AMBIENT,
                                               .shadow_map.size = 64 });
    memcpy(out, drift_hybrid_image(r.frame)->pixels, sizeof(float) * 3 * 24 * 24);
    test_rig_destroy(&r);
}

static void test_deterministic_across_threads(void **state)
{
    (void)state;
    static float a[3 * 24 * 24], b[3 * 24 * 24];
    const drift_shadow_technique techniques[] = { DRIFT_SHADOWS_HARD, DRIFT_SHADOWS_PCSS };
    for (int k = 0; k < 2; ++k) {
        render_room_with_threads(1, techniques[k], a);
        render_room_with_threads(3, techniques[k], b);
        assert_memory_equal(a, b, sizeof a);
    }
}

// --- UNSHADOWED LIGHT ---

typedef struct unshadowed_case {
    drift_vec3 p, n;
} unshadowed_case;

// The closed-form diffuse term of `light` at each case equals a brute-force Monte Carlo
// integral of the same BSDF and light code (the path tracer's light sampling); the cases
// listed in `dark` must be exactly 0.
static void check_unshadowed_matches_monte_carlo(const drift_light *light,
                                                 const unshadowed_case *cases, size_t count,
                                                 size_t dark)
{
    test_rig r = test_rig_begin(1);
    uint32_t white =
        test_add_material(r.scene, drift_material_make(drift_vec3_make(0.8f, 0.5f, 0.2f)));
    test_add_floor(r.scene, 10.0f, -5.0f, white);
    assert_int_equal(drift_scene_add_light(r.scene, light, NULL), DRIFT_OK);
    test_rig_commit(&r);
    drift_raster_light *lights = NULL;
    uint32_t light_count = 0;
    assert_int_equal(drift_raster_lights_build(r.ctx, r.scene, &lights, &light_count), DRIFT_OK);
    assert_int_equal(light_count, 1);
    for (size_t c = 0; c < count; ++c) {
        drift_surface s = { .position = cases[c].p,
                            .material = white,
                            .light = DRIFT_INVALID_INDEX };
        s.ns = s.ng = drift_vec3_normalize(cases[c].n);
        drift_bsdf bsdf = drift_bsdf_make(r.scene, &s);
        drift_vec3 wo = s.ns;
        drift_sampler sampler = drift_sampler_make(1, 0, 0);
        drift_vec3 closed =
            drift_raster_unshadowed(r.scene, &lights[0], &s, &bsdf, wo, 8, &sampler);
        double mc = 0.0;
        const int n = 200000;
        for (int k = 0; k < n; ++k) {
            drift_sampler ks = drift_sampler_make(7, 0, (uint32_t)k);
            drift_light_sample ls =
                drift_light_sample_li(r.scene, 0, s.position, drift_sampler_next2(&ks));
            if (ls.pdf > 0.0f) {
                drift_vec3 f = drift_bsdf_eval(&bsdf, wo, ls.wi);
                mc += (double)(f.x * ls.radiance.x * fabsf(drift_vec3_dot(ls.wi, s.ns)) / ls.pdf);
            }
        }
        mc /= n;
        print_message("case %zu: closed form %g, Monte Carlo %g\n", c, (double)closed.x, mc);
        assert_near(closed.x, mc, 0.01 * mc + 1e-6);
        if (c == dark) {
            assert_near(closed.x, 0.0, 0.0);
        }
    }
    drift_raster_lights_destroy(r.ctx, lights, light_count);
    test_rig_destroy(&r);
}

// A quad light, including points that see it partly below their horizon (clipping) and
// points behind it (zero).
static void test_unshadowed_quad_matches_monte_carlo(void **state)
{
    (void)state;
    const unshadowed_case cases[] = {
        { { 0, 0, 0 }, { 0, 1, 0 } },              // straight below
        { { 2, 0.5f, 0.3f }, { -0.6f, 0.8f, 0 } }, // off to the side, tilted
        { { 0.2f, 0.9f, 0 }, { 1, 0, 0 } }, // a wall just below: the quad crosses its horizon
        { { 0, 2, 0 }, { 0, -1, 0 } },      // above the light: behind its emitting side
    };
    check_unshadowed_matches_monte_carlo(&(drift_light){ .type = DRIFT_LIGHT_QUAD,
                                                         .position = { -0.5f, 1.0f, -0.5f },
                                                         .edge_u = { 1, 0, 0 },
                                                         .edge_v = { 0, 0, 1 },
                                                         .color = { 3, 3, 3 } },
                                         cases, sizeof cases / sizeof *cases, 3);
}

// The closed form a row at a time (drift_raster_polygon_rows, vectorised) gives the very value
// the pixel-by-pixel path gives, at every pixel of the Cornell box's G-buffer: its light is a
// mesh of two triangles that the tall block's faces see straddling their horizon (the clip),
// the ceiling sees behind its emitting side, and the walls see whole; in runs of up to
// DRIFT_RASTER_ROW_MAX pixels with the last run short (an odd width).
static void test_polygon_rows_equal_the_pixel_path(void **state)
{
    (void)state;
    test_rig r = test_rig_load(1, "scenes/cornell-box/cornell_box.json", 71);
    const drift_gbuffer *gb = drift_hybrid_gbuffer(r.frame);
    drift_raster_light *lights = NULL;
    uint32_t light_count = 0;
    assert_int_equal(drift_raster_lights_build(r.ctx, r.scene, &lights, &light_count), DRIFT_OK);
    assert_int_equal(light_count, 1);
    assert_true(drift_raster_has_polygon_rows(&lights[0]));
    size_t lit = 0, checked = 0;
    for (int32_t y = 0; y < gb->height; ++y) {
        for (int32_t x0 = 0; x0 < gb->width; x0 += DRIFT_RASTER_ROW_MAX) {
            int32_t n =
                gb->width - x0 < DRIFT_RASTER_ROW_MAX ? gb->width - x0 : DRIFT_RASTER_ROW_MAX;
            float p[6][DRIFT_RASTER_ROW_MAX], e[3][DRIFT_RASTER_ROW_MAX];
            drift_bsdf bsdf[DRIFT_RASTER_ROW_MAX];
            const drift_surface *s = &gb->surfaces[(size_t)y * (size_t)gb->width + (size_t)x0];
            for (int32_t i = 0; i < n; ++i) {
                bool hit = s[i].material != DRIFT_INVALID_INDEX;
                bsdf[i] = hit ? drift_bsdf_make(r.scene, &s[i]) : (drift_bsdf){ 0 };
                drift_vec3 nz = bsdf[i].frame.z;
                p[0][i] = s[i].position.x, p[1][i] = s[i].position.y, p[2][i] = s[i].position.z;
                p[3][i] = nz.x, p[4][i] = nz.y, p[5][i] = nz.z;
            }
            drift_raster_receivers rs = { p[0], p[1], p[2], p[3], p[4], p[5], n };
            drift_raster_polygon_rows(r.scene, &lights[0], &rs, e[0], e[1], e[2]);
            for (int32_t i = 0; i < n; ++i) {
                if (s[i].material == DRIFT_INVALID_INDEX) {
                    continue;
                }
                drift_vec3 wo = bsdf[i].frame.z;
                drift_sampler a = drift_sampler_make(3, (uint32_t)i, 0), b = a;
                drift_vec3 pixel =
                    drift_raster_unshadowed(r.scene, &lights[0], &s[i], &bsdf[i], wo, 1, &a);
                drift_vec3 row =
                    drift_raster_unshadowed_given(r.scene, &lights[0], &s[i], &bsdf[i], wo, 1, &b,
                                                  drift_vec3_make(e[0][i], e[1][i], e[2][i]));
                assert_memory_equal(&pixel, &row, sizeof pixel);
                lit += pixel.x > 0.0f;
                ++checked;
            }
        }
    }
    print_message("%zu pixels, %zu lit, the same value either way\n", checked, lit);
    assert_true(lit > checked / 2 && lit < checked);
    drift_raster_lights_destroy(r.ctx, lights, light_count);
    test_rig_destroy(&r);
}

// A sphere light (radius 0.4 at height 1), wholly above the horizon, partly below it (a wall
// beside and below it: the horizon cuts its cap, Snyder's clipped integral) and wholly below
// it (zero). Before the sphere had its closed form, its diffuse term was 8 samples a pixel.
static void test_unshadowed_sphere_matches_monte_carlo(void **state)
{
    (void)state;
    const unshadowed_case cases[] = {
        { { 0, 0, 0 }, { 0, 1, 0 } },              // straight below
        { { 2, 0.5f, 0.3f }, { -0.6f, 0.8f, 0 } }, // off to the side, tilted
        { { 0.45f, 1.0f, 0 }, { 0, 1, 0 } },       // beside it: the horizon halves the cap
        { { 0.6f, 1.2f, 0 }, { -0.2f, 1, 0 } },    // close: most of the cap below
        { { 0.6f, 1.0f, 0 }, { -0.3f, 1, 0 } },    // close: most of the cap above
        { { 0, 0, 0 }, { 0, -1, 0 } },             // facing away: wholly below the horizon
    };
    check_unshadowed_matches_monte_carlo(&(drift_light){ .type = DRIFT_LIGHT_SPHERE,
                                                         .position = { 0, 1.0f, 0 },
                                                         .radius = 0.4f,
                                                         .color = { 3, 3, 3 } },
                                         cases, sizeof cases / sizeof *cases, 5);
}

// An emissive mesh that tiles a sphere (a UV sphere of radius 0.4, as OBJ exports of a
// sphere emitter are; the Breakfast Room's sun) takes the sphere's closed form: its diffuse
// term matches a Monte Carlo integral over the mesh's own triangles (area sampling, the
// hybrid's) within 1.5%, at the cases of the analytic sphere above. A coarse one (6 x 3,
// whose faces sit well inside the sphere) keeps its samples.
static void test_tessellated_sphere_light_in_closed_form(void **state)
{
    (void)state;
    for (int coarse = 0; coarse < 2; ++coarse) {
        test_rig r = test_rig_begin(1);
        uint32_t white =
            test_add_material(r.scene, drift_material_make(drift_vec3_make(0.8f, 0.5f, 0.2f)));
        drift_material glow = drift_material_make(drift_vec3_splat(0.0f));
        glow.emission = drift_vec3_splat(3.0f);
        uint32_t sun = test_add_material(r.scene, glow);
        test_add_floor(r.scene, 10.0f, -5.0f, white);
        test_add_sphere(r.scene, drift_vec3_make(0, 1, 0), 0.4f, coarse ? 6 : 96, coarse ? 3 : 48,
                        sun);
        test_rig_commit(&r);
        drift_raster_light *lights = NULL;
        uint32_t light_count = 0;
        assert_int_equal(drift_raster_lights_build(r.ctx, r.scene, &lights, &light_count),
                         DRIFT_OK);
        assert_int_equal(light_count, 1);
        print_message("tessellated sphere (%s): stand-in radius %g\n", coarse ? "6 x 3" : "96 x 48",
                      (double)lights[0].sphere_radius);
        if (coarse) {
            assert_true(lights[0].sphere_radius == 0.0f);
        } else {
            assert_near(lights[0].sphere_radius, 0.4, 0.004);
            const unshadowed_case cases[] = {
                { { 0, 0, 0 }, { 0, 1, 0 } },
                { { 2, 0.5f, 0.3f }, { -0.6f, 0.8f, 0 } },
                { { 0.45f, 1.0f, 0 }, { 0, 1, 0 } },
                { { 0.6f, 1.0f, 0 }, { -0.3f, 1, 0 } },
            };
            for (size_t c = 0; c < sizeof cases / sizeof *cases; ++c) {
                drift_surface s = { .position = cases[c].p,
                                    .material = white,
                                    .light = DRIFT_INVALID_INDEX };
                s.ns = s.ng = drift_vec3_normalize(cases[c].n);
                drift_bsdf bsdf = drift_bsdf_make(r.scene, &s);
                drift_sampler sampler = drift_sampler_make(1, 0, 0);
                drift_vec3 closed =
                    drift_raster_unshadowed(r.scene, &lights[0], &s, &bsdf, s.ns, 1, &sampler);
                double mc = 0.0;
                const int n = 400000;
                for (int k = 0; k < n; ++k) {
                    drift_sampler ks = drift_sampler_make(7, 0, (uint32_t)k);
                    float pick = drift_sampler_next1(&ks);
                    drift_light_sample ls = drift_raster_light_sample(
                        r.scene, &lights[0], s.position, pick, drift_sampler_next2(&ks));
                    float cos_i = drift_vec3_dot(ls.wi, s.ns);
                    if (ls.pdf > 0.0f && cos_i > 0.0f) {
                        drift_vec3 f = drift_bsdf_eval(&bsdf, s.ns, ls.wi);
                        mc += (double)(f.x * ls.radiance.x * cos_i / ls.pdf);
                    }
                }
                mc /= n;
                print_message("case %zu: closed form %g, Monte Carlo over the mesh %g\n", c,
                              (double)closed.x, mc);
                assert_near(closed.x, mc, 0.015 * mc);
            }
        }
        drift_raster_lights_destroy(r.ctx, lights, light_count);
        test_rig_destroy(&r);
    }
}

// `hard` shadows under --aa N aim pass k's ray at point k of a stratified set on the light
// (the accumulation buffer's soft shadows): N passes draw the penumbra that one hard ray
// toward the centre leaves out. A floor under a square occluder, lit by one light at a time:
// a quad light, a sphere light and a tessellated sphere (an emissive mesh, the Breakfast
// Room's sun). Each `hard` frame is scored against `reference` shadows at the same passes, so
// the pixel filter is the same and only the shadow differs: 16 passes must come within 0.4 of
// one pass's RMSE, and one pass must still be the centre ray's hard edge.
static void test_aa_hard_shadows_draw_the_penumbra(void **state)
{
    (void)state;
    for (int kind = 0; kind < 3; ++kind) {
        test_rig r = test_rig_begin(2);
        uint32_t white = test_add_material(r.scene, drift_material_make(drift_vec3_splat(0.7f)));
        test_add_floor(r.scene, 4.0f, 0.0f, white);
        test_add_quad(r.scene, drift_vec3_make(-0.5f, 1.0f, -0.5f), drift_vec3_make(1, 0, 0),
                      drift_vec3_make(0, 0, 1), white);
        const drift_vec3 at = drift_vec3_make(0.6f, 3.0f, 0.2f);
        if (kind == 0) {
            test_add_quad_light(r.scene, drift_vec3_sub(at, drift_vec3_make(0.4f, 0, 0.4f)),
                                drift_vec3_make(0.8f, 0, 0), drift_vec3_make(0, 0, 0.8f), 4.0f);
        } else if (kind == 1) {
            drift_light sphere = {
                .type = DRIFT_LIGHT_SPHERE, .position = at, .radius = 0.4f, .color = { 4, 4, 4 }
            };
            assert_int_equal(drift_scene_add_light(r.scene, &sphere, NULL), DRIFT_OK);
        } else {
            drift_material glow = drift_material_make(drift_vec3_splat(0.0f));
            glow.emission = drift_vec3_splat(4.0f);
            test_add_sphere(r.scene, at, 0.4f, 48, 24, test_add_material(r.scene, glow));
        }
        r.scene->camera =
            drift_camera_look_at(drift_vec3_make(0, 5.0f, -0.01f), drift_vec3_make(0, 0, 0),
                                 drift_vec3_make(0, 1, 0), 0.8f, 48, 48);
        test_rig_commit(&r);
        double rmse[2];
        const uint32_t passes[2] = { 1, 16 };
        for (int k = 0; k < 2; ++k) {
            drift_hybrid_params p = { .aa = passes[k], .seed = 3 };
            p.shadows = DRIFT_SHADOWS_REFERENCE;
            // The mesh's triangle picks are noisy: its reference shadows take 4x the samples.
            p.spp = (kind == 2 ? 1024u : 256u) / passes[k];
            test_rig_frame(&r, &p);
            drift_image truth;
            const drift_image *img = drift_hybrid_image(r.frame);
            assert_int_equal(drift_image_create(r.ctx, img->width, img->height, 3, &truth),
                             DRIFT_OK);
            memcpy(truth.pixels, img->pixels, (size_t)img->width * img->height * 3 * sizeof(float));
            p.shadows = DRIFT_SHADOWS_HARD;
            test_rig_frame(&r, &p);
            rmse[k] = test_rmse(r.ctx, drift_hybrid_image(r.frame), &truth);
            if (k == 0) {
                // One pass: every shadow bit is the centre ray's, 0 or 1.
                const drift_image *bits = test_rig_plane(&r, "light0.hard_shadow");
                for (int32_t i = 0; i < bits->width * bits->height; ++i) {
                    float b = bits->pixels[(size_t)i * (size_t)bits->channels];
                    assert_true(b == 0.0f || b == 1.0f);
                }
            }
            drift_image_destroy(r.ctx, &truth);
        }
        print_message("light kind %d: hard against reference shadows, RMSE 1 pass %.4f, 16 "
                      "passes %.4f\n",
                      kind, rmse[0], rmse[1]);
        assert_true(rmse[0] > 0.002); // the penumbra is there to miss
        assert_true(rmse[1] < 0.4 * rmse[0]);
        test_rig_destroy(&r);
    }
}

// `--shadows hard` traces any-hit rays toward a light whose own surface the ray cannot meet
// (flat emitters, spheres: drift_raster_light.shadow_clearance), closest hits otherwise and
// whenever a row reads the occluder distances (`blur`, `isg`). Five lights over a floor
// under an occluder: a quad light, a sphere light, an emissive quad mesh (flat: clearance 0),
// a tessellated sphere (its radius) and an emissive tent (curved: -1, closest hits). The
// hard-shadow bits of `hard` (any-hit) equal those of `blur` (closest hit) at every pixel,
// the emitters' own included (a ray leaving the tessellated sphere's top grazes the quad
// light's plane: stopped only at 1e-4 short of the centre, it met the light itself).
static void test_hard_shadows_any_hit_match_closest_hit(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    uint32_t white = test_add_material(r.scene, drift_material_make(drift_vec3_splat(0.7f)));
    drift_material glow_material = drift_material_make(drift_vec3_splat(0.0f));
    glow_material.emission = drift_vec3_splat(5.0f);
    uint32_t glow = test_add_material(r.scene, glow_material);
    test_add_floor(r.scene, 4.0f, 0.0f, white);
    test_add_quad(r.scene, drift_vec3_make(-0.5f, 1.0f, -0.5f), drift_vec3_make(1, 0, 0),
                  drift_vec3_make(0, 0, 1), white);
    // Heights apart (3.2, 2.8, 3.5, 2.4, 2.6-3.0): a ray lying in a flat light's plane has no
    // answer either query must agree on.
    test_add_quad_light(r.scene, drift_vec3_make(-2.25f, 3.2f, -0.25f), drift_vec3_make(0.5f, 0, 0),
                        drift_vec3_make(0, 0, 0.5f), 4.0f);
    drift_light sphere = { .type = DRIFT_LIGHT_SPHERE,
                           .position = { 2.0f, 2.8f, 0.0f },
                           .radius = 0.3f,
                           .color = { 4, 4, 4 } };
    assert_int_equal(drift_scene_add_light(r.scene, &sphere, NULL), DRIFT_OK);
    test_add_quad(r.scene, drift_vec3_make(-0.25f, 3.5f, -2.25f), drift_vec3_make(0.5f, 0, 0),
                  drift_vec3_make(0, 0, 0.5f), glow);
    test_add_sphere(r.scene, drift_vec3_make(0.0f, 2.4f, 2.0f), 0.3f, 48, 24, glow);
    // A tent opening upward: four triangles down to an apex, facing down and out.
    const float tent[] = { -0.4f, 3.0f,  -0.4f, 0.4f, 3.0f, -0.4f, 0.4f, 3.0f,
                           0.4f,  -0.4f, 3.0f,  0.4f, 0.0f, 2.6f,  0.0f };
    float moved[15];
    for (int k = 0; k < 15; ++k) {
        moved[k] = tent[k] + (k % 3 == 0 ? -2.0f : k % 3 == 2 ? 2.0f : 0.0f);
    }
    const uint32_t tent_index[] = { 0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 4 };
    test_add_mesh(r.scene, moved, 5, tent_index, 4, glow);
    r.scene->camera =
        drift_camera_look_at(drift_vec3_make(0, 6.0f, -5.0f), drift_vec3_make(0, 0, 0),
                             drift_vec3_make(0, 1, 0), 0.9f, 64, 64);
    test_rig_commit(&r);
    drift_raster_light *lights = NULL;
    uint32_t light_count = 0;
    assert_int_equal(drift_raster_lights_build(r.ctx, r.scene, &lights, &light_count), DRIFT_OK);
    assert_int_equal(light_count, 5);
    int seen = 0;
    for (uint32_t l = 0; l < light_count; ++l) {
        const drift_raster_light *h = &lights[l];
        print_message("light %u: type %d, %u triangles, clearance %g\n", l, (int)h->type,
                      h->light_count, (double)h->shadow_clearance);
        if (h->type == DRIFT_LIGHT_QUAD ||
            (h->type == DRIFT_LIGHT_TRIANGLE && h->light_count == 2)) {
            assert_true(h->shadow_clearance == 0.0f);
            seen |= h->type == DRIFT_LIGHT_QUAD ? 1 : 2;
        } else if (h->type == DRIFT_LIGHT_SPHERE) {
            assert_near(h->shadow_clearance, 1.001 * 0.3, 1e-5); // the radius, and a margin
            seen |= 4;
        } else if (h->sphere_radius > 0.0f) {
            assert_true(h->shadow_clearance >= 0.3f && h->shadow_clearance < 0.31f);
            seen |= 8;
        } else {
            assert_true(h->shadow_clearance < 0.0f); // the tent
            seen |= 16;
        }
    }
    assert_int_equal(seen, 31);
    drift_raster_lights_destroy(r.ctx, lights, light_count);
    drift_image bits[2][5];
    drift_shadow_technique shadows[2] = { DRIFT_SHADOWS_HARD, DRIFT_SHADOWS_BLUR };
    for (int t = 0; t < 2; ++t) {
        test_rig_frame(&r, &(drift_hybrid_params){ .shadows = shadows[t] });
        for (uint32_t l = 0; l < 5; ++l) {
            char name[32];
            snprintf(name, sizeof name, "light%u.hard_shadow", l);
            const drift_image *plane = test_rig_plane(&r, name);
            assert_int_equal(drift_image_create(r.ctx, plane->width, plane->height, 1, &bits[t][l]),
                             DRIFT_OK);
            for (int32_t y = 0; y < plane->height; ++y) {
                for (int32_t x = 0; x < plane->width; ++x) {
                    drift_image_pixel(&bits[t][l], x, y)[0] = drift_image_pixel(plane, x, y)[0];
                }
            }
        }
    }
    int64_t shadowed = 0;
    for (uint32_t l = 0; l < 5; ++l) {
        for (int32_t y = 0; y < bits[0][l].height; ++y) {
            for (int32_t x = 0; x < bits[0][l].width; ++x) {
                float a = drift_image_pixel(&bits[0][l], x, y)[0];
                assert_true(a == drift_image_pixel(&bits[1][l], x, y)[0]);
                shadowed += a == 0.0f;
            }
        }
        drift_image_destroy(r.ctx, &bits[0][l]);
        drift_image_destroy(r.ctx, &bits[1][l]);
    }
    print_message("%lld shadowed pixel-lights, the same under any-hit and closest-hit rays\n",
                  (long long)shadowed);
    assert_true(shadowed > 100);
    test_rig_destroy(&r);
}

// The environment's direct light, copied from the frame rendered with `params`.
static drift_image environment_plane(test_rig *r, const drift_hybrid_params *params)
{
    test_rig_frame(r, params);
    const drift_image *plane = test_rig_plane(r, "environment_direct");
    drift_image copy;
    assert_int_equal(drift_image_create(r->ctx, plane->width, plane->height, 3, &copy), DRIFT_OK);
    memcpy(copy.pixels, plane->pixels, sizeof(float) * 3 * (size_t)plane->width * plane->height);
    return copy;
}

// A white floor (albedo 0.7, half size `half`) under a constant sky of 0.5, with a low 2 x 2
// roof over its middle when `roof`, seen from above at 64 x 48.
static test_rig sky_rig(float half, bool roof)
{
    test_rig r = test_rig_begin(2);
    uint32_t white = test_add_material(r.scene, drift_material_make(drift_vec3_splat(0.7f)));
    test_add_floor(r.scene, half, 0.0f, white);
    if (roof) {
        test_add_quad(r.scene, drift_vec3_make(-1.0f, 0.4f, -1.0f), drift_vec3_make(2.0f, 0, 0),
                      drift_vec3_make(0, 0, 2.0f), white);
    }
    r.scene->environment.color = drift_vec3_splat(0.5f);
    r.scene->camera =
        drift_camera_look_at(drift_vec3_make(0, 3.0f, -3.0f), drift_vec3_make(0, 0, 0),
                             drift_vec3_make(0, 1, 0), 0.9f, 64, 48);
    test_rig_commit(&r);
    return r;
}

// Interleaved environment samples (each pixel of a 2 x 2 block a quarter of one set of 8,
// gathered back over 3 x 3 of the same surface) against 2 samples a pixel, the same shadow
// rays: closer to the converged light (a floor under a constant sky, half shaded by a low
// roof, and the roof's top), with the same mean.
static void test_environment_interleave_beats_equal_rays(void **state)
{
    (void)state;
    test_rig r = sky_rig(4.0f, true);
    drift_image truth = environment_plane(&r, &(drift_hybrid_params){ .light_samples = 1024 });
    drift_image plain = environment_plane(&r, &(drift_hybrid_params){ .light_samples = 2 });
    uint64_t plain_rays = drift_hybrid_get_stats(r.frame).rays[DRIFT_PASS_UNSHADOWED];
    drift_image interleaved = environment_plane(
        &r, &(drift_hybrid_params){ .light_samples = 8, .environment_interleave = true });
    uint64_t interleaved_rays = drift_hybrid_get_stats(r.frame).rays[DRIFT_PASS_UNSHADOWED];
    double e_plain = test_rmse(r.ctx, &plain, &truth);
    double e_interleaved = test_rmse(r.ctx, &interleaved, &truth);
    double mean = drift_image_mean_luminance(&interleaved) / drift_image_mean_luminance(&truth);
    print_message("environment light: rmse 2 a pixel %g, interleaved 8 over 2 x 2 %g; rays %llu "
                  "and %llu; interleaved mean / converged %g\n",
                  e_plain, e_interleaved, (unsigned long long)plain_rays,
                  (unsigned long long)interleaved_rays, mean);
    assert_true(interleaved_rays <= plain_rays + plain_rays / 20);
    assert_true(e_interleaved < 0.7 * e_plain);
    assert_near(mean, 1.0, 0.02);
    drift_image_destroy(r.ctx, &truth);
    drift_image_destroy(r.ctx, &plain);
    drift_image_destroy(r.ctx, &interleaved);
    test_rig_destroy(&r);
}

// The environment filter (4 passes of the 3 x 3 a-trous kernel over one shadow ray a pixel)
// against the traced light at 1 and at 2 rays a pixel: closer to the converged light than 2
// rays a pixel, for the rays of 1; the mean kept. (At 64 x 48 the roof's penumbra is a few
// pixels wide, and what the filter blurs there keeps it above 4 rays a pixel; on the 400 x 400
// Breakfast Room it is closer than 8, docs/hybrid.md.) A frame asking for 11 passes is
// refused.
static void test_environment_filter_beats_two_rays(void **state)
{
    (void)state;
    test_rig r = sky_rig(4.0f, true);
    drift_image truth = environment_plane(&r, &(drift_hybrid_params){ .light_samples = 1024 });
    drift_image one = environment_plane(&r, &(drift_hybrid_params){ .light_samples = 1 });
    drift_image two = environment_plane(&r, &(drift_hybrid_params){ .light_samples = 2 });
    drift_image filtered = environment_plane(
        &r, &(drift_hybrid_params){ .light_samples = 1, .environment_filter = 4 });
    double e_one = test_rmse(r.ctx, &one, &truth), e_two = test_rmse(r.ctx, &two, &truth);
    double e_filtered = test_rmse(r.ctx, &filtered, &truth);
    double mean = drift_image_mean_luminance(&filtered) / drift_image_mean_luminance(&truth);
    print_message("environment light: rmse 1 ray a pixel %g, 2 rays %g, 1 ray filtered %g; "
                  "filtered mean / converged %g\n",
                  e_one, e_two, e_filtered, mean);
    assert_true(e_filtered < 0.8 * e_two);
    assert_near(mean, 1.0, 0.02);
    drift_hybrid *h = NULL;
    assert_int_equal(drift_hybrid_create(r.ctx, r.scene, r.accel,
                                         &(drift_hybrid_params){ .environment_filter = 11 }, &h),
                     DRIFT_ERR_INVALID_ARGUMENT);
    assert_null(h);
    drift_image_destroy(r.ctx, &truth);
    drift_image_destroy(r.ctx, &one);
    drift_image_destroy(r.ctx, &two);
    drift_image_destroy(r.ctx, &filtered);
    test_rig_destroy(&r);
}

// The environment's shadow rays at one pixel in 2 x 2 (4 a traced pixel) against 1 a pixel
// everywhere, about the same rays: closer to the converged light (each filled pixel mixes up
// to four 4-ray estimates), the mean kept; the filter over the traced pixels before the fill
// brings 1 ray a traced pixel near 4; and a constant sky over the open floor still exact (kd L)
// at every pixel, filled or traced, filtered or not. Scale 3, and scale 2 with interleaving,
// are refused.
static void test_environment_scale_two_carries_the_light(void **state)
{
    (void)state;
    test_rig r = sky_rig(4.0f, true);
    drift_image truth = environment_plane(&r, &(drift_hybrid_params){ .light_samples = 1024 });
    drift_image full = environment_plane(&r, &(drift_hybrid_params){ .light_samples = 1 });
    uint64_t full_rays = drift_hybrid_get_stats(r.frame).rays[DRIFT_PASS_UNSHADOWED];
    drift_image sparse =
        environment_plane(&r, &(drift_hybrid_params){ .light_samples = 4, .environment_scale = 2 });
    uint64_t sparse_rays = drift_hybrid_get_stats(r.frame).rays[DRIFT_PASS_UNSHADOWED];
    double e_full = test_rmse(r.ctx, &full, &truth), e_sparse = test_rmse(r.ctx, &sparse, &truth);
    double mean = drift_image_mean_luminance(&sparse) / drift_image_mean_luminance(&truth);
    print_message("environment light: rmse 1 ray every pixel %g (%llu rays), 4 rays one pixel in "
                  "2 x 2 %g (%llu rays); mean / converged %g\n",
                  e_full, (unsigned long long)full_rays, e_sparse, (unsigned long long)sparse_rays,
                  mean);
    assert_true(sparse_rays <= full_rays + full_rays / 4);
    assert_true(e_sparse < e_full);
    assert_near(mean, 1.0, 0.02);
    // The filter over the traced pixels alone, before the fill: 1 ray a traced pixel filtered
    // at half the error of 1 unfiltered and within 10% of 4 unfiltered, the mean kept.
    drift_image sparse_one =
        environment_plane(&r, &(drift_hybrid_params){ .light_samples = 1, .environment_scale = 2 });
    double e_sparse_one = test_rmse(r.ctx, &sparse_one, &truth);
    drift_image_destroy(r.ctx, &sparse_one);
    drift_image filtered = environment_plane(&r, &(drift_hybrid_params){ .light_samples = 1,
                                                                         .environment_scale = 2,
                                                                         .environment_filter = 2 });
    double e_filtered = test_rmse(r.ctx, &filtered, &truth);
    double filtered_mean =
        drift_image_mean_luminance(&filtered) / drift_image_mean_luminance(&truth);
    print_message("1 ray one pixel in 2 x 2: rmse %g; filtered over the traced pixels (2 "
                  "passes) %g, mean / converged %g\n",
                  e_sparse_one, e_filtered, filtered_mean);
    assert_true(e_filtered < 0.5 * e_sparse_one && e_filtered < 1.1 * e_sparse);
    assert_near(filtered_mean, 1.0, 0.02);
    drift_image_destroy(r.ctx, &filtered);
    drift_image_destroy(r.ctx, &truth);
    drift_image_destroy(r.ctx, &full);
    drift_image_destroy(r.ctx, &sparse);
    drift_hybrid *h = NULL;
    assert_int_equal(drift_hybrid_create(r.ctx, r.scene, r.accel,
                                         &(drift_hybrid_params){ .environment_scale = 3 }, &h),
                     DRIFT_ERR_INVALID_ARGUMENT);
    assert_int_equal(drift_hybrid_create(r.ctx, r.scene, r.accel,
                                         &(drift_hybrid_params){ .environment_scale = 2,
                                                                 .environment_interleave = true },
                                         &h),
                     DRIFT_ERR_INVALID_ARGUMENT);
    assert_null(h);
    test_rig_destroy(&r);

    test_rig open = sky_rig(40.0f, false);
    for (uint32_t passes = 0; passes <= 2; passes += 2) {
        drift_image e = environment_plane(
            &open, &(drift_hybrid_params){
                       .light_samples = 1, .environment_scale = 2, .environment_filter = passes });
        const drift_gbuffer *gb = drift_hybrid_gbuffer(open.frame);
        double worst = 0.0;
        for (int32_t y = 0; y < e.height; ++y) {
            for (int32_t x = 0; x < e.width; ++x) {
                if (drift_image_pixel(&gb->material_id, x, y)[0] >= 0.0f) {
                    worst = fmax(worst, fabs((double)drift_image_get3(&e, x, y).y - 0.35));
                }
            }
        }
        print_message("open floor, one pixel in 2 x 2 traced, %u filter passes: worst |E - kd "
                      "L| %g\n",
                      passes, worst);
        assert_true(worst < 1e-5);
        drift_image_destroy(open.ctx, &e);
    }
    test_rig_destroy(&open);
}

// A constant sky over an open floor: every cosine-sampled direction sees the sky, and the
// diffuse lobe's f cos / pdf is kd, so one sample a pixel gives the environment's direct light
// kd L exactly (the uniform sphere it replaced left half the samples below the horizon and
// weighed the rest 4 kd cos).
static void test_constant_sky_is_exact_with_one_sample(void **state)
{
    (void)state;
    test_rig r = sky_rig(40.0f, false);
    drift_image e = environment_plane(&r, &(drift_hybrid_params){ .light_samples = 1 });
    const drift_gbuffer *gb = drift_hybrid_gbuffer(r.frame);
    double worst = 0.0;
    int64_t floor_pixels = 0;
    for (int32_t y = 0; y < e.height; ++y) {
        for (int32_t x = 0; x < e.width; ++x) {
            if (drift_image_pixel(&gb->material_id, x, y)[0] < 0.0f) {
                continue;
            }
            ++floor_pixels;
            drift_vec3 v = drift_image_get3(&e, x, y);
            worst = fmax(worst, fabs((double)v.y - 0.35));
        }
    }
    print_message("%lld floor pixels, worst |E - kd L| %g\n", (long long)floor_pixels, worst);
    assert_true(floor_pixels > 1000);
    assert_true(worst < 1e-5);
    drift_image_destroy(r.ctx, &e);
    test_rig_destroy(&r);
}

// --- NAMES AND ARGUMENTS ---

static void test_technique_names_round_trip(void **state)
{
    (void)state;
    for (int e = 0; e < DRIFT_EFFECT_COUNT; ++e) {
        assert_true(drift_technique_count((drift_effect)e) >= 3);
        for (int t = 0; t < drift_technique_count((drift_effect)e); ++t) {
            const char *name = drift_technique_name((drift_effect)e, t);
            assert_non_null(name);
            assert_int_equal(drift_technique_parse((drift_effect)e, name), t);
        }
        assert_null(drift_technique_name((drift_effect)e, drift_technique_count((drift_effect)e)));
        assert_int_equal(drift_technique_parse((drift_effect)e, "bogus"), -1);
    }
    assert_int_equal(drift_technique_parse(DRIFT_EFFECT_SHADOWS, "pcss"), DRIFT_SHADOWS_PCSS);
}

static void test_rejects_bad_params(void **state)
{
    (void)state;
    test_log_capture capture = { 0 };
    test_rig r = { .ctx = test_context(1, &capture) };
    assert_int_equal(drift_scene_create(r.ctx, &r.scene), DRIFT_OK);
    build_room(&r, 16);
    test_rig_commit(&r);
    drift_hybrid *frame = NULL;
    assert_int_equal(drift_hybrid_create(
                         r.ctx, r.scene, r.accel,
                         &(drift_hybrid_params){ .shadows = (drift_shadow_technique)17 }, &frame),
                     DRIFT_ERR_INVALID_ARGUMENT);
    assert_null(frame);
    assert_int_equal(drift_hybrid_create(r.ctx, r.scene, r.accel,
                                         &(drift_hybrid_params){ .shadow_map.pcf_kernel = 200 },
                                         &frame),
                     DRIFT_ERR_INVALID_ARGUMENT);
    assert_true(capture.errors >= 2);
    assert_int_equal(drift_hybrid_create(r.ctx, r.scene, r.accel, NULL, &frame), DRIFT_OK);
    assert_int_equal(drift_hybrid_set_params(frame, &(drift_hybrid_params){ .width = 7 }),
                     DRIFT_ERR_INVALID_ARGUMENT);
    drift_hybrid_destroy(frame);
    test_rig_destroy(&r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_gbuffer_plane),
        cmocka_unit_test(test_gbuffer_sphere),
        cmocka_unit_test(test_all_reference_equals_path_tracer),
        cmocka_unit_test(test_reference_shadows_converge),
        cmocka_unit_test(test_aa_converges_to_pixel_filter),
        cmocka_unit_test(test_hard_shadow_buffer_distances),
        cmocka_unit_test(test_envmap_mirror_sphere_matches_ray_traced),
        cmocka_unit_test(test_post_dof_pinhole_is_identity),
        cmocka_unit_test(test_deterministic_across_threads),
        cmocka_unit_test(test_unshadowed_quad_matches_monte_carlo),
        cmocka_unit_test(test_polygon_rows_equal_the_pixel_path),
        cmocka_unit_test(test_unshadowed_sphere_matches_monte_carlo),
        cmocka_unit_test(test_tessellated_sphere_light_in_closed_form),
        cmocka_unit_test(test_hard_shadows_any_hit_match_closest_hit),
        cmocka_unit_test(test_aa_hard_shadows_draw_the_penumbra),
        cmocka_unit_test(test_environment_interleave_beats_equal_rays),
        cmocka_unit_test(test_environment_filter_beats_two_rays),
        cmocka_unit_test(test_environment_scale_two_carries_the_light),
        cmocka_unit_test(test_constant_sky_is_exact_with_one_sample),
        cmocka_unit_test(test_technique_names_round_trip),
        cmocka_unit_test(test_rejects_bad_params),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
