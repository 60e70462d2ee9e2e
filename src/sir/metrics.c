// SIR's error metrics (paper §5), per pixel in [0,1], from the hybrid frame's last render:
//   reflection1..5  on reflective material (a specular lobe): 1; |p - c| / max |q - c| over the
//                   scene bounds (c the environment probe); <-i, r>; <-i, n>; the ambient
//                   occlusion k_a (fraction of ao_samples cosine rays that hit within ao_radius)
//   dof             Sobel edges of the depth plane, each dilated by a square of radius
//                   C_max(p) = max(C(z_p), C_inf) pixels; zero for a pinhole or no DOF
//   shadow          1 where drift_shadow_map_penumbra says a light's penumbra may fall, or
//                   where an area light straddles the receiver's tangent plane; dilated (2 px
//                   at 600 rows a 512-texel face, growing with the pixels a texel spans)
#include "sir/sir.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

// A polygonal light's corners (a quad's four, a triangle's three, a small emissive mesh's
// vertices): the shadow metric bounds the light by them instead of its bounding sphere.
#define MAX_CORNERS 64

typedef struct light_shape {
    uint32_t count; // 0: use the bounding sphere
    bool planar;    // one-sided and every part faces `direction`: nothing lights its back
    drift_vec3 corner[MAX_CORNERS];
} light_shape;

typedef struct metric_job {
    const drift_refine_metric_params *params;
    drift_image *out;
    float ao_radius;
    uint64_t ao_rays;
    light_shape *shapes; // one a frame light, or NULL: bounding spheres
} metric_job;

static bool is_reflective(const drift_frame_state *f, const drift_surface *s)
{
    if (s->material == DRIFT_INVALID_INDEX) {
        return false;
    }
    const drift_material *m = &f->scene->materials[s->material];
    return !drift_vec3_is_zero(m->specular) &&
           (m->type == DRIFT_MATERIAL_MIRROR || m->exponent > 0.0f);
}

// The environment map's centre for a pixel of `mesh`: its probe when captured, else where the
// frame would put the scene probe.
static drift_vec3 probe_centre(const drift_frame_state *f, uint32_t mesh)
{
    for (uint32_t i = 0; i < f->probe_count; ++i) {
        if (f->probes[i].mesh == mesh || f->probes[i].mesh == DRIFT_INVALID_INDEX) {
            return drift_envmap_probe(f->probes[i].map);
        }
    }
    if (f->params.envmap.has_probe) {
        return f->params.envmap.probe;
    }
    return drift_vec3_scale(drift_vec3_add(f->scene->bounds.min, f->scene->bounds.max), 0.5f);
}

// The farthest a point of the scene can be from c: the farthest corner of the bounds.
static float max_distance(const drift_scene *scene, drift_vec3 c)
{
    float best = 0.0f;
    for (int k = 0; k < 8; ++k) {
        drift_vec3 corner = { (k & 1) ? scene->bounds.max.x : scene->bounds.min.x,
                              (k & 2) ? scene->bounds.max.y : scene->bounds.min.y,
                              (k & 4) ? scene->bounds.max.z : scene->bounds.min.z };
        best = fmaxf(best, drift_vec3_length(drift_vec3_sub(corner, c)));
    }
    return best;
}

static float ambient_occlusion(const drift_frame_state *f, const drift_surface *s, float radius,
                               uint32_t samples, drift_sampler *sampler, uint64_t *rays)
{
    drift_frame frame = drift_frame_from_normal(s->ns);
    uint32_t hits = 0;
    for (uint32_t k = 0; k < samples; ++k) {
        drift_vec3 dir = drift_frame_to_world(
            &frame, drift_sample_cosine_hemisphere(drift_sampler_next2(sampler)));
        drift_ray ray = { .origin = drift_offset_origin(s->position, s->ng, dir),
                          .dir = dir,
                          .tmin = 0.0f,
                          .tmax = radius };
        ++*rays;
        hits += drift_accel_occluded(f->accel, &ray) ? 1u : 0u;
    }
    return samples ? (float)hits / (float)samples : 0.0f;
}

static void reflection_pixel(drift_frame_state *f, int32_t x, int32_t y, uint64_t *rays, void *user)
{
    metric_job *job = user;
    size_t index = (size_t)y * (size_t)f->params.width + (size_t)x;
    const drift_surface *s = &f->gbuffer.surfaces[index];
    float e[5] = { 0 };
    if (is_reflective(f, s)) {
        drift_vec3 wo = drift_pass_wo(f, x, y); // -i
        drift_vec3 r = drift_vec3_reflect(wo, s->ns);
        drift_vec3 c = probe_centre(f, f->gbuffer.mesh_index[index]);
        float far = max_distance(f->scene, c);
        e[0] = 1.0f;
        e[1] = far > 0.0f ? drift_vec3_length(drift_vec3_sub(s->position, c)) / far : 0.0f;
        e[2] = drift_vec3_dot(wo, r);
        e[3] = drift_vec3_dot(wo, s->ns);
        drift_sampler sampler =
            drift_pass_sampler(f, DRIFT_STREAM_SIR_AO ^ job->params->seed, x, y);
        e[4] = ambient_occlusion(f, s, job->ao_radius, job->params->ao_samples, &sampler, rays);
    }
    for (int m = 0; m < 5; ++m) {
        drift_image_pixel(&job->out[DRIFT_METRIC_REFLECTION1 + m], x, y)[0] =
            drift_clampf(e[m], 0.0f, 1.0f);
    }
}

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
        out->planar = light->one_sided;
        return;
    }
    if (l->type != DRIFT_LIGHT_TRIANGLE || 3u * light->light_count > MAX_CORNERS) {
        return;
    }
    // Triangle lights (one, or a small emissive mesh): every vertex; planar when each
    // triangle faces the mean normal (then the back of the plane gets no light).
    bool planar = light->one_sided;
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

static void shadow_pixel(drift_frame_state *f, int32_t x, int32_t y, uint64_t *rays, void *user)
{
    (void)rays;
    metric_job *job = user;
    size_t index = (size_t)y * (size_t)f->params.width + (size_t)x;
    const drift_surface *s = &f->gbuffer.surfaces[index];
    float e = 0.0f;
    for (uint32_t l = 0; e == 0.0f && s->material != DRIFT_INVALID_INDEX && l < f->light_count;
         ++l) {
        const drift_raster_light *light = &f->lights[l];
        const drift_shadow_map *map = f->light_buffers[l].shadow_map;
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
        drift_penumbra_query query = {
            .light_size = shape ? light_size_from(light, shape, s->position) : 0.0f
        };
        e = drift_shadow_map_penumbra_query(map, s->position, s->ng, &query);
    }
    drift_image_pixel(&job->out[DRIFT_METRIC_SHADOW], x, y)[0] = e;
}

// Shadow maps of area lights, built (and left in the frame's cache) when the frame's shadow
// technique did not need them.
static void ensure_shadow_maps(drift_frame_state *f)
{
    for (uint32_t l = 0; l < f->light_count; ++l) {
        uint64_t rays = 0;
        if (f->lights[l].radius > 0.0f &&
            drift_realtime_ensure_shadow_map(f, l, &rays) != DRIFT_OK) {
            f->light_buffers[l].shadow_map = NULL; // logged; this light gets no estimate
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

void drift_refine_compute_metrics(drift_frame_state *f, const drift_refine_metric_params *params,
                                  drift_image out[DRIFT_METRIC_COUNT])
{
    drift_bounds3 b = f->scene->bounds;
    float diagonal = drift_vec3_length(drift_vec3_sub(b.max, b.min));
    metric_job job = { .params = params,
                       .out = out,
                       .ao_radius =
                           params->ao_radius > 0.0f ? params->ao_radius : 0.05f * diagonal };
    drift_pass_for_each_pixel(f, reflection_pixel, &job);
    ensure_shadow_maps(f);
    job.shapes = f->light_count ? drift_alloc(f->ctx, sizeof(light_shape) * f->light_count) : NULL;
    for (uint32_t l = 0; job.shapes && l < f->light_count; ++l) {
        light_corners(f->scene, &f->lights[l], &job.shapes[l]);
    }
    drift_pass_for_each_pixel(f, shadow_pixel, &job); // without memory: bounding spheres
    drift_free(f->ctx, job.shapes);
    float *scratch =
        drift_alloc(f->ctx, sizeof(float) * (size_t)f->params.width * (size_t)f->params.height);
    if (scratch) { // without memory the estimate stays undilated
        dilate(&out[DRIFT_METRIC_SHADOW], shadow_dilation(f), scratch);
        drift_free(f->ctx, scratch);
    }
    dof_metric(f, params->edge_threshold, &out[DRIFT_METRIC_DOF]);
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
            sum += weight * metrics[m].pixels[i];
        }
        combined->pixels[i] = drift_clampf(sum, 0.0f, 1.0f);
    }
}
