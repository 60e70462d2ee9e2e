// --aaf-denoise (drift_aaf_settings.denoise): AAF's noisy estimates through the feature-guided
// denoiser. On a small closed room under a quad light, the denoised AAF shadow (random
// sampler) and indirect planes at 4 spp are closer to AAF's own converged estimate (1024 / 256 spp,
// every pixel, unfiltered: the same estimator without noise) than the unfiltered samples, and the
// knob round-trips through its table row.
#include "aaf/aaf.h"
#include "drift/hybrid.h"
#include "drift/knobs.h"
#include "drift_test.h"
#include "test_rig.h"

#include <string.h>

enum {
    W = 48,
    H = 36
};

// A room (floor, ceiling, a red wall and two white ones) with a low square table under a 1 x 1
// quad light at height 3: the table's soft shadow on the floor and colour bleeding.
static test_rig room_rig(void)
{
    test_rig r = test_rig_begin(2);
    uint32_t white =
        test_add_material(r.scene, drift_material_make(drift_vec3_make(0.7f, 0.6f, 0.5f)));
    uint32_t red =
        test_add_material(r.scene, drift_material_make(drift_vec3_make(0.7f, 0.1f, 0.1f)));
    test_add_open_room(r.scene, 1.5f, white, red);
    test_add_quad(r.scene, drift_vec3_make(-0.1f, 0.8f, -0.2f), drift_vec3_make(0.8f, 0, 0),
                  drift_vec3_make(0, 0, 0.8f), white); // the table, facing down and up
    test_add_quad(r.scene, drift_vec3_make(-0.1f, 0.8f, -0.2f), drift_vec3_make(0, 0, 0.8f),
                  drift_vec3_make(0.8f, 0, 0), white);
    test_add_quad_light(r.scene, drift_vec3_make(-0.5f, 3.0f, -0.5f), drift_vec3_make(1, 0, 0),
                        drift_vec3_make(0, 0, 1), 5.0f);
    r.scene->camera =
        drift_camera_look_at(drift_vec3_make(0, 1.5f, -1.45f), drift_vec3_make(0, 0.5f, 0.5f),
                             drift_vec3_make(0, 1, 0), 1.4f, W, H);
    test_rig_commit(&r);
    return r;
}

static drift_image plane_copy(test_rig *r, const drift_hybrid_params *params, const char *name)
{
    test_rig_frame(r, params);
    return test_image_copy(r->ctx, test_rig_plane(r, name));
}

// The pass's plane at 4 spp unfiltered and with the denoiser instead of AAF's filter, against
// the converged estimate: the denoised error is below `bound` times the unfiltered one.
static void check_pass(test_rig *r, drift_hybrid_params p, const char *plane, uint32_t truth_spp,
                       double bound)
{
    drift_hybrid_params truth_params = p;
    truth_params.spp = truth_spp;
    truth_params.aaf.uniform = truth_params.aaf.unfiltered = true;
    drift_image truth = plane_copy(r, &truth_params, plane);
    p.spp = 4;
    p.aaf.unfiltered = true;
    drift_image raw = plane_copy(r, &p, plane);
    p.aaf.unfiltered = false;
    p.aaf.denoise = DRIFT_AAF_DENOISE_ON;
    drift_image denoised = plane_copy(r, &p, plane);
    double e_raw = test_rmse(r->ctx, &raw, &truth),
           e_denoised = test_rmse(r->ctx, &denoised, &truth);
    print_message("%s at 4 spp: rmse unfiltered %g, --aaf-denoise on %g\n", plane, e_raw,
                  e_denoised);
    assert_true(e_denoised < bound * e_raw);
    drift_image_destroy(r->ctx, &truth);
    drift_image_destroy(r->ctx, &raw);
    drift_image_destroy(r->ctx, &denoised);
}

static void test_denoised_passes_are_closer(void **state)
{
    (void)state;
    test_rig r = room_rig();
    // Shadows with independent random rays: Sobol points leave 4 spp's visibility so close to
    // converged that no filter helps it (docs/aaf.md, --aaf-denoise).
    check_pass(&r,
               (drift_hybrid_params){ .shadows = DRIFT_SHADOWS_AAF,
                                      .indirect = DRIFT_INDIRECT_NONE,
                                      .reflections = DRIFT_REFLECTIONS_NONE,
                                      .aaf.random = true,
                                      .seed = 3 },
               "light0.shadow", 1024, 0.9);
    check_pass(&r,
               (drift_hybrid_params){ .shadows = DRIFT_SHADOWS_HARD,
                                      .indirect = DRIFT_INDIRECT_AAF,
                                      .reflections = DRIFT_REFLECTIONS_NONE,
                                      .max_depth = 2,
                                      .seed = 5 },
               "indirect", 256, 0.5);
    test_rig_destroy(&r);
}

// The knob's row: each choice parses, sets the field, reads back and formats to its name;
// a value outside the choices is refused, and so is an out-of-range field.
static void test_knob_round_trips(void **state)
{
    (void)state;
    int k = drift_knob_find("aaf-denoise");
    assert_true(k >= 0);
    const drift_knob *knob = drift_knob_get(k);
    const char *names[3] = { "off", "on", "both" };
    const drift_aaf_denoise modes[3] = { DRIFT_AAF_DENOISE_OFF, DRIFT_AAF_DENOISE_ON,
                                         DRIFT_AAF_DENOISE_BOTH };
    for (int i = 0; i < 3; ++i) {
        double value;
        char text[16];
        drift_hybrid_params p = drift_hybrid_params_default();
        assert_true(drift_knob_parse(knob, names[i], &value));
        assert_true(drift_knob_set(&p, k, value));
        assert_int_equal(p.aaf.denoise, modes[i]);
        assert_true(drift_knob_value(&p, k) == value);
        drift_knob_format(knob, value, text, sizeof text);
        assert_string_equal(text, names[i]);
    }
    double value;
    assert_false(drift_knob_parse(knob, "before", &value));
    drift_aaf_settings s = { .max_spp = 64, .denoise = (drift_aaf_denoise)3 };
    assert_non_null(drift_aaf_settings_problem(&s, 8));
    s.denoise = DRIFT_AAF_DENOISE_BOTH;
    assert_null(drift_aaf_settings_problem(&s, 8));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_denoised_passes_are_closer),
        cmocka_unit_test(test_knob_round_trips),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
