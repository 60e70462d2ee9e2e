// test_ssdo: what its parts (tests/unit/ssdo/*.c) share with the main file.
#ifndef DRIFT_TEST_SSDO_TESTS_H
#define DRIFT_TEST_SSDO_TESTS_H

#include "drift/ssdo.h"
#include "drift_test.h"
#include "test_rig.h"

#include <math.h>
#include <string.h>

#define PI 3.14159265358979323846

typedef struct ssdo_case {
    test_rig rig;
    drift_ssdo_env *env;
    drift_ssdo_output out;
} ssdo_case;

void case_begin(ssdo_case *c);
void case_render(ssdo_case *c, const drift_ssdo_params *p);
void case_end(ssdo_case *c);
void look_down(drift_scene *scene, float height, float half_extent, int32_t size);
void add_box(drift_scene *scene, float x0, float x1, float h, float d, uint32_t material);
const float *pixel(const drift_image *image, int32_t x, int32_t y);
void test_second_layer_opens_the_gap_behind_a_slab(void **state);
void test_additional_cameras_find_an_off_screen_blocker(void **state);
void test_contact_shadows_within_the_bias(void **state);
void test_contact_shadows_fix_the_frames_shadow_map(void **state);

#endif
