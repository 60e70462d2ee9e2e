// drift ism (include/drift/ism.h): the object, the per-frame passes, interleaved gathering and
// the geometry-aware blur.
#include "ism/ism_internal.h"

#include <math.h>
#include <string.h>

struct drift_ism {
    drift_context *ctx;
    const drift_scene *scene;
    const drift_accel *accel;
    drift_ism_params params;
    float diagonal;
    drift_points *points;
    uint32_t max_vpls;
    uint32_t map_capacity; // VPLs the atlas and the points hold now (<= max_vpls)
    drift_vpl *vpls;
    uint32_t vpl_count;
    drift_frame *frames; // max_vpls
    float *atlas;        // map_capacity maps of map_size^2, when visibility is ISM
    float *scratch;      // one pull-push pyramid per thread
    int32_t width, height;
    drift_image irradiance, indirect, vpl_plane, tile;
    drift_ism_stats stats;
    float splat_radius; // k sqrt(A_pt / pi) of the last render, world units
    uint32_t *groups;   // group_count + 1 starts of the runs of VPLs of one bounce and round
    uint32_t group_count;
};

static const char *const stage_names[DRIFT_ISM_STAGE_COUNT] = { "vpls",      "points", "splat",
                                                                "pull_push", "gather", "blur" };

const char *drift_ism_stage_name(drift_ism_stage stage)
{
    return stage < DRIFT_ISM_STAGE_COUNT ? stage_names[stage] : NULL;
}

drift_ism_params drift_ism_params_resolve(const drift_ism_params *params, const drift_scene *scene)
{
    drift_ism_params p = params ? *params : (drift_ism_params){ 0 };
    float diag = 1.0f;
    if (scene && !drift_bounds3_is_empty(scene->bounds)) {
        diag = drift_vec3_length(drift_vec3_sub(scene->bounds.max, scene->bounds.min));
    }
    if (p.vpl_count == 0) {
        p.vpl_count = 256;
    }
    if (p.max_depth == 0) {
        p.max_depth = 2;
    }
    if (p.later_vpl_count == 0) {
        p.later_vpl_count = p.vpl_count / 4 ? p.vpl_count / 4 : 1;
    }
    if (p.later_vpl_count > p.vpl_count) {
        p.later_vpl_count = p.vpl_count;
    }
    if (p.max_path_rounds == 0) {
        p.max_path_rounds = 8;
    }
    if (p.rsm_size == 0) {
        p.rsm_size = 64;
    }
    if (p.map_size == 0) {
        p.map_size = 64;
    }
    if (p.points_per_vpl == 0) {
        p.points_per_vpl = 1024;
    }
    if (p.splat_scale == 0.0f) {
        p.splat_scale = 0.6f;
    }
    if (p.pull_push_levels == 0) {
        p.pull_push_levels = 2;
    }
    if (p.pull_push_threshold == 0.0f) {
        p.pull_push_threshold = 0.05f * diag;
    }
    if (p.depth_bias == 0.0f) {
        p.depth_bias = 0.01f * diag;
    }
    if (p.clamp_distance == 0.0f) {
        p.clamp_distance = 0.05f * diag;
    }
    if (p.block_size == 0) {
        p.block_size = 4;
    }
    if (p.blur_normal == 0.0f) {
        p.blur_normal = 0.9f;
    }
    if (p.blur_plane == 0.0f) {
        p.blur_plane = 0.01f * diag;
    }
    return p;
}

static bool params_valid(const drift_ism_params *p)
{
    return p->visibility < DRIFT_ISM_VISIBILITY_COUNT && p->vpl_count <= (1u << 20) &&
           p->max_depth >= 1 && p->max_depth <= 16 && p->max_path_rounds >= 1 &&
           p->max_path_rounds <= 64 && p->rsm_size >= 1 && p->rsm_size <= 1024 &&
           p->map_size >= 4 && p->map_size <= 1024 && p->points_per_vpl <= (1u << 20) &&
           p->splat_scale > 0.0f && p->pull_push_levels <= 7 && p->pull_push_threshold > 0.0f &&
           p->depth_bias >= 0.0f && p->clamp_distance >= 0.0f && p->block_size >= 1 &&
           p->block_size <= 64 && p->blur_normal <= 1.0f && p->blur_plane > 0.0f &&
           (uint64_t)p->points_per_vpl * drift__ism_max_vpls(p) <= (1u << 28);
}

// What one round of paths can leave: vpl_count first-bounce VPLs and later_vpl_count per
// later bounce. max_vpls also covers the extra path rounds, which most scenes never need;
// sizing the atlas and the scene points for it up front cost seconds and hundreds of MB at
// 1024 VPLs and depth 8 (14M points), so they start at one round and grow on demand.
static uint32_t initial_map_capacity(const drift_ism_params *p, uint32_t max_vpls)
{
    uint32_t bounces = p->max_depth > 1 ? (uint32_t)(p->max_depth - 1) : 0;
    uint64_t one_round = bounces ? p->vpl_count + (uint64_t)(bounces - 1) * p->later_vpl_count : 0;
    return one_round < max_vpls ? (uint32_t)one_round : max_vpls;
}

drift_result drift__ism_reserve(drift_ism *ism, uint32_t vpls)
{
    const drift_ism_params *p = &ism->params;
    if (p->visibility != DRIFT_ISM_VISIBILITY_ISM || vpls <= ism->map_capacity) {
        return DRIFT_OK;
    }
    // Grow by half at least, so that a count creeping up over frames reallocates rarely.
    uint64_t want = (uint64_t)ism->map_capacity + ism->map_capacity / 2;
    want = want > vpls ? want : vpls;
    uint32_t capacity = want < ism->max_vpls ? (uint32_t)want : ism->max_vpls;
    size_t map = (size_t)p->map_size * (size_t)p->map_size;
    float *atlas = drift_alloc(ism->ctx, (size_t)capacity * map * sizeof *atlas);
    if (!atlas) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    // Point i is Sobol sample i whatever the count, so the larger set's subsets 0..old-1 are
    // the smaller set's: growing changes no image.
    drift_points *points = NULL;
    // A scene of analytic shapes alone has no triangles to scatter points on: no occluder is
    // splatted and every VPL is taken as visible (the ISMs' points are triangle samples).
    if (p->points_per_vpl > 0 && drift_scene_triangle_count(ism->scene) > 0) {
        drift_points_desc pd = { .count = p->points_per_vpl * capacity,
                                 .subset_count = capacity,
                                 .seed = p->seed };
        drift_result r = drift_points_create(ism->ctx, ism->scene, &pd, &points);
        if (r != DRIFT_OK) {
            drift_free(ism->ctx, atlas);
            return r;
        }
    }
    drift_free(ism->ctx, ism->atlas);
    drift_points_destroy(ism->points);
    ism->atlas = atlas;
    ism->points = points;
    ism->map_capacity = capacity;
    return DRIFT_OK;
}

uint32_t drift__ism_map_capacity(const drift_ism *ism)
{
    return ism->map_capacity;
}

drift_result drift_ism_create(drift_context *ctx, const drift_scene *scene,
                              const drift_accel *accel, const drift_ism_params *params,
                              drift_ism **out_ism)
{
    *out_ism = NULL;
    if (!scene || !scene->committed || !accel) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, __FILE__, __LINE__,
                  "ism: needs a committed scene and its accel");
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    drift_ism_params p = drift_ism_params_resolve(params, scene);
    if (!params_valid(&p)) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, __FILE__, __LINE__,
                  "ism: a parameter is out of range (docs/ism.md lists them)");
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    drift_ism *ism = drift_alloc(ctx, sizeof *ism);
    if (!ism) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    ism->ctx = ctx;
    ism->scene = scene;
    ism->accel = accel;
    ism->params = p;
    ism->diagonal = drift_vec3_length(drift_vec3_sub(scene->bounds.max, scene->bounds.min));
    ism->max_vpls = drift__ism_max_vpls(&p);
    drift_result r = DRIFT_OK;
    if (ism->max_vpls > 0) {
        size_t map = (size_t)p.map_size * (size_t)p.map_size;
        ism->frames = drift_alloc(ctx, (size_t)ism->max_vpls * sizeof *ism->frames);
        ism->groups = drift_alloc(ctx, ((size_t)ism->max_vpls + 1) * sizeof *ism->groups);
        if (!ism->frames || !ism->groups) {
            r = DRIFT_ERR_OUT_OF_MEMORY;
        }
        if (r == DRIFT_OK && p.visibility == DRIFT_ISM_VISIBILITY_ISM) {
            ism->scratch =
                drift_alloc(ctx, (size_t)drift_context_thread_count(ctx) * map * sizeof(float));
            r = ism->scratch ? drift__ism_reserve(ism, initial_map_capacity(&p, ism->max_vpls))
                             : DRIFT_ERR_OUT_OF_MEMORY;
        }
    }
    if (r != DRIFT_OK) {
        drift_ism_destroy(ism);
        return r;
    }
    *out_ism = ism;
    return DRIFT_OK;
}

static void destroy_planes(drift_ism *ism)
{
    drift_image_destroy(ism->ctx, &ism->irradiance);
    drift_image_destroy(ism->ctx, &ism->indirect);
    drift_image_destroy(ism->ctx, &ism->vpl_plane);
    drift_image_destroy(ism->ctx, &ism->tile);
}

void drift_ism_destroy(drift_ism *ism)
{
    if (!ism) {
        return;
    }
    drift_context *ctx = ism->ctx;
    destroy_planes(ism);
    drift_points_destroy(ism->points);
    drift_free(ctx, ism->vpls);
    drift_free(ctx, ism->frames);
    drift_free(ctx, ism->groups);
    drift_free(ctx, ism->atlas);
    drift_free(ctx, ism->scratch);
    drift_free(ctx, ism);
}

// --- MAPS ---

typedef struct map_job {
    drift_ism *ism;
    drift__ism_splat_desc splat;
    uint32_t empty[64]; // per thread
} map_job;

static void splat_range(size_t begin, size_t end, int thread, void *user)
{
    (void)thread;
    map_job *job = user;
    drift_ism *ism = job->ism;
    size_t map = (size_t)job->splat.n * (size_t)job->splat.n;
    for (size_t j = begin; j < end; ++j) {
        float *depth = ism->atlas + j * map;
        uint32_t first = 0, count = 0;
        if (ism->points) {
            drift_points_subset(ism->points, (uint32_t)j, &first, &count);
        }
        drift__ism_splat(depth, &job->splat, ism->vpls[j].position, &ism->frames[j],
                         ism->points ? ism->points->position + first : NULL, count);
    }
}

static void pull_push_range(size_t begin, size_t end, int thread, void *user)
{
    map_job *job = user;
    drift_ism *ism = job->ism;
    int32_t n = job->splat.n;
    size_t map = (size_t)n * (size_t)n;
    for (size_t j = begin; j < end; ++j) {
        job->empty[thread % 64] += drift__ism_pull_push(
            ism->atlas + j * map, n, ism->params.pull_push_levels, ism->params.pull_push_threshold,
            ism->scratch + (size_t)thread * map);
    }
}

// --- GATHERING ---

typedef struct receiver receiver;

typedef struct gather_job {
    drift_ism *ism;
    const drift_gbuffer *gb;
    uint64_t rays[64];            // per thread
    receiver *receivers;          // receivers_per_thread for each thread
    int32_t receivers_per_thread; // one row's pixels of one subset
} gather_job;

// One receiver of a gather: a G-buffer pixel and its irradiance so far.
typedef struct receiver {
    drift_vec3 xp, n, ng; // position, shading and geometric normal
    int32_t x;
    double e[3];
} receiver;

// Adds VPLs [first, last) to each of `count` receivers. VPL-major: every receiver reads VPL j's
// map before the next map, so one map (n^2 floats) is in cache at a time. Receiver-major
// lookups touched every map of the subset per pixel (~100 maps, 1.6 MB at 1600 VPLs of 64^2):
// past the L2 cache the gather grew 6-7x for 4x the VPLs. Each receiver still sums its VPLs
// in the same order, so the image is the same to the bit.
static void gather_range(drift_ism *ism, receiver *rs, int32_t count, uint32_t first, uint32_t last,
                         uint64_t *rays)
{
    const drift_ism_params *p = &ism->params;
    float dmin2 = p->clamp_distance * p->clamp_distance;
    int32_t mn = p->map_size;
    size_t map = (size_t)mn * (size_t)mn;
    float texel = 2.0f / (float)mn;
    float splat_radius = ism->splat_radius;
    for (uint32_t j = first; j < last; ++j) {
        const drift_vpl *v = &ism->vpls[j];
        const float *depth = ism->atlas ? ism->atlas + j * map : NULL;
        for (int32_t i = 0; i < count; ++i) {
            receiver *r = &rs[i];
            drift_vec3 d = drift_vec3_sub(v->position, r->xp);
            // The facing tests first, on the unnormalised direction (about half the VPLs fail).
            float dx = drift_vec3_dot(r->n, d), dj = -drift_vec3_dot(v->normal, d);
            if (dx <= 0.0f || dj <= 0.0f) {
                continue;
            }
            float dist2 = drift_vec3_dot(d, d);
            float dist = sqrtf(dist2), inv = 1.0f / dist;
            drift_vec3 w = drift_vec3_scale(d, inv);
            float cos_x = dx * inv, cos_j = dj * inv;
            if (p->visibility == DRIFT_ISM_VISIBILITY_ISM) {
                drift_vec3 local = drift_frame_to_local(&ism->frames[j], drift_vec3_neg(w));
                float stored = depth[drift__ism_texel(mn, local)];
                // Slope-scaled: the receiver's own surface reaches the texel from as far as one
                // texel (2 (1 + v.z) / n radians) plus one splat radius (k sqrt(A_pt / pi) in
                // the world) away, over which its distance to the VPL changes by tan(theta_x)
                // times.
                float tan_x = fminf(sqrtf(fmaxf(1.0f - cos_x * cos_x, 0.0f)) / cos_x, 5.0f);
                float reach = dist * texel * (1.0f - drift_vec3_dot(v->normal, w)) + splat_radius;
                if (dist - p->depth_bias - reach * tan_x > stored) {
                    continue;
                }
            } else if (p->visibility == DRIFT_ISM_VISIBILITY_RAYS) {
                drift_vec3 o = drift_offset_origin(r->xp, r->ng, w);
                float len = drift_vec3_length(drift_vec3_sub(v->position, o));
                drift_ray ray = { o, 0.0f, w, len * 0.999f - 1e-4f * ism->diagonal };
                (*rays)++;
                if (ray.tmax > 0.0f && drift_accel_occluded(ism->accel, &ray)) {
                    continue;
                }
            }
            float g = cos_x * cos_j / fmaxf(dist2, dmin2);
            r->e[0] += (double)(v->flux.x * g);
            r->e[1] += (double)(v->flux.y * g);
            r->e[2] += (double)(v->flux.z * g);
        }
    }
}

// Irradiance (without albedo) at the pixels of one row that fall in interleaving subset k,
// from that subset's VPLs.
static void gather_subset(drift_ism *ism, const drift_gbuffer *gb, int32_t y, int32_t k_x,
                          receiver *rs, uint64_t *rays)
{
    const drift_ism_params *p = &ism->params;
    int32_t b = p->block_size, count = 0;
    for (int32_t x = k_x; x < gb->width; x += b) {
        if (drift_image_pixel(&gb->material_id, x, y)[0] < 0.0f) {
            drift_image_set3(&ism->irradiance, x, y, drift_vec3_splat(0.0f));
            continue;
        }
        rs[count++] = (receiver){ .xp = drift_image_get3(&gb->position, x, y),
                                  .n = drift_image_get3(&gb->normal, x, y),
                                  .ng = drift_image_get3(&gb->geometric_normal, x, y),
                                  .x = x };
    }
    // Subset k of the S = B^2 subsets takes the k-th run of each group of VPLs (one bounce of
    // one round of light paths). Consecutive paths are consecutive Sobol samples, so each run is
    // a stratified sample of the group (a stride of S instead would give every subset one
    // elementary interval of the light's domain). S times the subset's sum, averaged over the
    // S pixels of a block, is the sum over all VPLs.
    uint64_t subsets = (uint64_t)b * (uint64_t)b;
    uint64_t k = (uint64_t)(y % b) * (uint64_t)b + (uint64_t)k_x;
    for (uint32_t g = 0; g < ism->group_count; ++g) {
        uint64_t begin = ism->groups[g], size = (uint64_t)ism->groups[g + 1] - begin;
        uint32_t first = (uint32_t)(begin + size * k / subsets);
        uint32_t last = (uint32_t)(begin + size * (k + 1) / subsets);
        gather_range(ism, rs, count, first, last, rays);
    }
    float scale = (float)subsets * DRIFT_INV_PI;
    for (int32_t i = 0; i < count; ++i) {
        drift_image_set3(&ism->irradiance, rs[i].x, y,
                         drift_vec3_make((float)rs[i].e[0] * scale, (float)rs[i].e[1] * scale,
                                         (float)rs[i].e[2] * scale));
    }
}

static void gather_rows(size_t begin, size_t end, int thread, void *user)
{
    gather_job *job = user;
    const drift_gbuffer *gb = job->gb;
    int32_t b = job->ism->params.block_size;
    receiver *rs = job->receivers + (size_t)thread * (size_t)job->receivers_per_thread;
    for (size_t row = begin; row < end; ++row) {
        for (int32_t k_x = 0; k_x < b; ++k_x) {
            gather_subset(job->ism, gb, (int32_t)row, k_x, rs, &job->rays[thread % 64]);
        }
    }
}

// The block-sized window around each pixel, averaging only the pixels whose normal and plane
// agree with the centre's (Segovia et al. 2006), then times albedo / pi.
static void blur_rows(size_t begin, size_t end, int thread, void *user)
{
    (void)thread;
    gather_job *job = user;
    drift_ism *ism = job->ism;
    const drift_gbuffer *gb = job->gb;
    int32_t b = ism->params.no_blur ? 1 : ism->params.block_size;
    int32_t lo = -(b / 2), hi = lo + b;
    for (size_t row = begin; row < end; ++row) {
        int32_t y = (int32_t)row;
        for (int32_t x = 0; x < gb->width; ++x) {
            if (drift_image_pixel(&gb->material_id, x, y)[0] < 0.0f) {
                drift_image_set3(&ism->indirect, x, y, drift_vec3_splat(0.0f));
                continue;
            }
            drift_vec3 e = drift_image_get3(&ism->irradiance, x, y);
            if (b > 1) {
                drift_vec3 xp = drift_image_get3(&gb->position, x, y);
                drift_vec3 n = drift_image_get3(&gb->normal, x, y);
                drift_vec3 sum = drift_vec3_splat(0.0f);
                float weight = 0.0f;
                for (int32_t dy = lo; dy < hi; ++dy) {
                    int32_t yy = y + dy;
                    if (yy < 0 || yy >= gb->height) {
                        continue;
                    }
                    for (int32_t dx = lo; dx < hi; ++dx) {
                        int32_t xx = x + dx;
                        if (xx < 0 || xx >= gb->width ||
                            drift_image_pixel(&gb->material_id, xx, yy)[0] < 0.0f) {
                            continue;
                        }
                        drift_vec3 nn = drift_image_get3(&gb->normal, xx, yy);
                        drift_vec3 pp = drift_image_get3(&gb->position, xx, yy);
                        float plane = fabsf(drift_vec3_dot(n, drift_vec3_sub(pp, xp)));
                        if (drift_vec3_dot(n, nn) < ism->params.blur_normal ||
                            plane > ism->params.blur_plane) {
                            continue;
                        }
                        sum = drift_vec3_add(sum, drift_image_get3(&ism->irradiance, xx, yy));
                        weight += 1.0f;
                    }
                }
                e = weight > 0.0f ? drift_vec3_scale(sum, 1.0f / weight) : e;
            }
            drift_vec3 kd = drift_image_get3(&gb->albedo, x, y);
            drift_image_set3(&ism->indirect, x, y,
                             drift_vec3_scale(drift_vec3_mul(kd, e), DRIFT_INV_PI));
        }
    }
}

// --- FRAME ---

static drift_result ensure_planes(drift_ism *ism, int32_t w, int32_t h)
{
    if (ism->width == w && ism->height == h && ism->indirect.pixels) {
        return DRIFT_OK;
    }
    destroy_planes(ism);
    ism->width = w;
    ism->height = h;
    int32_t n = ism->params.map_size;
    if (drift_image_create(ism->ctx, w, h, 3, &ism->irradiance) != DRIFT_OK ||
        drift_image_create(ism->ctx, w, h, 3, &ism->indirect) != DRIFT_OK ||
        drift_image_create(ism->ctx, w, h, 3, &ism->vpl_plane) != DRIFT_OK ||
        drift_image_create(ism->ctx, n, n, 1, &ism->tile) != DRIFT_OK) {
        destroy_planes(ism);
        ism->width = ism->height = 0;
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    return DRIFT_OK;
}

static void diagnostic_planes(drift_ism *ism, const drift_camera *camera)
{
    memset(ism->vpl_plane.pixels, 0, (size_t)ism->width * (size_t)ism->height * 3 * sizeof(float));
    if (camera) {
        drift_camera_frame cf = drift_camera_frame_make(camera, ism->width, ism->height);
        for (uint32_t j = 0; j < ism->vpl_count; ++j) {
            drift_vec2 film;
            if (drift_camera_frame_project(&cf, ism->vpls[j].position, &film) && film.x >= 0 &&
                film.y >= 0 && film.x < (float)ism->width && film.y < (float)ism->height) {
                float *px = drift_image_pixel(&ism->vpl_plane, (int32_t)film.x, (int32_t)film.y);
                px[0] += ism->vpls[j].flux.x;
                px[1] += ism->vpls[j].flux.y;
                px[2] += ism->vpls[j].flux.z;
            }
        }
    }
    int32_t n = ism->params.map_size;
    for (int32_t i = 0; i < n * n; ++i) {
        float d = ism->atlas && ism->vpl_count > 0 ? ism->atlas[i] : INFINITY;
        ism->tile.pixels[i] = isfinite(d) ? d : 0.0f;
    }
}

drift_result drift_ism_render(drift_ism *ism, const drift_gbuffer *gbuffer,
                              const drift_camera *camera)
{
    if (!gbuffer || gbuffer->width <= 0 || gbuffer->height <= 0 || !gbuffer->position.pixels ||
        !gbuffer->normal.pixels || !gbuffer->albedo.pixels || !gbuffer->material_id.pixels ||
        !gbuffer->geometric_normal.pixels) {
        drift_log(ism->ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, __FILE__, __LINE__,
                  "ism: the G-buffer lacks a plane gathering reads");
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    drift_result r = ensure_planes(ism, gbuffer->width, gbuffer->height);
    if (r != DRIFT_OK) {
        return r;
    }
    drift_ism_stats st = { 0 };
    double t0 = drift_time_now(), t = t0, now;
    drift_free(ism->ctx, ism->vpls);
    ism->vpls = NULL;
    ism->vpl_count = 0;
    r = drift__ism_generate_vpls(ism->ctx, ism->scene, ism->accel, &ism->params, &ism->vpls,
                                 &ism->vpl_count, NULL);
    if (r != DRIFT_OK) {
        return r;
    }
    ism->group_count = 0;
    for (uint32_t j = 0; j < ism->vpl_count; ++j) {
        ism->frames[j] = drift_frame_from_normal(ism->vpls[j].normal);
        if (j == 0 || ism->vpls[j].bounce != ism->vpls[j - 1].bounce) {
            ism->groups[ism->group_count++] = j;
        }
    }
    if (ism->groups) {
        ism->groups[ism->group_count] = ism->vpl_count;
    }
    now = drift_time_now();
    st.ms[DRIFT_ISM_STAGE_VPLS] = (now - t) * 1e3;
    t = now;
    if (ism->params.visibility == DRIFT_ISM_VISIBILITY_ISM && ism->vpl_count > 0) {
        r = drift__ism_reserve(ism, ism->vpl_count);
        if (r != DRIFT_OK) {
            return r;
        }
        if (ism->points) {
            // Only the subsets of this render's VPLs are read.
            uint32_t first, count;
            drift_points_subset(ism->points, ism->vpl_count - 1, &first, &count);
            r = drift_points_update_range(ism->points, ism->scene, 0, first + count);
            if (r != DRIFT_OK) {
                return r;
            }
        }
        now = drift_time_now();
        st.ms[DRIFT_ISM_STAGE_POINTS] = (now - t) * 1e3;
        t = now;
        map_job mj = { .ism = ism };
        mj.splat.n = ism->params.map_size;
        float area_per_point =
            ism->points ? (float)(ism->points->area / (double)ism->params.points_per_vpl) : 0.0f;
        mj.splat.point_radius = sqrtf(area_per_point * DRIFT_INV_PI);
        mj.splat.splat_scale = ism->params.splat_scale;
        ism->splat_radius = mj.splat.splat_scale * mj.splat.point_radius;
        drift_parallel_for(ism->ctx, ism->vpl_count, 4, splat_range, &mj);
        st.splats = (uint64_t)ism->vpl_count * ism->params.points_per_vpl;
        now = drift_time_now();
        st.ms[DRIFT_ISM_STAGE_SPLAT] = (now - t) * 1e3;
        t = now;
        uint64_t empty = 0;
        if (ism->params.pull_push_levels > 0) {
            drift_parallel_for(ism->ctx, ism->vpl_count, 4, pull_push_range, &mj);
            for (int i = 0; i < 64; ++i) {
                empty += mj.empty[i];
            }
        } else {
            for (uint32_t j = 0; j < ism->vpl_count; ++j) {
                empty += drift__ism_pull_push(ism->atlas + (size_t)j * (size_t)mj.splat.n *
                                                               (size_t)mj.splat.n,
                                              mj.splat.n, 0, 1.0f, ism->scratch);
            }
        }
        double disc = (double)DRIFT_PI * 0.25 * (double)mj.splat.n * (double)mj.splat.n;
        st.hole_fraction = (double)empty / ((double)ism->vpl_count * disc);
        now = drift_time_now();
        st.ms[DRIFT_ISM_STAGE_PULL_PUSH] = (now - t) * 1e3;
        t = now;
    }
    gather_job gj = { .ism = ism,
                      .gb = gbuffer,
                      .receivers_per_thread =
                          (gbuffer->width + ism->params.block_size - 1) / ism->params.block_size };
    gj.receivers = drift_alloc(ism->ctx, (size_t)drift_context_thread_count(ism->ctx) *
                                             (size_t)gj.receivers_per_thread * sizeof(receiver));
    if (!gj.receivers) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    drift_parallel_for(ism->ctx, (size_t)gbuffer->height, 2, gather_rows, &gj);
    drift_free(ism->ctx, gj.receivers);
    for (int i = 0; i < 64; ++i) {
        st.shadow_rays += gj.rays[i];
    }
    now = drift_time_now();
    st.ms[DRIFT_ISM_STAGE_GATHER] = (now - t) * 1e3;
    t = now;
    drift_parallel_for(ism->ctx, (size_t)gbuffer->height, 4, blur_rows, &gj);
    now = drift_time_now();
    st.ms[DRIFT_ISM_STAGE_BLUR] = (now - t) * 1e3;
    diagnostic_planes(ism, camera);
    st.total_ms = (drift_time_now() - t0) * 1e3;
    st.vpl_count = ism->vpl_count;
    ism->stats = st;
    return DRIFT_OK;
}

const drift_image *drift_ism_indirect(const drift_ism *ism)
{
    return ism->indirect.pixels ? &ism->indirect : NULL;
}

const drift_image *drift_ism_plane_named(const drift_ism *ism, const char *name)
{
    if (!ism->indirect.pixels || !name) {
        return NULL;
    }
    if (strcmp(name, "ism.irradiance") == 0) {
        return &ism->irradiance;
    }
    if (strcmp(name, "ism.vpls") == 0) {
        return &ism->vpl_plane;
    }
    if (strcmp(name, "ism.tile") == 0 && ism->atlas) {
        return &ism->tile;
    }
    return NULL;
}

const drift_vpl *drift_ism_vpls(const drift_ism *ism, uint32_t *out_count)
{
    *out_count = ism->vpl_count;
    return ism->vpls;
}

drift_ism_stats drift_ism_get_stats(const drift_ism *ism)
{
    return ism->stats;
}

drift_ism_params drift_ism_get_params(const drift_ism *ism)
{
    return ism->params;
}
