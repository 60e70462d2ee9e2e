// The technique families' state (frame/family.h, src/hybrid/families.c): each family creates,
// updates and frees what it keeps through its hooks, so a frame that has lived through other
// techniques and other knobs (the viewer's frame, a sequence's) renders every row exactly as
// a frame made for it does: a cache a family kept past a change that invalidates it, or state
// another family left behind, shows up as a byte of difference. ASan checks that destroy
// frees everything.
#include "drift_test.h"
#include "hybrid/families.h"
#include "hybrid/frame_access.h"
#include "hybrid/techniques.h"
#include "test_rig.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

// The effects stage (test_rig.h), its spheres at 16x8.
static void build_scene(test_rig *r, int32_t size)
{
    test_add_effects_stage(r->scene, 16, 8, size);
}

static bool same_pixels(const drift_image *a, const drift_image *b)
{
    if (a->width != b->width || a->height != b->height || a->channels != b->channels) {
        return false;
    }
    size_t row = sizeof(float) * (size_t)a->width * (size_t)a->channels;
    for (int32_t y = 0; y < a->height; ++y) {
        if (memcmp(a->pixels + (ptrdiff_t)y * a->stride, b->pixels + (ptrdiff_t)y * b->stride,
                   row) != 0) {
            return false;
        }
    }
    return true;
}

// Renders `p` on the long-lived frame and on a new one; fails naming `what` unless the final
// images are the same bytes.
static void check_same_as_new(test_rig *r, drift_hybrid *lived, const drift_hybrid_params *p,
                              const char *what)
{
    assert_int_equal(drift_hybrid_set_params(lived, p), DRIFT_OK);
    assert_int_equal(drift_hybrid_render(lived, &r->scene->camera, NULL), DRIFT_OK);
    test_rig_frame(r, p);
    if (!same_pixels(drift_hybrid_image(lived), drift_hybrid_image(r->frame))) {
        fail_msg("%s: the frame that lived through other rows differs from a new one", what);
    }
}

static drift_hybrid_params small_params(void)
{
    return (drift_hybrid_params){ .spp = 2,
                                  .seed = 3,
                                  .micro = { .points = 512 },
                                  .ism = { .vpls = 16, .map_size = 16, .points_per_vpl = 256 } };
}

// Every row of every effect, in turn, on one frame: each renders as a new frame does.
static void test_every_row_as_a_new_frame(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    build_scene(&r, 16);
    test_rig_commit(&r);
    drift_hybrid_params p = small_params();
    drift_hybrid *lived = NULL;
    assert_int_equal(drift_hybrid_create(r.ctx, r.scene, r.accel, &p, &lived), DRIFT_OK);
    assert_int_equal(drift_hybrid_render(lived, &r.scene->camera, NULL), DRIFT_OK);
    int rows = 0;
    for (int e = 0; e < DRIFT_EFFECT_COUNT; ++e) {
        for (int t = 0; t < drift_technique_count((drift_effect)e); ++t) {
            drift_hybrid_params q = small_params();
            drift_hybrid_params_set_technique(&q, (drift_effect)e, t);
            char what[96];
            snprintf(what, sizeof what, "%s %s", drift_effect_name((drift_effect)e),
                     drift_technique_name((drift_effect)e, t));
            check_same_as_new(&r, lived, &q, what);
            ++rows;
        }
    }
    assert_true(rows > 20);
    drift_hybrid_destroy(lived);
    test_rig_destroy(&r);
}

// The caches that survive frames (shadow maps, probes, ISM's and micro-rendering's objects)
// are remade when a knob they depend on changes, and the families' after-row work (contact
// shadows, then D's sum) follows the row that asks for it.
static void test_caches_follow_their_knobs(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    build_scene(&r, 16);
    test_rig_commit(&r);
    drift_hybrid_params p = small_params();
    p.shadows = DRIFT_SHADOWS_PCSS;
    p.reflections = DRIFT_REFLECTIONS_ENVMAP;
    p.shadow_map.size = 64;
    p.envmap.size = 16;
    drift_hybrid *lived = NULL;
    assert_int_equal(drift_hybrid_create(r.ctx, r.scene, r.accel, &p, &lived), DRIFT_OK);
    check_same_as_new(&r, lived, &p, "pcss + envmap");
    p.shadow_map.size = 32;
    check_same_as_new(&r, lived, &p, "shadow-map-size 32");
    p.shadow_map.bias = 3.0f;
    check_same_as_new(&r, lived, &p, "shadow-map-bias 3");
    p.shadow_map.contact_shadows = true;
    check_same_as_new(&r, lived, &p, "contact shadows");
    p.envmap.size = 8;
    check_same_as_new(&r, lived, &p, "envmap-size 8");
    p.seed = 4;
    check_same_as_new(&r, lived, &p, "seed 4");
    p.indirect = DRIFT_INDIRECT_ISM;
    check_same_as_new(&r, lived, &p, "ism");
    p.ism.vpls = 8;
    check_same_as_new(&r, lived, &p, "ism-vpls 8");
    p.indirect = DRIFT_INDIRECT_MICRO;
    p.reflections = DRIFT_REFLECTIONS_MICRO;
    check_same_as_new(&r, lived, &p, "micro");
    p.micro.points = 256;
    check_same_as_new(&r, lived, &p, "micro-points 256");
    p.shadows = DRIFT_SHADOWS_ISG;
    p.dof = DRIFT_DOF_ISG;
    check_same_as_new(&r, lived, &p, "isg shadows and dof");
    p.shadows = DRIFT_SHADOWS_AAF;
    p.indirect = DRIFT_INDIRECT_AAF;
    check_same_as_new(&r, lived, &p, "aaf");
    drift_hybrid_destroy(lived);
    test_rig_destroy(&r);
}

// The count `name` of the frame's last render, or NAN when it reported none.
static double count_of(drift_hybrid *frame, const char *name)
{
    drift_hybrid_stats s = drift_hybrid_get_stats(frame);
    const char *n;
    double v;
    for (uint32_t k = 0; drift_hybrid_stats_count(&s, k, &n, &v); ++k) {
        if (strcmp(n, name) == 0) {
            return v;
        }
    }
    return NAN;
}

// Every count is named "family.what" after a family of the list, once, and is a finite,
// non-negative number; a family whose rows did not run reports nothing.
static void check_counts_named(drift_hybrid *frame, const char *silent)
{
    drift_hybrid_stats s = drift_hybrid_get_stats(frame);
    const char *name;
    double value;
    for (uint32_t k = 0; drift_hybrid_stats_count(&s, k, &name, &value); ++k) {
        assert_true(isfinite(value) && value >= 0.0);
        bool known = false;
        for (int i = 0; drift_family_at(i); ++i) {
            size_t n = strlen(drift_family_at(i)->name);
            known |= strncmp(name, drift_family_at(i)->name, n) == 0 && name[n] == '.';
        }
        if (!known || (silent && strncmp(name, silent, strlen(silent)) == 0)) {
            fail_msg("count '%s' is not its family's (or its rows did not run)", name);
        }
        for (uint32_t j = 0; j < k; ++j) {
            assert_string_not_equal(s.counts[j].name, name);
        }
    }
}

static void render(test_rig *r, drift_hybrid *frame, const drift_hybrid_params *p)
{
    assert_int_equal(drift_hybrid_set_params(frame, p), DRIFT_OK);
    assert_int_equal(drift_hybrid_render(frame, &r->scene->camera, NULL), DRIFT_OK);
}

// A frame reports what it did: the shadow maps and probes cast rays on the first frame and
// none on the next (the caches survive), again after a knob they depend on changes; AAF
// spends its --spp budget on average (exactly with uniform sampling); ISM reports its VPLs,
// micro-rendering its points (a power of two); hard shadows cast at most a ray per surface
// pixel and light.
static void test_a_frame_reports_what_it_did(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    build_scene(&r, 16);
    test_rig_commit(&r);
    drift_hybrid_params p = small_params();
    p.indirect = DRIFT_INDIRECT_NONE;
    drift_hybrid *frame = NULL;
    assert_int_equal(drift_hybrid_create(r.ctx, r.scene, r.accel, &p, &frame), DRIFT_OK);

    render(&r, frame, &p); // hard shadows alone
    check_counts_named(frame, "isg");
    double hard = count_of(frame, "realtime.hard_shadow_rays");
    assert_true(hard > 0.0 && hard <= 16.0 * 16.0);
    assert_true(count_of(frame, "realtime.environment_shadow_rays") > 0.0);
    assert_true(isnan(count_of(frame, "ism.vpls")));

    p.shadows = DRIFT_SHADOWS_PCSS;
    p.reflections = DRIFT_REFLECTIONS_ENVMAP;
    render(&r, frame, &p);
    check_counts_named(frame, "aaf");
    assert_true(count_of(frame, "realtime.shadow_map_rays") > 0.0);
    assert_true(count_of(frame, "realtime.probe_rays") > 0.0);
    render(&r, frame, &p);
    assert_true(count_of(frame, "realtime.shadow_maps") == 1.0);
    assert_true(count_of(frame, "realtime.shadow_map_rays") == 0.0);
    assert_true(count_of(frame, "realtime.probe_rays") == 0.0);
    p.shadow_map.size = 32;
    render(&r, frame, &p);
    assert_true(count_of(frame, "realtime.shadow_map_rays") > 0.0);
    assert_true(count_of(frame, "realtime.probe_rays") == 0.0);

    // Contact shadows: the lights they marched (those with a map), the pixels the map let
    // through, --contact-samples points each, and the pixels whose march met an occluder:
    // exactly those whose S_l the fix turned to 0.
    assert_true(isnan(count_of(frame, "ssdo.contact_shadows.lights")));
    float before[16 * 16];
    const drift_image *shadow = drift_hybrid_plane_named(frame, "light0.shadow");
    assert_non_null(shadow);
    for (int32_t i = 0; i < 16 * 16; ++i) {
        before[i] = drift_image_pixel(shadow, i % 16, i / 16)[0];
    }
    p.shadow_map.contact_shadows = true;
    p.shadow_map.contact_samples = 4;
    render(&r, frame, &p);
    check_counts_named(frame, "aaf");
    shadow = drift_hybrid_plane_named(frame, "light0.shadow");
    double turned = 0.0;
    for (int32_t i = 0; i < 16 * 16; ++i) {
        turned += before[i] > 0.0f && drift_image_pixel(shadow, i % 16, i / 16)[0] == 0.0f;
    }
    double lit = count_of(frame, "ssdo.contact_shadows.lit_pixels");
    assert_true(count_of(frame, "ssdo.contact_shadows.lights") == 1.0);
    assert_true(lit > 0.0 && lit <= 16.0 * 16.0);
    assert_true(count_of(frame, "ssdo.contact_shadows.march_samples") == 4.0 * lit);
    if (count_of(frame, "ssdo.contact_shadows.shadowed_pixels") != turned) {
        fail_msg("contact shadows: %g pixels reported shadowed, %g turned to 0",
                 count_of(frame, "ssdo.contact_shadows.shadowed_pixels"), turned);
    }
    p.shadow_map.contact_shadows = false;

    p = small_params();
    p.spp = 8;
    p.indirect = DRIFT_INDIRECT_AAF;
    render(&r, frame, &p);
    check_counts_named(frame, "ism");
    double mean = count_of(frame, "aaf.indirect.mean_spp");
    if (!(fabs(mean - 8.0) <= 0.8)) {
        fail_msg("aaf: %.3f samples a pixel on average, --spp 8", mean);
    }
    assert_true(count_of(frame, "aaf.indirect.sampled_pixels") > 0.0);
    p.aaf.uniform = true;
    render(&r, frame, &p);
    assert_true(count_of(frame, "aaf.indirect.mean_spp") == 8.0);

    p = small_params();
    p.indirect = DRIFT_INDIRECT_ISM;
    render(&r, frame, &p);
    check_counts_named(frame, "aaf");
    assert_true(count_of(frame, "ism.vpls") > 0.0);
    assert_true(count_of(frame, "ism.splats") > 0.0);

    p.indirect = DRIFT_INDIRECT_MICRO;
    render(&r, frame, &p);
    check_counts_named(frame, "ism");
    assert_true(count_of(frame, "micro.indirect.points") == 512.0);
    assert_true(count_of(frame, "micro.indirect.gathers") > 0.0);

    // SSDO: its resolved samples and steps (4 x 4 by default), the pixels it shaded (those
    // that see a surface), one layer, no extra views, the bounce when asked for; none of it
    // with occlusion reference.
    p = small_params();
    p.indirect = DRIFT_INDIRECT_NONE;
    p.occlusion = DRIFT_OCCLUSION_SSDO;
    render(&r, frame, &p);
    check_counts_named(frame, "micro");
    assert_true(count_of(frame, "ssdo.samples") == 4.0);
    assert_true(count_of(frame, "ssdo.steps") == 4.0);
    assert_true(count_of(frame, "ssdo.bounce") == 0.0);
    assert_true(count_of(frame, "ssdo.layers") == 1.0);
    assert_true(count_of(frame, "ssdo.views") == 0.0);
    double shaded = count_of(frame, "ssdo.shaded_pixels");
    assert_true(shaded > 0.0 && shaded <= 16.0 * 16.0);
    p.occlusion_settings.samples = 8;
    p.occlusion_settings.layers = 2;
    p.occlusion_settings.bounce = true;
    render(&r, frame, &p);
    assert_true(count_of(frame, "ssdo.bounce") == 1.0);
    assert_true(count_of(frame, "ssdo.samples") == 8.0);
    assert_true(count_of(frame, "ssdo.layers") == 2.0);
    assert_true(count_of(frame, "ssdo.shaded_pixels") == shaded);
    p.occlusion = DRIFT_OCCLUSION_REFERENCE;
    render(&r, frame, &p);
    check_counts_named(frame, "ssdo");

    // Glare: the static eye makes its PSF on the first frame only, and convolves every pixel
    // on a padded FFT at least the frame's size each frame.
    p = small_params();
    p.indirect = DRIFT_INDIRECT_NONE;
    p.glare = DRIFT_GLARE_STATIC;
    render(&r, frame, &p);
    check_counts_named(frame, "ssdo");
    assert_true(count_of(frame, "glare.psf_updates") == 1.0);
    assert_true(count_of(frame, "glare.aperture_fft") > 0.0);
    assert_true(count_of(frame, "glare.psf_size") > 0.0);
    assert_true(count_of(frame, "glare.fft_width") >= 16.0);
    assert_true(count_of(frame, "glare.fft_height") >= 16.0);
    assert_true(count_of(frame, "glare.convolved_pixels") == 16.0 * 16.0);
    render(&r, frame, &p);
    assert_true(count_of(frame, "glare.psf_updates") == 0.0);
    assert_true(count_of(frame, "glare.convolved_pixels") == 16.0 * 16.0);
    p.glare = DRIFT_GLARE_NONE;
    render(&r, frame, &p);
    check_counts_named(frame, "glare");
    drift_hybrid_destroy(frame);
    test_rig_destroy(&r);
}

// Each family that makes state (a create hook) puts it in a slot of its own, which the frame
// holds from its creation to its end; the other families have none.
static void test_each_family_owns_its_slot(void **state)
{
    (void)state;
    bool taken[DRIFT_FAMILY_SLOT_COUNT] = { false };
    int creators = 0;
    for (int i = 0; drift_family_at(i); ++i) {
        const drift_family *family = drift_family_at(i);
        if (!family->create) {
            assert_int_equal(family->slot, DRIFT_FAMILY_NONE);
            continue;
        }
        if (family->slot == DRIFT_FAMILY_NONE || family->slot >= DRIFT_FAMILY_SLOT_COUNT ||
            taken[family->slot]) {
            fail_msg("family %s: its state has no slot of its own", family->name);
        }
        taken[family->slot] = true;
        assert_non_null(family->destroy);
        ++creators;
    }
    assert_true(creators >= 4); // realtime, isg, aaf, ssdo
    test_rig r = test_rig_begin(1);
    build_scene(&r, 8);
    test_rig_commit(&r);
    drift_hybrid_params p = small_params();
    drift_hybrid *frame = NULL;
    assert_int_equal(drift_hybrid_create(r.ctx, r.scene, r.accel, &p, &frame), DRIFT_OK);
    const drift_frame_state *f = drift_hybrid_frame(frame);
    for (int slot = 0; slot < DRIFT_FAMILY_SLOTS; ++slot) {
        bool made = drift_family_state(f, (drift_family_slot)slot) != NULL;
        assert_true(made == (slot < DRIFT_FAMILY_SLOT_COUNT && taken[slot]));
    }
    drift_hybrid_destroy(frame);
    test_rig_destroy(&r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_every_row_as_a_new_frame),
        cmocka_unit_test(test_caches_follow_their_knobs),
        cmocka_unit_test(test_a_frame_reports_what_it_did),
        cmocka_unit_test(test_each_family_owns_its_slot),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
