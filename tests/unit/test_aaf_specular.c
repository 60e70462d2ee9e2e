// AAF's specular buffer (--reflections aaf, src/hybrid/aaf_specular.c): its R term converges
// to the path-traced first-bounce glossy light as spp grows, and the filter width of eq. 4.4
// with Omega_spec = 3.6 + 0.084 m (eq. 4.5) narrows as the lobe sharpens.
// ctest-labels: quality slow
#include "aaf/aaf.h"
#include "drift/accel.h"
#include "drift/hybrid.h"
#include "drift/pt.h"
#include "drift/scene.h"
#include "drift_test.h"
#include "test_rig.h"

#include <math.h>
#include <string.h>

enum {
    W = 64,
    H = 48
};

// A reflective floor reflecting a lit red wall at z = 1.5 and a white one at x = -1.5, under a
// 1x1 quad light at height 3, seen from above the floor looking at `target`.
static test_rig build_floor(const drift_material *floor, drift_vec3 target)
{
    test_rig r = test_rig_begin(2);
    drift_material red = drift_material_make(drift_vec3_make(0.8f, 0.2f, 0.1f));
    drift_material white = drift_material_make(drift_vec3_splat(0.7f));
    uint32_t g, rd, wh;
    assert_int_equal(drift_scene_add_material(r.scene, floor, &g), DRIFT_OK);
    assert_int_equal(drift_scene_add_material(r.scene, &red, &rd), DRIFT_OK);
    assert_int_equal(drift_scene_add_material(r.scene, &white, &wh), DRIFT_OK);
    const float h = 1.5f;
    test_add_quad(r.scene, drift_vec3_make(-h, 0, -h), drift_vec3_make(0, 0, 2 * h),
                  drift_vec3_make(2 * h, 0, 0), g); // floor, up
    test_add_quad(r.scene, drift_vec3_make(-h, 0, h), drift_vec3_make(0, 3, 0),
                  drift_vec3_make(2 * h, 0, 0),
                  rd); // back wall, facing -z
    test_add_quad(r.scene, drift_vec3_make(-h, 0, -h), drift_vec3_make(0, 3, 0),
                  drift_vec3_make(0, 0, 2 * h),
                  wh); // left wall, facing +x
    test_add_quad_light(r.scene, drift_vec3_make(-0.5f, 3.0f, -0.5f), drift_vec3_make(1, 0, 0),
                        drift_vec3_make(0, 0, 1), 5.0f);
    r.scene->camera = drift_camera_look_at(drift_vec3_make(0.3f, 1.2f, -1.4f), target,
                                           drift_vec3_make(0, 1, 0), 1.2f, W, H);
    test_rig_commit(&r);
    return r;
}

// The floor glossy, of Phong exponent `exponent`.
static test_rig build(float exponent)
{
    drift_material glossy = drift_material_make(drift_vec3_splat(0.2f));
    glossy.specular = drift_vec3_splat(0.6f);
    glossy.exponent = exponent;
    return build_floor(&glossy, drift_vec3_make(0, 0.3f, 0.8f));
}

// The pt's SPECULAR component (first bounce glossy or mirror, one bounce): the R term's truth.
static drift_image render_truth(test_rig *r, drift_pt **pt)
{
    drift_pt_params pp = { .width = W,
                           .height = H,
                           .seed = 1234,
                           .max_depth = 2,
                           .components = DRIFT_PT_COMPONENT_SPECULAR,
                           .pixel_centre = true,
                           .pinhole = true };
    assert_int_equal(drift_pt_create(r->ctx, r->scene, r->accel, &pp, pt), DRIFT_OK);
    uint32_t truth_spp = (uint32_t)(512 * test_intensity());
    assert_int_equal(drift_pt_render_samples(*pt, truth_spp < 256 ? 256 : truth_spp, NULL),
                     DRIFT_OK);
    drift_image truth;
    assert_int_equal(drift_pt_resolve(*pt, DRIFT_PT_AOV_BEAUTY, &truth), DRIFT_OK);
    return truth;
}

static void test_specular_converges(void **state)
{
    (void)state;
    test_rig r = build(20.0f);
    drift_pt *pt = NULL;
    drift_image truth = render_truth(&r, &pt);
    const uint32_t spps[3] = { 4, 16, 64 };
    double aaf[3];
    for (int k = 0; k < 3; ++k) {
        drift_hybrid_params p = { .reflections = DRIFT_REFLECTIONS_AAF, .spp = spps[k], .seed = 5 };
        test_rig_frame(&r, &p);
        aaf[k] = test_rmse(r.ctx, test_rig_plane(&r, "reflections"), &truth);
    }
    print_message("specular rmse aaf %g %g %g\n", aaf[0], aaf[1], aaf[2]);
    assert_true(aaf[1] < 0.9 * aaf[0]);
    assert_true(aaf[2] < 0.9 * aaf[1]);
    drift_pt_destroy(pt);
    test_rig_destroy(&r);
}

// A mirror floor keeps a sharp ray: nothing is filtered (beta 0 everywhere), the light's
// emission seen in the mirror is R's, and the estimate converges to the reference.
static void test_mirror_stays_sharp(void **state)
{
    (void)state;
    drift_material mirror = drift_material_make(drift_vec3_splat(0.0f));
    mirror.type = DRIFT_MATERIAL_MIRROR;
    mirror.specular = drift_vec3_splat(0.8f);
    test_rig r = build_floor(&mirror, drift_vec3_make(0, -0.5f, 0)); // the light is in the mirror
    drift_pt *pt = NULL;
    drift_image truth = render_truth(&r, &pt);
    double error[2], brightest = 0.0, brightest_truth = 0.0;
    const uint32_t spps[2] = { 4, 64 };
    for (int k = 0; k < 2; ++k) {
        drift_hybrid_params p = { .reflections = DRIFT_REFLECTIONS_AAF, .spp = spps[k], .seed = 5 };
        test_rig_frame(&r, &p);
        error[k] = test_rmse(r.ctx, test_rig_plane(&r, "reflections"), &truth);
        const drift_image *beta = test_rig_plane(&r, "reflections.aaf.beta");
        const drift_image *refl = test_rig_plane(&r, "reflections");
        for (int y = 0; y < H; ++y) {
            for (int x = 0; x < W; ++x) {
                assert_true(drift_image_pixel(beta, x, y)[0] == 0.0f);
                brightest = fmax(brightest, (double)drift_image_pixel(refl, x, y)[0]);
                brightest_truth = fmax(brightest_truth, (double)drift_image_pixel(&truth, x, y)[0]);
            }
        }
    }
    print_message("mirror rmse %g %g, brightest %g (truth %g)\n", error[0], error[1], brightest,
                  brightest_truth);
    assert_true(error[1] < 0.7 * error[0]);
    assert_true(brightest > 0.9 * brightest_truth); // the light itself, seen in the mirror
    drift_pt_destroy(pt);
    test_rig_destroy(&r);
}

static double mean_beta(const test_rig *r)
{
    const drift_image *beta = test_rig_plane(r, "reflections.aaf.beta");
    double sum = 0.0;
    int count = 0;
    for (int y = 0; y < beta->height; ++y) {
        for (int x = 0; x < beta->width; ++x) {
            float b = drift_image_pixel(beta, x, y)[0];
            sum += b > 0.0f ? (double)b : 0.0;
            count += b > 0.0f;
        }
    }
    assert_true(count > 0);
    return sum / count;
}

// Sharper lobes resolve finer detail of the incoming light (eq. 4.5): the filter narrows.
static void test_beta_shrinks_with_the_exponent(void **state)
{
    (void)state;
    assert_float_equal(drift_aaf_omega_specular(25.0f), 3.6f + 0.084f * 100.0f, 1e-5f);
    assert_true(drift_aaf_indirect_beta(1.0f, 0.01f, 10.0f, 1.0f) <
                drift_aaf_indirect_beta(1.0f, 0.01f, 5.0f, 1.0f));
    const float exponents[3] = { 1.0f, 4.0f, 16.0f };
    double beta[3];
    for (int k = 0; k < 3; ++k) {
        test_rig r = build(exponents[k]);
        drift_hybrid_params p = { .reflections = DRIFT_REFLECTIONS_AAF, .spp = 4, .seed = 5 };
        test_rig_frame(&r, &p);
        beta[k] = mean_beta(&r);
        test_rig_destroy(&r);
    }
    print_message("specular mean beta %g %g %g\n", beta[0], beta[1], beta[2]);
    assert_true(beta[1] < 0.95 * beta[0]);
    assert_true(beta[2] < 0.95 * beta[1]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_specular_converges),
        cmocka_unit_test(test_mirror_stays_sharp),
        cmocka_unit_test(test_beta_shrinks_with_the_exponent),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
