// Internal to the assimp importer (scene_assimp.c, scene_assimp_materials.c): the import's
// state and the helpers both stages use.
#ifndef DRIFT_SCENE_ASSIMP_INTERNAL_H
#define DRIFT_SCENE_ASSIMP_INTERNAL_H

#include "scene_io_internal.h"

#include <assimp/scene.h>

typedef struct import_state {
    drift_scene *scene;
    drift_context *ctx;
    const struct aiScene *ai;
    const drift__import_params *params;
    const char *where;
    int line;
    char dir[DRIFT__PATH_MAX]; // folder of the mesh file, for texture paths
    bool is_gltf;              // .gltf or .glb: glTF camera conventions
    const char *base_name;     // file name without folder, for unnamed meshes and materials
    uint32_t *material_map;    // assimp material -> drift material
    bool *light_placed;        // assimp light already added through its node
    uint32_t *embedded;        // assimp embedded texture -> drift texture (or invalid)
    drift__gltf *gltf;         // the glTF JSON (glTF files only)
    drift__obj *obj;           // the OBJ and MTL text (OBJ files only)
    unsigned camera;           // assimp camera to use (glTF: chosen by params->camera)
    drift__import_info *info;
} import_state;

// An aiString into out (cut at out_size - 1).
void drift__ai_name(const struct aiString *s, char *out, size_t out_size);
// The file's materials into the scene (s->material_map): assimp's colours, then glTF's JSON
// or the OBJ's MTL text where they say more (scene_assimp_materials.c).
drift_result drift__assimp_convert_materials(import_state *s);

#endif
