// test_hybrid, part: emissive meshes that emit from both faces (drift_material.emission_two_sided,
// glTF doubleSided as Cycles draws it) light the hybrid frame behind their plane as the path
// tracer does: the closed form of U_l, the shadow maps' faces and SIR's planar test.
#include "hybrid_tests.h"

// A floor at y = 0, a square occluder at y = 0.8 and a 0.6 m square emissive mesh at y = 2
// whose front faces +y: the floor and the camera (below it) see only its back.
static void two_sided_stage(test_rig *r, bool two_sided)
{
    uint32_t white = test_add_material(r->scene, drift_material_make(drift_vec3_splat(0.7f)));
    drift_material glow = drift_material_make(drift_vec3_splat(0.0f));
    glow.emission = drift_vec3_splat(6.0f);
    glow.emission_two_sided = two_sided;
    uint32_t lamp = test_add_material(r->scene, glow);
    test_add_floor(r->scene, 3.0f, 0.0f, white);
    test_add_quad(r->scene, drift_vec3_make(-0.4f, 0.8f, -0.4f), drift_vec3_make(0.8f, 0, 0),
                  drift_vec3_make(0, 0, 0.8f), white); // faces -y: cross(x, z)
    // cross(z, x) = +y: the front looks up, away from everything.
    test_add_quad(r->scene, drift_vec3_make(-0.3f, 2.0f, -0.3f), drift_vec3_make(0, 0, 0.6f),
                  drift_vec3_make(0.6f, 0, 0), lamp);
    r->scene->camera =
        drift_camera_look_at(drift_vec3_make(0.0f, 1.6f, -3.0f), drift_vec3_make(0.0f, 0.3f, 0.0f),
                             drift_vec3_make(0, 1, 0), 1.0f, 40, 30);
    test_rig_commit(r);
}

// At floor points in the open, in the occluder's shadow's edge and straddling nothing: the
// closed form of a two-sided mesh light behind its plane equals the Monte Carlo integral of
// the path tracer's light sampling, summed over its two triangles; one-sided, both are 0.
void test_two_sided_mesh_light_closed_form(void **state)
{
    (void)state;
    const drift_vec3 points[] = { { 0, 0, 0 }, { 1.2f, 0, 0.4f }, { -0.5f, 1.0f, 2.0f } };
    for (int two = 0; two < 2; ++two) {
        test_rig r = test_rig_begin(1);
        two_sided_stage(&r, two == 1);
        drift_raster_light *lights = NULL;
        uint32_t count = 0;
        assert_int_equal(drift_raster_lights_build(r.ctx, r.scene, &lights, &count), DRIFT_OK);
        assert_int_equal(count, 1);
        assert_int_equal(lights[0].two_sided, two == 1);
        for (size_t c = 0; c < sizeof points / sizeof *points; ++c) {
            drift_surface s = { .position = points[c],
                                .material = 0,
                                .light = DRIFT_INVALID_INDEX };
            s.ns = s.ng = drift_vec3_make(0, 1, 0);
            drift_bsdf bsdf = drift_bsdf_make(r.scene, &s);
            drift_sampler sampler = drift_sampler_make(1, 0, 0);
            drift_vec3 closed =
                drift_raster_unshadowed(r.scene, &lights[0], &s, &bsdf, s.ns, 8, &sampler);
            double mc = 0.0;
            for (uint32_t t = 0; t < lights[0].light_count; ++t) {
                mc += test_direct_light_mc(r.scene, lights[0].first_light + t, &s, &bsdf, s.ns,
                                           100000, 0);
            }
            print_message("%s-sided, point %zu: closed form %g, Monte Carlo %g\n",
                          two ? "two" : "one", c, (double)closed.x, mc);
            assert_near(closed.x, mc, 0.01 * mc + 1e-7);
            assert_true(two ? mc > 1e-3 : mc == 0.0);
        }
        drift_raster_lights_destroy(r.ctx, lights, count);
        test_rig_destroy(&r);
    }
}

// The rig's hybrid frame with direct light only, shadows by `shadows`.
static const drift_image *direct_light_frame(test_rig *r, drift_shadow_technique shadows)
{
    drift_hybrid_params p = { .seed = 3, .spp = 16 };
    p.shadows = shadows;
    p.reflections = DRIFT_REFLECTIONS_NONE;
    p.indirect = DRIFT_INDIRECT_NONE;
    p.dof = DRIFT_DOF_NONE;
    test_rig_frame(r, &p);
    return drift_hybrid_image(r->frame);
}

// The whole hybrid frame (direct light only, each shadow technique) against the path
// tracer's emission + direct light of the same scene: the floor lit by the back of a
// two-sided emitter, the occluder's shadow under it. Before the hybrid lights honoured
// two-sidedness the floor was black (closed form) and the occluder cast no shadow map.
void test_two_sided_emitter_lights_hybrid_frame(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    two_sided_stage(&r, true);
    drift_pt *pt = NULL;
    drift_image truth = test_rig_render_pt(
        &r, DRIFT_PT_COMPONENT_EMISSION | DRIFT_PT_COMPONENT_DIRECT, 1, 512, 5, &pt);
    double truth_mean = drift_image_mean_luminance(&truth);
    const drift_shadow_technique rows[] = { DRIFT_SHADOWS_HARD, DRIFT_SHADOWS_PCF,
                                            DRIFT_SHADOWS_PCSS, DRIFT_SHADOWS_ISG,
                                            DRIFT_SHADOWS_AAF,  DRIFT_SHADOWS_REFERENCE };
    for (size_t i = 0; i < sizeof rows / sizeof *rows; ++i) {
        const drift_image *img = direct_light_frame(&r, rows[i]);
        double ratio = drift_image_mean_luminance(img) / truth_mean;
        double nrmse = test_nrmse(r.ctx, &truth, img);
        print_message("shadows %-9s mean luminance / path tracer %.4f, NRMSE %.4f\n",
                      drift_technique_name(DRIFT_EFFECT_SHADOWS, (int)rows[i]), ratio, nrmse);
        assert_true(fabs(ratio - 1.0) < 0.05);
        assert_true(nrmse < 0.25);
    }
    drift_pt_destroy(pt); // owns `truth`
    test_rig_destroy(&r);
}

// A two-sided emissive cube (one mesh, 8 shared corners, fronts facing out) 0.5 m above the
// floor: the floor sees the fronts of its bottom and sides; the backs of the top and far sides
// face the floor too but their light stays inside the cube. Commit makes it one-sided, so the
// hybrid frame's unshadowed closed form (which does not see a light's own surface) no longer
// counts those backs: before, the frame was ~1.5x the path tracer. With the camera inside the
// cube, the backs are what it sees lit: the cube stays two-sided.
static void emissive_cube_stage(test_rig *r, drift_vec3 eye, drift_vec3 target)
{
    uint32_t white = test_add_material(r->scene, drift_material_make(drift_vec3_splat(0.7f)));
    drift_material glow = drift_material_make(drift_vec3_splat(0.0f));
    glow.emission = drift_vec3_splat(4.0f);
    glow.emission_two_sided = true;
    uint32_t lamp = test_add_material(r->scene, glow);
    test_add_floor(r->scene, 3.0f, 0.0f, white);
    float p[24];
    for (int v = 0; v < 8; ++v) {
        p[3 * v + 0] = (v & 1) ? 0.25f : -0.25f;
        p[3 * v + 1] = (v & 2) ? 1.0f : 0.5f;
        p[3 * v + 2] = (v & 4) ? 0.25f : -0.25f;
    }
    // Corner bit 0: +x, bit 1: +y, bit 2: +z; each face's two triangles wound to face out.
    const uint32_t idx[36] = { 0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5, 0, 1, 5, 0, 5, 4,
                               2, 6, 7, 2, 7, 3, 0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6 };
    test_add_mesh(r->scene, p, 8, idx, 12, lamp);
    r->scene->camera = drift_camera_look_at(eye, target, drift_vec3_make(0, 1, 0), 1.0f, 40, 30);
    test_rig_commit(r);
}

void test_closed_two_sided_emitter_is_one_sided(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    emissive_cube_stage(&r, drift_vec3_make(0.0f, 1.6f, -3.0f), drift_vec3_make(0.0f, 0.3f, 0.0f));
    const drift_mesh *cube = &r.scene->meshes[1];
    for (uint32_t t = 0; t < cube->triangle_count; ++t) {
        assert_false(r.scene->lights[cube->first_light + t].two_sided);
    }
    drift_pt *pt = NULL;
    drift_image truth = test_rig_render_pt(
        &r, DRIFT_PT_COMPONENT_EMISSION | DRIFT_PT_COMPONENT_DIRECT, 1, 256, 5, &pt);
    double truth_mean = drift_image_mean_luminance(&truth);
    const drift_shadow_technique rows[] = { DRIFT_SHADOWS_HARD, DRIFT_SHADOWS_ISG };
    for (size_t i = 0; i < sizeof rows / sizeof *rows; ++i) {
        double ratio = drift_image_mean_luminance(direct_light_frame(&r, rows[i])) / truth_mean;
        print_message("closed cube, shadows %-4s: mean luminance / path tracer %.4f\n",
                      drift_technique_name(DRIFT_EFFECT_SHADOWS, (int)rows[i]), ratio);
        assert_true(fabs(ratio - 1.0) < 0.05);
    }
    drift_pt_destroy(pt); // owns `truth`
    test_rig_destroy(&r);

    test_rig inside = test_rig_begin(1);
    emissive_cube_stage(&inside, drift_vec3_make(0.0f, 0.75f, 0.0f),
                        drift_vec3_make(0.0f, 0.75f, 1.0f));
    const drift_mesh *box = &inside.scene->meshes[1];
    assert_true(inside.scene->lights[box->first_light].two_sided);
    test_rig_destroy(&inside);
}
