// The hybrid frame's split-sum environment light of GGX surfaces (raster/env_prefilter.c)
// under a real HDR panorama (../shared/scenes/hdri/courtyard.exr):
// - at one point, against the integral of the environment through the GGX BSDF itself
//   (the path tracer's drift_bsdf_sample_wi, many samples);
// - over a frame of four gold spheres (perceptual roughness 0.05, 0.25, 0.5, 0.8), the
//   frame's direct light D against the path tracer's (DRIFT_PT_COMPONENT_DIRECT, depth 1):
//   without the prefilter the sharp spheres render nearly black (env sampling cannot find
//   their lobe), and the bounds fail.
// ctest-labels: quality
#include "drift/accel.h"
#include "drift/image_io.h"
#include "drift/metric.h"
#include "drift_test.h"
#include "raster/raster.h"
#include "test_rig.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static const float roughness[4] = { 0.05f, 0.25f, 0.5f, 0.8f };

// A scene with the courtyard as its environment and gold spheres (or, with spheres false, one
// small floor far below: something for the accelerator to hold).
static test_rig courtyard_rig(bool spheres)
{
    test_rig r = test_rig_begin(2);
    char path[1024];
    drift_image env;
    assert_int_equal(
        drift_image_load(r.ctx, test_shared_path(path, "scenes/hdri/courtyard.exr"), &env),
        DRIFT_OK);
    assert_int_equal(drift_scene_add_texture(r.scene, env, &r.scene->environment.texture),
                     DRIFT_OK);
    r.scene->environment.color = drift_vec3_splat(1.0f);
    for (int i = 0; i < 4; ++i) {
        drift_material m = drift_material_make(drift_vec3_splat(1.0f));
        m.type = DRIFT_MATERIAL_GGX;
        assert_true(drift_ggx_named_metal("Au", &m.ggx));
        m.ggx.alpha = roughness[i] * roughness[i];
        uint32_t mat = test_add_material(r.scene, m);
        if (spheres) {
            test_add_sphere(r.scene, drift_vec3_make(-3.3f + 2.2f * (float)i, 1.0f, 0.0f), 1.0f, 32,
                            16, mat);
        } else if (i == 0) {
            test_add_floor(r.scene, 1.0f, -1000.0f, mat);
        }
    }
    r.scene->camera =
        drift_camera_look_at(drift_vec3_make(0.0f, 2.2f, 9.0f), drift_vec3_make(0.0f, 1.0f, 0.0f),
                             drift_vec3_make(0.0f, 1.0f, 0.0f), 0.5235988f, 64, 32);
    test_rig_commit(&r);
    return r;
}

// One point facing up, wo at angle acos(mu) from the normal: the split sum against the
// BSDF-sampled integral of the environment (unoccluded), per roughness.
static void test_split_sum_matches_the_integral_at_a_point(void **state)
{
    (void)state;
    test_rig r = courtyard_rig(false);
    drift_env_prefilter *p;
    assert_int_equal(drift_env_prefilter_build(r.ctx, r.scene, &p), DRIFT_OK);
    const float mus[3] = { 1.0f, 0.7f, 0.35f };
    double abs_error = 0.0, total = 0.0, worst = 0.0;
    for (int i = 0; i < 4; ++i) {
        for (int k = 0; k < 3; ++k) {
            for (int az = 0; az < 4; ++az) {
                float phi = 1.5707963f * (float)az + 0.4f;
                drift_surface s = { .position = drift_vec3_make(0.0f, 0.0f, 0.0f),
                                    .ng = drift_vec3_make(0.0f, 1.0f, 0.0f),
                                    .ns = drift_vec3_make(0.0f, 1.0f, 0.0f),
                                    .material = (uint32_t)i,
                                    .mesh = DRIFT_INVALID_INDEX,
                                    .front_face = true };
                drift_bsdf bsdf = drift_bsdf_make(r.scene, &s);
                float st = sqrtf(1.0f - mus[k] * mus[k]);
                drift_vec3 wo = drift_vec3_make(st * cosf(phi), mus[k], st * sinf(phi));
                uint64_t rays = 0;
                drift_vec3 split = drift_raster_environment_split_sum(
                    p, r.accel, &s, &bsdf, wo, 4, drift_vec2_make(0.3f, 0.7f), &rays);
                drift_vec3 sum = drift_vec3_splat(0.0f);
                const uint32_t n = 4096;
                for (uint32_t j = 0; j < n; ++j) {
                    drift_vec2 u = drift_hammersley_shifted(j, n, drift_vec2_make(0.1f, 0.2f));
                    drift_bsdf_sample bs =
                        drift_bsdf_sample_wi(&bsdf, wo, test_hash_unit(j * 7u + 1u), u);
                    if (bs.pdf > 0.0f) {
                        sum = drift_vec3_add(
                            sum, drift_vec3_mul(bs.weight, drift_environment_eval(r.scene, bs.wi)));
                    }
                }
                sum = drift_vec3_scale(sum, 1.0f / (float)n);
                double ratio = drift_luminance(split) / drift_luminance(sum);
                printf("roughness %.2f mu %.2f phi %.1f: split %.4f integral %.4f ratio %.3f\n",
                       (double)roughness[i], (double)mus[k], (double)phi,
                       (double)drift_luminance(split), (double)drift_luminance(sum), ratio);
                worst = fmax(worst, fabs(ratio - 1.0));
                abs_error += fabs((double)drift_luminance(split) - (double)drift_luminance(sum));
                total += (double)drift_luminance(sum);
            }
        }
    }
    // The split sum's own error (n = v = r, the lobe's grazing stretch, the sun in a lobe's
    // tail between levels) reaches a factor 2-3 at single points next to the sun; over the
    // 48 points it is 0.20 of the light (docs/hybrid.md).
    printf("worst |ratio - 1| %.3f, mean |split - integral| / mean integral %.3f\n", worst,
           abs_error / total);
    assert_true(abs_error / total < 0.25);
    drift_env_prefilter_destroy(r.ctx, p);
    test_rig_destroy(&r);
}

// The frame's direct light D (hard shadows, nothing else) of four gold spheres under the
// courtyard against the path tracer's direct light: FLIP and relative RMSE bounds that the
// unfiltered environment sampling of the sharp spheres (nearly black) fails.
static void test_frame_direct_light_matches_the_path_tracer(void **state)
{
    (void)state;
    test_rig r = courtyard_rig(true);
    test_rig_frame(&r, &(drift_hybrid_params){ .width = 64, .height = 32, .seed = 3 });
    const drift_image *d = test_rig_plane(&r, "direct");
    drift_pt *pt;
    drift_image truth = test_rig_render_pt(&r, DRIFT_PT_COMPONENT_DIRECT, 1, 64, 5, &pt);
    double flip = 0.0;
    assert_int_equal(drift_metric_flip(r.ctx, &truth, d, &(drift_metric_params){ 0 }, &flip, NULL),
                     DRIFT_OK);
    double nrmse = test_nrmse(r.ctx, &truth, d);
    double ratio = drift_image_mean_luminance(d) / drift_image_mean_luminance(&truth);
    printf("gold spheres under the courtyard, D against the path tracer: FLIP %.4f, NRMSE %.4f, "
           "mean luminance x%.3f\n",
           flip, nrmse, ratio);
    // Measured: FLIP 0.097, NRMSE 0.67, luminance x1.025; with the environment sampled through
    // the whole BSDF instead (no prefilter): FLIP 0.189, NRMSE 4.49, luminance x0.607.
    assert_true(flip < 0.14);
    assert_true(nrmse < 1.5);
    assert_true(fabs(ratio - 1.0) < 0.1);
    drift_pt_destroy(pt);
    test_rig_destroy(&r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_split_sum_matches_the_integral_at_a_point),
        cmocka_unit_test(test_frame_direct_light_matches_the_path_tracer),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
