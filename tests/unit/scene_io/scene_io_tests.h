// test_scene_io: what its parts (tests/unit/scene_io/*.c) share with the main file.
#ifndef DRIFT_TEST_SCENE_IO_TESTS_H
#define DRIFT_TEST_SCENE_IO_TESTS_H

#include "drift/image_io.h"
#include "drift/scene.h"
#include "drift/scene_io.h"
#include "drift_test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <zlib.h>

// Remembers the first error's code, file and line (drift_test's capture keeps no location).
typedef struct located_log {
    int errors, warnings;
    drift_result first_error_code;
    int first_error_line; // first non-zero line among errors
    int min_warning_line;
    char first_error_file[1024];   // file of the first error
    char located_error_file[1024]; // file of the first error with a line
    char text[8192];               // every warning and error message, one a line
} located_log;

drift_context *located_context(located_log *log);
void write_file(const char *path, const char *text);
const char *scenes_dir(char *out);
void test_scene_io_gzip(void **state);
void test_scene_io_transforms_and_overrides(void **state);
void test_scene_io_every_light_type(void **state);
void test_scene_io_gltf_camera_lights_emission(void **state);
void test_scene_io_gltf_photometry_and_materials(void **state);
void test_scene_io_gltf_extensions_and_cameras(void **state);
void test_scene_io_mitsuba_subset(void **state);
void test_scene_io_mitsuba_face_normals(void **state);
void test_scene_io_textures_are_shared(void **state);
void test_scene_io_camera_views(void **state);

#endif
