// drift bind (include/drift/bind.h): the hybrid parameters by name for language bindings.
#include "drift/bind.h"

#include "drift/knobs.h"
#include "drift/pt.h"

#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

// The frame's own fields a binding sets besides the knob table's rows (drift/knobs.h, whose
// names are the command line's options: --ism-vpls is "ism-vpls"; "ism_vpls" and "ism.vpls"
// are read as the same name, for Python's keyword arguments).
typedef enum field_type {
    FIELD_INT,
    FIELD_UINT
} field_type;

typedef struct field {
    const char *name;
    size_t offset;
    field_type type;
} field;

#define FIELD_ROW(name, member, type)                     \
    {                                                     \
        name, offsetof(drift_hybrid_params, member), type \
    }
static const field fields[] = {
    FIELD_ROW("width", width, FIELD_INT),         FIELD_ROW("height", height, FIELD_INT),
    FIELD_ROW("seed", seed, FIELD_UINT),          FIELD_ROW("spp", spp, FIELD_UINT),
    FIELD_ROW("max_depth", max_depth, FIELD_INT),
};
#undef FIELD_ROW
#define FIELD_COUNT ((uint32_t)(sizeof fields / sizeof fields[0]))

static const field *find_field(const char *name)
{
    for (uint32_t i = 0; name && i < FIELD_COUNT; ++i) {
        if (strcmp(fields[i].name, name) == 0) {
            return &fields[i];
        }
    }
    return NULL;
}

// The knob table's index of `name`, with '_' and '.' read as '-'; -1 when there is none.
static int find_knob(const char *name)
{
    char key[64];
    size_t n = name ? strlen(name) : sizeof key;
    if (n >= sizeof key) {
        return -1;
    }
    for (size_t i = 0; i <= n; ++i) {
        key[i] = name[i] == '_' || name[i] == '.' ? '-' : name[i];
    }
    return drift_knob_find(key);
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
    int knob = find_knob(name);
    if (knob >= 0) {
        double v;
        return drift_knob_parse(drift_knob_get(knob), value, &v) && drift_knob_set(params, knob, v)
                   ? DRIFT_OK
                   : DRIFT_ERR_INVALID_ARGUMENT;
    }
    const field *f = find_field(name);
    char *end = NULL;
    double v = f ? strtod(value, &end) : 0.0;
    if (!f || end == value || *end != '\0' || !isfinite(v) || v != floor(v) || v > 2147483647.0 ||
        v < (f->type == FIELD_UINT ? 0.0 : -2147483648.0)) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    char *at = (char *)params + f->offset;
    if (f->type == FIELD_UINT) {
        uint32_t u = (uint32_t)v;
        memcpy(at, &u, sizeof u);
    } else {
        int32_t i = (int32_t)v;
        memcpy(at, &i, sizeof i);
    }
    return DRIFT_OK;
}

double drift_bind_params_get(const drift_hybrid_params *params, const char *name)
{
    int knob = find_knob(name);
    const field *f = knob < 0 ? find_field(name) : NULL;
    if (!params || (knob < 0 && !f)) {
        return (double)NAN;
    }
    if (knob >= 0) {
        return drift_knob_value(params, knob);
    }
    const char *at = (const char *)params + f->offset;
    if (f->type == FIELD_UINT) {
        uint32_t u;
        memcpy(&u, at, sizeof u);
        return (double)u;
    }
    int32_t i;
    memcpy(&i, at, sizeof i);
    return (double)i;
}

// The frame's fields first, then every row of the knob table.
uint32_t drift_bind_knob_count(void)
{
    return FIELD_COUNT + (uint32_t)drift_knob_count();
}

const char *drift_bind_knob_name(uint32_t index)
{
    if (index < FIELD_COUNT) {
        return fields[index].name;
    }
    const drift_knob *k = drift_knob_get((int)(index - FIELD_COUNT));
    return k ? k->name : NULL;
}

const char *drift_bind_knob_type(uint32_t index)
{
    if (index < FIELD_COUNT) {
        return fields[index].type == FIELD_UINT ? "uint" : "int";
    }
    const drift_knob *k = drift_knob_get((int)(index - FIELD_COUNT));
    static const char *const names[] = {
        [DRIFT_KNOB_INT] = "int", [DRIFT_KNOB_NUMBER] = "float", [DRIFT_KNOB_CHOICE] = "choice"
    };
    return k ? names[k->type] : NULL;
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
