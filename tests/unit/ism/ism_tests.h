// test_ism: what its parts (tests/unit/ism/*.c) share with the main file.
#ifndef DRIFT_TEST_ISM_TESTS_H
#define DRIFT_TEST_ISM_TESTS_H

#include "drift/accel.h"
#include "drift/hybrid.h"
#include "drift/ism.h"
#include "drift/metric.h"
#include "drift/pt.h"
#include "drift/scene.h"
#include "drift/scene_io.h"
#include "drift_test.h"
#include "ism/ism_internal.h"
#include "test_rig.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

test_rig cornell_rig(int threads, int32_t w);
drift_ism *render_ism(test_rig *r, const drift_ism_params *params);
void add_closed_box(drift_scene *scene, float albedo);
void test_gather_equals_the_formula(void **state);
void test_blur_is_the_window_average(void **state);
void test_gather_scale_upsamples_by_the_blur_tests(void **state);
void test_extent_ignores_a_distant_pure_emitter(void **state);
void test_slices_average_to_the_full_render(void **state);
void test_ism_is_deterministic(void **state);
void test_vpl_importance_is_unbiased(void **state);
void test_vpl_importance_keeps_useful_vpls(void **state);
void test_maps_grow_without_changing_the_image(void **state);
void test_rigid_motion_leaves_the_image(void **state);
void test_bounces_add_shrinking_light(void **state);
void test_parameters_and_planes(void **state);

#endif
