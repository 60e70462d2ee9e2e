// Issue 41 s7: the MS lobe times a reciprocal, non-separable kernel K = 1 + beta (t_o t_i)^p,
// t = 1 - mu, with s refitted (Sinkhorn as drift__ggx_fit_ms_scale) so the albedo stays 1 - E1.
// Args: r k beta p. Prints per Cycles-grid row: ss (Schlick gold) and the lobe part, x cos theta_i.
#include "scene/microfacet.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

enum {
    MU = DRIFT_GGX_TABLE_MU_N
};

static const double PI = 3.14159265358979;
static double BETA, P;

static double kern(double mo, double mi)
{
    return 1 + BETA * pow((1 - mo) * (1 - mi), P);
}

static double interp(const double *t, double mu)
{
    double x = fmin(fmax(mu * MU - 0.5, 0), MU - 1.0);
    int j = x >= MU - 1 ? MU - 2 : (int)x;
    return t[j] + (t[j + 1] - t[j]) * (x - j);
}

static void fit(double ms_alpha, const float *e1, int strata, double *s)
{
    static double b[MU][MU];
    for (int i = 0; i < MU; ++i) {
        double mo = (i + 0.5) / MU;
        drift_vec3 wo = drift_vec3_make((float)sqrt(1 - mo * mo), 0, (float)mo);
        float lo = drift__ggx_lambda((float)ms_alpha, wo);
        for (int j = 0; j < MU; ++j)
            b[i][j] = 0;
        for (int u0 = 0; u0 < strata; ++u0)
            for (int u1 = 0; u1 < strata; ++u1) {
                drift_vec2 u = drift_vec2_make((u0 + 0.5f) / strata, (u1 + 0.5f) / strata);
                drift_vec3 m = drift__ggx_sample_vndf((float)ms_alpha, wo, u);
                drift_vec3 wi =
                    drift_vec3_sub(drift_vec3_scale(m, 2.0f * drift_vec3_dot(wo, m)), wo);
                if (wi.z <= 0)
                    continue;
                double li = drift__ggx_lambda((float)ms_alpha, wi);
                double w = (1.0 + lo) / (1.0 + lo + li) * kern(mo, wi.z);
                double x = fmin(fmax(wi.z * MU - 0.5, 0.0), MU - 1.0);
                int j = x >= MU - 1 ? MU - 2 : (int)x;
                b[i][j] += w * (j + 1 - x);
                b[i][j + 1] += w * (x - j);
            }
        for (int j = 0; j < MU; ++j)
            b[i][j] /= (double)strata * strata;
    }
    double t[MU], bs[MU];
    for (int i = 0; i < MU; ++i) {
        t[i] = fmax(0, 1 - e1[i]);
        s[i] = 1;
    }
    for (int it = 0; it < 4000; ++it) {
        double res = 0;
        for (int i = 0; i < MU; ++i) {
            bs[i] = 0;
            for (int j = 0; j < MU; ++j)
                bs[i] += b[i][j] * s[j];
            res = fmax(res, fabs(s[i] * bs[i] - t[i]));
        }
        if (res < 1e-7)
            break;
        for (int i = 0; i < MU; ++i)
            s[i] = bs[i] > 0 ? sqrt(s[i] * t[i] / bs[i]) : 0;
    }
}

int main(int argc, char **argv)
{
    double r = atof(argv[1]), k = atof(argv[2]), a = r * r, a2 = k * a;
    BETA = atof(argv[3]);
    P = atof(argv[4]);
    double col[3] = { 1.0, 0.78, 0.34 }, W[3] = { 0.2126, 0.7152, 0.0722 };
    float e1[MU], es[MU];
    double s[MU], eavg = 0, fms = 0;
    for (int i = 0; i < MU; i++) {
        drift__ggx_integrate_reflection((i + 0.5f) / MU, (float)a, 128, &e1[i], &es[i]);
        eavg += 2.0 * e1[i] * (i + 0.5) / MU / MU;
    }
    fit(a2, e1, 96, s);
    for (int c = 0; c < 3; c++) {
        double fa = col[c] + (1 - col[c]) / 21.0;
        fms += W[c] * fa * fa * eavg / (1 - fa * (1 - eavg));
    }
    int th[] = { 85, 80, 70, 60, 40, 30, 20 }, ph_[] = { 180, 135, 90, 45, 0 };
    for (int a1 = 0; a1 < 7; a1++)
        for (int b1 = 0; b1 < 7; b1++)
            for (int c1 = 0; c1 < 5; c1++) {
                double to = th[a1] * PI / 180, ti = th[b1] * PI / 180, ph = ph_[c1] * PI / 180;
                drift_vec3 o = drift_vec3_make((float)sin(to), 0, (float)cos(to));
                drift_vec3 i = drift_vec3_make((float)(sin(ti) * cos(ph)),
                                               (float)(sin(ti) * sin(ph)), (float)cos(ti));
                drift_vec3 h = drift_vec3_normalize(drift_vec3_add(o, i));
                double oh = drift_vec3_dot(o, h), m5 = pow(1 - oh, 5), fs = 0;
                double ss = drift__ggx_d((float)a, h) /
                            ((1 + drift__ggx_lambda((float)a, o) + drift__ggx_lambda((float)a, i)) *
                             4 * o.z * i.z);
                for (int c = 0; c < 3; c++)
                    fs += W[c] * (col[c] + (1 - col[c]) * m5);
                double lobe =
                    interp(s, o.z) * interp(s, i.z) * kern(o.z, i.z) * drift__ggx_d((float)a2, h) /
                    ((1 + drift__ggx_lambda((float)a2, o) + drift__ggx_lambda((float)a2, i)) * 4 *
                     o.z * i.z);
                printf("{\"r\":%g,\"k\":%g,\"beta\":%g,\"p\":%g,\"to\":%d,\"ti\":%d,\"ph\":%d,"
                       "\"ss\":%g,\"lobe\":%g,\"kc\":0}\n",
                       r, k, BETA, P, th[a1], th[b1], ph_[c1], ss * fs * o.z * 0 + ss * fs * i.z,
                       fms * lobe * i.z);
            }
    return 0;
}
