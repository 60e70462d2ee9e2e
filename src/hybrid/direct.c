// Direct light of the hybrid frame: D = sum_l U_l * S_l + environment. U_l is the unshadowed
// light (shading.c); S_l the shadow term of the chosen technique: the hard-shadow buffer, or
// a shadow map filtered by PCF or PCSS. The reference technique leaves D to reference.c.
#include "hybrid/frame_internal.h"
#include "hybrid/isg_internal.h"
#include "hybrid/aaf_internal.h"

#include <math.h>

// Sampler streams, so that passes draw independent numbers for the same pixel.
enum { STREAM_UNSHADOWED = 1, STREAM_PCSS = 2 };

static size_t pixel_index(const drift_hybrid *f, int32_t x, int32_t y)
{
    return (size_t)y * (size_t)f->params.width + (size_t)x;
}

static void unshadowed_pixel(drift_hybrid *f, int32_t x, int32_t y, uint64_t *rays, void *user)
{
    (void)user;
    const drift_surface *s = &f->gbuffer.surfaces[pixel_index(f, x, y)];
    drift_vec3 zero = drift_vec3_splat(0.0f);
    if (s->material == DRIFT_INVALID_INDEX) {
        for (uint32_t l = 0; l < f->light_count; ++l) {
            drift_image_set3(&f->light_buffers[l].unshadowed, x, y, zero);
        }
        drift_image_set3(&f->environment_direct, x, y, zero);
        return;
    }
    drift_bsdf bsdf = drift_bsdf_make(f->scene, s);
    drift_vec3 wo = drift_hybrid_wo(f, x, y);
    drift_sampler sampler = drift_hybrid_sampler(f, STREAM_UNSHADOWED, x, y);
    for (uint32_t l = 0; l < f->light_count; ++l) {
        drift_vec3 u = drift_hybrid_unshadowed(f->scene, &f->lights[l], s, &bsdf, wo,
                                               f->params.light_samples, &sampler);
        drift_image_set3(&f->light_buffers[l].unshadowed, x, y, u);
    }
    drift_image_set3(&f->environment_direct, x, y,
           drift_hybrid_environment_direct(f->scene, f->accel, s, &bsdf, wo,
                                           f->params.light_samples, &sampler, rays));
}

// Hard shadows of one row toward one light, traced as coherent packets: neighbouring
// pixels aim at the same centre.
#define SHADOW_BATCH 64

static void hard_shadow_row(drift_hybrid *f, int32_t y, uint64_t *rays, void *user)
{
    (void)user;
    drift_ray batch[SHADOW_BATCH];
    drift_hit hits[SHADOW_BATCH];
    int32_t xs[SHADOW_BATCH];
    float light_distance[SHADOW_BATCH];
    for (uint32_t l = 0; l < f->light_count; ++l) {
        drift_hybrid_light_buffers *b = &f->light_buffers[l];
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
                batch[n] = drift_hybrid_hard_shadow_ray(&f->lights[l], s, &light_distance[n]);
                ++n;
            }
            drift_accel_intersect_coherent(f->accel, batch, hits, n);
            *rays += n;
            for (uint32_t k = 0; k < n; ++k) {
                float *out = drift_image_pixel(&b->hard_shadow, xs[k], y);
                bool visible = drift_hybrid_hard_shadow_visible(&f->lights[l], &hits[k], &out[1]);
                out[0] = visible ? 1.0f : 0.0f;
                out[2] = light_distance[k];
                drift_image_pixel(&b->shadow, xs[k], y)[0] = out[0];
            }
        }
    }
}

static void shadow_filter_pixel(drift_hybrid *f, int32_t x, int32_t y, uint64_t *rays, void *user)
{
    (void)rays;
    (void)user;
    const drift_surface *s = &f->gbuffer.surfaces[pixel_index(f, x, y)];
    uint32_t hash = drift_hash_combine(f->params.seed ^ STREAM_PCSS, (uint32_t)pixel_index(f, x, y));
    for (uint32_t l = 0; l < f->light_count; ++l) {
        const drift_shadow_map *map = f->light_buffers[l].shadow_map;
        float v = 0.0f;
        if (s->material != DRIFT_INVALID_INDEX) {
            v = f->params.shadows == DRIFT_SHADOWS_PCSS
                    ? drift_shadow_map_pcss(map, s->position, s->ng, drift_hash_u32(hash + l))
                    : drift_shadow_map_pcf(map, s->position, s->ng, f->params.pcf_kernel);
        }
        drift_image_pixel(&f->light_buffers[l].shadow, x, y)[0] = v;
    }
}

static void sum_direct_pixel(drift_hybrid *f, int32_t x, int32_t y, uint64_t *rays, void *user)
{
    (void)rays;
    (void)user;
    drift_vec3 d = drift_image_get3(&f->environment_direct, x, y);
    for (uint32_t l = 0; l < f->light_count; ++l) {
        const drift_hybrid_light_buffers *b = &f->light_buffers[l];
        d = drift_vec3_fma(d, drift_image_get3(&b->unshadowed, x, y), drift_image_pixel(&b->shadow, x, y)[0]);
    }
    drift_image_set3(&f->direct, x, y, d);
}

static drift_result build_shadow_maps(drift_hybrid *f)
{
    drift_shadow_map_params params = { .size = f->params.shadow_map_size,
                                       .bias_texels = f->params.shadow_bias };
    for (uint32_t l = 0; l < f->light_count; ++l) {
        if (f->light_buffers[l].shadow_map) {
            continue; // cached: the scene has not changed
        }
        drift_result r = drift_shadow_map_build(f->ctx, f->scene, f->accel, &f->lights[l], &params,
                                                &f->light_buffers[l].shadow_map,
                                                &f->stats.rays[DRIFT_PASS_SHADOW_MAPS]);
        if (r != DRIFT_OK) {
            return r;
        }
    }
    return DRIFT_OK;
}

drift_result drift_hybrid_pass_direct(drift_hybrid *f)
{
    drift_hybrid_stats *st = &f->stats;
    if (f->params.shadows == DRIFT_SHADOWS_REFERENCE) {
        return DRIFT_OK; // reference.c fills `direct`
    }
    double t = drift_time_now();
    st->rays[DRIFT_PASS_UNSHADOWED] += drift_hybrid_for_each_pixel(f, unshadowed_pixel, NULL);
    st->ms[DRIFT_PASS_UNSHADOWED] = 1000.0 * (drift_time_now() - t);

    t = drift_time_now();
    drift_shadow_technique shadows = f->params.shadows;
    if (shadows == DRIFT_SHADOWS_HARD || shadows == DRIFT_SHADOWS_ISG ||
        shadows == DRIFT_SHADOWS_BLUR) {
        st->rays[DRIFT_PASS_HARD_SHADOWS] += drift_hybrid_for_each_row(f, hard_shadow_row, NULL);
        st->ms[DRIFT_PASS_HARD_SHADOWS] = 1000.0 * (drift_time_now() - t);
        if (shadows != DRIFT_SHADOWS_HARD) {
            drift_result r = drift_isg_pass_shadows(f); // gathers the bits into S_l
            if (r != DRIFT_OK) {
                return r;
            }
        }
    } else if (f->params.shadows == DRIFT_SHADOWS_AAF) {
        drift_result r = drift_hybrid_pass_aaf_shadows(f); // times its own passes
        if (r != DRIFT_OK) {
            return r;
        }
    } else {
        drift_result r = build_shadow_maps(f);
        st->ms[DRIFT_PASS_SHADOW_MAPS] = 1000.0 * (drift_time_now() - t);
        if (r != DRIFT_OK) {
            return r;
        }
        t = drift_time_now();
        drift_hybrid_for_each_pixel(f, shadow_filter_pixel, NULL);
        st->ms[DRIFT_PASS_SHADOW_FILTER] = 1000.0 * (drift_time_now() - t);
    }
    // Summing is part of composition.
    t = drift_time_now();
    drift_hybrid_for_each_pixel(f, sum_direct_pixel, NULL);
    st->ms[DRIFT_PASS_COMPOSE] += 1000.0 * (drift_time_now() - t);
    return DRIFT_OK;
}
