// The scene loaders' registry: one row per file format, its extension, what it is, whether
// it is read gzip-compressed and whether a scene file may name it as a mesh, and the function
// that loads it. drift_scene_load dispatches through it, the JSON scene's mesh check and the
// error messages list from it, and the commands' --help and docs print it
// (drift_scene_format_get). A new format is one row here and its load function.
#include "drift/scene_io.h"
#include "scene_io_internal.h"

#include <stdio.h>
#include <string.h>

// Mitsuba 0.6 and 3 (scene_mitsuba.c tells them apart by the file's version); not gzip.
static drift_result load_mitsuba(drift_context *ctx, const char *path, bool gz,
                                 drift_scene_input_fn on_input, void *user, drift_scene **out_scene)
{
    (void)gz;
    return drift__scene_load_mitsuba(ctx, path, on_input, user, out_scene);
}

typedef struct loader {
    drift_scene_format format;
    drift__scene_load_fn load;
} loader;

static const loader loaders[] = {
    { { "json", "drift scene file (docs/scene-format.md)", true, false },
      drift__scene_load_json_file },
    { { "obj", "Wavefront OBJ mesh and its .mtl libraries, through assimp", true, true },
      drift__scene_load_mesh_file },
    { { "gltf", "glTF 2.0 (JSON, with its .bin and images), through assimp", true, true },
      drift__scene_load_mesh_file },
    { { "glb", "binary glTF 2.0, through assimp", true, true }, drift__scene_load_mesh_file },
    { { "ply", "Stanford PLY mesh, through assimp", true, true }, drift__scene_load_mesh_file },
    { { "xml", "Mitsuba 0.6 or 3 scene (the subset docs/scene-format.md lists), with expat", false,
        false },
      load_mitsuba },
};

enum {
    LOADER_COUNT = sizeof loaders / sizeof *loaders
};

int drift_scene_format_count(void)
{
    return LOADER_COUNT;
}

const drift_scene_format *drift_scene_format_get(int index)
{
    return index >= 0 && index < LOADER_COUNT ? &loaders[index].format : NULL;
}

static const loader *loader_of(const char *path, bool *out_gz)
{
    char ext[16];
    bool gz = false;
    drift__path_extension(path ? path : "", ext, sizeof ext, &gz);
    for (int i = 0; i < LOADER_COUNT; ++i) {
        if (strcmp(ext, loaders[i].format.extension) == 0 && (!gz || loaders[i].format.gz)) {
            if (out_gz) {
                *out_gz = gz;
            }
            return &loaders[i];
        }
    }
    return NULL;
}

const drift_scene_format *drift_scene_format_of(const char *path)
{
    const loader *l = loader_of(path, NULL);
    return l ? &l->format : NULL;
}

drift__scene_load_fn drift__scene_loader_of(const char *path, bool *out_gz)
{
    const loader *l = loader_of(path, out_gz);
    return l ? l->load : NULL;
}

bool drift__is_mesh_extension(const char *ext)
{
    for (int i = 0; i < LOADER_COUNT; ++i) {
        if (loaders[i].format.mesh && strcmp(ext, loaders[i].format.extension) == 0) {
            return true;
        }
    }
    return false;
}

// Appends to out[*at ..] like snprintf, never past size.
static void append(char *out, size_t size, size_t *at, const char *text)
{
    int n = snprintf(out + *at, size - *at, "%s", text);
    size_t wrote = n > 0 ? (size_t)n : 0;
    *at = *at + wrote < size ? *at + wrote : size - 1;
}

void drift__scene_formats_text(char *out, size_t size, bool mesh_only)
{
    size_t at = 0;
    out[0] = '\0';
    // Those read gzip-compressed first, then the others.
    for (int pass = 0; pass < 2; ++pass) {
        bool listed = false;
        for (int i = 0; i < LOADER_COUNT; ++i) {
            const drift_scene_format *f = &loaders[i].format;
            if ((mesh_only && !f->mesh) || f->gz != (pass == 0)) {
                continue;
            }
            append(out, size, &at, at ? ", ." : ".");
            append(out, size, &at, f->extension);
            listed = true;
        }
        if (pass == 0 && listed) {
            append(out, size, &at, " (each optionally .gz)");
        }
    }
}
