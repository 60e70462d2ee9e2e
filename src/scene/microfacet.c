// GGX (Trowbridge-Reitz) microfacet building blocks: the distribution, Smith's masking, the
// visible-normal sampling of Heitz 2018, Fresnel terms, and the integrals of the directional
// albedo that scripts/gen_ggx_tables.sh tabulates for the energy compensation of
// DRIFT_MATERIAL_GGX (Kulla & Conty 2017, "Revisiting Physically Based Shading at Imageworks").
#include "microfacet.h"

#include <complex.h>
#include <math.h>

float drift__ggx_d(float alpha, drift_vec3 m)
{
    if (m.z <= 0.0f) {
        return 0.0f;
    }
    float a2 = alpha * alpha;
    float t = (a2 - 1.0f) * m.z * m.z + 1.0f;
    return a2 / (DRIFT_PI * t * t);
}

float drift__ggx_lambda(float alpha, drift_vec3 w)
{
    float z2 = w.z * w.z;
    if (z2 <= 0.0f) {
        return INFINITY;
    }
    float tan2 = fmaxf(0.0f, 1.0f - z2) / z2;
    return 0.5f * (-1.0f + sqrtf(1.0f + alpha * alpha * tan2));
}

drift_vec3 drift__ggx_sample_vndf(float alpha, drift_vec3 wo, drift_vec2 u)
{
    // Stretch to the hemisphere configuration, sample the projected disk, unstretch.
    drift_vec3 vh = drift_vec3_normalize(drift_vec3_make(alpha * wo.x, alpha * wo.y, wo.z));
    float lensq = vh.x * vh.x + vh.y * vh.y;
    drift_vec3 t1 = lensq > 0.0f
                        ? drift_vec3_scale(drift_vec3_make(-vh.y, vh.x, 0.0f), 1.0f / sqrtf(lensq))
                        : drift_vec3_make(1.0f, 0.0f, 0.0f);
    drift_vec3 t2 = drift_vec3_cross(vh, t1);
    float r = sqrtf(u.x), phi = 2.0f * DRIFT_PI * u.y;
    float p1 = r * cosf(phi), p2 = r * sinf(phi);
    float s = 0.5f * (1.0f + vh.z);
    p2 = (1.0f - s) * sqrtf(fmaxf(0.0f, 1.0f - p1 * p1)) + s * p2;
    float p3 = sqrtf(fmaxf(0.0f, 1.0f - p1 * p1 - p2 * p2));
    drift_vec3 nh =
        drift_vec3_add(drift_vec3_add(drift_vec3_scale(t1, p1), drift_vec3_scale(t2, p2)),
                       drift_vec3_scale(vh, p3));
    return drift_vec3_normalize(drift_vec3_make(alpha * nh.x, alpha * nh.y, fmaxf(1e-6f, nh.z)));
}

float drift__ggx_pdf_vndf(float alpha, drift_vec3 wo, drift_vec3 m)
{
    float wo_m = drift_vec3_dot(wo, m);
    if (wo.z <= 0.0f || wo_m <= 0.0f) {
        return 0.0f;
    }
    float g1 = 1.0f / (1.0f + drift__ggx_lambda(alpha, wo));
    return g1 * wo_m * drift__ggx_d(alpha, m) / wo.z;
}

float drift__fresnel_dielectric(float cos_i, float eta)
{
    cos_i = drift_clampf(cos_i, -1.0f, 1.0f);
    if (cos_i < 0.0f) {
        eta = 1.0f / eta;
        cos_i = -cos_i;
    }
    float sin2_t = (1.0f - cos_i * cos_i) / (eta * eta);
    if (sin2_t >= 1.0f) {
        return 1.0f;
    }
    float cos_t = sqrtf(fmaxf(0.0f, 1.0f - sin2_t));
    float r_parl = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    float r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    return 0.5f * (r_parl * r_parl + r_perp * r_perp);
}

static float fresnel_complex(float cos_i, float eta, float k)
{
    cos_i = drift_clampf(cos_i, 0.0f, 1.0f);
    float complex n = eta + k * I;
    float complex sin2_t = (1.0f - cos_i * cos_i) / (n * n);
    float complex cos_t = csqrtf(1.0f - sin2_t);
    float complex r_parl = (n * cos_i - cos_t) / (n * cos_i + cos_t);
    float complex r_perp = (cos_i - n * cos_t) / (cos_i + n * cos_t);
    float a = cabsf(r_parl), b = cabsf(r_perp);
    return 0.5f * (a * a + b * b);
}

drift_vec3 drift__fresnel_conductor(float cos_i, drift_vec3 eta, drift_vec3 k)
{
    return drift_vec3_make(fresnel_complex(cos_i, eta.x, k.x), fresnel_complex(cos_i, eta.y, k.y),
                           fresnel_complex(cos_i, eta.z, k.z));
}

static void tint_channel(float f0, float g, float *eta, float *k)
{
    float r = drift_clampf(f0, 0.0f, 0.99f);
    g = drift_clampf(g, 0.0f, 1.0f);
    float sr = sqrtf(r);
    float n_min = (1.0f - r) / (1.0f + r), n_max = (1.0f + sr) / (1.0f - sr);
    float n = g * n_min + (1.0f - g) * n_max;
    float k2 = ((n + 1.0f) * (n + 1.0f) * r - (n - 1.0f) * (n - 1.0f)) / (1.0f - r);
    *eta = n;
    *k = sqrtf(fmaxf(0.0f, k2));
}

void drift__conductor_from_tint(drift_vec3 f0, drift_vec3 g, drift_vec3 *eta, drift_vec3 *k)
{
    tint_channel(f0.x, g.x, &eta->x, &k->x);
    tint_channel(f0.y, g.y, &eta->y, &k->y);
    tint_channel(f0.z, g.z, &eta->z, &k->z);
}

bool drift__refract(drift_vec3 wi, drift_vec3 n, float eta, drift_vec3 *out_wt)
{
    float cos_i = drift_vec3_dot(n, wi);
    if (cos_i < 0.0f) {
        eta = 1.0f / eta;
        cos_i = -cos_i;
        n = drift_vec3_neg(n);
    }
    float sin2_t = fmaxf(0.0f, 1.0f - cos_i * cos_i) / (eta * eta);
    if (sin2_t >= 1.0f) {
        return false;
    }
    float cos_t = sqrtf(1.0f - sin2_t);
    *out_wt = drift_vec3_add(drift_vec3_scale(drift_vec3_neg(wi), 1.0f / eta),
                             drift_vec3_scale(n, cos_i / eta - cos_t));
    return true;
}

// --- ALBEDO INTEGRALS ---

float drift__ggx_grid_alpha(int j, int n)
{
    float r = (float)j / (float)(n - 1);
    return fmaxf(DRIFT_GGX_TABLE_ALPHA_LOW, r * r);
}

float drift__ggx_grid_mu_d(int i)
{
    return fmaxf(0.01f, (float)i / (float)(DRIFT_GGX_TABLE_D_MU_N - 1));
}

float drift__ggx_eta_coord(float eta)
{
    float r = (eta - 1.0f) / (eta + 1.0f),
          r0 = (DRIFT_GGX_TABLE_ETA_MIN - 1.0f) / (DRIFT_GGX_TABLE_ETA_MIN + 1.0f);
    float r1 = (DRIFT_GGX_TABLE_ETA_MAX - 1.0f) / (DRIFT_GGX_TABLE_ETA_MAX + 1.0f);
    return (r - r0) / (r1 - r0) * (float)(DRIFT_GGX_TABLE_ETA_N - 1);
}

float drift__ggx_grid_eta(int e)
{
    float r0 = (DRIFT_GGX_TABLE_ETA_MIN - 1.0f) / (DRIFT_GGX_TABLE_ETA_MIN + 1.0f);
    float r1 = (DRIFT_GGX_TABLE_ETA_MAX - 1.0f) / (DRIFT_GGX_TABLE_ETA_MAX + 1.0f);
    float r = r0 + (r1 - r0) * (float)e / (float)(DRIFT_GGX_TABLE_ETA_N - 1);
    return (1.0f + r) / (1.0f - r);
}

static drift_vec3 dir_of_mu(float mu)
{
    return drift_vec3_make(sqrtf(fmaxf(0.0f, 1.0f - mu * mu)), 0.0f, mu);
}

// By visible-normal sampling on a strata x strata grid: each sample's weight is F G2 / G1(wo).
void drift__ggx_integrate_reflection(float mu, float alpha, int strata, float *e1, float *es)
{
    drift_vec3 wo = dir_of_mu(mu);
    float lo = drift__ggx_lambda(alpha, wo);
    double s1 = 0.0, s5 = 0.0;
    for (int a = 0; a < strata; ++a) {
        for (int b = 0; b < strata; ++b) {
            drift_vec2 u = drift_vec2_make((a + 0.5f) / (float)strata, (b + 0.5f) / (float)strata);
            drift_vec3 m = drift__ggx_sample_vndf(alpha, wo, u);
            float wo_m = drift_vec3_dot(wo, m);
            drift_vec3 wi = drift_vec3_sub(drift_vec3_scale(m, 2.0f * wo_m), wo);
            if (wi.z <= 0.0f) {
                continue;
            }
            float w = (1.0f + lo) / (1.0f + lo + drift__ggx_lambda(alpha, wi));
            float c = 1.0f - wo_m, c5 = (c * c) * (c * c) * c;
            s1 += (double)w;
            s5 += (double)(w * c5);
        }
    }
    *e1 = (float)(s1 / (strata * strata));
    *es = (float)(s5 / (strata * strata));
}

float drift__ggx_integrate_dielectric(float mu, float alpha, float eta, int strata)
{
    drift_vec3 wo = dir_of_mu(mu);
    float lo = drift__ggx_lambda(alpha, wo);
    double sum = 0.0;
    for (int a = 0; a < strata; ++a) {
        for (int b = 0; b < strata; ++b) {
            drift_vec2 u = drift_vec2_make((a + 0.5f) / (float)strata, (b + 0.5f) / (float)strata);
            drift_vec3 m = drift__ggx_sample_vndf(alpha, wo, u);
            float wo_m = drift_vec3_dot(wo, m);
            float f = drift__fresnel_dielectric(wo_m, eta);
            drift_vec3 wr = drift_vec3_sub(drift_vec3_scale(m, 2.0f * wo_m), wo);
            if (wr.z > 0.0f) {
                sum += (double)(f * (1.0f + lo) / (1.0f + lo + drift__ggx_lambda(alpha, wr)));
            }
            drift_vec3 wt;
            if (f < 1.0f && drift__refract(wo, m, eta, &wt) && wt.z < 0.0f) {
                sum +=
                    (double)((1.0f - f) * (1.0f + lo) / (1.0f + lo + drift__ggx_lambda(alpha, wt)));
            }
        }
    }
    return (float)(sum / (strata * strata));
}

// --- THE MULTIPLE-SCATTERING LOBE'S SCALE ---

float drift__ggx_ms_alpha(float alpha)
{
    // Cycles 3.4's random walk keeps a rough metal's multiply scattered light nearer the
    // specular direction than a lobe 2.5 times as wide (issue 41 s6: at r 0.8 the old width
    // was 0.89-1.20x Cycles at theta >= 70 degrees, back-scattering too bright).
    float a = fmaxf(alpha, DRIFT_GGX_MIN_ALPHA), r = sqrtf(a);
    float t =
        drift_clampf((r - DRIFT_GGX_MS_WIDTH_KNEE) / (1.0f - DRIFT_GGX_MS_WIDTH_KNEE), 0.0f, 1.0f);
    return (DRIFT_GGX_MS_WIDTH + t * (DRIFT_GGX_MS_WIDTH_ROUGH - DRIFT_GGX_MS_WIDTH)) * a;
}

float drift__ggx_ms_beta(float alpha)
{
    // Cycles 3.4's walk at r >= 0.65 is 2-11% above the widened lobe where wo and wi are both
    // grazing (theta >= 70) and 1-2% below it in between (issue 41 s7: r 0.8, rms log over 102
    // values 0.034 -> 0.019, the grazing pairs' mean -3.9% -> -0.6%); at r <= 0.5 it is not.
    float r = sqrtf(fmaxf(alpha, DRIFT_GGX_MIN_ALPHA));
    return fmaxf(0.0f, r - DRIFT_GGX_MS_BETA_KNEE) * DRIFT_GGX_MS_BETA_SLOPE;
}

float drift__ggx_ms_kernel(float beta, float mu_o, float mu_i)
{
    float t = (1.0f - mu_o) * (1.0f - mu_i);
    return 1.0f + beta * t * t;
}

float drift__ggx_fit_ms_scale(float alpha, const float *e1, int strata, float *out_scale)
{
    enum {
        MU = DRIFT_GGX_TABLE_MU_N
    };

    float ms_alpha = drift__ggx_ms_alpha(alpha), beta = drift__ggx_ms_beta(alpha);

    // b[i][j]: the albedo at mu_i of the broad lobe (with its kernel) weighted by the hat function
    // of grid point j in mu_i (the table's linear interpolation, constant beyond the end cells).
    double b[MU][MU];
    for (int i = 0; i < MU; ++i) {
        drift_vec3 wo = dir_of_mu((i + 0.5f) / MU);
        float lo = drift__ggx_lambda(ms_alpha, wo);
        for (int j = 0; j < MU; ++j) {
            b[i][j] = 0.0;
        }
        for (int u0 = 0; u0 < strata; ++u0) {
            for (int u1 = 0; u1 < strata; ++u1) {
                drift_vec2 u =
                    drift_vec2_make((u0 + 0.5f) / (float)strata, (u1 + 0.5f) / (float)strata);
                drift_vec3 m = drift__ggx_sample_vndf(ms_alpha, wo, u);
                drift_vec3 wi =
                    drift_vec3_sub(drift_vec3_scale(m, 2.0f * drift_vec3_dot(wo, m)), wo);
                if (wi.z <= 0.0f) {
                    continue;
                }
                double li = (double)drift__ggx_lambda(ms_alpha, wi);
                double w = (1.0 + (double)lo) / (1.0 + (double)lo + li) *
                           (double)drift__ggx_ms_kernel(beta, wo.z, wi.z);
                double x = fmin(fmax((double)wi.z * MU - 0.5, 0.0), MU - 1.0);
                int j = x >= MU - 1 ? MU - 2 : (int)x;
                b[i][j] += w * (j + 1 - x);
                b[i][j + 1] += w * (x - j);
            }
        }
        for (int j = 0; j < MU; ++j) {
            b[i][j] /= (double)strata * strata;
        }
    }
    // Symmetric Sinkhorn-Knopp (Knight 2008): s <- sqrt(s t / (B s)), the geometric mean of s
    // and the one-sided update, converges to s_i (B s)_i = t_i for B near symmetric.
    double s[MU], t[MU], bs[MU], residual = 0.0;
    for (int i = 0; i < MU; ++i) {
        t[i] = fmax(0.0, 1.0 - (double)e1[i]);
        s[i] = 1.0;
    }
    for (int iter = 0; iter < 4000; ++iter) {
        residual = 0.0;
        for (int i = 0; i < MU; ++i) {
            bs[i] = 0.0;
            for (int j = 0; j < MU; ++j) {
                bs[i] += b[i][j] * s[j];
            }
            residual = fmax(residual, fabs(s[i] * bs[i] - t[i]));
        }
        if (residual < 1e-7) {
            break;
        }
        for (int i = 0; i < MU; ++i) {
            s[i] = bs[i] > 0.0 ? sqrt(s[i] * t[i] / bs[i]) : 0.0;
        }
    }
    for (int i = 0; i < MU; ++i) {
        out_scale[i] = (float)s[i];
    }
    return (float)residual;
}

float drift__ggx_reflect_ss(float alpha, drift_vec3 wo, drift_vec3 wi, drift_vec3 *out_h)
{
    drift_vec3 h = drift_vec3_add(wo, wi);
    float len = drift_vec3_length(h);
    if (!(len > 0.0f)) {
        return 0.0f;
    }
    h = drift_vec3_scale(h, 1.0f / len);
    *out_h = h;
    float g2 = 1.0f / (1.0f + drift__ggx_lambda(alpha, wo) + drift__ggx_lambda(alpha, wi));
    return drift__ggx_d(alpha, h) * g2 / (4.0f * wo.z * wi.z);
}

float drift__ggx_reflect_pdf(float alpha, drift_vec3 wo, drift_vec3 wi)
{
    drift_vec3 h = drift_vec3_add(wo, wi);
    float len = drift_vec3_length(h);
    if (!(len > 0.0f)) {
        return 0.0f;
    }
    h = drift_vec3_scale(h, 1.0f / len);
    float wo_h = drift_vec3_dot(wo, h);
    return wo_h > 0.0f ? drift__ggx_pdf_vndf(alpha, wo, h) / (4.0f * wo_h) : 0.0f;
}
