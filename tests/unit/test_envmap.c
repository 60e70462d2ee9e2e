// Environment map: cube-face addressing, capture and lookup against synthetic radiance
// functions of direction (drift_envmap_capture_fn), mip levels by cone angle, and one
// capture of a real scene through drift_raster_trace_radiance.
#include "drift/accel.h"
#include "drift_test.h"
#include "raster/raster.h"

#include <math.h>
#include <stdatomic.h>
#include <string.h>

#define HALF_PI 1.57079632679489661923

// --- SYNTHETIC RADIANCE ---

typedef struct synthetic {
    drift_vec3 probe;
    atomic_int bad_rays; // rays not from the probe or not unit length
} synthetic;

static void check_ray(synthetic *s, drift_ray ray)
{
    bool from_probe =
        ray.origin.x == s->probe.x && ray.origin.y == s->probe.y && ray.origin.z == s->probe.z;
    if (!from_probe || fabsf(drift_vec3_length(ray.dir) - 1.0f) > 1e-5f) {
        atomic_fetch_add(&s->bad_rays, 1);
    }
}

// Emitted and reflected are different smooth functions, so mixing them up shows.
static drift_vec3 linear_emitted(drift_vec3 d)
{
    return drift_vec3_make(0.5f + 0.5f * d.x, 0.5f + 0.5f * d.y, 0.5f + 0.5f * d.z);
}

static drift_vec3 linear_reflected(drift_vec3 d)
{
    return drift_vec3_make(0.25f + 0.25f * d.z, 0.75f - 0.25f * d.x, 2.0f + d.y);
}

static drift_raster_radiance linear_fn(void *user, drift_ray ray, drift_sampler *sampler,
                                       uint64_t *rays)
{
    (void)sampler;
    check_ray(user, ray);
    *rays += 1;
    return (drift_raster_radiance){ linear_emitted(ray.dir), linear_reflected(ray.dir) };
}

static drift_raster_radiance constant_fn(void *user, drift_ray ray, drift_sampler *sampler,
                                         uint64_t *rays)
{
    (void)sampler;
    check_ray(user, ray);
    *rays += 1;
    return (drift_raster_radiance){ { 0.3f, 0.6f, 0.9f }, { 2.0f, 1.0f, 0.5f } };
}

// Varies over a few texels' worth of angle at the sizes used here.
static drift_raster_radiance wave_fn(void *user, drift_ray ray, drift_sampler *sampler,
                                     uint64_t *rays)
{
    (void)sampler;
    (void)user;
    *rays += 1;
    drift_vec3 d = ray.dir;
    float v = 0.5f + 0.5f * sinf(9.0f * d.x) * cosf(7.0f * d.y + 3.0f * d.z);
    return (drift_raster_radiance){ drift_vec3_splat(v), drift_vec3_splat(1.0f - v) };
}

// The sampler's first pair as the radiance: shows which sample each texel drew.
static drift_raster_radiance sampler_fn(void *user, drift_ray ray, drift_sampler *sampler,
                                        uint64_t *rays)
{
    (void)user;
    (void)ray;
    *rays += 1;
    drift_vec2 u = drift_sampler_next2(sampler);
    return (drift_raster_radiance){ { u.x, u.y, 0.0f }, { 0.0f, u.x, u.y } };
}

static drift_vec3 random_direction(uint32_t i)
{
    return drift_sample_uniform_sphere(
        drift_vec2_make(test_hash_unit(2 * i), test_hash_unit(2 * i + 1)));
}

static drift_envmap *capture(drift_context *ctx, drift_envmap_radiance_fn fn, synthetic *s,
                             int32_t face_size)
{
    drift_envmap *map = NULL;
    uint64_t rays = 0;
    assert_int_equal(drift_envmap_capture_fn(ctx, fn, s, s->probe, face_size, 7, &map, &rays),
                     DRIFT_OK);
    assert_non_null(map);
    assert_int_equal(rays, 6u * (uint64_t)face_size * (uint64_t)face_size);
    return map;
}

static void assert_vec3_near(drift_vec3 a, drift_vec3 b, double eps, int line)
{
    test_assert_close(a.x, b.x, eps, line);
    test_assert_close(a.y, b.y, eps, line);
    test_assert_close(a.z, b.z, eps, line);
}

// --- FACE ADDRESSING ---

typedef struct texel_id {
    int face;
    int32_t i, j;
} texel_id;

static texel_id texel_of(drift_vec3 dir, int32_t n)
{
    drift_vec2 st;
    texel_id t = { drift_cube_face_coords(dir, &st), 0, 0 };
    assert_true(t.face >= 0 && t.face < 6);
    assert_true(st.x >= 0.0f && st.x <= 1.0f && st.y >= 0.0f && st.y <= 1.0f);
    t.i = (int32_t)fminf(st.x * (float)n, (float)(n - 1));
    t.j = (int32_t)fminf(st.y * (float)n, (float)(n - 1));
    return t;
}

// The texel whose centre direction is closest to dir, by brute force; *out_best_dot its cosine.
static texel_id nearest_centre(drift_vec3 dir, int32_t n, double *out_best_dot)
{
    texel_id best = { -1, 0, 0 };
    double best_dot = -2.0;
    for (int f = 0; f < 6; ++f) {
        for (int32_t j = 0; j < n; ++j) {
            for (int32_t i = 0; i < n; ++i) {
                double d = drift_vec3_dot(dir, drift_cube_texel_direction(n, f, i, j));
                if (d > best_dot) {
                    best_dot = d;
                    best = (texel_id){ f, i, j };
                }
            }
        }
    }
    *out_best_dot = best_dot;
    return best;
}

static void test_envmap_texel_centres_round_trip(void **state)
{
    (void)state;
    const int32_t sizes[] = { 1, 5, 8 };
    for (size_t k = 0; k < sizeof(sizes) / sizeof(sizes[0]); ++k) {
        int32_t n = sizes[k];
        for (int f = 0; f < 6; ++f) {
            for (int32_t j = 0; j < n; ++j) {
                for (int32_t i = 0; i < n; ++i) {
                    texel_id t = texel_of(drift_cube_texel_direction(n, f, i, j), n);
                    assert_int_equal(t.face, f);
                    assert_int_equal(t.i, i);
                    assert_int_equal(t.j, j);
                }
            }
        }
    }
}

// OpenGL's table, one direction a face: (s, t) = ((sc / m + 1) / 2, (tc / m + 1) / 2).
static void test_envmap_faces_follow_the_opengl_convention(void **state)
{
    (void)state;

    const struct {
        drift_vec3 dir;
        int face;
        float s, t;
    } cases[] = {
        { { 2.0f, -1.0f, 0.5f }, 0, 0.375f, 0.75f },  // sc = -z, tc = -y
        { { -2.0f, 1.0f, 0.5f }, 1, 0.625f, 0.25f },  // sc = +z, tc = -y
        { { 0.5f, 2.0f, -1.0f }, 2, 0.625f, 0.25f },  // sc = +x, tc = +z
        { { 0.5f, -2.0f, -1.0f }, 3, 0.625f, 0.75f }, // sc = +x, tc = -z
        { { -1.0f, 0.5f, 2.0f }, 4, 0.25f, 0.375f },  // sc = +x, tc = -y
        { { -1.0f, 0.5f, -2.0f }, 5, 0.75f, 0.375f }, // sc = -x, tc = -y
    };

    for (size_t k = 0; k < sizeof(cases) / sizeof(cases[0]); ++k) {
        drift_vec2 st;
        assert_int_equal(drift_cube_face_coords(cases[k].dir, &st), cases[k].face);
        assert_near(st.x, cases[k].s, 1e-6);
        assert_near(st.y, cases[k].t, 1e-6);
    }
    drift_vec2 st;
    assert_int_equal(drift_cube_face_coords(drift_vec3_make(0.0f, 0.0f, 0.0f), &st), -1);
    assert_int_equal(drift_cube_face_coords(drift_vec3_make(NAN, 1.0f, 0.0f), &st), -1);
}

// With an odd face size each axis passes through a texel centre: the middle texel of its
// own face, and the nearest centre of all.
static void test_envmap_axes_map_to_their_face_centre(void **state)
{
    (void)state;
    const int32_t n = 5;
    const drift_vec3 axes[6] = { { 1, 0, 0 },  { -1, 0, 0 }, { 0, 1, 0 },
                                 { 0, -1, 0 }, { 0, 0, 1 },  { 0, 0, -1 } };
    for (int f = 0; f < 6; ++f) {
        texel_id t = texel_of(axes[f], n);
        assert_int_equal(t.face, f);
        assert_int_equal(t.i, n / 2);
        assert_int_equal(t.j, n / 2);
        double best_dot;
        texel_id nearest = nearest_centre(axes[f], n, &best_dot);
        assert_memory_equal(&t, &nearest, sizeof(t));
        assert_near(best_dot, 1.0, 1e-6);
    }
}

// The texel a direction falls in has the closest centre, up to a sliver: texel borders are
// straight lines on the face (great circles), while the bisectors between neighbouring centres
// tilt where the projection stretches, toward the face corners. Over 20000 directions at n = 8
// the chosen centre was at most 0.2 texel angles farther than the nearest, and the nearest in
// 94% of cases; any wrong orientation or rounding costs a whole texel.
static void test_envmap_random_directions_pick_the_nearest_texel(void **state)
{
    (void)state;
    const int32_t n = 8;
    const double texel_angle = HALF_PI / n;
    int exact = 0, count = 2000;
    for (uint32_t k = 0; k < (uint32_t)count; ++k) {
        drift_vec3 d = random_direction(k);
        texel_id t = texel_of(d, n);
        double best_dot;
        texel_id nearest = nearest_centre(d, n, &best_dot);
        double chosen = drift_vec3_dot(d, drift_cube_texel_direction(n, t.face, t.i, t.j));
        double excess = acos(fmin(chosen, 1.0)) - acos(fmin(best_dot, 1.0));
        assert_true(excess <= 0.3 * texel_angle);
        exact += memcmp(&t, &nearest, sizeof(t)) == 0;
    }
    assert_true(exact >= count * 9 / 10);
}

// --- LOOKUP ---

static void test_envmap_level0_matches_the_function(void **state)
{
    (void)state;
    drift_context *ctx = test_context(2, NULL);
    synthetic s = { .probe = { 1.0f, -2.0f, 0.5f } };
    const int32_t n = 16;
    drift_envmap *map = capture(ctx, linear_fn, &s, n);
    assert_int_equal(atomic_load(&s.bad_rays), 0);
    // At texel centres the lookup is the captured sample itself.
    for (int f = 0; f < 6; ++f) {
        for (int32_t j = 0; j < n; ++j) {
            for (int32_t i = 0; i < n; ++i) {
                drift_vec3 d = drift_cube_texel_direction(n, f, i, j);
                drift_raster_radiance r = drift_envmap_lookup(map, d, 0.0f);
                assert_vec3_near(r.emitted, linear_emitted(d), 1e-6, __LINE__);
                assert_vec3_near(r.reflected, linear_reflected(d), 1e-6, __LINE__);
            }
        }
    }
    // Elsewhere bilinear interpolation errs by O(h^2) inside a face (h = 2 / n on the face
    // plane) and by at most the slope times half a texel diagonal where it clamps at edges.
    double h = 2.0 / n, inner_bound = 0.5 * h * h, edge_bound = 0.5 * 0.5 * sqrt(2.0) * h;
    double inner_max = 0.0, edge_max = 0.0;
    for (uint32_t k = 0; k < 4000; ++k) {
        drift_vec3 d = random_direction(k);
        drift_raster_radiance r = drift_envmap_lookup(map, d, 0.0f);
        drift_vec3 e = drift_vec3_sub(r.emitted, linear_emitted(d));
        drift_vec3 g = drift_vec3_sub(r.reflected, linear_reflected(d));
        double err = fmax(drift_vec3_max_component(drift_vec3_max(e, drift_vec3_neg(e))),
                          drift_vec3_max_component(drift_vec3_max(g, drift_vec3_neg(g))));
        drift_vec2 st;
        drift_cube_face_coords(d, &st);
        float margin = 0.5f / (float)n;
        bool inner = st.x > margin && st.x < 1.0f - margin && st.y > margin && st.y < 1.0f - margin;
        if (inner) {
            inner_max = fmax(inner_max, err);
        } else {
            edge_max = fmax(edge_max, err);
        }
    }
    assert_true(inner_max <= inner_bound);
    assert_true(edge_max <= edge_bound);
    drift_envmap_destroy(ctx, map);
    drift_context_destroy(ctx);
}

static void test_envmap_constant_stays_constant_at_every_cone(void **state)
{
    (void)state;
    drift_context *ctx = test_context(2, NULL);
    synthetic s = { .probe = { 0.0f, 0.0f, 0.0f } };
    drift_envmap *map = capture(ctx, constant_fn, &s, 8);
    const float cones[] = { 0.0f, 0.05f, 0.2f, 0.3f, 0.7f, 1.5f, 3.2f };
    for (size_t c = 0; c < sizeof(cones) / sizeof(cones[0]); ++c) {
        for (uint32_t k = 0; k < 200; ++k) {
            drift_raster_radiance r = drift_envmap_lookup(map, random_direction(k), cones[c]);
            assert_vec3_near(r.emitted, drift_vec3_make(0.3f, 0.6f, 0.9f), 1e-6, __LINE__);
            assert_vec3_near(r.reflected, drift_vec3_make(2.0f, 1.0f, 0.5f), 1e-6, __LINE__);
        }
    }
    drift_envmap_destroy(ctx, map);
    drift_context_destroy(ctx);
}

// A cone of half angle (pi/2) / (n/2) reads level 1 alone: at a level-1 texel centre that is
// the mean of the 2x2 level-0 texels under it. A cone past the 1x1 level reads each face's mean.
static void test_envmap_cone_angle_selects_the_mip_level(void **state)
{
    (void)state;
    drift_context *ctx = test_context(2, NULL);
    synthetic s = { .probe = { 0.0f, 0.0f, 0.0f } };
    const int32_t n = 8;
    drift_envmap *map = capture(ctx, linear_fn, &s, n);
    assert_int_equal(drift_envmap_face_size(map), n);
    assert_int_equal(drift_envmap_level_count(map), 4);
    for (int f = 0; f < 6; ++f) {
        drift_vec3 face_mean = { 0.0f, 0.0f, 0.0f };
        for (int32_t j = 0; j < n / 2; ++j) {
            for (int32_t i = 0; i < n / 2; ++i) {
                drift_vec3 mean = { 0.0f, 0.0f, 0.0f };
                for (int32_t q = 0; q < 4; ++q) {
                    drift_vec3 d = drift_cube_texel_direction(n, f, 2 * i + q % 2, 2 * j + q / 2);
                    mean = drift_vec3_fma(mean, linear_emitted(d), 0.25f);
                }
                face_mean = drift_vec3_fma(face_mean, mean, 1.0f / (float)(n * n / 4));
                drift_vec3 centre = drift_cube_texel_direction(n / 2, f, i, j);
                drift_raster_radiance r =
                    drift_envmap_lookup(map, centre, (float)HALF_PI / (float)(n / 2));
                assert_vec3_near(r.emitted, mean, 1e-5, __LINE__);
            }
        }
        drift_vec3 anywhere = drift_cube_texel_direction(n, f, 1, 6);
        drift_raster_radiance wide = drift_envmap_lookup(map, anywhere, 2.0f);
        assert_vec3_near(wide.emitted, face_mean, 1e-5, __LINE__);
    }
    drift_envmap_destroy(ctx, map);
    drift_context_destroy(ctx);
}

// Between levels the lookup blends linearly in log2 of the cone angle: halfway (in that
// scale) between the angles of levels 1 and 2 it is the mean of the two levels' lookups.
static void test_envmap_cones_between_levels_blend_trilinearly(void **state)
{
    (void)state;
    drift_context *ctx = test_context(2, NULL);
    synthetic s = { .probe = { 0.0f, 0.0f, 0.0f } };
    const int32_t n = 16;
    drift_envmap *map = capture(ctx, wave_fn, &s, n);
    float angle1 = (float)HALF_PI / 8.0f, angle2 = (float)HALF_PI / 4.0f;
    float halfway = sqrtf(angle1 * angle2);
    double largest_step = 0.0;
    for (uint32_t k = 0; k < 500; ++k) {
        drift_vec3 d = random_direction(k);
        drift_raster_radiance a = drift_envmap_lookup(map, d, angle1);
        drift_raster_radiance b = drift_envmap_lookup(map, d, angle2);
        drift_raster_radiance m = drift_envmap_lookup(map, d, halfway);
        assert_near(m.emitted.x, 0.5f * (a.emitted.x + b.emitted.x), 1e-5);
        assert_near(m.reflected.y, 0.5f * (a.reflected.y + b.reflected.y), 1e-5);
        largest_step = fmax(largest_step, fabs(a.emitted.x - b.emitted.x));
    }
    assert_true(largest_step > 0.05); // the levels differ, so the blend is seen
    drift_envmap_destroy(ctx, map);
    drift_context_destroy(ctx);
}

static double lookup_variance(const drift_envmap *map, float cone)
{
    double sum = 0.0, sum2 = 0.0;
    const uint32_t count = 4000;
    for (uint32_t k = 0; k < count; ++k) {
        double v = drift_envmap_lookup(map, random_direction(k), cone).emitted.x;
        sum += v;
        sum2 += v * v;
    }
    double mean = sum / count;
    return sum2 / count - mean * mean;
}

// Blurring over a wider cone averages the function's swings away; the variance falls with
// every step up the chain.
static void test_envmap_wide_cones_are_smoother(void **state)
{
    (void)state;
    drift_context *ctx = test_context(2, NULL);
    synthetic s = { .probe = { 0.0f, 0.0f, 0.0f } };
    const int32_t n = 32;
    drift_envmap *map = capture(ctx, wave_fn, &s, n);
    double sharp = lookup_variance(map, 0.0f);
    double mid = lookup_variance(map, (float)HALF_PI / 4.0f);
    double wide = lookup_variance(map, (float)HALF_PI / 2.0f);
    assert_true(sharp > 0.02);
    assert_true(mid < 0.8 * sharp);
    assert_true(wide < 0.8 * mid);
    drift_envmap_destroy(ctx, map);
    drift_context_destroy(ctx);
}

// --- CAPTURE ---

// Each texel draws sample 0 of its own sampler: the map does not depend on thread count.
static void test_envmap_capture_is_deterministic_across_threads(void **state)
{
    (void)state;
    drift_context *one = test_context(1, NULL), *two = test_context(2, NULL);
    synthetic s = { .probe = { 0.0f, 0.0f, 0.0f } };
    const int32_t n = 6;
    drift_envmap *a = capture(one, sampler_fn, &s, n), *b = capture(two, sampler_fn, &s, n);
    assert_int_equal(drift_envmap_level_count(a), 3); // 6, 3, 1
    bool differ_between_texels = false;
    float first = drift_envmap_lookup(a, drift_cube_texel_direction(n, 0, 0, 0), 0.0f).emitted.x;
    for (int f = 0; f < 6; ++f) {
        for (int32_t j = 0; j < n; ++j) {
            for (int32_t i = 0; i < n; ++i) {
                drift_vec3 d = drift_cube_texel_direction(n, f, i, j);
                drift_raster_radiance ra = drift_envmap_lookup(a, d, 0.0f);
                drift_raster_radiance rb = drift_envmap_lookup(b, d, 0.0f);
                assert_memory_equal(&ra, &rb, sizeof(ra));
                differ_between_texels |= fabsf(ra.emitted.x - first) > 1e-3f;
            }
        }
    }
    assert_true(differ_between_texels);
    drift_envmap_destroy(one, a);
    drift_envmap_destroy(two, b);
    drift_context_destroy(one);
    drift_context_destroy(two);
}

// --- CAPTURE FROM A SCENE ---

// The probe above an endless grey floor (kd = 0.5) under a constant sky: upward texels see the
// sky as emitted light; downward ones see the floor, which emits nothing and reflects
// kd * sky (a Lambertian plane under a uniform hemisphere). Skipping the floor mesh (a probe
// inside its own object) sees the sky everywhere.
static void test_envmap_capture_sees_the_scene(void **state)
{
    (void)state;
    drift_context *ctx = test_context(2, NULL);
    drift_scene *scene = NULL;
    assert_int_equal(drift_scene_create(ctx, &scene), DRIFT_OK);
    const drift_vec3 sky = { 0.2f, 0.4f, 0.8f };
    scene->environment.color = sky;
    uint32_t grey;
    drift_material m = drift_material_make(drift_vec3_splat(0.5f));
    assert_int_equal(drift_scene_add_material(scene, &m, &grey), DRIFT_OK);
    const float h = 1000.0f;
    const float p[] = { -h, -1.0f, -h, h, -1.0f, -h, h, -1.0f, h, -h, -1.0f, h };
    const uint32_t idx[] = { 0, 2, 1, 0, 3, 2 }; // normal +y
    uint32_t floor_mesh = test_add_mesh(scene, p, 4, idx, 2, grey);
    assert_int_equal(drift_scene_commit(scene), DRIFT_OK);
    drift_accel *accel = NULL;
    assert_int_equal(drift_accel_create(ctx, scene, &(drift_accel_desc){ 0 }, &accel), DRIFT_OK);
    drift_raster_shading shading = { .scene = scene, .accel = accel, .light_samples = 16 };
    const int32_t n = 8;
    const drift_vec3 probe = { 0.0f, 0.0f, 0.0f };
    drift_vec3 down = { 0.0f, -1.0f, 0.0f }, up = { 0.0f, 1.0f, 0.0f };

    drift_envmap *map = NULL;
    uint64_t rays = 0;
    assert_int_equal(
        drift_envmap_capture(ctx, &shading, probe, DRIFT_INVALID_INDEX, n, 3, &map, &rays),
        DRIFT_OK);
    assert_true(rays > 6u * (uint64_t)(n * n)); // camera rays plus the floor's shadow rays
    drift_raster_radiance r_up = drift_envmap_lookup(map, up, 0.0f);
    assert_vec3_near(r_up.emitted, sky, 1e-6, __LINE__);
    assert_vec3_near(r_up.reflected, drift_vec3_splat(0.0f), 0.0, __LINE__);
    drift_raster_radiance r_down = drift_envmap_lookup(map, down, 2.0f); // the face's mean
    assert_vec3_near(r_down.emitted, drift_vec3_splat(0.0f), 0.0, __LINE__);
    assert_vec3_near(r_down.reflected, drift_vec3_scale(sky, 0.5f), 0.01, __LINE__);
    drift_envmap_destroy(ctx, map);

    assert_int_equal(drift_envmap_capture(ctx, &shading, probe, floor_mesh, n, 3, &map, NULL),
                     DRIFT_OK);
    r_down = drift_envmap_lookup(map, down, 0.0f);
    assert_vec3_near(r_down.emitted, sky, 1e-6, __LINE__);
    assert_vec3_near(r_down.reflected, drift_vec3_splat(0.0f), 0.0, __LINE__);
    drift_envmap_destroy(ctx, map);

    drift_accel_destroy(accel);
    drift_scene_destroy(scene);
    drift_context_destroy(ctx);
}

static void test_envmap_probe_and_bad_arguments(void **state)
{
    (void)state;
    test_log_capture log = { 0 };
    drift_context *ctx = test_context(2, &log);
    synthetic s = { .probe = { 3.0f, 4.0f, -5.0f } };
    drift_envmap *map = capture(ctx, constant_fn, &s, 2);
    drift_vec3 p = drift_envmap_probe(map);
    assert_memory_equal(&p, &s.probe, sizeof(p));
    drift_envmap_destroy(ctx, map);
    drift_envmap_destroy(ctx, NULL);

    const int32_t bad_sizes[] = { 0, -3, DRIFT_ENVMAP_MAX_FACE_SIZE + 1 };
    for (size_t k = 0; k < sizeof(bad_sizes) / sizeof(bad_sizes[0]); ++k) {
        map = (drift_envmap *)&s; // must be cleared
        int errors = log.errors;
        assert_int_equal(
            drift_envmap_capture_fn(ctx, constant_fn, &s, s.probe, bad_sizes[k], 0, &map, NULL),
            DRIFT_ERR_INVALID_ARGUMENT);
        assert_null(map);
        assert_int_equal(log.errors, errors + 1);
        assert_int_equal(log.last_code, DRIFT_ERR_INVALID_ARGUMENT);
    }
    assert_int_equal(drift_envmap_capture_fn(ctx, NULL, &s, s.probe, 4, 0, &map, NULL),
                     DRIFT_ERR_INVALID_ARGUMENT);
    drift_vec3 nan_probe = { NAN, 0.0f, 0.0f };
    assert_int_equal(drift_envmap_capture_fn(ctx, constant_fn, &s, nan_probe, 4, 0, &map, NULL),
                     DRIFT_ERR_INVALID_ARGUMENT);
    assert_null(map);
    drift_context_destroy(ctx);
}

// --- PARALLAX CORRECTION (box projection) ---

// A closed room, the box [-1, 1]^3, whose walls show their own position: the radiance along a
// ray is where it leaves the box (offset so every channel is positive).
static drift_vec3 room_exit(drift_vec3 p, drift_vec3 d)
{
    float t = INFINITY;
    const float pp[3] = { p.x, p.y, p.z }, dd[3] = { d.x, d.y, d.z };
    for (int a = 0; a < 3; ++a) {
        if (dd[a] != 0.0f) {
            t = fminf(t, ((dd[a] > 0.0f ? 1.0f : -1.0f) - pp[a]) / dd[a]);
        }
    }
    return drift_vec3_fma(p, d, t);
}

static drift_raster_radiance room_fn(void *user, drift_ray ray, drift_sampler *sampler,
                                     uint64_t *rays)
{
    (void)user;
    (void)sampler;
    *rays += 1;
    drift_vec3 w = drift_vec3_add(room_exit(ray.origin, ray.dir), drift_vec3_splat(2.0f));
    return (drift_raster_radiance){ w, w };
}

// A mirror floor (y = -1) in the room, the map captured off-centre: the texel a floor point's
// reflected ray looks up must show the wall point that ray really meets. Box-projected, it does
// within two texels' footprint; looked up along the reflected direction (the map as if the floor
// point sat at the probe), it does not.
static void test_envmap_box_projection_finds_the_reflected_wall_point(void **state)
{
    (void)state;
    drift_context *ctx = test_context(2, NULL);
    synthetic s = { .probe = { 0.1f, 0.2f, -0.15f } };
    const int32_t n = 64;
    drift_envmap *map = NULL;
    assert_int_equal(drift_envmap_capture_fn(ctx, room_fn, &s, s.probe, n, 7, &map, NULL),
                     DRIFT_OK);
    drift_bounds3 room = { { -1.0f, -1.0f, -1.0f }, { 1.0f, 1.0f, 1.0f } };
    // A texel spans 2/n of a face across; two of them, and the probe at most ~2 units away.
    const float tolerance = 2.0f * 2.0f / (float)n * 2.0f;
    int far_without = 0, count = 0;
    double worst_with = 0.0;
    for (uint32_t i = 0; i < 64; ++i) {
        drift_vec3 p = { -0.8f + 1.0f * test_hash_unit(4 * i), -1.0f,
                         -0.5f + 1.0f * test_hash_unit(4 * i + 1) };
        drift_vec3 w = { 1.0f, -0.6f + 1.2f * test_hash_unit(4 * i + 2),
                         -0.6f + 1.2f * test_hash_unit(4 * i + 3) };
        drift_vec3 d = drift_vec3_normalize(drift_vec3_sub(w, p));
        drift_vec3 seen_with = drift_vec3_sub(
            drift_envmap_lookup(map, drift_envmap_parallax_direction(room, s.probe, p, d, NULL),
                                0.0f)
                .reflected,
            drift_vec3_splat(2.0f));
        drift_vec3 seen_without =
            drift_vec3_sub(drift_envmap_lookup(map, d, 0.0f).reflected, drift_vec3_splat(2.0f));
        double e_with = drift_vec3_length(drift_vec3_sub(seen_with, w));
        worst_with = fmax(worst_with, e_with);
        far_without += drift_vec3_length(drift_vec3_sub(seen_without, w)) > tolerance ? 1 : 0;
        ++count;
    }
    assert_true(worst_with < (double)tolerance);
    assert_true(far_without > count * 9 / 10);
    // Outside the box there is nothing to correct against: the direction is kept.
    drift_vec3 up = { 0.0f, 1.0f, 0.0f };
    drift_vec3 kept =
        drift_envmap_parallax_direction(room, s.probe, drift_vec3_make(3.0f, 0.0f, 0.0f), up, NULL);
    assert_true(kept.x == up.x && kept.y == up.y && kept.z == up.z);
    drift_envmap_destroy(ctx, map);
    drift_context_destroy(ctx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_envmap_faces_follow_the_opengl_convention),
        cmocka_unit_test(test_envmap_texel_centres_round_trip),
        cmocka_unit_test(test_envmap_axes_map_to_their_face_centre),
        cmocka_unit_test(test_envmap_random_directions_pick_the_nearest_texel),
        cmocka_unit_test(test_envmap_level0_matches_the_function),
        cmocka_unit_test(test_envmap_constant_stays_constant_at_every_cone),
        cmocka_unit_test(test_envmap_cone_angle_selects_the_mip_level),
        cmocka_unit_test(test_envmap_cones_between_levels_blend_trilinearly),
        cmocka_unit_test(test_envmap_wide_cones_are_smoother),
        cmocka_unit_test(test_envmap_capture_is_deterministic_across_threads),
        cmocka_unit_test(test_envmap_capture_sees_the_scene),
        cmocka_unit_test(test_envmap_probe_and_bad_arguments),
        cmocka_unit_test(test_envmap_box_projection_finds_the_reflected_wall_point),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
