// glTF's metallic-roughness material and its KHR_materials_transmission, _ior, _specular,
// _volume and _clearcoat extensions onto DRIFT_MATERIAL_GGX (docs/materials.md, "glTF").
#include "drift/image_io.h"
#include "scene_io_internal.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

static float number_at(const cJSON *obj, const char *key, float fallback)
{
    const cJSON *v = obj ? cJSON_GetObjectItemCaseSensitive(obj, key) : NULL;
    return cJSON_IsNumber(v) && isfinite(v->valuedouble) ? (float)v->valuedouble : fallback;
}

static drift_vec3 color_at(const cJSON *obj, const char *key, drift_vec3 fallback)
{
    const cJSON *a = obj ? cJSON_GetObjectItemCaseSensitive(obj, key) : NULL;
    if (!cJSON_IsArray(a) || cJSON_GetArraySize(a) < 3) {
        return fallback;
    }
    float c[3];
    for (int i = 0; i < 3; ++i) {
        const cJSON *v = cJSON_GetArrayItem(a, i);
        if (!cJSON_IsNumber(v) || !isfinite(v->valuedouble)) {
            return fallback;
        }
        c[i] = fmaxf(0.0f, (float)v->valuedouble);
    }
    return drift_vec3_make(c[0], c[1], c[2]);
}

// glTF's sampler enums (OpenGL's).
enum {
    GL_NEAREST = 9728,
    GL_LINEAR = 9729,
    GL_NEAREST_MIPMAP_NEAREST = 9984,
    GL_NEAREST_MIPMAP_LINEAR = 9986,
    GL_CLAMP_TO_EDGE = 33071,
    GL_MIRRORED_REPEAT = 33648,
};

static uint8_t wrap_mode(const cJSON *sampler, const char *key)
{
    float v = number_at(sampler, key, 10497.0f);
    return v == GL_CLAMP_TO_EDGE
               ? DRIFT_WRAP_CLAMP
               : (v == GL_MIRRORED_REPEAT ? DRIFT_WRAP_MIRROR : DRIFT_WRAP_REPEAT);
}

// array[index] for a JSON number index in range, else NULL.
static const cJSON *item(const cJSON *array, const cJSON *index)
{
    if (!cJSON_IsArray(array) || !cJSON_IsNumber(index) || !(index->valuedouble >= 0.0) ||
        index->valuedouble >= (double)cJSON_GetArraySize(array)) {
        return NULL;
    }
    return cJSON_GetArrayItem(array, (int)index->valuedouble);
}

// A textureInfo `ref` of the file whose JSON is root: its image, sampler, texCoord and
// KHR_texture_transform (offset, rotation, scale; its texCoord overrides the reference's).
static void read_texture(const cJSON *root, const cJSON *ref, drift__gltf_texture *out)
{
    *out = (drift__gltf_texture){ .image = -1 };
    if (!cJSON_IsObject(ref)) {
        return;
    }
    out->present = true;
    const cJSON *texture = item(cJSON_GetObjectItemCaseSensitive(root, "textures"),
                                cJSON_GetObjectItemCaseSensitive(ref, "index"));
    const cJSON *source = cJSON_GetObjectItemCaseSensitive(texture, "source");
    const cJSON *image = item(cJSON_GetObjectItemCaseSensitive(root, "images"), source);
    if (image) {
        out->image = source->valueint;
        const cJSON *uri = cJSON_GetObjectItemCaseSensitive(image, "uri");
        if (cJSON_IsString(uri) && strncmp(uri->valuestring, "data:", 5) != 0) {
            snprintf(out->uri, sizeof out->uri, "%s", uri->valuestring);
        }
    }
    drift_texture_map *m = &out->map;
    const cJSON *sampler = item(cJSON_GetObjectItemCaseSensitive(root, "samplers"),
                                cJSON_GetObjectItemCaseSensitive(texture, "sampler"));
    if (sampler) {
        m->wrap_s = wrap_mode(sampler, "wrapS");
        m->wrap_t = wrap_mode(sampler, "wrapT");
        m->mag_nearest = number_at(sampler, "magFilter", GL_LINEAR) == GL_NEAREST;
        float min = number_at(sampler, "minFilter", 0.0f);
        m->min_nearest = min == GL_NEAREST || min == GL_NEAREST_MIPMAP_NEAREST ||
                         min == GL_NEAREST_MIPMAP_LINEAR;
        m->no_mipmaps = min == GL_NEAREST || min == GL_LINEAR;
    }
    out->tex_coord = (int)drift_clampf(number_at(ref, "texCoord", 0.0f), 0.0f, 255.0f);
    const cJSON *ext = cJSON_GetObjectItemCaseSensitive(ref, "extensions");
    const cJSON *tt = cJSON_GetObjectItemCaseSensitive(ext, "KHR_texture_transform");
    if (cJSON_IsObject(tt)) {
        const cJSON *tc = cJSON_GetObjectItemCaseSensitive(tt, "texCoord");
        if (cJSON_IsNumber(tc)) {
            out->tex_coord = (int)drift_clampf((float)tc->valuedouble, 0.0f, 255.0f);
        }
        float offset[2] = { 0.0f, 0.0f }, scale[2] = { 1.0f, 1.0f };
        const cJSON *o = cJSON_GetObjectItemCaseSensitive(tt, "offset");
        const cJSON *sc = cJSON_GetObjectItemCaseSensitive(tt, "scale");
        for (int k = 0; k < 2; ++k) {
            const cJSON *ok = cJSON_IsArray(o) ? cJSON_GetArrayItem(o, k) : NULL;
            const cJSON *sk = cJSON_IsArray(sc) ? cJSON_GetArrayItem(sc, k) : NULL;
            offset[k] =
                cJSON_IsNumber(ok) && isfinite(ok->valuedouble) ? (float)ok->valuedouble : 0.0f;
            scale[k] =
                cJSON_IsNumber(sk) && isfinite(sk->valuedouble) ? (float)sk->valuedouble : 1.0f;
        }
        float r = number_at(tt, "rotation", 0.0f), c = cosf(r), sn = sinf(r);
        // T(offset) R(rotation) S(scale), R as the glTF Sample Viewer and three.js apply it:
        // u' = c u + s v, v' = -s u + c v (docs/materials.md).
        m->has_transform = true;
        m->transform[0] = c * scale[0];
        m->transform[1] = sn * scale[1];
        m->transform[2] = offset[0];
        m->transform[3] = -sn * scale[0];
        m->transform[4] = c * scale[1];
        m->transform[5] = offset[1];
    }
    m->uv_set = out->tex_coord == 1 ? 1 : 0;
}

drift_result drift__data_uri_decode(drift_context *ctx, const char *uri, uint8_t **out_data,
                                    size_t *out_size)
{
    *out_data = NULL;
    *out_size = 0;
    const char *comma = strchr(uri, ',');
    if (strncmp(uri, "data:", 5) != 0 || !comma || (size_t)(comma - uri) < 7 ||
        strncmp(comma - 7, ";base64", 7) != 0) {
        return DRIFT_ERR_PARSE;
    }
    const char *in = comma + 1;
    size_t n = strlen(in);
    uint8_t *out = drift_alloc(ctx, n / 4 * 3 + 3);
    if (!out) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    uint32_t acc = 0;
    int bits = 0;
    size_t size = 0;
    for (size_t i = 0; i < n && in[i] != '='; ++i) {
        char ch = in[i];
        int v = ch >= 'A' && ch <= 'Z'   ? ch - 'A'
                : ch >= 'a' && ch <= 'z' ? ch - 'a' + 26
                : ch >= '0' && ch <= '9' ? ch - '0' + 52
                : ch == '+'              ? 62
                : ch == '/'              ? 63
                                         : -1;
        if (v < 0) {
            drift_free(ctx, out);
            return DRIFT_ERR_PARSE;
        }
        acc = acc << 6 | (uint32_t)v;
        bits += 6;
        if (bits >= 8) {
            bits -= 8;
            out[size++] = (uint8_t)(acc >> bits);
        }
    }
    *out_data = out;
    *out_size = size;
    return DRIFT_OK;
}

// An 8/16-bit image decoded as sRGB by drift_image_load*, back to its stored values (data).
static void undo_srgb(drift_image *image)
{
    for (int32_t y = 0; y < image->height; ++y) {
        float *row = drift_image_pixel(image, 0, y);
        for (int32_t i = 0; i < image->width * image->channels; ++i) {
            row[i] = drift_linear_to_srgb(row[i]);
        }
    }
}

// The image inside the glTF (a .glb's buffer view, a data URI, a buffer file's view) that
// texture t names: its colour, sRGB-decoded, or its alpha.
static drift_result embedded_image(drift_context *ctx, const drift__gltf *g,
                                   const drift__gltf_texture *t, bool alpha, const char *where,
                                   int line, drift_image *out)
{
    uint8_t *bytes = NULL;
    size_t size = 0;
    drift_result r = drift__gltf_image_bytes(ctx, g, t->image, &bytes, &size);
    char name[DRIFT__PATH_MAX];
    snprintf(name, sizeof name, "%s (glTF image %d)", where ? where : "scene", t->image);
    if (r == DRIFT_OK) {
        r = alpha ? drift_image_load_alpha_memory(ctx, name, bytes, size, DRIFT_ALPHA_CHANNEL, out)
                  : drift_image_load_memory(ctx, name, bytes, size, out);
    }
    drift_free(ctx, bytes);
    if (r != DRIFT_OK) {
        drift_image_destroy(ctx, out);
        drift_log(ctx, DRIFT_LOG_WARNING, r, where, line, "cannot read or decode %s", name);
    }
    return r;
}

drift_result drift__gltf_load_texture(drift_scene *scene, const drift__gltf *g,
                                      const drift__gltf_texture *t, const char *dir,
                                      drift__texture_cache *cache, bool srgb, const char *where,
                                      int line, uint32_t *out_index)
{
    if (t->image < 0) {
        return DRIFT_ERR_PARSE;
    }
    if (t->uri[0]) {
        char full[DRIFT__PATH_MAX];
        if (!drift__path_join(dir, t->uri, full, sizeof full)) {
            return DRIFT_ERR_IO;
        }
        return srgb && cache ? drift__texture_cache_get(scene, cache, full, where, line, out_index)
                             : drift__texture_load_data(scene, full, where, line, out_index);
    }
    drift_image image = { 0 };
    drift_result r = embedded_image(scene->ctx, g, t, false, where, line, &image);
    if (r != DRIFT_OK) {
        return r;
    }
    if (!srgb) {
        undo_srgb(&image);
    }
    return drift_scene_add_texture(scene, image, out_index);
}

drift_result drift__gltf_load_alpha(drift_scene *scene, const drift__gltf *g,
                                    const drift__gltf_texture *t, const char *dir,
                                    const char *where, int line, uint32_t *out_index)
{
    if (t->image < 0) {
        return DRIFT_ERR_PARSE;
    }
    drift_image image = { 0 };
    drift_result r;
    if (t->uri[0]) {
        char full[DRIFT__PATH_MAX];
        if (!drift__path_join(dir, t->uri, full, sizeof full)) {
            return DRIFT_ERR_IO;
        }
        size_t size = 0;
        r = drift__check_file(scene->ctx, full, where, line, &size);
        r = r ? r : drift_image_load_alpha(scene->ctx, full, DRIFT_ALPHA_CHANNEL, &image);
    } else {
        r = embedded_image(scene->ctx, g, t, true, where, line, &image);
    }
    return r ? r : drift_scene_add_texture(scene, image, out_index);
}

drift_result drift__texture_load_data(drift_scene *scene, const char *path, const char *where,
                                      int line, uint32_t *out_index)
{
    FILE *probe = fopen(path, "rb"); // a missing image is a warning here, not an error
    if (!probe) {
        drift_log(scene->ctx, DRIFT_LOG_WARNING, DRIFT_ERR_IO, where, line,
                  "cannot open texture '%s'", path);
        return DRIFT_ERR_IO;
    }
    fclose(probe);
    size_t size = 0;
    drift_result r = drift__check_file(scene->ctx, path, where, line, &size);
    drift_image image = { 0 };
    if (r == DRIFT_OK) {
        r = drift_image_load(scene->ctx, path, &image);
    }
    if (r != DRIFT_OK) {
        drift_log(scene->ctx, DRIFT_LOG_WARNING, r, where, line, "cannot load texture '%s'", path);
        return r;
    }
    // drift_image_load decodes 8- and 16-bit files as sRGB; data textures are stored as is.
    const char *dot = strrchr(path, '.');
    bool linear_file = dot && (strcmp(dot, ".exr") == 0 || strcmp(dot, ".hdr") == 0);
    if (!linear_file) {
        undo_srgb(&image);
    }
    return drift_scene_add_texture(scene, image, out_index);
}

void drift__gltf_read_ggx(const cJSON *root, const cJSON *material, drift__gltf_material *out)
{
    const cJSON *pbr = cJSON_GetObjectItemCaseSensitive(material, "pbrMetallicRoughness");
    const cJSON *ext = cJSON_GetObjectItemCaseSensitive(material, "extensions");
    drift_vec3 base = color_at(pbr, "baseColorFactor", drift_vec3_splat(1.0f));
    out->base_color = drift_vec3_min(base, drift_vec3_splat(1.0f));
    drift_ggx_params *g = &out->ggx;
    *g = (drift_ggx_params){ .metallic_roughness_texture = DRIFT_INVALID_INDEX,
                             .normal_texture = DRIFT_INVALID_INDEX,
                             .emissive_texture = DRIFT_INVALID_INDEX,
                             .occlusion_texture = DRIFT_INVALID_INDEX,
                             .clearcoat_texture = DRIFT_INVALID_INDEX,
                             .clearcoat_roughness_texture = DRIFT_INVALID_INDEX };
    g->metallic = drift_clampf(number_at(pbr, "metallicFactor", 1.0f), 0.0f, 1.0f);
    float roughness = drift_clampf(number_at(pbr, "roughnessFactor", 1.0f), 0.0f, 1.0f);
    g->alpha = roughness * roughness;
    const cJSON *transmission = cJSON_GetObjectItemCaseSensitive(ext, "KHR_materials_transmission");
    g->transmission = drift_clampf(number_at(transmission, "transmissionFactor", 0.0f), 0.0f, 1.0f);
    const cJSON *ior = cJSON_GetObjectItemCaseSensitive(ext, "KHR_materials_ior");
    g->ior = drift_clampf(number_at(ior, "ior", 1.5f), 1.0f, 10.0f);
    // F0 = ((ior - 1) / (ior + 1))^2 specularColorFactor specularFactor (capped at 1 per
    // channel when the material is evaluated).
    const cJSON *specular = cJSON_GetObjectItemCaseSensitive(ext, "KHR_materials_specular");
    if (specular) {
        float factor = drift_clampf(number_at(specular, "specularFactor", 1.0f), 0.0f, 1.0f);
        drift_vec3 color = color_at(specular, "specularColorFactor", drift_vec3_splat(1.0f));
        g->specular_tint = drift_vec3_scale(color, factor);
        if (drift_vec3_is_zero(g->specular_tint)) {
            g->specular_tint = drift_vec3_splat(1e-6f); // zero means "untinted" to drift
        }
    }
    // KHR_materials_volume of thickness 0 is thin-walled. Without the extension the glTF
    // specification says thin-walled too, but Blender exports its solid glass so and imports
    // it back as solid: drift follows Blender there (docs/materials.md).
    const cJSON *volume = cJSON_GetObjectItemCaseSensitive(ext, "KHR_materials_volume");
    g->thin = volume && !(number_at(volume, "thicknessFactor", 0.0f) > 0.0f);
    // KHR_materials_clearcoat: factor and perceptual roughness (defaults 0), each multiplied by
    // its texture's R / G channel. The coat's own normal map is not read: the coat follows the
    // base's shading normal (docs/materials.md "Clear coat").
    const cJSON *clearcoat = cJSON_GetObjectItemCaseSensitive(ext, "KHR_materials_clearcoat");
    g->clearcoat = drift_clampf(number_at(clearcoat, "clearcoatFactor", 0.0f), 0.0f, 1.0f);
    float coat_roughness =
        drift_clampf(number_at(clearcoat, "clearcoatRoughnessFactor", 0.0f), 0.0f, 1.0f);
    g->clearcoat_alpha = coat_roughness * coat_roughness;
    g->clearcoat_principled = DRIFT_GLTF_CLEARCOAT_PRINCIPLED;
    out->has_clearcoat_normal =
        cJSON_GetObjectItemCaseSensitive(clearcoat, "clearcoatNormalTexture") != NULL;
    const cJSON *normal = cJSON_GetObjectItemCaseSensitive(material, "normalTexture");
    const cJSON *occlusion = cJSON_GetObjectItemCaseSensitive(material, "occlusionTexture");
    const cJSON *refs[DRIFT_TEXTURE_SLOT_COUNT] = {
        [DRIFT_TEXTURE_BASE] = cJSON_GetObjectItemCaseSensitive(pbr, "baseColorTexture"),
        [DRIFT_TEXTURE_METALLIC_ROUGHNESS] =
            cJSON_GetObjectItemCaseSensitive(pbr, "metallicRoughnessTexture"),
        [DRIFT_TEXTURE_NORMAL] = normal,
        [DRIFT_TEXTURE_EMISSIVE] = cJSON_GetObjectItemCaseSensitive(material, "emissiveTexture"),
        [DRIFT_TEXTURE_OCCLUSION] = occlusion,
        [DRIFT_TEXTURE_CLEARCOAT] = cJSON_GetObjectItemCaseSensitive(clearcoat, "clearcoatTexture"),
        [DRIFT_TEXTURE_CLEARCOAT_ROUGHNESS] =
            cJSON_GetObjectItemCaseSensitive(clearcoat, "clearcoatRoughnessTexture"),
    };
    for (int k = 0; k < DRIFT_TEXTURE_SLOT_COUNT; ++k) {
        read_texture(root, refs[k], &out->textures[k]);
    }
    out->normal_scale = number_at(normal, "scale", 1.0f);
    out->occlusion_strength = drift_clampf(number_at(occlusion, "strength", 1.0f), 0.0f, 1.0f);
}

void drift__gltf_material_apply(drift_scene *scene, const drift__gltf *gltf,
                                const drift__gltf_material *gm, const char *dir,
                                drift__texture_cache *cache, const char *path, const char *where,
                                int line, drift_material *m)
{
    // GGX metallic-roughness (material_gltf.c); the base colour texture multiplies `diffuse`.
    m->type = DRIFT_MATERIAL_GGX;
    m->diffuse = gm->base_color;
    m->ggx = gm->ggx;
    m->emission = gm->emission;
    m->emission_two_sided = gm->double_sided;
    // The diffuse of Blender's Principled BSDF (Cycles 3.4), the reference of glTF scenes here.
    m->diffuse_model = DRIFT_DIFFUSE_BURLEY;
    m->diffuse_roughness = sqrtf(gm->ggx.alpha);
    for (int k = 0; k < DRIFT_TEXTURE_SLOT_COUNT; ++k) {
        m->maps[k] = gm->textures[k].map;
        if (gm->textures[k].present && gm->textures[k].tex_coord > 1) {
            drift_log(scene->ctx, DRIFT_LOG_WARNING, DRIFT_ERR_UNSUPPORTED, where, line,
                      "'%s': material '%s': texCoord %d read as 0 (drift reads uv sets 0 and 1)",
                      path, m->name, gm->textures[k].tex_coord);
        }
    }

    // The base colour comes through assimp (material_texture); the others from the JSON.
    struct {
        drift_texture_slot slot;
        bool srgb;
        uint32_t *index;
        const char *what;
    } loads[] = {
        { DRIFT_TEXTURE_METALLIC_ROUGHNESS, false, &m->ggx.metallic_roughness_texture,
          "metallic-roughness texture (its factors are used)" },
        { DRIFT_TEXTURE_NORMAL, false, &m->ggx.normal_texture, "normal texture" },
        { DRIFT_TEXTURE_EMISSIVE, true, &m->ggx.emissive_texture,
          "emissive texture (its factor is used)" },
        { DRIFT_TEXTURE_OCCLUSION, false, &m->ggx.occlusion_texture, "occlusion texture" },
        { DRIFT_TEXTURE_CLEARCOAT, false, &m->ggx.clearcoat_texture,
          "clearcoat texture (its factor is used)" },
        { DRIFT_TEXTURE_CLEARCOAT_ROUGHNESS, false, &m->ggx.clearcoat_roughness_texture,
          "clearcoat roughness texture (its factor is used)" },
    };

    for (size_t k = 0; k < sizeof loads / sizeof loads[0]; ++k) {
        const drift__gltf_texture *t = &gm->textures[loads[k].slot];
        uint32_t index;
        if (!t->present) {
            continue;
        }
        if (drift__gltf_load_texture(scene, gltf, t, dir, cache, loads[k].srgb, where, line,
                                     &index) == DRIFT_OK) {
            *loads[k].index = index;
        } else {
            drift_log(scene->ctx, DRIFT_LOG_WARNING, DRIFT_ERR_UNSUPPORTED, where, line,
                      "'%s': material '%s': %s not loaded; ignored", path, m->name, loads[k].what);
        }
    }
    // Coverage: the base colour image's alpha times baseColorFactor's; where the alpha cannot
    // be read the factor alone holds (a warning says so).
    m->alpha_mode = gm->alpha_mode;
    m->alpha_cutoff = gm->alpha_cutoff;
    m->opacity = gm->opacity;
    m->opacity_texture = DRIFT_INVALID_INDEX;
    const drift__gltf_texture *base = &gm->textures[DRIFT_TEXTURE_BASE];
    if (m->alpha_mode != DRIFT_ALPHA_OPAQUE && base->present &&
        drift__gltf_load_alpha(scene, gltf, base, dir, where, line, &m->opacity_texture) !=
            DRIFT_OK) {
        m->opacity_texture = DRIFT_INVALID_INDEX;
        drift_log(scene->ctx, DRIFT_LOG_WARNING, DRIFT_ERR_UNSUPPORTED, where, line,
                  "'%s': material '%s': base colour alpha not loaded; its factor alone is used",
                  path, m->name);
    }
    m->ggx.normal_scale = gm->normal_scale;
    m->ggx.occlusion_strength = gm->occlusion_strength;
    if (m->ggx.emissive_texture != DRIFT_INVALID_INDEX && drift_vec3_is_zero(m->emission)) {
        // glTF multiplies the texture by emissiveFactor (default 0): nothing to emit.
        m->ggx.emissive_texture = DRIFT_INVALID_INDEX;
    }

    const struct {
        bool present;
        const char *what;
    } ignored[] = {
        { gm->has_clearcoat_normal,
          "clearcoat normal texture (the coat follows the base's shading normal)" },
    };

    for (size_t k = 0; k < sizeof(ignored) / sizeof(ignored[0]); ++k) {
        if (ignored[k].present) {
            drift_log(scene->ctx, DRIFT_LOG_WARNING, DRIFT_ERR_UNSUPPORTED, where, line,
                      "'%s': material '%s': %s ignored", path, m->name, ignored[k].what);
        }
    }
}
