// Photon-map lighting of the points (the thesis's Fig. 6.9 walkthrough; Jensen 1996): light
// paths traced from the lights through drift's Embree accel and scattered by the full BSDF
// (diffuse, glossy and mirror lobes), so that photons which left a mirror or a glossy surface
// and land on a diffuse one are the caustics; their flux is stored where they land after
// min_scatter..max_scatter scatterings, a kd-tree is built over them, and each leaf's disc
// gets the irradiance of its k nearest photons on each side (kd / pi E), which the tree's pull
// then carries up.
//
// Emission mirrors the path tracer's light sampling: a light picked in proportion to its power
// (drift_scene_pick_light), point and spot lights a uniform direction (of the sphere, or of
// the spot's cone), weighted by the scene's own falloff (read through drift_light_sample_li one
// unit away); area lights a uniform point and a cosine direction; directional lights and the
// environment parallel rays from a disc covering the scene. Every path's flux is divided by
// its pdf and the path count: the paths' sum is an unbiased estimate of the emitted power.
#include "micro/micro_internal.h"
#include "scene/light_path.h"

#include <math.h>
#include <string.h>

#define PHOTON_STREAM 0x6d70686fu // "mpho"

typedef struct photon_job {
    const drift_scene *scene;
    const drift_accel *accel;
    const drift__micro_photon_desc *desc;
    drift__micro_photon *slots; // paths x (max_scatter - min_scatter + 1)
    uint8_t *stored;            // 1 where a slot holds a photon
    drift_vec3 *emitted;        // per path
    uint32_t key, per_path;
    drift_vec3 centre;
    float radius;
    uint64_t rays[DRIFT_MAX_THREADS];
} photon_job;

// The first ray of a path and its flux; false when it carries nothing (point and spot lights
// in a uniform direction).
static bool emit(const photon_job *job, drift_sampler *s, drift_ray *out_ray, drift_vec3 *out_flux)
{
    return drift__light_path_emit(job->scene, s, (float)job->desc->paths, job->centre, job->radius,
                                  NULL, NULL, out_ray, out_flux);
}

static void trace_range(size_t begin, size_t end, int thread, void *user)
{
    photon_job *job = user;
    const drift__micro_photon_desc *desc = job->desc;
    uint64_t *rays = &job->rays[thread];
    for (size_t i = begin; i < end; ++i) {
        drift__micro_photon *slots = job->slots + i * job->per_path;
        uint8_t *stored = job->stored + i * job->per_path;
        memset(stored, 0, job->per_path);
        drift_sampler s = drift_sampler_make(job->key, 0, (uint32_t)i);
        drift_ray ray;
        drift_vec3 flux;
        job->emitted[i] = drift_vec3_splat(0.0f);
        if (!emit(job, &s, &ray, &flux)) {
            continue;
        }
        job->emitted[i] = flux;
        for (int32_t v = 0; v <= desc->max_scatter; ++v) {
            drift_hit hit;
            (*rays)++;
            if (!drift_accel_intersect(job->accel, &ray, &hit)) {
                break;
            }
            drift_surface surf = drift_scene_surface(job->scene, &ray, &hit);
            if (surf.material == DRIFT_INVALID_INDEX) {
                break; // a light's own shape absorbs
            }
            drift_bsdf bsdf = drift_bsdf_make(job->scene, &surf);
            if (v >= desc->min_scatter && bsdf.type != DRIFT_MATERIAL_MIRROR &&
                !drift_vec3_is_zero(bsdf.diffuse)) {
                slots[v - desc->min_scatter] =
                    (drift__micro_photon){ surf.position, surf.ng, flux };
                stored[v - desc->min_scatter] = 1;
            }
            if (v == desc->max_scatter) {
                break;
            }
            drift_vec3 wo = drift_vec3_neg(ray.dir);
            float u_lobe = drift_sampler_next1(&s);
            drift_bsdf_sample bs = drift_bsdf_sample_wi(&bsdf, wo, u_lobe, drift_sampler_next2(&s));
            if (!(bs.pdf > 0.0f) || drift_vec3_dot(bs.wi, surf.ng) <= 0.0f) {
                break;
            }
            flux = drift_vec3_mul(flux, bs.weight);
            if (drift_vec3_is_zero(flux)) {
                break;
            }
            ray = (drift_ray){ drift_offset_origin(surf.position, surf.ng, bs.wi), 0.0f, bs.wi,
                               INFINITY, 0 };
        }
    }
}

// --- KD-TREE ---

static float coord(drift_vec3 v, int a)
{
    return a == 0 ? v.x : (a == 1 ? v.y : v.z);
}

static void swap_photons(drift__micro_photon *a, drift__micro_photon *b)
{
    drift__micro_photon t = *a;
    *a = *b;
    *b = t;
}

// Quickselect: photons[k] is the one of rank k along axis a in [lo, hi), smaller ones before.
static void select_kth(drift__micro_photon *ph, uint32_t lo, uint32_t hi, uint32_t k, int a)
{
    while (hi - lo > 1) {
        uint32_t mid = lo + (hi - lo) / 2;
        // Median of three as the pivot, moved to the end.
        float x0 = coord(ph[lo].position, a), x1 = coord(ph[mid].position, a),
              x2 = coord(ph[hi - 1].position, a);
        uint32_t piv = (x0 < x1) == (x1 < x2) ? mid : ((x1 < x0) == (x0 < x2) ? lo : hi - 1);
        swap_photons(&ph[piv], &ph[hi - 1]);
        float pv = coord(ph[hi - 1].position, a);
        uint32_t store = lo;
        for (uint32_t i = lo; i + 1 < hi; ++i) {
            if (coord(ph[i].position, a) < pv) {
                swap_photons(&ph[i], &ph[store++]);
            }
        }
        swap_photons(&ph[store], &ph[hi - 1]);
        if (store == k) {
            return;
        }
        if (k < store) {
            hi = store;
        } else {
            lo = store + 1;
        }
    }
}

// The median of [lo, hi) along the axis of the range's largest extent splits it.
static void build(drift__micro_photon *ph, uint8_t *axis, uint32_t lo, uint32_t hi)
{
    while (hi - lo > 1) {
        drift_vec3 mn = ph[lo].position, mx = mn;
        for (uint32_t i = lo + 1; i < hi; ++i) {
            mn = drift_vec3_min(mn, ph[i].position);
            mx = drift_vec3_max(mx, ph[i].position);
        }
        drift_vec3 ext = drift_vec3_sub(mx, mn);
        int a = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
        uint32_t mid = lo + (hi - lo) / 2;
        select_kth(ph, lo, hi, mid, a);
        axis[mid] = (uint8_t)a;
        build(ph, axis, lo, mid);
        lo = mid + 1; // the right half by iteration
    }
    if (hi - lo == 1) {
        axis[lo] = 0;
    }
}

typedef struct knn {
    const drift__micro_photon_map *map;
    drift_vec3 x, n;
    bool both_sides; // accept photons facing n or -n (each within 60 degrees)
    int32_t k, count;
    float max_d2; // the search radius squared: the k-th's once k are found
    float d2[DRIFT_MICRO_MAX_PHOTON_K];
    uint32_t idx[DRIFT_MICRO_MAX_PHOTON_K];
} knn;

// A max-heap of the k nearest by squared distance.
static void knn_insert(knn *q, float d2, uint32_t i)
{
    int32_t c;
    if (q->count < q->k) {
        c = q->count++;
        while (c > 0 && q->d2[(c - 1) / 2] < d2) {
            q->d2[c] = q->d2[(c - 1) / 2];
            q->idx[c] = q->idx[(c - 1) / 2];
            c = (c - 1) / 2;
        }
        q->d2[c] = d2;
        q->idx[c] = i;
        if (q->count == q->k) {
            q->max_d2 = q->d2[0];
        }
        return;
    }
    // Replace the farthest and sift down.
    c = 0;
    for (;;) {
        int32_t l = 2 * c + 1, r = l + 1, big = c;
        float big_d = d2;
        if (l < q->k && q->d2[l] > big_d) {
            big = l;
            big_d = q->d2[l];
        }
        if (r < q->k && q->d2[r] > big_d) {
            big = r;
        }
        if (big == c) {
            break;
        }
        q->d2[c] = q->d2[big];
        q->idx[c] = q->idx[big];
        c = big;
    }
    q->d2[c] = d2;
    q->idx[c] = i;
    q->max_d2 = q->d2[0];
}

static void knn_search(knn *q, uint32_t lo, uint32_t hi)
{
    while (lo < hi) {
        uint32_t mid = lo + (hi - lo) / 2;
        const drift__micro_photon *p = &q->map->photons[mid];
        drift_vec3 d = drift_vec3_sub(p->position, q->x);
        float d2 = drift_vec3_dot(d, d);
        // Only photons that arrived on a surface facing the query's side.
        float c = drift_vec3_dot(p->normal, q->n);
        if (d2 < q->max_d2 && (c > 0.5f || (q->both_sides && c < -0.5f))) {
            knn_insert(q, d2, mid);
        }
        int a = q->map->axis[mid];
        float diff = coord(q->x, a) - coord(p->position, a);
        uint32_t near_lo = diff < 0.0f ? lo : mid + 1, near_hi = diff < 0.0f ? mid : hi;
        uint32_t far_lo = diff < 0.0f ? mid + 1 : lo, far_hi = diff < 0.0f ? hi : mid;
        knn_search(q, near_lo, near_hi);
        if (diff * diff >= q->max_d2) {
            return;
        }
        lo = far_lo;
        hi = far_hi;
    }
}

// The k nearest photons around x on a surface facing n (or, both_sides, n or -n): their
// flux over pi r^2 split by the side they arrived on.
static void estimate(const drift__micro_photon_map *map, drift_vec3 x, drift_vec3 n, int32_t k,
                     float max_radius, bool both_sides, drift_vec3 *out_front, drift_vec3 *out_back)
{
    *out_front = *out_back = drift_vec3_splat(0.0f);
    if (map->count == 0) {
        return;
    }
    knn q;
    q.map = map;
    q.x = x;
    q.n = n;
    q.both_sides = both_sides;
    q.k = k < 1 ? 1 : (k > DRIFT_MICRO_MAX_PHOTON_K ? DRIFT_MICRO_MAX_PHOTON_K : k);
    q.count = 0;
    q.max_d2 = isfinite(max_radius) ? max_radius * max_radius : INFINITY;
    knn_search(&q, 0, map->count);
    if (q.count == 0) {
        return;
    }
    // The k-th's distance; with fewer, the search radius (or, unbounded, the farthest found).
    float r2 = q.count == q.k || isfinite(q.max_d2) ? q.max_d2 : q.d2[0];
    if (!(r2 > 0.0f) || !isfinite(r2)) {
        return;
    }
    drift_vec3 front = drift_vec3_splat(0.0f), back = front;
    for (int32_t i = 0; i < q.count; ++i) {
        const drift__micro_photon *p = &map->photons[q.idx[i]];
        if (drift_vec3_dot(p->normal, n) > 0.0f) {
            front = drift_vec3_add(front, p->power);
        } else {
            back = drift_vec3_add(back, p->power);
        }
    }
    *out_front = drift_vec3_scale(front, 1.0f / (DRIFT_PI * r2));
    *out_back = drift_vec3_scale(back, 1.0f / (DRIFT_PI * r2));
}

drift_vec3 drift__micro_photons_irradiance(const drift__micro_photon_map *map, drift_vec3 x,
                                           drift_vec3 n, int32_t k, float max_radius)
{
    drift_vec3 front, back;
    estimate(map, x, n, k, max_radius, false, &front, &back);
    return front;
}

drift_result drift__micro_photons_trace(drift_context *ctx, const drift_scene *scene,
                                        const drift_accel *accel,
                                        const drift__micro_photon_desc *desc,
                                        drift__micro_photon_map *out_map)
{
    memset(out_map, 0, sizeof *out_map);
    if (desc->max_scatter < desc->min_scatter || desc->paths == 0) {
        return DRIFT_OK;
    }
    uint32_t per_path = (uint32_t)(desc->max_scatter - desc->min_scatter + 1);
    size_t slots_n = (size_t)desc->paths * per_path;
    photon_job *job = drift_alloc(ctx, sizeof *job);
    drift__micro_photon *slots = drift_alloc(ctx, slots_n * sizeof *slots);
    uint8_t *stored = drift_alloc(ctx, slots_n);
    drift_vec3 *emitted = drift_alloc(ctx, (size_t)desc->paths * sizeof *emitted);
    drift_result r = DRIFT_OK;
    if (!job || !slots || !stored || !emitted) {
        r = DRIFT_ERR_OUT_OF_MEMORY;
        goto done;
    }
    memset(job, 0, sizeof *job);
    // The distant lights' disc covers the reflecting geometry (as instant radiosity's).
    drift_bounds3 reach =
        drift_bounds3_is_empty(scene->reflector_bounds) ? scene->bounds : scene->reflector_bounds;
    drift_vec3 lo = reach.min, hi = reach.max;
    job->scene = scene;
    job->accel = accel;
    job->desc = desc;
    job->slots = slots;
    job->stored = stored;
    job->emitted = emitted;
    job->per_path = per_path;
    job->key = drift_hash_combine(desc->seed, PHOTON_STREAM);
    job->centre = drift_vec3_scale(drift_vec3_add(lo, hi), 0.5f);
    job->radius = 0.5f * drift_vec3_length(drift_vec3_sub(hi, lo)) * 1.01f;
    drift_parallel_for(ctx, desc->paths, 64, trace_range, job);
    // Compact in (path, scattering) order: the same map for any thread count.
    uint32_t count = 0;
    double sum[3] = { 0, 0, 0 };
    for (size_t i = 0; i < slots_n; ++i) {
        count += stored[i];
    }
    for (uint32_t i = 0; i < desc->paths; ++i) {
        sum[0] += (double)emitted[i].x;
        sum[1] += (double)emitted[i].y;
        sum[2] += (double)emitted[i].z;
    }
    out_map->emitted = drift_vec3_make((float)sum[0], (float)sum[1], (float)sum[2]);
    for (int i = 0; i < DRIFT_MAX_THREADS; ++i) {
        out_map->rays += job->rays[i];
    }
    if (count > 0) {
        out_map->photons = drift_alloc(ctx, (size_t)count * sizeof *out_map->photons);
        out_map->axis = drift_alloc(ctx, count);
        if (!out_map->photons || !out_map->axis) {
            drift__micro_photons_destroy(ctx, out_map);
            r = DRIFT_ERR_OUT_OF_MEMORY;
            goto done;
        }
        uint32_t w = 0;
        for (size_t i = 0; i < slots_n; ++i) {
            if (stored[i]) {
                out_map->photons[w++] = slots[i];
            }
        }
        out_map->count = count;
        build(out_map->photons, out_map->axis, 0, count);
    }
done:
    drift_free(ctx, job);
    drift_free(ctx, slots);
    drift_free(ctx, stored);
    drift_free(ctx, emitted);
    return r;
}

void drift__micro_photons_destroy(drift_context *ctx, drift__micro_photon_map *map)
{
    drift_free(ctx, map->photons);
    drift_free(ctx, map->axis);
    memset(map, 0, sizeof *map);
}

typedef struct leaves_job {
    const drift__micro_photon_map *map;
    const drift_points *points;
    drift__micro_tree *tree;
    int32_t k;
    float max_radius;
} leaves_job;

static void light_range(size_t begin, size_t end, int thread, void *user)
{
    (void)thread;
    leaves_job *job = user;
    drift__micro_tree *tree = job->tree;
    uint32_t n = tree->leaf_count;
    for (size_t j = begin; j < end; ++j) {
        uint32_t node = n - 1 + (uint32_t)j;
        drift_vec3 kd = tree->albedo[node];
        if (drift_vec3_is_zero(kd)) {
            continue;
        }
        // One search for both sides: a wall's dark outside costs nothing extra, and a thin
        // surface lit on both sides splits the k nearest by the side they arrived on.
        drift_vec3 ef, eb;
        estimate(job->map, tree->center[node], tree->axis[node], job->k, job->max_radius, true, &ef,
                 &eb);
        tree->front[node] = drift_vec3_fma(tree->front[node], drift_vec3_mul(kd, ef), DRIFT_INV_PI);
        tree->back[node] = drift_vec3_fma(tree->back[node], drift_vec3_mul(kd, eb), DRIFT_INV_PI);
    }
}

void drift__micro_photons_light_leaves(drift_context *ctx, const drift__micro_photon_map *map,
                                       const drift_points *points, drift__micro_tree *tree,
                                       int32_t k)
{
    // The search stops at 4x the radius that would hold k photons were they spread evenly over
    // the scene's area (pi r_leaf^2 a leaf): dark sides (a wall's outside) end early.
    float area = DRIFT_PI * tree->leaf_radius * tree->leaf_radius * (float)tree->leaf_count;
    float even = map->count > 0 ? sqrtf((float)k * area / (DRIFT_PI * (float)map->count)) : 0.0f;
    leaves_job job = { map, points, tree, k, 4.0f * even };
    drift_parallel_for(ctx, tree->leaf_count, 256, light_range, &job);
}
