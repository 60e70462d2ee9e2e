// Post-process depth of field: the thin lens's circle of confusion per pixel, and the usual
// real-time gather over it.
//
// The gather averages taps on a disk of the pixel's own CoC radius, each weighed by whether
// the tap's own circle reaches the centre (scatter as gather, as real-time engines do it:
// Jimenez 2014): a point is seen at the centre only if its blur spreads that far, so a blurred
// background pixel beside a sharp foreground object leaves the object out (without the weight
// it averaged it in: a bright rim of the in-focus object on the blurred wall, issue 17). The
// artefact kept, because it is what a single-layer gather does: a blurred foreground object's
// edge stays sharp against an in-focus background behind it, since those pixels (circles
// under half a pixel) gather nothing. The reference technique and ISG's DOF have neither.
#include "core/scratch.h"
#include "core/vectorise.h"
#include "raster/raster.h"

#include <math.h>
#include <string.h>

#define DEFAULT_TAPS 64u
#define TAP_SEED     0x6d0f5a3bu // one fixed pattern for every pixel and frame

// --- CIRCLE OF CONFUSION ---

// drift_camera_ray aims every lens ray at the pinhole ray's point at view depth F, so two
// lens points 2A apart see a point at depth z through film points 2 A |z - F| / z scene
// units apart on the focus plane; the focus plane spans 2 F tan(fov_y / 2) over H pixels.
drift_coc_lens drift_coc_lens_make(const drift_camera *camera, int32_t image_height)
{
    drift_coc_lens none = { 0 };
    if (!camera || !(camera->aperture_radius > 0.0f) || image_height <= 0) {
        return none;
    }
    float focus = camera->focus_distance > 0.0f
                      ? camera->focus_distance
                      : drift_vec3_length(drift_vec3_sub(camera->target, camera->position));
    float tan_half = tanf(0.5f * camera->fov_y);
    if (!(focus > 0.0f) || !(tan_half > 0.0f)) {
        return none;
    }
    return (drift_coc_lens){ .aperture = camera->aperture_radius,
                             .focus = focus,
                             .pixels_per_unit = (float)image_height / (2.0f * focus * tan_half) };
}

float drift_coc_radius_pixels(const drift_camera *camera, int32_t image_height, float z)
{
    drift_coc_lens lens = drift_coc_lens_make(camera, image_height);
    return drift_coc_lens_radius(&lens, z);
}

// --- GATHER ---

typedef struct dof_job {
    const drift_image *in;
    const drift_image *coc;
    drift_image *out;
    const drift_vec2 *taps; // offsets on the unit disk; taps[0] is the centre
    uint32_t tap_count;
    uint8_t *uniform; // per UNIFORM_TILE tile: every pixel its gathers read is alike
    int32_t *run;     // per pixel: the run of equal pixels from it rightwards (equal_runs)
    int32_t tiles_x;
    // RGB, its indices in int32 and its coordinates under 2^21: the batched gather (with radii
    // up to 2^20 pixels, so that its taps' coordinates stay whole in float arithmetic).
    bool batched;
} dof_job;

#define UNIFORM_TILE 16

// The centre, then the concentric-disk image of a scrambled Sobol (0,2)-sequence: its first
// 2^k points are stratified over [0,1)^2, so the taps cover the disk evenly.
static void make_taps(drift_vec2 *taps, uint32_t count)
{
    taps[0] = drift_vec2_make(0.0f, 0.0f);
    for (uint32_t k = 1; k < count; ++k) {
        drift_sampler s = drift_sampler_make(TAP_SEED, 0, k - 1);
        taps[k] = drift_sample_disk_concentric(drift_sampler_next2(&s));
    }
}

static int32_t clamp_index(int32_t v, int32_t n)
{
    return v < 0 ? 0 : (v >= n ? n - 1 : v);
}

static float lerp(float a, float b, float t)
{
    return a + (b - a) * t; // exact when a == b, so a constant image stays constant
}

// Bilinear fetch at (x, y) in pixel-centre units (pixel p's centre at p), clamped to the image.
static inline void fetch_bilinear(const drift_image *image, float x, float y, float *out,
                                  const int32_t channels)
{
    float x0f = floorf(x), y0f = floorf(y);
    float fx = x - x0f, fy = y - y0f;
    int32_t xa = clamp_index((int32_t)x0f, image->width);
    int32_t xb = clamp_index((int32_t)x0f + 1, image->width);
    int32_t ya = clamp_index((int32_t)y0f, image->height);
    int32_t yb = clamp_index((int32_t)y0f + 1, image->height);
    const float *p00 = drift_image_pixel(image, xa, ya), *p10 = drift_image_pixel(image, xb, ya);
    const float *p01 = drift_image_pixel(image, xa, yb), *p11 = drift_image_pixel(image, xb, yb);
    for (int32_t c = 0; c < channels; ++c) {
        out[c] = lerp(lerp(p00[c], p10[c], fx), lerp(p01[c], p11[c], fx), fy);
    }
}

// Taps for a disk of `radius` pixels: the centre plus a power of two of the stratified set
// (a prefix of 2^k points stays stratified), one per four pixels of the disk's area, at most
// the table: each bilinear tap reads a 2x2 footprint, so together they read about every pixel.
static uint32_t taps_for_radius(float radius, uint32_t table_size)
{
    float quarter_area = 0.25f * 3.14159265f * radius * radius;
    uint32_t n = 4;
    while ((float)n < quarter_area && n < table_size - 1) {
        n *= 2;
    }
    return n + 1 < table_size ? n + 1 : table_size;
}

// How much a tap `distance` pixels from the centre is seen there: 1 where its own circle of
// confusion (at the nearest pixel) reaches the centre, 0 where it falls a pixel or more
// short, linear between, so the weight does not switch on a sub-pixel change of depth.
static inline float tap_weight(const drift_image *coc, float tx, float ty, float distance)
{
    int32_t px = clamp_index((int32_t)floorf(tx + 0.5f), coc->width);
    int32_t py = clamp_index((int32_t)floorf(ty + 0.5f), coc->height);
    float reach = drift_image_pixel(coc, px, py)[0];
    return reach >= 0.0f ? drift_clampf(reach - distance + 1.0f, 0.0f, 1.0f) : 0.0f;
}

// Summing weighted differences from the centre pixel keeps a flat region exactly flat (a
// float sum of 64 equal values would not return the value). Inlined with a constant channel
// count for RGB, so the channel loops unroll.
static inline void gather(const dof_job *job, int32_t x, int32_t y, float radius, float *out,
                          const int32_t channels)
{
    const float *centre = drift_image_pixel(job->in, x, y);
    float sum[4] = { 0.0f, 0.0f, 0.0f, 0.0f }, tap[4];
    float total = 1.0f; // the centre: its own circle reaches it
    uint32_t tap_count = taps_for_radius(radius, job->tap_count);
    for (uint32_t k = 1; k < tap_count; ++k) {
        float ox = job->taps[k].x * radius, oy = job->taps[k].y * radius;
        float tx = (float)x + ox, ty = (float)y + oy;
        float weight = tap_weight(job->coc, tx, ty, sqrtf(ox * ox + oy * oy));
        if (!(weight > 0.0f)) {
            continue;
        }
        fetch_bilinear(job->in, tx, ty, tap, channels);
        for (int32_t c = 0; c < channels; ++c) {
            sum[c] += weight * (tap[c] - centre[c]);
        }
        total += weight;
    }
    float inv = 1.0f / total;
    for (int32_t c = 0; c < channels; ++c) {
        out[c] = centre[c] + sum[c] * inv;
    }
}

// The RGB gather of up to BATCH pixels of row y with the same tap count, one pixel a vector
// lane: one loop a tap over the pixels, branch-free (docs/decisions/0028), the bilinear
// corners and the circles read by gathers. Each pixel does gather()'s operations in its order,
// a weightless tap left out by a select instead of a branch (it is fetched, at a clamped,
// valid address, and not added): the same image to the bit.
#define BATCH 64

typedef struct dof_batch {
    int32_t n;
    uint32_t taps;
    float x[BATCH], radius[BATCH];
} dof_batch;

// clamp_index((int32_t)v, n) for a whole v under 2^22 in magnitude, without a conversion: GCC
// 12 does not vectorise an int index made by a conversion and a select (docs/decisions/0028),
// so the clamp is in float and the bits of v + 1.5 * 2^23 give the integer.
static inline int32_t clamp_lane(float v, float last)
{
    v = v < 0.0f ? 0.0f : v;
    v = v > last ? last : v;
    float biased = v + 12582912.0f;
    int32_t bits;
    memcpy(&bits, &biased, sizeof bits);
    return bits - 0x4B400000;
}

static DRIFT_AVX2_CLONES void post_dof_gather_batch(const dof_job *job, int32_t y,
                                                    const dof_batch *batch)
{
    const drift_image *in = job->in, *coc = job->coc;
    const float *restrict pix = in->pixels, *restrict reach_plane = coc->pixels;
    const int32_t stride = (int32_t)in->stride;
    const float w = (float)(in->width - 1), h = (float)(in->height - 1); // the last pixel
    const int32_t coc_stride = (int32_t)coc->stride, coc_channels = coc->channels;
    const int32_t n = batch->n;
    const float yf = (float)y;
    float c0[BATCH], c1[BATCH], c2[BATCH], s0[BATCH], s1[BATCH], s2[BATCH], total[BATCH];
    float xs[BATCH], radii[BATCH];
    for (int32_t i = 0; i < n; ++i) {
        xs[i] = batch->x[i];
        radii[i] = batch->radius[i];
        const float *centre = drift_image_pixel(in, (int32_t)batch->x[i], y);
        c0[i] = centre[0];
        c1[i] = centre[1];
        c2[i] = centre[2];
        s0[i] = s1[i] = s2[i] = 0.0f;
        total[i] = 1.0f; // the centre: its own circle reaches it
    }
    for (uint32_t k = 1; k < batch->taps; ++k) {
        const float dx = job->taps[k].x, dy = job->taps[k].y;
        DRIFT_IVDEP
        for (int32_t i = 0; i < n; ++i) {
            float radius = radii[i];
            float ox = dx * radius, oy = dy * radius;
            float tx = xs[i] + ox, ty = yf + oy;
            // tap_weight
            int32_t px = clamp_lane(floorf(tx + 0.5f), w);
            int32_t py = clamp_lane(floorf(ty + 0.5f), h);
            float reach = reach_plane[py * coc_stride + px * coc_channels];
            float v = reach - sqrtf(ox * ox + oy * oy) + 1.0f;
            v = v < 0.0f ? 0.0f : (v > 1.0f ? 1.0f : v);
            float weight = reach >= 0.0f ? v : 0.0f;
            // fetch_bilinear
            float x0f = floorf(tx), y0f = floorf(ty);
            float fx = tx - x0f, fy = ty - y0f;
            int32_t xa = clamp_lane(x0f, w) * 3, xb = clamp_lane(x0f + 1.0f, w) * 3;
            int32_t ya = clamp_lane(y0f, h) * stride, yb = clamp_lane(y0f + 1.0f, h) * stride;
            float t0 = lerp(lerp(pix[ya + xa], pix[ya + xb], fx),
                            lerp(pix[yb + xa], pix[yb + xb], fx), fy);
            float t1 = lerp(lerp(pix[ya + xa + 1], pix[ya + xb + 1], fx),
                            lerp(pix[yb + xa + 1], pix[yb + xb + 1], fx), fy);
            float t2 = lerp(lerp(pix[ya + xa + 2], pix[ya + xb + 2], fx),
                            lerp(pix[yb + xa + 2], pix[yb + xb + 2], fx), fy);
            // A weightless tap adds exact zeros (a sum here is never -0: it starts at +0, and
            // a sum of two floats is -0 only when both are), its difference zeroed first so
            // that an infinite or NaN tap cannot leak in: what skipping it does.
            bool on = weight > 0.0f;
            float ws = on ? weight : 0.0f;
            float d0 = on ? t0 - c0[i] : 0.0f, d1 = on ? t1 - c1[i] : 0.0f;
            float d2 = on ? t2 - c2[i] : 0.0f;
            s0[i] += ws * d0;
            s1[i] += ws * d1;
            s2[i] += ws * d2;
            total[i] += ws;
        }
    }
    for (int32_t i = 0; i < n; ++i) {
        float inv = 1.0f / total[i];
        float *out = drift_image_pixel(job->out, (int32_t)batch->x[i], y);
        out[0] = c0[i] + s0[i] * inv;
        out[1] = c1[i] + s1[i] * inv;
        out[2] = c2[i] + s2[i] * inv;
    }
}

// Whether every pixel the gathers of tile (tx, ty) can read holds the same value. Each
// gather then returns its centre exactly (it sums differences from the centre), so the tile
// is copied instead: the background of a frame, with the largest circle of confusion and a
// single colour, costs a scan instead of a gather.
static bool tile_is_uniform(const dof_job *job, int32_t tx, int32_t ty)
{
    const drift_image *in = job->in;
    int32_t x0 = tx * UNIFORM_TILE, y0 = ty * UNIFORM_TILE;
    int32_t x1 = x0 + UNIFORM_TILE < in->width ? x0 + UNIFORM_TILE : in->width;
    int32_t y1 = y0 + UNIFORM_TILE < in->height ? y0 + UNIFORM_TILE : in->height;
    float reach = 0.0f;
    for (int32_t y = y0; y < y1; ++y) {
        for (int32_t x = x0; x < x1; ++x) {
            reach = fmaxf(reach, drift_image_pixel(job->coc, x, y)[0]); // fmaxf drops NaN
        }
    }
    // A tap lands within the radius; its bilinear fetch reads one pixel further.
    int32_t pad = (int32_t)ceilf(fminf(reach, (float)(in->width + in->height))) + 1;
    // Each row of the region: its first pixel equals the tile's first, and so do the ones
    // after it (the run of equal pixels from there spans the region). Float == per channel, as
    // a scan would compare: -0 equals +0, NaN nothing, so equal runs are all equal to their
    // first pixel.
    const float *first = drift_image_pixel(in, x0, y0);
    int32_t xa = clamp_index(x0 - pad, in->width), xb = clamp_index(x1 - 1 + pad, in->width);
    for (int32_t y = clamp_index(y0 - pad, in->height); y <= clamp_index(y1 - 1 + pad, in->height);
         ++y) {
        const float *p = drift_image_pixel(in, xa, y);
        for (int32_t c = 0; c < in->channels; ++c) {
            if (p[c] != first[c]) {
                return false;
            }
        }
        if (job->run[(size_t)y * (size_t)in->width + (size_t)xa] < xb - xa + 1) {
            return false;
        }
    }
    return true;
}

// run[y][x]: how many pixels from (x, y) rightwards equal their left neighbour, itself
// included (tile_is_uniform's rows).
static void equal_runs(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    const dof_job *job = user;
    const drift_image *in = job->in;
    for (int32_t y = (int32_t)begin; y < (int32_t)end; ++y) {
        int32_t *run = job->run + (size_t)y * (size_t)in->width;
        run[in->width - 1] = 1;
        for (int32_t x = in->width - 2; x >= 0; --x) {
            const float *p = drift_image_pixel(in, x, y), *q = p + in->channels;
            bool same = true;
            for (int32_t c = 0; c < in->channels; ++c) {
                same = same && p[c] == q[c];
            }
            run[x] = same ? run[x + 1] + 1 : 1;
        }
    }
}

static DRIFT_AVX2_CLONES void classify_tiles(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    const dof_job *job = user;
    for (size_t t = begin; t < end; ++t) {
        job->uniform[t] = tile_is_uniform(job, (int32_t)(t % (size_t)job->tiles_x),
                                          (int32_t)(t / (size_t)job->tiles_x));
    }
}

// Cloned for AVX2: floorf is one instruction there and sqrtf needs no errno (the file is built
// with -fno-math-errno): 1.3x, the same image. RGB pixels that gather wait in batches by tap
// count (a power of two plus one, or the table: one batch for each), so a batch's lanes run
// the same taps.
static DRIFT_AVX2_CLONES void dof_rows(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    const dof_job *job = user;
    int32_t channels = job->in->channels;

    enum {
        BUCKETS = 32
    };

    dof_batch batches[BUCKETS];
    for (int32_t y = (int32_t)begin; y < (int32_t)end; ++y) {
        const uint8_t *uniform_row =
            job->uniform + (size_t)(y / UNIFORM_TILE) * (size_t)job->tiles_x;
        for (int32_t b = 0; b < BUCKETS; ++b) {
            batches[b].n = 0;
        }
        for (int32_t x = 0; x < job->in->width; ++x) {
            float radius = drift_image_pixel(job->coc, x, y)[0];
            const float *src = drift_image_pixel(job->in, x, y);
            float *dst = drift_image_pixel(job->out, x, y);
            // Below half a pixel the disk stays inside the pixel: copy, bit for bit (and
            // NaN or negative radii count as in focus). A uniform tile copies too (above).
            if (!(radius >= 0.5f) || uniform_row[x / UNIFORM_TILE]) {
                for (int32_t c = 0; c < channels; ++c) {
                    dst[c] = src[c];
                }
                continue;
            }
            if (!job->batched || !(radius <= 1048576.0f)) {
                gather(job, x, y, radius, dst, channels); // the batches' bounds, below
                continue;
            }
            uint32_t taps = taps_for_radius(radius, job->tap_count);
            int32_t b = 0; // floor(log2(taps)): one count a bucket for the default table
            while (b < BUCKETS - 1 && (2u << b) <= taps) {
                ++b;
            }
            dof_batch *batch = &batches[b];
            if (batch->n > 0 && batch->taps != taps) { // another table's counts can share it
                post_dof_gather_batch(job, y, batch);
                batch->n = 0;
            }
            batch->taps = taps;
            batch->x[batch->n] = (float)x;
            batch->radius[batch->n] = radius;
            if (++batch->n == BATCH) {
                post_dof_gather_batch(job, y, batch);
                batch->n = 0;
            }
        }
        for (int32_t b = 0; b < BUCKETS; ++b) {
            if (batches[b].n > 0) {
                post_dof_gather_batch(job, y, &batches[b]);
            }
        }
    }
}

static drift_result check_dof_args(drift_context *ctx, const drift_image *in,
                                   const drift_image *coc, uint32_t taps, const drift_image *out)
{
    const char *why = NULL;
    if (!drift_image_is_valid(in) || !drift_image_is_valid(coc) || !drift_image_is_valid(out)) {
        why = "an image is missing or invalid";
    } else if (out->width != in->width || out->height != in->height ||
               out->channels != in->channels) {
        why = "out must have the size and channels of in";
    } else if (coc->width != in->width || coc->height != in->height) {
        why = "the circle-of-confusion image must have the size of in";
    } else if (out->pixels == in->pixels || out->pixels == coc->pixels) {
        why = "out must not be in or coc";
    } else if (taps > DRIFT_POST_DOF_MAX_TAPS) {
        why = "too many taps";
    }
    if (why) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, __FILE__, __LINE__,
                  "post dof: %s", why);
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    return DRIFT_OK;
}

drift_result drift_post_dof(drift_context *ctx, const drift_image *in, const drift_image *coc,
                            uint32_t taps, drift_image *out)
{
    drift_result r = check_dof_args(ctx, in, coc, taps, out);
    if (r != DRIFT_OK) {
        return r;
    }
    uint32_t tap_count = taps == 0 ? DEFAULT_TAPS : taps;
    drift_vec2 *table = drift_alloc(ctx, sizeof(drift_vec2) * tap_count);
    if (!table) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_OUT_OF_MEMORY, __FILE__, __LINE__,
                  "post dof: out of memory for %u taps", tap_count);
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    make_taps(table, tap_count);
    int32_t tiles_x = (in->width + UNIFORM_TILE - 1) / UNIFORM_TILE;
    int32_t tiles_y = (in->height + UNIFORM_TILE - 1) / UNIFORM_TILE;
    size_t tile_count = (size_t)tiles_x * (size_t)tiles_y;
    uint8_t *uniform = drift_alloc(ctx, tile_count);
    // The runs in the context's scratch block (kept between calls: no fresh pages each frame).
    size_t run_bytes = (size_t)in->width * (size_t)in->height * sizeof(int32_t), have = 0;
    int32_t *run = uniform ? drift__scratch_take(ctx, run_bytes, &have) : NULL;
    if (!run) {
        drift_free(ctx, uniform);
        drift_free(ctx, table);
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_OUT_OF_MEMORY, __FILE__, __LINE__,
                  "post dof: out of memory for %zu tiles", tile_count);
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    dof_job job = { .in = in,
                    .coc = coc,
                    .out = out,
                    .taps = table,
                    .tap_count = tap_count,
                    .uniform = uniform,
                    .run = run,
                    .tiles_x = tiles_x,
                    .batched = in->channels == 3 && in->width <= (1 << 20) &&
                               in->height <= (1 << 20) &&
                               (double)in->stride * (double)in->height < 2147483647.0 &&
                               (double)coc->stride * (double)coc->height < 2147483647.0 };
    drift_parallel_for(ctx, (size_t)in->height, 8, equal_runs, &job);
    drift_parallel_for(ctx, tile_count, 1, classify_tiles, &job);
    drift_parallel_for(ctx, (size_t)in->height, 1, dof_rows, &job);
    drift__scratch_give(ctx, run, have);
    drift_free(ctx, uniform);
    drift_free(ctx, table);
    return DRIFT_OK;
}
