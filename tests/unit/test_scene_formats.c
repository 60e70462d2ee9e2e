// The scene loaders' registry (src/io/scene_formats.c, drift_scene_format_get): every format
// it lists loads a file of the repository through drift_scene_load, a path goes to the row
// of its extension (any case, through .gz only where the row reads gzip), a path no row
// reads is refused as unsupported, and the commands' --help lists every row. The JSON reader
// checks each object's keys against the key table of its own object (a sphere light's `radius`
// warns on a point light), and the scene-format reference prints every table.
#include "drift/scene_io.h"
#include "drift_test.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>

// A file of each format, in the repository. A new row without one fails the test.
static const struct {
    const char *extension, *path;
} samples[] = {
    { "json", "scenes/cornell-box/cornell_box.json" },
    { "obj", "scenes/cornell-box/cornell_box.obj" },
    { "gltf", "tests/data/gltf/blender_scene.gltf" },
    { "glb", "tests/data/gltf/camera_step_cubic.glb" },
    { "ply", "tests/fuzz/corpus/scene_ply/binary_triangle.ply" },
    { "xml", "tests/data/mitsuba/transforms_v06.xml" },
};

static const char *sample_of(const char *extension)
{
    for (size_t i = 0; i < sizeof samples / sizeof *samples; ++i) {
        if (strcmp(samples[i].extension, extension) == 0) {
            return samples[i].path;
        }
    }
    return NULL;
}

static void test_every_format_loads(void **state)
{
    (void)state;
    test_log_capture log = { 0 };
    drift_context *ctx = test_context(1, &log);
    int count = drift_scene_format_count();
    assert_true(count >= 6);
    assert_null(drift_scene_format_get(count));
    assert_null(drift_scene_format_get(-1));
    for (int i = 0; i < count; ++i) {
        const drift_scene_format *f = drift_scene_format_get(i);
        assert_non_null(f->summary);
        for (int j = 0; j < i; ++j) {
            assert_string_not_equal(drift_scene_format_get(j)->extension, f->extension);
        }
        const char *sample = sample_of(f->extension);
        if (!sample) {
            fail_msg("format .%s has no sample file in this test", f->extension);
        }
        char path[4096];
        snprintf(path, sizeof path, "%s/%s", DRIFT_SOURCE_DIR, sample);
        assert_ptr_equal(drift_scene_format_of(path), f);
        drift_scene *scene = NULL;
        drift_result r = drift_scene_load(ctx, path, &scene);
        if (r != DRIFT_OK) {
            fail_msg(".%s: %s did not load (%d)", f->extension, sample, (int)r);
        }
        drift_scene_destroy(scene);

        // The name's case does not matter; .gz only where the row reads gzip.
        char upper[64], name[96];
        size_t n = strlen(f->extension);
        for (size_t k = 0; k <= n && k < sizeof upper; ++k) {
            upper[k] = (char)(f->extension[k] >= 'a' && f->extension[k] <= 'z'
                                  ? f->extension[k] - 'a' + 'A'
                                  : f->extension[k]);
        }
        snprintf(name, sizeof name, "dir/scene.%s", upper);
        assert_ptr_equal(drift_scene_format_of(name), f);
        snprintf(name, sizeof name, "scene.%s.gz", f->extension);
        assert_ptr_equal(drift_scene_format_of(name), f->gz ? f : NULL);
    }
    const char *unread[] = { "scene.stl", "scene", "scene.json.zip", "scene.xml.gz", "" };
    for (size_t i = 0; i < sizeof unread / sizeof *unread; ++i) {
        assert_null(drift_scene_format_of(unread[i]));
        drift_scene *scene = NULL;
        char path[256];
        snprintf(path, sizeof path, "/tmp/%s", unread[i]);
        assert_int_equal(drift_scene_load(ctx, path, &scene), DRIFT_ERR_UNSUPPORTED);
        assert_null(scene);
        // The message lists what the registry reads.
        if (unread[i][0] && !strstr(log.last_message, ".obj, .gltf")) {
            fail_msg("'%s': the error names no formats: %s", unread[i], log.last_message);
        }
    }
    drift_context_destroy(ctx);
}

// `drift render --help` and `drift info --help` list every row: its extension and summary.
static void test_help_lists_every_format(void **state)
{
    (void)state;
    const char *bin = getenv("DRIFT_BIN");
    if (!bin) {
        skip();
    }
    const char *commands[] = { "render", "info" };
    for (size_t c = 0; c < sizeof commands / sizeof *commands; ++c) {
        char command[4096];
        snprintf(command, sizeof command, "'%s' %s --help 2>&1", bin, commands[c]);
        FILE *pipe = popen(command, "r");
        assert_non_null(pipe);
        static char help[1 << 16];
        size_t n = fread(help, 1, sizeof help - 1, pipe);
        help[n] = '\0';
        assert_int_equal(pclose(pipe), 0);
        for (int i = 0; drift_scene_format_get(i); ++i) {
            const drift_scene_format *f = drift_scene_format_get(i);
            char label[32];
            snprintf(label, sizeof label, "  .%s", f->extension);
            if (!strstr(help, label) || !strstr(help, f->summary)) {
                fail_msg("drift %s --help does not list .%s", commands[c], f->extension);
            }
        }
    }
}

// Unknown-key warnings read the key table by object: a key of another object (a sphere light's
// `radius` on a point light) warns; every key of the right object (all the camera's, a spot's
// `inner_angle`) does not.
static void test_json_keys_checked_by_object(void **state)
{
    (void)state;
    static const char text[] =
        "{ \"camera\": { \"position\": [0, 0, 5], \"target\": [0, 0, 0], \"up\": [0, 1, 0],\n"
        "    \"fov_y\": 40, \"aperture_radius\": 0, \"focus_distance\": 0, \"width\": 8,\n"
        "    \"height\": 8 },\n"
        "  \"environment\": { \"color\": 0.1 },\n"
        "  \"lights\": [\n"
        "    { \"type\": \"sphere\", \"center\": [0, 2, 0], \"radius\": 0.5, \"radiance\": 1 },\n"
        "    { \"type\": \"point\", \"position\": [0, 2, 0], \"intensity\": 5, \"radius\": 1 },\n"
        "    { \"type\": \"spot\", \"position\": [0, 2, 0], \"direction\": [0, -1, 0],\n"
        "      \"intensity\": 5, \"outer_angle\": 30, \"inner_angle\": 10 } ] }\n";
    test_log_capture log = { 0 };
    drift_context *ctx = test_context(1, &log);
    drift_scene *scene = NULL;
    assert_int_equal(drift_scene_load_json_text(ctx, text, strlen(text), NULL, "keys.json", &scene),
                     DRIFT_OK);
    assert_int_equal(log.errors, 0);
    assert_int_equal(log.warnings, 1);
    assert_non_null(strstr(log.last_message, "lights[1].radius"));
    assert_int_equal(scene->light_count, 3);
    drift_scene_destroy(scene);
    drift_context_destroy(ctx);
}

// The reference (docs/reference/scene-formats.md) prints every row of every reader's table.
static void test_reference_prints_every_table(void **state)
{
    (void)state;
    char *text = NULL;
    size_t size = 0;
    FILE *out = open_memstream(&text, &size);
    assert_non_null(out);
    drift_scene_formats_markdown(out);
    assert_int_equal(fclose(out), 0);
    const char *want[] = { "| `.json` | yes",
                           "| `.xml` | no",
                           "### camera",
                           "### light spot",
                           "| `inner_angle` | degrees | 0 |",
                           "| `KHR_texture_transform` ",
                           "| `map_Kd` ",
                           "| `bsdf plastic, roughplastic` " };
    for (size_t i = 0; i < sizeof want / sizeof *want; ++i) {
        if (!strstr(text, want[i])) {
            fail_msg("the scene-format reference has no '%s'", want[i]);
        }
    }
    free(text);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_every_format_loads),
        cmocka_unit_test(test_help_lists_every_format),
        cmocka_unit_test(test_json_keys_checked_by_object),
        cmocka_unit_test(test_reference_prints_every_table),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
