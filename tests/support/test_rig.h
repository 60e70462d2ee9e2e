// Test support for the hybrid-frame tests: a scene, its accelerator and one frame held
// together (a "rig"), and the small scene pieces several tests build with.
#ifndef DRIFT_TEST_RIG_H
#define DRIFT_TEST_RIG_H

#include "drift/accel.h"
#include "drift/hybrid.h"
#include "drift/pt.h"
#include "drift/scene.h"

typedef struct test_rig {
    drift_context *ctx;
    drift_scene *scene;
    drift_accel *accel;
    drift_hybrid *frame;
} test_rig;

// A context with `threads` threads and an empty scene.
test_rig test_rig_begin(int threads);
// A context with `threads` threads, the repository's scene `repo_path` at w x w pixels, its
// accelerator, and a first frame (drift_hybrid_params' defaults) rendered from its camera.
test_rig test_rig_load(int threads, const char *repo_path, int32_t w);
// Commits the scene and builds its accelerator.
void test_rig_commit(test_rig *r);
// Replaces the rig's frame by one made with `params` and renders it from the scene camera.
void test_rig_frame(test_rig *r, const drift_hybrid_params *params);
void test_rig_destroy(test_rig *r);
// The frame's plane named `wanted`; fails the test when there is none.
const drift_image *test_rig_plane(const test_rig *r, const char *wanted);
// A copy of `image` (a frame's planes are replaced by its next render); free with
// drift_image_destroy.
drift_image test_image_copy(drift_context *ctx, const drift_image *image);

uint32_t test_add_material(drift_scene *scene, drift_material m);
// The quad corner, corner + u, corner + u + v, corner + v (two triangles, wound as listed).
void test_add_quad(drift_scene *scene, drift_vec3 corner, drift_vec3 u, drift_vec3 v,
                   uint32_t material);
// A quad light of `radiance` at corner, corner + u, corner + u + v, corner + v, emitting along
// cross(u, v).
void test_add_quad_light(drift_scene *scene, drift_vec3 corner, drift_vec3 u, drift_vec3 v,
                         float radiance);
// A room of half width `half` and height 3.05 open toward -z: floor, ceiling, the left (x =
// -half) wall in `left`, the right and back (z = +half) walls in `white`, all facing in.
void test_add_open_room(drift_scene *scene, float half, uint32_t white, uint32_t left);
// Square of half size `half` in the plane y = height, facing +y.
void test_add_floor(drift_scene *scene, float half, float height, uint32_t material);
// UV sphere with smooth normals and outward winding; returns its mesh index.
uint32_t test_add_sphere(drift_scene *scene, drift_vec3 centre, float radius, uint32_t slices,
                         uint32_t stacks, uint32_t material);
// Direct light at `s` from the scene's light `light` by n light samples (seed 7, sample k):
// the Monte Carlo truth a closed form of one light is compared with; `channel` 0, 1 or 2.
double test_direct_light_mc(const drift_scene *scene, uint32_t light, const drift_surface *s,
                            const drift_bsdf *bsdf, drift_vec3 wo, int n, int channel);
// Every effect at once on a size x size camera: a floor and a back wall, a glossy and a mirror
// sphere (slices x stacks), one quad light emitting down, an environment (for occlusion) and a
// lens (for depth of field).
void test_add_effects_stage(drift_scene *scene, uint32_t slices, uint32_t stacks, int32_t size);

// The path tracer's image of the rig's scene camera through the pixel centres, pinhole, with
// only `components` (DRIFT_PT_COMPONENT_*) up to max_depth, at spp samples: the truth a
// hybrid term is compared with. *pt owns the image; destroy it after use.
struct drift_image;
drift_image test_rig_render_pt(test_rig *r, uint32_t components, int32_t max_depth, uint32_t spp,
                               uint32_t seed, struct drift_pt **pt);

// RMSE over the three colour channels of two images of one size (drift_metric_mse).
double test_rmse(drift_context *ctx, const drift_image *a, const drift_image *b);
// test_rmse of b against a over a's mean luminance (drift_image_mean_luminance).
double test_nrmse(drift_context *ctx, const drift_image *a, const drift_image *b);

#endif
