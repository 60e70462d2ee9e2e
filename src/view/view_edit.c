// Reflection editing in the view (thesis §7.2, the user model): pick a point on a reflective
// surface (a new constraint whose green handle starts where the point reflects now), drag its
// red handle (the reflection slides across the surface) or its green handle (what the point
// reflects), add and remove regions, undo, save. Every change re-commits the edit set, which
// the hybrid frame and the reference borrow, and restarts the reference.
#include "drift/file.h"
#include "view/view_internal.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define HISTORY_MAX 64

// One undo state: the descriptions the edit set is rebuilt from.
typedef struct view_edit_snapshot {
    drift_edit_distance distance;
    uint32_t constraint_count, region_count;
    drift_reflection_constraint constraints[DRIFT_EDIT_MAX_CONSTRAINTS];
    drift_reflection_region regions[DRIFT_EDIT_MAX_REGIONS];
    uint32_t *masks[DRIFT_EDIT_MAX_REGIONS]; // copies of mask regions' vertices
    int32_t selected;
} view_edit_snapshot;

static void snapshot_free(drift_context *ctx, view_edit_snapshot *s)
{
    for (uint32_t k = 0; k < s->region_count; ++k) {
        drift_free(ctx, s->masks[k]);
        s->masks[k] = NULL;
    }
}

static bool snapshot_take(drift_view *view, view_edit_snapshot *s)
{
    const drift_reflection_edits *e = view->edits;
    memset(s, 0, sizeof(*s));
    s->distance = drift_reflection_edits_distance(e);
    s->constraint_count = drift_reflection_edits_constraint_count(e);
    s->region_count = drift_reflection_edits_region_count(e);
    s->selected = view->selected;
    for (uint32_t n = 0; n < s->constraint_count; ++n) {
        s->constraints[n] = *drift_reflection_edits_constraint(e, n);
    }
    for (uint32_t k = 0; k < s->region_count; ++k) {
        s->regions[k] = *drift_reflection_edits_region(e, k);
        if (s->regions[k].mask_vertex_count > 0) {
            size_t bytes = s->regions[k].mask_vertex_count * sizeof(uint32_t);
            s->masks[k] = drift_alloc(view->ctx, bytes);
            if (!s->masks[k]) {
                snapshot_free(view->ctx, s);
                return false;
            }
            memcpy(s->masks[k], s->regions[k].mask_vertices, bytes);
            s->regions[k].mask_vertices = s->masks[k];
        }
    }
    return true;
}

// Rebuilds the edit set from a snapshot (all or nothing: on failure the set stays as it was).
static bool snapshot_restore(drift_view *view, const view_edit_snapshot *s)
{
    drift_reflection_edits *fresh = NULL;
    if (drift_reflection_edits_create(view->ctx, view->scene, view->accel, &fresh) != DRIFT_OK) {
        return false;
    }
    drift_reflection_edits_set_distance(fresh, s->distance);
    bool ok = true;
    for (uint32_t n = 0; n < s->constraint_count && ok; ++n) {
        ok = drift_reflection_edits_add_constraint(fresh, &s->constraints[n]) == DRIFT_OK;
    }
    for (uint32_t k = 0; k < s->region_count && ok; ++k) {
        ok = drift_reflection_edits_add_region(fresh, &s->regions[k]) == DRIFT_OK;
    }
    if (!ok || drift_reflection_edits_commit(fresh) != DRIFT_OK) {
        drift_reflection_edits_destroy(fresh);
        return false;
    }
    // The frame and the reference borrow the set: swap its contents in place by swapping the
    // pointers they hold.
    drift_reflection_edits *old = view->edits;
    view->edits = fresh;
    view->params.reflection_edits = fresh;
    view->params_changed = true;
    drift_pt_destroy(view->reference);
    view->reference = NULL;
    drift_reflection_edits_destroy(old);
    view->selected = s->selected < (int32_t)s->constraint_count ? s->selected : -1;
    view->camera_moved = true;
    return true;
}

drift_result drift_view_edit_begin(drift_view *view, const char *path)
{
    view->selected = -1;
    view->history = drift_alloc(view->ctx, HISTORY_MAX * sizeof(view_edit_snapshot));
    if (!view->history) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    if (path) {
        size_t len = strlen(path);
        view->edits_path = drift_alloc(view->ctx, len + 1);
        if (!view->edits_path) {
            return DRIFT_ERR_OUT_OF_MEMORY;
        }
        memcpy(view->edits_path, path, len);
        // A file that is there is loaded (a FIFO or device too: the loader refuses it, where
        // fopen here waited for a writer); a new one starts empty.
        char why[128];
        int fd = drift_input_open(path, why, sizeof why);
        if (fd >= 0 || errno == EINVAL) {
            if (fd >= 0) {
                close(fd);
            }
            return drift_reflection_edits_load(view->ctx, view->scene, view->accel, path,
                                               &view->edits);
        }
    }
    return drift_reflection_edits_create(view->ctx, view->scene, view->accel, &view->edits);
}

void drift_view_edit_end(drift_view *view)
{
    for (uint32_t i = 0; view->history && i < view->history_count; ++i) {
        snapshot_free(view->ctx, &view->history[i]);
    }
    drift_free(view->ctx, view->history);
    drift_free(view->ctx, view->edits_path);
    drift_reflection_edits_destroy(view->edits);
}

// Remembers the state before a change (the oldest is dropped when the history is full).
static bool push_history(drift_view *view)
{
    if (view->history_count == HISTORY_MAX) {
        snapshot_free(view->ctx, &view->history[0]);
        memmove(view->history, view->history + 1, (HISTORY_MAX - 1) * sizeof(view_edit_snapshot));
        view->history_count--;
    }
    if (!snapshot_take(view, &view->history[view->history_count])) {
        return false;
    }
    view->history_count++;
    return true;
}

// Applies a changed snapshot `next` (the state after an edit): kept when it commits, else the
// edit is dropped and the view stays as it was.
static bool apply(drift_view *view, view_edit_snapshot *next)
{
    if (!push_history(view)) {
        return false;
    }
    if (!snapshot_restore(view, next)) {
        view->history_count--;
        snapshot_free(view->ctx, &view->history[view->history_count]);
        return false;
    }
    return true;
}

// The surface seen through pixel (x, y) of the view's camera.
static bool surface_at(const drift_view *view, float x, float y, drift_ray *out_ray,
                       drift_surface *out)
{
    if (!isfinite(x) || !isfinite(y) || x < 0.0f || y < 0.0f || x >= (float)view->width ||
        y >= (float)view->height) {
        return false;
    }
    drift_camera_frame frame = drift_camera_frame_make(&view->camera, view->width, view->height);
    frame.camera.aperture_radius = 0.0f;
    *out_ray = drift_camera_frame_ray(&frame, x, y, drift_vec2_make(0.5f, 0.5f));
    drift_hit hit;
    if (!drift_accel_intersect(view->accel, out_ray, &hit) || hit.mesh == DRIFT_INVALID_INDEX) {
        return false;
    }
    *out = drift_scene_surface(view->scene, out_ray, &hit);
    return true;
}

static bool is_reflective(const drift_view *view, const drift_surface *s)
{
    return s->material != DRIFT_INVALID_INDEX &&
           !drift_vec3_is_zero(view->scene->materials[s->material].specular);
}

// What the point reflects now: the hit along r, or a point far along it.
static drift_vec3 reflected_point(const drift_view *view, const drift_surface *s, drift_vec3 r)
{
    drift_ray ray = { .origin = drift_offset_origin(s->position, s->ng, r),
                      .dir = r,
                      .tmin = 0.0f,
                      .tmax = INFINITY };
    drift_hit hit;
    if (drift_accel_intersect(view->accel, &ray, &hit)) {
        return drift_vec3_fma(ray.origin, r, hit.t);
    }
    return drift_vec3_fma(s->position, r, drift_scene_extent(view->scene));
}

bool drift_view_edit_event(drift_view *view, const drift_view_event *event)
{
    drift_ray ray;
    drift_surface s;
    if (!surface_at(view, event->x, event->y, &ray, &s)) {
        return false;
    }
    view_edit_snapshot *next = malloc(sizeof(view_edit_snapshot));
    if (!next || !snapshot_take(view, next)) {
        free(next);
        return false;
    }
    bool changed = false;
    if (event->type == DRIFT_VIEW_EVENT_EDIT_PICK && is_reflective(view, &s) &&
        next->constraint_count < DRIFT_EDIT_MAX_CONSTRAINTS) {
        drift_vec3 r = drift_vec3_reflect(drift_vec3_neg(ray.dir), s.ns);
        next->constraints[next->constraint_count] =
            (drift_reflection_constraint){ .mesh = s.mesh,
                                           .point = s.position,
                                           .target = reflected_point(view, &s, r),
                                           .view = view->camera.position };
        next->selected = (int32_t)next->constraint_count++;
        changed = true;
    } else if (event->type == DRIFT_VIEW_EVENT_EDIT_RED && view->selected >= 0 &&
               is_reflective(view, &s)) {
        drift_reflection_constraint *c = &next->constraints[view->selected];
        c->mesh = s.mesh;
        c->point = s.position;
        c->view = view->camera.position;
        changed = true;
    } else if (event->type == DRIFT_VIEW_EVENT_EDIT_GREEN && view->selected >= 0) {
        next->constraints[view->selected].target = s.position;
        changed = true;
    }
    changed = changed && apply(view, next);
    snapshot_free(view->ctx, next);
    free(next);
    return changed;
}

bool drift_view_edit_key(drift_view *view, drift_view_key key)
{
    if (key == DRIFT_VIEW_KEY_EDIT_SAVE) {
        if (!view->edits_path) {
            drift_log(view->ctx, DRIFT_LOG_WARNING, DRIFT_ERR_INVALID_ARGUMENT, NULL, 0,
                      "view: no edit file to save to (drift view --reflection-edits F.json)");
            return false;
        }
        if (drift_reflection_edits_save(view->edits, view->edits_path) == DRIFT_OK) {
            drift_log(view->ctx, DRIFT_LOG_INFO, DRIFT_OK, view->edits_path, 0,
                      "reflection edits saved");
        }
        return false;
    }
    if (key == DRIFT_VIEW_KEY_EDIT_UNDO) {
        if (view->history_count == 0) {
            return false;
        }
        view_edit_snapshot *last = &view->history[view->history_count - 1];
        bool ok = snapshot_restore(view, last);
        snapshot_free(view->ctx, last);
        view->history_count--;
        return ok;
    }
    view_edit_snapshot *next = malloc(sizeof(view_edit_snapshot));
    if (!next || !snapshot_take(view, next)) {
        free(next);
        return false;
    }
    bool changed = false;
    bool add = key == DRIFT_VIEW_KEY_EDIT_REGION || key == DRIFT_VIEW_KEY_EDIT_GEODESIC_REGION;
    if (add && view->selected >= 0 && next->region_count < DRIFT_EDIT_MAX_REGIONS) {
        // Around the red handle; a geodesic region measures along the handle's own mesh, so
        // it does not reach across a gap to another part of the object.
        const drift_reflection_constraint *c = &next->constraints[view->selected];
        float size = 0.05f * drift_scene_extent(view->scene);
        next->regions[next->region_count++] =
            (drift_reflection_region){ .type = key == DRIFT_VIEW_KEY_EDIT_REGION
                                                   ? DRIFT_EDIT_REGION_EUCLIDEAN
                                                   : DRIFT_EDIT_REGION_GEODESIC,
                                       .centre = c->point,
                                       .radius = size,
                                       .border = size,
                                       .mesh = c->mesh };
        changed = true;
    } else if (key == DRIFT_VIEW_KEY_EDIT_UNREGION && next->region_count > 0) {
        next->region_count--;
        drift_free(view->ctx, next->masks[next->region_count]);
        next->masks[next->region_count] = NULL;
        changed = true;
    }
    changed = changed && apply(view, next);
    snapshot_free(view->ctx, next);
    free(next);
    return changed;
}

// --- OVERLAY ---

static void draw_marker(drift_view *view, const drift_camera_frame *frame, drift_vec3 p,
                        const uint8_t color[3], int32_t half)
{
    drift_vec2 film;
    if (!drift_camera_frame_project(frame, p, &film)) {
        return;
    }
    int32_t x = (int32_t)floorf(film.x), y = (int32_t)floorf(film.y);
    static const uint8_t black[3] = { 0, 0, 0 };
    drift_view_blend_rect(view, x - half - 1, y - half - 1, x + half + 2, y + half + 2, black,
                          0.8f);
    drift_view_blend_rect(view, x - half, y - half, x + half + 1, y + half + 1, color, 1.0f);
}

void drift_view_draw_edits(drift_view *view)
{
    drift_camera_frame frame = drift_camera_frame_make(&view->camera, view->width, view->height);
    static const uint8_t red[3] = { 230, 30, 30 }, green[3] = { 40, 220, 40 },
                         yellow[3] = { 240, 210, 40 }, white[3] = { 255, 255, 255 };
    // Regions: the centre and 24 dots around the radius, in the camera's image plane.
    for (uint32_t k = 0; k < drift_reflection_edits_region_count(view->edits); ++k) {
        const drift_reflection_region *g = drift_reflection_edits_region(view->edits, k);
        if (g->type == DRIFT_EDIT_REGION_MASK) {
            continue;
        }
        draw_marker(view, &frame, g->centre, yellow, 1);
        for (int i = 0; i < 24; ++i) {
            float a = 2.0f * DRIFT_PI * (float)i / 24.0f;
            for (int ring = 0; ring < 2; ++ring) {
                float radius = g->radius + (ring ? g->border : 0.0f);
                drift_vec3 d = drift_vec3_add(drift_vec3_scale(frame.u, radius * cosf(a)),
                                              drift_vec3_scale(frame.v, radius * sinf(a)));
                draw_marker(view, &frame, drift_vec3_add(g->centre, d), ring ? white : yellow, 0);
            }
        }
    }
    for (uint32_t n = 0; n < drift_reflection_edits_constraint_count(view->edits); ++n) {
        const drift_reflection_constraint *c = drift_reflection_edits_constraint(view->edits, n);
        int32_t size = (int32_t)n == view->selected ? 3 : 2;
        draw_marker(view, &frame, c->target, green, size);
        draw_marker(view, &frame, c->point, red, size);
    }
}

const drift_reflection_edits *drift_view_reflection_edits(const drift_view *view)
{
    return view->edits;
}

int32_t drift_view_selected_constraint(const drift_view *view)
{
    return view->selected;
}
