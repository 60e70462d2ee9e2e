// The pre-filtered environment of SSAO, GTAO and SSDO (docs/ssdo.md, "Environment"): the
// lat-long environment box-averaged to a small source map, then convolved by brute force into
// an irradiance map (cosine lobe, stored as E / pi) and nine cone-filtered radiance maps, one
// per sample count N = 2^k, each with the von Mises-Fisher lobe exp(N (cos - 1)) whose solid
// angle is about 2 pi / N: the share of the hemisphere one SSDO sample stands for. Each map is
// normalised by the sum of its discrete weights, so a constant environment stays exact. The
// renders read octahedral copies (128^2, bilinear), which need no trigonometry per lookup.
#include "ssdo_internal.h"

#include <string.h>

typedef struct env_build {
    const drift_scene *scene;
    int32_t source_width, source_height;
    float *source;     // source_width*source_height*3 radiance
    float *source_dir; // 4 floats a texel: direction and solid angle
    drift_ssdo_env *env;
} env_build;

// The environment box-averaged over one source cell.
static drift_vec3 source_cell(const env_build *b, int32_t x, int32_t y)
{
    const drift_scene *scene = b->scene;
    drift_vec3 c = scene->environment.color;
    uint32_t t = scene->environment.texture;
    if (t == DRIFT_INVALID_INDEX || t >= scene->texture_count) {
        return c;
    }
    const drift_image *img = &scene->textures[t];
    int32_t x0 = (int32_t)((int64_t)x * img->width / b->source_width);
    int32_t x1 = (int32_t)((int64_t)(x + 1) * img->width / b->source_width);
    int32_t y0 = (int32_t)((int64_t)y * img->height / b->source_height);
    int32_t y1 = (int32_t)((int64_t)(y + 1) * img->height / b->source_height);
    x1 = x1 > x0 ? x1 : x0 + 1;
    y1 = y1 > y0 ? y1 : y0 + 1;
    double sum[3] = { 0.0, 0.0, 0.0 };
    for (int32_t j = y0; j < y1; ++j) {
        for (int32_t i = x0; i < x1; ++i) {
            const float *p = drift_image_pixel(img, i < img->width ? i : img->width - 1,
                                               j < img->height ? j : img->height - 1);
            for (int k = 0; k < 3; ++k) {
                sum[k] += (double)(img->channels >= 3 ? p[k] : p[0]);
            }
        }
    }
    double n = (double)(x1 - x0) * (double)(y1 - y0);
    return drift_vec3_mul(
        c, drift_vec3_make((float)(sum[0] / n), (float)(sum[1] / n), (float)(sum[2] / n)));
}

static void build_source_rows(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    env_build *b = user;
    for (int32_t y = (int32_t)begin; y < (int32_t)end; ++y) {
        float theta0 = SSDO_PI * (float)y / (float)b->source_height;
        float theta1 = SSDO_PI * (float)(y + 1) / (float)b->source_height;
        float solid = (cosf(theta0) - cosf(theta1)) * 2.0f * SSDO_PI / (float)b->source_width;
        for (int32_t x = 0; x < b->source_width; ++x) {
            size_t i = (size_t)y * (size_t)b->source_width + (size_t)x;
            drift_vec3 l = source_cell(b, x, y);
            drift_vec3 d =
                ssdo_uv_to_dir(drift_vec2_make(((float)x + 0.5f) / (float)b->source_width,
                                               ((float)y + 0.5f) / (float)b->source_height));
            memcpy(b->source + 3 * i, &l, sizeof(float) * 3);
            b->source_dir[4 * i] = d.x;
            b->source_dir[4 * i + 1] = d.y;
            b->source_dir[4 * i + 2] = d.z;
            b->source_dir[4 * i + 3] = solid;
        }
    }
}

// One output row: every source texel against the cosine lobe and the nine vMF lobes.
static void convolve_rows(size_t begin, size_t end, int thread_index, void *user)
{
    (void)thread_index;
    env_build *b = user;
    drift_ssdo_env *env = b->env;
    size_t source_count = (size_t)b->source_width * (size_t)b->source_height;
    for (int32_t y = (int32_t)begin; y < (int32_t)end; ++y) {
        for (int32_t x = 0; x < env->width; ++x) {
            drift_vec3 n = ssdo_uv_to_dir(drift_vec2_make(((float)x + 0.5f) / (float)env->width,
                                                          ((float)y + 0.5f) / (float)env->height));
            float sum[SSDO_ENV_LEVELS + 1][4]; // float: 8192 terms of one sign
            memset(sum, 0, sizeof(sum));
            for (size_t i = 0; i < source_count; ++i) {
                const float *d = b->source_dir + 4 * i;
                const float *l = b->source + 3 * i;
                float c = n.x * d[0] + n.y * d[1] + n.z * d[2];
                float w[SSDO_ENV_LEVELS + 1];
                w[0] = c > 0.0f ? c : 0.0f;
                float e = expf(c - 1.0f); // exp(2^k (c - 1)) by repeated squaring
                for (int k = 0; k < SSDO_ENV_LEVELS; ++k) {
                    w[k + 1] = e;
                    e *= e;
                }
                for (int k = 0; k <= SSDO_ENV_LEVELS; ++k) {
                    float wk = w[k] * d[3];
                    sum[k][0] += wk * l[0];
                    sum[k][1] += wk * l[1];
                    sum[k][2] += wk * l[2];
                    sum[k][3] += wk;
                }
            }
            size_t o = 3 * ((size_t)y * (size_t)env->width + (size_t)x);
            for (int k = 0; k <= SSDO_ENV_LEVELS; ++k) {
                float *dst = k == 0 ? env->irradiance + o : env->cone[k - 1] + o;
                for (int c = 0; c < 3; ++c) {
                    dst[c] = sum[k][3] > 0.0f ? sum[k][c] / sum[k][3] : 0.0f;
                }
            }
        }
    }
}

static void build_octahedral(drift_ssdo_env *env);

drift_result drift_ssdo_env_create(drift_context *ctx, const drift_scene *scene,
                                   const drift_ssdo_env_desc *desc, drift_ssdo_env **out_env)
{
    if (!out_env) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    *out_env = NULL;
    drift_ssdo_env_desc d = desc ? *desc : (drift_ssdo_env_desc){ 0 };
    d.width = d.width ? d.width : 64;
    d.source_width = d.source_width ? d.source_width : 128;
    if (!ctx || !scene || !scene->committed || d.width < 4 || d.width > 1024 ||
        d.source_width < 4 || d.source_width > 2048) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, __FILE__, __LINE__,
                  "ssdo env: needs a committed scene and map widths in 4..1024 / 4..2048");
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    drift_ssdo_env *env = drift_alloc(ctx, sizeof(*env));
    if (!env) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    env->ctx = ctx;
    env->width = d.width;
    env->height = d.width / 2;
    size_t floats = (size_t)env->width * (size_t)env->height * 3;
    bool ok = (env->irradiance = drift_alloc(ctx, floats * sizeof(float))) != NULL;
    for (int k = 0; k < SSDO_ENV_LEVELS; ++k) {
        ok = ok && (env->cone[k] = drift_alloc(ctx, floats * sizeof(float))) != NULL;
    }
    size_t oct_floats = (size_t)SSDO_OCT_SIZE * SSDO_OCT_SIZE * 3;
    for (int k = 0; k <= SSDO_ENV_LEVELS; ++k) {
        ok = ok && (env->oct[k] = drift_alloc(ctx, oct_floats * sizeof(float))) != NULL;
    }
    if (!ok) {
        drift_ssdo_env_destroy(env);
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    bool textured =
        drift_scene_has_environment(scene) && scene->environment.texture != DRIFT_INVALID_INDEX;
    if (!textured) {
        // Constant (or no) environment: every filter returns the constant exactly.
        drift_vec3 c =
            drift_scene_has_environment(scene) ? scene->environment.color : drift_vec3_splat(0.0f);
        for (size_t i = 0; i < floats; i += 3) {
            float v[3] = { c.x, c.y, c.z };
            memcpy(env->irradiance + i, v, sizeof(v));
            for (int k = 0; k < SSDO_ENV_LEVELS; ++k) {
                memcpy(env->cone[k] + i, v, sizeof(v));
            }
        }
        build_octahedral(env);
        *out_env = env;
        return DRIFT_OK;
    }
    env_build b = { .scene = scene,
                    .source_width = d.source_width,
                    .source_height = d.source_width / 2,
                    .env = env };
    size_t count = (size_t)b.source_width * (size_t)b.source_height;
    b.source = drift_alloc(ctx, count * 3 * sizeof(float));
    b.source_dir = drift_alloc(ctx, count * 4 * sizeof(float));
    if (!b.source || !b.source_dir) {
        drift_free(ctx, b.source);
        drift_free(ctx, b.source_dir);
        drift_ssdo_env_destroy(env);
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    drift_parallel_for(ctx, (size_t)b.source_height, 1, build_source_rows, &b);
    drift_parallel_for(ctx, (size_t)env->height, 1, convolve_rows, &b);
    drift_free(ctx, b.source);
    drift_free(ctx, b.source_dir);
    build_octahedral(env);
    *out_env = env;
    return DRIFT_OK;
}

void drift_ssdo_env_destroy(drift_ssdo_env *env)
{
    if (!env) {
        return;
    }
    drift_free(env->ctx, env->irradiance);
    for (int k = 0; k < SSDO_ENV_LEVELS; ++k) {
        drift_free(env->ctx, env->cone[k]);
    }
    for (int k = 0; k <= SSDO_ENV_LEVELS; ++k) {
        drift_free(env->ctx, env->oct[k]);
    }
    drift_free(env->ctx, env);
}

// Bilinear in the lat-long map, wrapping in longitude and across the poles.
static drift_vec3 lookup(const drift_ssdo_env *env, const float *map, drift_vec3 dir)
{
    drift_vec2 uv = ssdo_dir_to_uv(dir);
    float fx = uv.x * (float)env->width - 0.5f, fy = uv.y * (float)env->height - 0.5f;
    float x0f = floorf(fx), y0f = floorf(fy);
    float tx = fx - x0f, ty = fy - y0f;
    int32_t x0 = (int32_t)x0f, y0 = (int32_t)y0f;
    drift_vec3 r = drift_vec3_splat(0.0f);
    for (int j = 0; j < 2; ++j) {
        // A row past a pole is the row beside it, half way round in longitude.
        int32_t y = y0 + j, shift = 0;
        if (y < 0 || y >= env->height) {
            y = y < 0 ? 0 : env->height - 1;
            shift = env->width / 2;
        }
        float wy = j ? ty : 1.0f - ty;
        for (int i = 0; i < 2; ++i) {
            int32_t x = ((x0 + i + shift) % env->width + env->width) % env->width;
            float w = wy * (i ? tx : 1.0f - tx);
            const float *p = map + 3 * ((size_t)y * (size_t)env->width + (size_t)x);
            r = drift_vec3_fma(r, drift_vec3_make(p[0], p[1], p[2]), w);
        }
    }
    return r;
}

// Bilinear in an octahedral map, clamped at its border.
static drift_vec3 lookup_oct(const float *map, drift_vec3 dir)
{
    drift_vec2 uv = ssdo_dir_to_oct(dir);
    float fx = uv.x * SSDO_OCT_SIZE - 0.5f, fy = uv.y * SSDO_OCT_SIZE - 0.5f;
    fx = drift_clampf(fx, 0.0f, SSDO_OCT_SIZE - 1.001f);
    fy = drift_clampf(fy, 0.0f, SSDO_OCT_SIZE - 1.001f);
    int32_t x0 = (int32_t)fx, y0 = (int32_t)fy;
    float tx = fx - (float)x0, ty = fy - (float)y0;
    const float *p00 = map + 3 * ((size_t)y0 * SSDO_OCT_SIZE + (size_t)x0);
    const float *p10 = p00 + 3, *p01 = p00 + 3 * SSDO_OCT_SIZE, *p11 = p01 + 3;
    float w00 = (1.0f - tx) * (1.0f - ty), w10 = tx * (1.0f - ty), w01 = (1.0f - tx) * ty,
          w11 = tx * ty;
    return drift_vec3_make(w00 * p00[0] + w10 * p10[0] + w01 * p01[0] + w11 * p11[0],
                           w00 * p00[1] + w10 * p10[1] + w01 * p01[1] + w11 * p11[1],
                           w00 * p00[2] + w10 * p10[2] + w01 * p01[2] + w11 * p11[2]);
}

// The octahedral copies, sampled from the lat-long maps at each texel's centre direction.
static void build_octahedral(drift_ssdo_env *env)
{
    for (int k = 0; k <= SSDO_ENV_LEVELS; ++k) {
        const float *src = k == 0 ? env->irradiance : env->cone[k - 1];
        for (int32_t y = 0; y < SSDO_OCT_SIZE; ++y) {
            for (int32_t x = 0; x < SSDO_OCT_SIZE; ++x) {
                drift_vec3 d = ssdo_oct_to_dir(drift_vec2_make(((float)x + 0.5f) / SSDO_OCT_SIZE,
                                                               ((float)y + 0.5f) / SSDO_OCT_SIZE));
                drift_vec3 c = lookup(env, src, d);
                float *dst = env->oct[k] + 3 * ((size_t)y * SSDO_OCT_SIZE + (size_t)x);
                dst[0] = c.x;
                dst[1] = c.y;
                dst[2] = c.z;
            }
        }
    }
}

drift_vec3 drift_ssdo_env_irradiance(const drift_ssdo_env *env, drift_vec3 n)
{
    return lookup_oct(env->oct[0], n);
}

drift_vec3 drift_ssdo_env_radiance(const drift_ssdo_env *env, drift_vec3 dir, int32_t samples)
{
    int k = 0;
    while (k + 1 < SSDO_ENV_LEVELS && (1 << (k + 1)) <= samples) {
        ++k;
    }
    return lookup_oct(env->oct[k + 1], dir);
}
