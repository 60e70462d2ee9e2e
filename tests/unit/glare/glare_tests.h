// test_glare: what its parts (tests/unit/glare/*.c) share with the main file.
#ifndef DRIFT_TEST_GLARE_TESTS_H
#define DRIFT_TEST_GLARE_TESTS_H

#include "drift/glare.h"
#include "drift/image.h"
#include "drift_test.h"
#include "glare/glare_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846

double at(const float *img, int32_t n, int32_t x, int32_t y);
drift_image make_image(drift_context *ctx, int32_t w, int32_t h, uint32_t seed, int32_t border);
void test_glare_pupil_model_values_and_bounds(void **state);
void test_glare_symmetric_aperture_gives_point_symmetric_psf(void **state);
void test_glare_deterministic_and_fluid(void **state);
void test_glare_bit_identical_for_any_thread_count(void **state);
void test_glare_supersampling_lowers_temporal_variance(void **state);
void test_glare_psf_resampled_to_image_pitch(void **state);
void test_glare_billboards_match_convolution_for_bright_pixels(void **state);
void test_glare_params_defaults_and_bad_input(void **state);

#endif
