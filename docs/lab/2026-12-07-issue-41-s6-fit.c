// Issue 41 s6: drift's gold conductor (SS + the MS lobe of width k alpha) from microfacet.c's
// integrals for a list of k, on the s6 grid, as JSON lines (s4's fit.c, other grid).
#include "scene/microfacet.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

enum {
    MU = DRIFT_GGX_TABLE_MU_N
};

static double PI = 3.14159265358979;

static double schl(double f0, double c)
{
    double m = 1 - c;
    return f0 + (1 - f0) * m * m * m * m * m;
}

static double interp(const float *t, double mu)
{
    double x = fmin(fmax(mu * MU - 0.5, 0), MU - 1.0);
    int j = x >= MU - 1 ? MU - 2 : (int)x;
    return t[j] + (t[j + 1] - t[j]) * (x - j);
}

static double ssv(double a, drift_vec3 o, drift_vec3 i)
{
    drift_vec3 h = drift_vec3_normalize(drift_vec3_add(o, i));
    return drift__ggx_d((float)a, h) /
           ((1 + drift__ggx_lambda((float)a, o) + drift__ggx_lambda((float)a, i)) * 4 * o.z * i.z);
}

int main(int argc, char **argv)
{
    double r = atof(argv[1]);
    double ks[32];
    int nk = 0;
    for (int i = 2; i < argc; i++)
        ks[nk++] = atof(argv[i]);
    double col[3] = { 1.0, 0.78, 0.34 };
    double a = r * r;
    float e1[MU], es[MU];
    double eavg = 0;
    for (int i = 0; i < MU; i++) {
        drift__ggx_integrate_reflection((i + 0.5f) / MU, (float)a, 128, &e1[i], &es[i]);
        eavg += 2.0 * e1[i] * (i + 0.5) / MU / MU;
    }
    for (int ki = 0; ki < nk; ki++) {
        float g[MU];
        double a2 = ks[ki] * a;
        drift__ggx_fit_ms_scale((float)a2, e1, 96, g);
        int tos[3] = { 85, 80, 70 }, tis[5] = { 85, 80, 70, 60, 30 },
            phs[5] = { 180, 135, 90, 45, 0 };
        for (int a1 = 0; a1 < 3; a1++)
            for (int b1 = 0; b1 < 5; b1++)
                for (int c1 = 0; c1 < 5; c1++) {
                    double to = tos[a1] * PI / 180, ti = tis[b1] * PI / 180,
                           ph = phs[c1] * PI / 180;
                    drift_vec3 o = drift_vec3_make((float)sin(to), 0, (float)cos(to));
                    drift_vec3 i = drift_vec3_make((float)(sin(ti) * cos(ph)),
                                                   (float)(sin(ti) * sin(ph)), (float)cos(ti));
                    drift_vec3 h = drift_vec3_normalize(drift_vec3_add(o, i));
                    double oh = drift_vec3_dot(o, h);
                    double ss = ssv(a, o, i), s2 = ssv(a2, o, i);
                    double ms = interp(g, o.z) * interp(g, i.z) * s2;
                    double tot[3];
                    for (int c = 0; c < 3; c++) {
                        double fa = col[c] + (1 - col[c]) / 21,
                               fms = fa * fa * eavg / (1 - fa * (1 - eavg));
                        tot[c] = (ss * schl(col[c], oh) + fms * ms) * i.z;
                    }
                    printf("{\"k\":%g,\"r\":%g,\"to\":%d,\"ti\":%d,\"ph\":%d,\"tot\":[%g,%g,%g]}\n",
                           ks[ki], r, tos[a1], tis[b1], phs[c1], tot[0], tot[1], tot[2]);
                }
    }
    return 0;
}
