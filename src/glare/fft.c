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

// Rows by kiss_fftr, columns by kiss_fft, each pass spread over the context's threads.
// kiss_fftndr of Debian 12's kissfft 131.1.0 cannot be used: kiss_fftndr_alloc returns NULL
// (and a lenmem of SIZE_MAX) for 64 x 64 and most other 2-D sizes, with or without caller
// memory. A kiss_fftr plan has a scratch buffer inside, so each thread has its own; a kiss_fft
// plan is read-only when input and output differ, so one serves all threads.
// Columns are gathered COLUMN_BLOCK at a time: one 64-byte line of a row holds 8 of them, so
// each line read serves 8 columns instead of one (the transforms are the same).
#define COLUMN_BLOCK 8

struct drift__glare_rfft {
    drift_context *ctx;
    int32_t width, height, thread_count;
    kiss_fftr_cfg *rows; // one a thread
    kiss_fft_cfg cols;
    drift__cpx *column; // 2 * COLUMN_BLOCK * height a thread: gathered columns, transforms
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
    int32_t threads = drift_context_thread_count(ctx);
    threads = threads < 1 ? 1 : threads;
    size_t len_r = 0, len_c = 0;
    kiss_fftr_alloc(width, inverse ? 1 : 0, NULL, &len_r);
    kiss_fft_alloc(height, inverse ? 1 : 0, NULL, &len_c);
    drift__glare_rfft *f = drift_alloc(ctx, sizeof(*f));
    if (!f) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    f->ctx = ctx;
    f->width = width;
    f->height = height;
    f->thread_count = threads;
    f->rows = drift_alloc(ctx, (size_t)threads * sizeof(*f->rows));
    f->cols = len_c ? drift_alloc(ctx, len_c) : NULL;
    f->column =
        drift_alloc(ctx, (size_t)threads * 2 * COLUMN_BLOCK * (size_t)height * sizeof(drift__cpx));
    bool ok = f->rows && f->cols && f->column;
    for (int32_t t = 0; ok && t < threads; ++t) {
        void *mem = drift_alloc(ctx, len_r);
        size_t len = len_r;
        ok = mem && kiss_fftr_alloc(width, inverse ? 1 : 0, mem, &len) == mem;
        if (mem && !ok) {
            drift_free(ctx, mem);
        } else {
            f->rows[t] = mem;
        }
    }
    if (ok) {
        size_t len = len_c;
        ok = kiss_fft_alloc(height, inverse ? 1 : 0, f->cols, &len) == f->cols;
    }
    if (!ok) {
        drift__glare_rfft_destroy(ctx, f);
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    *out_fft = f;
    return DRIFT_OK;
}

void drift__glare_rfft_destroy(drift_context *ctx, drift__glare_rfft *fft)
{
    if (!fft) {
        return;
    }
    for (int32_t t = 0; fft->rows && t < fft->thread_count; ++t) {
        drift_free(ctx, fft->rows[t]);
    }
    drift_free(ctx, fft->rows);
    drift_free(ctx, fft->cols);
    drift_free(ctx, fft->column);
    drift_free(ctx, fft);
}

typedef struct rfft_job {
    const drift__glare_rfft *fft;
    const float *real_in;
    float *real_out;
    drift__cpx *spectrum;
    bool inverse;
} rfft_job;

// Columns [begin, end) of the spectrum, in blocks of COLUMN_BLOCK.
static void column_range(size_t begin, size_t end, int thread_index, void *user)
{
    const rfft_job *job = user;
    const drift__glare_rfft *fft = job->fft;
    const size_t w = (size_t)(fft->width / 2 + 1), h = (size_t)fft->height;
    drift__cpx *in = fft->column + (size_t)thread_index * 2 * COLUMN_BLOCK * h;
    drift__cpx *out = in + COLUMN_BLOCK * h;
    for (size_t x0 = begin; x0 < end; x0 += COLUMN_BLOCK) {
        size_t n = end - x0 < COLUMN_BLOCK ? end - x0 : COLUMN_BLOCK;
        for (size_t y = 0; y < h; ++y) {
            const drift__cpx *row = job->spectrum + y * w + x0;
            for (size_t b = 0; b < n; ++b) {
                in[b * h + y] = row[b];
            }
        }
        for (size_t b = 0; b < n; ++b) {
            kiss_fft(fft->cols, (const kiss_fft_cpx *)(const void *)(in + b * h),
                     (kiss_fft_cpx *)(void *)(out + b * h));
        }
        for (size_t y = 0; y < h; ++y) {
            drift__cpx *row = job->spectrum + y * w + x0;
            for (size_t b = 0; b < n; ++b) {
                row[b] = out[b * h + y];
            }
        }
    }
}

static void row_range(size_t begin, size_t end, int thread_index, void *user)
{
    const rfft_job *job = user;
    const drift__glare_rfft *fft = job->fft;
    const size_t w = (size_t)(fft->width / 2 + 1), rw = (size_t)fft->width;
    kiss_fftr_cfg cfg = fft->rows[thread_index];
    for (size_t y = begin; y < end; ++y) {
        kiss_fft_cpx *spec = (kiss_fft_cpx *)(void *)(job->spectrum + y * w);
        if (job->inverse) {
            kiss_fftri(cfg, spec, job->real_out + y * rw);
        } else {
            kiss_fftr(cfg, job->real_in + y * rw, spec);
        }
    }
}

void drift__glare_rfft_forward(const drift__glare_rfft *fft, const float *in, drift__cpx *out)
{
    rfft_job job = { fft, in, NULL, out, false };
    drift_parallel_for(fft->ctx, (size_t)fft->height, 16, row_range, &job);
    drift_parallel_for(fft->ctx, (size_t)(fft->width / 2 + 1), 16, column_range, &job);
}

void drift__glare_rfft_inverse(const drift__glare_rfft *fft, drift__cpx *in, float *out)
{
    rfft_job job = { fft, NULL, out, in, true };
    drift_parallel_for(fft->ctx, (size_t)(fft->width / 2 + 1), 16, column_range, &job);
    drift_parallel_for(fft->ctx, (size_t)fft->height, 16, row_range, &job);
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
