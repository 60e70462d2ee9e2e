// kissfft (BSD-3, Debian libkissfft-dev) behind drift's allocator: the plans' memory comes from
// the context (kissfft's lenmem protocol), so no FFT here is hand-written.
#include "glare_internal.h"

#include <kiss_fft.h>
#include <kiss_fftnd.h>
#include <kiss_fftr.h>
#include <string.h>

_Static_assert(sizeof(drift__cpx) == sizeof(kiss_fft_cpx), "drift__cpx mirrors kiss_fft_cpx");

struct drift__glare_fft {
    kiss_fftnd_cfg cfg;
};

// Rows by kiss_fftr, columns by kiss_fft. kiss_fftndr of Debian 12's kissfft 131.1.0 cannot
// be used: kiss_fftndr_alloc returns NULL (and a lenmem of SIZE_MAX) for 64 x 64 and most
// other 2-D sizes, with or without caller memory.
struct drift__glare_rfft {
    int32_t width, height;
    kiss_fftr_cfg rows;
    kiss_fft_cfg cols;
    drift__cpx *column; // 2 * height: gathered column and its transform
};

drift_result drift__glare_fft_create(drift_context *ctx, int32_t width, int32_t height,
                                     bool inverse, drift__glare_fft **out_fft)
{
    *out_fft = NULL;
    int dims[2] = { height, width };
    size_t len = 0;
    kiss_fftnd_alloc(dims, 2, inverse ? 1 : 0, NULL, &len);
    drift__glare_fft *f = drift_alloc(ctx, sizeof(*f));
    void *mem = len ? drift_alloc(ctx, len) : NULL;
    if (!f || !mem) {
        drift_free(ctx, f);
        drift_free(ctx, mem);
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    f->cfg = kiss_fftnd_alloc(dims, 2, inverse ? 1 : 0, mem, &len);
    DRIFT_CHECK(f->cfg == mem);
    *out_fft = f;
    return DRIFT_OK;
}

void drift__glare_fft_destroy(drift_context *ctx, drift__glare_fft *fft)
{
    if (fft) {
        drift_free(ctx, fft->cfg);
        drift_free(ctx, fft);
    }
}

void drift__glare_fft_run(const drift__glare_fft *fft, const drift__cpx *in, drift__cpx *out)
{
    kiss_fftnd(fft->cfg, (const kiss_fft_cpx *)(const void *)in, (kiss_fft_cpx *)(void *)out);
}

drift_result drift__glare_rfft_create(drift_context *ctx, int32_t width, int32_t height,
                                      bool inverse, drift__glare_rfft **out_fft)
{
    *out_fft = NULL;
    DRIFT_CHECK(width % 2 == 0);
    size_t len_r = 0, len_c = 0;
    kiss_fftr_alloc(width, inverse ? 1 : 0, NULL, &len_r);
    kiss_fft_alloc(height, inverse ? 1 : 0, NULL, &len_c);
    drift__glare_rfft *f = drift_alloc(ctx, sizeof(*f));
    void *mem_r = len_r ? drift_alloc(ctx, len_r) : NULL;
    void *mem_c = len_c ? drift_alloc(ctx, len_c) : NULL;
    drift__cpx *column = drift_alloc(ctx, 2 * (size_t)height * sizeof(drift__cpx));
    if (!f || !mem_r || !mem_c || !column) {
        drift_free(ctx, f);
        drift_free(ctx, mem_r);
        drift_free(ctx, mem_c);
        drift_free(ctx, column);
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    f->width = width;
    f->height = height;
    f->rows = kiss_fftr_alloc(width, inverse ? 1 : 0, mem_r, &len_r);
    f->cols = kiss_fft_alloc(height, inverse ? 1 : 0, mem_c, &len_c);
    f->column = column;
    DRIFT_CHECK(f->rows == mem_r && f->cols == mem_c);
    *out_fft = f;
    return DRIFT_OK;
}

void drift__glare_rfft_destroy(drift_context *ctx, drift__glare_rfft *fft)
{
    if (fft) {
        drift_free(ctx, fft->rows);
        drift_free(ctx, fft->cols);
        drift_free(ctx, fft->column);
        drift_free(ctx, fft);
    }
}

// The column pass over the width / 2 + 1 spectrum columns, in place in `spectrum`.
static void column_pass(const drift__glare_rfft *fft, drift__cpx *spectrum)
{
    const size_t w = (size_t)(fft->width / 2 + 1), h = (size_t)fft->height;
    drift__cpx *in = fft->column, *out = fft->column + h;
    for (size_t x = 0; x < w; ++x) {
        for (size_t y = 0; y < h; ++y) {
            in[y] = spectrum[y * w + x];
        }
        kiss_fft(fft->cols, (const kiss_fft_cpx *)(const void *)in, (kiss_fft_cpx *)(void *)out);
        for (size_t y = 0; y < h; ++y) {
            spectrum[y * w + x] = out[y];
        }
    }
}

void drift__glare_rfft_forward(const drift__glare_rfft *fft, const float *in, drift__cpx *out)
{
    const size_t w = (size_t)(fft->width / 2 + 1);
    for (int32_t y = 0; y < fft->height; ++y) {
        kiss_fftr(fft->rows, in + (size_t)y * (size_t)fft->width,
                  (kiss_fft_cpx *)(void *)(out + (size_t)y * w));
    }
    column_pass(fft, out);
}

void drift__glare_rfft_inverse(const drift__glare_rfft *fft, drift__cpx *in, float *out)
{
    const size_t w = (size_t)(fft->width / 2 + 1);
    column_pass(fft, in);
    for (int32_t y = 0; y < fft->height; ++y) {
        kiss_fftri(fft->rows, (const kiss_fft_cpx *)(const void *)(in + (size_t)y * w),
                   out + (size_t)y * (size_t)fft->width);
    }
}

int32_t drift__glare_fft_size(int32_t n)
{
    for (int32_t m = n < 2 ? 2 : n;; ++m) {
        if (m % 2) {
            continue;
        }
        int32_t r = m;
        while (r % 2 == 0) {
            r /= 2;
        }
        while (r % 3 == 0) {
            r /= 3;
        }
        while (r % 5 == 0) {
            r /= 5;
        }
        if (r == 1) {
            return m;
        }
    }
}
