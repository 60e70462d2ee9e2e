#include "drift/core.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

void drift_log(const drift_context *ctx, drift_log_level level, drift_result code, const char *file,
               int line, const char *fmt, ...)
{
    drift_logger logger = drift_context_logger(ctx);
    if (!logger.func) {
        return;
    }
    char message[1024];
    va_list args;
    va_start(args, fmt);
    vsnprintf(message, sizeof(message), fmt, args);
    va_end(args);
    logger.func(level, code, file, line, message, logger.user);
}

double drift_time_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

void drift__check_failed(const char *expr, const char *file, int line)
{
    // The one place the library may print and abort: a broken invariant would corrupt output.
    fprintf(stderr, "drift: check failed: %s at %s:%d\n", expr, file, line);
    abort();
}
