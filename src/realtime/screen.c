// The real-time renderer's screen-space terms: ambient indirect light (albedo x a constant
// radiance: the mean direct light when none is given, a one-bounce guess at the light
// arriving from everywhere) and the post-process depth of field over the circle of confusion.
#include "realtime/realtime.h"

typedef struct ambient_job {
    drift_vec3 ambient;
} ambient_job;

static void ambient_pixel(drift_frame_state *f, int32_t x, int32_t y, uint64_t *rays, void *user)
{
    (void)rays;
    const ambient_job *job = user;
    if (drift_image_pixel(&f->gbuffer.material_id, x, y)[0] >= 0.0f) {
        drift_vec3 i = drift_vec3_mul(drift_image_get3(&f->gbuffer.albedo, x, y), job->ambient);
        drift_image_set3(&f->indirect, x, y, i);
    }
}

// The mean direct radiance over the visible surfaces.
static drift_vec3 mean_direct(const drift_frame_state *f)
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

drift_result drift_realtime_pass_ambient(drift_frame_state *f, const drift_pass_args *args)
{
    (void)args;
    double t = drift_time_now();
    ambient_job job = { .ambient = f->params.has_ambient ? f->params.ambient : mean_direct(f) };
    drift_pass_for_each_pixel(f, ambient_pixel, &job);
    drift_pass_time(f, DRIFT_PASS_COMPOSE, t);
    return DRIFT_OK;
}

drift_result drift_realtime_pass_post_dof(drift_frame_state *f, const drift_pass_args *args)
{
    (void)args;
    double t = drift_time_now();
    drift_result r = drift_post_dof_tiles(f->ctx, &f->focus, &f->coc, 0,
                                          !f->params.post_dof.per_pixel, &f->final);
    drift_pass_time(f, DRIFT_PASS_DOF, t);
    return r;
}
