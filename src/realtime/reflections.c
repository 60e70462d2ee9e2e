// Reflections of the hybrid frame, R: light whose first bounce is the glossy or mirror lobe.
// `sharp` traces one mirror ray per glossy or mirror pixel and shades its hit with direct
// light and hard shadows, an ambient guess at its indirect light and one more mirror bounce
// (trace_reflected); `envmap` looks the mirror direction up in a cube map captured at a
// probe (blurred over the lobe's cone for glossy pixels). Both weight the radiance by the
// lobe's directional albedo (drift_raster_reflection_weight). Under reflection edits both
// look along the edited direction e(q) instead (drift/reflect_edit.h). Emission seen in the mirror
// direction belongs to R only for mirrors: for glossy lobes the direct pass already has it.
#include "realtime/realtime.h"

#include <math.h>

static size_t pixel_index(const drift_frame_state *f, int32_t x, int32_t y)
{
    return (size_t)y * (size_t)f->params.width + (size_t)x;
}

static bool has_reflection(const drift_frame_state *f, const drift_surface *s, drift_bsdf *out_bsdf)
{
    if (s->material == DRIFT_INVALID_INDEX) {
        return false;
    }
    *out_bsdf = drift_bsdf_make(f->scene, s);
    return !drift_vec3_is_zero(out_bsdf->specular) &&
           (out_bsdf->type == DRIFT_MATERIAL_MIRROR || out_bsdf->exponent > 0.0f);
}

// The direction a reflection looks along: the mirror direction of wo, or e(q) under edits.
static drift_vec3 reflection_direction(const drift_frame_state *f, const drift_surface *s,
                                       drift_vec3 wo)
{
    drift_vec3 r = drift_vec3_reflect(wo, s->ns);
    if (!f->params.reflection_edits) {
        return r;
    }
    drift_edit_point q = drift_edit_point_from_surface(s);
    return drift_reflection_edits_direction(f->params.reflection_edits, &q, r);
}

static drift_vec3 combine(const drift_bsdf *bsdf, drift_vec3 wo, drift_raster_radiance l)
{
    drift_vec3 seen =
        bsdf->type == DRIFT_MATERIAL_MIRROR ? drift_vec3_add(l.emitted, l.reflected) : l.reflected;
    return drift_vec3_mul(drift_raster_reflection_weight(bsdf, wo), seen);
}

// The light along a ray leaving a smooth-glass interface: what it meets shaded as a sharp
// reflection's hit, or, at another smooth-glass interface with interfaces left, that
// interface's light (glass_interface).
static drift_vec3 glass_interface(drift_frame_state *f, const drift_surface *s,
                                  const drift_bsdf *bsdf, drift_vec3 wo, int left, bool inside,
                                  drift_sampler *sampler, uint64_t *rays);

// Rough glass is traced as if smooth: its refraction's mean direction, sharp, with the smooth
// interface's Fresnel shares. The blur of the rough interface is left out (docs/hybrid.md,
// "Glass"); a black pane, which the fast rows showed before, is further from the truth.
static drift_bsdf as_smooth_glass(const drift_bsdf *bsdf)
{
    drift_bsdf smooth = *bsdf;
    smooth.ggx.alpha = 0.0f;
    return smooth;
}

static drift_vec3 glass_ray(drift_frame_state *f, const drift_surface *at, drift_vec3 wi, int left,
                            drift_sampler *sampler, uint64_t *rays)
{
    drift_ray ray = { .origin = drift_offset_origin(at->position, at->ng, wi),
                      .dir = wi,
                      .tmin = 0.0f,
                      .tmax = INFINITY };
    drift_hit hit;
    ++*rays;
    if (left > 0 && drift_accel_intersect(f->accel, &ray, &hit)) {
        drift_surface next = drift_scene_surface(f->scene, &ray, &hit);
        if (next.material != DRIFT_INVALID_INDEX) {
            drift_bsdf nb = drift_bsdf_make(f->scene, &next);
            if (drift_bsdf_is_glass(&nb)) {
                nb = as_smooth_glass(&nb);
                return glass_interface(f, &next, &nb, drift_vec3_neg(ray.dir), left, true, sampler,
                                       rays);
            }
        }
    }
    float distance;
    drift_raster_radiance l = drift_raster_trace_radiance(&f->shading, ray, DRIFT_INVALID_INDEX,
                                                          sampler, rays, &distance);
    return drift_vec3_add(l.emitted, l.reflected);
}

// Both branches of a smooth-glass interface, each weighted by its share (1 - F, or F): u_lobe
// at the top of the dielectric's range transmits (reflects only under total internal
// reflection), at its bottom reflects. The camera's own interface leaves its reflection to
// the sharp buffer (inside = false). Inside the glass, exits near grazing reflect most of the
// light (F -> 1 before total internal reflection): the transmitted branch alone lost it.
static drift_vec3 glass_interface(drift_frame_state *f, const drift_surface *s,
                                  const drift_bsdf *bsdf, drift_vec3 wo, int left, bool inside,
                                  drift_sampler *sampler, uint64_t *rays)
{
    drift_vec3 sum = drift_vec3_splat(0.0f);
    drift_bsdf_sample t = drift_bsdf_sample_wi(bsdf, wo, 1.0f - 1e-6f, drift_vec2_make(0, 0));
    drift_bsdf_sample r = { 0 };
    if (inside && t.pdf < bsdf->ggx.w_dielectric) {
        r = drift_bsdf_sample_wi(bsdf, wo, 1.0f - bsdf->ggx.w_dielectric, drift_vec2_make(0, 0));
        if (drift_vec3_dot(r.wi, t.wi) > 0.9999f) {
            r.pdf = 0.0f; // total internal reflection: t already is the reflection
        }
    }
    const drift_bsdf_sample *branch[2] = { &t, &r };
    for (int i = 0; i < 2; ++i) {
        if (branch[i]->pdf > 0.0f) {
            drift_vec3 w = drift_vec3_scale(branch[i]->weight, branch[i]->pdf);
            sum = drift_vec3_add(
                sum, drift_vec3_mul(w, glass_ray(f, s, branch[i]->wi, left - 1, sampler, rays)));
        }
    }
    return sum;
}

// Glass (a GGX dielectric; rough glass as if smooth): the light it lets through, traced.
// The refracted ray goes on through up to GLASS_INTERFACES smooth-dielectric interfaces,
// splitting at each inside one into its transmitted and reflected rays, weighted by their
// shares; what they meet is shaded as a sharp reflection's hit (emission, direct light with
// hard shadows; the environment on a miss). Every other lobe is not traced here
// (docs/hybrid.md, "Glass").
#define GLASS_INTERFACES 4

static drift_vec3 glass_transmission(drift_frame_state *f, const drift_surface *s,
                                     const drift_bsdf *bsdf, drift_vec3 wo, drift_sampler *sampler,
                                     uint64_t *rays)
{
    drift_bsdf smooth = as_smooth_glass(bsdf);
    return glass_interface(f, s, &smooth, wo, GLASS_INTERFACES, false, sampler, rays);
}

// What a sharp ray's hit reflects besides its direct light (docs/hybrid.md, "Reflections"):
// indirect light, the frame's ambient radiance (frame_ambient) times the hit's diffuse albedo,
// a guess where no screen-space buffer reaches, and, at a glossy, mirror or glass hit, its own
// mirror reflection traced the same way, SHARP_BOUNCES deep (metal seen in metal; glass's
// transmission too). Without them a metal sphere seen in another was black in the buffer and
// a floor lit only indirectly was missing its indirect light.
#define SHARP_BOUNCES 1

typedef struct sharp_job {
    drift_vec3 ambient;
    int bounces;
} sharp_job;

static drift_raster_radiance trace_reflected(drift_frame_state *f, const sharp_job *job,
                                             drift_ray ray, int bounces, drift_sampler *sampler,
                                             uint64_t *rays, float *distance)
{
    drift_surface hit;
    drift_raster_radiance l = drift_raster_trace_radiance_surface(
        &f->shading, ray, DRIFT_INVALID_INDEX, sampler, rays, distance, &hit);
    if (hit.material == DRIFT_INVALID_INDEX) {
        return l;
    }
    drift_bsdf bsdf = drift_bsdf_make(f->scene, &hit);
    drift_vec3 wo = drift_vec3_neg(ray.dir);
    l.reflected = drift_vec3_add(
        l.reflected, drift_vec3_mul(drift_raster_diffuse_albedo(&bsdf, wo), job->ambient));
    if (bounces <= 0 || !has_reflection(f, &hit, &bsdf)) {
        return l;
    }
    drift_vec3 dir = drift_vec3_reflect(wo, hit.ns);
    drift_ray next = { .origin = drift_offset_origin(hit.position, hit.ng, dir),
                       .dir = dir,
                       .tmin = 0.0f,
                       .tmax = INFINITY };
    float d;
    drift_raster_radiance seen = trace_reflected(f, job, next, bounces - 1, sampler, rays, &d);
    l.reflected = drift_vec3_add(l.reflected, combine(&bsdf, wo, seen));
    if (drift_bsdf_is_glass(&bsdf)) {
        l.reflected =
            drift_vec3_add(l.reflected, glass_transmission(f, &hit, &bsdf, wo, sampler, rays));
    }
    return l;
}

// The light arriving at `at` after one bounce, from one cosine-distributed direction about its
// shading normal turned toward wo: the direct light its hit reflects (a miss brings none: the
// environment is direct light); the diffuse albedo of that hit toward `at` (0 on a miss) goes to
// *out_albedo.
static drift_vec3 one_bounce_sample(drift_frame_state *f, const drift_surface *at, drift_vec3 wo,
                                    drift_sampler *sampler, uint64_t *rays, drift_vec3 *out_albedo)
{
    drift_vec3 n = drift_vec3_dot(at->ns, wo) < 0.0f ? drift_vec3_neg(at->ns) : at->ns;
    drift_frame frame = drift_frame_from_normal(n);
    drift_vec3 dir =
        drift_frame_to_world(&frame, drift_sample_cosine_hemisphere(drift_sampler_next2(sampler)));
    drift_ray ray = { .origin = drift_offset_origin(at->position, at->ng, dir),
                      .dir = dir,
                      .tmin = 0.0f,
                      .tmax = INFINITY };
    float distance;
    drift_surface hit;
    drift_raster_radiance l = drift_raster_trace_radiance_surface(
        &f->shading, ray, DRIFT_INVALID_INDEX, sampler, rays, &distance, &hit);
    *out_albedo = drift_vec3_splat(0.0f);
    if (hit.material != DRIFT_INVALID_INDEX) {
        drift_bsdf bsdf = drift_bsdf_make(f->scene, &hit);
        *out_albedo = drift_raster_diffuse_albedo(&bsdf, drift_vec3_neg(dir));
    }
    return l.reflected;
}

// The frame's ambient radiance for the hits: the mean light arriving after one bounce at the
// points the mirror rays meet, sampled where it is used: about AMBIENT_SAMPLES reflective
// pixels, evenly spread in scan order, each trace their mirror ray and one_bounce_sample at
// its hit. --ambient's radiance when given; none under --indirect none or --max-depth 2.
// Two guesses that read the camera's view instead were measured and dropped (docs/lab, issue
// 40 s7 reflhits): the `ambient` row's mean direct light leaving the visible surfaces (the
// GGX scene's spheres too bright: it ignores how much of a hemisphere sees nothing), and the
// mean one-bounce light at the visible surfaces (5x too dark for a ceiling seen in a mirror
// that fills the view).
#define AMBIENT_SAMPLES  1024
#define AMBIENT_MAX_ECHO 0.9

static drift_vec3 frame_ambient(drift_frame_state *f)
{
    if (f->params.indirect == DRIFT_INDIRECT_NONE || f->params.max_depth < 3) {
        return drift_vec3_splat(0.0f);
    }
    if (f->params.has_ambient) {
        return f->params.ambient;
    }
    // One pass over the frame lists the reflective pixels (drift_bsdf_make each, once); the
    // samples are every `every`-th of them in scan order.
    const size_t pixels = (size_t)f->params.width * (size_t)f->params.height;
    uint32_t *reflective = drift_alloc(f->ctx, pixels * sizeof *reflective);
    if (!reflective) {
        return drift_vec3_splat(0.0f); // no ambient guess: the buffer as without it
    }
    size_t total = 0;
    for (size_t i = 0; i < pixels; ++i) {
        drift_bsdf bsdf;
        if (has_reflection(f, &f->gbuffer.surfaces[i], &bsdf)) {
            reflective[total++] = (uint32_t)i;
        }
    }
    size_t every = total / AMBIENT_SAMPLES + 1, count = 0;
    double sum[3] = { 0.0, 0.0, 0.0 }, bounce[3] = { 0.0, 0.0, 0.0 };
    uint64_t *rays = &f->stats.rays[DRIFT_PASS_REFLECTIONS];
    for (size_t j = 0; j < total; j += every) {
        int32_t x = (int32_t)(reflective[j] % (uint32_t)f->params.width);
        int32_t y = (int32_t)(reflective[j] / (uint32_t)f->params.width);
        const drift_surface *s = &f->gbuffer.surfaces[reflective[j]];
        drift_vec3 dir = reflection_direction(f, s, drift_pass_wo(f, x, y));
        drift_ray ray = { .origin = drift_offset_origin(s->position, s->ng, dir),
                          .dir = dir,
                          .tmin = 0.0f,
                          .tmax = INFINITY };
        drift_hit hit;
        ++*rays;
        if (!drift_accel_intersect(f->accel, &ray, &hit)) {
            continue;
        }
        drift_surface at = drift_scene_surface(f->scene, &ray, &hit);
        if (at.material == DRIFT_INVALID_INDEX) {
            continue;
        }
        drift_sampler sampler = drift_pass_sampler(f, DRIFT_STREAM_REFLECTION, x, y);
        drift_vec3 albedo;
        drift_vec3 d = one_bounce_sample(f, &at, drift_vec3_neg(dir), &sampler, rays, &albedo);
        sum[0] += (double)d.x;
        sum[1] += (double)d.y;
        sum[2] += (double)d.z;
        bounce[0] += (double)albedo.x;
        bounce[1] += (double)albedo.y;
        bounce[2] += (double)albedo.z;
        ++count;
    }
    drift_free(f->ctx, reflective);
    if (count == 0) {
        return drift_vec3_splat(0.0f);
    }
    // Later bounces as a geometric series: each passes on the mean albedo the samples met
    // (misses count 0), L1 / (1 - a) with a at most AMBIENT_MAX_ECHO.
    float c[3];
    for (int k = 0; k < 3; ++k) {
        double a = fmin(bounce[k] / (double)count, AMBIENT_MAX_ECHO);
        c[k] = (float)(sum[k] / (double)count / (1.0 - a));
    }
    return drift_vec3_make(c[0], c[1], c[2]);
}

static void sharp_pixel(drift_frame_state *f, int32_t x, int32_t y, uint64_t *rays, void *user)
{
    const sharp_job *job = user;
    const drift_surface *s = &f->gbuffer.surfaces[pixel_index(f, x, y)];
    drift_vec3 zero = drift_vec3_splat(0.0f);
    drift_bsdf bsdf;
    if (!has_reflection(f, s, &bsdf)) {
        drift_image_set3(&f->reflection_emitted, x, y, zero);
        drift_image_set3(&f->reflection_reflected, x, y, zero);
        drift_image_pixel(&f->reflection_distance, x, y)[0] = INFINITY;
        drift_image_set3(&f->reflections, x, y, zero);
        return;
    }
    drift_vec3 wo = drift_pass_wo(f, x, y);
    drift_vec3 dir = reflection_direction(f, s, wo);
    drift_ray ray = { .origin = drift_offset_origin(s->position, s->ng, dir),
                      .dir = dir,
                      .tmin = 0.0f,
                      .tmax = INFINITY };
    drift_sampler sampler = drift_pass_sampler(f, DRIFT_STREAM_REFLECTION, x, y);
    float distance;
    drift_raster_radiance l = trace_reflected(f, job, ray, job->bounces, &sampler, rays, &distance);
    drift_image_set3(&f->reflection_emitted, x, y, l.emitted);
    drift_image_set3(&f->reflection_reflected, x, y, l.reflected);
    drift_image_pixel(&f->reflection_distance, x, y)[0] = distance;
    drift_vec3 r = combine(&bsdf, wo, l);
    if (drift_bsdf_is_glass(&bsdf)) {
        // A delta reflection: no light sample finds the emitters it sees (the environment's
        // share is D's split sum). A rough one's are D's light samples.
        if (isfinite(distance) && drift_bsdf_is_smooth_glass(&bsdf)) {
            r = drift_vec3_add(
                r, drift_vec3_mul(drift_raster_reflection_weight(&bsdf, wo), l.emitted));
        }
        r = drift_vec3_add(r, glass_transmission(f, s, &bsdf, wo, &sampler, rays));
    }
    drift_image_set3(&f->reflections, x, y, r);
}

const drift_envmap *drift_realtime_probe_of(const drift_frame_state *f, uint32_t mesh)
{
    const drift_realtime_state *s = drift_realtime_of(f);
    for (uint32_t i = 0; s && i < s->probe_count; ++i) {
        if (s->probes[i].mesh == mesh || s->probes[i].mesh == DRIFT_INVALID_INDEX) {
            return s->probes[i].map;
        }
    }
    return NULL;
}

drift_vec3 drift_realtime_envmap_direction(const drift_frame_state *f, const drift_envmap *map,
                                           drift_vec3 p, drift_vec3 dir, float *cone)
{
    if (f->params.envmap.parallax != DRIFT_ENVMAP_PARALLAX_BOX) {
        return dir;
    }
    float ratio;
    drift_vec3 d =
        drift_envmap_parallax_direction(f->scene->bounds, drift_envmap_probe(map), p, dir, &ratio);
    *cone = drift_envmap_parallax_cone(*cone, ratio);
    return d;
}

static void envmap_pixel(drift_frame_state *f, int32_t x, int32_t y, uint64_t *rays, void *user)
{
    (void)rays;
    (void)user;
    size_t index = pixel_index(f, x, y);
    const drift_surface *s = &f->gbuffer.surfaces[index];
    drift_bsdf bsdf;
    const drift_envmap *map = NULL;
    if (has_reflection(f, s, &bsdf)) {
        map = drift_realtime_probe_of(f, f->gbuffer.mesh_index[index]);
    }
    if (!map) {
        drift_image_set3(&f->reflections, x, y, drift_vec3_splat(0.0f));
        return;
    }
    drift_vec3 wo = drift_pass_wo(f, x, y);
    drift_vec3 dir = reflection_direction(f, s, wo);
    float cone = bsdf.type == DRIFT_MATERIAL_MIRROR
                     ? 0.0f
                     : drift_gloss_theta_max(&f->scene->materials[s->material]);
    dir = drift_realtime_envmap_direction(f, map, s->position, dir, &cone);
    drift_image_set3(&f->reflections, x, y,
                     combine(&bsdf, wo, drift_envmap_lookup(map, dir, cone)));
}

static bool mesh_is_reflective(const drift_scene *scene, uint32_t mesh)
{
    const drift_material *m = &scene->materials[scene->meshes[mesh].material];
    return !drift_vec3_is_zero(m->specular);
}

static drift_vec3 mesh_centre(const drift_scene *scene, uint32_t mesh)
{
    drift_bounds3 b = drift_mesh_bounds(&scene->meshes[mesh]);
    return drift_vec3_scale(drift_vec3_add(b.min, b.max), 0.5f);
}

// Captures the probes on first use; they hold while the scene and settings stand.
static drift_result capture_probes(drift_frame_state *f)
{
    drift_realtime_state *st = drift_realtime_of(f);
    if (st->probes) {
        return DRIFT_OK;
    }
    const drift_scene *scene = f->scene;
    uint32_t count = 1;
    if (f->params.envmap.per_object) {
        count = 0;
        for (uint32_t m = 0; m < scene->mesh_count; ++m) {
            count += mesh_is_reflective(scene, m) ? 1u : 0u;
        }
        if (count == 0) {
            return DRIFT_OK;
        }
    }
    st->probes = drift_alloc(f->ctx, sizeof(drift_realtime_probe) * count);
    if (!st->probes) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    uint64_t *rays = &f->stats.rays[DRIFT_PASS_ENVMAP];
    uint32_t seed = drift_hash_combine(f->params.seed, DRIFT_STREAM_PROBE);
    if (!f->params.envmap.per_object) {
        drift_vec3 centre =
            f->params.envmap.has_probe
                ? f->params.envmap.probe
                : drift_vec3_scale(drift_vec3_add(scene->bounds.min, scene->bounds.max), 0.5f);
        st->probes[0].mesh = DRIFT_INVALID_INDEX;
        st->probe_count = 1;
        return drift_envmap_capture(f->ctx, &f->shading, centre, DRIFT_INVALID_INDEX,
                                    f->params.envmap.size, seed, &st->probes[0].map, rays);
    }
    for (uint32_t m = 0; m < scene->mesh_count; ++m) {
        if (!mesh_is_reflective(scene, m)) {
            continue;
        }
        drift_realtime_probe *probe = &st->probes[st->probe_count++];
        probe->mesh = m;
        drift_result r = drift_envmap_capture(f->ctx, &f->shading, mesh_centre(scene, m), m,
                                              f->params.envmap.size, seed, &probe->map, rays);
        if (r != DRIFT_OK) {
            return r;
        }
    }
    return DRIFT_OK;
}

drift_result drift_realtime_pass_sharp_reflections(drift_frame_state *f)
{
    // Both additions are paths of three segments or more: --max-depth 2 (the library's
    // default, the `reference` row's one bounce) keeps the buffer what it was.
    int depth_left = f->params.max_depth - 2;
    sharp_job job = { .ambient = frame_ambient(f),
                      .bounces = depth_left < SHARP_BOUNCES ? depth_left : SHARP_BOUNCES };
    drift_pass_pixels(f, DRIFT_PASS_REFLECTIONS, sharp_pixel, &job);
    return DRIFT_OK;
}

static void glass_pixel(drift_frame_state *f, int32_t x, int32_t y, uint64_t *rays, void *user)
{
    (void)user;
    const drift_surface *s = &f->gbuffer.surfaces[pixel_index(f, x, y)];
    if (s->material == DRIFT_INVALID_INDEX) {
        return;
    }
    drift_bsdf bsdf = drift_bsdf_make(f->scene, s);
    if (!drift_bsdf_is_glass(&bsdf)) {
        return;
    }
    drift_vec3 wo = drift_pass_wo(f, x, y);
    // Its own stream: the row's R stays what it was, the transmission is added.
    drift_sampler sampler = drift_pass_sampler(f, DRIFT_STREAM_GLASS, x, y);
    drift_vec3 t = glass_transmission(f, s, &bsdf, wo, &sampler, rays);
    drift_image_set3(&f->reflections, x, y,
                     drift_vec3_add(drift_image_get3(&f->reflections, x, y), t));
}

drift_result drift_realtime_pass_glass_transmission(drift_frame_state *f)
{
    drift_pass_pixels(f, DRIFT_PASS_REFLECTIONS, glass_pixel, NULL);
    return DRIFT_OK;
}

drift_result drift_realtime_capture_probes(drift_frame_state *f)
{
    double t = drift_time_now();
    drift_result r = capture_probes(f);
    drift_pass_time(f, DRIFT_PASS_ENVMAP, t);
    return r;
}

drift_result drift_realtime_pass_envmap_reflections(drift_frame_state *f,
                                                    const drift_pass_args *args)
{
    (void)args;
    drift_pass_pixels(f, DRIFT_PASS_ENVMAP, envmap_pixel, NULL);
    return DRIFT_OK;
}
