// --env-denoise (drift_hybrid_params.environment_denoise): the environment filter's passes
// through the path tracer's variance-guided denoiser (drift/denoise.h) instead of the
// guide-only a-trous filter. A floor under a constant sky, half shaded by a low roof: the
// environment's direct light at one shadow ray a pixel, against the converged light.
#include "drift/hybrid.h"
#include "drift/image.h"
#include "drift_test.h"
#include "test_rig.h"

#include <string.h>

// A white floor (albedo 0.7) under a constant sky of 0.5 with a low 2 x 2 roof over its
// middle, seen from above at 64 x 48, on `threads` threads.
static test_rig sky_rig(int threads)
{
    test_rig r = test_rig_begin(threads);
    uint32_t white = test_add_material(r.scene, drift_material_make(drift_vec3_splat(0.7f)));
    test_add_floor(r.scene, 4.0f, 0.0f, white);
    test_add_quad(r.scene, drift_vec3_make(-1.0f, 0.4f, -1.0f), drift_vec3_make(2.0f, 0, 0),
                  drift_vec3_make(0, 0, 2.0f), white);
    r.scene->environment.color = drift_vec3_splat(0.5f);
    r.scene->camera =
        drift_camera_look_at(drift_vec3_make(0, 3.0f, -3.0f), drift_vec3_make(0, 0, 0),
                             drift_vec3_make(0, 1, 0), 0.9f, 64, 48);
    test_rig_commit(&r);
    return r;
}

static drift_image environment_plane(test_rig *r, const drift_hybrid_params *params)
{
    test_rig_frame(r, params);
    return test_image_copy(r->ctx, test_rig_plane(r, "environment_direct"));
}

// With --env-denoise on the plane is not the traced one nor the a-trous one (the filter is
// applied), is closer to the converged light than the traced light at 1 ray, keeps the mean,
// and is bit-identical on 1 and 3 threads.
static void test_env_denoise_applied(void **state)
{
    (void)state;
    test_rig r = sky_rig(2);
    drift_image truth = environment_plane(&r, &(drift_hybrid_params){ .light_samples = 1024 });
    drift_image traced = environment_plane(&r, &(drift_hybrid_params){ .light_samples = 1 });
    drift_image atrous = environment_plane(
        &r, &(drift_hybrid_params){ .light_samples = 1, .environment_filter = 4 });
    const drift_hybrid_params on = { .light_samples = 1,
                                     .environment_filter = 4,
                                     .environment_denoise = true };
    drift_image denoised = environment_plane(&r, &on);
    double e_traced = test_rmse(r.ctx, &traced, &truth);
    double e_atrous = test_rmse(r.ctx, &atrous, &truth);
    double e_denoised = test_rmse(r.ctx, &denoised, &truth);
    double mean = drift_image_mean_luminance(&denoised) / drift_image_mean_luminance(&truth);
    print_message("environment light, 1 ray a pixel: rmse traced %g, a-trous 4 passes %g, "
                  "--env-denoise on %g; denoised mean / converged %g\n",
                  e_traced, e_atrous, e_denoised, mean);
    assert_true(e_denoised < 0.7 * e_traced);
    assert_true(test_rmse(r.ctx, &denoised, &atrous) > 0.0);
    assert_near(mean, 1.0, 0.03);

    test_rig one = sky_rig(1), three = sky_rig(3);
    drift_image d1 = environment_plane(&one, &on), d3 = environment_plane(&three, &on);
    assert_memory_equal(d1.pixels, d3.pixels, sizeof(float) * 3 * (size_t)d1.width * d1.height);
    assert_memory_equal(d1.pixels, denoised.pixels,
                        sizeof(float) * 3 * (size_t)d1.width * d1.height);
    drift_image_destroy(one.ctx, &d1);
    drift_image_destroy(three.ctx, &d3);
    test_rig_destroy(&one);
    test_rig_destroy(&three);
    drift_image_destroy(r.ctx, &truth);
    drift_image_destroy(r.ctx, &traced);
    drift_image_destroy(r.ctx, &atrous);
    drift_image_destroy(r.ctx, &denoised);
    test_rig_destroy(&r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_env_denoise_applied),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
