// Temporal glare (Ritschel 2009, thesis ch. 8): the nine objective tests of thesis-spec §6.7 —
// the FFT against a naive DFT, the Airy pattern, chromatic scaling, energy, identity, the pupil
// model, point symmetry, determinism and bounded change, supersampling — and bad input.
// ctest-labels: slow
#include "drift/glare.h"
#include "drift/image.h"
#include "drift_test.h"
#include "glare/glare_internal.h"
#include "glare/glare_tests.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

// --- helpers ---

// The monochromatic PSF of a plain disk pupil of diameter d_px pixels (Fraunhofer unless e).
static float *disk_psf(drift_context *ctx, int32_t n, double d_px, int32_t ss, const drift__cpx *e)
{
    float *hires = malloc(sizeof(float) * (size_t)(n * ss) * (size_t)(n * ss));
    float *ap = malloc(sizeof(float) * (size_t)n * (size_t)n);
    float *psf = malloc(sizeof(float) * (size_t)n * (size_t)n);
    drift__cpx *scratch = malloc(sizeof(drift__cpx) * 2 * (size_t)n * (size_t)n);
    assert_non_null(hires);
    assert_non_null(ap);
    assert_non_null(psf);
    assert_non_null(scratch);
    drift__glare_fft *fft = NULL;
    assert_int_equal(drift__glare_fft_create(ctx, n, n, false, &fft), DRIFT_OK);
    // Width n mm: one pixel per mm, so the pupil diameter in mm is d_px.
    drift__glare_aperture_desc ad = { .pupil_mm = d_px };
    drift__glare_aperture_draw(&ad, n, ss, (double)n, hires, ap);
    drift__glare_psf_mono(fft, ap, e, n, scratch, psf, NULL);
    drift__glare_fft_destroy(ctx, fft);
    free(scratch);
    free(ap);
    free(hires);
    return psf;
}

double at(const float *img, int32_t n, int32_t x, int32_t y)
{
    return img[(size_t)y * (size_t)n + (size_t)x];
}

// Radius of the first minimum along +x from the centre, refined by a parabola through the three
// samples around it.
static double first_minimum(const float *psf, int32_t n)
{
    int32_t c = n / 2;
    for (int32_t i = 1; i < c - 1; ++i) {
        double a = at(psf, n, c + i - 1, c), b = at(psf, n, c + i, c), d = at(psf, n, c + i + 1, c);
        if (b < a && b <= d) {
            double den = a - 2.0 * b + d;
            return i + (den > 0.0 ? 0.5 * (a - d) / den : 0.0);
        }
    }
    return -1.0;
}

drift_image make_image(drift_context *ctx, int32_t w, int32_t h, uint32_t seed, int32_t border)
{
    drift_image img;
    assert_int_equal(drift_image_create(ctx, w, h, 3, &img), DRIFT_OK);
    for (int32_t y = border; y < h - border; ++y) {
        for (int32_t x = border; x < w - border; ++x) {
            for (int32_t c = 0; c < 3; ++c) {
                drift_image_pixel(&img, x, y)[c] =
                    test_hash_unit(seed * 7919u + (uint32_t)((y * w + x) * 3 + c));
            }
        }
    }
    return img;
}

// --- 1. FFT ---

static void test_glare_fft_matches_naive_dft_and_round_trips(void **state)
{
    (void)state;
    drift_context *ctx = test_context(1, NULL);
    const int32_t w = 16, h = 16;
    drift__cpx in[256], out[256], back[256];
    for (int32_t i = 0; i < w * h; ++i) {
        in[i] = (drift__cpx){ test_hash_unit((uint32_t)i) - 0.5f,
                              test_hash_unit((uint32_t)i + 1000u) - 0.5f };
    }
    drift__glare_fft *fwd = NULL, *inv = NULL;
    assert_int_equal(drift__glare_fft_create(ctx, w, h, false, &fwd), DRIFT_OK);
    assert_int_equal(drift__glare_fft_create(ctx, w, h, true, &inv), DRIFT_OK);
    drift__glare_fft_run(fwd, in, out);
    double err = 0.0, norm = 0.0;
    for (int32_t ky = 0; ky < h; ++ky) {
        for (int32_t kx = 0; kx < w; ++kx) {
            double re = 0.0, im = 0.0;
            for (int32_t y = 0; y < h; ++y) {
                for (int32_t x = 0; x < w; ++x) {
                    double a = -2.0 * PI * ((double)kx * x / w + (double)ky * y / h);
                    double ir = in[y * w + x].re, ii = in[y * w + x].im;
                    re += ir * cos(a) - ii * sin(a);
                    im += ir * sin(a) + ii * cos(a);
                }
            }
            double dr = re - (double)out[ky * w + kx].re, di = im - (double)out[ky * w + kx].im;
            err += dr * dr + di * di;
            norm += re * re + im * im;
        }
    }
    assert_true(sqrt(err / norm) < 1e-4);
    drift__glare_fft_run(inv, out, back);
    for (int32_t i = 0; i < w * h; ++i) {
        assert_near((double)back[i].re / (w * h), (double)in[i].re, 1e-5);
        assert_near((double)back[i].im / (w * h), (double)in[i].im, 1e-5);
    }
    drift__glare_fft_destroy(ctx, fwd);
    drift__glare_fft_destroy(ctx, inv);
    drift_context_destroy(ctx);
}

// The real 2-D FFT (rows by kiss_fftr, columns by kiss_fft) against the complex one, and its
// round trip, at sizes with factors 2, 3 and 5, with 1 and 3 threads.
static void test_glare_real_fft_matches_complex_fft(void **state)
{
    (void)state;
    const int32_t sizes[][2] = { { 60, 48 }, { 64, 64 }, { 90, 50 }, { 16, 30 } };
    for (int32_t threads = 1; threads <= 3; threads += 2) {
        drift_context *ctx = test_context(threads, NULL);
        for (size_t s = 0; s < sizeof(sizes) / sizeof(sizes[0]); ++s) {
            const int32_t w = sizes[s][0], h = sizes[s][1], hw = w / 2 + 1;
            float *real = malloc(sizeof(float) * (size_t)(w * h));
            float *back = malloc(sizeof(float) * (size_t)(w * h));
            drift__cpx *spec = malloc(sizeof(drift__cpx) * (size_t)(hw * h));
            drift__cpx *cin = malloc(sizeof(drift__cpx) * (size_t)(w * h));
            drift__cpx *cout = malloc(sizeof(drift__cpx) * (size_t)(w * h));
            for (int32_t i = 0; i < w * h; ++i) {
                real[i] = test_hash_unit((uint32_t)i * 3u + 1u) - 0.3f;
                cin[i] = (drift__cpx){ real[i], 0.0f };
            }
            drift__glare_rfft *fwd = NULL, *inv = NULL;
            drift__glare_fft *cfft = NULL;
            assert_int_equal(drift__glare_rfft_create(ctx, w, h, false, &fwd), DRIFT_OK);
            assert_int_equal(drift__glare_rfft_create(ctx, w, h, true, &inv), DRIFT_OK);
            assert_int_equal(drift__glare_fft_create(ctx, w, h, false, &cfft), DRIFT_OK);
            drift__glare_rfft_forward(fwd, real, h, spec);
            drift__glare_fft_run(cfft, cin, cout);
            for (int32_t y = 0; y < h; ++y) {
                for (int32_t x = 0; x < hw; ++x) {
                    assert_near(spec[y * hw + x].re, cout[y * w + x].re, 1e-3);
                    assert_near(spec[y * hw + x].im, cout[y * w + x].im, 1e-3);
                }
            }
            drift__glare_rfft_inverse(inv, spec, h, back);
            for (int32_t i = 0; i < w * h; ++i) {
                assert_near((double)back[i] / (w * h), real[i], 1e-5);
            }
            drift__glare_rfft_destroy(ctx, fwd);
            drift__glare_rfft_destroy(ctx, inv);
            drift__glare_fft_destroy(ctx, cfft);
            free(cout);
            free(cin);
            free(spec);
            free(back);
            free(real);
        }
        drift_context_destroy(ctx);
    }
}

// The lane FFT (fft_lanes.c: the columns of the real 2-D FFT, 8 at a time) against a double
// DFT of each lane, both directions, at sizes with every radix; and each lane's result the same
// to the bit whatever the other lanes hold. Bound: the rms error under 2e-6 of the rms of the
// transform (float rounding of log n stages; kissfft's own is of that size).
static void test_glare_lane_fft_matches_double_dft(void **state)
{
    (void)state;
    drift_context *ctx = test_context(1, NULL);

    enum {
        L = DRIFT__GLARE_LANES
    };

    const int32_t sizes[] = { 1,  2,  3,  4,  5,  6,  8,  9,   10,  12,  15,  16, 25,
                              27, 30, 45, 48, 60, 64, 81, 100, 120, 135, 243, 250 };
    for (size_t s = 0; s < sizeof(sizes) / sizeof(sizes[0]); ++s) {
        const int32_t n = sizes[s];
        for (int inverse = 0; inverse < 2; ++inverse) {
            drift__glare_lanes *plan = NULL;
            assert_int_equal(drift__glare_lanes_create(ctx, n, inverse, &plan), DRIFT_OK);
            float *data = malloc(sizeof(float) * 2 * L * (size_t)n);
            float *work = malloc(sizeof(float) * 2 * L * (size_t)n);
            float *keep = malloc(sizeof(float) * 2 * L * (size_t)n);
            assert_non_null(data);
            assert_non_null(work);
            assert_non_null(keep);
            for (int32_t i = 0; i < 2 * L * n; ++i) {
                data[i] = test_hash_unit((uint32_t)(i * 7 + n * 131 + inverse)) - 0.4f;
            }
            memcpy(keep, data, sizeof(float) * 2 * L * (size_t)n);
            const float *out = drift__glare_lanes_run(plan, data, work);
            double err = 0.0, norm = 0.0, sign = inverse ? 1.0 : -1.0;
            for (int32_t b = 0; b < L; ++b) {
                for (int32_t k = 0; k < n; ++k) {
                    double re = 0.0, im = 0.0;
                    for (int32_t j = 0; j < n; ++j) {
                        double a = sign * 6.283185307179586 * (double)((int64_t)j * k % n) / n;
                        double xr = keep[2 * L * j + b], xi = keep[2 * L * j + L + b];
                        re += xr * cos(a) - xi * sin(a);
                        im += xr * sin(a) + xi * cos(a);
                    }
                    double dr = (double)out[2 * L * k + b] - re,
                           di = (double)out[2 * L * k + L + b] - im;
                    err += dr * dr + di * di;
                    norm += re * re + im * im;
                }
            }
            assert_true(sqrt(err / norm) < 2e-6);
            // Lane 5's input moved to lane 2, the other lanes new: lane 2 gives lane 5's result.
            float *first = malloc(sizeof(float) * 2 * L * (size_t)n);
            assert_non_null(first);
            memcpy(first, out, sizeof(float) * 2 * L * (size_t)n);
            for (int32_t j = 0; j < n; ++j) {
                for (int32_t b = 0; b < L; ++b) {
                    data[2 * L * j + b] = b == 2 ? keep[2 * L * j + 5] : (float)(j * b) * 0.1f;
                    data[2 * L * j + L + b] = b == 2 ? keep[2 * L * j + L + 5] : -(float)b;
                }
            }
            out = drift__glare_lanes_run(plan, data, work);
            for (int32_t k = 0; k < n; ++k) {
                assert_memory_equal(&out[2 * L * k + 2], &first[2 * L * k + 5], sizeof(float));
                assert_memory_equal(&out[2 * L * k + L + 2], &first[2 * L * k + L + 5],
                                    sizeof(float));
            }
            free(first);
            free(keep);
            free(work);
            free(data);
            drift__glare_lanes_destroy(ctx, plan);
        }
    }
    drift__glare_lanes *bad = NULL;
    assert_int_equal(drift__glare_lanes_create(ctx, 14, false, &bad), DRIFT_ERR_INVALID_ARGUMENT);
    assert_null(bad);
    drift_context_destroy(ctx);
}

// The FFT convolution against the direct sum in double (a random image and PSF, the PSF's
// centre at (k/2, k/2), zero outside the image), on 1 and 3 threads: within 1e-5 of the
// largest output value (the FFT's float rounding spreads over the whole image), and the two
// thread counts' images the same to the bit.
static void test_glare_convolution_matches_direct_sum(void **state)
{
    (void)state;
    const int32_t k = 20, w = 70, h = 45;
    float *psf = malloc(sizeof(float) * (size_t)(k * k * 3));
    assert_non_null(psf);
    for (int32_t i = 0; i < k * k * 3; ++i) {
        psf[i] = test_hash_unit((uint32_t)i * 5u + 3u) / (float)(k * k);
    }
    drift_image out[2];
    drift_context *ctxs[2] = { test_context(1, NULL), test_context(3, NULL) };
    for (int32_t t = 0; t < 2; ++t) {
        drift_context *ctx = ctxs[t];
        drift_image in = make_image(ctx, w, h, 17, 0);
        drift_image_set3(&in, 30, 20, (drift_vec3){ 40.0f, 20.0f, 10.0f }); // a bright source
        drift__glare_conv conv = { 0 };
        assert_int_equal(drift_image_create(ctx, w, h, 3, &out[t]), DRIFT_OK);
        assert_int_equal(drift__glare_convolve(ctx, &conv, &in, psf, k, true, &out[t]), DRIFT_OK);
        if (t == 0) {
            double worst = 0.0, peak = 0.0;
            for (int32_t y = 0; y < h; ++y) {
                for (int32_t x = 0; x < w; ++x) {
                    for (int32_t ch = 0; ch < 3; ++ch) {
                        double sum = 0.0;
                        for (int32_t v = 0; v < k; ++v) {
                            for (int32_t u = 0; u < k; ++u) {
                                int32_t sx = x - (u - k / 2), sy = y - (v - k / 2);
                                if (sx >= 0 && sx < w && sy >= 0 && sy < h) {
                                    sum += (double)psf[(v * k + u) * 3 + ch] *
                                           (double)drift_image_pixel(&in, sx, sy)[ch];
                                }
                            }
                        }
                        double d = fabs((double)drift_image_pixel(&out[t], x, y)[ch] - sum);
                        worst = d > worst ? d : worst;
                        peak = fabs(sum) > peak ? fabs(sum) : peak;
                    }
                }
            }
            assert_true(worst <= 1e-5 * peak);
        }
        drift__glare_conv_release(ctx, &conv);
        drift_image_destroy(ctx, &in);
    }
    for (int32_t y = 0; y < h; ++y) {
        assert_memory_equal(drift_image_pixel(&out[0], 0, y), drift_image_pixel(&out[1], 0, y),
                            sizeof(float) * 3 * w);
    }
    for (int32_t t = 0; t < 2; ++t) {
        drift_image_destroy(ctxs[t], &out[t]);
        drift_context_destroy(ctxs[t]);
    }
    free(psf);
}

// --- 2. Airy ---

static void test_glare_airy_rings_and_energy(void **state)
{
    (void)state;
    drift_context *ctx = test_context(1, NULL);
    // N = 512 and a 64-pixel pupil: the first dark ring at 1.2197 N / D = 9.76 pixels.
    const int32_t n = 512;
    const double d = 64.0;
    float *psf = disk_psf(ctx, n, d, 2, NULL);
    double r1 = first_minimum(psf, n);
    assert_true(fabs(r1 - 1.2197 * n / d) < 1.0);
    // First side lobe at 1.635 lambda / D with I / I0 = 0.0175.
    int32_t c = n / 2;
    double peak = at(psf, n, c, c), lobe = 0.0, lobe_r = 0.0;
    for (int32_t i = (int32_t)r1; i < (int32_t)(2.2 * n / d); ++i) {
        if (at(psf, n, c + i, c) > lobe) {
            lobe = at(psf, n, c + i, c);
            lobe_r = i;
        }
    }
    assert_true(fabs(lobe_r - 1.635 * n / d) <= 1.0);
    assert_true(fabs(lobe / peak - 0.0175) < 0.003);
    // Encircled energy inside the first three dark rings (1.2197, 2.2331, 3.2383 N / D).
    const double rings[3] = { 1.2197, 2.2331, 3.2383 }, energy[3] = { 0.838, 0.910, 0.938 };
    for (int32_t k = 0; k < 3; ++k) {
        double rr = rings[k] * n / d, sum = 0.0;
        for (int32_t y = 0; y < n; ++y) {
            for (int32_t x = 0; x < n; ++x) {
                double dx = x - c, dy = y - c;
                if (dx * dx + dy * dy <= rr * rr) {
                    sum += at(psf, n, x, y);
                }
            }
        }
        assert_true(fabs(sum - energy[k]) < 0.015);
    }
    // Radial symmetry: the profile along the diagonal matches the one along the axis.
    for (double r = 2.0; r < 30.0; r += 1.5) {
        double axis = drift__glare_bilinear(psf, n, c + r, c);
        double diag = drift__glare_bilinear(psf, n, c + r / sqrt(2.0), c + r / sqrt(2.0));
        assert_true(fabs(axis - diag) < 0.02 * peak);
    }
    free(psf);
    drift_context_destroy(ctx);
}

// --- 3. Chromatic scaling ---

static void test_glare_chromatic_scaling(void **state)
{
    (void)state;
    drift_context *ctx = test_context(1, NULL);
    const int32_t n = 256;
    const double l1 = 575.0, l2 = 700.0, d = 32.0;
    // F_l2 directly: on the same angular grid the aperture texture is l2 / l1 wider, so the
    // pupil covers d l1 / l2 pixels.
    float *f1 = disk_psf(ctx, n, d, 4, NULL);
    float *f2 = disk_psf(ctx, n, d * l1 / l2, 4, NULL);
    double s = l1 / l2, err = 0.0, ref = 0.0;
    int32_t c = n / 2;
    for (int32_t y = c - 40; y <= c + 40; ++y) {
        for (int32_t x = c - 40; x <= c + 40; ++x) {
            double scaled = s * s * drift__glare_bilinear(f1, n, c + (x - c) * s, c + (y - c) * s);
            err += fabs(scaled - at(f2, n, x, y));
            ref += at(f2, n, x, y);
        }
    }
    assert_true(err / ref < 0.05);
    // The RGB PSF: red is wider than green, green wider than blue (second moments), by about the
    // ratio of the channels' mean wavelengths.
    float *rgb = malloc(sizeof(float) * (size_t)n * (size_t)n * 3);
    assert_non_null(rgb);
    void *taps = malloc(drift__glare_psf_rgb_scratch(n, 1.0));
    assert_non_null(taps);
    drift__glare_psf_rgb(f1, n, 32, 1.0, n, taps, rgb);
    free(taps);
    double m2[3] = { 0, 0, 0 }, sum[3] = { 0, 0, 0 };
    for (int32_t y = 0; y < n; ++y) {
        for (int32_t x = 0; x < n; ++x) {
            double r2 = (double)(x - c) * (x - c) + (double)(y - c) * (y - c);
            for (int32_t ch = 0; ch < 3; ++ch) {
                double v = rgb[((size_t)y * (size_t)n + (size_t)x) * 3 + (size_t)ch];
                m2[ch] += v * fmin(r2, 40.0 * 40.0);
                sum[ch] += v;
            }
        }
    }
    for (int32_t ch = 0; ch < 3; ++ch) {
        assert_near(sum[ch], 1.0, 1e-5);
    }
    double wr = sqrt(m2[0]), wg = sqrt(m2[1]), wb = sqrt(m2[2]);
    assert_true(wr > wg && wg > wb);
    assert_true(wr / wb > 1.1 && wr / wb < 1.6);
    free(rgb);
    free(f2);
    free(f1);
    drift_context_destroy(ctx);
}

// --- 4. Energy ---

static void test_glare_parseval_unit_sum_and_flux(void **state)
{
    (void)state;
    drift_context *ctx = test_context(1, NULL);
    const int32_t n = 64;
    float ap[64 * 64], hires[128 * 128], psf[64 * 64];
    drift__cpx scratch[2 * 64 * 64], e[64 * 64];
    drift__glare_disk disks[2] = { { 1.0f, 2.0f, 0.8f }, { -3.0f, 0.5f, 0.3f } };
    drift__glare_aperture_desc ad = { .pupil_mm = 30.0, .disks = disks, .disk_count = 2 };
    drift__glare_aperture_draw(&ad, n, 2, 64.0, hires, ap);
    drift__glare_fresnel_table(n, 64.0, 575.0, 2000.0, e);
    drift__glare_fft *fft = NULL;
    assert_int_equal(drift__glare_fft_create(ctx, n, n, false, &fft), DRIFT_OK);
    double power = 0.0, p2 = 0.0;
    drift__glare_psf_mono(fft, ap, e, n, scratch, psf, &power);
    double psf_sum = 0.0;
    for (int32_t i = 0; i < n * n; ++i) {
        p2 += (double)ap[i] * (double)ap[i];
        psf_sum += (double)psf[i];
    }
    // Parseval: sum |FFT|^2 = N^2 sum |P E|^2 (|E| = 1).
    assert_true(fabs(power / ((double)n * n * p2) - 1.0) < 1e-4);
    assert_near(psf_sum, 1.0, 1e-5);

    // Linear convolution keeps each channel's flux (nothing spills out: the image is zero
    // within k/2 of the border).
    const int32_t k = 16;
    float *rgb = malloc(sizeof(float) * (size_t)(k * k * 3));
    assert_non_null(rgb);
    void *taps = malloc(drift__glare_psf_rgb_scratch(k, 4.0));
    assert_non_null(taps);
    drift__glare_psf_rgb(psf, n, 32, 4.0, k, taps, rgb);
    free(taps);
    drift_image in = make_image(ctx, 61, 47, 3, k / 2), out;
    drift__glare_conv conv = { 0 };
    assert_int_equal(drift_image_create(ctx, in.width, in.height, 3, &out), DRIFT_OK);
    assert_int_equal(drift__glare_convolve(ctx, &conv, &in, rgb, k, true, &out), DRIFT_OK);
    for (int32_t ch = 0; ch < 3; ++ch) {
        double a = 0.0, b = 0.0;
        for (int32_t y = 0; y < in.height; ++y) {
            for (int32_t x = 0; x < in.width; ++x) {
                a += (double)drift_image_pixel(&in, x, y)[ch];
                b += (double)drift_image_pixel(&out, x, y)[ch];
            }
        }
        assert_true(fabs(b / a - 1.0) < 1e-4);
    }
    drift__glare_conv_release(ctx, &conv);
    drift_image_destroy(ctx, &out);
    drift_image_destroy(ctx, &in);
    free(rgb);
    drift__glare_fft_destroy(ctx, fft);
    drift_context_destroy(ctx);
}

// --- 5. Identity ---

static void test_glare_delta_psf_and_point_light(void **state)
{
    (void)state;
    drift_context *ctx = test_context(1, NULL);
    const int32_t k = 8;
    float delta[8 * 8 * 3] = { 0 };
    for (int32_t ch = 0; ch < 3; ++ch) {
        delta[((k / 2) * k + k / 2) * 3 + ch] = 1.0f;
    }
    drift_image in = make_image(ctx, 33, 20, 9, 0), out;
    drift__glare_conv conv = { 0 };
    assert_int_equal(drift_image_create(ctx, in.width, in.height, 3, &out), DRIFT_OK);
    assert_int_equal(drift__glare_convolve(ctx, &conv, &in, delta, k, true, &out), DRIFT_OK);
    for (int32_t y = 0; y < in.height; ++y) {
        for (int32_t x = 0; x < in.width; ++x) {
            for (int32_t ch = 0; ch < 3; ++ch) {
                assert_near(drift_image_pixel(&out, x, y)[ch], drift_image_pixel(&in, x, y)[ch],
                            1e-5);
            }
        }
    }
    drift_image_destroy(ctx, &out);
    drift_image_destroy(ctx, &in);
    // A single bright pixel reproduces the PSF around it.
    float psf[8 * 8 * 3];
    for (int32_t i = 0; i < k * k * 3; ++i) {
        psf[i] = test_hash_unit((uint32_t)i) / (k * k * 0.5f);
    }
    drift_image point;
    assert_int_equal(drift_image_create(ctx, 20, 20, 3, &point), DRIFT_OK);
    drift_image_set3(&point, 9, 11, (drift_vec3){ 2.0f, 2.0f, 2.0f });
    assert_int_equal(drift_image_create(ctx, point.width, point.height, 3, &out), DRIFT_OK);
    assert_int_equal(drift__glare_convolve(ctx, &conv, &point, psf, k, true, &out), DRIFT_OK);
    for (int32_t v = 0; v < k; ++v) {
        for (int32_t u = 0; u < k; ++u) {
            const float *o = drift_image_pixel(&out, 9 + u - k / 2, 11 + v - k / 2);
            for (int32_t ch = 0; ch < 3; ++ch) {
                assert_near(o[ch], 2.0f * psf[(v * k + u) * 3 + ch], 1e-5);
            }
        }
    }
    drift_image_destroy(ctx, &out);
    // Linear, not circular: a source on the left edge sends nothing to the right edge.
    drift_image_set3(&point, 9, 11, (drift_vec3){ 0.0f, 0.0f, 0.0f });
    drift_image_set3(&point, 0, 11, (drift_vec3){ 2.0f, 2.0f, 2.0f });
    assert_int_equal(drift_image_create(ctx, point.width, point.height, 3, &out), DRIFT_OK);
    assert_int_equal(drift__glare_convolve(ctx, &conv, &point, psf, k, true, &out), DRIFT_OK);
    for (int32_t y = 0; y < point.height; ++y) {
        for (int32_t x = point.width - k / 2; x < point.width; ++x) {
            assert_true(fabs((double)drift_image_pixel(&out, x, y)[0]) < 1e-6);
        }
    }
    assert_near(drift_image_pixel(&out, 1, 11)[0], 2.0f * psf[((k / 2) * k + k / 2 + 1) * 3], 1e-5);
    drift__glare_conv_release(ctx, &conv);
    drift_image_destroy(ctx, &out);
    drift_image_destroy(ctx, &point);
    drift_context_destroy(ctx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_glare_fft_matches_naive_dft_and_round_trips),
        cmocka_unit_test(test_glare_real_fft_matches_complex_fft),
        cmocka_unit_test(test_glare_lane_fft_matches_double_dft),
        cmocka_unit_test(test_glare_convolution_matches_direct_sum),
        cmocka_unit_test(test_glare_airy_rings_and_energy),
        cmocka_unit_test(test_glare_chromatic_scaling),
        cmocka_unit_test(test_glare_parseval_unit_sum_and_flux),
        cmocka_unit_test(test_glare_delta_psf_and_point_light),
        cmocka_unit_test(test_glare_pupil_model_values_and_bounds),
        cmocka_unit_test(test_glare_symmetric_aperture_gives_point_symmetric_psf),
        cmocka_unit_test(test_glare_deterministic_and_fluid),
        cmocka_unit_test(test_glare_bit_identical_for_any_thread_count),
        cmocka_unit_test(test_glare_supersampling_lowers_temporal_variance),
        cmocka_unit_test(test_glare_psf_resampled_to_image_pitch),
        cmocka_unit_test(test_glare_billboards_match_convolution_for_bright_pixels),
        cmocka_unit_test(test_glare_params_defaults_and_bad_input),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
