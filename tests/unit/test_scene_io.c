// Scene loading: the default Cornell box, the real scenes in ../shared/scenes, JSON errors
// with their lines, unknown keys, gzip, transforms, glTF cameras and lights, textures, and
// the camera views files of drift bench sir --views.
#include "drift/image_io.h"
#include "drift/scene.h"
#include "drift/scene_io.h"
#include "drift_test.h"
#include "scene_io/scene_io_tests.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <zlib.h>

static void located_log_func(drift_log_level level, drift_result code, const char *file, int line,
                             const char *message, void *user)
{
    located_log *log = user;
    if (getenv("DRIFT_TEST_VERBOSE")) {
        fprintf(stderr, "[log %d] %s:%d: %s\n", (int)level, file ? file : "-", line, message);
    }
    if (level >= DRIFT_LOG_WARNING) {
        size_t used = strlen(log->text);
        snprintf(log->text + used, sizeof(log->text) - used, "%s\n", message);
    }
    if (level == DRIFT_LOG_WARNING) {
        if (log->warnings++ == 0 || line < log->min_warning_line) {
            log->min_warning_line = line;
        }
    }
    if (level == DRIFT_LOG_ERROR) {
        if (log->errors++ == 0) {
            log->first_error_code = code;
            snprintf(log->first_error_file, sizeof(log->first_error_file), "%s", file ? file : "");
        }
        if (log->first_error_line == 0 && line > 0) {
            log->first_error_line = line;
            snprintf(log->located_error_file, sizeof(log->located_error_file), "%s",
                     file ? file : "");
        }
    }
}

drift_context *located_context(located_log *log)
{
    *log = (located_log){ 0 };
    drift_context *ctx = NULL;
    drift_result r = drift_context_create(
        &(drift_context_desc){ .thread_count = 1,
                               .logger = { .func = located_log_func, .user = log } },
        &ctx);
    assert_int_equal(r, DRIFT_OK);
    return ctx;
}

void write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
}

const char *scenes_dir(char *out)
{
    return test_repo_path(out, "scenes/cornell-box");
}

// --- THE DEFAULT SCENE ---

static void test_scene_io_default_cornell_box(void **state)
{
    (void)state;
    located_log log;
    drift_context *ctx = located_context(&log);
    char path[1024];
    drift_scene *scene = NULL;
    assert_int_equal(
        drift_scene_load(ctx, test_repo_path(path, "scenes/cornell-box/cornell_box.json"), &scene),
        DRIFT_OK);
    assert_true(scene->committed);
    assert_int_equal(drift_scene_triangle_count(scene), 32);
    // The light is the emissive quad of the OBJ: two triangle lights and nothing else.
    assert_int_equal(scene->light_count, 2);
    for (uint32_t i = 0; i < scene->light_count; ++i) {
        assert_int_equal(scene->lights[i].type, DRIFT_LIGHT_TRIANGLE);
        assert_float_equal(scene->lights[i].color.x, 20.74f, 1e-4f);
        assert_float_equal(scene->lights[i].color.y, 10.86f, 1e-4f);
        assert_float_equal(scene->lights[i].color.z, 2.77f, 1e-4f);
    }
    // Bounds of the measured data (mm): floor corner 552.8/549.6, ceiling 556.0, depth 559.2.
    assert_float_equal(scene->bounds.min.x, 0.0f, 1e-4f);
    assert_float_equal(scene->bounds.min.y, 0.0f, 1e-4f);
    assert_float_equal(scene->bounds.min.z, 0.0f, 1e-4f);
    assert_float_equal(scene->bounds.max.x, 556.0f, 1e-3f);
    assert_float_equal(scene->bounds.max.y, 548.8f, 1e-3f);
    assert_float_equal(scene->bounds.max.z, 559.2f, 1e-3f);
    const drift_camera *cam = &scene->camera;
    assert_float_equal(cam->position.x, 278.0f, 1e-4f);
    assert_float_equal(cam->position.y, 273.0f, 1e-4f);
    assert_float_equal(cam->position.z, -800.0f, 1e-4f);
    assert_float_equal(cam->fov_y * 180.0f / DRIFT_PI, 39.3077f, 1e-3f);
    assert_int_equal(cam->width, 512);
    assert_int_equal(cam->height, 512);
    // The red wall (x ~ 556) must be on the image left: a ray through the left edge heads +x.
    drift_ray left = drift_camera_ray(cam, 512, 512, 0.5f, 256.0f, drift_vec2_make(0.5f, 0.5f));
    drift_ray right = drift_camera_ray(cam, 512, 512, 511.5f, 256.0f, drift_vec2_make(0.5f, 0.5f));
    assert_true(left.dir.x > 0.1f);
    assert_true(right.dir.x < -0.1f);
    bool found_red = false;
    for (uint32_t m = 0; m < scene->mesh_count; ++m) {
        const drift_mesh *mesh = &scene->meshes[m];
        const drift_material *mat = &scene->materials[mesh->material];
        if (mat->diffuse.x > 3.0f * mat->diffuse.y) {
            found_red = true;
            for (uint32_t v = 0; v < mesh->vertex_count; ++v) {
                assert_true(mesh->positions[3 * v] > 540.0f);
            }
        }
    }
    assert_true(found_red);
    assert_int_equal(log.errors, 0);
    drift_scene_destroy(scene);
    drift_context_destroy(ctx);
}

// --- REAL SCENES ---

typedef struct real_scene {
    const char *path; // under ../shared/scenes
    uint64_t triangles;
} real_scene;

static void test_scene_io_real_scenes(void **state)
{
    (void)state;
    char dir[1024];
    struct stat st;
    if (stat(test_shared_path(dir, "scenes"), &st) != 0) {
        fprintf(stderr, "skipped: %s is absent\n", dir);
        skip();
    }
    // Expected counts: the READMEs' counts; the full dragon loses 110 zero-area triangles.
    static const real_scene scenes[] = {
        { "cornell-box/cornell_box_official.obj", 32 },
        { "cornell-box/CornellBox-Original.obj", 36 },
        { "stanford-bunny/bunny.obj", 69451 },
        { "stanford-dragon/dragon_vrip.ply.gz", 871304 },
        { "stanford-dragon/dragon_vrip_res2.ply.gz", 202520 },
        { "stanford-dragon/dragon_vrip_res3.ply.gz", 47794 },
        { "stanford-dragon/dragon_vrip_res4.ply.gz", 11102 },
        { "breakfast-room/breakfast_room.obj", 269858 },
        { "utah-teapot/teapot_bezier_16x16.obj", 16256 },
        { "utah-teapot/teapot_newell_6320.obj", 6320 },
        { "veach-mi/veach_mi.obj", 12 },
        { "plants-and-blinds/palm-plant/plant.obj", 14370 },
        { "plants-and-blinds/window-blinds/window-blinds.obj", 1252 },
    };
    for (size_t i = 0; i < sizeof(scenes) / sizeof(scenes[0]); ++i) {
        located_log log;
        drift_context *ctx = located_context(&log);
        char rel[512], path[1024];
        snprintf(rel, sizeof(rel), "scenes/%s", scenes[i].path);
        test_shared_path(path, rel);
        drift_scene *scene = NULL;
        drift_result r = drift_scene_load(ctx, path, &scene);
        if (r != DRIFT_OK) {
            fail_msg("%s: %s", scenes[i].path, drift_result_string(r));
        }
        if (drift_scene_triangle_count(scene) != scenes[i].triangles) {
            fail_msg("%s: %llu triangles, expected %llu", scenes[i].path,
                     (unsigned long long)drift_scene_triangle_count(scene),
                     (unsigned long long)scenes[i].triangles);
        }
        assert_true(scene->light_count > 0);
        assert_false(drift_bounds3_is_empty(scene->bounds));
        drift_scene_destroy(scene);
        drift_context_destroy(ctx);
    }
}

static void test_scene_io_bare_mesh_gets_camera_and_light(void **state)
{
    (void)state;
    char path[1024];
    test_out_path(path, "scene_io_triangle.obj");
    write_file(path, "v -1 0 0\nv 1 0 0\nv 0 2 0\nf 1 2 3\n");
    located_log log;
    drift_context *ctx = located_context(&log);
    drift_scene *scene = NULL;
    assert_int_equal(drift_scene_load(ctx, path, &scene), DRIFT_OK);
    assert_int_equal(scene->light_count, 1);
    assert_int_equal(scene->lights[0].type, DRIFT_LIGHT_DIRECTIONAL);
    assert_float_equal(scene->environment.color.x, 0.2f, 1e-6f);
    // Framing camera: looks at the bounds centre (0, 1, 0) from +z, 45 degrees.
    const drift_camera *cam = &scene->camera;
    assert_float_equal(cam->target.x, 0.0f, 1e-6f);
    assert_float_equal(cam->target.y, 1.0f, 1e-6f);
    assert_float_equal(cam->position.x, 0.0f, 1e-6f);
    assert_true(cam->position.z > 1.0f);
    assert_float_equal(cam->fov_y, 45.0f * DRIFT_PI / 180.0f, 1e-6f);
    // No normals in the file: none are generated (flat shading).
    assert_null(scene->meshes[0].normals);
    // The light travels away from the camera side (toward -z) and downward.
    assert_true(scene->lights[0].direction.z < 0.0f);
    assert_true(scene->lights[0].direction.y < 0.0f);
    drift_scene_destroy(scene);
    drift_context_destroy(ctx);
}

// --- BAD INPUT ---

typedef struct bad_json {
    const char *what;
    const char *text;
    drift_result code;
    int line; // the line the error must name
} bad_json;

static void test_scene_io_bad_json_reports_code_and_line(void **state)
{
    (void)state;
    static const bad_json cases[] = {
        { "malformed", "{\n  \"camera\": {\n    \"position\": [1, 2,\n  }\n}\n", DRIFT_ERR_PARSE,
          4 },
        { "truncated", "{\n  \"meshes\": [\n", DRIFT_ERR_PARSE, 3 },
        { "trailing garbage", "{}\n\nxyz\n", DRIFT_ERR_PARSE, 3 },
        { "empty", "", DRIFT_ERR_PARSE, 1 },
        { "not an object", "[1, 2]\n", DRIFT_ERR_PARSE, 1 },
        { "wrong type",
          "{\n  \"camera\": {\n    \"position\": [0,0,1], \"target\": [0,0,0],\n"
          "    \"fov_y\": \"wide\"\n  }\n}\n",
          DRIFT_ERR_PARSE, 4 },
        { "vector of 2", "{\n \"camera\": {\n  \"position\": [0, 1],\n  \"target\": [0,0,0] }\n}",
          DRIFT_ERR_PARSE, 3 },
        { "infinite",
          "{\n \"lights\": [\n  { \"type\": \"point\",\n    \"position\": [0, 1e999, 0],\n"
          "    \"intensity\": 1 }\n ]\n}\n",
          DRIFT_ERR_INVALID_ARGUMENT, 4 },
        { "float overflow",
          "{\n \"lights\": [ { \"type\": \"point\", \"position\": [0,0,0],\n"
          "   \"intensity\": 1e300 } ]\n}\n",
          DRIFT_ERR_INVALID_ARGUMENT, 3 },
        { "negative radius",
          "{\n \"lights\": [\n  {\n   \"type\": \"sphere\", \"center\": [0,0,0],\n"
          "   \"radius\": -1, \"radiance\": 1\n  }\n ]\n}\n",
          DRIFT_ERR_INVALID_ARGUMENT, 3 },
        { "zero-area quad",
          "{\n \"lights\": [\n  { \"type\": \"quad\", \"corner\": [0,0,0],\n"
          "    \"edge_u\": [1,0,0], \"edge_v\": [2,0,0], \"radiance\": 1 }\n ]\n}\n",
          DRIFT_ERR_INVALID_ARGUMENT, 3 },
        { "zero disk",
          "{\"lights\": [\n{\"type\": \"disk\", \"center\": [0,0,0], \"normal\": [0,1,0],"
          " \"radius\": 0, \"radiance\": 1}]}",
          DRIFT_ERR_INVALID_ARGUMENT, 2 },
        { "negative colour",
          "{\n \"materials\": {\n  \"m\": { \"diffuse\": [0.5, -0.1, 0.5] }\n }\n}\n",
          DRIFT_ERR_INVALID_ARGUMENT, 3 },
        { "diffuse roughness over 1",
          "{\n \"materials\": {\n  \"m\": {\n \"diffuse_roughness\": 1.5 }\n }\n}\n",
          DRIFT_ERR_INVALID_ARGUMENT, 4 },
        { "diffuse roughness on a mirror",
          "{\n \"materials\": {\n  \"m\": { \"type\": \"mirror\",\n"
          "   \"diffuse_roughness\": 0.5 }\n }\n}\n",
          DRIFT_ERR_INVALID_ARGUMENT, 4 },
        { "absurd width",
          "{\n \"camera\": { \"position\": [0,0,1], \"target\": [0,0,0],\n"
          "   \"width\": 1000000000 }\n}\n",
          DRIFT_ERR_INVALID_ARGUMENT, 3 },
        { "fractional height",
          "{\n \"camera\": { \"position\": [0,0,1], \"target\": [0,0,0],\n\n"
          "   \"height\": 1.5 }\n}\n",
          DRIFT_ERR_INVALID_ARGUMENT, 4 },
        { "fov out of range",
          "{\"camera\": {\"position\": [0,0,1], \"target\": [0,0,0],\n"
          "\"fov_y\": 180}}",
          DRIFT_ERR_INVALID_ARGUMENT, 2 },
        { "up parallel",
          "{\"camera\": {\"position\": [0,0,1], \"target\": [0,0,0],\n"
          "\"up\": [0,0,2]}}",
          DRIFT_ERR_INVALID_ARGUMENT, 2 },
        { "missing mesh file", "{\n \"meshes\": [\n  { \"path\": \"no_such_file.obj\" }\n ]\n}\n",
          DRIFT_ERR_IO, 3 },
        { "mesh extension", "{\n \"meshes\": [ { \"path\": \"mesh.fbx\" } ]\n}\n",
          DRIFT_ERR_UNSUPPORTED, 2 },
        { "unknown material",
          "{\n \"meshes\": [\n  { \"path\": \"cornell_box.obj\",\n"
          "    \"material\": \"nope\" }\n ]\n}\n",
          DRIFT_ERR_INVALID_ARGUMENT, 4 },
        { "missing key", "{\n \"lights\": [\n  { \"type\": \"point\", \"intensity\": 1 }\n ]\n}\n",
          DRIFT_ERR_PARSE, 3 },
        { "unknown light type", "{\n \"lights\": [\n  { \"type\": \"laser\" }\n ]\n}\n",
          DRIFT_ERR_INVALID_ARGUMENT, 3 },
        { "duplicate key",
          "{\n \"camera\": { \"position\": [0,0,1], \"target\": [0,0,0],\n"
          "   \"position\": [0,0,2] }\n}\n",
          DRIFT_ERR_PARSE, 3 },
        { "spot cone",
          "{\"lights\": [\n{\"type\": \"spot\", \"position\": [0,0,0], \"direction\": [0,-1,0],"
          " \"intensity\": 1, \"inner_angle\": 40, \"outer_angle\": 30}]}",
          DRIFT_ERR_INVALID_ARGUMENT, 2 },
        { "zero scale",
          "{\"meshes\": [{\"path\": \"cornell_box.obj\",\n\"transform\": {\"scale\": 0}}]}",
          DRIFT_ERR_INVALID_ARGUMENT, 2 },
        { "non-affine matrix",
          "{\"meshes\": [{\"path\": \"cornell_box.obj\", \"transform\":\n"
          "{\"matrix\": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,1,1]}}]}",
          DRIFT_ERR_INVALID_ARGUMENT, 2 },
        { "matrix and translate",
          "{\"meshes\": [{\"path\": \"cornell_box.obj\", \"transform\":\n"
          "{\"translate\": [1,0,0],\n\"matrix\": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1]}}]}",
          DRIFT_ERR_INVALID_ARGUMENT, 3 },
        { "glossy without exponent",
          "{\"materials\": {\n\"g\": {\"type\": \"glossy\", \"specular\": 0.5}}}", DRIFT_ERR_PARSE,
          2 },
        { "specular on diffuse", "{\"materials\": {\"d\": {\n\"specular\": 0.5}}}",
          DRIFT_ERR_INVALID_ARGUMENT, 2 },
        { "version", "{\n\"version\": 2}", DRIFT_ERR_UNSUPPORTED, 2 },
        { "missing texture", "{\"materials\": {\"d\": {\n\"diffuse_texture\": \"missing.png\"}}}",
          DRIFT_ERR_IO, 2 },
        { "environment both", "{\"environment\": {\"map\": \"sky.hdr\",\n\"color\": 1}}",
          DRIFT_ERR_INVALID_ARGUMENT, 2 },
    };
    char dir[1024];
    scenes_dir(dir);
    for (size_t i = 0; i < sizeof(cases) / sizeof(cases[0]); ++i) {
        located_log log;
        drift_context *ctx = located_context(&log);
        drift_scene *scene = (drift_scene *)&log; // must be reset to NULL
        drift_result r = drift_scene_load_json_text(ctx, cases[i].text, strlen(cases[i].text), dir,
                                                    "bad.json", &scene);
        if (r != cases[i].code) {
            fail_msg("%s: got %s, expected %s", cases[i].what, drift_result_string(r),
                     drift_result_string(cases[i].code));
        }
        assert_null(scene);
        if (log.errors == 0 || strcmp(log.located_error_file, "bad.json") != 0) {
            fail_msg("%s: no error naming bad.json was logged", cases[i].what);
        }
        if (log.first_error_line != cases[i].line) {
            fail_msg("%s: error at line %d, expected %d", cases[i].what, log.first_error_line,
                     cases[i].line);
        }
        drift_context_destroy(ctx);
    }
}

static void test_scene_io_embedded_nul_is_a_parse_error(void **state)
{
    (void)state;
    located_log log;
    drift_context *ctx = located_context(&log);
    static const char text[] = "{}\n\0{\"x\": 1}";
    drift_scene *scene = NULL;
    assert_int_equal(
        drift_scene_load_json_text(ctx, text, sizeof(text) - 1, NULL, "nul.json", &scene),
        DRIFT_ERR_PARSE);
    assert_null(scene);
    assert_int_equal(log.first_error_line, 2);
    drift_context_destroy(ctx);
}

typedef struct bad_file {
    const char *name;
    const char *content;
    drift_result code;
} bad_file;

static void test_scene_io_bad_mesh_files(void **state)
{
    (void)state;
    static const bad_file cases[] = {
        { "scene_io_bad_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99\n", DRIFT_ERR_PARSE },
        { "scene_io_empty.obj", "", DRIFT_ERR_PARSE },
        { "scene_io_no_faces.obj", "v 0 0 0\nv 1 0 0\n", DRIFT_ERR_PARSE },
        { "scene_io_garbage.ply", "ply\nthis is not a ply file\n", DRIFT_ERR_PARSE },
        // A header claiming 10^9 vertices must fail fast, not allocate gigabytes.
        { "scene_io_huge.ply",
          "ply\nformat ascii 1.0\nelement vertex 1000000000\nproperty float x\n"
          "property float y\nproperty float z\nelement face 1\n"
          "property list uchar int vertex_indices\nend_header\n0 0 0\n",
          DRIFT_ERR_PARSE },
        { "scene_io_nan.obj", "v 0 0 0\nv 1 0 0\nv 0 nan 0\nf 1 2 3\n",
          DRIFT_ERR_INVALID_ARGUMENT },
        { "scene_io_degenerate.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n",
          DRIFT_ERR_INVALID_ARGUMENT },
        { "scene_io_not_gzip.obj.gz", "v 0 0 0\n", DRIFT_ERR_PARSE },
        { "scene_io_unknown.fbx", "whatever", DRIFT_ERR_UNSUPPORTED },
    };
    for (size_t i = 0; i < sizeof(cases) / sizeof(cases[0]); ++i) {
        char path[1024];
        test_out_path(path, cases[i].name);
        write_file(path, cases[i].content);
        located_log log;
        drift_context *ctx = located_context(&log);
        drift_scene *scene = NULL;
        drift_result r = drift_scene_load(ctx, path, &scene);
        if (r != cases[i].code) {
            fail_msg("%s: got %s, expected %s", cases[i].name, drift_result_string(r),
                     drift_result_string(cases[i].code));
        }
        assert_null(scene);
        assert_true(log.errors > 0);
        drift_context_destroy(ctx);
    }
    // A directory and a missing file are I/O errors.
    located_log log;
    drift_context *ctx = located_context(&log);
    drift_scene *scene = NULL;
    char path[1024];
    test_out_path(path, "scene_io_dir.obj");
    mkdir(path, 0755);
    assert_int_equal(drift_scene_load(ctx, path, &scene), DRIFT_ERR_IO);
    test_out_path(path, "scene_io_missing.json");
    remove(path);
    drift_context_destroy(ctx);
    ctx = located_context(&log);
    assert_int_equal(drift_scene_load(ctx, path, &scene), DRIFT_ERR_IO);
    assert_string_equal(log.first_error_file, path);
    assert_int_equal(drift_scene_load(ctx, NULL, &scene), DRIFT_ERR_INVALID_ARGUMENT);
    assert_null(scene);
    drift_context_destroy(ctx);
}

static void test_scene_io_unknown_keys_warn_but_load(void **state)
{
    (void)state;
    static const char text[] = "{\n"
                               "  \"camera\": { \"position\": [0, 0, 5], \"target\": [0, 0, 0],\n"
                               "              \"fov\": 40 },\n"
                               "  \"comment\": \"comments are allowed anywhere\",\n"
                               "  \"lights\": [ { \"type\": \"point\", \"position\": [0, 2, 0],\n"
                               "                \"intensity\": 5, \"colour\": [1, 0, 0] } ],\n"
                               "  \"extra\": true\n"
                               "}\n";
    located_log log;
    drift_context *ctx = located_context(&log);
    drift_scene *scene = NULL;
    assert_int_equal(drift_scene_load_json_text(ctx, text, strlen(text), NULL, "warn.json", &scene),
                     DRIFT_OK);
    assert_int_equal(log.warnings, 3);
    assert_int_equal(log.min_warning_line, 3);
    assert_int_equal(log.errors, 0);
    assert_int_equal(scene->light_count, 1);
    drift_scene_destroy(scene);
    drift_context_destroy(ctx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_scene_io_default_cornell_box),
        cmocka_unit_test(test_scene_io_real_scenes),
        cmocka_unit_test(test_scene_io_bare_mesh_gets_camera_and_light),
        cmocka_unit_test(test_scene_io_bad_json_reports_code_and_line),
        cmocka_unit_test(test_scene_io_embedded_nul_is_a_parse_error),
        cmocka_unit_test(test_scene_io_bad_mesh_files),
        cmocka_unit_test(test_scene_io_unknown_keys_warn_but_load),
        cmocka_unit_test(test_scene_io_gzip),
        cmocka_unit_test(test_scene_io_transforms_and_overrides),
        cmocka_unit_test(test_scene_io_every_light_type),
        cmocka_unit_test(test_scene_io_gltf_camera_lights_emission),
        cmocka_unit_test(test_scene_io_gltf_photometry_and_materials),
        cmocka_unit_test(test_scene_io_gltf_extensions_and_cameras),
        cmocka_unit_test(test_scene_io_mitsuba_subset),
        cmocka_unit_test(test_scene_io_mitsuba_face_normals),
        cmocka_unit_test(test_scene_io_textures_are_shared),
        cmocka_unit_test(test_scene_io_camera_views),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
