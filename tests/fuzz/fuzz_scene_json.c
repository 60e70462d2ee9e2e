// libFuzzer target for drift_scene_load_json_text: the input is a scene file. Paths in it are
// resolved against a folder that does not exist, so mesh and texture loads fail (that error
// path is part of what is fuzzed). Any result code is fine; crashes, sanitizer reports and
// leaks are not.
#define _DEFAULT_SOURCE // mkstemps (fuzz_context.h)
#include "drift/scene.h"
#include "drift/scene_io.h"
#include "fuzz_context.h"

#include <stddef.h>
#include <stdint.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    size_t total = 0;
    drift_context *ctx = fuzz_context(&total);
    if (!ctx) {
        return 0;
    }
    drift_scene *scene = NULL;
    drift_result r = drift_scene_load_json_text(ctx, (const char *)data, size,
                                                "/nonexistent-drift-fuzz", "fuzz.json", &scene);
    fuzz_check_scene(r, scene);
    drift_scene_destroy(scene);
    drift_context_destroy(ctx);
    return 0;
}
