// Shading shared by every pass of the hybrid frame: the unshadowed light U_l, the hard
// shadow toward a light's centre, and the radiance a secondary ray sees (what the sharp
// reflection buffer and the environment map store). It calls the same BSDF and light code
// as the reference path tracer, so a technique's error is its own.
#include "core/vectorise.h"
#include "raster/raster.h"

#include <math.h>

// f * L * cos / pdf of one light sample, without visibility (the pt's NEE, minus the ray);
// with glossy_only, f is the glossy lobe alone.
static drift_vec3 light_sample_contribution(const drift_surface *surface, const drift_bsdf *bsdf,
                                            drift_vec3 wo, const drift_light_sample *ls,
                                            bool glossy_only)
{
    if (!(ls->pdf > 0.0f) || drift_vec3_is_zero(ls->radiance)) {
        return drift_vec3_splat(0.0f);
    }
    drift_vec3 diffuse, glossy;
    drift_bsdf_eval_lobes(bsdf, wo, ls->wi, &diffuse, &glossy);
    drift_vec3 f = glossy_only ? glossy : drift_vec3_add(diffuse, glossy);
    float cos_i = fabsf(drift_vec3_dot(ls->wi, surface->ns));
    return drift_vec3_scale(drift_vec3_mul(f, ls->radiance), cos_i / ls->pdf);
}

// --- POLYGON LIGHTS IN CLOSED FORM ---

// Meshes with more triangles than this are sampled rather than summed triangle by triangle.
#define MAX_CLOSED_FORM_TRIANGLES 32

// Clips the convex polygon `in` to the half space above the plane through p with normal n
// (Sutherland-Hodgman); returns the vertex count of `out` (room for count + 1).
static int clip_to_hemisphere(drift_vec3 p, drift_vec3 n, const drift_vec3 *in, int count,
                              drift_vec3 *out)
{
    int m = 0;
    for (int i = 0; i < count; ++i) {
        drift_vec3 a = in[i], b = in[(i + 1) % count];
        float da = drift_vec3_dot(drift_vec3_sub(a, p), n);
        float db = drift_vec3_dot(drift_vec3_sub(b, p), n);
        if (da >= 0.0f) {
            out[m++] = a;
        }
        if ((da >= 0.0f) != (db >= 0.0f)) {
            out[m++] = drift_vec3_add(a, drift_vec3_scale(drift_vec3_sub(b, a), da / (da - db)));
        }
    }
    return m;
}

// acos to ~2 ulp, inline (Cephes' acosf: asin's minimax polynomial on [0, 1/2], the half-angle
// identity above it): the libm call cannot overlap a polygon's edges, and was ~5% of a frame.
// Both branches are computed and one selected, so that the polygon rows' loop vectorises.
static inline DRIFT_ALWAYS_INLINE float acos_inline(float x)
{
    float a = fabsf(x);
    bool half = a > 0.5f;
    float s = half ? sqrtf(0.5f * (1.0f - a)) : a;
    float z = s * s;
    float p = (((4.2163199048e-2f * z + 2.4181311049e-2f) * z + 4.5470025998e-2f) * z +
               7.4953002686e-2f) *
                  z +
              1.6666752422e-1f;
    float asin_s = s + s * z * p;
    float above = x > 0.0f ? 2.0f * asin_s : DRIFT_PI - 2.0f * asin_s;
    float below = 0.5f * DRIFT_PI - (x > 0.0f ? asin_s : -asin_s);
    return half ? above : below;
}

// Irradiance at p (normal n) from a polygon of unit radiance: Lambert's formula,
// E = 1/2 sum_i theta_i (n . gamma_i) over the edges (Arvo 1994), after clipping the polygon
// to the hemisphere above p.
static float polygon_irradiance(drift_vec3 p, drift_vec3 n, const drift_vec3 *polygon, int count)
{
    drift_vec3 clipped[8];
    int m = clip_to_hemisphere(p, n, polygon, count, clipped);
    if (m < 3) {
        return 0.0f;
    }
    drift_vec3 dirs[8];
    for (int i = 0; i < m; ++i) {
        dirs[i] = drift_vec3_normalize(drift_vec3_sub(clipped[i], p));
    }
    float sum = 0.0f;
    for (int i = 0; i < m; ++i) {
        drift_vec3 a = dirs[i], b = dirs[(i + 1) % m];
        drift_vec3 c = drift_vec3_cross(a, b);
        float length = drift_vec3_length(c);
        if (length > 1e-12f) {
            float theta = acos_inline(drift_clampf(drift_vec3_dot(a, b), -1.0f, 1.0f));
            sum += theta * drift_vec3_dot(c, n) / length;
        }
    }
    return 0.5f * fabsf(sum);
}

// The corners of a quad or triangle light, and its emitting normal.
static int light_polygon(const drift_scene *scene, const drift_light *l, drift_vec3 *out,
                         drift_vec3 *out_normal)
{
    if (l->type == DRIFT_LIGHT_QUAD) {
        out[0] = l->position;
        out[1] = drift_vec3_add(l->position, l->edge_u);
        out[2] = drift_vec3_add(out[1], l->edge_v);
        out[3] = drift_vec3_add(l->position, l->edge_v);
        *out_normal = drift_vec3_cross(l->edge_u, l->edge_v);
        return 4;
    }
    drift_light_triangle_vertices(scene, l, &out[0], &out[1], &out[2]);
    *out_normal = drift_vec3_cross(drift_vec3_sub(out[1], out[0]), drift_vec3_sub(out[2], out[0]));
    return 3;
}

// --- SPHERE LIGHTS IN CLOSED FORM ---

// Irradiance at p (normal n) from a sphere of unit radiance: pi sin^2(sigma) cos(theta) while
// the sphere stands wholly above p's horizon (sigma its angular radius, theta the angle to its
// centre), else the exact integral over the part of its cap above the horizon (Snyder 1996,
// as restated by Lagarde and de Rousiers 2014, "Moving Frostbite to PBR", sec. 4.7.2). Inside
// the sphere every direction above the horizon sees it: pi.
static float sphere_irradiance(drift_vec3 p, drift_vec3 n, drift_vec3 centre, float radius)
{
    drift_vec3 to_centre = drift_vec3_sub(centre, p);
    float d2 = drift_vec3_dot(to_centre, to_centre);
    if (!(d2 > radius * radius)) {
        return DRIFT_PI;
    }
    float sin2 = radius * radius / d2;
    float cos_t = drift_clampf(drift_vec3_dot(n, to_centre) / sqrtf(d2), -1.0f, 1.0f);
    if (cos_t * cos_t > sin2) {
        return cos_t > 0.0f ? DRIFT_PI * sin2 * cos_t : 0.0f;
    }
    float sin_t = sqrtf(fmaxf(1.0f - cos_t * cos_t, 0.0f)); // > 0: cos_t^2 <= sin2 < 1
    float x = sqrtf(1.0f / sin2 - 1.0f);
    float y = drift_clampf(-x * cos_t / sin_t, -1.0f, 1.0f);
    float s = sin_t * sqrtf(fmaxf(1.0f - y * y, 0.0f));
    return fmaxf((cos_t * acos_inline(y) - x * s) * sin2 + atanf(s / x), 0.0f);
}

static bool has_closed_form(const drift_raster_light *light)
{
    return light->type == DRIFT_LIGHT_QUAD || light->type == DRIFT_LIGHT_SPHERE ||
           (light->type == DRIFT_LIGHT_TRIANGLE &&
            (light->light_count <= MAX_CLOSED_FORM_TRIANGLES || light->sphere_radius > 0.0f));
}

// The diffuse albedo the closed forms multiply the irradiance by (f_diffuse = albedo / pi):
// kd for Lambert; for Burley's diffuse and GGX's plastic base, pi times the BSDF's own diffuse
// lobe toward the light's centre (the normal when the centre is below the horizon). Both vary
// slowly with wi: exact for a small light, the lobe at the centre for a large one.
static drift_vec3 diffuse_albedo_toward(const drift_bsdf *bsdf, const drift_surface *surface,
                                        drift_vec3 wo, drift_vec3 centre)
{
    if (bsdf->type == DRIFT_MATERIAL_DEFAULT && bsdf->diffuse_model == DRIFT_DIFFUSE_LAMBERT) {
        return bsdf->diffuse;
    }
    drift_vec3 n = bsdf->frame.z;
    drift_vec3 wi = drift_vec3_sub(centre, surface->position);
    float len = drift_vec3_length(wi);
    wi = len > 0.0f ? drift_vec3_scale(wi, 1.0f / len) : n;
    if (!(drift_vec3_dot(wi, n) > 0.05f)) {
        wi = n;
    }
    drift_vec3 diffuse, glossy;
    drift_bsdf_eval_lobes(bsdf, wo, wi, &diffuse, &glossy);
    return drift_vec3_scale(diffuse, DRIFT_PI);
}

drift_vec3 drift_raster_diffuse_albedo(const drift_bsdf *bsdf, drift_vec3 w)
{
    if (bsdf->type == DRIFT_MATERIAL_MIRROR) {
        return drift_vec3_splat(0.0f);
    }
    if (bsdf->type == DRIFT_MATERIAL_DEFAULT && bsdf->diffuse_model == DRIFT_DIFFUSE_LAMBERT) {
        return bsdf->diffuse;
    }
    float mu = drift_vec3_dot(w, bsdf->frame.z);
    if (!(mu > 0.0f)) {
        w = bsdf->frame.z;
        mu = 1.0f;
    }
    drift_bsdf b = *bsdf;
    if (b.type == DRIFT_MATERIAL_GGX) {
        const drift_bsdf_ggx *g = &bsdf->ggx;
        if (!(g->w_plastic > 0.0f) || g->skip_diffuse) {
            return drift_vec3_splat(0.0f);
        }
        // A layered clear coat leaves the diffuse base's albedo toward w exactly 1 - c Ec(mu)
        // of the uncoated one (src/scene/clearcoat.c).
        float coat =
            g->clearcoat_principled ? 1.0f : 1.0f - drift_bsdf_clearcoat_albedo(bsdf, mu, NULL);
        b.ggx.clearcoat = 0.0f;
        drift_vec3 base = drift_vec3_scale(g->base, g->w_plastic * coat);
        if (g->burley_roughness < 0.0f) {
            // The layered base reflects base (1 - Ec(mu)) exactly (its normalisation by
            // 1 - Ec_avg makes the cosine-weighted integral over wi of 1 - Ec(mu_i) one).
            b.ggx.w_conductor = 0.0f;
            b.ggx.w_dielectric = 0.0f;
            b.ggx.w_plastic = 1.0f;
            drift_vec3 ec, unused;
            drift_bsdf_ggx_reflection_albedo(&b, mu, &ec, &unused);
            return drift_vec3_mul(base, drift_vec3_sub(drift_vec3_splat(1.0f), ec));
        }
        // Principled's Burley base: the same lobe as a Burley material's.
        b.type = DRIFT_MATERIAL_DEFAULT;
        b.diffuse = base;
        b.specular = drift_vec3_splat(0.0f);
        b.diffuse_model = DRIFT_DIFFUSE_BURLEY;
        b.diffuse_roughness = g->burley_roughness;
    }
    // Burley: int f_diffuse(w, wi) cos dwi = E[pi f_diffuse] over cosine-distributed wi (16
    // points: 8 were 2% low at normal incidence).
    drift_vec3 sum = drift_vec3_splat(0.0f);
    const uint32_t n = 16;
    for (uint32_t k = 0; k < n; ++k) {
        // (y shifted half a stratum: y = 0 is the disc's rim, a grazing direction of f = 0)
        drift_vec3 local = drift_sample_cosine_hemisphere(
            drift_hammersley_shifted(k, n, drift_vec2_make(0.0f, 0.5f / (float)n)));
        drift_vec3 diffuse, glossy;
        drift_bsdf_eval_lobes(&b, w, drift_frame_to_world(&b.frame, local), &diffuse, &glossy);
        sum = drift_vec3_add(sum, diffuse);
    }
    return drift_vec3_scale(sum, DRIFT_PI / (float)n);
}

// The diffuse lobe's share of U_l in closed form: kd / pi * sum over polygons (or the sphere)
// of L_e * E. Each polygon emits from its front face only.
static drift_vec3 polygon_diffuse(const drift_scene *scene, const drift_raster_light *light,
                                  const drift_surface *surface, const drift_bsdf *bsdf,
                                  drift_vec3 wo)
{
    drift_vec3 n = bsdf->frame.z;
    drift_vec3 sum = drift_vec3_splat(0.0f);
    if (drift_vec3_dot(wo, n) <= 0.0f) {
        return sum; // the diffuse lobe is zero for a viewer below the shading normal
    }
    if (light->sphere_radius > 0.0f) {
        float e = sphere_irradiance(surface->position, n, light->centre, light->sphere_radius);
        drift_vec3 colour = scene->lights[light->first_light].color;
        drift_vec3 kd = diffuse_albedo_toward(bsdf, surface, wo, light->centre);
        return drift_vec3_scale(drift_vec3_mul(colour, kd), e * DRIFT_INV_PI);
    }
    for (uint32_t i = 0; i < light->light_count; ++i) {
        const drift_light *l = &scene->lights[light->first_light + i];
        if (l->type == DRIFT_LIGHT_SPHERE) {
            sum = drift_vec3_fma(sum, l->color,
                                 sphere_irradiance(surface->position, n, l->position, l->radius));
            continue;
        }
        drift_vec3 polygon[4], normal;
        int count = light_polygon(scene, l, polygon, &normal);
        float side = drift_vec3_dot(drift_vec3_sub(surface->position, polygon[0]), normal);
        if (!(side > 0.0f || (l->two_sided && side < 0.0f))) {
            continue; // behind the emitting side (or in its plane)
        }
        float e = polygon_irradiance(surface->position, n, polygon, count);
        sum = drift_vec3_fma(sum, l->color, e);
    }
    drift_vec3 kd = diffuse_albedo_toward(bsdf, surface, wo, light->centre);
    return drift_vec3_scale(drift_vec3_mul(sum, kd), DRIFT_INV_PI);
}

// --- POLYGON LIGHTS IN CLOSED FORM, A ROW AT A TIME ---
//
// Lambert's formula is the unshadowed pass's hot loop (27% of the Cornell box's frame, its
// acos and square roots scalar per pixel and edge). Here it runs for many receivers and one
// polygon at once, branch-free over structure-of-arrays receivers so that it vectorises
// (docs/decisions/0028): the same operations in the same order as polygon_irradiance, so the
// same values. A receiver whose horizon the polygon straddles needs the clip, and takes the
// scalar polygon_irradiance afterwards.

// E of a unit-radiance polygon of M corners (v, its emitting normal en) at receivers i: e[i],
// 0 behind its emitting side (unless two_sided: both sides emit) or below the horizon;
// straddles[i] = 1 where the horizon cuts it (e[i] is then to be computed with the clip).
static inline DRIFT_ALWAYS_INLINE void
polygon_irradiance_rows(const float (*v)[3], const int m, drift_vec3 en, bool two_sided,
                        int32_t count, const float *restrict px, const float *restrict py,
                        const float *restrict pz, const float *restrict nx,
                        const float *restrict ny, const float *restrict nz, float *restrict e,
                        int32_t *restrict straddles)
{
    DRIFT_IVDEP
    for (int32_t i = 0; i < count; ++i) {
        float dx[4], dy[4], dz[4];
        bool above = true, below = true;
        for (int k = 0; k < m; ++k) {
            float ax = v[k][0] - px[i], ay = v[k][1] - py[i], az = v[k][2] - pz[i];
            float da = ax * nx[i] + ay * ny[i] + az * nz[i];
            above = above & (da >= 0.0f);
            below = below & !(da >= 0.0f);
            float len = sqrtf(ax * ax + ay * ay + az * az);
            float inv = len > 0.0f ? 1.0f / len : 1.0f;
            dx[k] = ax * inv, dy[k] = ay * inv, dz[k] = az * inv;
        }
        float sum = 0.0f;
        for (int k = 0; k < m; ++k) {
            int k1 = k + 1 < m ? k + 1 : 0;
            float cx = dy[k] * dz[k1] - dz[k] * dy[k1];
            float cy = dz[k] * dx[k1] - dx[k] * dz[k1];
            float cz = dx[k] * dy[k1] - dy[k] * dx[k1];
            float length = sqrtf(cx * cx + cy * cy + cz * cz);
            float cosab = dx[k] * dx[k1] + dy[k] * dy[k1] + dz[k] * dz[k1];
            cosab = cosab < -1.0f ? -1.0f : (cosab > 1.0f ? 1.0f : cosab);
            float t = acos_inline(cosab) * (cx * nx[i] + cy * ny[i] + cz * nz[i]) / length;
            sum += length > 1e-12f ? t : 0.0f;
        }
        float side = (px[i] - v[0][0]) * en.x + (py[i] - v[0][1]) * en.y + (pz[i] - v[0][2]) * en.z;
        bool lit = (side > 0.0f) | (two_sided & (side < 0.0f));
        e[i] = (lit & above) ? 0.5f * fabsf(sum) : 0.0f;
        straddles[i] = lit & !above & !below;
    }
}

DRIFT_AVX2_CLONES static void triangle_rows(const float (*v)[3], drift_vec3 en, bool two_sided,
                                            int32_t count, const float *px, const float *py,
                                            const float *pz, const float *nx, const float *ny,
                                            const float *nz, float *e, int32_t *straddles)
{
    polygon_irradiance_rows(v, 3, en, two_sided, count, px, py, pz, nx, ny, nz, e, straddles);
}

DRIFT_AVX2_CLONES static void quad_rows(const float (*v)[3], drift_vec3 en, bool two_sided,
                                        int32_t count, const float *px, const float *py,
                                        const float *pz, const float *nx, const float *ny,
                                        const float *nz, float *e, int32_t *straddles)
{
    polygon_irradiance_rows(v, 4, en, two_sided, count, px, py, pz, nx, ny, nz, e, straddles);
}

bool drift_raster_has_polygon_rows(const drift_raster_light *light)
{
    return has_closed_form(light) && light->sphere_radius == 0.0f &&
           (light->type == DRIFT_LIGHT_QUAD || light->type == DRIFT_LIGHT_TRIANGLE);
}

void drift_raster_polygon_rows(const drift_scene *scene, const drift_raster_light *light,
                               const drift_raster_receivers *rs, float *er, float *eg, float *eb)
{
    float e[DRIFT_RASTER_ROW_MAX];
    int32_t straddles[DRIFT_RASTER_ROW_MAX];
    int32_t count = rs->count < DRIFT_RASTER_ROW_MAX ? rs->count : DRIFT_RASTER_ROW_MAX;
    for (int32_t i = 0; i < count; ++i) {
        er[i] = eg[i] = eb[i] = 0.0f;
    }
    for (uint32_t j = 0; j < light->light_count; ++j) {
        const drift_light *l = &scene->lights[light->first_light + j];
        drift_vec3 polygon[4], normal;
        int m = light_polygon(scene, l, polygon, &normal);
        float v[4][3];
        for (int k = 0; k < m; ++k) {
            v[k][0] = polygon[k].x, v[k][1] = polygon[k].y, v[k][2] = polygon[k].z;
        }
        (m == 4 ? quad_rows : triangle_rows)((const float(*)[3])v, normal, l->two_sided, count,
                                             rs->px, rs->py, rs->pz, rs->nx, rs->ny, rs->nz, e,
                                             straddles);
        for (int32_t i = 0; i < count; ++i) {
            if (straddles[i]) {
                e[i] = polygon_irradiance(drift_vec3_make(rs->px[i], rs->py[i], rs->pz[i]),
                                          drift_vec3_make(rs->nx[i], rs->ny[i], rs->nz[i]), polygon,
                                          m);
            }
            er[i] += l->color.x * e[i];
            eg[i] += l->color.y * e[i];
            eb[i] += l->color.z * e[i];
        }
    }
}

// --- GLOSSY LOBES: LIGHT AND BSDF SAMPLES BY MULTIPLE IMPORTANCE ---

// Whether U's glossy lobe takes BSDF-sampled directions besides its light samples: a glossy
// lobe narrower than twice the light's angular radius seen from the surface (the lobe's 90%
// cone, drift_ggx_theta_90; Phong's by its exponent), and a light whose shapes
// drift_raster_light_hit can meet. A wider lobe is served by light samples alone (the GGX
// scene's rough floor under its panel: the BSDF samples' cost saved there), and either
// estimator is unbiased, so the choice moves noise, not the mean.
static bool glossy_mis_applies(const drift_raster_light *light, const drift_surface *surface,
                               const drift_bsdf *bsdf)
{
    if (drift_vec3_is_zero(bsdf->specular) || !drift_light_is_area(light->type) ||
        light->light_count > DRIFT_RASTER_HIT_TRIANGLES) {
        return false;
    }
    float lobe;
    if (bsdf->type == DRIFT_MATERIAL_GGX) {
        float alpha = bsdf->ggx.alpha;
        if (bsdf->ggx.clearcoat > 0.0f) {
            alpha = fminf(alpha, bsdf->ggx.clearcoat_alpha);
        }
        lobe = drift_ggx_theta_90(alpha);
    } else {
        lobe = acosf(powf(0.1f, 1.0f / (fmaxf(bsdf->exponent, 0.0f) + 1.0f)));
    }
    float d = drift_vec3_length(drift_vec3_sub(light->centre, surface->position));
    float sigma = d > light->radius ? asinf(light->radius / d) : 0.5f * DRIFT_PI;
    return lobe < 2.0f * sigma;
}

// The sum over n BSDF-sampled directions (a shifted Hammersley set, the lobe picked by a
// stratified number) of f L cos / p_bsdf times the power heuristic's weight against the light
// samples, where the direction meets the light (its own shapes only: visibility is S_l's).
// With glossy_only (the diffuse lobe in closed form) f is the glossy lobe alone; p_bsdf is the
// whole BSDF's pdf either way, as the estimator's is.
static drift_vec3 bsdf_sampled(const drift_scene *scene, const drift_raster_light *light,
                               const drift_surface *surface, const drift_bsdf *bsdf, drift_vec3 wo,
                               uint32_t n, bool glossy_only, drift_sampler *sampler)
{
    drift_vec3 sum = drift_vec3_splat(0.0f);
    drift_vec2 shift = drift_sampler_next2(sampler);
    float lobe_shift = drift_sampler_next1(sampler);
    for (uint32_t k = 0; k < n; ++k) {
        float u_lobe = ((float)k + lobe_shift) / (float)n;
        drift_bsdf_sample bs = drift_bsdf_sample_wi(bsdf, wo, fminf(u_lobe, 1.0f - 1e-6f),
                                                    drift_hammersley_shifted(k, n, shift));
        drift_vec3 le;
        float light_pdf;
        if (!(bs.pdf > 0.0f) || bs.is_delta ||
            !drift_raster_light_hit(scene, light, surface->position, bs.wi, &le, &light_pdf)) {
            continue;
        }
        drift_vec3 diffuse, glossy;
        drift_bsdf_eval_lobes(bsdf, wo, bs.wi, &diffuse, &glossy);
        drift_vec3 f = glossy_only ? glossy : drift_vec3_add(diffuse, glossy);
        float cos_i = fabsf(drift_vec3_dot(bs.wi, surface->ns));
        float w = drift_power_heuristic(bs.pdf, light_pdf);
        sum = drift_vec3_add(sum, drift_vec3_scale(drift_vec3_mul(f, le), cos_i * w / bs.pdf));
    }
    return sum;
}

static drift_vec3 unshadowed(const drift_scene *scene, const drift_raster_light *light,
                             const drift_surface *surface, const drift_bsdf *bsdf, drift_vec3 wo,
                             uint32_t sample_count, drift_sampler *sampler,
                             const drift_vec3 *polygon_irradiance_given)
{
    drift_vec3 sum = drift_vec3_splat(0.0f);
    if (drift_bsdf_is_delta(bsdf)) {
        return sum;
    }
    if (!drift_light_is_area(light->type)) {
        drift_light_sample ls = drift_raster_light_sample(scene, light, surface->position, 0.0f,
                                                          drift_vec2_make(0.5f, 0.5f));
        return light_sample_contribution(surface, bsdf, wo, &ls, false);
    }
    // Polygons and spheres: the diffuse lobe in closed form (no noise), samples for the glossy
    // lobe only.
    bool closed_form = has_closed_form(light);
    if (closed_form && polygon_irradiance_given) {
        if (drift_vec3_dot(wo, bsdf->frame.z) > 0.0f) {
            drift_vec3 kd = diffuse_albedo_toward(bsdf, surface, wo, light->centre);
            sum = drift_vec3_scale(drift_vec3_mul(*polygon_irradiance_given, kd), DRIFT_INV_PI);
        }
        if (drift_vec3_is_zero(bsdf->specular)) {
            return sum;
        }
    } else if (closed_form) {
        sum = polygon_diffuse(scene, light, surface, bsdf, wo);
        if (drift_vec3_is_zero(bsdf->specular)) {
            return sum;
        }
    }
    drift_vec3 sampled = drift_vec3_splat(0.0f);
    uint32_t n = sample_count > 0 ? sample_count : 1;
    drift_vec2 shift = drift_sampler_next2(sampler);
    float pick_shift = drift_sampler_next1(sampler);
    // With a glossy lobe, as many BSDF-sampled directions again, each weighed against the light
    // samples by the power heuristic (as the path tracer): a near-mirror lobe's highlight of an
    // area light is a small solid angle that light samples almost never find.
    bool mis = glossy_mis_applies(light, surface, bsdf);
    for (uint32_t k = 0; k < n; ++k) {
        drift_vec2 u = drift_hammersley_shifted(k, n, shift);
        // Golden-ratio sequence for the triangle pick of mesh lights.
        float pick = (float)k * 0.618034f + pick_shift;
        drift_light_sample ls =
            drift_raster_light_sample(scene, light, surface->position, pick - floorf(pick), u);
        drift_vec3 c = light_sample_contribution(surface, bsdf, wo, &ls, closed_form);
        if (mis && !drift_vec3_is_zero(c)) {
            c = drift_vec3_scale(c, drift_power_heuristic(ls.pdf, drift_bsdf_pdf(bsdf, wo, ls.wi)));
        }
        sampled = drift_vec3_add(sampled, c);
    }
    if (mis) {
        sampled = drift_vec3_add(
            sampled, bsdf_sampled(scene, light, surface, bsdf, wo, n, closed_form, sampler));
    }
    return drift_vec3_fma(sum, sampled, 1.0f / (float)n);
}

drift_vec3 drift_raster_unshadowed(const drift_scene *scene, const drift_raster_light *light,
                                   const drift_surface *surface, const drift_bsdf *bsdf,
                                   drift_vec3 wo, uint32_t sample_count, drift_sampler *sampler)
{
    return unshadowed(scene, light, surface, bsdf, wo, sample_count, sampler, NULL);
}

drift_vec3 drift_raster_unshadowed_given(const drift_scene *scene, const drift_raster_light *light,
                                         const drift_surface *surface, const drift_bsdf *bsdf,
                                         drift_vec3 wo, uint32_t sample_count,
                                         drift_sampler *sampler, drift_vec3 polygon_irradiance)
{
    return unshadowed(scene, light, surface, bsdf, wo, sample_count, sampler, &polygon_irradiance);
}

drift_vec3 drift_raster_environment_direct(const drift_scene *scene, const drift_accel *accel,
                                           const drift_surface *surface, const drift_bsdf *bsdf,
                                           drift_vec3 wo, uint32_t sample_count,
                                           drift_sampler *sampler, uint64_t *rays)
{
    if (!drift_scene_has_environment(scene) || drift_bsdf_is_delta(bsdf)) {
        return drift_vec3_splat(0.0f);
    }
    uint32_t n = sample_count > 0 ? sample_count : 1;
    return drift_raster_environment_direct_subset(scene, accel, surface, bsdf, wo, n, 0, 1,
                                                  drift_sampler_next2(sampler), rays);
}

drift_vec3 drift_raster_environment_direct_subset(const drift_scene *scene,
                                                  const drift_accel *accel,
                                                  const drift_surface *surface,
                                                  const drift_bsdf *bsdf, drift_vec3 wo,
                                                  uint32_t set_size, uint32_t first,
                                                  uint32_t stride, drift_vec2 shift, uint64_t *rays)
{
    drift_vec3 sum = drift_vec3_splat(0.0f);
    if (!drift_scene_has_environment(scene) || drift_bsdf_is_delta(bsdf) || stride == 0) {
        return sum;
    }
    uint32_t n = set_size, taken = 0;
    // A constant sky: directions by the cosine around the shading normal, the diffuse lobe's
    // own weight (f cos / pdf = kd), instead of the uniform sphere, half of which lies below the
    // horizon and whose survivors weigh 4 kd cos.
    bool cosine = drift_environment_is_constant(scene);
    drift_frame frame = cosine ? drift_frame_from_normal(surface->ns) : (drift_frame){ 0 };
    for (uint32_t k = first; k < n; k += stride) {
        ++taken;
        drift_vec2 u = drift_hammersley_shifted(k, n, shift);
        drift_light_sample ls;
        if (cosine) {
            drift_vec3 local = drift_sample_cosine_hemisphere(u);
            ls = (drift_light_sample){ .wi = drift_frame_to_world(&frame, local),
                                       .pdf = local.z * DRIFT_INV_PI,
                                       .distance = INFINITY };
            ls.radiance = drift_environment_eval(scene, ls.wi);
        } else {
            ls = drift_environment_sample(scene, u);
        }
        drift_vec3 c = light_sample_contribution(surface, bsdf, wo, &ls, false);
        if (drift_vec3_is_zero(c)) {
            continue;
        }
        drift_ray shadow = { .origin = drift_offset_origin(surface->position, surface->ng, ls.wi),
                             .dir = ls.wi,
                             .tmin = 0.0f,
                             .tmax = INFINITY };
        ++*rays;
        if (!drift_accel_occluded(accel, &shadow)) {
            sum = drift_vec3_add(sum, c);
        }
    }
    return taken ? drift_vec3_scale(sum, 1.0f / (float)taken) : sum;
}

drift_ray drift_raster_hard_shadow_ray(const drift_raster_light *light,
                                       const drift_surface *surface, float *out_light_distance)
{
    drift_vec3 dir;
    float distance;
    if (light->type == DRIFT_LIGHT_DIRECTIONAL) {
        dir = drift_vec3_neg(light->direction);
        distance = INFINITY;
    } else {
        drift_vec3 d = drift_vec3_sub(light->centre, surface->position);
        distance = drift_vec3_length(d);
        dir = distance > 0.0f ? drift_vec3_scale(d, 1.0f / distance) : surface->ns;
    }
    *out_light_distance = distance;
    return (drift_ray){ .origin = drift_offset_origin(surface->position, surface->ng, dir),
                        .dir = dir,
                        .tmin = 0.0f,
                        .tmax = isfinite(distance) ? distance * (1.0f - 1e-4f) : INFINITY };
}

bool drift_raster_hard_shadow_visible(const drift_raster_light *light, const drift_hit *hit,
                                      float *out_occluder_distance)
{
    // Closest hit rather than any hit: the buffer needs the occluder's distance, and a ray
    // toward the centre of a sphere light meets the light's own surface, which is no occluder.
    bool missed = hit->mesh == DRIFT_INVALID_INDEX && hit->light == DRIFT_INVALID_INDEX;
    if (missed || drift_raster_light_owns(light, hit->light)) {
        *out_occluder_distance = INFINITY;
        return true;
    }
    *out_occluder_distance = hit->t;
    return false;
}

bool drift_raster_hard_shadow(const drift_accel *accel, const drift_raster_light *light,
                              const drift_surface *surface, float *out_occluder_distance,
                              float *out_light_distance)
{
    drift_ray ray = drift_raster_hard_shadow_ray(light, surface, out_light_distance);
    drift_hit hit = { .mesh = DRIFT_INVALID_INDEX, .light = DRIFT_INVALID_INDEX };
    drift_accel_intersect(accel, &ray, &hit); // a miss leaves `hit` as it was: missed
    return drift_raster_hard_shadow_visible(light, &hit, out_occluder_distance);
}

// Direct light at a secondary hit from every light, each with its hard shadow.
drift_vec3 drift_raster_direct_hard(const drift_raster_shading *shading,
                                    const drift_surface *surface, const drift_bsdf *bsdf,
                                    drift_vec3 wo, drift_sampler *sampler, uint64_t *rays)
{
    drift_vec3 sum = drift_vec3_splat(0.0f);
    for (uint32_t l = 0; l < shading->light_count; ++l) {
        const drift_raster_light *light = &shading->lights[l];
        drift_vec3 u = drift_raster_unshadowed(shading->scene, light, surface, bsdf, wo,
                                               shading->light_samples, sampler);
        if (drift_vec3_is_zero(u)) {
            continue;
        }
        float occluder, distance;
        ++*rays;
        if (drift_raster_hard_shadow(shading->accel, light, surface, &occluder, &distance)) {
            sum = drift_vec3_add(sum, u);
        }
    }
    drift_vec3 env = drift_raster_environment_direct(shading->scene, shading->accel, surface, bsdf,
                                                     wo, shading->light_samples, sampler, rays);
    return drift_vec3_add(sum, env);
}

drift_raster_radiance drift_raster_trace_radiance(const drift_raster_shading *shading,
                                                  drift_ray ray, uint32_t skip_mesh,
                                                  drift_sampler *sampler, uint64_t *rays,
                                                  float *out_distance)
{
    drift_surface surface;
    return drift_raster_trace_radiance_surface(shading, ray, skip_mesh, sampler, rays, out_distance,
                                               &surface);
}

drift_raster_radiance drift_raster_trace_radiance_surface(const drift_raster_shading *shading,
                                                          drift_ray ray, uint32_t skip_mesh,
                                                          drift_sampler *sampler, uint64_t *rays,
                                                          float *out_distance,
                                                          drift_surface *out_surface)
{
    const drift_scene *scene = shading->scene;
    drift_raster_radiance out = { drift_vec3_splat(0.0f), drift_vec3_splat(0.0f) };
    *out_distance = INFINITY;
    out_surface->material = DRIFT_INVALID_INDEX;
    drift_hit hit;
    // Pass through the skipped mesh (a probe inside its own object); a few layers at most.
    for (int layer = 0;; ++layer) {
        ++*rays;
        if (!drift_accel_intersect(shading->accel, &ray, &hit)) {
            if (drift_scene_has_environment(scene)) {
                out.emitted = drift_environment_eval(scene, ray.dir);
            }
            return out;
        }
        if (hit.mesh != skip_mesh || skip_mesh == DRIFT_INVALID_INDEX || layer == 8) {
            break;
        }
        ray.tmin = hit.t * (1.0f + 1e-5f) + 1e-6f;
    }
    *out_distance = hit.t;
    *out_surface = drift_scene_surface(scene, &ray, &hit);
    out.emitted = out_surface->emission;
    if (out_surface->material == DRIFT_INVALID_INDEX) {
        return out;
    }
    drift_bsdf bsdf = drift_bsdf_make(scene, out_surface);
    out.reflected = drift_raster_direct_hard(shading, out_surface, &bsdf, drift_vec3_neg(ray.dir),
                                             sampler, rays);
    return out;
}

// GGX at normal incidence (n = v): tan^2 theta_h of a D-sampled half vector is
// alpha^2 u / (1 - u), so 90% of the half vectors lie within tan theta_h = 3 alpha, and the
// reflected direction (theta = 2 theta_h) within 2 atan(3 alpha) (docs/isg.md derives it).
float drift_ggx_theta_90(float alpha)
{
    return fminf(2.0f * atanf(3.0f * fmaxf(alpha, 1e-3f)), 0.5f * DRIFT_PI);
}

float drift_gloss_blinn_exponent(const drift_bsdf *bsdf)
{
    if (bsdf->type == DRIFT_MATERIAL_MIRROR) {
        return INFINITY;
    }
    if (bsdf->type != DRIFT_MATERIAL_GGX) {
        return 4.0f * bsdf->exponent;
    }
    // Blinn-Phong's D ~ cos^m theta_h holds 1 - cos^(m+2) theta_h of its half vectors within
    // theta_h: 90% within the GGX cone tan theta_h = 3 alpha when cos^(m+2) = 0.1 there.
    float a = fmaxf(bsdf->ggx.alpha, 1e-3f);
    return fmaxf(2.0f * logf(10.0f) / log1pf(9.0f * a * a) - 2.0f, 0.0f);
}

float drift_gloss_theta_max(const drift_material *material)
{
    if (material->type == DRIFT_MATERIAL_MIRROR) {
        return 0.0f;
    }
    if (material->type == DRIFT_MATERIAL_GGX) {
        return drift_ggx_theta_90(material->ggx.alpha);
    }
    if (drift_vec3_is_zero(material->specular) || !(material->exponent > 0.0f)) {
        return 0.5f * DRIFT_PI;
    }
    // The Phong lobe's pdf is proportional to cos^n: the cone of half angle theta holds
    // 1 - cos^(n+1)(theta) of it; 90% gives cos(theta) = 0.1^(1/(n+1)).
    return acosf(powf(0.1f, 1.0f / (material->exponent + 1.0f)));
}

// Directional albedo of the specular lobe toward wo: ks for a mirror; for GGX its reflection
// lobes' albedo (drift_bsdf_ggx_reflection_albedo); for the normalized Phong lobe around the
// mirror direction r, integral of f cos = ks (n+2)/(n+1) cos(theta_r)
// when the lobe is narrow (clamped to ks).
drift_vec3 drift_raster_reflection_weight(const drift_bsdf *bsdf, drift_vec3 wo)
{
    if (bsdf->type == DRIFT_MATERIAL_MIRROR) {
        return bsdf->specular;
    }
    float cos_o = fmaxf(0.0f, drift_vec3_dot(wo, bsdf->frame.z));
    if (bsdf->type == DRIFT_MATERIAL_GGX) { // the GGX reflection lobes' albedo (the DFG term)
        drift_vec3 single, multiple;
        drift_bsdf_ggx_reflection_albedo(bsdf, cos_o, &single, &multiple);
        float coat = drift_bsdf_clearcoat_albedo(bsdf, cos_o, NULL); // 0 without a coat
        return drift_vec3_add(drift_vec3_add(single, multiple), drift_vec3_splat(coat));
    }
    float n = bsdf->exponent;
    return drift_vec3_scale(bsdf->specular, fminf(1.0f, (n + 2.0f) / (n + 1.0f) * cos_o));
}
