// Stage 5, regression: blockwise multi-order feature regression (Koskela, Immonen, Mäkitalo,
// Foi, Viitanen, Jääskeläinen, Kultala & Takala 2019, "Blockwise Multi-Order Feature
// Regression for Real-Time Path-Tracing Reconstruction", ACM TOG 38(5)), first order in the
// buffers and second order in depth and screen position, without its temporal part.
//
// The image is covered by blocks (32x32 for REGRESSION; REGRESSION_RESIDUAL's size is a knob)
// whose origins are half a block apart (so that every pixel lies in four of them). In each block
// the irradiance of every channel is fitted by least squares to the features
//   f = (1, n_x, n_y, n_z, z, z^2, x, y, x^2, y^2)
// and, with a guide image (drift_denoise_guided's regression), its three demodulated channels
// g_r, g_g, g_b as well (13 features): where the guide has a shadow or a reflection the fit can
// scale it rather than smooth it away;
// each but the constant scaled to [-1, 1] over the block (BMFR §3.2), solving the normal
// equations (F^T F + lambda I) beta = F^T c by Cholesky with lambda = 1e-3 (max diagonal).
// A pixel's output is its four blocks' fits blended by tent weights (1 - |d_x| / s)
// (1 - |d_y| / s) from each block's centre (s the half block), which sum to 1: no block seams.
#include "feature_internal.h"

#include <math.h>
#include <string.h>

#define BMFR_FEATURES 13 // the most: 10 without a guide

typedef struct bmfr_block {
    float lo[BMFR_FEATURES], inv_half[BMFR_FEATURES]; // scaled = (f - lo) * inv_half - 1
    float beta[BMFR_FEATURES][3];
} bmfr_block;

typedef struct bmfr_job {
    const denoise_frame *f;
    bmfr_block *blocks;
    int32_t blocks_x;
    int32_t stride; // block origins apart, half the block's side
    float *out;
} bmfr_job;

static void raw_features(const denoise_frame *f, int32_t x, int32_t y, float *out)
{
    size_t i = (size_t)y * (size_t)f->width + (size_t)x;
    float z = f->depth[i], u = (float)x, v = (float)y;
    out[0] = 1.0f;
    out[1] = f->normal[3 * i];
    out[2] = f->normal[3 * i + 1];
    out[3] = f->normal[3 * i + 2];
    out[4] = z;
    out[5] = z * z;
    out[6] = u;
    out[7] = v;
    out[8] = u * u;
    out[9] = v * v;
    if (f->guide) {
        out[10] = f->guide[3 * i];
        out[11] = f->guide[3 * i + 1];
        out[12] = f->guide[3 * i + 2];
    }
}

static int feature_count(const denoise_frame *f)
{
    return f->guide ? BMFR_FEATURES : BMFR_FEATURES - 3;
}

static void scaled_features(const denoise_frame *f, const bmfr_block *b, int32_t x, int32_t y,
                            float *out)
{
    raw_features(f, x, y, out);
    for (int k = 1; k < feature_count(f); ++k) {
        out[k] = (out[k] - b->lo[k]) * b->inv_half[k] - 1.0f;
    }
}

// Solves (A + lambda I) x = b for the three right-hand sides by Cholesky; A is symmetric
// positive semi-definite (a Gram matrix), so with the ridge the factor exists.
static void solve_ridge(int n, double a[BMFR_FEATURES][BMFR_FEATURES], double b[BMFR_FEATURES][3],
                        float beta[BMFR_FEATURES][3])
{
    double largest = 0.0;
    for (int i = 0; i < n; ++i) {
        largest = fmax(largest, a[i][i]);
    }
    double lambda = 1e-3 * largest + 1e-12;
    double l[BMFR_FEATURES][BMFR_FEATURES] = { { 0.0 } };
    for (int i = 0; i < n; ++i) {
        for (int j = 0; j <= i; ++j) {
            double s = a[i][j] + (i == j ? lambda : 0.0);
            for (int k = 0; k < j; ++k) {
                s -= l[i][k] * l[j][k];
            }
            l[i][j] = i == j ? sqrt(fmax(s, 1e-300)) : s / l[j][j];
        }
    }
    for (int c = 0; c < 3; ++c) {
        double y[BMFR_FEATURES];
        for (int i = 0; i < n; ++i) {
            double s = b[i][c];
            for (int k = 0; k < i; ++k) {
                s -= l[i][k] * y[k];
            }
            y[i] = s / l[i][i];
        }
        for (int i = n - 1; i >= 0; --i) {
            double s = y[i];
            for (int k = i + 1; k < n; ++k) {
                s -= l[k][i] * y[k];
            }
            y[i] = s / l[i][i];
            beta[i][c] = (float)y[i];
        }
    }
}

static void fit_blocks(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    const bmfr_job *job = user;
    const denoise_frame *f = job->f;
    for (size_t bi = begin; bi < end; ++bi) {
        bmfr_block *b = &job->blocks[bi];
        int32_t ox = (int32_t)(bi % (size_t)job->blocks_x) * job->stride - job->stride;
        int32_t oy = (int32_t)(bi / (size_t)job->blocks_x) * job->stride - job->stride;
        int32_t x0 = ox < 0 ? 0 : ox, y0 = oy < 0 ? 0 : oy;
        int32_t x1 = ox + (2 * job->stride) < f->width ? ox + (2 * job->stride) : f->width;
        int32_t y1 = oy + (2 * job->stride) < f->height ? oy + (2 * job->stride) : f->height;
        const int n = feature_count(f);
        float lo[BMFR_FEATURES], hi[BMFR_FEATURES], raw[BMFR_FEATURES];
        memset(b, 0, sizeof *b);
        for (int k = 0; k < n; ++k) {
            lo[k] = INFINITY;
            hi[k] = -INFINITY;
        }
        for (int32_t y = y0; y < y1; ++y) {
            for (int32_t x = x0; x < x1; ++x) {
                raw_features(f, x, y, raw);
                for (int k = 0; k < n; ++k) {
                    lo[k] = fminf(lo[k], raw[k]);
                    hi[k] = fmaxf(hi[k], raw[k]);
                }
            }
        }
        for (int k = 0; k < n; ++k) {
            float half = 0.5f * (hi[k] - lo[k]);
            b->lo[k] = x1 > x0 && y1 > y0 ? lo[k] : 0.0f;
            b->inv_half[k] = half > 1e-12f ? 1.0f / half : 0.0f; // constant: scaled to -1
        }
        double a[BMFR_FEATURES][BMFR_FEATURES] = { { 0.0 } }, rhs[BMFR_FEATURES][3] = { { 0.0 } };
        float fs[BMFR_FEATURES];
        for (int32_t y = y0; y < y1; ++y) {
            for (int32_t x = x0; x < x1; ++x) {
                scaled_features(f, b, x, y, fs);
                const float *c = f->irr + 3 * ((size_t)y * (size_t)f->width + (size_t)x);
                for (int i = 0; i < n; ++i) {
                    for (int j = 0; j <= i; ++j) {
                        a[i][j] += (double)fs[i] * (double)fs[j];
                    }
                    for (int k = 0; k < 3; ++k) {
                        rhs[i][k] += (double)fs[i] * (double)c[k];
                    }
                }
            }
        }
        for (int i = 0; i < n; ++i) {
            for (int j = i + 1; j < n; ++j) {
                a[i][j] = a[j][i];
            }
        }
        solve_ridge(n, a, rhs, b->beta);
    }
}

static void blend_rows(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    const bmfr_job *job = user;
    const denoise_frame *f = job->f;
    float fs[BMFR_FEATURES];
    for (size_t yy = begin; yy < end; ++yy) {
        int32_t y = (int32_t)yy;
        for (int32_t x = 0; x < f->width; ++x) {
            float sum[3] = { 0.0f, 0.0f, 0.0f };
            for (int32_t by = y / job->stride; by <= y / job->stride + 1; ++by) {
                float wy = 1.0f - fabsf((float)y + 0.5f - (float)(by * job->stride)) / job->stride;
                for (int32_t bx = x / job->stride; bx <= x / job->stride + 1; ++bx) {
                    float wx =
                        1.0f - fabsf((float)x + 0.5f - (float)(bx * job->stride)) / job->stride;
                    const bmfr_block *b =
                        &job->blocks[(size_t)by * (size_t)job->blocks_x + (size_t)bx];
                    scaled_features(f, b, x, y, fs);
                    for (int k = 0; k < 3; ++k) {
                        float v = 0.0f;
                        for (int i = 0; i < feature_count(f); ++i) {
                            v += fs[i] * b->beta[i][k];
                        }
                        sum[k] += wx * wy * v;
                    }
                }
            }
            for (int k = 0; k < 3; ++k) {
                job->out[3 * ((size_t)y * (size_t)f->width + (size_t)x) + k] =
                    f->params.signed_color ? sum[k] : fmaxf(sum[k], 0.0f);
            }
        }
    }
}

drift_result denoise_regression(const denoise_frame *f, int32_t block, float *out)
{
    int32_t stride = block / 2;
    int32_t blocks_x = f->width / stride + 2, blocks_y = f->height / stride + 2;
    bmfr_job job = { .f = f, .blocks_x = blocks_x, .stride = stride, .out = out };
    job.blocks = drift_alloc(f->ctx, (size_t)blocks_x * (size_t)blocks_y * sizeof(bmfr_block));
    if (!job.blocks) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    drift_parallel_for(f->ctx, (size_t)blocks_x * (size_t)blocks_y, 4, fit_blocks, &job);
    drift_parallel_for(f->ctx, (size_t)f->height, 4, blend_rows, &job);
    drift_free(f->ctx, job.blocks);
    return DRIFT_OK;
}
