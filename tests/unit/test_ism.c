// Instant radiosity and imperfect shadow maps (src/ism): the objective tests of the thesis
// spec §3.5 that a CPU build can run in seconds. The paraboloid mapping round-trips and
// covers pi/4 n^2 texels; the VPLs' flux is the emitted power times the albedo, bounce by
// bounce; an ISM of one occluder plane matches the ray-traced map and improves with points;
// pull-push fills the holes of a closed scene and keeps valid texels; the gather equals the
// formula; `ir` converges to the path tracer's first-bounce diffuse light up to the clamping
// bias; ISM approaches `ir` as points grow; results are deterministic across thread counts;
// moving scene, light and camera rigidly leaves the image unchanged.
// ctest-labels: quality
#include "drift/accel.h"
#include "drift/hybrid.h"
#include "drift/ism.h"
#include "drift/metric.h"
#include "drift/pt.h"
#include "drift/scene.h"
#include "drift/scene_io.h"
#include "drift_test.h"
#include "ism/ism_internal.h"
#include "ism/ism_tests.h"
#include "test_rig.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

// --- HELPERS ---

// The Cornell box at w x w, committed with its accel, and a G-buffer frame.
test_rig cornell_rig(int threads, int32_t w)
{
    return test_rig_load(threads, "scenes/cornell-box/cornell_box.json", w);
}

// The path tracer's truth of a term (seed 99).
static drift_image render_pt(test_rig *r, uint32_t components, int32_t max_depth, uint32_t spp,
                             drift_pt **pt)
{
    return test_rig_render_pt(r, components, max_depth, spp, 99, pt);
}

// Renders the rig's G-buffer with `params`, the VPL gather alone (no_near_field: the
// compensation needs a direct image); the ism is returned for its planes.
drift_ism *render_ism(test_rig *r, const drift_ism_params *params)
{
    drift_ism_params gather_alone = *params;
    gather_alone.no_near_field = true;
    drift_ism *ism = NULL;
    assert_int_equal(drift_ism_create(r->ctx, r->scene, r->accel, &gather_alone, &ism), DRIFT_OK);
    assert_int_equal(drift_ism_render(ism, drift_hybrid_gbuffer(r->frame), &r->scene->camera, NULL),
                     DRIFT_OK);
    return ism;
}

// --- TESTS ---

// A grid over the hemisphere maps to the disc and back within 1e-5, and the texels whose
// centre lies in the disc number pi/4 n^2 within 1%.
static void test_paraboloid_round_trip(void **state)
{
    (void)state;
    double worst = 0.0;
    for (int i = 0; i <= 64; ++i) {
        for (int j = 0; j < 128; ++j) {
            float theta = 0.5f * DRIFT_PI * (float)i / 64.0f,
                  phi = 2.0f * DRIFT_PI * (float)j / 128.0f;
            drift_vec3 v = { sinf(theta) * cosf(phi), sinf(theta) * sinf(phi), cosf(theta) };
            drift_vec2 p = drift_paraboloid_project(v);
            assert_true(p.x * p.x + p.y * p.y <= 1.0f + 1e-5f);
            drift_vec3 back = drift_paraboloid_unproject(p);
            worst = fmax(worst, (double)drift_vec3_length(drift_vec3_sub(back, v)));
        }
    }
    assert_true(worst < 1e-5);
    int32_t n = 128, inside = 0;
    for (int32_t y = 0; y < n; ++y) {
        for (int32_t x = 0; x < n; ++x) {
            float u = 2.0f * ((float)x + 0.5f) / (float)n - 1.0f;
            float v = 2.0f * ((float)y + 0.5f) / (float)n - 1.0f;
            inside += u * u + v * v <= 1.0f;
        }
    }
    double expected = (double)DRIFT_PI / 4.0 * (double)n * (double)n;
    assert_true(fabs((double)inside - expected) < 0.01 * expected);
}

// The box [-1, 1]^3 with inward faces of albedo `albedo`.
void add_closed_box(drift_scene *scene, float albedo)
{
    uint32_t m = test_add_material(scene, drift_material_make(drift_vec3_splat(albedo)));
    drift_vec3 ex = { 2, 0, 0 }, ey = { 0, 2, 0 }, ez = { 0, 0, 2 };
    // Windings chosen so cross(u, v) points into the box.
    test_add_quad(scene, drift_vec3_make(-1, -1, -1), ez, ex, m); // floor
    test_add_quad(scene, drift_vec3_make(-1, 1, -1), ex, ez, m);  // ceiling
    test_add_quad(scene, drift_vec3_make(-1, -1, -1), ex, ey, m); // back z=-1
    test_add_quad(scene, drift_vec3_make(-1, -1, 1), ey, ex, m);  // front
    test_add_quad(scene, drift_vec3_make(-1, -1, -1), ey, ez, m); // x=-1
    test_add_quad(scene, drift_vec3_make(1, -1, -1), ez, ey, m);  // x=+1
}

// Sums the VPL flux (luminance) per bounce, with the standard error of bounce 1.
static void flux_by_bounce(const drift_vpl *vpls, uint32_t count, uint32_t paths, double *sum,
                           double *sigma1)
{
    double sq = 0.0;
    for (uint32_t b = 0; b < 4; ++b) {
        sum[b] = 0.0;
    }
    for (uint32_t i = 0; i < count; ++i) {
        double f = (double)drift_luminance(vpls[i].flux);
        if (vpls[i].bounce <= 4) {
            sum[vpls[i].bounce - 1] += f;
        }
        if (vpls[i].bounce == 1) {
            sq += f * f;
        }
    }
    // Paths are independent: var(sum) ~ sum f_i^2 - (sum f_i)^2 / N.
    *sigma1 = sqrt(fmax(sq - sum[0] * sum[0] / (double)paths, 0.0));
}

// The VPLs of `p` in the rig's scene, their flux summed per bounce (flux_by_bounce).
static drift_vpl *vpls_by_bounce(test_rig *r, const drift_ism_params *p, uint32_t *count,
                                 double *sum, double *sigma1)
{
    drift_vpl *vpls = NULL;
    assert_int_equal(drift__ism_generate_vpls(r->ctx, r->scene, r->accel, p, &vpls, count, NULL),
                     DRIFT_OK);
    flux_by_bounce(vpls, *count, p->vpl_count, sum, sigma1);
    return vpls;
}

// In a closed box of albedo a, the first bounce's VPL flux sums to the emitted power times a
// (within 3 sigma), and every later bounce to a times the one before: for a quad light, a
// point light (RSM cube) and a spot (one RSM face).
static void test_vpl_flux_is_power_times_albedo(void **state)
{
    (void)state;
    const float a = 0.5f;
    for (int kind = 0; kind < 3; ++kind) {
        test_rig r = test_rig_begin(2);
        add_closed_box(r.scene, a);
        double power;
        if (kind == 0) {
            // A 0.5 x 0.5 quad light just under the ceiling, facing down: pi A L.
            test_add_quad_light(r.scene, drift_vec3_make(-0.25f, 0.9f, -0.25f),
                                drift_vec3_make(0.5f, 0, 0), drift_vec3_make(0, 0, 0.5f), 4.0f);
            power = (double)DRIFT_PI * 0.25 * 4.0;
        } else if (kind == 2) {
            // A hard-edged spot (inner = outer): one RSM face, power 2 pi (1 - cos) I.
            drift_light l = { .type = DRIFT_LIGHT_SPOT,
                              .color = drift_vec3_splat(3.0f),
                              .position = drift_vec3_make(0.1f, 0.8f, 0.0f),
                              .direction = drift_vec3_normalize(drift_vec3_make(0.2f, -1, 0.1f)),
                              .spot_inner = 0.6f,
                              .spot_outer = 0.6f };
            assert_int_equal(drift_scene_add_light(r.scene, &l, NULL), DRIFT_OK);
            power = 2.0 * (double)DRIFT_PI * (1.0 - cos(0.6)) * 3.0;
        } else {
            drift_light l = { .type = DRIFT_LIGHT_POINT,
                              .color = drift_vec3_splat(2.0f),
                              .position = drift_vec3_make(0.2f, 0.3f, -0.1f) };
            assert_int_equal(drift_scene_add_light(r.scene, &l, NULL), DRIFT_OK);
            power = 4.0 * (double)DRIFT_PI * 2.0;
        }
        test_rig_commit(&r);
        drift_ism_params p = drift_ism_params_resolve(
            &(drift_ism_params){ .vpl_count = 4096, .max_depth = 4, .later_vpl_count = 4096 },
            r.scene);
        drift_vpl *vpls = NULL;
        uint32_t count = 0;
        drift_vec3 emitted;
        assert_int_equal(
            drift__ism_generate_vpls(r.ctx, r.scene, r.accel, &p, &vpls, &count, &emitted),
            DRIFT_OK);
        double sum[4], sigma;
        flux_by_bounce(vpls, count, p.vpl_count, sum, &sigma);
        double expected = power * (double)a;
        assert_true(fabs(sum[0] - expected) <= 3.0 * sigma + 1e-3 * expected);
        for (int b = 1; b < 3; ++b) {
            assert_true(sum[b] < sum[b - 1]);
            assert_near(sum[b] / sum[b - 1], a, 0.05);
        }
        drift_free(r.ctx, vpls);
        test_rig_destroy(&r);
    }
}

// Light paths go on through glossy and mirror lobes (drift_bsdf_sample_wi), not only diffuse
// ones: a quad light faces a mirror floor (ks 0.8) under a diffuse ceiling (albedo 0.5), both
// so large that almost no path escapes. The mirror leaves no VPL; the ceiling's VPLs, the
// paths' second vertex, carry the emitted power times 0.8 x 0.5 (a path that stopped at the
// mirror, as a diffuse-only path did, carried none).
static void test_paths_go_on_through_mirrors(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    drift_material m = drift_material_make(drift_vec3_splat(0.0f));
    m.type = DRIFT_MATERIAL_MIRROR;
    m.specular = drift_vec3_splat(0.8f);
    uint32_t mirror = test_add_material(r.scene, m);
    uint32_t white = test_add_material(r.scene, drift_material_make(drift_vec3_splat(0.5f)));
    test_add_floor(r.scene, 100.0f, -1.0f, mirror);
    // The ceiling at y = 1, facing down.
    test_add_quad(r.scene, drift_vec3_make(-100, 1, -100), drift_vec3_make(200, 0, 0),
                  drift_vec3_make(0, 0, 200), white);
    test_add_quad_light(r.scene, drift_vec3_make(-0.25f, 0.9f, -0.25f), drift_vec3_make(0.5f, 0, 0),
                        drift_vec3_make(0, 0, 0.5f), 4.0f);
    test_rig_commit(&r);
    double power = (double)DRIFT_PI * 0.25 * 4.0;
    drift_ism_params p = drift_ism_params_resolve(
        &(drift_ism_params){ .vpl_count = 4096, .max_depth = 3, .later_vpl_count = 4096 }, r.scene);
    uint32_t count = 0;
    double sum[4], sigma;
    drift_vpl *vpls = vpls_by_bounce(&r, &p, &count, sum, &sigma);
    assert_true(sum[0] == 0.0);
    // Within 2%: the light's own quad stops a few tenths of a percent of the reflected paths
    // (those within ~4 degrees of the vertical), the planes' finite size lets fewer escape.
    printf("mirror floor: ceiling VPLs carry %.4f of 0.8 x 0.5 of the power\n",
           sum[1] / (power * 0.4));
    assert_near(sum[1] / (power * 0.4), 1.0, 0.02);
    drift_free(r.ctx, vpls);
    test_rig_destroy(&r);
}

// A VPL at the origin facing +z, a 1 x 1 occluder at z = 1 inside a sphere of radius 3 (so
// every direction of the map sees a surface at a steady depth).
static void build_occluder_scene(test_rig *r)
{
    uint32_t m = test_add_material(r->scene, drift_material_make(drift_vec3_splat(0.5f)));
    test_add_quad(r->scene, drift_vec3_make(-0.5f, -0.5f, 1), drift_vec3_make(0, 1, 0),
                  drift_vec3_make(1, 0, 0), m);
    test_add_sphere(r->scene, drift_vec3_splat(0.0f), 3.0f, 96, 48, m);
    test_rig_commit(r);
}

// Fraction of the disc's texels whose ISM depth (after pull-push when `levels` > 0) is within
// 1% of the scene extent of the ray-traced paraboloid map (or both empty).
static double ism_agreement(test_rig *r, uint32_t points_count, int32_t n, int32_t levels,
                            double *out_holes)
{
    drift_points *points = NULL;
    assert_int_equal(drift_points_create(r->ctx, r->scene,
                                         &(drift_points_desc){ .count = points_count, .seed = 3 },
                                         &points),
                     DRIFT_OK);
    float *depth = malloc((size_t)n * (size_t)n * sizeof *depth);
    float *scratch = malloc((size_t)n * (size_t)n * sizeof *scratch);
    drift_frame frame = drift_frame_from_normal(drift_vec3_make(0, 0, 1));
    drift_vec3 origin = drift_vec3_splat(0.0f);
    drift__ism_splat_desc desc = { .n = n,
                                   .point_radius =
                                       sqrtf((float)points->area / (float)points_count / DRIFT_PI),
                                   .splat_scale = 1.5f };
    drift__ism_splat(depth, &desc, origin, &frame, points->position, points->count);
    float extent = drift_vec3_length(drift_vec3_sub(r->scene->bounds.max, r->scene->bounds.min));
    uint32_t holes = drift__ism_pull_push(depth, n, levels, 0.05f * extent, scratch);
    int32_t inside = 0, agree = 0;
    for (int32_t y = 0; y < n; ++y) {
        for (int32_t x = 0; x < n; ++x) {
            drift_vec2 p = { 2.0f * ((float)x + 0.5f) / (float)n - 1.0f,
                             2.0f * ((float)y + 0.5f) / (float)n - 1.0f };
            if (p.x * p.x + p.y * p.y > 1.0f) {
                continue;
            }
            inside++;
            drift_vec3 dir = drift_frame_to_world(&frame, drift_paraboloid_unproject(p));
            drift_ray ray = { origin, 0.0f, dir, INFINITY, 0 };
            drift_hit hit;
            float exact = drift_accel_intersect(r->accel, &ray, &hit) ? hit.t : INFINITY;
            float got = depth[y * n + x];
            if (isinf(exact) ? isinf(got) : fabsf(got - exact) <= 0.01f * extent) {
                agree++;
            }
        }
    }
    free(depth);
    free(scratch);
    drift_points_destroy(points);
    if (out_holes) {
        *out_holes = (double)holes / (double)inside;
    }
    return (double)agree / (double)inside;
}

// Spec §3.5 test 2: with dense points and pull-push at least 95% of the texels match the exact
// map, and the agreement grows with the points.
static void test_ism_of_an_occluder_matches_rays(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    build_occluder_scene(&r);
    double a1 = ism_agreement(&r, 2000, 64, 2, NULL);
    double a2 = ism_agreement(&r, 20000, 64, 2, NULL);
    double a3 = ism_agreement(&r, 200000, 64, 2, NULL);
    printf("agreement %.4f %.4f %.4f\n", a1, a2, a3);
    assert_true(a3 >= 0.95);
    assert_true(a1 < a2 && a2 <= a3);
    test_rig_destroy(&r);
}

// Spec §3.5 test 3: in a closed box, sparse points leave holes that two pull-push levels fill
// to below 1%; texels that were valid and near their parents keep their depth.
static void test_pull_push_fills_holes(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    add_closed_box(r.scene, 0.5f);
    test_rig_commit(&r);
    drift_points *points = NULL;
    assert_int_equal(drift_points_create(r.ctx, r.scene,
                                         &(drift_points_desc){ .count = 6000, .seed = 5 }, &points),
                     DRIFT_OK);
    int32_t n = 64;
    float *depth = malloc((size_t)n * (size_t)n * sizeof *depth);
    float *before = malloc((size_t)n * (size_t)n * sizeof *before);
    float *scratch = malloc((size_t)n * (size_t)n * sizeof *scratch);
    // A VPL on the floor's centre, facing up.
    drift_frame frame = drift_frame_from_normal(drift_vec3_make(0, 1, 0));
    drift__ism_splat_desc desc = { .n = n, .point_radius = 0.0f, .splat_scale = 1.0f };
    drift__ism_splat(depth, &desc, drift_vec3_make(0, -0.999f, 0), &frame, points->position,
                     points->count);
    memcpy(before, depth, (size_t)n * (size_t)n * sizeof *depth);
    uint32_t holes0 = drift__ism_pull_push(before, n, 0, 1.0f, scratch);
    uint32_t holes2 = drift__ism_pull_push(depth, n, 2, 0.05f * 3.4641f, scratch);
    double disc = (double)DRIFT_PI / 4.0 * (double)n * (double)n;
    printf("holes before %.3f after %.4f\n", holes0 / disc, holes2 / disc);
    assert_true((double)holes0 / disc > 0.2);
    assert_true((double)holes2 / disc < 0.01);
    int32_t valid = 0, kept = 0;
    for (int32_t i = 0; i < n * n; ++i) {
        if (isfinite(before[i])) {
            valid++;
            kept += depth[i] == before[i];
        }
    }
    // Texels on the box's smooth walls are near their parents: nearly all keep their depth.
    assert_true((double)kept / (double)valid > 0.9);
    free(depth);
    free(before);
    free(scratch);
    drift_points_destroy(points);
    test_rig_destroy(&r);
}

// The lazy pull-push (pull at build time, the push replayed by each lookup along the texel's
// ancestors) gives every texel the eager pull-push's depth, to the bit, and the same holes:
// on random maps of near and far depths with holes (every push case: empty children, far
// children behind a near majority, empty parents), odd and even sizes, one and two levels.
static void test_lazy_push_equals_eager(void **state)
{
    (void)state;
    const int32_t sizes[] = { 64, 37 };
    uint32_t rng = 12345u;
    for (int s = 0; s < 2; ++s) {
        int32_t n = sizes[s];
        size_t texels = (size_t)n * (size_t)n;
        for (int32_t levels = 1; levels <= 2; ++levels) {
            for (int trial = 0; trial < 4; ++trial) {
                float *eager = malloc(texels * sizeof *eager);
                float *lazy = malloc(drift__ism_map_floats(n, levels) * sizeof *lazy);
                float *scratch = malloc(2 * texels * sizeof *scratch);
                // Holes from 20% to 80%; depths in a near (1.0-1.1) and a far (3.0-3.1)
                // cluster, the far one a third of the valid texels.
                for (size_t i = 0; i < texels; ++i) {
                    rng = rng * 1664525u + 1013904223u;
                    float u = (float)(rng >> 8) / 16777216.0f;
                    rng = rng * 1664525u + 1013904223u;
                    float w = (float)(rng >> 8) / 16777216.0f;
                    bool hole = u < 0.2f + 0.2f * (float)trial;
                    eager[i] = hole ? INFINITY : (w < 0.33f ? 3.0f : 1.0f) + 0.1f * w;
                    lazy[i] = eager[i];
                }
                float threshold = 0.3f;
                uint32_t holes = drift__ism_pull_push(eager, n, levels, threshold, scratch);
                drift__ism_pull(lazy, n, levels, threshold);
                float *counts = malloc(texels * sizeof *counts);
                drift__ism_disc_counts(n, levels, counts);
                assert_int_equal(drift__ism_holes(lazy, n, levels, counts), holes);
                free(counts);
                int32_t differ = 0;
                for (int32_t y = 0; y < n; ++y) {
                    for (int32_t x = 0; x < n; ++x) {
                        float got = drift__ism_lookup(lazy, n, levels, threshold, x, y);
                        differ += memcmp(&got, &eager[(size_t)y * (size_t)n + (size_t)x],
                                         sizeof got) != 0;
                    }
                }
                assert_int_equal(differ, 0);
                free(eager);
                free(lazy);
                free(scratch);
            }
        }
    }
}

// The Cornell box at 32 x 32: `ir` with many VPLs, every pixel gathering every VPL, is close
// to the path tracer's first-bounce diffuse light (max depth 2) up to the clamping bias, and
// the visibility-free limit is brighter; ISM's error against `ir` falls as points grow and as
// the maps grow.
static void test_ir_and_ism_against_path_tracer(void **state)
{
    (void)state;
    test_rig r = cornell_rig(2, 32);
    drift_pt *pt = NULL;
    drift_image ref = render_pt(&r, DRIFT_PT_COMPONENT_DIFFUSE, 2, 512, &pt);
    drift_ism *ir = render_ism(&r, &(drift_ism_params){ .visibility = DRIFT_ISM_VISIBILITY_RAYS,
                                                        .vpl_count = 2048,
                                                        .block_size = 1 });
    double e_ir = test_nrmse(r.ctx, &ref, drift_ism_indirect(ir));
    double bias_ir =
        drift_image_mean_luminance(drift_ism_indirect(ir)) / drift_image_mean_luminance(&ref);
    drift_ism *none = render_ism(&r, &(drift_ism_params){ .visibility = DRIFT_ISM_VISIBILITY_NONE,
                                                          .vpl_count = 2048,
                                                          .block_size = 1 });
    double bias_none =
        drift_image_mean_luminance(drift_ism_indirect(none)) / drift_image_mean_luminance(&ref);
    // ISM against `ir` with the same 256 VPLs as the points per VPL grow.
    drift_ism *ir256 = render_ism(&r, &(drift_ism_params){ .visibility = DRIFT_ISM_VISIBILITY_RAYS,
                                                           .vpl_count = 256,
                                                           .block_size = 1 });
    double e_ism[3];
    uint32_t pts[3] = { 64, 512, 4096 };
    for (int i = 0; i < 3; ++i) {
        drift_ism *ism = render_ism(
            &r, &(drift_ism_params){ .vpl_count = 256, .block_size = 1, .points_per_vpl = pts[i] });
        e_ism[i] = test_nrmse(r.ctx, drift_ism_indirect(ir256), drift_ism_indirect(ism));
        drift_ism_destroy(ism);
    }
    // And as the maps grow, at 4096 points a VPL.
    double e_res[2];
    int32_t sizes[2] = { 16, 64 };
    for (int i = 0; i < 2; ++i) {
        drift_ism *ism = render_ism(&r, &(drift_ism_params){ .vpl_count = 256,
                                                             .block_size = 1,
                                                             .points_per_vpl = 4096,
                                                             .map_size = sizes[i] });
        e_res[i] = test_nrmse(r.ctx, drift_ism_indirect(ir256), drift_ism_indirect(ism));
        drift_ism_destroy(ism);
    }
    printf("ism vs ir at 16^2 and 64^2 maps: %.4f %.4f\n", e_res[0], e_res[1]);
    assert_true(e_res[1] < e_res[0]);
    drift_ism_destroy(ir256);
    printf("ir nrmse %.4f mean ratio %.4f, no visibility ratio %.4f; ism vs ir %.4f %.4f %.4f\n",
           e_ir, bias_ir, bias_none, e_ism[0], e_ism[1], e_ism[2]);
    assert_true(e_ir < 0.2);
    assert_true(bias_ir > 0.85 && bias_ir < 1.05);
    assert_true(bias_none > bias_ir);
    assert_true(e_ism[1] < e_ism[0] && e_ism[2] < e_ism[1]);
    assert_true(e_ism[2] < 0.1);
    drift_ism_destroy(none);
    drift_ism_destroy(ir);
    drift_pt_destroy(pt);
    test_rig_destroy(&r);
}

// The near-field compensation gives back the light the clamp takes: `ir` with 1024 VPLs and a
// wide clamp (0.2 of the diagonal) against the path tracer's one-bounce diffuse light, without
// the compensation (measured: 0.89 of the mean) and with it fed the path tracer's direct light
// (0.98; the rest is near surfaces the camera does not see). With a clamp that reaches no
// surface it adds nothing.
static void test_near_field_gives_back_the_clamp(void **state)
{
    (void)state;
    test_rig r = cornell_rig(2, 64); // at 32 x 32 a hit's pixel is too often another surface
    drift_pt *pt = NULL, *pt_direct = NULL;
    drift_image ref = render_pt(&r, DRIFT_PT_COMPONENT_DIFFUSE, 2, 256, &pt);
    drift_image direct = render_pt(&r, DRIFT_PT_COMPONENT_DIRECT, 1, 128, &pt_direct);
    const drift_gbuffer *gb = drift_hybrid_gbuffer(r.frame);
    drift_ism_params p = { .visibility = DRIFT_ISM_VISIBILITY_RAYS,
                           .vpl_count = 1024,
                           .max_depth = 2 };
    float diag = 10.0f * drift_ism_params_resolve(&p, r.scene).clamp_distance;
    double ratio[2], error[2];
    for (int on = 0; on < 2; ++on) {
        p.clamp_distance = 0.2f * diag; // the same clamp either way
        p.no_near_field = !on;
        drift_ism *ism = NULL;
        assert_int_equal(drift_ism_create(r.ctx, r.scene, r.accel, &p, &ism), DRIFT_OK);
        assert_int_equal(drift_ism_render(ism, gb, &r.scene->camera, on ? &direct : NULL),
                         DRIFT_OK);
        ratio[on] =
            drift_image_mean_luminance(drift_ism_indirect(ism)) / drift_image_mean_luminance(&ref);
        error[on] = test_nrmse(r.ctx, &ref, drift_ism_indirect(ism));
        assert_true((drift_ism_get_stats(ism).near_field_rays > 0) == (on == 1));
        drift_ism_destroy(ism);
    }
    printf("clamp 0.2 x diagonal: mean ratio %.4f without, %.4f with; nrmse %.4f, %.4f\n", ratio[0],
           ratio[1], error[0], error[1]);
    assert_true(ratio[0] < 0.92); // the clamp's loss is there to give back
    assert_true(fabs(ratio[1] - 1.0) < 0.03);
    assert_true(error[1] < error[0]);
    // A clamp shorter than any ray's way to a surface: the same image.
    p.clamp_distance = 1e-4f * diag;
    drift_ism *a = NULL, *b = NULL;
    drift_ism_params without = p;
    without.no_near_field = true;
    p.no_near_field = false;
    assert_int_equal(drift_ism_create(r.ctx, r.scene, r.accel, &without, &a), DRIFT_OK);
    assert_int_equal(drift_ism_create(r.ctx, r.scene, r.accel, &p, &b), DRIFT_OK);
    assert_int_equal(drift_ism_render(a, gb, &r.scene->camera, NULL), DRIFT_OK);
    assert_int_equal(drift_ism_render(b, gb, &r.scene->camera, &direct), DRIFT_OK);
    assert_memory_equal(drift_ism_indirect(a)->pixels, drift_ism_indirect(b)->pixels,
                        64 * 64 * 3 * sizeof(float));
    drift_ism_destroy(a);
    drift_ism_destroy(b);
    drift_pt_destroy(pt_direct);
    drift_pt_destroy(pt);
    test_rig_destroy(&r);
}

// The Cornell box with every surface glossy (kd halved, ks 0.4, n 32: under
// DRIFT_VPL_MAX_EXPONENT, so no lobe is widened): `ir` with many VPLs against the path
// tracer's first-bounce diffuse light, whose second vertex scatters by the whole BSDF. The
// VPLs' glossy lobes carry the light the glossy surfaces reflect; without them (VPLs that
// shine kd alone) the mean falls to 0.48 of the path tracer's and the NRMSE rises from 0.38
// to 0.85 (the glossy lobes' spots and the path tracer's noise at 32 x 32 keep it high).
static void test_glossy_vpls_against_path_tracer(void **state)
{
    (void)state;
    test_rig r = cornell_rig(2, 32);
    for (uint32_t i = 0; i < r.scene->material_count; ++i) {
        drift_material *m = &r.scene->materials[i];
        m->diffuse = drift_vec3_scale(m->diffuse, 0.5f);
        m->specular = drift_vec3_splat(0.4f);
        m->exponent = 32.0f;
    }
    test_rig_frame(&r, &(drift_hybrid_params){ .width = 32, .height = 32 });
    drift_pt *pt = NULL;
    drift_image ref = render_pt(&r, DRIFT_PT_COMPONENT_DIFFUSE, 2, 512, &pt);
    drift_ism *ir = render_ism(&r, &(drift_ism_params){ .visibility = DRIFT_ISM_VISIBILITY_RAYS,
                                                        .vpl_count = 2048,
                                                        .block_size = 1 });
    uint32_t count, glossy = 0;
    const drift_vpl *vpls = drift_ism_vpls(ir, &count);
    for (uint32_t j = 0; j < count; ++j) {
        glossy += !drift_vec3_is_zero(vpls[j].glossy) && vpls[j].squarings == 5;
    }
    double ratio =
        drift_image_mean_luminance(drift_ism_indirect(ir)) / drift_image_mean_luminance(&ref);
    double e = test_nrmse(r.ctx, &ref, drift_ism_indirect(ir));
    printf("glossy box: ir / pt mean %.4f, nrmse %.4f, %u of %u VPLs glossy\n", ratio, e, glossy,
           count);
    assert_true(glossy == count);
    assert_true(ratio > 0.9 && ratio < 1.05);
    assert_true(e < 0.5);
    // The ISM gather's glossy loop (vectorised) agrees with the ray-traced one.
    drift_ism *ism = render_ism(&r, &(drift_ism_params){ .vpl_count = 2048, .block_size = 1 });
    double ism_ratio = drift_image_mean_luminance(drift_ism_indirect(ism)) /
                       drift_image_mean_luminance(drift_ism_indirect(ir));
    printf("ism / ir mean %.4f\n", ism_ratio);
    assert_true(ism_ratio > 0.9 && ism_ratio < 1.1);
    drift_ism_destroy(ism);
    drift_ism_destroy(ir);
    drift_pt_destroy(pt);
    test_rig_destroy(&r);
}

// A constant environment of radiance L over a 2 x 2 floor of albedo a: both faces see the
// environment's half, so the VPLs carry 2 x a x pi L x 4 (within 3 sigma). With a small
// triangle far away the scene's bounding disc grows and few paths land: the path rounds keep
// the estimate unbiased.
static void test_environment_vpls_carry_its_power(void **state)
{
    (void)state;
    for (int far = 0; far < 2; ++far) {
        test_rig r = test_rig_begin(2);
        uint32_t m = test_add_material(r.scene, drift_material_make(drift_vec3_splat(0.5f)));
        test_add_floor(r.scene, 1.0f, 0.0f, m);
        if (far) {
            float tri[9] = { 9, 9, 9, 9.01f, 9, 9, 9, 9.01f, 9 };
            uint32_t idx[3] = { 0, 1, 2 };
            test_add_mesh(r.scene, tri, 3, idx, 1, m);
        }
        r.scene->environment.color = drift_vec3_splat(0.25f);
        test_rig_commit(&r);
        drift_ism_params p =
            drift_ism_params_resolve(&(drift_ism_params){ .vpl_count = 4096 }, r.scene);
        uint32_t count = 0;
        double sum[4], sigma;
        drift_vpl *vpls = vpls_by_bounce(&r, &p, &count, sum, &sigma);
        if (far) {
            // Several rounds ran: the VPLs of all of them count, divided by the rounds.
            assert_true(count > p.vpl_count / 16);
            assert_true(count <= drift__ism_max_vpls(&p));
        }
        double expected = 2.0 * 0.5 * (double)DRIFT_PI * 0.25 * 4.0;
        assert_true(fabs(sum[0] - expected) <= 3.0 * sigma);
        drift_free(r.ctx, vpls);
        test_rig_destroy(&r);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_paraboloid_round_trip),
        cmocka_unit_test(test_vpl_flux_is_power_times_albedo),
        cmocka_unit_test(test_paths_go_on_through_mirrors),
        cmocka_unit_test(test_ism_of_an_occluder_matches_rays),
        cmocka_unit_test(test_pull_push_fills_holes),
        cmocka_unit_test(test_lazy_push_equals_eager),
        cmocka_unit_test(test_ir_and_ism_against_path_tracer),
        cmocka_unit_test(test_near_field_gives_back_the_clamp),
        cmocka_unit_test(test_glossy_vpls_against_path_tracer),
        cmocka_unit_test(test_environment_vpls_carry_its_power),
        cmocka_unit_test(test_gather_equals_the_formula),
        cmocka_unit_test(test_blur_is_the_window_average),
        cmocka_unit_test(test_gather_scale_upsamples_by_the_blur_tests),
        cmocka_unit_test(test_slices_average_to_the_full_render),
        cmocka_unit_test(test_extent_ignores_a_distant_pure_emitter),
        cmocka_unit_test(test_ism_is_deterministic),
        cmocka_unit_test(test_vpl_importance_is_unbiased),
        cmocka_unit_test(test_vpl_importance_keeps_useful_vpls),
        cmocka_unit_test(test_maps_grow_without_changing_the_image),
        cmocka_unit_test(test_rigid_motion_leaves_the_image),
        cmocka_unit_test(test_bounces_add_shrinking_light),
        cmocka_unit_test(test_parameters_and_planes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
