// The knobs of image space gathering (the isg and blur rows of every effect, docs/isg.md):
// src/frame/knob_rows.h, include/drift/knobs.h.
#include "frame/knob_rows.h"

#define DRIFT_KNOB_FAMILY_NAME "isg"
static const drift_knob rows[] = {
    { .name = "isg-search",
      .family = DRIFT_KNOB_FAMILY_NAME,
      .arg = "N",
      .type = DRIFT_KNOB_INT,
      .lo = 1,
      .hi = 1024,
      // 9 and 25 (issue 40): on the Cornell box at 200^2 they keep 80% of 25/49's gain over
      // hard shadows (FLIP 0.0851 hard, 0.0833, 0.0828) at 45% of its ms
      // (docs/lab/2026-12-07-issue-40.md).
      .def = 9,
      .unit = "samples",
      .help = "parameter-search samples, a perfect square (9, 25, 49, 81, ...)",
      .effect = -1,
      .techniques = "isg",
      .flags = DRIFT_KNOB_SQUARE,
      DRIFT_KNOB_AT_(isg.search) },
    { .name = "isg-gather",
      .family = DRIFT_KNOB_FAMILY_NAME,
      .arg = "M",
      .type = DRIFT_KNOB_INT,
      .lo = 1,
      .hi = 1024,
      .def = 25,
      .unit = "samples",
      .help = "gather samples, a perfect square",
      .effect = -1,
      .techniques = "isg",
      .flags = DRIFT_KNOB_SQUARE,
      DRIFT_KNOB_AT_(isg.gather) },
    { .name = "isg-sigma",
      .family = DRIFT_KNOB_FAMILY_NAME,
      .arg = "S",
      .type = DRIFT_KNOB_NUMBER,
      .lo = 1e-30,
      .hi = 1e30,
      .unit = "squared scene units",
      .help = "range sigma of eq. 6 and 10",
      .default_text = "(0.02 x scene extent)^2",
      .effect = -1,
      .techniques = "isg",
      .flags = DRIFT_KNOB_AUTO,
      DRIFT_KNOB_AT_(isg.sigma) },
    DRIFT_KNOB_NUMBER_ROW("blur-radius", "R", isg.blur_radius, 1e-30, 1024.0, 4.0, "pixels",
                          "disk radius of the blur baselines", -1, "blur"),
    DRIFT_KNOB_INT_ROW("isg-layers", "1|2", isg.layers, 1, 2, 1, "layers",
                       "2: a second depth layer behind objects for --dof isg", DRIFT_EFFECT_DOF,
                       "isg"),
    DRIFT_KNOB_CHOICE_ROW("isg-range", isg.range_plane, "full|plane", 0,
                          "l of the range functions: world distance (the paper) or the\n"
                          "distance to the centre's tangent plane",
                          -1, "isg"),
};
DRIFT_KNOB_FAMILY(drift_isg_knobs, "image space gathering (the isg and blur rows, docs/isg.md)",
                  rows);
