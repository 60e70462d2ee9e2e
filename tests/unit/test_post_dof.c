// Post-process depth of field: the circle of confusion against the thin-lens camera's own
// rays, and the gather's identity, normalization, blur width and the sharp foreground kept out.
#include "drift_test.h"
#include "raster/raster.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define M_PI 3.14159265358979323846

// --- CIRCLE OF CONFUSION ---

static drift_camera test_camera(float aperture, float focus)
{
    drift_camera c =
        drift_camera_look_at(drift_vec3_make(1.0f, 2.0f, 3.0f), drift_vec3_make(1.0f, 1.0f, -7.0f),
                             drift_vec3_make(0.0f, 1.0f, 0.0f), 0.7f, 64, 48);
    c.aperture_radius = aperture;
    c.focus_distance = focus;
    return c;
}

// Where a ray crosses the plane at view depth z (along the camera's forward axis).
static drift_vec3 at_depth(const drift_camera *c, drift_ray ray, float z)
{
    drift_vec3 w = drift_vec3_normalize(drift_vec3_sub(c->target, c->position));
    float depth0 = drift_vec3_dot(drift_vec3_sub(ray.origin, c->position), w);
    return drift_vec3_fma(ray.origin, ray.dir, (z - depth0) / drift_vec3_dot(ray.dir, w));
}

// Two rays through one film point from opposite ends of the lens (concentric map of
// (0, 1/2) and (1, 1/2): (-1, 0) and (1, 0)) land 2 CoC apart on the plane at depth z.
static double thin_lens_blur_pixels(const drift_camera *c, float film_x, float film_y, float z)
{
    drift_ray a =
        drift_camera_ray(c, c->width, c->height, film_x, film_y, drift_vec2_make(0.0f, 0.5f));
    drift_ray b =
        drift_camera_ray(c, c->width, c->height, film_x, film_y, drift_vec2_make(1.0f, 0.5f));
    double separation = drift_vec3_length(drift_vec3_sub(at_depth(c, a, z), at_depth(c, b, z)));
    double pixels_per_unit = (double)c->height / (2.0 * (double)z * tan(0.5 * (double)c->fov_y));
    return separation * pixels_per_unit;
}

static void test_post_dof_coc_matches_the_thin_lens(void **state)
{
    (void)state;
    const float focuses[] = { 4.0f, 0.0f }; // 0: |target - position|, about 10.05
    const float depths[] = { 1.0f, 2.5f, 4.0f, 7.0f, 10.0f, 30.0f };
    for (size_t f = 0; f < 2; ++f) {
        drift_camera c = test_camera(0.15f, focuses[f]);
        for (size_t k = 0; k < sizeof(depths) / sizeof(depths[0]); ++k) {
            float z = depths[k];
            double coc = drift_coc_radius_pixels(&c, c.height, z);
            double blur = thin_lens_blur_pixels(&c, 13.25f, 40.5f, z);
            assert_near(blur, 2.0 * coc, 1e-3 * fmax(1.0, blur));
            blur = thin_lens_blur_pixels(&c, 50.0f, 3.0f, z);
            assert_near(blur, 2.0 * coc, 1e-3 * fmax(1.0, blur));
        }
    }
}

static void test_post_dof_coc_is_zero_in_focus_and_grows_away(void **state)
{
    (void)state;
    drift_camera c = test_camera(0.2f, 5.0f);
    assert_true(drift_coc_radius_pixels(&c, 48, 5.0f) == 0.0f);
    float previous = 0.0f;
    for (float z = 5.25f; z < 100.0f; z *= 1.5f) { // behind the focus plane
        float coc = drift_coc_radius_pixels(&c, 48, z);
        assert_true(coc > previous);
        previous = coc;
    }
    previous = 0.0f;
    for (float z = 4.75f; z > 0.05f; z *= 0.7f) { // in front of it
        float coc = drift_coc_radius_pixels(&c, 48, z);
        assert_true(coc > previous);
        previous = coc;
    }
    assert_true(drift_coc_radius_pixels(&c, 96, 9.0f) ==
                2.0f * drift_coc_radius_pixels(&c, 48, 9.0f));
    drift_camera pinhole = test_camera(0.0f, 5.0f);
    assert_true(drift_coc_radius_pixels(&pinhole, 48, 1.0f) == 0.0f);
    assert_true(drift_coc_radius_pixels(&c, 48, 0.0f) == 0.0f);
    assert_true(drift_coc_radius_pixels(&c, 48, -2.0f) == 0.0f);
}

// --- GATHER ---

typedef struct dof_images {
    drift_context *ctx;
    drift_image in, coc, out;
} dof_images;

static dof_images make_images(int32_t width, int32_t height, int32_t channels)
{
    dof_images d = { .ctx = test_context(2, NULL) };
    assert_int_equal(drift_image_create(d.ctx, width, height, channels, &d.in), DRIFT_OK);
    assert_int_equal(drift_image_create(d.ctx, width, height, 1, &d.coc), DRIFT_OK);
    assert_int_equal(drift_image_create(d.ctx, width, height, channels, &d.out), DRIFT_OK);
    return d;
}

static void destroy_images(dof_images *d)
{
    drift_image_destroy(d->ctx, &d->in);
    drift_image_destroy(d->ctx, &d->coc);
    drift_image_destroy(d->ctx, &d->out);
    drift_context_destroy(d->ctx);
}

static void fill_coc(drift_image *coc, float radius)
{
    for (int32_t y = 0; y < coc->height; ++y) {
        for (int32_t x = 0; x < coc->width; ++x) {
            drift_image_pixel(coc, x, y)[0] = radius;
        }
    }
}

// CoC from a pinhole camera is 0 everywhere (and anything under half a pixel copies too):
// the output is the input, bit for bit.
static void test_post_dof_zero_aperture_is_the_identity(void **state)
{
    (void)state;
    dof_images d = make_images(37, 23, 3);
    drift_camera pinhole = test_camera(0.0f, 5.0f);
    uint32_t n = 0;
    for (int32_t y = 0; y < d.in.height; ++y) {
        for (int32_t x = 0; x < d.in.width; ++x) {
            float *p = drift_image_pixel(&d.in, x, y);
            for (int c = 0; c < 3; ++c) {
                p[c] = 10.0f * test_hash_unit(n++) - 2.0f;
            }
            float z = 0.5f + 20.0f * test_hash_unit(n++);
            drift_image_pixel(&d.coc, x, y)[0] = drift_coc_radius_pixels(&pinhole, 23, z);
        }
    }
    assert_int_equal(drift_post_dof(d.ctx, &d.in, &d.coc, 0, &d.out), DRIFT_OK);
    assert_memory_equal(d.in.pixels, d.out.pixels, sizeof(float) * 37 * 23 * 3);
    fill_coc(&d.coc, 0.49f);
    memset(d.out.pixels, 0, sizeof(float) * 37 * 23 * 3);
    assert_int_equal(drift_post_dof(d.ctx, &d.in, &d.coc, 16, &d.out), DRIFT_OK);
    assert_memory_equal(d.in.pixels, d.out.pixels, sizeof(float) * 37 * 23 * 3);
    // The pattern starts at the centre: one tap reads the pixel itself, whatever the CoC.
    fill_coc(&d.coc, 7.5f);
    memset(d.out.pixels, 0, sizeof(float) * 37 * 23 * 3);
    assert_int_equal(drift_post_dof(d.ctx, &d.in, &d.coc, 1, &d.out), DRIFT_OK);
    assert_memory_equal(d.in.pixels, d.out.pixels, sizeof(float) * 37 * 23 * 3);
    destroy_images(&d);
}

static void test_post_dof_constant_image_stays_constant(void **state)
{
    (void)state;
    dof_images d = make_images(29, 17, 4);
    const float value[4] = { 0.3f, 0.7f, 1.9f, 1.0f };
    uint32_t n = 0;
    for (int32_t y = 0; y < d.in.height; ++y) {
        for (int32_t x = 0; x < d.in.width; ++x) {
            memcpy(drift_image_pixel(&d.in, x, y), value, sizeof(value));
            drift_image_pixel(&d.coc, x, y)[0] = 12.0f * test_hash_unit(n++);
        }
    }
    const uint32_t taps[] = { 1, 7, 0, 200 };
    for (size_t t = 0; t < sizeof(taps) / sizeof(taps[0]); ++t) {
        assert_int_equal(drift_post_dof(d.ctx, &d.in, &d.coc, taps[t], &d.out), DRIFT_OK);
        for (int32_t y = 0; y < d.out.height; ++y) {
            for (int32_t x = 0; x < d.out.width; ++x) {
                for (int c = 0; c < 4; ++c) {
                    assert_near(drift_image_pixel(&d.out, x, y)[c], value[c],
                                1e-6 * (double)value[c]);
                }
            }
        }
    }
    destroy_images(&d);
}

// Width (in pixels) of the ramp a blurred step leaves: pixels strictly between the two sides.
static int step_width(float radius)
{
    dof_images d = make_images(96, 5, 1);
    for (int32_t y = 0; y < d.in.height; ++y) {
        for (int32_t x = 0; x < d.in.width; ++x) {
            drift_image_pixel(&d.in, x, y)[0] = x < 48 ? 0.0f : 1.0f;
        }
    }
    fill_coc(&d.coc, radius);
    assert_int_equal(drift_post_dof(d.ctx, &d.in, &d.coc, 64, &d.out), DRIFT_OK);
    int width = 0;
    float previous = -1.0f;
    for (int32_t x = 0; x < d.out.width; ++x) {
        float v = drift_image_pixel(&d.out, x, 2)[0];
        assert_true(v >= 0.0f && v <= 1.0f);
        assert_true(v >= previous); // still a monotone ramp
        previous = v;
        width += v > 1e-3f && v < 1.0f - 1e-3f;
    }
    destroy_images(&d);
    return width;
}

static void test_post_dof_step_edge_blurs_wider_with_larger_coc(void **state)
{
    (void)state;
    int w0 = step_width(0.0f), w2 = step_width(2.0f), w5 = step_width(5.0f);
    int w12 = step_width(12.0f);
    assert_int_equal(w0, 0);
    assert_true(w2 >= 2 && w2 <= 5); // the ramp spans about the disk's diameter
    assert_true(w5 > w2 && w5 <= 11);
    assert_true(w12 > w5 && w12 >= 18 && w12 <= 25);
}

// Under a constant CoC the gather is a normalized disk kernel: a single bright pixel spreads
// over the disk of that radius (plus the bilinear fetch's pixel) and nowhere else, with its
// its energy kept, and no pixel brighter than two taps' weight. The gather takes about one tap
// per four pixels of the disk (a tap weighs about 4 / (pi r^2)), so not every pixel of the
// disk sees the impulse: most do.
static void test_post_dof_impulse_spreads_over_the_disk(void **state)
{
    (void)state;
    const int32_t size = 41, c = 20;
    const float radius = 6.0f;
    dof_images d = make_images(size, size, 1);
    drift_image_pixel(&d.in, c, c)[0] = 1.0f;
    fill_coc(&d.coc, radius);
    assert_int_equal(drift_post_dof(d.ctx, &d.in, &d.coc, 256, &d.out), DRIFT_OK);
    double energy = 0.0, density = 1.0 / (M_PI * (double)(radius * radius));
    int inner = 0, inner_lit = 0;
    for (int32_t y = 0; y < size; ++y) {
        for (int32_t x = 0; x < size; ++x) {
            double v = drift_image_pixel(&d.out, x, y)[0];
            double r = hypot(x - c, y - c);
            energy += v;
            assert_true(v >= 0.0 && v <= 8.0 * density);
            if (r > (double)radius + 1.5) {
                assert_true(v == 0.0);
            }
            if (r < (double)radius - 1.5) {
                ++inner;
                inner_lit += v > 0.0;
            }
        }
    }
    print_message("impulse: energy %g, %d of %d inner pixels lit\n", energy, inner_lit, inner);
    assert_true(inner_lit >= (inner * 3) / 4);
    assert_near(energy, 1.0, 0.1);
    destroy_images(&d);
}

// A blurred background pixel beside a sharp foreground leaves the foreground out: its taps
// there have circles under a pixel, which do not reach it (without the weight it gathered a
// third of the foreground: a bright rim, issue 17). The sharp foreground gathers nothing.
static void test_post_dof_sharp_foreground_does_not_leak(void **state)
{
    (void)state;
    dof_images d = make_images(40, 3, 1);
    for (int32_t y = 0; y < d.in.height; ++y) {
        for (int32_t x = 0; x < d.in.width; ++x) {
            bool foreground = x < 20;
            drift_image_pixel(&d.in, x, y)[0] = foreground ? 1.0f : 0.0f;
            drift_image_pixel(&d.coc, x, y)[0] = foreground ? 0.0f : 6.0f;
        }
    }
    assert_int_equal(drift_post_dof(d.ctx, &d.in, &d.coc, 0, &d.out), DRIFT_OK);
    assert_true(drift_image_pixel(&d.out, 19, 1)[0] == 1.0f);
    float rim = 0.0f;
    for (int32_t x = 20; x < 27; ++x) {
        rim = fmaxf(rim, drift_image_pixel(&d.out, x, 1)[0]);
    }
    print_message("background beside a sharp foreground: at most %.4f of it\n", (double)rim);
    assert_true(rim < 0.05f);
    assert_true(drift_image_pixel(&d.out, 30, 1)[0] == 0.0f);
    destroy_images(&d);
}

static void test_post_dof_rejects_bad_arguments(void **state)
{
    (void)state;
    test_log_capture log = { 0 };
    drift_context *ctx = test_context(2, &log);
    drift_image in, coc, small, grey;
    assert_int_equal(drift_image_create(ctx, 8, 6, 3, &in), DRIFT_OK);
    assert_int_equal(drift_image_create(ctx, 8, 6, 1, &coc), DRIFT_OK);
    assert_int_equal(drift_image_create(ctx, 7, 6, 3, &small), DRIFT_OK);
    assert_int_equal(drift_image_create(ctx, 8, 6, 1, &grey), DRIFT_OK);
    assert_int_equal(drift_post_dof(ctx, &in, &coc, 0, &small), DRIFT_ERR_INVALID_ARGUMENT);
    assert_int_equal(drift_post_dof(ctx, &in, &coc, 0, &grey), DRIFT_ERR_INVALID_ARGUMENT);
    assert_int_equal(drift_post_dof(ctx, &in, &coc, 0, &in), DRIFT_ERR_INVALID_ARGUMENT);
    assert_int_equal(drift_post_dof(ctx, &in, &small, 0, &grey), DRIFT_ERR_INVALID_ARGUMENT);
    assert_int_equal(drift_post_dof(ctx, &in, &coc, DRIFT_POST_DOF_MAX_TAPS + 1, &small),
                     DRIFT_ERR_INVALID_ARGUMENT);
    assert_int_equal(drift_post_dof(ctx, NULL, &coc, 0, &in), DRIFT_ERR_INVALID_ARGUMENT);
    assert_int_equal(log.errors, 6);
    assert_int_equal(log.last_code, DRIFT_ERR_INVALID_ARGUMENT);
    drift_image_destroy(ctx, &in);
    drift_image_destroy(ctx, &coc);
    drift_image_destroy(ctx, &small);
    drift_image_destroy(ctx, &grey);
    drift_context_destroy(ctx);
}

// The RGB gather runs in batches, one pixel a vector lane; other channel counts take the
// per-pixel gather. Both do the same operations per pixel, so an RGB image and the same image
// with an alpha channel give the same RGB to the bit, on 1 and 3 threads, with default, short
// and long tap tables, and the same on both thread counts: circles from 0 to 9 pixels, a flat block
// (uniform tiles), -0, an infinite pixel, and negative and NaN circles.
static void test_post_dof_rgb_batches_equal_the_per_pixel_gather(void **state)
{
    (void)state;
    const int32_t w = 83, h = 61;
    const uint32_t taps[] = { 0, 7, 200 };
    float *first = malloc(sizeof(float) * 3 * (size_t)(w * h) * 3); // 1 thread's, each table
    assert_non_null(first);
    for (int threads = 1; threads <= 3; threads += 2) {
        drift_context *ctx = test_context(threads, NULL);
        drift_image rgb, rgba, coc, out3, out4;
        assert_int_equal(drift_image_create(ctx, w, h, 3, &rgb), DRIFT_OK);
        assert_int_equal(drift_image_create(ctx, w, h, 4, &rgba), DRIFT_OK);
        assert_int_equal(drift_image_create(ctx, w, h, 1, &coc), DRIFT_OK);
        assert_int_equal(drift_image_create(ctx, w, h, 3, &out3), DRIFT_OK);
        assert_int_equal(drift_image_create(ctx, w, h, 4, &out4), DRIFT_OK);
        uint32_t n = 0;
        for (int32_t y = 0; y < h; ++y) {
            for (int32_t x = 0; x < w; ++x) {
                bool flat = x < 40 && y < 36;
                for (int c = 0; c < 3; ++c) {
                    float v = flat ? 0.25f * (float)(c + 1) : 10.0f * test_hash_unit(n++) - 2.0f;
                    drift_image_pixel(&rgb, x, y)[c] = drift_image_pixel(&rgba, x, y)[c] = v;
                }
                drift_image_pixel(&rgba, x, y)[3] = 1.0f;
                int block = (x / 9 + 3 * (y / 7)) % 5;
                float r = block == 0 ? 0.3f : 2.0f * (float)block + test_hash_unit(n++);
                drift_image_pixel(&coc, x, y)[0] = flat ? 1.5f : r;
            }
        }
        drift_image_pixel(&rgb, 60, 50)[1] = drift_image_pixel(&rgba, 60, 50)[1] = -0.0f;
        drift_image_pixel(&rgb, 70, 10)[0] = drift_image_pixel(&rgba, 70, 10)[0] = INFINITY;
        drift_image_pixel(&coc, 50, 40)[0] = -3.0f;
        drift_image_pixel(&coc, 51, 40)[0] = NAN;
        for (size_t t = 0; t < sizeof(taps) / sizeof(taps[0]); ++t) {
            assert_int_equal(drift_post_dof(ctx, &rgb, &coc, taps[t], &out3), DRIFT_OK);
            assert_int_equal(drift_post_dof(ctx, &rgba, &coc, taps[t], &out4), DRIFT_OK);
            for (int32_t y = 0; y < h; ++y) {
                for (int32_t x = 0; x < w; ++x) {
                    assert_memory_equal(drift_image_pixel(&out3, x, y),
                                        drift_image_pixel(&out4, x, y), 3 * sizeof(float));
                }
                // and the same for any thread count
                float *row = first + ((size_t)t * (size_t)h + (size_t)y) * 3 * (size_t)w;
                if (threads == 1) {
                    memcpy(row, drift_image_pixel(&out3, 0, y), 3 * sizeof(float) * (size_t)w);
                } else {
                    assert_memory_equal(row, drift_image_pixel(&out3, 0, y),
                                        3 * sizeof(float) * (size_t)w);
                }
            }
        }
        // The flat block is copied, and the gather moved the pixels around it.
        assert_memory_equal(drift_image_pixel(&out3, 5, 5), drift_image_pixel(&rgb, 5, 5),
                            3 * sizeof(float));
        assert_true(memcmp(drift_image_pixel(&out3, 20, 50), drift_image_pixel(&rgb, 20, 50),
                           3 * sizeof(float)) != 0);
        drift_image_destroy(ctx, &rgb);
        drift_image_destroy(ctx, &rgba);
        drift_image_destroy(ctx, &coc);
        drift_image_destroy(ctx, &out3);
        drift_image_destroy(ctx, &out4);
        drift_context_destroy(ctx);
    }
    free(first);
}

// Under one circle a tile's shared taps are the pixel's own: the table scaled by the same
// radius, every tap on the pixel's disk. So on tiles of one circle each (0.7 to 20 pixels;
// taps near a tile's border land on other circles, weighed by them in both paths) the shared
// gather gives the per-pixel gather's image but for the bilinear fraction's rounding (the
// shared path takes it from the offset, the per-pixel from the tap's position), on 1 and 3
// threads, the same image to the bit on both.
static void test_post_dof_shared_tiles_equal_the_per_pixel_gather(void **state)
{
    (void)state;
    const int32_t w = 88, h = 72; // a partial tile at the right and bottom
    const float radii[] = { 0.7f, 2.0f, 4.5f, 9.0f, 20.0f, 3.0f };
    float *first = malloc(sizeof(float) * 3 * (size_t)(w * h));
    assert_non_null(first);
    for (int threads = 1; threads <= 3; threads += 2) {
        drift_context *ctx = test_context(threads, NULL);
        drift_image in, coc, shared, per_pixel;
        assert_int_equal(drift_image_create(ctx, w, h, 3, &in), DRIFT_OK);
        assert_int_equal(drift_image_create(ctx, w, h, 1, &coc), DRIFT_OK);
        assert_int_equal(drift_image_create(ctx, w, h, 3, &shared), DRIFT_OK);
        assert_int_equal(drift_image_create(ctx, w, h, 3, &per_pixel), DRIFT_OK);
        uint32_t n = 0;
        for (int32_t y = 0; y < h; ++y) {
            for (int32_t x = 0; x < w; ++x) {
                for (int c = 0; c < 3; ++c) {
                    drift_image_pixel(&in, x, y)[c] = test_hash_unit(n++);
                }
                drift_image_pixel(&coc, x, y)[0] = radii[(x / 16 + 2 * (y / 16)) % 6];
            }
        }
        assert_int_equal(drift_post_dof_tiles(ctx, &in, &coc, 0, true, &shared), DRIFT_OK);
        assert_int_equal(drift_post_dof_tiles(ctx, &in, &coc, 0, false, &per_pixel), DRIFT_OK);
        double worst = 0.0, moved = 0.0;
        for (int32_t y = 0; y < h; ++y) {
            for (int32_t x = 0; x < w; ++x) {
                for (int c = 0; c < 3; ++c) {
                    double a = drift_image_pixel(&shared, x, y)[c];
                    double b = drift_image_pixel(&per_pixel, x, y)[c];
                    worst = fmax(worst, fabs(a - b));
                    moved = fmax(moved, fabs(b - (double)drift_image_pixel(&in, x, y)[c]));
                }
            }
            float *row = first + (size_t)y * 3 * (size_t)w;
            if (threads == 1) {
                memcpy(row, drift_image_pixel(&shared, 0, y), 3 * sizeof(float) * (size_t)w);
            } else {
                assert_memory_equal(row, drift_image_pixel(&shared, 0, y),
                                    3 * sizeof(float) * (size_t)w);
            }
        }
        print_message("shared against per-pixel taps, one circle a tile: at most %.3g (the "
                      "gather moved pixels by up to %.3g)\n",
                      worst, moved);
        assert_true(moved > 0.3);
        assert_true(worst < 1e-5);
        drift_image_destroy(ctx, &in);
        drift_image_destroy(ctx, &coc);
        drift_image_destroy(ctx, &shared);
        drift_image_destroy(ctx, &per_pixel);
        drift_context_destroy(ctx);
    }
    free(first);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_post_dof_coc_matches_the_thin_lens),
        cmocka_unit_test(test_post_dof_coc_is_zero_in_focus_and_grows_away),
        cmocka_unit_test(test_post_dof_zero_aperture_is_the_identity),
        cmocka_unit_test(test_post_dof_constant_image_stays_constant),
        cmocka_unit_test(test_post_dof_step_edge_blurs_wider_with_larger_coc),
        cmocka_unit_test(test_post_dof_impulse_spreads_over_the_disk),
        cmocka_unit_test(test_post_dof_sharp_foreground_does_not_leak),
        cmocka_unit_test(test_post_dof_rejects_bad_arguments),
        cmocka_unit_test(test_post_dof_rgb_batches_equal_the_per_pixel_gather),
        cmocka_unit_test(test_post_dof_shared_tiles_equal_the_per_pixel_gather),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
