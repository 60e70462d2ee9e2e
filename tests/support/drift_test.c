#include "drift_test.h"

#include "drift/math.h"
#include "drift/scene.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static void capture_log(drift_log_level level, drift_result code, const char *file, int line,
                        const char *message, void *user)
{
    test_log_capture *c = user;
    (void)file;
    (void)line;
    c->count++;
    if (level == DRIFT_LOG_WARNING) {
        c->warnings++;
    }
    if (level == DRIFT_LOG_ERROR) {
        c->errors++;
    }
    c->last_code = code;
    snprintf(c->last_message, sizeof(c->last_message), "%s", message);
    if (getenv("DRIFT_TEST_VERBOSE")) {
        fprintf(stderr, "[log %d] %s:%d: %s\n", (int)level, file ? file : "-", line, message);
    }
}

// DRIFT_TEST_FILTER=PATTERN runs only the cmocka tests whose names match it (cmocka's * and ?),
// e.g. `DRIFT_TEST_FILTER='test_aa_*' build/dev/test_hybrid`: a developer times or debugs one.
__attribute__((constructor)) static void filter_from_environment(void)
{
    const char *pattern = getenv("DRIFT_TEST_FILTER");
    if (pattern && *pattern) {
        cmocka_set_test_filter(pattern);
    }
}

drift_logger test_capture_logger(test_log_capture *capture)
{
    return (drift_logger){ .func = capture ? capture_log : NULL, .user = capture };
}

drift_context *test_context(int threads, test_log_capture *capture)
{
    drift_context *ctx = NULL;
    drift_result r = drift_context_create(
        &(drift_context_desc){ .thread_count = threads, .logger = test_capture_logger(capture) },
        &ctx);
    if (r != DRIFT_OK) {
        fail_msg("drift_context_create: %s", drift_result_string(r));
    }
    return ctx;
}

const char *test_repo_path(char *out, const char *relative)
{
    snprintf(out, 1024, "%s/%s", DRIFT_SOURCE_DIR, relative);
    return out;
}

const char *test_shared_path(char *out, const char *relative)
{
    snprintf(out, 1024, "%s/../shared/%s", DRIFT_SOURCE_DIR, relative);
    return out;
}

const char *test_out_path(char *out, const char *name)
{
    mkdir(DRIFT_BINARY_DIR "/test-out", 0755);
    snprintf(out, 1024, "%s/test-out/%s", DRIFT_BINARY_DIR, name);
    return out;
}

double test_intensity(void)
{
    const char *s = getenv("DRIFT_TEST_INTENSITY");
    double v = s ? strtod(s, NULL) : 1.0;
    return v > 0.0 ? v : 1.0;
}

void test_assert_close(double a, double b, double eps, int line)
{
    if (!(fabs(a - b) <= eps)) {
        fail_msg("line %d: %.17g vs %.17g (eps %g)", line, a, b, eps);
    }
}

float test_hash_unit(uint32_t i)
{
    return drift_u32_to_unit(drift_hash_u32(i));
}

uint32_t test_add_mesh(struct drift_scene *scene, const float *positions, uint32_t vertex_count,
                       const uint32_t *indices, uint32_t triangle_count, uint32_t material)
{
    uint32_t index = DRIFT_INVALID_INDEX;
    drift_result r = drift_scene_add_mesh(scene,
                                          &(drift_mesh_desc){ .positions = positions,
                                                              .vertex_count = vertex_count,
                                                              .indices = indices,
                                                              .triangle_count = triangle_count,
                                                              .material = material },
                                          &index);
    if (r != DRIFT_OK) {
        fail_msg("drift_scene_add_mesh: %s", drift_result_string(r));
    }
    return index;
}

// --- CHI-SQUARE (pbrt-v3's and Mitsuba's approach) ---

#ifndef M_PI
#    define M_PI 3.14159265358979323846
#endif

#define THETA_BINS 16
#define PHI_BINS   32

// Upper quantile of the chi-square distribution (Wilson-Hilferty approximation), for
// significance 1e-3 per test: z = 3.09.
static double chi2_critical(int dof)
{
    double k = (double)dof, z = 3.09;
    double t = 1.0 - 2.0 / (9.0 * k) + z * sqrt(2.0 / (9.0 * k));
    return k * t * t * t;
}

static drift_vec3 sphere_dir(double cos_theta, double phi)
{
    double s = sqrt(fmax(0.0, 1.0 - cos_theta * cos_theta));
    return drift_vec3_make((float)(s * cos(phi)), (float)(s * sin(phi)), (float)cos_theta);
}

// Binning uses +y as its pole: every tested lobe lies in the xz plane, so it sits on the
// binning equator where equal-area bins are well shaped (near a pole they are slivers and
// the per-bin quadrature of a sharp lobe fails).
static drift_vec3 bin_dir(double cos_theta, double phi)
{
    drift_vec3 d = sphere_dir(cos_theta, phi);
    return drift_vec3_make(d.y, d.z, d.x);
}

// Bins sampled directions over (cos theta, phi) of the whole sphere and compares with the
// pdf integrated over each bin. Bins expecting fewer than 5 samples are pooled. Returns
// false, with the reason in `why`, when the sampler and pdf disagree.
bool test_chi_square_passes(const char *what, test_pdf_fn pdf, test_sample_fn sample, void *user,
                            int sample_count, int quadrature, char *why, size_t why_size)
{
    static double observed[THETA_BINS * PHI_BINS], expected[THETA_BINS * PHI_BINS];
    memset(observed, 0, sizeof(observed));
    memset(expected, 0, sizeof(expected));
    int failed = 0;
    for (int i = 0; i < sample_count; ++i) {
        drift_sampler s = drift_sampler_make(11, 0, (uint32_t)i);
        drift_vec2 u = drift_sampler_next2(&s);
        float u_lobe = drift_sampler_next1(&s);
        drift_vec3 wi;
        if (!sample(user, u, u_lobe, &wi)) {
            failed++;
            continue;
        }
        double ct = fmax(-1.0, fmin(1.0, (double)wi.y));
        double phi = atan2((double)wi.x, (double)wi.z);
        if (phi < 0.0) {
            phi += 2.0 * M_PI;
        }
        int ti = (int)((ct + 1.0) * 0.5 * THETA_BINS), pi = (int)(phi / (2.0 * M_PI) * PHI_BINS);
        ti = ti >= THETA_BINS ? THETA_BINS - 1 : ti;
        pi = pi >= PHI_BINS ? PHI_BINS - 1 : pi;
        observed[ti * PHI_BINS + pi] += 1.0;
    }
    // Integrate the pdf over each bin with a midpoint rule (bins are equal-area); fine enough
    // that the quadrature error stays far below the 1% tolerance for lobes up to n = 300.
    double integral = 0.0;
    const int sub = quadrature;
    double bin_area = (2.0 / THETA_BINS) * (2.0 * M_PI / PHI_BINS);
    for (int ti = 0; ti < THETA_BINS; ++ti) {
        for (int pi = 0; pi < PHI_BINS; ++pi) {
            double acc = 0.0;
            for (int a = 0; a < sub; ++a) {
                for (int b = 0; b < sub; ++b) {
                    double ct = -1.0 + (ti + (a + 0.5) / sub) * (2.0 / THETA_BINS);
                    double phi = (pi + (b + 0.5) / sub) * (2.0 * M_PI / PHI_BINS);
                    acc += (double)pdf(user, bin_dir(ct, phi));
                }
            }
            double p = acc / (sub * sub) * bin_area;
            expected[ti * PHI_BINS + pi] = p * sample_count;
            integral += p;
        }
    }
    // The pdf integrates to the probability that sampling succeeds.
    double success = 1.0 - (double)failed / sample_count;
    if (fabs(integral - success) > 0.01) {
        snprintf(why, why_size, "%s: pdf integrates to %.4f but sampling succeeds %.4f of the time",
                 what, integral, success);
        return false;
    }
    double chi2 = 0.0, pooled_obs = 0.0, pooled_exp = 0.0;
    int dof = -1;
    for (int i = 0; i < THETA_BINS * PHI_BINS; ++i) {
        if (expected[i] < 5.0) {
            pooled_obs += observed[i];
            pooled_exp += expected[i];
            continue;
        }
        double d = observed[i] - expected[i];
        chi2 += d * d / expected[i];
        dof++;
    }
    if (pooled_exp >= 5.0) {
        double d = pooled_obs - pooled_exp;
        chi2 += d * d / pooled_exp;
        dof++;
    } else if (pooled_obs > 5.0 + 5.0 * pooled_exp) {
        snprintf(why, why_size, "%s: %.0f samples landed where the pdf expects %.2f", what,
                 pooled_obs, pooled_exp);
        return false;
    }
    if (dof < 1) {
        snprintf(why, why_size, "%s: too few populated bins", what);
        return false;
    }
    double critical = chi2_critical(dof);
    if (chi2 > critical) {
        snprintf(why, why_size, "%s: chi-square %.1f exceeds %.1f (dof %d)", what, chi2, critical,
                 dof);
        return false;
    }
    return true;
}

double test_bsdf_albedo_sampled(const struct drift_bsdf *bsdf, drift_vec3 wo, int n, uint32_t seed,
                                uint32_t pixel)
{
    double sum = 0.0;
    for (int i = 0; i < n; ++i) {
        drift_sampler s = drift_sampler_make(seed, pixel, (uint32_t)i);
        drift_vec2 u = drift_sampler_next2(&s);
        drift_bsdf_sample bs = drift_bsdf_sample_wi(bsdf, wo, drift_sampler_next1(&s), u);
        if (bs.pdf > 0.0f) {
            sum += (double)bs.weight.x;
        }
    }
    return sum / n;
}

drift_bsdf test_bsdf_of_material(const drift_material *m, bool front_face)
{
    drift_context *ctx = test_context(1, NULL);
    drift_scene *scene = NULL;
    assert_int_equal(drift_scene_create(ctx, &scene), DRIFT_OK);
    uint32_t index;
    assert_int_equal(drift_scene_add_material(scene, m, &index), DRIFT_OK);
    drift_surface surf = { .material = index,
                           .ns = drift_vec3_make(0, 0, 1),
                           .ng = drift_vec3_make(0, 0, 1),
                           .front_face = front_face };
    drift_bsdf b = drift_bsdf_make(scene, &surf);
    drift_scene_destroy(scene);
    drift_context_destroy(ctx);
    return b;
}

typedef struct bsdf_pair {
    const drift_bsdf *sampled, *pdf;
    drift_vec3 wo;
} bsdf_pair;

static bool bsdf_pair_sample(void *user, drift_vec2 u, float u_lobe, drift_vec3 *out_wi)
{
    const bsdf_pair *p = user;
    drift_bsdf_sample bs = drift_bsdf_sample_wi(p->sampled, p->wo, u_lobe, u);
    *out_wi = bs.wi;
    return bs.pdf > 0.0f;
}

static float bsdf_pair_pdf(void *user, drift_vec3 wi)
{
    const bsdf_pair *p = user;
    return drift_bsdf_pdf(p->pdf, p->wo, wi);
}

bool test_bsdf_chi_square_passes(const char *what, const drift_bsdf *sampled, const drift_bsdf *pdf,
                                 drift_vec3 wo, int sample_count, char *why, size_t why_size)
{
    bsdf_pair p = { .sampled = sampled, .pdf = pdf, .wo = wo };
    return test_chi_square_passes(what, bsdf_pair_pdf, bsdf_pair_sample, &p, sample_count, 16, why,
                                  why_size);
}
