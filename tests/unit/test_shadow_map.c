// Shadow maps against ray-traced visibility: a 1-texel PCF matches shadow rays away from
// edges, hard == PCF(1), PCSS penumbrae widen with the occluder's height as w = L h / (H - h)
// predicts, radius-0 PCSS is exactly hard, open sky and deep umbra are 1 and 0 under every
// lookup, and the build skips faces behind a one-sided light (exact ray counts).
#include "drift/accel.h"
#include "drift/scene.h"
#include "drift_test.h"
#include "raster/raster.h"

#include <math.h>
#include <stdio.h>

#define GROUND_HALF  4.0f
#define LIGHT_HEIGHT 2.0f

static const drift_vec3 up = { 0.0f, 1.0f, 0.0f };

// A ground quad at y = 0, one horizontal square occluder and one light.
typedef struct rig {
    drift_context *ctx;
    drift_scene *scene;
    drift_accel *accel;
    drift_raster_light light;
    drift_shadow_map *map;
    uint64_t rays;
} rig;

static rig rig_begin(void)
{
    rig r = { .ctx = test_context(2, NULL) };
    assert_int_equal(drift_scene_create(r.ctx, &r.scene), DRIFT_OK);
    drift_material m = drift_material_make(drift_vec3_splat(0.5f));
    uint32_t material;
    assert_int_equal(drift_scene_add_material(r.scene, &m, &material), DRIFT_OK);
    assert_int_equal(material, 0);
    return r;
}

// Horizontal square [cx - half, cx + half] x [cz - half, cz + half] at height y.
static void add_square(rig *r, float cx, float cz, float half, float y)
{
    const float p[] = { cx - half, y, cz - half, cx + half, y, cz - half,
                        cx + half, y, cz + half, cx - half, y, cz + half };
    const uint32_t idx[] = { 0, 2, 1, 0, 3, 2 };
    test_add_mesh(r->scene, p, 4, idx, 2, 0);
}

static void add_ground(rig *r)
{
    add_square(r, 0.0f, 0.0f, GROUND_HALF, 0.0f);
}

static uint32_t add_light(rig *r, drift_light light)
{
    light.color = drift_vec3_splat(1.0f);
    uint32_t index;
    assert_int_equal(drift_scene_add_light(r->scene, &light, &index), DRIFT_OK);
    return index;
}

// The hybrid light that lights.c would make, filled by hand.
static void set_light(rig *r, drift_light_type type, drift_vec3 centre, float radius,
                      drift_vec3 direction, bool one_sided, uint32_t index)
{
    r->light = (drift_raster_light){ .type = type,
                                     .centre = centre,
                                     .direction = direction,
                                     .radius = radius,
                                     .one_sided = one_sided,
                                     .first_light = index,
                                     .light_count = index == DRIFT_INVALID_INDEX ? 0 : 1,
                                     .mesh = DRIFT_INVALID_INDEX,
                                     .light_cdf = NULL };
}

static void add_sphere_light(rig *r, drift_vec3 centre, float radius)
{
    uint32_t index = add_light(
        r, (drift_light){ .type = DRIFT_LIGHT_SPHERE, .position = centre, .radius = radius });
    set_light(r, DRIFT_LIGHT_SPHERE, centre, radius, drift_vec3_splat(0.0f), false, index);
}

static void add_point_light(rig *r, drift_vec3 centre)
{
    uint32_t index = add_light(r, (drift_light){ .type = DRIFT_LIGHT_POINT, .position = centre });
    set_light(r, DRIFT_LIGHT_POINT, centre, 0.0f, drift_vec3_splat(0.0f), false, index);
}

// Square quad light of half size `half` at height y, emitting down (cross(u, v) = -y).
static void add_down_quad_light(rig *r, float half, float y, bool one_sided)
{
    drift_light l = { .type = DRIFT_LIGHT_QUAD,
                      .position = { -half, y, -half },
                      .edge_u = { 2.0f * half, 0.0f, 0.0f },
                      .edge_v = { 0.0f, 0.0f, 2.0f * half } };
    uint32_t index = add_light(r, l);
    set_light(r, DRIFT_LIGHT_QUAD, drift_vec3_make(0.0f, y, 0.0f), half * sqrtf(2.0f),
              drift_vec3_make(0.0f, -1.0f, 0.0f), one_sided, index);
}

static void rig_build(rig *r, int32_t size)
{
    assert_int_equal(drift_scene_commit(r->scene), DRIFT_OK);
    assert_int_equal(drift_accel_create(r->ctx, r->scene, &(drift_accel_desc){ 0 }, &r->accel),
                     DRIFT_OK);
    drift_shadow_map_params params = { .size = size, .bias_texels = 1.5f };
    r->rays = 0;
    assert_int_equal(
        drift_shadow_map_build(r->ctx, r->scene, r->accel, &r->light, &params, &r->map, &r->rays),
        DRIFT_OK);
    assert_non_null(r->map);
}

static void rig_destroy(rig *r)
{
    drift_shadow_map_destroy(r->ctx, r->map);
    drift_accel_destroy(r->accel);
    drift_scene_destroy(r->scene);
    drift_context_destroy(r->ctx);
}

// Ray-traced visibility of the light's centre from p, stopping at the light's bounding
// radius (a sphere light's own surface is not an occluder).
static bool traced_visible(const rig *r, drift_vec3 p, drift_vec3 n)
{
    drift_vec3 to = drift_vec3_sub(r->light.centre, p);
    float dist = drift_vec3_length(to);
    drift_vec3 dir = drift_vec3_scale(to, 1.0f / dist);
    drift_ray ray = { .origin = drift_offset_origin(p, n, dir),
                      .dir = dir,
                      .tmin = 0.0f,
                      .tmax = (dist - r->light.radius) * (1.0f - 1e-4f) };
    return !drift_accel_occluded(r->accel, &ray);
}

static drift_vec3 ground_point(float x, float z)
{
    return drift_vec3_make(x, 0.0f, z);
}

// --- TESTS ---

#define GRID      48
#define GRID_HALF 3.6f

static float grid_coord(int i)
{
    return -GRID_HALF + 2.0f * GRID_HALF * (float)i / (float)(GRID - 1);
}

// Away from shadow edges (visibility constant out to two grid steps, 0.3 units, against a
// texel footprint under 0.1 on this ground), one PCF tap is the shadow ray's answer.
static void test_pcf1_matches_ray_traced_away_from_edges(void **state)
{
    (void)state;
    rig r = rig_begin();
    add_ground(&r);
    add_square(&r, 0.3f, -0.2f, 0.6f, 1.0f);
    add_square(&r, -1.5f, 1.2f, 0.3f, 0.5f);
    add_sphere_light(&r, drift_vec3_make(0.0f, 3.0f, 0.0f), 0.2f);
    rig_build(&r, 256);

    bool *visible = test_malloc(sizeof(bool) * GRID * GRID);
    for (int j = 0; j < GRID; ++j) {
        for (int i = 0; i < GRID; ++i) {
            visible[j * GRID + i] =
                traced_visible(&r, ground_point(grid_coord(i), grid_coord(j)), up);
        }
    }
    int compared = 0, mismatches = 0, lit = 0, shadowed = 0;
    for (int j = 2; j < GRID - 2; ++j) {
        for (int i = 2; i < GRID - 2; ++i) {
            bool v = visible[j * GRID + i], stable = true;
            for (int dj = -2; dj <= 2; ++dj) {
                for (int di = -2; di <= 2; ++di) {
                    stable = stable && visible[(j + dj) * GRID + i + di] == v;
                }
            }
            if (!stable) {
                continue;
            }
            float pcf =
                drift_shadow_map_pcf(r.map, ground_point(grid_coord(i), grid_coord(j)), up, 1);
            assert_true(pcf == 0.0f || pcf == 1.0f);
            compared++;
            mismatches += (pcf == 1.0f) != v;
            lit += v;
            shadowed += !v;
        }
    }
    test_free(visible);
    assert_int_equal(mismatches, 0);
    assert_true(compared > GRID * GRID / 2);
    assert_true(lit > 100);
    assert_true(shadowed > 10);
    rig_destroy(&r);
}

// hard and PCF(1) are one tap at the same place: bit-identical, on the ground, on the
// occluders and at points in the air with arbitrary normals.
static void test_hard_equals_pcf1(void **state)
{
    (void)state;
    rig r = rig_begin();
    add_ground(&r);
    add_square(&r, 0.3f, -0.2f, 0.6f, 1.0f);
    add_sphere_light(&r, drift_vec3_make(0.5f, 3.0f, 0.2f), 0.3f);
    rig_build(&r, 64);
    int shadowed = 0;
    for (uint32_t k = 0; k < 2000; ++k) {
        drift_vec3 p = { GRID_HALF * (2.0f * test_hash_unit(4 * k) - 1.0f),
                         k % 3 == 0 ? 1.5f * test_hash_unit(4 * k + 1) : 0.0f,
                         GRID_HALF * (2.0f * test_hash_unit(4 * k + 2) - 1.0f) };
        drift_vec3 n = k % 3 == 0 ? drift_sample_uniform_sphere(drift_vec2_make(
                                        test_hash_unit(4 * k + 3), test_hash_unit(5 * k + 7)))
                                  : up;
        float hard = drift_shadow_map_hard(r.map, p, n);
        assert_true(hard == drift_shadow_map_pcf(r.map, p, n, 1));
        shadowed += hard == 0.0f;
    }
    assert_true(shadowed > 50);
    rig_destroy(&r);
}

// PCSS visibility along the ground line z = 0 from under the occluder's centre outward,
// averaged over rotations, and the distance between its 0.1 and 0.9 crossings.
static float pcss_penumbra_width(const rig *r, float x_max)
{
    const int steps = 320, rotations = 8;
    float x_low = -1.0f, x_high = -1.0f;
    for (int s = 0; s <= steps; ++s) {
        float x = x_max * (float)s / (float)steps, v = 0.0f;
        for (int k = 0; k < rotations; ++k) {
            v += drift_shadow_map_pcss(r->map, ground_point(x, 0.0f), up,
                                       drift_hash_combine((uint32_t)s, (uint32_t)k));
        }
        v /= (float)rotations;
        if (s == 0) {
            assert_true(v == 0.0f); // umbra under the occluder
        }
        if (x_low < 0.0f && v >= 0.1f) {
            x_low = x;
        }
        if (x_high < 0.0f && v >= 0.9f) {
            x_high = x;
        }
    }
    assert_true(x_low >= 0.0f && x_high >= x_low);
    return x_high - x_low;
}

// A sphere light of radius L at height H over a square occluder at height h: the penumbra
// half-width at the receiver is w = L (d_r - d_b) / d_b = L h / (H - h) (measured across
// the ray); a PCF disk of radius w over an edge goes from 10% to 90% lit across 1.37 w,
// 1.37 w / cos(phi) along the ground at angle phi from the vertical.
static void test_pcss_penumbra_widens_with_occluder_height(void **state)
{
    (void)state;
    const float L = 0.3f, half = 0.5f, heights[2] = { 0.4f, 0.8f };
    float widths[2];
    for (int i = 0; i < 2; ++i) {
        rig r = rig_begin();
        add_ground(&r);
        add_square(&r, 0.0f, 0.0f, half, heights[i]);
        add_sphere_light(&r, drift_vec3_make(0.0f, LIGHT_HEIGHT, 0.0f), L);
        rig_build(&r, 256);
        widths[i] = pcss_penumbra_width(&r, 1.6f);
        float h = heights[i];
        float w = L * h / (LIGHT_HEIGHT - h);
        float edge_x = half * LIGHT_HEIGHT / (LIGHT_HEIGHT - h);
        float cos_phi = LIGHT_HEIGHT / sqrtf(LIGHT_HEIGHT * LIGHT_HEIGHT + edge_x * edge_x);
        float expected = 1.37f * w / cos_phi;
        printf("occluder at h = %.2f: penumbra 10-90%% width %.4f, expected %.4f (w = %.4f)\n",
               (double)h, (double)widths[i], (double)expected, (double)w);
        assert_true(widths[i] > 0.5f * expected && widths[i] < 2.0f * expected);
        rig_destroy(&r);
    }
    assert_true(widths[1] > widths[0]);
}

// With L = 0 the penumbra is empty: PCSS must be exactly the hard lookup everywhere, at
// shadow edges too. Points: lines across the shadow along x and z a tenth of a texel
// footprint apart (so some lie within a texel of every edge they cross), and a grid.
static void test_pcss_radius_zero_equals_hard(void **state)
{
    (void)state;
    rig r = rig_begin();
    add_ground(&r);
    add_square(&r, 0.3f, -0.2f, 0.6f, 1.0f);
    add_point_light(&r, drift_vec3_make(0.0f, 3.0f, 0.0f));
    rig_build(&r, 128);
    const int line = 1200, points = 2 * line + GRID * GRID;
    int shadowed = 0, changes = 0;
    float previous = -1.0f;
    for (int k = 0; k < points; ++k) {
        float s = -1.8f + 3.6f * (float)(k % line) / (float)line;
        drift_vec3 p = k < line       ? ground_point(s, 0.0f)
                       : k < 2 * line ? ground_point(0.5f, s)
                                      : ground_point(grid_coord((k - 2 * line) % GRID),
                                                     grid_coord((k - 2 * line) / GRID));
        float hard = drift_shadow_map_hard(r.map, p, up);
        for (uint32_t j = 0; j < 4; ++j) {
            assert_true(drift_shadow_map_pcss(r.map, p, up, (uint32_t)k * 4 + j) == hard);
        }
        shadowed += hard == 0.0f;
        changes += k < 2 * line && k % line > 0 && hard != previous;
        previous = hard;
    }
    assert_true(shadowed > 100);
    assert_int_equal(changes, 4); // each line crosses the shadow once
    rig_destroy(&r);
}

static void assert_all_lookups(const drift_shadow_map *map, drift_vec3 p, float expected)
{
    assert_true(drift_shadow_map_hard(map, p, up) == expected);
    for (int32_t kernel = 1; kernel <= 5; ++kernel) {
        assert_true(drift_shadow_map_pcf(map, p, up, kernel) == expected);
    }
    for (uint32_t k = 0; k < 16; ++k) {
        assert_true(drift_shadow_map_pcss(map, p, up, k) == expected);
    }
}

// Open sky is lit and deep umbra dark under every lookup (a 2x2 occluder at h = 1 under a
// light of radius 0.2 at H = 3: umbra out to |x| ~ 1.4 on the ground).
static void test_open_sky_lit_and_deep_umbra_dark(void **state)
{
    (void)state;
    rig r = rig_begin();
    add_ground(&r);
    add_square(&r, 0.0f, 0.0f, 1.0f, 1.0f);
    add_sphere_light(&r, drift_vec3_make(0.0f, 3.0f, 0.0f), 0.2f);
    rig_build(&r, 128);
    assert_all_lookups(r.map, ground_point(0.0f, 0.0f), 0.0f);
    assert_all_lookups(r.map, ground_point(0.5f, -0.4f), 0.0f);
    assert_all_lookups(r.map, ground_point(3.5f, 3.5f), 1.0f);
    assert_all_lookups(r.map, ground_point(-3.0f, 2.0f), 1.0f);
    assert_all_lookups(r.map, drift_vec3_make(0.0f, 1.5f, 0.0f), 1.0f); // above the occluder
    rig_destroy(&r);
}

// The same for a directional light shining straight down: an orthographic map, one ray a
// texel, the umbra exactly under the occluder.
static void test_directional_map(void **state)
{
    (void)state;
    rig r = rig_begin();
    add_ground(&r);
    add_square(&r, 0.0f, 0.0f, 1.0f, 1.0f);
    uint32_t index = add_light(
        &r, (drift_light){ .type = DRIFT_LIGHT_DIRECTIONAL, .direction = { 0.0f, -1.0f, 0.0f } });
    set_light(&r, DRIFT_LIGHT_DIRECTIONAL, drift_vec3_splat(0.0f), 0.0f,
              drift_vec3_make(0.0f, -1.0f, 0.0f), false, index);
    rig_build(&r, 128);
    assert_int_equal(r.rays, 128 * 128);
    assert_all_lookups(r.map, ground_point(0.0f, 0.0f), 0.0f);
    assert_all_lookups(r.map, ground_point(0.8f, -0.8f), 0.0f);
    assert_all_lookups(r.map, ground_point(1.3f, 0.0f), 1.0f);
    assert_all_lookups(r.map, ground_point(-3.5f, 3.5f), 1.0f);
    rig_destroy(&r);
}

// A downward one-sided quad light needs 5 faces (+y is behind it); its centre lies on its
// own shape, but rays start just past it and no texel ray of an even size runs in its
// plane, so each texel costs exactly one ray. A ceiling above the light shadows a point
// above it only when the +y face is built. Rays from a sphere light's centre all hit its
// inside first: two rays a texel, six faces.
static void test_faces_behind_one_sided_light_are_skipped(void **state)
{
    (void)state;
    const int32_t size = 32;
    const drift_vec3 above = { 0.0f, 3.0f, 0.0f };
    for (int sided = 0; sided < 2; ++sided) {
        bool one_sided = sided == 0;
        rig r = rig_begin();
        add_ground(&r);
        add_square(&r, 0.0f, 0.0f, 1.0f, 2.5f); // ceiling over the light
        add_down_quad_light(&r, 0.25f, LIGHT_HEIGHT, one_sided);
        rig_build(&r, size);
        uint64_t faces = one_sided ? 5 : 6;
        assert_int_equal(r.rays, faces * (uint64_t)(size * size));
        assert_true(drift_shadow_map_hard(r.map, above, up) == (one_sided ? 1.0f : 0.0f));
        assert_true(drift_shadow_map_hard(r.map, ground_point(2.0f, 1.0f), up) == 1.0f);
        rig_destroy(&r);
    }
    rig r = rig_begin();
    add_ground(&r);
    add_sphere_light(&r, drift_vec3_make(0.0f, LIGHT_HEIGHT, 0.0f), 0.25f);
    rig_build(&r, size);
    assert_int_equal(r.rays, 2 * 6 * (uint64_t)(size * size));
    assert_true(drift_shadow_map_hard(r.map, ground_point(0.5f, 0.5f), up) == 1.0f);
    rig_destroy(&r);
}

// An emissive ceiling quad (two triangles facing down) as drift_raster_lights_build makes
// it: one one-sided light over both triangles, so 5 faces, and its own triangles are no
// occluders. One PCF tap agrees with the frame's hard-shadow ray away from edges.
static void test_mesh_light_matches_hybrid_hard_shadow(void **state)
{
    (void)state;
    rig r = rig_begin();
    add_ground(&r);
    add_square(&r, 0.3f, -0.2f, 0.6f, 1.0f);
    drift_material emitter = drift_material_make(drift_vec3_splat(0.0f));
    emitter.emission = drift_vec3_splat(10.0f);
    uint32_t emissive;
    assert_int_equal(drift_scene_add_material(r.scene, &emitter, &emissive), DRIFT_OK);
    const float h = 0.3f, y = 3.0f;
    const float p[] = { -h, y, -h, h, y, -h, h, y, h, -h, y, h };
    const uint32_t idx[] = { 0, 1, 2, 0, 2, 3 }; // normal -y
    test_add_mesh(r.scene, p, 4, idx, 2, emissive);
    assert_int_equal(drift_scene_commit(r.scene), DRIFT_OK);
    drift_raster_light *lights = NULL;
    uint32_t light_count = 0;
    assert_int_equal(drift_raster_lights_build(r.ctx, r.scene, &lights, &light_count), DRIFT_OK);
    assert_int_equal(light_count, 1);
    assert_int_equal(lights[0].type, DRIFT_LIGHT_TRIANGLE);
    assert_int_equal(lights[0].light_count, 2);
    assert_true(lights[0].one_sided);
    r.light = lights[0];
    const int32_t size = 128;
    rig_build(&r, size);
    // 5 faces; a texel ray re-traced past the light's own triangles would cost one more.
    assert_true(r.rays >= 5 * (uint64_t)(size * size) && r.rays < 6 * (uint64_t)(size * size));

    bool *visible = test_malloc(sizeof(bool) * GRID * GRID);
    for (int k = 0; k < GRID * GRID; ++k) {
        drift_surface surface = {
            .position = ground_point(grid_coord(k % GRID), grid_coord(k / GRID)), .ng = up, .ns = up
        };
        float occluder, distance;
        visible[k] = drift_raster_hard_shadow(r.accel, &r.light, &surface, &occluder, &distance);
    }
    int compared = 0, mismatches = 0, shadowed = 0;
    for (int j = 2; j < GRID - 2; ++j) {
        for (int i = 2; i < GRID - 2; ++i) {
            bool v = visible[j * GRID + i], stable = true;
            for (int d = -2; d <= 2; ++d) {
                stable =
                    stable && visible[(j + d) * GRID + i] == v && visible[j * GRID + i + d] == v;
            }
            if (stable) {
                float pcf =
                    drift_shadow_map_pcf(r.map, ground_point(grid_coord(i), grid_coord(j)), up, 1);
                compared++;
                mismatches += (pcf == 1.0f) != v;
                shadowed += !v;
            }
        }
    }
    test_free(visible);
    assert_int_equal(mismatches, 0);
    assert_true(compared > GRID * GRID / 2 && shadowed > 10);
    drift_raster_lights_destroy(r.ctx, lights, light_count);
    rig_destroy(&r);
}

static void test_build_rejects_bad_arguments(void **state)
{
    (void)state;
    test_log_capture capture = { 0 };
    rig r = { .ctx = test_context(1, &capture) };
    assert_int_equal(drift_scene_create(r.ctx, &r.scene), DRIFT_OK);
    drift_material m = drift_material_make(drift_vec3_splat(0.5f));
    assert_int_equal(drift_scene_add_material(r.scene, &m, NULL), DRIFT_OK);
    add_ground(&r);
    add_point_light(&r, drift_vec3_make(0.0f, 1.0f, 0.0f));
    assert_int_equal(drift_scene_commit(r.scene), DRIFT_OK);
    assert_int_equal(drift_accel_create(r.ctx, r.scene, &(drift_accel_desc){ 0 }, &r.accel),
                     DRIFT_OK);
    drift_shadow_map *map = (drift_shadow_map *)(void *)&capture; // must be reset to NULL
    drift_shadow_map_params params = { .size = 0, .bias_texels = 1.5f };
    assert_int_equal(drift_shadow_map_build(r.ctx, r.scene, r.accel, &r.light, &params, &map, NULL),
                     DRIFT_ERR_INVALID_ARGUMENT);
    assert_null(map);
    params = (drift_shadow_map_params){ .size = 16, .bias_texels = -1.0f };
    assert_int_equal(drift_shadow_map_build(r.ctx, r.scene, r.accel, &r.light, &params, &map, NULL),
                     DRIFT_ERR_INVALID_ARGUMENT);
    assert_int_equal(capture.errors, 2);
    assert_int_equal(capture.last_code, DRIFT_ERR_INVALID_ARGUMENT);
    drift_shadow_map_destroy(r.ctx, NULL);
    rig_destroy(&r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_pcf1_matches_ray_traced_away_from_edges),
        cmocka_unit_test(test_hard_equals_pcf1),
        cmocka_unit_test(test_pcss_penumbra_widens_with_occluder_height),
        cmocka_unit_test(test_pcss_radius_zero_equals_hard),
        cmocka_unit_test(test_open_sky_lit_and_deep_umbra_dark),
        cmocka_unit_test(test_directional_map),
        cmocka_unit_test(test_faces_behind_one_sided_light_are_skipped),
        cmocka_unit_test(test_mesh_light_matches_hybrid_hard_shadow),
        cmocka_unit_test(test_build_rejects_bad_arguments),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
