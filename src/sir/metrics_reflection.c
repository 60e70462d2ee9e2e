// SIR's reflection metrics (paper §5): reflection1..5 on reflective material (a specular
// lobe): 1; |p - c| / max |q - c| over the scene bounds (c the environment probe); <-i, r>;
// <-i, n>; the ambient occlusion k_a; and the expected display error of the raster reflection
// that orders the pixels (metrics.c drives them).
#include "sir/metrics_internal.h"

#include <stdlib.h>
#include <string.h>

static bool is_reflective(const drift_frame_state *f, const drift_surface *s)
{
    if (s->material == DRIFT_INVALID_INDEX) {
        return false;
    }
    const drift_material *m = &f->scene->materials[s->material];
    return !drift_vec3_is_zero(m->specular) &&
           (m->type == DRIFT_MATERIAL_MIRROR || m->exponent > 0.0f);
}

// The environment map's centre for a pixel of `mesh`: its probe when captured, else where the
// frame would put the scene probe.
static drift_vec3 probe_centre(const drift_frame_state *f, uint32_t mesh)
{
    const drift_envmap *map = drift_realtime_probe_of(f, mesh);
    if (map) {
        return drift_envmap_probe(map);
    }
    if (f->params.envmap.has_probe) {
        return f->params.envmap.probe;
    }
    return drift_vec3_scale(drift_vec3_add(f->scene->bounds.min, f->scene->bounds.max), 0.5f);
}

// The farthest a point of the scene can be from c: the farthest corner of the bounds.
static float max_distance(const drift_scene *scene, drift_vec3 c)
{
    float best = 0.0f;
    for (int k = 0; k < 8; ++k) {
        drift_vec3 corner = { (k & 1) ? scene->bounds.max.x : scene->bounds.min.x,
                              (k & 2) ? scene->bounds.max.y : scene->bounds.min.y,
                              (k & 4) ? scene->bounds.max.z : scene->bounds.min.z };
        best = fmaxf(best, drift_vec3_length(drift_vec3_sub(corner, c)));
    }
    return best;
}

static float ambient_occlusion(const drift_frame_state *f, const drift_surface *s, float radius,
                               uint32_t samples, drift_sampler *sampler, uint64_t *rays)
{
    drift_frame frame = drift_frame_from_normal(s->ns);
    uint32_t hits = 0;
    for (uint32_t k = 0; k < samples; ++k) {
        drift_vec3 dir = drift_frame_to_world(
            &frame, drift_sample_cosine_hemisphere(drift_sampler_next2(sampler)));
        drift_ray ray = { .origin = drift_offset_origin(s->position, s->ng, dir),
                          .dir = dir,
                          .tmin = 0.0f,
                          .tmax = radius };
        ++*rays;
        hits += drift_accel_occluded(f->accel, &ray) ? 1u : 0u;
    }
    return samples ? (float)hits / (float)samples : 0.0f;
}

static drift_vec3 seen_in_map(const drift_envmap *map, drift_vec3 dir, float cone, bool mirror)
{
    drift_raster_radiance l = drift_envmap_lookup(map, dir, cone);
    return mirror ? drift_vec3_add(l.emitted, l.reflected) : l.reflected;
}

// The most lobe rays a pixel's expected reflection error keeps for shading.
#define MAX_LOBE_RAYS 16
// Shadow rays a light for each lobe ray's hit when shading what a hidden q shows.
#define HIDDEN_LIGHT_SAMPLES 2

// The expected reflection error where the map cannot see q: the lobe rays' hits shaded by the
// pure ray tracer's direct light (one bounce), as it estimates R: each sample of the Phong lobe
// weighs ks (n + 2) / (n + 1) cos theta_i (a mirror: ks), escaped and below-surface samples
// count zero. Against the raster's R, in display values.
static float hidden_reflection_error(drift_frame_state *f, size_t index, const drift_bsdf *bsdf,
                                     const drift_ray *lobe, uint32_t lobe_count, uint32_t samples,
                                     drift_vec3 raster, drift_sampler *sampler, uint64_t *rays)
{
    bool mirror = bsdf->type == DRIFT_MATERIAL_MIRROR;
    drift_refine_tracer tracer = drift_refine_tracer_make(f, 0, 1);
    tracer.light_samples = HIDDEN_LIGHT_SAMPLES;
    drift_vec3 sum = drift_vec3_splat(0.0f);
    for (uint32_t k = 0; k < lobe_count; ++k) {
        float cos_i = drift_vec3_dot(lobe[k].dir, bsdf->frame.z);
        if (!mirror && cos_i <= 0.0f) {
            continue;
        }
        drift_vec3 w = mirror
                           ? bsdf->specular
                           : drift_vec3_scale(bsdf->specular, (bsdf->exponent + 2.0f) /
                                                                  (bsdf->exponent + 1.0f) * cos_i);
        sum = drift_vec3_fma(
            sum, drift_vec3_mul(w, drift_refine_trace_ray(&tracer, lobe[k], mirror, sampler, rays)),
            1.0f);
    }
    drift_vec3 traced = drift_vec3_scale(sum, 1.0f / (float)(samples ? samples : 1));
    return drift__sir_display_change(drift_image_get3(&f->final,
                                                      (int32_t)(index % (size_t)f->params.width),
                                                      (int32_t)(index / (size_t)f->params.width)),
                                     drift_vec3_sub(traced, raster));
}

// The raster's own expected reflection error at a reflective pixel, in display values: R
// looks the map up along the mirror direction r as if the pixel sat at the probe c. The mirror
// ray and rays drawn from the lobe find where the reflection really lands (q_k) and the share
// of it that escapes the scene; the map seen from c toward each q_k, blurred over the lobe's
// cone as R is (parallax-corrected, as local cube maps are), is what R would hold there. The change
// of the pixel when R takes that value, weighted by the lobe's albedo as R is, is the expected
// error. A q hidden from c is unknown to the map: there the lobe rays' hits are shaded as the
// ray tracer would (hidden_reflection_error). Without a map (another reflection technique)
// the error is unknown: 1.
static float expected_reflection_error(drift_frame_state *f, size_t index, const drift_surface *s,
                                       drift_vec3 wo, uint32_t samples, drift_sampler *sampler,
                                       uint64_t *rays)
{
    const drift_envmap *map = drift_realtime_probe_of(f, f->gbuffer.mesh_index[index]);
    if (!map || f->params.reflections != DRIFT_REFLECTIONS_ENVMAP) {
        return 1.0f;
    }
    drift_bsdf bsdf = drift_bsdf_make(f->scene, s);
    bool mirror = bsdf.type == DRIFT_MATERIAL_MIRROR;
    float cone = mirror ? 0.0f : drift_gloss_theta_max(&f->scene->materials[s->material]);
    drift_vec3 c = drift_envmap_probe(map);
    drift_vec3 r = drift_vec3_reflect(wo, s->ns);
    // Where R looks the map up for r, and the lobe's cone as the probe sees it there (the
    // reflection pass's own lookup: box-projected under envmap.parallax = BOX).
    bool box = f->params.envmap.parallax == DRIFT_ENVMAP_PARALLAX_BOX;
    float cone_map = cone;
    drift_vec3 r_map = drift_realtime_envmap_direction(f, map, s->position, r, &cone_map);
    drift_vec3 escaped = drift_vec3_splat(0.0f);
    uint32_t used = 0, hit_count = 0;
    drift_vec3 hit_at[MAX_LOBE_RAYS + 1]; // the mirror ray's and the lobe rays' hit points
    drift_ray lobe[MAX_LOBE_RAYS];
    uint32_t lobe_count = 0;
    // At most MAX_LOBE_RAYS lobe rays, so that every ray cast is kept and counted.
    uint32_t lobe_rays = mirror ? 0u : (samples < MAX_LOBE_RAYS ? samples : MAX_LOBE_RAYS);
    for (uint32_t k = 0; k <= lobe_rays; ++k) { // k = 0: the mirror ray
        drift_vec3 dir =
            k == 0 ? r : drift_bsdf_sample_glossy_lobe(&bsdf, wo, drift_sampler_next2(sampler));
        if (drift_vec3_dot(dir, s->ng) <= 0.0f) {
            continue; // below the surface: the ray tracer gives it no weight either
        }
        drift_ray ray = { .origin = drift_offset_origin(s->position, s->ng, dir),
                          .dir = dir,
                          .tmin = 0.0f,
                          .tmax = INFINITY };
        drift_hit hit;
        ++*rays;
        ++used;
        if (drift_accel_intersect(f->accel, &ray, &hit)) {
            hit_at[hit_count++] = drift_vec3_fma(ray.origin, dir, hit.t);
            if (k > 0 || mirror) {
                lobe[lobe_count++] = ray;
            }
        } else if (mirror && drift_scene_has_environment(f->scene)) {
            escaped = drift_vec3_add(escaped, drift_environment_eval(f->scene, dir));
        } // a glossy lobe's escaped rays see the environment in D, not R
    }
    if (used == 0) {
        return 0.0f;
    }
    drift_vec3 expected = escaped;
    drift_vec3 weight = drift_raster_reflection_weight(&bsdf, wo);
    drift_vec3 raster = drift_vec3_mul(weight, seen_in_map(map, r_map, cone_map, mirror));
    // Each hit q_k shows what the map sees toward it, blurred as R is over the lobe's cone at
    // q_k as the probe sees it: the lobe rays that meet another surface than the mirror ray's
    // (a statue's edge in a glossy floor) are part of the expectation, not of its blind spot.
    for (uint32_t k = 0; k < hit_count; ++k) {
        drift_vec3 to_q = drift_vec3_sub(hit_at[k], c);
        float distance = drift_vec3_length(to_q);
        if (!(distance > 0.0f)) {
            return 1.0f;
        }
        drift_ray from_probe = { .origin = c,
                                 .dir = drift_vec3_scale(to_q, 1.0f / distance),
                                 .tmin = 0.0f,
                                 .tmax = 0.99f * distance };
        ++*rays;
        if (drift_accel_occluded(f->accel, &from_probe)) {
            // A q the map cannot see (a contact, the underside of an object in the floor):
            // what the lobe's rays see there, shaded by the tracer's direct light (a few
            // shadow rays), is the reflection the ray tracer will find.
            return hidden_reflection_error(f, index, &bsdf, lobe, lobe_count,
                                           mirror ? 1u : lobe_rays, raster, sampler, rays);
        }
        float from_p = drift_vec3_length(drift_vec3_sub(hit_at[k], s->position));
        float cone_q = box ? drift_envmap_parallax_cone(cone, from_p / distance) : cone;
        expected = drift_vec3_add(expected, seen_in_map(map, to_q, cone_q, mirror));
    }
    expected = drift_vec3_scale(expected, 1.0f / (float)used);
    drift_vec3 delta = drift_vec3_sub(drift_vec3_mul(weight, expected), raster);
    return drift__sir_display_change(drift_image_get3(&f->final,
                                                      (int32_t)(index % (size_t)f->params.width),
                                                      (int32_t)(index / (size_t)f->params.width)),
                                     delta);
}

// First pass: the expected error of each reflective pixel (-1 elsewhere), into job->expected.
void drift__sir_expected_error_pixel(drift_frame_state *f, int32_t x, int32_t y, uint64_t *rays,
                                     void *user)
{
    metric_job *job = user;
    size_t index = (size_t)y * (size_t)f->params.width + (size_t)x;
    const drift_surface *s = &f->gbuffer.surfaces[index];
    float expected = -1.0f;
    if (is_reflective(f, s)) {
        drift_sampler sampler =
            drift_pass_sampler(f, DRIFT_STREAM_SIR_LOBE ^ job->params->seed, x, y);
        expected = expected_reflection_error(f, index, s, drift_pass_wo(f, x, y),
                                             job->params->lobe_samples, &sampler, rays);
    }
    job->expected[index] = expected;
}

// A few lobe rays a pixel make a noisy estimate; its mean over the reflective pixels of a
// (2 radius + 1)^2 square is steadier (the error it estimates varies smoothly, but for
// contacts, which an unknown q marks 1 and the mean spreads).
void drift__sir_smooth_expected(const float *in, int32_t w, int32_t h, int32_t radius, float *out)
{
    for (int32_t y = 0; y < h; ++y) {
        for (int32_t x = 0; x < w; ++x) {
            size_t index = (size_t)y * (size_t)w + (size_t)x;
            float sum = 0.0f;
            int count = 0;
            for (int32_t v = y - radius; in[index] >= 0.0f && v <= y + radius; ++v) {
                for (int32_t u = x - radius; v >= 0 && v < h && u <= x + radius; ++u) {
                    float e = u >= 0 && u < w ? in[(size_t)v * (size_t)w + (size_t)u] : -1.0f;
                    sum += e >= 0.0f ? e : 0.0f;
                    count += e >= 0.0f;
                }
            }
            out[index] = count ? sum / (float)count : in[index];
        }
    }
}

void drift__sir_reflection_pixel(drift_frame_state *f, int32_t x, int32_t y, uint64_t *rays,
                                 void *user)
{
    metric_job *job = user;
    const drift_refine_metric_params *params = job->params;
    size_t index = (size_t)y * (size_t)f->params.width + (size_t)x;
    const drift_surface *s = &f->gbuffer.surfaces[index];
    float e[5] = { 0 };
    if (is_reflective(f, s)) {
        drift_vec3 wo = drift_pass_wo(f, x, y); // -i
        drift_vec3 r = drift_vec3_reflect(wo, s->ns);
        drift_vec3 c = probe_centre(f, f->gbuffer.mesh_index[index]);
        float far = max_distance(f->scene, c);
        // The paper's metrics say where an environment map may be wrong; weigh them by how
        // wrong this one is expected to be here, so a glossy surface whose raster reflection
        // is already right is not flagged (0 below the tolerance).
        float tolerance = params->reflection_tolerance;
        float expected = job->expected ? job->expected[index] : 1.0f;
        float weight =
            expected >= tolerance ? drift_clampf(expected / REAL_ERROR_SCALE, 0.0f, 1.0f) : 0.0f;
        weight = job->expected ? weight : 1.0f;
        if (weight > 0.0f) {
            e[0] = 1.0f;
            e[1] = far > 0.0f ? drift_vec3_length(drift_vec3_sub(s->position, c)) / far : 0.0f;
            // <-i, r> = 2 <-i, n>^2 - 1 runs from 1 head-on to -1 at grazing view: mapped
            // onto [0,1] growing toward grazing view, where the map's parallax is largest
            // (clamped as printed, it was 0 wherever the view is more than 45 degrees off).
            e[2] = 0.5f * (1.0f - drift_vec3_dot(wo, r));
            e[3] = drift_vec3_dot(wo, s->ns);
            drift_sampler sampler = drift_pass_sampler(f, DRIFT_STREAM_SIR_AO ^ params->seed, x, y);
            e[4] = ambient_occlusion(f, s, job->ao_radius, params->ao_samples, &sampler, rays);
            for (int m = 0; m < 5; ++m) {
                e[m] *= weight;
            }
        }
    }
    for (int m = 0; m < 5; ++m) {
        drift_image_pixel(&job->out[DRIFT_METRIC_REFLECTION1 + m], x, y)[0] =
            drift_clampf(e[m], 0.0f, 1.0f);
    }
}
