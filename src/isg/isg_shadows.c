// ISG soft shadows (Robison & Shirley 2009, section 3.1), light by light over the hard-shadow
// buffer (visible bit, occluder distance, light distance; one ray to the light's centre):
//   search  radius R_p = L / z_eye (eq. 5) over the occluder distances, range eq. 6:
//           r = exp(-l^2 / sigma) * inShadow -> d, their average. l (eq. 7) is the world
//           distance, or with isg_range_plane the distance to the centre's tangent plane
//   penumbra R_s = L d / (D - d) (eq. 8), D the distance to the light's centre
//   gather  radius R_g = R_s / z_eye (eq. 9) over the visible bits, range exp(-l^2 / sigma)
// "/ z_eye" projects scene units to pixels: times H / (2 tan(fov_y / 2)) / z_eye. The light's
// shape is the sample layout: a disk of radius L for sphere, disk and mesh lights (a mesh's L
// is the radius of the disk of its area), a rectangle of half extents |u| / 2 x |v| / 2 for
// quad lights, laid along the image's x and y. Point, spot and directional lights have L = 0:
// their shadow stays hard. The `blur` baseline averages the bits over a fixed disk instead.
#include "isg/isg.h"

#include <math.h>

// The light's size as the search sees it: half extents in scene units and the layout.
typedef struct light_shape {
    drift_isg_layout layout;
    drift_vec2 size;
} light_shape;

static light_shape shape_of(const drift_scene *scene, const drift_raster_light *light)
{
    const drift_light *l = &scene->lights[light->first_light];
    switch (light->type) {
    case DRIFT_LIGHT_QUAD:
        return (light_shape){ DRIFT_ISG_RECT,
                              drift_vec2_make(0.5f * drift_vec3_length(l->edge_u),
                                              0.5f * drift_vec3_length(l->edge_v)) };
    case DRIFT_LIGHT_SPHERE:
    case DRIFT_LIGHT_DISK:
        return (light_shape){ DRIFT_ISG_DISK, drift_vec2_make(l->radius, l->radius) };
    case DRIFT_LIGHT_TRIANGLE: {
        double area = 0.0;
        for (uint32_t t = 0; t < light->light_count; ++t) {
            drift_vec3 c[3];
            drift_light_triangle_vertices(scene, &scene->lights[light->first_light + t], &c[0],
                                          &c[1], &c[2]);
            area += 0.5 * (double)drift_vec3_length(drift_vec3_cross(drift_vec3_sub(c[1], c[0]),
                                                                     drift_vec3_sub(c[2], c[0])));
        }
        float r = (float)sqrt(area / (double)DRIFT_PI);
        return (light_shape){ DRIFT_ISG_DISK, drift_vec2_make(r, r) };
    }
    case DRIFT_LIGHT_POINT:
    case DRIFT_LIGHT_SPOT:
    case DRIFT_LIGHT_DIRECTIONAL:
    case DRIFT_LIGHT_COUNT:
        break;
    }
    return (light_shape){ DRIFT_ISG_DISK, drift_vec2_make(0.0f, 0.0f) };
}

typedef struct range_ctx {
    const drift_image *position;
    const drift_image *material_id;
    const drift_image *hard;
    drift_vec3 p0, n0;
    float inv_sigma;
    bool plane;
} range_ctx;

static float range_position(const range_ctx *c, int32_t x, int32_t y)
{
    if (drift_image_pixel(c->material_id, x, y)[0] < 0.0f) {
        return 0.0f; // a miss or a light: no receiver there
    }
    // l: the world distance (eq. 7), or with isg_range_plane the distance to the centre's
    // tangent plane, which does not weigh down the receiver's own plane (docs/isg.md).
    drift_vec3 d = drift_vec3_sub(drift_image_get3(c->position, x, y), c->p0);
    float l = drift_vec3_dot(d, c->n0);
    return expf(-(c->plane ? l * l : drift_vec3_dot(d, d)) * c->inv_sigma);
}

// Eq. 6.
static float range_search(const void *user, int32_t x, int32_t y)
{
    const range_ctx *c = user;
    if (drift_image_pixel(c->hard, x, y)[0] != 0.0f) {
        return 0.0f; // not in shadow
    }
    return range_position(c, x, y);
}

static float range_gather(const void *user, int32_t x, int32_t y)
{
    return range_position(user, x, y);
}

static float range_surface(const void *user, int32_t x, int32_t y)
{
    const range_ctx *c = user;
    return drift_image_pixel(c->material_id, x, y)[0] >= 0.0f ? 1.0f : 0.0f;
}

// The filter with each range function inlined, one channel (isg.h).
#define SHADOW_FILTER(name, range)                                                           \
    static DRIFT_AVX2_CLONES float name(const drift_isg_kernel *k, const drift_image *image, \
                                        int32_t first, int32_t x, int32_t y, float *out)     \
    {                                                                                        \
        return drift_isg_filter_inline(k, range, NULL, image, first, 1, x, y, out);          \
    }
SHADOW_FILTER(shadow_filter_search, range_search)
SHADOW_FILTER(shadow_filter_gather, range_gather)
SHADOW_FILTER(filter_surface, range_surface)
#undef SHADOW_FILTER

typedef struct shadow_job {
    light_shape *shapes;
    float pixels_per_unit;
} shadow_job;

static void shadow_pixel(drift_frame_state *f, int32_t x, int32_t y, uint64_t *rays, void *user)
{
    (void)rays;
    const shadow_job *job = user;
    const drift_gbuffer *g = &f->gbuffer;
    const drift_isg_state *s = drift_isg_of(f);
    if (drift_image_pixel(&g->material_id, x, y)[0] < 0.0f) {
        for (uint32_t l = 0; l < f->light_count; ++l) {
            float *out = drift_image_pixel(&s->light_search[l], x, y);
            out[0] = INFINITY;
            out[1] = 0.0f;
        }
        return; // direct.c has set S_l = 0 on misses
    }
    uint32_t hash = drift_hash_u32(f->params.seed ^ DRIFT_STREAM_ISG_SHADOWS);
    float z = drift_image_pixel(&g->depth, x, y)[0];
    range_ctx rc = { .position = &g->position,
                     .material_id = &g->material_id,
                     .p0 = drift_image_get3(&g->position, x, y),
                     .n0 = drift_image_get3(&g->normal, x, y),
                     .inv_sigma = 1.0f / f->params.isg.sigma,
                     .plane = f->params.isg.range_plane };
    for (uint32_t l = 0; l < f->light_count; ++l) {
        drift_frame_light_buffers *b = &f->light_buffers[l];
        const float *hard = drift_image_pixel(&b->hard_shadow, x, y);
        float *shadow = drift_image_pixel(&b->shadow, x, y);
        float *search_out = drift_image_pixel(&s->light_search[l], x, y);
        rc.hard = &b->hard_shadow;
        drift_isg_jitter jitter = drift_isg_jitter_at(drift_hash_u32(hash + l), x, y);
        if (f->params.shadows == DRIFT_SHADOWS_BLUR) {
            float r = f->params.isg.blur_radius;
            drift_isg_kernel k = { &s->gather,    jitter, drift_vec2_make(r, r),
                                   range_surface, &rc,    NULL };
            filter_surface(&k, &b->hard_shadow, 0, x, y, shadow);
            continue;
        }
        const light_shape *shape = &job->shapes[l];
        float scale = job->pixels_per_unit / z;
        drift_vec2 search_radius = drift_vec2_make(shape->size.x * scale, shape->size.y * scale);
        search_out[0] = INFINITY;
        search_out[1] = 0.0f;
        shadow[0] = hard[0];
        if (fmaxf(search_radius.x, search_radius.y) < 0.5f) {
            continue; // the light is under half a pixel: the hard shadow
        }
        bool rect = shape->layout == DRIFT_ISG_RECT;
        drift_isg_kernel search = {
            rect ? &s->search_rect : &s->search, jitter, search_radius, range_search, &rc, NULL
        };
        float d;
        if (!(shadow_filter_search(&search, &b->hard_shadow, 1, x, y, &d) > 0.0f)) {
            continue; // no occluder in reach (every sample rejected): the centre's bit
        }
        // Eq. 8 per axis of the light's shape, then eq. 9.
        float penumbra = drift_isg_penumbra(1.0f, d, hard[2]);
        drift_vec2 gather_radius =
            drift_vec2_make(penumbra * search_radius.x, penumbra * search_radius.y);
        search_out[0] = d;
        search_out[1] = fmaxf(gather_radius.x, gather_radius.y);
        if (search_out[1] < 0.5f) {
            continue;
        }
        drift_isg_kernel gather = {
            rect ? &s->gather_rect : &s->gather, jitter, gather_radius, range_gather, &rc, NULL
        };
        shadow_filter_gather(&gather, &b->hard_shadow, 0, x, y, shadow);
    }
}

drift_result drift_isg_pass_shadows(drift_frame_state *f, const drift_pass_args *args)
{
    (void)args;
    double t = drift_time_now();
    drift_result r = drift_isg_prepare(f);
    if (r != DRIFT_OK || f->light_count == 0) {
        return r;
    }
    light_shape *shapes = drift_alloc(f->ctx, sizeof(light_shape) * f->light_count);
    if (!shapes) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    for (uint32_t l = 0; l < f->light_count; ++l) {
        shapes[l] = shape_of(f->scene, &f->lights[l]);
    }
    shadow_job job = { shapes, drift_isg_pixels_per_unit(&f->camera, f->params.height) };
    drift_pass_for_each_pixel(f, shadow_pixel, &job);
    drift_free(f->ctx, shapes);
    f->stats.ms[DRIFT_PASS_ISG] += 1000.0 * (drift_time_now() - t);
    return DRIFT_OK;
}
