// drift info [SCENE]: loads a scene (the built-in Cornell box when none is given) and prints
// its triangle, mesh, material, light and texture counts, bounds and camera, as text or JSON.
#include "cli.h"
#include "drift/scene.h"
#include "drift/scene_io.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static void print_help(FILE *out)
{
    fprintf(out,
            "usage: drift info [options] [SCENE]\n"
            "\n"
            "Loads SCENE (.json, .obj, .gltf, .glb, .ply, optionally .gz; default: the built-in\n"
            "Cornell box) and prints its triangle, mesh, material, light (by type) and texture\n"
            "counts, its bounding box and its camera.\n"
            "\n"
            "options:\n"
            "  --json       machine-readable output (one JSON object on stdout)\n"
            "  --verbose    also print informational messages from the loader\n"
            "  -h, --help   this text\n"
            "\n"
            "Exit status: 0 success, 1 the scene could not be loaded, 2 usage error.\n");
}

static const char *const light_type_names[DRIFT_LIGHT_COUNT] = {
    "point", "spot", "directional", "quad", "disk", "sphere", "triangle",
};

// Writes s as a JSON string literal (names come from files and may hold anything).
static void print_json_string(const char *s)
{
    putchar('"');
    for (const unsigned char *p = (const unsigned char *)s; *p; ++p) {
        if (*p == '"' || *p == '\\') {
            printf("\\%c", *p);
        } else if (*p < 0x20) {
            printf("\\u%04x", *p);
        } else {
            putchar(*p);
        }
    }
    putchar('"');
}

static void print_vec3_json(drift_vec3 v)
{
    printf("[%.9g, %.9g, %.9g]", (double)v.x, (double)v.y, (double)v.z);
}

static void print_json(const char *path, const drift_scene *scene, const uint32_t *light_counts)
{
    const drift_camera *c = &scene->camera;
    printf("{\n  \"scene\": ");
    print_json_string(path);
    printf(",\n  \"triangles\": %llu,\n  \"meshes\": %u,\n  \"materials\": %u,\n",
           (unsigned long long)drift_scene_triangle_count(scene), scene->mesh_count,
           scene->material_count);
    printf("  \"lights\": { \"total\": %u", scene->light_count);
    for (int t = 0; t < DRIFT_LIGHT_COUNT; ++t) {
        printf(", \"%s\": %u", light_type_names[t], light_counts[t]);
    }
    printf(" },\n  \"textures\": %u,\n", scene->texture_count);
    printf("  \"environment\": { \"color\": ");
    print_vec3_json(scene->environment.color);
    printf(", \"textured\": %s },\n",
           scene->environment.texture != DRIFT_INVALID_INDEX ? "true" : "false");
    printf("  \"bounds\": { \"min\": ");
    print_vec3_json(scene->bounds.min);
    printf(", \"max\": ");
    print_vec3_json(scene->bounds.max);
    printf(" },\n  \"camera\": { \"position\": ");
    print_vec3_json(c->position);
    printf(", \"target\": ");
    print_vec3_json(c->target);
    printf(", \"up\": ");
    print_vec3_json(c->up);
    printf(", \"fov_y_degrees\": %.9g, \"aperture_radius\": %.9g, \"focus_distance\": %.9g, "
           "\"width\": %d, \"height\": %d }\n}\n",
           (double)(c->fov_y * 180.0f / DRIFT_PI), (double)c->aperture_radius,
           (double)c->focus_distance, c->width, c->height);
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
    bool json = false, verbose = false;
    const char *path = NULL;
    for (int i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "-h") == 0 || strcmp(argv[i], "--help") == 0) {
            print_help(stdout);
            return 0;
        } else if (strcmp(argv[i], "--json") == 0) {
            json = true;
        } else if (strcmp(argv[i], "--verbose") == 0) {
            verbose = true;
        } else if (argv[i][0] == '-' && argv[i][1] != '\0') {
            fprintf(stderr, "drift info: unknown option '%s' (see drift info --help)\n", argv[i]);
            return 2;
        } else if (path) {
            fprintf(stderr, "drift info: one scene at a time ('%s' and '%s' given)\n", path,
                    argv[i]);
            return 2;
        } else {
            path = argv[i];
        }
    }
    if (!path) {
        path = cli_default_scene_path();
    }
    drift_context *ctx = cli_open_context("info", 1, verbose);
    if (!ctx) {
        return 1;
    }
    drift_result r = DRIFT_OK;
    drift_scene *scene = NULL;
    r = drift_scene_load(ctx, path, &scene);
    if (r != DRIFT_OK) {
        fprintf(stderr, "drift info: cannot load '%s': %s\n", path, drift_result_string(r));
        drift_context_destroy(ctx);
        return 1;
    }
    uint32_t light_counts[DRIFT_LIGHT_COUNT] = { 0 };
    for (uint32_t i = 0; i < scene->light_count; ++i) {
        if ((unsigned)scene->lights[i].type < DRIFT_LIGHT_COUNT) {
            light_counts[scene->lights[i].type]++;
        }
    }
    if (json) {
        print_json(path, scene, light_counts);
    } else {
        print_text(path, scene, light_counts);
    }
    drift_scene_destroy(scene);
    drift_context_destroy(ctx);
    return 0;
}
