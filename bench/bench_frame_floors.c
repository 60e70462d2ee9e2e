// drift bench frame --floors: each image pass of the hybrid frame against its own floor, in
// one run. The bandwidth floor of a pass is the bytes it must read and write (each input plane
// once, each output plane once, at the planes' own channel counts) at this machine's copy
// bandwidth, measured in the same run (memcpy of a W x H RGBA32F frame: one read and one write
// of every byte). Passes whose work is per sample, not per byte (ISG's search and gather, the
// glare FFT), also get a compute floor, stated with them (bench_frame_floors_json).
//
// The passes are timed on frames the hybrid renderer has made (so that their inputs are a real
// frame's), each re-run `repeats` times and the least time kept: compose (D = sum_l U_l S_l +
// environment, then E + D + the terms and the circle of confusion), post depth of field, the
// three ISG passes (soft shadows, glossy reflections, depth of field), the a-trous filter
// (5 passes over the frame's colour with its G-buffer guides) and the glare convolution of the
// frame with a 256 x 256 RGB PSF. The a-trous filter also gets the bytes of its passes apart
// (each reading the colour and the guides, writing the colour) and a compute floor: its taps
// at the ISG sample's cost.
#include "bench_frame_floors.h"

#include "bench.h"
#include "denoise/exp_neg.h"
#include "drift/accel.h"
#include "drift/denoise.h"
#include "drift/hybrid.h"
#include "glare/glare_internal.h"
#include "hybrid/frame_access.h"
#include "hybrid/techniques.h"
#include "isg/isg.h"
#include "realtime/realtime.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define FLOOR_PASS_MAX 8

// The clock: the process's CPU seconds (on one thread, what the pass itself spent: the machine's
// other load does not count), or wall seconds with more threads.
static bool cpu_clock = true;

static double now(void)
{
    struct timespec ts;
    if (cpu_clock && clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts) == 0) {
        return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
    }
    return drift_time_now();
}

typedef struct floor_pass {
    const char *name;
    double ms;           // least of the repeats
    double bytes;        // bytes the pass must read and write
    double level_bytes;  // a-trous: the bytes of its passes, each on its own (0: none)
    double compute_ms;   // its compute floor (0: none stated)
    const char *compute; // what the compute floor counts
    double samples;      // filter samples (ISG), taps (a-trous, post DOF)
    double flops;        // the float operations its compute floor counts (0: not by flops)
    bool isg;
} floor_pass;

typedef struct floor_run {
    double copy_gbs;  // bytes moved (read + written) per ns
    double sample_ns; // the ideal cross-bilateral sample, ns (ISG's compute floor)
    double gflops;    // float multiplies and adds a ns, one thread, vectorised (glare, post DOF)
    floor_pass pass[FLOOR_PASS_MAX];
    int count;
} floor_run;

static double image_bytes(const drift_image *image)
{
    return (double)image->width * (double)image->height * (double)image->channels * 4.0;
}

// The machine's copy bandwidth: the best of `repeats` memcpys of a W x H RGBA32F frame.
static double copy_bandwidth(drift_context *ctx, int32_t w, int32_t h, int repeats)
{
    size_t bytes = (size_t)w * (size_t)h * 16u;
    unsigned char *a = drift_alloc(ctx, bytes), *b = drift_alloc(ctx, bytes);
    double best = HUGE_VAL;
    if (a && b) {
        memset(a, 1, bytes);
        memset(b, 2, bytes);
        for (int k = 0; k < repeats + 1; ++k) {
            double t = now();
            memcpy(k % 2 ? a : b, k % 2 ? b : a, bytes);
            t = now() - t;
            best = k > 0 && t < best ? t : best; // the first touches the pages
        }
    }
    drift_free(ctx, a);
    drift_free(ctx, b);
    return isfinite(best) ? 2.0 * (double)bytes / best * 1e-9 : 0.0;
}

// One tap of the sweep: every pixel of the N-pixel planes weighs its neighbour `tap` away.
static DRIFT_AVX2_CLONES void sample_sweep(float *const p[6], int tap, float *sum)
{
    enum {
        N = 1 << 16
    };

    const float *restrict c0 = p[0], *restrict c1 = p[1], *restrict c2 = p[2];
    const float *restrict q0 = p[0] + tap, *restrict q1 = p[1] + tap, *restrict q2 = p[2] + tap;
    const float *restrict v0 = p[3] + tap, *restrict v1 = p[4] + tap, *restrict v2 = p[5] + tap;
    float *restrict s0 = sum, *restrict s1 = sum + N, *restrict s2 = sum + 2 * N,
                    *restrict sw = sum + 3 * N;
    DRIFT_IVDEP
    for (int i = 0; i < N; ++i) {
        float d0 = q0[i] - c0[i], d1 = q1[i] - c1[i], d2 = q2[i] - c2[i];
        float e = (d0 * d0 + d1 * d1 + d2 * d2) * 4.0f;
        float w = exp_neg(e < DENOISE_EXP_CUTOFF ? e : DENOISE_EXP_CUTOFF);
        s0[i] += w * v0[i];
        s1[i] += w * v1[i];
        s2[i] += w * v2[i];
        sw[i] += w;
    }
}

// ISG's compute floor: one cross-bilateral sample at its least, measured here. A vectorised
// sweep over a plane reads a neighbour's position (3 floats) and value (3 floats), weighs it
// by exp(-|p - q|^2 / sigma) and adds it in: what every ISG sample does at the least (the
// real ones also find their offset in a pattern and test the sample's material).
static double sample_floor_ns(drift_context *ctx, int repeats)
{
    enum {
        N = 1 << 16,
        TAPS = 16
    };

    float *plane = drift_alloc(ctx, sizeof(float) * 6 * (N + 64));
    float *sum = drift_alloc(ctx, sizeof(float) * 4 * N);
    double best = HUGE_VAL;
    if (plane && sum) {
        for (size_t i = 0; i < 6 * (size_t)(N + 64); ++i) {
            plane[i] = (float)(i % 97) * 0.01f;
        }
        float *p[6];
        for (int c = 0; c < 6; ++c) {
            p[c] = plane + (size_t)c * (N + 64);
        }
        for (int k = 0; k < repeats + 1; ++k) {
            double t = now();
            memset(sum, 0, sizeof(float) * 4 * N);
            for (int tap = 0; tap < TAPS; ++tap) {
                sample_sweep(p, tap, sum);
            }
            t = now() - t;
            best = k > 0 && t < best ? t : best;
        }
        volatile float keep = sum[N / 2];
        (void)keep;
    }
    drift_free(ctx, plane);
    drift_free(ctx, sum);
    return isfinite(best) ? best * 1e9 / ((double)N * TAPS) : 0.0;
}

// The machine's FLOP rate on one thread: 16 independent chains of 8-lane multiplies and adds
// (a multiply, then an add: -ffp-contract=off keeps them apart, as in the passes), enough
// chains to fill both arithmetic ports through their latency. The glare FFT's and the post
// DOF gather's compute floors are their float operations at this rate.
typedef float flop_v __attribute__((vector_size(32)));

static DRIFT_AVX2_CLONES void flop_chains(flop_v *x, long rounds)
{
    const flop_v m = { 0.999f, 0.999f, 0.999f, 0.999f, 0.999f, 0.999f, 0.999f, 0.999f };
    const flop_v c = { 1e-3f, 1e-3f, 1e-3f, 1e-3f, 1e-3f, 1e-3f, 1e-3f, 1e-3f };
    flop_v a0 = x[0], a1 = x[1], a2 = x[2], a3 = x[3], a4 = x[4], a5 = x[5], a6 = x[6], a7 = x[7];
    flop_v a8 = x[8], a9 = x[9], a10 = x[10], a11 = x[11], a12 = x[12], a13 = x[13], a14 = x[14],
           a15 = x[15];
    for (long r = 0; r < rounds; ++r) {
        a0 = a0 * m + c, a1 = a1 * m + c, a2 = a2 * m + c, a3 = a3 * m + c;
        a4 = a4 * m + c, a5 = a5 * m + c, a6 = a6 * m + c, a7 = a7 * m + c;
        a8 = a8 * m + c, a9 = a9 * m + c, a10 = a10 * m + c, a11 = a11 * m + c;
        a12 = a12 * m + c, a13 = a13 * m + c, a14 = a14 * m + c, a15 = a15 * m + c;
    }
    x[0] = a0, x[1] = a1, x[2] = a2, x[3] = a3, x[4] = a4, x[5] = a5, x[6] = a6, x[7] = a7;
    x[8] = a8, x[9] = a9, x[10] = a10, x[11] = a11, x[12] = a12, x[13] = a13, x[14] = a14;
    x[15] = a15;
}

static double flop_rate(int repeats)
{
    enum {
        ROUNDS = 1 << 20
    };

    flop_v x[16];
    for (int i = 0; i < 16; ++i) {
        for (int l = 0; l < 8; ++l) {
            x[i][l] = (float)(i + l) * 0.01f;
        }
    }
    double best = HUGE_VAL;
    for (int k = 0; k < repeats + 1; ++k) {
        double t = now();
        flop_chains(x, ROUNDS);
        t = now() - t;
        best = k > 0 && t < best ? t : best;
    }
    volatile float keep = x[3][5];
    (void)keep;
    return isfinite(best) ? 16.0 * 8.0 * 2.0 * ROUNDS / best * 1e-9 : 0.0;
}

// Whether --passes names the pass (every pass without --passes).
static bool wanted(const bench_floor_options *o, const char *name)
{
    if (!o->passes) {
        return true;
    }
    size_t n = strlen(name);
    for (const char *p = o->passes; *p;) {
        const char *comma = strchr(p, ',');
        size_t len = comma ? (size_t)(comma - p) : strlen(p);
        if (len == n && strncmp(p, name, n) == 0) {
            return true;
        }
        p += len + (comma ? 1 : 0);
    }
    return false;
}

// The post DOF gather's taps on this frame, by the per-pixel gather's rules (src/raster/
// post_dof.c): none where the circle's radius is under half a pixel or the 16 x 16 tile and all
// it reads hold one colour (those pixels are copied); else the centre and a power of two of the
// 64-entry table, one a quarter of the disk's area (at least 4, at most 63), of which all but
// the centre are fetched. The default pass's shared tiles (post_dof_tiles.c) run at least as
// many (each pixel the count of its tile's largest circle; flat tiles found by whole tiles), so
// this stays a floor of its work.
static double post_dof_taps(const drift_image *in, const drift_image *coc)
{
    enum {
        TILE = 16,
        TABLE = 64
    };

    double taps = 0.0;
    for (int32_t ty = 0; ty * TILE < in->height; ++ty) {
        for (int32_t tx = 0; tx * TILE < in->width; ++tx) {
            int32_t x0 = tx * TILE, y0 = ty * TILE;
            int32_t x1 = x0 + TILE < in->width ? x0 + TILE : in->width;
            int32_t y1 = y0 + TILE < in->height ? y0 + TILE : in->height;
            float reach = 0.0f;
            for (int32_t y = y0; y < y1; ++y) {
                for (int32_t x = x0; x < x1; ++x) {
                    reach = fmaxf(reach, drift_image_pixel(coc, x, y)[0]);
                }
            }
            int32_t pad = (int32_t)ceilf(fminf(reach, (float)(in->width + in->height))) + 1;
            const float *first = drift_image_pixel(in, x0, y0);
            bool uniform = true;
            for (int32_t y = y0 - pad; uniform && y <= y1 - 1 + pad; ++y) {
                int32_t cy = y < 0 ? 0 : (y >= in->height ? in->height - 1 : y);
                for (int32_t x = x0 - pad; uniform && x <= x1 - 1 + pad; ++x) {
                    int32_t cx = x < 0 ? 0 : (x >= in->width ? in->width - 1 : x);
                    const float *q = drift_image_pixel(in, cx, cy);
                    for (int32_t c = 0; c < in->channels; ++c) {
                        uniform = uniform && q[c] == first[c];
                    }
                }
            }
            for (int32_t y = y0; !uniform && y < y1; ++y) {
                for (int32_t x = x0; x < x1; ++x) {
                    float radius = drift_image_pixel(coc, x, y)[0];
                    if (!(radius >= 0.5f)) {
                        continue;
                    }
                    float quarter_area = 0.25f * 3.14159265f * radius * radius;
                    uint32_t n = 4;
                    while ((float)n < quarter_area && n < TABLE - 1) {
                        n *= 2;
                    }
                    taps += (double)((n + 1 < TABLE ? n + 1 : TABLE) - 1);
                }
            }
        }
    }
    return taps;
}

typedef drift_result (*pass_call)(drift_frame_state *f, void *user);

// The least milliseconds of `repeats` calls.
static drift_result time_pass(drift_frame_state *f, pass_call call, void *user, int repeats,
                              double *ms)
{
    *ms = HUGE_VAL;
    for (int k = 0; k < repeats; ++k) {
        double t = now();
        drift_result r = call(f, user);
        if (r != DRIFT_OK) {
            return r;
        }
        t = 1e3 * (now() - t);
        *ms = t < *ms ? t : *ms;
    }
    return DRIFT_OK;
}

static drift_result call_compose(drift_frame_state *f, void *user)
{
    (void)user;
    drift_result r = drift_realtime_pass_sum_direct(f);
    return r == DRIFT_OK ? drift_hybrid_pass_compose(f) : r;
}

static drift_result call_post_dof(drift_frame_state *f, void *user)
{
    (void)user;
    return drift_post_dof(f->ctx, &f->focus, &f->coc, 0, &f->final);
}

static drift_result call_isg(drift_frame_state *f, void *user)
{
    const drift_effect *effect = user;
    drift_pass_args args = { .effect = *effect };
    switch (*effect) {
    case DRIFT_EFFECT_SHADOWS:
        return drift_isg_pass_shadows(f, &args);
    case DRIFT_EFFECT_REFLECTIONS:
        return drift_isg_pass_reflections(f, &args);
    default:
        return drift_isg_pass_dof(f, &args);
    }
}

static drift_result call_atrous(drift_frame_state *f, void *user)
{
    drift_image *out = user;
    drift_image_destroy(f->ctx, out);
    return drift_denoise_atrous(f->ctx, &f->focus, &f->gbuffer.albedo, &f->gbuffer.normal,
                                &f->gbuffer.depth, NULL, out);
}

typedef struct glare_call {
    drift__glare_conv conv;
    const float *psf;
    int32_t k;
} glare_call;

static drift_result call_glare(drift_frame_state *f, void *user)
{
    glare_call *g = user;
    // The PSF's spectrum is cached across frames (it changes with the eye, not the image).
    return drift__glare_convolve(f->ctx, &g->conv, &f->focus, g->psf, g->k, false, &f->final);
}

static drift_result render_frame(drift_context *ctx, const drift_scene *scene,
                                 const drift_accel *accel, const bench_floor_options *o,
                                 drift_hybrid_params params, drift_hybrid **frame)
{
    params.width = (int32_t)o->width;
    params.height = (int32_t)o->height;
    drift_result r = drift_hybrid_create(ctx, scene, accel, &params, frame);
    return r == DRIFT_OK ? drift_hybrid_render(*frame, &scene->camera, NULL) : r;
}

static floor_pass *add_pass(floor_run *run, const char *name)
{
    floor_pass *p = &run->pass[run->count++];
    *p = (floor_pass){ .name = name };
    return p;
}

static drift_result measure_compose(drift_frame_state *f, const bench_floor_options *o,
                                    floor_run *run);
static drift_result measure_atrous(drift_frame_state *f, const bench_floor_options *o,
                                   floor_run *run, double px);
static drift_result measure_glare(drift_frame_state *f, const bench_floor_options *o,
                                  floor_run *run);

// Compose, post DOF, a-trous and the glare convolution on the frame of hard shadows, sharp
// reflections and post DOF (those --passes names).
static drift_result measure_plain(drift_frame_state *f, const bench_floor_options *o,
                                  floor_run *run)
{
    double px = (double)o->width * (double)o->height;
    drift_result r = DRIFT_OK;
    floor_pass *p = NULL;
    if (wanted(o, "compose")) {
        r = measure_compose(f, o, run);
    }
    if (r == DRIFT_OK && wanted(o, "post dof")) {
        p = add_pass(run, "post dof");
        p->bytes = image_bytes(&f->focus) + image_bytes(&f->coc) + image_bytes(&f->final);
        // Compute floor: each tap's bilinear RGB fetch and weighted sum (3 channels x 3 lerps of
        // 3 operations, 3 x a difference, a product and a sum, the weight's sum: 37), counted
        // for every tap; a tap whose weight is zero skips its fetch (it still computes the
        // weight, ~12 operations), so on frames with many such taps this floor is high.
        p->samples = post_dof_taps(&f->focus, &f->coc);
        p->flops = 37.0 * p->samples;
        p->compute_ms = p->flops / (run->gflops * 1e6);
        p->compute = "taps x 37 float operations (bilinear RGB fetch + weighted sum) at the "
                     "measured FLOP rate";
        r = time_pass(f, call_post_dof, NULL, o->repeats, &p->ms);
    }
    if (r == DRIFT_OK && wanted(o, "a-trous")) {
        r = measure_atrous(f, o, run, px);
    }
    if (r == DRIFT_OK && wanted(o, "glare conv")) {
        r = measure_glare(f, o, run);
    }
    return r;
}

// Compose: D = sum_l U_l S_l + environment, then E + D + the terms and the circle of confusion.
static drift_result measure_compose(drift_frame_state *f, const bench_floor_options *o,
                                    floor_run *run)
{
    double px = (double)o->width * (double)o->height;
    floor_pass *p = add_pass(run, "compose");
    // Reads: the environment's direct light, each light's U_l (3) and S_l (1), E, the material
    // id, each term added, the depth; writes the focused frame and the circle of confusion.
    double bytes = image_bytes(&f->environment_direct) + image_bytes(&f->gbuffer.emission) +
                   image_bytes(&f->gbuffer.material_id) + image_bytes(&f->gbuffer.depth) +
                   image_bytes(&f->focus) + image_bytes(&f->coc);
    for (uint32_t l = 0; l < f->light_count; ++l) {
        bytes +=
            image_bytes(&f->light_buffers[l].unshadowed) + image_bytes(&f->light_buffers[l].shadow);
    }
    for (int e = 0; e < DRIFT_EFFECT_COUNT; ++e) {
        if (e != DRIFT_EFFECT_SHADOWS &&
            drift_effect_info_of((drift_effect)e)->kind == DRIFT_EFFECT_KIND_TERM &&
            !(drift_technique_row_chosen(&f->params, (drift_effect)e)->flags & DRIFT_ROW_NO_TERM)) {
            bytes += 12.0 * px;
        }
    }
    p->bytes = bytes;
    return time_pass(f, call_compose, NULL, o->repeats, &p->ms);
}

static drift_result measure_atrous(drift_frame_state *f, const bench_floor_options *o,
                                   floor_run *run, double px)
{
    drift_result r = DRIFT_OK;
    floor_pass *p = add_pass(run, "a-trous");
    // The floor: the colour, albedo, normal and depth once; the filtered colour once, as a
    // filter fusing its 5 passes in cache would move them. Beside it, the bytes of 5 passes
    // each on its own: each reads the colour and the three guides and writes the colour.
    double guides = image_bytes(&f->gbuffer.albedo) + image_bytes(&f->gbuffer.normal) +
                    image_bytes(&f->gbuffer.depth);
    p->bytes = image_bytes(&f->focus) * 2.0 + guides;
    drift_denoise_params dp = drift_denoise_params_resolve(NULL);
    p->level_bytes = (double)dp.iterations * (2.0 * 12.0 * px + guides);
    // Compute floor: each tap in the image (24 a pixel and pass, fewer at the edges) at least
    // an ideal bilateral sample (a 3-float distance, exp, three weighted channels).
    double taps = 0.0;
    for (int32_t i = 0; i < dp.iterations; ++i) {
        double s = ldexp(1.0, i), w = (double)o->width, h = (double)o->height;
        double row = 0.0, col = 0.0;
        for (int d = -2; d <= 2; ++d) {
            row += fmax(w - fabs((double)d) * s, 0.0);
            col += fmax(h - fabs((double)d) * s, 0.0);
        }
        taps += row * col - w * h; // less the centre tap, which weighs nothing
    }
    p->samples = taps;
    p->compute_ms = taps * run->sample_ns * 1e-6;
    p->compute = "taps x the ideal vectorised bilateral sample";
    drift_image out = { 0 };
    if (r == DRIFT_OK) {
        r = time_pass(f, call_atrous, &out, o->repeats, &p->ms);
    }
    drift_image_destroy(f->ctx, &out);
    return r;
}

// The glare convolution of the frame with a 256 x 256 RGB PSF, its spectrum cached.
static drift_result measure_glare(drift_frame_state *f, const bench_floor_options *o,
                                  floor_run *run)
{
    drift_result r = DRIFT_OK;
    floor_pass *p = add_pass(run, "glare conv");
    p->bytes = image_bytes(&f->focus) + image_bytes(&f->final);

    // A 256 x 256 PSF, its energy at the centre and a faint halo (the values do not change
    // the time).
    enum {
        K = 256
    };

    float *psf = drift_alloc(f->ctx, sizeof(float) * 3 * K * K);
    glare_call g = { .psf = psf, .k = K };
    if (!psf) {
        r = r == DRIFT_OK ? DRIFT_ERR_OUT_OF_MEMORY : r;
    } else {
        for (size_t i = 0; i < 3u * K * K; ++i) {
            psf[i] = 1e-6f;
        }
        psf[3 * (K / 2 * K + K / 2)] = psf[3 * (K / 2 * K + K / 2) + 1] =
            psf[3 * (K / 2 * K + K / 2) + 2] = 1.0f;
    }
    if (r == DRIFT_OK) {
        r = drift__glare_convolve(f->ctx, &g.conv, &f->focus, psf, K, true, &f->final);
    }
    if (r == DRIFT_OK) {
        r = time_pass(f, call_glare, &g, o->repeats, &p->ms);
    }
    // Compute floor: 3 channels x (forward + inverse) real 2-D FFTs of the padded plane of P
    // points, 2.5 P log2 P float operations each (half the 5 N log2 N of a complex FFT), and
    // the product of the spectra (6 operations a bin), at the measured FLOP rate.
    double points = (double)g.conv.width * (double)g.conv.height;
    double bins = (double)(g.conv.width / 2 + 1) * (double)g.conv.height;
    p->flops = 3.0 * (2.0 * 2.5 * points * log2(points) + 6.0 * bins);
    p->compute_ms = p->flops / (run->gflops * 1e6);
    p->compute = "3 channels x (2 real FFTs x 2.5 P log2 P + 6 a bin) at the measured FLOP rate";
    drift__glare_conv_release(f->ctx, &g.conv);
    drift_free(f->ctx, psf);
    return r;
}

// The samples an ISG pass took, from its search plane (search distance, gather radius): a
// search where the plane holds a finite distance or a gather radius, a gather where that
// radius is half a pixel or more (the passes' own tests); with every_receiver (soft shadows,
// whose lights are over half a pixel here), a search at every surface pixel.
static double count_samples(const drift_frame_state *f, const drift_image *plane, double search,
                            double gather, bool every_receiver)
{
    double n = 0.0;
    for (int32_t y = 0; y < plane->height; ++y) {
        for (int32_t x = 0; x < plane->width; ++x) {
            const float *v = drift_image_pixel(plane, x, y);
            bool searched = drift_image_pixel(&f->gbuffer.material_id, x, y)[0] >= 0.0f &&
                            (every_receiver || isfinite(v[0]) || v[1] > 0.0f);
            n += (searched ? search : 0.0) + (v[1] >= 0.5f ? gather : 0.0);
        }
    }
    return n;
}

// The three ISG passes on the frame of isg shadows, reflections and depth of field.
static drift_result measure_isg(drift_frame_state *f, const bench_floor_options *o, floor_run *run)
{
    static const struct {
        const char *name;
        drift_effect effect;
    } isg[3] = { { "isg shadows", DRIFT_EFFECT_SHADOWS },
                 { "isg reflections", DRIFT_EFFECT_REFLECTIONS },
                 { "isg dof", DRIFT_EFFECT_DOF } };

    double search = (double)f->params.isg.search, gather = (double)f->params.isg.gather;
    drift_result r = DRIFT_OK;
    for (int k = 0; k < 3 && r == DRIFT_OK; ++k) {
        if (!wanted(o, isg[k].name)) {
            continue;
        }
        floor_pass *p = add_pass(run, isg[k].name);
        drift_effect effect = isg[k].effect;
        r = time_pass(f, call_isg, &effect, o->repeats, &p->ms);
        double bytes = 0.0, samples = 0.0;
        if (effect == DRIFT_EFFECT_SHADOWS) {
            // Per light: the hard-shadow buffer (bit, occluder and light distance) in, S_l out;
            // the positions, normals and material ids once. Samples: a search at every
            // receiver, a gather where the search plane says one ran.
            for (uint32_t l = 0; l < f->light_count; ++l) {
                bytes += image_bytes(&f->light_buffers[l].hard_shadow) +
                         image_bytes(&f->light_buffers[l].shadow);
                samples +=
                    count_samples(f, &drift_isg_of(f)->light_search[l], search, gather, true);
            }
        } else if (effect == DRIFT_EFFECT_REFLECTIONS) {
            bytes = image_bytes(&f->reflection_emitted) + image_bytes(&f->reflection_reflected) +
                    image_bytes(&f->reflection_distance) + image_bytes(&f->reflections);
            samples = count_samples(f, &drift_isg_of(f)->reflection_search, search, gather, false);
        } else {
            bytes = image_bytes(&f->focus) + image_bytes(&f->coc) + image_bytes(&f->final) +
                    image_bytes(&f->gbuffer.depth);
            // A search at every pixel, a gather where its radius is half a pixel or more;
            // nothing with a pinhole (the pass copies the frame).
            if (drift_coc_radius_pixels(&f->camera, f->params.height, 1e30f) >= 0.5f) {
                samples = (double)o->width * (double)o->height * search;
                for (int32_t y = 0; y < f->params.height; ++y) {
                    for (int32_t x = 0; x < f->params.width; ++x) {
                        samples += drift_image_pixel(&drift_isg_of(f)->dof_search, x, y)[0] >= 0.5f
                                       ? gather
                                       : 0.0;
                    }
                }
            }
        }
        bytes += image_bytes(&f->gbuffer.position) + image_bytes(&f->gbuffer.normal) +
                 image_bytes(&f->gbuffer.material_id);
        p->bytes = bytes;
        p->samples = samples;
        p->isg = true;
        p->compute_ms = samples * run->sample_ns * 1e-6;
        p->compute = "search + gather samples x the ideal vectorised bilateral sample";
    }
    return r;
}

static void print_run(const char *scene_path, const bench_floor_options *o, int threads,
                      const floor_run *run)
{
    if (o->json) {
        cJSON *root = cJSON_CreateObject();
        cJSON_AddStringToObject(root, "scene", scene_path);
        cJSON_AddNumberToObject(root, "width", (double)o->width);
        cJSON_AddNumberToObject(root, "height", (double)o->height);
        cJSON_AddNumberToObject(root, "threads", threads);
        cJSON_AddNumberToObject(root, "repeats", (double)o->repeats);
        cJSON_AddStringToObject(root, "clock", cpu_clock ? "process cpu" : "wall");
        cli_json_number(root, "copy_gb_per_s", run->copy_gbs, 4);
        cli_json_number(root, "sample_floor_ns", run->sample_ns, 4);
        cli_json_number(root, "gflop_per_s", run->gflops, 3);
        cJSON *array = cJSON_AddArrayToObject(root, "passes");
        for (int k = 0; k < run->count; ++k) {
            const floor_pass *p = &run->pass[k];
            double floor_ms = p->bytes / (run->copy_gbs * 1e6);
            cJSON *item = cJSON_CreateObject();
            cJSON_AddItemToArray(array, item);
            cJSON_AddStringToObject(item, "name", p->name);
            cli_json_number(item, "ms", p->ms, 4);
            cli_json_number(item, "bytes", p->bytes, 0);
            cli_json_number(item, "floor_ms", floor_ms, 6);
            cli_json_number(item, "floor_ratio", p->ms / floor_ms, 2);
            if (p->compute_ms > 0.0) {
                cli_json_number(item, "compute_floor_ms", p->compute_ms, 3);
                cli_json_number(item, "compute_floor_ratio", p->ms / p->compute_ms, 2);
                cJSON_AddStringToObject(item, "compute_floor", p->compute);
            }
            if (p->level_bytes > 0.0) {
                double level_ms = p->level_bytes / (run->copy_gbs * 1e6);
                cli_json_number(item, "level_bytes", p->level_bytes, 0);
                cli_json_number(item, "level_floor_ms", level_ms, 6);
                cli_json_number(item, "level_floor_ratio", p->ms / level_ms, 2);
            }
            if (p->flops > 0.0) {
                cli_json_number(item, "flops", p->flops, 0);
            }
            if (p->isg || p->samples > 0.0) {
                cli_json_number(item, "samples", p->samples, 0);
            }
            if (p->samples > 0.0) {
                cli_json_number(item, "ns_per_sample", p->ms * 1e6 / p->samples, 3);
            }
        }
        cli_json_write("bench frame", root, NULL);
        return;
    }
    printf("%s, %ldx%ld, %d thread(s), least of %ld runs a pass, %s ms\n", scene_path, o->width,
           o->height, threads, o->repeats, cpu_clock ? "process CPU" : "wall");
    printf("copy bandwidth %.2f GB/s (read + write); ideal bilateral sample %.3f ns; "
           "%.1f GFLOP/s (one thread, 8 lanes)\n",
           run->copy_gbs, run->sample_ns, run->gflops);
    printf("%-16s %10s %10s %10s %8s %10s %8s\n", "pass", "ms", "MB", "floor ms", "x floor",
           "compute ms", "x comp");
    for (int k = 0; k < run->count; ++k) {
        const floor_pass *p = &run->pass[k];
        double floor_ms = p->bytes / (run->copy_gbs * 1e6);
        printf("%-16s %10.2f %10.1f %10.3f %7.1fx", p->name, p->ms, p->bytes * 1e-6, floor_ms,
               p->ms / floor_ms);
        if (p->compute_ms > 0.0) {
            printf(" %10.2f %7.1fx", p->compute_ms, p->ms / p->compute_ms);
        }
        if (p->level_bytes > 0.0) {
            printf("  (passes apart: %.1f MB, %.1fx)", p->level_bytes * 1e-6,
                   p->ms / (p->level_bytes / (run->copy_gbs * 1e6)));
        }
        printf("\n");
    }
}

int bench_frame_floors(drift_context *ctx, const drift_scene *scene, const drift_accel *accel,
                       const char *scene_path, const bench_floor_options *o)
{
    floor_run run = { 0 };
    cpu_clock = drift_context_thread_count(ctx) == 1;
    run.copy_gbs = copy_bandwidth(ctx, (int32_t)o->width, (int32_t)o->height, (int)o->repeats);
    run.sample_ns = sample_floor_ns(ctx, (int)o->repeats);
    run.gflops = flop_rate((int)o->repeats);
    if (!(run.copy_gbs > 0.0) || !(run.gflops > 0.0)) {
        fprintf(stderr, "drift bench frame: out of memory measuring the copy bandwidth\n");
        return 1;
    }
    drift_hybrid *frame = NULL;
    drift_result r = render_frame(ctx, scene, accel, o,
                                  (drift_hybrid_params){ .shadows = DRIFT_SHADOWS_HARD,
                                                         .reflections = DRIFT_REFLECTIONS_SHARP,
                                                         .dof = DRIFT_DOF_POST },
                                  &frame);
    if (r == DRIFT_OK) {
        r = measure_plain(drift_hybrid_frame(frame), o, &run);
    }
    drift_hybrid_destroy(frame);
    frame = NULL;
    if (r == DRIFT_OK &&
        (wanted(o, "isg shadows") || wanted(o, "isg reflections") || wanted(o, "isg dof"))) {
        drift_hybrid_params params = { 0 };
        drift_hybrid_params_set_technique(&params, DRIFT_EFFECT_SHADOWS,
                                          drift_technique_parse(DRIFT_EFFECT_SHADOWS, "isg"));
        drift_hybrid_params_set_technique(&params, DRIFT_EFFECT_REFLECTIONS,
                                          drift_technique_parse(DRIFT_EFFECT_REFLECTIONS, "isg"));
        drift_hybrid_params_set_technique(&params, DRIFT_EFFECT_DOF,
                                          drift_technique_parse(DRIFT_EFFECT_DOF, "isg"));
        r = render_frame(ctx, scene, accel, o, params, &frame);
        if (r == DRIFT_OK) {
            r = measure_isg(drift_hybrid_frame(frame), o, &run);
        }
    }
    drift_hybrid_destroy(frame);
    if (r != DRIFT_OK) {
        fprintf(stderr, "drift bench frame: the floors run failed: %s\n", drift_result_string(r));
        return 1;
    }
    print_run(scene_path, o, drift_context_thread_count(ctx), &run);
    return 0;
}
