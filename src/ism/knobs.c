// The knobs of instant radiosity (--indirect ism|ir, docs/ism.md): src/frame/knob_rows.h,
// include/drift/knobs.h.
#include "frame/knob_rows.h"

#define DRIFT_KNOB_FAMILY_NAME "ism"
static const drift_knob rows[] = {
    DRIFT_KNOB_INT_ROW("ism-vpls", "N", ism.vpls, 1, 65536, 1024, "light paths",
                       "light paths, one first-bounce VPL each", DRIFT_EFFECT_INDIRECT, "ism ir"),
    DRIFT_KNOB_CHOICE_ROW("ism-vpl-importance", ism.vpl_importance, "off|on", 0,
                          "on: keep candidate VPLs with probability by their contribution to\n"
                          "the view, divided by it (Georgiev & Slusallek 2010)",
                          DRIFT_EFFECT_INDIRECT, "ism ir"),
    DRIFT_KNOB_CHOICE_ROW("ism-near-field", ism.no_near_field, "on|off", 0,
                          "off: no near-field compensation (short rays from a quarter of the\n"
                          "pixels give back the light of surfaces nearer than the VPLs' clamp)",
                          DRIFT_EFFECT_INDIRECT, "ism ir"),
    { .name = "ism-gather-scale",
      .family = DRIFT_KNOB_FAMILY_NAME,
      .arg = "1|2|4",
      .type = DRIFT_KNOB_CHOICE,
      .choices = "1|2|4",
      .choice_values = (const int32_t[]){ 1, 2, 4 },
      .def = 2,
      .unit = "pixels",
      .help = "1: every pixel gathers the VPLs; 2 or 4: one pixel in 2x2 or 4x4\n"
              "does, its irradiance upsampled to the others",
      .effect = DRIFT_EFFECT_INDIRECT,
      .techniques = "ism ir",
      DRIFT_KNOB_AT_(ism.gather_scale) },
    DRIFT_KNOB_INT_ROW("ism-map-size", "N", ism.map_size, 4, 1024, 64, "texels",
                       "texels a side of each VPL's imperfect shadow map", DRIFT_EFFECT_INDIRECT,
                       "ism"),
    DRIFT_KNOB_INT_ROW("ism-points", "N", ism.points_per_vpl, 16, 1 << 20, 1024, "points",
                       "scene points splatted into each map", DRIFT_EFFECT_INDIRECT, "ism"),
    { .name = "ism-later-paths",
      .family = DRIFT_KNOB_FAMILY_NAME,
      .arg = "N",
      .type = DRIFT_KNOB_INT,
      .lo = 1,
      .hi = 65536,
      .unit = "light paths",
      .help = "of the --ism-vpls paths, how many go on past their first VPL (at most\n"
              "all of them)",
      .default_text = "a quarter of --ism-vpls",
      .effect = DRIFT_EFFECT_INDIRECT,
      .techniques = "ism ir",
      .flags = DRIFT_KNOB_AUTO,
      DRIFT_KNOB_AT_(ism.later_paths) },
};
DRIFT_KNOB_FAMILY(drift_ism_knobs, "instant radiosity (--indirect ism|ir, docs/ism.md)", rows);
