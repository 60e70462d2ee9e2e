// exp(-e) written out so that the filters' tap loops vectorise (libm's expf does not): the
// a-trous filter's (atrous.c) and the variance-guided filter's (svgf.c).
#ifndef DRIFT_DENOISE_EXP_NEG_H
#define DRIFT_DENOISE_EXP_NEG_H

#include "core/vectorise.h"

#include <stdint.h>

#define DENOISE_EXP_CUTOFF 30.0f // exp(-30) ~ 1e-13: the tap adds nothing

// exp(-e) for e in [0, DENOISE_EXP_CUTOFF]: 2^x with x = -e / ln 2 split into the nearest
// integer n (by the 1.5 * 2^23 rounding trick: a float-to-int conversion keeps GCC from
// vectorising the AVX2 clone) and f in [-1/2, 1/2], 2^f by its Taylor series to the 6th
// power (relative error < 2e-7) and 2^n put in the exponent bits.
static inline DRIFT_ALWAYS_INLINE float exp_neg(float e)
{
    float x = -e * 1.44269504f;

    union {
        float f;
        int32_t i;
    } rounded = { .f = x + 12582912.0f };

    float f = (x - (rounded.f - 12582912.0f)) * 0.69314718f; // 2^f = e^(f ln 2)
    float p = 1.0f + f * (1.0f + f * (0.5f + f * (1.0f / 6.0f +
                                                  f * (1.0f / 24.0f + f * (1.0f / 120.0f +
                                                                           f * (1.0f / 720.0f))))));

    union {
        int32_t i;
        float f;
    } scale = { .i = (rounded.i - 0x4B400000 + 127) << 23 };

    return p * scale.f;
}

#endif
