// VPL generation (docs/ism.md, "VPLs"): light paths whose diffuse vertices become VPLs.
//
// A path picks a light in proportion to its power (drift_scene_pick_light; the environment is
// the entry light_count). Point and spot lights then pick a texel of their reflective shadow
// map (RSM) through its 2-D CDF over the texels' reflected flux and shoot a ray jittered
// inside that texel; area lights shoot from a uniform point along a cosine direction;
// directional lights and the environment shoot parallel rays from a disc covering the
// scene's bounding sphere. Every path's flux is weighted by 1 / (pdf x path count), so the sum
// over paths is an unbiased estimate of the emitted power and the sum of the VPLs' flux is the
// reflected flux, bounce by bounce.
#include "ism/ism_internal.h"
#include "raster/raster.h"
#include "scene/light_path.h"

#include <math.h>
#include <string.h>

// --- REFLECTIVE SHADOW MAPS ---

// One RSM: `faces` faces of size x size texels, each a plane at distance 1 from the light
// along `axis[f]`, spanning [-extent, extent]^2 along `u[f]`, `v[f]`. The flux of each texel
// (luminance of the light reflected at the surface its centre ray hits) feeds the CDF over
// rows (faces * size rows) and columns.
typedef struct rsm {
    int32_t size, faces;
    float extent;
    drift_vec3 axis[6], u[6], v[6];
    float *flux;        // faces * size * size
    float *marginal;    // rows + 1
    float *conditional; // rows * (size + 1)
    double total;
} rsm;

static float spot_falloff(const drift_light *l, drift_vec3 dir)
{
    if (l->type != DRIFT_LIGHT_SPOT) {
        return 1.0f;
    }
    return drift_light_spot_falloff(l, drift_vec3_dot(l->direction, dir));
}

// Direction (unnormalised) through face coordinates (a, b) in [0, 1)^2 of face f.
static drift_vec3 rsm_dir(const rsm *m, int32_t f, float a, float b)
{
    float x = (2.0f * a - 1.0f) * m->extent, y = (2.0f * b - 1.0f) * m->extent;
    return drift_vec3_add(
        m->axis[f], drift_vec3_add(drift_vec3_scale(m->u[f], x), drift_vec3_scale(m->v[f], y)));
}

// The closest hit of `ray` and its BSDF; false when the ray misses or hits a pure emitter.
static bool trace_vertex(const drift_scene *scene, const drift_accel *accel, const drift_ray *ray,
                         drift_surface *out_surface, drift_bsdf *out_bsdf)
{
    drift_hit hit;
    if (!drift_accel_intersect(accel, ray, &hit)) {
        return false;
    }
    *out_surface = drift_scene_surface(scene, ray, &hit);
    if (out_surface->material == DRIFT_INVALID_INDEX) {
        return false;
    }
    *out_bsdf = drift_bsdf_make(scene, out_surface);
    return true;
}

// The diffuse albedo at the closest hit of `ray`, with the surface; false when the ray misses
// or hits a pure emitter (a light's shape).
static bool trace_surface(const drift_scene *scene, const drift_accel *accel, const drift_ray *ray,
                          drift_surface *out_surface, drift_vec3 *out_kd)
{
    drift_bsdf bsdf;
    if (!trace_vertex(scene, accel, ray, out_surface, &bsdf)) {
        return false;
    }
    *out_kd = bsdf.type == DRIFT_MATERIAL_MIRROR ? drift_vec3_splat(0.0f) : bsdf.diffuse;
    return true;
}

typedef struct rsm_job {
    rsm *map;
    const drift_scene *scene;
    const drift_accel *accel;
    const drift_light *light;
} rsm_job;

static void rsm_rows(size_t begin, size_t end, int thread, void *user)
{
    (void)thread;
    const rsm_job *job = user;
    rsm *m = job->map;
    float texel_area = (2.0f * m->extent / (float)m->size) * (2.0f * m->extent / (float)m->size);
    for (size_t row = begin; row < end; ++row) {
        int32_t f = (int32_t)(row / (size_t)m->size), y = (int32_t)(row % (size_t)m->size);
        for (int32_t x = 0; x < m->size; ++x) {
            drift_vec3 d = rsm_dir(m, f, ((float)x + 0.5f) / (float)m->size,
                                   ((float)y + 0.5f) / (float)m->size);
            float len = drift_vec3_length(d);
            drift_vec3 w = drift_vec3_scale(d, 1.0f / len);
            drift_ray ray = { job->light->position, 0.0f, w, INFINITY, 0 };
            drift_surface s;
            drift_vec3 kd;
            float flux = 0.0f;
            if (trace_surface(job->scene, job->accel, &ray, &s, &kd)) {
                // Intensity x solid angle of the texel (dA / d^3 on the unit-distance plane).
                float omega = texel_area / (len * len * len);
                flux = drift_luminance(drift_vec3_mul(job->light->color, kd)) *
                       spot_falloff(job->light, w) * omega;
            }
            m->flux[row * (size_t)m->size + (size_t)x] = flux;
        }
    }
}

static void rsm_destroy(drift_context *ctx, rsm *m)
{
    if (!m) {
        return;
    }
    drift_free(ctx, m->flux);
    drift_free(ctx, m->marginal);
    drift_free(ctx, m->conditional);
    drift_free(ctx, m);
}

static drift_result rsm_build(drift_context *ctx, const drift_scene *scene,
                              const drift_accel *accel, const drift_light *l, int32_t size,
                              rsm **out)
{
    *out = NULL;
    rsm *m = drift_alloc(ctx, sizeof *m);
    if (!m) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    m->size = size;
    // A spot whose cone fits in one 120-degree face gets one face, anything wider a cube.
    if (l->type == DRIFT_LIGHT_SPOT && l->spot_outer < 1.0472f) {
        drift_frame fr = drift_frame_from_normal(l->direction);
        m->faces = 1;
        m->extent = tanf(l->spot_outer);
        m->axis[0] = fr.z;
        m->u[0] = fr.x;
        m->v[0] = fr.y;
    } else {
        static const float axes[6][3][3] = {
            { { 1, 0, 0 }, { 0, 0, -1 }, { 0, 1, 0 } }, { { -1, 0, 0 }, { 0, 0, 1 }, { 0, 1, 0 } },
            { { 0, 1, 0 }, { 1, 0, 0 }, { 0, 0, -1 } }, { { 0, -1, 0 }, { 1, 0, 0 }, { 0, 0, 1 } },
            { { 0, 0, 1 }, { 1, 0, 0 }, { 0, 1, 0 } },  { { 0, 0, -1 }, { -1, 0, 0 }, { 0, 1, 0 } },
        };
        m->faces = 6;
        m->extent = 1.0f;
        for (int f = 0; f < 6; ++f) {
            m->axis[f] = drift_vec3_make(axes[f][0][0], axes[f][0][1], axes[f][0][2]);
            m->u[f] = drift_vec3_make(axes[f][1][0], axes[f][1][1], axes[f][1][2]);
            m->v[f] = drift_vec3_make(axes[f][2][0], axes[f][2][1], axes[f][2][2]);
        }
    }
    size_t rows = (size_t)m->faces * (size_t)size;
    m->flux = drift_alloc(ctx, rows * (size_t)size * sizeof *m->flux);
    m->marginal = drift_alloc(ctx, (rows + 1) * sizeof *m->marginal);
    m->conditional = drift_alloc(ctx, rows * ((size_t)size + 1) * sizeof *m->conditional);
    if (!m->flux || !m->marginal || !m->conditional) {
        rsm_destroy(ctx, m);
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    rsm_job job = { m, scene, accel, l };
    drift_parallel_for(ctx, rows, 4, rsm_rows, &job);
    // Conditional CDF of each row, then the marginal over the rows' sums (in double).
    double total = 0.0;
    for (size_t r = 0; r < rows; ++r) {
        float *cdf = m->conditional + r * ((size_t)size + 1);
        const float *flux = m->flux + r * (size_t)size;
        double sum = 0.0;
        cdf[0] = 0.0f;
        for (int32_t x = 0; x < size; ++x) {
            sum += (double)flux[x];
            cdf[x + 1] = (float)sum;
        }
        for (int32_t x = 1; x <= size; ++x) {
            cdf[x] = sum > 0.0 ? (float)((double)cdf[x] / sum) : (float)x / (float)size;
        }
        m->marginal[r] = (float)total;
        total += sum;
    }
    m->marginal[rows] = (float)total;
    for (size_t r = 1; r <= rows; ++r) {
        m->marginal[r] = total > 0.0 ? (float)((double)m->marginal[r] / total) : 0.0f;
    }
    m->total = total;
    *out = m;
    return DRIFT_OK;
}

// Index i with cdf[i] <= u < cdf[i+1] over a CDF of n entries (n + 1 values), skipping empty
// entries; *out_pmf gets cdf[i+1] - cdf[i].
static int32_t cdf_pick(const float *cdf, int32_t n, float u, float *out_pmf)
{
    int32_t lo = (int32_t)drift_cdf_find(cdf, (uint32_t)n, u);
    while (lo + 1 < n && !(cdf[lo + 1] > cdf[lo])) {
        lo++;
    }
    *out_pmf = cdf[lo + 1] - cdf[lo];
    return lo;
}

// --- LIGHT PATHS ---

typedef struct path_job {
    const drift_scene *scene;
    const drift_accel *accel;
    const drift_ism_params *params;
    rsm **rsms;          // per light; NULL for lights that are not point or spot lights
    drift_vpl *slots;    // paths x bounces
    drift_vec3 *emitted; // per path
    uint32_t bounces;
    uint32_t first; // sampler index of path 0 of this round
    uint32_t key;
    drift_vec3 centre;
    float radius;
} path_job;

// A point or spot light's first ray, importance-sampled from its reflective shadow map.
static bool emit_point_rsm(const void *user, uint32_t li, drift_vec2 u1, drift_vec2 u2, float pmf,
                           float n, drift_ray *out_ray, drift_vec3 *out_flux)
{
    const path_job *job = user;
    const drift_light *l = &job->scene->lights[li];
    const rsm *m = job->rsms[li];
    if (!m || !(m->total > 0.0)) {
        return false;
    }
    float p_row, p_col;
    int32_t rows = m->faces * m->size;
    int32_t row = cdf_pick(m->marginal, rows, u1.y, &p_row);
    int32_t col =
        cdf_pick(m->conditional + (size_t)row * ((size_t)m->size + 1), m->size, u1.x, &p_col);
    int32_t f = row / m->size, y = row % m->size;
    drift_vec3 d =
        rsm_dir(m, f, ((float)col + u2.x) / (float)m->size, ((float)y + u2.y) / (float)m->size);
    float len = drift_vec3_length(d);
    drift_vec3 w = drift_vec3_scale(d, 1.0f / len);
    float texel_area = (2.0f * m->extent / (float)m->size) * (2.0f * m->extent / (float)m->size);
    // Solid-angle pdf: the texel's probability over its solid angle (dA / d^3).
    float pdf_dir = p_row * p_col * len * len * len / texel_area;
    if (!(pdf_dir > 0.0f)) {
        return false;
    }
    *out_ray = (drift_ray){ l->position, 0.0f, w, INFINITY, 0 };
    *out_flux = drift_vec3_scale(l->color, spot_falloff(l, w) / (pdf_dir * pmf * n));
    return true;
}

// The first ray of path i and the flux it carries; false when the path carries nothing.
static bool emit(const path_job *job, drift_sampler *s, drift_ray *out_ray, drift_vec3 *out_flux)
{
    return drift__light_path_emit(job->scene, s, (float)job->params->vpl_count, job->centre,
                                  job->radius, emit_point_rsm, job, out_ray, out_flux);
}

// The glossy lobe a VPL at a glossy vertex shines: the Phong lobe ks (n + 2) / (2 pi) cos^n
// around the mirror direction of the light's incoming direction, n clamped to a power of two
// m <= DRIFT_VPL_MAX_EXPONENT (the gather raises to m by squaring), energy kept by (m + 2).
static void glossy_lobe(const drift_bsdf *bsdf, drift_vec3 toward_light, drift_vec3 flux,
                        drift_vpl *vpl)
{
    // GGX: the Phong lobe of its 90% cone and of its reflection's albedo toward the light.
    float n = bsdf->type == DRIFT_MATERIAL_GGX ? 0.25f * drift_gloss_blinn_exponent(bsdf)
                                               : bsdf->exponent;
    n = fminf(n, DRIFT_VPL_MAX_EXPONENT);
    uint32_t k = 0;
    while (k < DRIFT_VPL_MAX_SQUARINGS && (float)(2u << k) <= n) {
        ++k;
    }
    float m = (float)(1u << k);
    vpl->squarings = k;
    vpl->lobe = drift_bsdf_mirror_direction(bsdf, toward_light);
    drift_vec3 ks = bsdf->type == DRIFT_MATERIAL_GGX
                        ? drift_raster_reflection_weight(bsdf, toward_light)
                        : bsdf->specular;
    vpl->glossy = drift_vec3_scale(drift_vec3_mul(flux, ks), 0.5f * (m + 2.0f));
}

// Every vertex leaves a VPL of the light its diffuse lobe reflects, and of its glossy lobe's.
// The path goes on by the cosine of a diffuse surface, or by drift_bsdf_sample_wi's lobes
// where the surface has a glossy or mirror lobe: that carries the light a glossy floor
// reflects to the ceiling, which a diffuse-only path dropped (40% of the glossy Cornell
// floor's reflected light; docs/ism.md, "VPLs").
static void trace_paths(size_t begin, size_t end, int thread, void *user)
{
    (void)thread;
    const path_job *job = user;
    uint32_t later = job->params->later_vpl_count;
    for (size_t i = begin; i < end; ++i) {
        drift_vpl *slots = job->slots + i * job->bounces;
        drift_sampler s = drift_sampler_make(job->key, 0, job->first + (uint32_t)i);
        drift_ray ray;
        drift_vec3 flux;
        job->emitted[i] = drift_vec3_splat(0.0f);
        if (!emit(job, &s, &ray, &flux)) {
            continue;
        }
        job->emitted[i] = flux;
        for (uint32_t b = 0; b < job->bounces; ++b) {
            if (b == 1) {
                // Only the first `later` paths go on, carrying vpl_count / later times more.
                if (i >= later) {
                    break;
                }
                flux = drift_vec3_scale(flux, (float)job->params->vpl_count / (float)later);
            }
            drift_surface surf;
            drift_bsdf bsdf;
            if (!trace_vertex(job->scene, job->accel, &ray, &surf, &bsdf)) {
                break;
            }
            bool mirror = bsdf.type == DRIFT_MATERIAL_MIRROR;
            // The diffuse lobe's albedo toward the light: kd for Lambert, Burley's and GGX's
            // base integrated (drift_raster_diffuse_albedo).
            drift_vec3 diffuse =
                drift_vec3_mul(flux, drift_raster_diffuse_albedo(&bsdf, drift_vec3_neg(ray.dir)));
            drift_vpl vpl = {
                .position = surf.position, .normal = surf.ns, .flux = diffuse, .bounce = b + 1
            };
            if (!mirror && !drift_vec3_is_zero(bsdf.specular)) {
                glossy_lobe(&bsdf, drift_vec3_neg(ray.dir), flux, &vpl);
            }
            if (!drift_vec3_is_zero(vpl.flux) || !drift_vec3_is_zero(vpl.glossy)) {
                slots[b] = vpl;
            }
            // A diffuse surface keeps the cosine direction (and its sampler dimensions) the
            // paths always took, so diffuse scenes' VPLs are unchanged.
            drift_vec3 w;
            if (!mirror && drift_vec3_is_zero(bsdf.specular)) {
                flux = diffuse;
                drift_frame fr = drift_frame_from_normal(surf.ns);
                w = drift_frame_to_world(&fr,
                                         drift_sample_cosine_hemisphere(drift_sampler_next2(&s)));
            } else {
                float u_lobe = drift_sampler_next1(&s);
                drift_bsdf_sample bs = drift_bsdf_sample_wi(&bsdf, drift_vec3_neg(ray.dir), u_lobe,
                                                            drift_sampler_next2(&s));
                flux = bs.pdf > 0.0f ? drift_vec3_mul(flux, bs.weight) : drift_vec3_splat(0.0f);
                w = bs.wi;
            }
            if (drift_vec3_is_zero(flux) || drift_vec3_dot(w, surf.ng) <= 0.0f) {
                break;
            }
            ray =
                (drift_ray){ drift_offset_origin(surf.position, surf.ng, w), 0.0f, w, INFINITY, 0 };
        }
    }
}

uint32_t drift__ism_max_vpls(const drift_ism_params *params)
{
    uint32_t bounces = params->max_depth > 1 ? (uint32_t)(params->max_depth - 1) : 0;
    if (bounces == 0) {
        return 0;
    }
    // One round: at most vpl_count first-bounce VPLs. More rounds stop once half of
    // vpl_count have landed, so fewer than 1.5 vpl_count; later bounces add at most
    // later_vpl_count a round.
    uint32_t rounds = params->max_path_rounds > 1 ? (uint32_t)params->max_path_rounds : 1;
    uint32_t first = rounds > 1 ? params->vpl_count + params->vpl_count / 2 : params->vpl_count;
    if (params->vpl_importance && rounds > 1) {
        first = 2 * params->vpl_count; // rounds stop once vpl_count are accepted
    }
    return first + (bounces - 1) * params->later_vpl_count * rounds;
}

// --- IMPORTANCE (Georgiev & Slusallek 2010) ---

// A candidate VPL's estimated contribution to the view: the luminance of its flux times the
// unshadowed geometry term clamped at d_min, averaged over the camera-visible points (16
// shadow rays each instead were measured worse: docs/ism.md).
static float vpl_contribution(const drift_vpl *v, const drift_vec3 *points,
                              const drift_vec3 *normals, uint32_t count, float d_min2)
{
    double sum = 0.0;
    for (uint32_t k = 0; k < count; ++k) {
        drift_vec3 d = drift_vec3_sub(points[k], v->position);
        float d2 = drift_vec3_dot(d, d);
        float cos_v = drift_vec3_dot(v->normal, d), cos_x = -drift_vec3_dot(normals[k], d);
        if (cos_v > 0.0f && cos_x > 0.0f && d2 > 0.0f) {
            sum += (double)(cos_v * cos_x / (d2 * fmaxf(d2, d_min2)));
        }
    }
    // The glossy lobe's power is about glossy x 2 / (m + 2); its direction is not weighed.
    float glossy = drift_luminance(v->glossy) * 2.0f / ((float)(1u << v->squarings) + 2.0f);
    return (drift_luminance(v->flux) + glossy) * (float)(sum / (double)count);
}

drift_result drift__ism_generate_vpls(drift_context *ctx, const drift_scene *scene,
                                      const drift_accel *accel, const drift_ism_params *params,
                                      drift_vpl **out_vpls, uint32_t *out_count,
                                      drift_vec3 *out_emitted)
{
    return drift__ism_generate_vpls_for(ctx, scene, accel, params, NULL, NULL, 0, out_vpls,
                                        out_count, out_emitted);
}

drift_result drift__ism_generate_vpls_for(drift_context *ctx, const drift_scene *scene,
                                          const drift_accel *accel, const drift_ism_params *params,
                                          const drift_vec3 *points, const drift_vec3 *normals,
                                          uint32_t point_count, drift_vpl **out_vpls,
                                          uint32_t *out_count, drift_vec3 *out_emitted)
{
    *out_vpls = NULL;
    *out_count = 0;
    if (out_emitted) {
        *out_emitted = drift_vec3_splat(0.0f);
    }
    uint32_t bounces = params->max_depth > 1 ? (uint32_t)(params->max_depth - 1) : 0;
    uint32_t paths = params->vpl_count;
    if (bounces == 0 || paths == 0 || scene->light_count + 1 == 0) {
        return DRIFT_OK;
    }
    drift_result result = DRIFT_OK;
    rsm **rsms = drift_alloc(ctx, ((size_t)scene->light_count + 1) * sizeof *rsms);
    drift_vpl *slots = drift_alloc(ctx, (size_t)paths * bounces * sizeof *slots);
    drift_vec3 *emitted = drift_alloc(ctx, (size_t)paths * sizeof *emitted);
    if (!rsms || !slots || !emitted) {
        result = DRIFT_ERR_OUT_OF_MEMORY;
        goto done;
    }
    for (uint32_t i = 0; i < scene->light_count && result == DRIFT_OK; ++i) {
        drift_light_type t = scene->lights[i].type;
        if ((t == DRIFT_LIGHT_POINT || t == DRIFT_LIGHT_SPOT) &&
            drift_scene_light_pmf(scene, i) > 0.0f) {
            result = rsm_build(ctx, scene, accel, &scene->lights[i], params->rsm_size, &rsms[i]);
        }
    }
    if (result != DRIFT_OK) {
        goto done;
    }
    // Distant light's parallel rays cover the reflecting geometry (a pure emitter sends none
    // of it back), so a sun far outside the room does not widen their disc.
    drift_bounds3 reach =
        drift_bounds3_is_empty(scene->reflector_bounds) ? scene->bounds : scene->reflector_bounds;
    drift_vec3 lo = reach.min, hi = reach.max;
    path_job job = { .scene = scene,
                     .accel = accel,
                     .params = params,
                     .rsms = rsms,
                     .slots = slots,
                     .emitted = emitted,
                     .bounces = bounces,
                     .key = drift_hash_combine(params->seed, DRIFT_ISM_VPL_STREAM),
                     .centre = drift_vec3_scale(drift_vec3_add(lo, hi), 0.5f),
                     .radius = 0.5f * drift_vec3_length(drift_vec3_sub(hi, lo)) * 1.01f };
    // Rounds of `paths` light paths (Sobol samples round * paths + i) until at least half as
    // many first-bounce VPLs as paths have landed, or max_path_rounds; every flux is then
    // divided by the rounds traced, so the estimate stays unbiased.
    uint32_t rounds_max = params->max_path_rounds > 0 ? (uint32_t)params->max_path_rounds : 1;
    drift_vpl *vpls = drift_alloc(ctx, ((size_t)drift__ism_max_vpls(params) + 1) * sizeof *vpls);
    if (!vpls) {
        result = DRIFT_ERR_OUT_OF_MEMORY;
        goto done;
    }
    uint32_t count = 0, landed = 0, rounds = 0;
    double sum[3] = { 0, 0, 0 };
    // Importance: candidates are accepted with p = min(1, c / target) and divided by p; the
    // target is the mean contribution of the first round's candidates, so the ones that
    // light the view are kept and the rest thinned. Rounds go on until vpl_count are kept.
    bool importance = params->vpl_importance && point_count > 0;
    uint32_t want = importance ? paths : (paths + 1) / 2;
    float target = 0.0f;
    drift_vec3 dd = drift_vec3_sub(hi, lo);
    float d_min =
        params->clamp_distance > 0.0f ? params->clamp_distance : 0.05f * drift_vec3_length(dd);
    uint32_t accept_key = drift_hash_combine(params->seed, DRIFT_ISM_VPL_STREAM + 1u);
    while (rounds < rounds_max && (rounds == 0 || landed < want)) {
        memset(slots, 0, (size_t)paths * bounces * sizeof *slots);
        job.first = rounds * paths;
        drift_parallel_for(ctx, paths, 16, trace_paths, &job);
        rounds++;
        for (uint32_t i = 0; i < paths; ++i) {
            sum[0] += (double)emitted[i].x;
            sum[1] += (double)emitted[i].y;
            sum[2] += (double)emitted[i].z;
        }
        if (importance && rounds == 1) {
            double total = 0.0;
            uint32_t n = 0;
            for (size_t j = 0; j < (size_t)paths * bounces; ++j) {
                if (slots[j].bounce == (uint32_t)(j % bounces) + 1) {
                    total += (double)vpl_contribution(&slots[j], points, normals, point_count,
                                                      d_min * d_min);
                    n++;
                }
            }
            target = n > 0 ? (float)(total / (double)n) : 0.0f;
        }
        // Append in (bounce, path) order: the same list for any thread count.
        for (uint32_t b = 0; b < bounces; ++b) {
            for (uint32_t i = 0; i < paths; ++i) {
                drift_vpl v = slots[(size_t)i * bounces + b];
                if (v.bounce != b + 1) {
                    continue;
                }
                if (importance && target > 0.0f) {
                    float c = vpl_contribution(&v, points, normals, point_count, d_min * d_min);
                    // At least 1/10: a VPL the 256 view points miss may still light a pixel.
                    float p = fmaxf(0.1f, fminf(1.0f, c / target));
                    uint32_t h = drift_hash_combine(accept_key, (rounds - 1) * paths * bounces +
                                                                    i * bounces + b);
                    float u = drift_u32_to_unit(h);
                    if (!(u < p)) {
                        continue;
                    }
                    v.flux = drift_vec3_scale(v.flux, 1.0f / p);
                    v.glossy = drift_vec3_scale(v.glossy, 1.0f / p);
                }
                vpls[count++] = v;
                landed += b == 0;
            }
        }
    }
    if (rounds > 1) {
        for (uint32_t j = 0; j < count; ++j) {
            vpls[j].flux = drift_vec3_scale(vpls[j].flux, 1.0f / (float)rounds);
            vpls[j].glossy = drift_vec3_scale(vpls[j].glossy, 1.0f / (float)rounds);
        }
    }
    *out_vpls = vpls;
    *out_count = count;
    if (out_emitted) {
        double inv = 1.0 / (double)rounds;
        *out_emitted =
            drift_vec3_make((float)(sum[0] * inv), (float)(sum[1] * inv), (float)(sum[2] * inv));
    }
done:
    if (rsms) {
        for (uint32_t i = 0; i < scene->light_count; ++i) {
            rsm_destroy(ctx, rsms[i]);
        }
    }
    drift_free(ctx, rsms);
    drift_free(ctx, slots);
    drift_free(ctx, emitted);
    return result;
}
