// DRIFT_MATERIAL_GGX: a conductor, a dielectric-coated diffuse ("plastic") and a dielectric
// that refracts, blended by weight (glTF's metallic-roughness and transmission), all on GGX
// microfacets (Walter et al. 2007) with height-correlated Smith masking and visible-normal
// sampling (microfacet.c). Energy lost by single scattering comes back for the conductor in a
// multiple-scattering lobe of Kulla & Conty's (2017) colour F_ms and albedo 1 - E(mu_o), shaped
// as a broader GGX lobe about the specular direction (microfacet.h, docs/materials.md), where
// Heitz et al.'s (2016) random walk puts it; the plastic's diffuse base receives what
// its coat does not reflect, (1 - Ec(mu_o))(1 - Ec(mu_i)) / (pi (1 - Ec_avg)), so a white
// plastic reflects exactly 1; the rough dielectric is divided by its single-scattering albedo
// (Turquin 2019's normalisation for a lossless interface). docs/materials.md has the model.
#include "clearcoat.h"
#include "microfacet.h"

#include <math.h>
#include <string.h>

typedef struct named_metal {
    const char *names[3];
    drift_vec3 eta, k;
} named_metal;

// Measured complex IOR integrated to linear sRGB primaries (the spectral tables Mitsuba
// ships, as Tungsten's ComplexIorData converts them): Au, Ag, Cu from Johnson & Christy
// 1972, Al from Rakic 1995.
static const named_metal named_metals[] = {
    { { "Au", "gold", NULL },
      { 0.1431189557f, 0.3749570432f, 1.4424785571f },
      { 3.9831604247f, 2.3857207478f, 1.6032152899f } },
    { { "Ag", "silver", NULL },
      { 0.1552646489f, 0.1167232965f, 0.1383806959f },
      { 4.8283433224f, 3.1222459278f, 2.1469504455f } },
    { { "Cu", "copper", NULL },
      { 0.2004376970f, 0.9240334304f, 1.1022119527f },
      { 3.9129485033f, 2.4528477015f, 2.1421879552f } },
    { { "Al", "aluminium", "aluminum" },
      { 1.6574599595f, 0.8803689579f, 0.5212287346f },
      { 9.2238691996f, 6.2695232477f, 4.8370012281f } },
};

bool drift_ggx_named_metal(const char *name, drift_ggx_params *ggx)
{
    for (size_t i = 0; name && i < sizeof(named_metals) / sizeof(named_metals[0]); ++i) {
        for (int j = 0; j < 3 && named_metals[i].names[j]; ++j) {
            if (strcmp(name, named_metals[i].names[j]) == 0) {
                ggx->eta = named_metals[i].eta;
                ggx->k = named_metals[i].k;
                ggx->metallic = 1.0f;
                return true;
            }
        }
    }
    return false;
}

static drift_vec3 schlick(drift_vec3 f0, float c)
{
    float m = 1.0f - drift_clampf(c, 0.0f, 1.0f), m5 = (m * m) * (m * m) * m;
    return drift_vec3_add(f0, drift_vec3_scale(drift_vec3_sub(drift_vec3_splat(1.0f), f0), m5));
}

static drift_vec3 conductor_fresnel(const drift_bsdf_ggx *g, float c)
{
    return g->schlick ? schlick(g->base, c) : drift__fresnel_conductor(c, g->eta, g->k);
}

static bool smooth_dielectric(const drift_bsdf_ggx *g)
{
    return g->thin || g->alpha < DRIFT_GGX_MIN_ALPHA;
}

bool drift_bsdf_is_smooth_glass(const drift_bsdf *bsdf)
{
    return bsdf->type == DRIFT_MATERIAL_GGX && bsdf->ggx.w_dielectric > 0.0f &&
           smooth_dielectric(&bsdf->ggx);
}

bool drift_bsdf_is_glass(const drift_bsdf *bsdf)
{
    return bsdf->type == DRIFT_MATERIAL_GGX && bsdf->ggx.w_dielectric > 0.0f;
}

bool drift__ggx_is_delta(const drift_bsdf_ggx *g)
{
    return g->w_dielectric >= 1.0f && smooth_dielectric(g);
}

static float g2(float alpha, drift_vec3 wo, drift_vec3 wi)
{
    return 1.0f / (1.0f + drift__ggx_lambda(alpha, wo) + drift__ggx_lambda(alpha, wi));
}

// The coat's directional albedo per channel: F0 (E1 - Es) + Es.
static drift_vec3 coat_albedo(drift_vec3 f0, float e1, float es)
{
    return drift_vec3_add(drift_vec3_scale(f0, e1 - es), drift_vec3_splat(es));
}

// The conductor's and the coat's roughness: a smooth one is a very sharp lobe, not a delta.
static float ra(const drift_bsdf_ggx *g)
{
    return fmaxf(g->alpha, DRIFT_GGX_MIN_ALPHA);
}

// E1 and Es at cos theta = mu for this BSDF's roughness.
static void albedos(const drift_bsdf_ggx *g, float mu, float *e1, float *es)
{
    drift__ggx_e1_es_at(mu, g->alpha_row, g->alpha_frac, e1, es);
}

// --- CONDUCTOR ---

// Kulla & Conty's colour of the multiply scattered light, F_ms = F_avg^2 E_avg / (1 - F_avg (1 -
// E_avg)) with F_avg = F0 + (1 - F0) / 21 (exact for Schlick).
static drift_vec3 conductor_f_ms(const drift_bsdf_ggx *g)
{
    drift_vec3 f0 = conductor_fresnel(g, 1.0f);
    drift_vec3 f_avg = drift_vec3_add(
        f0, drift_vec3_scale(drift_vec3_sub(drift_vec3_splat(1.0f), f0), 1.0f / 21.0f));
    float e_avg = g->e1_avg;
    drift_vec3 f_ms;
    f_ms.x = f_avg.x * f_avg.x * e_avg / (1.0f - f_avg.x * (1.0f - e_avg));
    f_ms.y = f_avg.y * f_avg.y * e_avg / (1.0f - f_avg.y * (1.0f - e_avg));
    f_ms.z = f_avg.z * f_avg.z * e_avg / (1.0f - f_avg.z * (1.0f - e_avg));
    return f_ms;
}

// The multiple-scattering lobe with F = 1 at wo, wi (both above) and their half vector h:
// s(mu_o) s(mu_i) K(mu_o, mu_i) D2(h) G2(wo, wi) / (4 mu_o mu_i) of the broad roughness; its pdf
// (the broad lobe's visible normals) in out_pdf.
static float ms_lobe(const drift_bsdf_ggx *g, drift_vec3 wo, drift_vec3 wi, drift_vec3 h,
                     float *out_pdf)
{
    float a2 = drift__ggx_ms_alpha(g->alpha);
    float d = drift__ggx_d(a2, h);
    float lo = drift__ggx_lambda(a2, wo), li = drift__ggx_lambda(a2, wi);
    // D_wo(h) / (4 wo.h) = G1(wo) D / (4 wo.z).
    *out_pdf = d / ((1.0f + lo) * 4.0f * wo.z);
    float s = drift__ggx_ms_scale_at(wo.z, g->alpha_row, g->alpha_frac) *
              drift__ggx_ms_scale_at(wi.z, g->alpha_row, g->alpha_frac) *
              drift__ggx_ms_kernel(drift__ggx_ms_beta(g->alpha), wo.z, wi.z);
    return s * d / ((1.0f + lo + li) * 4.0f * wo.z * wi.z);
}

// Whether the conductor loses enough to single scattering to have the lobe at all.
static bool has_ms(const drift_bsdf_ggx *g)
{
    return g->e1_avg < 0.9999f;
}

static drift_vec3 conductor_eval(const drift_bsdf_ggx *g, drift_vec3 wo, drift_vec3 wi)
{
    drift_vec3 h;
    float ss = drift__ggx_reflect_ss(ra(g), wo, wi, &h);
    if (!(ss > 0.0f)) {
        return drift_vec3_splat(0.0f);
    }
    drift_vec3 f = drift_vec3_scale(conductor_fresnel(g, drift_vec3_dot(wo, h)), ss);
    if (has_ms(g)) {
        float unused;
        f = drift_vec3_fma(f, conductor_f_ms(g), ms_lobe(g, wo, wi, h, &unused));
    }
    return f;
}

// Probability of sampling the single-scattering lobe, E1(mu_o): the rest, the albedo of the
// multiple-scattering lobe with F = 1, goes to it.
static float conductor_p_ss(const drift_bsdf_ggx *g, drift_vec3 wo)
{
    float e1, es;
    albedos(g, wo.z, &e1, &es);
    return has_ms(g) ? drift_clampf(e1, 0.0f, 1.0f) : 1.0f;
}

static float conductor_pdf(const drift_bsdf_ggx *g, drift_vec3 wo, drift_vec3 wi)
{
    float p = conductor_p_ss(g, wo);
    float pdf = p * drift__ggx_reflect_pdf(ra(g), wo, wi);
    if (p < 1.0f) {
        drift_vec3 h = drift_vec3_normalize(drift_vec3_add(wo, wi));
        float pdf_ms;
        ms_lobe(g, wo, wi, h, &pdf_ms);
        pdf += (1.0f - p) * pdf_ms;
    }
    return pdf;
}

// --- PLASTIC ---

// The coat's Fresnel: Schlick of F0 (glTF); for the Principled form (a Burley base) Cycles
// 3.4's interpolate_fresnel_color, the exact dielectric Fresnel of the IOR rescaled to run from
// F0 to 1 (up to 27% above Schlick at 60 degrees off the half vector for IOR 1.5).
static drift_vec3 coat_fresnel(const drift_bsdf_ggx *g, float c)
{
    if (g->burley_roughness < 0.0f) {
        return schlick(g->f0_coat, c);
    }
    float eta = fmaxf(g->eta_rel, 1.0f / g->eta_rel), f0n = (eta - 1.0f) / (eta + 1.0f);
    f0n *= f0n;
    float fh = f0n < 1.0f ? (drift__fresnel_dielectric(drift_clampf(c, 0.0f, 1.0f), eta) - f0n) /
                                (1.0f - f0n)
                          : 1.0f;
    return drift_vec3_add(drift_vec3_scale(g->f0_coat, 1.0f - fh), drift_vec3_splat(fh));
}

static drift_vec3 plastic_eval(const drift_bsdf_ggx *g, drift_vec3 wo, drift_vec3 wi,
                               drift_vec3 *out_diffuse)
{
    drift_vec3 h;
    float ss = drift__ggx_reflect_ss(ra(g), wo, wi, &h);
    drift_vec3 coat = drift_vec3_scale(coat_fresnel(g, drift_vec3_dot(wo, h)), ss);
    if (g->burley_roughness >= 0.0f) {
        // Burley's factor (docs/materials.md): F_D90 = 1/2 + r (1 + wi.wo).
        float fd90_minus_1 = g->burley_roughness * (1.0f + drift_vec3_dot(wo, wi)) - 0.5f;
        float fo = 1.0f - wo.z, fi = 1.0f - wi.z;
        float fo5 = (fo * fo) * (fo * fo) * fo, fi5 = (fi * fi) * (fi * fi) * fi;
        float burley = (1.0f + fd90_minus_1 * fi5) * (1.0f + fd90_minus_1 * fo5);
        *out_diffuse = drift_vec3_scale(g->base, burley * DRIFT_INV_PI);
        return drift_vec3_add(coat, *out_diffuse);
    }
    float e1_o, es_o, e1_i, es_i;
    albedos(g, wo.z, &e1_o, &es_o);
    albedos(g, wi.z, &e1_i, &es_i);
    drift_vec3 ec_o = coat_albedo(g->f0_coat, e1_o, es_o);
    drift_vec3 ec_i = coat_albedo(g->f0_coat, e1_i, es_i);
    drift_vec3 ec_avg = coat_albedo(g->f0_coat, g->e1_avg, g->es_avg);
    drift_vec3 one = drift_vec3_splat(1.0f);
    drift_vec3 base = drift_vec3_mul(drift_vec3_sub(one, ec_o), drift_vec3_sub(one, ec_i));
    drift_vec3 denom = drift_vec3_scale(drift_vec3_sub(one, ec_avg), DRIFT_PI);
    base = drift_vec3_make(base.x / denom.x, base.y / denom.y, base.z / denom.z);
    *out_diffuse = drift_vec3_mul(g->base, base);
    return drift_vec3_add(coat, *out_diffuse);
}

static float plastic_p_coat(const drift_bsdf_ggx *g, drift_vec3 wo)
{
    float e1, es;
    albedos(g, wo.z, &e1, &es);
    drift_vec3 ec = coat_albedo(g->f0_coat, e1, es);
    float lc = drift_luminance(ec);
    float ld =
        drift_luminance(g->burley_roughness >= 0.0f
                            ? g->base
                            : drift_vec3_mul(g->base, drift_vec3_sub(drift_vec3_splat(1.0f), ec)));
    return lc + ld > 0.0f ? lc / (lc + ld) : 1.0f;
}

static float plastic_pdf(const drift_bsdf_ggx *g, drift_vec3 wo, drift_vec3 wi)
{
    float p = plastic_p_coat(g, wo);
    return p * drift__ggx_reflect_pdf(ra(g), wo, wi) + (1.0f - p) * wi.z * DRIFT_INV_PI;
}

// --- ROUGH DIELECTRIC (Walter et al. 2007, as pbrt-v4 writes it) ---

// The generalized half vector of wo and wi (facing +z) and whether the pair is a valid
// reflection or refraction through it.
static bool dielectric_half(const drift_bsdf_ggx *g, drift_vec3 wo, drift_vec3 wi, bool *reflect,
                            drift_vec3 *out_m)
{
    *reflect = wi.z > 0.0f;
    float etap = *reflect ? 1.0f : g->eta_rel;
    drift_vec3 m = drift_vec3_add(drift_vec3_scale(wi, etap), wo);
    float len = drift_vec3_length(m);
    if (wi.z == 0.0f || !(len > 0.0f)) {
        return false;
    }
    m = drift_vec3_scale(m, 1.0f / len);
    if (m.z < 0.0f) {
        m = drift_vec3_neg(m);
    }
    *out_m = m;
    // Microfacets seen from the wrong side contribute nothing.
    return drift_vec3_dot(m, wi) * wi.z > 0.0f && drift_vec3_dot(m, wo) > 0.0f;
}

static float dielectric_eval(const drift_bsdf_ggx *g, drift_vec3 wo, drift_vec3 wi)
{
    bool reflect;
    drift_vec3 m;
    if (!dielectric_half(g, wo, wi, &reflect, &m)) {
        return 0.0f;
    }
    float alpha = g->alpha, f = drift__fresnel_dielectric(drift_vec3_dot(wo, m), g->eta_rel);
    float value;
    if (reflect) {
        value = f * drift__ggx_d(alpha, m) * g2(alpha, wo, wi) / (4.0f * wo.z * wi.z);
    } else {
        float wi_m = drift_vec3_dot(wi, m), wo_m = drift_vec3_dot(wo, m);
        float denom = wi_m + wo_m / g->eta_rel;
        value = (1.0f - f) * drift__ggx_d(alpha, m) * g2(alpha, wo, wi) *
                fabsf(wi_m * wo_m / (wi.z * wo.z * denom * denom));
    }
    return value / drift__ggx_e_dielectric(wo.z, alpha, g->eta_rel);
}

static float dielectric_pdf(const drift_bsdf_ggx *g, drift_vec3 wo, drift_vec3 wi)
{
    bool reflect;
    drift_vec3 m;
    if (!dielectric_half(g, wo, wi, &reflect, &m)) {
        return 0.0f;
    }
    float wo_m = drift_vec3_dot(wo, m), f = drift__fresnel_dielectric(wo_m, g->eta_rel);
    float pm = drift__ggx_pdf_vndf(g->alpha, wo, m);
    if (reflect) {
        return f * pm / (4.0f * wo_m);
    }
    float wi_m = drift_vec3_dot(wi, m), denom = wi_m + wo_m / g->eta_rel;
    return (1.0f - f) * pm * fabsf(wi_m) / (denom * denom);
}

// --- THE BLEND ---

drift_vec3 drift__ggx_eval(const drift_bsdf_ggx *g, drift_vec3 wo, drift_vec3 wi,
                           drift_vec3 *out_diffuse)
{
    drift_vec3 f = drift_vec3_splat(0.0f), diffuse = f;
    if (wo.z > 0.0f && wi.z > 0.0f) {
        if (g->w_conductor > 0.0f && !g->skip_reflection) {
            f = drift_vec3_scale(conductor_eval(g, wo, wi), g->w_conductor);
        }
        if (g->w_plastic > 0.0f) {
            drift_vec3 p = plastic_eval(g, wo, wi, &diffuse);
            p = g->skip_reflection ? diffuse : p;
            if (g->skip_diffuse) {
                p = drift_vec3_sub(p, diffuse);
                diffuse = drift_vec3_splat(0.0f);
            }
            f = drift_vec3_fma(f, p, g->w_plastic);
            diffuse = drift_vec3_scale(diffuse, g->w_plastic);
        }
    }
    if (wo.z > 0.0f && g->w_dielectric > 0.0f && !smooth_dielectric(g)) {
        f = drift_vec3_add(f, drift_vec3_splat(g->w_dielectric * dielectric_eval(g, wo, wi)));
    }
    if (out_diffuse) {
        *out_diffuse = diffuse;
    }
    return f;
}

float drift__ggx_pdf(const drift_bsdf_ggx *g, drift_vec3 wo, drift_vec3 wi)
{
    float pdf = 0.0f;
    if (wo.z > 0.0f && wi.z > 0.0f) {
        if (g->w_conductor > 0.0f) {
            pdf += g->w_conductor * conductor_pdf(g, wo, wi);
        }
        if (g->w_plastic > 0.0f) {
            pdf += g->w_plastic * plastic_pdf(g, wo, wi);
        }
    }
    if (wo.z > 0.0f && g->w_dielectric > 0.0f && !smooth_dielectric(g)) {
        pdf += g->w_dielectric * dielectric_pdf(g, wo, wi);
    }
    return pdf;
}

// drift__ggx_eval and drift__ggx_pdf at once for a material without a dielectric part and
// wo, wi above the surface (the sampling's case): the half vector, D, both Lambdas and the
// albedo lookups are shared.
static drift_vec3 reflection_eval_pdf(const drift_bsdf_ggx *g, drift_vec3 wo, drift_vec3 wi,
                                      float *out_pdf)
{
    float a = ra(g);
    drift_vec3 h = drift_vec3_add(wo, wi);
    float len = drift_vec3_length(h);
    *out_pdf = 0.0f;
    if (!(len > 0.0f)) {
        return drift_vec3_splat(0.0f);
    }
    h = drift_vec3_scale(h, 1.0f / len);
    float wo_h = drift_vec3_dot(wo, h);
    float d = drift__ggx_d(a, h);
    float lo = drift__ggx_lambda(a, wo), li = drift__ggx_lambda(a, wi);
    float ss = d / ((1.0f + lo + li) * 4.0f * wo.z * wi.z);
    // D_wo(h) / (4 wo.h) = G1(wo) D / (4 wo.z).
    float pdf_r = wo_h > 0.0f ? d / ((1.0f + lo) * 4.0f * wo.z) : 0.0f;
    float pdf_c = wi.z * DRIFT_INV_PI;
    float e1_o, es_o;
    albedos(g, wo.z, &e1_o, &es_o);
    drift_vec3 f = drift_vec3_splat(0.0f);
    float pdf = 0.0f;
    if (g->w_conductor > 0.0f) {
        drift_vec3 fc = drift_vec3_scale(conductor_fresnel(g, wo_h), ss);
        float p = 1.0f, pdf_ms = 0.0f;
        if (has_ms(g)) {
            fc = drift_vec3_fma(fc, conductor_f_ms(g), ms_lobe(g, wo, wi, h, &pdf_ms));
            p = drift_clampf(e1_o, 0.0f, 1.0f);
        }
        f = drift_vec3_scale(fc, g->w_conductor);
        pdf += g->w_conductor * (p * pdf_r + (1.0f - p) * pdf_ms);
    }
    if (g->w_plastic > 0.0f) {
        drift_vec3 coat = drift_vec3_scale(coat_fresnel(g, wo_h), ss);
        drift_vec3 one = drift_vec3_splat(1.0f);
        drift_vec3 ec_o = coat_albedo(g->f0_coat, e1_o, es_o);
        drift_vec3 base;
        if (g->burley_roughness >= 0.0f) {
            float fd90_minus_1 = g->burley_roughness * (1.0f + drift_vec3_dot(wo, wi)) - 0.5f;
            float fo = 1.0f - wo.z, fi = 1.0f - wi.z;
            float fo5 = (fo * fo) * (fo * fo) * fo, fi5 = (fi * fi) * (fi * fi) * fi;
            float burley = (1.0f + fd90_minus_1 * fi5) * (1.0f + fd90_minus_1 * fo5);
            base = drift_vec3_scale(g->base, burley * DRIFT_INV_PI);
        } else {
            float e1_i, es_i; // only the layered base reads the albedo toward wi
            albedos(g, wi.z, &e1_i, &es_i);
            drift_vec3 ec_i = coat_albedo(g->f0_coat, e1_i, es_i);
            drift_vec3 ec_avg = coat_albedo(g->f0_coat, g->e1_avg, g->es_avg);
            base = drift_vec3_mul(drift_vec3_sub(one, ec_o), drift_vec3_sub(one, ec_i));
            drift_vec3 denom = drift_vec3_scale(drift_vec3_sub(one, ec_avg), DRIFT_PI);
            base = drift_vec3_mul(
                g->base, drift_vec3_make(base.x / denom.x, base.y / denom.y, base.z / denom.z));
        }
        float lc = drift_luminance(ec_o);
        float ld = drift_luminance(g->burley_roughness >= 0.0f
                                       ? g->base
                                       : drift_vec3_mul(g->base, drift_vec3_sub(one, ec_o)));
        float p = lc + ld > 0.0f ? lc / (lc + ld) : 1.0f;
        f = drift_vec3_fma(f, drift_vec3_add(coat, base), g->w_plastic);
        pdf += g->w_plastic * (p * pdf_r + (1.0f - p) * pdf_c);
    }
    *out_pdf = pdf;
    return f;
}

// A smooth (or thin-walled) dielectric: reflect with probability R, else transmit.
static drift_bsdf_sample sample_smooth_dielectric(const drift_bsdf_ggx *g, drift_vec3 wo, float u)
{
    drift_bsdf_sample s = { .is_delta = true, .weight = drift_vec3_splat(1.0f) };
    float r = drift__fresnel_dielectric(wo.z, g->thin ? fmaxf(g->eta_rel, 1.0f / g->eta_rel)
                                                      : g->eta_rel);
    if (g->thin && r < 1.0f) {
        r += (1.0f - r) * (1.0f - r) * r / (1.0f - r * r); // inter-reflections in the slab
    }
    if (u < r) {
        s.wi = drift_vec3_make(-wo.x, -wo.y, wo.z);
        s.pdf = g->w_dielectric * r;
    } else if (g->thin) {
        s.wi = drift_vec3_neg(wo);
        s.pdf = g->w_dielectric * (1.0f - r);
    } else {
        if (!drift__refract(wo, drift_vec3_make(0.0f, 0.0f, 1.0f), g->eta_rel, &s.wi)) {
            return (drift_bsdf_sample){ 0 };
        }
        s.pdf = g->w_dielectric * (1.0f - r);
    }
    return s;
}

drift_bsdf_sample drift__ggx_sample(const drift_bsdf_ggx *g, drift_vec3 wo, float u_lobe,
                                    drift_vec2 u)
{
    drift_bsdf_sample s = { 0 };
    if (!(wo.z > 0.0f)) {
        return s;
    }
    drift_vec3 wi;
    if (u_lobe < g->w_conductor || u_lobe < g->w_conductor + g->w_plastic) {
        bool conductor = u_lobe < g->w_conductor;
        float w = conductor ? g->w_conductor : g->w_plastic;
        float v = (u_lobe - (conductor ? 0.0f : g->w_conductor)) / w;
        float p = conductor ? conductor_p_ss(g, wo) : plastic_p_coat(g, wo);
        if (v < p || conductor) {
            // The specular lobe, or the conductor's broader multiple-scattering lobe.
            float a = v < p ? ra(g) : drift__ggx_ms_alpha(g->alpha);
            drift_vec3 m = drift__ggx_sample_vndf(a, wo, u);
            wi = drift_vec3_sub(drift_vec3_scale(m, 2.0f * drift_vec3_dot(wo, m)), wo);
            if (wi.z <= 0.0f) {
                return s;
            }
        } else {
            wi = drift_sample_cosine_hemisphere(u);
        }
    } else {
        if (smooth_dielectric(g)) {
            float v = (u_lobe - g->w_conductor - g->w_plastic) / fmaxf(g->w_dielectric, 1e-12f);
            return sample_smooth_dielectric(g, wo, drift_clampf(v, 0.0f, 1.0f));
        }
        float v = (u_lobe - g->w_conductor - g->w_plastic) / fmaxf(g->w_dielectric, 1e-12f);
        drift_vec3 m = drift__ggx_sample_vndf(g->alpha, wo, u);
        float wo_m = drift_vec3_dot(wo, m);
        if (v < drift__fresnel_dielectric(wo_m, g->eta_rel)) {
            wi = drift_vec3_sub(drift_vec3_scale(m, 2.0f * wo_m), wo);
            if (wi.z <= 0.0f) {
                return s;
            }
        } else if (!drift__refract(wo, m, g->eta_rel, &wi) || wi.z >= 0.0f) {
            return s;
        }
    }
    drift_vec3 f;
    if (g->w_dielectric <= 0.0f && wi.z > 0.0f) {
        f = reflection_eval_pdf(g, wo, wi, &s.pdf);
    } else {
        s.pdf = drift__ggx_pdf(g, wo, wi);
        f = drift__ggx_eval(g, wo, wi, NULL);
    }
    if (!(s.pdf > 0.0f) || wi.z == 0.0f) {
        return (drift_bsdf_sample){ 0 };
    }
    s.wi = wi;
    s.weight = drift_vec3_scale(f, fabsf(wi.z) / s.pdf);
    return s;
}

void drift_bsdf_ggx_reflection_albedo(const drift_bsdf *bsdf, float mu, drift_vec3 *out_single,
                                      drift_vec3 *out_multiple)
{
    const drift_bsdf_ggx *g = &bsdf->ggx;
    drift_vec3 single = drift_vec3_splat(0.0f), multiple = single;
    if (bsdf->type == DRIFT_MATERIAL_GGX && mu > 0.0f) {
        float e1, es;
        albedos(g, fminf(mu, 1.0f), &e1, &es);
        if (g->w_conductor > 0.0f) {
            // Exact for Schlick's Fresnel; for eta/k the Schlick curve through its F0.
            drift_vec3 f0 = conductor_fresnel(g, 1.0f);
            single = drift_vec3_scale(coat_albedo(f0, e1, es), g->w_conductor);
            if (has_ms(g)) {
                // The multiple-scattering lobe's albedo: F_ms (1 - E(mu)) (its scale s is fitted
                // to that, microfacet.h).
                multiple = drift_vec3_scale(conductor_f_ms(g), g->w_conductor * (1.0f - e1));
            }
        }
        if (g->w_plastic > 0.0f) {
            single = drift_vec3_fma(single, coat_albedo(g->f0_coat, e1, es), g->w_plastic);
        }
        if (g->w_dielectric > 0.0f && smooth_dielectric(g)) {
            // A smooth dielectric's reflection, a delta no light sample finds: its Fresnel
            // (a thin sheet's with the inter-reflections, as its sampling has it).
            float r = drift__fresnel_dielectric(
                fminf(mu, 1.0f), g->thin ? fmaxf(g->eta_rel, 1.0f / g->eta_rel) : g->eta_rel);
            if (g->thin && r < 1.0f) {
                r += (1.0f - r) * (1.0f - r) * r / (1.0f - r * r);
            }
            single = drift_vec3_add(single, drift_vec3_splat(g->w_dielectric * r));
        }
        drift__clearcoat_dim_albedo(g, fminf(mu, 1.0f), &single, &multiple);
    }
    *out_single = single;
    *out_multiple = multiple;
}

drift_vec3 drift_ggx_sample_visible_normal(float alpha, drift_vec3 wo, drift_vec2 u)
{
    return drift__ggx_sample_vndf(fmaxf(alpha, DRIFT_GGX_MIN_ALPHA), wo, u);
}

float drift_ggx_multiple_scattering_alpha(float alpha)
{
    return drift__ggx_ms_alpha(alpha);
}
