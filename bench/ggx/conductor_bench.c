// The GGX conductor's sampling and evaluation, this tree's against an earlier revision's
// (scripts/bench_ggx_conductor.sh compiles that revision's ggx.c into the same program with its
// functions renamed old_*): a gold conductor of roughness 0.3 and 0.7, the path tracer's calls
// per bounce (a sample, then an eval and a pdf for a light direction), runs interleaved.
#include "scene/microfacet.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

drift_vec3 old_ggx_eval(const drift_bsdf_ggx *g, drift_vec3 wo, drift_vec3 wi, drift_vec3 *d);
float old_ggx_pdf(const drift_bsdf_ggx *g, drift_vec3 wo, drift_vec3 wi);
drift_bsdf_sample old_ggx_sample(const drift_bsdf_ggx *g, drift_vec3 wo, float u_lobe,
                                 drift_vec2 u);

typedef struct impl {
    drift_vec3 (*eval)(const drift_bsdf_ggx *, drift_vec3, drift_vec3, drift_vec3 *);
    float (*pdf)(const drift_bsdf_ggx *, drift_vec3, drift_vec3);
    drift_bsdf_sample (*sample)(const drift_bsdf_ggx *, drift_vec3, float, drift_vec2);
} impl;

static float rnd(uint64_t *s)
{
    *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
    return (float)(*s >> 40) / 16777216.0f;
}

// CPU seconds of n bounces; the sum of the results in *sink so nothing is optimised away.
static double run(const impl *f, const drift_bsdf_ggx *g, int n, double *sink)
{
    uint64_t s = 7;
    double acc = 0.0;
    clock_t t0 = clock();
    for (int i = 0; i < n; ++i) {
        drift_vec3 wo = drift_sample_cosine_hemisphere(drift_vec2_make(rnd(&s), rnd(&s)));
        drift_bsdf_sample b = f->sample(g, wo, rnd(&s), drift_vec2_make(rnd(&s), rnd(&s)));
        drift_vec3 wl = drift_sample_cosine_hemisphere(drift_vec2_make(rnd(&s), rnd(&s)));
        drift_vec3 e = f->eval(g, wo, wl, NULL);
        acc += (double)(b.weight.y + e.y + f->pdf(g, wo, wl));
    }
    *sink += acc;
    return (double)(clock() - t0) / CLOCKS_PER_SEC;
}

int main(int argc, char **argv)
{
    int n = argc > 1 ? atoi(argv[1]) : 2000000, runs = argc > 2 ? atoi(argv[2]) : 5;
    impl now = { drift__ggx_eval, drift__ggx_pdf, drift__ggx_sample };
    impl old = { old_ggx_eval, old_ggx_pdf, old_ggx_sample };
    const float roughness[] = { 0.3f, 0.7f };
    double sink = 0.0;
    for (int r = 0; r < 2; ++r) {
        drift_bsdf_ggx g = { 0 };
        g.alpha = roughness[r] * roughness[r];
        g.w_conductor = 1.0f;
        g.schlick = true;
        g.burley_roughness = -1.0f;
        g.base = drift_vec3_make(1.0f, 0.766f, 0.336f);
        drift__ggx_alpha_slot(g.alpha, &g.alpha_row, &g.alpha_frac);
        g.e1_avg = drift__ggx_e1_avg(g.alpha);
        g.es_avg = drift__ggx_es_avg(g.alpha);
        double t_old = 0.0, t_now = 0.0;
        for (int k = 0; k < runs; ++k) {
            t_old += run(&old, &g, n, &sink);
            t_now += run(&now, &g, n, &sink);
        }
        printf("gold roughness %.1f: %.1f ns per bounce before, %.1f after: after / before %.3f\n",
               (double)roughness[r], 1e9 * t_old / ((double)n * runs),
               1e9 * t_now / ((double)n * runs), t_now / t_old);
    }
    fprintf(stderr, "(checksum %g)\n", sink);
    return 0;
}
