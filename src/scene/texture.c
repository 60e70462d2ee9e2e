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
