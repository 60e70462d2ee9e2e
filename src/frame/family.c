// The helpers the families' report hooks share (frame/family.h).
#include "frame/family.h"

static bool sees_surface(const drift_frame_state *f, int32_t x, int32_t y)
{
    return drift_image_pixel(&f->gbuffer.material_id, x, y)[0] >= 0.0f;
}

uint64_t drift_family_surface_pixels(const drift_frame_state *f)
{
    uint64_t n = 0;
    for (int32_t y = 0; y < f->params.height; ++y) {
        for (int32_t x = 0; x < f->params.width; ++x) {
            n += sees_surface(f, x, y);
        }
    }
    return n;
}

static bool plane_fits(const drift_frame_state *f, const drift_image *plane, int c)
{
    return plane && plane->pixels && plane->width == f->params.width &&
           plane->height == f->params.height && c < plane->channels;
}

double drift_family_nonzero_mean(const drift_frame_state *f, const drift_image *plane,
                                 uint64_t *out_n)
{
    double sum = 0.0;
    uint64_t n = 0;
    for (int32_t y = 0; plane_fits(f, plane, 0) && y < f->params.height; ++y) {
        for (int32_t x = 0; x < f->params.width; ++x) {
            float v = drift_image_pixel(plane, x, y)[0];
            if (sees_surface(f, x, y) && v != 0.0f) {
                sum += (double)v;
                ++n;
            }
        }
    }
    if (out_n) {
        *out_n = n;
    }
    return n ? sum / (double)n : 0.0;
}

uint64_t drift_family_surface_at_least(const drift_frame_state *f, const drift_image *plane, int c,
                                       float at)
{
    if (!plane_fits(f, plane, c)) {
        return 0;
    }
    uint64_t n = 0;
    for (int32_t y = 0; y < f->params.height; ++y) {
        for (int32_t x = 0; x < f->params.width; ++x) {
            n += sees_surface(f, x, y) && drift_image_pixel(plane, x, y)[c] >= at;
        }
    }
    return n;
}
