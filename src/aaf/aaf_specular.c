// AAF's specular buffer (--reflections aaf; Mehta, Wang, Ramamoorthi 2013, sec. 4.3;
// docs/aaf.md): the frame's R term, light whose first bounce is the glossy lobe, path-traced
// and filtered by the machinery of aaf_indirect.c in buffers of its own, apart from the
// diffuse buffer (--indirect aaf). Omega_h^max = 3.6 + 0.084 m (eq. 4.5, Blinn-Phong), so
// sharper lobes get narrower filters, down to one pixel footprint. Mirrors (a delta lobe) keep a
// sharp ray: the mirror direction, the emission it meets and next-event estimation at its hit,
// unfiltered.
#include "aaf/aaf.h"

#include <math.h>

static bool specular_at(const drift_bsdf *bsdf, drift_vec3 wo, drift_vec3 *albedo, float *omega)
{
    if (bsdf->type == DRIFT_MATERIAL_GGX) {
        *albedo = drift_raster_reflection_weight(bsdf, wo); // the GGX reflection's albedo
    } else {
        *albedo = bsdf->specular;
    }
    // The bandwidth of the lobe's Blinn-Phong exponent: GGX's by its 90% cone (docs/aaf.md).
    *omega = bsdf->type == DRIFT_MATERIAL_MIRROR
                 ? 0.0f
                 : drift_aaf_omega_specular(0.25f * drift_gloss_blinn_exponent(bsdf));
    bool lobe = bsdf->type == DRIFT_MATERIAL_MIRROR || bsdf->exponent > 0.0f;
    // Seen from below, the lobe reflects nothing (drift_bsdf_eval is 0 there).
    return lobe && !drift_vec3_is_zero(bsdf->specular) && drift_vec3_dot(wo, bsdf->frame.z) > 0.0f;
}

// The glossy lobe ks (n+2)/(2 pi) cos^n(alpha) sampled as the pt does (cos alpha = u^(1/(n+1))
// around the mirror direction): f cos / (pdf ks) = (n+2)/(n+1) cos(theta_i). A mirror's
// weight is 1 and its ray sees emission.
static void specular_sample(const drift_bsdf *bsdf, drift_vec3 wo, drift_vec2 u, drift_vec3 *wi,
                            float *weight, bool *emission)
{
    *emission = bsdf->type == DRIFT_MATERIAL_MIRROR;
    if (*emission) {
        *wi = drift_bsdf_mirror_direction(bsdf, wo); // e(q) under reflection edits
        *weight = 1.0f;
        return;
    }
    if (bsdf->type == DRIFT_MATERIAL_GGX) {
        // GGX's own reflection lobe by its visible normals; the albedo (specular_at) carries
        // the energy, so each sample weighs 1 (F G2 / G1 over the albedo averages 1).
        drift_vec3 wo_local = drift_frame_to_local(&bsdf->frame, wo);
        drift_vec3 m = drift_ggx_sample_visible_normal(bsdf->ggx.alpha, wo_local, u);
        drift_vec3 wi_local =
            drift_vec3_sub(drift_vec3_scale(m, 2.0f * drift_vec3_dot(wo_local, m)), wo_local);
        *wi = drift_frame_to_world(&bsdf->frame, wi_local);
        *weight = wi_local.z > 0.0f ? 1.0f : 0.0f;
        return;
    }
    float n = bsdf->exponent;
    *wi = drift_bsdf_sample_glossy_lobe(bsdf, wo, u);
    *weight = fmaxf(0.0f, (n + 2.0f) / (n + 1.0f) * drift_vec3_dot(*wi, bsdf->frame.z));
}

drift_result drift_aaf_pass_specular(drift_frame_state *f, const drift_pass_args *args)
{
    (void)args;
    drift_result r = drift_aaf_state_ensure(f);
    if (r != DRIFT_OK) {
        return r;
    }
    drift_aaf_lobe lobe = { .stream = DRIFT_STREAM_AAF_SPECULAR,
                            .buffers = &drift_aaf_of(f)->specular,
                            .out = &f->reflections,
                            .shrink_from_spp = DRIFT_AAF_INDIRECT_SHRINK_SPP,
                            .shrink_exponent = DRIFT_AAF_INDIRECT_SHRINK_EXP,
                            // One pixel footprint, not eq. 4.4's 1 / 0.15: that floor, a
                            // Gaussian of 6.7 footprints, blurred the glossy reflections' detail
                            // (docs/aaf.md: Cornell glossy RMSE 0.00117 -> 0.00075 at 16 spp).
                            .pixel_width = 1.0f,
                            .at = specular_at,
                            .sample = specular_sample };
    return drift_aaf_lobe_pass(f, &lobe);
}
