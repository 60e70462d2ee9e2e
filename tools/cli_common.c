#include "cli.h"
#include "drift/accel.h"
#include "drift/scene_io.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

bool cli_parse_int(const char *cmd, const char *flag, const char *text, long lo, long hi, long *out)
{
    char *end = NULL;
    errno = 0;
    long v = strtol(text, &end, 10);
    if (errno != 0 || end == text || *end != '\0' || v < lo || v > hi) {
        fprintf(stderr, "drift %s: %s expects an integer in [%ld, %ld], got '%s'\n", cmd, flag, lo,
                hi, text);
        return false;
    }
    *out = v;
    return true;
}

bool cli_parse_float(const char *cmd, const char *flag, const char *text, double lo, double hi,
                     double *out)
{
    char *end = NULL;
    errno = 0;
    double v = strtod(text, &end);
    if (errno != 0 || end == text || *end != '\0' || !isfinite(v) || v < lo || v > hi) {
        fprintf(stderr, "drift %s: %s expects a number in [%g, %g], got '%s'\n", cmd, flag, lo, hi,
                text);
        return false;
    }
    *out = v;
    return true;
}

bool cli_parse_technique(const char *cmd, drift_effect effect, const char *flag, const char *text,
                         int *out)
{
    int t = drift_technique_parse(effect, text);
    if (t >= 0) {
        *out = t;
        return true;
    }
    fprintf(stderr, "drift %s: %s expects one of", cmd, flag);
    for (int i = 0; i < drift_technique_count(effect); ++i) {
        fprintf(stderr, "%s %s", i ? "," : "", drift_technique_name(effect, i));
    }
    fprintf(stderr, ", got '%s'\n", text);
    return false;
}

const char *cli_next_value(const char *cmd, int argc, char **argv, int *i)
{
    if (*i + 1 >= argc) {
        fprintf(stderr, "drift %s: %s needs a value (see drift %s --help)\n", cmd, argv[*i], cmd);
        return NULL;
    }
    *i += 1;
    return argv[*i];
}

static void stderr_log(drift_log_level level, drift_result code, const char *file, int line,
                       const char *message, void *user)
{
    bool verbose = user != NULL;
    if (level < DRIFT_LOG_WARNING && !verbose) {
        return;
    }
    static const char *const names[] = { "info", "debug", "info", "warning", "error" };
    const char *name = level < DRIFT_LOG_COUNT ? names[level] : "log";
    (void)code;
    if (file && line > 0) {
        fprintf(stderr, "drift: %s:%d: %s: %s\n", file, line, name, message);
    } else if (file) {
        fprintf(stderr, "drift: %s: %s: %s\n", file, name, message);
    } else {
        fprintf(stderr, "drift: %s: %s\n", name, message);
    }
}

drift_logger cli_stderr_logger(bool verbose)
{
    // The user pointer only carries the verbose flag; any non-NULL value means verbose.
    static int verbose_marker;
    return (drift_logger){ .func = stderr_log, .user = verbose ? &verbose_marker : NULL };
}

drift_context *cli_open_context(const char *cmd, int threads, bool verbose)
{
    drift_context *ctx = NULL;
    drift_result r = drift_context_create(
        &(drift_context_desc){ .thread_count = threads, .logger = cli_stderr_logger(verbose) },
        &ctx);
    if (r != DRIFT_OK) {
        fprintf(stderr, "drift %s: %s\n", cmd, drift_result_string(r));
        return NULL;
    }
    return ctx;
}

const char *cli_default_scene_path(void)
{
    const char *env = getenv("DRIFT_DEFAULT_SCENE");
    return env && *env ? env : DRIFT_SOURCE_DIR "/scenes/cornell-box/cornell_box.json";
}

bool cli_open_scene(drift_context *ctx, const char *cmd, const char *path, drift_scene **out_scene,
                    drift_accel **out_accel, double *out_loaded_time)
{
    *out_accel = NULL;
    const char *scene_path = path ? path : cli_default_scene_path();
    drift_result r = drift_scene_load(ctx, scene_path, out_scene);
    if (r != DRIFT_OK) {
        fprintf(stderr, "drift %s: cannot load scene %s: %s\n", cmd, scene_path,
                drift_result_string(r));
        return false;
    }
    if (out_loaded_time) {
        *out_loaded_time = drift_time_now();
    }
    r = drift_accel_create(ctx, *out_scene, &(drift_accel_desc){ 0 }, out_accel);
    if (r != DRIFT_OK) {
        fprintf(stderr, "drift %s: cannot build the ray-tracing structure: %s\n", cmd,
                drift_result_string(r));
        return false;
    }
    return true;
}
