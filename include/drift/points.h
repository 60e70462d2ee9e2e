// drift points: scene points, area-proportional random samples of the scene's surfaces stored
// as (mesh, triangle, barycentrics) so that they follow moving or deforming meshes, split into
// equal subsets (one per virtual point light in imperfect shadow maps, one per micro-buffer
// in micro-rendering).
//
// Each point is drawn by picking a triangle with probability proportional to its area and a
// uniform point on it (Ritschel et al. 2008, §5.2.1). Point i comes from the Sobol sample i of
// one sampler stream, so every run of consecutive points (a subset) is itself a stratified
// area-proportional sample of the whole scene.
//
// STEP BY STEP
//   drift_points *points = NULL;
//   drift_points_create(ctx, scene, &(drift_points_desc){ .count = 256 * 1024,
//                                                      .subset_count = 256 }, &points);
//   drift_points_update(points, scene);          // after the meshes moved: re-derive positions
//   uint32_t begin, count;
//   drift_points_subset(points, 7, &begin, &count);
//   for (uint32_t i = begin; i < begin + count; ++i) { points->position[i] ... }
//   drift_points_destroy(points);
//
// Ownership: the points own their arrays; the scene is only read (create and update).
// Threads: create and update use the context's pool; reading the arrays is thread-safe.
#ifndef DRIFT_POINTS_H
#define DRIFT_POINTS_H

#include "drift/core.h"
#include "drift/math.h"
#include "drift/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

// Key of the point positions: h = drift_hash_combine(drift_hash_combine(seed,
// DRIFT_POINTS_STREAM), subset). Point k of a subset of n picks its triangle by the area CDF at
// (k + 0.5) / n shifted by h modulo 1 (stratified: each subset's points cover the area evenly)
// and its place on it by the R2 sequence k (0.7549, 0.5698) shifted by hashes of h (Roberts
// 2018): a few arithmetic operations a point where the Owen-scrambled Sobol sampler took ~40%
// of a 400^2 Cornell box's first hybrid frame (issue 40). A subset's points depend only on
// (seed, subset, its size), so a larger set's first subsets are a smaller one's.
#define DRIFT_POINTS_STREAM 0x706e7473u // "pnts"

// One scene point: where it lies on which triangle. Vertex 0 has weight 1 - b1 - b2.
typedef struct drift_scene_point {
    uint32_t mesh;
    uint32_t triangle;
    float b1, b2;
} drift_scene_point;

// How to sample. The default configuration is:
//   count         = 0 -> 65536 points
//   subset_count  = 0 -> 1 (all points in one subset); at most count
//   seed          = 0
//   skip_emissive = false: emissive mesh triangles get points too (they occlude like any other)
typedef struct drift_points_desc {
    uint32_t count;
    uint32_t subset_count;
    uint32_t seed;
    bool skip_emissive;
} drift_points_desc;

drift_points_desc drift_points_desc_resolve(const drift_points_desc *desc);

typedef struct drift_points {
    drift_context *ctx;
    drift_scene_point *points; // count
    drift_vec3 *position;      // count, world space, from the last create or update
    drift_vec3 *normal;        // count, unit geometric normal (the winding's side)
    uint32_t count;
    uint32_t subset_count;
    double area;        // total area of the sampled triangles at the last update, times coverage
    double coverage;    // the share of that area a surface is there (drift_alpha_mode), 0..1
    bool skip_emissive; // from the desc
} drift_points;

// Samples the points of a committed scene. A point drawn where a MASK or BLEND material is not
// there (drift_scene_covers) is drawn again, so the points lie on what rays hit. Errors:
// DRIFT_ERR_INVALID_ARGUMENT (uncommitted scene, no triangles with area, subset_count > count),
// DRIFT_ERR_OUT_OF_MEMORY.
drift_result drift_points_create(drift_context *ctx, const drift_scene *scene,
                                 const drift_points_desc *desc, drift_points **out_points);
void drift_points_destroy(drift_points *points); // NULL-safe

// Re-derives position, normal and area from the scene's current vertices (same meshes and
// triangle counts as at create; DRIFT_ERR_INVALID_ARGUMENT otherwise).
drift_result drift_points_update(drift_points *points, const drift_scene *scene);
// The same for points [first, first + count) only (the area is always recomputed):
// for users that read only some subsets this frame. DRIFT_ERR_INVALID_ARGUMENT past the end.
drift_result drift_points_update_range(drift_points *points, const drift_scene *scene,
                                       uint32_t first, uint32_t count);

// Subset s is the points [begin, begin + count): consecutive, disjoint, sizes differing by at
// most one, covering all points.
void drift_points_subset(const drift_points *points, uint32_t subset, uint32_t *out_begin,
                         uint32_t *out_count);

#ifdef __cplusplus
}
#endif
#endif // DRIFT_POINTS_H
