// The FFTs of src/glare: the PSF's complex 2-D transform is kissfft's (BSD-3, Debian
// libkissfft-dev) behind drift's allocator (the plans' memory comes from the context through
// kissfft's lenmem protocol); the convolution's real 2-D transforms run on fft_lanes.c, 8 rows
// or columns at a time in SIMD lanes (kissfft's scalar transforms were most of the pass's time).
#include "core/vectorise.h"
#include "glare_internal.h"

#include <kiss_fft.h>
#include <kiss_fftnd.h>
#include <math.h>
#include <stdint.h>
#include <string.h>

_Static_assert(sizeof(drift__cpx) == sizeof(kiss_fft_cpx), "drift__cpx mirrors kiss_fft_cpx");

struct drift__glare_fft {
    kiss_fftnd_cfg cfg;
};

// The real 2-D FFT: rows and columns both DRIFT__GLARE_LANES at a time in SIMD lanes
// (fft_lanes.c), each pass spread over the context's threads. A row of W reals is W/2 complex
// numbers (even and odd samples) whose W/2-point transform is split into the row's spectrum
// (the usual real-FFT identity, below). Columns are gathered 8 at a time: one 64-byte line of
// a spectrum row holds 8 of them, so each line read serves 8 columns. A short block's spare
// lanes transform zeros; every lane does the same operations whatever the others hold, so the
// spectrum does not depend on the blocks or the thread count.
// (kiss_fftndr of Debian 12's kissfft 131.1.0 cannot be used: kiss_fftndr_alloc returns NULL,
// and a lenmem of SIZE_MAX, for 64 x 64 and most other 2-D sizes.)
#define L DRIFT__GLARE_LANES

struct drift__glare_rfft {
    drift_context *ctx;
    int32_t width, height;
    drift__glare_lanes *half; // width / 2 points, the rows
    drift__glare_lanes *cols; // height points
    drift__cpx *split;        // exp(-+ i pi k / (width / 2)), k <= width / 2
    size_t buffer;            // floats of one thread's buffers: two of 2 L elements each
    float *buffers;           // one set a thread
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
    const int32_t n = width / 2;
    drift__glare_rfft *f = drift_alloc(ctx, sizeof(*f));
    if (!f) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    f->ctx = ctx;
    f->width = width;
    f->height = height;
    size_t elements = (size_t)(height > n + 1 ? height : n + 1);
    f->buffer = 4 * L * elements;
    f->buffers = drift_alloc(ctx, (size_t)threads * f->buffer * sizeof(float));
    f->split = drift_alloc(ctx, (size_t)(n + 1) * sizeof(drift__cpx));
    drift_result r = f->buffers && f->split ? DRIFT_OK : DRIFT_ERR_OUT_OF_MEMORY;
    if (r == DRIFT_OK) {
        r = drift__glare_lanes_create(ctx, n, inverse, &f->half);
    }
    if (r == DRIFT_OK) {
        r = drift__glare_lanes_create(ctx, height, inverse, &f->cols);
    }
    if (r != DRIFT_OK) {
        drift__glare_rfft_destroy(ctx, f);
        return r;
    }
    const double pi = 3.14159265358979323846264338328;
    for (int32_t k = 0; k <= n; ++k) {
        double a = (inverse ? pi : -pi) * (double)k / (double)n;
        f->split[k] = (drift__cpx){ (float)cos(a), (float)sin(a) };
    }
    *out_fft = f;
    return DRIFT_OK;
}

void drift__glare_rfft_destroy(drift_context *ctx, drift__glare_rfft *fft)
{
    if (!fft) {
        return;
    }
    drift__glare_lanes_destroy(ctx, fft->half);
    drift__glare_lanes_destroy(ctx, fft->cols);
    drift_free(ctx, fft->split);
    drift_free(ctx, fft->buffers);
    drift_free(ctx, fft);
}

// Real rows as read or written: row y's sample x at base[y * stride + x * step], the samples
// from `valid` on zeros (read) or left out (written). A plane of W floats a row, or one channel
// of an image.
typedef struct real_rows {
    float *base;
    size_t stride, step, valid;
} real_rows;

typedef struct rfft_job {
    const drift__glare_rfft *fft;
    real_rows real_in, real_out;
    drift__cpx *spectrum;
    const drift__glare_rfft *then; // the convolution: the inverse plan run after the kernel
    const float *kernel;           // its spectrum, lane layout (NULL: a plain transform)
    float norm;
} rfft_job;

static void gather_block(const drift__cpx *src, size_t stride, size_t h, size_t n, float *data)
{
    if (n == L) {
        drift__glare_lanes_gather(src, stride, h, data);
        return;
    }
    for (size_t y = 0; y < h; ++y) {
        const drift__cpx *row = src + y * stride;
        float *e = data + 2 * L * y;
        for (size_t b = 0; b < L; ++b) {
            e[b] = b < n ? row[b].re : 0.0f;
            e[L + b] = b < n ? row[b].im : 0.0f;
        }
    }
}

static void scatter_block(const float *out, size_t h, size_t n, drift__cpx *dst, size_t stride)
{
    if (n == L) {
        drift__glare_lanes_scatter(out, h, dst, stride);
        return;
    }
    for (size_t y = 0; y < h; ++y) {
        drift__cpx *row = dst + y * stride;
        const float *e = out + 2 * L * y;
        for (size_t b = 0; b < n; ++b) {
            row[b] = (drift__cpx){ e[b], e[L + b] };
        }
    }
}

// Columns [begin, end) of the spectrum, L at a time, one a lane; in the convolution, each
// block's forward transform is multiplied by the kernel's and transformed back while it is in
// cache.
static void column_range(size_t begin, size_t end, int thread_index, void *user)
{
    const rfft_job *job = user;
    const drift__glare_rfft *fft = job->fft;
    const size_t w = (size_t)(fft->width / 2 + 1), h = (size_t)fft->height;
    float *data = fft->buffers + (size_t)thread_index * fft->buffer;
    float *work = data + fft->buffer / 2;
    for (size_t x0 = begin; x0 < end; x0 += L) {
        size_t n = end - x0 < L ? end - x0 : L;
        gather_block(job->spectrum + x0, w, h, n, data);
        float *out = drift__glare_lanes_run(fft->cols, data, work);
        if (job->kernel) {
            drift__glare_lanes_multiply(out, job->kernel + (x0 / L) * 2 * L * h, h, job->norm);
            out = drift__glare_lanes_run(job->then->cols, out, out == data ? work : data);
        }
        scatter_block(out, h, n, job->spectrum + x0, w);
    }
}

// Rows [begin, end): z[m] = x[2m] + i x[2m + 1] (m < N = W / 2) in the lanes, Z its N-point
// transform, then X[k] = E[k] + w^k O[k] for k <= N, with E[k] = (Z[k] + conj Z[N - k]) / 2,
// O[k] = -i (Z[k] - conj Z[N - k]) / 2 (the transforms of the even and odd samples) and
// w = exp(-i pi / N).
static DRIFT_AVX2_CLONES void glare_row_forward(size_t begin, size_t end, int thread_index,
                                                void *user)
{
    const rfft_job *job = user;
    const drift__glare_rfft *fft = job->fft;
    const size_t n2 = (size_t)(fft->width / 2), w = n2 + 1;
    const real_rows in = job->real_in;
    float *data = fft->buffers + (size_t)thread_index * fft->buffer;
    float *work = data + fft->buffer / 2;
    for (size_t y0 = begin; y0 < end; y0 += L) {
        size_t n = end - y0 < L ? end - y0 : L;
        for (size_t b = 0; b < L; ++b) {
            const float *row = in.base + (y0 + (b < n ? b : 0)) * in.stride;
            size_t m = 0;
            for (; b < n && 2 * m + 1 < in.valid; ++m) {
                data[2 * L * m + b] = row[2 * m * in.step];
                data[2 * L * m + L + b] = row[(2 * m + 1) * in.step];
            }
            for (; m < n2; ++m) {
                data[2 * L * m + b] = b < n && 2 * m < in.valid ? row[2 * m * in.step] : 0.0f;
                data[2 * L * m + L + b] = 0.0f;
            }
        }
        const float *z = drift__glare_lanes_run(fft->half, data, work);
        for (size_t k = 0; k <= n2; ++k) {
            const float *zk = z + 2 * L * (k % n2), *zn = z + 2 * L * ((n2 - k) % n2);
            const drift__cpx t = fft->split[k];
            for (size_t b = 0; b < n; ++b) {
                float er = (zk[b] + zn[b]) * 0.5f, ei = (zk[L + b] - zn[L + b]) * 0.5f;
                float o_re = (zk[L + b] + zn[L + b]) * 0.5f, o_im = (zn[b] - zk[b]) * 0.5f;
                job->spectrum[(y0 + b) * w + k] = (drift__cpx){ er + (t.re * o_re - t.im * o_im),
                                                                ei + (t.re * o_im + t.im * o_re) };
            }
        }
    }
}

// The inverse of glare_row_forward (unnormalised: W times the row): for k < N,
// Z[k] = A[k] + i B[k] with A[k] = X[k] + conj X[N - k], B[k] = (X[k] - conj X[N - k]) w^-k,
// then the N-point inverse transform holds x[2m] + i x[2m + 1].
static DRIFT_AVX2_CLONES void glare_row_inverse(size_t begin, size_t end, int thread_index,
                                                void *user)
{
    const rfft_job *job = user;
    const drift__glare_rfft *fft = job->fft;
    const size_t n2 = (size_t)(fft->width / 2), w = n2 + 1;
    const real_rows out = job->real_out;
    float *data = fft->buffers + (size_t)thread_index * fft->buffer;
    float *work = data + fft->buffer / 2;
    for (size_t y0 = begin; y0 < end; y0 += L) {
        size_t n = end - y0 < L ? end - y0 : L;
        for (size_t k = 0; k < n2; ++k) {
            const drift__cpx t = fft->split[k];
            float *e = data + 2 * L * k;
            for (size_t b = 0; b < L; ++b) {
                const drift__cpx *row = job->spectrum + (y0 + (b < n ? b : 0)) * w;
                drift__cpx xk = row[k], xn = row[n2 - k];
                float ar = xk.re + xn.re, ai = xk.im - xn.im;
                float dr = xk.re - xn.re, di = xk.im + xn.im;
                float br = dr * t.re - di * t.im, bi = dr * t.im + di * t.re;
                e[b] = b < n ? ar - bi : 0.0f;
                e[L + b] = b < n ? ai + br : 0.0f;
            }
        }
        const float *z = drift__glare_lanes_run(fft->half, data, work);
        for (size_t b = 0; b < n; ++b) {
            float *row = out.base + (y0 + b) * out.stride;
            size_t m = 0;
            for (; 2 * m + 1 < out.valid; ++m) {
                row[2 * m * out.step] = z[2 * L * m + b];
                row[(2 * m + 1) * out.step] = z[2 * L * m + L + b];
            }
            if (2 * m < out.valid) {
                row[2 * m * out.step] = z[2 * L * m + b];
            }
        }
    }
}

// The columns in blocks of L (a block's kernel is stored whole): [begin, end) counts blocks.
static void column_blocks(size_t begin, size_t end, int thread_index, void *user)
{
    const rfft_job *job = user;
    size_t w = (size_t)(job->fft->width / 2 + 1);
    size_t last = end * L < w ? end * L : w;
    column_range(begin * L, last, thread_index, user);
}

static size_t column_block_count(const drift__glare_rfft *fft)
{
    return ((size_t)(fft->width / 2 + 1) + L - 1) / L;
}

void drift__glare_rfft_forward(const drift__glare_rfft *fft, const float *in, int32_t rows,
                               drift__cpx *out)
{
    // Rows past `rows` are zeros: so are their transforms.
    const size_t w = (size_t)(fft->width / 2 + 1);
    rows = rows < fft->height ? rows : fft->height;
    memset(out + (size_t)rows * w, 0, (size_t)(fft->height - rows) * w * sizeof(*out));
    rfft_job job = { .fft = fft,
                     .real_in = { (float *)(uintptr_t)in, (size_t)fft->width, 1,
                                  (size_t)fft->width },
                     .spectrum = out };
    drift_parallel_for(fft->ctx, (size_t)rows, 16, glare_row_forward, &job);
    drift_parallel_for(fft->ctx, column_block_count(fft), 2, column_blocks, &job);
}

void drift__glare_rfft_inverse(const drift__glare_rfft *fft, drift__cpx *in, int32_t rows,
                               float *out)
{
    rows = rows < fft->height ? rows : fft->height;
    rfft_job job = { .fft = fft,
                     .real_out = { out, (size_t)fft->width, 1, (size_t)fft->width },
                     .spectrum = in };
    drift_parallel_for(fft->ctx, column_block_count(fft), 2, column_blocks, &job);
    drift_parallel_for(fft->ctx, (size_t)rows, 16, glare_row_inverse, &job);
}

size_t drift__glare_rfft_kernel_floats(const drift__glare_rfft *fft)
{
    return column_block_count(fft) * 2 * L * (size_t)fft->height;
}

void drift__glare_rfft_kernel_layout(const drift__glare_rfft *fft, const drift__cpx *spectrum,
                                     float *kernel)
{
    const size_t w = (size_t)(fft->width / 2 + 1), h = (size_t)fft->height;
    for (size_t x0 = 0; x0 < w; x0 += L) {
        gather_block(spectrum + x0, w, h, w - x0 < L ? w - x0 : L, kernel + (x0 / L) * 2 * L * h);
    }
}

void drift__glare_rfft_convolve(const drift__glare_rfft *forward, const drift__glare_rfft *inverse,
                                const drift_image *in, int32_t channel, const float *kernel,
                                float norm, drift__cpx *spectrum, const drift_image *out)
{
    const size_t w = (size_t)(forward->width / 2 + 1);
    size_t rows = (size_t)(in->height < forward->height ? in->height : forward->height);
    memset(spectrum + rows * w, 0, ((size_t)forward->height - rows) * w * sizeof(*spectrum));
    // The image's channel read and written in place of a plane: zeros to its right and below.
    rfft_job job = { .fft = forward,
                     .real_in = { in->pixels + channel, (size_t)in->stride, (size_t)in->channels,
                                  (size_t)in->width },
                     .real_out = { out->pixels + channel, (size_t)out->stride,
                                   (size_t)out->channels, (size_t)out->width },
                     .spectrum = spectrum,
                     .then = inverse,
                     .kernel = kernel,
                     .norm = norm };
    drift_parallel_for(forward->ctx, rows, 16, glare_row_forward, &job);
    drift_parallel_for(forward->ctx, column_block_count(forward), 2, column_blocks, &job);
    job.fft = inverse;
    drift_parallel_for(forward->ctx, rows, 16, glare_row_inverse, &job);
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
