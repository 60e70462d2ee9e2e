// Lighting micro-rendering's points beyond one bounce (src/micro/radiosity.c, photons.c; spec
// §4.5 test 6 and the photon map of Fig. 6.9): the radiosity iteration is energy bounded and
// monotone convergent (each increment non-negative leaf by leaf, each rho times the last in a
// closed furnace, the total the geometric series' partial sum); a photon map estimates the
// closed-form irradiance of a plane under a point light and the caustic a mirror throws; the
// photons' flux is unbiased (the emitted power, rho and rho^2 of it at the next bounces of a
// closed sphere); the increments on the Cornell box shrink by at least its largest albedo; and
// micro-rendering with 2 bounces matches the path tracer's max depth 3 on the Cornell box
// where one bounce falls short.
#include "drift/accel.h"
#include "drift/hybrid.h"
#include "drift/micro.h"
#include "drift/pt.h"
#include "drift/scene.h"
#include "drift_test.h"
#include "micro/micro_internal.h"
#include "test_rig.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void make_tree(test_rig *r, uint32_t count, drift_points **points, drift__micro_tree *tree)
{
    assert_int_equal(
        drift_points_create(r->ctx, r->scene, &(drift_points_desc){ .count = count }, points),
        DRIFT_OK);
    assert_int_equal(drift__micro_tree_create(r->ctx, *points, tree), DRIFT_OK);
}

// Every leaf of a closed sphere of albedo rho starts with radiance L on both sides (the
// outside sees nothing). Each Jacobi increment is non-negative at every leaf (the totals of
// n + 1 iterations are at least those of n, leaf by leaf), each mean increment is at most rho
// times the last (and above 0.9 rho times it), and the total never exceeds the partial
// geometric sum L (1 - rho^(n+1)) / (1 - rho) (within 3% of it), below L / (1 - rho).
static void test_radiosity_energy_bound_and_monotone(void **state)
{
    (void)state;
    const float rho = 0.6f, L = 2.0f;
    test_rig r = test_rig_begin(2);
    uint32_t mat = test_add_material(r.scene, drift_material_make(drift_vec3_splat(rho)));
    test_add_sphere(r.scene, drift_vec3_splat(0.0f), 1.0f, 64, 32, mat);
    test_rig_commit(&r);
    drift_points *points;
    drift__micro_tree tree;
    make_tree(&r, 2048, &points, &tree);
    uint32_t n = tree.leaf_count;

    enum {
        ITER = 4
    };

    double inc[ITER + 1];
    float *prev = calloc(2 * (size_t)n, sizeof *prev);
    for (int iterations = 0; iterations <= ITER; ++iterations) {
        for (uint32_t j = 0; j < n; ++j) {
            tree.albedo[n - 1 + j] = drift_vec3_splat(rho);
            tree.front[n - 1 + j] = tree.back[n - 1 + j] = drift_vec3_splat(L);
        }
        drift__micro_radiosity_desc desc = {
            .accel = r.accel, .iterations = iterations, .buffer_size = 8, .element_leaves = 16
        };
        assert_int_equal(drift__micro_radiosity(r.ctx, &tree, points, &desc, inc, NULL), DRIFT_OK);
        // Leaf by leaf, one more iteration only adds.
        double inside = 0.0;
        for (uint32_t j = 0; j < n; ++j) {
            float f = tree.front[n - 1 + j].y, b = tree.back[n - 1 + j].y;
            assert_true(f >= prev[2 * j] - 1e-6f && b >= prev[2 * j + 1] - 1e-6f);
            prev[2 * j] = f;
            prev[2 * j + 1] = b;
            inside += (double)fmaxf(f, b);
        }
        inside /= (double)n;
        double partial = (double)L * (1.0 - pow((double)rho, iterations + 1)) / (1.0 - (double)rho);
        printf("%d iterations: inside mean %.4f, partial sum %.4f, bound %.4f\n", iterations,
               inside, partial, (double)L / (1.0 - (double)rho));
        // Never above the series (no energy made), at most 3% below it after 4 bounces (the
        // near nodes of a curved wall are partly seen with their dark outsides: docs/micro.md).
        assert_true(inside <= partial * 1.001 && inside >= 0.97 * partial);
        assert_true(inside < (double)L / (1.0 - (double)rho));
    }
    // The increments (both sides; the outside's stay 0) shrink by rho each.
    for (int k = 2; k <= ITER; ++k) {
        printf("increment %d: %.4f (ratio %.4f)\n", k, inc[k], inc[k] / inc[k - 1]);
        assert_true(inc[k] >= 0.0);
        assert_true(inc[k] <= 1.001 * (double)rho * inc[k - 1]);
        assert_true(inc[k] >= 0.9 * (double)rho * inc[k - 1]);
    }
    free(prev);
    drift__micro_tree_destroy(r.ctx, &tree);
    drift_points_destroy(points);
    test_rig_destroy(&r);
}

// A large floor under a point light of intensity I at height h: the photons' first hits
// estimate E(x) = I h / d^3 (d the distance to the light) within 6% with 400 neighbours, at
// the foot and two offsets. The emitted flux is 4 pi I.
static void test_photon_irradiance_under_point_light(void **state)
{
    (void)state;
    const float I = 3.0f, h = 1.0f;
    test_rig r = test_rig_begin(2);
    uint32_t mat = test_add_material(r.scene, drift_material_make(drift_vec3_splat(0.5f)));
    test_add_floor(r.scene, 50.0f, 0.0f, mat);
    drift_light light = { .type = DRIFT_LIGHT_POINT,
                          .color = drift_vec3_splat(I),
                          .position = drift_vec3_make(0.0f, h, 0.0f) };
    assert_int_equal(drift_scene_add_light(r.scene, &light, NULL), DRIFT_OK);
    test_rig_commit(&r);
    drift__micro_photon_map map;
    uint32_t paths = (uint32_t)(262144.0 * fmin(1.0, test_intensity()));
    drift__micro_photon_desc desc = { .paths = paths, .min_scatter = 0, .max_scatter = 0 };
    assert_int_equal(drift__micro_photons_trace(r.ctx, r.scene, r.accel, &desc, &map), DRIFT_OK);
    printf("%u photons stored of %u paths; emitted %.4f (4 pi I = %.4f)\n", map.count, paths,
           (double)map.emitted.y, 4.0 * (double)DRIFT_PI * (double)I);
    assert_true(fabs((double)map.emitted.y / (4.0 * (double)DRIFT_PI * (double)I) - 1.0) < 1e-3);
    // Half the photons go down (the floor holds them all but a sliver past 50 m).
    assert_true(fabs((double)map.count / (double)paths - 0.5) < 0.01);
    const float xs[3] = { 0.0f, 0.7f, 1.5f };
    for (int i = 0; i < 3; ++i) {
        drift_vec3 x = drift_vec3_make(xs[i], 0.0f, 0.3f * xs[i]);
        float d = sqrtf(h * h + x.x * x.x + x.z * x.z);
        double truth = (double)(I * h / (d * d * d));
        drift_vec3 e =
            drift__micro_photons_irradiance(&map, x, drift_vec3_make(0, 1, 0), 256, INFINITY);
        drift_vec3 below =
            drift__micro_photons_irradiance(&map, x, drift_vec3_make(0, -1, 0), 256, INFINITY);
        printf("x = %.1f: E %.4f, closed form %.4f; the floor's underside %.4f\n", (double)xs[i],
               (double)e.y, truth, (double)below.y);
        assert_true(fabs((double)e.y / truth - 1.0) < 0.06);
        assert_true(below.y == 0.0f);
    }
    drift__micro_photons_destroy(r.ctx, &map);
    test_rig_destroy(&r);
}

// Caustics: a mirror of reflectance ks at height 2 over the floor, the light at 1 between
// them. Photons that scattered once and landed on the floor all came off the mirror (the
// floor cannot light itself), so they see the light's image at height 3: E = ks I / 9 at the
// foot, ks I 3 / d^3 beside it (6%).
static void test_photon_caustic_of_a_mirror(void **state)
{
    (void)state;
    const float I = 3.0f, ks = 0.8f;
    test_rig r = test_rig_begin(2);
    uint32_t floor_mat = test_add_material(r.scene, drift_material_make(drift_vec3_splat(0.5f)));
    drift_material mirror = drift_material_make(drift_vec3_splat(0.0f));
    mirror.type = DRIFT_MATERIAL_MIRROR;
    mirror.specular = drift_vec3_splat(ks);
    uint32_t mirror_mat = test_add_material(r.scene, mirror);
    test_add_floor(r.scene, 50.0f, 0.0f, floor_mat);
    test_add_quad(r.scene, drift_vec3_make(-50.0f, 2.0f, -50.0f), drift_vec3_make(100.0f, 0, 0),
                  drift_vec3_make(0, 0, 100.0f), mirror_mat);
    drift_light light = { .type = DRIFT_LIGHT_POINT,
                          .color = drift_vec3_splat(I),
                          .position = drift_vec3_make(0.0f, 1.0f, 0.0f) };
    assert_int_equal(drift_scene_add_light(r.scene, &light, NULL), DRIFT_OK);
    test_rig_commit(&r);
    drift__micro_photon_map map;
    uint32_t paths = (uint32_t)(262144.0 * fmin(1.0, test_intensity()));
    drift__micro_photon_desc desc = { .paths = paths, .min_scatter = 1, .max_scatter = 1 };
    assert_int_equal(drift__micro_photons_trace(r.ctx, r.scene, r.accel, &desc, &map), DRIFT_OK);
    printf("%u caustic photons of %u paths\n", map.count, paths);
    const float xs[2] = { 0.0f, 1.0f };
    for (int i = 0; i < 2; ++i) {
        drift_vec3 x = drift_vec3_make(xs[i], 0.0f, 0.0f);
        float d = sqrtf(9.0f + x.x * x.x);
        double truth = (double)(ks * I * 3.0f / (d * d * d));
        drift_vec3 e =
            drift__micro_photons_irradiance(&map, x, drift_vec3_make(0, 1, 0), 256, INFINITY);
        printf("x = %.1f: caustic E %.4f, closed form %.4f\n", (double)xs[i], (double)e.y, truth);
        assert_true(fabs((double)e.y / truth - 1.0) < 0.06);
    }
    drift__micro_photons_destroy(r.ctx, &map);
    test_rig_destroy(&r);
}

// Unbiased flux: inside a closed sphere of albedo rho around a point light, the photons that
// land after 0, 1 and 2 scatterings carry 4 pi I, rho 4 pi I and rho^2 4 pi I (1.5%).
static void test_photon_flux_is_unbiased(void **state)
{
    (void)state;
    const float I = 1.0f, rho = 0.7f;
    test_rig r = test_rig_begin(2);
    uint32_t mat = test_add_material(r.scene, drift_material_make(drift_vec3_splat(rho)));
    test_add_sphere(r.scene, drift_vec3_splat(0.0f), 1.0f, 64, 32, mat);
    drift_light light = { .type = DRIFT_LIGHT_POINT,
                          .color = drift_vec3_splat(I),
                          .position = drift_vec3_make(0.1f, 0.2f, 0.0f) };
    assert_int_equal(drift_scene_add_light(r.scene, &light, NULL), DRIFT_OK);
    test_rig_commit(&r);
    uint32_t paths = (uint32_t)(131072.0 * fmin(1.0, test_intensity()));
    double phi = 4.0 * (double)DRIFT_PI * (double)I;
    for (int32_t v = 0; v <= 2; ++v) {
        drift__micro_photon_map map;
        drift__micro_photon_desc desc = { .paths = paths, .min_scatter = v, .max_scatter = v };
        assert_int_equal(drift__micro_photons_trace(r.ctx, r.scene, r.accel, &desc, &map),
                         DRIFT_OK);
        double sum = 0.0;
        for (uint32_t i = 0; i < map.count; ++i) {
            sum += (double)map.photons[i].power.y;
        }
        double truth = phi * pow((double)rho, v);
        printf("after %d scatterings: %u photons, flux %.4f (closed form %.4f)\n", v, map.count,
               sum, truth);
        assert_true(fabs(sum / truth - 1.0) < 0.015);
        drift__micro_photons_destroy(r.ctx, &map);
    }
    test_rig_destroy(&r);
}

// The Cornell box at 16 x 16: with 2 bounces (radiosity and photons) I matches the path
// tracer's diffuse light at max depth 3 (NRMS, mean within 8%), where one bounce is short of it
// by more than 10%; and the radiosity leaves' light with 2 bounces exceeds that with 1.
static void test_two_bounces_against_path_tracer(void **state)
{
    (void)state;
    test_rig r = test_rig_load(2, "scenes/cornell-box/cornell_box.json", 16);
    drift_pt *pt = NULL;
    drift_image ref = test_rig_render_pt(&r, DRIFT_PT_COMPONENT_DIFFUSE, 3, 1024, 99, &pt);
    double ref_mean = drift_image_mean_luminance(&ref);
    const drift_micro_lighting modes[3] = { DRIFT_MICRO_LIGHTING_DIRECT,
                                            DRIFT_MICRO_LIGHTING_RADIOSITY,
                                            DRIFT_MICRO_LIGHTING_PHOTONS };
    double ratio[3], e[3];
    for (int i = 0; i < 3; ++i) {
        drift_micro_params mp = { .point_count = 8192,
                                  .buffer_size = 16,
                                  .lighting = modes[i],
                                  .bounces = i == 0 ? 1 : 2,
                                  .photon_count = 1u << 15 };
        drift_micro *m = NULL;
        assert_int_equal(drift_micro_create(r.ctx, r.scene, r.accel, &mp, &m), DRIFT_OK);
        assert_int_equal(drift_micro_render(m, drift_hybrid_gbuffer(r.frame), &r.scene->camera,
                                            DRIFT_MICRO_LOBE_DIFFUSE),
                         DRIFT_OK);
        drift_micro_stats st = drift_micro_get_stats(m);
        ratio[i] = drift_image_mean_luminance(drift_micro_result(m)) / ref_mean;
        e[i] = test_nrmse(r.ctx, &ref, drift_micro_result(m));
        printf("%s, %d bounce(s): NRMS %.4f, mean ratio %.4f; direct %.1f ms, bounces %.1f ms, "
               "%llu photons, total %.1f ms\n",
               drift_micro_lighting_name(modes[i]), mp.bounces, e[i], ratio[i], st.direct_ms,
               st.bounces_ms, (unsigned long long)st.photons, st.total_ms);
        drift_micro_destroy(m);
    }
    assert_true(ratio[0] < 0.9);
    for (int i = 1; i < 3; ++i) {
        assert_true(fabs(ratio[i] - 1.0) < 0.08);
        assert_true(e[i] < e[0]);
    }
    drift_pt_destroy(pt);
    test_rig_destroy(&r);
}

// On the Cornell box, lit by its light: each radiosity increment is positive and at most the
// largest albedo times the last (equal-area leaves: what an enclosure gathers is at most what
// it holds), so the series converges.
static void test_radiosity_increments_shrink_on_cornell_box(void **state)
{
    (void)state;
    test_rig r = test_rig_load(2, "scenes/cornell-box/cornell_box.json", 8);
    drift_points *points;
    drift__micro_tree tree;
    make_tree(&r, 4096, &points, &tree);
    drift__micro_light_leaves(r.ctx, r.scene, r.accel, points, &tree, 4, 0);
    uint32_t n = tree.leaf_count;
    float kd_max = 0.0f;
    for (uint32_t j = 0; j < n; ++j) {
        drift_vec3 kd = tree.albedo[n - 1 + j];
        kd_max = fmaxf(kd_max, fmaxf(kd.x, fmaxf(kd.y, kd.z)));
    }

    enum {
        ITER = 3
    };

    double inc[ITER + 1];
    drift__micro_radiosity_desc desc = {
        .accel = r.accel, .iterations = ITER, .buffer_size = 8, .element_leaves = 32
    };
    assert_int_equal(drift__micro_radiosity(r.ctx, &tree, points, &desc, inc, NULL), DRIFT_OK);
    for (int k = 1; k <= ITER; ++k) {
        printf("increment %d: %.5f (ratio %.4f; largest albedo %.3f)\n", k, inc[k],
               inc[k] / inc[k - 1], (double)kd_max);
        assert_true(inc[k] > 0.0);
        assert_true(inc[k] <= 1.02 * (double)kd_max * inc[k - 1]);
    }
    drift__micro_tree_destroy(r.ctx, &tree);
    drift_points_destroy(points);
    test_rig_destroy(&r);
}

// Bad lighting parameters are refused: direct light with 2 bounces, 0 or 9 bounces.
static void test_bad_lighting_parameters(void **state)
{
    (void)state;
    test_rig r = test_rig_load(1, "scenes/cornell-box/cornell_box.json", 8);
    drift_micro *m = NULL;
    const drift_micro_params bad[2] = {
        { .lighting = DRIFT_MICRO_LIGHTING_DIRECT, .bounces = 2 },
        { .bounces = DRIFT_MICRO_MAX_BOUNCES + 1 },
    };
    for (int i = 0; i < 2; ++i) {
        assert_int_equal(drift_micro_create(r.ctx, r.scene, r.accel, &bad[i], &m),
                         DRIFT_ERR_INVALID_ARGUMENT);
        assert_null(m);
    }
    drift_micro_params p = drift_micro_params_resolve(&(drift_micro_params){ .bounces = 3 });
    assert_int_equal(p.lighting, DRIFT_MICRO_LIGHTING_RADIOSITY);
    test_rig_destroy(&r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_radiosity_energy_bound_and_monotone),
        cmocka_unit_test(test_radiosity_increments_shrink_on_cornell_box),
        cmocka_unit_test(test_photon_irradiance_under_point_light),
        cmocka_unit_test(test_photon_caustic_of_a_mirror),
        cmocka_unit_test(test_photon_flux_is_unbiased),
        cmocka_unit_test(test_two_bounces_against_path_tracer),
        cmocka_unit_test(test_bad_lighting_parameters),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
