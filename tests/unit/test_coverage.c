// Coverage (drift_alpha_mode): glTF's alphaMode MASK and BLEND, the cut-out cards of foliage
// and the see-through veils users' files have. The alpha channel as the image stores it; the
// file's modes, cutoff and factor; rays (single and in packets, closest hit and shadow) pass
// where a MASK surface is not there and a BLEND surface with probability 1 - opacity; the path
// tracer sees an emitter through a black veil of opacity a at (1 - a) of its radiance; the
// scene's point sets lie only on what is there, their area the part that is.
#include "drift/accel.h"
#include "drift/image.h"
#include "drift/image_io.h"
#include "drift/points.h"
#include "drift/pt.h"
#include "drift/scene.h"
#include "drift/scene_io.h"
#include "drift_test.h"
#include "test_rig.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static void test_alpha_channel_loads(void **state)
{
    (void)state;
    test_log_capture log = { 0 };
    drift_context *ctx = test_context(1, &log);
    char path[1024];
    drift_image a;
    assert_int_equal(drift_image_load_alpha(ctx,
                                            test_repo_path(path, "tests/data/coverage/alpha.png"),
                                            DRIFT_ALPHA_CHANNEL, &a),
                     DRIFT_OK);
    assert_int_equal(a.channels, 1);
    assert_int_equal(a.width, 4);
    const float want[4] = { 0.0f, 128.0f / 255.0f, 1.0f, 1.0f }; // stored, not sRGB-decoded
    for (int x = 0; x < 4; ++x) {
        assert_near(drift_image_pixel(&a, x, 0)[0], want[x], 1e-6);
    }
    drift_image_destroy(ctx, &a);
    // No alpha channel: opaque everywhere. The colour load of the same file is unchanged.
    assert_int_equal(drift_image_load_alpha(ctx,
                                            test_repo_path(path, "tests/data/coverage/opaque.png"),
                                            DRIFT_ALPHA_CHANNEL, &a),
                     DRIFT_OK);
    assert_near(drift_image_pixel(&a, 1, 0)[0], 1.0, 0);
    drift_image_destroy(ctx, &a);
    // An MTL's map_d reads such a file's grey value instead: (200 + 100 + 50) / 3 / 255.
    assert_int_equal(drift_image_load_alpha(ctx,
                                            test_repo_path(path, "tests/data/coverage/opaque.png"),
                                            DRIFT_ALPHA_OR_GREY, &a),
                     DRIFT_OK);
    assert_near(drift_image_pixel(&a, 0, 0)[0], 350.0 / 3.0 / 255.0, 1e-6);
    drift_image_destroy(ctx, &a);
    assert_int_equal(
        drift_image_load(ctx, test_repo_path(path, "tests/data/coverage/alpha.png"), &a), DRIFT_OK);
    assert_int_equal(a.channels, 3);
    assert_near(drift_image_pixel(&a, 0, 0)[0], drift_srgb_to_linear(10.0f / 255.0f), 1e-6);
    drift_image_destroy(ctx, &a);
    drift_context_destroy(ctx);
}

// cards.gltf (tests/data/coverage/make_coverage.py): MASK with its cutoff and texture, BLEND
// with its factor's alpha, an opaque wall; no "drawn opaque" warning any more.
static void test_gltf_alpha_modes(void **state)
{
    (void)state;
    test_log_capture log = { 0 };
    drift_context *ctx = test_context(1, &log);
    char path[1024];
    drift_scene *scene = NULL;
    assert_int_equal(
        drift_scene_load(ctx, test_repo_path(path, "tests/data/coverage/cards.gltf"), &scene),
        DRIFT_OK);
    assert_int_equal(log.warnings, 0);
    assert_int_equal(scene->mesh_count, 3);
    const drift_material *card = &scene->materials[scene->meshes[0].material];
    const drift_material *veil = &scene->materials[scene->meshes[1].material];
    const drift_material *wall = &scene->materials[scene->meshes[2].material];
    assert_int_equal(card->alpha_mode, DRIFT_ALPHA_MASK);
    assert_near(card->alpha_cutoff, 0.4, 1e-6);
    assert_true(card->opacity_texture < scene->texture_count);
    assert_int_equal(scene->textures[card->opacity_texture].channels, 1);
    assert_int_equal(veil->alpha_mode, DRIFT_ALPHA_BLEND);
    assert_near(veil->opacity, 0.25, 1e-6);
    assert_int_equal(veil->opacity_texture, DRIFT_INVALID_INDEX);
    assert_int_equal(wall->alpha_mode, DRIFT_ALPHA_OPAQUE);
    // The card's texels (nearest): alpha 0, 0.5, 1, 1 along x; the cutoff 0.4 keeps three.
    const float xs[4] = { -0.75f, -0.25f, 0.25f, 0.75f };
    const bool kept[4] = { false, true, true, true };
    drift_accel *accel = NULL;
    assert_int_equal(drift_accel_create(ctx, scene, &(drift_accel_desc){ 0 }, &accel), DRIFT_OK);
    for (int k = 0; k < 4; ++k) {
        drift_ray ray = { .origin = drift_vec3_make(xs[k], 0.3f, 1.0f),
                          .dir = drift_vec3_make(0, 0, -1),
                          .tmax = INFINITY };
        drift_hit hit;
        assert_true(drift_accel_intersect(accel, &ray, &hit));
        // Through a missing texel the ray meets the veil (if it lets it) or the wall.
        if (kept[k]) {
            assert_int_equal(hit.mesh, 0);
        } else {
            assert_true(hit.mesh == 1 || hit.mesh == 2);
        }
        assert_true(drift_accel_occluded(accel, &ray)); // the wall is there behind all
    }
    drift_accel_destroy(accel);
    drift_scene_destroy(scene);
    drift_context_destroy(ctx);
}

// An OBJ's MTL: d and Tr give a BLEND opacity, map_d its texture (alpha.png's alpha), a bad d
// a warning naming its line, and a missing map_d a warning with d alone kept.
static void test_obj_dissolve(void **state)
{
    (void)state;
    test_log_capture log = { 0 };
    drift_context *ctx = test_context(1, &log);
    char obj[1024], mtl[1024], png[1024];
    test_out_path(obj, "coverage.obj");
    test_out_path(mtl, "coverage.mtl");
    test_repo_path(png, "tests/data/coverage/alpha.png");
    FILE *f = fopen(mtl, "w");
    assert_non_null(f);
    fprintf(f,
            "newmtl leaf\nKd 0.2 0.6 0.1\nmap_d %s\n"
            "newmtl veil\nKd 1 1 1\nd 0.3\n"
            "newmtl tinted\nKd 1 1 1\nTr 0.25\n"
            "newmtl solid\nKd 1 1 1\nd 1.0\n"
            "newmtl broken\nKd 1 1 1\nd 7\nmap_d no-such-file.png\n",
            png);
    fclose(f);
    f = fopen(obj, "w");
    assert_non_null(f);
    fprintf(f, "mtllib coverage.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\n");
    const char *names[5] = { "leaf", "veil", "tinted", "solid", "broken" };
    for (int k = 0; k < 5; ++k) {
        fprintf(f, "o %s\nusemtl %s\nf 1/1 2/2 3/3\n", names[k], names[k]);
    }
    fclose(f);
    drift_scene *scene = NULL;
    assert_int_equal(drift_scene_load(ctx, obj, &scene), DRIFT_OK);
    assert_int_equal(log.warnings, 2); // d 7 (line 13) and the missing map_d (line 14)
    const drift_alpha_mode modes[5] = { DRIFT_ALPHA_BLEND, DRIFT_ALPHA_BLEND, DRIFT_ALPHA_BLEND,
                                        DRIFT_ALPHA_OPAQUE, DRIFT_ALPHA_OPAQUE };
    const float opacity[5] = { 1.0f, 0.3f, 0.75f, 1.0f, 1.0f };
    for (uint32_t i = 0; i < scene->mesh_count; ++i) {
        const drift_material *m = &scene->materials[scene->meshes[i].material];
        for (int k = 0; k < 5; ++k) {
            if (strcmp(m->name, names[k]) != 0) {
                continue;
            }
            assert_int_equal(m->alpha_mode, modes[k]);
            if (modes[k] != DRIFT_ALPHA_OPAQUE) {
                assert_near(m->opacity, opacity[k], 1e-6);
                assert_int_equal(m->opacity_texture != DRIFT_INVALID_INDEX, k == 0);
            }
        }
    }
    drift_scene_destroy(scene);
    drift_context_destroy(ctx);
}

// Mitsuba's mask BSDF: opacity a number (BLEND of that opacity over the nested BSDF) or a
// bitmap (its grey or alpha: alpha.png's, read along the rectangle's u as Mitsuba lays it out).
static void test_mitsuba_mask(void **state)
{
    (void)state;
    test_log_capture log = { 0 };
    drift_context *ctx = test_context(1, &log);
    char xml[1024], png[1024];
    test_out_path(xml, "coverage_mask.xml");
    test_repo_path(png, "tests/data/coverage/alpha.png");
    FILE *f = fopen(xml, "w");
    assert_non_null(f);
    fprintf(f,
            "<scene version=\"0.6.0\">\n"
            " <bsdf type=\"mask\" id=\"leaf\">\n"
            "  <texture name=\"opacity\" type=\"bitmap\">"
            "<string name=\"filename\" value=\"%s\"/></texture>\n"
            "  <bsdf type=\"diffuse\"><rgb name=\"reflectance\" value=\"0.1, 0.6, 0.1\"/></bsdf>\n"
            " </bsdf>\n"
            " <bsdf type=\"mask\" id=\"veil\"><float name=\"opacity\" value=\"0.3\"/>"
            "<bsdf type=\"diffuse\"/></bsdf>\n"
            " <shape type=\"rectangle\"><ref id=\"leaf\"/></shape>\n"
            " <shape type=\"rectangle\"><transform name=\"toWorld\"><translate z=\"-1\"/>"
            "</transform><ref id=\"veil\"/></shape>\n"
            "</scene>\n",
            png);
    fclose(f);
    drift_scene *scene = NULL;
    assert_int_equal(drift_scene_load(ctx, xml, &scene), DRIFT_OK);
    const drift_material *leaf = &scene->materials[scene->meshes[0].material];
    const drift_material *veil = &scene->materials[scene->meshes[1].material];
    assert_int_equal(leaf->alpha_mode, DRIFT_ALPHA_BLEND);
    assert_true(leaf->opacity_texture < scene->texture_count);
    assert_near(leaf->diffuse.y, 0.6, 1e-6); // the nested BSDF's
    assert_int_equal(veil->alpha_mode, DRIFT_ALPHA_BLEND);
    assert_near(veil->opacity, 0.3, 1e-6);
    // The bitmap along x (u), at texel centres on the bottom edge (triangle 0's barycentric u
    // is the rectangle's u there): opacity 0 at the left texel, 0.5 and 1 further right.
    assert_near(drift_scene_opacity(scene, 0, 0, 0.125f, 0.0f), 0.0, 1e-6);
    assert_near(drift_scene_opacity(scene, 0, 0, 0.375f, 0.0f), 128.0 / 255.0, 1e-6);
    assert_near(drift_scene_opacity(scene, 0, 0, 0.875f, 0.0f), 1.0, 1e-6);
    drift_scene_destroy(scene);
    drift_context_destroy(ctx);
}

// drift's own scene format: opacity alone is a BLEND, alpha_cutoff makes a MASK, an
// opacity_texture is read as a coverage image; an opacity outside [0, 1] is refused.
static void test_json_coverage(void **state)
{
    (void)state;
    test_log_capture log = { 0 };
    drift_context *ctx = test_context(1, &log);
    char json[1024], png[1024], mesh[1024];
    test_out_path(json, "coverage.json");
    test_repo_path(png, "tests/data/coverage/alpha.png");
    test_repo_path(mesh, "tests/data/coverage/cards.gltf");
    for (int bad = 0; bad < 2; ++bad) {
        FILE *f = fopen(json, "w");
        assert_non_null(f);
        fprintf(f,
                "{\"materials\": {\"veil\": {\"opacity\": %s},\n"
                "  \"card\": {\"type\": \"ggx\", \"opacity_texture\": \"%s\", "
                "\"alpha_cutoff\": 0.4},\n"
                "  \"wall\": {}},\n"
                " \"meshes\": [{\"path\": \"%s\", \"material\": \"veil\"}]}\n",
                bad ? "1.5" : "0.3", png, mesh);
        fclose(f);
        drift_scene *scene = NULL;
        drift_result r = drift_scene_load(ctx, json, &scene);
        if (bad) {
            assert_int_not_equal(r, DRIFT_OK);
            continue;
        }
        assert_int_equal(r, DRIFT_OK);
        assert_int_equal(scene->materials[0].alpha_mode, DRIFT_ALPHA_BLEND);
        assert_near(scene->materials[0].opacity, 0.3, 1e-6);
        assert_int_equal(scene->materials[1].alpha_mode, DRIFT_ALPHA_MASK);
        assert_near(scene->materials[1].alpha_cutoff, 0.4, 1e-6);
        assert_true(scene->materials[1].opacity_texture < scene->texture_count);
        assert_int_equal(scene->materials[2].alpha_mode, DRIFT_ALPHA_OPAQUE);
        drift_scene_destroy(scene);
    }
    drift_context_destroy(ctx);
}

// A quad in z = z0 facing +z, uv (0, 0) at its bottom-left corner, of `material`.
static uint32_t add_card(drift_scene *scene, float half, float z0, uint32_t material)
{
    const float pos[12] = { -half, -half, z0, half, -half, z0, half, half, z0, -half, half, z0 };
    const float uv[8] = { 0, 0, 1, 0, 1, 1, 0, 1 };
    const uint32_t idx[6] = { 0, 1, 2, 0, 2, 3 };
    uint32_t mesh;
    assert_int_equal(drift_scene_add_mesh(scene,
                                          &(drift_mesh_desc){ .positions = pos,
                                                              .uvs = uv,
                                                              .indices = idx,
                                                              .vertex_count = 4,
                                                              .triangle_count = 2,
                                                              .material = material },
                                          &mesh),
                     DRIFT_OK);
    return mesh;
}

// A material whose opacity is a 2 x 1 texture: transparent on the left half (u < 0.5),
// opaque on the right, read nearest.
static uint32_t add_half_mask(drift_scene *scene)
{
    drift_image alpha;
    assert_int_equal(drift_image_create(scene->ctx, 2, 1, 1, &alpha), DRIFT_OK);
    drift_image_pixel(&alpha, 0, 0)[0] = 0.0f;
    drift_image_pixel(&alpha, 1, 0)[0] = 1.0f;
    uint32_t tex;
    assert_int_equal(drift_scene_add_texture(scene, alpha, &tex), DRIFT_OK);
    drift_material m = drift_material_make(drift_vec3_splat(0.5f));
    m.alpha_mode = DRIFT_ALPHA_MASK;
    m.opacity_texture = tex;
    m.maps[DRIFT_TEXTURE_BASE].mag_nearest = true;
    return test_add_material(scene, m);
}

// Rays one at a time and in 16-wide packets agree, for closest hits and shadow rays: the
// MASK card's left half lets every ray through, its right half none.
static void test_mask_rays(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    uint32_t card = add_card(r.scene, 1.0f, 0.0f, add_half_mask(r.scene));
    test_rig_commit(&r);

    enum {
        N = 64
    };

    drift_ray rays[N];
    for (int i = 0; i < N; ++i) {
        float x = -0.95f + 1.9f * test_hash_unit((uint32_t)i);
        float y = -0.95f + 1.9f * test_hash_unit((uint32_t)i + 1000u);
        rays[i] = (drift_ray){ .origin = drift_vec3_make(x, y, 1.0f),
                               .dir = drift_vec3_make(0, 0, -1),
                               .tmax = 10.0f };
    }
    drift_hit packet[N];
    uint8_t occluded[N];
    drift_accel_intersect_coherent(r.accel, rays, packet, N);
    drift_accel_occluded_coherent(r.accel, rays, occluded, N);
    int hits = 0;
    for (int i = 0; i < N; ++i) {
        bool there = rays[i].origin.x > 0.0f;
        drift_hit hit;
        bool got = drift_accel_intersect(r.accel, &rays[i], &hit);
        assert_int_equal(got, there);
        assert_int_equal(packet[i].mesh == card, there);
        assert_int_equal(drift_accel_occluded(r.accel, &rays[i]), there);
        assert_int_equal(occluded[i] != 0, there);
        hits += got;
    }
    assert_true(hits > 16 && hits < 48);
    test_rig_destroy(&r);
}

// A BLEND veil of opacity 0.3 stops that share of rays (binomial bound, 4 sigma), the same
// ray always the same way.
static void test_blend_stops_its_share(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(1);
    drift_material veil = drift_material_make(drift_vec3_splat(0.5f));
    veil.alpha_mode = DRIFT_ALPHA_BLEND;
    veil.opacity = 0.3f;
    add_card(r.scene, 2.0f, 0.0f, test_add_material(r.scene, veil));
    test_rig_commit(&r);
    const int n = 20000;
    int stopped = 0;
    for (int i = 0; i < n; ++i) {
        drift_ray ray = { .origin =
                              drift_vec3_make(test_hash_unit((uint32_t)i) - 0.5f,
                                              test_hash_unit((uint32_t)i + 77777u) - 0.5f, 1.0f),
                          .dir = drift_vec3_make(0, 0, -1),
                          .tmax = 10.0f };
        drift_hit hit;
        bool got = drift_accel_intersect(r.accel, &ray, &hit);
        assert_int_equal(drift_accel_intersect(r.accel, &ray, &hit), got);
        stopped += got;
    }
    double share = (double)stopped / n, sigma = sqrt(0.3 * 0.7 / n);
    print_message("BLEND opacity 0.3: %d of %d rays stopped (%.4f)\n", stopped, n, share);
    assert_near(share, 0.3, 4.0 * sigma);
    // One ray, sample after sample (its seed), through the card's centre, on the edge its two
    // triangles share: still 0.3, not 1 - 0.7^2 (a number a triangle gave two chances).
    stopped = 0;
    for (int i = 0; i < n; ++i) {
        drift_ray ray = { .origin = drift_vec3_make(0, 0, 1),
                          .dir = drift_vec3_make(0, 0, -1),
                          .tmax = 10.0f,
                          .seed = (uint32_t)i };
        drift_hit hit;
        stopped += drift_accel_intersect(r.accel, &ray, &hit);
    }
    share = (double)stopped / n;
    print_message("BLEND opacity 0.3 on a shared edge: %.4f of one ray's samples stopped\n", share);
    assert_near(share, 0.3, 4.0 * sigma);
    test_rig_destroy(&r);
}

// The path tracer looks at an emitter of radiance 2 through a black veil: (1 - a) 2 at
// opacity a (a = 0: nothing in the way; 1: black), each pixel's mean over its samples within
// a binomial bound. Drawn opaque, as before, every value was 0.
static void test_pt_sees_through_veil(void **state)
{
    (void)state;
    const float opacities[3] = { 0.0f, 0.35f, 1.0f };
    for (int k = 0; k < 3; ++k) {
        test_rig r = test_rig_begin(2);
        drift_material veil = drift_material_make(drift_vec3_splat(0.0f));
        veil.alpha_mode = DRIFT_ALPHA_BLEND;
        veil.opacity = opacities[k];
        add_card(r.scene, 3.0f, 0.0f, test_add_material(r.scene, veil));
        drift_material lamp = drift_material_make(drift_vec3_splat(0.0f));
        lamp.emission = drift_vec3_splat(2.0f);
        add_card(r.scene, 6.0f, -1.0f, test_add_material(r.scene, lamp));
        const int32_t size = 8;
        r.scene->camera = drift_camera_look_at(drift_vec3_make(0, 0, 4), drift_vec3_make(0, 0, 0),
                                               drift_vec3_make(0, 1, 0), 0.4f, size, size);
        test_rig_commit(&r);
        const uint32_t spp = 64;
        drift_pt *pt = NULL;
        drift_image img = test_rig_render_pt(&r, 0, 4, spp, 7, &pt);
        double sum = 0.0;
        for (int32_t y = 0; y < size; ++y) {
            for (int32_t x = 0; x < size; ++x) {
                sum += (double)drift_image_pixel(&img, x, y)[1];
            }
        }
        double a = (double)opacities[k], mean = sum / (size * size), want = 2.0 * (1.0 - a);
        double n = (double)spp * size * size;
        double bound = 4.0 * 2.0 * sqrt(a * (1.0 - a) / n) + 1e-6;
        print_message("veil opacity %.2f: %.4f, expected %.4f (+- %.4f)\n", a, mean, want, bound);
        assert_near(mean, want, bound);
        drift_pt_destroy(pt);
        test_rig_destroy(&r);
    }
}

// The hybrid frame blends a veil over what is behind it: an emitter of radiance 2 through a
// black veil of opacity a shows 2 (1 - a) in every pixel, with no dithering (each pixel was
// 0 or 2 when the G-buffer's one camera ray met the veil by chance); a lit white veil over a
// black background shows its direct light times a (the path tracer's, within 5%).
static void test_hybrid_blends_veils(void **state)
{
    (void)state;
    const float opacities[2] = { 0.35f, 0.8f };
    for (int k = 0; k < 2; ++k) {
        test_rig r = test_rig_begin(2);
        drift_material veil = drift_material_make(drift_vec3_splat(0.0f));
        veil.alpha_mode = DRIFT_ALPHA_BLEND;
        veil.opacity = opacities[k];
        add_card(r.scene, 3.0f, 0.0f, test_add_material(r.scene, veil));
        drift_material lamp = drift_material_make(drift_vec3_splat(0.0f));
        lamp.emission = drift_vec3_splat(2.0f);
        add_card(r.scene, 6.0f, -1.0f, test_add_material(r.scene, lamp));
        const int32_t size = 9;
        r.scene->camera = drift_camera_look_at(drift_vec3_make(0, 0, 4), drift_vec3_make(0, 0, 0),
                                               drift_vec3_make(0, 1, 0), 0.4f, size, size);
        test_rig_commit(&r);
        test_rig_frame(&r, &(drift_hybrid_params){ .width = size, .height = size });
        const drift_image *img = drift_hybrid_image(r.frame);
        double want = 2.0 * (1.0 - (double)opacities[k]);
        for (int32_t y = 0; y < size; ++y) {
            for (int32_t x = 0; x < size; ++x) {
                assert_near(drift_image_pixel(img, x, y)[1], want, 0.01 * want);
            }
        }
        test_rig_destroy(&r);
    }
    // A white veil of opacity 0.5 lit by a quad light off to the side, nothing behind it.
    test_rig r = test_rig_begin(2);
    drift_material veil = drift_material_make(drift_vec3_splat(0.8f));
    veil.alpha_mode = DRIFT_ALPHA_BLEND;
    veil.opacity = 0.5f;
    add_card(r.scene, 1.0f, 0.0f, test_add_material(r.scene, veil));
    test_add_quad_light(r.scene, drift_vec3_make(1.5f, -0.5f, 1.5f), drift_vec3_make(0, 1, 0),
                        drift_vec3_make(1, 0, 0), 4.0f);
    const int32_t size = 9;
    r.scene->camera = drift_camera_look_at(drift_vec3_make(0, 0, 4), drift_vec3_make(0, 0, 0),
                                           drift_vec3_make(0, 1, 0), 0.2f, size, size);
    test_rig_commit(&r);
    test_rig_frame(&r,
                   &(drift_hybrid_params){ .width = size, .height = size, .light_samples = 256 });
    drift_pt *pt = NULL;
    drift_image truth = test_rig_render_pt(&r, 0, 4, 1024, 7, &pt);
    double got = 0.0, want = 0.0;
    const drift_image *img = drift_hybrid_image(r.frame);
    for (int32_t y = 3; y <= 5; ++y) {
        for (int32_t x = 3; x <= 5; ++x) {
            got += (double)drift_image_pixel(img, x, y)[1];
            want += (double)drift_image_pixel(&truth, x, y)[1];
        }
    }
    print_message("lit veil: hybrid %.4f, path tracer %.4f\n", got / 9.0, want / 9.0);
    assert_true(want > 0.05);
    assert_near(got, want, 0.05 * want);
    drift_pt_destroy(pt);
    test_rig_destroy(&r);
}

// Points sampled on a scene of one half-masked card and one opaque card of the same size lie
// on the right half of the first or anywhere on the second, and their area is 3/4 of the two
// cards' (the first draw of each point lands on the missing half a quarter of the time).
static void test_points_lie_on_what_is_there(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    uint32_t card = add_card(r.scene, 1.0f, 0.0f, add_half_mask(r.scene));
    add_card(r.scene, 1.0f, -3.0f,
             test_add_material(r.scene, drift_material_make(drift_vec3_splat(0.5f))));
    test_rig_commit(&r);
    drift_points *pts = NULL;
    assert_int_equal(drift_points_create(r.ctx, r.scene,
                                         &(drift_points_desc){ .count = 4096, .subset_count = 8 },
                                         &pts),
                     DRIFT_OK);
    uint32_t on_card = 0;
    for (uint32_t i = 0; i < pts->count; ++i) {
        if (pts->points[i].mesh == card) {
            assert_true(pts->position[i].x >= 0.0f);
            ++on_card;
        }
    }
    print_message("points: %u of %u on the card, coverage %.4f\n", on_card, pts->count,
                  pts->coverage);
    assert_near((double)on_card / pts->count, 1.0 / 3.0, 0.03);
    assert_near(pts->coverage, 0.75, 0.03);
    assert_near(pts->area, 0.75 * 8.0, 0.03 * 8.0);
    drift_points_destroy(pts);
    test_rig_destroy(&r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_alpha_channel_loads),
        cmocka_unit_test(test_gltf_alpha_modes),
        cmocka_unit_test(test_obj_dissolve),
        cmocka_unit_test(test_mitsuba_mask),
        cmocka_unit_test(test_json_coverage),
        cmocka_unit_test(test_mask_rays),
        cmocka_unit_test(test_blend_stops_its_share),
        cmocka_unit_test(test_pt_sees_through_veil),
        cmocka_unit_test(test_hybrid_blends_veils),
        cmocka_unit_test(test_points_lie_on_what_is_there),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
