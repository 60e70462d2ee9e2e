// The hybrid frame's rows of instant radiosity: `--indirect ism` (VPL visibility from
// imperfect shadow maps) and `--indirect ir` (the same VPLs, visibility ray-traced: the
// baseline the thesis compares against). The drift_ism lives in the indirect effect's state
// slot across frames (its scene points are the only pre-computation) and is remade when the
// frame's settings change.
#include "ism/ism_pass.h"

#include "drift/ism.h"

typedef struct ism_pass_state {
    drift_ism *ism;
    drift_ism_params params; // what it was made with
} ism_pass_state;

static void state_destroy(drift_context *ctx, void *data)
{
    ism_pass_state *s = data;
    drift_ism_destroy(s->ism);
    drift_free(ctx, s);
}

static drift_ism_params params_of(const drift_frame_state *f, drift_ism_visibility visibility)
{
    return (drift_ism_params){ .seed = f->base_seed,
                               .visibility = visibility,
                               .vpl_count = f->params.ism.vpls,
                               .max_depth = f->params.max_depth,
                               .map_size = f->params.ism.map_size,
                               .points_per_vpl = f->params.ism.points_per_vpl,
                               .vpl_importance = f->params.ism.vpl_importance,
                               .no_near_field = f->params.ism.no_near_field,
                               .gather_scale = f->params.ism.gather_scale,
                               .later_vpl_count = f->params.ism.later_paths };
}

// All but the seed: a new seed draws new VPLs from the same scene points
// (drift_ism_set_seed), so that a sequence can reseed every frame without the set-up.
static bool same_params(const drift_ism_params *a, const drift_ism_params *b)
{
    return a->visibility == b->visibility && a->vpl_count == b->vpl_count &&
           a->max_depth == b->max_depth && a->map_size == b->map_size &&
           a->points_per_vpl == b->points_per_vpl && a->vpl_importance == b->vpl_importance &&
           a->no_near_field == b->no_near_field && a->gather_scale == b->gather_scale &&
           a->later_vpl_count == b->later_vpl_count;
}

static drift_result indirect(drift_frame_state *f, const drift_pass_args *args,
                             drift_ism_visibility visibility)
{
    drift_ism_params want = params_of(f, visibility);
    ism_pass_state *s = drift_pass_state(f, args);
    if (!s || !same_params(&s->params, &want)) {
        ism_pass_state *made = drift_alloc(f->ctx, sizeof *made);
        if (!made) {
            return DRIFT_ERR_OUT_OF_MEMORY;
        }
        made->params = want;
        drift_result r = drift_ism_create(f->ctx, f->scene, f->accel, &want, &made->ism);
        if (r != DRIFT_OK) {
            drift_free(f->ctx, made);
            return r;
        }
        drift_pass_set_state(f, args, made, state_destroy);
        s = made;
    } else if (s->params.seed != want.seed) {
        drift_ism_set_seed(s->ism, want.seed);
        s->params.seed = want.seed;
    }
    // The lights do not move between the anti-aliasing passes of a frame (their paths key on
    // the frame's seed, not the pass's): pass 0 draws them, and each pass gathers its own
    // share of them, so the frame's mean gathers each VPL once.
    uint32_t passes = f->params.aa ? f->params.aa : 1;
    drift_result r =
        drift_ism_render_slice(s->ism, &f->gbuffer, &f->camera, &f->direct, f->aa_pass, passes);
    if (r == DRIFT_OK) {
        drift_pass_copy_rgb(drift_ism_indirect(s->ism), &f->indirect);
    }
    return r;
}

const char *drift_ism_settings_problem(const drift_ism_settings *s)
{
    int32_t g = s->gather_scale;
    return g == 0 || g == 1 || g == 2 || g == 4 ? NULL : "ism gather scale not 1, 2 or 4";
}

drift_result drift_ism_pass_indirect(drift_frame_state *f, const drift_pass_args *args)
{
    return indirect(f, args, DRIFT_ISM_VISIBILITY_ISM);
}

drift_result drift_ism_pass_ir(drift_frame_state *f, const drift_pass_args *args)
{
    return indirect(f, args, DRIFT_ISM_VISIBILITY_RAYS);
}

void drift_ism_indirect_planes(const drift_frame_state *f, drift_pass_plane_fn add, void *sink)
{
    const drift_pass_args args = { .effect = DRIFT_EFFECT_INDIRECT,
                                   .technique = f->params.indirect };
    const ism_pass_state *s = drift_pass_state(f, &args);
    // ism.tile (one VPL's map) is the map's size, not the frame's: not an --aov plane.
    static const char *const names[] = { "ism.irradiance", "ism.near_field", "ism.vpls" };
    for (size_t i = 0; s && i < sizeof names / sizeof *names; ++i) {
        const drift_image *plane = drift_ism_plane_named(s->ism, names[i]);
        if (plane && plane->width == f->params.width && plane->height == f->params.height) {
            add(sink, names[i], plane);
        }
    }
}

const drift_ism *drift_ism_pass_object(const drift_frame_state *f)
{
    if (f->params.indirect != DRIFT_INDIRECT_ISM && f->params.indirect != DRIFT_INDIRECT_IR) {
        return NULL; // the slot is another technique's
    }
    const drift_pass_args args = { .effect = DRIFT_EFFECT_INDIRECT,
                                   .technique = f->params.indirect };
    const ism_pass_state *s = drift_pass_state(f, &args);
    return s ? s->ism : NULL;
}
