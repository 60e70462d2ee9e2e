// libFuzzer target for glTF 2.0 files (.gltf): the input is written to a temporary file and
// loaded with drift_scene_load, the path a user's file takes (assimp for the geometry,
// src/io/scene_gltf.c for the lights, materials, extensions and cameras). External buffers and
// images resolve in the temporary folder and are usually missing: that error path is fuzzed
// too. Any result code is fine; crashes, sanitizer reports and leaks are not.
#define _DEFAULT_SOURCE // mkstemps
#include "fuzz_context.h"

#include <stddef.h>
#include <stdint.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
const char *__lsan_default_suppressions(void);

// assimp 5.2.5's glTF 2.0 reader leaks a buffer's decoded data URI when a later part of the
// file is rejected (seen as a 44-byte operator new[] inside libassimp, the seed's buffer).
// That is assimp's, not drift's: LeakSanitizer ignores allocations made inside libassimp, and
// still reports every leak of drift's own.
const char *__lsan_default_suppressions(void)
{
    return "leak:libassimp.so\n";
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fuzz_scene_file(data, size, ".gltf");
    return 0;
}
