// Per-vertex tangents for normal maps where the file has none, in the manner of MikkTSpace
// (Mikkelsen 2008, the tangent space Blender bakes and Cycles shades with): each triangle's
// dp/du, projected onto the plane of each corner's vertex normal and normalised, summed over the
// triangles around a vertex with the corner's angle as weight; the bitangent's sign is the
// weighted vote of the triangles' dp/dv against cross(n, t). No Debian 12 package ships
// MikkTSpace; unlike it, vertices whose triangles disagree in handedness (a mirrored uv seam
// that shares vertices) are not split here (docs/materials.md).
#include "scene_internal.h"

#include <math.h>
#include <string.h>

static drift_vec3 at3(const float *a, uint32_t i)
{
    return drift_vec3_make(a[3 * (size_t)i], a[3 * (size_t)i + 1], a[3 * (size_t)i + 2]);
}

// Angle at corner p between the edges toward q and r.
static float corner_angle(drift_vec3 p, drift_vec3 q, drift_vec3 r)
{
    drift_vec3 a = drift_vec3_sub(q, p), b = drift_vec3_sub(r, p);
    float la = drift_vec3_length(a), lb = drift_vec3_length(b);
    if (!(la > 0.0f) || !(lb > 0.0f)) {
        return 0.0f;
    }
    return acosf(drift_clampf(drift_vec3_dot(a, b) / (la * lb), -1.0f, 1.0f));
}

drift_result drift__mesh_tangents(drift_context *ctx, const drift_mesh *mesh, int uv_set,
                                  float **out)
{
    *out = NULL;
    const float *uv = uv_set == 1 && mesh->uvs1 ? mesh->uvs1 : mesh->uvs;
    if (!uv || !mesh->normals) {
        return DRIFT_OK;
    }
    size_t nv = mesh->vertex_count;
    float *t = drift_alloc(ctx, nv * 4 * sizeof(float)); // xyz sum, w: handedness vote
    if (!t) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    memset(t, 0, nv * 4 * sizeof(float));
    const float *p = mesh->positions;
    for (uint32_t f = 0; f < mesh->triangle_count; ++f) {
        const uint32_t *tri = mesh->indices + 3 * (size_t)f;
        drift_vec3 v[3] = { at3(p, tri[0]), at3(p, tri[1]), at3(p, tri[2]) };
        drift_vec3 dp1 = drift_vec3_sub(v[1], v[0]), dp2 = drift_vec3_sub(v[2], v[0]);
        float du1 = uv[2 * tri[1]] - uv[2 * tri[0]], dv1 = uv[2 * tri[1] + 1] - uv[2 * tri[0] + 1];
        float du2 = uv[2 * tri[2]] - uv[2 * tri[0]], dv2 = uv[2 * tri[2] + 1] - uv[2 * tri[0] + 1];
        float det = du1 * dv2 - dv1 * du2;
        if (!(fabsf(det) > 1e-20f)) {
            continue; // no uv area: this triangle says nothing about the tangent
        }
        drift_vec3 dpdu = drift_vec3_scale(
            drift_vec3_sub(drift_vec3_scale(dp1, dv2), drift_vec3_scale(dp2, dv1)), 1.0f / det);
        drift_vec3 dpdv = drift_vec3_scale(
            drift_vec3_sub(drift_vec3_scale(dp2, du1), drift_vec3_scale(dp1, du2)), 1.0f / det);
        for (int c = 0; c < 3; ++c) {
            uint32_t vi = tri[c];
            drift_vec3 n = at3(mesh->normals, vi);
            drift_vec3 tc = drift_vec3_fma(dpdu, n, -drift_vec3_dot(n, dpdu));
            float len = drift_vec3_length(tc);
            if (!(len > 0.0f) || !isfinite(len)) {
                continue;
            }
            tc = drift_vec3_scale(tc, 1.0f / len);
            float w = corner_angle(v[c], v[(c + 1) % 3], v[(c + 2) % 3]);
            float hand = drift_vec3_dot(drift_vec3_cross(n, tc), dpdv) < 0.0f ? -1.0f : 1.0f;
            float *o = t + 4 * (size_t)vi;
            o[0] += w * tc.x;
            o[1] += w * tc.y;
            o[2] += w * tc.z;
            o[3] += w * hand;
        }
    }
    for (size_t i = 0; i < nv; ++i) {
        float *o = t + 4 * i;
        drift_vec3 n = at3(mesh->normals, (uint32_t)i);
        drift_vec3 s = drift_vec3_make(o[0], o[1], o[2]);
        s = drift_vec3_fma(s, n, -drift_vec3_dot(n, s));
        float len = drift_vec3_length(s);
        if (!(len > 1e-12f) || !isfinite(len)) {
            s = drift_frame_from_normal(drift_vec3_length(n) > 0.0f ? n : drift_vec3_make(0, 0, 1))
                    .x;
        } else {
            s = drift_vec3_scale(s, 1.0f / len);
        }
        o[0] = s.x;
        o[1] = s.y;
        o[2] = s.z;
        o[3] = o[3] < 0.0f ? -1.0f : 1.0f;
    }
    *out = t;
    return DRIFT_OK;
}
