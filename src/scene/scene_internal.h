// Private to src/scene (and the scene loaders in src/io): pieces shared between scene.c and
// the light/BSDF code.
#ifndef DRIFT_SCENE_INTERNAL_H
#define DRIFT_SCENE_INTERNAL_H

#include "drift/scene.h"

// Bounds of all mesh vertices added so far (commit adds the light shapes for scene->bounds;
// the loaders frame a default camera on it before commit).
drift_bounds3 drift__scene_mesh_bounds(const drift_scene *scene);

// Builds scene->light_table (power distribution over lights and the environment).
drift_result drift__light_table_build(drift_scene *scene);
void drift__light_table_destroy(drift_scene *scene);

// Piecewise-constant distribution over a lat-long environment map, proportional to
// luminance x sin(theta), for importance sampling (pbrt-v4 §12.5.2, discrete 2-D case).
typedef struct drift__env_distribution {
    int32_t width, height;
    float *conditional_cdf; // height rows of width + 1 entries
    float *marginal_cdf;    // height + 1 entries
    float *row_weight;      // height entries: integral of row j (un-normalized)
    double total;           // sum of all weights
} drift__env_distribution;

drift_result drift__environment_build(drift_scene *scene, drift__env_distribution **out_dist);
void drift__environment_destroy(drift_scene *scene, drift__env_distribution *dist);
// Average luminance of the environment over the sphere (for light power).
float drift__environment_average(const drift_scene *scene);
const drift__env_distribution *drift__light_table_environment(const drift_scene *scene);

// Bilinear lookup with repeat wrapping; uv origin bottom-left (OBJ/glTF convention
// flipped accordingly by loaders: v = 0 is the image's bottom row).
drift_vec3 drift__texture_bilinear(const drift_image *texture, drift_vec2 uv);

#endif
