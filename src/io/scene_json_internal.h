// The scene-file reader's private parts, shared by its stages: scene_json.c (source
// positions, messages, typed reads, the document and camera views), scene_json_materials.c,
// scene_json_meshes.c and scene_json_lights.c (lights, environment, camera).
#ifndef DRIFT_SCENE_JSON_INTERNAL_H
#define DRIFT_SCENE_JSON_INTERNAL_H

#include "io/json_lines.h"
#include "scene_io_internal.h"

#include <cjson/cJSON.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

// Largest counts a scene file may list (far above real scenes; keeps a hostile file small).
#define MAX_JSON_MESHES    65536
#define MAX_JSON_MATERIALS 65536
#define KEY_PATH_MAX       256

typedef struct json_reader {
    drift_context *ctx;
    drift_scene *scene;
    const char *file;        // name in messages
    const char *base_dir;    // paths in the file are relative to this
    drift__json_lines lines; // every node's line
    uint32_t material_count; // the file's materials: scene materials 0 .. material_count - 1
    drift__texture_cache textures;
    bool file_camera_found;
    drift_camera file_camera;
} json_reader;

#define FAIL(r, node, code, ...) \
    drift__json_report((r), DRIFT_LOG_ERROR, (node), (code), __VA_ARGS__)
#define CHECK_KEYS(r, obj, path, object) drift__json_check_keys((r), (obj), (path), (object))

typedef enum vec3_kind {
    VEC3_ANY,      // position: any finite value
    VEC3_COLOR,    // colour: components >= 0; a single number means grey
    VEC3_DIRECTION // direction: not all zero
} vec3_kind;

int drift__json_line_of(const json_reader *r, const cJSON *node);
#if defined(__GNUC__)
__attribute__((format(printf, 5, 6)))
#endif
drift_result
drift__json_report(const json_reader *r, drift_log_level level, const cJSON *node,
                   drift_result code, const char *fmt, ...);
void drift__json_key_path(char *out, const char *parent, const char *key);
void drift__json_index_path(char *out, const char *parent, size_t index);
const char *drift__json_type_name(const cJSON *item);
drift_result drift__json_expect_object(const json_reader *r, const cJSON *item, const char *path);
// Warns about keys that are not rows of `object` in the key table (scene_json_keys.c; NULL:
// any key is allowed) and fails on duplicate keys.
drift_result drift__json_check_keys(const json_reader *r, const cJSON *obj, const char *path,
                                    const char *object);
drift_result drift__json_number_value(const json_reader *r, const cJSON *item, const char *path,
                                      double lo, double hi, double *out);
drift_result drift__json_read_float(const json_reader *r, const cJSON *obj, const char *path,
                                    const char *key, bool required, double lo, double hi,
                                    float *out);
drift_result drift__json_read_int(const json_reader *r, const cJSON *obj, const char *path,
                                  const char *key, bool required, int32_t lo, int32_t hi,
                                  int32_t *out);
drift_result drift__json_read_vec3(const json_reader *r, const cJSON *obj, const char *path,
                                   const char *key, bool required, vec3_kind kind, drift_vec3 *out);
drift_result drift__json_read_string(const json_reader *r, const cJSON *obj, const char *path,
                                     const char *key, bool required, const char **out);
// Joins a path from the file with the file's folder; fails when too long.
drift_result drift__json_resolve_path(const json_reader *r, const cJSON *node, const char *relative,
                                      char *out);
drift_result drift__json_load_texture(json_reader *r, const cJSON *obj, const char *path,
                                      const char *key, uint32_t *out_index);
drift_result drift__json_read_materials(json_reader *r, const cJSON *root);
bool drift__json_find_material(const json_reader *r, const char *name, uint32_t *out_index);
drift_result drift__json_read_meshes(json_reader *r, const cJSON *root);
drift_result drift__json_read_lights(json_reader *r, const cJSON *root);
drift_result drift__json_read_environment(json_reader *r, const cJSON *root);
drift_result drift__json_read_camera(json_reader *r, const cJSON *root, bool *out_found);

#endif
