// drift ism: the stages that build each VPL's map (splat and pull-push) and gather them into
// the receivers (interleaved, ISM, rays or no visibility), and the geometry-aware blur.
#include "core/vectorise.h"
#include "ism/ism_object.h"

#include <math.h>
#include <string.h>

// --- MAPS ---

// Splat and pull-push of one map back to back on one thread, so that the map (256 KB at 256^2)
// is still in that core's cache for pull-push: as two passes over the atlas (109 MB for the
// Breakfast Room's 417 maps of 256^2) each map went to memory and back in between.
void drift__ism_maps_range(size_t begin, size_t end, int thread, void *user)
{
    map_job *job = user;
    drift_ism *ism = job->ism;
    int32_t n = job->splat.n, levels = ism->params.pull_push_levels;
    size_t map = (size_t)n * (size_t)n;
    for (size_t j = begin; j < end; ++j) {
        float *depth = ism->atlas + j * ism->map_floats;
        uint32_t first = 0, count = 0;
        if (ism->points) {
            drift_points_subset(ism->points, (uint32_t)j, &first, &count);
        }
        double t0 = drift_time_now();
        drift__ism_splat(depth, &job->splat, ism->vpls[j].position, &ism->frames[j],
                         ism->points ? ism->points->position + first : NULL, count);
        double t1 = drift_time_now();
        if (ism->lazy_levels > 0) {
            drift__ism_pull(depth, n, ism->lazy_levels, ism->params.pull_push_threshold);
            job->empty[thread] += drift__ism_holes(depth, n, ism->lazy_levels, ism->disc_counts);
        } else {
            job->empty[thread] += drift__ism_pull_push(depth, n, levels > 0 ? levels : 0,
                                                       ism->params.pull_push_threshold,
                                                       ism->scratch + (size_t)thread * 2 * map);
        }
        job->seconds[thread][0] += t1 - t0;
        job->seconds[thread][1] += drift_time_now() - t1;
    }
}

// --- GATHERING ---

// A glossy VPL's lobe in the receiver loop: its axis and, for m = 2^squarings, a flag per
// squaring (1 to square, 0 to keep), so that cos^m is a fixed chain of multiplies with no
// select in the loop, which then stays vectorised.
typedef struct vpl_lobe {
    float x, y, z;
    float square[DRIFT_VPL_MAX_SQUARINGS];
} vpl_lobe;

static vpl_lobe vpl_lobe_of(const drift_vpl *v)
{
    vpl_lobe l = { .x = v->lobe.x, .y = v->lobe.y, .z = v->lobe.z };
    for (uint32_t k = 0; k < DRIFT_VPL_MAX_SQUARINGS; ++k) {
        l.square[k] = k < v->squarings ? 1.0f : 0.0f;
    }
    return l;
}

// cos^m of the angle between the lobe and the direction -a / |a| to the receiver.
static inline DRIFT_ALWAYS_INLINE float lobe_power(const vpl_lobe *l, float ax, float ay, float az,
                                                   float inv)
{
    float c = -(l->x * ax + l->y * ay + l->z * az) * inv;
    c = c > 0.0f ? c : 0.0f;
    for (uint32_t k = 0; k < DRIFT_VPL_MAX_SQUARINGS; ++k) {
        c *= 1.0f + l->square[k] * (c - 1.0f);
    }
    return c;
}

// VPL j's contribution to every receiver, visibility from its map. One loop without branches
// over the receivers (the compiler vectorises it): the facing tests, the paraboloid lookup
// and the geometry term are computed for all and masked at the end. With a = y_j - x and
// v = -a / |a| in the VPL's frame, v.xy / (1 + v.z) = -(a . t, a . b) / (|a| + c) where
// c = -a . n_j = |a| cos theta_j: the lookup needs one reciprocal, not the normalised w.
static inline DRIFT_ALWAYS_INLINE void
gather_vpl_ism_levels(const drift_vpl *v, const drift_frame *f, const float *restrict map,
                      const gather_consts *c, int32_t count, const float *restrict px,
                      const float *restrict py, const float *restrict pz, const float *restrict nx,
                      const float *restrict ny, const float *restrict nz, float *restrict er,
                      float *restrict eg, float *restrict eb, const int32_t levels,
                      const bool glossy)
{
    const float vx = v->position.x, vy = v->position.y, vz = v->position.z;
    const float mx = v->normal.x, my = v->normal.y, mz = v->normal.z;
    const float tx = f->x.x, ty = f->x.y, tz = f->x.z, bx = f->y.x, by = f->y.y, bz = f->y.z;
    const float fr = v->flux.x, fg = v->flux.y, fb = v->flux.z;
    const float half_n = 0.5f * (float)c->n, dmin2 = c->dmin2, bias = c->bias;
    const float texel = c->texel, splat_radius = c->splat_radius, threshold = c->threshold;
    const int32_t n = c->n;
    const float *l[5];
    drift__ism_levels_of(map, n, l);
    const vpl_lobe lobe = vpl_lobe_of(v);
    const float sr = v->glossy.x, sg = v->glossy.y, sb = v->glossy.z;
    DRIFT_IVDEP
    for (int32_t i = 0; i < count; ++i) {
        float ax = vx - px[i], ay = vy - py[i], az = vz - pz[i];
        float dx = nx[i] * ax + ny[i] * ay + nz[i] * az;
        float dj = -(mx * ax + my * ay + mz * az);
        float dist2 = ax * ax + ay * ay + az * az;
        dist2 = dist2 > 1e-30f ? dist2 : 1e-30f;
        float dist = sqrtf(dist2), inv = 1.0f / dist;
        float cos_x = dx * inv, cos_j = dj * inv;
        float s = 1.0f / (dist + (dj > 0.0f ? dj : 0.0f));
        float u = -(tx * ax + ty * ay + tz * az) * s, w = -(bx * ax + by * ay + bz * az) * s;
        // Texel coordinates clamped in floats first (also maps a NaN to the edge).
        float fu = (u + 1.0f) * half_n, fw = (w + 1.0f) * half_n;
        fu = fu > 0.0f ? fu : 0.0f;
        fw = fw > 0.0f ? fw : 0.0f;
        fu = fu < (float)(n - 1) ? fu : (float)(n - 1);
        fw = fw < (float)(n - 1) ? fw : (float)(n - 1);
        float stored = drift__ism_lookup_at(l[0], l[1], l[2], l[3], l[4], n, levels, threshold,
                                            (int32_t)fu, (int32_t)fw);
        // Slope-scaled: the receiver's own surface reaches the texel from as far as one texel
        // (2 (1 + v.z) / n radians) plus one splat radius (k sqrt(A_pt / pi) in the world)
        // away, over which its distance to the VPL changes by tan(theta_x) times.
        float cx = cos_x > 1e-6f ? cos_x : 1e-6f;
        float sin2 = 1.0f - cx * cx;
        float tan_x = sqrtf(sin2 > 0.0f ? sin2 : 0.0f) / cx;
        tan_x = tan_x < 5.0f ? tan_x : 5.0f;
        float reach = dist * texel * (1.0f + cos_j) + splat_radius;
        bool lit = (dx > 0.0f) & (dj > 0.0f) & (dist - bias - reach * tan_x <= stored);
        float g = cos_x * cos_j / (dist2 > dmin2 ? dist2 : dmin2);
        g = lit ? g : 0.0f;
        if (glossy) {
            float t = lobe_power(&lobe, ax, ay, az, inv) * g;
            er[i] += fr * g + sr * t;
            eg[i] += fg * g + sg * t;
            eb[i] += fb * g + sb * t;
        } else {
            er[i] += fr * g;
            eg[i] += fg * g;
            eb[i] += fb * g;
        }
    }
}

// One copy of the loop per pyramid depth and lobe, each without a branch on them (so that it
// vectorises).
#define GATHER_ISM_LEVELS(L, G, NAME)                                                              \
    DRIFT_AVX2_CLONES static void NAME(const drift_vpl *v, const drift_frame *f, const float *map, \
                                       const gather_consts *c, receivers *rs)                      \
    {                                                                                              \
        gather_vpl_ism_levels(v, f, map, c, rs->count, rs->px, rs->py, rs->pz, rs->nx, rs->ny,     \
                              rs->nz, rs->er, rs->eg, rs->eb, L, G);                               \
    }
GATHER_ISM_LEVELS(0, false, gather_vpl_ism0)
GATHER_ISM_LEVELS(1, false, gather_vpl_ism1)
GATHER_ISM_LEVELS(2, false, gather_vpl_ism2)
GATHER_ISM_LEVELS(0, true, gather_vpl_ism0_glossy)
GATHER_ISM_LEVELS(1, true, gather_vpl_ism1_glossy)
GATHER_ISM_LEVELS(2, true, gather_vpl_ism2_glossy)
#undef GATHER_ISM_LEVELS

// The same without a lookup: every facing VPL is visible.
static void gather_vpl_none(const drift_vpl *v, const gather_consts *c, int32_t count,
                            const float *restrict px, const float *restrict py,
                            const float *restrict pz, const float *restrict nx,
                            const float *restrict ny, const float *restrict nz, float *restrict er,
                            float *restrict eg, float *restrict eb)
{
    const float vx = v->position.x, vy = v->position.y, vz = v->position.z;
    const float mx = v->normal.x, my = v->normal.y, mz = v->normal.z;
    const float fr = v->flux.x, fg = v->flux.y, fb = v->flux.z, dmin2 = c->dmin2;
    const bool glossy = !drift_vec3_is_zero(v->glossy);
    const vpl_lobe lobe = vpl_lobe_of(v);
    const float sr = v->glossy.x, sg = v->glossy.y, sb = v->glossy.z;
    for (int32_t i = 0; i < count; ++i) {
        float ax = vx - px[i], ay = vy - py[i], az = vz - pz[i];
        float dx = nx[i] * ax + ny[i] * ay + nz[i] * az;
        float dj = -(mx * ax + my * ay + mz * az);
        float dist2 = ax * ax + ay * ay + az * az;
        dist2 = dist2 > 1e-30f ? dist2 : 1e-30f;
        // cos_x cos_j / max(d^2, dmin^2) = dx dj / (d^2 max(d^2, dmin^2)).
        float g = dx * dj / (dist2 * (dist2 > dmin2 ? dist2 : dmin2));
        g = ((dx > 0.0f) & (dj > 0.0f)) ? g : 0.0f;
        float t = glossy ? lobe_power(&lobe, ax, ay, az, 1.0f / sqrtf(dist2)) * g : 0.0f;
        er[i] += fr * g + sr * t;
        eg[i] += fg * g + sg * t;
        eb[i] += fb * g + sb * t;
    }
}

// The `ir` baseline: one shadow ray per facing receiver (Embree; not vectorised).
static void gather_vpl_rays(const drift_ism *ism, const drift_vpl *v, receivers *rs,
                            const gather_consts *c, uint64_t *rays)
{
    const bool glossy = !drift_vec3_is_zero(v->glossy);
    const vpl_lobe lobe = vpl_lobe_of(v);
    for (int32_t i = 0; i < rs->count; ++i) {
        drift_vec3 xp = { rs->px[i], rs->py[i], rs->pz[i] };
        drift_vec3 d = drift_vec3_sub(v->position, xp);
        float dx = rs->nx[i] * d.x + rs->ny[i] * d.y + rs->nz[i] * d.z;
        float dj = -drift_vec3_dot(v->normal, d);
        if (dx <= 0.0f || dj <= 0.0f) {
            continue;
        }
        float dist2 = drift_vec3_dot(d, d);
        float dist = sqrtf(dist2), inv = 1.0f / dist;
        drift_vec3 w = drift_vec3_scale(d, inv);
        drift_vec3 o = drift_offset_origin(xp, (drift_vec3){ rs->gx[i], rs->gy[i], rs->gz[i] }, w);
        float len = drift_vec3_length(drift_vec3_sub(v->position, o));
        drift_ray ray = { o, 0.0f, w, len * 0.999f - 1e-4f * c->diagonal, 0 };
        (*rays)++;
        if (ray.tmax > 0.0f && drift_accel_occluded(ism->accel, &ray)) {
            continue;
        }
        float g = dx * inv * dj * inv / fmaxf(dist2, c->dmin2);
        float t = glossy ? lobe_power(&lobe, d.x, d.y, d.z, inv) * g : 0.0f;
        rs->er[i] += v->flux.x * g + v->glossy.x * t;
        rs->eg[i] += v->flux.y * g + v->glossy.y * t;
        rs->eb[i] += v->flux.z * g + v->glossy.z * t;
    }
}

receivers drift__ism_receivers_in(float *b, size_t cap)
{
    receivers rs = { .px = b,
                     .py = b + cap,
                     .pz = b + 2 * cap,
                     .nx = b + 3 * cap,
                     .ny = b + 4 * cap,
                     .nz = b + 5 * cap,
                     .gx = b + 6 * cap,
                     .gy = b + 7 * cap,
                     .gz = b + 8 * cap,
                     .er = b + 9 * cap,
                     .eg = b + 10 * cap,
                     .eb = b + 11 * cap,
                     .x = (int32_t *)(b + 12 * cap),
                     .y = (int32_t *)(b + 13 * cap) };
    return rs;
}

static receivers job_receivers(const gather_job *job, int thread)
{
    size_t cap = (size_t)job->capacity;
    return drift__ism_receivers_in(job->buffers + (size_t)thread * cap * RECEIVER_ARRAYS, cap);
}

gather_consts drift__ism_gather_consts(const drift_ism *ism)
{
    const drift_ism_params *p = &ism->params;
    return (gather_consts){ .dmin2 = p->clamp_distance * p->clamp_distance,
                            .bias = p->depth_bias,
                            .texel = 2.0f / (float)p->map_size,
                            .splat_radius = ism->splat_radius,
                            .diagonal = ism->diagonal,
                            .threshold = p->pull_push_threshold,
                            .n = p->map_size,
                            .levels = ism->lazy_levels };
}

// VPL j's irradiance added to every receiver of rs, its visibility as the params choose.
void drift__ism_gather_vpl(const drift_ism *ism, uint32_t j, const gather_consts *c, receivers *rs,
                           uint64_t *rays)
{
    const drift_ism_params *p = &ism->params;
    if (p->visibility == DRIFT_ISM_VISIBILITY_ISM) {
        const float *m = ism->atlas + j * ism->map_floats;
        typedef void gather_fn(const drift_vpl *, const drift_frame *, const float *,
                               const gather_consts *, receivers *);
        static gather_fn *const gathers[2][3] = {
            { gather_vpl_ism0, gather_vpl_ism1, gather_vpl_ism2 },
            { gather_vpl_ism0_glossy, gather_vpl_ism1_glossy, gather_vpl_ism2_glossy },
        };
        bool glossy = !drift_vec3_is_zero(ism->vpls[j].glossy);
        gathers[glossy][c->levels == 2 ? 2 : c->levels == 1](&ism->vpls[j], &ism->frames[j], m, c,
                                                             rs);
    } else if (p->visibility == DRIFT_ISM_VISIBILITY_RAYS) {
        gather_vpl_rays(ism, &ism->vpls[j], rs, c, rays);
    } else {
        gather_vpl_none(&ism->vpls[j], c, rs->count, rs->px, rs->py, rs->pz, rs->nx, rs->ny, rs->nz,
                        rs->er, rs->eg, rs->eb);
    }
}

// Job = (band of rows, subset k): the band's pixels of subset k gather that subset's VPLs,
// VPL by VPL (one map in cache at a time, read by every receiver of the band), each receiver
// summing its VPLs in the same order whatever the threads.
// Run `run` of `runs` equal runs of group g's VPLs: [*first, *last). Consecutive runs tile the
// group, so summing them gathers each VPL once.
void drift__ism_group_run(const drift_ism *ism, uint32_t g, uint64_t run, uint64_t runs,
                          uint32_t *first, uint32_t *last)
{
    uint64_t first_vpl = ism->groups[g], size = (uint64_t)ism->groups[g + 1] - first_vpl;
    *first = (uint32_t)(first_vpl + size * run / runs);
    *last = (uint32_t)(first_vpl + size * (run + 1) / runs);
}

void drift__ism_gather_jobs(size_t begin, size_t end, int thread, void *user)
{
    gather_job *job = user;
    drift_ism *ism = job->ism;
    const drift_gbuffer *gb = job->gb;
    const drift_ism_params *p = &ism->params;
    int32_t b = p->block_size;
    uint64_t subsets = (uint64_t)b * (uint64_t)b;
    gather_consts c = drift__ism_gather_consts(ism);
    receivers rs = job_receivers(job, thread);
    for (size_t id = begin; id < end; ++id) {
        int32_t band = (int32_t)(id / subsets);
        uint64_t k = id % subsets;
        int32_t k_x = (int32_t)(k % (uint64_t)b), k_y = (int32_t)(k / (uint64_t)b);
        rs.count = 0;
        for (int32_t r = 0; r < job->subset_rows; ++r) {
            int32_t y = (band * job->subset_rows + r) * b + k_y;
            if (y >= gb->height) {
                break;
            }
            const float *mat = drift_image_pixel(&gb->material_id, 0, y);
            const float *pos = drift_image_pixel(&gb->position, 0, y);
            const float *nrm = drift_image_pixel(&gb->normal, 0, y);
            const float *geo = drift_image_pixel(&gb->geometric_normal, 0, y);
            int32_t mc = gb->material_id.channels, pc = gb->position.channels;
            int32_t nc = gb->normal.channels, gc = gb->geometric_normal.channels;
            for (int32_t x = k_x; x < gb->width; x += b) {
                if (mat[(size_t)x * (size_t)mc] < 0.0f) {
                    drift_image_set3(&ism->irradiance, x, y, drift_vec3_splat(0.0f));
                    continue;
                }
                int32_t i = rs.count++;
                const float *q = pos + (size_t)x * (size_t)pc;
                rs.px[i] = q[0], rs.py[i] = q[1], rs.pz[i] = q[2];
                q = nrm + (size_t)x * (size_t)nc;
                rs.nx[i] = q[0], rs.ny[i] = q[1], rs.nz[i] = q[2];
                q = geo + (size_t)x * (size_t)gc;
                rs.gx[i] = q[0], rs.gy[i] = q[1], rs.gz[i] = q[2];
                rs.er[i] = rs.eg[i] = rs.eb[i] = 0.0f;
                rs.x[i] = x;
                rs.y[i] = y;
            }
        }
        if (rs.count == 0) {
            continue;
        }
        // Subset k of the S = B^2 subsets takes the k-th run of each group of VPLs (one bounce
        // of one round of light paths). Consecutive paths are consecutive Sobol samples, so
        // each run is a stratified sample of the group (a stride of S instead would give
        // every subset one elementary interval of the light's domain). S times the subset's
        // sum, averaged over the S pixels of a block, is the sum over all VPLs. A slice of n
        // splits each run in n again and takes its own part, at n times the light.
        uint64_t runs = subsets * ism->slices, run = k * ism->slices + ism->slice;
        for (uint32_t g = 0; g < ism->group_count; ++g) {
            uint32_t first, last;
            drift__ism_group_run(ism, g, run, runs, &first, &last);
            for (uint32_t j = first; j < last; ++j) {
                drift__ism_gather_vpl(ism, j, &c, &rs, &job->rays[thread]);
            }
        }
        float scale = (float)runs * DRIFT_INV_PI;
        for (int32_t i = 0; i < rs.count; ++i) {
            drift_image_set3(&ism->irradiance, rs.x[i], rs.y[i],
                             drift_vec3_make(rs.er[i] * scale, rs.eg[i] * scale, rs.eb[i] * scale));
        }
    }
}

// The block-sized window of `in` around (x, y), averaging only the pixels whose normal and plane
// agree with the centre's (Segovia et al. 2006): the blur's rule at one pixel.
drift_vec3 drift__ism_block_average(const drift_ism *ism, const drift_gbuffer *gb,
                                    const drift_image *in, int32_t x, int32_t y)
{
    int32_t b = ism->params.no_blur ? 1 : ism->params.block_size;
    drift_vec3 e = drift_image_get3(in, x, y);
    if (b <= 1) {
        return e;
    }
    int32_t lo = -(b / 2), hi = lo + b;
    float blur_normal = ism->params.blur_normal, blur_plane = ism->params.blur_plane;
    const drift_image *mat = &gb->material_id, *pos = &gb->position, *nrm = &gb->normal;
    int32_t y0 = y + lo < 0 ? 0 : y + lo, y1 = y + hi > gb->height ? gb->height : y + hi;
    int32_t x0 = x + lo < 0 ? 0 : x + lo, x1 = x + hi > gb->width ? gb->width : x + hi;
    const float *c = drift_image_pixel(pos, x, y), *cn = drift_image_pixel(nrm, x, y);
    float sr = 0.0f, sg = 0.0f, sb = 0.0f, weight = 0.0f;
    for (int32_t yy = y0; yy < y1; ++yy) {
        const float *m = drift_image_pixel(mat, 0, yy);
        const float *pp = drift_image_pixel(pos, 0, yy);
        const float *nn = drift_image_pixel(nrm, 0, yy);
        const float *ee = drift_image_pixel(in, 0, yy);
        for (int32_t xx = x0; xx < x1; ++xx) {
            const float *q = pp + (size_t)xx * (size_t)pos->channels;
            const float *qn = nn + (size_t)xx * (size_t)nrm->channels;
            float plane =
                fabsf(cn[0] * (q[0] - c[0]) + cn[1] * (q[1] - c[1]) + cn[2] * (q[2] - c[2]));
            float cosn = cn[0] * qn[0] + cn[1] * qn[1] + cn[2] * qn[2];
            if (m[(size_t)xx * (size_t)mat->channels] < 0.0f || cosn < blur_normal ||
                plane > blur_plane) {
                continue;
            }
            const float *qe = ee + (size_t)xx * (size_t)in->channels;
            sr += qe[0];
            sg += qe[1];
            sb += qe[2];
            weight += 1.0f;
        }
    }
    return weight > 0.0f ? drift_vec3_make(sr / weight, sg / weight, sb / weight) : e;
}

// The blur over rows as structure of arrays, so that each offset of the window is one loop
// over x that vectorises: a row's positions, normals, a mask of the pixels with a surface, and
// the irradiance (plus the near-field compensation's). block_average's rule, whole rows at a
// time.
typedef struct blur_row {
    float *px, *py, *pz, *nx, *ny, *nz, *surface, *er, *eg, *eb;
} blur_row;

#define BLUR_ROW_ARRAYS 10

// Floats of one thread's blur scratch: the row copies of a job and four sums a pixel.
size_t drift__ism_blur_scratch_floats(int32_t width, int32_t block_size)
{
    return (size_t)width * ((size_t)(BLUR_JOB_ROWS + block_size - 1) * BLUR_ROW_ARRAYS + 4);
}

static void blur_copy_row(const drift_ism *ism, const drift_gbuffer *gb, bool near_field, int32_t y,
                          const blur_row *r)
{
    const float *p = drift_image_pixel(&gb->position, 0, y);
    const float *n = drift_image_pixel(&gb->normal, 0, y);
    const float *m = drift_image_pixel(&gb->material_id, 0, y);
    const float *e = drift_image_pixel(&ism->irradiance, 0, y);
    const float *f = drift_image_pixel(&ism->near_spread, 0, y);
    for (int32_t x = 0; x < gb->width; ++x, p += 3, n += 3, e += 3, f += 3) {
        r->px[x] = p[0];
        r->py[x] = p[1];
        r->pz[x] = p[2];
        r->nx[x] = n[0];
        r->ny[x] = n[1];
        r->nz[x] = n[2];
        r->surface[x] = m[x] < 0.0f ? 0.0f : 1.0f;
        r->er[x] = near_field ? e[0] + f[0] : e[0];
        r->eg[x] = near_field ? e[1] + f[1] : e[1];
        r->eb[x] = near_field ? e[2] + f[2] : e[2];
    }
}

// Adds the pixels of row q at offset dx that pass the centres' tests (row c) to the sums of
// centres x0..x1-1.
DRIFT_AVX2_CLONES static void blur_accumulate(const blur_row *c, const blur_row *q, int32_t x0,
                                              int32_t x1, int32_t dx, float blur_normal,
                                              float blur_plane, float *restrict sr,
                                              float *restrict sg, float *restrict sb,
                                              float *restrict weight)
{
    const float *restrict cpx = c->px, *restrict cpy = c->py, *restrict cpz = c->pz;
    const float *restrict cnx = c->nx, *restrict cny = c->ny, *restrict cnz = c->nz;
    const float *restrict qpx = q->px + dx, *restrict qpy = q->py + dx, *restrict qpz = q->pz + dx;
    const float *restrict qnx = q->nx + dx, *restrict qny = q->ny + dx, *restrict qnz = q->nz + dx;
    const float *restrict qs = q->surface + dx, *restrict qr = q->er + dx;
    const float *restrict qg = q->eg + dx, *restrict qb = q->eb + dx;
    DRIFT_IVDEP
    for (int32_t x = x0; x < x1; ++x) {
        float d =
            cnx[x] * (qpx[x] - cpx[x]) + cny[x] * (qpy[x] - cpy[x]) + cnz[x] * (qpz[x] - cpz[x]);
        float cosn = cnx[x] * qnx[x] + cny[x] * qny[x] + cnz[x] * qnz[x];
        // block_average's tests without branches (& not &&), so that the loop vectorises.
        bool keep =
            (qs[x] != 0.0f) & (cosn >= blur_normal) & (d <= blur_plane) & (-d <= blur_plane);
        sr[x] += keep ? qr[x] : 0.0f;
        sg[x] += keep ? qg[x] : 0.0f;
        sb[x] += keep ? qb[x] : 0.0f;
        weight[x] += keep ? 1.0f : 0.0f;
    }
}

// I = kd / pi times the block average of the irradiance and the near-field compensation's,
// rows begin..end-1 of one job.
void drift__ism_blur_rows(size_t begin, size_t end, int thread, void *user)
{
    gather_job *job = user;
    drift_ism *ism = job->ism;
    const drift_gbuffer *gb = job->gb;
    int32_t w = gb->width, b = ism->params.no_blur ? 1 : ism->params.block_size;
    int32_t lo = -(b / 2), hi = lo + b;
    int32_t first = (int32_t)begin + lo < 0 ? 0 : (int32_t)begin + lo;
    int32_t last = (int32_t)end - 1 + hi > gb->height ? gb->height : (int32_t)end - 1 + hi;
    int32_t rows = last - first;
    float *scratch = job->blur_scratch + (size_t)thread * drift__ism_blur_scratch_floats(w, b);
    blur_row soa[64 + 3];
    for (int32_t i = 0; i < rows; ++i) {
        float *a = scratch + (size_t)i * BLUR_ROW_ARRAYS * (size_t)w;
        soa[i] = (blur_row){ a,         a + w,     a + 2 * w, a + 3 * w, a + 4 * w,
                             a + 5 * w, a + 6 * w, a + 7 * w, a + 8 * w, a + 9 * w };
        blur_copy_row(ism, gb, job->near_field, first + i, &soa[i]);
    }
    float *sums = scratch + (size_t)rows * BLUR_ROW_ARRAYS * (size_t)w;
    float *sr = sums, *sg = sums + w, *sb = sums + 2 * w, *weight = sums + 3 * w;
    float blur_normal = ism->params.blur_normal, blur_plane = ism->params.blur_plane;
    for (size_t row = begin; row < end; ++row) {
        int32_t y = (int32_t)row;
        const blur_row *c = &soa[y - first];
        memset(sums, 0, sizeof(float) * 4 * (size_t)w);
        int32_t y0 = y + lo < 0 ? 0 : y + lo, y1 = y + hi > gb->height ? gb->height : y + hi;
        for (int32_t yy = y0; yy < y1; ++yy) {
            for (int32_t dx = lo; dx < hi; ++dx) {
                int32_t x0 = dx < 0 ? -dx : 0, x1 = dx > 0 ? w - dx : w;
                blur_accumulate(c, &soa[yy - first], x0, x1, dx, blur_normal, blur_plane, sr, sg,
                                sb, weight);
            }
        }
        for (int32_t x = 0; x < w; ++x) {
            drift_vec3 e = drift_vec3_splat(0.0f);
            if (c->surface[x] != 0.0f) {
                e = weight[x] > 0.0f
                        ? drift_vec3_make(sr[x] / weight[x], sg[x] / weight[x], sb[x] / weight[x])
                        : drift_vec3_make(c->er[x], c->eg[x], c->eb[x]);
            }
            if (job->blur_to_coarse) {
                drift_image_set3(&ism->coarse_blurred, x, y, e);
                continue;
            }
            drift_vec3 kd = drift_image_get3(&gb->albedo, x, y);
            drift_image_set3(&ism->indirect, x, y,
                             drift_vec3_scale(drift_vec3_mul(kd, e), DRIFT_INV_PI));
        }
    }
}
