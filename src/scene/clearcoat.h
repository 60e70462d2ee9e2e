// Private to src/scene (and its unit tests): the clear coat of DRIFT_MATERIAL_GGX
// (clearcoat.c). Its entry points wrap microfacet.h's drift__ggx_eval, _pdf and _sample: with
// no coat (drift_bsdf_ggx.clearcoat 0) they return what those return, bit for bit.
#ifndef DRIFT_CLEARCOAT_H
#define DRIFT_CLEARCOAT_H

#include "drift/scene.h"

// The coat's IOR is 1.5 (KHR_materials_clearcoat): F0 = ((1.5 - 1) / (1.5 + 1))^2.
#define DRIFT_CLEARCOAT_F0 0.04f

// Fills g's clear coat from material m at the surface point (its textures read when scene is
// not NULL); no coat when the material has none.
void drift__clearcoat_make(const drift_scene *scene, const drift_material *m,
                           const drift_surface *surface, drift_bsdf_ggx *g);
// The GGX material with its coat: value (out_diffuse, may be NULL, gets the dimmed diffuse
// part), pdf and sampling, in the local frame as drift__ggx_eval, _pdf and _sample.
drift_vec3 drift__coated_eval(const drift_bsdf_ggx *g, drift_vec3 wo, drift_vec3 wi,
                              drift_vec3 *out_diffuse);
float drift__coated_pdf(const drift_bsdf_ggx *g, drift_vec3 wo, drift_vec3 wi);
drift_bsdf_sample drift__coated_sample(const drift_bsdf_ggx *g, drift_vec3 wo, float u_lobe,
                                       drift_vec2 u);
// The coat's directional albedo toward mu (weight included, 0 without a coat).
float drift__clearcoat_albedo(const drift_bsdf_ggx *g, float mu);
// Dims the base's reflection albedos (drift_bsdf_ggx_reflection_albedo) by what the coat
// takes on the way in and out: around the mirror direction mu_i ~ mu_o.
void drift__clearcoat_dim_albedo(const drift_bsdf_ggx *g, float mu, drift_vec3 *single,
                                 drift_vec3 *multiple);
// The coat in the Phong-equivalent lobe (docs/materials.md): at normal incidence, from the
// material's factors.
void drift__clearcoat_phong(const drift_material *m, drift_vec3 *kd, drift_vec3 *ks);

#endif
