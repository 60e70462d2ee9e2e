// drift hybrid: the hybrid frame. One sharp sample per pixel stored as image-space buffers,
// the rasterization-style approximations a real-time renderer uses, and a composition that
// picks a technique per effect. Every later technique (ISG, AAF, SIR) is one more pass here.
//
// The frame, pass by pass (docs/hybrid.md has the equations):
//   1. primary visibility: one pinhole ray through each pixel centre -> the G-buffer planes
//   2. sharp inputs: one shadow ray per pixel per light toward the light's centre (hard-shadow
//      buffer), one mirror ray per glossy or mirror pixel (sharp reflection buffer), and the
//      in-focus colour, depth and circle of confusion
//   3. approximations: shadow maps (hard lookup, PCF, PCSS), a cube environment map captured
//      at a probe point, post-process depth of field
//   4. composition: L = E + sum_l U_l * S_l + R + I, then depth of field.
//      E emission, U_l the unshadowed direct light from light l, S_l its shadow term,
//      R reflections (paths whose first bounce is glossy or mirror), I indirect light
//      (first bounce diffuse). Each of S, R, I and the depth of field comes from the chosen
//      technique; `reference` computes that term alone with the reference path tracer
//      (drift_pt with DRIFT_PT_COMPONENT_*), so its error is the technique's and no other.
//
// STEP BY STEP
//   drift_hybrid *frame = NULL;
//   drift_hybrid_params params = { .shadows = DRIFT_SHADOWS_PCSS, .dof = DRIFT_DOF_POST };
//   drift_hybrid_create(ctx, scene, accel, &params, &frame);
//   drift_hybrid_render(frame, &scene->camera, &cancel);      // once per frame
//   const drift_image *rgb = drift_hybrid_image(frame);        // linear radiance
//   drift_hybrid_stats stats = drift_hybrid_get_stats(frame); // ms and rays per pass
//   drift_hybrid_destroy(frame);
//
// Ownership: scene and accel are borrowed and must outlive the frame. Images returned here
// belong to the frame and stay valid until the next render or destroy.
// Threads: one frame is driven from one thread; it uses the context's pool internally.
#ifndef DRIFT_HYBRID_H
#define DRIFT_HYBRID_H

#include "drift/accel.h"
#include "drift/core.h"
#include "drift/image.h"
#include "drift/reflect_edit.h"
#include "drift/scene.h"
#include "drift/techniques.h"

#ifdef __cplusplus
extern "C" {
#endif

// --- EFFECTS AND TECHNIQUES ---

// Effects and their techniques' values, generated from the technique table
// (drift/techniques.h). The names (drift_effect_name, drift_technique_name) are stable: the
// command line, stats files and the viewer use them, and later techniques append rows.
#define DRIFT_EFFECT_ENUM_(ENUM, name, type, TECHNIQUES, kind, plane) DRIFT_EFFECT_##ENUM,

typedef enum drift_effect {
    DRIFT_EFFECTS(DRIFT_EFFECT_ENUM_) DRIFT_EFFECT_COUNT
} drift_effect;

#define DRIFT_TECHNIQUE_ENUM_(P, ENUM, ...) P##ENUM,
#define DRIFT_TECHNIQUE_TYPE_(ENUM, name, type, TECHNIQUES, kind, plane)                      \
    typedef enum drift_##type##_technique{ TECHNIQUES(DRIFT_TECHNIQUE_ENUM_, DRIFT_##ENUM##_) \
                                               DRIFT_##ENUM##_COUNT } drift_##type##_technique;
DRIFT_EFFECTS(DRIFT_TECHNIQUE_TYPE_)

const char *drift_effect_name(drift_effect effect); // "shadows", "reflections", "dof", "indirect"
int drift_technique_count(drift_effect effect);
// NULL when technique is out of range.
const char *drift_technique_name(drift_effect effect, int technique);
// One line describing the technique (the table's summary), for --help and the viewer; NULL
// when technique is out of range.
const char *drift_technique_summary(drift_effect effect, int technique);
// Whether the technique path-traces (reference, AAF, ...): its cost grows with --spp. The
// others are the real-time rows a frame benchmark sweeps.
bool drift_technique_path_traced(drift_effect effect, int technique);
// Whether the equal-time frontier (drift bench frontier, docs/frontier.md) searches the
// technique: the table's DRIFT_ROW_FRONTIER flag (shadows hard, pcss, isg, aaf; indirect
// none, ambient, aaf, ism, ir).
bool drift_technique_frontier(drift_effect effect, int technique);
// The technique called `name`, or -1.
int drift_technique_parse(drift_effect effect, const char *name);

// --- PARAMETERS ---

// Each technique family's settings, nested in drift_hybrid_params; 0 (false) picks the default,
// and each family resolves and checks its own (src/realtime, src/isg, src/aaf).

// Shadow maps (pcf, pcss, and SIR's penumbra metric):
//   size       = 0 -> 512 texels a cube face
//   bias       = 0 -> 1.5 texels (the depth bias, scaled by the texel footprint)
//   pcf_kernel = 0 -> 3 (texels across; 1 = a single tap)
//   contact_shadows = false: true marches each lit pixel's blind length toward the light in
//              screen space and shadows it on an occluder (thesis §4.5, docs/ssdo.md), with
//              contact_samples = 0 -> 8 points; the occlusion settings' layers and cameras
//              apply to it too
typedef struct drift_shadow_map_settings {
    int32_t size;
    float bias;
    int32_t pcf_kernel;
    bool contact_shadows;
    int32_t contact_samples;
} drift_shadow_map_settings;

// Environment-map reflections (envmap):
//   size       = 0 -> 128 texels a cube face
//   per_object = false: one probe at the scene centre (or `probe` when has_probe); true: one
//                probe at the centre of every reflective mesh
//   parallax   = NONE: the map looked up along the reflected direction, as if every pixel sat at
//                the probe; BOX: parallax-corrected (a local cube map, Lagarde and Zanuttini
//                2012): the reflected ray meets the scene's bounding box and the map is looked
//                up from the probe toward that point
typedef enum drift_envmap_parallax {
    DRIFT_ENVMAP_PARALLAX_NONE = 0,
    DRIFT_ENVMAP_PARALLAX_BOX = 1,
} drift_envmap_parallax;

typedef struct drift_envmap_settings {
    int32_t size;
    bool has_probe;
    drift_vec3 probe;
    bool per_object;
    drift_envmap_parallax parallax;
} drift_envmap_settings;

// Post-process depth of field (post; src/raster/post_dof.c):
//   per_pixel = false: the 16 x 16 tiles whose gathering pixels' circles are alike gather with
//               one set of taps for the whole tile (issue 46: about 2.8x faster on the bench
//               frame, FLIP against the path tracer unchanged; docs/lab/2026-12-08-issue-46-s8-
//               dof.md); true: every pixel its own taps (the pass before)
typedef struct drift_post_dof_settings {
    bool per_pixel;
} drift_post_dof_settings;

// Image space gathering (docs/isg.md):
//   search, gather = 0 -> 25, 49 samples (perfect squares 1..1024: 9, 25, 49, 81)
//   sigma       = 0 -> (0.02 x scene extent)^2, sigma of eq. 6 and 10 in squared scene units
//   a, b        = 0 -> 1 and 100 sigma (eq. 10: a normal difference n = 0.1 costs 1/e)
//   blur_radius = 0 -> 4 pixels, the disk of the `blur` baselines
//   layers      = 0 -> 1; 2 adds a second depth layer (one more ray a pixel) that ISG depth of
//                 field reads behind foreground objects
//   range_plane = false: l of eq. 7 and 11 is the world distance (the paper); true: the
//                 distance to the centre's tangent plane (docs/isg.md)
typedef struct drift_isg_settings {
    int32_t search;
    int32_t gather;
    float sigma;
    float a, b;
    float blur_radius;
    int32_t layers;
    bool range_plane;
} drift_isg_settings;

// Axis-aligned filtering (docs/aaf.md):
//   max_spp    = 0 -> 8 x spp (at most 4096): the cap on AAF's adaptive n(x)
//   uniform    = false: AAF samples adaptively; true: every pixel takes spp samples
//   unfiltered = false: AAF filters; true: the noisy estimate is used as it is (both true:
//                plain Monte Carlo with AAF's sampler, the benchmark baseline)
//   random     = false: AAF's samples are Owen-scrambled Sobol points; true: independent
//                uniform random numbers (the paper's traditional Monte Carlo sampling)
//   denoise    = OFF: AAF's own filter alone; ON: the path tracer's feature-guided denoiser
//                (drift/denoise.h) instead of it; BOTH: the denoiser, then AAF's filter
//                (measured in docs/aaf.md; OFF is the default)
typedef enum drift_aaf_denoise {
    DRIFT_AAF_DENOISE_OFF = 0,
    DRIFT_AAF_DENOISE_ON,
    DRIFT_AAF_DENOISE_BOTH,
} drift_aaf_denoise;

typedef struct drift_aaf_settings {
    uint32_t max_spp;
    bool uniform;
    bool unfiltered;
    bool random;
    drift_aaf_denoise denoise;
} drift_aaf_settings;

// Instant radiosity (indirect ism and ir, docs/ism.md):
//   vpls           = 0 -> 256 light paths (first-bounce VPLs)
//   map_size       = 0 -> 64: each VPL's imperfect shadow map is map_size^2 texels
//   points_per_vpl = 0 -> 1024 scene points splatted into each map
//   vpl_importance = false: true keeps VPLs by their contribution to the view (docs/ism.md)
//   no_near_field  = false: the near-field compensation runs (short rays, docs/ism.md)
//   gather_scale   = 0 -> 1: every pixel gathers; 2 or 4: one in 2 x 2 or 4 x 4, upsampled
typedef struct drift_ism_settings {
    uint32_t vpls;
    int32_t map_size;
    uint32_t points_per_vpl;
    bool vpl_importance;
    bool no_near_field;
    int32_t gather_scale;
    uint32_t later_paths; // drift_ism_params.later_vpl_count: 0 -> vpls / 4
} drift_ism_settings;

// Micro-rendering (indirect micro and reflections micro, docs/micro.md):
//   points      = 0 -> 65536 scene points in the hierarchy (rounded up to a power of two)
//   buffer_size = 0 -> 16: K, each gather's micro-buffer is K x K pixels
//   density     = 0 -> 1: a gather every pixel; 2: 1/4 of them, 4: 1/16 (bilateral upsampling)
//   bounces     = 0 -> 1: light bounces at the points; lighting: a drift_micro_lighting (0: auto)
typedef struct drift_micro_settings {
    uint32_t points;
    int32_t buffer_size;
    int32_t density;
    int32_t bounces;
    int32_t lighting;
} drift_micro_settings;

// Light from the environment in screen space (occlusion ssao, gtao, ssdo; docs/ssdo.md):
//   samples = 0 -> 16: N sample points a pixel (GTAO: slices x steps x 2 horizon samples)
//   radius  = 0 -> 0.05 x the scene's extent: r_max, the sample hemisphere's radius
//   bounce  = false: SSDO's one indirect bounce (only when no indirect technique is chosen)
//   layers  = 0 -> 1; 2: a second depth layer (one more ray a pixel) so that a sample behind a
//             thin object is not taken for occluded (thesis §4.3.2, drift_ssdo_peel)
//   no_fade = false: occluders at 0.75..1 r_max fade out; no_blur = false: the 4x4
//             geometry-aware blur over the interleaved sample sets runs
//   cameras = 0: additional depth-only cameras (0..5, thesis §4.3.3, drift_ssdo_views_render)
//             at half the frame's size that find occluders outside the image (ssao, ssdo)
//   steps   = 0 -> 1: points on each ssao/ssdo sample direction; more march it to r_max (a ray
//             test instead of the thesis's point test; drift_ssdo_params.steps)
typedef struct drift_occlusion_settings {
    int32_t samples;
    float radius;
    bool bounce;
    int32_t layers;
    bool no_fade;
    bool no_blur;
    int32_t cameras;
    int32_t steps;
} drift_occlusion_settings;

// How to build a frame. The default configuration is:
//   width, height    = 0 -> the scene camera's size
//   techniques       = hard shadows, no reflections, no depth of field, no indirect light
//   seed             = 0
//   spp              = 0 -> 64 samples a pixel for `reference` effects
//   max_depth        = 0 -> 2 for reference reflections and indirect light (pt convention:
//                      2 = one bounce, what the sharp buffers can capture)
//   light_samples    = 0 -> 8 samples per area light for the unshadowed light U_l
//   environment_interleave = false: each pixel traces its light_samples environment shadow
//                      rays; true: interleaved sampling (Keller and Heidrich 2001), each pixel
//                      of a 2 x 2 block traces a quarter of one shared set, and a 3 x 3
//                      tent gather over pixels of the same surface sums the set again
//   environment_scale = 0 or 1: every pixel traces the environment's shadow rays; 2: one
//                      pixel in 2 x 2 does, and the other three take the bilinear mix of
//                      the traced ones on their surface (demodulated by the albedo), or
//                      trace their own where none is (not with environment_interleave)
//   environment_filter = 0: the environment's direct light as traced; N (at most 10):
//                      N passes of the edge-avoiding a-trous filter (drift/denoise.h; its
//                      3 x 3 kernel) over it, guided by the G-buffer's normal, depth and
//                      albedo (the light is demodulated), with no colour weight: its noise is
//                      visibility's, which the colour weight would keep. A footprint of
//                      2^(N+1) - 1 pixels; with environment_scale 2 the passes run over the
//                      traced pixels alone, before the fill (2^(N+2) - 2 full pixels)
//   environment_denoise = false: environment_filter is the a-trous filter above; true: its N
//                      passes are the path tracer's variance-guided filter instead
//                      (drift_denoise_feature: demodulated, fireflies clamped, the luminance
//                      weight set by the spatial variance of light_samples rays a pixel)
//   aa               = 0 -> 1: anti-aliasing passes. N > 1 renders the whole frame N times,
//                      each pass with the camera's film shifted by a stratified sub-pixel
//                      offset (the path tracer's box pixel filter) and its own seed, and
//                      averages them: edges converge to the path tracer's pixel filter. 1 is
//                      one sample through each pixel centre. Costs about N frames: ISM's
//                      VPLs and maps are built once and each pass gathers 1/N of them, and
//                      `hard` shadow rays aim at a stratified point of an area light per pass
//                      (the passes average N shadow samples: soft shadows; docs/hybrid.md).
//   ambient          = used when has_ambient; otherwise the mean direct radiance of the frame
//   shadow_map, envmap, post_dof, isg, aaf, ism, micro, occlusion_settings: each family's
//                      settings (above)
//   reflection_edits = NULL: physical reflections. Otherwise the sharp and environment-map
//                      reflections (and so ISG's glossy gather over the sharp buffer) and the
//                      reference's first specular bounce follow e(q) (drift/reflect_edit.h).
//                      Borrowed: it must outlive the frame.
#define DRIFT_TECHNIQUE_FIELD_(ENUM, name, type, TECHNIQUES, kind, plane) \
    drift_##type##_technique name;

typedef struct drift_hybrid_params {
    int32_t width, height;

    // One technique an effect, by name (params.shadows = DRIFT_SHADOWS_PCSS) or by effect
    // (params.techniques[DRIFT_EFFECT_SHADOWS]): the fields come from the technique table.
    union {
        struct {
            DRIFT_EFFECTS(DRIFT_TECHNIQUE_FIELD_)
        };

        int techniques[DRIFT_EFFECT_COUNT];
    };

    uint32_t seed;
    uint32_t spp;
    int32_t max_depth;
    uint32_t light_samples;
    bool environment_interleave;
    uint32_t environment_filter;
    uint32_t environment_scale;
    bool environment_denoise;
    uint32_t aa;
    bool has_ambient;
    drift_vec3 ambient;
    drift_shadow_map_settings shadow_map;
    drift_envmap_settings envmap;
    drift_post_dof_settings post_dof;
    drift_isg_settings isg;
    drift_aaf_settings aaf;
    drift_ism_settings ism;
    drift_micro_settings micro;
    drift_occlusion_settings occlusion_settings;
    const drift_reflection_edits *reflection_edits;
} drift_hybrid_params;

drift_hybrid_params drift_hybrid_params_resolve(const drift_hybrid_params *params,
                                                const drift_scene *scene);
// drift_hybrid_params_default() (drift/knobs.h): every effect's default technique and every
// knob at the default in its row of the knob table, the one default the command line, the
// viewer and --help use. Kept for the callers of the earlier name. A zeroed
// drift_hybrid_params stays the library's neutral frame (hard shadows, no indirect light, 8
// light samples, max depth 2, each family's zero fallbacks).
drift_hybrid_params drift_hybrid_params_recommended(void);
// The technique `params` chooses for `effect` (-1 for an invalid effect), and setting it: one
// int per effect for code that walks the effects (the viewer's keys and overlay, the CLI).
int drift_hybrid_params_technique(const drift_hybrid_params *params, drift_effect effect);
void drift_hybrid_params_set_technique(drift_hybrid_params *params, drift_effect effect,
                                       int technique);

// --- G-BUFFER ---

// One pinhole sample at each pixel centre. A pixel whose ray misses has depth 0 and
// material_id -1; its emission plane holds the environment radiance.
typedef struct drift_gbuffer {
    int32_t width, height;
    drift_image depth;            // 1: view depth (along the camera's forward axis)
    drift_image position;         // 3: world position
    drift_image normal;           // 3: unit shading normal, facing the camera
    drift_image geometric_normal; // 3: unit geometric normal, facing the camera
    drift_image albedo;           // 3: diffuse reflectance kd (textures applied)
    drift_image specular;         // 3: glossy or mirror reflectance ks
    drift_image gloss;            // 3: theta_max (radians; 0 mirror), Phong exponent (INFINITY
                                  //    for a mirror), Beckmann-equivalent roughness
    drift_image material_id;      // 1: material index, -1 for a miss or a light's shape
    drift_image emission;         // 3: emitted radiance toward the camera (environment on a miss)
    drift_image motion;           // 2: pixels from here to this point in the previous frame
                                  //    (the camera's move and its mesh's: set_mesh_motion)
    drift_surface *surfaces;      // width*height, what shading needs (material invalid = none)
    uint32_t *mesh_index;         // width*height, the mesh hit, DRIFT_INVALID_INDEX for none
    // width*height: where this point was in the previous frame minus where it is (world
    // space): zero unless its mesh moved (drift_hybrid_set_mesh_motion).
    drift_vec3 *object_motion;
} drift_gbuffer;

// --- FRAME ---

typedef enum drift_hybrid_pass {
    DRIFT_PASS_PRIMARY = 0,   // G-buffer
    DRIFT_PASS_UNSHADOWED,    // U_l for every pixel and light
    DRIFT_PASS_HARD_SHADOWS,  // hard-shadow buffer
    DRIFT_PASS_SHADOW_MAPS,   // building the shadow maps (cached while the scene stands)
    DRIFT_PASS_SHADOW_FILTER, // PCF or PCSS lookups
    DRIFT_PASS_REFLECTIONS,   // sharp reflection buffer
    DRIFT_PASS_ENVMAP,        // capturing the cube map (cached) and looking it up
    DRIFT_PASS_REFERENCE,     // every `reference` effect
    DRIFT_PASS_COMPOSE,
    DRIFT_PASS_DOF,          // post-process depth of field
    DRIFT_PASS_ISG,          // image space gathering (every effect) and the blur baselines
    DRIFT_PASS_AAF_SAMPLING, // AAF sparse and adaptive sampling (shadows and indirect)
    DRIFT_PASS_AAF_FILTER,   // AAF's separable filter
    DRIFT_PASS_COUNT
} drift_hybrid_pass;

const char *drift_hybrid_pass_name(drift_hybrid_pass pass);

#define DRIFT_HYBRID_MAX_COUNTS 48 // the counts one frame can report

typedef struct drift_hybrid_stats {
    double ms[DRIFT_PASS_COUNT]; // wall milliseconds of the last frame, per pass
    // Per effect: its chosen technique's own work (the row's pass, and summing D after a
    // shadow technique), without the inputs rows share (U_l, hard shadows, shadow maps, ...).
    double effect_ms[DRIFT_EFFECT_COUNT];
    uint64_t rays[DRIFT_PASS_COUNT];
    double frame_ms; // the whole drift_hybrid_render call
    // With ms[DRIFT_PASS_PRIMARY] and effect_ms, the frame's stages, each timed once at the
    // top level of drift_hybrid_render and none inside another (drift_hybrid_stats_stage).
    double inputs_ms;  // the inputs the chosen rows share (U_l, hard shadows, maps, probes, ...)
    double compose_ms; // L = E + D + R + I + ...
    double other_ms;   // --aa's running sum and the list of planes

    // What the frame did, as each technique family reports it (drift_hybrid_stats_count).
    struct {
        const char *name; // "family.what": "ism.vpls", "aaf.indirect.mean_spp", ...
        double value;
    } counts[DRIFT_HYBRID_MAX_COUNTS];

    uint32_t count_count;
} drift_hybrid_stats;

// The frame's stages, in order: "primary", "inputs", every effect by name (its chosen row's
// whole work: the ISM or AAF pass, summing D after a shadow row, ...), "compose", "other".
// Each is timed once at the top level of the frame, so they add up to frame_ms but for the
// frame's own bookkeeping: the pass table, the viewer's overlay and --stats print these and
// cannot leave a stage out. Returns false past the last stage.
bool drift_hybrid_stats_stage(const drift_hybrid_stats *stats, uint32_t index,
                              const char **out_name, double *out_ms);

// What the frame did, count by count, in the order the families report them: each chosen
// row's family reports its own samples and set-up ("realtime.environment_shadow_rays",
// "isg.shadows.gather_samples", "aaf.indirect.mean_spp", "ism.vpls", "micro.indirect.points",
// ...; docs/hybrid.md lists them). With --aa N, the last pass's. Returns false past the last.
bool drift_hybrid_stats_count(const drift_hybrid_stats *stats, uint32_t index,
                              const char **out_name, double *out_value);

typedef struct drift_hybrid drift_hybrid;

// Errors: DRIFT_ERR_INVALID_ARGUMENT (uncommitted scene, bad parameters, logged),
// DRIFT_ERR_OUT_OF_MEMORY.
drift_result drift_hybrid_create(drift_context *ctx, const drift_scene *scene,
                                 const drift_accel *accel, const drift_hybrid_params *params,
                                 drift_hybrid **out_frame);
void drift_hybrid_destroy(drift_hybrid *frame); // NULL-safe

// Changes techniques or settings for the next frame. Caches that still hold (shadow maps,
// the environment map) are kept. The size may not change.
drift_result drift_hybrid_set_params(drift_hybrid *frame, const drift_hybrid_params *params);
drift_hybrid_params drift_hybrid_get_params(const drift_hybrid *frame);
// The scene's geometry or lights moved (drift_scene_animation_pose, then a new `accel` built
// over it): every technique's per-scene state (shadow maps, probes, VPLs, scene points,
// caches) is dropped and remade on the next frame, which is right for any change and costs a
// frame's set-up. The light count may not change. The meshes' own motion for the motion
// vectors is drift_hybrid_set_mesh_motion's.
drift_result drift_hybrid_scene_changed(drift_hybrid *frame, const drift_accel *accel);
// How each mesh moved since the previous frame, for the next drift_hybrid_render's motion
// vectors: prev_from_now[12 m .. 12 m + 11] is the row-major 3 x 4 affine map taking mesh m's
// points now to where they were (drift_scene_animation_motion); mesh_count must be the
// scene's. NULL: no mesh moved. It holds for one frame (all its --aa passes).
drift_result drift_hybrid_set_mesh_motion(drift_hybrid *frame, const float *prev_from_now,
                                          uint32_t mesh_count);

// Renders one frame seen by `camera` (its width/height are ignored: the frame's size is
// used). Motion vectors are relative to the camera of the previous call (zero the first
// time). `cancel` may be NULL; reference passes poll it (DRIFT_ERR_CANCELLED).
drift_result drift_hybrid_render(drift_hybrid *frame, const drift_camera *camera,
                                 const atomic_bool *cancel);

// The composed frame: linear radiance, RGB.
const drift_image *drift_hybrid_image(const drift_hybrid *frame);
const drift_gbuffer *drift_hybrid_gbuffer(const drift_hybrid *frame);
drift_hybrid_stats drift_hybrid_get_stats(const drift_hybrid *frame);

// Every plane and buffer of the last frame, by name ("depth", "light0.hard_shadow",
// "reflection.emitted", ...): for --aov and the viewer. Returns false past the last index.
// Planes a technique did not need this frame are absent.
bool drift_hybrid_plane(const drift_hybrid *frame, uint32_t index, const char **out_name,
                        const drift_image **out_image);
// The plane called `name`, or NULL when the last frame has none.
const drift_image *drift_hybrid_plane_named(const drift_hybrid *frame, const char *name);

#ifdef __cplusplus
}
#endif
#endif // DRIFT_HYBRID_H
