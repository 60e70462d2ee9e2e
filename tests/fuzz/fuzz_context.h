// Shared by the fuzz targets: a one-thread context whose logger reads every message, so that
// a bad format argument or a dangling file name shows up under ASan; the scene targets' check
// of a load's result; and the load of a scene file written from the input (glTF, Mitsuba).
#ifndef DRIFT_FUZZ_CONTEXT_H
#define DRIFT_FUZZ_CONTEXT_H

#include "drift/core.h"
#include "drift/scene.h"
#include "drift/scene_io.h"

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

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

// A loaded scene is committed and has a camera; a failed load leaves no scene. Traps otherwise.
static inline void fuzz_check_scene(drift_result r, const drift_scene *scene)
{
    if (r == DRIFT_OK) {
        if (!scene->committed || scene->camera.width <= 0 || scene->camera.height <= 0) {
            __builtin_trap();
        }
        (void)drift_scene_triangle_count(scene);
    } else if (scene != NULL) {
        __builtin_trap();
    }
}

// Writes the input to a temporary file named "/tmp/drift-fuzz-XXXXXX" + suffix and loads it
// with drift_scene_load, the path a user's file takes (files it names resolve in /tmp and are
// usually missing: that error path is fuzzed too).
static inline void fuzz_scene_file(const uint8_t *data, size_t size, const char *suffix)
{
    char path[64];
    snprintf(path, sizeof path, "/tmp/drift-fuzz-XXXXXX%s", suffix);
    int fd = mkstemps(path, (int)strlen(suffix));
    if (fd < 0) {
        return;
    }
    bool written = write(fd, data, size) == (ssize_t)size;
    close(fd);
    size_t total = 0;
    drift_context *ctx = written ? fuzz_context(&total) : NULL;
    if (ctx) {
        drift_scene *scene = NULL;
        fuzz_check_scene(drift_scene_load(ctx, path, &scene), scene);
        drift_scene_destroy(scene);
        drift_context_destroy(ctx);
    }
    unlink(path);
}

#endif
