// Texture lookups: the plain bilinear read (environment maps) and the materials' reads through
// their drift_texture_map (wrap, filter, uv set, KHR_texture_transform) with mip-mapping by the
// ray's footprint (docs/materials.md, "Textures").
#include "scene_internal.h"

#include <math.h>

static int32_t wrap(int32_t i, int32_t n)
{
    int32_t m = i % n;
    return m < 0 ? m + n : m;
}

static drift_vec3 texel(const drift_image *t, int32_t x, int32_t y)
{
    const float *p = drift_image_pixel(t, wrap(x, t->width), wrap(y, t->height));
    return t->channels >= 3 ? drift_vec3_make(p[0], p[1], p[2]) : drift_vec3_splat(p[0]);
}

drift_vec3 drift__texture_bilinear(const drift_image *texture, drift_vec2 uv)
{
    if (!isfinite(uv.x) || !isfinite(uv.y)) {
        return texel(texture, 0, 0);
    }
    // Texel centres sit at half-integers; row 0 is the top of the image, v = 1.
    float x = uv.x * (float)texture->width - 0.5f;
    float y = (1.0f - uv.y) * (float)texture->height - 0.5f;
    float fx = floorf(x), fy = floorf(y);
    float tx = x - fx, ty = y - fy;
    // Keep indices in range for huge uv values before converting to int.
    int32_t x0 = (int32_t)fmodf(fx, (float)texture->width);
    int32_t y0 = (int32_t)fmodf(fy, (float)texture->height);
    drift_vec3 a = texel(texture, x0, y0), b = texel(texture, x0 + 1, y0);
    drift_vec3 c = texel(texture, x0, y0 + 1), d = texel(texture, x0 + 1, y0 + 1);
    drift_vec3 top = drift_vec3_add(drift_vec3_scale(a, 1.0f - tx), drift_vec3_scale(b, tx));
    drift_vec3 bottom = drift_vec3_add(drift_vec3_scale(c, 1.0f - tx), drift_vec3_scale(d, tx));
    return drift_vec3_add(drift_vec3_scale(top, 1.0f - ty), drift_vec3_scale(bottom, ty));
}

// --- MIP-MAPS ---

struct drift_texture_pyramid {
    int32_t count;       // levels, level 0 included (0: no pyramid)
    drift_image *levels; // levels[0] is a view of the scene's texture; the others are owned
};

// Level k + 1 of level k: each texel the mean of the (up to) 2 x 2 texels it covers.
static drift_result downsample(drift_context *ctx, const drift_image *src, drift_image *out)
{
    int32_t w = src->width > 1 ? src->width / 2 : 1, h = src->height > 1 ? src->height / 2 : 1;
    drift_result r = drift_image_create(ctx, w, h, src->channels, out);
    for (int32_t y = 0; r == DRIFT_OK && y < h; ++y) {
        for (int32_t x = 0; x < w; ++x) {
            int32_t x0 = 2 * x < src->width ? 2 * x : src->width - 1;
            int32_t y0 = 2 * y < src->height ? 2 * y : src->height - 1;
            int32_t x1 = x0 + 1 < src->width ? x0 + 1 : x0, y1 = y0 + 1 < src->height ? y0 + 1 : y0;
            float *o = drift_image_pixel(out, x, y);
            for (int32_t c = 0; c < src->channels; ++c) {
                o[c] =
                    0.25f * (drift_image_pixel(src, x0, y0)[c] + drift_image_pixel(src, x1, y0)[c] +
                             drift_image_pixel(src, x0, y1)[c] + drift_image_pixel(src, x1, y1)[c]);
            }
        }
    }
    return r;
}

void drift__texture_pyramids_destroy(drift_scene *scene)
{
    if (!scene->pyramids) {
        return;
    }
    for (uint32_t i = 0; i < scene->texture_count; ++i) {
        drift_texture_pyramid *p = &scene->pyramids[i];
        for (int32_t k = 1; k < p->count; ++k) {
            drift_image_destroy(scene->ctx, &p->levels[k]);
        }
        drift_free(scene->ctx, p->levels);
    }
    drift_free(scene->ctx, scene->pyramids);
    scene->pyramids = NULL;
}

// The textures of slot `slot` of material m (DRIFT_INVALID_INDEX for none).
static uint32_t slot_texture(const drift_material *m, drift_texture_slot slot)
{
    if (slot == DRIFT_TEXTURE_BASE) {
        return m->diffuse_texture;
    }
    if (m->type != DRIFT_MATERIAL_GGX) {
        return DRIFT_INVALID_INDEX;
    }
    switch (slot) {
    case DRIFT_TEXTURE_METALLIC_ROUGHNESS:
        return m->ggx.metallic_roughness_texture;
    case DRIFT_TEXTURE_NORMAL:
        return m->ggx.normal_texture;
    case DRIFT_TEXTURE_EMISSIVE:
        return m->ggx.emissive_texture;
    case DRIFT_TEXTURE_OCCLUSION:
        return m->ggx.occlusion_texture;
    case DRIFT_TEXTURE_CLEARCOAT:
        return m->ggx.clearcoat_texture;
    case DRIFT_TEXTURE_CLEARCOAT_ROUGHNESS:
        return m->ggx.clearcoat_roughness_texture;
    default:
        return DRIFT_INVALID_INDEX;
    }
}

drift_result drift__texture_pyramids_build(drift_scene *scene)
{
    drift__texture_pyramids_destroy(scene);
    if (scene->texture_count == 0) {
        return DRIFT_OK;
    }
    drift_context *ctx = scene->ctx;
    scene->pyramids = drift_alloc(ctx, scene->texture_count * sizeof(drift_texture_pyramid));
    if (!scene->pyramids) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    for (uint32_t i = 0; i < scene->texture_count; ++i) {
        scene->pyramids[i] = (drift_texture_pyramid){ 0 };
    }
    for (uint32_t m = 0; m < scene->material_count; ++m) {
        for (int slot = 0; slot < DRIFT_TEXTURE_SLOT_COUNT; ++slot) {
            uint32_t t = slot_texture(&scene->materials[m], (drift_texture_slot)slot);
            if (t >= scene->texture_count || scene->pyramids[t].count > 0) {
                continue;
            }
            const drift_image *base = &scene->textures[t];
            int32_t count = 1;
            for (int32_t w = base->width, h = base->height; w > 1 || h > 1; ++count) {
                w = w > 1 ? w / 2 : 1;
                h = h > 1 ? h / 2 : 1;
            }
            drift_texture_pyramid *p = &scene->pyramids[t];
            p->levels = drift_alloc(ctx, (size_t)count * sizeof(drift_image));
            if (!p->levels) {
                return DRIFT_ERR_OUT_OF_MEMORY;
            }
            p->levels[0] = drift_image_view(base, 0, 0, base->width, base->height);
            p->count = 1;
            for (int32_t k = 1; k < count; ++k) {
                drift_result r = downsample(ctx, &p->levels[k - 1], &p->levels[k]);
                if (r != DRIFT_OK) {
                    return r;
                }
                p->count = k + 1;
            }
        }
    }
    return DRIFT_OK;
}

// --- SAMPLING THROUGH A MAP ---

// Integer texel index i wrapped into [0, n) by mode.
static int32_t wrap_index(int32_t i, int32_t n, int mode)
{
    switch (mode) {
    case DRIFT_WRAP_CLAMP:
        return i < 0 ? 0 : (i >= n ? n - 1 : i);
    case DRIFT_WRAP_MIRROR: {
        int32_t m = wrap(i, 2 * n);
        return m < n ? m : 2 * n - 1 - m;
    }
    default:
        return wrap(i, n);
    }
}

// A texel coordinate brought near [0, n) without changing what the wrap mode makes of it, so
// that huge uvs stay exact enough and convert to int safely.
static float reduce(float x, int32_t n, int mode)
{
    float period = mode == DRIFT_WRAP_MIRROR ? 2.0f * (float)n : (float)n;
    if (mode == DRIFT_WRAP_CLAMP) {
        return drift_clampf(x, -1.0f, (float)n);
    }
    return fmodf(x, period);
}

static drift_vec3 texel_at(const drift_image *t, int32_t x, int32_t y, const drift_texture_map *m)
{
    const float *p = drift_image_pixel(t, wrap_index(x, t->width, m->wrap_s),
                                       wrap_index(y, t->height, m->wrap_t));
    return t->channels >= 3 ? drift_vec3_make(p[0], p[1], p[2]) : drift_vec3_splat(p[0]);
}

// One level at (s, t): glTF's uv, origin at the image's top left.
static drift_vec3 sample_level(const drift_image *t, float s, float tt, bool nearest,
                               const drift_texture_map *m)
{
    float x = reduce(s * (float)t->width, t->width, m->wrap_s);
    float y = reduce(tt * (float)t->height, t->height, m->wrap_t);
    if (nearest) {
        return texel_at(t, (int32_t)floorf(x), (int32_t)floorf(y), m);
    }
    x -= 0.5f;
    y -= 0.5f;
    float fx = floorf(x), fy = floorf(y);
    float ax = x - fx, ay = y - fy;
    int32_t x0 = (int32_t)fx, y0 = (int32_t)fy;
    drift_vec3 a = texel_at(t, x0, y0, m), b = texel_at(t, x0 + 1, y0, m);
    drift_vec3 c = texel_at(t, x0, y0 + 1, m), d = texel_at(t, x0 + 1, y0 + 1, m);
    drift_vec3 top = drift_vec3_add(drift_vec3_scale(a, 1.0f - ax), drift_vec3_scale(b, ax));
    drift_vec3 bottom = drift_vec3_add(drift_vec3_scale(c, 1.0f - ax), drift_vec3_scale(d, ax));
    return drift_vec3_add(drift_vec3_scale(top, 1.0f - ay), drift_vec3_scale(bottom, ay));
}

drift_vec3 drift__texture_sample(const drift_scene *scene, uint32_t index,
                                 const drift_texture_map *map, drift_vec2 uv, float footprint)
{
    static const drift_texture_map plain = { 0 };
    const drift_texture_map *m = map ? map : &plain;
    const drift_image *base = &scene->textures[index];
    // glTF's uv (top-left origin), then KHR_texture_transform.
    float s = uv.x, t = 1.0f - uv.y;
    float det = 1.0f;
    if (m->has_transform) {
        const float *k = m->transform;
        float s2 = k[0] * s + k[1] * t + k[2], t2 = k[3] * s + k[4] * t + k[5];
        s = s2;
        t = t2;
        det = fabsf(k[0] * k[4] - k[1] * k[3]);
    }
    if (!isfinite(s) || !isfinite(t)) {
        return texel_at(base, 0, 0, m);
    }
    const drift_texture_pyramid *p =
        scene->pyramids && index < scene->texture_count ? &scene->pyramids[index] : NULL;
    float lod = -INFINITY;
    if (footprint > 0.0f && !m->no_mipmaps) {
        // The footprint's width in texels of level 0 (Akenine-Moller et al. 2021, eq. 34).
        lod = log2f(footprint * sqrtf(det * (float)base->width * (float)base->height));
    }
    if (!(lod > 0.0f) || !p || p->count < 2) {
        bool nearest = lod > 0.0f ? m->min_nearest : m->mag_nearest;
        return sample_level(base, s, t, nearest, m);
    }
    float top = (float)(p->count - 1);
    if (lod >= top) {
        return sample_level(&p->levels[p->count - 1], s, t, m->min_nearest, m);
    }
    int32_t k = (int32_t)lod;
    float f = lod - (float)k;
    drift_vec3 a = sample_level(&p->levels[k], s, t, m->min_nearest, m);
    drift_vec3 b = sample_level(&p->levels[k + 1], s, t, m->min_nearest, m);
    return drift_vec3_add(drift_vec3_scale(a, 1.0f - f), drift_vec3_scale(b, f));
}

drift_vec3 drift_material_texture(const drift_scene *scene, const drift_material *material,
                                  drift_texture_slot slot, const drift_surface *surface)
{
    uint32_t index = slot_texture(material, slot);
    if (index == DRIFT_INVALID_INDEX || index >= scene->texture_count) {
        return drift_vec3_splat(1.0f);
    }
    const drift_texture_map *m = &material->maps[slot];
    bool second = m->uv_set == 1;
    return drift__texture_sample(scene, index, m, second ? surface->uv1 : surface->uv,
                                 second ? surface->uv1_footprint : surface->uv_footprint);
}
