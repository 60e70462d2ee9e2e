// Reference path tracer: unidirectional, next-event estimation, MIS with the power heuristic.
#include "drift/pt.h"

#include <math.h>
#include <string.h>

#define TILE_SIZE DRIFT_PT_TILE_SIZE
// Channels accumulated per pixel: beauty RGB, albedo RGB, normal XYZ, depth, then the
// denoiser's inputs: the sum of the squared beauty luminance (the running second moment), and
// albedo RGB, normal XYZ and depth at the first non-delta vertex (drift/pt.h), the direct
// part RGB and the squared luminances of the direct part and of the rest.
#define SUM_CHANNELS 23

// Per-thread counters, padded to a cache line so threads do not share one.
typedef struct thread_stats {
    uint64_t camera_rays, shadow_rays, bounce_rays, nan_samples;
    uint8_t padding[64 - 4 * sizeof(uint64_t)];
} thread_stats;

struct drift_pt {
    drift_context *ctx;
    const drift_scene *scene;
    const drift_accel *accel;
    drift_pt_params params;
    drift_camera_frame camera; // params.camera or the scene's, pinhole when asked, per image
    double *sums;              // SUM_CHANNELS a pixel
    uint32_t *counts;          // samples a pixel
    thread_stats *thread_stats;
    int thread_count;
    drift_image resolved[DRIFT_PT_AOV_COUNT];
    double render_seconds;
};

typedef struct path_result {
    drift_vec3 radiance;
    drift_vec3 albedo;
    drift_vec3 normal;
    float depth;
    // At the first vertex whose BSDF is not a delta (mirror, glass): the feature the denoiser
    // is guided by; the albedo is times the delta bounces' throughput up to there.
    drift_vec3 feature_albedo;
    drift_vec3 feature_normal;
    float feature_depth; // length of the path up to that vertex (0 = it escaped first)
    drift_vec3 direct;   // the radiance's direct part (DRIFT_PT_AOV_DIRECT)
} path_result;

drift_pt_params drift_pt_params_resolve(const drift_pt_params *params, const drift_scene *scene)
{
    drift_pt_params p = params ? *params : (drift_pt_params){ 0 };
    if (p.width == 0) {
        p.width = scene ? scene->camera.width : 512;
    }
    if (p.height == 0) {
        p.height = scene ? scene->camera.height : 512;
    }
    if (p.max_depth == 0) {
        p.max_depth = 8;
    }
    if (p.rr_depth == 0) {
        p.rr_depth = 3;
    }
    if (p.components == 0) {
        p.components = DRIFT_PT_COMPONENT_ALL;
    }
    return p;
}

drift_result drift_pt_create(drift_context *ctx, const drift_scene *scene, const drift_accel *accel,
                             const drift_pt_params *params, drift_pt **out_pt)
{
    if (!out_pt) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    *out_pt = NULL;
    if (!scene || !accel || !scene->committed) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    drift_pt_params p = drift_pt_params_resolve(params, scene);
    if (p.width <= 0 || p.height <= 0 || p.width > DRIFT_IMAGE_MAX_DIMENSION ||
        p.height > DRIFT_IMAGE_MAX_DIMENSION || p.max_depth < 0 || p.rr_depth < 0) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, NULL, 0,
                  "path tracer: image %dx%d or depth %d out of range", p.width, p.height,
                  p.max_depth);
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    if (p.components & ~(uint32_t)DRIFT_PT_COMPONENT_ALL) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, NULL, 0,
                  "path tracer: components 0x%x outside DRIFT_PT_COMPONENT_ALL", p.components);
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    drift_pt *pt = drift_alloc(ctx, sizeof(drift_pt));
    if (!pt) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    pt->ctx = ctx;
    pt->scene = scene;
    pt->accel = accel;
    pt->params = p;
    drift_camera camera = p.camera ? *p.camera : scene->camera;
    if (p.pinhole) {
        camera.aperture_radius = 0.0f;
    }
    pt->camera = drift_camera_frame_make(&camera, p.width, p.height);
    pt->thread_count = drift_context_thread_count(ctx);
    size_t pixels = (size_t)p.width * (size_t)p.height;
    pt->sums = drift_alloc(ctx, pixels * SUM_CHANNELS * sizeof(double));
    pt->counts = drift_alloc(ctx, pixels * sizeof(uint32_t));
    pt->thread_stats = drift_alloc(ctx, (size_t)pt->thread_count * sizeof(thread_stats));
    if (!pt->sums || !pt->counts || !pt->thread_stats) {
        drift_pt_destroy(pt);
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    *out_pt = pt;
    return DRIFT_OK;
}

void drift_pt_destroy(drift_pt *pt)
{
    if (!pt) {
        return;
    }
    drift_context *ctx = pt->ctx;
    for (int i = 0; i < DRIFT_PT_AOV_COUNT; ++i) {
        drift_image_destroy(ctx, &pt->resolved[i]);
    }
    drift_free(ctx, pt->sums);
    drift_free(ctx, pt->counts);
    drift_free(ctx, pt->thread_stats);
    drift_free(ctx, pt);
}

// --- COMPONENTS ---

// Where a path's contributions go when the image is split into components (pt.h): every
// contribution is added to the path's radiance as usual and, when splitting, also to one of
// these by the vertex it comes from. The first scattering event decides.
typedef struct path_split {
    bool active;                    // components select a strict subset: split
    drift_vec3 emission;            // emitted at the first hit (the environment on a miss)
    drift_vec3 direct;              // NEE at the first vertex + the first bounce's emitter hit
    drift_vec3 rest;                // everything after the first bounce
    bool first_delta;               // the first bounce was a mirror sample: rest is specular
    drift_vec3 f_diffuse, f_glossy; // the first vertex's lobes for the first bounce (wo, wi)
} path_split;

// A contribution found at vertex `depth` (0 = the camera ray's hit), either emission seen
// there (or the environment where the ray from vertex depth - 1 escaped) or NEE from it.
static void split_add(path_split *s, int32_t depth, bool is_emission, drift_vec3 c)
{
    if (!s->active) {
        return;
    }
    drift_vec3 *part = &s->rest;
    if (depth == 0) {
        part = is_emission ? &s->emission : &s->direct;
    } else if (depth == 1 && is_emission && !s->first_delta) {
        part = &s->direct;
    }
    *part = drift_vec3_add(*part, c);
}

// Share of a continuing path's light that goes with one lobe: f_lobe / (f_diffuse + f_glossy).
static float lobe_share(float f_lobe, float f_sum, float if_none)
{
    return f_sum > 0.0f ? f_lobe / f_sum : if_none;
}

static drift_vec3 split_select(const path_split *s, uint32_t components)
{
    drift_vec3 out = drift_vec3_splat(0.0f);
    if (components & DRIFT_PT_COMPONENT_EMISSION) {
        out = drift_vec3_add(out, s->emission);
    }
    if (components & DRIFT_PT_COMPONENT_DIRECT) {
        out = drift_vec3_add(out, s->direct);
    }
    if (s->first_delta) {
        if (components & DRIFT_PT_COMPONENT_SPECULAR) {
            out = drift_vec3_add(out, s->rest);
        }
        return out;
    }
    // The diffuse and glossy lobes sampled the same direction: share per channel by their
    // values there (a channel where both are zero carries no light; it goes to diffuse).
    drift_vec3 sum = drift_vec3_add(s->f_diffuse, s->f_glossy);
    if (components & DRIFT_PT_COMPONENT_SPECULAR) {
        drift_vec3 share = { lobe_share(s->f_glossy.x, sum.x, 0.0f),
                             lobe_share(s->f_glossy.y, sum.y, 0.0f),
                             lobe_share(s->f_glossy.z, sum.z, 0.0f) };
        out = drift_vec3_add(out, drift_vec3_mul(s->rest, share));
    }
    if (components & DRIFT_PT_COMPONENT_DIFFUSE) {
        drift_vec3 share = { lobe_share(s->f_diffuse.x, sum.x, 1.0f),
                             lobe_share(s->f_diffuse.y, sum.y, 1.0f),
                             lobe_share(s->f_diffuse.z, sum.z, 1.0f) };
        out = drift_vec3_add(out, drift_vec3_mul(s->rest, share));
    }
    return out;
}

// --- PATH ---

// Light arriving by next-event estimation at a surface point, MIS-weighted against BSDF
// sampling (Veach 1997, §9.2), with visibility.
static drift_vec3 sample_direct(const drift_pt *pt, const drift_surface *surf,
                                const drift_bsdf *bsdf, drift_vec3 wo, drift_sampler *sampler,
                                thread_stats *stats)
{
    const drift_scene *scene = pt->scene;
    drift_vec2 u_light = drift_sampler_next2(sampler);
    float pmf;
    // The pick reuses u_light.x, rescaled (drift_scene_pick_light_reuse): the light's point
    // keeps its stratification.
    uint32_t light = drift_scene_pick_light_reuse(scene, &u_light.x, &pmf);
    if (light == DRIFT_INVALID_INDEX || !(pmf > 0.0f)) {
        return drift_vec3_splat(0.0f);
    }
    drift_light_sample ls = drift_light_sample_li(scene, light, surf->position, u_light);
    if (!(ls.pdf > 0.0f) || drift_vec3_is_zero(ls.radiance)) {
        return drift_vec3_splat(0.0f);
    }
    drift_vec3 f = drift_bsdf_eval(bsdf, wo, ls.wi);
    // The cosine about the BSDF's own normal (a normal map's, where there is one), as BSDF
    // sampling's weight has it: the two strategies then estimate the same integral.
    float cos_i = fabsf(drift_vec3_dot(ls.wi, bsdf->frame.z));
    if (drift_vec3_is_zero(f) || cos_i <= 0.0f) {
        return drift_vec3_splat(0.0f);
    }
    // Shadow ray: stop just short of the light so its own surface does not block it.
    drift_ray shadow = { .origin = drift_offset_origin(surf->position, surf->ng, ls.wi),
                         .dir = ls.wi,
                         .tmin = 0.0f,
                         .tmax = isfinite(ls.distance) ? ls.distance * (1.0f - 1e-4f) : INFINITY };
    stats->shadow_rays++;
    if (drift_accel_occluded(pt->accel, &shadow)) {
        return drift_vec3_splat(0.0f);
    }
    float light_pdf = pmf * ls.pdf;
    float weight = 1.0f;
    if (!ls.is_delta && !pt->params.disable_mis) {
        weight = drift_power_heuristic(light_pdf, drift_bsdf_pdf(bsdf, wo, ls.wi));
    }
    return drift_vec3_scale(drift_vec3_mul(f, ls.radiance), cos_i * weight / light_pdf);
}

// MIS weight for emission found by BSDF sampling from `prev` with solid-angle pdf bsdf_pdf.
static float emission_weight(const drift_pt *pt, bool prev_specular, float bsdf_pdf,
                             float light_pdf)
{
    if (pt->params.disable_nee || prev_specular) {
        return 1.0f;
    }
    if (pt->params.disable_mis) {
        return 0.0f; // NEE already counted this light
    }
    return drift_power_heuristic(bsdf_pdf, light_pdf);
}

// cache: the pixel's sampler seeds (drift_sampler_cache), or NULL.
static void trace_path(const drift_pt *pt, int32_t x, int32_t y, uint32_t sample,
                       drift_sampler_cache *cache, path_result *out, thread_stats *stats)
{
    const drift_scene *scene = pt->scene;
    const drift_pt_params *p = &pt->params;
    uint32_t pixel = (uint32_t)y * (uint32_t)p->width + (uint32_t)x;
    drift_sampler sampler = cache ? drift_sampler_make_cached(p->seed, pixel, sample, cache)
                                  : drift_sampler_make(p->seed, pixel, sample);
    drift_vec2 film = drift_sampler_next2(&sampler);
    drift_vec2 lens = drift_sampler_next2(&sampler);
    if (p->pixel_centre) {
        film = drift_vec2_make(0.5f, 0.5f); // the dimensions are still drawn: same layout
    }
    drift_ray ray = drift_camera_frame_ray(&pt->camera, (float)x + film.x, (float)y + film.y, lens);
    // A pixel centre's camera ray is the same sample after sample: its seed is not, so the
    // veils it meets are met with their opacity's probability over the samples.
    ray.seed = drift_hash_combine(drift_hash_u32(pixel ^ p->seed), sample);
    *out = (path_result){ 0 };
    drift_vec3 radiance = drift_vec3_splat(0.0f);
    drift_vec3 beta = drift_vec3_splat(1.0f);
    bool prev_specular = true; // the camera ray counts as specular: see emitters directly
    float prev_bsdf_pdf = 0.0f;
    drift_vec3 prev_position = ray.origin;
    path_split split = { .active = p->components != DRIFT_PT_COMPONENT_ALL };
    bool feature_open = true; // no non-delta vertex yet: the next one gives the features
    float path_length = 0.0f;
    // The ray cone (Akenine-Moller et al. 2021): its width at the ray's origin and its spread
    // angle, a pixel's at the camera. Textures read the mip level of its footprint.
    float cone_width = 0.0f;
    uint32_t planned = p->texture_filter_spp > 1 ? p->texture_filter_spp : 1;
    float spp_scale = drift_maxf(0.125f, 1.0f / sqrtf((float)planned));
    float cone_spread = p->texture_point_sampling
                            ? 0.0f
                            : spp_scale * 2.0f * pt->camera.tan_half / (float)pt->camera.height;
    int bounces = 0; // non-delta bounces so far: light found after at most one is direct
    stats->camera_rays++;

    for (int32_t depth = 0;; ++depth) {
        drift_hit hit;
        if (!drift_accel_intersect(pt->accel, &ray, &hit)) {
            if (drift_scene_has_environment(scene)) {
                drift_vec3 le = drift_environment_eval(scene, ray.dir);
                float light_pdf =
                    drift_scene_environment_pmf(scene) * drift_environment_pdf(scene, ray.dir);
                float w = emission_weight(pt, prev_specular, prev_bsdf_pdf, light_pdf);
                drift_vec3 c = drift_vec3_scale(drift_vec3_mul(beta, le), w);
                radiance = drift_vec3_add(radiance, c);
                split_add(&split, depth, true, c);
                if (bounces <= 1) {
                    out->direct = drift_vec3_add(out->direct, c);
                }
                if (depth == 0) {
                    out->albedo = le;
                }
                if (feature_open) {
                    out->feature_albedo = drift_vec3_mul(beta, le);
                }
            }
            break;
        }
        drift_surface surf = drift_scene_surface(scene, &ray, &hit);
        cone_width += cone_spread * hit.t;
        if (cone_spread > 0.0f && scene->texture_count > 0) { // only textures read it
            drift_surface_set_footprint(scene, &surf, cone_width, ray.dir);
        }
        drift_vec3 wo = drift_vec3_neg(ray.dir);
        if (depth == 0) {
            out->depth = hit.t;
            out->normal = surf.ns;
            if (surf.material != DRIFT_INVALID_INDEX) {
                const drift_material *m = &scene->materials[surf.material];
                out->albedo = drift_vec3_add(m->diffuse, m->specular);
            } else {
                out->albedo = surf.emission;
            }
        }
        if (!drift_vec3_is_zero(surf.emission)) {
            float w = 1.0f;
            if (!prev_specular && surf.light != DRIFT_INVALID_INDEX) {
                float light_pdf =
                    drift_scene_light_pmf(scene, surf.light) *
                    drift_light_pdf_li(scene, surf.light, prev_position, ray.dir, hit.t, surf.ng);
                w = emission_weight(pt, prev_specular, prev_bsdf_pdf, light_pdf);
            }
            drift_vec3 c = drift_vec3_scale(drift_vec3_mul(beta, surf.emission), w);
            radiance = drift_vec3_add(radiance, c);
            split_add(&split, depth, true, c);
            if (bounces <= 1) {
                out->direct = drift_vec3_add(out->direct, c);
            }
        }
        if (feature_open && (surf.material == DRIFT_INVALID_INDEX || depth >= p->max_depth)) {
            out->feature_albedo =
                drift_vec3_mul(beta, surf.material == DRIFT_INVALID_INDEX ? surf.emission
                                                                          : drift_vec3_splat(1.0f));
            out->feature_normal = surf.ns;
            out->feature_depth = path_length + hit.t;
            feature_open = false;
        }
        if (surf.material == DRIFT_INVALID_INDEX || depth >= p->max_depth) {
            break;
        }
        drift_bsdf bsdf = drift_bsdf_make(scene, &surf);
        if (depth == 0) {
            // The first specular bounce follows the edit: its lobes centre on e(q).
            drift_reflection_edits_aim_bsdf(p->reflection_edits, &surf, wo, &bsdf);
        }
        if (feature_open && !drift_bsdf_is_delta(&bsdf)) {
            // An emitter's own light counts as albedo (the denoiser's irradiance there is ~1,
            // so that a small light is no outlier to its neighbours).
            // The BSDF's reflectances: the diffuse texture's texel, not the material's factor,
            // so that demodulation keeps texture detail.
            drift_vec3 a =
                drift_vec3_add(drift_vec3_add(bsdf.diffuse, bsdf.specular), surf.emission);
            out->feature_albedo = drift_vec3_mul(beta, a);
            out->feature_normal = surf.ns;
            out->feature_depth = path_length + hit.t;
            feature_open = false;
        }
        path_length += hit.t;
        // y: the lobe pick. x is unused since the light pick reuses the light sample's number;
        // the pair is still drawn so that every later dimension, and every image, stays as it was.
        drift_vec2 u_choice = drift_sampler_next2(&sampler);
        if (!p->disable_nee && !drift_bsdf_is_delta(&bsdf)) {
            drift_vec3 ld = sample_direct(pt, &surf, &bsdf, wo, &sampler, stats);
            drift_vec3 c = drift_vec3_mul(beta, ld);
            radiance = drift_vec3_add(radiance, c);
            split_add(&split, depth, false, c);
            if (bounces == 0) {
                out->direct = drift_vec3_add(out->direct, c);
            }
        } else {
            (void)drift_sampler_next2(&sampler); // keep the dimension layout fixed
        }
        drift_bsdf_sample bs =
            drift_bsdf_sample_wi(&bsdf, wo, u_choice.y, drift_sampler_next2(&sampler));
        float u_rr = drift_sampler_next1(&sampler);
        if (!(bs.pdf > 0.0f) || drift_vec3_is_zero(bs.weight)) {
            break;
        }
        if (depth == 0 && split.active) {
            split.first_delta = bs.is_delta;
            if (!bs.is_delta) {
                drift_bsdf_eval_lobes(&bsdf, wo, bs.wi, &split.f_diffuse, &split.f_glossy);
            }
        }
        beta = drift_vec3_mul(beta, bs.weight);
        // The cone keeps the camera's spread through every bounce (pbrt-v4's footprint at
        // secondary hits is the camera's too): a glossy or diffuse sample is one of many that
        // the estimator averages over the lobe, so filtering its texture by the lobe's width
        // (the solid angle 1 / pdf it stands for) filtered twice and blurred what a rough
        // surface reflects (issue 41: Blender's textured scene 0.121 from Cycles with that
        // widening, 0.065 without, as with no mip-maps at all).
        bounces += bs.is_delta ? 0 : 1;
        prev_specular = bs.is_delta;
        prev_bsdf_pdf = bs.pdf;
        prev_position = surf.position;
        // Russian roulette (pbrt-v4 §14.1.4) with Cycles' survival probability sqrt(max(beta)),
        // at most 1: paths of dim throughput live longer than pbrt's max(beta) lets them, which
        // measured 1.08-1.14x less relMSE x time (docs/lab/2026-12-07-issue-46-s4.md).
        float max_beta = drift_vec3_max_component(beta);
        if (!p->disable_rr && depth + 1 >= p->rr_depth && max_beta < 1.0f) {
            float q = drift_maxf(0.0f, 1.0f - sqrtf(max_beta));
            if (u_rr < q) {
                break;
            }
            beta = drift_vec3_scale(beta, 1.0f / (1.0f - q));
        }
        ray = (drift_ray){ .origin = drift_offset_origin(surf.position, surf.ng, bs.wi),
                           .dir = bs.wi,
                           .tmin = 0.0f,
                           .tmax = INFINITY };
        stats->bounce_rays++;
    }
    out->radiance = split.active ? split_select(&split, p->components) : radiance;
    if (split.active) {
        out->direct = drift_vec3_splat(0.0f); // a component render: all of it is "the rest"
    }
}

drift_vec3 drift_pt_trace_sample(const drift_pt *pt, int32_t x, int32_t y, uint32_t sample)
{
    thread_stats scratch = { 0 };
    path_result r;
    trace_path(pt, x, y, sample, NULL, &r, &scratch);
    return r.radiance;
}

// --- RENDER LOOP ---

// Each listed pixel continues from its own sample count: sample indices [first, end) with
// end = min(first + add, until). Samples are summed one by one in index order, so a pixel's
// sums do not depend on how its samples were split into calls, tiles or processes.
typedef struct render_job {
    drift_pt *pt;
    const uint32_t *tiles; // NULL: tile i is the i-th
    uint32_t add, until;
    const atomic_bool *cancel;
} render_job;

drift_pt_tile drift_pt_tile_rect(const drift_pt *pt, uint32_t tile)
{
    int32_t width = pt->params.width, height = pt->params.height;
    int32_t tiles_x = (width + TILE_SIZE - 1) / TILE_SIZE;
    drift_pt_tile t = { .x0 = (int32_t)(tile % (uint32_t)tiles_x) * TILE_SIZE,
                        .y0 = (int32_t)(tile / (uint32_t)tiles_x) * TILE_SIZE };
    t.x1 = t.x0 + TILE_SIZE < width ? t.x0 + TILE_SIZE : width;
    t.y1 = t.y0 + TILE_SIZE < height ? t.y0 + TILE_SIZE : height;
    return t;
}

uint32_t drift_pt_tile_count(const drift_pt *pt)
{
    uint32_t tiles_x = (uint32_t)(pt->params.width + TILE_SIZE - 1) / TILE_SIZE;
    uint32_t tiles_y = (uint32_t)(pt->params.height + TILE_SIZE - 1) / TILE_SIZE;
    return tiles_x * tiles_y;
}

static void render_tiles(size_t begin, size_t end, int thread_index, void *user)
{
    render_job *job = user;
    drift_pt *pt = job->pt;
    thread_stats *stats = &pt->thread_stats[thread_index];
    int32_t width = pt->params.width;
    // A pixel's samples run in a row: the cache hashes their pair seeds once (once a call).
    // A pixel with one sample to add skips it: filling a cache never read cost 3% more
    // instructions than hashing (1-spp passes, docs/lab/2026-12-07-issue-46-s6-pt.md).
    drift_sampler_cache cache;
    drift_sampler_cache_init(&cache);
    for (size_t i = begin; i < end; ++i) {
        if (job->cancel && atomic_load(job->cancel)) {
            return;
        }
        drift_pt_tile t = drift_pt_tile_rect(pt, job->tiles ? job->tiles[i] : (uint32_t)i);
        for (int32_t y = t.y0; y < t.y1; ++y) {
            for (int32_t x = t.x0; x < t.x1; ++x) {
                size_t pixel = (size_t)y * (size_t)width + (size_t)x;
                double *sum = pt->sums + pixel * SUM_CHANNELS;
                uint32_t first = pt->counts[pixel];
                uint32_t last = job->until - first < job->add ? job->until : first + job->add;
                if (first >= job->until) {
                    continue;
                }
                for (uint32_t s = first; s < last; ++s) {
                    path_result r;
                    trace_path(pt, x, y, s, last - first > 1 ? &cache : NULL, &r, stats);
                    if (!drift_vec3_is_finite(r.radiance)) {
                        stats->nan_samples++;
                        r.radiance = drift_vec3_splat(0.0f);
                        r.direct = r.radiance;
                    }
                    if (!drift_vec3_is_finite(r.direct)) {
                        r.direct = drift_vec3_splat(0.0f);
                    }
                    float lum = drift_luminance(r.radiance);
                    float lum_direct = drift_luminance(r.direct), lum_rest = lum - lum_direct;
                    const float v[SUM_CHANNELS] = { r.radiance.x,       r.radiance.y,
                                                    r.radiance.z,       r.albedo.x,
                                                    r.albedo.y,         r.albedo.z,
                                                    r.normal.x,         r.normal.y,
                                                    r.normal.z,         r.depth,
                                                    lum * lum,          r.feature_albedo.x,
                                                    r.feature_albedo.y, r.feature_albedo.z,
                                                    r.feature_normal.x, r.feature_normal.y,
                                                    r.feature_normal.z, r.feature_depth,
                                                    r.direct.x,         r.direct.y,
                                                    r.direct.z,         lum_direct * lum_direct,
                                                    lum_rest * lum_rest };
                    for (int c = 0; c < SUM_CHANNELS; ++c) {
                        sum[c] += (double)v[c];
                    }
                }
                pt->counts[pixel] = last;
            }
        }
    }
}

drift_result drift_pt_render_tiles(drift_pt *pt, const uint32_t *tiles, uint32_t tile_count,
                                   uint32_t add, uint32_t until, const atomic_bool *cancel)
{
    if (!pt) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    uint32_t all = drift_pt_tile_count(pt);
    for (uint32_t i = 0; tiles && i < tile_count; ++i) {
        if (tiles[i] >= all) {
            return DRIFT_ERR_INVALID_ARGUMENT;
        }
    }
    double start = drift_time_now();
    render_job job = { .pt = pt, .tiles = tiles, .add = add, .until = until, .cancel = cancel };
    drift_parallel_for(pt->ctx, tiles ? tile_count : all, 1, render_tiles, &job);
    pt->render_seconds += drift_time_now() - start;
    return cancel && atomic_load(cancel) ? DRIFT_ERR_CANCELLED : DRIFT_OK;
}

drift_result drift_pt_render_samples(drift_pt *pt, uint32_t count, const atomic_bool *cancel)
{
    return drift_pt_render_tiles(pt, NULL, 0, count, UINT32_MAX, cancel);
}

uint32_t drift_pt_tile_sample_count(const drift_pt *pt, uint32_t tile)
{
    drift_pt_tile t = drift_pt_tile_rect(pt, tile);
    uint32_t lowest = UINT32_MAX;
    for (int32_t y = t.y0; y < t.y1; ++y) {
        for (int32_t x = t.x0; x < t.x1; ++x) {
            uint32_t n = pt->counts[(size_t)y * (size_t)pt->params.width + (size_t)x];
            lowest = n < lowest ? n : lowest;
        }
    }
    return lowest;
}

// A tile's state: its pixels' sums (SUM_CHANNELS doubles each, row by row), then their
// sample counts (uint32 each).
size_t drift_pt_tile_state_size(const drift_pt *pt, uint32_t tile)
{
    drift_pt_tile t = drift_pt_tile_rect(pt, tile);
    size_t pixels = (size_t)(t.x1 - t.x0) * (size_t)(t.y1 - t.y0);
    return pixels * (SUM_CHANNELS * sizeof(double) + sizeof(uint32_t));
}

void drift_pt_tile_get_state(const drift_pt *pt, uint32_t tile, void *out)
{
    drift_pt_tile t = drift_pt_tile_rect(pt, tile);
    size_t row = (size_t)(t.x1 - t.x0), rows = (size_t)(t.y1 - t.y0);
    uint8_t *sums = out, *counts = sums + row * rows * SUM_CHANNELS * sizeof(double);
    for (int32_t y = t.y0; y < t.y1; ++y) {
        size_t pixel = (size_t)y * (size_t)pt->params.width + (size_t)t.x0;
        memcpy(sums, pt->sums + pixel * SUM_CHANNELS, row * SUM_CHANNELS * sizeof(double));
        memcpy(counts, pt->counts + pixel, row * sizeof(uint32_t));
        sums += row * SUM_CHANNELS * sizeof(double);
        counts += row * sizeof(uint32_t);
    }
}

void drift_pt_tile_set_state(drift_pt *pt, uint32_t tile, const void *state)
{
    drift_pt_tile t = drift_pt_tile_rect(pt, tile);
    size_t row = (size_t)(t.x1 - t.x0), rows = (size_t)(t.y1 - t.y0);
    const uint8_t *sums = state, *counts = sums + row * rows * SUM_CHANNELS * sizeof(double);
    for (int32_t y = t.y0; y < t.y1; ++y) {
        size_t pixel = (size_t)y * (size_t)pt->params.width + (size_t)t.x0;
        memcpy(pt->sums + pixel * SUM_CHANNELS, sums, row * SUM_CHANNELS * sizeof(double));
        memcpy(pt->counts + pixel, counts, row * sizeof(uint32_t));
        sums += row * SUM_CHANNELS * sizeof(double);
        counts += row * sizeof(uint32_t);
    }
}

void drift_pt_add_stats(drift_pt *pt, const drift_pt_stats *stats)
{
    thread_stats *s = &pt->thread_stats[0];
    s->camera_rays += stats->camera_rays;
    s->shadow_rays += stats->shadow_rays;
    s->bounce_rays += stats->bounce_rays;
    s->nan_samples += stats->nan_samples;
}

uint32_t drift_pt_sample_count(const drift_pt *pt)
{
    size_t pixels = (size_t)pt->params.width * (size_t)pt->params.height;
    uint32_t lowest = UINT32_MAX;
    for (size_t i = 0; i < pixels; ++i) {
        lowest = pt->counts[i] < lowest ? pt->counts[i] : lowest;
    }
    return pixels ? lowest : 0;
}

drift_pt_stats drift_pt_get_stats(const drift_pt *pt)
{
    drift_pt_stats s = { .render_seconds = pt->render_seconds };
    for (int i = 0; i < pt->thread_count; ++i) {
        s.camera_rays += pt->thread_stats[i].camera_rays;
        s.shadow_rays += pt->thread_stats[i].shadow_rays;
        s.bounce_rays += pt->thread_stats[i].bounce_rays;
        s.nan_samples += pt->thread_stats[i].nan_samples;
    }
    return s;
}

drift_pt_params drift_pt_get_params(const drift_pt *pt)
{
    return pt->params;
}

drift_result drift_pt_resolve(drift_pt *pt, drift_pt_aov aov, drift_image *out_image)
{
    if (!pt || !out_image || (unsigned)aov >= DRIFT_PT_AOV_COUNT) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    static const int first_channel[DRIFT_PT_AOV_COUNT] = { 0, 3, 6, 9, 10, 11, 14, 17, 18, 21, 22 };
    static const int channel_count[DRIFT_PT_AOV_COUNT] = { 3, 3, 3, 1, 1, 3, 3, 1, 3, 1, 1 };
    drift_image *img = &pt->resolved[aov];
    if (!img->pixels) {
        drift_result r = drift_image_create(pt->ctx, pt->params.width, pt->params.height,
                                            channel_count[aov], img);
        if (r != DRIFT_OK) {
            return r;
        }
    }
    for (int32_t y = 0; y < img->height; ++y) {
        for (int32_t x = 0; x < img->width; ++x) {
            size_t pixel = (size_t)y * (size_t)img->width + (size_t)x;
            uint32_t n = pt->counts[pixel];
            const double *sum = pt->sums + pixel * SUM_CHANNELS + first_channel[aov];
            float *dst = drift_image_pixel(img, x, y);
            if (aov == DRIFT_PT_AOV_VARIANCE || aov == DRIFT_PT_AOV_DIRECT_VARIANCE ||
                aov == DRIFT_PT_AOV_INDIRECT_VARIANCE) {
                // The unbiased sample variance of the luminance over n, the variance of the
                // pixel's mean; 0 below two samples.
                const double *beauty = pt->sums + pixel * SUM_CHANNELS;
                const double *direct = beauty + first_channel[DRIFT_PT_AOV_DIRECT];
                double lb = 0.2126 * beauty[0] + 0.7152 * beauty[1] + 0.0722 * beauty[2];
                double ld = 0.2126 * direct[0] + 0.7152 * direct[1] + 0.0722 * direct[2];
                double mean = (aov == DRIFT_PT_AOV_VARIANCE          ? lb
                               : aov == DRIFT_PT_AOV_DIRECT_VARIANCE ? ld
                                                                     : lb - ld) /
                              (double)(n ? n : 1);
                double var = n > 1 ? (sum[0] - (double)n * mean * mean) / (double)(n - 1) : 0.0;
                dst[0] = var > 0.0 ? (float)(var / (double)n) : 0.0f;
                continue;
            }
            for (int c = 0; c < channel_count[aov]; ++c) {
                dst[c] = n ? (float)(sum[c] / (double)n) : 0.0f;
            }
        }
    }
    *out_image = *img;
    return DRIFT_OK;
}
