// What assimp 5.2 does not tell about a glTF 2.0 file, read from its JSON with cJSON.
//
// assimp gives drift the geometry, the node graph, textures and cameras, but it multiplies
// KHR_lights_punctual intensities into the colour without their units, drops
// KHR_materials_emissive_strength and keeps no list of the extensions it ignored. This file
// parses the same file's JSON (a .gltf, or the JSON chunk of a .glb) for those fields only:
// the light units (candela, lux) become drift's radiometric W/sr and W/m² through the
// 683 lm/W luminous efficacy the glTF specification uses, and the metallic-roughness
// material becomes drift's diffuse + glossy material by the rule in docs/scene-format.md.
//
// Index correspondence: assimp 5.2's glTF importer keeps the order of `materials` (adding
// its default material after them) and of the KHR_lights_punctual `lights`, so entry i of
// each assimp array is entry i of the JSON array.
#include "scene_io_internal.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

// Luminous efficacy of the glTF specification (KHR_lights_punctual): 683 lm/W.
#define GLTF_LUMENS_PER_WATT 683.0f

// Dielectric reflectance at normal incidence of the metallic-roughness model (IOR 1.5).
#define GLTF_DIELECTRIC_F0 0.04f

struct drift__gltf {
    cJSON *root;
    const cJSON *lights;    // extensions.KHR_lights_punctual.lights, or NULL
    const cJSON *materials; // materials, or NULL
    uint8_t *bin;           // a .glb's BIN chunk (buffer 0 without a uri), or NULL
    size_t bin_size;
    char dir[DRIFT__PATH_MAX]; // the file's folder, for its buffers' files
    // The node graph, indexed once (cJSON arrays are lists): nodes[i], the children of node i
    // at children[child_start[i] .. child_start[i + 1]) (-1: not a node index), the scene's
    // root nodes at roots[0 .. root_count).
    const cJSON **nodes;
    int node_count;
    int *child_start, *children, *roots;
    int root_count;
};

// The extensions this file and material_gltf.c turn into drift's quantities; any other in
// extensionsUsed is named in a warning. docs/reference/scene-formats.md prints this table.
const drift__format_row drift__gltf_extensions[] = {
    { "KHR_lights_punctual", "point, spot and directional lights (cd, lux / 683 → W)" },
    { "KHR_materials_emissive_strength", "multiplies emissiveFactor" },
    { "KHR_materials_transmission", "GGX transmission (refracting fraction)" },
    { "KHR_materials_ior", "GGX index of refraction" },
    { "KHR_materials_specular", "tint and strength of the coat's F0" },
    { "KHR_materials_volume", "thickness 0: thin-walled; else solid glass" },
    { "KHR_materials_clearcoat", "GGX clear coat of IOR 1.5 (factor, roughness, their textures)" },
    { "KHR_texture_transform", "offset, rotation, scale and texCoord of a texture" },
};
const size_t drift__gltf_extension_count =
    sizeof drift__gltf_extensions / sizeof *drift__gltf_extensions;

static uint32_t read_u32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

// The JSON text of a .glb (binary glTF): the 12-byte header, then the first chunk, which the
// specification requires to be the JSON chunk.
static bool glb_json(const char *data, size_t size, const char **out_json, size_t *out_length)
{
    const uint8_t *p = (const uint8_t *)data;
    if (size < 20 || memcmp(p, "glTF", 4) != 0 || read_u32(p + 4) != 2) {
        return false;
    }
    uint32_t length = read_u32(p + 12);
    if (memcmp(p + 16, "JSON", 4) != 0 || length > size - 20) {
        return false;
    }
    *out_json = data + 20;
    *out_length = length;
    return true;
}

// A .glb's BIN chunk: after the JSON chunk (padded to 4 bytes), an 8-byte header "BIN\0".
static bool glb_bin(const char *data, size_t size, size_t json_length, const char **out_bin,
                    size_t *out_size)
{
    size_t at = 20 + ((json_length + 3) & ~(size_t)3);
    if (at + 8 > size || memcmp(data + at + 4, "BIN", 4) != 0) {
        return false;
    }
    uint32_t length = read_u32((const uint8_t *)data + at);
    if (length > size - at - 8) {
        return false;
    }
    *out_bin = data + at + 8;
    *out_size = length;
    return true;
}

static drift_result index_nodes(drift_context *ctx, drift__gltf *g);

drift_result drift__gltf_open(drift_context *ctx, const char *path, bool gz, const char *where,
                              int line, drift__gltf **out)
{
    *out = NULL;
    char *data = NULL;
    size_t size = 0;
    drift_result r = drift__read_file(ctx, path, gz, where, line, &data, &size);
    if (r != DRIFT_OK) {
        return r;
    }
    const char *json = data;
    size_t length = size;
    if (size >= 4 && memcmp(data, "glTF", 4) == 0 && !glb_json(data, size, &json, &length)) {
        drift_free(ctx, data);
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_PARSE, where, line,
                  "'%s': not a glTF 2.0 binary (.glb): bad header or no JSON chunk", path);
        return DRIFT_ERR_PARSE;
    }
    const char *error_at = NULL;
    cJSON *root = cJSON_ParseWithLengthOpts(json, length, &error_at, false);
    if (!root) {
        // Where cJSON stopped (its cJSON_GetErrorPtr, without the global state), as a line.
        size_t offset = error_at && error_at >= json ? (size_t)(error_at - json) : 0;
        offset = offset < length ? offset : length;
        int json_line = 1;
        size_t line_start = 0;
        for (size_t i = 0; i < offset; ++i) {
            if (json[i] == '\n') {
                ++json_line;
                line_start = i + 1;
            }
        }
        int column = (int)(offset - line_start) + 1;
        if (json == data) {
            drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_PARSE, path, json_line,
                      "malformed glTF JSON at column %d%s", column,
                      offset == length ? " (the file ends early: cut short?)" : "");
        } else {
            drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_PARSE, where, line,
                      "'%s': the JSON chunk of this .glb is malformed at its line %d, column %d",
                      path, json_line, column);
        }
        drift_free(ctx, data);
        return DRIFT_ERR_PARSE;
    }
    const char *bin = NULL;
    size_t bin_size = 0;
    uint8_t *bin_copy = NULL;
    if (json != data && glb_bin(data, size, length, &bin, &bin_size) && bin_size > 0) {
        bin_copy = drift_alloc(ctx, bin_size);
        if (bin_copy) {
            memcpy(bin_copy, bin, bin_size);
        }
    }
    drift_free(ctx, data);
    if (!cJSON_IsObject(root)) {
        drift_free(ctx, bin_copy);
        cJSON_Delete(root);
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_PARSE, where, line,
                  "'%s': not a glTF 2.0 file: its JSON is malformed or not an object", path);
        return DRIFT_ERR_PARSE;
    }
    drift__gltf *g = drift_alloc(ctx, sizeof(*g));
    if (!g) {
        cJSON_Delete(root);
        drift_free(ctx, bin_copy);
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    *g = (drift__gltf){ .root = root, .bin = bin_copy, .bin_size = bin_copy ? bin_size : 0 };
    const char *slash = strrchr(path, '/');
    if (slash) {
        snprintf(g->dir, sizeof g->dir, "%.*s", (int)(slash - path), path);
    }
    g->materials = cJSON_GetObjectItemCaseSensitive(root, "materials");
    const cJSON *ext = cJSON_GetObjectItemCaseSensitive(root, "extensions");
    const cJSON *punctual = cJSON_GetObjectItemCaseSensitive(ext, "KHR_lights_punctual");
    g->lights = cJSON_GetObjectItemCaseSensitive(punctual, "lights");
    if (!cJSON_IsArray(g->materials)) {
        g->materials = NULL;
    }
    if (!cJSON_IsArray(g->lights)) {
        g->lights = NULL;
    }
    // Ignored extensions: one warning each. Required ones the file cannot be shown without
    // are still loaded (assimp decides what it can read); the warning says so.
    const cJSON *used = cJSON_GetObjectItemCaseSensitive(root, "extensionsUsed");
    const cJSON *required = cJSON_GetObjectItemCaseSensitive(root, "extensionsRequired");
    used = cJSON_IsArray(used) ? used : NULL;
    required = cJSON_IsArray(required) ? required : NULL;
    const cJSON *name;
    cJSON_ArrayForEach(name, used)
    {
        if (!cJSON_IsString(name)) {
            continue;
        }
        bool handled = false;
        for (size_t i = 0; i < drift__gltf_extension_count; ++i) {
            handled = handled || strcmp(name->valuestring, drift__gltf_extensions[i].name) == 0;
        }
        bool is_required = false;
        const cJSON *req;
        cJSON_ArrayForEach(req, required)
        {
            is_required = is_required ||
                          (cJSON_IsString(req) && strcmp(req->valuestring, name->valuestring) == 0);
        }
        if (!handled) {
            drift_log(ctx, DRIFT_LOG_WARNING, DRIFT_ERR_UNSUPPORTED, where, line,
                      "'%s': glTF extension %s is not supported by drift; ignored%s", path,
                      name->valuestring, is_required ? " (the file marks it required)" : "");
        }
    }
    drift__gltf_anim_check(ctx, root, path); // scene_gltf_anim.c: warns of what won't play
    if (index_nodes(ctx, g) != DRIFT_OK) {
        drift__gltf_close(ctx, g);
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    *out = g;
    return DRIFT_OK;
}

void drift__gltf_close(drift_context *ctx, drift__gltf *g)
{
    if (g) {
        cJSON_Delete(g->root);
        drift_free(ctx, g->bin);
        drift_free(ctx, g->nodes);
        drift_free(ctx, g->child_start);
        drift_free(ctx, g->children);
        drift_free(ctx, g->roots);
        drift_free(ctx, g);
    }
}

// A finite number member of `object`, or `fallback` when absent or not a number.
static float number_or(const cJSON *object, const char *key, float fallback)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(object, key);
    return cJSON_IsNumber(v) && isfinite(v->valuedouble) ? (float)v->valuedouble : fallback;
}

// An array member of `object` of `n` numbers, into out (left as is when absent or malformed).
static bool numbers(const cJSON *object, const char *key, float *out, int n)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(object, key);
    if (!cJSON_IsArray(v) || cJSON_GetArraySize(v) < n) {
        return false;
    }
    float tmp[4];
    for (int i = 0; i < n; ++i) {
        const cJSON *e = cJSON_GetArrayItem(v, i);
        if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble)) {
            return false;
        }
        tmp[i] = (float)e->valuedouble;
    }
    memcpy(out, tmp, sizeof(float) * (size_t)n);
    return true;
}

// The cone a file's spot lights mean. Blender's exporter writes Blender's spot (size, blend)
// as outer = size / 2, inner = outer · (1 − blend), and Blender's importer reads them back the
// same way: such a file renders as Cycles shows the spot (DRIFT_SPOT_BLENDER). Any other file
// gets the falloff of KHR_lights_punctual's reference code (DRIFT_SPOT_GLTF).
static drift_spot_falloff gltf_spot_falloff(const drift__gltf *g)
{
    const cJSON *asset = cJSON_GetObjectItemCaseSensitive(g->root, "asset");
    const cJSON *generator = cJSON_GetObjectItemCaseSensitive(asset, "generator");
    static const char blender[] = "Khronos glTF Blender I/O";
    return cJSON_IsString(generator) &&
                   strncmp(generator->valuestring, blender, sizeof blender - 1) == 0
               ? DRIFT_SPOT_BLENDER
               : DRIFT_SPOT_GLTF;
}

bool drift__gltf_get_light(const drift__gltf *g, unsigned index, drift__gltf_light *out)
{
    const cJSON *l = g && g->lights ? cJSON_GetArrayItem(g->lights, (int)index) : NULL;
    if (!cJSON_IsObject(l)) {
        return false;
    }
    float color[3] = { 1.0f, 1.0f, 1.0f };
    numbers(l, "color", color, 3);
    // candela (lm/sr) for point and spot lights, lux (lm/m²) for directional ones; divided by
    // 683 lm/W they are W/sr and W/m², drift's units for those lights.
    float scale = number_or(l, "intensity", 1.0f) / GLTF_LUMENS_PER_WATT;
    out->color = drift_vec3_make(color[0] * scale, color[1] * scale, color[2] * scale);
    const cJSON *spot = cJSON_GetObjectItemCaseSensitive(l, "spot");
    out->outer_angle = number_or(spot, "outerConeAngle", DRIFT_PI / 4.0f);
    out->inner_angle = number_or(spot, "innerConeAngle", 0.0f);
    out->has_range = cJSON_GetObjectItemCaseSensitive(l, "range") != NULL;
    out->falloff = gltf_spot_falloff(g);
    return true;
}

// Glossy exponent of drift's normalized Phong lobe for a glTF roughness (see
// docs/scene-format.md): α = roughness², the Beckmann/Blinn-Phong equivalence n_b = 2/α² − 2
// (Walter et al. 2007), and a quarter of it for a lobe about the mirror direction instead of
// the half vector; kept within [1, 10000].
static float roughness_to_exponent(float roughness)
{
    float alpha = drift_clampf(roughness, 0.0f, 1.0f);
    alpha *= alpha;
    if (alpha < 1e-4f) {
        return 10000.0f;
    }
    float n = 0.25f * (2.0f / (alpha * alpha) - 2.0f);
    return drift_clampf(n, 1.0f, 10000.0f);
}

// array[index] for a JSON number index, or NULL when it is not an integer in range.
static const cJSON *item_at(const cJSON *array, const cJSON *index)
{
    if (!cJSON_IsArray(array) || !cJSON_IsNumber(index) || !(index->valuedouble >= 0.0) ||
        index->valuedouble >= (double)cJSON_GetArraySize(array)) {
        return NULL;
    }
    return cJSON_GetArrayItem(array, (int)index->valuedouble);
}

bool drift__gltf_get_material(const drift__gltf *g, unsigned index, drift__gltf_material *out)
{
    const cJSON *m = g && g->materials ? cJSON_GetArrayItem(g->materials, (int)index) : NULL;
    if (!cJSON_IsObject(m)) {
        return false;
    }
    const cJSON *pbr = cJSON_GetObjectItemCaseSensitive(m, "pbrMetallicRoughness");
    float base[4] = { 1.0f, 1.0f, 1.0f, 1.0f };
    numbers(pbr, "baseColorFactor", base, 4);
    float metallic = drift_clampf(number_or(pbr, "metallicFactor", 1.0f), 0.0f, 1.0f);
    float roughness = drift_clampf(number_or(pbr, "roughnessFactor", 1.0f), 0.0f, 1.0f);
    drift_vec3 base_color =
        drift_vec3_make(drift_clampf(base[0], 0.0f, 1.0f), drift_clampf(base[1], 0.0f, 1.0f),
                        drift_clampf(base[2], 0.0f, 1.0f));
    // Metals reflect their base colour; dielectrics reflect 4% at normal incidence on top of
    // an undimmed diffuse base, as Blender's Principled BSDF does (the base is cut only where
    // base + 4% would pass 1, drift's bound on kd + ks).
    out->specular = drift_vec3_add(drift_vec3_splat(GLTF_DIELECTRIC_F0 * (1.0f - metallic)),
                                   drift_vec3_scale(base_color, metallic));
    drift_vec3 d = drift_vec3_scale(base_color, 1.0f - metallic);
    out->diffuse =
        drift_vec3_make(fminf(d.x, 1.0f - out->specular.x), fminf(d.y, 1.0f - out->specular.y),
                        fminf(d.z, 1.0f - out->specular.z));
    out->exponent = roughness_to_exponent(roughness);
    out->roughness = roughness;
    float emissive[3] = { 0.0f, 0.0f, 0.0f };
    numbers(m, "emissiveFactor", emissive, 3);
    const cJSON *ext = cJSON_GetObjectItemCaseSensitive(m, "extensions");
    const cJSON *es = cJSON_GetObjectItemCaseSensitive(ext, "KHR_materials_emissive_strength");
    float strength = fmaxf(number_or(es, "emissiveStrength", 1.0f), 0.0f);
    out->emission =
        drift_vec3_make(fmaxf(emissive[0], 0.0f) * strength, fmaxf(emissive[1], 0.0f) * strength,
                        fmaxf(emissive[2], 0.0f) * strength);
    out->double_sided = cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(m, "doubleSided"));
    const cJSON *alpha_mode = cJSON_GetObjectItemCaseSensitive(m, "alphaMode");
    const char *mode = cJSON_IsString(alpha_mode) ? alpha_mode->valuestring : "OPAQUE";
    out->alpha_mode = strcmp(mode, "MASK") == 0    ? DRIFT_ALPHA_MASK
                      : strcmp(mode, "BLEND") == 0 ? DRIFT_ALPHA_BLEND
                                                   : DRIFT_ALPHA_OPAQUE;
    out->alpha_cutoff = drift_clampf(number_or(m, "alphaCutoff", 0.5f), 0.0f, 1.0f);
    out->opacity = drift_clampf(base[3], 0.0f, 1.0f);
    drift__gltf_read_ggx(g->root, m, out);
    return true;
}

int drift__gltf_camera_index(const drift__gltf *g, const char *selector)
{
    const cJSON *cameras = g ? cJSON_GetObjectItemCaseSensitive(g->root, "cameras") : NULL;
    int count = cJSON_IsArray(cameras) ? cJSON_GetArraySize(cameras) : 0;
    char *end = NULL;
    long index = strtol(selector, &end, 10);
    if (end != selector && *end == '\0') {
        return index >= 0 && index < count ? (int)index : -1;
    }
    for (int i = 0; i < count; ++i) {
        const cJSON *name =
            cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(cameras, i), "name");
        if (cJSON_IsString(name) && strcmp(name->valuestring, selector) == 0) {
            return i;
        }
    }
    return -1;
}

// `node` when it is the node assimp named `ai_name` with `ai_children` children: the same
// number of children and, where the file names the node, the same name.
static int matched_node(const drift__gltf *g, int node, const char *ai_name, unsigned ai_children)
{
    if (node < 0) {
        return DRIFT__GLTF_NO_NODE;
    }
    const cJSON *name = cJSON_GetObjectItemCaseSensitive(g->nodes[node], "name");
    unsigned count = (unsigned)(g->child_start[node + 1] - g->child_start[node]);
    bool named = cJSON_IsString(name) && name->valuestring[0] != '\0';
    if (count != ai_children || (named && strcmp(name->valuestring, ai_name) != 0)) {
        return DRIFT__GLTF_NO_NODE;
    }
    return node;
}

// assimp 5.2 makes a scene's only root node its root, and adds a root above several.
int drift__gltf_root_node(const drift__gltf *g, const char *ai_name, unsigned ai_children)
{
    if (!g || !g->nodes) {
        return DRIFT__GLTF_NO_NODE;
    }
    if (g->root_count == 1) {
        return matched_node(g, g->roots[0], ai_name, ai_children);
    }
    return g->root_count > 1 && (unsigned)g->root_count == ai_children ? DRIFT__GLTF_SCENE_ROOT
                                                                       : DRIFT__GLTF_NO_NODE;
}

int drift__gltf_child_node(const drift__gltf *g, int parent, unsigned position, const char *ai_name,
                           unsigned ai_children)
{
    if (!g || !g->nodes || parent == DRIFT__GLTF_NO_NODE) {
        return DRIFT__GLTF_NO_NODE;
    }
    if (parent == DRIFT__GLTF_SCENE_ROOT) {
        return position < (unsigned)g->root_count
                   ? matched_node(g, g->roots[position], ai_name, ai_children)
                   : DRIFT__GLTF_NO_NODE;
    }
    if (parent < 0 || parent >= g->node_count) {
        return DRIFT__GLTF_NO_NODE;
    }
    unsigned count = (unsigned)(g->child_start[parent + 1] - g->child_start[parent]);
    return position < count ? matched_node(g, g->children[g->child_start[parent] + (int)position],
                                           ai_name, ai_children)
                            : DRIFT__GLTF_NO_NODE;
}

// -1 unless v is the index of one of the file's nodes.
static int node_index_of(const drift__gltf *g, const cJSON *v)
{
    double d = cJSON_IsNumber(v) ? v->valuedouble : -1.0;
    return d >= 0.0 && d < (double)g->node_count && d == floor(d) ? (int)d : -1;
}

// Builds g's node index (the walk of drift__gltf_child_node is then linear in the nodes).
static drift_result index_nodes(drift_context *ctx, drift__gltf *g)
{
    const cJSON *nodes = cJSON_GetObjectItemCaseSensitive(g->root, "nodes");
    int n = cJSON_IsArray(nodes) ? cJSON_GetArraySize(nodes) : 0;
    const cJSON *scenes = cJSON_GetObjectItemCaseSensitive(g->root, "scenes");
    const cJSON *scene = cJSON_GetObjectItemCaseSensitive(g->root, "scene");
    const cJSON *chosen = scene ? item_at(scenes, scene) : cJSON_GetArrayItem(scenes, 0);
    const cJSON *roots = cJSON_GetObjectItemCaseSensitive(chosen, "nodes");
    if (!cJSON_IsArray(nodes)) {
        nodes = NULL; // no node: every count below is 0 (an object's members are no nodes)
    }
    if (!cJSON_IsArray(roots)) {
        roots = NULL;
    }
    int total = 0, i = 0;
    const cJSON *node, *c;
    cJSON_ArrayForEach(node, nodes)
    {
        const cJSON *kids = cJSON_GetObjectItemCaseSensitive(node, "children");
        total += cJSON_IsArray(kids) ? cJSON_GetArraySize(kids) : 0;
    }
    g->root_count = roots ? cJSON_GetArraySize(roots) : 0;
    g->nodes = drift_alloc(ctx, ((size_t)n + 1) * sizeof *g->nodes);
    g->child_start = drift_alloc(ctx, ((size_t)n + 1) * sizeof(int));
    g->children = drift_alloc(ctx, ((size_t)total + 1) * sizeof(int));
    g->roots = drift_alloc(ctx, ((size_t)g->root_count + 1) * sizeof(int));
    if (!g->nodes || !g->child_start || !g->children || !g->roots) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    g->node_count = n;
    int k = 0;
    cJSON_ArrayForEach(node, nodes)
    {
        const cJSON *kids = cJSON_GetObjectItemCaseSensitive(node, "children");
        if (!cJSON_IsArray(kids)) {
            kids = NULL;
        }
        g->nodes[i] = node;
        g->child_start[i++] = k;
        cJSON_ArrayForEach(c, kids)
        {
            g->children[k++] = node_index_of(g, c);
        }
    }
    g->child_start[n] = k;
    k = 0;
    cJSON_ArrayForEach(c, roots)
    {
        g->roots[k++] = node_index_of(g, c);
    }
    return DRIFT_OK;
}

// Bytes [offset, offset + length) of buffer `index`: the .glb's BIN chunk, a data URI or a file
// beside the glTF; *out_data allocated.
static drift_result buffer_bytes(drift_context *ctx, const drift__gltf *g, const cJSON *index,
                                 size_t offset, size_t length, uint8_t **out_data)
{
    const cJSON *buffer = item_at(cJSON_GetObjectItemCaseSensitive(g->root, "buffers"), index);
    if (!buffer) {
        return DRIFT_ERR_PARSE;
    }
    const cJSON *uri = cJSON_GetObjectItemCaseSensitive(buffer, "uri");
    uint8_t *whole = NULL;
    size_t size = 0;
    drift_result r = DRIFT_OK;
    if (!cJSON_IsString(uri)) {
        if (!g->bin) {
            return DRIFT_ERR_PARSE;
        }
        whole = g->bin;
        size = g->bin_size;
    } else if (strncmp(uri->valuestring, "data:", 5) == 0) {
        r = drift__data_uri_decode(ctx, uri->valuestring, &whole, &size);
    } else {
        char path[DRIFT__PATH_MAX];
        char *text = NULL;
        r = drift__path_join(g->dir, uri->valuestring, path, sizeof path)
                ? drift__read_file(ctx, path, false, path, 0, &text, &size)
                : DRIFT_ERR_IO;
        whole = (uint8_t *)text;
    }
    if (r == DRIFT_OK && (offset > size || length > size - offset)) {
        r = DRIFT_ERR_PARSE;
    }
    uint8_t *out = r == DRIFT_OK ? drift_alloc(ctx, length ? length : 1) : NULL;
    if (r == DRIFT_OK && !out) {
        r = DRIFT_ERR_OUT_OF_MEMORY;
    }
    if (out) {
        memcpy(out, whole + offset, length);
    }
    if (whole != g->bin) {
        drift_free(ctx, whole);
    }
    *out_data = out;
    return r;
}

drift_result drift__gltf_image_bytes(drift_context *ctx, const drift__gltf *g, int image,
                                     uint8_t **out_data, size_t *out_size)
{
    *out_data = NULL;
    *out_size = 0;
    const cJSON *images = cJSON_GetObjectItemCaseSensitive(g->root, "images");
    const cJSON *img =
        image >= 0 && image < cJSON_GetArraySize(images) ? cJSON_GetArrayItem(images, image) : NULL;
    if (!cJSON_IsObject(img)) {
        return DRIFT_ERR_PARSE;
    }
    const cJSON *uri = cJSON_GetObjectItemCaseSensitive(img, "uri");
    if (cJSON_IsString(uri)) {
        return strncmp(uri->valuestring, "data:", 5) == 0
                   ? drift__data_uri_decode(ctx, uri->valuestring, out_data, out_size)
                   : DRIFT_ERR_UNSUPPORTED; // a file of its own
    }
    const cJSON *view = item_at(cJSON_GetObjectItemCaseSensitive(g->root, "bufferViews"),
                                cJSON_GetObjectItemCaseSensitive(img, "bufferView"));
    if (!view) {
        return DRIFT_ERR_PARSE;
    }
    float offset = number_or(view, "byteOffset", 0.0f),
          length = number_or(view, "byteLength", -1.0f);
    if (!(offset >= 0.0f) || !(length >= 0.0f) || offset > 4e9f || length > 4e9f) {
        return DRIFT_ERR_PARSE;
    }
    *out_size = (size_t)length;
    return buffer_bytes(ctx, g, cJSON_GetObjectItemCaseSensitive(view, "buffer"), (size_t)offset,
                        (size_t)length, out_data);
}

const cJSON *drift__gltf_root(const drift__gltf *g)
{
    return g ? g->root : NULL;
}

void drift__gltf_camera_names(const drift__gltf *g, char *out, size_t out_size)
{
    out[0] = '\0';
    const cJSON *cameras = g ? cJSON_GetObjectItemCaseSensitive(g->root, "cameras") : NULL;
    int count = cJSON_IsArray(cameras) ? cJSON_GetArraySize(cameras) : 0;
    size_t used = 0;
    for (int i = 0; i < count && used + 4 < out_size; ++i) {
        const cJSON *name =
            cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(cameras, i), "name");
        int n = cJSON_IsString(name)
                    ? snprintf(out + used, out_size - used, "%s%d '%s'", i ? ", " : "", i,
                               name->valuestring)
                    : snprintf(out + used, out_size - used, "%s%d", i ? ", " : "", i);
        if (n < 0 || (size_t)n >= out_size - used) {
            snprintf(out + (out_size > 4 ? out_size - 4 : 0), out_size > 4 ? 4 : out_size, "...");
            return;
        }
        used += (size_t)n;
    }
}
