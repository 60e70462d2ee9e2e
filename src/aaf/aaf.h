// Axis-aligned filtering (Mehta, Wang, Ramamoorthi 2012/2013; docs/aaf.md): the pieces shared
// by the soft-shadow pass (aaf_shadows.c), the indirect pass (aaf_indirect.c) and the filter
// they both use (aaf_filter.c). Tests include this header to test the filter alone.
#ifndef DRIFT_AAF_H
#define DRIFT_AAF_H

#include "frame/family.h"

// Defaults (docs/aaf.md explains each).
#define DRIFT_AAF_SPARSE_MIN          4 // sparse samples a pixel, at least (when spp allows)
#define DRIFT_AAF_DILATE              4 // pixels searched for occluders a pixel's sparse rays missed
#define DRIFT_AAF_FLAT_EVIDENCE       16.0f // sparse rays (own + neighbours') that may call a pixel flat
#define DRIFT_AAF_MAX_RADIUS          16 // filter half width in pixels (the paper's "large constant")
#define DRIFT_AAF_FLOOR_SHARE         0.75 // an adaptive pixel's least share of their mean budget
#define DRIFT_AAF_BETA_RATIO          2.0f // neighbours whose beta differs by more are rejected
#define DRIFT_AAF_NORMAL_COS          0.9f // ... and those whose normal turns by more than ~25 degrees
#define DRIFT_AAF_DEPTH_TOLERANCE     0.1f  // ... or whose depth differs by more than 10%
#define DRIFT_AAF_SHADOW_SHRINK_SPP   16.0f // shadows: beta shrinks as (spp / 16)^(-1/6)
#define DRIFT_AAF_SHADOW_SHRINK_EXP   (1.0f / 6.0f)
#define DRIFT_AAF_INDIRECT_SHRINK_SPP 4.0f // indirect: as (spp / 4)^(-1/3)
#define DRIFT_AAF_INDIRECT_SHRINK_EXP (1.0f / 3.0f)
#define DRIFT_AAF_OMEGA_DIFFUSE       2.8f // eq. 4.5, Lambertian
// The light as a Gaussian: sigma = sqrt(area / 12), the standard deviation of a uniform square
// of that area.
#define DRIFT_AAF_LIGHT_SIGMA 0.2887f

// --- SAMPLES ---

// AAF's sample stream for one (pixel, sample): the Owen-scrambled Sobol sampler, or with
// `random` independent uniform numbers hashed from (seed, pixel, sample, dimension). Sobol
// integrates a pixel's smooth visibility of a quad light at nearly 1/N; the paper's
// comparison (Fig. 3.6) is against random sampling's 1/sqrt(N), with AAF random-sampled too.
typedef struct drift_aaf_sampler {
    drift_sampler base; // keys and dimension; its Sobol points unless `random`
    bool random;
} drift_aaf_sampler;

static inline drift_aaf_sampler drift_aaf_sampler_make(uint32_t key, uint32_t pixel,
                                                       uint32_t sample, bool random)
{
    return (drift_aaf_sampler){ drift_sampler_make(key, pixel, sample), random };
}

static inline drift_vec2 drift_aaf_next2(drift_aaf_sampler *s)
{
    return s->random ? drift_sampler_next2_random(&s->base) : drift_sampler_next2(&s->base);
}

static inline float drift_aaf_next1(drift_aaf_sampler *s)
{
    return drift_aaf_next2(s).x;
}

// --- THE FILTER (aaf_filter.c) ---

// What the filter reads per pixel. beta is the Gaussian's standard deviation in world units;
// a pixel whose beta is not > 0 (no occluder, no reflector) keeps its value unfiltered, and
// serves its neighbours without the beta test. Distances between pixels are measured in
// world space; with has_axis, only their part perpendicular to `axis` counts (the plane
// parallel to the light, eq. 3.3).
typedef struct drift_aaf_filter_desc {
    const drift_image *beta;      // 1 channel
    const drift_image *footprint; // 1 channel: world size of the pixel (d of eqs. 3.4, 4.4)
    const drift_gbuffer *gbuffer; // position, normal, depth, material_id
    bool has_axis;
    drift_vec3 axis;
    int32_t max_radius; // pixels
    void *workspace;    // drift_aaf_filter_workspace_bytes for the image, or NULL: allocated
} drift_aaf_filter_desc;

// Bytes of the filter's packed per-pixel inputs for an image of this size.
size_t drift_aaf_filter_workspace_bytes(int32_t width, int32_t height);

// The separable filter of eq. 3.7: a horizontal then a vertical 1-D Gaussian, both with the
// centre pixel's beta, over neighbours that pass the beta-ratio, depth and normal tests.
// in, scratch and out have the same size and channel count; out may not be in or scratch.
// Errors: DRIFT_ERR_OUT_OF_MEMORY (its packed copy of the per-pixel inputs).
drift_result drift_aaf_filter_separable(drift_context *ctx, const drift_aaf_filter_desc *desc,
                                        const drift_image *in, drift_image *scratch,
                                        drift_image *out);
// The exact 2-D filter of eq. 3.2 with the same tests (quadratic in the radius: for tests).
drift_result drift_aaf_filter_exact(drift_context *ctx, const drift_aaf_filter_desc *desc,
                                    const drift_image *in, drift_image *out);

// The consistent filter width (paper reference [51]): beta times this factor, which is 1 up
// to from_spp samples a pixel and falls as (spp / from_spp)^-exponent after, so the filter's
// bias falls with the samples and the estimate converges to the reference.
float drift_aaf_beta_shrink(uint32_t spp, float from_spp, float exponent);

// World size of a pixel at view depth z for the frame's camera.
float drift_aaf_pixel_footprint(const drift_camera *camera, int32_t image_height, float z);

// --- SAMPLE BUDGET (aaf_filter.c) ---

// Sparse samples per pixel for an average target of `spp`: a quarter of it, at least
// DRIFT_AAF_SPARSE_MIN (never more than spp).
uint32_t drift_aaf_sparse_count(uint32_t spp);
// The soft-shadow pass's: the same from 8 spp on, half of spp (at least 2) below, so that 4 spp
// keeps an adaptive pass (aaf_shadows.c).
uint32_t drift_aaf_shadow_sparse_count(uint32_t spp);

// Turns the desired rates want[i] (eq. 3.5 or 4.6; 0 for flat pixels, which get no adaptive
// samples; < 0 for pixels outside the budget) into counts[i] >= sparse, at most max_spp, whose
// mean over the `active` pixels (those with want >= 0) is spp: the rates are scaled by one
// factor found by bisection, then rounded up or down by a per-pixel hash so the expected total
// is the budget. When the adaptive pixels cannot spend it under max_spp, the cap doubles until
// they can (at most to 8 max_spp). Flat pixels keep `sparse`, plus an even share of what the
// adaptive pixels still cannot take; pixels outside the budget keep `sparse`.
void drift_aaf_allocate(const float *want, size_t count, size_t active, uint32_t sparse,
                        uint32_t spp, uint32_t max_spp, uint32_t seed, uint32_t *counts);

// --- THE DENOISER (aaf_denoise.c, --aaf-denoise) ---

// Variance of the mean of a light-weighted visibility v estimated from n rays (Bernoulli,
// v pulled half a ray toward 1/2 so that a pixel whose few rays agreed is not noise-free;
// over n again for Sobol points, `random` false).
float drift_aaf_visibility_variance(float v, float n, bool random);
// Filters a pass's noisy estimate `in` (1 or 3 channels) with the feature-guided denoiser,
// guided by the G-buffer's normal and depth, `variance` (1 channel) the variance of each
// pixel's mean; writes out's channels (out the size of in, may be in).
drift_result drift_aaf_denoise_estimate(drift_frame_state *frame, const drift_image *in,
                                        const drift_image *variance, drift_image *out);

// --- STATE AND PASSES ---

#define DRIFT_AAF_AUX 6 // floats of running sums a pixel keeps between the passes

typedef struct drift_aaf_light {
    drift_image beta;       // 1: filter width (0: not filtered)
    drift_image spp;        // 1: n(x), the samples the pixel took
    drift_image unfiltered; // 1: the visibility estimate before filtering
} drift_aaf_light;

// One indirect lobe's buffers (diffuse: --indirect aaf; glossy: --reflections aaf).
typedef struct drift_aaf_lobe_buffers {
    drift_image beta, spp, unfiltered; // 1, 1, 3: the planes of --aov
    drift_image radiance, filtered;    // 3: the demodulated estimate, filtered
} drift_aaf_lobe_buffers;

typedef struct drift_aaf_state {
    int32_t width, height;
    uint32_t light_count;
    drift_aaf_light *lights;
    drift_image footprint; // 1
    drift_image scratch1, scratch3;
    float *want;            // width*height
    uint32_t *counts;       // width*height
    float *aux;             // DRIFT_AAF_AUX * width*height: per-pixel running sums
    void *filter_workspace; // the filter's packed inputs, reused by every filter call
    drift_aaf_lobe_buffers indirect, specular;
} drift_aaf_state;

// AAF's state, in its slot of the frame (frame/family.h): made empty by the family's create
// hook, its buffers the first time a pass of the frame uses AAF (lights is NULL until then;
// most frames never do), freed by its destroy hook.
static inline drift_aaf_state *drift_aaf_of(const drift_frame_state *frame)
{
    return (drift_aaf_state *)drift_family_state(frame, DRIFT_FAMILY_AAF);
}

// The state once an AAF pass has made its buffers, else NULL (what the planes and counts read).
static inline const drift_aaf_state *drift_aaf_buffers(const drift_frame_state *frame)
{
    const drift_aaf_state *s = drift_aaf_of(frame);
    return s && s->lights ? s : NULL;
}

// The family's create and destroy hooks (aaf_state.c): an empty state; the state and all it
// holds (NULL-safe).
drift_result drift_aaf_state_create(drift_frame_state *frame, void **out_state);
void drift_aaf_state_destroy(drift_frame_state *frame, void *state);
// Makes the buffers on first use.
drift_result drift_aaf_state_ensure(drift_frame_state *frame);
// Makes a lobe's buffers the first time the lobe runs (a frame that filters only shadows, or
// only one lobe, does not hold the others').
drift_result drift_aaf_lobe_buffers_ensure(drift_context *ctx, drift_aaf_lobe_buffers *buffers,
                                           int32_t width, int32_t height);
// Makes the state if needed and fills its footprint plane; *out_active (may be NULL) gets the
// number of pixels that see a surface (the pixels the average spp is over).
drift_result drift_aaf_prepare(drift_frame_state *frame, size_t *out_active);

// Fills every light's shadow buffer S_l (--shadows aaf). Needs the G-buffer.
drift_result drift_aaf_pass_shadows(drift_frame_state *frame, const drift_pass_args *args);
// Fills frame->indirect (--indirect aaf). Needs the G-buffer.
drift_result drift_aaf_pass_indirect(drift_frame_state *frame, const drift_pass_args *args);
// Fills frame->reflections (--reflections aaf, aaf_specular.c). Needs the G-buffer.
drift_result drift_aaf_pass_specular(drift_frame_state *frame, const drift_pass_args *args);

// Fills zero settings with their defaults for a frame of `spp` samples a pixel (drift/hybrid.h),
// and says what is wrong with resolved ones (NULL: nothing).
void drift_aaf_settings_resolve(drift_aaf_settings *settings, uint32_t spp);
const char *drift_aaf_settings_problem(const drift_aaf_settings *settings, uint32_t spp);

// The --aov planes of the AAF rows: per light (or per lobe) beta, n(x) and the unfiltered
// estimate, listed once the buffers exist (aaf_state.c).
void drift_aaf_shadow_planes(const drift_frame_state *frame, drift_pass_plane_fn add, void *sink);
void drift_aaf_indirect_planes(const drift_frame_state *frame, drift_pass_plane_fn add, void *sink);
void drift_aaf_specular_planes(const drift_frame_state *frame, drift_pass_plane_fn add, void *sink);

// --- INDIRECT LOBES (aaf_indirect.c, shared by aaf_specular.c) ---

// A lobe whose first bounce AAF path-traces, filters and multiplies back by its albedo.
typedef struct drift_aaf_lobe {
    uint32_t stream;                 // sampler stream
    drift_aaf_lobe_buffers *buffers; // in frame->aaf
    drift_image *out;                // the frame's term
    float shrink_from_spp, shrink_exponent;
    float pixel_width; // beta's floor in pixel footprints d (eq. 4.4: 1 / 0.15 for diffuse)
    // Whether the pixel has the lobe; then *albedo (what the estimate is divided by before the
    // filter) and *omega (Omega_h^max of eq. 4.5; 0: a delta lobe, kept sharp: no filter and
    // no adaptive samples).
    bool (*at)(const drift_bsdf *bsdf, drift_vec3 wo, drift_vec3 *albedo, float *omega);
    // The first bounce's direction *wi and the sample's weight f cos / (pdf albedo) (0: the
    // sample carries nothing). *emission: whether light emitted at the first hit counts (a
    // mirror's; for other lobes it is the direct term's).
    void (*sample)(const drift_bsdf *bsdf, drift_vec3 wo, drift_vec2 u, drift_vec3 *wi,
                   float *weight, bool *emission);
} drift_aaf_lobe;

// The three passes for one lobe: sparse (z_min, z_max -> beta of eq. 4.4 and n(x) of eq. 4.6),
// adaptive, and the separable world-space filter of the demodulated estimate.
drift_result drift_aaf_lobe_pass(drift_frame_state *frame, const drift_aaf_lobe *lobe);

// eq. 4.4: the filter width for the nearest reflector at z_min and a pixel of world size d,
// max(2 z_min / omega, pixel_width d); the paper's pixel_width is 1 / 0.15.
float drift_aaf_indirect_beta(float z_min, float footprint, float omega, float pixel_width);
// eq. 4.5 for a glossy lobe of Phong exponent n: Omega = 3.6 + 0.084 m with m = 4 n, the
// Blinn-Phong exponent of the same lobe width (cos^m of the half angle ~ cos^n(2 x it)).
float drift_aaf_omega_specular(float phong_exponent);

#endif // DRIFT_AAF_H
