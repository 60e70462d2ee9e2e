// drift scene files (.json): the "materials" table (see scene_json.c).
#include "drift/image_io.h"
#include "scene_json_internal.h"

#include <cjson/cJSON.h>
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

// --- MATERIALS ---

// Coverage, for every type: "opacity" (default 1) times "opacity_texture" (an image's alpha,
// or its grey value where it has none); "alpha_cutoff" makes it a MASK of that cutoff (glTF's),
// else anything below 1 is a BLEND (stochastic transparency). None of them: opaque.
static drift_result read_coverage(json_reader *r, const cJSON *item, const char *path,
                                  drift_material *m)
{
    float opacity = 1.0f, cutoff = -1.0f;
    const char *rel = NULL;
    drift_result res;
    if ((res = drift__json_read_float(r, item, path, "opacity", false, 0.0, 1.0, &opacity)) !=
            DRIFT_OK ||
        (res = drift__json_read_float(r, item, path, "alpha_cutoff", false, 0.0, 1.0, &cutoff)) !=
            DRIFT_OK ||
        (res = drift__json_read_string(r, item, path, "opacity_texture", false, &rel)) !=
            DRIFT_OK) {
        return res;
    }
    uint32_t texture = DRIFT_INVALID_INDEX;
    if (rel) {
        const cJSON *key = cJSON_GetObjectItemCaseSensitive(item, "opacity_texture");
        char full[DRIFT__PATH_MAX];
        size_t size = 0;
        drift_image image = { 0 };
        int line = drift__json_line_of(r, key);
        if ((res = drift__json_resolve_path(r, key, rel, full)) != DRIFT_OK ||
            (res = drift__check_file(r->scene->ctx, full, r->file, line, &size)) != DRIFT_OK ||
            (res = drift_image_load_alpha(r->scene->ctx, full, DRIFT_ALPHA_OR_GREY, &image)) !=
                DRIFT_OK ||
            (res = drift_scene_add_texture(r->scene, image, &texture)) != DRIFT_OK) {
            return FAIL(r, key, res, "%s.opacity_texture '%s' cannot be loaded", path, rel);
        }
    }
    if (cutoff >= 0.0f) {
        m->alpha_mode = DRIFT_ALPHA_MASK;
        m->alpha_cutoff = cutoff;
    } else if (opacity < 1.0f || texture != DRIFT_INVALID_INDEX) {
        m->alpha_mode = DRIFT_ALPHA_BLEND;
    }
    m->opacity = opacity;
    m->opacity_texture = texture;
    return DRIFT_OK;
}

// type "ggx" (docs/materials.md): diffuse is the base colour; roughness is glTF's perceptual
// roughness (alpha = roughness^2); metal names a measured conductor (and makes it metallic).
static drift_result read_ggx_material(json_reader *r, const cJSON *item, const char *path)
{
    const char *unused = cJSON_HasObjectItem(item, "specular")            ? "specular"
                         : cJSON_HasObjectItem(item, "exponent")          ? "exponent"
                         : cJSON_HasObjectItem(item, "diffuse_roughness") ? "diffuse_roughness"
                                                                          : NULL;
    if (unused) {
        return FAIL(r, cJSON_GetObjectItemCaseSensitive(item, unused), DRIFT_ERR_INVALID_ARGUMENT,
                    "%s: a ggx material takes no '%s'", path, unused);
    }
    drift_material m = drift_material_make(drift_vec3_splat(0.8f));
    snprintf(m.name, sizeof(m.name), "%s", item->string);
    m.type = DRIFT_MATERIAL_GGX;
    float roughness = 0.5f, clearcoat_roughness = 0.0f;
    const char *metal = NULL;
    drift_result res;
    if ((res = drift__json_read_vec3(r, item, path, "diffuse", false, VEC3_COLOR, &m.diffuse)) !=
            DRIFT_OK ||
        (res = drift__json_read_vec3(r, item, path, "emission", false, VEC3_COLOR, &m.emission)) !=
            DRIFT_OK ||
        (res = drift__json_load_texture(r, item, path, "diffuse_texture", &m.diffuse_texture)) !=
            DRIFT_OK ||
        (res = drift__json_read_float(r, item, path, "roughness", false, 0.0, 1.0, &roughness)) !=
            DRIFT_OK ||
        (res = drift__json_read_float(r, item, path, "metallic", false, 0.0, 1.0,
                                      &m.ggx.metallic)) != DRIFT_OK ||
        (res = drift__json_read_float(r, item, path, "transmission", false, 0.0, 1.0,
                                      &m.ggx.transmission)) != DRIFT_OK ||
        (res = drift__json_read_float(r, item, path, "ior", false, 1.0, 10.0, &m.ggx.ior)) !=
            DRIFT_OK ||
        (res = drift__json_read_vec3(r, item, path, "edge_tint", false, VEC3_COLOR,
                                     &m.ggx.edge_tint)) != DRIFT_OK ||
        (res = drift__json_read_float(r, item, path, "clearcoat", false, 0.0, 1.0,
                                      &m.ggx.clearcoat)) != DRIFT_OK ||
        (res = drift__json_read_float(r, item, path, "clearcoat_roughness", false, 0.0, 1.0,
                                      &clearcoat_roughness)) != DRIFT_OK ||
        (res = drift__json_read_string(r, item, path, "metal", false, &metal)) != DRIFT_OK) {
        return res;
    }
    m.ggx.alpha = roughness * roughness;
    m.ggx.clearcoat_alpha = clearcoat_roughness * clearcoat_roughness;
    const cJSON *thin = cJSON_GetObjectItemCaseSensitive(item, "thin");
    if (thin && !cJSON_IsBool(thin)) {
        return FAIL(r, thin, DRIFT_ERR_PARSE, "%s.thin must be true or false", path);
    }
    m.ggx.thin = cJSON_IsTrue(thin);
    if (metal && !drift_ggx_named_metal(metal, &m.ggx)) {
        return FAIL(r, cJSON_GetObjectItemCaseSensitive(item, "metal"), DRIFT_ERR_INVALID_ARGUMENT,
                    "%s.metal '%s' is not one of Au, Ag, Cu, Al (gold, silver, copper, aluminium)",
                    path, metal);
    }
    res = read_coverage(r, item, path, &m);
    res = res ? res : drift_scene_add_material(r->scene, &m, NULL);
    if (res != DRIFT_OK) {
        return FAIL(r, item, res, "%s is not valid", path);
    }
    return DRIFT_OK;
}

static drift_result read_material(json_reader *r, const cJSON *item)
{
    char path[KEY_PATH_MAX];
    drift__json_key_path(path, "materials", item->string);
    drift_result res = drift__json_expect_object(r, item, path);
    if (res != DRIFT_OK) {
        return res;
    }
    res = CHECK_KEYS(r, item, path, "material");
    if (res != DRIFT_OK) {
        return res;
    }
    if (strlen(item->string) >= DRIFT_NAME_MAX) {
        return FAIL(r, item, DRIFT_ERR_INVALID_ARGUMENT,
                    "material name '%.32s...' is longer than %d bytes", item->string,
                    DRIFT_NAME_MAX - 1);
    }
    const char *type = "diffuse";
    res = drift__json_read_string(r, item, path, "type", false, &type);
    if (res != DRIFT_OK) {
        return res;
    }
    bool is_diffuse = strcmp(type, "diffuse") == 0;
    bool is_glossy = strcmp(type, "glossy") == 0;
    bool is_mirror = strcmp(type, "mirror") == 0;
    const cJSON *type_item = cJSON_GetObjectItemCaseSensitive(item, "type");
    if (strcmp(type, "ggx") == 0) {
        return read_ggx_material(r, item, path);
    }
    if (!is_diffuse && !is_glossy && !is_mirror) {
        return FAIL(r, type_item, DRIFT_ERR_INVALID_ARGUMENT,
                    "%s.type '%s' is not one of diffuse, glossy, mirror, ggx", path, type);
    }
    static const char *const ggx_only[] = { "roughness", "metallic",  "transmission",
                                            "ior",       "metal",     "edge_tint",
                                            "thin",      "clearcoat", "clearcoat_roughness" };
    for (size_t k = 0; k < sizeof(ggx_only) / sizeof(ggx_only[0]); ++k) {
        if (cJSON_HasObjectItem(item, ggx_only[k])) {
            return FAIL(r, cJSON_GetObjectItemCaseSensitive(item, ggx_only[k]),
                        DRIFT_ERR_INVALID_ARGUMENT, "%s: a %s material takes no '%s'", path, type,
                        ggx_only[k]);
        }
    }
    // Keys that the type has no use for are mistakes, not something to ignore quietly.
    const char *unused = NULL;
    if (is_diffuse && cJSON_HasObjectItem(item, "specular")) {
        unused = "specular";
    } else if (!is_glossy && cJSON_HasObjectItem(item, "exponent")) {
        unused = "exponent";
    } else if (is_mirror && cJSON_HasObjectItem(item, "diffuse")) {
        unused = "diffuse";
    } else if (is_mirror && cJSON_HasObjectItem(item, "diffuse_texture")) {
        unused = "diffuse_texture";
    } else if (is_mirror && cJSON_HasObjectItem(item, "diffuse_roughness")) {
        unused = "diffuse_roughness";
    }
    if (unused) {
        return FAIL(r, cJSON_GetObjectItemCaseSensitive(item, unused), DRIFT_ERR_INVALID_ARGUMENT,
                    "%s: a %s material takes no '%s'", path, type, unused);
    }
    drift_material m = drift_material_make(drift_vec3_splat(is_diffuse ? 0.8f : 0.0f));
    snprintf(m.name, sizeof(m.name), "%s", item->string);
    m.type = is_mirror ? DRIFT_MATERIAL_MIRROR : DRIFT_MATERIAL_DEFAULT;
    if (is_mirror) {
        m.specular = drift_vec3_splat(1.0f);
    }
    if ((res = drift__json_read_vec3(r, item, path, "diffuse", false, VEC3_COLOR, &m.diffuse)) !=
            DRIFT_OK ||
        (res = drift__json_read_vec3(r, item, path, "specular", is_glossy, VEC3_COLOR,
                                     &m.specular)) != DRIFT_OK ||
        (res = drift__json_read_float(r, item, path, "exponent", is_glossy, 1e-3, 1e7,
                                      &m.exponent)) != DRIFT_OK ||
        (res = drift__json_read_vec3(r, item, path, "emission", false, VEC3_COLOR, &m.emission)) !=
            DRIFT_OK ||
        (res = drift__json_load_texture(r, item, path, "diffuse_texture", &m.diffuse_texture)) !=
            DRIFT_OK ||
        (res = drift__json_read_float(r, item, path, "diffuse_roughness", false, 0.0, 1.0,
                                      &m.diffuse_roughness)) != DRIFT_OK) {
        return res;
    }
    // A diffuse roughness asks for Burley's diffuse (what glTF and Blender materials use).
    if (cJSON_HasObjectItem(item, "diffuse_roughness")) {
        m.diffuse_model = DRIFT_DIFFUSE_BURLEY;
    }
    res = read_coverage(r, item, path, &m);
    res = res ? res : drift_scene_add_material(r->scene, &m, NULL);
    if (res != DRIFT_OK) {
        return FAIL(r, item, res, "%s is not valid", path);
    }
    return DRIFT_OK;
}

drift_result drift__json_read_materials(json_reader *r, const cJSON *root)
{
    const cJSON *materials = cJSON_GetObjectItemCaseSensitive(root, "materials");
    if (!materials) {
        return DRIFT_OK;
    }
    drift_result res = drift__json_expect_object(r, materials, "materials");
    if (res != DRIFT_OK) {
        return res;
    }
    int count = cJSON_GetArraySize(materials);
    if (count > MAX_JSON_MATERIALS) {
        return FAIL(r, materials, DRIFT_ERR_INVALID_ARGUMENT,
                    "materials lists %d materials (at most %d)", count, MAX_JSON_MATERIALS);
    }
    // Material names are keys, so duplicates are caught by check_keys' duplicate test.
    res = drift__json_check_keys(r, materials, "materials", NULL);
    if (res != DRIFT_OK) {
        return res;
    }
    // They are read before anything else adds materials, so the n-th is scene material n.
    for (const cJSON *c = materials->child; c; c = c->next) {
        res = read_material(r, c);
        if (res != DRIFT_OK) {
            return res;
        }
        r->material_count++;
    }
    return DRIFT_OK;
}

bool drift__json_find_material(const json_reader *r, const char *name, uint32_t *out_index)
{
    // Names are whole (read_material rejects any DRIFT_NAME_MAX would cut) and unique.
    for (uint32_t i = 0; i < r->material_count; ++i) {
        if (strcmp(r->scene->materials[i].name, name) == 0) {
            *out_index = i;
            return true;
        }
    }
    return false;
}
