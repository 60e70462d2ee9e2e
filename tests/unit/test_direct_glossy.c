// The hybrid frame's unshadowed light U_l through GGX glossy lobes (src/raster/shading.c):
// light samples and BSDF-sampled directions combined by the power heuristic. Before, the
// glossy lobe saw an area light through light samples alone, which a near-mirror lobe almost
// never finds: a smooth conductor under a quad rendered ~0 where it mirrors F L_e (Blender's
// GGX scene: the roughness-0.05 sphere's highlight of its emissive slab at 0.05 of the path
// tracer's direct light).
#include "drift_test.h"
#include "raster/raster.h"
#include "test_rig.h"

#include <math.h>

// A gold-ish conductor (Schlick from F0 = base) or the layered plastic, of roughness alpha.
static drift_material ggx_material(float alpha, bool metal)
{
    drift_material m = drift_material_make(drift_vec3_make(0.9f, 0.6f, 0.3f));
    m.type = DRIFT_MATERIAL_GGX;
    m.ggx.alpha = alpha;
    m.ggx.metallic = metal ? 1.0f : 0.0f;
    return m;
}

// The light kinds under test, each facing the receiver at the origin (normal +y) from around
// the mirror direction r of wo, at distance 3 (light_kind, below).
typedef enum light_kind {
    KIND_QUAD,
    KIND_MESH,   // an emissive mesh: the same quad as two triangles
    KIND_SPHERE, // a sphere light of radius 1
    KIND_DISK,   // a disk light of radius 1
} light_kind;

static const char *const kind_names[] = { "quad", "mesh", "sphere", "disk" };

static void add_light(drift_scene *scene, light_kind kind, drift_vec3 r, float radiance)
{
    drift_vec3 centre = drift_vec3_scale(r, 3.0f);
    // A 2 x 2 square across r: edges in the xy plane and along z, cross(eu, ev) along -r.
    drift_vec3 eu = drift_vec3_make(2.0f * r.y, -2.0f * r.x, 0.0f), ev = { 0.0f, 0.0f, 2.0f };
    drift_vec3 corner = drift_vec3_sub(centre, drift_vec3_scale(drift_vec3_add(eu, ev), 0.5f));
    drift_light light = { .color = drift_vec3_splat(radiance) };
    switch (kind) {
    case KIND_QUAD:
        test_add_quad_light(scene, corner, eu, ev, radiance);
        return;
    case KIND_MESH: {
        drift_material lamp = drift_material_make(drift_vec3_splat(0.0f));
        lamp.emission = drift_vec3_splat(radiance);
        test_add_quad(scene, corner, eu, ev, test_add_material(scene, lamp));
        return;
    }
    case KIND_SPHERE:
        light.type = DRIFT_LIGHT_SPHERE;
        light.position = centre;
        light.radius = 1.0f;
        break;
    case KIND_DISK:
        light.type = DRIFT_LIGHT_DISK;
        light.position = centre;
        light.direction = drift_vec3_neg(r);
        light.radius = 1.0f;
        break;
    }
    assert_int_equal(drift_scene_add_light(scene, &light, NULL), DRIFT_OK);
}

typedef struct stage {
    test_rig rig;
    drift_raster_light *lights;
    uint32_t light_count;
    drift_surface surface;
    drift_bsdf bsdf;
    drift_vec3 wo, r;
} stage;

// A receiver at the origin in `m`, seen from wo = (-sin t, cos t, 0), t = 37 degrees, under a
// light of `kind` and radiance 3 around its mirror direction.
static stage stage_make(drift_material m, light_kind kind)
{
    stage st = { .rig = test_rig_begin(1) };
    uint32_t mat = test_add_material(st.rig.scene, m);
    test_add_floor(st.rig.scene, 0.5f, 0.0f, mat);
    st.wo = drift_vec3_make(-0.6f, 0.8f, 0.0f);
    st.r = drift_vec3_make(0.6f, 0.8f, 0.0f);
    add_light(st.rig.scene, kind, st.r, 3.0f);
    test_rig_commit(&st.rig);
    assert_int_equal(
        drift_raster_lights_build(st.rig.ctx, st.rig.scene, &st.lights, &st.light_count), DRIFT_OK);
    assert_int_equal(st.light_count, 1);
    st.surface = (drift_surface){ .position = { 0.0f, 0.0f, 0.0f },
                                  .material = mat,
                                  .light = DRIFT_INVALID_INDEX,
                                  .front_face = true };
    st.surface.ns = st.surface.ng = drift_vec3_make(0.0f, 1.0f, 0.0f);
    st.bsdf = drift_bsdf_make(st.rig.scene, &st.surface);
    return st;
}

static void stage_destroy(stage *st)
{
    drift_raster_lights_destroy(st->rig.ctx, st->lights, st->light_count);
    test_rig_destroy(&st->rig);
}

// U_l's green channel by n samples of each kind, averaged over `pixels` pixels' samplers.
static double unshadowed_mean(stage *st, uint32_t n, uint32_t pixels)
{
    double sum = 0.0;
    for (uint32_t p = 0; p < pixels; ++p) {
        drift_sampler sampler = drift_sampler_make(3, p, 0);
        sum += (double)drift_raster_unshadowed(st->rig.scene, &st->lights[0], &st->surface,
                                               &st->bsdf, st->wo, n, &sampler)
                   .y;
    }
    return sum / pixels;
}

// A smooth conductor (alpha 0.002: not a delta lobe, far narrower than the light) seen in the
// mirror direction of a light of radiance L_e reflects F(theta) L_e: Schlick's
// F = F0 + (1 - F0)(1 - cos)^5 at cos = 0.8, green F0 0.6 (the multiple-scattering share is
// ~0 at this roughness). At the default 2 samples a pixel, the mean of 64 pixels within 2%, and
// every pixel within 25% (a BSDF sample that picks the conductor's broader multiple-scattering
// lobe finds less). Light samples alone gave ~0 (the lobe's solid angle is ~1e-5 of the light's).
static void test_smooth_conductor_mirrors_the_light(void **state)
{
    (void)state;
    const double f = 0.6 + 0.4 * pow(0.2, 5.0), want = 3.0 * f;
    for (int kind = KIND_QUAD; kind <= KIND_DISK; ++kind) {
        stage st = stage_make(ggx_material(0.002f, true), (light_kind)kind);
        const uint32_t pixels = 64;
        double sum = 0.0, lo = INFINITY;
        for (uint32_t p = 0; p < pixels; ++p) {
            drift_sampler sampler = drift_sampler_make(5, p, 0);
            double got = drift_raster_unshadowed(st.rig.scene, &st.lights[0], &st.surface, &st.bsdf,
                                                 st.wo, 2, &sampler)
                             .y;
            sum += got;
            lo = fmin(lo, got);
            assert_near(got, want, 0.25 * want);
        }
        print_message("%s light, smooth conductor: U %.4f (lowest pixel %.4f), F L_e %.4f\n",
                      kind_names[kind], sum / pixels, lo, want);
        assert_near(sum / pixels, want, 0.02 * want);
        stage_destroy(&st);
    }
}

// Rough lobes (roughness 0.25, 0.5, 0.8: alpha 0.0625, 0.25, 0.64) of the conductor and the
// plastic's coat against the Monte Carlo of the same BSDF by light samples alone (200000 of
// them: converged for these lobes), within 3%: the two estimators' MIS weights sum to one. (The
// 2 x 2 lights subtend ~28 degrees of radius here: alpha 0.0625's 90% cone of 21 degrees takes
// BSDF samples, the two wider lobes light samples alone.)
static void test_rough_lobes_match_monte_carlo(void **state)
{
    (void)state;
    const float alphas[] = { 0.0625f, 0.25f, 0.64f };
    for (int kind = KIND_QUAD; kind <= KIND_DISK; ++kind) {
        for (int metal = 0; metal < 2; ++metal) {
            for (size_t a = 0; a < sizeof alphas / sizeof *alphas; ++a) {
                stage st = stage_make(ggx_material(alphas[a], metal), (light_kind)kind);
                double got = unshadowed_mean(&st, 64, 16);
                double mc =
                    test_direct_light_mc(st.rig.scene, 0, &st.surface, &st.bsdf, st.wo, 200000, 1);
                if (kind == KIND_MESH) { // two triangle lights: the sum of both
                    mc += test_direct_light_mc(st.rig.scene, 1, &st.surface, &st.bsdf, st.wo,
                                               200000, 1);
                }
                print_message("%s light, %s alpha %.4f: U %.4f, Monte Carlo %.4f (%.3f)\n",
                              kind_names[kind], metal ? "conductor" : "plastic", (double)alphas[a],
                              got, mc, got / mc);
                assert_true(mc > 0.0);
                assert_near(got, mc, 0.03 * mc);
                stage_destroy(&st);
            }
        }
    }
}

// A point light (a delta light: no BSDF samples) stays exact: f I cos / d^2.
static void test_point_light_is_exact(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(1);
    uint32_t mat = test_add_material(r.scene, ggx_material(0.25f, true));
    test_add_floor(r.scene, 0.5f, 0.0f, mat);
    drift_light point = { .type = DRIFT_LIGHT_POINT,
                          .position = { 1.2f, 1.6f, 0.0f },
                          .color = { 4, 4, 4 } };
    assert_int_equal(drift_scene_add_light(r.scene, &point, NULL), DRIFT_OK);
    test_rig_commit(&r);
    drift_raster_light *lights = NULL;
    uint32_t count = 0;
    assert_int_equal(drift_raster_lights_build(r.ctx, r.scene, &lights, &count), DRIFT_OK);
    drift_surface s = { .material = mat, .light = DRIFT_INVALID_INDEX, .front_face = true };
    s.ns = s.ng = drift_vec3_make(0.0f, 1.0f, 0.0f);
    drift_bsdf bsdf = drift_bsdf_make(r.scene, &s);
    drift_vec3 wo = drift_vec3_make(-0.6f, 0.8f, 0.0f), wi = drift_vec3_make(0.6f, 0.8f, 0.0f);
    drift_sampler sampler = drift_sampler_make(1, 0, 0);
    float got = drift_raster_unshadowed(r.scene, &lights[0], &s, &bsdf, wo, 2, &sampler).y;
    float want = drift_bsdf_eval(&bsdf, wo, wi).y * 4.0f / 4.0f * 0.8f;
    print_message("point light: U %.5f, f L cos / d^2 %.5f\n", (double)got, (double)want);
    assert_near(got, want, 1e-4f * want);
    drift_raster_lights_destroy(r.ctx, lights, count);
    test_rig_destroy(&r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_smooth_conductor_mirrors_the_light),
        cmocka_unit_test(test_rough_lobes_match_monte_carlo),
        cmocka_unit_test(test_point_light_is_exact),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
