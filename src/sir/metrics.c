// SIR's error metrics (paper §5), per pixel in [0,1], from the hybrid frame's last render:
//   reflection1..5  on reflective material (a specular lobe): 1; |p - c| / max |q - c| over the
//                   scene bounds (c the environment probe); <-i, r>; <-i, n>; the ambient
//                   occlusion k_a (fraction of ao_samples cosine rays that hit within ao_radius)
//   dof             Sobel edges of the depth plane, each dilated by a square of radius
//                   C_max(p) = max(C(z_p), C_inf) pixels; zero for a pinhole or no DOF
//   shadow          1 where drift_shadow_map_penumbra says a light's penumbra may fall, or
//                   where an area light straddles the receiver's tangent plane; dilated (2 px
//                   at 600 rows a 512-texel face, growing with the pixels a texel spans)
#include "sir/metrics_internal.h"

#include <stdlib.h>
#include <string.h>

// The corners of a light, or count 0 when it has too many or none (spheres, disks).
static void light_corners(const drift_scene *scene, const drift_raster_light *light,
                          light_shape *out)
{
    out->count = 0;
    out->planar = false;
    const drift_light *l = &scene->lights[light->first_light];
    if (light->mesh == DRIFT_INVALID_INDEX && l->type == DRIFT_LIGHT_QUAD) {
        out->corner[0] = l->position;
        out->corner[1] = drift_vec3_add(l->position, l->edge_u);
        out->corner[2] = drift_vec3_add(drift_vec3_add(l->position, l->edge_u), l->edge_v);
        out->corner[3] = drift_vec3_add(l->position, l->edge_v);
        out->count = 4;
        out->planar = light->one_sided && !light->two_sided;
        return;
    }
    if (l->type != DRIFT_LIGHT_TRIANGLE || 3u * light->light_count > MAX_CORNERS) {
        return;
    }
    // Triangle lights (one, or a small emissive mesh): every vertex; planar when each
    // triangle faces the mean normal (then the back of the plane gets no light, unless the
    // mesh emits from both faces).
    bool planar = light->one_sided && !light->two_sided;
    for (uint32_t t = 0; t < light->light_count; ++t) {
        drift_vec3 *c = out->corner + 3u * t;
        drift_light_triangle_vertices(scene, &scene->lights[light->first_light + t], &c[0], &c[1],
                                      &c[2]);
        drift_vec3 cross = drift_vec3_cross(drift_vec3_sub(c[1], c[0]), drift_vec3_sub(c[2], c[0]));
        float area2 = drift_vec3_length(cross);
        planar =
            planar && area2 > 0.0f && drift_vec3_dot(cross, light->direction) > 0.9999f * area2;
        for (int k = 0; k < 3 && planar; ++k) {
            planar = fabsf(drift_vec3_dot(drift_vec3_sub(c[k], light->centre), light->direction)) <=
                     1e-4f * light->radius;
        }
    }
    out->count = 3u * light->light_count;
    out->planar = planar;
}

// The light's size as the cone from p sees it, for the penumbra estimate: a blocker d from the
// light's centre c (on the way to p, d_r from c) hides a corner q = c + delta when its offset
// from the direction to p is |delta_perp| d_r / (d_r - delta_par) (d_r - d) / (d_r d), and the
// largest over the light is at a corner (the ratio is quasi-convex). 1% wider for the map's
// normal offset of the receiver. The bounding radius when a corner is beyond p.
static float light_size_from(const drift_raster_light *light, const light_shape *shape,
                             drift_vec3 p)
{
    drift_vec3 to_p = drift_vec3_sub(p, light->centre);
    float d_r = drift_vec3_length(to_p);
    if (shape->count == 0 || !(d_r > 0.0f)) {
        return light->radius;
    }
    drift_vec3 dir = drift_vec3_scale(to_p, 1.0f / d_r);
    float size = 0.0f;
    for (uint32_t k = 0; k < shape->count; ++k) {
        drift_vec3 delta = drift_vec3_sub(shape->corner[k], light->centre);
        float along = drift_vec3_dot(delta, dir);
        if (!(d_r - along > 0.01f * d_r)) {
            return light->radius;
        }
        float across = drift_vec3_length(drift_vec3_fma(delta, dir, -along));
        size = fmaxf(size, across * d_r / (d_r - along));
    }
    return fminf(1.01f * size, light->radius);
}

// Where the penumbra estimate finds p outside every penumbra of light l, one shadow ray to
// the light's centre says whether all of it is seen (1) or none (0); the raster's shadow S_l
// should say the same. Returns U_l (v - S_l): what the raster's direct light lacks (or has too
// much of) there. The shadow map's mistakes at contacts and seams (its bias and texels of the
// neighbouring surface) are exactly such pixels, which the penumbra estimate does not flag.
static drift_vec3 shadow_map_mistake(drift_frame_state *f, uint32_t l, int32_t x, int32_t y,
                                     const drift_surface *s, uint64_t *rays)
{
    const drift_frame_light_buffers *b = &f->light_buffers[l];
    drift_vec3 unshadowed = drift_image_get3(&b->unshadowed, x, y);
    if (drift_vec3_is_zero(unshadowed)) {
        return drift_vec3_splat(0.0f);
    }
    const drift_raster_light *light = &f->lights[l];
    drift_vec3 to_light = drift_vec3_sub(light->centre, s->position);
    float distance = drift_vec3_length(to_light);
    if (!(distance > 0.0f)) {
        return drift_vec3_splat(0.0f);
    }
    drift_vec3 dir = drift_vec3_scale(to_light, 1.0f / distance);
    drift_ray ray = { .origin = drift_offset_origin(s->position, s->ng, dir),
                      .dir = dir,
                      .tmin = 0.0f,
                      .tmax = distance * (1.0f - 1e-4f) };
    drift_hit hit;
    ++*rays;
    bool seen =
        !drift_accel_intersect(f->accel, &ray, &hit) || drift_raster_light_owns(light, hit.light);
    float raster = drift_image_pixel(&b->shadow, x, y)[0];
    return drift_vec3_scale(unshadowed, (seen ? 1.0f : 0.0f) - raster);
}

// In a penumbra of light l, what the raster's shadow S_l gets wrong, estimated with `samples`
// shadow rays to stratified points of the light: U_l (v - S_l), v the rays' visible share.
// Noisy alone (a quarter of U_l at 4 rays); smooth_shadow_mistakes averages it over a square
// of penumbra pixels, where the raster's error varies slowly and the noise cancels.
static drift_vec3 penumbra_mistake(drift_frame_state *f, uint32_t l, int32_t x, int32_t y,
                                   const drift_surface *s, uint32_t samples, bool *contradicted,
                                   uint64_t *rays)
{
    const drift_frame_light_buffers *b = &f->light_buffers[l];
    drift_vec3 unshadowed = drift_image_get3(&b->unshadowed, x, y);
    if (drift_vec3_is_zero(unshadowed)) {
        return drift_vec3_splat(0.0f);
    }
    const drift_raster_light *light = &f->lights[l];
    drift_sampler sampler = drift_pass_sampler(f, DRIFT_STREAM_SIR_LOBE + 1u + l, x, y);
    uint32_t side = 1;
    while (side * side < samples) {
        ++side;
    }
    uint32_t seen = 0, cast = 0;
    for (uint32_t k = 0; k < side * side; ++k) {
        drift_vec2 u = drift_sampler_next2(&sampler);
        u = drift_vec2_make(((float)(k % side) + u.x) / (float)side,
                            ((float)(k / side) + u.y) / (float)side);
        drift_light_sample ls = drift_raster_light_sample(f->scene, light, s->position,
                                                          drift_sampler_next1(&sampler), u);
        if (!(ls.pdf > 0.0f)) {
            continue;
        }
        drift_ray ray = { .origin = drift_offset_origin(s->position, s->ng, ls.wi),
                          .dir = ls.wi,
                          .tmin = 0.0f,
                          .tmax = isfinite(ls.distance) ? ls.distance * (1.0f - 1e-4f) : INFINITY };
        ++*rays;
        ++cast;
        seen += drift_accel_occluded(f->accel, &ray) ? 0u : 1u;
    }
    float raster = drift_image_pixel(&b->shadow, x, y)[0];
    float visible = cast ? (float)seen / (float)cast : raster;
    // A raster umbra whose rays see the light, or a fully lit raster with a ray blocked, is
    // wrong however few rays were cast: no noise lets an umbra see the light.
    *contradicted = *contradicted || (raster <= CERTAIN_SHADOW && seen > 0) ||
                    (raster >= 1.0f - CERTAIN_SHADOW && seen < cast);
    return drift_vec3_scale(unshadowed, visible - raster);
}

// Second pass over the (dilated) penumbra estimate: the raster's shadow error there, summed
// over the area lights, into job->checks.
static void penumbra_check_pixel(drift_frame_state *f, int32_t x, int32_t y, uint64_t *rays,
                                 void *user)
{
    metric_job *job = user;
    size_t index = (size_t)y * (size_t)f->params.width + (size_t)x;
    const drift_surface *s = &f->gbuffer.surfaces[index];
    penumbra_check check = { .delta = drift_vec3_splat(0.0f) };
    uint32_t checked = 0;
    if (drift_image_pixel(&job->out[DRIFT_METRIC_SHADOW], x, y)[0] > 0.0f &&
        s->material != DRIFT_INVALID_INDEX) {
        for (uint32_t l = 0; l < f->light_count; ++l) {
            if (drift_realtime_shadow_map(f, l) && f->lights[l].radius > 0.0f) {
                check.delta = drift_vec3_add(
                    check.delta, penumbra_mistake(f, l, x, y, s, job->params->lobe_samples,
                                                  &check.contradicted, rays));
                check.raster += drift_image_pixel(&f->light_buffers[l].shadow, x, y)[0];
                ++checked;
            }
        }
    }
    check.raster = checked ? check.raster / (float)checked : 0.0f;
    job->checks[index] = check;
}

// The penumbra estimate (the metrics' largest cost: the blocker search's shadow-map taps) is
// evaluated at half resolution: at the corner pixel of each 2 x 2 block, for every light; the
// block's other pixels take it when they lie on the same surface (same mesh, normals within
// 25 degrees, depth within 2%), else search themselves. The estimate is dilated by at least
// 2 pixels afterwards, which covers the block.
static void penumbra_coarse_pixel(drift_frame_state *f, int32_t x, int32_t y, uint64_t *rays,
                                  void *user)
{
    (void)rays;
    metric_job *job = user;
    if ((x | y) & 1) {
        return;
    }
    size_t index = (size_t)y * (size_t)f->params.width + (size_t)x;
    size_t block = (size_t)(y / 2) * (size_t)((f->params.width + 1) / 2) + (size_t)(x / 2);
    const drift_surface *s = &f->gbuffer.surfaces[index];
    for (uint32_t l = 0; l < f->light_count; ++l) {
        const drift_raster_light *light = &f->lights[l];
        const drift_shadow_map *map = drift_realtime_shadow_map(f, l);
        float e = -1.0f;
        const light_shape *shape = job->shapes ? &job->shapes[l] : NULL;
        bool behind =
            shape && shape->planar &&
            drift_vec3_dot(light->direction, drift_vec3_sub(s->position, light->centre)) <= 0.0f;
        if (map && light->radius > 0.0f && s->material != DRIFT_INVALID_INDEX && !behind) {
            drift_penumbra_query query = {
                .light_size = shape ? light_size_from(light, shape, s->position) : 0.0f
            };
            e = drift_shadow_map_penumbra_query(map, s->position, s->ng, &query);
        }
        job->coarse[block * f->light_count + l] = e;
    }
}

static float coarse_estimate(const drift_frame_state *f, const metric_job *job, int32_t x,
                             int32_t y, uint32_t l)
{
    int32_t w = f->params.width;
    size_t index = (size_t)y * (size_t)w + (size_t)x;
    size_t corner = (size_t)(y & ~1) * (size_t)w + (size_t)(x & ~1);
    if (corner != index) {
        float za = drift_image_pixel(&f->gbuffer.depth, x, y)[0];
        float zb = drift_image_pixel(&f->gbuffer.depth, x & ~1, y & ~1)[0];
        if (!drift_gbuffer_same_surface(&f->gbuffer, index, corner) ||
            !(fabsf(za - zb) <= 0.02f * za)) {
            return -1.0f;
        }
    }
    size_t block = (size_t)(y / 2) * (size_t)((w + 1) / 2) + (size_t)(x / 2);
    return job->coarse[block * f->light_count + l];
}

static void shadow_pixel(drift_frame_state *f, int32_t x, int32_t y, uint64_t *rays, void *user)
{
    metric_job *job = user;
    size_t index = (size_t)y * (size_t)f->params.width + (size_t)x;
    const drift_surface *s = &f->gbuffer.surfaces[index];
    float e = 0.0f;
    drift_vec3 leak = drift_vec3_splat(0.0f);
    for (uint32_t l = 0; e == 0.0f && s->material != DRIFT_INVALID_INDEX && l < f->light_count;
         ++l) {
        const drift_raster_light *light = &f->lights[l];
        const drift_shadow_map *map = drift_realtime_shadow_map(f, l);
        if (!map || !(light->radius > 0.0f)) {
            continue;
        }
        const light_shape *shape = job->shapes ? &job->shapes[l] : NULL;
        if (shape && shape->planar &&
            drift_vec3_dot(light->direction, drift_vec3_sub(s->position, light->centre)) <= 0.0f) {
            continue; // behind a one-sided planar light: neither raster nor ray tracer sees it
        }
        // A light that straddles the receiver's tangent plane is cut by the horizon: there the
        // shadow map's depth test is at grazing angles and its bias decides, so the estimate
        // counts it as penumbra (the raster's U_l clips the light exactly; S_l does not). With
        // corners the test is exact: some on each side; else the bounding sphere's. A light
        // below both the geometric and the shading normal's horizon casts no light there, so
        // neither raster nor ray tracer has anything to get wrong.
        if (light->type != DRIFT_LIGHT_DIRECTIONAL) {
            float lo = INFINITY, hi = -INFINITY, hi_shading = -INFINITY;
            if (shape && shape->count > 0) {
                for (uint32_t k = 0; k < shape->count; ++k) {
                    drift_vec3 d = drift_vec3_sub(shape->corner[k], s->position);
                    float h = drift_vec3_dot(s->ng, d);
                    lo = fminf(lo, h);
                    hi = fmaxf(hi, h);
                    hi_shading = fmaxf(hi_shading, drift_vec3_dot(s->ns, d));
                }
            } else {
                drift_vec3 d = drift_vec3_sub(light->centre, s->position);
                float h = drift_vec3_dot(s->ng, d);
                lo = h - light->radius;
                hi = h + light->radius;
                hi_shading = drift_vec3_dot(s->ns, d) + light->radius;
            }
            if (hi <= 0.0f && hi_shading <= 0.0f) {
                continue; // the light is wholly below the receiver's horizon: it gets none
            }
            if (lo <= 0.0f && hi >= 0.0f) {
                e = 1.0f;
                break;
            }
        }
        float known = job->coarse ? coarse_estimate(f, job, x, y, l) : -1.0f;
        if (known >= 0.0f) {
            e = known;
        } else {
            drift_penumbra_query query = {
                .light_size = shape ? light_size_from(light, shape, s->position) : 0.0f
            };
            e = drift_shadow_map_penumbra_query(map, s->position, s->ng, &query);
        }
        if (e == 0.0f && job->params->leak_tolerance > 0.0f) {
            leak = drift_vec3_add(leak, shadow_map_mistake(f, l, x, y, s, rays));
        }
    }
    drift_image_pixel(&job->out[DRIFT_METRIC_SHADOW], x, y)[0] = e;
    // Outside every penumbra the light is wholly seen or wholly hidden; where the raster's
    // shadow says otherwise by more than the tolerance (light leaking through a contact or a
    // seam, or a seam darkened by the map's own surfaces), its error is known.
    float leaked = 0.0f;
    if (e == 0.0f && !drift_vec3_is_zero(leak)) {
        float change = drift__sir_display_change(drift_image_get3(&f->final, x, y), leak);
        leaked = change >= job->params->leak_tolerance
                     ? drift_clampf(change / REAL_ERROR_SCALE, 0.0f, 1.0f)
                     : 0.0f;
    }
    drift_image_pixel(&job->out[DRIFT_METRIC_LEAK], x, y)[0] = leaked;
}

// Shadow maps of area lights, built (and left in the frame's cache) when the frame's shadow
// technique did not need them.
static void ensure_shadow_maps(drift_frame_state *f)
{
    for (uint32_t l = 0; l < f->light_count; ++l) {
        uint64_t rays = 0;
        if (f->lights[l].radius > 0.0f &&
            drift_realtime_ensure_shadow_map(f, l, &rays) != DRIFT_OK) {
            drift_realtime_drop_shadow_map(f, l); // logged; this light gets no estimate
        }
    }
}

// Depth with misses far beyond everything seen, so the silhouette against the background is
// an edge like any other.
static float depth_at(const drift_image *depth, int32_t x, int32_t y, float miss)
{
    x = x < 0 ? 0 : (x >= depth->width ? depth->width - 1 : x);
    y = y < 0 ? 0 : (y >= depth->height ? depth->height - 1 : y);
    float z = drift_image_pixel(depth, x, y)[0];
    return z > 0.0f ? z : miss;
}

static void dof_metric(drift_frame_state *f, float threshold, drift_image *out)
{
    int32_t w = f->params.width, h = f->params.height;
    memset(out->pixels, 0, sizeof(float) * (size_t)w * (size_t)h);
    if (f->params.dof == DRIFT_DOF_NONE || !(f->camera.aperture_radius > 0.0f)) {
        return; // a pinhole image has no depth-of-field error
    }
    const drift_image *depth = &f->gbuffer.depth;
    float far = 0.0f;
    for (int32_t y = 0; y < h; ++y) {
        for (int32_t x = 0; x < w; ++x) {
            far = fmaxf(far, drift_image_pixel(depth, x, y)[0]);
        }
    }
    float miss = far > 0.0f ? 4.0f * far : 1.0f;
    float c_inf = drift_coc_radius_pixels(&f->camera, h, 1e30f);
    // reach[p]: 1 + the square's radius around an edge pixel, 0 elsewhere; then spread along
    // rows (the largest reach covering each pixel) and along columns: a square of each edge
    // pixel's own radius in O(pixels x radius) instead of O(edges x radius^2).
    size_t n = (size_t)w * (size_t)h;
    int32_t *reach = drift_alloc(f->ctx, sizeof(int32_t) * n);
    int32_t *rows = drift_alloc(f->ctx, sizeof(int32_t) * n);
    if (!reach || !rows) {
        drift_free(f->ctx, reach);
        drift_free(f->ctx, rows);
        for (size_t i = 0; i < n; ++i) {
            out->pixels[i] = 1.0f; // no memory for the estimate: conservatively everything
        }
        return;
    }
    for (int32_t y = 0; y < h; ++y) {
        for (int32_t x = 0; x < w; ++x) {
            float z[3][3];
            for (int j = 0; j < 3; ++j) {
                for (int i = 0; i < 3; ++i) {
                    z[j][i] = depth_at(depth, x + i - 1, y + j - 1, miss);
                }
            }
            float gx = (z[0][2] + 2.0f * z[1][2] + z[2][2]) - (z[0][0] + 2.0f * z[1][0] + z[2][0]);
            float gy = (z[2][0] + 2.0f * z[2][1] + z[2][2]) - (z[0][0] + 2.0f * z[0][1] + z[0][2]);
            // Sobel weights sum to 8 a side: |G| / 8 is the depth step a pixel, relative to z.
            bool edge = sqrtf(gx * gx + gy * gy) / 8.0f > threshold * z[1][1];
            float c = fmaxf(drift_coc_radius_pixels(&f->camera, h, z[1][1]), c_inf);
            float r = fminf(ceilf(c), (float)(w > h ? w : h));
            reach[(size_t)y * (size_t)w + (size_t)x] = edge ? (int32_t)r + 1 : 0;
        }
    }
    for (int32_t y = 0; y < h; ++y) {
        int32_t *in = reach + (size_t)y * (size_t)w, *row = rows + (size_t)y * (size_t)w;
        for (int32_t x = 0; x < w; ++x) {
            int32_t r = in[x] - 1;
            for (int32_t u = x - r < 0 ? 0 : x - r; r >= 0 && u <= x + r && u < w; ++u) {
                row[u] = row[u] > in[x] ? row[u] : in[x];
            }
        }
    }
    for (int32_t y = 0; y < h; ++y) {
        for (int32_t x = 0; x < w; ++x) {
            int32_t r = rows[(size_t)y * (size_t)w + (size_t)x] - 1;
            for (int32_t v = y - r < 0 ? 0 : y - r; r >= 0 && v <= y + r && v < h; ++v) {
                drift_image_pixel(out, x, v)[0] = 1.0f;
            }
        }
    }
    drift_free(f->ctx, reach);
    drift_free(f->ctx, rows);
}

// The penumbra estimate grown by `radius` pixels each way (a square structuring element, as
// Knauer et al. 2010 dilate theirs): the shadow-map taps are coarser than the image.
static void dilate(drift_image *plane, int32_t radius, float *scratch)
{
    int32_t w = plane->width, h = plane->height;
    for (int32_t y = 0; y < h; ++y) { // rows, then columns: a square element
        for (int32_t x = 0; x < w; ++x) {
            float m = 0.0f;
            for (int32_t u = x - radius; u <= x + radius; ++u) {
                m = u >= 0 && u < w ? fmaxf(m, drift_image_pixel(plane, u, y)[0]) : m;
            }
            scratch[(size_t)y * (size_t)w + (size_t)x] = m;
        }
    }
    for (int32_t y = 0; y < h; ++y) {
        for (int32_t x = 0; x < w; ++x) {
            float m = 0.0f;
            for (int32_t v = y - radius; v <= y + radius; ++v) {
                m = v >= 0 && v < h ? fmaxf(m, scratch[(size_t)v * (size_t)w + (size_t)x]) : m;
            }
            drift_image_pixel(plane, x, y)[0] = m;
        }
    }
}

// 2 pixels (a 5x5 element) where a 512-texel face meets 600 image rows, growing with the
// image pixels a texel spans: at 1920x1080 a fixed 2 let recall fall to 0.82-0.88, since a
// texel's worth of penumbra edge there spans more pixels than the dilation covered.
static int32_t shadow_dilation(const drift_frame_state *f)
{
    double pixels_per_texel = (double)f->params.height / (double)f->params.shadow_map.size;
    long radius = lround(2.0 * pixels_per_texel * 512.0 / 600.0);
    return radius > 2 ? (int32_t)radius : 2;
}

// Keeps a penumbra pixel flagged only where the raster's shadow error, its estimate averaged
// (signed, so the rays' noise cancels) over the penumbra pixels of the same surface and a
// similar raster shadow in a 5 x 5 square, moves the displayed pixel by the tolerance or more
// (or, where its own rays contradict a certain raster, its own estimate does): PCSS is right in
// much of a broad penumbra. Valued by that change / 0.1, as the other weighted metrics, so that
// their largest (DRIFT_COMBINE_MAX) orders pixels by the expected error.
static void gate_penumbra(drift_frame_state *f, drift_image *shadow, const penumbra_check *checks,
                          float tolerance, float *scratch)
{
    int32_t w = shadow->width, h = shadow->height;
    for (int32_t y = 0; y < h; ++y) {
        for (int32_t x = 0; x < w; ++x) {
            size_t index = (size_t)y * (size_t)w + (size_t)x;
            drift_vec3 sum = drift_vec3_splat(0.0f);
            int count = 0;
            for (int32_t v = y - EXPECTED_RADIUS; v <= y + EXPECTED_RADIUS; ++v) {
                for (int32_t u = x - EXPECTED_RADIUS; v >= 0 && v < h && u <= x + EXPECTED_RADIUS;
                     ++u) {
                    size_t other = (size_t)v * (size_t)w + (size_t)u;
                    if (u < 0 || u >= w || drift_image_pixel(shadow, u, v)[0] <= 0.0f ||
                        !drift_gbuffer_same_surface(&f->gbuffer, index, other) ||
                        fabsf(checks[other].raster - checks[index].raster) > SIMILAR_SHADOW) {
                        continue;
                    }
                    sum = drift_vec3_add(sum, checks[other].delta);
                    ++count;
                }
            }
            float change =
                count ? drift__sir_display_change(drift_image_get3(&f->final, x, y),
                                                  drift_vec3_scale(sum, 1.0f / (float)count))
                      : 0.0f;
            // The average hides a sliver the raster got wrong for certain (a fold of a
            // scanned mesh letting light into an umbra): the pixel's own estimate speaks.
            if (checks[index].contradicted) {
                change = fmaxf(change, drift__sir_display_change(drift_image_get3(&f->final, x, y),
                                                                 checks[index].delta));
            }
            scratch[(size_t)y * (size_t)w + (size_t)x] =
                drift_image_pixel(shadow, x, y)[0] > 0.0f && change >= tolerance
                    ? drift_clampf(change / REAL_ERROR_SCALE, 0.0f, 1.0f)
                    : 0.0f;
        }
    }
    memcpy(shadow->pixels, scratch, sizeof(float) * (size_t)w * (size_t)h);
}

uint64_t drift_refine_compute_metrics(drift_frame_state *f,
                                      const drift_refine_metric_params *params,
                                      drift_image out[DRIFT_METRIC_COUNT])
{
    uint64_t rays = 0;
    drift_bounds3 b = f->scene->bounds;
    float diagonal = drift_vec3_length(drift_vec3_sub(b.max, b.min));
    metric_job job = { .params = params,
                       .out = out,
                       .ao_radius =
                           params->ao_radius > 0.0f ? params->ao_radius : 0.05f * diagonal };
    size_t pixels = (size_t)f->params.width * (size_t)f->params.height;
    float *raw = NULL;
    if (params->reflection_tolerance > 0.0f) { // without memory: the unweighted metrics
        raw = drift_alloc(f->ctx, sizeof(float) * pixels);
        job.expected = raw ? drift_alloc(f->ctx, sizeof(float) * pixels) : NULL;
    }
    if (job.expected) {
        float *smooth = job.expected;
        job.expected = raw;
        rays += drift_pass_for_each_pixel(f, drift__sir_expected_error_pixel, &job);
        drift__sir_smooth_expected(raw, f->params.width, f->params.height, EXPECTED_RADIUS, smooth);
        job.expected = smooth;
    }
    rays += drift_pass_for_each_pixel(f, drift__sir_reflection_pixel, &job);
    drift_free(f->ctx, job.expected);
    drift_free(f->ctx, raw);
    ensure_shadow_maps(f);
    job.shapes = f->light_count ? drift_alloc(f->ctx, sizeof(light_shape) * f->light_count) : NULL;
    for (uint32_t l = 0; job.shapes && l < f->light_count; ++l) {
        light_corners(f->scene, &f->lights[l], &job.shapes[l]);
    }
    size_t blocks = (size_t)((f->params.width + 1) / 2) * (size_t)((f->params.height + 1) / 2);
    job.coarse = f->light_count && params->half_res_penumbra
                     ? drift_alloc(f->ctx, sizeof(float) * blocks * f->light_count)
                     : NULL;
    if (job.coarse) { // without memory: every pixel searches
        rays += drift_pass_for_each_pixel(f, penumbra_coarse_pixel, &job);
    }
    rays += drift_pass_for_each_pixel(f, shadow_pixel, &job); // without memory: spheres
    drift_free(f->ctx, job.coarse);
    job.coarse = NULL;
    drift_free(f->ctx, job.shapes);
    float *scratch = drift_alloc(f->ctx, sizeof(float) * pixels);
    if (scratch) { // without memory the estimate stays undilated
        dilate(&out[DRIFT_METRIC_SHADOW], shadow_dilation(f), scratch);
    }
    if (scratch && params->shadow_tolerance > 0.0f) { // without memory: the estimate ungated
        job.checks = drift_alloc(f->ctx, sizeof(penumbra_check) * pixels);
    }
    if (job.checks) {
        rays += drift_pass_for_each_pixel(f, penumbra_check_pixel, &job);
        gate_penumbra(f, &out[DRIFT_METRIC_SHADOW], job.checks, params->shadow_tolerance, scratch);
        drift_free(f->ctx, job.checks);
    }
    drift_free(f->ctx, scratch);
    dof_metric(f, params->edge_threshold, &out[DRIFT_METRIC_DOF]);
    return rays;
}

void drift_refine_combine_metrics(const drift_image metrics[DRIFT_METRIC_COUNT],
                                  drift_refine_combine combine,
                                  const float lambda[DRIFT_METRIC_COUNT], drift_image *combined)
{
    size_t n = (size_t)combined->width * (size_t)combined->height;
    for (size_t i = 0; i < n; ++i) {
        float sum = 0.0f;
        for (int m = 0; m < DRIFT_METRIC_COUNT; ++m) {
            float weight = combine == DRIFT_COMBINE_LAMBDA ? lambda[m] : 1.0f / DRIFT_METRIC_COUNT;
            sum = combine == DRIFT_COMBINE_MAX ? fmaxf(sum, metrics[m].pixels[i])
                                               : sum + weight * metrics[m].pixels[i];
        }
        combined->pixels[i] = drift_clampf(sum, 0.0f, 1.0f);
    }
}
