// The knobs of axis-aligned filtering (the aaf rows, docs/aaf.md): src/frame/knob_rows.h,
// include/drift/knobs.h.
#include "frame/knob_rows.h"

#define DRIFT_KNOB_FAMILY_NAME "aaf"
static const drift_knob rows[] = {
    { .name = "aaf-max-spp",
      .family = DRIFT_KNOB_FAMILY_NAME,
      .arg = "N",
      .type = DRIFT_KNOB_INT,
      .lo = 1,
      .hi = 65536,
      .unit = "samples",
      .help = "cap on AAF's adaptive samples a pixel",
      .default_text = "8 x --spp, at most 4096",
      .effect = -1,
      .techniques = "aaf",
      .flags = DRIFT_KNOB_AUTO,
      DRIFT_KNOB_AT_(aaf.max_spp) },
    DRIFT_KNOB_CHOICE_ROW("aaf-sampling", aaf.uniform, "adaptive|uniform", 0,
                          "uniform: --spp samples in every pixel", -1, "aaf"),
    DRIFT_KNOB_CHOICE_ROW("aaf-filter", aaf.unfiltered, "on|off", 0,
                          "off: AAF's unfiltered estimate (with uniform: plain Monte Carlo)", -1,
                          "aaf"),
    DRIFT_KNOB_CHOICE_ROW("aaf-denoise", aaf.denoise, "off|on|both", 0,
                          "on: the feature-guided denoiser (--denoise on) instead of AAF's\n"
                          "filter; both: the denoiser, then AAF's filter",
                          -1, "aaf"),
    DRIFT_KNOB_CHOICE_ROW("aaf-sampler", aaf.random, "sobol|random", 0,
                          "sobol: Owen-scrambled Sobol points; random: independent uniform\n"
                          "numbers (the paper's Monte Carlo)",
                          -1, "aaf"),
};
DRIFT_KNOB_FAMILY(drift_aaf_knobs, "axis-aligned filtering (the aaf rows, docs/aaf.md)", rows);
