// Temporal reuse (drift/temporal.h): reprojection, disocclusion tests, accumulation of the
// demodulated lighting and its luminance moments, and the variance-guided a-trous filter.
#include "drift/temporal.h"

#include "drift/math.h"
#include "temporal_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

enum {
    PLANES = 2 // current and previous
};

struct drift_temporal {
    drift_context *ctx;
    int32_t width, height;
    drift_temporal_settings s;
    int cur; // index of the current frame's planes
    bool has_prev;
    temporal_layer hybrid;        // the hybrid frame's lighting
    drift_image depth[PLANES];    // 1
    drift_image position[PLANES]; // 3: world position
    drift_image normal[PLANES];   // 3
    drift_image material[PLANES]; // 1
    // The last apply's reprojection: each pixel's bilinear taps around p + motion in the
    // previous frame (x0, y0 the top-left one) and their weights, 0 where a tap was rejected.
    drift_image tap_origin; // 2: x0, y0
    drift_image tap_weight; // 4
    drift_image out;        // 3
};

drift_temporal_settings drift_temporal_settings_resolve(const drift_temporal_settings *in)
{
    drift_temporal_settings s = in ? *in : (drift_temporal_settings){ 0 };
    s.max_history = s.max_history ? s.max_history : 32;
    s.moments_alpha = s.moments_alpha > 0.0f ? s.moments_alpha : 0.2f;
    s.depth_tolerance = s.depth_tolerance > 0.0f ? s.depth_tolerance : 0.05f;
    s.normal_tolerance = s.normal_tolerance > 0.0f ? s.normal_tolerance : 0.9f;
    s.filter_passes = s.no_filter ? 0 : (s.filter_passes ? s.filter_passes : 3);
    s.phi_luminance = s.phi_luminance > 0.0f ? s.phi_luminance : 4.0f;
    s.depth_sigma = s.depth_sigma > 0.0f ? s.depth_sigma : 1.0f;
    s.moving_refine_history = s.moving_refine_history ? s.moving_refine_history : 32;
    s.moving_history = s.moving_history ? s.moving_history : 8;
    return s;
}

drift_result temporal_layer_init(drift_context *ctx, int32_t width, int32_t height,
                                 int32_t max_history, temporal_layer *L)
{
    *L = (temporal_layer){ .max_history = max_history };
    drift_result r = drift_image_create(ctx, width, height, 1, &L->sample_lum);
    for (int k = 0; k < PLANES && r == DRIFT_OK; ++k) {
        if ((r = drift_image_create(ctx, width, height, 3, &L->light[k])) != DRIFT_OK ||
            (r = drift_image_create(ctx, width, height, 2, &L->moments[k])) != DRIFT_OK ||
            (r = drift_image_create(ctx, width, height, 1, &L->length[k])) != DRIFT_OK ||
            (r = drift_image_create(ctx, width, height, 4, &L->filter[k])) != DRIFT_OK) {
            break;
        }
    }
    if (r != DRIFT_OK) {
        temporal_layer_free(ctx, L);
    }
    return r;
}

void temporal_layer_free(drift_context *ctx, temporal_layer *L)
{
    for (int k = 0; k < PLANES; ++k) {
        drift_image_destroy(ctx, &L->light[k]);
        drift_image_destroy(ctx, &L->moments[k]);
        drift_image_destroy(ctx, &L->length[k]);
        drift_image_destroy(ctx, &L->filter[k]);
    }
    drift_image_destroy(ctx, &L->sample_lum);
}

void drift_temporal_destroy(drift_temporal *t)
{
    if (!t) {
        return;
    }
    temporal_layer_free(t->ctx, &t->hybrid);
    for (int k = 0; k < PLANES; ++k) {
        drift_image_destroy(t->ctx, &t->depth[k]);
        drift_image_destroy(t->ctx, &t->position[k]);
        drift_image_destroy(t->ctx, &t->normal[k]);
        drift_image_destroy(t->ctx, &t->material[k]);
    }
    drift_image_destroy(t->ctx, &t->tap_origin);
    drift_image_destroy(t->ctx, &t->tap_weight);
    drift_image_destroy(t->ctx, &t->out);
    drift_free(t->ctx, t);
}

drift_result drift_temporal_create(drift_context *ctx, int32_t width, int32_t height,
                                   const drift_temporal_settings *settings, drift_temporal **out)
{
    if (!out) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    *out = NULL;
    drift_temporal_settings s = drift_temporal_settings_resolve(settings);
    if (width < 1 || height < 1 || s.max_history < 1 || s.max_history > 4096 ||
        !(s.moments_alpha <= 1.0f) || !(s.depth_tolerance <= 1.0f) ||
        !(s.normal_tolerance <= 1.0f) || s.filter_passes < 0 || s.filter_passes > 8 ||
        !isfinite(s.phi_luminance) || !isfinite(s.depth_sigma) || s.moving_refine_history < 1 ||
        s.moving_refine_history > 4096 || s.moving_refine_period < 0 ||
        s.moving_refine_period > 16 || (s.moving_refine_period & (s.moving_refine_period - 1)) ||
        s.moving_refine_passes < 0 || s.moving_refine_passes > 8 || s.history_resample < 0 ||
        s.history_resample > 1 || s.moving_history < 1 || s.moving_history > 4096) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, NULL, 0,
                  "temporal: size %dx%d or settings out of range (drift/temporal.h)", width,
                  height);
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    drift_temporal *t = drift_alloc(ctx, sizeof *t);
    if (!t) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    t->ctx = ctx;
    t->width = width;
    t->height = height;
    t->s = s;
    drift_result r = temporal_layer_init(ctx, width, height, s.max_history, &t->hybrid);
    for (int k = 0; k < PLANES && r == DRIFT_OK; ++k) {
        if ((r = drift_image_create(ctx, width, height, 1, &t->depth[k])) != DRIFT_OK ||
            (r = drift_image_create(ctx, width, height, 3, &t->position[k])) != DRIFT_OK ||
            (r = drift_image_create(ctx, width, height, 3, &t->normal[k])) != DRIFT_OK ||
            (r = drift_image_create(ctx, width, height, 1, &t->material[k])) != DRIFT_OK) {
            break;
        }
    }
    if (r == DRIFT_OK) {
        r = drift_image_create(ctx, width, height, 2, &t->tap_origin);
    }
    if (r == DRIFT_OK) {
        r = drift_image_create(ctx, width, height, 4, &t->tap_weight);
    }
    if (r == DRIFT_OK) {
        r = drift_image_create(ctx, width, height, 3, &t->out);
    }
    if (r != DRIFT_OK) {
        drift_temporal_destroy(t);
        return r;
    }
    *out = t;
    return DRIFT_OK;
}

void drift_temporal_reset(drift_temporal *t)
{
    if (t) {
        t->has_prev = false;
        t->hybrid.has_prev = false;
    }
}

void temporal_size(const drift_temporal *t, int32_t *width, int32_t *height)
{
    *width = t->width;
    *height = t->height;
}

const drift_image *drift_temporal_image(const drift_temporal *t)
{
    return t ? &t->out : NULL;
}

const drift_image *drift_temporal_history(const drift_temporal *t)
{
    return t ? &t->hybrid.length[t->cur] : NULL;
}

// --- REPROJECTION AND ACCUMULATION ---

typedef struct frame_job {
    drift_temporal *t;
    temporal_layer *layer;
    const drift_gbuffer *g;
    const drift_image *color;
    drift_image *raw_variance; // may be NULL
    const uint8_t *sampled;    // the pixels `color` has a sample for (NULL: all)
    int cur, prev;
} frame_job;

static bool job_sampled(const frame_job *job, int32_t x, int32_t y)
{
    return !job->sampled || job->sampled[(size_t)y * (size_t)job->t->width + (size_t)x];
}

drift_vec3 temporal_demodulation(const drift_gbuffer *g, int32_t x, int32_t y)
{
    drift_vec3 a = drift_image_get3(&g->albedo, x, y);
    return drift_vec3_make(fmaxf(a.x, 0.01f), fmaxf(a.y, 0.01f), fmaxf(a.z, 0.01f));
}

// Whether the previous frame's pixel (x, y) shows the surface at world point p (view depth z)
// with normal n and material m: the same material, normals within normal_tolerance, and the
// previous point within depth_tolerance x z of p's tangent plane (a plane test, not a depth
// test: sub-pixel offsets along a slanted surface keep their history).
static bool tap_valid(const frame_job *job, int32_t x, int32_t y, float material, drift_vec3 n,
                      drift_vec3 p, float z)
{
    const drift_temporal *t = job->t;
    if (x < 0 || y < 0 || x >= t->width || y >= t->height) {
        return false;
    }
    int pr = job->prev;
    if (!(drift_image_pixel(&t->depth[pr], x, y)[0] > 0.0f) ||
        drift_image_pixel(&t->material[pr], x, y)[0] != material) {
        return false;
    }
    if (drift_vec3_dot(drift_image_get3(&t->normal[pr], x, y), n) < t->s.normal_tolerance) {
        return false;
    }
    drift_vec3 q = drift_image_get3(&t->position[pr], x, y);
    return fabsf(drift_vec3_dot(drift_vec3_sub(q, p), n)) <= t->s.depth_tolerance * z;
}

// This frame's G-buffer into the current planes, and each pixel's reprojection taps.
static void reproject_rows(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    const frame_job *job = user;
    drift_temporal *t = job->t;
    const drift_gbuffer *g = job->g;
    int c = job->cur;
    for (int32_t y = (int32_t)begin; y < (int32_t)end; ++y) {
        for (int32_t x = 0; x < t->width; ++x) {
            float z = drift_image_pixel(&g->depth, x, y)[0];
            float material = drift_image_pixel(&g->material_id, x, y)[0];
            drift_vec3 n = drift_image_get3(&g->normal, x, y);
            drift_image_pixel(&t->depth[c], x, y)[0] = z;
            drift_image_pixel(&t->material[c], x, y)[0] = material;
            drift_image_set3(&t->normal[c], x, y, n);
            drift_image_set3(&t->position[c], x, y, drift_image_get3(&g->position, x, y));
            float *origin = drift_image_pixel(&t->tap_origin, x, y);
            float *tw = drift_image_pixel(&t->tap_weight, x, y);
            tw[0] = tw[1] = tw[2] = tw[3] = 0.0f;
            origin[0] = (float)x;
            origin[1] = (float)y;
            if (!(z > 0.0f) || !t->has_prev) { // a miss, or no previous frame: no history
                continue;
            }
            // The valid bilinear taps around p + motion.
            const float *m = drift_image_pixel(&g->motion, x, y);
            // Where the point was: the history's positions are the previous frame's.
            drift_vec3 p = drift_image_get3(&g->position, x, y);
            if (g->object_motion) {
                p = drift_vec3_add(p, g->object_motion[(size_t)y * (size_t)g->width + (size_t)x]);
            }
            float qx = (float)x + m[0], qy = (float)y + m[1];
            int32_t x0 = (int32_t)floorf(qx), y0 = (int32_t)floorf(qy);
            float fx = qx - (float)x0, fy = qy - (float)y0;
            origin[0] = (float)x0;
            origin[1] = (float)y0;
            for (int k = 0; k < 4; ++k) {
                int32_t tx = x0 + (k & 1), ty = y0 + (k >> 1);
                float w = ((k & 1) ? fx : 1.0f - fx) * ((k >> 1) ? fy : 1.0f - fy);
                if (w > 0.0f && tap_valid(job, tx, ty, material, n, p, z)) {
                    tw[k] = w;
                }
            }
        }
    }
}

// The Catmull-Rom weights of the 4 taps at offsets -1, 0, 1, 2 for a point f in [0, 1) past
// tap 0.
static void catmull_rom_weights(float f, float w[4])
{
    w[0] = f * (-0.5f + f * (1.0f - 0.5f * f));
    w[1] = 1.0f + f * f * (-2.5f + 1.5f * f);
    w[2] = f * (0.5f + f * (2.0f - 1.5f * f));
    w[3] = f * f * (-0.5f + 0.5f * f);
}

// A pixel whose motion vector is longer than this has moved: its history is resampled off
// the pixel grid this frame.
#define MOVING_PIXELS 0.05f

// The frames pixel (x, y)'s accumulation averages at most: the layer's max_history, or, in the
// hybrid frame's layer, the shorter moving_history where the pixel moved since the last frame
// (the camera's or its mesh's move; the path-traced refinement's layers keep theirs: their
// samples are noisy, not biased). Measured (docs/lab/2026-12-08-issue-47-s8-tframe.md): under a
// moving camera an 8-frame history beat 32 on both scenes (each frame's bilinear resampling blurs a
// long one), while a still camera needs the long one to converge.
static int32_t history_cap(const drift_temporal *t, const temporal_layer *L, const drift_gbuffer *g,
                           int32_t x, int32_t y)
{
    if (L != &t->hybrid) {
        return L->max_history;
    }
    const float *m = drift_image_pixel(&g->motion, x, y);
    bool moved = m[0] * m[0] + m[1] * m[1] > MOVING_PIXELS * MOVING_PIXELS;
    if (!moved && g->object_motion) {
        drift_vec3 d = g->object_motion[(size_t)y * (size_t)g->width + (size_t)x];
        moved = drift_vec3_dot(d, d) > 0.0f;
    }
    int32_t cap = t->s.moving_history < L->max_history ? t->s.moving_history : L->max_history;
    return moved ? cap : L->max_history;
}

// --temporal-resample catmull-rom: the history's lighting at pixel (x, y)'s reprojected point
// from the 4 x 4 taps around it, each of which must show the pixel's surface (tap_valid) and
// hold history; clamped per channel to the 2 x 2 central taps' range so the negative lobes
// cannot ring. False (keep the bilinear value) where a tap fails. Bilinear resampling low-pass
// filters the history once a frame, so a moving camera's 32-frame history is blurred by up to
// 32 such filters; this one keeps more of its detail.
static bool resample_catmull_rom(const frame_job *job, const temporal_layer *L, int32_t x,
                                 int32_t y, drift_vec3 *out)
{
    const drift_gbuffer *g = job->g;
    int pr = job->prev;
    const float *m = drift_image_pixel(&g->motion, x, y);
    float qx = (float)x + m[0], qy = (float)y + m[1];
    int32_t x0 = (int32_t)floorf(qx), y0 = (int32_t)floorf(qy);
    float wx[4], wy[4];
    catmull_rom_weights(qx - (float)x0, wx);
    catmull_rom_weights(qy - (float)y0, wy);
    float z = drift_image_pixel(&g->depth, x, y)[0];
    float material = drift_image_pixel(&g->material_id, x, y)[0];
    drift_vec3 n = drift_image_get3(&g->normal, x, y);
    drift_vec3 p = drift_image_get3(&g->position, x, y);
    if (g->object_motion) {
        p = drift_vec3_add(p, g->object_motion[(size_t)y * (size_t)g->width + (size_t)x]);
    }
    drift_vec3 sum = drift_vec3_splat(0.0f);
    drift_vec3 lo = drift_vec3_splat(INFINITY), hi = drift_vec3_splat(-INFINITY);
    for (int j = 0; j < 4; ++j) {
        for (int i = 0; i < 4; ++i) {
            int32_t tx = x0 - 1 + i, ty = y0 - 1 + j;
            if (!tap_valid(job, tx, ty, material, n, p, z) ||
                !(drift_image_pixel(&L->length[pr], tx, ty)[0] > 0.0f)) {
                return false;
            }
            drift_vec3 v = drift_image_get3(&L->light[pr], tx, ty);
            sum = drift_vec3_fma(sum, v, wx[i] * wy[j]);
            if ((i == 1 || i == 2) && (j == 1 || j == 2)) {
                lo = drift_vec3_make(fminf(lo.x, v.x), fminf(lo.y, v.y), fminf(lo.z, v.z));
                hi = drift_vec3_make(fmaxf(hi.x, v.x), fmaxf(hi.y, v.y), fmaxf(hi.z, v.z));
            }
        }
    }
    *out = drift_vec3_make(fminf(fmaxf(sum.x, lo.x), hi.x), fminf(fmaxf(sum.y, lo.y), hi.y),
                           fminf(fmaxf(sum.z, lo.z), hi.z));
    return true;
}

// Accumulates the job's colour into its layer through the taps: N = min(N_prev + 1, max),
// alpha = 1 / N, the lighting and the luminance moments blended with the reprojected history.
// A pixel without a sample (job->sampled) keeps the reprojected history as it is (N, moments).
static void accumulate_rows(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    const frame_job *job = user;
    drift_temporal *t = job->t;
    temporal_layer *L = job->layer;
    const drift_gbuffer *g = job->g;
    int c = job->cur, pr = job->prev;
    for (int32_t y = (int32_t)begin; y < (int32_t)end; ++y) {
        for (int32_t x = 0; x < t->width; ++x) {
            float z = drift_image_pixel(&g->depth, x, y)[0];
            float *len = drift_image_pixel(&L->length[c], x, y);
            float *mom = drift_image_pixel(&L->moments[c], x, y);
            if (!(z > 0.0f)) { // a miss: passes through, no history
                len[0] = 0.0f;
                mom[0] = mom[1] = 0.0f;
                drift_image_set3(&L->light[c], x, y, drift_vec3_splat(0.0f));
                drift_image_pixel(&L->sample_lum, x, y)[0] = 0.0f;
                continue;
            }
            bool has_sample = job_sampled(job, x, y);
            drift_vec3 l = drift_vec3_splat(0.0f);
            if (has_sample) {
                drift_vec3 a = temporal_demodulation(g, x, y);
                drift_vec3 col = drift_vec3_sub(drift_image_get3(job->color, x, y),
                                                drift_image_get3(&g->emission, x, y));
                l = drift_vec3_make(col.x / a.x, col.y / a.y, col.z / a.z);
            }
            float lum = drift_luminance(l);
            drift_image_pixel(&L->sample_lum, x, y)[0] = lum;
            drift_vec3 hist = drift_vec3_splat(0.0f);
            float hist_mom[2] = { 0.0f, 0.0f };
            float hist_len = 0.0f, weight = 0.0f;
            if (L->has_prev) {
                const float *origin = drift_image_pixel(&t->tap_origin, x, y);
                const float *tw = drift_image_pixel(&t->tap_weight, x, y);
                int32_t x0 = (int32_t)origin[0], y0 = (int32_t)origin[1];
                for (int k = 0; k < 4; ++k) {
                    float w = tw[k];
                    int32_t tx = x0 + (k & 1), ty = y0 + (k >> 1);
                    if (!(w > 0.0f) || !(drift_image_pixel(&L->length[pr], tx, ty)[0] > 0.0f)) {
                        continue;
                    }
                    hist = drift_vec3_fma(hist, drift_image_get3(&L->light[pr], tx, ty), w);
                    const float *hm = drift_image_pixel(&L->moments[pr], tx, ty);
                    hist_mom[0] += w * hm[0];
                    hist_mom[1] += w * hm[1];
                    hist_len += w * drift_image_pixel(&L->length[pr], tx, ty)[0];
                    weight += w;
                }
            }
            float n_frames = 1.0f;
            if (weight > 1e-3f) {
                float inv = 1.0f / weight;
                hist = drift_vec3_scale(hist, inv);
                drift_vec3 sharp;
                // (It needs the 2 x 2 taps valid too: the weight is whole.)
                if (t->s.history_resample == 1 && weight > 0.999f &&
                    resample_catmull_rom(job, L, x, y, &sharp)) {
                    hist = sharp;
                }
                hist_mom[0] *= inv;
                hist_mom[1] *= inv;
                n_frames = fminf(hist_len * inv + (has_sample ? 1.0f : 0.0f),
                                 (float)history_cap(t, L, g, x, y));
            }
            if (!has_sample) { // the history as it is, or nothing known (N = 0)
                bool known = weight > 1e-3f;
                len[0] = known ? n_frames : 0.0f;
                mom[0] = known ? hist_mom[0] : 0.0f;
                mom[1] = known ? hist_mom[1] : 0.0f;
                drift_image_set3(&L->light[c], x, y, known ? hist : drift_vec3_splat(0.0f));
                continue;
            }
            float alpha = 1.0f / n_frames;
            float alpha_m = fmaxf(alpha, t->s.moments_alpha);
            drift_vec3 acc = n_frames > 1.0f ? drift_vec3_add(drift_vec3_scale(hist, 1.0f - alpha),
                                                              drift_vec3_scale(l, alpha))
                                             : l;
            mom[0] = n_frames > 1.0f ? (1.0f - alpha_m) * hist_mom[0] + alpha_m * lum : lum;
            mom[1] =
                n_frames > 1.0f ? (1.0f - alpha_m) * hist_mom[1] + alpha_m * lum * lum : lum * lum;
            len[0] = n_frames;
            drift_image_set3(&L->light[c], x, y, acc);
        }
    }
}

// The variance of each pixel's accumulated lighting into filter[0]'s fourth channel (and the
// lighting into its first three): the temporal moments' variance over N frames, or below 4
// frames the 7x7 spatial moments of this frame's samples over the same surface.
static void variance_rows(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    const frame_job *job = user;
    drift_temporal *t = job->t;
    temporal_layer *L = job->layer;
    int c = job->cur;
    for (int32_t y = (int32_t)begin; y < (int32_t)end; ++y) {
        for (int32_t x = 0; x < t->width; ++x) {
            float *f = drift_image_pixel(&L->filter[0], x, y);
            drift_vec3 l = drift_image_get3(&L->light[c], x, y);
            f[0] = l.x;
            f[1] = l.y;
            f[2] = l.z;
            float n_frames = drift_image_pixel(&L->length[c], x, y)[0];
            if (n_frames <= 0.0f) {
                // A surface with neither sample nor history (only with job->sampled): unknown.
                f[3] = drift_image_pixel(&t->depth[c], x, y)[0] > 0.0f ? -1.0f : 0.0f;
                if (job->raw_variance) {
                    drift_image_pixel(job->raw_variance, x, y)[0] = 0.0f;
                }
                continue;
            }
            const float *mom = drift_image_pixel(&L->moments[c], x, y);
            float var = fmaxf(mom[1] - mom[0] * mom[0], 0.0f);
            if (n_frames < 4.0f) {
                float z = drift_image_pixel(&t->depth[c], x, y)[0];
                drift_vec3 n = drift_image_get3(&t->normal[c], x, y);
                float m1 = 0.0f, m2 = 0.0f, wsum = 0.0f;
                for (int32_t dy = -3; dy <= 3; ++dy) {
                    for (int32_t dx = -3; dx <= 3; ++dx) {
                        int32_t qx = x + dx, qy = y + dy;
                        if (qx < 0 || qy < 0 || qx >= t->width || qy >= t->height) {
                            continue;
                        }
                        float zq = drift_image_pixel(&t->depth[c], qx, qy)[0];
                        if (!(zq > 0.0f) || fabsf(zq - z) > 0.1f * z ||
                            drift_vec3_dot(drift_image_get3(&t->normal[c], qx, qy), n) < 0.8f ||
                            !job_sampled(job, qx, qy)) {
                            continue;
                        }
                        float s = drift_image_pixel(&L->sample_lum, qx, qy)[0];
                        m1 += s;
                        m2 += s * s;
                        wsum += 1.0f;
                    }
                }
                // With a sample mask the history may hold samples this frame's neighbours do
                // not show (a pixel's last sample is up to P frames old): the larger of the two.
                // None sampled near an unsampled pixel: the moments' variance.
                if (wsum > 0.0f) {
                    m1 /= wsum;
                    float spatial = fmaxf(m2 / wsum - m1 * m1, 0.0f);
                    var = job->sampled ? fmaxf(var, spatial) : spatial;
                }
            }
            f[3] = var / n_frames; // the variance of the mean of N frames
            if (job->raw_variance) {
                drift_image_pixel(job->raw_variance, x, y)[0] = f[3];
            }
        }
    }
}

// --- THE VARIANCE-GUIDED FILTER ---

typedef struct filter_job {
    const drift_temporal *t;
    const drift_image *in;
    drift_image *out;
    int cur;
    int32_t step;
} filter_job;

static void filter_rows(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    const filter_job *job = user;
    const drift_temporal *t = job->t;
    static const float kernel[3] = { 3.0f / 8.0f, 1.0f / 4.0f, 1.0f / 16.0f };
    static const float gauss[2] = { 0.5f, 0.25f };
    int c = job->cur;
    for (int32_t y = (int32_t)begin; y < (int32_t)end; ++y) {
        for (int32_t x = 0; x < t->width; ++x) {
            const float *p = drift_image_pixel(job->in, x, y);
            float *o = drift_image_pixel(job->out, x, y);
            float z = drift_image_pixel(&t->depth[c], x, y)[0];
            if (!(z > 0.0f)) {
                memcpy(o, p, 4 * sizeof *o);
                continue;
            }
            // SVGF's 3x3 Gaussian of the variance steers the luminance weight. A pixel with
            // variance < 0 is unknown (temporal_layer_apply's `sampled`): no tap takes it, and
            // its own value is its known taps' mean without the luminance weight.
            bool known = p[3] >= 0.0f;
            float var = 0.0f, gw = 0.0f;
            for (int32_t dy = -1; dy <= 1; ++dy) {
                for (int32_t dx = -1; dx <= 1; ++dx) {
                    int32_t qx = x + dx, qy = y + dy;
                    if (qx < 0 || qy < 0 || qx >= t->width || qy >= t->height ||
                        !(drift_image_pixel(&t->depth[c], qx, qy)[0] > 0.0f) ||
                        drift_image_pixel(job->in, qx, qy)[3] < 0.0f) {
                        continue;
                    }
                    float w = gauss[abs(dx)] * gauss[abs(dy)];
                    var += w * drift_image_pixel(job->in, qx, qy)[3];
                    gw += w;
                }
            }
            var = gw > 0.0f ? var / gw : 0.0f;
            float lum_p = drift_luminance(drift_vec3_make(p[0], p[1], p[2]));
            float phi_l = t->s.phi_luminance * sqrtf(var) + 1e-4f;
            float phi_z = t->s.depth_sigma * (float)job->step * z * 0.02f;
            drift_vec3 n = drift_image_get3(&t->normal[c], x, y);
            float material = drift_image_pixel(&t->material[c], x, y)[0];
            float sum[4] = { 0 }, wsum = 0.0f;
            for (int32_t j = -2; j <= 2; ++j) {
                for (int32_t i = -2; i <= 2; ++i) {
                    int32_t qx = x + i * job->step, qy = y + j * job->step;
                    if (qx < 0 || qy < 0 || qx >= t->width || qy >= t->height) {
                        continue;
                    }
                    float zq = drift_image_pixel(&t->depth[c], qx, qy)[0];
                    if (!(zq > 0.0f) || drift_image_pixel(&t->material[c], qx, qy)[0] != material) {
                        continue;
                    }
                    const float *q = drift_image_pixel(job->in, qx, qy);
                    if (q[3] < 0.0f) {
                        continue;
                    }
                    float nd =
                        fmaxf(drift_vec3_dot(drift_image_get3(&t->normal[c], qx, qy), n), 0.0f);
                    float nd2 = nd * nd, nd4 = nd2 * nd2, nd8 = nd4 * nd4, nd16 = nd8 * nd8;
                    float nd32 = nd16 * nd16, nd64 = nd32 * nd32;
                    float w_n = nd64 * nd64; // ^128
                    float lum_q = drift_luminance(drift_vec3_make(q[0], q[1], q[2]));
                    float w = kernel[abs(i)] * kernel[abs(j)] * w_n *
                              expf(-fabsf(z - zq) / phi_z -
                                   (known ? fabsf(lum_p - lum_q) / phi_l : 0.0f));
                    sum[0] += w * q[0];
                    sum[1] += w * q[1];
                    sum[2] += w * q[2];
                    sum[3] += w * w * q[3];
                    wsum += w;
                }
            }
            // A known centre tap always counts (weight 9/64), so wsum > 0 but for an unknown
            // pixel with no known tap, which stays unknown.
            if (!(wsum > 0.0f)) {
                memcpy(o, p, 4 * sizeof *o);
                continue;
            }
            o[0] = sum[0] / wsum;
            o[1] = sum[1] / wsum;
            o[2] = sum[2] / wsum;
            o[3] = sum[3] / (wsum * wsum);
        }
    }
}

typedef struct remodulate_job {
    const drift_temporal *t;
    const drift_gbuffer *g;
    const drift_image *light, *misses;
    drift_image *out;
} remodulate_job;

static void remodulate_rows(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    const remodulate_job *job = user;
    const drift_gbuffer *g = job->g;
    for (int32_t y = (int32_t)begin; y < (int32_t)end; ++y) {
        for (int32_t x = 0; x < job->t->width; ++x) {
            if (!(drift_image_pixel(&g->depth, x, y)[0] > 0.0f)) {
                drift_image_set3(job->out, x, y, drift_image_get3(job->misses, x, y));
                continue;
            }
            const float *l = drift_image_pixel(job->light, x, y);
            drift_vec3 a = temporal_demodulation(g, x, y);
            drift_vec3 e = drift_image_get3(&g->emission, x, y);
            drift_image_set3(
                job->out, x, y,
                drift_vec3_add(e, drift_vec3_make(a.x * l[0], a.y * l[1], a.z * l[2])));
        }
    }
}

void temporal_remodulate(drift_temporal *t, const drift_gbuffer *g, const drift_image *light,
                         const drift_image *misses, drift_image *out)
{
    remodulate_job job = { .t = t, .g = g, .light = light, .misses = misses, .out = out };
    drift_parallel_for(t->ctx, (size_t)t->height, 4, remodulate_rows, &job);
}

const drift_image *temporal_layer_apply(drift_temporal *t, temporal_layer *L,
                                        const drift_gbuffer *g, const drift_image *color,
                                        const uint8_t *sampled, int32_t passes,
                                        drift_image *raw_variance)
{
    frame_job job = { .t = t,
                      .layer = L,
                      .g = g,
                      .color = color,
                      .raw_variance = raw_variance,
                      .sampled = sampled,
                      .cur = t->cur,
                      .prev = t->cur ^ 1 };
    size_t rows = (size_t)t->height;
    drift_parallel_for(t->ctx, rows, 4, accumulate_rows, &job);
    drift_parallel_for(t->ctx, rows, 4, variance_rows, &job);
    for (int32_t pass = 0; pass < passes; ++pass) {
        filter_job fj = { .t = t,
                          .in = &L->filter[pass & 1],
                          .out = &L->filter[(pass & 1) ^ 1],
                          .cur = t->cur,
                          .step = 1 << pass };
        drift_parallel_for(t->ctx, rows, 4, filter_rows, &fj);
    }
    L->has_prev = true;
    return &L->filter[passes & 1];
}

const drift_image *temporal_layer_light(const drift_temporal *t, const temporal_layer *L)
{
    return &L->light[t->cur];
}

drift_result drift_temporal_apply(drift_temporal *t, const drift_gbuffer *g,
                                  const drift_camera *camera, const drift_image *color)
{
    if (!t || !g || !camera || !color || color->channels < 3 || color->width != t->width ||
        color->height != t->height || g->width != t->width || g->height != t->height) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    t->cur ^= 1;
    frame_job job = { .t = t, .g = g, .cur = t->cur, .prev = t->cur ^ 1 };
    drift_parallel_for(t->ctx, (size_t)t->height, 4, reproject_rows, &job);
    const drift_image *filtered =
        temporal_layer_apply(t, &t->hybrid, g, color, NULL, t->s.filter_passes, NULL);
    temporal_remodulate(t, g, filtered, color, &t->out);
    (void)camera; // the motion vectors carry the camera's move
    t->has_prev = true;
    return DRIFT_OK;
}

bool drift_temporal_reseeds(const drift_hybrid_params *p)
{
    // ISM and IR reseed their VPLs without remaking the scene points (drift_ism_set_seed).
    return p->indirect != DRIFT_INDIRECT_MICRO && p->reflections != DRIFT_REFLECTIONS_MICRO &&
           p->reflections != DRIFT_REFLECTIONS_ENVMAP;
}

drift_result drift_temporal_prepare(drift_hybrid *frame, uint32_t base_seed, uint32_t k,
                                    drift_camera *camera)
{
    if (!frame || !camera) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    drift_hybrid_params p = drift_hybrid_get_params(frame);
    if (drift_temporal_reseeds(&p) && p.seed != base_seed + k) {
        p.seed = base_seed + k;
        drift_result r = drift_hybrid_set_params(frame, &p);
        if (r != DRIFT_OK) {
            return r;
        }
    }
    drift_vec2 jitter = drift_temporal_jitter(k);
    camera->film_shift_x += jitter.x;
    camera->film_shift_y += jitter.y;
    return DRIFT_OK;
}

// The radical inverse of k in `base`.
static float radical_inverse(uint32_t k, uint32_t base)
{
    float f = 1.0f, r = 0.0f;
    while (k > 0) {
        f /= (float)base;
        r += f * (float)(k % base);
        k /= base;
    }
    return r;
}

drift_vec2 drift_temporal_jitter(uint32_t frame)
{
    return (drift_vec2){ radical_inverse(frame + 1, 2) - 0.5f,
                         radical_inverse(frame + 1, 3) - 0.5f };
}
