// What the sharp reflection buffer shades a mirror ray's hit with, beyond direct light with a
// hard shadow (realtime/reflections.c, trace_reflected): the indirect light at the hit (an
// ambient guess) and one more mirror bounce. Both against the path tracer's SPECULAR light
// through the same pixel centres.
#include "drift_test.h"
#include "test_rig.h"

#include <math.h>

// The mean green of the size x size image's central 5 x 5 pixels.
static double centre_mean(const drift_image *image, int32_t size)
{
    double sum = 0.0;
    for (int32_t y = size / 2 - 2; y <= size / 2 + 2; ++y) {
        for (int32_t x = size / 2 - 2; x <= size / 2 + 2; ++x) {
            sum += (double)drift_image_pixel(image, x, y)[1];
        }
    }
    return sum / 25.0;
}

// R (the `sharp` row, at --max-depth 8) and the path tracer's SPECULAR component at depth 8
// over the centre of the rig's camera.
static void reflections_and_truth(test_rig *r, drift_hybrid_params params, int32_t size,
                                  double *out_r, double *out_truth)
{
    params.width = params.height = size;
    params.reflections = DRIFT_REFLECTIONS_SHARP;
    params.max_depth = 8;
    test_rig_frame(r, &params);
    *out_r = centre_mean(test_rig_plane(r, "reflections"), size);
    drift_pt *pt = NULL;
    drift_image truth = test_rig_render_pt(r, DRIFT_PT_COMPONENT_SPECULAR, 8, 1024, 7, &pt);
    *out_truth = centre_mean(&truth, size);
    drift_pt_destroy(pt);
}

// A mirror on the back wall of a white room, seen from below, shows the ceiling; the room's
// quad light hangs under the ceiling emitting down, so the ceiling is lit only by the room.
// The mirror's reflection of it was black (the hit's direct light with hard shadows only);
// with the ambient guess at the hit (the frame's mean one-bounce light times the ceiling's
// albedo) it is within a factor 1.5 of the path tracer's, and without indirect light
// (--indirect none) it stays black. Measured 0.84 (0.19 with the ambient sampled at the
// visible surfaces, 0.43 without the later bounces' series). The guess is one number a frame,
// so the bound is a stated tolerance, not a closed form.
static void test_mirror_shows_a_ceiling_lit_only_indirectly(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    uint32_t white = test_add_material(r.scene, drift_material_make(drift_vec3_splat(0.7f)));
    uint32_t mirror =
        test_add_material(r.scene, (drift_material){ .type = DRIFT_MATERIAL_MIRROR,
                                                     .specular = { 0.9f, 0.9f, 0.9f },
                                                     .diffuse_texture = DRIFT_INVALID_INDEX });
    test_add_open_room(r.scene, 2.0f, white, white);
    test_add_quad(r.scene, drift_vec3_make(-1, 1.5f, 1.98f), drift_vec3_make(0, 1.5f, 0),
                  drift_vec3_make(2, 0, 0), mirror); // facing -z, into the room
    test_add_quad_light(r.scene, drift_vec3_make(-0.5f, 3.0f, -0.5f), drift_vec3_make(1, 0, 0),
                        drift_vec3_make(0, 0, 1), 10.0f); // emitting down
    const int32_t size = 24;
    r.scene->camera =
        drift_camera_look_at(drift_vec3_make(0, 1.0f, -1.5f), drift_vec3_make(0, 2.7f, 1.98f),
                             drift_vec3_make(0, 1, 0), 0.3f, size, size);
    test_rig_commit(&r);
    double got, truth;
    reflections_and_truth(&r, (drift_hybrid_params){ .indirect = DRIFT_INDIRECT_AMBIENT }, size,
                          &got, &truth);
    print_message("mirror of a ceiling lit only indirectly: R %g, path tracer %g (ratio %.3f)\n",
                  got, truth, got / truth);
    assert_true(truth > 0.0);
    assert_true(got > truth / 1.5 && got < truth * 1.5);
    test_rig_frame(&r, &(drift_hybrid_params){ .width = size,
                                               .height = size,
                                               .reflections = DRIFT_REFLECTIONS_SHARP,
                                               .max_depth = 8 });
    double none = centre_mean(test_rig_plane(&r, "reflections"), size);
    print_message("--indirect none: R %g\n", none);
    assert_true(none < 1e-6);
    test_rig_destroy(&r);
}

// Two mirrors facing each other, A (z = 2) and B (z = -2), and a white card between them that
// a point light in front of it lights: the camera sees A, which shows B, which shows the card.
// R at A is ks_A ks_B times the card's radiance: black without the second bounce (a mirror has
// no direct light; --max-depth 2 keeps the buffer one bounce deep), within 5% of the path
// tracer's with it. --indirect none: no ambient, the bounce alone (a card of albedo 0.5 keeps
// its light reflected back by B, which the path tracer has, near 2%).
static void test_facing_mirrors_show_the_second_bounce(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    uint32_t white = test_add_material(r.scene, drift_material_make(drift_vec3_splat(0.5f)));
    uint32_t mirror =
        test_add_material(r.scene, (drift_material){ .type = DRIFT_MATERIAL_MIRROR,
                                                     .specular = { 0.9f, 0.9f, 0.9f },
                                                     .diffuse_texture = DRIFT_INVALID_INDEX });
    test_add_quad(r.scene, drift_vec3_make(-4, -2, 2), drift_vec3_make(0, 4, 0),
                  drift_vec3_make(8, 0, 0), mirror); // A, facing -z
    test_add_quad(r.scene, drift_vec3_make(-4, -2, -2), drift_vec3_make(8, 0, 0),
                  drift_vec3_make(0, 4, 0), mirror); // B, facing +z
    test_add_quad(r.scene, drift_vec3_make(2.5f, -1, 0), drift_vec3_make(0, 2, 0),
                  drift_vec3_make(1, 0, 0), white); // the card at z = 0, facing -z (toward B)
    drift_light point = { .type = DRIFT_LIGHT_POINT,
                          .position = { 3.0f, 0.0f, -1.0f },
                          .color = { 4, 4, 4 } };
    assert_int_equal(drift_scene_add_light(r.scene, &point, NULL), DRIFT_OK);
    // From (-1, 0, 0) toward A at (0, 0, 2): A reflects to B at (2, 0, -2), B to the card at
    // (3, 0, 0).
    const int32_t size = 24;
    r.scene->camera = drift_camera_look_at(drift_vec3_make(-1, 0, 0), drift_vec3_make(0, 0, 2),
                                           drift_vec3_make(0, 1, 0), 0.2f, size, size);
    test_rig_commit(&r);
    double got, truth;
    reflections_and_truth(&r, (drift_hybrid_params){ 0 }, size, &got, &truth);
    print_message("mirror A showing mirror B showing a lit card: R %g, path tracer %g (ratio "
                  "%.3f)\n",
                  got, truth, got / truth);
    assert_true(truth > 0.0);
    assert_near(got, truth, 0.05 * truth);
    test_rig_frame(&r, &(drift_hybrid_params){ .width = size,
                                               .height = size,
                                               .reflections = DRIFT_REFLECTIONS_SHARP,
                                               .max_depth = 2 });
    assert_true(centre_mean(test_rig_plane(&r, "reflections"), size) < 1e-6);
    test_rig_destroy(&r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_mirror_shows_a_ceiling_lit_only_indirectly),
        cmocka_unit_test(test_facing_mirrors_show_the_second_bounce),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
