// The clear coat of DRIFT_MATERIAL_GGX (KHR_materials_clearcoat): a GGX dielectric interface of
// IOR 1.5 over the whole material (conductor, plastic, dielectric), weighted by `clearcoat`.
// Two forms (docs/materials.md "Clear coat", docs/decisions/0411-gltf-clearcoat.md):
//
//   layered (the glTF specification's, made reciprocal and energy-bounded):
//     f = c f_coat(wo, wi) + T(mu_o) T(mu_i) (f_base(wo, wi) + (gain - 1) f_diffuse(wo, wi))
//   Principled (Blender 3.4's Cycles, Disney's clearcoat):
//     f = 0.25 c f_coat(wo, wi) + f_base(wo, wi)
//
// with f_coat = F_Schlick(0.04, wo.h) D G2 / (4 mu_o mu_i), Ec its directional albedo (the
// albedo tables of ggx_tables.c) and T = 1 - c Ec the light that crosses the coat. The base is
// dimmed on the way in and on the way out. Its diffuse part f_diffuse (the plastic's) gets back
// the light the coat reflects down into it, as the plastic does under its own coat: `gain`
// makes the diffuse albedo toward any mu_o exactly T(mu_o) times the uncoated one (for the
// layered plastic gain = (1 - Ep_avg) / int (1 - Ep)(1 - c Ec) 2 mu dmu, Ep the plastic coat's
// albedo; for Burley's 1 / (1 - c Ec_avg)). So a white plastic under a clear coat reflects
// c Ec + T (Ep + 1 - Ep) = 1 but for what its own coat's reflection loses through the clear coat
// (< 0.5% at normal incidence); a conductor base gets nothing back (a smooth mirror under a
// smooth coat at 77 degrees reflects 0.79). The coat lies about the base's shading normal.
#include "clearcoat.h"

#include "microfacet.h"
#include "scene_internal.h"

#include <math.h>

// The coat lobe's scale: c, or Disney's 0.25 c.
static float coat_scale(const drift_bsdf_ggx *g)
{
    return g->clearcoat_principled ? 0.25f * g->clearcoat : g->clearcoat;
}

static float coat_alpha(const drift_bsdf_ggx *g)
{
    return fmaxf(g->clearcoat_alpha, DRIFT_GGX_MIN_ALPHA);
}

float drift__clearcoat_albedo(const drift_bsdf_ggx *g, float mu)
{
    if (!(g->clearcoat > 0.0f)) {
        return 0.0f;
    }
    float e1, es;
    drift__ggx_e1_es_at(drift_clampf(mu, 0.0f, 1.0f), g->clearcoat_row, g->clearcoat_frac, &e1,
                        &es);
    return coat_scale(g) * (DRIFT_CLEARCOAT_F0 * (e1 - es) + es);
}

// What of the light crossing the coat at mu reaches the other side: 1 - c Ec(mu); 1 in the
// Principled form, which does not dim the base.
static float coat_transmittance(const drift_bsdf_ggx *g, float mu)
{
    return g->clearcoat_principled ? 1.0f : 1.0f - drift__clearcoat_albedo(g, mu);
}

void drift__clearcoat_make(const drift_scene *scene, const drift_material *m,
                           const drift_surface *surface, drift_bsdf_ggx *g)
{
    const drift_ggx_params *p = &m->ggx;
    g->clearcoat = 0.0f;
    float c = p->clearcoat;
    if (!(c > 0.0f)) {
        return;
    }
    float r = sqrtf(drift_clampf(p->clearcoat_alpha, 0.0f, 1.0f));
    if (scene && p->clearcoat_texture != DRIFT_INVALID_INDEX) {
        c *= drift_material_texture(scene, m, DRIFT_TEXTURE_CLEARCOAT, surface).x;
    }
    if (scene && p->clearcoat_roughness_texture != DRIFT_INVALID_INDEX) {
        r *= drift_material_texture(scene, m, DRIFT_TEXTURE_CLEARCOAT_ROUGHNESS, surface).y;
    }
    c = drift_clampf(c, 0.0f, 1.0f);
    if (!(c > 0.0f)) {
        return;
    }
    g->clearcoat = c;
    g->clearcoat_alpha = drift_clampf(r * r, 0.0f, 1.0f);
    g->clearcoat_principled = p->clearcoat_principled;
    float a = coat_alpha(g);
    drift__ggx_alpha_slot(a, &g->clearcoat_row, &g->clearcoat_frac);
    float e1_avg = drift__ggx_e1_avg(a), es_avg = drift__ggx_es_avg(a);
    g->clearcoat_avg = coat_scale(g) * (DRIFT_CLEARCOAT_F0 * (e1_avg - es_avg) + es_avg);
    g->clearcoat_diffuse_gain = drift_vec3_splat(1.0f);
    if (g->clearcoat_principled || !(g->w_plastic > 0.0f)) {
        return;
    }
    if (g->burley_roughness >= 0.0f) {
        // Lambert's: int (1 - c Ec(mu_i)) cos / pi = 1 - c Ec_avg.
        g->clearcoat_diffuse_gain = drift_vec3_splat(1.0f / (1.0f - g->clearcoat_avg));
        return;
    }
    // The layered plastic's diffuse is kd (1 - Ep(mu_o))(1 - Ep(mu_i)) / (pi (1 - Ep_avg)):
    // the ratio of the cosine-weighted integrals of 1 - Ep and (1 - Ep)(1 - c Ec), by the same
    // midpoint rule on the tables' mu grid.
    drift_vec3 plain = drift_vec3_splat(0.0f), coated = plain, one = drift_vec3_splat(1.0f);
    for (int i = 0; i < DRIFT_GGX_TABLE_MU_N; ++i) {
        float mu = ((float)i + 0.5f) / (float)DRIFT_GGX_TABLE_MU_N, e1, es;
        drift__ggx_e1_es_at(mu, g->alpha_row, g->alpha_frac, &e1, &es);
        drift_vec3 ep = drift_vec3_add(drift_vec3_scale(g->f0_coat, e1 - es), drift_vec3_splat(es));
        drift_vec3 below = drift_vec3_scale(drift_vec3_sub(one, ep), mu);
        plain = drift_vec3_add(plain, below);
        coated = drift_vec3_fma(coated, below, coat_transmittance(g, mu));
    }
    g->clearcoat_diffuse_gain =
        drift_vec3_make(plain.x / coated.x, plain.y / coated.y, plain.z / coated.z);
}

// The coat lobe f_coat (scale included), wo and wi above the surface.
static float coat_eval(const drift_bsdf_ggx *g, drift_vec3 wo, drift_vec3 wi)
{
    drift_vec3 h;
    float ss = drift__ggx_reflect_ss(coat_alpha(g), wo, wi, &h);
    if (!(ss > 0.0f)) {
        return 0.0f;
    }
    float m = 1.0f - drift_clampf(drift_vec3_dot(wo, h), 0.0f, 1.0f), m5 = (m * m) * (m * m) * m;
    float fresnel = DRIFT_CLEARCOAT_F0 + (1.0f - DRIFT_CLEARCOAT_F0) * m5;
    return coat_scale(g) * fresnel * ss;
}

static float coat_pdf(const drift_bsdf_ggx *g, drift_vec3 wo, drift_vec3 wi)
{
    return drift__ggx_reflect_pdf(coat_alpha(g), wo, wi);
}

// Probability of sampling the coat lobe toward wo: its albedo against the light the base
// returns through it (the base's albedo estimated from its weights and colours).
static float coat_probability(const drift_bsdf_ggx *g, drift_vec3 wo)
{
    float a = drift__clearcoat_albedo(g, wo.z);
    float base = drift_luminance(g->base);
    float plastic = base + drift_luminance(g->f0_coat) * (1.0f - base);
    float estimate = g->w_conductor * base + g->w_plastic * plastic + g->w_dielectric;
    float rest = coat_transmittance(g, wo.z) * fmaxf(estimate, 0.02f);
    return a / (a + rest);
}

drift_vec3 drift__coated_eval(const drift_bsdf_ggx *g, drift_vec3 wo, drift_vec3 wi,
                              drift_vec3 *out_diffuse)
{
    if (!(g->clearcoat > 0.0f)) {
        return drift__ggx_eval(g, wo, wi, out_diffuse);
    }
    drift_vec3 diffuse;
    drift_vec3 f = drift__ggx_eval(g, wo, wi, &diffuse);
    if (!(wo.z > 0.0f)) {
        if (out_diffuse) {
            *out_diffuse = diffuse;
        }
        return f;
    }
    // Transmission through a coated dielectric is dimmed on both sides too (docs/materials.md).
    float t = coat_transmittance(g, wo.z) * coat_transmittance(g, fabsf(wi.z));
    drift_vec3 more =
        drift_vec3_mul(diffuse, drift_vec3_sub(g->clearcoat_diffuse_gain, drift_vec3_splat(1.0f)));
    f = drift_vec3_scale(drift_vec3_add(f, more), t);
    if (out_diffuse) {
        *out_diffuse = drift_vec3_scale(drift_vec3_mul(diffuse, g->clearcoat_diffuse_gain), t);
    }
    if (wi.z > 0.0f && !g->skip_reflection) {
        f = drift_vec3_add(f, drift_vec3_splat(coat_eval(g, wo, wi)));
    }
    return f;
}

float drift__coated_pdf(const drift_bsdf_ggx *g, drift_vec3 wo, drift_vec3 wi)
{
    if (!(g->clearcoat > 0.0f) || !(wo.z > 0.0f)) {
        return drift__ggx_pdf(g, wo, wi);
    }
    float p = coat_probability(g, wo);
    float pdf = (1.0f - p) * drift__ggx_pdf(g, wo, wi);
    if (wi.z > 0.0f) {
        pdf += p * coat_pdf(g, wo, wi);
    }
    return pdf;
}

drift_bsdf_sample drift__coated_sample(const drift_bsdf_ggx *g, drift_vec3 wo, float u_lobe,
                                       drift_vec2 u)
{
    if (!(g->clearcoat > 0.0f)) {
        return drift__ggx_sample(g, wo, u_lobe, u);
    }
    drift_bsdf_sample s = { 0 };
    if (!(wo.z > 0.0f)) {
        return s;
    }
    float p = coat_probability(g, wo);
    drift_vec3 wi;
    if (u_lobe < p) {
        drift_vec3 m = drift__ggx_sample_vndf(coat_alpha(g), wo, u);
        wi = drift_vec3_sub(drift_vec3_scale(m, 2.0f * drift_vec3_dot(wo, m)), wo);
        if (wi.z <= 0.0f) {
            return s;
        }
    } else {
        // u_lobe's rest, rescaled to [0, 1), picks the base's lobe.
        float v = fminf((u_lobe - p) / (1.0f - p), 0x1.fffffep-1f);
        drift_bsdf_sample b = drift__ggx_sample(g, wo, v, u);
        if (!(b.pdf > 0.0f) || b.is_delta) {
            // A delta direction (smooth glass) has no coat lobe: only the coat's dimming.
            float t = coat_transmittance(g, wo.z) * coat_transmittance(g, fabsf(b.wi.z));
            b.weight = drift_vec3_scale(b.weight, t / (1.0f - p));
            b.pdf *= 1.0f - p;
            return b;
        }
        wi = b.wi;
    }
    s.pdf = drift__coated_pdf(g, wo, wi);
    if (!(s.pdf > 0.0f) || wi.z == 0.0f) {
        return (drift_bsdf_sample){ 0 };
    }
    s.wi = wi;
    s.weight = drift_vec3_scale(drift__coated_eval(g, wo, wi, NULL), fabsf(wi.z) / s.pdf);
    return s;
}

void drift__clearcoat_dim_albedo(const drift_bsdf_ggx *g, float mu, drift_vec3 *single,
                                 drift_vec3 *multiple)
{
    if (!(g->clearcoat > 0.0f) || g->clearcoat_principled) {
        return;
    }
    // Around the mirror direction mu_i ~ mu_o; the nearly cosine-shaped multiple-scattering
    // lobe meets the coat at every mu_i: its average.
    float t = coat_transmittance(g, mu);
    *single = drift_vec3_scale(*single, t * t);
    *multiple = drift_vec3_scale(*multiple, t * (1.0f - g->clearcoat_avg));
}

void drift__clearcoat_phong(const drift_material *m, drift_vec3 *kd, drift_vec3 *ks)
{
    const drift_ggx_params *p = &m->ggx;
    float c = drift_clampf(p->clearcoat, 0.0f, 1.0f);
    if (!(c > 0.0f)) {
        return;
    }
    float scale = p->clearcoat_principled ? 0.25f * c : c;
    float t = p->clearcoat_principled ? 1.0f : 1.0f - scale * DRIFT_CLEARCOAT_F0;
    *kd = drift_vec3_scale(*kd, t * t);
    *ks =
        drift_vec3_add(drift_vec3_scale(*ks, t * t), drift_vec3_splat(scale * DRIFT_CLEARCOAT_F0));
}

float drift_bsdf_clearcoat_albedo(const drift_bsdf *bsdf, float mu, float *out_alpha)
{
    if (out_alpha) {
        *out_alpha = bsdf->ggx.clearcoat_alpha;
    }
    if (bsdf->type != DRIFT_MATERIAL_GGX || !(mu > 0.0f)) {
        return 0.0f;
    }
    return drift__clearcoat_albedo(&bsdf->ggx, fminf(mu, 1.0f));
}
