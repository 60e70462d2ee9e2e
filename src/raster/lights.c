// The lights as the hybrid frame sees them: scene lights one by one, except that every
// triangle light of one emissive mesh becomes one light, so that a quad modelled as two
// triangles casts one shadow map and one hard-shadow ray, not two.
#include "raster/raster.h"

#include <math.h>

static drift_raster_light single_light(const drift_scene *scene, uint32_t index)
{
    const drift_light *l = &scene->lights[index];
    drift_raster_light h = { .type = l->type,
                             .centre = l->position,
                             .first_light = index,
                             .light_count = 1,
                             .mesh = DRIFT_INVALID_INDEX };
    switch (l->type) {
    case DRIFT_LIGHT_SPOT:
    case DRIFT_LIGHT_DIRECTIONAL:
        h.direction = l->direction;
        break;
    case DRIFT_LIGHT_QUAD: {
        drift_vec3 half = drift_vec3_scale(drift_vec3_add(l->edge_u, l->edge_v), 0.5f);
        h.centre = drift_vec3_add(l->position, half);
        h.radius = drift_vec3_length(half);
        h.direction = drift_vec3_normalize(drift_vec3_cross(l->edge_u, l->edge_v));
        h.one_sided = true;
        break;
    }
    case DRIFT_LIGHT_DISK:
        h.direction = l->direction;
        h.radius = l->radius;
        h.one_sided = true;
        break;
    case DRIFT_LIGHT_SPHERE:
        h.radius = l->radius;
        h.shadow_clearance = 1.001f * l->radius;
        break;
    case DRIFT_LIGHT_TRIANGLE: {
        drift_vec3 c[3];
        drift_light_triangle_vertices(scene, l, &c[0], &c[1], &c[2]);
        h.centre = drift_vec3_scale(drift_vec3_add(c[0], drift_vec3_add(c[1], c[2])), 1.0f / 3.0f);
        h.direction = drift_vec3_normalize(
            drift_vec3_cross(drift_vec3_sub(c[1], c[0]), drift_vec3_sub(c[2], c[0])));
        for (int k = 0; k < 3; ++k) {
            h.radius = fmaxf(h.radius, drift_vec3_length(drift_vec3_sub(c[k], h.centre)));
        }
        h.one_sided = true;
        break;
    }
    case DRIFT_LIGHT_POINT:
    case DRIFT_LIGHT_COUNT:
        break;
    }
    return h;
}

// The radius of the sphere a mesh light's triangles tile, or 0. A tessellated sphere (the
// Breakfast Room's sun, most OBJ exports of a sphere emitter) has every vertex at one distance
// from the area centroid, every triangle's centre close to it (which rules out a cube or an
// icosahedron, whose corners lie on a sphere too), normals pointing out and one radiance.
// The stand-in sphere has the mesh's area, so the same power (pi A L) and, by Cauchy's
// formula, the same mean projected area.
static float tiled_sphere_radius(const drift_scene *scene, const drift_mesh *m, drift_vec3 centre,
                                 double area)
{
    enum {
        MIN_TRIANGLES = 32
    };

    if (m->triangle_count < MIN_TRIANGLES) {
        return 0.0f;
    }
    float radius = sqrtf((float)(area / (4.0 * (double)DRIFT_PI)));
    drift_vec3 colour = scene->lights[m->first_light].color;
    for (uint32_t t = 0; t < m->triangle_count; ++t) {
        const drift_light *l = &scene->lights[m->first_light + t];
        if (l->color.x != colour.x || l->color.y != colour.y || l->color.z != colour.z) {
            return 0.0f;
        }
        drift_vec3 c[3];
        drift_light_triangle_vertices(scene, l, &c[0], &c[1], &c[2]);
        for (int k = 0; k < 3; ++k) {
            float d = drift_vec3_length(drift_vec3_sub(c[k], centre));
            if (fabsf(d - radius) > 0.03f * radius) {
                return 0.0f;
            }
        }
        drift_vec3 mid = drift_vec3_sub(
            drift_vec3_scale(drift_vec3_add(c[0], drift_vec3_add(c[1], c[2])), 1.0f / 3.0f),
            centre);
        drift_vec3 normal =
            drift_vec3_cross(drift_vec3_sub(c[1], c[0]), drift_vec3_sub(c[2], c[0]));
        // A sliver at a pole (no area) has no direction to check.
        bool sliver = drift_vec3_length(normal) < 1e-6f * radius * radius;
        if (drift_vec3_length(mid) < 0.95f * radius ||
            (!sliver && drift_vec3_dot(normal, mid) <= 0.0f)) {
            return 0.0f;
        }
    }
    return radius;
}

// Whether every vertex of a one-sided mesh light lies in the plane through its centre along
// its mean normal (a quad as two triangles): a ray toward the centre then meets none of it.
static bool is_flat(const drift_mesh *m, const drift_raster_light *light)
{
    if (!light->one_sided) {
        return false;
    }
    for (uint32_t v = 0; v < m->vertex_count; ++v) {
        const float *p = m->positions + 3u * v;
        drift_vec3 d = drift_vec3_sub(drift_vec3_make(p[0], p[1], p[2]), light->centre);
        if (fabsf(drift_vec3_dot(d, light->direction)) > 1e-4f * light->radius) {
            return false;
        }
    }
    return true;
}

// Gathers the triangle lights first_light .. first_light + count - 1 of one mesh: area CDF,
// area-weighted centroid and mean normal, bounding radius about the centroid.
static drift_result mesh_light(drift_context *ctx, const drift_scene *scene, uint32_t mesh,
                               drift_raster_light *out)
{
    const drift_mesh *m = &scene->meshes[mesh];
    *out = (drift_raster_light){ .type = DRIFT_LIGHT_TRIANGLE,
                                 .first_light = m->first_light,
                                 .light_count = m->triangle_count,
                                 .mesh = mesh,
                                 .one_sided = true };
    out->light_cdf = drift_alloc(ctx, sizeof(float) * m->triangle_count);
    if (!out->light_cdf) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    double total = 0.0;
    drift_vec3 centroid = drift_vec3_splat(0.0f), normal = drift_vec3_splat(0.0f);
    for (uint32_t t = 0; t < m->triangle_count; ++t) {
        drift_vec3 c[3];
        drift_light_triangle_vertices(scene, &scene->lights[m->first_light + t], &c[0], &c[1],
                                      &c[2]);
        drift_vec3 cross = drift_vec3_cross(drift_vec3_sub(c[1], c[0]), drift_vec3_sub(c[2], c[0]));
        float area = 0.5f * drift_vec3_length(cross);
        total += (double)area;
        out->light_cdf[t] = (float)total;
        drift_vec3 mid =
            drift_vec3_scale(drift_vec3_add(c[0], drift_vec3_add(c[1], c[2])), 1.0f / 3.0f);
        centroid = drift_vec3_fma(centroid, mid, area);
        normal = drift_vec3_add(normal, drift_vec3_scale(cross, 0.5f));
    }
    for (uint32_t t = 0; t < m->triangle_count; ++t) {
        out->light_cdf[t] = (float)((double)out->light_cdf[t] / total);
    }
    out->light_cdf[m->triangle_count - 1] = 1.0f;
    out->centre = drift_vec3_scale(centroid, (float)(1.0 / total));
    // A closed emitter has no mean normal: treat it as emitting all around.
    float normal_length = drift_vec3_length(normal);
    out->one_sided = normal_length > 0.5f * (float)total;
    out->two_sided = scene->lights[m->first_light].two_sided; // one material: all or none
    out->direction =
        out->one_sided ? drift_vec3_scale(normal, 1.0f / normal_length) : drift_vec3_splat(0.0f);
    for (uint32_t v = 0; v < m->vertex_count; ++v) {
        const float *p = m->positions + 3u * v;
        drift_vec3 d = drift_vec3_sub(drift_vec3_make(p[0], p[1], p[2]), out->centre);
        out->radius = fmaxf(out->radius, drift_vec3_length(d));
    }
    out->sphere_radius = out->one_sided ? 0.0f : tiled_sphere_radius(scene, m, out->centre, total);
    out->shadow_clearance = out->sphere_radius > 0.0f ? 1.001f * out->radius
                            : is_flat(m, out)         ? 0.0f
                                                      : -1.0f;
    return DRIFT_OK;
}

drift_result drift_raster_lights_build(drift_context *ctx, const drift_scene *scene,
                                       drift_raster_light **out_lights, uint32_t *out_count)
{
    *out_lights = NULL;
    *out_count = 0;
    if (!scene->committed) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    uint32_t count = 0;
    for (uint32_t i = 0; i < scene->light_count; ++i) {
        const drift_light *l = &scene->lights[i];
        // A mesh's triangle lights are consecutive from mesh.first_light: count its first.
        if (l->type != DRIFT_LIGHT_TRIANGLE || scene->meshes[l->mesh].first_light == i) {
            ++count;
        }
    }
    if (count == 0) {
        return DRIFT_OK;
    }
    drift_raster_light *lights = drift_alloc(ctx, sizeof(drift_raster_light) * count);
    if (!lights) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    uint32_t n = 0;
    for (uint32_t i = 0; i < scene->light_count; ++i) {
        const drift_light *l = &scene->lights[i];
        if (l->type != DRIFT_LIGHT_TRIANGLE) {
            lights[n++] = single_light(scene, i);
        } else if (scene->meshes[l->mesh].first_light == i) {
            drift_result r = mesh_light(ctx, scene, l->mesh, &lights[n++]);
            if (r != DRIFT_OK) {
                drift_raster_lights_destroy(ctx, lights, n);
                return r;
            }
        }
    }
    *out_lights = lights;
    *out_count = count;
    return DRIFT_OK;
}

void drift_raster_lights_destroy(drift_context *ctx, drift_raster_light *lights, uint32_t count)
{
    if (!lights) {
        return;
    }
    for (uint32_t i = 0; i < count; ++i) {
        drift_free(ctx, lights[i].light_cdf);
    }
    drift_free(ctx, lights);
}

drift_light_sample drift_raster_light_sample(const drift_scene *scene,
                                             const drift_raster_light *light, drift_vec3 ref,
                                             float u_pick, drift_vec2 u)
{
    if (!light->light_cdf) {
        return drift_light_sample_li(scene, light->first_light, ref, u);
    }
    // Pick a triangle in proportion to its area (binary search of the CDF).
    uint32_t lo = 0, hi = light->light_count - 1;
    while (lo < hi) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (light->light_cdf[mid] <= u_pick) {
            lo = mid + 1;
        } else {
            hi = mid;
        }
    }
    float pmf = light->light_cdf[lo] - (lo > 0 ? light->light_cdf[lo - 1] : 0.0f);
    drift_light_sample s = drift_light_sample_li(scene, light->first_light + lo, ref, u);
    s.pdf *= pmf;
    return s;
}

// --- RAYS AGAINST THE LIGHT'S OWN SHAPES ---

// Distance along the unit direction d from o to triangle (a, b, c) (Moller-Trumbore), and its
// barycentrics of b and c; -1 on a miss. Both faces: which one emits is the surface's call.
static float ray_triangle(drift_vec3 o, drift_vec3 d, drift_vec3 a, drift_vec3 b, drift_vec3 c,
                          float *out_u, float *out_v)
{
    drift_vec3 e1 = drift_vec3_sub(b, a), e2 = drift_vec3_sub(c, a);
    drift_vec3 p = drift_vec3_cross(d, e2);
    float det = drift_vec3_dot(e1, p);
    if (det == 0.0f) {
        return -1.0f;
    }
    float inv = 1.0f / det;
    drift_vec3 s = drift_vec3_sub(o, a);
    float u = drift_vec3_dot(s, p) * inv;
    if (u < 0.0f || u > 1.0f) {
        return -1.0f;
    }
    drift_vec3 q = drift_vec3_cross(s, e1);
    float v = drift_vec3_dot(d, q) * inv;
    if (v < 0.0f || u + v > 1.0f) {
        return -1.0f;
    }
    *out_u = u;
    *out_v = v;
    return drift_vec3_dot(e2, q) * inv;
}

// The nearest hit t > 0 of the ray (o, unit d) on scene light `index`'s shape, or INFINITY;
// hit gets what drift_scene_surface needs.
static float ray_scene_light(const drift_scene *scene, uint32_t index, drift_vec3 o, drift_vec3 d,
                             drift_hit *hit)
{
    const drift_light *l = &scene->lights[index];
    *hit = (drift_hit){ .mesh = DRIFT_INVALID_INDEX, .light = index };
    float t = -1.0f;
    switch (l->type) {
    case DRIFT_LIGHT_QUAD: {
        // The parallelogram p + s edge_u + r edge_v as two triangles.
        drift_vec3 c = drift_vec3_add(l->position, drift_vec3_add(l->edge_u, l->edge_v));
        drift_vec3 b = drift_vec3_add(l->position, l->edge_u);
        drift_vec3 e = drift_vec3_add(l->position, l->edge_v);
        t = ray_triangle(o, d, l->position, b, c, &hit->u, &hit->v);
        if (!(t > 0.0f)) {
            t = ray_triangle(o, d, l->position, c, e, &hit->u, &hit->v);
        }
        break;
    }
    case DRIFT_LIGHT_DISK: {
        float cos_d = drift_vec3_dot(d, l->direction);
        if (cos_d != 0.0f) {
            t = drift_vec3_dot(drift_vec3_sub(l->position, o), l->direction) / cos_d;
            drift_vec3 p = drift_vec3_sub(drift_vec3_fma(o, d, t), l->position);
            t = drift_vec3_dot(p, p) <= l->radius * l->radius ? t : -1.0f;
        }
        break;
    }
    case DRIFT_LIGHT_SPHERE: {
        drift_vec3 oc = drift_vec3_sub(l->position, o);
        float b = drift_vec3_dot(oc, d), c = drift_vec3_dot(oc, oc) - l->radius * l->radius;
        float disc = b * b - c;
        if (disc >= 0.0f) {
            float s = sqrtf(disc);
            t = b - s > 0.0f ? b - s : b + s;
        }
        break;
    }
    case DRIFT_LIGHT_TRIANGLE: {
        drift_vec3 a, b, c;
        drift_light_triangle_vertices(scene, l, &a, &b, &c);
        t = ray_triangle(o, d, a, b, c, &hit->u, &hit->v);
        hit->mesh = l->mesh;
        hit->prim = l->triangle;
        break;
    }
    case DRIFT_LIGHT_POINT:
    case DRIFT_LIGHT_SPOT:
    case DRIFT_LIGHT_DIRECTIONAL:
    case DRIFT_LIGHT_COUNT:
        break;
    }
    hit->t = t;
    return t > 0.0f ? t : INFINITY;
}

bool drift_raster_light_hit(const drift_scene *scene, const drift_raster_light *light,
                            drift_vec3 origin, drift_vec3 dir, drift_vec3 *out_radiance,
                            float *out_pdf)
{
    if (!drift_light_is_area(light->type) || light->light_count > DRIFT_RASTER_HIT_TRIANGLES) {
        return false;
    }
    // Rays that pass the light's bounding sphere meet none of it.
    drift_vec3 oc = drift_vec3_sub(light->centre, origin);
    float b = drift_vec3_dot(oc, dir);
    float reach = light->radius * 1.001f;
    if (light->light_cdf && drift_vec3_dot(oc, oc) - b * b > reach * reach) {
        return false;
    }
    float nearest = INFINITY;
    uint32_t index = DRIFT_INVALID_INDEX;
    drift_hit hit = { 0 };
    for (uint32_t i = 0; i < light->light_count; ++i) {
        drift_hit h;
        float t = ray_scene_light(scene, light->first_light + i, origin, dir, &h);
        if (t < nearest) {
            nearest = t, index = i, hit = h;
        }
    }
    if (index == DRIFT_INVALID_INDEX) {
        return false;
    }
    drift_ray ray = { .origin = origin, .dir = dir, .tmin = 0.0f, .tmax = INFINITY };
    drift_surface s = drift_scene_surface(scene, &ray, &hit);
    if (drift_vec3_is_zero(s.emission)) {
        return false; // its back face: the light's own shape hides the rest
    }
    float pmf = 1.0f;
    if (light->light_cdf) {
        pmf = light->light_cdf[index] - (index > 0 ? light->light_cdf[index - 1] : 0.0f);
    }
    *out_radiance = s.emission;
    *out_pdf =
        pmf * drift_light_pdf_li(scene, light->first_light + index, origin, dir, nearest, s.ng);
    return true;
}
