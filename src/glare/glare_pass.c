// Temporal glare as the hybrid frame's last effect: final is convolved in place with the PSF
// of the eye model (drift/glare.h). The drift_glare (its particles, FFT plans and, in static
// mode, its PSF) lives in the effect's state slot across frames.
#include "glare/glare_pass.h"

#include "drift/glare.h"

#include <math.h>

typedef struct glare_pass_state {
    drift_glare *glare;
    double last_time; // drift_time_now() of the last frame, for the dynamic eye's dt
} glare_pass_state;

static void state_destroy(drift_context *ctx, void *data)
{
    glare_pass_state *s = data;
    drift_glare_destroy(s->glare);
    drift_free(ctx, s);
}

static drift_result apply(drift_frame_state *f, const drift_pass_args *args, drift_glare_mode mode)
{
    glare_pass_state *s = drift_pass_state(f, args);
    if (!s) {
        s = drift_alloc(f->ctx, sizeof *s);
        if (!s) {
            return DRIFT_ERR_OUT_OF_MEMORY;
        }
        // The PSF at the camera's angular pitch: the glare a viewer of this field of view sees.
        double aspect = (double)f->params.width / (double)f->params.height;
        double fov_x = 2.0 * atan(aspect * tan(0.5 * (double)f->camera.fov_y));
        drift_glare_params params = { .mode = mode, .seed = f->params.seed, .image_fov = fov_x };
        drift_result r = drift_glare_create(f->ctx, &params, &s->glare);
        if (r != DRIFT_OK) {
            drift_free(f->ctx, s);
            return r;
        }
        drift_pass_set_state(f, args, s, state_destroy);
    }
    double now = drift_time_now();
    double dt = s->last_time > 0.0 ? now - s->last_time : 0.0;
    s->last_time = now;
    return drift_glare_apply_to(s->glare, &f->final, dt, &f->final);
}

drift_result drift_glare_pass_static(drift_frame_state *f, const drift_pass_args *args)
{
    return apply(f, args, DRIFT_GLARE_MODE_STATIC);
}

drift_result drift_glare_pass_dynamic(drift_frame_state *f, const drift_pass_args *args)
{
    return apply(f, args, DRIFT_GLARE_MODE_DYNAMIC);
}

const drift_glare *drift_glare_pass_object(const drift_frame_state *f)
{
    const drift_pass_args args = { .effect = DRIFT_EFFECT_GLARE, .technique = f->params.glare };
    const glare_pass_state *s = drift_pass_state(f, &args);
    return s ? s->glare : NULL;
}
