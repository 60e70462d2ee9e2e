// Lambertian diffuse plus a normalized modified-Phong glossy lobe (Lafortune & Willems 1994,
// "Using the Modified Phong Reflectance Model for Physically Based Rendering"), and a perfect
// mirror; or, for materials from Blender and glTF, Burley's diffuse ("Physically-Based Shading
// at Disney", 2012, section 5.3) in place of the Lambertian one. Directions are world space;
// the lobe frame's z is the shading normal.
#include "clearcoat.h"
#include "microfacet.h"
#include "scene_internal.h"

#include <math.h>

// The Phong exponent of the lobe as wide as GGX of roughness alpha: Blinn-Phong's
// m = 2 / alpha^2 - 2 (Walter et al. 2007, eq. 33, Beckmann ~ GGX near the peak) and Phong's
// n ~ m / 4 (docs/materials.md).
static float phong_exponent_of_alpha(float alpha)
{
    float a = drift_maxf(alpha, DRIFT_GGX_MIN_ALPHA);
    return drift_clampf(0.5f / (a * a) - 0.5f, 0.5f, 1e6f);
}

void drift__ggx_phong_equivalent(const drift_material *m, drift_vec3 base, float alpha,
                                 float metallic, drift_vec3 *kd, drift_vec3 *ks, float *exponent)
{
    const drift_ggx_params *p = &m->ggx;
    float ior = p->ior > 0.0f ? p->ior : 1.5f;
    float f0 = (ior - 1.0f) / (ior + 1.0f);
    drift_vec3 tint =
        drift_vec3_is_zero(p->specular_tint) ? drift_vec3_splat(1.0f) : p->specular_tint;
    drift_vec3 f0_coat = drift_vec3_min(drift_vec3_scale(tint, f0 * f0), drift_vec3_splat(1.0f));
    drift_vec3 f0_metal = base;
    if (p->k.x > 0.0f || p->k.y > 0.0f || p->k.z > 0.0f) {
        f0_metal = drift__fresnel_conductor(1.0f, p->eta, p->k);
    }
    float w_plastic = (1.0f - metallic) * (1.0f - p->transmission);
    float w_dielectric = (1.0f - metallic) * p->transmission;
    *ks = drift_vec3_add(drift_vec3_scale(f0_metal, metallic),
                         drift_vec3_scale(f0_coat, w_plastic + w_dielectric));
    *kd = drift_vec3_scale(drift_vec3_mul(base, drift_vec3_sub(drift_vec3_splat(1.0f), f0_coat)),
                           w_plastic);
    *exponent = phong_exponent_of_alpha(alpha);
    drift__clearcoat_phong(m, kd, ks);
}

// The tangent frame's first two axes at a surface point of a mesh with uvs: the mesh's
// per-vertex tangents (the file's, or MikkTSpace-style from commit) interpolated, with
// bitangent = w cross(n, t) as Cycles and glTF do; else (no normals, no tangents) the hit
// triangle's dp/du and dp/dv (pbrt). False when the uvs are degenerate.
static bool tangent_frame(const drift_mesh *mesh, const drift_material *m,
                          const drift_surface *surface, drift_vec3 n, drift_vec3 *out_t,
                          drift_vec3 *out_b)
{
    const uint32_t *tri = mesh->indices + 3 * (size_t)surface->triangle;
    if (mesh->tangents) {
        float u = surface->barycentric.x, v = surface->barycentric.y, w0 = 1.0f - u - v;
        const float *t0 = mesh->tangents + 4 * (size_t)tri[0];
        const float *t1 = mesh->tangents + 4 * (size_t)tri[1];
        const float *t2 = mesh->tangents + 4 * (size_t)tri[2];
        drift_vec3 t =
            drift_vec3_make(w0 * t0[0] + u * t1[0] + v * t2[0], w0 * t0[1] + u * t1[1] + v * t2[1],
                            w0 * t0[2] + u * t1[2] + v * t2[2]);
        // The file's frame is about the geometric side the normals point to; a back-face hit
        // flipped n (drift_scene_surface), which mirrors cross(n, t): undo that in the sign.
        float sign = (t0[3] < 0.0f ? -1.0f : 1.0f) * (surface->front_face ? 1.0f : -1.0f);
        t = drift_vec3_fma(t, n, -drift_vec3_dot(n, t));
        float len = drift_vec3_length(t);
        if (!(len > 0.0f)) {
            return false;
        }
        *out_t = drift_vec3_scale(t, 1.0f / len);
        *out_b = drift_vec3_scale(drift_vec3_cross(n, *out_t), sign);
        return true;
    }
    bool second = m->maps[DRIFT_TEXTURE_NORMAL].uv_set == 1 && mesh->uvs1;
    const float *p = mesh->positions, *t = second ? mesh->uvs1 : mesh->uvs;
    drift_vec3 p0 = drift_vec3_make(p[3 * tri[0]], p[3 * tri[0] + 1], p[3 * tri[0] + 2]);
    drift_vec3 dp1 =
        drift_vec3_sub(drift_vec3_make(p[3 * tri[1]], p[3 * tri[1] + 1], p[3 * tri[1] + 2]), p0);
    drift_vec3 dp2 =
        drift_vec3_sub(drift_vec3_make(p[3 * tri[2]], p[3 * tri[2] + 1], p[3 * tri[2] + 2]), p0);
    float du1 = t[2 * tri[1]] - t[2 * tri[0]], dv1 = t[2 * tri[1] + 1] - t[2 * tri[0] + 1];
    float du2 = t[2 * tri[2]] - t[2 * tri[0]], dv2 = t[2 * tri[2] + 1] - t[2 * tri[0] + 1];
    float det = du1 * dv2 - dv1 * du2;
    if (!(fabsf(det) > 1e-12f)) {
        return false;
    }
    drift_vec3 dpdu = drift_vec3_scale(
        drift_vec3_sub(drift_vec3_scale(dp1, dv2), drift_vec3_scale(dp2, dv1)), 1.0f / det);
    drift_vec3 dpdv = drift_vec3_scale(
        drift_vec3_sub(drift_vec3_scale(dp2, du1), drift_vec3_scale(dp1, du2)), 1.0f / det);
    drift_vec3 tangent = drift_vec3_fma(dpdu, n, -drift_vec3_dot(n, dpdu));
    float len = drift_vec3_length(tangent);
    if (!(len > 0.0f)) {
        return false;
    }
    tangent = drift_vec3_scale(tangent, 1.0f / len);
    drift_vec3 bitangent = drift_vec3_cross(n, tangent);
    if (drift_vec3_dot(bitangent, dpdv) < 0.0f) {
        bitangent = drift_vec3_neg(bitangent);
    }
    *out_t = tangent;
    *out_b = bitangent;
    return true;
}

// The shading normal bent by a tangent-space normal map (glTF's convention: +X along the
// tangent, +Y along the bitangent, RGB = (n + 1) / 2). Unchanged where the mesh has no uvs or
// the map would turn the normal below the surface.
static drift_vec3 normal_mapped(const drift_scene *scene, const drift_material *m,
                                const drift_surface *surface)
{
    drift_vec3 n = surface->ns;
    if (surface->mesh == DRIFT_INVALID_INDEX) {
        return n;
    }
    const drift_mesh *mesh = &scene->meshes[surface->mesh];
    drift_vec3 tangent, bitangent;
    if (!mesh->uvs || !tangent_frame(mesh, m, surface, n, &tangent, &bitangent)) {
        return n;
    }
    drift_vec3 c = drift_material_texture(scene, m, DRIFT_TEXTURE_NORMAL, surface);
    float scale = m->ggx.normal_scale > 0.0f ? m->ggx.normal_scale : 1.0f;
    drift_vec3 local = drift_vec3_make((2.0f * c.x - 1.0f) * scale, (2.0f * c.y - 1.0f) * scale,
                                       drift_maxf(2.0f * c.z - 1.0f, 0.0f));
    drift_vec3 bent = drift_vec3_add(
        drift_vec3_add(drift_vec3_scale(tangent, local.x), drift_vec3_scale(bitangent, local.y)),
        drift_vec3_scale(n, local.z));
    float bent_len = drift_vec3_length(bent);
    if (!(bent_len > 0.0f)) {
        return n;
    }
    bent = drift_vec3_scale(bent, 1.0f / bent_len);
    return drift_vec3_dot(bent, surface->ng) > 0.0f ? bent : n;
}

static void make_ggx(const drift_scene *scene, const drift_material *m,
                     const drift_surface *surface, drift_bsdf *b)
{
    const drift_ggx_params *p = &m->ggx;
    float alpha = p->alpha, metallic = p->metallic;
    // Burley's roughness is the Principled BSDF's one roughness (a glTF material's
    // roughnessFactor), so the roughness texture scales it as it scales the coat's: the base
    // otherwise kept the factor's retro-reflection (issue 41: +2-23% at grazing angles).
    float burley_roughness = m->diffuse_roughness;
    if (p->metallic_roughness_texture != DRIFT_INVALID_INDEX && scene) {
        drift_vec3 t = drift_material_texture(scene, m, DRIFT_TEXTURE_METALLIC_ROUGHNESS, surface);
        float r = sqrtf(drift_maxf(alpha, 0.0f)) * t.y;
        alpha = r * r;
        metallic *= t.z;
        burley_roughness = drift_clampf(burley_roughness * t.y, 0.0f, 1.0f);
    }
    if (p->normal_texture != DRIFT_INVALID_INDEX && scene) {
        b->frame = drift_frame_from_normal(normal_mapped(scene, m, surface));
    }
    if (p->occlusion_texture != DRIFT_INVALID_INDEX && scene) {
        // glTF: 1 + strength (ao - 1), from the texture's R channel.
        float ao = drift_material_texture(scene, m, DRIFT_TEXTURE_OCCLUSION, surface).x;
        float strength = p->occlusion_strength > 0.0f ? p->occlusion_strength : 1.0f;
        b->occlusion = drift_clampf(1.0f + strength * (ao - 1.0f), 0.0f, 1.0f);
    }
    alpha = drift_clampf(alpha, 0.0f, 1.0f);
    metallic = drift_clampf(metallic, 0.0f, 1.0f);
    float transmission = drift_clampf(p->transmission, 0.0f, 1.0f);
    drift_bsdf_ggx *g = &b->ggx;
    g->base = b->diffuse;
    g->alpha = alpha;
    g->w_conductor = metallic;
    g->w_plastic = (1.0f - metallic) * (1.0f - transmission);
    g->w_dielectric = (1.0f - metallic) * transmission;
    float ior = p->ior > 0.0f ? p->ior : 1.5f;
    float f0 = (ior - 1.0f) / (ior + 1.0f);
    drift_vec3 tint =
        drift_vec3_is_zero(p->specular_tint) ? drift_vec3_splat(1.0f) : p->specular_tint;
    g->f0_coat = drift_vec3_min(drift_vec3_scale(tint, f0 * f0), drift_vec3_splat(1.0f));
    g->thin = p->thin;
    float table_alpha = drift_maxf(alpha, DRIFT_GGX_MIN_ALPHA);
    drift__ggx_alpha_slot(table_alpha, &g->alpha_row, &g->alpha_frac);
    g->e1_avg = drift__ggx_e1_avg(table_alpha);
    g->es_avg = drift__ggx_es_avg(table_alpha);
    g->burley_roughness = m->diffuse_model == DRIFT_DIFFUSE_BURLEY ? burley_roughness : -1.0f;
    g->eta_rel = p->thin || surface->front_face ? ior : 1.0f / ior;
    if (p->k.x > 0.0f || p->k.y > 0.0f || p->k.z > 0.0f) {
        g->eta = p->eta;
        g->k = p->k;
    } else if (!drift_vec3_is_zero(p->edge_tint)) {
        drift__conductor_from_tint(g->base, p->edge_tint, &g->eta, &g->k);
    } else {
        g->schlick = true;
    }
    drift__clearcoat_make(scene, m, surface, g);
    drift__ggx_phong_equivalent(m, g->base, alpha, metallic, &b->diffuse, &b->specular,
                                &b->exponent);
}

// The mesh's vertex colour at the surface's point (its barycentrics on its triangle).
static drift_vec3 vertex_color(const drift_mesh *mesh, const drift_surface *surface)
{
    const uint32_t *tri = &mesh->indices[3 * (size_t)surface->triangle];
    float u = surface->barycentric.x, v = surface->barycentric.y, w = 1.0f - u - v;
    const float *a = &mesh->colors[3 * (size_t)tri[0]], *b = &mesh->colors[3 * (size_t)tri[1]],
                *c = &mesh->colors[3 * (size_t)tri[2]];
    return drift_vec3_make(w * a[0] + u * b[0] + v * c[0], w * a[1] + u * b[1] + v * c[1],
                           w * a[2] + u * b[2] + v * c[2]);
}

drift_bsdf drift_bsdf_make(const drift_scene *scene, const drift_surface *surface)
{
    const drift_material *m = &scene->materials[surface->material];
    drift_bsdf b = { .type = m->type,
                     .diffuse = m->diffuse,
                     .specular = m->specular,
                     .exponent = m->exponent,
                     .diffuse_model = m->diffuse_model,
                     .diffuse_roughness = m->diffuse_roughness,
                     .frame = drift_frame_from_normal(surface->ns),
                     .occlusion = 1.0f };
    if (m->diffuse_texture != DRIFT_INVALID_INDEX) {
        b.diffuse = drift_vec3_mul(b.diffuse,
                                   drift_material_texture(scene, m, DRIFT_TEXTURE_BASE, surface));
    }
    const drift_mesh *mesh =
        surface->mesh < scene->mesh_count ? &scene->meshes[surface->mesh] : NULL;
    if (mesh && mesh->colors && mesh->material == surface->material &&
        surface->triangle < mesh->triangle_count) {
        b.diffuse = drift_vec3_mul(b.diffuse, vertex_color(mesh, surface));
    }
    if (m->type == DRIFT_MATERIAL_GGX) {
        make_ggx(scene, m, surface, &b);
    }
    return b;
}

bool drift_bsdf_is_delta(const drift_bsdf *bsdf)
{
    if (bsdf->type == DRIFT_MATERIAL_GGX) {
        return drift__ggx_is_delta(&bsdf->ggx);
    }
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
    return drift_maxf(0.0f, drift_vec3_dot(r, wi));
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
    if (bsdf->type == DRIFT_MATERIAL_GGX) {
        drift_vec3 f = drift__coated_eval(&bsdf->ggx, drift_frame_to_local(&bsdf->frame, wo),
                                          drift_frame_to_local(&bsdf->frame, wi), out_diffuse);
        *out_glossy = drift_vec3_sub(f, *out_diffuse);
        return;
    }
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
    if (bsdf->type == DRIFT_MATERIAL_GGX) {
        return drift__coated_pdf(&bsdf->ggx, drift_frame_to_local(&bsdf->frame, wo),
                                 drift_frame_to_local(&bsdf->frame, wi));
    }
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
    float sin_a = sqrtf(drift_maxf(0.0f, 1.0f - cos_a * cos_a));
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
    if (bsdf->type == DRIFT_MATERIAL_GGX) {
        s = drift__coated_sample(&bsdf->ggx, drift_frame_to_local(&bsdf->frame, wo), u_lobe, u);
        s.wi = drift_frame_to_world(&bsdf->frame, s.wi);
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
