// drift ism (include/drift/ism.h): the object and the frame's order of stages; the stages are
// in ism_gather.c (maps, interleaved gathering, the blur), ism_near_field.c and ism_upsample.c.
#include "core/vectorise.h"
#include "ism/ism_object.h"

#include <math.h>
#include <string.h>

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
                                 .seed = ism->points_seed };
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
    ism->points_seed = p.seed;
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
            // The atlas and the scene points are sized by the first render for the VPLs it
            // made, and grow by half when a later one makes more (drift__ism_reserve). Sizing
            // them up front for max_vpls (eight rounds of paths) sampled 14M points at 1024
            // VPLs and depth 8; even one round's bound (1024 + 6 x 256 at depth 8) zeroed and
            // faulted in 170 MB for a first frame that made 891 VPLs (1.6 s of a 1.9 s frame).
            r = ism->scratch ? DRIFT_OK : DRIFT_ERR_OUT_OF_MEMORY;
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
        drift_parallel_for(ism->ctx, ism->vpl_count, 1, drift__ism_maps_range, &mj);
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
        drift_parallel_for(ism->ctx, (size_t)ism->coarse.height, 4, drift__ism_decimate_rows, &dj);
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
    drift_parallel_for(ism->ctx, (size_t)gj.bands * (size_t)b * (size_t)b, 1,
                       drift__ism_gather_jobs, &gj);
    drift_free(ism->ctx, gj.buffers);
    for (int i = 0; i < DRIFT_MAX_THREADS; ++i) {
        st.shadow_rays += gj.rays[i];
    }
    now = drift_time_now();
    st.ms[DRIFT_ISM_STAGE_GATHER] = (now - t) * 1e3;
    t = now;
    if (near_field) {
        drift__ism_add_near_field(ism, gb, camera, direct, &st);
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
                                  drift__ism_blur_scratch_floats(gb->width, blur_block));
    if (!gj.blur_scratch) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    drift_parallel_for(ism->ctx, (size_t)gb->height, BLUR_JOB_ROWS, drift__ism_blur_rows, &gj);
    drift_free(ism->ctx, gj.blur_scratch);
    now = drift_time_now();
    st.ms[DRIFT_ISM_STAGE_BLUR] = (now - t) * 1e3;
    t = now;
    if (coarse) {
        r = drift__ism_upsample(ism, gbuffer, &st);
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

void drift_ism_set_seed(drift_ism *ism, uint32_t seed)
{
    if (ism && ism->params.seed != seed) {
        ism->params.seed = seed;
        ism->lights_ready = false; // the next render draws the new seed's VPLs
    }
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
