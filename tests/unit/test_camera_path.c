// Camera paths (drift/camera_path.h): interpolation through the keys, and errors naming the
// file and line.
#include "drift/camera_path.h"
#include "drift_test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct line_capture {
    int line;
    char message[512];
} line_capture;

static void capture_line(drift_log_level level, drift_result code, const char *file, int line,
                         const char *message, void *user)
{
    (void)level;
    (void)code;
    (void)file;
    line_capture *c = user;
    c->line = line;
    snprintf(c->message, sizeof c->message, "%s", message);
}

static drift_context *line_context(line_capture *c)
{
    drift_context *ctx = NULL;
    drift_context_desc desc = { .thread_count = 1, .logger = { .func = capture_line, .user = c } };
    assert_int_equal(drift_context_create(&desc, &ctx), DRIFT_OK);
    return ctx;
}

static const char path_text[] =
    "{\"fps\": 10, \"keyframes\": [\n"
    "  {\"time\": 0, \"position\": [0, 0, 5], \"target\": [0, 0, 0], \"fov_y\": 40},\n"
    "  {\"time\": 1, \"position\": [2, 0, 5], \"target\": [0, 0, 0], \"fov_y\": 50},\n"
    "  {\"time\": 2, \"position\": [3, 1, 4], \"target\": [0, 1, 0]},\n"
    "  {\"time\": 4, \"position\": [3, 1, 2], \"target\": [0, 1, 0], \"aperture_radius\": 0.1}\n"
    "]}\n";

// The spline passes through every key, holds the ends outside them, and is continuous.
static void test_camera_path_keys(void **state)
{
    (void)state;
    line_capture c = { 0 };
    drift_context *ctx = line_context(&c);
    drift_camera_path path;
    assert_int_equal(
        drift_camera_path_load_json_text(ctx, path_text, strlen(path_text), "p.json", &path),
        DRIFT_OK);
    assert_int_equal(path.count, 4);
    assert_near(path.fps, 10.0, 0.0);
    drift_camera base = drift_camera_look_at(drift_vec3_make(9, 9, 9), drift_vec3_make(0, 0, 0),
                                             drift_vec3_make(0, 1, 0), 0.5f, 32, 32);
    for (uint32_t k = 0; k < path.count; ++k) {
        drift_camera cam = drift_camera_path_eval(&path, &base, path.keys[k].time);
        assert_near(cam.position.x, path.keys[k].position.x, 1e-5);
        assert_near(cam.position.y, path.keys[k].position.y, 1e-5);
        assert_near(cam.position.z, path.keys[k].position.z, 1e-5);
        assert_near(cam.target.y, path.keys[k].target.y, 1e-5);
        assert_near(cam.fov_y, path.keys[k].has_fov ? path.keys[k].fov_y : base.fov_y, 1e-6);
    }
    drift_camera before = drift_camera_path_eval(&path, &base, -1.0);
    drift_camera after = drift_camera_path_eval(&path, &base, 9.0);
    assert_near(before.position.x, 0.0, 0.0);
    assert_near(after.position.z, 2.0, 0.0);
    assert_near(after.aperture_radius, 0.1, 1e-6);
    // Continuity: a small step in time moves the camera a small distance.
    drift_camera prev = drift_camera_path_eval(&path, &base, 0.0);
    for (int k = 1; k <= 400; ++k) {
        drift_camera cam = drift_camera_path_eval(&path, &base, 0.01 * k);
        float step = drift_vec3_length(drift_vec3_sub(cam.position, prev.position));
        assert_true((double)step < 0.06);
        prev = cam;
    }
    // Linear interpolation: the midpoint of a segment is the keys' mean.
    path.interpolation = DRIFT_CAMERA_PATH_LINEAR;
    drift_camera mid = drift_camera_path_eval(&path, &base, 0.5);
    assert_near(mid.position.x, 1.0, 1e-6);
    assert_near(mid.fov_y, 0.5f * (path.keys[0].fov_y + path.keys[1].fov_y), 1e-6);
    drift_camera_path_free(ctx, &path);
    drift_context_destroy(ctx);
}

// Bad files fail with the line of the offending value.
static void test_camera_path_errors(void **state)
{
    (void)state;

    static const struct {
        const char *text;
        int line;
        drift_result code;
    } cases[] = {
        { "{\"keyframes\": [\n{\"time\": 0, \"position\": [0,0,1], \"target\": [0,0,0]},\n"
          "{\"time\": 0, \"position\": [0,0,2], \"target\": [0,0,0]}]}",
          3, DRIFT_ERR_INVALID_ARGUMENT },
        { "{\"keyframes\": [\n{\"time\": 0,\n \"position\": [0,0],\n \"target\": [0,0,0]}]}", 3,
          DRIFT_ERR_PARSE },
        { "{\"keyframes\": [\n{\"time\": 0, \"position\": [0,0,1], \"target\": [0,0,0],\n"
          "\"fov_y\": 200}]}",
          3, DRIFT_ERR_INVALID_ARGUMENT },
        { "{\"fps\": 24,\n\"keyframes\": [\n}", 3, DRIFT_ERR_PARSE },
        { "{\"keyframes\": [],\n \"colour\": 1}", 2, DRIFT_ERR_PARSE },
    };

    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        line_capture c = { 0 };
        drift_context *ctx = line_context(&c);
        drift_camera_path path;
        drift_result r = drift_camera_path_load_json_text(ctx, cases[k].text, strlen(cases[k].text),
                                                          "p.json", &path);
        if (r != cases[k].code || c.line != cases[k].line) {
            fail_msg("case %zu: %s at line %d (%s), expected %s at line %d", k,
                     drift_result_string(r), c.line, c.message, drift_result_string(cases[k].code),
                     cases[k].line);
        }
        assert_null(path.keys);
        drift_context_destroy(ctx);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_camera_path_keys),
        cmocka_unit_test(test_camera_path_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
