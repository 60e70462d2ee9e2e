// drift info [SCENE]: loads a scene (the built-in Cornell box when none is given) and prints
// its triangle, mesh, material, light and texture counts, bounds and camera, as text or JSON.
#include "cli.h"
#include "drift/scene.h"
#include "drift/scene_io.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

typedef struct info_options {
    const char *scene_path;
    bool json, verbose;
} info_options;

static const cli_option info_table[] = {
    CLI_SECTION("options:", 0),
    CLI_FLAG("--json", info_options, json, "machine-readable output (one JSON object on stdout)"),
    CLI_FLAG("--verbose", info_options, verbose,
             "also print informational messages from the loader"),
};

static const cli_command info_command = {
    .name = "info",
    .usage = "usage: drift info [options] [SCENE]\n"
             "\n"
             "Loads SCENE (a scene or mesh file, below; default: the built-in Cornell box) and\n"
             "prints its triangle, mesh, material, light (by type) and texture counts, its\n"
             "bounding box and its camera.\n"
             "\n",
    .epilogue = "\nExit status: 0 success, 1 the scene could not be loaded, 2 usage error.\n",
    CLI_TABLE(info_table),
    CLI_POSITIONAL("SCENE", info_options, scene_path, 1),
    .help_column = 15,
};

static const char *const light_type_names[DRIFT_LIGHT_COUNT] = {
    "point", "spot", "directional", "quad", "disk", "sphere", "triangle",
};

static void add_vec3(cJSON *object, const char *key, drift_vec3 v)
{
    cli_json_vec3(object, key, v.x, v.y, v.z);
}

static bool print_json(const char *path, const drift_scene *scene, const uint32_t *light_counts)
{
    const drift_camera *c = &scene->camera;
    cJSON *root = cJSON_CreateObject();
    cJSON_AddStringToObject(root, "scene", path);
    cli_json_count(root, "triangles", drift_scene_triangle_count(scene));
    cli_json_count(root, "meshes", scene->mesh_count);
    cli_json_count(root, "materials", scene->material_count);
    cJSON *lights = cJSON_AddObjectToObject(root, "lights");
    cli_json_count(lights, "total", scene->light_count);
    for (int t = 0; t < DRIFT_LIGHT_COUNT; ++t) {
        cli_json_count(lights, light_type_names[t], light_counts[t]);
    }
    cli_json_count(root, "textures", scene->texture_count);
    cJSON *environment = cJSON_AddObjectToObject(root, "environment");
    add_vec3(environment, "color", scene->environment.color);
    cJSON_AddBoolToObject(environment, "textured",
                          scene->environment.texture != DRIFT_INVALID_INDEX);
    cJSON *bounds = cJSON_AddObjectToObject(root, "bounds");
    add_vec3(bounds, "min", scene->bounds.min);
    add_vec3(bounds, "max", scene->bounds.max);
    cJSON_AddNumberToObject(root, "extent", (double)drift_scene_extent(scene));
    cJSON *camera = cJSON_AddObjectToObject(root, "camera");
    add_vec3(camera, "position", c->position);
    add_vec3(camera, "target", c->target);
    add_vec3(camera, "up", c->up);
    cli_json_float(camera, "fov_y_degrees", c->fov_y * 180.0f / DRIFT_PI);
    cli_json_float(camera, "aperture_radius", c->aperture_radius);
    cli_json_float(camera, "focus_distance", c->focus_distance);
    cJSON_AddNumberToObject(camera, "width", c->width);
    cJSON_AddNumberToObject(camera, "height", c->height);
    return cli_json_write("info", root, NULL);
}

static void print_text(const char *path, const drift_scene *scene, const uint32_t *light_counts)
{
    const drift_camera *c = &scene->camera;
    printf("scene      %s\n", path);
    printf("triangles  %llu\n", (unsigned long long)drift_scene_triangle_count(scene));
    printf("meshes     %u\n", scene->mesh_count);
    printf("materials  %u\n", scene->material_count);
    printf("lights     %u", scene->light_count);
    const char *sep = " (";
    for (int t = 0; t < DRIFT_LIGHT_COUNT; ++t) {
        if (light_counts[t]) {
            printf("%s%u %s", sep, light_counts[t], light_type_names[t]);
            sep = ", ";
        }
    }
    printf("%s\n", scene->light_count ? ")" : "");
    printf("textures   %u\n", scene->texture_count);
    if (scene->environment.texture != DRIFT_INVALID_INDEX) {
        printf("environment  map (texture %u) x (%g %g %g)\n", scene->environment.texture,
               (double)scene->environment.color.x, (double)scene->environment.color.y,
               (double)scene->environment.color.z);
    } else {
        printf("environment  (%g %g %g)\n", (double)scene->environment.color.x,
               (double)scene->environment.color.y, (double)scene->environment.color.z);
    }
    printf("bounds     (%g %g %g) - (%g %g %g)\n", (double)scene->bounds.min.x,
           (double)scene->bounds.min.y, (double)scene->bounds.min.z, (double)scene->bounds.max.x,
           (double)scene->bounds.max.y, (double)scene->bounds.max.z);
    // The length scale the techniques' defaults are fractions of (drift_scene_extent).
    printf("extent     %g (the diagonal of the reflecting meshes)\n",
           (double)drift_scene_extent(scene));
    printf("camera     position (%g %g %g) target (%g %g %g) up (%g %g %g)\n",
           (double)c->position.x, (double)c->position.y, (double)c->position.z, (double)c->target.x,
           (double)c->target.y, (double)c->target.z, (double)c->up.x, (double)c->up.y,
           (double)c->up.z);
    printf("           fov_y %.4g deg, %dx%d", (double)(c->fov_y * 180.0f / DRIFT_PI), c->width,
           c->height);
    if (c->aperture_radius > 0.0f) {
        printf(", aperture radius %g, focus distance %g", (double)c->aperture_radius,
               (double)c->focus_distance);
    }
    printf("\n");
}

int drift_cmd_info(int argc, char **argv)
{
    info_options o = { 0 };
    int status = cli_parse(&info_command, argc, argv, &o, NULL);
    if (status != CLI_PARSED) {
        return cli_parse_exit(status);
    }
    cli_session session;
    if (!cli_session_open(&(cli_session_desc){ .cmd = "info",
                                               .scene_path = o.scene_path,
                                               .threads = 1,
                                               .verbose = o.verbose,
                                               .no_accel = true },
                          &session)) {
        cli_session_close(&session);
        return 1;
    }
    const drift_scene *scene = session.scene;
    uint32_t light_counts[DRIFT_LIGHT_COUNT] = { 0 };
    for (uint32_t i = 0; i < scene->light_count; ++i) {
        if ((unsigned)scene->lights[i].type < DRIFT_LIGHT_COUNT) {
            light_counts[scene->lights[i].type]++;
        }
    }
    int exit_code = 0;
    if (o.json) {
        exit_code = print_json(session.scene_path, scene, light_counts) ? 0 : 1;
    } else {
        print_text(session.scene_path, scene, light_counts);
    }
    cli_session_close(&session);
    return exit_code;
}
