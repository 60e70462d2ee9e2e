// test_ssdo, part: depth peeling, additional cameras and contact shadows (the test list is in
// tests/unit/test_ssdo.c).
#include "ssdo_tests.h"

// --- DEPTH PEELING ---

// Spec §2.5 test 5: a thin slab in front of a far wall. With one layer every sample in the gap
// behind the slab reads as inside it (the thesis's "sample A") and darkens the wall around the
// slab's silhouette; with the second layer from drift_ssdo_peel the gap is open again.
void test_second_layer_opens_the_gap_behind_a_slab(void **state)
{
    (void)state;
    ssdo_case c = { .rig = test_rig_begin(2) };
    uint32_t grey = test_add_material(c.rig.scene, drift_material_make(drift_vec3_splat(0.5f)));
    test_add_quad(c.rig.scene, drift_vec3_make(-8, -8, 2), drift_vec3_make(0, 16, 0),
                  drift_vec3_make(16, 0, 0), grey);
    add_box(c.rig.scene, -1.0f, 1.0f, 1.0f, 0.1f, grey);
    c.rig.scene->environment.color = drift_vec3_splat(1.0f);
    c.rig.scene->camera =
        drift_camera_look_at(drift_vec3_make(0, 0.5f, -6), drift_vec3_make(0, 0.5f, 0),
                             drift_vec3_make(0, 1, 0), 0.6f, 48, 48);
    case_begin(&c);
    const drift_gbuffer *g = drift_hybrid_gbuffer(c.rig.frame);
    drift_image back;
    assert_int_equal(drift_image_create(c.rig.ctx, 48, 48, 1, &back), DRIFT_OK);
    assert_int_equal(drift_ssdo_peel(c.rig.ctx, c.rig.accel, g, &c.rig.scene->camera, &back),
                     DRIFT_OK);
    assert_near(pixel(&back, 24, 24)[0], 6.1, 1e-3); // the slab's back face (camera z = -6)
    assert_true(pixel(&back, 2, 2)[0] == 0.0f);      // nothing behind the wall
    drift_ssdo_params p = { .method = DRIFT_SSDO_METHOD_SSAO,
                            .samples = 32,
                            .radius = 2.5f,
                            .no_fade = true,
                            .no_blur = true };
    drift_image one;
    assert_int_equal(drift_image_create(c.rig.ctx, 48, 48, 1, &one), DRIFT_OK);
    case_render(&c, &p);
    memcpy(one.pixels, c.out.visibility.pixels, sizeof(float) * 48 * 48);
    drift_ssdo_inputs in = { .gbuffer = g, .camera = &c.rig.scene->camera, .back_depth = &back };
    assert_int_equal(drift_ssdo_render(c.rig.ctx, c.env, &in, &p, &c.out), DRIFT_OK);
    double sum_one = 0.0, sum_two = 0.0;
    int count = 0;
    for (int32_t y = 3; y < 45; ++y) {
        for (int32_t x = 3; x < 45; ++x) {
            bool wall = pixel(&g->position, x, y)[2] > 1.9f;
            bool near_slab = pixel(&g->position, x - 3, y)[2] < 0.0f ||
                             pixel(&g->position, x + 3, y)[2] < 0.0f ||
                             pixel(&g->position, x, y - 3)[2] < 0.0f ||
                             pixel(&g->position, x, y + 3)[2] < 0.0f;
            if (wall && near_slab) {
                sum_one += (double)pixel(&one, x, y)[0];
                sum_two += (double)pixel(&c.out.visibility, x, y)[0];
                assert_true(pixel(&c.out.visibility, x, y)[0] >= pixel(&one, x, y)[0]);
                ++count;
            }
        }
    }
    assert_true(count > 20);
    print_message("wall beside the slab: visibility %.3f with one layer, %.3f with two\n",
                  sum_one / count, sum_two / count);
    assert_true(sum_one / count < 0.85);
    assert_true(sum_two / count > 0.97);
    drift_image_destroy(c.rig.ctx, &one);
    drift_image_destroy(c.rig.ctx, &back);
    case_end(&c);
}

// --- ADDITIONAL CAMERAS ---

// Thesis §4.3.3: a wall just outside the image on the right (x 1.1..1.3, seen from above, the
// image covers x -1..1) darkens the floor at the border only when an additional camera sees
// it; floor pixels whose samples stay on screen are unchanged, and without the wall the extra
// cameras invent no occluder.
void test_additional_cameras_find_an_off_screen_blocker(void **state)
{
    (void)state;
    for (int wall = 0; wall < 2; ++wall) {
        ssdo_case c = { .rig = test_rig_begin(2) };
        uint32_t grey = test_add_material(c.rig.scene, drift_material_make(drift_vec3_splat(0.5f)));
        test_add_floor(c.rig.scene, 20.0f, 0.0f, grey);
        if (wall) {
            add_box(c.rig.scene, 1.1f, 1.3f, 1.0f, 3.0f, grey);
        }
        c.rig.scene->environment.color = drift_vec3_splat(1.0f);
        look_down(c.rig.scene, 8.0f, 1.0f, 48);
        case_begin(&c);
        const drift_gbuffer *g = drift_hybrid_gbuffer(c.rig.frame);
        drift_ssdo_params p = { .method = DRIFT_SSDO_METHOD_SSAO,
                                .samples = 32,
                                .radius = 0.5f,
                                .no_fade = true,
                                .no_blur = true };
        case_render(&c, &p);
        static float one[48 * 48];
        for (int32_t i = 0; i < 48 * 48; ++i) {
            one[i] = pixel(&c.out.visibility, i % 48, i / 48)[0];
        }
        for (int32_t count = 1; count <= DRIFT_SSDO_MAX_VIEWS; count += 4) {
            drift_ssdo_view views[DRIFT_SSDO_MAX_VIEWS];
            assert_int_equal(drift_ssdo_views_render(c.rig.ctx, c.rig.scene, c.rig.accel,
                                                     &c.rig.scene->camera, count, 24, 24, views),
                             DRIFT_OK);
            drift_ssdo_inputs in = {
                .gbuffer = g, .camera = &c.rig.scene->camera, .views = views, .view_count = count
            };
            assert_int_equal(drift_ssdo_render(c.rig.ctx, c.env, &in, &p, &c.out), DRIFT_OK);
            double border_one = 0.0, border_views = 0.0;
            int n = 0;
            for (int32_t y = 0; y < 48; ++y) {
                for (int32_t x = 0; x < 48; ++x) {
                    float px = pixel(&g->position, x, y)[0];
                    float v = pixel(&c.out.visibility, x, y)[0];
                    if (px < 0.4f && fabsf(pixel(&g->position, x, y)[2]) < 0.4f) {
                        assert_true(v == one[y * 48 + x]); // its samples stay on screen
                    } else if (px > 0.85f && fabsf(pixel(&g->position, x, y)[2]) < 0.5f) {
                        border_one += (double)one[y * 48 + x];
                        border_views += (double)v;
                        ++n;
                    }
                }
            }
            border_one /= n;
            border_views /= n;
            print_message("wall %d, %d cameras: border visibility %.3f, %.3f with the cameras\n",
                          wall, count, border_one, border_views);
            assert_true(border_one > 0.99);
            if (wall) {
                assert_true(border_views < 0.95);
            } else {
                assert_true(border_views > 0.99);
            }
            drift_ssdo_views_destroy(c.rig.ctx, views, count);
        }
        case_end(&c);
    }
}

// --- CONTACT SHADOWS ---

// Spec §2.5 test 7, the screen-space half: a small box on a floor, a directional light 10
// degrees above the horizon. Marching b = 0.2 toward the light marks the floor within b of the
// box's lit-away side as shadowed and leaves the floor further out and the box's top lit.
void test_contact_shadows_within_the_bias(void **state)
{
    (void)state;
    ssdo_case c = { .rig = test_rig_begin(2) };
    uint32_t grey = test_add_material(c.rig.scene, drift_material_make(drift_vec3_splat(0.5f)));
    test_add_floor(c.rig.scene, 20.0f, 0.0f, grey);
    add_box(c.rig.scene, 0.0f, 0.5f, 0.5f, 0.25f, grey);
    c.rig.scene->environment.color = drift_vec3_splat(1.0f);
    look_down(c.rig.scene, 8.0f, 1.0f, 64);
    case_begin(&c);
    const drift_gbuffer *g = drift_hybrid_gbuffer(c.rig.frame);
    drift_image visible;
    assert_int_equal(drift_image_create(c.rig.ctx, 64, 64, 1, &visible), DRIFT_OK);
    drift_vec3 travel = drift_vec3_make(-cosf(0.1745f), -sinf(0.1745f), 0.0f);
    drift_ssdo_inputs in = { .gbuffer = g, .camera = &c.rig.scene->camera };
    assert_int_equal(drift_ssdo_contact_shadows(c.rig.ctx, &in, travel, true, 0.2f, 8, &visible),
                     DRIFT_OK);
    int shadowed = 0, lit = 0;
    for (int32_t y = 0; y < 64; ++y) {
        for (int32_t x = 0; x < 64; ++x) {
            const float *q = pixel(&g->position, x, y);
            float v = pixel(&visible, x, y)[0];
            if (q[1] > 0.49f) {
                assert_true(v == 1.0f); // the box's top sees the light
            } else if (q[0] > -0.15f && q[0] < -0.03f && fabsf(q[2]) < 0.2f) {
                assert_true(v == 0.0f); // within b of the contact line
                ++shadowed;
            } else if (q[0] < -0.3f || q[0] > 0.6f) {
                assert_true(v == 1.0f);
                ++lit;
            }
        }
    }
    assert_true(shadowed > 10 && lit > 100);
    assert_int_equal(drift_ssdo_contact_shadows(c.rig.ctx, &in, travel, true, 0.0f, 8, &visible),
                     DRIFT_ERR_INVALID_ARGUMENT);
    drift_image_destroy(c.rig.ctx, &visible);
    case_end(&c);
}

// Spec §2.5 test 7 against the frame: a small box (0.1 thick, 0.5 high) on a floor lit by a
// point light 10 degrees above the horizon, its shadow map coarse and biased (b about 0.37).
// The ray-traced hard shadow is the truth. Without the fix the map's bias erases the contact
// shadow: the floor within 0.1 of the box's far side, truly shadowed, is lit. With
// --contact-shadows every such pixel is shadowed again, and (almost) no truly lit pixel is
// darkened.
void test_contact_shadows_fix_the_frames_shadow_map(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    uint32_t grey = test_add_material(r.scene, drift_material_make(drift_vec3_splat(0.5f)));
    test_add_floor(r.scene, 20.0f, 0.0f, grey);
    add_box(r.scene, -0.05f, 0.05f, 0.5f, 0.25f, grey);
    drift_vec3 light = drift_vec3_make(-6.0f * cosf(0.1745f), 6.0f * sinf(0.1745f), 0.0f);
    assert_int_equal(drift_scene_add_light(r.scene,
                                           &(drift_light){ .type = DRIFT_LIGHT_POINT,
                                                           .color = drift_vec3_splat(30.0f),
                                                           .position = light },
                                           NULL),
                     DRIFT_OK);
    look_down(r.scene, 6.0f, 1.0f, 64);
    test_rig_commit(&r);

    enum {
        N = 64 * 64
    };

    static float truth[N], biased[N], fixed[N];
    float *out[3] = { truth, biased, fixed };
    for (int run = 0; run < 3; ++run) {
        drift_hybrid_params p = { .shadows = run == 0 ? DRIFT_SHADOWS_HARD : DRIFT_SHADOWS_PCF,
                                  .shadow_map = { .size = 128,
                                                  .bias = 3.0f,
                                                  .pcf_kernel = 1,
                                                  .contact_shadows = run == 2,
                                                  .contact_samples = 16 } };
        test_rig_frame(&r, &p);
        const drift_image *s = test_rig_plane(&r, "light0.shadow");
        for (int32_t i = 0; i < N; ++i) {
            out[run][i] = pixel(s, i % 64, i / 64)[0];
        }
    }
    const drift_gbuffer *g = drift_hybrid_gbuffer(r.frame);
    int contact = 0, lit = 0, darkened = 0;
    for (int32_t i = 0; i < N; ++i) {
        const float *q = pixel(&g->position, i % 64, i / 64);
        bool floor = q[1] < 1e-3f;
        if (floor && truth[i] == 0.0f && q[0] > 0.06f && q[0] < 0.15f && fabsf(q[2]) < 0.2f) {
            assert_true(biased[i] == 1.0f); // the bias erased it
            assert_true(fixed[i] == 0.0f);  // the march restores it
            ++contact;
        }
        if (truth[i] == 1.0f && biased[i] == 1.0f) {
            ++lit;
            darkened += fixed[i] == 0.0f;
        }
    }
    print_message("contact pixels %d; truly lit %d, of them darkened by the fix %d\n", contact, lit,
                  darkened);
    assert_true(contact >= 6);
    assert_true(darkened * 100 <= lit);
    // The frame reports what the fix did (the ssdo family's counts): the pixels it turned to
    // shadow, exactly those counted here, out of the pixels the map let through.
    double through = 0.0, turned = 0.0, counted[2] = { NAN, NAN };
    for (int32_t i = 0; i < N; ++i) {
        through += biased[i] > 0.0f;
        turned += biased[i] > 0.0f && fixed[i] == 0.0f;
    }
    drift_hybrid_stats stats = drift_hybrid_get_stats(r.frame);
    const char *name;
    double value;
    for (uint32_t k = 0; drift_hybrid_stats_count(&stats, k, &name, &value); ++k) {
        counted[0] = strcmp(name, "ssdo.contact_shadows.shadowed_pixels") == 0 ? value : counted[0];
        counted[1] = strcmp(name, "ssdo.contact_shadows.lit_pixels") == 0 ? value : counted[1];
    }
    if (!(counted[0] == turned && turned >= contact && counted[1] > 0.0 && counted[1] <= through)) {
        fail_msg("contact shadows report %g shadowed of %g marched; %g turned, %g let through",
                 counted[0], counted[1], turned, through);
    }
    test_rig_destroy(&r);
}
