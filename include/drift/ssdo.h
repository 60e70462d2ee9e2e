// drift ssdo: light from the environment and from nearby surfaces in screen space: classic
// SSAO, ground-truth AO with bent normals (GTAO, Jimenez et al. 2016) and screen-space
// directional occlusion with one indirect bounce (SSDO, Ritschel, Grosch & Seidel 2009; thesis
// ch. 4). docs/ssdo.md has the equations as implemented, the defaults and the departures.
//
// Every technique reads one G-buffer (world position, normal, albedo, depth) and the camera
// that made it, and writes the same output planes, so they are interchangeable:
//   radiance    O = rho * (direct + bounce): light leaving each pixel toward the camera that
//               arrived from the environment (direct) or from one diffuse bounce off a nearby
//               on-screen surface lit by the environment (bounce; SSDO only)
//   direct      rho * (the environment light that reaches the pixel)
//   bounce      rho * (the one-bounce light), zero unless SSDO with bounce
//   visibility  1 channel: the cosine-weighted fraction of the hemisphere that is open (AO)
//   bent_normal 3 channels: the mean open direction (unit; the normal where all is closed)
// Pixels with no surface (depth 0) or on a light's shape (material_id -1) are zero.
//
// STEP BY STEP
//   drift_ssdo_env *env = NULL;                       // once per environment
//   drift_ssdo_env_create(ctx, scene, &(drift_ssdo_env_desc){ 0 }, &env);
//   drift_ssdo_output out;
//   drift_ssdo_output_create(ctx, gbuffer->width, gbuffer->height, &out);
//   drift_ssdo_params params = { .method = DRIFT_SSDO_METHOD_SSDO, .bounce = true };
//   drift_ssdo_inputs in = { .gbuffer = gbuffer, .camera = camera };
//   drift_ssdo_render(ctx, env, &in, &params, &out);                     // once per frame
//   ... out.radiance ...
//   drift_ssdo_output_destroy(ctx, &out);
//   drift_ssdo_env_destroy(env);
//
// The reference for the same term is drift_ssdo_reference: the path tracer's environment
// light with visibility (DRIFT_PT_COMPONENT_DIRECT, max depth 1) plus, for the bounce, its
// first-bounce diffuse light (DRIFT_PT_COMPONENT_DIFFUSE at max depth 2).
//
// Randomness: the M = 4x4 sample sets are Owen-scrambled Sobol points keyed on
// (seed ^ DRIFT_SSDO_STREAM, set, sample): fixed per seed, so frames are bit-identical for any
// thread count. Threads: drift_ssdo_render uses the context's pool; it is not re-entrant from
// inside a drift_parallel_for worker. A drift_ssdo_env is immutable after create and can be
// shared by any number of renders.
#ifndef DRIFT_SSDO_H
#define DRIFT_SSDO_H

#include "drift/accel.h"
#include "drift/core.h"
#include "drift/hybrid.h"
#include "drift/image.h"
#include "drift/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

// The sampler stream of the sample sets (xor-ed into the seed).
#define DRIFT_SSDO_STREAM 0x55d00000u
// Sample sets tile the image in blocks of this many pixels a side (M = 4x4 sets).
#define DRIFT_SSDO_BLOCK 4

typedef enum drift_ssdo_method {
    DRIFT_SSDO_METHOD_SSAO = 0, // AO of the SSDO sample points x one irradiance lookup along n
    DRIFT_SSDO_METHOD_GTAO,     // horizon-based AO and bent normal x one irradiance lookup along b
    DRIFT_SSDO_METHOD_SSDO,     // one environment lookup per open sample direction (+ bounce)
    DRIFT_SSDO_METHOD_COUNT
} drift_ssdo_method;

// "ssao", "gtao", "ssdo"; NULL when out of range.
const char *drift_ssdo_method_name(drift_ssdo_method technique);
// The technique called `name`, or -1.
int drift_ssdo_method_parse(const char *name);

// --- PRE-FILTERED ENVIRONMENT ---

// How to pre-filter. The default configuration is:
//   width = 0 -> 64 texels of longitude for the filtered maps (height width / 2)
//   source_width = 0 -> 128: the environment is first box-averaged to this lat-long size
typedef struct drift_ssdo_env_desc {
    int32_t width;
    int32_t source_width;
} drift_ssdo_env_desc;

// The scene's environment convolved once: an irradiance map (E / pi, the cosine-weighted mean
// radiance around a normal) and cone-filtered radiance maps for the sample solid angles
// 2 pi / N, N = 1, 2, 4, ..., 256 (a von Mises-Fisher lobe of concentration N).
typedef struct drift_ssdo_env drift_ssdo_env;

// Errors: DRIFT_ERR_INVALID_ARGUMENT (uncommitted scene, bad sizes; logged),
// DRIFT_ERR_OUT_OF_MEMORY. A scene without an environment gives black maps.
drift_result drift_ssdo_env_create(drift_context *ctx, const drift_scene *scene,
                                   const drift_ssdo_env_desc *desc, drift_ssdo_env **out_env);
void drift_ssdo_env_destroy(drift_ssdo_env *env); // NULL-safe
// E(n) / pi: irradiance around unit normal n over pi (rho times this is the outgoing radiance
// of an unoccluded Lambertian surface).
drift_vec3 drift_ssdo_env_irradiance(const drift_ssdo_env *env, drift_vec3 n);
// Radiance along unit direction dir, filtered over a lobe of solid angle ~2 pi / samples.
drift_vec3 drift_ssdo_env_radiance(const drift_ssdo_env *env, drift_vec3 dir, int32_t samples);

// --- PARAMETERS ---

// How to render. The default configuration is:
//   method          = ssao
//   samples         = 0 -> 16: N, sample points a pixel (SSAO, SSDO); GTAO takes
//                     slices x steps x 2 = N horizon samples
//   radius          = 0 -> 0.05 x drift_scene_extent (drift_ssdo_params_resolve):
//                     r_max in scene units, the sample hemisphere and the horizon search
//   bounce          = false: SSDO's one indirect bounce (--ssdo-bounce)
//   bounce_area     = 0 -> 1: A_s = bounce_area x pi r_max^2 / N, the bleeding strength
//   bounce_clamp    = 0 -> 0.5: sender distances are clamped to bounce_clamp x r_max (the
//                     thesis clamps at 1 scene unit)
//   bias            = 0 -> 0.01: a sample is an occluder when the buffer is nearer than it by
//                     more than bias x r_max
//   no_fade         = false: occluders at distance 0.75..1 r_max fade out (smooth-step)
//   no_blur         = false: the geometry-aware 4x4 blur over the interleaving block
//   blur_normal     = 0 -> 0.8: the blur skips pixels whose normals' dot is below this
//   blur_plane      = 0 -> 0.1: ... or lie further than this x r_max off the centre's plane
//   plain_sum       = false: SSDO's direct light is the ratio estimator E(n) x (sum of
//                     L V cos) / (sum of L cos) per channel (docs/ssdo.md); true: the
//                     thesis's plain sum of L V cos 2 pi / N
//   gtao_slices     = 0 -> 2 slice directions a pixel (steps = max(1, N / (2 slices)))
//   gtao_thickness  = 0: off; in (0, 1]: the paper's thickness heuristic, a horizon that a
//                     sample falls below relaxes toward it by this fraction
//   gtao_multibounce= false: Jimenez et al.'s multi-bounce fit of the AO (eq. 10)
//   seed            = 0
typedef struct drift_ssdo_params {
    drift_ssdo_method method;
    int32_t samples;
    float radius;
    bool bounce;
    float bounce_area;
    float bounce_clamp;
    float bias;
    bool no_fade;
    bool no_blur;
    float blur_normal;
    float blur_plane;
    bool plain_sum;
    int32_t gtao_slices;
    float gtao_thickness;
    bool gtao_multibounce;
    uint32_t seed;
    // 0 -> 1: points tested along each SSAO/SSDO sample direction. 1: the thesis's point at
    // lambda_i; more: a march to r_max through (k + lambda_i / r) r / steps, k = 0..steps-1,
    // the direction blocked by its strongest occluder (a ray test, like GTAO's horizons and
    // the path tracer, instead of a point test that reads the air behind a ridge as open)
    int32_t steps;
} drift_ssdo_params;

// Fills the defaults (scene may be NULL: then radius 0 stays 0 and is invalid).
drift_ssdo_params drift_ssdo_params_resolve(const drift_ssdo_params *params,
                                            const drift_scene *scene);

// --- OUTPUT ---

typedef struct drift_ssdo_stats {
    double occlusion_ms; // pass 1: sample sets or horizons, direct light
    double bounce_ms;    // pass 2: the indirect bounce (0 without)
    double blur_ms;      // the geometry-aware blur and the final multiply by albedo
    double total_ms;
} drift_ssdo_stats;

typedef struct drift_ssdo_output {
    drift_image radiance;    // 3
    drift_image direct;      // 3
    drift_image bounce;      // 3
    drift_image visibility;  // 1
    drift_image bent_normal; // 3
    drift_ssdo_stats stats;  // of the last render
} drift_ssdo_output;

// Errors: DRIFT_ERR_INVALID_ARGUMENT (bad size), DRIFT_ERR_OUT_OF_MEMORY.
drift_result drift_ssdo_output_create(drift_context *ctx, int32_t width, int32_t height,
                                      drift_ssdo_output *out);
void drift_ssdo_output_destroy(drift_context *ctx, drift_ssdo_output *out); // NULL-safe

// --- RENDERING ---

// What one frame gives the techniques. gbuffer and camera are required; the rest may be NULL.
//   gbuffer         drift_hybrid_gbuffer: reads depth, position, normal, albedo, material_id
//   camera          the camera that made the G-buffer (its width/height are ignored)
//   sender_radiance more outgoing radiance at each pixel that the bounce reflects, e.g. the
//                   frame's shadowed direct light from point and area lights (3 channels)
//   back_depth      a second depth layer (drift_ssdo_peel, 1 channel): a sample counts as an
//                   occluder only between the first layer and this one (thesis §4.3.2)
// Additional cameras (thesis §4.3.3): depth-only views of the scene, so that a sample outside
// the viewer's image can still meet an occluder. Made by drift_ssdo_views_render.
#define DRIFT_SSDO_MAX_VIEWS 5

typedef struct drift_ssdo_view {
    drift_camera camera; // pinhole
    drift_image depth;   // 1 channel: view depth along the camera's axis, 0 where nothing
} drift_ssdo_view;

// views, view_count: 0..DRIFT_SSDO_MAX_VIEWS additional cameras. A sample outside the
// viewer's image is an occluder when some of them see it and all that do have it behind a
// surface (one that has it in front proves it free). They add occluders only (no sender pixels for
// the bounce), and only to SSAO, SSDO and the contact shadows (GTAO marches the viewer's image).
typedef struct drift_ssdo_inputs {
    const drift_gbuffer *gbuffer;
    const drift_camera *camera;
    const drift_image *sender_radiance;
    const drift_image *back_depth;
    const drift_ssdo_view *views;
    int32_t view_count;
} drift_ssdo_inputs;

// Renders one technique into out (made by drift_ssdo_output_create at the G-buffer's size).
// Errors: DRIFT_ERR_INVALID_ARGUMENT (sizes differ, bad parameters; logged),
// DRIFT_ERR_OUT_OF_MEMORY.
drift_result drift_ssdo_render(drift_context *ctx, const drift_ssdo_env *env,
                               const drift_ssdo_inputs *inputs, const drift_ssdo_params *params,
                               drift_ssdo_output *out);

// Depth peeling by a second ray: for every G-buffer pixel, the view depth of the next surface
// along its camera ray behind the first (for a closed solid, where the ray leaves it) into
// back_depth (1 channel, the G-buffer's size, made by the caller); 0 where there is none,
// which the occluder test reads as solid to infinity (the one-layer rule). One ray a pixel.
drift_result drift_ssdo_peel(drift_context *ctx, const drift_accel *accel,
                             const drift_gbuffer *gbuffer, const drift_camera *camera,
                             drift_image *back_depth);

// The screen-space contact-shadow fix for shadow-map bias (thesis §4.5): for every pixel that
// faces the light, `samples` points on the segment from P toward the light over `length`
// scene units (the shadow map's depth bias b = p/2 tan(alpha) there, or a fixed length) are
// tested against the depth buffer like SSDO's samples (no fade; `back_depth` honoured); any
// occluder writes 0 to out_visible (1 channel, the G-buffer's size), else 1. The frame
// multiplies its shadow-map visibility by it. `light` is a point light's position, or with
// `directional` the direction its light travels.
drift_result drift_ssdo_contact_shadows(drift_context *ctx, const drift_ssdo_inputs *inputs,
                                        drift_vec3 light, bool directional, float length,
                                        int32_t samples, drift_image *out_visible);

// As drift_ssdo_contact_shadows with one march length a pixel (`lengths`, 1 channel, the
// G-buffer's size; <= 0: not marched, visible): the frame's shadow maps give each pixel its
// own b (drift_shadow_map_blind_length).
drift_result drift_ssdo_contact_shadows_per_pixel(drift_context *ctx,
                                                  const drift_ssdo_inputs *inputs, drift_vec3 light,
                                                  bool directional, const drift_image *lengths,
                                                  int32_t samples, drift_image *out_visible);

// Renders `count` (1..DRIFT_SSDO_MAX_VIEWS) additional cameras for `camera` by one ray a
// texel into views[0..count) (their depth images created here, width x height each; free
// with drift_ssdo_views_destroy). All look at the viewer's centre of interest (its centre
// ray's first hit) with twice the viewer's tan(fov/2): view 0 from the viewer's eye (a guard
// band), views 1-4 from the eye moved by 0.25 x the scene's bounding-sphere radius along the
// image's +x, -x, +y, -y, pulled back to free space when the move would cross a surface.
drift_result drift_ssdo_views_render(drift_context *ctx, const drift_scene *scene,
                                     const drift_accel *accel, const drift_camera *camera,
                                     int32_t count, int32_t width, int32_t height,
                                     drift_ssdo_view *views);
void drift_ssdo_views_destroy(drift_context *ctx, drift_ssdo_view *views, int32_t count);

// The path-traced reference of the same term into out (3 channels, created here and owned by
// the caller): environment light with visibility at the first hit, plus with `bounce` the
// first-bounce diffuse light, at spp samples through each pixel centre (pinhole). The scene
// should be lit by its environment alone (other lights would add their direct light too).
drift_result drift_ssdo_reference(drift_context *ctx, const drift_scene *scene,
                                  const drift_accel *accel, const drift_camera *camera,
                                  int32_t width, int32_t height, uint32_t spp, uint32_t seed,
                                  bool bounce, drift_image *out);

#ifdef __cplusplus
}
#endif
#endif // DRIFT_SSDO_H
