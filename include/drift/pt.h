// drift pt: the reference path tracer, the ground truth every technique is measured against.
//
// Unidirectional path tracing with next-event estimation and multiple importance sampling
// (power heuristic) for every light type and the environment (Veach 1997, ch. 9), thin-lens
// depth of field, glossy and mirror reflection, Russian roulette. Every random number comes
// from drift_sampler keyed on (seed, pixel, sample), and each pixel accumulates its samples
// in order, so the image is bit-identical for any thread count.
//
// Rendering is progressive: each call to drift_pt_render_samples adds samples to every
// pixel; the image can be read between calls (checkpoints, progress, viewers).
//
// STEP BY STEP
//   drift_pt *pt = NULL;
//   drift_pt_create(ctx, scene, accel, &(drift_pt_params){ .seed = 7 }, &pt);
//   while (drift_pt_sample_count(pt) < 256) {
//       drift_pt_render_samples(pt, 16, &cancel_flag);     // DRIFT_ERR_CANCELLED on Ctrl-C
//   }
//   drift_image beauty;  drift_pt_resolve(pt, DRIFT_PT_AOV_BEAUTY, &beauty);  // owned by pt
//   drift_pt_destroy(pt);
//
// Ownership: scene and accel are borrowed and must outlive the pt. Images
// returned by drift_pt_resolve belong to the pt and stay valid until the next render call or
// destroy.
// Threads: one pt is driven from one thread; it uses the context's pool internally.
#ifndef DRIFT_PT_H
#define DRIFT_PT_H

#include "drift/accel.h"
#include "drift/core.h"
#include "drift/image.h"
#include "drift/reflect_edit.h"
#include "drift/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

// Which parts of the light to accumulate (bit set of drift_pt_component); 0 = all. The parts
// split every path by its first scattering event, so their sum is the full image:
//   EMISSION  emitted radiance at the first hit (the environment on a miss)
//   DIRECT    light reaching the first hit straight from an emitter through its non-delta
//             lobes: NEE at the first vertex plus the MIS-weighted emitter hit of the
//             first BSDF-sampled ray (when that sample was not a delta/mirror sample)
//   SPECULAR  everything else whose first bounce is the glossy or mirror lobe (for a mirror
//             first bounce this includes the emission it sees)
//   DIFFUSE   everything else whose first bounce is the diffuse lobe
// Diffuse and glossy lobes share the sampled direction of the first bounce, so the light
// that continues the path is shared between SPECULAR and DIFFUSE per channel in the ratio
// of the two lobes at the first vertex, f_glossy : f_diffuse (docs/reference-renderer.md).
typedef enum drift_pt_component {
    DRIFT_PT_COMPONENT_EMISSION = 1,
    DRIFT_PT_COMPONENT_DIRECT = 2,
    DRIFT_PT_COMPONENT_SPECULAR = 4,
    DRIFT_PT_COMPONENT_DIFFUSE = 8,
    DRIFT_PT_COMPONENT_ALL = 15
} drift_pt_component;

// How to render. The default configuration is:
//   width, height = 0 -> the scene camera's size (also with `camera` set: its size is ignored)
//   seed          = 0 (a valid seed)
//   max_depth     = 0 -> 8. Depth counts scattering vertices as in pbrt: 1 = direct light only
//                   (camera -> surface -> light). Emitters seen directly are always included.
//   rr_depth      = 0 -> 3: Russian roulette starts after this many bounces
//   disable_mis   = false: with true, NEE handles all non-delta light (BSDF hits on emitters
//                   are ignored except after delta bounces); for tests and comparisons
//   disable_nee   = false: with true, only BSDF sampling finds lights (pure path tracing)
//   disable_rr    = false
//   components    = 0 -> DRIFT_PT_COMPONENT_ALL: the whole image. Any other set renders only
//                   those parts into the beauty AOV (the other AOVs do not change); paths
//                   and their random numbers stay the same, so the parts of one seed sum to
//                   the full image of that seed
//   pixel_centre  = false: with true, every sample goes through its pixel's centre (no pixel
//                   jitter), the footprint of a one-sample-per-pixel G-buffer
//   pinhole       = false: with true, the camera's aperture is ignored (no depth of field)
//   texture_point_sampling = false: textures are read at the mip level of the ray cone's
//                   footprint (Akenine-Moller et al. 2021; docs/materials.md "Textures"), so
//                   distant textures do not alias; true reads them at full size
//   texture_filter_spp = 0 -> 1: the samples each pixel will get; the camera's cone is
//                   max(1/8, 1/sqrt(n)) of a pixel wide, as pbrt-v4 scales its ray
//                   differentials, for the pixels' own supersampling filters the rest
//   camera        = NULL -> scene->camera
//   reflection_edits = NULL: physical reflection. Otherwise the glossy and mirror lobes of the
//                   first vertex centre on the edited direction e(q) (drift/reflect_edit.h)
//                   instead of the mirror direction, the reference of an edited image;
//                   diffuse light and later bounces do not change. Borrowed.
typedef struct drift_pt_params {
    int32_t width, height;
    uint32_t seed;
    int32_t max_depth;
    int32_t rr_depth;
    bool disable_mis;
    bool disable_nee;
    bool disable_rr;
    uint32_t components; // bit set of drift_pt_component
    bool pixel_centre;   // every sample through the pixel centre (no pixel jitter): the same
                         // footprint as a one-sample-per-pixel G-buffer
    bool pinhole;        // ignore the camera's aperture
    bool texture_point_sampling; // read textures at full size: no mip level by ray cone
    uint32_t texture_filter_spp; // the samples a pixel will get (0: 1): see above
    const drift_camera *camera;  // NULL = scene->camera; else this camera, copied at create
                                 // (moving it later does not move the pt's camera).
                                 // width/height still come from params.
    const drift_reflection_edits *reflection_edits;
} drift_pt_params;

drift_pt_params drift_pt_params_resolve(const drift_pt_params *params, const drift_scene *scene);

typedef enum drift_pt_aov {
    DRIFT_PT_AOV_BEAUTY = 0, // radiance, RGB
    DRIFT_PT_AOV_ALBEDO,     // diffuse + specular reflectance (or emission) at the first hit, RGB
    DRIFT_PT_AOV_NORMAL,     // shading normal at the first hit, RGB in [-1, 1]
    DRIFT_PT_AOV_DEPTH,      // distance along the camera ray to the first hit, 1 channel (0 = miss)
    // The feature-guided denoiser's inputs (drift_denoise_feature, drift/denoise.h):
    DRIFT_PT_AOV_VARIANCE,        // variance of the pixel's mean beauty luminance: the samples'
                                  // unbiased variance over n (running moments; 0 below 2 samples)
    DRIFT_PT_AOV_FEATURE_ALBEDO,  // albedo at the first non-delta vertex (through mirrors and
                                  // glass, times their throughput; plus its emission), RGB
    DRIFT_PT_AOV_FEATURE_NORMAL,  // shading normal there, RGB in [-1, 1]
    DRIFT_PT_AOV_FEATURE_DEPTH,   // length of the path up to there, 1 channel (0 = escaped)
    DRIFT_PT_AOV_DIRECT,          // the beauty's direct part, RGB: light that reached the camera
                                  // after at most one non-delta bounce (emitters and the sky seen
                                  // directly or through mirrors/glass, next-event estimation at the
                                  // first non-delta vertex and its bounce's emitter hit)
    DRIFT_PT_AOV_DIRECT_VARIANCE, // variance of the pixel's mean direct luminance, 1 channel
    DRIFT_PT_AOV_INDIRECT_VARIANCE, // the same of the rest (beauty - direct), 1 channel
    DRIFT_PT_AOV_COUNT
} drift_pt_aov;

typedef struct drift_pt_stats {
    uint64_t camera_rays;
    uint64_t shadow_rays;
    uint64_t bounce_rays;
    uint64_t nan_samples;  // samples with a non-finite value, discarded (should stay 0)
    double render_seconds; // wall time inside drift_pt_render_samples
} drift_pt_stats;

typedef struct drift_pt drift_pt;

// Errors: DRIFT_ERR_INVALID_ARGUMENT (uncommitted scene, bad size, components outside
// DRIFT_PT_COMPONENT_ALL), DRIFT_ERR_OUT_OF_MEMORY.
drift_result drift_pt_create(drift_context *ctx, const drift_scene *scene, const drift_accel *accel,
                             const drift_pt_params *params, drift_pt **out_pt);
void drift_pt_destroy(drift_pt *pt); // NULL-safe

// Adds `count` samples to every pixel. `cancel` (may be NULL) is polled between tiles; when
// it becomes true the call returns DRIFT_ERR_CANCELLED and pixels keep what they had, each
// divided by its own sample count at resolve.
drift_result drift_pt_render_samples(drift_pt *pt, uint32_t count, const atomic_bool *cancel);

// --- TILES ---
// The image is cut into DRIFT_PT_TILE_SIZE squares (smaller at the right and bottom edges),
// numbered row by row. Every render call works tile by tile and polls `cancel` between
// tiles, so after a cancelled call tiles can hold different sample counts; each pixel still
// holds whole samples 0..n-1. A tile's state (its pixels' sums and counts) can be copied out
// and back in: checkpoints, resuming, and other processes rendering some of the tiles
// (tools/distributed) give the same bits as one uninterrupted render, because a pixel's
// samples are summed one by one in index order whoever renders them.
#define DRIFT_PT_TILE_SIZE 16

typedef struct drift_pt_tile {
    int32_t x0, y0, x1, y1; // pixels [x0, x1) x [y0, y1)
} drift_pt_tile;

uint32_t drift_pt_tile_count(const drift_pt *pt);
drift_pt_tile drift_pt_tile_rect(const drift_pt *pt, uint32_t tile);
// The samples every pixel of the tile holds (the lowest of its pixels).
uint32_t drift_pt_tile_sample_count(const drift_pt *pt, uint32_t tile);

// Renders the listed tiles (NULL: all of them, tile_count ignored): each pixel gets the
// samples from its own count n up to min(n + add, until). Tiles already at `until` are left
// as they are. Errors: DRIFT_ERR_INVALID_ARGUMENT (a tile out of range), DRIFT_ERR_CANCELLED.
drift_result drift_pt_render_tiles(drift_pt *pt, const uint32_t *tiles, uint32_t tile_count,
                                   uint32_t add, uint32_t until, const atomic_bool *cancel);

// Bytes of one tile's state; get copies it to `out` (that many bytes), set replaces the
// tile's sums and counts by it. The layout is the pt's own: only for a pt of the same
// size (and the same params, for the bits to mean the same render).
size_t drift_pt_tile_state_size(const drift_pt *pt, uint32_t tile);
void drift_pt_tile_get_state(const drift_pt *pt, uint32_t tile, void *out);
void drift_pt_tile_set_state(drift_pt *pt, uint32_t tile, const void *state);
// Adds another renderer's counters (rays of tiles rendered elsewhere) to this pt's stats.
void drift_pt_add_stats(drift_pt *pt, const drift_pt_stats *stats);

// Completed samples per pixel (the minimum over pixels).
uint32_t drift_pt_sample_count(const drift_pt *pt);
drift_pt_stats drift_pt_get_stats(const drift_pt *pt);
drift_pt_params drift_pt_get_params(const drift_pt *pt);

// The mean of the samples so far for one AOV (see the ownership note above).
drift_result drift_pt_resolve(drift_pt *pt, drift_pt_aov aov, drift_image *out_image);

// Radiance of one camera-ray sample (pixel x, y; sample index) exactly as the renderer
// computes it, of the selected components only: for tests and for replaying a single sample
// (`drift render --debug-sample`).
drift_vec3 drift_pt_trace_sample(const drift_pt *pt, int32_t x, int32_t y, uint32_t sample);

#ifdef __cplusplus
}
#endif
#endif // DRIFT_PT_H
