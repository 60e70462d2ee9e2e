// Environment light: a constant colour, optionally times a lat-long radiance map.
//
// Lat-long mapping (docs/conventions.md): theta = acos(dir.y) from +y, phi = atan2(-dir.z,
// dir.x) in [0, 2 pi); u = phi / (2 pi), v = theta / pi with v = 0 the top image row.
#include "scene_internal.h"

#include <math.h>

bool drift_scene_has_environment(const drift_scene *scene)
{
    return !drift_vec3_is_zero(scene->environment.color);
}

static const drift_image *env_texture(const drift_scene *scene)
{
    uint32_t t = scene->environment.texture;
    return t != DRIFT_INVALID_INDEX && t < scene->texture_count ? &scene->textures[t] : NULL;
}

static drift_vec2 direction_to_uv(drift_vec3 d)
{
    float theta = acosf(drift_clampf(d.y, -1.0f, 1.0f));
    float phi = atan2f(-d.z, d.x);
    if (phi < 0.0f) {
        phi += 2.0f * DRIFT_PI;
    }
    return drift_vec2_make(phi * DRIFT_INV_2PI, theta * DRIFT_INV_PI);
}

static drift_vec3 uv_to_direction(drift_vec2 uv, float *out_sin_theta)
{
    float theta = uv.y * DRIFT_PI, phi = uv.x * 2.0f * DRIFT_PI;
    float sin_theta = sinf(theta);
    *out_sin_theta = sin_theta;
    return drift_vec3_make(sin_theta * cosf(phi), cosf(theta), -sin_theta * sinf(phi));
}

static void uv_to_texel(const drift_image *t, drift_vec2 uv, int32_t *x, int32_t *y)
{
    *x = (int32_t)(uv.x * (float)t->width);
    *y = (int32_t)(uv.y * (float)t->height);
    *x = *x < 0 ? 0 : (*x >= t->width ? t->width - 1 : *x);
    *y = *y < 0 ? 0 : (*y >= t->height ? t->height - 1 : *y);
}

static drift_vec3 texel_rgb(const drift_image *t, int32_t x, int32_t y)
{
    const float *p = drift_image_pixel(t, x, y);
    return t->channels >= 3 ? drift_vec3_make(p[0], p[1], p[2]) : drift_vec3_splat(p[0]);
}

// Piecewise-constant lookup, so evaluation matches the sampling density exactly.
drift_vec3 drift_environment_eval(const drift_scene *scene, drift_vec3 dir)
{
    drift_vec3 c = scene->environment.color;
    const drift_image *t = env_texture(scene);
    if (!t) {
        return c;
    }
    int32_t x, y;
    uv_to_texel(t, direction_to_uv(dir), &x, &y);
    return drift_vec3_mul(c, texel_rgb(t, x, y));
}

drift_result drift__environment_build(drift_scene *scene, drift__env_distribution **out_dist)
{
    *out_dist = NULL;
    const drift_image *t = env_texture(scene);
    if (!t) {
        return DRIFT_OK;
    }
    drift_context *ctx = scene->ctx;
    drift__env_distribution *d = drift_alloc(ctx, sizeof(*d));
    if (!d) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    d->width = t->width;
    d->height = t->height;
    size_t w = (size_t)t->width, h = (size_t)t->height;
    d->conditional_cdf = drift_alloc(ctx, sizeof(float) * h * (w + 1));
    d->marginal_cdf = drift_alloc(ctx, sizeof(float) * (h + 1));
    d->row_weight = drift_alloc(ctx, sizeof(float) * h);
    if (!d->conditional_cdf || !d->marginal_cdf || !d->row_weight) {
        drift__environment_destroy(scene, d);
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    double total = 0.0;
    for (size_t y = 0; y < h; ++y) {
        float sin_theta = sinf(DRIFT_PI * ((float)y + 0.5f) / (float)h);
        float *cdf = d->conditional_cdf + y * (w + 1);
        double row = 0.0;
        cdf[0] = 0.0f;
        for (size_t x = 0; x < w; ++x) {
            float lum = drift_luminance(texel_rgb(t, (int32_t)x, (int32_t)y));
            row += (double)(fmaxf(lum, 0.0f) * sin_theta);
            cdf[x + 1] = (float)row;
        }
        for (size_t x = 1; x <= w; ++x) {
            cdf[x] = row > 0.0 ? (float)((double)cdf[x] / row) : (float)x / (float)w;
        }
        d->row_weight[y] = (float)row;
        total += row;
        d->marginal_cdf[y + 1] = (float)total;
    }
    for (size_t y = 1; y <= h; ++y) {
        d->marginal_cdf[y] =
            total > 0.0 ? (float)((double)d->marginal_cdf[y] / total) : (float)y / (float)h;
    }
    d->total = total;
    *out_dist = d;
    return DRIFT_OK;
}

void drift__environment_destroy(drift_scene *scene, drift__env_distribution *dist)
{
    if (!dist) {
        return;
    }
    drift_free(scene->ctx, dist->conditional_cdf);
    drift_free(scene->ctx, dist->marginal_cdf);
    drift_free(scene->ctx, dist->row_weight);
    drift_free(scene->ctx, dist);
}

float drift__environment_average(const drift_scene *scene)
{
    float base = drift_luminance(scene->environment.color);
    const drift_image *t = env_texture(scene);
    if (!t) {
        return base;
    }
    // Solid-angle weighted mean over the sphere: sum(lum * sin) * (2 pi^2 / (w h)) / 4 pi.
    const drift__env_distribution *d = drift__light_table_environment(scene);
    if (!d) {
        return base;
    }
    double mean = d->total * (double)(2.0f * DRIFT_PI * DRIFT_PI) /
                  ((double)d->width * (double)d->height) / (double)(4.0f * DRIFT_PI);
    return base * (float)mean;
}

// Finds i with cdf[i] <= u < cdf[i+1] among n intervals and the offset within it.
static int32_t sample_cdf(const float *cdf, int32_t n, float u, float *out_offset)
{
    int32_t lo = (int32_t)drift_cdf_find(cdf, (uint32_t)n, u);
    float width = cdf[lo + 1] - cdf[lo];
    *out_offset =
        width > 0.0f ? drift_clampf((u - cdf[lo]) / width, 0.0f, DRIFT_ONE_MINUS_EPSILON) : 0.5f;
    return lo;
}

bool drift_environment_is_constant(const drift_scene *scene)
{
    return drift_scene_has_environment(scene) && !drift__light_table_environment(scene);
}

float drift_environment_pdf(const drift_scene *scene, drift_vec3 dir)
{
    const drift__env_distribution *d = drift__light_table_environment(scene);
    if (!d) {
        return DRIFT_INV_4PI;
    }
    drift_vec2 uv = direction_to_uv(dir);
    float sin_theta = sqrtf(fmaxf(0.0f, 1.0f - dir.y * dir.y));
    if (!(sin_theta > 0.0f) || !(d->total > 0.0)) {
        return 0.0f;
    }
    int32_t x, y;
    uv_to_texel(env_texture(scene), uv, &x, &y);
    const float *cdf = d->conditional_cdf + (size_t)y * ((size_t)d->width + 1);
    float p_row = d->marginal_cdf[y + 1] - d->marginal_cdf[y];
    float p_col = cdf[x + 1] - cdf[x];
    // Density in (u, v) is p * w * h; the Jacobian to solid angle is 2 pi^2 sin(theta).
    float pdf_uv = p_row * p_col * (float)d->width * (float)d->height;
    return pdf_uv / (2.0f * DRIFT_PI * DRIFT_PI * sin_theta);
}

drift_light_sample drift_environment_sample(const drift_scene *scene, drift_vec2 u)
{
    drift_light_sample s = { .distance = INFINITY };
    const drift__env_distribution *d = drift__light_table_environment(scene);
    if (!d) {
        s.wi = drift_sample_uniform_sphere(u);
        s.pdf = DRIFT_INV_4PI;
        s.radiance = drift_environment_eval(scene, s.wi);
        return s;
    }
    if (!(d->total > 0.0)) {
        return s;
    }
    float dy, dx;
    int32_t y = sample_cdf(d->marginal_cdf, d->height, u.y, &dy);
    const float *cdf = d->conditional_cdf + (size_t)y * ((size_t)d->width + 1);
    int32_t x = sample_cdf(cdf, d->width, u.x, &dx);
    drift_vec2 uv = { ((float)x + dx) / (float)d->width, ((float)y + dy) / (float)d->height };
    float sin_theta;
    s.wi = uv_to_direction(uv, &sin_theta);
    if (!(sin_theta > 0.0f)) {
        return s;
    }
    s.pdf = drift_environment_pdf(scene, s.wi);
    s.radiance = drift_environment_eval(scene, s.wi);
    return s;
}
