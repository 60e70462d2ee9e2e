// Environment map: a cube map of the radiance seen from a probe point, one sample per texel,
// emitted and reflected parts kept apart, with a box-filtered mip chain per face so glossy
// lookups can blur over a cone.
//
// Faces and orientation follow OpenGL (the ARB_texture_cube_map table): face 0..5 is the major
// axis +x -x +y -y +z -z of the direction, and with m the major component's magnitude,
//   face   sc    tc          face   sc    tc
//   +x     -z    -y          -x     +z    -y
//   +y     +x    +z          -y     +x    -z
//   +z     +x    -y          -z     -x    -y
// s = (sc / m + 1) / 2, t = (tc / m + 1) / 2. Texel (i, j) is column i along s, row j along t,
// its centre at s = (i + 0.5) / n. Ties between axes go to x, then y.
//
// Lookups are bilinear within one face and clamp at its edges: a direction within half a
// texel of an edge reads the edge texels only, never the neighbouring face (no seamless
// filtering). The mip level is the one whose texel angle (pi/2) / n_k matches the cone's half
// angle, trilinear between the two nearest levels.
#include "raster/raster.h"

#include <math.h>
#include <stdatomic.h>

#define MAX_LEVELS   16 // 4096 -> 1 is 13 levels
#define TEXEL_FLOATS 6  // emitted rgb, reflected rgb

struct drift_envmap {
    drift_vec3 probe;
    int32_t level_count;
    int32_t size[MAX_LEVELS];  // texels across a face per level
    size_t offset[MAX_LEVELS]; // first float of each level in `texels`
    float *texels;             // per level: face, row, column, TEXEL_FLOATS
};

// --- CUBE FACES ---

int drift_cube_face_coords(drift_vec3 dir, drift_vec2 *out_st)
{
    float ax = fabsf(dir.x), ay = fabsf(dir.y), az = fabsf(dir.z);
    int face;
    float m, sc, tc;
    if (ax >= ay && ax >= az) {
        face = dir.x >= 0.0f ? 0 : 1;
        m = ax;
        sc = dir.x >= 0.0f ? -dir.z : dir.z;
        tc = -dir.y;
    } else if (ay >= az) {
        face = dir.y >= 0.0f ? 2 : 3;
        m = ay;
        sc = dir.x;
        tc = dir.y >= 0.0f ? dir.z : -dir.z;
    } else {
        face = dir.z >= 0.0f ? 4 : 5;
        m = az;
        sc = dir.z >= 0.0f ? dir.x : -dir.x;
        tc = -dir.y;
    }
    if (!(m > 0.0f) || !isfinite(m) || !isfinite(sc) || !isfinite(tc)) {
        return -1;
    }
    *out_st = drift_vec2_make(0.5f * (sc / m + 1.0f), 0.5f * (tc / m + 1.0f));
    return face;
}

// The inverse of the table above for a point (a, b) = (2s - 1, 2t - 1) on the face.
static drift_vec3 face_point_direction(int face, float a, float b)
{
    switch (face) {
    case 0:
        return drift_vec3_make(1.0f, -b, -a);
    case 1:
        return drift_vec3_make(-1.0f, -b, a);
    case 2:
        return drift_vec3_make(a, 1.0f, b);
    case 3:
        return drift_vec3_make(a, -1.0f, -b);
    case 4:
        return drift_vec3_make(a, -b, 1.0f);
    default:
        return drift_vec3_make(-a, -b, -1.0f);
    }
}

drift_vec3 drift_cube_texel_direction(int32_t face_size, int face, int32_t i, int32_t j)
{
    float n = (float)face_size;
    float a = (2.0f * (float)i + 1.0f) / n - 1.0f;
    float b = (2.0f * (float)j + 1.0f) / n - 1.0f;
    return drift_vec3_normalize(face_point_direction(face, a, b));
}

// --- STORAGE ---

static float *texel_at(const drift_envmap *map, int32_t level, int face, int32_t i, int32_t j)
{
    size_t n = (size_t)map->size[level];
    return map->texels + map->offset[level] +
           (((size_t)face * n + (size_t)j) * n + (size_t)i) * TEXEL_FLOATS;
}

// Level sizes halve (rounding down) to 1x1; returns the float count of all levels, 0 on overflow.
static size_t plan_levels(drift_envmap *map, int32_t face_size)
{
    size_t total = 0;
    int32_t n = face_size;
    map->level_count = 0;
    while (map->level_count < MAX_LEVELS) {
        size_t level_floats;
        if (!drift_size_mul((size_t)n * (size_t)n, 6 * TEXEL_FLOATS, &level_floats)) {
            return 0;
        }
        map->size[map->level_count] = n;
        map->offset[map->level_count] = total;
        map->level_count++;
        if (!drift_size_add(total, level_floats, &total)) {
            return 0;
        }
        if (n == 1) {
            break;
        }
        n /= 2;
    }
    return total;
}

// --- CAPTURE ---

typedef struct capture_job {
    drift_envmap *map;
    drift_envmap_radiance_fn radiance;
    void *user;
    uint32_t seed;
    atomic_uint_fast64_t rays;
} capture_job;

static void store_texel(float *t, drift_raster_radiance r)
{
    const float v[TEXEL_FLOATS] = { r.emitted.x,   r.emitted.y,   r.emitted.z,
                                    r.reflected.x, r.reflected.y, r.reflected.z };
    for (int c = 0; c < TEXEL_FLOATS; ++c) {
        t[c] = v[c];
    }
}

static void capture_texels(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    capture_job *job = user;
    const drift_envmap *map = job->map;
    size_t n = (size_t)map->size[0];
    uint64_t rays = 0;
    for (size_t index = begin; index < end; ++index) {
        int face = (int)(index / (n * n));
        int32_t j = (int32_t)(index / n % n), i = (int32_t)(index % n);
        drift_ray ray = { .origin = map->probe,
                          .tmin = 0.0f,
                          .dir = drift_cube_texel_direction((int32_t)n, face, i, j),
                          .tmax = INFINITY };
        drift_sampler sampler = drift_sampler_make(job->seed, (uint32_t)index, 0);
        drift_raster_radiance r = job->radiance(job->user, ray, &sampler, &rays);
        store_texel(texel_at(map, 0, face, i, j), r);
    }
    atomic_fetch_add(&job->rays, rays);
}

// A texel of the coarser level averages the finer texels it overlaps: exactly 2x2 for even
// sizes; an odd size's middle row or column is shared by two coarse texels.
static void downsample_level(drift_envmap *map, int32_t level)
{
    int32_t fine = map->size[level - 1], coarse = map->size[level];
    for (int face = 0; face < 6; ++face) {
        for (int32_t j = 0; j < coarse; ++j) {
            int32_t j0 = j * fine / coarse, j1 = ((j + 1) * fine + coarse - 1) / coarse;
            for (int32_t i = 0; i < coarse; ++i) {
                int32_t i0 = i * fine / coarse, i1 = ((i + 1) * fine + coarse - 1) / coarse;
                float sum[TEXEL_FLOATS] = { 0 };
                for (int32_t y = j0; y < j1; ++y) {
                    for (int32_t x = i0; x < i1; ++x) {
                        const float *src = texel_at(map, level - 1, face, x, y);
                        for (int c = 0; c < TEXEL_FLOATS; ++c) {
                            sum[c] += src[c];
                        }
                    }
                }
                float inv = 1.0f / (float)((j1 - j0) * (i1 - i0));
                float *dst = texel_at(map, level, face, i, j);
                for (int c = 0; c < TEXEL_FLOATS; ++c) {
                    dst[c] = sum[c] * inv;
                }
            }
        }
    }
}

static drift_result check_capture_args(drift_context *ctx, drift_envmap_radiance_fn radiance,
                                       drift_vec3 probe, int32_t face_size, drift_envmap **out_map)
{
    if (!radiance || !out_map) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, __FILE__, __LINE__,
                  "envmap capture: NULL radiance function or output");
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    if (face_size < 1 || face_size > DRIFT_ENVMAP_MAX_FACE_SIZE) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, __FILE__, __LINE__,
                  "envmap face size %d is outside 1..%d", (int)face_size,
                  DRIFT_ENVMAP_MAX_FACE_SIZE);
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    if (!drift_vec3_is_finite(probe)) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, __FILE__, __LINE__,
                  "envmap probe position is not finite");
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    return DRIFT_OK;
}

drift_result drift_envmap_capture_fn(drift_context *ctx, drift_envmap_radiance_fn radiance,
                                     void *user, drift_vec3 probe, int32_t face_size, uint32_t seed,
                                     drift_envmap **out_map, uint64_t *out_rays)
{
    if (out_map) {
        *out_map = NULL;
    }
    drift_result r = check_capture_args(ctx, radiance, probe, face_size, out_map);
    if (r != DRIFT_OK) {
        return r;
    }
    drift_envmap *map = drift_alloc(ctx, sizeof(*map));
    if (!map) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_OUT_OF_MEMORY, __FILE__, __LINE__,
                  "envmap: out of memory");
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    map->probe = probe;
    size_t floats = plan_levels(map, face_size), bytes = 0;
    if (floats == 0 || !drift_size_mul(floats, sizeof(float), &bytes) ||
        !(map->texels = drift_alloc(ctx, bytes))) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_OUT_OF_MEMORY, __FILE__, __LINE__,
                  "envmap: out of memory for %d texels a face", (int)face_size);
        drift_envmap_destroy(ctx, map);
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    capture_job job = { .map = map, .radiance = radiance, .user = user, .seed = seed };
    atomic_init(&job.rays, 0);
    size_t texel_count = 6 * (size_t)face_size * (size_t)face_size;
    drift_parallel_for(ctx, texel_count, 64, capture_texels, &job);
    for (int32_t level = 1; level < map->level_count; ++level) {
        downsample_level(map, level);
    }
    if (out_rays) {
        *out_rays = (uint64_t)atomic_load(&job.rays);
    }
    *out_map = map;
    return DRIFT_OK;
}

typedef struct scene_radiance {
    const drift_raster_shading *shading;
    uint32_t skip_mesh;
} scene_radiance;

static drift_raster_radiance trace_scene(void *user, drift_ray ray, drift_sampler *sampler,
                                         uint64_t *rays)
{
    const scene_radiance *s = user;
    float distance;
    return drift_raster_trace_radiance(s->shading, ray, s->skip_mesh, sampler, rays, &distance);
}

drift_result drift_envmap_capture(drift_context *ctx, const drift_raster_shading *shading,
                                  drift_vec3 probe, uint32_t skip_mesh, int32_t face_size,
                                  uint32_t seed, drift_envmap **out_map, uint64_t *out_rays)
{
    if (!shading) {
        if (out_map) {
            *out_map = NULL;
        }
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, __FILE__, __LINE__,
                  "envmap capture: NULL shading");
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    scene_radiance user = { .shading = shading, .skip_mesh = skip_mesh };
    return drift_envmap_capture_fn(ctx, trace_scene, &user, probe, face_size, seed, out_map,
                                   out_rays);
}

void drift_envmap_destroy(drift_context *ctx, drift_envmap *map)
{
    if (!map) {
        return;
    }
    drift_free(ctx, map->texels);
    drift_free(ctx, map);
}

// --- LOOKUP ---

typedef struct texel_sum {
    float v[TEXEL_FLOATS];
} texel_sum;

static void add_scaled(texel_sum *sum, const float *texel, float w)
{
    for (int c = 0; c < TEXEL_FLOATS; ++c) {
        sum->v[c] += texel[c] * w;
    }
}

// Bilinear between the four texel centres around (s, t), clamped to the face.
static void bilinear(const drift_envmap *map, int32_t level, int face, drift_vec2 st, float w,
                     texel_sum *sum)
{
    int32_t n = map->size[level];
    float x = st.x * (float)n - 0.5f, y = st.y * (float)n - 0.5f;
    float x0f = floorf(x), y0f = floorf(y);
    float fx = x - x0f, fy = y - y0f;
    int32_t x0 = (int32_t)x0f, y0 = (int32_t)y0f;
    int32_t xa = x0 < 0 ? 0 : (x0 > n - 1 ? n - 1 : x0);
    int32_t xb = x0 + 1 < 0 ? 0 : (x0 + 1 > n - 1 ? n - 1 : x0 + 1);
    int32_t ya = y0 < 0 ? 0 : (y0 > n - 1 ? n - 1 : y0);
    int32_t yb = y0 + 1 < 0 ? 0 : (y0 + 1 > n - 1 ? n - 1 : y0 + 1);
    add_scaled(sum, texel_at(map, level, face, xa, ya), w * (1.0f - fx) * (1.0f - fy));
    add_scaled(sum, texel_at(map, level, face, xb, ya), w * fx * (1.0f - fy));
    add_scaled(sum, texel_at(map, level, face, xa, yb), w * (1.0f - fx) * fy);
    add_scaled(sum, texel_at(map, level, face, xb, yb), w * fx * fy);
}

// Fractional level whose texel angle (pi/2) / n_k equals cone_angle, clamped to the chain.
static float cone_level(const drift_envmap *map, float cone_angle)
{
    float half_pi = 0.5f * DRIFT_PI;
    if (!(cone_angle > half_pi / (float)map->size[0])) {
        return 0.0f;
    }
    for (int32_t k = 0; k + 1 < map->level_count; ++k) {
        float a0 = half_pi / (float)map->size[k], a1 = half_pi / (float)map->size[k + 1];
        if (cone_angle < a1) {
            return (float)k + logf(cone_angle / a0) / logf(a1 / a0);
        }
    }
    return (float)(map->level_count - 1);
}

drift_raster_radiance drift_envmap_lookup(const drift_envmap *map, drift_vec3 dir, float cone_angle)
{
    drift_raster_radiance out = { { 0.0f, 0.0f, 0.0f }, { 0.0f, 0.0f, 0.0f } };
    drift_vec2 st;
    int face = drift_cube_face_coords(dir, &st);
    if (face < 0) {
        return out;
    }
    float level = cone_level(map, cone_angle);
    int32_t k = (int32_t)level;
    float f = level - (float)k;
    texel_sum sum = { { 0.0f } };
    bilinear(map, k, face, st, 1.0f - f, &sum);
    if (f > 0.0f && k + 1 < map->level_count) {
        bilinear(map, k + 1, face, st, f, &sum);
    }
    out.emitted = drift_vec3_make(sum.v[0], sum.v[1], sum.v[2]);
    out.reflected = drift_vec3_make(sum.v[3], sum.v[4], sum.v[5]);
    return out;
}

drift_vec3 drift_envmap_probe(const drift_envmap *map)
{
    return map->probe;
}

drift_vec3 drift_envmap_parallax_direction(drift_bounds3 box, drift_vec3 probe, drift_vec3 p,
                                           drift_vec3 dir, float *out_ratio)
{
    if (out_ratio) {
        *out_ratio = 1.0f;
    }
    // The exit distance: the nearest of the three far slabs along dir.
    float t = INFINITY;
    const float pp[3] = { p.x, p.y, p.z }, d[3] = { dir.x, dir.y, dir.z };
    const float lo[3] = { box.min.x, box.min.y, box.min.z };
    const float hi[3] = { box.max.x, box.max.y, box.max.z };
    for (int a = 0; a < 3; ++a) {
        if (pp[a] < lo[a] || pp[a] > hi[a]) {
            return dir; // outside (or an empty box): nothing to correct against
        }
        if (d[a] > 0.0f) {
            t = fminf(t, (hi[a] - pp[a]) / d[a]);
        } else if (d[a] < 0.0f) {
            t = fminf(t, (lo[a] - pp[a]) / d[a]);
        }
    }
    if (!(t < INFINITY)) {
        return dir;
    }
    drift_vec3 to = drift_vec3_sub(drift_vec3_fma(p, dir, t), probe);
    float length = drift_vec3_length(to);
    if (!(length > 0.0f)) {
        return dir;
    }
    if (out_ratio) {
        *out_ratio = t / length;
    }
    return drift_vec3_scale(to, 1.0f / length);
}

float drift_envmap_parallax_cone(float cone, float ratio)
{
    if (!(cone > 0.0f) || ratio == 1.0f) {
        return cone;
    }
    return atanf(tanf(fminf(cone, 1.5f)) * ratio);
}

int32_t drift_envmap_face_size(const drift_envmap *map)
{
    return map->size[0];
}

int32_t drift_envmap_level_count(const drift_envmap *map)
{
    return map->level_count;
}
