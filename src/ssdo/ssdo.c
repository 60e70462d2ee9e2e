// SSAO, GTAO and SSDO over one G-buffer (docs/ssdo.md has the equations as implemented).
//
// Passes, each a drift_parallel_for over rows:
//   1. occlusion: per pixel, SSAO and SSDO place the N points of the pixel's sample set
//      (M = 4x4 sets tiled over the image) in the normal's frame, project each into the
//      G-buffer and test it against the stored depth; SSAO keeps the cosine-weighted open
//      fraction, SSDO sums the cone-filtered environment along every open direction. GTAO
//      searches the horizon on both sides of `gtao_slices` slices and integrates the cosine-
//      weighted visibility and the bent normal in closed form (Jimenez et al. 2016).
//   2. bounce (SSDO with bounce): the same samples again; every occluder's pixel is a sender
//      patch whose radiance is pass 1's direct light there (times its albedo).
//   3. blur and compose: the geometry-aware 4x4 blur over the interleaving block, then the
//      albedo and (SSAO, GTAO) the one irradiance lookup.
// Raw per-pixel values live in one interleaved scratch array of RAW_CHANNELS floats.
#include "ssdo_internal.h"

#include <string.h>

#define MAX_SAMPLES 1024
#define MAX_SLICES  64
#define SETS        (DRIFT_SSDO_BLOCK * DRIFT_SSDO_BLOCK)
// Raw channels: direct (3), bounce (3), visibility (1), bent normal (3).
#define RAW_DIRECT   0
#define RAW_BOUNCE   3
#define RAW_VIS      6
#define RAW_BENT     7
#define RAW_CHANNELS 10

const char *drift_ssdo_method_name(drift_ssdo_method technique)
{
    static const char *const names[DRIFT_SSDO_METHOD_COUNT] = { "ssao", "gtao", "ssdo" };
    return (unsigned)technique < DRIFT_SSDO_METHOD_COUNT ? names[technique] : NULL;
}

int drift_ssdo_method_parse(const char *name)
{
    for (int t = 0; name && t < DRIFT_SSDO_METHOD_COUNT; ++t) {
        if (strcmp(name, drift_ssdo_method_name((drift_ssdo_method)t)) == 0) {
            return t;
        }
    }
    return -1;
}

drift_ssdo_params drift_ssdo_params_resolve(const drift_ssdo_params *params,
                                            const drift_scene *scene)
{
    drift_ssdo_params p = params ? *params : (drift_ssdo_params){ 0 };
    p.samples = p.samples ? p.samples : 16;
    if (p.radius == 0.0f && scene && !drift_bounds3_is_empty(scene->bounds)) {
        p.radius = 0.05f * drift_scene_extent(scene);
    }
    p.bounce_area = p.bounce_area != 0.0f ? p.bounce_area : 1.0f;
    p.bounce_clamp = p.bounce_clamp != 0.0f ? p.bounce_clamp : 0.5f;
    p.bias = p.bias != 0.0f ? p.bias : 0.01f;
    p.blur_normal = p.blur_normal != 0.0f ? p.blur_normal : 0.8f;
    p.blur_plane = p.blur_plane != 0.0f ? p.blur_plane : 0.1f;
    p.gtao_slices = p.gtao_slices ? p.gtao_slices : 2;
    p.steps = p.steps ? p.steps : 1;
    return p;
}

drift_result drift_ssdo_output_create(drift_context *ctx, int32_t width, int32_t height,
                                      drift_ssdo_output *out)
{
    if (!out) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    memset(out, 0, sizeof(*out));
    drift_result r = drift_image_create(ctx, width, height, 3, &out->radiance);
    r = r ? r : drift_image_create(ctx, width, height, 3, &out->direct);
    r = r ? r : drift_image_create(ctx, width, height, 3, &out->bounce);
    r = r ? r : drift_image_create(ctx, width, height, 1, &out->visibility);
    r = r ? r : drift_image_create(ctx, width, height, 3, &out->bent_normal);
    if (r != DRIFT_OK) {
        drift_ssdo_output_destroy(ctx, out);
    }
    return r;
}

void drift_ssdo_output_destroy(drift_context *ctx, drift_ssdo_output *out)
{
    if (!out) {
        return;
    }
    drift_image_destroy(ctx, &out->radiance);
    drift_image_destroy(ctx, &out->direct);
    drift_image_destroy(ctx, &out->bounce);
    drift_image_destroy(ctx, &out->visibility);
    drift_image_destroy(ctx, &out->bent_normal);
}

// --- SHARED STATE ---

typedef struct ssdo_job {
    const drift_ssdo_env *env;
    const drift_gbuffer *gb;
    const drift_image *sender_extra;
    const drift_image *back_depth;
    drift_ssdo_params p;
    drift_camera_frame cam;
    int32_t view_count; // additional cameras (thesis §4.3.3)
    drift_camera_frame view_cam[DRIFT_SSDO_MAX_VIEWS];
    const drift_image *view_depth[DRIFT_SSDO_MAX_VIEWS];
    int32_t width, height;
    float focal_px;            // pixels per unit of tan: height / (2 tan(fov / 2))
    drift_vec3 *set_dir;       // SETS x N unit directions in the local frame (z = normal)
    float *set_len;            // SETS x N step lengths lambda in [0, r_max]
    float set_jitter[SETS][2]; // GTAO: slice rotation and step jitter per set
    float *raw;                // width*height*RAW_CHANNELS, pass 1 and 2
    float *blurred;            // the same after the blur
} ssdo_job;

static bool pixel_valid(const ssdo_job *j, int32_t x, int32_t y)
{
    return drift_image_pixel(&j->gb->depth, x, y)[0] > 0.0f &&
           drift_image_pixel(&j->gb->material_id, x, y)[0] >= 0.0f;
}

static int set_index(int32_t x, int32_t y)
{
    return (x % DRIFT_SSDO_BLOCK) + DRIFT_SSDO_BLOCK * (y % DRIFT_SSDO_BLOCK);
}

// The sets: set m holds Sobol points m N .. m N + N - 1 of one Owen-scrambled sequence, so for
// N a power of two each set is a (0, log2 N, 2)-net and the 16 sets together are one net of
// 16 N points: the blur over a block sees a well-stratified 16 N-point hemisphere.
static void make_sets(ssdo_job *j)
{
    int32_t n = j->p.samples;
    uint32_t seed = j->p.seed ^ DRIFT_SSDO_STREAM;
    for (int m = 0; m < SETS; ++m) {
        for (int32_t i = 0; i < n; ++i) {
            drift_sampler s = drift_sampler_make(seed, 0, (uint32_t)(m * n + i));
            drift_vec2 u = drift_sampler_next2(&s);
            float z = u.x, r = sqrtf(fmaxf(0.0f, 1.0f - z * z)), phi = 2.0f * SSDO_PI * u.y;
            j->set_dir[m * n + i] = drift_vec3_make(r * cosf(phi), r * sinf(phi), z);
            j->set_len[m * n + i] = drift_sampler_next1(&s) * j->p.radius;
        }
        drift_sampler s = drift_sampler_make(seed, 1, (uint32_t)m);
        drift_vec2 u = drift_sampler_next2(&s);
        j->set_jitter[m][0] = u.x;
        j->set_jitter[m][1] = u.y;
    }
}

// --- THE OCCLUDER TEST ---

// Where point s falls in one view: false when it is behind the camera or outside the image;
// else its pixel, its view depth *zs and the depth stored there *zq.
static bool view_lookup(const drift_camera_frame *cam, const drift_image *depth, drift_vec3 s,
                        float *zs, float *zq, int32_t *qx, int32_t *qy)
{
    drift_vec3 d = drift_vec3_sub(s, cam->camera.position);
    *zs = drift_vec3_dot(d, cam->w);
    if (!(*zs > 0.0f)) {
        return false;
    }
    float sx = drift_vec3_dot(d, cam->u) / (*zs * cam->tan_half * cam->aspect);
    float sy = drift_vec3_dot(d, cam->v) / (*zs * cam->tan_half);
    float fx = 0.5f * (sx + 1.0f) * (float)cam->width, fy = 0.5f * (1.0f - sy) * (float)cam->height;
    if (!(fx >= 0.0f && fy >= 0.0f && fx < (float)cam->width && fy < (float)cam->height)) {
        return false;
    }
    *qx = (int32_t)fx;
    *qy = (int32_t)fy;
    *zq = drift_image_pixel(depth, *qx, *qy)[0];
    return true;
}

// How much the point s, a sample of the pixel at p, counts as an occluder: 0 when the depth
// buffer at its pixel lies behind it (or it falls on a miss, or with two layers behind the
// second), else 1, faded out by 1 - smoothstep(0.75 r, r, |Q - P|) unless the fade is off. A
// sample outside the image is open, unless additional cameras see it: then it is an occluder
// when every camera whose image holds it has it behind a surface by `margin` (any one in
// front proves free space), with Q on the first one's ray. `margin` is the depth margin in scene
// units. *out_x, *out_y get the viewer's pixel of Q (-1 when an additional camera found it).
static float occluder(const ssdo_job *j, drift_vec3 p, drift_vec3 s, float margin, int32_t *out_x,
                      int32_t *out_y)
{
    float zs, zq;
    int32_t qx, qy;
    drift_vec3 q = p;
    *out_x = *out_y = -1;
    if (view_lookup(&j->cam, &j->gb->depth, s, &zs, &zq, &qx, &qy)) {
        *out_x = qx;
        *out_y = qy;
        if (!(zq > 0.0f) || !(zq < zs - margin)) {
            return 0.0f;
        }
        if (j->back_depth) {
            // Two layers: behind the solid's back face is open again (fixes "sample A").
            float zb = drift_image_pixel(j->back_depth, qx, qy)[0];
            if (zb > 0.0f && zs > zb) {
                return 0.0f;
            }
        }
        if (j->p.no_fade) {
            return 1.0f;
        }
        q = drift_image_get3(&j->gb->position, qx, qy);
    } else {
        bool seen = false;
        for (int32_t k = 0; k < j->view_count; ++k) {
            const drift_camera_frame *cam = &j->view_cam[k];
            float zk, zqk;
            int32_t vx, vy;
            if (!view_lookup(cam, j->view_depth[k], s, &zk, &zqk, &vx, &vy)) {
                continue;
            }
            if (!(zqk > 0.0f) || !(zqk < zk - margin)) {
                return 0.0f; // this camera sees free space there
            }
            if (!seen) {
                drift_vec3 eye = cam->camera.position;
                q = drift_vec3_fma(eye, drift_vec3_sub(s, eye), zqk / zk);
            }
            seen = true;
        }
        if (!seen) {
            return 0.0f;
        }
        if (j->p.no_fade) {
            return 1.0f;
        }
    }
    float dist = drift_vec3_length(drift_vec3_sub(q, p));
    return 1.0f - ssdo_smoothstep(0.75f * j->p.radius, j->p.radius, dist);
}

// --- PASS 1: SSAO AND SSDO ---

static void occlusion_pixel(const ssdo_job *j, int32_t x, int32_t y, float *raw)
{
    drift_vec3 p = drift_image_get3(&j->gb->position, x, y);
    drift_vec3 n = drift_image_get3(&j->gb->normal, x, y);
    drift_frame frame = drift_frame_from_normal(n);
    int32_t count = j->p.samples;
    const drift_vec3 *dirs = j->set_dir + set_index(x, y) * count;
    const float *lens = j->set_len + set_index(x, y) * count;
    bool directional = j->p.method == DRIFT_SSDO_METHOD_SSDO;
    float margin = j->p.bias * j->p.radius;
    int32_t steps = j->p.steps;
    drift_vec3 direct = drift_vec3_splat(0.0f), bent = drift_vec3_splat(0.0f);
    drift_vec3 unoccluded = drift_vec3_splat(0.0f);
    float open = 0.0f, total = 0.0f;
    for (int32_t i = 0; i < count; ++i) {
        drift_vec3 w = drift_frame_to_world(&frame, dirs[i]);
        int32_t qx, qy;
        // steps = 1: the thesis's point at lambda_i. More: a march to r_max through the points
        // (k + lambda_i / r) r / steps, blocked by the strongest occluder among them.
        float occ = 0.0f;
        for (int32_t k = 0; k < steps && occ < 1.0f; ++k) {
            float t = ((float)k * j->p.radius + lens[i]) / (float)steps;
            occ = fmaxf(occ, occluder(j, p, drift_vec3_fma(p, w, t), margin, &qx, &qy));
        }
        float v = 1.0f - occ;
        float c = dirs[i].z;
        open += v * c;
        total += c;
        bent = drift_vec3_fma(bent, w, v * c);
        if (directional) {
            // (rho / pi) L V cos (2 pi / N), rho applied after the blur; `unoccluded` is the
            // same sum with V = 1, for the ratio estimator.
            drift_vec3 l = drift_ssdo_env_radiance(j->env, w, count);
            direct = drift_vec3_fma(direct, l, v * c * 2.0f / (float)count);
            unoccluded = drift_vec3_fma(unoccluded, l, c * 2.0f / (float)count);
        }
    }
    if (directional && !j->p.plain_sum) {
        // Ratio estimator: the exact pre-filtered irradiance times the share of it, per colour
        // channel, that the open samples carry. Unbiased where nothing occludes (the thesis's
        // sum has the fixed sets' quadrature error there, the same at every pixel of a plane),
        // and as directional as the sum where something does.
        drift_vec3 e = drift_ssdo_env_irradiance(j->env, n);
        float a = total > 0.0f ? open / total : 1.0f;
        direct = drift_vec3_make(unoccluded.x > 0.0f ? e.x * direct.x / unoccluded.x : e.x * a,
                                 unoccluded.y > 0.0f ? e.y * direct.y / unoccluded.y : e.y * a,
                                 unoccluded.z > 0.0f ? e.z * direct.z / unoccluded.z : e.z * a);
    }
    memcpy(raw + RAW_DIRECT, &direct, sizeof(float) * 3);
    raw[RAW_VIS] = total > 0.0f ? open / total : 1.0f;
    memcpy(raw + RAW_BENT, &bent, sizeof(float) * 3);
}

// --- PASS 1: GTAO ---

// The surface point seen through film point (fx, fy) inside pixel (qx, qy): the camera ray
// there met with the tangent plane of the pixel's stored point. Point-sampling the pixel centre
// instead (XeGTAO) puts near samples up to half a pixel off the slice, which on a V-groove
// lowers the AO by 3% (30 degree walls) to 15% (60 degrees); docs/ssdo.md.
static drift_vec3 sample_position(const ssdo_job *j, int32_t qx, int32_t qy, float fx, float fy)
{
    drift_vec3 q = drift_image_get3(&j->gb->position, qx, qy);
    drift_vec3 nq = drift_image_get3(&j->gb->normal, qx, qy);
    float sx = (2.0f * fx / (float)j->width - 1.0f) * j->cam.tan_half * j->cam.aspect;
    float sy = (1.0f - 2.0f * fy / (float)j->height) * j->cam.tan_half;
    drift_vec3 dir = drift_vec3_add(
        j->cam.w, drift_vec3_add(drift_vec3_scale(j->cam.u, sx), drift_vec3_scale(j->cam.v, sy)));
    float denom = drift_vec3_dot(nq, dir);
    if (!(fabsf(denom) > 0.05f * drift_vec3_length(dir))) {
        return q; // grazing: keep the stored point
    }
    float t = drift_vec3_dot(nq, drift_vec3_sub(q, j->cam.camera.position)) / denom;
    return t > 0.0f ? drift_vec3_fma(j->cam.camera.position, dir, t) : q;
}

// XeGTAO's XeGTAO_FastACos (Lagarde's fit), as the real-time baseline uses it: absolute
// error below 0.009 rad over [-1, 1].
static float fast_acos(float x)
{
    float a = fabsf(x);
    float r = (-0.156583f * a + 0.5f * SSDO_PI) * sqrtf(1.0f - a);
    return x >= 0.0f ? r : SSDO_PI - r;
}

// The cosine-weighted visibility of one side of a slice between the normal's angle n and
// the horizon angle h (Jimenez et al. 2016, eq. 7 inner integral).
// One horizon's share of the slice integrals, from sin and cos of h and of n by the angle-sum
// identities (five trigonometric calls a slice instead of sixteen): the visibility arc
// (eq. 7's inner integral) and XeGTAO's bent-normal terms t0 (along the slice) and t1
// (along V).
typedef struct gtao_terms {
    float arc, t0, t1;
} gtao_terms;

static gtao_terms gtao_side(float h, float cos_n, float sin_n)
{
    float sh = sinf(h), ch = cosf(h);
    float s2 = 2.0f * sh * ch, c2 = ch * ch - sh * sh;
    float s3 = sh * (3.0f - 4.0f * sh * sh), c3 = ch * (4.0f * ch * ch - 3.0f);
    float cos_2h_n = c2 * cos_n + s2 * sin_n;
    float sin_h_n = sh * cos_n - ch * sin_n, sin_hpn = sh * cos_n + ch * sin_n;
    float cos_hpn = ch * cos_n - sh * sin_n;
    float sin_3h_n = s3 * cos_n - c3 * sin_n, cos_3h_n = c3 * cos_n + s3 * sin_n;
    return (gtao_terms){ .arc = 0.25f * (cos_n + 2.0f * h * sin_n - cos_2h_n),
                         .t0 = 6.0f * sin_h_n - sin_3h_n - 3.0f * sin_hpn,
                         .t1 = -cos_3h_n - 3.0f * cos_hpn };
}

static void gtao_pixel(const ssdo_job *j, int32_t x, int32_t y, float *raw)
{
    drift_vec3 p = drift_image_get3(&j->gb->position, x, y);
    drift_vec3 nrm = drift_image_get3(&j->gb->normal, x, y);
    drift_vec3 view = drift_vec3_normalize(drift_vec3_sub(j->cam.camera.position, p));
    float z = drift_image_pixel(&j->gb->depth, x, y)[0];
    float r = j->p.radius;
    float screen_radius = r * j->focal_px / z; // pixels
    int32_t slices = j->p.gtao_slices;
    int32_t steps = j->p.samples / (2 * slices);
    steps = steps > 0 ? steps : 1;
    const float *jitter = j->set_jitter[set_index(x, y)];
    float falloff_range = 0.615f * r; // XeGTAO's default falloff: the last 61.5% of r
    float vis = 0.0f;
    drift_vec3 bent = drift_vec3_splat(0.0f);
    float cx = (float)x + 0.5f, cy = (float)y + 0.5f;
    for (int32_t k = 0; k < slices; ++k) {
        float phi = ((float)k + jitter[0]) * SSDO_PI / (float)slices;
        float dx = cosf(phi), dy = sinf(phi); // image direction, y down
        drift_vec3 dir =
            drift_vec3_sub(drift_vec3_scale(j->cam.u, dx), drift_vec3_scale(j->cam.v, dy));
        drift_vec3 ortho = drift_vec3_fma(dir, view, -drift_vec3_dot(dir, view));
        ortho = drift_vec3_normalize(ortho);
        drift_vec3 axis = drift_vec3_normalize(drift_vec3_cross(ortho, view));
        drift_vec3 proj = drift_vec3_fma(nrm, axis, -drift_vec3_dot(nrm, axis));
        float proj_len = drift_vec3_length(proj);
        if (!(proj_len > 1e-6f)) {
            continue;
        }
        float cos_n = drift_clampf(drift_vec3_dot(proj, view) / proj_len, -1.0f, 1.0f);
        float n = copysignf(fast_acos(cos_n), drift_vec3_dot(ortho, proj));
        float sin_n = sinf(n);
        // Horizon cosines on the +dir side (0) and the -dir side (1), starting at the tangent
        // plane: the angles n + pi/2 and n - pi/2 from the view vector.
        float low[2] = { cosf(n + 0.5f * SSDO_PI), cosf(n - 0.5f * SSDO_PI) };
        float hc[2] = { low[0], low[1] };
        for (int32_t s = 0; s < steps; ++s) {
            // XeGTAO's distribution: power 2, never nearer than 1.3 pixels.
            float t = ((float)s + jitter[1]) / (float)steps;
            float offset = t * t * screen_radius + 1.3f;
            for (int side = 0; side < 2; ++side) {
                float sign = side == 0 ? 1.0f : -1.0f;
                float fx = cx + sign * offset * dx, fy = cy + sign * offset * dy;
                if (!(fx >= 0.0f && fy >= 0.0f && fx < (float)j->width && fy < (float)j->height)) {
                    continue;
                }
                int32_t qx = (int32_t)fx, qy = (int32_t)fy;
                if (!(drift_image_pixel(&j->gb->depth, qx, qy)[0] > 0.0f)) {
                    continue;
                }
                drift_vec3 delta = drift_vec3_sub(sample_position(j, qx, qy, fx, fy), p);
                float dist = drift_vec3_length(delta);
                if (!(dist > 0.0f)) {
                    continue;
                }
                float shc = drift_vec3_dot(delta, view) / dist;
                float weight = j->p.no_fade ? (dist < r ? 1.0f : 0.0f)
                                            : drift_clampf((r - dist) / falloff_range, 0.0f, 1.0f);
                shc = low[side] + (shc - low[side]) * weight;
                if (shc > hc[side]) {
                    hc[side] = shc;
                } else if (j->p.gtao_thickness > 0.0f) {
                    hc[side] += (shc - hc[side]) * j->p.gtao_thickness;
                }
            }
        }
        float h0 = -fast_acos(drift_clampf(hc[1], -1.0f, 1.0f));
        float h1 = fast_acos(drift_clampf(hc[0], -1.0f, 1.0f));
        h0 = n + fmaxf(h0 - n, -0.5f * SSDO_PI);
        h1 = n + fminf(h1 - n, 0.5f * SSDO_PI);
        gtao_terms a = gtao_side(h0, cos_n, sin_n), b = gtao_side(h1, cos_n, sin_n);
        vis += proj_len * (a.arc + b.arc);
        // The slice's cosine-weighted mean open direction (XeGTAO's bent-normal integral).
        float t0 = (a.t0 + b.t0 + 16.0f * sin_n) / 12.0f;
        float t1 = (a.t1 + b.t1 + 8.0f * cos_n) / 12.0f;
        bent = drift_vec3_add(bent, drift_vec3_scale(drift_vec3_add(drift_vec3_scale(ortho, t0),
                                                                    drift_vec3_scale(view, t1)),
                                                     proj_len));
    }
    memset(raw, 0, sizeof(float) * RAW_CHANNELS);
    raw[RAW_VIS] = drift_clampf(vis / (float)slices, 0.0f, 1.0f);
    memcpy(raw + RAW_BENT, &bent, sizeof(float) * 3);
}

static void occlusion_rows(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    const ssdo_job *j = user;
    for (int32_t y = (int32_t)begin; y < (int32_t)end; ++y) {
        for (int32_t x = 0; x < j->width; ++x) {
            float *raw = j->raw + ((size_t)y * (size_t)j->width + (size_t)x) * RAW_CHANNELS;
            if (!pixel_valid(j, x, y)) {
                memset(raw, 0, sizeof(float) * RAW_CHANNELS);
            } else if (j->p.method == DRIFT_SSDO_METHOD_GTAO) {
                gtao_pixel(j, x, y, raw);
            } else {
                occlusion_pixel(j, x, y, raw);
            }
        }
    }
}

// --- PASS 2: THE BOUNCE ---

static void bounce_pixel(const ssdo_job *j, int32_t x, int32_t y, float *raw)
{
    drift_vec3 p = drift_image_get3(&j->gb->position, x, y);
    drift_vec3 n = drift_image_get3(&j->gb->normal, x, y);
    drift_frame frame = drift_frame_from_normal(n);
    int32_t count = j->p.samples;
    const drift_vec3 *dirs = j->set_dir + set_index(x, y) * count;
    const float *lens = j->set_len + set_index(x, y) * count;
    float r = j->p.radius;
    float area = j->p.bounce_area * SSDO_PI * r * r / (float)count; // A_s
    float dmin = j->p.bounce_clamp * r;
    drift_vec3 sum = drift_vec3_splat(0.0f);
    for (int32_t i = 0; i < count; ++i) {
        drift_vec3 s = drift_vec3_fma(p, drift_frame_to_world(&frame, dirs[i]), lens[i]);
        int32_t qx, qy;
        float occ = occluder(j, p, s, j->p.bias * r, &qx, &qy);
        if (!(occ > 0.0f) || qx < 0 || !pixel_valid(j, qx, qy)) {
            continue; // open, or found by an additional camera only: no sender pixel
        }
        drift_vec3 q = drift_image_get3(&j->gb->position, qx, qy);
        drift_vec3 nq = drift_image_get3(&j->gb->normal, qx, qy);
        drift_vec3 to_receiver = drift_vec3_sub(p, q);
        float d = drift_vec3_length(to_receiver);
        if (!(d > 0.0f)) {
            continue;
        }
        float cos_s = drift_vec3_dot(nq, to_receiver) / d;
        float cos_r = -drift_vec3_dot(n, to_receiver) / d;
        if (!(cos_s > 0.0f) || !(cos_r > 0.0f)) {
            continue; // back-facing sender, or sender below the receiver's plane
        }
        // The sender's radiance: pass 1's direct light there times its albedo, plus any
        // other direct light the caller gives.
        const float *qraw = j->raw + ((size_t)qy * (size_t)j->width + (size_t)qx) * RAW_CHANNELS;
        drift_vec3 ls = drift_vec3_mul(
            drift_image_get3(&j->gb->albedo, qx, qy),
            drift_vec3_make(qraw[RAW_DIRECT], qraw[RAW_DIRECT + 1], qraw[RAW_DIRECT + 2]));
        if (j->sender_extra) {
            ls = drift_vec3_add(ls, drift_image_get3(j->sender_extra, qx, qy));
        }
        float dd = fmaxf(d, dmin);
        sum = drift_vec3_fma(sum, ls, occ * area * cos_s * cos_r / (SSDO_PI * dd * dd));
    }
    memcpy(raw + RAW_BOUNCE, &sum, sizeof(float) * 3);
}

static void bounce_rows(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    const ssdo_job *j = user;
    for (int32_t y = (int32_t)begin; y < (int32_t)end; ++y) {
        for (int32_t x = 0; x < j->width; ++x) {
            // Pass 2 writes only the bounce channels, which pass 2 never reads.
            float *raw = j->raw + ((size_t)y * (size_t)j->width + (size_t)x) * RAW_CHANNELS;
            if (pixel_valid(j, x, y)) {
                bounce_pixel(j, x, y, raw);
            }
        }
    }
}

// --- BLUR AND COMPOSE ---

// Geometry-aware blur over the 4x4 block [x - 2, x + 1] x [y - 2, y + 1], which holds every
// sample set once: a neighbour counts when it is a surface, its normal is within blur_normal
// (dot) of the centre's and it lies within blur_plane x r_max of the centre's tangent plane.
static void blur_rows(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    const ssdo_job *j = user;
    float tolerance = j->p.blur_plane * j->p.radius;
    for (int32_t y = (int32_t)begin; y < (int32_t)end; ++y) {
        for (int32_t x = 0; x < j->width; ++x) {
            size_t o = ((size_t)y * (size_t)j->width + (size_t)x) * RAW_CHANNELS;
            float *dst = j->blurred + o;
            if (j->p.no_blur || !pixel_valid(j, x, y)) {
                memcpy(dst, j->raw + o, sizeof(float) * RAW_CHANNELS);
                continue;
            }
            drift_vec3 p = drift_image_get3(&j->gb->position, x, y);
            drift_vec3 n = drift_image_get3(&j->gb->normal, x, y);
            float sum[RAW_CHANNELS] = { 0 };
            float weight = 0.0f;
            for (int32_t v = y - 2; v <= y + 1; ++v) {
                for (int32_t u = x - 2; u <= x + 1; ++u) {
                    if (u < 0 || v < 0 || u >= j->width || v >= j->height ||
                        !pixel_valid(j, u, v)) {
                        continue;
                    }
                    drift_vec3 nq = drift_image_get3(&j->gb->normal, u, v);
                    drift_vec3 q = drift_image_get3(&j->gb->position, u, v);
                    if (drift_vec3_dot(n, nq) < j->p.blur_normal ||
                        fabsf(drift_vec3_dot(n, drift_vec3_sub(q, p))) > tolerance) {
                        continue;
                    }
                    const float *src =
                        j->raw + ((size_t)v * (size_t)j->width + (size_t)u) * RAW_CHANNELS;
                    for (int c = 0; c < RAW_CHANNELS; ++c) {
                        sum[c] += src[c];
                    }
                    weight += 1.0f;
                }
            }
            for (int c = 0; c < RAW_CHANNELS; ++c) {
                dst[c] = sum[c] / weight; // the centre always counts: weight >= 1
            }
        }
    }
}

// Jimenez et al. 2016, eq. 10: the multi-bounce AO fit for albedo rho.
static float gtao_multibounce(float ao, float rho)
{
    float a = 2.0404f * rho - 0.3324f, b = -4.7951f * rho + 0.6417f, c = 2.7552f * rho + 0.6903f;
    return fmaxf(ao, ((ao * a + b) * ao + c) * ao);
}

typedef struct compose_job {
    const ssdo_job *j;
    drift_ssdo_output *out;
} compose_job;

static void compose_rows_out(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    const compose_job *c = user;
    const ssdo_job *j = c->j;
    drift_vec3 zero = drift_vec3_splat(0.0f);
    for (int32_t y = (int32_t)begin; y < (int32_t)end; ++y) {
        for (int32_t x = 0; x < j->width; ++x) {
            const float *b = j->blurred + ((size_t)y * (size_t)j->width + (size_t)x) * RAW_CHANNELS;
            if (!pixel_valid(j, x, y)) {
                drift_image_set3(&c->out->radiance, x, y, zero);
                drift_image_set3(&c->out->direct, x, y, zero);
                drift_image_set3(&c->out->bounce, x, y, zero);
                drift_image_set3(&c->out->bent_normal, x, y, zero);
                drift_image_pixel(&c->out->visibility, x, y)[0] = 0.0f;
                continue;
            }
            drift_vec3 n = drift_image_get3(&j->gb->normal, x, y);
            drift_vec3 rho = drift_image_get3(&j->gb->albedo, x, y);
            drift_vec3 bent = drift_vec3_make(b[RAW_BENT], b[RAW_BENT + 1], b[RAW_BENT + 2]);
            float bl = drift_vec3_length(bent);
            bent = bl > 1e-8f ? drift_vec3_scale(bent, 1.0f / bl) : n;
            float vis = b[RAW_VIS];
            drift_vec3 direct, bounce = zero;
            if (j->p.method == DRIFT_SSDO_METHOD_SSDO) {
                direct = drift_vec3_mul(
                    rho, drift_vec3_make(b[RAW_DIRECT], b[RAW_DIRECT + 1], b[RAW_DIRECT + 2]));
                bounce = drift_vec3_mul(
                    rho, drift_vec3_make(b[RAW_BOUNCE], b[RAW_BOUNCE + 1], b[RAW_BOUNCE + 2]));
            } else if (j->p.method == DRIFT_SSDO_METHOD_GTAO) {
                drift_vec3 e = drift_ssdo_env_irradiance(j->env, bent);
                drift_vec3 ao = drift_vec3_splat(vis);
                if (j->p.gtao_multibounce) {
                    ao = drift_vec3_make(gtao_multibounce(vis, rho.x), gtao_multibounce(vis, rho.y),
                                         gtao_multibounce(vis, rho.z));
                }
                direct = drift_vec3_mul(drift_vec3_mul(rho, ao), e);
            } else {
                direct = drift_vec3_scale(drift_vec3_mul(rho, drift_ssdo_env_irradiance(j->env, n)),
                                          vis);
            }
            drift_image_set3(&c->out->radiance, x, y, drift_vec3_add(direct, bounce));
            drift_image_set3(&c->out->direct, x, y, direct);
            drift_image_set3(&c->out->bounce, x, y, bounce);
            drift_image_set3(&c->out->bent_normal, x, y, bent);
            drift_image_pixel(&c->out->visibility, x, y)[0] = vis;
        }
    }
}

// --- ENTRY POINTS ---

static bool plane_ok(const drift_image *image, int32_t w, int32_t h, int32_t channels)
{
    return drift_image_is_valid(image) && image->width == w && image->height == h &&
           image->channels >= channels;
}

static bool views_ok(const drift_ssdo_inputs *in)
{
    if (in->view_count < 0 || in->view_count > DRIFT_SSDO_MAX_VIEWS ||
        (in->view_count > 0 && !in->views)) {
        return false;
    }
    for (int32_t k = 0; k < in->view_count; ++k) {
        const drift_image *d = &in->views[k].depth;
        if (!drift_image_is_valid(d) || d->channels < 1) {
            return false;
        }
    }
    return true;
}

static void set_views(ssdo_job *j, const drift_ssdo_inputs *in)
{
    j->view_count = in->view_count;
    for (int32_t k = 0; k < in->view_count; ++k) {
        const drift_image *d = &in->views[k].depth;
        j->view_cam[k] = drift_camera_frame_make(&in->views[k].camera, d->width, d->height);
        j->view_depth[k] = d;
    }
}

drift_result drift_ssdo_render(drift_context *ctx, const drift_ssdo_env *env,
                               const drift_ssdo_inputs *inputs, const drift_ssdo_params *params,
                               drift_ssdo_output *out)
{
    double t0 = drift_time_now();
    drift_ssdo_params p = drift_ssdo_params_resolve(params, NULL);
    if (!ctx || !env || !inputs || !inputs->gbuffer || !inputs->camera || !out) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    const drift_gbuffer *gbuffer = inputs->gbuffer;
    const drift_image *sender_extra = inputs->sender_radiance;
    int32_t w = gbuffer->width, h = gbuffer->height;
    bool planes = plane_ok(&gbuffer->depth, w, h, 1) && plane_ok(&gbuffer->position, w, h, 3) &&
                  plane_ok(&gbuffer->normal, w, h, 3) && plane_ok(&gbuffer->albedo, w, h, 3) &&
                  plane_ok(&gbuffer->material_id, w, h, 1) && plane_ok(&out->radiance, w, h, 3) &&
                  plane_ok(&out->direct, w, h, 3) && plane_ok(&out->bounce, w, h, 3) &&
                  plane_ok(&out->visibility, w, h, 1) && plane_ok(&out->bent_normal, w, h, 3) &&
                  (!sender_extra || plane_ok(sender_extra, w, h, 3)) &&
                  (!inputs->back_depth || plane_ok(inputs->back_depth, w, h, 1)) &&
                  views_ok(inputs);
    if (!planes || (unsigned)p.method >= DRIFT_SSDO_METHOD_COUNT || p.samples < 1 ||
        p.samples > MAX_SAMPLES || !(p.radius > 0.0f) || !isfinite(p.radius) ||
        !(p.bounce_area > 0.0f) || !(p.bounce_clamp > 0.0f) || !(p.bias >= 0.0f) ||
        p.gtao_slices < 1 || p.gtao_slices > MAX_SLICES || p.steps < 1 || p.steps > 64 ||
        !(p.gtao_thickness >= 0.0f) || !(p.gtao_thickness <= 1.0f) || !(p.blur_plane > 0.0f)) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, __FILE__, __LINE__,
                  "ssdo: G-buffer and output planes of one size, samples 1..%d, radius > 0, "
                  "slices 1..%d and thickness in [0, 1] are required",
                  MAX_SAMPLES, MAX_SLICES);
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    ssdo_job j = { .env = env,
                   .gb = gbuffer,
                   .sender_extra = sender_extra,
                   .back_depth = inputs->back_depth,
                   .p = p,
                   .cam = drift_camera_frame_make(inputs->camera, w, h),
                   .width = w,
                   .height = h };
    j.focal_px = (float)h / (2.0f * j.cam.tan_half);
    set_views(&j, inputs);
    size_t pixels = (size_t)w * (size_t)h;
    j.set_dir = drift_alloc(ctx, sizeof(drift_vec3) * SETS * (size_t)p.samples);
    j.set_len = drift_alloc(ctx, sizeof(float) * SETS * (size_t)p.samples);
    j.raw = drift_alloc(ctx, sizeof(float) * RAW_CHANNELS * pixels);
    j.blurred = drift_alloc(ctx, sizeof(float) * RAW_CHANNELS * pixels);
    drift_result result = DRIFT_OK;
    if (!j.set_dir || !j.set_len || !j.raw || !j.blurred) {
        result = DRIFT_ERR_OUT_OF_MEMORY;
        goto done;
    }
    make_sets(&j);
    drift_parallel_for(ctx, (size_t)h, 2, occlusion_rows, &j);
    double t1 = drift_time_now();
    if (p.bounce && p.method == DRIFT_SSDO_METHOD_SSDO) {
        drift_parallel_for(ctx, (size_t)h, 2, bounce_rows, &j);
    }
    double t2 = drift_time_now();
    drift_parallel_for(ctx, (size_t)h, 2, blur_rows, &j);
    compose_job c = { .j = &j, .out = out };
    drift_parallel_for(ctx, (size_t)h, 2, compose_rows_out, &c);
    double t3 = drift_time_now();
    out->stats = (drift_ssdo_stats){ .occlusion_ms = 1e3 * (t1 - t0),
                                     .bounce_ms = 1e3 * (t2 - t1),
                                     .blur_ms = 1e3 * (t3 - t2),
                                     .total_ms = 1e3 * (t3 - t0) };
done:
    drift_free(ctx, j.set_dir);
    drift_free(ctx, j.set_len);
    drift_free(ctx, j.raw);
    drift_free(ctx, j.blurred);
    return result;
}

// --- CONTACT SHADOWS (thesis §4.5) ---

typedef struct contact_job {
    ssdo_job j;
    drift_vec3 light; // position, or for a directional light the way its light travels
    bool directional;
    float length;               // of the march toward the light
    const drift_image *lengths; // or one length a pixel (<= 0: no march)
    int32_t samples;
    drift_image *out;
} contact_job;

static void contact_rows(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    const contact_job *c = user;
    const ssdo_job *j = &c->j;
    for (int32_t y = (int32_t)begin; y < (int32_t)end; ++y) {
        for (int32_t x = 0; x < j->width; ++x) {
            float *dst = drift_image_pixel(c->out, x, y);
            dst[0] = 1.0f;
            if (!pixel_valid(j, x, y)) {
                continue;
            }
            float length = c->lengths ? drift_image_pixel(c->lengths, x, y)[0] : c->length;
            if (!(length > 0.0f)) {
                continue;
            }
            drift_vec3 p = drift_image_get3(&j->gb->position, x, y);
            drift_vec3 n = drift_image_get3(&j->gb->normal, x, y);
            drift_vec3 l = c->directional ? drift_vec3_neg(drift_vec3_normalize(c->light))
                                          : drift_vec3_normalize(drift_vec3_sub(c->light, p));
            if (!(drift_vec3_dot(n, l) > 0.0f)) {
                continue; // facing away: the light's own shadow test decides
            }
            for (int32_t k = 0; k < c->samples; ++k) {
                float t = ((float)k + 0.5f) / (float)c->samples * length;
                int32_t qx, qy;
                float margin = 0.01f * length;
                if (!(occluder(j, p, drift_vec3_fma(p, l, t), margin, &qx, &qy) > 0.0f)) {
                    continue;
                }
                // A blocker rises above the receiver's tangent plane. The same surface seen at
                // a grazing angle does not: its next pixel's stored point is nearer only because
                // depth changes fast across a pixel there (self-shadowing acne otherwise).
                if (qx < 0 ||
                    drift_vec3_dot(n, drift_vec3_sub(drift_image_get3(&j->gb->position, qx, qy),
                                                     p)) > margin) {
                    dst[0] = 0.0f;
                    break;
                }
            }
        }
    }
}

static drift_result contact_shadows(drift_context *ctx, const drift_ssdo_inputs *inputs,
                                    drift_vec3 light, bool directional, float length,
                                    const drift_image *lengths, int32_t samples,
                                    drift_image *out_visible)
{
    if (!ctx || !inputs || !inputs->gbuffer || !inputs->camera || !out_visible) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    const drift_gbuffer *g = inputs->gbuffer;
    int32_t w = g->width, h = g->height;
    if (!plane_ok(&g->depth, w, h, 1) || !plane_ok(&g->position, w, h, 3) ||
        !plane_ok(&g->normal, w, h, 3) || !plane_ok(&g->material_id, w, h, 1) ||
        !plane_ok(out_visible, w, h, 1) ||
        (inputs->back_depth && !plane_ok(inputs->back_depth, w, h, 1)) || !views_ok(inputs) ||
        (lengths ? !plane_ok(lengths, w, h, 1) : !(length > 0.0f) || !isfinite(length)) ||
        samples < 1 || samples > MAX_SAMPLES || (directional && drift_vec3_is_zero(light))) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, __FILE__, __LINE__,
                  "ssdo contact shadows: planes of one size, length > 0 and samples 1..%d",
                  MAX_SAMPLES);
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    // The occluder test of the sample sets with no fade: any buffer surface nearer than a
    // sample on the segment, by more than 1% of its length, blocks it.
    contact_job c = { .j = { .gb = g,
                             .back_depth = inputs->back_depth,
                             .p = drift_ssdo_params_resolve(
                                 &(drift_ssdo_params){ .radius = 1.0f, .no_fade = true }, NULL),
                             .cam = drift_camera_frame_make(inputs->camera, w, h),
                             .width = w,
                             .height = h },
                      .light = light,
                      .directional = directional,
                      .length = length,
                      .lengths = lengths,
                      .samples = samples,
                      .out = out_visible };
    set_views(&c.j, inputs);
    drift_parallel_for(ctx, (size_t)h, 2, contact_rows, &c);
    return DRIFT_OK;
}

drift_result drift_ssdo_contact_shadows(drift_context *ctx, const drift_ssdo_inputs *inputs,
                                        drift_vec3 light, bool directional, float length,
                                        int32_t samples, drift_image *out_visible)
{
    return contact_shadows(ctx, inputs, light, directional, length, NULL, samples, out_visible);
}

drift_result drift_ssdo_contact_shadows_per_pixel(drift_context *ctx,
                                                  const drift_ssdo_inputs *inputs, drift_vec3 light,
                                                  bool directional, const drift_image *lengths,
                                                  int32_t samples, drift_image *out_visible)
{
    if (!lengths) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    return contact_shadows(ctx, inputs, light, directional, 0.0f, lengths, samples, out_visible);
}
