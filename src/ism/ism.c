// drift ism (include/drift/ism.h): the object, the per-frame passes, interleaved gathering,
// the geometry-aware blur and the near-field compensation.
#include "core/vectorise.h"
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
    drift_frame *frames;   // max_vpls
    float *atlas;          // map_capacity maps of map_floats, when visibility is ISM
    size_t map_floats;     // one map: map_size^2 depths, then the lazy pyramid's levels
    int32_t lazy_levels;   // pull-push levels the lookups push (1, 2), or 0: pushed at build
    float *disc_counts;    // drift__ism_disc_counts of the lazy pyramid's top level
    float *scratch;        // one pull-push pyramid per thread
    int32_t width, height; // the gathering resolution (the G-buffer's / gather_scale)
    drift_image irradiance, indirect, vpl_plane, tile, near_field, near_spread;
    // gather_scale > 1: the G-buffer and the direct image at one pixel in scale^2, and the
    // blurred irradiance there (what is upsampled).
    drift_gbuffer coarse;
    drift_image coarse_direct, coarse_blurred;
    drift_ism_stats stats;
    float splat_radius; // k sqrt(A_pt / pi) of the last render, world units
    uint32_t *groups;   // group_count + 1 starts of the runs of VPLs of one bounce and round
    uint32_t group_count;
    uint64_t points_print; // vertex_fingerprint when points [0, points_valid) were derived
    uint32_t points_valid;
    bool lights_ready; // vpls and the atlas hold a render's lights (drift_ism_render_slice)
    // This render gathers run `slice` of `slices` of every group of VPLs, at slices times their
    // light (drift_ism_render_slice; 0 of 1 for drift_ism_render).
    uint32_t slice, slices;
};

static const char *const stage_names[DRIFT_ISM_STAGE_COUNT] = { "vpls",       "points",  "splat",
                                                                "pull_push",  "gather",  "blur",
                                                                "near_field", "upsample" };

const char *drift_ism_stage_name(drift_ism_stage stage)
{
    return stage < DRIFT_ISM_STAGE_COUNT ? stage_names[stage] : NULL;
}

drift_ism_params drift_ism_params_resolve(const drift_ism_params *params, const drift_scene *scene)
{
    drift_ism_params p = params ? *params : (drift_ism_params){ 0 };
    float diag = scene ? drift_scene_extent(scene) : 1.0f;
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
        // The compensation gives back what the clamp takes: a wider clamp removes more of the
        // VPLs' near-field spikes (docs/ism.md, "Near-field compensation").
        p.clamp_distance = (p.no_near_field ? 0.05f : 0.1f) * diag;
    }
    if (p.block_size == 0) {
        p.block_size = 4;
    }
    if (p.gather_scale == 0) {
        p.gather_scale = 1;
    }
    if (p.near_field_stride == 0) {
        p.near_field_stride = p.block_size % 2 == 0 ? 2 : 1;
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
           p->block_size <= 64 && p->near_field_stride >= 1 &&
           p->block_size % p->near_field_stride == 0 &&
           (p->gather_scale == 1 || p->gather_scale == 2 || p->gather_scale == 4) &&
           p->blur_normal <= 1.0f && p->blur_plane > 0.0f &&
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

// A fingerprint of every mesh's vertex positions: the points are re-derived only when it
// changes (a moving or deforming mesh), so a static frame skips the 3.4M random vertex reads
// that the Breakfast Room's 417 maps of 8192 points cost (~250 ms loaded, as much as the
// gather). 64-bit multiply-xor over the float bits, four lanes.
static uint64_t vertex_fingerprint(const drift_scene *scene)
{
    uint64_t h[4] = { 0x9e3779b97f4a7c15ull, 0xbf58476d1ce4e5b9ull, 0x94d049bb133111ebull,
                      (uint64_t)scene->mesh_count };
    for (uint32_t m = 0; m < scene->mesh_count; ++m) {
        const drift_mesh *mesh = &scene->meshes[m];
        size_t words = 3 * (size_t)mesh->vertex_count;
        const float *p = mesh->positions;
        size_t i = 0;
        for (; i + 4 <= words; i += 4) {
            for (int l = 0; l < 4; ++l) {
                uint32_t bits;
                memcpy(&bits, &p[i + (size_t)l], sizeof bits);
                h[l] = (h[l] ^ bits) * 0x100000001b3ull;
            }
        }
        for (; i < words; ++i) {
            uint32_t bits;
            memcpy(&bits, &p[i], sizeof bits);
            h[0] = (h[0] ^ bits) * 0x100000001b3ull;
        }
        h[1] =
            (h[1] ^ mesh->vertex_count ^ ((uint64_t)mesh->triangle_count << 32)) * 0x100000001b3ull;
    }
    return h[0] ^ (h[1] * 3) ^ (h[2] * 5) ^ (h[3] * 7);
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
    float *atlas = drift_alloc(ism->ctx, (size_t)capacity * ism->map_floats * sizeof *atlas);
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
    // drift_points_create derived every point from the current vertices.
    ism->points_print = points ? vertex_fingerprint(ism->scene) : 0;
    ism->points_valid = points ? points->count : 0;
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
        uint64_t points = (uint64_t)p.points_per_vpl * drift__ism_max_vpls(&p);
        if (points > (1u << 28)) {
            // The one limit a user meets by combining in-range values: say which.
            drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, __FILE__, __LINE__,
                      "ism: %u points a map x %u VPLs (the most %u paths, %u going on, can "
                      "leave in %d rounds at max depth %d) exceed 2^28 scene points; lower "
                      "the points, the VPLs or the later paths",
                      p.points_per_vpl, drift__ism_max_vpls(&p), p.vpl_count, p.later_vpl_count,
                      p.max_path_rounds, p.max_depth);
        } else {
            drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, __FILE__, __LINE__,
                      "ism: a parameter is out of range (docs/ism.md lists them)");
        }
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
    ism->diagonal = drift_scene_extent(scene);
    ism->max_vpls = drift__ism_max_vpls(&p);
    // The push is left to the lookups for the usual 1 or 2 levels (drift__ism_lookup);
    // deeper pyramids are pushed whole at build time.
    ism->lazy_levels = p.pull_push_levels == 1 || p.pull_push_levels == 2 ? p.pull_push_levels : 0;
    ism->map_floats = drift__ism_map_floats(p.map_size, ism->lazy_levels);
    drift_result r = DRIFT_OK;
    if (ism->lazy_levels > 0) {
        int32_t top = p.map_size;
        for (int32_t l = 0; l < ism->lazy_levels; ++l) {
            top = (top + 1) / 2;
        }
        ism->disc_counts = drift_alloc(ctx, (size_t)top * (size_t)top * sizeof(float));
        if (ism->disc_counts) {
            drift__ism_disc_counts(p.map_size, ism->lazy_levels, ism->disc_counts);
        } else {
            r = DRIFT_ERR_OUT_OF_MEMORY;
        }
    }
    if (ism->max_vpls > 0) {
        size_t map = (size_t)p.map_size * (size_t)p.map_size;
        ism->frames = drift_alloc(ctx, (size_t)ism->max_vpls * sizeof *ism->frames);
        ism->groups = drift_alloc(ctx, ((size_t)ism->max_vpls + 1) * sizeof *ism->groups);
        if (!ism->frames || !ism->groups) {
            r = DRIFT_ERR_OUT_OF_MEMORY;
        }
        if (r == DRIFT_OK && p.visibility == DRIFT_ISM_VISIBILITY_ISM) {
            ism->scratch =
                drift_alloc(ctx, (size_t)drift_context_thread_count(ctx) * 2 * map * sizeof(float));
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
    drift_image_destroy(ism->ctx, &ism->near_field);
    drift_image_destroy(ism->ctx, &ism->near_spread);
    drift_image_destroy(ism->ctx, &ism->coarse.depth);
    drift_image_destroy(ism->ctx, &ism->coarse.position);
    drift_image_destroy(ism->ctx, &ism->coarse.normal);
    drift_image_destroy(ism->ctx, &ism->coarse.geometric_normal);
    drift_image_destroy(ism->ctx, &ism->coarse.albedo);
    drift_image_destroy(ism->ctx, &ism->coarse.material_id);
    drift_free(ism->ctx, ism->coarse.surfaces);
    ism->coarse = (drift_gbuffer){ 0 };
    drift_image_destroy(ism->ctx, &ism->coarse_direct);
    drift_image_destroy(ism->ctx, &ism->coarse_blurred);
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
    drift_free(ctx, ism->disc_counts);
    drift_free(ctx, ism);
}

// --- MAPS ---

typedef struct map_job {
    drift_ism *ism;
    drift__ism_splat_desc splat;
    uint32_t empty[DRIFT_MAX_THREADS];    // per thread
    double seconds[DRIFT_MAX_THREADS][2]; // per thread: splatting, pull-push
} map_job;

// Splat and pull-push of one map back to back on one thread, so that the map (256 KB at 256^2)
// is still in that core's cache for pull-push: as two passes over the atlas (109 MB for the
// Breakfast Room's 417 maps of 256^2) each map went to memory and back in between.
static void maps_range(size_t begin, size_t end, int thread, void *user)
{
    map_job *job = user;
    drift_ism *ism = job->ism;
    int32_t n = job->splat.n, levels = ism->params.pull_push_levels;
    size_t map = (size_t)n * (size_t)n;
    for (size_t j = begin; j < end; ++j) {
        float *depth = ism->atlas + j * ism->map_floats;
        uint32_t first = 0, count = 0;
        if (ism->points) {
            drift_points_subset(ism->points, (uint32_t)j, &first, &count);
        }
        double t0 = drift_time_now();
        drift__ism_splat(depth, &job->splat, ism->vpls[j].position, &ism->frames[j],
                         ism->points ? ism->points->position + first : NULL, count);
        double t1 = drift_time_now();
        if (ism->lazy_levels > 0) {
            drift__ism_pull(depth, n, ism->lazy_levels, ism->params.pull_push_threshold);
            job->empty[thread] += drift__ism_holes(depth, n, ism->lazy_levels, ism->disc_counts);
        } else {
            job->empty[thread] += drift__ism_pull_push(depth, n, levels > 0 ? levels : 0,
                                                       ism->params.pull_push_threshold,
                                                       ism->scratch + (size_t)thread * 2 * map);
        }
        job->seconds[thread][0] += t1 - t0;
        job->seconds[thread][1] += drift_time_now() - t1;
    }
}

// --- GATHERING ---

// A gather job's receivers: one interleaving subset's pixels in a band of rows. Each map is
// read by all the receivers of a job, VPL after VPL, so the fewer the jobs the fewer times a
// map comes into the cache: on the Breakfast Room (640x480, 417 maps of 256^2) gathering in
// 16x16-receiver tiles cost 1.9x, bands of 12 subset rows 1.3x, 48 rows 1.0x (perf samples).
// At most this many receivers a job (3.6 MB of buffers a thread).
#define GATHER_MAX_RECEIVERS 65536

// Receivers of one gather job, structure of arrays for the vectorised loop over them.
typedef struct receivers {
    float *px, *py, *pz; // position
    float *nx, *ny, *nz; // shading normal
    float *gx, *gy, *gz; // geometric normal (the shadow rays' origin offset)
    float *er, *eg, *eb; // irradiance so far
    int32_t *x, *y;
    int32_t count;
} receivers;

typedef struct gather_job {
    drift_ism *ism;
    const drift_gbuffer *gb;
    uint64_t rays[DRIFT_MAX_THREADS]; // per thread
    float *buffers;                   // per thread: receivers_in of `capacity`
    int32_t capacity;                 // receivers a job can hold
    int32_t subset_rows; // rows of one subset in a band (a band is subset_rows * B rows)
    int32_t bands;
    bool near_field;     // the blur adds the near-field plane
    bool blur_to_coarse; // the blur writes the irradiance to coarse_blurred, not I to indirect
    float *blur_scratch; // per thread: blur_scratch_floats
} gather_job;

// The constants of one render's lookups.
typedef struct gather_consts {
    float dmin2, bias, texel, splat_radius, diagonal;
    float threshold; // pull-push's at level 0
    int32_t n;
    int32_t levels; // the levels the lookups push (drift__ism_lookup)
} gather_consts;

// A glossy VPL's lobe in the receiver loop: its axis and, for m = 2^squarings, a flag per
// squaring (1 to square, 0 to keep), so that cos^m is a fixed chain of multiplies with no
// select in the loop, which then stays vectorised.
typedef struct vpl_lobe {
    float x, y, z;
    float square[DRIFT_VPL_MAX_SQUARINGS];
} vpl_lobe;

static vpl_lobe vpl_lobe_of(const drift_vpl *v)
{
    vpl_lobe l = { .x = v->lobe.x, .y = v->lobe.y, .z = v->lobe.z };
    for (uint32_t k = 0; k < DRIFT_VPL_MAX_SQUARINGS; ++k) {
        l.square[k] = k < v->squarings ? 1.0f : 0.0f;
    }
    return l;
}

// cos^m of the angle between the lobe and the direction -a / |a| to the receiver.
static inline DRIFT_ALWAYS_INLINE float lobe_power(const vpl_lobe *l, float ax, float ay, float az,
                                                   float inv)
{
    float c = -(l->x * ax + l->y * ay + l->z * az) * inv;
    c = c > 0.0f ? c : 0.0f;
    for (uint32_t k = 0; k < DRIFT_VPL_MAX_SQUARINGS; ++k) {
        c *= 1.0f + l->square[k] * (c - 1.0f);
    }
    return c;
}

// VPL j's contribution to every receiver, visibility from its map. One loop without branches
// over the receivers (the compiler vectorises it): the facing tests, the paraboloid lookup
// and the geometry term are computed for all and masked at the end. With a = y_j - x and
// v = -a / |a| in the VPL's frame, v.xy / (1 + v.z) = -(a . t, a . b) / (|a| + c) where
// c = -a . n_j = |a| cos theta_j: the lookup needs one reciprocal, not the normalised w.
static inline DRIFT_ALWAYS_INLINE void
gather_vpl_ism_levels(const drift_vpl *v, const drift_frame *f, const float *restrict map,
                      const gather_consts *c, int32_t count, const float *restrict px,
                      const float *restrict py, const float *restrict pz, const float *restrict nx,
                      const float *restrict ny, const float *restrict nz, float *restrict er,
                      float *restrict eg, float *restrict eb, const int32_t levels,
                      const bool glossy)
{
    const float vx = v->position.x, vy = v->position.y, vz = v->position.z;
    const float mx = v->normal.x, my = v->normal.y, mz = v->normal.z;
    const float tx = f->x.x, ty = f->x.y, tz = f->x.z, bx = f->y.x, by = f->y.y, bz = f->y.z;
    const float fr = v->flux.x, fg = v->flux.y, fb = v->flux.z;
    const float half_n = 0.5f * (float)c->n, dmin2 = c->dmin2, bias = c->bias;
    const float texel = c->texel, splat_radius = c->splat_radius, threshold = c->threshold;
    const int32_t n = c->n;
    const float *l[5];
    drift__ism_levels_of(map, n, l);
    const vpl_lobe lobe = vpl_lobe_of(v);
    const float sr = v->glossy.x, sg = v->glossy.y, sb = v->glossy.z;
    DRIFT_IVDEP
    for (int32_t i = 0; i < count; ++i) {
        float ax = vx - px[i], ay = vy - py[i], az = vz - pz[i];
        float dx = nx[i] * ax + ny[i] * ay + nz[i] * az;
        float dj = -(mx * ax + my * ay + mz * az);
        float dist2 = ax * ax + ay * ay + az * az;
        dist2 = dist2 > 1e-30f ? dist2 : 1e-30f;
        float dist = sqrtf(dist2), inv = 1.0f / dist;
        float cos_x = dx * inv, cos_j = dj * inv;
        float s = 1.0f / (dist + (dj > 0.0f ? dj : 0.0f));
        float u = -(tx * ax + ty * ay + tz * az) * s, w = -(bx * ax + by * ay + bz * az) * s;
        // Texel coordinates clamped in floats first (also maps a NaN to the edge).
        float fu = (u + 1.0f) * half_n, fw = (w + 1.0f) * half_n;
        fu = fu > 0.0f ? fu : 0.0f;
        fw = fw > 0.0f ? fw : 0.0f;
        fu = fu < (float)(n - 1) ? fu : (float)(n - 1);
        fw = fw < (float)(n - 1) ? fw : (float)(n - 1);
        float stored = drift__ism_lookup_at(l[0], l[1], l[2], l[3], l[4], n, levels, threshold,
                                            (int32_t)fu, (int32_t)fw);
        // Slope-scaled: the receiver's own surface reaches the texel from as far as one texel
        // (2 (1 + v.z) / n radians) plus one splat radius (k sqrt(A_pt / pi) in the world)
        // away, over which its distance to the VPL changes by tan(theta_x) times.
        float cx = cos_x > 1e-6f ? cos_x : 1e-6f;
        float sin2 = 1.0f - cx * cx;
        float tan_x = sqrtf(sin2 > 0.0f ? sin2 : 0.0f) / cx;
        tan_x = tan_x < 5.0f ? tan_x : 5.0f;
        float reach = dist * texel * (1.0f + cos_j) + splat_radius;
        bool lit = (dx > 0.0f) & (dj > 0.0f) & (dist - bias - reach * tan_x <= stored);
        float g = cos_x * cos_j / (dist2 > dmin2 ? dist2 : dmin2);
        g = lit ? g : 0.0f;
        if (glossy) {
            float t = lobe_power(&lobe, ax, ay, az, inv) * g;
            er[i] += fr * g + sr * t;
            eg[i] += fg * g + sg * t;
            eb[i] += fb * g + sb * t;
        } else {
            er[i] += fr * g;
            eg[i] += fg * g;
            eb[i] += fb * g;
        }
    }
}

// One copy of the loop per pyramid depth and lobe, each without a branch on them (so that it
// vectorises).
#define GATHER_ISM_LEVELS(L, G, NAME)                                                              \
    DRIFT_AVX2_CLONES static void NAME(const drift_vpl *v, const drift_frame *f, const float *map, \
                                       const gather_consts *c, receivers *rs)                      \
    {                                                                                              \
        gather_vpl_ism_levels(v, f, map, c, rs->count, rs->px, rs->py, rs->pz, rs->nx, rs->ny,     \
                              rs->nz, rs->er, rs->eg, rs->eb, L, G);                               \
    }
GATHER_ISM_LEVELS(0, false, gather_vpl_ism0)
GATHER_ISM_LEVELS(1, false, gather_vpl_ism1)
GATHER_ISM_LEVELS(2, false, gather_vpl_ism2)
GATHER_ISM_LEVELS(0, true, gather_vpl_ism0_glossy)
GATHER_ISM_LEVELS(1, true, gather_vpl_ism1_glossy)
GATHER_ISM_LEVELS(2, true, gather_vpl_ism2_glossy)
#undef GATHER_ISM_LEVELS

// The same without a lookup: every facing VPL is visible.
static void gather_vpl_none(const drift_vpl *v, const gather_consts *c, int32_t count,
                            const float *restrict px, const float *restrict py,
                            const float *restrict pz, const float *restrict nx,
                            const float *restrict ny, const float *restrict nz, float *restrict er,
                            float *restrict eg, float *restrict eb)
{
    const float vx = v->position.x, vy = v->position.y, vz = v->position.z;
    const float mx = v->normal.x, my = v->normal.y, mz = v->normal.z;
    const float fr = v->flux.x, fg = v->flux.y, fb = v->flux.z, dmin2 = c->dmin2;
    const bool glossy = !drift_vec3_is_zero(v->glossy);
    const vpl_lobe lobe = vpl_lobe_of(v);
    const float sr = v->glossy.x, sg = v->glossy.y, sb = v->glossy.z;
    for (int32_t i = 0; i < count; ++i) {
        float ax = vx - px[i], ay = vy - py[i], az = vz - pz[i];
        float dx = nx[i] * ax + ny[i] * ay + nz[i] * az;
        float dj = -(mx * ax + my * ay + mz * az);
        float dist2 = ax * ax + ay * ay + az * az;
        dist2 = dist2 > 1e-30f ? dist2 : 1e-30f;
        // cos_x cos_j / max(d^2, dmin^2) = dx dj / (d^2 max(d^2, dmin^2)).
        float g = dx * dj / (dist2 * (dist2 > dmin2 ? dist2 : dmin2));
        g = ((dx > 0.0f) & (dj > 0.0f)) ? g : 0.0f;
        float t = glossy ? lobe_power(&lobe, ax, ay, az, 1.0f / sqrtf(dist2)) * g : 0.0f;
        er[i] += fr * g + sr * t;
        eg[i] += fg * g + sg * t;
        eb[i] += fb * g + sb * t;
    }
}

// The `ir` baseline: one shadow ray per facing receiver (Embree; not vectorised).
static void gather_vpl_rays(const drift_ism *ism, const drift_vpl *v, receivers *rs,
                            const gather_consts *c, uint64_t *rays)
{
    const bool glossy = !drift_vec3_is_zero(v->glossy);
    const vpl_lobe lobe = vpl_lobe_of(v);
    for (int32_t i = 0; i < rs->count; ++i) {
        drift_vec3 xp = { rs->px[i], rs->py[i], rs->pz[i] };
        drift_vec3 d = drift_vec3_sub(v->position, xp);
        float dx = rs->nx[i] * d.x + rs->ny[i] * d.y + rs->nz[i] * d.z;
        float dj = -drift_vec3_dot(v->normal, d);
        if (dx <= 0.0f || dj <= 0.0f) {
            continue;
        }
        float dist2 = drift_vec3_dot(d, d);
        float dist = sqrtf(dist2), inv = 1.0f / dist;
        drift_vec3 w = drift_vec3_scale(d, inv);
        drift_vec3 o = drift_offset_origin(xp, (drift_vec3){ rs->gx[i], rs->gy[i], rs->gz[i] }, w);
        float len = drift_vec3_length(drift_vec3_sub(v->position, o));
        drift_ray ray = { o, 0.0f, w, len * 0.999f - 1e-4f * c->diagonal };
        (*rays)++;
        if (ray.tmax > 0.0f && drift_accel_occluded(ism->accel, &ray)) {
            continue;
        }
        float g = dx * inv * dj * inv / fmaxf(dist2, c->dmin2);
        float t = glossy ? lobe_power(&lobe, d.x, d.y, d.z, inv) * g : 0.0f;
        rs->er[i] += v->flux.x * g + v->glossy.x * t;
        rs->eg[i] += v->flux.y * g + v->glossy.y * t;
        rs->eb[i] += v->flux.z * g + v->glossy.z * t;
    }
}

// Receivers in a buffer of RECEIVER_ARRAYS arrays of `cap` entries (floats, the last two int32).
#define RECEIVER_ARRAYS 14

static receivers receivers_in(float *b, size_t cap)
{
    receivers rs = { .px = b,
                     .py = b + cap,
                     .pz = b + 2 * cap,
                     .nx = b + 3 * cap,
                     .ny = b + 4 * cap,
                     .nz = b + 5 * cap,
                     .gx = b + 6 * cap,
                     .gy = b + 7 * cap,
                     .gz = b + 8 * cap,
                     .er = b + 9 * cap,
                     .eg = b + 10 * cap,
                     .eb = b + 11 * cap,
                     .x = (int32_t *)(b + 12 * cap),
                     .y = (int32_t *)(b + 13 * cap) };
    return rs;
}

static receivers job_receivers(const gather_job *job, int thread)
{
    size_t cap = (size_t)job->capacity;
    return receivers_in(job->buffers + (size_t)thread * cap * RECEIVER_ARRAYS, cap);
}

static gather_consts gather_consts_of(const drift_ism *ism)
{
    const drift_ism_params *p = &ism->params;
    return (gather_consts){ .dmin2 = p->clamp_distance * p->clamp_distance,
                            .bias = p->depth_bias,
                            .texel = 2.0f / (float)p->map_size,
                            .splat_radius = ism->splat_radius,
                            .diagonal = ism->diagonal,
                            .threshold = p->pull_push_threshold,
                            .n = p->map_size,
                            .levels = ism->lazy_levels };
}

// VPL j's irradiance added to every receiver of rs, its visibility as the params choose.
static void gather_vpl(const drift_ism *ism, uint32_t j, const gather_consts *c, receivers *rs,
                       uint64_t *rays)
{
    const drift_ism_params *p = &ism->params;
    if (p->visibility == DRIFT_ISM_VISIBILITY_ISM) {
        const float *m = ism->atlas + j * ism->map_floats;
        typedef void gather_fn(const drift_vpl *, const drift_frame *, const float *,
                               const gather_consts *, receivers *);
        static gather_fn *const gathers[2][3] = {
            { gather_vpl_ism0, gather_vpl_ism1, gather_vpl_ism2 },
            { gather_vpl_ism0_glossy, gather_vpl_ism1_glossy, gather_vpl_ism2_glossy },
        };
        bool glossy = !drift_vec3_is_zero(ism->vpls[j].glossy);
        gathers[glossy][c->levels == 2 ? 2 : c->levels == 1](&ism->vpls[j], &ism->frames[j], m, c,
                                                             rs);
    } else if (p->visibility == DRIFT_ISM_VISIBILITY_RAYS) {
        gather_vpl_rays(ism, &ism->vpls[j], rs, c, rays);
    } else {
        gather_vpl_none(&ism->vpls[j], c, rs->count, rs->px, rs->py, rs->pz, rs->nx, rs->ny, rs->nz,
                        rs->er, rs->eg, rs->eb);
    }
}

// Job = (band of rows, subset k): the band's pixels of subset k gather that subset's VPLs,
// VPL by VPL (one map in cache at a time, read by every receiver of the band), each receiver
// summing its VPLs in the same order whatever the threads.
// Run `run` of `runs` equal runs of group g's VPLs: [*first, *last). Consecutive runs tile the
// group, so summing them gathers each VPL once.
static void group_run(const drift_ism *ism, uint32_t g, uint64_t run, uint64_t runs,
                      uint32_t *first, uint32_t *last)
{
    uint64_t first_vpl = ism->groups[g], size = (uint64_t)ism->groups[g + 1] - first_vpl;
    *first = (uint32_t)(first_vpl + size * run / runs);
    *last = (uint32_t)(first_vpl + size * (run + 1) / runs);
}

static void gather_jobs(size_t begin, size_t end, int thread, void *user)
{
    gather_job *job = user;
    drift_ism *ism = job->ism;
    const drift_gbuffer *gb = job->gb;
    const drift_ism_params *p = &ism->params;
    int32_t b = p->block_size;
    uint64_t subsets = (uint64_t)b * (uint64_t)b;
    gather_consts c = gather_consts_of(ism);
    receivers rs = job_receivers(job, thread);
    for (size_t id = begin; id < end; ++id) {
        int32_t band = (int32_t)(id / subsets);
        uint64_t k = id % subsets;
        int32_t k_x = (int32_t)(k % (uint64_t)b), k_y = (int32_t)(k / (uint64_t)b);
        rs.count = 0;
        for (int32_t r = 0; r < job->subset_rows; ++r) {
            int32_t y = (band * job->subset_rows + r) * b + k_y;
            if (y >= gb->height) {
                break;
            }
            const float *mat = drift_image_pixel(&gb->material_id, 0, y);
            const float *pos = drift_image_pixel(&gb->position, 0, y);
            const float *nrm = drift_image_pixel(&gb->normal, 0, y);
            const float *geo = drift_image_pixel(&gb->geometric_normal, 0, y);
            int32_t mc = gb->material_id.channels, pc = gb->position.channels;
            int32_t nc = gb->normal.channels, gc = gb->geometric_normal.channels;
            for (int32_t x = k_x; x < gb->width; x += b) {
                if (mat[(size_t)x * (size_t)mc] < 0.0f) {
                    drift_image_set3(&ism->irradiance, x, y, drift_vec3_splat(0.0f));
                    continue;
                }
                int32_t i = rs.count++;
                const float *q = pos + (size_t)x * (size_t)pc;
                rs.px[i] = q[0], rs.py[i] = q[1], rs.pz[i] = q[2];
                q = nrm + (size_t)x * (size_t)nc;
                rs.nx[i] = q[0], rs.ny[i] = q[1], rs.nz[i] = q[2];
                q = geo + (size_t)x * (size_t)gc;
                rs.gx[i] = q[0], rs.gy[i] = q[1], rs.gz[i] = q[2];
                rs.er[i] = rs.eg[i] = rs.eb[i] = 0.0f;
                rs.x[i] = x;
                rs.y[i] = y;
            }
        }
        if (rs.count == 0) {
            continue;
        }
        // Subset k of the S = B^2 subsets takes the k-th run of each group of VPLs (one bounce
        // of one round of light paths). Consecutive paths are consecutive Sobol samples, so
        // each run is a stratified sample of the group (a stride of S instead would give
        // every subset one elementary interval of the light's domain). S times the subset's
        // sum, averaged over the S pixels of a block, is the sum over all VPLs. A slice of n
        // splits each run in n again and takes its own part, at n times the light.
        uint64_t runs = subsets * ism->slices, run = k * ism->slices + ism->slice;
        for (uint32_t g = 0; g < ism->group_count; ++g) {
            uint32_t first, last;
            group_run(ism, g, run, runs, &first, &last);
            for (uint32_t j = first; j < last; ++j) {
                gather_vpl(ism, j, &c, &rs, &job->rays[thread]);
            }
        }
        float scale = (float)runs * DRIFT_INV_PI;
        for (int32_t i = 0; i < rs.count; ++i) {
            drift_image_set3(&ism->irradiance, rs.x[i], rs.y[i],
                             drift_vec3_make(rs.er[i] * scale, rs.eg[i] * scale, rs.eb[i] * scale));
        }
    }
}

// The block-sized window of `in` around (x, y), averaging only the pixels whose normal and plane
// agree with the centre's (Segovia et al. 2006): the blur's rule at one pixel.
static drift_vec3 block_average(const drift_ism *ism, const drift_gbuffer *gb,
                                const drift_image *in, int32_t x, int32_t y)
{
    int32_t b = ism->params.no_blur ? 1 : ism->params.block_size;
    drift_vec3 e = drift_image_get3(in, x, y);
    if (b <= 1) {
        return e;
    }
    int32_t lo = -(b / 2), hi = lo + b;
    float blur_normal = ism->params.blur_normal, blur_plane = ism->params.blur_plane;
    const drift_image *mat = &gb->material_id, *pos = &gb->position, *nrm = &gb->normal;
    int32_t y0 = y + lo < 0 ? 0 : y + lo, y1 = y + hi > gb->height ? gb->height : y + hi;
    int32_t x0 = x + lo < 0 ? 0 : x + lo, x1 = x + hi > gb->width ? gb->width : x + hi;
    const float *c = drift_image_pixel(pos, x, y), *cn = drift_image_pixel(nrm, x, y);
    float sr = 0.0f, sg = 0.0f, sb = 0.0f, weight = 0.0f;
    for (int32_t yy = y0; yy < y1; ++yy) {
        const float *m = drift_image_pixel(mat, 0, yy);
        const float *pp = drift_image_pixel(pos, 0, yy);
        const float *nn = drift_image_pixel(nrm, 0, yy);
        const float *ee = drift_image_pixel(in, 0, yy);
        for (int32_t xx = x0; xx < x1; ++xx) {
            const float *q = pp + (size_t)xx * (size_t)pos->channels;
            const float *qn = nn + (size_t)xx * (size_t)nrm->channels;
            float plane =
                fabsf(cn[0] * (q[0] - c[0]) + cn[1] * (q[1] - c[1]) + cn[2] * (q[2] - c[2]));
            float cosn = cn[0] * qn[0] + cn[1] * qn[1] + cn[2] * qn[2];
            if (m[(size_t)xx * (size_t)mat->channels] < 0.0f || cosn < blur_normal ||
                plane > blur_plane) {
                continue;
            }
            const float *qe = ee + (size_t)xx * (size_t)in->channels;
            sr += qe[0];
            sg += qe[1];
            sb += qe[2];
            weight += 1.0f;
        }
    }
    return weight > 0.0f ? drift_vec3_make(sr / weight, sg / weight, sb / weight) : e;
}

// The blur over rows as structure of arrays, so that each offset of the window is one loop
// over x that vectorises: a row's positions, normals, a mask of the pixels with a surface, and
// the irradiance (plus the near-field compensation's). block_average's rule, whole rows at a
// time.
typedef struct blur_row {
    float *px, *py, *pz, *nx, *ny, *nz, *surface, *er, *eg, *eb;
} blur_row;

#define BLUR_ROW_ARRAYS 10
// Rows a job blurs: its copies hold b - 1 rows more (<= 64 + 3 with block_size <= 64).
#define BLUR_JOB_ROWS 4

// Floats of one thread's blur scratch: the row copies of a job and four sums a pixel.
static size_t blur_scratch_floats(int32_t width, int32_t block_size)
{
    return (size_t)width * ((size_t)(BLUR_JOB_ROWS + block_size - 1) * BLUR_ROW_ARRAYS + 4);
}

static void blur_copy_row(const drift_ism *ism, const drift_gbuffer *gb, bool near_field, int32_t y,
                          const blur_row *r)
{
    const float *p = drift_image_pixel(&gb->position, 0, y);
    const float *n = drift_image_pixel(&gb->normal, 0, y);
    const float *m = drift_image_pixel(&gb->material_id, 0, y);
    const float *e = drift_image_pixel(&ism->irradiance, 0, y);
    const float *f = drift_image_pixel(&ism->near_spread, 0, y);
    for (int32_t x = 0; x < gb->width; ++x, p += 3, n += 3, e += 3, f += 3) {
        r->px[x] = p[0];
        r->py[x] = p[1];
        r->pz[x] = p[2];
        r->nx[x] = n[0];
        r->ny[x] = n[1];
        r->nz[x] = n[2];
        r->surface[x] = m[x] < 0.0f ? 0.0f : 1.0f;
        r->er[x] = near_field ? e[0] + f[0] : e[0];
        r->eg[x] = near_field ? e[1] + f[1] : e[1];
        r->eb[x] = near_field ? e[2] + f[2] : e[2];
    }
}

// Adds the pixels of row q at offset dx that pass the centres' tests (row c) to the sums of
// centres x0..x1-1.
DRIFT_AVX2_CLONES static void blur_accumulate(const blur_row *c, const blur_row *q, int32_t x0,
                                              int32_t x1, int32_t dx, float blur_normal,
                                              float blur_plane, float *restrict sr,
                                              float *restrict sg, float *restrict sb,
                                              float *restrict weight)
{
    const float *restrict cpx = c->px, *restrict cpy = c->py, *restrict cpz = c->pz;
    const float *restrict cnx = c->nx, *restrict cny = c->ny, *restrict cnz = c->nz;
    const float *restrict qpx = q->px + dx, *restrict qpy = q->py + dx, *restrict qpz = q->pz + dx;
    const float *restrict qnx = q->nx + dx, *restrict qny = q->ny + dx, *restrict qnz = q->nz + dx;
    const float *restrict qs = q->surface + dx, *restrict qr = q->er + dx;
    const float *restrict qg = q->eg + dx, *restrict qb = q->eb + dx;
    DRIFT_IVDEP
    for (int32_t x = x0; x < x1; ++x) {
        float d =
            cnx[x] * (qpx[x] - cpx[x]) + cny[x] * (qpy[x] - cpy[x]) + cnz[x] * (qpz[x] - cpz[x]);
        float cosn = cnx[x] * qnx[x] + cny[x] * qny[x] + cnz[x] * qnz[x];
        // block_average's tests without branches (& not &&), so that the loop vectorises.
        bool keep =
            (qs[x] != 0.0f) & (cosn >= blur_normal) & (d <= blur_plane) & (-d <= blur_plane);
        sr[x] += keep ? qr[x] : 0.0f;
        sg[x] += keep ? qg[x] : 0.0f;
        sb[x] += keep ? qb[x] : 0.0f;
        weight[x] += keep ? 1.0f : 0.0f;
    }
}

// I = kd / pi times the block average of the irradiance and the near-field compensation's,
// rows begin..end-1 of one job.
static void blur_rows(size_t begin, size_t end, int thread, void *user)
{
    gather_job *job = user;
    drift_ism *ism = job->ism;
    const drift_gbuffer *gb = job->gb;
    int32_t w = gb->width, b = ism->params.no_blur ? 1 : ism->params.block_size;
    int32_t lo = -(b / 2), hi = lo + b;
    int32_t first = (int32_t)begin + lo < 0 ? 0 : (int32_t)begin + lo;
    int32_t last = (int32_t)end - 1 + hi > gb->height ? gb->height : (int32_t)end - 1 + hi;
    int32_t rows = last - first;
    float *scratch = job->blur_scratch + (size_t)thread * blur_scratch_floats(w, b);
    blur_row soa[64 + 3];
    for (int32_t i = 0; i < rows; ++i) {
        float *a = scratch + (size_t)i * BLUR_ROW_ARRAYS * (size_t)w;
        soa[i] = (blur_row){ a,         a + w,     a + 2 * w, a + 3 * w, a + 4 * w,
                             a + 5 * w, a + 6 * w, a + 7 * w, a + 8 * w, a + 9 * w };
        blur_copy_row(ism, gb, job->near_field, first + i, &soa[i]);
    }
    float *sums = scratch + (size_t)rows * BLUR_ROW_ARRAYS * (size_t)w;
    float *sr = sums, *sg = sums + w, *sb = sums + 2 * w, *weight = sums + 3 * w;
    float blur_normal = ism->params.blur_normal, blur_plane = ism->params.blur_plane;
    for (size_t row = begin; row < end; ++row) {
        int32_t y = (int32_t)row;
        const blur_row *c = &soa[y - first];
        memset(sums, 0, sizeof(float) * 4 * (size_t)w);
        int32_t y0 = y + lo < 0 ? 0 : y + lo, y1 = y + hi > gb->height ? gb->height : y + hi;
        for (int32_t yy = y0; yy < y1; ++yy) {
            for (int32_t dx = lo; dx < hi; ++dx) {
                int32_t x0 = dx < 0 ? -dx : 0, x1 = dx > 0 ? w - dx : w;
                blur_accumulate(c, &soa[yy - first], x0, x1, dx, blur_normal, blur_plane, sr, sg,
                                sb, weight);
            }
        }
        for (int32_t x = 0; x < w; ++x) {
            drift_vec3 e = drift_vec3_splat(0.0f);
            if (c->surface[x] != 0.0f) {
                e = weight[x] > 0.0f
                        ? drift_vec3_make(sr[x] / weight[x], sg[x] / weight[x], sb[x] / weight[x])
                        : drift_vec3_make(c->er[x], c->eg[x], c->eb[x]);
            }
            if (job->blur_to_coarse) {
                drift_image_set3(&ism->coarse_blurred, x, y, e);
                continue;
            }
            drift_vec3 kd = drift_image_get3(&gb->albedo, x, y);
            drift_image_set3(&ism->indirect, x, y,
                             drift_vec3_scale(drift_vec3_mul(kd, e), DRIFT_INV_PI));
        }
    }
}

// --- NEAR-FIELD COMPENSATION ---
//
// The clamp d_min in the geometry term keeps a VPL next to a receiver from painting a spike, and
// takes away the light that nearby surfaces really send (corners, contact, a wall beside a sunlit
// floor). Written over directions, the clamped gather is
//   E_clamped(x) = integral of L_o(y(w)) cos(theta_x) min(1, d^2 / d_min^2) dw,
// so the part it misses is the same integral with max(0, 1 - d^2 / d_min^2): zero beyond d_min.
// A cosine ray at most d_min long estimates it as pi L_o(y) (1 - d^2 / d_min^2) (Kollig and
// Keller 2004's bias compensation, cut to one bounce). L_o(y) is read off the frame where the
// hit is the surface a pixel sees (its direct radiance plus the clamped indirect light just
// gathered; Novak et al. 2011 compensate in screen space alone); a hit the camera does not see
// adds nothing. One pixel in stride x stride shoots (a quarter by default: 1 ray a pixel cost
// 3x as much for 0.001-0.003 FLIP), a block's rays take stratified directions, each shooting
// pixel takes the mean of the 5 x 5 shooting pixels around it that pass the blur's tests, and
// the block average blurs those with the VPLs' subsets.

typedef struct near_field_job {
    drift_ism *ism;
    const drift_gbuffer *gb;
    drift_camera_frame camera;
    const drift_image *direct;
    float dmin;
    uint32_t seed;
    uint64_t rays[DRIFT_MAX_THREADS]; // per thread
} near_field_job;

// Shooting pixels a side, either way, that near_field_spread_rows averages: 2 spreads a block's
// 4 rays over 25 blocks' worth, 0.001-0.003 FLIP on the four frontier scenes for ~1-4 ms.
#define NEAR_FIELD_SPREAD 2

// L_o of hit point p, read off the frame: the pixel p projects to must see p itself (its depth
// within 2%, its normal facing the ray that found p). False where the camera does not see p.
static bool frame_radiance(const near_field_job *job, drift_vec3 p, drift_vec3 dir, drift_vec3 *out)
{
    const drift_gbuffer *gb = job->gb;
    drift_vec2 film;
    if (!drift_camera_frame_project(&job->camera, p, &film) || !(film.x >= 0.0f) ||
        !(film.y >= 0.0f) || film.x >= (float)gb->width || film.y >= (float)gb->height) {
        return false;
    }
    int32_t qx = (int32_t)film.x, qy = (int32_t)film.y;
    if (drift_image_pixel(&gb->material_id, qx, qy)[0] < 0.0f) {
        return false;
    }
    float seen = drift_image_pixel(&gb->depth, qx, qy)[0];
    float depth = drift_vec3_dot(drift_vec3_sub(p, job->camera.camera.position), job->camera.w);
    const float *n = drift_image_pixel(&gb->normal, qx, qy);
    if (!(fabsf(seen - depth) < 0.02f * depth) ||
        n[0] * dir.x + n[1] * dir.y + n[2] * dir.z >= 0.0f) {
        return false;
    }
    *out = drift_image_get3(job->direct, qx, qy);
    if (job->ism->params.max_depth > 2) {
        // Paths of max_depth 2 bounce once: p sends its direct light alone. Deeper ones add the
        // indirect light gathered at p (all of its bounces: one more than max_depth allows).
        drift_vec3 kd = drift_image_get3(&gb->albedo, qx, qy);
        drift_vec3 e = block_average(job->ism, gb, &job->ism->irradiance, qx, qy);
        *out = drift_vec3_fma(*out, drift_vec3_mul(kd, e), DRIFT_INV_PI);
    }
    return true;
}

static void near_field_rows(size_t begin, size_t end, int thread, void *user)
{
    near_field_job *job = user;
    drift_ism *ism = job->ism;
    const drift_gbuffer *gb = job->gb;
    int32_t b = ism->params.block_size;
    // One ray per stride x stride pixels, weighed by stride^2: the block's B^2 / stride^2 rays
    // stratify its hemisphere.
    int32_t stride = ism->params.near_field_stride;
    int32_t per_side = b / stride;
    uint32_t directions = (uint32_t)(per_side * per_side);
    float weight = DRIFT_PI * (float)(stride * stride);
    for (size_t row = begin; row < end; ++row) {
        int32_t y = (int32_t)row, by = y / b, ky = y % b, bx = 0, kx = 0;
        for (int32_t x = 0; x < gb->width; ++x, kx = kx + 1 < b ? kx + 1 : (++bx, 0)) {
            drift_vec3 e = drift_vec3_splat(0.0f);
            const drift_surface *s = &gb->surfaces[(size_t)y * (size_t)gb->width + (size_t)x];
            if (s->material == DRIFT_INVALID_INDEX || kx % stride || ky % stride) {
                drift_image_set3(&ism->near_field, x, y, e);
                continue;
            }
            // Direction k of the block's set, the set shifted block by block.
            uint32_t k = (uint32_t)((ky / stride) * per_side + kx / stride);
            uint32_t h = drift_hash_combine(job->seed, (uint32_t)by * 65536u + (uint32_t)bx);
            drift_vec2 shift =
                drift_vec2_make((float)(h & 0xffffu) * 0x1p-16f, (float)(h >> 16) * 0x1p-16f);
            drift_frame frame = drift_frame_from_normal(s->ns);
            drift_vec3 dir = drift_frame_to_world(
                &frame,
                drift_sample_cosine_hemisphere(drift_hammersley_shifted(k, directions, shift)));
            drift_hit hit;
            drift_vec3 lo;
            if (drift_vec3_dot(dir, s->ng) > 0.0f) {
                drift_ray ray = { .origin = drift_offset_origin(s->position, s->ng, dir),
                                  .dir = dir,
                                  .tmin = 0.0f,
                                  .tmax = job->dmin };
                ++job->rays[thread];
                // Emitters are the direct light's; only a reflecting surface is near-field light.
                if (drift_accel_intersect(ism->accel, &ray, &hit) &&
                    hit.mesh != DRIFT_INVALID_INDEX && hit.light == DRIFT_INVALID_INDEX &&
                    frame_radiance(job, drift_vec3_fma(ray.origin, dir, hit.t), dir, &lo)) {
                    float falloff = 1.0f - (hit.t * hit.t) / (job->dmin * job->dmin);
                    e = drift_vec3_scale(lo, weight * fmaxf(falloff, 0.0f));
                }
            }
            drift_image_set3(&ism->near_field, x, y, e);
        }
    }
}

// The near field's few rays a block, spread wider than the block: at each pixel that shot, the
// mean of the (2 r + 1)^2 shooting pixels around it that pass the blur's tests (the block
// average then blurs these means as it blurs the VPLs' subsets).
static void near_field_spread_rows(size_t begin, size_t end, int thread, void *user)
{
    (void)thread;
    near_field_job *job = user;
    drift_ism *ism = job->ism;
    const drift_gbuffer *gb = job->gb;
    int32_t stride = ism->params.near_field_stride, r = NEAR_FIELD_SPREAD;
    float blur_normal = ism->params.blur_normal, blur_plane = ism->params.blur_plane;
    for (size_t row = begin; row < end; ++row) {
        int32_t y = (int32_t)row;
        for (int32_t x = 0; x < gb->width; ++x) {
            drift_vec3 sum = drift_vec3_splat(0.0f);
            float weight = 0.0f;
            if (y % stride == 0 && x % stride == 0 &&
                drift_image_pixel(&gb->material_id, x, y)[0] >= 0.0f) {
                const float *c = drift_image_pixel(&gb->position, x, y);
                const float *cn = drift_image_pixel(&gb->normal, x, y);
                for (int32_t v = y - r * stride; v <= y + r * stride; v += stride) {
                    for (int32_t u = x - r * stride; u <= x + r * stride; u += stride) {
                        if (u < 0 || v < 0 || u >= gb->width || v >= gb->height ||
                            drift_image_pixel(&gb->material_id, u, v)[0] < 0.0f) {
                            continue;
                        }
                        const float *q = drift_image_pixel(&gb->position, u, v);
                        const float *qn = drift_image_pixel(&gb->normal, u, v);
                        float d =
                            cn[0] * (q[0] - c[0]) + cn[1] * (q[1] - c[1]) + cn[2] * (q[2] - c[2]);
                        float cosn = cn[0] * qn[0] + cn[1] * qn[1] + cn[2] * qn[2];
                        if (cosn < blur_normal || fabsf(d) > blur_plane) {
                            continue;
                        }
                        sum = drift_vec3_add(sum, drift_image_get3(&ism->near_field, u, v));
                        weight += 1.0f;
                    }
                }
            }
            drift_image_set3(&ism->near_spread, x, y,
                             weight > 0.0f ? drift_vec3_scale(sum, 1.0f / weight) : sum);
        }
    }
}

static void add_near_field(drift_ism *ism, const drift_gbuffer *gb, const drift_camera *camera,
                           const drift_image *direct, drift_ism_stats *st)
{
    near_field_job job = { .ism = ism,
                           .gb = gb,
                           .camera = drift_camera_frame_make(camera, gb->width, gb->height),
                           .direct = direct,
                           .dmin = ism->params.clamp_distance,
                           .seed = drift_hash_combine(ism->params.seed, 0x4e454152u) };
    drift_parallel_for(ism->ctx, (size_t)gb->height, 4, near_field_rows, &job);
    drift_parallel_for(ism->ctx, (size_t)gb->height, 4, near_field_spread_rows, &job);
    for (int i = 0; i < DRIFT_MAX_THREADS; ++i) {
        st->near_field_rays += job.rays[i];
    }
}

// --- GATHERING AT A LOWER RESOLUTION (gather_scale > 1) ---
//
// Indirect diffuse light is smooth where the surface is. One pixel in s x s gathers, with the
// interleaving, the blur and the near-field compensation run at that resolution (a block's
// window then spans s^2 times the pixels), and every pixel takes the irradiance of its four
// nearest gathering pixels that pass the blur's tests against it, weighed bilinearly (or of
// those of the twelve around them that do); the albedo is its own. The thesis upsamples
// micro-rendering's gathers so (§6.2.4, with Sloan et al. 2007's weights; the blur's tests keep ISM
// to one rule). A pixel none of the 16 passes (a chair's leg, a leaf, a silhouette's rim) gathers
// every VPL itself, as §6.2.4's extra pass does: exact there, and few (stats.fallback_pixels). It
// takes no near-field compensation.

// The G-buffer pixel gathering pixel i stands for: its s x s cell's centre.
static int32_t cell_pixel(int32_t i, int32_t s, int32_t full)
{
    int32_t v = i * s + s / 2;
    return v < full ? v : full - 1;
}

static void copy_pixel(const drift_image *from, int32_t x, int32_t y, drift_image *to, int32_t i,
                       int32_t j)
{
    if (from->pixels) {
        memcpy(drift_image_pixel(to, i, j), drift_image_pixel(from, x, y),
               sizeof(float) * (size_t)to->channels);
    }
}

typedef struct decimate_job {
    drift_ism *ism;
    const drift_gbuffer *gb;
    const drift_image *direct; // NULL without the near field
} decimate_job;

static void decimate_rows(size_t begin, size_t end, int thread, void *user)
{
    (void)thread;
    const decimate_job *job = user;
    drift_ism *ism = job->ism;
    const drift_gbuffer *gb = job->gb;
    drift_gbuffer *c = &ism->coarse;
    int32_t s = ism->params.gather_scale;
    for (size_t row = begin; row < end; ++row) {
        int32_t j = (int32_t)row, y = cell_pixel(j, s, gb->height);
        for (int32_t i = 0; i < c->width; ++i) {
            int32_t x = cell_pixel(i, s, gb->width);
            size_t from = (size_t)y * (size_t)gb->width + (size_t)x;
            c->surfaces[(size_t)j * (size_t)c->width + (size_t)i] =
                gb->surfaces ? gb->surfaces[from]
                             : (drift_surface){ .material = DRIFT_INVALID_INDEX };
            copy_pixel(&gb->depth, x, y, &c->depth, i, j);
            copy_pixel(&gb->position, x, y, &c->position, i, j);
            copy_pixel(&gb->normal, x, y, &c->normal, i, j);
            copy_pixel(&gb->geometric_normal, x, y, &c->geometric_normal, i, j);
            copy_pixel(&gb->albedo, x, y, &c->albedo, i, j);
            copy_pixel(&gb->material_id, x, y, &c->material_id, i, j);
            if (job->direct) {
                drift_image_set3(&ism->coarse_direct, i, j, drift_image_get3(job->direct, x, y));
            }
        }
    }
}

typedef struct upsample_job {
    drift_ism *ism;
    const drift_gbuffer *gb;
    uint8_t *fallback;                // per G-buffer pixel: 1 where it must gather itself
    uint64_t rays[DRIFT_MAX_THREADS]; // per thread, the fallback's `ir` rays
    const uint32_t *fallback_pixels;
    size_t fallback_count;
    size_t job_pixels;       // receivers of one fallback job
    float *receiver_buffers; // per thread: receivers_in of job_pixels
} upsample_job;

static void upsample_rows(size_t begin, size_t end, int thread, void *user)
{
    (void)thread;
    upsample_job *job = user;
    drift_ism *ism = job->ism;
    const drift_gbuffer *gb = job->gb, *c = &ism->coarse;
    int32_t s = ism->params.gather_scale;
    float blur_normal = ism->params.blur_normal, blur_plane = ism->params.blur_plane;
    for (size_t row = begin; row < end; ++row) {
        int32_t y = (int32_t)row;
        float fy = ((float)y - (float)(s / 2)) / (float)s;
        int32_t j0 = (int32_t)floorf(fy);
        float wy = fy - (float)j0;
        for (int32_t x = 0; x < gb->width; ++x) {
            size_t index = (size_t)y * (size_t)gb->width + (size_t)x;
            drift_vec3 e = drift_vec3_splat(0.0f);
            job->fallback[index] = 0;
            if (drift_image_pixel(&gb->material_id, x, y)[0] >= 0.0f) {
                const float *p = drift_image_pixel(&gb->position, x, y);
                const float *n = drift_image_pixel(&gb->normal, x, y);
                float fx = ((float)x - (float)(s / 2)) / (float)s;
                int32_t i0 = (int32_t)floorf(fx);
                float wx = fx - (float)i0, total = 0.0f;
                // The four nearest, bilinearly; where none passes, the ring of twelve around
                // them alike (a thin object's pixels are some gathering pixel's in the ring).
                for (int32_t k = 0; k < 16 && !(k == 4 && total > 0.0f); ++k) {
                    static const int8_t ring[12][2] = {
                        { -1, -1 }, { 0, -1 }, { 1, -1 }, { 2, -1 }, { -1, 0 }, { 2, 0 },
                        { -1, 1 },  { 2, 1 },  { -1, 2 }, { 0, 2 },  { 1, 2 },  { 2, 2 }
                    };
                    int32_t i = i0 + (k < 4 ? (k & 1) : ring[k - 4][0]);
                    int32_t j = j0 + (k < 4 ? (k >> 1) : ring[k - 4][1]);
                    if (i < 0 || j < 0 || i >= c->width || j >= c->height ||
                        drift_image_pixel(&c->material_id, i, j)[0] < 0.0f) {
                        continue;
                    }
                    const float *q = drift_image_pixel(&c->position, i, j);
                    const float *qn = drift_image_pixel(&c->normal, i, j);
                    float d = n[0] * (q[0] - p[0]) + n[1] * (q[1] - p[1]) + n[2] * (q[2] - p[2]);
                    float cosn = n[0] * qn[0] + n[1] * qn[1] + n[2] * qn[2];
                    if (cosn < blur_normal || fabsf(d) > blur_plane) {
                        continue;
                    }
                    // A little weight even where the bilinear one is 0: a pixel on a gathering
                    // pixel's row still reads the next row when its own fails the tests.
                    float w = k < 4
                                  ? ((k & 1) ? wx : 1.0f - wx) * ((k >> 1) ? wy : 1.0f - wy) + 1e-3f
                                  : 1.0f;
                    e = drift_vec3_fma(e, drift_image_get3(&ism->coarse_blurred, i, j), w);
                    total += w;
                }
                if (total > 0.0f) {
                    e = drift_vec3_scale(e, 1.0f / total);
                } else {
                    job->fallback[index] = 1;
                }
            }
            drift_vec3 kd = drift_image_get3(&gb->albedo, x, y);
            drift_image_set3(&ism->indirect, x, y,
                             drift_vec3_scale(drift_vec3_mul(kd, e), DRIFT_INV_PI));
        }
    }
}

// A fallback job's receivers read every VPL's map once: as few jobs as keep the threads busy.
static void fallback_jobs(size_t begin, size_t end, int thread, void *user)
{
    upsample_job *job = user;
    drift_ism *ism = job->ism;
    const drift_gbuffer *gb = job->gb;
    gather_consts c = gather_consts_of(ism);
    size_t cap = job->job_pixels;
    float *b = job->receiver_buffers + (size_t)thread * cap * RECEIVER_ARRAYS;
    for (size_t id = begin; id < end; ++id) {
        size_t first = id * cap;
        size_t last = first + cap < job->fallback_count ? first + cap : job->fallback_count;
        receivers rs = receivers_in(b, cap);
        for (size_t k = first; k < last; ++k) {
            int32_t i = rs.count++;
            int32_t x = (int32_t)(job->fallback_pixels[k] % (uint32_t)gb->width);
            int32_t y = (int32_t)(job->fallback_pixels[k] / (uint32_t)gb->width);
            const float *q = drift_image_pixel(&gb->position, x, y);
            rs.px[i] = q[0], rs.py[i] = q[1], rs.pz[i] = q[2];
            q = drift_image_pixel(&gb->normal, x, y);
            rs.nx[i] = q[0], rs.ny[i] = q[1], rs.nz[i] = q[2];
            q = drift_image_pixel(&gb->geometric_normal, x, y);
            rs.gx[i] = q[0], rs.gy[i] = q[1], rs.gz[i] = q[2];
            rs.er[i] = rs.eg[i] = rs.eb[i] = 0.0f;
            rs.x[i] = x;
            rs.y[i] = y;
        }
        // Every VPL of the render's slice: its part of each group, at `slices` times the light.
        for (uint32_t g = 0; g < ism->group_count; ++g) {
            uint32_t from, to;
            group_run(ism, g, ism->slice, ism->slices, &from, &to);
            for (uint32_t j = from; j < to; ++j) {
                gather_vpl(ism, j, &c, &rs, &job->rays[thread]);
            }
        }
        float scale = (float)ism->slices * DRIFT_INV_PI * DRIFT_INV_PI;
        for (int32_t i = 0; i < rs.count; ++i) {
            drift_vec3 e = drift_vec3_make(rs.er[i], rs.eg[i], rs.eb[i]);
            drift_vec3 kd = drift_image_get3(&gb->albedo, rs.x[i], rs.y[i]);
            drift_image_set3(&ism->indirect, rs.x[i], rs.y[i],
                             drift_vec3_scale(drift_vec3_mul(kd, e), scale));
        }
    }
}

// The blurred irradiance of the gathering pixels to every pixel of `gb`, times its albedo.
static drift_result upsample(drift_ism *ism, const drift_gbuffer *gb, drift_ism_stats *st)
{
    size_t count = (size_t)gb->width * (size_t)gb->height;
    upsample_job job = { .ism = ism, .gb = gb, .fallback = drift_alloc(ism->ctx, count) };
    if (!job.fallback) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    drift_parallel_for(ism->ctx, (size_t)gb->height, 4, upsample_rows, &job);
    size_t fallbacks = 0;
    for (size_t i = 0; i < count; ++i) {
        fallbacks += job.fallback[i];
    }
    drift_result r = DRIFT_OK;
    if (fallbacks > 0) {
        size_t threads = (size_t)drift_context_thread_count(ism->ctx);
        job.job_pixels = (fallbacks + 2 * threads - 1) / (2 * threads);
        uint32_t *pixels = drift_alloc(ism->ctx, fallbacks * sizeof *pixels);
        job.receiver_buffers =
            drift_alloc(ism->ctx, threads * job.job_pixels * RECEIVER_ARRAYS * sizeof(float));
        if (pixels && job.receiver_buffers) {
            for (size_t i = 0, k = 0; i < count; ++i) {
                if (job.fallback[i]) {
                    pixels[k++] = (uint32_t)i;
                }
            }
            job.fallback_pixels = pixels;
            job.fallback_count = fallbacks;
            drift_parallel_for(ism->ctx, (fallbacks + job.job_pixels - 1) / job.job_pixels, 1,
                               fallback_jobs, &job);
            for (int i = 0; i < DRIFT_MAX_THREADS; ++i) {
                st->shadow_rays += job.rays[i];
            }
        } else {
            r = DRIFT_ERR_OUT_OF_MEMORY;
        }
        drift_free(ism->ctx, pixels);
        drift_free(ism->ctx, job.receiver_buffers);
    }
    st->fallback_pixels = fallbacks;
    drift_free(ism->ctx, job.fallback);
    return r;
}

// --- FRAME ---

// The gathering resolution's side for a G-buffer side of `full` pixels.
static int32_t gathering_side(const drift_ism *ism, int32_t full)
{
    int32_t s = ism->params.gather_scale;
    return (full + s - 1) / s;
}

static drift_result ensure_planes(drift_ism *ism, int32_t fw, int32_t fh)
{
    if (ism->indirect.pixels && ism->indirect.width == fw && ism->indirect.height == fh) {
        return DRIFT_OK;
    }
    destroy_planes(ism);
    int32_t w = gathering_side(ism, fw), h = gathering_side(ism, fh);
    ism->width = w;
    ism->height = h;
    int32_t n = ism->params.map_size;
    bool coarse = ism->params.gather_scale > 1;
    drift_gbuffer *c = &ism->coarse;
    if (coarse) {
        c->width = w;
        c->height = h;
        c->surfaces = drift_alloc(ism->ctx, sizeof(drift_surface) * (size_t)w * (size_t)h);
    }
    if (drift_image_create(ism->ctx, w, h, 3, &ism->irradiance) != DRIFT_OK ||
        drift_image_create(ism->ctx, fw, fh, 3, &ism->indirect) != DRIFT_OK ||
        (coarse && (!c->surfaces || drift_image_create(ism->ctx, w, h, 1, &c->depth) != DRIFT_OK ||
                    drift_image_create(ism->ctx, w, h, 3, &c->position) != DRIFT_OK ||
                    drift_image_create(ism->ctx, w, h, 3, &c->normal) != DRIFT_OK ||
                    drift_image_create(ism->ctx, w, h, 3, &c->geometric_normal) != DRIFT_OK ||
                    drift_image_create(ism->ctx, w, h, 3, &c->albedo) != DRIFT_OK ||
                    drift_image_create(ism->ctx, w, h, 1, &c->material_id) != DRIFT_OK ||
                    drift_image_create(ism->ctx, w, h, 3, &ism->coarse_direct) != DRIFT_OK ||
                    drift_image_create(ism->ctx, w, h, 3, &ism->coarse_blurred) != DRIFT_OK)) ||
        drift_image_create(ism->ctx, w, h, 3, &ism->vpl_plane) != DRIFT_OK ||
        drift_image_create(ism->ctx, w, h, 3, &ism->near_field) != DRIFT_OK ||
        drift_image_create(ism->ctx, w, h, 3, &ism->near_spread) != DRIFT_OK ||
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
    // Map 0 as the lookups see it (pushed).
    int32_t n = ism->params.map_size;
    for (int32_t y = 0; y < n; ++y) {
        for (int32_t x = 0; x < n; ++x) {
            float d = ism->atlas && ism->vpl_count > 0
                          ? drift__ism_lookup(ism->atlas, n, ism->lazy_levels,
                                              ism->params.pull_push_threshold, x, y)
                          : INFINITY;
            ism->tile.pixels[(size_t)y * (size_t)n + (size_t)x] = isfinite(d) ? d : 0.0f;
        }
    }
}

// Passes 1 and 2: the VPLs (their importance points from `gbuffer`, the full-size one) and,
// with ISM visibility, their maps. *t is the stage clock, advanced past what ran.
static drift_result make_lights(drift_ism *ism, const drift_gbuffer *gbuffer, drift_ism_stats *st,
                                double *t)
{
    double now;
    drift_result r;
    drift_free(ism->ctx, ism->vpls);
    ism->vpls = NULL;
    ism->vpl_count = 0;
    // The importance points: the visible surfaces at the centres of a 16 x 16 pixel grid.
    drift_vec3 view_pos[256], view_nrm[256];
    uint32_t view_count = 0;
    for (int32_t gy = 0; ism->params.vpl_importance && gy < 16; ++gy) {
        for (int32_t gx = 0; gx < 16; ++gx) {
            int32_t x = (2 * gx + 1) * gbuffer->width / 32, y = (2 * gy + 1) * gbuffer->height / 32;
            if (*drift_image_pixel(&gbuffer->material_id, x, y) < 0.0f) {
                continue;
            }
            const float *ps = drift_image_pixel(&gbuffer->position, x, y);
            const float *ns = drift_image_pixel(&gbuffer->normal, x, y);
            view_pos[view_count] = drift_vec3_make(ps[0], ps[1], ps[2]);
            view_nrm[view_count++] = drift_vec3_make(ns[0], ns[1], ns[2]);
        }
    }
    r = drift__ism_generate_vpls_for(ism->ctx, ism->scene, ism->accel, &ism->params, view_pos,
                                     view_nrm, view_count, &ism->vpls, &ism->vpl_count, NULL);
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
    st->ms[DRIFT_ISM_STAGE_VPLS] = (now - *t) * 1e3;
    *t = now;
    if (ism->params.visibility == DRIFT_ISM_VISIBILITY_ISM && ism->vpl_count > 0) {
        r = drift__ism_reserve(ism, ism->vpl_count);
        if (r != DRIFT_OK) {
            return r;
        }
        if (ism->points) {
            // Only the subsets of this render's VPLs are read, and only when a vertex moved
            // since they were derived (or they were never derived this far).
            uint32_t first, count;
            drift_points_subset(ism->points, ism->vpl_count - 1, &first, &count);
            uint64_t print = vertex_fingerprint(ism->scene);
            if (print != ism->points_print || first + count > ism->points_valid) {
                r = drift_points_update_range(ism->points, ism->scene, 0, first + count);
                if (r != DRIFT_OK) {
                    return r;
                }
                ism->points_print = print;
                ism->points_valid = first + count;
            }
        }
        now = drift_time_now();
        st->ms[DRIFT_ISM_STAGE_POINTS] = (now - *t) * 1e3;
        *t = now;
        map_job mj = { .ism = ism };
        mj.splat.n = ism->params.map_size;
        float area_per_point =
            ism->points ? (float)(ism->points->area / (double)ism->params.points_per_vpl) : 0.0f;
        mj.splat.point_radius = sqrtf(area_per_point * DRIFT_INV_PI);
        mj.splat.splat_scale = ism->params.splat_scale;
        ism->splat_radius = mj.splat.splat_scale * mj.splat.point_radius;
        drift_parallel_for(ism->ctx, ism->vpl_count, 1, maps_range, &mj);
        st->splats = (uint64_t)ism->vpl_count * ism->params.points_per_vpl;
        uint64_t empty = 0;
        for (int i = 0; i < DRIFT_MAX_THREADS; ++i) {
            empty += mj.empty[i];
        }
        double disc = (double)DRIFT_PI * 0.25 * (double)mj.splat.n * (double)mj.splat.n;
        st->hole_fraction = (double)empty / ((double)ism->vpl_count * disc);
        now = drift_time_now();
        // Splat and pull-push run map by map on one thread: the pass's wall time is split
        // between them in proportion to the threads' own clock of each.
        double splat_s = 0.0, pull_s = 0.0;
        for (int i = 0; i < DRIFT_MAX_THREADS; ++i) {
            splat_s += mj.seconds[i][0];
            pull_s += mj.seconds[i][1];
        }
        double maps_ms = (now - *t) * 1e3;
        double split = splat_s + pull_s > 0.0 ? splat_s / (splat_s + pull_s) : 0.5;
        st->ms[DRIFT_ISM_STAGE_SPLAT] = maps_ms * split;
        st->ms[DRIFT_ISM_STAGE_PULL_PUSH] = maps_ms * (1.0 - split);
        *t = now;
    }
    ism->lights_ready = true;
    return DRIFT_OK;
}

static drift_result render(drift_ism *ism, const drift_gbuffer *gbuffer, const drift_camera *camera,
                           const drift_image *direct, uint32_t slice, uint32_t slices)
{
    if (slices == 0 || slice >= slices) {
        drift_log(ism->ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, __FILE__, __LINE__,
                  "ism: slice %u of %u", slice, slices);
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    bool keep_lights = slice > 0 && ism->lights_ready;
    if (!gbuffer || gbuffer->width <= 0 || gbuffer->height <= 0 || !gbuffer->position.pixels ||
        !gbuffer->normal.pixels || !gbuffer->albedo.pixels || !gbuffer->material_id.pixels ||
        !gbuffer->geometric_normal.pixels) {
        drift_log(ism->ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, __FILE__, __LINE__,
                  "ism: the G-buffer lacks a plane gathering reads");
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    // The clamp's default was chosen with the compensation on: without its inputs the render
    // fails rather than clamp wide and give nothing back.
    bool near_field = !ism->params.no_near_field;
    if (near_field && (!direct || !camera || !gbuffer->surfaces || !gbuffer->depth.pixels ||
                       direct->width != gbuffer->width || direct->height != gbuffer->height ||
                       direct->channels < 3)) {
        drift_log(ism->ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, __FILE__, __LINE__,
                  "ism: the near-field compensation needs the camera, the G-buffer's surfaces "
                  "and depth, and a direct image of its size (or params.no_near_field)");
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    drift_result r = ensure_planes(ism, gbuffer->width, gbuffer->height);
    if (r != DRIFT_OK) {
        return r;
    }
    drift_ism_stats st = { 0 };
    double t0 = drift_time_now(), t = t0, now;
    // gb: the G-buffer the VPLs are gathered at (one pixel in gather_scale^2 of gbuffer's).
    const drift_gbuffer *gb = gbuffer;
    bool coarse = ism->params.gather_scale > 1;
    if (coarse) {
        decimate_job dj = { .ism = ism, .gb = gbuffer, .direct = near_field ? direct : NULL };
        drift_parallel_for(ism->ctx, (size_t)ism->coarse.height, 4, decimate_rows, &dj);
        gb = &ism->coarse;
        direct = &ism->coarse_direct;
        now = drift_time_now();
        st.ms[DRIFT_ISM_STAGE_UPSAMPLE] = (now - t) * 1e3;
        t = now;
    }
    ism->slice = slice;
    ism->slices = slices;
    if (!keep_lights) {
        ism->lights_ready = false;
        r = make_lights(ism, gbuffer, &st, &t);
        if (r != DRIFT_OK) {
            return r;
        }
    } else {
        // The lights' figures are the render's that made them.
        st.splats = ism->stats.splats;
        st.hole_fraction = ism->stats.hole_fraction;
    }
    int32_t b = ism->params.block_size;
    int32_t cols = (gb->width + b - 1) / b;
    gather_job gj = { .ism = ism, .gb = gb, .blur_to_coarse = coarse };
    // Whole rows of a subset, as few bands as keep the threads busy and the receivers of a job
    // under GATHER_MAX_RECEIVERS (the image does not depend on the split).
    int32_t rows = (gb->height + b - 1) / b;
    int64_t subsets = (int64_t)b * b, threads = drift_context_thread_count(ism->ctx);
    int64_t bands = (4 * threads + subsets - 1) / subsets;
    int64_t by_size = ((int64_t)rows * cols + GATHER_MAX_RECEIVERS - 1) / GATHER_MAX_RECEIVERS;
    bands = bands > by_size ? bands : by_size;
    bands = bands < rows ? bands : rows;
    gj.subset_rows = (int32_t)((rows + bands - 1) / bands);
    gj.bands = (rows + gj.subset_rows - 1) / gj.subset_rows;
    gj.capacity = gj.subset_rows * cols;
    gj.buffers = drift_alloc(ism->ctx, (size_t)drift_context_thread_count(ism->ctx) *
                                           (size_t)gj.capacity * RECEIVER_ARRAYS * sizeof(float));
    if (!gj.buffers) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    drift_parallel_for(ism->ctx, (size_t)gj.bands * (size_t)b * (size_t)b, 1, gather_jobs, &gj);
    drift_free(ism->ctx, gj.buffers);
    for (int i = 0; i < DRIFT_MAX_THREADS; ++i) {
        st.shadow_rays += gj.rays[i];
    }
    now = drift_time_now();
    st.ms[DRIFT_ISM_STAGE_GATHER] = (now - t) * 1e3;
    t = now;
    if (near_field) {
        add_near_field(ism, gb, camera, direct, &st);
    } else {
        memset(ism->near_field.pixels, 0,
               (size_t)ism->width * (size_t)ism->height * 3 * sizeof(float));
    }
    now = drift_time_now();
    st.ms[DRIFT_ISM_STAGE_NEAR_FIELD] = (now - t) * 1e3;
    t = now;
    gj.near_field = near_field;
    int32_t blur_block = ism->params.no_blur ? 1 : b;
    gj.blur_scratch =
        drift_alloc(ism->ctx, sizeof(float) * (size_t)drift_context_thread_count(ism->ctx) *
                                  blur_scratch_floats(gb->width, blur_block));
    if (!gj.blur_scratch) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    drift_parallel_for(ism->ctx, (size_t)gb->height, BLUR_JOB_ROWS, blur_rows, &gj);
    drift_free(ism->ctx, gj.blur_scratch);
    now = drift_time_now();
    st.ms[DRIFT_ISM_STAGE_BLUR] = (now - t) * 1e3;
    t = now;
    if (coarse) {
        r = upsample(ism, gbuffer, &st);
        if (r != DRIFT_OK) {
            return r;
        }
        now = drift_time_now();
        st.ms[DRIFT_ISM_STAGE_UPSAMPLE] += (now - t) * 1e3;
    }
    diagnostic_planes(ism, camera);
    st.total_ms = (drift_time_now() - t0) * 1e3;
    st.vpl_count = ism->vpl_count;
    ism->stats = st;
    drift_log(ism->ctx, DRIFT_LOG_DEBUG, DRIFT_OK, __FILE__, __LINE__,
              "ism: %u VPLs%s; ms: vpls %.2f points %.2f splat %.2f pull-push %.2f gather %.2f "
              "blur %.2f near-field %.2f upsample %.2f (total %.2f); %llu pixels gathered alone",
              st.vpl_count, keep_lights ? " kept" : "", st.ms[DRIFT_ISM_STAGE_VPLS],
              st.ms[DRIFT_ISM_STAGE_POINTS], st.ms[DRIFT_ISM_STAGE_SPLAT],
              st.ms[DRIFT_ISM_STAGE_PULL_PUSH], st.ms[DRIFT_ISM_STAGE_GATHER],
              st.ms[DRIFT_ISM_STAGE_BLUR], st.ms[DRIFT_ISM_STAGE_NEAR_FIELD],
              st.ms[DRIFT_ISM_STAGE_UPSAMPLE], st.total_ms, (unsigned long long)st.fallback_pixels);
    return DRIFT_OK;
}

drift_result drift_ism_render(drift_ism *ism, const drift_gbuffer *gbuffer,
                              const drift_camera *camera, const drift_image *direct)
{
    return render(ism, gbuffer, camera, direct, 0, 1);
}

drift_result drift_ism_render_slice(drift_ism *ism, const drift_gbuffer *gbuffer,
                                    const drift_camera *camera, const drift_image *direct,
                                    uint32_t slice, uint32_t slices)
{
    return render(ism, gbuffer, camera, direct, slice, slices);
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
    if (strcmp(name, "ism.near_field") == 0) {
        return &ism->near_field;
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
