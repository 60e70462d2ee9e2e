// Mitsuba's BSDFs onto drift's materials (scene_mitsuba.c reads the rest of the scene): the
// mapping table is docs/scene-format.md's "Mitsuba" section.
#include "drift/image_io.h"
#include "scene_mitsuba_internal.h"

#include <math.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

static float ior_value(mitsuba_state *s, const xml_node *b, const char *name, float fallback)
{
    static const struct {
        const char *name;
        float ior;
    } named[] = { { "vacuum", 1.0f },         { "air", 1.000277f },  { "water", 1.333f },
                  { "bk7", 1.5046f },         { "glass", 1.5046f },  { "acrylic glass", 1.49f },
                  { "polypropylene", 1.49f }, { "diamond", 2.419f }, { "fused quartz", 1.458f },
                  { "sapphire", 1.77f },      { "ethanol", 1.361f }, { "pyrex", 1.47f } };

    const xml_node *p = drift__mts_property(b, name);
    const char *v = p ? drift__mts_attr(p, "value") : NULL;
    float f;
    if (!v) {
        return fallback;
    }
    if (drift__mts_parse_numbers(v, &f, 1) == 1 && f >= 1.0f && f <= 10.0f) {
        return f;
    }
    for (size_t i = 0; i < sizeof(named) / sizeof(named[0]); ++i) {
        if (strcmp(v, named[i].name) == 0) {
            return named[i].ior;
        }
    }
    drift__mts_warn(s, p, "is an IOR drift does not know (the default used)");
    return fallback;
}

static float mitsuba_ior(mitsuba_state *s, const xml_node *b, float int_fallback)
{
    float ior = ior_value(s, b, "intIOR", int_fallback) / ior_value(s, b, "extIOR", 1.000277f);
    return drift_clampf(ior, 1.0f, 10.0f);
}

static drift_result diffuse_texture(mitsuba_state *s, const xml_node *bsdf, const char *name,
                                    drift_material *m)
{
    const xml_node *t = drift__mts_property(bsdf, name);
    if (!t || strcmp(t->name, "texture") != 0) {
        return DRIFT_OK;
    }
    const xml_node *file = drift__mts_property(t, "filename");
    const char *rel = file ? drift__mts_attr(file, "value") : NULL;
    char full[DRIFT__PATH_MAX];
    uint32_t index;
    // Scenes often ship without their textures: a missing file is a warning, not an error.
    struct stat st;
    if (!rel || !drift__path_join(s->dir, rel, full, sizeof(full)) || stat(full, &st) != 0 ||
        drift__texture_cache_get(s->scene, s->textures, full, s->path, t->line, &index) !=
            DRIFT_OK) {
        drift_log(s->ctx, DRIFT_LOG_WARNING, DRIFT_ERR_IO, s->path, t->line,
                  "texture '%s' not loaded; using grey 0.5", rel ? rel : "(no filename)");
        m->diffuse = drift_vec3_splat(0.5f);
        return DRIFT_OK;
    }
    m->diffuse_texture = index;
    m->diffuse = drift_vec3_splat(1.0f);
    return DRIFT_OK;
}

// A mask's `opacity`: <float value> in [0, 1], or <texture type="bitmap"> whose grey value
// (its alpha where it has one) is the opacity; a bitmap that cannot be read is a warning and
// leaves the surface opaque.
static drift_result mask_opacity(mitsuba_state *s, const xml_node *b, drift_material *m)
{
    const xml_node *p = drift__mts_property(b, "opacity");
    m->alpha_mode = DRIFT_ALPHA_BLEND;
    m->opacity = 0.5f; // Mitsuba's default
    if (p && strcmp(p->name, "texture") == 0) {
        const xml_node *file = drift__mts_property(p, "filename");
        const char *rel = file ? drift__mts_attr(file, "value") : NULL;
        char full[DRIFT__PATH_MAX];
        size_t size = 0;
        drift_image image = { 0 };
        drift_result r =
            rel && drift__path_join(s->dir, rel, full, sizeof full) ? DRIFT_OK : DRIFT_ERR_IO;
        r = r ? r : drift__check_file(s->ctx, full, s->path, p->line, &size);
        r = r ? r : drift_image_load_alpha(s->ctx, full, DRIFT_ALPHA_OR_GREY, &image);
        r = r ? r : drift_scene_add_texture(s->scene, image, &m->opacity_texture);
        if (r != DRIFT_OK) {
            drift_log(s->ctx, DRIFT_LOG_WARNING, r, s->path, p->line,
                      "mask opacity '%s' not loaded; drawn opaque", rel ? rel : "(no filename)");
            m->alpha_mode = DRIFT_ALPHA_OPAQUE;
            m->opacity_texture = DRIFT_INVALID_INDEX;
        }
        m->opacity = 1.0f;
        return DRIFT_OK;
    }
    drift_result r = drift__mts_read_float(s, b, "opacity", 0.5f, &m->opacity);
    if (r == DRIFT_OK && !(m->opacity >= 0.0f && m->opacity <= 1.0f)) {
        return drift__mts_fail(s, p, DRIFT_ERR_PARSE, "mask opacity is not in [0, 1]", NULL);
    }
    return r;
}

// A <bsdf> onto a drift material (docs/scene-format.md, Mitsuba mapping).
static drift_result convert_bsdf(mitsuba_state *s, const xml_node *b, const char *name,
                                 drift_material *m)
{
    const char *type = drift__mts_attr(b, "type");
    if (!type) {
        return drift__mts_fail(s, b, DRIFT_ERR_PARSE, "<bsdf> without a type", NULL);
    }
    if (strcmp(type, "mask") == 0) {
        // Mitsuba's mask blends the nested BSDF with a transparent one by `opacity` (a number,
        // or a bitmap's grey): drift's stochastic coverage (DRIFT_ALPHA_BLEND).
        const xml_node *inner = NULL;
        for (const xml_node *c = b->first; c && !inner; c = c->next) {
            inner = strcmp(c->name, "bsdf") == 0 ? c : NULL;
        }
        if (!inner) {
            return drift__mts_fail(s, b, DRIFT_ERR_PARSE, "mask <bsdf> holds no <bsdf>", NULL);
        }
        drift_result r = convert_bsdf(s, inner, name, m);
        if (r != DRIFT_OK) {
            return r;
        }
        return mask_opacity(s, b, m);
    }
    if (strcmp(type, "twosided") == 0) {
        // drift shades both sides of a surface alike already.
        for (const xml_node *c = b->first; c; c = c->next) {
            if (strcmp(c->name, "bsdf") == 0) {
                return convert_bsdf(s, c, name, m);
            }
        }
        return drift__mts_fail(s, b, DRIFT_ERR_PARSE, "twosided <bsdf> holds no <bsdf>", NULL);
    }
    *m = drift_material_make(drift_vec3_splat(0.5f));
    snprintf(m->name, sizeof(m->name), "%s", name);
    drift_result r = DRIFT_OK;
    float alpha = 0.0f;
    if (strcmp(type, "diffuse") == 0) {
        r = drift__mts_read_color(s, b, "reflectance", drift_vec3_splat(0.5f), &m->diffuse, NULL);
        if (r == DRIFT_OK) {
            r = diffuse_texture(s, b, "reflectance", m);
        }
    } else if (strcmp(type, "plastic") == 0 || strcmp(type, "roughplastic") == 0) {
        // A diffuse base under a dielectric coat of the file's alpha, on GGX (docs/materials.md).
        bool found = false;
        r = drift__mts_read_color(s, b, "diffuseReflectance", drift_vec3_splat(0.5f), &m->diffuse,
                                  &found);
        if (r == DRIFT_OK && !found) {
            r = drift__mts_read_color(s, b, "reflectance", drift_vec3_splat(0.5f), &m->diffuse,
                                      NULL);
        }
        if (r == DRIFT_OK) {
            r = drift__mts_read_float(s, b, "alpha", type[0] == 'r' ? 0.1f : 0.0f, &alpha);
        }
        m->type = DRIFT_MATERIAL_GGX;
        m->ggx.alpha = drift_clampf(alpha, 0.0f, 1.0f);
        m->ggx.ior = mitsuba_ior(s, b, 1.49f);
        if (r == DRIFT_OK) {
            r = diffuse_texture(s, b,
                                drift__mts_property(b, "diffuseReflectance") ? "diffuseReflectance"
                                                                             : "reflectance",
                                m);
            m->diffuse =
                m->diffuse_texture != DRIFT_INVALID_INDEX ? drift_vec3_splat(1.0f) : m->diffuse;
        }
    } else if (strcmp(type, "conductor") == 0 || strcmp(type, "roughconductor") == 0) {
        // A named metal (material=) by its measured complex IOR; otherwise the reflectance
        // specularReflectance (default 0.9) as F0. Smooth conductors without a metal stay mirrors.
        drift_vec3 ks;
        r = drift__mts_read_color(s, b, "specularReflectance", drift_vec3_splat(0.9f), &ks, NULL);
        if (r == DRIFT_OK) {
            r = drift__mts_read_float(s, b, "alpha", type[0] == 'r' ? 0.1f : 0.0f, &alpha);
        }
        const xml_node *metal = drift__mts_property(b, "material");
        const char *metal_name = metal ? drift__mts_attr(metal, "value") : NULL;
        bool named = metal_name && drift_ggx_named_metal(metal_name, &m->ggx);
        if (metal_name && !named && strcmp(metal_name, "none") != 0) {
            drift__mts_warn(
                s, b,
                "names a metal drift has no table for (Au, Ag, Cu, Al); specularReflectance used");
        }
        if (type[0] == 'c' && !named) {
            m->diffuse = drift_vec3_splat(0.0f);
            m->specular = ks;
            m->type = DRIFT_MATERIAL_MIRROR;
        } else {
            m->type = DRIFT_MATERIAL_GGX;
            m->diffuse = ks; // F0 without a named metal
            m->ggx.metallic = 1.0f;
            m->ggx.alpha = drift_clampf(alpha, 0.0f, 1.0f);
        }
    } else if (strcmp(type, "dielectric") == 0 || strcmp(type, "thindielectric") == 0 ||
               strcmp(type, "roughdielectric") == 0) {
        r = drift__mts_read_float(s, b, "alpha", type[0] == 'r' ? 0.1f : 0.0f, &alpha);
        m->type = DRIFT_MATERIAL_GGX;
        m->diffuse = drift_vec3_splat(1.0f);
        m->ggx.transmission = 1.0f;
        m->ggx.alpha = drift_clampf(alpha, 0.0f, 1.0f);
        m->ggx.ior = mitsuba_ior(s, b, 1.5046f);
        m->ggx.thin = type[0] == 't';
    } else {
        drift__mts_warn(s, b, "is not a supported bsdf (grey diffuse 0.5 used)");
    }
    return r;
}

drift_result drift__mts_add_bsdf(mitsuba_state *s, const xml_node *b, uint32_t *out_material)
{
    const char *id = drift__mts_attr(b, "id");
    char name[DRIFT_NAME_MAX];
    if (id) {
        snprintf(name, sizeof(name), "%s", id);
    } else {
        snprintf(name, sizeof(name), "mitsuba#bsdf-line%d", b->line);
    }
    drift_material m;
    drift_result r = convert_bsdf(s, b, name, &m);
    if (r == DRIFT_OK) {
        r = drift_scene_add_material(s->scene, &m, out_material);
        if (r != DRIFT_OK) {
            return drift__mts_fail(s, b, r, "material not valid", name);
        }
    }
    if (r == DRIFT_OK && id) {
        if (s->bsdf_count == s->bsdf_capacity) {
            uint32_t cap = s->bsdf_capacity ? 2 * s->bsdf_capacity : 16;
            named_bsdf *grown = drift_alloc(s->ctx, cap * sizeof(*grown));
            if (!grown) {
                return DRIFT_ERR_OUT_OF_MEMORY;
            }
            if (s->bsdfs) {
                memcpy(grown, s->bsdfs, s->bsdf_count * sizeof(*grown));
            }
            drift_free(s->ctx, s->bsdfs);
            s->bsdfs = grown;
            s->bsdf_capacity = cap;
        }
        s->bsdfs[s->bsdf_count++] = (named_bsdf){ id, *out_material };
    }
    return r;
}

// Adds a triangle mesh from local positions under `world`.
