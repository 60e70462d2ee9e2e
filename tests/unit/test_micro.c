// Micro-rendering (src/micro): the objective tests of the thesis spec §4.5 that a CPU build
// can run in seconds. The warp is distribution-correct (chi-square against f_r cos / rho for
// diffuse and Phong 1, 5, 20), round-trips and its pixels' solid angles sum to 2 pi; a white
// furnace inside a closed sphere gives rho L with every pixel filled once ray casting runs
// (holes without it); the hierarchy's spheres and cones contain their children's after a
// deformation and refit; the cut splats only nodes within their pixel's solid angle and
// visits grow sub-linearly with the points; every-pixel gathering matches the path tracer's
// first-bounce diffuse light on the Cornell box (upsampled within 2x of that); no pixel
// exceeds rho max L; the error shrinks from K = 8 to 16 to 24.
// ctest-labels: quality
#include "drift/accel.h"
#include "drift/hybrid.h"
#include "drift/metric.h"
#include "drift/micro.h"
#include "drift/pt.h"
#include "drift/scene.h"
#include "drift/scene_io.h"
#include "drift_test.h"
#include "micro/micro_internal.h"
#include "test_rig.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

// --- HELPERS ---

// The Cornell box at w x w, committed with its accel, and a G-buffer frame.
static test_rig cornell_rig(int threads, int32_t w)
{
    return test_rig_load(threads, "scenes/cornell-box/cornell_box.json", w);
}

static drift_micro *render_micro(test_rig *r, const drift_micro_params *params,
                                 drift_micro_lobe lobe)
{
    drift_micro *m = NULL;
    assert_int_equal(drift_micro_create(r->ctx, r->scene, r->accel, params, &m), DRIFT_OK);
    assert_int_equal(drift_micro_render(m, drift_hybrid_gbuffer(r->frame), &r->scene->camera, lobe),
                     DRIFT_OK);
    return m;
}

// --- TESTS ---

typedef struct phong_slice {
    float n;
    drift_vec3 mirror; // local mirror direction of the view
} phong_slice;

// The Phong lobe (n + 2) / (2 pi) cos^n(alpha) around the mirror direction.
static float phong_lobe(drift_vec3 omega, const void *user)
{
    const phong_slice *s = user;
    float c = drift_vec3_dot(omega, s->mirror);
    return c > 0.0f ? (s->n + 2.0f) / (2.0f * DRIFT_PI) * powf(c, s->n) : 0.0f;
}

// A grid over [0, 1]^2 mapped through Phi and back lands where it started (within the table's
// precision), and the micro-buffer pixels' solid angles sum to 2 pi.
static void test_warp_round_trip_and_solid_angles(void **state)
{
    (void)state;
    drift__micro_warp *warp = malloc(sizeof *warp);
    drift__micro_pixels *pixels = malloc(sizeof *pixels);
    for (int lobe = 0; lobe < 3; ++lobe) {
        phong_slice slice = { lobe == 2 ? 200.0f : 5.0f,
                              lobe == 2 ? drift_vec3_normalize(drift_vec3_make(0.3f, -0.2f, 0.9f))
                                        : drift_vec3_make(0.0f, 0.0f, 1.0f) };
        if (lobe == 0) {
            drift__micro_warp_build_diffuse(warp, 32);
            assert_float_equal(warp->rho, 1.0f, 1e-4f);
        } else if (lobe == 1) {
            drift__micro_warp_build(warp, 32, phong_lobe, &slice);
        } else {
            drift__micro_warp_build_cap(warp, 32, slice.mirror, drift__micro_phong_cap(200.0f),
                                        phong_lobe, &slice);
        }
        double worst = 0.0;
        for (int j = 0; j < 64; ++j) {
            for (int i = 0; i < 64; ++i) {
                drift_vec2 xy =
                    drift_vec2_make(((float)i + 0.5f) / 64.0f, ((float)j + 0.5f) / 64.0f);
                float pdf;
                drift_vec3 w = drift__micro_warp_forward(warp, xy, &pdf);
                assert_float_equal(drift_vec3_length(w), 1.0f, 1e-4f);
                assert_true(w.z >= 0.0f);
                drift_vec2 back = drift__micro_warp_inverse(warp, w);
                worst =
                    fmax(worst, fmax(fabs((double)(back.x - xy.x)), fabs((double)(back.y - xy.y))));
            }
        }
        printf("lobe %d: worst round trip %.2e\n", lobe, worst);
        assert_true(worst < 1e-3);
        drift__micro_pixels_make(pixels, warp, 24);
        double sum = 0.0;
        for (int q = 0; q < 24 * 24; ++q) {
            sum += (double)pixels->omega[q];
        }
        // The hemisphere's 2 pi, or the cap's 2 pi (1 - cos).
        double whole = 2.0 * (double)DRIFT_PI *
                       (1.0 - sqrt(fmax(1.0 - (double)warp->scale * (double)warp->scale, 0.0)));
        printf("lobe %d: pixels' solid angles sum to %.4f (expected %.4f)\n", lobe, sum, whole);
        assert_true(fabs(sum - whole) < (lobe == 0 ? 0.02 : 0.1) * whole);
    }
    free(warp);
    free(pixels);
}

// Expected share of f_r cos / rho in each of B x B bins of (cos theta, phi) about the warp's
// axis (the normal, or a cap's axis), by fine quadrature of the exact lobe; observed: a 128^2
// grid through Phi. Their L1 distance is small and rho matches the quadrature's. scale < 1:
// the warp over the cap of that sine around slice->mirror.
#define BINS 8

static void check_warp_distribution(drift__micro_lobe_fn lobe, const void *user, float scale,
                                    drift_vec3 axis, const char *what)
{
    drift__micro_warp *warp = malloc(sizeof *warp);
    drift__micro_warp_build_cap(warp, 64, axis, scale, lobe, user);
    float cap_cos = sqrtf(fmaxf(1.0f - warp->scale * warp->scale, 0.0f));
    double expected[BINS * BINS] = { 0 }, observed[BINS * BINS] = { 0 }, rho = 0.0;
    const int fine = 512;
    for (int j = 0; j < fine; ++j) {
        for (int i = 0; i < fine; ++i) {
            // Uniform in (cos theta, phi) about the axis: d omega = d cos d phi.
            float ct = cap_cos + (1.0f - cap_cos) * ((float)j + 0.5f) / (float)fine,
                  phi = 2.0f * DRIFT_PI * ((float)i + 0.5f) / (float)fine;
            float st = sqrtf(1.0f - ct * ct);
            drift_vec3 w = drift_frame_to_world(
                &warp->cap, drift_vec3_make(st * cosf(phi), st * sinf(phi), ct));
            double f = w.z > 0.0f ? (double)lobe(w, user) * (double)w.z * 2.0 * (double)DRIFT_PI *
                                        (double)(1.0f - cap_cos) / ((double)fine * fine)
                                  : 0.0;
            rho += f;
            expected[(j * BINS / fine) * BINS + i * BINS / fine] += f;
        }
    }
    const int grid = 128;
    for (int j = 0; j < grid; ++j) {
        for (int i = 0; i < grid; ++i) {
            float pdf;
            drift_vec3 w = drift_frame_to_local(
                &warp->cap,
                drift__micro_warp_forward(warp,
                                          drift_vec2_make(((float)i + 0.5f) / (float)grid,
                                                          ((float)j + 0.5f) / (float)grid),
                                          &pdf));
            float phi = atan2f(w.y, w.x);
            phi = phi < 0.0f ? phi + 2.0f * DRIFT_PI : phi;
            int bt = (int)((w.z - cap_cos) / (1.0f - cap_cos) * BINS),
                bp = (int)(phi / (2.0f * DRIFT_PI) * BINS);
            bt = bt >= BINS ? BINS - 1 : (bt < 0 ? 0 : bt);
            bp = bp >= BINS ? BINS - 1 : bp;
            observed[bt * BINS + bp] += 1.0 / (grid * grid);
        }
    }
    double l1 = 0.0, chi2 = 0.0;
    for (int b = 0; b < BINS * BINS; ++b) {
        double e = expected[b] / rho;
        l1 += fabs(observed[b] - e);
        if (e > 1e-4) {
            chi2 += (observed[b] - e) * (observed[b] - e) / e * (grid * grid);
        }
    }
    printf("%s: rho %.4f (table %.4f), L1 %.4f, chi2 %.1f over %d bins\n", what, rho,
           (double)warp->rho, l1, chi2, BINS * BINS);
    assert_true(fabs((double)warp->rho - rho) < 0.02 * rho);
    assert_true(l1 < 0.04);
    free(warp);
}

static float diffuse_lobe(drift_vec3 omega, const void *user)
{
    (void)omega;
    (void)user;
    return DRIFT_INV_PI;
}

// Spec §4.5 test 1: the warped directions are distributed as f_r cos / rho for the diffuse
// lobe and Phong n = 1, 5, 20 (the exponents of Fig. 6.5), off the normal.
static void test_warp_is_distribution_correct(void **state)
{
    (void)state;
    drift_vec3 z = drift_vec3_make(0.0f, 0.0f, 1.0f);
    check_warp_distribution(diffuse_lobe, NULL, 1.0f, z, "diffuse");
    float exponents[3] = { 1.0f, 5.0f, 20.0f };
    for (int i = 0; i < 3; ++i) {
        phong_slice slice = { exponents[i],
                              drift_vec3_normalize(drift_vec3_make(0.4f, 0.2f, 0.9f)) };
        char what[32];
        snprintf(what, sizeof what, "phong %g", (double)exponents[i]);
        check_warp_distribution(phong_lobe, &slice, 1.0f, z, what);
    }
    // The sharp lobes of the glossy scenes (60-200) through the cap around the lobe's axis,
    // one of them grazing (the cap cut by the horizon).
    float sharp[3] = { 20.0f, 60.0f, 200.0f };
    for (int i = 0; i < 3; ++i) {
        phong_slice slice = { sharp[i], drift_vec3_normalize(
                                            drift_vec3_make(0.4f, 0.2f, i == 1 ? 0.1f : 0.9f)) };
        char what[32];
        snprintf(what, sizeof what, "phong %g, cap", (double)sharp[i]);
        assert_true(drift__micro_phong_cap(sharp[i]) < 1.0f);
        check_warp_distribution(phong_lobe, &slice, drift__micro_phong_cap(sharp[i]), slice.mirror,
                                what);
    }
}

// A tree over `count` points of the rig's committed scene (its points returned too).
static void make_tree(test_rig *r, uint32_t count, drift_points **points, drift__micro_tree *tree)
{
    assert_int_equal(
        drift_points_create(r->ctx, r->scene, &(drift_points_desc){ .count = count }, points),
        DRIFT_OK);
    assert_int_equal(drift__micro_tree_create(r->ctx, *points, tree), DRIFT_OK);
}

// Spec §4.5 test 2: at the centre of a closed sphere whose points all have radiance L every
// micro-buffer pixel is filled once ray casting runs, and the gather gives L (so L_out =
// rho L) within 1%, for the diffuse lobe and warped Phong lobes; without ray casting pixels
// stay empty and the mean falls short.
static void test_white_furnace(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    uint32_t mat = test_add_material(r.scene, drift_material_make(drift_vec3_splat(0.5f)));
    test_add_sphere(r.scene, drift_vec3_splat(0.0f), 1.0f, 96, 48, mat);
    test_rig_commit(&r);
    drift_points *points;
    drift__micro_tree tree;
    make_tree(&r, 4096, &points, &tree);
    for (uint32_t i = 0; i < tree.node_count; ++i) {
        tree.front[i] = tree.back[i] = drift_vec3_splat(2.0f);
    }
    drift__micro_tree_pull(&tree);
    drift__micro_warp *warp = malloc(sizeof *warp);
    drift__micro_pixels *pixels = malloc(sizeof *pixels);
    int32_t nodes[DRIFT_MICRO_MAX_K * DRIFT_MICRO_MAX_K];
    for (int lobe = 0; lobe < 4; ++lobe) {
        phong_slice slice = { lobe == 1 ? 5.0f : (lobe == 2 ? 20.0f : 200.0f),
                              drift_vec3_normalize(drift_vec3_make(0.4f, 0.2f, 0.9f)) };
        if (lobe == 0) {
            drift__micro_warp_build_diffuse(warp, 32);
        } else if (lobe < 3) {
            drift__micro_warp_build(warp, 32, phong_lobe, &slice);
        } else {
            // Phong 200 through the cap around its axis (the glossy gathers' warp).
            drift__micro_warp_build_cap(warp, 32, slice.mirror, drift__micro_phong_cap(200.0f),
                                        phong_lobe, &slice);
        }
        drift__micro_pixels_make(pixels, warp, 16);
        // At the centre, and near the bottom looking up (near leaves bigger than their pixel).
        for (int where = 0; where < 2; ++where) {
            drift_vec3 p = where ? drift_vec3_make(0.0f, -0.9f, 0.0f) : drift_vec3_splat(0.0f);
            drift_frame frame = drift_frame_from_normal(
                where ? drift_vec3_make(0.0f, 1.0f, 0.0f)
                      : drift_vec3_normalize(drift_vec3_make(0.2f, 1.0f, 0.1f)));
            for (int cast = 0; cast < 2; ++cast) {
                drift__micro_gather_desc desc = {
                    &tree, cast ? r.accel : NULL, warp, pixels, 1.0f, NULL, 0
                };
                drift__micro_gather_stats st = { 0 };
                drift_vec3 mean = drift__micro_gather(&desc, p, &frame, frame.z, nodes, &st, NULL);
                int empty = 0;
                for (int q = 0; q < 16 * 16; ++q) {
                    empty += nodes[q] < 0;
                }
                printf("lobe %d at %d, ray casting %d: mean %.4f (L = 2), %d empty, %.0f visited, "
                       "%.0f post\n",
                       lobe, where, cast, (double)mean.y, empty, (double)st.visited,
                       (double)st.post_leaves);
                if (cast) {
                    assert_int_equal(empty, 0);
                    assert_float_equal(mean.y, 2.0f, 0.02f);
                } else if (lobe < 3) {
                    assert_true(empty > 0);
                    assert_true(mean.y < 1.9f);
                }
            }
        }
    }
    free(warp);
    free(pixels);
    drift__micro_tree_destroy(r.ctx, &tree);
    drift_points_destroy(points);
    test_rig_destroy(&r);
}

// A floor laid 0.005 over another (cornell-glossy's glossy floor over the box's own): the
// lower floor's leaves lie in the dark under the cover, and a node that mixes them with the
// cover's must still show the cover's light from above. Leaf radiance 1 on the cover, 0 under
// it: every node seen from above gives exactly 1 once the covered sides are marked (0.5
// without).
static void test_covered_leaves_left_out(void **state)
{
    (void)state;
    test_rig r = test_rig_begin(2);
    uint32_t mat = test_add_material(r.scene, drift_material_make(drift_vec3_splat(0.5f)));
    test_add_floor(r.scene, 1.0f, 0.0f, mat);
    test_add_floor(r.scene, 1.0f, 0.005f, mat);
    test_rig_commit(&r);
    drift_points *points;
    drift__micro_tree tree;
    make_tree(&r, 4096, &points, &tree);
    uint32_t n = tree.leaf_count;
    for (uint32_t j = 0; j < n; ++j) {
        bool cover = tree.center[n - 1 + j].y > 0.0025f;
        tree.front[n - 1 + j] = drift_vec3_splat(cover ? 1.0f : 0.0f);
        tree.back[n - 1 + j] = drift_vec3_splat(0.0f);
    }
    drift__micro_tree_cover(r.ctx, &tree, r.accel);
    drift__micro_tree_pull(&tree);
    float lo = INFINITY, hi = -INFINITY;
    for (uint32_t i = 0; i < n - 1; ++i) {
        if (!drift__micro_tree_seen(&tree, i, drift_vec3_make(0.0f, 1.0f, 0.0f))) {
            continue; // under the cover only: the gathers do not show it from above
        }
        float v = drift__micro_tree_radiance(&tree, i, drift_vec3_make(0.0f, 1.0f, 0.0f)).y;
        lo = fminf(lo, v);
        hi = fmaxf(hi, v);
    }
    printf("nodes seen from above: radiance %.4f .. %.4f (the cover's 1)\n", (double)lo,
           (double)hi);
    assert_float_equal(lo, 1.0f, 1e-4f);
    assert_float_equal(hi, 1.0f, 1e-4f);
    drift__micro_tree_destroy(r.ctx, &tree);
    drift_points_destroy(points);
    test_rig_destroy(&r);
}

// Every interior node's sphere holds its children's spheres and its cone their cones.
static void check_invariants(const drift__micro_tree *t)
{
    assert_true(t->leaf_count >= 2 && (t->leaf_count & (t->leaf_count - 1)) == 0);
    assert_int_equal(t->node_count, 2 * t->leaf_count - 1);
    for (uint32_t i = 0; i + 1 < t->leaf_count; ++i) {
        float half = t->cone_cos[i] <= -1.0f ? DRIFT_PI : acosf(fminf(t->cone_cos[i], 1.0f));
        for (uint32_t c = 2 * i + 1; c <= 2 * i + 2; ++c) {
            float d = drift_vec3_length(drift_vec3_sub(t->center[c], t->center[i]));
            assert_true(d + t->radius[c] <= t->radius[i] * 1.0001f + 1e-6f);
            if (half < DRIFT_PI) {
                float child = acosf(fminf(t->cone_cos[c], 1.0f));
                float between =
                    acosf(drift_clampf(drift_vec3_dot(t->axis[c], t->axis[i]), -1.0f, 1.0f));
                assert_true(between + child <= half + 2e-3f);
            }
        }
    }
}

// Spec §4.5 test 3: the invariants hold after the build, and after a deformation (a twist
// and a squash of every vertex) and the refit; the leaves follow the points.
static void test_hierarchy_invariants_after_refit(void **state)
{
    (void)state;
    test_rig r = cornell_rig(2, 8);
    drift_points *points;
    drift__micro_tree tree;
    make_tree(&r, 8192, &points, &tree);
    check_invariants(&tree);
    for (uint32_t m = 0; m < r.scene->mesh_count; ++m) {
        drift_mesh *mesh = &r.scene->meshes[m];
        for (uint32_t v = 0; v < mesh->vertex_count; ++v) {
            float *p = mesh->positions + 3 * v;
            float a = 0.002f * p[1], c = cosf(a), s = sinf(a);
            float x = p[0] - 278.0f, z = p[2] - 278.0f;
            p[0] = 278.0f + c * x - s * z;
            p[2] = 278.0f + s * x + c * z;
            p[1] *= 0.7f;
        }
    }
    assert_int_equal(drift_points_update(points, r.scene), DRIFT_OK);
    drift__micro_tree_refit(&tree, points);
    check_invariants(&tree);
    for (uint32_t j = 0; j < tree.leaf_count; j += 97) {
        drift_vec3 d = drift_vec3_sub(tree.center[tree.leaf_count - 1 + j],
                                      points->position[tree.point_of[j]]);
        assert_true(drift_vec3_length(d) == 0.0f);
    }
    drift__micro_tree_destroy(r.ctx, &tree);
    drift_points_destroy(points);
    test_rig_destroy(&r);
}

// Spec §4.5 test 4: gathers at a few Cornell-box pixels splat only nodes within their pixel's
// solid angle and list only leaves bigger than theirs; the nodes visited grow sub-linearly as
// the points grow 16-fold (2^10 -> 2^14; `drift bench micro` goes to 2^20).
static void test_cut_is_correct_and_sublinear(void **state)
{
    (void)state;
    test_rig r = cornell_rig(2, 16);
    const drift_gbuffer *gb = drift_hybrid_gbuffer(r.frame);
    drift__micro_warp *warp = malloc(sizeof *warp);
    drift__micro_pixels *pixels = malloc(sizeof *pixels);
    drift__micro_warp_build_diffuse(warp, 32);
    drift__micro_pixels_make(pixels, warp, 16);
    double visits[3];
    uint32_t counts[3] = { 1u << 10, 1u << 12, 1u << 14 };
    for (int c = 0; c < 3; ++c) {
        drift_points *points;
        drift__micro_tree tree;
        make_tree(&r, counts[c], &points, &tree);
        drift__micro_gather_desc desc = { &tree, NULL, warp, pixels, 1.0f, NULL, 0 };
        drift__micro_gather_stats st = { 0 };
        bool ok = true;
        int gathers = 0;
        for (int32_t y = 1; y < 16; y += 3) {
            for (int32_t x = 1; x < 16; x += 3) {
                if (drift_image_pixel(&gb->material_id, x, y)[0] < 0.0f) {
                    continue;
                }
                drift_frame frame = drift_frame_from_normal(drift_image_get3(&gb->normal, x, y));
                drift__micro_gather(&desc, drift_image_get3(&gb->position, x, y), &frame,
                                    drift_image_get3(&gb->geometric_normal, x, y), NULL, &st, &ok);
                gathers++;
            }
        }
        assert_true(ok);
        visits[c] = (double)st.visited / gathers;
        printf("%u points: %.0f nodes visited, %.0f post-list leaves a gather\n", counts[c],
               visits[c], (double)st.post_leaves / gathers);
        drift__micro_tree_destroy(r.ctx, &tree);
        drift_points_destroy(points);
    }
    assert_true(visits[1] > visits[0] && visits[2] > visits[1]);
    assert_true(visits[2] < 8.0 * visits[0]); // 16x the points, well under 16x the visits
    free(warp);
    free(pixels);
    test_rig_destroy(&r);
}

// Spec §4.5 tests 5 to 7 on the Cornell box at 16 x 16 against the path tracer's first-bounce
// diffuse light (max depth 2): every-pixel gathers are close to it (NRMS, mean within 10%);
// the error shrinks from K = 8 to 16 to 24; 1/4-density upsampled stays within 2x of the
// every-pixel error; no pixel exceeds kd x the brightest leaf (one bounce: a mean of node
// radiances times rho).
static void test_against_path_tracer(void **state)
{
    (void)state;
    test_rig r = cornell_rig(2, 16);
    drift_pt *pt = NULL;
    drift_image ref = test_rig_render_pt(&r, DRIFT_PT_COMPONENT_DIFFUSE, 2, 2048, 99, &pt);
    int32_t sizes[3] = { 8, 16, 24 };
    double e[3], bias[3];
    for (int i = 0; i < 3; ++i) {
        drift_micro *m =
            render_micro(&r, &(drift_micro_params){ .point_count = 16384, .buffer_size = sizes[i] },
                         DRIFT_MICRO_LOBE_DIFFUSE);
        e[i] = test_nrmse(r.ctx, &ref, drift_micro_result(m));
        drift_micro_stats st = drift_micro_get_stats(m);
        printf("K = %d: nrmse %.4f mean ratio %.4f; %.0f visited, %.1f post-list leaves, %.1f "
               "empty pixels a gather; %.1f ms\n",
               sizes[i], e[i],
               drift_image_mean_luminance(drift_micro_result(m)) / drift_image_mean_luminance(&ref),
               (double)st.nodes_visited / (double)st.gathers,
               (double)st.post_leaves / (double)st.gathers,
               (double)st.empty_pixels / (double)st.gathers, st.total_ms);
        bias[i] =
            drift_image_mean_luminance(drift_micro_result(m)) / drift_image_mean_luminance(&ref);
        drift_micro_destroy(m);
    }
    // The error shrinks 8 -> 16 -> 24 (Fig. 6.17), and at K = 24 it is within 7% (measured
    // 5.2%, of which the 2048-spp reference's own noise is about 3%; docs/micro.md).
    assert_true(e[1] < 0.8 * e[0]);
    assert_true(e[2] < 0.85 * e[1]);
    assert_true(e[2] < 0.07);
    for (int i = 0; i < 3; ++i) {
        assert_true(bias[i] > 0.9 && bias[i] < 1.1);
    }

    drift_micro *full =
        render_micro(&r, &(drift_micro_params){ .point_count = 16384 }, DRIFT_MICRO_LOBE_DIFFUSE);
    drift_micro *quarter = render_micro(
        &r, &(drift_micro_params){ .point_count = 16384, .density = 2 }, DRIFT_MICRO_LOBE_DIFFUSE);
    double e_full = test_nrmse(r.ctx, &ref, drift_micro_result(full));
    double e_quarter = test_nrmse(r.ctx, &ref, drift_micro_result(quarter));
    drift_micro_stats sq = drift_micro_get_stats(quarter);
    printf("every pixel %.4f, 1/4 upsampled %.4f (%llu gathers, %llu fallbacks)\n", e_full,
           e_quarter, (unsigned long long)sq.gathers, (unsigned long long)sq.fallbacks);
    assert_true(e_quarter < 2.0 * e_full);
    assert_true(sq.gathers < 16 * 16);
    // The energy bound, with the brightest leaf of the hierarchy the full render lit.
    drift_points *points;
    drift__micro_tree tree;
    make_tree(&r, 16384, &points, &tree);
    drift__micro_light_leaves(r.ctx, r.scene, r.accel, points, &tree, 4, 0);
    float brightest = 0.0f;
    for (uint32_t j = 0; j < tree.leaf_count; ++j) {
        drift_vec3 f = tree.front[tree.leaf_count - 1 + j], b = tree.back[tree.leaf_count - 1 + j];
        brightest =
            fmaxf(brightest, fmaxf(fmaxf(f.x, fmaxf(f.y, f.z)), fmaxf(b.x, fmaxf(b.y, b.z))));
    }
    const drift_image *out = drift_micro_result(full);
    const drift_gbuffer *gb = drift_hybrid_gbuffer(r.frame);
    for (int32_t y = 0; y < 16; ++y) {
        for (int32_t x = 0; x < 16; ++x) {
            drift_vec3 v = drift_image_get3(out, x, y), kd = drift_image_get3(&gb->albedo, x, y);
            assert_true(v.x <= kd.x * brightest * 1.0001f && v.y <= kd.y * brightest * 1.0001f &&
                        v.z <= kd.z * brightest * 1.0001f);
        }
    }
    drift__micro_tree_destroy(r.ctx, &tree);
    drift_points_destroy(points);
    drift_micro_destroy(full);
    drift_micro_destroy(quarter);
    drift_pt_destroy(pt);
    test_rig_destroy(&r);
}

// Spec §4.5 test 5 for the Phong lobe: on the glossy Cornell box (floor Phong 200, bunny 60,
// dragon 120; the glossy floor laid 0.5 mm over the box's own) every-pixel glossy gathers
// with the default 2^16 points match the path tracer's first-bounce glossy light (SPECULAR
// at max depth 2) in the mean within 8% and per pixel within NRMS 0.8 (measured 0.64 and
// 0.943 here, 0.55-0.8 over four seeds, against a 2048-spp reference whose own noise is
// about 0.25; 0.95 and 0.891 without the covered floor's points left out, docs/micro.md).
static void test_glossy_against_path_tracer(void **state)
{
    (void)state;
    test_rig r = test_rig_load(2, "scenes/cornell-glossy/cornell_glossy.json", 16);
    drift_pt *pt = NULL;
    drift_image ref = test_rig_render_pt(&r, DRIFT_PT_COMPONENT_SPECULAR, 2, 2048, 99, &pt);
    drift_micro *m =
        render_micro(&r, &(drift_micro_params){ .point_count = 65536 }, DRIFT_MICRO_LOBE_GLOSSY);
    double e = test_nrmse(r.ctx, &ref, drift_micro_result(m));
    double ratio =
        drift_image_mean_luminance(drift_micro_result(m)) / drift_image_mean_luminance(&ref);
    printf("glossy: nrmse %.4f, mean ratio %.4f\n", e, ratio);
    assert_true(ratio > 0.92 && ratio < 1.08);
    assert_true(e < 0.8);
    drift_micro_destroy(m);
    drift_pt_destroy(pt);
    test_rig_destroy(&r);
}

// The gathers skip the warp's inverse for a node bigger than omega_bound of its direction's
// cosine bin: that bound must be at least the omega of the pixel the inverse gives, for every
// direction (else the cut would change). Dense random directions, diffuse, Phong 5, a cap.
static void test_pixel_bound_holds(void **state)
{
    (void)state;
    drift__micro_warp *warp = malloc(sizeof *warp);
    drift__micro_pixels *pixels = malloc(sizeof *pixels);
    uint64_t seed = 12345u;
    for (int lobe = 0; lobe < 3; ++lobe) {
        phong_slice slice = { lobe == 2 ? 200.0f : 5.0f,
                              lobe == 2 ? drift_vec3_normalize(drift_vec3_make(0.3f, -0.2f, 0.9f))
                                        : drift_vec3_make(0.0f, 0.0f, 1.0f) };
        if (lobe == 0) {
            drift__micro_warp_build_diffuse(warp, 32);
        } else if (lobe == 1) {
            drift__micro_warp_build(warp, 32, phong_lobe, &slice);
        } else {
            drift__micro_warp_build_cap(warp, 32, slice.mirror, drift__micro_phong_cap(200.0f),
                                        phong_lobe, &slice);
        }
        const int32_t k = 16;
        drift__micro_pixels_make(pixels, warp, k);
        bool capped = warp->scale < 1.0f;
        float cap_cos = sqrtf(fmaxf(1.0f - warp->scale * warp->scale, 0.0f));
        double ratio = 0.0;
        int tested = 0;
        for (int s = 0; s < 200000; ++s) {
            float v[3];
            for (int a = 0; a < 3; ++a) {
                seed = seed * 6364136223846793005ull + 1442695040888963407ull;
                v[a] = (float)(seed >> 40) / (float)(1u << 24) * 2.0f - 1.0f;
            }
            drift_vec3 w = drift_vec3_make(v[0], v[1], fabsf(v[2]));
            float len = drift_vec3_length(w);
            if (!(len > 1e-3f) || len > 1.0f) {
                continue;
            }
            w = drift_vec3_scale(w, 1.0f / len);
            float z = capped ? drift_vec3_dot(w, warp->cap.z) : w.z;
            if (!(w.z > 0.0f) || z < cap_cos) {
                continue;
            }
            drift_vec2 xy = drift__micro_warp_inverse(warp, w);
            int32_t px = (int32_t)drift_clampf(floorf(xy.x * (float)k), 0.0f, (float)(k - 1));
            int32_t py = (int32_t)drift_clampf(floorf(xy.y * (float)k), 0.0f, (float)(k - 1));
            int32_t bin = (int32_t)fminf(z * z * (float)DRIFT_MICRO_BOUND_BINS,
                                         (float)(DRIFT_MICRO_BOUND_BINS - 1));
            float omega = pixels->omega[py * k + px], bound = pixels->omega_bound[bin];
            assert_true(bound >= omega);
            ratio += (double)(bound / omega);
            tested++;
        }
        printf("lobe %d: %d directions, bound / pixel omega %.3f on average\n", lobe, tested,
               ratio / (double)tested);
        assert_true(tested > 1000);
    }
    free(warp);
    free(pixels);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_warp_round_trip_and_solid_angles),
        cmocka_unit_test(test_warp_is_distribution_correct),
        cmocka_unit_test(test_pixel_bound_holds),
        cmocka_unit_test(test_white_furnace),
        cmocka_unit_test(test_hierarchy_invariants_after_refit),
        cmocka_unit_test(test_covered_leaves_left_out),
        cmocka_unit_test(test_cut_is_correct_and_sublinear),
        cmocka_unit_test(test_against_path_tracer),
        cmocka_unit_test(test_glossy_against_path_tracer),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
