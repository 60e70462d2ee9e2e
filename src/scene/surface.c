// Surface reconstruction from a hit: position, normals, uv, material and emission.
#include "scene_internal.h"

#include <math.h>

static drift_vec3 load3(const float *a, uint32_t i)
{
    return drift_vec3_make(a[3 * (size_t)i], a[3 * (size_t)i + 1], a[3 * (size_t)i + 2]);
}

static drift_vec3 lerp3(drift_vec3 a, drift_vec3 b, drift_vec3 c, float u, float v)
{
    return drift_vec3_add(drift_vec3_scale(a, 1.0f - u - v),
                          drift_vec3_add(drift_vec3_scale(b, u), drift_vec3_scale(c, v)));
}

static drift_vec2 lerp_uv(const float *t, const uint32_t *tri, float u, float v)
{
    float w = 1.0f - u - v;
    return drift_vec2_make(w * t[2 * tri[0]] + u * t[2 * tri[1]] + v * t[2 * tri[2]],
                           w * t[2 * tri[0] + 1] + u * t[2 * tri[1] + 1] + v * t[2 * tri[2] + 1]);
}

drift_vec3 drift__material_emission(const drift_scene *scene, const drift_material *m,
                                    const drift_surface *surface)
{
    if (m->type != DRIFT_MATERIAL_GGX || m->ggx.emissive_texture == DRIFT_INVALID_INDEX) {
        return m->emission;
    }
    return drift_vec3_mul(m->emission,
                          drift_material_texture(scene, m, DRIFT_TEXTURE_EMISSIVE, surface));
}

// Orients ng toward the ray origin and ns to ng's side; records which face was hit.
static void orient(drift_surface *s, drift_vec3 ng_geometric, drift_vec3 ns, drift_vec3 ray_dir)
{
    s->front_face = drift_vec3_dot(ng_geometric, ray_dir) < 0.0f;
    s->ng = s->front_face ? ng_geometric : drift_vec3_neg(ng_geometric);
    if (drift_vec3_dot(ns, ng_geometric) < 0.0f) {
        ns = drift_vec3_neg(ns);
    }
    s->ns = s->front_face ? ns : drift_vec3_neg(ns);
}

drift_surface drift_scene_surface(const drift_scene *scene, const drift_ray *ray,
                                  const drift_hit *hit)
{
    drift_surface s = { .material = DRIFT_INVALID_INDEX,
                        .light = hit->light,
                        .mesh = DRIFT_INVALID_INDEX,
                        .triangle = DRIFT_INVALID_INDEX };
    drift_vec3 dir = drift_vec3_normalize(ray->dir);
    if (hit->mesh != DRIFT_INVALID_INDEX) {
        const drift_mesh *mesh = &scene->meshes[hit->mesh];
        const uint32_t *tri = mesh->indices + 3 * (size_t)hit->prim;
        drift_vec3 a = load3(mesh->positions, tri[0]);
        drift_vec3 b = load3(mesh->positions, tri[1]);
        drift_vec3 c = load3(mesh->positions, tri[2]);
        // Barycentric interpolation is more precise than origin + t * dir far from the origin.
        s.position = lerp3(a, b, c, hit->u, hit->v);
        drift_vec3 ng =
            drift_vec3_normalize(drift_vec3_cross(drift_vec3_sub(b, a), drift_vec3_sub(c, a)));
        drift_vec3 ns = ng;
        if (mesh->normals) {
            drift_vec3 n = lerp3(load3(mesh->normals, tri[0]), load3(mesh->normals, tri[1]),
                                 load3(mesh->normals, tri[2]), hit->u, hit->v);
            float len = drift_vec3_length(n);
            if (len > 1e-6f) {
                ns = drift_vec3_scale(n, 1.0f / len);
            }
        }
        s.uv =
            mesh->uvs ? lerp_uv(mesh->uvs, tri, hit->u, hit->v) : drift_vec2_make(hit->u, hit->v);
        s.uv1 = mesh->uvs1 ? lerp_uv(mesh->uvs1, tri, hit->u, hit->v) : s.uv;
        orient(&s, ng, ns, dir);
        s.material = mesh->material;
        s.mesh = hit->mesh;
        s.triangle = hit->prim;
        s.barycentric = drift_vec2_make(hit->u, hit->v);
        const drift_material *m = &scene->materials[mesh->material];
        if ((s.front_face || m->emission_two_sided) && !drift_vec3_is_zero(m->emission)) {
            s.emission = drift__material_emission(scene, m, &s);
        }
        return s;
    }
    if (hit->light != DRIFT_INVALID_INDEX) {
        const drift_light *l = &scene->lights[hit->light];
        s.position = drift_vec3_fma(ray->origin, ray->dir, hit->t);
        drift_vec3 n;
        if (l->type == DRIFT_LIGHT_SPHERE) {
            n = drift_vec3_normalize(drift_vec3_sub(s.position, l->position));
        } else if (l->type == DRIFT_LIGHT_DISK) {
            n = l->direction;
        } else {
            n = drift_vec3_normalize(drift_vec3_cross(l->edge_u, l->edge_v));
        }
        orient(&s, n, n, dir);
        if (s.front_face) {
            s.emission = l->color;
        }
    }
    return s;
}

drift_surface drift__triangle_surface(const drift_scene *scene, uint32_t mesh, uint32_t triangle,
                                      float u, float v)
{
    const drift_mesh *m = &scene->meshes[mesh];
    const uint32_t *tri = m->indices + 3 * (size_t)triangle;
    drift_vec3 a = load3(m->positions, tri[0]);
    drift_vec3 ng = drift_vec3_cross(drift_vec3_sub(load3(m->positions, tri[1]), a),
                                     drift_vec3_sub(load3(m->positions, tri[2]), a));
    drift_hit hit = { .t = 1.0f,
                      .u = u,
                      .v = v,
                      .mesh = mesh,
                      .prim = triangle,
                      .light = DRIFT_INVALID_INDEX,
                      .ng = ng };
    drift_ray ray = { .origin = a, .dir = drift_vec3_neg(ng), .tmax = INFINITY };
    return drift_scene_surface(scene, &ray, &hit);
}

// sqrt(uv area / world area) of the hit triangle in uv set `t` (0 when degenerate).
static float uv_density(const drift_mesh *mesh, const uint32_t *tri, const float *t, float area)
{
    if (!t || !(area > 0.0f)) {
        return 0.0f;
    }
    float du1 = t[2 * tri[1]] - t[2 * tri[0]], dv1 = t[2 * tri[1] + 1] - t[2 * tri[0] + 1];
    float du2 = t[2 * tri[2]] - t[2 * tri[0]], dv2 = t[2 * tri[2] + 1] - t[2 * tri[0] + 1];
    (void)mesh;
    return sqrtf(fabsf(du1 * dv2 - dv1 * du2) / area);
}

void drift_surface_set_footprint(const drift_scene *scene, drift_surface *surface, float width,
                                 drift_vec3 ray_dir)
{
    surface->uv_footprint = surface->uv1_footprint = 0.0f;
    if (surface->mesh == DRIFT_INVALID_INDEX || !(width > 0.0f) || !isfinite(width)) {
        return;
    }
    const drift_mesh *mesh = &scene->meshes[surface->mesh];
    const uint32_t *tri = mesh->indices + 3 * (size_t)surface->triangle;
    drift_vec3 a = load3(mesh->positions, tri[0]);
    drift_vec3 e1 = drift_vec3_sub(load3(mesh->positions, tri[1]), a);
    drift_vec3 e2 = drift_vec3_sub(load3(mesh->positions, tri[2]), a);
    float area = drift_vec3_length(drift_vec3_cross(e1, e2)); // twice the area, as the uv one
    // The cone's width over the surface: width / |cos| (eq. 34's log2|n . d| term), kept
    // finite at grazing angles.
    float cos_theta = fabsf(drift_vec3_dot(surface->ng, drift_vec3_normalize(ray_dir)));
    float w = width / drift_maxf(cos_theta, 1e-3f);
    surface->uv_footprint = w * uv_density(mesh, tri, mesh->uvs, area);
    surface->uv1_footprint =
        mesh->uvs1 ? w * uv_density(mesh, tri, mesh->uvs1, area) : surface->uv_footprint;
}

drift_vec3 drift_offset_origin(drift_vec3 position, drift_vec3 ng, drift_vec3 dir)
{
    // Offset scaled to the coordinates' magnitude: float spacing grows with |p|.
    float magnitude =
        drift_maxf(fabsf(position.x), drift_maxf(fabsf(position.y), fabsf(position.z)));
    float eps = 3e-5f * drift_maxf(1.0f, magnitude);
    drift_vec3 n = drift_vec3_dot(ng, dir) < 0.0f ? drift_vec3_neg(ng) : ng;
    return drift_vec3_fma(position, n, eps);
}

float drift_scene_opacity(const drift_scene *scene, uint32_t mesh_index, uint32_t prim, float u,
                          float v)
{
    const drift_mesh *mesh = &scene->meshes[mesh_index];
    const drift_material *m = &scene->materials[mesh->material];
    float opacity = m->opacity;
    if (m->opacity_texture != DRIFT_INVALID_INDEX) {
        // Level 0 at the hit's uv, as the base colour's texture reads it (its uv set,
        // transform, wrap and filter): a cut-out's edge is where the artist painted it.
        const drift_texture_map *map = &m->maps[DRIFT_TEXTURE_BASE];
        const uint32_t *tri = &mesh->indices[3 * (size_t)prim];
        const float *uvs = map->uv_set == 1 && mesh->uvs1 ? mesh->uvs1 : mesh->uvs;
        drift_vec2 uv = uvs ? lerp_uv(uvs, tri, u, v) : drift_vec2_make(u, v);
        opacity *= drift__texture_sample(scene, m->opacity_texture, map, uv, 0.0f).x;
    }
    return drift_clampf(opacity, 0.0f, 1.0f);
}

bool drift_scene_covers(const drift_scene *scene, uint32_t mesh, uint32_t prim, float u, float v,
                        float xi)
{
    const drift_material *m = &scene->materials[scene->meshes[mesh].material];
    switch (m->alpha_mode) {
    case DRIFT_ALPHA_MASK:
        return drift_scene_opacity(scene, mesh, prim, u, v) >= m->alpha_cutoff;
    case DRIFT_ALPHA_BLEND:
        return xi < drift_scene_opacity(scene, mesh, prim, u, v);
    default:
        return true;
    }
}
