// The technique table expanded: the rows of drift/techniques.h with their passes, and the
// public names, summaries and counts read from them.
#include "hybrid/techniques.h"

#include <string.h>

// The table names each row's pass and planes function; their prototypes come from the table
// too (each folder's header declares the same), so a new row needs no include here.
#define DECLARE_(ENUM, name, summary, pass, inputs, flags, planes, stream, components) \
    drift_result pass(drift_frame_state *frame, const drift_pass_args *args);          \
    void planes(const drift_frame_state *frame, drift_pass_plane_fn add, void *sink);
DRIFT_SHADOW_TECHNIQUES(DECLARE_)
DRIFT_REFLECTION_TECHNIQUES(DECLARE_)
DRIFT_DOF_TECHNIQUES(DECLARE_)
DRIFT_INDIRECT_TECHNIQUES(DECLARE_)

#define ROW_(effect, prefix, ENUM, name, summary, pass, inputs, flags, planes, stream, components) \
    { effect, prefix##ENUM, name, summary, pass, inputs, flags, planes, stream, components },
#define SHADOW_ROW_(ENUM, ...) ROW_(DRIFT_EFFECT_SHADOWS, DRIFT_SHADOWS_, ENUM, __VA_ARGS__)
#define REFLECTION_ROW_(ENUM, ...) \
    ROW_(DRIFT_EFFECT_REFLECTIONS, DRIFT_REFLECTIONS_, ENUM, __VA_ARGS__)
#define DOF_ROW_(ENUM, ...)      ROW_(DRIFT_EFFECT_DOF, DRIFT_DOF_, ENUM, __VA_ARGS__)
#define INDIRECT_ROW_(ENUM, ...) ROW_(DRIFT_EFFECT_INDIRECT, DRIFT_INDIRECT_, ENUM, __VA_ARGS__)

static const drift_technique_row shadow_rows[] = { DRIFT_SHADOW_TECHNIQUES(SHADOW_ROW_) };
static const drift_technique_row reflection_rows[] = { DRIFT_REFLECTION_TECHNIQUES(
    REFLECTION_ROW_) };
static const drift_technique_row dof_rows[] = { DRIFT_DOF_TECHNIQUES(DOF_ROW_) };
static const drift_technique_row indirect_rows[] = { DRIFT_INDIRECT_TECHNIQUES(INDIRECT_ROW_) };

typedef struct effect_table {
    const char *name;
    const drift_technique_row *rows;
    int count;
} effect_table;

#define COUNT_(array) ((int)(sizeof array / sizeof *array))
static const effect_table effects[DRIFT_EFFECT_COUNT] = {
    [DRIFT_EFFECT_SHADOWS] = { "shadows", shadow_rows, COUNT_(shadow_rows) },
    [DRIFT_EFFECT_REFLECTIONS] = { "reflections", reflection_rows, COUNT_(reflection_rows) },
    [DRIFT_EFFECT_DOF] = { "dof", dof_rows, COUNT_(dof_rows) },
    [DRIFT_EFFECT_INDIRECT] = { "indirect", indirect_rows, COUNT_(indirect_rows) },
};
_Static_assert(COUNT_(shadow_rows) == DRIFT_SHADOWS_COUNT, "one row a technique");
_Static_assert(COUNT_(reflection_rows) == DRIFT_REFLECTIONS_COUNT, "one row a technique");
_Static_assert(COUNT_(dof_rows) == DRIFT_DOF_COUNT, "one row a technique");
_Static_assert(COUNT_(indirect_rows) == DRIFT_INDIRECT_COUNT, "one row a technique");

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

int drift_technique_parse(drift_effect effect, const char *name)
{
    for (int i = 0; name && i < drift_technique_count(effect); ++i) {
        if (strcmp(effects[effect].rows[i].name, name) == 0) {
            return i;
        }
    }
    return -1;
}
