// The rotation nearest to a 3x3 matrix (its polar factor, Horn 1987) through a Jacobi SVD in
// double: M^T M = V S^2 V^T by cyclic Jacobi sweeps, u_i = M v_i / s_i for the two largest
// singular values, and R = [u1 u2 u1 x u2] [v1 v2 v1 x v2]^T, which equals
// U diag(1, 1, det(U V^T)) V^T and needs no third singular value (rank 2 is enough).
#include "drift/reflect_edit.h"

#include <math.h>

// Below this ratio of the second singular value to the first, M counts as rank 1.
#define RANK_ONE_RATIO 1e-7

static void jacobi_eigen(double a[3][3], double v[3][3])
{
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            v[i][j] = i == j ? 1.0 : 0.0;
        }
    }
    for (int sweep = 0; sweep < 32; ++sweep) {
        double off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
        double diag = a[0][0] * a[0][0] + a[1][1] * a[1][1] + a[2][2] * a[2][2];
        if (off <= 1e-30 * diag || off == 0.0) {
            return;
        }
        for (int p = 0; p < 2; ++p) {
            for (int q = p + 1; q < 3; ++q) {
                if (a[p][q] == 0.0) {
                    continue;
                }
                // The rotation zeroing a[p][q] (Golub & Van Loan, Alg. 8.4.1).
                double theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                double t = (theta >= 0.0 ? 1.0 : -1.0) / (fabs(theta) + sqrt(theta * theta + 1.0));
                double c = 1.0 / sqrt(t * t + 1.0), s = t * c;
                for (int k = 0; k < 3; ++k) {
                    double akp = a[k][p], akq = a[k][q];
                    a[k][p] = c * akp - s * akq;
                    a[k][q] = s * akp + c * akq;
                }
                for (int k = 0; k < 3; ++k) {
                    double apk = a[p][k], aqk = a[q][k];
                    a[p][k] = c * apk - s * aqk;
                    a[q][k] = s * apk + c * aqk;
                }
                for (int k = 0; k < 3; ++k) {
                    double vkp = v[k][p], vkq = v[k][q];
                    v[k][p] = c * vkp - s * vkq;
                    v[k][q] = s * vkp + c * vkq;
                }
            }
        }
    }
}

static void cross3(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

static double normalize3(double v[3])
{
    double len = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (len > 0.0) {
        v[0] /= len;
        v[1] /= len;
        v[2] /= len;
    }
    return len;
}

drift_mat3 drift_mat3_rotation_between(drift_vec3 a, drift_vec3 b)
{
    double x[3] = { (double)a.x, (double)a.y, (double)a.z },
           y[3] = { (double)b.x, (double)b.y, (double)b.z };
    normalize3(x);
    normalize3(y);
    double c = x[0] * y[0] + x[1] * y[1] + x[2] * y[2];
    double out[3][3];
    if (c < -1.0 + 1e-12) {
        // A half turn about an axis k normal to a: 2 k k^T - I.
        drift_frame f = drift_frame_from_normal(drift_vec3_normalize(a));
        double k[3] = { (double)f.x.x, (double)f.x.y, (double)f.x.z };
        for (int i = 0; i < 3; ++i) {
            for (int j = 0; j < 3; ++j) {
                out[i][j] = 2.0 * k[i] * k[j] - (i == j ? 1.0 : 0.0);
            }
        }
    } else {
        // Rodrigues: I + [v]x + [v]x^2 / (1 + c), v = a x b.
        double v[3];
        cross3(x, y, v);
        double k[3][3] = { { 0.0, -v[2], v[1] }, { v[2], 0.0, -v[0] }, { -v[1], v[0], 0.0 } };
        double scale = 1.0 / (1.0 + c);
        for (int i = 0; i < 3; ++i) {
            for (int j = 0; j < 3; ++j) {
                double k2 = 0.0;
                for (int l = 0; l < 3; ++l) {
                    k2 += k[i][l] * k[l][j];
                }
                out[i][j] = (i == j ? 1.0 : 0.0) + k[i][j] + k2 * scale;
            }
        }
    }
    drift_mat3 r;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            r.m[i][j] = (float)out[i][j];
        }
    }
    return r;
}

drift_mat3 drift_mat3_ortho(double m[3][3])
{
    double mtm[3][3], v[3][3];
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            mtm[i][j] = m[0][i] * m[0][j] + m[1][i] * m[1][j] + m[2][i] * m[2][j];
        }
    }
    jacobi_eigen(mtm, v);
    // Order the eigenpairs by eigenvalue, largest first.
    int order[3] = { 0, 1, 2 };
    for (int i = 0; i < 2; ++i) {
        for (int j = i + 1; j < 3; ++j) {
            if (mtm[order[j]][order[j]] > mtm[order[i]][order[i]]) {
                int t = order[i];
                order[i] = order[j];
                order[j] = t;
            }
        }
    }
    double vs[3][3], us[3][3]; // vs[i], us[i]: the i-th right and left singular vectors
    double sigma[2];
    for (int i = 0; i < 3; ++i) {
        for (int k = 0; k < 3; ++k) {
            vs[i][k] = v[k][order[i]];
        }
    }
    for (int i = 0; i < 2; ++i) {
        for (int k = 0; k < 3; ++k) {
            us[i][k] = m[k][0] * vs[i][0] + m[k][1] * vs[i][1] + m[k][2] * vs[i][2];
        }
        sigma[i] = normalize3(us[i]);
    }
    if (!(sigma[0] > 0.0) || !isfinite(sigma[0])) {
        return drift_mat3_identity();
    }
    if (sigma[1] <= RANK_ONE_RATIO * sigma[0]) {
        // Rank 1: the roll about u1 is free; take the minimal rotation v1 -> u1.
        return drift_mat3_rotation_between(
            drift_vec3_make((float)vs[0][0], (float)vs[0][1], (float)vs[0][2]),
            drift_vec3_make((float)us[0][0], (float)us[0][1], (float)us[0][2]));
    }
    // u2 orthogonal to u1 exactly (Gram-Schmidt removes the round-off), then the third columns.
    double d = us[1][0] * us[0][0] + us[1][1] * us[0][1] + us[1][2] * us[0][2];
    for (int k = 0; k < 3; ++k) {
        us[1][k] -= d * us[0][k];
    }
    normalize3(us[1]);
    d = vs[1][0] * vs[0][0] + vs[1][1] * vs[0][1] + vs[1][2] * vs[0][2];
    for (int k = 0; k < 3; ++k) {
        vs[1][k] -= d * vs[0][k];
    }
    normalize3(vs[1]);
    cross3(us[0], us[1], us[2]);
    cross3(vs[0], vs[1], vs[2]);
    drift_mat3 r;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            r.m[i][j] = (float)(us[0][i] * vs[0][j] + us[1][i] * vs[1][j] + us[2][i] * vs[2][j]);
        }
    }
    return r;
}
