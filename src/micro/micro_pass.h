// The rows of the technique table that src/micro provides (micro_pass.c).
#ifndef DRIFT_MICRO_PASS_H
#define DRIFT_MICRO_PASS_H

#include "frame/frame.h"

// Fill frame->indirect (I): the diffuse lobe's one-bounce light by micro-buffer final gathers.
drift_result drift_micro_pass_indirect(drift_frame_state *frame, const drift_pass_args *args);
// Fill frame->reflections (R): the glossy lobe's, the micro-buffers importance-warped.
drift_result drift_micro_pass_reflections(drift_frame_state *frame, const drift_pass_args *args);
// The micro.incident and micro.gathers planes of the last render (micro.glossy_... for R).
void drift_micro_indirect_planes(const drift_frame_state *frame, drift_pass_plane_fn add,
                                 void *sink);
void drift_micro_reflection_planes(const drift_frame_state *frame, drift_pass_plane_fn add,
                                   void *sink);

// The effect's drift_micro (indirect or reflections), or NULL when its chosen row is not
// micro-rendering or has not run (the family's report reads its stats).
struct drift_micro;
const struct drift_micro *drift_micro_pass_object(const drift_frame_state *frame,
                                                  drift_effect effect);

#endif // DRIFT_MICRO_PASS_H
