// drift ism: the near-field compensation (short rays for the light of surfaces nearer than the
// VPLs' clamp).
#include "core/vectorise.h"
#include "ism/ism_object.h"

#include <math.h>
#include <string.h>

// --- NEAR-FIELD COMPENSATION ---
//
// The clamp d_min in the geometry term keeps a VPL next to a receiver from painting a spike, and
// takes away the light that nearby surfaces really send (corners, contact, a wall beside a sunlit
// floor). Written over directions, the clamped gather is
//   E_clamped(x) = integral of L_o(y(w)) cos(theta_x) min(1, d^2 / d_min^2) dw,
// so the part it misses is the same integral with max(0, 1 - d^2 / d_min^2): zero beyond d_min.
// A cosine ray at most d_min long estimates it as pi L_o(y) (1 - d^2 / d_min^2) (Kollig and
// Keller 2004's bias compensation, cut to one bounce). L_o(y) is read off the frame where the
// hit is the surface a pixel sees (its direct radiance plus the clamped indirect light just
// gathered; Novak et al. 2011 compensate in screen space alone); a hit the camera does not see
// adds nothing. One pixel in stride x stride shoots (a quarter by default: 1 ray a pixel cost
// 3x as much for 0.001-0.003 FLIP), a block's rays take stratified directions, each shooting
// pixel takes the mean of the 5 x 5 shooting pixels around it that pass the blur's tests, and
// the block average blurs those with the VPLs' subsets.

typedef struct near_field_job {
    drift_ism *ism;
    const drift_gbuffer *gb;
    drift_camera_frame camera;
    const drift_image *direct;
    float dmin;
    uint32_t seed;
    uint64_t rays[DRIFT_MAX_THREADS]; // per thread
} near_field_job;

// Shooting pixels a side, either way, that near_field_spread_rows averages: 2 spreads a block's
// 4 rays over 25 blocks' worth, 0.001-0.003 FLIP on the four frontier scenes for ~1-4 ms.
#define NEAR_FIELD_SPREAD 2

// L_o of hit point p, read off the frame: the pixel p projects to must see p itself (its depth
// within 2%, its normal facing the ray that found p). False where the camera does not see p.
static bool frame_radiance(const near_field_job *job, drift_vec3 p, drift_vec3 dir, drift_vec3 *out)
{
    const drift_gbuffer *gb = job->gb;
    drift_vec2 film;
    if (!drift_camera_frame_project(&job->camera, p, &film) || !(film.x >= 0.0f) ||
        !(film.y >= 0.0f) || film.x >= (float)gb->width || film.y >= (float)gb->height) {
        return false;
    }
    int32_t qx = (int32_t)film.x, qy = (int32_t)film.y;
    if (drift_image_pixel(&gb->material_id, qx, qy)[0] < 0.0f) {
        return false;
    }
    float seen = drift_image_pixel(&gb->depth, qx, qy)[0];
    float depth = drift_vec3_dot(drift_vec3_sub(p, job->camera.camera.position), job->camera.w);
    const float *n = drift_image_pixel(&gb->normal, qx, qy);
    if (!(fabsf(seen - depth) < 0.02f * depth) ||
        n[0] * dir.x + n[1] * dir.y + n[2] * dir.z >= 0.0f) {
        return false;
    }
    *out = drift_image_get3(job->direct, qx, qy);
    if (job->ism->params.max_depth > 2) {
        // Paths of max_depth 2 bounce once: p sends its direct light alone. Deeper ones add the
        // indirect light gathered at p (all of its bounces: one more than max_depth allows).
        drift_vec3 kd = drift_image_get3(&gb->albedo, qx, qy);
        drift_vec3 e = drift__ism_block_average(job->ism, gb, &job->ism->irradiance, qx, qy);
        *out = drift_vec3_fma(*out, drift_vec3_mul(kd, e), DRIFT_INV_PI);
    }
    return true;
}

static void near_field_rows(size_t begin, size_t end, int thread, void *user)
{
    near_field_job *job = user;
    drift_ism *ism = job->ism;
    const drift_gbuffer *gb = job->gb;
    int32_t b = ism->params.block_size;
    // One ray per stride x stride pixels, weighed by stride^2: the block's B^2 / stride^2 rays
    // stratify its hemisphere.
    int32_t stride = ism->params.near_field_stride;
    int32_t per_side = b / stride;
    uint32_t directions = (uint32_t)(per_side * per_side);
    float weight = DRIFT_PI * (float)(stride * stride);
    for (size_t row = begin; row < end; ++row) {
        int32_t y = (int32_t)row, by = y / b, ky = y % b, bx = 0, kx = 0;
        for (int32_t x = 0; x < gb->width; ++x, kx = kx + 1 < b ? kx + 1 : (++bx, 0)) {
            drift_vec3 e = drift_vec3_splat(0.0f);
            const drift_surface *s = &gb->surfaces[(size_t)y * (size_t)gb->width + (size_t)x];
            if (s->material == DRIFT_INVALID_INDEX || kx % stride || ky % stride) {
                drift_image_set3(&ism->near_field, x, y, e);
                continue;
            }
            // Direction k of the block's set, the set shifted block by block.
            uint32_t k = (uint32_t)((ky / stride) * per_side + kx / stride);
            uint32_t h = drift_hash_combine(job->seed, (uint32_t)by * 65536u + (uint32_t)bx);
            drift_vec2 shift =
                drift_vec2_make((float)(h & 0xffffu) * 0x1p-16f, (float)(h >> 16) * 0x1p-16f);
            drift_frame frame = drift_frame_from_normal(s->ns);
            drift_vec3 dir = drift_frame_to_world(
                &frame,
                drift_sample_cosine_hemisphere(drift_hammersley_shifted(k, directions, shift)));
            drift_hit hit;
            drift_vec3 lo;
            if (drift_vec3_dot(dir, s->ng) > 0.0f) {
                drift_ray ray = { .origin = drift_offset_origin(s->position, s->ng, dir),
                                  .dir = dir,
                                  .tmin = 0.0f,
                                  .tmax = job->dmin };
                ++job->rays[thread];
                // Emitters are the direct light's; only a reflecting surface is near-field light.
                if (drift_accel_intersect(ism->accel, &ray, &hit) &&
                    hit.mesh != DRIFT_INVALID_INDEX && hit.light == DRIFT_INVALID_INDEX &&
                    frame_radiance(job, drift_vec3_fma(ray.origin, dir, hit.t), dir, &lo)) {
                    float falloff = 1.0f - (hit.t * hit.t) / (job->dmin * job->dmin);
                    e = drift_vec3_scale(lo, weight * fmaxf(falloff, 0.0f));
                }
            }
            drift_image_set3(&ism->near_field, x, y, e);
        }
    }
}

// The near field's few rays a block, spread wider than the block: at each pixel that shot, the
// mean of the (2 r + 1)^2 shooting pixels around it that pass the blur's tests (the block
// average then blurs these means as it blurs the VPLs' subsets).
static void near_field_spread_rows(size_t begin, size_t end, int thread, void *user)
{
    (void)thread;
    near_field_job *job = user;
    drift_ism *ism = job->ism;
    const drift_gbuffer *gb = job->gb;
    int32_t stride = ism->params.near_field_stride, r = NEAR_FIELD_SPREAD;
    float blur_normal = ism->params.blur_normal, blur_plane = ism->params.blur_plane;
    for (size_t row = begin; row < end; ++row) {
        int32_t y = (int32_t)row;
        for (int32_t x = 0; x < gb->width; ++x) {
            drift_vec3 sum = drift_vec3_splat(0.0f);
            float weight = 0.0f;
            if (y % stride == 0 && x % stride == 0 &&
                drift_image_pixel(&gb->material_id, x, y)[0] >= 0.0f) {
                const float *c = drift_image_pixel(&gb->position, x, y);
                const float *cn = drift_image_pixel(&gb->normal, x, y);
                for (int32_t v = y - r * stride; v <= y + r * stride; v += stride) {
                    for (int32_t u = x - r * stride; u <= x + r * stride; u += stride) {
                        if (u < 0 || v < 0 || u >= gb->width || v >= gb->height ||
                            drift_image_pixel(&gb->material_id, u, v)[0] < 0.0f) {
                            continue;
                        }
                        const float *q = drift_image_pixel(&gb->position, u, v);
                        const float *qn = drift_image_pixel(&gb->normal, u, v);
                        float d =
                            cn[0] * (q[0] - c[0]) + cn[1] * (q[1] - c[1]) + cn[2] * (q[2] - c[2]);
                        float cosn = cn[0] * qn[0] + cn[1] * qn[1] + cn[2] * qn[2];
                        if (cosn < blur_normal || fabsf(d) > blur_plane) {
                            continue;
                        }
                        sum = drift_vec3_add(sum, drift_image_get3(&ism->near_field, u, v));
                        weight += 1.0f;
                    }
                }
            }
            drift_image_set3(&ism->near_spread, x, y,
                             weight > 0.0f ? drift_vec3_scale(sum, 1.0f / weight) : sum);
        }
    }
}

void drift__ism_add_near_field(drift_ism *ism, const drift_gbuffer *gb, const drift_camera *camera,
                               const drift_image *direct, drift_ism_stats *st)
{
    near_field_job job = { .ism = ism,
                           .gb = gb,
                           .camera = drift_camera_frame_make(camera, gb->width, gb->height),
                           .direct = direct,
                           .dmin = ism->params.clamp_distance,
                           .seed = drift_hash_combine(ism->params.seed, 0x4e454152u) };
    drift_parallel_for(ism->ctx, (size_t)gb->height, 4, near_field_rows, &job);
    drift_parallel_for(ism->ctx, (size_t)gb->height, 4, near_field_spread_rows, &job);
    for (int i = 0; i < DRIFT_MAX_THREADS; ++i) {
        st->near_field_rays += job.rays[i];
    }
}
