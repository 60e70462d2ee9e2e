// The aperture texture of Ritschel 2009, thesis §8.4 step 1: the pupil as an open disk, the
// lids, and every scatterer as an opaque primitive, point sampled at supersample^2 positions
// a pixel and box-averaged (the "2x2 or more supersampling" that keeps the FFT from amplifying
// aliasing). P is a transmittance (1 open, 0 opaque; thesis-spec §6.4 on the convention).
#include "glare_internal.h"

#include <math.h>
#include <string.h>

// Hi-res pixel a's centre is at (a + 0.5 - origin) * hp mm, origin = S (n + 1) / 2, so that the
// S x S samples of final pixel i are centred on (i - n/2) * W / n.
typedef struct raster {
    float *t;
    int32_t m; // n * supersample
    double hp; // hi-res pixel size, mm
    double origin;
} raster;

static double px_x(const raster *r, double x)
{
    return x / r->hp + r->origin - 0.5;
}

static double px_y(const raster *r, double y)
{
    return -y / r->hp + r->origin - 0.5;
}

static void clip_range(const raster *r, double lo, double hi, int32_t *out_lo, int32_t *out_hi)
{
    double a = ceil(lo), b = floor(hi);
    *out_lo = a < 0.0 ? 0 : (a > r->m ? r->m : (int32_t)a);
    *out_hi = b >= r->m ? r->m - 1 : (b < -1.0 ? -1 : (int32_t)b);
}

static void draw_disk(const raster *r, const drift__glare_disk *d)
{
    double cx = px_x(r, (double)d->x), cy = px_y(r, (double)d->y), rad = (double)d->radius / r->hp;
    if (rad < 0.5) {
        // Smaller than a sample: splat the disk's area bilinearly over the 4 nearest samples.
        double area = 3.14159265358979323846 * rad * rad;
        int32_t x0 = (int32_t)floor(cx), y0 = (int32_t)floor(cy);
        double fx = cx - x0, fy = cy - y0;
        for (int32_t j = 0; j < 2; ++j) {
            for (int32_t i = 0; i < 2; ++i) {
                int32_t x = x0 + i, y = y0 + j;
                if (x < 0 || y < 0 || x >= r->m || y >= r->m) {
                    continue;
                }
                double w = (i ? fx : 1.0 - fx) * (j ? fy : 1.0 - fy);
                float *t = &r->t[(size_t)y * (size_t)r->m + (size_t)x];
                *t *= (float)fmax(0.0, 1.0 - w * area);
            }
        }
        return;
    }
    int32_t x0, x1, y0, y1;
    clip_range(r, cx - rad, cx + rad, &x0, &x1);
    clip_range(r, cy - rad, cy + rad, &y0, &y1);
    double r2 = rad * rad;
    for (int32_t y = y0; y <= y1; ++y) {
        double dy = y - cy;
        float *row = r->t + (size_t)y * (size_t)r->m;
        for (int32_t x = x0; x <= x1; ++x) {
            double dx = x - cx;
            if (dx * dx + dy * dy <= r2) {
                row[x] = 0.0f;
            }
        }
    }
}

static void draw_line(const raster *r, const drift__glare_line *l)
{
    double ax = px_x(r, (double)l->ax), ay = px_y(r, (double)l->ay), bx = px_x(r, (double)l->bx),
           by = px_y(r, (double)l->by);
    double hw = 0.5 * (double)l->width / r->hp;
    int32_t x0, x1, y0, y1;
    clip_range(r, fmin(ax, bx) - hw, fmax(ax, bx) + hw, &x0, &x1);
    clip_range(r, fmin(ay, by) - hw, fmax(ay, by) + hw, &y0, &y1);
    double ex = bx - ax, ey = by - ay, ee = ex * ex + ey * ey;
    for (int32_t y = y0; y <= y1; ++y) {
        float *row = r->t + (size_t)y * (size_t)r->m;
        for (int32_t x = x0; x <= x1; ++x) {
            double px = x - ax, py = y - ay;
            double s = ee > 0.0 ? fmin(fmax((px * ex + py * ey) / ee, 0.0), 1.0) : 0.0;
            double dx = px - s * ex, dy = py - s * ey;
            if (dx * dx + dy * dy <= hw * hw) {
                row[x] = 0.0f;
            }
        }
    }
}

void drift__glare_aperture_draw(const drift__glare_aperture_desc *desc, int32_t n,
                                int32_t supersample, double width_mm, float *hires, float *out)
{
    const int32_t s = supersample;
    raster r = { .t = hires, .m = n * s, .hp = width_mm / (n * s), .origin = 0.5 * s * (n + 1) };
    // The pupil: an open disk of diameter h(t, p) (thesis §8.4 step 1.2), cut by the lids.
    double pr = 0.5 * desc->pupil_mm;
    double top = 1e30, bottom = -1e30;
    if (desc->lids) {
        drift__glare_lids(desc->closure, &top, &bottom);
    }
    for (int32_t b = 0; b < r.m; ++b) {
        double y = -(b + 0.5 - r.origin) * r.hp;
        float *row = hires + (size_t)b * (size_t)r.m;
        for (int32_t a = 0; a < r.m; ++a) {
            double x = (a + 0.5 - r.origin) * r.hp;
            double bend = 0.02 * x * x;
            bool open = x * x + y * y <= pr * pr && y < top + bend && y > bottom - bend;
            row[a] = open ? 1.0f : 0.0f;
        }
    }
    for (int32_t i = 0; i < desc->disk_count; ++i) {
        draw_disk(&r, &desc->disks[i]);
    }
    for (int32_t i = 0; i < desc->line_count; ++i) {
        draw_line(&r, &desc->lines[i]);
    }
    // Box-downsample the coverage.
    const float inv = 1.0f / (float)(s * s);
    for (int32_t y = 0; y < n; ++y) {
        for (int32_t x = 0; x < n; ++x) {
            float sum = 0.0f;
            for (int32_t j = 0; j < s; ++j) {
                const float *row = hires + (size_t)(y * s + j) * (size_t)r.m + (size_t)(x * s);
                for (int32_t i = 0; i < s; ++i) {
                    sum += row[i];
                }
            }
            out[(size_t)y * (size_t)n + (size_t)x] = sum * inv;
        }
    }
}
