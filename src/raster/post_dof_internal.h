// The post-process DOF's two files (src/raster/post_dof.c: the circle of confusion, the
// per-pixel gather and the pass; post_dof_tiles.c: the tile classification and the shared-tap
// gather): the job they share and the helpers both use.
#ifndef DRIFT_RASTER_POST_DOF_INTERNAL_H
#define DRIFT_RASTER_POST_DOF_INTERNAL_H

#include "core/vectorise.h"
#include "raster/raster.h"

#include <stddef.h>

typedef struct dof_job {
    const drift_image *in;
    const drift_image *coc;
    drift_image *out;
    const drift_vec2 *taps; // offsets on the unit disk; taps[0] is the centre
    uint32_t tap_count;
    int32_t tiles_x;
    float *tile_lo;      // per UNIFORM_TILE tile: its gathering pixels' smallest circle
    float *tile_radius;  // per tile: its pixels' largest circle
    uint8_t *tile_flat;  // per tile: its pixels all equal its first
    uint8_t *tile_class; // per tile: TILE_COPY, TILE_GATHER or TILE_SHARED
    uint16_t *row_lanes; // per tile row of a TILE_GATHER tile (y * tiles_x + tx): the pixels
                         // (bit i: x = 16 tx + i) gathered with shared taps
    float *local;        // each thread's tile_planes, local_floats apiece
    size_t local_floats;
    // RGB, its indices in int32 and its coordinates under 2^21: the batched gather (with radii
    // up to 2^20 pixels, so that its taps' coordinates stay whole in float arithmetic).
    bool batched;
    bool planes_allowed; // the shared path: channels <= 4, tables up to SHARED_MAX_TAPS
} dof_job;

#define UNIFORM_TILE 16

// The tile classes; the widest circle and the longest table the shared path takes.
enum {
    TILE_GATHER = 0, // per pixel (the batches)
    TILE_COPY = 1,   // every pixel copied
    TILE_SHARED = 2, // every pixel the same taps (post_dof_tiles.c)
};

#define SHARED_MAX_RADIUS 32.0f
#define SHARED_MAX_TAPS   256u // the shared taps live on the stack
// The side of a tile's padded planes at the widest pad (each thread's local buffer).
#define LOCAL_SIDE (UNIFORM_TILE + 2 * ((int32_t)SHARED_MAX_RADIUS + 2))

static inline int32_t clamp_index(int32_t v, int32_t n)
{
    return v < 0 ? 0 : (v >= n ? n - 1 : v);
}

static inline float lerp(float a, float b, float t)
{
    return a + (b - a) * t; // exact when a == b, so a constant image stays constant
}

// Taps for a disk of `radius` pixels: the centre plus a power of two of the stratified set
// (a prefix of 2^k points stays stratified), one per four pixels of the disk's area, at most
// the table: each bilinear tap reads a 2x2 footprint, so together they read about every pixel.
static inline uint32_t taps_for_radius(float radius, uint32_t table_size)
{
    float quarter_area = 0.25f * 3.14159265f * radius * radius;
    uint32_t n = 4;
    while ((float)n < quarter_area && n < table_size - 1) {
        n *= 2;
    }
    return n + 1 < table_size ? n + 1 : table_size;
}

// The tile passes (drift_parallel_for over tiles): each tile's circles and flatness, then its
// class (post_dof_tiles.c).
void drift__post_dof_scan_tiles(size_t begin, size_t end, int thread_index, void *user);
void drift__post_dof_classify_tiles(size_t begin, size_t end, int thread_index, void *user);
// Tile row ty's shared gathers: its TILE_SHARED tiles, and the rows of its TILE_GATHER tiles
// whose circles share, in up to 3 groups a row (row_lanes set for those), each tile's planes
// built in `local`.
void drift__post_dof_shared_band(const dof_job *job, int32_t ty, float *local);

#endif // DRIFT_RASTER_POST_DOF_INTERNAL_H
