// Radiosity over the point hierarchy (thesis §6.4, "multiple bounces"): a Jacobi iteration in
// which every radiosity element gathers the last bounce's light from the tree with a small
// diffuse micro-buffer, and the next bounce is kd times what it saw. The thesis gathers at
// one interior level and pushes the result to the leaves; drift cuts the tree adaptively
// (nodes of at most element_leaves leaves whose normals agree), so that an element over a
// box's corner does not hand one side's light to the other.
//
// Iterating on the increments (B_0 = direct, dB_k = rho F dB_{k-1}) rather than on the totals
// (B_k = B_0 + rho F B_{k-1}) is the same sum; it keeps each term visible for the tests:
// every increment is a mean of non-negative radiances times kd, so the total never shrinks,
// and in a closed furnace of albedo rho each increment is rho times the last.
#include "micro/micro_internal.h"

#include <math.h>
#include <string.h>

typedef struct element {
    uint32_t node;          // the element's node
    uint32_t first, count;  // its leaves j = first .. first + count - 1
    drift_vec3 position;    // its leaf nearest to the node's centre (on the surface)
    drift_vec3 front, back; // gathered mean incident radiance over each side's hemisphere
} element;

typedef struct radiosity_job {
    const drift__micro_tree *tree;
    drift__micro_gather_desc gather;
    element *elements;
    drift__micro_gather_stats stats[DRIFT_MAX_THREADS]; // per thread
} radiosity_job;

static void gather_elements(size_t begin, size_t end, int thread, void *user)
{
    radiosity_job *job = user;
    const drift__micro_tree *tree = job->tree;
    drift__micro_gather_stats *st = &job->stats[thread];
    for (size_t e = begin; e < end; ++e) {
        element *el = &job->elements[e];
        drift_vec3 axis = tree->axis[el->node];
        drift_frame front = drift_frame_from_normal(axis);
        drift_frame back = drift_frame_from_normal(drift_vec3_neg(axis));
        el->front =
            drift__micro_gather(&job->gather, el->position, &front, front.z, NULL, st, NULL);
        el->back = drift__micro_gather(&job->gather, el->position, &back, back.z, NULL, st, NULL);
    }
}

static uint32_t floor_log2(uint32_t v)
{
    uint32_t l = 0;
    while (v >>= 1) {
        l++;
    }
    return l;
}

// The elements of the tree, depth first (their leaves in order).
static uint32_t cut_elements(const drift__micro_tree *tree, uint32_t max_leaves, element *out)
{
    const float cone_cos = 0.866f; // 30 degrees
    // Below an eighth of the largest, an element over a crease stays one (its leaves take the
    // side of its axis they face): splitting creases down to the leaves cost 5x the gathers.
    uint32_t min_leaves = max_leaves / 8 > 1 ? max_leaves / 8 : 1;
    uint32_t n = tree->leaf_count, depth_leaves = floor_log2(n), count = 0;
    uint32_t stack[64];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        uint32_t i = stack[--top];
        uint32_t depth = floor_log2(i + 1);
        uint32_t size = 1u << (depth_leaves - depth);
        if (size <= min_leaves || (size <= max_leaves && tree->cone_cos[i] >= cone_cos)) {
            uint32_t first = (i - ((1u << depth) - 1)) * size;
            // The leaf nearest to the node's centre stands for the element on the surface.
            uint32_t best = first;
            float best_d = INFINITY;
            for (uint32_t j = first; j < first + size; ++j) {
                drift_vec3 dv = drift_vec3_sub(tree->center[n - 1 + j], tree->center[i]);
                float d = drift_vec3_dot(dv, dv);
                if (d < best_d) {
                    best_d = d;
                    best = j;
                }
            }
            out[count++] = (element){
                .node = i, .first = first, .count = size, .position = tree->center[n - 1 + best]
            };
            continue;
        }
        // Right child first so that the left one is cut first.
        stack[top++] = 2 * i + 2;
        stack[top++] = 2 * i + 1;
    }
    return count;
}

static double mean_luminance(const drift__micro_tree *tree)
{
    uint32_t n = tree->leaf_count;
    double sum = 0.0;
    for (uint32_t j = 0; j < n; ++j) {
        sum +=
            (double)drift_luminance(drift_vec3_add(tree->front[n - 1 + j], tree->back[n - 1 + j]));
    }
    return sum / (double)n;
}

drift_result drift__micro_radiosity(drift_context *ctx, drift__micro_tree *tree,
                                    const drift_points *points,
                                    const drift__micro_radiosity_desc *desc, double *out_increments,
                                    uint64_t *out_rays)
{
    (void)points;
    uint32_t n = tree->leaf_count;
    if (out_increments) {
        out_increments[0] = mean_luminance(tree);
    }
    if (desc->iterations <= 0) {
        return DRIFT_OK;
    }
    element *elements = drift_alloc(ctx, (size_t)n * sizeof *elements);
    drift_vec3 *total = drift_alloc(ctx, 2 * (size_t)n * sizeof *total);
    drift__micro_warp *warp = drift_alloc(ctx, sizeof *warp);
    drift__micro_pixels *pixels = drift_alloc(ctx, sizeof *pixels);
    radiosity_job *job = drift_alloc(ctx, sizeof *job);
    drift_result r = DRIFT_OK;
    if (!elements || !total || !warp || !pixels || !job) {
        r = DRIFT_ERR_OUT_OF_MEMORY;
        goto done;
    }
    memset(job, 0, sizeof *job);
    drift__micro_warp_build_diffuse(warp, 32);
    drift__micro_pixels_make(pixels, warp, desc->buffer_size);
    uint32_t count =
        cut_elements(tree, desc->element_leaves > 0 ? desc->element_leaves : 1, elements);
    job->tree = tree;
    job->elements = elements;
    job->gather = (drift__micro_gather_desc){
        .tree = tree, .accel = desc->accel, .warp = warp, .pixels = pixels, .cut_scale = 1.0f
    };
    for (uint32_t j = 0; j < n; ++j) {
        total[2 * j] = tree->front[n - 1 + j];
        total[2 * j + 1] = tree->back[n - 1 + j];
    }
    for (int32_t it = 1; it <= desc->iterations; ++it) {
        // The last increment, pulled up the tree, is what the elements see.
        drift__micro_tree_pull(tree);
        drift_parallel_for(ctx, count, 4, gather_elements, job);
        for (uint32_t e = 0; e < count; ++e) {
            const element *el = &elements[e];
            drift_vec3 axis = tree->axis[el->node];
            for (uint32_t j = el->first; j < el->first + el->count; ++j) {
                uint32_t node = n - 1 + j;
                bool same = drift_vec3_dot(tree->axis[node], axis) >= 0.0f;
                drift_vec3 kd = tree->albedo[node];
                tree->front[node] = drift_vec3_mul(kd, same ? el->front : el->back);
                tree->back[node] = drift_vec3_mul(kd, same ? el->back : el->front);
                total[2 * j] = drift_vec3_add(total[2 * j], tree->front[node]);
                total[2 * j + 1] = drift_vec3_add(total[2 * j + 1], tree->back[node]);
            }
        }
        if (out_increments) {
            out_increments[it] = mean_luminance(tree);
        }
    }
    for (uint32_t j = 0; j < n; ++j) {
        tree->front[n - 1 + j] = total[2 * j];
        tree->back[n - 1 + j] = total[2 * j + 1];
    }
    if (out_rays) {
        for (int i = 0; i < DRIFT_MAX_THREADS; ++i) {
            *out_rays += job->stats[i].rays;
        }
    }
done:
    drift_free(ctx, elements);
    drift_free(ctx, total);
    drift_free(ctx, warp);
    drift_free(ctx, pixels);
    drift_free(ctx, job);
    return r;
}
