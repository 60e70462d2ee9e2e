// Light selection and sampling: a power-proportional pick over the scene's lights and the
// environment, then a point (or direction) on the picked light with its solid-angle pdf.
#include "drift/scene.h"
#include "scene_internal.h"

#include <math.h>

struct drift_light_table {
    float *cdf;           // entry_count + 1 values, cdf[0] = 0, cdf[entry_count] = 1
    uint32_t entry_count; // light_count, plus one for the environment when present
    bool has_environment;
    float environment_radius;             // radius of the scene's bounding sphere (for env power)
    drift__env_distribution *environment; // NULL for a constant environment
    // Per light, fixed after commit, so sampling does not recompute them: 1 / area (0 for
    // delta lights) and the emitting normal (unused for spheres, whose normal varies).
    float *inv_area;
    drift_vec3 *normal;
};

const drift__env_distribution *drift__light_table_environment(const drift_scene *scene)
{
    return scene->light_table ? scene->light_table->environment : NULL;
}

// --- GEOMETRY HELPERS ---

void drift_light_triangle_vertices(const drift_scene *scene, const drift_light *l, drift_vec3 *a,
                                   drift_vec3 *b, drift_vec3 *c)
{
    const drift_mesh *mesh = &scene->meshes[l->mesh];
    const uint32_t *tri = mesh->indices + 3 * (size_t)l->triangle;
    const float *p = mesh->positions;
    *a = drift_vec3_make(p[3 * tri[0]], p[3 * tri[0] + 1], p[3 * tri[0] + 2]);
    *b = drift_vec3_make(p[3 * tri[1]], p[3 * tri[1] + 1], p[3 * tri[1] + 2]);
    *c = drift_vec3_make(p[3 * tri[2]], p[3 * tri[2] + 1], p[3 * tri[2] + 2]);
}

// Area of the light's emitting surface (0 for delta lights).
static float light_area(const drift_scene *scene, const drift_light *l)
{
    switch (l->type) {
    case DRIFT_LIGHT_QUAD:
        return drift_vec3_length(drift_vec3_cross(l->edge_u, l->edge_v));
    case DRIFT_LIGHT_DISK:
        return DRIFT_PI * l->radius * l->radius;
    case DRIFT_LIGHT_SPHERE:
        return 4.0f * DRIFT_PI * l->radius * l->radius;
    case DRIFT_LIGHT_TRIANGLE: {
        drift_vec3 a, b, c;
        drift_light_triangle_vertices(scene, l, &a, &b, &c);
        return 0.5f *
               drift_vec3_length(drift_vec3_cross(drift_vec3_sub(b, a), drift_vec3_sub(c, a)));
    }
    case DRIFT_LIGHT_POINT:
    case DRIFT_LIGHT_SPOT:
    case DRIFT_LIGHT_DIRECTIONAL:
    case DRIFT_LIGHT_COUNT:
        break;
    }
    return 0.0f;
}

static float smoothstep01(float t)
{
    t = drift_clampf(t, 0.0f, 1.0f);
    return t * t * (3.0f - 2.0f * t);
}

float drift_light_spot_falloff(const drift_light *l, float cos_theta)
{
    if (l->type != DRIFT_LIGHT_SPOT) {
        return 1.0f;
    }
    float lo = cosf(l->spot_outer), hi = cosf(l->spot_inner);
    if (cos_theta <= lo) {
        return 0.0f;
    }
    switch (l->spot_falloff) {
    case DRIFT_SPOT_GLTF: {
        // lightAngleScale = 1 / max(0.001, cos inner − cos outer), as the extension's code.
        float t = drift_clampf((cos_theta - lo) / drift_maxf(0.001f, hi - lo), 0.0f, 1.0f);
        return t * t;
    }
    case DRIFT_SPOT_BLENDER: {
        // Cycles' spot_attenuation: the cosine times a smoothstep over spot_smooth =
        // (1 − cos(size / 2)) · blend; Blender's glTF importer reads blend = 1 − inner / outer.
        float blend = l->spot_outer > 0.0f ? 1.0f - l->spot_inner / l->spot_outer : 0.0f;
        float smooth = (1.0f - lo) * drift_clampf(blend, 0.0f, 1.0f);
        float t = cos_theta - lo;
        return cos_theta * (t < smooth && smooth > 0.0f ? smoothstep01(t / smooth) : 1.0f);
    }
    case DRIFT_SPOT_SMOOTHSTEP:
    default:
        return hi > lo ? smoothstep01((cos_theta - lo) / (hi - lo)) : 1.0f;
    }
}

// ∫ falloff dω over the sphere of a spot light: 2π ∫ f(c) dc from cos outer to 1 (midpoint
// rule; the integrands are smooth but for the ramp's ends, 512 steps hold 1e-5).
static float spot_solid_angle(const drift_light *l)
{
    float lo = cosf(l->spot_outer), sum = 0.0f;
    const int steps = 512;
    for (int i = 0; i < steps; ++i) {
        float c = lo + (1.0f - lo) * ((float)i + 0.5f) / (float)steps;
        sum += drift_light_spot_falloff(l, c);
    }
    return 2.0f * DRIFT_PI * sum * (1.0f - lo) / (float)steps;
}

// Emitted power (luminance-weighted), the weight of the light in the pick distribution.
static float light_power(const drift_scene *scene, const drift_light *l, float scene_radius)
{
    float lum = drift_luminance(l->color);
    switch (l->type) {
    case DRIFT_LIGHT_POINT:
        return 4.0f * DRIFT_PI * lum;
    case DRIFT_LIGHT_SPOT:
        return l->spot_falloff == DRIFT_SPOT_SMOOTHSTEP
                   ? 2.0f * DRIFT_PI * (1.0f - 0.5f * (cosf(l->spot_inner) + cosf(l->spot_outer))) *
                         lum
                   : spot_solid_angle(l) * lum;
    case DRIFT_LIGHT_DIRECTIONAL:
        return DRIFT_PI * scene_radius * scene_radius * lum;
    case DRIFT_LIGHT_QUAD:
    case DRIFT_LIGHT_DISK:
    case DRIFT_LIGHT_SPHERE:
    case DRIFT_LIGHT_TRIANGLE:
        // A one-sided Lambertian emitter of area A and radiance L emits pi A L; a two-sided
        // triangle twice that.
        return (l->two_sided ? 2.0f : 1.0f) * DRIFT_PI * light_area(scene, l) * lum;
    case DRIFT_LIGHT_COUNT:
        break;
    }
    return 0.0f;
}

// Unit normal a flat area light emits along; zero for spheres (their normal varies per point)
// and for delta lights.
static drift_vec3 flat_light_normal(const drift_scene *scene, const drift_light *l)
{
    switch (l->type) {
    case DRIFT_LIGHT_QUAD:
        return drift_vec3_normalize(drift_vec3_cross(l->edge_u, l->edge_v));
    case DRIFT_LIGHT_DISK:
        return l->direction;
    case DRIFT_LIGHT_TRIANGLE: {
        drift_vec3 a, b, c;
        drift_light_triangle_vertices(scene, l, &a, &b, &c);
        return drift_vec3_normalize(drift_vec3_cross(drift_vec3_sub(b, a), drift_vec3_sub(c, a)));
    }
    case DRIFT_LIGHT_SPHERE:
    case DRIFT_LIGHT_POINT:
    case DRIFT_LIGHT_SPOT:
    case DRIFT_LIGHT_DIRECTIONAL:
    case DRIFT_LIGHT_COUNT:
        break;
    }
    return drift_vec3_splat(0.0f);
}

// --- TABLE ---

drift_result drift__light_table_build(drift_scene *scene)
{
    drift__light_table_destroy(scene);
    drift_context *ctx = scene->ctx;
    drift_light_table *table = drift_alloc(ctx, sizeof(drift_light_table));
    if (!table) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    scene->light_table = table;
    table->has_environment = drift_scene_has_environment(scene);
    drift_result r = drift__environment_build(scene, &table->environment);
    if (r != DRIFT_OK) {
        return r;
    }
    drift_bounds3 b = scene->bounds;
    table->environment_radius =
        drift_bounds3_is_empty(b) ? 1.0f : 0.5f * drift_vec3_length(drift_vec3_sub(b.max, b.min));
    table->entry_count = scene->light_count + (table->has_environment ? 1u : 0u);
    size_t lights = scene->light_count ? scene->light_count : 1;
    table->inv_area = drift_alloc(ctx, sizeof(float) * lights);
    table->normal = drift_alloc(ctx, sizeof(drift_vec3) * lights);
    if (!table->inv_area || !table->normal) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    for (uint32_t i = 0; i < scene->light_count; ++i) {
        const drift_light *l = &scene->lights[i];
        float area = light_area(scene, l);
        table->inv_area[i] = area > 0.0f ? 1.0f / area : 0.0f;
        table->normal[i] = flat_light_normal(scene, l);
    }
    table->cdf = drift_alloc(ctx, sizeof(float) * ((size_t)table->entry_count + 1));
    if (!table->cdf) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    // Accumulate in double: millions of emissive triangles would lose precision in float.
    double total = 0.0;
    double *running = drift_alloc(ctx, sizeof(double) * ((size_t)table->entry_count + 1));
    if (!running) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    for (uint32_t i = 0; i < scene->light_count; ++i) {
        total += (double)light_power(scene, &scene->lights[i], table->environment_radius);
        running[i + 1] = total;
    }
    if (table->has_environment) {
        float env_r = table->environment_radius;
        total += (double)(DRIFT_PI * DRIFT_PI * env_r * env_r * 4.0f *
                          drift__environment_average(scene));
        running[table->entry_count] = total;
    }
    for (uint32_t i = 0; i <= table->entry_count; ++i) {
        // All-black lights: fall back to a uniform pick rather than divide by zero.
        table->cdf[i] = total > 0.0
                            ? (float)(running[i] / total)
                            : (float)i / (float)(table->entry_count ? table->entry_count : 1);
    }
    if (table->entry_count > 0) {
        table->cdf[table->entry_count] = 1.0f;
    }
    drift_free(ctx, running);
    return DRIFT_OK;
}

void drift__light_table_destroy(drift_scene *scene)
{
    if (scene->light_table) {
        drift__environment_destroy(scene, scene->light_table->environment);
        drift_free(scene->ctx, scene->light_table->inv_area);
        drift_free(scene->ctx, scene->light_table->normal);
        drift_free(scene->ctx, scene->light_table->cdf);
        drift_free(scene->ctx, scene->light_table);
        scene->light_table = NULL;
    }
}

static float entry_pmf(const drift_light_table *t, uint32_t i)
{
    return i < t->entry_count ? t->cdf[i + 1] - t->cdf[i] : 0.0f;
}

// Index of the entry whose [cdf[i], cdf[i+1]) holds u, skipping zero-width entries.
static uint32_t table_pick(const drift_light_table *t, float u)
{
    uint32_t lo = drift_cdf_find(t->cdf, t->entry_count, u);
    while (lo + 1 < t->entry_count && entry_pmf(t, lo) <= 0.0f) {
        lo++;
    }
    return lo;
}

uint32_t drift_scene_pick_light(const drift_scene *scene, float u, float *out_pmf)
{
    const drift_light_table *t = scene->light_table;
    if (!t || t->entry_count == 0) {
        *out_pmf = 0.0f;
        return DRIFT_INVALID_INDEX;
    }
    uint32_t i = table_pick(t, u);
    *out_pmf = entry_pmf(t, i);
    // The environment is the entry after the last light; report it as light_count.
    return i;
}

uint32_t drift_scene_pick_light_reuse(const drift_scene *scene, float *u, float *out_pmf)
{
    uint32_t i = drift_scene_pick_light(scene, *u, out_pmf);
    if (i != DRIFT_INVALID_INDEX && *out_pmf > 0.0f) {
        const drift_light_table *t = scene->light_table;
        // Clamped below 1: a float's rounding at the top of the interval must not reach it.
        *u = drift_minf((*u - t->cdf[i]) / *out_pmf, 0x1.fffffep-1f);
        *u = drift_maxf(*u, 0.0f);
    }
    return i;
}

float drift_scene_light_pmf(const drift_scene *scene, uint32_t light)
{
    const drift_light_table *t = scene->light_table;
    return t && light < scene->light_count ? entry_pmf(t, light) : 0.0f;
}

float drift_scene_environment_pmf(const drift_scene *scene)
{
    const drift_light_table *t = scene->light_table;
    return t && t->has_environment ? entry_pmf(t, scene->light_count) : 0.0f;
}

// --- SAMPLING ---

// Converts an area-measure pdf at point p (normal n) into solid angle as seen from ref.
static float area_to_solid_angle(float pdf_area, float dist, drift_vec3 wi, drift_vec3 n)
{
    float cos_l = fabsf(drift_vec3_dot(n, wi));
    return cos_l > 0.0f ? pdf_area * dist * dist / cos_l : 0.0f;
}

// 1 - cos(theta_max) of the cone a sphere of radius r subtends at distance d, computed
// without cancellation for small r/d.
static float sphere_cone_one_minus_cos(float r, float d)
{
    float sin2 = (r * r) / (d * d);
    return sin2 / (1.0f + sqrtf(drift_maxf(0.0f, 1.0f - sin2)));
}

// A uniformly sampled point p on area light `light` (density 1 / area), seen from ref.
static drift_light_sample sample_area_point(const drift_scene *scene, uint32_t light,
                                            drift_vec3 ref, drift_vec3 p)
{
    const drift_light *l = &scene->lights[light];
    const drift_light_table *t = scene->light_table;
    drift_light_sample s = { 0 };
    drift_vec3 d = drift_vec3_sub(p, ref);
    float dist = drift_vec3_length(d);
    if (!(dist > 0.0f)) {
        return s;
    }
    s.wi = drift_vec3_scale(d, 1.0f / dist);
    s.distance = dist;
    s.point = p;
    s.light_normal = l->type == DRIFT_LIGHT_SPHERE
                         ? drift_vec3_normalize(drift_vec3_sub(p, l->position))
                         : t->normal[light];
    s.pdf = area_to_solid_angle(t->inv_area[light], dist, s.wi, s.light_normal);
    // One-sided emitters: light leaves along the normal only (both ways for two-sided
    // triangles: glTF doubleSided emissive materials, as Cycles).
    bool facing = drift_vec3_dot(s.light_normal, s.wi) < 0.0f || l->two_sided;
    s.radiance = facing ? l->color : drift_vec3_splat(0.0f);
    return s;
}

// The emission of a triangle light at barycentrics bary: its material's, with the emissive
// texture read there (l->color is only the triangle's mean, for picking it).
static drift_vec3 triangle_radiance(const drift_scene *scene, const drift_light *l, drift_vec2 bary)
{
    const drift_material *m = &scene->materials[scene->meshes[l->mesh].material];
    if (m->type != DRIFT_MATERIAL_GGX || m->ggx.emissive_texture == DRIFT_INVALID_INDEX) {
        return l->color;
    }
    drift_surface s = drift__triangle_surface(scene, l->mesh, l->triangle, bary.x, bary.y);
    return drift__material_emission(scene, m, &s);
}

drift_light_sample drift_light_sample_li(const drift_scene *scene, uint32_t light, drift_vec3 ref,
                                         drift_vec2 u)
{
    if (light == scene->light_count) {
        return drift_environment_sample(scene, u);
    }
    const drift_light *l = &scene->lights[light];
    drift_light_sample s = { 0 };
    switch (l->type) {
    case DRIFT_LIGHT_POINT:
    case DRIFT_LIGHT_SPOT: {
        drift_vec3 d = drift_vec3_sub(l->position, ref);
        float dist2 = drift_vec3_dot(d, d);
        if (!(dist2 > 0.0f)) {
            return s;
        }
        float dist = sqrtf(dist2);
        s.wi = drift_vec3_scale(d, 1.0f / dist);
        s.distance = dist;
        s.point = l->position;
        s.pdf = 1.0f;
        s.is_delta = true;
        float falloff = 1.0f;
        if (l->type == DRIFT_LIGHT_SPOT) {
            // pbrt-v4 SpotLight's smoothstep, glTF's or Blender's (spot_falloff).
            float cos_theta = drift_vec3_dot(l->direction, drift_vec3_neg(s.wi));
            falloff = drift_light_spot_falloff(l, cos_theta);
        }
        s.radiance = drift_vec3_scale(l->color, falloff / dist2);
        return s;
    }
    case DRIFT_LIGHT_DIRECTIONAL:
        s.wi = drift_vec3_neg(l->direction);
        s.distance = INFINITY;
        s.radiance = l->color;
        s.pdf = 1.0f;
        s.is_delta = true;
        return s;
    case DRIFT_LIGHT_QUAD: {
        drift_vec3 p =
            drift_vec3_add(l->position, drift_vec3_add(drift_vec3_scale(l->edge_u, u.x),
                                                       drift_vec3_scale(l->edge_v, u.y)));
        return sample_area_point(scene, light, ref, p);
    }
    case DRIFT_LIGHT_DISK: {
        drift_frame f = drift_frame_from_normal(l->direction);
        drift_vec2 d = drift_sample_disk_concentric(u);
        drift_vec3 p = drift_vec3_add(
            l->position,
            drift_frame_to_world(&f, drift_vec3_make(d.x * l->radius, d.y * l->radius, 0)));
        return sample_area_point(scene, light, ref, p);
    }
    case DRIFT_LIGHT_SPHERE: {
        drift_vec3 to_center = drift_vec3_sub(l->position, ref);
        float dc = drift_vec3_length(to_center);
        if (dc <= l->radius * 1.0001f) {
            // Inside (or on) the sphere: uniform area sampling.
            drift_vec3 p = drift_vec3_fma(l->position, drift_sample_uniform_sphere(u), l->radius);
            return sample_area_point(scene, light, ref, p);
        }
        // Outside: uniform over the cone of directions the sphere subtends (pbrt-v4 §6.2.4).
        float one_minus_cos = sphere_cone_one_minus_cos(l->radius, dc);
        float cos_max = 1.0f - one_minus_cos;
        drift_frame f = drift_frame_from_normal(drift_vec3_scale(to_center, 1.0f / dc));
        drift_vec3 local = drift_sample_uniform_cone(u, cos_max);
        drift_vec3 wi = drift_vec3_normalize(drift_frame_to_world(&f, local));
        // Distance to the near intersection of the sampled ray with the sphere.
        float b = drift_vec3_dot(wi, to_center);
        float disc = l->radius * l->radius - (dc * dc - b * b);
        float t = b - sqrtf(drift_maxf(0.0f, disc));
        s.wi = wi;
        s.distance = t;
        s.point = drift_vec3_fma(ref, wi, t);
        s.light_normal = drift_vec3_normalize(drift_vec3_sub(s.point, l->position));
        s.pdf = 1.0f / (2.0f * DRIFT_PI * one_minus_cos);
        s.radiance = l->color;
        return s;
    }
    case DRIFT_LIGHT_TRIANGLE: {
        drift_vec3 a, b, c;
        drift_light_triangle_vertices(scene, l, &a, &b, &c);
        drift_vec2 bary = drift_sample_triangle(u);
        drift_vec3 p = drift_vec3_add(
            drift_vec3_scale(a, 1.0f - bary.x - bary.y),
            drift_vec3_add(drift_vec3_scale(b, bary.x), drift_vec3_scale(c, bary.y)));
        s = sample_area_point(scene, light, ref, p);
        if (!drift_vec3_is_zero(s.radiance)) {
            s.radiance = triangle_radiance(scene, l, bary);
        }
        return s;
    }
    case DRIFT_LIGHT_COUNT:
        break;
    }
    return s;
}

float drift_light_pdf_li(const drift_scene *scene, uint32_t light, drift_vec3 ref, drift_vec3 wi,
                         float distance, drift_vec3 light_normal)
{
    if (light >= scene->light_count) {
        return 0.0f;
    }
    const drift_light *l = &scene->lights[light];
    switch (l->type) {
    case DRIFT_LIGHT_SPHERE: {
        float dc = drift_vec3_length(drift_vec3_sub(l->position, ref));
        if (dc > l->radius * 1.0001f) {
            return 1.0f / (2.0f * DRIFT_PI * sphere_cone_one_minus_cos(l->radius, dc));
        }
        return area_to_solid_angle(scene->light_table->inv_area[light], distance, wi, light_normal);
    }
    case DRIFT_LIGHT_QUAD:
    case DRIFT_LIGHT_DISK:
    case DRIFT_LIGHT_TRIANGLE:
        return area_to_solid_angle(scene->light_table->inv_area[light], distance, wi, light_normal);
    case DRIFT_LIGHT_POINT:
    case DRIFT_LIGHT_SPOT:
    case DRIFT_LIGHT_DIRECTIONAL:
    case DRIFT_LIGHT_COUNT:
        break;
    }
    return 0.0f;
}

bool drift_light_emit_distant(const drift_scene *scene, uint32_t light, drift_vec3 centre,
                              float radius, drift_vec2 u1, drift_vec2 u2, float pmf, float paths,
                              drift_ray *out_ray, drift_vec3 *out_flux)
{
    // Parallel rays from a disc of radius R perpendicular to the direction of travel, 1.5 R
    // before the centre: the disc's area stands in for the light's cross-section.
    drift_vec3 travel;
    drift_vec3 radiance;
    float pdf_dir = 1.0f;
    if (light == scene->light_count) {
        drift_light_sample ls = drift_environment_sample(scene, u1);
        if (!(ls.pdf > 0.0f)) {
            return false;
        }
        travel = drift_vec3_neg(ls.wi);
        radiance = ls.radiance;
        pdf_dir = ls.pdf;
    } else if (light < scene->light_count && scene->lights[light].type == DRIFT_LIGHT_DIRECTIONAL) {
        travel = scene->lights[light].direction;
        radiance = scene->lights[light].color;
    } else {
        return false;
    }
    drift_frame f = drift_frame_from_normal(travel);
    drift_vec2 d = drift_sample_disk_concentric(u2);
    drift_vec3 o = drift_vec3_fma(centre, travel, -1.5f * radius);
    o = drift_vec3_fma(o, f.x, d.x * radius);
    o = drift_vec3_fma(o, f.y, d.y * radius);
    *out_ray = (drift_ray){ o, 0.0f, travel, INFINITY, 0 };
    float area = DRIFT_PI * radius * radius;
    *out_flux = drift_vec3_scale(radiance, area / (pdf_dir * pmf * paths));
    return true;
}

bool drift_light_emit_area(const drift_scene *scene, const drift_light *l, drift_vec2 u1,
                           drift_vec2 u2, float pmf, float paths, drift_ray *out_ray,
                           drift_vec3 *out_flux)
{
    // A uniform point (density 1 / A) and a cosine direction (cos / pi) give
    // L cos / (cos / pi / A) = pi A L per path.
    drift_vec3 p, normal, radiance = l->color;
    float area, sides = 1.0f;
    switch (l->type) {
    case DRIFT_LIGHT_QUAD:
        p = drift_vec3_fma(drift_vec3_fma(l->position, l->edge_u, u1.x), l->edge_v, u1.y);
        normal = drift_vec3_cross(l->edge_u, l->edge_v);
        area = drift_vec3_length(normal);
        normal = drift_vec3_scale(normal, 1.0f / area);
        break;
    case DRIFT_LIGHT_DISK: {
        drift_frame fr = drift_frame_from_normal(l->direction);
        drift_vec2 d = drift_sample_disk_concentric(u1);
        p = drift_vec3_fma(drift_vec3_fma(l->position, fr.x, d.x * l->radius), fr.y,
                           d.y * l->radius);
        normal = l->direction;
        area = DRIFT_PI * l->radius * l->radius;
        break;
    }
    case DRIFT_LIGHT_SPHERE:
        normal = drift_sample_uniform_sphere(u1);
        p = drift_vec3_fma(l->position, normal, l->radius);
        area = 4.0f * DRIFT_PI * l->radius * l->radius;
        break;
    case DRIFT_LIGHT_TRIANGLE: {
        drift_vec3 a, b, c;
        drift_light_triangle_vertices(scene, l, &a, &b, &c);
        drift_vec2 bc = drift_sample_triangle(u1);
        p = drift_vec3_fma(drift_vec3_fma(drift_vec3_scale(a, 1.0f - bc.x - bc.y), b, bc.x), c,
                           bc.y);
        normal = drift_vec3_cross(drift_vec3_sub(b, a), drift_vec3_sub(c, a));
        area = 0.5f * drift_vec3_length(normal);
        normal = drift_vec3_normalize(normal);
        radiance = triangle_radiance(scene, l, bc);
        if (l->two_sided) {
            // Either face with probability 1/2 (u2.x picks it, then is reused as a fresh number).
            sides = 2.0f;
            if (u2.x < 0.5f) {
                normal = drift_vec3_neg(normal);
                u2.x *= 2.0f;
            } else {
                u2.x = 2.0f * u2.x - 1.0f;
            }
            u2.x = drift_minf(u2.x, 0x1.fffffep-1f);
        }
        break;
    }
    default:
        return false;
    }
    drift_frame fr = drift_frame_from_normal(normal);
    drift_vec3 w = drift_frame_to_world(&fr, drift_sample_cosine_hemisphere(u2));
    *out_ray = (drift_ray){ drift_offset_origin(p, normal, w), 0.0f, w, INFINITY, 0 };
    *out_flux = drift_vec3_scale(radiance, sides * DRIFT_PI * area / (pmf * paths));
    return true;
}
