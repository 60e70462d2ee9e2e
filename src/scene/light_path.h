// The first ray of a light path, shared by the techniques that trace paths from the lights:
// instant radiosity's VPLs (src/ism/vpl.c) and micro-rendering's photons (src/micro/photons.c).
// Private to the library: a technique folder includes it as "scene/light_path.h".
#ifndef DRIFT_SCENE_LIGHT_PATH_H
#define DRIFT_SCENE_LIGHT_PATH_H

#include "drift/math.h"
#include "drift/scene.h"

// A point or spot light's first ray and flux, for a caller that samples them its own way
// (ISM importance-samples a reflective shadow map): light `li` picked with probability pmf,
// u1 and u2 the path's next four numbers, `paths` the paths that share the light's power.
typedef bool (*drift_light_path_point_fn)(const void *user, uint32_t li, drift_vec2 u1,
                                          drift_vec2 u2, float pmf, float paths, drift_ray *out_ray,
                                          drift_vec3 *out_flux);

// The first ray of one of `paths` light paths and the flux it carries (the light's power over
// the paths); false when it carries nothing. A light is picked by the scene's light pmf from
// the sampler's next number, then two pairs are drawn: distant lights and the environment
// enter through a disc of `radius` about `centre` that covers the scene, area lights leave a
// uniform point in a cosine direction, and point and spot lights go to `point` (NULL: a
// uniform direction over the sphere or the spot's cone).
bool drift__light_path_emit(const drift_scene *scene, drift_sampler *s, float paths,
                            drift_vec3 centre, float radius, drift_light_path_point_fn point,
                            const void *user, drift_ray *out_ray, drift_vec3 *out_flux);

#endif
