// Private to src/view: the view's state and what its files call across. The dependencies go
// one way: view.c (state, events, frames, queries) calls view_camera.c (the camera controller),
// view_buffers.c (planes into the RGB8 framebuffer) and view_overlay.c (the text overlay);
// view_overlay.c draws with view_buffers.c's drift_view_blend_rect. Nothing calls view.c.
#ifndef DRIFT_VIEW_INTERNAL_H
#define DRIFT_VIEW_INTERNAL_H

#include "drift/image.h"
#include "drift/math.h"
#include "drift/refine.h"
#include "drift/reflect_edit.h"
#include "drift/view.h"

#define VIEW_BUFFER_NAME_MAX 128
// stb_easy_font writes 64 bytes a quad; one line of the overlay stays far below this.
#define VIEW_TEXT_VERTEX_BYTES (64 * 4096)

struct drift_view {
    drift_context *ctx;
    const drift_scene *scene;
    const drift_accel *accel;
    int32_t width, height;

    drift_hybrid *hybrid;
    drift_hybrid_params params;
    bool params_changed;
    int knob;             // the knob panel's selected row (drift/knobs.h)
    bool hybrid_rendered; // a frame was rendered: drift_hybrid_plane has planes

    drift_pt *reference;           // NULL until a frame with the split on, and after a move
    drift_camera reference_camera; // the camera the reference was created with
    uint32_t spp_per_frame;
    uint32_t seed;

    drift_camera camera;
    drift_camera home; // the scene's camera (RESET_CAMERA)
    bool camera_moved; // since the last frame: the reference must restart
    float move_step;

    char buffer_name[VIEW_BUFFER_NAME_MAX]; // "frame" or a plane name; looked up at each frame
    int32_t pending_buffer_steps;           // buffer keys pressed before the first frame
    float exposure_stops;
    bool split;
    float split_position;
    bool overlay, help;
    char *help_text;

    drift_temporal *temporal;    // NULL unless desc.temporal
    uint32_t temporal_frame;     // frames since the history began (seed and jitter index)
    drift_still_refine *still;   // a still camera's path-traced refinement, with temporal
    drift_moving_refine *moving; // every frame's reprojected path-traced refinement, or NULL
    uint32_t base_seed;          // the hybrid frame's seed from the desc

    drift_refine *sir;       // NULL unless the view refines (desc.refine)
    drift_camera sir_camera; // the camera of the last sort: a move (or new techniques,
    bool sir_dirty;          // sir_dirty) re-sorts, a standing view keeps refining
    bool sir_begun;

    // Reflection editing (view_edit.c).
    drift_reflection_edits *edits;
    int32_t selected;                   // the constraint the handles move, -1: none
    struct view_edit_snapshot *history; // undo states, oldest first
    uint32_t history_count;
    char *edits_path; // NULL: no file to save to

    uint8_t *pixels;
    void *text_vertices; // VIEW_TEXT_VERTEX_BYTES for the overlay's glyph quads
    uint64_t frame_count;
};

// --- THE CAMERA CONTROLLER (view_camera.c) ---
// Fly, drag and dolly change only the camera they are given and return whether they moved
// it; the view notes the move (the reference restarts).

// The length of one fly step for `scene`: 2% of its bounding-box diagonal, else of the
// camera's distance to its target, else 0.1.
float drift_view_camera_step(const drift_scene *scene);

// For the fly keys (forward, back, left, right, up, down): moves position and target together
// by `step` along the camera's forward, right or up axis. False for any other key, and for a
// camera without a frame (position on the target, or view direction along up).
bool drift_view_camera_fly(drift_camera *camera, drift_view_key key, float step);

// An orbit (about the target) or look (about the position) drag of dx, dy pixels; the
// camera keeps its up vector and stops pitching short of looking along it.
bool drift_view_camera_drag(drift_camera *camera, drift_view_event_type type, float dx, float dy);

// Dollies toward the target by `notches` wheel notches (negative: away), never closer to it
// than 1e-3 * step (`step`: the length of a fly step).
bool drift_view_camera_dolly(drift_camera *camera, float notches, float step);

// --- THE FRAMEBUFFER (view_buffers.c) ---

// Fills [x0, x1) x [y0, y1) (clipped to the framebuffer) with `color` blended at `alpha`.
void drift_view_blend_rect(drift_view *view, int32_t x0, int32_t y0, int32_t x1, int32_t y1,
                           const uint8_t color[3], float alpha);

// Draws `shown` into the framebuffer left of column split_x and `reference` (tone-mapped)
// from split_x on, then lightens the column just left of a split line inside the image.
// `plane_name` NULL: `shown` is the composed frame, tone-mapped; otherwise a plane, shown
// the way its name and channels call for (docs/viewer.md, Buffers). Both images are the
// view's size; `reference` is read only where split_x < width.
void drift_view_show(drift_view *view, const drift_image *shown, const char *plane_name,
                     const drift_image *reference, int32_t split_x);

// --- REFLECTION EDITING (view_edit.c) ---

// Creates the view's edit set (loaded from desc's path when the file exists).
drift_result drift_view_edit_begin(drift_view *view, const char *path);
void drift_view_edit_end(drift_view *view);
// The EDIT_* events and keys; true when the image changes (the reference restarts).
bool drift_view_edit_event(drift_view *view, const drift_view_event *event);
bool drift_view_edit_key(drift_view *view, drift_view_key key);
// The handles (red: on the mirror, green: the target) and the regions over the framebuffer.
void drift_view_draw_edits(drift_view *view);

// --- THE OVERLAY (view_overlay.c) ---

// Draws the overlay over the framebuffer, top left: the help text while help is on, else a
// table of techniques, the shown buffer, exposure, the reference's samples and pass timings.
void drift_view_draw_overlay(drift_view *view);

// Temporal reuse's per-frame seed and sub-pixel offset (view.c).
drift_result drift_view_temporal_begin(drift_view *view, drift_camera *camera);

#endif
