// The technique table (drift/techniques.h, src/hybrid/techniques.c): every row renders, every
// row is what the table says it is, and the frame prepares only the inputs the chosen rows ask
// for (a technique that does not list shadow maps never gets them silently).
#include "drift/ism.h"
#include "drift/points.h"
#include "drift/ssdo.h"
#include "drift_test.h"
#include "hybrid/techniques.h"
#include "test_rig.h"

#include <math.h>
#include <string.h>

// The effects stage (test_rig.h), its spheres at 32x16.
static void build_scene(test_rig *r, int32_t size)
{
    test_add_effects_stage(r->scene, 32, 16, size);
}

static double plane_sum(const drift_image *image)
{
    double sum = 0.0;
    size_t n = (size_t)image->width * (size_t)image->height * (size_t)image->channels;
    for (size_t i = 0; i < n; ++i) {
        assert_true(isfinite(image->pixels[i]) || image->pixels[i] == INFINITY);
        sum += isfinite(image->pixels[i]) ? fabs((double)image->pixels[i]) : 0.0;
    }
    return sum;
}

// Every row of every effect, chosen alone: the frame renders, the final image is finite, the
// effect's term holds light unless the row adds none, plane names are unique, and passes that
// the row's inputs do not ask for did not run.
static void test_every_row_renders(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    build_scene(&r, 20);
    test_rig_commit(&r);
    int rows = 0;
    for (int e = 0; e < DRIFT_EFFECT_COUNT; ++e) {
        for (int t = 0; t < drift_technique_count((drift_effect)e); ++t) {
            const drift_technique_row *row = drift_technique_row_of((drift_effect)e, t);
            drift_hybrid_params p = { .spp = 2, .seed = 3, .micro = { .points = 1024 } };
            drift_hybrid_params_set_technique(&p, (drift_effect)e, t);
            print_message("%s %s\n", drift_effect_name((drift_effect)e), row->name);
            test_rig_frame(&r, &p);
            const drift_image *final = drift_hybrid_image(r.frame);
            double total = plane_sum(final);
            assert_true(total > 0.0);
            if (!(row->flags & DRIFT_ROW_NO_TERM)) {
                const char *plane = drift_effect_info_of((drift_effect)e)->plane;
                assert_true(plane_sum(test_rig_plane(&r, plane)) > 0.0);
            }
            const char *names[256];
            const drift_image *image;
            uint32_t count = 0;
            while (count < 256 && drift_hybrid_plane(r.frame, count, &names[count], &image)) {
                for (uint32_t k = 0; k < count; ++k) {
                    assert_string_not_equal(names[k], names[count]);
                }
                // --aov writes every plane as a layer of one EXR: the frame's size.
                assert_int_equal(image->width, 20);
                assert_int_equal(image->height, 20);
                ++count;
            }
            drift_hybrid_stats stats = drift_hybrid_get_stats(r.frame);
            if (!(row->inputs & DRIFT_INPUT_SHADOW_MAPS) && e == DRIFT_EFFECT_SHADOWS) {
                assert_true(stats.rays[DRIFT_PASS_SHADOW_MAPS] == 0);
            }
            if (!(row->inputs & DRIFT_INPUT_HARD_SHADOWS) && e == DRIFT_EFFECT_SHADOWS) {
                assert_true(stats.rays[DRIFT_PASS_HARD_SHADOWS] == 0);
            }
            if (!(row->inputs & DRIFT_INPUT_SHARP_REFLECTIONS) && e == DRIFT_EFFECT_REFLECTIONS) {
                assert_true(stats.rays[DRIFT_PASS_REFLECTIONS] == 0);
            }
            if (!(row->flags & DRIFT_ROW_PATH_TRACED)) {
                assert_true(stats.rays[DRIFT_PASS_REFERENCE] == 0);
            }
            ++rows;
        }
    }
    assert_true(rows >= DRIFT_SHADOWS_COUNT + DRIFT_REFLECTIONS_COUNT + DRIFT_DOF_COUNT +
                            DRIFT_INDIRECT_COUNT);
    test_rig_destroy(&r);
}

// The rows are what the table says: in enum order, named uniquely with a summary, reference
// rows path-traced with their effect's components, and no two different passes keyed on one
// sampler stream (nor on a stream of the frame's shared inputs or of SIR).
static void test_rows_are_consistent(void **state)
{
    (void)state;
    const uint32_t reserved[] = { DRIFT_STREAM_UNSHADOWED, DRIFT_STREAM_REFLECTION,
                                  DRIFT_STREAM_PROBE,      DRIFT_STREAM_GLASS,
                                  DRIFT_STREAM_ISG_LAYER,  DRIFT_STREAM_SIR_AO,
                                  DRIFT_STREAM_SIR_TRACE };
    const drift_technique_row *seen[64];
    int seen_count = 0, searched[DRIFT_EFFECT_COUNT] = { 0 };
    for (int e = 0; e < DRIFT_EFFECT_COUNT; ++e) {
        uint32_t components = 0;
        for (int t = 0; t < drift_technique_count((drift_effect)e); ++t) {
            const drift_technique_row *row = drift_technique_row_of((drift_effect)e, t);
            assert_non_null(row);
            assert_int_equal(row->effect, e);
            assert_int_equal(row->technique, t);
            assert_true(row->summary && strlen(row->summary) > 8);
            assert_string_equal(drift_technique_summary((drift_effect)e, t), row->summary);
            for (int k = 0; k < t; ++k) {
                assert_string_not_equal(drift_technique_name((drift_effect)e, k), row->name);
            }
            if (strcmp(row->name, "reference") == 0) {
                assert_true(row->flags & DRIFT_ROW_PATH_TRACED);
                assert_true(row->pass != drift_pass_none);
            }
            if (e != DRIFT_EFFECT_DOF) { // one truth an effect
                assert_true(components == 0 || components == row->components);
                components = row->components;
            }
            // The frontier searches shadows x indirect light (drift bench frontier), never
            // against the truth it is scored by.
            assert_int_equal(drift_technique_frontier((drift_effect)e, t),
                             (row->flags & DRIFT_ROW_FRONTIER) != 0);
            if (row->flags & DRIFT_ROW_FRONTIER) {
                assert_true(e == DRIFT_EFFECT_SHADOWS || e == DRIFT_EFFECT_INDIRECT);
                assert_string_not_equal(row->name, "reference");
                ++searched[e];
            }
            if (row->flags & DRIFT_ROW_NO_TERM) { // adds nothing: runs nothing, needs nothing
                assert_true(row->pass == drift_pass_none && row->inputs == 0);
            }
            if (row->pass == drift_pass_none) { // the inputs are the term, or there is none
                assert_true(row->inputs != 0 || (row->flags & DRIFT_ROW_NO_TERM));
            }
            for (size_t k = 0; row->stream && k < sizeof reserved / sizeof *reserved; ++k) {
                assert_true(row->stream != reserved[k]);
            }
            for (int k = 0; row->stream && k < seen_count; ++k) {
                if (seen[k]->stream == row->stream) {
                    assert_true(seen[k]->pass == row->pass);
                }
            }
            assert_true(seen_count < 64);
            seen[seen_count++] = row;
        }
        assert_null(
            drift_technique_row_of((drift_effect)e, drift_technique_count((drift_effect)e)));
        assert_null(drift_technique_summary((drift_effect)e, -1));
    }
    assert_null(drift_technique_row_of(DRIFT_EFFECT_COUNT, 0));
    assert_true(searched[DRIFT_EFFECT_SHADOWS] >= 2 && searched[DRIFT_EFFECT_INDIRECT] >= 2);
    assert_false(drift_technique_frontier(DRIFT_EFFECT_SHADOWS, -1));
}

static double mean_of(const drift_image *image)
{
    double sum = 0.0;
    size_t n = (size_t)image->width * (size_t)image->height * (size_t)image->channels;
    for (size_t i = 0; i < n; ++i) {
        sum += (double)image->pixels[i];
    }
    return sum / (double)n;
}

// The environment's diffuse light is counted once: ray-traced inside D (occlusion none), or
// as the occlusion term with D keeping only its glossy part (occlusion reference, the same
// estimator with other samples). Both frames converge to one image; a double count would be
// off by the whole diffuse environment term (about a third of this frame).
static void test_occlusion_counts_the_environment_once(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    build_scene(&r, 24);
    test_rig_commit(&r);
    drift_hybrid_params p = { .light_samples = 64, .spp = 64, .seed = 5 };
    test_rig_frame(&r, &p);
    double none = mean_of(drift_hybrid_image(r.frame));
    p.occlusion = DRIFT_OCCLUSION_REFERENCE;
    test_rig_frame(&r, &p);
    double reference = mean_of(drift_hybrid_image(r.frame));
    double term = mean_of(test_rig_plane(&r, "occlusion"));
    print_message("mean final: occlusion none %g, reference %g (term %g)\n", none, reference, term);
    assert_true(term > 0.1 * reference);
    assert_near(reference, none, 0.02 * none);
    test_rig_destroy(&r);
}

// Glare spreads light and makes none: the last effect changes the frame, and its mean stays
// at most what it was (the PSF integrates to one, tests/unit/test_glare.c; the convolution is
// zero-padded, so the light the PSF's wide halo carries past the border of this small frame
// leaves it).
static void test_glare_keeps_the_light(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    build_scene(&r, 32);
    // A narrow view of the light's edge: at the camera's angular pitch the PSF's halo spans
    // pixels only when a pixel is a few arcminutes (a wide 32-pixel view shows no glare).
    r.scene->camera =
        drift_camera_look_at(drift_vec3_make(0, 0.5f, -3.0f), drift_vec3_make(0.5f, 2.0f, 0.0f),
                             drift_vec3_make(0, 1, 0), 0.02f, 32, 32);
    test_rig_commit(&r);
    drift_hybrid_params p = { .seed = 2 };
    test_rig_frame(&r, &p);
    double plain = mean_of(drift_hybrid_image(r.frame));
    drift_image before;
    assert_int_equal(drift_image_create(r.ctx, 32, 32, 3, &before), DRIFT_OK);
    memcpy(before.pixels, drift_hybrid_image(r.frame)->pixels, sizeof(float) * 32 * 32 * 3);
    p.glare = DRIFT_GLARE_STATIC;
    test_rig_frame(&r, &p);
    double glared = mean_of(drift_hybrid_image(r.frame));
    print_message("mean final: no glare %g, static glare %g\n", plain, glared);
    assert_true(test_rmse(r.ctx, &before, drift_hybrid_image(r.frame)) > 1e-4);
    assert_true(glared <= plain * 1.001 && glared > 0.75 * plain);
    drift_image_destroy(r.ctx, &before);
    test_rig_destroy(&r);
}

static int freed;

static void count_free(drift_context *ctx, void *data)
{
    drift_free(ctx, data);
    ++freed;
}

// A technique's state stays with it across frames, and is freed once: when another technique
// of the effect takes the slot, or when the frame goes.
static void test_state_slots(void **state)
{
    (void)state;
    drift_frame_state f = { .ctx = test_context(1, NULL) };
    drift_pass_args ism = { .effect = DRIFT_EFFECT_INDIRECT, .technique = 3 };
    drift_pass_args other = { .effect = DRIFT_EFFECT_INDIRECT, .technique = 1 };
    drift_pass_args shadows = { .effect = DRIFT_EFFECT_SHADOWS, .technique = 3 };
    freed = 0;
    assert_null(drift_pass_state(&f, &ism));
    void *a = drift_alloc(f.ctx, 16), *b = drift_alloc(f.ctx, 16), *c = drift_alloc(f.ctx, 16);
    drift_pass_set_state(&f, &ism, a, count_free);
    drift_pass_set_state(&f, &shadows, c, count_free);
    assert_ptr_equal(drift_pass_state(&f, &ism), a);
    assert_null(drift_pass_state(&f, &other));
    assert_ptr_equal(drift_pass_state(&f, &shadows), c);
    drift_pass_set_state(&f, &other, b, count_free);
    assert_int_equal(freed, 1);
    assert_null(drift_pass_state(&f, &ism));
    assert_ptr_equal(drift_pass_state(&f, &other), b);
    drift_pass_free_states(&f);
    assert_int_equal(freed, 3);
    assert_null(drift_pass_state(&f, &other));
    drift_context_destroy(f.ctx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rows_are_consistent),
        cmocka_unit_test(test_state_slots),
        cmocka_unit_test(test_occlusion_counts_the_environment_once),
        cmocka_unit_test(test_glare_keeps_the_light),
        cmocka_unit_test(test_every_row_renders),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
