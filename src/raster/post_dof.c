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
//
// Tile classification (issue 46; the tiles of production engines' DOF, Jimenez 2014): each
// 16 x 16 tile is copied (every pixel in focus, or the tile and all its gathers read one
// colour), split (the circles of its gathering pixels differ by more than 1.2x + 0.5 px: depth
// edges; each row's pixels in up to 3 groups that share, the rest gathered per pixel), or
// gathered at once: every pixel of the tile takes the same taps, the table scaled by the tile's
// largest circle R, each tap weighed as above and also by whether it lies on the pixel's own disk
// (1 within its radius, 0 a pixel beyond). Same offsets for every pixel make a tap a vector load of
// a row of the tile from the tile's padded planar copy (one bilinear fraction for the whole tile),
// instead of 13 gathered loads (post_dof_tiles.c). The per-pixel gather of every tile stays
// selectable (drift_post_dof_tiles, the post-dof-tiles knob).
#include "raster/post_dof_internal.h"

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
        const uint8_t *class_row =
            job->tile_class + (size_t)(y / UNIFORM_TILE) * (size_t)job->tiles_x;
        const uint16_t *row_lanes = job->row_lanes + (size_t)y * (size_t)job->tiles_x;
        for (int32_t b = 0; b < BUCKETS; ++b) {
            batches[b].n = 0;
        }
        for (int32_t x = 0; x < job->in->width; ++x) {
            int32_t tx = x / UNIFORM_TILE;
            uint8_t tile = class_row[tx];
            if (tile == TILE_SHARED) {
                x = (tx + 1) * UNIFORM_TILE - 1; // dof_bands gathered it
                continue;
            }
            if (tile == TILE_GATHER && ((row_lanes[tx] >> (x - tx * UNIFORM_TILE)) & 1u)) {
                continue; // gathered with shared taps (dof_bands)
            }
            if (tile == TILE_COPY) {
                int32_t n = job->in->width - x < UNIFORM_TILE ? job->in->width - x : UNIFORM_TILE;
                memcpy(drift_image_pixel(job->out, x, y), drift_image_pixel(job->in, x, y),
                       sizeof(float) * (size_t)(n * channels));
                x += n - 1;
                continue;
            }
            float radius = drift_image_pixel(job->coc, x, y)[0];
            const float *src = drift_image_pixel(job->in, x, y);
            float *dst = drift_image_pixel(job->out, x, y);
            // Below half a pixel the disk stays inside the pixel: copy, bit for bit (and
            // NaN or negative radii count as in focus).
            if (!(radius >= 0.5f)) {
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

// A band of tile rows: its shared gathers (post_dof_tiles.c), then its rows' copies and
// per-pixel gathers.
static DRIFT_AVX2_CLONES void dof_bands(size_t begin, size_t end, int thread_index, void *user)
{
    const dof_job *job = user;
    float *local = job->local + (size_t)thread_index * job->local_floats;
    for (size_t ty = begin; ty < end; ++ty) {
        drift__post_dof_shared_band(job, (int32_t)ty, local);
        size_t y0 = ty * UNIFORM_TILE, y1 = y0 + UNIFORM_TILE;
        dof_rows(y0, y1 < (size_t)job->in->height ? y1 : (size_t)job->in->height, thread_index,
                 user);
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
    return drift_post_dof_tiles(ctx, in, coc, taps, true, out);
}

drift_result drift_post_dof_tiles(drift_context *ctx, const drift_image *in, const drift_image *coc,
                                  uint32_t taps, bool shared, drift_image *out)
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
    size_t segments = (size_t)tiles_x * (size_t)in->height;
    float *tile_floats =
        drift_alloc(ctx, tile_count * (2 * sizeof(float) + 2) + segments * sizeof(uint16_t));
    // Each thread's tile planes, for the widest pad.
    bool planes_allowed = shared && in->channels <= 4 && tap_count <= SHARED_MAX_TAPS;
    size_t local_floats = (size_t)(in->channels + 1) * LOCAL_SIDE * LOCAL_SIDE;
    size_t threads = (size_t)drift_context_thread_count(ctx);
    float *local = planes_allowed && tile_floats
                       ? drift_alloc(ctx, sizeof(float) * local_floats * threads)
                       : NULL;
    if (!tile_floats || (planes_allowed && !local)) {
        drift_free(ctx, tile_floats);
        drift_free(ctx, table);
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_OUT_OF_MEMORY, __FILE__, __LINE__,
                  "post dof: out of memory for %zu tiles", tile_count);
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    uint8_t *tile_bytes = (uint8_t *)(tile_floats + 2 * tile_count);
    dof_job job = { .in = in,
                    .coc = coc,
                    .out = out,
                    .taps = table,
                    .tap_count = tap_count,
                    .tiles_x = tiles_x,
                    .tile_lo = tile_floats,
                    .tile_radius = tile_floats + tile_count,
                    .tile_flat = tile_bytes,
                    .tile_class = tile_bytes + tile_count,
                    .row_lanes = (uint16_t *)(void *)(tile_bytes + 2 * tile_count),
                    .local = local,
                    .local_floats = local_floats,
                    .batched = in->channels == 3 && in->width <= (1 << 20) &&
                               in->height <= (1 << 20) &&
                               (double)in->stride * (double)in->height < 2147483647.0 &&
                               (double)coc->stride * (double)coc->height < 2147483647.0,
                    .planes_allowed = planes_allowed };
    drift_parallel_for(ctx, tile_count, 8, drift__post_dof_scan_tiles, &job);
    drift_parallel_for(ctx, tile_count, 64, drift__post_dof_classify_tiles, &job);
    drift_parallel_for(ctx, (size_t)tiles_y, 1, dof_bands, &job);
    drift_free(ctx, local);
    drift_free(ctx, tile_floats);
    drift_free(ctx, table);
    return DRIFT_OK;
}
