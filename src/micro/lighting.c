// Lighting the points (thesis §6.4). The first bounce: the direct light each leaf's disc
// reflects through its diffuse lobe, on both sides (drift's surfaces are two-sided), with
// ray-traced visibility where the thesis used shadow maps. Light picks follow the path
// tracer's power-proportional distribution (the environment included). More bounces come from
// a radiosity (Jacobi) iteration over the tree (radiosity.c) or a photon map (photons.c).
#include "micro/micro_internal.h"

#include <math.h>
#include <string.h>

typedef struct light_job {
    const drift_scene *scene;
    const drift_accel *accel;
    const drift_points *points;
    drift__micro_tree *tree;
    int32_t samples;
    uint32_t key;
    uint64_t rays[DRIFT_MAX_THREADS]; // per thread
} light_job;

// E kd / pi on the side of `surf` its normals face, from `samples` light samples.
static drift_vec3 reflected_direct(const light_job *job, const drift_surface *surf, drift_vec3 kd,
                                   drift_sampler *s, uint64_t *rays)
{
    drift_vec3 sum = drift_vec3_splat(0.0f);
    for (int32_t k = 0; k < job->samples; ++k) {
        float u_pick = drift_sampler_next1(s);
        drift_vec2 u = drift_sampler_next2(s);
        float pmf = 0.0f;
        uint32_t light = drift_scene_pick_light(job->scene, u_pick, &pmf);
        if (light == DRIFT_INVALID_INDEX || !(pmf > 0.0f)) {
            continue;
        }
        drift_light_sample ls = drift_light_sample_li(job->scene, light, surf->position, u);
        float cos_i = drift_vec3_dot(ls.wi, surf->ns);
        if (!(ls.pdf > 0.0f) || cos_i <= 0.0f || drift_vec3_is_zero(ls.radiance)) {
            continue;
        }
        drift_ray shadow = { .origin = drift_offset_origin(surf->position, surf->ng, ls.wi),
                             .dir = ls.wi,
                             .tmin = 0.0f,
                             .tmax =
                                 isfinite(ls.distance) ? ls.distance * (1.0f - 1e-4f) : INFINITY };
        (*rays)++;
        if (drift_accel_occluded(job->accel, &shadow)) {
            continue;
        }
        sum = drift_vec3_fma(sum, ls.radiance, cos_i / (pmf * ls.pdf));
    }
    return drift_vec3_scale(drift_vec3_mul(sum, kd), DRIFT_INV_PI / (float)job->samples);
}

static void light_range(size_t begin, size_t end, int thread, void *user)
{
    light_job *job = user;
    drift__micro_tree *tree = job->tree;
    uint32_t n = tree->leaf_count;
    for (size_t j = begin; j < end; ++j) {
        uint32_t node = n - 1 + (uint32_t)j, p = tree->point_of[j];
        const drift_scene_point *sp = &job->points->points[p];
        drift_vec3 x = job->points->position[p], nrm = job->points->normal[p];
        // The surface as a ray arriving from the front of the disc sees it.
        drift_ray ray = { drift_vec3_add(x, nrm), 0.0f, drift_vec3_neg(nrm), 2.0f, 0 };
        drift_hit hit = { .t = 1.0f,
                          .u = sp->b1,
                          .v = sp->b2,
                          .mesh = sp->mesh,
                          .prim = sp->triangle,
                          .light = DRIFT_INVALID_INDEX,
                          .ng = nrm };
        drift_surface surf = drift_scene_surface(job->scene, &ray, &hit);
        drift_vec3 kd = drift_vec3_splat(0.0f);
        if (surf.material != DRIFT_INVALID_INDEX) {
            kd = drift_bsdf_make(job->scene, &surf).diffuse;
        }
        tree->albedo[node] = kd;
        drift_vec3 front = drift_vec3_splat(0.0f), back = front;
        if (!drift_vec3_is_zero(kd)) {
            drift_sampler s = drift_sampler_make(job->key, 0, (uint32_t)j);
            // The shading normal on the side the disc's axis points to.
            if (drift_vec3_dot(surf.ng, nrm) < 0.0f) {
                surf.ng = drift_vec3_neg(surf.ng);
                surf.ns = drift_vec3_neg(surf.ns);
            }
            front = reflected_direct(job, &surf, kd, &s, &job->rays[thread]);
            surf.ng = drift_vec3_neg(surf.ng);
            surf.ns = drift_vec3_neg(surf.ns);
            back = reflected_direct(job, &surf, kd, &s, &job->rays[thread]);
        }
        tree->front[node] = front;
        tree->back[node] = back;
    }
}

uint64_t drift__micro_light_leaves(drift_context *ctx, const drift_scene *scene,
                                   const drift_accel *accel, const drift_points *points,
                                   drift__micro_tree *tree, int32_t samples, uint32_t seed)
{
    light_job job = { .scene = scene,
                      .accel = accel,
                      .points = points,
                      .tree = tree,
                      .samples = samples,
                      .key = drift_hash_combine(seed, DRIFT_MICRO_LIGHT_STREAM) };
    drift_parallel_for(ctx, tree->leaf_count, 256, light_range, &job);
    uint64_t rays = 0;
    for (int i = 0; i < DRIFT_MAX_THREADS; ++i) {
        rays += job.rays[i];
    }
    return rays;
}

// --- THE LIGHTING MODES ---

const char *drift_micro_lighting_name(drift_micro_lighting lighting)
{
    static const char *const names[DRIFT_MICRO_LIGHTING_COUNT] = { "auto", "direct", "radiosity",
                                                                   "photons" };
    return (unsigned)lighting < DRIFT_MICRO_LIGHTING_COUNT ? names[lighting] : "?";
}

void drift__micro_lighting_resolve(drift_micro_params *p)
{
    if (p->bounces == 0) {
        p->bounces = 1;
    }
    if (p->lighting == DRIFT_MICRO_LIGHTING_AUTO) {
        p->lighting = p->bounces > 1 ? DRIFT_MICRO_LIGHTING_RADIOSITY : DRIFT_MICRO_LIGHTING_DIRECT;
    }
    if (p->radiosity_size == 0) {
        p->radiosity_size = 8;
    }
    if (p->photon_count == 0) {
        p->photon_count = 1u << 18;
    }
    if (p->photon_k == 0) {
        p->photon_k = 64;
    }
}

bool drift__micro_lighting_valid(const drift_micro_params *p)
{
    // Direct light is one bounce: more with it would silently be ignored.
    return (unsigned)p->lighting < DRIFT_MICRO_LIGHTING_COUNT && p->bounces >= 1 &&
           p->bounces <= DRIFT_MICRO_MAX_BOUNCES &&
           (p->lighting != DRIFT_MICRO_LIGHTING_DIRECT || p->bounces == 1) &&
           p->radiosity_size >= 4 && p->radiosity_size <= DRIFT_MICRO_MAX_K &&
           p->photon_count >= 1 && p->photon_count <= (1u << 24) && p->photon_k >= 1 &&
           p->photon_k <= DRIFT_MICRO_MAX_PHOTON_K;
}

drift_result drift__micro_light_points(drift_context *ctx, const drift_scene *scene,
                                       const drift_accel *accel, const drift_points *points,
                                       drift__micro_tree *tree, const drift_micro_params *params,
                                       drift_micro_stats *stats)
{
    double t0 = drift_time_now();
    stats->rays += drift__micro_light_leaves(ctx, scene, accel, points, tree, params->light_samples,
                                             params->seed);
    double t1 = drift_time_now();
    drift_result r = DRIFT_OK;
    if (params->bounces > 1 && params->lighting == DRIFT_MICRO_LIGHTING_RADIOSITY) {
        // Elements of 32 leaves up to 2^14 points, then as many elements as at 2^14 (their
        // gathers cost what the final gather does, whatever the points).
        uint32_t element_leaves = tree->leaf_count / 512 > DRIFT_MICRO_RADIOSITY_LEAVES
                                      ? tree->leaf_count / 512
                                      : DRIFT_MICRO_RADIOSITY_LEAVES;
        drift__micro_radiosity_desc desc = { .accel = accel,
                                             .iterations = params->bounces - 1,
                                             .buffer_size = params->radiosity_size,
                                             .element_leaves = element_leaves };
        r = drift__micro_radiosity(ctx, tree, points, &desc, NULL, &stats->rays);
    } else if (params->bounces > 1 && params->lighting == DRIFT_MICRO_LIGHTING_PHOTONS) {
        drift__micro_photon_map map;
        drift__micro_photon_desc desc = { .paths = params->photon_count,
                                          .min_scatter = 1,
                                          .max_scatter = params->bounces - 1,
                                          .seed = params->seed };
        r = drift__micro_photons_trace(ctx, scene, accel, &desc, &map);
        if (r == DRIFT_OK) {
            stats->photons = map.count;
            stats->rays += map.rays;
            drift__micro_photons_light_leaves(ctx, &map, points, tree, params->photon_k);
            drift__micro_photons_destroy(ctx, &map);
        }
    }
    drift__micro_tree_pull(tree);
    double t2 = drift_time_now();
    stats->direct_ms = (t1 - t0) * 1e3;
    stats->bounces_ms = (t2 - t1) * 1e3;
    return r;
}
