// The frame's buffers for the layers above the conductor (SIR refines a rendered frame: it
// reads the G-buffer, the lights, the shadow maps and the probes the last render made). The
// conductor's own state (planes, the table) stays private to frame.c.
#ifndef DRIFT_HYBRID_FRAME_ACCESS_H
#define DRIFT_HYBRID_FRAME_ACCESS_H

#include "frame/frame.h"

drift_frame_state *drift_hybrid_frame(drift_hybrid *frame);

#endif // DRIFT_HYBRID_FRAME_ACCESS_H
