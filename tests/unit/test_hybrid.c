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
#include "hybrid/hybrid_tests.h"
#include "raster/raster.h"
#include "test_rig.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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
        cmocka_unit_test(test_two_sided_mesh_light_closed_form),
        cmocka_unit_test(test_two_sided_emitter_lights_hybrid_frame),
        cmocka_unit_test(test_closed_two_sided_emitter_is_one_sided),
        cmocka_unit_test(test_technique_names_round_trip),
        cmocka_unit_test(test_rejects_bad_params),
    };
    if (getenv("DRIFT_TEST_FILTER")) {
        cmocka_set_test_filter(getenv("DRIFT_TEST_FILTER")); // e.g. "test_two_sided*"
    }
    return cmocka_run_group_tests(tests, NULL, NULL);
}
