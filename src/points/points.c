// Scene points (include/drift/points.h): an area-proportional triangle pick through one CDF
// over every triangle of every mesh, then a uniform point on the triangle.
#include "drift/points.h"

#include <math.h>
#include <stdatomic.h>
#include <string.h>

drift_points_desc drift_points_desc_resolve(const drift_points_desc *desc)
{
    drift_points_desc d = desc ? *desc : (drift_points_desc){ 0 };
    if (d.count == 0) {
        d.count = 65536;
    }
    if (d.subset_count == 0) {
        d.subset_count = 1;
    }
    return d;
}

static void triangle_corners(const drift_mesh *mesh, uint32_t t, drift_vec3 *a, drift_vec3 *b,
                             drift_vec3 *c)
{
    const uint32_t *tri = mesh->indices + 3 * (size_t)t;
    const float *p = mesh->positions;
    *a = drift_vec3_make(p[3 * tri[0]], p[3 * tri[0] + 1], p[3 * tri[0] + 2]);
    *b = drift_vec3_make(p[3 * tri[1]], p[3 * tri[1] + 1], p[3 * tri[1] + 2]);
    *c = drift_vec3_make(p[3 * tri[2]], p[3 * tri[2] + 1], p[3 * tri[2] + 2]);
}

static float triangle_area(const drift_mesh *mesh, uint32_t t)
{
    drift_vec3 a, b, c;
    triangle_corners(mesh, t, &a, &b, &c);
    return 0.5f * drift_vec3_length(drift_vec3_cross(drift_vec3_sub(b, a), drift_vec3_sub(c, a)));
}

static bool mesh_skipped(const drift_scene *scene, const drift_mesh *mesh, bool skip_emissive)
{
    return skip_emissive && mesh->material < scene->material_count &&
           !drift_vec3_is_zero(scene->materials[mesh->material].emission);
}

typedef struct sample_job {
    drift_points *points;
    const drift_scene *scene;
    const double *cdf;       // total_triangles + 1, normalised to [0, 1]
    const uint32_t *mesh_of; // global triangle -> mesh
    const uint32_t *first;   // mesh -> first global triangle
    const uint32_t *guide;   // guides + 1: guide[j] = the last triangle with cdf <= j / guides
    uint32_t guides;
    uint32_t total;
    uint32_t key;
    bool partial;             // some material is not opaque: points are tested for coverage
    _Atomic uint64_t *misses; // first draws that fell where no surface is
} sample_job;

// The subset of point i: begin(s) = floor(count * s / subset_count) <= i < begin(s + 1).
static uint32_t subset_of(uint64_t i, uint64_t count, uint64_t subsets, uint64_t *out_begin,
                          uint64_t *out_n)
{
    uint64_t s = i * subsets / count;
    while (s > 0 && count * s / subsets > i) {
        --s;
    }
    while (s + 1 < subsets && count * (s + 1) / subsets <= i) {
        ++s;
    }
    *out_begin = count * s / subsets;
    *out_n = count * (s + 1) / subsets - *out_begin;
    return (uint32_t)s;
}

static double unit_of(uint32_t h)
{
    return (double)h * 0x1p-32;
}

// The R2 sequence's generators (Roberts 2018): 1/phi2 and 1/phi2^2, phi2^3 = phi2 + 1.
#define R2_A1 0.7548776662466927
#define R2_A2 0.5698402909980532

// Points k0 .. k1 - 1 of subset s (points first .. first + n - 1).
// The point at u in the area CDF and (x, y) in the unit square.
static drift_scene_point draw_point(const sample_job *job, double u, double x, double y)
{
    // The guide table narrows the search to the triangles whose CDF interval meets u's
    // 1 / guides cell (the cutpoint method): O(1) reads on average, not log2(total) cache
    // misses.
    uint32_t j = (uint32_t)(u * (double)job->guides);
    j = j < job->guides ? j : job->guides - 1;
    uint32_t lo = job->guide[j], hi = job->guide[j + 1] + 1;
    hi = hi < job->total ? hi : job->total;
    while (hi - lo > 1) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (job->cdf[mid] <= u) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    while (lo + 1 < job->total && !(job->cdf[lo + 1] > job->cdf[lo])) {
        lo++;
    }
    drift_vec2 b = drift_sample_triangle(
        drift_vec2_make(fminf((float)x, 0x1.fffffep-1f), fminf((float)y, 0x1.fffffep-1f)));
    uint32_t mesh = job->mesh_of[lo];
    return (
        drift_scene_point){ .mesh = mesh, .triangle = lo - job->first[mesh], .b1 = b.x, .b2 = b.y };
}

static bool point_covered(const sample_job *job, const drift_scene_point *p, uint32_t h)
{
    return drift_scene_covers(job->scene, p->mesh, p->triangle, p->b1, p->b2,
                              (float)unit_of(drift_hash_u32(h ^ 0x5bd1e995u)));
}

// Points k0 .. k1 - 1 of subset s (points first .. first + n - 1).
static void sample_subset(const sample_job *job, uint32_t s, uint64_t first, uint64_t n,
                          uint64_t k0, uint64_t k1)
{
    uint32_t h = drift_hash_combine(job->key, s);
    double shift = unit_of(h);
    double x0 = unit_of(drift_hash_u32(h ^ 0x68bc21ebu));
    double y0 = unit_of(drift_hash_u32(h ^ 0x02e5be93u));
    uint64_t misses = 0;
    for (uint64_t k = k0; k < k1; ++k) {
        double u = ((double)k + 0.5) / (double)n + shift;
        u -= floor(u);
        double x = x0 + (double)k * R2_A1, y = y0 + (double)k * R2_A2;
        x -= floor(x);
        y -= floor(y);
        drift_scene_point p = draw_point(job, u, x, y);
        uint32_t hk = drift_hash_combine(h, (uint32_t)k);
        if (job->partial && !point_covered(job, &p, hk)) {
            // Drawn again at random (the stratification is kept by the points that were
            // there); after 16 misses the point stays where it fell.
            ++misses;
            for (uint32_t a = 1; a < 16; ++a) {
                uint32_t ha = drift_hash_combine(hk, a);
                p = draw_point(job, unit_of(drift_hash_u32(ha)),
                               unit_of(drift_hash_u32(ha ^ 0x68bc21ebu)),
                               unit_of(drift_hash_u32(ha ^ 0x02e5be93u)));
                if (point_covered(job, &p, ha)) {
                    break;
                }
            }
        }
        job->points->points[first + k] = p;
    }
    if (misses > 0) {
        atomic_fetch_add(job->misses, misses);
    }
}

// Many subsets (the ISMs' maps): a job a subset.
static void sample_subsets(size_t begin, size_t end, int thread, void *user)
{
    (void)thread;
    const sample_job *job = user;
    const uint64_t count = job->points->count, subsets = job->points->subset_count;
    for (size_t s = begin; s < end; ++s) {
        uint64_t first = count * s / subsets, n = count * (s + 1) / subsets - first;
        sample_subset(job, (uint32_t)s, first, n, 0, n);
    }
}

// Few subsets: a job a range of points.
static void sample_range(size_t begin, size_t end, int thread, void *user)
{
    (void)thread;
    const sample_job *job = user;
    const uint64_t count = job->points->count, subsets = job->points->subset_count;
    for (size_t i = begin; i < end;) {
        uint64_t first, n;
        uint32_t s = subset_of(i, count, subsets, &first, &n);
        uint64_t stop = first + n < end ? first + n : end;
        sample_subset(job, s, first, n, i - first, stop - first);
        i = (size_t)stop;
    }
}

drift_result drift_points_create(drift_context *ctx, const drift_scene *scene,
                                 const drift_points_desc *desc, drift_points **out_points)
{
    *out_points = NULL;
    drift_points_desc d = drift_points_desc_resolve(desc);
    if (!scene || !scene->committed || d.subset_count > d.count) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, __FILE__, __LINE__,
                  "points: the scene must be committed and subset_count <= count");
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    uint64_t total64 = drift_scene_triangle_count(scene);
    if (total64 == 0 || total64 >= UINT32_MAX) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, __FILE__, __LINE__,
                  "points: the scene has no triangles");
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    uint32_t total = (uint32_t)total64;
    drift_points *pts = drift_alloc(ctx, sizeof *pts);
    double *cdf = drift_alloc(ctx, ((size_t)total + 1) * sizeof *cdf);
    uint32_t *mesh_of = drift_alloc(ctx, (size_t)total * sizeof *mesh_of);
    uint32_t *first = drift_alloc(ctx, ((size_t)scene->mesh_count + 1) * sizeof *first);
    if (pts) {
        pts->ctx = ctx;
        pts->count = d.count;
        pts->subset_count = d.subset_count;
        pts->skip_emissive = d.skip_emissive;
        pts->coverage = 1.0;
        pts->points = drift_alloc(ctx, (size_t)d.count * sizeof *pts->points);
        pts->position = drift_alloc(ctx, (size_t)d.count * sizeof *pts->position);
        pts->normal = drift_alloc(ctx, (size_t)d.count * sizeof *pts->normal);
    }
    if (!pts || !cdf || !mesh_of || !first || !pts->points || !pts->position || !pts->normal) {
        drift_free(ctx, cdf);
        drift_free(ctx, mesh_of);
        drift_free(ctx, first);
        drift_points_destroy(pts);
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    uint32_t g = 0;
    double sum = 0.0;
    for (uint32_t m = 0; m < scene->mesh_count; ++m) {
        const drift_mesh *mesh = &scene->meshes[m];
        bool skip = mesh_skipped(scene, mesh, d.skip_emissive);
        first[m] = g;
        for (uint32_t t = 0; t < mesh->triangle_count; ++t, ++g) {
            cdf[g] = sum;
            mesh_of[g] = m;
            sum += skip ? 0.0 : (double)triangle_area(mesh, t);
        }
    }
    cdf[total] = sum;
    drift_result result = DRIFT_OK;
    if (!(sum > 0.0)) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, __FILE__, __LINE__,
                  "points: the scene's triangles have no area");
        result = DRIFT_ERR_INVALID_ARGUMENT;
    } else {
        for (uint32_t i = 0; i <= total; ++i) {
            cdf[i] /= sum;
        }
        uint32_t guides = total < (1u << 22) ? total : (1u << 22);
        uint32_t *guide = drift_alloc(ctx, ((size_t)guides + 1) * sizeof *guide);
        if (!guide) {
            result = DRIFT_ERR_OUT_OF_MEMORY;
        } else {
            for (uint32_t j = 0, i = 0; j <= guides; ++j) {
                double at = (double)j / (double)guides;
                while (i + 1 < total && cdf[i + 1] <= at) {
                    ++i;
                }
                guide[j] = i;
            }
            _Atomic uint64_t misses = 0;
            bool partial = false;
            for (uint32_t m = 0; m < scene->material_count; ++m) {
                partial |= scene->materials[m].alpha_mode != DRIFT_ALPHA_OPAQUE;
            }
            sample_job job = { .points = pts,
                               .scene = scene,
                               .cdf = cdf,
                               .mesh_of = mesh_of,
                               .first = first,
                               .guide = guide,
                               .guides = guides,
                               .total = total,
                               .key = drift_hash_combine(d.seed, DRIFT_POINTS_STREAM),
                               .partial = partial,
                               .misses = &misses };
            if (d.subset_count >= 64) {
                drift_parallel_for(ctx, d.subset_count, 16, sample_subsets, &job);
            } else {
                drift_parallel_for(ctx, d.count, 4096, sample_range, &job);
            }
            // The share of the sampled area where a surface is: the first draws that hit it.
            pts->coverage = 1.0 - (double)atomic_load(&misses) / (double)d.count;
            result = drift_points_update(pts, scene);
            drift_free(ctx, guide);
        }
    }
    drift_free(ctx, cdf);
    drift_free(ctx, mesh_of);
    drift_free(ctx, first);
    if (result != DRIFT_OK) {
        drift_points_destroy(pts);
        return result;
    }
    *out_points = pts;
    return DRIFT_OK;
}

void drift_points_destroy(drift_points *points)
{
    if (!points) {
        return;
    }
    drift_context *ctx = points->ctx;
    drift_free(ctx, points->points);
    drift_free(ctx, points->position);
    drift_free(ctx, points->normal);
    drift_free(ctx, points);
}

typedef struct update_job {
    drift_points *points;
    const drift_scene *scene;
    uint32_t first;
} update_job;

static void update_range(size_t begin, size_t end, int thread, void *user)
{
    (void)thread;
    const update_job *job = user;
    for (size_t i = begin + job->first; i < end + job->first; ++i) {
        const drift_scene_point *p = &job->points->points[i];
        drift_vec3 a, b, c;
        triangle_corners(&job->scene->meshes[p->mesh], p->triangle, &a, &b, &c);
        float b0 = 1.0f - p->b1 - p->b2;
        drift_vec3 x = drift_vec3_scale(a, b0);
        x = drift_vec3_fma(x, b, p->b1);
        x = drift_vec3_fma(x, c, p->b2);
        job->points->position[i] = x;
        job->points->normal[i] =
            drift_vec3_normalize(drift_vec3_cross(drift_vec3_sub(b, a), drift_vec3_sub(c, a)));
    }
}

drift_result drift_points_update(drift_points *points, const drift_scene *scene)
{
    return drift_points_update_range(points, scene, 0, points->count);
}

drift_result drift_points_update_range(drift_points *points, const drift_scene *scene,
                                       uint32_t first, uint32_t count)
{
    if (first > points->count || count > points->count - first) {
        drift_log(points->ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, __FILE__, __LINE__,
                  "points: range %u + %u past the %u points", first, count, points->count);
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    for (uint32_t i = first; i < first + count; ++i) {
        const drift_scene_point *p = &points->points[i];
        if (p->mesh >= scene->mesh_count || p->triangle >= scene->meshes[p->mesh].triangle_count) {
            drift_log(points->ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, __FILE__, __LINE__,
                      "points: point %u names a triangle the scene no longer has", i);
            return DRIFT_ERR_INVALID_ARGUMENT;
        }
    }
    double area = 0.0;
    for (uint32_t m = 0; m < scene->mesh_count; ++m) {
        if (mesh_skipped(scene, &scene->meshes[m], points->skip_emissive)) {
            continue;
        }
        for (uint32_t t = 0; t < scene->meshes[m].triangle_count; ++t) {
            area += (double)triangle_area(&scene->meshes[m], t);
        }
    }
    points->area = area * points->coverage;
    update_job job = { points, scene, first };
    drift_parallel_for(points->ctx, count, 4096, update_range, &job);
    return DRIFT_OK;
}

void drift_points_subset(const drift_points *points, uint32_t subset, uint32_t *out_begin,
                         uint32_t *out_count)
{
    uint64_t n = points->count, s = points->subset_count;
    uint64_t begin = n * subset / s, end = n * ((uint64_t)subset + 1) / s;
    *out_begin = (uint32_t)begin;
    *out_count = (uint32_t)(end - begin);
}
