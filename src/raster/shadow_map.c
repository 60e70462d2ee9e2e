// Shadow maps: depth seen from a light, filled by ray casting through texel centres, and
// the three lookups a rasterizer would do with them (hard, PCF, PCSS).
//
// Local lights get a cube map of radial distances from the light's centre; directional
// lights an orthographic map over the scene bounds. Every lookup goes through one tap
// function, so hard, PCF and PCSS differ only in where they put their taps.
//
// Depth test (the same for every tap): a tap is lit when stored >= receiver - bias, where
//   receiver is the depth of the receiver's tangent plane along the ray through the tap's
//     texel centre (receiver-plane depth bias, Isidoro 2006, "Shadow Mapping: GPU-based Tips
//     and Techniques"): a plane never shadows itself, however wide the kernel or grazing
//     the light. Its difference from the receiver's own depth is capped at a slope of
//     MAX_RECEIVER_SLOPE so that grazing planes cannot push it to infinity;
//   bias = bias_texels * the texel footprint at the receiver (texel angle * distance for
//     cube maps, texel size for orthographic maps), for curved receivers and rounding.
// Plus a normal offset of NORMAL_OFFSET_TEXELS footprints: the receiver plane alone left acne
// on planes nearly edge-on to the light's centre (the Cornell box's tall block under PCSS);
// the offset moves shadow edges by about a texel.
#include "raster/shadow_map_internal.h"

#include <math.h>

#define MAX_SIZE 16384
// Rays that keep hitting the light's own shape give up after this many (a light is never
// that many layers deep in practice).
#define MAX_OWN_HITS       16
#define MAX_RECEIVER_SLOPE 8.0f
// PCSS near plane as a fraction of the receiver's distance (see pcss_search_radius).
#define PCSS_NEAR_FRACTION 0.25f
// Widest tap region of a cube lookup, radians: offsets are taken in the tangent plane of
// the direction, which distorts beyond this.
#define MAX_CUBE_RADIUS 0.5f
// Widest tap region of an orthographic lookup, as a fraction of the map's width.
#define MAX_ORTHO_RADIUS 0.25f

// --- CUBE FACES ---
// Face f looks along axis a = f / 2 with sign s = + for even f. Its texel (x, y) looks along
// s e_a + u e_b + v e_c with b = (a + 1) % 3, c = (a + 2) % 3 and u, v in [-1, 1] the texel
// centre; any fixed layout works, as build and lookup share these functions.

static drift_vec3 axis_vec3(int axis, float value)
{
    drift_vec3 v = { 0.0f, 0.0f, 0.0f };
    if (axis == 0) {
        v.x = value;
    } else if (axis == 1) {
        v.y = value;
    } else {
        v.z = value;
    }
    return v;
}

static drift_vec3 face_direction(int face, float u, float v)
{
    int a = face / 2;
    float s = face % 2 == 0 ? 1.0f : -1.0f;
    drift_vec3 d = axis_vec3(a, s);
    d = drift_vec3_add(d, axis_vec3((a + 1) % 3, u));
    return drift_vec3_add(d, axis_vec3((a + 2) % 3, v));
}

int drift_shadow_map_major_face(drift_vec3 d)
{
    float ax = fabsf(d.x), ay = fabsf(d.y), az = fabsf(d.z);
    int a = ax >= ay && ax >= az ? 0 : (ay >= az ? 1 : 2);
    return 2 * a + (drift_shadow_map_axis(d, a) >= 0.0f ? 0 : 1);
}

// Whether any direction of the face has dot(dir, n) > 0: the largest dot over the face
// is s n_a + |n_b| + |n_c| (u and v take the signs of n_b and n_c).
static bool face_faces(int face, drift_vec3 n)
{
    int a = face / 2;
    float s = face % 2 == 0 ? 1.0f : -1.0f;
    float best = s * drift_shadow_map_axis(n, a) + fabsf(drift_shadow_map_axis(n, (a + 1) % 3)) +
                 fabsf(drift_shadow_map_axis(n, (a + 2) % 3));
    return best > 0.0f;
}

static float texel_centre(int32_t i, int32_t size)
{
    return ((float)i + 0.5f) * 2.0f / (float)size - 1.0f;
}

int32_t drift_shadow_map_texel_index(float u, int32_t size)
{
    int32_t i = (int32_t)floorf((u + 1.0f) * 0.5f * (float)size);
    return i < 0 ? 0 : (i >= size ? size - 1 : i);
}

// Angular size of a texel at face coordinates (u, v): d(angle)/du is
// sqrt(1 + v^2) / (1 + u^2 + v^2), and likewise for v; the larger of the two, so that
// bias errs toward no acne and kernel steps never land twice in one texel.
static float cube_texel_angle(float u, float v, int32_t size)
{
    float m = fmaxf(u * u, v * v);
    return 2.0f / (float)size * sqrtf(1.0f + m) / (1.0f + u * u + v * v);
}

// --- BUILD ---

typedef struct build_job {
    drift_shadow_map *map;
    const drift_accel *accel;
    const drift_raster_light *light;
    float tmin; // where rays start: past the centre, which lies on a planar light's shape
    int face_of_slot[CUBE_FACES];
    atomic_uint_fast64_t rays;
} build_job;

// Distance along the unit direction to the nearest surface that is not the light's own
// shape (rays from a sphere light's centre would hit its inside), INFINITY on a miss.
static float trace_depth(const build_job *job, drift_vec3 origin, drift_vec3 dir, uint64_t *rays)
{
    drift_ray ray = { .origin = origin, .dir = dir, .tmin = job->tmin, .tmax = INFINITY };
    for (int i = 0; i < MAX_OWN_HITS; ++i) {
        drift_hit hit;
        ++*rays;
        if (!drift_accel_intersect(job->accel, &ray, &hit)) {
            return INFINITY;
        }
        if (!drift_raster_light_owns(job->light, hit.light)) {
            return hit.t;
        }
        // Re-trace from just past the hit; t stays measured from the centre.
        ray.tmin = fmaxf(hit.t * (1.0f + 1e-5f), hit.t + job->tmin);
    }
    return INFINITY;
}

static drift_ray texel_ray(const drift_shadow_map *map, int face, int32_t x, int32_t y)
{
    if (map->directional) {
        float px = ((float)x + 0.5f) * map->texel_size, py = ((float)y + 0.5f) * map->texel_size;
        drift_vec3 o =
            drift_vec3_fma(drift_vec3_fma(map->origin, map->frame.x, px), map->frame.y, py);
        return (drift_ray){ .origin = o, .dir = map->frame.z };
    }
    drift_vec3 d = face_direction(face, texel_centre(x, map->size), texel_centre(y, map->size));
    return (drift_ray){ .origin = map->centre, .dir = drift_vec3_normalize(d) };
}

static void fill_rows(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    build_job *job = user;
    drift_shadow_map *map = job->map;
    size_t size = (size_t)map->size;
    uint64_t rays = 0;
    for (size_t row = begin; row < end; ++row) {
        int face = job->face_of_slot[row / size];
        int32_t y = (int32_t)(row % size);
        for (int32_t x = 0; x < map->size; ++x) {
            drift_ray ray = texel_ray(map, face, x, y);
            map->depth[row * size + (size_t)x] = trace_depth(job, ray.origin, ray.dir, &rays);
        }
    }
    atomic_fetch_add(&job->rays, rays);
}

static int32_t mip_size(int32_t size, int32_t level)
{
    return (int32_t)(((int64_t)size + (1 << level) - 1) >> level);
}

// The min-depth chain: each cell the least of its (up to) four children.
static drift_result build_min_mip(drift_context *ctx, drift_shadow_map *map)
{
    map->mip_levels = 0;
    size_t total = 0;
    for (int32_t k = 1; k < 31 && mip_size(map->size, k - 1) > 1; ++k) {
        map->mip_offset[k] = total;
        total += (size_t)mip_size(map->size, k) * (size_t)mip_size(map->size, k);
        map->mip_levels = k;
    }
    map->mip_slot = total;
    if (total == 0) {
        return DRIFT_OK;
    }
    map->min_mip = drift_alloc(ctx, sizeof(float) * total * map->slot_count);
    if (!map->min_mip) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    for (uint32_t slot = 0; slot < map->slot_count; ++slot) {
        for (int32_t k = 1; k <= map->mip_levels; ++k) {
            int32_t from = mip_size(map->size, k - 1), to = mip_size(map->size, k);
            const float *src =
                k == 1 ? map->depth + (size_t)slot * (size_t)map->size * (size_t)map->size
                       : map->min_mip + slot * map->mip_slot + map->mip_offset[k - 1];
            float *dst = map->min_mip + slot * map->mip_slot + map->mip_offset[k];
            for (int32_t y = 0; y < to; ++y) {
                for (int32_t x = 0; x < to; ++x) {
                    float m = INFINITY;
                    for (int32_t j = 2 * y; j < 2 * y + 2 && j < from; ++j) {
                        for (int32_t i = 2 * x; i < 2 * x + 2 && i < from; ++i) {
                            m = fminf(m, src[(size_t)j * (size_t)from + (size_t)i]);
                        }
                    }
                    dst[(size_t)y * (size_t)to + (size_t)x] = m;
                }
            }
        }
    }
    return DRIFT_OK;
}

// Least stored depth over texels [x0, x1] x [y0, y1] of a slot (inclusive, in range): at most
// four cells of the coarsest level whose cells are at least the rectangle's size.
float drift_shadow_map_min_depth_rect(const drift_shadow_map *map, int32_t slot, int32_t x0,
                                      int32_t y0, int32_t x1, int32_t y1)
{
    int32_t extent = (x1 - x0 > y1 - y0 ? x1 - x0 : y1 - y0) + 1, k = 0;
    while ((1 << k) < extent && k < map->mip_levels) {
        ++k;
    }
    int32_t size = mip_size(map->size, k);
    const float *level = k == 0 ? map->depth + (size_t)slot * (size_t)map->size * (size_t)map->size
                                : map->min_mip + (size_t)slot * map->mip_slot + map->mip_offset[k];
    float m = INFINITY;
    for (int32_t y = y0 >> k; y <= y1 >> k && y < size; ++y) {
        for (int32_t x = x0 >> k; x <= x1 >> k && x < size; ++x) {
            m = fminf(m, level[(size_t)y * (size_t)size + (size_t)x]);
        }
    }
    return m;
}

// Fixed tap sets: stratified points of [0,1)^2 mapped to the unit disk (Shirley & Chiu),
// so taps cover the disk evenly without a random pattern to store.
static void make_disk_taps(drift_vec2 *taps, int32_t columns, int32_t rows)
{
    for (int32_t j = 0; j < rows; ++j) {
        for (int32_t i = 0; i < columns; ++i) {
            drift_vec2 u = { ((float)i + 0.5f) / (float)columns, ((float)j + 0.5f) / (float)rows };
            taps[j * columns + i] = drift_sample_disk_concentric(u);
        }
    }
}

// Orthographic frame over the scene bounds: the bounds' corners in light space give the
// map's square (one texel of margin each side) and its near plane (just before the scene).
static void setup_orthographic(drift_shadow_map *map, const drift_scene *scene,
                               drift_vec3 direction)
{
    map->frame = drift_frame_from_normal(drift_vec3_normalize(direction));
    drift_bounds3 b = scene->bounds;
    if (drift_bounds3_is_empty(b)) {
        b = (drift_bounds3){ { -1.0f, -1.0f, -1.0f }, { 1.0f, 1.0f, 1.0f } };
    }
    drift_bounds3 local = drift_bounds3_empty();
    for (int i = 0; i < 8; ++i) {
        drift_vec3 corner = { (i & 1) ? b.max.x : b.min.x, (i & 2) ? b.max.y : b.min.y,
                              (i & 4) ? b.max.z : b.min.z };
        local = drift_bounds3_extend(local, drift_frame_to_local(&map->frame, corner));
    }
    float extent = fmaxf(fmaxf(local.max.x - local.min.x, local.max.y - local.min.y), 1e-6f);
    map->texel_size = extent / (float)(map->size - 2 > 0 ? map->size - 2 : 1);
    float margin = map->texel_size;
    drift_vec3 centre = drift_vec3_scale(drift_vec3_add(local.min, local.max), 0.5f);
    float half = 0.5f * map->texel_size * (float)map->size;
    float near = local.min.z - margin - 1e-4f * fmaxf(1.0f, fabsf(local.min.z));
    drift_vec3 corner = { centre.x - half, centre.y - half, near };
    map->origin = drift_frame_to_world(&map->frame, corner);
}

static drift_result validate(drift_context *ctx, const drift_scene *scene, const drift_accel *accel,
                             const drift_raster_light *light, const drift_shadow_map_params *params)
{
    const char *problem = NULL;
    if (!scene || !accel || !light || !params) {
        problem = "missing scene, accel, light or parameters";
    } else if (!scene->committed) {
        problem = "scene not committed";
    } else if (params->size < 1 || params->size > MAX_SIZE) {
        problem = "size out of range";
    } else if (!(params->bias_texels >= 0.0f) || !isfinite(params->bias_texels)) {
        problem = "bias must be finite and >= 0";
    } else if ((unsigned)light->type >= DRIFT_LIGHT_COUNT || !(light->radius >= 0.0f) ||
               !isfinite(light->radius) || !drift_vec3_is_finite(light->centre) ||
               !drift_vec3_is_finite(light->direction)) {
        problem = "light out of range";
    } else if (light->type == DRIFT_LIGHT_DIRECTIONAL && drift_vec3_is_zero(light->direction)) {
        problem = "directional light without a direction";
    }
    if (problem) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, NULL, 0, "shadow map: %s",
                  problem);
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    return DRIFT_OK;
}

// Picks the faces to store (all but those behind a one-sided light; a two-sided one lights
// both half-spaces).
static void choose_faces(drift_shadow_map *map, const drift_raster_light *light,
                         int face_of_slot[CUBE_FACES])
{
    map->slot_count = 0;
    for (int f = 0; f < CUBE_FACES; ++f) {
        map->face_slot[f] = -1;
        if (!light->one_sided || light->two_sided || face_faces(f, light->direction)) {
            face_of_slot[map->slot_count] = f;
            map->face_slot[f] = (int8_t)map->slot_count++;
        }
    }
}

drift_result drift_shadow_map_build(drift_context *ctx, const drift_scene *scene,
                                    const drift_accel *accel, const drift_raster_light *light,
                                    const drift_shadow_map_params *params,
                                    drift_shadow_map **out_map, uint64_t *out_rays)
{
    if (!out_map) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    *out_map = NULL;
    drift_result r = validate(ctx, scene, accel, light, params);
    if (r != DRIFT_OK) {
        return r;
    }
    drift_shadow_map *map = drift_alloc(ctx, sizeof(drift_shadow_map));
    if (!map) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    map->directional = light->type == DRIFT_LIGHT_DIRECTIONAL;
    map->size = params->size;
    map->bias_texels = params->bias_texels;
    map->radius = light->radius;
    map->centre = light->centre;
    build_job job = { .map = map, .accel = accel, .light = light };
    if (map->directional) {
        setup_orthographic(map, scene, light->direction);
        map->slot_count = 1;
        job.tmin = 0.0f;
    } else {
        choose_faces(map, light, job.face_of_slot);
        // The same scale-aware epsilon as drift_offset_origin.
        float magnitude =
            fmaxf(fabsf(map->centre.x), fmaxf(fabsf(map->centre.y), fabsf(map->centre.z)));
        job.tmin = 3e-5f * fmaxf(1.0f, magnitude);
    }
    make_disk_taps(map->search_taps, 4, 4);
    make_disk_taps(map->filter_taps, 8, 4);
    size_t rows = (size_t)map->slot_count * (size_t)map->size, bytes;
    if (!drift_size_mul(rows * (size_t)map->size, sizeof(float), &bytes) ||
        !(map->depth = drift_alloc(ctx, bytes))) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_OUT_OF_MEMORY, NULL, 0,
                  "shadow map: %u faces of %d^2 texels do not fit", map->slot_count, map->size);
        drift_shadow_map_destroy(ctx, map);
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    atomic_init(&job.rays, 0);
    drift_parallel_for(ctx, rows, 4, fill_rows, &job);
    if (build_min_mip(ctx, map) != DRIFT_OK) {
        drift_shadow_map_destroy(ctx, map);
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    if (out_rays) {
        *out_rays += atomic_load(&job.rays);
    }
    *out_map = map;
    return DRIFT_OK;
}

void drift_shadow_map_destroy(drift_context *ctx, drift_shadow_map *map)
{
    if (!map) {
        return;
    }
    drift_free(ctx, map->depth);
    drift_free(ctx, map->min_mip);
    drift_free(ctx, map);
}

// --- TAPS ---

// Normal offset (Holbert 2011): the lookup point moves this many texel footprints along the
// normal toward the light, which removes the acne left where the receiver plane is nearly
// edge-on to the light's centre (there the plane's depth is ill-conditioned and capped).
#define NORMAL_OFFSET_TEXELS 1.0f

static drift_vec3 offset_along_normal(drift_vec3 p, drift_vec3 n, drift_vec3 to_light,
                                      float footprint)
{
    if (drift_vec3_is_zero(n)) {
        return p;
    }
    n = drift_vec3_normalize(n);
    if (drift_vec3_dot(n, to_light) < 0.0f) {
        n = drift_vec3_neg(n);
    }
    return drift_vec3_fma(p, n, NORMAL_OFFSET_TEXELS * footprint);
}

static drift_shadow_receiver cube_receiver(const drift_shadow_map *map, drift_vec3 p, drift_vec3 n)
{
    drift_shadow_receiver rec = { 0 };
    drift_vec3 to_centre = drift_vec3_sub(map->centre, p);
    // The footprint at the receiver: the face-centre texel angle times the distance.
    float footprint = 2.0f / (float)map->size * drift_vec3_length(to_centre);
    p = offset_along_normal(p, n, to_centre, footprint);
    drift_vec3 d = drift_vec3_sub(p, map->centre);
    rec.depth = drift_vec3_length(d);
    rec.dir = rec.depth > 0.0f ? drift_vec3_scale(d, 1.0f / rec.depth)
                               : drift_vec3_make(0.0f, -1.0f, 0.0f);
    rec.n = drift_vec3_is_zero(n) ? drift_vec3_neg(rec.dir) : drift_vec3_normalize(n);
    if (drift_vec3_dot(rec.n, rec.dir) > 0.0f) {
        rec.n = drift_vec3_neg(rec.n); // as drift_offset_origin: the side the light is on
    }
    int face = drift_shadow_map_major_face(rec.dir);
    int a = face / 2;
    float major = fabsf(drift_shadow_map_axis(rec.dir, a));
    float u = drift_shadow_map_axis(rec.dir, (a + 1) % 3) / major,
          v = drift_shadow_map_axis(rec.dir, (a + 2) % 3) / major;
    // Tangents along the face's u axis and its perpendicular: |dir . e_b| <= 1/sqrt(2),
    // so the projection never degenerates.
    drift_vec3 eb = axis_vec3((a + 1) % 3, 1.0f);
    rec.t1 = drift_vec3_normalize(drift_vec3_fma(eb, rec.dir, -drift_vec3_dot(eb, rec.dir)));
    rec.t2 = drift_vec3_cross(rec.dir, rec.t1);
    rec.texel = cube_texel_angle(u, v, map->size);
    rec.bias = map->bias_texels * rec.texel * rec.depth;
    return rec;
}

static drift_shadow_receiver ortho_receiver(const drift_shadow_map *map, drift_vec3 p, drift_vec3 n)
{
    drift_shadow_receiver rec = { 0 };
    p = offset_along_normal(p, n, drift_vec3_neg(map->frame.z), map->texel_size);
    drift_vec3 local = drift_frame_to_local(&map->frame, drift_vec3_sub(p, map->origin));
    rec.x = local.x;
    rec.y = local.y;
    rec.depth = local.z;
    rec.n = drift_vec3_is_zero(n) ? drift_vec3_make(0.0f, 0.0f, -1.0f)
                                  : drift_frame_to_local(&map->frame, drift_vec3_normalize(n));
    if (rec.n.z > 0.0f) {
        rec.n = drift_vec3_neg(rec.n); // face the light, which shines along +z
    }
    rec.texel = map->texel_size;
    rec.bias = map->bias_texels * map->texel_size;
    return rec;
}

drift_shadow_receiver drift_shadow_map_receiver(const drift_shadow_map *map, drift_vec3 p,
                                                drift_vec3 n)
{
    return map->directional ? ortho_receiver(map, p, n) : cube_receiver(map, p, n);
}

// The receiver's depth along another texel's ray, `lateral` scene units away: where that
// ray meets the receiver's tangent plane (plane_depth), with the change from the receiver's
// own depth capped at a slope of MAX_RECEIVER_SLOPE. A ray that never meets the plane takes
// the cap.
static float receiver_depth(const drift_shadow_receiver *rec, float plane_depth, bool meets_plane,
                            float lateral)
{
    float cap = MAX_RECEIVER_SLOPE * lateral;
    float change = meets_plane ? plane_depth - rec->depth : cap;
    return rec->depth + drift_clampf(change, -cap, cap);
}

static drift_shadow_texel cube_texel(const drift_shadow_map *map, const drift_shadow_receiver *rec,
                                     float ox, float oy)
{
    drift_vec3 d = drift_vec3_fma(drift_vec3_fma(rec->dir, rec->t1, ox), rec->t2, oy);
    drift_shadow_texel t = { .stored = INFINITY, .face = drift_shadow_map_major_face(d) };
    int slot = map->face_slot[t.face];
    if (slot < 0) {
        // Behind a one-sided light: it sends nothing there, so nothing can block it.
        return t;
    }
    int a = t.face / 2;
    float major = fabsf(drift_shadow_map_axis(d, a));
    t.x = drift_shadow_map_texel_index(drift_shadow_map_axis(d, (a + 1) % 3) / major, map->size);
    t.y = drift_shadow_map_texel_index(drift_shadow_map_axis(d, (a + 2) % 3) / major, map->size);
    size_t size = (size_t)map->size;
    t.stored = map->depth[((size_t)slot * size + (size_t)t.y) * size + (size_t)t.x];
    return t;
}

// The receiver plane's depth along the ray through the tap's texel centre.
static float cube_receiver_at(const drift_shadow_map *map, const drift_shadow_receiver *rec,
                              const drift_shadow_texel *t)
{
    if (map->face_slot[t->face] < 0) {
        return rec->depth;
    }
    // Plane through p with normal n (toward the centre): a ray from the centre along unit dc
    // meets it at t = h / (-n . dc), h = n . (centre - p) = -(n . dir) depth.
    drift_vec3 dc = drift_vec3_normalize(
        face_direction(t->face, texel_centre(t->x, map->size), texel_centre(t->y, map->size)));
    float h = -drift_vec3_dot(rec->n, rec->dir) * rec->depth;
    float cos_c = -drift_vec3_dot(rec->n, dc);
    float lateral = drift_vec3_length(drift_vec3_sub(dc, rec->dir)) * rec->depth;
    return receiver_depth(rec, h / cos_c, cos_c > 0.0f, lateral);
}

static drift_shadow_texel ortho_texel(const drift_shadow_map *map, const drift_shadow_receiver *rec,
                                      float ox, float oy)
{
    drift_shadow_texel t = { .stored = INFINITY, .face = -1 };
    float fx = (rec->x + ox) / map->texel_size, fy = (rec->y + oy) / map->texel_size;
    if (!(fx >= 0.0f && fy >= 0.0f && fx < (float)map->size && fy < (float)map->size)) {
        return t; // outside the scene: nothing there
    }
    t.face = 0;
    t.x = (int32_t)fx;
    t.y = (int32_t)fy;
    t.stored = map->depth[(size_t)t.y * (size_t)map->size + (size_t)t.x];
    return t;
}

static float ortho_receiver_at(const drift_shadow_map *map, const drift_shadow_receiver *rec,
                               const drift_shadow_texel *t)
{
    if (t->face < 0) {
        return rec->depth;
    }
    // Plane n . (q - p) = 0 in map coordinates: dz = -(n.x dx + n.y dy) / n.z.
    float dx = ((float)t->x + 0.5f) * map->texel_size - rec->x;
    float dy = ((float)t->y + 0.5f) * map->texel_size - rec->y;
    float rise = -(rec->n.x * dx + rec->n.y * dy);
    float run = rec->n.z;
    bool meets = run < 0.0f;
    float plane = meets ? rec->depth + rise / run : rec->depth;
    return receiver_depth(rec, plane, meets, sqrtf(dx * dx + dy * dy));
}

drift_shadow_texel drift_shadow_map_tap_lands(const drift_shadow_map *map,
                                              const drift_shadow_receiver *rec, float ox, float oy)
{
    return map->directional ? ortho_texel(map, rec, ox, oy) : cube_texel(map, rec, ox, oy);
}

float drift_shadow_map_receiver_at(const drift_shadow_map *map, const drift_shadow_receiver *rec,
                                   const drift_shadow_texel *t)
{
    return map->directional ? ortho_receiver_at(map, rec, t) : cube_receiver_at(map, rec, t);
}

drift_shadow_tap drift_shadow_map_tap(const drift_shadow_map *map, const drift_shadow_receiver *rec,
                                      float ox, float oy)
{
    drift_shadow_texel t = drift_shadow_map_tap_lands(map, rec, ox, oy);
    return (drift_shadow_tap){ t.stored, drift_shadow_map_receiver_at(map, rec, &t) };
}

bool drift_shadow_map_tap_lit(const drift_shadow_receiver *rec, drift_shadow_tap t)
{
    return t.stored >= t.receiver - rec->bias;
}

// --- LOOKUPS ---

// One tap at the receiver itself: the nearest texel.
static float hard_lookup(const drift_shadow_map *map, const drift_shadow_receiver *rec)
{
    return drift_shadow_map_tap_lit(rec, drift_shadow_map_tap(map, rec, 0.0f, 0.0f)) ? 1.0f : 0.0f;
}

float drift_shadow_map_blind_length(const drift_shadow_map *map, drift_vec3 p, drift_vec3 n)
{
    drift_shadow_receiver rec = drift_shadow_map_receiver(map, p, n);
    // The lookup moved p NORMAL_OFFSET_TEXELS footprints along n, then compared with the bias.
    return rec.bias + NORMAL_OFFSET_TEXELS * rec.texel * (map->directional ? 1.0f : rec.depth);
}

float drift_shadow_map_hard(const drift_shadow_map *map, drift_vec3 p, drift_vec3 n)
{
    drift_shadow_receiver rec = drift_shadow_map_receiver(map, p, n);
    return hard_lookup(map, &rec);
}

// Box of kernel x kernel taps a texel apart, centred on the receiver.
static float pcf_box(const drift_shadow_map *map, const drift_shadow_receiver *rec, int32_t kernel)
{
    float half = 0.5f * (float)(kernel - 1);
    int32_t lit = 0;
    for (int32_t j = 0; j < kernel; ++j) {
        for (int32_t i = 0; i < kernel; ++i) {
            float ox = ((float)i - half) * rec->texel, oy = ((float)j - half) * rec->texel;
            lit += drift_shadow_map_tap_lit(rec, drift_shadow_map_tap(map, rec, ox, oy));
        }
    }
    return (float)lit / (float)(kernel * kernel);
}

float drift_shadow_map_pcf(const drift_shadow_map *map, drift_vec3 p, drift_vec3 n, int32_t kernel)
{
    drift_shadow_receiver rec = drift_shadow_map_receiver(map, p, n);
    return pcf_box(map, &rec, kernel < 1 ? 1 : kernel);
}

// --- PCSS (Fernando 2005, "Percentage-Closer Soft Shadows") ---

typedef struct rotation {
    float c, s;
} rotation;

static rotation make_rotation(uint32_t hash)
{
    float angle = 2.0f * DRIFT_PI * drift_u32_to_unit(drift_hash_u32(hash));
    return (rotation){ cosf(angle), sinf(angle) };
}

static drift_vec2 rotate(rotation r, drift_vec2 v, float radius)
{
    return (drift_vec2){ (r.c * v.x - r.s * v.y) * radius, (r.s * v.x + r.c * v.y) * radius };
}

float drift_shadow_map_max_radius(const drift_shadow_map *map)
{
    return map->directional ? MAX_ORTHO_RADIUS * map->texel_size * (float)map->size
                            : MAX_CUBE_RADIUS;
}

// Region where blockers of this receiver can be (offset units). The cone from the receiver
// to the light (radius L) is L (d_r - z) / d_r wide at distance z from the light; taken at
// a near plane z = near and seen from the centre, that is L (d_r - near) / (d_r near).
// near = PCSS_NEAR_FRACTION d_r (and at least L: nothing blocks inside the light): the
// search finds every blocker in the far three quarters of the way to the receiver and
// trims the outer penumbra of blockers closer to the light, the usual PCSS trade-off.
// Directional lights (L an angle, map depth from the near plane) have a cone L (d_r - z)
// wide, widest at the near plane: L d_r.
static float pcss_search_radius(const drift_shadow_map *map, const drift_shadow_receiver *rec)
{
    float L = map->radius, d_r = rec->depth, radius;
    if (map->directional) {
        radius = L * d_r;
    } else {
        float near = fmaxf(PCSS_NEAR_FRACTION * d_r, L);
        radius = d_r > near ? L * (d_r - near) / (d_r * near) : 0.0f;
    }
    return drift_clampf(radius, rec->texel, drift_shadow_map_max_radius(map));
}

// Filter radius in offset units for a mean blocker depth d_b: the penumbra width at the
// receiver w = L (d_r - d_b) / d_b (directional: L (d_r - d_b)), as an angle w / d_r for
// cube maps.
static float pcss_filter_radius(const drift_shadow_map *map, const drift_shadow_receiver *rec,
                                float d_b)
{
    float L = map->radius, d_r = rec->depth, radius;
    if (map->directional) {
        radius = L * (d_r - d_b);
    } else {
        radius = d_b > 0.0f ? L * (d_r - d_b) / (d_b * d_r) : drift_shadow_map_max_radius(map);
    }
    return drift_clampf(radius, 0.0f, drift_shadow_map_max_radius(map));
}

float drift_shadow_map_pcss(const drift_shadow_map *map, drift_vec3 p, drift_vec3 n,
                            uint32_t rotation_hash)
{
    drift_shadow_receiver rec = drift_shadow_map_receiver(map, p, n);
    if (!(map->radius > 0.0f)) {
        return hard_lookup(map, &rec); // a point light casts no penumbra
    }
    rotation rot = make_rotation(rotation_hash);
    float search = pcss_search_radius(map, &rec);
    float blocker_sum = 0.0f;
    int32_t blockers = 0;
    for (int i = 0; i < SEARCH_TAPS; ++i) {
        drift_vec2 o = rotate(rot, map->search_taps[i], search);
        drift_shadow_tap t = drift_shadow_map_tap(map, &rec, o.x, o.y);
        if (!drift_shadow_map_tap_lit(&rec, t)) {
            blocker_sum += t.stored;
            blockers++;
        }
    }
    if (blockers == 0) {
        return 1.0f;
    }
    float filter = pcss_filter_radius(map, &rec, blocker_sum / (float)blockers);
    int32_t lit = 0;
    for (int i = 0; i < FILTER_TAPS; ++i) {
        drift_vec2 o = rotate(rot, map->filter_taps[i], filter);
        lit += drift_shadow_map_tap_lit(&rec, drift_shadow_map_tap(map, &rec, o.x, o.y));
    }
    return (float)lit / (float)FILTER_TAPS;
}
