// glTF animation (src/io/scene_gltf_anim*.c, docs/temporal.md "glTF animation"): the camera
// of tests/data/gltf/camera_*.gltf (made by make_camera_anim.py) sampled at each frame against
// the closed form of its channels — a parent turning by slerp with a child moving linearly, a
// CUBICSPLINE translation and a STEP rotation — plus malformed files refused with their name;
// and node animation played on a mesh (mesh_anim.gltf): posed at t its vertices, its path-traced
// render and its hybrid frame are bit for bit those of its static twin (mesh_moved.gltf), and
// posed back at rest those of the scene as loaded.
#include "drift/accel.h"
#include "drift/camera_path.h"
#include "drift/hybrid.h"
#include "drift/pt.h"
#include "drift/scene_io.h"
#include "drift_test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define EPS 1e-4

static void assert_vec(drift_vec3 v, double x, double y, double z, int line)
{
    test_assert_close(v.x, x, EPS, line);
    test_assert_close(v.y, y, EPS, line);
    test_assert_close(v.z, z, EPS, line);
}

// R_y(theta) p.
static drift_vec3 rot_y(double theta, double x, double y, double z)
{
    return drift_vec3_make((float)(x * cos(theta) + z * sin(theta)), (float)y,
                           (float)(-x * sin(theta) + z * cos(theta)));
}

// camera_linear.gltf: the rig turns 0 -> 90 degrees about +y over [0, 1] s (slerp: the angle
// is linear in time), the camera below it moves (0, 1, 5) -> (2, 1, 5).
static void test_linear_slerp_parent(void **state)
{
    (void)state;
    test_log_capture cap = { 0 };
    drift_context *ctx = test_context(1, &cap);
    char path[1024];
    test_repo_path(path, "tests/data/gltf/camera_linear.gltf");
    drift_camera_path p;
    assert_int_equal(drift_camera_path_from_gltf(ctx, path, NULL, 24.0, 0, 30, &p), DRIFT_OK);
    assert_int_equal(p.count, 31);
    drift_scene *scene = NULL;
    assert_int_equal(drift_scene_load(ctx, path, &scene), DRIFT_OK);
    // The loader's still camera (assimp, at rest) is the animation's first frame.
    assert_vec(scene->camera.position, 0, 1, 5, __LINE__);
    for (int k = 0; k <= 30; ++k) {
        double t = fmin(k / 24.0, 1.0); // the ends hold
        double theta = 0.5 * (double)DRIFT_PI * t;
        drift_camera c = drift_camera_path_eval(&p, &scene->camera, k / 24.0);
        drift_vec3 eye = rot_y(theta, 2.0 * t, 1.0, 5.0);
        drift_vec3 fwd = rot_y(theta, 0.0, 0.0, -1.0);
        assert_vec(c.position, eye.x, eye.y, eye.z, __LINE__);
        assert_vec(drift_vec3_sub(c.target, c.position), fwd.x, fwd.y, fwd.z, __LINE__);
        assert_vec(c.up, 0, 1, 0, __LINE__);
        test_assert_close(c.fov_y, scene->camera.fov_y, 1e-6, __LINE__);
    }
    drift_scene_destroy(scene);
    drift_camera_path_free(ctx, &p);
    drift_context_destroy(ctx);
}

// camera_step_cubic.gltf: translation a cubic Hermite over [0, 2] s (values (0, 1, 5) and
// (1, 1, 6), out-tangent (3, 0, 0) at the first, in-tangent (0, 0, -1) at the second), rotation
// STEP: identity, then 90 degrees about +y from 0.5 s.
static void test_step_and_cubic(void **state)
{
    (void)state;
    drift_context *ctx = test_context(1, NULL);
    char path[1024];
    test_repo_path(path, "tests/data/gltf/camera_step_cubic.gltf");
    drift_camera_path p;
    assert_int_equal(drift_camera_path_from_gltf(ctx, path, "Camera", 24.0, 0, 48, &p), DRIFT_OK);
    drift_camera base = drift_camera_look_at(drift_vec3_make(0, 0, 0), drift_vec3_make(0, 0, -1),
                                             drift_vec3_make(0, 1, 0), 1.0f, 8, 8);
    for (int k = 0; k <= 48; ++k) {
        double t = k / 24.0, s = t / 2.0, td = 2.0;
        double h00 = 2 * s * s * s - 3 * s * s + 1, h10 = s * s * s - 2 * s * s + s;
        double h01 = -2 * s * s * s + 3 * s * s, h11 = s * s * s - s * s;
        double x = h00 * 0 + td * h10 * 3 + h01 * 1 + td * h11 * 0;
        double y = h00 * 1 + h01 * 1;
        double z = h00 * 5 + h01 * 6 + td * h11 * -1;
        drift_camera c = drift_camera_path_eval(&p, &base, t);
        assert_vec(c.position, x, y, z, __LINE__);
        drift_vec3 fwd = drift_vec3_sub(c.target, c.position);
        if (t < 0.5) {
            assert_vec(fwd, 0, 0, -1, __LINE__);
        } else {
            assert_vec(fwd, -1, 0, 0, __LINE__);
        }
    }
    // The same file as a .glb (its buffer in the BIN chunk) gives the same keys.
    drift_camera_path q;
    assert_int_equal(drift_camera_path_from_gltf(
                         ctx, test_repo_path(path, "tests/data/gltf/camera_step_cubic.glb"), NULL,
                         24.0, 0, 48, &q),
                     DRIFT_OK);
    assert_int_equal(q.count, p.count);
    for (uint32_t k = 0; k < p.count; ++k) {
        assert_true(q.keys[k].time == p.keys[k].time);
        assert_memory_equal(&q.keys[k].position, &p.keys[k].position, sizeof(drift_vec3));
        assert_memory_equal(&q.keys[k].target, &p.keys[k].target, sizeof(drift_vec3));
        assert_memory_equal(&q.keys[k].up, &p.keys[k].up, sizeof(drift_vec3));
    }
    drift_camera_path_free(ctx, &q);
    drift_camera_path_free(ctx, &p);
    drift_context_destroy(ctx);
}

// Replaces the first `from` of the file's text (src: in the repository, or absolute) with `to` and
// writes it to the test folder.
static const char *mutate(const char *src, const char *from, const char *to, const char *name,
                          char *out)
{
    char path[1024];
    FILE *f = fopen(src[0] == '/' ? src : test_repo_path(path, src), "rb");
    assert_non_null(f);
    static char text[65536];
    size_t n = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    text[n] = '\0';
    char *at = strstr(text, from);
    assert_non_null(at);
    test_out_path(out, name);
    f = fopen(out, "wb");
    assert_non_null(f);
    fwrite(text, 1, (size_t)(at - text), f);
    fputs(to, f);
    fputs(at + strlen(from), f);
    fclose(f);
    return out;
}

// Malformed animations are refused with the file's name; nothing leaks (ASan).
static void test_errors(void **state)
{
    (void)state;

    static const struct {
        const char *from, *to;
        drift_result code;
    } cases[] = {
        { "\"count\": 2,\n   \"type\": \"VEC4\"", "\"count\": 3,\n   \"type\": \"VEC4\"",
          DRIFT_ERR_PARSE }, // an accessor past the end of its buffer view
        { "\"interpolation\": \"LINEAR\"", "\"interpolation\": \"CUBIC\"", DRIFT_ERR_PARSE },
        { "\"node\": 2,\n      \"path\": \"rotation\"",
          "\"node\": 99,\n      \"path\": \"rotation\"", DRIFT_ERR_PARSE },
        { "\"uri\": \"data:", "\"uri\": \"no_such.bin\", \"x\": \"", DRIFT_ERR_IO },
        { "\"camera\": 0,\n   \"translation\": [\n    0,",
          "\"camera\": 0,\n   \"translation\": [\n    1e30,", DRIFT_ERR_PARSE }, // absurd
        { "\"node\": 2,\n      \"path\": \"rotation\"", "\"node\": 2,\n      \"path\": \"weights\"",
          DRIFT_OK }, // morph weights: skipped (the camera still moves by its translation)
    };

    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        test_log_capture cap = { 0 };
        drift_context *ctx = test_context(1, &cap);
        char name[64], path[1024];
        snprintf(name, sizeof name, "gltf_anim_bad_%zu.gltf", i);
        mutate("tests/data/gltf/camera_linear.gltf", cases[i].from, cases[i].to, name, path);
        drift_camera_path p;
        drift_result r = drift_camera_path_from_gltf(ctx, path, NULL, 24.0, 0, 3, &p);
        if (r != cases[i].code) {
            fail_msg("case %zu: %s, expected %s (%s)", i, drift_result_string(r),
                     drift_result_string(cases[i].code), cap.last_message);
        }
        if (r != DRIFT_OK) {
            assert_int_equal(p.count, 0);
            assert_true(cap.errors > 0);
        }
        drift_camera_path_free(ctx, &p);
        drift_context_destroy(ctx);
    }
    // No channel on the camera or its parents: an error that says so.
    test_log_capture cap = { 0 };
    drift_context *ctx = test_context(1, &cap);
    char path[1024], path2[1024];
    mutate("tests/data/gltf/camera_linear.gltf", "\"node\": 2,\n      \"path\": \"rotation\"",
           "\"node\": 0,\n      \"path\": \"rotation\"", "gltf_anim_still_a.gltf", path);
    mutate(path, "\"node\": 3,\n      \"path\": \"translation\"",
           "\"node\": 1,\n      \"path\": \"translation\"", "gltf_anim_still.gltf", path2);
    drift_camera_path p;
    assert_int_equal(drift_camera_path_from_gltf(ctx, path2, NULL, 24.0, 0, 3, &p),
                     DRIFT_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(cap.last_message, "no animation moves the camera"));
    drift_context_destroy(ctx);
}

// Loading a file whose animation moves a mesh warns no more than a camera animation alone:
// drift plays both.
static void test_mesh_animation_loads_quietly(void **state)
{
    (void)state;
    int warnings[2];
    const char *files[2] = { "tests/data/gltf/camera_linear.gltf",
                             "tests/data/gltf/mesh_anim.gltf" };
    for (int i = 0; i < 2; ++i) {
        test_log_capture cap = { 0 };
        drift_context *ctx = test_context(1, &cap);
        char path[1024];
        drift_scene *scene = NULL;
        assert_int_equal(drift_scene_load(ctx, test_repo_path(path, files[i]), &scene), DRIFT_OK);
        warnings[i] = cap.warnings;
        drift_scene_destroy(scene);
        drift_context_destroy(ctx);
    }
    assert_int_equal(warnings[1], warnings[0]);
}

// A 24 x 24 path-traced image of the scene camera (4 spp, seed 9): its bytes are compared.
static drift_image render_pt(drift_context *ctx, const drift_scene *scene, drift_pt **pt)
{
    drift_accel *accel = NULL;
    assert_int_equal(drift_accel_create(ctx, scene, NULL, &accel), DRIFT_OK);
    drift_pt_params params = { .width = 24, .height = 24, .seed = 9 };
    assert_int_equal(drift_pt_create(ctx, scene, accel, &params, pt), DRIFT_OK);
    assert_int_equal(drift_pt_render_samples(*pt, 4, NULL), DRIFT_OK);
    drift_image image;
    assert_int_equal(drift_pt_resolve(*pt, DRIFT_PT_AOV_BEAUTY, &image), DRIFT_OK);
    drift_image copy;
    assert_int_equal(drift_image_create(ctx, image.width, image.height, image.channels, &copy),
                     DRIFT_OK);
    memcpy(copy.pixels, image.pixels, sizeof(float) * 24 * 24 * (size_t)image.channels);
    drift_pt_destroy(*pt);
    *pt = NULL;
    drift_accel_destroy(accel);
    return copy;
}

static void assert_same_image(const drift_image *a, const drift_image *b)
{
    assert_int_equal(a->channels, b->channels);
    assert_memory_equal(a->pixels, b->pixels,
                        sizeof(float) * (size_t)a->width * (size_t)a->height * (size_t)a->channels);
}

// The wall's node rises (0, 0, 0) -> (0, 1, 0) over 1 s. Posed at 0.5 s the wall's vertices,
// the path tracer's image and the hybrid frame (drift_hybrid_scene_changed over a new accel)
// equal, bit for bit, those of mesh_moved.gltf, whose wall stands at (0, 0.5, 0) with no
// animation (the translation is exact in binary, so the two roads give the same floats); the
// frame's motion vectors carry the wall's move (drift_hybrid_set_mesh_motion).
// Posed at 0 s (its rest pose) it is the scene as loaded again, bit for bit.
static void test_mesh_animation_poses_the_mesh(void **state)
{
    (void)state;
    test_log_capture cap = { 0 };
    drift_context *ctx = test_context(2, &cap);
    char path[1024], moved_path[1024];
    test_repo_path(path, "tests/data/gltf/mesh_anim.gltf");
    test_repo_path(moved_path, "tests/data/gltf/mesh_moved.gltf");
    drift_scene *scene = NULL, *moved = NULL;
    assert_int_equal(drift_scene_load(ctx, path, &scene), DRIFT_OK);
    assert_int_equal(drift_scene_load(ctx, moved_path, &moved), DRIFT_OK);
    assert_int_equal(scene->mesh_count, 2);
    assert_int_equal(scene->meshes[0].node, 0); // the loader recorded the file's nodes
    assert_int_equal(scene->meshes[1].node, 1);
    drift_pt *pt = NULL;
    drift_image at_load = render_pt(ctx, scene, &pt);
    drift_image twin = render_pt(ctx, moved, &pt);

    drift_scene_animation *anim = NULL;
    assert_int_equal(drift_scene_animation_from_gltf(ctx, path, scene, &anim), DRIFT_OK);
    assert_non_null(anim);
    assert_int_equal(drift_scene_animation_mesh_count(anim), 1);
    assert_int_equal(drift_scene_animation_light_count(anim), 0);
    assert_true(drift_scene_animation_camera_moves(anim));
    bool moved_now = true;
    assert_int_equal(drift_scene_animation_pose(anim, 0.0, &moved_now), DRIFT_OK);
    assert_false(moved_now); // the rest pose is frame 0's

    // A hybrid frame made at rest follows the move.
    drift_accel *accel = NULL;
    assert_int_equal(drift_accel_create(ctx, scene, NULL, &accel), DRIFT_OK);
    drift_hybrid_params hp = { .width = 24, .height = 24, .seed = 4 };
    drift_hybrid *frame = NULL;
    assert_int_equal(drift_hybrid_create(ctx, scene, accel, &hp, &frame), DRIFT_OK);
    assert_int_equal(drift_hybrid_render(frame, &scene->camera, NULL), DRIFT_OK);

    assert_int_equal(drift_scene_animation_pose(anim, 0.5, &moved_now), DRIFT_OK);
    assert_true(moved_now);
    const drift_mesh *wall = &scene->meshes[1];
    assert_int_equal(wall->vertex_count, moved->meshes[1].vertex_count);
    assert_memory_equal(wall->positions, moved->meshes[1].positions,
                        sizeof(float) * 3 * wall->vertex_count);
    assert_memory_equal(scene->meshes[0].positions, moved->meshes[0].positions,
                        sizeof(float) * 3 * scene->meshes[0].vertex_count);
    drift_image posed = render_pt(ctx, scene, &pt);
    assert_same_image(&posed, &twin);

    drift_accel *posed_accel = NULL, *twin_accel = NULL;
    assert_int_equal(drift_accel_create(ctx, scene, NULL, &posed_accel), DRIFT_OK);
    assert_int_equal(drift_hybrid_scene_changed(frame, posed_accel), DRIFT_OK);
    float motion[2 * 12];
    assert_int_equal(drift_scene_animation_motion(anim, motion, 2), DRIFT_OK);
    assert_int_equal(drift_hybrid_set_mesh_motion(frame, motion, 2), DRIFT_OK);
    assert_int_equal(drift_hybrid_render(frame, &scene->camera, NULL), DRIFT_OK);
    // Motion vectors (the camera stood still): the wall's points were 0.5 lower, the floor's
    // did not move.
    const drift_gbuffer *g = drift_hybrid_gbuffer(frame);
    drift_camera_frame cf = drift_camera_frame_make(&scene->camera, 24, 24);
    int wall_pixels = 0;
    for (int32_t y = 0; y < 24; ++y) {
        for (int32_t x = 0; x < 24; ++x) {
            size_t i = (size_t)y * 24 + (size_t)x;
            const float *mv = drift_image_pixel(&g->motion, x, y);
            drift_vec3 om = g->object_motion[i];
            if (g->mesh_index[i] == 0) {
                assert_true(fabsf(mv[0]) < 1e-3f && fabsf(mv[1]) < 1e-3f && drift_vec3_is_zero(om));
            } else if (g->mesh_index[i] == 1) {
                ++wall_pixels;
                assert_vec(om, 0.0, -0.5, 0.0, __LINE__);
                drift_vec2 was;
                assert_true(drift_camera_frame_project(
                    &cf, drift_vec3_add(drift_image_get3(&g->position, x, y), om), &was));
                test_assert_close(mv[0], was.x - ((float)x + 0.5f), 1e-3, __LINE__);
                test_assert_close(mv[1], was.y - ((float)y + 0.5f), 1e-3, __LINE__);
                assert_true(fabsf(mv[1]) > 0.5f); // half a metre is pixels here
            }
        }
    }
    assert_true(wall_pixels > 20);
    assert_int_equal(drift_accel_create(ctx, moved, NULL, &twin_accel), DRIFT_OK);
    drift_hybrid *twin_frame = NULL;
    assert_int_equal(drift_hybrid_create(ctx, moved, twin_accel, &hp, &twin_frame), DRIFT_OK);
    assert_int_equal(drift_hybrid_render(twin_frame, &moved->camera, NULL), DRIFT_OK);
    assert_same_image(drift_hybrid_image(frame), drift_hybrid_image(twin_frame));

    // Back at rest: the loaded scene, bit for bit.
    assert_int_equal(drift_scene_animation_pose(anim, 0.0, &moved_now), DRIFT_OK);
    assert_true(moved_now);
    drift_image back = render_pt(ctx, scene, &pt);
    assert_same_image(&back, &at_load);
    // The move is visible: the twin is not the rest pose.
    assert_true(memcmp(at_load.pixels, twin.pixels, sizeof(float) * 24 * 24 * 3) != 0);

    drift_hybrid_destroy(frame);
    drift_hybrid_destroy(twin_frame);
    drift_accel_destroy(accel);
    drift_accel_destroy(posed_accel);
    drift_accel_destroy(twin_accel);
    drift_scene_animation_destroy(anim);
    drift_image_destroy(ctx, &at_load);
    drift_image_destroy(ctx, &twin);
    drift_image_destroy(ctx, &posed);
    drift_image_destroy(ctx, &back);
    drift_scene_destroy(scene);
    drift_scene_destroy(moved);
    drift_context_destroy(ctx);
}

// A file whose animation moves only its camera gives no scene animation (NULL, no error).
static void test_camera_only_animation_moves_no_mesh(void **state)
{
    (void)state;
    test_log_capture cap = { 0 };
    drift_context *ctx = test_context(1, &cap);
    char path[1024];
    test_repo_path(path, "tests/data/gltf/camera_linear.gltf");
    drift_scene *scene = NULL;
    assert_int_equal(drift_scene_load(ctx, path, &scene), DRIFT_OK);
    drift_scene_animation *anim = (drift_scene_animation *)1;
    assert_int_equal(drift_scene_animation_from_gltf(ctx, path, scene, &anim), DRIFT_OK);
    assert_null(anim);
    drift_scene_destroy(scene);
    drift_context_destroy(ctx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_linear_slerp_parent),
        cmocka_unit_test(test_step_and_cubic),
        cmocka_unit_test(test_errors),
        cmocka_unit_test(test_mesh_animation_loads_quietly),
        cmocka_unit_test(test_mesh_animation_poses_the_mesh),
        cmocka_unit_test(test_camera_only_animation_moves_no_mesh),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
