// Shadow maps' texels and taps, shared by raster/shadow_map.c (the lookups) and SIR's
// penumbra estimate (sir/penumbra.c), which searches the same texels for blockers. Nothing
// else reads a shadow map's insides: use the lookups of raster/raster.h.
#ifndef DRIFT_SHADOW_MAP_INTERNAL_H
#define DRIFT_SHADOW_MAP_INTERNAL_H

#include "raster/raster.h"

#define CUBE_FACES  6
#define SEARCH_TAPS 16 // PCSS blocker search, a 4 x 4 stratified concentric disk
#define FILTER_TAPS 32 // PCSS filter, an 8 x 4 stratified concentric disk

struct drift_shadow_map {
    bool directional;
    int32_t size;
    float bias_texels;
    float radius;                 // light size L (directional: angular radius, radians)
    drift_vec3 centre;            // cube: where the map looks from
    int8_t face_slot[CUBE_FACES]; // cube: slot of each face in `depth`, -1 when skipped
    uint32_t slot_count;          // faces stored (1 for orthographic maps)
    drift_frame frame;            // orthographic: z = the way light travels
    drift_vec3 origin;            // orthographic: world point of texel corner (0, 0) at depth 0
    float texel_size;             // orthographic: scene units a texel
    float *depth;                 // slot_count * size * size; INFINITY where rays miss
    // Min-depth mip chain of each slot (level k: cells of 2^k x 2^k texels, k = 1 ..
    // mip_levels), so the penumbra estimate can prove a tap region free of blockers with a
    // few reads (see search_level).
    float *min_mip;
    int32_t mip_levels;
    size_t mip_offset[32]; // level k of slot s at min_mip + s * mip_slot + mip_offset[k]
    size_t mip_slot;
    drift_vec2 search_taps[SEARCH_TAPS];
    drift_vec2 filter_taps[FILTER_TAPS];
};

// A lookup's receiver, in the map's own terms. Cube maps take tap offsets as angles along
// t1 and t2 (tangents of the direction, aligned with the face's texel axes); orthographic
// maps as distances along the map's x and y.
typedef struct drift_shadow_receiver {
    drift_vec3 dir;    // cube: unit direction centre -> p
    drift_vec3 t1, t2; // cube: tangent axes of dir
    drift_vec3 n;      // unit normal turned toward the light (map coordinates for ortho)
    float x, y;        // orthographic: position on the map
    float depth;       // cube: distance from the centre; ortho: depth below the near plane
    float texel;       // one texel in offset units (radians or scene units)
    float bias;        // depth bias, scene units
} drift_shadow_receiver;

// What one tap saw: the stored depth, and the receiver plane's depth along the same texel.
typedef struct drift_shadow_tap {
    float stored;
    float receiver;
} drift_shadow_tap;

// Where a tap lands: the texel it reads (face and slot for cube maps) and the depth stored
// there; INFINITY behind a one-sided light or outside an orthographic map.
typedef struct drift_shadow_texel {
    float stored;
    int face;
    int32_t x, y;
} drift_shadow_texel;

static inline float drift_shadow_map_axis(drift_vec3 v, int axis)
{
    return axis == 0 ? v.x : (axis == 1 ? v.y : v.z);
}

// The cube face a direction falls on (0..5 = +x -x +y -y +z -z), and the texel index along a
// face axis of face coordinate u in [-1, 1] (clamped to the face).
int drift_shadow_map_major_face(drift_vec3 d);
int32_t drift_shadow_map_texel_index(float u, int32_t size);
// Least stored depth over texels [x0, x1] x [y0, y1] of a slot (inclusive, in range), read
// from the coarsest min-depth mip level whose cells cover the rectangle in at most four.
float drift_shadow_map_min_depth_rect(const drift_shadow_map *map, int32_t slot, int32_t x0,
                                      int32_t y0, int32_t x1, int32_t y1);
// The receiver at p with normal n in the map's terms.
drift_shadow_receiver drift_shadow_map_receiver(const drift_shadow_map *map, drift_vec3 p,
                                                drift_vec3 n);
// Where a tap at offset (ox, oy) lands, the receiver plane's depth along its texel, both, and
// whether the tap is lit (stored >= receiver - bias).
drift_shadow_texel drift_shadow_map_tap_lands(const drift_shadow_map *map,
                                              const drift_shadow_receiver *rec, float ox, float oy);
float drift_shadow_map_receiver_at(const drift_shadow_map *map, const drift_shadow_receiver *rec,
                                   const drift_shadow_texel *texel);
drift_shadow_tap drift_shadow_map_tap(const drift_shadow_map *map, const drift_shadow_receiver *rec,
                                      float ox, float oy);
bool drift_shadow_map_tap_lit(const drift_shadow_receiver *rec, drift_shadow_tap tap);
// The widest tap region of a lookup, in offset units.
float drift_shadow_map_max_radius(const drift_shadow_map *map);

#endif // DRIFT_SHADOW_MAP_INTERNAL_H
