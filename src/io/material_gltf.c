// glTF's metallic-roughness material and its KHR_materials_transmission, _ior, _specular and
// _volume extensions onto DRIFT_MATERIAL_GGX (docs/materials.md, "glTF").
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

// The uri of the image that texture reference `ref` ({"index": i, ...}) shows, or NULL.
static const char *texture_uri(const cJSON *root, const cJSON *ref)
{
    const cJSON *index = cJSON_GetObjectItemCaseSensitive(ref, "index");
    if (!cJSON_IsNumber(index)) {
        return NULL;
    }
    const cJSON *texture =
        cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(root, "textures"), index->valueint);
    const cJSON *source = cJSON_GetObjectItemCaseSensitive(texture, "source");
    if (!cJSON_IsNumber(source)) {
        return NULL;
    }
    const cJSON *image =
        cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(root, "images"), source->valueint);
    const cJSON *uri = cJSON_GetObjectItemCaseSensitive(image, "uri");
    return cJSON_IsString(uri) && strncmp(uri->valuestring, "data:", 5) != 0 ? uri->valuestring
                                                                             : NULL;
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
    for (int32_t y = 0; y < image.height && !linear_file; ++y) {
        float *row = drift_image_pixel(&image, 0, y);
        for (int32_t i = 0; i < image.width * image.channels; ++i) {
            row[i] = drift_linear_to_srgb(row[i]);
        }
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
                             .normal_texture = DRIFT_INVALID_INDEX };
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
    out->has_clearcoat = cJSON_GetObjectItemCaseSensitive(ext, "KHR_materials_clearcoat") != NULL;
    const cJSON *mr = cJSON_GetObjectItemCaseSensitive(pbr, "metallicRoughnessTexture");
    const char *uri = texture_uri(root, mr);
    snprintf(out->metallic_roughness_uri, sizeof(out->metallic_roughness_uri), "%s",
             uri ? uri : "");
    const cJSON *normal = cJSON_GetObjectItemCaseSensitive(material, "normalTexture");
    uri = texture_uri(root, normal);
    snprintf(out->normal_uri, sizeof(out->normal_uri), "%s", uri ? uri : "");
    out->normal_scale = number_at(normal, "scale", 1.0f);
    out->metallic_roughness_uv_set = (int)drift_clampf(number_at(mr, "texCoord", 0.0f), 0.0f, 7.0f);
}
