// drift view: the interactive viewer's core, everything `drift view` does except the window.
//
// A view owns one hybrid frame (drift_hybrid) and one progressive reference (drift_pt) of the
// same scene, camera and size, a camera controller, the technique chosen per effect, which
// buffer is shown, a split line (left: hybrid, right: reference), the exposure and an RGB8
// framebuffer with a text overlay. Input arrives as abstract events, so tests drive a view
// without a display and the window (tools/cmd_view.c) only translates SDL events and copies
// the framebuffer to the screen (docs/viewer.md).
//
// The reference restarts whenever the camera moves and, while the split view is on, gains
// spp_per_frame samples a pixel every frame; with the camera still it converges.
//
// STEP BY STEP
//   drift_view *view = NULL;
//   drift_view_create(ctx, scene, accel, &(drift_view_desc){ .hybrid.shadows = DRIFT_SHADOWS_PCSS
//   },
//                     &view);
//   drift_view_handle_event(view, &(drift_view_event){ .type = DRIFT_VIEW_EVENT_KEY,
//                                                      .key = DRIFT_VIEW_KEY_SPLIT });
//   drift_view_frame(view, &cancel);                 // once per displayed frame
//   const uint8_t *rgb = drift_view_pixels(view);    // width * height * 3 bytes, sRGB
//   drift_view_destroy(view);
//
// Ownership: scene and accel are borrowed and must outlive the view. The framebuffer, the
// hybrid frame and the reference belong to the view.
// Threads: one view is driven from one thread; rendering uses the context's pool.
#ifndef DRIFT_VIEW_H
#define DRIFT_VIEW_H

#include "drift/accel.h"
#include "drift/core.h"
#include "drift/hybrid.h"
#include "drift/pt.h"
#include "drift/scene.h"
#include "drift/temporal.h"

#ifdef __cplusplus
extern "C" {
#endif

// Keys the view understands (the window maps physical keys to these; docs/viewer.md). The
// first keys step an effect to its next technique (wrapping around), one key an effect of the
// technique table in its order: DRIFT_VIEW_KEY_SHADOWS, ..._REFLECTIONS, ..._DOF, ..._INDIRECT.
#define DRIFT_VIEW_EFFECT_KEY_(ENUM, ...) DRIFT_VIEW_KEY_##ENUM,

typedef enum drift_view_key {
    DRIFT_VIEW_KEY_NONE = 0,
    DRIFT_EFFECTS(DRIFT_VIEW_EFFECT_KEY_)
    DRIFT_VIEW_KEY_NEXT_BUFFER, // show the next buffer: the frame, then every plane
    DRIFT_VIEW_KEY_PREV_BUFFER,
    DRIFT_VIEW_KEY_SPLIT,      // split view on/off
    DRIFT_VIEW_KEY_SPLIT_LEFT, // move the split line by 1/16 of the width
    DRIFT_VIEW_KEY_SPLIT_RIGHT,
    DRIFT_VIEW_KEY_FORWARD, // fly: move camera and target together
    DRIFT_VIEW_KEY_BACK,
    DRIFT_VIEW_KEY_LEFT,
    DRIFT_VIEW_KEY_RIGHT,
    DRIFT_VIEW_KEY_UP, // along the camera's up vector
    DRIFT_VIEW_KEY_DOWN,
    DRIFT_VIEW_KEY_EXPOSURE_UP,   // +0.5 stops
    DRIFT_VIEW_KEY_EXPOSURE_DOWN, // -0.5 stops
    DRIFT_VIEW_KEY_RESET_CAMERA,  // back to the scene's camera
    DRIFT_VIEW_KEY_OVERLAY,       // text overlay on/off
    DRIFT_VIEW_KEY_HELP,          // key list in the overlay on/off
    // Reflection editing (docs/reflection-editing.md): on the selected constraint
    DRIFT_VIEW_KEY_EDIT_REGION,          // add a Euclidean region around its red handle
    DRIFT_VIEW_KEY_EDIT_UNREGION,        // remove the last region
    DRIFT_VIEW_KEY_EDIT_UNDO,            // undo the last edit
    DRIFT_VIEW_KEY_EDIT_SAVE,            // write the edit file (desc.reflection_edits_path)
    DRIFT_VIEW_KEY_EDIT_GEODESIC_REGION, // add a geodesic region around it, along its mesh
    // The knob panel (drift/knobs.h): select a knob of the knob table, step its value
    // (drift_knob_step); the overlay shows the selected knob and its value.
    DRIFT_VIEW_KEY_KNOB_NEXT,
    DRIFT_VIEW_KEY_KNOB_PREV,
    DRIFT_VIEW_KEY_KNOB_UP,
    DRIFT_VIEW_KEY_KNOB_DOWN,
    DRIFT_VIEW_KEY_COUNT
} drift_view_key;

// The key that steps `effect`'s technique (DRIFT_VIEW_KEY_NONE out of range), and the effect a
// key steps (-1 for any other key).
drift_view_key drift_view_key_of_effect(drift_effect effect);
int drift_view_key_effect(drift_view_key key);

typedef enum drift_view_event_type {
    DRIFT_VIEW_EVENT_KEY = 0,  // key pressed (or auto-repeated)
    DRIFT_VIEW_EVENT_ORBIT,    // drag by (dx, dy) pixels: orbit the camera about its target
    DRIFT_VIEW_EVENT_LOOK,     // drag by (dx, dy) pixels: turn the camera about its position
    DRIFT_VIEW_EVENT_DOLLY,    // wheel by dy notches: toward the target (dy > 0) or away
    DRIFT_VIEW_EVENT_SPLIT_AT, // put the split line at column x (and turn the split on)
    // Reflection editing at pixel (x, y):
    DRIFT_VIEW_EVENT_EDIT_PICK,  // a new constraint at the reflective point seen there (its
                                 // green handle where it reflects now: no change yet)
    DRIFT_VIEW_EVENT_EDIT_RED,   // the selected constraint's red handle to the point seen there
                                 // (slides the reflection; this view becomes its view)
    DRIFT_VIEW_EVENT_EDIT_GREEN, // its green handle to the point seen there (what it reflects)
    DRIFT_VIEW_EVENT_COUNT
} drift_view_event_type;

typedef struct drift_view_event {
    drift_view_event_type type;
    drift_view_key key; // DRIFT_VIEW_EVENT_KEY
    float dx, dy;       // ORBIT, LOOK: pixels, right and down positive; DOLLY: dy notches
    float x;            // SPLIT_AT: the column; EDIT_*: the pixel's column
    float y;            // EDIT_*: the pixel's row
} drift_view_event;

// How to create a view. The default configuration is:
//   width, height   = 0 -> the scene camera's size
//   hybrid          = the hybrid frame's parameters (techniques, spp of `reference` effects,
//                     ...); width and height are replaced by the view's size
//   spp_per_frame   = 0 -> 1 reference sample a pixel per frame while the split view is on
//   seed            = 0, the reference's seed
//   exposure_stops  = 0
//   split           = false; split_position = 0 -> 0.5 (fraction of the width)
//   hide_overlay    = false
//   reflection_edits_path = NULL: edits live in memory only (the save key refuses); else
//                     loaded from it at create when it exists, and written by the save key
//   help_text       = NULL: what the help key shows in the overlay (the window knows its key
//                     bindings; copied, lines of printable ASCII)
typedef struct drift_view_desc {
    int32_t width, height;
    drift_hybrid_params hybrid;
    uint32_t spp_per_frame;
    uint32_t seed;
    float exposure_stops;
    bool split;
    float split_position;
    bool hide_overlay;
    const char *help_text;
    // Smart image refinement (docs/sir.md): with `refine`, the frame is refined by ray
    // tracing `refine_budget` samples a frame (0 -> 16384) while the camera stands; the
    // planes gain error.combined (a heat map), refine.mask and the metrics.
    bool refine;
    uint32_t refine_budget;
    const char *reflection_edits_path;
    // Temporal reuse (docs/temporal.md): with `temporal`, each frame takes a new seed and a
    // sub-pixel offset and drift/temporal.h accumulates and filters the frames (a still camera
    // converges; a moving one reprojects its history). Not with `refine`.
    bool temporal;
    drift_temporal_settings temporal_settings;
} drift_view_desc;

// What the view shows now.
typedef struct drift_view_state {
    int32_t width, height;
    drift_camera camera;        // the camera both renderers use
    drift_hybrid_params params; // the hybrid frame's parameters (techniques)
    uint32_t buffer;            // 0: the composed frame; i > 0: drift_hybrid_plane(i - 1)
    const char *buffer_name;    // "frame" or the plane's name; valid until the next frame
    bool split;
    int32_t split_x; // first column of the reference when split (0..width)
    float exposure_stops;
    bool overlay, help;
    uint32_t reference_spp; // samples a pixel in the reference so far
    uint64_t frame_count;   // drift_view_frame calls that succeeded
} drift_view_state;

typedef struct drift_view drift_view;

// Errors: DRIFT_ERR_INVALID_ARGUMENT (uncommitted scene, bad size or parameters, logged),
// DRIFT_ERR_OUT_OF_MEMORY; and what drift_hybrid_create reports.
drift_result drift_view_create(drift_context *ctx, const drift_scene *scene,
                               const drift_accel *accel, const drift_view_desc *desc,
                               drift_view **out_view);
void drift_view_destroy(drift_view *view); // NULL-safe

// Applies one input event. Returns true when the next frame will look different (the
// window may skip rendering otherwise). Technique, buffer and camera changes take effect
// at the next drift_view_frame.
bool drift_view_handle_event(drift_view *view, const drift_view_event *event);

// Renders one frame: the hybrid frame, reference samples (restarted if the camera moved),
// the shown buffer and the split, then the overlay, into the framebuffer. `cancel` may be
// NULL; DRIFT_ERR_CANCELLED leaves the framebuffer as it was.
drift_result drift_view_frame(drift_view *view, const atomic_bool *cancel);

// The framebuffer: width * height * 3 bytes of sRGB, rows top to bottom. Valid until destroy.
const uint8_t *drift_view_pixels(const drift_view *view);

drift_view_state drift_view_get_state(const drift_view *view);

// Replaces the camera (its width and height are ignored); the reference restarts.
void drift_view_set_camera(drift_view *view, const drift_camera *camera);

// The renderers behind the view, for tests and tools: the hybrid frame, and the reference
// (NULL until the first frame with the split on).
const drift_hybrid *drift_view_hybrid(const drift_view *view);
drift_pt *drift_view_reference(drift_view *view);

// The view's reflection edits (never NULL after create) and the selected constraint (-1:
// none).
const drift_reflection_edits *drift_view_reflection_edits(const drift_view *view);
int32_t drift_view_selected_constraint(const drift_view *view);

// The overlay's text as the next frame draws it: lines by '\n', table cells by '\t' (the help
// text while help is on; else the techniques, the knob, the buffer, the frame's stages and,
// beside them, its counts: drift_hybrid_stats_count). Copies at most capacity - 1 bytes and a
// NUL into text (may be NULL); returns the whole text's length. The overlay keeps at most
// DRIFT_VIEW_OVERLAY_TEXT_MAX - 1 bytes.
#define DRIFT_VIEW_OVERLAY_TEXT_MAX 4096
size_t drift_view_overlay_text(const drift_view *view, char *text, size_t capacity);

// "shadows", ..., "help": the stable name of a key (NULL out of range), for docs and logs.
const char *drift_view_key_name(drift_view_key key);

#ifdef __cplusplus
}
#endif
#endif // DRIFT_VIEW_H
