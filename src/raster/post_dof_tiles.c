// Post DOF's tiles (issue 46): each 16 x 16 tile's circles of confusion and flatness, its
// class (copied, gathered per pixel, or gathered with shared taps), and the shared gather: every
// pixel of a tile the same taps, the table scaled by the tile's largest circle, each tap weighed
// by its own circle reaching the centre (as the per-pixel gather does) and by its place on the
// pixel's own disk, read as vector loads of a row of the tile from its padded planar copy.
#include "raster/post_dof_internal.h"

#include <math.h>
#include <string.h>

// A tile whose gathering pixels' circles lie within [lo, 1.2 lo + 0.5] shares its taps: a pixel
// of radius r then keeps r^2 / R^2 >= 1/5 of the R disk's taps (about its own disk's count: one
// a four pixels either way, up to the table's size), and its disk's soft edge (a pixel wide,
// where the per-pixel disk stops at r) stays close to its own. Wider spreads are the depth
// edges, gathered per pixel. NaN and negative circles (copied pixels) do not count. [lo, 1.5 lo
// + 1] was as fast on the bench frame and raised the relMSE against the path tracer by a fifth
// where a bright light's edge blurs (docs/lab/2026-12-08-issue-46-s8-dof.md).
static bool circles_share(float lo, float hi)
{
    return hi <= 1.2f * lo + 0.5f && hi <= SHARED_MAX_RADIUS;
}

// Per tile: its gathering pixels' smallest circle, the largest circle of any pixel (how far
// its gathers read; 0 when none is positive), and whether its pixels all equal its first one
// (float == per channel: -0 equals +0, NaN nothing).
// (The entry points below are plain functions over file-local clones: clang 14 emits a
// target_clones function's resolver only in the files that call it, so an extern clone
// called from post_dof.c did not link; decision 0460.)
static DRIFT_AVX2_CLONES void scan_tiles(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;

    enum {
        N = UNIFORM_TILE
    };

    const dof_job *job = user;
    const drift_image *in = job->in;
    const int32_t channels = in->channels, step = job->coc->channels;
    // Per column (per float of a row): elementwise, so the loops vectorise (a conditional
    // min reduction does not, without -ffast-math).
    float first[N * 4], lo_lane[N], hi_lane[N];
    int32_t differ[N * 4];
    for (size_t t = begin; t < end; ++t) {
        int32_t x0 = (int32_t)(t % (size_t)job->tiles_x) * UNIFORM_TILE;
        int32_t y0 = (int32_t)(t / (size_t)job->tiles_x) * UNIFORM_TILE;
        int32_t n = in->width - x0 < N ? in->width - x0 : N;
        int32_t y1 = y0 + N < in->height ? y0 + N : in->height;
        const float *origin = drift_image_pixel(in, x0, y0);
        for (int32_t k = 0; k < N * 4; ++k) {
            first[k] = origin[k % channels];
            differ[k] = 0;
        }
        for (int32_t i = 0; i < N; ++i) {
            lo_lane[i] = HUGE_VALF;
            hi_lane[i] = 0.0f;
        }
        for (int32_t y = y0; y < y1; ++y) {
            const float *restrict row = drift_image_pixel(in, x0, y);
            const float *restrict reach = drift_image_pixel(job->coc, x0, y);
            if (n == N && step == 1) {
                for (int32_t i = 0; i < N; ++i) {
                    float r = reach[i], low = r >= 0.5f ? r : HUGE_VALF;
                    lo_lane[i] = low < lo_lane[i] ? low : lo_lane[i];
                    hi_lane[i] = r > hi_lane[i] ? r : hi_lane[i];
                }
            } else {
                for (int32_t i = 0; i < n; ++i) {
                    float r = reach[i * step], low = r >= 0.5f ? r : HUGE_VALF;
                    lo_lane[i] = low < lo_lane[i] ? low : lo_lane[i];
                    hi_lane[i] = r > hi_lane[i] ? r : hi_lane[i];
                }
            }
            if (n == N && channels == 3) {
                for (int32_t k = 0; k < N * 3; ++k) {
                    differ[k] |= row[k] != first[k];
                }
            } else {
                for (int32_t k = 0; k < n * channels; ++k) {
                    differ[k] |= row[k] != first[k];
                }
            }
        }
        float lo = HUGE_VALF, hi = 0.0f;
        int32_t any = 0;
        for (int32_t i = 0; i < N; ++i) {
            lo = lo_lane[i] < lo ? lo_lane[i] : lo;
            hi = hi_lane[i] > hi ? hi_lane[i] : hi;
        }
        for (int32_t k = 0; k < N * 4; ++k) {
            any |= differ[k];
        }
        job->tile_lo[t] = lo;
        job->tile_radius[t] = hi;
        job->tile_flat[t] = !any;
    }
}

// A tile is copied when every pixel its gathers can read holds one value: each gather would
// return its centre (it sums differences from the centre). Checked by whole tiles: every tile
// the padded tile meets is flat and starts with the same value (a tap lands within the
// largest radius; its bilinear fetch reads one pixel further). Also copied: tiles without a
// gathering pixel. Then the shared tiles (circles_share), and the rest per pixel.
void drift__post_dof_classify_tiles(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    const dof_job *job = user;
    const drift_image *in = job->in;
    for (size_t t = begin; t < end; ++t) {
        int32_t tx = (int32_t)(t % (size_t)job->tiles_x), ty = (int32_t)(t / (size_t)job->tiles_x);
        float hi = job->tile_radius[t];
        int32_t pad = (int32_t)ceilf(fminf(hi, (float)(in->width + in->height))) + 1;
        int32_t x0 = tx * UNIFORM_TILE, y0 = ty * UNIFORM_TILE;
        int32_t ua = clamp_index(x0 - pad, in->width) / UNIFORM_TILE;
        int32_t ub = clamp_index(x0 + UNIFORM_TILE - 1 + pad, in->width) / UNIFORM_TILE;
        int32_t va = clamp_index(y0 - pad, in->height) / UNIFORM_TILE;
        int32_t vb = clamp_index(y0 + UNIFORM_TILE - 1 + pad, in->height) / UNIFORM_TILE;
        const float *first = drift_image_pixel(in, x0, y0);
        bool uniform = true;
        for (int32_t v = va; uniform && v <= vb; ++v) {
            for (int32_t u = ua; uniform && u <= ub; ++u) {
                const float *q = drift_image_pixel(in, u * UNIFORM_TILE, v * UNIFORM_TILE);
                uniform = job->tile_flat[(size_t)v * (size_t)job->tiles_x + (size_t)u];
                for (int32_t c = 0; c < in->channels; ++c) {
                    uniform = uniform && q[c] == first[c];
                }
            }
        }
        bool copy = uniform || !(hi >= 0.5f);
        bool shared = job->planes_allowed && circles_share(job->tile_lo[t], hi);
        job->tile_class[t] = copy ? TILE_COPY : (shared ? TILE_SHARED : TILE_GATHER);
    }
}

// A tile's padded planar copy: channels planes then the circles, each `size` rows of `stride`
// floats (the tile and `pad` pixels each side), the nearest pixel repeated outside the frame
// (what the clamped fetches read). Small enough to stay in the first-level cache and its
// pages in the TLB (a frame-wide copy had each tap's rows on other pages: 1.6x slower).
typedef struct tile_planes {
    float *planes;
    int32_t x0, y0, pad, stride;
    size_t plane;
} tile_planes;

static inline void fill_tile_planes(const dof_job *job, tile_planes *tp, const int32_t channels)
{
    const drift_image *in = job->in;
    const int32_t side = UNIFORM_TILE + 2 * tp->pad, step = job->coc->channels;
    int32_t xs[LOCAL_SIDE];
    for (int32_t lx = 0; lx < side; ++lx) {
        xs[lx] = clamp_index(tp->x0 - tp->pad + lx, in->width);
    }
    for (int32_t ly = 0; ly < side; ++ly) {
        int32_t y = clamp_index(tp->y0 - tp->pad + ly, in->height);
        const float *restrict src = drift_image_pixel(in, 0, y);
        const float *restrict reach = drift_image_pixel(job->coc, 0, y);
        float *restrict row = tp->planes + (size_t)ly * (size_t)tp->stride;
        if (xs[0] == tp->x0 - tp->pad && xs[side - 1] == tp->x0 - tp->pad + side - 1 &&
            step == 1) { // inside the frame: a plain deinterleave, vectorised
            const float *restrict from = src + (size_t)xs[0] * (size_t)channels;
            float *restrict to[5];
            for (int32_t c = 0; c <= channels; ++c) {
                to[c] = row + (size_t)c * tp->plane;
            }
            for (int32_t lx = 0; lx < side; ++lx) {
                for (int32_t c = 0; c < channels; ++c) {
                    to[c][lx] = from[lx * channels + c];
                }
            }
            memcpy(to[channels], reach + xs[0], sizeof(float) * (size_t)side);
            continue;
        }
        for (int32_t lx = 0; lx < side; ++lx) {
            const float *p = src + (size_t)xs[lx] * (size_t)channels;
            for (int32_t c = 0; c < channels; ++c) {
                row[(size_t)c * tp->plane + (size_t)lx] = p[c];
            }
            row[(size_t)channels * tp->plane + (size_t)lx] = reach[(size_t)xs[lx] * (size_t)step];
        }
    }
}

// Sets up and fills tp for tile (tx, ty) with room for circles up to `radius`.
static DRIFT_AVX2_CLONES void tile_planes_make(const dof_job *job, int32_t tx, int32_t ty,
                                               float radius, float *buffer, tile_planes *tp)
{
    tp->planes = buffer;
    tp->x0 = tx * UNIFORM_TILE;
    tp->y0 = ty * UNIFORM_TILE;
    tp->pad = (int32_t)ceilf(radius) + 2; // a pixel for the bilinear corner, one to spare
    tp->stride = UNIFORM_TILE + 2 * tp->pad;
    tp->plane = (size_t)tp->stride * (size_t)tp->stride;
    switch (job->in->channels) {
    case 1:
        fill_tile_planes(job, tp, 1);
        break;
    case 2:
        fill_tile_planes(job, tp, 2);
        break;
    case 3:
        fill_tile_planes(job, tp, 3);
        break;
    default:
        fill_tile_planes(job, tp, 4);
        break;
    }
}

// One tap of a shared tile: its offsets in the planes (nearest pixel, bilinear corner), the
// bilinear fractions and its distance from the centre, the same for every pixel of the tile.
typedef struct shared_tap {
    ptrdiff_t near, corner;
    float fx, fy, distance;
} shared_tap;

// The shared gather of tile row y (pixels x0 .. x0 + n - 1, n <= UNIFORM_TILE), `channels`
// constant once inlined: gather()'s sums (differences from the centre, weighed; a weightless
// tap adds exact zeros), each tap's weight times its place on the pixel's own disk.
static inline void shared_row(const dof_job *job, const tile_planes *tp, int32_t y,
                              const shared_tap *taps, uint32_t tap_count, uint32_t lanes,
                              const int32_t channels)
{
    enum {
        N = UNIFORM_TILE
    };

    const int32_t stride = tp->stride, x0 = tp->x0;
    const size_t plane = tp->plane;
    const size_t at = (size_t)(y - tp->y0 + tp->pad) * (size_t)stride + (size_t)tp->pad;
    const float *restrict reach_at = tp->planes + (size_t)channels * plane + at;
    float radius[N], centre[4][N], sum[4][N], total[N];
    // All N lanes, past the frame's right edge too (the planes hold whole tiles); only the
    // frame's pixels are written.
    for (int32_t i = 0; i < N; ++i) {
        radius[i] = reach_at[i];
        for (int32_t c = 0; c < channels; ++c) {
            centre[c][i] = tp->planes[(size_t)c * plane + at + (size_t)i];
            sum[c][i] = 0.0f;
        }
        total[i] = 1.0f; // the centre: its own circle reaches it
    }
    for (uint32_t k = 0; k < tap_count; ++k) {
        const shared_tap tap = taps[k];
        const float *restrict reach = reach_at + tap.near;
        const float *restrict corner[4];
        for (int32_t c = 0; c < channels; ++c) {
            corner[c] = tp->planes + (size_t)c * plane + at + tap.corner;
        }
        DRIFT_IVDEP
        for (int32_t i = 0; i < N; ++i) {
            float v = reach[i] - tap.distance + 1.0f;
            v = v < 0.0f ? 0.0f : (v > 1.0f ? 1.0f : v);
            float own = radius[i] - tap.distance + 1.0f;
            own = own < 0.0f ? 0.0f : (own > 1.0f ? 1.0f : own);
            float weight = reach[i] >= 0.0f ? v * own : 0.0f;
            bool on = weight > 0.0f;
            float ws = on ? weight : 0.0f;
            for (int32_t c = 0; c < channels; ++c) {
                const float *p = corner[c] + i;
                float t =
                    lerp(lerp(p[0], p[1], tap.fx), lerp(p[stride], p[stride + 1], tap.fx), tap.fy);
                float d = on ? t - centre[c][i] : 0.0f;
                sum[c][i] += ws * d;
            }
            total[i] += ws;
        }
    }
    float result[4][N];
    for (int32_t i = 0; i < N; ++i) {
        float inv = 1.0f / total[i];
        for (int32_t c = 0; c < channels; ++c) {
            result[c][i] = centre[c][i] + sum[c][i] * inv;
        }
    }
    int32_t n = job->in->width - x0 < N ? job->in->width - x0 : N;
    const float *src = drift_image_pixel(job->in, x0, y);
    float *dst = drift_image_pixel(job->out, x0, y);
    for (int32_t i = 0; i < n; ++i) {
        if (!((lanes >> i) & 1u)) {
            continue; // another group's, or the per-pixel gather's
        }
        // Below half a pixel (or NaN) the pixel is copied, as everywhere.
        bool gathers = radius[i] >= 0.5f;
        for (int32_t c = 0; c < channels; ++c) {
            dst[i * channels + c] = gathers ? result[c][i] : src[i * channels + c];
        }
    }
}

// The taps of a shared gather of the largest circle `radius`: the table's first
// taps_for_radius(radius) scaled by it, the centre left out; their count.
static uint32_t shared_taps(const dof_job *job, float radius, ptrdiff_t stride, shared_tap *taps)
{
    const uint32_t count = taps_for_radius(radius, job->tap_count);
    for (uint32_t k = 1; k < count; ++k) {
        float ox = job->taps[k].x * radius, oy = job->taps[k].y * radius;
        float fx0 = floorf(ox), fy0 = floorf(oy);
        taps[k - 1] = (shared_tap){ .near = (ptrdiff_t)floorf(oy + 0.5f) * stride +
                                            (ptrdiff_t)floorf(ox + 0.5f),
                                    .corner = (ptrdiff_t)fy0 * stride + (ptrdiff_t)fx0,
                                    .fx = ox - fx0,
                                    .fy = oy - fy0,
                                    .distance = sqrtf(ox * ox + oy * oy) };
    }
    return count - 1;
}

static inline void shared_rows(const dof_job *job, const tile_planes *tp, int32_t y0, int32_t y1,
                               const shared_tap *taps, uint32_t count, uint32_t lanes)
{
    for (int32_t y = y0; y < y1; ++y) {
        switch (job->in->channels) {
        case 1:
            shared_row(job, tp, y, taps, count, lanes, 1);
            break;
        case 2:
            shared_row(job, tp, y, taps, count, lanes, 2);
            break;
        case 3:
            shared_row(job, tp, y, taps, count, lanes, 3);
            break;
        default:
            shared_row(job, tp, y, taps, count, lanes, 4);
            break;
        }
    }
}

// Tile row ty's shared gathers (post_dof_internal.h). A tile across a depth edge is gathered
// per pixel, but each of its rows is split into groups that share: the pixels whose circles
// share with the row's largest remaining circle (circles_share), gathered with its taps (all 16
// lanes run, the group's are written), then the same with the rest, up to 3 groups (two
// depths and the pixels between); a group of under 3 pixels is left to the per-pixel gather
// (16 lanes of shared taps cost about what 2 pixels' own gathers do).
static DRIFT_AVX2_CLONES void shared_band(const dof_job *job, int32_t ty, float *local)
{
    enum {
        GROUPS = 3,
        LEAST = 3
    };

    const drift_image *in = job->in;
    shared_tap taps[SHARED_MAX_TAPS];
    tile_planes tp;
    int32_t y0 = ty * UNIFORM_TILE;
    int32_t y1 = y0 + UNIFORM_TILE < in->height ? y0 + UNIFORM_TILE : in->height;
    for (int32_t tx = 0; tx < job->tiles_x; ++tx) {
        size_t t = (size_t)ty * (size_t)job->tiles_x + (size_t)tx;
        int32_t x0 = tx * UNIFORM_TILE;
        float widest = job->tile_radius[t];
        if (job->tile_class[t] == TILE_SHARED) {
            tile_planes_make(job, tx, ty, widest, local, &tp);
            uint32_t count = shared_taps(job, widest, tp.stride, taps);
            shared_rows(job, &tp, y0, y1, taps, count, 0xFFFFu);
            continue;
        }
        if (job->tile_class[t] != TILE_GATHER) {
            continue;
        }
        int32_t n = in->width - x0 < UNIFORM_TILE ? in->width - x0 : UNIFORM_TILE;
        bool filled = false, allowed = job->planes_allowed && widest <= SHARED_MAX_RADIUS;
        float made = -1.0f; // the circle `taps` holds (for this tile's planes)
        uint32_t count = 0;
        for (int32_t y = y0; y < y1; ++y) {
            const float *reach = drift_image_pixel(job->coc, x0, y);
            float r[UNIFORM_TILE];
            uint32_t left = 0, done = 0; // the gathering pixels not yet gathered; those done
            for (int32_t i = 0; i < n; ++i) {
                r[i] = reach[i * job->coc->channels];
                left |= r[i] >= 0.5f ? 1u << i : 0u;
            }
            for (int group = 0; allowed && left && group < GROUPS; ++group) {
                float hi = 0.0f;
                for (int32_t i = 0; i < n; ++i) {
                    hi = ((left >> i) & 1u) && r[i] > hi ? r[i] : hi;
                }
                uint32_t members = 0;
                int32_t size = 0;
                for (int32_t i = 0; i < n; ++i) {
                    bool in_group = ((left >> i) & 1u) && circles_share(r[i], hi);
                    members |= in_group ? 1u << i : 0u;
                    size += in_group;
                }
                left &= ~members;
                if (size < LEAST) {
                    continue; // left to the per-pixel gather
                }
                if (!filled) { // the tile's planes, padded for its widest circle
                    tile_planes_make(job, tx, ty, widest, local, &tp);
                    filled = true;
                }
                if (hi != made) { // rows beside one depth edge often repeat their circle
                    count = shared_taps(job, hi, tp.stride, taps);
                    made = hi;
                }
                shared_rows(job, &tp, y, y + 1, taps, count, members);
                done |= members;
            }
            job->row_lanes[(size_t)y * (size_t)job->tiles_x + (size_t)tx] = (uint16_t)done;
        }
    }
}

void drift__post_dof_scan_tiles(size_t begin, size_t end, int thread_index, void *user)
{
    scan_tiles(begin, end, thread_index, user);
}

void drift__post_dof_shared_band(const dof_job *job, int32_t ty, float *local)
{
    shared_band(job, ty, local);
}
