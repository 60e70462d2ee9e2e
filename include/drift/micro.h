// drift micro: micro-rendering (Ritschel et al. 2009; thesis ch. 6). Final gathering of the
// indirect light at every gather point by rasterising the whole scene into a tiny K x K
// hemispherical image, the micro-buffer, through a hierarchy of scene points.
//
// The passes of one drift_micro_render (docs/micro.md has the equations):
//   1. Hierarchy (hierarchy.c): the scene points of drift_points (a power of two of them) in
//      the order of a median-split BSP form an implicit complete binary tree; each node keeps a
//      bounding sphere, a cone of normals, an albedo and its outgoing radiance. The topology is
//      fixed at create; each render re-derives the leaves and refits the nodes bottom-up.
//   2. Lighting (lighting.c): the direct light reflected by each leaf, both sides of its disc,
//      ray-traced; with bounces > 1 the further bounces from a radiosity (Jacobi) iteration
//      over the tree (radiosity.c) or a photon map (photons.c, caustics included); pulled up
//      the tree as area-weighted means.
//   3. Gathering (microbuffer.c, warp.c): per gather point a depth-first cut of the tree by
//      solid angle, each node of the cut splatted into the pixel of the micro-buffer its
//      direction warps to (depth-tested); then one ray a pixel (Embree), which decides what
//      the pixel sees (a splat stays where the ray hits inside its node); the reflected
//      radiance is rho times the mean of the micro-buffer, with the pixels importance-warped
//      by f_r cos / rho through tabulated 2-D CDFs (the diffuse lobe's warp is the Nusselt
//      map; a sharp glossy lobe's covers only the cap around its axis).
//   4. Upsampling (micro.c): gathers at every pixel, 1/4 or 1/16 of them; a bilateral
//      (depth- and normal-aware) upsampling fills the rest.
//
// STEP BY STEP
//   drift_micro *micro = NULL;
//   drift_micro_create(ctx, scene, accel, &(drift_micro_params){ .buffer_size = 16 }, &micro);
//   drift_micro_render(micro, gbuffer, &camera, DRIFT_MICRO_LOBE_DIFFUSE);  // per frame
//   const drift_image *indirect = drift_micro_result(micro);     // RGB radiance
//   drift_micro_destroy(micro);
//
// Ownership: scene and accel are borrowed and must outlive the micro. Images returned here
// belong to the micro and stay valid until the next render or destroy.
// Threads: one micro is driven from one thread; it uses the context's pool internally.
#ifndef DRIFT_MICRO_H
#define DRIFT_MICRO_H

#include "drift/accel.h"
#include "drift/core.h"
#include "drift/hybrid.h"
#include "drift/image.h"
#include "drift/points.h"
#include "drift/reflect_edit.h"
#include "drift/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

// Sampler streams: the light samples of leaf i, drift_sampler_make(drift_hash_combine(seed,
// DRIFT_MICRO_LIGHT_STREAM), 0, i); the frame rotation of gather pixel (x, y) hashes the same
// seed with DRIFT_MICRO_JITTER_STREAM, and the light samples of its rays' glossy hits with
// DRIFT_MICRO_GLOSSY_STREAM. The scene points use DRIFT_POINTS_STREAM.
#define DRIFT_MICRO_LIGHT_STREAM  0x6d6c6974u // "mlit"
#define DRIFT_MICRO_JITTER_STREAM 0x6d6a6974u // "mjit"
#define DRIFT_MICRO_GLOSSY_STREAM 0x6d676c73u // "mgls"

// Which lobe of the gather point's BSDF the micro-buffer integrates.
typedef enum drift_micro_lobe {
    DRIFT_MICRO_LOBE_DIFFUSE = 0, // kd / pi: the indirect term I (Nusselt map, rho = kd)
    DRIFT_MICRO_LOBE_GLOSSY,      // the Phong lobe: the glossy part of R (a warp per gather)
    DRIFT_MICRO_LOBE_COUNT
} drift_micro_lobe;

// How the points are lit (thesis §6.4; docs/micro.md "Lighting the points").
typedef enum drift_micro_lighting {
    DRIFT_MICRO_LIGHTING_AUTO = 0,  // direct when bounces = 1, radiosity above
    DRIFT_MICRO_LIGHTING_DIRECT,    // ray-traced direct light only (one bounce)
    DRIFT_MICRO_LIGHTING_RADIOSITY, // direct, then bounces - 1 Jacobi gathers over the tree
    DRIFT_MICRO_LIGHTING_PHOTONS,   // direct, plus a photon map's light of bounces 2..bounces
    DRIFT_MICRO_LIGHTING_COUNT
} drift_micro_lighting;

const char *drift_micro_lighting_name(drift_micro_lighting lighting);

// How to render. The default configuration is:
//   seed          = 0
//   point_count   = 0 -> 65536 scene points (rounded up to a power of two; at most 2^22)
//   buffer_size   = 0 -> 16: K, the micro-buffer is K x K pixels (4..32; the thesis: 8, 16, 24)
//   density       = 0 -> 1: a gather every pixel; 2: one a 2x2 block (1/4), 4: 1/16
//   light_samples = 0 -> 4 light samples (shadow rays) a leaf and side
//   warp_size     = 0 -> 32 cells a side of each BRDF warp table (8..128)
//   cut_scale     = 0 -> 1: a node is splatted when its solid angle is at most cut_scale times
//                   its pixel's (smaller: a finer cut, fewer holes, more nodes visited)
//   no_ray_casting = false: true skips the post-traversal ray casting (holes stay, Fig. 6.16)
//   no_jitter     = false: true keeps every gather point's tangent frame unrotated
typedef struct drift_micro_params {
    uint32_t seed;
    uint32_t point_count;
    int32_t buffer_size;
    int32_t density;
    int32_t light_samples;
    int32_t warp_size;
    float cut_scale;
    bool no_ray_casting;
    bool no_jitter;
    // Lighting the points (lighting.c, radiosity.c, photons.c):
    //   lighting       = AUTO (direct for one bounce, radiosity above)
    //   bounces        = 0 -> 1: light bounces the gather sees (the path tracer's max depth - 1)
    //   radiosity_size = 0 -> 8: K of the radiosity gathers' micro-buffers (4..32)
    //   photon_count   = 0 -> 2^18 photon paths; photon_k = 0 -> 64 nearest photons a leaf
    drift_micro_lighting lighting;
    int32_t bounces;
    int32_t radiosity_size;
    uint32_t photon_count;
    int32_t photon_k;
    // NULL: physical reflections. Otherwise the glossy lobe of each gather point centres on
    // the edited direction e(q) (drift/reflect_edit.h); borrowed, it must outlive the renders.
    const drift_reflection_edits *reflection_edits;
} drift_micro_params;

drift_micro_params drift_micro_params_resolve(const drift_micro_params *params);

typedef enum drift_micro_stage {
    DRIFT_MICRO_STAGE_HIERARCHY = 0, // re-deriving the leaves and refitting the tree
    DRIFT_MICRO_STAGE_LIGHTING,      // direct light at the leaves and the pull
    DRIFT_MICRO_STAGE_GATHER,        // warps, traversal and ray casting, all gather points
    DRIFT_MICRO_STAGE_UPSAMPLE,      // bilateral upsampling and the fallback gathers
    DRIFT_MICRO_STAGE_COUNT
} drift_micro_stage;

const char *drift_micro_stage_name(drift_micro_stage stage);

typedef struct drift_micro_stats {
    double ms[DRIFT_MICRO_STAGE_COUNT];
    double total_ms;
    uint64_t gathers;       // micro-buffers rendered (fallbacks included; not on misses)
    uint64_t nodes_visited; // nodes the traversals touched
    uint64_t splats;        // nodes written into a micro-buffer pixel
    uint64_t post_leaves;   // leaves put on post-traversal lists
    uint64_t cast_gathers;  // gathers that cast rays (every one unless no_ray_casting)
    uint64_t rays;          // gather rays (one a micro-buffer pixel) and light rays
    uint64_t empty_pixels;  // micro-buffer pixels left without a node (holes and misses)
    uint64_t fallbacks;     // full-resolution gathers where the upsampling had no weight
    // Lighting the points, inside DRIFT_MICRO_STAGE_LIGHTING: the direct light, the radiosity
    // iterations or the photon map (tracing, kd-tree and the density estimates) and the pulls.
    double direct_ms, bounces_ms;
    uint64_t photons; // photons stored (the photon map's size)
} drift_micro_stats;

typedef struct drift_micro drift_micro;

// Samples the scene points and builds the hierarchy's topology (the only pre-computation).
// Errors: DRIFT_ERR_INVALID_ARGUMENT (uncommitted scene, bad parameters; logged),
// DRIFT_ERR_OUT_OF_MEMORY.
drift_result drift_micro_create(drift_context *ctx, const drift_scene *scene,
                                const drift_accel *accel, const drift_micro_params *params,
                                drift_micro **out_micro);
void drift_micro_destroy(drift_micro *micro); // NULL-safe

// One frame: re-derives and refits the hierarchy from the meshes, lights it and gathers `lobe`
// at the G-buffer's pixels (position, normal, geometric_normal, albedo, material_id and
// surfaces are read; the camera's position gives the glossy lobe its view direction and may
// be NULL for the diffuse lobe). Errors: DRIFT_ERR_INVALID_ARGUMENT (empty G-buffer, bad lobe),
// DRIFT_ERR_OUT_OF_MEMORY.
drift_result drift_micro_render(drift_micro *micro, const drift_gbuffer *gbuffer,
                                const drift_camera *camera, drift_micro_lobe lobe);

// RGB radiance of the last render: the lobe's indirect light (of `bounces` bounces) toward the
// camera (0 where the G-buffer missed, and for the glossy lobe on mirrors).
const drift_image *drift_micro_result(const drift_micro *micro);
// "micro.incident" (RGB, the micro-buffers' mean radiance before rho, at full resolution
// after upsampling) and "micro.gathers" (1 channel: 1 where a gather ran). NULL before a render.
const drift_image *drift_micro_plane_named(const drift_micro *micro, const char *name);
drift_micro_stats drift_micro_get_stats(const drift_micro *micro);
drift_micro_params drift_micro_get_params(const drift_micro *micro);

#ifdef __cplusplus
}
#endif
#endif // DRIFT_MICRO_H
