// Shared by the JSON fuzz targets: a one-thread context whose logger reads every message, so
// that a bad format argument or a dangling file name shows up under ASan.
#ifndef DRIFT_FUZZ_CONTEXT_H
#define DRIFT_FUZZ_CONTEXT_H

#include "drift/core.h"

#include <stddef.h>
#include <string.h>

static void fuzz_check_log(drift_log_level level, drift_result code, const char *file, int line,
                           const char *message, void *user)
{
    size_t *total = user;
    *total += strlen(message) + (size_t)level + (size_t)code + (size_t)(line > 0);
    if (file) {
        *total += strlen(file);
    }
}

// NULL when the context cannot be made; `total` must outlive it.
static inline drift_context *fuzz_context(size_t *total)
{
    drift_context *ctx = NULL;
    drift_context_desc desc = { .thread_count = 1,
                                .logger = { .func = fuzz_check_log, .user = total } };
    return drift_context_create(&desc, &ctx) == DRIFT_OK ? ctx : NULL;
}

#endif
