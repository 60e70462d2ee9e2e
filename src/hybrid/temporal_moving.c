// Moving refinement (drift/temporal.h): one path-traced sample a pixel every `period` frames,
// accumulated through the temporal history's reprojection, filtered by its variance-guided
// filter and blended into the temporal image where its estimated error is below the hybrid's.
// Every per-pixel pass runs over rows on the context's threads (gathers: the same bits for any
// thread count).
#include "drift/math.h"
#include "drift/pt.h"
#include "drift/temporal.h"
#include "temporal_internal.h"

#include <math.h>
#include <string.h>

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
    drift_image samples;   // 3: period > 1: this frame's samples (0 where none)
    uint8_t *sampled;      // period > 1: width x height, 1 where this frame has a sample
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
    drift_image_destroy(m->ctx, &m->samples);
    drift_free(m->ctx, m->sampled);
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
        s.filter_passes < 0 || s.filter_passes > 8 || s.radius > 32 || s.scale < 0 || s.scale > 2 ||
        !(s.period == 0 || s.period == 1 || s.period == 2 || s.period == 4 || s.period == 8 ||
          s.period == 16) ||
        (s.period > 1 && s.scale == 2)) {
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
    if (r == DRIFT_OK && s.period > 1) {
        r = drift_image_create(ctx, w, h, 3, &m->samples);
        m->sampled = r == DRIFT_OK ? drift_alloc(ctx, (size_t)w * (size_t)h) : NULL;
        r = r == DRIFT_OK && !m->sampled ? DRIFT_ERR_OUT_OF_MEMORY : r;
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

// The per-pixel passes' data (each pass reads what it needs).
typedef struct rows_job {
    drift_moving_refine *m;
    const drift_gbuffer *g;
    const drift_camera *camera;
    const drift_pt *pt;
    drift_image *beauty;
    const drift_image *frame, *hybrid, *light, *half, *depth;
    drift_image *out;
} rows_job;

// The residual's signal: this frame's sample minus the hybrid frame's, plus the emission that
// the layer subtracts (so that it accumulates (pt - frame) / albedo).
static void residual_rows(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    const rows_job *j = user;
    for (int32_t y = (int32_t)begin; y < (int32_t)end; ++y) {
        for (int32_t x = 0; x < j->m->width; ++x) {
            drift_vec3 d =
                drift_vec3_sub(drift_image_get3(j->beauty, x, y), drift_image_get3(j->frame, x, y));
            drift_image_set3(j->beauty, x, y,
                             drift_vec3_add(d, drift_image_get3(&j->g->emission, x, y)));
        }
    }
}

// hybrid + the accumulated residual's lighting `light` remodulated (no emission: the
// hybrid has it); misses show the hybrid.
static void add_residual_rows(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    const rows_job *j = user;
    for (int32_t y = (int32_t)begin; y < (int32_t)end; ++y) {
        for (int32_t x = 0; x < j->m->width; ++x) {
            drift_vec3 h = drift_image_get3(j->hybrid, x, y);
            if (drift_image_pixel(&j->g->depth, x, y)[0] > 0.0f) {
                drift_vec3 a = temporal_demodulation(j->g, x, y);
                const float *l = drift_image_pixel(j->light, x, y);
                h = drift_vec3_add(h, drift_vec3_make(a.x * l[0], a.y * l[1], a.z * l[2]));
            }
            drift_image_set3(j->out, x, y, h);
        }
    }
}

// Each pixel takes the half-size sample, among the 3 x 3 around its own, whose hit distance
// is relatively closest to its G-buffer point's (a miss: one that missed); ties keep the
// nearest. `depth` is the half-size path tracer's distance along the ray (0: a miss).
static void upsample_rows(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    const rows_job *j = user;
    const drift_image *half = j->half;
    for (int32_t y = (int32_t)begin; y < (int32_t)end; ++y) {
        for (int32_t x = 0; x < j->m->width; ++x) {
            bool hit = drift_image_pixel(&j->g->depth, x, y)[0] > 0.0f;
            float d = hit ? drift_vec3_length(drift_vec3_sub(
                                drift_image_get3(&j->g->position, x, y), j->camera->position))
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
                float dq = drift_image_pixel(j->depth, qx, qy)[0];
                float e =
                    hit ? (dq > 0.0f ? fabsf(dq - d) / d : INFINITY) : (dq > 0.0f ? 1.0f : 0.0f);
                if (e < best) {
                    best = e;
                    bx = qx;
                    by = qy;
                }
            }
            drift_image_set3(&j->m->upsampled, x, y, drift_image_get3(half, bx, by));
        }
    }
}

// Whether pixel (x, y) gets a sample in frame k of a period-P refinement: its rank in the 4x4
// Bayer matrix, scaled to 0..P-1, is k mod P (the lowest ranks are the most spread: P = 4 takes
// one pixel of each 2x2 quad a frame).
static bool sampled_in_frame(int32_t x, int32_t y, uint32_t k, int32_t period)
{
    static const uint8_t bayer[4][4] = {
        { 0, 8, 2, 10 }, { 12, 4, 14, 6 }, { 3, 11, 1, 9 }, { 15, 7, 13, 5 }
    };
    return (uint32_t)(bayer[y & 3][x & 3] * period / 16) == k % (uint32_t)period;
}

// This frame's samples for its share of the pixels (period > 1): one path each, sample 0 of
// the frame's path tracer, exactly as drift_pt_render_samples would trace it; a non-finite
// one (the path tracer drops those) counts as none.
static void sample_rows(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    const rows_job *j = user;
    drift_moving_refine *m = j->m;
    for (int32_t y = (int32_t)begin; y < (int32_t)end; ++y) {
        for (int32_t x = 0; x < m->width; ++x) {
            size_t i = (size_t)y * (size_t)m->width + (size_t)x;
            drift_vec3 c = drift_vec3_splat(0.0f);
            bool ok = sampled_in_frame(x, y, m->frame, m->s.period);
            if (ok) {
                c = drift_pt_trace_sample(j->pt, x, y, 0);
                ok = isfinite(c.x) && isfinite(c.y) && isfinite(c.z);
                c = ok ? c : drift_vec3_splat(0.0f);
            }
            m->sampled[i] = ok ? 1 : 0;
            drift_image_set3(&m->samples, x, y, c);
        }
    }
}

// The variance of the mean in the image's units: the lighting's times the albedo's luminance
// squared (a miss: 0, the hybrid and the path tracer both show the same sky). A pixel the
// layer left unknown (variance < 0, only with period > 1) shows the hybrid with variance 0:
// the blend sees the two agree there.
static void fvar_rows(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    const rows_job *j = user;
    drift_moving_refine *m = j->m;
    for (int32_t y = (int32_t)begin; y < (int32_t)end; ++y) {
        for (int32_t x = 0; x < m->width; ++x) {
            bool hit = drift_image_pixel(&j->g->depth, x, y)[0] > 0.0f;
            float v = drift_image_pixel(j->light, x, y)[3];
            if (hit && v < 0.0f) {
                drift_image_set3(&m->path, x, y, drift_image_get3(j->hybrid, x, y));
                v = 0.0f;
            }
            float a = hit ? drift_luminance(temporal_demodulation(j->g, x, y)) : 0.0f;
            drift_image_pixel(&m->fvar, x, y)[0] = v * a * a;
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
    bool half = m->s.scale == 2, part = m->s.period > 1;
    drift_pt_params p = { .width = half ? (m->width + 1) / 2 : m->width,
                          .height = half ? (m->height + 1) / 2 : m->height,
                          .seed = m->s.seed + m->frame,
                          .max_depth = m->s.max_depth,
                          .texture_filter_spp = (uint32_t)m->s.max_history,
                          .camera = camera };
    drift_pt *pt = NULL;
    rows_job job = { .m = m, .g = g, .camera = camera, .frame = frame, .hybrid = hybrid };
    size_t rows = (size_t)m->height;
    drift_result r = drift_pt_create(m->ctx, m->scene, m->accel, &p, &pt);
    drift_image beauty;
    if (r == DRIFT_OK && part) {
        job.pt = pt;
        drift_parallel_for(m->ctx, rows, 1, sample_rows, &job);
        r = cancel && atomic_load(cancel) ? DRIFT_ERR_CANCELLED : DRIFT_OK;
        beauty = m->samples;
    } else if (r == DRIFT_OK) {
        r = drift_pt_render_samples(pt, 1, cancel);
        if (r == DRIFT_OK) {
            r = drift_pt_resolve(pt, DRIFT_PT_AOV_BEAUTY, &beauty);
        }
    }
    drift_image depth;
    if (r == DRIFT_OK && half &&
        (r = drift_pt_resolve(pt, DRIFT_PT_AOV_DEPTH, &depth)) == DRIFT_OK) {
        job.half = &beauty;
        job.depth = &depth;
        drift_parallel_for(m->ctx, rows, 4, upsample_rows, &job);
        beauty = m->upsampled; // the layer reads it as the frame's samples
    }
    if (r != DRIFT_OK) {
        drift_pt_destroy(pt);
        return r;
    }
    m->frame += 1;
    job.beauty = &beauty;
    if (m->s.residual) {
        drift_parallel_for(m->ctx, rows, 4, residual_rows, &job);
    }
    const drift_image *filtered = temporal_layer_apply(
        m->t, &m->layer, g, &beauty, part ? m->sampled : NULL, m->s.filter_passes, NULL);
    drift_pt_destroy(pt);
    job.light = filtered;
    if (m->s.residual) {
        job.out = &m->path;
        drift_parallel_for(m->ctx, rows, 4, add_residual_rows, &job);
    } else {
        temporal_remodulate(m->t, g, filtered, hybrid, &m->path);
    }
    drift_parallel_for(m->ctx, rows, 4, fvar_rows, &job);
    // The hybrid's error is judged against the filtered accumulation (its variance the
    // filter's estimate): the raw mean of a few one-sample frames is too noisy to show the
    // hybrid's bias under it (the weight stayed near 0.1-0.2 on both measured scenes).
    temporal_error_blend(m->ctx, hybrid, &m->path, &m->fvar, &m->path, &m->fvar, 1.0f, m->s.radius,
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
