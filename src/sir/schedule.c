// SIR's scheduling (paper §6): the combined error is encoded as a 16-bit key whose ascending
// order is descending error, and a stable LSD radix sort orders the pixels by it (Thrust's
// radix sort in the paper). Stability keeps equal errors in scanline order, which makes the
// refinement order, and so every image along the way, independent of the thread count.
#include "sir/sir.h"

#include <math.h>
#include <string.h>

uint32_t drift_refine_encode_error(float error)
{
    if (!(error > 0.0f)) {
        return DRIFT_REFINE_ZERO_KEY;
    }
    // Any error above zero keeps a key below zero's, however small it is.
    uint32_t q = (uint32_t)lrintf(drift_clampf(error, 0.0f, 1.0f) * 65534.0f);
    return 65534u - (q < 65534u ? q : 65534u);
}

void drift_refine_radix_sort(const uint16_t *keys, uint32_t count, uint32_t *order,
                             uint32_t *scratch)
{
    for (uint32_t i = 0; i < count; ++i) {
        order[i] = i;
    }
    for (int shift = 0; shift < 16; shift += 8) {
        uint32_t histogram[257] = { 0 };
        for (uint32_t i = 0; i < count; ++i) {
            histogram[((keys[order[i]] >> shift) & 0xffu) + 1u]++;
        }
        for (int b = 0; b < 256; ++b) {
            histogram[b + 1] += histogram[b];
        }
        for (uint32_t i = 0; i < count; ++i) {
            scratch[histogram[(keys[order[i]] >> shift) & 0xffu]++] = order[i];
        }
        memcpy(order, scratch, sizeof(uint32_t) * count);
    }
}
