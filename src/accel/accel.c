// The accel: an Embree device and scene over a committed drift_scene. Meshes are shared
// with Embree (no copies); area-light shapes get small buffers of their own.
#include "drift/accel.h"

#include "drift/math.h"

#include <embree3/rtcore.h>
#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <string.h>

// Geometry IDs: mesh i is geometry i, so a hit maps to its mesh without a table. The light
// shapes follow, one geometry per shape kind (all quads, all disks, all spheres).
enum shape_kind {
    SHAPE_QUAD,
    SHAPE_DISK,
    SHAPE_SPHERE,
    SHAPE_COUNT
};

struct drift_accel {
    drift_context *ctx;
    const drift_scene *scene;
    RTCDevice device;
    RTCScene rtc_scene;
    uint32_t mesh_count;
    // Copy of meshes[i].first_light: saves a 100-byte-stride load through the scene per hit.
    uint32_t *mesh_first_light;
    // Per shape kind: light index of each Embree primitive (quads have two per light).
    uint32_t *shape_prim_light[SHAPE_COUNT];
    uint32_t shape_geom[SHAPE_COUNT]; // geometry ID of each kind, or RTC_INVALID_GEOMETRY_ID
    // Memory monitor (only installed with a limit).
    size_t memory_limit;
    atomic_llong memory_used;
    // First Embree error code seen by the error callback (RTC_ERROR_NONE if none).
    atomic_int first_error;
};

drift_accel_desc drift_accel_desc_resolve(const drift_accel_desc *desc)
{
    drift_accel_desc d = desc ? *desc : (drift_accel_desc){ 0 };
    return d;
}

static const char *rtc_error_name(enum RTCError code)
{
    switch (code) {
    case RTC_ERROR_NONE:
        return "none";
    case RTC_ERROR_UNKNOWN:
        return "unknown";
    case RTC_ERROR_INVALID_ARGUMENT:
        return "invalid argument";
    case RTC_ERROR_INVALID_OPERATION:
        return "invalid operation";
    case RTC_ERROR_OUT_OF_MEMORY:
        return "out of memory";
    case RTC_ERROR_UNSUPPORTED_CPU:
        return "unsupported cpu";
    case RTC_ERROR_CANCELLED:
        return "cancelled";
    }
    return "unrecognised error";
}

static drift_result result_of(enum RTCError code)
{
    if (code == RTC_ERROR_NONE) {
        return DRIFT_OK;
    }
    return code == RTC_ERROR_OUT_OF_MEMORY ? DRIFT_ERR_OUT_OF_MEMORY : DRIFT_ERR_EMBREE;
}

// Embree calls this from whichever thread hit the error; drift_log is thread-safe.
static void on_embree_error(void *user, enum RTCError code, const char *message)
{
    drift_accel *accel = user;
    int none = RTC_ERROR_NONE;
    atomic_compare_exchange_strong(&accel->first_error, &none, (int)code);
    drift_log(accel->ctx, DRIFT_LOG_ERROR, result_of(code), __FILE__, __LINE__, "embree: %s (%s)",
              message ? message : "no message", rtc_error_name(code));
}

// Embree reports every allocation (bytes > 0) and release (bytes < 0); returning false
// fails the allocation, and Embree then aborts the build with RTC_ERROR_OUT_OF_MEMORY.
static bool on_embree_memory(void *user, ssize_t bytes, bool post)
{
    drift_accel *accel = user;
    (void)post;
    long long used = atomic_fetch_add(&accel->memory_used, (long long)bytes) + (long long)bytes;
    if (bytes > 0 && used > (long long)accel->memory_limit) {
        // Embree does not report the release of a refused allocation: undo it here.
        atomic_fetch_sub(&accel->memory_used, (long long)bytes);
        return false;
    }
    return true;
}

// Reads (and clears) the device's pending error; logs it when the callback did not.
static drift_result check_device(drift_accel *accel, const char *what)
{
    enum RTCError code = rtcGetDeviceError(accel->device);
    int seen = atomic_load(&accel->first_error);
    if (code == RTC_ERROR_NONE && seen != RTC_ERROR_NONE) {
        code = (enum RTCError)seen;
    }
    // The callback has logged Embree's own message already; only a silent error is logged here.
    if (code != RTC_ERROR_NONE && seen == RTC_ERROR_NONE) {
        drift_log(accel->ctx, DRIFT_LOG_ERROR, result_of(code), __FILE__, __LINE__,
                  "embree failed during %s (%s)", what, rtc_error_name(code));
    }
    return result_of(code);
}

// A random number of one ray meeting one mesh's surface: the same for the same ray (so a
// pixel's image does not depend on the thread count or on how often Embree asks), different
// for the next sample's or bounce's ray, which starts or points elsewhere or carries another
// seed (drift_ray.seed, in Embree's id). It keys on the mesh and the hit's distance, not the
// triangle: a ray through a shared edge is offered both triangles, and two numbers gave it two
// chances (a pixel-centre ray on a quad's diagonal met a veil of opacity 0.5 three times in
// four). The distance's low 12 mantissa bits are dropped so both offers agree; the surfaces
// of one mesh a ray meets further on (a closed veil's far side) get numbers of their own.
// Embree's RTCRayN layout (rtcore_ray.h; its accessors are C++ only): org x, y, z, tnear, dir
// x, y, z, time, tfar (the candidate hit's distance in a filter), mask, id, each N words in a
// row.
static float ray_hit_uniform(const struct RTCRayN *ray, unsigned n, unsigned i, uint32_t mesh)
{
    static const unsigned fields[8] = { 0, 1, 2, 4, 5, 6, 10, 8 }; // org, dir, id, tfar
    const uint32_t *words = (const uint32_t *)(const void *)ray;
    uint32_t h = drift_hash_u32(mesh);
    for (int k = 0; k < 8; ++k) {
        uint32_t bits = words[fields[k] * n + i];
        h = drift_hash_combine(h, fields[k] == 8 ? bits >> 12 : bits);
    }
    return (float)(h >> 8) * 0x1p-24f;
}

// Embree's context with how this query treats veils (drift_accel_veils): the filter below
// reads it back from the context it is given.
typedef struct veils_context {
    struct RTCIntersectContext embree; // first: Embree passes a pointer to it
    drift_accel_veils veils;
} veils_context;

// Embree's filter for meshes whose material is not opaque (drift_alpha_mode): a candidate hit
// where the surface is not there is dropped and the ray goes on, for closest hits and shadow
// rays alike.
static void coverage_filter(const struct RTCFilterFunctionNArguments *args)
{
    const drift_accel *accel = args->geometryUserPtr;
    drift_accel_veils veils = ((const veils_context *)(const void *)args->context)->veils;
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] != -1) {
            continue;
        }
        const float *hit = (const float *)(const void *)args->hit;
        const uint32_t *ids = (const uint32_t *)(const void *)args->hit;
        uint32_t mesh = ids[6 * args->N + i], prim = ids[5 * args->N + i];
        float u = hit[3 * args->N + i], v = hit[4 * args->N + i];
        float xi = ray_hit_uniform(args->ray, args->N, i, mesh);
        bool veil = accel->scene->materials[accel->scene->meshes[mesh].material].alpha_mode ==
                    DRIFT_ALPHA_BLEND;
        if (veil && veils != DRIFT_VEILS_STOCHASTIC) {
            xi = veils == DRIFT_VEILS_SKIP ? 2.0f : -1.0f; // never, or always, below opacity
        }
        if (!drift_scene_covers(accel->scene, mesh, prim, u, v, xi)) {
            args->valid[i] = 0;
        }
    }
}

static drift_result add_mesh(drift_accel *accel, const drift_mesh *mesh, uint32_t id)
{
    RTCGeometry geom = rtcNewGeometry(accel->device, RTC_GEOMETRY_TYPE_TRIANGLE);
    if (!geom) {
        return check_device(accel, "rtcNewGeometry");
    }
    // The scene pads positions by one float, which covers Embree's 16-byte load of the
    // last vertex (buffer_padding.md); so the buffer can be shared as it is.
    rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, mesh->positions,
                               0, 3 * sizeof(float), mesh->vertex_count);
    rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, mesh->indices, 0,
                               3 * sizeof(uint32_t), mesh->triangle_count);
    if (accel->scene->materials[mesh->material].alpha_mode != DRIFT_ALPHA_OPAQUE) {
        rtcSetGeometryUserData(geom, accel);
        rtcSetGeometryIntersectFilterFunction(geom, coverage_filter);
        rtcSetGeometryOccludedFilterFunction(geom, coverage_filter);
    }
    rtcCommitGeometry(geom);
    rtcAttachGeometryByID(accel->rtc_scene, geom, id);
    rtcReleaseGeometry(geom);
    return check_device(accel, "mesh setup");
}

static void put3(float *dst, drift_vec3 v)
{
    dst[0] = v.x;
    dst[1] = v.y;
    dst[2] = v.z;
}

// One geometry for all lights of one shape kind; prims[i] gets the light of primitive i.
static drift_result add_shapes(drift_accel *accel, enum shape_kind kind, uint32_t id)
{
    const drift_scene *scene = accel->scene;
    static const drift_light_type light_type[SHAPE_COUNT] = { DRIFT_LIGHT_QUAD, DRIFT_LIGHT_DISK,
                                                              DRIFT_LIGHT_SPHERE };
    uint32_t count = 0;
    for (uint32_t i = 0; i < scene->light_count; ++i) {
        count += scene->lights[i].type == light_type[kind];
    }
    accel->shape_geom[kind] = RTC_INVALID_GEOMETRY_ID;
    if (count == 0) {
        return DRIFT_OK;
    }
    uint32_t prims_per_light = kind == SHAPE_QUAD ? 2 : 1;
    uint32_t *prim_light =
        drift_alloc(accel->ctx, (size_t)count * prims_per_light * sizeof(uint32_t));
    if (!prim_light) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    accel->shape_prim_light[kind] = prim_light;

    enum RTCGeometryType type = kind == SHAPE_QUAD   ? RTC_GEOMETRY_TYPE_TRIANGLE
                                : kind == SHAPE_DISK ? RTC_GEOMETRY_TYPE_ORIENTED_DISC_POINT
                                                     : RTC_GEOMETRY_TYPE_SPHERE_POINT;
    RTCGeometry geom = rtcNewGeometry(accel->device, type);
    if (!geom) {
        return check_device(accel, "rtcNewGeometry");
    }
    // Embree-allocated buffers (rtcSetNewGeometryBuffer) come padded and are freed with it.
    float *vertices = NULL, *normals = NULL;
    uint32_t *indices = NULL;
    if (kind == SHAPE_QUAD) {
        vertices = rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                           3 * sizeof(float), (size_t)count * 4);
        indices = rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                          3 * sizeof(uint32_t), (size_t)count * 2);
    } else {
        vertices = rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4,
                                           4 * sizeof(float), count);
        if (kind == SHAPE_DISK) {
            normals = rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_NORMAL, 0, RTC_FORMAT_FLOAT3,
                                              3 * sizeof(float), count);
        }
    }
    if (!vertices || (kind == SHAPE_QUAD && !indices) || (kind == SHAPE_DISK && !normals)) {
        rtcReleaseGeometry(geom);
        drift_result r = check_device(accel, "light shape buffers");
        return r != DRIFT_OK ? r : DRIFT_ERR_OUT_OF_MEMORY;
    }
    uint32_t k = 0;
    for (uint32_t i = 0; i < scene->light_count; ++i) {
        const drift_light *l = &scene->lights[i];
        if (l->type != light_type[kind]) {
            continue;
        }
        if (kind == SHAPE_QUAD) {
            // Corners c, c+u, c+u+v, c+v; both triangles wind so that ng = u x v.
            drift_vec3 c = l->position;
            put3(vertices + 12 * (size_t)k, c);
            put3(vertices + 12 * (size_t)k + 3, drift_vec3_add(c, l->edge_u));
            put3(vertices + 12 * (size_t)k + 6,
                 drift_vec3_add(drift_vec3_add(c, l->edge_u), l->edge_v));
            put3(vertices + 12 * (size_t)k + 9, drift_vec3_add(c, l->edge_v));
            uint32_t *tri = indices + 6 * (size_t)k;
            uint32_t base = 4 * k;
            tri[0] = base, tri[1] = base + 1, tri[2] = base + 2;
            tri[3] = base, tri[4] = base + 2, tri[5] = base + 3;
            prim_light[2 * k] = prim_light[2 * k + 1] = i;
        } else {
            put3(vertices + 4 * (size_t)k, l->position);
            vertices[4 * (size_t)k + 3] = l->radius;
            if (kind == SHAPE_DISK) {
                put3(normals + 3 * (size_t)k, l->direction); // unit: add_light normalizes it
            }
            prim_light[k] = i;
        }
        k++;
    }
    rtcCommitGeometry(geom);
    rtcAttachGeometryByID(accel->rtc_scene, geom, id);
    rtcReleaseGeometry(geom);
    accel->shape_geom[kind] = id;
    return check_device(accel, "light shape setup");
}

static drift_result build(drift_accel *accel, const drift_accel_desc *desc)
{
    drift_context *ctx = accel->ctx;
    const drift_scene *scene = accel->scene;
    char config[64];
    snprintf(config, sizeof(config), "threads=%d", drift_context_thread_count(ctx));
    accel->device = rtcNewDevice(config);
    if (!accel->device) {
        enum RTCError code = rtcGetDeviceError(NULL);
        drift_log(ctx, DRIFT_LOG_ERROR, result_of(code), __FILE__, __LINE__,
                  "embree could not create a device with \"%s\" (%s)", config,
                  rtc_error_name(code));
        return code == RTC_ERROR_NONE ? DRIFT_ERR_EMBREE : result_of(code);
    }
    rtcSetDeviceErrorFunction(accel->device, on_embree_error, accel);
    if (desc->memory_limit_bytes > 0) {
        rtcSetDeviceMemoryMonitorFunction(accel->device, on_embree_memory, accel);
    }

    accel->rtc_scene = rtcNewScene(accel->device);
    if (!accel->rtc_scene) {
        return check_device(accel, "rtcNewScene");
    }
    rtcSetSceneBuildQuality(accel->rtc_scene, desc->quality == DRIFT_ACCEL_QUALITY_FAST_BUILD
                                                  ? RTC_BUILD_QUALITY_MEDIUM
                                                  : RTC_BUILD_QUALITY_HIGH);

    accel->mesh_count = scene->mesh_count;
    accel->mesh_first_light = drift_alloc(ctx, ((size_t)scene->mesh_count + 1) * sizeof(uint32_t));
    if (!accel->mesh_first_light) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    for (uint32_t m = 0; m < scene->mesh_count; ++m) {
        accel->mesh_first_light[m] = scene->meshes[m].first_light;
        drift_result r = add_mesh(accel, &scene->meshes[m], m);
        if (r != DRIFT_OK) {
            return r;
        }
    }
    for (int kind = 0; kind < SHAPE_COUNT; ++kind) {
        drift_result r =
            add_shapes(accel, (enum shape_kind)kind, scene->mesh_count + (uint32_t)kind);
        if (r != DRIFT_OK) {
            return r;
        }
    }
    rtcCommitScene(accel->rtc_scene);
    return check_device(accel, "rtcCommitScene");
}

drift_result drift_accel_create(drift_context *ctx, const drift_scene *scene,
                                const drift_accel_desc *desc, drift_accel **out_accel)
{
    if (!out_accel) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    *out_accel = NULL;
    drift_accel_desc d = drift_accel_desc_resolve(desc);
    if (!ctx || !scene || (unsigned)d.quality >= DRIFT_ACCEL_QUALITY_COUNT) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, __FILE__, __LINE__,
                  "drift_accel_create needs a context, a scene and a valid quality");
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    if (!scene->committed) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, __FILE__, __LINE__,
                  "the scene must be committed (drift_scene_commit) before building an accel");
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    // Geometry IDs are mesh indices followed by the shape kinds; Embree IDs are unsigned.
    if (scene->mesh_count > UINT32_MAX - SHAPE_COUNT - 1) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    drift_accel *accel = drift_alloc(ctx, sizeof(drift_accel));
    if (!accel) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    accel->ctx = ctx;
    accel->scene = scene;
    accel->memory_limit = d.memory_limit_bytes;
    atomic_init(&accel->memory_used, 0);
    atomic_init(&accel->first_error, RTC_ERROR_NONE);
    for (int k = 0; k < SHAPE_COUNT; ++k) {
        accel->shape_geom[k] = RTC_INVALID_GEOMETRY_ID;
    }
    drift_result r = build(accel, &d);
    if (r != DRIFT_OK) {
        drift_accel_destroy(accel);
        return r;
    }
    *out_accel = accel;
    return DRIFT_OK;
}

void drift_accel_destroy(drift_accel *accel)
{
    if (!accel) {
        return;
    }
    drift_context *ctx = accel->ctx;
    if (accel->rtc_scene) {
        rtcReleaseScene(accel->rtc_scene);
    }
    if (accel->device) {
        rtcReleaseDevice(accel->device);
    }
    for (int k = 0; k < SHAPE_COUNT; ++k) {
        drift_free(ctx, accel->shape_prim_light[k]);
    }
    drift_free(ctx, accel->mesh_first_light);
    drift_free(ctx, accel);
}

// --- QUERIES ---
//
// These are on every hot path: no validation beyond what Embree does, no branches that
// a well-formed query does not need.

static inline void ray_to_rtc(const drift_ray *ray, struct RTCRay *out)
{
    out->org_x = ray->origin.x;
    out->org_y = ray->origin.y;
    out->org_z = ray->origin.z;
    out->tnear = ray->tmin;
    out->dir_x = ray->dir.x;
    out->dir_y = ray->dir.y;
    out->dir_z = ray->dir.z;
    out->time = 0.0f;
    out->tfar = ray->tmax;
    out->mask = UINT32_MAX;
    out->id = ray->seed;
    out->flags = 0;
}

static inline void rayhit_init(const drift_ray *ray, struct RTCRayHit *rh)
{
    ray_to_rtc(ray, &rh->ray);
    rh->hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh->hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
}

// Light shapes are rare in a scene's hits, so their lookup stays out of the inlined path.
static void fill_shape_hit(const drift_accel *accel, uint32_t geom, uint32_t prim, drift_hit *hit)
{
    uint32_t kind = geom - accel->mesh_count;
    hit->mesh = DRIFT_INVALID_INDEX;
    hit->light = accel->shape_prim_light[kind][prim];
    hit->prim = kind == SHAPE_QUAD ? (prim & 1u) : 0u;
}

// Maps Embree's (geometry, primitive) to drift's mesh, triangle and light: the one place that
// knows mesh i is geometry i and that light shapes follow the meshes.
static inline void fill_hit_ids(const drift_accel *accel, uint32_t geom, uint32_t prim,
                                drift_hit *hit)
{
    if (geom < accel->mesh_count) {
        uint32_t first = accel->mesh_first_light[geom];
        hit->mesh = geom;
        hit->prim = prim;
        hit->light = first == DRIFT_INVALID_INDEX ? DRIFT_INVALID_INDEX : first + prim;
    } else {
        fill_shape_hit(accel, geom, prim, hit);
    }
}

static inline void fill_hit(const drift_accel *accel, const struct RTCRayHit *rh, drift_hit *hit)
{
    hit->t = rh->ray.tfar;
    hit->u = rh->hit.u;
    hit->v = rh->hit.v;
    hit->ng = (drift_vec3){ rh->hit.Ng_x, rh->hit.Ng_y, rh->hit.Ng_z };
    fill_hit_ids(accel, rh->hit.geomID, rh->hit.primID, hit);
}

static inline void fill_miss(drift_hit *hit)
{
    hit->t = INFINITY;
    hit->u = hit->v = 0.0f;
    hit->mesh = hit->prim = hit->light = DRIFT_INVALID_INDEX;
    hit->ng = (drift_vec3){ 0.0f, 0.0f, 0.0f };
}

static veils_context make_context(drift_accel_veils veils, bool coherent)
{
    veils_context c;
    rtcInitIntersectContext(&c.embree);
    if (coherent) {
        c.embree.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    }
    c.veils = veils;
    return c;
}

bool drift_accel_intersect(const drift_accel *accel, const drift_ray *ray, drift_hit *out_hit)
{
    return drift_accel_intersect_veils(accel, ray, DRIFT_VEILS_STOCHASTIC, out_hit);
}

bool drift_accel_intersect_veils(const drift_accel *accel, const drift_ray *ray,
                                 drift_accel_veils veils, drift_hit *out_hit)
{
    veils_context context = make_context(veils, false);
    struct RTCRayHit rh;
    rayhit_init(ray, &rh);
    rtcIntersect1(accel->rtc_scene, &context.embree, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) {
        return false;
    }
    fill_hit(accel, &rh, out_hit);
    return true;
}

bool drift_accel_occluded(const drift_accel *accel, const drift_ray *ray)
{
    veils_context context = make_context(DRIFT_VEILS_STOCHASTIC, false);
    struct RTCRay r;
    ray_to_rtc(ray, &r);
    rtcOccluded1(accel->rtc_scene, &context.embree, &r);
    // Embree marks an occluded ray by setting tfar to -inf; an empty segment (tmax < tmin,
    // e.g. a shadow ray that starts inside the sphere light it aims at) keeps its own tfar.
    return r.tfar == -INFINITY;
}

// Coherent batches go to Embree as 16-wide packets: on this Embree build (AVX-512) they
// traced camera rays 1.0-1.35x as fast as the stream API (rtcIntersect1M) and ~4x as fast
// as single rays (drift bench rays --variants; docs/benchmarks.md).
static inline void packet_load(const drift_ray *rays, uint32_t n, struct RTCRay16 *p, int *valid)
{
    for (uint32_t i = 0; i < 16; ++i) {
        // Lanes past the end repeat ray 0 (finite data) and are masked off.
        const drift_ray *r = &rays[i < n ? i : 0];
        valid[i] = i < n ? -1 : 0;
        p->org_x[i] = r->origin.x;
        p->org_y[i] = r->origin.y;
        p->org_z[i] = r->origin.z;
        p->tnear[i] = r->tmin;
        p->dir_x[i] = r->dir.x;
        p->dir_y[i] = r->dir.y;
        p->dir_z[i] = r->dir.z;
        p->time[i] = 0.0f;
        p->tfar[i] = r->tmax;
        p->mask[i] = UINT32_MAX;
        p->id[i] = r->seed;
        p->flags[i] = 0;
    }
}

void drift_accel_intersect_coherent(const drift_accel *accel, const drift_ray *rays,
                                    drift_hit *hits, uint32_t count)
{
    drift_accel_intersect_coherent_veils(accel, rays, hits, count, DRIFT_VEILS_STOCHASTIC);
}

void drift_accel_intersect_coherent_veils(const drift_accel *accel, const drift_ray *rays,
                                          drift_hit *hits, uint32_t count, drift_accel_veils veils)
{
    veils_context context = make_context(veils, true);
    struct RTCRayHit16 p;
    // Embree requires the valid mask, like the packet, aligned to the packet size.
    _Alignas(64) int valid[16];
    for (uint32_t begin = 0; begin < count; begin += 16) {
        uint32_t n = count - begin < 16 ? count - begin : 16;
        packet_load(rays + begin, n, &p.ray, valid);
        for (uint32_t i = 0; i < 16; ++i) {
            p.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
            p.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
        }
        rtcIntersect16(valid, accel->rtc_scene, &context.embree, &p);
        for (uint32_t i = 0; i < n; ++i) {
            drift_hit *hit = &hits[begin + i];
            if (p.hit.geomID[i] == RTC_INVALID_GEOMETRY_ID) {
                fill_miss(hit);
                continue;
            }
            hit->t = p.ray.tfar[i];
            hit->u = p.hit.u[i];
            hit->v = p.hit.v[i];
            hit->ng = (drift_vec3){ p.hit.Ng_x[i], p.hit.Ng_y[i], p.hit.Ng_z[i] };
            fill_hit_ids(accel, p.hit.geomID[i], p.hit.primID[i], hit);
        }
    }
}

void drift_accel_occluded_coherent(const drift_accel *accel, const drift_ray *rays,
                                   uint8_t *out_occluded, uint32_t count)
{
    veils_context context = make_context(DRIFT_VEILS_STOCHASTIC, true);
    struct RTCRay16 p;
    // Embree requires the valid mask, like the packet, aligned to the packet size.
    _Alignas(64) int valid[16];
    for (uint32_t begin = 0; begin < count; begin += 16) {
        uint32_t n = count - begin < 16 ? count - begin : 16;
        packet_load(rays + begin, n, &p, valid);
        rtcOccluded16(valid, accel->rtc_scene, &context.embree, &p);
        for (uint32_t i = 0; i < n; ++i) {
            // Embree marks an occluded ray by setting tfar to -inf (not a negative tmax).
            out_occluded[begin + i] = p.tfar[i] == -INFINITY;
        }
    }
}
