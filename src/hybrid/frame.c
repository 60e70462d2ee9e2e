// The hybrid frame: lifecycle, technique names, the pass order, and the table of planes
// (--aov, the viewer). The passes themselves live in direct.c, reflections.c, reference.c
// and compose.c.
#include "hybrid/frame_internal.h"
#include "hybrid/isg_internal.h"
#include "hybrid/aaf_internal.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

// --- NAMES ---

static const char *const shadow_names[] = { "hard", "pcf", "pcss", "reference",
                                           "isg",  "blur", "aaf" };
static const char *const reflection_names[] = { "none", "envmap", "sharp",
                                               "reference", "isg", "blur", "aaf" };
static const char *const dof_names[] = { "none", "post", "reference", "isg" };
static const char *const indirect_names[] = { "none", "ambient", "reference", "aaf" };
static const char *const effect_names[] = { "shadows", "reflections", "dof", "indirect" };
static const char *const pass_names[] = { "primary",     "unshadowed", "hard_shadows",
                                          "shadow_maps", "shadow_filter", "reflections",
                                          "envmap",      "reference",  "compose", "dof",
                                          "isg", "aaf_sampling", "aaf_filter" };

_Static_assert(sizeof shadow_names / sizeof *shadow_names == DRIFT_SHADOWS_COUNT, "names");
_Static_assert(sizeof reflection_names / sizeof *reflection_names == DRIFT_REFLECTIONS_COUNT,
               "names");
_Static_assert(sizeof dof_names / sizeof *dof_names == DRIFT_DOF_COUNT, "names");
_Static_assert(sizeof indirect_names / sizeof *indirect_names == DRIFT_INDIRECT_COUNT, "names");
_Static_assert(sizeof pass_names / sizeof *pass_names == DRIFT_PASS_COUNT, "names");

static const char *const *technique_table(drift_effect effect, int *out_count)
{
    switch (effect) {
    case DRIFT_EFFECT_SHADOWS:
        *out_count = DRIFT_SHADOWS_COUNT;
        return shadow_names;
    case DRIFT_EFFECT_REFLECTIONS:
        *out_count = DRIFT_REFLECTIONS_COUNT;
        return reflection_names;
    case DRIFT_EFFECT_DOF:
        *out_count = DRIFT_DOF_COUNT;
        return dof_names;
    case DRIFT_EFFECT_INDIRECT:
        *out_count = DRIFT_INDIRECT_COUNT;
        return indirect_names;
    case DRIFT_EFFECT_COUNT:
        break;
    }
    *out_count = 0;
    return NULL;
}

const char *drift_effect_name(drift_effect effect)
{
    return (unsigned)effect < DRIFT_EFFECT_COUNT ? effect_names[effect] : NULL;
}

int drift_technique_count(drift_effect effect)
{
    int count;
    technique_table(effect, &count);
    return count;
}

const char *drift_technique_name(drift_effect effect, int technique)
{
    int count;
    const char *const *names = technique_table(effect, &count);
    return technique >= 0 && technique < count ? names[technique] : NULL;
}

int drift_technique_parse(drift_effect effect, const char *name)
{
    int count;
    const char *const *names = technique_table(effect, &count);
    for (int i = 0; name && i < count; ++i) {
        if (strcmp(names[i], name) == 0) {
            return i;
        }
    }
    return -1;
}

const char *drift_hybrid_pass_name(drift_hybrid_pass pass)
{
    return (unsigned)pass < DRIFT_PASS_COUNT ? pass_names[pass] : NULL;
}

// --- PARAMETERS ---

int drift_hybrid_params_technique(const drift_hybrid_params *params, drift_effect effect)
{
    switch (effect) {
    case DRIFT_EFFECT_SHADOWS:
        return (int)params->shadows;
    case DRIFT_EFFECT_REFLECTIONS:
        return (int)params->reflections;
    case DRIFT_EFFECT_DOF:
        return (int)params->dof;
    case DRIFT_EFFECT_INDIRECT:
        return (int)params->indirect;
    case DRIFT_EFFECT_COUNT:
        break;
    }
    return -1;
}

void drift_hybrid_params_set_technique(drift_hybrid_params *params, drift_effect effect,
                                       int technique)
{
    switch (effect) {
    case DRIFT_EFFECT_SHADOWS:
        params->shadows = (drift_shadow_technique)technique;
        break;
    case DRIFT_EFFECT_REFLECTIONS:
        params->reflections = (drift_reflection_technique)technique;
        break;
    case DRIFT_EFFECT_DOF:
        params->dof = (drift_dof_technique)technique;
        break;
    case DRIFT_EFFECT_INDIRECT:
        params->indirect = (drift_indirect_technique)technique;
        break;
    case DRIFT_EFFECT_COUNT:
        break;
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
    p.shadow_map_size = p.shadow_map_size ? p.shadow_map_size : 512;
    p.shadow_bias = p.shadow_bias > 0.0f ? p.shadow_bias : 1.5f;
    p.pcf_kernel = p.pcf_kernel ? p.pcf_kernel : 3;
    p.envmap_size = p.envmap_size ? p.envmap_size : 128;
    drift_isg_params_resolve(&p, scene);
    if (p.aaf_max_spp == 0) {
        p.aaf_max_spp = p.spp > 512 ? 4096 : 8 * p.spp;
    }
    return p;
}

static bool params_valid(const drift_context *ctx, const drift_hybrid_params *p)
{
    const char *problem = NULL;
    if (p->width <= 0 || p->height <= 0 || p->width > DRIFT_IMAGE_MAX_DIMENSION ||
        p->height > DRIFT_IMAGE_MAX_DIMENSION) {
        problem = "image size out of range";
    } else if ((unsigned)p->shadows >= DRIFT_SHADOWS_COUNT ||
               (unsigned)p->reflections >= DRIFT_REFLECTIONS_COUNT ||
               (unsigned)p->dof >= DRIFT_DOF_COUNT ||
               (unsigned)p->indirect >= DRIFT_INDIRECT_COUNT) {
        problem = "unknown technique";
    } else if (p->max_depth < 1 || p->max_depth > 1024) {
        problem = "max_depth outside 1..1024";
    } else if (p->shadow_map_size < 1 || p->shadow_map_size > 8192 || p->envmap_size < 1 ||
               p->envmap_size > 4096) {
        problem = "shadow map or environment map size out of range";
    } else if (p->pcf_kernel < 1 || p->pcf_kernel > 63 || p->light_samples > 4096) {
        problem = "pcf kernel outside 1..63 or light samples over 4096";
    } else if (p->aaf_max_spp < p->spp || p->aaf_max_spp > 65536) {
        problem = "aaf max spp below spp or over 65536";
    } else if (!isfinite(p->shadow_bias) || (p->has_probe && !drift_vec3_is_finite(p->probe)) ||
               (p->has_ambient && !drift_vec3_is_finite(p->ambient))) {
        problem = "non-finite bias, probe or ambient";
    } else {
        problem = drift_isg_params_problem(p);
    }
    if (problem) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, NULL, 0, "hybrid frame: %s",
                  problem);
    }
    return problem == NULL;
}

// --- LIFECYCLE ---

static drift_result create_images(drift_hybrid *f)
{
    drift_context *ctx = f->ctx;
    int32_t w = f->params.width, h = f->params.height;
    drift_result r = drift_gbuffer_create(ctx, w, h, &f->gbuffer);
    drift_image *rgb[] = { &f->environment_direct, &f->direct,     &f->reflection_emitted,
                           &f->reflection_reflected, &f->reflections, &f->indirect,
                           &f->reference,           &f->focus,      &f->final };
    for (size_t i = 0; r == DRIFT_OK && i < sizeof rgb / sizeof *rgb; ++i) {
        r = drift_image_create(ctx, w, h, 3, rgb[i]);
    }
    if (r == DRIFT_OK) {
        r = drift_image_create(ctx, w, h, 1, &f->reflection_distance);
    }
    if (r == DRIFT_OK) {
        r = drift_image_create(ctx, w, h, 1, &f->coc);
    }
    for (uint32_t l = 0; r == DRIFT_OK && l < f->light_count; ++l) {
        drift_hybrid_light_buffers *b = &f->light_buffers[l];
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
    drift_hybrid *f = drift_alloc(ctx, sizeof(drift_hybrid));
    if (!f) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    f->ctx = ctx;
    f->scene = scene;
    f->accel = accel;
    f->params = p;
    f->thread_count = drift_context_thread_count(ctx);
    drift_result r = drift_hybrid_lights_build(ctx, scene, &f->lights, &f->light_count);
    if (r == DRIFT_OK) {
        f->counters = drift_alloc(ctx, sizeof(drift_ray_counter) * (size_t)f->thread_count);
        // + 1: a scene with no lights still gets an allocation.
        f->light_buffers =
            drift_alloc(ctx, sizeof(drift_hybrid_light_buffers) * (f->light_count + 1u));
        f->plane_capacity = DRIFT_HYBRID_FIXED_PLANES + DRIFT_HYBRID_PLANES_PER_LIGHT * f->light_count +
                            DRIFT_ISG_FIXED_PLANES + DRIFT_ISG_PLANES_PER_LIGHT * f->light_count;
        f->planes = drift_alloc(ctx, sizeof(drift_hybrid_plane_ref) * f->plane_capacity);
        r = f->counters && f->light_buffers && f->planes ? DRIFT_OK : DRIFT_ERR_OUT_OF_MEMORY;
    }
    if (r == DRIFT_OK) {
        r = create_images(f);
    }
    if (r != DRIFT_OK) {
        drift_hybrid_destroy(f);
        return r;
    }
    f->shading = (drift_hybrid_shading){ .scene = scene,
                                         .accel = accel,
                                         .lights = f->lights,
                                         .light_count = f->light_count,
                                         .light_samples = p.light_samples };
    *out_frame = f;
    return DRIFT_OK;
}

static void destroy_probes(drift_hybrid *f)
{
    for (uint32_t i = 0; i < f->probe_count; ++i) {
        drift_envmap_destroy(f->ctx, f->probes[i].map);
    }
    drift_free(f->ctx, f->probes);
    f->probes = NULL;
    f->probe_count = 0;
}

static void destroy_shadow_maps(drift_hybrid *f)
{
    for (uint32_t l = 0; l < f->light_count; ++l) {
        drift_shadow_map_destroy(f->ctx, f->light_buffers[l].shadow_map);
        f->light_buffers[l].shadow_map = NULL;
    }
}

void drift_hybrid_destroy(drift_hybrid *f)
{
    if (!f) {
        return;
    }
    drift_context *ctx = f->ctx;
    if (f->light_buffers) {
        destroy_shadow_maps(f);
        for (uint32_t l = 0; l < f->light_count; ++l) {
            drift_image_destroy(ctx, &f->light_buffers[l].unshadowed);
            drift_image_destroy(ctx, &f->light_buffers[l].hard_shadow);
            drift_image_destroy(ctx, &f->light_buffers[l].shadow);
        }
    }
    destroy_probes(f);
    drift_isg_destroy(f);
    drift_aaf_state_destroy(ctx, f->aaf);
    drift_gbuffer_destroy(ctx, &f->gbuffer);
    drift_image *images[] = { &f->environment_direct, &f->direct,      &f->reflection_emitted,
                              &f->reflection_reflected, &f->reflection_distance, &f->reflections,
                              &f->indirect,           &f->reference,   &f->coc,
                              &f->focus,              &f->final };
    for (size_t i = 0; i < sizeof images / sizeof *images; ++i) {
        drift_image_destroy(ctx, images[i]);
    }
    drift_hybrid_lights_destroy(ctx, f->lights, f->light_count);
    drift_free(ctx, f->light_buffers);
    drift_free(ctx, f->planes);
    drift_free(ctx, f->counters);
    drift_free(ctx, f);
}

drift_result drift_hybrid_set_params(drift_hybrid *f, const drift_hybrid_params *params)
{
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
    // Cached maps that depend on a changed setting are rebuilt on next use.
    if (p.shadow_map_size != f->params.shadow_map_size || p.shadow_bias != f->params.shadow_bias) {
        destroy_shadow_maps(f);
    }
    if (p.envmap_size != f->params.envmap_size || p.has_probe != f->params.has_probe ||
        p.probe_per_object != f->params.probe_per_object || p.seed != f->params.seed ||
        p.light_samples != f->params.light_samples ||
        (p.has_probe && !drift_vec3_is_zero(drift_vec3_sub(p.probe, f->params.probe)))) {
        destroy_probes(f);
    }
    f->params = p;
    f->shading.light_samples = p.light_samples;
    return DRIFT_OK;
}

drift_hybrid_params drift_hybrid_get_params(const drift_hybrid *f)
{
    return f->params;
}

// --- SHARED PIECES OF THE PASSES ---

typedef struct row_job {
    drift_hybrid *frame;
    drift_hybrid_row_fn fn;
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

uint64_t drift_hybrid_for_each_row(drift_hybrid *frame, drift_hybrid_row_fn fn, void *user)
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
    drift_hybrid_pixel_fn fn;
    void *user;
} pixel_job;

static void pixels_of_row(drift_hybrid *frame, int32_t y, uint64_t *rays, void *user)
{
    const pixel_job *job = user;
    for (int32_t x = 0; x < frame->params.width; ++x) {
        job->fn(frame, x, y, rays, job->user);
    }
}

uint64_t drift_hybrid_for_each_pixel(drift_hybrid *frame, drift_hybrid_pixel_fn fn, void *user)
{
    pixel_job job = { fn, user };
    return drift_hybrid_for_each_row(frame, pixels_of_row, &job);
}

drift_sampler drift_hybrid_sampler(const drift_hybrid *frame, uint32_t stream, int32_t x,
                                   int32_t y)
{
    uint32_t pixel = (uint32_t)y * (uint32_t)frame->params.width + (uint32_t)x;
    return drift_sampler_make(drift_hash_combine(frame->params.seed, stream), pixel, 0);
}

drift_vec3 drift_hybrid_wo(const drift_hybrid *frame, int32_t x, int32_t y)
{
    // The primary ray is a pinhole ray from the camera's position: toward the eye from the hit.
    const drift_surface *s = &frame->gbuffer.surfaces[(size_t)y * (size_t)frame->params.width + (size_t)x];
    return drift_vec3_normalize(drift_vec3_sub(frame->camera.position, s->position));
}

void drift_hybrid_copy_rgb(const drift_image *from, drift_image *to)
{
    for (int32_t y = 0; y < to->height; ++y) {
        for (int32_t x = 0; x < to->width; ++x) {
            drift_image_set3(to, x, y, drift_image_get3(from, x, y));
        }
    }
}

// --- PLANES ---

static void add_plane(drift_hybrid *f, const char *name, const drift_image *image)
{
    DRIFT_CHECK(f->plane_count < f->plane_capacity); // sized for every plane at create
    drift_hybrid_plane_ref *p = &f->planes[f->plane_count++];
    snprintf(p->name, sizeof p->name, "%s", name);
    p->image = image;
}

// The planes this frame filled, in a stable order: final image first.
static void collect_planes(drift_hybrid *f)
{
    const drift_hybrid_params *p = &f->params;
    const drift_gbuffer *g = &f->gbuffer;
    f->plane_count = 0;
    add_plane(f, "final", &f->final);
    add_plane(f, "focus", &f->focus);
    add_plane(f, "direct", &f->direct);
    add_plane(f, "reflections", &f->reflections);
    add_plane(f, "indirect", &f->indirect);
    add_plane(f, "depth", &g->depth);
    add_plane(f, "position", &g->position);
    add_plane(f, "normal", &g->normal);
    add_plane(f, "geometric_normal", &g->geometric_normal);
    add_plane(f, "albedo", &g->albedo);
    add_plane(f, "specular", &g->specular);
    add_plane(f, "gloss", &g->gloss);
    add_plane(f, "material_id", &g->material_id);
    add_plane(f, "emission", &g->emission);
    add_plane(f, "motion", &g->motion);
    add_plane(f, "coc", &f->coc);
    if (drift_scene_has_environment(f->scene) && p->shadows != DRIFT_SHADOWS_REFERENCE) {
        add_plane(f, "environment_direct", &f->environment_direct);
    }
    for (uint32_t l = 0; l < f->light_count && p->shadows != DRIFT_SHADOWS_REFERENCE; ++l) {
        char name[DRIFT_HYBRID_PLANE_NAME];
        snprintf(name, sizeof name, "light%u.unshadowed", l);
        add_plane(f, name, &f->light_buffers[l].unshadowed);
        if (p->shadows == DRIFT_SHADOWS_HARD || p->shadows == DRIFT_SHADOWS_ISG ||
            p->shadows == DRIFT_SHADOWS_BLUR) {
            snprintf(name, sizeof name, "light%u.hard_shadow", l);
            add_plane(f, name, &f->light_buffers[l].hard_shadow);
        }
        snprintf(name, sizeof name, "light%u.shadow", l);
        add_plane(f, name, &f->light_buffers[l].shadow);
    }
    for (uint32_t l = 0; l < f->light_count && p->shadows == DRIFT_SHADOWS_AAF && f->aaf; ++l) {
        const char *names[3] = { "beta", "spp", "unfiltered" };
        const drift_image *images[3] = { &f->aaf->lights[l].beta, &f->aaf->lights[l].spp,
                                         &f->aaf->lights[l].unfiltered };
        for (int k = 0; k < 3; ++k) {
            char name[DRIFT_HYBRID_PLANE_NAME];
            snprintf(name, sizeof name, "light%u.aaf.%s", l, names[k]);
            add_plane(f, name, images[k]);
        }
    }
    if (p->indirect == DRIFT_INDIRECT_AAF && f->aaf && f->aaf->indirect.beta.pixels) {
        add_plane(f, "indirect.aaf.beta", &f->aaf->indirect.beta);
        add_plane(f, "indirect.aaf.spp", &f->aaf->indirect.spp);
        add_plane(f, "indirect.aaf.unfiltered", &f->aaf->indirect.unfiltered);
    }
    if (p->reflections == DRIFT_REFLECTIONS_AAF && f->aaf && f->aaf->specular.beta.pixels) {
        add_plane(f, "reflections.aaf.beta", &f->aaf->specular.beta);
        add_plane(f, "reflections.aaf.spp", &f->aaf->specular.spp);
        add_plane(f, "reflections.aaf.unfiltered", &f->aaf->specular.unfiltered);
    }
    if (p->reflections == DRIFT_REFLECTIONS_SHARP || p->reflections == DRIFT_REFLECTIONS_ISG ||
        p->reflections == DRIFT_REFLECTIONS_BLUR) {
        add_plane(f, "reflection.emitted", &f->reflection_emitted);
        add_plane(f, "reflection.reflected", &f->reflection_reflected);
        add_plane(f, "reflection.distance", &f->reflection_distance);
    }
    drift_isg_add_planes(f, add_plane);
}

bool drift_hybrid_plane(const drift_hybrid *f, uint32_t index, const char **out_name,
                        const drift_image **out_image)
{
    if (index >= f->plane_count) {
        return false;
    }
    *out_name = f->planes[index].name;
    *out_image = f->planes[index].image;
    return true;
}

const drift_image *drift_hybrid_plane_named(const drift_hybrid *f, const char *name)
{
    for (uint32_t i = 0; i < f->plane_count; ++i) {
        if (strcmp(f->planes[i].name, name) == 0) {
            return f->planes[i].image;
        }
    }
    return NULL;
}

// --- RENDER ---

drift_result drift_hybrid_render(drift_hybrid *f, const drift_camera *camera,
                                 const atomic_bool *cancel)
{
    if (!f || !camera) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    double start = drift_time_now();
    f->stats = (drift_hybrid_stats){ 0 };
    f->camera = *camera;
    f->camera.width = f->params.width;
    f->camera.height = f->params.height;

    double t = drift_time_now();
    drift_gbuffer_render(f->ctx, f->scene, f->accel, &f->camera,
                         f->has_prev_camera ? &f->prev_camera : NULL, &f->gbuffer,
                         &f->stats.rays[DRIFT_PASS_PRIMARY]);
    f->stats.ms[DRIFT_PASS_PRIMARY] = 1000.0 * (drift_time_now() - t);

    drift_result r = drift_hybrid_pass_direct(f);
    if (r == DRIFT_OK) {
        r = drift_hybrid_pass_reflections(f);
    }
    // AAF's path-traced terms are skipped when the lens render replaces every term.
    bool lens_reference = f->params.dof == DRIFT_DOF_REFERENCE;
    if (r == DRIFT_OK && f->params.reflections == DRIFT_REFLECTIONS_AAF && !lens_reference) {
        r = drift_hybrid_pass_aaf_specular(f);
    }
    if (r == DRIFT_OK && f->params.indirect == DRIFT_INDIRECT_AAF && !lens_reference) {
        r = drift_hybrid_pass_aaf_indirect(f);
    }
    if (r == DRIFT_OK) {
        r = drift_hybrid_pass_reference(f, cancel);
    }
    if (r == DRIFT_OK) {
        r = drift_hybrid_pass_compose(f, cancel);
    }
    f->prev_camera = f->camera;
    f->has_prev_camera = true;
    collect_planes(f);
    f->stats.frame_ms = 1000.0 * (drift_time_now() - start);
    return r;
}

const drift_image *drift_hybrid_image(const drift_hybrid *f)
{
    return &f->final;
}

const drift_gbuffer *drift_hybrid_gbuffer(const drift_hybrid *f)
{
    return &f->gbuffer;
}

drift_hybrid_stats drift_hybrid_get_stats(const drift_hybrid *f)
{
    return f->stats;
}
