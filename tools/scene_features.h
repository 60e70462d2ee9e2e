// Cheap features of a loaded scene for the technique chooser (issue 40): what drift render
// --budget-ms measures at load and drift bench frontier --corpus --json records a scene, so
// that scripts/chooser/fit_table.py fits on the same numbers the renderer sees.
#ifndef DRIFT_SCENE_FEATURES_H
#define DRIFT_SCENE_FEATURES_H

#include "drift/accel.h"
#include "drift/scene.h"

// The features, in this order (names from scene_feature_name):
//   log_triangles  log10(1 + triangles)
//   log_lights     log10(1 + lights): emissive triangles count one each
//   area_share     share of the lights with an area (quad, disk, sphere, triangle)
//   delta_share    share of the lights without one (point, spot, directional)
//   environment    1 with an environment that is not black, else 0
//   glossy_share   share of the triangle area whose material reflects glossily or as a mirror
//   emissive_share share of the triangle area that emits
//   lens           1 when the camera has an aperture, else 0
//   depth_range    log10 of the scene's extent over the camera's distance to its centre
//   log_rays       log10 of the rays a path-tracer sample casts (camera, shadow, bounce),
//                  measured by a 16 x 16, 1 spp, depth 8 probe (seed 1: deterministic; a
//                  few ms): what a sample costs beyond the triangles; 0 without an accel
#define SCENE_FEATURE_COUNT 10

const char *scene_feature_name(int k);
void scene_features(drift_context *ctx, const drift_scene *scene, const drift_accel *accel,
                    double out[SCENE_FEATURE_COUNT]);

#endif
