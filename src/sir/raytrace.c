// The paper's "pure ray tracer" (Table 1): per sample one primary ray through the pixel
// centre (through the thin lens when the camera has an aperture), at every hit one shadow
// ray per light and one reflection ray, recursively to max_depth reflections. It sums the
// same terms as the hybrid frame with indirect light off, so where the raster is exact the
// two agree: emission, direct light of the non-delta lobes (shadow rays instead of shadow
// maps), the environment's direct light, and reflections (mirror: everything seen; glossy:
// the reflected part, as the direct term already holds the emitters seen through the lobe).
// The environment has no centre and no shadow map: the hybrid frame ray-traces its direct
// light in every technique, and so does this tracer, with the same estimator and ray count
// (docs/sir.md).
#include "sir/sir.h"

#include <math.h>

drift_refine_tracer drift_refine_tracer_make(const drift_frame_state *frame, uint32_t seed,
                                             int32_t max_depth)
{
    return (drift_refine_tracer){ .scene = frame->scene,
                                  .accel = frame->accel,
                                  .lights = frame->lights,
                                  .light_count = frame->light_count,
                                  .camera = drift_camera_frame_make(
                                      &frame->camera, frame->params.width, frame->params.height),
                                  .seed = drift_hash_combine(seed, DRIFT_STREAM_SIR_TRACE),
                                  .max_depth = max_depth,
                                  .light_samples = frame->params.light_samples,
                                  .reflection_edits = frame->params.reflection_edits };
}

// light_samples sampled points on each light, each with a shadow ray: an unbiased estimate of
// sum_l U_l S_l with as many samples as the raster spends on U_l (delta lights take one).
static drift_vec3 direct_light(const drift_refine_tracer *t, const drift_surface *s,
                               const drift_bsdf *bsdf, drift_vec3 wo, drift_sampler *sampler,
                               uint64_t *rays)
{
    drift_vec3 sum = drift_vec3_splat(0.0f);
    for (uint32_t l = 0; l < t->light_count; ++l) {
        const drift_raster_light *light = &t->lights[l];
        uint32_t n = drift_light_is_area(light->type) || light->light_cdf ? t->light_samples : 1;
        n = n ? n : 1;
        drift_vec3 light_sum = drift_vec3_splat(0.0f);
        for (uint32_t k = 0; k < n; ++k) {
            float pick = drift_sampler_next1(sampler);
            drift_vec2 u = drift_sampler_next2(sampler);
            drift_light_sample ls =
                drift_raster_light_sample(t->scene, light, s->position, pick, u);
            if (!(ls.pdf > 0.0f) || drift_vec3_is_zero(ls.radiance)) {
                continue;
            }
            drift_vec3 f = drift_bsdf_eval(bsdf, wo, ls.wi);
            float cos_i = fabsf(drift_vec3_dot(ls.wi, s->ns));
            if (drift_vec3_is_zero(f) || cos_i <= 0.0f) {
                continue;
            }
            drift_ray shadow = { .origin = drift_offset_origin(s->position, s->ng, ls.wi),
                                 .dir = ls.wi,
                                 .tmin = 0.0f,
                                 .tmax = isfinite(ls.distance) ? ls.distance * (1.0f - 1e-4f)
                                                               : INFINITY };
            ++*rays;
            if (!drift_accel_occluded(t->accel, &shadow)) {
                light_sum =
                    drift_vec3_fma(light_sum, drift_vec3_mul(f, ls.radiance), cos_i / ls.pdf);
            }
        }
        sum = drift_vec3_fma(sum, light_sum, 1.0f / (float)n);
    }
    return sum;
}

// The sampler pairs direct_light and the environment's estimator draw at a hit: a
// reflection-only sample skips them and still draws its lobe direction from the same pair as
// the full sample, so its R is the full sample's R exactly.
static uint32_t direct_light_pairs(const drift_refine_tracer *t)
{
    uint32_t pairs = drift_scene_has_environment(t->scene) ? 1u : 0u;
    for (uint32_t l = 0; l < t->light_count; ++l) {
        const drift_raster_light *light = &t->lights[l];
        uint32_t n = drift_light_is_area(light->type) || light->light_cdf ? t->light_samples : 1;
        pairs += 2u * (n ? n : 1u);
    }
    return pairs;
}

// A direction from the Phong lobe cos^n around the mirror direction r, and its weight
// f_glossy cos / pdf = ks (n + 2) / (n + 1) cos(theta_i) (zero below the surface).
static drift_vec3 sample_glossy(const drift_bsdf *bsdf, drift_vec3 wo, drift_vec3 ng, drift_vec2 u,
                                drift_vec3 *out_dir)
{
    float n = bsdf->exponent;
    drift_vec3 wi = drift_bsdf_sample_glossy_lobe(bsdf, wo, u);
    *out_dir = wi;
    float cos_i = drift_vec3_dot(wi, bsdf->frame.z);
    if (cos_i <= 0.0f || drift_vec3_dot(wi, ng) * drift_vec3_dot(wo, ng) <= 0.0f) {
        return drift_vec3_splat(0.0f);
    }
    return drift_vec3_scale(bsdf->specular, (n + 2.0f) / (n + 1.0f) * cos_i);
}

// Radiance back along ray. see_emission: emitters and the environment seen by this ray count
// (camera and mirror rays; glossy rays leave them to the direct term). reflection_only: this
// hit's emission and direct light are left out (the raster keeps them), only what its
// reflection ray brings back counts.
static drift_vec3 radiance(const drift_refine_tracer *t, drift_ray ray, int32_t depth,
                           bool see_emission, bool reflection_only, drift_sampler *sampler,
                           uint64_t *rays)
{
    ++*rays;
    drift_hit hit;
    if (!drift_accel_intersect(t->accel, &ray, &hit)) {
        return see_emission && drift_scene_has_environment(t->scene)
                   ? drift_environment_eval(t->scene, ray.dir)
                   : drift_vec3_splat(0.0f);
    }
    drift_surface s = drift_scene_surface(t->scene, &ray, &hit);
    drift_vec3 l = see_emission && !reflection_only ? s.emission : drift_vec3_splat(0.0f);
    if (s.material == DRIFT_INVALID_INDEX) {
        return l;
    }
    drift_bsdf bsdf = drift_bsdf_make(t->scene, &s);
    drift_vec3 wo = drift_vec3_neg(ray.dir);
    if (reflection_only) {
        if (!drift_bsdf_is_delta(&bsdf)) {
            sampler->dimension += direct_light_pairs(t);
        }
    } else if (!drift_bsdf_is_delta(&bsdf)) {
        l = drift_vec3_add(l, direct_light(t, &s, &bsdf, wo, sampler, rays));
        l = drift_vec3_add(l, drift_raster_environment_direct(t->scene, t->accel, &s, &bsdf, wo,
                                                              t->light_samples, sampler, rays));
    }
    bool mirror = bsdf.type == DRIFT_MATERIAL_MIRROR;
    bool reflective = !drift_vec3_is_zero(bsdf.specular) && (mirror || bsdf.exponent > 0.0f);
    drift_vec2 u = drift_sampler_next2(sampler);
    if (!reflective || depth >= t->max_depth) {
        return l;
    }
    if (depth == 0) {
        // The camera ray's reflection follows the edit, as the hybrid frame's sharp ray does;
        // its direct term above stays physical, as the frame's direct pass.
        drift_reflection_edits_aim_bsdf(t->reflection_edits, &s, wo, &bsdf);
    }
    drift_vec3 dir, weight;
    if (mirror) {
        dir = drift_bsdf_mirror_direction(&bsdf, wo);
        weight = bsdf.specular;
    } else {
        weight = sample_glossy(&bsdf, wo, s.ng, u, &dir);
    }
    if (drift_vec3_is_zero(weight)) {
        return l;
    }
    drift_ray next = { .origin = drift_offset_origin(s.position, s.ng, dir),
                       .dir = dir,
                       .tmin = 0.0f,
                       .tmax = INFINITY };
    drift_vec3 seen = radiance(t, next, depth + 1, mirror, false, sampler, rays);
    return drift_vec3_add(l, drift_vec3_mul(weight, seen));
}

drift_vec3 drift_refine_trace_ray(const drift_refine_tracer *t, drift_ray ray, bool see_emission,
                                  drift_sampler *sampler, uint64_t *rays)
{
    drift_vec3 l = radiance(t, ray, 1, see_emission, false, sampler, rays);
    return drift_vec3_is_finite(l) ? l : drift_vec3_splat(0.0f);
}

drift_vec3 drift_refine_trace_sample(const drift_refine_tracer *t, int32_t x, int32_t y,
                                     uint32_t sample, bool reflection_only, uint64_t *rays)
{
    uint32_t pixel = (uint32_t)y * (uint32_t)t->camera.width + (uint32_t)x;
    drift_sampler sampler = drift_sampler_make(t->seed, pixel, sample);
    // Component samples are pinhole only (refine.c): the lens pair is skipped, not drawn.
    drift_vec2 lens = drift_vec2_make(0.5f, 0.5f);
    if (reflection_only) {
        ++sampler.dimension;
    } else {
        lens = drift_sampler_next2(&sampler);
    }
    // Through the pixel centre, as the G-buffer: the comparison is of effects, not of
    // antialiasing.
    drift_ray ray = drift_camera_frame_ray(&t->camera, (float)x + 0.5f, (float)y + 0.5f, lens);
    drift_vec3 l = radiance(t, ray, 0, true, reflection_only, &sampler, rays);
    return drift_vec3_is_finite(l) ? l : drift_vec3_splat(0.0f);
}
