// BRDF importance warping (thesis §6.2.3): the micro-buffer's pixels redistributed over the
// hemisphere so that each one carries the same share of f_r cos, through a tabulated 2-D CDF
// over projected-disc coordinates (marginal over omega_x, conditional over omega_y). The
// thesis always tabulates, even where an analytic inverse exists; so does this.
#include "micro/micro_internal.h"

#include <math.h>

// Mean of sqrt(1 - u^2) over [a, b]: the disc's height over a column of the table, exactly.
static float column_height(float a, float b)
{
    double da = fmax(fmin((double)a, 1.0), -1.0), db = fmax(fmin((double)b, 1.0), -1.0);
    double fa = 0.5 * (da * sqrt(fmax(1.0 - da * da, 0.0)) + asin(da));
    double fb = 0.5 * (db * sqrt(fmax(1.0 - db * db, 0.0)) + asin(db));
    return (float)((fb - fa) / (db - da));
}

// The direction of table point (u, t) in the cap's frame.
static drift_vec3 cap_direction(float u, float t, float s)
{
    float h = sqrtf(fmaxf(1.0f - u * u, 0.0f));
    float x = s * u, y = s * t * h;
    float z =
        s >= 1.0f ? h * sqrtf(fmaxf(1.0f - t * t, 0.0f)) : sqrtf(fmaxf(1.0f - x * x - y * y, 0.0f));
    return drift_vec3_make(x, y, z);
}

static drift_vec3 to_local(const drift__micro_warp *warp, drift_vec3 c)
{
    return drift_frame_to_world(&warp->cap, c);
}

void drift__micro_warp_build_cap(drift__micro_warp *warp, int32_t n, drift_vec3 axis, float scale,
                                 drift__micro_lobe_fn lobe, const void *user)
{
    n = n < 2 ? 2 : (n > DRIFT_MICRO_MAX_WARP ? DRIFT_MICRO_MAX_WARP : n);
    warp->n = n;
    bool whole = !(scale < 1.0f);
    warp->scale = whole ? 1.0f : scale;
    warp->cap =
        whole ? (drift_frame){ drift_vec3_make(1.0f, 0.0f, 0.0f), drift_vec3_make(0.0f, 1.0f, 0.0f),
                               drift_vec3_make(0.0f, 0.0f, 1.0f) }
              : drift_frame_from_normal(axis);
    float s = warp->scale, cell = 2.0f / (float)n;
    warp->marginal[0] = 0.0f;
    for (int32_t c = 0; c < n; ++c) {
        float u0 = -1.0f + (float)c * cell, u = u0 + 0.5f * cell;
        float height = column_height(u0, u0 + cell);
        float *cond = warp->conditional + (size_t)c * (size_t)(n + 1);
        cond[0] = 0.0f;
        for (int32_t r = 0; r < n; ++r) {
            float t = -1.0f + ((float)r + 0.5f) * cell;
            drift_vec3 wc = cap_direction(u, t, s), w = to_local(warp, wc);
            float f = fmaxf(lobe(w, user), 0.0f);
            // d omega_x d omega_y = s^2 sqrt(1 - u^2) du dt = cos_cap d omega, so f_r cos d omega
            // over (u, t) is f_r (cos / cos_cap) s^2 sqrt(1 - u^2) (the hemisphere: f_r sqrt).
            if (!whole) {
                f *= w.z > 0.0f && wc.z > 0.0f ? w.z / wc.z * s * s : 0.0f;
            }
            cond[r + 1] = cond[r] + f * height * cell;
        }
        warp->marginal[c + 1] = warp->marginal[c] + cond[n] * cell;
    }
    warp->rho = warp->marginal[n];
}

void drift__micro_warp_build(drift__micro_warp *warp, int32_t n, drift__micro_lobe_fn lobe,
                             const void *user)
{
    drift__micro_warp_build_cap(warp, n, drift_vec3_make(0.0f, 0.0f, 1.0f), 1.0f, lobe, user);
}

float drift__micro_phong_cap(float exponent)
{
    float c = powf(1e-3f, 1.0f / (fmaxf(exponent, 0.0f) + 1.0f));
    return c < 0.35f ? 1.0f : sqrtf(1.0f - c * c); // 0.35: 70 degrees
}

static float diffuse_lobe(drift_vec3 omega, const void *user)
{
    (void)omega;
    (void)user;
    return DRIFT_INV_PI;
}

void drift__micro_warp_build_diffuse(drift__micro_warp *warp, int32_t n)
{
    drift__micro_warp_build(warp, n, diffuse_lobe, NULL);
}

// Where `v` falls in the CDF `cdf` of n cells over [-1, 1]: the coordinate, linear in a cell.
static float invert_cdf(const float *cdf, int32_t n, float v, float *out_mass)
{
    uint32_t i = drift_cdf_find(cdf, (uint32_t)n, v);
    float w = cdf[i + 1] - cdf[i];
    float frac = w > 0.0f ? drift_clampf((v - cdf[i]) / w, 0.0f, 1.0f) : 0.5f;
    *out_mass = w;
    return -1.0f + ((float)i + frac) * 2.0f / (float)n;
}

drift_vec3 drift__micro_warp_forward(const drift__micro_warp *warp, drift_vec2 xy, float *out_pdf)
{
    int32_t n = warp->n;
    float total = warp->marginal[n];
    if (!(total > 0.0f)) {
        *out_pdf = 0.0f;
        return drift_vec3_make(0.0f, 0.0f, 1.0f);
    }
    float column_mass;
    float u = invert_cdf(warp->marginal, n, xy.x * total, &column_mass);
    int32_t c = (int32_t)drift_clampf(floorf((u + 1.0f) * 0.5f * (float)n), 0.0f, (float)(n - 1));
    const float *cond = warp->conditional + (size_t)c * (size_t)(n + 1);
    float cell_mass;
    float t = invert_cdf(cond, n, xy.y * cond[n], &cell_mass);
    // Density over (u, t): the cell's mass over its area; over (omega_x, omega_y) divided by
    // sqrt(1 - u^2); over solid angle times omega_z = sqrt(1 - u^2) sqrt(1 - t^2).
    float cell = 2.0f / (float)n;
    float p_ut = cell_mass / (cell * total);
    (void)column_mass;
    float s = warp->scale;
    drift_vec3 wc = cap_direction(u, t, s);
    if (s >= 1.0f) {
        *out_pdf = p_ut * sqrtf(fmaxf(1.0f - t * t, 0.0f));
    } else {
        float h = sqrtf(fmaxf(1.0f - u * u, 0.0f));
        *out_pdf = h > 0.0f ? p_ut * wc.z / (s * s * h) : 0.0f;
    }
    return to_local(warp, wc);
}

// The fraction of a CDF of n cells over [-1, 1] below coordinate a.
static float cdf_at(const float *cdf, int32_t n, float a)
{
    float f = (a + 1.0f) * 0.5f * (float)n;
    int32_t i = (int32_t)drift_clampf(floorf(f), 0.0f, (float)(n - 1));
    float frac = drift_clampf(f - (float)i, 0.0f, 1.0f);
    return cdf[n] > 0.0f ? (cdf[i] + frac * (cdf[i + 1] - cdf[i])) / cdf[n] : 0.5f;
}

drift_vec2 drift__micro_warp_inverse(const drift__micro_warp *warp, drift_vec3 omega)
{
    int32_t n = warp->n;
    float sc = warp->scale;
    drift_vec3 wc = drift_frame_to_local(&warp->cap, omega);
    float u = drift_clampf(wc.x / sc, -1.0f, 1.0f);
    float s = sqrtf(fmaxf(1.0f - u * u, 0.0f)) * sc;
    float t = s > 1e-7f ? drift_clampf(wc.y / s, -1.0f, 1.0f) : 0.0f;
    float x = cdf_at(warp->marginal, n, u);
    int32_t c = (int32_t)drift_clampf(floorf((u + 1.0f) * 0.5f * (float)n), 0.0f, (float)(n - 1));
    float y = cdf_at(warp->conditional + (size_t)c * (size_t)(n + 1), n, t);
    return drift_vec2_make(x, y);
}

// Solid angle of the spherical triangle a, b, c (Van Oosterom and Strackee 1983).
static float triangle_solid_angle(drift_vec3 a, drift_vec3 b, drift_vec3 c)
{
    float num = fabsf(drift_vec3_dot(a, drift_vec3_cross(b, c)));
    float den = 1.0f + drift_vec3_dot(a, b) + drift_vec3_dot(b, c) + drift_vec3_dot(c, a);
    return 2.0f * atan2f(num, den);
}

// The pixels [*lo, *hi] a coordinate of CDF cell i can land in (drift__micro_warp_inverse),
// padded by 10^-3 pixel for its rounding (~10^-5 pixel); the whole row where the CDF is empty.
static void cell_pixels(const float *cdf, int32_t n, int32_t i, int32_t k, int32_t *lo, int32_t *hi)
{
    *lo = 0;
    *hi = k - 1;
    if (cdf[n] > 0.0f) {
        int32_t a = (int32_t)floorf(cdf[i] / cdf[n] * (float)k - 1e-3f);
        int32_t b = (int32_t)floorf(cdf[i + 1] / cdf[n] * (float)k + 1e-3f);
        *lo = a > 0 ? a : 0;
        *hi = b < k - 1 ? b : k - 1;
    }
}

// The squares of the smallest and largest |a| over [a0, a1].
static void square_range(float a0, float a1, float *lo, float *hi)
{
    *lo = a0 <= 0.0f && a1 >= 0.0f ? 0.0f : fminf(a0 * a0, a1 * a1);
    *hi = fmaxf(a0 * a0, a1 * a1);
}

// drift__micro_pixels.omega_bound. A table cell (u, t) holds the directions of cap-frame
// cosine z with z^2 = 1 - s^2 (u^2 + t^2 - u^2 t^2) (increasing in |u| and |t|): each bin
// its cells' z^2 range meets (padded for rounding) takes the largest omega of the pixels
// the cell's CDF ranges reach.
static void make_omega_bound(drift__micro_pixels *pixels, const drift__micro_warp *warp, int32_t k)
{
    const int32_t bins = DRIFT_MICRO_BOUND_BINS, n = warp->n;
    const float s2 = warp->scale * warp->scale, cell = 2.0f / (float)n, pad = 1e-4f;
    for (int32_t b = 0; b < bins; ++b) {
        pixels->omega_bound[b] = 0.0f;
    }
    for (int32_t c = 0; c < n; ++c) {
        int32_t x0, x1;
        cell_pixels(warp->marginal, n, c, k, &x0, &x1);
        const float *cond = warp->conditional + (size_t)c * (size_t)(n + 1);
        float u2lo, u2hi;
        square_range(-1.0f + (float)c * cell, -1.0f + (float)(c + 1) * cell, &u2lo, &u2hi);
        for (int32_t r = 0; r < n; ++r) {
            int32_t y0, y1;
            cell_pixels(cond, n, r, k, &y0, &y1);
            float t2lo, t2hi;
            square_range(-1.0f + (float)r * cell, -1.0f + (float)(r + 1) * cell, &t2lo, &t2hi);
            float most = 0.0f;
            for (int32_t y = y0; y <= y1; ++y) {
                for (int32_t x = x0; x <= x1; ++x) {
                    most = fmaxf(most, pixels->omega[y * k + x]);
                }
            }
            float z2lo = 1.0f - s2 * (u2hi + t2hi - u2hi * t2hi) - pad;
            float z2hi = 1.0f - s2 * (u2lo + t2lo - u2lo * t2lo) + pad;
            int32_t b0 = (int32_t)drift_clampf(floorf(z2lo * (float)bins), 0.0f, (float)(bins - 1));
            int32_t b1 = (int32_t)drift_clampf(floorf(z2hi * (float)bins), 0.0f, (float)(bins - 1));
            for (int32_t b = b0; b <= b1; ++b) {
                pixels->omega_bound[b] = fmaxf(pixels->omega_bound[b], most);
            }
        }
    }
}

void drift__micro_pixels_make(drift__micro_pixels *pixels, const drift__micro_warp *warp, int32_t k)
{
    pixels->k = k;
    float inv = 1.0f / (float)k;
    // Omega(x, y): the spherical quad of the pixel's warped corners, so that the pixels tile
    // the hemisphere (the first-order 1 / (K^2 p_omega) undercounts near the horizon).
    drift_vec3 corner[(DRIFT_MICRO_MAX_K + 1) * (DRIFT_MICRO_MAX_K + 1)];
    for (int32_t j = 0; j <= k; ++j) {
        for (int32_t i = 0; i <= k; ++i) {
            float pdf;
            corner[j * (k + 1) + i] = drift__micro_warp_forward(
                warp, drift_vec2_make((float)i * inv, (float)j * inv), &pdf);
        }
    }
    for (int32_t j = 0; j < k; ++j) {
        for (int32_t i = 0; i < k; ++i) {
            float pdf;
            drift_vec3 d = drift__micro_warp_forward(
                warp, drift_vec2_make(((float)i + 0.5f) * inv, ((float)j + 0.5f) * inv), &pdf);
            pixels->dir[j * k + i] = d;
            drift_vec3 c00 = corner[j * (k + 1) + i], c10 = corner[j * (k + 1) + i + 1];
            drift_vec3 c01 = corner[(j + 1) * (k + 1) + i], c11 = corner[(j + 1) * (k + 1) + i + 1];
            float omega = triangle_solid_angle(c00, c10, c11) + triangle_solid_angle(c00, c11, c01);
            if (warp->scale < 1.0f) {
                // A cap's pixels far from a sharp lobe's axis are long and bent: their four
                // corners' quad missed 12% of the cap at Phong 200, so sum 4 x 4 sub-quads.
                omega = 0.0f;
                drift_vec3 sub[5 * 5];
                for (int32_t b = 0; b <= 4; ++b) {
                    for (int32_t a = 0; a <= 4; ++a) {
                        float sp;
                        sub[b * 5 + a] = drift__micro_warp_forward(
                            warp,
                            drift_vec2_make(((float)i + 0.25f * (float)a) * inv,
                                            ((float)j + 0.25f * (float)b) * inv),
                            &sp);
                    }
                }
                for (int32_t b = 0; b < 4; ++b) {
                    for (int32_t a = 0; a < 4; ++a) {
                        drift_vec3 s00 = sub[b * 5 + a], s10 = sub[b * 5 + a + 1];
                        drift_vec3 s01 = sub[(b + 1) * 5 + a], s11 = sub[(b + 1) * 5 + a + 1];
                        omega += triangle_solid_angle(s00, s10, s11) +
                                 triangle_solid_angle(s00, s11, s01);
                    }
                }
            }
            pixels->omega[j * k + i] = omega > 0.0f ? omega : (pdf > 0.0f ? inv * inv / pdf : 0.0f);
        }
    }
    pixels->omega_max = 0.0f;
    for (int32_t i = 0; i < k * k; ++i) {
        pixels->omega_max = fmaxf(pixels->omega_max, pixels->omega[i]);
    }
    make_omega_bound(pixels, warp, k);
}
