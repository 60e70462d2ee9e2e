// One gather into a micro-buffer (thesis §6.2.2): a depth-first cut of the point hierarchy
// by solid angle, each node of the cut splatted into the pixels its disc covers (nearest
// first), the leaves bigger than their pixel kept on a post-traversal list; then one ray a
// pixel against the scene's triangles (Embree), which decides what each pixel sees, so that
// the buffer is watertight and free of the splats' silhouette errors; then the mean.
#include "micro/micro_internal.h"

#include <math.h>

#define NO_NODE (-1)
#define BLOCKED (-2) // a ray hit geometry without points (a light's shape): radiance 0

// The direct light the glossy lobe of the surface a ray hit reflects back along it (toward
// the gather point), from one power-proportional light sample with a shadow ray; 0 for a
// surface without a glossy lobe or a mirror (a delta lobe: the light's image, not gathered).
static drift_vec3 glossy_direct(const drift__micro_gather_desc *desc, const drift_ray *ray,
                                const drift_hit *hit, drift_sampler *s, uint64_t *rays)
{
    const drift_scene *scene = desc->scene;
    drift_surface surf = drift_scene_surface(scene, ray, hit);
    drift_vec3 zero = drift_vec3_splat(0.0f);
    if (surf.material == DRIFT_INVALID_INDEX) {
        return zero;
    }
    drift_bsdf bsdf = drift_bsdf_make(scene, &surf);
    if (drift_vec3_is_zero(bsdf.specular) || drift_bsdf_is_delta(&bsdf)) {
        return zero;
    }
    float u_pick = drift_sampler_next1(s);
    drift_vec2 u = drift_sampler_next2(s);
    float pmf = 0.0f;
    uint32_t light = drift_scene_pick_light(scene, u_pick, &pmf);
    if (light == DRIFT_INVALID_INDEX || !(pmf > 0.0f)) {
        return zero;
    }
    drift_light_sample ls = drift_light_sample_li(scene, light, surf.position, u);
    float cos_i = drift_vec3_dot(ls.wi, surf.ns);
    if (!(ls.pdf > 0.0f) || cos_i <= 0.0f || drift_vec3_is_zero(ls.radiance)) {
        return zero;
    }
    drift_vec3 diffuse, glossy;
    drift_bsdf_eval_lobes(&bsdf, drift_vec3_neg(ray->dir), ls.wi, &diffuse, &glossy);
    if (drift_vec3_is_zero(glossy)) {
        return zero;
    }
    drift_ray shadow = { .origin = drift_offset_origin(surf.position, surf.ng, ls.wi),
                         .dir = ls.wi,
                         .tmin = 0.0f,
                         .tmax = isfinite(ls.distance) ? ls.distance * (1.0f - 1e-4f) : INFINITY };
    (*rays)++;
    if (drift_accel_occluded(desc->accel, &shadow)) {
        return zero;
    }
    return drift_vec3_scale(drift_vec3_mul(glossy, ls.radiance), cos_i / (pmf * ls.pdf));
}

drift_vec3 drift__micro_gather(const drift__micro_gather_desc *desc, drift_vec3 p,
                               const drift_frame *frame, drift_vec3 ng, int32_t *out_node,
                               drift__micro_gather_stats *stats, bool *splat_ok)
{
    const drift__micro_tree *tree = desc->tree;
    const drift__micro_pixels *pixels = desc->pixels;
    const int32_t k = pixels->k, k2 = k * k;
    const uint32_t n = tree->leaf_count;
    float depth[DRIFT_MICRO_MAX_K * DRIFT_MICRO_MAX_K];
    int32_t node[DRIFT_MICRO_MAX_K * DRIFT_MICRO_MAX_K];
    for (int32_t i = 0; i < k2; ++i) {
        depth[i] = INFINITY;
        node[i] = NO_NODE;
    }
    uint32_t post = 0;
    stats->gathers++;
    // A warp over a cap (a sharp glossy lobe): nodes wholly outside it are culled, and only
    // those whose centre lies in it have a pixel.
    const drift__micro_warp *warp = desc->warp;
    bool capped = warp->scale < 1.0f;
    float cap_cos = sqrtf(fmaxf(1.0f - warp->scale * warp->scale, 0.0f));
    uint32_t stack[96];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        uint32_t i = stack[--top];
        stats->visited++;
        drift_vec3 d = drift_vec3_sub(tree->center[i], p);
        drift_vec3 local = drift_frame_to_local(frame, d);
        float r = tree->radius[i];
        if (local.z < -r) {
            continue; // entirely below the tangent plane
        }
        if (tree->covered[i] & 4u) {
            continue; // every side of its leaves lies under another surface
        }
        bool leaf = i >= n - 1;
        float dist = drift_vec3_length(d);
        float cos_c = capped && dist > 0.0f ? drift_vec3_dot(local, warp->cap.z) / dist : 1.0f;
        if (capped && dist > r) {
            float sin_r = r / dist, cos_r = sqrtf(fmaxf(1.0f - sin_r * sin_r, 0.0f));
            float sin_c = sqrtf(fmaxf(1.0f - cos_c * cos_c, 0.0f));
            if (cos_c < cos_r && cos_c * cos_r + sin_c * sin_r < cap_cos) {
                continue; // its nearest direction to the axis is outside the cap
            }
        }
        // A flat node whose plane holds p is seen edge-on from it (the floor around a gather
        // point on the floor): it covers no pixel, and refining it would reach every leaf.
        if (tree->cone_cos[i] >= 0.99995f &&
            fabsf(drift_vec3_dot(tree->axis[i], d)) <= 1e-3f * (dist + r)) {
            continue;
        }
        float omega_node = dist > r ? DRIFT_PI * r * r / (dist * dist) : INFINITY;
        if (!leaf && omega_node > desc->cut_scale * pixels->omega_max) {
            // Bigger than the biggest pixel: refined whichever pixel it falls in, so its
            // pixel (the warp's inverse, most of a visit's cost) is not looked up.
            stack[top++] = 2 * i + 2;
            stack[top++] = 2 * i + 1;
            continue;
        }
        int32_t pix = -1;
        if (local.z > 0.0f && dist > r && cos_c >= cap_cos) {
            // Bigger than any pixel of its direction's cosine bin: refined (or left to the
            // rays) whichever its pixel is, so the warp's inverse is skipped.
            float z = capped ? cos_c : local.z / dist;
            int32_t bin = (int32_t)fminf(z * z * (float)DRIFT_MICRO_BOUND_BINS,
                                         (float)(DRIFT_MICRO_BOUND_BINS - 1));
            if (omega_node > desc->cut_scale * pixels->omega_bound[bin]) {
                if (!leaf) {
                    stack[top++] = 2 * i + 2;
                    stack[top++] = 2 * i + 1;
                } else {
                    post++;
                }
                continue;
            }
            drift_vec2 xy =
                drift__micro_warp_inverse(desc->warp, drift_vec3_scale(local, 1.0f / dist));
            int32_t px = (int32_t)drift_clampf(floorf(xy.x * (float)k), 0.0f, (float)(k - 1));
            int32_t py = (int32_t)drift_clampf(floorf(xy.y * (float)k), 0.0f, (float)(k - 1));
            pix = py * k + px;
        }
        if (pix < 0 || omega_node > desc->cut_scale * pixels->omega[pix]) {
            // Bigger than its pixel (or straddling the plane): refine, or leave to the rays.
            if (!leaf) {
                stack[top++] = 2 * i + 2;
                stack[top++] = 2 * i + 1;
            } else if (local.z > -r) {
                post++;
                if (splat_ok && pix >= 0 && !(omega_node > desc->cut_scale * pixels->omega[pix])) {
                    *splat_ok = false;
                }
            }
            continue;
        }
        if (splat_ok && omega_node > desc->cut_scale * pixels->omega[pix]) {
            *splat_ok = false;
        }
        if (!drift__micro_tree_seen(tree, i, drift_vec3_neg(d))) {
            continue; // what it turns toward p lies under another surface
        }
        // The splat: every pixel whose centre direction the node's disc covers, its own and
        // its neighbours' (coverage point-sampled at the pixel centres, as rays would: a
        // node merely falling into a pixel at a silhouette would fill it whole and brighten
        // the mean). Pixels no node covers are left to the rays. Depth-tested at the node's
        // centre: nodes of the cut differ in size, and a big far one's sphere front would
        // win over a small near one's.
        // The disc of the node's own area (its leaves' discs), foreshortened when the node
        // is flat: the bounding sphere would dilate every surface into the background.
        uint32_t leaves = n >> (31 - __builtin_clz(i + 1));
        float area_r = sqrtf((float)leaves) * tree->leaf_radius;
        if (tree->cone_cos[i] > 0.9f) {
            area_r *= sqrtf(fmaxf(fabsf(drift_vec3_dot(tree->axis[i], d)) / dist, 0.05f));
        }
        float sin_a = fminf(r, area_r) / dist, pixel_a = sqrtf(pixels->omega[pix]);
        drift_vec3 w = drift_vec3_scale(local, 1.0f / dist);
        float cos_a = sqrtf(fmaxf(1.0f - sin_a * sin_a, 0.0f));
        int32_t span = (int32_t)ceilf(sin_a / pixel_a) + 1;
        span = span > k / 2 ? k / 2 : span;
        int32_t px = pix % k, py = pix / k;
        int32_t y0 = py > span ? py - span : 0, y1 = py + span < k ? py + span : k - 1;
        int32_t x0 = px > span ? px - span : 0, x1 = px + span < k ? px + span : k - 1;
        for (int32_t qy = y0; qy <= y1; ++qy) {
            for (int32_t qx = x0; qx <= x1; ++qx) {
                int32_t q = qy * k + qx;
                if (dist < depth[q] && drift_vec3_dot(pixels->dir[q], w) >= cos_a) {
                    depth[q] = dist;
                    node[q] = (int32_t)i;
                    stats->splats++;
                }
            }
        }
    }
    stats->post_leaves += post;
    drift_vec3 on_the_fly = drift_vec3_splat(0.0f);
    if (desc->accel) {
        drift_sampler sampler = drift_sampler_make(desc->seed, 0, 0);
        // Every pixel's ray is cast, not only those a near leaf may cover or no splat did:
        // the splats alone were biased (docs/micro.md: on the Cornell box's ceiling, which
        // gathers without near leaves, 10% dark at K = 24), because a splat's disc is only
        // its node's area in a circle around its centre and at silhouettes (the boxes'
        // edges, the open front, the light's quad seen edge-on) it covers pixel centres
        // that see past it. So the ray decides what the pixel's centre sees, and a splat
        // stays only when the surface hit lies within its node.
        stats->cast++;
        for (int32_t pix = 0; pix < k2; ++pix) {
            drift_vec3 dir = drift_frame_to_world(frame, pixels->dir[pix]);
            drift_ray ray = { drift_offset_origin(p, ng, dir), 0.0f, dir, INFINITY, 0 };
            drift_hit hit;
            stats->rays++;
            if (!drift_accel_intersect(desc->accel, &ray, &hit)) {
                node[pix] = NO_NODE; // the open scene: nothing there
                continue;
            }
            drift_vec3 x = drift_vec3_fma(ray.origin, dir, hit.t);
            if (desc->scene && hit.mesh != DRIFT_INVALID_INDEX) {
                on_the_fly = drift_vec3_add(
                    on_the_fly, glossy_direct(desc, &ray, &hit, &sampler, &stats->rays));
            }
            if (node[pix] >= 0 && drift_vec3_length(drift_vec3_sub(tree->center[node[pix]], x)) <=
                                      tree->radius[node[pix]]) {
                continue;
            }
            depth[pix] = hit.t;
            if (hit.mesh == DRIFT_INVALID_INDEX) {
                node[pix] = BLOCKED;
                continue;
            }
            // The nearest leaf to the hit, then its largest ancestor that still fits the
            // pixel: the radiance at the pixel's own scale, not one leaf's.
            uint32_t i = drift__micro_tree_nearest_leaf_seen(tree, x, &p, frame->z,
                                                             drift_vec3_normalize(hit.ng));
            float limit = desc->cut_scale * pixels->omega[pix] * hit.t * hit.t * DRIFT_INV_PI;
            while (i > 0) {
                uint32_t up = (i - 1) / 2;
                float r = tree->radius[up];
                if (r * r > limit || drift_vec3_length(drift_vec3_sub(tree->center[up], x)) > r) {
                    break;
                }
                i = up;
            }
            node[pix] = (int32_t)i;
        }
    }
    drift_vec3 sum = drift_vec3_splat(0.0f);
    for (int32_t pix = 0; pix < k2; ++pix) {
        int32_t i = node[pix];
        if (out_node) {
            out_node[pix] = i;
        }
        if (i == NO_NODE) {
            stats->empty++;
            continue;
        }
        if (i == BLOCKED) {
            continue;
        }
        sum = drift_vec3_add(
            sum, drift__micro_tree_radiance(tree, (uint32_t)i, drift_vec3_sub(p, tree->center[i])));
    }
    return drift_vec3_scale(drift_vec3_add(sum, on_the_fly), 1.0f / (float)k2);
}
