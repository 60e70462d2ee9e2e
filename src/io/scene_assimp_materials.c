// The assimp importer's materials (scene_assimp.c imports the rest): assimp's colours and
// diffuse texture, then what glTF's JSON (material_gltf.c) or the OBJ's MTL text
// (scene_obj.c) says that assimp does not: GGX, the other textures, coverage.
#include "drift/image_io.h"
#include "scene_assimp_internal.h"

#include <assimp/material.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

void drift__ai_name(const struct aiString *s, char *out, size_t out_size)
{
    size_t n = s->length < out_size - 1 ? s->length : out_size - 1;
    memcpy(out, s->data, n);
    out[n] = '\0';
}

static drift_vec3 ai_color3(const struct aiMaterial *mat, const char *key, unsigned type,
                            unsigned index, bool *found)
{
    struct aiColor4D c;
    if (aiGetMaterialColor(mat, key, type, index, &c) == AI_SUCCESS) {
        *found = true;
        return drift_vec3_make(c.r, c.g, c.b);
    }
    *found = false;
    return drift_vec3_splat(0.0f);
}

// Loads the diffuse texture of `mat`, if any. A texture that cannot be loaded is a
// warning: the material keeps its colour, as viewers do.
static void material_texture(import_state *s, const struct aiMaterial *mat, drift_material *m)
{
    struct aiString tex;

    enum aiTextureType types[2] = { aiTextureType_DIFFUSE, aiTextureType_BASE_COLOR };

    for (int t = 0; t < 2; ++t) {
        if (aiGetMaterialTexture(mat, types[t], 0, &tex, NULL, NULL, NULL, NULL, NULL, NULL) !=
            AI_SUCCESS) {
            continue;
        }
        char rel[DRIFT__PATH_MAX];
        drift__ai_name(&tex, rel, sizeof(rel));
        uint32_t index;
        if (rel[0] != '\0' && drift__is_embedded_texture(s->ai, rel)) { // .glb, data URI
            if (drift__embedded_texture(s->scene, s->ai, rel, s->embedded, s->where, s->line,
                                        &index) != DRIFT_OK) {
                drift_log(s->ctx, DRIFT_LOG_WARNING, DRIFT_ERR_IO, s->where, s->line,
                          "material '%s': embedded texture %s not loaded; using its colour",
                          m->name, rel);
                return;
            }
            m->diffuse_texture = index;
            m->diffuse = drift_vec3_is_zero(m->diffuse) ? drift_vec3_splat(1.0f) : m->diffuse;
            return;
        }
        if (rel[0] == '\0') {
            return;
        }
        // Files written on Windows use backslashes.
        for (char *c = rel; *c; ++c) {
            if (*c == '\\') {
                *c = '/';
            }
        }
        // An MTL's map_Kd as its text says (whitespace and options removed), named by the
        // library's file and line when it cannot be loaded.
        const drift__obj_material *om = drift__obj_get_material(s->obj, m->name);
        bool from_mtl = om && om->map_kd[0];
        if (from_mtl) {
            snprintf(rel, sizeof rel, "%s", om->map_kd);
        }
        const char *where = from_mtl ? om->mtl_path : s->where;
        int line = from_mtl ? om->map_kd_line : s->line;
        char full[DRIFT__PATH_MAX];
        if (!drift__path_join(s->dir, rel, full, sizeof(full)) ||
            drift__texture_cache_get(s->scene, s->params->textures, full, where, line, &index) !=
                DRIFT_OK) {
            drift_log(s->ctx, DRIFT_LOG_WARNING, DRIFT_ERR_IO, where, line,
                      "material '%s': texture '%s' not loaded; using its colour", m->name, rel);
            return;
        }
        if (from_mtl && !om->has_kd) {
            m->diffuse = drift_vec3_splat(1.0f); // Blender writes map_Kd without Kd: the texture
        }
        m->diffuse_texture = index;
        // A texture multiplies the diffuse colour; a black Kd would hide it.
        if (drift_vec3_is_zero(m->diffuse)) {
            m->diffuse = drift_vec3_splat(1.0f);
        }
        return;
    }
}

// An MTL's opacity: d (or 1 - Tr) times map_d's alpha (its grey where it has none), drawn as
// stochastic transparency, as Blender's OBJ importer makes it (Principled Alpha) and Cycles
// renders it. A map_d that cannot be loaded is a warning naming its line; d alone then holds.
static void obj_opacity(import_state *s, const drift__obj_material *om, drift_material *m)
{
    uint32_t texture = DRIFT_INVALID_INDEX;
    if (om->map_d_line > 0) {
        char full[DRIFT__PATH_MAX];
        drift_image alpha = { 0 };
        size_t size = 0;
        drift_result r =
            drift__path_join(s->dir, om->map_d, full, sizeof full) ? DRIFT_OK : DRIFT_ERR_IO;
        r = r ? r : drift__check_file(s->ctx, full, om->mtl_path, om->map_d_line, &size);
        r = r ? r : drift_image_load_alpha(s->ctx, full, DRIFT_ALPHA_OR_GREY, &alpha);
        r = r ? r : drift_scene_add_texture(s->scene, alpha, &texture);
        if (r != DRIFT_OK) {
            texture = DRIFT_INVALID_INDEX;
            drift_log(s->ctx, DRIFT_LOG_WARNING, r, om->mtl_path, om->map_d_line,
                      "material '%s': map_d '%s' not loaded; its d alone is the opacity", m->name,
                      om->map_d);
        }
    }
    if (om->dissolve < 1.0f || texture != DRIFT_INVALID_INDEX) {
        m->alpha_mode = DRIFT_ALPHA_BLEND;
        m->opacity = om->dissolve;
        m->opacity_texture = texture;
    }
}

drift_result drift__assimp_convert_materials(import_state *s)
{
    const struct aiScene *ai = s->ai;
    for (unsigned i = 0; i < ai->mNumMaterials; ++i) {
        const struct aiMaterial *mat = ai->mMaterials[i];
        drift_material m = drift_material_make(drift_vec3_splat(0.5f));
        struct aiString name;
        if (aiGetMaterialString(mat, AI_MATKEY_NAME, &name) == AI_SUCCESS) {
            drift__ai_name(&name, m.name, sizeof(m.name));
        }
        if (!m.name[0]) {
            snprintf(m.name, sizeof(m.name), "%s#material%u", s->base_name, i);
        }
        bool found;
        drift_vec3 kd = ai_color3(mat, AI_MATKEY_COLOR_DIFFUSE, &found);
        if (!found) {
            kd = ai_color3(mat, AI_MATKEY_BASE_COLOR, &found);
        }
        if (found) {
            m.diffuse = kd;
        }
        m.specular = ai_color3(mat, AI_MATKEY_COLOR_SPECULAR, &found);
        float shininess = 0.0f;
        if (aiGetMaterialFloatArray(mat, AI_MATKEY_SHININESS, &shininess, NULL) == AI_SUCCESS) {
            // MTL Ns is the Phong exponent; drift's glossy lobe is normalized Phong.
            m.exponent = shininess;
        }
        if (!drift_vec3_is_zero(m.specular) && !(m.exponent > 0.0f)) {
            // Common (PLY default materials, MTL without Ns), so not worth a warning.
            drift_log(s->ctx, DRIFT_LOG_INFO, DRIFT_ERR_INVALID_ARGUMENT, s->where, s->line,
                      "material '%s' has a specular colour but no exponent; specular dropped",
                      m.name);
            m.specular = drift_vec3_splat(0.0f);
            m.exponent = 0.0f;
        }
        m.emission = ai_color3(mat, AI_MATKEY_COLOR_EMISSIVE, &found);
        float strength = 1.0f;
        if (aiGetMaterialFloatArray(mat, AI_MATKEY_EMISSIVE_INTENSITY, &strength, NULL) ==
            AI_SUCCESS) {
            m.emission = drift_vec3_scale(m.emission, strength);
        }
        drift__gltf_material gm;
        if (drift__gltf_get_material(s->gltf, i, &gm)) {
            drift__gltf_material_apply(s->scene, s->gltf, &gm, s->dir, s->params->textures,
                                       s->params->path, s->where, s->line, &m);
        }
        material_texture(s, mat, &m);
        const drift__obj_material *om = drift__obj_get_material(s->obj, m.name);
        if (om && om->blender) { // Blender's MTL: Blender's importer's rule (scene_obj.c)
            drift__obj_blender_material(om, &m);
        }
        if (om) {
            obj_opacity(s, om, &m);
        }
        uint32_t index;
        drift_result r = drift_scene_add_material(s->scene, &m, &index);
        if (r != DRIFT_OK) {
            drift_log(s->ctx, DRIFT_LOG_ERROR, r, s->where, s->line,
                      "material '%s' of '%s' is not valid", m.name, s->params->path);
            return r;
        }
        s->material_map[i] = index;
        if (!drift_vec3_is_zero(m.emission) &&
            s->params->material_override == DRIFT_INVALID_INDEX) {
            s->info->emissive_material_count++;
        }
    }
    return DRIFT_OK;
}
