// Test support for the hybrid-frame tests (see test_rig.h).
#include "test_rig.h"

#include "drift/metric.h"
#include "drift/scene_io.h"
#include "drift_test.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

test_rig test_rig_begin(int threads)
{
    test_rig r = { .ctx = test_context(threads, NULL) };
    assert_int_equal(drift_scene_create(r.ctx, &r.scene), DRIFT_OK);
    return r;
}

test_rig test_rig_load(int threads, const char *repo_path, int32_t w)
{
    test_rig r = { .ctx = test_context(threads, NULL) };
    char path[1024];
    assert_int_equal(drift_scene_load(r.ctx, test_repo_path(path, repo_path), &r.scene), DRIFT_OK);
    r.scene->camera.width = w;
    r.scene->camera.height = w;
    assert_int_equal(drift_accel_create(r.ctx, r.scene, &(drift_accel_desc){ 0 }, &r.accel),
                     DRIFT_OK);
    test_rig_frame(&r, &(drift_hybrid_params){ .width = w, .height = w });
    return r;
}

void test_rig_commit(test_rig *r)
{
    assert_int_equal(drift_scene_commit(r->scene), DRIFT_OK);
    assert_int_equal(drift_accel_create(r->ctx, r->scene, &(drift_accel_desc){ 0 }, &r->accel),
                     DRIFT_OK);
}

void test_rig_frame(test_rig *r, const drift_hybrid_params *params)
{
    drift_hybrid_destroy(r->frame);
    r->frame = NULL;
    assert_int_equal(drift_hybrid_create(r->ctx, r->scene, r->accel, params, &r->frame), DRIFT_OK);
    assert_int_equal(drift_hybrid_render(r->frame, &r->scene->camera, NULL), DRIFT_OK);
}

void test_rig_destroy(test_rig *r)
{
    drift_hybrid_destroy(r->frame);
    drift_accel_destroy(r->accel);
    drift_scene_destroy(r->scene);
    drift_context_destroy(r->ctx);
}

const drift_image *test_rig_plane(const test_rig *r, const char *wanted)
{
    const drift_image *image = drift_hybrid_plane_named(r->frame, wanted);
    if (!image) {
        fail_msg("no plane %s", wanted);
    }
    return image;
}

uint32_t test_add_material(drift_scene *scene, drift_material m)
{
    uint32_t index;
    assert_int_equal(drift_scene_add_material(scene, &m, &index), DRIFT_OK);
    return index;
}

void test_add_quad(drift_scene *scene, drift_vec3 corner, drift_vec3 u, drift_vec3 v,
                   uint32_t material)
{
    drift_vec3 c[4] = { corner, drift_vec3_add(corner, u),
                        drift_vec3_add(drift_vec3_add(corner, u), v), drift_vec3_add(corner, v) };
    float p[12];
    for (int k = 0; k < 4; ++k) {
        p[3 * k] = c[k].x;
        p[3 * k + 1] = c[k].y;
        p[3 * k + 2] = c[k].z;
    }
    const uint32_t idx[] = { 0, 1, 2, 0, 2, 3 };
    test_add_mesh(scene, p, 4, idx, 2, material);
}

void test_add_open_room(drift_scene *scene, float half, uint32_t white, uint32_t left)
{
    const float h = half, top = 3.05f;
    test_add_quad(scene, drift_vec3_make(-h, 0, -h), drift_vec3_make(0, 0, 2 * h),
                  drift_vec3_make(2 * h, 0, 0), white); // floor, up
    test_add_quad(scene, drift_vec3_make(-h, top, -h), drift_vec3_make(2 * h, 0, 0),
                  drift_vec3_make(0, 0, 2 * h), white); // ceiling
    test_add_quad(scene, drift_vec3_make(-h, 0, -h), drift_vec3_make(0, top, 0),
                  drift_vec3_make(0, 0, 2 * h), left); // left wall
    test_add_quad(scene, drift_vec3_make(h, 0, -h), drift_vec3_make(0, 0, 2 * h),
                  drift_vec3_make(0, top, 0), white);
    test_add_quad(scene, drift_vec3_make(-h, 0, h), drift_vec3_make(0, top, 0),
                  drift_vec3_make(2 * h, 0, 0), white);
}

void test_add_quad_light(drift_scene *scene, drift_vec3 corner, drift_vec3 u, drift_vec3 v,
                         float radiance)
{
    drift_light light = { .type = DRIFT_LIGHT_QUAD,
                          .position = corner,
                          .edge_u = u,
                          .edge_v = v,
                          .color = drift_vec3_splat(radiance) };
    assert_int_equal(drift_scene_add_light(scene, &light, NULL), DRIFT_OK);
}

void test_add_floor(drift_scene *scene, float half, float height, uint32_t material)
{
    const float p[] = { -half, height, -half, half,  height, -half,
                        half,  height, half,  -half, height, half };
    const uint32_t idx[] = { 0, 2, 1, 0, 3, 2 };
    test_add_mesh(scene, p, 4, idx, 2, material);
}

uint32_t test_add_sphere(drift_scene *scene, drift_vec3 centre, float radius, uint32_t slices,
                         uint32_t stacks, uint32_t material)
{
    uint32_t vcount = (slices + 1) * (stacks + 1);
    float *p = malloc(sizeof(float) * 3 * vcount);
    float *n = malloc(sizeof(float) * 3 * vcount);
    uint32_t *idx = malloc(sizeof(uint32_t) * 6 * slices * stacks);
    assert_non_null(p);
    assert_non_null(n);
    assert_non_null(idx);
    const float c[3] = { centre.x, centre.y, centre.z };
    for (uint32_t j = 0; j <= stacks; ++j) {
        float theta = 3.14159265f * (float)j / (float)stacks;
        for (uint32_t i = 0; i <= slices; ++i) {
            float phi = 2.0f * 3.14159265f * (float)i / (float)slices;
            uint32_t v = j * (slices + 1) + i;
            float d[3] = { sinf(theta) * cosf(phi), cosf(theta), sinf(theta) * sinf(phi) };
            for (int k = 0; k < 3; ++k) {
                n[3 * v + k] = d[k];
                p[3 * v + k] = c[k] + radius * d[k];
            }
        }
    }
    uint32_t t = 0;
    for (uint32_t j = 0; j < stacks; ++j) {
        for (uint32_t i = 0; i < slices; ++i) {
            uint32_t a = j * (slices + 1) + i, b = a + slices + 1;
            // Outward winding; the poles' degenerate triangles are dropped by the scene.
            uint32_t quad[6] = { a, a + 1, b, a + 1, b + 1, b };
            for (int k = 0; k < 6; ++k) {
                idx[t * 3 + (uint32_t)k] = quad[k];
            }
            t += 2;
        }
    }
    uint32_t mesh;
    assert_int_equal(drift_scene_add_mesh(scene,
                                          &(drift_mesh_desc){ .positions = p,
                                                              .normals = n,
                                                              .vertex_count = vcount,
                                                              .indices = idx,
                                                              .triangle_count = t,
                                                              .material = material },
                                          &mesh),
                     DRIFT_OK);
    free(p);
    free(n);
    free(idx);
    return mesh;
}

double test_rmse(drift_context *ctx, const drift_image *a, const drift_image *b)
{
    double mse = 0.0;
    assert_int_equal(drift_metric_mse(ctx, a, b, &mse), DRIFT_OK);
    return sqrt(mse);
}

double test_nrmse(drift_context *ctx, const drift_image *a, const drift_image *b)
{
    return test_rmse(ctx, a, b) / drift_image_mean_luminance(a);
}

drift_image test_rig_render_pt(test_rig *r, uint32_t components, int32_t max_depth, uint32_t spp,
                               uint32_t seed, drift_pt **pt)
{
    drift_pt_params params = { .width = r->scene->camera.width,
                               .height = r->scene->camera.height,
                               .seed = seed,
                               .max_depth = max_depth,
                               .components = components,
                               .pixel_centre = true,
                               .pinhole = true };
    assert_int_equal(drift_pt_create(r->ctx, r->scene, r->accel, &params, pt), DRIFT_OK);
    assert_int_equal(drift_pt_render_samples(*pt, spp, NULL), DRIFT_OK);
    drift_image img;
    assert_int_equal(drift_pt_resolve(*pt, DRIFT_PT_AOV_BEAUTY, &img), DRIFT_OK);
    return img;
}

void test_add_effects_stage(drift_scene *scene, uint32_t slices, uint32_t stacks, int32_t size)
{
    uint32_t white =
        test_add_material(scene, drift_material_make(drift_vec3_make(0.7f, 0.6f, 0.5f)));
    uint32_t glossy =
        test_add_material(scene, (drift_material){ .diffuse = { 0.3f, 0.1f, 0.1f },
                                                   .specular = { 0.5f, 0.5f, 0.5f },
                                                   .exponent = 40.0f,
                                                   .diffuse_texture = DRIFT_INVALID_INDEX });
    uint32_t mirror =
        test_add_material(scene, (drift_material){ .type = DRIFT_MATERIAL_MIRROR,
                                                   .specular = { 0.9f, 0.9f, 0.9f },
                                                   .diffuse_texture = DRIFT_INVALID_INDEX });
    test_add_floor(scene, 3.0f, -1.0f, white);
    test_add_quad(scene, drift_vec3_make(-3, -1, 2), drift_vec3_make(6, 0, 0),
                  drift_vec3_make(0, 4, 0), white);
    test_add_sphere(scene, drift_vec3_make(-0.6f, -0.5f, 0.5f), 0.5f, slices, stacks, glossy);
    test_add_sphere(scene, drift_vec3_make(0.7f, -0.6f, 0.2f), 0.4f, slices, stacks, mirror);
    test_add_quad_light(scene, drift_vec3_make(-0.5f, 2.0f, -0.5f), drift_vec3_make(1, 0, 0),
                        drift_vec3_make(0, 0, 1), 8.0f); // emits down
    scene->camera =
        drift_camera_look_at(drift_vec3_make(0, 0.5f, -3.0f), drift_vec3_make(0, -0.5f, 0.5f),
                             drift_vec3_make(0, 1, 0), 1.0f, size, size);
    scene->environment.color = drift_vec3_make(0.3f, 0.35f, 0.4f);
    scene->camera.aperture_radius = 0.05f;
    scene->camera.focus_distance = 3.0f;
}

double test_direct_light_mc(const drift_scene *scene, uint32_t light, const drift_surface *s,
                            const drift_bsdf *bsdf, drift_vec3 wo, int n, int channel)
{
    double sum = 0.0;
    for (int k = 0; k < n; ++k) {
        drift_sampler ks = drift_sampler_make(7, 0, (uint32_t)k);
        drift_light_sample ls =
            drift_light_sample_li(scene, light, s->position, drift_sampler_next2(&ks));
        if (ls.pdf > 0.0f) {
            drift_vec3 f = drift_bsdf_eval(bsdf, wo, ls.wi);
            float fl = channel == 0   ? f.x * ls.radiance.x
                       : channel == 1 ? f.y * ls.radiance.y
                                      : f.z * ls.radiance.z;
            sum += (double)(fl * fabsf(drift_vec3_dot(ls.wi, s->ns)) / ls.pdf);
        }
    }
    return sum / n;
}

drift_image test_image_copy(drift_context *ctx, const drift_image *image)
{
    drift_image copy;
    assert_int_equal(drift_image_create(ctx, image->width, image->height, image->channels, &copy),
                     DRIFT_OK);
    memcpy(copy.pixels, image->pixels,
           sizeof(float) * (size_t)image->channels * (size_t)image->width * (size_t)image->height);
    return copy;
}
