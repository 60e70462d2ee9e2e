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
        if (mesh->uvs) {
            const float *t = mesh->uvs;
            float w = 1.0f - hit->u - hit->v;
            s.uv.x = w * t[2 * tri[0]] + hit->u * t[2 * tri[1]] + hit->v * t[2 * tri[2]];
            s.uv.y =
                w * t[2 * tri[0] + 1] + hit->u * t[2 * tri[1] + 1] + hit->v * t[2 * tri[2] + 1];
        } else {
            s.uv = drift_vec2_make(hit->u, hit->v);
        }
        orient(&s, ng, ns, dir);
        s.material = mesh->material;
        s.mesh = hit->mesh;
        s.triangle = hit->prim;
        s.barycentric = drift_vec2_make(hit->u, hit->v);
        const drift_material *m = &scene->materials[mesh->material];
        if (s.front_face && !drift_vec3_is_zero(m->emission)) {
            s.emission = m->emission;
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

drift_vec3 drift_offset_origin(drift_vec3 position, drift_vec3 ng, drift_vec3 dir)
{
    // Offset scaled to the coordinates' magnitude: float spacing grows with |p|.
    float magnitude = fmaxf(fabsf(position.x), fmaxf(fabsf(position.y), fabsf(position.z)));
    float eps = 3e-5f * fmaxf(1.0f, magnitude);
    drift_vec3 n = drift_vec3_dot(ng, dir) < 0.0f ? drift_vec3_neg(ng) : ng;
    return drift_vec3_fma(position, n, eps);
}
