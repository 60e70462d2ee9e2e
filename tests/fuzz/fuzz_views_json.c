// libFuzzer target for drift_camera_views_load_json_text: the input is a views file (drift
// bench sir --views). Any result code is fine; crashes, sanitizer reports and leaks are not,
// and a successful load must hold 1 to capacity named views.
#define _DEFAULT_SOURCE // mkstemps (fuzz_context.h)
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

    enum {
        CAPACITY = 4
    };

    drift_camera_view views[CAPACITY];
    uint32_t count = 99;
    drift_result r = drift_camera_views_load_json_text(ctx, (const char *)data, size, "fuzz.json",
                                                       views, CAPACITY, &count);
    if (r == DRIFT_OK) {
        if (count < 1 || count > CAPACITY) {
            __builtin_trap();
        }
        for (uint32_t k = 0; k < count; ++k) {
            const char *end = memchr(views[k].name, '\0', sizeof views[k].name);
            if (!end || end == views[k].name) {
                __builtin_trap();
            }
        }
    } else if (count != 0) {
        __builtin_trap();
    }
    drift_context_destroy(ctx);
    return 0;
}
