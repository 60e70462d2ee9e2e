// The viewer's core without a display: the framebuffer shows the scene, technique keys
// change the hybrid frame's parameters and wrap around, the buffer keys visit every plane,
// the reference restarts when the camera moves and converges while it stands still, and
// the split puts the reference right of the line.
#include "drift/accel.h"
#include "drift/hybrid.h"
#include "drift/image.h"
#include "drift/pt.h"
#include "drift/scene.h"
#include "drift/view.h"
#include "drift_test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define W 64
#define H 48

typedef struct rig {
    drift_context *ctx;
    drift_scene *scene;
    drift_accel *accel;
    drift_view *view;
} rig;

// A floor, a box standing on it and a quad light above, seen from the front and above.
static void build_scene(drift_scene *scene)
{
    uint32_t grey, red;
    assert_int_equal(
        drift_scene_add_material(scene,
                                 &(drift_material){ .diffuse = { 0.7f, 0.7f, 0.7f },
                                                    .diffuse_texture = DRIFT_INVALID_INDEX },
                                 &grey),
        DRIFT_OK);
    assert_int_equal(
        drift_scene_add_material(scene,
                                 &(drift_material){ .diffuse = { 0.6f, 0.2f, 0.2f },
                                                    .specular = { 0.2f, 0.2f, 0.2f },
                                                    .exponent = 50.0f,
                                                    .diffuse_texture = DRIFT_INVALID_INDEX },
                                 &red),
        DRIFT_OK);
    const float floor_p[] = { -2, 0, -2, 2, 0, -2, 2, 0, 2, -2, 0, 2 };
    const uint32_t floor_i[] = { 0, 2, 1, 0, 3, 2 }; // normal +y
    test_add_mesh(scene, floor_p, 4, floor_i, 2, grey);
    // A box [-0.3, 0.3] x [0, 0.6] x [-0.3, 0.3], faces outward.
    const float a = 0.3f, h = 0.6f;
    const float box_p[] = { -a, 0, -a, a, 0, -a, a, h, -a, -a, h, -a,
                            -a, 0, a,  a, 0, a,  a, h, a,  -a, h, a };
    const uint32_t box_i[] = { 0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                               3, 6, 2, 3, 7, 6, 0, 4, 7, 0, 7, 3, 1, 2, 6, 1, 6, 5 };
    test_add_mesh(scene, box_p, 8, box_i, 12, red);
    // Quad light at y = 1.5 emitting down: cross(u, v) = -y.
    assert_int_equal(drift_scene_add_light(scene,
                                           &(drift_light){ .type = DRIFT_LIGHT_QUAD,
                                                           .color = { 8.0f, 8.0f, 8.0f },
                                                           .position = { -0.25f, 1.5f, -0.25f },
                                                           .edge_u = { 0.5f, 0.0f, 0.0f },
                                                           .edge_v = { 0.0f, 0.0f, 0.5f } },
                                           NULL),
                     DRIFT_OK);
    scene->camera =
        drift_camera_look_at(drift_vec3_make(0.0f, 1.2f, 2.5f), drift_vec3_make(0.0f, 0.2f, 0.0f),
                             drift_vec3_make(0.0f, 1.0f, 0.0f), 0.9f, W, H);
}

static drift_hybrid_params cheap_params(void)
{
    // Small maps and one sample for `reference` techniques keep every frame fast under ASan.
    return (drift_hybrid_params){ .spp = 1, .shadow_map.size = 64, .envmap.size = 16 };
}

static rig rig_make(const drift_view_desc *desc)
{
    rig r = { .ctx = test_context(2, NULL) };
    assert_int_equal(drift_scene_create(r.ctx, &r.scene), DRIFT_OK);
    build_scene(r.scene);
    assert_int_equal(drift_scene_commit(r.scene), DRIFT_OK);
    assert_int_equal(drift_accel_create(r.ctx, r.scene, &(drift_accel_desc){ 0 }, &r.accel),
                     DRIFT_OK);
    assert_int_equal(drift_view_create(r.ctx, r.scene, r.accel, desc, &r.view), DRIFT_OK);
    drift_view_state s = drift_view_get_state(r.view);
    assert_int_equal(s.width, W);
    assert_int_equal(s.height, H);
    return r;
}

static void rig_destroy(rig *r)
{
    drift_view_destroy(r->view);
    drift_accel_destroy(r->accel);
    drift_scene_destroy(r->scene);
    drift_context_destroy(r->ctx);
}

static void frame(rig *r)
{
    assert_int_equal(drift_view_frame(r->view, NULL), DRIFT_OK);
}

static bool key(rig *r, drift_view_key k)
{
    return drift_view_handle_event(r->view,
                                   &(drift_view_event){ .type = DRIFT_VIEW_EVENT_KEY, .key = k });
}

static double mean_byte(const uint8_t *p, size_t count)
{
    double sum = 0.0;
    for (size_t i = 0; i < count; ++i) {
        sum += p[i];
    }
    return sum / (double)count;
}

static uint8_t *copy_pixels(const rig *r)
{
    uint8_t *copy = malloc(W * H * 3);
    assert_non_null(copy);
    memcpy(copy, drift_view_pixels(r->view), W * H * 3);
    return copy;
}

static int count_differing(const uint8_t *a, const uint8_t *b)
{
    int n = 0;
    for (int i = 0; i < W * H * 3; ++i) {
        n += a[i] != b[i];
    }
    return n;
}

// The byte drift_image_tonemap would write for one channel of one pixel.
static uint8_t tonemapped(const drift_image *img, int x, int y, int c, float exposure)
{
    drift_tonemap_params t = { .exposure_stops = exposure };
    return (uint8_t)lrintf(drift_tonemap_value(drift_image_pixel(img, x, y)[c], &t) * 255.0f);
}

// --- TESTS ---

static void test_view_framebuffer_shows_the_scene(void **state)
{
    (void)state;
    rig r = rig_make(&(drift_view_desc){ .hybrid = cheap_params(), .hide_overlay = true });
    frame(&r);
    const uint8_t *p = drift_view_pixels(r.view);
    int dark = 0, bright = 0;
    for (int i = 0; i < W * H; ++i) {
        int luma = p[3 * i] + p[3 * i + 1] + p[3 * i + 2];
        dark += luma < 30;
        bright += luma > 150;
    }
    if (dark < W * H / 20 || bright < W * H / 20) {
        fail_msg("framebuffer looks blank or flat: %d dark and %d bright pixels of %d", dark,
                 bright, W * H);
    }
    // With the overlay and split off, the framebuffer is the hybrid frame tone-mapped.
    const drift_image *img = drift_hybrid_image(drift_view_hybrid(r.view));
    for (int y = 0; y < H; ++y) {
        for (int x = 0; x < W; ++x) {
            for (int c = 0; c < 3; ++c) {
                assert_int_equal(p[(y * W + x) * 3 + c], tonemapped(img, x, y, c, 0.0f));
            }
        }
    }
    // The overlay draws text on a dark box from the top left.
    uint8_t *plain = copy_pixels(&r);
    assert_true(key(&r, DRIFT_VIEW_KEY_OVERLAY));
    assert_true(drift_view_get_state(r.view).overlay);
    frame(&r);
    p = drift_view_pixels(r.view);
    int changed = count_differing(plain, p);
    assert_true(changed > 50);
    assert_true(p[0] < plain[0] || plain[0] == 0); // darkened under the box
    free(plain);
    rig_destroy(&r);
}

// The overlay shows the frame's counts beside its pass table: every count the frame reports
// (drift_hybrid_stats_count) with its value, every stage that ran, and the first count on
// the line of the first stage.
static void test_view_overlay_shows_the_frames_counts(void **state)
{
    (void)state;
    drift_hybrid_params p = cheap_params();
    p.shadows = DRIFT_SHADOWS_PCSS;
    p.occlusion = DRIFT_OCCLUSION_SSDO;
    rig r = rig_make(&(drift_view_desc){ .hybrid = p });
    frame(&r);
    char text[DRIFT_VIEW_OVERLAY_TEXT_MAX];
    size_t len = drift_view_overlay_text(r.view, text, sizeof text);
    assert_true(len > 0 && len < sizeof text);
    drift_hybrid_stats stats = drift_hybrid_get_stats(drift_view_hybrid(r.view));
    const char *name;
    double value;
    uint32_t counts = 0;
    for (; drift_hybrid_stats_count(&stats, counts, &name, &value); ++counts) {
        char cell[160];
        snprintf(cell, sizeof cell, "%s\t%.6g", name, value);
        if (!strstr(text, cell)) {
            fail_msg("the overlay leaves out the count '%s' (%g):\n%s", name, value, text);
        }
    }
    assert_true(counts >= 4); // shadow maps, SSDO's samples, ...
    const char *first_stage = NULL;
    for (uint32_t k = 0; drift_hybrid_stats_stage(&stats, k, &name, &value); ++k) {
        char cell[80];
        snprintf(cell, sizeof cell, "%s\t", name);
        if (value > 0.0 && !strstr(text, cell)) {
            fail_msg("the overlay leaves out the stage '%s':\n%s", name, text);
        }
        first_stage = first_stage || !(value > 0.0) ? first_stage : name;
    }
    assert_non_null(first_stage);
    const char *line = strstr(text, first_stage);
    const char *end = strchr(line, '\n');
    assert_true(drift_hybrid_stats_count(&stats, 0, &name, &value));
    const char *beside = strstr(line, name);
    assert_true(beside && (!end || beside < end));
    rig_destroy(&r);
}

static void test_view_technique_keys_cycle(void **state)
{
    (void)state;
    rig r = rig_make(&(drift_view_desc){ .hybrid = cheap_params() });
    frame(&r);
    for (int e = 0; e < DRIFT_EFFECT_COUNT; ++e) {
        drift_view_key effect_key = drift_view_key_of_effect((drift_effect)e);
        assert_int_equal(drift_view_key_effect(effect_key), e);
        assert_string_equal(drift_view_key_name(effect_key), drift_effect_name((drift_effect)e));
        int count = drift_technique_count((drift_effect)e);
        assert_true(count >= 2);
        for (int press = 1; press <= count; ++press) {
            assert_true(key(&r, effect_key));
            frame(&r);
            drift_hybrid_params p = drift_hybrid_get_params(drift_view_hybrid(r.view));
            int got = drift_hybrid_params_technique(&p, (drift_effect)e);
            // Every technique starts at 0 (the default), so after `press` presses it is
            // press mod count: all of them once, then back to the first.
            if (got != press % count) {
                fail_msg("%s after %d presses: technique %d, expected %d",
                         drift_effect_name((drift_effect)e), press, got, press % count);
            }
            drift_view_state s = drift_view_get_state(r.view);
            assert_int_equal(s.params.shadows, p.shadows);
            assert_int_equal(s.params.dof, p.dof);
        }
    }
    rig_destroy(&r);
}

static void test_view_buffer_keys_visit_every_plane(void **state)
{
    (void)state;
    drift_hybrid_params params = cheap_params();
    params.shadows = DRIFT_SHADOWS_PCSS;
    params.reflections = DRIFT_REFLECTIONS_SHARP;
    params.dof = DRIFT_DOF_POST;
    params.indirect = DRIFT_INDIRECT_AMBIENT;
    rig r = rig_make(&(drift_view_desc){ .hybrid = params, .hide_overlay = true });
    frame(&r);
    const drift_hybrid *hybrid = drift_view_hybrid(r.view);
    const char *names[256];
    const drift_image *planes[256];
    uint32_t count = 0;
    while (count < 256 && drift_hybrid_plane(hybrid, count, &names[count], &planes[count])) {
        ++count;
    }
    assert_true(count >= 5); // at least the G-buffer's planes
    assert_string_equal(drift_view_get_state(r.view).buffer_name, "frame");
    uint8_t *frame_pixels = copy_pixels(&r);
    bool saw_depth = false;
    for (uint32_t i = 1; i <= count; ++i) {
        assert_true(key(&r, DRIFT_VIEW_KEY_NEXT_BUFFER));
        drift_view_state s = drift_view_get_state(r.view);
        assert_int_equal(s.buffer, i);
        assert_string_equal(s.buffer_name, names[i - 1]);
        frame(&r);
        s = drift_view_get_state(r.view);
        assert_string_equal(s.buffer_name, names[i - 1]); // still there after the frame
        const uint8_t *p = drift_view_pixels(r.view);
        if (strcmp(names[i - 1], "depth") == 0) {
            // Depth is grey, normalized, and not constant.
            saw_depth = true;
            int varied = 0;
            for (int k = 0; k < W * H; ++k) {
                assert_int_equal(p[3 * k], p[3 * k + 1]);
                assert_int_equal(p[3 * k], p[3 * k + 2]);
                varied += p[3 * k] != p[0];
            }
            assert_true(varied > W * H / 10);
        }
        if (strcmp(names[i - 1], "normal") == 0) {
            // The floor faces +y: 0.5 + 0.5 n = (0.5, 1, 0.5) at the bottom row's centre.
            const uint8_t *q = p + ((H - 1) * W + W / 2) * 3;
            assert_in_range(q[0], 120, 135);
            assert_in_range(q[1], 250, 255);
            assert_in_range(q[2], 120, 135);
        }
    }
    assert_true(saw_depth);
    // One more press wraps around to the composed frame.
    assert_true(key(&r, DRIFT_VIEW_KEY_NEXT_BUFFER));
    assert_string_equal(drift_view_get_state(r.view).buffer_name, "frame");
    assert_int_equal(drift_view_get_state(r.view).buffer, 0);
    frame(&r);
    assert_memory_equal(frame_pixels, drift_view_pixels(r.view), W * H * 3);
    // Backwards from the frame is the last plane.
    assert_true(key(&r, DRIFT_VIEW_KEY_PREV_BUFFER));
    assert_string_equal(drift_view_get_state(r.view).buffer_name, names[count - 1]);
    free(frame_pixels);
    rig_destroy(&r);
}

static void test_view_reference_restarts_when_the_camera_moves(void **state)
{
    (void)state;
    rig r = rig_make(&(drift_view_desc){
        .hybrid = cheap_params(), .spp_per_frame = 2, .split = true, .hide_overlay = true });
    assert_null(drift_view_reference(r.view));
    // Still camera: the reference grows frame by frame.
    for (uint32_t i = 1; i <= 3; ++i) {
        frame(&r);
        assert_int_equal(drift_view_get_state(r.view).reference_spp, 2 * i);
    }
    uint8_t *before = copy_pixels(&r);
    drift_camera cam0 = drift_view_get_state(r.view).camera;

    // Fly forward: the camera and target move together, the reference starts over.
    assert_true(key(&r, DRIFT_VIEW_KEY_FORWARD));
    frame(&r);
    drift_view_state s = drift_view_get_state(r.view);
    assert_int_equal(s.reference_spp, 2);
    assert_true(count_differing(before, drift_view_pixels(r.view)) > W * H / 10);
    drift_vec3 moved = drift_vec3_sub(s.camera.position, cam0.position);
    drift_vec3 moved_target = drift_vec3_sub(s.camera.target, cam0.target);
    assert_true(drift_vec3_length(moved) > 0.0f);
    assert_near(drift_vec3_length(drift_vec3_sub(moved, moved_target)), 0.0, 1e-5);
    frame(&r);
    assert_int_equal(drift_view_get_state(r.view).reference_spp, 4);

    // Orbit: same distance to the target, same up; the reference restarts again.
    float d0 = drift_vec3_length(drift_vec3_sub(s.camera.target, s.camera.position));
    assert_true(drift_view_handle_event(
        r.view, &(drift_view_event){ .type = DRIFT_VIEW_EVENT_ORBIT, .dx = 40.0f, .dy = 10.0f }));
    frame(&r);
    s = drift_view_get_state(r.view);
    assert_int_equal(s.reference_spp, 2);
    assert_near(drift_vec3_length(drift_vec3_sub(s.camera.target, s.camera.position)), d0,
                1e-4 * (double)d0);
    assert_near(s.camera.up.y, cam0.up.y, 0.0);

    // Dolly in: closer to the same target.
    assert_true(drift_view_handle_event(
        r.view, &(drift_view_event){ .type = DRIFT_VIEW_EVENT_DOLLY, .dy = 2.0f }));
    drift_view_state s2 = drift_view_get_state(r.view);
    assert_true(drift_vec3_length(drift_vec3_sub(s2.camera.target, s2.camera.position)) < d0);

    // Reset, then turn around (yaw pi about the position): the scene is behind the camera, so
    // the reference, which follows the view's camera, sees (almost) nothing.
    assert_true(key(&r, DRIFT_VIEW_KEY_RESET_CAMERA));
    frame(&r);
    drift_image ref;
    assert_int_equal(drift_pt_resolve(drift_view_reference(r.view), DRIFT_PT_AOV_BEAUTY, &ref),
                     DRIFT_OK);
    double lit = 0.0;
    for (int y = 0; y < H; ++y) {
        for (int x = 0; x < W; ++x) {
            lit += (double)drift_image_pixel(&ref, x, y)[1];
        }
    }
    assert_true(drift_view_handle_event(
        r.view, &(drift_view_event){ .type = DRIFT_VIEW_EVENT_LOOK, .dx = 3.14159265f / 0.005f }));
    frame(&r);
    assert_int_equal(drift_pt_resolve(drift_view_reference(r.view), DRIFT_PT_AOV_BEAUTY, &ref),
                     DRIFT_OK);
    double away = 0.0;
    for (int y = 0; y < H; ++y) {
        for (int x = 0; x < W; ++x) {
            away += (double)drift_image_pixel(&ref, x, y)[1];
        }
    }
    if (!(lit > 0.0) || away > 0.05 * lit) {
        fail_msg("reference does not follow the camera: %.3f facing the scene, %.3f facing away",
                 lit, away);
    }
    free(before);
    rig_destroy(&r);
}

static void test_view_split_shows_the_reference_right_of_the_line(void **state)
{
    (void)state;
    rig r = rig_make(&(drift_view_desc){ .hybrid = cheap_params(), .hide_overlay = true });
    frame(&r);
    assert_int_equal(drift_view_get_state(r.view).reference_spp, 0); // split off: no reference
    assert_true(key(&r, DRIFT_VIEW_KEY_SPLIT));
    frame(&r);
    frame(&r);
    drift_view_state s = drift_view_get_state(r.view);
    assert_true(s.split);
    assert_int_equal(s.split_x, W / 2);
    assert_int_equal(s.reference_spp, 2);

    drift_image ref;
    assert_int_equal(drift_pt_resolve(drift_view_reference(r.view), DRIFT_PT_AOV_BEAUTY, &ref),
                     DRIFT_OK);
    const drift_image *hybrid = drift_hybrid_image(drift_view_hybrid(r.view));
    const uint8_t *p = drift_view_pixels(r.view);
    for (int y = 0; y < H; ++y) {
        for (int x = 0; x < W; ++x) {
            // Column split_x - 1 carries the split line.
            if (x == s.split_x - 1) {
                continue;
            }
            const drift_image *img = x >= s.split_x ? &ref : hybrid;
            for (int c = 0; c < 3; ++c) {
                if (p[(y * W + x) * 3 + c] != tonemapped(img, x, y, c, 0.0f)) {
                    fail_msg("pixel (%d, %d) channel %d: %u, expected the %s's %u", x, y, c,
                             p[(y * W + x) * 3 + c], x >= s.split_x ? "reference" : "hybrid",
                             tonemapped(img, x, y, c, 0.0f));
                }
            }
        }
    }

    // The split moves by keys and by a click; exposure brightens both sides.
    assert_true(key(&r, DRIFT_VIEW_KEY_SPLIT_RIGHT));
    assert_int_equal(drift_view_get_state(r.view).split_x, W / 2 + W / 16);
    assert_true(drift_view_handle_event(
        r.view, &(drift_view_event){ .type = DRIFT_VIEW_EVENT_SPLIT_AT, .x = 16.0f }));
    assert_int_equal(drift_view_get_state(r.view).split_x, 16);
    frame(&r);
    double mean0 = mean_byte(drift_view_pixels(r.view), W * H * 3);
    assert_true(key(&r, DRIFT_VIEW_KEY_EXPOSURE_UP));
    assert_near(drift_view_get_state(r.view).exposure_stops, 0.5, 1e-6);
    frame(&r);
    assert_true(mean_byte(drift_view_pixels(r.view), W * H * 3) > mean0 + 1.0);

    // Split off again: the reference keeps what it has but gets no more samples.
    assert_true(key(&r, DRIFT_VIEW_KEY_SPLIT));
    uint32_t spp = drift_view_get_state(r.view).reference_spp;
    frame(&r);
    assert_int_equal(drift_view_get_state(r.view).reference_spp, spp);
    rig_destroy(&r);
}

static void test_view_rejects_bad_input(void **state)
{
    (void)state;
    drift_context *ctx = test_context(1, NULL);
    drift_scene *scene = NULL;
    assert_int_equal(drift_scene_create(ctx, &scene), DRIFT_OK);
    build_scene(scene);
    drift_view *view = (drift_view *)(uintptr_t)1; // must be reset to NULL
    // Not committed.
    assert_int_equal(drift_view_create(ctx, scene, NULL, NULL, &view), DRIFT_ERR_INVALID_ARGUMENT);
    assert_null(view);
    assert_string_equal(drift_view_key_name(DRIFT_VIEW_KEY_SHADOWS), "shadows");
    assert_null(drift_view_key_name(DRIFT_VIEW_KEY_COUNT));
    assert_string_equal(drift_view_key_name(DRIFT_VIEW_KEY_NEXT_BUFFER), "next-buffer");
    assert_string_equal(drift_view_key_name(DRIFT_VIEW_KEY_HELP), "help");
    assert_int_equal(drift_view_key_effect(DRIFT_VIEW_KEY_HELP), -1);
    drift_view_destroy(NULL);
    assert_false(drift_view_handle_event(NULL, NULL));
    drift_scene_destroy(scene);
    drift_context_destroy(ctx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_view_framebuffer_shows_the_scene),
        cmocka_unit_test(test_view_overlay_shows_the_frames_counts),
        cmocka_unit_test(test_view_technique_keys_cycle),
        cmocka_unit_test(test_view_buffer_keys_visit_every_plane),
        cmocka_unit_test(test_view_reference_restarts_when_the_camera_moves),
        cmocka_unit_test(test_view_split_shows_the_reference_right_of_the_line),
        cmocka_unit_test(test_view_rejects_bad_input),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
