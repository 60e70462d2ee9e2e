// Per-technique reuse across frames (docs/temporal.md): instant radiosity reseeds its VPLs
// without remaking its scene points (drift_ism_set_seed), so that a sequence gathers a new VPL
// set every frame and the history averages them. A reseed is deterministic (back to the first
// seed gives the first image bit for bit), with ray-traced visibility it equals a fresh object
// of the new seed, the hybrid frame's pass keeps its state across a seed change, and the mean
// of K reseeded frames converges to a K-times larger VPL set (its error against 4096 VPLs falls
// as 1 / sqrt(K) within a margin).
// ctest-labels: quality
#include "drift/hybrid.h"
#include "drift/ism.h"
#include "drift/pt.h"
#include "drift/temporal.h"
#include "drift_test.h"
#include "test_rig.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static test_rig cornell_rig(int threads, int32_t w)
{
    return test_rig_load(threads, "scenes/cornell-box/cornell_box.json", w);
}

static void render(drift_ism *ism, const test_rig *r)
{
    assert_int_equal(drift_ism_render(ism, drift_hybrid_gbuffer(r->frame), &r->scene->camera, NULL),
                     DRIFT_OK);
}

static size_t floats_of(const drift_image *im)
{
    return (size_t)im->width * (size_t)im->height * 3;
}

// Reseeding: deterministic, a new VPL set, and with ray-traced visibility (no scene points)
// the image of a fresh object with that seed.
static void test_ism_reseed_is_a_fresh_vpl_set(void **state)
{
    (void)state;
    test_rig r = cornell_rig(2, 24);
    for (int v = 0; v < 2; ++v) {
        drift_ism_params p = { .vpl_count = 64,
                               .seed = 1,
                               .no_near_field = true,
                               .visibility =
                                   v ? DRIFT_ISM_VISIBILITY_RAYS : DRIFT_ISM_VISIBILITY_ISM };
        drift_ism *ism = NULL, *fresh = NULL;
        assert_int_equal(drift_ism_create(r.ctx, r.scene, r.accel, &p, &ism), DRIFT_OK);
        render(ism, &r);
        size_t n = floats_of(drift_ism_indirect(ism));
        float *first = malloc(n * sizeof(float));
        assert_non_null(first);
        memcpy(first, drift_ism_indirect(ism)->pixels, n * sizeof(float));
        drift_ism_set_seed(ism, 2);
        render(ism, &r);
        assert_memory_not_equal(first, drift_ism_indirect(ism)->pixels, n * sizeof(float));
        if (v) {
            p.seed = 2;
            assert_int_equal(drift_ism_create(r.ctx, r.scene, r.accel, &p, &fresh), DRIFT_OK);
            render(fresh, &r);
            assert_memory_equal(drift_ism_indirect(fresh)->pixels, drift_ism_indirect(ism)->pixels,
                                n * sizeof(float));
            drift_ism_destroy(fresh);
        }
        drift_ism_set_seed(ism, 1);
        render(ism, &r);
        assert_memory_equal(first, drift_ism_indirect(ism)->pixels, n * sizeof(float));
        free(first);
        drift_ism_destroy(ism);
    }
    test_rig_destroy(&r);
}

// The mean of K frames of 64 reseeded VPLs against one render of 4096: its error falls with K
// (below 0.6 of one frame's at K = 4 and 0.4 at K = 16; independent sets give 0.5 and 0.25).
static void test_reseeded_frames_average_to_more_vpls(void **state)
{
    (void)state;
    test_rig r = cornell_rig(2, 24);
    drift_ism_params p = { .vpl_count = 4096,
                           .seed = 1000,
                           .no_near_field = true,
                           .visibility = DRIFT_ISM_VISIBILITY_RAYS };
    drift_ism *many = NULL, *ism = NULL;
    assert_int_equal(drift_ism_create(r.ctx, r.scene, r.accel, &p, &many), DRIFT_OK);
    render(many, &r);
    p.vpl_count = 64;
    assert_int_equal(drift_ism_create(r.ctx, r.scene, r.accel, &p, &ism), DRIFT_OK);
    const drift_image *want = drift_ism_indirect(many);
    size_t n = floats_of(want);
    drift_image mean = { 0 };
    assert_int_equal(drift_image_create(r.ctx, want->width, want->height, 3, &mean), DRIFT_OK);
    double e[17] = { 0 };
    for (uint32_t k = 1; k <= 16; ++k) {
        drift_ism_set_seed(ism, k);
        render(ism, &r);
        const float *px = drift_ism_indirect(ism)->pixels;
        for (size_t i = 0; i < n; ++i) {
            mean.pixels[i] += (px[i] - mean.pixels[i]) / (float)k;
        }
        e[k] = test_nrmse(r.ctx, want, &mean);
    }
    printf("nrmse of the mean of K reseeded 64-VPL frames against 4096 VPLs: K=1 %.4f, 4 %.4f, "
           "16 %.4f\n",
           e[1], e[4], e[16]);
    assert_true(e[1] > 0.02); // one frame's VPL noise is visible
    assert_true(e[4] < 0.6 * e[1]);
    assert_true(e[16] < 0.4 * e[1]);
    drift_image_destroy(r.ctx, &mean);
    drift_ism_destroy(ism);
    drift_ism_destroy(many);
    test_rig_destroy(&r);
}

// Through the hybrid frame: a new seed keeps the indirect pass's object (its planes stay where
// they were) and changes the image; the old seed gives the old image back.
static void test_hybrid_reseed_keeps_the_ism(void **state)
{
    (void)state;
    test_rig r = cornell_rig(2, 24);
    drift_hybrid_params p = drift_hybrid_get_params(r.frame);
    p.indirect = DRIFT_INDIRECT_ISM;
    p.ism.vpls = 64;
    p.seed = 5;
    test_rig_frame(&r, &p);
    const drift_image *plane = test_rig_plane(&r, "ism.irradiance");
    const float *where = plane->pixels;
    size_t n = (size_t)plane->width * (size_t)plane->height * (size_t)plane->channels;
    float *first = malloc(n * sizeof(float));
    assert_non_null(first);
    memcpy(first, where, n * sizeof(float));
    p.seed = 6;
    assert_int_equal(drift_hybrid_set_params(r.frame, &p), DRIFT_OK);
    assert_int_equal(drift_hybrid_render(r.frame, &r.scene->camera, NULL), DRIFT_OK);
    plane = test_rig_plane(&r, "ism.irradiance");
    assert_ptr_equal(plane->pixels, where); // the same object: not remade
    assert_memory_not_equal(first, plane->pixels, n * sizeof(float));
    p.seed = 5;
    assert_int_equal(drift_hybrid_set_params(r.frame, &p), DRIFT_OK);
    assert_int_equal(drift_hybrid_render(r.frame, &r.scene->camera, NULL), DRIFT_OK);
    assert_memory_equal(first, test_rig_plane(&r, "ism.irradiance")->pixels, n * sizeof(float));
    free(first);
    test_rig_destroy(&r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_ism_reseed_is_a_fresh_vpl_set),
        cmocka_unit_test(test_reseeded_frames_average_to_more_vpls),
        cmocka_unit_test(test_hybrid_reseed_keeps_the_ism),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
