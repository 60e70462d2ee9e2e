// The viewer's core: the view's state, its events and keys, and each frame: the hybrid frame,
// technique and buffer selection, the split view against the progressive reference, and the
// overlay, into an RGB8 framebuffer. The camera controller is in view_camera.c, how buffers
// are drawn in view_buffers.c, the text overlay in view_overlay.c (view_internal.h). No window
// code here (tools/cmd_view.c is the window); see include/drift/view.h and docs/viewer.md.
#include "drift/knobs.h"
#include "view/view_internal.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define HELP_TEXT_MAX 4096
#define EXPOSURE_STEP 0.5f
#define SPLIT_STEP    (1.0f / 16.0f)

// --- SMALL HELPERS ---

// The keys after the effects' (those are named after their effects).
static const char *const key_names[DRIFT_VIEW_KEY_COUNT - DRIFT_VIEW_KEY_NEXT_BUFFER] = {
    "next-buffer",
    "prev-buffer",
    "split",
    "split-left",
    "split-right",
    "forward",
    "back",
    "left",
    "right",
    "up",
    "down",
    "exposure-up",
    "exposure-down",
    "reset-camera",
    "overlay",
    "help",
    "edit-region",
    "edit-unregion",
    "undo",
    "save-edits",
    "edit-geodesic-region",
    "knob-next",
    "knob-prev",
    "knob-up",
    "knob-down",
};

drift_view_key drift_view_key_of_effect(drift_effect effect)
{
    return (unsigned)effect < DRIFT_EFFECT_COUNT
               ? (drift_view_key)(DRIFT_VIEW_KEY_NONE + 1 + effect)
               : DRIFT_VIEW_KEY_NONE;
}

int drift_view_key_effect(drift_view_key key)
{
    int effect = (int)key - (int)DRIFT_VIEW_KEY_NONE - 1;
    return effect >= 0 && effect < DRIFT_EFFECT_COUNT ? effect : -1;
}

const char *drift_view_key_name(drift_view_key key)
{
    if (key == DRIFT_VIEW_KEY_NONE) {
        return "none";
    }
    int effect = drift_view_key_effect(key);
    if (effect >= 0) {
        return drift_effect_name((drift_effect)effect);
    }
    return (unsigned)key < DRIFT_VIEW_KEY_COUNT ? key_names[key - DRIFT_VIEW_KEY_NEXT_BUFFER]
                                                : NULL;
}

static int32_t split_column(const drift_view *view)
{
    long x = lrintf(view->split_position * (float)view->width);
    return (int32_t)(x < 0 ? 0 : (x > view->width ? view->width : x));
}

// Plane `index` of the last frame: the hybrid frame's, then the refiner's (when refining).
static bool view_plane(const drift_view *view, uint32_t index, const char **out_name,
                       const drift_image **out_image)
{
    if (drift_hybrid_plane(view->hybrid, index, out_name, out_image)) {
        return true;
    }
    if (!view->sir || !view->sir_begun) {
        return false;
    }
    uint32_t hybrid_count = 0;
    const char *name;
    const drift_image *image;
    while (drift_hybrid_plane(view->hybrid, hybrid_count, &name, &image)) {
        ++hybrid_count;
    }
    return drift_refine_plane(view->sir, index - hybrid_count, out_name, out_image);
}

// The index (1-based; 0 = the composed frame) of the plane called `name` in the last frame.
static uint32_t buffer_index(const drift_view *view, const char *name)
{
    if (!view->hybrid_rendered || strcmp(name, "frame") == 0) {
        return 0;
    }
    const char *plane_name = NULL;
    const drift_image *image = NULL;
    for (uint32_t i = 0; view_plane(view, i, &plane_name, &image); ++i) {
        if (plane_name && strcmp(plane_name, name) == 0) {
            return i + 1;
        }
    }
    return 0;
}

static uint32_t plane_count(const drift_view *view)
{
    if (!view->hybrid_rendered) {
        return 0;
    }
    const char *name = NULL;
    const drift_image *image = NULL;
    uint32_t count = 0;
    while (view_plane(view, count, &name, &image)) {
        ++count;
    }
    return count;
}

static void select_buffer(drift_view *view, uint32_t index)
{
    const char *name = NULL;
    const drift_image *image = NULL;
    if (index == 0 || !view_plane(view, index - 1, &name, &image) || !name) {
        name = "frame";
    }
    snprintf(view->buffer_name, sizeof(view->buffer_name), "%s", name);
}

// Moves the shown buffer by `steps` through the frame and every plane of the last frame,
// wrapping around. Before the first frame there are no planes yet: the steps wait for it.
static void step_buffer(drift_view *view, int32_t steps)
{
    if (!view->hybrid_rendered) {
        view->pending_buffer_steps += steps;
        return;
    }
    int64_t count = (int64_t)plane_count(view) + 1; // the frame, then every plane
    int64_t index = ((int64_t)buffer_index(view, view->buffer_name) + steps) % count;
    select_buffer(view, (uint32_t)(index < 0 ? index + count : index));
}

// --- THE REFERENCE ---

// The reference's parameters: the view's size and the view's camera (`camera` in
// drift_pt_params: the path tracer looks through it instead of the scene's). The path tracer
// borrows the camera, so reference_camera stays put while the reference lives.
static drift_pt_params reference_params(const drift_view *view)
{
    return (drift_pt_params){ .width = view->width,
                              .height = view->height,
                              .seed = view->seed,
                              .camera = &view->reference_camera,
                              .reflection_edits = view->edits };
}

// Called only without a reference (drift_view_frame drops it when the camera moves).
static drift_result reference_restart(drift_view *view)
{
    view->reference_camera = view->camera;
    view->reference_camera.width = view->width;
    view->reference_camera.height = view->height;
    drift_pt_params params = reference_params(view);
    return drift_pt_create(view->ctx, view->scene, view->accel, &params, &view->reference);
}

// --- CREATE / DESTROY ---

drift_result drift_view_create(drift_context *ctx, const drift_scene *scene,
                               const drift_accel *accel, const drift_view_desc *desc,
                               drift_view **out_view)
{
    if (!out_view) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    *out_view = NULL;
    if (!ctx || !scene || !accel || !scene->committed) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, NULL, 0,
                  "drift_view_create: needs a context, a committed scene and its accel");
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    drift_view_desc d = desc ? *desc : (drift_view_desc){ 0 };
    int32_t width = d.width ? d.width : scene->camera.width;
    int32_t height = d.height ? d.height : scene->camera.height;
    if (width <= 0 || height <= 0 || width > DRIFT_IMAGE_MAX_DIMENSION ||
        height > DRIFT_IMAGE_MAX_DIMENSION || !isfinite(d.exposure_stops) ||
        !(d.split_position >= 0.0f && d.split_position <= 1.0f)) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, NULL, 0,
                  "drift_view_create: bad size %dx%d, exposure or split position", width, height);
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    size_t pixel_bytes = 0;
    if (!drift_size_mul((size_t)width * 3u, (size_t)height, &pixel_bytes)) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }

    drift_view *view = drift_alloc(ctx, sizeof(*view));
    if (!view) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    *view = (drift_view){ .ctx = ctx,
                          .scene = scene,
                          .accel = accel,
                          .width = width,
                          .height = height,
                          .spp_per_frame = d.spp_per_frame ? d.spp_per_frame : 1u,
                          .seed = d.seed,
                          .camera = scene->camera,
                          .home = scene->camera,
                          .camera_moved = true,
                          .buffer_name = "frame",
                          .exposure_stops = d.exposure_stops,
                          .split = d.split,
                          .split_position = d.split_position > 0.0f ? d.split_position : 0.5f,
                          .overlay = !d.hide_overlay };
    view->move_step = drift_view_camera_step(scene);

    drift_result r = DRIFT_OK;
    view->pixels = drift_alloc(ctx, pixel_bytes);
    view->text_vertices = drift_alloc(ctx, VIEW_TEXT_VERTEX_BYTES);
    if (d.help_text) {
        size_t len = strnlen(d.help_text, HELP_TEXT_MAX - 1);
        view->help_text = drift_alloc(ctx, len + 1);
        if (view->help_text) {
            memcpy(view->help_text, d.help_text, len);
        }
    }
    if (!view->pixels || !view->text_vertices || (d.help_text && !view->help_text)) {
        r = DRIFT_ERR_OUT_OF_MEMORY;
        goto fail;
    }
    r = drift_view_edit_begin(view, d.reflection_edits_path);
    if (r != DRIFT_OK) {
        goto fail;
    }
    view->params = d.hybrid;
    view->params.width = width;
    view->params.height = height;
    view->params.reflection_edits = view->edits;
    r = drift_hybrid_create(ctx, scene, accel, &view->params, &view->hybrid);
    if (r != DRIFT_OK) {
        goto fail;
    }
    view->params = drift_hybrid_get_params(view->hybrid);
    view->base_seed = view->params.seed;
    if (d.temporal && !d.refine) {
        r = drift_temporal_create(ctx, width, height, &d.temporal_settings, &view->temporal);
        if (r == DRIFT_OK && d.temporal_settings.moving_refine) {
            r = drift_moving_refine_create(
                ctx, scene, accel, view->temporal,
                &(drift_moving_refine_settings){ .seed = view->base_seed + 0x9e3779b9u,
                                                 .max_history =
                                                     d.temporal_settings.moving_refine_history,
                                                 .residual = d.temporal_settings.moving_refine == 2,
                                                 .scale = d.temporal_settings.moving_refine_scale },
                &view->moving);
        }
        if (r == DRIFT_OK && !d.temporal_settings.no_still_refine) {
            r = drift_still_refine_create(
                ctx, scene, accel, width, height,
                &(drift_still_refine_settings){ .seed = view->base_seed,
                                                .spp = d.temporal_settings.still_spp,
                                                .keeps_hybrid =
                                                    d.temporal_settings.still_keeps_hybrid },
                &view->still);
        }
        if (r != DRIFT_OK) {
            goto fail;
        }
    }
    if (d.refine) {
        r = drift_refine_create(
            ctx, view->hybrid,
            &(drift_refine_params){ .budget = d.refine_budget ? d.refine_budget : 16384u },
            &view->sir);
        if (r != DRIFT_OK) {
            goto fail;
        }
    }
    *out_view = view;
    return DRIFT_OK;

fail:
    drift_view_destroy(view);
    return r;
}

void drift_view_destroy(drift_view *view)
{
    if (!view) {
        return;
    }
    drift_context *ctx = view->ctx;
    drift_refine_destroy(view->sir);
    drift_still_refine_destroy(view->still);
    drift_moving_refine_destroy(view->moving);
    drift_temporal_destroy(view->temporal);
    drift_hybrid_destroy(view->hybrid);
    drift_pt_destroy(view->reference);
    drift_view_edit_end(view);
    drift_free(ctx, view->pixels);
    drift_free(ctx, view->text_vertices);
    drift_free(ctx, view->help_text);
    drift_free(ctx, view);
}

// --- INPUT ---

static void cycle_technique(drift_view *view, drift_effect effect)
{
    int count = drift_technique_count(effect);
    if (count <= 0) {
        return;
    }
    int next = (drift_hybrid_params_technique(&view->params, effect) + 1) % count;
    drift_hybrid_params_set_technique(&view->params, effect, next);
    view->params_changed = true;
}

// Steps the selected knob; interleaving the environment's rays takes every pixel's (the
// frame refuses --env-scale 2 with it), as on the command line.
static bool step_knob(drift_view *view, int direction)
{
    const drift_knob *k = drift_knob_get(view->knob);
    double before = drift_knob_value(&view->params, view->knob);
    double after = drift_knob_step(k, before, direction);
    if (after == before || !drift_knob_set(&view->params, view->knob, after)) {
        return false;
    }
    if (view->params.environment_interleave && view->params.environment_scale == 2) {
        view->params.environment_scale = 1;
    }
    view->params_changed = true;
    view->overlay = true;
    return true;
}

// Passes on whether the camera controller moved the camera, noting a move for the reference.
static bool note_camera_move(drift_view *view, bool moved)
{
    view->camera_moved = view->camera_moved || moved;
    return moved;
}

static bool handle_key(drift_view *view, drift_view_key key)
{
    int effect = drift_view_key_effect(key);
    if (effect >= 0) {
        cycle_technique(view, (drift_effect)effect);
        return true;
    }
    switch (key) {
    case DRIFT_VIEW_KEY_NEXT_BUFFER:
    case DRIFT_VIEW_KEY_PREV_BUFFER:
        step_buffer(view, key == DRIFT_VIEW_KEY_NEXT_BUFFER ? 1 : -1);
        return true;
    case DRIFT_VIEW_KEY_SPLIT:
        view->split = !view->split;
        return true;
    case DRIFT_VIEW_KEY_SPLIT_LEFT:
        view->split_position = fmaxf(0.0f, view->split_position - SPLIT_STEP);
        return view->split;
    case DRIFT_VIEW_KEY_SPLIT_RIGHT:
        view->split_position = fminf(1.0f, view->split_position + SPLIT_STEP);
        return view->split;
    case DRIFT_VIEW_KEY_FORWARD:
    case DRIFT_VIEW_KEY_BACK:
    case DRIFT_VIEW_KEY_LEFT:
    case DRIFT_VIEW_KEY_RIGHT:
    case DRIFT_VIEW_KEY_UP:
    case DRIFT_VIEW_KEY_DOWN:
        return note_camera_move(view, drift_view_camera_fly(&view->camera, key, view->move_step));
    case DRIFT_VIEW_KEY_EXPOSURE_UP:
        view->exposure_stops += EXPOSURE_STEP;
        return true;
    case DRIFT_VIEW_KEY_EXPOSURE_DOWN:
        view->exposure_stops -= EXPOSURE_STEP;
        return true;
    case DRIFT_VIEW_KEY_RESET_CAMERA:
        view->camera = view->home;
        view->camera_moved = true;
        return true;
    case DRIFT_VIEW_KEY_OVERLAY:
        view->overlay = !view->overlay;
        return true;
    case DRIFT_VIEW_KEY_HELP:
        view->help = !view->help;
        view->overlay = view->overlay || view->help;
        return true;
    case DRIFT_VIEW_KEY_EDIT_REGION:
    case DRIFT_VIEW_KEY_EDIT_UNREGION:
    case DRIFT_VIEW_KEY_EDIT_UNDO:
    case DRIFT_VIEW_KEY_EDIT_SAVE:
    case DRIFT_VIEW_KEY_EDIT_GEODESIC_REGION:
        return drift_view_edit_key(view, key);
    case DRIFT_VIEW_KEY_KNOB_NEXT:
    case DRIFT_VIEW_KEY_KNOB_PREV: {
        int n = drift_knob_count();
        view->knob = (view->knob + (key == DRIFT_VIEW_KEY_KNOB_NEXT ? 1 : n - 1)) % n;
        view->overlay = true;
        return true;
    }
    case DRIFT_VIEW_KEY_KNOB_UP:
    case DRIFT_VIEW_KEY_KNOB_DOWN:
        return step_knob(view, key == DRIFT_VIEW_KEY_KNOB_UP ? 1 : -1);
    default:
        return false;
    }
}

bool drift_view_handle_event(drift_view *view, const drift_view_event *event)
{
    if (!view || !event) {
        return false;
    }
    switch (event->type) {
    case DRIFT_VIEW_EVENT_KEY:
        return handle_key(view, event->key);
    case DRIFT_VIEW_EVENT_ORBIT:
    case DRIFT_VIEW_EVENT_LOOK:
        return note_camera_move(
            view, drift_view_camera_drag(&view->camera, event->type, event->dx, event->dy));
    case DRIFT_VIEW_EVENT_DOLLY:
        return note_camera_move(view,
                                drift_view_camera_dolly(&view->camera, event->dy, view->move_step));
    case DRIFT_VIEW_EVENT_EDIT_PICK:
    case DRIFT_VIEW_EVENT_EDIT_RED:
    case DRIFT_VIEW_EVENT_EDIT_GREEN:
        return drift_view_edit_event(view, event);
    case DRIFT_VIEW_EVENT_SPLIT_AT:
        if (!isfinite(event->x)) {
            return false;
        }
        view->split = true;
        view->split_position = drift_clampf(event->x / (float)view->width, 0.0f, 1.0f);
        return true;
    default:
        return false;
    }
}

void drift_view_set_camera(drift_view *view, const drift_camera *camera)
{
    if (view && camera) {
        view->camera = *camera;
        view->camera_moved = true;
    }
}

// --- FRAME ---

// Temporal reuse: a new seed and a sub-pixel offset a frame, so that the history averages
// independent samples over the pixel (the path tracer's box filter).
drift_result drift_view_temporal_begin(drift_view *view, drift_camera *camera)
{
    // The same set-up as drift render's sequences and --frames (drift/temporal.h).
    return drift_temporal_prepare(view->hybrid, view->base_seed, view->temporal_frame++, camera);
}

drift_result drift_view_frame(drift_view *view, const atomic_bool *cancel)
{
    if (!view) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    drift_result r = DRIFT_OK;
    if (view->params_changed) {
        drift_temporal_reset(view->temporal); // other techniques: the history is another image
        drift_still_refine_reset(view->still);
        drift_moving_refine_reset(view->moving);
        view->temporal_frame = 0;
        view->params.seed = view->base_seed;
        r = drift_hybrid_set_params(view->hybrid, &view->params);
        view->params_changed = false;
        view->sir_dirty = true;
        view->params = drift_hybrid_get_params(view->hybrid); // what the frame has, if refused too
        if (r != DRIFT_OK) {
            return r;
        }
    }
    drift_camera camera = view->camera;
    bool refined = view->still && drift_still_refine_applies(&view->params);
    // --still-refine progressive: a standing camera's frames go to the path tracer alone.
    bool hybrid_frame = !refined || drift_still_refine_needs_hybrid(view->still, &view->camera);
    if (view->temporal && hybrid_frame) {
        r = drift_view_temporal_begin(view, &camera);
        if (r != DRIFT_OK) {
            return r;
        }
    }
    if (hybrid_frame) {
        r = drift_hybrid_render(view->hybrid, &camera, cancel);
    }
    if (r == DRIFT_OK && view->temporal && hybrid_frame) {
        r = drift_temporal_apply(view->temporal, drift_hybrid_gbuffer(view->hybrid), &camera,
                                 drift_hybrid_image(view->hybrid));
    }
    // The moving refinement (every frame) feeds the still one (frames of a standing camera).
    bool moving = view->moving && drift_still_refine_applies(&view->params);
    if (r == DRIFT_OK && moving) {
        if (hybrid_frame) { // else its last image stays the progressive refinement's start
            r = drift_moving_refine_apply(view->moving, drift_hybrid_gbuffer(view->hybrid),
                                          &view->camera, drift_hybrid_image(view->hybrid),
                                          drift_temporal_image(view->temporal), cancel);
        }
    } else {
        drift_moving_refine_reset(view->moving);
    }
    const drift_image *temporal_image =
        moving ? drift_moving_refine_image(view->moving) : drift_temporal_image(view->temporal);
    if (r == DRIFT_OK && refined) {
        // The camera before its jitter: a still one refines toward the path tracer.
        r = drift_still_refine_apply(view->still, &view->camera, temporal_image, cancel);
    } else {
        drift_still_refine_reset(view->still); // glare or edits on: the temporal image alone
    }
    if (r != DRIFT_OK) {
        return r;
    }
    view->hybrid_rendered = true; // its planes exist from now on
    if (view->sir) {
        // Re-sort only when the camera or the techniques changed; a standing view refines on.
        if (!view->sir_begun || view->sir_dirty ||
            memcmp(&view->sir_camera, &view->camera, sizeof view->camera) != 0) {
            r = drift_refine_begin(view->sir);
            view->sir_camera = view->camera;
            view->sir_dirty = false;
            view->sir_begun = r == DRIFT_OK;
        }
        if (r == DRIFT_OK && !drift_refine_done(view->sir)) {
            r = drift_refine_iterate(view->sir, cancel);
        }
        if (r != DRIFT_OK) {
            return r;
        }
    }
    if (view->pending_buffer_steps != 0) {
        step_buffer(view, view->pending_buffer_steps);
        view->pending_buffer_steps = 0;
    }
    if (view->camera_moved) {
        drift_pt_destroy(view->reference);
        view->reference = NULL;
        view->camera_moved = false;
    }
    drift_image reference = { 0 };
    if (view->split) {
        if (!view->reference && (r = reference_restart(view)) != DRIFT_OK) {
            return r;
        }
        r = drift_pt_render_samples(view->reference, view->spp_per_frame, cancel);
        if (r != DRIFT_OK && r != DRIFT_ERR_CANCELLED) {
            return r;
        }
        drift_result resolved = drift_pt_resolve(view->reference, DRIFT_PT_AOV_BEAUTY, &reference);
        if (resolved != DRIFT_OK) {
            return resolved;
        }
        if (r == DRIFT_ERR_CANCELLED) {
            return r;
        }
    }

    // The shown buffer: the composed frame, or a plane by name (it may have disappeared with
    // a technique change; then the frame again).
    const drift_image *shown = view->sir        ? drift_refine_image(view->sir)
                               : refined        ? drift_still_refine_image(view->still)
                               : view->temporal ? temporal_image
                                                : drift_hybrid_image(view->hybrid);
    const char *plane_name = NULL; // NULL: the composed frame
    uint32_t index = buffer_index(view, view->buffer_name);
    const char *name = NULL;
    const drift_image *plane = NULL;
    if (index > 0 && view_plane(view, index - 1, &name, &plane) && plane &&
        drift_image_is_valid(plane) && plane->width == view->width &&
        plane->height == view->height) {
        shown = plane;
        plane_name = name ? name : "";
    } else {
        snprintf(view->buffer_name, sizeof(view->buffer_name), "frame");
    }

    int32_t split_x = view->split ? split_column(view) : view->width;
    drift_view_show(view, shown, plane_name, &reference, split_x);
    if (view->overlay) {
        drift_view_draw_edits(view);
        drift_view_draw_overlay(view);
    }
    view->frame_count += 1;
    return DRIFT_OK;
}

// --- QUERIES ---

const uint8_t *drift_view_pixels(const drift_view *view)
{
    return view ? view->pixels : NULL;
}

drift_view_state drift_view_get_state(const drift_view *view)
{
    if (!view) {
        return (drift_view_state){ 0 };
    }
    return (drift_view_state){ .width = view->width,
                               .height = view->height,
                               .camera = view->camera,
                               .params = view->params,
                               .buffer = buffer_index(view, view->buffer_name),
                               .buffer_name = view->buffer_name,
                               .split = view->split,
                               .split_x = split_column(view),
                               .exposure_stops = view->exposure_stops,
                               .overlay = view->overlay,
                               .help = view->help,
                               .reference_spp =
                                   view->reference ? drift_pt_sample_count(view->reference) : 0u,
                               .frame_count = view->frame_count };
}

const drift_hybrid *drift_view_hybrid(const drift_view *view)
{
    return view ? view->hybrid : NULL;
}

drift_pt *drift_view_reference(drift_view *view)
{
    return view ? view->reference : NULL;
}
