// libFuzzer target for Mitsuba scene files (.xml): the input is written to a temporary file and
// loaded with drift_scene_load, the path a user's file takes (expat, src/io/scene_mitsuba.c).
// Mesh and texture files resolve in /tmp and are usually missing: that error path is fuzzed
// too. Any result code is fine; crashes, sanitizer reports and leaks are not.
#define _DEFAULT_SOURCE // mkstemps
#include "drift/scene.h"
#include "drift/scene_io.h"
#include "fuzz_context.h"

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char path[] = "/tmp/drift-fuzz-XXXXXX.xml";
    int fd = mkstemps(path, 4);
    if (fd < 0) {
        return 0;
    }
    bool written = write(fd, data, size) == (ssize_t)size;
    close(fd);
    size_t total = 0;
    drift_context *ctx = written ? fuzz_context(&total) : NULL;
    if (ctx) {
        drift_scene *scene = NULL;
        drift_result r = drift_scene_load(ctx, path, &scene);
        if (r == DRIFT_OK) {
            if (!scene->committed || scene->camera.width <= 0 || scene->camera.height <= 0) {
                __builtin_trap();
            }
            (void)drift_scene_triangle_count(scene);
        } else if (scene != NULL) {
            __builtin_trap();
        }
        drift_scene_destroy(scene);
        drift_context_destroy(ctx);
    }
    unlink(path);
    return 0;
}
