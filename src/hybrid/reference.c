// The `reference` technique of each effect: that effect's term alone, path-traced by drift_pt
// at --spp through the same pixel centres as the G-buffer (so the comparison measures the
// technique, not antialiasing), with the pt's component split (docs/reference-renderer.md):
//   shadows     -> DIRECT   (max depth 1: light straight from the emitters)
//   reflections -> SPECULAR (first bounce glossy or mirror, up to max_depth)
//   indirect    -> DIFFUSE  (first bounce diffuse, up to max_depth)
// Reference depth of field cannot reuse pinhole buffers: compose.c renders the whole frame
// through the lens with drift_hybrid_render_reference_lens.
#include "hybrid/frame_internal.h"

drift_result drift_hybrid_reference_render(drift_hybrid *f, uint32_t components, int32_t max_depth,
                                           bool lens, const atomic_bool *cancel, drift_image *out)
{
    drift_pt_params params = { .width = f->params.width,
                               .height = f->params.height,
                               .seed = f->params.seed,
                               .max_depth = max_depth,
                               .components = components,
                               .pixel_centre = true,
                               .pinhole = !lens,
                               .camera = &f->camera };
    drift_pt *pt = NULL;
    drift_result r = drift_pt_create(f->ctx, f->scene, f->accel, &params, &pt);
    if (r == DRIFT_OK) {
        r = drift_pt_render_samples(pt, f->params.spp, cancel);
    }
    if (r == DRIFT_OK) {
        drift_image beauty;
        r = drift_pt_resolve(pt, DRIFT_PT_AOV_BEAUTY, &beauty);
        if (r == DRIFT_OK) {
            drift_hybrid_copy_rgb(&beauty, out);
        }
        drift_pt_stats s = drift_pt_get_stats(pt);
        f->stats.rays[DRIFT_PASS_REFERENCE] += s.camera_rays + s.shadow_rays + s.bounce_rays;
    }
    drift_pt_destroy(pt);
    return r;
}

drift_result drift_hybrid_pass_reference(drift_hybrid *f, const atomic_bool *cancel)
{
    const drift_hybrid_params *p = &f->params;
    double t = drift_time_now();
    drift_result r = DRIFT_OK;
    if (p->dof == DRIFT_DOF_REFERENCE) {
        return DRIFT_OK; // the lens render in compose.c replaces every term
    }
    if (p->shadows == DRIFT_SHADOWS_REFERENCE) {
        r = drift_hybrid_reference_render(f, DRIFT_PT_COMPONENT_DIRECT, 1, false, cancel,
                                          &f->direct);
    }
    if (r == DRIFT_OK && p->reflections == DRIFT_REFLECTIONS_REFERENCE) {
        r = drift_hybrid_reference_render(f, DRIFT_PT_COMPONENT_SPECULAR, p->max_depth, false,
                                          cancel, &f->reflections);
    }
    if (r == DRIFT_OK && p->indirect == DRIFT_INDIRECT_REFERENCE) {
        r = drift_hybrid_reference_render(f, DRIFT_PT_COMPONENT_DIFFUSE, p->max_depth, false,
                                          cancel, &f->indirect);
    }
    f->stats.ms[DRIFT_PASS_REFERENCE] += 1000.0 * (drift_time_now() - t);
    return r;
}
