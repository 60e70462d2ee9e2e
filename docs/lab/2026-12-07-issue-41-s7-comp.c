// Issue 41 s7: per Cycles row (r, theta_o, theta_i, phi), drift's gold conductor split into parts,
// each x cos theta_i, luminance: ss (Schlick), ss_cyc (interpolate_fresnel_color IOR 1.5), the
// broad lobe F_ms * s s D G2/(4 mu mu) at width k alpha, and the Kulla-Conty diffuse lobe F_ms
// (1-E1(mu_o))(1-E1(mu_i)) / (pi (1 - E1avg)). Args: r k.
#include "scene/microfacet.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

enum {
    MU = DRIFT_GGX_TABLE_MU_N
};

static const double PI = 3.14159265358979;

static double interp(const float *t, double mu)
{
    double x = fmin(fmax(mu * MU - 0.5, 0), MU - 1.0);
    int j = x >= MU - 1 ? MU - 2 : (int)x;
    return t[j] + (t[j + 1] - t[j]) * (x - j);
}

static double fdiel(double c, double eta)
{
    double g2 = eta * eta - 1 + c * c;
    if (g2 < 0)
        return 1;
    double g = sqrt(g2), A = (g - c) / (g + c), B = (c * (g + c) - 1) / (c * (g - c) + 1);
    return 0.5 * A * A * (1 + B * B);
}

int main(int argc, char **argv)
{
    double r = atof(argv[1]), k = atof(argv[2]), a = r * r, a2 = k * a;
    double col[3] = { 1.0, 0.78, 0.34 }, W[3] = { 0.2126, 0.7152, 0.0722 };
    float e1[MU], es[MU], g[MU];
    double eavg = 0;
    for (int i = 0; i < MU; i++) {
        drift__ggx_integrate_reflection((i + 0.5f) / MU, (float)a, 128, &e1[i], &es[i]);
        eavg += 2.0 * e1[i] * (i + 0.5) / MU / MU;
    }
    drift__ggx_fit_ms_scale((float)a2, e1, 96, g);
    double fms = 0;
    for (int c = 0; c < 3; c++) {
        double fa = col[c] + (1 - col[c]) / 21.0;
        fms += W[c] * fa * fa * eavg / (1 - fa * (1 - eavg));
    }
    double th[][2] = { { 85, 85 } };
    (void)th;
    int tos[] = { 85, 80, 70, 60, 40, 30, 20 }, ph_[] = { 180, 135, 90, 45, 0 };
    for (int a1 = 0; a1 < 7; a1++)
        for (int b1 = 0; b1 < 7; b1++)
            for (int c1 = 0; c1 < 5; c1++) {
                double to = tos[a1] * PI / 180, ti = tos[b1] * PI / 180, ph = ph_[c1] * PI / 180;
                drift_vec3 o = drift_vec3_make((float)sin(to), 0, (float)cos(to));
                drift_vec3 i = drift_vec3_make((float)(sin(ti) * cos(ph)),
                                               (float)(sin(ti) * sin(ph)), (float)cos(ti));
                drift_vec3 h = drift_vec3_normalize(drift_vec3_add(o, i));
                double oh = drift_vec3_dot(o, h);
                double ss = drift__ggx_d((float)a, h) /
                            ((1 + drift__ggx_lambda((float)a, o) + drift__ggx_lambda((float)a, i)) *
                             4 * o.z * i.z);
                double fs = 0, fc = 0, m5 = pow(1 - oh, 5), fh = (fdiel(oh, 1.5) - 0.04) / 0.96;
                for (int c = 0; c < 3; c++) {
                    fs += W[c] * (col[c] + (1 - col[c]) * m5);
                    fc += W[c] * (col[c] * (1 - fh) + fh);
                }
                double lobe =
                    interp(g, o.z) * interp(g, i.z) * drift__ggx_d((float)a2, h) /
                    ((1 + drift__ggx_lambda((float)a2, o) + drift__ggx_lambda((float)a2, i)) * 4 *
                     o.z * i.z);
                double kc = (1 - interp(e1, o.z)) * (1 - interp(e1, i.z)) / (PI * (1 - eavg));
                double ci = i.z;
                printf("{\"r\":%g,\"k\":%g,\"to\":%d,\"ti\":%d,\"ph\":%d,\"ss\":%g,\"ss_cyc\":%g,"
                       "\"lobe\":%g,\"kc\":%g}\n",
                       r, k, tos[a1], tos[b1], ph_[c1], ss * fs * ci, ss * fc * ci, fms * lobe * ci,
                       fms * kc * ci);
            }
    return 0;
}
