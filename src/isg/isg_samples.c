// ISG's sample sets: a regular grid passed through the square-to-disk map of Shirley and Chiu
// (the paper's section 4 pattern), or kept as a rectangle for quad lights, and the per-pixel
// rotation or shift that turns one pattern's banding into noise.
#include "isg/isg.h"

#include <math.h>

bool drift_isg_count_valid(int32_t count)
{
    if (count < 1 || count > DRIFT_ISG_MAX_SAMPLES) {
        return false;
    }
    int32_t k = (int32_t)lrint(sqrt((double)count));
    return k * k == count;
}

void drift_isg_pattern_make(uint32_t count, drift_isg_layout layout, drift_isg_pattern *out)
{
    uint32_t k = (uint32_t)lrint(sqrt((double)count));
    out->layout = layout;
    out->count = k * k;
    for (uint32_t j = 0; j < k; ++j) {
        for (uint32_t i = 0; i < k; ++i) {
            drift_vec2 u =
                drift_vec2_make(((float)i + 0.5f) / (float)k, ((float)j + 0.5f) / (float)k);
            out->points[j * k + i] = layout == DRIFT_ISG_DISK
                                         ? drift_sample_disk_concentric(u)
                                         : drift_vec2_make(2.0f * u.x - 1.0f, 2.0f * u.y - 1.0f);
        }
    }
}

drift_isg_jitter drift_isg_jitter_make(uint32_t hash)
{
    float angle = 2.0f * DRIFT_PI * drift_u32_to_unit(hash);
    uint32_t h2 = drift_hash_u32(hash);
    return (drift_isg_jitter){ .cos_a = cosf(angle),
                               .sin_a = sinf(angle),
                               .shift =
                                   drift_vec2_make(drift_u32_to_unit(h2) - 0.5f,
                                                   drift_u32_to_unit(drift_hash_u32(h2)) - 0.5f) };
}

// Interleaved sampling (Keller and Heidrich 2001) over 3 x 3 pixel tiles: the nine pixels of
// a tile take the nine strata of the rotation (and of the shift), so every 3 x 3 window of
// the image, aligned or not, holds each stratum once and its errors nearly cancel there,
// where independent per-pixel rotations leave white noise (stipple). The order within the
// tile is a knight's-move permutation, so that neighbours take strata far apart.
static const uint8_t interleave_order[9] = { 0, 5, 7, 3, 8, 1, 6, 2, 4 };

drift_isg_jitter drift_isg_jitter_at(uint32_t hash, int32_t x, int32_t y)
{
    uint32_t i = (uint32_t)(x % 3 + 3) % 3, j = (uint32_t)(y % 3 + 3) % 3;
    uint32_t h2 = drift_hash_u32(hash);
    // The hash places the strata's points (one offset per seed and light): the strata stay.
    float a = ((float)interleave_order[3 * j + i] + drift_u32_to_unit(hash)) / 9.0f;
    // The grid's disk has the square's four-fold symmetry: angles a quarter turn apart give
    // one pattern, so the strata cover a quarter turn.
    float angle = 0.5f * DRIFT_PI * a;
    float sx = ((float)i + drift_u32_to_unit(h2)) / 3.0f;
    float sy = ((float)j + drift_u32_to_unit(drift_hash_u32(h2))) / 3.0f;
    return (drift_isg_jitter){ .cos_a = cosf(angle),
                               .sin_a = sinf(angle),
                               .shift = drift_vec2_make(sx - 0.5f, sy - 0.5f) };
}

drift_vec2 drift_isg_offset(const drift_isg_pattern *pattern, const drift_isg_jitter *jitter,
                            uint32_t i, drift_vec2 radius)
{
    return drift_isg_offset_inline(pattern, jitter, i, radius);
}
