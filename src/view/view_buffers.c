// How the viewer draws into its RGB8 framebuffer: the shown buffer (the composed frame
// tone-mapped, or a plane made readable by its name and channels), the reference right of the
// split line, the line itself, and the blended rectangles the overlay is made of.
// docs/viewer.md, Buffers.
#include "view/view_internal.h"

#include <math.h>
#include <string.h>

static uint8_t to_byte(float display)
{
    if (!(display > 0.0f)) {
        return 0;
    }
    return (uint8_t)lrintf(fminf(display, 1.0f) * 255.0f);
}

typedef enum buffer_look {
    LOOK_RADIANCE = 0, // tone-mapped with the exposure (frame, radiance and colour planes)
    LOOK_UNIT,         // 1 channel in [0,1]: grey as is (visibility, masks)
    LOOK_RANGE,        // 1 channel: (v - min) / (max - min), grey (ids, distances)
    LOOK_DEPTH,        // grey from 0.1 at the nearest hit to 1 at the farthest; misses (0) black
    LOOK_NORMAL,       // 0.5 + 0.5 n; black where there is no normal (a miss)
    LOOK_POSITION,     // normalized to the scene's bounds
    LOOK_MOTION,       // 2 channels: 0.5 + 0.5 m / max|m| as red and green
    LOOK_HEAT,         // 1 channel in [0,1] (SIR's error.*): black, blue, red, yellow
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

// How the plane called `name` is shown; sets *range where the look needs it.
static buffer_look look_of(const char *name, const drift_image *image, buffer_range *range)
{
    if (image->channels == 2) {
        *range = image_range(image, true, false);
        return LOOK_MOTION;
    }
    if (image->channels == 1) {
        if (strncmp(name, "error.", 6) == 0) {
            return LOOK_HEAT;
        }
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
        case LOOK_HEAT: {
            // Zero stays black so the pixels SIR will never trace stand out.
            float e = drift_clampf(p[0], 0.0f, 1.0f);
            if (e > 0.0f) {
                v[0] = drift_clampf(3.0f * e - 0.5f, 0.0f, 1.0f);
                v[1] = drift_clampf(3.0f * e - 2.0f, 0.0f, 1.0f);
                v[2] = drift_clampf(1.0f - 2.0f * e, 0.25f, 1.0f) * (e < 0.5f ? 1.0f : 0.0f);
            }
            break;
        }
        }
        for (int c = 0; c < 3; ++c) {
            out[c] = to_byte(v[c]);
        }
    }
}

void drift_view_blend_rect(drift_view *view, int32_t x0, int32_t y0, int32_t x1, int32_t y1,
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

void drift_view_show(drift_view *view, const drift_image *shown, const char *plane_name,
                     const drift_image *reference, int32_t split_x)
{
    buffer_look look = LOOK_RADIANCE;
    buffer_range range = { 0.0f, 0.0f };
    if (plane_name) {
        look = look_of(plane_name, shown, &range);
    }
    for (int32_t y = 0; y < view->height; ++y) {
        show_row(view, shown, look, range, y, 0, split_x);
        if (split_x < view->width) {
            show_row(view, reference, LOOK_RADIANCE, range, y, split_x, view->width);
        }
    }
    if (split_x > 0 && split_x < view->width) {
        // The split line, on the hybrid side's last column so reference pixels stay intact.
        const uint8_t white[3] = { 255, 255, 255 };
        drift_view_blend_rect(view, split_x - 1, 0, split_x, view->height, white, 0.6f);
    }
}
