// test_scene_io, part: gzip, transforms, every light type, glTF, Mitsuba, shared textures and
// camera views (the test list is in tests/unit/test_scene_io.c).
#include "scene_io_tests.h"

// --- FEATURES ---

static void gzip_file(const char *src, const char *dst)
{
    FILE *in = fopen(src, "rb");
    assert_non_null(in);
    gzFile out = gzopen(dst, "wb");
    assert_non_null(out);
    char buf[4096];
    size_t n;
    while ((n = fread(buf, 1, sizeof(buf), in)) > 0) {
        assert_int_equal(gzwrite(out, buf, (unsigned)n), (int)n);
    }
    fclose(in);
    gzclose(out);
}

void test_scene_io_gzip(void **state)
{
    (void)state;
    char src[1024], dst[1024];
    test_repo_path(src, "scenes/cornell-box/cornell_box.obj");
    test_out_path(dst, "scene_io_box.OBJ.gz");
    gzip_file(src, dst);
    located_log log;
    drift_context *ctx = located_context(&log);
    drift_scene *scene = NULL;
    assert_int_equal(drift_scene_load(ctx, dst, &scene), DRIFT_OK);
    // From memory the .mtl is not found, so there is no emitter: the default light is added.
    assert_int_equal(drift_scene_triangle_count(scene), 32);
    assert_int_equal(scene->light_count, 1);
    assert_int_equal(scene->lights[0].type, DRIFT_LIGHT_DIRECTIONAL);
    drift_scene_destroy(scene);

    // A truncated gzip stream is an error, not a short mesh.
    FILE *f = fopen(dst, "rb");
    char data[8192];
    size_t n = fread(data, 1, sizeof(data), f);
    fclose(f);
    test_out_path(dst, "scene_io_truncated.obj.gz");
    f = fopen(dst, "wb");
    fwrite(data, 1, n / 2, f);
    fclose(f);
    scene = NULL;
    assert_int_equal(drift_scene_load(ctx, dst, &scene), DRIFT_ERR_PARSE);
    assert_null(scene);

    // A gzipped scene file.
    char json_src[1024];
    test_out_path(json_src, "scene_io_plain.json");
    write_file(json_src,
               "{ \"environment\": { \"color\": 0.5 },\n"
               "  \"lights\": [ { \"type\": \"sphere\", \"center\": [0,0,0], \"radius\": 1,"
               " \"radiance\": 2 } ] }\n");
    test_out_path(dst, "scene_io_scene.json.gz");
    gzip_file(json_src, dst);
    assert_int_equal(drift_scene_load(ctx, dst, &scene), DRIFT_OK);
    assert_int_equal(scene->light_count, 1);
    assert_float_equal(scene->environment.color.y, 0.5f, 1e-6f);
    drift_scene_destroy(scene);
    drift_context_destroy(ctx);
}

static drift_scene *load_text(drift_context *ctx, const char *text)
{
    char dir[1024];
    drift_scene *scene = NULL;
    drift_result r =
        drift_scene_load_json_text(ctx, text, strlen(text), scenes_dir(dir), "t.json", &scene);
    if (r != DRIFT_OK) {
        fail_msg("load: %s", drift_result_string(r));
    }
    return scene;
}

void test_scene_io_transforms_and_overrides(void **state)
{
    (void)state;
    located_log log;
    drift_context *ctx = located_context(&log);
    // Scale 2 then translate: x in [1000, 1000 + 2 * 556].
    drift_scene *scene =
        load_text(ctx, "{\"meshes\": [{\"path\": \"cornell_box.obj\", \"transform\": "
                       "{\"translate\": [1000, 0, 0], \"scale\": 2}}]}");
    assert_float_equal(scene->bounds.min.x, 1000.0f, 1e-2f);
    assert_float_equal(scene->bounds.max.x, 1000.0f + 2.0f * 556.0f, 1e-2f);
    assert_float_equal(scene->bounds.max.y, 2.0f * 548.8f, 1e-2f);
    drift_scene_destroy(scene);

    // Rotating 90 degrees about +y maps (x, z) to (z, -x).
    scene = load_text(ctx, "{\"meshes\": [{\"path\": \"cornell_box.obj\", \"transform\": "
                           "{\"rotate\": {\"axis\": [0, 1, 0], \"degrees\": 90}}}]}");
    assert_float_equal(scene->bounds.min.x, 0.0f, 1e-2f);
    assert_float_equal(scene->bounds.max.x, 559.2f, 1e-2f);
    assert_float_equal(scene->bounds.min.z, -556.0f, 1e-2f);
    assert_float_equal(scene->bounds.max.z, 0.0f, 1e-2f);
    drift_scene_destroy(scene);

    // A row-major matrix: the same translation as the first case; a mirror keeps the
    // emitter facing down (winding flipped back), so it still gives two lights.
    scene = load_text(ctx, "{\"meshes\": [{\"path\": \"cornell_box.obj\", \"transform\": "
                           "{\"matrix\": [-1,0,0,1000, 0,1,0,0, 0,0,1,0, 0,0,0,1]}}]}");
    assert_float_equal(scene->bounds.min.x, 1000.0f - 556.0f, 1e-2f);
    assert_float_equal(scene->bounds.max.x, 1000.0f, 1e-2f);
    assert_int_equal(scene->light_count, 2);
    for (uint32_t m = 0; m < scene->mesh_count; ++m) {
        const drift_mesh *mesh = &scene->meshes[m];
        if (!drift_vec3_is_zero(scene->materials[mesh->material].emission)) {
            const float *p = mesh->positions;
            const uint32_t *t = mesh->indices;
            drift_vec3 a = { p[3 * t[0]], p[3 * t[0] + 1], p[3 * t[0] + 2] };
            drift_vec3 b = { p[3 * t[1]], p[3 * t[1] + 1], p[3 * t[1] + 2] };
            drift_vec3 c = { p[3 * t[2]], p[3 * t[2] + 1], p[3 * t[2] + 2] };
            drift_vec3 n = drift_vec3_cross(drift_vec3_sub(b, a), drift_vec3_sub(c, a));
            assert_true(n.y < 0.0f);
        }
    }
    drift_scene_destroy(scene);

    // A material override replaces every material of the file, emission included.
    scene =
        load_text(ctx, "{\"materials\": {\"grey\": {\"diffuse\": 0.5},\n"
                       "               \"chrome\": {\"type\": \"mirror\", \"specular\": 0.9}},\n"
                       " \"meshes\": [{\"path\": \"cornell_box.obj\", \"material\": \"chrome\"}],\n"
                       " \"lights\": [{\"type\": \"directional\", \"direction\": [0,-1,0],"
                       " \"irradiance\": 3}]}");
    uint32_t chrome = DRIFT_INVALID_INDEX;
    for (uint32_t i = 0; i < scene->material_count; ++i) {
        if (strcmp(scene->materials[i].name, "chrome") == 0) {
            chrome = i;
        }
    }
    assert_int_not_equal(chrome, DRIFT_INVALID_INDEX);
    assert_int_equal(scene->materials[chrome].type, DRIFT_MATERIAL_MIRROR);
    for (uint32_t m = 0; m < scene->mesh_count; ++m) {
        assert_int_equal(scene->meshes[m].material, chrome);
    }
    assert_int_equal(scene->light_count, 1);
    drift_scene_destroy(scene);
    assert_int_equal(log.errors, 0);
    drift_context_destroy(ctx);
}

void test_scene_io_every_light_type(void **state)
{
    (void)state;
    located_log log;
    drift_context *ctx = located_context(&log);
    drift_scene *scene = load_text(
        ctx,
        "{\"camera\": {\"position\": [0,1,5], \"target\": [0,1,0], \"fov_y\": 50,"
        "  \"aperture_radius\": 0.1, \"focus_distance\": 5, \"width\": 320, \"height\": 200},\n"
        " \"lights\": [\n"
        "  {\"type\": \"point\", \"position\": [0,2,0], \"intensity\": [1,2,3]},\n"
        "  {\"type\": \"spot\", \"position\": [0,2,0], \"direction\": [0,-1,0], \"intensity\": 4,"
        "   \"inner_angle\": 20, \"outer_angle\": 30},\n"
        "  {\"type\": \"directional\", \"direction\": [0,-2,0], \"irradiance\": 1},\n"
        "  {\"type\": \"quad\", \"corner\": [0,3,0], \"edge_u\": [1,0,0], \"edge_v\": [0,0,1],"
        "   \"radiance\": 5},\n"
        "  {\"type\": \"disk\", \"center\": [0,3,0], \"normal\": [0,-1,0], \"radius\": 0.5,"
        "   \"radiance\": 5},\n"
        "  {\"type\": \"sphere\", \"center\": [2,2,2], \"radius\": 0.25, \"radiance\": 5}],\n"
        " \"environment\": {\"color\": [0.1, 0.2, 0.3]}}");
    assert_int_equal(scene->light_count, 6);
    for (int t = 0; t < 6; ++t) {
        assert_int_equal(scene->lights[t].type, (drift_light_type)t);
    }
    assert_float_equal(scene->lights[1].spot_outer, 30.0f * DRIFT_PI / 180.0f, 1e-6f);
    assert_float_equal(scene->lights[1].spot_inner, 20.0f * DRIFT_PI / 180.0f, 1e-6f);
    assert_float_equal(scene->lights[2].direction.y, -1.0f, 1e-6f);
    assert_float_equal(scene->camera.fov_y, 50.0f * DRIFT_PI / 180.0f, 1e-6f);
    assert_int_equal(scene->camera.width, 320);
    assert_int_equal(scene->camera.height, 200);
    assert_float_equal(scene->camera.aperture_radius, 0.1f, 1e-7f);
    assert_float_equal(scene->environment.color.z, 0.3f, 1e-7f);
    drift_scene_destroy(scene);
    assert_int_equal(log.errors, 0);
    drift_context_destroy(ctx);
}

// A one-triangle glTF with a camera at (0,0,5) (yfov 0.8, aspect 1.5), a point light at
// (1,2,3) and a spot light at (0,4,0) turned to point down.
static const char gltf_text[] =
    "{\"asset\": {\"version\": \"2.0\"}, \"extensionsUsed\": [\"KHR_lights_punctual\"],"
    " \"extensions\": {\"KHR_lights_punctual\": {\"lights\": ["
    "  {\"type\": \"point\", \"color\": [1, 0.5, 0.25], \"intensity\": 10, \"name\": \"lamp\"},"
    "  {\"type\": \"spot\", \"color\": [1, 1, 1], \"intensity\": 5, \"name\": \"spot\","
    "   \"spot\": {\"innerConeAngle\": 0.2, \"outerConeAngle\": 0.5}}]}},"
    " \"scene\": 0, \"scenes\": [{\"nodes\": [0, 1, 2, 3]}],"
    " \"nodes\": [{\"mesh\": 0, \"name\": \"tri\"},"
    "  {\"camera\": 0, \"translation\": [0, 0, 5], \"name\": \"cam\"},"
    "  {\"translation\": [1, 2, 3], \"name\": \"lampnode\","
    "   \"extensions\": {\"KHR_lights_punctual\": {\"light\": 0}}},"
    "  {\"translation\": [0, 4, 0], \"rotation\": [-0.7071068, 0, 0, 0.7071068],"
    "   \"name\": \"spotnode\", \"extensions\": {\"KHR_lights_punctual\": {\"light\": 1}}}],"
    " \"cameras\": [{\"type\": \"perspective\","
    "  \"perspective\": {\"yfov\": 0.8, \"aspectRatio\": 1.5, \"znear\": 0.1}}],"
    " \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0}, \"indices\": 1,"
    "  \"material\": 0}]}],"
    " \"materials\": [{\"pbrMetallicRoughness\": {\"baseColorFactor\": [0.2, 0.4, 0.6, 1]},"
    "  \"emissiveFactor\": [1, 1, 1]}],"
    " \"buffers\": [{\"byteLength\": 44, \"uri\": \"data:application/octet-stream;base64,"
    "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAABAAIAAAA=\"}],"
    " \"bufferViews\": [{\"buffer\": 0, \"byteOffset\": 0, \"byteLength\": 36},"
    "  {\"buffer\": 0, \"byteOffset\": 36, \"byteLength\": 6}],"
    " \"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 3, \"type\": "
    "\"VEC3\","
    "  \"min\": [0, 0, 0], \"max\": [1, 1, 0]},"
    "  {\"bufferView\": 1, \"componentType\": 5123, \"count\": 3, \"type\": \"SCALAR\"}]}";

void test_scene_io_gltf_camera_lights_emission(void **state)
{
    (void)state;
    char path[1024];
    test_out_path(path, "scene_io_triangle.gltf");
    write_file(path, gltf_text);
    located_log log;
    drift_context *ctx = located_context(&log);
    drift_scene *scene = NULL;
    assert_int_equal(drift_scene_load(ctx, path, &scene), DRIFT_OK);
    const drift_camera *cam = &scene->camera;
    assert_float_equal(cam->position.z, 5.0f, 1e-5f);
    assert_float_equal(cam->target.z, 4.0f, 1e-5f); // looks down -z
    assert_float_equal(cam->fov_y, 0.8f, 1e-5f);
    assert_int_equal(cam->width, 768);
    assert_int_equal(cam->height, 512);
    uint32_t point = 0, spot = 0, triangle = 0;
    for (uint32_t i = 0; i < scene->light_count; ++i) {
        const drift_light *l = &scene->lights[i];
        if (l->type == DRIFT_LIGHT_POINT) {
            point++;
            assert_float_equal(l->position.y, 2.0f, 1e-5f);
            assert_float_equal(l->color.y, 5.0f / 683.0f, 1e-7f); // 10 cd × 0.5 → W/sr
        } else if (l->type == DRIFT_LIGHT_SPOT) {
            spot++;
            assert_float_equal(l->direction.y, -1.0f, 1e-5f);
            assert_float_equal(l->spot_outer, 0.5f, 1e-6f);
            assert_float_equal(l->spot_inner, 0.2f, 1e-6f);
        } else if (l->type == DRIFT_LIGHT_TRIANGLE) {
            triangle++;
        }
    }
    assert_int_equal(point, 1);
    assert_int_equal(spot, 1);
    assert_int_equal(triangle, 1); // the emissive material
    drift_scene_destroy(scene);
    drift_context_destroy(ctx);
}

static const drift_material *material_named(const drift_scene *scene, const char *name)
{
    for (uint32_t i = 0; i < scene->material_count; ++i) {
        if (strcmp(scene->materials[i].name, name) == 0) {
            return &scene->materials[i];
        }
    }
    fail_msg("no material '%s'", name);
    return NULL;
}

// tests/data/gltf/blender_scene.gltf (Blender's exporter conventions): Blender's watts come
// back as radiant intensity (the exporter's cd = W·683/4π, so W/sr = W/4π), the spot cone is
// Blender's half spot size, the metallic-roughness rule gives the documented diffuse, F0 and
// exponent, and KHR_materials_emissive_strength scales the emission.
void test_scene_io_gltf_photometry_and_materials(void **state)
{
    (void)state;
    char path[1024];
    test_repo_path(path, "tests/data/gltf/blender_scene.gltf");
    located_log log;
    drift_context *ctx = located_context(&log);
    drift_scene *scene = NULL;
    assert_int_equal(drift_scene_load(ctx, path, &scene), DRIFT_OK);
    assert_int_equal(log.errors, 0);
    uint32_t point = 0, spot = 0;
    for (uint32_t i = 0; i < scene->light_count; ++i) {
        const drift_light *l = &scene->lights[i];
        if (l->type == DRIFT_LIGHT_POINT) {
            point++;
            assert_float_equal(l->color.x, 1000.0f / (4.0f * DRIFT_PI), 1e-3f);
            assert_float_equal(l->position.y, 4.0f, 1e-5f);
        } else if (l->type == DRIFT_LIGHT_SPOT) {
            spot++;
            assert_float_equal(l->color.x, 800.0f / (4.0f * DRIFT_PI), 1e-3f);
            assert_float_equal(l->color.z, 0.9f * 800.0f / (4.0f * DRIFT_PI), 1e-3f);
            assert_float_equal(l->spot_outer, 30.0f * DRIFT_PI / 180.0f, 1e-5f);
            assert_float_equal(l->spot_inner, 0.85f * 30.0f * DRIFT_PI / 180.0f, 1e-5f);
            // Aimed from (-3, 5, 0) at the origin.
            assert_float_equal(l->direction.x, 3.0f / sqrtf(34.0f), 1e-4f);
            assert_float_equal(l->direction.y, -5.0f / sqrtf(34.0f), 1e-4f);
        }
    }
    assert_int_equal(point, 1);
    assert_int_equal(spot, 1);
    // Red: base (0.8, 0.05, 0.05), metallic 0, roughness 0.3: a GGX plastic of the base with
    // alpha = 0.09 and F0 = 0.04; its Phong equivalent n = (2/α² − 2)/4.
    const drift_material *red = material_named(scene, "Red");
    assert_int_equal(red->type, DRIFT_MATERIAL_GGX);
    assert_float_equal(red->diffuse.x, 0.8f, 1e-6f);
    assert_float_equal(red->diffuse.y, 0.05f, 1e-6f);
    assert_float_equal(red->ggx.alpha, 0.09f, 1e-6f);
    assert_float_equal(red->ggx.metallic, 0.0f, 0.0f);
    assert_float_equal(red->specular.x, 0.04f, 1e-6f);
    float alpha = 0.3f * 0.3f;
    assert_float_equal(red->exponent, 0.25f * (2.0f / (alpha * alpha) - 2.0f), 1e-2f);
    const drift_material *panel = material_named(scene, "Panel");
    assert_float_equal(panel->emission.x, 4.0f, 1e-6f);
    assert_float_equal(panel->emission.z, 2.8f, 1e-6f);
    drift_scene_destroy(scene);
    drift_context_destroy(ctx);
}

// gltf_text with a metal that has a normal texture, extensions drift ignores, a light range
// and a second camera ("side", on a node at x = 7).
static const char gltf_cameras_text[] =
    "{\"asset\": {\"version\": \"2.0\"}, \"extensionsUsed\": [\"KHR_lights_punctual\","
    "  \"KHR_materials_clearcoat\", \"KHR_materials_sheen\"],"
    " \"extensions\": {\"KHR_lights_punctual\": {\"lights\": ["
    "  {\"type\": \"point\", \"color\": [1, 1, 1], \"intensity\": 683, \"range\": 3}]}},"
    " \"scene\": 0, \"scenes\": [{\"nodes\": [0, 1, 2, 3]}],"
    " \"nodes\": [{\"mesh\": 0, \"name\": \"tri\"},"
    "  {\"camera\": 0, \"translation\": [0, 0, 5], \"name\": \"cam\"},"
    "  {\"camera\": 1, \"translation\": [7, 0, 0], \"name\": \"sidenode\"},"
    "  {\"translation\": [1, 2, 3], \"name\": \"lampnode\","
    "   \"extensions\": {\"KHR_lights_punctual\": {\"light\": 0}}}],"
    " \"cameras\": [{\"type\": \"perspective\", \"name\": \"front\","
    "  \"perspective\": {\"yfov\": 0.8, \"aspectRatio\": 1.5, \"znear\": 0.1}},"
    "  {\"type\": \"perspective\", \"name\": \"side\","
    "  \"perspective\": {\"yfov\": 0.5, \"aspectRatio\": 1, \"znear\": 0.1}}],"
    " \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0}, \"indices\": 1,"
    "  \"material\": 0}]}],"
    " \"materials\": [{\"name\": \"metal\", \"normalTexture\": {\"index\": 0},"
    "  \"pbrMetallicRoughness\": {\"baseColorFactor\": [0.2, 0.4, 0.6, 1],"
    "  \"metallicFactor\": 1, \"roughnessFactor\": 0}}],"
    " \"textures\": [{\"source\": 0}], \"images\": [{\"uri\": \"normal.png\"}],"
    " \"buffers\": [{\"byteLength\": 44, \"uri\": \"data:application/octet-stream;base64,"
    "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAABAAIAAAA=\"}],"
    " \"bufferViews\": [{\"buffer\": 0, \"byteOffset\": 0, \"byteLength\": 36},"
    "  {\"buffer\": 0, \"byteOffset\": 36, \"byteLength\": 6}],"
    " \"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 3, \"type\": "
    "\"VEC3\", \"min\": [0, 0, 0], \"max\": [1, 1, 0]},"
    "  {\"bufferView\": 1, \"componentType\": 5123, \"count\": 3, \"type\": \"SCALAR\"}]}";

// One warning per ignored extension and feature; cameras chosen by name or index through a
// scene file; an unknown camera is an error naming the file.
void test_scene_io_gltf_extensions_and_cameras(void **state)
{
    (void)state;
    char gltf_path[1024], json_path[1024];
    test_out_path(gltf_path, "scene_io_cameras.gltf");
    write_file(gltf_path, gltf_cameras_text);
    located_log log;
    drift_context *ctx = located_context(&log);
    drift_scene *scene = NULL;
    assert_int_equal(drift_scene_load(ctx, gltf_path, &scene), DRIFT_OK);
    assert_int_equal(log.errors, 0);
    assert_null(strstr(log.text, "KHR_materials_clearcoat")); // read since issue 41's s4b
    assert_non_null(strstr(log.text, "KHR_materials_sheen is not supported"));
    assert_non_null(strstr(log.text, "normal texture not loaded; ignored"));
    assert_non_null(strstr(log.text, "range ignored"));
    assert_float_equal(scene->camera.position.z, 5.0f, 1e-5f); // the first camera
    assert_int_equal(scene->lights[0].type, DRIFT_LIGHT_POINT);
    assert_float_equal(scene->lights[0].color.x, 1.0f, 1e-6f); // 683 cd = 1 W/sr
    // The metal: a smooth GGX conductor of F0 = its base colour (its Phong equivalent
    // reflects the base colour).
    const drift_material *m = &scene->materials[0];
    assert_int_equal(m->type, DRIFT_MATERIAL_GGX);
    assert_float_equal(m->ggx.metallic, 1.0f, 0.0f);
    assert_float_equal(m->ggx.alpha, 0.0f, 0.0f);
    assert_float_equal(m->specular.y, 0.4f, 1e-6f);
    assert_float_equal(m->diffuse.y, 0.4f, 1e-6f);
    drift_scene_destroy(scene);

    const char *selectors[] = { "side", "1", "front", "0" };
    const float eye_x[] = { 7.0f, 7.0f, 0.0f, 0.0f };
    for (int i = 0; i < 4; ++i) {
        char json[1024];
        snprintf(json, sizeof(json),
                 "{\"version\": 1, \"meshes\": [{\"path\": \"scene_io_cameras.gltf\","
                 " \"camera\": \"%s\"}]}",
                 selectors[i]);
        test_out_path(json_path, "scene_io_cameras.json");
        write_file(json_path, json);
        assert_int_equal(drift_scene_load(ctx, json_path, &scene), DRIFT_OK);
        assert_float_equal(scene->camera.position.x, eye_x[i], 1e-5f);
        drift_scene_destroy(scene);
    }
    log = (located_log){ 0 };
    write_file(json_path, "{\"version\": 1, \"meshes\": [{\"path\": \"scene_io_cameras.gltf\","
                          " \"camera\": \"top\"}]}");
    assert_int_equal(drift_scene_load(ctx, json_path, &scene), DRIFT_ERR_INVALID_ARGUMENT);
    assert_null(scene);
    assert_non_null(strstr(log.text, "no camera named or numbered 'top'"));
    assert_non_null(strstr(log.text, "scene_io_cameras.gltf"));
    drift_context_destroy(ctx);
}

// A Mitsuba scene with every supported element (the line numbers of the warnings are checked,
// so keep its lines as they are).
static const char mitsuba_text[] =
    "<?xml version='1.0'?>\n"                                                        // 1
    "<scene version=\"0.5.0\">\n"                                                    // 2
    " <sensor type=\"perspective\"><float name=\"fov\" value=\"60\"/>\n"             // 3
    "  <transform name=\"toWorld\"><lookat origin=\"0,1,5\" target=\"0,1,0\""        //
    " up=\"0,1,0\"/></transform>\n"                                                  // 4
    "  <film type=\"hdrfilm\"><integer name=\"width\" value=\"64\"/>"                //
    "<integer name=\"height\" value=\"48\"/></film></sensor>\n"                      // 5
    " <bsdf type=\"twosided\" id=\"wall\"><bsdf type=\"diffuse\">"                   //
    "<rgb name=\"reflectance\" value=\"0.2, 0.4, 0.6\"/></bsdf></bsdf>\n"            // 6
    " <bsdf type=\"roughplastic\" id=\"coat\"><float name=\"alpha\" value=\"0.3\"/>" //
    "<spectrum name=\"diffuseReflectance\" value=\"0.5\"/></bsdf>\n"                 // 7
    " <bsdf type=\"conductor\" id=\"mirror\"/>\n"                                    // 8
    " <bsdf type=\"dielectric\" id=\"glass\"/>\n"                                    // 9
    " <medium type=\"homogeneous\" id=\"fog\"/>\n"                                   // 10
    " <shape type=\"rectangle\"><transform name=\"toWorld\"><scale value=\"2\"/>"    //
    "<translate z=\"-1\"/></transform><ref id=\"wall\"/></shape>\n"                  // 11
    " <shape type=\"cube\"><bsdf type=\"roughconductor\"><float name=\"alpha\""      //
    " value=\"0.1\"/></bsdf><transform name=\"toWorld\"><scale value=\"0.5\"/>"      //
    "</transform></shape>\n"                                                         // 12
    " <shape type=\"sphere\"><point name=\"center\" x=\"3\" y=\"0\" z=\"0\"/>"       //
    "<float name=\"radius\" value=\"0.25\"/><emitter type=\"area\">"                 //
    "<rgb name=\"radiance\" value=\"10, 10, 10\"/></emitter></shape>\n"              // 13
    " <shape type=\"sphere\"><ref id=\"glass\"/></shape>\n"                          // 14
    " <emitter type=\"point\"><point name=\"position\" x=\"0\" y=\"4\" z=\"0\"/>"    //
    "<spectrum name=\"intensity\" value=\"5\"/></emitter>\n"                         // 15
    " <emitter type=\"spot\"><float name=\"cutoffAngle\" value=\"30\"/>"             //
    "<transform name=\"toWorld\"><lookat origin=\"0,4,0\" target=\"0,0,0\""          //
    " up=\"0,0,1\"/></transform></emitter>\n"                                        // 16
    " <emitter type=\"constant\"><rgb name=\"radiance\" value=\"0.1,0.2,0.3\"/></emitter>\n"
    " <emitter type=\"sunsky\"/>\n" // 18
    "</scene>\n";

static const drift_light *light_of_type(const drift_scene *scene, drift_light_type type)
{
    for (uint32_t i = 0; i < scene->light_count; ++i) {
        if (scene->lights[i].type == type) {
            return &scene->lights[i];
        }
    }
    fail_msg("no light of type %d", (int)type);
    return NULL;
}

void test_scene_io_mitsuba_subset(void **state)
{
    (void)state;
    char path[1024];
    test_out_path(path, "scene_io_mitsuba.xml");
    write_file(path, mitsuba_text);
    located_log log;
    drift_context *ctx = located_context(&log);
    drift_scene *scene = NULL;
    assert_int_equal(drift_scene_load(ctx, path, &scene), DRIFT_OK);
    assert_int_equal(log.errors, 0);
    // fovAxis x (the default): 60° across 64 pixels is 2 atan(tan 30° · 48/64) vertically.
    assert_float_equal(scene->camera.fov_y, 2.0f * atanf(tanf(DRIFT_PI / 6.0f) * 0.75f), 1e-5f);
    assert_int_equal(scene->camera.width, 64);
    assert_float_equal(scene->camera.position.z, 5.0f, 1e-5f);
    assert_float_equal(scene->camera.target.y, 1.0f, 1e-5f);
    const drift_material *wall = material_named(scene, "wall");
    assert_float_equal(wall->diffuse.y, 0.4f, 1e-6f);
    const drift_material *coat = material_named(scene, "coat");
    // roughplastic: a GGX plastic of the file's alpha (0.3) and IOR 1.49 / 1.000277.
    assert_int_equal(coat->type, DRIFT_MATERIAL_GGX);
    assert_float_equal(coat->diffuse.x, 0.5f, 1e-6f);
    assert_float_equal(coat->ggx.alpha, 0.3f, 1e-6f);
    assert_float_equal(coat->ggx.ior, 1.49f / 1.000277f, 1e-5f);
    assert_float_equal(coat->exponent, 0.25f * (2.0f / 0.09f - 2.0f), 1e-3f);
    // dielectric: a smooth GGX dielectric that refracts (bk7 inside, air outside).
    const drift_material *glass = material_named(scene, "glass");
    assert_int_equal(glass->type, DRIFT_MATERIAL_GGX);
    assert_float_equal(glass->ggx.transmission, 1.0f, 0.0f);
    assert_float_equal(glass->ggx.ior, 1.5046f / 1.000277f, 1e-5f);
    assert_int_equal(material_named(scene, "mirror")->type, DRIFT_MATERIAL_MIRROR);
    // The rectangle, scaled by 2 then moved to z = -1: corners at ±2.
    assert_float_equal(scene->bounds.min.z, -1.0f, 1e-5f);
    assert_float_equal(scene->bounds.min.x, -2.0f, 1e-5f);
    const drift_light *sun = light_of_type(scene, DRIFT_LIGHT_SPHERE);
    assert_float_equal(sun->radius, 0.25f, 1e-6f);
    assert_float_equal(sun->position.x, 3.0f, 1e-6f);
    assert_float_equal(light_of_type(scene, DRIFT_LIGHT_POINT)->color.x, 5.0f, 0.0f);
    const drift_light *spot = light_of_type(scene, DRIFT_LIGHT_SPOT);
    assert_float_equal(spot->spot_outer, DRIFT_PI / 6.0f, 1e-6f);
    assert_float_equal(spot->direction.y, -1.0f, 1e-5f);
    assert_float_equal(scene->environment.color.z, 0.3f, 1e-6f);
    // Warnings name the element and its line: the medium (10), sunsky (18).
    assert_non_null(strstr(log.text, "<medium type=homogeneous> is not supported"));
    assert_non_null(strstr(log.text, "<emitter type=sunsky> is not a supported emitter"));
    assert_int_equal(log.min_warning_line, 10);
    drift_scene_destroy(scene);

    // Errors name the file and the line.
    static const struct {
        const char *text, *message;
        int line;
    } bad[] = {
        { "<scene>\n <shape type=\"hair\"/>\n</scene>\n", "unknown shape type", 2 },
        { "<scene>\n\n <shape type=\"cube\"><ref id=\"nope\"/></shape>\n</scene>\n",
          "unknown bsdf id", 3 },
        { "<scene>\n <shape type=\"cube\">\n</scene>\n", "malformed Mitsuba XML", 3 },
        { "<scene>\n <shape type=\"obj\"><string name=\"filename\" value=\"none.obj\"/>"
          "</shape>\n</scene>\n",
          "none.obj", 2 },
        { "<scene>\n <shape type=\"rectangle\"><transform name=\"toWorld\">"
          "<matrix value=\"1 2 3\"/></transform></shape>\n</scene>\n",
          "16 numbers", 2 },
        { "<scene>\n <sensor type=\"perspective\"><float name=\"fov\" value=\"wide\"/>"
          "</sensor>\n</scene>\n",
          "expected a number", 2 },
        { "<scene/>\n", "no shapes", 1 },
    };

    for (size_t i = 0; i < sizeof(bad) / sizeof(bad[0]); ++i) {
        write_file(path, bad[i].text);
        log = (located_log){ 0 };
        assert_int_not_equal(drift_scene_load(ctx, path, &scene), DRIFT_OK);
        assert_null(scene);
        if (!strstr(log.text, bad[i].message) || log.first_error_line != bad[i].line ||
            !strstr(log.located_error_file, "scene_io_mitsuba.xml")) {
            fail_msg("case %zu: line %d, file '%s': %s", i, log.first_error_line,
                     log.located_error_file, log.text);
        }
    }
    drift_context_destroy(ctx);
}

// Mitsuba's faceNormals shades a mesh flat: the OBJ's vertex normals are dropped for the
// shape that sets it and kept for the one that does not.
void test_scene_io_mitsuba_face_normals(void **state)
{
    (void)state;
    char obj[1024], xml[1024];
    test_out_path(obj, "scene_io_face_normals.obj");
    write_file(obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0.6 0 0.8\nf 1//1 2//1 3//1\n");
    test_out_path(xml, "scene_io_face_normals.xml");
    write_file(xml, "<scene version=\"0.5.0\">\n"
                    " <shape type=\"obj\"><string name=\"filename\""
                    " value=\"scene_io_face_normals.obj\"/>"
                    "<boolean name=\"faceNormals\" value=\"true\"/></shape>\n"
                    " <shape type=\"obj\"><string name=\"filename\""
                    " value=\"scene_io_face_normals.obj\"/></shape>\n"
                    " <emitter type=\"constant\"/>\n"
                    "</scene>\n");
    located_log log;
    drift_context *ctx = located_context(&log);
    drift_scene *scene = NULL;
    assert_int_equal(drift_scene_load(ctx, xml, &scene), DRIFT_OK);
    assert_int_equal(scene->mesh_count, 2);
    assert_null(scene->meshes[0].normals);
    assert_non_null(scene->meshes[1].normals);
    drift_scene_destroy(scene);
    drift_context_destroy(ctx);
}

void test_scene_io_textures_are_shared(void **state)
{
    (void)state;
    located_log log;
    drift_context *ctx = located_context(&log);
    drift_image img;
    assert_int_equal(drift_image_create(ctx, 4, 2, 3, &img), DRIFT_OK);
    for (int i = 0; i < 4 * 2 * 3; ++i) {
        img.pixels[i] = 0.25f;
    }
    char png[1024];
    test_out_path(png, "scene_io_texture.png");
    assert_int_equal(drift_image_save_png(ctx, png, &img, &(drift_tonemap_params){ 0 }), DRIFT_OK);
    drift_image_destroy(ctx, &img);
    char text[4096];
    snprintf(text, sizeof(text),
             "{\"materials\": {\"a\": {\"diffuse_texture\": \"%s\", \"diffuse_roughness\": 0.25},\n"
             "               \"b\": {\"type\": \"glossy\", \"specular\": 0.2, \"exponent\": 50,"
             " \"diffuse_texture\": \"%s\"}},\n"
             " \"environment\": {\"map\": \"%s\", \"multiplier\": 2}}",
             png, png, png);
    drift_scene *scene = NULL;
    assert_int_equal(drift_scene_load_json_text(ctx, text, strlen(text), NULL, "tex.json", &scene),
                     DRIFT_OK);
    assert_int_equal(scene->texture_count, 1);
    assert_int_equal(scene->materials[0].diffuse_texture, 0);
    assert_int_equal(scene->materials[1].diffuse_texture, 0);
    // diffuse_roughness asks for Burley's diffuse; without it the diffuse stays Lambertian.
    assert_int_equal(scene->materials[0].diffuse_model, DRIFT_DIFFUSE_BURLEY);
    assert_float_equal(scene->materials[0].diffuse_roughness, 0.25f, 0.0f);
    assert_int_equal(scene->materials[1].diffuse_model, DRIFT_DIFFUSE_LAMBERT);
    assert_int_equal(scene->environment.texture, 0);
    assert_float_equal(scene->environment.color.x, 2.0f, 1e-6f);
    assert_int_equal(scene->textures[0].width, 4);
    drift_scene_destroy(scene);

    // An OBJ's map_Kd is found next to the OBJ, and its UVs come along.
    char obj[1024], mtl[1024];
    write_file(test_out_path(mtl, "scene_io_textured.mtl"),
               "newmtl tex\nKd 1 1 1\nmap_Kd scene_io_texture.png\n");
    write_file(test_out_path(obj, "scene_io_textured.obj"),
               "mtllib scene_io_textured.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n"
               "vt 0 0\nvt 1 0\nvt 0 1\nusemtl tex\nf 1/1 2/2 3/3\n");
    scene = NULL;
    assert_int_equal(drift_scene_load(ctx, obj, &scene), DRIFT_OK);
    assert_int_equal(scene->texture_count, 1);
    assert_int_equal(scene->materials[scene->meshes[0].material].diffuse_texture, 0);
    assert_non_null(scene->meshes[0].uvs);
    drift_scene_destroy(scene);
    drift_context_destroy(ctx);
}

// --- CAMERA VIEWS ---

// The hall's views file loads; a view overrides only the camera fields it names; bad files
// fail with the right code and line.
void test_scene_io_camera_views(void **state)
{
    (void)state;
    located_log log;
    drift_context *ctx = located_context(&log);
    char path[1024];
    drift_camera_view views[16];
    uint32_t count = 0;
    assert_int_equal(drift_camera_views_load(ctx,
                                             test_repo_path(path, "scenes/sir-hall/sir_views.json"),
                                             views, 16, &count),
                     DRIFT_OK);
    assert_int_equal(count, 6);
    assert_string_equal(views[0].name, "closeup");

    const char *text = "{\"views\": [\n"
                       "  {\"name\": \"a\", \"target\": [1, 2, 3], \"fov_y\": 90},\n"
                       "  {\"name\": \"b_2\", \"position\": [4, 5, 6], \"aperture_radius\": 0.5}\n"
                       "]}\n";
    assert_int_equal(
        drift_camera_views_load_json_text(ctx, text, strlen(text), "v.json", views, 16, &count),
        DRIFT_OK);
    assert_int_equal(count, 2);
    drift_camera base = { .position = { 0, 0, -1 },
                          .target = { 0, 0, 0 },
                          .fov_y = 0.5f,
                          .aperture_radius = 0.1f,
                          .width = 8,
                          .height = 6 };
    drift_camera a = base, b = base;
    drift_camera_view_apply(&views[0], &a);
    drift_camera_view_apply(&views[1], &b);
    assert_near(a.target.z, 3.0f, 0.0f);
    assert_near(a.position.z, -1.0f, 0.0f);
    assert_near(a.fov_y, 3.14159265f / 2.0f, 1e-6f);
    assert_near(a.aperture_radius, 0.1f, 0.0f);
    assert_near(b.position.x, 4.0f, 0.0f);
    assert_near(b.target.x, 0.0f, 0.0f);
    assert_near(b.fov_y, 0.5f, 0.0f);
    assert_near(b.aperture_radius, 0.5f, 0.0f);

    const struct {
        const char *text;
        drift_result code;
        int line;
    } cases[] = {
        { "{\"views\": [\n  {\"target\": [1, 2, 3]}\n]}", DRIFT_ERR_PARSE, 2 },        // no name
        { "{\"views\": [\n  {\"name\": \"a b\"}\n]}", DRIFT_ERR_INVALID_ARGUMENT, 2 }, // file name
        { "{\"views\": [\n  {\"name\": \"a\",\n   \"fov_y\": 500}\n]}", DRIFT_ERR_INVALID_ARGUMENT,
          3 },
        { "{\"views\": [\n  {\"name\": \"a\", \"position\": [1, 2]}\n]}", DRIFT_ERR_PARSE, 2 },
        { "{\"views\": []}", DRIFT_ERR_INVALID_ARGUMENT, 1 },
        { "{\"views\": 3}", DRIFT_ERR_PARSE, 1 },
        { "{}", DRIFT_ERR_PARSE, 1 },
        { "{\"views\": [\n  {\"name\": \"a\",}\n]}", DRIFT_ERR_PARSE, 2 }, // syntax
    };

    for (size_t i = 0; i < sizeof cases / sizeof *cases; ++i) {
        drift_context_destroy(ctx);
        ctx = located_context(&log);
        count = 99;
        drift_result r = drift_camera_views_load_json_text(
            ctx, cases[i].text, strlen(cases[i].text), "bad.json", views, 16, &count);
        if (r != cases[i].code || log.first_error_line != cases[i].line || count != 0) {
            fail_msg("case %zu: code %d line %d count %u", i, (int)r, log.first_error_line, count);
        }
    }
    // More views than the caller holds is an error, not a silent cut.
    assert_int_equal(
        drift_camera_views_load_json_text(ctx, text, strlen(text), "v.json", views, 1, &count),
        DRIFT_ERR_INVALID_ARGUMENT);
    drift_context_destroy(ctx);
}
