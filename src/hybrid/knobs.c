// The knob table (include/drift/knobs.h): the frame's own knobs, and the accessors over
// every family's rows (each family's array is in its folder's knobs.c).
#include "frame/knob_rows.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define DRIFT_KNOB_FAMILY_NAME "frame"
static const drift_knob frame_rows[] = {
    DRIFT_KNOB_INT_ROW("light-samples", "N", light_samples, 1, 4096, 2, "samples",
                       "samples per area light for unshadowed light, and the environment's\n"
                       "shadow rays a pixel (docs/frontier.md#the-defaults)",
                       -1, NULL),
    DRIFT_KNOB_INT_ROW("aa", "N", aa, 1, 4096, 1, "passes",
                       "anti-aliasing: the whole frame N times, each through a stratified\n"
                       "sub-pixel offset with its own seed, averaged (1: pixel centres; hard\n"
                       "shadows aim at a stratified point of the light a pass, ISM gathers\n"
                       "1/N of one frame's VPLs a pass)",
                       -1, NULL),
    DRIFT_KNOB_CHOICE_ROW("env-interleave", environment_interleave, "off|on", 0,
                          "on: a quarter of the environment's --light-samples shadow rays a\n"
                          "pixel, interleaved over 2 x 2 pixels and gathered back over 3 x 3\n"
                          "of the same surface (takes --env-scale 1; docs/hybrid.md)",
                          -1, NULL),
    DRIFT_KNOB_INT_ROW("env-scale", "N", environment_scale, 1, 2, 2, "pixels",
                       "2: one pixel in 2 x 2 traces the environment's shadow rays, the\n"
                       "others take the traced ones on their surface; 1: every pixel (1 when\n"
                       "--env-interleave is on; docs/hybrid.md)",
                       -1, NULL),
    DRIFT_KNOB_INT_ROW("env-filter", "N", environment_filter, 0, 10, 4, "passes",
                       "passes of the edge-avoiding a-trous filter over the environment's\n"
                       "direct light, guided by the G-buffer (0: none; docs/hybrid.md)",
                       -1, NULL),
    DRIFT_KNOB_CHOICE_ROW("env-denoise", environment_denoise, "off|on", 0,
                          "on: --env-filter's passes are the path tracer's variance-guided\n"
                          "filter (--denoise on's), not the guide-only a-trous (docs/denoiser.md)",
                          -1, NULL),
};
DRIFT_KNOB_FAMILY(drift_frame_knobs, "the frame (docs/hybrid.md)", frame_rows);

// The families in --help's order.
static const drift_knob_family *const families[] = {
    &drift_frame_knobs,     &drift_shadow_map_knobs, &drift_envmap_knobs,
    &drift_post_dof_knobs,  &drift_isg_knobs,        &drift_aaf_knobs,
    &drift_occlusion_knobs, &drift_ism_knobs,        &drift_micro_knobs,
};

enum {
    FAMILY_COUNT = sizeof families / sizeof families[0]
};

// Each effect's default technique: the equal-time frontier's pick (docs/frontier.md): hard
// shadows and instant radiosity from imperfect shadow maps; the others off.
// Every effect a scene has is rendered by something (issue 40): area lights' penumbrae by ISG
// over the hard-shadow buffer (a point light's stays hard), glossy and metal surfaces by ISG's
// gather over the sharp reflection buffer (`none` left a metal sphere black), a lens's depth of
// field by the post-process gather (a pinhole's circles of confusion are 0).
static const int default_techniques[DRIFT_EFFECT_COUNT] = {
    [DRIFT_EFFECT_SHADOWS] = DRIFT_SHADOWS_ISG,
    [DRIFT_EFFECT_REFLECTIONS] = DRIFT_REFLECTIONS_ISG,
    [DRIFT_EFFECT_DOF] = DRIFT_DOF_POST,
    [DRIFT_EFFECT_INDIRECT] = DRIFT_INDIRECT_ISM,
    [DRIFT_EFFECT_OCCLUSION] = DRIFT_OCCLUSION_NONE,
    [DRIFT_EFFECT_GLARE] = DRIFT_GLARE_NONE,
};

int drift_knob_count(void)
{
    int n = 0;
    for (int f = 0; f < FAMILY_COUNT; ++f) {
        n += families[f]->count;
    }
    return n;
}

const drift_knob *drift_knob_get(int index)
{
    for (int f = 0; f < FAMILY_COUNT && index >= 0; ++f) {
        if (index < families[f]->count) {
            return &families[f]->rows[index];
        }
        index -= families[f]->count;
    }
    return NULL;
}

int drift_knob_find(const char *name)
{
    for (int i = 0, n = drift_knob_count(); name && i < n; ++i) {
        if (strcmp(drift_knob_get(i)->name, name) == 0) {
            return i;
        }
    }
    return -1;
}

const char *drift_knob_family_title(const char *family)
{
    for (int f = 0; f < FAMILY_COUNT; ++f) {
        if (family && strcmp(families[f]->name, family) == 0) {
            return families[f]->title;
        }
    }
    return NULL;
}

double drift_knob_value(const drift_hybrid_params *params, int index)
{
    const drift_knob *k = drift_knob_get(index);
    if (!k || !params) {
        return 0.0;
    }
    const char *field = (const char *)params + k->offset;
    switch (k->store) {
    case DRIFT_KNOB_STORE_I32: {
        int32_t v;
        memcpy(&v, field, sizeof v);
        return (double)v;
    }
    case DRIFT_KNOB_STORE_U32: {
        uint32_t v;
        memcpy(&v, field, sizeof v);
        return (double)v;
    }
    case DRIFT_KNOB_STORE_F32: {
        float v;
        memcpy(&v, field, sizeof v);
        return (double)v;
    }
    case DRIFT_KNOB_STORE_BOOL:
        return *(const bool *)field ? 1.0 : 0.0;
    }
    return 0.0;
}

// The index of choice value `value`, or -1.
static int choice_of_value(const drift_knob *k, double value)
{
    int index = 0;
    for (const char *p = k->choices; p; ++index) {
        double v = k->choice_values ? (double)k->choice_values[index] : (double)index;
        if (v == value) {
            return index;
        }
        p = strchr(p, '|');
        p = p ? p + 1 : NULL;
    }
    return -1;
}

static bool value_valid(const drift_knob *k, double value)
{
    if (!isfinite(value)) {
        return false;
    }
    if (value == 0.0 && (k->flags & DRIFT_KNOB_AUTO)) {
        return true;
    }
    switch (k->type) {
    case DRIFT_KNOB_INT: {
        if (value != floor(value) || value < k->lo || value > k->hi) {
            return false;
        }
        if (k->flags & DRIFT_KNOB_SQUARE) {
            double root = floor(sqrt(value) + 0.5);
            return root * root == value;
        }
        return true;
    }
    case DRIFT_KNOB_NUMBER:
        return value >= k->lo && value <= k->hi;
    case DRIFT_KNOB_CHOICE:
        return choice_of_value(k, value) >= 0;
    }
    return false;
}

bool drift_knob_set(drift_hybrid_params *params, int index, double value)
{
    const drift_knob *k = drift_knob_get(index);
    if (!k || !params || !value_valid(k, value)) {
        return false;
    }
    char *field = (char *)params + k->offset;
    switch (k->store) {
    case DRIFT_KNOB_STORE_I32: {
        int32_t v = (int32_t)value;
        memcpy(field, &v, sizeof v);
        break;
    }
    case DRIFT_KNOB_STORE_U32: {
        uint32_t v = (uint32_t)value;
        memcpy(field, &v, sizeof v);
        break;
    }
    case DRIFT_KNOB_STORE_F32: {
        float v = (float)value;
        memcpy(field, &v, sizeof v);
        break;
    }
    case DRIFT_KNOB_STORE_BOOL:
        *(bool *)field = value != 0.0;
        break;
    }
    return true;
}

bool drift_knob_parse(const drift_knob *k, const char *text, double *out_value)
{
    if (!k || !text || !out_value) {
        return false;
    }
    if ((k->flags & DRIFT_KNOB_AUTO) && strcmp(text, "auto") == 0) {
        *out_value = 0.0;
        return true;
    }
    double value = 0.0;
    if (k->type == DRIFT_KNOB_CHOICE) {
        size_t len = strlen(text);
        int index = 0;
        bool found = false;
        for (const char *p = k->choices; p && !found; ++index) {
            const char *end = strchr(p, '|');
            size_t n = end ? (size_t)(end - p) : strlen(p);
            if (n == len && strncmp(p, text, n) == 0) {
                value = k->choice_values ? (double)k->choice_values[index] : (double)index;
                found = true;
            }
            p = end ? end + 1 : NULL;
        }
        if (!found) {
            return false;
        }
    } else {
        char *end = NULL;
        value = strtod(text, &end);
        if (end == text || *end != '\0' || (value == 0.0 && (k->flags & DRIFT_KNOB_AUTO))) {
            return false; // auto is spelled "auto"
        }
    }
    if (!value_valid(k, value)) {
        return false;
    }
    *out_value = value;
    return true;
}

int drift_knob_format(const drift_knob *k, double value, char *out, size_t size)
{
    if (!k) {
        return snprintf(out, size, "?");
    }
    if (value == 0.0 && (k->flags & DRIFT_KNOB_AUTO)) {
        return snprintf(out, size, "auto");
    }
    if (k->type == DRIFT_KNOB_CHOICE) {
        int index = choice_of_value(k, value);
        const char *p = k->choices;
        for (int i = 0; p && i < index; ++i) {
            p = strchr(p, '|');
            p = p ? p + 1 : NULL;
        }
        if (index < 0 || !p) {
            return snprintf(out, size, "?");
        }
        const char *end = strchr(p, '|');
        return snprintf(out, size, "%.*s", (int)(end ? (size_t)(end - p) : strlen(p)), p);
    }
    return snprintf(out, size, "%.9g", value);
}

double drift_knob_step(const drift_knob *k, double value, int direction)
{
    if (!k || direction == 0) {
        return value;
    }
    bool up = direction > 0;
    if ((k->flags & DRIFT_KNOB_AUTO) && value == 0.0) {
        return up ? k->lo : value;
    }
    double next = value;
    if (k->type == DRIFT_KNOB_CHOICE) {
        int index = choice_of_value(k, value), count = 1;
        for (const char *p = k->choices; (p = strchr(p, '|')) != NULL; ++p) {
            ++count;
        }
        int to = index + (up ? 1 : -1);
        if (index < 0 || to < 0 || to >= count) {
            return value;
        }
        return k->choice_values ? (double)k->choice_values[to] : (double)to;
    }
    if (k->flags & DRIFT_KNOB_SQUARE) {
        double root = floor(sqrt(value) + 0.5);
        next = up ? (root * 2.0) * (root * 2.0) : floor(root / 2.0) * floor(root / 2.0);
        next = next < 1.0 ? 1.0 : next;
        while (next > k->hi) {
            root = floor(sqrt(next)) - 1.0;
            next = root * root;
        }
    } else if (k->type == DRIFT_KNOB_INT && k->hi - k->lo <= 16.0) {
        next = value + (up ? 1.0 : -1.0);
    } else if (k->type == DRIFT_KNOB_INT) {
        next = up ? value * 2.0 : floor(value / 2.0);
    } else {
        next = up ? value * 2.0 : value * 0.5;
    }
    if (next < k->lo) {
        next = (k->flags & DRIFT_KNOB_AUTO) && value == k->lo ? 0.0 : k->lo;
    }
    next = next > k->hi ? k->hi : next;
    return value_valid(k, next) ? next : value;
}

int drift_knob_expects(const drift_knob *k, char *out, size_t size)
{
    if (!k) {
        return snprintf(out, size, "?");
    }
    const char *auto_text = (k->flags & DRIFT_KNOB_AUTO) ? "auto or " : "";
    switch (k->type) {
    case DRIFT_KNOB_INT:
        return snprintf(out, size, "%s%s in [%.9g, %.9g]", auto_text,
                        (k->flags & DRIFT_KNOB_SQUARE) ? "a perfect square" : "an integer", k->lo,
                        k->hi);
    case DRIFT_KNOB_NUMBER:
        return snprintf(out, size, "%sa number in [%.9g, %.9g]", auto_text, k->lo, k->hi);
    case DRIFT_KNOB_CHOICE: {
        size_t n = 0;
        for (const char *p = k->choices; p;) {
            const char *end = strchr(p, '|');
            size_t len = end ? (size_t)(end - p) : strlen(p);
            const char *next = end ? strchr(end + 1, '|') : NULL;
            n += (size_t)snprintf(n < size ? out + n : NULL, n < size ? size - n : 0, "%.*s%s",
                                  (int)len, p,
                                  !end   ? ""
                                  : next ? ", "
                                         : " or ");
            p = end ? end + 1 : NULL;
        }
        return (int)n;
    }
    }
    return 0;
}

int drift_technique_default(drift_effect effect)
{
    return (unsigned)effect < DRIFT_EFFECT_COUNT ? default_techniques[effect] : -1;
}

drift_hybrid_params drift_hybrid_params_default(void)
{
    drift_hybrid_params p = { .max_depth = 8 };
    for (int e = 0; e < DRIFT_EFFECT_COUNT; ++e) {
        p.techniques[e] = default_techniques[e];
    }
    for (int i = 0, n = drift_knob_count(); i < n; ++i) {
        drift_knob_set(&p, i, drift_knob_get(i)->def);
    }
    return p;
}
