// ISG's glossy reflections on a curved reflector against the path tracer: a rough GGX metal
// sphere reflecting a bright stripe. The stripe's reflection on the sphere must be as wide as
// the path tracer's first-bounce glossy light shows it. The gather weighted by world distance
// and normal change (eq. 10) closes to a few pixels on a sphere whatever the lobe's cone, and
// left the stripe nearly sharp (issue 40, session 7: docs/isg.md).
// ctest-labels: quality
#include "drift/hybrid.h"
#include "drift/pt.h"
#include "drift/scene.h"
#include "drift_test.h"
#include "test_rig.h"

#include <math.h>

#define SIZE 64

// A unit sphere of GGX gold-like metal of roughness alpha at the origin, seen from -z; a long
// white diffuse stripe up and behind the camera (out of view) that the sphere reflects in its
// upper half, lit by a point light; no environment.
static void build_stripe(test_rig *r, float alpha)
{
    drift_material metal = drift_material_make(drift_vec3_splat(0.9f));
    metal.type = DRIFT_MATERIAL_GGX;
    metal.ggx.alpha = alpha;
    metal.ggx.metallic = 1.0f; // a conductor of F0 0.9 (Schlick)
    uint32_t sphere = test_add_material(r->scene, metal);
    test_add_sphere(r->scene, drift_vec3_make(0.0f, 0.0f, 0.0f), 1.0f, 96, 48, sphere);
    uint32_t white = test_add_material(r->scene, drift_material_make(drift_vec3_splat(0.9f)));
    // The stripe lies along x, 0.6 wide, centred 3 units from the sphere point whose normal is
    // tilted 30 degrees up, along that point's mirror direction (0, sin 60, -cos 60).
    drift_vec3 m = drift_vec3_make(0.0f, 0.866f, -0.5f);
    drift_vec3 centre = drift_vec3_fma(drift_vec3_make(0.0f, 0.5f, -0.866f), m, 3.0f);
    drift_vec3 across = drift_vec3_make(0.0f, 0.5f, 0.866f); // perpendicular to m in the yz plane
    drift_vec3 u = drift_vec3_make(12.0f, 0.0f, 0.0f), v = drift_vec3_scale(across, 0.6f);
    drift_vec3 corner = drift_vec3_sub(centre, drift_vec3_scale(drift_vec3_add(u, v), 0.5f));
    test_add_quad(r->scene, corner, v, u, white); // faces -m, toward the sphere
    assert_int_equal(drift_scene_add_light(r->scene,
                                           &(drift_light){ .type = DRIFT_LIGHT_POINT,
                                                           .position = { 0.0f, 1.2f, -3.0f },
                                                           .color = { 20, 20, 20 } },
                                           NULL),
                     DRIFT_OK);
    r->scene->camera =
        drift_camera_look_at(drift_vec3_make(0.0f, 0.0f, -4.0f), drift_vec3_make(0.0f, 0.0f, 0.0f),
                             drift_vec3_make(0.0f, 1.0f, 0.0f), 0.6f, SIZE, SIZE);
    test_rig_commit(r);
}

typedef struct profile {
    double total, mean; // sum, centroid row
    double width;       // rows between the 25% and 75% points of the cumulative sum
} profile;

// The row (fractional, linear within a row) where the cumulative sum reaches q of the total.
static double quantile_row(const double *row, int32_t rows, double total, double q)
{
    double acc = 0.0;
    for (int32_t y = 0; y < rows; ++y) {
        if (acc + row[y] >= q * total) {
            return (double)y + (q * total - acc) / row[y];
        }
        acc += row[y];
    }
    return (double)rows;
}

// The green channel over the sphere's central columns, summed per row over the sphere's upper
// half (where the stripe's reflection lies; image y grows downward): its total, centroid and
// interquartile width (the middle half of the light; a second moment would be ruled by GGX's
// long tails and the path tracer's noise).
static profile stripe_profile(const drift_image *image)
{
    enum {
        ROWS = SIZE / 2 + 1
    };

    double row[ROWS] = { 0 };
    profile p = { 0 };
    for (int32_t y = 0; y < ROWS; ++y) {
        for (int32_t x = SIZE / 2 - 3; x <= SIZE / 2 + 2; ++x) {
            row[y] += (double)drift_image_pixel(image, x, y)[1];
        }
        p.total += row[y];
        p.mean += row[y] * ((double)y + 0.5);
    }
    p.mean /= p.total;
    p.width = quantile_row(row, ROWS, p.total, 0.75) - quantile_row(row, ROWS, p.total, 0.25);
    return p;
}

static void test_rough_sphere_reflects_a_stripe_as_wide_as_the_path_tracer(void **state)
{
    (void)state;
    const float alphas[2] = { 0.1f, 0.3f };
    for (int k = 0; k < 2; ++k) {
        test_rig r = test_rig_begin(2);
        build_stripe(&r, alphas[k]);
        drift_pt *pt = NULL;
        drift_image ref = test_rig_render_pt(&r, DRIFT_PT_COMPONENT_SPECULAR, 2, 512, 5, &pt);
        test_rig_frame(&r, &(drift_hybrid_params){ .reflections = DRIFT_REFLECTIONS_ISG,
                                                   .shadows = DRIFT_SHADOWS_HARD });
        profile isg = stripe_profile(test_rig_plane(&r, "reflections"));
        test_rig_frame(&r, &(drift_hybrid_params){ .reflections = DRIFT_REFLECTIONS_SHARP,
                                                   .shadows = DRIFT_SHADOWS_HARD });
        profile sharp = stripe_profile(test_rig_plane(&r, "reflections"));
        profile truth = stripe_profile(&ref);
        print_message("alpha %.2f: stripe width (rows) path tracer %.2f, isg %.2f, sharp %.2f; "
                      "centroid %.2f / %.2f; total %.3f / %.3f / sharp %.3f\n",
                      (double)alphas[k], truth.width, isg.width, sharp.width, truth.mean, isg.mean,
                      truth.total, isg.total, sharp.total);
        assert_true(truth.total > 0.0 && isg.total > 0.0);
        // The sharp stripe is far narrower than the lobe makes it (the test can tell); the
        // gather's width is the path tracer's within 25% (measured 1.06x and 1.07x).
        assert_true(sharp.width < 0.6 * truth.width);
        assert_true(isg.width > 0.8 * truth.width && isg.width < 1.25 * truth.width);
        assert_near(isg.mean, truth.mean, 0.2 * truth.width + 0.5);
        // The gather's light is 11-17% short of the path tracer's here (docs/isg.md).
        assert_near(isg.total, truth.total, 0.25 * truth.total);
        drift_pt_destroy(pt);
        test_rig_destroy(&r);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rough_sphere_reflects_a_stripe_as_wide_as_the_path_tracer),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
