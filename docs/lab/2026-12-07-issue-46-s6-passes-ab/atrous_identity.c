// main's a-trous filter (old_atrous) against this tree's on 135 cases (5 sizes, 1-3 threads, 9
// parameter sets: small kernel, no colour weight, other normal powers, missing guides, 7 passes):
// byte equal.
#include "drift/core.h"
#include "drift/denoise.h"
#include "drift/image.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
drift_result old_atrous(drift_context *ctx, const drift_image *color, const drift_image *albedo,
                        const drift_image *normal, const drift_image *depth,
                        const drift_denoise_params *params, drift_image *out);

static float hashf(uint32_t i)
{
    i ^= i >> 16;
    i *= 0x7feb352du;
    i ^= i >> 15;
    i *= 0x846ca68bu;
    i ^= i >> 16;
    return (float)(i >> 8) / 16777216.0f;
}

static void fill(drift_context *ctx, drift_image *im, int w, int h, int ch, uint32_t seed, int kind)
{
    drift_image_create(ctx, w, h, ch, im);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float *p = drift_image_pixel(im, x, y);
            uint32_t i = (uint32_t)(y * w + x) * 2654435761u ^ seed;
            int region = (x / 37 + y / 23) % 3;
            for (int c = 0; c < ch; ++c) {
                float v = hashf(i + (uint32_t)c * 7919u);
                if (kind == 0)
                    p[c] = (region == 0 ? 5.0f : 0.3f) * v + (c == 3); // colour
                else if (kind == 1)
                    p[c] = region == 1 ? 0.0f : 0.2f + 0.6f * v * 0.1f + 0.3f * region; // albedo
                else if (kind == 2) {
                    float t = 0.3f * (v - 0.5f) + (region == 2 ? 0.8f : 0.0f);
                    p[c] = c == 2 ? 1.0f : t;
                } else
                    p[c] = (x + y) % 11 == 0 && region == 0
                               ? 0.0f
                               : 2.0f + 3.0f * region + 0.2f * v; // depth, some misses
            }
            if (kind == 2) {
                float l = sqrtf(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
                for (int c = 0; c < 3; ++c)
                    p[c] /= l;
            }
        }
}

int main(void)
{
    int sizes[][2] = { { 64, 48 }, { 131, 77 }, { 300, 200 }, { 17, 260 }, { 1000, 40 } };
    int threads[] = { 1, 2, 3 };
    int bad = 0, runs = 0;
    for (int s = 0; s < 5; ++s)
        for (int t = 0; t < 3; ++t)
            for (int v = 0; v < 9; ++v) {
                drift_context_desc d = { 0 };
                d.thread_count = threads[t];
                drift_context *ctx = NULL;
                if (drift_context_create(&d, &ctx) != DRIFT_OK) {
                    printf("ctx fail\n");
                    return 2;
                }
                int w = sizes[s][0], h = sizes[s][1];
                drift_image col, alb, nor, dep;
                fill(ctx, &col, w, h, v % 2 ? 3 : 4, 11u + (uint32_t)v, 0);
                fill(ctx, &alb, w, h, 3, 5u, 1);
                fill(ctx, &nor, w, h, 3, 6u, 2);
                fill(ctx, &dep, w, h, 1, 7u, 3);
                drift_denoise_params p = { 0 };
                const drift_image *a = &alb, *n = &nor, *z = &dep;
                switch (v) {
                case 1:
                    p.small_kernel = true;
                    break;
                case 2:
                    p.disable_color = true;
                    break;
                case 3:
                    p.sigma_normal = 37.0f;
                    break;
                case 4:
                    p.sigma_normal = 2.5f;
                    break;
                case 5:
                    a = NULL;
                    n = NULL;
                    z = NULL;
                    break;
                case 6:
                    p.iterations = 7;
                    p.sigma_color = 0.3f;
                    break;
                case 7:
                    p.no_demodulate = true;
                    z = NULL;
                    break;
                case 8:
                    p.iterations = 2;
                    p.small_kernel = true;
                    p.sigma_depth = 0.01f;
                    n = NULL;
                    break;
                default:
                    break;
                }
                drift_image o1, o2;
                drift_result r1 = old_atrous(ctx, &col, a, n, z, &p, &o1);
                drift_result r2 = drift_denoise_atrous(ctx, &col, a, n, z, &p, &o2);
                runs++;
                if (r1 != DRIFT_OK || r2 != DRIFT_OK) {
                    printf("fail %d %d\n", r1, r2);
                    bad++;
                    continue;
                }
                int diff = 0;
                for (int y = 0; y < h; ++y)
                    if (memcmp(drift_image_pixel(&o1, 0, y), drift_image_pixel(&o2, 0, y),
                               (size_t)w * 12))
                        diff++;
                if (diff) {
                    printf("size %dx%d threads %d variant %d: %d rows differ\n", w, h, threads[t],
                           v, diff);
                    bad++;
                }
                drift_image_destroy(ctx, &o1);
                drift_image_destroy(ctx, &o2);
                drift_image_destroy(ctx, &col);
                drift_image_destroy(ctx, &alb);
                drift_image_destroy(ctx, &nor);
                drift_image_destroy(ctx, &dep);
                drift_context_destroy(ctx);
            }
    printf("%d runs, %d differ\n", runs, bad);
    return bad != 0;
}
