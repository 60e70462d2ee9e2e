// Still refinement (drift/temporal.h): a still camera's path-traced accumulation, denoised, and
// blended into the temporal image where its estimated error is below the hybrid's.
#include "drift/denoise.h"
#include "drift/math.h"
#include "drift/pt.h"
#include "drift/temporal.h"
#include "temporal_internal.h"

#include <math.h>
#include <string.h>

struct drift_still_refine {
    drift_context *ctx;
    const drift_scene *scene;
    const drift_accel *accel;
    int32_t width, height;
    drift_still_refine_settings s;
    drift_pt *pt;        // NULL until the second frame of a still camera
    drift_camera camera; // the last frame's (unjittered)
    bool has_camera;
    drift_image out;      // 3: the shown image
    drift_image weight;   // 1: the path tracer's weight
    drift_image denoised; // 3: drift_denoise_feature's output (remade each frame)
    float *scratch[4];    // width x height: squared difference, variance, a blur's rows
};

static drift_still_refine_settings resolve(const drift_still_refine_settings *in)
{
    drift_still_refine_settings s = in ? *in : (drift_still_refine_settings){ 0 };
    s.spp = s.spp ? s.spp : (s.keeps_hybrid ? 1u : 4u);
    s.fade_samples = s.fade_samples ? s.fade_samples : 1u;
    s.denoised_error = s.denoised_error > 0.0f ? s.denoised_error : 0.25f;
    s.radius = s.radius > 0 ? s.radius : 4;
    return s;
}

void drift_still_refine_destroy(drift_still_refine *s)
{
    if (!s) {
        return;
    }
    drift_pt_destroy(s->pt);
    drift_image_destroy(s->ctx, &s->out);
    drift_image_destroy(s->ctx, &s->weight);
    drift_image_destroy(s->ctx, &s->denoised);
    for (int k = 0; k < 4; ++k) {
        drift_free(s->ctx, s->scratch[k]);
    }
    drift_free(s->ctx, s);
}

drift_result drift_still_refine_create(drift_context *ctx, const drift_scene *scene,
                                       const drift_accel *accel, int32_t width, int32_t height,
                                       const drift_still_refine_settings *settings,
                                       drift_still_refine **out)
{
    if (!ctx || !scene || !accel || !out || width < 1 || height < 1 ||
        (settings && (settings->radius < 0 || settings->radius > 32))) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    *out = NULL;
    drift_still_refine *s = drift_alloc(ctx, sizeof(*s));
    if (!s) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    *s = (drift_still_refine){
        .ctx = ctx, .scene = scene, .accel = accel, .width = width, .height = height
    };
    s->s = resolve(settings);
    drift_result r = drift_image_create(ctx, width, height, 3, &s->out);
    if (r == DRIFT_OK) {
        r = drift_image_create(ctx, width, height, 1, &s->weight);
    }
    for (int k = 0; k < 4 && r == DRIFT_OK; ++k) {
        s->scratch[k] = drift_alloc(ctx, sizeof(float) * (size_t)width * (size_t)height);
        r = s->scratch[k] ? DRIFT_OK : DRIFT_ERR_OUT_OF_MEMORY;
    }
    if (r != DRIFT_OK) {
        drift_still_refine_destroy(s);
        return r;
    }
    *out = s;
    return DRIFT_OK;
}

bool drift_still_refine_applies(const drift_hybrid_params *params)
{
    return params &&
           (!params->reflection_edits ||
            drift_reflection_edits_constraint_count(params->reflection_edits) == 0) &&
           drift_hybrid_params_technique(params, DRIFT_EFFECT_GLARE) == 0;
}

void drift_still_refine_reset(drift_still_refine *s)
{
    if (s) {
        drift_pt_destroy(s->pt);
        s->pt = NULL;
        s->has_camera = false;
    }
}

static void show_hybrid(drift_still_refine *s, const drift_image *hybrid)
{
    for (int32_t y = 0; y < s->height; ++y) {
        for (int32_t x = 0; x < s->width; ++x) {
            drift_image_set3(&s->out, x, y, drift_image_get3(hybrid, x, y));
            *drift_image_pixel(&s->weight, x, y) = 0.0f;
        }
    }
}

// Progressive: the path tracer's weight is at least n / (n + fade_samples), so the frozen
// hybrid start fades out as the samples come (the error blend alone keeps it wherever its bias
// hides under the path tracer's noise estimate).
static void fade_by_samples(drift_still_refine *s, const drift_image *hybrid)
{
    float n = (float)drift_pt_sample_count(s->pt);
    float floor_w = n / (n + (float)s->s.fade_samples);
    for (int32_t y = 0; y < s->height; ++y) {
        for (int32_t x = 0; x < s->width; ++x) {
            float *w = drift_image_pixel(&s->weight, x, y);
            if (*w >= floor_w) {
                continue;
            }
            *w = floor_w;
            drift_vec3 a = drift_image_get3(hybrid, x, y);
            drift_vec3 b = drift_image_get3(&s->denoised, x, y);
            drift_image_set3(&s->out, x, y, drift_vec3_fma(a, drift_vec3_sub(b, a), floor_w));
        }
    }
}

// The path-traced mean denoised by --denoise on's filter (the direct part apart).
static drift_result denoise(drift_still_refine *s)
{
    drift_image beauty, variance, albedo, normal, depth, direct, direct_var, indirect_var;
    drift_result r;
    if ((r = drift_pt_resolve(s->pt, DRIFT_PT_AOV_BEAUTY, &beauty)) != DRIFT_OK ||
        (r = drift_pt_resolve(s->pt, DRIFT_PT_AOV_VARIANCE, &variance)) != DRIFT_OK ||
        (r = drift_pt_resolve(s->pt, DRIFT_PT_AOV_FEATURE_ALBEDO, &albedo)) != DRIFT_OK ||
        (r = drift_pt_resolve(s->pt, DRIFT_PT_AOV_FEATURE_NORMAL, &normal)) != DRIFT_OK ||
        (r = drift_pt_resolve(s->pt, DRIFT_PT_AOV_FEATURE_DEPTH, &depth)) != DRIFT_OK ||
        (r = drift_pt_resolve(s->pt, DRIFT_PT_AOV_DIRECT, &direct)) != DRIFT_OK ||
        (r = drift_pt_resolve(s->pt, DRIFT_PT_AOV_DIRECT_VARIANCE, &direct_var)) != DRIFT_OK ||
        (r = drift_pt_resolve(s->pt, DRIFT_PT_AOV_INDIRECT_VARIANCE, &indirect_var)) != DRIFT_OK) {
        return r;
    }
    drift_denoise_inputs in = { &beauty, &albedo,     &normal,
                                &depth,  &variance,   drift_pt_sample_count(s->pt),
                                &direct, &direct_var, &indirect_var };
    drift_image_destroy(s->ctx, &s->denoised);
    return drift_denoise_feature(s->ctx, &in, &(drift_denoise_feature_params){ 0 }, &s->denoised,
                                 NULL);
}

drift_result drift_still_refine_apply(drift_still_refine *s, const drift_camera *camera,
                                      const drift_image *hybrid, const atomic_bool *cancel)
{
    if (!s || !camera || !hybrid || hybrid->width != s->width || hybrid->height != s->height ||
        hybrid->channels < 3) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    if (!s->has_camera || memcmp(&s->camera, camera, sizeof *camera) != 0) {
        // A new view: the accumulation starts with the next still frame.
        drift_still_refine_reset(s);
        s->camera = *camera;
        s->has_camera = true;
        show_hybrid(s, hybrid);
        return DRIFT_OK;
    }
    drift_result r = DRIFT_OK;
    if (!s->pt) {
        drift_pt_params p = { .width = s->width,
                              .height = s->height,
                              .seed = s->s.seed,
                              .max_depth = s->s.max_depth,
                              .texture_filter_spp = 64u,
                              .camera = &s->camera };
        if ((r = drift_pt_create(s->ctx, s->scene, s->accel, &p, &s->pt)) != DRIFT_OK) {
            return r;
        }
    }
    if ((r = drift_pt_render_samples(s->pt, s->s.spp, cancel)) != DRIFT_OK) {
        return r;
    }
    if (drift_pt_sample_count(s->pt) < 2) {
        show_hybrid(s, hybrid); // no variance yet: nothing says the path tracer is better
        return DRIFT_OK;
    }
    if ((r = denoise(s)) != DRIFT_OK) {
        return r;
    }
    drift_image beauty, variance;
    if ((r = drift_pt_resolve(s->pt, DRIFT_PT_AOV_BEAUTY, &beauty)) != DRIFT_OK ||
        (r = drift_pt_resolve(s->pt, DRIFT_PT_AOV_VARIANCE, &variance)) != DRIFT_OK) {
        return r;
    }
    temporal_error_blend(s->ctx, hybrid, &beauty, &variance, &s->denoised, NULL,
                         s->s.denoised_error, s->s.radius, s->scratch, &s->out, &s->weight);
    if (!s->s.keeps_hybrid) {
        fade_by_samples(s, hybrid);
    }
    return DRIFT_OK;
}

bool drift_still_refine_needs_hybrid(const drift_still_refine *s, const drift_camera *camera)
{
    return !s || !camera || s->s.keeps_hybrid || !s->has_camera ||
           memcmp(&s->camera, camera, sizeof *camera) != 0;
}

// The blend's rows: its inputs' planes, a separable (2r+1)^2 box mean of each plane in place
// (clamped at the borders; rows into tmp, then columns back), and the mix.
typedef struct blend_job {
    const drift_image *hybrid, *raw, *variance, *denoised, *denoised_variance;
    float denoised_error;
    int32_t w, h, radius;
    float *diff2, *var, *tmp, *dvar;
    float *plane; // the plane the box mean runs on
    drift_image *out, *weight;
} blend_job;

static void blend_inputs_rows(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    const blend_job *j = user;
    for (int32_t y = (int32_t)begin; y < (int32_t)end; ++y) {
        for (int32_t x = 0; x < j->w; ++x) {
            size_t i = (size_t)y * (size_t)j->w + (size_t)x;
            float d = drift_luminance(drift_image_get3(j->hybrid, x, y)) -
                      drift_luminance(drift_image_get3(j->raw, x, y));
            float v = *drift_image_pixel(j->variance, x, y);
            j->diff2[i] = isfinite(d) ? d * d : 0.0f;
            j->var[i] = isfinite(v) && v > 0.0f ? v : 0.0f;
            if (j->denoised_variance) {
                float dv = *drift_image_pixel(j->denoised_variance, x, y);
                j->dvar[i] = isfinite(dv) && dv > 0.0f ? dv : 0.0f;
            }
        }
    }
}

static void box_rows(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    const blend_job *j = user;
    int32_t w = j->w, r = j->radius;
    for (int32_t y = (int32_t)begin; y < (int32_t)end; ++y) {
        for (int32_t x = 0; x < w; ++x) {
            float sum = 0.0f;
            int32_t n = 0;
            for (int32_t i = x - r; i <= x + r; ++i) {
                if (i >= 0 && i < w) {
                    sum += j->plane[(size_t)y * (size_t)w + (size_t)i];
                    n += 1;
                }
            }
            j->tmp[(size_t)y * (size_t)w + (size_t)x] = sum / (float)n;
        }
    }
}

static void box_columns(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    const blend_job *j = user;
    int32_t w = j->w, h = j->h, r = j->radius;
    for (int32_t y = (int32_t)begin; y < (int32_t)end; ++y) {
        for (int32_t x = 0; x < w; ++x) {
            float sum = 0.0f;
            int32_t n = 0;
            for (int32_t i = y - r; i <= y + r; ++i) {
                if (i >= 0 && i < h) {
                    sum += j->tmp[(size_t)i * (size_t)w + (size_t)x];
                    n += 1;
                }
            }
            j->plane[(size_t)y * (size_t)w + (size_t)x] = sum / (float)n;
        }
    }
}

static void mix_rows(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    const blend_job *j = user;
    for (int32_t y = (int32_t)begin; y < (int32_t)end; ++y) {
        for (int32_t x = 0; x < j->w; ++x) {
            size_t i = (size_t)y * (size_t)j->w + (size_t)x;
            float hybrid_error = fmaxf(j->diff2[i] - j->var[i], 0.0f);
            float path_error = j->denoised_error * (j->denoised_variance ? j->dvar[i] : j->var[i]);
            float sum = hybrid_error + path_error;
            float wp = sum > 0.0f ? hybrid_error / sum : 1.0f; // both 0: they agree
            drift_vec3 a = drift_image_get3(j->hybrid, x, y);
            drift_vec3 b = drift_image_get3(j->denoised, x, y);
            drift_image_set3(j->out, x, y, drift_vec3_fma(a, drift_vec3_sub(b, a), wp));
            *drift_image_pixel(j->weight, x, y) = wp;
        }
    }
}

void temporal_error_blend(drift_context *ctx, const drift_image *hybrid, const drift_image *raw,
                          const drift_image *variance, const drift_image *denoised,
                          const drift_image *denoised_variance, float denoised_error,
                          int32_t radius, float *scratch[4], drift_image *out, drift_image *weight)
{
    blend_job j = { .hybrid = hybrid,
                    .raw = raw,
                    .variance = variance,
                    .denoised = denoised,
                    .denoised_variance = denoised_variance,
                    .denoised_error = denoised_error,
                    .w = hybrid->width,
                    .h = hybrid->height,
                    .radius = radius,
                    .diff2 = scratch[0],
                    .var = scratch[1],
                    .tmp = scratch[2],
                    .dvar = scratch[3],
                    .out = out,
                    .weight = weight };
    size_t rows = (size_t)j.h;
    drift_parallel_for(ctx, rows, 4, blend_inputs_rows, &j);
    float *planes[3] = { j.diff2, j.var, j.dvar };
    for (int k = 0; k < (denoised_variance ? 3 : 2); ++k) {
        j.plane = planes[k];
        drift_parallel_for(ctx, rows, 4, box_rows, &j);
        drift_parallel_for(ctx, rows, 4, box_columns, &j);
    }
    drift_parallel_for(ctx, rows, 4, mix_rows, &j);
}

const drift_image *drift_still_refine_image(const drift_still_refine *s)
{
    return s ? &s->out : NULL;
}

const drift_image *drift_still_refine_weight(const drift_still_refine *s)
{
    return s ? &s->weight : NULL;
}

uint32_t drift_still_refine_samples(const drift_still_refine *s)
{
    return s && s->pt ? drift_pt_sample_count(s->pt) : 0u;
}
