// A technique family's hooks: how a folder of techniques (src/realtime, src/isg, src/aaf,
// src/ssdo, src/ism, src/micro, src/glare) declares the state it keeps and what it reports,
// so that the conductor (src/hybrid) runs a frame without knowing any family's internals.
// Each family defines one drift_family in its folder's family.c; src/hybrid/families.c lists
// them, in the order the conductor calls them. docs/decisions/0445-technique-families.md.
//
// The life of a family's state, all through these hooks:
//   resolve, problem  the frame's parameters: zero settings get their defaults, then checked
//   prepare           the inputs (DRIFT_INPUT_*) of the chosen rows that the family provides,
//                     made before any row's pass (caches that survive frames are kept here)
//   after_row         work that follows a row's pass (summing D after a row that writes S_l)
//   update            the parameters are about to change: drop the caches they invalidate
//   destroy           the frame is destroyed: free everything the family made
//   report            what the last frame did, as named counts (samples, rays, points)
// A hook may be NULL: the family has nothing to do at that point.
#ifndef DRIFT_FRAME_FAMILY_H
#define DRIFT_FRAME_FAMILY_H

#include "frame/frame.h"

// Adds one named count of the last frame ("ism.vpls", 256) to the frame's report.
typedef void (*drift_family_count_fn)(drift_frame_state *frame, const char *name, double value);

// The row the conductor just ran, for after_row.
typedef struct drift_family_row {
    const drift_pass_args *args;
    uint32_t inputs; // the row's DRIFT_INPUT_* (the table's inputs column)
    uint32_t flags;  // the row's DRIFT_ROW_* (the table's flags column)
} drift_family_row;

typedef struct drift_family {
    const char *name; // "realtime", "isg", ...: the prefix of its counts
    void (*resolve)(drift_hybrid_params *params, const drift_scene *scene);
    const char *(*problem)(const drift_hybrid_params *params); // NULL: nothing wrong
    uint32_t provides;                                         // DRIFT_INPUT_* that prepare makes
    drift_result (*prepare)(drift_frame_state *frame, uint32_t inputs);
    drift_result (*after_row)(drift_frame_state *frame, const drift_family_row *row);
    void (*update)(drift_frame_state *frame, const drift_hybrid_params *next);
    void (*destroy)(drift_frame_state *frame);
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
