// The point hierarchy of micro-rendering (thesis §6.2.1): a binary space partition of the
// scene points (split the list at its median along its largest extent, recurse) whose final
// order makes an implicit complete binary tree, refit bottom-up every frame.
#include "micro/micro_internal.h"

#include <math.h>
#include <string.h>

// --- THE BSP ORDER ---

static float key_of(const drift_vec3 *pos, uint32_t i, int axis)
{
    return axis == 0 ? pos[i].x : (axis == 1 ? pos[i].y : pos[i].z);
}

// Hoare quickselect: after it, idx[mid] is where a sort would put it, smaller keys before.
static void select_median(uint32_t *idx, uint32_t lo, uint32_t hi, uint32_t mid,
                          const drift_vec3 *pos, int axis)
{
    while (hi - lo > 1) {
        float pivot = key_of(pos, idx[lo + (hi - lo) / 2], axis);
        uint32_t i = lo, j = hi - 1;
        while (i <= j) {
            while (key_of(pos, idx[i], axis) < pivot) {
                i++;
            }
            while (key_of(pos, idx[j], axis) > pivot) {
                j--;
            }
            if (i <= j) {
                uint32_t t = idx[i];
                idx[i] = idx[j];
                idx[j] = t;
                i++;
                if (j == 0) {
                    break;
                }
                j--;
            }
        }
        if (mid <= j) {
            hi = j + 1;
        } else if (mid >= i) {
            lo = i;
        } else {
            return;
        }
    }
}

static void partition(uint32_t *idx, uint32_t lo, uint32_t hi, const drift_vec3 *pos)
{
    if (hi - lo < 2) {
        return;
    }
    drift_bounds3 b = drift_bounds3_empty();
    for (uint32_t i = lo; i < hi; ++i) {
        b = drift_bounds3_extend(b, pos[idx[i]]);
    }
    drift_vec3 e = drift_vec3_sub(b.max, b.min);
    int axis = e.x >= e.y && e.x >= e.z ? 0 : (e.y >= e.z ? 1 : 2);
    uint32_t mid = lo + (hi - lo) / 2;
    select_median(idx, lo, hi, mid, pos, axis);
    partition(idx, lo, mid, pos);
    partition(idx, mid, hi, pos);
}

drift_result drift__micro_tree_create(drift_context *ctx, const drift_points *points,
                                      drift__micro_tree *tree)
{
    memset(tree, 0, sizeof *tree);
    uint32_t n = points->count;
    if (n == 0 || (n & (n - 1)) != 0) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    tree->leaf_count = n;
    tree->node_count = 2 * n - 1;
    size_t m = tree->node_count;
    tree->point_of = drift_alloc(ctx, n * sizeof *tree->point_of);
    tree->center = drift_alloc(ctx, m * sizeof *tree->center);
    tree->radius = drift_alloc(ctx, m * sizeof *tree->radius);
    tree->axis = drift_alloc(ctx, m * sizeof *tree->axis);
    tree->cone_cos = drift_alloc(ctx, m * sizeof *tree->cone_cos);
    tree->albedo = drift_alloc(ctx, m * sizeof *tree->albedo);
    tree->front = drift_alloc(ctx, m * sizeof *tree->front);
    tree->back = drift_alloc(ctx, m * sizeof *tree->back);
    tree->cube = drift_alloc(ctx, 6 * m * sizeof *tree->cube);
    tree->cube_weight = drift_alloc(ctx, 6 * m * sizeof *tree->cube_weight);
    tree->covered = drift_alloc(ctx, m * sizeof *tree->covered);
    if (!tree->point_of || !tree->center || !tree->radius || !tree->axis || !tree->cone_cos ||
        !tree->albedo || !tree->front || !tree->back || !tree->cube || !tree->cube_weight ||
        !tree->covered) {
        drift__micro_tree_destroy(ctx, tree);
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    for (uint32_t i = 0; i < n; ++i) {
        tree->point_of[i] = i;
    }
    partition(tree->point_of, 0, n, points->position);
    memset(tree->albedo, 0, m * sizeof *tree->albedo);
    memset(tree->front, 0, m * sizeof *tree->front);
    memset(tree->back, 0, m * sizeof *tree->back);
    memset(tree->cube, 0, 6 * m * sizeof *tree->cube);
    memset(tree->cube_weight, 0, 6 * m * sizeof *tree->cube_weight);
    memset(tree->covered, 0, m * sizeof *tree->covered);
    drift__micro_tree_refit(tree, points);
    return DRIFT_OK;
}

void drift__micro_tree_destroy(drift_context *ctx, drift__micro_tree *tree)
{
    drift_free(ctx, tree->point_of);
    drift_free(ctx, tree->center);
    drift_free(ctx, tree->radius);
    drift_free(ctx, tree->axis);
    drift_free(ctx, tree->cone_cos);
    drift_free(ctx, tree->albedo);
    drift_free(ctx, tree->front);
    drift_free(ctx, tree->back);
    drift_free(ctx, tree->cube);
    drift_free(ctx, tree->cube_weight);
    drift_free(ctx, tree->covered);
    memset(tree, 0, sizeof *tree);
}

// --- REFIT ---

// The smallest sphere holding two spheres, padded so rounding never lets a child stick out.
static void merge_spheres(drift_vec3 c1, float r1, drift_vec3 c2, float r2, drift_vec3 *c, float *r)
{
    drift_vec3 d = drift_vec3_sub(c2, c1);
    float dist = drift_vec3_length(d);
    if (dist + r2 <= r1) {
        *c = c1;
        *r = r1;
        return;
    }
    if (dist + r1 <= r2) {
        *c = c2;
        *r = r2;
        return;
    }
    float big = 0.5f * (dist + r1 + r2);
    *c = drift_vec3_fma(c1, d, (big - r1) / dist);
    *r = big * (1.0f + 1e-5f) + 1e-7f;
}

// The smallest cone of directions holding two cones (axis, half angle).
static void merge_cones(drift_vec3 a1, float cos1, drift_vec3 a2, float cos2, drift_vec3 *axis,
                        float *cone_cos)
{
    if (cos1 <= -1.0f || cos2 <= -1.0f) {
        *axis = a1;
        *cone_cos = -1.0f;
        return;
    }
    float t1 = acosf(drift_clampf(cos1, -1.0f, 1.0f));
    float t2 = acosf(drift_clampf(cos2, -1.0f, 1.0f));
    float phi = acosf(drift_clampf(drift_vec3_dot(a1, a2), -1.0f, 1.0f));
    if (phi + t2 <= t1) {
        *axis = a1;
        *cone_cos = cos1;
        return;
    }
    if (phi + t1 <= t2) {
        *axis = a2;
        *cone_cos = cos2;
        return;
    }
    float t = 0.5f * (phi + t1 + t2) + 1e-4f;
    drift_vec3 perp = drift_vec3_sub(a2, drift_vec3_scale(a1, drift_vec3_dot(a1, a2)));
    float plen = drift_vec3_length(perp);
    if (t >= DRIFT_PI || plen < 1e-6f) {
        *axis = a1;
        *cone_cos = -1.0f;
        return;
    }
    float turn = t - t1;
    *axis = drift_vec3_normalize(drift_vec3_add(drift_vec3_scale(a1, cosf(turn)),
                                                drift_vec3_scale(perp, sinf(turn) / plen)));
    *cone_cos = cosf(t);
}

void drift__micro_tree_refit(drift__micro_tree *tree, const drift_points *points)
{
    uint32_t n = tree->leaf_count;
    tree->leaf_radius = sqrtf((float)(points->area / ((double)n * (double)DRIFT_PI)));
    for (uint32_t j = 0; j < n; ++j) {
        uint32_t node = n - 1 + j, p = tree->point_of[j];
        tree->center[node] = points->position[p];
        tree->radius[node] = tree->leaf_radius;
        tree->axis[node] = points->normal[p];
        tree->cone_cos[node] = 1.0f;
    }
    for (uint32_t i = n - 1; i-- > 0;) {
        uint32_t l = 2 * i + 1, r = 2 * i + 2;
        merge_spheres(tree->center[l], tree->radius[l], tree->center[r], tree->radius[r],
                      &tree->center[i], &tree->radius[i]);
        merge_cones(tree->axis[l], tree->cone_cos[l], tree->axis[r], tree->cone_cos[r],
                    &tree->axis[i], &tree->cone_cos[i]);
    }
}

// The weights of direction m on the six axes +x, -x, +y, -y, +z, -z: its squared
// components on the axes it points along (they sum to 1 for a unit m).
static void cube_weights(drift_vec3 m, float w[6])
{
    float c[3] = { m.x, m.y, m.z };
    for (int a = 0; a < 3; ++a) {
        w[2 * a] = c[a] > 0.0f ? c[a] * c[a] : 0.0f;
        w[2 * a + 1] = c[a] < 0.0f ? c[a] * c[a] : 0.0f;
    }
}

// --- COVERED SIDES ---

typedef struct cover_job {
    drift__micro_tree *tree;
    const drift_accel *accel;
} cover_job;

static void cover_range(size_t begin, size_t end, int thread, void *user)
{
    (void)thread;
    cover_job *job = user;
    drift__micro_tree *tree = job->tree;
    uint32_t n = tree->leaf_count;
    float reach = 0.5f * tree->leaf_radius;
    for (size_t j = begin; j < end; ++j) {
        uint32_t node = n - 1 + (uint32_t)j;
        uint8_t bits = 0;
        for (int side = 0; side < 2; ++side) {
            drift_vec3 dir = side ? drift_vec3_neg(tree->axis[node]) : tree->axis[node];
            drift_ray ray = { drift_offset_origin(tree->center[node], dir, dir), 0.0f, dir, reach,
                              0 };
            if (drift_accel_occluded(job->accel, &ray)) {
                bits |= (uint8_t)(1u << side);
            }
        }
        tree->covered[node] = bits == 3u ? 7u : bits;
    }
}

void drift__micro_tree_cover(drift_context *ctx, drift__micro_tree *tree, const drift_accel *accel)
{
    cover_job job = { tree, accel };
    drift_parallel_for(ctx, tree->leaf_count, 1024, cover_range, &job);
    for (uint32_t i = tree->leaf_count - 1; i-- > 0;) {
        tree->covered[i] = (uint8_t)(tree->covered[2 * i + 1] & tree->covered[2 * i + 2] & 4u);
    }
}

void drift__micro_tree_pull(drift__micro_tree *tree)
{
    uint32_t n = tree->leaf_count;
    for (uint32_t j = 0; j < n; ++j) {
        uint32_t node = n - 1 + j;
        float wf[6], wb[6];
        cube_weights(tree->axis[node], wf);
        cube_weights(drift_vec3_neg(tree->axis[node]), wb);
        // A covered side is seen by nothing: it takes no part in what its ancestors show.
        for (int k = 0; k < 6; ++k) {
            wf[k] = (tree->covered[node] & 1u) ? 0.0f : wf[k];
            wb[k] = (tree->covered[node] & 2u) ? 0.0f : wb[k];
        }
        for (int k = 0; k < 6; ++k) {
            tree->cube[6 * node + k] = drift_vec3_add(drift_vec3_scale(tree->front[node], wf[k]),
                                                      drift_vec3_scale(tree->back[node], wb[k]));
            tree->cube_weight[6 * node + k] = wf[k] + wb[k];
        }
    }
    for (uint32_t i = n - 1; i-- > 0;) {
        drift_vec3 front = drift_vec3_splat(0.0f), back = front, albedo = front;
        for (uint32_t c = 2 * i + 1; c <= 2 * i + 2; ++c) {
            bool same = drift_vec3_dot(tree->axis[c], tree->axis[i]) >= 0.0f;
            front = drift_vec3_add(front, same ? tree->front[c] : tree->back[c]);
            back = drift_vec3_add(back, same ? tree->back[c] : tree->front[c]);
            albedo = drift_vec3_add(albedo, tree->albedo[c]);
        }
        tree->front[i] = drift_vec3_scale(front, 0.5f);
        tree->back[i] = drift_vec3_scale(back, 0.5f);
        tree->albedo[i] = drift_vec3_scale(albedo, 0.5f);
        for (int k = 0; k < 6; ++k) {
            tree->cube[6 * i + k] =
                drift_vec3_add(tree->cube[6 * (2 * i + 1) + k], tree->cube[6 * (2 * i + 2) + k]);
            tree->cube_weight[6 * i + k] =
                tree->cube_weight[6 * (2 * i + 1) + k] + tree->cube_weight[6 * (2 * i + 2) + k];
        }
    }
}

drift_vec3 drift__micro_tree_radiance(const drift__micro_tree *tree, uint32_t i, drift_vec3 toward)
{
    float len = drift_vec3_length(toward);
    float c[6];
    cube_weights(len > 0.0f ? drift_vec3_scale(toward, 1.0f / len) : tree->axis[i], c);
    drift_vec3 sum = drift_vec3_splat(0.0f), all = sum;
    float weight = 0.0f, all_weight = 0.0f;
    for (int k = 0; k < 6; ++k) {
        sum = drift_vec3_fma(sum, tree->cube[6 * i + k], c[k]);
        weight += c[k] * tree->cube_weight[6 * i + k];
        all = drift_vec3_add(all, tree->cube[6 * i + k]);
        all_weight += tree->cube_weight[6 * i + k];
    }
    // Seen exactly edge-on no leaf faces the viewer: the node's mean over all of them.
    if (weight > 1e-6f * all_weight) {
        return drift_vec3_scale(sum, 1.0f / weight);
    }
    return all_weight > 0.0f ? drift_vec3_scale(all, 1.0f / all_weight) : all;
}

bool drift__micro_tree_seen(const drift__micro_tree *tree, uint32_t i, drift_vec3 toward)
{
    float len = drift_vec3_length(toward);
    if (!(len > 0.0f)) {
        return true;
    }
    float c[6];
    cube_weights(drift_vec3_scale(toward, 1.0f / len), c);
    const float *w = tree->cube_weight + 6 * (size_t)i;
    float all = w[0] + w[1] + w[2] + w[3] + w[4] + w[5], seen = 0.0f;
    for (int k = 0; k < 6; ++k) {
        seen += c[k] * w[k];
    }
    return all <= 0.0f || seen > 1e-6f * all;
}

// --- NEAREST LEAF ---

uint32_t drift__micro_tree_nearest_leaf(const drift__micro_tree *tree, drift_vec3 x)
{
    return drift__micro_tree_nearest_leaf_seen(tree, x, NULL, drift_vec3_splat(0.0f),
                                               drift_vec3_splat(0.0f));
}

uint32_t drift__micro_tree_nearest_leaf_seen(const drift__micro_tree *tree, drift_vec3 x,
                                             const drift_vec3 *p, drift_vec3 n, drift_vec3 ng)
{
    uint32_t leaves = tree->leaf_count, best = leaves - 1;
    float best_d2 = INFINITY;
    uint32_t stack[64];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        uint32_t i = stack[--top];
        float d = drift_vec3_length(drift_vec3_sub(tree->center[i], x)) - tree->radius[i];
        if (d > 0.0f && d * d >= best_d2) {
            continue;
        }
        if (i >= leaves - 1) {
            drift_vec3 v = drift_vec3_sub(tree->center[i], x);
            float d2 = drift_vec3_dot(v, v);
            // A leaf behind the gather point's tangent plane, or on a surface turned away
            // from the hit's, is not what the ray sees: at a contact (a box on the floor)
            // the nearest leaf may lie under the box, in its shadow.
            float facing =
                p ? drift_vec3_dot(tree->axis[i], drift_vec3_sub(*p, tree->center[i])) : 0.0f;
            if (p && (drift_vec3_dot(drift_vec3_sub(tree->center[i], *p), n) <= 0.0f ||
                      fabsf(drift_vec3_dot(tree->axis[i], ng)) < 0.5f ||
                      (tree->covered[i] & (facing >= 0.0f ? 1u : 2u)))) {
                continue;
            }
            if (d2 < best_d2) {
                best_d2 = d2;
                best = i;
            }
            continue;
        }
        // The nearer child last, so that it is searched first.
        uint32_t l = 2 * i + 1, r = 2 * i + 2;
        drift_vec3 vl = drift_vec3_sub(tree->center[l], x), vr = drift_vec3_sub(tree->center[r], x);
        bool left_nearer = drift_vec3_dot(vl, vl) < drift_vec3_dot(vr, vr);
        stack[top++] = left_nearer ? r : l;
        stack[top++] = left_nearer ? l : r;
    }
    return best;
}
