// --budget-ms's probes (tools/render_choose.c): what a frame of this scene costs on this
// machine, now. The cost model's rows were measured on other scenes under another load; a
// few cheap frames of this scene, timed just before the render, scale its predictions.
#include "drift/image_io.h"
#include "drift/pt.h"
#include "render.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include <unistd.h>

// The process's CPU time, all its threads, in seconds.
static double cpu_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int compare_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

// CPU milliseconds (all threads) of a one-shot path tracer at w x h, 1 spp, depth 8: create,
// one sample, the resolve (what a candidate's frame pays apart from its samples' count).
// Seeded: the frame is the same each run, only its time varies.
static double time_pt(const cli_session *session, int32_t w, int32_t h)
{
    double t0 = cpu_now();
    drift_pt_params params = { .width = w, .height = h, .seed = 1u, .max_depth = 8 };
    drift_pt *pt = NULL;
    drift_image beauty;
    bool ok =
        drift_pt_create(session->ctx, session->scene, session->accel, &params, &pt) == DRIFT_OK &&
        drift_pt_render_samples(pt, 1, NULL) == DRIFT_OK &&
        drift_pt_resolve(pt, DRIFT_PT_AOV_BEAUTY, &beauty) == DRIFT_OK;
    drift_pt_destroy(pt);
    return ok ? 1e3 * (cpu_now() - t0) : -1.0;
}

// CPU milliseconds of a one-shot hybrid frame of `params` at w x h: create (its set-up) and
// the first frame.
static double time_hybrid(const cli_session *session, drift_hybrid_params params, int32_t w,
                          int32_t h)
{
    params.width = w;
    params.height = h;
    params.seed = 1u;
    drift_hybrid *frame = NULL;
    double t0 = cpu_now();
    bool ok = drift_hybrid_create(session->ctx, session->scene, session->accel, &params, &frame) ==
                  DRIFT_OK &&
              drift_hybrid_render(frame, &session->scene->camera, NULL) == DRIFT_OK;
    drift_hybrid_destroy(frame);
    return ok ? 1e3 * (cpu_now() - t0) : -1.0;
}

// Wall milliseconds of writing a w x h frame as EXR and PNG (what a render writes) into the
// temporary folder, both removed: the writes the frame's must leave room for, per pixel.
static double time_writes(const cli_session *session, int32_t w, int32_t h)
{
    const char *dir = getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp";
    char exr[4096], png[4096];
    snprintf(exr, sizeof exr, "%s/drift-probe-%ld.exr", dir, (long)getpid());
    snprintf(png, sizeof png, "%s/drift-probe-%ld.png", dir, (long)getpid());
    drift_image img;
    if (drift_image_create(session->ctx, w, h, 3, &img) != DRIFT_OK) {
        return -1.0;
    }
    // Noise, as a few samples a pixel are: the encoders' work depends on what they compress,
    // and a smooth test image wrote 3x faster than a rendered one.
    for (int32_t y = 0; y < h; ++y) {
        for (int32_t x = 0; x < w; ++x) {
            float *p = drift_image_pixel(&img, x, y);
            uint32_t k = drift_hash_u32((uint32_t)(y * w + x));
            for (int c = 0; c < 3; ++c) {
                k = drift_hash_u32(k);
                p[c] = (float)(k >> 8) * 0x1p-24f;
            }
        }
    }
    double t0 = drift_time_now();
    drift_image_layer layer = { NULL, &img };
    bool ok =
        drift_image_save_exr(session->ctx, exr, &layer, 1) == DRIFT_OK &&
        drift_image_save_png(session->ctx, png, &img, &(drift_tonemap_params){ 0 }) == DRIFT_OK;
    double ms = 1e3 * (drift_time_now() - t0);
    unlink(exr);
    unlink(png);
    drift_image_destroy(session->ctx, &img);
    return ok ? ms : -1.0;
}

void render_choose_probe(const cli_session *session, int32_t w, int32_t h,
                         const drift_hybrid_params *base_hybrid, render_probe *out)
{
    double t0 = drift_time_now();
    *out = (render_probe){ .pixels = (double)w * (double)h,
                           .hybrid_ms = -1.0,
                           .write_per_pixel_ms = -1.0 };
    // CPU time, not wall: a probe of a few ms runs within a time slice or two and sees none
    // of the machine's load that a longer frame shares the cores with (render_choose scales by
    // that apart). The path tracer three times, the median.
    double pt_ms[3];
    for (int k = 0; k < 3; ++k) {
        pt_ms[k] = time_pt(session, w, h);
    }
    qsort(pt_ms, 3, sizeof *pt_ms, compare_double);
    out->pt_ms = pt_ms[1];
    if (base_hybrid) {
        out->hybrid_ms = time_hybrid(session, *base_hybrid, w, h);
    }

    out->spent_ms = 1e3 * (drift_time_now() - t0);
}

void render_choose_probe_writes(const cli_session *session, render_probe *out)
{
    double t0 = drift_time_now();
    // Two sizes, so the files' own overhead (opening, headers) is not taken per pixel.
    double small = time_writes(session, 64, 64), large = time_writes(session, 128, 128);
    if (small >= 0.0 && large >= 0.0) {
        out->write_per_pixel_ms = fmax(large - small, 0.0) / (128.0 * 128.0 - 64.0 * 64.0);
        out->write_fixed_ms = fmax(small - 64.0 * 64.0 * out->write_per_pixel_ms, 0.0);
    }
    out->spent_ms += 1e3 * (drift_time_now() - t0);
}

double render_choose_probe_denoise(const cli_session *session, const render_options *o)
{
    const int32_t side = 96;
    drift_pt_params params = { .width = side, .height = side, .seed = 1u, .max_depth = 8 };
    drift_pt *pt = NULL;
    bool ok =
        drift_pt_create(session->ctx, session->scene, session->accel, &params, &pt) == DRIFT_OK &&
        drift_pt_render_samples(pt, 1, NULL) == DRIFT_OK;
    double ms = ok ? render_denoise_ms(session->ctx, pt, o) : -1.0;
    drift_pt_destroy(pt);
    return ms > 0.0 ? ms / ((double)side * (double)side) : -1.0;
}
