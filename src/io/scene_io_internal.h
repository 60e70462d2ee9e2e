// Private to the scene loaders in src/io: what scene_load.c (dispatch, gzip, defaults),
// scene_json.c and scene_assimp.c share.
#ifndef DRIFT_SCENE_IO_INTERNAL_H
#define DRIFT_SCENE_IO_INTERNAL_H

#include "drift/scene.h"
#include "drift/scene_io.h"
#include "scene/scene_internal.h" // drift__scene_mesh_bounds

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

// Deepest assimp node graph walked (a guard against cycles and absurd files).
#define DRIFT__SCENE_MAX_NODE_DEPTH 256
#define DRIFT__PATH_MAX             4096

// Textures loaded once per path while one scene loads.
typedef struct drift__texture_cache {
    char **paths;
    uint32_t *indices;
    uint32_t count;
    uint32_t capacity;
    drift_scene_input_fn on_input; // told of each texture and mesh file read (may be NULL)
    void *user;
} drift__texture_cache;

// Returns the scene texture index for the image at `path`, loading it on first use.
// Errors are logged against (where, line).
drift_result drift__texture_cache_get(drift_scene *scene, drift__texture_cache *cache,
                                      const char *path, const char *where, int line,
                                      uint32_t *out_index);
void drift__texture_cache_clear(drift_context *ctx, drift__texture_cache *cache);

// Row-major 4x4 affine transform (the layout of aiMatrix4x4 and of the JSON "matrix").
typedef struct drift__mat4 {
    float m[16];
} drift__mat4;

drift__mat4 drift__mat4_identity(void);
drift__mat4 drift__mat4_mul(const drift__mat4 *a, const drift__mat4 *b);
// t applied to a point (with the translation) and to a direction (without it).
drift_vec3 drift__mat4_point(const drift__mat4 *t, drift_vec3 p);
drift_vec3 drift__mat4_vector(const drift__mat4 *t, drift_vec3 v);

// How to bring one mesh file into a scene.
typedef struct drift__import_params {
    const char *path;             // the mesh file
    const char *where;            // file named in messages about this import (NULL: path)
    int line;                     // line of `where` that asked for the import (0: none)
    const drift__mat4 *transform; // applied after the file's own; NULL: identity
    uint32_t material_override;   // DRIFT_INVALID_INDEX: the file's materials
    drift__texture_cache *textures;
    const char *camera; // glTF: the camera to use, by name or index; NULL: the first
    bool face_normals;  // drop the file's normals: flat shading (Mitsuba's faceNormals)
} drift__import_params;

// What the import found besides geometry.
typedef struct drift__import_info {
    bool has_camera;
    drift_camera camera; // the file's first camera (when has_camera)
    uint32_t mesh_count, light_count, emissive_material_count;
} drift__import_info;

// Imports meshes, materials, lights and the first camera of a mesh file through assimp.
drift_result drift__scene_import_mesh_file(drift_scene *scene, const drift__import_params *params,
                                           drift__import_info *out_info);

// --- Embedded textures (scene_embedded.c): a .glb's images, data URIs ---

struct aiScene;
// Whether an assimp texture reference names a texture inside the file ("*N", or the name of
// one of ai->mTextures).
bool drift__is_embedded_texture(const struct aiScene *ai, const char *ref);
// The scene texture of embedded texture `ref`, decoded on first use; loaded[] (one entry per
// ai->mTextures, DRIFT_INVALID_INDEX at first) remembers them. Warns against (where, line).
drift_result drift__embedded_texture(drift_scene *scene, const struct aiScene *ai, const char *ref,
                                     uint32_t *loaded, const char *where, int line,
                                     uint32_t *out_index);

// --- OBJ and MTL text (scene_obj.c): what assimp 5.2 drops ---

typedef struct drift__obj drift__obj;

// A material of the OBJ's MTL libraries, as its text says.
typedef struct drift__obj_material {
    char name[DRIFT_NAME_MAX];
    bool has_kd;                  // a Kd statement (else, beside map_Kd, the texture alone)
    char map_kd[DRIFT__PATH_MAX]; // map_Kd's file, options and surrounding whitespace removed
    int map_kd_line;              // its line in mtl_path (0: no map_Kd)
    int illum;                    // 2 when not given
    bool blender;                 // the library says Blender 2.8+ wrote it (its header)
    bool has_ks, has_ns;          // Ks, Ns given
    float ks, ns;                 // mean of Ks; Ns
    float dissolve;               // d (1 - Tr), 1 when not given: the material's opacity
    char map_d[DRIFT__PATH_MAX];  // map_d's file (its alpha, or its grey value), as map_kd
    int map_d_line;               // its line in mtl_path (0: no map_d)
    const char *mtl_path;         // the library that defines it
} drift__obj_material;

// Reads the OBJ's text (already in memory) and its MTL libraries. Errors: a file cut short
// (DRIFT_ERR_PARSE, naming the line). A missing library and what drift's material drops are
// warnings naming the file and line.
drift_result drift__obj_open(drift_context *ctx, const char *path, const char *text, size_t size,
                             drift__obj **out);
void drift__obj_close(drift_context *ctx, drift__obj *o);
// Whether object (o) or group (g) `object` has a smoothing group on (s 1 ...).
bool drift__obj_smooth(const drift__obj *o, const char *object);
const drift__obj_material *drift__obj_get_material(const drift__obj *o, const char *name);
// The highlight and diffuse of an MTL material as Blender 3.4's importer reads it: roughness
// 1 − sqrt(Ns / 1000), Principled specular mean(Ks) (F0 = 0.08 · it), Burley diffuse of that
// roughness; drift's glossy lobe by the glTF rule (docs/scene-format.md, "OBJ and MTL").
// m->diffuse holds the colour (Kd or the texture's 1) and is kept below 1 − F0.
void drift__obj_blender_material(const drift__obj_material *om, drift_material *m);
// Area-weighted smooth normals of a triangle mesh (vertices at one position share one).
drift_result drift__smooth_normals(drift_context *ctx, const float *positions, size_t vertex_count,
                                   const uint32_t *indices, size_t triangle_count,
                                   float **out_normals);

// --- glTF JSON (scene_gltf.c): what assimp 5.2 drops ---

typedef struct drift__gltf drift__gltf;

// Reads the animations of a glTF file whose JSON is `root` (scene_gltf_anim.c): one warning
// when they move nodes that hold no camera (rendered at rest), one when they are malformed.
struct cJSON;
void drift__gltf_anim_check(drift_context *ctx, const struct cJSON *root, const char *path);

// A KHR_lights_punctual light in drift's units.
typedef struct drift__gltf_light {
    drift_vec3 color;               // W/sr (point, spot) or W/m² (directional): cd or lux / 683
    float inner_angle, outer_angle; // spot cone half angles, radians (defaults 0, π/4)
    bool has_range;                 // a `range` is given (drift ignores it)
    drift_spot_falloff falloff;     // Blender's exporter wrote the file: Cycles' cone; else glTF's
} drift__gltf_light;

// One texture reference of a glTF material (textureInfo): which image, and how it is read.
typedef struct drift__gltf_texture {
    bool present;              // the material names this texture
    int image;                 // index into the file's `images` (-1: none or malformed)
    char uri[DRIFT__PATH_MAX]; // the image's file, relative to the glTF file ("": inside the file)
    drift_texture_map map;     // sampler, texCoord (KHR_texture_transform's override) and transform
    int tex_coord;             // the texCoord asked for (drift reads sets 0 and 1)
} drift__gltf_texture;

// The form of KHR_materials_clearcoat's coat (drift_ggx_params.clearcoat_principled) a glTF
// file gets: docs/decisions/0411-gltf-clearcoat.md.
#define DRIFT_GLTF_CLEARCOAT_PRINCIPLED true

// A glTF metallic-roughness material as drift's diffuse + glossy (docs/scene-format.md).
typedef struct drift__gltf_material {
    drift_vec3 diffuse, specular, emission; // emission includes KHR_materials_emissive_strength
    float exponent;
    float roughness;             // the Burley diffuse's (the clamped roughnessFactor)
    drift_alpha_mode alpha_mode; // alphaMode, with alphaCutoff and baseColorFactor's alpha
    float alpha_cutoff, opacity;
    bool double_sided; // `doubleSided`: emits from both faces (Cycles does)
    // The same material for DRIFT_MATERIAL_GGX (material_gltf.c): base colour, metallic,
    // roughness and the KHR_materials_transmission / _ior / _specular / _clearcoat values.
    drift_vec3 base_color;
    drift_ggx_params ggx;
    bool has_clearcoat_normal; // clearcoatNormalTexture: not read (docs/materials.md)
    // Its textures by drift_texture_slot (base colour, metallic-roughness, normal, emissive,
    // occlusion), with normalTexture.scale and occlusionTexture.strength.
    drift__gltf_texture textures[DRIFT_TEXTURE_SLOT_COUNT];
    float normal_scale, occlusion_strength;
} drift__gltf_material;

// Fills out->base_color, out->ggx and out->textures from a glTF material object of the file
// whose JSON root is `root` (material_gltf.c).
struct cJSON;
void drift__gltf_read_ggx(const struct cJSON *root, const struct cJSON *material,
                          drift__gltf_material *out);
// Loads texture `t` of a glTF material as a scene texture (material_gltf.c): an image file
// beside the glTF (relative to dir; through `cache` when srgb), or one inside it (a .glb's
// buffer view, a data URI, a buffer file's view). srgb: colour (base, emissive) decoded to
// linear; else data stored as is. Warns against (where, line) when it cannot.
drift_result drift__gltf_load_texture(drift_scene *scene, const drift__gltf *g,
                                      const drift__gltf_texture *t, const char *dir,
                                      drift__texture_cache *cache, bool srgb, const char *where,
                                      int line, uint32_t *out_index);
// The alpha channel of texture `t`'s image (a file beside the glTF or one inside it) as a
// 1-channel scene texture: a MASK or BLEND material's opacity (drift_material).
drift_result drift__gltf_load_alpha(drift_scene *scene, const drift__gltf *g,
                                    const drift__gltf_texture *t, const char *dir,
                                    const char *where, int line, uint32_t *out_index);
// The JSON root of an open glTF.
const struct cJSON *drift__gltf_root(const drift__gltf *g);
// Decodes a base64 `data:` URI (RFC 2397) into *out_data (allocated). DRIFT_ERR_PARSE when it
// is not one.
drift_result drift__data_uri_decode(drift_context *ctx, const char *uri, uint8_t **out_data,
                                    size_t *out_size);
// Material m (named, its assimp colours read) as glTF material gm says: GGX, its textures
// loaded (the base colour's excepted: assimp's), a warning for each part drift cannot hold.
void drift__gltf_material_apply(drift_scene *scene, const drift__gltf *gltf,
                                const drift__gltf_material *gm, const char *dir,
                                drift__texture_cache *cache, const char *path, const char *where,
                                int line, drift_material *m);
// The bytes of image `image` when it is inside the file or its buffers: *out_data allocated
// (drift_free). DRIFT_ERR_UNSUPPORTED when the image is a file of its own (its uri), other errors
// for a malformed reference.
drift_result drift__gltf_image_bytes(drift_context *ctx, const drift__gltf *g, int image,
                                     uint8_t **out_data, size_t *out_size);
// Loads an image of data (metallic-roughness, normals: not sRGB-encoded) as a scene texture.
// Errors are logged against (where, line).
drift_result drift__texture_load_data(drift_scene *scene, const char *path, const char *where,
                                      int line, uint32_t *out_index);

// Reads the JSON of a .gltf or .glb (gunzipped when gz), warns once for each extension in
// extensionsUsed that drift ignores. Errors (logged against where/line, naming path):
// DRIFT_ERR_IO, DRIFT_ERR_PARSE (bad .glb header, malformed JSON).
drift_result drift__gltf_open(drift_context *ctx, const char *path, bool gz, const char *where,
                              int line, drift__gltf **out);
void drift__gltf_close(drift_context *ctx, drift__gltf *g);
// Entry `index` of the file's lights / materials; false when the file has no such entry.
bool drift__gltf_get_light(const drift__gltf *g, unsigned index, drift__gltf_light *out);
bool drift__gltf_get_material(const drift__gltf *g, unsigned index, drift__gltf_material *out);
// The names of the file's cameras, "0 'front', 1 'side'" (an unnamed one by its index alone),
// into out (cut short with "..." when it does not fit).
void drift__gltf_camera_names(const drift__gltf *g, char *out, size_t out_size);
// The index in `cameras` of the camera named `selector`, or numbered by it; -1 if none.
int drift__gltf_camera_index(const drift__gltf *g, const char *selector);
// Which of the file's `nodes` assimp made a node from, found by walking both graphs together:
// the index, DRIFT__GLTF_SCENE_ROOT for the root assimp adds above a scene of several root
// nodes, or DRIFT__GLTF_NO_NODE where the graphs part (names or child counts differ; g NULL).
// _root for assimp's root node, _child for child `position` of a node already matched.
#define DRIFT__GLTF_NO_NODE    (-1)
#define DRIFT__GLTF_SCENE_ROOT (-2)
int drift__gltf_root_node(const drift__gltf *g, const char *ai_name, unsigned ai_children);
int drift__gltf_child_node(const drift__gltf *g, int parent, unsigned position, const char *ai_name,
                           unsigned ai_children);

// Loads a Mitsuba 0.5/0.6 scene file (.xml) with expat (scene_mitsuba.c); on_input as for
// drift_scene_load_inputs.
drift_result drift__scene_load_mitsuba(drift_context *ctx, const char *path,
                                       drift_scene_input_fn on_input, void *user,
                                       drift_scene **out_scene);

// drift_scene_load_json_text that tells on_input of each file read (see drift_scene_load_inputs).
drift_result drift__scene_load_json_text(drift_context *ctx, const char *text, size_t length,
                                         const char *base_dir, const char *name_for_messages,
                                         drift_scene_input_fn on_input, void *user,
                                         drift_scene **out_scene);

// Fails with DRIFT_ERR_IO unless path names a readable regular file (not a directory or a
// device); *out_size gets its size in bytes.
drift_result drift__check_file(drift_context *ctx, const char *path, const char *where, int line,
                               size_t *out_size);

// Reads a whole file into memory (gunzipped when gzip is true), NUL-terminated; size
// excludes the terminator. Errors are logged against `where`/`line`.
drift_result drift__read_file(drift_context *ctx, const char *path, bool gzip, const char *where,
                              int line, char **out_data, size_t *out_size);

// Checks a PLY file's header and that its data holds every element the header declares,
// each with its values (scene_ply.c): errors name path and line (ASCII) or byte offset
// (binary). A header with more elements or properties than any mesh needs is an error.
drift_result drift__ply_check(drift_context *ctx, const char *path, const char *data, size_t size);

// Lower-case extension of path without the dot ("" when none). A trailing ".gz" is looked
// through: "x.obj.gz" gives "obj" and sets *out_gz (false for any other name).
void drift__path_extension(const char *path, char *out, size_t out_size, bool *out_gz);

// True for the extensions of the registry's mesh formats (obj, gltf, glb, ply; lower case).
bool drift__is_mesh_extension(const char *ext);

// --- The loaders' registry (scene_formats.c): extension -> load function ---

// A format's load function: reads `path` (gunzipped when gz) into a committed scene.
typedef drift_result (*drift__scene_load_fn)(drift_context *ctx, const char *path, bool gz,
                                             drift_scene_input_fn on_input, void *user,
                                             drift_scene **out_scene);
// The load function of the format that reads `path` (NULL: none) and, when not NULL, whether
// the file is gzip-compressed.
drift__scene_load_fn drift__scene_loader_of(const char *path, bool *out_gz);
// The registry's extensions as ".json, .obj, ..." (mesh_only: the mesh formats), and the
// gzip note, for messages.
void drift__scene_formats_text(char *out, size_t size, bool mesh_only);

// The registry's load functions: a drift scene file (scene_load.c), a bare mesh file through
// assimp with the camera and lights it lacks (scene_load.c), a Mitsuba file (scene_mitsuba.c).
drift_result drift__scene_load_json_file(drift_context *ctx, const char *path, bool gz,
                                         drift_scene_input_fn on_input, void *user,
                                         drift_scene **out_scene);
drift_result drift__scene_load_mesh_file(drift_context *ctx, const char *path, bool gz,
                                         drift_scene_input_fn on_input, void *user,
                                         drift_scene **out_scene);

// base_dir + "/" + relative (relative unchanged when absolute or base_dir is NULL/empty).
bool drift__path_join(const char *base_dir, const char *relative, char *out, size_t out_size);

// aiImportFile through drift_input_open (scene_assimp_io.c): every file assimp opens (the
// mesh, an OBJ's mtllib, a glTF's buffers) must be a regular file, and each one other than
// `path` is told to on_input (may be NULL). *out_ai is assimp's result (NULL: see
// aiGetErrorString). A side file that is not a regular file (a FIFO, /dev/zero) fails the
// import with an error naming it against (where, line): DRIFT_ERR_IO, *out_ai NULL.
struct aiScene;
drift_result drift__assimp_import_file(drift_context *ctx, const char *path, unsigned flags,
                                       const char *where, int line, drift_scene_input_fn on_input,
                                       void *user, const struct aiScene **out_ai);

// The framing camera of a bare mesh file (see scene_io.h).
drift_camera drift__framing_camera(drift_bounds3 bounds);

// --- What each reader handles (docs/reference/scene-formats.md, scene_formats_doc.c) ---

// One key of an object of the JSON scene or camera-views file (scene_json_keys.c).
typedef struct drift__json_key {
    const char *object;  // "scene", "camera", "material", "light spot", "view", ...
    const char *key;     // its name in the file
    const char *type;    // what its value is ("vec3, required", ...)
    const char *def;     // its default ("": required or fixed)
    const char *meaning; // one line
} drift__json_key;

extern const drift__json_key drift__json_keys[];
extern const size_t drift__json_key_count;
// Whether `key` is a row of `object` (or "comment", allowed everywhere).
bool drift__json_key_known(const char *object, const char *key);

// A name a reader recognises and what drift makes of it.
typedef struct drift__format_row {
    const char *name;
    const char *what;
} drift__format_row;

// glTF extensions read (scene_gltf.c, material_gltf.c); any other warns.
extern const drift__format_row drift__gltf_extensions[];
extern const size_t drift__gltf_extension_count;
// OBJ and MTL statements drift reads beside assimp (scene_obj.c).
extern const drift__format_row drift__obj_statements[];
extern const size_t drift__obj_statement_count;
// Mitsuba elements and plugin types read, as "element type" (scene_mitsuba.c).
extern const drift__format_row drift__mitsuba_plugins[];
extern const size_t drift__mitsuba_plugin_count;

#endif
