// drift bind (include/drift/bind.h): the hybrid parameters by name for language bindings.
#include "drift/bind.h"

#include "drift/pt.h"

#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

typedef enum knob_type {
    KNOB_INT,
    KNOB_UINT,
    KNOB_FLOAT,
    KNOB_BOOL
} knob_type;

// The knobs, X(name, field of drift_hybrid_params, type): the command line's option names
// with the family's prefix and a dot (--ism-vpls is "ism.vpls").
#define DRIFT_BIND_KNOBS(X)                                                \
    X("width", width, KNOB_INT)                                            \
    X("height", height, KNOB_INT)                                          \
    X("seed", seed, KNOB_UINT)                                             \
    X("spp", spp, KNOB_UINT)                                               \
    X("max_depth", max_depth, KNOB_INT)                                    \
    X("light_samples", light_samples, KNOB_UINT)                           \
    X("environment_interleave", environment_interleave, KNOB_BOOL)         \
    X("environment_filter", environment_filter, KNOB_UINT)                 \
    X("environment_scale", environment_scale, KNOB_UINT)                   \
    X("aa", aa, KNOB_UINT)                                                 \
    X("shadow_map.size", shadow_map.size, KNOB_INT)                        \
    X("shadow_map.bias", shadow_map.bias, KNOB_FLOAT)                      \
    X("shadow_map.pcf_kernel", shadow_map.pcf_kernel, KNOB_INT)            \
    X("shadow_map.contact_shadows", shadow_map.contact_shadows, KNOB_BOOL) \
    X("envmap.size", envmap.size, KNOB_INT)                                \
    X("isg.search", isg.search, KNOB_INT)                                  \
    X("isg.gather", isg.gather, KNOB_INT)                                  \
    X("isg.sigma", isg.sigma, KNOB_FLOAT)                                  \
    X("isg.layers", isg.layers, KNOB_INT)                                  \
    X("aaf.max_spp", aaf.max_spp, KNOB_UINT)                               \
    X("ism.vpls", ism.vpls, KNOB_UINT)                                     \
    X("ism.map_size", ism.map_size, KNOB_INT)                              \
    X("ism.points_per_vpl", ism.points_per_vpl, KNOB_UINT)                 \
    X("ism.gather_scale", ism.gather_scale, KNOB_INT)                      \
    X("ism.later_paths", ism.later_paths, KNOB_UINT)                       \
    X("micro.points", micro.points, KNOB_UINT)                             \
    X("micro.buffer_size", micro.buffer_size, KNOB_INT)                    \
    X("micro.density", micro.density, KNOB_INT)                            \
    X("micro.bounces", micro.bounces, KNOB_INT)                            \
    X("occlusion.samples", occlusion_settings.samples, KNOB_INT)           \
    X("occlusion.radius", occlusion_settings.radius, KNOB_FLOAT)           \
    X("occlusion.steps", occlusion_settings.steps, KNOB_INT)

typedef struct knob {
    const char *name;
    size_t offset;
    knob_type type;
} knob;

#define KNOB_ROW(name, field, type) { name, offsetof(drift_hybrid_params, field), type },
static const knob knobs[] = { DRIFT_BIND_KNOBS(KNOB_ROW) };
#undef KNOB_ROW
#define KNOB_COUNT (sizeof knobs / sizeof knobs[0])

static const knob *find_knob(const char *name)
{
    for (size_t i = 0; name && i < KNOB_COUNT; ++i) {
        if (strcmp(knobs[i].name, name) == 0) {
            return &knobs[i];
        }
    }
    return NULL;
}

drift_hybrid_params *drift_bind_params_new(void)
{
    drift_hybrid_params *p = malloc(sizeof *p);
    if (p) {
        *p = drift_hybrid_params_recommended();
    }
    return p;
}

void drift_bind_params_free(drift_hybrid_params *params)
{
    free(params);
}

drift_result drift_bind_params_set(drift_hybrid_params *params, const char *name, const char *value)
{
    if (!params || !name || !value) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    for (int e = 0; e < DRIFT_EFFECT_COUNT; ++e) {
        if (strcmp(drift_effect_name((drift_effect)e), name) == 0) {
            int t = drift_technique_parse((drift_effect)e, value);
            if (t < 0) {
                return DRIFT_ERR_INVALID_ARGUMENT;
            }
            drift_hybrid_params_set_technique(params, (drift_effect)e, t);
            return DRIFT_OK;
        }
    }
    const knob *k = find_knob(name);
    if (!k) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    char *end = NULL;
    char *field = (char *)params + k->offset;
    if (k->type == KNOB_BOOL) {
        bool b = strcmp(value, "true") == 0 || strcmp(value, "1") == 0;
        if (!b && strcmp(value, "false") != 0 && strcmp(value, "0") != 0) {
            return DRIFT_ERR_INVALID_ARGUMENT;
        }
        memcpy(field, &b, sizeof b);
        return DRIFT_OK;
    }
    double v = strtod(value, &end);
    if (end == value || *end != '\0' || !isfinite(v)) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    if (k->type == KNOB_FLOAT) {
        float f = (float)v;
        memcpy(field, &f, sizeof f);
    } else if (v != floor(v) || v > 2147483647.0 ||
               v < (k->type == KNOB_UINT ? 0.0 : -2147483648.0)) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    } else if (k->type == KNOB_UINT) {
        uint32_t u = (uint32_t)v;
        memcpy(field, &u, sizeof u);
    } else {
        int32_t i = (int32_t)v;
        memcpy(field, &i, sizeof i);
    }
    return DRIFT_OK;
}

double drift_bind_params_get(const drift_hybrid_params *params, const char *name)
{
    const knob *k = find_knob(name);
    if (!params || !k) {
        return (double)NAN;
    }
    const char *field = (const char *)params + k->offset;
    switch (k->type) {
    case KNOB_BOOL: {
        bool b;
        memcpy(&b, field, sizeof b);
        return b ? 1.0 : 0.0;
    }
    case KNOB_FLOAT: {
        float f;
        memcpy(&f, field, sizeof f);
        return (double)f;
    }
    case KNOB_UINT: {
        uint32_t u;
        memcpy(&u, field, sizeof u);
        return (double)u;
    }
    default: {
        int32_t i;
        memcpy(&i, field, sizeof i);
        return (double)i;
    }
    }
}

uint32_t drift_bind_knob_count(void)
{
    return (uint32_t)KNOB_COUNT;
}

const char *drift_bind_knob_name(uint32_t index)
{
    return index < KNOB_COUNT ? knobs[index].name : NULL;
}

const char *drift_bind_knob_type(uint32_t index)
{
    static const char *const names[] = { "int", "uint", "float", "bool" };
    return index < KNOB_COUNT ? names[knobs[index].type] : NULL;
}

const drift_camera *drift_bind_scene_camera(const drift_scene *scene)
{
    return scene ? &scene->camera : NULL;
}

drift_result drift_bind_reference(drift_context *ctx, const drift_scene *scene,
                                  const drift_accel *accel, int32_t width, int32_t height,
                                  uint32_t spp, uint32_t seed, int32_t max_depth,
                                  drift_image *out_image)
{
    if (!out_image) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    *out_image = (drift_image){ 0 };
    drift_pt *pt = NULL;
    drift_pt_params params = {
        .width = width, .height = height, .seed = seed, .max_depth = max_depth
    };
    drift_result r = drift_pt_create(ctx, scene, accel, &params, &pt);
    if (r == DRIFT_OK) {
        r = drift_pt_render_samples(pt, spp ? spp : 1, NULL);
    }
    drift_image beauty = { 0 };
    if (r == DRIFT_OK) {
        r = drift_pt_resolve(pt, DRIFT_PT_AOV_BEAUTY, &beauty);
    }
    if (r == DRIFT_OK) {
        r = drift_image_create(ctx, beauty.width, beauty.height, 3, out_image);
    }
    for (int32_t y = 0; r == DRIFT_OK && y < beauty.height; ++y) {
        for (int32_t x = 0; x < beauty.width; ++x) {
            memcpy(drift_image_pixel(out_image, x, y), drift_image_pixel(&beauty, x, y),
                   3 * sizeof(float));
        }
    }
    drift_pt_destroy(pt);
    return r;
}
