// The occlusion effect's rows in the hybrid frame (thesis ch. 4): O = the environment's light
// through the diffuse lobe, with the visibility each technique estimates in screen space, and
// SSDO's one bounce. The environment's diffuse light then leaves D (DRIFT_ROW_ENVIRONMENT_DIFFUSE),
// so the frame counts it once: L = E + D(lights, glossy environment) + R + I + O.
// The pre-filtered environment and the output planes live in the effect's state slot.
#include "ssdo/ssdo_pass.h"

#include "drift/ssdo.h"
#include "realtime/realtime.h"

typedef struct ssdo_pass_state {
    drift_ssdo_env *env;
    drift_ssdo_output out;
    drift_image back_depth; // 1: the second depth layer (layers = 2)
    drift_ssdo_view views[DRIFT_SSDO_MAX_VIEWS];
    int32_t view_count;     // rendered this frame (cameras > 0)
    drift_ssdo_params used; // the last render's resolved parameters (the family's report)
    uint64_t pixels;        // pixels the last render shaded (they see a surface)
} ssdo_pass_state;

static void state_destroy(drift_context *ctx, void *data)
{
    ssdo_pass_state *s = data;
    drift_ssdo_env_destroy(s->env);
    drift_ssdo_output_destroy(ctx, &s->out);
    drift_image_destroy(ctx, &s->back_depth);
    drift_ssdo_views_destroy(ctx, s->views, s->view_count);
    drift_free(ctx, s);
}

static drift_result ensure_state(drift_frame_state *f, const drift_pass_args *args,
                                 ssdo_pass_state **out)
{
    *out = drift_pass_state(f, args);
    if (*out) {
        return DRIFT_OK;
    }
    ssdo_pass_state *s = drift_alloc(f->ctx, sizeof *s);
    if (!s) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    drift_result r = drift_ssdo_env_create(f->ctx, f->scene, NULL, &s->env);
    if (r == DRIFT_OK) {
        r = drift_ssdo_output_create(f->ctx, f->params.width, f->params.height, &s->out);
    }
    if (r == DRIFT_OK) {
        r = drift_image_create(f->ctx, f->params.width, f->params.height, 1, &s->back_depth);
    }
    if (r != DRIFT_OK) {
        state_destroy(f->ctx, s);
        return r;
    }
    drift_pass_set_state(f, args, s, state_destroy);
    *out = s;
    return DRIFT_OK;
}

// The second depth layer (layers = 2) and the additional cameras (cameras > 0) into `in`.
static drift_result prepare_layers(drift_frame_state *f, drift_image *back_depth,
                                   drift_ssdo_view *views, int32_t *view_count,
                                   drift_ssdo_inputs *in)
{
    const drift_occlusion_settings *o = &f->params.occlusion_settings;
    if (o->layers == 2) { // one more ray a pixel: where the first layer's surface ends
        drift_result r = drift_ssdo_peel(f->ctx, f->accel, &f->gbuffer, &f->camera, back_depth);
        if (r != DRIFT_OK) {
            return r;
        }
        in->back_depth = back_depth;
    }
    drift_ssdo_views_destroy(f->ctx, views, *view_count);
    *view_count = 0;
    if (o->cameras > 0) { // the camera moves every frame: so do its views
        int32_t w = f->params.width / 2 > 0 ? f->params.width / 2 : 1;
        int32_t h = f->params.height / 2 > 0 ? f->params.height / 2 : 1;
        drift_result r = drift_ssdo_views_render(f->ctx, f->scene, f->accel, &f->camera, o->cameras,
                                                 w, h, views);
        if (r != DRIFT_OK) {
            return r;
        }
        *view_count = o->cameras;
        in->views = views;
        in->view_count = o->cameras;
    }
    return DRIFT_OK;
}

static drift_result render(drift_frame_state *f, const drift_pass_args *args,
                           drift_ssdo_method method)
{
    ssdo_pass_state *s = NULL;
    drift_result r = ensure_state(f, args, &s);
    if (r != DRIFT_OK) {
        return r;
    }
    // The bounce is indirect light: when an indirect technique renders I, it already has it.
    bool indirect_none = f->params.indirect == DRIFT_INDIRECT_NONE;
    const drift_occlusion_settings *o = &f->params.occlusion_settings;
    // The frame's SSDO marches 4 directions x 4 points by default: at the same 16 depth reads
    // as the thesis's 16-point test it had the lowest FLIP of SSAO, GTAO and SSDO on all five
    // scenes of docs/ssdo.md; --occlusion-samples 16 --occlusion-steps 1 is the thesis's.
    bool ssdo_default = method == DRIFT_SSDO_METHOD_SSDO;
    drift_ssdo_params params = { .method = method,
                                 .samples = o->samples ? o->samples : (ssdo_default ? 4 : 0),
                                 .radius = o->radius,
                                 .bounce = o->bounce && indirect_none,
                                 .no_fade = o->no_fade,
                                 .no_blur = o->no_blur,
                                 .steps = o->steps ? o->steps : (ssdo_default ? 4 : 0),
                                 .seed = f->params.seed };
    params = drift_ssdo_params_resolve(&params, f->scene);
    // The bounce reflects what the senders send: their shadowed direct light D.
    drift_ssdo_inputs in = { .gbuffer = &f->gbuffer,
                             .camera = &f->camera,
                             .sender_radiance = &f->direct };
    r = prepare_layers(f, &s->back_depth, s->views, &s->view_count, &in);
    if (r != DRIFT_OK) {
        return r;
    }
    r = drift_ssdo_render(f->ctx, s->env, &in, &params, &s->out);
    if (r == DRIFT_OK) {
        drift_pass_copy_rgb(&s->out.radiance, &f->terms[args->effect]);
        s->used = params;
        s->pixels = 0;
        size_t n = (size_t)f->params.width * (size_t)f->params.height;
        for (size_t i = 0; i < n; ++i) {
            s->pixels += f->gbuffer.surfaces[i].material != DRIFT_INVALID_INDEX;
        }
    }
    return r;
}

drift_result drift_ssdo_pass_ssao(drift_frame_state *f, const drift_pass_args *args)
{
    return render(f, args, DRIFT_SSDO_METHOD_SSAO);
}

drift_result drift_ssdo_pass_gtao(drift_frame_state *f, const drift_pass_args *args)
{
    return render(f, args, DRIFT_SSDO_METHOD_GTAO);
}

drift_result drift_ssdo_pass_ssdo(drift_frame_state *f, const drift_pass_args *args)
{
    return render(f, args, DRIFT_SSDO_METHOD_SSDO);
}

typedef struct reference_job {
    drift_image *out;
    uint32_t stream;
} reference_job;

static void reference_pixel(drift_frame_state *f, int32_t x, int32_t y, uint64_t *rays, void *user)
{
    const reference_job *job = user;
    const drift_surface *s = &f->gbuffer.surfaces[(size_t)y * (size_t)f->params.width + (size_t)x];
    drift_vec3 o = drift_vec3_splat(0.0f);
    if (s->material != DRIFT_INVALID_INDEX) {
        drift_bsdf bsdf = drift_bsdf_make(f->scene, s);
        bsdf.specular = drift_vec3_splat(0.0f); // the diffuse lobe: what O stands for
        drift_sampler sampler = drift_pass_sampler(f, job->stream, x, y);
        o = drift_raster_environment_direct(f->scene, f->accel, s, &bsdf, drift_pass_wo(f, x, y),
                                            f->params.spp, &sampler, rays);
    }
    drift_image_set3(job->out, x, y, o);
}

drift_result drift_ssdo_pass_reference(drift_frame_state *f, const drift_pass_args *args)
{
    reference_job job = { &f->terms[args->effect], args->stream };
    drift_pass_pixels(f, DRIFT_PASS_REFERENCE, reference_pixel, &job);
    return DRIFT_OK;
}

bool drift_ssdo_pass_report(const drift_frame_state *f, drift_ssdo_pass_counts *out)
{
    const drift_pass_args args = { .effect = DRIFT_EFFECT_OCCLUSION,
                                   .technique = f->params.occlusion };
    const ssdo_pass_state *s = drift_pass_state(f, &args);
    if (!s) {
        return false;
    }
    *out = (drift_ssdo_pass_counts){ .samples = s->used.samples,
                                     .steps = s->used.steps,
                                     .bounce = s->used.bounce,
                                     .views = s->view_count,
                                     .layers = f->params.occlusion_settings.layers == 2 ? 2 : 1,
                                     .pixels = s->pixels };
    return true;
}

void drift_ssdo_planes(const drift_frame_state *f, drift_pass_plane_fn add, void *sink)
{
    const drift_pass_args args = { .effect = DRIFT_EFFECT_OCCLUSION,
                                   .technique = f->params.occlusion };
    const ssdo_pass_state *s = drift_pass_state(f, &args);
    if (s) {
        add(sink, "occlusion.visibility", &s->out.visibility);
        add(sink, "occlusion.bent_normal", &s->out.bent_normal);
        add(sink, "occlusion.direct", &s->out.direct);
        if (f->params.occlusion_settings.layers == 2) {
            add(sink, "occlusion.back_depth", &s->back_depth);
        }
        add(sink, "occlusion.bounce", &s->out.bounce);
    }
}

// The contact-shadow fix (thesis §4.5) for the shadow-mapped lights: every pixel the map lets
// through marches its blind length b (the map's depth bias plus its normal offset there)
// toward the light through the depth buffer; an occluder on the way shadows it. S_l *= mask.
drift_result drift_ssdo_pass_contact_shadows(drift_frame_state *f)
{
    drift_context *ctx = f->ctx;
    int32_t w = f->params.width, h = f->params.height;
    drift_image lengths = { 0 }, mask = { 0 }, back = { 0 };
    drift_ssdo_view views[DRIFT_SSDO_MAX_VIEWS];
    int32_t view_count = 0;
    drift_ssdo_inputs in = { .gbuffer = &f->gbuffer, .camera = &f->camera };
    drift_result r = drift_image_create(ctx, w, h, 1, &lengths);
    r = r ? r : drift_image_create(ctx, w, h, 1, &mask);
    r = r ? r : drift_image_create(ctx, w, h, 1, &back);
    r = r ? r : prepare_layers(f, &back, views, &view_count, &in);
    drift_ssdo_contact_counts *counts = &drift_ssdo_family_of(f)->contact;
    *counts = (drift_ssdo_contact_counts){ .samples = f->params.shadow_map.contact_samples };
    for (uint32_t l = 0; r == DRIFT_OK && l < f->light_count; ++l) {
        const drift_raster_light *light = &f->lights[l];
        const drift_shadow_map *map = drift_realtime_shadow_map(f, l);
        drift_image *shadow = &f->light_buffers[l].shadow;
        if (!map) {
            continue;
        }
        ++counts->lights;
        for (int32_t y = 0; y < h; ++y) {
            for (int32_t x = 0; x < w; ++x) {
                const drift_surface *s = &f->gbuffer.surfaces[(size_t)y * (size_t)w + (size_t)x];
                bool lit =
                    s->material != DRIFT_INVALID_INDEX && drift_image_pixel(shadow, x, y)[0] > 0.0f;
                float length = lit ? drift_shadow_map_blind_length(map, s->position, s->ng) : 0.0f;
                drift_image_pixel(&lengths, x, y)[0] = length;
                counts->lit_pixels += length > 0.0f;
            }
        }
        bool directional = light->type == DRIFT_LIGHT_DIRECTIONAL;
        r = drift_ssdo_contact_shadows_per_pixel(
            ctx, &in, directional ? light->direction : light->centre, directional, &lengths,
            f->params.shadow_map.contact_samples, &mask);
        for (int32_t y = 0; r == DRIFT_OK && y < h; ++y) {
            for (int32_t x = 0; x < w; ++x) {
                float visible = drift_image_pixel(&mask, x, y)[0];
                drift_image_pixel(shadow, x, y)[0] *= visible;
                counts->shadowed_pixels +=
                    visible < 1.0f && drift_image_pixel(&lengths, x, y)[0] > 0.0f;
            }
        }
    }
    drift_ssdo_views_destroy(ctx, views, view_count);
    drift_image_destroy(ctx, &lengths);
    drift_image_destroy(ctx, &mask);
    drift_image_destroy(ctx, &back);
    return r;
}
