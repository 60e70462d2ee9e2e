// drift scene: the scene as plain data (camera, meshes, materials, lights, textures,
// environment), plus the shading math every renderer shares: camera rays, BSDF
// evaluation and sampling, light sampling and surface reconstruction from a hit.
//
// Data refers to data by index (DRIFT_INVALID_INDEX for none). The scene owns every array
// in it; add_* functions copy what they are given. Positions are in world space (loaders
// apply transforms) and padded by one float so Embree can share them without copies.
//
// STEP BY STEP
//   drift_scene *scene = NULL;
//   drift_scene_create(ctx, &scene);
//   uint32_t white;  drift_scene_add_material(scene, &(drift_material){ .diffuse = {.8f,.8f,.8f} },
//   &white); drift_scene_add_mesh(scene, &(drift_mesh_desc){ .positions = p, .vertex_count = 4,
//                        .indices = idx, .triangle_count = 2, .material = white }, NULL);
//   drift_scene_add_light(scene, &(drift_light){ .type = DRIFT_LIGHT_SPHERE, ... }, NULL);
//   scene->camera = drift_camera_look_at(eye, target, up, fov_y, width, height);
//   if (drift_scene_commit(scene) != DRIFT_OK) { ... }   // validates, builds light tables
//   ... render ...
//   drift_scene_destroy(scene);
//
// Units: scene units are whatever the file uses (the Cornell box is in millimetres);
// angles are radians. Threads: a committed scene is immutable and every const function
// here is thread-safe on it; add_* and commit are not.
//
// Material model (docs/materials.md): Lambertian diffuse plus a normalized modified-Phong
// glossy lobe (Lafortune & Willems 1994), f = kd/pi + ks (n+2)/(2 pi) cos^n(alpha), alpha
// the angle between wi and the mirror direction of wo. With kd + ks <= 1 per channel it
// conserves energy (commit rescales materials that exceed it and warns). A mirror material
// reflects ks along the mirror direction exactly.
#ifndef DRIFT_SCENE_H
#define DRIFT_SCENE_H

#include "drift/core.h"
#include "drift/image.h"
#include "drift/math.h"

#ifdef __cplusplus
extern "C" {
#endif

#define DRIFT_INVALID_INDEX UINT32_MAX
// Limits the loaders and commit enforce ("absurd sizes").
#define DRIFT_SCENE_MAX_TRIANGLES (1u << 28)
#define DRIFT_SCENE_MAX_VERTICES  (1u << 28)
#define DRIFT_SCENE_MAX_LIGHTS    (1u << 24)
// Largest |coordinate| of a vertex, light, camera or probe (scene units): squares and
// cross products stay far inside float range. Embree aborted on positions past ~1.8e18; a
// scene reaching further is refused when it loads or commits (docs/scene-format.md).
#define DRIFT_SCENE_COORD_MAX 1e12
#define DRIFT_NAME_MAX        64

// --- CAMERA ---

// Thin-lens camera; aperture_radius 0 is a pinhole. Looks from position toward target.
typedef struct drift_camera {
    drift_vec3 position;
    drift_vec3 target;
    drift_vec3 up;
    float fov_y;           // full vertical field of view, radians
    float aperture_radius; // lens radius in scene units; 0 = pinhole
    float focus_distance;  // distance to the plane in focus; 0 = |target - position|
    int32_t width, height; // default image size in pixels
    // Pixels added to every film position (rays and projections): the sub-pixel jitter of
    // the hybrid frame's anti-aliasing passes (drift_hybrid_params.aa). Zero for a camera.
    float film_shift_x, film_shift_y;
} drift_camera;

drift_camera drift_camera_look_at(drift_vec3 position, drift_vec3 target, drift_vec3 up,
                                  float fov_y, int32_t width, int32_t height);

// What every ray of one image shares: the camera's right-handed frame (w forward, u
// image-right, v image-up), the film scale and the focus distance. Renderers derive it once
// per image instead of once per ray.
typedef struct drift_camera_frame {
    drift_camera camera;
    drift_vec3 u, v, w;
    float tan_half; // tan(fov_y / 2)
    float aspect;   // width / height
    float focus;    // focus_distance, or |target - position| when that is 0
    int32_t width, height;
} drift_camera_frame;

drift_camera_frame drift_camera_frame_make(const drift_camera *camera, int32_t width,
                                           int32_t height);
// As drift_camera_ray, bit for bit.
drift_ray drift_camera_frame_ray(const drift_camera_frame *frame, float film_x, float film_y,
                                 drift_vec2 lens);
// Film position (pixels, top-left origin) of world point p through the pinhole; false when
// p is not in front of the camera. The inverse of drift_camera_frame_ray with a pinhole.
bool drift_camera_frame_project(const drift_camera_frame *frame, drift_vec3 p,
                                drift_vec2 *out_film);

// The ray through film point (film_x, film_y) in pixels (top-left origin; pixel centres at
// +0.5) for an image of width x height, with lens sample `lens` in [0,1)^2 (ignored for a
// pinhole). The direction is unit length.
drift_ray drift_camera_ray(const drift_camera *camera, int32_t width, int32_t height, float film_x,
                           float film_y, drift_vec2 lens);

// --- MATERIALS ---

typedef enum drift_material_type {
    DRIFT_MATERIAL_DEFAULT = 0, // diffuse + glossy (either may be zero)
    DRIFT_MATERIAL_MIRROR,      // perfect specular reflection with reflectance `specular`
    DRIFT_MATERIAL_GGX,         // microfacet conductor / plastic / dielectric (`ggx`)
    DRIFT_MATERIAL_COUNT
} drift_material_type;

// The diffuse lobe's shape (docs/materials.md).
typedef enum drift_diffuse_model {
    DRIFT_DIFFUSE_LAMBERT = 0, // kd / pi
    DRIFT_DIFFUSE_BURLEY,      // Burley's (Disney's) diffuse of roughness `diffuse_roughness`
} drift_diffuse_model;

// DRIFT_MATERIAL_GGX (docs/materials.md): GGX (Trowbridge-Reitz) microfacets with Smith
// height-correlated masking-shadowing and multiple-scattering energy compensation. Its base
// colour is the material's `diffuse` (times diffuse_texture). Three components, blended as
// glTF's metallic-roughness model does: a conductor (weight metallic), a dielectric-coated
// diffuse "plastic" (weight (1 - metallic)(1 - transmission)) and a dielectric that refracts
// (weight (1 - metallic) transmission). All zero is a rough-free white plastic of IOR 1.5.
typedef struct drift_ggx_params {
    float alpha;              // GGX roughness alpha (glTF's perceptual roughness squared); 0..1
    float metallic;           // 0..1
    float transmission;       // 0..1, of the non-metallic part
    float ior;                // coat and dielectric IOR; 0 means 1.5
    drift_vec3 specular_tint; // scales the coat's F0 (KHR_materials_specular); 0 means 1
    drift_vec3 edge_tint;     // conductor: Gulbrandsen edge tint; 0 = Schlick from F0 = base
    drift_vec3 eta, k;        // conductor: measured complex IOR per RGB, used when k != 0
    bool thin;                // dielectric: thin-walled (no bend, light passes straight)
    // Textures (DRIFT_INVALID_INDEX for none; drift_material_make sets none): glTF's
    // metallic-roughness (B = metallic, G = perceptual roughness, multiplying the factors).
    uint32_t metallic_roughness_texture;
    // A tangent-space normal map (glTF's convention: +X along increasing u, +Y along
    // increasing v of drift's bottom-up uv, RGB = (n + 1) / 2), its XY scaled by normal_scale
    // (0 means 1). Tangents come from each triangle's uv derivatives (docs/materials.md).
    uint32_t normal_texture;
    float normal_scale;
    // glTF's emissive texture (sRGB colour multiplying the material's emission) and occlusion
    // texture (R: ambient occlusion, mixed in by occlusion_strength; 0 means 1). The path tracer
    // computes occlusion itself and does not read it, as Cycles (docs/materials.md).
    uint32_t emissive_texture;
    uint32_t occlusion_texture;
    float occlusion_strength;
    // KHR_materials_clearcoat (docs/materials.md "Clear coat"): a GGX dielectric coat of IOR 1.5
    // over the whole material, of weight clearcoat (0: none) and roughness alpha
    // clearcoat_alpha (perceptual roughness squared). The textures' R (clearcoat_texture) and G
    // (clearcoat_roughness_texture, perceptual roughness) multiply them. clearcoat_principled:
    // Blender 3.4's Principled form (0.25 clearcoat times the coat, the base not dimmed) in
    // place of the glTF specification's layering.
    float clearcoat;
    float clearcoat_alpha;
    uint32_t clearcoat_texture;
    uint32_t clearcoat_roughness_texture;
    bool clearcoat_principled;
} drift_ggx_params;

// How a material reads one of its textures (glTF's sampler, texCoord and KHR_texture_transform,
// docs/materials.md "Textures"). All zero is drift's default: repeat, bilinear, mip-mapped by
// the ray's footprint where the renderer gives one, the mesh's first uv set, no transform.
typedef enum drift_texture_wrap {
    DRIFT_WRAP_REPEAT = 0,
    DRIFT_WRAP_CLAMP,  // clamp to the edge texel
    DRIFT_WRAP_MIRROR, // mirrored repeat
} drift_texture_wrap;

typedef struct drift_texture_map {
    uint8_t wrap_s, wrap_t; // drift_texture_wrap along u and along v
    bool mag_nearest;       // magnification: the nearest texel (else bilinear)
    bool min_nearest;       // minification: nearest texels (else bilinear)
    bool no_mipmaps;        // minification reads the full-size image only
    uint8_t uv_set;         // 0: the mesh's uvs, 1: its uvs1 (uvs when it has none)
    bool has_transform;
    // KHR_texture_transform as uv' = (t0 u + t1 v + t2, t3 u + t4 v + t5) on glTF's uv (origin at
    // the image's top left: v_gltf = 1 - v of drift's bottom-up uv).
    float transform[6];
} drift_texture_map;

// The textures of a material, by role: index into drift_material.maps.
typedef enum drift_texture_slot {
    DRIFT_TEXTURE_BASE = 0, // diffuse_texture
    DRIFT_TEXTURE_METALLIC_ROUGHNESS,
    DRIFT_TEXTURE_NORMAL,
    DRIFT_TEXTURE_EMISSIVE,
    DRIFT_TEXTURE_OCCLUSION,
    DRIFT_TEXTURE_CLEARCOAT,
    DRIFT_TEXTURE_CLEARCOAT_ROUGHNESS,
    DRIFT_TEXTURE_SLOT_COUNT
} drift_texture_slot;

// Fills `ggx` with the measured complex IOR of a named metal ("Au", "Ag", "Cu", "Al", and the
// English names); false when the name is unknown.
bool drift_ggx_named_metal(const char *name, drift_ggx_params *ggx);

// How much of a surface is there (glTF's alphaMode): every ray hits an OPAQUE one; a MASK one
// is hit where its opacity is at least alpha_cutoff (foliage and fence cards); a BLEND one is
// hit with probability equal to its opacity (stochastic transparency: what Cycles renders of
// Blender's alpha, converging to the blend).
typedef enum drift_alpha_mode {
    DRIFT_ALPHA_OPAQUE = 0,
    DRIFT_ALPHA_MASK,
    DRIFT_ALPHA_BLEND,
    DRIFT_ALPHA_MODE_COUNT
} drift_alpha_mode;

typedef struct drift_material {
    char name[DRIFT_NAME_MAX];
    drift_material_type type;
    drift_vec3 diffuse;       // diffuse albedo kd (at normal incidence for Burley)
    drift_vec3 specular;      // glossy or mirror reflectance ks
    float exponent;           // Phong exponent n of the glossy lobe (> 0 when specular > 0)
    drift_vec3 emission;      // emitted radiance from the front face (0 = not emissive)
    uint32_t diffuse_texture; // texture index modulating `diffuse`, or DRIFT_INVALID_INDEX
    drift_diffuse_model diffuse_model;
    float diffuse_roughness; // Burley only: in [0, 1] (glTF's perceptual roughness)
    drift_ggx_params ggx;    // DRIFT_MATERIAL_GGX only
    drift_texture_map maps[DRIFT_TEXTURE_SLOT_COUNT]; // how each texture is read (zero: default)
    bool emission_two_sided; // emits from both faces (glTF doubleSided, as Cycles)
    // Coverage (drift_alpha_mode; zero: opaque, the fields below unread). opacity: glTF's
    // baseColorFactor alpha, times opacity_texture (a 1-channel texture, the base colour
    // image's alpha, read through maps[DRIFT_TEXTURE_BASE]) where set. Rays test it
    // (src/accel), and so does every point set sampled on surfaces (src/points).
    drift_alpha_mode alpha_mode;
    float alpha_cutoff; // MASK: opacity >= cutoff is hit (glTF alphaCutoff, default 0.5)
    float opacity;
    uint32_t opacity_texture;
} drift_material;

// A material with no texture: the value to start from when filling one in.
drift_material drift_material_make(drift_vec3 diffuse);

// --- LIGHTS ---

typedef enum drift_light_type {
    DRIFT_LIGHT_POINT = 0,   // position, color = intensity (W/sr in scene units)
    DRIFT_LIGHT_SPOT,        // position, direction, inner/outer half angles
    DRIFT_LIGHT_DIRECTIONAL, // direction (the way light travels), color = irradiance
    DRIFT_LIGHT_QUAD,        // position = corner, edge_u, edge_v; emits along cross(u, v)
    DRIFT_LIGHT_DISK,        // position = centre, direction = normal it emits along, radius
    DRIFT_LIGHT_SPHERE,      // position = centre, radius; emits outward
    DRIFT_LIGHT_TRIANGLE,    // an emissive mesh triangle (made by commit from materials)
    DRIFT_LIGHT_COUNT
} drift_light_type;

// How a spot light's intensity falls off from its inner to its outer cone (cos θ: the
// angle from its axis; docs/scene-format.md "Spot lights").
typedef enum drift_spot_falloff {
    DRIFT_SPOT_SMOOTHSTEP = 0, // smoothstep of the cosine from outer to inner (pbrt-v4)
    DRIFT_SPOT_GLTF,           // KHR_lights_punctual's reference: the linear ramp in cos, squared
    DRIFT_SPOT_BLENDER, // Cycles (Blender 3.x): cos θ · smoothstep over the last (1 − cos outer)
                        // · blend of the cosine, blend = 1 − inner / outer (Blender's glTF I/O)
} drift_spot_falloff;

typedef struct drift_light {
    drift_light_type type;
    drift_vec3 color; // intensity, irradiance or radiance by type (see above)
    drift_vec3 position;
    drift_vec3 direction;
    drift_vec3 edge_u, edge_v;
    float radius;
    float spot_inner, spot_outer; // half angles, radians
    drift_spot_falloff spot_falloff;
    uint32_t mesh, triangle; // DRIFT_LIGHT_TRIANGLE only
    bool two_sided;          // DRIFT_LIGHT_TRIANGLE: emits from both faces (set by commit)
    // The glTF node that placed it (its index in the file's `nodes`; node animation moves it:
    // drift_scene_animation), else DRIFT_INVALID_INDEX. drift_scene_add_light sets it invalid.
    uint32_t node;
} drift_light;

// True for lights with area (they are geometry: rays can hit them).
bool drift_light_is_area(drift_light_type type);

// The fraction of a spot light's intensity sent at cos θ from its axis (1 inside the inner
// cone, 0 outside the outer one, by its spot_falloff); 1 for other lights.
float drift_light_spot_falloff(const drift_light *light, float cos_theta);

// --- MESHES ---

typedef struct drift_mesh {
    char name[DRIFT_NAME_MAX];
    float *positions; // 3 floats a vertex, plus 1 padding float at the end
    float *normals;   // 3 floats a vertex (unit), or NULL for flat shading
    float *uvs;       // 2 floats a vertex, or NULL
    float *uvs1;      // a second uv set (glTF TEXCOORD_1), or NULL
    // 4 floats a vertex (unit tangent along increasing u of the normal map's uv set, and the
    // sign w with bitangent = w cross(n, t)): the file's (glTF TANGENT), or computed by commit
    // for normal-mapped meshes with normals and uvs (docs/materials.md); else NULL.
    float *tangents;
    // 3 floats a vertex: linear RGB multiplying the material's base colour (glTF COLOR_0, as
    // the spec and Blender's importer apply it), or NULL.
    float *colors;
    uint32_t *indices; // 3 a triangle
    uint32_t vertex_count;
    uint32_t triangle_count;
    uint32_t material;
    uint32_t first_light; // light index of triangle 0 when emissive (set by commit), else invalid
    // The glTF node that placed it (its index in the file's `nodes`; node animation moves it:
    // drift_scene_animation), else DRIFT_INVALID_INDEX. drift_scene_add_mesh sets it invalid.
    uint32_t node;
} drift_mesh;

// Input for drift_scene_add_mesh; arrays are copied. normals and uvs are optional.
typedef struct drift_mesh_desc {
    const char *name;
    const float *positions;
    const float *normals;
    const float *uvs;
    const uint32_t *indices;
    uint32_t vertex_count;
    uint32_t triangle_count;
    uint32_t material;
    const float *uvs1;     // optional second uv set
    const float *tangents; // optional, 4 floats a vertex (see drift_mesh)
    const float *colors;   // optional, 3 floats a vertex (see drift_mesh)
} drift_mesh_desc;

// --- ENVIRONMENT ---

// Radiance arriving from infinitely far away: `color`, times the lat-long texture if set.
// Lat-long layout (docs/conventions.md): u = phi / (2 pi), phi = atan2(-dir.z, dir.x) in
// [0, 2 pi); v = theta / pi with theta measured from +y (v = 0 is the top row).
typedef struct drift_environment {
    drift_vec3 color;
    uint32_t texture; // DRIFT_INVALID_INDEX for a constant environment
} drift_environment;

// --- SCENE ---

typedef struct drift_light_table drift_light_table; // private: light sampling distributions

typedef struct drift_scene {
    drift_context *ctx;
    drift_camera camera;
    drift_environment environment;
    drift_mesh *meshes;
    uint32_t mesh_count;
    drift_material *materials;
    uint32_t material_count;
    drift_light *lights;
    uint32_t light_count;
    drift_image *textures; // linear RGB(A); owned
    uint32_t texture_count;
    drift_bounds3 bounds; // of all geometry, set by commit
    // Of the meshes that reflect light (a pure emitter, emission and no reflectance, is not
    // one), set by commit: the scene's extent as a length scale (drift_scene_extent).
    drift_bounds3 reflector_bounds;
    drift_light_table *light_table; // set by commit
    // Set by the loaders when the file had no light, emitter or environment and they added
    // the default sun (lights[0]) and environment of docs/scene-format.md.
    bool default_lights;
    // Private: the mip-map pyramid of each texture materials read (built by commit).
    struct drift_texture_pyramid *pyramids;
    bool committed;
} drift_scene;

drift_result drift_scene_create(drift_context *ctx, drift_scene **out_scene);
void drift_scene_destroy(drift_scene *scene); // NULL-safe

// Copies the mesh in. Errors: DRIFT_ERR_INVALID_ARGUMENT (index out of range, non-finite
// vertex, sizes over the limits), DRIFT_ERR_OUT_OF_MEMORY. Degenerate (zero-area) triangles
// are dropped with a warning; a mesh left empty is an error.
drift_result drift_scene_add_mesh(drift_scene *scene, const drift_mesh_desc *desc,
                                  uint32_t *out_index);
drift_result drift_scene_add_material(drift_scene *scene, const drift_material *material,
                                      uint32_t *out_index);
// Errors: DRIFT_ERR_INVALID_ARGUMENT for zero-area area lights, non-finite or negative
// values, zero directions.
drift_result drift_scene_add_light(drift_scene *scene, const drift_light *light,
                                   uint32_t *out_index);
// Takes ownership of `image` (its pixels are freed with the scene).
drift_result drift_scene_add_texture(drift_scene *scene, drift_image image, uint32_t *out_index);

// Validates every reference, computes bounds, adds one DRIFT_LIGHT_TRIANGLE light per
// emissive mesh triangle and builds the power-proportional light distribution.
// Idempotent: a second call rebuilds. Errors: DRIFT_ERR_INVALID_ARGUMENT with a logged reason.
drift_result drift_scene_commit(drift_scene *scene);

// Triangle, material, light and texture counts.
uint64_t drift_scene_triangle_count(const drift_scene *scene);

// Bounds of one mesh's vertices.
drift_bounds3 drift_mesh_bounds(const drift_mesh *mesh);

// The scene's length scale for the techniques' defaults (a clamp distance, a search radius, a
// depth bias): the diagonal of the reflecting meshes' bounds, so that a sun far outside a
// window (the Breakfast Room's, 14 m beyond a 6 m room) does not stretch it; the diagonal of
// all of `bounds` when no mesh reflects, 1 when the scene is empty.
float drift_scene_extent(const drift_scene *scene);

// The corners of a DRIFT_LIGHT_TRIANGLE light, in the order of its mesh triangle (their
// cross product points the way it emits).
void drift_light_triangle_vertices(const drift_scene *scene, const drift_light *light,
                                   drift_vec3 *a, drift_vec3 *b, drift_vec3 *c);

// --- SURFACES ---

// What the accel reports about a hit: which geometry, which primitive, where.
typedef struct drift_hit {
    float t;
    float u, v;     // barycentrics of vertices 1 and 2 (triangles); unused otherwise
    uint32_t mesh;  // mesh index, or DRIFT_INVALID_INDEX when an area light's shape was hit
    uint32_t prim;  // triangle index within the mesh
    uint32_t light; // area light index (shape hit, or emissive mesh triangle), else invalid
    drift_vec3 ng;  // geometric normal, unnormalized, as the accel computed it
} drift_hit;

// Everything shading needs at a hit point.
typedef struct drift_surface {
    drift_vec3 position;
    drift_vec3 ng; // unit geometric normal, flipped to face the incoming ray
    drift_vec3 ns; // unit shading normal, on the same side as ng
    drift_vec2 uv;
    uint32_t material;   // DRIFT_INVALID_INDEX for light shapes (pure emitters)
    uint32_t light;      // area light at this point, or DRIFT_INVALID_INDEX
    drift_vec3 emission; // radiance emitted toward the incoming ray's origin
    bool front_face;     // the ray hit the side the geometric normal points to
    uint32_t mesh;       // the mesh hit, or DRIFT_INVALID_INDEX (a light's shape, nothing)
    uint32_t triangle;   // its triangle, and the barycentrics of vertices 1 and 2 there
    drift_vec2 barycentric;
    drift_vec2 uv1; // the mesh's second uv set (uv when it has none)
    // The ray's footprint on the surface as a width in units of uv and of uv1
    // (drift_surface_set_footprint); 0 (what drift_scene_surface leaves) reads textures at full
    // size.
    float uv_footprint, uv1_footprint;
} drift_surface;

drift_surface drift_scene_surface(const drift_scene *scene, const drift_ray *ray,
                                  const drift_hit *hit);

// Sets surface->uv_footprint from a ray cone (Akenine-Moller et al. 2021, "Improved Shader and
// Texture Level of Detail Using Ray Cones"): `width` is the cone's width at the hit, the ray
// arrives along ray_dir; the footprint is width / |cos| scaled by the hit triangle's uv-to-world
// density. Textures then read the mip level of that footprint.
void drift_surface_set_footprint(const drift_scene *scene, drift_surface *surface, float width,
                                 drift_vec3 ray_dir);

// Whether a ray meets mesh `mesh`'s triangle `prim` at barycentrics (u, v) (Embree's: the
// weights of vertices 1 and 2): always for an opaque material; for MASK where its opacity is
// at least alpha_cutoff; for BLEND when `xi` (uniform in [0, 1)) is below its opacity.
bool drift_scene_covers(const drift_scene *scene, uint32_t mesh, uint32_t prim, float u, float v,
                        float xi);
// The material's opacity at (mesh, prim, u, v): opacity times its texture there, in [0, 1].
float drift_scene_opacity(const drift_scene *scene, uint32_t mesh, uint32_t prim, float u, float v);

// The value of texture slot `slot` of `material` at the surface (its map's uv set, transform,
// wrap, filter and mip level), RGB linear; (1, 1, 1) when the material has no such texture.
drift_vec3 drift_material_texture(const drift_scene *scene, const drift_material *material,
                                  drift_texture_slot slot, const drift_surface *surface);

// Ray origin offset along the geometric normal toward `dir`, scaled to the position's
// magnitude, so secondary rays do not re-hit their own surface.
drift_vec3 drift_offset_origin(drift_vec3 position, drift_vec3 ng, drift_vec3 dir);

// --- BSDF ---

// A DRIFT_MATERIAL_GGX material resolved at one point (textures applied).
typedef struct drift_bsdf_ggx {
    float alpha;
    float w_conductor, w_plastic, w_dielectric; // component weights, summing to 1
    drift_vec3 base;                            // base colour: conductor F0, plastic diffuse
    drift_vec3 f0_coat;                         // plastic coat's F0 (Schlick)
    bool schlick;                               // conductor Fresnel: Schlick from base
    drift_vec3 eta, k;                          // otherwise complex IOR
    float eta_rel; // dielectric: IOR on the far side over the IOR on wo's side
    bool thin;
    // >= 0: the plastic's base is Burley's diffuse of this roughness, not dimmed by the coat
    // (Blender 3.4's Principled BSDF; the material's diffuse_model BURLEY); < 0: the
    // energy-conserving layering of docs/materials.md.
    float burley_roughness;
    // Set by drift_bsdf_make from the clamped roughness: its row of the albedo tables and
    // their cosine-weighted averages (src/scene/ggx_tables.c).
    int alpha_row;
    float alpha_frac, e1_avg, es_avg;
    // False from drift_bsdf_make. A technique that renders a part itself sets them on its copy:
    // drift_bsdf_eval and _eval_lobes then leave out the conductor and the coat's reflection
    // (skip_reflection: the hybrid frame's split-sum environment light) or the plastic's
    // diffuse base (skip_diffuse). The pdf and sampling do not change.
    bool skip_reflection, skip_diffuse;
    // The clear coat over all of the above (src/scene/clearcoat.c), textures applied: its
    // weight (0: none, the material above bit for bit), alpha, form, its alpha's row of the
    // albedo tables, the coat's cosine-weighted average albedo (weight included), and the gain
    // that gives the plastic's diffuse base back the light the coat reflects down into it.
    float clearcoat, clearcoat_alpha;
    bool clearcoat_principled;
    int clearcoat_row;
    float clearcoat_frac, clearcoat_avg;
    drift_vec3 clearcoat_diffuse_gain;
} drift_bsdf_ggx;

// Resolved material at one point (textures applied). All directions in world space.
// For DRIFT_MATERIAL_GGX, diffuse, specular and exponent hold the Phong-equivalent lobe
// (docs/materials.md, "Phong-equivalent") for the techniques whose papers shade with Phong;
// drift_bsdf_eval, _pdf and _sample_wi evaluate the GGX model itself.
typedef struct drift_bsdf {
    drift_material_type type;
    drift_vec3 diffuse, specular;
    float exponent;
    drift_diffuse_model diffuse_model;
    float diffuse_roughness;
    drift_frame frame; // z = shading normal
    // Zero: the lobes centre on the mirror direction of wo. Otherwise the unit direction they
    // centre on instead, for the one wo it was made for: an edited reflection e(q)
    // (drift/reflect_edit.h). The diffuse lobe does not change.
    drift_vec3 edited_mirror;
    drift_bsdf_ggx ggx; // DRIFT_MATERIAL_GGX only
    // Ambient occlusion of the material's occlusion texture (1 without one), for techniques that
    // approximate indirect light; the path tracer does not apply it.
    float occlusion;
} drift_bsdf;

drift_bsdf drift_bsdf_make(const drift_scene *scene, const drift_surface *surface);
// f(wo, wi) (without the cosine). Zero for mirrors (a delta lobe). The sum of the two lobes
// of drift_bsdf_eval_lobes.
drift_vec3 drift_bsdf_eval(const drift_bsdf *bsdf, drift_vec3 wo, drift_vec3 wi);
// The diffuse lobe kd/pi and the glossy lobe ks (n+2)/(2 pi) cos^n(alpha) of f(wo, wi) apart
// (both zero for mirrors and below the surface): for splitting light by the lobe that
// scattered it.
void drift_bsdf_eval_lobes(const drift_bsdf *bsdf, drift_vec3 wo, drift_vec3 wi,
                           drift_vec3 *out_diffuse, drift_vec3 *out_glossy);
// Solid-angle pdf of sampling wi given wo. Zero for mirrors.
float drift_bsdf_pdf(const drift_bsdf *bsdf, drift_vec3 wo, drift_vec3 wi);

typedef struct drift_bsdf_sample {
    drift_vec3 wi;
    drift_vec3 weight; // f * cos / pdf (for mirrors: ks)
    float pdf;         // solid-angle pdf; 0 on failure
    bool is_delta;     // sampled from a delta lobe (mirror, smooth glass): skip MIS and NEE
} drift_bsdf_sample;

// Samples wi. u_lobe picks the lobe, u the direction. pdf == 0 means no sample.
drift_bsdf_sample drift_bsdf_sample_wi(const drift_bsdf *bsdf, drift_vec3 wo, float u_lobe,
                                       drift_vec2 u);
// Smooth glass: a GGX dielectric whose lobes are deltas (thin-walled, or alpha below 1e-3).
// The hybrid frame traces the light it lets through along with the sharp reflection ray.
bool drift_bsdf_is_smooth_glass(const drift_bsdf *bsdf);
// Glass of any roughness: a GGX material with a dielectric (transmitting) component.
bool drift_bsdf_is_glass(const drift_bsdf *bsdf);
// The direction the glossy and mirror lobes centre on: the mirror direction of wo about the
// shading normal, or edited_mirror when set (the one ray a mirror reflects).
drift_vec3 drift_bsdf_mirror_direction(const drift_bsdf *bsdf, drift_vec3 wo);
// A direction from the glossy lobe's cos^n(alpha) distribution around the mirror direction of
// wo (cos alpha = u.x^(1/(n+1)), phi = 2 pi u.y): the one place the Phong lobe is sampled
// (the path tracer, AAF's specular buffer and SIR's ray tracer). It may point below the surface.
drift_vec3 drift_bsdf_sample_glossy_lobe(const drift_bsdf *bsdf, drift_vec3 wo, drift_vec2 u);
bool drift_bsdf_is_delta(const drift_bsdf *bsdf);
// A GGX BSDF's directional albedo toward wo (mu = cos theta_o) of its reflection lobes, the
// split sum's DFG term: the conductor's and the coat's single-scattering lobe F0 (E1 - Es) + Es
// (around the mirror direction) and the conductor's multiple-scattering lobe (a broader GGX
// lobe about the same direction), each times its weight; a smooth (delta) dielectric's
// Fresnel reflection too (a rough one's is left to sampling). Zero for other materials.
// A visible normal of GGX roughness alpha for wo (local frame, wo.z > 0; Heitz 2018): the
// path tracer's sampling, for techniques that trace the lobe's rays themselves.
drift_vec3 drift_ggx_sample_visible_normal(float alpha, drift_vec3 wo, drift_vec2 u);
void drift_bsdf_ggx_reflection_albedo(const drift_bsdf *bsdf, float mu, drift_vec3 *out_single,
                                      drift_vec3 *out_multiple);
// The GGX roughness of the conductor's multiple-scattering lobe for a material of roughness
// alpha (a broader lobe about the same mirror direction; docs/materials.md).
float drift_ggx_multiple_scattering_alpha(float alpha);
// A GGX BSDF's clear coat toward wo (mu = cos theta_o): the coat lobe's directional albedo
// (weight included; 0 without a coat), and its alpha in out_alpha. The lobe is about the same
// shading normal as the rest; drift_bsdf_ggx_reflection_albedo's lobes are already dimmed by
// what the coat takes (docs/materials.md "Clear coat").
float drift_bsdf_clearcoat_albedo(const drift_bsdf *bsdf, float mu, float *out_alpha);

// --- LIGHT SAMPLING ---

typedef struct drift_light_sample {
    drift_vec3 wi;       // unit direction from the reference point toward the light
    float distance;      // to the sampled point; INFINITY for directional/environment
    drift_vec3 radiance; // L arriving along -wi (intensity / d^2 for point lights)
    float pdf;           // solid-angle pdf of this light's sampling (times nothing else);
                         // for delta lights the pdf is 1 and is_delta is set
    bool is_delta;
    drift_vec3 point; // the sampled point on the light (for shadow rays)
    drift_vec3 light_normal;
} drift_light_sample;

// Picks a light in proportion to its power. Returns DRIFT_INVALID_INDEX when the scene has
// no lights; out_pmf gets the probability of the pick.
uint32_t drift_scene_pick_light(const drift_scene *scene, float u, float *out_pmf);
// The same pick, and *u rescaled from the picked light's [cdf, cdf + pmf) to [0, 1): one
// number both picks the light and, reused, places the sample on it, so that a stratified 2D
// point is still stratified over each light and not a random subset of it (Cycles does this).
uint32_t drift_scene_pick_light_reuse(const drift_scene *scene, float *u, float *out_pmf);
// Probability with which pick_light returns `light`.
float drift_scene_light_pmf(const drift_scene *scene, uint32_t light);
// Samples a point (or direction) on light `light` as seen from the point `ref`; the index
// light_count means the environment. u picks the point. pdf == 0 means no contribution.
drift_light_sample drift_light_sample_li(const drift_scene *scene, uint32_t light, drift_vec3 ref,
                                         drift_vec2 u);
// Light tracing's first ray (instant radiosity's VPLs, micro-rendering's photons) and the
// flux it carries for one of `paths` paths whose light was picked with probability pmf.
// Area light l (quad, disk, sphere, triangle): a uniform point (u1), a cosine direction
// (u2), pi A L / (pmf paths); false for a point, spot or directional light.
bool drift_light_emit_area(const drift_scene *scene, const drift_light *l, drift_vec2 u1,
                           drift_vec2 u2, float pmf, float paths, drift_ray *out_ray,
                           drift_vec3 *out_flux);
// The environment (light == light_count; direction by u1) or a directional light: parallel
// rays from a disc (u2) of `radius` around `centre` (the scene's bounding sphere); false for
// any other light.
bool drift_light_emit_distant(const drift_scene *scene, uint32_t light, drift_vec3 centre,
                              float radius, drift_vec2 u1, drift_vec2 u2, float pmf, float paths,
                              drift_ray *out_ray, drift_vec3 *out_flux);
// Solid-angle pdf with which drift_light_sample_li would pick direction wi toward the point
// `point` with normal `light_normal` on area light `light`, from `ref`.
float drift_light_pdf_li(const drift_scene *scene, uint32_t light, drift_vec3 ref, drift_vec3 wi,
                         float distance, drift_vec3 light_normal);

// Environment: radiance along direction dir (dir points away from the scene), and its
// sampling (importance-sampled by luminance when textured, uniform sphere otherwise).
bool drift_scene_has_environment(const drift_scene *scene);
drift_vec3 drift_environment_eval(const drift_scene *scene, drift_vec3 dir);
drift_light_sample drift_environment_sample(const drift_scene *scene, drift_vec2 u);
float drift_environment_pdf(const drift_scene *scene, drift_vec3 dir);
// True for an environment of one radiance in every direction (no texture).
bool drift_environment_is_constant(const drift_scene *scene);
// Probability of choosing the environment rather than a scene light for NEE.
float drift_scene_environment_pmf(const drift_scene *scene);

#ifdef __cplusplus
}
#endif
#endif // DRIFT_SCENE_H
