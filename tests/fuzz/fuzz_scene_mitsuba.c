// libFuzzer target for Mitsuba scene files (.xml): the input is written to a temporary file and
// loaded with drift_scene_load, the path a user's file takes (expat, src/io/scene_mitsuba.c).
// Mesh and texture files resolve in /tmp and are usually missing: that error path is fuzzed
// too. Any result code is fine; crashes, sanitizer reports and leaks are not.
#define _DEFAULT_SOURCE // mkstemps
#include "fuzz_context.h"

#include <stddef.h>
#include <stdint.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fuzz_scene_file(data, size, ".xml");
    return 0;
}
