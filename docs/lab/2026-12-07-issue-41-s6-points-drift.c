// Issue 41 s6: drift's glTF metal (drift__ggx_eval) x cos theta_i, its single-scattering part,
// and Cycles 3.4 MULTI_GGX's analytic first order (height-correlated G2, interpolate_fresnel_color
// with IOR 1.5 toward the base colour), per configuration as JSON lines.
#include "microfacet.h"

#include <math.h>
#include <stdio.h>
static const double PI = 3.14159265358979;

static double D(double a, double hz)
{
    double c2 = hz * hz, s2 = 1 - c2, den = c2 + s2 / (a * a);
    return 1.0 / (PI * a * a * den * den);
}

static double Lam(double a, double z)
{
    double t2 = (1 - z * z) / (z * z);
    return 0.5 * (-1 + sqrt(1 + a * a * t2));
}

static double fdiel(double c, double eta)
{
    double g2 = eta * eta - 1 + c * c;
    if (g2 < 0)
        return 1;
    double g = sqrt(g2);
    double A = (g - c) / (g + c), B = (c * (g + c) - 1) / (c * (g - c) + 1);
    return 0.5 * A * A * (1 + B * B);
}

int main(void)
{
    double cols[2][3] = { { 1.0, 0.78, 0.34 }, { 1, 1, 1 } };
    const char *cn[2] = { "gold", "white" };
    double rs[2] = { 0.8, 0.5 };
    int tos[3] = { 85, 80, 70 }, tis[5] = { 85, 80, 70, 60, 30 }, phs[5] = { 180, 135, 90, 45, 0 };
    for (int ci = 0; ci < 2; ci++)
        for (int ri = 0; ri < 2; ri++) {
            double r = rs[ri], a = r * r;
            const double *col = cols[ci];
            drift_bsdf_ggx g = { 0 };
            g.alpha = (float)a;
            g.w_conductor = 1;
            g.schlick = true;
            g.base = drift_vec3_make((float)col[0], (float)col[1], (float)col[2]);
            g.f0_coat = drift_vec3_splat(0.04f);
            g.eta_rel = 1.5f;
            g.burley_roughness = -1;
            drift__ggx_alpha_slot((float)a, &g.alpha_row, &g.alpha_frac);
            g.e1_avg = drift__ggx_e1_avg((float)a);
            g.es_avg = drift__ggx_es_avg((float)a);
            for (int a1 = 0; a1 < 3; a1++)
                for (int a2 = 0; a2 < 5; a2++)
                    for (int a3 = 0; a3 < 5; a3++) {
                        double to = tos[a1] * PI / 180, ti = tis[a2] * PI / 180,
                               ph = phs[a3] * PI / 180;
                        double o[3] = { sin(to), 0, cos(to) },
                               i[3] = { sin(ti) * cos(ph), sin(ti) * sin(ph), cos(ti) };
                        drift_vec3 wo = drift_vec3_make((float)o[0], (float)o[1], (float)o[2]);
                        drift_vec3 wi = drift_vec3_make((float)i[0], (float)i[1], (float)i[2]);
                        drift_vec3 dif = drift_vec3_splat(0);
                        drift_vec3 f = drift__ggx_eval(&g, wo, wi, &dif);
                        double h[3] = { o[0] + i[0], o[1] + i[1], o[2] + i[2] },
                               l = sqrt(h[0] * h[0] + h[1] * h[1] + h[2] * h[2]);
                        for (int k = 0; k < 3; k++)
                            h[k] /= l;
                        double oh = o[0] * h[0] + o[1] * h[1] + o[2] * h[2];
                        double ss = D(a, h[2]) /
                                    ((1 + Lam(a, o[2]) + Lam(a, i[2])) * 4 * o[2] * i[2]) * i[2];
                        double fh = (fdiel(oh, 1.5) - 0.04) / 0.96, m5 = pow(1 - oh, 5);
                        printf("{\"col\":\"%s\",\"r\":%g,\"to\":%d,\"ti\":%d,\"ph\":%d,\"drift\":[%"
                               "g,%g,%g],\"ss_cyc\":[%g,%g,%g],\"ss_drift\":[%g,%g,%g]}\n",
                               cn[ci], r, tos[a1], tis[a2], phs[a3], f.x * i[2], f.y * i[2],
                               f.z * i[2], ss * (col[0] * (1 - fh) + fh),
                               ss * (col[1] * (1 - fh) + fh), ss * (col[2] * (1 - fh) + fh),
                               ss * (col[0] + (1 - col[0]) * m5), ss * (col[1] + (1 - col[1]) * m5),
                               ss * (col[2] + (1 - col[2]) * m5));
                    }
        }
    return 0;
}
