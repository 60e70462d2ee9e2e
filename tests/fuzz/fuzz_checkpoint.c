// libFuzzer target for drift render's checkpoints (tools/render_checkpoint.c, read by
// --resume): a 40x24 path tracer of a one-quad scene reads a checkpoint file made from the
// input. With the first byte even the input is the whole file (the magic, the key, the
// header); odd, it is the body after a valid magic and key, followed by the checksum the
// reader wants, so that tile states past the checksum are fuzzed too. Any result is fine;
// crashes, hangs, sanitizer reports and leaks are not, and a refused file must leave
// status 2.
#define _DEFAULT_SOURCE // mkstemps
#include "../../tools/render_checkpoint.c"
#include "drift/accel.h"
#include "fuzz_context.h"

#include <stddef.h>
#include <stdint.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

// tools/cli_common.c's, without the rest of the command-line tool.
uint64_t cli_fnv1a(uint64_t h, const void *data, size_t size)
{
    const uint8_t *p = data;
    for (size_t i = 0; i < size; ++i) {
        h = (h ^ p[i]) * 0x100000001b3ull;
    }
    return h;
}

bool cli_hash_files(const char *const *paths, size_t count, uint64_t *out)
{
    (void)paths;
    (void)count;
    *out = CLI_FNV_BASIS;
    return true;
}

static const char fuzz_key[] = "drift fuzz\nsize 40x24\n";

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size == 0) {
        return 0;
    }
    size_t total = 0;
    drift_context *ctx = fuzz_context(&total);
    if (!ctx) {
        return 0;
    }
    drift_scene *scene = NULL;
    drift_accel *accel = NULL;
    drift_pt *pt = NULL;
    const float positions[] = { -1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0 };
    const uint32_t indices[] = { 0, 1, 2, 0, 2, 3 };
    uint32_t material = 0;
    if (drift_scene_create(ctx, &scene) != DRIFT_OK ||
        drift_scene_add_material(scene,
                                 &(drift_material){ .diffuse = { 0.5f, 0.5f, 0.5f },
                                                    .emission = { 1, 1, 1 },
                                                    .diffuse_texture = DRIFT_INVALID_INDEX },
                                 &material) != DRIFT_OK ||
        drift_scene_add_mesh(scene,
                             &(drift_mesh_desc){ .name = "quad",
                                                 .positions = positions,
                                                 .vertex_count = 4,
                                                 .indices = indices,
                                                 .triangle_count = 2,
                                                 .material = material },
                             NULL) != DRIFT_OK) {
        __builtin_trap();
    }
    scene->camera = (drift_camera){ .position = { 0, 0, 3 },
                                    .target = { 0, 0, 0 },
                                    .up = { 0, 1, 0 },
                                    .fov_y = 0.8f,
                                    .width = 40,
                                    .height = 24 };
    if (drift_scene_commit(scene) != DRIFT_OK ||
        drift_accel_create(ctx, scene, &(drift_accel_desc){ 0 }, &accel) != DRIFT_OK ||
        drift_pt_create(ctx, scene, accel, &(drift_pt_params){ .width = 40, .height = 24 }, &pt) !=
            DRIFT_OK) {
        __builtin_trap();
    }
    char path[64] = "/tmp/drift-fuzz-XXXXXX.ckpt";
    int fd = mkstemps(path, 5);
    FILE *f = fd >= 0 ? fdopen(fd, "wb") : NULL;
    if (f) {
        if (data[0] & 1) {
            uint64_t h = CLI_FNV_BASIS;
            h = cli_fnv1a(h, checkpoint_magic, strlen(checkpoint_magic));
            h = cli_fnv1a(h, fuzz_key, strlen(fuzz_key));
            h = cli_fnv1a(h, "\n", 1);
            h = cli_fnv1a(h, data + 1, size - 1);
            fputs(checkpoint_magic, f);
            fputs(fuzz_key, f);
            fputc('\n', f);
            fwrite(data + 1, 1, size - 1, f);
            fwrite(&h, sizeof h, 1, f);
        } else {
            fwrite(data, 1, size, f);
        }
        fclose(f);
        int status = render_checkpoint_read(path, fuzz_key, pt, 64);
        if (status != 0 && status != 2) {
            __builtin_trap();
        }
        unlink(path);
    } else if (fd >= 0) {
        close(fd);
    }
    drift_pt_destroy(pt);
    drift_accel_destroy(accel);
    drift_scene_destroy(scene);
    drift_context_destroy(ctx);
    return 0;
}
