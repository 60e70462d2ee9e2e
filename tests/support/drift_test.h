// Test support: cmocka includes in the right order, a capture logger, paths, and helpers
// shared by the unit tests.
#ifndef DRIFT_TEST_H
#define DRIFT_TEST_H

// cmocka needs these before its header (clang-format's include sorting would move it first).
// clang-format off
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>
// clang-format on

#include "drift/core.h"
#include "drift/math.h"

// Remembers the codes and levels of messages so tests can assert on codes, not text.
typedef struct test_log_capture {
    int count;
    int warnings;
    int errors;
    drift_result last_code;
    char last_message[512];
} test_log_capture;

drift_logger test_capture_logger(test_log_capture *capture);

// A context with `threads` threads and the capture logger (capture may be NULL: silent).
drift_context *test_context(int threads, test_log_capture *capture);

// Path of a file under the repository root / under ../shared (NULL-free; static buffer per call
// site is not used: writes into out, which must hold 1024 bytes).
const char *test_repo_path(char *out, const char *relative);
const char *test_shared_path(char *out, const char *relative);
// Directory for test outputs (created on demand): build/test-out.
const char *test_out_path(char *out, const char *name);

// Fails with both values and the line when |a - b| > eps (cmocka's float asserts are float-only).
void test_assert_close(double a, double b, double eps, int line);
#define assert_near(a, b, eps) test_assert_close((double)(a), (double)(b), (eps), __LINE__)

// A deterministic value in [0, 1) for test data.
float test_hash_unit(uint32_t i);

// Adds a mesh to a test scene and returns its index; fails the test if the scene rejects it.
struct drift_scene;
uint32_t test_add_mesh(struct drift_scene *scene, const float *positions, uint32_t vertex_count,
                       const uint32_t *indices, uint32_t triangle_count, uint32_t material);

// The BSDF of material m at a surface at the origin with normal +z (front_face: wo above it),
// from a scene of that one material.
struct drift_material;
struct drift_bsdf test_bsdf_of_material(const struct drift_material *m, bool front_face);

// The chi-square test of `sampled`'s sampling toward wo against `pdf`'s density (the same
// BSDF, or another one in a test that the check can fail).
bool test_bsdf_chi_square_passes(const char *what, const struct drift_bsdf *sampled,
                                 const struct drift_bsdf *pdf, drift_vec3 wo, int sample_count,
                                 char *why, size_t why_size);

// Directional albedo (red channel) of a BSDF toward wo by its own sampling: the mean of
// f |cos| / pdf over samples 0 .. n - 1 of the sampler (seed, pixel).
struct drift_bsdf;
double test_bsdf_albedo_sampled(const struct drift_bsdf *bsdf, drift_vec3 wo, int n, uint32_t seed,
                                uint32_t pixel);

// DRIFT_TEST_INTENSITY (default 1) scales sample counts in statistical tests.
double test_intensity(void);

// A sampler's pdf at wi, and its sampling from (u, u_lobe): false when it draws nothing.
typedef float (*test_pdf_fn)(void *user, drift_vec3 wi);
typedef bool (*test_sample_fn)(void *user, drift_vec2 u, float u_lobe, drift_vec3 *out_wi);
// The chi-square test of sampling against its pdf (pbrt's and Mitsuba's): sample_count
// directions binned over the sphere (16 x 32 equal-area bins, +y the pole) against the pdf
// integrated over each bin by quadrature x quadrature points; the pdf must integrate to the
// share of draws that succeed. False, with the reason in `why`, when they disagree.
bool test_chi_square_passes(const char *what, test_pdf_fn pdf, test_sample_fn sample, void *user,
                            int sample_count, int quadrature, char *why, size_t why_size);

#endif
