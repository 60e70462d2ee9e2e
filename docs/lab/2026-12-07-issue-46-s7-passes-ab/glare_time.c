// main's glare convolution against this tree's (1080p, a 256 x 256 PSF, one thread), alternating in
// one process: the least process CPU time of each, and how far apart the images are (the
// largest difference over the largest value of the old image).
#define _GNU_SOURCE
#include "glare/glare_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
drift_result old_convolve(drift_context *ctx, drift__glare_conv *c, const drift_image *in,
                          const float *psf, int32_t k, bool psf_changed, const drift_image *out);
void old_conv_release(drift_context *ctx, drift__glare_conv *c);

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

int main(int argc, char **argv)
{
    int w = 1920, h = 1080, K = 256, reps = argc > 1 ? atoi(argv[1]) : 3;
    drift_context_desc d = { .thread_count = 1 };
    drift_context *ctx;
    drift_context_create(&d, &ctx);
    drift_image in, o1, o2;
    drift_image_create(ctx, w, h, 3, &in);
    drift_image_create(ctx, w, h, 3, &o1);
    drift_image_create(ctx, w, h, 3, &o2);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 3; ++c)
                drift_image_pixel(&in, x, y)[c] =
                    (float)((x * 7 + y * 13 + c) % 101) * 0.01f +
                    ((x - 900) * (x - 900) + (y - 500) * (y - 500) < 400 ? 50.0f : 0.0f);
    float *psf = malloc(sizeof(float) * 3 * K * K);
    for (int i = 0; i < 3 * K * K; ++i)
        psf[i] = 1e-6f * (float)(1 + i % 17);
    drift__glare_conv c1 = { 0 }, c2 = { 0 };
    old_convolve(ctx, &c1, &in, psf, K, true, &o1);
    drift__glare_convolve(ctx, &c2, &in, psf, K, true, &o2);
    double best[2] = { 1e9, 1e9 };
    for (int r = 0; r < reps; ++r)
        for (int k = 0; k < 2; ++k) {
            double t = now();
            if (k == 0)
                old_convolve(ctx, &c1, &in, psf, K, false, &o1);
            else
                drift__glare_convolve(ctx, &c2, &in, psf, K, false, &o2);
            t = now() - t;
            if (t < best[k])
                best[k] = t;
        }
    int diff = 0;
    double worst = 0.0, peak = 0.0;
    for (int y = 0; y < h; ++y) {
        diff +=
            memcmp(drift_image_pixel(&o1, 0, y), drift_image_pixel(&o2, 0, y), (size_t)w * 12) != 0;
        for (int x = 0; x < w * 3; ++x) {
            double a = drift_image_pixel(&o1, 0, y)[x], b = drift_image_pixel(&o2, 0, y)[x];
            worst = fabs(a - b) > worst ? fabs(a - b) : worst;
            peak = fabs(a) > peak ? fabs(a) : peak;
        }
    }
    printf("glare conv 1920x1080 K=256 1 thread, least of %d alternating: old %.1f ms, new %.1f "
           "ms, old/new %.2f; rows differing %d, largest difference %.3g of the peak %.3g\n",
           reps, best[0] * 1e3, best[1] * 1e3, best[0] / best[1], diff, worst / peak, peak);
    old_conv_release(ctx, &c1);
    drift__glare_conv_release(ctx, &c2);
    return worst > 1e-5 * peak;
}
