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

// First two Sobol dimensions as 32-bit fixed point, bit-reversed (bit i of the value is the
// coefficient of 2^-(i+1)): the form the scramble below takes and gives, so that each value is
// reversed once, not before and after every step. Dimension 0 is van der Corput: the index
// itself. Dimension 1's direction numbers follow v_i = v_{i-1} ^ (v_{i-1} >> 1), so v_i is
// row i of Pascal's triangle mod 2 and, by Lucas' theorem, bit j of the reversed value is the
// parity of the index's set bits i with j a submask of i: a superset-sum transform over the
// five bits of j, five shift-and-xor steps instead of a loop over the index's bits with an
// unpredictable branch each (that loop was a tenth of the path tracer's time).
static uint32_t sobol_dim1_reversed(uint32_t index)
{
    index ^= (index >> 1) & 0x55555555U;
    index ^= (index >> 2) & 0x33333333U;
    index ^= (index >> 4) & 0x0f0f0f0fU;
    index ^= (index >> 8) & 0x00ff00ffU;
    index ^= (index >> 16) & 0x0000ffffU;
    return index;
}

// Nested uniform (Owen) scramble of a value given and returned bit-reversed.
static uint32_t owen_scramble_reversed(uint32_t reversed, uint32_t seed)
{
    return laine_karras_permutation(reversed, seed);
}

drift_sampler drift_sampler_make(uint32_t seed, uint32_t pixel, uint32_t sample)
{
    return (drift_sampler){ .key = drift_hash_combine(drift_hash_u32(seed), pixel),
                            .sample = sample,
                            .dimension = 0,
                            .sample_reversed = drift_reverse_bits(sample) };
}

// The scrambled index of the sample in the current dimension pair (its bits reversed) and the
// pair's key; advances the dimension. Forced inline: GCC left it a call (perf, Cornell box:
// 3.7% of the render's samples in it beside next2's 8.2%).
#if defined(__GNUC__)
#    define PAIR_INDEX_INLINE static inline __attribute__((always_inline))
#else
#    define PAIR_INDEX_INLINE static inline
#endif
PAIR_INDEX_INLINE uint32_t pair_index(drift_sampler *s, uint32_t *out_pair_key)
{
    uint32_t pair_key = drift_hash_combine(s->key, s->dimension++);
    *out_pair_key = pair_key;
    // Shuffle the sample order per dimension pair so pairs are decorrelated (Burley §4).
    return drift_reverse_bits(owen_scramble_reversed(s->sample_reversed, pair_key));
}

drift_vec2 drift_sampler_next2(drift_sampler *s)
{
    uint32_t pair_key;
    uint32_t index = pair_index(s, &pair_key);
    uint32_t x = owen_scramble_reversed(index, drift_hash_combine(pair_key, 1));
    uint32_t y =
        owen_scramble_reversed(sobol_dim1_reversed(index), drift_hash_combine(pair_key, 2));
    return (drift_vec2){ drift_u32_to_unit(drift_reverse_bits(x)),
                         drift_u32_to_unit(drift_reverse_bits(y)) };
}

// The first of next2's pair without the second's scramble: a one-dimensional draw still uses
// (and skips) a whole pair, as it always has, so every later dimension keeps its values.
float drift_sampler_next1(drift_sampler *s)
{
    uint32_t pair_key;
    uint32_t index = pair_index(s, &pair_key);
    uint32_t x = owen_scramble_reversed(index, drift_hash_combine(pair_key, 1));
    return drift_u32_to_unit(drift_reverse_bits(x));
}

drift_vec2 drift_sampler_next2_random(drift_sampler *s)
{
    uint32_t base = drift_hash_combine(drift_hash_combine(s->key, s->sample), s->dimension++);
    return (drift_vec2){ drift_u32_to_unit(drift_hash_combine(base, 1u)),
                         drift_u32_to_unit(drift_hash_combine(base, 2u)) };
}
