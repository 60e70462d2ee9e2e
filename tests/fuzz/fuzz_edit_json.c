// libFuzzer target for drift_reflection_edits_parse: the input is an edit file (drift render
// --reflection-edits) applied to a fixed scene (a square mirror named "mirror" in z = 0, seen
// from +z). Any result code is fine; crashes, sanitizer reports and leaks are not, a failed
// parse must leave no edit set, and a successful one must give unit edited directions.
#define _DEFAULT_SOURCE // mkstemps (fuzz_context.h)
#include "drift/accel.h"
#include "drift/reflect_edit.h"
#include "drift/scene.h"
#include "fuzz_context.h"

#include <math.h>
#include <stddef.h>
#include <stdint.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    size_t total = 0;
    drift_context *ctx = fuzz_context(&total);
    if (!ctx) {
        return 0;
    }
    drift_scene *scene = NULL;
    drift_accel *accel = NULL;
    const float positions[] = { -1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0, 0 };
    const uint32_t indices[] = { 0, 1, 2, 0, 2, 3 };
    uint32_t material = 0;
    if (drift_scene_create(ctx, &scene) != DRIFT_OK ||
        drift_scene_add_material(scene,
                                 &(drift_material){ .type = DRIFT_MATERIAL_MIRROR,
                                                    .specular = { 1, 1, 1 },
                                                    .diffuse_texture = DRIFT_INVALID_INDEX },
                                 &material) != DRIFT_OK ||
        drift_scene_add_mesh(scene,
                             &(drift_mesh_desc){ .name = "mirror",
                                                 .positions = positions,
                                                 .vertex_count = 4,
                                                 .indices = indices,
                                                 .triangle_count = 2,
                                                 .material = material },
                             NULL) != DRIFT_OK ||
        drift_scene_commit(scene) != DRIFT_OK ||
        drift_accel_create(ctx, scene, &(drift_accel_desc){ 0 }, &accel) != DRIFT_OK) {
        __builtin_trap();
    }
    drift_reflection_edits *edits = (drift_reflection_edits *)1;
    drift_result r = drift_reflection_edits_parse(ctx, scene, accel, (const char *)data, size,
                                                  "fuzz.json", &edits);
    if (r != DRIFT_OK && edits) {
        __builtin_trap();
    }
    if (r == DRIFT_OK) {
        drift_edit_point q = { .position = { 0.25f, 0.5f, 0.0f },
                               .mesh = 0,
                               .triangle = 1,
                               .barycentric = { 0.25f, 0.25f } };
        drift_vec3 e = drift_reflection_edits_direction(edits, &q, drift_vec3_make(0, 0, 1));
        if (!(fabsf(drift_vec3_length(e) - 1.0f) < 1e-3f)) {
            __builtin_trap();
        }
        drift_reflection_edits_destroy(edits);
    }
    drift_accel_destroy(accel);
    drift_scene_destroy(scene);
    drift_context_destroy(ctx);
    return 0;
}
