// drift scene files (.json): "lights", "environment" and "camera" (see scene_json.c).
#include "scene_json_internal.h"

#include <cjson/cJSON.h>
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

// --- LIGHTS ---

static drift_result read_light(json_reader *r, const cJSON *item, const char *path)
{
    drift_result res = drift__json_expect_object(r, item, path);
    if (res != DRIFT_OK) {
        return res;
    }
    const char *type = NULL;
    if ((res = drift__json_read_string(r, item, path, "type", true, &type)) != DRIFT_OK) {
        return res;
    }
    drift_light l = { 0 };
    if (strcmp(type, "point") == 0) {
        l.type = DRIFT_LIGHT_POINT;
        if ((res = CHECK_KEYS(r, item, path, "light point")) != DRIFT_OK ||
            (res = drift__json_read_vec3(r, item, path, "position", true, VEC3_ANY, &l.position)) !=
                DRIFT_OK ||
            (res = drift__json_read_vec3(r, item, path, "intensity", true, VEC3_COLOR, &l.color)) !=
                DRIFT_OK) {
            return res;
        }
    } else if (strcmp(type, "spot") == 0) {
        l.type = DRIFT_LIGHT_SPOT;
        float inner = 0.0f, outer = 0.0f;
        if ((res = CHECK_KEYS(r, item, path, "light spot")) != DRIFT_OK ||
            (res = drift__json_read_vec3(r, item, path, "position", true, VEC3_ANY, &l.position)) !=
                DRIFT_OK ||
            (res = drift__json_read_vec3(r, item, path, "direction", true, VEC3_DIRECTION,
                                         &l.direction)) != DRIFT_OK ||
            (res = drift__json_read_vec3(r, item, path, "intensity", true, VEC3_COLOR, &l.color)) !=
                DRIFT_OK ||
            (res = drift__json_read_float(r, item, path, "outer_angle", true, 0.0, 180.0,
                                          &outer)) != DRIFT_OK ||
            (res = drift__json_read_float(r, item, path, "inner_angle", false, 0.0, 180.0,
                                          &inner)) != DRIFT_OK) {
            return res;
        }
        l.spot_inner = inner * DRIFT_PI / 180.0f;
        l.spot_outer = outer * DRIFT_PI / 180.0f;
    } else if (strcmp(type, "directional") == 0) {
        l.type = DRIFT_LIGHT_DIRECTIONAL;
        if ((res = CHECK_KEYS(r, item, path, "light directional")) != DRIFT_OK ||
            (res = drift__json_read_vec3(r, item, path, "direction", true, VEC3_DIRECTION,
                                         &l.direction)) != DRIFT_OK ||
            (res = drift__json_read_vec3(r, item, path, "irradiance", true, VEC3_COLOR,
                                         &l.color)) != DRIFT_OK) {
            return res;
        }
    } else if (strcmp(type, "quad") == 0) {
        l.type = DRIFT_LIGHT_QUAD;
        if ((res = CHECK_KEYS(r, item, path, "light quad")) != DRIFT_OK ||
            (res = drift__json_read_vec3(r, item, path, "corner", true, VEC3_ANY, &l.position)) !=
                DRIFT_OK ||
            (res = drift__json_read_vec3(r, item, path, "edge_u", true, VEC3_ANY, &l.edge_u)) !=
                DRIFT_OK ||
            (res = drift__json_read_vec3(r, item, path, "edge_v", true, VEC3_ANY, &l.edge_v)) !=
                DRIFT_OK ||
            (res = drift__json_read_vec3(r, item, path, "radiance", true, VEC3_COLOR, &l.color)) !=
                DRIFT_OK) {
            return res;
        }
    } else if (strcmp(type, "disk") == 0) {
        l.type = DRIFT_LIGHT_DISK;
        if ((res = CHECK_KEYS(r, item, path, "light disk")) != DRIFT_OK ||
            (res = drift__json_read_vec3(r, item, path, "center", true, VEC3_ANY, &l.position)) !=
                DRIFT_OK ||
            (res = drift__json_read_vec3(r, item, path, "normal", true, VEC3_DIRECTION,
                                         &l.direction)) != DRIFT_OK ||
            (res = drift__json_read_float(r, item, path, "radius", true, -(double)FLT_MAX,
                                          (double)FLT_MAX, &l.radius)) != DRIFT_OK ||
            (res = drift__json_read_vec3(r, item, path, "radiance", true, VEC3_COLOR, &l.color)) !=
                DRIFT_OK) {
            return res;
        }
    } else if (strcmp(type, "sphere") == 0) {
        l.type = DRIFT_LIGHT_SPHERE;
        if ((res = CHECK_KEYS(r, item, path, "light sphere")) != DRIFT_OK ||
            (res = drift__json_read_vec3(r, item, path, "center", true, VEC3_ANY, &l.position)) !=
                DRIFT_OK ||
            (res = drift__json_read_float(r, item, path, "radius", true, -(double)FLT_MAX,
                                          (double)FLT_MAX, &l.radius)) != DRIFT_OK ||
            (res = drift__json_read_vec3(r, item, path, "radiance", true, VEC3_COLOR, &l.color)) !=
                DRIFT_OK) {
            return res;
        }
    } else {
        return FAIL(r, cJSON_GetObjectItemCaseSensitive(item, "type"), DRIFT_ERR_INVALID_ARGUMENT,
                    "%s.type '%s' is not one of point, spot, directional, quad, disk, sphere", path,
                    type);
    }
    // drift_scene_add_light checks the values (zero area, cone angles) and logs the reason;
    // this adds where in the file the light is.
    res = drift_scene_add_light(r->scene, &l, NULL);
    if (res != DRIFT_OK) {
        return FAIL(r, item, res, "%s (%s light) is not valid", path, type);
    }
    return DRIFT_OK;
}

drift_result drift__json_read_lights(json_reader *r, const cJSON *root)
{
    const cJSON *lights = cJSON_GetObjectItemCaseSensitive(root, "lights");
    if (!lights) {
        return DRIFT_OK;
    }
    if (!cJSON_IsArray(lights)) {
        return FAIL(r, lights, DRIFT_ERR_PARSE, "lights must be an array, not %s",
                    drift__json_type_name(lights));
    }
    size_t i = 0;
    for (const cJSON *c = lights->child; c; c = c->next, ++i) {
        char path[KEY_PATH_MAX];
        drift__json_index_path(path, "lights", i);
        drift_result res = read_light(r, c, path);
        if (res != DRIFT_OK) {
            return res;
        }
    }
    return DRIFT_OK;
}

// --- ENVIRONMENT AND CAMERA ---

drift_result drift__json_read_environment(json_reader *r, const cJSON *root)
{
    const cJSON *env = cJSON_GetObjectItemCaseSensitive(root, "environment");
    if (!env) {
        return DRIFT_OK;
    }
    const char *path = "environment";
    drift_result res = drift__json_expect_object(r, env, path);
    if (res != DRIFT_OK || (res = CHECK_KEYS(r, env, path, "environment")) != DRIFT_OK) {
        return res;
    }
    bool has_map = cJSON_HasObjectItem(env, "map");
    if (has_map && cJSON_HasObjectItem(env, "color")) {
        return FAIL(r, cJSON_GetObjectItemCaseSensitive(env, "color"), DRIFT_ERR_INVALID_ARGUMENT,
                    "environment: give either color or map (scaled by multiplier), not both");
    }
    if (!has_map && cJSON_HasObjectItem(env, "multiplier")) {
        return FAIL(r, cJSON_GetObjectItemCaseSensitive(env, "multiplier"),
                    DRIFT_ERR_INVALID_ARGUMENT, "environment.multiplier needs a map");
    }
    drift_environment e = { .color = drift_vec3_splat(has_map ? 1.0f : 0.0f),
                            .texture = DRIFT_INVALID_INDEX };
    if ((res = drift__json_read_vec3(r, env, path, "color", false, VEC3_COLOR, &e.color)) !=
            DRIFT_OK ||
        (res = drift__json_read_vec3(r, env, path, "multiplier", false, VEC3_COLOR, &e.color)) !=
            DRIFT_OK ||
        (res = drift__json_load_texture(r, env, path, "map", &e.texture)) != DRIFT_OK) {
        return res;
    }
    r->scene->environment = e;
    return DRIFT_OK;
}

drift_result drift__json_read_camera(json_reader *r, const cJSON *root, bool *out_found)
{
    const cJSON *cam = cJSON_GetObjectItemCaseSensitive(root, "camera");
    *out_found = cam != NULL;
    if (!cam) {
        return DRIFT_OK;
    }
    const char *path = "camera";
    drift_result res = drift__json_expect_object(r, cam, path);
    if (res != DRIFT_OK || (res = CHECK_KEYS(r, cam, path, "camera")) != DRIFT_OK) {
        return res;
    }
    drift_camera c = { .up = drift_vec3_make(0, 1, 0), .width = 512, .height = 512 };
    float fov_deg = 45.0f;
    if ((res = drift__json_read_vec3(r, cam, path, "position", true, VEC3_ANY, &c.position)) !=
            DRIFT_OK ||
        (res = drift__json_read_vec3(r, cam, path, "target", true, VEC3_ANY, &c.target)) !=
            DRIFT_OK ||
        (res = drift__json_read_vec3(r, cam, path, "up", false, VEC3_DIRECTION, &c.up)) !=
            DRIFT_OK ||
        (res = drift__json_read_float(r, cam, path, "fov_y", false, 1e-3, 179.0, &fov_deg)) !=
            DRIFT_OK ||
        (res = drift__json_read_float(r, cam, path, "aperture_radius", false, 0.0, (double)FLT_MAX,
                                      &c.aperture_radius)) != DRIFT_OK ||
        (res = drift__json_read_float(r, cam, path, "focus_distance", false, 0.0, (double)FLT_MAX,
                                      &c.focus_distance)) != DRIFT_OK ||
        (res = drift__json_read_int(r, cam, path, "width", false, 1, DRIFT_IMAGE_MAX_DIMENSION,
                                    &c.width)) != DRIFT_OK ||
        (res = drift__json_read_int(r, cam, path, "height", false, 1, DRIFT_IMAGE_MAX_DIMENSION,
                                    &c.height)) != DRIFT_OK) {
        return res;
    }
    c.fov_y = fov_deg * DRIFT_PI / 180.0f;
    // Commit rejects these too, but without saying where in the file they are.
    drift_vec3 forward = drift_vec3_sub(c.target, c.position);
    if (!(drift_vec3_length(forward) > 0.0f) || !isfinite(drift_vec3_length(forward))) {
        return FAIL(r, cJSON_GetObjectItemCaseSensitive(cam, "target"), DRIFT_ERR_INVALID_ARGUMENT,
                    "camera.target must differ from camera.position");
    }
    if (!(drift_vec3_length(drift_vec3_cross(drift_vec3_normalize(forward),
                                             drift_vec3_normalize(c.up))) > 1e-6f)) {
        return FAIL(r, cJSON_GetObjectItemCaseSensitive(cam, "up"), DRIFT_ERR_INVALID_ARGUMENT,
                    "camera.up must not be parallel to the view direction");
    }
    r->scene->camera = c;
    return DRIFT_OK;
}
