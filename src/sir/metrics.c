// SIR's error metrics (paper §5), per pixel in [0,1], from the hybrid frame's last render:
//   reflection1..5  on reflective material (a specular lobe): 1; |p - c| / max |q - c| over the
//                   scene bounds (c the environment probe); <-i, r>; <-i, n>; the ambient
//                   occlusion k_a (fraction of ao_samples cosine rays that hit within ao_radius)
//   dof             Sobel edges of the depth plane, each dilated by a square of radius
//                   C_max(p) = max(C(z_p), C_inf) pixels; zero for a pinhole or no DOF
//   shadow          1 where drift_shadow_map_penumbra says a light's penumbra may fall, or
//                   where an area light straddles the receiver's tangent plane; dilated (2 px
//                   at 600 rows a 512-texel face, growing with the pixels a texel spans)
#include "sir/sir.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

// A polygonal light's corners (a quad's four, a triangle's three, a small emissive mesh's
// vertices): the shadow metric bounds the light by them instead of its bounding sphere.
#define MAX_CORNERS 64

// A metric's value is its expected display-value error over this (the lambda fit's scale of
// the real error), so it orders pixels as the error does.
#define REAL_ERROR_SCALE 0.1f
// A raster shadow this close to 0 or 1 claims an umbra or full light.
#define CERTAIN_SHADOW 0.001f
// Penumbra pixels whose raster shadows differ by more are not averaged together: across a
// narrow contact shadow PCSS is too bright on one side and too dark on the other.
#define SIMILAR_SHADOW 0.15f
// The square over which the expected reflection error is averaged: 5 x 5 pixels.
#define EXPECTED_RADIUS 2

typedef struct light_shape {
    uint32_t count; // 0: use the bounding sphere
    bool planar;    // one-sided and every part faces `direction`: nothing lights its back
    drift_vec3 corner[MAX_CORNERS];
} light_shape;

// What a penumbra pixel's shadow rays say of the raster's shadow there.
typedef struct penumbra_check {
    drift_vec3 delta;  // the raster's estimated shadow error, summed over the area lights
    float raster;      // the raster's shadow S_l, averaged over those lights
    bool contradicted; // its own rays saw what a raster claiming certainty denies
} penumbra_check;

typedef struct metric_job {
    const drift_refine_metric_params *params;
    drift_image *out;
    float ao_radius;
    uint64_t ao_rays;
    light_shape *shapes;    // one a frame light, or NULL: bounding spheres
    float *expected;        // a pixel's expected reflection error (-1: not reflective), or NULL
    penumbra_check *checks; // a pixel: the raster's shadow checked by rays
    float *coarse;          // the penumbra estimate at each 2 x 2 block's corner pixel, a light
} metric_job;

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

static float display(float v)
{
    return powf(drift_clampf(v, 0.0f, 1.0f), 1.0f / 2.2f);
}

// How far the displayed pixel `base` moves when `delta` is added (largest channel, display
// values: clamp to [0,1], gamma 1/2.2, as the real error is measured).
static float display_change(drift_vec3 base, drift_vec3 delta)
{
    drift_vec3 moved = drift_vec3_add(base, delta);
    return fmaxf(
        fmaxf(fabsf(display(moved.x) - display(base.x)), fabsf(display(moved.y) - display(base.y))),
        fabsf(display(moved.z) - display(base.z)));
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
    return display_change(drift_image_get3(&f->final, (int32_t)(index % (size_t)f->params.width),
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
    return display_change(drift_image_get3(&f->final, (int32_t)(index % (size_t)f->params.width),
                                           (int32_t)(index / (size_t)f->params.width)),
                          delta);
}

// First pass: the expected error of each reflective pixel (-1 elsewhere), into job->expected.
static void expected_error_pixel(drift_frame_state *f, int32_t x, int32_t y, uint64_t *rays,
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
static void smooth_expected(const float *in, int32_t w, int32_t h, int32_t radius, float *out)
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

static void reflection_pixel(drift_frame_state *f, int32_t x, int32_t y, uint64_t *rays, void *user)
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

// The corners of a light, or count 0 when it has too many or none (spheres, disks).
static void light_corners(const drift_scene *scene, const drift_raster_light *light,
                          light_shape *out)
{
    out->count = 0;
    out->planar = false;
    const drift_light *l = &scene->lights[light->first_light];
    if (light->mesh == DRIFT_INVALID_INDEX && l->type == DRIFT_LIGHT_QUAD) {
        out->corner[0] = l->position;
        out->corner[1] = drift_vec3_add(l->position, l->edge_u);
        out->corner[2] = drift_vec3_add(drift_vec3_add(l->position, l->edge_u), l->edge_v);
        out->corner[3] = drift_vec3_add(l->position, l->edge_v);
        out->count = 4;
        out->planar = light->one_sided && !light->two_sided;
        return;
    }
    if (l->type != DRIFT_LIGHT_TRIANGLE || 3u * light->light_count > MAX_CORNERS) {
        return;
    }
    // Triangle lights (one, or a small emissive mesh): every vertex; planar when each
    // triangle faces the mean normal (then the back of the plane gets no light, unless the
    // mesh emits from both faces).
    bool planar = light->one_sided && !light->two_sided;
    for (uint32_t t = 0; t < light->light_count; ++t) {
        drift_vec3 *c = out->corner + 3u * t;
        drift_light_triangle_vertices(scene, &scene->lights[light->first_light + t], &c[0], &c[1],
                                      &c[2]);
        drift_vec3 cross = drift_vec3_cross(drift_vec3_sub(c[1], c[0]), drift_vec3_sub(c[2], c[0]));
        float area2 = drift_vec3_length(cross);
        planar =
            planar && area2 > 0.0f && drift_vec3_dot(cross, light->direction) > 0.9999f * area2;
        for (int k = 0; k < 3 && planar; ++k) {
            planar = fabsf(drift_vec3_dot(drift_vec3_sub(c[k], light->centre), light->direction)) <=
                     1e-4f * light->radius;
        }
    }
    out->count = 3u * light->light_count;
    out->planar = planar;
}

// The light's size as the cone from p sees it, for the penumbra estimate: a blocker d from the
// light's centre c (on the way to p, d_r from c) hides a corner q = c + delta when its offset
// from the direction to p is |delta_perp| d_r / (d_r - delta_par) (d_r - d) / (d_r d), and the
// largest over the light is at a corner (the ratio is quasi-convex). 1% wider for the map's
// normal offset of the receiver. The bounding radius when a corner is beyond p.
static float light_size_from(const drift_raster_light *light, const light_shape *shape,
                             drift_vec3 p)
{
    drift_vec3 to_p = drift_vec3_sub(p, light->centre);
    float d_r = drift_vec3_length(to_p);
    if (shape->count == 0 || !(d_r > 0.0f)) {
        return light->radius;
    }
    drift_vec3 dir = drift_vec3_scale(to_p, 1.0f / d_r);
    float size = 0.0f;
    for (uint32_t k = 0; k < shape->count; ++k) {
        drift_vec3 delta = drift_vec3_sub(shape->corner[k], light->centre);
        float along = drift_vec3_dot(delta, dir);
        if (!(d_r - along > 0.01f * d_r)) {
            return light->radius;
        }
        float across = drift_vec3_length(drift_vec3_fma(delta, dir, -along));
        size = fmaxf(size, across * d_r / (d_r - along));
    }
    return fminf(1.01f * size, light->radius);
}

// Where the penumbra estimate finds p outside every penumbra of light l, one shadow ray to
// the light's centre says whether all of it is seen (1) or none (0); the raster's shadow S_l
// should say the same. Returns U_l (v - S_l): what the raster's direct light lacks (or has too
// much of) there. The shadow map's mistakes at contacts and seams (its bias and texels of the
// neighbouring surface) are exactly such pixels, which the penumbra estimate does not flag.
static drift_vec3 shadow_map_mistake(drift_frame_state *f, uint32_t l, int32_t x, int32_t y,
                                     const drift_surface *s, uint64_t *rays)
{
    const drift_frame_light_buffers *b = &f->light_buffers[l];
    drift_vec3 unshadowed = drift_image_get3(&b->unshadowed, x, y);
    if (drift_vec3_is_zero(unshadowed)) {
        return drift_vec3_splat(0.0f);
    }
    const drift_raster_light *light = &f->lights[l];
    drift_vec3 to_light = drift_vec3_sub(light->centre, s->position);
    float distance = drift_vec3_length(to_light);
    if (!(distance > 0.0f)) {
        return drift_vec3_splat(0.0f);
    }
    drift_vec3 dir = drift_vec3_scale(to_light, 1.0f / distance);
    drift_ray ray = { .origin = drift_offset_origin(s->position, s->ng, dir),
                      .dir = dir,
                      .tmin = 0.0f,
                      .tmax = distance * (1.0f - 1e-4f) };
    drift_hit hit;
    ++*rays;
    bool seen =
        !drift_accel_intersect(f->accel, &ray, &hit) || drift_raster_light_owns(light, hit.light);
    float raster = drift_image_pixel(&b->shadow, x, y)[0];
    return drift_vec3_scale(unshadowed, (seen ? 1.0f : 0.0f) - raster);
}

// In a penumbra of light l, what the raster's shadow S_l gets wrong, estimated with `samples`
// shadow rays to stratified points of the light: U_l (v - S_l), v the rays' visible share.
// Noisy alone (a quarter of U_l at 4 rays); smooth_shadow_mistakes averages it over a square
// of penumbra pixels, where the raster's error varies slowly and the noise cancels.
static drift_vec3 penumbra_mistake(drift_frame_state *f, uint32_t l, int32_t x, int32_t y,
                                   const drift_surface *s, uint32_t samples, bool *contradicted,
                                   uint64_t *rays)
{
    const drift_frame_light_buffers *b = &f->light_buffers[l];
    drift_vec3 unshadowed = drift_image_get3(&b->unshadowed, x, y);
    if (drift_vec3_is_zero(unshadowed)) {
        return drift_vec3_splat(0.0f);
    }
    const drift_raster_light *light = &f->lights[l];
    drift_sampler sampler = drift_pass_sampler(f, DRIFT_STREAM_SIR_LOBE + 1u + l, x, y);
    uint32_t side = 1;
    while (side * side < samples) {
        ++side;
    }
    uint32_t seen = 0, cast = 0;
    for (uint32_t k = 0; k < side * side; ++k) {
        drift_vec2 u = drift_sampler_next2(&sampler);
        u = drift_vec2_make(((float)(k % side) + u.x) / (float)side,
                            ((float)(k / side) + u.y) / (float)side);
        drift_light_sample ls = drift_raster_light_sample(f->scene, light, s->position,
                                                          drift_sampler_next1(&sampler), u);
        if (!(ls.pdf > 0.0f)) {
            continue;
        }
        drift_ray ray = { .origin = drift_offset_origin(s->position, s->ng, ls.wi),
                          .dir = ls.wi,
                          .tmin = 0.0f,
                          .tmax = isfinite(ls.distance) ? ls.distance * (1.0f - 1e-4f) : INFINITY };
        ++*rays;
        ++cast;
        seen += drift_accel_occluded(f->accel, &ray) ? 0u : 1u;
    }
    float raster = drift_image_pixel(&b->shadow, x, y)[0];
    float visible = cast ? (float)seen / (float)cast : raster;
    // A raster umbra whose rays see the light, or a fully lit raster with a ray blocked, is
    // wrong however few rays were cast: no noise lets an umbra see the light.
    *contradicted = *contradicted || (raster <= CERTAIN_SHADOW && seen > 0) ||
                    (raster >= 1.0f - CERTAIN_SHADOW && seen < cast);
    return drift_vec3_scale(unshadowed, visible - raster);
}

// Second pass over the (dilated) penumbra estimate: the raster's shadow error there, summed
// over the area lights, into job->checks.
static void penumbra_check_pixel(drift_frame_state *f, int32_t x, int32_t y, uint64_t *rays,
                                 void *user)
{
    metric_job *job = user;
    size_t index = (size_t)y * (size_t)f->params.width + (size_t)x;
    const drift_surface *s = &f->gbuffer.surfaces[index];
    penumbra_check check = { .delta = drift_vec3_splat(0.0f) };
    uint32_t checked = 0;
    if (drift_image_pixel(&job->out[DRIFT_METRIC_SHADOW], x, y)[0] > 0.0f &&
        s->material != DRIFT_INVALID_INDEX) {
        for (uint32_t l = 0; l < f->light_count; ++l) {
            if (drift_realtime_shadow_map(f, l) && f->lights[l].radius > 0.0f) {
                check.delta = drift_vec3_add(
                    check.delta, penumbra_mistake(f, l, x, y, s, job->params->lobe_samples,
                                                  &check.contradicted, rays));
                check.raster += drift_image_pixel(&f->light_buffers[l].shadow, x, y)[0];
                ++checked;
            }
        }
    }
    check.raster = checked ? check.raster / (float)checked : 0.0f;
    job->checks[index] = check;
}

// The penumbra estimate (the metrics' largest cost: the blocker search's shadow-map taps) is
// evaluated at half resolution: at the corner pixel of each 2 x 2 block, for every light; the
// block's other pixels take it when they lie on the same surface (same mesh, normals within
// 25 degrees, depth within 2%), else search themselves. The estimate is dilated by at least
// 2 pixels afterwards, which covers the block.
static void penumbra_coarse_pixel(drift_frame_state *f, int32_t x, int32_t y, uint64_t *rays,
                                  void *user)
{
    (void)rays;
    metric_job *job = user;
    if ((x | y) & 1) {
        return;
    }
    size_t index = (size_t)y * (size_t)f->params.width + (size_t)x;
    size_t block = (size_t)(y / 2) * (size_t)((f->params.width + 1) / 2) + (size_t)(x / 2);
    const drift_surface *s = &f->gbuffer.surfaces[index];
    for (uint32_t l = 0; l < f->light_count; ++l) {
        const drift_raster_light *light = &f->lights[l];
        const drift_shadow_map *map = drift_realtime_shadow_map(f, l);
        float e = -1.0f;
        const light_shape *shape = job->shapes ? &job->shapes[l] : NULL;
        bool behind =
            shape && shape->planar &&
            drift_vec3_dot(light->direction, drift_vec3_sub(s->position, light->centre)) <= 0.0f;
        if (map && light->radius > 0.0f && s->material != DRIFT_INVALID_INDEX && !behind) {
            drift_penumbra_query query = {
                .light_size = shape ? light_size_from(light, shape, s->position) : 0.0f
            };
            e = drift_shadow_map_penumbra_query(map, s->position, s->ng, &query);
        }
        job->coarse[block * f->light_count + l] = e;
    }
}

static float coarse_estimate(const drift_frame_state *f, const metric_job *job, int32_t x,
                             int32_t y, uint32_t l)
{
    int32_t w = f->params.width;
    size_t index = (size_t)y * (size_t)w + (size_t)x;
    size_t corner = (size_t)(y & ~1) * (size_t)w + (size_t)(x & ~1);
    if (corner != index) {
        float za = drift_image_pixel(&f->gbuffer.depth, x, y)[0];
        float zb = drift_image_pixel(&f->gbuffer.depth, x & ~1, y & ~1)[0];
        if (!drift_gbuffer_same_surface(&f->gbuffer, index, corner) ||
            !(fabsf(za - zb) <= 0.02f * za)) {
            return -1.0f;
        }
    }
    size_t block = (size_t)(y / 2) * (size_t)((w + 1) / 2) + (size_t)(x / 2);
    return job->coarse[block * f->light_count + l];
}

static void shadow_pixel(drift_frame_state *f, int32_t x, int32_t y, uint64_t *rays, void *user)
{
    metric_job *job = user;
    size_t index = (size_t)y * (size_t)f->params.width + (size_t)x;
    const drift_surface *s = &f->gbuffer.surfaces[index];
    float e = 0.0f;
    drift_vec3 leak = drift_vec3_splat(0.0f);
    for (uint32_t l = 0; e == 0.0f && s->material != DRIFT_INVALID_INDEX && l < f->light_count;
         ++l) {
        const drift_raster_light *light = &f->lights[l];
        const drift_shadow_map *map = drift_realtime_shadow_map(f, l);
        if (!map || !(light->radius > 0.0f)) {
            continue;
        }
        const light_shape *shape = job->shapes ? &job->shapes[l] : NULL;
        if (shape && shape->planar &&
            drift_vec3_dot(light->direction, drift_vec3_sub(s->position, light->centre)) <= 0.0f) {
            continue; // behind a one-sided planar light: neither raster nor ray tracer sees it
        }
        // A light that straddles the receiver's tangent plane is cut by the horizon: there the
        // shadow map's depth test is at grazing angles and its bias decides, so the estimate
        // counts it as penumbra (the raster's U_l clips the light exactly; S_l does not). With
        // corners the test is exact: some on each side; else the bounding sphere's. A light
        // below both the geometric and the shading normal's horizon casts no light there, so
        // neither raster nor ray tracer has anything to get wrong.
        if (light->type != DRIFT_LIGHT_DIRECTIONAL) {
            float lo = INFINITY, hi = -INFINITY, hi_shading = -INFINITY;
            if (shape && shape->count > 0) {
                for (uint32_t k = 0; k < shape->count; ++k) {
                    drift_vec3 d = drift_vec3_sub(shape->corner[k], s->position);
                    float h = drift_vec3_dot(s->ng, d);
                    lo = fminf(lo, h);
                    hi = fmaxf(hi, h);
                    hi_shading = fmaxf(hi_shading, drift_vec3_dot(s->ns, d));
                }
            } else {
                drift_vec3 d = drift_vec3_sub(light->centre, s->position);
                float h = drift_vec3_dot(s->ng, d);
                lo = h - light->radius;
                hi = h + light->radius;
                hi_shading = drift_vec3_dot(s->ns, d) + light->radius;
            }
            if (hi <= 0.0f && hi_shading <= 0.0f) {
                continue; // the light is wholly below the receiver's horizon: it gets none
            }
            if (lo <= 0.0f && hi >= 0.0f) {
                e = 1.0f;
                break;
            }
        }
        float known = job->coarse ? coarse_estimate(f, job, x, y, l) : -1.0f;
        if (known >= 0.0f) {
            e = known;
        } else {
            drift_penumbra_query query = {
                .light_size = shape ? light_size_from(light, shape, s->position) : 0.0f
            };
            e = drift_shadow_map_penumbra_query(map, s->position, s->ng, &query);
        }
        if (e == 0.0f && job->params->leak_tolerance > 0.0f) {
            leak = drift_vec3_add(leak, shadow_map_mistake(f, l, x, y, s, rays));
        }
    }
    drift_image_pixel(&job->out[DRIFT_METRIC_SHADOW], x, y)[0] = e;
    // Outside every penumbra the light is wholly seen or wholly hidden; where the raster's
    // shadow says otherwise by more than the tolerance (light leaking through a contact or a
    // seam, or a seam darkened by the map's own surfaces), its error is known.
    float leaked = 0.0f;
    if (e == 0.0f && !drift_vec3_is_zero(leak)) {
        float change = display_change(drift_image_get3(&f->final, x, y), leak);
        leaked = change >= job->params->leak_tolerance
                     ? drift_clampf(change / REAL_ERROR_SCALE, 0.0f, 1.0f)
                     : 0.0f;
    }
    drift_image_pixel(&job->out[DRIFT_METRIC_LEAK], x, y)[0] = leaked;
}

// Shadow maps of area lights, built (and left in the frame's cache) when the frame's shadow
// technique did not need them.
static void ensure_shadow_maps(drift_frame_state *f)
{
    for (uint32_t l = 0; l < f->light_count; ++l) {
        uint64_t rays = 0;
        if (f->lights[l].radius > 0.0f &&
            drift_realtime_ensure_shadow_map(f, l, &rays) != DRIFT_OK) {
            drift_realtime_drop_shadow_map(f, l); // logged; this light gets no estimate
        }
    }
}

// Depth with misses far beyond everything seen, so the silhouette against the background is
// an edge like any other.
static float depth_at(const drift_image *depth, int32_t x, int32_t y, float miss)
{
    x = x < 0 ? 0 : (x >= depth->width ? depth->width - 1 : x);
    y = y < 0 ? 0 : (y >= depth->height ? depth->height - 1 : y);
    float z = drift_image_pixel(depth, x, y)[0];
    return z > 0.0f ? z : miss;
}

static void dof_metric(drift_frame_state *f, float threshold, drift_image *out)
{
    int32_t w = f->params.width, h = f->params.height;
    memset(out->pixels, 0, sizeof(float) * (size_t)w * (size_t)h);
    if (f->params.dof == DRIFT_DOF_NONE || !(f->camera.aperture_radius > 0.0f)) {
        return; // a pinhole image has no depth-of-field error
    }
    const drift_image *depth = &f->gbuffer.depth;
    float far = 0.0f;
    for (int32_t y = 0; y < h; ++y) {
        for (int32_t x = 0; x < w; ++x) {
            far = fmaxf(far, drift_image_pixel(depth, x, y)[0]);
        }
    }
    float miss = far > 0.0f ? 4.0f * far : 1.0f;
    float c_inf = drift_coc_radius_pixels(&f->camera, h, 1e30f);
    // reach[p]: 1 + the square's radius around an edge pixel, 0 elsewhere; then spread along
    // rows (the largest reach covering each pixel) and along columns: a square of each edge
    // pixel's own radius in O(pixels x radius) instead of O(edges x radius^2).
    size_t n = (size_t)w * (size_t)h;
    int32_t *reach = drift_alloc(f->ctx, sizeof(int32_t) * n);
    int32_t *rows = drift_alloc(f->ctx, sizeof(int32_t) * n);
    if (!reach || !rows) {
        drift_free(f->ctx, reach);
        drift_free(f->ctx, rows);
        for (size_t i = 0; i < n; ++i) {
            out->pixels[i] = 1.0f; // no memory for the estimate: conservatively everything
        }
        return;
    }
    for (int32_t y = 0; y < h; ++y) {
        for (int32_t x = 0; x < w; ++x) {
            float z[3][3];
            for (int j = 0; j < 3; ++j) {
                for (int i = 0; i < 3; ++i) {
                    z[j][i] = depth_at(depth, x + i - 1, y + j - 1, miss);
                }
            }
            float gx = (z[0][2] + 2.0f * z[1][2] + z[2][2]) - (z[0][0] + 2.0f * z[1][0] + z[2][0]);
            float gy = (z[2][0] + 2.0f * z[2][1] + z[2][2]) - (z[0][0] + 2.0f * z[0][1] + z[0][2]);
            // Sobel weights sum to 8 a side: |G| / 8 is the depth step a pixel, relative to z.
            bool edge = sqrtf(gx * gx + gy * gy) / 8.0f > threshold * z[1][1];
            float c = fmaxf(drift_coc_radius_pixels(&f->camera, h, z[1][1]), c_inf);
            float r = fminf(ceilf(c), (float)(w > h ? w : h));
            reach[(size_t)y * (size_t)w + (size_t)x] = edge ? (int32_t)r + 1 : 0;
        }
    }
    for (int32_t y = 0; y < h; ++y) {
        int32_t *in = reach + (size_t)y * (size_t)w, *row = rows + (size_t)y * (size_t)w;
        for (int32_t x = 0; x < w; ++x) {
            int32_t r = in[x] - 1;
            for (int32_t u = x - r < 0 ? 0 : x - r; r >= 0 && u <= x + r && u < w; ++u) {
                row[u] = row[u] > in[x] ? row[u] : in[x];
            }
        }
    }
    for (int32_t y = 0; y < h; ++y) {
        for (int32_t x = 0; x < w; ++x) {
            int32_t r = rows[(size_t)y * (size_t)w + (size_t)x] - 1;
            for (int32_t v = y - r < 0 ? 0 : y - r; r >= 0 && v <= y + r && v < h; ++v) {
                drift_image_pixel(out, x, v)[0] = 1.0f;
            }
        }
    }
    drift_free(f->ctx, reach);
    drift_free(f->ctx, rows);
}

// The penumbra estimate grown by `radius` pixels each way (a square structuring element, as
// Knauer et al. 2010 dilate theirs): the shadow-map taps are coarser than the image.
static void dilate(drift_image *plane, int32_t radius, float *scratch)
{
    int32_t w = plane->width, h = plane->height;
    for (int32_t y = 0; y < h; ++y) { // rows, then columns: a square element
        for (int32_t x = 0; x < w; ++x) {
            float m = 0.0f;
            for (int32_t u = x - radius; u <= x + radius; ++u) {
                m = u >= 0 && u < w ? fmaxf(m, drift_image_pixel(plane, u, y)[0]) : m;
            }
            scratch[(size_t)y * (size_t)w + (size_t)x] = m;
        }
    }
    for (int32_t y = 0; y < h; ++y) {
        for (int32_t x = 0; x < w; ++x) {
            float m = 0.0f;
            for (int32_t v = y - radius; v <= y + radius; ++v) {
                m = v >= 0 && v < h ? fmaxf(m, scratch[(size_t)v * (size_t)w + (size_t)x]) : m;
            }
            drift_image_pixel(plane, x, y)[0] = m;
        }
    }
}

// 2 pixels (a 5x5 element) where a 512-texel face meets 600 image rows, growing with the
// image pixels a texel spans: at 1920x1080 a fixed 2 let recall fall to 0.82-0.88, since a
// texel's worth of penumbra edge there spans more pixels than the dilation covered.
static int32_t shadow_dilation(const drift_frame_state *f)
{
    double pixels_per_texel = (double)f->params.height / (double)f->params.shadow_map.size;
    long radius = lround(2.0 * pixels_per_texel * 512.0 / 600.0);
    return radius > 2 ? (int32_t)radius : 2;
}

// Keeps a penumbra pixel flagged only where the raster's shadow error, its estimate averaged
// (signed, so the rays' noise cancels) over the penumbra pixels of the same surface and a
// similar raster shadow in a 5 x 5 square, moves the displayed pixel by the tolerance or more
// (or, where its own rays contradict a certain raster, its own estimate does): PCSS is right in
// much of a broad penumbra. Valued by that change / 0.1, as the other weighted metrics, so that
// their largest (DRIFT_COMBINE_MAX) orders pixels by the expected error.
static void gate_penumbra(drift_frame_state *f, drift_image *shadow, const penumbra_check *checks,
                          float tolerance, float *scratch)
{
    int32_t w = shadow->width, h = shadow->height;
    for (int32_t y = 0; y < h; ++y) {
        for (int32_t x = 0; x < w; ++x) {
            size_t index = (size_t)y * (size_t)w + (size_t)x;
            drift_vec3 sum = drift_vec3_splat(0.0f);
            int count = 0;
            for (int32_t v = y - EXPECTED_RADIUS; v <= y + EXPECTED_RADIUS; ++v) {
                for (int32_t u = x - EXPECTED_RADIUS; v >= 0 && v < h && u <= x + EXPECTED_RADIUS;
                     ++u) {
                    size_t other = (size_t)v * (size_t)w + (size_t)u;
                    if (u < 0 || u >= w || drift_image_pixel(shadow, u, v)[0] <= 0.0f ||
                        !drift_gbuffer_same_surface(&f->gbuffer, index, other) ||
                        fabsf(checks[other].raster - checks[index].raster) > SIMILAR_SHADOW) {
                        continue;
                    }
                    sum = drift_vec3_add(sum, checks[other].delta);
                    ++count;
                }
            }
            float change = count ? display_change(drift_image_get3(&f->final, x, y),
                                                  drift_vec3_scale(sum, 1.0f / (float)count))
                                 : 0.0f;
            // The average hides a sliver the raster got wrong for certain (a fold of a
            // scanned mesh letting light into an umbra): the pixel's own estimate speaks.
            if (checks[index].contradicted) {
                change = fmaxf(
                    change, display_change(drift_image_get3(&f->final, x, y), checks[index].delta));
            }
            scratch[(size_t)y * (size_t)w + (size_t)x] =
                drift_image_pixel(shadow, x, y)[0] > 0.0f && change >= tolerance
                    ? drift_clampf(change / REAL_ERROR_SCALE, 0.0f, 1.0f)
                    : 0.0f;
        }
    }
    memcpy(shadow->pixels, scratch, sizeof(float) * (size_t)w * (size_t)h);
}

uint64_t drift_refine_compute_metrics(drift_frame_state *f,
                                      const drift_refine_metric_params *params,
                                      drift_image out[DRIFT_METRIC_COUNT])
{
    uint64_t rays = 0;
    drift_bounds3 b = f->scene->bounds;
    float diagonal = drift_vec3_length(drift_vec3_sub(b.max, b.min));
    metric_job job = { .params = params,
                       .out = out,
                       .ao_radius =
                           params->ao_radius > 0.0f ? params->ao_radius : 0.05f * diagonal };
    size_t pixels = (size_t)f->params.width * (size_t)f->params.height;
    float *raw = NULL;
    if (params->reflection_tolerance > 0.0f) { // without memory: the unweighted metrics
        raw = drift_alloc(f->ctx, sizeof(float) * pixels);
        job.expected = raw ? drift_alloc(f->ctx, sizeof(float) * pixels) : NULL;
    }
    if (job.expected) {
        float *smooth = job.expected;
        job.expected = raw;
        rays += drift_pass_for_each_pixel(f, expected_error_pixel, &job);
        smooth_expected(raw, f->params.width, f->params.height, EXPECTED_RADIUS, smooth);
        job.expected = smooth;
    }
    rays += drift_pass_for_each_pixel(f, reflection_pixel, &job);
    drift_free(f->ctx, job.expected);
    drift_free(f->ctx, raw);
    ensure_shadow_maps(f);
    job.shapes = f->light_count ? drift_alloc(f->ctx, sizeof(light_shape) * f->light_count) : NULL;
    for (uint32_t l = 0; job.shapes && l < f->light_count; ++l) {
        light_corners(f->scene, &f->lights[l], &job.shapes[l]);
    }
    size_t blocks = (size_t)((f->params.width + 1) / 2) * (size_t)((f->params.height + 1) / 2);
    job.coarse = f->light_count && params->half_res_penumbra
                     ? drift_alloc(f->ctx, sizeof(float) * blocks * f->light_count)
                     : NULL;
    if (job.coarse) { // without memory: every pixel searches
        rays += drift_pass_for_each_pixel(f, penumbra_coarse_pixel, &job);
    }
    rays += drift_pass_for_each_pixel(f, shadow_pixel, &job); // without memory: spheres
    drift_free(f->ctx, job.coarse);
    job.coarse = NULL;
    drift_free(f->ctx, job.shapes);
    float *scratch = drift_alloc(f->ctx, sizeof(float) * pixels);
    if (scratch) { // without memory the estimate stays undilated
        dilate(&out[DRIFT_METRIC_SHADOW], shadow_dilation(f), scratch);
    }
    if (scratch && params->shadow_tolerance > 0.0f) { // without memory: the estimate ungated
        job.checks = drift_alloc(f->ctx, sizeof(penumbra_check) * pixels);
    }
    if (job.checks) {
        rays += drift_pass_for_each_pixel(f, penumbra_check_pixel, &job);
        gate_penumbra(f, &out[DRIFT_METRIC_SHADOW], job.checks, params->shadow_tolerance, scratch);
        drift_free(f->ctx, job.checks);
    }
    drift_free(f->ctx, scratch);
    dof_metric(f, params->edge_threshold, &out[DRIFT_METRIC_DOF]);
    return rays;
}

void drift_refine_combine_metrics(const drift_image metrics[DRIFT_METRIC_COUNT],
                                  drift_refine_combine combine,
                                  const float lambda[DRIFT_METRIC_COUNT], drift_image *combined)
{
    size_t n = (size_t)combined->width * (size_t)combined->height;
    for (size_t i = 0; i < n; ++i) {
        float sum = 0.0f;
        for (int m = 0; m < DRIFT_METRIC_COUNT; ++m) {
            float weight = combine == DRIFT_COMBINE_LAMBDA ? lambda[m] : 1.0f / DRIFT_METRIC_COUNT;
            sum = combine == DRIFT_COMBINE_MAX ? fmaxf(sum, metrics[m].pixels[i])
                                               : sum + weight * metrics[m].pixels[i];
        }
        combined->pixels[i] = drift_clampf(sum, 0.0f, 1.0f);
    }
}
