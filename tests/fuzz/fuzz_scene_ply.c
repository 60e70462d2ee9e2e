// libFuzzer target for PLY files (.ply): the input is written to a temporary file and loaded
// with drift_scene_load, the path a user's file takes (src/io/scene_ply.c's checks, then
// assimp). Any result code is fine; crashes, hangs, sanitizer reports and leaks are not.
// Seeds: tests/fuzz/corpus/scene_ply (with the face of 0 indices and the header of more than
// 64 properties that aborted and hung assimp before scene_ply.c refused them).
#define _DEFAULT_SOURCE // mkstemps
#include "fuzz_context.h"

#include <stddef.h>
#include <stdint.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fuzz_scene_file(data, size, ".ply");
    return 0;
}
