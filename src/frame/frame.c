// The helpers every pass of the hybrid frame shares (frame/frame.h): rows and pixels in
// parallel with per-thread ray counters, per-pixel samplers, the outgoing direction, and the
// reference path tracer restricted to some components.
#include "frame/frame.h"

// --- NO-OPS OF THE TABLE ---

drift_result drift_pass_none(drift_frame_state *frame, const drift_pass_args *args)
{
    (void)frame;
    (void)args;
    return DRIFT_OK;
}

void drift_planes_none(const drift_frame_state *frame, drift_pass_plane_fn add, void *sink)
{
    (void)frame;
    (void)add;
    (void)sink;
}

// --- TECHNIQUE STATE ---

void *drift_pass_state(const drift_frame_state *f, const drift_pass_args *args)
{
    DRIFT_CHECK((unsigned)args->effect < DRIFT_EFFECT_COUNT);
    const drift_pass_state_slot *slot = &f->effect_state[args->effect];
    return slot->data && slot->technique == args->technique ? slot->data : NULL;
}

static void free_state(drift_frame_state *f, int effect)
{
    if (f->effect_state[effect].data && f->effect_state[effect].destroy) {
        f->effect_state[effect].destroy(f->ctx, f->effect_state[effect].data);
    }
    f->effect_state[effect].data = NULL;
    f->effect_state[effect].destroy = NULL;
}

void drift_pass_set_state(drift_frame_state *f, const drift_pass_args *args, void *data,
                          void (*destroy)(drift_context *ctx, void *data))
{
    DRIFT_CHECK((unsigned)args->effect < DRIFT_EFFECT_COUNT);
    free_state(f, args->effect);
    f->effect_state[args->effect].data = data;
    f->effect_state[args->effect].destroy = destroy;
    f->effect_state[args->effect].technique = args->technique;
}

void drift_pass_free_states(drift_frame_state *f)
{
    for (int e = 0; e < DRIFT_EFFECT_COUNT; ++e) {
        free_state(f, e);
    }
}

// --- ROWS AND PIXELS ---

typedef struct row_job {
    drift_frame_state *frame;
    drift_pass_row_fn fn;
    void *user;
} row_job;

static void run_rows(size_t begin, size_t end, int thread_index, void *user)
{
    const row_job *job = user;
    uint64_t *rays = &job->frame->counters[thread_index].rays;
    for (size_t y = begin; y < end; ++y) {
        job->fn(job->frame, (int32_t)y, rays, job->user);
    }
}

uint64_t drift_pass_for_each_row(drift_frame_state *frame, drift_pass_row_fn fn, void *user)
{
    for (int t = 0; t < frame->thread_count; ++t) {
        frame->counters[t].rays = 0;
    }
    row_job job = { frame, fn, user };
    drift_parallel_for(frame->ctx, (size_t)frame->params.height, 1, run_rows, &job);
    uint64_t total = 0;
    for (int t = 0; t < frame->thread_count; ++t) {
        total += frame->counters[t].rays;
    }
    return total;
}

typedef struct pixel_job {
    drift_pass_pixel_fn fn;
    void *user;
} pixel_job;

static void pixels_of_row(drift_frame_state *frame, int32_t y, uint64_t *rays, void *user)
{
    const pixel_job *job = user;
    for (int32_t x = 0; x < frame->params.width; ++x) {
        job->fn(frame, x, y, rays, job->user);
    }
}

uint64_t drift_pass_for_each_pixel(drift_frame_state *frame, drift_pass_pixel_fn fn, void *user)
{
    pixel_job job = { fn, user };
    return drift_pass_for_each_row(frame, pixels_of_row, &job);
}

drift_sampler drift_pass_sampler(const drift_frame_state *frame, uint32_t stream, int32_t x,
                                 int32_t y)
{
    uint32_t pixel = (uint32_t)y * (uint32_t)frame->params.width + (uint32_t)x;
    return drift_sampler_make(drift_hash_combine(frame->params.seed, stream), pixel, 0);
}

drift_vec3 drift_pass_wo(const drift_frame_state *frame, int32_t x, int32_t y)
{
    // The primary ray is a pinhole ray from the camera's position: toward the eye from the hit.
    const drift_surface *s =
        &frame->gbuffer.surfaces[(size_t)y * (size_t)frame->params.width + (size_t)x];
    return drift_vec3_normalize(drift_vec3_sub(frame->camera.position, s->position));
}

void drift_pass_copy_rgb(const drift_image *from, drift_image *to)
{
    for (int32_t y = 0; y < to->height; ++y) {
        for (int32_t x = 0; x < to->width; ++x) {
            drift_image_set3(to, x, y, drift_image_get3(from, x, y));
        }
    }
}

void drift_pass_pixels(drift_frame_state *frame, drift_hybrid_pass pass, drift_pass_pixel_fn fn,
                       void *user)
{
    double t = drift_time_now();
    frame->stats.rays[pass] += drift_pass_for_each_pixel(frame, fn, user);
    drift_pass_time(frame, pass, t);
}

void drift_pass_rows(drift_frame_state *frame, drift_hybrid_pass pass, drift_pass_row_fn fn,
                     void *user)
{
    double t = drift_time_now();
    frame->stats.rays[pass] += drift_pass_for_each_row(frame, fn, user);
    drift_pass_time(frame, pass, t);
}

// --- PATH-TRACED COMPONENTS ---

drift_result drift_pass_reference_render(drift_frame_state *f, uint32_t components,
                                         int32_t max_depth, bool lens, const atomic_bool *cancel,
                                         drift_image *out)
{
    drift_pt_params params = { .width = f->params.width,
                               .height = f->params.height,
                               .seed = f->params.seed,
                               .max_depth = max_depth,
                               .components = components,
                               .pixel_centre = true,
                               .pinhole = !lens,
                               .camera = &f->camera,
                               .reflection_edits = f->params.reflection_edits };
    drift_pt *pt = NULL;
    drift_result r = drift_pt_create(f->ctx, f->scene, f->accel, &params, &pt);
    if (r == DRIFT_OK) {
        r = drift_pt_render_samples(pt, f->params.spp, cancel);
    }
    if (r == DRIFT_OK) {
        drift_image beauty;
        r = drift_pt_resolve(pt, DRIFT_PT_AOV_BEAUTY, &beauty);
        if (r == DRIFT_OK) {
            drift_pass_copy_rgb(&beauty, out);
        }
        drift_pt_stats s = drift_pt_get_stats(pt);
        f->stats.rays[DRIFT_PASS_REFERENCE] += s.camera_rays + s.shadow_rays + s.bounce_rays;
    }
    drift_pt_destroy(pt);
    return r;
}
