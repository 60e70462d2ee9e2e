// The conductor's view of the technique table (drift/techniques.h): a row per (effect,
// technique) with its pass, the inputs it needs, how its output is treated, its planes,
// sampler stream and reference components. frame.c runs the chosen row of every effect;
// nothing else in the conductor names a technique.
#ifndef DRIFT_HYBRID_TECHNIQUES_H
#define DRIFT_HYBRID_TECHNIQUES_H

#include "frame/frame.h"

typedef struct drift_technique_row {
    drift_effect effect;
    int technique;
    const char *name;
    const char *summary;
    drift_pass_fn pass;          // drift_pass_none: the inputs already are the term
    uint32_t inputs;             // DRIFT_INPUT_*
    uint32_t flags;              // DRIFT_ROW_*
    drift_pass_planes_fn planes; // drift_planes_none: no planes of its own
    uint32_t stream;
    uint32_t components;
} drift_technique_row;

typedef enum drift_effect_kind {
    DRIFT_EFFECT_KIND_TERM, // its rows fill a term of the composed frame
    DRIFT_EFFECT_KIND_POST, // its rows turn the composed frame into the final image
} drift_effect_kind;

typedef struct drift_effect_info {
    const char *name;
    const char *plane; // what its rows write, by --aov plane name
    drift_effect_kind kind;
    const drift_technique_row *rows;
    int count;
} drift_effect_info;

// The effect's row of the table of effects, or NULL out of range.
const drift_effect_info *drift_effect_info_of(drift_effect effect);

// The row of `technique` in `effect`, or NULL when either is out of range.
const drift_technique_row *drift_technique_row_of(drift_effect effect, int technique);
// The row the frame's parameters choose for `effect`.
const drift_technique_row *drift_technique_row_chosen(const drift_hybrid_params *params,
                                                      drift_effect effect);

// --- THE CONDUCTOR'S OWN PASSES ---

// reference.c: the effect's term alone, path-traced at the frame's spp with the row's
// components (shadows -> D at depth 1, reflections -> R and indirect -> I at max_depth).
drift_result drift_hybrid_pass_reference(drift_frame_state *frame, const drift_pass_args *args);
// compose.c: focus = E + D + R + I (terms of NO_TERM rows left out), and the coc plane.
drift_result drift_hybrid_pass_compose(drift_frame_state *frame);
// veils.c: the scene's BLEND surfaces, which the G-buffer's rays pass, blended over focus by
// their opacity (front to back, shaded by their emission, direct light and the indirect light
// behind them). Nothing without such surfaces.
drift_result drift_hybrid_pass_veils(drift_frame_state *frame);
bool drift_hybrid_scene_has_veils(const drift_scene *scene);
// compose.c: the depth-of-field rows the conductor owns: final = focus (pinhole), and the
// whole frame path-traced through the lens with every enabled term.
drift_result drift_hybrid_pass_pinhole(drift_frame_state *frame, const drift_pass_args *args);
drift_result drift_hybrid_pass_lens_reference(drift_frame_state *frame,
                                              const drift_pass_args *args);

#endif // DRIFT_HYBRID_TECHNIQUES_H
