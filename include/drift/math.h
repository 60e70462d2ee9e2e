// drift math: vectors, rays, bounds, orthonormal frames, hashing, the low-discrepancy
// sampler and the warps from [0,1)^2 to directions and shapes.
//
// Conventions (docs/conventions.md): right-handed, y-up world; the camera looks down -z in
// its own frame; radians everywhere; radiance is linear Rec.709 in float; `wo` points
// toward the viewer; directions are unit length unless a name says otherwise.
//
// STEP BY STEP (sampling one pixel sample)
//   drift_sampler s = drift_sampler_make(seed, pixel_index, sample_index);
//   drift_vec2 film = drift_sampler_next2(&s);  // dimensions 0,1
//   drift_vec2 lens = drift_sampler_next2(&s);  // dimensions 2,3
//   drift_vec3 d = drift_sample_cosine_hemisphere(drift_sampler_next2(&s));
//
// Everything here is pure and thread-safe. Most of it is static inline.
#ifndef DRIFT_MATH_H
#define DRIFT_MATH_H

#include <math.h>
#include <stdbool.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define DRIFT_PI      3.14159265358979323846f
#define DRIFT_INV_PI  0.31830988618379067154f
#define DRIFT_INV_2PI 0.15915494309189533577f
#define DRIFT_INV_4PI 0.07957747154594766788f
// Largest float below 1: samples live in [0, 1).
#define DRIFT_ONE_MINUS_EPSILON 0x1.fffffep-1f

typedef struct drift_vec2 {
    float x, y;
} drift_vec2;

typedef struct drift_vec3 {
    float x, y, z;
} drift_vec3;

typedef struct drift_ray {
    drift_vec3 origin;
    float tmin;
    drift_vec3 dir; // need not be unit length for accel queries; t is in units of |dir|
    float tmax;
    // Varies the ray's stochastic choices at veils (drift_alpha_mode BLEND) between rays that
    // are otherwise the same (a pixel centre's camera ray, sample after sample); 0 will do for
    // rays whose origin or direction is random already.
    uint32_t seed;
} drift_ray;

typedef struct drift_bounds3 {
    drift_vec3 min, max;
} drift_bounds3;

// Orthonormal frame: x, y tangent; z the normal.
typedef struct drift_frame {
    drift_vec3 x, y, z;
} drift_frame;

// --- VECTORS ---

static inline drift_vec2 drift_vec2_make(float x, float y)
{
    return (drift_vec2){ x, y };
}

static inline drift_vec3 drift_vec3_make(float x, float y, float z)
{
    return (drift_vec3){ x, y, z };
}

static inline drift_vec3 drift_vec3_splat(float v)
{
    return (drift_vec3){ v, v, v };
}

static inline drift_vec3 drift_vec3_add(drift_vec3 a, drift_vec3 b)
{
    return (drift_vec3){ a.x + b.x, a.y + b.y, a.z + b.z };
}

static inline drift_vec3 drift_vec3_sub(drift_vec3 a, drift_vec3 b)
{
    return (drift_vec3){ a.x - b.x, a.y - b.y, a.z - b.z };
}

static inline drift_vec3 drift_vec3_mul(drift_vec3 a, drift_vec3 b)
{
    return (drift_vec3){ a.x * b.x, a.y * b.y, a.z * b.z };
}

static inline drift_vec3 drift_vec3_scale(drift_vec3 a, float s)
{
    return (drift_vec3){ a.x * s, a.y * s, a.z * s };
}

// a + b * s
static inline drift_vec3 drift_vec3_fma(drift_vec3 a, drift_vec3 b, float s)
{
    return (drift_vec3){ a.x + b.x * s, a.y + b.y * s, a.z + b.z * s };
}

static inline drift_vec3 drift_vec3_neg(drift_vec3 a)
{
    return (drift_vec3){ -a.x, -a.y, -a.z };
}

static inline float drift_vec3_dot(drift_vec3 a, drift_vec3 b)
{
    return a.x * b.x + a.y * b.y + a.z * b.z;
}

static inline drift_vec3 drift_vec3_cross(drift_vec3 a, drift_vec3 b)
{
    return (drift_vec3){ a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x };
}

static inline float drift_vec3_length(drift_vec3 a)
{
    return sqrtf(drift_vec3_dot(a, a));
}

static inline drift_vec3 drift_vec3_normalize(drift_vec3 a)
{
    float len = drift_vec3_length(a);
    return len > 0.0f ? drift_vec3_scale(a, 1.0f / len) : a;
}

static inline drift_vec3 drift_vec3_min(drift_vec3 a, drift_vec3 b)
{
    return (drift_vec3){ fminf(a.x, b.x), fminf(a.y, b.y), fminf(a.z, b.z) };
}

static inline drift_vec3 drift_vec3_max(drift_vec3 a, drift_vec3 b)
{
    return (drift_vec3){ fmaxf(a.x, b.x), fmaxf(a.y, b.y), fmaxf(a.z, b.z) };
}

static inline float drift_vec3_max_component(drift_vec3 a)
{
    return fmaxf(a.x, fmaxf(a.y, a.z));
}

static inline bool drift_vec3_is_zero(drift_vec3 a)
{
    return a.x == 0.0f && a.y == 0.0f && a.z == 0.0f;
}

static inline bool drift_vec3_is_finite(drift_vec3 a)
{
    return isfinite(a.x) && isfinite(a.y) && isfinite(a.z);
}

// Rec.709 luminance of linear RGB.
static inline float drift_luminance(drift_vec3 c)
{
    return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z;
}

// Mirror of v about n (both pointing away from the surface).
static inline drift_vec3 drift_vec3_reflect(drift_vec3 v, drift_vec3 n)
{
    return drift_vec3_sub(drift_vec3_scale(n, 2.0f * drift_vec3_dot(v, n)), v);
}

static inline float drift_clampf(float v, float lo, float hi)
{
    return v < lo ? lo : (v > hi ? hi : v);
}

// --- FRAMES ---

// Duff et al. 2017, "Building an Orthonormal Basis, Revisited": branchless, no singularity.
static inline drift_frame drift_frame_from_normal(drift_vec3 n)
{
    float sign = copysignf(1.0f, n.z);
    float a = -1.0f / (sign + n.z);
    float b = n.x * n.y * a;
    drift_frame f;
    f.x = (drift_vec3){ 1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x };
    f.y = (drift_vec3){ b, sign + n.y * n.y * a, -n.y };
    f.z = n;
    return f;
}

static inline drift_vec3 drift_frame_to_world(const drift_frame *f, drift_vec3 v)
{
    return drift_vec3_add(drift_vec3_add(drift_vec3_scale(f->x, v.x), drift_vec3_scale(f->y, v.y)),
                          drift_vec3_scale(f->z, v.z));
}

static inline drift_vec3 drift_frame_to_local(const drift_frame *f, drift_vec3 v)
{
    return (drift_vec3){ drift_vec3_dot(v, f->x), drift_vec3_dot(v, f->y),
                         drift_vec3_dot(v, f->z) };
}

// --- BOUNDS ---

static inline drift_bounds3 drift_bounds3_empty(void)
{
    return (drift_bounds3){ { INFINITY, INFINITY, INFINITY }, { -INFINITY, -INFINITY, -INFINITY } };
}

static inline drift_bounds3 drift_bounds3_extend(drift_bounds3 b, drift_vec3 p)
{
    return (drift_bounds3){ drift_vec3_min(b.min, p), drift_vec3_max(b.max, p) };
}

static inline drift_bounds3 drift_bounds3_union(drift_bounds3 a, drift_bounds3 b)
{
    return (drift_bounds3){ drift_vec3_min(a.min, b.min), drift_vec3_max(a.max, b.max) };
}

static inline bool drift_bounds3_is_empty(drift_bounds3 b)
{
    return b.min.x > b.max.x || b.min.y > b.max.y || b.min.z > b.max.z;
}

// fmaxf / fminf as glibc computes them (a NaN argument gives the other; equal arguments, +0 and
// -0 included, give the second), but inline: without -ffinite-math-only GCC calls libm for
// fmaxf, a call per use in the path tracer's per-vertex code. Same bits as the libm call but
// for the sign of a zero from +0 against -0, which C leaves open (GCC may swap the operands).
static inline float drift_maxf(float a, float b)
{
    return (a > b || b != b) ? a : b;
}

static inline float drift_minf(float a, float b)
{
    return (a < b || b != b) ? a : b;
}

// --- HASHING AND RANDOM NUMBERS ---

// Integer hash with good avalanche (Wellons' lowbias32); the basis of every random
// number in drift, so results depend on keys, never on thread scheduling.
static inline uint32_t drift_hash_u32(uint32_t x)
{
    x ^= x >> 16;
    x *= 0x7feb352dU;
    x ^= x >> 15;
    x *= 0x846ca68bU;
    x ^= x >> 16;
    return x;
}

static inline uint32_t drift_hash_combine(uint32_t seed, uint32_t v)
{
    return drift_hash_u32(seed ^ (v + 0x9e3779b9U + (seed << 6) + (seed >> 2)));
}

// The bits of x in reverse order: the base-2 radical inverse as 32-bit fixed point (van der
// Corput), the basis of the Sobol sampler and of Hammersley point sets.
static inline uint32_t drift_reverse_bits(uint32_t x)
{
    x = ((x >> 1) & 0x55555555U) | ((x & 0x55555555U) << 1);
    x = ((x >> 2) & 0x33333333U) | ((x & 0x33333333U) << 2);
    x = ((x >> 4) & 0x0f0f0f0fU) | ((x & 0x0f0f0f0fU) << 4);
#if defined(__GNUC__)
    return __builtin_bswap32(x); // the last two swaps in one instruction
#else
    x = ((x >> 8) & 0x00ff00ffU) | ((x & 0x00ff00ffU) << 8);
    return (x >> 16) | (x << 16);
#endif
}

// Point k of a Hammersley set of n points in [0,1)^2, shifted by `shift` modulo 1 (a
// Cranley-Patterson rotation: each pixel or block its own shift, the set stays stratified).
static inline drift_vec2 drift_hammersley_shifted(uint32_t k, uint32_t n, drift_vec2 shift)
{
    float x = ((float)k + 0.5f) / (float)n + shift.x;
    float y = (float)drift_reverse_bits(k) * 0x1p-32f + shift.y;
    return drift_vec2_make(x - floorf(x), y - floorf(y));
}

// 24 high bits to a float in [0, 1).
static inline float drift_u32_to_unit(uint32_t x)
{
    return (float)(x >> 8) * 0x1p-24f;
}

// Low-discrepancy sampler: each pair of dimensions is the 2-D Sobol (0,2)-sequence with
// hash-based Owen scrambling, and the sample index is shuffled per dimension pair (Burley
// 2020, "Practical Hash-based Owen Scrambling", §4 padding by shuffling). Every value is a
// pure function of (seed, pixel, sample, dimension), which makes renders bit-identical for
// any thread count and lets a single sample be replayed.
// The per-pair scramble seeds depend on (seed, pixel, dimension) only, not on the sample: a
// caller that draws many samples of one pixel in a row keeps them here and hashes each pair's
// three seeds once a pixel instead of once a sample. Filled lazily, in dimension order; it
// belongs to the pixel whose key it holds and starts over when a sampler of another key uses it
// (two pixels of the same key derive the same seeds, so the values never depend on the cache).
#define DRIFT_SAMPLER_CACHE_PAIRS 96

typedef struct drift_sampler_cache {
    uint32_t key;   // the pixel key the entries belong to
    uint32_t count; // pairs filled, from dimension pair 0
    uint32_t seeds[DRIFT_SAMPLER_CACHE_PAIRS][3];
} drift_sampler_cache;

typedef struct drift_sampler {
    uint32_t key;               // hash of (seed, pixel)
    uint32_t sample;            // sample index within the pixel
    uint32_t dimension;         // next dimension pair to hand out
    uint32_t sample_reversed;   // sample's bits reversed, once a sample, not once a pair
    drift_sampler_cache *cache; // NULL: the seeds are hashed at every draw
} drift_sampler;

drift_sampler drift_sampler_make(uint32_t seed, uint32_t pixel, uint32_t sample);
// The same sampler, drawing its pair seeds through `cache` (drift_sampler_cache_init first):
// the same numbers as drift_sampler_make's, bit for bit.
drift_sampler drift_sampler_make_cached(uint32_t seed, uint32_t pixel, uint32_t sample,
                                        drift_sampler_cache *cache);
void drift_sampler_cache_init(drift_sampler_cache *cache);
// Next two dimensions, each in [0, 1).
drift_vec2 drift_sampler_next2(drift_sampler *s);
// Next dimension alone (uses a pair and drops one half).
float drift_sampler_next1(drift_sampler *s);
// Next two dimensions as independent uniform numbers hashed from (key, sample, dimension):
// plain random sampling over the same keys, the baseline against which the Sobol points are
// judged (error ~ 1/sqrt(N) where Sobol's falls nearly as 1/N on smooth integrands).
drift_vec2 drift_sampler_next2_random(drift_sampler *s);

// --- DISCRETE DISTRIBUTIONS ---

// The entry i of a CDF over n entries (n + 1 values, cdf[0] = 0, ascending) whose interval
// [cdf[i], cdf[i+1]) holds u, by binary search; n - 1 when u is at or past cdf[n - 1]'s end.
// Zero-width entries are never returned for a u inside [0, cdf[n]).
static inline uint32_t drift_cdf_find(const float *cdf, uint32_t n, float u)
{
    uint32_t lo = 0, hi = n;
    while (hi - lo > 1) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (cdf[mid] <= u) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    return lo;
}

// --- WARPS ([0,1)^2 -> shapes and directions; each with its pdf) ---

// Shirley & Chiu 1997 concentric map to the unit disk (area-preserving, low distortion).
drift_vec2 drift_sample_disk_concentric(drift_vec2 u);
// Cosine-weighted hemisphere around +z; pdf = cos(theta) / pi.
drift_vec3 drift_sample_cosine_hemisphere(drift_vec2 u);
// Uniform sphere; pdf = 1 / (4 pi).
drift_vec3 drift_sample_uniform_sphere(drift_vec2 u);
// Uniform cone around +z with cos of the half angle cos_max; pdf = 1 / (2 pi (1 - cos_max)).
drift_vec3 drift_sample_uniform_cone(drift_vec2 u, float cos_max);
// Uniform barycentrics (b1, b2) on a triangle (Heitz 2019 low-distortion map).
drift_vec2 drift_sample_triangle(drift_vec2 u);

// Power heuristic (beta = 2) for multiple importance sampling (Veach 1997, §9.2.4).
static inline float drift_power_heuristic(float pdf_a, float pdf_b)
{
    float a = pdf_a * pdf_a, b = pdf_b * pdf_b;
    return a + b > 0.0f ? a / (a + b) : 0.0f;
}

#ifdef __cplusplus
}
#endif
#endif // DRIFT_MATH_H
