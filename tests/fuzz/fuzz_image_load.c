// libFuzzer target for drift_image_load: the first byte picks the extension (.exr or .png), the
// rest is written to a temporary file and loaded. Any result code is fine; crashes, sanitizer
// reports and leaks are not.
#include "drift/image.h"
#include "drift/image_io.h"

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1) {
        return 0;
    }
    const char *ext = (data[0] & 1) ? "exr" : "png";
    char path[256];
    snprintf(path, sizeof(path), "/tmp/drift_fuzz_%ld.%s", (long)getpid(), ext);
    FILE *f = fopen(path, "wb");
    if (!f) {
        return 0;
    }
    if (size > 1) {
        fwrite(data + 1, 1, size - 1, f);
    }
    fclose(f);

    drift_context *ctx = NULL;
    if (drift_context_create(&(drift_context_desc){ .thread_count = 1 }, &ctx) != DRIFT_OK) {
        unlink(path);
        return 0;
    }
    drift_image img;
    if (drift_image_load(ctx, path, &img) == DRIFT_OK) {
        // Touch every pixel so a short decode shows up under ASan/MSan.
        volatile float sink = 0.0f;
        size_t count = (size_t)img.width * (size_t)img.height * (size_t)img.channels;
        for (size_t i = 0; i < count; ++i) {
            sink += img.pixels[i];
        }
        (void)sink;
    }
    drift_image_destroy(ctx, &img);
    drift_context_destroy(ctx);
    unlink(path);
    return 0;
}
