// The knobs of the shadow maps (--shadows pcf|pcss, contact shadows), of the environment
// map (--reflections envmap) and of the post-process DOF (--dof post): src/frame/knob_rows.h,
// include/drift/knobs.h.
#include "frame/knob_rows.h"

#define DRIFT_KNOB_FAMILY_NAME "shadow-map"
static const drift_knob shadow_map_rows[] = {
    DRIFT_KNOB_INT_ROW("shadow-map-size", "N", shadow_map.size, 1, 8192, 512, "texels",
                       "texels a side of each cube face", DRIFT_EFFECT_SHADOWS, "pcf pcss"),
    DRIFT_KNOB_NUMBER_ROW("shadow-bias", "B", shadow_map.bias, 1e-3, 1e3, 1.5, "texel footprints",
                          "shadow-map depth bias", DRIFT_EFFECT_SHADOWS, "pcf pcss"),
    DRIFT_KNOB_INT_ROW("pcf-kernel", "K", shadow_map.pcf_kernel, 1, 63, 3, "texels",
                       "PCF texels across (1: a single tap)", DRIFT_EFFECT_SHADOWS, "pcf"),
    DRIFT_KNOB_CHOICE_ROW("contact-shadows", shadow_map.contact_shadows, "off|on", 0,
                          "on: march each lit pixel's shadow-map bias toward the light in\n"
                          "screen space (thesis 4.5)",
                          DRIFT_EFFECT_SHADOWS, "pcf pcss"),
    DRIFT_KNOB_INT_ROW("contact-samples", "N", shadow_map.contact_samples, 1, 1024, 8, "points",
                       "points on each contact-shadow march", DRIFT_EFFECT_SHADOWS, "pcf pcss"),
};
DRIFT_KNOB_FAMILY(drift_shadow_map_knobs, "shadow maps (--shadows pcf|pcss)", shadow_map_rows);
#undef DRIFT_KNOB_FAMILY_NAME

#define DRIFT_KNOB_FAMILY_NAME "envmap"
static const drift_knob envmap_rows[] = {
    DRIFT_KNOB_INT_ROW("envmap-size", "N", envmap.size, 1, 4096, 128, "texels",
                       "texels a side of each cube face", DRIFT_EFFECT_REFLECTIONS, "envmap"),
    DRIFT_KNOB_CHOICE_ROW("envmap-parallax", envmap.parallax, "none|box", 0,
                          "box: the lookup parallax-corrected against the scene's bounds\n"
                          "(a local cube map); none: along the reflected direction",
                          DRIFT_EFFECT_REFLECTIONS, "envmap"),
};
DRIFT_KNOB_FAMILY(drift_envmap_knobs, "environment map (--reflections envmap)", envmap_rows);
#undef DRIFT_KNOB_FAMILY_NAME

#define DRIFT_KNOB_FAMILY_NAME "post-dof"
static const drift_knob post_dof_rows[] = {
    DRIFT_KNOB_CHOICE_ROW("post-dof-tiles", post_dof.per_pixel, "shared|per-pixel", 0,
                          "shared: 16 x 16 tiles whose circles of confusion are alike gather\n"
                          "with one set of taps (issue 46); per-pixel: every pixel its own",
                          DRIFT_EFFECT_DOF, "post"),
};
DRIFT_KNOB_FAMILY(drift_post_dof_knobs, "post-process depth of field (--dof post)", post_dof_rows);
#undef DRIFT_KNOB_FAMILY_NAME
