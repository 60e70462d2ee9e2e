// ISG depth of field (Robison & Shirley 2009, section 3.3) over the focused frame and its
// circle-of-confusion plane c (eq. 15: c = c_inf |z - z_f| / z, in pixels):
//   search  a disk of radius c_inf (or the frame's largest circle when a near object's is
//           larger: the paper's search misses blur from nearer than z_f / 2); a sample
//           spreads onto the centre when its own circle covers it (distance <= c_i,
//           softened over a pixel); eq. 16 with smoothstep: a
//           sample behind the centre (z_i > z_0) with a larger circle (c_i > c_0) is turned
//           down by smoothstep(0, 5%, (z_i - z_0) / z_0) * smoothstep(0, 1 px, c_i - c_0),
//           so a blurred background does not spread over an in-focus foreground -> R, the
//           weighted average of the c_i (the centre's own c_0 included)
//   gather  a disk of radius R over the focused colours (the disk is the bokeh); eq. 17 with
//           smoothstep: a sample in front (z_i < z_0) with a smaller circle (c_i < c_0) is
//           turned down the same way, so an in-focus foreground does not bleed onto a blurred
//           background, while a blurred foreground still spreads over what is behind it.
// Eq. 16 and 17 in the paper give the weights c_i and c_inf for the two cases; with c_i <=
// c_inf that only halves a case, so the smoothstep weights above go from 1 to 0 instead
// (docs/isg.md). With isg_layers = 2 the gather also reads the second depth layer behind a
// blurred object (value_behind).
#include "isg/isg.h"

#include <math.h>

#define DEPTH_RAMP 0.05f // relative depth difference over which "behind" turns on

typedef struct range_ctx {
    const drift_image *coc;
    const drift_image *depth;
    int32_t x0, y0;
    float z0, c0;
    const float *behind; // the second layer's colour at the centre, or NULL
    float z_behind;      // and its depth
} range_ctx;

static float depth_at(const drift_image *depth, int32_t x, int32_t y)
{
    float z = drift_image_pixel(depth, x, y)[0];
    return z > 0.0f ? z : 1e30f; // a miss is infinitely far
}

// Eq. 16, softened.
static float range_search(const void *user, int32_t x, int32_t y)
{
    const range_ctx *c = user;
    float ci = drift_image_pixel(c->coc, x, y)[0];
    float dx = (float)(x - c->x0), dy = (float)(y - c->y0);
    float covers = 1.0f - drift_isg_smoothstep(ci - 0.5f, ci + 0.5f, sqrtf(dx * dx + dy * dy));
    float zi = depth_at(c->depth, x, y);
    float behind = drift_isg_smoothstep(0.0f, DEPTH_RAMP, (zi - c->z0) / c->z0) *
                   drift_isg_smoothstep(0.0f, 1.0f, ci - c->c0);
    return covers * (1.0f - behind);
}

// Eq. 17, softened.
static float range_gather(const void *user, int32_t x, int32_t y)
{
    const range_ctx *c = user;
    float ci = drift_image_pixel(c->coc, x, y)[0];
    float zi = depth_at(c->depth, x, y);
    float in_front = drift_isg_smoothstep(0.0f, DEPTH_RAMP, (c->z0 - zi) / c->z0) *
                     drift_isg_smoothstep(0.0f, 1.0f, c->c0 - ci);
    return 1.0f - in_front;
}

// With a second layer: a sample that lands past a blurred centre's object, on the layer the
// object hides (its depth within 20% of the second layer's at the centre), stands for a lens
// ray that misses the object, and that ray sees what lies behind the centre, not the
// neighbouring pixel's first surface. Samples further along the centre's own receding
// surface, or on a surface that meets it at a corner, are not at the hidden layer's depth and
// keep their own colour.
static const float *value_behind(const void *user, int32_t x, int32_t y)
{
    const range_ctx *c = user;
    float z = depth_at(c->depth, x, y);
    bool past = z > c->z0 * (1.0f + DEPTH_RAMP);
    return past && fabsf(z - c->z_behind) < 0.2f * c->z_behind ? c->behind : NULL;
}

typedef struct dof_job {
    float c_inf;
    float search_radius;
} dof_job;

// The filter with each range (and value) function inlined (isg.h).
#define DOF_FILTER(name, range, value, channels)                                             \
    static DRIFT_AVX2_CLONES float name(const drift_isg_kernel *k, const drift_image *image, \
                                        int32_t x, int32_t y, float *out)                    \
    {                                                                                        \
        return drift_isg_filter_inline(k, range, value, image, 0, channels, x, y, out);      \
    }
DOF_FILTER(dof_filter_search, range_search, NULL, 1)
DOF_FILTER(dof_filter_gather, range_gather, NULL, 3)
DOF_FILTER(dof_filter_gather_behind, range_gather, value_behind, 3)
#undef DOF_FILTER

static void dof_pixel(drift_frame_state *f, int32_t x, int32_t y, uint64_t *rays, void *user)
{
    (void)rays;
    const dof_job *job = user;
    drift_isg_state *s = drift_isg_of(f);
    range_ctx rc = { .coc = &f->coc,
                     .depth = &f->gbuffer.depth,
                     .x0 = x,
                     .y0 = y,
                     .z0 = depth_at(&f->gbuffer.depth, x, y),
                     .c0 = drift_image_pixel(&f->coc, x, y)[0] };
    drift_isg_jitter jitter =
        drift_isg_jitter_at(drift_hash_u32(f->params.seed ^ DRIFT_STREAM_ISG_DOF), x, y);
    drift_isg_kernel search = {
        &s->search,   jitter, drift_vec2_make(job->search_radius, job->search_radius),
        range_search, &rc,    NULL
    };
    float radius;
    dof_filter_search(&search, &f->coc, x, y, &radius); // the centre always counts
    drift_image_pixel(&s->dof_search, x, y)[0] = radius;
    float *out = drift_image_pixel(&f->final, x, y);
    if (!(radius >= 0.5f)) {
        drift_image_set3(&f->final, x, y, drift_image_get3(&f->focus, x, y));
        return;
    }
    drift_isg_value_fn value = NULL;
    if (f->params.isg.layers == 2 && rc.c0 >= 1.0f &&
        drift_image_pixel(&s->layer_depth, x, y)[0] > rc.z0) {
        rc.behind = drift_image_pixel(&s->layer_colour, x, y);
        rc.z_behind = drift_image_pixel(&s->layer_depth, x, y)[0];
        value = value_behind;
    }
    drift_isg_kernel gather = { &s->gather,   jitter, drift_vec2_make(radius, radius),
                                range_gather, &rc,    value };
    (value ? dof_filter_gather_behind : dof_filter_gather)(&gather, &f->focus, x, y, out);
}

drift_result drift_isg_pass_dof(drift_frame_state *f, const drift_pass_args *args)
{
    (void)args;
    double t = drift_time_now();
    drift_result r = drift_isg_prepare(f);
    if (r != DRIFT_OK) {
        return r;
    }
    // The search reaches c_inf (the paper), or further when something nearer than half the
    // focus distance has a larger circle: its blur must reach the pixels it spreads over.
    dof_job job = { .c_inf = drift_coc_radius_pixels(&f->camera, f->params.height, 1e30f) };
    float widest = 0.0f;
    for (int32_t y = 0; y < f->params.height; ++y) {
        for (int32_t x = 0; x < f->params.width; ++x) {
            widest = fmaxf(widest, drift_image_pixel(&f->coc, x, y)[0]); // fmaxf drops NaN
        }
    }
    job.search_radius =
        fmaxf(job.c_inf, fminf(widest, (float)(f->params.width + f->params.height)));
    if (!(job.c_inf >= 0.5f)) {
        drift_pass_copy_rgb(&f->focus, &f->final); // a pinhole, or nearly: the identity
        for (int32_t y = 0; y < f->params.height; ++y) {
            for (int32_t x = 0; x < f->params.width; ++x) {
                drift_image_pixel(&drift_isg_of(f)->dof_search, x, y)[0] = 0.0f;
            }
        }
    } else {
        if (f->params.isg.layers == 2) {
            r = drift_isg_pass_layer(f);
            if (r != DRIFT_OK) {
                return r;
            }
        }
        drift_pass_for_each_pixel(f, dof_pixel, &job);
    }
    f->stats.ms[DRIFT_PASS_ISG] += 1000.0 * (drift_time_now() - t);
    return DRIFT_OK;
}
