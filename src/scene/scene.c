#include "drift/scene.h"

#include "microfacet.h"
#include "scene_internal.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

drift_result drift_scene_create(drift_context *ctx, drift_scene **out_scene)
{
    if (!out_scene) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    *out_scene = NULL;
    drift_scene *scene = drift_alloc(ctx, sizeof(drift_scene));
    if (!scene) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    scene->ctx = ctx;
    scene->environment.texture = DRIFT_INVALID_INDEX;
    scene->bounds = drift_bounds3_empty();
    scene->reflector_bounds = drift_bounds3_empty();
    scene->camera = drift_camera_look_at(drift_vec3_make(0, 0, 1), drift_vec3_make(0, 0, 0),
                                         drift_vec3_make(0, 1, 0), 0.8f, 512, 512);
    *out_scene = scene;
    return DRIFT_OK;
}

static void free_mesh(drift_context *ctx, drift_mesh *mesh)
{
    drift_free(ctx, mesh->positions);
    drift_free(ctx, mesh->normals);
    drift_free(ctx, mesh->uvs);
    drift_free(ctx, mesh->uvs1);
    drift_free(ctx, mesh->colors);
    drift_free(ctx, mesh->tangents);
    drift_free(ctx, mesh->indices);
}

void drift_scene_destroy(drift_scene *scene)
{
    if (!scene) {
        return;
    }
    drift_context *ctx = scene->ctx;
    for (uint32_t i = 0; i < scene->mesh_count; ++i) {
        free_mesh(ctx, &scene->meshes[i]);
    }
    for (uint32_t i = 0; i < scene->texture_count; ++i) {
        drift_image_destroy(ctx, &scene->textures[i]);
    }
    drift__light_table_destroy(scene);
    drift__texture_pyramids_destroy(scene);
    drift_free(ctx, scene->meshes);
    drift_free(ctx, scene->materials);
    drift_free(ctx, scene->lights);
    drift_free(ctx, scene->textures);
    drift_free(ctx, scene);
}

// Grows *array (of *count elements of `size` bytes) by one element; returns its index.
static drift_result push_back(drift_context *ctx, void **array, uint32_t *count, size_t size,
                              uint32_t limit, uint32_t *out_index)
{
    if (*count >= limit) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    uint32_t n = *count;
    // Grow by doubling: capacity is the next power of two at or above n + 1.
    bool is_power_of_two = n == 0 || (n & (n - 1)) == 0;
    if (is_power_of_two) {
        size_t new_cap = n == 0 ? 4 : (size_t)n * 2;
        void *grown = drift_realloc(ctx, *array, (size_t)n * size, new_cap * size);
        if (!grown) {
            return DRIFT_ERR_OUT_OF_MEMORY;
        }
        *array = grown;
    }
    *out_index = n;
    *count = n + 1;
    return DRIFT_OK;
}

static void *copy_array(drift_context *ctx, const void *src, size_t count, size_t elem,
                        size_t padding_bytes)
{
    size_t bytes, total;
    if (!drift_size_mul(count, elem, &bytes) || !drift_size_add(bytes, padding_bytes, &total)) {
        return NULL;
    }
    void *dst = drift_alloc(ctx, total);
    if (dst && src) {
        memcpy(dst, src, bytes);
    }
    return dst;
}

static bool triangle_is_degenerate(const float *p, const uint32_t *tri)
{
    drift_vec3 a = { p[3 * tri[0]], p[3 * tri[0] + 1], p[3 * tri[0] + 2] };
    drift_vec3 b = { p[3 * tri[1]], p[3 * tri[1] + 1], p[3 * tri[1] + 2] };
    drift_vec3 c = { p[3 * tri[2]], p[3 * tri[2] + 1], p[3 * tri[2] + 2] };
    drift_vec3 n = drift_vec3_cross(drift_vec3_sub(b, a), drift_vec3_sub(c, a));
    float area2 = drift_vec3_dot(n, n);
    return !(area2 > 0.0f) || !isfinite(area2);
}

drift_result drift_scene_add_mesh(drift_scene *scene, const drift_mesh_desc *desc,
                                  uint32_t *out_index)
{
    if (!scene || !desc || !desc->positions || !desc->indices) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    drift_context *ctx = scene->ctx;
    const char *name = desc->name ? desc->name : "mesh";
    if (desc->vertex_count == 0 || desc->triangle_count == 0 ||
        desc->vertex_count > DRIFT_SCENE_MAX_VERTICES ||
        desc->triangle_count > DRIFT_SCENE_MAX_TRIANGLES) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, name, 0,
                  "mesh has %u vertices and %u triangles (each must be in 1..%u)",
                  desc->vertex_count, desc->triangle_count, DRIFT_SCENE_MAX_TRIANGLES);
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    for (size_t i = 0; i < (size_t)desc->vertex_count * 3; ++i) {
        if (!isfinite(desc->positions[i])) {
            drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, name, 0,
                      "vertex %zu has a non-finite coordinate", i / 3);
            return DRIFT_ERR_INVALID_ARGUMENT;
        }
    }
    for (size_t i = 0; i < (size_t)desc->triangle_count * 3; ++i) {
        if (desc->indices[i] >= desc->vertex_count) {
            drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, name, 0,
                      "triangle %zu refers to vertex %u, but the mesh has %u", i / 3,
                      desc->indices[i], desc->vertex_count);
            return DRIFT_ERR_INVALID_ARGUMENT;
        }
    }
    if (desc->material >= scene->material_count) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, name, 0,
                  "material %u out of range (scene has %u)", desc->material, scene->material_count);
        return DRIFT_ERR_INVALID_ARGUMENT;
    }

    drift_mesh mesh = { .vertex_count = desc->vertex_count,
                        .material = desc->material,
                        .first_light = DRIFT_INVALID_INDEX,
                        .node = DRIFT_INVALID_INDEX };
    snprintf(mesh.name, sizeof(mesh.name), "%s", name);
    // One padding float: Embree reads 16 bytes for the last vertex (buffer_padding.md).
    mesh.positions = copy_array(ctx, desc->positions, (size_t)desc->vertex_count * 3, sizeof(float),
                                sizeof(float));
    mesh.indices = copy_array(ctx, NULL, (size_t)desc->triangle_count * 3, sizeof(uint32_t), 0);
    if (desc->normals) {
        mesh.normals =
            copy_array(ctx, desc->normals, (size_t)desc->vertex_count * 3, sizeof(float), 0);
    }
    if (desc->uvs) {
        mesh.uvs = copy_array(ctx, desc->uvs, (size_t)desc->vertex_count * 2, sizeof(float), 0);
    }
    if (desc->uvs1) {
        mesh.uvs1 = copy_array(ctx, desc->uvs1, (size_t)desc->vertex_count * 2, sizeof(float), 0);
    }
    if (desc->tangents) {
        mesh.tangents =
            copy_array(ctx, desc->tangents, (size_t)desc->vertex_count * 4, sizeof(float), 0);
    }
    if (desc->colors) {
        mesh.colors =
            copy_array(ctx, desc->colors, (size_t)desc->vertex_count * 3, sizeof(float), 0);
    }
    if (!mesh.positions || !mesh.indices || (desc->normals && !mesh.normals) ||
        (desc->uvs && !mesh.uvs) || (desc->uvs1 && !mesh.uvs1) ||
        (desc->tangents && !mesh.tangents) || (desc->colors && !mesh.colors)) {
        free_mesh(ctx, &mesh);
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    // Keep only triangles with area; the accel and light sampling need non-zero normals.
    uint32_t kept = 0, dropped = 0;
    for (uint32_t t = 0; t < desc->triangle_count; ++t) {
        const uint32_t *tri = desc->indices + 3 * (size_t)t;
        if (triangle_is_degenerate(desc->positions, tri)) {
            dropped++;
            continue;
        }
        memcpy(mesh.indices + 3 * (size_t)kept, tri, 3 * sizeof(uint32_t));
        kept++;
    }
    if (dropped > 0) {
        drift_log(ctx, DRIFT_LOG_WARNING, DRIFT_ERR_INVALID_ARGUMENT, name, 0,
                  "dropped %u degenerate (zero-area) triangles of %u", dropped,
                  desc->triangle_count);
    }
    if (kept == 0) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, name, 0,
                  "every triangle of the mesh is degenerate");
        free_mesh(ctx, &mesh);
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    mesh.triangle_count = kept;
    if (mesh.normals) {
        // Normalize; replace broken normals by zero so shading falls back to flat.
        for (uint32_t v = 0; v < mesh.vertex_count; ++v) {
            float *n = mesh.normals + 3 * (size_t)v;
            drift_vec3 nn = { n[0], n[1], n[2] };
            float len = drift_vec3_length(nn);
            bool ok = isfinite(len) && len > 1e-12f;
            for (int k = 0; k < 3; ++k) {
                n[k] = ok ? n[k] / len : 0.0f;
            }
        }
    }
    uint32_t index;
    drift_result r = push_back(ctx, (void **)&scene->meshes, &scene->mesh_count, sizeof(drift_mesh),
                               UINT32_MAX - 1, &index);
    if (r != DRIFT_OK) {
        free_mesh(ctx, &mesh);
        return r;
    }
    scene->meshes[index] = mesh;
    scene->committed = false;
    if (out_index) {
        *out_index = index;
    }
    return DRIFT_OK;
}

drift_material drift_material_make(drift_vec3 diffuse)
{
    return (drift_material){ .diffuse = diffuse,
                             .diffuse_texture = DRIFT_INVALID_INDEX,
                             .ggx = { .metallic_roughness_texture = DRIFT_INVALID_INDEX,
                                      .normal_texture = DRIFT_INVALID_INDEX,
                                      .emissive_texture = DRIFT_INVALID_INDEX,
                                      .occlusion_texture = DRIFT_INVALID_INDEX,
                                      .clearcoat_texture = DRIFT_INVALID_INDEX,
                                      .clearcoat_roughness_texture = DRIFT_INVALID_INDEX },
                             .alpha_cutoff = 0.5f,
                             .opacity = 1.0f,
                             .opacity_texture = DRIFT_INVALID_INDEX };
}

static bool vec3_is_nonnegative_finite(drift_vec3 v)
{
    return drift_vec3_is_finite(v) && v.x >= 0.0f && v.y >= 0.0f && v.z >= 0.0f;
}

static bool unit_range(float v)
{
    return v >= 0.0f && v <= 1.0f;
}

static bool ggx_params_valid(const drift_ggx_params *g)
{
    return unit_range(g->alpha) && unit_range(g->metallic) && unit_range(g->transmission) &&
           (g->ior == 0.0f || (g->ior >= 1.0f && g->ior <= 10.0f)) &&
           vec3_is_nonnegative_finite(g->specular_tint) &&
           vec3_is_nonnegative_finite(g->edge_tint) && vec3_is_nonnegative_finite(g->eta) &&
           vec3_is_nonnegative_finite(g->k);
}

drift_result drift_scene_add_material(drift_scene *scene, const drift_material *material,
                                      uint32_t *out_index)
{
    if (!scene || !material) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    drift_material m = *material;
    m.name[DRIFT_NAME_MAX - 1] = '\0';
    if (!vec3_is_nonnegative_finite(m.diffuse) || !vec3_is_nonnegative_finite(m.specular) ||
        !vec3_is_nonnegative_finite(m.emission) || !isfinite(m.exponent) || m.exponent < 0.0f ||
        (unsigned)m.type >= DRIFT_MATERIAL_COUNT ||
        (unsigned)m.diffuse_model > DRIFT_DIFFUSE_BURLEY ||
        !(m.diffuse_roughness >= 0.0f && m.diffuse_roughness <= 1.0f) ||
        !ggx_params_valid(&m.ggx) || (unsigned)m.alpha_mode >= DRIFT_ALPHA_MODE_COUNT ||
        (m.alpha_mode != DRIFT_ALPHA_OPAQUE &&
         (!unit_range(m.opacity) || !unit_range(m.alpha_cutoff)))) {
        drift_log(scene->ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, m.name, 0,
                  "material has a negative, non-finite or out-of-range value");
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    uint32_t index;
    drift_result r = push_back(scene->ctx, (void **)&scene->materials, &scene->material_count,
                               sizeof(drift_material), UINT32_MAX - 1, &index);
    if (r != DRIFT_OK) {
        return r;
    }
    scene->materials[index] = m;
    scene->committed = false;
    if (out_index) {
        *out_index = index;
    }
    return DRIFT_OK;
}

bool drift_light_is_area(drift_light_type type)
{
    return type == DRIFT_LIGHT_QUAD || type == DRIFT_LIGHT_DISK || type == DRIFT_LIGHT_SPHERE ||
           type == DRIFT_LIGHT_TRIANGLE;
}

static const char *light_problem(const drift_light *l)
{
    if ((unsigned)l->type >= DRIFT_LIGHT_COUNT) {
        return "unknown light type";
    }
    if (!vec3_is_nonnegative_finite(l->color)) {
        return "light colour is negative or not finite";
    }
    if (!drift_vec3_is_finite(l->position) || !drift_vec3_is_finite(l->direction) ||
        !drift_vec3_is_finite(l->edge_u) || !drift_vec3_is_finite(l->edge_v) ||
        !isfinite(l->radius)) {
        return "light geometry is not finite";
    }
    switch (l->type) {
    case DRIFT_LIGHT_SPOT:
        if (!(l->spot_outer > 0.0f) || l->spot_outer > DRIFT_PI || l->spot_inner < 0.0f ||
            l->spot_inner > l->spot_outer) {
            return "spot light needs 0 <= inner <= outer <= pi, outer > 0";
        }
        if ((unsigned)l->spot_falloff > (unsigned)DRIFT_SPOT_BLENDER) {
            return "spot light falloff is not a drift_spot_falloff";
        }
        return drift_vec3_length(l->direction) > 1e-12f ? NULL : "light direction is zero";
    case DRIFT_LIGHT_DIRECTIONAL:
        return drift_vec3_length(l->direction) > 1e-12f ? NULL : "light direction is zero";
    case DRIFT_LIGHT_QUAD: {
        drift_vec3 n = drift_vec3_cross(l->edge_u, l->edge_v);
        return drift_vec3_length(n) > 0.0f ? NULL : "quad light has zero area";
    }
    case DRIFT_LIGHT_DISK:
        if (!(l->radius > 0.0f)) {
            return "disk light has zero area (radius must be > 0)";
        }
        return drift_vec3_length(l->direction) > 1e-12f ? NULL : "disk light normal is zero";
    case DRIFT_LIGHT_SPHERE:
        return l->radius > 0.0f ? NULL : "sphere light has zero area (radius must be > 0)";
    case DRIFT_LIGHT_TRIANGLE:
        return "triangle lights come from emissive materials, not from add_light";
    case DRIFT_LIGHT_POINT:
    case DRIFT_LIGHT_COUNT:
        break;
    }
    return NULL;
}

drift_result drift_scene_add_light(drift_scene *scene, const drift_light *light,
                                   uint32_t *out_index)
{
    if (!scene || !light) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    const char *problem = light_problem(light);
    if (problem) {
        drift_log(scene->ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, NULL, 0, "%s", problem);
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    drift_light l = *light;
    if (l.type == DRIFT_LIGHT_SPOT || l.type == DRIFT_LIGHT_DIRECTIONAL ||
        l.type == DRIFT_LIGHT_DISK) {
        l.direction = drift_vec3_normalize(l.direction);
    }
    l.mesh = l.triangle = DRIFT_INVALID_INDEX;
    uint32_t index;
    drift_result r = push_back(scene->ctx, (void **)&scene->lights, &scene->light_count,
                               sizeof(drift_light), DRIFT_SCENE_MAX_LIGHTS, &index);
    if (r != DRIFT_OK) {
        return r;
    }
    scene->lights[index] = l;
    scene->lights[index].node = DRIFT_INVALID_INDEX; // the glTF importer sets it after
    scene->committed = false;
    if (out_index) {
        *out_index = index;
    }
    return DRIFT_OK;
}

drift_result drift_scene_add_texture(drift_scene *scene, drift_image image, uint32_t *out_index)
{
    if (!scene || !drift_image_is_valid(&image)) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    uint32_t index;
    drift_result r = push_back(scene->ctx, (void **)&scene->textures, &scene->texture_count,
                               sizeof(drift_image), UINT32_MAX - 1, &index);
    if (r != DRIFT_OK) {
        drift_image_destroy(scene->ctx, &image);
        return r;
    }
    scene->textures[index] = image;
    if (out_index) {
        *out_index = index;
    }
    return DRIFT_OK;
}

float drift_scene_extent(const drift_scene *scene)
{
    drift_bounds3 b = scene->reflector_bounds;
    if (drift_bounds3_is_empty(b)) {
        b = scene->bounds;
    }
    float d = drift_bounds3_is_empty(b) ? 0.0f : drift_vec3_length(drift_vec3_sub(b.max, b.min));
    return d > 0.0f && isfinite(d) ? d : 1.0f;
}

drift_bounds3 drift__scene_mesh_bounds(const drift_scene *scene)
{
    drift_bounds3 b = drift_bounds3_empty();
    for (uint32_t m = 0; m < scene->mesh_count; ++m) {
        b = drift_bounds3_union(b, drift_mesh_bounds(&scene->meshes[m]));
    }
    return b;
}

// Removes previously generated triangle lights (commit regenerates them).
static void drop_triangle_lights(drift_scene *scene)
{
    uint32_t kept = 0;
    for (uint32_t i = 0; i < scene->light_count; ++i) {
        if (scene->lights[i].type != DRIFT_LIGHT_TRIANGLE) {
            scene->lights[kept++] = scene->lights[i];
        }
    }
    scene->light_count = kept;
    for (uint32_t m = 0; m < scene->mesh_count; ++m) {
        scene->meshes[m].first_light = DRIFT_INVALID_INDEX;
    }
}

// Rescales kd + ks to at most 1 per channel so no material creates energy.
static void enforce_energy_conservation(drift_scene *scene, drift_material *m)
{
    float worst = fmaxf(fmaxf(m->diffuse.x + m->specular.x, m->diffuse.y + m->specular.y),
                        m->diffuse.z + m->specular.z);
    if (worst > 1.0f) {
        drift_log(scene->ctx, DRIFT_LOG_WARNING, DRIFT_ERR_INVALID_ARGUMENT, m->name, 0,
                  "diffuse + specular reflectance %.3f exceeds 1; scaled down", (double)worst);
        m->diffuse = drift_vec3_scale(m->diffuse, 1.0f / worst);
        m->specular = drift_vec3_scale(m->specular, 1.0f / worst);
    }
}

static bool within_coord_max(drift_vec3 p)
{
    const double m = DRIFT_SCENE_COORD_MAX;
    return fabs((double)p.x) <= m && fabs((double)p.y) <= m && fabs((double)p.z) <= m;
}

// Every vertex, light and the camera within +-DRIFT_SCENE_COORD_MAX (NaN fails too).
static drift_result check_coordinates(const drift_scene *scene)
{
    for (uint32_t m = 0; m < scene->mesh_count; ++m) {
        const drift_mesh *mesh = &scene->meshes[m];
        for (uint32_t v = 0; v < mesh->vertex_count; ++v) {
            const float *p = mesh->positions + 3 * (size_t)v;
            if (!within_coord_max(drift_vec3_make(p[0], p[1], p[2]))) {
                drift_log(scene->ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, mesh->name, 0,
                          "vertex %u is at (%g, %g, %g), outside the +-%g drift accepts", v,
                          (double)p[0], (double)p[1], (double)p[2], DRIFT_SCENE_COORD_MAX);
                return DRIFT_ERR_INVALID_ARGUMENT;
            }
        }
    }
    for (uint32_t i = 0; i < scene->light_count; ++i) {
        const drift_light *l = &scene->lights[i];
        if (l->type != DRIFT_LIGHT_TRIANGLE &&
            (!within_coord_max(l->position) || !within_coord_max(l->edge_u) ||
             !within_coord_max(l->edge_v) || !(fabs((double)l->radius) <= DRIFT_SCENE_COORD_MAX))) {
            drift_log(scene->ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, NULL, 0,
                      "light %u is at (%g, %g, %g) or spans further than the +-%g drift accepts", i,
                      (double)l->position.x, (double)l->position.y, (double)l->position.z,
                      DRIFT_SCENE_COORD_MAX);
            return DRIFT_ERR_INVALID_ARGUMENT;
        }
    }
    const drift_camera *cam = &scene->camera;
    if (!within_coord_max(cam->position) || !within_coord_max(cam->target)) {
        drift_log(scene->ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, NULL, 0,
                  "the camera's position (%g, %g, %g) or target is outside the +-%g drift accepts",
                  (double)cam->position.x, (double)cam->position.y, (double)cam->position.z,
                  DRIFT_SCENE_COORD_MAX);
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    return DRIFT_OK;
}

// A triangle light's colour: its material's emission, times the mean of the emissive texture
// at the triangle's corners, edge midpoints and centre, for the power the light is picked by
// (sampling reads the texture at each point). Kept at 1% of the untextured emission or more, so
// that no texel the mean misses goes unsampled.
static drift_vec3 triangle_emission(const drift_scene *scene, const drift_material *mat,
                                    uint32_t mesh, uint32_t triangle)
{
    if (mat->type != DRIFT_MATERIAL_GGX || mat->ggx.emissive_texture == DRIFT_INVALID_INDEX) {
        return mat->emission;
    }
    static const float points[7][2] = { { 0, 0 },
                                        { 1, 0 },
                                        { 0, 1 },
                                        { 0.5f, 0 },
                                        { 0, 0.5f },
                                        { 0.5f, 0.5f },
                                        { 1 / 3.0f, 1 / 3.0f } };
    drift_vec3 sum = drift_vec3_splat(0.0f);
    for (int i = 0; i < 7; ++i) {
        drift_surface s =
            drift__triangle_surface(scene, mesh, triangle, points[i][0], points[i][1]);
        sum = drift_vec3_add(sum, drift__material_emission(scene, mat, &s));
    }
    return drift_vec3_max(drift_vec3_scale(sum, 1.0f / 7.0f),
                          drift_vec3_scale(mat->emission, 0.01f));
}

// Per-vertex tangents for the normal-mapped meshes that have normals and uvs but none from
// their file (tangents.c).
static drift_result compute_tangents(drift_scene *scene)
{
    for (uint32_t i = 0; i < scene->mesh_count; ++i) {
        drift_mesh *mesh = &scene->meshes[i];
        const drift_material *m = &scene->materials[mesh->material];
        if (mesh->tangents || !mesh->normals || !mesh->uvs || m->type != DRIFT_MATERIAL_GGX ||
            m->ggx.normal_texture == DRIFT_INVALID_INDEX) {
            continue;
        }
        drift_result r = drift__mesh_tangents(
            scene->ctx, mesh, m->maps[DRIFT_TEXTURE_NORMAL].uv_set, &mesh->tangents);
        if (r != DRIFT_OK) {
            return r;
        }
    }
    return DRIFT_OK;
}

drift_result drift_scene_commit(drift_scene *scene)
{
    if (!scene) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    drift_context *ctx = scene->ctx;
    drop_triangle_lights(scene);
    for (uint32_t i = 0; i < scene->material_count; ++i) {
        drift_material *m = &scene->materials[i];
        if (m->diffuse_texture != DRIFT_INVALID_INDEX &&
            m->diffuse_texture >= scene->texture_count) {
            drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, m->name, 0,
                      "texture %u out of range (scene has %u)", m->diffuse_texture,
                      scene->texture_count);
            return DRIFT_ERR_INVALID_ARGUMENT;
        }
        if (m->alpha_mode != DRIFT_ALPHA_OPAQUE && m->opacity_texture != DRIFT_INVALID_INDEX &&
            m->opacity_texture >= scene->texture_count) {
            drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, m->name, 0,
                      "opacity texture %u out of range (scene has %u)", m->opacity_texture,
                      scene->texture_count);
            return DRIFT_ERR_INVALID_ARGUMENT;
        }
        if (m->type == DRIFT_MATERIAL_DEFAULT && !drift_vec3_is_zero(m->specular) &&
            !(m->exponent > 0.0f)) {
            drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, m->name, 0,
                      "glossy material needs an exponent > 0");
            return DRIFT_ERR_INVALID_ARGUMENT;
        }
        if (m->type == DRIFT_MATERIAL_GGX) {
            const uint32_t t[] = {
                m->ggx.metallic_roughness_texture, m->ggx.normal_texture,
                m->ggx.emissive_texture,           m->ggx.occlusion_texture,
                m->ggx.clearcoat_texture,          m->ggx.clearcoat_roughness_texture
            };
            bool out_of_range = false;
            for (size_t k = 0; k < sizeof t / sizeof t[0]; ++k) {
                out_of_range |= t[k] != DRIFT_INVALID_INDEX && t[k] >= scene->texture_count;
            }
            if (out_of_range) {
                drift_log(
                    ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, m->name, 0,
                    "metallic-roughness, normal, emissive, occlusion or clearcoat texture out "
                    "of range "
                    "(scene has %u)",
                    scene->texture_count);
                return DRIFT_ERR_INVALID_ARGUMENT;
            }
            // What the Phong-shading techniques read of it (docs/materials.md).
            drift_vec3 kd;
            drift__ggx_phong_equivalent(m, m->diffuse, m->ggx.alpha, m->ggx.metallic, &kd,
                                        &m->specular, &m->exponent);
            continue;
        }
        enforce_energy_conservation(scene, m);
    }
    if (scene->environment.texture != DRIFT_INVALID_INDEX &&
        scene->environment.texture >= scene->texture_count) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, NULL, 0,
                  "environment texture %u out of range", scene->environment.texture);
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    if (!vec3_is_nonnegative_finite(scene->environment.color)) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, NULL, 0,
                  "environment colour is negative or not finite");
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    const drift_camera *cam = &scene->camera;
    if (!(cam->fov_y > 0.0f && cam->fov_y < DRIFT_PI) || cam->aperture_radius < 0.0f ||
        !isfinite(cam->aperture_radius) || cam->focus_distance < 0.0f ||
        !isfinite(cam->focus_distance) || cam->width <= 0 || cam->height <= 0 ||
        cam->width > DRIFT_IMAGE_MAX_DIMENSION || cam->height > DRIFT_IMAGE_MAX_DIMENSION ||
        !drift_vec3_is_finite(cam->position) || !drift_vec3_is_finite(cam->target) ||
        drift_vec3_length(drift_vec3_sub(cam->target, cam->position)) <= 0.0f ||
        drift_vec3_length(drift_vec3_cross(drift_vec3_sub(cam->target, cam->position), cam->up)) <=
            0.0f) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, NULL, 0,
                  "camera is invalid (fov in (0, pi), non-negative aperture and focus, image size "
                  "1..%d, target != position, up not parallel to the view direction)",
                  DRIFT_IMAGE_MAX_DIMENSION);
        return DRIFT_ERR_INVALID_ARGUMENT;
    }

    // Bounds over meshes and light shapes.
    drift_bounds3 bounds = drift__scene_mesh_bounds(scene);
    for (uint32_t i = 0; i < scene->light_count; ++i) {
        const drift_light *l = &scene->lights[i];
        if (l->type == DRIFT_LIGHT_QUAD) {
            bounds = drift_bounds3_extend(bounds, l->position);
            bounds = drift_bounds3_extend(bounds, drift_vec3_add(l->position, l->edge_u));
            bounds = drift_bounds3_extend(bounds, drift_vec3_add(l->position, l->edge_v));
            bounds = drift_bounds3_extend(
                bounds, drift_vec3_add(drift_vec3_add(l->position, l->edge_u), l->edge_v));
        } else if (l->type == DRIFT_LIGHT_DISK || l->type == DRIFT_LIGHT_SPHERE) {
            drift_vec3 r = drift_vec3_splat(l->radius);
            bounds = drift_bounds3_extend(bounds, drift_vec3_sub(l->position, r));
            bounds = drift_bounds3_extend(bounds, drift_vec3_add(l->position, r));
        } else if (l->type == DRIFT_LIGHT_POINT || l->type == DRIFT_LIGHT_SPOT) {
            bounds = drift_bounds3_extend(bounds, l->position);
        }
    }
    drift_result far = check_coordinates(scene);
    if (far != DRIFT_OK) {
        return far;
    }
    scene->bounds = bounds;
    scene->reflector_bounds = drift_bounds3_empty();
    for (uint32_t m = 0; m < scene->mesh_count; ++m) {
        const drift_material *mat = &scene->materials[scene->meshes[m].material];
        bool pure_emitter = !drift_vec3_is_zero(mat->emission) &&
                            drift_vec3_is_zero(mat->diffuse) && drift_vec3_is_zero(mat->specular) &&
                            mat->diffuse_texture == DRIFT_INVALID_INDEX &&
                            mat->type != DRIFT_MATERIAL_MIRROR;
        if (!pure_emitter) {
            scene->reflector_bounds =
                drift_bounds3_union(scene->reflector_bounds, drift_mesh_bounds(&scene->meshes[m]));
        }
    }

    // One triangle light per emissive mesh triangle, consecutive per mesh.
    for (uint32_t m = 0; m < scene->mesh_count; ++m) {
        drift_mesh *mesh = &scene->meshes[m];
        const drift_material *mat = &scene->materials[mesh->material];
        if (drift_vec3_is_zero(mat->emission)) {
            continue;
        }
        if ((uint64_t)scene->light_count + mesh->triangle_count > DRIFT_SCENE_MAX_LIGHTS) {
            drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, mesh->name, 0,
                      "too many emissive triangles (limit %u lights)", DRIFT_SCENE_MAX_LIGHTS);
            return DRIFT_ERR_INVALID_ARGUMENT;
        }
        mesh->first_light = scene->light_count;
        // Closed and not see-through: the faces turned away from the camera's side light
        // only the mesh's inside (or outside), which the camera's side never receives.
        bool two_sided = mat->emission_two_sided &&
                         !(mat->type == DRIFT_MATERIAL_GGX && mat->ggx.transmission > 0.0f) &&
                         !drift__closed_emitter_front_only(scene, m);
        for (uint32_t t = 0; t < mesh->triangle_count; ++t) {
            uint32_t index;
            drift_result r = push_back(ctx, (void **)&scene->lights, &scene->light_count,
                                       sizeof(drift_light), DRIFT_SCENE_MAX_LIGHTS, &index);
            if (r != DRIFT_OK) {
                return r;
            }
            scene->lights[index] = (drift_light){ .type = DRIFT_LIGHT_TRIANGLE,
                                                  .color = triangle_emission(scene, mat, m, t),
                                                  .mesh = m,
                                                  .triangle = t,
                                                  .two_sided = two_sided,
                                                  .node = mesh->node };
        }
    }
    drift_result r = drift__texture_pyramids_build(scene);
    if (r == DRIFT_OK) {
        r = compute_tangents(scene);
    }
    if (r != DRIFT_OK) {
        return r;
    }
    r = drift__light_table_build(scene);
    if (r != DRIFT_OK) {
        return r;
    }
    scene->committed = true;
    return DRIFT_OK;
}

drift_bounds3 drift_mesh_bounds(const drift_mesh *mesh)
{
    drift_bounds3 bounds = drift_bounds3_empty();
    for (uint32_t v = 0; v < mesh->vertex_count; ++v) {
        const float *p = mesh->positions + 3 * (size_t)v;
        bounds = drift_bounds3_extend(bounds, drift_vec3_make(p[0], p[1], p[2]));
    }
    return bounds;
}

uint64_t drift_scene_triangle_count(const drift_scene *scene)
{
    uint64_t n = 0;
    for (uint32_t m = 0; m < scene->mesh_count; ++m) {
        n += scene->meshes[m].triangle_count;
    }
    return n;
}
