// Scene loading entry point: the registry's loader for the path (scene_formats.c), whole-file reads
// (gunzipped with zlib), the texture cache, and the camera and light a bare mesh file is given.
#include "drift/file.h"
#include "drift/image_io.h"
#include "drift/scene_io.h"
#include "image_io_internal.h" // drift__errno_text
#include "scene_io_internal.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

void drift__path_extension(const char *path, char *out, size_t out_size, bool *out_gz)
{
    out[0] = '\0';
    *out_gz = false;
    const char *slash = strrchr(path, '/');
    const char *name = slash ? slash + 1 : path;
    size_t len = strlen(name);
    const char *dot = NULL;
    for (int pass = 0; pass < 2; ++pass) {
        dot = NULL;
        for (size_t i = len; i > 0; --i) {
            if (name[i - 1] == '.') {
                dot = name + i - 1;
                break;
            }
        }
        if (!dot) {
            return;
        }
        size_t ext_len = len - (size_t)(dot - name) - 1;
        if (pass == 0 && ext_len == 2 && tolower((unsigned char)dot[1]) == 'g' &&
            tolower((unsigned char)dot[2]) == 'z') {
            // "x.obj.gz": look again at the name without ".gz".
            *out_gz = true;
            len = (size_t)(dot - name);
            continue;
        }
        size_t n = ext_len < out_size - 1 ? ext_len : out_size - 1;
        for (size_t i = 0; i < n; ++i) {
            out[i] = (char)tolower((unsigned char)dot[1 + i]);
        }
        out[n] = '\0';
        return;
    }
}

bool drift__path_join(const char *base_dir, const char *relative, char *out, size_t out_size)
{
    int n;
    if (relative[0] == '/' || !base_dir || !base_dir[0]) {
        n = snprintf(out, out_size, "%s", relative);
    } else {
        n = snprintf(out, out_size, "%s/%s", base_dir, relative);
    }
    return n >= 0 && (size_t)n < out_size;
}

drift_result drift__check_file(drift_context *ctx, const char *path, const char *where, int line,
                               size_t *out_size)
{
    *out_size = 0;
    struct stat st;
    char why[128];
    if (stat(path, &st) != 0) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_IO, where, line, "cannot open '%s': %s", path,
                  drift__errno_text(errno, why, sizeof(why)));
        return DRIFT_ERR_IO;
    }
    if (!S_ISREG(st.st_mode)) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_IO, where, line, "'%s' is not a regular file",
                  path);
        return DRIFT_ERR_IO;
    }
    *out_size = (size_t)st.st_size;
    return DRIFT_OK;
}

// Appends n bytes to a growing buffer (capacity doubles; one spare byte for the NUL).
static drift_result buffer_append(drift_context *ctx, char **data, size_t *size, size_t *cap,
                                  const void *bytes, size_t n)
{
    if (*size + n + 1 > *cap) {
        size_t new_cap = *cap ? *cap : 65536;
        while (new_cap < *size + n + 1) {
            new_cap *= 2;
        }
        char *grown = drift_realloc(ctx, *data, *size, new_cap);
        if (!grown) {
            return DRIFT_ERR_OUT_OF_MEMORY;
        }
        *data = grown;
        *cap = new_cap;
    }
    memcpy(*data + *size, bytes, n);
    *size += n;
    (*data)[*size] = '\0';
    return DRIFT_OK;
}

drift_result drift__read_file(drift_context *ctx, const char *path, bool gzip, const char *where,
                              int line, char **out_data, size_t *out_size)
{
    *out_data = NULL;
    *out_size = 0;
    size_t file_size = 0;
    drift_result r = drift__check_file(ctx, path, where, line, &file_size);
    if (r != DRIFT_OK) {
        return r;
    }
    const char *too_big = gzip ? "unpacks to more than" : "is larger than";
    if (!gzip && file_size > DRIFT_SCENE_MAX_FILE_BYTES) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, where, line,
                  "'%s' %s %zu bytes", path, too_big, DRIFT_SCENE_MAX_FILE_BYTES);
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    // gzread inflates gzip data and passes anything else through unchanged, so one loop reads
    // both kinds; gzdirect says which kind the file is, and it must match its name.
    char why[128];
    int fd = drift_input_open(path, why, sizeof(why));
    gzFile gz = fd >= 0 ? gzdopen(fd, "rb") : NULL;
    if (!gz) {
        if (fd >= 0) {
            drift__errno_text(errno, why, sizeof(why));
            close(fd);
        }
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_IO, where, line, "cannot open '%s': %s", path,
                  why);
        return DRIFT_ERR_IO;
    }
    if (gzdirect(gz) == (int)gzip) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_PARSE, where, line,
                  gzip ? "'%s' is not a gzip file" : "'%s' is gzip-compressed but not named .gz",
                  path);
        gzclose(gz);
        return DRIFT_ERR_PARSE;
    }
    char *data = NULL;
    size_t size = 0, cap = 0;

    enum {
        CHUNK = 1 << 16
    };

    char *chunk = drift_alloc(ctx, CHUNK);
    if (!chunk) {
        r = DRIFT_ERR_OUT_OF_MEMORY;
    }
    while (r == DRIFT_OK) {
        int n = gzread(gz, chunk, CHUNK);
        if (n < 0) {
            int errnum = 0;
            const char *msg = gzerror(gz, &errnum);
            drift_log(ctx, DRIFT_LOG_ERROR, gzip ? DRIFT_ERR_PARSE : DRIFT_ERR_IO, where, line,
                      gzip ? "'%s': gzip data is corrupt (%s)" : "cannot read '%s' (%s)", path,
                      msg ? msg : "unknown zlib error");
            r = gzip ? DRIFT_ERR_PARSE : DRIFT_ERR_IO;
            break;
        }
        if (n == 0) {
            // A truncated gzip stream ends in Z_BUF_ERROR rather than a clean end of file.
            int errnum = 0;
            gzerror(gz, &errnum);
            if (errnum != Z_OK) {
                drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_PARSE, where, line,
                          "'%s': gzip data is truncated", path);
                r = DRIFT_ERR_PARSE;
            }
            break;
        }
        if (size + (size_t)n > DRIFT_SCENE_MAX_FILE_BYTES) {
            drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, where, line,
                      "'%s' %s %zu bytes", path, too_big, DRIFT_SCENE_MAX_FILE_BYTES);
            r = DRIFT_ERR_INVALID_ARGUMENT;
            break;
        }
        r = buffer_append(ctx, &data, &size, &cap, chunk, (size_t)n);
    }
    gzclose(gz);
    drift_free(ctx, chunk);
    if (r == DRIFT_OK && !data) {
        r = buffer_append(ctx, &data, &size, &cap, "", 0);
    }
    if (r != DRIFT_OK) {
        drift_free(ctx, data);
        return r;
    }
    *out_data = data;
    *out_size = size;
    return DRIFT_OK;
}

// Sets the texels of `image` that are NaN or infinite to 0 and says how many: one such texel
// of a texture or environment map made NaN pixels in a hybrid frame.
static void replace_nonfinite_texels(drift_context *ctx, drift_image *image, const char *path,
                                     const char *where, int line)
{
    size_t count = 0;
    for (int32_t y = 0; y < image->height; ++y) {
        float *row = image->pixels + (size_t)y * (size_t)image->stride;
        for (size_t i = 0; i < (size_t)image->width * (size_t)image->channels; ++i) {
            if (!isfinite(row[i])) {
                row[i] = 0.0f;
                ++count;
            }
        }
    }
    if (count > 0) {
        drift_log(ctx, DRIFT_LOG_WARNING, DRIFT_ERR_INVALID_ARGUMENT, where, line,
                  "texture '%s': %zu texel values were NaN or infinite; set to 0", path, count);
    }
}

drift_result drift__texture_cache_get(drift_scene *scene, drift__texture_cache *cache,
                                      const char *path, const char *where, int line,
                                      uint32_t *out_index)
{
    drift_context *ctx = scene->ctx;
    for (uint32_t i = 0; i < cache->count; ++i) {
        if (strcmp(cache->paths[i], path) == 0) {
            *out_index = cache->indices[i];
            return DRIFT_OK;
        }
    }
    size_t file_size = 0;
    drift_result r = drift__check_file(ctx, path, where, line, &file_size);
    if (r != DRIFT_OK) {
        return r;
    }
    drift_image image = { 0 };
    r = drift_image_load(ctx, path, &image);
    if (r != DRIFT_OK) {
        drift_log(ctx, DRIFT_LOG_ERROR, r, where, line, "cannot load texture '%s'", path);
        return r;
    }
    replace_nonfinite_texels(ctx, &image, path, where, line);
    if (cache->on_input) {
        cache->on_input(path, cache->user);
    }
    uint32_t index;
    r = drift_scene_add_texture(scene, image, &index); // owns the pixels, even on failure
    if (r != DRIFT_OK) {
        drift_log(ctx, DRIFT_LOG_ERROR, r, where, line, "cannot add texture '%s'", path);
        return r;
    }
    if (cache->count == cache->capacity) {
        uint32_t new_cap = cache->capacity ? cache->capacity * 2 : 8;
        char **paths = drift_realloc(ctx, cache->paths, cache->capacity * sizeof(char *),
                                     new_cap * sizeof(char *));
        if (!paths) {
            return DRIFT_ERR_OUT_OF_MEMORY;
        }
        cache->paths = paths;
        uint32_t *indices = drift_realloc(ctx, cache->indices, cache->capacity * sizeof(uint32_t),
                                          new_cap * sizeof(uint32_t));
        if (!indices) {
            return DRIFT_ERR_OUT_OF_MEMORY;
        }
        cache->indices = indices;
        cache->capacity = new_cap;
    }
    size_t len = strlen(path);
    char *copy = drift_alloc(ctx, len + 1);
    if (!copy) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    memcpy(copy, path, len + 1);
    cache->paths[cache->count] = copy;
    cache->indices[cache->count] = index;
    cache->count++;
    *out_index = index;
    return DRIFT_OK;
}

void drift__texture_cache_clear(drift_context *ctx, drift__texture_cache *cache)
{
    for (uint32_t i = 0; i < cache->count; ++i) {
        drift_free(ctx, cache->paths[i]);
    }
    drift_free(ctx, cache->paths);
    drift_free(ctx, cache->indices);
    *cache = (drift__texture_cache){ 0 };
}

drift_camera drift__framing_camera(drift_bounds3 bounds)
{
    const float fov_y = 45.0f * DRIFT_PI / 180.0f;
    if (drift_bounds3_is_empty(bounds)) {
        // Nothing to frame (a scene of lights only): look at the origin from +z.
        bounds = (drift_bounds3){ drift_vec3_splat(-1.0f), drift_vec3_splat(1.0f) };
    }
    drift_vec3 centre = drift_vec3_scale(drift_vec3_add(bounds.min, bounds.max), 0.5f);
    float radius = 0.5f * drift_vec3_length(drift_vec3_sub(bounds.max, bounds.min));
    if (!(radius > 0.0f) || !isfinite(radius)) {
        radius = 1.0f;
    }
    // The bounding sphere touches the view cone at distance radius / sin(fov / 2).
    float distance = radius / sinf(0.5f * fov_y);
    drift_vec3 eye = drift_vec3_add(centre, drift_vec3_make(0.0f, 0.0f, distance));
    return drift_camera_look_at(eye, centre, drift_vec3_make(0.0f, 1.0f, 0.0f), fov_y, 512, 512);
}

// Light for a file that brings none: sun over the camera's right shoulder plus a dim sky,
// so any mesh is visible without setup. Irradiance pi makes a white Lambertian surface
// facing the sun as bright as its albedo.
static drift_result add_default_lights(drift_scene *scene, const char *path)
{
    drift_vec3 view =
        drift_vec3_normalize(drift_vec3_sub(scene->camera.target, scene->camera.position));
    drift_vec3 right = drift_vec3_normalize(drift_vec3_cross(view, scene->camera.up));
    drift_vec3 up = drift_vec3_cross(right, view);
    // From behind the camera, up and to the right: the light travels forward, down, left.
    drift_vec3 toward_light =
        drift_vec3_add(drift_vec3_add(drift_vec3_scale(view, -1.0f), drift_vec3_scale(up, 1.0f)),
                       drift_vec3_scale(right, 0.5f));
    drift_light sun = { .type = DRIFT_LIGHT_DIRECTIONAL,
                        .color = drift_vec3_splat(DRIFT_PI),
                        .direction = drift_vec3_neg(drift_vec3_normalize(toward_light)) };
    drift_result r = drift_scene_add_light(scene, &sun, NULL);
    if (r != DRIFT_OK) {
        return r;
    }
    scene->environment.color = drift_vec3_splat(0.2f);
    scene->environment.texture = DRIFT_INVALID_INDEX;
    scene->default_lights = true;
    drift_log(scene->ctx, DRIFT_LOG_INFO, DRIFT_OK, path, 0,
              "no lights or emitters in the file: added a directional light and an environment "
              "of 0.2");
    return DRIFT_OK;
}

static drift_result load_mesh_scene(drift_context *ctx, const char *path, const char *camera,
                                    drift_scene_input_fn on_input, void *user,
                                    drift_scene **out_scene)
{
    drift_scene *scene = NULL;
    drift_result r = drift_scene_create(ctx, &scene);
    if (r != DRIFT_OK) {
        return r;
    }
    drift__texture_cache textures = { .on_input = on_input, .user = user };
    drift__import_info info = { 0 };
    drift__import_params params = { .path = path,
                                    .where = path,
                                    .material_override = DRIFT_INVALID_INDEX,
                                    .textures = &textures,
                                    .camera = camera };
    r = drift__scene_import_mesh_file(scene, &params, &info);
    drift__texture_cache_clear(ctx, &textures);
    if (r == DRIFT_OK) {
        scene->camera =
            info.has_camera ? info.camera : drift__framing_camera(drift__scene_mesh_bounds(scene));
        if (info.light_count == 0 && info.emissive_material_count == 0) {
            r = add_default_lights(scene, path);
        }
    }
    if (r == DRIFT_OK) {
        r = drift_scene_commit(scene);
        if (r != DRIFT_OK) {
            drift_log(ctx, DRIFT_LOG_ERROR, r, path, 0, "the scene is not valid (see above)");
        }
    }
    if (r != DRIFT_OK) {
        drift_scene_destroy(scene);
        return r;
    }
    *out_scene = scene;
    return DRIFT_OK;
}

drift_result drift__scene_load_mesh_file(drift_context *ctx, const char *path, bool gz,
                                         drift_scene_input_fn on_input, void *user,
                                         drift_scene **out_scene)
{
    (void)gz; // the importer looks at the name itself
    return load_mesh_scene(ctx, path, NULL, on_input, user, out_scene);
}

static void dirname_of(const char *path, char *out, size_t out_size)
{
    const char *slash = strrchr(path, '/');
    if (!slash) {
        snprintf(out, out_size, ".");
    } else if (slash == path) {
        snprintf(out, out_size, "/");
    } else {
        snprintf(out, out_size, "%.*s", (int)(slash - path), path);
    }
}

drift_result drift_scene_load(drift_context *ctx, const char *path, drift_scene **out_scene)
{
    return drift_scene_load_inputs(ctx, path, NULL, NULL, out_scene);
}

drift_result drift_scene_load_camera(drift_context *ctx, const char *path, const char *camera,
                                     drift_scene_input_fn on_input, void *user,
                                     drift_scene **out_scene)
{
    if (!camera) {
        return drift_scene_load_inputs(ctx, path, on_input, user, out_scene);
    }
    if (!out_scene) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    *out_scene = NULL;
    char ext[16];
    bool gz = false;
    drift__path_extension(path ? path : "", ext, sizeof(ext), &gz);
    if (strcmp(ext, "gltf") != 0 && strcmp(ext, "glb") != 0) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_UNSUPPORTED, path, 0,
                  "a camera by name ('%s') is chosen among a glTF file's cameras; this is not a "
                  ".gltf or .glb (a JSON scene names its glTF's camera in the mesh entry's "
                  "\"camera\")",
                  camera);
        return DRIFT_ERR_UNSUPPORTED;
    }
    if (strlen(path) >= DRIFT__PATH_MAX) {
        return drift_scene_load_inputs(ctx, path, on_input, user, out_scene); // says why
    }
    return load_mesh_scene(ctx, path, camera, on_input, user, out_scene);
}

drift_result drift_scene_load_inputs(drift_context *ctx, const char *path,
                                     drift_scene_input_fn on_input, void *user,
                                     drift_scene **out_scene)
{
    if (!out_scene) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    *out_scene = NULL;
    if (!path || !path[0]) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, NULL, 0, "no scene path given");
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    if (strlen(path) >= DRIFT__PATH_MAX) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, NULL, 0,
                  "scene path is longer than %d bytes", DRIFT__PATH_MAX - 1);
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    bool gz = false;
    drift__scene_load_fn load = drift__scene_loader_of(path, &gz);
    if (!load) {
        char ext[16];
        drift__path_extension(path, ext, sizeof(ext), &gz);
        char formats[256];
        drift__scene_formats_text(formats, sizeof formats, false);
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_UNSUPPORTED, path, 0,
                  "unsupported scene file extension '%s%s' (drift reads %s)", ext, gz ? ".gz" : "",
                  formats);
        return DRIFT_ERR_UNSUPPORTED;
    }
    return load(ctx, path, gz, on_input, user, out_scene);
}

drift_result drift__scene_load_json_file(drift_context *ctx, const char *path, bool gz,
                                         drift_scene_input_fn on_input, void *user,
                                         drift_scene **out_scene)
{
    char *text = NULL;
    size_t size = 0;
    drift_result r = drift__read_file(ctx, path, gz, path, 0, &text, &size);
    if (r != DRIFT_OK) {
        return r;
    }
    if (on_input) {
        on_input(path, user);
    }
    char base_dir[DRIFT__PATH_MAX];
    dirname_of(path, base_dir, sizeof(base_dir));
    r = drift__scene_load_json_text(ctx, text, size, base_dir, path, on_input, user, out_scene);
    drift_free(ctx, text);
    return r;
}
