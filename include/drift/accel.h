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

// How to build. The default configuration is: high quality, Embree build threads = the
// context's thread count.
typedef struct drift_accel_desc {
    drift_accel_quality quality;
} drift_accel_desc;

// Builds the acceleration structure over a committed scene. Errors:
// DRIFT_ERR_INVALID_ARGUMENT (scene not committed), DRIFT_ERR_EMBREE, DRIFT_ERR_OUT_OF_MEMORY.
drift_result drift_accel_create(drift_context *ctx, const drift_scene *scene,
                                const drift_accel_desc *desc, drift_accel **out_accel);
void drift_accel_destroy(drift_accel *accel); // NULL-safe

// Closest hit in (ray.tmin, ray.tmax). Returns false on a miss (out_hit untouched then).
bool drift_accel_intersect(const drift_accel *accel, const drift_ray *ray, drift_hit *out_hit);
// Any hit in (ray.tmin, ray.tmax).
bool drift_accel_occluded(const drift_accel *accel, const drift_ray *ray);
// Closest hits for a batch of coherent rays (camera rays of a tile); a miss has
// hits[i].mesh == hits[i].light == DRIFT_INVALID_INDEX and t = INFINITY.
void drift_accel_intersect_coherent(const drift_accel *accel, const drift_ray *rays,
                                    drift_hit *hits, uint32_t count);
// Occlusion for a batch; out_occluded[i] is 1 when ray i is blocked.
void drift_accel_occluded_coherent(const drift_accel *accel, const drift_ray *rays,
                                   uint8_t *out_occluded, uint32_t count);

#ifdef __cplusplus
}
#endif
#endif // DRIFT_ACCEL_H
