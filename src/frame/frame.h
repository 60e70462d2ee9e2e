// The frame's buffers: everything the passes of the hybrid frame read and write, and the
// helpers every pass shares (rows and pixels in parallel, per-pixel samplers, the outgoing
// direction, path-traced components). This layer sits below every technique folder
// (src/realtime, src/isg, src/aaf, ...) and above the raster primitives (src/raster): a
// pass includes this header and its own folder's, never the conductor (src/hybrid), which
// owns the frame's lifecycle, the technique table and the pass order.
#ifndef DRIFT_FRAME_H
#define DRIFT_FRAME_H

#include "drift/pt.h"
#include "raster/raster.h"

#include <stddef.h>

// --- SAMPLER STREAMS ---

// One list of the stream ids the passes key their per-pixel random numbers on, so that two
// passes never draw the same numbers for a pixel (tests/unit/test_hybrid.c checks that they
// differ). The values are those the passes used before the list (images stay as they were).
typedef enum drift_stream {
    DRIFT_STREAM_UNSHADOWED = 1,       // U_l's Hammersley rotation (realtime/direct.c)
    DRIFT_STREAM_PCSS = 2,             // PCSS tap rotation (realtime/direct.c)
    DRIFT_STREAM_REFLECTION = 3,       // the sharp mirror ray's shading (realtime/reflections.c)
    DRIFT_STREAM_PROBE = 4,            // environment-map capture (realtime/reflections.c)
    DRIFT_STREAM_HARD_SHADOW_AIM = 5,  // --aa's shadow-ray aim points, keyed on base_seed
                                       // (one stratified set over the passes; direct.c)
    DRIFT_STREAM_GLASS = 6,            // glass transmission after the rows that do not trace
                                       // it (realtime/reflections.c)
    DRIFT_STREAM_VEIL = 7,             // the veils' direct light (hybrid/veils.c)
    DRIFT_STREAM_ISG_SHADOWS = 11,     // isg/isg_shadows.c
    DRIFT_STREAM_ISG_REFLECTIONS = 12, // isg/isg_reflections.c
    DRIFT_STREAM_ISG_DOF = 13,         // isg/isg_dof.c
    DRIFT_STREAM_ISG_LAYER = 14,       // isg/isg_layers.c
    DRIFT_STREAM_SIR_AO = 0x5150,      // SIR's ambient-occlusion metric (sir/metrics.c)
    DRIFT_STREAM_SIR_LOBE = 0x5151,    // SIR's expected reflection error (sir/metrics.c)
    DRIFT_STREAM_SIR_TRACE = 0x51f0,   // SIR's ray tracer (sir/raytrace.c)
    DRIFT_STREAM_AAF_SHADOWS = 0x5aaf0001,  // + light index (aaf/aaf_shadows.c)
    DRIFT_STREAM_AAF_INDIRECT = 0x5aaf1000, // aaf/aaf_indirect.c
    DRIFT_STREAM_AAF_SPECULAR = 0x5aaf2000, // aaf/aaf_specular.c
} drift_stream;

// --- THE FRAME'S BUFFERS ---

// Per-thread ray counter, padded so threads do not share a cache line.
typedef struct drift_ray_counter {
    uint64_t rays;
    uint8_t padding[56];
} drift_ray_counter;

// Per-light image-space buffers.
typedef struct drift_frame_light_buffers {
    drift_image unshadowed;  // 3: U_l
    drift_image hard_shadow; // 3: visible (0/1), occluder distance (INFINITY: none), light distance
    drift_image shadow;      // 1: S_l of the chosen technique
} drift_frame_light_buffers;

// A technique's state kept across frames (drift_pass_state).
typedef struct drift_pass_state_slot {
    void *data;
    void (*destroy)(drift_context *ctx, void *data);
    int technique; // the technique of the slot's effect that owns data
} drift_pass_state_slot;

// The most technique families a frame holds state for (frame/family.h lists them).
#define DRIFT_FAMILY_SLOTS 8

typedef struct drift_frame_state {
    drift_context *ctx;
    const drift_scene *scene;
    const drift_accel *accel;
    drift_hybrid_params params;
    // The seed the frame's params were set with. params.seed is this anti-aliasing pass's
    // (each pass mixes its index in); state kept across passes (ISM's VPLs, micro-rendering's
    // points) keys on this one so that a pass does not rebuild it.
    uint32_t base_seed;
    uint32_t aa_pass; // this anti-aliasing pass's index (0 .. params.aa - 1)
    drift_camera camera, prev_camera;
    bool has_prev_camera;
    // How each mesh moved since the previous frame (12 floats a mesh: a point now -> where it
    // was), for this frame's motion vectors; NULL: none moved (drift_hybrid_set_mesh_motion).
    float *mesh_motion;
    uint32_t mesh_motion_capacity;
    bool has_mesh_motion;

    drift_raster_light *lights;
    uint32_t light_count;
    drift_frame_light_buffers *light_buffers;
    drift_raster_shading shading;

    drift_gbuffer gbuffer;

    // 3 channels each: what each effect's rows write, by effect (the table's order), and by
    // name for the effects every pass knows.
    union {
        drift_image terms[DRIFT_EFFECT_COUNT];

        struct {
            drift_image direct;      // D = sum_l U_l S_l + environment (shadows)
            drift_image reflections; // R
            drift_image final;       // after depth of field (dof: a post effect)
            drift_image indirect;    // I
        };
    };

    drift_image environment_direct;   // 3: direct light from the environment (ray-traced)
    drift_image reflection_emitted;   // 3: sharp mirror ray, emitted radiance at its hit
    drift_image reflection_reflected; // 3: ... direct light with hard shadows at its hit
    drift_image reflection_distance;  // 1: hit distance (INFINITY: miss)
    drift_image coc;                  // 1: circle-of-confusion radius, pixels
    drift_image focus;                // 3: the composed in-focus frame

    // A chosen row (DRIFT_ROW_ENVIRONMENT_DIFFUSE: occlusion) renders the environment's light
    // through the diffuse lobe, so environment_direct (and D) keeps only its glossy part.
    bool environment_diffuse_elsewhere;
    uint32_t inputs; // DRIFT_INPUT_* the chosen rows asked for (this pass's)

    drift_ray_counter *counters; // one per thread
    int thread_count;
    drift_hybrid_stats stats;
    // State a technique keeps across frames (caches, atlases), one slot an effect, owned by
    // the technique that made it: drift_pass_state / drift_pass_set_state.
    drift_pass_state_slot effect_state[DRIFT_EFFECT_COUNT];
    // Each technique family's own state, one slot a family (frame/family.h's slots): made by
    // the family's create hook when the frame is made, freed by its destroy hook. Opaque
    // here: this layer knows no family; a family reads its slot through its own accessor
    // (drift_realtime_of, drift_isg_of, ...).
    void *family_state[DRIFT_FAMILY_SLOTS];
} drift_frame_state;

#define DRIFT_TERM_SLOT_(field, effect)    \
    (offsetof(drift_frame_state, field) == \
     offsetof(drift_frame_state, terms) + (size_t)(effect) * sizeof(drift_image))
_Static_assert(DRIFT_TERM_SLOT_(direct, DRIFT_EFFECT_SHADOWS) &&
                   DRIFT_TERM_SLOT_(reflections, DRIFT_EFFECT_REFLECTIONS) &&
                   DRIFT_TERM_SLOT_(final, DRIFT_EFFECT_DOF) &&
                   DRIFT_TERM_SLOT_(indirect, DRIFT_EFFECT_INDIRECT),
               "the named terms are their effects' slots");

// --- PASSES ---

// What the conductor hands a technique's pass besides the frame: which row runs (effect and
// technique), that row's sampler stream and path-traced components (the table's columns),
// and the flag that cancels a long pass (may be NULL; path-traced passes poll it).
typedef struct drift_pass_args {
    drift_effect effect;
    int technique;
    uint32_t stream;
    uint32_t components;
    const atomic_bool *cancel;
} drift_pass_args;

// A technique's pass: fills its effect's term (S_l, R, I, or final for depth of field).
// Returns DRIFT_OK or an error it has logged.
typedef drift_result (*drift_pass_fn)(drift_frame_state *frame, const drift_pass_args *args);

// Where a row lists its --aov planes: add(sink, name, image) once a plane.
typedef void (*drift_pass_plane_fn)(void *sink, const char *name, const drift_image *image);
#define DRIFT_FRAME_PLANE_NAME 48 // the longest plane name, with its terminator
typedef void (*drift_pass_planes_fn)(const drift_frame_state *frame, drift_pass_plane_fn add,
                                     void *sink);

// The state `args`'s technique keeps across frames in its effect's slot, or NULL when it has
// none yet (or another technique of the effect holds the slot).
void *drift_pass_state(const drift_frame_state *frame, const drift_pass_args *args);
// Gives the slot to `args`'s technique: `data`, freed by destroy(ctx, data) when the frame is
// destroyed or another technique of the effect takes the slot (the previous holder's state
// is freed now).
void drift_pass_set_state(drift_frame_state *frame, const drift_pass_args *args, void *data,
                          void (*destroy)(drift_context *ctx, void *data));
// Frees every slot (the conductor, at destroy).
void drift_pass_free_states(drift_frame_state *frame);

// The pass of a row whose inputs already are its term (hard shadows, sharp reflections) or
// that adds none, and the planes of a row with none of its own.
drift_result drift_pass_none(drift_frame_state *frame, const drift_pass_args *args);
void drift_planes_none(const drift_frame_state *frame, drift_pass_plane_fn add, void *sink);

// Inputs a row needs, prepared by the conductor before any row's pass (each at most once a
// frame, whichever rows ask): the table's `inputs` column.
enum {
    DRIFT_INPUT_UNSHADOWED = 1u << 0,         // U_l per light and the environment term
    DRIFT_INPUT_HARD_SHADOWS = 1u << 1,       // the hard-shadow buffer (S_l = its bits)
    DRIFT_INPUT_SHADOW_MAPS = 1u << 2,        // a shadow map per light (cached)
    DRIFT_INPUT_SHARP_REFLECTIONS = 1u << 3,  // one mirror ray a pixel (R = its light)
    DRIFT_INPUT_PROBES = 1u << 4,             // the environment-map probes (cached)
    DRIFT_INPUT_OCCLUDER_DISTANCES = 1u << 5, // the hard-shadow buffer's occluder distances
                                              // (ISG's search): closest-hit shadow rays
};

// How the conductor treats a row: the table's `flags` column.
enum {
    DRIFT_ROW_NO_TERM = 1u << 0,             // the effect adds nothing to the frame
    DRIFT_ROW_SUMS_DIRECT = 1u << 1,         // the pass writes S_l; the conductor sums D after it
    DRIFT_ROW_PATH_TRACED = 1u << 2,         // skipped when a row replaces the frame
    DRIFT_ROW_REPLACES_FRAME = 1u << 3,      // the pass renders `final` whole (the lens reference)
    DRIFT_ROW_ENVIRONMENT_DIFFUSE = 1u << 4, // the term is the environment's diffuse light: D
                                             // keeps only the glossy part of it
    // Not the conductor's: drift bench frontier renders the row against the other searched
    // rows of its effect (drift_technique_frontier, docs/frontier.md). The path-traced truths
    // and the baselines a searched row dominates (pcf under pcss, the blur rows) are not.
    DRIFT_ROW_FRONTIER = 1u << 5,
    // A reflection row whose R already holds the light smooth glass lets through (the rows
    // over the sharp buffer, the path-traced one); after any other the realtime family adds
    // it (drift_realtime_pass_glass_transmission), so that no row renders glass opaque.
    DRIFT_ROW_TRACES_GLASS = 1u << 6,
};

// Runs fn for every row, or every pixel, rows in parallel. `rays` is the calling thread's ray
// counter. Both return the rays the pass counted.
typedef void (*drift_pass_row_fn)(drift_frame_state *frame, int32_t y, uint64_t *rays, void *user);
typedef void (*drift_pass_pixel_fn)(drift_frame_state *frame, int32_t x, int32_t y, uint64_t *rays,
                                    void *user);
uint64_t drift_pass_for_each_row(drift_frame_state *frame, drift_pass_row_fn fn, void *user);
uint64_t drift_pass_for_each_pixel(drift_frame_state *frame, drift_pass_pixel_fn fn, void *user);

// Times a pass: adds the milliseconds since `start` (drift_time_now) to the pass's entry.
static inline void drift_pass_time(drift_frame_state *frame, drift_hybrid_pass pass, double start)
{
    frame->stats.ms[pass] += 1000.0 * (drift_time_now() - start);
}

// fn for every pixel (or row) of the frame, booked to `pass`: its rays and its milliseconds
// added to the frame's stats.
void drift_pass_pixels(drift_frame_state *frame, drift_hybrid_pass pass, drift_pass_pixel_fn fn,
                       void *user);
void drift_pass_rows(drift_frame_state *frame, drift_hybrid_pass pass, drift_pass_row_fn fn,
                     void *user);

// Renders `components` of the pt (DRIFT_PT_COMPONENT_*) at the frame's spp through the pixel
// centres, pinhole unless `lens`, into the RGB image `out`.
drift_result drift_pass_reference_render(drift_frame_state *frame, uint32_t components,
                                         int32_t max_depth, bool lens, const atomic_bool *cancel,
                                         drift_image *out);

// Copies the RGB channels of `from` into `to` (same size).
void drift_pass_copy_rgb(const drift_image *from, drift_image *to);

// A per-pixel sampler keyed on the frame's seed and a pass-specific stream.
drift_sampler drift_pass_sampler(const drift_frame_state *frame, uint32_t stream, int32_t x,
                                 int32_t y);

// Outgoing direction at the pixel's surface (toward the camera); pixels with a hit only.
drift_vec3 drift_pass_wo(const drift_frame_state *frame, int32_t x, int32_t y);

#endif // DRIFT_FRAME_H
