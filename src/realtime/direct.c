// Direct light of the hybrid frame: D = sum_l U_l * S_l + environment. U_l is the unshadowed
// light (raster/shading.c); S_l the shadow term of the chosen technique: the hard-shadow
// buffer, or a shadow map filtered by PCF or PCSS. Techniques of other folders write S_l
// too (ISG, AAF) and the conductor then sums D here; `reference` writes D itself.
#include "drift/denoise.h"
#include "realtime/realtime.h"

#include <math.h>
#include <stdlib.h>

static size_t pixel_index(const drift_frame_state *f, int32_t x, int32_t y)
{
    return (size_t)y * (size_t)f->params.width + (size_t)x;
}

// The environment's direct light at pixel (x, y) of surface s: --light-samples shadow rays,
// or with interleaving this pixel's quarter of its 2 x 2 block's shared set.
static drift_vec3 environment_light(const drift_frame_state *f, const drift_surface *s,
                                    drift_bsdf bsdf, drift_vec3 wo, int32_t x, int32_t y,
                                    drift_sampler *sampler, uint64_t *rays)
{
    // A row that renders the environment's diffuse light itself (occlusion) leaves D its
    // glossy part only.
    if (f->environment_diffuse_elsewhere) {
        bsdf.diffuse = drift_vec3_splat(0.0f);
        bsdf.ggx.skip_diffuse = true;
    }
    // A GGX surface's conductor and coat reflection of the environment: the split sum over
    // the prefiltered environment (raster/env_prefilter.c); the samples below take the rest.
    const drift_env_prefilter *prefilter = drift_realtime_of(f)->env_prefilter;
    bool split = prefilter && bsdf.type == DRIFT_MATERIAL_GGX;
    bsdf.ggx.skip_reflection = split;
    drift_vec3 l;
    if (!f->params.environment_interleave) {
        l = drift_raster_environment_direct(f->scene, f->accel, s, &bsdf, wo,
                                            f->params.light_samples, sampler, rays);
    } else {
        // One shifted set of 4 m points for the 2 x 2 block; this pixel takes every fourth.
        uint32_t m = (f->params.light_samples + 3) / 4;
        drift_sampler block = drift_pass_sampler(f, DRIFT_STREAM_UNSHADOWED, x & ~1, y & ~1);
        l = drift_raster_environment_direct_subset(f->scene, f->accel, s, &bsdf, wo, 4 * m,
                                                   (uint32_t)((x & 1) | ((y & 1) << 1)), 4,
                                                   drift_sampler_next2(&block), rays);
    }
    if (split) {
        uint32_t n = f->params.light_samples > 0 ? f->params.light_samples : 1;
        l = drift_vec3_add(l,
                           drift_raster_environment_split_sum(prefilter, f->accel, s, &bsdf, wo, n,
                                                              drift_sampler_next2(sampler), rays));
    }
    return l;
}

// The unshadowed light of pixels x0 .. x0 + n - 1 of row y (n <= DRIFT_RASTER_ROW_MAX): each
// closed-form polygon light for the whole run at once (drift_raster_polygon_rows, vectorised),
// the rest pixel by pixel, each pixel's sampler drawn in the same order as one pixel alone.
static void unshadowed_run(drift_frame_state *f, int32_t x0, int32_t n, int32_t y, uint64_t *rays)
{
    drift_vec3 zero = drift_vec3_splat(0.0f);
    drift_bsdf bsdf[DRIFT_RASTER_ROW_MAX];
    drift_vec3 wo[DRIFT_RASTER_ROW_MAX];
    drift_sampler sampler[DRIFT_RASTER_ROW_MAX];
    float p[6][DRIFT_RASTER_ROW_MAX], e[3][DRIFT_RASTER_ROW_MAX];
    const drift_surface *s = &f->gbuffer.surfaces[pixel_index(f, x0, y)];
    for (int32_t i = 0; i < n; ++i) {
        int32_t x = x0 + i;
        if (s[i].material == DRIFT_INVALID_INDEX) {
            for (int k = 0; k < 6; ++k) {
                p[k][i] = 0.0f;
            }
            continue;
        }
        bsdf[i] = drift_bsdf_make(f->scene, &s[i]);
        wo[i] = drift_pass_wo(f, x, y);
        sampler[i] = drift_pass_sampler(f, DRIFT_STREAM_UNSHADOWED, x, y);
        p[0][i] = s[i].position.x, p[1][i] = s[i].position.y, p[2][i] = s[i].position.z;
        p[3][i] = bsdf[i].frame.z.x, p[4][i] = bsdf[i].frame.z.y, p[5][i] = bsdf[i].frame.z.z;
    }
    drift_raster_receivers rs = { p[0], p[1], p[2], p[3], p[4], p[5], n };
    for (uint32_t l = 0; l < f->light_count; ++l) {
        const drift_raster_light *light = &f->lights[l];
        bool rows = drift_raster_has_polygon_rows(light);
        if (rows) {
            drift_raster_polygon_rows(f->scene, light, &rs, e[0], e[1], e[2]);
        }
        for (int32_t i = 0; i < n; ++i) {
            drift_vec3 u = zero;
            if (s[i].material != DRIFT_INVALID_INDEX) {
                u = rows ? drift_raster_unshadowed_given(f->scene, light, &s[i], &bsdf[i], wo[i],
                                                         f->params.light_samples, &sampler[i],
                                                         drift_vec3_make(e[0][i], e[1][i], e[2][i]))
                         : drift_raster_unshadowed(f->scene, light, &s[i], &bsdf[i], wo[i],
                                                   f->params.light_samples, &sampler[i]);
            }
            drift_image_set3(&f->light_buffers[l].unshadowed, x0 + i, y, u);
        }
    }
    const bool sparse = f->params.environment_scale == 2 && drift_scene_has_environment(f->scene);
    for (int32_t i = 0; i < n; ++i) {
        int32_t x = x0 + i;
        if (s[i].material == DRIFT_INVALID_INDEX) {
            drift_image_set3(&f->environment_direct, x, y, zero);
            continue;
        }
        if (sparse && ((x | y) & 1)) { // filled from the traced pixels (fill_sparse_pixel)
            drift_image_set3(&f->environment_direct, x, y, drift_vec3_splat(-1.0f));
            continue;
        }
        drift_image_set3(&f->environment_direct, x, y,
                         environment_light(f, &s[i], bsdf[i], wo[i], x, y, &sampler[i], rays));
    }
}

static void unshadowed_row(drift_frame_state *f, int32_t y, uint64_t *rays, void *user)
{
    (void)user;
    for (int32_t x0 = 0; x0 < f->params.width; x0 += DRIFT_RASTER_ROW_MAX) {
        int32_t n = f->params.width - x0;
        unshadowed_run(f, x0, n < DRIFT_RASTER_ROW_MAX ? n : DRIFT_RASTER_ROW_MAX, y, rays);
    }
}

// Whether pixel (u, v) lies on the surface of pixel `centre` (at view depth `depth`): the same
// mesh, normals within 25 degrees, depth within 5%. Its environment light may stand in for
// the centre's.
static bool on_centre_surface(const drift_frame_state *f, size_t centre, float depth, int32_t u,
                              int32_t v)
{
    const drift_gbuffer *g = &f->gbuffer;
    return drift_gbuffer_same_surface(g, centre, pixel_index(f, u, v)) &&
           fabsf(drift_image_pixel(&g->depth, u, v)[0] - depth) <= 0.05f * depth;
}

// Interleaved environment light gathered back: a 3 x 3 tent (1 2 1 x 1 2 1) weighs each of the
// 2 x 2 block's four point sets alike at a pixel, over the neighbours on the same surface
// (same mesh, normals within 25 degrees, depth within 5%), renormalised where some are not.
typedef struct interleave_job {
    const drift_image *in;
    drift_image *out;
} interleave_job;

static void interleave_gather_pixel(drift_frame_state *f, int32_t x, int32_t y, uint64_t *rays,
                                    void *user)
{
    (void)rays;
    const interleave_job *job = user;
    const drift_gbuffer *g = &f->gbuffer;
    size_t centre = pixel_index(f, x, y);
    if (g->surfaces[centre].material == DRIFT_INVALID_INDEX) {
        drift_image_set3(job->out, x, y, drift_image_get3(job->in, x, y));
        return;
    }
    float depth = drift_image_pixel(&g->depth, x, y)[0];
    drift_vec3 sum = drift_vec3_splat(0.0f);
    float total = 0.0f;
    for (int32_t dy = -1; dy <= 1; ++dy) {
        for (int32_t dx = -1; dx <= 1; ++dx) {
            int32_t u = x + dx, v = y + dy;
            if (u < 0 || v < 0 || u >= f->params.width || v >= f->params.height) {
                continue;
            }
            if (!on_centre_surface(f, centre, depth, u, v)) {
                continue;
            }
            float w = (float)((2 - abs(dx)) * (2 - abs(dy)));
            sum = drift_vec3_fma(sum, drift_image_get3(job->in, u, v), w);
            total += w;
        }
    }
    drift_image_set3(job->out, x, y, drift_vec3_scale(sum, 1.0f / total)); // total >= 4
}

// Hard shadows of one row toward one light, traced as coherent packets: neighbouring
// pixels aim at the same centre.
#define SHADOW_BATCH 64

// Where a ray from `ray`'s origin toward a point inside a sphere light (a tessellated sphere
// or a sphere; its vertices lie within `radius` of its centre) enters the sphere 1.001 times
// that size, short of which it can meet none of the light's own surface; `fallback` when it
// misses it (only rounding: the ray aims inside).
static float sphere_entry(const drift_raster_light *light, const drift_ray *ray, float fallback)
{
    float r = 1.001f * light->radius;
    drift_vec3 oc = drift_vec3_sub(light->centre, ray->origin);
    float b = drift_vec3_dot(oc, ray->dir), c = drift_vec3_dot(oc, oc) - r * r;
    float disc = b * b - c;
    return disc > 0.0f && b - sqrtf(disc) > 0.0f ? (b - sqrtf(disc)) * (1.0f - 1e-4f) : fallback;
}

// Where an any-hit shadow ray toward `light` must stop to meet none of the light's own
// surface: shadow_clearance short of its tmax, and for a flat emitter (one-sided with a
// clearance of 0) short of where the ray crosses the emitter's plane. The ray leaves from an
// origin offset off the surface, so at a grazing angle that crossing comes before the
// centre's distance d (1 - 1e-4) that tmax holds.
static float any_hit_tmax(const drift_raster_light *light, const drift_ray *ray, bool aimed)
{
    float tmax = ray->tmax - light->shadow_clearance;
    if (aimed && (light->sphere_radius > 0.0f || light->type == DRIFT_LIGHT_SPHERE)) {
        // Aimed off the centre (aimed_shadow_ray): stop where it enters the sphere, if that is
        // sooner.
        tmax = fminf(tmax, sphere_entry(light, ray, tmax));
    }
    if (light->one_sided) {
        float cos_plane = drift_vec3_dot(ray->dir, light->direction);
        float t = drift_vec3_dot(drift_vec3_sub(light->centre, ray->origin), light->direction) /
                  cos_plane;
        if (cos_plane != 0.0f && t > 0.0f) {
            tmax = fminf(tmax, t * (1.0f - 1e-4f));
        }
    }
    return tmax;
}

// Under --aa N (N > 1) with `hard` shadows, pass k's hard-shadow ray toward an area light aims
// at point k of a stratified set of N on it, each pixel's set rotated by its own hash (keyed on the
// frame's seed, not the pass's, so the N passes take the N points of one set): the passes'
// mean is the accumulation buffer's soft shadow (Haeberli and Akeley 1990), noise in the
// penumbra where one shared set would draw N shifted hard edges. A sphere (or tessellated
// sphere) is aimed at through its silhouette disc facing the pixel, the other area lights
// through drift_raster_light_sample; point, spot and directional lights keep the centre ray.
static bool aims_off_centre(const drift_frame_state *f, const drift_raster_light *light)
{
    return f->params.aa > 1 && f->params.shadows == DRIFT_SHADOWS_HARD && light->radius > 0.0f &&
           drift_light_is_area(light->type);
}

// That ray (only where aims_off_centre).
static drift_ray aimed_shadow_ray(const drift_frame_state *f, uint32_t l, const drift_surface *s,
                                  int32_t x, int32_t y, float *light_distance)
{
    const drift_raster_light *light = &f->lights[l];
    uint32_t passes = f->params.aa;
    bool sphere = light->sphere_radius > 0.0f || light->type == DRIFT_LIGHT_SPHERE;
    // A hash, not a sampler: this is one rotation a pixel, and a ray is all the pass costs.
    uint32_t pixel = (uint32_t)y * (uint32_t)f->params.width + (uint32_t)x;
    uint32_t h = drift_hash_combine(
        drift_hash_combine(f->base_seed, DRIFT_STREAM_HARD_SHADOW_AIM + 16u * l), pixel);
    uint32_t h2 = drift_hash_u32(h), h3 = drift_hash_u32(h2);
    drift_vec2 shift = drift_vec2_make((float)(h >> 8) * 0x1p-24f, (float)(h2 >> 8) * 0x1p-24f);
    drift_vec2 u = drift_hammersley_shifted(f->aa_pass, passes, shift);
    drift_vec3 target;
    if (sphere) {
        // The disc through the centre facing the pixel, of the radius the surface spans (a
        // pixel inside the sphere keeps the centre ray: it has no silhouette).
        float radius = light->sphere_radius > 0.0f ? light->sphere_radius : light->radius;
        drift_vec3 away = drift_vec3_sub(s->position, light->centre);
        float far = drift_vec3_length(away);
        if (!(far > light->radius)) {
            return drift_raster_hard_shadow_ray(light, s, light_distance);
        }
        drift_frame frame = drift_frame_from_normal(drift_vec3_scale(away, 1.0f / far));
        drift_vec2 d = drift_sample_disk_concentric(u);
        target = drift_vec3_add(
            light->centre,
            drift_frame_to_world(
                &frame, drift_vec3_make(0.99f * radius * d.x, 0.99f * radius * d.y, 0.0f)));
    } else {
        float pick = (float)(h3 >> 8) * 0x1p-24f + (float)f->aa_pass * 0.618034f;
        target =
            drift_raster_light_sample(f->scene, light, s->position, pick - floorf(pick), u).point;
    }
    drift_vec3 d = drift_vec3_sub(target, s->position);
    float distance = drift_vec3_length(d);
    if (!(distance > 0.0f)) {
        return drift_raster_hard_shadow_ray(light, s, light_distance);
    }
    drift_vec3 dir = drift_vec3_scale(d, 1.0f / distance);
    *light_distance = distance;
    return (drift_ray){ .origin = drift_offset_origin(s->position, s->ng, dir),
                        .dir = dir,
                        .tmin = 0.0f,
                        .tmax = distance * (1.0f - 1e-4f) };
}

static void hard_shadow_row(drift_frame_state *f, int32_t y, uint64_t *rays, void *user)
{
    bool occluder_distances = *(const bool *)user;
    drift_ray batch[SHADOW_BATCH];
    drift_hit hits[SHADOW_BATCH];
    uint8_t occluded[SHADOW_BATCH];
    int32_t xs[SHADOW_BATCH];
    float light_distance[SHADOW_BATCH];
    for (uint32_t l = 0; l < f->light_count; ++l) {
        drift_frame_light_buffers *b = &f->light_buffers[l];
        bool any_hit = !occluder_distances && f->lights[l].shadow_clearance >= 0.0f;
        bool aimed = aims_off_centre(f, &f->lights[l]);
        for (int32_t x0 = 0; x0 < f->params.width; x0 += SHADOW_BATCH) {
            int32_t x1 = x0 + SHADOW_BATCH < f->params.width ? x0 + SHADOW_BATCH : f->params.width;
            uint32_t n = 0;
            for (int32_t x = x0; x < x1; ++x) {
                const drift_surface *s = &f->gbuffer.surfaces[pixel_index(f, x, y)];
                float *out = drift_image_pixel(&b->hard_shadow, x, y);
                if (s->material == DRIFT_INVALID_INDEX) {
                    out[0] = 0.0f;
                    out[1] = out[2] = INFINITY;
                    drift_image_pixel(&b->shadow, x, y)[0] = 0.0f;
                    continue;
                }
                xs[n] = x;
                batch[n] = aimed
                               ? aimed_shadow_ray(f, l, s, x, y, &light_distance[n])
                               : drift_raster_hard_shadow_ray(&f->lights[l], s, &light_distance[n]);
                ++n;
            }
            if (any_hit) {
                for (uint32_t k = 0; k < n; ++k) {
                    batch[k].tmax = any_hit_tmax(&f->lights[l], &batch[k], aimed);
                }
                drift_accel_occluded_coherent(f->accel, batch, occluded, n);
            } else {
                drift_accel_intersect_coherent(f->accel, batch, hits, n);
            }
            *rays += n;
            for (uint32_t k = 0; k < n; ++k) {
                float *out = drift_image_pixel(&b->hard_shadow, xs[k], y);
                bool visible;
                if (any_hit) {
                    visible = !occluded[k];
                    out[1] = visible ? INFINITY : 0.0f;
                } else {
                    visible = drift_raster_hard_shadow_visible(&f->lights[l], &hits[k], &out[1]);
                }
                out[0] = visible ? 1.0f : 0.0f;
                out[2] = light_distance[k];
                drift_image_pixel(&b->shadow, xs[k], y)[0] = out[0];
            }
        }
    }
}

static void shadow_filter_pixel(drift_frame_state *f, int32_t x, int32_t y, uint64_t *rays,
                                void *user)
{
    (void)rays;
    bool pcss = *(const bool *)user;
    const drift_surface *s = &f->gbuffer.surfaces[pixel_index(f, x, y)];
    uint32_t hash =
        drift_hash_combine(f->params.seed ^ DRIFT_STREAM_PCSS, (uint32_t)pixel_index(f, x, y));
    for (uint32_t l = 0; l < f->light_count; ++l) {
        const drift_shadow_map *map = drift_realtime_shadow_map(f, l);
        float v = 0.0f;
        if (s->material != DRIFT_INVALID_INDEX) {
            v = pcss ? drift_shadow_map_pcss(map, s->position, s->ng, drift_hash_u32(hash + l))
                     : drift_shadow_map_pcf(map, s->position, s->ng,
                                            f->params.shadow_map.pcf_kernel);
        }
        drift_image_pixel(&f->light_buffers[l].shadow, x, y)[0] = v;
    }
}

// A row at a time (no call per pixel), the lights' terms added in the same order.
static void sum_direct_row(drift_frame_state *f, int32_t y, uint64_t *rays, void *user)
{
    (void)rays;
    (void)user;
    const int32_t w = f->params.width;
    const float *env = drift_image_pixel(&f->environment_direct, 0, y);
    float *out = drift_image_pixel(&f->direct, 0, y);
    const int32_t ce = f->environment_direct.channels, co = f->direct.channels;
    for (int32_t x = 0; x < w; ++x) {
        float *o = out + (ptrdiff_t)x * co;
        const float *e = env + (ptrdiff_t)x * ce;
        o[0] = e[0];
        o[1] = e[1];
        o[2] = e[2];
    }
    for (uint32_t l = 0; l < f->light_count; ++l) {
        const drift_frame_light_buffers *b = &f->light_buffers[l];
        const float *u = drift_image_pixel(&b->unshadowed, 0, y);
        const float *s = drift_image_pixel(&b->shadow, 0, y);
        const int32_t cu = b->unshadowed.channels, cs = b->shadow.channels;
        for (int32_t x = 0; x < w; ++x) {
            float *o = out + (ptrdiff_t)x * co;
            const float *ux = u + (ptrdiff_t)x * cu;
            float sx = s[(ptrdiff_t)x * cs];
            o[0] = o[0] + ux[0] * sx;
            o[1] = o[1] + ux[1] * sx;
            o[2] = o[2] + ux[2] * sx;
        }
    }
}

drift_result drift_realtime_ensure_shadow_map(drift_frame_state *f, uint32_t light, uint64_t *rays)
{
    drift_realtime_state *s = drift_realtime_of(f);
    if (s->shadow_maps[light]) {
        return DRIFT_OK; // cached: the scene has not changed
    }
    drift_shadow_map_params params = { .size = f->params.shadow_map.size,
                                       .bias_texels = f->params.shadow_map.bias };
    return drift_shadow_map_build(f->ctx, f->scene, f->accel, &f->lights[light], &params,
                                  &s->shadow_maps[light], rays);
}

void drift_realtime_drop_shadow_map(drift_frame_state *f, uint32_t light)
{
    drift_realtime_state *s = drift_realtime_of(f);
    drift_shadow_map_destroy(f->ctx, s->shadow_maps[light]);
    s->shadow_maps[light] = NULL;
}

drift_result drift_realtime_build_shadow_maps(drift_frame_state *f)
{
    double t = drift_time_now();
    drift_result r = DRIFT_OK;
    for (uint32_t l = 0; r == DRIFT_OK && l < f->light_count; ++l) {
        r = drift_realtime_ensure_shadow_map(f, l, &f->stats.rays[DRIFT_PASS_SHADOW_MAPS]);
    }
    drift_pass_time(f, DRIFT_PASS_SHADOW_MAPS, t);
    return r;
}

// One pixel in 2 x 2 traced the environment's shadow rays (--env-scale 2); the others take
// the bilinear mix of the four traced pixels around them that lie on their surface (same
// mesh, normals within 25 degrees, depth within 5%), divided by those pixels' albedo and
// multiplied by their own: the visibility and irradiance carry over, the texture does not.
// A pixel with no such neighbour (a silhouette, a thin leaf) traces its own rays.
static float demodulating_albedo(const drift_gbuffer *g, int32_t x, int32_t y, int c)
{
    return drift_denoise_albedo_divisor(drift_image_pixel(&g->albedo, x, y)[c]);
}

static void fill_sparse_pixel(drift_frame_state *f, int32_t x, int32_t y, uint64_t *rays,
                              void *user)
{
    (void)user;
    float *out = drift_image_pixel(&f->environment_direct, x, y);
    if (out[0] >= 0.0f) {
        return; // traced, or no surface
    }
    const drift_gbuffer *g = &f->gbuffer;
    size_t centre = pixel_index(f, x, y);
    float depth = drift_image_pixel(&g->depth, x, y)[0];
    // Bilinear over the traced pixels (even x and y) around: an odd coordinate lies halfway
    // between two, an even one on one.
    const float wx[2] = { x & 1 ? 0.5f : 1.0f, x & 1 ? 0.5f : 0.0f };
    const float wy[2] = { y & 1 ? 0.5f : 1.0f, y & 1 ? 0.5f : 0.0f };
    float sum[3] = { 0.0f, 0.0f, 0.0f }, total = 0.0f;
    for (int32_t k = 0; k < 4; ++k) {
        int32_t u = (x & ~1) + 2 * (k & 1), v = (y & ~1) + (k & 2);
        float w = wx[k & 1] * wy[k >> 1];
        if (w == 0.0f || u >= f->params.width || v >= f->params.height ||
            !on_centre_surface(f, centre, depth, u, v)) { // (its mesh: so it has a surface)
            continue;
        }
        const float *e = drift_image_pixel(&f->environment_direct, u, v);
        for (int c = 0; c < 3; ++c) {
            sum[c] += w * e[c] / demodulating_albedo(g, u, v, c);
        }
        total += w;
    }
    if (total > 0.0f) {
        for (int c = 0; c < 3; ++c) {
            out[c] = sum[c] / total * demodulating_albedo(g, x, y, c);
        }
        return;
    }
    const drift_surface *s = &g->surfaces[centre];
    drift_sampler sampler = drift_pass_sampler(f, DRIFT_STREAM_UNSHADOWED, x, y);
    drift_image_set3(&f->environment_direct, x, y,
                     environment_light(f, s, drift_bsdf_make(f->scene, s), drift_pass_wo(f, x, y),
                                       x, y, &sampler, rays));
}

// The environment's direct light through the a-trous filter: its noise is the visibility of
// a few shadow rays a pixel, smooth where the surface is, so the G-buffer guides it and no
// colour weight keeps the noise itself. Demodulated by the albedo: texture stays sharp. The
// 3 x 3 kernel: 9 taps a pass, and at 4 passes (a 31-pixel footprint) the Breakfast Room's
// sky light is as smooth as with the 5 x 5 one at 2.7x the time (docs/hybrid.md).
// step 2 (--env-scale 2): the filter sees the traced pixels alone (one in 2 x 2, so a quarter
// of the work), copied out with their albedo, normal and depth, before the fill carries them
// to the rest: the same passes reach twice as far in full pixels, and the other three pixels
// only ever read filtered light.
// --env-denoise on: the path tracer's variance-guided filter over the same inputs. Its
// variance is the spatial one (stage 4: no per-pixel moments are kept for the shadow rays),
// over the light_samples rays of a pixel.
static drift_result denoise_environment(drift_frame_state *f, const drift_image *in[4],
                                        drift_image *out)
{
    const uint32_t rays = f->params.light_samples; // (interleaved: gathered back to a set)
    const drift_denoise_inputs inputs = {
        .color = in[0], .albedo = in[1], .normal = in[2], .depth = in[3], .sample_count = rays
    };
    const drift_denoise_feature_params params = { .iterations =
                                                      (int32_t)f->params.environment_filter };
    return drift_denoise_feature(f->ctx, &inputs, &params, out, NULL);
}

static drift_result filter_environment(drift_frame_state *f, int32_t step)
{
    double t = drift_time_now();
    const drift_gbuffer *g = &f->gbuffer;
    const drift_image *full[4] = { &f->environment_direct, &g->albedo, &g->normal, &g->depth };
    const drift_image *in[4] = { full[0], full[1], full[2], full[3] };
    drift_image grid[4] = { 0 }; // step 2: colour, albedo, normal, depth of the traced pixels
    int32_t w = (f->params.width + step - 1) / step, h = (f->params.height + step - 1) / step;
    drift_result r = DRIFT_OK;
    for (int k = 0; step > 1 && k < 4 && r == DRIFT_OK; ++k) {
        r = drift_image_create(f->ctx, w, h, full[k]->channels < 3 ? 1 : 3, &grid[k]);
        for (int32_t y = 0; r == DRIFT_OK && y < h; ++y) {
            for (int32_t x = 0; x < w; ++x) {
                const float *from = drift_image_pixel(full[k], step * x, step * y);
                float *to = drift_image_pixel(&grid[k], x, y);
                for (int32_t c = 0; c < grid[k].channels; ++c) {
                    to[c] = from[c];
                }
            }
        }
        in[k] = &grid[k];
    }
    drift_denoise_params params = { .iterations = (int32_t)f->params.environment_filter,
                                    .disable_color = true,
                                    .small_kernel = true };
    drift_image filtered = { 0 };
    if (r == DRIFT_OK && f->params.environment_denoise) {
        r = denoise_environment(f, in, &filtered);
    } else if (r == DRIFT_OK) {
        r = drift_denoise_atrous(f->ctx, in[0], in[1], in[2], in[3], &params, &filtered);
    }
    if (r == DRIFT_OK && step == 1) { // the plane's struct is what the frame's planes point at
        drift_image traced = f->environment_direct;
        f->environment_direct = filtered;
        filtered = traced;
    }
    for (int32_t y = 0; r == DRIFT_OK && step > 1 && y < h; ++y) {
        for (int32_t x = 0; x < w; ++x) {
            drift_image_set3(&f->environment_direct, step * x, step * y,
                             drift_image_get3(&filtered, x, y));
        }
    }
    drift_image_destroy(f->ctx, &filtered);
    for (int k = 0; k < 4; ++k) {
        drift_image_destroy(f->ctx, &grid[k]);
    }
    drift_pass_time(f, DRIFT_PASS_UNSHADOWED, t);
    return r;
}

// The interleaved environment light summed back over 3 x 3 pixels of the same surface.
static drift_result gather_interleaved(drift_frame_state *f)
{
    drift_image gathered;
    drift_result r = drift_image_create(f->ctx, f->params.width, f->params.height, 3, &gathered);
    if (r != DRIFT_OK) {
        return r;
    }
    interleave_job job = { .in = &f->environment_direct, .out = &gathered };
    drift_pass_pixels(f, DRIFT_PASS_UNSHADOWED, interleave_gather_pixel, &job);
    // The gathered image becomes the plane (the frame's planes point at the struct, not at
    // its pixels); the interleaved one is freed.
    drift_image interleaved = f->environment_direct;
    f->environment_direct = gathered;
    drift_image_destroy(f->ctx, &interleaved);
    return DRIFT_OK;
}

drift_result drift_realtime_pass_unshadowed(drift_frame_state *f)
{
    drift_realtime_state *state = drift_realtime_of(f);
    if (!state->env_prefilter && drift_scene_has_environment(f->scene)) {
        double t = drift_time_now(); // made once, timed with the environment-map probes
        drift_result r = drift_env_prefilter_build(f->ctx, f->scene, &state->env_prefilter);
        drift_pass_time(f, DRIFT_PASS_ENVMAP, t);
        if (r != DRIFT_OK) {
            return r;
        }
    }
    drift_pass_rows(f, DRIFT_PASS_UNSHADOWED, unshadowed_row, NULL);
    if (!drift_scene_has_environment(f->scene)) {
        return DRIFT_OK;
    }
    drift_result r = DRIFT_OK;
    const bool filter = f->params.environment_filter > 0;
    if (f->params.environment_scale == 2) { // (never with interleaving: params_valid)
        if (filter) {
            r = filter_environment(f, 2);
        }
        drift_pass_pixels(f, DRIFT_PASS_UNSHADOWED, fill_sparse_pixel, NULL);
        return r;
    }
    if (f->params.environment_interleave) {
        r = gather_interleaved(f);
    }
    if (r == DRIFT_OK && filter) {
        r = filter_environment(f, 1);
    }
    return r;
}

drift_result drift_realtime_pass_hard_shadows(drift_frame_state *f, bool occluder_distances)
{
    drift_pass_rows(f, DRIFT_PASS_HARD_SHADOWS, hard_shadow_row, &occluder_distances);
    return DRIFT_OK;
}

static drift_result shadow_filter(drift_frame_state *f, bool pcss)
{
    drift_pass_pixels(f, DRIFT_PASS_SHADOW_FILTER, shadow_filter_pixel, &pcss);
    return DRIFT_OK;
}

drift_result drift_realtime_pass_pcf(drift_frame_state *f, const drift_pass_args *args)
{
    (void)args;
    return shadow_filter(f, false);
}

drift_result drift_realtime_pass_pcss(drift_frame_state *f, const drift_pass_args *args)
{
    (void)args;
    return shadow_filter(f, true);
}

drift_result drift_realtime_pass_sum_direct(drift_frame_state *f)
{
    drift_pass_rows(f, DRIFT_PASS_COMPOSE, sum_direct_row, NULL); // part of composition
    return DRIFT_OK;
}
