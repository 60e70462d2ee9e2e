// The ISM object's state and the interfaces between its stages' files: the object and the
// frame (ism.c), the maps and gathering (ism_gather.c), the near-field compensation
// (ism_near_field.c) and gathering at a lower resolution (ism_upsample.c). Private to src/ism.
#ifndef DRIFT_ISM_OBJECT_H
#define DRIFT_ISM_OBJECT_H

#include "ism/ism_internal.h"

struct drift_ism {
    drift_context *ctx;
    const drift_scene *scene;
    const drift_accel *accel;
    drift_ism_params params;
    float diagonal;
    drift_points *points;
    uint32_t points_seed; // the seed the points are drawn with: the create's (drift_ism_set_seed)
    uint32_t max_vpls;
    uint32_t map_capacity; // VPLs the atlas and the points hold now (<= max_vpls)
    drift_vpl *vpls;
    uint32_t vpl_count;
    drift_frame *frames;   // max_vpls
    float *atlas;          // map_capacity maps of map_floats, when visibility is ISM
    size_t map_floats;     // one map: map_size^2 depths, then the lazy pyramid's levels
    int32_t lazy_levels;   // pull-push levels the lookups push (1, 2), or 0: pushed at build
    float *disc_counts;    // drift__ism_disc_counts of the lazy pyramid's top level
    float *scratch;        // one pull-push pyramid per thread
    int32_t width, height; // the gathering resolution (the G-buffer's / gather_scale)
    drift_image irradiance, indirect, vpl_plane, tile, near_field, near_spread;
    // gather_scale > 1: the G-buffer and the direct image at one pixel in scale^2, and the
    // blurred irradiance there (what is upsampled).
    drift_gbuffer coarse;
    drift_image coarse_direct, coarse_blurred;
    drift_ism_stats stats;
    float splat_radius; // k sqrt(A_pt / pi) of the last render, world units
    uint32_t *groups;   // group_count + 1 starts of the runs of VPLs of one bounce and round
    uint32_t group_count;
    uint64_t points_print; // vertex_fingerprint when points [0, points_valid) were derived
    uint32_t points_valid;
    bool lights_ready; // vpls and the atlas hold a render's lights (drift_ism_render_slice)
    // This render gathers run `slice` of `slices` of every group of VPLs, at slices times their
    // light (drift_ism_render_slice; 0 of 1 for drift_ism_render).
    uint32_t slice, slices;
};

typedef struct map_job {
    drift_ism *ism;
    drift__ism_splat_desc splat;
    uint32_t empty[DRIFT_MAX_THREADS];    // per thread
    double seconds[DRIFT_MAX_THREADS][2]; // per thread: splatting, pull-push
} map_job;

// Receivers of one gather job, structure of arrays for the vectorised loop over them.
typedef struct receivers {
    float *px, *py, *pz; // position
    float *nx, *ny, *nz; // shading normal
    float *gx, *gy, *gz; // geometric normal (the shadow rays' origin offset)
    float *er, *eg, *eb; // irradiance so far
    int32_t *x, *y;
    int32_t count;
} receivers;

typedef struct gather_job {
    drift_ism *ism;
    const drift_gbuffer *gb;
    uint64_t rays[DRIFT_MAX_THREADS]; // per thread
    float *buffers;                   // per thread: receivers_in of `capacity`
    int32_t capacity;                 // receivers a job can hold
    int32_t subset_rows; // rows of one subset in a band (a band is subset_rows * B rows)
    int32_t bands;
    bool near_field;     // the blur adds the near-field plane
    bool blur_to_coarse; // the blur writes the irradiance to coarse_blurred, not I to indirect
    float *blur_scratch; // per thread: blur_scratch_floats
} gather_job;

// The constants of one render's lookups.
typedef struct gather_consts {
    float dmin2, bias, texel, splat_radius, diagonal;
    float threshold; // pull-push's at level 0
    int32_t n;
    int32_t levels; // the levels the lookups push (drift__ism_lookup)
} gather_consts;

typedef struct decimate_job {
    drift_ism *ism;
    const drift_gbuffer *gb;
    const drift_image *direct; // NULL without the near field
} decimate_job;

// A gather job's receivers: one interleaving subset's pixels in a band of rows. Each map is
// read by all the receivers of a job, VPL after VPL, so the fewer the jobs the fewer times a
// map comes into the cache: on the Breakfast Room (640x480, 417 maps of 256^2) gathering in
// 16x16-receiver tiles cost 1.9x, bands of 12 subset rows 1.3x, 48 rows 1.0x (perf samples).
// At most this many receivers a job (3.6 MB of buffers a thread).
#define GATHER_MAX_RECEIVERS 65536

// Receivers in a buffer of RECEIVER_ARRAYS arrays of `cap` entries (floats, the last two int32).
#define RECEIVER_ARRAYS 14

// Rows a job blurs: its copies hold b - 1 rows more (<= 64 + 3 with block_size <= 64).
#define BLUR_JOB_ROWS 4

// --- THE STAGES (drift_parallel_for jobs and their helpers) ---

// ism_gather.c: one map's splat and pull-push a VPL (`user`: a map_job).
void drift__ism_maps_range(size_t begin, size_t end, int thread, void *user);
// ism_gather.c: interleaved gathering (`user`: a gather_job), and the geometry-aware blur.
void drift__ism_gather_jobs(size_t begin, size_t end, int thread, void *user);
void drift__ism_blur_rows(size_t begin, size_t end, int thread, void *user);
size_t drift__ism_blur_scratch_floats(int32_t width, int32_t block_size);
receivers drift__ism_receivers_in(float *b, size_t cap);
gather_consts drift__ism_gather_consts(const drift_ism *ism);
void drift__ism_gather_vpl(const drift_ism *ism, uint32_t j, const gather_consts *c, receivers *rs,
                           uint64_t *rays);
void drift__ism_group_run(const drift_ism *ism, uint32_t g, uint64_t run, uint64_t runs,
                          uint32_t *first, uint32_t *last);
drift_vec3 drift__ism_block_average(const drift_ism *ism, const drift_gbuffer *gb,
                                    const drift_image *irradiance, int32_t x, int32_t y);
// ism_near_field.c
void drift__ism_add_near_field(drift_ism *ism, const drift_gbuffer *gb, const drift_camera *camera,
                               const drift_image *direct, drift_ism_stats *st);
// ism_upsample.c
void drift__ism_decimate_rows(size_t begin, size_t end, int thread, void *user);
drift_result drift__ism_upsample(drift_ism *ism, const drift_gbuffer *gb, drift_ism_stats *st);

#endif
