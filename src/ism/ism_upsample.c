// drift ism: gathering at a lower resolution (gather_scale > 1): the decimated G-buffer, the
// upsampling of the blurred irradiance and the pixels that gather alone.
#include "core/vectorise.h"
#include "ism/ism_object.h"

#include <math.h>
#include <string.h>

// --- GATHERING AT A LOWER RESOLUTION (gather_scale > 1) ---
//
// Indirect diffuse light is smooth where the surface is. One pixel in s x s gathers, with the
// interleaving, the blur and the near-field compensation run at that resolution (a block's
// window then spans s^2 times the pixels), and every pixel takes the irradiance of its four
// nearest gathering pixels that pass the blur's tests against it, weighed bilinearly (or of
// those of the twelve around them that do); the albedo is its own. The thesis upsamples
// micro-rendering's gathers so (§6.2.4, with Sloan et al. 2007's weights; the blur's tests keep ISM
// to one rule). A pixel none of the 16 passes (a chair's leg, a leaf, a silhouette's rim) gathers
// every VPL itself, as §6.2.4's extra pass does: exact there, and few (stats.fallback_pixels). It
// takes no near-field compensation.

// The G-buffer pixel gathering pixel i stands for: its s x s cell's centre.
static int32_t cell_pixel(int32_t i, int32_t s, int32_t full)
{
    int32_t v = i * s + s / 2;
    return v < full ? v : full - 1;
}

static void copy_pixel(const drift_image *from, int32_t x, int32_t y, drift_image *to, int32_t i,
                       int32_t j)
{
    if (from->pixels) {
        memcpy(drift_image_pixel(to, i, j), drift_image_pixel(from, x, y),
               sizeof(float) * (size_t)to->channels);
    }
}

void drift__ism_decimate_rows(size_t begin, size_t end, int thread, void *user)
{
    (void)thread;
    const decimate_job *job = user;
    drift_ism *ism = job->ism;
    const drift_gbuffer *gb = job->gb;
    drift_gbuffer *c = &ism->coarse;
    int32_t s = ism->params.gather_scale;
    for (size_t row = begin; row < end; ++row) {
        int32_t j = (int32_t)row, y = cell_pixel(j, s, gb->height);
        for (int32_t i = 0; i < c->width; ++i) {
            int32_t x = cell_pixel(i, s, gb->width);
            size_t from = (size_t)y * (size_t)gb->width + (size_t)x;
            c->surfaces[(size_t)j * (size_t)c->width + (size_t)i] =
                gb->surfaces ? gb->surfaces[from]
                             : (drift_surface){ .material = DRIFT_INVALID_INDEX };
            copy_pixel(&gb->depth, x, y, &c->depth, i, j);
            copy_pixel(&gb->position, x, y, &c->position, i, j);
            copy_pixel(&gb->normal, x, y, &c->normal, i, j);
            copy_pixel(&gb->geometric_normal, x, y, &c->geometric_normal, i, j);
            copy_pixel(&gb->albedo, x, y, &c->albedo, i, j);
            copy_pixel(&gb->material_id, x, y, &c->material_id, i, j);
            if (job->direct) {
                drift_image_set3(&ism->coarse_direct, i, j, drift_image_get3(job->direct, x, y));
            }
        }
    }
}

typedef struct upsample_job {
    drift_ism *ism;
    const drift_gbuffer *gb;
    uint8_t *fallback;                // per G-buffer pixel: 1 where it must gather itself
    uint64_t rays[DRIFT_MAX_THREADS]; // per thread, the fallback's `ir` rays
    const uint32_t *fallback_pixels;
    size_t fallback_count;
    size_t job_pixels;       // receivers of one fallback job
    float *receiver_buffers; // per thread: receivers_in of job_pixels
} upsample_job;

static void upsample_rows(size_t begin, size_t end, int thread, void *user)
{
    (void)thread;
    upsample_job *job = user;
    drift_ism *ism = job->ism;
    const drift_gbuffer *gb = job->gb, *c = &ism->coarse;
    int32_t s = ism->params.gather_scale;
    float blur_normal = ism->params.blur_normal, blur_plane = ism->params.blur_plane;
    for (size_t row = begin; row < end; ++row) {
        int32_t y = (int32_t)row;
        float fy = ((float)y - (float)(s / 2)) / (float)s;
        int32_t j0 = (int32_t)floorf(fy);
        float wy = fy - (float)j0;
        for (int32_t x = 0; x < gb->width; ++x) {
            size_t index = (size_t)y * (size_t)gb->width + (size_t)x;
            drift_vec3 e = drift_vec3_splat(0.0f);
            job->fallback[index] = 0;
            if (drift_image_pixel(&gb->material_id, x, y)[0] >= 0.0f) {
                const float *p = drift_image_pixel(&gb->position, x, y);
                const float *n = drift_image_pixel(&gb->normal, x, y);
                float fx = ((float)x - (float)(s / 2)) / (float)s;
                int32_t i0 = (int32_t)floorf(fx);
                float wx = fx - (float)i0, total = 0.0f;
                // The four nearest, bilinearly; where none passes, the ring of twelve around
                // them alike (a thin object's pixels are some gathering pixel's in the ring).
                for (int32_t k = 0; k < 16 && !(k == 4 && total > 0.0f); ++k) {
                    static const int8_t ring[12][2] = {
                        { -1, -1 }, { 0, -1 }, { 1, -1 }, { 2, -1 }, { -1, 0 }, { 2, 0 },
                        { -1, 1 },  { 2, 1 },  { -1, 2 }, { 0, 2 },  { 1, 2 },  { 2, 2 }
                    };
                    int32_t i = i0 + (k < 4 ? (k & 1) : ring[k - 4][0]);
                    int32_t j = j0 + (k < 4 ? (k >> 1) : ring[k - 4][1]);
                    if (i < 0 || j < 0 || i >= c->width || j >= c->height ||
                        drift_image_pixel(&c->material_id, i, j)[0] < 0.0f) {
                        continue;
                    }
                    const float *q = drift_image_pixel(&c->position, i, j);
                    const float *qn = drift_image_pixel(&c->normal, i, j);
                    float d = n[0] * (q[0] - p[0]) + n[1] * (q[1] - p[1]) + n[2] * (q[2] - p[2]);
                    float cosn = n[0] * qn[0] + n[1] * qn[1] + n[2] * qn[2];
                    if (cosn < blur_normal || fabsf(d) > blur_plane) {
                        continue;
                    }
                    // A little weight even where the bilinear one is 0: a pixel on a gathering
                    // pixel's row still reads the next row when its own fails the tests.
                    float w = k < 4
                                  ? ((k & 1) ? wx : 1.0f - wx) * ((k >> 1) ? wy : 1.0f - wy) + 1e-3f
                                  : 1.0f;
                    e = drift_vec3_fma(e, drift_image_get3(&ism->coarse_blurred, i, j), w);
                    total += w;
                }
                if (total > 0.0f) {
                    e = drift_vec3_scale(e, 1.0f / total);
                } else {
                    job->fallback[index] = 1;
                }
            }
            drift_vec3 kd = drift_image_get3(&gb->albedo, x, y);
            drift_image_set3(&ism->indirect, x, y,
                             drift_vec3_scale(drift_vec3_mul(kd, e), DRIFT_INV_PI));
        }
    }
}

// A fallback job's receivers read every VPL's map once: as few jobs as keep the threads busy.
static void fallback_jobs(size_t begin, size_t end, int thread, void *user)
{
    upsample_job *job = user;
    drift_ism *ism = job->ism;
    const drift_gbuffer *gb = job->gb;
    gather_consts c = drift__ism_gather_consts(ism);
    size_t cap = job->job_pixels;
    float *b = job->receiver_buffers + (size_t)thread * cap * RECEIVER_ARRAYS;
    for (size_t id = begin; id < end; ++id) {
        size_t first = id * cap;
        size_t last = first + cap < job->fallback_count ? first + cap : job->fallback_count;
        receivers rs = drift__ism_receivers_in(b, cap);
        for (size_t k = first; k < last; ++k) {
            int32_t i = rs.count++;
            int32_t x = (int32_t)(job->fallback_pixels[k] % (uint32_t)gb->width);
            int32_t y = (int32_t)(job->fallback_pixels[k] / (uint32_t)gb->width);
            const float *q = drift_image_pixel(&gb->position, x, y);
            rs.px[i] = q[0], rs.py[i] = q[1], rs.pz[i] = q[2];
            q = drift_image_pixel(&gb->normal, x, y);
            rs.nx[i] = q[0], rs.ny[i] = q[1], rs.nz[i] = q[2];
            q = drift_image_pixel(&gb->geometric_normal, x, y);
            rs.gx[i] = q[0], rs.gy[i] = q[1], rs.gz[i] = q[2];
            rs.er[i] = rs.eg[i] = rs.eb[i] = 0.0f;
            rs.x[i] = x;
            rs.y[i] = y;
        }
        // Every VPL of the render's slice: its part of each group, at `slices` times the light.
        for (uint32_t g = 0; g < ism->group_count; ++g) {
            uint32_t from, to;
            drift__ism_group_run(ism, g, ism->slice, ism->slices, &from, &to);
            for (uint32_t j = from; j < to; ++j) {
                drift__ism_gather_vpl(ism, j, &c, &rs, &job->rays[thread]);
            }
        }
        float scale = (float)ism->slices * DRIFT_INV_PI * DRIFT_INV_PI;
        for (int32_t i = 0; i < rs.count; ++i) {
            drift_vec3 e = drift_vec3_make(rs.er[i], rs.eg[i], rs.eb[i]);
            drift_vec3 kd = drift_image_get3(&gb->albedo, rs.x[i], rs.y[i]);
            drift_image_set3(&ism->indirect, rs.x[i], rs.y[i],
                             drift_vec3_scale(drift_vec3_mul(kd, e), scale));
        }
    }
}

// The blurred irradiance of the gathering pixels to every pixel of `gb`, times its albedo.
drift_result drift__ism_upsample(drift_ism *ism, const drift_gbuffer *gb, drift_ism_stats *st)
{
    size_t count = (size_t)gb->width * (size_t)gb->height;
    upsample_job job = { .ism = ism, .gb = gb, .fallback = drift_alloc(ism->ctx, count) };
    if (!job.fallback) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    drift_parallel_for(ism->ctx, (size_t)gb->height, 4, upsample_rows, &job);
    size_t fallbacks = 0;
    for (size_t i = 0; i < count; ++i) {
        fallbacks += job.fallback[i];
    }
    drift_result r = DRIFT_OK;
    if (fallbacks > 0) {
        size_t threads = (size_t)drift_context_thread_count(ism->ctx);
        job.job_pixels = (fallbacks + 2 * threads - 1) / (2 * threads);
        uint32_t *pixels = drift_alloc(ism->ctx, fallbacks * sizeof *pixels);
        job.receiver_buffers =
            drift_alloc(ism->ctx, threads * job.job_pixels * RECEIVER_ARRAYS * sizeof(float));
        if (pixels && job.receiver_buffers) {
            for (size_t i = 0, k = 0; i < count; ++i) {
                if (job.fallback[i]) {
                    pixels[k++] = (uint32_t)i;
                }
            }
            job.fallback_pixels = pixels;
            job.fallback_count = fallbacks;
            drift_parallel_for(ism->ctx, (fallbacks + job.job_pixels - 1) / job.job_pixels, 1,
                               fallback_jobs, &job);
            for (int i = 0; i < DRIFT_MAX_THREADS; ++i) {
                st->shadow_rays += job.rays[i];
            }
        } else {
            r = DRIFT_ERR_OUT_OF_MEMORY;
        }
        drift_free(ism->ctx, pixels);
        drift_free(ism->ctx, job.receiver_buffers);
    }
    st->fallback_pixels = fallbacks;
    drift_free(ism->ctx, job.fallback);
    return r;
}
