// Mitsuba 3 scenes beside 0.6 (scene_mitsuba_xml.h): the element tree of a v3 file is brought
// to the 0.6 form scene_mitsuba.c maps onto drift, so that one reader serves both and a v3
// scene renders as its 0.6 twin (tests/cli/test_mitsuba3.sh). The mapping table is in
// docs/scene-format.md ("Mitsuba 3").
#include "scene_io_internal.h"
#include "scene_mitsuba_xml.h"

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

// The Mitsuba elements and plugin types scene_mitsuba.c and this file turn into drift's
// (docs/reference/ scene-formats.md prints this table; docs/scene-format.md gives each parameter).
const drift__format_row drift__mitsuba_plugins[] = {
    { "sensor perspective, thinlens", "the camera: fov, fovAxis, toWorld; its film's size" },
    { "shape obj, ply", "imported through assimp with toWorld; faceNormals" },
    { "shape rectangle, cube", "[−1, 1]² in z = 0 (uv 0..1), [−1, 1]³, transformed" },
    { "shape sphere", "with an area emitter: a sphere light; else 32 × 16 facets" },
    { "bsdf diffuse", "diffuse of reflectance (rgb, spectrum or bitmap)" },
    { "bsdf plastic, roughplastic", "GGX plastic: diffuseReflectance, alpha, intIOR / extIOR" },
    { "bsdf conductor, roughconductor", "GGX conductor of the named metal, or a mirror" },
    { "bsdf dielectric, thindielectric, roughdielectric", "GGX dielectric that refracts" },
    { "bsdf twosided", "its inner bsdf" },
    { "bsdf mask", "its inner bsdf, stochastic transparency of opacity (number or bitmap)" },
    { "bsdf principled (Mitsuba 3)", "roughplastic of base_color, alpha = roughness², warns" },
    { "emitter area", "the shape's material emits radiance" },
    { "emitter point, spot, directional", "point, spot (cutoffAngle, beamWidth), directional" },
    { "emitter constant, envmap; background", "constant or lat-long environment" },
    { "integrator; sunsky, sun, sky, media", "skipped (integrator silently)" },
    { "default (Mitsuba 3)", "$name substituted in any attribute" },
};
const size_t drift__mitsuba_plugin_count =
    sizeof drift__mitsuba_plugins / sizeof *drift__mitsuba_plugins;

// Mitsuba 3 (and 2) property names and their Mitsuba 0.6 spelling.
static const char *const renamed[][2] = {
    { "to_world", "toWorld" },
    { "fov_axis", "fovAxis" },
    { "face_normals", "faceNormals" },
    { "flip_normals", "flipNormals" },
    { "cutoff_angle", "cutoffAngle" },
    { "beam_width", "beamWidth" },
    { "diffuse_reflectance", "diffuseReflectance" },
    { "specular_reflectance", "specularReflectance" },
    { "specular_transmittance", "specularTransmittance" },
    { "int_ior", "intIOR" },
    { "ext_ior", "extIOR" },
    { "max_depth", "maxDepth" },
    { "sample_count", "sampleCount" },
    { "near_clip", "nearClip" },
    { "far_clip", "farClip" },
    { "focus_distance", "focusDistance" },
    { "aperture_radius", "apertureRadius" },
    { "base_color", "diffuseReflectance" }, // principled, read as roughplastic (below)
};

typedef struct param {
    const char *name, *value; // borrowed from the <default> element
} param;

typedef struct normalizer {
    drift_context *ctx;
    const char *path;
    param params[64];
    int param_count;
    bool v3; // version 2 or 3: snake_case names and "x, y, z" values
} normalizer;

static drift_result fail(const normalizer *z, const xml_node *n, const char *what,
                         const char *detail)
{
    drift_log(z->ctx, DRIFT_LOG_ERROR, DRIFT_ERR_PARSE, z->path, n->line, "%s%s%s", what,
              detail ? ": " : "", detail ? detail : "");
    return DRIFT_ERR_PARSE;
}

static char **find_attr(xml_node *n, const char *key)
{
    for (char **a = n->attrs; a && a[0] && a[1]; a += 2) {
        if (strcmp(a[0], key) == 0) {
            return &a[1];
        }
    }
    return NULL;
}

static char *copy(drift_context *ctx, const char *s, size_t n)
{
    char *d = drift_alloc(ctx, n + 1);
    if (d) {
        memcpy(d, s, n);
        d[n] = '\0';
    }
    return d;
}

// Sets attribute key of n to value (replacing it, or adding it).
static drift_result set_attr(drift_context *ctx, xml_node *n, const char *key, const char *value)
{
    char *v = copy(ctx, value, strlen(value));
    if (!v) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    char **slot = find_attr(n, key);
    if (slot) {
        drift_free(ctx, *slot);
        *slot = v;
        return DRIFT_OK;
    }
    size_t count = 0;
    while (n->attrs && n->attrs[count]) {
        ++count;
    }
    char *k = copy(ctx, key, strlen(key));
    char **grown =
        drift_realloc(ctx, n->attrs, (count + 1) * sizeof(char *), (count + 3) * sizeof(char *));
    if (!k || !grown) {
        drift_free(ctx, k);
        drift_free(ctx, v);
        if (grown) {
            n->attrs = grown;
        }
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    grown[count] = k;
    grown[count + 1] = v;
    grown[count + 2] = NULL;
    n->attrs = grown;
    return DRIFT_OK;
}

static void remove_attr(drift_context *ctx, xml_node *n, const char *key)
{
    for (char **a = n->attrs; a && a[0] && a[1]; a += 2) {
        if (strcmp(a[0], key) == 0) {
            drift_free(ctx, a[0]);
            drift_free(ctx, a[1]);
            for (char **b = a; b[0]; b += 2) { // move the later pairs (and the NULL) down
                b[0] = b[2];
                if (!b[2]) {
                    break;
                }
                b[1] = b[3];
            }
            return;
        }
    }
}

// Every $name in *value replaced by its <default>'s value.
static drift_result substitute(normalizer *z, xml_node *n, char **value)
{
    if (!strchr(*value, '$')) {
        return DRIFT_OK;
    }
    char out[4096];
    size_t len = 0;
    for (const char *p = *value; *p;) {
        if (*p != '$') {
            if (len + 1 >= sizeof out) {
                return fail(z, n, "attribute too long after $ substitution", NULL);
            }
            out[len++] = *p++;
            continue;
        }
        const char *start = ++p;
        while (isalnum((unsigned char)*p) || *p == '_') {
            ++p;
        }
        char name[128];
        snprintf(name, sizeof name, "%.*s", (int)(p - start), start);
        const char *v = NULL;
        for (int i = 0; i < z->param_count && !v; ++i) {
            v = strcmp(z->params[i].name, name) == 0 ? z->params[i].value : NULL;
        }
        if (!v) {
            return fail(z, n, "no <default> gives the parameter", name);
        }
        size_t vl = strlen(v);
        if (len + vl >= sizeof out) {
            return fail(z, n, "attribute too long after $ substitution", NULL);
        }
        memcpy(out + len, v, vl);
        len += vl;
    }
    char *fresh = copy(z->ctx, out, len);
    if (!fresh) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    drift_free(z->ctx, *value);
    *value = fresh;
    return DRIFT_OK;
}

// value="x, y, z" (v3) as the x, y and z attributes of 0.6.
static drift_result split_xyz(normalizer *z, xml_node *n)
{
    char **value = find_attr(n, "value");
    if (!value) {
        return DRIFT_OK;
    }
    double v[3];
    int count = 0;
    for (const char *p = *value; *p && count < 4;) {
        while (*p == ',' || isspace((unsigned char)*p)) {
            ++p;
        }
        if (!*p) {
            break;
        }
        char *end = NULL;
        double d = strtod(p, &end);
        if (end == p || !isfinite(d) || count == 3) {
            return count == 3 ? fail(z, n, "expected at most three numbers in value=", *value)
                              : fail(z, n, "expected numbers in value=", *value);
        }
        v[count++] = d;
        p = end;
    }
    bool scale = strcmp(n->name, "scale") == 0;
    if (count == 1 && scale) {
        return DRIFT_OK; // a uniform scale: 0.6 reads value= too
    }
    if (count != 3) {
        return fail(z, n, "expected three numbers in value=", *value);
    }
    const char *keys[3] = { "x", "y", "z" };
    drift_result r = DRIFT_OK;
    for (int k = 0; k < 3 && r == DRIFT_OK; ++k) {
        char text[64];
        snprintf(text, sizeof text, "%.9g", v[k]);
        r = set_attr(z->ctx, n, keys[k], text);
    }
    if (r == DRIFT_OK && scale) { // 0.6 reads value= as a uniform scale: drop it
        remove_attr(z->ctx, n, "value");
    }
    return r;
}

// A principled BSDF's roughness r as roughplastic's alpha = r² (the Disney/GGX convention).
static drift_result principled(normalizer *z, xml_node *bsdf)
{
    drift_result r = set_attr(z->ctx, bsdf, "type", "roughplastic");
    for (xml_node *c = bsdf->first; c && r == DRIFT_OK; c = c->next) {
        char **name = find_attr(c, "name");
        char **value = find_attr(c, "value");
        if (name && value && strcmp(*name, "roughness") == 0) {
            double rough = strtod(*value, NULL);
            char text[64];
            snprintf(text, sizeof text, "%.9g", rough * rough);
            if ((r = set_attr(z->ctx, c, "name", "alpha")) == DRIFT_OK) {
                r = set_attr(z->ctx, c, "value", text);
            }
        }
    }
    if (r == DRIFT_OK) {
        drift_log(z->ctx, DRIFT_LOG_WARNING, DRIFT_ERR_UNSUPPORTED, z->path, bsdf->line,
                  "<bsdf type=principled> read as roughplastic (base_color, roughness); its "
                  "metallic, specular and other parameters are ignored");
    }
    return r;
}

static drift_result visit(normalizer *z, xml_node *n)
{
    drift_result r = DRIFT_OK;
    bool is_default = strcmp(n->name, "default") == 0; // its value is what others borrow
    for (char **a = n->attrs; !is_default && r == DRIFT_OK && a && a[0] && a[1]; a += 2) {
        r = substitute(z, n, &a[1]);
    }
    if (r != DRIFT_OK || !z->v3) {
        goto children;
    }
    char **name = find_attr(n, "name");
    for (size_t i = 0; name && i < sizeof renamed / sizeof renamed[0]; ++i) {
        if (strcmp(*name, renamed[i][0]) == 0) {
            r = set_attr(z->ctx, n, "name", renamed[i][1]);
            break;
        }
    }
    const char *el = n->name;
    if (r == DRIFT_OK &&
        (strcmp(el, "point") == 0 || strcmp(el, "vector") == 0 || strcmp(el, "translate") == 0 ||
         strcmp(el, "scale") == 0 || strcmp(el, "rotate") == 0)) {
        r = split_xyz(z, n);
    }
    char **type = find_attr(n, "type");
    if (r == DRIFT_OK && type && strcmp(el, "bsdf") == 0 && strcmp(*type, "principled") == 0) {
        r = principled(z, n);
    }
children:
    for (xml_node *c = n->first; c && r == DRIFT_OK; c = c->next) {
        r = visit(z, c);
    }
    return r;
}

drift_result drift__mitsuba3_normalize(drift_context *ctx, const char *path, xml_node *root)
{
    normalizer z = { .ctx = ctx, .path = path };
    char **version = find_attr(root, "version");
    z.v3 = version && atoi(*version) >= 2;
    // <default name value>: the scene's parameters (a $name before its <default> is fine).
    for (xml_node *c = root->first; c; c = c->next) {
        char **name = find_attr(c, "name");
        char **value = find_attr(c, "value");
        if (strcmp(c->name, "default") != 0) {
            continue;
        }
        if (!name || !value) {
            return fail(&z, c, "<default> needs name= and value=", NULL);
        }
        if (z.param_count == (int)(sizeof z.params / sizeof z.params[0])) {
            return fail(&z, c, "more than 64 <default> parameters", NULL);
        }
        z.params[z.param_count++] = (param){ *name, *value };
    }
    return visit(&z, root);
}
