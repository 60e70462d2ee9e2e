// Image space gathering's building block, the point-sampled cross-bilateral filter of eq. 4
// (the same samples in numerator and denominator, the centre included: consistent, not
// unbiased), and the frame's ISG state: parameters, buffers, sample patterns and planes.
// Each effect runs it twice, a parameter search and then a gather (isg_shadows.c,
// isg_reflections.c, isg_dof.c).
#include "isg/isg.h"

#include <math.h>
#include <stdio.h>

// --- THE FILTER ---

float drift_isg_filter(const drift_isg_kernel *k, const drift_image *image, int32_t first,
                       int32_t channels, int32_t x, int32_t y, float *out)
{
    return drift_isg_filter_inline(k, k->range, k->value, image, first, channels, x, y, out);
}

float drift_isg_pixels_per_unit(const drift_camera *camera, int32_t height)
{
    return (float)height / (2.0f * tanf(0.5f * camera->fov_y));
}

float drift_isg_fov_x(const drift_camera *camera, int32_t width, int32_t height)
{
    float aspect = (float)width / (float)height;
    return 2.0f * atanf(aspect * tanf(0.5f * camera->fov_y));
}

float drift_isg_penumbra(float light_size, float occluder_distance, float light_distance)
{
    if (!(light_size > 0.0f) || !isfinite(occluder_distance) || !(occluder_distance > 0.0f)) {
        return 0.0f;
    }
    if (!isfinite(light_distance)) {
        return 0.0f; // a directional light has no size here
    }
    // An occluder at the light (d -> D) would give an infinite penumbra: cap d / (D - d) at 1e3.
    float gap = fmaxf(light_distance - occluder_distance, 1e-3f * occluder_distance);
    return light_size * occluder_distance / gap;
}

float drift_isg_gloss_alpha(float theta_max, float eye_distance, float reflected_distance)
{
    if (!(theta_max > 0.0f)) {
        return 0.0f;
    }
    float t = tanf(fminf(theta_max, 1.5f)); // under pi/2: tan stays finite
    if (!isfinite(reflected_distance)) {
        return atanf(t); // E -> infinity: alpha = theta_max
    }
    return atanf(reflected_distance * t / (eye_distance + reflected_distance));
}

// --- PARAMETERS ---

void drift_isg_settings_resolve(drift_isg_settings *s, const drift_scene *scene)
{
    s->search = s->search ? s->search : 25;
    s->gather = s->gather ? s->gather : 49;
    if (!(s->sigma > 0.0f)) {
        float width = 0.02f * (scene ? drift_scene_extent(scene) : 1.0f);
        s->sigma = width * width;
    }
    s->a = s->a > 0.0f ? s->a : 1.0f;
    s->b = s->b > 0.0f ? s->b : 100.0f * s->sigma;
    s->blur_radius = s->blur_radius > 0.0f ? s->blur_radius : 4.0f;
    s->layers = s->layers ? s->layers : 1;
}

const char *drift_isg_settings_problem(const drift_isg_settings *s)
{
    if (!drift_isg_count_valid(s->search) || !drift_isg_count_valid(s->gather)) {
        return "isg search and gather sample counts must be perfect squares in 1..1024";
    }
    if (!isfinite(s->sigma) || !isfinite(s->a) || !isfinite(s->b) || !isfinite(s->blur_radius) ||
        s->blur_radius > 1024.0f) {
        return "isg sigma, a, b or blur radius out of range";
    }
    if (s->layers != 1 && s->layers != 2) {
        return "isg layers must be 1 or 2";
    }
    return NULL;
}

// --- STATE ---

drift_result drift_isg_create(drift_frame_state *f, void **out_state)
{
    *out_state = drift_alloc(f->ctx, sizeof(drift_isg_state));
    return *out_state ? DRIFT_OK : DRIFT_ERR_OUT_OF_MEMORY;
}

static void free_buffers(drift_context *ctx, drift_isg_state *s)
{
    for (uint32_t l = 0; s->light_search && l < s->light_count; ++l) {
        drift_image_destroy(ctx, &s->light_search[l]);
    }
    drift_free(ctx, s->light_search);
    s->light_search = NULL;
    s->light_count = 0;
    drift_image_destroy(ctx, &s->reflection_search);
    drift_image_destroy(ctx, &s->reflection_points);
    drift_image_destroy(ctx, &s->dof_search);
    drift_image_destroy(ctx, &s->layer_depth);
    drift_image_destroy(ctx, &s->layer_colour);
}

static drift_result make_buffers(drift_frame_state *f, drift_isg_state *s)
{
    drift_context *ctx = f->ctx;
    int32_t w = f->params.width, h = f->params.height;
    s->light_search = drift_alloc(ctx, sizeof(drift_image) * (f->light_count + 1u));
    if (!s->light_search) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    s->light_count = f->light_count;
    drift_result r = DRIFT_OK;
    for (uint32_t l = 0; r == DRIFT_OK && l < f->light_count; ++l) {
        r = drift_image_create(ctx, w, h, 2, &s->light_search[l]);
    }
    if (r == DRIFT_OK) {
        r = drift_image_create(ctx, w, h, 2, &s->reflection_search);
    }
    if (r == DRIFT_OK) {
        r = drift_image_create(ctx, w, h, 4, &s->reflection_points);
    }
    if (r == DRIFT_OK) {
        r = drift_image_create(ctx, w, h, 1, &s->dof_search);
    }
    if (r == DRIFT_OK) {
        r = drift_image_create(ctx, w, h, 1, &s->layer_depth);
    }
    if (r == DRIFT_OK) {
        r = drift_image_create(ctx, w, h, 3, &s->layer_colour);
    }
    if (r != DRIFT_OK) {
        free_buffers(ctx, s); // the next pass tries again
    }
    return r;
}

drift_result drift_isg_prepare(drift_frame_state *f)
{
    drift_isg_state *s = drift_isg_of(f);
    if (!s->light_search) {
        drift_result r = make_buffers(f, s);
        if (r != DRIFT_OK) {
            return r;
        }
    }
    drift_isg_pattern_make((uint32_t)f->params.isg.search, DRIFT_ISG_DISK, &s->search);
    drift_isg_pattern_make((uint32_t)f->params.isg.gather, DRIFT_ISG_DISK, &s->gather);
    drift_isg_pattern_make((uint32_t)f->params.isg.search, DRIFT_ISG_RECT, &s->search_rect);
    drift_isg_pattern_make((uint32_t)f->params.isg.gather, DRIFT_ISG_RECT, &s->gather_rect);
    return DRIFT_OK;
}

void drift_isg_destroy(drift_frame_state *f, void *state)
{
    drift_isg_state *s = state;
    if (s) {
        free_buffers(f->ctx, s);
        drift_free(f->ctx, s);
    }
}

void drift_isg_shadow_planes(const drift_frame_state *f, drift_pass_plane_fn add, void *sink)
{
    const drift_isg_state *s = drift_isg_buffers(f);
    for (uint32_t l = 0; s && l < f->light_count; ++l) {
        char name[DRIFT_FRAME_PLANE_NAME];
        snprintf(name, sizeof name, "light%u.isg", l);
        add(sink, name, &s->light_search[l]);
    }
}

void drift_isg_reflection_planes(const drift_frame_state *f, drift_pass_plane_fn add, void *sink)
{
    const drift_isg_state *s = drift_isg_buffers(f);
    if (s) {
        add(sink, "isg.reflection", &s->reflection_search);
    }
}

void drift_isg_dof_planes(const drift_frame_state *f, drift_pass_plane_fn add, void *sink)
{
    const drift_isg_state *s = drift_isg_buffers(f);
    if (!s) {
        return;
    }
    add(sink, "isg.dof", &s->dof_search);
    if (f->params.isg.layers == 2) {
        add(sink, "isg.layer2.depth", &s->layer_depth);
        add(sink, "isg.layer2.colour", &s->layer_colour);
    }
}
