// main's a-trous filter against this tree's at 1080p on one thread, alternating in one process:
// the least process CPU time of each.
#define _GNU_SOURCE
#include "drift/core.h"
#include "drift/denoise.h"
#include "drift/image.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
drift_result old_atrous(drift_context *ctx, const drift_image *color, const drift_image *albedo,
                        const drift_image *normal, const drift_image *depth,
                        const drift_denoise_params *params, drift_image *out);

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static float hashf(uint32_t i)
{
    i ^= i >> 16;
    i *= 0x7feb352du;
    i ^= i >> 15;
    i *= 0x846ca68bu;
    i ^= i >> 16;
    return (float)(i >> 8) / 16777216.0f;
}

static void fill(drift_context *ctx, drift_image *im, int w, int h, int ch, int kind)
{
    drift_image_create(ctx, w, h, ch, im);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float *p = drift_image_pixel(im, x, y);
            uint32_t i = (uint32_t)(y * w + x) * 2654435761u;
            int region = (x / 300 + y / 200) % 3;
            for (int c = 0; c < ch; ++c) {
                float v = hashf(i + (uint32_t)c * 7919u + (uint32_t)kind * 31u);
                if (kind == 0)
                    p[c] = (region == 0 ? 2.0f : 0.5f) * (0.7f + 0.6f * v);
                else if (kind == 1)
                    p[c] = 0.3f + 0.2f * region;
                else if (kind == 2)
                    p[c] = c == 2 ? 1.0f : (region == 2 ? 0.5f : 0.0f);
                else
                    p[c] = 2.0f + region + 0.001f * x;
            }
            if (kind == 2) {
                float l = sqrtf(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
                for (int c = 0; c < 3; ++c)
                    p[c] /= l;
            }
        }
}

int main(int argc, char **argv)
{
    int w = argc > 1 ? atoi(argv[1]) : 1920, h = argc > 2 ? atoi(argv[2]) : 1080,
        reps = argc > 3 ? atoi(argv[3]) : 5;
    drift_context_desc d = { .thread_count = 1 };
    drift_context *ctx;
    drift_context_create(&d, &ctx);
    drift_image col, alb, nor, dep, o;
    fill(ctx, &col, w, h, 3, 0);
    fill(ctx, &alb, w, h, 3, 1);
    fill(ctx, &nor, w, h, 3, 2);
    fill(ctx, &dep, w, h, 1, 3);
    double best[2] = { 1e9, 1e9 };
    for (int r = 0; r < reps; ++r)
        for (int k = 0; k < 2; ++k) {
            double t = now();
            if (k == 0)
                old_atrous(ctx, &col, &alb, &nor, &dep, NULL, &o);
            else
                drift_denoise_atrous(ctx, &col, &alb, &nor, &dep, NULL, &o);
            t = now() - t;
            if (t < best[k])
                best[k] = t;
            drift_image_destroy(ctx, &o);
        }
    printf("%dx%d 1 thread, least of %d alternating: old %.1f ms, new %.1f ms, old/new %.2f\n", w,
           h, reps, best[0] * 1e3, best[1] * 1e3, best[0] / best[1]);
}
