// Lambertian diffuse plus a normalized modified-Phong glossy lobe (Lafortune & Willems 1994,
// "Using the Modified Phong Reflectance Model for Physically Based Rendering"), and a perfect
// mirror; or, for materials from Blender and glTF, Burley's diffuse ("Physically-Based Shading
// at Disney", 2012, section 5.3) in place of the Lambertian one. Directions are world space;
// the lobe frame's z is the shading normal.
#include "scene_internal.h"

#include <math.h>

drift_bsdf drift_bsdf_make(const drift_scene *scene, const drift_surface *surface)
{
    const drift_material *m = &scene->materials[surface->material];
    drift_bsdf b = { .type = m->type,
                     .diffuse = m->diffuse,
                     .specular = m->specular,
                     .exponent = m->exponent,
                     .diffuse_model = m->diffuse_model,
                     .diffuse_roughness = m->diffuse_roughness,
                     .frame = drift_frame_from_normal(surface->ns) };
    if (m->diffuse_texture != DRIFT_INVALID_INDEX) {
        b.diffuse = drift_vec3_mul(
            b.diffuse, drift__texture_bilinear(&scene->textures[m->diffuse_texture], surface->uv));
    }
    return b;
}

bool drift_bsdf_is_delta(const drift_bsdf *bsdf)
{
    return bsdf->type == DRIFT_MATERIAL_MIRROR;
}

// Probability of sampling the glossy lobe rather than the diffuse one.
static float glossy_probability(const drift_bsdf *b)
{
    float ld = drift_luminance(b->diffuse), ls = drift_luminance(b->specular);
    return ld + ls > 0.0f ? ls / (ld + ls) : 0.0f;
}

// The direction the lobes centre on: the mirror direction of wo, or the edited one.
static drift_vec3 lobe_axis(const drift_bsdf *b, drift_vec3 wo)
{
    return drift_vec3_is_zero(b->edited_mirror) ? drift_vec3_reflect(wo, b->frame.z)
                                                : b->edited_mirror;
}

drift_vec3 drift_bsdf_mirror_direction(const drift_bsdf *bsdf, drift_vec3 wo)
{
    return lobe_axis(bsdf, wo);
}

// cos(alpha), alpha between wi and the lobe's axis (0 past a right angle).
static float phong_cos_alpha(const drift_bsdf *b, drift_vec3 wo, drift_vec3 wi)
{
    drift_vec3 r = lobe_axis(b, wo);
    return fmaxf(0.0f, drift_vec3_dot(r, wi));
}

// Burley's diffuse over Lambert's: (1 + (F_D90 − 1)(1 − cos θl)^5)(1 + (F_D90 − 1)(1 − cos θv)^5)
// with F_D90 = 0.5 + 2 roughness cos² θd, θd the angle between wi and the half vector
// (2 cos² θd = 1 + wi·wo). Darker than Lambert at grazing angles when smooth, brighter
// (retro-reflection) when rough; 1 at normal incidence. Cycles' Principled BSDF (Blender 3.4)
// evaluates the same expression.
static float burley_factor(float roughness, float cos_o, float cos_i, float cos_oi)
{
    float fd90_minus_1 = roughness * (1.0f + cos_oi) - 0.5f;
    float fo = 1.0f - cos_o, fi = 1.0f - cos_i;
    float fo5 = (fo * fo) * (fo * fo) * fo, fi5 = (fi * fi) * (fi * fi) * fi;
    return (1.0f + fd90_minus_1 * fi5) * (1.0f + fd90_minus_1 * fo5);
}

void drift_bsdf_eval_lobes(const drift_bsdf *bsdf, drift_vec3 wo, drift_vec3 wi,
                           drift_vec3 *out_diffuse, drift_vec3 *out_glossy)
{
    *out_diffuse = drift_vec3_splat(0.0f);
    *out_glossy = drift_vec3_splat(0.0f);
    float cos_o = drift_vec3_dot(wo, bsdf->frame.z), cos_i = drift_vec3_dot(wi, bsdf->frame.z);
    if (bsdf->type == DRIFT_MATERIAL_MIRROR || cos_o <= 0.0f || cos_i <= 0.0f) {
        return;
    }
    float diffuse = DRIFT_INV_PI;
    if (bsdf->diffuse_model == DRIFT_DIFFUSE_BURLEY) {
        diffuse *= burley_factor(bsdf->diffuse_roughness, cos_o, cos_i, drift_vec3_dot(wo, wi));
    }
    *out_diffuse = drift_vec3_scale(bsdf->diffuse, diffuse);
    if (!drift_vec3_is_zero(bsdf->specular)) {
        float n = bsdf->exponent;
        float lobe = (n + 2.0f) * DRIFT_INV_2PI * powf(phong_cos_alpha(bsdf, wo, wi), n);
        *out_glossy = drift_vec3_scale(bsdf->specular, lobe);
    }
}

drift_vec3 drift_bsdf_eval(const drift_bsdf *bsdf, drift_vec3 wo, drift_vec3 wi)
{
    drift_vec3 diffuse, glossy;
    drift_bsdf_eval_lobes(bsdf, wo, wi, &diffuse, &glossy);
    return drift_vec3_add(diffuse, glossy);
}

float drift_bsdf_pdf(const drift_bsdf *bsdf, drift_vec3 wo, drift_vec3 wi)
{
    float cos_o = drift_vec3_dot(wo, bsdf->frame.z), cos_i = drift_vec3_dot(wi, bsdf->frame.z);
    if (bsdf->type == DRIFT_MATERIAL_MIRROR || cos_o <= 0.0f || cos_i <= 0.0f) {
        return 0.0f;
    }
    float ps = glossy_probability(bsdf);
    float pdf = (1.0f - ps) * cos_i * DRIFT_INV_PI;
    if (ps > 0.0f) {
        float n = bsdf->exponent;
        pdf += ps * (n + 1.0f) * DRIFT_INV_2PI * powf(phong_cos_alpha(bsdf, wo, wi), n);
    }
    return pdf;
}

drift_vec3 drift_bsdf_sample_glossy_lobe(const drift_bsdf *bsdf, drift_vec3 wo, drift_vec2 u)
{
    drift_frame f = drift_frame_from_normal(lobe_axis(bsdf, wo));
    float cos_a = powf(u.x, 1.0f / (bsdf->exponent + 1.0f));
    float sin_a = sqrtf(fmaxf(0.0f, 1.0f - cos_a * cos_a));
    float phi = 2.0f * DRIFT_PI * u.y;
    return drift_frame_to_world(&f, drift_vec3_make(sin_a * cosf(phi), sin_a * sinf(phi), cos_a));
}

drift_bsdf_sample drift_bsdf_sample_wi(const drift_bsdf *bsdf, drift_vec3 wo, float u_lobe,
                                       drift_vec2 u)
{
    drift_bsdf_sample s = { 0 };
    float cos_o = drift_vec3_dot(wo, bsdf->frame.z);
    if (cos_o <= 0.0f) {
        return s;
    }
    if (bsdf->type == DRIFT_MATERIAL_MIRROR) {
        s.wi = lobe_axis(bsdf, wo);
        s.weight = bsdf->specular;
        s.pdf = 1.0f;
        s.is_delta = true;
        return s;
    }
    float ps = glossy_probability(bsdf);
    if (drift_vec3_is_zero(bsdf->diffuse) && ps <= 0.0f) {
        return s;
    }
    if (u_lobe < ps) {
        s.wi = drift_bsdf_sample_glossy_lobe(bsdf, wo, u);
    } else {
        s.wi = drift_frame_to_world(&bsdf->frame, drift_sample_cosine_hemisphere(u));
    }
    float cos_i = drift_vec3_dot(s.wi, bsdf->frame.z);
    if (cos_i <= 0.0f) {
        return (drift_bsdf_sample){ 0 };
    }
    s.pdf = drift_bsdf_pdf(bsdf, wo, s.wi);
    if (!(s.pdf > 0.0f)) {
        return (drift_bsdf_sample){ 0 };
    }
    s.weight = drift_vec3_scale(drift_bsdf_eval(bsdf, wo, s.wi), cos_i / s.pdf);
    return s;
}
