// Rows of a family's knob table (include/drift/knobs.h): each technique folder lists its
// knobs in one static array with these macros, next to its code, and the conductor
// (src/hybrid/knobs.c) strings the families' arrays together. A field of
// drift_hybrid_params, its type found from the field (int32_t, uint32_t, float, bool or an
// enum), a range, a default, a unit and one line of help:
//
//     static const drift_knob rows[] = {
//         DRIFT_KNOB_INT_ROW("shadow-map-size", "N", shadow_map.size, 1, 8192, 512, "texels",
//                            "texels a side of each cube face", DRIFT_EFFECT_SHADOWS, "pcf pcss"),
//     };
//     DRIFT_KNOB_FAMILY(drift_realtime_knobs, rows);
#ifndef DRIFT_FRAME_KNOB_ROWS_H
#define DRIFT_FRAME_KNOB_ROWS_H

#include "drift/knobs.h"

#include <stddef.h>

// The store of a drift_hybrid_params field, from its C type (enums with no negative values
// are unsigned).
// clang-format off
#define DRIFT_KNOB_STORE_OF(f)                      \
    _Generic((((drift_hybrid_params *)0)->f),       \
             int32_t: DRIFT_KNOB_STORE_I32,         \
             uint32_t: DRIFT_KNOB_STORE_U32,        \
             float: DRIFT_KNOB_STORE_F32,           \
             bool: DRIFT_KNOB_STORE_BOOL)
// clang-format on

#define DRIFT_KNOB_AT_(f) \
    .offset = offsetof(drift_hybrid_params, f), .store = DRIFT_KNOB_STORE_OF(f)

#define DRIFT_KNOB_INT_ROW(n, a, f, l, u, d, un, h, e, t)                                  \
    {                                                                                      \
        .name = (n), .family = DRIFT_KNOB_FAMILY_NAME, .arg = (a), .type = DRIFT_KNOB_INT, \
        .lo = (l), .hi = (u), .def = (d), .unit = (un), .help = (h), .effect = (e),        \
        .techniques = (t), DRIFT_KNOB_AT_(f)                                               \
    }
#define DRIFT_KNOB_NUMBER_ROW(n, a, f, l, u, d, un, h, e, t)                                  \
    {                                                                                         \
        .name = (n), .family = DRIFT_KNOB_FAMILY_NAME, .arg = (a), .type = DRIFT_KNOB_NUMBER, \
        .lo = (l), .hi = (u), .def = (d), .unit = (un), .help = (h), .effect = (e),           \
        .techniques = (t), DRIFT_KNOB_AT_(f)                                                  \
    }
// A choice: `c` is "off|on"; the field stores the chosen index (d: the default index).
#define DRIFT_KNOB_CHOICE_ROW(n, f, c, d, h, e, t)                                             \
    {                                                                                          \
        .name = (n), .family = DRIFT_KNOB_FAMILY_NAME, .arg = (c), .type = DRIFT_KNOB_CHOICE,  \
        .choices = (c), .def = (d), .unit = "", .help = (h), .effect = (e), .techniques = (t), \
        DRIFT_KNOB_AT_(f)                                                                      \
    }

// A family's table: the array and its length, for src/hybrid/knobs.c.
typedef struct drift_knob_family {
    const char *name;  // "ism"
    const char *title; // "imperfect shadow maps (--indirect ism|ir)"
    const drift_knob *rows;
    int count;
} drift_knob_family;

#define DRIFT_KNOB_FAMILY(symbol, title, rows)                                  \
    const drift_knob_family symbol = { DRIFT_KNOB_FAMILY_NAME, (title), (rows), \
                                       (int)(sizeof(rows) / sizeof((rows)[0])) }

// Every family's table (declared here, defined in the family's knobs.c).
extern const drift_knob_family drift_frame_knobs;      // src/hybrid/knobs.c
extern const drift_knob_family drift_shadow_map_knobs; // src/realtime/knobs.c
extern const drift_knob_family drift_envmap_knobs;     // src/realtime/knobs.c
extern const drift_knob_family drift_post_dof_knobs;   // src/realtime/knobs.c
extern const drift_knob_family drift_isg_knobs;        // src/isg/knobs.c
extern const drift_knob_family drift_aaf_knobs;        // src/aaf/knobs.c
extern const drift_knob_family drift_occlusion_knobs;  // src/ssdo/knobs.c
extern const drift_knob_family drift_ism_knobs;        // src/ism/knobs.c
extern const drift_knob_family drift_micro_knobs;      // src/micro/knobs.c

#endif
