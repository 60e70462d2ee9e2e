// glTF's metallic-roughness material and its KHR_materials_transmission, _ior, _specular and
// _volume extensions onto DRIFT_MATERIAL_GGX (docs/materials.md, "glTF").
#include "scene_io_internal.h"

#include <cjson/cJSON.h>
#include <math.h>

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

void drift__gltf_read_ggx(const cJSON *material, drift__gltf_material *out)
{
    const cJSON *pbr = cJSON_GetObjectItemCaseSensitive(material, "pbrMetallicRoughness");
    const cJSON *ext = cJSON_GetObjectItemCaseSensitive(material, "extensions");
    drift_vec3 base = color_at(pbr, "baseColorFactor", drift_vec3_splat(1.0f));
    out->base_color = drift_vec3_min(base, drift_vec3_splat(1.0f));
    drift_ggx_params *g = &out->ggx;
    *g = (drift_ggx_params){ .metallic_roughness_texture = DRIFT_INVALID_INDEX };
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
    // Without KHR_materials_volume (or with thickness 0) glTF's transmission is thin-walled.
    const cJSON *volume = cJSON_GetObjectItemCaseSensitive(ext, "KHR_materials_volume");
    g->thin = !(number_at(volume, "thicknessFactor", 0.0f) > 0.0f);
    out->has_clearcoat = cJSON_GetObjectItemCaseSensitive(ext, "KHR_materials_clearcoat") != NULL;
}
