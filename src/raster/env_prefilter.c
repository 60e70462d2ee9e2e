// The environment prefiltered by GGX roughness, and the split-sum environment light of a GGX
// surface (Karis 2013, "Real Shading in Unreal Engine 4"): L_glossy ~ prefiltered(R, alpha) x
// the lobe's directional albedo (drift_bsdf_ggx_reflection_albedo, the DFG table), times the
// fraction of the lobe's rays that escape the scene. docs/hybrid.md "Glossy environment light".
//
// Levels: perceptual roughness r = 0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.65, 0.8, 1 (denser where a
// lobe's width changes fastest). Level 0 is the environment itself (looked up exactly, the
// sharp end); level k >= 1 convolves a lat-long copy with the GGX lobe of
// alpha = r^2 under Karis's n = v = r assumption, by filtered importance sampling (Krivanek
// & Colbert 2008) over a box-filtered mip chain of the copy, so a small bright source (the
// sun) spreads into the lobe instead of into fireflies. A lookup interpolates linearly in r.
#include "raster/raster.h"

#include <math.h>
#include <string.h>

#define LEVELS       9 // perceptual roughness level_r[k]
#define BASE_WIDTH   256
#define MIPS         7   // 256 x 128 down to 4 x 2
#define LEVEL_SPP    256 // most lobe samples per prefiltered texel (level_spp)
#define SUPERSAMPLES 2   // per axis, for the base copy

static const float level_r[LEVELS] = { 0.0f, 0.1f, 0.2f, 0.3f, 0.4f, 0.5f, 0.65f, 0.8f, 1.0f };
static const int32_t level_width[LEVELS] = { 0, 128, 64, 64, 32, 32, 32, 32, 32 };
// Wide lobes take more samples: the coarse levels are few texels, and a bright source (the sun)
// seen through 32 samples turned with each texel's frame leaves blotches.
static const uint32_t level_spp[LEVELS] = { 0, 16, 32, 32, 64, 128, 128, 128, 128 };

typedef struct latlong {
    int32_t w, h;
    float *rgb;
} latlong;

struct drift_env_prefilter {
    const drift_scene *scene;
    bool constant;
    latlong mip[MIPS];     // the environment, box-filtered
    latlong level[LEVELS]; // level[0] unused (the environment itself)
};

// Our own lat-long parametrisation (any one will do: every texel is filled by direction).
static drift_vec3 uv_dir(float u, float v)
{
    float theta = v * DRIFT_PI, phi = u * 2.0f * DRIFT_PI;
    float st = sinf(theta);
    return drift_vec3_make(st * cosf(phi), cosf(theta), st * sinf(phi));
}

static void dir_uv(drift_vec3 d, float *u, float *v)
{
    float phi = atan2f(d.z, d.x);
    *u = (phi < 0.0f ? phi + 2.0f * DRIFT_PI : phi) * DRIFT_INV_2PI;
    *v = acosf(drift_clampf(d.y, -1.0f, 1.0f)) * DRIFT_INV_PI;
}

static drift_vec3 lerp3(drift_vec3 a, drift_vec3 b, float t)
{
    return drift_vec3_fma(a, drift_vec3_sub(b, a), t);
}

static drift_vec3 texel(const latlong *m, int32_t x, int32_t y)
{
    x = ((x % m->w) + m->w) % m->w; // wraps in longitude
    y = y < 0 ? 0 : (y >= m->h ? m->h - 1 : y);
    const float *p = &m->rgb[3 * ((size_t)y * (size_t)m->w + (size_t)x)];
    return drift_vec3_make(p[0], p[1], p[2]);
}

static drift_vec3 bilinear_uv(const latlong *m, float u, float v)
{
    float x = u * (float)m->w - 0.5f, y = v * (float)m->h - 0.5f;
    float fx = floorf(x), fy = floorf(y);
    int32_t x0 = (int32_t)fx, y0 = (int32_t)fy;
    float tx = x - fx, ty = y - fy;
    drift_vec3 a = lerp3(texel(m, x0, y0), texel(m, x0 + 1, y0), tx);
    drift_vec3 b = lerp3(texel(m, x0, y0 + 1), texel(m, x0 + 1, y0 + 1), tx);
    return lerp3(a, b, ty);
}

static drift_vec3 bilinear(const latlong *m, drift_vec3 d)
{
    float u, v;
    dir_uv(d, &u, &v);
    return bilinear_uv(m, u, v);
}

static drift_vec3 mip_lookup(const drift_env_prefilter *p, drift_vec3 d, float lod)
{
    lod = drift_clampf(lod, 0.0f, (float)(MIPS - 1));
    int l0 = (int)lod;
    int l1 = l0 + 1 < MIPS ? l0 + 1 : l0;
    float u, v;
    dir_uv(d, &u, &v);
    drift_vec3 a = bilinear_uv(&p->mip[l0], u, v);
    float t = lod - (float)l0;
    return t > 0.0f ? lerp3(a, bilinear_uv(&p->mip[l1], u, v), t) : a;
}

static drift_result alloc_latlong(drift_context *ctx, latlong *m, int32_t w, int32_t h)
{
    m->w = w;
    m->h = h;
    m->rgb = drift_alloc(ctx, sizeof(float) * 3u * (size_t)w * (size_t)h);
    return m->rgb ? DRIFT_OK : DRIFT_ERR_OUT_OF_MEMORY;
}

typedef struct build_job {
    drift_env_prefilter *p;
    int level; // 0: the base copy
    // Level k's lobe samples about +z (the same for every texel): directions and mip levels.
    drift_vec3 l[LEVEL_SPP];
    float lod[LEVEL_SPP];
    uint32_t count;
} build_job;

// One texel of the base copy: the mean of SUPERSAMPLES^2 environment lookups over it.
static drift_vec3 base_texel(const drift_env_prefilter *p, const latlong *m, int32_t x, int32_t y)
{
    drift_vec3 sum = drift_vec3_splat(0.0f);
    for (int j = 0; j < SUPERSAMPLES; ++j) {
        for (int i = 0; i < SUPERSAMPLES; ++i) {
            float u = ((float)x + ((float)i + 0.5f) / SUPERSAMPLES) / (float)m->w;
            float v = ((float)y + ((float)j + 0.5f) / SUPERSAMPLES) / (float)m->h;
            sum = drift_vec3_add(sum, drift_environment_eval(p->scene, uv_dir(u, v)));
        }
    }
    return drift_vec3_scale(sum, 1.0f / (SUPERSAMPLES * SUPERSAMPLES));
}

// Level k's lobe about +z: the GGX lobe of alpha around r (n = v = r, so pdf(l) = D(h) / 4),
// half vectors from D; each sample reads the mip whose texels match its share of the lobe.
static void level_samples(build_job *job)
{
    float r = level_r[job->level], alpha = r * r, a2 = alpha * alpha;
    const drift_env_prefilter *p = job->p;
    const float texel_solid_angle = 4.0f * DRIFT_PI / (float)(p->mip[0].w * p->mip[0].h);
    job->count = 0;
    const uint32_t spp = level_spp[job->level];
    for (uint32_t s = 0; s < spp; ++s) {
        drift_vec2 u = drift_hammersley_shifted(s, spp, drift_vec2_make(0.0f, 0.0f));
        float cos2 = (1.0f - u.x) / (1.0f + (a2 - 1.0f) * u.x);
        float ct = sqrtf(cos2), st = sqrtf(fmaxf(0.0f, 1.0f - cos2)), phi = 2.0f * DRIFT_PI * u.y;
        drift_vec3 h = drift_vec3_make(st * cosf(phi), st * sinf(phi), ct);
        drift_vec3 l = drift_vec3_make(2.0f * ct * h.x, 2.0f * ct * h.y, 2.0f * ct * ct - 1.0f);
        if (l.z <= 0.0f) {
            continue;
        }
        float dd = ct * ct * (a2 - 1.0f) + 1.0f;
        float pdf = a2 / (DRIFT_PI * dd * dd) * 0.25f;
        job->l[job->count] = l;
        job->lod[job->count] = 0.5f * log2f(1.0f / ((float)spp * pdf * texel_solid_angle));
        ++job->count;
    }
}

// One texel of a level: its lobe samples turned to the texel's direction, weighted by n.l.
static drift_vec3 level_texel(const build_job *job, const latlong *m, int32_t x, int32_t y)
{
    drift_vec3 n = uv_dir(((float)x + 0.5f) / (float)m->w, ((float)y + 0.5f) / (float)m->h);
    drift_frame frame = drift_frame_from_normal(n);
    drift_vec3 sum = drift_vec3_splat(0.0f);
    float weight = 0.0f;
    for (uint32_t s = 0; s < job->count; ++s) {
        drift_vec3 c = mip_lookup(job->p, drift_frame_to_world(&frame, job->l[s]), job->lod[s]);
        sum = drift_vec3_fma(sum, c, job->l[s].z);
        weight += job->l[s].z;
    }
    return weight > 0.0f ? drift_vec3_scale(sum, 1.0f / weight) : sum;
}

static void build_rows(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    build_job *job = user;
    latlong *m = job->level == 0 ? &job->p->mip[0] : &job->p->level[job->level];
    for (size_t y = begin; y < end; ++y) {
        for (int32_t x = 0; x < m->w; ++x) {
            drift_vec3 c = job->level == 0 ? base_texel(job->p, m, x, (int32_t)y)
                                           : level_texel(job, m, x, (int32_t)y);
            float *o = &m->rgb[3 * (y * (size_t)m->w + (size_t)x)];
            o[0] = c.x, o[1] = c.y, o[2] = c.z;
        }
    }
}

static void downsample(const latlong *in, latlong *out)
{
    for (int32_t y = 0; y < out->h; ++y) {
        for (int32_t x = 0; x < out->w; ++x) {
            drift_vec3 s = drift_vec3_add(
                drift_vec3_add(texel(in, 2 * x, 2 * y), texel(in, 2 * x + 1, 2 * y)),
                drift_vec3_add(texel(in, 2 * x, 2 * y + 1), texel(in, 2 * x + 1, 2 * y + 1)));
            float *o = &out->rgb[3 * ((size_t)y * (size_t)out->w + (size_t)x)];
            o[0] = 0.25f * s.x, o[1] = 0.25f * s.y, o[2] = 0.25f * s.z;
        }
    }
}

drift_result drift_env_prefilter_build(drift_context *ctx, const drift_scene *scene,
                                       drift_env_prefilter **out)
{
    *out = NULL;
    drift_env_prefilter *p = drift_alloc(ctx, sizeof *p);
    if (!p) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    memset(p, 0, sizeof *p);
    p->scene = scene;
    p->constant = !drift_scene_has_environment(scene) || drift_environment_is_constant(scene);
    drift_result r = DRIFT_OK;
    if (!p->constant) {
        for (int i = 0; r == DRIFT_OK && i < MIPS; ++i) {
            r = alloc_latlong(ctx, &p->mip[i], BASE_WIDTH >> i, (BASE_WIDTH / 2) >> i);
        }
        for (int k = 1; r == DRIFT_OK && k < LEVELS; ++k) {
            r = alloc_latlong(ctx, &p->level[k], level_width[k], level_width[k] / 2);
        }
        if (r == DRIFT_OK) {
            build_job job = { .p = p };
            drift_parallel_for(ctx, (size_t)p->mip[0].h, 4, build_rows, &job);
            for (int i = 1; i < MIPS; ++i) {
                downsample(&p->mip[i - 1], &p->mip[i]);
            }
            for (job.level = 1; job.level < LEVELS; ++job.level) {
                level_samples(&job);
                drift_parallel_for(ctx, (size_t)p->level[job.level].h, 2, build_rows, &job);
            }
        }
    }
    if (r != DRIFT_OK) {
        drift_env_prefilter_destroy(ctx, p);
        return r;
    }
    *out = p;
    return DRIFT_OK;
}

void drift_env_prefilter_destroy(drift_context *ctx, drift_env_prefilter *p)
{
    if (!p) {
        return;
    }
    for (int i = 0; i < MIPS; ++i) {
        drift_free(ctx, p->mip[i].rgb);
    }
    for (int k = 0; k < LEVELS; ++k) {
        drift_free(ctx, p->level[k].rgb);
    }
    drift_free(ctx, p);
}

drift_vec3 drift_env_prefilter_lookup(const drift_env_prefilter *p, drift_vec3 dir, float alpha)
{
    if (p->constant) {
        return drift_environment_eval(p->scene, dir);
    }
    float r = sqrtf(drift_clampf(alpha, 0.0f, 1.0f));
    int k0 = 0;
    while (k0 < LEVELS - 2 && r >= level_r[k0 + 1]) {
        ++k0;
    }
    float frac = drift_clampf((r - level_r[k0]) / (level_r[k0 + 1] - level_r[k0]), 0.0f, 1.0f);
    drift_vec3 a = k0 == 0 ? drift_environment_eval(p->scene, dir) : bilinear(&p->level[k0], dir);
    if (frac <= 0.0f) {
        return a;
    }
    return lerp3(a, bilinear(&p->level[k0 + 1], dir), frac);
}

// One GGX reflection lobe of roughness alpha: the prefiltered environment along its dominant
// direction times its albedo `single` (and the multiple-scattering lobe's, nearly
// cosine-shaped, around n), times the share of visible-normal reflections that escape.
static drift_vec3 lobe_split_sum(const drift_env_prefilter *p, const drift_accel *accel,
                                 const drift_surface *surface, const drift_bsdf *bsdf,
                                 drift_vec3 wo, float alpha, drift_vec3 single, drift_vec3 multiple,
                                 uint32_t visibility_rays, drift_vec2 shift, uint64_t *rays)
{
    drift_vec3 n = bsdf->frame.z;
    alpha = fmaxf(alpha, 1e-3f);
    // The lobe's dominant direction leans from r toward n as it widens (Lagarde & de
    // Rousiers 2014, "Moving Frostbite to PBR", for GGX with height-correlated Smith).
    drift_vec3 r = drift_bsdf_mirror_direction(bsdf, wo);
    float s = 1.0f - alpha, lean = s * (sqrtf(s) + alpha);
    drift_vec3 dominant = drift_vec3_normalize(lerp3(n, r, lean));
    drift_vec3 l = drift_vec3_mul(single, drift_env_prefilter_lookup(p, dominant, alpha));
    if (!drift_vec3_is_zero(multiple)) {
        // The multiple-scattering lobe is a broader GGX lobe about the same mirror direction:
        // its roughness's level (at most the widest) around its own dominant direction.
        float alpha_ms = fminf(drift_ggx_multiple_scattering_alpha(alpha), 1.0f);
        float s_ms = 1.0f - alpha_ms, lean_ms = s_ms * (sqrtf(s_ms) + alpha_ms);
        drift_vec3 dominant_ms = drift_vec3_normalize(lerp3(n, r, lean_ms));
        l = drift_vec3_add(
            l, drift_vec3_mul(multiple, drift_env_prefilter_lookup(p, dominant_ms, alpha_ms)));
    }
    // Visibility: the share of visible-normal reflections of wo that escape the scene.
    uint32_t valid = 0, open = 0;
    drift_vec3 wo_local = drift_frame_to_local(&bsdf->frame, wo);
    for (uint32_t k = 0; k < visibility_rays; ++k) {
        drift_vec2 u = drift_hammersley_shifted(k, visibility_rays, shift);
        drift_vec3 m = drift_ggx_sample_visible_normal(alpha, wo_local, u);
        drift_vec3 wi_local =
            drift_vec3_sub(drift_vec3_scale(m, 2.0f * drift_vec3_dot(wo_local, m)), wo_local);
        drift_vec3 wi = drift_frame_to_world(&bsdf->frame, wi_local);
        if (wi_local.z <= 0.0f || drift_vec3_dot(wi, surface->ng) <= 0.0f) {
            continue;
        }
        ++valid;
        drift_ray ray = { .origin = drift_offset_origin(surface->position, surface->ng, wi),
                          .dir = wi,
                          .tmin = 0.0f,
                          .tmax = INFINITY };
        ++*rays;
        open += drift_accel_occluded(accel, &ray) ? 0u : 1u;
    }
    float visibility = valid ? (float)open / (float)valid : 1.0f;
    return drift_vec3_scale(l, visibility);
}

drift_vec3 drift_raster_environment_split_sum(const drift_env_prefilter *p,
                                              const drift_accel *accel,
                                              const drift_surface *surface, const drift_bsdf *bsdf,
                                              drift_vec3 wo, uint32_t visibility_rays,
                                              drift_vec2 shift, uint64_t *rays)
{
    drift_vec3 zero = drift_vec3_splat(0.0f);
    float mu = drift_vec3_dot(wo, bsdf->frame.z);
    if (bsdf->type != DRIFT_MATERIAL_GGX || !(mu > 0.0f)) {
        return zero;
    }
    drift_vec3 single, multiple, l = zero;
    drift_bsdf_ggx_reflection_albedo(bsdf, mu, &single, &multiple);
    if (!drift_vec3_is_zero(single) || !drift_vec3_is_zero(multiple)) {
        l = lobe_split_sum(p, accel, surface, bsdf, wo, bsdf->ggx.alpha, single, multiple,
                           visibility_rays, shift, rays);
    }
    // A clear coat (src/scene/clearcoat.c): its own lobe, of its own roughness.
    float coat_alpha;
    float coat = drift_bsdf_clearcoat_albedo(bsdf, mu, &coat_alpha);
    if (coat > 0.0f) {
        l = drift_vec3_add(l, lobe_split_sum(p, accel, surface, bsdf, wo, coat_alpha,
                                             drift_vec3_splat(coat), zero, visibility_rays, shift,
                                             rays));
    }
    return l;
}
