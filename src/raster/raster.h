// Private interfaces between the passes of the hybrid frame (src/hybrid). Each pass is one
// file with one job; frame.c drives them. Tests include this header to test passes alone.
#ifndef DRIFT_HYBRID_INTERNAL_H
#define DRIFT_HYBRID_INTERNAL_H

#include "drift/hybrid.h"

// --- PRIMARY VISIBILITY (gbuffer.c) ---

drift_result drift_gbuffer_create(drift_context *ctx, int32_t width, int32_t height,
                                  drift_gbuffer *out);
void drift_gbuffer_destroy(drift_context *ctx, drift_gbuffer *gbuffer);

// Fills every plane from one pinhole ray through each pixel centre of `camera` (coherent
// packets, one tile at a time). prev_camera (NULL: none) sets the motion plane, with
// mesh_motion (NULL: no mesh moved; else 12 floats a scene mesh, the affine map from a point
// now to where it was: drift_hybrid_set_mesh_motion) for the points of moving meshes.
void drift_gbuffer_render(drift_context *ctx, const drift_scene *scene, const drift_accel *accel,
                          const drift_camera *camera, const drift_camera *prev_camera,
                          const float *mesh_motion, drift_gbuffer *gbuffer, uint64_t *rays);

// Whether pixels a and b (indices y * width + x) lie on one surface as an image-space filter
// sees it: the same mesh, shading normals within ~25 degrees (a thin part of an object in
// front of the floor is not averaged with it). Each filter adds its own depth tolerance.
static inline bool drift_gbuffer_same_surface(const drift_gbuffer *g, size_t a, size_t b)
{
    return g->mesh_index[a] == g->mesh_index[b] &&
           drift_vec3_dot(g->surfaces[a].ns, g->surfaces[b].ns) > 0.9f;
}

// --- LIGHTS AS THE HYBRID FRAME SEES THEM (lights.c) ---

// One light of the frame: a scene light, or every triangle light of one emissive mesh
// gathered into one (the Cornell box's ceiling quad is two triangle lights, one light here).
// Shadow maps, hard shadows and the gathers of later issues work per hybrid light.
typedef struct drift_raster_light {
    drift_light_type type;  // DRIFT_LIGHT_TRIANGLE stands for an emissive mesh
    drift_vec3 centre;      // where hard-shadow rays aim and shadow maps look from
                            // (area-weighted centroid for meshes); unused for directional
    drift_vec3 direction;   // directional: the way light travels; spot: its axis; quad, disk
                            // and mesh: the (mean) normal light leaves along; else zero
    float radius;           // light size L: 0 for point, spot and directional lights; for
                            // area lights the radius of a bounding sphere about `centre`
    bool one_sided;         // has a mean normal `direction` and emits only into the hemisphere
                            // around it, unless two_sided
    bool two_sided;         // an emissive mesh that emits from both faces (glTF doubleSided, as
                            // Cycles): points behind its plane are lit too
    uint32_t first_light;   // the scene lights it stands for: first_light ..
    uint32_t light_count;   //   first_light + light_count - 1 (1 unless a mesh)
    uint32_t mesh;          // the emissive mesh, or DRIFT_INVALID_INDEX
    float *light_cdf;       // light_count entries: area CDF over the triangles (meshes), or NULL
    float sphere_radius;    // > 0: a mesh whose triangles tile a sphere about `centre` of one
                            // radiance; the sphere of the same area stands in for its diffuse U
    float shadow_clearance; // how far short of `centre` a shadow ray must stop to meet none of
                            // the light's own surface (0: a flat emitter, the radius: a sphere);
                            // < 0: it may meet it anywhere (a curved mesh): closest hits only
} drift_raster_light;

// Whether scene light `scene_light` (e.g. drift_hit.light) is part of this light: a ray that
// meets it has reached the light, not an occluder.
static inline bool drift_raster_light_owns(const drift_raster_light *light, uint32_t scene_light)
{
    return scene_light != DRIFT_INVALID_INDEX &&
           scene_light - light->first_light < light->light_count;
}

// Builds the hybrid lights of a committed scene (not the environment). *out_lights is NULL
// when there are none. Free with drift_raster_lights_destroy.
drift_result drift_raster_lights_build(drift_context *ctx, const drift_scene *scene,
                                       drift_raster_light **out_lights, uint32_t *out_count);
void drift_raster_lights_destroy(drift_context *ctx, drift_raster_light *lights, uint32_t count);

// Samples a point on the light (u in [0,1)^2, u_pick picks a triangle of a mesh) as seen from
// ref, with the solid-angle pdf of that choice folded into the sample's pdf.
drift_light_sample drift_raster_light_sample(const drift_scene *scene,
                                             const drift_raster_light *light, drift_vec3 ref,
                                             float u_pick, drift_vec2 u);

// Emissive meshes of more triangles than this are not hit-tested (their glossy light is the
// light samples' alone).
#define DRIFT_RASTER_HIT_TRIANGLES 64

// Where the ray from `origin` along the unit `dir` meets the light's own shapes (nothing else
// in the scene: no visibility): the radiance it sees there and the solid-angle pdf with which
// drift_raster_light_sample would have chosen that direction (the first shape along the ray),
// for weighing a BSDF-sampled direction against light samples. False on a miss, a back face,
// a delta light or a mesh of more than DRIFT_RASTER_HIT_TRIANGLES triangles.
bool drift_raster_light_hit(const drift_scene *scene, const drift_raster_light *light,
                            drift_vec3 origin, drift_vec3 dir, drift_vec3 *out_radiance,
                            float *out_pdf);

// --- SHADING SHARED BY EVERY PASS (shading.c) ---

// Unshadowed direct light U_l: outgoing radiance toward wo at the surface from light
// `light` through the non-delta lobes, without visibility. Delta lights are exact. Quad
// lights and emissive meshes of up to 32 triangles get their diffuse lobe in closed form
// (Lambert's polygon formula, clipped to the hemisphere). What remains (the glossy lobe;
// both lobes for disk, sphere and larger mesh lights) takes `sample_count` points of a
// Hammersley set shifted by one random offset drawn from `sampler` (Cranley-Patterson
// rotation: stratified within a pixel, decorrelated between pixels). Zero for mirrors.
drift_vec3 drift_raster_unshadowed(const drift_scene *scene, const drift_raster_light *light,
                                   const drift_surface *surface, const drift_bsdf *bsdf,
                                   drift_vec3 wo, uint32_t sample_count, drift_sampler *sampler);

// Receivers of drift_raster_polygon_rows: up to DRIFT_RASTER_ROW_MAX positions and the shading
// normals of their BSDFs (bsdf.frame.z), structure of arrays.
#define DRIFT_RASTER_ROW_MAX 64

typedef struct drift_raster_receivers {
    const float *px, *py, *pz, *nx, *ny, *nz;
    int32_t count;
} drift_raster_receivers;

// Whether `light`'s diffuse lobe is a sum of quads or triangles in closed form, which
// drift_raster_polygon_rows gives for many receivers at once (not a sphere's).
bool drift_raster_has_polygon_rows(const drift_raster_light *light);
// At each receiver i, sum over the light's polygons of L_e E(p_i, n_i), E the irradiance of the
// unit-radiance polygon clipped to the hemisphere (Lambert's formula), vectorised over the
// receivers: the RGB that drift_raster_unshadowed's diffuse lobe is kd / pi times.
void drift_raster_polygon_rows(const drift_scene *scene, const drift_raster_light *light,
                               const drift_raster_receivers *receivers, float *er, float *eg,
                               float *eb);
// drift_raster_unshadowed with that sum given for this surface (from drift_raster_polygon_rows;
// only for a light drift_raster_has_polygon_rows): the same value, the closed form not redone.
drift_vec3 drift_raster_unshadowed_given(const drift_scene *scene, const drift_raster_light *light,
                                         const drift_surface *surface, const drift_bsdf *bsdf,
                                         drift_vec3 wo, uint32_t sample_count,
                                         drift_sampler *sampler, drift_vec3 polygon_irradiance);

// Direct light from the environment with ray-traced visibility (`sample_count` shadow rays,
// counted in *rays). The environment has no centre, so the shadow techniques do not apply
// to it: every technique shades it this way (docs/hybrid.md).
drift_vec3 drift_raster_environment_direct(const drift_scene *scene, const drift_accel *accel,
                                           const drift_surface *surface, const drift_bsdf *bsdf,
                                           drift_vec3 wo, uint32_t sample_count,
                                           drift_sampler *sampler, uint64_t *rays);
// The same estimate over the points first, first + stride, ... of a Hammersley set of
// set_size points shifted by `shift`: interleaved sampling, where neighbouring pixels take
// the set's other points (realtime/direct.c).
drift_vec3
drift_raster_environment_direct_subset(const drift_scene *scene, const drift_accel *accel,
                                       const drift_surface *surface, const drift_bsdf *bsdf,
                                       drift_vec3 wo, uint32_t set_size, uint32_t first,
                                       uint32_t stride, drift_vec2 shift, uint64_t *rays);

// --- GLOSSY ENVIRONMENT LIGHT BY THE SPLIT SUM (env_prefilter.c) ---

// The scene's environment prefiltered by GGX roughness (levels of perceptual roughness k / 6,
// level 0 the environment itself); a constant or absent environment is looked up as it is.
typedef struct drift_env_prefilter drift_env_prefilter;
drift_result drift_env_prefilter_build(drift_context *ctx, const drift_scene *scene,
                                       drift_env_prefilter **out);
void drift_env_prefilter_destroy(drift_context *ctx, drift_env_prefilter *prefilter); // NULL-safe
// The environment along dir averaged over the GGX lobe of roughness alpha (n = v = dir).
drift_vec3 drift_env_prefilter_lookup(const drift_env_prefilter *prefilter, drift_vec3 dir,
                                      float alpha);
// A GGX surface's environment light through its conductor and coat reflection (what
// skip_reflection leaves out of drift_bsdf_eval): the prefiltered environment along the lobe's
// dominant direction times the lobe's albedo (drift_bsdf_ggx_reflection_albedo), times the
// share of `visibility_rays` visible-normal reflections (a Hammersley set shifted by `shift`,
// counted in *rays) that escape the scene; a clear coat's lobe the same way with its own
// roughness and visibility rays. Zero for other materials.
drift_vec3 drift_raster_environment_split_sum(const drift_env_prefilter *prefilter,
                                              const drift_accel *accel,
                                              const drift_surface *surface, const drift_bsdf *bsdf,
                                              drift_vec3 wo, uint32_t visibility_rays,
                                              drift_vec2 shift, uint64_t *rays);

// A shadow ray from the surface toward the light's centre (or against a directional
// light's direction). Returns whether the centre is visible; distances to the nearest
// occluder (INFINITY when visible) and to the light's centre go to the out pointers.
bool drift_raster_hard_shadow(const drift_accel *accel, const drift_raster_light *light,
                              const drift_surface *surface, float *out_occluder_distance,
                              float *out_light_distance);
// The same in two halves, for callers that trace the rays in coherent batches: the ray, and
// what its closest hit means (a hit with mesh and light both invalid is a miss, as
// drift_accel_intersect_coherent reports it).
drift_ray drift_raster_hard_shadow_ray(const drift_raster_light *light,
                                       const drift_surface *surface, float *out_light_distance);
bool drift_raster_hard_shadow_visible(const drift_raster_light *light, const drift_hit *hit,
                                      float *out_occluder_distance);

// Radiance leaving a hit point back along ray->dir, split in two: what it emits, and direct
// light from every light with a hard shadow (one shadow ray each, counted in *rays). This is
// how the sharp reflection buffer and the environment map shade what they see.
typedef struct drift_raster_radiance {
    drift_vec3 emitted;
    drift_vec3 reflected;
} drift_raster_radiance;

typedef struct drift_raster_shading {
    const drift_scene *scene;
    const drift_accel *accel;
    const drift_raster_light *lights;
    uint32_t light_count;
    uint32_t light_samples;
} drift_raster_shading;

// Traces `ray`; a miss returns the environment as emitted radiance. skip_mesh (or
// DRIFT_INVALID_INDEX) is a mesh the ray passes through (a probe inside its own object).
drift_raster_radiance drift_raster_trace_radiance(const drift_raster_shading *shading,
                                                  drift_ray ray, uint32_t skip_mesh,
                                                  drift_sampler *sampler, uint64_t *rays,
                                                  float *out_distance);
// The same, also giving the surface it hit (material DRIFT_INVALID_INDEX on a miss or on a
// surface with no material): for callers that shade the hit further (the sharp reflection
// buffer's indirect light and second bounce, realtime/reflections.c).
drift_raster_radiance drift_raster_trace_radiance_surface(const drift_raster_shading *shading,
                                                          drift_ray ray, uint32_t skip_mesh,
                                                          drift_sampler *sampler, uint64_t *rays,
                                                          float *out_distance,
                                                          drift_surface *out_surface);

// What drift_raster_trace_radiance shades a hit's reflected light with: direct light from
// every light with one hard shadow ray each, and the environment's direct light.
drift_vec3 drift_raster_direct_hard(const drift_raster_shading *shading,
                                    const drift_surface *surface, const drift_bsdf *bsdf,
                                    drift_vec3 wo, drift_sampler *sampler, uint64_t *rays);

// Directional albedo of a specular lobe toward wo: what the radiance seen in the mirror
// direction is weighted by in R (ks for a mirror; the GGX reflection lobes' albedo, the split
// sum's DFG term; the normalized Phong lobe's integral of f cos when the lobe is narrow,
// clamped to ks).
drift_vec3 drift_raster_reflection_weight(const drift_bsdf *bsdf, drift_vec3 wo);

// The diffuse lobe's directional albedo toward w, what an image-space or VPL technique that
// shades albedo x irradiance / pi multiplies by: kd for Lambert; GGX's layered plastic base
// exactly, base (1 - Ec(mu)); Burley's diffuse (and GGX's Principled base) the integral of
// its lobe over 16 cosine points; 0 for mirrors and glass.
drift_vec3 drift_raster_diffuse_albedo(const drift_bsdf *bsdf, drift_vec3 w);

// Glossiness of a material for the gloss plane and gathers: the half angle theta_max of the
// cone that holds 90% of the Phong lobe, cos(theta_max) = 0.1^(1/(n+1)); for GGX the cone
// holding 90% of its reflected directions at normal incidence, drift_ggx_theta_90(alpha)
// (textures not applied); 0 for mirrors, pi/2 for materials with no specular lobe.
float drift_gloss_theta_max(const drift_material *material);
// 2 atan(3 alpha), at most pi/2: the cone about the mirror direction holding 90% of a GGX
// lobe of roughness alpha at normal incidence.
float drift_ggx_theta_90(float alpha);
// The Blinn-Phong exponent m of the lobe (AAF's bandwidth 3.6 + 0.084 m reads it): 4 n for
// the Phong lobe (n ~ m / 4); for GGX the m whose 90% cone of half vectors is GGX's,
// m = 2 ln 10 / ln(1 + 9 alpha^2) - 2 (about 0.51 / alpha^2: GGX's tails make it a quarter
// of Walter's 2 / alpha^2 - 2, which matches the peak); INFINITY for mirrors.
float drift_gloss_blinn_exponent(const drift_bsdf *bsdf);

// --- SHADOW MAPS (shadow_map.c) ---

// A depth map seen from a light: a cube map of radial distances from the centre for local
// lights (faces behind a one-sided light are skipped), an orthographic map over the scene
// bounds for directional lights. Texels hold the distance to the nearest surface through
// the texel centre (ray-cast: the value a rasterizer writes at that centre).
typedef struct drift_shadow_map drift_shadow_map;

typedef struct drift_shadow_map_params {
    int32_t size;      // texels across a face
    float bias_texels; // depth bias in texel footprints at the receiver's distance
} drift_shadow_map_params;

// Adds the rays it casts to *out_rays (may be NULL). Errors: DRIFT_ERR_INVALID_ARGUMENT
// (uncommitted scene, size outside [1, 16384], negative bias; logged), DRIFT_ERR_OUT_OF_MEMORY.
drift_result drift_shadow_map_build(drift_context *ctx, const drift_scene *scene,
                                    const drift_accel *accel, const drift_raster_light *light,
                                    const drift_shadow_map_params *params,
                                    drift_shadow_map **out_map, uint64_t *out_rays);
void drift_shadow_map_destroy(drift_context *ctx, drift_shadow_map *map); // NULL-safe

// Visibility in [0,1] of the light from point p with geometric normal n:
// hard = one tap, pcf = a kernel x kernel box of taps, pcss = blocker search, penumbra
// estimate w = L (d_receiver - d_blocker) / d_blocker, then PCF over w (taps rotated by
// `rotation_hash` per pixel to trade banding for noise).
float drift_shadow_map_hard(const drift_shadow_map *map, drift_vec3 p, drift_vec3 n);
float drift_shadow_map_pcf(const drift_shadow_map *map, drift_vec3 p, drift_vec3 n, int32_t kernel);
float drift_shadow_map_pcss(const drift_shadow_map *map, drift_vec3 p, drift_vec3 n,
                            uint32_t rotation_hash);
// How far toward the light from p (normal n) the map cannot see blockers, scene units: the
// depth bias plus the normal offset of the lookups (thesis §4.5's b; the screen-space
// contact-shadow fix marches this far, ssdo/ssdo_pass.c).
float drift_shadow_map_blind_length(const drift_shadow_map *map, drift_vec3 p, drift_vec3 n);
// --- ENVIRONMENT MAP (envmap.c) ---

// A cube map of the radiance seen from a probe point, emitted and reflected parts apart,
// with a mip chain so glossy lookups can blur by cone angle.
typedef struct drift_envmap drift_envmap;

drift_result drift_envmap_capture(drift_context *ctx, const drift_raster_shading *shading,
                                  drift_vec3 probe, uint32_t skip_mesh, int32_t face_size,
                                  uint32_t seed, drift_envmap **out_map, uint64_t *out_rays);
void drift_envmap_destroy(drift_context *ctx, drift_envmap *map); // NULL-safe

// Radiance seen along dir, blurred over a cone of half angle cone_angle (0 = sharpest level,
// bilinear).
drift_raster_radiance drift_envmap_lookup(const drift_envmap *map, drift_vec3 dir,
                                          float cone_angle);
drift_vec3 drift_envmap_probe(const drift_envmap *map);
// Box projection (a local cube map, Lagarde and Zanuttini 2012; Bjorke 2004): the direction to
// look a map captured at `probe` up in for the ray from p along dir, the direction from the
// probe to where the ray leaves `box`. dir itself when p is outside the box or the box is empty.
// out_ratio (may be NULL): that point's distance from p over its distance from the probe (1 when
// not corrected), which scales a glossy lobe's footprint as the probe sees it.
drift_vec3 drift_envmap_parallax_direction(drift_bounds3 box, drift_vec3 probe, drift_vec3 p,
                                           drift_vec3 dir, float *out_ratio);
// A lobe's cone half angle seen from the probe: a footprint of tan(cone) x distance from p,
// seen from `ratio` times farther or nearer.
float drift_envmap_parallax_cone(float cone, float ratio);

// The capture with the radiance per texel from `radiance` instead of the scene (what
// drift_envmap_capture wraps; tests pass a synthetic function of direction). `radiance` is
// called from the pool's threads at once, once per texel with a ray from the probe through
// the texel centre, and adds the rays it traced to *rays. out_rays may be NULL.
// Errors: DRIFT_ERR_INVALID_ARGUMENT (face_size outside 1..DRIFT_ENVMAP_MAX_FACE_SIZE,
// non-finite probe, NULL pointers; logged), DRIFT_ERR_OUT_OF_MEMORY.
#define DRIFT_ENVMAP_MAX_FACE_SIZE 4096
typedef drift_raster_radiance (*drift_envmap_radiance_fn)(void *user, drift_ray ray,
                                                          drift_sampler *sampler, uint64_t *rays);
drift_result drift_envmap_capture_fn(drift_context *ctx, drift_envmap_radiance_fn radiance,
                                     void *user, drift_vec3 probe, int32_t face_size, uint32_t seed,
                                     drift_envmap **out_map, uint64_t *out_rays);
int32_t drift_envmap_face_size(const drift_envmap *map);   // texels across a face at level 0
int32_t drift_envmap_level_count(const drift_envmap *map); // mip levels, down to 1x1

// Cube-face addressing (OpenGL's faces and orientation; envmap.c spells them out).
// The face a direction falls on (its major axis: 0..5 = +x -x +y -y +z -z) and its face
// coordinates (s, t) in [0,1]^2; dir need not be unit length. -1 for a zero or non-finite dir.
int drift_cube_face_coords(drift_vec3 dir, drift_vec2 *out_st);
// Unit direction through the centre of texel (i, j) (column i along s, row j along t) of
// `face` when a face has face_size x face_size texels.
drift_vec3 drift_cube_texel_direction(int32_t face_size, int face, int32_t i, int32_t j);

// --- DEPTH OF FIELD (post_dof.c) ---

// Circle-of-confusion radius in pixels of a point at view depth z for the thin-lens camera
// (aperture radius A, focus distance F, image height H): A |z - F| / z scaled by the
// pixels per scene unit on the focus plane, H / (2 F tan(fov_y / 2)). 0 for a pinhole.
float drift_coc_radius_pixels(const drift_camera *camera, int32_t image_height, float z);

// The same made once for a frame (its tanf was a per-pixel call of the composition):
// drift_coc_lens_radius(&lens, z) == drift_coc_radius_pixels(camera, image_height, z) for z > 0.
typedef struct drift_coc_lens {
    float aperture, focus, pixels_per_unit; // aperture 0: a pinhole, every radius 0
} drift_coc_lens;

drift_coc_lens drift_coc_lens_make(const drift_camera *camera, int32_t image_height);

static inline float drift_coc_lens_radius(const drift_coc_lens *lens, float z)
{
    return lens->aperture > 0.0f && z > 0.0f
               ? lens->aperture * fabsf(z - lens->focus) / z * lens->pixels_per_unit
               : 0.0f;
}

// The usual post-process DOF: each pixel averages concentric-disk samples over its own
// circle of confusion (colour leaks across depth edges, as in the usual real-time gather):
// the centre plus about one tap per four pixels of the disk's area (a power of two), at most
// `taps` in all. coc holds radii in pixels. in and out must differ; taps 0 -> 64.
// A pixel whose CoC is under half a pixel is copied exactly. out is preallocated with the
// size and channels of in. Errors: DRIFT_ERR_INVALID_ARGUMENT (sizes differ, out is in or coc,
// taps over DRIFT_POST_DOF_MAX_TAPS; logged), DRIFT_ERR_OUT_OF_MEMORY.
#define DRIFT_POST_DOF_MAX_TAPS 4096
drift_result drift_post_dof(drift_context *ctx, const drift_image *in, const drift_image *coc,
                            uint32_t taps, drift_image *out);
// The same with the shared-tap tiles on or off. drift_post_dof's tiles whose gathering pixels'
// circles lie within [r, 1.2 r + 0.5] (at most 32 px; images of up to 4 channels, tables of up to
// 256 taps) gather at once: every pixel the same taps, the table scaled by the tile's largest
// circle, each tap also weighed by whether it lies on the pixel's own disk (src/raster/
// post_dof.c). Off: every gathering pixel on its own (the pass before issue 46's tiles).
drift_result drift_post_dof_tiles(drift_context *ctx, const drift_image *in, const drift_image *coc,
                                  uint32_t taps, bool shared, drift_image *out);

#endif // DRIFT_HYBRID_INTERNAL_H
