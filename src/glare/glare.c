// The glare object: parameters, the per-frame pipeline of Ritschel 2009, thesis §8.4 (update the
// eye, draw the aperture, diffract, chromatic sum, convolve) and its buffers.
#include "drift/math.h"
#include "glare_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846

struct drift_glare {
    drift_context *ctx;
    drift_glare_params p; // resolved
    int32_t n;
    drift__glare_fft *fft;
    drift__cpx *e; // NULL: Fraunhofer
    drift__cpx *scratch;
    float *hires;
    float *aperture;
    float *mono;
    float *rgb;
    int32_t k, rgb_capacity;
    void *taps; // scratch of drift__glare_psf_rgb
    size_t taps_bytes;
    double ratio;     // PSF pixels per image pixel
    int32_t width_px; // image width the ratio was made for (0: none yet)
    bool psf_valid, psf_changed;
    bool last_updated;       // the last apply made the PSF anew
    uint64_t last_convolved; // pixels the last apply convolved by FFT (0: billboards)
    drift__glare_scene scene;
    drift__glare_eye_state eye;
    drift__glare_conv conv;
};

static int32_t count_or(int32_t v, int32_t def)
{
    return v < 0 ? 0 : (v == 0 ? def : v);
}

static double scale_or(double v, double def)
{
    return v < 0.0 ? 0.0 : (v == 0.0 ? def : v);
}

drift_glare_params drift_glare_params_resolve(const drift_glare_params *params)
{
    drift_glare_params p = params ? *params : (drift_glare_params){ 0 };
    if (p.mode == DRIFT_GLARE_MODE_DEFAULT) {
        p.mode = DRIFT_GLARE_MODE_STATIC;
    }
    p.psf_size = p.psf_size ? p.psf_size : 256;
    p.supersample = p.supersample ? p.supersample : 2;
    p.wavelength_count = p.wavelength_count ? p.wavelength_count : 32;
    if (p.diffraction == DRIFT_GLARE_DIFFRACTION_DEFAULT) {
        p.diffraction = DRIFT_GLARE_DIFFRACTION_FRESNEL;
    }
    p.aperture_width_mm = p.aperture_width_mm != 0.0 ? p.aperture_width_mm : 12.0;
    if (p.fresnel_distance_mm == 0.0) {
        // A quarter wave of chirp phase at the edge of the widest pupil: pi r^2 / (lambda d) =
        // pi / 2 with r = p_max / 2. Physical pupil-retina distances (17-24 mm) alias E at any
        // N <= 1024 (thesis-spec §6.4); this keeps E smooth and the PSF focused.
        double r = 0.5 * DRIFT_GLARE_PUPIL_MAX_MM;
        p.fresnel_distance_mm = 2.0 * r * r / (DRIFT_GLARE_LAMBDA_REF_NM * 1e-6);
    }
    if (p.pupil_model == DRIFT_GLARE_PUPIL_DEFAULT) {
        p.pupil_model = DRIFT_GLARE_PUPIL_THESIS;
    }
    p.wy_field_deg = p.wy_field_deg != 0.0 ? p.wy_field_deg : 60.0;
    p.wy_age = p.wy_age != 0.0 ? p.wy_age : 28.58;
    p.luminance_scale = p.luminance_scale != 0.0 ? p.luminance_scale : 1.0;
    p.adaptation_time = p.adaptation_time != 0.0 ? p.adaptation_time : 0.4;
    p.hippus_scale = scale_or(p.hippus_scale, 0.1);
    p.lens_particle_count = count_or(p.lens_particle_count, 750);
    p.grating_count = count_or(p.grating_count, 200);
    p.vitreous_particle_count = count_or(p.vitreous_particle_count, 200);
    p.cornea_particle_count = count_or(p.cornea_particle_count, 300);
    p.retina_particle_count = count_or(p.retina_particle_count, 20);
    p.lash_count = count_or(p.lash_count, 40);
    p.blink_interval = scale_or(p.blink_interval, 4.0);
    p.accommodation_scale = scale_or(p.accommodation_scale, 1.0);
    p.saccade_scale = scale_or(p.saccade_scale, 1.0);
    if (p.method == DRIFT_GLARE_METHOD_DEFAULT) {
        p.method = DRIFT_GLARE_METHOD_CONVOLUTION;
    }
    p.billboard_max = p.billboard_max ? p.billboard_max : 4096;
    return p;
}

#define FAIL(...)                                                                       \
    do {                                                                                \
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, __FILE__, __LINE__, \
                  __VA_ARGS__);                                                         \
        return DRIFT_ERR_INVALID_ARGUMENT;                                              \
    } while (0)

static bool in_range(double v, double lo, double hi)
{
    return isfinite(v) && v >= lo && v <= hi;
}

drift_result drift_glare_params_check(drift_context *ctx, const drift_glare_params *params)
{
    drift_glare_params p = drift_glare_params_resolve(params);
    if ((unsigned)p.mode >= DRIFT_GLARE_MODE_COUNT) {
        FAIL("glare: mode %d is not a drift_glare_mode", (int)p.mode);
    }
    if (p.psf_size < 16 || p.psf_size > 4096 || (p.psf_size & (p.psf_size - 1)) != 0) {
        FAIL("glare: PSF size %d is not a power of two in [16, 4096]", (int)p.psf_size);
    }
    if (p.supersample < 1 || p.supersample > 8) {
        FAIL("glare: supersampling %d is outside 1..8", (int)p.supersample);
    }
    if (p.wavelength_count < 1 || p.wavelength_count > 128) {
        FAIL("glare: wavelength count %d is outside 1..128", (int)p.wavelength_count);
    }
    if ((unsigned)p.diffraction >= DRIFT_GLARE_DIFFRACTION_COUNT ||
        (unsigned)p.pupil_model >= DRIFT_GLARE_PUPIL_COUNT ||
        (unsigned)p.method >= DRIFT_GLARE_METHOD_COUNT) {
        FAIL("glare: unknown diffraction, pupil model or method");
    }
    if (!in_range(p.billboard_threshold, 0.0, 1e30) || p.billboard_max < 1 ||
        p.billboard_max > 1 << 24) {
        FAIL("glare: billboard threshold %g or count %d out of range", p.billboard_threshold,
             (int)p.billboard_max);
    }
    if (!in_range(p.aperture_width_mm, 0.5, 100.0)) {
        FAIL("glare: aperture width %g mm is outside [0.5, 100]", p.aperture_width_mm);
    }
    if (!in_range(p.fresnel_distance_mm, 1e-3, 1e9)) {
        FAIL("glare: Fresnel distance %g mm is outside [0.001, 1e9]", p.fresnel_distance_mm);
    }
    if (!in_range(p.image_fov, 0.0, 2.0 * PI)) {
        FAIL("glare: image field of view %g rad is outside [0, 2 pi]", p.image_fov);
    }
    if (!in_range(p.wy_field_deg, 1e-3, 180.0) || !in_range(p.wy_age, 1.0, 120.0)) {
        FAIL("glare: Watson-Yellott field %g deg or age %g outside (0, 180], [1, 120]",
             p.wy_field_deg, p.wy_age);
    }
    if (!in_range(p.luminance_scale, 1e-12, 1e12) || !in_range(p.field_luminance, 0.0, 1e12)) {
        FAIL("glare: luminance scale %g or field luminance %g out of range", p.luminance_scale,
             p.field_luminance);
    }
    if (!in_range(p.adaptation_time, 1e-4, 1e4)) {
        FAIL("glare: adaptation time %g s is outside [1e-4, 1e4]", p.adaptation_time);
    }
    if (!in_range(p.hippus_scale, 0.0, 1.0) || !in_range(p.squint, 0.0, 0.99) ||
        !in_range(p.blink_interval, 0.0, 1e6) || !in_range(p.accommodation_scale, 0.0, 100.0) ||
        !in_range(p.saccade_scale, 0.0, 100.0)) {
        FAIL("glare: hippus scale, squint, blink interval, accommodation or saccade scale out "
             "of range");
    }
    const int32_t counts[] = { p.lens_particle_count,     p.grating_count,
                               p.vitreous_particle_count, p.cornea_particle_count,
                               p.retina_particle_count,   p.lash_count };
    for (size_t i = 0; i < sizeof(counts) / sizeof(counts[0]); ++i) {
        if (counts[i] > 100000) {
            FAIL("glare: particle, grating or lash count %d is over 100000", (int)counts[i]);
        }
    }
    return DRIFT_OK;
}

void drift_glare_destroy(drift_glare *g)
{
    if (!g) {
        return;
    }
    drift_context *ctx = g->ctx;
    drift__glare_fft_destroy(ctx, g->fft);
    drift_free(ctx, g->e);
    drift_free(ctx, g->scratch);
    drift_free(ctx, g->hires);
    drift_free(ctx, g->aperture);
    drift_free(ctx, g->mono);
    drift_free(ctx, g->rgb);
    drift_free(ctx, g->taps);
    drift__glare_scene_destroy(ctx, &g->scene);
    drift__glare_conv_release(ctx, &g->conv);
    drift_free(ctx, g);
}

drift_result drift_glare_create(drift_context *ctx, const drift_glare_params *params,
                                drift_glare **out_glare)
{
    *out_glare = NULL;
    drift_result r = drift_glare_params_check(ctx, params);
    if (r != DRIFT_OK) {
        return r;
    }
    drift_glare *g = drift_alloc(ctx, sizeof(*g));
    if (!g) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    g->ctx = ctx;
    g->p = drift_glare_params_resolve(params);
    g->n = g->p.psf_size;
    g->ratio = 1.0;
    size_t nn = (size_t)g->n * (size_t)g->n;
    size_t m = (size_t)g->n * (size_t)g->p.supersample;
    g->scratch = drift_alloc(ctx, 2 * nn * sizeof(drift__cpx));
    g->hires = drift_alloc(ctx, m * m * sizeof(float));
    g->aperture = drift_alloc(ctx, nn * sizeof(float));
    g->mono = drift_alloc(ctx, nn * sizeof(float));
    r = (g->scratch && g->hires && g->aperture && g->mono) ? DRIFT_OK : DRIFT_ERR_OUT_OF_MEMORY;
    if (r == DRIFT_OK) {
        r = drift__glare_fft_create(ctx, g->n, g->n, false, &g->fft);
    }
    if (r == DRIFT_OK && g->p.diffraction == DRIFT_GLARE_DIFFRACTION_FRESNEL) {
        // E is computed once at 575 nm and reused for every wavelength (thesis §8.4 step 3).
        if (!(g->e = drift_alloc(ctx, nn * sizeof(drift__cpx)))) {
            r = DRIFT_ERR_OUT_OF_MEMORY;
        } else {
            drift__glare_fresnel_table(g->n, g->p.aperture_width_mm, DRIFT_GLARE_LAMBDA_REF_NM,
                                       g->p.fresnel_distance_mm, g->e);
        }
    }
    if (r == DRIFT_OK) {
        r = drift__glare_scene_create(ctx, &g->p, &g->scene);
    }
    if (r != DRIFT_OK) {
        drift_glare_destroy(g);
        return r;
    }
    drift__glare_eye_init(&g->eye, &g->p);
    *out_glare = g;
    return DRIFT_OK;
}

// The PSF resampling for an image `width` pixels wide: PSF pixels per image pixel, and the
// kernel size k (even, at most 4096).
static void pitch_for(const drift_glare *g, int32_t width, double *out_ratio, int32_t *out_k)
{
    if (g->p.image_fov <= 0.0 || width <= 0) {
        *out_ratio = 1.0;
        *out_k = g->n;
        return;
    }
    // The PSF's angular pitch is lambda / W (thesis-spec §6.4); the image's is fov / width.
    double psf_pitch = DRIFT_GLARE_LAMBDA_REF_NM * 1e-6 / g->p.aperture_width_mm;
    double ratio = (g->p.image_fov / width) / psf_pitch;
    double k = ceil(g->n / ratio);
    k = 2.0 * ceil(0.5 * k);
    *out_ratio = ratio;
    *out_k = (int32_t)fmin(fmax(k, 2.0), 4096.0);
}

static drift_result update(drift_glare *g, double luminance, double dt, int32_t width)
{
    drift_context *ctx = g->ctx;
    if (luminance <= 0.0) {
        luminance = g->eye.started ? g->eye.pub.field_luminance : 1.0;
    }
    if (g->p.field_luminance > 0.0) {
        luminance = g->p.field_luminance;
    }
    bool dynamic = g->p.mode == DRIFT_GLARE_MODE_DYNAMIC;
    drift__glare_eye_step(&g->eye, &g->p, luminance, dt, dynamic);
    drift__glare_scene_pose(&g->scene, &g->eye, &g->p);

    // Step 1: the aperture.
    drift__glare_aperture_desc ad = {
        .pupil_mm = g->eye.pub.pupil_mm,
        .closure = g->eye.pub.blink,
        .lids = true,
        .disks = g->scene.disks,
        .disk_count = g->scene.disk_count,
        .lines = g->scene.lines,
        .line_count = g->scene.line_count,
    };
    drift__glare_aperture_draw(&ad, g->n, g->p.supersample, g->p.aperture_width_mm, g->hires,
                               g->aperture);
    // Step 2: Fresnel diffraction, F_575.
    drift__glare_psf_mono(g->fft, g->aperture, g->e, g->n, g->scratch, g->mono, NULL);
    // Step 3: the chromatic PSF at the image's pitch.
    double ratio;
    int32_t k;
    pitch_for(g, width ? width : g->width_px, &ratio, &k);
    if (k > g->rgb_capacity) {
        size_t bytes = (size_t)k * (size_t)k * 3 * sizeof(float);
        float *rgb = drift_alloc(ctx, bytes);
        if (!rgb) {
            return DRIFT_ERR_OUT_OF_MEMORY;
        }
        drift_free(ctx, g->rgb);
        g->rgb = rgb;
        g->rgb_capacity = k;
    }
    size_t taps = drift__glare_psf_rgb_scratch(k, ratio);
    if (taps > g->taps_bytes) {
        void *t = drift_alloc(ctx, taps);
        if (!t) {
            return DRIFT_ERR_OUT_OF_MEMORY;
        }
        drift_free(ctx, g->taps);
        g->taps = t;
        g->taps_bytes = taps;
    }
    drift__glare_psf_rgb(g->mono, g->n, g->p.wavelength_count, ratio, k, g->taps, g->rgb);
    g->k = k;
    g->ratio = ratio;
    if (width) {
        g->width_px = width;
    }
    g->psf_valid = true;
    g->psf_changed = true;
    return DRIFT_OK;
}

drift_result drift_glare_update(drift_glare *g, double luminance, double dt)
{
    if (!(isfinite(dt) && dt >= 0.0) || !isfinite(luminance)) {
        drift_log(g->ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, __FILE__, __LINE__,
                  "glare: dt %g s or luminance %g is not finite and non-negative", dt, luminance);
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    return update(g, luminance * g->p.luminance_scale, dt, 0);
}

typedef struct bright_pixel {
    float luminance;
    int32_t index; // y * width + x
    drift_vec3 value;
} bright_pixel;

static int brighter_first(const void *a, const void *b)
{
    const bright_pixel *p = a, *q = b;
    if (p->luminance != q->luminance) {
        return p->luminance > q->luminance ? -1 : 1;
    }
    return p->index < q->index ? -1 : (p->index > q->index);
}

// The billboard fast path (thesis §8.4 step 4, "dynamic textures"): the brightest pixels over
// the threshold give their light to a copy of the PSF centred on them; every other pixel stays
// as it is. For those pixels this is exactly the convolution; the rest is left sharp.
static drift_result billboards(drift_glare *g, const drift_image *in, double mean_luminance,
                               const drift_image *out)
{
    drift_context *ctx = g->ctx;
    for (int32_t y = 0; y < in->height && out->pixels != in->pixels; ++y) {
        memcpy(drift_image_pixel(out, 0, y), drift_image_pixel(in, 0, y),
               sizeof(float) * (size_t)in->width * (size_t)in->channels);
    }
    double threshold =
        g->p.billboard_threshold > 0.0 ? g->p.billboard_threshold : 20.0 * mean_luminance;
    size_t count = 0, pixels = (size_t)in->width * (size_t)in->height;
    for (int32_t y = 0; y < in->height; ++y) {
        for (int32_t x = 0; x < in->width; ++x) {
            count += (double)drift_luminance(drift_image_get3(in, x, y)) > threshold;
        }
    }
    bright_pixel *bright = drift_alloc(ctx, (count ? count : 1) * sizeof(*bright));
    if (!bright) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    size_t n = 0;
    for (size_t i = 0; i < pixels && n < count; ++i) {
        int32_t x = (int32_t)(i % (size_t)in->width), y = (int32_t)(i / (size_t)in->width);
        float l = drift_luminance(drift_image_get3(in, x, y));
        if ((double)l > threshold) {
            bright[n++] = (bright_pixel){ l, (int32_t)i, drift_image_get3(in, x, y) };
        }
    }
    qsort(bright, n, sizeof(*bright), brighter_first);
    if (n > (size_t)g->p.billboard_max) {
        n = (size_t)g->p.billboard_max;
    }
    const int32_t k = g->k, h = k / 2;
    for (size_t b = 0; b < n; ++b) {
        int32_t px = bright[b].index % in->width, py = bright[b].index / in->width;
        drift_vec3 v = bright[b].value; // in may be out, already changed by earlier billboards
        float *o = drift_image_pixel(out, px, py);
        o[0] -= v.x;
        o[1] -= v.y;
        o[2] -= v.z;
        int32_t y0 = py - h < 0 ? h - py : 0,
                y1 = py - h + k > in->height ? in->height - py + h : k;
        int32_t x0 = px - h < 0 ? h - px : 0, x1 = px - h + k > in->width ? in->width - px + h : k;
        for (int32_t v_ = y0; v_ < y1; ++v_) {
            const float *src = g->rgb + ((size_t)v_ * (size_t)k) * 3;
            for (int32_t u = x0; u < x1; ++u) {
                float *d = drift_image_pixel(out, px - h + u, py - h + v_);
                d[0] += v.x * src[u * 3 + 0];
                d[1] += v.y * src[u * 3 + 1];
                d[2] += v.z * src[u * 3 + 2];
            }
        }
    }
    drift_free(ctx, bright);
    return DRIFT_OK;
}

drift_result drift_glare_apply_to(drift_glare *g, const drift_image *in, double dt,
                                  const drift_image *out)
{
    drift_context *ctx = g->ctx;
    if (!drift_image_is_valid(in) || in->channels < 3) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, __FILE__, __LINE__,
                  "glare: the input must be a valid 3- or 4-channel image");
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    if (!drift_image_is_valid(out) || out->width != in->width || out->height != in->height ||
        out->channels != in->channels) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, __FILE__, __LINE__,
                  "glare: the output must be a valid image of the input's size and channels");
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    if (!(isfinite(dt) && dt >= 0.0)) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, __FILE__, __LINE__,
                  "glare: dt %g s must be finite and >= 0", dt);
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    // Check the pixels and measure the field luminance (mean Rec.709 luminance, §8.2.2).
    double sum = 0.0;
    for (int32_t y = 0; y < in->height; ++y) {
        for (int32_t x = 0; x < in->width; ++x) {
            const float *px = drift_image_pixel(in, x, y);
            for (int32_t c = 0; c < 3; ++c) {
                if (!isfinite(px[c])) {
                    drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, __FILE__, __LINE__,
                              "glare: pixel (%d, %d) channel %d is %g (NaN or infinite)", x, y, c,
                              (double)px[c]);
                    return DRIFT_ERR_INVALID_ARGUMENT;
                }
            }
            sum += 0.2126 * (double)px[0] + 0.7152 * (double)px[1] + 0.0722 * (double)px[2];
        }
    }
    double field = sum / ((double)in->width * in->height) * g->p.luminance_scale;
    double ratio;
    int32_t k;
    pitch_for(g, in->width, &ratio, &k);
    bool refresh =
        g->p.mode == DRIFT_GLARE_MODE_DYNAMIC || !g->psf_valid || k != g->k || ratio != g->ratio;
    drift_result r = DRIFT_OK;
    g->last_updated = refresh;
    g->last_convolved = 0;
    if (refresh && (r = update(g, field > 0.0 ? field : 1e-6, dt, in->width)) != DRIFT_OK) {
        return r;
    }
    if (g->p.method == DRIFT_GLARE_METHOD_BILLBOARD) {
        return billboards(g, in, sum / ((double)in->width * in->height), out);
    }
    r = drift__glare_convolve(ctx, &g->conv, in, g->rgb, g->k, g->psf_changed, out);
    g->psf_changed = false;
    if (r == DRIFT_OK) {
        g->last_convolved = (uint64_t)in->width * (uint64_t)in->height;
    }
    return r;
}

drift_result drift_glare_apply(drift_glare *g, const drift_image *in, double dt, drift_image *out)
{
    memset(out, 0, sizeof(*out));
    if (!drift_image_is_valid(in) || in->channels < 3) {
        drift_log(g->ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, __FILE__, __LINE__,
                  "glare: the input must be a valid 3- or 4-channel image");
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    drift_result r = drift_image_create(g->ctx, in->width, in->height, in->channels, out);
    if (r == DRIFT_OK && (r = drift_glare_apply_to(g, in, dt, out)) != DRIFT_OK) {
        drift_image_destroy(g->ctx, out);
    }
    return r;
}

drift_glare_stats drift_glare_get_stats(const drift_glare *g)
{
    bool fft = g->last_convolved > 0;
    return (drift_glare_stats){ .aperture_fft = g->psf_valid ? g->n : 0,
                                .psf_size = g->psf_valid ? g->k : 0,
                                .psf_updated = g->last_updated,
                                .fft_width = fft ? g->conv.width : 0,
                                .fft_height = fft ? g->conv.height : 0,
                                .convolved_pixels = g->last_convolved };
}

drift_image drift_glare_aperture(const drift_glare *g)
{
    if (!g->psf_valid) {
        return (drift_image){ 0 };
    }
    return (drift_image){ g->aperture, g->n, g->n, 1, g->n };
}

drift_image drift_glare_psf_mono(const drift_glare *g)
{
    if (!g->psf_valid) {
        return (drift_image){ 0 };
    }
    return (drift_image){ g->mono, g->n, g->n, 1, g->n };
}

drift_image drift_glare_psf(const drift_glare *g)
{
    if (!g->psf_valid) {
        return (drift_image){ 0 };
    }
    return (drift_image){ g->rgb, g->k, g->k, 3, (ptrdiff_t)g->k * 3 };
}

drift_glare_eye drift_glare_eye_state(const drift_glare *g)
{
    return g->eye.pub;
}
