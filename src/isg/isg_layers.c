// ISG's optional second depth layer (beyond the paper): one more ray per pixel, continuing
// the pinhole ray through the object it first hit (depth peeling by object), shaded like the
// sharp reflection buffer's hits (emission plus direct light with hard shadows). It holds
// what a blurred foreground object hides in the one-sample frame: the depth-of-field gather
// uses it where a lens ray would see past the object (isg_dof.c, docs/isg.md).
#include "isg/isg.h"

#include <math.h>

static void layer_pixel(drift_frame_state *f, int32_t x, int32_t y, uint64_t *rays, void *user)
{
    (void)user;
    drift_isg_state *s = drift_isg_of(f);
    size_t index = (size_t)y * (size_t)f->params.width + (size_t)x;
    const drift_gbuffer *g = &f->gbuffer;
    float *depth = drift_image_pixel(&s->layer_depth, x, y);
    drift_image_set3(&s->layer_colour, x, y, drift_vec3_splat(0.0f));
    depth[0] = 0.0f; // no second layer
    uint32_t mesh = g->mesh_index[index];
    if (mesh == DRIFT_INVALID_INDEX || drift_image_pixel(&g->depth, x, y)[0] <= 0.0f) {
        return;
    }
    drift_vec3 hit = drift_image_get3(&g->position, x, y);
    drift_vec3 d = drift_vec3_sub(hit, f->camera.position);
    float t_first = drift_vec3_length(d);
    drift_ray ray = { .origin = f->camera.position,
                      .dir = drift_vec3_scale(d, 1.0f / t_first),
                      .tmin = t_first * (1.0f - 1e-4f),
                      .tmax = INFINITY };
    drift_sampler sampler = drift_pass_sampler(f, DRIFT_STREAM_ISG_LAYER, x, y);
    float distance;
    drift_raster_radiance l =
        drift_raster_trace_radiance(&f->shading, ray, mesh, &sampler, rays, &distance);
    drift_vec3 forward = drift_vec3_normalize(drift_vec3_sub(f->camera.target, f->camera.position));
    depth[0] = isfinite(distance) ? distance * drift_vec3_dot(ray.dir, forward) : 1e30f;
    drift_image_set3(&s->layer_colour, x, y, drift_vec3_add(l.emitted, l.reflected));
}

drift_result drift_isg_pass_layer(drift_frame_state *f)
{
    drift_result r = drift_isg_prepare(f);
    if (r != DRIFT_OK) {
        return r;
    }
    f->stats.rays[DRIFT_PASS_ISG] += drift_pass_for_each_pixel(f, layer_pixel, NULL);
    return DRIFT_OK;
}
