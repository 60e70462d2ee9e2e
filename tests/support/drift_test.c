#include "drift_test.h"

#include "drift/math.h"
#include "drift/scene.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static void capture_log(drift_log_level level, drift_result code, const char *file, int line,
                        const char *message, void *user)
{
    test_log_capture *c = user;
    (void)file;
    (void)line;
    c->count++;
    if (level == DRIFT_LOG_WARNING) {
        c->warnings++;
    }
    if (level == DRIFT_LOG_ERROR) {
        c->errors++;
    }
    c->last_code = code;
    snprintf(c->last_message, sizeof(c->last_message), "%s", message);
    if (getenv("DRIFT_TEST_VERBOSE")) {
        fprintf(stderr, "[log %d] %s:%d: %s\n", (int)level, file ? file : "-", line, message);
    }
}

drift_logger test_capture_logger(test_log_capture *capture)
{
    return (drift_logger){ .func = capture ? capture_log : NULL, .user = capture };
}

drift_context *test_context(int threads, test_log_capture *capture)
{
    drift_context *ctx = NULL;
    drift_result r = drift_context_create(
        &(drift_context_desc){ .thread_count = threads, .logger = test_capture_logger(capture) },
        &ctx);
    if (r != DRIFT_OK) {
        fail_msg("drift_context_create: %s", drift_result_string(r));
    }
    return ctx;
}

const char *test_repo_path(char *out, const char *relative)
{
    snprintf(out, 1024, "%s/%s", DRIFT_SOURCE_DIR, relative);
    return out;
}

const char *test_shared_path(char *out, const char *relative)
{
    snprintf(out, 1024, "%s/../shared/%s", DRIFT_SOURCE_DIR, relative);
    return out;
}

const char *test_out_path(char *out, const char *name)
{
    mkdir(DRIFT_BINARY_DIR "/test-out", 0755);
    snprintf(out, 1024, "%s/test-out/%s", DRIFT_BINARY_DIR, name);
    return out;
}

double test_intensity(void)
{
    const char *s = getenv("DRIFT_TEST_INTENSITY");
    double v = s ? strtod(s, NULL) : 1.0;
    return v > 0.0 ? v : 1.0;
}

void test_assert_close(double a, double b, double eps, int line)
{
    if (!(fabs(a - b) <= eps)) {
        fail_msg("line %d: %.17g vs %.17g (eps %g)", line, a, b, eps);
    }
}

float test_hash_unit(uint32_t i)
{
    return drift_u32_to_unit(drift_hash_u32(i));
}

uint32_t test_add_mesh(struct drift_scene *scene, const float *positions, uint32_t vertex_count,
                       const uint32_t *indices, uint32_t triangle_count, uint32_t material)
{
    uint32_t index = DRIFT_INVALID_INDEX;
    drift_result r = drift_scene_add_mesh(scene,
                                          &(drift_mesh_desc){ .positions = positions,
                                                              .vertex_count = vertex_count,
                                                              .indices = indices,
                                                              .triangle_count = triangle_count,
                                                              .material = material },
                                          &index);
    if (r != DRIFT_OK) {
        fail_msg("drift_scene_add_mesh: %s", drift_result_string(r));
    }
    return index;
}
