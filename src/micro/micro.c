// drift micro (include/drift/micro.h): the object, the per-frame passes, the gather points
// and the bilateral upsampling (thesis §6.2.4).
#include "micro/micro_internal.h"
#include "raster/raster.h"

#include <math.h>
#include <string.h>

struct drift_micro {
    drift_context *ctx;
    const drift_scene *scene;
    const drift_accel *accel;
    drift_micro_params params;
    drift_points *points;
    drift__micro_tree tree;
    drift__micro_warp diffuse_warp;     // the Nusselt map: every diffuse gather's
    drift__micro_pixels diffuse_pixels; // and its pixels
    int32_t width, height;
    drift_image result, incident, gathers;
    drift_image coarse_in, coarse_out; // at the gather points: mean radiance, and times rho
    drift_micro_stats stats;
    bool any_glossy; // a material with a non-delta glossy lobe: the hits' on-the-fly light
};

static const char *const stage_names[DRIFT_MICRO_STAGE_COUNT] = { "hierarchy", "lighting", "gather",
                                                                  "upsample" };

const char *drift_micro_stage_name(drift_micro_stage stage)
{
    return stage < DRIFT_MICRO_STAGE_COUNT ? stage_names[stage] : NULL;
}

drift_micro_params drift_micro_params_resolve(const drift_micro_params *params)
{
    drift_micro_params p = params ? *params : (drift_micro_params){ 0 };
    if (p.point_count == 0) {
        p.point_count = 65536;
    }
    uint32_t pow2 = 1;
    while (pow2 < p.point_count && pow2 < (1u << 23)) {
        pow2 <<= 1;
    }
    p.point_count = pow2;
    if (p.buffer_size == 0) {
        p.buffer_size = 16;
    }
    if (p.density == 0) {
        p.density = 1;
    }
    if (p.light_samples == 0) {
        p.light_samples = 4;
    }
    if (p.warp_size == 0) {
        p.warp_size = 32;
    }
    if (p.cut_scale == 0.0f) {
        p.cut_scale = 1.0f;
    }
    drift__micro_lighting_resolve(&p);
    return p;
}

static bool params_valid(const drift_micro_params *p)
{
    return p->point_count >= 2 && p->point_count <= (1u << 22) && p->buffer_size >= 4 &&
           p->buffer_size <= DRIFT_MICRO_MAX_K &&
           (p->density == 1 || p->density == 2 || p->density == 4) && p->light_samples >= 1 &&
           p->light_samples <= 1024 && p->warp_size >= 8 && p->warp_size <= DRIFT_MICRO_MAX_WARP &&
           p->cut_scale > 0.0f && p->cut_scale <= 64.0f && drift__micro_lighting_valid(p);
}

drift_result drift_micro_create(drift_context *ctx, const drift_scene *scene,
                                const drift_accel *accel, const drift_micro_params *params,
                                drift_micro **out_micro)
{
    *out_micro = NULL;
    if (!scene || !scene->committed || !accel) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, __FILE__, __LINE__,
                  "micro: needs a committed scene and its accel");
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    drift_micro_params p = drift_micro_params_resolve(params);
    if (!params_valid(&p)) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, __FILE__, __LINE__,
                  "micro: a parameter is out of range (docs/micro.md lists them)");
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    drift_micro *m = drift_alloc(ctx, sizeof *m);
    if (!m) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    memset(m, 0, sizeof *m);
    m->ctx = ctx;
    m->scene = scene;
    m->accel = accel;
    m->params = p;
    for (uint32_t i = 0; i < scene->material_count; ++i) {
        const drift_material *mat = &scene->materials[i];
        m->any_glossy |= mat->type != DRIFT_MATERIAL_MIRROR && !drift_vec3_is_zero(mat->specular);
    }
    drift__micro_warp_build_diffuse(&m->diffuse_warp, p.warp_size);
    drift__micro_pixels_make(&m->diffuse_pixels, &m->diffuse_warp, p.buffer_size);
    drift_points_desc pd = { .count = p.point_count, .seed = p.seed };
    drift_result r = drift_points_create(ctx, scene, &pd, &m->points);
    if (r == DRIFT_OK) {
        r = drift__micro_tree_create(ctx, m->points, &m->tree);
    }
    if (r != DRIFT_OK) {
        drift_micro_destroy(m);
        return r;
    }
    *out_micro = m;
    return DRIFT_OK;
}

static void destroy_planes(drift_micro *m)
{
    drift_image_destroy(m->ctx, &m->result);
    drift_image_destroy(m->ctx, &m->incident);
    drift_image_destroy(m->ctx, &m->gathers);
    drift_image_destroy(m->ctx, &m->coarse_in);
    drift_image_destroy(m->ctx, &m->coarse_out);
}

void drift_micro_destroy(drift_micro *micro)
{
    if (!micro) {
        return;
    }
    destroy_planes(micro);
    drift__micro_tree_destroy(micro->ctx, &micro->tree);
    drift_points_destroy(micro->points);
    drift_free(micro->ctx, micro);
}

// --- GATHER POINTS ---

typedef struct gather_job {
    drift_micro *m;
    const drift_gbuffer *gb;
    drift_vec3 eye;
    drift_micro_lobe lobe;
    int32_t grid_w, grid_h;
    drift__micro_gather_stats stats[DRIFT_MAX_THREADS]; // per thread
    uint64_t fallbacks[DRIFT_MAX_THREADS];
} gather_job;

typedef struct glossy_slice {
    const drift_bsdf *bsdf;
    const drift_frame *frame;
    drift_vec3 wo;
} glossy_slice;

static float glossy_lobe(drift_vec3 omega, const void *user)
{
    const glossy_slice *s = user;
    drift_vec3 diffuse, glossy;
    drift_bsdf_eval_lobes(s->bsdf, s->wo, drift_frame_to_world(s->frame, omega), &diffuse, &glossy);
    return (glossy.x + glossy.y + glossy.z) * (1.0f / 3.0f);
}

// The gather at G-buffer pixel (x, y): *out_incident gets the micro-buffer's mean, the
// return value that times rho (the lobe's light toward the camera).
static drift_vec3 gather_pixel(const gather_job *job, int32_t x, int32_t y,
                               drift__micro_gather_stats *stats, drift_vec3 *out_incident)
{
    const drift_micro *m = job->m;
    const drift_gbuffer *gb = job->gb;
    *out_incident = drift_vec3_splat(0.0f);
    if (drift_image_pixel(&gb->material_id, x, y)[0] < 0.0f) {
        return drift_vec3_splat(0.0f);
    }
    drift_vec3 p = drift_image_get3(&gb->position, x, y);
    drift_vec3 n = drift_image_get3(&gb->normal, x, y);
    drift_vec3 ng = drift_image_get3(&gb->geometric_normal, x, y);
    drift_frame frame = drift_frame_from_normal(n);
    if (!m->params.no_jitter) {
        // A random rotation about the normal against banding (§6.2.3); it costs some noise.
        uint32_t h = drift_hash_combine(
            drift_hash_combine(drift_hash_combine(m->params.seed, DRIFT_MICRO_JITTER_STREAM),
                               (uint32_t)x),
            (uint32_t)y);
        float a = (float)(h >> 8) * (2.0f * DRIFT_PI / 16777216.0f);
        float c = cosf(a), s = sinf(a);
        drift_vec3 fx = drift_vec3_add(drift_vec3_scale(frame.x, c), drift_vec3_scale(frame.y, s));
        drift_vec3 fy = drift_vec3_sub(drift_vec3_scale(frame.y, c), drift_vec3_scale(frame.x, s));
        frame.x = fx;
        frame.y = fy;
    }
    drift__micro_gather_desc desc = {
        .tree = &m->tree,
        .accel = m->params.no_ray_casting ? NULL : m->accel,
        .warp = &m->diffuse_warp,
        .pixels = &m->diffuse_pixels,
        .cut_scale = m->params.cut_scale,
        .scene = m->any_glossy ? m->scene : NULL,
        .seed = drift_hash_combine(
            drift_hash_combine(drift_hash_combine(m->params.seed, DRIFT_MICRO_GLOSSY_STREAM),
                               (uint32_t)x),
            (uint32_t)y)
    };
    drift_vec3 rho;
    if (job->lobe == DRIFT_MICRO_LOBE_DIFFUSE) {
        rho = drift_image_get3(&gb->albedo, x, y);
        if (drift_vec3_is_zero(rho)) {
            return rho;
        }
        *out_incident = drift__micro_gather(&desc, p, &frame, ng, NULL, stats, NULL);
        return drift_vec3_mul(rho, *out_incident);
    }
    const drift_surface *surf = &gb->surfaces[(size_t)y * (size_t)gb->width + (size_t)x];
    if (surf->material == DRIFT_INVALID_INDEX) {
        return drift_vec3_splat(0.0f);
    }
    drift_bsdf bsdf = drift_bsdf_make(m->scene, surf);
    float ks = (bsdf.specular.x + bsdf.specular.y + bsdf.specular.z) * (1.0f / 3.0f);
    if (!(ks > 0.0f) || drift_bsdf_is_delta(&bsdf)) {
        return drift_vec3_splat(0.0f); // no glossy lobe, or a mirror (not a micro-buffer's)
    }
    drift_vec3 wo = drift_vec3_normalize(drift_vec3_sub(job->eye, p));
    // Under reflection edits the lobe the warp is built from centres on e(q).
    drift_reflection_edits_aim_bsdf(m->params.reflection_edits, surf, wo, &bsdf);
    glossy_slice slice = { &bsdf, &frame, wo };
    drift__micro_warp warp;
    drift__micro_pixels pixels;
    // The table covers the cap around the lobe's axis (the mirror direction, or e(q)) that
    // holds all but 10^-3 of a Phong lobe: at exponents 60-200 the whole disc's table gave
    // the lobe a few cells, and each pixel the width of a cell.
    drift_vec3 axis = drift_vec3_is_zero(bsdf.edited_mirror)
                          ? drift_vec3_sub(drift_vec3_scale(n, 2.0f * drift_vec3_dot(wo, n)), wo)
                          : bsdf.edited_mirror;
    axis = drift_frame_to_local(&frame, axis);
    axis.z = fmaxf(axis.z, 0.05f);
    axis = drift_vec3_normalize(axis);
    // GGX too: the cap of its Phong-equivalent lobe. GGX's own 10^-3 cap (tan theta_h =
    // 31.6 alpha, its tails) is ~12x wider and gives the peak too few cells: FLIP 0.297
    // against 0.232 on scenes/ggx-spheres (docs/lab/2026-12-07-issue-41-s2.md).
    float cap = drift__micro_phong_cap(bsdf.exponent);
    drift__micro_warp_build_cap(&warp, m->params.warp_size, axis, cap, glossy_lobe, &slice);
    if (!(warp.rho > 0.0f)) {
        return drift_vec3_splat(0.0f);
    }
    drift__micro_pixels_make(&pixels, &warp, m->params.buffer_size);
    desc.warp = &warp;
    desc.pixels = &pixels;
    rho = drift_vec3_scale(bsdf.specular, warp.rho / ks);
    *out_incident = drift__micro_gather(&desc, p, &frame, ng, NULL, stats, NULL);
    return drift_vec3_mul(rho, *out_incident);
}

// The full-resolution pixel of gather (i, j) on a grid of spacing d.
static int32_t grid_pixel(int32_t i, int32_t d, int32_t size)
{
    int32_t v = i * d + d / 2;
    return v < size ? v : size - 1;
}

static void gather_rows(size_t begin, size_t end, int thread, void *user)
{
    gather_job *job = user;
    drift_micro *m = job->m;
    int32_t d = m->params.density;
    for (size_t row = begin; row < end; ++row) {
        int32_t j = (int32_t)row, y = grid_pixel(j, d, m->height);
        for (int32_t i = 0; i < job->grid_w; ++i) {
            int32_t x = grid_pixel(i, d, m->width);
            drift_vec3 in;
            drift_vec3 out = gather_pixel(job, x, y, &job->stats[thread], &in);
            drift_image_set3(&m->coarse_in, i, j, in);
            drift_image_set3(&m->coarse_out, i, j, out);
            drift_image_pixel(&m->gathers, x, y)[0] = 1.0f;
        }
    }
}

// --- BILATERAL UPSAMPLING (Sloan et al. 2007 weights, our choice; thesis §6.2.4) ---

// The mirror direction of the view at G-buffer pixel (x, y), and its glossy exponent.
static drift_vec3 mirror_of(const drift_gbuffer *gb, drift_vec3 eye, int32_t x, int32_t y)
{
    drift_vec3 n = drift_image_get3(&gb->normal, x, y);
    drift_vec3 wo =
        drift_vec3_normalize(drift_vec3_sub(eye, drift_image_get3(&gb->position, x, y)));
    return drift_vec3_sub(drift_vec3_scale(n, 2.0f * drift_vec3_dot(wo, n)), wo);
}

static float gloss_exponent(const drift_micro *m, const drift_gbuffer *gb, int32_t x, int32_t y)
{
    const drift_surface *surf = &gb->surfaces[(size_t)y * (size_t)gb->width + (size_t)x];
    if (surf->material == DRIFT_INVALID_INDEX) {
        return 0.0f;
    }
    drift_bsdf bsdf = drift_bsdf_make(m->scene, surf);
    // GGX: the Phong exponent of its 90% cone (docs/micro.md), not the peak-matched one.
    return bsdf.type == DRIFT_MATERIAL_GGX ? 0.25f * drift_gloss_blinn_exponent(&bsdf)
                                           : bsdf.exponent;
}

static void upsample_rows(size_t begin, size_t end, int thread, void *user)
{
    gather_job *job = user;
    drift_micro *m = job->m;
    const drift_gbuffer *gb = job->gb;
    int32_t d = m->params.density;
    for (size_t row = begin; row < end; ++row) {
        int32_t y = (int32_t)row;
        for (int32_t x = 0; x < m->width; ++x) {
            drift_vec3 in = drift_vec3_splat(0.0f), out = in;
            if (drift_image_pixel(&gb->material_id, x, y)[0] >= 0.0f) {
                drift_vec3 n = drift_image_get3(&gb->normal, x, y);
                float z = drift_image_pixel(&gb->depth, x, y)[0];
                float fx = ((float)x - (float)(d / 2)) / (float)d;
                float fy = ((float)y - (float)(d / 2)) / (float)d;
                int32_t i0 = (int32_t)floorf(fx), j0 = (int32_t)floorf(fy);
                float wx = fx - (float)i0, wy = fy - (float)j0;
                float total = 0.0f, trusted = 0.0f;
                // The glossy lobe's light follows its mirror direction: a gather counts by how
                // much its lobe overlaps this pixel's, (r . r_k)^n (at 1/4 density on the
                // dragon, neighbours facing the open front and the floor differ by 100%).
                float exponent = 0.0f;
                drift_vec3 mirror = n;
                if (job->lobe == DRIFT_MICRO_LOBE_GLOSSY) {
                    exponent = gloss_exponent(m, gb, x, y);
                    mirror = mirror_of(gb, job->eye, x, y);
                }
                drift_vec3 sum_in = in, sum_out = out;
                for (int32_t c = 0; c < 4; ++c) {
                    int32_t i = i0 + (c & 1), j = j0 + (c >> 1);
                    float bil = ((c & 1) ? wx : 1.0f - wx) * ((c >> 1) ? wy : 1.0f - wy);
                    i = i < 0 ? 0 : (i >= job->grid_w ? job->grid_w - 1 : i);
                    j = j < 0 ? 0 : (j >= job->grid_h ? job->grid_h - 1 : j);
                    int32_t sx = grid_pixel(i, d, m->width), sy = grid_pixel(j, d, m->height);
                    float mat = drift_image_pixel(&gb->material_id, sx, sy)[0];
                    // The glossy lobe's light is its material's (rho, exponent): a gather on
                    // the dragon says nothing of the wall beside it.
                    if (mat < 0.0f || (job->lobe == DRIFT_MICRO_LOBE_GLOSSY &&
                                       mat != drift_image_pixel(&gb->material_id, x, y)[0])) {
                        continue;
                    }
                    float cos_n = drift_vec3_dot(n, drift_image_get3(&gb->normal, sx, sy));
                    float dz =
                        fabsf(drift_image_pixel(&gb->depth, sx, sy)[0] - z) / fmaxf(z, 1e-6f);
                    if (cos_n <= 0.0f) {
                        continue;
                    }
                    float w = bil * powf(cos_n, 32.0f) / (1e-3f + dz);
                    float overlap = 1.0f;
                    if (exponent > 0.0f) {
                        overlap = powf(
                            fmaxf(drift_vec3_dot(mirror, mirror_of(gb, job->eye, sx, sy)), 0.0f),
                            exponent);
                        w *= overlap;
                    }
                    total += w;
                    sum_in = drift_vec3_fma(sum_in, drift_image_get3(&m->coarse_in, i, j), w);
                    sum_out = drift_vec3_fma(sum_out, drift_image_get3(&m->coarse_out, i, j), w);
                    if (bil > 0.0f && cos_n > 0.8f && dz < 0.1f && overlap > 0.5f) {
                        trusted += bil;
                    }
                }
                if (total > 0.0f && (d == 1 || trusted > 0.01f)) {
                    in = drift_vec3_scale(sum_in, 1.0f / total);
                    out = drift_vec3_scale(sum_out, 1.0f / total);
                    if (job->lobe == DRIFT_MICRO_LOBE_DIFFUSE) {
                        out = drift_vec3_mul(drift_image_get3(&gb->albedo, x, y), in);
                    }
                } else {
                    // No gather point on this surface nearby: gather here (the extra pass).
                    out = gather_pixel(job, x, y, &job->stats[thread], &in);
                    drift_image_pixel(&m->gathers, x, y)[0] = 1.0f;
                    job->fallbacks[thread]++;
                }
            }
            drift_image_set3(&m->incident, x, y, in);
            drift_image_set3(&m->result, x, y, out);
        }
    }
}

// --- FRAME ---

static drift_result ensure_planes(drift_micro *m, int32_t w, int32_t h, int32_t gw, int32_t gh)
{
    if (m->width == w && m->height == h && m->coarse_in.width == gw && m->coarse_in.height == gh &&
        m->result.pixels) {
        return DRIFT_OK;
    }
    destroy_planes(m);
    m->width = w;
    m->height = h;
    if (drift_image_create(m->ctx, w, h, 3, &m->result) != DRIFT_OK ||
        drift_image_create(m->ctx, w, h, 3, &m->incident) != DRIFT_OK ||
        drift_image_create(m->ctx, w, h, 1, &m->gathers) != DRIFT_OK ||
        drift_image_create(m->ctx, gw, gh, 3, &m->coarse_in) != DRIFT_OK ||
        drift_image_create(m->ctx, gw, gh, 3, &m->coarse_out) != DRIFT_OK) {
        destroy_planes(m);
        m->width = m->height = 0;
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    return DRIFT_OK;
}

drift_result drift_micro_render(drift_micro *micro, const drift_gbuffer *gbuffer,
                                const drift_camera *camera, drift_micro_lobe lobe)
{
    drift_micro *m = micro;
    if (!gbuffer || gbuffer->width <= 0 || gbuffer->height <= 0 ||
        (unsigned)lobe >= DRIFT_MICRO_LOBE_COUNT ||
        (lobe == DRIFT_MICRO_LOBE_GLOSSY && (!camera || !gbuffer->surfaces))) {
        drift_log(m->ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, __FILE__, __LINE__,
                  "micro: needs a G-buffer (and a camera for the glossy lobe)");
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    double t0 = drift_time_now();
    memset(&m->stats, 0, sizeof m->stats);
    int32_t d = m->params.density;
    int32_t gw = (gbuffer->width + d - 1) / d, gh = (gbuffer->height + d - 1) / d;
    drift_result r = ensure_planes(m, gbuffer->width, gbuffer->height, gw, gh);
    if (r != DRIFT_OK) {
        return r;
    }
    memset(m->gathers.pixels, 0, (size_t)m->width * (size_t)m->height * sizeof(float));

    // 1. The hierarchy follows the meshes: leaves re-derived, the nodes refit.
    r = drift_points_update(m->points, m->scene);
    if (r != DRIFT_OK) {
        return r;
    }
    drift__micro_tree_refit(&m->tree, m->points);
    drift__micro_tree_cover(m->ctx, &m->tree, m->accel);
    double t1 = drift_time_now();
    // 2. Lighting the leaves (direct light and the further bounces), pulled up the tree.
    r = drift__micro_light_points(m->ctx, m->scene, m->accel, m->points, &m->tree, &m->params,
                                  &m->stats);
    if (r != DRIFT_OK) {
        return r;
    }
    double t2 = drift_time_now();
    // 3. The gathers.
    gather_job *job = drift_alloc(m->ctx, sizeof *job);
    if (!job) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    memset(job, 0, sizeof *job);
    job->m = m;
    job->gb = gbuffer;
    job->eye = camera ? camera->position : drift_vec3_splat(0.0f);
    job->lobe = lobe;
    job->grid_w = gw;
    job->grid_h = gh;
    drift_parallel_for(m->ctx, (size_t)gh, 1, gather_rows, job);
    double t3 = drift_time_now();
    // 4. Upsampling (a copy, with the albedo, at every-pixel density).
    drift_parallel_for(m->ctx, (size_t)m->height, 1, upsample_rows, job);
    double t4 = drift_time_now();
    for (int i = 0; i < DRIFT_MAX_THREADS; ++i) {
        const drift__micro_gather_stats *s = &job->stats[i];
        m->stats.gathers += s->gathers;
        m->stats.nodes_visited += s->visited;
        m->stats.splats += s->splats;
        m->stats.post_leaves += s->post_leaves;
        m->stats.rays += s->rays;
        m->stats.empty_pixels += s->empty;
        m->stats.cast_gathers += s->cast;
        m->stats.fallbacks += job->fallbacks[i];
    }
    drift_free(m->ctx, job);
    m->stats.ms[DRIFT_MICRO_STAGE_HIERARCHY] = (t1 - t0) * 1e3;
    m->stats.ms[DRIFT_MICRO_STAGE_LIGHTING] = (t2 - t1) * 1e3;
    m->stats.ms[DRIFT_MICRO_STAGE_GATHER] = (t3 - t2) * 1e3;
    m->stats.ms[DRIFT_MICRO_STAGE_UPSAMPLE] = (t4 - t3) * 1e3;
    m->stats.total_ms = (t4 - t0) * 1e3;
    return DRIFT_OK;
}

const drift_image *drift_micro_result(const drift_micro *micro)
{
    return &micro->result;
}

const drift_image *drift_micro_plane_named(const drift_micro *micro, const char *name)
{
    if (!micro->result.pixels || !name) {
        return NULL;
    }
    if (strcmp(name, "micro.incident") == 0) {
        return &micro->incident;
    }
    if (strcmp(name, "micro.gathers") == 0) {
        return &micro->gathers;
    }
    return NULL;
}

drift_micro_stats drift_micro_get_stats(const drift_micro *micro)
{
    return micro->stats;
}

drift_micro_params drift_micro_get_params(const drift_micro *micro)
{
    return micro->params;
}
