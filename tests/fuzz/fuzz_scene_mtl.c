// libFuzzer target for an OBJ's material library (.mtl): the input is written as
// /tmp/drift-fuzz-XXXXXX/m.mtl beside a fixed OBJ (two triangles, `mtllib m.mtl`, `usemtl a`
// and `usemtl b`) that is loaded with drift_scene_load, so assimp's MTL reader and drift's
// material import (src/io/scene_assimp.c) see the input. Any result code is fine; crashes,
// hangs, sanitizer reports and leaks are not.
#define _DEFAULT_SOURCE // mkdtemp
#include "fuzz_context.h"

#include <stddef.h>
#include <stdint.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static bool write_file(const char *path, const void *data, size_t size)
{
    FILE *f = fopen(path, "wb");
    bool ok = f && fwrite(data, 1, size, f) == size;
    return f && fclose(f) == 0 && ok;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static const char obj[] = "mtllib m.mtl\n"
                              "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
                              "usemtl a\nf 1/1 2/2 3/3\nusemtl b\nf 2/2 4/1 3/3\n";
    char dir[64] = "/tmp/drift-fuzz-XXXXXX";
    if (!mkdtemp(dir)) {
        return 0;
    }
    char obj_path[96], mtl_path[96];
    snprintf(obj_path, sizeof obj_path, "%s/s.obj", dir);
    snprintf(mtl_path, sizeof mtl_path, "%s/m.mtl", dir);
    size_t total = 0;
    drift_context *ctx = NULL;
    if (write_file(obj_path, obj, sizeof obj - 1) && write_file(mtl_path, data, size) &&
        (ctx = fuzz_context(&total)) != NULL) {
        drift_scene *scene = NULL;
        fuzz_check_scene(drift_scene_load(ctx, obj_path, &scene), scene);
        drift_scene_destroy(scene);
        drift_context_destroy(ctx);
    }
    unlink(obj_path);
    unlink(mtl_path);
    rmdir(dir);
    return 0;
}
