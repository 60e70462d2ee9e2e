// Composition of the hybrid frame: focus = E + D + R + I (+ the terms of later effects, in the
// table's order) per pixel (a term whose row adds nothing, `none`, is left out) and the
// circle-of-confusion plane; and the two depth-of-field rows the conductor owns: the pinhole copy
// and the reference lens render.
#include "hybrid/techniques.h"

typedef struct compose_job {
    int terms[DRIFT_EFFECT_COUNT]; // the effects added after D, in the table's order
    int count;
    drift_coc_lens lens;
} compose_job;

static void compose_pixel(drift_frame_state *f, int32_t x, int32_t y, uint64_t *rays, void *user)
{
    (void)rays;
    const compose_job *job = user;
    drift_vec3 l = drift_image_get3(&f->gbuffer.emission, x, y);
    bool surface = drift_image_pixel(&f->gbuffer.material_id, x, y)[0] >= 0.0f;
    if (surface) {
        l = drift_vec3_add(l, drift_image_get3(&f->direct, x, y));
        for (int k = 0; k < job->count; ++k) {
            l = drift_vec3_add(l, drift_image_get3(&f->terms[job->terms[k]], x, y));
        }
    }
    drift_image_set3(&f->focus, x, y, l);
    float z = drift_image_pixel(&f->gbuffer.depth, x, y)[0];
    // A miss is infinitely far: its circle of confusion is the limit A / F in pixels.
    drift_image_pixel(&f->coc, x, y)[0] = drift_coc_lens_radius(&job->lens, z > 0.0f ? z : 1e30f);
}

// Whether the effect's term is part of the frame: a term effect (other than D, always there)
// whose row adds something.
static bool adds_term(const drift_frame_state *f, drift_effect effect)
{
    return effect != DRIFT_EFFECT_SHADOWS &&
           drift_effect_info_of(effect)->kind == DRIFT_EFFECT_KIND_TERM &&
           !(drift_technique_row_chosen(&f->params, effect)->flags & DRIFT_ROW_NO_TERM);
}

drift_result drift_hybrid_pass_compose(drift_frame_state *f)
{
    compose_job job = { .count = 0, .lens = drift_coc_lens_make(&f->camera, f->params.height) };
    for (int e = 0; e < DRIFT_EFFECT_COUNT; ++e) {
        if (adds_term(f, (drift_effect)e)) {
            job.terms[job.count++] = e;
        }
    }
    drift_pass_pixels(f, DRIFT_PASS_COMPOSE, compose_pixel, &job);
    return DRIFT_OK;
}

drift_result drift_hybrid_pass_pinhole(drift_frame_state *f, const drift_pass_args *args)
{
    (void)args;
    double t = drift_time_now();
    drift_pass_copy_rgb(&f->focus, &f->final);
    drift_pass_time(f, DRIFT_PASS_COMPOSE, t);
    return DRIFT_OK;
}

// Every enabled effect path-traced through the lens: the reference depth of field.
drift_result drift_hybrid_pass_lens_reference(drift_frame_state *f, const drift_pass_args *args)
{
    uint32_t components = DRIFT_PT_COMPONENT_EMISSION | DRIFT_PT_COMPONENT_DIRECT;
    int32_t depth = 1;
    for (int e = 0; e < DRIFT_EFFECT_COUNT; ++e) {
        if (adds_term(f, (drift_effect)e)) { // the term's truth, through the lens
            components |= drift_technique_row_chosen(&f->params, (drift_effect)e)->components;
            depth = f->params.max_depth;
        }
    }
    double t = drift_time_now();
    drift_result r =
        drift_pass_reference_render(f, components, depth, true, args->cancel, &f->final);
    drift_pass_time(f, DRIFT_PASS_REFERENCE, t);
    return r;
}
