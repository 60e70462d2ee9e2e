// drift knobs: every technique family's settings in drift_hybrid_params as rows of one table.
// A family declares its knobs in one static array next to its code (src/realtime/knobs.c,
// src/isg/knobs.c, src/aaf/knobs.c, src/ssdo/knobs.c, src/ism/knobs.c, src/micro/knobs.c;
// the frame's own in src/hybrid/knobs.c): name, type, range, default, unit, one-line help,
// the effect and techniques that read it, and where it lives in drift_hybrid_params. The
// command line's options and --help (drift render --mode hybrid, drift view), the --stats
// JSON, the viewer's knob panel, the frontier and the chooser iterate these rows; a new knob
// is one row, and its default is in that row alone (docs/decisions/0441-knob-tables.md).
//
//     drift_hybrid_params p = drift_hybrid_params_default();   // every row's default
//     int k = drift_knob_find("ism-vpls");
//     double v;
//     if (drift_knob_parse(drift_knob_get(k), "2048", &v)) drift_knob_set(&p, k, v);
//     for (int i = 0; i < drift_knob_count(); ++i) {              // the search space
//         const drift_knob *knob = drift_knob_get(i);             // knob->lo .. knob->hi
//     }
//
// Values are doubles: integers, numbers, and a choice's stored value (its index in
// `choices`, or choice_values[index]). The table is constant: any thread may read it.
#ifndef DRIFT_KNOBS_H
#define DRIFT_KNOBS_H

#include "drift/hybrid.h"

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef enum drift_knob_type {
    DRIFT_KNOB_INT,    // an integer in [lo, hi]
    DRIFT_KNOB_NUMBER, // a finite number in [lo, hi]
    DRIFT_KNOB_CHOICE, // one of `choices` ("off|on")
} drift_knob_type;

// How the value is stored in drift_hybrid_params (the row macros pick it from the field's
// C type).
typedef enum drift_knob_store {
    DRIFT_KNOB_STORE_I32,
    DRIFT_KNOB_STORE_U32,
    DRIFT_KNOB_STORE_F32,
    DRIFT_KNOB_STORE_BOOL,
} drift_knob_store;

enum {
    DRIFT_KNOB_SQUARE = 1u << 0, // INT: perfect squares only (ISG's k x k sample grids)
    DRIFT_KNOB_AUTO = 1u << 1,   // the default is 0, "auto": the family derives the value
                                 // from the scene or other settings (default_text says how);
                                 // the text "auto" sets it
};

typedef struct drift_knob {
    const char *name;   // "ism-vpls": the option --ism-vpls, the key in --stats' "knobs" and
                        // the viewer's label; stable
    const char *family; // "ism": the family that owns the row (drift_knob_family_title)
    const char *arg;    // the value's placeholder in --help ("N", "on|off")
    drift_knob_type type;
    double lo, hi;       // INT, NUMBER: the range (inclusive)
    double def;          // the default (for a choice: the stored value); 0 with DRIFT_KNOB_AUTO
    const char *choices; // CHOICE: "off|on", "none|box"
    const int32_t *choice_values; // CHOICE: the value each choice stores (NULL: its index)
    const char *unit;             // "texels", "pixels", "scene units", ... ("" for none)
    const char *help;             // one line: what it changes
    const char *default_text;     // DRIFT_KNOB_AUTO: what "auto" resolves to
    int effect;                   // the drift_effect it changes; -1: the whole frame
    const char *techniques;       // the effect's techniques that read it ("pcf pcss"); NULL:
                                  // every one
    unsigned flags;               // DRIFT_KNOB_*
    size_t offset;                // where the value lives in drift_hybrid_params
    drift_knob_store store;
} drift_knob;

// The rows of every family, in family order. drift_knob_get returns NULL past the end.
int drift_knob_count(void);
const drift_knob *drift_knob_get(int index);
// The index of the knob called `name` ("ism-vpls", without dashes), or -1.
int drift_knob_find(const char *name);
// A family's heading for --help and the viewer ("imperfect shadow maps (--indirect ism|ir)").
const char *drift_knob_family_title(const char *family);

// The knob's value in `params`, and setting it. drift_knob_set refuses (false, params
// unchanged) a value outside the row's range, not a perfect square where one is needed, or
// not one of the choices' values; 0 is accepted for DRIFT_KNOB_AUTO rows.
double drift_knob_value(const drift_hybrid_params *params, int index);
bool drift_knob_set(drift_hybrid_params *params, int index, double value);

// Text <-> value: "on", "1/4", "512", "1.5", "auto". drift_knob_parse checks what
// drift_knob_set checks; drift_knob_format writes what drift_knob_parse reads back to the
// same value ("%.9g" for numbers) and returns snprintf's count.
bool drift_knob_parse(const drift_knob *knob, const char *text, double *out_value);
int drift_knob_format(const drift_knob *knob, double value, char *out, size_t size);
// The value a step up (direction > 0) or down from `value` gives, within the range: the
// next or previous choice; +-1 for an integer of a short range (at most 16 values), else
// x2 or /2 (the next or previous perfect square where squares are needed); x2 or /2 for a
// number. Down from the lower bound of an auto knob is auto (0), up from auto the lower
// bound. A step past the end gives the value back. For the viewer's keys and searches.
double drift_knob_step(const drift_knob *knob, double value, int direction);
// What the knob accepts, for error messages: "an integer in [1, 65536]", "off or on".
int drift_knob_expects(const drift_knob *knob, char *out, size_t size);

// The default frame: every effect's default technique (drift_technique_default) and every
// knob at its row's default, max_depth 8. What `drift render --mode hybrid`, `drift view`
// and the benchmarks start from, and what --help prints.
drift_hybrid_params drift_hybrid_params_default(void);
// The technique drift_hybrid_params_default chooses for `effect` (-1 for an invalid effect).
int drift_technique_default(drift_effect effect);

#ifdef __cplusplus
}
#endif
#endif // DRIFT_KNOBS_H
