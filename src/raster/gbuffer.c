// Primary visibility: one pinhole ray through every pixel centre, traced as coherent
// packets tile by tile, and the G-buffer planes filled from the hits.
#include "raster/raster.h"

#include <math.h>
#include <string.h>

#define TILE 16

// Planes in the order of drift_gbuffer, with their channel counts.
// (clang-format 14 rewraps this list differently on every run.)
// clang-format off
#define GBUFFER_PLANES(X) \
    X(depth, 1) X(position, 3) X(normal, 3) X(geometric_normal, 3) X(albedo, 3) \
    X(specular, 3) X(gloss, 3) X(material_id, 1) X(emission, 3) X(motion, 2)

// clang-format on

drift_result drift_gbuffer_create(drift_context *ctx, int32_t width, int32_t height,
                                  drift_gbuffer *out)
{
    *out = (drift_gbuffer){ .width = width, .height = height };
    drift_result r = DRIFT_OK;
#define CREATE_PLANE(name, channels)                                      \
    if (r == DRIFT_OK) {                                                  \
        r = drift_image_create(ctx, width, height, channels, &out->name); \
    }
    GBUFFER_PLANES(CREATE_PLANE)
#undef CREATE_PLANE
    if (r == DRIFT_OK) {
        size_t count = (size_t)width * (size_t)height;
        out->surfaces = drift_alloc(ctx, sizeof(drift_surface) * count);
        out->mesh_index = drift_alloc(ctx, sizeof(uint32_t) * count);
        out->object_motion = drift_alloc(ctx, sizeof(drift_vec3) * count);
        r = out->surfaces && out->mesh_index && out->object_motion ? DRIFT_OK
                                                                   : DRIFT_ERR_OUT_OF_MEMORY;
    }
    if (r != DRIFT_OK) {
        drift_gbuffer_destroy(ctx, out);
    }
    return r;
}

void drift_gbuffer_destroy(drift_context *ctx, drift_gbuffer *gbuffer)
{
#define DESTROY_PLANE(name, channels) drift_image_destroy(ctx, &gbuffer->name);
    GBUFFER_PLANES(DESTROY_PLANE)
#undef DESTROY_PLANE
    drift_free(ctx, gbuffer->surfaces);
    drift_free(ctx, gbuffer->mesh_index);
    drift_free(ctx, gbuffer->object_motion);
    gbuffer->surfaces = NULL;
    gbuffer->mesh_index = NULL;
    gbuffer->object_motion = NULL;
}

typedef struct gbuffer_job {
    const drift_scene *scene;
    const drift_accel *accel;
    drift_camera_frame camera; // pinhole: the G-buffer samples no lens
    drift_camera_frame prev_camera;
    bool has_prev_camera;
    const float *mesh_motion; // 12 floats a mesh (a point now -> where it was), or NULL
    drift_gbuffer *gbuffer;
    int32_t tiles_x;
    const drift_vec3 *gloss; // per material: the same for every pixel, so made once a frame
} gbuffer_job;

// The gloss plane's value of one material: (theta_max, exponent, roughness).
static drift_vec3 material_gloss(const drift_material *m)
{
    float exponent = m->type == DRIFT_MATERIAL_MIRROR ? INFINITY : m->exponent;
    // Roughness of the Beckmann lobe with the same width: alpha = sqrt(2 / (n + 2)).
    float roughness = isfinite(exponent) ? sqrtf(2.0f / (exponent + 2.0f)) : 0.0f;
    return drift_vec3_make(drift_gloss_theta_max(m), exponent, roughness);
}

// hit_surface: drift_scene_surface of the hit, made by the caller (unread for a miss).
static void write_pixel(const gbuffer_job *job, int32_t x, int32_t y, const drift_ray *ray,
                        const drift_hit *hit, const drift_surface *hit_surface)
{
    const drift_scene *scene = job->scene;
    drift_gbuffer *g = job->gbuffer;
    size_t index = (size_t)y * (size_t)g->width + (size_t)x;
    drift_surface *surface = &g->surfaces[index];
    g->mesh_index[index] = hit->mesh;
    drift_vec3 zero = drift_vec3_splat(0.0f);
    g->object_motion[index] = zero;
    if (hit->mesh == DRIFT_INVALID_INDEX && hit->light == DRIFT_INVALID_INDEX) {
        *surface = (drift_surface){ .material = DRIFT_INVALID_INDEX,
                                    .light = DRIFT_INVALID_INDEX,
                                    .mesh = DRIFT_INVALID_INDEX,
                                    .triangle = DRIFT_INVALID_INDEX };
        if (drift_scene_has_environment(scene)) {
            surface->emission = drift_environment_eval(scene, ray->dir);
        }
        drift_image_pixel(&g->depth, x, y)[0] = 0.0f;
        drift_image_set3(&g->position, x, y, zero);
        drift_image_set3(&g->normal, x, y, zero);
        drift_image_set3(&g->geometric_normal, x, y, zero);
        drift_image_set3(&g->albedo, x, y, zero);
        drift_image_set3(&g->specular, x, y, zero);
        drift_image_set3(&g->gloss, x, y, zero);
        drift_image_pixel(&g->material_id, x, y)[0] = -1.0f;
        drift_image_set3(&g->emission, x, y, surface->emission);
        drift_image_pixel(&g->motion, x, y)[0] = 0.0f;
        drift_image_pixel(&g->motion, x, y)[1] = 0.0f;
        return;
    }
    *surface = *hit_surface;
    drift_image_pixel(&g->depth, x, y)[0] =
        drift_vec3_dot(drift_vec3_sub(surface->position, ray->origin), job->camera.w);
    drift_image_set3(&g->position, x, y, surface->position);
    drift_image_set3(&g->normal, x, y, surface->ns);
    drift_image_set3(&g->geometric_normal, x, y, surface->ng);
    drift_image_set3(&g->emission, x, y, surface->emission);
    drift_vec3 albedo = zero, specular = zero, gloss = zero;
    float material_id = -1.0f;
    if (surface->material != DRIFT_INVALID_INDEX) {
        drift_bsdf bsdf = drift_bsdf_make(scene, surface); // textures applied
        // Burley and GGX: the diffuse lobe's directional albedo toward the camera, not the
        // Phong-equivalent kd (what albedo x irradiance / pi shades with; docs/materials.md).
        albedo = drift_raster_diffuse_albedo(&bsdf, drift_vec3_neg(ray->dir));
        specular = bsdf.specular;
        gloss = job->gloss ? job->gloss[surface->material]
                           : material_gloss(&scene->materials[surface->material]);
        material_id = (float)surface->material;
    }
    drift_image_set3(&g->albedo, x, y, albedo);
    drift_image_set3(&g->specular, x, y, specular);
    drift_image_set3(&g->gloss, x, y, gloss);
    drift_image_pixel(&g->material_id, x, y)[0] = material_id;
    drift_vec2 prev;
    float *motion = drift_image_pixel(&g->motion, x, y);
    drift_vec3 was = surface->position;
    if (job->mesh_motion && hit->mesh != DRIFT_INVALID_INDEX) {
        const float *a = job->mesh_motion + 12 * (size_t)hit->mesh;
        drift_vec3 p = surface->position;
        was = drift_vec3_make(a[0] * p.x + a[1] * p.y + a[2] * p.z + a[3],
                              a[4] * p.x + a[5] * p.y + a[6] * p.z + a[7],
                              a[8] * p.x + a[9] * p.y + a[10] * p.z + a[11]);
        g->object_motion[index] = drift_vec3_sub(was, p);
    }
    if (job->has_prev_camera && drift_camera_frame_project(&job->prev_camera, was, &prev)) {
        motion[0] = prev.x - ((float)x + 0.5f);
        motion[1] = prev.y - ((float)y + 0.5f);
    } else {
        motion[0] = motion[1] = 0.0f;
    }
}

static void render_tiles(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    const gbuffer_job *job = user;
    const drift_gbuffer *g = job->gbuffer;
    drift_ray rays[TILE * TILE];
    drift_hit hits[TILE * TILE];
    drift_surface surfaces[TILE * TILE];
    for (size_t tile = begin; tile < end; ++tile) {
        int32_t x0 = (int32_t)(tile % (size_t)job->tiles_x) * TILE;
        int32_t y0 = (int32_t)(tile / (size_t)job->tiles_x) * TILE;
        int32_t x1 = x0 + TILE < g->width ? x0 + TILE : g->width;
        int32_t y1 = y0 + TILE < g->height ? y0 + TILE : g->height;
        uint32_t n = 0;
        for (int32_t y = y0; y < y1; ++y) {
            for (int32_t x = x0; x < x1; ++x) {
                rays[n++] = drift_camera_frame_ray(&job->camera, (float)x + 0.5f, (float)y + 0.5f,
                                                   drift_vec2_make(0.5f, 0.5f));
            }
        }
        // Veils are passed: the frame blends them over what is behind (hybrid/veils.c).
        drift_accel_intersect_coherent_veils(job->accel, rays, hits, n, DRIFT_VEILS_SKIP);
        // The surfaces first, then the planes: the vertex loads of a whole tile overlap.
        for (uint32_t i = 0; i < n; ++i) {
            if (hits[i].mesh != DRIFT_INVALID_INDEX || hits[i].light != DRIFT_INVALID_INDEX) {
                surfaces[i] = drift_scene_surface(job->scene, &rays[i], &hits[i]);
            }
        }
        n = 0;
        for (int32_t y = y0; y < y1; ++y) {
            for (int32_t x = x0; x < x1; ++x, ++n) {
                write_pixel(job, x, y, &rays[n], &hits[n], &surfaces[n]);
            }
        }
    }
}

void drift_gbuffer_render(drift_context *ctx, const drift_scene *scene, const drift_accel *accel,
                          const drift_camera *camera, const drift_camera *prev_camera,
                          const float *mesh_motion, drift_gbuffer *gbuffer, uint64_t *rays)
{
    drift_camera pinhole = *camera;
    pinhole.aperture_radius = 0.0f;
    gbuffer_job job = {
        .scene = scene,
        .accel = accel,
        .camera = drift_camera_frame_make(&pinhole, gbuffer->width, gbuffer->height),
        .has_prev_camera = prev_camera != NULL,
        .mesh_motion = mesh_motion,
        .gbuffer = gbuffer,
        .tiles_x = (gbuffer->width + TILE - 1) / TILE,
    };
    if (prev_camera) {
        job.prev_camera = drift_camera_frame_make(prev_camera, gbuffer->width, gbuffer->height);
    }
    // A failed allocation only costs the per-pixel computation.
    drift_vec3 *gloss =
        scene->material_count ? drift_alloc(ctx, sizeof *gloss * scene->material_count) : NULL;
    if (gloss) {
        for (uint32_t i = 0; i < scene->material_count; ++i) {
            gloss[i] = material_gloss(&scene->materials[i]);
        }
    }
    job.gloss = gloss;
    int32_t tiles_y = (gbuffer->height + TILE - 1) / TILE;
    drift_parallel_for(ctx, (size_t)job.tiles_x * (size_t)tiles_y, 1, render_tiles, &job);
    drift_free(ctx, gloss);
    *rays += (uint64_t)gbuffer->width * (uint64_t)gbuffer->height;
}
