// One imperfect shadow map: paraboloid point splatting with a z-test, and pull-push hole
// filling (Ritschel et al. 2008, §5.2.2; docs/ism.md, "Maps").
#include "core/vectorise.h"
#include "drift/accel.h"
#include "ism/ism_internal.h"

#include <math.h>

// Points are splatted in blocks: first every point's square (corner, side, distance) in a
// loop without branches the compiler vectorises, then the squares are z-tested into the map.
#define SPLAT_BLOCK 256

// Splatting and pulling are also compiled for AVX2 where the CPU has it (DRIFT_AVX2_CLONES),
// as the gather (docs/decisions/0028-ism-vectorised-gather.md).
// Static: clang 14 emits no plain symbol for an external multi-versioned function (the
// fuzz build's link failed), so the clones stay inside this file behind drift__ism_splat.
DRIFT_AVX2_CLONES static void splat_points(float *depth, const drift__ism_splat_desc *desc,
                                           drift_vec3 origin, const drift_frame *frame,
                                           const drift_vec3 *positions, uint32_t count)
{
    int32_t n = desc->n;
    for (int32_t i = 0; i < n * n; ++i) {
        depth[i] = INFINITY;
    }
    float half_n = 0.5f * (float)n;
    float k = desc->splat_scale * desc->point_radius * (float)n;
    const drift_vec3 fx = frame->x, fy = frame->y, fz = frame->z;
    int32_t x0s[SPLAT_BLOCK], y0s[SPLAT_BLOCK], ws[SPLAT_BLOCK];
    float rs[SPLAT_BLOCK];
    for (uint32_t base = 0; base < count; base += SPLAT_BLOCK) {
        uint32_t m = count - base < SPLAT_BLOCK ? count - base : SPLAT_BLOCK;
        const drift_vec3 *pts = positions + base;
        for (uint32_t i = 0; i < m; ++i) {
            float ax = pts[i].x - origin.x, ay = pts[i].y - origin.y, az = pts[i].z - origin.z;
            float lx = ax * fx.x + ay * fx.y + az * fx.z;
            float ly = ax * fy.x + ay * fy.y + az * fy.z;
            float lz = ax * fz.x + ay * fz.y + az * fz.z;
            float r = sqrtf(ax * ax + ay * ay + az * az);
            // With v = a / r: v.xy / (1 + v.z) = a.xy / (r + a.z), and the side in texels
            // k / (r (1 + v.z)) = k / (r + a.z): the disc the point stands for, seen from the
            // VPL, through the paraboloid's Jacobian 1 / (1 + v.z) (1/2 at the pole, 1 at
            // the rim).
            bool front = lz > 0.0f && r > 0.0f;
            float s = 1.0f / (front ? r + lz : 1.0f);
            float side = k * s;
            side = side < 1.0f ? 1.0f : (side > 8.0f ? 8.0f : side);
            // Behind the VPL: a square of side 0 at the centre (no out-of-range conversions).
            float px = ((front ? lx * s : 0.0f) + 1.0f) * half_n;
            float py = ((front ? ly * s : 0.0f) + 1.0f) * half_n;
            // floor of values > -16 without floorf (SSE2 has no vector floor).
            x0s[i] = (int32_t)(px - 0.5f * side + 16.5f) - 16;
            y0s[i] = (int32_t)(py - 0.5f * side + 16.5f) - 16;
            ws[i] = front ? (int32_t)(side + 0.5f) : 0;
            rs[i] = r;
        }
        for (uint32_t i = 0; i < m; ++i) {
            int32_t x0 = x0s[i], y0 = y0s[i], w = ws[i];
            float r = rs[i];
            if (w == 1) {
                if ((uint32_t)x0 < (uint32_t)n && (uint32_t)y0 < (uint32_t)n) {
                    float *t = depth + (size_t)y0 * (size_t)n + (size_t)x0;
                    *t = r < *t ? r : *t;
                }
                continue;
            }
            int32_t x1 = x0 + w, y1 = y0 + w;
            x0 = x0 < 0 ? 0 : x0;
            y0 = y0 < 0 ? 0 : y0;
            x1 = x1 > n ? n : x1;
            y1 = y1 > n ? n : y1;
            for (int32_t y = y0; y < y1; ++y) {
                float *row = depth + (size_t)y * (size_t)n;
                for (int32_t x = x0; x < x1; ++x) {
                    row[x] = r < row[x] ? r : row[x];
                }
            }
        }
    }
}

void drift__ism_splat(float *depth, const drift__ism_splat_desc *desc, drift_vec3 origin,
                      const drift_frame *frame, const drift_vec3 *positions, uint32_t count)
{
    splat_points(depth, desc, origin, frame, positions, count);
}

// The texels [*lo, *hi) of row y whose centres lie inside the unit disc (|u| <= sqrt(1 - v^2)),
// the same test texel by texel as the map's lookup uses, found from the row's estimate.
static void disc_span(int32_t n, int32_t y, int32_t *lo, int32_t *hi)
{
    float v = 2.0f * ((float)y + 0.5f) / (float)n - 1.0f;
    float half = sqrtf(fmaxf(1.0f - v * v, 0.0f));
    int32_t a = (int32_t)((1.0f - half) * 0.5f * (float)n);
    a = a < 0 ? 0 : (a > n ? n : a);
    while (a > 0 && fabsf(2.0f * ((float)(a - 1) + 0.5f) / (float)n - 1.0f) <= half) {
        a--;
    }
    while (a < n && !(fabsf(2.0f * ((float)a + 0.5f) / (float)n - 1.0f) <= half)) {
        a++;
    }
    int32_t b = a;
    while (b < n && fabsf(2.0f * ((float)b + 0.5f) / (float)n - 1.0f) <= half) {
        b++;
    }
    *lo = a;
    *hi = b;
}

// One pull step: each coarse texel averages its valid children within t of the nearest one
// (an empty child is INFINITY), and `members` counts them. Children past an odd edge read as
// empty: row `inf_row` (fs floats of INFINITY) stands for the missing last row.
DRIFT_AVX2_CLONES static void pull_level(const float *fine, int32_t fs, float *coarse,
                                         float *members, int32_t cs, float t, const float *inf_row)
{
    int32_t pairs = fs / 2;
    for (int32_t y = 0; y < cs; ++y) {
        const float *r0 = fine + (size_t)(2 * y) * (size_t)fs;
        const float *r1 = 2 * y + 1 < fs ? r0 + fs : inf_row;
        float *out = coarse + (size_t)y * (size_t)cs, *used_out = members + (size_t)y * (size_t)cs;
        for (int32_t x = 0; x < cs; ++x) {
            bool full = x < pairs;
            float c0 = r0[2 * x], c1 = full ? r0[2 * x + 1] : INFINITY;
            float c2 = r1[2 * x], c3 = full ? r1[2 * x + 1] : INFINITY;
            float m01 = c0 < c1 ? c0 : c1, m23 = c2 < c3 ? c2 : c3;
            float limit = (m01 < m23 ? m01 : m23) + t;
            // INFINITY is never < INFINITY: an empty child is never used, even when all are.
            bool u0 = (c0 <= limit) & (c0 < INFINITY), u1 = (c1 <= limit) & (c1 < INFINITY);
            bool u2 = (c2 <= limit) & (c2 < INFINITY), u3 = (c3 <= limit) & (c3 < INFINITY);
            float sum = (u0 ? c0 : 0.0f) + (u1 ? c1 : 0.0f) + (u2 ? c2 : 0.0f) + (u3 ? c3 : 0.0f);
            int32_t used = (int32_t)u0 + (int32_t)u1 + (int32_t)u2 + (int32_t)u3;
            out[x] = used ? sum / (float)used : INFINITY;
            used_out[x] = (float)used;
        }
    }
}

// One push step: a fine texel that is empty takes its parent's depth; one that lies more than
// t behind its parent does too when the parent's near cluster holds at least 3 of its 4
// children (a light leak through a near surface). Requiring the majority keeps an occluder's
// silhouette from growing by the parent's size at every level.
static void push_level(float *fine, int32_t fs, const float *coarse, const float *members,
                       int32_t cs, float t)
{
    int32_t pairs = fs / 2;
    for (int32_t y = 0; y < fs; ++y) {
        const float *restrict parents = coarse + (size_t)(y / 2) * (size_t)cs;
        const float *restrict counts = members + (size_t)(y / 2) * (size_t)cs;
        float *restrict row = fine + (size_t)y * (size_t)fs;
        // Two fine texels a parent, without branches (the holes fall at random: branches on
        // them mispredicted) so that the loop vectorises.
        for (int32_t x = 0; x < pairs; ++x) {
            float parent = parents[x], f0 = row[2 * x], f1 = row[2 * x + 1];
            float behind = counts[x] >= 3.0f ? parent + t : INFINITY;
            bool valid = parent < INFINITY;
            row[2 * x] = valid & ((f0 == INFINITY) | (f0 > behind)) ? parent : f0;
            row[2 * x + 1] = valid & ((f1 == INFINITY) | (f1 > behind)) ? parent : f1;
        }
        if (fs > 2 * pairs) {
            float parent = parents[pairs], f = row[2 * pairs];
            float behind = counts[pairs] >= 3.0f ? parent + t : INFINITY;
            bool valid = parent < INFINITY;
            row[2 * pairs] = valid & ((f == INFINITY) | (f > behind)) ? parent : f;
        }
    }
}

// Texels of the unit disc only matter; outside it the map is never read, but pull-push treats
// the whole square alike (the corners stay empty or get filled, either is harmless).
uint32_t drift__ism_pull_push(float *depth, int32_t n, int32_t levels, float threshold,
                              float *scratch)
{
    // Level sizes and offsets into scratch (level 0 is `depth` itself), then a row of
    // INFINITY for odd sizes.
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
    float *inf_row = scratch + offset;
    if (count > 1) {
        for (int32_t i = 0; i < n; ++i) {
            inf_row[i] = INFINITY;
        }
    }
    for (int32_t l = 1; l < count; ++l) {
        pull_level(level[l - 1], size[l - 1], level[l], members[l], size[l],
                   threshold * (float)(1 << (l - 1)), inf_row);
    }
    for (int32_t l = count - 1; l >= 1; --l) {
        push_level(level[l - 1], size[l - 1], level[l], members[l], size[l],
                   threshold * (float)(1 << (l - 1)));
    }
    uint32_t empty = 0;
    for (int32_t y = 0; y < n; ++y) {
        int32_t lo, hi;
        disc_span(n, y, &lo, &hi);
        const float *row = depth + (size_t)y * (size_t)n;
        for (int32_t x = lo; x < hi; ++x) {
            empty += row[x] == INFINITY;
        }
    }
    return empty;
}

size_t drift__ism_map_floats(int32_t n, int32_t levels)
{
    size_t floats = (size_t)n * (size_t)n;
    for (int32_t l = 1, s = n; l <= levels; ++l) {
        s = (s + 1) / 2;
        floats += 2 * (size_t)s * (size_t)s;
    }
    return floats;
}

void drift__ism_pull(float *map, int32_t n, int32_t levels, float threshold)
{
    // A missing last row of an odd level reads as empty.
    float inf_row[1024];
    float *fine = map;
    for (int32_t l = 1, fs = n; l <= levels; ++l) {
        int32_t cs = (fs + 1) / 2;
        if (fs % 2) {
            for (int32_t i = 0; i < fs; ++i) {
                inf_row[i] = INFINITY;
            }
        }
        float *coarse = fine + (l == 1 ? (size_t)n * (size_t)n : 2 * (size_t)fs * (size_t)fs);
        pull_level(fine, fs, coarse, coarse + (size_t)cs * (size_t)cs, cs,
                   threshold * (float)(1 << (l - 1)), inf_row);
        fine = coarse;
        fs = cs;
    }
}

// The top level of a map's lazy pyramid and its side.
static const float *top_level(const float *map, int32_t n, int32_t levels, int32_t *side)
{
    const float *top = map + (size_t)n * (size_t)n;
    int32_t s = (n + 1) / 2;
    for (int32_t l = 2; l <= levels; ++l) {
        top += 2 * (size_t)s * (size_t)s;
        s = (s + 1) / 2;
    }
    *side = s;
    return top;
}

void drift__ism_disc_counts(int32_t n, int32_t levels, float *counts)
{
    int32_t s = n;
    for (int32_t l = 1; l <= levels; ++l) {
        s = (s + 1) / 2;
    }
    for (int32_t i = 0; i < s * s; ++i) {
        counts[i] = 0.0f;
    }
    for (int32_t y = 0; y < n; ++y) {
        int32_t lo, hi;
        disc_span(n, y, &lo, &hi);
        for (int32_t x = lo; x < hi; ++x) {
            counts[(size_t)(y >> levels) * (size_t)s + (size_t)(x >> levels)] += 1.0f;
        }
    }
}

uint32_t drift__ism_holes(const float *map, int32_t n, int32_t levels, const float *counts)
{
    if (levels <= 0) {
        uint32_t empty = 0;
        for (int32_t y = 0; y < n; ++y) {
            int32_t lo, hi;
            disc_span(n, y, &lo, &hi);
            for (int32_t x = lo; x < hi; ++x) {
                empty += map[(size_t)y * (size_t)n + (size_t)x] == INFINITY;
            }
        }
        return empty;
    }
    // A texel stays empty after the push exactly when its top-level ancestor is empty (an
    // empty coarse texel has only empty children, all the way down): the disc texels under
    // each empty top-level texel.
    int32_t s;
    const float *top = top_level(map, n, levels, &s);
    float empty = 0.0f;
    for (int32_t i = 0; i < s * s; ++i) {
        empty += top[i] == INFINITY ? counts[i] : 0.0f;
    }
    return (uint32_t)empty;
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
                drift_ray ray = { origin, 0.0f, dir, INFINITY, 0 };
                drift_hit hit;
                d = drift_accel_intersect(accel, &ray, &hit) ? hit.t : INFINITY;
            }
            depth[y * n + x] = d;
        }
    }
}
