// drift scene files (.json): the "meshes" list and their transforms (see scene_json.c).
#include "scene_json_internal.h"

#include <cjson/cJSON.h>
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

// --- MESHES ---

// Rotation by `degrees` about `axis` (right-handed: counter-clockwise looking down the axis).
static drift__mat4 mat4_rotation(drift_vec3 axis, float degrees)
{
    drift_vec3 a = drift_vec3_normalize(axis);
    float t = degrees * DRIFT_PI / 180.0f;
    float c = cosf(t), s = sinf(t), k = 1.0f - c;
    return (drift__mat4){
        { k * a.x * a.x + c, k * a.x * a.y - s * a.z, k * a.x * a.z + s * a.y, 0.0f, //
          k * a.x * a.y + s * a.z, k * a.y * a.y + c, k * a.y * a.z - s * a.x, 0.0f, //
          k * a.x * a.z - s * a.y, k * a.y * a.z + s * a.x, k * a.z * a.z + c, 0.0f, //
          0.0f, 0.0f, 0.0f, 1.0f }
    };
}

// "transform": { translate, rotate: { axis, degrees }, scale } (applied scale, rotate,
// translate) or { matrix: 16 numbers, row-major }.
static drift_result read_transform(const json_reader *r, const cJSON *obj, const char *parent,
                                   drift__mat4 *out)
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, "transform");
    *out = drift__mat4_identity();
    if (!item) {
        return DRIFT_OK;
    }
    char path[KEY_PATH_MAX];
    drift__json_key_path(path, parent, "transform");
    drift_result res = drift__json_expect_object(r, item, path);
    if (res != DRIFT_OK) {
        return res;
    }
    res = CHECK_KEYS(r, item, path, "transform");
    if (res != DRIFT_OK) {
        return res;
    }
    const cJSON *matrix = cJSON_GetObjectItemCaseSensitive(item, "matrix");
    if (matrix) {
        char mpath[KEY_PATH_MAX];
        drift__json_key_path(mpath, path, "matrix");
        if (cJSON_HasObjectItem(item, "translate") || cJSON_HasObjectItem(item, "rotate") ||
            cJSON_HasObjectItem(item, "scale")) {
            return FAIL(r, matrix, DRIFT_ERR_INVALID_ARGUMENT,
                        "%s: give either matrix or translate/rotate/scale, not both", path);
        }
        if (!cJSON_IsArray(matrix) || cJSON_GetArraySize(matrix) != 16) {
            return FAIL(r, matrix, DRIFT_ERR_PARSE, "%s must be an array of 16 numbers", mpath);
        }
        int k = 0;
        for (const cJSON *c = matrix->child; c; c = c->next, ++k) {
            char element[KEY_PATH_MAX];
            drift__json_index_path(element, mpath, (size_t)k);
            double v;
            res = drift__json_number_value(r, c, element, -(double)FLT_MAX, (double)FLT_MAX, &v);
            if (res != DRIFT_OK) {
                return res;
            }
            out->m[k] = (float)v;
        }
        if (out->m[12] != 0.0f || out->m[13] != 0.0f || out->m[14] != 0.0f || out->m[15] != 1.0f) {
            return FAIL(r, matrix, DRIFT_ERR_INVALID_ARGUMENT,
                        "%s must be affine (last row 0 0 0 1; the matrix is row-major)", mpath);
        }
        return DRIFT_OK;
    }
    drift_vec3 translate = drift_vec3_splat(0.0f), scale = drift_vec3_splat(1.0f);
    if ((res = drift__json_read_vec3(r, item, path, "translate", false, VEC3_ANY, &translate)) !=
        DRIFT_OK) {
        return res;
    }
    const cJSON *scale_item = cJSON_GetObjectItemCaseSensitive(item, "scale");
    if (scale_item) {
        char spath[KEY_PATH_MAX];
        drift__json_key_path(spath, path, "scale");
        if (cJSON_IsNumber(scale_item)) {
            double s;
            res = drift__json_number_value(r, scale_item, spath, -(double)FLT_MAX, (double)FLT_MAX,
                                           &s);
            scale = drift_vec3_splat((float)s);
        } else {
            res = drift__json_read_vec3(r, item, path, "scale", false, VEC3_ANY, &scale);
        }
        if (res != DRIFT_OK) {
            return res;
        }
        if (scale.x == 0.0f || scale.y == 0.0f || scale.z == 0.0f) {
            return FAIL(r, scale_item, DRIFT_ERR_INVALID_ARGUMENT,
                        "%s must be non-zero on every axis", spath);
        }
    }
    drift__mat4 rotation = drift__mat4_identity();
    const cJSON *rotate = cJSON_GetObjectItemCaseSensitive(item, "rotate");
    if (rotate) {
        char rpath[KEY_PATH_MAX];
        drift__json_key_path(rpath, path, "rotate");
        if ((res = drift__json_expect_object(r, rotate, rpath)) != DRIFT_OK ||
            (res = CHECK_KEYS(r, rotate, rpath, "transform.rotate")) != DRIFT_OK) {
            return res;
        }
        drift_vec3 axis = drift_vec3_make(0, 1, 0);
        float degrees = 0.0f;
        if ((res = drift__json_read_vec3(r, rotate, rpath, "axis", true, VEC3_DIRECTION, &axis)) !=
                DRIFT_OK ||
            (res = drift__json_read_float(r, rotate, rpath, "degrees", true, -1e6, 1e6,
                                          &degrees)) != DRIFT_OK) {
            return res;
        }
        rotation = mat4_rotation(axis, degrees);
    }
    drift__mat4 s = { { scale.x, 0, 0, 0, 0, scale.y, 0, 0, 0, 0, scale.z, 0, 0, 0, 0, 1 } };
    drift__mat4 t = { { 1, 0, 0, translate.x, //
                        0, 1, 0, translate.y, //
                        0, 0, 1, translate.z, //
                        0, 0, 0, 1 } };
    drift__mat4 rs = drift__mat4_mul(&rotation, &s);
    *out = drift__mat4_mul(&t, &rs);
    return DRIFT_OK;
}

static drift_result read_mesh(json_reader *r, const cJSON *item, const char *path)
{
    drift_result res = drift__json_expect_object(r, item, path);
    if (res != DRIFT_OK) {
        return res;
    }
    if ((res = CHECK_KEYS(r, item, path, "mesh")) != DRIFT_OK) {
        return res;
    }
    const char *rel = NULL, *material_name = NULL, *camera = NULL;
    if ((res = drift__json_read_string(r, item, path, "path", true, &rel)) != DRIFT_OK ||
        (res = drift__json_read_string(r, item, path, "material", false, &material_name)) !=
            DRIFT_OK ||
        (res = drift__json_read_string(r, item, path, "camera", false, &camera)) != DRIFT_OK) {
        return res;
    }
    const cJSON *path_item = cJSON_GetObjectItemCaseSensitive(item, "path");
    uint32_t material = DRIFT_INVALID_INDEX;
    if (material_name && !drift__json_find_material(r, material_name, &material)) {
        return FAIL(r, cJSON_GetObjectItemCaseSensitive(item, "material"),
                    DRIFT_ERR_INVALID_ARGUMENT, "%s.material '%s' is not in materials", path,
                    material_name);
    }
    drift__mat4 transform;
    if ((res = read_transform(r, item, path, &transform)) != DRIFT_OK) {
        return res;
    }
    char ext[16];
    bool gz = false;
    drift__path_extension(rel, ext, sizeof(ext), &gz);
    if (!drift__is_mesh_extension(ext)) {
        char formats[128];
        drift__scene_formats_text(formats, sizeof formats, true);
        return FAIL(r, path_item, DRIFT_ERR_UNSUPPORTED, "%s.path '%s': meshes must be %s", path,
                    rel, formats);
    }
    char full[DRIFT__PATH_MAX];
    if ((res = drift__json_resolve_path(r, path_item, rel, full)) != DRIFT_OK) {
        return res;
    }
    drift__import_info info;
    drift__import_params params = { .path = full,
                                    .where = r->file,
                                    .line = drift__json_line_of(r, path_item),
                                    .transform = &transform,
                                    .material_override = material,
                                    .textures = &r->textures,
                                    .camera = camera };
    res = drift__scene_import_mesh_file(r->scene, &params, &info);
    if (res != DRIFT_OK) {
        return res;
    }
    if (info.has_camera && !r->file_camera_found) {
        r->file_camera_found = true;
        r->file_camera = info.camera;
    }
    return DRIFT_OK;
}

drift_result drift__json_read_meshes(json_reader *r, const cJSON *root)
{
    const cJSON *meshes = cJSON_GetObjectItemCaseSensitive(root, "meshes");
    if (!meshes) {
        return DRIFT_OK;
    }
    if (!cJSON_IsArray(meshes)) {
        return FAIL(r, meshes, DRIFT_ERR_PARSE, "meshes must be an array, not %s",
                    drift__json_type_name(meshes));
    }
    if (cJSON_GetArraySize(meshes) > MAX_JSON_MESHES) {
        return FAIL(r, meshes, DRIFT_ERR_INVALID_ARGUMENT, "meshes lists more than %d files",
                    MAX_JSON_MESHES);
    }
    size_t i = 0;
    for (const cJSON *c = meshes->child; c; c = c->next, ++i) {
        char path[KEY_PATH_MAX];
        drift__json_index_path(path, "meshes", i);
        drift_result res = read_mesh(r, c, path);
        if (res != DRIFT_OK) {
            return res;
        }
    }
    return DRIFT_OK;
}
