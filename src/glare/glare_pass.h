// The rows of the glare effect (glare_pass.c): the eye's scattering applied to the final HDR
// frame as the last pass (thesis ch. 8, docs/glare.md).
#ifndef DRIFT_GLARE_PASS_H
#define DRIFT_GLARE_PASS_H

#include "drift/glare.h"
#include "frame/frame.h"

// final -> final with glare: the eye at rest (static) or advancing by the wall time between
// frames (dynamic: pupil, hippus, lens and vitreous move; the viewer animates).
drift_result drift_glare_pass_static(drift_frame_state *frame, const drift_pass_args *args);
drift_result drift_glare_pass_dynamic(drift_frame_state *frame, const drift_pass_args *args);

// The glare effect's drift_glare (NULL before its first pass or when glare is none), for
// the family's report hook (family.c).
const drift_glare *drift_glare_pass_object(const drift_frame_state *frame);

#endif // DRIFT_GLARE_PASS_H
