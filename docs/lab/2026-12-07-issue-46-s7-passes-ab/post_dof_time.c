// main's post DOF against this tree's (a synthetic 1080p frame, CoC 0.2-6.3 px in blocks, one
// thread), alternating in one process: the least process CPU time of each, and whether the images
// are byte equal.
#define _GNU_SOURCE
#include "drift/image.h"
#include "raster/raster.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
drift_result old_post_dof(drift_context *ctx, const drift_image *in, const drift_image *coc,
                          uint32_t taps, drift_image *out);

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

int main(int argc, char **argv)
{
    int w = 1920, h = 1080, reps = argc > 1 ? atoi(argv[1]) : 3;
    drift_context_desc d = { .thread_count = 1 };
    drift_context *ctx;
    drift_context_create(&d, &ctx);
    drift_image in, coc, o1, o2;
    drift_image_create(ctx, w, h, 3, &in);
    drift_image_create(ctx, w, h, 1, &coc);
    drift_image_create(ctx, w, h, 3, &o1);
    drift_image_create(ctx, w, h, 3, &o2);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            uint32_t i = (uint32_t)(y * w + x) * 2654435761u;
            for (int c = 0; c < 3; ++c)
                drift_image_pixel(&in, x, y)[c] = hashf(i + c) * (1.0f + (x / 200) % 3);
            // objects at several depths: a CoC from 0 to 6 pixels, blocky with edges
            int obj = ((x / 150) * 7 + (y / 120) * 3) % 5;
            drift_image_pixel(&coc, x, y)[0] = obj == 0 ? 0.2f : 1.5f * obj + 0.3f * hashf(i ^ 77u);
        }
    double best[2] = { 1e9, 1e9 };
    for (int r = 0; r < reps; ++r)
        for (int k = 0; k < 2; ++k) {
            double t = now();
            if (k == 0)
                old_post_dof(ctx, &in, &coc, 0, &o1);
            else
                drift_post_dof(ctx, &in, &coc, 0, &o2);
            t = now() - t;
            if (t < best[k])
                best[k] = t;
        }
    int diff = 0;
    for (int y = 0; y < h; ++y)
        diff +=
            memcmp(drift_image_pixel(&o1, 0, y), drift_image_pixel(&o2, 0, y), (size_t)w * 12) != 0;
    printf("post dof 1920x1080 1 thread, least of %d alternating: old %.1f ms, new %.1f ms, "
           "old/new %.2f; rows differing %d\n",
           reps, best[0] * 1e3, best[1] * 1e3, best[0] / best[1], diff);
    return diff != 0;
}
