// From aperture to PSF: Ritschel 2009, thesis §8.3 eq. 8.3 (Fresnel diffraction as one FFT of
// P E, the power spectrum |F|^2) and §8.4 step 3 (the chromatic PSF as a sum of copies of F_575
// scaled by 575 nm / lambda_i, weighted by the colour matching functions, held in XYZ).
#include "glare_internal.h"

#include <math.h>
#include <string.h>

#define PI 3.14159265358979323846

void drift__glare_fresnel_table(int32_t n, double width_mm, double lambda_nm, double distance_mm,
                                drift__cpx *out_e)
{
    // Thesis eq. 8.3: E(x, y) = exp(i pi (x^2 + y^2) / (lambda d)), x, y at the pixel centres
    // (i - n/2) W / n, so E is even about the aperture's centre like the pupil.
    double pitch = width_mm / n;
    double k = PI / (lambda_nm * 1e-6 * distance_mm); // mm^-2
    for (int32_t y = 0; y < n; ++y) {
        double yy = (y - n / 2) * pitch;
        for (int32_t x = 0; x < n; ++x) {
            double xx = (x - n / 2) * pitch;
            double phase = k * (xx * xx + yy * yy);
            out_e[(size_t)y * (size_t)n + (size_t)x] =
                (drift__cpx){ (float)cos(phase), (float)sin(phase) };
        }
    }
}

void drift__glare_psf_mono(const drift__glare_fft *fft, const float *aperture, const drift__cpx *e,
                           int32_t n, drift__cpx *scratch, float *out_psf, double *out_power)
{
    size_t count = (size_t)n * (size_t)n;
    drift__cpx *field = scratch, *spectrum = scratch + count;
    for (size_t i = 0; i < count; ++i) {
        float a = aperture[i];
        field[i] = e ? (drift__cpx){ a * e[i].re, a * e[i].im } : (drift__cpx){ a, 0.0f };
    }
    drift__glare_fft_run(fft, field, spectrum);
    // |F|^2, the power spectrum (not |F|); K = 1 / (lambda d)^2 drops out in the normalisation.
    double sum = 0.0;
    for (size_t i = 0; i < count; ++i) {
        double re = (double)spectrum[i].re, im = (double)spectrum[i].im;
        double p = re * re + im * im;
        sum += p;
    }
    if (out_power) {
        *out_power = sum;
    }
    double inv = sum > 0.0 ? 1.0 / sum : 0.0;
    // fftshift: DC to (n/2, n/2).
    int32_t h = n / 2;
    for (int32_t y = 0; y < n; ++y) {
        const drift__cpx *row = spectrum + (size_t)y * (size_t)n;
        float *dst = out_psf + (size_t)((y + h) % n) * (size_t)n;
        for (int32_t x = 0; x < n; ++x) {
            double re = (double)row[x].re, im = (double)row[x].im;
            double p = re * re + im * im;
            dst[(x + h) % n] = (float)(p * inv);
        }
    }
}

static double lobe(double x, double mu, double s1, double s2)
{
    double t = (x - mu) / (x < mu ? s1 : s2);
    return exp(-0.5 * t * t);
}

void drift__glare_cie_xyz(double l, double out_xyz[3])
{
    // Wyman, Sloan & Shirley 2013 (JCGT 2(2)), the multi-lobe piecewise Gaussian fit of the CIE
    // 1931 2-degree observer.
    out_xyz[0] = 1.056 * lobe(l, 599.8, 37.9, 31.0) + 0.362 * lobe(l, 442.0, 16.0, 26.7) -
                 0.065 * lobe(l, 501.1, 20.4, 26.2);
    out_xyz[1] = 0.821 * lobe(l, 568.8, 46.9, 40.5) + 0.286 * lobe(l, 530.9, 16.3, 31.1);
    out_xyz[2] = 1.217 * lobe(l, 437.0, 11.8, 36.0) + 0.681 * lobe(l, 459.0, 26.0, 13.8);
}

double drift__glare_bilinear(const float *img, int32_t n, double x, double y)
{
    double fx = floor(x), fy = floor(y);
    int32_t x0 = (int32_t)fx, y0 = (int32_t)fy;
    if (x0 < -1 || y0 < -1 || x0 >= n || y0 >= n) {
        return 0.0;
    }
    double ax = x - fx, ay = y - fy;
    double v = 0.0;
    for (int32_t j = 0; j < 2; ++j) {
        int32_t yy = y0 + j;
        if (yy < 0 || yy >= n) {
            continue;
        }
        double wy = j ? ay : 1.0 - ay;
        const float *row = img + (size_t)yy * (size_t)n;
        if (x0 >= 0) {
            v += wy * (1.0 - ax) * (double)row[x0];
        }
        if (x0 + 1 < n) {
            v += wy * ax * (double)row[x0 + 1];
        }
    }
    return v;
}

// One axis of the resampling: the two taps and weights of each sample position, with weight 0
// (and a clamped index) outside the image.
static void axis_taps(int32_t n, int32_t k, int32_t ss, double ratio, double scale,
                      drift__glare_tap *taps)
{
    double centre = n / 2;
    for (int32_t j = 0; j < k; ++j) {
        for (int32_t s = 0; s < ss; ++s) {
            double u = ((j - k / 2) + (s + 0.5) / ss - 0.5) * ratio;
            double x = centre + u * scale, fl = floor(x);
            int32_t i0 = (int32_t)fmax(fmin(fl, 1e9), -1e9);
            double f = x - fl;
            drift__glare_tap t = { 0, 0, 0.0f, 0.0f };
            if (i0 >= 0 && i0 < n) {
                t.i0 = i0;
                t.w0 = (float)(1.0 - f);
            }
            if (i0 + 1 >= 0 && i0 + 1 < n) {
                t.i1 = i0 + 1;
                t.w1 = (float)f;
            }
            taps[j * ss + s] = t;
        }
    }
}

size_t drift__glare_psf_rgb_scratch(int32_t k, double ratio)
{
    return (size_t)k * (size_t)(ratio > 1.0 ? (ratio > 8.0 ? 8 : (int32_t)ceil(ratio)) : 1) * 2 *
           sizeof(drift__glare_tap);
}

void drift__glare_psf_rgb(const float *mono, int32_t n, int32_t wavelength_count, double ratio,
                          int32_t k, void *scratch, float *out)
{
    // Thesis §8.4 step 3: lambda_i = 380 + i (770 - 380) / n nm, F_lambda(x) = F_575(x 575 /
    // lambda) and, so that each copy keeps its energy, times (575 / lambda)^2.
    double scale[128], weight[128][3];
    int32_t wc = wavelength_count > 128 ? 128 : wavelength_count;
    for (int32_t i = 0; i < wc; ++i) {
        double lambda = wc == 1 ? DRIFT_GLARE_LAMBDA_REF_NM : 380.0 + i * (770.0 - 380.0) / wc;
        scale[i] = DRIFT_GLARE_LAMBDA_REF_NM / lambda;
        drift__glare_cie_xyz(lambda, weight[i]);
        for (int32_t c = 0; c < 3; ++c) {
            weight[i][c] *= scale[i] * scale[i];
        }
    }
    // XYZ -> linear Rec.709 (D65), the sRGB primaries drift works in.
    static const double m[3][3] = { { 3.2404542, -1.5371385, -0.4985314 },
                                    { -0.9692660, 1.8760108, 0.0415560 },
                                    { 0.0556434, -0.2040259, 1.0572252 } };
    int32_t ss = ratio > 1.0 ? (int32_t)ceil(ratio) : 1;
    if (ss > 8) {
        ss = 8;
    }
    // Accumulate XYZ in `out`, one wavelength at a time: the bilinear taps of a scaled copy are
    // separable, so each axis's taps are made once per wavelength. Box filter over the output
    // pixel's footprint of ratio x ratio PSF pixels (ss^2 samples).
    size_t count = (size_t)k * (size_t)k;
    memset(out, 0, count * 3 * sizeof(float));
    drift__glare_tap *tx = scratch, *ty = tx + (size_t)k * (size_t)ss;
    const float inv_ss2 = 1.0f / (float)(ss * ss);
    for (int32_t i = 0; i < wc; ++i) {
        axis_taps(n, k, ss, ratio, scale[i], tx);
        memcpy(ty, tx, (size_t)k * (size_t)ss * sizeof(*tx));
        const float wx = (float)weight[i][0] * inv_ss2, wy = (float)weight[i][1] * inv_ss2;
        const float wz = (float)weight[i][2] * inv_ss2;
        for (int32_t y = 0; y < k; ++y) {
            float *row = out + (size_t)y * (size_t)k * 3;
            // Only the disk inside the taper's outer radius k/2 is kept; skip the corners.
            double dy = y - k / 2, half = 0.5 * k, reach2 = half * half - dy * dy;
            if (reach2 <= 0.0) {
                continue;
            }
            double reach = sqrt(reach2);
            int32_t xa = (int32_t)fmax(0.0, floor(k / 2 - reach));
            int32_t xb = (int32_t)fmin((double)k, ceil(k / 2 + reach) + 1.0);
            for (int32_t sy = 0; sy < ss; ++sy) {
                drift__glare_tap t = ty[y * ss + sy];
                if (t.w0 == 0.0f && t.w1 == 0.0f) {
                    continue;
                }
                const float *r0 = mono + (size_t)t.i0 * (size_t)n;
                const float *r1 = mono + (size_t)t.i1 * (size_t)n;
                for (int32_t x = xa; x < xb; ++x) {
                    float acc = 0.0f;
                    for (int32_t sx = 0; sx < ss; ++sx) {
                        drift__glare_tap a = tx[x * ss + sx];
                        acc += t.w0 * (a.w0 * r0[a.i0] + a.w1 * r0[a.i1]) +
                               t.w1 * (a.w0 * r1[a.i0] + a.w1 * r1[a.i1]);
                    }
                    row[x * 3 + 0] += wx * acc;
                    row[x * 3 + 1] += wy * acc;
                    row[x * 3 + 2] += wz * acc;
                }
            }
        }
    }
    double sum[3] = { 0.0, 0.0, 0.0 };
    for (int32_t y = 0; y < k; ++y) {
        for (int32_t x = 0; x < k; ++x) {
            // A radial taper, cos^2 from 0.7 to 1.0 of the kernel's half width: the power
            // spectrum of pixel-sized features fills the square N x N and wraps around; without
            // the taper every bright source gets a visible square veil (seen on night.exr).
            double rx = x - k / 2, ry = y - k / 2, rr = sqrt(rx * rx + ry * ry) / (0.5 * k);
            double taper = rr <= 0.7 ? 1.0 : (rr >= 1.0 ? 0.0 : cos(0.5 * PI * (rr - 0.7) / 0.3));
            taper *= taper;
            float *dst = out + ((size_t)y * (size_t)k + (size_t)x) * 3;
            double xyz[3] = { (double)dst[0], (double)dst[1], (double)dst[2] };
            for (int32_t c = 0; c < 3; ++c) {
                // One wavelength is the monochromatic PSF itself, grey.
                double v =
                    wc == 1 ? xyz[1] : m[c][0] * xyz[0] + m[c][1] * xyz[1] + m[c][2] * xyz[2];
                v = v > 0.0 ? taper * v : 0.0; // 0: spectral colours outside the gamut
                dst[c] = (float)v;
                sum[c] += v;
            }
        }
    }
    for (int32_t c = 0; c < 3; ++c) {
        double inv = sum[c] > 0.0 ? 1.0 / sum[c] : 0.0;
        for (size_t i = 0; i < count; ++i) {
            out[i * 3 + (size_t)c] = (float)((double)out[i * 3 + (size_t)c] * inv);
        }
    }
}
