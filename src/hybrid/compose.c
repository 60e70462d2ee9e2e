// Composition of the hybrid frame: focus = E + D + R + I per pixel, the circle-of-confusion
// plane, then depth of field (none, the post-process gather, or the reference lens render).
#include "hybrid/frame_internal.h"
#include "hybrid/isg_internal.h"

typedef struct compose_job {
    drift_vec3 ambient;
} compose_job;

static void compose_pixel(drift_hybrid *f, int32_t x, int32_t y, uint64_t *rays, void *user)
{
    (void)rays;
    const compose_job *job = user;
    const drift_hybrid_params *p = &f->params;
    drift_vec3 l = drift_image_get3(&f->gbuffer.emission, x, y);
    bool surface = drift_image_pixel(&f->gbuffer.material_id, x, y)[0] >= 0.0f;
    if (surface) {
        l = drift_vec3_add(l, drift_image_get3(&f->direct, x, y));
        if (p->reflections != DRIFT_REFLECTIONS_NONE) {
            l = drift_vec3_add(l, drift_image_get3(&f->reflections, x, y));
        }
        if (p->indirect == DRIFT_INDIRECT_AMBIENT) {
            drift_vec3 i = drift_vec3_mul(drift_image_get3(&f->gbuffer.albedo, x, y), job->ambient);
            drift_image_set3(&f->indirect, x, y, i);
        }
        if (p->indirect != DRIFT_INDIRECT_NONE) {
            l = drift_vec3_add(l, drift_image_get3(&f->indirect, x, y));
        }
    }
    drift_image_set3(&f->focus, x, y, l);
    float z = drift_image_pixel(&f->gbuffer.depth, x, y)[0];
    // A miss is infinitely far: its circle of confusion is the limit A / F in pixels.
    drift_image_pixel(&f->coc, x, y)[0] =
        drift_coc_radius_pixels(&f->camera, p->height, z > 0.0f ? z : 1e30f);
}

// The default ambient radiance: the mean direct radiance over the visible surfaces, a
// one-bounce guess at the light arriving from everywhere.
static drift_vec3 default_ambient(const drift_hybrid *f)
{
    double sum[3] = { 0.0, 0.0, 0.0 };
    size_t count = 0;
    for (int32_t y = 0; y < f->params.height; ++y) {
        for (int32_t x = 0; x < f->params.width; ++x) {
            if (drift_image_pixel(&f->gbuffer.material_id, x, y)[0] < 0.0f) {
                continue;
            }
            drift_vec3 d = drift_image_get3(&f->direct, x, y);
            sum[0] += (double)d.x;
            sum[1] += (double)d.y;
            sum[2] += (double)d.z;
            ++count;
        }
    }
    if (count == 0) {
        return drift_vec3_splat(0.0f);
    }
    return drift_vec3_make((float)(sum[0] / (double)count), (float)(sum[1] / (double)count),
                           (float)(sum[2] / (double)count));
}

// Every enabled effect path-traced through the lens: the reference depth of field.
static drift_result render_lens_reference(drift_hybrid *f, const atomic_bool *cancel)
{
    const drift_hybrid_params *p = &f->params;
    uint32_t components = DRIFT_PT_COMPONENT_EMISSION | DRIFT_PT_COMPONENT_DIRECT;
    int32_t depth = 1;
    if (p->reflections != DRIFT_REFLECTIONS_NONE) {
        components |= DRIFT_PT_COMPONENT_SPECULAR;
        depth = p->max_depth;
    }
    if (p->indirect != DRIFT_INDIRECT_NONE) {
        components |= DRIFT_PT_COMPONENT_DIFFUSE;
        depth = p->max_depth;
    }
    double t = drift_time_now();
    drift_result r = drift_hybrid_reference_render(f, components, depth, true, cancel, &f->final);
    f->stats.ms[DRIFT_PASS_REFERENCE] += 1000.0 * (drift_time_now() - t);
    return r;
}

drift_result drift_hybrid_pass_compose(drift_hybrid *f, const atomic_bool *cancel)
{
    const drift_hybrid_params *p = &f->params;
    if (p->dof == DRIFT_DOF_REFERENCE) {
        return render_lens_reference(f, cancel);
    }
    double t = drift_time_now();
    compose_job job = { .ambient = p->has_ambient ? p->ambient : drift_vec3_splat(0.0f) };
    if (p->indirect == DRIFT_INDIRECT_AMBIENT && !p->has_ambient) {
        job.ambient = default_ambient(f);
    }
    drift_hybrid_for_each_pixel(f, compose_pixel, &job);
    if (p->dof == DRIFT_DOF_NONE) {
        drift_hybrid_copy_rgb(&f->focus, &f->final);
    }
    f->stats.ms[DRIFT_PASS_COMPOSE] += 1000.0 * (drift_time_now() - t);
    if (p->dof == DRIFT_DOF_POST) {
        t = drift_time_now();
        drift_result r = drift_post_dof(f->ctx, &f->focus, &f->coc, 0, &f->final);
        f->stats.ms[DRIFT_PASS_DOF] = 1000.0 * (drift_time_now() - t);
        return r;
    }
    if (p->dof == DRIFT_DOF_ISG) {
        return drift_isg_pass_dof(f); // focus -> final (isg_dof.c)
    }
    return DRIFT_OK;
}
