// A technique family's hooks: how a folder of techniques (src/realtime, src/isg, src/aaf,
// src/ssdo, src/ism, src/micro, src/glare) declares the state it keeps and what it reports,
// so that the conductor (src/hybrid) runs a frame without knowing any family's internals.
// Each family defines one drift_family in its folder's family.c; src/hybrid/families.c lists
// them, in the order the conductor calls them. docs/decisions/0445-technique-families.md.
//
// The life of a family's state, all through these hooks:
//   create            the frame is made: the family makes its state (its slot of the frame,
//                     read through the family's own accessor); big buffers may wait for the
//                     first pass that needs them
//   resolve, problem  the frame's parameters: zero settings get their defaults, then checked
//   prepare           the inputs (DRIFT_INPUT_*) of the chosen rows that the family provides,
//                     made before any row's pass (caches that survive frames are kept here)
//   after_row         work that follows a row's pass (summing D after a row that writes S_l)
//   update            the parameters are about to change: drop the caches they invalidate
//   destroy           the frame is destroyed: free the family's state and all it made
//   report            what the last frame did, as named counts (samples, rays, points)
// A hook may be NULL: the family has nothing to do at that point.
#ifndef DRIFT_FRAME_FAMILY_H
#define DRIFT_FRAME_FAMILY_H

#include "frame/frame.h"

// Where each family keeps its state in the frame (drift_frame_state.family_state): one slot a
// family that has a create hook. DRIFT_FAMILY_NONE: the family keeps no state of its own
// there (its techniques' state, if any, is in their effects' slots: drift_pass_set_state).
typedef enum drift_family_slot {
    DRIFT_FAMILY_NONE,
    DRIFT_FAMILY_REALTIME, // realtime/realtime.h: shadow maps, probes, the prefiltered environment
    DRIFT_FAMILY_ISG,      // isg/isg.h: the search planes, the second layer, the patterns
    DRIFT_FAMILY_AAF,      // aaf/aaf.h: the per-light and per-lobe sampling and filter buffers
    DRIFT_FAMILY_SSDO,     // ssdo/ssdo_pass.h: what the contact shadows did
    DRIFT_FAMILY_SLOT_COUNT
} drift_family_slot;

_Static_assert(DRIFT_FAMILY_SLOT_COUNT <= DRIFT_FAMILY_SLOTS, "frame/frame.h's slots");

// The state in a family's slot (NULL before create, or when create made none).
static inline void *drift_family_state(const drift_frame_state *frame, drift_family_slot slot)
{
    return frame->family_state[slot];
}

// Adds one named count of the last frame ("ism.vpls", 256) to the frame's report.
typedef void (*drift_family_count_fn)(drift_frame_state *frame, const char *name, double value);

// The row the conductor just ran, for after_row.
typedef struct drift_family_row {
    const drift_pass_args *args;
    uint32_t inputs; // the row's DRIFT_INPUT_* (the table's inputs column)
    uint32_t flags;  // the row's DRIFT_ROW_* (the table's flags column)
} drift_family_row;

typedef struct drift_family {
    const char *name;       // "realtime", "isg", ...: the prefix of its counts
    drift_family_slot slot; // where create's state goes (DRIFT_FAMILY_NONE: no create)
    // Makes the family's state for a new frame (its lights and buffers exist); *out_state
    // goes to the family's slot.
    drift_result (*create)(drift_frame_state *frame, void **out_state);
    void (*resolve)(drift_hybrid_params *params, const drift_scene *scene);
    const char *(*problem)(const drift_hybrid_params *params); // NULL: nothing wrong
    uint32_t provides;                                         // DRIFT_INPUT_* that prepare makes
    drift_result (*prepare)(drift_frame_state *frame, uint32_t inputs);
    drift_result (*after_row)(drift_frame_state *frame, const drift_family_row *row);
    void (*update)(drift_frame_state *frame, const drift_hybrid_params *next);
    void (*destroy)(drift_frame_state *frame, void *state); // state: the slot's (may be NULL)
    // Called after the frame's last pass: count(frame, name, value) for each thing the
    // family's chosen rows did (nothing when none of its rows ran).
    void (*report)(drift_frame_state *frame, drift_family_count_fn count);
} drift_family;

// Helpers of the report hooks (family.c): the pixels that see a surface, and the mean of a
// one-channel plane over those of them where it is not 0 (*out_n of them; 0 with none).
uint64_t drift_family_surface_pixels(const drift_frame_state *frame);
double drift_family_nonzero_mean(const drift_frame_state *frame, const drift_image *plane,
                                 uint64_t *out_n);
// The number of the frame's pixels that see a surface where plane's channel c >= at.
uint64_t drift_family_surface_at_least(const drift_frame_state *frame, const drift_image *plane,
                                       int c, float at);

// Every family (defined in the family's folder, listed by src/hybrid/families.c).
extern const drift_family drift_realtime_family; // src/realtime/family.c
extern const drift_family drift_isg_family;      // src/isg/family.c
extern const drift_family drift_aaf_family;      // src/aaf/family.c
extern const drift_family drift_ssdo_family;     // src/ssdo/family.c
extern const drift_family drift_ism_family;      // src/ism/family.c
extern const drift_family drift_micro_family;    // src/micro/family.c
extern const drift_family drift_glare_family;    // src/glare/family.c

#endif // DRIFT_FRAME_FAMILY_H
