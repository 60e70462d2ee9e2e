// The first ray of a light path (scene/light_path.h).
#include "scene/light_path.h"

#include <math.h>

// A point or spot light's ray in a uniform direction over the sphere or the spot's cone.
static bool emit_point_uniform(const drift_scene *scene, uint32_t li, drift_vec2 u1, drift_vec2 u2,
                               float pmf, float paths, drift_ray *out_ray, drift_vec3 *out_flux)
{
    const drift_light *l = &scene->lights[li];
    float pdf_dir = 1.0f / (4.0f * DRIFT_PI);
    drift_vec3 w;
    if (l->type == DRIFT_LIGHT_SPOT) {
        float cos_max = cosf(l->spot_outer);
        drift_frame fr = drift_frame_from_normal(l->direction);
        w = drift_frame_to_world(&fr, drift_sample_uniform_cone(u1, cos_max));
        pdf_dir = 1.0f / (2.0f * DRIFT_PI * (1.0f - cos_max));
    } else {
        w = drift_sample_uniform_sphere(u1);
    }
    // The intensity toward w: the radiance one unit away (the scene's falloff).
    drift_light_sample ls = drift_light_sample_li(scene, li, drift_vec3_add(l->position, w), u2);
    if (drift_vec3_is_zero(ls.radiance)) {
        return false;
    }
    *out_ray = (drift_ray){ l->position, 0.0f, w, INFINITY, 0 };
    *out_flux = drift_vec3_scale(ls.radiance, 1.0f / (pdf_dir * pmf * paths));
    return true;
}

bool drift__light_path_emit(const drift_scene *scene, drift_sampler *s, float paths,
                            drift_vec3 centre, float radius, drift_light_path_point_fn point,
                            const void *user, drift_ray *out_ray, drift_vec3 *out_flux)
{
    float pmf = 0.0f;
    uint32_t li = drift_scene_pick_light(scene, drift_sampler_next1(s), &pmf);
    drift_vec2 u1 = drift_sampler_next2(s), u2 = drift_sampler_next2(s);
    if (li == DRIFT_INVALID_INDEX || !(pmf > 0.0f)) {
        return false;
    }
    if (li == scene->light_count || scene->lights[li].type == DRIFT_LIGHT_DIRECTIONAL) {
        return drift_light_emit_distant(scene, li, centre, radius, u1, u2, pmf, paths, out_ray,
                                        out_flux);
    }
    const drift_light *l = &scene->lights[li];
    if (l->type == DRIFT_LIGHT_POINT || l->type == DRIFT_LIGHT_SPOT) {
        return point ? point(user, li, u1, u2, pmf, paths, out_ray, out_flux)
                     : emit_point_uniform(scene, li, u1, u2, pmf, paths, out_ray, out_flux);
    }
    // Area lights: a uniform point and a cosine direction, pi A L per path.
    return drift_light_emit_area(scene, l, u1, u2, pmf, paths, out_ray, out_flux);
}
