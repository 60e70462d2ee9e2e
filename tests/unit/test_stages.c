// The frame's stages (drift_hybrid_stats_stage): every stage a frame runs is reported from one
// place, so the stages a frame reports add up to the frame's measured time, for the default
// frame (ISM, the stage the pass table used to leave out) and for other techniques, one pass
// or several (--aa).
#include "drift/knobs.h"
#include "drift_test.h"
#include "test_rig.h"

#include <math.h>
#include <string.h>

// The sum of the frame's stages against its measured time: within 3 % (and 0.05 ms for the
// clock's own reads on a tiny frame).
static void check_stages_add_up(const test_rig *r, const char *what)
{
    drift_hybrid_stats s = drift_hybrid_get_stats(r->frame);
    double sum = 0.0;
    const char *name = NULL;
    double ms = 0.0;
    uint32_t count = 0;
    bool effect_seen[DRIFT_EFFECT_COUNT] = { false };
    for (uint32_t k = 0; drift_hybrid_stats_stage(&s, k, &name, &ms); ++k, ++count) {
        assert_non_null(name);
        assert_true(ms >= 0.0);
        sum += ms;
        for (int e = 0; e < DRIFT_EFFECT_COUNT; ++e) {
            effect_seen[e] |= strcmp(name, drift_effect_name((drift_effect)e)) == 0;
        }
    }
    assert_int_equal(count, DRIFT_EFFECT_COUNT + 4);
    for (int e = 0; e < DRIFT_EFFECT_COUNT; ++e) {
        assert_true(effect_seen[e]);
    }
    assert_true(s.frame_ms > 0.0);
    if (!(fabs(sum - s.frame_ms) <= 0.03 * s.frame_ms + 0.05)) {
        fail_msg("%s: stages add up to %.3f ms, the frame took %.3f ms", what, sum, s.frame_ms);
    }
    // The frame's work is in its stages, not in the remainder.
    assert_true(s.other_ms <= s.frame_ms);
}

static void test_stages_add_up_to_the_frame(void **state)
{
    (void)state;
    test_rig r = test_rig_load(2, "scenes/cornell-box/cornell_box.json", 24);
    drift_hybrid_params p = drift_hybrid_params_default();
    p.ism.vpls = 64; // the default frame's techniques, small
    test_rig_frame(&r, &p);
    check_stages_add_up(&r, "default frame");
    // ISM's time is in its effect's stage.
    drift_hybrid_stats s = drift_hybrid_get_stats(r.frame);
    assert_true(s.effect_ms[DRIFT_EFFECT_INDIRECT] > 0.0);

    drift_hybrid_params q = drift_hybrid_params_default();
    q.shadows = DRIFT_SHADOWS_PCSS;
    q.reflections = DRIFT_REFLECTIONS_ENVMAP;
    q.dof = DRIFT_DOF_POST;
    q.indirect = DRIFT_INDIRECT_AMBIENT;
    q.occlusion = DRIFT_OCCLUSION_SSAO;
    q.aa = 2;
    q.shadow_map.size = 64;
    test_rig_frame(&r, &q);
    check_stages_add_up(&r, "pcss, envmap, post dof, ambient, ssao, aa 2");
    test_rig_destroy(&r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_stages_add_up_to_the_frame),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
