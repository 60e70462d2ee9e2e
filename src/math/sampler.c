#include "drift/math.h"

#include <stddef.h>

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
                            .sample_reversed = drift_reverse_bits(sample),
                            .cache = NULL };
}

void drift_sampler_cache_init(drift_sampler_cache *cache)
{
    cache->key = 0;
    cache->count = 0;
}

drift_sampler drift_sampler_make_cached(uint32_t seed, uint32_t pixel, uint32_t sample,
                                        drift_sampler_cache *cache)
{
    drift_sampler s = drift_sampler_make(seed, pixel, sample);
    if (cache->key != s.key) {
        cache->key = s.key;
        cache->count = 0;
    }
    s.cache = cache;
    return s;
}

// The scramble seeds of the current dimension pair: the shuffle's, x's and y's; advances the
// dimension. Forced inline: GCC left the older pair_index a call (perf, Cornell box: 3.7% of
// the render's samples in it beside next2's 8.2%).
#if defined(__GNUC__)
#    define PAIR_INLINE static inline __attribute__((always_inline))
#else
#    define PAIR_INLINE static inline
#endif
PAIR_INLINE void pair_seeds(drift_sampler *s, uint32_t seeds[3])
{
    uint32_t d = s->dimension++;
    drift_sampler_cache *c = s->cache;
    if (c && d < c->count) {
        seeds[0] = c->seeds[d][0];
        seeds[1] = c->seeds[d][1];
        seeds[2] = c->seeds[d][2];
        return;
    }
    uint32_t pair_key = drift_hash_combine(s->key, d);
    seeds[0] = pair_key;
    seeds[1] = drift_hash_combine(pair_key, 1);
    seeds[2] = drift_hash_combine(pair_key, 2);
    // Pairs are drawn in order, so a miss is the next entry (or past the end).
    if (c && d == c->count && d < DRIFT_SAMPLER_CACHE_PAIRS) {
        c->seeds[d][0] = seeds[0];
        c->seeds[d][1] = seeds[1];
        c->seeds[d][2] = seeds[2];
        c->count = d + 1;
    }
}

// The sample's index shuffled per dimension pair (Burley §4), so pairs are decorrelated.
PAIR_INLINE uint32_t shuffled_index(const drift_sampler *s, uint32_t shuffle_seed)
{
    return drift_reverse_bits(owen_scramble_reversed(s->sample_reversed, shuffle_seed));
}

drift_vec2 drift_sampler_next2(drift_sampler *s)
{
    uint32_t seeds[3];
    pair_seeds(s, seeds);
    uint32_t index = shuffled_index(s, seeds[0]);
    uint32_t x = owen_scramble_reversed(index, seeds[1]);
    uint32_t y = owen_scramble_reversed(sobol_dim1_reversed(index), seeds[2]);
    return (drift_vec2){ drift_u32_to_unit(drift_reverse_bits(x)),
                         drift_u32_to_unit(drift_reverse_bits(y)) };
}

// The first of next2's pair without the second's scramble: a one-dimensional draw still uses
// (and skips) a whole pair, as it always has, so every later dimension keeps its values.
float drift_sampler_next1(drift_sampler *s)
{
    uint32_t seeds[3];
    pair_seeds(s, seeds);
    uint32_t x = owen_scramble_reversed(shuffled_index(s, seeds[0]), seeds[1]);
    return drift_u32_to_unit(drift_reverse_bits(x));
}

drift_vec2 drift_sampler_next2_random(drift_sampler *s)
{
    uint32_t base = drift_hash_combine(drift_hash_combine(s->key, s->sample), s->dimension++);
    return (drift_vec2){ drift_u32_to_unit(drift_hash_combine(base, 1u)),
                         drift_u32_to_unit(drift_hash_combine(base, 2u)) };
}
