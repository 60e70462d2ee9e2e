// The knobs of micro-rendering (--indirect micro, --reflections micro, docs/micro.md):
// src/frame/knob_rows.h, include/drift/knobs.h.
#include "frame/knob_rows.h"

#define DRIFT_KNOB_FAMILY_NAME "micro"
static const drift_knob rows[] = {
    DRIFT_KNOB_INT_ROW("micro-points", "N", micro.points, 2, 1 << 22, 65536, "points",
                       "scene points in the hierarchy, rounded up to a power of two", -1, "micro"),
    DRIFT_KNOB_INT_ROW("micro-size", "K", micro.buffer_size, 4, 32, 16, "pixels",
                       "each gather's micro-buffer is K x K pixels", -1, "micro"),
    { .name = "micro-density",
      .family = DRIFT_KNOB_FAMILY_NAME,
      .arg = "1|1/4|1/16",
      .type = DRIFT_KNOB_CHOICE,
      .choices = "1|1/4|1/16",
      .choice_values = (const int32_t[]){ 1, 2, 4 },
      .def = 1,
      .unit = "",
      .help = "gather at every pixel, 1/4 or 1/16 of them and upsample bilaterally",
      .effect = -1,
      .techniques = "micro",
      DRIFT_KNOB_AT_(micro.density) },
    DRIFT_KNOB_INT_ROW("micro-bounces", "N", micro.bounces, 1, 8, 1, "bounces",
                       "light bounces the micro-buffers gather: the points hold direct\n"
                       "light plus N - 1 bounces",
                       -1, "micro"),
    DRIFT_KNOB_CHOICE_ROW("micro-lighting", micro.lighting, "auto|direct|radiosity|photons", 0,
                          "how the points get bounces 2..N: Jacobi gathers over the hierarchy\n"
                          "or a photon map (caustics included); direct is one bounce; auto:\n"
                          "direct for one bounce, else radiosity",
                          -1, "micro"),
};
DRIFT_KNOB_FAMILY(drift_micro_knobs, "micro-rendering (the micro rows, docs/micro.md)", rows);
