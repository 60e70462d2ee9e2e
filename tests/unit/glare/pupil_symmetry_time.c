// test_glare, part: the pupil, symmetry, determinism, supersampling, resampling, billboards and bad
// input (the test list is in tests/unit/test_glare.c).
#include "glare_tests.h"

// --- 6. Pupil ---

void test_glare_pupil_model_values_and_bounds(void **state)
{
    (void)state;
    const drift_glare_pupil_model th = DRIFT_GLARE_PUPIL_THESIS;
    const drift_glare_pupil_model ms = DRIFT_GLARE_PUPIL_MOON_SPENCER;
    const drift_glare_pupil_model wy = DRIFT_GLARE_PUPIL_WATSON_YELLOTT;
    // Thesis eq. 8.2 with log10 (thesis-spec §6.2 table).
    assert_near(drift_glare_pupil_diameter(th, 0.01, NULL), 6.040, 5e-4);
    assert_near(drift_glare_pupil_diameter(th, 0.1, NULL), 4.900, 5e-4);
    assert_near(drift_glare_pupil_diameter(th, 1.0, NULL), 3.760, 5e-4);
    assert_near(drift_glare_pupil_diameter(th, 100.0, NULL), 2.399, 5e-4);
    assert_near(drift_glare_pupil_diameter(DRIFT_GLARE_PUPIL_DEFAULT, 1.0, NULL), 3.760, 5e-4);
    // Moon & Spencer 1944 as published: 4.9 - 3 tanh(0.4 log10 L).
    assert_near(drift_glare_pupil_diameter(ms, 0.01, NULL), 6.892, 5e-4);
    assert_near(drift_glare_pupil_diameter(ms, 1.0, NULL), 4.900, 5e-4);
    assert_near(drift_glare_pupil_diameter(ms, 100.0, NULL), 2.908, 5e-4);
    // Watson & Yellott 2012 at 100 cd/m^2, a 60-degree field, both eyes, age 28.58:
    // F = 100 pi 30^2 = 28274 cd deg^2 / m^2... times 10 -> (F / 846)^0.41 = 10.835, D = 2.896.
    assert_near(drift_glare_pupil_diameter(wy, 100.0, NULL), 2.896, 2e-3);
    drift_glare_params older = { .wy_age = 70.0 };
    assert_true(drift_glare_pupil_diameter(wy, 0.01, &older) <
                drift_glare_pupil_diameter(wy, 0.01, NULL));
    drift_glare_params mono = { .wy_monocular = true };
    assert_true(drift_glare_pupil_diameter(wy, 1.0, &mono) >
                drift_glare_pupil_diameter(wy, 1.0, NULL));
    // Monotone decreasing and bounded; the hippus factor grows as the pupil shrinks.
    double prev = 1e9, prev_amp = -1.0;
    for (double logl = -4.0; logl <= 4.0; logl += 0.25) {
        double p = drift_glare_pupil_diameter(th, pow(10.0, logl), NULL);
        assert_true(p < prev && p > 1.9 && p < 7.9);
        double amp = drift_glare_hippus_amplitude(p);
        assert_true(amp > prev_amp);
        prev = p;
        prev_amp = amp;
        double w = drift_glare_pupil_diameter(wy, pow(10.0, logl), NULL);
        assert_true(w > 1.9 && w < 8.0);
    }
    assert_near(drift_glare_hippus_amplitude(3.760), 1.826, 1e-3);
    // The time average of h(t, p) tends to p (zero-mean noise).
    drift_glare_params p = drift_glare_params_resolve(
        &(drift_glare_params){ .mode = DRIFT_GLARE_MODE_DYNAMIC, .seed = 4, .blink_interval = -1 });
    drift__glare_eye_state eye;
    drift__glare_eye_init(&eye, &p);
    double sum = 0.0, lo = 1e9, hi = 0.0;
    int32_t count = 0;
    // 1000 frames (33 s of the eye): the mean is 3.78, 3.76 at 3000 frames; a 0.15 mm bias
    // fails it.
    for (int32_t f = 0; f < 1000; ++f) {
        drift__glare_eye_step(&eye, &p, 1.0, 1.0 / 30.0, true);
        sum += eye.pub.pupil_mm;
        lo = fmin(lo, eye.pub.pupil_mm);
        hi = fmax(hi, eye.pub.pupil_mm);
        ++count;
    }
    print_message("pupil over %d frames: mean %.4f mm, %.4f to %.4f\n", count, sum / count, lo, hi);
    assert_near(sum / count, 3.760, 0.1);
    assert_true(hi - lo > 0.05 && hi - lo < 1.0); // it pulsates, by tenths of a mm
}

// --- 7. Symmetry ---

void test_glare_symmetric_aperture_gives_point_symmetric_psf(void **state)
{
    (void)state;
    drift_context *ctx = test_context(1, NULL);
    const int32_t n = 128;
    static float hires[256 * 256], ap[128 * 128], psf[128 * 128];
    static drift__cpx scratch[2 * 128 * 128], e[128 * 128];
    // Pairs of particles and lines mirrored through the centre.
    drift__glare_disk disks[4] = { { 0.8f, 0.3f, 0.12f },
                                   { -0.8f, -0.3f, 0.12f },
                                   { -0.5f, 1.1f, 0.05f },
                                   { 0.5f, -1.1f, 0.05f } };
    drift__glare_line lines[2] = { { 0.2f, 0.4f, 1.0f, 1.3f, 0.06f },
                                   { -0.2f, -0.4f, -1.0f, -1.3f, 0.06f } };
    drift__glare_aperture_desc ad = {
        .pupil_mm = 3.0, .disks = disks, .disk_count = 4, .lines = lines, .line_count = 2
    };
    drift__glare_aperture_draw(&ad, n, 2, 6.0, hires, ap);
    drift__glare_fresnel_table(n, 6.0, 575.0, 600.0, e); // Fresnel mode: E is even
    drift__glare_fft *fft = NULL;
    assert_int_equal(drift__glare_fft_create(ctx, n, n, false, &fft), DRIFT_OK);
    drift__glare_psf_mono(fft, ap, e, n, scratch, psf, NULL);
    int32_t c = n / 2;
    double peak = 0.0, worst = 0.0;
    for (int32_t i = 0; i < n * n; ++i) {
        peak = fmax(peak, (double)psf[i]);
    }
    for (int32_t y = 1; y < n; ++y) {
        for (int32_t x = 1; x < n; ++x) {
            worst = fmax(worst, fabs(at(psf, n, x, y) - at(psf, n, 2 * c - x, 2 * c - y)));
        }
    }
    assert_true(worst < 1e-4 * peak);
    // A negative control: an asymmetric particle breaks the symmetry in Fresnel mode.
    drift__glare_disk one = { 0.8f, 0.3f, 0.3f };
    ad.disks = &one;
    ad.disk_count = 1;
    ad.line_count = 0;
    drift__glare_aperture_draw(&ad, n, 2, 6.0, hires, ap);
    drift__glare_psf_mono(fft, ap, e, n, scratch, psf, NULL);
    worst = 0.0;
    for (int32_t y = 1; y < n; ++y) {
        for (int32_t x = 1; x < n; ++x) {
            worst = fmax(worst, fabs(at(psf, n, x, y) - at(psf, n, 2 * c - x, 2 * c - y)));
        }
    }
    assert_true(worst > 1e-3 * peak);
    drift__glare_fft_destroy(ctx, fft);
    drift_context_destroy(ctx);
}

// --- 8. Determinism and temporal behaviour ---

static double mono_l1(const drift_image *a, const float *b)
{
    double s = 0.0;
    for (int32_t i = 0; i < a->width * a->height; ++i) {
        s += fabs((double)a->pixels[i] - (double)b[i]);
    }
    return s;
}

void test_glare_deterministic_and_fluid(void **state)
{
    (void)state;
    drift_context *ctx = test_context(2, NULL);
    drift_glare_params params = {
        .mode = DRIFT_GLARE_MODE_DYNAMIC, .seed = 11, .psf_size = 64, .aperture_width_mm = 10.0
    };
    drift_glare *a = NULL, *b = NULL, *c = NULL;
    assert_int_equal(drift_glare_create(ctx, &params, &a), DRIFT_OK);
    assert_int_equal(drift_glare_create(ctx, &params, &b), DRIFT_OK);
    params.seed = 12;
    assert_int_equal(drift_glare_create(ctx, &params, &c), DRIFT_OK);
    drift_image in = make_image(ctx, 48, 40, 5, 0);
    drift_image_set3(&in, 20, 20, (drift_vec3){ 500.0f, 400.0f, 300.0f });
    static float prev[64 * 64];
    double max_step = 0.0, total = 0.0;
    bool seeds_differ = false;
    for (int32_t f = 0; f < 12; ++f) {
        drift_image oa, ob, oc;
        double dt = f == 0 ? 0.0 : 1.0 / 30.0;
        assert_int_equal(drift_glare_apply(a, &in, dt, &oa), DRIFT_OK);
        assert_int_equal(drift_glare_apply(b, &in, dt, &ob), DRIFT_OK);
        assert_int_equal(drift_glare_apply(c, &in, dt, &oc), DRIFT_OK);
        size_t bytes = sizeof(float) * (size_t)(in.width * in.height * 3);
        assert_memory_equal(oa.pixels, ob.pixels, bytes);
        seeds_differ = seeds_differ || memcmp(oa.pixels, oc.pixels, bytes) != 0;
        drift_image m = drift_glare_psf_mono(a);
        if (f > 0) {
            double step = mono_l1(&m, prev);
            max_step = fmax(max_step, step);
            total += step;
        }
        memcpy(prev, m.pixels, sizeof(prev));
        drift_image_destroy(ctx, &oa);
        drift_image_destroy(ctx, &ob);
        drift_image_destroy(ctx, &oc);
    }
    assert_true(seeds_differ);
    // It moves, but fluidly: consecutive PSFs (unit sum, L1 in [0, 2]) differ by little.
    assert_true(total > 0.0);
    assert_true(max_step < 0.25);
    drift_glare_eye eye = drift_glare_eye_state(a);
    assert_near(eye.time, 11.0 / 30.0, 1e-9);
    drift_image_destroy(ctx, &in);
    drift_glare_destroy(a);
    drift_glare_destroy(b);
    drift_glare_destroy(c);
    drift_context_destroy(ctx);
}

// The same bits with 1 or 3 threads (the FFT passes split rows and columns over threads).
void test_glare_bit_identical_for_any_thread_count(void **state)
{
    (void)state;
    drift_image outs[2];
    for (int32_t t = 0; t < 2; ++t) {
        drift_context *ctx = test_context(t ? 3 : 1, NULL);
        drift_glare *g = NULL;
        assert_int_equal(drift_glare_create(ctx,
                                            &(drift_glare_params){ .mode = DRIFT_GLARE_MODE_DYNAMIC,
                                                                   .psf_size = 64,
                                                                   .seed = 2 },
                                            &g),
                         DRIFT_OK);
        drift_image in = make_image(ctx, 70, 45, 8, 0), out;
        for (int32_t f = 0; f < 3; ++f) {
            assert_int_equal(drift_glare_apply(g, &in, 0.05, &out), DRIFT_OK);
            if (f < 2) {
                drift_image_destroy(ctx, &out);
            }
        }
        // Keep the last frame in memory this test owns.
        size_t bytes = sizeof(float) * (size_t)(out.width * out.height * 3);
        outs[t] = out;
        outs[t].pixels = malloc(bytes);
        assert_non_null(outs[t].pixels);
        memcpy(outs[t].pixels, out.pixels, bytes);
        drift_image_destroy(ctx, &out);
        drift_image_destroy(ctx, &in);
        drift_glare_destroy(g);
        drift_context_destroy(ctx);
    }
    assert_memory_equal(outs[0].pixels, outs[1].pixels,
                        sizeof(float) * (size_t)(outs[0].width * outs[0].height * 3));
    free(outs[0].pixels);
    free(outs[1].pixels);
}

// --- 9. Supersampling ---

// Variance over frames of the frame-to-frame L1 change of the PSF while one particle moves by
// 0.07 pixels a frame.
static double temporal_variance(drift_context *ctx, int32_t ss)
{
    const int32_t n = 64, frames = 40;
    static float hires[64 * 8 * 64 * 8], ap[64 * 64], psf[64 * 64], prev[64 * 64];
    static drift__cpx scratch[2 * 64 * 64];
    drift__glare_fft *fft = NULL;
    assert_int_equal(drift__glare_fft_create(ctx, n, n, false, &fft), DRIFT_OK);
    double sum = 0.0, sum2 = 0.0;
    for (int32_t f = 0; f < frames; ++f) {
        drift__glare_disk d = { -4.0f + 0.07f * (float)f, 1.3f, 2.2f };
        drift__glare_aperture_desc ad = { .pupil_mm = 30.0, .disks = &d, .disk_count = 1 };
        drift__glare_aperture_draw(&ad, n, ss, 64.0, hires, ap);
        drift__glare_psf_mono(fft, ap, NULL, n, scratch, psf, NULL);
        if (f > 0) {
            double l1 = 0.0;
            for (int32_t i = 0; i < n * n; ++i) {
                l1 += fabs((double)psf[i] - (double)prev[i]);
            }
            sum += l1;
            sum2 += l1 * l1;
        }
        memcpy(prev, psf, sizeof(prev));
    }
    drift__glare_fft_destroy(ctx, fft);
    double mean = sum / (frames - 1);
    return sum2 / (frames - 1) - mean * mean;
}

void test_glare_supersampling_lowers_temporal_variance(void **state)
{
    (void)state;
    drift_context *ctx = test_context(1, NULL);
    double v1 = temporal_variance(ctx, 1), v2 = temporal_variance(ctx, 2);
    double v4 = temporal_variance(ctx, 4);
    assert_true(v2 < v1);
    assert_true(v4 < v2);
    drift_context_destroy(ctx);
}

// --- Resampling to the image's pitch ---

static double encircled(const drift_image *psf, int32_t channel, double radius)
{
    double sum = 0.0;
    int32_t c = psf->width / 2;
    for (int32_t y = 0; y < psf->height; ++y) {
        for (int32_t x = 0; x < psf->width; ++x) {
            double dx = x - c, dy = y - c;
            if (dx * dx + dy * dy <= radius * radius) {
                sum += (double)drift_image_pixel(psf, x, y)[channel];
            }
        }
    }
    return sum;
}

// With image_fov set, the PSF (pitch lambda / W) is box-resampled to the image's pitch fov /
// width: at two PSF pixels an image pixel the kernel is half as wide and encloses the same
// energy within half the radius. A clean pupil (no scatterers, no lids), Fraunhofer.
void test_glare_psf_resampled_to_image_pitch(void **state)
{
    (void)state;
    drift_context *ctx = test_context(1, NULL);
    const int32_t width = 64;
    drift_glare_params params = { .psf_size = 128,
                                  .diffraction = DRIFT_GLARE_DIFFRACTION_FRAUNHOFER,
                                  .field_luminance = 1.0,
                                  .lens_particle_count = -1,
                                  .grating_count = -1,
                                  .vitreous_particle_count = -1,
                                  .cornea_particle_count = -1,
                                  .retina_particle_count = -1,
                                  .lash_count = -1 };
    drift_glare *native = NULL, *coarse = NULL;
    assert_int_equal(drift_glare_create(ctx, &params, &native), DRIFT_OK);
    // fov / width = 2 lambda / W.
    params.image_fov = 2.0 * width * DRIFT_GLARE_LAMBDA_REF_NM * 1e-6 / 12.0;
    assert_int_equal(drift_glare_create(ctx, &params, &coarse), DRIFT_OK);
    drift_image in = make_image(ctx, width, 48, 4, 0), a, b;
    assert_int_equal(drift_glare_apply(native, &in, 0.0, &a), DRIFT_OK);
    assert_int_equal(drift_glare_apply(coarse, &in, 0.0, &b), DRIFT_OK);
    drift_image pa = drift_glare_psf(native), pb = drift_glare_psf(coarse);
    assert_int_equal(pa.width, 128);
    assert_int_equal(pb.width, 64);
    assert_near(drift_glare_eye_state(native).pupil_mm, 3.760, 5e-4);
    for (int32_t ch = 0; ch < 3; ++ch) {
        for (double r = 3.0; r <= 12.0; r += 3.0) {
            assert_near(encircled(&pb, ch, r), encircled(&pa, ch, 2.0 * r), 0.03);
        }
    }
    drift_image_destroy(ctx, &a);
    drift_image_destroy(ctx, &b);
    drift_image_destroy(ctx, &in);
    drift_glare_destroy(native);
    drift_glare_destroy(coarse);
    drift_context_destroy(ctx);
}

// --- Billboards ---

// The billboard path is the convolution for the bright pixels and leaves the rest sharp.
void test_glare_billboards_match_convolution_for_bright_pixels(void **state)
{
    (void)state;
    drift_context *ctx = test_context(1, NULL);
    drift_glare_params params = { .psf_size = 32, .seed = 6 };
    drift_glare *conv = NULL, *bill = NULL;
    assert_int_equal(drift_glare_create(ctx, &params, &conv), DRIFT_OK);
    params.method = DRIFT_GLARE_METHOD_BILLBOARD;
    assert_int_equal(drift_glare_create(ctx, &params, &bill), DRIFT_OK);
    // Bright points on black, one near a corner: identical results, spill included.
    drift_image in, a, b;
    assert_int_equal(drift_image_create(ctx, 50, 40, 3, &in), DRIFT_OK);
    drift_image_set3(&in, 25, 20, (drift_vec3){ 900.0f, 800.0f, 700.0f });
    drift_image_set3(&in, 3, 2, (drift_vec3){ 300.0f, 300.0f, 300.0f });
    drift_image_set3(&in, 40, 33, (drift_vec3){ 50.0f, 200.0f, 100.0f });
    assert_int_equal(drift_glare_apply(conv, &in, 0.0, &a), DRIFT_OK);
    assert_int_equal(drift_glare_apply(bill, &in, 0.0, &b), DRIFT_OK);
    for (int32_t i = 0; i < 50 * 40 * 3; ++i) {
        assert_near(a.pixels[i], b.pixels[i], 1e-3);
    }
    drift_image_destroy(ctx, &a);
    drift_image_destroy(ctx, &b);
    // A dim background stays exactly as it was away from the bright pixel.
    for (int32_t y = 0; y < 40; ++y) {
        for (int32_t x = 0; x < 50; ++x) {
            if (drift_luminance(drift_image_get3(&in, x, y)) == 0.0f) {
                drift_image_set3(&in, x, y, (drift_vec3){ 0.1f, 0.2f, 0.1f });
            }
        }
    }
    assert_int_equal(drift_glare_apply(bill, &in, 0.0, &b), DRIFT_OK);
    for (int32_t y = 0; y < 40; ++y) {
        for (int32_t x = 0; x < 50; ++x) {
            bool near = false;
            const int32_t pts[3][2] = { { 25, 20 }, { 3, 2 }, { 40, 33 } };
            for (int32_t p = 0; p < 3; ++p) {
                near = near || (abs(x - pts[p][0]) <= 16 && abs(y - pts[p][1]) <= 16);
            }
            if (!near) {
                assert_true(drift_image_pixel(&b, x, y)[1] == drift_image_pixel(&in, x, y)[1]);
            }
        }
    }
    // In place, the billboards of nearby bright pixels still read the original values.
    drift_image_set3(&in, 27, 21, (drift_vec3){ 600.0f, 600.0f, 600.0f });
    assert_int_equal(drift_glare_apply(bill, &in, 0.0, &a), DRIFT_OK);
    assert_int_equal(drift_glare_apply_to(bill, &in, 0.0, &in), DRIFT_OK);
    assert_memory_equal(a.pixels, in.pixels, sizeof(float) * 50 * 40 * 3);
    drift_image_destroy(ctx, &a);
    drift_image_destroy(ctx, &b);
    drift_image_destroy(ctx, &in);
    drift_glare_destroy(conv);
    drift_glare_destroy(bill);
    drift_context_destroy(ctx);
}

// --- API and bad input ---

void test_glare_params_defaults_and_bad_input(void **state)
{
    (void)state;
    test_log_capture cap = { 0 };
    drift_context *ctx = test_context(1, &cap);
    drift_glare_params r = drift_glare_params_resolve(NULL);
    assert_int_equal(r.mode, DRIFT_GLARE_MODE_STATIC);
    assert_int_equal(r.psf_size, 256);
    assert_int_equal(r.supersample, 2);
    assert_int_equal(r.wavelength_count, 32);
    assert_int_equal(r.lens_particle_count, 750);
    assert_int_equal(r.grating_count, 200);
    assert_near(r.fresnel_distance_mm, 2.0 * 4.5 * 4.5 / 575e-6, 1e-6);
    assert_int_equal(
        drift_glare_params_resolve(&(drift_glare_params){ .lash_count = -1 }).lash_count, 0);
    drift_glare *g = NULL;
    assert_int_equal(drift_glare_create(ctx, &(drift_glare_params){ .psf_size = 100 }, &g),
                     DRIFT_ERR_INVALID_ARGUMENT);
    assert_null(g);
    assert_int_equal(cap.last_code, DRIFT_ERR_INVALID_ARGUMENT);
    assert_int_equal(drift_glare_create(ctx, &(drift_glare_params){ .supersample = 9 }, &g),
                     DRIFT_ERR_INVALID_ARGUMENT);
    assert_int_equal(drift_glare_create(ctx, &(drift_glare_params){ .squint = NAN }, &g),
                     DRIFT_ERR_INVALID_ARGUMENT);
    assert_int_equal(drift_glare_create(ctx, &(drift_glare_params){ .psf_size = 32 }, &g),
                     DRIFT_OK);
    // Before any frame there is no PSF.
    assert_null(drift_glare_psf(g).pixels);
    drift_image in = make_image(ctx, 16, 16, 1, 0), out;
    drift_image_pixel(&in, 3, 4)[1] = NAN;
    int errors = cap.errors;
    assert_int_equal(drift_glare_apply(g, &in, 0.0, &out), DRIFT_ERR_INVALID_ARGUMENT);
    assert_null(out.pixels);
    assert_int_equal(cap.errors, errors + 1);
    drift_image_pixel(&in, 3, 4)[1] = 0.5f;
    assert_int_equal(drift_glare_apply(g, &in, -1.0, &out), DRIFT_ERR_INVALID_ARGUMENT);
    assert_int_equal(drift_glare_apply(g, &in, 0.0, &out), DRIFT_OK);
    drift_image psf = drift_glare_psf(g);
    assert_int_equal(psf.width, 32);
    assert_int_equal(psf.channels, 3);
    // apply_to: into a caller's image, or in place, gives the same bits as apply.
    drift_image into, wrong;
    assert_int_equal(drift_image_create(ctx, 16, 16, 3, &into), DRIFT_OK);
    assert_int_equal(drift_image_create(ctx, 16, 15, 3, &wrong), DRIFT_OK);
    assert_int_equal(drift_glare_apply_to(g, &in, 0.0, &into), DRIFT_OK);
    assert_memory_equal(into.pixels, out.pixels, sizeof(float) * 16 * 16 * 3);
    assert_int_equal(drift_glare_apply_to(g, &in, 0.0, &in), DRIFT_OK);
    assert_memory_equal(in.pixels, out.pixels, sizeof(float) * 16 * 16 * 3);
    assert_int_equal(drift_glare_apply_to(g, &in, 0.0, &wrong), DRIFT_ERR_INVALID_ARGUMENT);
    drift_image_destroy(ctx, &wrong);
    drift_image_destroy(ctx, &into);
    drift_image_destroy(ctx, &out);
    drift_image_destroy(ctx, &in);
    drift_glare_destroy(g);
    drift_glare_destroy(NULL);
    drift_context_destroy(ctx);
}
