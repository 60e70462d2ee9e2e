// Material textures (issue 41): each texture's sampler (repeat, clamp, mirrored repeat; nearest
// and bilinear) and KHR_texture_transform against their definitions in the glTF specification,
// written out here; mip levels by footprint (a 1-texel checker averages to its mean); per-vertex
// tangents where the file has none; a glTF file with an emissive texture (a data URI, its
// transform on TEXCOORD_1), an occlusion texture in a buffer view, a mirrored/clamped nearest
// sampler, TANGENT with w = -1 and doubleSided, read as the file says; a textured two-sided
// emitter lights the same by light sampling as by BSDF sampling; the path tracer's ray-cone
// mip-mapping of a distant checker against a supersampled reference.
#include "drift/accel.h"
#include "drift/image.h"
#include "drift/image_io.h"
#include "drift/pt.h"
#include "drift/scene.h"
#include "drift/scene_io.h"
#include "drift_test.h"
#include "scene/scene_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

// A 4 x 2 texture: row 0 (the top, glTF t in [0, 0.5)) holds 0 1 2 3, row 1 holds 10..13.
static drift_scene *ramp_scene(drift_context *ctx, uint32_t *out_material)
{
    drift_scene *scene = NULL;
    assert_int_equal(drift_scene_create(ctx, &scene), DRIFT_OK);
    drift_image img;
    assert_int_equal(drift_image_create(ctx, 4, 2, 3, &img), DRIFT_OK);
    for (int y = 0; y < 2; ++y) {
        for (int x = 0; x < 4; ++x) {
            float *p = drift_image_pixel(&img, x, y);
            p[0] = p[1] = p[2] = (float)(10 * y + x);
        }
    }
    uint32_t tex;
    assert_int_equal(drift_scene_add_texture(scene, img, &tex), DRIFT_OK);
    drift_material m = drift_material_make(drift_vec3_splat(1.0f));
    m.diffuse_texture = tex;
    assert_int_equal(drift_scene_add_material(scene, &m, out_material), DRIFT_OK);
    return scene;
}

// The texture at glTF's (s, t) (top-left origin) through map `map`.
static float at(drift_scene *scene, uint32_t material, drift_texture_map map, float s, float t,
                float footprint)
{
    scene->materials[material].maps[DRIFT_TEXTURE_BASE] = map;
    drift_surface surf = { .material = material,
                           .uv = drift_vec2_make(s, 1.0f - t),
                           .uv_footprint = footprint };
    surf.uv1 = surf.uv;
    return drift_material_texture(scene, &scene->materials[material], DRIFT_TEXTURE_BASE, &surf).x;
}

static void test_wrap_filter_transform(void **state)
{
    (void)state;
    drift_context *ctx = test_context(1, NULL);
    uint32_t mat;
    drift_scene *scene = ramp_scene(ctx, &mat);
    const float row0 = 0.25f; // glTF t of row 0's centre
    drift_texture_map nearest = { .mag_nearest = true };
    // Repeat: s = 1.1 is s = 0.1, texel 0; s = -0.1 is 0.9, texel 3.
    assert_near(at(scene, mat, nearest, 1.1f, row0, 0), 0.0, 0);
    assert_near(at(scene, mat, nearest, -0.1f, row0, 0), 3.0, 0);
    // Clamp to edge.
    drift_texture_map clamp = nearest;
    clamp.wrap_s = DRIFT_WRAP_CLAMP;
    assert_near(at(scene, mat, clamp, 1.1f, row0, 0), 3.0, 0);
    assert_near(at(scene, mat, clamp, -0.3f, row0, 0), 0.0, 0);
    // Mirrored repeat: s in [1, 2) reads 2 - s; s in [-1, 0) reads -s.
    drift_texture_map mirror = nearest;
    mirror.wrap_s = DRIFT_WRAP_MIRROR;
    assert_near(at(scene, mat, mirror, 1.1f, row0, 0), 3.0, 0);  // 0.9
    assert_near(at(scene, mat, mirror, 1.3f, row0, 0), 2.0, 0);  // 0.7
    assert_near(at(scene, mat, mirror, -0.1f, row0, 0), 0.0, 0); // 0.1
    assert_near(at(scene, mat, mirror, 2.1f, row0, 0), 0.0, 0);  // period 2
    // Mirrored in t: t = 1.2 reads 0.8 (row 1); repeat reads 0.2 (row 0).
    drift_texture_map mirror_t = nearest;
    mirror_t.wrap_t = DRIFT_WRAP_MIRROR;
    assert_near(at(scene, mat, mirror_t, 0.1f, 1.2f, 0), 10.0, 0);
    assert_near(at(scene, mat, nearest, 0.1f, 1.2f, 0), 0.0, 0);
    // Bilinear: exact at a texel centre, the mean halfway, and at the edge the repeat wraps
    // (texels 3 and 0) where clamp does not.
    drift_texture_map linear = { 0 };
    assert_near(at(scene, mat, linear, 2.5f / 4.0f, row0, 0), 2.0, 1e-5);
    assert_near(at(scene, mat, linear, 0.5f, row0, 0), 1.5, 1e-5);
    assert_near(at(scene, mat, linear, 0.0f, row0, 0), 1.5, 1e-5);
    drift_texture_map linear_clamp = { .wrap_s = DRIFT_WRAP_CLAMP };
    assert_near(at(scene, mat, linear_clamp, 0.0f, row0, 0), 0.0, 1e-5);
    assert_near(at(scene, mat, linear, 0.5f, 0.5f, 0), 6.5, 1e-5); // between both rows

    // KHR_texture_transform: uv' = T(offset) R(rotation) S(scale) uv, with the rotation
    // u' = cos u + sin v, v' = -sin u + cos v (the glTF Sample Viewer's and three.js's).
    drift_texture_map t = nearest;
    t.has_transform = true;
    const float offset[2] = { 0.25f, 0.0f }, scale[2] = { 2.0f, 1.0f };
    float r = 0.0f;
    t.transform[0] = cosf(r) * scale[0];
    t.transform[1] = sinf(r) * scale[1];
    t.transform[2] = offset[0];
    t.transform[3] = -sinf(r) * scale[0];
    t.transform[4] = cosf(r) * scale[1];
    t.transform[5] = offset[1];
    assert_near(at(scene, mat, t, 0.1f, row0, 0), 1.0, 0); // 0.2 + 0.25 = 0.45: texel 1
    r = (float)DRIFT_PI / 2.0f;                            // quarter turn, no scale or offset
    t.transform[0] = cosf(r);
    t.transform[1] = sinf(r);
    t.transform[2] = 0.0f;
    t.transform[3] = -sinf(r);
    t.transform[4] = cosf(r);
    t.transform[5] = 0.0f;
    // (s, t) = (0.1, 0.6) -> (0.6, -0.1), repeated (0.6, 0.9): row 1, texel 2.
    assert_near(at(scene, mat, t, 0.1f, 0.6f, 0), 12.0, 0);
    drift_scene_destroy(scene);
    drift_context_destroy(ctx);
}

enum {
    CHECKER_TEXELS = 64
};

// A white material textured by a CHECKER_TEXELS-square checker of 1-texel squares.
static uint32_t add_checker_material(drift_context *ctx, drift_scene *scene)
{
    const int n = CHECKER_TEXELS;
    drift_image img;
    assert_int_equal(drift_image_create(ctx, n, n, 3, &img), DRIFT_OK);
    for (int y = 0; y < n; ++y) {
        for (int x = 0; x < n; ++x) {
            float *p = drift_image_pixel(&img, x, y);
            p[0] = p[1] = p[2] = (float)((x + y) & 1);
        }
    }
    uint32_t tex, mat;
    assert_int_equal(drift_scene_add_texture(scene, img, &tex), DRIFT_OK);
    drift_material m = drift_material_make(drift_vec3_splat(1.0f));
    m.diffuse_texture = tex;
    assert_int_equal(drift_scene_add_material(scene, &m, &mat), DRIFT_OK);
    return mat;
}

// A checker of 1-texel squares: at full size a texel, at a footprint of many texels its mean.
static void test_mip_levels(void **state)
{
    (void)state;
    drift_context *ctx = test_context(1, NULL);
    drift_scene *scene = NULL;
    assert_int_equal(drift_scene_create(ctx, &scene), DRIFT_OK);
    uint32_t mat = add_checker_material(ctx, scene);
    const int n = CHECKER_TEXELS;
    float quad[] = { 0, 0, 0, 1, 0, 0, 0, 1, 0 };
    uint32_t tri[] = { 0, 1, 2 };
    test_add_mesh(scene, quad, 3, tri, 1, mat);
    assert_int_equal(drift_scene_commit(scene), DRIFT_OK); // builds the pyramid
    drift_texture_map linear = { 0 };
    float s = 10.5f / (float)n, t = 20.5f / (float)n; // a texel centre: (10 + 20) even -> 0
    assert_near(at(scene, mat, linear, s, t, 0.0f), 0.0, 1e-5);
    assert_near(at(scene, mat, linear, s + 1.0f / (float)n, t, 0.0f), 1.0, 1e-5);
    // A footprint of one texel reads level 0; of 8 or 64 texels, the mean.
    assert_near(at(scene, mat, linear, s, t, 1.0f / (float)n), 0.0, 1e-5);
    assert_near(at(scene, mat, linear, s, t, 8.0f / (float)n), 0.5, 1e-5);
    assert_near(at(scene, mat, linear, s, t, 1.0f), 0.5, 1e-5);
    // Between levels 0 and 1 (a footprint of sqrt 2 texels): half a texel, half the mean.
    assert_near(at(scene, mat, linear, s, t, sqrtf(2.0f) / (float)n), 0.25, 1e-4);
    // A sampler without mip-maps reads level 0 at any footprint.
    drift_texture_map no_mips = { .no_mipmaps = true };
    assert_near(at(scene, mat, no_mips, s, t, 1.0f), 0.0, 1e-5);
    drift_scene_destroy(scene);
    drift_context_destroy(ctx);
}

// Per-vertex tangents of a normal-mapped quad (normals +z) whose u runs along -x (a mirrored
// mapping: w = -1 so that w cross(n, t) follows dp/dv = +y) and of one whose u runs along +y.
static void test_computed_tangents(void **state)
{
    (void)state;
    drift_context *ctx = test_context(1, NULL);
    drift_scene *scene = NULL;
    assert_int_equal(drift_scene_create(ctx, &scene), DRIFT_OK);
    drift_image flat;
    assert_int_equal(drift_image_create(ctx, 1, 1, 3, &flat), DRIFT_OK);
    float *p = drift_image_pixel(&flat, 0, 0);
    p[0] = p[1] = 0.5f;
    p[2] = 1.0f;
    uint32_t tex, mat;
    assert_int_equal(drift_scene_add_texture(scene, flat, &tex), DRIFT_OK);
    drift_material m = drift_material_make(drift_vec3_splat(0.5f));
    m.type = DRIFT_MATERIAL_GGX;
    m.ggx.alpha = 0.5f;
    m.ggx.normal_texture = tex;
    assert_int_equal(drift_scene_add_material(scene, &m, &mat), DRIFT_OK);
    const float pos[] = { 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0 };
    const float nrm[] = { 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1 };
    const uint32_t idx[] = { 0, 1, 2, 0, 2, 3 };
    const float uv_mirrored[] = { 0, 0, -1, 0, -1, 1, 0, 1 }; // u = -x, v = y
    const float uv_turned[] = { 0, 0, 0, -1, 1, -1, 1, 0 };   // u = y, v = -x
    const float *uvs[2] = { uv_mirrored, uv_turned };
    const drift_vec3 want_t[2] = { { -1, 0, 0 }, { 0, 1, 0 } };
    const float want_w[2] = { -1.0f, 1.0f }; // w cross(n, t) = dp/dv: +y, then -x
    for (int k = 0; k < 2; ++k) {
        assert_int_equal(drift_scene_add_mesh(scene,
                                              &(drift_mesh_desc){ .positions = pos,
                                                                  .normals = nrm,
                                                                  .uvs = uvs[k],
                                                                  .indices = idx,
                                                                  .vertex_count = 4,
                                                                  .triangle_count = 2,
                                                                  .material = mat },
                                              NULL),
                         DRIFT_OK);
    }
    assert_int_equal(drift_scene_commit(scene), DRIFT_OK);
    for (int k = 0; k < 2; ++k) {
        const float *t = scene->meshes[k].tangents;
        assert_non_null(t);
        for (int v = 0; v < 4; ++v) {
            assert_near(t[4 * v], want_t[k].x, 1e-5);
            assert_near(t[4 * v + 1], want_t[k].y, 1e-5);
            assert_near(t[4 * v + 2], want_t[k].z, 1e-5);
            assert_near(t[4 * v + 3], want_w[k], 0);
        }
    }
    drift_scene_destroy(scene);
    drift_context_destroy(ctx);
}

// --- A glTF FILE WITH EVERY KIND OF TEXTURE REFERENCE ---

static void base64(const uint8_t *in, size_t n, char *out)
{
    static const char abc[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    size_t o = 0;
    for (size_t i = 0; i < n; i += 3) {
        uint32_t v = (uint32_t)in[i] << 16 | (i + 1 < n ? (uint32_t)in[i + 1] << 8 : 0) |
                     (i + 2 < n ? in[i + 2] : 0);
        out[o++] = abc[v >> 18 & 63];
        out[o++] = abc[v >> 12 & 63];
        out[o++] = i + 1 < n ? abc[v >> 6 & 63] : '=';
        out[o++] = i + 2 < n ? abc[v & 63] : '=';
    }
    out[o] = '\0';
}

// A PNG of a w x 1 image with values `v` (0 or 1), read back as bytes.
static size_t png_bytes(drift_context *ctx, const char *name, const float *v, int w, uint8_t *out,
                        size_t cap)
{
    drift_image img;
    assert_int_equal(drift_image_create(ctx, w, 1, 3, &img), DRIFT_OK);
    for (int x = 0; x < w; ++x) {
        float *p = drift_image_pixel(&img, x, 0);
        p[0] = p[1] = p[2] = v[x];
    }
    char path[1024];
    test_out_path(path, name);
    assert_int_equal(drift_image_save_png(ctx, path, &img, &(drift_tonemap_params){ 0 }), DRIFT_OK);
    drift_image_destroy(ctx, &img);
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    size_t n = fread(out, 1, cap, f);
    fclose(f);
    assert_true(n > 0 && n < cap);
    return n;
}

// A quad in z = 0 facing +z: POSITION, NORMAL, TEXCOORD_0, TEXCOORD_1, TANGENT, indices.
typedef struct quad_buffer {
    float pos[12], nrm[12], uv0[8], uv1[8], tan[16];
    uint16_t idx[6];
} quad_buffer;

// `material_extra`: more of the material's JSON members (each followed by a comma).
static void write_textured_gltf(drift_context *ctx, const char *path, const char *material_extra)
{
    quad_buffer q = { .pos = { -1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0 },
                      .nrm = { 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1 },
                      .uv0 = { 0, 1, 1, 1, 1, 0, 0, 0 },
                      // TEXCOORD_1: only s = 0..0.5 (the emissive texture's left half)...
                      .uv1 = { 0, 1, 0.5f, 1, 0.5f, 0, 0, 0 },
                      // ...and tangents along +x with w = -1 (the file's choice, kept).
                      .tan = { 1, 0, 0, -1, 1, 0, 0, -1, 1, 0, 0, -1, 1, 0, 0, -1 },
                      .idx = { 0, 1, 2, 0, 2, 3 } };
    uint8_t png_a[4096], png_b[4096];
    const float emissive[2] = { 1, 0 }, occlusion[2] = { 0, 1 };
    size_t na = png_bytes(ctx, "textures_emissive.png", emissive, 2, png_a, sizeof png_a);
    size_t nb = png_bytes(ctx, "textures_occlusion.png", occlusion, 2, png_b, sizeof png_b);
    // Buffer 0: the quad, then the occlusion PNG (a buffer view holds it).
    size_t n0 = sizeof q + nb;
    uint8_t *b0 = malloc(n0);
    memcpy(b0, &q, sizeof q);
    memcpy(b0 + sizeof q, png_b, nb);
    char *b0_64 = malloc(n0 * 2 + 8), *a64 = malloc(na * 2 + 8);
    base64(b0, n0, b0_64);
    base64(png_a, na, a64);
    size_t cap = strlen(b0_64) + strlen(a64) + strlen(material_extra) + 8192;
    char *json = malloc(cap);
    snprintf(json, cap,
             "{\"asset\": {\"version\": \"2.0\"}, \"extensionsUsed\": [\"KHR_texture_transform\"],"
             " \"scene\": 0, \"scenes\": [{\"nodes\": [0]}], \"nodes\": [{\"mesh\": 0}],"
             " \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0, \"NORMAL\": 1,"
             "  \"TEXCOORD_0\": 2, \"TEXCOORD_1\": 3, \"TANGENT\": 4}, \"indices\": 5,"
             "  \"material\": 0}]}],"
             " \"materials\": [{\"name\": \"lamp\", \"doubleSided\": true, %s"
             "  \"emissiveFactor\": [2, 2, 2],"
             "  \"emissiveTexture\": {\"index\": 0, \"extensions\": {\"KHR_texture_transform\":"
             "   {\"texCoord\": 1, \"offset\": [0.5, 0], \"scale\": [1, 1]}}},"
             "  \"occlusionTexture\": {\"index\": 1, \"strength\": 0.5},"
             "  \"pbrMetallicRoughness\": {\"metallicFactor\": 0, \"roughnessFactor\": 1}}],"
             " \"samplers\": [{\"wrapS\": 33648, \"wrapT\": 33071, \"magFilter\": 9728,"
             "  \"minFilter\": 9729}],"
             " \"textures\": [{\"source\": 0, \"sampler\": 0}, {\"source\": 1}],"
             " \"images\": [{\"uri\": \"data:image/png;base64,%s\"},"
             "  {\"bufferView\": 6, \"mimeType\": \"image/png\"}],"
             " \"buffers\": [{\"byteLength\": %zu, \"uri\": "
             "\"data:application/octet-stream;base64,%s\"}],"
             " \"bufferViews\": [{\"buffer\": 0, \"byteOffset\": %zu, \"byteLength\": 48},"
             "  {\"buffer\": 0, \"byteOffset\": %zu, \"byteLength\": 48},"
             "  {\"buffer\": 0, \"byteOffset\": %zu, \"byteLength\": 32},"
             "  {\"buffer\": 0, \"byteOffset\": %zu, \"byteLength\": 32},"
             "  {\"buffer\": 0, \"byteOffset\": %zu, \"byteLength\": 64},"
             "  {\"buffer\": 0, \"byteOffset\": %zu, \"byteLength\": 12},"
             "  {\"buffer\": 0, \"byteOffset\": %zu, \"byteLength\": %zu}],"
             " \"accessors\": ["
             "  {\"bufferView\": 0, \"componentType\": 5126, \"count\": 4, \"type\": \"VEC3\","
             "   \"min\": [-1, -1, 0], \"max\": [1, 1, 0]},"
             "  {\"bufferView\": 1, \"componentType\": 5126, \"count\": 4, \"type\": \"VEC3\"},"
             "  {\"bufferView\": 2, \"componentType\": 5126, \"count\": 4, \"type\": \"VEC2\"},"
             "  {\"bufferView\": 3, \"componentType\": 5126, \"count\": 4, \"type\": \"VEC2\"},"
             "  {\"bufferView\": 4, \"componentType\": 5126, \"count\": 4, \"type\": \"VEC4\"},"
             "  {\"bufferView\": 5, \"componentType\": 5123, \"count\": 6, \"type\": \"SCALAR\"}]}",
             material_extra, a64, n0, b0_64, offsetof(quad_buffer, pos), offsetof(quad_buffer, nrm),
             offsetof(quad_buffer, uv0), offsetof(quad_buffer, uv1), offsetof(quad_buffer, tan),
             offsetof(quad_buffer, idx), sizeof q, nb);
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    fputs(json, f);
    fclose(f);
    free(json);
    free(b0);
    free(b0_64);
    free(a64);
}

static void test_gltf_textures(void **state)
{
    (void)state;
    test_log_capture log = { 0 };
    drift_context *ctx = test_context(1, &log);
    char path[1024];
    test_out_path(path, "textures_quad.gltf");
    write_textured_gltf(ctx, path, "");
    drift_scene *scene = NULL;
    assert_int_equal(drift_scene_load(ctx, path, &scene), DRIFT_OK);
    assert_int_equal(log.warnings, 0);
    const drift_material *m = &scene->materials[scene->meshes[0].material];
    assert_int_equal(m->type, DRIFT_MATERIAL_GGX);
    assert_true(m->ggx.emissive_texture < scene->texture_count);  // the data URI image
    assert_true(m->ggx.occlusion_texture < scene->texture_count); // the buffer view image
    assert_near(m->ggx.occlusion_strength, 0.5, 1e-6);
    assert_true(m->emission_two_sided);
    const drift_texture_map *e = &m->maps[DRIFT_TEXTURE_EMISSIVE];
    assert_int_equal(e->uv_set, 1); // KHR_texture_transform's texCoord overrides
    assert_int_equal(e->wrap_s, DRIFT_WRAP_MIRROR);
    assert_int_equal(e->wrap_t, DRIFT_WRAP_CLAMP);
    assert_true(e->mag_nearest && e->no_mipmaps && !e->min_nearest);
    assert_true(e->has_transform);
    assert_near(e->transform[2], 0.5, 1e-6);
    const drift_mesh *mesh = &scene->meshes[0];
    assert_non_null(mesh->uvs1);
    assert_non_null(mesh->tangents);
    for (uint32_t v = 0; v < mesh->vertex_count; ++v) {
        assert_near(mesh->tangents[4 * v], 1.0, 1e-6);
        assert_near(mesh->tangents[4 * v + 3], -1.0, 0); // the file's w, not recomputed
    }
    // The emission seen from the back (doubleSided): TEXCOORD_1's s in [0, 0.5] + 0.5 reads
    // the texture's right (black) half; TEXCOORD_0 would read both halves.
    drift_accel *accel = NULL;
    assert_int_equal(drift_accel_create(ctx, scene, &(drift_accel_desc){ 0 }, &accel), DRIFT_OK);
    for (int side = 0; side < 2; ++side) {
        for (float x = -0.5f; x < 0.9f; x += 1.0f) { // texel centres of the occlusion texture
            float z = side ? -1.0f : 1.0f;
            drift_ray ray = { .origin = drift_vec3_make(x, 0.1f, z),
                              .dir = drift_vec3_make(0, 0, -z),
                              .tmax = INFINITY };
            drift_hit hit;
            assert_true(drift_accel_intersect(accel, &ray, &hit));
            drift_surface s = drift_scene_surface(scene, &ray, &hit);
            assert_near(s.emission.x, 0.0, 1e-6);
            // The occlusion texture (s from TEXCOORD_0: 0 on the left, 1 on the right) at
            // strength 1/2.
            drift_bsdf b = drift_bsdf_make(scene, &s);
            assert_near(b.occlusion, x < 0.0f ? 0.5 : 1.0, 1e-6);
        }
    }
    // Without the offset the left half (white, x 2) shows, from both faces.
    scene->materials[mesh->material].maps[DRIFT_TEXTURE_EMISSIVE].has_transform = false;
    for (int side = 0; side < 2; ++side) {
        float z = side ? -1.0f : 1.0f;
        drift_ray ray = { .origin = drift_vec3_make(0.3f, 0, z),
                          .dir = drift_vec3_make(0, 0, -z),
                          .tmax = INFINITY };
        drift_hit hit;
        assert_true(drift_accel_intersect(accel, &ray, &hit));
        drift_surface s = drift_scene_surface(scene, &ray, &hit);
        assert_near(s.emission.x, 2.0, 1e-5);
    }
    drift_accel_destroy(accel);
    drift_scene_destroy(scene);
    drift_context_destroy(ctx);
}

// KHR_materials_clearcoat with its textures: the factor times clearcoatTexture's R, the
// roughness times clearcoatRoughnessTexture's G (both the 0 | 1 occlusion image, read as
// data), read per point by drift_bsdf_make; clearcoatNormalTexture warns that it is dropped.
static void test_gltf_clearcoat(void **state)
{
    (void)state;
    test_log_capture log = { 0 };
    drift_context *ctx = test_context(1, &log);
    char path[1024];
    test_out_path(path, "textures_clearcoat.gltf");
    write_textured_gltf(ctx, path,
                        "\"extensions\": {\"KHR_materials_clearcoat\": {\"clearcoatFactor\": 0.8,"
                        " \"clearcoatRoughnessFactor\": 0.5, \"clearcoatTexture\": {\"index\": 1},"
                        " \"clearcoatRoughnessTexture\": {\"index\": 1},"
                        " \"clearcoatNormalTexture\": {\"index\": 0}}},");
    drift_scene *scene = NULL;
    assert_int_equal(drift_scene_load(ctx, path, &scene), DRIFT_OK);
    assert_int_equal(log.warnings, 1);
    assert_non_null(strstr(log.last_message, "clearcoat normal texture"));
    const drift_mesh *mesh = &scene->meshes[0];
    const drift_material *m = &scene->materials[mesh->material];
    assert_near(m->ggx.clearcoat, 0.8, 1e-6);
    assert_near(m->ggx.clearcoat_alpha, 0.25, 1e-6);
    assert_true(m->ggx.clearcoat_texture < scene->texture_count);
    assert_true(m->ggx.clearcoat_roughness_texture < scene->texture_count);
    assert_true(m->ggx.clearcoat_principled); // docs/decisions/0411-gltf-clearcoat.md
    drift_accel *accel = NULL;
    assert_int_equal(drift_accel_create(ctx, scene, &(drift_accel_desc){ 0 }, &accel), DRIFT_OK);
    for (float x = -0.5f; x < 0.9f; x += 1.0f) { // the texel centres
        drift_ray ray = { .origin = drift_vec3_make(x, 0.1f, 1.0f),
                          .dir = drift_vec3_make(0, 0, -1),
                          .tmax = INFINITY };
        drift_hit hit;
        assert_true(drift_accel_intersect(accel, &ray, &hit));
        drift_surface s = drift_scene_surface(scene, &ray, &hit);
        drift_bsdf b = drift_bsdf_make(scene, &s);
        // Left: R = 0, no coat; right: R = G = 1, the factors.
        assert_near(b.ggx.clearcoat, x < 0.0f ? 0.0 : 0.8, 1e-6);
        if (x > 0.0f) {
            assert_near(b.ggx.clearcoat_alpha, 0.25, 1e-6);
            assert_true(drift_bsdf_clearcoat_albedo(&b, 1.0f, NULL) > 0.0f);
        }
    }
    drift_accel_destroy(accel);
    drift_scene_destroy(scene);
    drift_context_destroy(ctx);
}

// --- LIGHT FROM A TEXTURED TWO-SIDED EMITTER ---

// The mean radiance of a diffuse floor lit only by an emissive quad whose front faces away
// from it (emitting from its back: two-sided), half of it black by its emissive texture.
static double floor_mean(bool two_sided, bool nee, uint32_t spp, bool bumpy)
{
    drift_context *ctx = test_context(2, NULL);
    drift_scene *scene = NULL;
    assert_int_equal(drift_scene_create(ctx, &scene), DRIFT_OK);
    drift_image tex;
    assert_int_equal(drift_image_create(ctx, 2, 1, 3, &tex), DRIFT_OK);
    float *p = drift_image_pixel(&tex, 0, 0);
    p[0] = p[1] = p[2] = 1.0f;
    p = drift_image_pixel(&tex, 1, 0);
    p[0] = p[1] = p[2] = 0.0f;
    uint32_t t, lamp, floor_mat;
    assert_int_equal(drift_scene_add_texture(scene, tex, &t), DRIFT_OK);
    drift_material e = drift_material_make(drift_vec3_splat(0.0f));
    e.type = DRIFT_MATERIAL_GGX;
    e.ggx.metallic = 1.0f;
    e.emission = drift_vec3_splat(4.0f);
    e.ggx.emissive_texture = t;
    e.maps[DRIFT_TEXTURE_EMISSIVE].mag_nearest = true;
    e.emission_two_sided = two_sided;
    assert_int_equal(drift_scene_add_material(scene, &e, &lamp), DRIFT_OK);
    drift_material d = drift_material_make(drift_vec3_splat(0.8f));
    if (bumpy) {
        // A GGX plastic whose normal map tilts every normal by 30 degrees about v.
        drift_image nm;
        assert_int_equal(drift_image_create(ctx, 1, 1, 3, &nm), DRIFT_OK);
        float *q = drift_image_pixel(&nm, 0, 0);
        q[0] = 0.5f + 0.5f * sinf(0.5236f);
        q[1] = 0.5f;
        q[2] = 0.5f + 0.5f * cosf(0.5236f);
        uint32_t nt;
        assert_int_equal(drift_scene_add_texture(scene, nm, &nt), DRIFT_OK);
        d.type = DRIFT_MATERIAL_GGX;
        d.ggx.alpha = 0.2f;
        d.ggx.normal_texture = nt;
    }
    assert_int_equal(drift_scene_add_material(scene, &d, &floor_mat), DRIFT_OK);
    // The lamp at y = 1 facing +y (away from the floor); uv s = 0..1 along x.
    const float lp[] = { -0.5f, 1, 0.5f, 0.5f, 1, 0.5f, 0.5f, 1, -0.5f, -0.5f, 1, -0.5f };
    const float luv[] = { 0, 0, 1, 0, 1, 1, 0, 1 };
    const uint32_t li[] = { 0, 1, 2, 0, 2, 3 };
    assert_int_equal(drift_scene_add_mesh(scene,
                                          &(drift_mesh_desc){ .positions = lp,
                                                              .uvs = luv,
                                                              .indices = li,
                                                              .vertex_count = 4,
                                                              .triangle_count = 2,
                                                              .material = lamp },
                                          NULL),
                     DRIFT_OK);
    const float fp[] = { -2, 0, 2, 2, 0, 2, 2, 0, -2, -2, 0, -2 };
    const float fn[] = { 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0 };
    assert_int_equal(drift_scene_add_mesh(scene,
                                          &(drift_mesh_desc){ .positions = fp,
                                                              .normals = fn,
                                                              .uvs = luv,
                                                              .indices = li,
                                                              .vertex_count = 4,
                                                              .triangle_count = 2,
                                                              .material = floor_mat },
                                          NULL),
                     DRIFT_OK);
    scene->camera = drift_camera_look_at(drift_vec3_make(0, 0.5f, 0.01f), drift_vec3_make(0, 0, 0),
                                         drift_vec3_make(0, 0, -1), 0.6f, 8, 8);
    assert_int_equal(drift_scene_commit(scene), DRIFT_OK);
    drift_accel *accel = NULL;
    assert_int_equal(drift_accel_create(ctx, scene, &(drift_accel_desc){ 0 }, &accel), DRIFT_OK);
    drift_pt *pt = NULL;
    drift_pt_params params = {
        .width = 8, .height = 8, .seed = 3, .max_depth = 1, .disable_nee = !nee
    };
    assert_int_equal(drift_pt_create(ctx, scene, accel, &params, &pt), DRIFT_OK);
    assert_int_equal(drift_pt_render_samples(pt, spp, NULL), DRIFT_OK);
    drift_image img;
    assert_int_equal(drift_pt_resolve(pt, DRIFT_PT_AOV_BEAUTY, &img), DRIFT_OK);
    double sum = 0.0;
    for (int y = 0; y < img.height; ++y) {
        for (int x = 0; x < img.width; ++x) {
            sum += (double)drift_image_pixel(&img, x, y)[0];
        }
    }
    drift_pt_destroy(pt);
    drift_accel_destroy(accel);
    drift_scene_destroy(scene);
    drift_context_destroy(ctx);
    return sum / (double)(img.width * img.height);
}

static void test_two_sided_textured_emitter(void **state)
{
    (void)state;
    // The camera, below the lamp, sees only the floor under the lamp's back: one-sided, no light.
    assert_near(floor_mean(false, true, 16, false), 0.0, 0.0);
    assert_near(floor_mean(false, false, 16, false), 0.0, 0.0);
    double nee = floor_mean(true, true, 256, false), bsdf = floor_mean(true, false, 2048, false);
    printf("two-sided textured lamp: floor mean %.4f by light sampling, %.4f by BSDF sampling\n",
           nee, bsdf);
    assert_true(nee > 0.05);
    assert_near(nee / bsdf, 1.0, 0.05);
    // A normal-mapped floor: light sampling takes the cosine about the mapped normal, as BSDF
    // sampling does (about the interpolated normal it was 1.31 times the BSDF estimate).
    nee = floor_mean(true, true, 256, true);
    bsdf = floor_mean(true, false, 2048, true);
    printf("normal-mapped floor: %.4f by light sampling, %.4f by BSDF sampling\n", nee, bsdf);
    assert_near(nee / bsdf, 1.0, 0.05);
}

// --- RAY-CONE MIP-MAPPING IN THE PATH TRACER ---

// A 1-texel checker on a plane running to the horizon, lit straight down by a directional light
// of irradiance pi: each pixel is its texture's mean over the pixel (Lambert, kd / pi x pi).
static drift_image checker_render(drift_context *ctx, bool point_sampling, uint32_t spp)
{
    drift_scene *scene = NULL;
    assert_int_equal(drift_scene_create(ctx, &scene), DRIFT_OK);
    uint32_t mat = add_checker_material(ctx, scene);
    const float x0 = -200, x1 = 200, z0 = 2, z1 = -400, k = 0.25f; // a texel is 1/16 unit
    const float pos[] = { x0, 0, z0, x1, 0, z0, x1, 0, z1, x0, 0, z1 };
    const float uv[] = { k * x0, k * z0, k * x1, k * z0, k * x1, k * z1, k * x0, k * z1 };
    const uint32_t idx[] = { 0, 1, 2, 0, 2, 3 };
    assert_int_equal(drift_scene_add_mesh(scene,
                                          &(drift_mesh_desc){ .positions = pos,
                                                              .uvs = uv,
                                                              .indices = idx,
                                                              .vertex_count = 4,
                                                              .triangle_count = 2,
                                                              .material = mat },
                                          NULL),
                     DRIFT_OK);
    drift_light sun = { .type = DRIFT_LIGHT_DIRECTIONAL,
                        .color = drift_vec3_splat((float)DRIFT_PI),
                        .direction = drift_vec3_make(0, -1, 0) };
    assert_int_equal(drift_scene_add_light(scene, &sun, NULL), DRIFT_OK);
    scene->camera = drift_camera_look_at(drift_vec3_make(0, 1, 0), drift_vec3_make(0, 0.55f, -10),
                                         drift_vec3_make(0, 1, 0), 0.7f, 48, 32);
    assert_int_equal(drift_scene_commit(scene), DRIFT_OK);
    drift_accel *accel = NULL;
    assert_int_equal(drift_accel_create(ctx, scene, &(drift_accel_desc){ 0 }, &accel), DRIFT_OK);
    drift_pt *pt = NULL;
    drift_pt_params params = { .seed = 5,
                               .max_depth = 1,
                               .texture_point_sampling = point_sampling };
    assert_int_equal(drift_pt_create(ctx, scene, accel, &params, &pt), DRIFT_OK);
    assert_int_equal(drift_pt_render_samples(pt, spp, NULL), DRIFT_OK);
    drift_image view, out;
    assert_int_equal(drift_pt_resolve(pt, DRIFT_PT_AOV_BEAUTY, &view), DRIFT_OK);
    assert_int_equal(drift_image_create(ctx, view.width, view.height, 3, &out), DRIFT_OK);
    for (int y = 0; y < view.height; ++y) {
        memcpy(drift_image_pixel(&out, 0, y), drift_image_pixel(&view, 0, y),
               (size_t)view.width * 3 * sizeof(float));
    }
    drift_pt_destroy(pt);
    drift_accel_destroy(accel);
    drift_scene_destroy(scene);
    return out;
}

static double rmse(const drift_image *a, const drift_image *b)
{
    double sum = 0.0;
    for (int y = 0; y < a->height; ++y) {
        for (int x = 0; x < a->width; ++x) {
            double d =
                (double)drift_image_pixel(a, x, y)[0] - (double)drift_image_pixel(b, x, y)[0];
            sum += d * d;
        }
    }
    return sqrt(sum / (double)(a->width * a->height));
}

static void test_pt_mip_mapping(void **state)
{
    (void)state;
    drift_context *ctx = test_context(2, NULL);
    drift_image reference = checker_render(ctx, true, 256); // the pixels' box-filtered truth
    drift_image point = checker_render(ctx, true, 1);
    drift_image mip = checker_render(ctx, false, 1);
    drift_image again = checker_render(ctx, false, 1);
    double e_point = rmse(&point, &reference), e_mip = rmse(&mip, &reference);
    printf("distant checker, 1 spp against 256 spp point-sampled: RMSE point-sampled %.4f, "
           "mip-mapped %.4f\n",
           e_point, e_mip);
    assert_true(e_point > 0.1); // the checker aliases
    assert_true(e_mip < 0.5 * e_point);
    assert_near(rmse(&mip, &again), 0.0, 0.0); // deterministic
    drift_image_destroy(ctx, &reference);
    drift_image_destroy(ctx, &point);
    drift_image_destroy(ctx, &mip);
    drift_image_destroy(ctx, &again);
    drift_context_destroy(ctx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_wrap_filter_transform),
        cmocka_unit_test(test_mip_levels),
        cmocka_unit_test(test_computed_tangents),
        cmocka_unit_test(test_gltf_textures),
        cmocka_unit_test(test_gltf_clearcoat),
        cmocka_unit_test(test_two_sided_textured_emitter),
        cmocka_unit_test(test_pt_mip_mapping),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
