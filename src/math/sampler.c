#include "drift/math.h"

// Burley 2020, §3: Laine-Karras style hash that only lets lower bits affect higher ones;
// applied to bit-reversed values it is a nested uniform (Owen) scramble.
static uint32_t laine_karras_permutation(uint32_t x, uint32_t seed)
{
    x += seed;
    x ^= x * 0x6c50b47cU;
    x ^= x * 0xb82f1e52U;
    x ^= x * 0xc7afe638U;
    x ^= x * 0x8d22f6e6U;
    return x;
}

static uint32_t nested_uniform_scramble(uint32_t x, uint32_t seed)
{
    return drift_reverse_bits(laine_karras_permutation(drift_reverse_bits(x), seed));
}

// First two Sobol dimensions as 32-bit fixed point. Dimension 0 is van der Corput; the
// direction numbers of dimension 1 follow v_i = v_{i-1} ^ (v_{i-1} >> 1).
static uint32_t sobol_dim0(uint32_t index)
{
    return drift_reverse_bits(index);
}

static uint32_t sobol_dim1(uint32_t index)
{
    uint32_t result = 0;
    uint32_t v = 0x80000000U;
    for (; index; index >>= 1, v ^= v >> 1) {
        if (index & 1U) {
            result ^= v;
        }
    }
    return result;
}

drift_sampler drift_sampler_make(uint32_t seed, uint32_t pixel, uint32_t sample)
{
    return (drift_sampler){ .key = drift_hash_combine(drift_hash_u32(seed), pixel),
                            .sample = sample,
                            .dimension = 0 };
}

drift_vec2 drift_sampler_next2(drift_sampler *s)
{
    uint32_t pair_key = drift_hash_combine(s->key, s->dimension++);
    // Shuffle the sample order per dimension pair so pairs are decorrelated (Burley §4).
    uint32_t index = nested_uniform_scramble(s->sample, pair_key);
    uint32_t x = nested_uniform_scramble(sobol_dim0(index), drift_hash_combine(pair_key, 1));
    uint32_t y = nested_uniform_scramble(sobol_dim1(index), drift_hash_combine(pair_key, 2));
    return (drift_vec2){ drift_u32_to_unit(x), drift_u32_to_unit(y) };
}

float drift_sampler_next1(drift_sampler *s)
{
    return drift_sampler_next2(s).x;
}

drift_vec2 drift_sampler_next2_random(drift_sampler *s)
{
    uint32_t base = drift_hash_combine(drift_hash_combine(s->key, s->sample), s->dimension++);
    return (drift_vec2){ drift_u32_to_unit(drift_hash_combine(base, 1u)),
                         drift_u32_to_unit(drift_hash_combine(base, 2u)) };
}
