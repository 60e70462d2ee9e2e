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

// The same with params->vpl_importance: `count` camera-visible points (positions, shading
// normals) that candidate VPLs are weighed against; none: every candidate is kept.
drift_result drift__ism_generate_vpls_for(drift_context *ctx, const drift_scene *scene,
                                          const drift_accel *accel, const drift_ism_params *params,
                                          const drift_vec3 *points, const drift_vec3 *normals,
                                          uint32_t count, drift_vpl **out_vpls, uint32_t *out_count,
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
// `threshold`; scratch holds at least 2 n^2 floats (n^2 for even n; levels <= 7). Returns the
// number of texels inside the unit disc still empty.
uint32_t drift__ism_pull_push(float *depth, int32_t n, int32_t levels, float threshold,
                              float *scratch);

// Pull-push with the push left to the lookups ("only where needed": the gather reads ~1 texel
// in 7 of a 256^2 map). A map then holds its n^2 depths followed, for each level l = 1..levels,
// by the pulled level's depths and member counts (ceil(n / 2^l)^2 floats each); the lookup
// replays the push along the texel's ancestors only, giving the eager drift__ism_pull_push's
// value to the bit (tested). drift__ism_map_floats is one map's size; levels 0..2.
size_t drift__ism_map_floats(int32_t n, int32_t levels);
// Splatted depths in map[0, n^2) -> the pulled levels after them.
void drift__ism_pull(float *map, int32_t n, int32_t levels, float threshold);
// Texels inside the unit disc that the push leaves empty; `counts` (levels >= 1): the disc
// texels under each top-level texel, from drift__ism_disc_counts (ceil(n / 2^levels)^2 floats).
void drift__ism_disc_counts(int32_t n, int32_t levels, float *counts);
uint32_t drift__ism_holes(const float *map, int32_t n, int32_t levels, const float *counts);

// The pushed depth of texel (x, y) of a map with its pulled levels (levels 0..2). Written for
// the gather's vectorised loop: 32-bit indices (64-bit ones kept the loads scalar) and one
// float select at a time (boolean operators between comparisons mix mask widths, which the
// vectoriser refuses). The _at form takes the levels' pointers (l[0] the depths, l[1], l[2]
// level 1's depths and member counts, l[3], l[4] level 2's; drift__ism_levels_of), so that a
// loop over receivers computes them once.
static inline void drift__ism_levels_of(const float *map, int32_t n, const float *l[5])
{
    int32_t s1 = (n + 1) / 2, s2 = (s1 + 1) / 2;
    l[0] = map;
    l[1] = map + n * n;
    l[2] = l[1] + s1 * s1;
    l[3] = l[2] + s1 * s1;
    l[4] = l[3] + s2 * s2;
}

static inline float drift__ism_lookup_at(const float *depth, const float *p1, const float *m1,
                                         const float *p2, const float *m2, int32_t n,
                                         int32_t levels, float threshold, int32_t x, int32_t y)
{
    float v = depth[y * n + x];
    if (levels <= 0) {
        return v;
    }
    int32_t s1 = (n + 1) / 2, s2 = (s1 + 1) / 2;
    int32_t i1 = (y >> 1) * s1 + (x >> 1);
    float v1 = p1[i1];
    if (levels >= 2) {
        int32_t i2 = (y >> 2) * s2 + (x >> 2);
        float top = p2[i2], behind = m2[i2] >= 3.0f ? top + 2.0f * threshold : INFINITY;
        float pushed = v1 > behind ? top : v1;
        pushed = v1 == INFINITY ? top : pushed;
        v1 = top < INFINITY ? pushed : v1;
    }
    float behind = m1[i1] >= 3.0f ? v1 + threshold : INFINITY;
    float pushed = v > behind ? v1 : v;
    pushed = v == INFINITY ? v1 : pushed;
    return v1 < INFINITY ? pushed : v;
}

static inline float drift__ism_lookup(const float *map, int32_t n, int32_t levels, float threshold,
                                      int32_t x, int32_t y)
{
    const float *l[5];
    drift__ism_levels_of(map, n, l);
    return drift__ism_lookup_at(l[0], l[1], l[2], l[3], l[4], n, levels, threshold, x, y);
}

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
