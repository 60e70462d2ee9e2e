#include "drift/accel.h"
#include "drift/scene.h"
#include "drift_test.h"

#include <math.h>
#include <string.h>

// --- HELPERS ---

typedef struct rng {
    uint32_t state;
} rng;

static float rng_next(rng *r)
{
    r->state = drift_hash_u32(r->state + 0x9e3779b9U);
    return drift_u32_to_unit(r->state);
}

static float rng_range(rng *r, float lo, float hi)
{
    return lo + (hi - lo) * rng_next(r);
}

static drift_vec3 rng_vec3(rng *r, float lo, float hi)
{
    return drift_vec3_make(rng_range(r, lo, hi), rng_range(r, lo, hi), rng_range(r, lo, hi));
}

static drift_scene *new_scene(drift_context *ctx, uint32_t *out_material)
{
    drift_scene *scene = NULL;
    assert_int_equal(drift_scene_create(ctx, &scene), DRIFT_OK);
    drift_material m = drift_material_make(drift_vec3_splat(0.5f));
    assert_int_equal(drift_scene_add_material(scene, &m, out_material), DRIFT_OK);
    return scene;
}

static drift_accel *new_accel(drift_context *ctx, drift_scene *scene)
{
    drift_accel *accel = NULL;
    assert_int_equal(drift_scene_commit(scene), DRIFT_OK);
    assert_int_equal(drift_accel_create(ctx, scene, &(drift_accel_desc){ 0 }, &accel), DRIFT_OK);
    assert_non_null(accel);
    return accel;
}

// Random triangles of size ~`size` in [-1, 1]^3, split over `mesh_count` meshes.
static void add_random_meshes(drift_scene *scene, rng *r, uint32_t material, uint32_t mesh_count,
                              uint32_t triangles_per_mesh, float size)
{
    for (uint32_t m = 0; m < mesh_count; ++m) {
        uint32_t vertex_count = 3 * triangles_per_mesh;
        float *p = test_malloc(sizeof(float) * 3 * vertex_count);
        uint32_t *idx = test_malloc(sizeof(uint32_t) * 3 * triangles_per_mesh);
        for (uint32_t t = 0; t < triangles_per_mesh; ++t) {
            drift_vec3 c = rng_vec3(r, -1.0f, 1.0f);
            for (int k = 0; k < 3; ++k) {
                drift_vec3 v = drift_vec3_add(c, rng_vec3(r, -size, size));
                p[9 * t + 3 * k] = v.x;
                p[9 * t + 3 * k + 1] = v.y;
                p[9 * t + 3 * k + 2] = v.z;
                idx[3 * t + k] = 3 * t + (uint32_t)k;
            }
        }
        test_add_mesh(scene, p, vertex_count, idx, triangles_per_mesh, material);
        test_free(p);
        test_free(idx);
    }
}

static drift_ray random_ray(rng *r, bool finite_tmax)
{
    drift_vec3 o = rng_vec3(r, -2.0f, 2.0f);
    drift_vec3 d = drift_sample_uniform_sphere(drift_vec2_make(rng_next(r), rng_next(r)));
    // Non-unit directions too: t is in units of |dir|.
    d = drift_vec3_scale(d, rng_range(r, 0.5f, 2.0f));
    return (drift_ray){ .origin = o,
                        .tmin = rng_next(r) < 0.3f ? rng_range(r, 0.0f, 1.0f) : 0.0f,
                        .dir = d,
                        .tmax = finite_tmax ? rng_range(r, 0.5f, 3.0f) : INFINITY };
}

// Brute force in double: Möller & Trumbore 1997, "Fast, Minimum Storage Ray/Triangle
// Intersection". `margin` gets how far the hit is from the triangle's edges (in barycentric
// units) so that near-edge rays, where float and double may disagree, can be skipped.
typedef struct bf_hit {
    bool hit;
    double t, second_t; // closest and second-closest t in range
    uint32_t mesh, prim;
    double margin; // min over candidate triangles of |barycentric - boundary|
    drift_vec3 ng;
} bf_hit;

static bf_hit brute_force(const drift_scene *scene, const drift_ray *ray)
{
    bf_hit best = { .t = (double)INFINITY,
                    .second_t = (double)INFINITY,
                    .margin = (double)INFINITY };
    double o[3] = { (double)ray->origin.x, (double)ray->origin.y, (double)ray->origin.z };
    double d[3] = { (double)ray->dir.x, (double)ray->dir.y, (double)ray->dir.z };
    for (uint32_t m = 0; m < scene->mesh_count; ++m) {
        const drift_mesh *mesh = &scene->meshes[m];
        for (uint32_t t = 0; t < mesh->triangle_count; ++t) {
            double v[3][3];
            for (int k = 0; k < 3; ++k) {
                const float *p = mesh->positions + 3 * (size_t)mesh->indices[3 * t + k];
                v[k][0] = (double)p[0], v[k][1] = (double)p[1], v[k][2] = (double)p[2];
            }
            double e1[3], e2[3], s[3];
            for (int k = 0; k < 3; ++k) {
                e1[k] = v[1][k] - v[0][k];
                e2[k] = v[2][k] - v[0][k];
                s[k] = o[k] - v[0][k];
            }
            double pv[3] = { d[1] * e2[2] - d[2] * e2[1], d[2] * e2[0] - d[0] * e2[2],
                             d[0] * e2[1] - d[1] * e2[0] };
            double det = e1[0] * pv[0] + e1[1] * pv[1] + e1[2] * pv[2];
            if (fabs(det) < 1e-300) {
                continue;
            }
            double inv = 1.0 / det;
            double u = (s[0] * pv[0] + s[1] * pv[1] + s[2] * pv[2]) * inv;
            double q[3] = { s[1] * e1[2] - s[2] * e1[1], s[2] * e1[0] - s[0] * e1[2],
                            s[0] * e1[1] - s[1] * e1[0] };
            double w = (d[0] * q[0] + d[1] * q[1] + d[2] * q[2]) * inv;
            double tt = (e2[0] * q[0] + e2[1] * q[1] + e2[2] * q[2]) * inv;
            double edge = fmin(fmin(u, w), 1.0 - u - w);
            double tmargin = fmin(fabs(tt - (double)ray->tmin), fabs(tt - (double)ray->tmax)) /
                             fmax(1.0, fabs(tt));
            // Candidates close to any boundary (edges, or tmin/tmax) make the test ambiguous.
            if (fabs(edge) < best.margin && tt > -1.0) {
                best.margin = fmin(best.margin, fabs(edge));
            }
            if (edge >= 0.0 && tmargin < best.margin) {
                best.margin = tmargin;
            }
            if (edge < 0.0 || tt < (double)ray->tmin || tt > (double)ray->tmax) {
                continue;
            }
            if (tt < best.t) {
                best.second_t = best.t;
                best.t = tt;
                best.mesh = m;
                best.prim = t;
                best.hit = true;
                best.ng = drift_vec3_make((float)(e1[1] * e2[2] - e1[2] * e2[1]),
                                          (float)(e1[2] * e2[0] - e1[0] * e2[2]),
                                          (float)(e1[0] * e2[1] - e1[1] * e2[0]));
            } else if (tt < best.second_t) {
                best.second_t = tt;
            }
        }
    }
    return best;
}

// --- TESTS ---

static void test_accel_matches_brute_force(void **state)
{
    (void)state;
    drift_context *ctx = test_context(1, NULL);
    int ray_count = (int)(4000 * test_intensity());
    for (uint32_t seed = 1; seed <= 3; ++seed) {
        rng r = { seed * 7919u };
        uint32_t material;
        drift_scene *scene = new_scene(ctx, &material);
        add_random_meshes(scene, &r, material, seed, 300, 0.35f);
        drift_accel *accel = new_accel(ctx, scene);
        int hits = 0, compared = 0;
        for (int i = 0; i < ray_count; ++i) {
            drift_ray ray = random_ray(&r, i % 2 == 0);
            bf_hit ref = brute_force(scene, &ray);
            if (ref.margin < 1e-5) {
                continue; // grazing an edge or a range end: either answer is right
            }
            compared++;
            drift_hit hit;
            memset(&hit, 0, sizeof(hit));
            bool got = drift_accel_intersect(accel, &ray, &hit);
            assert_int_equal(got, ref.hit);
            assert_int_equal(drift_accel_occluded(accel, &ray), ref.hit);
            if (!got) {
                continue;
            }
            hits++;
            assert_true(fabs((double)hit.t - ref.t) <= 1e-4 * fmax(1.0, fabs(ref.t)));
            if ((ref.second_t - ref.t) > 1e-4 * fmax(1.0, ref.t)) {
                assert_int_equal(hit.mesh, ref.mesh);
                assert_int_equal(hit.prim, ref.prim);
                assert_int_equal(hit.light, DRIFT_INVALID_INDEX);
                // Same geometric normal direction (Embree's Ng = e1 x e2, unnormalized).
                float c =
                    drift_vec3_dot(drift_vec3_normalize(hit.ng), drift_vec3_normalize(ref.ng));
                assert_true(c > 0.999f);
            }
        }
        // Guard against a degenerate test (everything skipped, or nothing hit).
        assert_true(compared > ray_count * 9 / 10);
        assert_true(hits > compared / 10);
        drift_accel_destroy(accel);
        drift_scene_destroy(scene);
    }
    drift_context_destroy(ctx);
}

static void test_accel_coherent_equals_single(void **state)
{
    (void)state;
    drift_context *ctx = test_context(2, NULL);
    rng r = { 42 };
    uint32_t material;
    drift_scene *scene = new_scene(ctx, &material);
    add_random_meshes(scene, &r, material, 2, 300, 0.3f);
    assert_int_equal(
        drift_scene_add_light(scene,
                              &(drift_light){ .type = DRIFT_LIGHT_SPHERE,
                                              .color = drift_vec3_splat(1.0f),
                                              .position = drift_vec3_make(0.5f, 0.5f, 0.5f),
                                              .radius = 0.3f },
                              NULL),
        DRIFT_OK);
    drift_accel *accel = new_accel(ctx, scene);

    // Not a multiple of any chunk or packet size, so the tails are exercised.
    enum {
        N = 1000 + 37
    };

    drift_ray *rays = test_malloc(sizeof(drift_ray) * N);
    drift_hit *hits = test_malloc(sizeof(drift_hit) * N);
    uint8_t *occluded = test_malloc(N);
    // Coherent: a pinhole camera's rays over a 33 x 32 grid (minus a few).
    drift_camera cam = drift_camera_look_at(drift_vec3_make(0, 0, 4), drift_vec3_make(0, 0, 0),
                                            drift_vec3_make(0, 1, 0), 0.9f, 33, 32);
    for (int i = 0; i < N; ++i) {
        if (i % 3 == 0) {
            rays[i] = random_ray(&r, i % 2 == 0);
        } else {
            rays[i] = drift_camera_ray(&cam, 33, 32, (float)(i % 33) + 0.5f, (float)(i / 33) + 0.5f,
                                       drift_vec2_make(0.5f, 0.5f));
            rays[i].tmax = i % 4 == 0 ? 4.0f : INFINITY;
        }
    }
    drift_accel_intersect_coherent(accel, rays, hits, N);
    drift_accel_occluded_coherent(accel, rays, occluded, N);
    int hit_count = 0;
    for (int i = 0; i < N; ++i) {
        drift_hit single;
        bool got = drift_accel_intersect(accel, &rays[i], &single);
        assert_int_equal(occluded[i], drift_accel_occluded(accel, &rays[i]));
        if (!got) {
            assert_true(isinf(hits[i].t));
            assert_int_equal(hits[i].mesh, DRIFT_INVALID_INDEX);
            assert_int_equal(hits[i].light, DRIFT_INVALID_INDEX);
            continue;
        }
        hit_count++;
        // The stream kernels may round the sphere quadratic differently from the single-ray
        // one (seen: 1 ulp); triangles agree exactly.
        assert_true(fabsf(hits[i].t - single.t) <= 1e-6f * fmaxf(1.0f, single.t));
        assert_int_equal(hits[i].mesh, single.mesh);
        assert_int_equal(hits[i].prim, single.prim);
        assert_int_equal(hits[i].light, single.light);
        assert_true(fabsf(hits[i].u - single.u) <= 1e-6f && fabsf(hits[i].v - single.v) <= 1e-6f);
        assert_true(drift_vec3_dot(hits[i].ng, single.ng) > 0.0f);
    }
    assert_true(hit_count > N / 10);
    test_free(rays);
    test_free(hits);
    test_free(occluded);
    drift_accel_destroy(accel);
    drift_scene_destroy(scene);
    drift_context_destroy(ctx);
}

static void expect_hit(const drift_accel *accel, drift_vec3 o, drift_vec3 d, float t,
                       uint32_t light, drift_vec3 ng_dir)
{
    drift_hit hit;
    drift_ray ray = { .origin = o, .tmin = 0.0f, .dir = d, .tmax = INFINITY };
    assert_true(drift_accel_intersect(accel, &ray, &hit));
    assert_true(fabsf(hit.t - t) <= 1e-4f * fmaxf(1.0f, t));
    assert_int_equal(hit.mesh, DRIFT_INVALID_INDEX);
    assert_int_equal(hit.light, light);
    float c = drift_vec3_dot(drift_vec3_normalize(hit.ng), ng_dir);
    assert_true(c > 0.9999f);
    assert_true(drift_accel_occluded(accel, &ray));
}

static void test_accel_light_shapes_hit_at_known_t(void **state)
{
    (void)state;
    drift_context *ctx = test_context(1, NULL);
    uint32_t material;
    drift_scene *scene = new_scene(ctx, &material);
    // A small mesh far away, so meshes and shapes coexist in one Embree scene.
    static const float floor_p[] = { -1, -50, -1, 1, -50, -1, 0, -50, 1 };
    static const uint32_t floor_i[] = { 0, 1, 2 };
    test_add_mesh(scene, floor_p, 3, floor_i, 1, material);
    uint32_t point, quad, disk, sphere, quad2;
    // A point light first, so that shape light indices are not their shape ordinals.
    assert_int_equal(drift_scene_add_light(scene,
                                           &(drift_light){ .type = DRIFT_LIGHT_POINT,
                                                           .color = drift_vec3_splat(1.0f),
                                                           .position = drift_vec3_make(0, 9, 0) },
                                           &point),
                     DRIFT_OK);
    // Quad at y = 2 over [0,2] x [0,1] in x, z, emitting down: u x v = (0,-1,0) needs u = +x,
    // v = +z... (1,0,0) x (0,0,1) = (0,-1,0).
    assert_int_equal(drift_scene_add_light(scene,
                                           &(drift_light){ .type = DRIFT_LIGHT_QUAD,
                                                           .color = drift_vec3_splat(1.0f),
                                                           .position = drift_vec3_make(0, 2, 0),
                                                           .edge_u = drift_vec3_make(2, 0, 0),
                                                           .edge_v = drift_vec3_make(0, 0, 1) },
                                           &quad),
                     DRIFT_OK);
    // Disk centred at (10, 0, 0), radius 1, facing +x (given unnormalized on purpose).
    assert_int_equal(drift_scene_add_light(scene,
                                           &(drift_light){ .type = DRIFT_LIGHT_DISK,
                                                           .color = drift_vec3_splat(1.0f),
                                                           .position = drift_vec3_make(10, 0, 0),
                                                           .direction = drift_vec3_make(3, 0, 0),
                                                           .radius = 1.0f },
                                           &disk),
                     DRIFT_OK);
    assert_int_equal(drift_scene_add_light(scene,
                                           &(drift_light){ .type = DRIFT_LIGHT_SPHERE,
                                                           .color = drift_vec3_splat(1.0f),
                                                           .position = drift_vec3_make(0, 0, -10),
                                                           .radius = 2.0f },
                                           &sphere),
                     DRIFT_OK);
    // A second quad: shape primitives must map to the right light.
    assert_int_equal(drift_scene_add_light(scene,
                                           &(drift_light){ .type = DRIFT_LIGHT_QUAD,
                                                           .color = drift_vec3_splat(1.0f),
                                                           .position = drift_vec3_make(20, 0, 20),
                                                           .edge_u = drift_vec3_make(1, 0, 0),
                                                           .edge_v = drift_vec3_make(0, 1, 0) },
                                           &quad2),
                     DRIFT_OK);
    drift_accel *accel = new_accel(ctx, scene);
    drift_vec3 up = drift_vec3_make(0, 1, 0), down = drift_vec3_make(0, -1, 0);

    // Quad from below (the side it emits toward) and from above, both triangles.
    expect_hit(accel, drift_vec3_make(0.5f, 0, 0.8f), up, 2.0f, quad, down);
    expect_hit(accel, drift_vec3_make(1.5f, 0, 0.2f), up, 2.0f, quad, down);
    expect_hit(accel, drift_vec3_make(1.5f, 5, 0.2f), down, 3.0f, quad, down);
    expect_hit(accel, drift_vec3_make(20.5f, 0.5f, 25), drift_vec3_make(0, 0, -2), 2.5f, quad2,
               drift_vec3_make(0, 0, 1));
    // Next to the quad: a miss (the floor triangle is out of the way).
    drift_hit hit;
    drift_ray miss = { .origin = drift_vec3_make(2.5f, 0, 0.5f), .dir = up, .tmax = INFINITY };
    assert_false(drift_accel_intersect(accel, &miss, &hit));

    // Disk from the front (+x side) and from behind; ng is the disk normal both times.
    drift_vec3 px = drift_vec3_make(1, 0, 0);
    expect_hit(accel, drift_vec3_make(14, 0.5f, 0.5f), drift_vec3_make(-1, 0, 0), 4.0f, disk, px);
    expect_hit(accel, drift_vec3_make(7, -0.3f, 0.2f), px, 3.0f, disk, px);
    // Outside the radius (0.8^2 + 0.8^2 > 1) but inside the bounding square: a miss.
    drift_ray disk_miss = { .origin = drift_vec3_make(14, 0.8f, 0.8f),
                            .dir = drift_vec3_make(-1, 0, 0),
                            .tmax = INFINITY };
    assert_false(drift_accel_intersect(accel, &disk_miss, &hit));

    // Sphere from outside (t = distance - radius), and from its centre (t = radius); ng
    // points outward.
    drift_vec3 pz = drift_vec3_make(0, 0, 1);
    expect_hit(accel, drift_vec3_make(0, 0, -3), drift_vec3_make(0, 0, -1), 5.0f, sphere,
               drift_vec3_make(0, 0, 1));
    expect_hit(accel, drift_vec3_make(0, 0, -10), pz, 2.0f, sphere, pz);
    // Off-centre from outside: t from the quadratic, o = (1, 0, 0) relative, d = -z.
    float t_off = 5.0f + 3.0f - sqrtf(4.0f - 1.0f);
    expect_hit(accel, drift_vec3_make(1, 0, -2), drift_vec3_make(0, 0, -1), t_off, sphere,
               drift_vec3_normalize(drift_vec3_make(1, 0, sqrtf(3.0f))));

    drift_accel_destroy(accel);
    drift_scene_destroy(scene);
    drift_context_destroy(ctx);
}

static void test_accel_emissive_mesh_reports_its_light(void **state)
{
    (void)state;
    drift_context *ctx = test_context(1, NULL);
    uint32_t white;
    drift_scene *scene = new_scene(ctx, &white);
    drift_material glow = drift_material_make(drift_vec3_splat(0.0f));
    glow.emission = drift_vec3_splat(5.0f);
    uint32_t emissive;
    assert_int_equal(drift_scene_add_material(scene, &glow, &emissive), DRIFT_OK);
    // Two meshes, each a unit square of 2 triangles at z = 0 (plain) and z = -1 (emissive).
    static const uint32_t idx[] = { 0, 1, 2, 0, 2, 3 };
    float plain_p[] = { 5, 5, 0, 6, 5, 0, 6, 6, 0, 5, 6, 0 };
    float glow_p[] = { 0, 0, -1, 1, 0, -1, 1, 1, -1, 0, 1, -1 };
    uint32_t plain_mesh, glow_mesh;
    plain_mesh = test_add_mesh(scene, plain_p, 4, idx, 2, white);
    glow_mesh = test_add_mesh(scene, glow_p, 4, idx, 2, emissive);
    drift_accel *accel = new_accel(ctx, scene);
    uint32_t first = scene->meshes[glow_mesh].first_light;
    assert_int_not_equal(first, DRIFT_INVALID_INDEX);
    drift_vec3 dz = drift_vec3_make(0, 0, -1);
    // (0.8, 0.2) lies in triangle 0 (below the diagonal), (0.2, 0.8) in triangle 1.
    drift_ray a = { .origin = drift_vec3_make(0.8f, 0.2f, 1), .dir = dz, .tmax = INFINITY };
    drift_ray b = { .origin = drift_vec3_make(0.2f, 0.8f, 1), .dir = dz, .tmax = INFINITY };
    drift_hit hit;
    assert_true(drift_accel_intersect(accel, &a, &hit));
    assert_int_equal(hit.mesh, glow_mesh);
    assert_int_equal(hit.prim, 0);
    assert_int_equal(hit.light, first);
    assert_true(fabsf(hit.t - 2.0f) < 1e-5f);
    // Barycentrics: p = p0 + u (p1 - p0) + v (p2 - p0) = (u + v, v) -> u = 0.6, v = 0.2.
    assert_true(fabsf(hit.u - 0.6f) < 1e-5f && fabsf(hit.v - 0.2f) < 1e-5f);
    assert_true(drift_accel_intersect(accel, &b, &hit));
    assert_int_equal(hit.prim, 1);
    assert_int_equal(hit.light, first + 1);
    assert_int_equal(scene->lights[hit.light].type, DRIFT_LIGHT_TRIANGLE);
    assert_int_equal(scene->lights[hit.light].mesh, glow_mesh);
    assert_int_equal(scene->lights[hit.light].triangle, 1);
    // The plain mesh reports no light.
    drift_ray c = { .origin = drift_vec3_make(5.5f, 5.2f, 1), .dir = dz, .tmax = INFINITY };
    assert_true(drift_accel_intersect(accel, &c, &hit));
    assert_int_equal(hit.mesh, plain_mesh);
    assert_int_equal(hit.light, DRIFT_INVALID_INDEX);
    drift_accel_destroy(accel);
    drift_scene_destroy(scene);
    drift_context_destroy(ctx);
}

static void test_accel_occluded_respects_range(void **state)
{
    (void)state;
    drift_context *ctx = test_context(1, NULL);
    uint32_t material;
    drift_scene *scene = new_scene(ctx, &material);
    // A large square at z = -5.
    static const float p[] = { -10, -10, -5, 10, -10, -5, 10, 10, -5, -10, 10, -5 };
    static const uint32_t idx[] = { 0, 1, 2, 0, 2, 3 };
    test_add_mesh(scene, p, 4, idx, 2, material);
    drift_accel *accel = new_accel(ctx, scene);
    drift_ray ray = { .origin = drift_vec3_make(0.3f, 0.1f, 0), .dir = drift_vec3_make(0, 0, -1) };
    drift_hit hit;
    // The last: an empty segment (tmax < tmin, a shadow ray starting inside the sphere light
    // it aims at) is not occluded; reading any negative tfar as Embree's mark said it was.
    const float tmax[] = { 4.9f, 5.1f, INFINITY, 4.999f, -0.5f };
    const bool expect[] = { false, true, true, false, false };
    for (int i = 0; i < 5; ++i) {
        ray.tmin = 0.0f;
        ray.tmax = tmax[i];
        assert_int_equal(drift_accel_occluded(accel, &ray), expect[i]);
        assert_int_equal(drift_accel_intersect(accel, &ray, &hit), expect[i]);
        uint8_t occ = 7;
        drift_accel_occluded_coherent(accel, &ray, &occ, 1);
        assert_int_equal(occ, expect[i]);
    }
    // tmin past the square: nothing.
    ray.tmin = 5.1f;
    ray.tmax = INFINITY;
    assert_false(drift_accel_occluded(accel, &ray));
    assert_false(drift_accel_intersect(accel, &ray, &hit));
    // A direction of length 2 halves t.
    ray.tmin = 0.0f;
    ray.dir = drift_vec3_make(0, 0, -2);
    ray.tmax = 2.4f;
    assert_false(drift_accel_occluded(accel, &ray));
    ray.tmax = 2.6f;
    assert_true(drift_accel_occluded(accel, &ray));
    assert_true(drift_accel_intersect(accel, &ray, &hit));
    assert_true(fabsf(hit.t - 2.5f) < 1e-5f);
    drift_accel_destroy(accel);
    drift_scene_destroy(scene);
    drift_context_destroy(ctx);
}

static void test_accel_embree_error_reaches_logger(void **state)
{
    (void)state;
    test_log_capture cap = { 0 };
    drift_context *ctx = test_context(1, &cap);
    rng r = { 5 };
    uint32_t material;
    drift_scene *scene = new_scene(ctx, &material);
    add_random_meshes(scene, &r, material, 1, 2000, 0.1f);
    assert_int_equal(drift_scene_commit(scene), DRIFT_OK);
    int errors_before = cap.errors;
    // A 4 KiB cap cannot hold a BVH over 2000 triangles: Embree's allocation fails inside
    // the build and Embree reports RTC_ERROR_OUT_OF_MEMORY through its error callback.
    drift_accel *accel = (drift_accel *)1;
    drift_result res =
        drift_accel_create(ctx, scene, &(drift_accel_desc){ .memory_limit_bytes = 4096 }, &accel);
    assert_int_equal(res, DRIFT_ERR_OUT_OF_MEMORY);
    assert_null(accel);
    assert_true(cap.errors > errors_before);
    assert_int_equal(cap.last_code, DRIFT_ERR_OUT_OF_MEMORY);
    // The message is Embree's own, forwarded by the callback.
    assert_non_null(strstr(cap.last_message, "embree"));
    // The same scene builds fine without the cap.
    assert_int_equal(drift_accel_create(ctx, scene, NULL, &accel), DRIFT_OK);
    drift_accel_destroy(accel);
    drift_scene_destroy(scene);
    drift_context_destroy(ctx);
}

static void test_accel_uncommitted_scene_rejected(void **state)
{
    (void)state;
    test_log_capture cap = { 0 };
    drift_context *ctx = test_context(1, &cap);
    rng r = { 9 };
    uint32_t material;
    drift_scene *scene = new_scene(ctx, &material);
    add_random_meshes(scene, &r, material, 1, 10, 0.3f);
    drift_accel *accel = (drift_accel *)1;
    assert_int_equal(drift_accel_create(ctx, scene, &(drift_accel_desc){ 0 }, &accel),
                     DRIFT_ERR_INVALID_ARGUMENT);
    assert_null(accel);
    assert_int_equal(cap.last_code, DRIFT_ERR_INVALID_ARGUMENT);
    // Editing a committed scene uncommits it.
    assert_int_equal(drift_scene_commit(scene), DRIFT_OK);
    add_random_meshes(scene, &r, material, 1, 10, 0.3f);
    assert_int_equal(drift_accel_create(ctx, scene, NULL, &accel), DRIFT_ERR_INVALID_ARGUMENT);
    // A bad quality is rejected too.
    assert_int_equal(drift_scene_commit(scene), DRIFT_OK);
    assert_int_equal(drift_accel_create(ctx, scene,
                                        &(drift_accel_desc){ .quality = DRIFT_ACCEL_QUALITY_COUNT },
                                        &accel),
                     DRIFT_ERR_INVALID_ARGUMENT);
    assert_int_equal(
        drift_accel_create(
            ctx, scene, &(drift_accel_desc){ .quality = DRIFT_ACCEL_QUALITY_FAST_BUILD }, &accel),
        DRIFT_OK);
    drift_accel_destroy(accel);
    drift_accel_destroy(NULL);
    drift_scene_destroy(scene);
    drift_context_destroy(ctx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_accel_matches_brute_force),
        cmocka_unit_test(test_accel_coherent_equals_single),
        cmocka_unit_test(test_accel_light_shapes_hit_at_known_t),
        cmocka_unit_test(test_accel_emissive_mesh_reports_its_light),
        cmocka_unit_test(test_accel_occluded_respects_range),
        cmocka_unit_test(test_accel_embree_error_reaches_logger),
        cmocka_unit_test(test_accel_uncommitted_scene_rejected),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
