// The defaults render every effect a scene has (issue 40): drift_hybrid_params_recommended,
// what `drift render --mode hybrid` and `drift view` start from, on a small scene with a
// metal sphere and a quad area light over a floor, against the reference path tracer.
// A default that leaves an effect out (reflections `none` rendered the metal black) fails.
// 40 x 30 pixels, the path tracer at 64 spp.
#include "drift/hybrid.h"
#include "drift/pt.h"
#include "drift/scene.h"
#include "drift_test.h"
#include "test_rig.h"

#include <math.h>
#include <stdlib.h>

enum {
    W = 48,
    H = 36
};

// A floor, a metal sphere (black diffuse, gold specular, Phong 60) casting a penumbra under
// a 1 x 1 quad light above it, and a black sky: the metal shows the lit floor.
static test_rig build_scene(void)
{
    test_rig r = test_rig_begin(2);
    uint32_t white = test_add_material(r.scene, drift_material_make(drift_vec3_splat(0.6f)));
    drift_material metal = drift_material_make(drift_vec3_splat(0.0f));
    metal.specular = drift_vec3_make(0.95f, 0.75f, 0.35f);
    metal.exponent = 60.0f;
    uint32_t gold = test_add_material(r.scene, metal);
    test_add_floor(r.scene, 6.0f, 0.0f, white);
    test_add_sphere(r.scene, drift_vec3_make(0.0f, 1.0f, 0.0f), 1.0f, 32, 16, gold);
    test_add_quad_light(r.scene, drift_vec3_make(-0.5f, 4.0f, -0.5f), drift_vec3_make(1, 0, 0),
                        drift_vec3_make(0, 0, 1), 30.0f);
    r.scene->environment = (drift_environment){ drift_vec3_splat(0.0f), DRIFT_INVALID_INDEX };
    r.scene->camera =
        drift_camera_look_at(drift_vec3_make(0.0f, 2.0f, 5.0f), drift_vec3_make(0.0f, 0.8f, 0.0f),
                             drift_vec3_make(0, 1, 0), 0.9f, W, H);
    test_rig_commit(&r);
    return r;
}

static int by_value(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

// The upper quartile of the luminance over the pixels the sphere covers (material 1 in the
// G-buffer): its lower half reflects the lit floor (the upper one the black sky), the
// light's highlight is a few pixels.
static double sphere_quartile(const test_rig *r, const drift_image *img)
{
    const drift_gbuffer *g = drift_hybrid_gbuffer(r->frame);
    static double values[W * H];
    int n = 0;
    for (int y = 0; y < H; ++y) {
        for (int x = 0; x < W; ++x) {
            if (drift_image_pixel(&g->material_id, x, y)[0] == 1.0f) {
                drift_vec3 c = drift_image_get3(img, x, y);
                values[n++] = 0.2126 * (double)c.x + 0.7152 * (double)c.y + 0.0722 * (double)c.z;
            }
        }
    }
    assert_true(n > 50);
    qsort(values, (size_t)n, sizeof *values, by_value);
    return values[3 * n / 4];
}

static void test_defaults_render_every_effect(void **state)
{
    (void)state;
    test_rig r = build_scene();
    drift_pt *pt = NULL;
    drift_image truth = test_rig_render_pt(&r, DRIFT_PT_COMPONENT_ALL, 8, 64, 7, &pt);

    drift_hybrid_params p = drift_hybrid_params_recommended();
    // Each effect the scene has is rendered by a technique: reflections, and soft shadows
    // (ISG, PCSS, AAF or the path tracer; `hard` at one anti-aliasing pass is a point's).
    assert_int_not_equal(p.reflections, DRIFT_REFLECTIONS_NONE);
    assert_true(p.shadows != DRIFT_SHADOWS_HARD || p.aa > 1);
    assert_true(p.shadows != DRIFT_SHADOWS_PCF);
    assert_int_not_equal(p.indirect, DRIFT_INDIRECT_NONE);
    assert_int_not_equal(p.dof, DRIFT_DOF_NONE); // a lens's depth of field
    test_rig_frame(&r, &p);
    double got = sphere_quartile(&r, drift_hybrid_image(r.frame));
    double want = sphere_quartile(&r, &truth);
    // The metal is lit by its reflections alone: without them it is black (got ~ 0).
    assert_true(want > 0.02);
    assert_true(got > 0.6 * want && got < 1.5 * want);
    // The zeroed (neutral) frame, reflections `none`, leaves the metal nearly black: the
    // measurement above can tell.
    test_rig_frame(&r, &(drift_hybrid_params){ 0 });
    double neutral = sphere_quartile(&r, drift_hybrid_image(r.frame));
    print_message("metal sphere: default %.4f, path tracer %.4f, neutral frame %.4f\n", got, want,
                  neutral);
    assert_true(neutral < 0.5 * want);

    drift_pt_destroy(pt);
    test_rig_destroy(&r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_defaults_render_every_effect),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
