// Mesh files through assimp (.obj, .gltf, .glb, .ply, and those gzipped): meshes with the
// node graph's transforms applied, materials, punctual lights and the first camera.
//
// Normals: the file's normals are kept; none are generated, so a file without them is
// shaded flat (right for boxes like the Cornell box). UVs are kept as assimp gives them
// (origin bottom-left, as docs/conventions.md wants).
#include "drift/file.h"
#include "scene_assimp_internal.h"

#include <assimp/cimport.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

drift__mat4 drift__mat4_identity(void)
{
    return (drift__mat4){ { 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1 } };
}

drift__mat4 drift__mat4_mul(const drift__mat4 *a, const drift__mat4 *b)
{
    drift__mat4 r;
    for (int i = 0; i < 4; ++i) {
        for (int j = 0; j < 4; ++j) {
            float s = 0.0f;
            for (int k = 0; k < 4; ++k) {
                s += a->m[4 * i + k] * b->m[4 * k + j];
            }
            r.m[4 * i + j] = s;
        }
    }
    return r;
}

static drift__mat4 mat4_from_ai(const struct aiMatrix4x4 *a)
{
    return (drift__mat4){ { a->a1, a->a2, a->a3, a->a4, a->b1, a->b2, a->b3, a->b4, a->c1, a->c2,
                            a->c3, a->c4, a->d1, a->d2, a->d3, a->d4 } };
}

drift_vec3 drift__mat4_point(const drift__mat4 *t, drift_vec3 p)
{
    const float *m = t->m;
    return drift_vec3_make(m[0] * p.x + m[1] * p.y + m[2] * p.z + m[3],
                           m[4] * p.x + m[5] * p.y + m[6] * p.z + m[7],
                           m[8] * p.x + m[9] * p.y + m[10] * p.z + m[11]);
}

drift_vec3 drift__mat4_vector(const drift__mat4 *t, drift_vec3 v)
{
    const float *m = t->m;
    return drift_vec3_make(m[0] * v.x + m[1] * v.y + m[2] * v.z,
                           m[4] * v.x + m[5] * v.y + m[6] * v.z,
                           m[8] * v.x + m[9] * v.y + m[10] * v.z);
}

static float mat3_determinant(const drift__mat4 *t)
{
    const float *m = t->m;
    return m[0] * (m[5] * m[10] - m[6] * m[9]) - m[1] * (m[4] * m[10] - m[6] * m[8]) +
           m[2] * (m[4] * m[9] - m[5] * m[8]);
}

// Cofactor matrix of the upper 3x3 (= det * inverse transpose): maps normals up to scale.
static void mat3_cofactor(const drift__mat4 *t, float c[9])
{
    const float *m = t->m;
    c[0] = m[5] * m[10] - m[6] * m[9];
    c[1] = m[6] * m[8] - m[4] * m[10];
    c[2] = m[4] * m[9] - m[5] * m[8];
    c[3] = m[2] * m[9] - m[1] * m[10];
    c[4] = m[0] * m[10] - m[2] * m[8];
    c[5] = m[1] * m[8] - m[0] * m[9];
    c[6] = m[1] * m[6] - m[2] * m[5];
    c[7] = m[2] * m[4] - m[0] * m[6];
    c[8] = m[0] * m[5] - m[1] * m[4];
}

static drift_result add_mesh(import_state *s, const struct aiMesh *mesh, const drift__mat4 *world,
                             const char *node_name, int gltf_node)
{
    drift_context *ctx = s->ctx;
    if (!(mesh->mPrimitiveTypes & aiPrimitiveType_TRIANGLE) || mesh->mNumVertices == 0) {
        return DRIFT_OK; // points and lines have no surface to render
    }
    uint32_t tri_count = 0;
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
        tri_count += mesh->mFaces[f].mNumIndices == 3;
    }
    if (tri_count == 0) {
        return DRIFT_OK;
    }
    size_t nv = mesh->mNumVertices;
    // uv sets 0 and 1 (a material's texCoord picks one per texture: drift_texture_map).
    const struct aiVector3D *uv_source = mesh->mTextureCoords[0];
    const struct aiVector3D *uv1_source = uv_source ? mesh->mTextureCoords[1] : NULL;
    // glTF TANGENT (assimp gives t and b = w cross(n, t)); other files' tangents are computed
    // by commit where a normal map needs them.
    bool keep_tangents = s->is_gltf && mesh->mTangents && mesh->mBitangents && mesh->mNormals;
    float *positions = drift_alloc(ctx, nv * 3 * sizeof(float));
    bool keep_normals = mesh->mNormals && !s->params->face_normals;
    float *normals = keep_normals ? drift_alloc(ctx, nv * 3 * sizeof(float)) : NULL;
    float *uvs = uv_source ? drift_alloc(ctx, nv * 2 * sizeof(float)) : NULL;
    float *uvs1 = uv1_source ? drift_alloc(ctx, nv * 2 * sizeof(float)) : NULL;
    float *tangents = keep_tangents ? drift_alloc(ctx, nv * 4 * sizeof(float)) : NULL;
    // glTF COLOR_0 (linear, multiplying the base colour); other formats' vertex colours have no
    // one meaning (a PLY scan's are sRGB bytes, often unused by its material) and are left out.
    const struct aiColor4D *color_source = s->is_gltf ? mesh->mColors[0] : NULL;
    float *colors = color_source ? drift_alloc(ctx, nv * 3 * sizeof(float)) : NULL;
    uint32_t *indices = drift_alloc(ctx, (size_t)tri_count * 3 * sizeof(uint32_t));
    drift_result r = DRIFT_OK;
    if (!positions || !indices || (keep_normals && !normals) || (uv_source && !uvs) ||
        (uv1_source && !uvs1) || (keep_tangents && !tangents) || (color_source && !colors)) {
        r = DRIFT_ERR_OUT_OF_MEMORY;
        goto done;
    }
    float det = mat3_determinant(world);
    float cof[9];
    mat3_cofactor(world, cof);
    float normal_sign = det < 0.0f ? -1.0f : 1.0f;
    for (size_t v = 0; v < nv; ++v) {
        const struct aiVector3D *p = &mesh->mVertices[v];
        drift_vec3 q = drift__mat4_point(world, drift_vec3_make(p->x, p->y, p->z));
        positions[3 * v] = q.x;
        positions[3 * v + 1] = q.y;
        positions[3 * v + 2] = q.z;
        if (normals) {
            const struct aiVector3D *n = &mesh->mNormals[v];
            for (int k = 0; k < 3; ++k) {
                normals[3 * v + (size_t)k] =
                    normal_sign *
                    (cof[3 * k] * n->x + cof[3 * k + 1] * n->y + cof[3 * k + 2] * n->z);
            }
        }
        if (uvs) {
            uvs[2 * v] = uv_source[v].x;
            uvs[2 * v + 1] = uv_source[v].y;
        }
        if (colors) {
            const struct aiColor4D *c = &color_source[v];
            colors[3 * v] = isfinite(c->r) ? fmaxf(c->r, 0.0f) : 1.0f;
            colors[3 * v + 1] = isfinite(c->g) ? fmaxf(c->g, 0.0f) : 1.0f;
            colors[3 * v + 2] = isfinite(c->b) ? fmaxf(c->b, 0.0f) : 1.0f;
        }
        if (uvs1) {
            uvs1[2 * v] = uv1_source[v].x;
            uvs1[2 * v + 1] = uv1_source[v].y;
        }
        if (tangents) {
            const struct aiVector3D *tl = &mesh->mTangents[v], *bl = &mesh->mBitangents[v];
            const struct aiVector3D *nl = &mesh->mNormals[v];
            drift_vec3 tv = drift_vec3_make(tl->x, tl->y, tl->z);
            drift_vec3 nb = drift_vec3_cross(drift_vec3_make(nl->x, nl->y, nl->z), tv);
            float w = nb.x * bl->x + nb.y * bl->y + nb.z * bl->z < 0.0f ? -1.0f : 1.0f;
            drift_vec3 tw = drift_vec3_normalize(drift__mat4_vector(world, tv));
            // A mirroring transform mirrors cross(n, t) against the transformed b: flip w.
            tangents[4 * v] = drift_vec3_is_finite(tw) ? tw.x : 0.0f;
            tangents[4 * v + 1] = drift_vec3_is_finite(tw) ? tw.y : 0.0f;
            tangents[4 * v + 2] = drift_vec3_is_finite(tw) ? tw.z : 0.0f;
            tangents[4 * v + 3] = w * normal_sign;
        }
    }
    // A mirroring transform reverses the winding; swap two corners to keep faces facing out.
    bool flip = det < 0.0f;
    size_t t = 0;
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
        const struct aiFace *face = &mesh->mFaces[f];
        if (face->mNumIndices != 3) {
            continue;
        }
        indices[3 * t] = face->mIndices[0];
        indices[3 * t + 1] = face->mIndices[flip ? 2 : 1];
        indices[3 * t + 2] = face->mIndices[flip ? 1 : 2];
        t++;
    }
    // OBJ smoothing groups (s 1) without normals: smooth, as Blender shows them.
    if (!normals && !mesh->mNormals && !s->params->face_normals &&
        drift__obj_smooth(s->obj, node_name)) {
        r = drift__smooth_normals(ctx, positions, nv, indices, tri_count, &normals);
        if (r != DRIFT_OK) {
            goto done;
        }
    }
    uint32_t material = s->params->material_override;
    if (material == DRIFT_INVALID_INDEX) {
        if (mesh->mMaterialIndex >= s->ai->mNumMaterials) {
            drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_PARSE, s->where, s->line,
                      "'%s': mesh refers to material %u of %u", s->params->path,
                      mesh->mMaterialIndex, s->ai->mNumMaterials);
            r = DRIFT_ERR_PARSE;
            goto done;
        }
        material = s->material_map[mesh->mMaterialIndex];
    }
    char name[DRIFT_NAME_MAX];
    drift__ai_name(&mesh->mName, name, sizeof(name));
    if (!name[0]) {
        snprintf(name, sizeof(name), "%s", node_name[0] ? node_name : s->base_name);
    }
    drift_mesh_desc desc = { .name = name,
                             .positions = positions,
                             .normals = normals,
                             .uvs = uvs,
                             .uvs1 = uvs1,
                             .tangents = tangents,
                             .colors = colors,
                             .indices = indices,
                             .vertex_count = (uint32_t)nv,
                             .triangle_count = tri_count,
                             .material = material };
    uint32_t index = 0;
    r = drift_scene_add_mesh(s->scene, &desc, &index);
    if (r != DRIFT_OK) {
        drift_log(ctx, DRIFT_LOG_ERROR, r, s->where, s->line, "mesh '%s' of '%s' is not valid",
                  name, s->params->path);
        goto done;
    }
    s->scene->meshes[index].node = gltf_node >= 0 ? (uint32_t)gltf_node : DRIFT_INVALID_INDEX;
    s->info->mesh_count++;
done:
    drift_free(ctx, positions);
    drift_free(ctx, normals);
    drift_free(ctx, uvs);
    drift_free(ctx, uvs1);
    drift_free(ctx, colors);
    drift_free(ctx, tangents);
    drift_free(ctx, indices);
    return r;
}

static drift_result add_light(import_state *s, unsigned index, const drift__mat4 *world,
                              int gltf_node)
{
    const struct aiLight *l = s->ai->mLights[index];
    drift_light light = { 0 };
    drift_vec3 position =
        drift__mat4_point(world, drift_vec3_make(l->mPosition.x, l->mPosition.y, l->mPosition.z));
    drift_vec3 direction = drift_vec3_normalize(drift__mat4_vector(
        world, drift_vec3_make(l->mDirection.x, l->mDirection.y, l->mDirection.z)));
    light.color = drift_vec3_make(l->mColorDiffuse.r, l->mColorDiffuse.g, l->mColorDiffuse.b);
    char name[DRIFT_NAME_MAX];
    drift__ai_name(&l->mName, name, sizeof(name));
    switch (l->mType) {
    case aiLightSource_POINT:
        light.type = DRIFT_LIGHT_POINT;
        light.position = position;
        break;
    case aiLightSource_SPOT:
        light.type = DRIFT_LIGHT_SPOT;
        light.position = position;
        light.direction = direction;
        // glTF (KHR_lights_punctual) cone angles arrive as half angles, measured from the axis.
        light.spot_outer = l->mAngleOuterCone > 0.0f && l->mAngleOuterCone <= DRIFT_PI
                               ? l->mAngleOuterCone
                               : DRIFT_PI / 4.0f;
        light.spot_inner = drift_clampf(l->mAngleInnerCone, 0.0f, light.spot_outer);
        break;
    case aiLightSource_DIRECTIONAL:
        light.type = DRIFT_LIGHT_DIRECTIONAL;
        light.direction = direction;
        break;
    case aiLightSource_AMBIENT:
        s->scene->environment.color = drift_vec3_add(s->scene->environment.color, light.color);
        s->info->light_count++;
        return DRIFT_OK;
    default:
        drift_log(s->ctx, DRIFT_LOG_WARNING, DRIFT_ERR_UNSUPPORTED, s->where, s->line,
                  "'%s': light '%s' has an unsupported type; ignored", s->params->path, name);
        return DRIFT_OK;
    }
    drift__gltf_light gl;
    if (drift__gltf_get_light(s->gltf, index, &gl)) {
        // assimp multiplies the intensity into the colour without its unit; take both from
        // the JSON, converted to W/sr or W/m².
        light.color = gl.color;
        if (light.type == DRIFT_LIGHT_SPOT) {
            light.spot_outer = gl.outer_angle > 0.0f && gl.outer_angle <= DRIFT_PI / 2.0f
                                   ? gl.outer_angle
                                   : DRIFT_PI / 4.0f;
            light.spot_inner = drift_clampf(gl.inner_angle, 0.0f, light.spot_outer);
            light.spot_falloff = gl.falloff;
        }
        if (gl.has_range) {
            drift_log(s->ctx, DRIFT_LOG_WARNING, DRIFT_ERR_UNSUPPORTED, s->where, s->line,
                      "'%s': light '%s': range ignored (drift lights fall off as 1/d² without "
                      "a cut-off)",
                      s->params->path, name);
        }
    }
    uint32_t light_index = 0;
    drift_result r = drift_scene_add_light(s->scene, &light, &light_index);
    if (r != DRIFT_OK) {
        drift_log(s->ctx, DRIFT_LOG_ERROR, r, s->where, s->line, "light '%s' of '%s' is not valid",
                  name, s->params->path);
        return r;
    }
    s->scene->lights[light_index].node = gltf_node >= 0 ? (uint32_t)gltf_node : DRIFT_INVALID_INDEX;
    s->info->light_count++;
    return DRIFT_OK;
}

static void set_camera(import_state *s, const struct aiCamera *cam, const drift__mat4 *world)
{
    drift_vec3 local_eye = drift_vec3_make(cam->mPosition.x, cam->mPosition.y, cam->mPosition.z);
    drift_vec3 local_look = drift_vec3_make(cam->mLookAt.x, cam->mLookAt.y, cam->mLookAt.z);
    drift_vec3 local_up = drift_vec3_make(cam->mUp.x, cam->mUp.y, cam->mUp.z);
    float aspect = cam->mAspect > 0.0f && isfinite(cam->mAspect) ? cam->mAspect : 1.0f;
    float fov_y;
    if (s->is_gltf) {
        // glTF cameras sit at their node's origin looking down -z with +y up. assimp 5.2
        // also copies the node's translation into mPosition (applying it twice), and stores
        // yfov * aspect as mHorizontalFOV.
        local_eye = drift_vec3_make(0.0f, 0.0f, 0.0f);
        local_look = drift_vec3_make(0.0f, 0.0f, -1.0f);
        local_up = drift_vec3_make(0.0f, 1.0f, 0.0f);
        fov_y = cam->mHorizontalFOV / aspect;
    } else {
        // Elsewhere mHorizontalFOV is the full horizontal angle.
        fov_y = 2.0f * atanf(tanf(0.5f * cam->mHorizontalFOV) / aspect);
    }
    if (!(fov_y > 0.0f && fov_y < DRIFT_PI)) {
        fov_y = 45.0f * DRIFT_PI / 180.0f;
    }
    if (cam->mOrthographicWidth > 0.0f) {
        // drift's cameras are perspective (thin lens); every technique projects that way.
        drift_log(s->ctx, DRIFT_LOG_WARNING, DRIFT_ERR_UNSUPPORTED, s->where, s->line,
                  "'%s': camera '%s' is orthographic (half width %g); drawn as a perspective "
                  "camera of %.0f degrees from the same place",
                  s->params->path, cam->mName.data, (double)cam->mOrthographicWidth,
                  (double)(fov_y * 180.0f / DRIFT_PI));
    }
    drift_vec3 eye = drift__mat4_point(world, local_eye);
    drift_vec3 look = drift_vec3_normalize(drift__mat4_vector(world, local_look));
    drift_vec3 up = drift_vec3_normalize(drift__mat4_vector(world, local_up));
    int32_t height = 512;
    int32_t width = (int32_t)lroundf(drift_clampf(512.0f * aspect, 1.0f, 8192.0f));
    s->info->camera =
        drift_camera_look_at(eye, drift_vec3_add(eye, look), up, fov_y, width, height);
    s->info->has_camera = true;
}

// gltf_node: the glTF node `node` was made from (drift__gltf_child_node), which the meshes and
// lights it places record for node animation (drift_scene_animation).
static drift_result walk_nodes(import_state *s, const struct aiNode *node,
                               const drift__mat4 *parent, int depth, int gltf_node)
{
    if (depth > DRIFT__SCENE_MAX_NODE_DEPTH) {
        drift_log(s->ctx, DRIFT_LOG_ERROR, DRIFT_ERR_PARSE, s->where, s->line,
                  "'%s': node graph is deeper than %d", s->params->path,
                  DRIFT__SCENE_MAX_NODE_DEPTH);
        return DRIFT_ERR_PARSE;
    }
    drift__mat4 local = mat4_from_ai(&node->mTransformation);
    drift__mat4 world = drift__mat4_mul(parent, &local);
    char node_name[DRIFT_NAME_MAX];
    drift__ai_name(&node->mName, node_name, sizeof(node_name));
    for (unsigned i = 0; i < node->mNumMeshes; ++i) {
        unsigned mi = node->mMeshes[i];
        if (mi >= s->ai->mNumMeshes) {
            continue; // aiProcess_ValidateDataStructure rejects this; stay safe anyway
        }
        drift_result r = add_mesh(s, s->ai->mMeshes[mi], &world, node_name, gltf_node);
        if (r != DRIFT_OK) {
            return r;
        }
    }
    // Cameras and lights are tied to the node of the same name.
    if (!s->info->has_camera && s->camera < s->ai->mNumCameras &&
        strcmp(s->ai->mCameras[s->camera]->mName.data, node->mName.data) == 0) {
        set_camera(s, s->ai->mCameras[s->camera], &world);
    }
    for (unsigned i = 0; i < s->ai->mNumLights; ++i) {
        const struct aiLight *l = s->ai->mLights[i];
        if (!s->light_placed[i] && strcmp(l->mName.data, node->mName.data) == 0) {
            s->light_placed[i] = true;
            drift_result r = add_light(s, i, &world, gltf_node);
            if (r != DRIFT_OK) {
                return r;
            }
        }
    }
    for (unsigned c = 0; c < node->mNumChildren; ++c) {
        const struct aiNode *child = node->mChildren[c];
        char child_name[DRIFT_NAME_MAX];
        drift__ai_name(&child->mName, child_name, sizeof(child_name));
        int gltf_child =
            drift__gltf_child_node(s->gltf, gltf_node, c, child_name, child->mNumChildren);
        drift_result r = walk_nodes(s, child, &world, depth + 1, gltf_child);
        if (r != DRIFT_OK) {
            return r;
        }
    }
    return DRIFT_OK;
}

static drift_result import_scene(import_state *s)
{
    const struct aiScene *ai = s->ai;
    drift_context *ctx = s->ctx;
    drift__mat4 root = s->params->transform ? *s->params->transform : drift__mat4_identity();
    drift_result r = DRIFT_OK;
    s->material_map = drift_alloc(ctx, ((size_t)ai->mNumMaterials + 1) * sizeof(uint32_t));
    s->light_placed = drift_alloc(ctx, ((size_t)ai->mNumLights + 1) * sizeof(bool));
    s->embedded = drift_alloc(ctx, ((size_t)ai->mNumTextures + 1) * sizeof(uint32_t));
    if (!s->material_map || !s->light_placed || !s->embedded) {
        r = DRIFT_ERR_OUT_OF_MEMORY;
    }
    for (unsigned i = 0; r == DRIFT_OK && i < ai->mNumTextures; ++i) {
        s->embedded[i] = DRIFT_INVALID_INDEX;
    }
    if (r == DRIFT_OK) {
        r = drift__assimp_convert_materials(s);
    }
    if (r == DRIFT_OK && ai->mRootNode) {
        char root_name[DRIFT_NAME_MAX];
        drift__ai_name(&ai->mRootNode->mName, root_name, sizeof(root_name));
        int gltf_root = drift__gltf_root_node(s->gltf, root_name, ai->mRootNode->mNumChildren);
        r = walk_nodes(s, ai->mRootNode, &root, 0, gltf_root);
    }
    // Lights no node names are in world space already.
    for (unsigned i = 0; r == DRIFT_OK && i < ai->mNumLights; ++i) {
        if (!s->light_placed[i]) {
            r = add_light(s, i, &root, DRIFT__GLTF_NO_NODE);
        }
    }
    if (r == DRIFT_OK && s->info->mesh_count == 0) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_PARSE, s->where, s->line, "'%s' has no triangles",
                  s->params->path);
        r = DRIFT_ERR_PARSE;
    }
    drift_free(ctx, s->material_map);
    drift_free(ctx, s->light_placed);
    drift_free(ctx, s->embedded);
    return r;
}

// assimp's PLY reader reserves what the header declares before reading any data, so a
// header claiming 10^9 vertices takes gigabytes. Every element takes at least one byte
// (ASCII or binary), which bounds the counts a file of this size can hold.
static drift_result check_ply_header(const import_state *s, const char *head, size_t head_size,
                                     size_t file_size)
{
    size_t pos = 0;
    unsigned long long declared = 0;
    while (pos < head_size) {
        const char *line = head + pos;
        const char *end = memchr(line, '\n', head_size - pos);
        size_t len = end ? (size_t)(end - line) : head_size - pos;
        pos += len + 1;
        if (len >= 10 && memcmp(line, "end_header", 10) == 0) {
            size_t data = file_size > pos ? file_size - pos : 0;
            if (declared > data) {
                drift_log(s->ctx, DRIFT_LOG_ERROR, DRIFT_ERR_PARSE, s->where, s->line,
                          "'%s': the PLY header declares %llu elements but only %zu bytes of "
                          "data follow",
                          s->params->path, declared, data);
                return DRIFT_ERR_PARSE;
            }
            return DRIFT_OK;
        }
        if (len > 8 && memcmp(line, "element ", 8) == 0) {
            char buf[128];
            size_t n = len < sizeof(buf) - 1 ? len : sizeof(buf) - 1;
            memcpy(buf, line, n);
            buf[n] = '\0';
            char name[64];
            unsigned long long count = 0;
            if (sscanf(buf, "element %63s %llu", name, &count) == 2) {
                declared += count > DRIFT_SCENE_MAX_FILE_BYTES ? DRIFT_SCENE_MAX_FILE_BYTES : count;
            }
        }
    }
    return DRIFT_OK; // no end_header in the first bytes: assimp reports the file as broken
}

// Reads the start of a file for check_ply_header.
static drift_result check_ply_file(const import_state *s, size_t file_size)
{
    char head[8192], why[128];
    FILE *f = drift_input_fopen(s->params->path, why, sizeof why);
    if (!f) {
        return DRIFT_OK; // drift__check_file just saw it; let assimp report what changed
    }
    size_t n = fread(head, 1, sizeof(head), f);
    fclose(f);
    return check_ply_header(s, head, n, file_size);
}

drift_result drift__scene_import_mesh_file(drift_scene *scene, const drift__import_params *params,
                                           drift__import_info *out_info)
{
    drift_context *ctx = scene->ctx;
    *out_info = (drift__import_info){ 0 };
    if (params->textures && params->textures->on_input) {
        params->textures->on_input(params->path, params->textures->user);
    }
    import_state s = { .scene = scene,
                       .ctx = ctx,
                       .params = params,
                       .where = params->where ? params->where : params->path,
                       .line = params->line,
                       .info = out_info };
    const char *slash = strrchr(params->path, '/');
    s.base_name = slash ? slash + 1 : params->path;
    if (slash) {
        snprintf(s.dir, sizeof(s.dir), "%.*s", (int)(slash - params->path), params->path);
    }
    if (slash == params->path) {
        snprintf(s.dir, sizeof(s.dir), "/");
    }
    char ext[16];
    bool gz = false;
    drift__path_extension(params->path, ext, sizeof(ext), &gz);
    s.is_gltf = strcmp(ext, "gltf") == 0 || strcmp(ext, "glb") == 0;

    // Triangulate quads and polygons, share vertices, split point/line primitives away from
    // triangles, and let assimp reject out-of-range indices. No normal generation: see top.
    const unsigned flags = aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                           aiProcess_SortByPType | aiProcess_ValidateDataStructure;
    char *data = NULL;
    size_t size = 0;
    // Plain files go to assimp by name so that it finds their side files.
    drift_result r = gz ? drift__read_file(ctx, params->path, true, s.where, s.line, &data, &size)
                        : drift__check_file(ctx, params->path, s.where, s.line, &size);
    if (r != DRIFT_OK) {
        return r;
    }
    if (size == 0) {
        drift_free(ctx, data);
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_PARSE, s.where, s.line, "'%s' is empty",
                  params->path);
        return DRIFT_ERR_PARSE;
    }
    if (strcmp(ext, "ply") == 0) {
        r = gz ? check_ply_header(&s, data, size < 8192 ? size : 8192, size)
               : check_ply_file(&s, size);
        // Then every element, naming the line or byte where assimp would name none.
        char *text = data;
        size_t text_size = size;
        if (r == DRIFT_OK && !gz) {
            r = drift__read_file(ctx, params->path, false, s.where, s.line, &text, &text_size);
        }
        if (r == DRIFT_OK) {
            r = drift__ply_check(ctx, params->path, text, text_size);
        }
        if (text != data) {
            drift_free(ctx, text);
        }
        if (r != DRIFT_OK) {
            drift_free(ctx, data);
            return r;
        }
    }
    if (strcmp(ext, "obj") == 0) { // its text and MTLs: scene_obj.c
        char *text = data;
        size_t text_size = size;
        if (!gz) {
            r = drift__read_file(ctx, params->path, false, s.where, s.line, &text, &text_size);
        }
        if (r == DRIFT_OK) {
            r = drift__obj_open(ctx, params->path, text, text_size, &s.obj);
        }
        if (text != data) {
            drift_free(ctx, text);
        }
        if (r != DRIFT_OK) {
            drift_free(ctx, data);
            return r;
        }
    }
    // glTF's own JSON first: a syntax error is named by line, where assimp names none.
    if (s.is_gltf) {
        r = drift__gltf_open(ctx, params->path, gz, s.where, s.line, &s.gltf);
        if (r != DRIFT_OK) {
            drift_free(ctx, data);
            return r;
        }
    }
    const struct aiScene *ai = NULL;
    if (gz) {
        // From memory, assimp cannot open side files (an OBJ's .mtl, a glTF's .bin).
        ai = aiImportFileFromMemory(data, (unsigned)size, flags, ext);
    } else {
        drift__texture_cache *t = params->textures;
        r = drift__assimp_import_file(ctx, params->path, flags, s.where, s.line,
                                      t ? t->on_input : NULL, t ? t->user : NULL, &ai);
    }
    drift_free(ctx, data);
    if (r != DRIFT_OK) { // a side file that is not a regular file, already said
        drift__gltf_close(ctx, s.gltf);
        return r;
    }
    if (!ai || !ai->mRootNode) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_PARSE, s.where, s.line, "cannot read '%s': %s",
                  params->path, ai ? "no scene" : aiGetErrorString());
        aiReleaseImport(ai);
        drift__gltf_close(ctx, s.gltf);
        drift__obj_close(ctx, s.obj);
        return DRIFT_ERR_PARSE;
    }
    s.ai = ai;
    if (r == DRIFT_OK && params->camera) {
        int camera = s.gltf ? drift__gltf_camera_index(s.gltf, params->camera) : -1;
        if (camera < 0 || (unsigned)camera >= ai->mNumCameras) {
            char names[512];
            drift__gltf_camera_names(s.gltf, names, sizeof names);
            drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, s.where, s.line,
                      "'%s' has no camera named or numbered '%s' (it has %u%s%s)", params->path,
                      params->camera, ai->mNumCameras, names[0] ? ": " : "", names);
            r = DRIFT_ERR_INVALID_ARGUMENT;
        }
        s.camera = (unsigned)camera;
    }
    if (r == DRIFT_OK) {
        r = import_scene(&s);
    }
    drift__gltf_close(ctx, s.gltf);
    drift__obj_close(ctx, s.obj);
    aiReleaseImport(ai);
    return r;
}
