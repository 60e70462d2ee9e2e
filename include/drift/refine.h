// drift refine: Smart Image Refinement (Amann, Chajdas, Westermann 2012). The hybrid frame is
// the rasterized approximation; per-pixel error metrics estimate where a ray tracer would
// change it, pixels are sorted by that estimate, and a ray budget per iteration refines the
// worst pixels first, blending ray-traced samples into the raster image.
//
// The pieces (docs/sir.md has the equations and the departures from the paper):
//   metrics   E_reflection1..5, E_dof, E_shadow per pixel in [0,1], combined by the averaged
//             sum or by a linear combination with per-scene weights lambda (fitted offline)
//   tracer    the paper's "pure ray tracer": per sample a primary ray through the pixel
//             centre (thin lens when the camera has an aperture), a shadow ray per light,
//             reflection rays recursively to depth 3. Enough samples a pixel give the pure
//             ray-traced image.
//   schedule  a stable radix sort of the pixels by encoded combined error (every non-zero
//             error before any zero), a request buffer of (pixel, samples), `budget` samples
//             traced per iteration, blend weight n / spp from the samples a pixel received.
//
// STEP BY STEP
//   drift_hybrid_render(frame, &camera, NULL);                 // the raster approximation
//   drift_refine *sir = NULL;
//   drift_refine_create(ctx, frame, &(drift_refine_params){ .budget = 8192 }, &sir);
//   drift_refine_begin(sir);                                   // metrics + sort (camera moved)
//   while (!drift_refine_done(sir)) drift_refine_iterate(sir, NULL);
//   const drift_image *rgb = drift_refine_image(sir);          // raster + blended ray tracing
//   drift_refine_destroy(sir);
//
// Ownership: the hybrid frame (and its scene and accel) are borrowed and must outlive the
// refiner. Images returned here belong to the refiner and stay valid until the next begin.
// Threads: one refiner is driven from one thread; it uses the context's pool internally.
#ifndef DRIFT_REFINE_H
#define DRIFT_REFINE_H

#include "drift/core.h"
#include "drift/hybrid.h"
#include "drift/image.h"

#ifdef __cplusplus
extern "C" {
#endif

// --- METRICS ---

typedef enum drift_refine_metric {
    DRIFT_METRIC_REFLECTION1 = 0, // 1 on reflective material
    DRIFT_METRIC_REFLECTION2,     // distance to the environment probe / the largest possible
    DRIFT_METRIC_REFLECTION3,     // <-i, r> (incident and mirror direction)
    DRIFT_METRIC_REFLECTION4,     // <-i, n>
    DRIFT_METRIC_REFLECTION5,     // ambient occlusion k_a: a self-reflection estimate
    DRIFT_METRIC_DOF,             // Sobel depth edges dilated by C_max(p)
    DRIFT_METRIC_SHADOW,          // conservative penumbra estimate of area lights
    DRIFT_METRIC_LEAK,            // the raster's shadow wrong outside every penumbra (contacts,
                                  // seams), by one shadow ray to each light's centre
    DRIFT_METRIC_COUNT
} drift_refine_metric;

// "reflection1" .. "reflection5", "dof", "shadow"; NULL out of range.
const char *drift_refine_metric_name(drift_refine_metric metric);
int drift_refine_metric_parse(const char *name); // -1 when unknown

typedef enum drift_refine_combine {
    DRIFT_COMBINE_DEFAULT = 0, // MAX with the weighted metrics, AVERAGE with the paper's
    DRIFT_COMBINE_AVERAGE,     // E = sum_i E_i / n
    DRIFT_COMBINE_LAMBDA,      // E = min(1, sum_i lambda_i E_i)
    DRIFT_COMBINE_MAX,         // E = max_i E_i: each metric is its expected error / 0.1
    DRIFT_COMBINE_COUNT
} drift_refine_combine;

// --- PARAMETERS ---

// How to refine. The default configuration is:
//   budget            = 0 -> width * height samples an iteration (rays per iteration: each
//                       sample is one primary ray plus its shadow and reflection rays)
//   spp               = 0 -> 16 samples a pixel make it refined (blend weight 1)
//   visit_spp         = 0 -> spp: the most samples one visit of the request buffer gives a
//                       pixel (ceil(visit_spp * error), at least 1)
//   max_depth         = 0 -> 3 reflection bounces
//   combine           = DRIFT_COMBINE_DEFAULT -> DRIFT_COMBINE_MAX when the metrics are weighted
//                       by the raster's expected error (they are that error, so the largest
//                       orders pixels as the error does), DRIFT_COMBINE_AVERAGE with the
//                       paper's metrics (reflection_tolerance < 0); DRIFT_COMBINE_LAMBDA uses
//                       `lambda`
//   refine_zero_error = false: pixels with zero error are never traced; true: they follow
//                       every non-zero one (the whole image converges to the pure one)
//   edge_threshold    = 0 -> 0.05: relative depth step per pixel that counts as an edge
//   ao_radius         = 0 -> 5% of the scene's bounding diagonal
//   ao_samples        = 0 -> 8 occlusion rays a reflective pixel
//   reflection_tolerance = 0 -> 0.01: a reflective pixel whose raster reflection is expected
//                       to be off by less (display values) gets no reflection error; < 0:
//                       the paper's unweighted reflection metrics
//   lobe_samples      = 0 -> 4 rays from a glossy lobe for that expectation (a mirror: 1)
//   leak_tolerance    = 0 -> 0.01: the leak metric flags a raster shadow wrong by more;
//                       < 0: no leak metric (and no rays for it)
//   shadow_tolerance  = 0 -> 0.01: a penumbra pixel stays flagged only where the raster's
//                       shadow, checked by lobe_samples shadow rays averaged over 5 x 5
//                       pixels, is off by more; < 0: the paper's ungated penumbra estimate
//   full_res_penumbra = false: with the gate (shadow_tolerance > 0) the penumbra estimate is
//                       searched at one pixel of each 2 x 2 block on one surface; true: at
//                       every pixel (always so without the gate)
//   components        = false: every refined pixel is traced whole; true: a pixel flagged by
//                       the reflection metrics alone gets only its reflection term R traced
//                       (no shadow rays at its first hit) and keeps the raster's E + D
//   seed              = 0
typedef struct drift_refine_params {
    uint32_t budget;
    uint32_t spp;
    uint32_t visit_spp;
    int32_t max_depth;
    drift_refine_combine combine;
    float lambda[DRIFT_METRIC_COUNT];
    bool refine_zero_error;
    float edge_threshold;
    float ao_radius;
    uint32_t ao_samples;
    float reflection_tolerance;
    uint32_t lobe_samples;
    float leak_tolerance;
    float shadow_tolerance;
    bool full_res_penumbra;
    bool components;
    uint32_t seed;
} drift_refine_params;

drift_refine_params drift_refine_params_resolve(const drift_refine_params *params,
                                                const drift_hybrid *frame);

// --- THE REFINER ---

typedef struct drift_refine drift_refine;

typedef struct drift_refine_stats {
    uint32_t iterations;   // since the last begin
    uint32_t sorts;        // since create
    uint64_t error_pixels; // pixels with non-zero combined error
    uint64_t requested;    // pixels in the request list (error pixels, or all)
    uint64_t refined;      // pixels of the list that have all their samples
    uint64_t samples;      // samples traced since the last begin
    uint64_t rays;         // rays traced since the last begin (primary, shadow, reflection)
    uint64_t metrics_rays; // the last begin: rays the metrics cast (AO, lobe, shadow checks)
    double metrics_ms;     // the last begin: metrics
    double sort_ms;        //                 combine, sort, request list
    double trace_ms;       // since the last begin: tracing and blending
} drift_refine_stats;

// Errors: DRIFT_ERR_INVALID_ARGUMENT (NULL, bad parameters; logged), DRIFT_ERR_OUT_OF_MEMORY.
drift_result drift_refine_create(drift_context *ctx, drift_hybrid *frame,
                                 const drift_refine_params *params, drift_refine **out);
void drift_refine_destroy(drift_refine *refine); // NULL-safe
drift_result drift_refine_set_params(drift_refine *refine, const drift_refine_params *params);

// Computes the metrics of the hybrid frame's last render (its camera), the combined error,
// the sort and the request list, and restarts the refinement from the raster image. Call it
// after each drift_hybrid_render whose camera or scene changed (and only then: the sort is
// what the paper keeps while the view stands).
drift_result drift_refine_begin(drift_refine *refine);
// Traces up to `budget` samples from the request list and blends them in. Returns
// DRIFT_ERR_CANCELLED when cancel becomes true (the image keeps what was traced).
drift_result drift_refine_iterate(drift_refine *refine, const atomic_bool *cancel);
bool drift_refine_done(const drift_refine *refine); // every listed pixel has its spp

const drift_image *drift_refine_image(const drift_refine *refine); // RGB, refined
const drift_image *drift_refine_error(const drift_refine *refine); // 1: combined error
const drift_image *drift_refine_metric_image(const drift_refine *refine, drift_refine_metric m);
drift_refine_stats drift_refine_get_stats(const drift_refine *refine);

// Planes for --aov and the viewer: "refined", "error.combined", "error.<metric>",
// "refine.mask" (1 where a pixel has all its samples), "refine.samples". False past the end.
bool drift_refine_plane(const drift_refine *refine, uint32_t index, const char **out_name,
                        const drift_image **out_image);

// --- THE PURE RAY TRACER ---

// Renders the pure ray-traced image of the hybrid frame's last camera: `spp` samples a pixel
// of the tracer that refinement uses (same samples, so refinement with every pixel listed
// converges to this image bit for bit). out: RGB of the frame's size, preallocated.
// rays (may be NULL) gets the rays traced.
drift_result drift_refine_render_pure(drift_refine *refine, uint32_t spp, drift_image *out,
                                      uint64_t *rays, const atomic_bool *cancel);

// --- LAMBDA FIT (the paper's pre-process) ---

// One training view: the metrics of a frame and its real error in [0,1].
typedef struct drift_refine_view {
    const drift_image *metrics[DRIFT_METRIC_COUNT]; // 1 channel each
    const drift_image *real_error;                  // 1 channel
} drift_refine_view;

// The real error of a raster pixel against the ray-traced one, in [0,1]: the largest
// per-channel difference of the display values (clamp to [0,1], gamma 1/2.2), divided by
// `scale` and clamped. out: 1 channel, preallocated.
void drift_refine_real_error(const drift_image *raster, const drift_image *traced, float scale,
                             drift_image *out);

// Mean absolute difference between min(1, sum lambda_i E_i) and the real error over views.
double drift_refine_lambda_cost(const drift_refine_view *views, uint32_t view_count,
                                const float lambda[DRIFT_METRIC_COUNT]);
// Random search for lambda (each in [0,1]) minimizing the cost. The averaged sum (1/n each)
// is the first candidate, so the result never does worse than it on these views.
void drift_refine_fit_lambda(const drift_refine_view *views, uint32_t view_count, uint32_t trials,
                             uint32_t seed, float out_lambda[DRIFT_METRIC_COUNT], double *out_cost);
// {"lambda": {"reflection1": ..., ...}} files. Errors: DRIFT_ERR_IO, DRIFT_ERR_PARSE (logged).
drift_result drift_refine_lambda_save(drift_context *ctx, const char *path,
                                      const float lambda[DRIFT_METRIC_COUNT]);
drift_result drift_refine_lambda_load(drift_context *ctx, const char *path,
                                      float out_lambda[DRIFT_METRIC_COUNT]);

#ifdef __cplusplus
}
#endif
#endif // DRIFT_REFINE_H
