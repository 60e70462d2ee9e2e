// The rows of the occlusion effect that src/ssdo provides (ssdo_pass.c): light from the
// environment through the diffuse lobe, with screen-space visibility, and its reference.
#ifndef DRIFT_SSDO_PASS_H
#define DRIFT_SSDO_PASS_H

#include "frame/family.h"

// Fill frame->terms[DRIFT_EFFECT_OCCLUSION] (O) by SSAO, GTAO or SSDO (with the one bounce
// when params.occlusion.bounce and no indirect technique already has that light).
drift_result drift_ssdo_pass_ssao(drift_frame_state *frame, const drift_pass_args *args);
drift_result drift_ssdo_pass_gtao(drift_frame_state *frame, const drift_pass_args *args);
drift_result drift_ssdo_pass_ssdo(drift_frame_state *frame, const drift_pass_args *args);
// O ray-traced: the environment through the diffuse lobe at --spp shadow rays a pixel, exact
// visibility (what the screen-space techniques approximate; no bounce).
drift_result drift_ssdo_pass_reference(drift_frame_state *frame, const drift_pass_args *args);
// The contact-shadow fix for shadow-map bias in the frame's S_l (--contact-shadows on): runs
// after the pcf or pcss row, before D is summed (the family's after_row hook).
drift_result drift_ssdo_pass_contact_shadows(drift_frame_state *frame);

// What the contact shadows did on the frame's last pass, for the family's report hook.
typedef struct drift_ssdo_contact_counts {
    uint32_t lights;          // the lights with a shadow map, each marched
    uint64_t lit_pixels;      // pixels x lights the map let through: each marches toward its
                              // light (unless its surface faces away from it)
    uint64_t shadowed_pixels; // of those, the ones whose march met an occluder (S_l set to 0)
    int32_t samples;          // points a march
} drift_ssdo_contact_counts;

// The ssdo family's own state, in its slot of the frame (frame/family.h): made by its create
// hook, freed by its destroy hook. (The occlusion rows' buffers are in the occlusion effect's
// slot: drift_pass_set_state.)
typedef struct drift_ssdo_family_state {
    drift_ssdo_contact_counts contact;
} drift_ssdo_family_state;

static inline drift_ssdo_family_state *drift_ssdo_family_of(const drift_frame_state *frame)
{
    return (drift_ssdo_family_state *)drift_family_state(frame, DRIFT_FAMILY_SSDO);
}

// occlusion.visibility, .bent_normal, .direct and .bounce of the last render.
void drift_ssdo_planes(const drift_frame_state *frame, drift_pass_plane_fn add, void *sink);

// What the occlusion row's last screen-space render did (SSAO, GTAO, SSDO), for the family's
// report hook: the resolved samples a pixel (GTAO: horizon samples) and points marched along
// each, whether the bounce ran, the extra cameras and depth layers read, and the pixels shaded.
// False when no such row has run (occlusion none or reference).
typedef struct drift_ssdo_pass_counts {
    int32_t samples, steps;
    bool bounce;
    int32_t views, layers;
    uint64_t pixels;
} drift_ssdo_pass_counts;

bool drift_ssdo_pass_report(const drift_frame_state *frame, drift_ssdo_pass_counts *out);

#endif // DRIFT_SSDO_PASS_H
