// test_hybrid: what its parts (tests/unit/hybrid/*.c) share with the main file.
#ifndef DRIFT_TEST_HYBRID_TESTS_H
#define DRIFT_TEST_HYBRID_TESTS_H

#include "drift/accel.h"
#include "drift/hybrid.h"
#include "drift/metric.h"
#include "drift/pt.h"
#include "drift/scene.h"
#include "drift_test.h"
#include "raster/raster.h"
#include "test_rig.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PI_F 3.14159265f
#define M_PI 3.14159265358979323846

void test_unshadowed_quad_matches_monte_carlo(void **state);
void test_polygon_rows_equal_the_pixel_path(void **state);
void test_unshadowed_sphere_matches_monte_carlo(void **state);
void test_tessellated_sphere_light_in_closed_form(void **state);
void test_aa_hard_shadows_draw_the_penumbra(void **state);
void test_hard_shadows_any_hit_match_closest_hit(void **state);
void test_environment_interleave_beats_equal_rays(void **state);
void test_environment_filter_beats_two_rays(void **state);
void test_environment_scale_two_carries_the_light(void **state);
void test_constant_sky_is_exact_with_one_sample(void **state);
void test_two_sided_mesh_light_closed_form(void **state);
void test_two_sided_emitter_lights_hybrid_frame(void **state);
void test_closed_two_sided_emitter_is_one_sided(void **state);

#endif
