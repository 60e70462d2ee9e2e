// ISG glossy reflections (Robison & Shirley 2009, section 3.2) over the sharp reflection
// buffer (one mirror ray per pixel: radiance seen, hit distance):
//   search  half extents R_p = theta_max / fov in texture space, per axis (fov_x along x,
//           fov_y along y: the aspect correction), over the reflected distances, range eq. 10:
//           r = exp(-(a l^2 + b n^2) / sigma), l the world distance (eq. 11; or to the
//           centre's tangent plane with isg_range_plane), n = 1 - N_i . N_0
//           (eq. 12) -> E, their average (misses rejected; none found: E = infinity)
//   gather  in direction space (beyond the paper, docs/isg.md): each sample weighted by the
//           centre's lobe toward the point its mirror ray met, over a support of theta_max
//           divided by the angle that direction turns per pixel here (eq. 13's alpha on a
//           plane; on a curved reflector the normal's turn adds to it). Under reflection
//           edits, the paper's gather: support eq. 13 (no eq. 14 cosine), range eq. 10 and a
//           spatial weight 0.1^(rho^2) at fraction rho of the support.
// theta_max comes per pixel from the gloss plane (90% of the lobe). The gathered radiance is
// weighted by the centre's lobe albedo, as the sharp buffer is. Samples on pixels without a
// specular lobe are rejected (their buffer holds no reflection). Mirrors keep the sharp
// reflection. The `blur` baseline gathers over a fixed disk instead.
#include "isg/isg.h"

#include <math.h>

typedef struct range_ctx {
    const drift_gbuffer *g;
    const drift_image *distance; // NULL: any distance
    drift_vec3 p0, n0;
    float a_over_sigma, b_over_sigma;
    bool plane;
    int32_t x0, y0;
    float inv_rx, inv_ry; // 1 / the gather's half extents; 0 in the search (constant weight)
} range_ctx;

static bool has_lobe(const drift_gbuffer *g, int32_t x, int32_t y)
{
    return drift_image_pixel(&g->material_id, x, y)[0] >= 0.0f &&
           !drift_vec3_is_zero(drift_image_get3(&g->specular, x, y));
}

// Eq. 10.
static float range_eq10(const void *user, int32_t x, int32_t y)
{
    const range_ctx *c = user;
    if (!has_lobe(c->g, x, y) ||
        (c->distance && !isfinite(drift_image_pixel(c->distance, x, y)[0]))) {
        return 0.0f;
    }
    // l: the world distance (eq. 11), or the distance to the centre's tangent plane.
    drift_vec3 d = drift_vec3_sub(drift_image_get3(&c->g->position, x, y), c->p0);
    float l = c->plane ? drift_vec3_dot(d, c->n0) : drift_vec3_length(d);
    float n = 1.0f - drift_vec3_dot(drift_image_get3(&c->g->normal, x, y), c->n0);
    // The spatial weight: the Phong lobe across the cone. A sample at fraction rho of the
    // support stands for a direction rho * theta_max off the mirror direction, where
    // cos^n(rho theta_max) ~ 0.1^(rho^2) since cos^n(theta_max) ~ 0.1 (90% of the lobe).
    float u = (float)(x - c->x0) * c->inv_rx, v = (float)(y - c->y0) * c->inv_ry;
    float lobe = -2.3026f * (u * u + v * v);
    return expf(lobe - (c->a_over_sigma * l * l + c->b_over_sigma * n * n));
}

static float range_lobe(const void *user, int32_t x, int32_t y)
{
    const range_ctx *c = user;
    return has_lobe(c->g, x, y) ? 1.0f : 0.0f;
}

// The filter with each range function inlined (isg.h), for 1 or 3 channels.
#define REFLECTION_FILTER(name, range, channels)                                             \
    static DRIFT_AVX2_CLONES float name(const drift_isg_kernel *k, const drift_image *image, \
                                        int32_t x, int32_t y, float *out)                    \
    {                                                                                        \
        return drift_isg_filter_inline(k, range, NULL, image, 0, channels, x, y, out);       \
    }
REFLECTION_FILTER(filter_lobe3, range_lobe, 3)
REFLECTION_FILTER(filter_eq10_1, range_eq10, 1)
REFLECTION_FILTER(filter_eq10_3, range_eq10, 3)
#undef REFLECTION_FILTER

// --- THE GATHER IN DIRECTION SPACE (curved reflectors) ---
// A sample pixel i holds the radiance its mirror ray met at h_i = p_i + d_i r_i. Seen from the
// centre p0, that is light arriving along w_i = normalize(h_i - p0) (r_i itself for a miss), so
// the sample is weighted by the centre's lobe in that direction, f cos ~ D(h) G2(wo, w_i) for
// GGX, cos^n(w_i, r0) (w_i . n0) for Phong. On a plane w_i sweeps the cone as eq. 13 says; on a
// sphere r_i turns twice as fast as the normal, and the world-distance and normal weights of
// eq. 10 (which cut the gather to a few pixels there whatever the cone) are not needed: only
// samples on the centre's mesh, above its tangent plane, count.
typedef struct lobe_ctx {
    const drift_frame_state *f;
    drift_vec3 wo, p0, n0, r0;
    uint32_t mesh;
    bool ggx;
    float alpha2, exponent;
    float lambda_o; // Smith's Lambda(wo), GGX
    int32_t x0, y0;
    float centre_share;        // the centre's weight factor: its one pixel against a sample's area
    const drift_image *points; // the reflected points (isg.h)
} lobe_ctx;

static float smith_lambda(float alpha2, float cos_t)
{
    float c2 = fmaxf(cos_t * cos_t, 1e-8f);
    return 0.5f * (sqrtf(1.0f + alpha2 * (1.0f - c2) / c2) - 1.0f);
}

// w_i of the sample at pixel index i, with the reflected distance d (its own, or the search's E).
static drift_vec3 sample_direction(const lobe_ctx *c, size_t i, float d)
{
    const drift_surface *s = &c->f->gbuffer.surfaces[i];
    drift_vec3 wo = drift_vec3_normalize(drift_vec3_sub(c->f->camera.position, s->position));
    drift_vec3 r = drift_vec3_reflect(wo, s->ns);
    if (!isfinite(d)) {
        return r;
    }
    drift_vec3 h = drift_vec3_add(s->position, drift_vec3_scale(r, d));
    return drift_vec3_normalize(drift_vec3_sub(h, c->p0));
}

static float lobe_weight(const lobe_ctx *c, drift_vec3 wi)
{
    float cos_i = drift_vec3_dot(wi, c->n0);
    if (!(cos_i > 0.0f)) {
        return 0.0f;
    }
    if (!c->ggx) {
        float cos_r = drift_vec3_dot(wi, c->r0);
        return cos_r > 0.0f ? powf(cos_r, c->exponent) * cos_i : 0.0f;
    }
    drift_vec3 h = drift_vec3_normalize(drift_vec3_add(c->wo, wi));
    float ch = drift_vec3_dot(h, c->n0);
    float t = ch * ch * (c->alpha2 - 1.0f) + 1.0f;
    float d = c->alpha2 / (t * t); // GGX's D without 1/pi (the sum is normalised)
    return d / (1.0f + c->lambda_o + smith_lambda(c->alpha2, cos_i));
}

static float range_lobe_direction(const void *user, int32_t x, int32_t y)
{
    const lobe_ctx *c = user;
    size_t i = (size_t)y * (size_t)c->f->params.width + (size_t)x;
    const float *h = drift_image_pixel(c->points, x, y);
    if (!(h[3] >= 0.0f) || c->f->gbuffer.mesh_index[i] != c->mesh) {
        return 0.0f;
    }
    drift_vec3 w = drift_vec3_make(h[0], h[1], h[2]);
    if (h[3] > 0.0f) {
        w = drift_vec3_normalize(drift_vec3_sub(w, c->p0));
    }
    float weight = lobe_weight(c, w);
    return x == c->x0 && y == c->y0 ? weight * c->centre_share : weight;
}

// Fills the reflected-point buffer (isg.h) the gather reads, once per frame: a sample then
// costs one read and one normalisation.
static void point_pixel(drift_frame_state *f, int32_t x, int32_t y, uint64_t *rays, void *user)
{
    (void)rays;
    (void)user;
    float *out = drift_image_pixel(&drift_isg_of(f)->reflection_points, x, y);
    size_t i = (size_t)y * (size_t)f->params.width + (size_t)x;
    if (!has_lobe(&f->gbuffer, x, y) || f->gbuffer.surfaces[i].material == DRIFT_INVALID_INDEX) {
        out[0] = out[1] = out[2] = 0.0f;
        out[3] = -1.0f;
        return;
    }
    const drift_surface *s = &f->gbuffer.surfaces[i];
    drift_vec3 wo = drift_vec3_normalize(drift_vec3_sub(f->camera.position, s->position));
    drift_vec3 r = drift_vec3_reflect(wo, s->ns);
    float d = drift_image_pixel(&f->reflection_distance, x, y)[0];
    drift_vec3 h = isfinite(d) ? drift_vec3_add(s->position, drift_vec3_scale(r, d)) : r;
    out[0] = h.x;
    out[1] = h.y;
    out[2] = h.z;
    out[3] = isfinite(d) ? 1.0f : 0.0f;
}

// Radians w turns per pixel along (dx, dy) at (x, y), w taken at the searched distance E for
// every neighbour (its own distance jumps at the edges of what it reflects): a central
// difference over the centre's mesh, one-sided at its edge, 0 with no neighbour on it.
static float direction_rate(const lobe_ctx *c, int32_t x, int32_t y, int32_t dx, int32_t dy,
                            float reflected_distance)
{
    const drift_frame_state *f = c->f;
    drift_vec3 w[2];
    int32_t n = 0;
    for (int32_t side = -1; side <= 1; side += 2) {
        int32_t sx = x + side * dx, sy = y + side * dy;
        if (sx < 0 || sy < 0 || sx >= f->params.width || sy >= f->params.height) {
            continue;
        }
        size_t i = (size_t)sy * (size_t)f->params.width + (size_t)sx;
        if (f->gbuffer.mesh_index[i] == c->mesh && has_lobe(&f->gbuffer, sx, sy)) {
            w[n++] = sample_direction(c, i, reflected_distance);
        }
    }
    if (n == 0) {
        return 0.0f;
    }
    drift_vec3 a = n == 2 ? w[1] : c->r0;
    float cos_w = fminf(fmaxf(drift_vec3_dot(w[0], a), -1.0f), 1.0f);
    return acosf(cos_w) / (n == 2 ? 2.0f : 1.0f);
}

static DRIFT_AVX2_CLONES float filter_direction3(const drift_isg_kernel *k,
                                                 const drift_image *image, int32_t x, int32_t y,
                                                 float *out)
{
    return drift_isg_filter_inline(k, range_lobe_direction, NULL, image, 0, 3, x, y, out);
}

// The gather in direction space at (x, y) into *out; returns its support's larger half extent
// (pixels; under half a pixel nothing was gathered). The support is the cone theta_max over
// the rate at which w turns per pixel here, per axis (eq. 13's alpha on a plane, where the
// parallax of the reflected points sets the rate; on a sphere the normal's turn adds twice its
// angle), within a quarter of the image.
static float direction_gather(drift_frame_state *f, const drift_bsdf *bsdf, drift_vec3 wo,
                              int32_t x, int32_t y, float theta, float reflected_distance,
                              drift_isg_jitter jitter, drift_vec3 *out)
{
    const drift_hybrid_params *p = &f->params;
    drift_isg_state *s = drift_isg_of(f);
    size_t index = (size_t)y * (size_t)p->width + (size_t)x;
    const drift_surface *surface = &f->gbuffer.surfaces[index];
    float a = fmaxf(bsdf->ggx.alpha, 1e-3f);
    lobe_ctx lc = { .f = f,
                    .wo = wo,
                    .p0 = surface->position,
                    .n0 = surface->ns,
                    .r0 = drift_vec3_reflect(wo, surface->ns),
                    .mesh = f->gbuffer.mesh_index[index],
                    .ggx = bsdf->type == DRIFT_MATERIAL_GGX,
                    .alpha2 = a * a,
                    .exponent = bsdf->exponent,
                    .x0 = x,
                    .y0 = y,
                    .points = &s->reflection_points };
    lc.lambda_o = smith_lambda(lc.alpha2, drift_vec3_dot(wo, surface->ns));
    float rate_x = direction_rate(&lc, x, y, 1, 0, reflected_distance);
    float rate_y = direction_rate(&lc, x, y, 0, 1, reflected_distance);
    float cap = 0.25f * (float)(p->width > p->height ? p->width : p->height);
    float cone = fminf(theta, 0.5f * DRIFT_PI);
    drift_vec2 radius = drift_vec2_make(rate_x > 0.0f ? fminf(cone / rate_x, cap) : 0.0f,
                                        rate_y > 0.0f ? fminf(cone / rate_y, cap) : 0.0f);
    if (fmaxf(radius.x, radius.y) < 0.5f) {
        return 0.0f;
    }
    // Each of the N samples stands for pi R_x R_y / N pixels of the support, the centre for its
    // own pixel: weighted alike, the centre stood out and a thin bright line reflected on a
    // sphere stayed 0.66x as wide as the path tracer's (1.06x with this share).
    float area = DRIFT_PI * fmaxf(radius.x, 0.5f) * fmaxf(radius.y, 0.5f) / (float)s->gather.count;
    lc.centre_share = fminf(1.0f / fmaxf(area, 1e-6f), 1.0f);
    drift_isg_kernel gather = { &s->gather, jitter, radius, range_lobe_direction, &lc, NULL };
    filter_direction3(&gather, &f->reflection_reflected, x, y, &out->x);
    return fmaxf(radius.x, radius.y);
}

typedef struct reflection_job {
    float fov_x, fov_y;
} reflection_job;

static void reflection_pixel(drift_frame_state *f, int32_t x, int32_t y, uint64_t *rays, void *user)
{
    (void)rays;
    const reflection_job *job = user;
    const drift_gbuffer *g = &f->gbuffer;
    const drift_hybrid_params *p = &f->params;
    drift_isg_state *s = drift_isg_of(f);
    float *search_out = drift_image_pixel(&s->reflection_search, x, y);
    search_out[0] = INFINITY;
    search_out[1] = 0.0f;
    size_t index = (size_t)y * (size_t)p->width + (size_t)x;
    const drift_surface *surface = &g->surfaces[index];
    float theta = drift_image_pixel(&g->gloss, x, y)[0];
    if (!has_lobe(g, x, y) || !(theta > 0.0f) || surface->material == DRIFT_INVALID_INDEX) {
        return; // no reflection, or a mirror: the sharp buffer stands
    }
    drift_bsdf bsdf = drift_bsdf_make(f->scene, surface);
    if (bsdf.type == DRIFT_MATERIAL_MIRROR || drift_bsdf_is_glass(&bsdf)) {
        return; // delta lobes and glass: the sharp buffer stands (it holds the light glass
                // lets through; a rough pane's reflection, a few percent, stays sharp)
    }
    drift_vec3 wo = drift_pass_wo(f, x, y);
    range_ctx rc = { .g = g,
                     .distance = &f->reflection_distance,
                     .p0 = drift_image_get3(&g->position, x, y),
                     .n0 = drift_image_get3(&g->normal, x, y),
                     .a_over_sigma = p->isg.a / p->isg.sigma,
                     .b_over_sigma = p->isg.b / p->isg.sigma,
                     .plane = p->isg.range_plane,
                     .x0 = x,
                     .y0 = y };
    drift_isg_jitter jitter =
        drift_isg_jitter_at(drift_hash_u32(p->seed ^ DRIFT_STREAM_ISG_REFLECTIONS), x, y);
    drift_vec3 gathered;
    if (p->reflections == DRIFT_REFLECTIONS_BLUR) {
        drift_isg_kernel k = {
            &s->gather, jitter, drift_vec2_make(p->isg.blur_radius, p->isg.blur_radius),
            range_lobe, &rc,    NULL
        };
        filter_lobe3(&k, &f->reflection_reflected, x, y, &gathered.x);
    } else {
        float scale_x = (float)p->width / job->fov_x, scale_y = (float)p->height / job->fov_y;
        drift_vec2 search_radius = drift_vec2_make(theta * scale_x, theta * scale_y);
        if (fmaxf(search_radius.x, search_radius.y) < 0.5f) {
            return; // a lobe under half a pixel: the sharp reflection
        }
        drift_isg_kernel search = { &s->search, jitter, search_radius, range_eq10, &rc, NULL };
        float reflected_distance;
        if (!(filter_eq10_1(&search, &f->reflection_distance, x, y, &reflected_distance) > 0.0f)) {
            reflected_distance = INFINITY; // nothing reflected in reach: the environment
        }
        float eye_distance = drift_vec3_length(drift_vec3_sub(f->camera.position, rc.p0));
        float alpha = drift_isg_gloss_alpha(theta, eye_distance, reflected_distance);
        // No eq. 14: its cos(theta_incident) tightens a half-vector (Blinn-Phong) lobe at
        // grazing angles, but drift's Phong lobe is a cone about the mirror direction at any
        // angle, and a flat reflector shows the virtual image undistorted, so the cone stays
        // alpha wide on screen. With the cosine, a Phong-100 floor seen at grazing view blurred
        // 3-5x too little (a ghost of the dragon in the open glossy room, issue 17).
        drift_vec2 gather_radius = drift_vec2_make(alpha * scale_x, alpha * scale_y);
        if (!p->reflection_edits) {
            float radius =
                direction_gather(f, &bsdf, wo, x, y, theta, reflected_distance, jitter, &gathered);
            search_out[0] = reflected_distance;
            search_out[1] = radius;
            if (radius < 0.5f) {
                return;
            }
            drift_image_set3(&f->reflections, x, y,
                             drift_vec3_mul(drift_raster_reflection_weight(&bsdf, wo), gathered));
            return;
        }
        search_out[0] = reflected_distance;
        search_out[1] = fmaxf(gather_radius.x, gather_radius.y);
        if (search_out[1] < 0.5f) {
            return;
        }
        rc.distance = NULL; // the gather reads radiance; a miss has radiance too
        rc.inv_rx = 1.0f / fmaxf(gather_radius.x, 1e-6f);
        rc.inv_ry = 1.0f / fmaxf(gather_radius.y, 1e-6f);
        drift_isg_kernel gather = { &s->gather, jitter, gather_radius, range_eq10, &rc, NULL };
        filter_eq10_3(&gather, &f->reflection_reflected, x, y, &gathered.x);
    }
    drift_image_set3(&f->reflections, x, y,
                     drift_vec3_mul(drift_raster_reflection_weight(&bsdf, wo), gathered));
}

drift_result drift_isg_pass_reflections(drift_frame_state *f, const drift_pass_args *args)
{
    (void)args;
    double t = drift_time_now();
    drift_result r = drift_isg_prepare(f);
    if (r != DRIFT_OK) {
        return r;
    }
    reflection_job job = { .fov_x = drift_isg_fov_x(&f->camera, f->params.width, f->params.height),
                           .fov_y = f->camera.fov_y };
    if (f->params.reflections == DRIFT_REFLECTIONS_ISG && !f->params.reflection_edits) {
        drift_pass_for_each_pixel(f, point_pixel, NULL);
    }
    drift_pass_for_each_pixel(f, reflection_pixel, &job);
    f->stats.ms[DRIFT_PASS_ISG] += 1000.0 * (drift_time_now() - t);
    return DRIFT_OK;
}
