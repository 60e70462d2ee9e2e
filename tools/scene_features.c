// Cheap features of a loaded scene (tools/scene_features.h): one pass over the lights and the
// triangles, and a 16 x 16 one-sample path-tracer probe.
#include "scene_features.h"

#include "drift/pt.h"

#include <math.h>

static const char *const names[SCENE_FEATURE_COUNT] = {
    "log_triangles", "log_lights",     "area_share", "delta_share", "environment",
    "glossy_share",  "emissive_share", "lens",       "depth_range", "log_rays"
};

// log10 of the rays a sample casts: the path tracer at 16 x 16, 1 spp, depth 8.
static double probe_rays(drift_context *ctx, const drift_scene *scene, const drift_accel *accel)
{
    enum {
        N = 16
    };

    drift_pt_params params = { .width = N, .height = N, .seed = 1u, .max_depth = 8 };
    drift_pt *pt = NULL;
    double rays = 0.0;
    if (drift_pt_create(ctx, scene, accel, &params, &pt) == DRIFT_OK &&
        drift_pt_render_samples(pt, 1, NULL) == DRIFT_OK) {
        drift_pt_stats st = drift_pt_get_stats(pt);
        rays = (double)(st.camera_rays + st.shadow_rays + st.bounce_rays) / (N * N);
    }
    drift_pt_destroy(pt);
    return rays > 0.0 ? log10(rays) : 0.0;
}

const char *scene_feature_name(int k)
{
    return k >= 0 && k < SCENE_FEATURE_COUNT ? names[k] : NULL;
}

static double triangle_area(const drift_mesh *mesh, uint32_t t)
{
    const uint32_t *i = mesh->indices + 3 * (size_t)t;
    const float *p = mesh->positions;
    drift_vec3 a = drift_vec3_make(p[3 * i[0]], p[3 * i[0] + 1], p[3 * i[0] + 2]);
    drift_vec3 b = drift_vec3_make(p[3 * i[1]], p[3 * i[1] + 1], p[3 * i[1] + 2]);
    drift_vec3 c = drift_vec3_make(p[3 * i[2]], p[3 * i[2] + 1], p[3 * i[2] + 2]);
    return 0.5 *
           (double)drift_vec3_length(drift_vec3_cross(drift_vec3_sub(b, a), drift_vec3_sub(c, a)));
}

void scene_features(drift_context *ctx, const drift_scene *scene, const drift_accel *accel,
                    double out[SCENE_FEATURE_COUNT])
{
    uint64_t triangles = 0;
    double area = 0.0, glossy = 0.0, emissive = 0.0;
    drift_vec3 lo = drift_vec3_splat(INFINITY), hi = drift_vec3_splat(-INFINITY);
    for (uint32_t m = 0; m < scene->mesh_count; ++m) {
        const drift_mesh *mesh = &scene->meshes[m];
        const drift_material *mat =
            mesh->material < scene->material_count ? &scene->materials[mesh->material] : NULL;
        double a = 0.0;
        for (uint32_t t = 0; t < mesh->triangle_count; ++t) {
            a += triangle_area(mesh, t);
        }
        for (uint32_t v = 0; v < mesh->vertex_count; ++v) {
            drift_vec3 p = drift_vec3_make(mesh->positions[3 * v], mesh->positions[3 * v + 1],
                                           mesh->positions[3 * v + 2]);
            lo = drift_vec3_min(lo, p);
            hi = drift_vec3_max(hi, p);
        }
        triangles += mesh->triangle_count;
        area += a;
        if (mat && (mat->type == DRIFT_MATERIAL_MIRROR || !drift_vec3_is_zero(mat->specular))) {
            glossy += a;
        }
        if (mat && !drift_vec3_is_zero(mat->emission)) {
            emissive += a;
        }
    }
    uint32_t with_area = 0;
    for (uint32_t l = 0; l < scene->light_count; ++l) {
        drift_light_type t = scene->lights[l].type;
        with_area += t == DRIFT_LIGHT_QUAD || t == DRIFT_LIGHT_DISK || t == DRIFT_LIGHT_SPHERE ||
                     t == DRIFT_LIGHT_TRIANGLE;
    }
    double lights = scene->light_count > 0 ? (double)scene->light_count : 1.0;
    const drift_camera *cam = &scene->camera;
    double dist = 1.0;
    if (triangles > 0) {
        drift_vec3 centre = drift_vec3_scale(drift_vec3_add(lo, hi), 0.5f);
        dist = fmax((double)drift_vec3_length(drift_vec3_sub(centre, cam->position)), 1e-6);
    }
    out[0] = log10(1.0 + (double)triangles);
    out[1] = log10(1.0 + (double)scene->light_count);
    out[2] = with_area / lights;
    out[3] = (scene->light_count - with_area) / lights;
    out[4] = drift_scene_has_environment(scene) ? 1.0 : 0.0;
    out[5] = area > 0.0 ? glossy / area : 0.0;
    out[6] = area > 0.0 ? emissive / area : 0.0;
    out[7] = cam->aperture_radius > 0.0f ? 1.0 : 0.0;
    out[8] = triangles > 0 ? log10(fmax((double)drift_scene_extent(scene), 1e-6) / dist) : 0.0;
    out[9] = ctx && accel ? probe_rays(ctx, scene, accel) : 0.0;
}
