// Internals of drift ism shared by its files and the unit tests: VPL generation, one
// imperfect shadow map's splatting, pull-push and lookup.
#ifndef DRIFT_ISM_INTERNAL_H
#define DRIFT_ISM_INTERNAL_H

#include "drift/ism.h"

// The VPLs of all bounces, compacted in (bounce, path) order. *out_vpls is owned by the
// caller (drift_free). out_emitted (may be NULL) gets the sum over paths of the flux that
// left the lights (the estimate of the scene's emitted power, RGB).
drift_result drift__ism_generate_vpls(drift_context *ctx, const drift_scene *scene,
                                      const drift_accel *accel, const drift_ism_params *params,
                                      drift_vpl **out_vpls, uint32_t *out_count,
                                      drift_vec3 *out_emitted);

// The most VPLs drift__ism_generate_vpls can make with these (resolved) parameters.
uint32_t drift__ism_max_vpls(const drift_ism_params *params);

// Sizes the atlas and the scene points for at least `vpls` maps (at most the max above);
// a render calls it with its VPL count. Growing re-samples the points, with the same result.
drift_result drift__ism_reserve(drift_ism *ism, uint32_t vpls);
// How many maps the atlas and the points hold now.
uint32_t drift__ism_map_capacity(const drift_ism *ism);

// What splatting one map needs.
typedef struct drift__ism_splat_desc {
    int32_t n;          // the map is n x n texels
    float point_radius; // sqrt(A_pt / pi): the radius of the disc one point stands for
    float splat_scale;  // k
} drift__ism_splat_desc;

// Splats `count` points into the n x n depth map `depth` (filled with INFINITY first) of a
// VPL at `origin` with frame `frame` (z = its normal), keeping the nearest distance per texel.
void drift__ism_splat(float *depth, const drift__ism_splat_desc *desc, drift_vec3 origin,
                      const drift_frame *frame, const drift_vec3 *positions, uint32_t count);

// The exact n x n paraboloid depth map of a VPL at `origin` (frame z = its normal): one ray
// through each texel centre inside the disc, the nearest hit's distance (INFINITY: a miss or
// outside the disc). The CPU's classic shadow map, against which ISMs are timed.
void drift__ism_exact_map(float *depth, int32_t n, const drift_accel *accel, drift_vec3 origin,
                          const drift_frame *frame);

// Pull-push hole filling of an n x n map over `levels` levels with the level-0 threshold
// `threshold`; scratch holds at least n * n floats (levels <= 7). Returns the number of texels
// inside the unit disc still empty.
uint32_t drift__ism_pull_push(float *depth, int32_t n, int32_t levels, float threshold,
                              float *scratch);

// The texel of the map that direction `local` (unit, in the VPL's frame, z > 0) falls in.
static inline int32_t drift__ism_texel(int32_t n, drift_vec3 local)
{
    drift_vec2 p = drift_paraboloid_project(local);
    int32_t x = (int32_t)((p.x * 0.5f + 0.5f) * (float)n);
    int32_t y = (int32_t)((p.y * 0.5f + 0.5f) * (float)n);
    x = x < 0 ? 0 : (x >= n ? n - 1 : x);
    y = y < 0 ? 0 : (y >= n ? n - 1 : y);
    return y * n + x;
}

#endif
