// The real-time family's hooks (frame/family.h): its settings, the inputs other rows share
// (U_l, hard shadows, shadow maps, sharp reflections, probes), summing D after a row that
// writes S_l, and the caches that survive frames (the shadow maps, the probes and the
// prefiltered environment: its state, drift_realtime_state).
#include "realtime/realtime.h"

static void resolve(drift_hybrid_params *p, const drift_scene *scene)
{
    (void)scene;
    drift_realtime_settings_resolve(&p->shadow_map, &p->envmap);
}

static const char *problem(const drift_hybrid_params *p)
{
    return drift_realtime_settings_problem(&p->shadow_map, &p->envmap);
}

// In the order the frame has always prepared them.
static drift_result prepare(drift_frame_state *f, uint32_t inputs)
{
    drift_result r = DRIFT_OK;
    if (inputs & DRIFT_INPUT_UNSHADOWED) {
        r = drift_realtime_pass_unshadowed(f);
    }
    if (r == DRIFT_OK && (inputs & DRIFT_INPUT_HARD_SHADOWS)) {
        r = drift_realtime_pass_hard_shadows(f, (inputs & DRIFT_INPUT_OCCLUDER_DISTANCES) != 0);
    }
    if (r == DRIFT_OK && (inputs & DRIFT_INPUT_SHADOW_MAPS)) {
        r = drift_realtime_build_shadow_maps(f);
    }
    if (r == DRIFT_OK && (inputs & DRIFT_INPUT_SHARP_REFLECTIONS)) {
        r = drift_realtime_pass_sharp_reflections(f);
    }
    if (r == DRIFT_OK && (inputs & DRIFT_INPUT_PROBES)) {
        r = drift_realtime_capture_probes(f);
    }
    return r;
}

static drift_result after_row(drift_frame_state *f, const drift_family_row *row)
{
    drift_result r = DRIFT_OK;
    if (row->args->effect == DRIFT_EFFECT_REFLECTIONS &&
        !(row->flags & (DRIFT_ROW_NO_TERM | DRIFT_ROW_TRACES_GLASS))) {
        r = drift_realtime_pass_glass_transmission(f);
    }
    if (r == DRIFT_OK && (row->flags & DRIFT_ROW_SUMS_DIRECT)) {
        r = drift_realtime_pass_sum_direct(f);
    }
    return r;
}

// The caches start empty: each is made by the first pass that needs it.
static drift_result create(drift_frame_state *f, void **out_state)
{
    drift_realtime_state *s = drift_alloc(f->ctx, sizeof *s);
    if (!s) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    *out_state = s;
    // + 1: a scene with no lights still gets an allocation.
    s->shadow_maps = drift_alloc(f->ctx, sizeof(drift_shadow_map *) * (f->light_count + 1u));
    if (!s->shadow_maps) {
        return DRIFT_ERR_OUT_OF_MEMORY; // destroy frees s
    }
    s->light_count = f->light_count;
    return DRIFT_OK;
}

static void destroy_probes(drift_frame_state *f, drift_realtime_state *s)
{
    for (uint32_t i = 0; i < s->probe_count; ++i) {
        drift_envmap_destroy(f->ctx, s->probes[i].map);
    }
    drift_free(f->ctx, s->probes);
    s->probes = NULL;
    s->probe_count = 0;
}

static void destroy_shadow_maps(drift_frame_state *f, drift_realtime_state *s)
{
    for (uint32_t l = 0; s->shadow_maps && l < s->light_count; ++l) {
        drift_shadow_map_destroy(f->ctx, s->shadow_maps[l]);
        s->shadow_maps[l] = NULL;
    }
}

// Cached maps that depend on a changed setting are rebuilt on next use.
static void update(drift_frame_state *f, const drift_hybrid_params *p)
{
    drift_realtime_state *s = drift_realtime_of(f);
    if (p->shadow_map.size != f->params.shadow_map.size ||
        p->shadow_map.bias != f->params.shadow_map.bias) {
        destroy_shadow_maps(f, s);
    }
    if (p->envmap.size != f->params.envmap.size ||
        p->envmap.has_probe != f->params.envmap.has_probe ||
        p->envmap.per_object != f->params.envmap.per_object || p->seed != f->params.seed ||
        p->light_samples != f->params.light_samples ||
        (p->envmap.has_probe &&
         !drift_vec3_is_zero(drift_vec3_sub(p->envmap.probe, f->params.envmap.probe)))) {
        destroy_probes(f, s);
    }
}

static void destroy(drift_frame_state *f, void *state)
{
    drift_realtime_state *s = state;
    if (!s) {
        return;
    }
    destroy_shadow_maps(f, s);
    destroy_probes(f, s);
    drift_env_prefilter_destroy(f->ctx, s->env_prefilter); // built by the unshadowed pass
    drift_free(f->ctx, s->shadow_maps);
    drift_free(f->ctx, s);
}

// The rays of the inputs this frame prepared; the shadow maps' and probes' rays are 0 on a
// frame that found them cached.
static void report(drift_frame_state *f, drift_family_count_fn count)
{
    const drift_hybrid_stats *s = &f->stats;
    if ((f->inputs & DRIFT_INPUT_UNSHADOWED) && drift_scene_has_environment(f->scene)) {
        count(f, "realtime.environment_shadow_rays", (double)s->rays[DRIFT_PASS_UNSHADOWED]);
    }
    if (f->inputs & DRIFT_INPUT_HARD_SHADOWS) {
        count(f, "realtime.hard_shadow_rays", (double)s->rays[DRIFT_PASS_HARD_SHADOWS]);
    }
    if (f->inputs & DRIFT_INPUT_SHADOW_MAPS) {
        uint32_t maps = 0;
        for (uint32_t l = 0; l < f->light_count; ++l) {
            maps += drift_realtime_shadow_map(f, l) != NULL;
        }
        count(f, "realtime.shadow_maps", maps);
        count(f, "realtime.shadow_map_rays", (double)s->rays[DRIFT_PASS_SHADOW_MAPS]);
    }
    if (f->inputs & DRIFT_INPUT_SHARP_REFLECTIONS) {
        count(f, "realtime.reflection_rays", (double)s->rays[DRIFT_PASS_REFLECTIONS]);
    }
    if (f->inputs & DRIFT_INPUT_PROBES) {
        count(f, "realtime.probes", drift_realtime_of(f)->probe_count);
        count(f, "realtime.probe_rays", (double)s->rays[DRIFT_PASS_ENVMAP]);
    }
}

const drift_family drift_realtime_family = {
    .name = "realtime",
    .slot = DRIFT_FAMILY_REALTIME,
    .create = create,
    .resolve = resolve,
    .problem = problem,
    .provides = DRIFT_INPUT_UNSHADOWED | DRIFT_INPUT_HARD_SHADOWS | DRIFT_INPUT_SHADOW_MAPS |
                DRIFT_INPUT_SHARP_REFLECTIONS | DRIFT_INPUT_PROBES | DRIFT_INPUT_OCCLUDER_DISTANCES,
    .prepare = prepare,
    .after_row = after_row,
    .update = update,
    .destroy = destroy,
    .report = report,
};
