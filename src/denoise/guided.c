// The hybrid-guided denoiser (include/drift/denoise.h): a noise-free but biased image of the
// frame (the hybrid frame) and the path tracer's samples, combined by the feature denoiser
// either as a control variate (RESIDUAL: guide + the filtered signed residual, the direct part
// and the rest apart when the path tracer's direct part is given) or with the guide as three
// more regression features (REGRESSION). docs/denoiser.md has the figures.
#include "feature_internal.h"

#include <math.h>

static float finite(float v)
{
    return isfinite(v) ? v : 0.0f;
}

// dst = a - b - c per channel (c may be NULL: 0), non-finite guide values taken as 0.
static drift_result difference(drift_context *ctx, const drift_image *a, const drift_image *b,
                               const drift_image *c, drift_image *dst)
{
    drift_result r = drift_image_create(ctx, a->width, a->height, 3, dst);
    for (int32_t y = 0; r == DRIFT_OK && y < a->height; ++y) {
        for (int32_t x = 0; x < a->width; ++x) {
            const float *pa = drift_image_pixel(a, x, y);
            const float *pb = drift_image_pixel(b, x, y);
            const float *pc = c ? drift_image_pixel(c, x, y) : NULL;
            float *d = drift_image_pixel(dst, x, y);
            for (int k = 0; k < 3; ++k) {
                d[k] = pa[k] - finite(pb[k]) - (pc ? finite(pc[k]) : 0.0f);
            }
        }
    }
    return r;
}

static bool fits(const drift_image *c, const drift_image *g)
{
    return g && g->pixels && g->channels >= 3 && g->width == c->width && g->height == c->height;
}

drift_result drift_denoise_guided(drift_context *ctx, const drift_denoise_inputs *in,
                                  const drift_image *guide, const drift_image *guide_indirect,
                                  drift_denoise_guide_mode mode,
                                  const drift_denoise_feature_params *params, drift_image *out,
                                  drift_denoise_report *report)
{
    if (out) {
        *out = (drift_image){ 0 };
    }
    const drift_image *c = in ? in->color : NULL;
    const bool split = in && (in->direct || in->direct_variance || in->indirect_variance);
    if (!out || !c || !c->pixels || c->channels < 3 || !fits(c, guide) ||
        (guide_indirect && !fits(c, guide_indirect)) || (unsigned)mode >= DRIFT_GUIDE_MODE_COUNT ||
        (split && (mode != DRIFT_GUIDE_RESIDUAL || !fits(c, in->direct) || !in->direct_variance ||
                   !in->indirect_variance))) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, NULL, 0,
                  "denoise: the guided denoiser needs an RGB colour and guides of its size, a "
                  "known mode, and a direct part (RESIDUAL only) with both variances");
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    drift_denoise_feature_params p = drift_denoise_feature_params_resolve(params);
    drift_denoise_inputs part = *in;
    part.direct = part.direct_variance = part.indirect_variance = NULL;
    if (mode == DRIFT_GUIDE_REGRESSION) {
        if (p.method == DRIFT_DENOISE_VARIANCE_GUIDED) {
            p.method = DRIFT_DENOISE_REGRESSION_RESIDUAL; // the guide acts through the fit
        }
        return denoise_feature_guided(ctx, &part, guide, &p, out, report);
    }
    // RESIDUAL: the path tracer's variance is the residual's (the guide is deterministic).
    p.signed_color = true;
    drift_image residual = { 0 }, filtered = { 0 }, rest = { 0 }, rest_filtered = { 0 };
    drift_result r = DRIFT_OK;
    drift_denoise_report rep_rest = { 0 };
    if (split) {
        // As drift_denoise_feature splits: the direct part against the guide less its indirect
        // part, the rest against that indirect part (none: 0), each by its own variance. Both
        // by `method`: REGRESSION_RESIDUAL's fit cannot follow the steps a residual has where
        // the guide's bias changes (a shadow's edge), and at sigma_luminance_residual its
        // filter carries them across (6 % of the guide's bias left at 4096 spp in
        // tests/unit/test_denoise_guided.c; 1 % with VARIANCE_GUIDED).
        drift_denoise_feature_params pd = p, pi = p;
        pd.sigma_luminance = p.sigma_luminance_direct;
        pi.sigma_luminance = p.sigma_luminance_indirect;
        r = difference(ctx, in->direct, guide, NULL, &residual);
        for (int32_t y = 0; r == DRIFT_OK && guide_indirect && y < c->height; ++y) {
            for (int32_t x = 0; x < c->width; ++x) { // + the guide's indirect part
                float *d = drift_image_pixel(&residual, x, y);
                const float *gi = drift_image_pixel(guide_indirect, x, y);
                for (int k = 0; k < 3; ++k) {
                    d[k] += finite(gi[k]);
                }
            }
        }
        r = r ? r : difference(ctx, c, in->direct, guide_indirect, &rest);
        part.color = &residual;
        part.variance = in->direct_variance;
        r = r ? r : denoise_feature_guided(ctx, &part, NULL, &pd, &filtered, report);
        part.color = &rest;
        part.variance = in->indirect_variance;
        r = r ? r : denoise_feature_guided(ctx, &part, NULL, &pi, &rest_filtered, &rep_rest);
    } else {
        r = difference(ctx, c, guide, NULL, &residual);
        part.color = &residual;
        r = r ? r : denoise_feature_guided(ctx, &part, NULL, &p, &filtered, report);
    }
    r = r ? r : drift_image_create(ctx, c->width, c->height, 3, out);
    for (int32_t y = 0; r == DRIFT_OK && y < c->height; ++y) {
        for (int32_t x = 0; x < c->width; ++x) {
            const float *g = drift_image_pixel(guide, x, y),
                        *d = drift_image_pixel(&filtered, x, y);
            const float *e = split ? drift_image_pixel(&rest_filtered, x, y) : NULL;
            float *dst = drift_image_pixel(out, x, y);
            for (int k = 0; k < 3; ++k) {
                dst[k] = fmaxf(finite(g[k]) + d[k] + (e ? e[k] : 0.0f), 0.0f);
            }
        }
    }
    if (r == DRIFT_OK && split && report) {
        report->nonfinite += rep_rest.nonfinite;
        report->clamped += rep_rest.clamped;
        report->mean_variance += rep_rest.mean_variance;
    }
    if (r != DRIFT_OK) {
        drift_image_destroy(ctx, out);
    }
    drift_image_destroy(ctx, &residual);
    drift_image_destroy(ctx, &filtered);
    drift_image_destroy(ctx, &rest);
    drift_image_destroy(ctx, &rest_filtered);
    return r;
}
