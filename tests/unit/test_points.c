// Scene points (src/points): area-proportional over triangles (chi-square), every subset too;
// subsets are disjoint and cover the points; the same seed gives the same points on any
// thread count; points follow a moved mesh through their barycentrics.
#include "drift/points.h"
#include "drift/scene.h"
#include "drift_test.h"
#include "test_rig.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

// Triangles of very different areas: a 4 x 1 quad, a 1 x 1 quad, a small triangle, and an
// emissive 1 x 1 quad.
static void build_scene(test_rig *r)
{
    uint32_t m = test_add_material(r->scene, drift_material_make(drift_vec3_splat(0.5f)));
    test_add_quad(r->scene, drift_vec3_make(0, 0, 0), drift_vec3_make(4, 0, 0),
                  drift_vec3_make(0, 0, 1), m);
    test_add_quad(r->scene, drift_vec3_make(0, 1, 0), drift_vec3_make(1, 0, 0),
                  drift_vec3_make(0, 1, 0), m);
    float tri[9] = { 0, 0, 3, 0.5f, 0, 3, 0, 0.3f, 3 };
    uint32_t idx[3] = { 0, 1, 2 };
    test_add_mesh(r->scene, tri, 3, idx, 1, m);
    drift_material e = drift_material_make(drift_vec3_splat(0.5f));
    e.emission = drift_vec3_splat(1.0f);
    uint32_t em = test_add_material(r->scene, e);
    test_add_quad(r->scene, drift_vec3_make(0, 3, 0), drift_vec3_make(1, 0, 0),
                  drift_vec3_make(0, 0, 1), em);
    test_rig_commit(r);
}

static double triangle_area(const drift_scene *scene, uint32_t mesh, uint32_t t)
{
    const drift_mesh *m = &scene->meshes[mesh];
    const float *p = m->positions;
    const uint32_t *i = m->indices + 3 * t;
    drift_vec3 a = { p[3 * i[0]], p[3 * i[0] + 1], p[3 * i[0] + 2] };
    drift_vec3 b = { p[3 * i[1]], p[3 * i[1] + 1], p[3 * i[1] + 2] };
    drift_vec3 c = { p[3 * i[2]], p[3 * i[2] + 1], p[3 * i[2] + 2] };
    return 0.5 *
           (double)drift_vec3_length(drift_vec3_cross(drift_vec3_sub(b, a), drift_vec3_sub(c, a)));
}

// Chi-square of the points [begin, begin + count) over the scene's triangles against the
// area-proportional expectation; *out_dof gets the degrees of freedom.
static double chi_square(const drift_scene *scene, const drift_points *pts, uint32_t begin,
                         uint32_t count, bool skip_emissive, int *out_dof)
{
    double total_area = 0.0;
    double chi = 0.0;
    int dof = -1;
    for (uint32_t m = 0; m < scene->mesh_count; ++m) {
        bool skip = skip_emissive &&
                    !drift_vec3_is_zero(scene->materials[scene->meshes[m].material].emission);
        for (uint32_t t = 0; t < scene->meshes[m].triangle_count; ++t) {
            total_area += skip ? 0.0 : triangle_area(scene, m, t);
        }
    }
    for (uint32_t m = 0; m < scene->mesh_count; ++m) {
        bool skip = skip_emissive &&
                    !drift_vec3_is_zero(scene->materials[scene->meshes[m].material].emission);
        for (uint32_t t = 0; t < scene->meshes[m].triangle_count; ++t) {
            uint32_t observed = 0;
            for (uint32_t i = begin; i < begin + count; ++i) {
                observed += pts->points[i].mesh == m && pts->points[i].triangle == t;
            }
            if (skip) {
                assert_int_equal(observed, 0);
                continue;
            }
            double expected = (double)count * triangle_area(scene, m, t) / total_area;
            chi += ((double)observed - expected) * ((double)observed - expected) / expected;
            dof++;
        }
    }
    *out_dof = dof;
    return chi;
}

// Every point lies on its triangle (barycentrics in the triangle), the counts per triangle
// pass a chi-square test against the areas (for all points and for one subset), and with
// skip_emissive the light gets none.
static void test_points_are_area_proportional(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    build_scene(&r);
    for (int skip = 0; skip < 2; ++skip) {
        drift_points *pts = NULL;
        assert_int_equal(drift_points_create(r.ctx, r.scene,
                                             &(drift_points_desc){ .count = 40000,
                                                                   .subset_count = 16,
                                                                   .seed = 11,
                                                                   .skip_emissive = skip },
                                             &pts),
                         DRIFT_OK);
        for (uint32_t i = 0; i < pts->count; ++i) {
            const drift_scene_point *p = &pts->points[i];
            assert_true(p->b1 >= 0.0f && p->b2 >= 0.0f && p->b1 + p->b2 <= 1.0f);
        }
        int dof;
        // 99.9th percentile of chi-square with 6 or 4 degrees of freedom: 22.5, 18.5.
        double chi = chi_square(r.scene, pts, 0, pts->count, skip, &dof);
        assert_true(chi < (dof == 6 ? 22.5 : 18.5));
        uint32_t begin, count;
        drift_points_subset(pts, 5, &begin, &count);
        chi = chi_square(r.scene, pts, begin, count, skip, &dof);
        assert_true(chi < (dof == 6 ? 22.5 : 18.5));
        double expected_area = skip ? 4.0 + 1.0 + 0.075 : 4.0 + 1.0 + 0.075 + 1.0;
        assert_near(pts->area, expected_area, 1e-4);
        drift_points_destroy(pts);
    }
    test_rig_destroy(&r);
}

// Subsets are consecutive, disjoint, sizes within one, and cover all points.
static void test_subsets_partition_the_points(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(1);
    build_scene(&r);
    drift_points *pts = NULL;
    assert_int_equal(drift_points_create(r.ctx, r.scene,
                                         &(drift_points_desc){ .count = 1000, .subset_count = 7 },
                                         &pts),
                     DRIFT_OK);
    uint32_t next = 0;
    for (uint32_t s = 0; s < 7; ++s) {
        uint32_t begin, count;
        drift_points_subset(pts, s, &begin, &count);
        assert_int_equal(begin, next);
        assert_true(count == 142 || count == 143);
        next = begin + count;
    }
    assert_int_equal(next, 1000);
    drift_points_destroy(pts);
    assert_int_equal(drift_points_create(r.ctx, r.scene,
                                         &(drift_points_desc){ .count = 10, .subset_count = 11 },
                                         &pts),
                     DRIFT_ERR_INVALID_ARGUMENT);
    assert_null(pts);
    test_rig_destroy(&r);
}

// One seed gives the same points on 1 and 2 threads; another seed gives others.
static void test_points_are_deterministic(void **state)
{
    (void)state;
    drift_points *a = NULL, *b = NULL, *c = NULL;
    test_rig r1 = test_rig_begin(1), r2 = test_rig_begin(2);
    build_scene(&r1);
    build_scene(&r2);
    drift_points_desc d = { .count = 5000, .seed = 4 };
    assert_int_equal(drift_points_create(r1.ctx, r1.scene, &d, &a), DRIFT_OK);
    assert_int_equal(drift_points_create(r2.ctx, r2.scene, &d, &b), DRIFT_OK);
    d.seed = 5;
    assert_int_equal(drift_points_create(r2.ctx, r2.scene, &d, &c), DRIFT_OK);
    assert_memory_equal(a->points, b->points, 5000 * sizeof *a->points);
    assert_memory_equal(a->position, b->position, 5000 * sizeof *a->position);
    assert_true(memcmp(a->points, c->points, 5000 * sizeof *a->points) != 0);
    drift_points_destroy(a);
    drift_points_destroy(b);
    drift_points_destroy(c);
    test_rig_destroy(&r1);
    test_rig_destroy(&r2);
}

// Moving a mesh's vertices and updating moves its points with it (barycentric storage), a
// range update only the points of the range.
static void test_points_follow_a_moved_mesh(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(1);
    build_scene(&r);
    drift_points *pts = NULL;
    assert_int_equal(
        drift_points_create(r.ctx, r.scene, &(drift_points_desc){ .count = 2000 }, &pts), DRIFT_OK);
    drift_vec3 *before = malloc(pts->count * sizeof *before);
    memcpy(before, pts->position, pts->count * sizeof *before);
    drift_mesh *m = &r.scene->meshes[0];
    for (uint32_t v = 0; v < m->vertex_count; ++v) {
        m->positions[3 * v + 1] += 2.0f;
    }
    // A range update moves the points of the range only.
    assert_int_equal(drift_points_update_range(pts, r.scene, 100, 50), DRIFT_OK);
    for (uint32_t i = 0; i < pts->count; ++i) {
        float dy = pts->points[i].mesh == 0 && i >= 100 && i < 150 ? 2.0f : 0.0f;
        assert_near(pts->position[i].y, before[i].y + dy, 1e-5);
    }
    assert_int_equal(drift_points_update_range(pts, r.scene, 1990, 11), DRIFT_ERR_INVALID_ARGUMENT);
    assert_int_equal(drift_points_update(pts, r.scene), DRIFT_OK);
    for (uint32_t i = 0; i < pts->count; ++i) {
        float dy = pts->points[i].mesh == 0 ? 2.0f : 0.0f;
        assert_near(pts->position[i].x, before[i].x, 1e-5);
        assert_near(pts->position[i].y, before[i].y + dy, 1e-5);
        assert_near(pts->position[i].z, before[i].z, 1e-5);
    }
    free(before);
    drift_points_destroy(pts);
    test_rig_destroy(&r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_points_are_area_proportional),
        cmocka_unit_test(test_subsets_partition_the_points),
        cmocka_unit_test(test_points_are_deterministic),
        cmocka_unit_test(test_points_follow_a_moved_mesh),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
