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

// Mip-map pyramids of the textures materials read (texture.c), built by commit.
typedef struct drift_texture_pyramid drift_texture_pyramid;
drift_result drift__texture_pyramids_build(drift_scene *scene);
void drift__texture_pyramids_destroy(drift_scene *scene);
// Texture `index` read through `map` (NULL: the default) at drift's bottom-up uv, at the mip
// level of a footprint `footprint` wide in uv units (0: full size).
drift_vec3 drift__texture_sample(const drift_scene *scene, uint32_t index,
                                 const drift_texture_map *map, drift_vec2 uv, float footprint);
// The surface of triangle `triangle` of mesh `mesh` at barycentrics (u, v), seen from its front.
// Whether emissive mesh `mesh` is closed and its front faces face the camera's side of it
// (then its faces turned away emit nothing the camera's side can receive;
// src/scene/closed_emitter.c).
bool drift__closed_emitter_front_only(const drift_scene *scene, uint32_t mesh);

drift_surface drift__triangle_surface(const drift_scene *scene, uint32_t mesh, uint32_t triangle,
                                      float u, float v);
// The emission of material m at a surface point (its emissive texture applied).
drift_vec3 drift__material_emission(const drift_scene *scene, const drift_material *m,
                                    const drift_surface *surface);
// Per-vertex tangents of a mesh with normals and uvs (uv set `uv_set`), MikkTSpace-style
// (tangents.c): 4 floats a vertex into *out (allocated).
drift_result drift__mesh_tangents(drift_context *ctx, const drift_mesh *mesh, int uv_set,
                                  float **out);

#endif
