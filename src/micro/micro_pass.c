// The hybrid frame's rows of micro-rendering: `--indirect micro` (the diffuse lobe) and
// `--reflections micro` (the glossy lobe). Each effect's drift_micro lives in its state slot
// across frames (the scene points and the hierarchy's topology are its pre-computation) and
// is remade when the frame's settings change.
#include "micro/micro_pass.h"

#include "drift/micro.h"

#include <stdio.h>

typedef struct micro_pass_state {
    drift_micro *micro;
    drift_micro_params params; // what it was made with
} micro_pass_state;

static void state_destroy(drift_context *ctx, void *data)
{
    micro_pass_state *s = data;
    drift_micro_destroy(s->micro);
    drift_free(ctx, s);
}

static drift_micro_params params_of(const drift_frame_state *f)
{
    return drift_micro_params_resolve(&(drift_micro_params){
        .seed = f->base_seed,
        .point_count = f->params.micro.points,
        .buffer_size = f->params.micro.buffer_size,
        .density = f->params.micro.density,
        .bounces = f->params.micro.bounces,
        .lighting = (drift_micro_lighting)f->params.micro.lighting,
        .reflection_edits = f->params.reflection_edits,
    });
}

static bool same_params(const drift_micro_params *a, const drift_micro_params *b)
{
    return a->seed == b->seed && a->point_count == b->point_count &&
           a->buffer_size == b->buffer_size && a->density == b->density &&
           a->reflection_edits == b->reflection_edits && a->bounces == b->bounces &&
           a->lighting == b->lighting;
}

static drift_result render(drift_frame_state *f, const drift_pass_args *args, drift_micro_lobe lobe)
{
    drift_micro_params want = params_of(f);
    if (f->params.max_depth > want.bounces + 1) {
        drift_log(f->ctx, DRIFT_LOG_WARNING, DRIFT_OK, __FILE__, __LINE__,
                  "micro: %d bounce(s) (--max-depth %d is rendered as %d; --micro-bounces, "
                  "docs/micro.md)",
                  want.bounces, f->params.max_depth, want.bounces + 1);
    }
    micro_pass_state *s = drift_pass_state(f, args);
    if (!s || !same_params(&s->params, &want)) {
        micro_pass_state *made = drift_alloc(f->ctx, sizeof *made);
        if (!made) {
            return DRIFT_ERR_OUT_OF_MEMORY;
        }
        made->params = want;
        drift_result r = drift_micro_create(f->ctx, f->scene, f->accel, &want, &made->micro);
        if (r != DRIFT_OK) {
            drift_free(f->ctx, made);
            return r;
        }
        drift_pass_set_state(f, args, made, state_destroy);
        s = made;
    }
    drift_result r = drift_micro_render(s->micro, &f->gbuffer, &f->camera, lobe);
    if (r == DRIFT_OK) {
        drift_pass_copy_rgb(drift_micro_result(s->micro), &f->terms[args->effect]);
    }
    return r;
}

drift_result drift_micro_pass_indirect(drift_frame_state *f, const drift_pass_args *args)
{
    return render(f, args, DRIFT_MICRO_LOBE_DIFFUSE);
}

drift_result drift_micro_pass_reflections(drift_frame_state *f, const drift_pass_args *args)
{
    return render(f, args, DRIFT_MICRO_LOBE_GLOSSY);
}

static void planes(const drift_frame_state *f, drift_effect effect, const char *prefix,
                   drift_pass_plane_fn add, void *sink)
{
    const drift_pass_args args = { .effect = effect,
                                   .technique = drift_hybrid_params_technique(&f->params, effect) };
    const micro_pass_state *s = drift_pass_state(f, &args);
    static const char *const names[] = { "incident", "gathers" };
    for (size_t i = 0; s && i < sizeof names / sizeof *names; ++i) {
        char own[DRIFT_FRAME_PLANE_NAME], name[DRIFT_FRAME_PLANE_NAME];
        snprintf(own, sizeof own, "micro.%s", names[i]);
        snprintf(name, sizeof name, "micro.%s%s", prefix, names[i]);
        const drift_image *plane = drift_micro_plane_named(s->micro, own);
        if (plane && plane->width == f->params.width && plane->height == f->params.height) {
            add(sink, name, plane);
        }
    }
}

void drift_micro_indirect_planes(const drift_frame_state *f, drift_pass_plane_fn add, void *sink)
{
    planes(f, DRIFT_EFFECT_INDIRECT, "", add, sink);
}

void drift_micro_reflection_planes(const drift_frame_state *f, drift_pass_plane_fn add, void *sink)
{
    planes(f, DRIFT_EFFECT_REFLECTIONS, "glossy_", add, sink);
}

const drift_micro *drift_micro_pass_object(const drift_frame_state *f, drift_effect effect)
{
    if (!(effect == DRIFT_EFFECT_INDIRECT && f->params.indirect == DRIFT_INDIRECT_MICRO) &&
        !(effect == DRIFT_EFFECT_REFLECTIONS && f->params.reflections == DRIFT_REFLECTIONS_MICRO)) {
        return NULL; // the slot is another technique's
    }
    const drift_pass_args args = { .effect = effect,
                                   .technique = drift_hybrid_params_technique(&f->params, effect) };
    const micro_pass_state *s = drift_pass_state(f, &args);
    return s ? s->micro : NULL;
}
