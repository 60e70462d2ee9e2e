// The hybrid frame's state, shared by the files that run its passes: frame.c (lifecycle,
// planes, the pass order), direct.c (U_l and shadow terms), reflections.c (sharp and
// environment-map reflections), reference.c (path-traced effects), compose.c (composition
// and depth of field).
#ifndef DRIFT_FRAME_INTERNAL_H
#define DRIFT_FRAME_INTERNAL_H

#include "hybrid/hybrid_internal.h"
#include "drift/pt.h"

// Planes the frame can list: the fixed ones, plus six a light (three of them AAF's).
#define DRIFT_HYBRID_FIXED_PLANES 27
#define DRIFT_HYBRID_PLANES_PER_LIGHT 6
#define DRIFT_HYBRID_PLANE_NAME 48

typedef struct drift_hybrid_plane_ref {
    char name[DRIFT_HYBRID_PLANE_NAME];
    const drift_image *image;
} drift_hybrid_plane_ref;

// Per-light image-space buffers.
// Per-thread ray counter, padded so threads do not share a cache line.
typedef struct drift_ray_counter {
    uint64_t rays;
    uint8_t padding[56];
} drift_ray_counter;

typedef struct drift_hybrid_light_buffers {
    drift_image unshadowed;  // 3: U_l
    drift_image hard_shadow; // 3: visible (0/1), occluder distance (INFINITY: none), light distance
    drift_image shadow;      // 1: S_l of the chosen technique
    drift_shadow_map *shadow_map; // built on first use, kept while the scene stands
} drift_hybrid_light_buffers;

// An environment probe: one for the whole scene, or one per reflective mesh.
typedef struct drift_hybrid_probe {
    uint32_t mesh; // DRIFT_INVALID_INDEX for the scene probe
    drift_envmap *map;
} drift_hybrid_probe;

struct drift_hybrid {
    drift_context *ctx;
    const drift_scene *scene;
    const drift_accel *accel;
    drift_hybrid_params params;
    drift_camera camera, prev_camera;
    bool has_prev_camera;

    drift_hybrid_light *lights;
    uint32_t light_count;
    drift_hybrid_light_buffers *light_buffers;
    drift_hybrid_shading shading;

    drift_gbuffer gbuffer;
    drift_image environment_direct; // 3: direct light from the environment (ray-traced)
    drift_image direct;             // 3: D = sum_l U_l S_l + environment
    drift_image reflection_emitted; // 3: sharp mirror ray, emitted radiance at its hit
    drift_image reflection_reflected; // 3: ... direct light with hard shadows at its hit
    drift_image reflection_distance;  // 1: hit distance (INFINITY: miss)
    drift_image reflections;        // 3: R
    drift_image indirect;           // 3: I
    drift_image reference;          // 3: scratch copy of the last reference pass
    drift_image coc;                // 1: circle-of-confusion radius, pixels
    drift_image focus;              // 3: the composed in-focus frame
    drift_image final;              // 3: after depth of field

    drift_hybrid_probe *probes;
    uint32_t probe_count;

    drift_ray_counter *counters; // one per thread
    int thread_count;
    drift_hybrid_stats stats;
    drift_hybrid_plane_ref *planes; // room for every plane (sized at create)
    uint32_t plane_count, plane_capacity;
    struct drift_isg_state *isg; // image space gathering's buffers (isg.c), made on first use
    struct drift_aaf_state *aaf;    // AAF's buffers, made on first use (aaf_internal.h)
};

// Runs fn for every row, or every pixel, rows in parallel. `rays` is the calling thread's ray
// counter. Both return the rays the pass counted.
typedef void (*drift_hybrid_row_fn)(drift_hybrid *frame, int32_t y, uint64_t *rays, void *user);
typedef void (*drift_hybrid_pixel_fn)(drift_hybrid *frame, int32_t x, int32_t y, uint64_t *rays,
                                      void *user);
uint64_t drift_hybrid_for_each_row(drift_hybrid *frame, drift_hybrid_row_fn fn, void *user);
uint64_t drift_hybrid_for_each_pixel(drift_hybrid *frame, drift_hybrid_pixel_fn fn, void *user);

// Passes (each returns DRIFT_OK or an error already logged).
drift_result drift_hybrid_pass_direct(drift_hybrid *frame);
drift_result drift_hybrid_pass_reflections(drift_hybrid *frame);
drift_result drift_hybrid_pass_reference(drift_hybrid *frame, const atomic_bool *cancel);
drift_result drift_hybrid_pass_compose(drift_hybrid *frame, const atomic_bool *cancel);

// Renders `components` of the pt (DRIFT_PT_COMPONENT_*) at the frame's spp through the pixel
// centres, pinhole unless `lens`, into the RGB image `out`.
drift_result drift_hybrid_reference_render(drift_hybrid *frame, uint32_t components,
                                           int32_t max_depth, bool lens,
                                           const atomic_bool *cancel, drift_image *out);

// Copies the RGB channels of `from` into `to` (same size).
void drift_hybrid_copy_rgb(const drift_image *from, drift_image *to);

// A per-pixel sampler keyed on the frame's seed and a pass-specific stream.
drift_sampler drift_hybrid_sampler(const drift_hybrid *frame, uint32_t stream, int32_t x,
                                   int32_t y);

// Directional albedo of a specular lobe toward wo (reflections.c): what the radiance seen in
// the mirror direction is weighted by in R.
drift_vec3 drift_hybrid_reflection_weight(const drift_bsdf *bsdf, drift_vec3 wo);

// Outgoing direction at the pixel's surface (toward the camera); pixels with a hit only.
drift_vec3 drift_hybrid_wo(const drift_hybrid *frame, int32_t x, int32_t y);

#endif
