// Moving refinement (drift/temporal.h): one path-traced sample a pixel a frame, accumulated
// through the temporal history's reprojection, filtered by its variance-guided filter and
// blended into the temporal image where its estimated error is below the hybrid's.
#include "drift/math.h"
#include "drift/pt.h"
#include "drift/temporal.h"
#include "temporal_internal.h"

#include <math.h>

struct drift_moving_refine {
    drift_context *ctx;
    const drift_scene *scene;
    const drift_accel *accel;
    drift_temporal *t;
    int32_t width, height;
    drift_moving_refine_settings s;
    uint32_t frame;        // applies so far: frame k's seed is seed + k
    temporal_layer layer;  // the path-traced samples' accumulation
    drift_image path;      // 3: the filtered accumulation, remodulated
    drift_image out;       // 3: the shown image
    drift_image weight;    // 1: the path tracer's weight
    drift_image fvar;      // 1: the filtered accumulation's variance, image units
    drift_image upsampled; // 3: scale 2: the half-size samples at full size
    float *scratch[4];     // width x height: the blend's
};

static drift_moving_refine_settings resolve(const drift_moving_refine_settings *in)
{
    drift_moving_refine_settings s = in ? *in : (drift_moving_refine_settings){ 0 };
    s.max_history = s.max_history ? s.max_history : 32;
    s.filter_passes = s.filter_passes ? s.filter_passes : 5;
    s.radius = s.radius > 0 ? s.radius : 4;
    return s;
}

void drift_moving_refine_destroy(drift_moving_refine *m)
{
    if (!m) {
        return;
    }
    temporal_layer_free(m->ctx, &m->layer);
    drift_image_destroy(m->ctx, &m->path);
    drift_image_destroy(m->ctx, &m->out);
    drift_image_destroy(m->ctx, &m->weight);
    drift_image_destroy(m->ctx, &m->fvar);
    drift_image_destroy(m->ctx, &m->upsampled);
    for (int k = 0; k < 4; ++k) {
        drift_free(m->ctx, m->scratch[k]);
    }
    drift_free(m->ctx, m);
}

drift_result drift_moving_refine_create(drift_context *ctx, const drift_scene *scene,
                                        const drift_accel *accel, drift_temporal *temporal,
                                        const drift_moving_refine_settings *settings,
                                        drift_moving_refine **out)
{
    if (!out) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    *out = NULL;
    drift_moving_refine_settings s = resolve(settings);
    if (!ctx || !scene || !accel || !temporal || s.max_history < 1 || s.max_history > 4096 ||
        s.filter_passes < 0 || s.filter_passes > 8 || s.radius > 32 || s.scale < 0 || s.scale > 2) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    drift_moving_refine *m = drift_alloc(ctx, sizeof(*m));
    if (!m) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    *m = (drift_moving_refine){ .ctx = ctx, .scene = scene, .accel = accel, .t = temporal, .s = s };
    temporal_size(temporal, &m->width, &m->height);
    int32_t w = m->width, h = m->height;
    drift_result r = temporal_layer_init(ctx, w, h, s.max_history, &m->layer);
    if (r == DRIFT_OK) {
        r = drift_image_create(ctx, w, h, 3, &m->path);
    }
    if (r == DRIFT_OK) {
        r = drift_image_create(ctx, w, h, 3, &m->out);
    }
    if (r == DRIFT_OK) {
        r = drift_image_create(ctx, w, h, 1, &m->weight);
    }
    if (r == DRIFT_OK) {
        r = drift_image_create(ctx, w, h, 1, &m->fvar);
    }
    if (r == DRIFT_OK && s.scale == 2) {
        r = drift_image_create(ctx, w, h, 3, &m->upsampled);
    }
    for (int k = 0; k < 4 && r == DRIFT_OK; ++k) {
        m->scratch[k] = drift_alloc(ctx, sizeof(float) * (size_t)w * (size_t)h);
        r = m->scratch[k] ? DRIFT_OK : DRIFT_ERR_OUT_OF_MEMORY;
    }
    if (r != DRIFT_OK) {
        drift_moving_refine_destroy(m);
        return r;
    }
    *out = m;
    return DRIFT_OK;
}

void drift_moving_refine_reset(drift_moving_refine *m)
{
    if (m) {
        m->layer.has_prev = false;
    }
}

// The residual's signal: this frame's sample minus the hybrid frame's, plus the emission that
// the layer subtracts (so that it accumulates (pt - frame) / albedo).
static void residual_signal(drift_moving_refine *m, const drift_gbuffer *g, drift_image *beauty,
                            const drift_image *frame)
{
    for (int32_t y = 0; y < m->height; ++y) {
        for (int32_t x = 0; x < m->width; ++x) {
            drift_vec3 d =
                drift_vec3_sub(drift_image_get3(beauty, x, y), drift_image_get3(frame, x, y));
            drift_image_set3(beauty, x, y, drift_vec3_add(d, drift_image_get3(&g->emission, x, y)));
        }
    }
}

// hybrid + the accumulated residual's lighting `light` remodulated (no emission: the
// hybrid has it); misses show the hybrid.
static void add_residual(drift_moving_refine *m, const drift_gbuffer *g, const drift_image *hybrid,
                         const drift_image *light, drift_image *out)
{
    for (int32_t y = 0; y < m->height; ++y) {
        for (int32_t x = 0; x < m->width; ++x) {
            drift_vec3 h = drift_image_get3(hybrid, x, y);
            if (drift_image_pixel(&g->depth, x, y)[0] > 0.0f) {
                drift_vec3 a = temporal_demodulation(g, x, y);
                const float *l = drift_image_pixel(light, x, y);
                h = drift_vec3_add(h, drift_vec3_make(a.x * l[0], a.y * l[1], a.z * l[2]));
            }
            drift_image_set3(out, x, y, h);
        }
    }
}

// Each pixel takes the half-size sample, among the 3 x 3 around its own, whose hit distance
// is relatively closest to its G-buffer point's (a miss: one that missed); ties keep the
// nearest. `depth` is the half-size path tracer's distance along the ray (0: a miss).
static void upsample(drift_moving_refine *m, const drift_gbuffer *g, const drift_camera *camera,
                     const drift_image *half, const drift_image *depth)
{
    for (int32_t y = 0; y < m->height; ++y) {
        for (int32_t x = 0; x < m->width; ++x) {
            bool hit = drift_image_pixel(&g->depth, x, y)[0] > 0.0f;
            float d = hit ? drift_vec3_length(drift_vec3_sub(drift_image_get3(&g->position, x, y),
                                                             camera->position))
                          : 0.0f;
            int32_t cx = x / 2, cy = y / 2, bx = cx, by = cy;
            float best = INFINITY;
            for (int k = 0; k < 9; ++k) {
                static const int8_t order[9][2] = { { 0, 0 },  { -1, 0 }, { 1, 0 },
                                                    { 0, -1 }, { 0, 1 },  { -1, -1 },
                                                    { 1, -1 }, { -1, 1 }, { 1, 1 } };
                int32_t qx = cx + order[k][0], qy = cy + order[k][1];
                if (qx < 0 || qy < 0 || qx >= half->width || qy >= half->height) {
                    continue;
                }
                float dq = drift_image_pixel(depth, qx, qy)[0];
                float e =
                    hit ? (dq > 0.0f ? fabsf(dq - d) / d : INFINITY) : (dq > 0.0f ? 1.0f : 0.0f);
                if (e < best) {
                    best = e;
                    bx = qx;
                    by = qy;
                }
            }
            drift_image_set3(&m->upsampled, x, y, drift_image_get3(half, bx, by));
        }
    }
}

drift_result drift_moving_refine_apply(drift_moving_refine *m, const drift_gbuffer *g,
                                       const drift_camera *camera, const drift_image *frame,
                                       const drift_image *hybrid, const atomic_bool *cancel)
{
    if (!m || !g || !camera || !hybrid || hybrid->channels < 3 || hybrid->width != m->width ||
        hybrid->height != m->height || g->width != m->width || g->height != m->height || !frame ||
        frame->channels < 3 || frame->width != m->width || frame->height != m->height) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    // This frame's sample: a new path tracer through this camera (its own pixel jitter, so the
    // samples cover the pixel's box as the reference's do).
    bool half = m->s.scale == 2;
    drift_pt_params p = { .width = half ? (m->width + 1) / 2 : m->width,
                          .height = half ? (m->height + 1) / 2 : m->height,
                          .seed = m->s.seed + m->frame,
                          .max_depth = m->s.max_depth,
                          .texture_filter_spp = (uint32_t)m->s.max_history,
                          .camera = camera };
    drift_pt *pt = NULL;
    drift_result r = drift_pt_create(m->ctx, m->scene, m->accel, &p, &pt);
    if (r == DRIFT_OK) {
        r = drift_pt_render_samples(pt, 1, cancel);
    }
    drift_image beauty;
    if (r == DRIFT_OK) {
        r = drift_pt_resolve(pt, DRIFT_PT_AOV_BEAUTY, &beauty);
    }
    drift_image depth;
    if (r == DRIFT_OK && half &&
        (r = drift_pt_resolve(pt, DRIFT_PT_AOV_DEPTH, &depth)) == DRIFT_OK) {
        upsample(m, g, camera, &beauty, &depth);
        beauty = m->upsampled; // the layer reads it as the frame's samples
    }
    if (r != DRIFT_OK) {
        drift_pt_destroy(pt);
        return r;
    }
    m->frame += 1;
    if (m->s.residual) {
        residual_signal(m, g, &beauty, frame);
    }
    const drift_image *filtered =
        temporal_layer_apply(m->t, &m->layer, g, &beauty, m->s.filter_passes, NULL);
    drift_pt_destroy(pt);
    if (m->s.residual) {
        add_residual(m, g, hybrid, filtered, &m->path);
    } else {
        temporal_remodulate(m->t, g, filtered, hybrid, &m->path);
    }
    // The variance of the mean in the image's units: the lighting's times the albedo's
    // luminance squared (a miss: 0, the hybrid and the path tracer both show the same sky).
    for (int32_t y = 0; y < m->height; ++y) {
        for (int32_t x = 0; x < m->width; ++x) {
            float a = drift_image_pixel(&g->depth, x, y)[0] > 0.0f
                          ? drift_luminance(temporal_demodulation(g, x, y))
                          : 0.0f;
            drift_image_pixel(&m->fvar, x, y)[0] = drift_image_pixel(filtered, x, y)[3] * a * a;
        }
    }
    // The hybrid's error is judged against the filtered accumulation (its variance the
    // filter's estimate): the raw mean of a few one-sample frames is too noisy to show the
    // hybrid's bias under it (the weight stayed near 0.1-0.2 on both measured scenes).
    temporal_error_blend(hybrid, &m->path, &m->fvar, &m->path, &m->fvar, 1.0f, m->s.radius,
                         m->scratch, &m->out, &m->weight);
    return DRIFT_OK;
}

const drift_image *drift_moving_refine_image(const drift_moving_refine *m)
{
    return m ? &m->out : NULL;
}

const drift_image *drift_moving_refine_weight(const drift_moving_refine *m)
{
    return m ? &m->weight : NULL;
}

const drift_image *drift_moving_refine_path(const drift_moving_refine *m)
{
    return m ? &m->path : NULL;
}
