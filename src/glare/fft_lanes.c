// Complex FFTs of DRIFT__GLARE_LANES sequences at once, one sequence a SIMD lane (the columns
// of the convolution's spectrum, issue 46): kissfft transforms one column at a time with scalar
// arithmetic, 6.2 ns a point at 1215 points; here every operation serves 8 columns. Stockham
// autosort, radix 4, 2, 3 and 5 (the padded sizes have no other factor), twiddles computed in
// double. Each lane does the same IEEE operations whatever the others hold, so a column's
// transform does not depend on which block or thread ran it; the AVX2 clone and the default one
// do the same operations (-ffp-contract=off): the same result to the bit. The rounding is not
// kissfft's: tests/unit/test_glare.c bounds the difference.
#include "core/vectorise.h"
#include "glare_internal.h"

#include <math.h>
#include <string.h>

#define MAX_STAGES 32

typedef float lane_v __attribute__((vector_size(4 * DRIFT__GLARE_LANES)));
// A lane vector at any float's alignment (the buffers are the allocator's).
typedef float lane_u __attribute__((vector_size(4 * DRIFT__GLARE_LANES), aligned(4), may_alias));

typedef struct lane_cpx {
    lane_v re, im;
} lane_cpx;

struct drift__glare_lanes {
    int32_t n, stages;
    int32_t radix[MAX_STAGES];
    float sign;           // -1 forward, +1 inverse: the exponent's sign
    drift__cpx *twiddles; // per stage, [f][q - 1] for f < l (the length done), 1 <= q < radix
    size_t offset[MAX_STAGES];
};

drift_result drift__glare_lanes_create(drift_context *ctx, int32_t n, bool inverse,
                                       drift__glare_lanes **out)
{
    *out = NULL;
    drift__glare_lanes *p = drift_alloc(ctx, sizeof(*p));
    if (!p) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    p->n = n;
    p->sign = inverse ? 1.0f : -1.0f;
    int32_t m = n;
    static const int32_t order[4] = { 4, 2, 3, 5 };
    for (int32_t i = 0; i < 4; ++i) {
        while (m % order[i] == 0 && p->stages < MAX_STAGES) {
            p->radix[p->stages++] = order[i];
            m /= order[i];
        }
    }
    size_t count = 0;
    for (int32_t s = 0, l = 1; s < p->stages; l *= p->radix[s++]) {
        p->offset[s] = count;
        count += (size_t)l * (size_t)(p->radix[s] - 1);
    }
    p->twiddles = drift_alloc(ctx, (count ? count : 1) * sizeof(drift__cpx));
    if (m != 1 || !p->twiddles) {
        drift__glare_lanes_destroy(ctx, p);
        return m != 1 ? DRIFT_ERR_INVALID_ARGUMENT : DRIFT_ERR_OUT_OF_MEMORY;
    }
    const double two_pi = 6.283185307179586476925286766559;
    for (int32_t s = 0, l = 1; s < p->stages; l *= p->radix[s++]) {
        int32_t radix = p->radix[s];
        for (int32_t f = 0; f < l; ++f) {
            for (int32_t q = 1; q < radix; ++q) {
                double a = (double)p->sign * two_pi * (double)(q * f) / (double)(l * radix);
                p->twiddles[p->offset[s] + (size_t)f * (size_t)(radix - 1) + (size_t)(q - 1)] =
                    (drift__cpx){ (float)cos(a), (float)sin(a) };
            }
        }
    }
    *out = p;
    return DRIFT_OK;
}

void drift__glare_lanes_destroy(drift_context *ctx, drift__glare_lanes *plan)
{
    if (plan) {
        drift_free(ctx, plan->twiddles);
        drift_free(ctx, plan);
    }
}

static inline DRIFT_ALWAYS_INLINE lane_cpx load(const float *base, size_t e)
{
    const float *p = base + 2 * DRIFT__GLARE_LANES * e;
    return (lane_cpx){ *(const lane_u *)(const void *)p,
                       *(const lane_u *)(const void *)(p + DRIFT__GLARE_LANES) };
}

static inline DRIFT_ALWAYS_INLINE void store(float *base, size_t e, lane_cpx v)
{
    float *p = base + 2 * DRIFT__GLARE_LANES * e;
    *(lane_u *)(void *)p = v.re;
    *(lane_u *)(void *)(p + DRIFT__GLARE_LANES) = v.im;
}

static inline DRIFT_ALWAYS_INLINE lane_cpx add(lane_cpx a, lane_cpx b)
{
    return (lane_cpx){ a.re + b.re, a.im + b.im };
}

static inline DRIFT_ALWAYS_INLINE lane_cpx sub(lane_cpx a, lane_cpx b)
{
    return (lane_cpx){ a.re - b.re, a.im - b.im };
}

static inline DRIFT_ALWAYS_INLINE lane_cpx twiddle(lane_cpx a, drift__cpx w)
{
    return (lane_cpx){ a.re * w.re - a.im * w.im, a.re * w.im + a.im * w.re };
}

static inline DRIFT_ALWAYS_INLINE lane_cpx scale(lane_cpx a, float s)
{
    return (lane_cpx){ a.re * s, a.im * s };
}

// i s a, for a real s.
static inline DRIFT_ALWAYS_INLINE lane_cpx times_i(lane_cpx a, float s)
{
    return (lane_cpx){ -(a.im * s), a.re * s };
}

// One stage: the transforms of length l become transforms of length l * radix. Element
// (a, f) of the sub-transform of residue a (< r = n / l) is at f * r + a; the output's
// residues are r' = r / radix, its element (a', f + l k) at (f + l k) r' + a'.
static inline DRIFT_ALWAYS_INLINE void stage(const drift__glare_lanes *p, int32_t s, int32_t l,
                                             const int32_t radix, const float *in, float *out)
{
    const size_t r1 = (size_t)(p->n / (l * radix)), r = r1 * (size_t)radix;
    const float sg = p->sign;
    const drift__cpx *tw = p->twiddles + p->offset[s];
    // cos and sin of 2 pi / 3, 2 pi / 5 and 4 pi / 5 (the sign is sg's).
    const float c3 = -0.5f, s3 = sg * 0.86602540378443864676f;
    const float c51 = 0.30901699437494742410f, c52 = -0.80901699437494742410f;
    const float s51 = sg * 0.95105651629515357212f, s52 = sg * 0.58778525229247312917f;
    for (size_t f = 0; f < (size_t)l; ++f) {
        const drift__cpx *w = tw + f * (size_t)(radix - 1);
        const float *src = in + 2 * DRIFT__GLARE_LANES * (f * r);
        float *dst = out;
        const size_t o = f * r1, ol = (size_t)l * r1; // output (f, k = 0) and its stride in k
        for (size_t a = 0; a < r1; ++a) {
            lane_cpx u0 = load(src, a);
            if (radix == 2) {
                lane_cpx u1 = twiddle(load(src, a + r1), w[0]);
                store(dst, o + a, add(u0, u1));
                store(dst, o + ol + a, sub(u0, u1));
            } else if (radix == 4) {
                lane_cpx u1 = twiddle(load(src, a + r1), w[0]);
                lane_cpx u2 = twiddle(load(src, a + 2 * r1), w[1]);
                lane_cpx u3 = twiddle(load(src, a + 3 * r1), w[2]);
                lane_cpx t0 = add(u0, u2), t1 = sub(u0, u2), t2 = add(u1, u3);
                lane_cpx t3 = times_i(sub(u1, u3), sg);
                store(dst, o + a, add(t0, t2));
                store(dst, o + ol + a, add(t1, t3));
                store(dst, o + 2 * ol + a, sub(t0, t2));
                store(dst, o + 3 * ol + a, sub(t1, t3));
            } else if (radix == 3) {
                lane_cpx u1 = twiddle(load(src, a + r1), w[0]);
                lane_cpx u2 = twiddle(load(src, a + 2 * r1), w[1]);
                lane_cpx t = add(u1, u2), d = times_i(sub(u1, u2), s3);
                lane_cpx m = add(u0, scale(t, c3));
                store(dst, o + a, add(u0, t));
                store(dst, o + ol + a, add(m, d));
                store(dst, o + 2 * ol + a, sub(m, d));
            } else { // 5
                lane_cpx u1 = twiddle(load(src, a + r1), w[0]);
                lane_cpx u2 = twiddle(load(src, a + 2 * r1), w[1]);
                lane_cpx u3 = twiddle(load(src, a + 3 * r1), w[2]);
                lane_cpx u4 = twiddle(load(src, a + 4 * r1), w[3]);
                lane_cpx t1 = add(u1, u4), d1 = sub(u1, u4), t2 = add(u2, u3), d2 = sub(u2, u3);
                lane_cpx m1 = add(u0, add(scale(t1, c51), scale(t2, c52)));
                lane_cpx m2 = add(u0, add(scale(t1, c52), scale(t2, c51)));
                lane_cpx e1 = add(times_i(d1, s51), times_i(d2, s52));
                lane_cpx e2 = sub(times_i(d1, s52), times_i(d2, s51));
                store(dst, o + a, add(u0, add(t1, t2)));
                store(dst, o + ol + a, add(m1, e1));
                store(dst, o + 2 * ol + a, add(m2, e2));
                store(dst, o + 3 * ol + a, sub(m2, e2));
                store(dst, o + 4 * ol + a, sub(m1, e1));
            }
        }
    }
}

DRIFT_AVX2_CLONES static float *lanes_run_clones(const drift__glare_lanes *plan, float *data,
                                                 float *work)
{
    float *in = data, *out = work;
    for (int32_t s = 0, l = 1; s < plan->stages; l *= plan->radix[s++]) {
        // Each radix's stage specialised (the branches on the radix fold away).
        switch (plan->radix[s]) {
        case 2:
            stage(plan, s, l, 2, in, out);
            break;
        case 3:
            stage(plan, s, l, 3, in, out);
            break;
        case 4:
            stage(plan, s, l, 4, in, out);
            break;
        default:
            stage(plan, s, l, 5, in, out);
            break;
        }
        float *t = in;
        in = out;
        out = t;
    }
    return in;
}

// The deinterleaving loads and interleaving stores of a block of L complex columns (one
// 64-byte line of a spectrum row), `count` rows `stride` complex numbers apart.
DRIFT_AVX2_CLONES static void lanes_gather_clones(const drift__cpx *src, size_t stride,
                                                  size_t count, float *dst)
{
    for (size_t y = 0; y < count; ++y) {
        const float *p = (const float *)(const void *)(src + y * stride);
        lane_v a = *(const lane_u *)(const void *)p;
        lane_v b = *(const lane_u *)(const void *)(p + DRIFT__GLARE_LANES);
        // __builtin_shufflevector: GCC (12 on) and clang both have it, with constant indices.
        store(dst, y,
              (lane_cpx){ __builtin_shufflevector(a, b, 0, 2, 4, 6, 8, 10, 12, 14),
                          __builtin_shufflevector(a, b, 1, 3, 5, 7, 9, 11, 13, 15) });
    }
}

DRIFT_AVX2_CLONES static void lanes_scatter_clones(const float *src, size_t count, drift__cpx *dst,
                                                   size_t stride)
{
    for (size_t y = 0; y < count; ++y) {
        lane_cpx v = load(src, y);
        float *p = (float *)(void *)(dst + y * stride);
        *(lane_u *)(void *)p = __builtin_shufflevector(v.re, v.im, 0, 8, 1, 9, 2, 10, 3, 11);
        *(lane_u *)(void *)(p + DRIFT__GLARE_LANES) =
            __builtin_shufflevector(v.re, v.im, 4, 12, 5, 13, 6, 14, 7, 15);
    }
}

// data = data x kernel x norm, element by element (the spectrum times the PSF's).
DRIFT_AVX2_CLONES static void lanes_multiply_clones(float *data, const float *kernel, size_t count,
                                                    float norm)
{
    for (size_t e = 0; e < count; ++e) {
        lane_cpx a = load(data, e), b = load(kernel, e);
        store(data, e,
              (lane_cpx){ (a.re * b.re - a.im * b.im) * norm, (a.re * b.im + a.im * b.re) * norm });
    }
}

// The entry points fft.c calls: plain functions over the clones above. Clang 14 emits a cloned
// function's resolver only in a file that calls it, so an extern cloned definition that only
// other files call has no symbol (the CI's clang link failed); the clones' names are this
// file's alone (vectorise.h: clang gives a static clone's resolver external linkage).
float *drift__glare_lanes_run(const drift__glare_lanes *plan, float *data, float *work)
{
    return lanes_run_clones(plan, data, work);
}

void drift__glare_lanes_gather(const drift__cpx *src, size_t stride, size_t count, float *dst)
{
    lanes_gather_clones(src, stride, count, dst);
}

void drift__glare_lanes_scatter(const float *src, size_t count, drift__cpx *dst, size_t stride)
{
    lanes_scatter_clones(src, count, dst, stride);
}

void drift__glare_lanes_multiply(float *data, const float *kernel, size_t count, float norm)
{
    lanes_multiply_clones(data, kernel, count, norm);
}
