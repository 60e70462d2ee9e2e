// drift bench rays: rays per second on one thread through drift's accel (src/accel) and
// through raw Embree calls on an identical Embree scene built here, over the same ray sets:
//   primary  camera rays, coherent batches of one 16x16 tile (intersect_coherent)
//   shadow   from the primary hits toward random points on the first area light, or a point
//            above the scene when there is none (occluded, one ray at a time)
//   bounce   cosine-sampled from the primary hits (intersect, one ray at a time, incoherent)
// The two sides alternate, each repeated, and the best of the repeats counts, to cut noise
// on a shared machine. drift/raw is the wrapper's cost: 1.0 means free.
#include "bench.h"
#include "cli.h"
#include "drift/accel.h"
#include "drift/scene.h"
#include "drift/scene_io.h"

#include <embree3/rtcore.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define TILE      16
#define RAW_CHUNK 64

enum ray_kind {
    KIND_PRIMARY,
    KIND_SHADOW,
    KIND_BOUNCE,
    KIND_COUNT
};

static const char *const kind_names[KIND_COUNT] = { "primary", "shadow", "bounce" };

// What the raw side writes per hit: the same information drift_hit carries.
typedef struct raw_hit {
    float t, u, v;
    uint32_t geom, prim;
    float ng[3];
} raw_hit;

typedef struct rays_options {
    const char *scene;
    long width, height; // 0: the scene camera's size
    double seconds;
    long repeats;
    bool json;
    bool variants;
} rays_options;

typedef struct ray_set {
    drift_ray *rays;
    uint32_t count;
} ray_set;

typedef struct bench_state {
    drift_context *ctx;
    drift_scene *scene;
    drift_accel *accel;
    RTCDevice device;
    RTCScene raw_scene;
    ray_set sets[KIND_COUNT];
    drift_hit *hits;   // drift's output, sized for the largest set
    raw_hit *raw_hits; // raw output
    uint8_t *occluded; // shadow output (both sides)
    int32_t width, height;
} bench_state;

// --- BUILT-IN SCENES ---

// Cornell box, official measured data (Cornell University Program of Computer Graphics,
// /work/shared/scenes/cornell-box/cornell_box_data.txt), millimetres. Quads split (v0 v1 v2),
// (v0 v2 v3), as the data's notes ask (the red wall is not planar).
static const float cornell_quads[][4][3] = {
    // floor, ceiling, back wall: white (0..2)
    { { 552.8f, 0, 0 }, { 0, 0, 0 }, { 0, 0, 559.2f }, { 549.6f, 0, 559.2f } },
    { { 556, 548.8f, 0 }, { 556, 548.8f, 559.2f }, { 0, 548.8f, 559.2f }, { 0, 548.8f, 0 } },
    { { 549.6f, 0, 559.2f }, { 0, 0, 559.2f }, { 0, 548.8f, 559.2f }, { 556, 548.8f, 559.2f } },
    // right wall: green (3)
    { { 0, 0, 559.2f }, { 0, 0, 0 }, { 0, 548.8f, 0 }, { 0, 548.8f, 559.2f } },
    // left wall: red (4)
    { { 552.8f, 0, 0 }, { 549.6f, 0, 559.2f }, { 556, 548.8f, 559.2f }, { 556, 548.8f, 0 } },
    // short block (5..9)
    { { 130, 165, 65 }, { 82, 165, 225 }, { 240, 165, 272 }, { 290, 165, 114 } },
    { { 290, 0, 114 }, { 290, 165, 114 }, { 240, 165, 272 }, { 240, 0, 272 } },
    { { 130, 0, 65 }, { 130, 165, 65 }, { 290, 165, 114 }, { 290, 0, 114 } },
    { { 82, 0, 225 }, { 82, 165, 225 }, { 130, 165, 65 }, { 130, 0, 65 } },
    { { 240, 0, 272 }, { 240, 165, 272 }, { 82, 165, 225 }, { 82, 0, 225 } },
    // tall block (10..14)
    { { 423, 330, 247 }, { 265, 330, 296 }, { 314, 330, 456 }, { 472, 330, 406 } },
    { { 423, 0, 247 }, { 423, 330, 247 }, { 472, 330, 406 }, { 472, 0, 406 } },
    { { 472, 0, 406 }, { 472, 330, 406 }, { 314, 330, 456 }, { 314, 0, 456 } },
    { { 314, 0, 456 }, { 314, 330, 456 }, { 265, 330, 296 }, { 265, 0, 296 } },
    { { 265, 0, 296 }, { 265, 330, 296 }, { 423, 330, 247 }, { 423, 0, 247 } },
};

static drift_result add_quads(drift_scene *scene, const char *name, uint32_t first, uint32_t count,
                              uint32_t material)
{
    float p[15 * 12];
    uint32_t idx[15 * 6];
    for (uint32_t q = 0; q < count; ++q) {
        memcpy(p + 12 * q, cornell_quads[first + q], sizeof(cornell_quads[0]));
        const uint32_t tri[6] = { 0, 1, 2, 0, 2, 3 };
        for (int k = 0; k < 6; ++k) {
            idx[6 * q + (uint32_t)k] = 4 * q + tri[k];
        }
    }
    return drift_scene_add_mesh(scene,
                                &(drift_mesh_desc){ .name = name,
                                                    .positions = p,
                                                    .vertex_count = 4 * count,
                                                    .indices = idx,
                                                    .triangle_count = 2 * count,
                                                    .material = material },
                                NULL);
}

static drift_result build_cornell(drift_scene *scene)
{
    uint32_t white, red, green;
    drift_result r =
        drift_scene_add_material(scene,
                                 &(drift_material){ .name = "white",
                                                    .diffuse = { 0.73f, 0.73f, 0.73f },
                                                    .diffuse_texture = DRIFT_INVALID_INDEX },
                                 &white);
    r = r ? r
          : drift_scene_add_material(scene,
                                     &(drift_material){ .name = "red",
                                                        .diffuse = { 0.63f, 0.065f, 0.05f },
                                                        .diffuse_texture = DRIFT_INVALID_INDEX },
                                     &red);
    r = r ? r
          : drift_scene_add_material(scene,
                                     &(drift_material){ .name = "green",
                                                        .diffuse = { 0.14f, 0.45f, 0.091f },
                                                        .diffuse_texture = DRIFT_INVALID_INDEX },
                                     &green);
    r = r ? r : add_quads(scene, "white walls", 0, 3, white);
    r = r ? r : add_quads(scene, "green wall", 3, 1, green);
    r = r ? r : add_quads(scene, "red wall", 4, 1, red);
    r = r ? r : add_quads(scene, "short block", 5, 5, white);
    r = r ? r : add_quads(scene, "tall block", 10, 5, white);
    // The light, lowered 0.1 mm below the ceiling (see the data's notes); u x v = -y.
    r = r ? r
          : drift_scene_add_light(scene,
                                  &(drift_light){ .type = DRIFT_LIGHT_QUAD,
                                                  .color = { 17, 12, 4 },
                                                  .position = { 343, 548.7f, 227 },
                                                  .edge_u = { 0, 0, 105 },
                                                  .edge_v = { -130, 0, 0 } },
                                  NULL);
    // focal length 35 mm, film 25 mm: fov = 2 atan(12.5 / 35).
    scene->camera =
        drift_camera_look_at(drift_vec3_make(278, 273, -800), drift_vec3_make(278, 273, 0),
                             drift_vec3_make(0, 1, 0), 2.0f * atanf(12.5f / 35.0f), 512, 512);
    return r;
}

// A UV sphere of 2 * 224 * 224 (~100k) triangles resting on a plane, under a quad light.
static drift_result build_sphere(drift_scene *scene, drift_context *ctx)
{
    enum {
        RINGS = 224,
        SEGMENTS = 224
    };

    uint32_t white;
    drift_result r =
        drift_scene_add_material(scene,
                                 &(drift_material){ .name = "white",
                                                    .diffuse = { 0.7f, 0.7f, 0.7f },
                                                    .diffuse_texture = DRIFT_INVALID_INDEX },
                                 &white);
    if (r != DRIFT_OK) {
        return r;
    }
    uint32_t vertex_count = (RINGS + 1) * (SEGMENTS + 1);
    uint32_t triangle_count = 2 * RINGS * SEGMENTS;
    float *p = drift_alloc(ctx, sizeof(float) * 3 * vertex_count);
    uint32_t *idx = drift_alloc(ctx, sizeof(uint32_t) * 3 * triangle_count);
    if (!p || !idx) {
        drift_free(ctx, p);
        drift_free(ctx, idx);
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    for (uint32_t i = 0; i <= RINGS; ++i) {
        float theta = DRIFT_PI * (float)i / RINGS;
        for (uint32_t j = 0; j <= SEGMENTS; ++j) {
            float phi = 2.0f * DRIFT_PI * (float)j / SEGMENTS;
            float *v = p + 3 * (i * (SEGMENTS + 1) + j);
            v[0] = sinf(theta) * cosf(phi);
            v[1] = 1.0f + cosf(theta);
            v[2] = sinf(theta) * sinf(phi);
        }
    }
    // At the poles one triangle of each quad has zero area: leave it out.
    uint32_t t = 0;
    for (uint32_t i = 0; i < RINGS; ++i) {
        for (uint32_t j = 0; j < SEGMENTS; ++j) {
            uint32_t a = i * (SEGMENTS + 1) + j, b = a + SEGMENTS + 1;
            if (i > 0) {
                uint32_t tri[3] = { a, b, a + 1 };
                memcpy(idx + 3 * t++, tri, sizeof(tri));
            }
            if (i < RINGS - 1) {
                uint32_t tri[3] = { a + 1, b, b + 1 };
                memcpy(idx + 3 * t++, tri, sizeof(tri));
            }
        }
    }
    triangle_count = t;
    r = drift_scene_add_mesh(scene,
                             &(drift_mesh_desc){ .name = "sphere",
                                                 .positions = p,
                                                 .vertex_count = vertex_count,
                                                 .indices = idx,
                                                 .triangle_count = triangle_count,
                                                 .material = white },
                             NULL);
    drift_free(ctx, p);
    drift_free(ctx, idx);
    static const float plane_p[] = { -5, 0, -5, 5, 0, -5, 5, 0, 5, -5, 0, 5 };
    static const uint32_t plane_i[] = { 0, 2, 1, 0, 3, 2 };
    r = r ? r
          : drift_scene_add_mesh(scene,
                                 &(drift_mesh_desc){ .name = "plane",
                                                     .positions = plane_p,
                                                     .vertex_count = 4,
                                                     .indices = plane_i,
                                                     .triangle_count = 2,
                                                     .material = white },
                                 NULL);
    r = r ? r
          : drift_scene_add_light(scene,
                                  &(drift_light){ .type = DRIFT_LIGHT_QUAD,
                                                  .color = { 10, 10, 10 },
                                                  .position = { -1, 4, -1 },
                                                  .edge_u = { 2, 0, 0 },
                                                  .edge_v = { 0, 0, 2 } },
                                  NULL);
    scene->camera = drift_camera_look_at(drift_vec3_make(0, 2.5f, 5), drift_vec3_make(0, 0.8f, 0),
                                         drift_vec3_make(0, 1, 0), 0.8f, 512, 512);
    return r;
}

static drift_result load_scene(drift_context *ctx, const char *name, drift_scene **out)
{
    if (strncmp(name, "builtin:", 8) != 0) {
        return drift_scene_load(ctx, name, out);
    }
    drift_result r = drift_scene_create(ctx, out);
    if (r != DRIFT_OK) {
        return r;
    }
    if (strcmp(name, "builtin:cornell") == 0) {
        r = build_cornell(*out);
    } else if (strcmp(name, "builtin:sphere") == 0) {
        r = build_sphere(*out, ctx);
    } else {
        fprintf(stderr, "drift bench rays: unknown built-in scene '%s'\n", name);
        r = DRIFT_ERR_INVALID_ARGUMENT;
    }
    r = r ? r : drift_scene_commit(*out);
    if (r != DRIFT_OK) {
        drift_scene_destroy(*out);
        *out = NULL;
    }
    return r;
}

// --- THE RAW EMBREE SCENE ---

// The same geometry, IDs and build quality drift_accel_create uses, by direct Embree calls.
static bool build_raw(bench_state *s)
{
    const drift_scene *scene = s->scene;
    s->device = rtcNewDevice("threads=1");
    if (!s->device) {
        return false;
    }
    s->raw_scene = rtcNewScene(s->device);
    rtcSetSceneBuildQuality(s->raw_scene, RTC_BUILD_QUALITY_HIGH);
    for (uint32_t m = 0; m < scene->mesh_count; ++m) {
        const drift_mesh *mesh = &scene->meshes[m];
        RTCGeometry g = rtcNewGeometry(s->device, RTC_GEOMETRY_TYPE_TRIANGLE);
        rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, mesh->positions,
                                   0, 12, mesh->vertex_count);
        rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, mesh->indices, 0,
                                   12, mesh->triangle_count);
        rtcCommitGeometry(g);
        rtcAttachGeometryByID(s->raw_scene, g, m);
        rtcReleaseGeometry(g);
    }
    // Light shapes: one geometry per kind, in drift's order (quads, disks, spheres).
    const drift_light_type types[3] = { DRIFT_LIGHT_QUAD, DRIFT_LIGHT_DISK, DRIFT_LIGHT_SPHERE };
    for (uint32_t kind = 0; kind < 3; ++kind) {
        uint32_t n = 0;
        for (uint32_t i = 0; i < scene->light_count; ++i) {
            n += scene->lights[i].type == types[kind];
        }
        if (n == 0) {
            continue;
        }
        RTCGeometry g =
            rtcNewGeometry(s->device, kind == 0   ? RTC_GEOMETRY_TYPE_TRIANGLE
                                      : kind == 1 ? RTC_GEOMETRY_TYPE_ORIENTED_DISC_POINT
                                                  : RTC_GEOMETRY_TYPE_SPHERE_POINT);
        float *v = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0,
                                           kind == 0 ? RTC_FORMAT_FLOAT3 : RTC_FORMAT_FLOAT4,
                                           kind == 0 ? 12 : 16, kind == 0 ? 4 * n : n);
        uint32_t *idx = kind == 0 ? rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0,
                                                            RTC_FORMAT_UINT3, 12, 2 * n)
                                  : NULL;
        float *nrm = kind == 1 ? rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_NORMAL, 0,
                                                         RTC_FORMAT_FLOAT3, 12, n)
                               : NULL;
        uint32_t k = 0;
        for (uint32_t i = 0; i < scene->light_count; ++i) {
            const drift_light *l = &scene->lights[i];
            if (l->type != types[kind]) {
                continue;
            }
            if (kind == 0) {
                drift_vec3 c[4] = { l->position, drift_vec3_add(l->position, l->edge_u),
                                    drift_vec3_add(drift_vec3_add(l->position, l->edge_u),
                                                   l->edge_v),
                                    drift_vec3_add(l->position, l->edge_v) };
                memcpy(v + 12 * k, c, sizeof(c));
                const uint32_t tri[6] = { 0, 1, 2, 0, 2, 3 };
                for (int j = 0; j < 6; ++j) {
                    idx[6 * k + (uint32_t)j] = 4 * k + tri[j];
                }
            } else {
                memcpy(v + 4 * k, &l->position, sizeof(drift_vec3));
                v[4 * k + 3] = l->radius;
                if (nrm) {
                    memcpy(nrm + 3 * k, &l->direction, sizeof(drift_vec3));
                }
            }
            k++;
        }
        rtcCommitGeometry(g);
        rtcAttachGeometryByID(s->raw_scene, g, scene->mesh_count + kind);
        rtcReleaseGeometry(g);
    }
    rtcCommitScene(s->raw_scene);
    return rtcGetDeviceError(s->device) == RTC_ERROR_NONE;
}

// --- RAY SETS ---

static float unit(uint32_t key, uint32_t i)
{
    return drift_u32_to_unit(drift_hash_combine(key, i));
}

// A random point on the first area light as the renderer samples it from `from`
// (drift_light_sample_li), or a point above the scene without one.
static drift_vec3 shadow_target(const drift_scene *scene, uint32_t light, drift_vec3 from,
                                uint32_t i)
{
    if (light == DRIFT_INVALID_INDEX) {
        drift_bounds3 b = scene->bounds;
        drift_vec3 c = drift_vec3_scale(drift_vec3_add(b.min, b.max), 0.5f);
        float extent = drift_vec3_length(drift_vec3_sub(b.max, b.min));
        return drift_vec3_make(c.x, b.max.y + 0.5f * extent, c.z);
    }
    drift_vec2 u = drift_vec2_make(unit(11, i), unit(12, i));
    return drift_light_sample_li(scene, light, from, u).point;
}

static bool make_ray_sets(bench_state *s)
{
    int32_t w = s->width, h = s->height;
    uint32_t n = (uint32_t)w * (uint32_t)h;
    for (int k = 0; k < KIND_COUNT; ++k) {
        s->sets[k].rays = calloc(n, sizeof(drift_ray));
    }
    s->hits = calloc(n, sizeof(drift_hit));
    s->raw_hits = calloc(n, sizeof(raw_hit));
    s->occluded = calloc(n, 1);
    if (!s->sets[0].rays || !s->sets[1].rays || !s->sets[2].rays || !s->hits || !s->raw_hits ||
        !s->occluded) {
        return false;
    }
    // Primary rays in tile order, so that each coherent batch is one tile.
    uint32_t count = 0;
    for (int32_t ty = 0; ty < h; ty += TILE) {
        for (int32_t tx = 0; tx < w; tx += TILE) {
            for (int32_t y = ty; y < ty + TILE && y < h; ++y) {
                for (int32_t x = tx; x < tx + TILE && x < w; ++x) {
                    s->sets[KIND_PRIMARY].rays[count++] =
                        drift_camera_ray(&s->scene->camera, w, h, (float)x + 0.5f, (float)y + 0.5f,
                                         drift_vec2_make(0.5f, 0.5f));
                }
            }
        }
    }
    s->sets[KIND_PRIMARY].count = count;
    uint32_t light = DRIFT_INVALID_INDEX;
    for (uint32_t i = 0; i < s->scene->light_count && light == DRIFT_INVALID_INDEX; ++i) {
        if (drift_light_is_area(s->scene->lights[i].type)) {
            light = i;
        }
    }
    // Secondary rays start at the primary hits.
    drift_accel_intersect_coherent(s->accel, s->sets[KIND_PRIMARY].rays, s->hits, count);
    uint32_t m = 0;
    for (uint32_t i = 0; i < count; ++i) {
        const drift_hit *hit = &s->hits[i];
        if (hit->mesh == DRIFT_INVALID_INDEX && hit->light == DRIFT_INVALID_INDEX) {
            continue;
        }
        const drift_ray *pr = &s->sets[KIND_PRIMARY].rays[i];
        drift_vec3 p = drift_vec3_fma(pr->origin, pr->dir, hit->t);
        drift_vec3 ng = drift_vec3_normalize(hit->ng);
        if (drift_vec3_dot(ng, pr->dir) > 0.0f) {
            ng = drift_vec3_neg(ng);
        }
        drift_vec3 target = shadow_target(s->scene, light, p, i);
        drift_vec3 o = drift_offset_origin(p, ng, drift_vec3_sub(target, p));
        // Unnormalized: t = 1 is the target, so tmax just below 1 excludes the light itself.
        s->sets[KIND_SHADOW].rays[m] = (drift_ray){
            .origin = o, .tmin = 0.0f, .dir = drift_vec3_sub(target, o), .tmax = 1.0f - 1e-3f
        };
        drift_frame f = drift_frame_from_normal(ng);
        drift_vec3 d = drift_frame_to_world(
            &f, drift_sample_cosine_hemisphere(drift_vec2_make(unit(21, i), unit(22, i))));
        s->sets[KIND_BOUNCE].rays[m] = (drift_ray){
            .origin = drift_offset_origin(p, ng, d), .tmin = 0.0f, .dir = d, .tmax = INFINITY
        };
        m++;
    }
    s->sets[KIND_SHADOW].count = s->sets[KIND_BOUNCE].count = m;
    return m > 0;
}

// --- PASSES (one trace of a whole ray set; returns a checksum that both sides share) ---

// noinline: callgrind then reports each pass on its own (docs/benchmarks.md).
__attribute__((noinline)) static uint64_t drift_pass(bench_state *s, enum ray_kind kind)
{
    const ray_set *set = &s->sets[kind];
    uint64_t sum = 0;
    switch (kind) {
    case KIND_PRIMARY:
        for (uint32_t b = 0; b < set->count; b += TILE * TILE) {
            uint32_t n = set->count - b < TILE * TILE ? set->count - b : TILE * TILE;
            drift_accel_intersect_coherent(s->accel, set->rays + b, s->hits + b, n);
        }
        for (uint32_t i = 0; i < set->count; ++i) {
            sum += s->hits[i].prim;
        }
        break;
    case KIND_SHADOW:
        for (uint32_t i = 0; i < set->count; ++i) {
            s->occluded[i] = drift_accel_occluded(s->accel, &set->rays[i]);
            sum += s->occluded[i];
        }
        break;
    case KIND_BOUNCE:
        for (uint32_t i = 0; i < set->count; ++i) {
            if (drift_accel_intersect(s->accel, &set->rays[i], &s->hits[i])) {
                sum += s->hits[i].prim;
            } else {
                sum += DRIFT_INVALID_INDEX;
            }
        }
        break;
    case KIND_COUNT:
        break;
    }
    return sum;
}

static inline void raw_ray(const drift_ray *r, struct RTCRay *out)
{
    out->org_x = r->origin.x;
    out->org_y = r->origin.y;
    out->org_z = r->origin.z;
    out->tnear = r->tmin;
    out->dir_x = r->dir.x;
    out->dir_y = r->dir.y;
    out->dir_z = r->dir.z;
    out->time = 0.0f;
    out->tfar = r->tmax;
    out->mask = UINT32_MAX;
    out->id = 0;
    out->flags = 0;
}

static inline void raw_store(const struct RTCRayHit *rh, raw_hit *out)
{
    out->t = rh->ray.tfar;
    out->u = rh->hit.u;
    out->v = rh->hit.v;
    out->geom = rh->hit.geomID;
    out->prim = rh->hit.geomID == RTC_INVALID_GEOMETRY_ID ? DRIFT_INVALID_INDEX : rh->hit.primID;
    out->ng[0] = rh->hit.Ng_x;
    out->ng[1] = rh->hit.Ng_y;
    out->ng[2] = rh->hit.Ng_z;
}

// Primary rays by Embree's stream API (rtcIntersect1M): measured against packets.
static void raw_primary_stream(bench_state *s, const drift_ray *rays, raw_hit *hits, uint32_t n)
{
    struct RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    struct RTCRayHit chunk[RAW_CHUNK];
    for (uint32_t b = 0; b < n; b += RAW_CHUNK) {
        uint32_t m = n - b < RAW_CHUNK ? n - b : RAW_CHUNK;
        for (uint32_t i = 0; i < m; ++i) {
            raw_ray(&rays[b + i], &chunk[i].ray);
            chunk[i].hit.geomID = RTC_INVALID_GEOMETRY_ID;
            chunk[i].hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        }
        rtcIntersect1M(s->raw_scene, &context, chunk, m, sizeof(struct RTCRayHit));
        for (uint32_t i = 0; i < m; ++i) {
            raw_store(&chunk[i], &hits[b + i]);
        }
    }
}

// Primary rays as 16-wide packets (rtcIntersect16), as drift does.
static void raw_primary_packet16(bench_state *s, const drift_ray *rays, raw_hit *hits, uint32_t n)
{
    struct RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    struct RTCRayHit16 p;
    // Embree requires the valid mask, like the packet, aligned to the packet size.
    _Alignas(64) int valid[16];
    for (uint32_t b = 0; b < n; b += 16) {
        for (uint32_t i = 0; i < 16; ++i) {
            const drift_ray *r = &rays[b + (b + i < n ? i : 0)];
            valid[i] = b + i < n ? -1 : 0;
            p.ray.org_x[i] = r->origin.x;
            p.ray.org_y[i] = r->origin.y;
            p.ray.org_z[i] = r->origin.z;
            p.ray.tnear[i] = r->tmin;
            p.ray.dir_x[i] = r->dir.x;
            p.ray.dir_y[i] = r->dir.y;
            p.ray.dir_z[i] = r->dir.z;
            p.ray.time[i] = 0.0f;
            p.ray.tfar[i] = r->tmax;
            p.ray.mask[i] = UINT32_MAX;
            p.ray.id[i] = 0;
            p.ray.flags[i] = 0;
            p.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
            p.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
        }
        rtcIntersect16(valid, s->raw_scene, &context, &p);
        for (uint32_t i = 0; i < 16 && b + i < n; ++i) {
            raw_hit *o = &hits[b + i];
            o->t = p.ray.tfar[i];
            o->u = p.hit.u[i];
            o->v = p.hit.v[i];
            o->geom = p.hit.geomID[i];
            o->prim =
                p.hit.geomID[i] == RTC_INVALID_GEOMETRY_ID ? DRIFT_INVALID_INDEX : p.hit.primID[i];
            o->ng[0] = p.hit.Ng_x[i];
            o->ng[1] = p.hit.Ng_y[i];
            o->ng[2] = p.hit.Ng_z[i];
        }
    }
}

// Primary rays one by one (rtcIntersect1).
static void raw_primary_single(bench_state *s, const drift_ray *rays, raw_hit *hits, uint32_t n)
{
    struct RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    for (uint32_t i = 0; i < n; ++i) {
        struct RTCRayHit rh;
        raw_ray(&rays[i], &rh.ray);
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(s->raw_scene, &context, &rh);
        raw_store(&rh, &hits[i]);
    }
}

typedef void (*raw_primary_fn)(bench_state *s, const drift_ray *rays, raw_hit *hits, uint32_t n);

// The prim id drift reports for a raw hit, so checksums agree: drift numbers the triangles of a
// mesh as Embree does, but a quad light's two triangles as 0/1 of that light and a disk or
// sphere as 0 (the raw scene holds one geometry per shape kind, quads first).
static inline uint32_t raw_prim_as_drift(const bench_state *s, const raw_hit *h)
{
    if (h->geom == RTC_INVALID_GEOMETRY_ID || h->geom < s->scene->mesh_count) {
        return h->prim;
    }
    return h->geom == s->scene->mesh_count ? (h->prim & 1u) : 0u;
}

__attribute__((noinline)) static uint64_t raw_pass(bench_state *s, enum ray_kind kind,
                                                   raw_primary_fn primary)
{
    const ray_set *set = &s->sets[kind];
    uint64_t sum = 0;
    struct RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    switch (kind) {
    case KIND_PRIMARY:
        for (uint32_t b = 0; b < set->count; b += TILE * TILE) {
            uint32_t n = set->count - b < TILE * TILE ? set->count - b : TILE * TILE;
            primary(s, set->rays + b, s->raw_hits + b, n);
        }
        for (uint32_t i = 0; i < set->count; ++i) {
            sum += raw_prim_as_drift(s, &s->raw_hits[i]);
        }
        break;
    case KIND_SHADOW:
        for (uint32_t i = 0; i < set->count; ++i) {
            struct RTCRay r;
            raw_ray(&set->rays[i], &r);
            rtcOccluded1(s->raw_scene, &context, &r);
            s->occluded[i] = r.tfar < 0.0f;
            sum += s->occluded[i];
        }
        break;
    case KIND_BOUNCE:
        for (uint32_t i = 0; i < set->count; ++i) {
            struct RTCRayHit rh;
            raw_ray(&set->rays[i], &rh.ray);
            rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
            rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
            rtcIntersect1(s->raw_scene, &context, &rh);
            raw_store(&rh, &s->raw_hits[i]);
            sum += raw_prim_as_drift(s, &s->raw_hits[i]);
        }
        break;
    case KIND_COUNT:
        break;
    }
    return sum;
}

// Runs whole passes until `budget` seconds are spent; returns rays per second.
static double timed(bench_state *s, enum ray_kind kind, raw_primary_fn raw, double budget,
                    uint64_t *out_sum)
{
    uint64_t passes = 0, sum = 0;
    double start = drift_time_now(), elapsed;
    do {
        sum = raw ? raw_pass(s, kind, raw) : drift_pass(s, kind);
        passes++;
        elapsed = drift_time_now() - start;
    } while (elapsed < budget);
    *out_sum = sum;
    return (double)passes * (double)s->sets[kind].count / elapsed;
}

// --- COMMAND ---

#define O rays_options
static const cli_option rays_table[] = {
    CLI_SECTION("options:", 0),
    CLI_INT("--width", "W", O, width, 1, 16384,
            "image size for primary rays (default: the camera's)"),
    CLI_INT("--height", "H", O, height, 1, 16384, "image size for primary rays"),
    CLI_NUMBER("--seconds", "S", O, seconds, 0.01, 3600.0,
               "total time to spend measuring (default 6)"),
    CLI_INT("--repeats", "N", O, repeats, 1, 1000, "alternations of the two sides (default 5)"),
    CLI_FLAG("--json", O, json, "one JSON object on stdout instead of the table"),
    CLI_FLAG("--variants", O, variants,
             "also time raw Embree's other ways of tracing primary rays\n"
             "(rtcIntersect1M stream, rtcIntersect1 one by one)"),
};
#undef O

static const cli_command rays_command = {
    .name = "bench rays",
    .usage = "usage: drift bench rays [SCENE] [options]\n\n"
             "Rays per second on one thread through drift's accel and through raw Embree calls\n"
             "on an identical Embree scene, with identical ray sets: primary (coherent 16x16\n"
             "tiles), shadow (occlusion toward the first area light) and bounce (cosine-\n"
             "sampled from the primary hits, incoherent). The two sides alternate N times\n"
             "and the best run of each counts; drift/raw near 1 means the wrapper is free.\n\n"
             "SCENE is a scene or mesh file (drift_scene_load), or builtin:cornell or\n"
             "builtin:sphere (a ~100k-triangle sphere on a plane); default: the built-in\n"
             "Cornell box file, or builtin:cornell when that file cannot be loaded.\n\n",
    CLI_TABLE(rays_table),
    CLI_POSITIONAL("SCENE", rays_options, scene, 1),
    .help_column = 15,
};

static void state_destroy(bench_state *s)
{
    for (int k = 0; k < KIND_COUNT; ++k) {
        free(s->sets[k].rays);
    }
    free(s->hits);
    free(s->raw_hits);
    free(s->occluded);
    if (s->raw_scene) {
        rtcReleaseScene(s->raw_scene);
    }
    if (s->device) {
        rtcReleaseDevice(s->device);
    }
    drift_accel_destroy(s->accel);
    drift_scene_destroy(s->scene);
}

int drift_bench_rays(int argc, char **argv)
{
    rays_options o = { .seconds = 6.0, .repeats = 5 };
    int status = cli_parse(&rays_command, argc, argv, &o, NULL);
    if (status != CLI_PARSED) {
        return cli_parse_exit(status);
    }
    const char *scene_name = o.scene ? o.scene : cli_default_scene_path();
    bench_state s = { 0 };
    // One thread: the figures are per thread, and Embree builds with one thread too.
    cli_session session;
    if (!cli_session_open(
            &(cli_session_desc){ .cmd = "bench rays", .threads = 1, .no_scene = true }, &session)) {
        cli_session_close(&session);
        return 1;
    }
    s.ctx = session.ctx;
    drift_result r = load_scene(s.ctx, scene_name, &s.scene);
    if (r != DRIFT_OK && !o.scene) {
        // The default scene file may be missing (or unreadable) in a partial checkout: the
        // same Cornell box built in code still gives comparable figures.
        fprintf(stderr, "drift bench rays: default scene unavailable; using builtin:cornell\n");
        scene_name = "builtin:cornell";
        r = load_scene(s.ctx, scene_name, &s.scene);
    }
    if (r != DRIFT_OK) {
        fprintf(stderr, "drift bench rays: cannot load '%s': %s\n", scene_name,
                drift_result_string(r));
        state_destroy(&s);
        cli_session_close(&session);
        return 1;
    }
    s.width = o.width ? (int32_t)o.width : s.scene->camera.width;
    s.height = o.height ? (int32_t)o.height : s.scene->camera.height;
    double t0 = drift_time_now();
    r = drift_accel_create(s.ctx, s.scene, NULL, &s.accel);
    double build_s = drift_time_now() - t0;
    if (r != DRIFT_OK || !build_raw(&s) || !make_ray_sets(&s)) {
        fprintf(stderr, "drift bench rays: setup failed (%s)\n", drift_result_string(r));
        state_destroy(&s);
        cli_session_close(&session);
        return 1;
    }

    // Alternate drift and raw per repeat (and swap who goes first) so that clock and
    // cache drift hit both sides alike; keep the best of each.
    raw_primary_fn variants[3] = { raw_primary_packet16, raw_primary_stream, raw_primary_single };
    static const char *const variant_names[3] = { "packet16", "stream", "single" };
    int variant_count = o.variants ? 3 : 1;
    int slots = KIND_COUNT * 2 + (variant_count - 1);
    double budget = o.seconds / ((double)o.repeats * slots);
    double best_drift[KIND_COUNT] = { 0 }, best_raw[KIND_COUNT] = { 0 }, best_variant[3] = { 0 };
    bool mismatch = false;
    for (long rep = 0; rep < o.repeats; ++rep) {
        for (int k = 0; k < KIND_COUNT; ++k) {
            uint64_t sum_drift = 0, sum_raw = 0;
            for (int side = 0; side < 2; ++side) {
                bool drift_side = (side == 0) == (rep % 2 == 0);
                if (drift_side) {
                    double rate = timed(&s, (enum ray_kind)k, NULL, budget, &sum_drift);
                    best_drift[k] = rate > best_drift[k] ? rate : best_drift[k];
                } else {
                    double rate = timed(&s, (enum ray_kind)k, variants[0], budget, &sum_raw);
                    best_raw[k] = rate > best_raw[k] ? rate : best_raw[k];
                }
            }
            mismatch |= sum_drift != sum_raw;
        }
        for (int v = 1; v < variant_count; ++v) {
            uint64_t sum = 0;
            double rate = timed(&s, KIND_PRIMARY, variants[v], budget, &sum);
            best_variant[v] = rate > best_variant[v] ? rate : best_variant[v];
        }
    }
    best_variant[0] = best_raw[KIND_PRIMARY];
    if (mismatch) {
        fprintf(stderr, "drift bench rays: drift and raw Embree disagree on the results\n");
    }

    if (o.json) {
        cJSON *root = cJSON_CreateObject();
        cJSON_AddStringToObject(root, "scene", scene_name);
        cli_json_count(root, "triangles", drift_scene_triangle_count(s.scene));
        cJSON_AddNumberToObject(root, "width", s.width);
        cJSON_AddNumberToObject(root, "height", s.height);
        cJSON_AddNumberToObject(root, "threads", 1);
        cli_json_number(root, "build_seconds", build_s, 4);
        cJSON_AddBoolToObject(root, "results_match", !mismatch);
        for (int k = 0; k < KIND_COUNT; ++k) {
            cJSON *kind = cJSON_AddObjectToObject(root, kind_names[k]);
            cli_json_count(kind, "rays", s.sets[k].count);
            cli_json_number(kind, "drift_rays_per_s", best_drift[k], 0);
            cli_json_number(kind, "raw_rays_per_s", best_raw[k], 0);
            cli_json_number(kind, "ratio", best_drift[k] / best_raw[k], 4);
        }
        for (int v = 1; v < variant_count; ++v) {
            char key[64];
            snprintf(key, sizeof key, "raw_primary_%s_rays_per_s", variant_names[v]);
            cli_json_number(root, key, best_variant[v], 0);
        }
        mismatch |= !cli_json_write("bench rays", root, NULL);
    } else {
        printf("scene %s: %llu triangles, %dx%d, 1 thread, accel build %.3f s, best of %ld\n",
               scene_name, (unsigned long long)drift_scene_triangle_count(s.scene), s.width,
               s.height, build_s, o.repeats);
        printf("%-8s %10s %14s %14s %8s\n", "rays", "count", "drift Mrays/s", "raw Mrays/s",
               "drift/raw");
        for (int k = 0; k < KIND_COUNT; ++k) {
            printf("%-8s %10u %14.3f %14.3f %8.3f\n", kind_names[k], s.sets[k].count,
                   best_drift[k] * 1e-6, best_raw[k] * 1e-6, best_drift[k] / best_raw[k]);
        }
        for (int v = 0; v < variant_count && o.variants; ++v) {
            printf("raw primary via %-9s %8.3f Mrays/s\n", variant_names[v],
                   best_variant[v] * 1e-6);
        }
    }
    state_destroy(&s);
    cli_session_close(&session);
    return mismatch ? 1 : 0;
}
