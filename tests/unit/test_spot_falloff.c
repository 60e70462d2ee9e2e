// Spot light cones (issue 42): drift_light_spot_falloff's three models against their
// definitions, written here independently — KHR_lights_punctual's reference code (the linear
// ramp in cos between the cone angles, squared), Cycles 3.x's spot_attenuation as Blender
// shows a spot (cos θ · smoothstep over the last (1 − cos outer) · blend of the cosine, with
// Blender's glTF importer's blend = 1 − inner/outer; measured against Cycles in
// tests/cli/test_interchange.sh), pbrt-v4's smoothstep — and their shared properties: 1 or cos θ
// inside the inner cone, 0 outside the outer one, never rising away from the axis.
#include "drift/scene.h"
#include "drift_test.h"

#include <math.h>

static drift_light spot(drift_spot_falloff falloff, float inner_deg, float outer_deg)
{
    return (drift_light){ .type = DRIFT_LIGHT_SPOT,
                          .color = drift_vec3_splat(1.0f),
                          .direction = drift_vec3_make(0.0f, -1.0f, 0.0f),
                          .spot_inner = inner_deg * DRIFT_PI / 180.0f,
                          .spot_outer = outer_deg * DRIFT_PI / 180.0f,
                          .spot_falloff = falloff };
}

static double gltf_reference(double inner, double outer, double cd)
{
    double scale = 1.0 / fmax(0.001, cos(inner) - cos(outer));
    double offset = -cos(outer) * scale;
    double a = fmin(fmax(cd * scale + offset, 0.0), 1.0);
    return a * a;
}

static double cycles_reference(double size, double blend, double cd)
{
    double cos_half = cos(0.5 * size), smooth = (1.0 - cos_half) * blend;
    if (cd <= cos_half) {
        return 0.0;
    }
    double t = cd - cos_half;
    if (t < smooth && smooth != 0.0) {
        double x = t / smooth;
        return cd * x * x * (3.0 - 2.0 * x);
    }
    return cd;
}

static void test_spot_falloff_matches_definitions(void **state)
{
    (void)state;
    const float cones[][2] = { { 24, 30 }, { 0, 45 }, { 10, 12 }, { 44.9f, 45 }, { 30, 89 } };
    for (size_t k = 0; k < sizeof cones / sizeof cones[0]; ++k) {
        drift_light g = spot(DRIFT_SPOT_GLTF, cones[k][0], cones[k][1]);
        drift_light b = spot(DRIFT_SPOT_BLENDER, cones[k][0], cones[k][1]);
        // Blender's exporter: outer = size / 2, inner = outer (1 − blend).
        double size = 2.0 * (double)b.spot_outer,
               blend = 1.0 - (double)b.spot_inner / (double)b.spot_outer;
        for (int i = 0; i <= 1000; ++i) {
            double theta = 0.5 * (double)DRIFT_PI * i / 1000.0, cd = cos(theta);
            assert_near(drift_light_spot_falloff(&g, (float)cd),
                        gltf_reference(g.spot_inner, g.spot_outer, cd), 2e-4);
            assert_near(drift_light_spot_falloff(&b, (float)cd), cycles_reference(size, blend, cd),
                        2e-4);
        }
    }
}

static void test_spot_falloff_bounds_and_monotone(void **state)
{
    (void)state;
    for (int model = DRIFT_SPOT_SMOOTHSTEP; model <= DRIFT_SPOT_BLENDER; ++model) {
        drift_light l = spot((drift_spot_falloff)model, 20, 35);
        float previous = 2.0f;
        for (int i = 0; i <= 900; ++i) {
            float theta = (float)i * 0.1f * DRIFT_PI / 180.0f, cd = cosf(theta);
            float f = drift_light_spot_falloff(&l, cd);
            float inside = model == DRIFT_SPOT_BLENDER ? cd : 1.0f;
            assert_true(f >= 0.0f && f <= 1.0f);
            assert_true(f <= previous + 1e-6f);
            if (theta < l.spot_inner - 1e-4f) {
                assert_near(f, inside, 1e-5);
            }
            if (theta > l.spot_outer + 1e-4f) {
                assert_true(f == 0.0f);
            }
            previous = f;
        }
    }
    // Other lights are not cones.
    drift_light point = { .type = DRIFT_LIGHT_POINT };
    assert_true(drift_light_spot_falloff(&point, -1.0f) == 1.0f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_spot_falloff_matches_definitions),
        cmocka_unit_test(test_spot_falloff_bounds_and_monotone),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
