// The `reference` technique of each effect: that effect's term alone, path-traced by drift_pt
// at --spp through the same pixel centres as the G-buffer (so the comparison measures the
// technique, not antialiasing), with the pt's component split (docs/reference-renderer.md)
// the row names:
//   shadows     -> DIRECT   (max depth 1: light straight from the emitters)
//   reflections -> SPECULAR (first bounce glossy or mirror, up to max_depth)
//   indirect    -> DIFFUSE  (first bounce diffuse, up to max_depth)
// Reference depth of field cannot reuse pinhole buffers: compose.c renders the whole frame
// through the lens (drift_hybrid_pass_lens_reference).
#include "hybrid/techniques.h"

drift_result drift_hybrid_pass_reference(drift_frame_state *f, const drift_pass_args *args)
{
    DRIFT_CHECK((unsigned)args->effect < DRIFT_EFFECT_COUNT);
    // Direct light is one scattering event; every other term follows paths to max_depth.
    int32_t depth = args->components == DRIFT_PT_COMPONENT_DIRECT ? 1 : f->params.max_depth;
    double t = drift_time_now();
    drift_result r = drift_pass_reference_render(f, args->components, depth, false, args->cancel,
                                                 &f->terms[args->effect]);
    drift_pass_time(f, DRIFT_PASS_REFERENCE, t);
    return r;
}
