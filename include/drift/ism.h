// drift ism: instant radiosity with imperfect shadow maps (Ritschel et al. 2008; thesis ch. 5).
// Diffuse indirect light from many virtual point lights (VPLs), each VPL's visibility taken
// from a tiny paraboloid depth map splatted from a sparse subset of the scene points and
// hole-filled by pull-push.
//
// The passes of one drift_ism_render (docs/ism.md has the equations):
//   1. VPLs: light paths from every light. Point and spot lights go through a reflective
//      shadow map (a ray-traced cube, one face for a narrow spot) whose texel flux is
//      importance-sampled through a 2-D CDF; area lights, directional lights and the
//      environment emit their paths directly (beyond the thesis). A path leaves one VPL at
//      each diffuse surface it reaches, for max_depth - 1 bounces (pt depth convention).
//   2. Imperfect shadow maps: VPL j splats point subset j of drift_points into its own
//      paraboloid map (z-test), then pull-push fills the holes; parallel over VPLs.
//   3. Gathering: each pixel of the G-buffer sums the VPLs of its interleaving subset
//      (block_size^2 subsets), visibility from the ISMs (or rays: the `ir` baseline), the
//      distance clamped at d_min; a geometry-aware blur over the block; times albedo / pi.
//
// STEP BY STEP
//   drift_ism *ism = NULL;
//   drift_ism_create(ctx, scene, accel, &(drift_ism_params){ .vpl_count = 256 }, &ism);
//   drift_ism_render(ism, gbuffer, &camera);          // per frame, after the G-buffer
//   const drift_image *indirect = drift_ism_indirect(ism);  // RGB radiance I
//   drift_ism_destroy(ism);
//
// Ownership: scene and accel are borrowed and must outlive the ism. Images and VPLs returned
// here belong to the ism and stay valid until the next render or destroy.
// Threads: one ism is driven from one thread; it uses the context's pool internally.
#ifndef DRIFT_ISM_H
#define DRIFT_ISM_H

#include "drift/accel.h"
#include "drift/core.h"
#include "drift/hybrid.h"
#include "drift/image.h"
#include "drift/points.h"
#include "drift/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

// Sampler stream of the VPL paths: drift_sampler_make(drift_hash_combine(seed,
// DRIFT_ISM_VPL_STREAM), 0, path index). The scene points use DRIFT_POINTS_STREAM with the
// same seed. Gathering draws no random numbers.
#define DRIFT_ISM_VPL_STREAM 0x76706c73u // "vpls"

typedef enum drift_ism_visibility {
    DRIFT_ISM_VISIBILITY_ISM = 0, // imperfect shadow maps (the technique)
    DRIFT_ISM_VISIBILITY_RAYS,    // one shadow ray per pixel and VPL: instant radiosity (`ir`)
    DRIFT_ISM_VISIBILITY_NONE,    // every VPL visible (the visibility-free limit, for tests)
    DRIFT_ISM_VISIBILITY_COUNT
} drift_ism_visibility;

// How to render. The default configuration is:
//   seed              = 0
//   visibility        = ISM
//   vpl_count         = 0 -> 256 light paths (first-bounce VPLs)
//   max_depth         = 0 -> 2 (pt convention: 2 = one bounce, the VPLs where light paths
//                       first land; D leaves VPLs at the first D - 1 path vertices)
//   later_vpl_count   = 0 -> vpl_count / 4: how many of the paths go on past their first VPL
//                       (their VPLs carry vpl_count / later_vpl_count times the flux)
//   max_path_rounds   = 0 -> 8: light paths go in rounds of vpl_count until half as many
//                       VPLs as paths have landed (lights that shine mostly outside the scene
//                       in view, a sun outside a window); 1 = one round
//   rsm_size          = 0 -> 64 texels a side of each reflective-shadow-map face
//   map_size          = 0 -> 64: the ISM of each VPL is map_size^2 texels
//   points_per_vpl    = 0 -> 1024 scene points splatted into each ISM
//   splat_scale       = 0 -> 0.6: k of the splat side in texels,
//                       s = clamp(k sqrt(A_pt / pi) n / (r (1 + v.z)), 1, 8)
//   pull_push_levels  = 0 -> 2; negative: no hole filling
//   pull_push_threshold = 0 -> 0.05 x scene extent at level 0 (times 2^l at level l)
//   depth_bias        = 0 -> 0.01 x scene extent, plus one texel's footprint at the receiver
//   clamp_distance    = 0 -> 0.1 x scene extent (0.05 with no_near_field): d_min of the
//                       geometry term
//   no_near_field     = false: rays at most d_min long, from one pixel in near_field_stride^2,
//                       add back the light of the surfaces nearer than d_min that the clamp
//                       takes away (near-field compensation; it needs drift_ism_render's direct
//                       image)
//   near_field_stride = 0 -> 2 (1 for an odd block_size): the compensation's rays leave one
//                       pixel in stride x stride, weighed by stride^2; divides block_size
//   block_size        = 0 -> 4: interleaved sampling over 4x4 pixel blocks (1 = every pixel
//                       gathers every VPL)
//   no_blur           = false: the geometry-aware blur over the block runs
//   gather_scale      = 0 -> 1: every G-buffer pixel gathers; 2 (or 4): one pixel in 2 x 2
//                       (4 x 4) gathers, blurs and compensates at that lower resolution, and
//                       the irradiance is upsampled to every pixel through the blur's tests
//                       (its four nearest gathering pixels, else the twelve around them; a
//                       pixel none of those passes gathers every VPL itself); the albedo is
//                       applied at full resolution
//   blur_normal       = 0 -> 0.9: smallest cosine between two normals the blur mixes
//   blur_plane        = 0 -> 0.01 x scene extent: largest distance to the centre's plane
//   vpl_importance    = false: true accepts each candidate VPL with p = min(1, c / target), c
//                       its unshadowed contribution to 256 G-buffer points, and divides the
//                       accepted by p (Georgiev & Slusallek 2010); rounds go on until
//                       vpl_count first-bounce VPLs are accepted or max_path_rounds
typedef struct drift_ism_params {
    uint32_t seed;
    drift_ism_visibility visibility;
    uint32_t vpl_count;
    int32_t max_depth;
    uint32_t later_vpl_count;
    int32_t max_path_rounds;
    int32_t rsm_size;
    int32_t map_size;
    uint32_t points_per_vpl;
    float splat_scale;
    int32_t pull_push_levels;
    float pull_push_threshold;
    float depth_bias;
    float clamp_distance;
    bool no_near_field;
    int32_t near_field_stride;
    int32_t block_size;
    bool no_blur;
    int32_t gather_scale;
    float blur_normal;
    float blur_plane;
    bool vpl_importance;
} drift_ism_params;

drift_ism_params drift_ism_params_resolve(const drift_ism_params *params, const drift_scene *scene);

// One virtual point light: a cosine emitter of total flux `flux` on the surface at position
// with normal `normal` (facing the side the light came from).
// A VPL shines I(w) = (flux + glossy cos^m(w, lobe)) cos(w, normal) / pi: its diffuse lobe,
// and on a glossy surface the Phong lobe around the incoming light's mirror direction, its
// exponent m clamped to DRIFT_VPL_MAX_EXPONENT (a wider lobe of the same energy, so that a
// few hundred VPLs do not paint the glossy floor's reflected light as spots).
typedef struct drift_vpl {
    drift_vec3 position;
    drift_vec3 normal;
    drift_vec3 flux;    // the light its diffuse lobe reflects
    uint32_t bounce;    // 1 for the first surface a light path reaches
    drift_vec3 glossy;  // incoming flux x ks (m + 2) / 2; zero for a diffuse or mirror VPL
    drift_vec3 lobe;    // the glossy lobe's axis
    uint32_t squarings; // m = 2^squarings
} drift_vpl;

#define DRIFT_VPL_MAX_SQUARINGS 6
#define DRIFT_VPL_MAX_EXPONENT  ((float)(1u << DRIFT_VPL_MAX_SQUARINGS))

typedef enum drift_ism_stage {
    DRIFT_ISM_STAGE_VPLS = 0, // reflective shadow maps, CDFs and the VPL paths
    DRIFT_ISM_STAGE_POINTS,   // re-deriving the scene points from the meshes
    DRIFT_ISM_STAGE_SPLAT,    // splatting the points into the ISMs
    DRIFT_ISM_STAGE_PULL_PUSH,
    DRIFT_ISM_STAGE_GATHER,     // interleaved gathering (with the shadow rays for `ir`)
    DRIFT_ISM_STAGE_BLUR,       // geometry-aware blur and the albedo multiply
    DRIFT_ISM_STAGE_NEAR_FIELD, // the near-field compensation's rays (its blur is BLUR's)
    DRIFT_ISM_STAGE_UPSAMPLE,   // gather_scale > 1: the decimated G-buffer, the upsampling and
                                // the gathers of the pixels it has no neighbour for
    DRIFT_ISM_STAGE_COUNT
} drift_ism_stage;

const char *drift_ism_stage_name(drift_ism_stage stage);

typedef struct drift_ism_stats {
    double ms[DRIFT_ISM_STAGE_COUNT];
    double total_ms;
    uint32_t vpl_count;   // VPLs of the last render (all bounces)
    uint64_t shadow_rays; // `ir` visibility rays
    uint64_t near_field_rays;
    uint64_t fallback_pixels; // gather_scale > 1: pixels that gathered every VPL themselves
    uint64_t splats;          // points splatted
    double hole_fraction;     // ISM texels still empty after pull-push
} drift_ism_stats;

typedef struct drift_ism drift_ism;

// Samples the scene points once (the only pre-computation). Errors:
// DRIFT_ERR_INVALID_ARGUMENT (uncommitted scene, bad parameters; logged),
// DRIFT_ERR_OUT_OF_MEMORY.
drift_result drift_ism_create(drift_context *ctx, const drift_scene *scene,
                              const drift_accel *accel, const drift_ism_params *params,
                              drift_ism **out_ism);
void drift_ism_destroy(drift_ism *ism); // NULL-safe

// Renders the indirect light of one frame: re-derives the points from the meshes, draws the
// VPLs, builds the maps and gathers at every G-buffer pixel (or one in gather_scale^2, then
// upsampled). The G-buffer's position, normal,
// geometric_normal, albedo and material_id planes are read. `direct` is the frame's direct
// radiance at each pixel (RGB, the G-buffer's size): the near-field compensation reads the light
// the surfaces it hits reflect off it, and needs it, the camera and the G-buffer's surfaces and
// depth. With params.no_near_field `direct` is not read (may be NULL) and `camera` may be NULL
// (it then only places the "ism.vpls" plane). Errors: DRIFT_ERR_INVALID_ARGUMENT (the
// compensation's inputs missing; a G-buffer of another size than the last call is fine, an
// empty one is not), DRIFT_ERR_OUT_OF_MEMORY.
drift_result drift_ism_render(drift_ism *ism, const drift_gbuffer *gbuffer,
                              const drift_camera *camera, const drift_image *direct);
// One of `slices` renders of the same lights from nearly the same view (the anti-aliasing
// passes of one frame, whose cameras differ by a sub-pixel shift): slice 0 draws the VPLs and
// builds their maps as drift_ism_render does, a later slice keeps the last render's (it draws
// them only when there are none). Each gathers its own 1/slices of every group of VPLs, at
// `slices` times their light, so the mean of the slices' images gathers every VPL once: the
// lights of slices renders at the gathering cost of one. The near-field compensation runs in
// full in each. Errors: those of drift_ism_render; DRIFT_ERR_INVALID_ARGUMENT for
// slice >= slices.
drift_result drift_ism_render_slice(drift_ism *ism, const drift_gbuffer *gbuffer,
                                    const drift_camera *camera, const drift_image *direct,
                                    uint32_t slice, uint32_t slices);
// Draws the next render's VPL paths (and the near-field rays) from `seed` without remaking
// the pre-computation: the scene points keep the seed the object was created with. A sequence
// that reseeds every frame gets an independent set of VPLs a frame at the cost of a render
// (temporal reuse averages them: docs/temporal.md). NULL-safe.
void drift_ism_set_seed(drift_ism *ism, uint32_t seed);

// RGB radiance: the diffuse indirect light I at each pixel (0 where the G-buffer missed).
const drift_image *drift_ism_indirect(const drift_ism *ism);
// Diagnostic planes by name: "ism.irradiance" (RGB, before blur and albedo), "ism.near_field"
// (RGB, the compensation's irradiance a pixel, before blur and albedo; these two and ism.vpls
// at the gathering resolution, the G-buffer's divided by gather_scale), "ism.vpls" (RGB,
// the VPLs' flux splatted where they project on the camera image), "ism.tile" (1 channel,
// the depth map of VPL 0 after pull-push, 0 where empty). NULL when the last render has none.
const drift_image *drift_ism_plane_named(const drift_ism *ism, const char *name);
const drift_vpl *drift_ism_vpls(const drift_ism *ism, uint32_t *out_count);
drift_ism_stats drift_ism_get_stats(const drift_ism *ism);
drift_ism_params drift_ism_get_params(const drift_ism *ism);

// --- PARABOLOID MAPPING (Brabec et al. 2002) ---

// A unit direction v with v.z >= 0 in a VPL's frame -> its map coordinate in the unit disc.
static inline drift_vec2 drift_paraboloid_project(drift_vec3 v)
{
    float s = 1.0f / (1.0f + v.z);
    return drift_vec2_make(v.x * s, v.y * s);
}

// The inverse: a point of the unit disc -> the unit direction of the hemisphere z >= 0.
static inline drift_vec3 drift_paraboloid_unproject(drift_vec2 p)
{
    float r2 = p.x * p.x + p.y * p.y;
    float s = 1.0f / (1.0f + r2);
    return drift_vec3_make(2.0f * p.x * s, 2.0f * p.y * s, (1.0f - r2) * s);
}

#ifdef __cplusplus
}
#endif
#endif // DRIFT_ISM_H
