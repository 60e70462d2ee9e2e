// drift accel: every ray query in drift goes through here. It is the only module that
// includes Embree.
//
// The accel shares the scene's vertex and index arrays with Embree (no copies), so the
// scene must outlive the accel and must not change while it exists. Area lights with a
// shape (quad, disk, sphere) are geometry too, so that rays can hit them.
//
// STEP BY STEP
//   drift_accel *accel = NULL;
//   if (drift_accel_create(ctx, scene, &(drift_accel_desc){ 0 }, &accel) != DRIFT_OK) { ... }
//   drift_hit hit;
//   if (drift_accel_intersect(accel, &ray, &hit)) { ... hit.t, hit.mesh, hit.prim ... }
//   bool blocked = drift_accel_occluded(accel, &shadow_ray);
//   drift_accel_intersect_coherent(accel, rays, hits, count);  // camera rays
//   drift_accel_destroy(accel);
//
// What a hit reports (drift_hit in scene.h):
//   mesh triangle  mesh = mesh index, prim = triangle index, u/v = barycentrics of vertices
//                  1 and 2, ng = (p1 - p0) x (p2 - p0); light = mesh.first_light + prim when
//                  the mesh is emissive, else DRIFT_INVALID_INDEX.
//   quad light     mesh = DRIFT_INVALID_INDEX, light = its index; the quad is the triangles
//                  (c, c+u, c+u+v) (prim 0) and (c, c+u+v, c+v) (prim 1), u/v their
//                  barycentrics, ng = edge_u x edge_v (times a positive factor).
//   disk light     prim 0, u = v = 0, ng = the disk normal (`direction`), unit length.
//   sphere light   prim 0, u = v = 0, ng = hit point - centre (length = radius).
// Every shape is two-sided: a ray hits it from either side, and a ray starting inside a
// sphere light hits its far side; ng does not flip with the side (drift_scene_surface does).
//
// Threads: queries are thread-safe; create/destroy are not. Embree's own build threads
// follow the context's thread count. Embree errors go to the context logger.
#ifndef DRIFT_ACCEL_H
#define DRIFT_ACCEL_H

#include "drift/core.h"
#include "drift/math.h"
#include "drift/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct drift_accel drift_accel;

typedef enum drift_accel_quality {
    DRIFT_ACCEL_QUALITY_DEFAULT = 0, // high-quality BVH (slower build, faster traversal)
    DRIFT_ACCEL_QUALITY_FAST_BUILD,
    DRIFT_ACCEL_QUALITY_COUNT
} drift_accel_quality;

// How to build. The default configuration is:
//   quality            = DEFAULT -> high-quality BVH (Embree RTC_BUILD_QUALITY_HIGH)
//   memory_limit_bytes = 0       -> no limit on what Embree allocates
// Embree's build threads always equal the context's thread count.
typedef struct drift_accel_desc {
    drift_accel_quality quality;
    // Cap on Embree's memory for this accel; a build that needs more fails with
    // DRIFT_ERR_OUT_OF_MEMORY (and Embree's message reaches the logger).
    size_t memory_limit_bytes;
} drift_accel_desc;

drift_accel_desc drift_accel_desc_resolve(const drift_accel_desc *desc);

// Builds the acceleration structure over a committed scene. Retains `scene` (its vertex and
// index arrays are shared with Embree) until drift_accel_destroy. *out_accel is NULL on
// failure. Errors: DRIFT_ERR_INVALID_ARGUMENT (scene not committed, bad desc),
// DRIFT_ERR_EMBREE (Embree failed; its message is logged), DRIFT_ERR_OUT_OF_MEMORY.
drift_result drift_accel_create(drift_context *ctx, const drift_scene *scene,
                                const drift_accel_desc *desc, drift_accel **out_accel);
void drift_accel_destroy(drift_accel *accel); // NULL-safe

// Closest hit with t in [ray.tmin, ray.tmax] (Embree's tnear/tfar). Returns false on a miss
// (out_hit untouched then).
bool drift_accel_intersect(const drift_accel *accel, const drift_ray *ray, drift_hit *out_hit);
// Whether anything is hit with t in [ray.tmin, ray.tmax]. For a shadow ray toward a point at
// distance d along a unit dir, pass tmax slightly below d so the target itself does not count.
bool drift_accel_occluded(const drift_accel *accel, const drift_ray *ray);
// Closest hits for a batch of coherent rays (camera rays of a tile; any count, best in
// multiples of 16); a miss has hits[i].mesh == hits[i].light == DRIFT_INVALID_INDEX and
// t = INFINITY. Same results as drift_accel_intersect ray by ray.
void drift_accel_intersect_coherent(const drift_accel *accel, const drift_ray *rays,
                                    drift_hit *hits, uint32_t count);

// How a ray treats the surfaces of BLEND materials (veils, drift_alpha_mode): by default it meets
// one with probability equal to its opacity; a frame that composites its veils itself traces its
// camera rays past them (SKIP) and then to each of them (MEET).
typedef enum drift_accel_veils {
    DRIFT_VEILS_STOCHASTIC = 0,
    DRIFT_VEILS_SKIP,
    DRIFT_VEILS_MEET
} drift_accel_veils;

// drift_accel_intersect and drift_accel_intersect_coherent with veils treated as `veils` says.
bool drift_accel_intersect_veils(const drift_accel *accel, const drift_ray *ray,
                                 drift_accel_veils veils, drift_hit *out_hit);
void drift_accel_intersect_coherent_veils(const drift_accel *accel, const drift_ray *rays,
                                          drift_hit *hits, uint32_t count, drift_accel_veils veils);
// Occlusion for a batch; out_occluded[i] is 1 when ray i is blocked.
void drift_accel_occluded_coherent(const drift_accel *accel, const drift_ray *rays,
                                   uint8_t *out_occluded, uint32_t count);

#ifdef __cplusplus
}
#endif
#endif // DRIFT_ACCEL_H
