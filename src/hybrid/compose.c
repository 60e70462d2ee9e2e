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

// A row at a time over the planes' rows (no call per pixel): the same additions in the same
// order as a pixel at a time.
static void compose_row(drift_frame_state *f, int32_t y, uint64_t *rays, void *user)
{
    (void)rays;
    const compose_job *job = user;
    const float *emission = drift_image_pixel(&f->gbuffer.emission, 0, y);
    const float *material = drift_image_pixel(&f->gbuffer.material_id, 0, y);
    const float *direct = drift_image_pixel(&f->direct, 0, y);
    const float *depth = drift_image_pixel(&f->gbuffer.depth, 0, y);
    const float *terms[DRIFT_EFFECT_COUNT];
    for (int k = 0; k < job->count; ++k) {
        terms[k] = drift_image_pixel(&f->terms[job->terms[k]], 0, y);
    }
    float *focus = drift_image_pixel(&f->focus, 0, y);
    float *coc = drift_image_pixel(&f->coc, 0, y);
    const int32_t ce = f->gbuffer.emission.channels, cm = f->gbuffer.material_id.channels;
    const int32_t cd = f->direct.channels, cz = f->gbuffer.depth.channels;
    const int32_t cf = f->focus.channels, cc = f->coc.channels;
    for (int32_t x = 0; x < f->params.width; ++x) {
        const float *e = emission + (ptrdiff_t)x * ce;
        float l0 = e[0], l1 = e[1], l2 = e[2];
        if (material[(ptrdiff_t)x * cm] >= 0.0f) {
            const float *d = direct + (ptrdiff_t)x * cd;
            l0 += d[0];
            l1 += d[1];
            l2 += d[2];
            for (int k = 0; k < job->count; ++k) {
                const float *t = terms[k] + (ptrdiff_t)x * 3;
                l0 += t[0];
                l1 += t[1];
                l2 += t[2];
            }
        }
        float *o = focus + (ptrdiff_t)x * cf;
        o[0] = l0;
        o[1] = l1;
        o[2] = l2;
        float z = depth[(ptrdiff_t)x * cz];
        // A miss is infinitely far: its circle of confusion is the limit A / F in pixels.
        coc[(ptrdiff_t)x * cc] = drift_coc_lens_radius(&job->lens, z > 0.0f ? z : 1e30f);
    }
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
    drift_pass_rows(f, DRIFT_PASS_COMPOSE, compose_row, &job);
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
