// The rows of the technique table that src/ism provides (ism_pass.c).
#ifndef DRIFT_ISM_PASS_H
#define DRIFT_ISM_PASS_H

#include "frame/frame.h"

// Fill frame->indirect (I) from VPLs with imperfect-shadow-map / ray-traced visibility.
drift_result drift_ism_pass_indirect(drift_frame_state *frame, const drift_pass_args *args);
drift_result drift_ism_pass_ir(drift_frame_state *frame, const drift_pass_args *args);
// What is wrong with the frame's instant-radiosity settings, or NULL.
const char *drift_ism_settings_problem(const drift_ism_settings *settings);
// The ism.irradiance and ism.vpls planes of the last render.
void drift_ism_indirect_planes(const drift_frame_state *frame, drift_pass_plane_fn add, void *sink);

// The indirect row's drift_ism, or NULL when the chosen row is neither ism nor ir or has not
// run (the family's report reads its stats).
struct drift_ism;
const struct drift_ism *drift_ism_pass_object(const drift_frame_state *frame);

#endif // DRIFT_ISM_PASS_H
