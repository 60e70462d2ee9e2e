// drift render --mode hybrid --denoise guided: the hybrid frame as the guide of the path
// tracer's --spp samples, combined by drift_denoise_guided (RESIDUAL, the direct part and the
// rest apart: the frame plus the path tracer's filtered residual; docs/denoiser.md).
#include "cli.h"
#include "drift/denoise.h"
#include "drift/pt.h"
#include "render.h"

#include <stdio.h>

drift_result render_guided_image(const render_options *o, const cli_session *session,
                                 const drift_image *guide, const drift_image *guide_indirect,
                                 drift_image *out)
{
    *out = (drift_image){ 0 };
    drift_pt_params params = { .width = guide->width,
                               .height = guide->height,
                               .seed = (uint32_t)o->seed,
                               .max_depth = (int32_t)o->max_depth,
                               .reflection_edits = o->hybrid.reflection_edits };
    drift_pt *pt = NULL;
    double t0 = drift_time_now();
    drift_result r = drift_pt_create(session->ctx, session->scene, session->accel, &params, &pt);
    r = r ? r : drift_pt_render_samples(pt, (uint32_t)o->spp, render_catch_sigint());
    double pt_ms = 1e3 * (drift_time_now() - t0);
    drift_image beauty, var, albedo, normal, depth, direct, direct_var, indirect_var;
    r = r ? r : drift_pt_resolve(pt, DRIFT_PT_AOV_BEAUTY, &beauty);
    r = r ? r : drift_pt_resolve(pt, DRIFT_PT_AOV_VARIANCE, &var);
    r = r ? r : drift_pt_resolve(pt, DRIFT_PT_AOV_FEATURE_ALBEDO, &albedo);
    r = r ? r : drift_pt_resolve(pt, DRIFT_PT_AOV_FEATURE_NORMAL, &normal);
    r = r ? r : drift_pt_resolve(pt, DRIFT_PT_AOV_FEATURE_DEPTH, &depth);
    r = r ? r : drift_pt_resolve(pt, DRIFT_PT_AOV_DIRECT, &direct);
    r = r ? r : drift_pt_resolve(pt, DRIFT_PT_AOV_DIRECT_VARIANCE, &direct_var);
    r = r ? r : drift_pt_resolve(pt, DRIFT_PT_AOV_INDIRECT_VARIANCE, &indirect_var);
    t0 = drift_time_now();
    if (r == DRIFT_OK) {
        drift_denoise_inputs in = { .color = &beauty,
                                    .albedo = &albedo,
                                    .normal = &normal,
                                    .depth = &depth,
                                    .variance = &var,
                                    .sample_count = (uint32_t)o->spp,
                                    .direct = &direct,
                                    .direct_variance = &direct_var,
                                    .indirect_variance = &indirect_var };
        r = drift_denoise_guided(session->ctx, &in, guide, guide_indirect, DRIFT_GUIDE_RESIDUAL,
                                 NULL, out, NULL);
    }
    if (r == DRIFT_OK && !o->quiet) {
        fprintf(stderr,
                "drift render: --denoise guided: path tracer %ld spp %.1f ms, filter %.1f ms\n",
                o->spp, pt_ms, 1e3 * (drift_time_now() - t0));
    }
    drift_pt_destroy(pt);
    return r;
}
