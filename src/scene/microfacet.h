// Private to src/scene (and its unit tests): the GGX (Trowbridge-Reitz) microfacet pieces of
// DRIFT_MATERIAL_GGX. Every direction here is in the local shading frame (z = shading normal).
#ifndef DRIFT_MICROFACET_H
#define DRIFT_MICROFACET_H

#include "drift/scene.h"

// Below this alpha a dielectric is smooth (delta lobes); conductors and coats are clamped to it.
#define DRIFT_GGX_MIN_ALPHA 1e-3f

// Normal distribution D(m) of isotropic GGX with roughness alpha.
float drift__ggx_d(float alpha, drift_vec3 m);
// Smith's Lambda(w) for GGX; G1 = 1 / (1 + Lambda); the height-correlated G2(wo, wi) =
// 1 / (1 + Lambda(wo) + Lambda(wi)) (Heitz 2014).
float drift__ggx_lambda(float alpha, drift_vec3 w);
// A visible normal for wo (wo.z > 0), Heitz 2018 ("Sampling the GGX Distribution of Visible
// Normals"), and its density D_wo(m) = G1(wo) max(0, wo.m) D(m) / wo.z.
drift_vec3 drift__ggx_sample_vndf(float alpha, drift_vec3 wo, drift_vec2 u);
float drift__ggx_pdf_vndf(float alpha, drift_vec3 wo, drift_vec3 m);
// Single-scattering reflection D G2 / (4 mu_o mu_i) without the Fresnel term (h in out_h),
// and the density of sampling wi through the visible normals; 0 when wo + wi = 0.
float drift__ggx_reflect_ss(float alpha, drift_vec3 wo, drift_vec3 wi, drift_vec3 *out_h);
float drift__ggx_reflect_pdf(float alpha, drift_vec3 wo, drift_vec3 wi);

// Unpolarized Fresnel reflectance of a dielectric interface; cos_i may be negative (from the
// other side); eta = IOR on the transmitted side over the IOR on the incident side for cos_i > 0.
// 1 under total internal reflection.
float drift__fresnel_dielectric(float cos_i, float eta);
// Fresnel reflectance of a conductor of complex IOR eta + i k (per channel), cos_i in [0, 1].
drift_vec3 drift__fresnel_conductor(float cos_i, drift_vec3 eta, drift_vec3 k);
// Gulbrandsen 2014 ("Artist Friendly Metallic Fresnel"): the complex IOR with reflectance
// f0 at normal incidence and edge tint g.
void drift__conductor_from_tint(drift_vec3 f0, drift_vec3 g, drift_vec3 *eta, drift_vec3 *k);
// Refraction of wi (pointing away from the surface on the side n points to) into the side
// beyond, eta = IOR beyond over IOR on wi's side; false under total internal reflection.
bool drift__refract(drift_vec3 wi, drift_vec3 n, float eta, drift_vec3 *out_wt);

// Directional albedo tables (ggx_tables.c): with F = 1: e1; with F = (1 - wo.m)^5: es, so a
// Schlick surface of F0 has albedo F0 (e1 - es) + es. Averages over the cosine-weighted
// hemisphere: 2 int E(mu) mu dmu. Rough dielectric (reflection plus transmission, single
// scattering) of relative IOR eta (1/3 to 3): e_dielectric.
float drift__ggx_e1(float mu, float alpha);
float drift__ggx_es(float mu, float alpha);
float drift__ggx_e1_avg(float alpha);
float drift__ggx_es_avg(float alpha);
float drift__ggx_e_dielectric(float mu, float alpha, float eta);
// The same lookups with the roughness's row of the table found once (a BSDF's alpha is fixed).
void drift__ggx_alpha_slot(float alpha, int *row, float *frac);
void drift__ggx_e1_es_at(float mu, int row, float frac, float *e1, float *es);
// The multiple-scattering lobe's scale s(mu) at a row (see drift__ggx_fit_ms_scale).
float drift__ggx_ms_scale_at(float mu, int row, float frac);
float drift__ggx_ms_scale(float mu, float alpha);

// The tables' grids: mu at (i + 0.5) / MU_N (dielectric: at drift__ggx_grid_mu_d(i), from
// 0 to 1 inclusive, for the steep change near normal incidence inside); sqrt(alpha) at j / (ALPHA_N
// - 1) (alpha at least ALPHA_LOW); eta (side 0) or 1 / eta (side 1) at drift__ggx_grid_eta(e),
// uniform in (eta - 1) / (eta + 1) (the square root of F0), where E changes evenly.
#define DRIFT_GGX_TABLE_MU_N      32
#define DRIFT_GGX_TABLE_ALPHA_N   32
#define DRIFT_GGX_TABLE_D_MU_N    24
#define DRIFT_GGX_TABLE_D_ALPHA_N 16
#define DRIFT_GGX_TABLE_ETA_N     16
#define DRIFT_GGX_TABLE_ETA_MIN   1.01f
#define DRIFT_GGX_TABLE_ETA_MAX   3.0f
#define DRIFT_GGX_TABLE_ALPHA_LOW 1e-4f
float drift__ggx_grid_alpha(int j, int n);
float drift__ggx_grid_eta(int e);
// The continuous grid index of eta (>= 1) on that grid.
float drift__ggx_eta_coord(float eta);
float drift__ggx_grid_mu_d(int i);
// The integrals the tables hold, on a strata x strata grid of visible normals.
void drift__ggx_integrate_reflection(float mu, float alpha, int strata, float *e1, float *es);
float drift__ggx_integrate_dielectric(float mu, float alpha, float eta, int strata);

// The conductor's multiple-scattering lobe (docs/materials.md): with F = 1,
//   f_ms(wo, wi) = s(mu_o) s(mu_i) K(mu_o, mu_i) D2(h) G2(wo, wi) / (4 mu_o mu_i),
// single-scatter GGX of the broader roughness drift__ggx_ms_alpha(alpha), times the kernel K,
// scaled by s so that its albedo is 1 - E1(mu_o) at every mu_o: reciprocal and white-furnace
// exact. s is tabulated on the E tables' grid (drift__ggx_ms_scale_at, linear in mu between
// cell centres). The broad roughness is k(r) alpha, r = sqrt(alpha): k = 2.5 up to r = 0.35,
// then falling linearly to 1 at r = 1; K = 1 + beta(r) ((1 - mu_o)(1 - mu_i))^2, beta 0 up to
// r = 0.5, then rising by BETA_SLOPE per unit of r: it moves the walk's light toward grazing
// pairs of directions, which no separable factor (s absorbs those) and no width can (both
// fitted to Cycles 3.4's random walk: docs/materials.md).
#define DRIFT_GGX_MS_WIDTH       2.5f
#define DRIFT_GGX_MS_WIDTH_KNEE  0.35f
#define DRIFT_GGX_MS_WIDTH_ROUGH 1.0f
#define DRIFT_GGX_MS_BETA_KNEE   0.5f
#define DRIFT_GGX_MS_BETA_SLOPE  6.667f
float drift__ggx_ms_alpha(float alpha);
float drift__ggx_ms_beta(float alpha);
// K(mu_o, mu_i) for the lobe's beta.
float drift__ggx_ms_kernel(float beta, float mu_o, float mu_i);
// One alpha row of s for the BSDF's roughness alpha (the lobe of drift__ggx_ms_alpha(alpha) and
// drift__ggx_ms_beta(alpha)) and that row of the E1 table (e1, DRIFT_GGX_TABLE_MU_N values):
// with wo at each grid mu, the lobe's albedo is linear in s's entries, B s (B by strata x strata
// visible normals of the broad lobe); s solves s_i (B s)_i = 1 - e1[i] by a symmetric
// Sinkhorn-Knopp scaling. Returns the largest residual |s_i (B s)_i - (1 - e1[i])|.
float drift__ggx_fit_ms_scale(float alpha, const float *e1, int strata, float *out_scale);

// The GGX material's value, pdf and sampling in the local frame. out_diffuse (may be NULL)
// gets the plastic's diffuse part of the value.
drift_vec3 drift__ggx_eval(const drift_bsdf_ggx *g, drift_vec3 wo, drift_vec3 wi,
                           drift_vec3 *out_diffuse);
float drift__ggx_pdf(const drift_bsdf_ggx *g, drift_vec3 wo, drift_vec3 wi);
// wi in the local frame; pdf 0 means no sample.
drift_bsdf_sample drift__ggx_sample(const drift_bsdf_ggx *g, drift_vec3 wo, float u_lobe,
                                    drift_vec2 u);
// The Phong-equivalent lobe of a GGX material (base colour `base`, roughness alpha and
// metallic after textures) for the techniques that shade with Phong (docs/materials.md).
void drift__ggx_phong_equivalent(const drift_material *m, drift_vec3 base, float alpha,
                                 float metallic, drift_vec3 *kd, drift_vec3 *ks, float *exponent);
// True when every component is a delta (a smooth, fully transmissive dielectric).
bool drift__ggx_is_delta(const drift_bsdf_ggx *g);

#endif
