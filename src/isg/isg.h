// Image space gathering (Robison & Shirley 2009), the pieces shared by its files:
//   isg_samples.c      sample sets on the disk (Shirley-Chiu concentric map of a regular grid,
//                      rotated per pixel) or the rectangle (grid shifted per pixel)
//   isg.c              the two-phase cross-bilateral filter's one building block, eq. 4, the
//                      frame's ISG buffers, parameters and planes
//   isg_shadows.c      soft shadows (section 3.1) and the `blur` shadow baseline
//   isg_reflections.c  glossy reflections (section 3.2) and the `blur` reflection baseline
//   isg_dof.c          depth of field (section 3.3)
// docs/isg.md has the equations and where this departs from the paper.
#ifndef DRIFT_ISG_INTERNAL_H
#define DRIFT_ISG_INTERNAL_H

#include "core/vectorise.h"
#include "frame/family.h"

#include <math.h>

// --- SAMPLE SETS (isg_samples.c) ---

#define DRIFT_ISG_MAX_SAMPLES 1024 // 32 x 32

typedef enum drift_isg_layout {
    DRIFT_ISG_DISK = 0, // sphere and disk lights, glossy lobes, the lens
    DRIFT_ISG_RECT,     // quad lights
} drift_isg_layout;

// `count` points (a perfect square k*k) at the centres of a regular k x k grid, mapped to the
// unit disk by the concentric map (DISK) or to [-1,1]^2 (RECT).
typedef struct drift_isg_pattern {
    drift_isg_layout layout;
    uint32_t count;
    drift_vec2 points[DRIFT_ISG_MAX_SAMPLES];
} drift_isg_pattern;

// False when count is not a perfect square in 1..DRIFT_ISG_MAX_SAMPLES.
bool drift_isg_count_valid(int32_t count);
void drift_isg_pattern_make(uint32_t count, drift_isg_layout layout, drift_isg_pattern *out);

// Per-pixel decorrelation, to trade the banding of one fixed pattern for noise: a rotation
// for the disk (keeps the disk), a toroidal shift by less than a grid cell for the rectangle
// (keeps the rectangle and its orientation).
typedef struct drift_isg_jitter {
    float cos_a, sin_a;
    drift_vec2 shift;
} drift_isg_jitter;

drift_isg_jitter drift_isg_jitter_make(uint32_t hash); // white: independent per pixel
// Interleaved over the image (what the passes use): the nine pixels of every 3 x 3 window
// take the nine strata of the rotation (quarter turn) and of the shift, placed by the hash,
// so neighbouring errors cancel (less stipple than white noise at the same cost).
drift_isg_jitter drift_isg_jitter_at(uint32_t hash, int32_t x, int32_t y);

// Offset in pixels of sample i of the pattern for a kernel of half extents `radius`.
drift_vec2 drift_isg_offset(const drift_isg_pattern *pattern, const drift_isg_jitter *jitter,
                            uint32_t i, drift_vec2 radius);

// Wraps v into [-1, 1).
static inline float drift_isg_wrap_unit(float v)
{
    float t = 0.5f * (v + 1.0f);
    return 2.0f * (t - floorf(t)) - 1.0f;
}

// drift_isg_offset's body, inlined into the filters.
static inline DRIFT_ALWAYS_INLINE drift_vec2 drift_isg_offset_inline(
    const drift_isg_pattern *pattern, const drift_isg_jitter *jitter, uint32_t i, drift_vec2 radius)
{
    drift_vec2 p = pattern->points[i];
    if (pattern->layout == DRIFT_ISG_DISK) {
        p = drift_vec2_make(jitter->cos_a * p.x - jitter->sin_a * p.y,
                            jitter->sin_a * p.x + jitter->cos_a * p.y);
    } else {
        // A shift of under one cell (2 / k) keeps the grid stratified over the rectangle.
        float cell = 2.0f / sqrtf((float)pattern->count);
        p = drift_vec2_make(drift_isg_wrap_unit(p.x + cell * jitter->shift.x),
                            drift_isg_wrap_unit(p.y + cell * jitter->shift.y));
    }
    return drift_vec2_make(p.x * radius.x, p.y * radius.y);
}

// --- THE FILTER (isg.c) ---

// Range function times spatial weight of the sample at pixel (x, y) for the centre the
// caller's `user` describes; 0 rejects the sample.
typedef float (*drift_isg_range_fn)(const void *user, int32_t x, int32_t y);
// Optional: the channels to read for the sample at (x, y) instead of the image's (NULL: the
// image's). The second depth layer substitutes what lies behind the centre this way.
typedef const float *(*drift_isg_value_fn)(const void *user, int32_t x, int32_t y);

typedef struct drift_isg_kernel {
    const drift_isg_pattern *pattern;
    drift_isg_jitter jitter;
    drift_vec2 radius; // half extents in pixels along x and y
    drift_isg_range_fn range;
    const void *user;
    drift_isg_value_fn value; // may be NULL
} drift_isg_kernel;

// Eq. 4 at pixel (x, y): the average of `image` channels [first, first + channels) over the
// centre and the pattern's samples (each read at the nearest pixel; samples off the image are
// dropped), weighted by the range function, the same weights in numerator and denominator.
// Returns the weight sum; where it is 0 (every sample rejected), out is the centre's value.
// Sums differences from the centre (when finite) so that a constant image stays exact.
float drift_isg_filter(const drift_isg_kernel *kernel, const drift_image *image, int32_t first,
                       int32_t channels, int32_t x, int32_t y, float *out);

// The filter's body for a range and value function known where it is inlined (the passes
// wrap it once per range function in a function cloned for AVX2, so that the range function
// is inlined and floorf is one instruction): the same operations in the same order as
// drift_isg_filter, so the same result to the bit. First the samples' pixels (a loop over the
// pattern that vectorises), then the weighted sum over them in the pattern's order.
static inline DRIFT_ALWAYS_INLINE float
drift_isg_filter_inline(const drift_isg_kernel *k, drift_isg_range_fn range,
                        drift_isg_value_fn value, const drift_image *image, int32_t first,
                        int32_t channels, int32_t x, int32_t y, float *out)
{
    const float *centre = drift_image_pixel(image, x, y) + first;
    float ref[4], sum[4] = { 0.0f, 0.0f, 0.0f, 0.0f };
    for (int32_t c = 0; c < channels; ++c) {
        ref[c] = isfinite(centre[c]) ? centre[c] : 0.0f;
    }
    uint32_t n = k->pattern->count;
    int32_t sxs[DRIFT_ISG_MAX_SAMPLES + 1], sys[DRIFT_ISG_MAX_SAMPLES + 1];
    sxs[0] = x;
    sys[0] = y;
    uint32_t m = 1;
    for (uint32_t i = 0; i < n; ++i) {
        drift_vec2 o = drift_isg_offset_inline(k->pattern, &k->jitter, i, k->radius);
        int32_t sx = (int32_t)floorf((float)x + o.x + 0.5f);
        int32_t sy = (int32_t)floorf((float)y + o.y + 0.5f);
        sxs[m] = sx;
        sys[m] = sy;
        m += sx >= 0 && sy >= 0 && sx < image->width && sy < image->height; // off the image: out
    }
    float weight_sum = 0.0f;
    for (uint32_t i = 0; i < m; ++i) {
        int32_t sx = sxs[i], sy = sys[i];
        float w = range(k->user, sx, sy);
        if (!(w > 0.0f)) {
            continue; // rejected; skipping also keeps an infinite value of a rejected sample out
        }
        const float *v = value ? value(k->user, sx, sy) : NULL;
        v = v ? v : drift_image_pixel(image, sx, sy) + first;
        for (int32_t c = 0; c < channels; ++c) {
            sum[c] += w * (v[c] - ref[c]);
        }
        weight_sum += w;
    }
    for (int32_t c = 0; c < channels; ++c) {
        out[c] = weight_sum > 0.0f ? ref[c] + sum[c] / weight_sum : centre[c];
    }
    return weight_sum;
}

// Pixels per scene unit at view depth 1 (the projection's scale, H / (2 tan(fov_y / 2))), and
// the horizontal field of view.
float drift_isg_pixels_per_unit(const drift_camera *camera, int32_t height);
float drift_isg_fov_x(const drift_camera *camera, int32_t width, int32_t height);

// GLSL smoothstep.
static inline float drift_isg_smoothstep(float e0, float e1, float x)
{
    float t = (x - e0) / (e1 - e0);
    t = t < 0.0f ? 0.0f : (t > 1.0f ? 1.0f : t);
    return t * t * (3.0f - 2.0f * t);
}

// --- FRAME STATE, PARAMETERS, PLANES (isg.c) ---

typedef struct drift_isg_state {
    drift_image *light_search; // per light, 2: average occluder distance d, gather radius (px)
    uint32_t light_count;
    drift_image reflection_search; // 2: average reflected distance E, gather radius (px)
    // 4: what each glossy pixel's mirror ray met, the point p + d r (w = 1), or r for a miss
    // (w = 0); w = -1 where there is no lobe (isg_reflections.c)
    drift_image reflection_points;
    drift_image dof_search;   // 1: gather radius (px) found by the search
    drift_image layer_depth;  // 1: view depth of the second layer (0: none; 1e30: a miss)
    drift_image layer_colour; // 3: its radiance (isg_layers.c)
    drift_isg_pattern search, gather, search_rect, gather_rect;
} drift_isg_state;

// ISG's state, in its slot of the frame (frame/family.h): made empty by the family's create
// hook, its buffers on the first ISG pass (light_search is NULL until then; most frames never
// run ISG), freed by its destroy hook.
static inline drift_isg_state *drift_isg_of(const drift_frame_state *frame)
{
    return (drift_isg_state *)drift_family_state(frame, DRIFT_FAMILY_ISG);
}

// The state once an ISG pass has made its buffers, else NULL (what the planes and counts read).
static inline const drift_isg_state *drift_isg_buffers(const drift_frame_state *frame)
{
    const drift_isg_state *s = drift_isg_of(frame);
    return s && s->light_search ? s : NULL;
}

// Fills ISG's zero settings with their defaults (drift/hybrid.h) for this scene.
void drift_isg_settings_resolve(drift_isg_settings *settings, const drift_scene *scene);
// What is wrong with resolved ISG settings, or NULL.
const char *drift_isg_settings_problem(const drift_isg_settings *settings);

// The family's create and destroy hooks (isg.c): an empty state; the state and all it holds
// (NULL-safe).
drift_result drift_isg_create(drift_frame_state *frame, void **out_state);
void drift_isg_destroy(drift_frame_state *frame, void *state);
// Makes the buffers on first use and the patterns for the current parameters.
drift_result drift_isg_prepare(drift_frame_state *frame);

// The --aov planes of the ISG rows (light search radii, the reflection and lens searches,
// the second layer).
void drift_isg_shadow_planes(const drift_frame_state *frame, drift_pass_plane_fn add, void *sink);
void drift_isg_reflection_planes(const drift_frame_state *frame, drift_pass_plane_fn add,
                                 void *sink);
void drift_isg_dof_planes(const drift_frame_state *frame, drift_pass_plane_fn add, void *sink);

// The passes (they add their milliseconds to DRIFT_PASS_ISG).
drift_result drift_isg_pass_shadows(drift_frame_state *frame,
                                    const drift_pass_args *args); // isg or blur: bits -> S_l
drift_result drift_isg_pass_reflections(drift_frame_state *frame,
                                        const drift_pass_args *args); // isg or blur: sharp -> R
drift_result drift_isg_pass_dof(drift_frame_state *frame,
                                const drift_pass_args *args); // focus -> final
// The second depth layer, for isg_layers = 2 (isg_layers.c).
drift_result drift_isg_pass_layer(drift_frame_state *frame);

// --- THE PIECES THE PASSES ARE MADE OF, FOR TESTS ---

// Soft-shadow penumbra radius in scene units, eq. 8: L d / (D - d); 0 without occluder.
float drift_isg_penumbra(float light_size, float occluder_distance, float light_distance);
// Glossy gather half angle alpha (radians), eq. 13: tan alpha = E tan theta / (e + E).
float drift_isg_gloss_alpha(float theta_max, float eye_distance, float reflected_distance);

#endif // DRIFT_ISG_INTERNAL_H
