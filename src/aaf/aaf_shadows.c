// AAF soft shadows (--shadows aaf; Mehta, Wang, Ramamoorthi 2012; docs/aaf.md): per area
// light, three passes fill the shadow term S_l that multiplies the unshadowed light U_l
// (eq. 3.2; U_l is the closed form of shading.c):
//   1. sparse: a few shadow rays to points on the light; each occluded ray gives the ratio
//      s = d1/d2 - 1 (receiver-to-light over occluder-to-light distance), whose extremes s1
//      (from d2min) and s2 (from d2max) set the filter width beta (eq. 3.4) and the wanted
//      rate n(x) (eq. 3.5);
//   2. adaptive: the average --spp budget is spread in proportion to n(x), capped at
//      aaf_max_spp; pixels whose sparse rays met no occluder keep their sparse estimate;
//   3. the separable filter (aaf_filter.c), distances in the plane parallel to the light.
// The visibility estimate is light-weighted: sum V_i w_i / sum w_i with w_i the luminance of
// the sample's unshadowed contribution f L cos / pdf, so U_l S_l converges to the shadowed
// direct light the reference computes.
#include "aaf/aaf.h"

#include <math.h>

typedef struct shadow_job {
    uint32_t light;
    uint32_t key;    // sampler key of this light
    uint32_t sparse; // sparse samples a pixel
    float area;      // A_l
    float sigma;     // the light's Gaussian standard deviation
    float shrink;    // drift_aaf_beta_shrink(spp)
    bool uniform;    // plain sampling: every pixel takes spp
    bool random;     // independent random numbers, not Sobol points
} shadow_job;

static size_t pixel_index(const drift_frame_state *f, int32_t x, int32_t y)
{
    return (size_t)y * (size_t)f->params.width + (size_t)x;
}

// Area of the hybrid light (0 for delta lights): what eq. 3.5 calls A_l.
static float light_area(const drift_scene *scene, const drift_raster_light *light)
{
    float area = 0.0f;
    for (uint32_t i = 0; i < light->light_count; ++i) {
        const drift_light *l = &scene->lights[light->first_light + i];
        switch (l->type) {
        case DRIFT_LIGHT_QUAD:
            area += drift_vec3_length(drift_vec3_cross(l->edge_u, l->edge_v));
            break;
        case DRIFT_LIGHT_DISK:
        case DRIFT_LIGHT_SPHERE: // a sphere is seen as its disc
            area += DRIFT_PI * l->radius * l->radius;
            break;
        case DRIFT_LIGHT_TRIANGLE: {
            drift_vec3 a, b, c;
            drift_light_triangle_vertices(scene, l, &a, &b, &c);
            area += 0.5f *
                    drift_vec3_length(drift_vec3_cross(drift_vec3_sub(b, a), drift_vec3_sub(c, a)));
            break;
        }
        case DRIFT_LIGHT_POINT:
        case DRIFT_LIGHT_SPOT:
        case DRIFT_LIGHT_DIRECTIONAL:
        case DRIFT_LIGHT_COUNT:
            break;
        }
    }
    return area;
}

// Per-pixel running sums kept in state->aux: light-weighted visibility, total weight, the
// largest and smallest s = d1/d2 - 1 of the occluded rays (s1 and s2 of eq. 3.5), the
// samples traced and the next index of the pixel's sample sequence.
typedef struct shadow_sums {
    float visible, weight, s1, s2, taken, next;
} shadow_sums;

// Traces samples of the pixel toward the light until `target` have been traced, adding to
// *sums. Points the light sampler gives that cannot light the pixel (w = 0: the far side of
// a sphere light, behind the surface) are skipped, not counted: a sun sphere returns such
// points half the time, and a pixel whose few sparse points all fell there would look lit.
// At most 16 target + 16 points are drawn (a leaf seen from its unlit side may face only a
// sliver of the light; 4 target + 4 left the open plant scene 1.3% under its budget).
static void trace_samples(drift_frame_state *f, const shadow_job *job, const drift_surface *s,
                          const drift_bsdf *bsdf, drift_vec3 wo, uint32_t pixel, uint32_t target,
                          shadow_sums *sums, uint64_t *rays)
{
    const drift_raster_light *light = &f->lights[job->light];
    while (sums->taken < (float)target && sums->next < 16.0f * (float)target + 16.0f) {
        uint32_t k = (uint32_t)sums->next;
        sums->next += 1.0f;
        drift_aaf_sampler sampler = drift_aaf_sampler_make(job->key, pixel, k, job->random);
        float pick = drift_aaf_next1(&sampler);
        drift_vec2 u = drift_aaf_next2(&sampler);
        drift_light_sample ls = drift_raster_light_sample(f->scene, light, s->position, pick, u);
        if (!(ls.pdf > 0.0f)) {
            continue;
        }
        drift_vec3 fr = drift_bsdf_eval(bsdf, wo, ls.wi);
        float cos_i = fabsf(drift_vec3_dot(ls.wi, s->ns));
        float w = drift_luminance(drift_vec3_mul(fr, ls.radiance)) * cos_i / ls.pdf;
        if (!(w > 0.0f) || !isfinite(w)) {
            continue;
        }
        drift_ray ray = { .origin = drift_offset_origin(s->position, s->ng, ls.wi),
                          .dir = ls.wi,
                          .tmin = 0.0f,
                          .tmax = isfinite(ls.distance) ? ls.distance * (1.0f - 1e-4f) : INFINITY };
        drift_hit hit = { .mesh = DRIFT_INVALID_INDEX, .light = DRIFT_INVALID_INDEX };
        ++*rays;
        sums->taken += 1.0f;
        drift_accel_intersect(f->accel, &ray, &hit);
        float occluder;
        sums->weight += w;
        if (drift_raster_hard_shadow_visible(light, &hit, &occluder)) {
            sums->visible += w;
        } else if (isfinite(ls.distance) && ls.distance > occluder) {
            // d1 / d2 - 1 with d1 the light's distance and d2 = d1 - t the occluder's.
            float ratio = occluder / fmaxf(ls.distance - occluder, 1e-6f * ls.distance);
            sums->s1 = fmaxf(sums->s1, ratio);
            sums->s2 = fminf(sums->s2, ratio);
        }
    }
}

static float sums_visibility(const shadow_sums *sums)
{
    // No weight: the light does not reach this side, U_l is 0 and S_l does not matter.
    return sums->weight > 0.0f ? sums->visible / sums->weight : 1.0f;
}

static void sparse_pixel(drift_frame_state *f, int32_t x, int32_t y, uint64_t *rays, void *user)
{
    const shadow_job *job = user;
    drift_aaf_state *st = drift_aaf_of(f);
    size_t i = pixel_index(f, x, y);
    shadow_sums *sums = (shadow_sums *)&st->aux[DRIFT_AAF_AUX * i];
    *sums = (shadow_sums){ 0.0f, 0.0f, 0.0f, INFINITY, 0.0f, 0.0f };
    const drift_surface *s = &f->gbuffer.surfaces[i];
    if (s->material == DRIFT_INVALID_INDEX) {
        return;
    }
    drift_bsdf bsdf = drift_bsdf_make(f->scene, s);
    drift_vec3 wo = drift_pass_wo(f, x, y);
    uint32_t n = job->uniform ? f->params.spp : job->sparse;
    trace_samples(f, job, s, &bsdf, wo, (uint32_t)i, n, sums, rays);
}

// What the sparse rays of a pixel and its neighbours say about its shadow.
typedef enum pixel_shadow {
    SHADOW_FLAT,     // lit or hidden: keeps its sparse estimate, exactly 1 or 0
    SHADOW_PENUMBRA, // some rays met an occluder, some the light: filtered, n(x) samples
    SHADOW_UNSURE,   // no ray disagreed, but too few rays to call it flat
} pixel_shadow;

// s1 and s2 of the pixel, from its neighbours (same surface) within DRIFT_AAF_DILATE pixels,
// its own left out: the means of theirs that met an occluder, or, when none did, the pixel's
// own. Taken from its own sparse rays, beta and n(x) were functions of the samples they
// filter and add to (a pixel whose few rays met a near occluder got more samples and a narrow
// filter): adaptive sampling conditioned on a pixel's own first samples is biased, and on the
// Cornell box at 4 spp that bias was most of AAF's error (docs/aaf.md). Flat when the pixel
// is in full light or full shadow: no ray of the pixel or of those neighbours met an
// occluder, or none reached the light (an umbra, as flat as full light); unsure when those
// rays agree but are fewer than DRIFT_AAF_FLAT_EVIDENCE (a pixel with few neighbours on its
// surface, at 2 sparse rays, is "flat" on a coin toss: on the Breakfast Room at 4 spp such
// pixels, kept at 0 or 1, held a third of AAF's squared error and 4% of plain MC's).
static pixel_shadow occluder_ratios(const drift_frame_state *f, int32_t x, int32_t y, float *s1,
                                    float *s2)
{
    const drift_aaf_state *st = drift_aaf_of(f);
    const shadow_sums *own = (const shadow_sums *)&st->aux[DRIFT_AAF_AUX * pixel_index(f, x, y)];
    bool lit = own->visible > 0.0f, occluded = isfinite(own->s2);
    double sum1 = 0.0, sum2 = 0.0;
    int count = 0;
    float rays = own->taken;
    const drift_gbuffer *g = &f->gbuffer;
    float depth = drift_image_pixel(&g->depth, x, y)[0];
    drift_vec3 normal = drift_image_get3(&g->normal, x, y);
    for (int32_t ny = y - DRIFT_AAF_DILATE; ny <= y + DRIFT_AAF_DILATE; ++ny) {
        for (int32_t nx = x - DRIFT_AAF_DILATE; nx <= x + DRIFT_AAF_DILATE; ++nx) {
            if (nx < 0 || ny < 0 || nx >= f->params.width || ny >= f->params.height ||
                (nx == x && ny == y) || drift_image_pixel(&g->material_id, nx, ny)[0] < 0.0f) {
                continue;
            }
            const shadow_sums *n =
                (const shadow_sums *)&st->aux[DRIFT_AAF_AUX * pixel_index(f, nx, ny)];
            if (fabsf(drift_image_pixel(&g->depth, nx, ny)[0] - depth) >
                    DRIFT_AAF_DEPTH_TOLERANCE * depth ||
                drift_vec3_dot(drift_image_get3(&g->normal, nx, ny), normal) <
                    DRIFT_AAF_NORMAL_COS) {
                continue;
            }
            lit = lit || n->visible > 0.0f;
            rays += n->taken;
            if (isfinite(n->s2)) {
                sum1 += (double)n->s1;
                sum2 += (double)n->s2;
                ++count;
            }
        }
    }
    *s1 = count > 0 ? (float)(sum1 / count) : own->s1;
    *s2 = count > 0 ? (float)(sum2 / count) : own->s2;
    if ((occluded || count > 0) && lit) {
        return SHADOW_PENUMBRA;
    }
    return rays >= DRIFT_AAF_FLAT_EVIDENCE ? SHADOW_FLAT : SHADOW_UNSURE;
}

// beta (eq. 3.4) and the wanted rate n(x) (eq. 3.5) from the sparse pass.
static void rates_pixel(drift_frame_state *f, int32_t x, int32_t y, uint64_t *rays, void *user)
{
    (void)rays;
    const shadow_job *job = user;
    drift_aaf_state *st = drift_aaf_of(f);
    size_t i = pixel_index(f, x, y);
    float s1, s2;
    drift_image_pixel(&st->lights[job->light].beta, x, y)[0] = 0.0f;
    // Outside the budget (want < 0): no surface, or one the light cannot reach.
    st->want[i] = -1.0f;
    if (f->gbuffer.surfaces[i].material == DRIFT_INVALID_INDEX ||
        !(((const shadow_sums *)&st->aux[DRIFT_AAF_AUX * i])->taken > 0.0f)) {
        return;
    }
    st->want[i] = 0.0f; // flat: the sparse samples, and a share of what the budget leaves
    pixel_shadow shadow = occluder_ratios(f, x, y, &s1, &s2);
    if (shadow == SHADOW_UNSURE) {
        // No occluder to size a filter by (beta stays 0), but its few rays may be wrong: the
        // least rate that makes it adaptive, so it takes the adaptive floor (at least --spp).
        st->want[i] = 1e-3f;
        return;
    }
    if (shadow == SHADOW_FLAT) {
        return;
    }
    s2 = fmaxf(s2, 1e-4f);
    float d = drift_image_pixel(&st->footprint, x, y)[0];
    // eq. 3.4, with the pixel term as a width d / (1 + s2) (docs/aaf.md: the thesis prints
    // its reciprocal, the frequency bound).
    float beta = (1.0f / 3.0f) * fmaxf(job->sigma * s2, d / (1.0f + s2));
    drift_image_pixel(&st->lights[job->light].beta, x, y)[0] = beta * job->shrink;
    // eq. 3.5 with A_p = d^2.
    float a = 1.0f + s1 / s2;
    float b = 2.0f / s2 * d / sqrtf(job->area) + 1.0f / (1.0f + s2);
    float want = 4.0f * a * a * b * b;
    st->want[i] = isfinite(want) ? fmaxf(want, 1e-3f) : 1e30f;
}

static void adaptive_pixel(drift_frame_state *f, int32_t x, int32_t y, uint64_t *rays, void *user)
{
    const shadow_job *job = user;
    drift_aaf_state *st = drift_aaf_of(f);
    drift_aaf_light *al = &st->lights[job->light];
    size_t i = pixel_index(f, x, y);
    shadow_sums *sums = (shadow_sums *)&st->aux[DRIFT_AAF_AUX * i];
    const drift_surface *s = &f->gbuffer.surfaces[i];
    bool surface = s->material != DRIFT_INVALID_INDEX;
    // A pixel none of whose sparse points could light it (the light behind its surface) has
    // nothing to add.
    if (surface && !job->uniform && sums->taken > 0.0f && st->counts[i] > (uint32_t)sums->taken) {
        drift_bsdf bsdf = drift_bsdf_make(f->scene, s);
        trace_samples(f, job, s, &bsdf, drift_pass_wo(f, x, y), (uint32_t)i, st->counts[i], sums,
                      rays);
    }
    drift_image_pixel(&al->spp, x, y)[0] = surface ? sums->taken : 0.0f;
    drift_image_pixel(&al->unfiltered, x, y)[0] = surface ? sums_visibility(sums) : 0.0f;
}

// Delta lights have no penumbra: their term is the hard shadow toward the light.
static void hard_pixel(drift_frame_state *f, int32_t x, int32_t y, uint64_t *rays, void *user)
{
    const shadow_job *job = user;
    drift_aaf_light *al = &drift_aaf_of(f)->lights[job->light];
    const drift_surface *s = &f->gbuffer.surfaces[pixel_index(f, x, y)];
    float v = 0.0f;
    if (s->material != DRIFT_INVALID_INDEX) {
        float occluder, distance;
        ++*rays;
        v = drift_raster_hard_shadow(f->accel, &f->lights[job->light], s, &occluder, &distance)
                ? 1.0f
                : 0.0f;
    }
    drift_image_pixel(&al->beta, x, y)[0] = 0.0f;
    drift_image_pixel(&al->spp, x, y)[0] = s->material != DRIFT_INVALID_INDEX ? 1.0f : 0.0f;
    drift_image_pixel(&al->unfiltered, x, y)[0] = v;
}

static void footprint_pixel(drift_frame_state *f, int32_t x, int32_t y, uint64_t *rays, void *user)
{
    (void)rays;
    (void)user;
    float z = drift_image_pixel(&f->gbuffer.depth, x, y)[0];
    drift_image_pixel(&drift_aaf_of(f)->footprint, x, y)[0] =
        drift_aaf_pixel_footprint(&f->camera, f->params.height, z);
}

drift_result drift_aaf_prepare(drift_frame_state *f, size_t *out_active)
{
    drift_result r = drift_aaf_state_ensure(f);
    if (r != DRIFT_OK) {
        return r;
    }
    drift_pass_for_each_pixel(f, footprint_pixel, NULL);
    if (out_active) {
        size_t active = 0, pixels = (size_t)f->params.width * (size_t)f->params.height;
        for (size_t i = 0; i < pixels; ++i) {
            active += f->gbuffer.surfaces[i].material != DRIFT_INVALID_INDEX;
        }
        *out_active = active;
    }
    return DRIFT_OK;
}

uint32_t drift_aaf_shadow_sparse_count(uint32_t spp)
{
    if (spp >= 2 * DRIFT_AAF_SPARSE_MIN) {
        return drift_aaf_sparse_count(spp);
    }
    // Below 8 spp the sparse pass takes half the budget (at least 2 rays), so that an
    // adaptive pass remains: at k0 = N = 4 there was none and AAF gained 1.6-3.1x, not 4x.
    uint32_t k = spp / 2 < 2 ? 2 : spp / 2;
    return k < spp ? k : spp;
}

// The light's shadow term from its unfiltered visibility: AAF's filter, or (--aaf-denoise)
// the denoiser instead of it or before it. Delta lights' hard shadows are kept as they are.
static drift_result filter_light(drift_frame_state *f, uint32_t l, bool area)
{
    drift_aaf_state *st = drift_aaf_of(f);
    drift_aaf_light *al = &st->lights[l];
    drift_image *shadow = &f->light_buffers[l].shadow;
    drift_aaf_denoise mode = area ? f->params.aaf.denoise : DRIFT_AAF_DENOISE_OFF;
    bool aaf_filter = area && !f->params.aaf.unfiltered && mode != DRIFT_AAF_DENOISE_ON;
    const drift_image *in = &al->unfiltered;
    drift_image denoised = { 0 };
    drift_result r = DRIFT_OK;
    if (mode != DRIFT_AAF_DENOISE_OFF) {
        // The variance in scratch1, which the filter reuses once the denoiser is done.
        for (int32_t y = 0; y < shadow->height; ++y) {
            for (int32_t x = 0; x < shadow->width; ++x) {
                drift_image_pixel(&st->scratch1, x, y)[0] = drift_aaf_visibility_variance(
                    drift_image_pixel(in, x, y)[0], drift_image_pixel(&al->spp, x, y)[0],
                    f->params.aaf.random);
            }
        }
        r = drift_image_create(f->ctx, shadow->width, shadow->height, 1, &denoised);
        if (r == DRIFT_OK) {
            r = drift_aaf_denoise_estimate(f, in, &st->scratch1, &denoised);
        }
        in = &denoised;
    }
    if (r == DRIFT_OK && !aaf_filter) {
        for (int32_t y = 0; y < shadow->height; ++y) {
            for (int32_t x = 0; x < shadow->width; ++x) {
                drift_image_pixel(shadow, x, y)[0] = drift_image_pixel(in, x, y)[0];
            }
        }
    } else if (r == DRIFT_OK) {
        drift_aaf_filter_desc desc = { .beta = &al->beta,
                                       .footprint = &st->footprint,
                                       .gbuffer = &f->gbuffer,
                                       // World distance, not the paper's plane parallel to
                                       // the light: that plane folds a wall's height away
                                       // (docs/aaf.md, departures).
                                       .has_axis = false,
                                       .axis = f->lights[l].direction,
                                       .max_radius = DRIFT_AAF_MAX_RADIUS,
                                       .workspace = st->filter_workspace };
        r = drift_aaf_filter_separable(f->ctx, &desc, in, &st->scratch1, shadow);
    }
    drift_image_destroy(f->ctx, &denoised);
    return r;
}

drift_result drift_aaf_pass_shadows(drift_frame_state *f, const drift_pass_args *args)
{
    (void)args;
    drift_result r = drift_aaf_prepare(f, NULL);
    if (r != DRIFT_OK) {
        return r;
    }
    drift_aaf_state *st = drift_aaf_of(f);
    drift_hybrid_stats *stats = &f->stats;
    size_t pixels = (size_t)f->params.width * (size_t)f->params.height;
    for (uint32_t l = 0; l < f->light_count; ++l) {
        const drift_raster_light *light = &f->lights[l];
        shadow_job job = { .light = l,
                           .key = drift_hash_combine(f->params.seed, DRIFT_STREAM_AAF_SHADOWS + l),
                           .sparse = drift_aaf_shadow_sparse_count(f->params.spp),
                           .area = light_area(f->scene, light),
                           .shrink =
                               drift_aaf_beta_shrink(f->params.spp, DRIFT_AAF_SHADOW_SHRINK_SPP,
                                                     DRIFT_AAF_SHADOW_SHRINK_EXP),
                           .uniform = f->params.aaf.uniform,
                           .random = f->params.aaf.random };
        job.sigma = DRIFT_AAF_LIGHT_SIGMA * sqrtf(job.area);
        double t = drift_time_now();
        bool area = job.area > 0.0f && light->type != DRIFT_LIGHT_DIRECTIONAL;
        if (!area) {
            stats->rays[DRIFT_PASS_AAF_SAMPLING] += drift_pass_for_each_pixel(f, hard_pixel, &job);
        } else {
            stats->rays[DRIFT_PASS_AAF_SAMPLING] +=
                drift_pass_for_each_pixel(f, sparse_pixel, &job);
            drift_pass_for_each_pixel(f, rates_pixel, &job);
            if (!job.uniform) {
                // The average is over the pixels the light can reach (a sparse point with a
                // contribution): counting those facing away as well spent 3.7-4% under the
                // budget on the open plant scene (issue 17).
                size_t lit = 0;
                for (size_t i = 0; i < pixels; ++i) {
                    lit += st->want[i] >= 0.0f;
                }
                drift_aaf_allocate(st->want, pixels, lit, job.sparse, f->params.spp,
                                   f->params.aaf.max_spp, job.key, st->counts);
            }
            stats->rays[DRIFT_PASS_AAF_SAMPLING] +=
                drift_pass_for_each_pixel(f, adaptive_pixel, &job);
        }
        stats->ms[DRIFT_PASS_AAF_SAMPLING] += 1000.0 * (drift_time_now() - t);

        t = drift_time_now();
        r = filter_light(f, l, area);
        if (r != DRIFT_OK) {
            return r;
        }
        stats->ms[DRIFT_PASS_AAF_FILTER] += 1000.0 * (drift_time_now() - t);
    }
    return DRIFT_OK;
}
