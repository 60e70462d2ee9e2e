// AAF diffuse indirect light (--indirect aaf; Mehta, Wang, Ramamoorthi 2013; docs/aaf.md):
// the frame's I term, the light whose first bounce is the diffuse lobe, path-traced per pixel
// and filtered in world space:
//   1. sparse: a few cosine-weighted rays; their hit distances give z_min and z_max, which set
//      beta (eq. 4.4, Omega_h^max = 2.8 for the diffuse lobe, eq. 4.5) and n(x) (eq. 4.6);
//   2. adaptive: the --spp budget spread in proportion to n(x), capped at aaf_max_spp;
//   3. the separable filter on the incoming radiance (the estimate divided by the albedo, so
//      texture is not blurred), then multiplied back by the albedo.
// Each sample is one bounce (max_depth 2, the reference's default) or more (max_depth 3:
// two bounces), with next-event estimation at every vertex after the first: emission that a
// bounce ray meets is direct light, which the frame computes apart (shadows technique).
#include "hybrid/aaf_internal.h"

#include <math.h>

enum { STREAM_AAF_INDIRECT = 0x5aaf1000u };

typedef struct indirect_job {
    uint32_t key;
    uint32_t sparse;
    float shrink;
    bool uniform;
    int32_t bounces;
} indirect_job;

static size_t pixel_index(const drift_hybrid *f, int32_t x, int32_t y)
{
    return (size_t)y * (size_t)f->params.width + (size_t)x;
}

// Direct light leaving surface y toward wo: one sample of every light and of the environment,
// each with its shadow ray.
static drift_vec3 next_event(drift_hybrid *f, const drift_surface *y, const drift_bsdf *bsdf,
                             drift_vec3 wo, drift_sampler *sampler, uint64_t *rays)
{
    drift_vec3 sum = drift_vec3_splat(0.0f);
    uint32_t count = f->light_count + (drift_scene_has_environment(f->scene) ? 1u : 0u);
    for (uint32_t l = 0; l < count; ++l) {
        float pick = drift_sampler_next1(sampler);
        drift_vec2 u = drift_sampler_next2(sampler);
        drift_light_sample ls = l < f->light_count
                                    ? drift_hybrid_light_sample(f->scene, &f->lights[l], y->position, pick, u)
                                    : drift_environment_sample(f->scene, u);
        if (!(ls.pdf > 0.0f) || drift_vec3_is_zero(ls.radiance)) {
            continue;
        }
        drift_vec3 fr = drift_bsdf_eval(bsdf, wo, ls.wi);
        float cos_i = fabsf(drift_vec3_dot(ls.wi, y->ns));
        drift_vec3 c = drift_vec3_scale(drift_vec3_mul(fr, ls.radiance), cos_i / ls.pdf);
        if (drift_vec3_is_zero(c) || !drift_vec3_is_finite(c)) {
            continue;
        }
        drift_ray shadow = { .origin = drift_offset_origin(y->position, y->ng, ls.wi),
                             .dir = ls.wi,
                             .tmin = 0.0f,
                             .tmax = isfinite(ls.distance) ? ls.distance * (1.0f - 1e-4f) : INFINITY };
        ++*rays;
        if (!drift_accel_occluded(f->accel, &shadow)) {
            sum = drift_vec3_add(sum, c);
        }
    }
    return sum;
}

// Radiance arriving at the pixel's surface along one cosine-weighted direction (the diffuse
// lobe's estimate is then albedo x this). *out_distance: the first hit, INFINITY for none.
static drift_vec3 trace_path(drift_hybrid *f, const indirect_job *job, const drift_surface *s,
                             drift_sampler *sampler, float *out_distance, uint64_t *rays)
{
    *out_distance = INFINITY;
    drift_vec3 total = drift_vec3_splat(0.0f);
    drift_frame frame = drift_frame_from_normal(s->ns);
    drift_vec3 dir = drift_frame_to_world(&frame, drift_sample_cosine_hemisphere(drift_sampler_next2(sampler)));
    if (!(drift_vec3_dot(dir, s->ng) > 0.0f)) {
        return total; // below the geometric surface: no light arrives this way
    }
    drift_ray ray = { .origin = drift_offset_origin(s->position, s->ng, dir),
                      .dir = dir,
                      .tmin = 0.0f,
                      .tmax = INFINITY };
    drift_vec3 throughput = drift_vec3_splat(1.0f);
    for (int32_t bounce = 0; bounce < job->bounces; ++bounce) {
        drift_hit hit;
        ++*rays;
        if (!drift_accel_intersect(f->accel, &ray, &hit)) {
            break; // the environment seen by a bounce ray is direct light (or was NEE's)
        }
        if (bounce == 0) {
            *out_distance = hit.t;
        }
        drift_surface y = drift_scene_surface(f->scene, &ray, &hit);
        if (y.material == DRIFT_INVALID_INDEX) {
            break; // a light's shape: its emission is counted by next-event estimation
        }
        drift_bsdf bsdf = drift_bsdf_make(f->scene, &y);
        drift_vec3 wo = drift_vec3_neg(ray.dir);
        total = drift_vec3_add(total, drift_vec3_mul(throughput, next_event(f, &y, &bsdf, wo, sampler, rays)));
        if (bounce + 1 == job->bounces) {
            break;
        }
        float u_lobe = drift_sampler_next1(sampler);
        drift_bsdf_sample bs = drift_bsdf_sample_wi(&bsdf, wo, u_lobe, drift_sampler_next2(sampler));
        if (!(bs.pdf > 0.0f) || bs.is_delta) {
            break; // after a mirror only emission would follow; NEE has none to add
        }
        throughput = drift_vec3_mul(throughput, bs.weight);
        ray = (drift_ray){ .origin = drift_offset_origin(y.position, y.ng, bs.wi),
                           .dir = bs.wi,
                           .tmin = 0.0f,
                           .tmax = INFINITY };
    }
    return drift_vec3_is_finite(total) ? total : drift_vec3_splat(0.0f);
}

// Running sums a pixel keeps between the passes, in state->aux and indirect_radiance.
typedef struct indirect_sums {
    float z_min, z_max, count, unused;
} indirect_sums;

static bool has_diffuse(const drift_hybrid *f, const drift_surface *s)
{
    if (s->material == DRIFT_INVALID_INDEX) {
        return false;
    }
    drift_bsdf bsdf = drift_bsdf_make(f->scene, s);
    return !drift_bsdf_is_delta(&bsdf) && !drift_vec3_is_zero(bsdf.diffuse);
}

static void add_samples(drift_hybrid *f, const indirect_job *job, int32_t x, int32_t y,
                        uint32_t first, uint32_t end, uint64_t *rays)
{
    size_t i = pixel_index(f, x, y);
    const drift_surface *s = &f->gbuffer.surfaces[i];
    indirect_sums *sums = (indirect_sums *)&f->aaf->aux[DRIFT_AAF_AUX * i];
    float *radiance = drift_image_pixel(&f->aaf->indirect_radiance, x, y);
    drift_vec3 sum = drift_vec3_scale(drift_vec3_make(radiance[0], radiance[1], radiance[2]), sums->count);
    for (uint32_t k = first; k < end; ++k) {
        drift_sampler sampler = drift_sampler_make(job->key, (uint32_t)i, k);
        float distance;
        sum = drift_vec3_add(sum, trace_path(f, job, s, &sampler, &distance, rays));
        if (isfinite(distance)) {
            sums->z_min = fminf(sums->z_min, distance);
            sums->z_max = fmaxf(sums->z_max, distance);
        }
    }
    sums->count = (float)end;
    drift_vec3 mean = end > 0 ? drift_vec3_scale(sum, 1.0f / (float)end) : sum;
    radiance[0] = mean.x;
    radiance[1] = mean.y;
    radiance[2] = mean.z;
}

static void sparse_pixel(drift_hybrid *f, int32_t x, int32_t y, uint64_t *rays, void *user)
{
    const indirect_job *job = user;
    drift_aaf_state *st = f->aaf;
    size_t i = pixel_index(f, x, y);
    indirect_sums *sums = (indirect_sums *)&st->aux[DRIFT_AAF_AUX * i];
    *sums = (indirect_sums){ INFINITY, 0.0f, 0.0f, 0.0f };
    drift_image_set3(&st->indirect_radiance, x, y, drift_vec3_splat(0.0f));
    drift_image_pixel(&st->indirect_beta, x, y)[0] = 0.0f;
    st->want[i] = 0.0f;
    if (!has_diffuse(f, &f->gbuffer.surfaces[i])) {
        return;
    }
    add_samples(f, job, x, y, 0, job->uniform ? f->params.spp : job->sparse, rays);
    if (!isfinite(sums->z_min)) {
        return; // open to the sky: nothing reflects light here, nothing to filter
    }
    float z_min = fmaxf(sums->z_min, 1e-4f), z_max = fmaxf(sums->z_max, z_min);
    float d = drift_image_pixel(&st->footprint, x, y)[0];
    const float omega = DRIFT_AAF_OMEGA_DIFFUSE;
    // eq. 4.4
    float beta = fmaxf(2.0f * z_min / omega, d / 0.15f);
    drift_image_pixel(&st->indirect_beta, x, y)[0] = beta * job->shrink;
    // eq. 4.6 with sqrt(A_p) = d.
    float a = 0.9f * omega * d / z_min + 0.3f;
    float b = 1.0f + 0.9f * z_max / z_min;
    st->want[i] = fmaxf(0.4f * a * a * omega * omega * b * b, 1e-3f);
}

static void adaptive_pixel(drift_hybrid *f, int32_t x, int32_t y, uint64_t *rays, void *user)
{
    const indirect_job *job = user;
    drift_aaf_state *st = f->aaf;
    size_t i = pixel_index(f, x, y);
    bool diffuse = has_diffuse(f, &f->gbuffer.surfaces[i]);
    uint32_t taken = job->uniform ? f->params.spp : job->sparse;
    uint32_t n = job->uniform ? taken : st->counts[i];
    if (diffuse && n > taken) {
        add_samples(f, job, x, y, taken, n, rays);
    }
    drift_image_pixel(&st->indirect_spp, x, y)[0] = diffuse ? (float)(n > taken ? n : taken) : 0.0f;
}

static void modulate_pixel(drift_hybrid *f, int32_t x, int32_t y, uint64_t *rays, void *user)
{
    (void)rays;
    (void)user;
    drift_aaf_state *st = f->aaf;
    const drift_surface *s = &f->gbuffer.surfaces[pixel_index(f, x, y)];
    drift_vec3 albedo = drift_vec3_splat(0.0f);
    if (has_diffuse(f, s)) {
        albedo = drift_bsdf_make(f->scene, s).diffuse;
    }
    drift_image_set3(&st->indirect_unfiltered, x, y,
                     drift_vec3_mul(albedo, drift_image_get3(&st->indirect_radiance, x, y)));
    drift_image_set3(&f->indirect, x, y,
                     drift_vec3_mul(albedo, drift_image_get3(&st->indirect_filtered, x, y)));
}

drift_result drift_hybrid_pass_aaf_indirect(drift_hybrid *f)
{
    size_t active = 0;
    drift_result r = drift_aaf_prepare(f, &active);
    if (r != DRIFT_OK) {
        return r;
    }
    drift_aaf_state *st = f->aaf;
    drift_hybrid_stats *stats = &f->stats;
    size_t pixels = (size_t)f->params.width * (size_t)f->params.height;
    indirect_job job = { .key = drift_hash_combine(f->params.seed, STREAM_AAF_INDIRECT),
                         .sparse = drift_aaf_sparse_count(f->params.spp),
                         .shrink = drift_aaf_beta_shrink(f->params.spp, DRIFT_AAF_INDIRECT_SHRINK_SPP,
                                                         DRIFT_AAF_INDIRECT_SHRINK_EXP),
                         .uniform = f->params.aaf_uniform,
                         .bounces = f->params.max_depth - 1 };
    double t = drift_time_now();
    if (job.bounces > 0) {
        stats->rays[DRIFT_PASS_AAF_SAMPLING] += drift_hybrid_for_each_pixel(f, sparse_pixel, &job);
        if (!job.uniform) {
            drift_aaf_allocate(st->want, pixels, active, job.sparse, f->params.spp,
                               f->params.aaf_max_spp, job.key, st->counts);
        }
        stats->rays[DRIFT_PASS_AAF_SAMPLING] += drift_hybrid_for_each_pixel(f, adaptive_pixel, &job);
    } else {
        for (int32_t y = 0; y < f->params.height; ++y) {
            for (int32_t x = 0; x < f->params.width; ++x) {
                drift_image_set3(&st->indirect_radiance, x, y, drift_vec3_splat(0.0f));
                drift_image_pixel(&st->indirect_beta, x, y)[0] = 0.0f;
                drift_image_pixel(&st->indirect_spp, x, y)[0] = 0.0f;
            }
        }
    }
    stats->ms[DRIFT_PASS_AAF_SAMPLING] += 1000.0 * (drift_time_now() - t);

    t = drift_time_now();
    if (f->params.aaf_unfiltered) {
        drift_hybrid_copy_rgb(&st->indirect_radiance, &st->indirect_filtered);
    } else {
        drift_aaf_filter_desc desc = { .beta = &st->indirect_beta,
                                       .footprint = &st->footprint,
                                       .gbuffer = &f->gbuffer,
                                       .max_radius = DRIFT_AAF_MAX_RADIUS };
        r = drift_aaf_filter_separable(f->ctx, &desc, &st->indirect_radiance, &st->scratch3,
                                       &st->indirect_filtered);
        if (r != DRIFT_OK) {
            return r;
        }
    }
    drift_hybrid_for_each_pixel(f, modulate_pixel, NULL);
    stats->ms[DRIFT_PASS_AAF_FILTER] += 1000.0 * (drift_time_now() - t);
    return DRIFT_OK;
}
