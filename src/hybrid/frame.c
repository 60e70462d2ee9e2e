// The hybrid frame's conductor: lifecycle, parameters, the pass order and the table of
// planes (--aov, the viewer). It runs the chosen row of the technique table for every effect
// (hybrid/techniques.h); the passes live in the technique folders (src/realtime, src/isg,
// src/aaf, ...) and reach the frame's buffers through frame/frame.h, never through here.
// Each family's settings, shared inputs, caches and counts go through its hooks
// (frame/family.h, the list in families.c): this file names no family.
#include "drift/knobs.h"
#include "hybrid/families.h"
#include "hybrid/frame_access.h"
#include "hybrid/techniques.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

typedef struct plane_ref {
    char name[DRIFT_FRAME_PLANE_NAME];
    const drift_image *image;
} plane_ref;

struct drift_hybrid {
    drift_frame_state frame; // the buffers every pass reads and writes
    plane_ref *planes;       // the last frame's planes, in a stable order
    uint32_t plane_count, plane_capacity;
    bool planes_out_of_memory;
    drift_image aa_sum; // the anti-aliasing passes' running sum (made on first use)
};

static const char *const pass_names[] = { "primary",     "unshadowed",    "hard_shadows",
                                          "shadow_maps", "shadow_filter", "reflections",
                                          "envmap",      "reference",     "compose",
                                          "dof",         "isg",           "aaf_sampling",
                                          "aaf_filter" };
_Static_assert(sizeof pass_names / sizeof *pass_names == DRIFT_PASS_COUNT, "names");

const char *drift_hybrid_pass_name(drift_hybrid_pass pass)
{
    return (unsigned)pass < DRIFT_PASS_COUNT ? pass_names[pass] : NULL;
}

// --- PARAMETERS ---

int drift_hybrid_params_technique(const drift_hybrid_params *params, drift_effect effect)
{
    return (unsigned)effect < DRIFT_EFFECT_COUNT ? params->techniques[effect] : -1;
}

void drift_hybrid_params_set_technique(drift_hybrid_params *params, drift_effect effect,
                                       int technique)
{
    if ((unsigned)effect < DRIFT_EFFECT_COUNT) {
        params->techniques[effect] = technique;
    }
}

drift_hybrid_params drift_hybrid_params_resolve(const drift_hybrid_params *params,
                                                const drift_scene *scene)
{
    drift_hybrid_params p = params ? *params : (drift_hybrid_params){ 0 };
    if (p.width == 0) {
        p.width = scene ? scene->camera.width : 512;
    }
    if (p.height == 0) {
        p.height = scene ? scene->camera.height : 512;
    }
    p.spp = p.spp ? p.spp : 64;
    p.max_depth = p.max_depth ? p.max_depth : 2;
    p.light_samples = p.light_samples ? p.light_samples : 8;
    for (int i = 0; drift_family_at(i); ++i) {
        if (drift_family_at(i)->resolve) {
            drift_family_at(i)->resolve(&p, scene);
        }
    }
    return p;
}

drift_hybrid_params drift_hybrid_params_recommended(void)
{
    return drift_hybrid_params_default(); // the knob table's rows (src/hybrid/knobs.c)
}

static bool techniques_valid(const drift_hybrid_params *p)
{
    for (int e = 0; e < DRIFT_EFFECT_COUNT; ++e) {
        if (!drift_technique_row_chosen(p, (drift_effect)e)) {
            return false;
        }
    }
    return true;
}

static bool params_valid(const drift_context *ctx, const drift_hybrid_params *p)
{
    const char *problem = NULL;
    if (p->width <= 0 || p->height <= 0 || p->width > DRIFT_IMAGE_MAX_DIMENSION ||
        p->height > DRIFT_IMAGE_MAX_DIMENSION) {
        problem = "image size out of range";
    } else if (!techniques_valid(p)) {
        problem = "unknown technique";
    } else if (p->max_depth < 1 || p->max_depth > 1024) {
        problem = "max_depth outside 1..1024";
    } else if (p->light_samples > 4096) {
        problem = "light samples over 4096";
    } else if (p->environment_filter > 10) {
        problem = "environment filter passes over 10";
    } else if (p->environment_scale > 2) {
        problem = "environment scale not 1 or 2";
    } else if (p->environment_scale == 2 && p->environment_interleave) {
        problem = "environment scale 2 with interleaving";
    } else if (p->aa > 4096) {
        problem = "anti-aliasing passes over 4096";
    } else if (p->has_ambient && !drift_vec3_is_finite(p->ambient)) {
        problem = "non-finite ambient";
    }
    // Then each technique family's own settings.
    for (int i = 0; !problem && drift_family_at(i); ++i) {
        if (drift_family_at(i)->problem) {
            problem = drift_family_at(i)->problem(p);
        }
    }
    if (problem) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, NULL, 0, "hybrid frame: %s",
                  problem);
    }
    return problem == NULL;
}

// --- LIFECYCLE ---

static drift_result create_images(drift_frame_state *f)
{
    drift_context *ctx = f->ctx;
    int32_t w = f->params.width, h = f->params.height;
    drift_result r = drift_gbuffer_create(ctx, w, h, &f->gbuffer);
    drift_image *rgb[] = { &f->environment_direct, &f->reflection_emitted, &f->reflection_reflected,
                           &f->focus };
    for (size_t i = 0; r == DRIFT_OK && i < sizeof rgb / sizeof *rgb; ++i) {
        r = drift_image_create(ctx, w, h, 3, rgb[i]);
    }
    for (int e = 0; r == DRIFT_OK && e < DRIFT_EFFECT_COUNT; ++e) {
        r = drift_image_create(ctx, w, h, 3, &f->terms[e]);
    }
    if (r == DRIFT_OK) {
        r = drift_image_create(ctx, w, h, 1, &f->reflection_distance);
    }
    if (r == DRIFT_OK) {
        r = drift_image_create(ctx, w, h, 1, &f->coc);
    }
    for (uint32_t l = 0; r == DRIFT_OK && l < f->light_count; ++l) {
        drift_frame_light_buffers *b = &f->light_buffers[l];
        r = drift_image_create(ctx, w, h, 3, &b->unshadowed);
        if (r == DRIFT_OK) {
            r = drift_image_create(ctx, w, h, 3, &b->hard_shadow);
        }
        if (r == DRIFT_OK) {
            r = drift_image_create(ctx, w, h, 1, &b->shadow);
        }
    }
    return r;
}

// Each family makes its own state, into its slot.
static drift_result families_create(drift_frame_state *f)
{
    drift_result r = DRIFT_OK;
    for (int i = 0; r == DRIFT_OK && drift_family_at(i); ++i) {
        const drift_family *family = drift_family_at(i);
        if (family->create) {
            r = family->create(f, &f->family_state[family->slot]);
        }
    }
    return r;
}

// Each family frees what it made (its caches, its buffers); the slots are left empty.
static void families_destroy(drift_frame_state *f)
{
    for (int i = 0; drift_family_at(i); ++i) {
        const drift_family *family = drift_family_at(i);
        if (family->destroy) {
            family->destroy(f, f->family_state[family->slot]);
        }
        f->family_state[family->slot] = NULL;
    }
}

drift_result drift_hybrid_create(drift_context *ctx, const drift_scene *scene,
                                 const drift_accel *accel, const drift_hybrid_params *params,
                                 drift_hybrid **out_frame)
{
    if (!out_frame) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    *out_frame = NULL;
    if (!ctx || !scene || !accel || !scene->committed) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    drift_hybrid_params p = drift_hybrid_params_resolve(params, scene);
    if (!params_valid(ctx, &p)) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    drift_hybrid *h = drift_alloc(ctx, sizeof(drift_hybrid));
    if (!h) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    drift_frame_state *f = &h->frame;
    f->ctx = ctx;
    f->scene = scene;
    f->accel = accel;
    f->params = p;
    f->thread_count = drift_context_thread_count(ctx);
    drift_result r = drift_raster_lights_build(ctx, scene, &f->lights, &f->light_count);
    if (r == DRIFT_OK) {
        f->counters = drift_alloc(ctx, sizeof(drift_ray_counter) * (size_t)f->thread_count);
        // + 1: a scene with no lights still gets an allocation.
        f->light_buffers =
            drift_alloc(ctx, sizeof(drift_frame_light_buffers) * (f->light_count + 1u));
        r = f->counters && f->light_buffers ? DRIFT_OK : DRIFT_ERR_OUT_OF_MEMORY;
    }
    if (r == DRIFT_OK) {
        r = create_images(f);
    }
    if (r == DRIFT_OK) {
        r = families_create(f);
    }
    if (r != DRIFT_OK) {
        drift_hybrid_destroy(h);
        return r;
    }
    f->shading = (drift_raster_shading){ .scene = scene,
                                         .accel = accel,
                                         .lights = f->lights,
                                         .light_count = f->light_count,
                                         .light_samples = p.light_samples };
    *out_frame = h;
    return DRIFT_OK;
}

void drift_hybrid_destroy(drift_hybrid *h)
{
    if (!h) {
        return;
    }
    drift_frame_state *f = &h->frame;
    drift_context *ctx = f->ctx;
    families_destroy(f); // then the frame frees its own
    drift_pass_free_states(f);
    if (f->light_buffers) {
        for (uint32_t l = 0; l < f->light_count; ++l) {
            drift_image_destroy(ctx, &f->light_buffers[l].unshadowed);
            drift_image_destroy(ctx, &f->light_buffers[l].hard_shadow);
            drift_image_destroy(ctx, &f->light_buffers[l].shadow);
        }
    }
    drift_gbuffer_destroy(ctx, &f->gbuffer);
    drift_image *images[] = { &f->environment_direct,
                              &f->reflection_emitted,
                              &f->reflection_reflected,
                              &f->reflection_distance,
                              &f->coc,
                              &f->focus };
    for (size_t i = 0; i < sizeof images / sizeof *images; ++i) {
        drift_image_destroy(ctx, images[i]);
    }
    for (int e = 0; e < DRIFT_EFFECT_COUNT; ++e) {
        drift_image_destroy(ctx, &f->terms[e]);
    }
    drift_raster_lights_destroy(ctx, f->lights, f->light_count);
    drift_free(ctx, f->light_buffers);
    drift_free(ctx, f->counters);
    drift_free(ctx, f->mesh_motion);
    drift_image_destroy(ctx, &h->aa_sum);
    drift_free(ctx, h->planes);
    drift_free(ctx, h);
}

drift_result drift_hybrid_set_params(drift_hybrid *h, const drift_hybrid_params *params)
{
    drift_frame_state *f = &h->frame;
    drift_hybrid_params p = drift_hybrid_params_resolve(params, f->scene);
    if (!params_valid(f->ctx, &p)) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    if (p.width != f->params.width || p.height != f->params.height) {
        drift_log(f->ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, NULL, 0,
                  "hybrid frame: the size cannot change (%dx%d -> %dx%d)", f->params.width,
                  f->params.height, p.width, p.height);
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    // Each family drops the caches the change invalidates (rebuilt on next use).
    for (int i = 0; drift_family_at(i); ++i) {
        if (drift_family_at(i)->update) {
            drift_family_at(i)->update(f, &p);
        }
    }
    f->params = p;
    f->shading.light_samples = p.light_samples;
    return DRIFT_OK;
}

drift_result drift_hybrid_scene_changed(drift_hybrid *h, const drift_accel *accel)
{
    drift_frame_state *f = &h->frame;
    if (!accel || !f->scene->committed) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    drift_raster_light *lights = NULL;
    uint32_t count = 0;
    drift_result r = drift_raster_lights_build(f->ctx, f->scene, &lights, &count);
    if (r != DRIFT_OK) {
        return r;
    }
    if (count != f->light_count) {
        drift_raster_lights_destroy(f->ctx, lights, count);
        drift_log(f->ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, NULL, 0,
                  "hybrid frame: the scene's lights changed in number (%u -> %u); make a new "
                  "frame",
                  f->light_count, count);
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    // Every technique's state may hold the old geometry (shadow maps, probes, VPLs, points,
    // caches): each family frees its slot and makes it anew over the new lights, and the
    // techniques remake their caches on next use. The camera history (motion vectors) and the
    // frame's buffers stay.
    families_destroy(f);
    drift_pass_free_states(f);
    drift_raster_lights_destroy(f->ctx, f->lights, f->light_count);
    f->lights = lights;
    f->accel = accel;
    f->shading.accel = accel;
    f->shading.lights = lights;
    return families_create(f);
}

drift_result drift_hybrid_set_mesh_motion(drift_hybrid *h, const float *prev_from_now,
                                          uint32_t mesh_count)
{
    drift_frame_state *f = &h->frame;
    if (!prev_from_now) {
        f->has_mesh_motion = false;
        return DRIFT_OK;
    }
    if (mesh_count != f->scene->mesh_count) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    if (f->mesh_motion_capacity < mesh_count) {
        float *grown = drift_alloc(f->ctx, sizeof(float) * 12 * (size_t)mesh_count);
        if (!grown) {
            return DRIFT_ERR_OUT_OF_MEMORY;
        }
        drift_free(f->ctx, f->mesh_motion);
        f->mesh_motion = grown;
        f->mesh_motion_capacity = mesh_count;
    }
    memcpy(f->mesh_motion, prev_from_now, sizeof(float) * 12 * (size_t)mesh_count);
    f->has_mesh_motion = mesh_count > 0;
    return DRIFT_OK;
}

drift_hybrid_params drift_hybrid_get_params(const drift_hybrid *h)
{
    return h->frame.params;
}

// --- PLANES ---

static void add_plane(void *sink, const char *name, const drift_image *image)
{
    drift_hybrid *h = sink;
    if (h->plane_count == h->plane_capacity) {
        uint32_t capacity = h->plane_capacity ? 2 * h->plane_capacity : 64;
        plane_ref *grown =
            drift_realloc(h->frame.ctx, h->planes, sizeof(plane_ref) * h->plane_capacity,
                          sizeof(plane_ref) * capacity);
        if (!grown) {
            h->planes_out_of_memory = true;
            return;
        }
        h->planes = grown;
        h->plane_capacity = capacity;
    }
    plane_ref *p = &h->planes[h->plane_count++];
    snprintf(p->name, sizeof p->name, "%s", name);
    p->image = image;
}

// The planes of the inputs the chosen rows asked for, per light: U_l, the hard-shadow bits,
// S_l (the order --aov has always listed them in).
static void input_planes(drift_hybrid *h, uint32_t inputs)
{
    const drift_frame_state *f = &h->frame;
    if (!(inputs & DRIFT_INPUT_UNSHADOWED)) {
        return;
    }
    if (drift_scene_has_environment(f->scene)) {
        add_plane(h, "environment_direct", &f->environment_direct);
    }
    for (uint32_t l = 0; l < f->light_count; ++l) {
        char name[DRIFT_FRAME_PLANE_NAME];
        snprintf(name, sizeof name, "light%u.unshadowed", l);
        add_plane(h, name, &f->light_buffers[l].unshadowed);
        if (inputs & DRIFT_INPUT_HARD_SHADOWS) {
            snprintf(name, sizeof name, "light%u.hard_shadow", l);
            add_plane(h, name, &f->light_buffers[l].hard_shadow);
        }
        snprintf(name, sizeof name, "light%u.shadow", l);
        add_plane(h, name, &f->light_buffers[l].shadow);
    }
}

// The planes this frame filled, in a stable order: final image first, then the G-buffer,
// the inputs, and each effect's row's own planes.
static void collect_planes(drift_hybrid *h, uint32_t inputs)
{
    const drift_frame_state *f = &h->frame;
    const drift_gbuffer *g = &f->gbuffer;
    h->plane_count = 0;

    const struct {
        const char *name;
        const drift_image *image;
    } fixed[] = { { "depth", &g->depth },
                  { "position", &g->position },
                  { "normal", &g->normal },
                  { "geometric_normal", &g->geometric_normal },
                  { "albedo", &g->albedo },
                  { "specular", &g->specular },
                  { "gloss", &g->gloss },
                  { "material_id", &g->material_id },
                  { "emission", &g->emission },
                  { "motion", &g->motion },
                  { "coc", &f->coc } };

    add_plane(h, "final", &f->final);
    add_plane(h, "focus", &f->focus);
    for (int e = 0; e < DRIFT_EFFECT_COUNT; ++e) {
        const drift_effect_info *effect = drift_effect_info_of((drift_effect)e);
        if (effect->kind == DRIFT_EFFECT_KIND_TERM) {
            add_plane(h, effect->plane, &f->terms[e]);
        }
    }
    for (size_t i = 0; i < sizeof fixed / sizeof *fixed; ++i) {
        add_plane(h, fixed[i].name, fixed[i].image);
    }
    input_planes(h, inputs);
    if (inputs & DRIFT_INPUT_SHARP_REFLECTIONS) {
        add_plane(h, "reflection.emitted", &f->reflection_emitted);
        add_plane(h, "reflection.reflected", &f->reflection_reflected);
        add_plane(h, "reflection.distance", &f->reflection_distance);
    }
    for (int e = 0; e < DRIFT_EFFECT_COUNT; ++e) {
        const drift_technique_row *row = drift_technique_row_chosen(&f->params, (drift_effect)e);
        row->planes(f, add_plane, h);
    }
}

bool drift_hybrid_plane(const drift_hybrid *h, uint32_t index, const char **out_name,
                        const drift_image **out_image)
{
    if (index >= h->plane_count) {
        return false;
    }
    *out_name = h->planes[index].name;
    *out_image = h->planes[index].image;
    return true;
}

const drift_image *drift_hybrid_plane_named(const drift_hybrid *h, const char *name)
{
    for (uint32_t i = 0; i < h->plane_count; ++i) {
        if (strcmp(h->planes[i].name, name) == 0) {
            return h->planes[i].image;
        }
    }
    return NULL;
}

// --- RENDER ---

// The inputs rows share, each prepared once whichever rows asked for it, by the family that
// provides it.
static drift_result prepare_inputs(drift_frame_state *f, uint32_t inputs)
{
    drift_result r = DRIFT_OK;
    for (int i = 0; r == DRIFT_OK && drift_family_at(i); ++i) {
        const drift_family *family = drift_family_at(i);
        if (family->prepare && (inputs & family->provides)) {
            r = family->prepare(f, inputs & family->provides);
        }
    }
    return r;
}

// Adds pass k's final image to the sum; after the last of n passes, final is their mean.
static drift_result accumulate(drift_hybrid *h, uint32_t k, uint32_t n)
{
    drift_frame_state *f = &h->frame;
    if (!h->aa_sum.pixels) {
        drift_result r = drift_image_create(f->ctx, f->final.width, f->final.height,
                                            f->final.channels, &h->aa_sum);
        if (r != DRIFT_OK) {
            return r;
        }
    }
    size_t row = (size_t)f->final.width * (size_t)f->final.channels;
    float scale = 1.0f / (float)n;
    for (int32_t y = 0; y < f->final.height; ++y) {
        float *sum = h->aa_sum.pixels + (ptrdiff_t)y * h->aa_sum.stride;
        float *final = f->final.pixels + (ptrdiff_t)y * f->final.stride;
        for (size_t i = 0; i < row; ++i) {
            sum[i] = k == 0 ? final[i] : sum[i] + final[i];
            if (k + 1 == n) {
                final[i] = sum[i] * scale;
            }
        }
    }
    return DRIFT_OK;
}

bool drift_hybrid_stats_stage(const drift_hybrid_stats *stats, uint32_t index,
                              const char **out_name, double *out_ms)
{
    const char *name = NULL;
    double ms = 0.0;
    if (index == 0) {
        name = "primary";
        ms = stats->ms[DRIFT_PASS_PRIMARY];
    } else if (index == 1) {
        name = "inputs";
        ms = stats->inputs_ms;
    } else if (index < 2u + DRIFT_EFFECT_COUNT) {
        name = drift_effect_name((drift_effect)(index - 2));
        ms = stats->effect_ms[index - 2];
    } else if (index == 2u + DRIFT_EFFECT_COUNT) {
        name = "compose";
        ms = stats->compose_ms;
    } else if (index == 3u + DRIFT_EFFECT_COUNT) {
        name = "other";
        ms = stats->other_ms;
    } else {
        return false;
    }
    if (out_name) {
        *out_name = name;
    }
    if (out_ms) {
        *out_ms = ms;
    }
    return true;
}

bool drift_hybrid_stats_count(const drift_hybrid_stats *stats, uint32_t index,
                              const char **out_name, double *out_value)
{
    if (index >= stats->count_count) {
        return false;
    }
    if (out_name) {
        *out_name = stats->counts[index].name;
    }
    if (out_value) {
        *out_value = stats->counts[index].value;
    }
    return true;
}

static void add_count(drift_frame_state *f, const char *name, double value)
{
    drift_hybrid_stats *s = &f->stats;
    if (s->count_count < DRIFT_HYBRID_MAX_COUNTS) {
        s->counts[s->count_count].name = name;
        s->counts[s->count_count].value = value;
        ++s->count_count;
    } else {
        drift_log(f->ctx, DRIFT_LOG_WARNING, DRIFT_OK, __FILE__, __LINE__,
                  "hybrid frame: more than %d counts, '%s' left out", DRIFT_HYBRID_MAX_COUNTS,
                  name);
    }
}

// What the frame did, as each family reports it (after its last pass).
static void report_counts(drift_frame_state *f)
{
    f->stats.count_count = 0;
    for (int i = 0; drift_family_at(i); ++i) {
        if (drift_family_at(i)->report) {
            drift_family_at(i)->report(f, add_count);
        }
    }
}

static drift_result run_row(drift_frame_state *f, const drift_technique_row *row,
                            const atomic_bool *cancel)
{
    drift_pass_args args = { .effect = row->effect,
                             .technique = row->technique,
                             .stream = row->stream,
                             .components = row->components,
                             .cancel = cancel };
    double t = drift_time_now();
    drift_result r = row->pass(f, &args);
    // What follows the pass (contact shadows, summing D), by the families that do it.
    drift_family_row done = { .args = &args, .inputs = row->inputs, .flags = row->flags };
    for (int i = 0; r == DRIFT_OK && drift_family_at(i); ++i) {
        if (drift_family_at(i)->after_row) {
            r = drift_family_at(i)->after_row(f, &done);
        }
    }
    f->stats.effect_ms[row->effect] += 1000.0 * (drift_time_now() - t);
    return r;
}

// One pass of the frame: the G-buffer through f->camera, every chosen row, the composition
// and the post effects, into f->final. *out_inputs: the inputs the rows asked for.
static drift_result render_pass(drift_frame_state *f, const atomic_bool *cancel,
                                uint32_t *out_inputs)
{
    double t = drift_time_now();
    drift_camera prev = f->prev_camera;
    // The previous camera shifted like this pass's: the jitter is not motion.
    prev.film_shift_x = f->camera.film_shift_x;
    prev.film_shift_y = f->camera.film_shift_y;
    drift_gbuffer_render(f->ctx, f->scene, f->accel, &f->camera, f->has_prev_camera ? &prev : NULL,
                         f->has_mesh_motion ? f->mesh_motion : NULL, &f->gbuffer,
                         &f->stats.rays[DRIFT_PASS_PRIMARY]);
    drift_pass_time(f, DRIFT_PASS_PRIMARY, t);

    const drift_technique_row *rows[DRIFT_EFFECT_COUNT];
    uint32_t inputs = 0;
    bool replaced = false; // a row renders the whole frame: path-traced terms are not needed
    bool diffuse_environment = false;
    for (int e = 0; e < DRIFT_EFFECT_COUNT; ++e) {
        rows[e] = drift_technique_row_chosen(&f->params, (drift_effect)e);
        inputs |= rows[e]->inputs;
        replaced |= (rows[e]->flags & DRIFT_ROW_REPLACES_FRAME) != 0;
        diffuse_environment |= (rows[e]->flags & DRIFT_ROW_ENVIRONMENT_DIFFUSE) != 0;
    }
    *out_inputs = inputs;
    f->inputs = inputs;
    f->environment_diffuse_elsewhere = diffuse_environment;
    t = drift_time_now();
    drift_result r = prepare_inputs(f, inputs);
    f->stats.inputs_ms += 1000.0 * (drift_time_now() - t);
    // The terms in the table's order (direct light first: ambient light reads D), then the
    // composition, then the post effects (depth of field turns focus into final).
    for (int e = 0; r == DRIFT_OK && e < DRIFT_EFFECT_COUNT; ++e) {
        const drift_technique_row *row = rows[e];
        bool skipped = replaced && (row->flags & DRIFT_ROW_PATH_TRACED) &&
                       !(row->flags & DRIFT_ROW_REPLACES_FRAME);
        if (drift_effect_info_of((drift_effect)e)->kind == DRIFT_EFFECT_KIND_TERM && !skipped) {
            r = run_row(f, row, cancel);
        }
    }
    if (r == DRIFT_OK && !replaced) {
        t = drift_time_now();
        r = drift_hybrid_pass_compose(f);
        r = r ? r : drift_hybrid_pass_veils(f);
        f->stats.compose_ms += 1000.0 * (drift_time_now() - t);
    }
    for (int e = 0; r == DRIFT_OK && e < DRIFT_EFFECT_COUNT; ++e) {
        if (drift_effect_info_of((drift_effect)e)->kind == DRIFT_EFFECT_KIND_POST) {
            r = run_row(f, rows[e], cancel);
        }
    }
    return r;
}

// Pass k of n's film offset from the pixel centre: the Hammersley point set, shifted so that
// one pass is the centre. n points stratify the pixel in x and (for n a power of two) in y,
// so their mean converges to the path tracer's box pixel filter (its film sample is uniform
// over the pixel).
static void aa_offset(uint32_t k, uint32_t n, float *dx, float *dy)
{
    float x = ((float)k + 0.5f) / (float)n;
    float y = (float)drift_reverse_bits(k) * 0x1p-32f + 0.5f / (float)n;
    *dx = x - 0.5f;
    *dy = (y >= 1.0f ? y - 1.0f : y) - 0.5f;
}

drift_result drift_hybrid_render(drift_hybrid *h, const drift_camera *camera,
                                 const atomic_bool *cancel)
{
    if (!h || !camera) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    drift_frame_state *f = &h->frame;
    double start = drift_time_now();
    f->stats = (drift_hybrid_stats){ 0 };
    uint32_t seed = f->params.seed, passes = f->params.aa ? f->params.aa : 1;
    f->base_seed = seed;
    uint32_t inputs = 0;
    drift_result r = DRIFT_OK;
    for (uint32_t k = 0; r == DRIFT_OK && k < passes; ++k) {
        f->camera = *camera;
        f->camera.width = f->params.width;
        f->camera.height = f->params.height;
        float dx = 0.0f, dy = 0.0f;
        if (passes > 1) {
            aa_offset(k, passes, &dx, &dy);
        }
        f->camera.film_shift_x += dx;
        f->camera.film_shift_y += dy;
        // Pass 0 keeps the frame's seed (one pass is the frame it always was); the others
        // draw other sampler streams.
        f->params.seed = k ? drift_hash_combine(seed, 0x41410000u + k) : seed;
        f->aa_pass = k;
        r = render_pass(f, cancel, &inputs);
        if (r == DRIFT_OK && passes > 1) {
            double t = drift_time_now();
            r = accumulate(h, k, passes);
            f->stats.other_ms += 1000.0 * (drift_time_now() - t);
        }
    }
    f->params.seed = seed;
    f->aa_pass = 0;
    f->camera.film_shift_x = camera->film_shift_x;
    f->camera.film_shift_y = camera->film_shift_y;
    f->prev_camera = f->camera;
    f->has_prev_camera = true;
    f->has_mesh_motion = false; // one frame's
    double t_planes = drift_time_now();
    collect_planes(h, inputs);
    if (r == DRIFT_OK) {
        report_counts(f);
    }
    f->stats.other_ms += 1000.0 * (drift_time_now() - t_planes);
    if (r == DRIFT_OK && h->planes_out_of_memory) {
        h->planes_out_of_memory = false;
        r = DRIFT_ERR_OUT_OF_MEMORY;
    }
    f->stats.frame_ms = 1000.0 * (drift_time_now() - start);
    return r;
}

const drift_image *drift_hybrid_image(const drift_hybrid *h)
{
    return &h->frame.final;
}

const drift_gbuffer *drift_hybrid_gbuffer(const drift_hybrid *h)
{
    return &h->frame.gbuffer;
}

drift_hybrid_stats drift_hybrid_get_stats(const drift_hybrid *h)
{
    return h->frame.stats;
}

drift_frame_state *drift_hybrid_frame(drift_hybrid *h)
{
    return &h->frame;
}
