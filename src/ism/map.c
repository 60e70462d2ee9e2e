// One imperfect shadow map: paraboloid point splatting with a z-test, and pull-push hole
// filling (Ritschel et al. 2008, §5.2.2; docs/ism.md, "Maps").
#include "drift/accel.h"
#include "ism/ism_internal.h"

#include <math.h>

void drift__ism_splat(float *depth, const drift__ism_splat_desc *desc, drift_vec3 origin,
                      const drift_frame *frame, const drift_vec3 *positions, uint32_t count)
{
    int32_t n = desc->n;
    for (int32_t i = 0; i < n * n; ++i) {
        depth[i] = INFINITY;
    }
    float half_n = 0.5f * (float)n;
    float k = desc->splat_scale * desc->point_radius * (float)n;
    for (uint32_t i = 0; i < count; ++i) {
        drift_vec3 d = drift_frame_to_local(frame, drift_vec3_sub(positions[i], origin));
        float r2 = drift_vec3_dot(d, d);
        if (d.z <= 0.0f || !(r2 > 0.0f)) {
            continue;
        }
        float r = sqrtf(r2);
        drift_vec3 v = drift_vec3_scale(d, 1.0f / r);
        drift_vec2 p = drift_paraboloid_project(v);
        // Side in texels: the disc the point stands for, seen from the VPL, through the
        // paraboloid's Jacobian 1 / (1 + v.z) (1/2 at the pole, 1 at the rim).
        float side = drift_clampf(k / (r * (1.0f + v.z)), 1.0f, 8.0f);
        float px = (p.x + 1.0f) * half_n, py = (p.y + 1.0f) * half_n;
        int32_t x0 = (int32_t)floorf(px - 0.5f * side + 0.5f);
        int32_t y0 = (int32_t)floorf(py - 0.5f * side + 0.5f);
        int32_t w = (int32_t)(side + 0.5f);
        int32_t x1 = x0 + w, y1 = y0 + w;
        x0 = x0 < 0 ? 0 : x0;
        y0 = y0 < 0 ? 0 : y0;
        x1 = x1 > n ? n : x1;
        y1 = y1 > n ? n : y1;
        for (int32_t y = y0; y < y1; ++y) {
            float *row = depth + (size_t)y * (size_t)n;
            for (int32_t x = x0; x < x1; ++x) {
                if (r < row[x]) {
                    row[x] = r;
                }
            }
        }
    }
}

// Texels of the unit disc only matter; outside it the map is never read, but pull-push treats
// the whole square alike (the corners stay empty or get filled, either is harmless).
uint32_t drift__ism_pull_push(float *depth, int32_t n, int32_t levels, float threshold,
                              float *scratch)
{
    // Level sizes and offsets into scratch (level 0 is `depth` itself).
    float *level[8], *members[8];
    int32_t size[8];
    level[0] = depth;
    members[0] = NULL;
    size[0] = n;
    int32_t count = 1;
    size_t offset = 0;
    while (count <= levels && count < 8 && size[count - 1] > 1) {
        size[count] = (size[count - 1] + 1) / 2;
        size_t texels = (size_t)size[count] * (size_t)size[count];
        level[count] = scratch + offset;
        members[count] = scratch + offset + texels;
        offset += 2 * texels;
        count++;
    }
    // Pull: a coarse texel averages the valid children within the threshold of the nearest.
    for (int32_t l = 1; l < count; ++l) {
        int32_t fs = size[l - 1], cs = size[l];
        float t = threshold * (float)(1 << (l - 1));
        const float *fine = level[l - 1];
        for (int32_t y = 0; y < cs; ++y) {
            for (int32_t x = 0; x < cs; ++x) {
                float c[4];
                int32_t m = 0;
                float nearest = INFINITY;
                for (int32_t dy = 0; dy < 2; ++dy) {
                    for (int32_t dx = 0; dx < 2; ++dx) {
                        int32_t fx = 2 * x + dx, fy = 2 * y + dy;
                        if (fx < fs && fy < fs && isfinite(fine[fy * fs + fx])) {
                            c[m] = fine[fy * fs + fx];
                            nearest = fminf(nearest, c[m]);
                            m++;
                        }
                    }
                }
                float sum = 0.0f;
                int32_t used = 0;
                for (int32_t i = 0; i < m; ++i) {
                    if (c[i] <= nearest + t) {
                        sum += c[i];
                        used++;
                    }
                }
                level[l][y * cs + x] = used ? sum / (float)used : INFINITY;
                members[l][y * cs + x] = (float)used;
            }
        }
    }
    // Push: a fine texel that is empty takes its parent's depth; one that lies more than the
    // threshold behind its parent does too when the parent's near cluster holds at least 3 of
    // its 4 children (a light leak through a near surface). Requiring the majority keeps an
    // occluder's silhouette from growing by the parent's size at every level.
    for (int32_t l = count - 1; l >= 1; --l) {
        int32_t fs = size[l - 1], cs = size[l];
        float t = threshold * (float)(1 << (l - 1));
        float *fine = level[l - 1];
        for (int32_t y = 0; y < fs; ++y) {
            for (int32_t x = 0; x < fs; ++x) {
                size_t up = (size_t)(y / 2) * (size_t)cs + (size_t)(x / 2);
                float parent = level[l][up];
                float *f = &fine[y * fs + x];
                if (isfinite(parent) &&
                    (!isfinite(*f) || (*f > parent + t && members[l][up] >= 3.0f))) {
                    *f = parent;
                }
            }
        }
    }
    uint32_t empty = 0;
    for (int32_t y = 0; y < n; ++y) {
        // The texel centres of this row inside the disc: |u| <= sqrt(1 - v^2).
        float v = 2.0f * ((float)y + 0.5f) / (float)n - 1.0f;
        float half = sqrtf(fmaxf(1.0f - v * v, 0.0f));
        for (int32_t x = 0; x < n; ++x) {
            float u = 2.0f * ((float)x + 0.5f) / (float)n - 1.0f;
            empty += fabsf(u) <= half && depth[y * n + x] == INFINITY;
        }
    }
    return empty;
}

void drift__ism_exact_map(float *depth, int32_t n, const drift_accel *accel, drift_vec3 origin,
                          const drift_frame *frame)
{
    for (int32_t y = 0; y < n; ++y) {
        for (int32_t x = 0; x < n; ++x) {
            drift_vec2 p = { 2.0f * ((float)x + 0.5f) / (float)n - 1.0f,
                             2.0f * ((float)y + 0.5f) / (float)n - 1.0f };
            float d = INFINITY;
            if (p.x * p.x + p.y * p.y <= 1.0f) {
                drift_vec3 dir = drift_frame_to_world(frame, drift_paraboloid_unproject(p));
                drift_ray ray = { origin, 0.0f, dir, INFINITY };
                drift_hit hit;
                d = drift_accel_intersect(accel, &ray, &hit) ? hit.t : INFINITY;
            }
            depth[y * n + x] = d;
        }
    }
}
