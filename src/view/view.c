// The viewer's core: camera controller, technique and buffer selection, split view against
// the progressive reference, and the text overlay, all into an RGB8 framebuffer. No window
// code here (tools/cmd_view.c is the window); see include/drift/view.h and docs/viewer.md.
#include "drift/view.h"

#include "drift/image.h"
#include "drift/math.h"

#include <math.h>
#include <stb/stb_easy_font.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#define BUFFER_NAME_MAX  128
#define HELP_TEXT_MAX    4096
#define OVERLAY_TEXT_MAX 2048
// stb_easy_font writes 64 bytes a quad; one line of the overlay stays far below this.
#define TEXT_VERTEX_BYTES (64 * 4096)

#define ORBIT_RADIANS_PER_PIXEL 0.005f
#define MOVE_FRACTION           0.02f // of the scene's bounding-box diagonal, per key press
#define DOLLY_FACTOR            0.9f  // distance to the target times this per wheel notch
#define EXPOSURE_STEP           0.5f
#define SPLIT_STEP              (1.0f / 16.0f)
// How close (|cos|) the view direction may come to the up vector before pitching stops.
#define MAX_COS_TO_UP 0.995f

struct drift_view {
    drift_context *ctx;
    const drift_scene *scene;
    const drift_accel *accel;
    int32_t width, height;

    drift_hybrid *hybrid;
    drift_hybrid_params params;
    bool params_changed;
    bool hybrid_rendered; // a frame was rendered: drift_hybrid_plane has planes

    drift_pt *reference;           // NULL until a frame with the split on, and after a move
    drift_camera reference_camera; // the camera the reference was created with
    uint32_t spp_per_frame;
    uint32_t seed;

    drift_camera camera;
    drift_camera home; // the scene's camera (RESET_CAMERA)
    bool camera_moved; // since the last frame: the reference must restart
    float move_step;

    char buffer_name[BUFFER_NAME_MAX]; // "frame" or a plane name; looked up at each frame
    int32_t pending_buffer_steps;      // buffer keys pressed before the first frame
    float exposure_stops;
    bool split;
    float split_position;
    bool overlay, help;
    char *help_text;

    uint8_t *pixels;
    void *text_vertices;
    uint64_t frame_count;
};

// --- SMALL HELPERS ---

static const char *const key_names[DRIFT_VIEW_KEY_COUNT] = {
    "none",         "shadows", "reflections", "dof",         "indirect",    "next-buffer",
    "prev-buffer",  "split",   "split-left",  "split-right", "forward",     "back",
    "left",         "right",   "up",          "down",        "exposure-up", "exposure-down",
    "reset-camera", "overlay", "help",
};

const char *drift_view_key_name(drift_view_key key)
{
    return (unsigned)key < DRIFT_VIEW_KEY_COUNT ? key_names[key] : NULL;
}

static uint8_t to_byte(float display)
{
    if (!(display > 0.0f)) {
        return 0;
    }
    return (uint8_t)lrintf(fminf(display, 1.0f) * 255.0f);
}

// Rotates v about the unit axis k by angle (Rodrigues).
static drift_vec3 rotate(drift_vec3 v, drift_vec3 k, float angle)
{
    float c = cosf(angle), s = sinf(angle);
    drift_vec3 r = drift_vec3_scale(v, c);
    r = drift_vec3_fma(r, drift_vec3_cross(k, v), s);
    return drift_vec3_fma(r, k, drift_vec3_dot(k, v) * (1.0f - c));
}

static int32_t split_column(const drift_view *view)
{
    long x = lrintf(view->split_position * (float)view->width);
    return (int32_t)(x < 0 ? 0 : (x > view->width ? view->width : x));
}

// The index (1-based; 0 = the composed frame) of the plane called `name` in the last frame.
static uint32_t buffer_index(const drift_view *view, const char *name)
{
    if (!view->hybrid_rendered || strcmp(name, "frame") == 0) {
        return 0;
    }
    const char *plane_name = NULL;
    const drift_image *image = NULL;
    for (uint32_t i = 0; drift_hybrid_plane(view->hybrid, i, &plane_name, &image); ++i) {
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
    while (drift_hybrid_plane(view->hybrid, count, &name, &image)) {
        ++count;
    }
    return count;
}

static void select_buffer(drift_view *view, uint32_t index)
{
    const char *name = NULL;
    const drift_image *image = NULL;
    if (index == 0 || !drift_hybrid_plane(view->hybrid, index - 1, &name, &image) || !name) {
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
                              .camera = &view->reference_camera };
}

static drift_result reference_restart(drift_view *view)
{
    drift_pt_destroy(view->reference);
    view->reference = NULL;
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
    drift_vec3 extent = drift_vec3_sub(scene->bounds.max, scene->bounds.min);
    float diagonal = drift_bounds3_is_empty(scene->bounds) ? 0.0f : drift_vec3_length(extent);
    if (!(diagonal > 0.0f) || !isfinite(diagonal)) {
        diagonal = drift_vec3_length(drift_vec3_sub(scene->camera.target, scene->camera.position));
    }
    view->move_step = diagonal > 0.0f && isfinite(diagonal) ? MOVE_FRACTION * diagonal : 0.1f;

    drift_result r = DRIFT_OK;
    view->pixels = drift_alloc(ctx, pixel_bytes);
    view->text_vertices = drift_alloc(ctx, TEXT_VERTEX_BYTES);
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
    view->params = d.hybrid;
    view->params.width = width;
    view->params.height = height;
    r = drift_hybrid_create(ctx, scene, accel, &view->params, &view->hybrid);
    if (r != DRIFT_OK) {
        goto fail;
    }
    view->params = drift_hybrid_get_params(view->hybrid);
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
    drift_hybrid_destroy(view->hybrid);
    drift_pt_destroy(view->reference);
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
    drift_hybrid_params *p = &view->params;
    switch (effect) {
    case DRIFT_EFFECT_SHADOWS:
        p->shadows = (drift_shadow_technique)(((int)p->shadows + 1) % count);
        break;
    case DRIFT_EFFECT_REFLECTIONS:
        p->reflections = (drift_reflection_technique)(((int)p->reflections + 1) % count);
        break;
    case DRIFT_EFFECT_DOF:
        p->dof = (drift_dof_technique)(((int)p->dof + 1) % count);
        break;
    case DRIFT_EFFECT_INDIRECT:
        p->indirect = (drift_indirect_technique)(((int)p->indirect + 1) % count);
        break;
    default:
        return;
    }
    view->params_changed = true;
}

// Moves camera and target together by `delta`.
static void camera_translate(drift_view *view, drift_vec3 direction, float amount)
{
    drift_vec3 delta = drift_vec3_scale(direction, amount);
    view->camera.position = drift_vec3_add(view->camera.position, delta);
    view->camera.target = drift_vec3_add(view->camera.target, delta);
    view->camera_moved = true;
}

typedef struct camera_axes {
    drift_vec3 forward, right, up;
    float distance; // to the target
} camera_axes;

static bool camera_axes_of(const drift_camera *camera, camera_axes *out)
{
    drift_vec3 to_target = drift_vec3_sub(camera->target, camera->position);
    out->distance = drift_vec3_length(to_target);
    out->up = drift_vec3_normalize(camera->up);
    if (!(out->distance > 0.0f) || drift_vec3_is_zero(out->up)) {
        return false;
    }
    out->forward = drift_vec3_scale(to_target, 1.0f / out->distance);
    drift_vec3 right = drift_vec3_cross(out->forward, out->up);
    if (!(drift_vec3_length(right) > 1e-6f)) {
        return false;
    }
    out->right = drift_vec3_normalize(right);
    return true;
}

// Turns `v` (the view direction, or the offset from the target) by yaw about up and pitch
// about right, refusing a pitch that would bring it within acos(MAX_COS_TO_UP) of up.
static drift_vec3 turn(drift_vec3 v, const camera_axes *axes, float yaw, float pitch)
{
    v = rotate(v, axes->up, yaw);
    drift_vec3 right = drift_vec3_normalize(drift_vec3_cross(v, axes->up));
    drift_vec3 pitched = rotate(v, right, pitch);
    float cos_up = drift_vec3_dot(drift_vec3_normalize(pitched), axes->up);
    return fabsf(cos_up) < MAX_COS_TO_UP ? pitched : v;
}

static bool camera_drag(drift_view *view, drift_view_event_type type, float dx, float dy)
{
    camera_axes axes;
    if (!isfinite(dx) || !isfinite(dy) || (dx == 0.0f && dy == 0.0f) ||
        !camera_axes_of(&view->camera, &axes)) {
        return false;
    }
    float yaw = -dx * ORBIT_RADIANS_PER_PIXEL, pitch = -dy * ORBIT_RADIANS_PER_PIXEL;
    drift_camera *c = &view->camera;
    if (type == DRIFT_VIEW_EVENT_ORBIT) {
        // The camera circles the target; dragging right swings it to the left, so the scene
        // appears to turn with the mouse. Pitch is negated for the same reason.
        drift_vec3 offset = drift_vec3_sub(c->position, c->target);
        c->position = drift_vec3_add(c->target, turn(offset, &axes, yaw, -pitch));
    } else {
        drift_vec3 direction = drift_vec3_sub(c->target, c->position);
        c->target = drift_vec3_add(c->position, turn(direction, &axes, yaw, pitch));
    }
    view->camera_moved = true;
    return true;
}

static bool camera_dolly(drift_view *view, float notches)
{
    camera_axes axes;
    if (!isfinite(notches) || notches == 0.0f || !camera_axes_of(&view->camera, &axes)) {
        return false;
    }
    float distance = axes.distance * powf(DOLLY_FACTOR, notches);
    float min_distance = 1e-3f * view->move_step;
    if (distance < min_distance) {
        distance = min_distance;
    }
    view->camera.position = drift_vec3_fma(view->camera.target, axes.forward, -distance);
    view->camera_moved = true;
    return true;
}

static bool handle_key(drift_view *view, drift_view_key key)
{
    camera_axes axes;
    bool have_axes = camera_axes_of(&view->camera, &axes);
    float step = view->move_step;
    switch (key) {
    case DRIFT_VIEW_KEY_SHADOWS:
        cycle_technique(view, DRIFT_EFFECT_SHADOWS);
        return true;
    case DRIFT_VIEW_KEY_REFLECTIONS:
        cycle_technique(view, DRIFT_EFFECT_REFLECTIONS);
        return true;
    case DRIFT_VIEW_KEY_DOF:
        cycle_technique(view, DRIFT_EFFECT_DOF);
        return true;
    case DRIFT_VIEW_KEY_INDIRECT:
        cycle_technique(view, DRIFT_EFFECT_INDIRECT);
        return true;
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
        if (!have_axes) {
            return false;
        }
        camera_translate(view, axes.forward, key == DRIFT_VIEW_KEY_FORWARD ? step : -step);
        return true;
    case DRIFT_VIEW_KEY_LEFT:
    case DRIFT_VIEW_KEY_RIGHT:
        if (!have_axes) {
            return false;
        }
        camera_translate(view, axes.right, key == DRIFT_VIEW_KEY_RIGHT ? step : -step);
        return true;
    case DRIFT_VIEW_KEY_UP:
    case DRIFT_VIEW_KEY_DOWN:
        if (!have_axes) {
            return false;
        }
        camera_translate(view, axes.up, key == DRIFT_VIEW_KEY_UP ? step : -step);
        return true;
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
        return camera_drag(view, event->type, event->dx, event->dy);
    case DRIFT_VIEW_EVENT_DOLLY:
        return camera_dolly(view, event->dy);
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

// --- SHOWING A BUFFER ---

typedef enum buffer_look {
    LOOK_RADIANCE = 0, // tone-mapped with the exposure (frame, radiance and colour planes)
    LOOK_UNIT,         // 1 channel in [0,1]: grey as is (visibility, masks)
    LOOK_RANGE,        // 1 channel: (v - min) / (max - min), grey (ids, distances)
    LOOK_DEPTH,        // grey from 0.1 at the nearest hit to 1 at the farthest; misses (0) black
    LOOK_NORMAL,       // 0.5 + 0.5 n; black where there is no normal (a miss)
    LOOK_POSITION,     // normalized to the scene's bounds
    LOOK_MOTION,       // 2 channels: 0.5 + 0.5 m / max|m| as red and green
} buffer_look;

typedef struct buffer_range {
    float lo, hi;
} buffer_range;

// The finite range of the values (absolute: of |v|; positive: of the values above 0 only).
static buffer_range image_range(const drift_image *image, bool absolute, bool positive)
{
    buffer_range range = { INFINITY, -INFINITY };
    for (int32_t y = 0; y < image->height; ++y) {
        const float *p = drift_image_pixel(image, 0, y);
        for (int32_t i = 0; i < image->width * image->channels; ++i) {
            float v = absolute ? fabsf(p[i]) : p[i];
            if (isfinite(v) && (!positive || v > 0.0f)) {
                range.lo = fminf(range.lo, v);
                range.hi = fmaxf(range.hi, v);
            }
        }
    }
    if (range.lo > range.hi) {
        range = (buffer_range){ 0.0f, 0.0f };
    }
    return range;
}

static buffer_look look_of(const char *name, const drift_image *image, buffer_range *range)
{
    if (image->channels == 2) {
        *range = image_range(image, true, false);
        return LOOK_MOTION;
    }
    if (image->channels == 1) {
        if (strstr(name, "depth")) {
            *range = image_range(image, false, true);
            return LOOK_DEPTH;
        }
        *range = image_range(image, false, false);
        return range->lo >= 0.0f && range->hi <= 1.0f ? LOOK_UNIT : LOOK_RANGE;
    }
    if (strstr(name, "normal")) {
        return LOOK_NORMAL;
    }
    if (strstr(name, "position")) {
        return LOOK_POSITION;
    }
    return LOOK_RADIANCE;
}

// Writes columns [x0, x1) of row y of `image` into the framebuffer.
static void show_row(drift_view *view, const drift_image *image, buffer_look look,
                     buffer_range range, int32_t y, int32_t x0, int32_t x1)
{
    const drift_tonemap_params tonemap = { .exposure_stops = view->exposure_stops };
    const drift_bounds3 bounds = view->scene->bounds;
    uint8_t *out = view->pixels + ((size_t)y * (size_t)view->width + (size_t)x0) * 3u;
    for (int32_t x = x0; x < x1; ++x, out += 3) {
        const float *p = drift_image_pixel(image, x, y);
        float v[3] = { 0.0f, 0.0f, 0.0f };
        switch (look) {
        case LOOK_RADIANCE:
            for (int c = 0; c < 3; ++c) {
                v[c] = drift_tonemap_value(p[image->channels >= 3 ? c : 0], &tonemap);
            }
            break;
        case LOOK_UNIT:
            v[0] = v[1] = v[2] = p[0];
            break;
        case LOOK_RANGE:
            v[0] = v[1] = v[2] =
                range.hi > range.lo ? (p[0] - range.lo) / (range.hi - range.lo) : 0.5f;
            break;
        case LOOK_DEPTH:
            v[0] = v[1] = v[2] = !(p[0] > 0.0f) ? 0.0f
                                 : range.hi > range.lo
                                     ? 0.1f + 0.9f * (p[0] - range.lo) / (range.hi - range.lo)
                                     : 1.0f;
            break;
        case LOOK_NORMAL:
            // A miss has no normal (zero): black rather than the grey of 0.5 + 0.5 * 0.
            for (int c = 0; c < 3 && (p[0] != 0.0f || p[1] != 0.0f || p[2] != 0.0f); ++c) {
                v[c] = 0.5f + 0.5f * p[c];
            }
            break;
        case LOOK_POSITION: {
            const float lo[3] = { bounds.min.x, bounds.min.y, bounds.min.z };
            const float hi[3] = { bounds.max.x, bounds.max.y, bounds.max.z };
            for (int c = 0; c < 3; ++c) {
                v[c] = hi[c] > lo[c] ? (p[c] - lo[c]) / (hi[c] - lo[c]) : 0.5f;
            }
            break;
        }
        case LOOK_MOTION: {
            float scale = range.hi > 1.0f ? range.hi : 1.0f;
            v[0] = 0.5f + 0.5f * p[0] / scale;
            v[1] = 0.5f + 0.5f * p[1] / scale;
            break;
        }
        }
        for (int c = 0; c < 3; ++c) {
            out[c] = to_byte(v[c]);
        }
    }
}

// --- THE OVERLAY ---

// Fills [x0, x1) x [y0, y1) with `color` blended at `alpha` over the framebuffer.
static void blend_rect(drift_view *view, int32_t x0, int32_t y0, int32_t x1, int32_t y1,
                       const uint8_t color[3], float alpha)
{
    x0 = x0 < 0 ? 0 : x0;
    y0 = y0 < 0 ? 0 : y0;
    x1 = x1 > view->width ? view->width : x1;
    y1 = y1 > view->height ? view->height : y1;
    for (int32_t y = y0; y < y1; ++y) {
        uint8_t *p = view->pixels + ((size_t)y * (size_t)view->width + (size_t)x0) * 3u;
        for (int32_t x = x0; x < x1; ++x, p += 3) {
            for (int c = 0; c < 3; ++c) {
                p[c] = (uint8_t)lrintf((float)p[c] * (1.0f - alpha) + (float)color[c] * alpha);
            }
        }
    }
}

// stb_easy_font indexes a table by (char - 32): keep printable ASCII, tabs and newlines.
static void sanitize(char *text)
{
    for (char *c = text; *c; ++c) {
        if (*c != '\n' && *c != '\t' && (*c < 32 || *c > 126)) {
            *c = '?';
        }
    }
}

#define TEXT_MAX_COLUMNS 8
#define TEXT_COLUMN_GAP  8 // font units between table columns
#define TEXT_LINE_HEIGHT 12

// Calls draw(cell, column x, line y) for every tab-separated cell of `text` in font units;
// columns line up (each as wide as its widest cell). Returns the table's size.
typedef void (*cell_func)(drift_view *view, char *cell, int32_t x, int32_t y, void *user);

static void layout_table(drift_view *view, char *text, cell_func draw, void *user,
                         int32_t *out_width, int32_t *out_height)
{
    int32_t widths[TEXT_MAX_COLUMNS] = { 0 };
    int32_t lines = 0;
    for (int pass = 0; pass < 2; ++pass) {
        char *line = text;
        lines = 0;
        while (*line) {
            char *line_end = strchr(line, '\n');
            char *next = line_end ? line_end + 1 : line + strlen(line);
            char saved_line = line_end ? *line_end : '\0';
            if (line_end) {
                *line_end = '\0';
            }
            int32_t x = 0;
            char *cell = line;
            for (int column = 0; cell; ++column) {
                char *tab = column < TEXT_MAX_COLUMNS - 1 ? strchr(cell, '\t') : NULL;
                if (tab) {
                    *tab = '\0';
                }
                if (pass == 0) {
                    int32_t w = stb_easy_font_width(cell);
                    widths[column] = w > widths[column] ? w : widths[column];
                } else if (draw) {
                    draw(view, cell, x, lines * TEXT_LINE_HEIGHT, user);
                }
                x += widths[column] + TEXT_COLUMN_GAP;
                if (tab) {
                    *tab = '\t';
                }
                cell = tab ? tab + 1 : NULL;
            }
            if (line_end) {
                *line_end = saved_line;
            }
            lines += 1;
            line = next;
        }
    }
    int32_t width = 0;
    for (int c = 0; c < TEXT_MAX_COLUMNS; ++c) {
        width += widths[c] > 0 ? widths[c] + (c ? TEXT_COLUMN_GAP : 0) : 0;
    }
    *out_width = width;
    *out_height = lines * TEXT_LINE_HEIGHT - 2; // the last line has no gap below it
}

typedef struct text_origin {
    int32_t x, y, scale;
} text_origin;

// Rasterizes stb_easy_font's quads for one cell into the framebuffer.
static void draw_cell(drift_view *view, char *cell, int32_t x, int32_t y, void *user)
{
    const text_origin *o = user;
    const uint8_t ink[3] = { 235, 235, 235 };
    int quads =
        stb_easy_font_print((float)x, (float)y, cell, NULL, view->text_vertices, TEXT_VERTEX_BYTES);
    const float *v = view->text_vertices; // 4 floats a vertex: x, y, z, colour bytes
    const float s = (float)o->scale;
    for (int q = 0; q < quads; ++q, v += 16) {
        // Vertices 0 and 2 are opposite corners of the quad.
        float qx0 = fminf(v[0], v[8]), qx1 = fmaxf(v[0], v[8]);
        float qy0 = fminf(v[1], v[9]), qy1 = fmaxf(v[1], v[9]);
        blend_rect(view, o->x + (int32_t)lrintf(qx0 * s), o->y + (int32_t)lrintf(qy0 * s),
                   o->x + (int32_t)lrintf(qx1 * s), o->y + (int32_t)lrintf(qy1 * s), ink, 1.0f);
    }
}

// Draws `text` (lines separated by '\n', table cells by '\t') at (x, y) on a dark box,
// `scale` pixels a font unit.
static void draw_text(drift_view *view, char *text, int32_t x, int32_t y, int32_t scale)
{
    sanitize(text);
    int32_t w = 0, h = 0;
    layout_table(view, text, NULL, NULL, &w, &h);
    const int32_t pad = 4 * scale;
    const uint8_t dark[3] = { 0, 0, 0 };
    blend_rect(view, x - pad, y - pad, x + w * scale + pad, y + h * scale + pad, dark, 0.7f);
    text_origin origin = { x, y, scale };
    layout_table(view, text, draw_cell, &origin, &w, &h);
}

// Appends printf-style text to buf (capacity OVERLAY_TEXT_MAX), truncating quietly.
#if defined(__GNUC__)
__attribute__((format(printf, 3, 4)))
#endif
static void
append(char *buf, size_t *len, const char *fmt, ...)
{
    if (*len >= OVERLAY_TEXT_MAX - 1) {
        return;
    }
    va_list args;
    va_start(args, fmt);
    int n = vsnprintf(buf + *len, OVERLAY_TEXT_MAX - *len, fmt, args);
    va_end(args);
    if (n > 0) {
        *len += (size_t)n < OVERLAY_TEXT_MAX - *len ? (size_t)n : OVERLAY_TEXT_MAX - 1 - *len;
    }
}

static const char *technique_of(const drift_hybrid_params *p, drift_effect effect)
{
    int t = effect == DRIFT_EFFECT_SHADOWS       ? (int)p->shadows
            : effect == DRIFT_EFFECT_REFLECTIONS ? (int)p->reflections
            : effect == DRIFT_EFFECT_DOF         ? (int)p->dof
                                                 : (int)p->indirect;
    const char *name = drift_technique_name(effect, t);
    return name ? name : "?";
}

static void draw_overlay(drift_view *view)
{
    char text[OVERLAY_TEXT_MAX];
    size_t len = 0;
    text[0] = '\0';
    if (view->help && view->help_text) {
        append(text, &len, "%s", view->help_text);
    } else {
        for (int e = 0; e < DRIFT_EFFECT_COUNT; ++e) {
            append(text, &len, "%s\t%s\n", drift_effect_name((drift_effect)e),
                   technique_of(&view->params, (drift_effect)e));
        }
        append(text, &len, "buffer\t%s\n", view->buffer_name);
        append(text, &len, "exposure\t%+.1f stops\n", (double)view->exposure_stops);
        if (view->split) {
            append(text, &len, "pt reference\t%u spp\n",
                   view->reference ? drift_pt_sample_count(view->reference) : 0u);
        } else {
            append(text, &len, "pt reference\toff\n");
        }
        drift_hybrid_stats stats = drift_hybrid_get_stats(view->hybrid);
        append(text, &len, "frame\t%.2f ms\n", stats.frame_ms);
        int column = 0;
        for (int p = 0; p < DRIFT_PASS_COUNT; ++p) {
            if (!(stats.ms[p] > 0.0)) {
                continue; // the pass did not run (or was cached) this frame
            }
            const char *name = drift_hybrid_pass_name((drift_hybrid_pass)p);
            append(text, &len, "%s%s\t%.2f ms", column ? "\t" : "", name ? name : "?", stats.ms[p]);
            column = !column;
            if (!column) {
                append(text, &len, "\n");
            }
        }
    }
    while (len > 0 && text[len - 1] == '\n') {
        text[--len] = '\0';
    }
    int32_t scale = view->width >= 1280 ? 2 : 1;
    draw_text(view, text, 6 * scale, 6 * scale, scale);
}

// --- FRAME ---

drift_result drift_view_frame(drift_view *view, const atomic_bool *cancel)
{
    if (!view) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    drift_result r = DRIFT_OK;
    if (view->params_changed) {
        r = drift_hybrid_set_params(view->hybrid, &view->params);
        view->params_changed = false;
        if (r != DRIFT_OK) {
            view->params = drift_hybrid_get_params(view->hybrid); // keep what the frame has
            return r;
        }
        view->params = drift_hybrid_get_params(view->hybrid);
    }
    r = drift_hybrid_render(view->hybrid, &view->camera, cancel);
    if (r != DRIFT_OK) {
        return r;
    }
    view->hybrid_rendered = true; // its planes exist from now on
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
    const drift_image *shown = drift_hybrid_image(view->hybrid);
    buffer_look look = LOOK_RADIANCE;
    buffer_range range = { 0.0f, 0.0f };
    uint32_t index = buffer_index(view, view->buffer_name);
    const char *name = NULL;
    const drift_image *plane = NULL;
    if (index > 0 && drift_hybrid_plane(view->hybrid, index - 1, &name, &plane) && plane &&
        drift_image_is_valid(plane) && plane->width == view->width &&
        plane->height == view->height) {
        shown = plane;
        look = look_of(name ? name : "", plane, &range);
    } else {
        snprintf(view->buffer_name, sizeof(view->buffer_name), "frame");
    }

    int32_t split_x = view->split ? split_column(view) : view->width;
    for (int32_t y = 0; y < view->height; ++y) {
        show_row(view, shown, look, range, y, 0, split_x);
        if (split_x < view->width) {
            show_row(view, &reference, LOOK_RADIANCE, range, y, split_x, view->width);
        }
    }
    if (view->split && split_x > 0 && split_x < view->width) {
        // The split line, on the hybrid side's last column so reference pixels stay intact.
        const uint8_t white[3] = { 255, 255, 255 };
        blend_rect(view, split_x - 1, 0, split_x, view->height, white, 0.6f);
    }
    if (view->overlay) {
        draw_overlay(view);
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
