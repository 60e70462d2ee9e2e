// test_refine: what its parts (tests/unit/refine/*.c) share with the main file.
#ifndef DRIFT_TEST_REFINE_TESTS_H
#define DRIFT_TEST_REFINE_TESTS_H

#include "drift/accel.h"
#include "drift/hybrid.h"
#include "drift/refine.h"
#include "drift/scene.h"
#include "drift_test.h"

typedef struct rig {
    drift_context *ctx;
    drift_scene *scene;
    drift_accel *accel;
    drift_hybrid *frame;
    drift_refine *sir;
} rig;

rig rig_begin(void);
// The hybrid techniques SIR refines: shadow maps, environment maps, post DOF, no indirect.
extern const drift_hybrid_params raster_params;
void rig_commit_raster(rig *r, const drift_hybrid_params *raster,
                       const drift_refine_params *params);
void rig_commit(rig *r, const drift_refine_params *params);
void rig_destroy(rig *r);
uint32_t test_spp(void);
// Every effect SIR refines (a mirror and a glossy sphere, a box on a floor under a quad light,
// depth edges seen through a lens), seen from `eye` at width x height.
void build_effects_scene(rig *r, int32_t width, int32_t height, drift_vec3 eye);

// tests/unit/refine/raster_error_metrics.c: metrics that weigh the raster's own error.
void test_glossy_plane_not_flagged(void **state);
void test_glossy_room_refined_in_error_order(void **state);
void test_component_refinement_cheaper_and_close(void **state);
void test_leak_metric_finds_seams(void **state);
void test_half_res_penumbra_keeps_flags(void **state);

#endif // DRIFT_TEST_REFINE_TESTS_H
