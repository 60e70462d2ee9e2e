// Tests of src/ssdo: SSAO, GTAO and SSDO with its bounce (thesis spec §2.5, docs/ssdo.md).
// Scenes are small and seen from straight above, where one depth layer sees everything the
// sample points can reach.
// ctest-labels: quality
#include "drift/ssdo.h"
#include "drift_test.h"
#include "ssdo/ssdo_tests.h"
#include "test_rig.h"

#include <math.h>
#include <string.h>

// --- HELPERS ---

// Commits the rig's scene, renders its G-buffer and pre-filters its environment.
void case_begin(ssdo_case *c)
{
    test_rig_commit(&c->rig);
    test_rig_frame(&c->rig, &(drift_hybrid_params){ 0 });
    assert_int_equal(
        drift_ssdo_env_create(c->rig.ctx, c->rig.scene,
                              &(drift_ssdo_env_desc){ .width = 32, .source_width = 64 }, &c->env),
        DRIFT_OK);
    const drift_gbuffer *g = drift_hybrid_gbuffer(c->rig.frame);
    assert_int_equal(drift_ssdo_output_create(c->rig.ctx, g->width, g->height, &c->out), DRIFT_OK);
}

static void case_render_gbuffer(ssdo_case *c, const drift_gbuffer *g, const drift_ssdo_params *p,
                                const drift_image *extra)
{
    drift_ssdo_inputs in = { .gbuffer = g,
                             .camera = &c->rig.scene->camera,
                             .sender_radiance = extra };
    assert_int_equal(drift_ssdo_render(c->rig.ctx, c->env, &in, p, &c->out), DRIFT_OK);
}

void case_render(ssdo_case *c, const drift_ssdo_params *p)
{
    case_render_gbuffer(c, drift_hybrid_gbuffer(c->rig.frame), p, NULL);
}

void case_end(ssdo_case *c)
{
    drift_ssdo_output_destroy(c->rig.ctx, &c->out);
    drift_ssdo_env_destroy(c->env);
    test_rig_destroy(&c->rig);
}

void look_down(drift_scene *scene, float height, float half_extent, int32_t size)
{
    scene->camera = drift_camera_look_at(drift_vec3_make(0.0f, height, 0.0f),
                                         drift_vec3_splat(0.0f), drift_vec3_make(0.0f, 0.0f, 1.0f),
                                         2.0f * atanf(half_extent / height), size, size);
}

// A box [x0, x1] x [0, h] x [-d, d] with outward-wound faces (the bottom left out).
void add_box(drift_scene *scene, float x0, float x1, float h, float d, uint32_t material)
{
    test_add_quad(scene, drift_vec3_make(x0, h, -d), drift_vec3_make(0, 0, 2 * d),
                  drift_vec3_make(x1 - x0, 0, 0), material); // top (+y)
    test_add_quad(scene, drift_vec3_make(x0, 0, -d), drift_vec3_make(0, 0, 2 * d),
                  drift_vec3_make(0, h, 0), material); // -x side
    test_add_quad(scene, drift_vec3_make(x1, 0, -d), drift_vec3_make(0, h, 0),
                  drift_vec3_make(0, 0, 2 * d), material); // +x side
    test_add_quad(scene, drift_vec3_make(x0, 0, -d), drift_vec3_make(0, h, 0),
                  drift_vec3_make(x1 - x0, 0, 0), material); // -z side
    test_add_quad(scene, drift_vec3_make(x0, 0, d), drift_vec3_make(x1 - x0, 0, 0),
                  drift_vec3_make(0, h, 0), material); // +z side
}

const float *pixel(const drift_image *image, int32_t x, int32_t y)
{
    return drift_image_pixel(image, x, y);
}

// --- WHITE FURNACE: AN UNOCCLUDED PLANE ---

// Spec §2.5 test 1: under a constant environment L an open plane gives V = 1, L_dir = rho L
// and no bounce, for every technique.
static void test_open_plane_gives_albedo_times_environment(void **state)
{
    (void)state;
    ssdo_case c = { .rig = test_rig_begin(2) };
    uint32_t grey = test_add_material(c.rig.scene, drift_material_make(drift_vec3_splat(0.5f)));
    test_add_floor(c.rig.scene, 50.0f, 0.0f, grey);
    c.rig.scene->environment.color = drift_vec3_splat(1.0f);
    look_down(c.rig.scene, 10.0f, 2.0f, 48);
    case_begin(&c);
    for (int t = 0; t < DRIFT_SSDO_METHOD_COUNT; ++t) {
        case_render(&c, &(drift_ssdo_params){ .method = (drift_ssdo_method)t,
                                              .samples = 64,
                                              .radius = 0.5f,
                                              .bounce = true });
        for (int32_t y = 0; y < 48; ++y) {
            for (int32_t x = 0; x < 48; ++x) {
                assert_near(pixel(&c.out.visibility, x, y)[0], 1.0, 0.02);
                for (int k = 0; k < 3; ++k) {
                    assert_near(pixel(&c.out.radiance, x, y)[k], 0.5, 0.01);
                    assert_true(pixel(&c.out.bounce, x, y)[k] == 0.0f);
                }
                assert_near(pixel(&c.out.bent_normal, x, y)[1], 1.0, 0.01);
            }
        }
    }
    case_end(&c);
}

// --- THE V-GROOVE: A CLOSED FORM ---

// The groove y = |x| tan(gamma) seen from above; at its crease, with the normal along the
// bisector, the cosine-weighted open fraction is cos(gamma) (the 2-D wedge of half-opening
// pi/2 - gamma: sin of it). GTAO's slice integral gives the same: each slice at angle phi to
// the cross-section sees horizons at elevation atan(|cos phi| tan gamma), and
// (1/pi) int cos^2(elevation) dphi = 1 / sqrt(1 + tan^2 gamma). SSAO's point test is exact
// here because the groove is star-shaped from the crease.
static void test_groove_crease_matches_closed_form(void **state)
{
    (void)state;
    const float gammas[] = { 0.5235988f, 0.7853982f, 1.0471976f };
    // Only the crease pixel is read: the view is cut to the 65 pixels around it, at the pixel
    // footprint of 129 pixels over [-1.5, 1.5] (the footprint sets the steep walls' error
    // below); it spans +-0.756, past the samples' radius 0.5.
    const int32_t size = 65, mid = size / 2;
    const float half_extent = 1.5f * (float)size / 129.0f;
    for (int g = 0; g < 3; ++g) {
        ssdo_case c = { .rig = test_rig_begin(2) };
        uint32_t grey = test_add_material(c.rig.scene, drift_material_make(drift_vec3_splat(0.5f)));
        float t = tanf(gammas[g]), w = 3.0f;
        test_add_quad(c.rig.scene, drift_vec3_make(0, 0, -w), drift_vec3_make(0, 0, 2 * w),
                      drift_vec3_make(w, w * t, 0), grey);
        test_add_quad(c.rig.scene, drift_vec3_make(0, 0, -w), drift_vec3_make(-w, w * t, 0),
                      drift_vec3_make(0, 0, 2 * w), grey);
        c.rig.scene->environment.color = drift_vec3_splat(1.0f);
        look_down(c.rig.scene, 40.0f, half_extent, size);
        case_begin(&c);
        // The crease pixel's normal is one wall's; give it the bisector (a copy of the plane).
        const drift_gbuffer *gb = drift_hybrid_gbuffer(c.rig.frame);
        drift_gbuffer crease = *gb;
        assert_int_equal(drift_image_create(c.rig.ctx, size, size, 3, &crease.normal), DRIFT_OK);
        memcpy(crease.normal.pixels, gb->normal.pixels, sizeof(float) * size * size * 3);
        drift_image_set3(&crease.normal, mid, mid, drift_vec3_make(0, 1, 0));
        assert_near(pixel(&gb->position, mid, mid)[0], 0.0, 1e-3);
        double expected = cos((double)gammas[g]);
        case_render_gbuffer(&c, &crease,
                            &(drift_ssdo_params){ .method = DRIFT_SSDO_METHOD_GTAO,
                                                  .samples = 2 * 32 * 8,
                                                  .gtao_slices = 32,
                                                  .radius = 0.5f,
                                                  .no_fade = true,
                                                  .no_blur = true },
                            NULL);
        assert_near(pixel(&c.out.visibility, mid, mid)[0], expected, 0.02 * expected);
        assert_near(pixel(&c.out.bent_normal, mid, mid)[1], 1.0, 1e-3);
        for (int t2 = 0; t2 < 2; ++t2) {
            drift_ssdo_method tech = t2 ? DRIFT_SSDO_METHOD_SSDO : DRIFT_SSDO_METHOD_SSAO;
            case_render_gbuffer(&c, &crease,
                                &(drift_ssdo_params){ .method = tech,
                                                      .samples = 256,
                                                      .radius = 0.5f,
                                                      .bias = 1e-4f,
                                                      .no_fade = true,
                                                      .no_blur = true },
                                NULL);
            // 5%: samples within a pixel footprint of the steep walls read as open (spec
            // §2.5 test 4a); at 60 degrees they lift the estimate by 4% (2.6% at N = 1024).
            assert_near(pixel(&c.out.visibility, mid, mid)[0], expected, 0.05 * expected);
            assert_near(pixel(&c.out.direct, mid, mid)[0], 0.5 * expected, 0.05 * expected);
        }
        drift_image_destroy(c.rig.ctx, &crease.normal);
        case_end(&c);
    }
}

// --- COLOURED DIRECTIONAL SHADOWS ---

// A lat-long environment, red toward +x and blue toward -x.
static void add_red_blue_environment(drift_scene *scene)
{
    drift_image env;
    assert_int_equal(drift_image_create(scene->ctx, 64, 32, 3, &env), DRIFT_OK);
    for (int32_t y = 0; y < 32; ++y) {
        for (int32_t x = 0; x < 64; ++x) {
            double phi = 2.0 * PI * (x + 0.5) / 64.0;
            bool plus_x = cos(phi) > 0.0; // dir.x = sin(theta) cos(phi)
            drift_image_set3(&env, x, y,
                             plus_x ? drift_vec3_make(1, 0, 0) : drift_vec3_make(0, 0, 1));
        }
    }
    uint32_t index;
    assert_int_equal(drift_scene_add_texture(scene, env, &index), DRIFT_OK);
    scene->environment = (drift_environment){ .color = drift_vec3_splat(1.0f), .texture = index };
}

// A floor with (box) a box on the +x side of the origin under the red/blue environment, seen
// from above or (side_view) from the -x side, where the box's -x face is on screen.
static void build_box_scene(ssdo_case *c, bool box, drift_vec3 box_albedo, float env_scale,
                            bool side_view)
{
    c->rig = test_rig_begin(2);
    uint32_t grey = test_add_material(c->rig.scene, drift_material_make(drift_vec3_splat(0.5f)));
    uint32_t boxm = test_add_material(c->rig.scene, drift_material_make(box_albedo));
    test_add_floor(c->rig.scene, 20.0f, 0.0f, grey);
    if (box) {
        add_box(c->rig.scene, 0.3f, 1.3f, 1.0f, 2.0f, boxm);
    }
    add_red_blue_environment(c->rig.scene);
    c->rig.scene->environment.color = drift_vec3_splat(env_scale);
    look_down(c->rig.scene, 8.0f, 1.5f, 48);
    if (side_view) {
        c->rig.scene->camera = drift_camera_look_at(
            drift_vec3_make(-5.0f, 4.0f, 0.0f), drift_vec3_make(0.0f, 0.3f, 0.0f),
            drift_vec3_make(0.0f, 1.0f, 0.0f), 0.5f, 48, 48);
    }
    case_begin(c);
}

// Spec §2.5 test 3: with a box on the +x side, the floor beside it sees less red than blue
// under SSDO; SSAO darkens both alike.
static void test_directional_shadow_is_coloured(void **state)
{
    (void)state;
    ssdo_case c;
    build_box_scene(&c, true, drift_vec3_splat(0.5f), 1.0f, false);
    drift_ssdo_params p = { .samples = 32, .radius = 2.0f };
    int32_t x = 25, y = 24; // floor just to the -x side of the box (image right is -x)
    assert_true(pixel(&drift_hybrid_gbuffer(c.rig.frame)->position, x, y)[0] < 0.3f);
    p.method = DRIFT_SSDO_METHOD_SSAO;
    case_render(&c, &p);
    const float *ao = pixel(&c.out.radiance, x, y);
    assert_near(ao[2] / ao[0], 1.0, 0.02);
    assert_true(pixel(&c.out.visibility, x, y)[0] < 0.9f);
    p.method = DRIFT_SSDO_METHOD_SSDO;
    case_render(&c, &p);
    const float *d = pixel(&c.out.radiance, x, y);
    assert_true(d[2] / d[0] > 1.2f);
    case_end(&c);
}

// Spec §2.5 test 2: with the fade off and the sets fixed, adding the box only lowers the
// direct light wherever the visible surface is unchanged.
static void test_added_geometry_only_darkens(void **state)
{
    (void)state;
    ssdo_case open, boxed;
    build_box_scene(&open, false, drift_vec3_splat(0.5f), 1.0f, false);
    build_box_scene(&boxed, true, drift_vec3_splat(0.5f), 1.0f, false);
    drift_ssdo_params p = { .method = DRIFT_SSDO_METHOD_SSDO,
                            .samples = 16,
                            .radius = 1.0f,
                            .no_fade = true,
                            .no_blur = true };
    case_render(&open, &p);
    case_render(&boxed, &p);
    const drift_gbuffer *ga = drift_hybrid_gbuffer(open.rig.frame);
    const drift_gbuffer *gb = drift_hybrid_gbuffer(boxed.rig.frame);
    int darker = 0;
    for (int32_t y = 0; y < 48; ++y) {
        for (int32_t x = 0; x < 48; ++x) {
            if (pixel(&ga->position, x, y)[1] != pixel(&gb->position, x, y)[1]) {
                continue; // the box covers this pixel
            }
            for (int k = 0; k < 3; ++k) {
                float a = pixel(&open.out.direct, x, y)[k], b = pixel(&boxed.out.direct, x, y)[k];
                assert_true(b <= a);
                darker += b < a;
            }
        }
    }
    assert_true(darker > 100);
    case_end(&open);
    case_end(&boxed);
}

// --- THE BOUNCE ---

// Spec §2.5 test 6: the bounce is non-negative, zero away from occluders, carries the
// sender's colour times the receiver's albedo, is linear in the sender's radiance, and a
// back-facing sender gives nothing.
static void test_bounce_sanity(void **state)
{
    (void)state;
    ssdo_case c, bright;
    build_box_scene(&c, true, drift_vec3_make(0.8f, 0.0f, 0.0f), 1.0f, true);
    build_box_scene(&bright, true, drift_vec3_make(0.8f, 0.0f, 0.0f), 2.0f, true);
    drift_ssdo_params p = {
        .method = DRIFT_SSDO_METHOD_SSDO, .samples = 16, .radius = 1.0f, .bounce = true
    };
    case_render(&c, &p);
    case_render(&bright, &p);
    const drift_gbuffer *g = drift_hybrid_gbuffer(c.rig.frame);
    double lit = 0.0;
    for (int32_t y = 0; y < 48; ++y) {
        for (int32_t x = 0; x < 48; ++x) {
            const float *b = pixel(&c.out.bounce, x, y);
            const float *b2 = pixel(&bright.out.bounce, x, y);
            bool floor = pixel(&g->position, x, y)[1] < 1e-3f;
            for (int k = 0; k < 3; ++k) {
                assert_true(b[k] >= 0.0f);
                assert_near(b2[k], 2.0f * b[k], 1e-5f + 1e-5f * b[k]);
            }
            if (floor) {
                // Red sender x grey receiver: red only.
                assert_true(b[1] == 0.0f && b[2] == 0.0f);
                lit += (double)b[0];
            }
            if (floor && pixel(&g->position, x, y)[0] < 0.3f - 1.2f) {
                assert_true(b[0] == 0.0f); // no occluder within r_max
            }
        }
    }
    assert_true(lit > 0.0);
    // Bounded: with sender distances clamped to c r_max, N patches of area pi r_max^2 / N
    // give at most rho_r L_s / c^2 (docs/ssdo.md); here rho_r 0.5, L_s <= 0.8 x 1.05, c 0.5.
    for (int32_t y = 0; y < 48; ++y) {
        for (int32_t x = 0; x < 48; ++x) {
            assert_true(pixel(&c.out.bounce, x, y)[0] <= 0.5f * 0.84f / 0.25f);
        }
    }
    // Box senders turned to face +x, away from every visible floor point, give nothing.
    drift_gbuffer flipped = *g;
    assert_int_equal(drift_image_create(c.rig.ctx, 48, 48, 3, &flipped.normal), DRIFT_OK);
    for (int32_t y = 0; y < 48; ++y) {
        for (int32_t x = 0; x < 48; ++x) {
            bool box = pixel(&g->position, x, y)[1] > 1e-3f;
            drift_image_set3(&flipped.normal, x, y,
                             box ? drift_vec3_make(1, 0, 0) : drift_image_get3(&g->normal, x, y));
        }
    }
    case_render_gbuffer(&c, &flipped, &p, NULL);
    for (int32_t y = 0; y < 48; ++y) {
        for (int32_t x = 0; x < 48; ++x) {
            if (pixel(&g->position, x, y)[1] < 1e-3f) {
                assert_true(pixel(&c.out.bounce, x, y)[0] == 0.0f);
            }
        }
    }
    drift_image_destroy(c.rig.ctx, &flipped.normal);
    case_end(&c);
    case_end(&bright);
}

// The pre-filtered maps of the red/blue environment: around +x the cosine lobe sees red
// alone, around +y half of each, and the narrow cone along -x blue; and SSDO's direct light
// of the open floor under it is exactly rho E / pi.
static void test_prefiltered_environment(void **state)
{
    (void)state;
    ssdo_case c;
    build_box_scene(&c, false, drift_vec3_splat(0.5f), 1.0f, false);
    drift_vec3 e = drift_ssdo_env_irradiance(c.env, drift_vec3_make(1, 0, 0));
    assert_near(e.x, 1.0, 0.02);
    assert_near(e.z, 0.0, 0.02);
    e = drift_ssdo_env_irradiance(c.env, drift_vec3_make(0, 1, 0));
    assert_near(e.x, 0.5, 0.01);
    assert_near(e.z, 0.5, 0.01);
    e = drift_ssdo_env_radiance(c.env, drift_vec3_make(-1, 0, 0), 64);
    assert_near(e.z, 1.0, 0.01);
    assert_near(e.x, 0.0, 0.01);
    // SSDO's ratio estimator is exact on the open floor under this environment: rho E(n) / pi.
    case_render(&c, &(drift_ssdo_params){
                        .method = DRIFT_SSDO_METHOD_SSDO, .samples = 16, .radius = 1.0f });
    drift_vec3 up = drift_ssdo_env_irradiance(c.env, drift_vec3_make(0, 1, 0));
    for (int32_t y = 0; y < 48; ++y) {
        for (int32_t x = 0; x < 48; ++x) {
            assert_near(pixel(&c.out.radiance, x, y)[0], 0.5 * (double)up.x, 1e-4);
            assert_near(pixel(&c.out.radiance, x, y)[2], 0.5 * (double)up.z, 1e-4);
        }
    }
    case_end(&c);
}

// SSDO approaches the path-traced environment light with visibility as N grows, on a scene
// that one depth layer sees whole (a box on a floor from above, r_max around all of it).
static void test_converges_toward_reference(void **state)
{
    (void)state;
    ssdo_case c;
    build_box_scene(&c, true, drift_vec3_splat(0.5f), 1.0f, false);
    drift_image ref;
    assert_int_equal(drift_ssdo_reference(c.rig.ctx, c.rig.scene, c.rig.accel, &c.rig.scene->camera,
                                          48, 48, 64, 1, false, &ref),
                     DRIFT_OK);
    double rmse[3];
    const int32_t counts[3] = { 2, 8, 64 };
    for (int i = 0; i < 3; ++i) {
        case_render(&c, &(drift_ssdo_params){ .method = DRIFT_SSDO_METHOD_SSDO,
                                              .samples = counts[i],
                                              .radius = 3.0f });
        rmse[i] = test_rmse(c.rig.ctx, &ref, &c.out.radiance);
    }
    print_message("SSDO RMSE vs reference: N=2 %.4f, N=8 %.4f, N=64 %.4f\n", rmse[0], rmse[1],
                  rmse[2]);
    assert_true(rmse[1] < rmse[0]);
    assert_true(rmse[2] < rmse[1]);
    assert_true(rmse[2] < 0.05);
    drift_image_destroy(c.rig.ctx, &ref);
    case_end(&c);
}

// Spec §2.5 test 4b: on a heightfield seen from far above, where one depth layer is nearly
// exact, SSDO at N = 64 against the spec's reference, cosine-weighted rays up to r_max from the
// same points. The thesis's point test reads a sample beyond a ridge, in the next valley's air,
// as open, and a blocker at t as blocking only samples with lambda > t: 12% of rho L brighter.
// With steps = 4 (a march to r_max along each direction) SSDO is within 3%, as GTAO is; both
// inside the spec's 10%. For the record, the signed difference to the unbounded environment
// light (occluders beyond r_max) is printed too.
static void test_heightfield_against_ray_traced_occlusion(void **state)
{
    (void)state;
    ssdo_case c = { .rig = test_rig_begin(2) };
    uint32_t grey = test_add_material(c.rig.scene, drift_material_make(drift_vec3_splat(0.5f)));

    enum {
        G = 64
    };

    static float p[(G + 1) * (G + 1) * 3];
    static uint32_t idx[G * G * 6];
    for (int j = 0; j <= G; ++j) {
        for (int i = 0; i <= G; ++i) {
            float x = -3.0f + 6.0f * (float)i / G, z = -3.0f + 6.0f * (float)j / G;
            float *v = p + 3 * (j * (G + 1) + i);
            v[0] = x;
            v[1] = 0.3f * sinf(4.18879f * x) * sinf(4.18879f * z); // period 1.5
            v[2] = z;
        }
    }
    for (int j = 0, t = 0; j < G; ++j) {
        for (int i = 0; i < G; ++i, t += 6) {
            uint32_t a = (uint32_t)(j * (G + 1) + i), b = a + 1, d = a + G + 1, e = d + 1;
            const uint32_t tri[6] = { a, d, e, a, e, b };
            memcpy(idx + t, tri, sizeof(tri));
        }
    }
    test_add_mesh(c.rig.scene, p, (G + 1) * (G + 1), idx, G * G * 2, grey);
    c.rig.scene->environment.color = drift_vec3_splat(1.0f);
    look_down(c.rig.scene, 30.0f, 1.5f, 48);
    case_begin(&c);
    drift_image ref;
    assert_int_equal(drift_ssdo_reference(c.rig.ctx, c.rig.scene, c.rig.accel, &c.rig.scene->camera,
                                          48, 48, 64, 1, false, &ref),
                     DRIFT_OK);
    // The spec's reference: cosine-weighted rays up to r_max = 1 from each pixel's point
    // (16 x 16 stratified), the visibility SSDO estimates with its radius.
    const drift_gbuffer *g = drift_hybrid_gbuffer(c.rig.frame);
    static float bounded[48 * 48];
    for (int32_t i = 0; i < 48 * 48; ++i) {
        drift_vec3 q = drift_image_get3(&g->position, i % 48, i / 48);
        drift_vec3 n = drift_image_get3(&g->normal, i % 48, i / 48);
        drift_frame f = drift_frame_from_normal(n);
        int open = 0;
        for (int k = 0; k < 256; ++k) {
            float u = ((float)(k % 16) + 0.5f) / 16.0f, v = ((float)(k / 16) + 0.5f) / 16.0f;
            float r = sqrtf(u), phi = 2.0f * (float)PI * v;
            drift_vec3 w = drift_frame_to_world(
                &f, drift_vec3_make(r * cosf(phi), r * sinf(phi), sqrtf(1.0f - u)));
            drift_ray ray = { .origin = drift_offset_origin(q, n, w), .dir = w, .tmax = 1.0f };
            drift_hit hit;
            open += !drift_accel_intersect(c.rig.accel, &ray, &hit);
        }
        bounded[i] = 0.5f * (float)open / 256.0f; // rho L V
    }
    // SSDO against both: the visibility within r_max (the spec's 10%), and the full
    // environment light (occluders beyond r_max too).
    // The centre 16 x 16 pixels, whose samples stay on screen; no fade (the rays have none).
    static const char *const names[] = { "ssdo (point test)", "ssdo, 4 steps", "gtao" };
    double within[3];
    for (int m = 0; m < 3; ++m) {
        case_render(&c, &(drift_ssdo_params){ .method = m == 2 ? DRIFT_SSDO_METHOD_GTAO
                                                               : DRIFT_SSDO_METHOD_SSDO,
                                              .samples = 64,
                                              .radius = 1.0f,
                                              .no_fade = true,
                                              .steps = m == 1 ? 4 : 1 });
        double diff = 0.0, signed_diff = 0.0, full = 0.0;
        int lo = 16, hi = 32;
        for (int32_t y = lo; y < hi; ++y) {
            for (int32_t x = lo; x < hi; ++x) {
                double o = (double)pixel(&c.out.radiance, x, y)[0];
                double d = o - (double)bounded[y * 48 + x];
                diff += fabs(d);
                signed_diff += d;
                full += o - (double)pixel(&ref, x, y)[0];
            }
        }
        double npx = (double)((hi - lo) * (hi - lo));
        within[m] = diff / (npx * 0.5);
        print_message("heightfield %s: mean |. - rays to r_max| = %.3f of rho L (signed %+.3f); "
                      "signed against the unbounded environment light %+.3f\n",
                      names[m], within[m], signed_diff / (npx * 0.5), full / (npx * 0.5));
    }
    assert_true(within[1] < 0.05); // the march: well inside the spec's 10%
    assert_true(within[0] < 0.15); // the thesis's point test, a regression metric
    assert_true(within[2] < 0.05); // GTAO's horizons are rays too
    drift_image_destroy(c.rig.ctx, &ref);
    case_end(&c);
}

// --- DETERMINISM ---

// Spec §2.5 test 8: fixed sets give a bit-identical image, for any thread count.
static void test_bit_identical_across_threads(void **state)
{
    (void)state;
    ssdo_case c;
    build_box_scene(&c, true, drift_vec3_make(0.8f, 0.2f, 0.1f), 1.0f, false);
    drift_context *one = test_context(1, NULL);
    for (int t = 0; t < DRIFT_SSDO_METHOD_COUNT; ++t) {
        drift_ssdo_params p = {
            .method = (drift_ssdo_method)t, .samples = 16, .radius = 1.0f, .bounce = true, .seed = 3
        };
        case_render(&c, &p);
        drift_ssdo_output first;
        assert_int_equal(drift_ssdo_output_create(one, 48, 48, &first), DRIFT_OK);
        drift_ssdo_inputs in = { .gbuffer = drift_hybrid_gbuffer(c.rig.frame),
                                 .camera = &c.rig.scene->camera };
        assert_int_equal(drift_ssdo_render(one, c.env, &in, &p, &first), DRIFT_OK);
        assert_memory_equal(first.radiance.pixels, c.out.radiance.pixels,
                            sizeof(float) * 48 * 48 * 3);
        assert_memory_equal(first.visibility.pixels, c.out.visibility.pixels,
                            sizeof(float) * 48 * 48);
        drift_ssdo_output_destroy(one, &first);
    }
    drift_context_destroy(one);
    case_end(&c);
}

// --- ERRORS ---

static void test_bad_parameters_are_rejected(void **state)
{
    (void)state;
    ssdo_case c;
    build_box_scene(&c, false, drift_vec3_splat(0.5f), 1.0f, false);
    const drift_gbuffer *g = drift_hybrid_gbuffer(c.rig.frame);
    const drift_ssdo_params bad[] = {
        { .radius = -1.0f },
        { .radius = 1.0f, .samples = -3 },
        { .radius = 1.0f, .method = DRIFT_SSDO_METHOD_COUNT },
        { .radius = 1.0f, .gtao_thickness = 2.0f },
    };
    for (size_t i = 0; i < sizeof(bad) / sizeof(bad[0]); ++i) {
        drift_ssdo_inputs in = { .gbuffer = g, .camera = &c.rig.scene->camera };
        assert_int_equal(drift_ssdo_render(c.rig.ctx, c.env, &in, &bad[i], &c.out),
                         DRIFT_ERR_INVALID_ARGUMENT);
    }
    assert_int_equal(drift_ssdo_method_parse("gtao"), DRIFT_SSDO_METHOD_GTAO);
    assert_int_equal(drift_ssdo_method_parse("hbao"), -1);
    case_end(&c);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_open_plane_gives_albedo_times_environment),
        cmocka_unit_test(test_groove_crease_matches_closed_form),
        cmocka_unit_test(test_directional_shadow_is_coloured),
        cmocka_unit_test(test_added_geometry_only_darkens),
        cmocka_unit_test(test_bounce_sanity),
        cmocka_unit_test(test_prefiltered_environment),
        cmocka_unit_test(test_converges_toward_reference),
        cmocka_unit_test(test_heightfield_against_ray_traced_occlusion),
        cmocka_unit_test(test_second_layer_opens_the_gap_behind_a_slab),
        cmocka_unit_test(test_additional_cameras_find_an_off_screen_blocker),
        cmocka_unit_test(test_contact_shadows_within_the_bias),
        cmocka_unit_test(test_contact_shadows_fix_the_frames_shadow_map),
        cmocka_unit_test(test_bit_identical_across_threads),
        cmocka_unit_test(test_bad_parameters_are_rejected),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
