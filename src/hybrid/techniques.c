// The technique table expanded: the rows of drift/techniques.h with their passes, and the
// public names, summaries and counts read from them.
#include "hybrid/techniques.h"

#include <string.h>

// The table names each row's pass and planes function; their prototypes come from the table
// too (each folder's header declares the same), so a new row needs no include here.
#define DECLARE_(P, ENUM, name, summary, pass, inputs, flags, planes, stream, components) \
    drift_result pass(drift_frame_state *frame, const drift_pass_args *args);             \
    void planes(const drift_frame_state *frame, drift_pass_plane_fn add, void *sink);
#define DECLARE_EFFECT_(ENUM, name, type, TECHNIQUES, kind, plane) TECHNIQUES(DECLARE_, ENUM)
DRIFT_EFFECTS(DECLARE_EFFECT_)

// Each effect's rows, in the order of its enum.
#define ROW_(P, ENUM, name, summary, pass, inputs, flags, planes, stream, components)   \
    { DRIFT_EFFECT_##P, DRIFT_##P##_##ENUM, name, summary, pass, inputs, flags, planes, \
      stream,           components },
#define ROWS_(ENUM, name, type, TECHNIQUES, kind, plane)                                      \
    static const drift_technique_row name##_rows[] = { TECHNIQUES(ROW_, ENUM) };              \
    _Static_assert(sizeof name##_rows / sizeof *name##_rows == DRIFT_##ENUM##_COUNT, "rows"); \
    _Static_assert(sizeof(drift_##type##_technique) == sizeof(int), "params.techniques");
DRIFT_EFFECTS(ROWS_)

#define EFFECT_(ENUM, name, type, TECHNIQUES, kind, plane)                         \
    [DRIFT_EFFECT_##ENUM] = { #name, plane, DRIFT_EFFECT_KIND_##kind, name##_rows, \
                              (int)(sizeof name##_rows / sizeof *name##_rows) },
static const drift_effect_info effects[DRIFT_EFFECT_COUNT] = { DRIFT_EFFECTS(EFFECT_) };

const drift_effect_info *drift_effect_info_of(drift_effect effect)
{
    return (unsigned)effect < DRIFT_EFFECT_COUNT ? &effects[effect] : NULL;
}

const drift_technique_row *drift_technique_row_of(drift_effect effect, int technique)
{
    if ((unsigned)effect >= DRIFT_EFFECT_COUNT || technique < 0 ||
        technique >= effects[effect].count) {
        return NULL;
    }
    return &effects[effect].rows[technique];
}

const drift_technique_row *drift_technique_row_chosen(const drift_hybrid_params *params,
                                                      drift_effect effect)
{
    return drift_technique_row_of(effect, drift_hybrid_params_technique(params, effect));
}

const char *drift_effect_name(drift_effect effect)
{
    return (unsigned)effect < DRIFT_EFFECT_COUNT ? effects[effect].name : NULL;
}

int drift_technique_count(drift_effect effect)
{
    return (unsigned)effect < DRIFT_EFFECT_COUNT ? effects[effect].count : 0;
}

const char *drift_technique_name(drift_effect effect, int technique)
{
    const drift_technique_row *row = drift_technique_row_of(effect, technique);
    return row ? row->name : NULL;
}

const char *drift_technique_summary(drift_effect effect, int technique)
{
    const drift_technique_row *row = drift_technique_row_of(effect, technique);
    return row ? row->summary : NULL;
}

bool drift_technique_path_traced(drift_effect effect, int technique)
{
    const drift_technique_row *row = drift_technique_row_of(effect, technique);
    return row && (row->flags & DRIFT_ROW_PATH_TRACED);
}

bool drift_technique_frontier(drift_effect effect, int technique)
{
    const drift_technique_row *row = drift_technique_row_of(effect, technique);
    return row && (row->flags & DRIFT_ROW_FRONTIER);
}

int drift_technique_parse(drift_effect effect, const char *name)
{
    for (int i = 0; name && i < drift_technique_count(effect); ++i) {
        if (strcmp(effects[effect].rows[i].name, name) == 0) {
            return i;
        }
    }
    return -1;
}
