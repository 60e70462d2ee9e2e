// Veils in the hybrid frame: the surfaces of BLEND materials (drift_alpha_mode), composited
// over the frame. The G-buffer's camera rays pass them (DRIFT_VEILS_SKIP), so every row shades
// what lies behind; then each pixel's camera ray is traced again to meet them (DRIFT_VEILS_MEET),
// front to back, up to VEIL_LAYERS deep, and each is blended over the focus image by its
// opacity a: focus = sum_i T_i a_i S_i + T_n focus, T_i the product of (1 - a_j) in front of
// it. A veil's light S is its emission, its direct light with hard shadows (as a sharp
// reflection's hit), and its diffuse albedo times the indirect light the surface behind it
// receives (its indirect term over its albedo). Without this, the stochastic veil of the path
// tracer took a single G-buffer sample a pixel and showed dithered.
#include "drift/image.h"
#include "hybrid/techniques.h"
#include "raster/raster.h"

#define VEIL_LAYERS 4

typedef struct veil_job {
    drift_camera_frame camera;
    const drift_image *indirect; // the frame's I term, or NULL when the indirect row adds none
} veil_job;

bool drift_hybrid_scene_has_veils(const drift_scene *scene)
{
    for (uint32_t m = 0; m < scene->mesh_count; ++m) {
        if (scene->materials[scene->meshes[m].material].alpha_mode == DRIFT_ALPHA_BLEND) {
            return true;
        }
    }
    return false;
}

// The indirect radiance arriving at the surface behind pixel i (its I term over its diffuse
// albedo where that albedo says anything), for the veils in front of it.
static drift_vec3 indirect_behind(const drift_frame_state *f, const veil_job *job, int32_t x,
                                  int32_t y)
{
    const size_t i = (size_t)y * (size_t)f->params.width + (size_t)x;
    const drift_surface *s = &f->gbuffer.surfaces[i];
    if (!job->indirect || s->material == DRIFT_INVALID_INDEX) {
        return drift_vec3_splat(0.0f);
    }
    drift_bsdf bsdf = drift_bsdf_make(f->scene, s);
    drift_vec3 a = drift_raster_diffuse_albedo(&bsdf, drift_pass_wo(f, x, y));
    drift_vec3 term = drift_image_get3(job->indirect, x, y);
    return drift_vec3_make(a.x > 0.02f ? term.x / a.x : 0.0f, a.y > 0.02f ? term.y / a.y : 0.0f,
                           a.z > 0.02f ? term.z / a.z : 0.0f);
}

static void veil_pixel(drift_frame_state *f, int32_t x, int32_t y, uint64_t *rays, void *user)
{
    const veil_job *job = user;
    drift_ray ray = drift_camera_frame_ray(&job->camera, (float)x + 0.5f, (float)y + 0.5f,
                                           drift_vec2_make(0.5f, 0.5f));
    drift_vec3 sum = drift_vec3_splat(0.0f), ambient = drift_vec3_splat(0.0f);
    float through = 1.0f;
    bool ambient_known = false;
    drift_sampler sampler = drift_pass_sampler(f, DRIFT_STREAM_VEIL, x, y);
    for (int layer = 0; layer < VEIL_LAYERS; ++layer) {
        drift_hit hit;
        ++*rays;
        if (!drift_accel_intersect_veils(f->accel, &ray, DRIFT_VEILS_MEET, &hit) ||
            hit.mesh == DRIFT_INVALID_INDEX ||
            f->scene->materials[f->scene->meshes[hit.mesh].material].alpha_mode !=
                DRIFT_ALPHA_BLEND) {
            break; // the surface the G-buffer holds, or nothing
        }
        float a = drift_scene_opacity(f->scene, hit.mesh, hit.prim, hit.u, hit.v);
        drift_surface s = drift_scene_surface(f->scene, &ray, &hit);
        drift_bsdf bsdf = drift_bsdf_make(f->scene, &s);
        drift_vec3 wo = drift_vec3_neg(ray.dir);
        if (!ambient_known) {
            ambient = indirect_behind(f, job, x, y);
            ambient_known = true;
        }
        drift_vec3 light = drift_vec3_add(
            s.emission, drift_raster_direct_hard(&f->shading, &s, &bsdf, wo, &sampler, rays));
        light =
            drift_vec3_add(light, drift_vec3_mul(drift_raster_diffuse_albedo(&bsdf, wo), ambient));
        sum = drift_vec3_add(sum, drift_vec3_scale(light, through * a));
        through *= 1.0f - a;
        ray.tmin = hit.t * (1.0f + 1e-5f) + 1e-6f;
    }
    if (through < 1.0f) {
        drift_vec3 behind = drift_image_get3(&f->focus, x, y);
        drift_image_set3(&f->focus, x, y, drift_vec3_add(sum, drift_vec3_scale(behind, through)));
    }
}

drift_result drift_hybrid_pass_veils(drift_frame_state *f)
{
    if (!drift_hybrid_scene_has_veils(f->scene)) {
        return DRIFT_OK;
    }
    drift_camera pinhole = f->camera;
    pinhole.aperture_radius = 0.0f; // as the G-buffer's rays
    const drift_technique_row *indirect =
        drift_technique_row_chosen(&f->params, DRIFT_EFFECT_INDIRECT);
    veil_job job = {
        .camera = drift_camera_frame_make(&pinhole, f->params.width, f->params.height),
        .indirect = indirect->flags & DRIFT_ROW_NO_TERM ? NULL : &f->terms[DRIFT_EFFECT_INDIRECT],
    };
    drift_pass_pixels(f, DRIFT_PASS_COMPOSE, veil_pixel, &job);
    return DRIFT_OK;
}
