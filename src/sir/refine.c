// Smart Image Refinement: lifecycle, begin (metrics, combination, sort, request list) and the
// iterations that trace the request buffer and blend the results into the raster image.
#include "sir/sir.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#define DEFAULT_SPP        16
#define DEFAULT_DEPTH      3
#define DEFAULT_EDGE       0.05f
#define DEFAULT_AO_SAMPLES 8
// Display-value error a metric lets pass: half the bench's real-error threshold (0.02).
#define DEFAULT_TOLERANCE    0.01f
#define DEFAULT_LOBE_SAMPLES 4

static const char *const metric_names[] = { "reflection1", "reflection2", "reflection3",
                                            "reflection4", "reflection5", "dof",
                                            "shadow",      "leak" };
_Static_assert(sizeof metric_names / sizeof *metric_names == DRIFT_METRIC_COUNT, "names");

const char *drift_refine_metric_name(drift_refine_metric metric)
{
    return (unsigned)metric < DRIFT_METRIC_COUNT ? metric_names[metric] : NULL;
}

int drift_refine_metric_parse(const char *name)
{
    for (int m = 0; name && m < DRIFT_METRIC_COUNT; ++m) {
        if (strcmp(metric_names[m], name) == 0) {
            return m;
        }
    }
    return -1;
}

// One entry of the request buffer: a pixel and the samples it gets this iteration.
typedef struct request {
    uint32_t pixel;
    uint32_t samples;
} request;

struct drift_refine {
    drift_context *ctx;
    drift_hybrid *frame;
    drift_refine_params params;
    int32_t width, height;
    drift_refine_tracer tracer;

    drift_image metrics[DRIFT_METRIC_COUNT]; // 1 each
    drift_image combined;                    // 1
    drift_image refined;                     // 3: the output
    drift_image mask;                        // 1: 1 where a pixel has all its samples
    drift_image samples_plane;               // 1: samples received

    uint16_t *keys;
    uint32_t *order; // pixels by descending error (the sorted error buffer)
    uint32_t *scratch;
    uint32_t list_count;        // the request list: order[0 .. list_count)
    uint32_t cursor;            // next entry of the list to visit
    uint64_t incomplete;        // listed pixels still short of spp
    uint32_t error_count;       // order[0 .. error_count): the non-zero errors
    uint64_t incomplete_errors; // of those, still short of spp
    uint64_t lacking;           // samples the listed pixels still lack
    request *requests;          // the request buffer of one iteration
    uint32_t *counts;           // samples received, per pixel
    uint8_t *reflection_only;   // 1: flagged by reflection metrics alone (params.components)
    double *sums;               // 3 a pixel
    drift_ray_counter *counters;
    int thread_count;
    drift_refine_stats stats;
};

drift_refine_params drift_refine_params_resolve(const drift_refine_params *params,
                                                const drift_hybrid *frame)
{
    drift_refine_params p = params ? *params : (drift_refine_params){ 0 };
    drift_hybrid_params h = drift_hybrid_get_params(frame);
    if (p.budget == 0) {
        p.budget = (uint32_t)h.width * (uint32_t)h.height;
    }
    p.spp = p.spp ? p.spp : DEFAULT_SPP;
    p.visit_spp = p.visit_spp ? p.visit_spp : p.spp;
    p.max_depth = p.max_depth ? p.max_depth : DEFAULT_DEPTH;
    p.edge_threshold = p.edge_threshold > 0.0f ? p.edge_threshold : DEFAULT_EDGE;
    p.ao_samples = p.ao_samples ? p.ao_samples : DEFAULT_AO_SAMPLES;
    p.reflection_tolerance =
        p.reflection_tolerance != 0.0f ? p.reflection_tolerance : DEFAULT_TOLERANCE;
    p.lobe_samples = p.lobe_samples ? p.lobe_samples : DEFAULT_LOBE_SAMPLES;
    p.leak_tolerance = p.leak_tolerance != 0.0f ? p.leak_tolerance : DEFAULT_TOLERANCE;
    p.shadow_tolerance = p.shadow_tolerance != 0.0f ? p.shadow_tolerance : DEFAULT_TOLERANCE;
    if (p.combine == DRIFT_COMBINE_DEFAULT) {
        p.combine = p.reflection_tolerance < 0.0f ? DRIFT_COMBINE_AVERAGE : DRIFT_COMBINE_MAX;
    }
    return p;
}

static bool params_valid(drift_context *ctx, const drift_refine_params *p)
{
    const char *problem = NULL;
    if (p->max_depth < 0 || p->max_depth > 64) {
        problem = "max_depth outside 0..64";
    } else if ((unsigned)p->combine >= DRIFT_COMBINE_COUNT) {
        problem = "unknown combination";
    } else if (!isfinite(p->edge_threshold) || !isfinite(p->ao_radius) || p->ao_radius < 0.0f ||
               !isfinite(p->reflection_tolerance) || !isfinite(p->leak_tolerance) ||
               !isfinite(p->shadow_tolerance)) {
        problem = "non-finite edge threshold, AO radius or tolerance";
    }
    for (int m = 0; !problem && m < DRIFT_METRIC_COUNT; ++m) {
        if (!(p->lambda[m] >= 0.0f) || !isfinite(p->lambda[m])) {
            problem = "lambda must be finite and non-negative";
        }
    }
    if (problem) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_INVALID_ARGUMENT, NULL, 0, "refine: %s", problem);
    }
    return problem == NULL;
}

void drift_refine_destroy(drift_refine *r)
{
    if (!r) {
        return;
    }
    for (int m = 0; m < DRIFT_METRIC_COUNT; ++m) {
        drift_image_destroy(r->ctx, &r->metrics[m]);
    }
    drift_image *images[] = { &r->combined, &r->refined, &r->mask, &r->samples_plane };
    for (size_t i = 0; i < sizeof images / sizeof *images; ++i) {
        drift_image_destroy(r->ctx, images[i]);
    }
    drift_free(r->ctx, r->keys);
    drift_free(r->ctx, r->order);
    drift_free(r->ctx, r->scratch);
    drift_free(r->ctx, r->requests);
    drift_free(r->ctx, r->counts);
    drift_free(r->ctx, r->reflection_only);
    drift_free(r->ctx, r->sums);
    drift_free(r->ctx, r->counters);
    drift_free(r->ctx, r);
}

drift_result drift_refine_create(drift_context *ctx, drift_hybrid *frame,
                                 const drift_refine_params *params, drift_refine **out)
{
    if (!out) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    *out = NULL;
    if (!ctx || !frame) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    drift_refine_params p = drift_refine_params_resolve(params, frame);
    if (!params_valid(ctx, &p)) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    drift_refine *r = drift_alloc(ctx, sizeof(drift_refine));
    if (!r) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    r->ctx = ctx;
    r->frame = frame;
    r->params = p;
    r->width = drift_hybrid_get_params(frame).width;
    r->height = drift_hybrid_get_params(frame).height;
    r->thread_count = drift_context_thread_count(ctx);
    size_t n = (size_t)r->width * (size_t)r->height;
    drift_result result = DRIFT_OK;
    for (int m = 0; result == DRIFT_OK && m < DRIFT_METRIC_COUNT; ++m) {
        result = drift_image_create(ctx, r->width, r->height, 1, &r->metrics[m]);
    }
    drift_image *ones[] = { &r->combined, &r->mask, &r->samples_plane };
    for (size_t i = 0; result == DRIFT_OK && i < sizeof ones / sizeof *ones; ++i) {
        result = drift_image_create(ctx, r->width, r->height, 1, ones[i]);
    }
    if (result == DRIFT_OK) {
        result = drift_image_create(ctx, r->width, r->height, 3, &r->refined);
    }
    if (result == DRIFT_OK) {
        r->keys = drift_alloc(ctx, sizeof(uint16_t) * n);
        r->order = drift_alloc(ctx, sizeof(uint32_t) * n);
        r->scratch = drift_alloc(ctx, sizeof(uint32_t) * n);
        r->requests = drift_alloc(ctx, sizeof(request) * n);
        r->counts = drift_alloc(ctx, sizeof(uint32_t) * n);
        r->reflection_only = drift_alloc(ctx, n);
        r->sums = drift_alloc(ctx, sizeof(double) * 3 * n);
        r->counters = drift_alloc(ctx, sizeof(drift_ray_counter) * (size_t)r->thread_count);
        result = r->keys && r->order && r->scratch && r->requests && r->counts &&
                         r->reflection_only && r->sums && r->counters
                     ? DRIFT_OK
                     : DRIFT_ERR_OUT_OF_MEMORY;
    }
    if (result != DRIFT_OK) {
        drift_refine_destroy(r);
        return result;
    }
    *out = r;
    return DRIFT_OK;
}

drift_result drift_refine_set_params(drift_refine *r, const drift_refine_params *params)
{
    drift_refine_params p = drift_refine_params_resolve(params, r->frame);
    if (!params_valid(r->ctx, &p)) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    r->params = p;
    return DRIFT_OK;
}

// The tracer sees what the raster approximates: no lens when the frame renders no depth of
// field.
static drift_refine_tracer make_tracer(const drift_refine *r)
{
    drift_refine_tracer t =
        drift_refine_tracer_make(drift_hybrid_frame(r->frame), r->params.seed, r->params.max_depth);
    if (drift_hybrid_get_params(r->frame).dof == DRIFT_DOF_NONE) {
        t.camera.camera.aperture_radius = 0.0f;
    }
    return t;
}

// Component refinement (params.components): a pixel whose only non-zero metrics are the
// reflection metrics has its raster E + D right by the metrics' own account, so only R is
// traced there and the raster's R replaced (raster - R_raster + R_traced). Only where the
// pixel is the composed E + D + R (+ I): one anti-aliasing pass and a pinhole tracer (with a
// lens, the post blur mixes neighbours into the pixel); never with refine_zero_error, whose
// whole image converges to the pure one.
static void mark_reflection_only(drift_refine *r)
{
    uint32_t n = (uint32_t)r->width * (uint32_t)r->height;
    memset(r->reflection_only, 0, n);
    drift_hybrid_params h = drift_hybrid_get_params(r->frame);
    if (!r->params.components || r->params.refine_zero_error || h.aa > 1 ||
        h.reflections == DRIFT_REFLECTIONS_NONE || r->tracer.camera.camera.aperture_radius > 0.0f) {
        return;
    }
    for (uint32_t i = 0; i < n; ++i) {
        bool other = false, reflection = false;
        for (int m = 0; m < DRIFT_METRIC_COUNT; ++m) {
            bool set = r->metrics[m].pixels[i] > 0.0f;
            if (m <= DRIFT_METRIC_REFLECTION5) {
                reflection |= set;
            } else {
                other |= set;
            }
        }
        r->reflection_only[i] = reflection && !other;
    }
}

drift_result drift_refine_begin(drift_refine *r)
{
    if (!r) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    drift_refine_stats *st = &r->stats;
    uint32_t sorts = st->sorts;
    *st = (drift_refine_stats){ .sorts = sorts + 1 };
    r->tracer = make_tracer(r);

    double t = drift_time_now();
    drift_refine_metric_params mp = { .edge_threshold = r->params.edge_threshold,
                                      .ao_radius = r->params.ao_radius,
                                      .ao_samples = r->params.ao_samples,
                                      .reflection_tolerance = r->params.reflection_tolerance,
                                      .lobe_samples = r->params.lobe_samples,
                                      .leak_tolerance = r->params.leak_tolerance,
                                      .shadow_tolerance = r->params.shadow_tolerance,
                                      .half_res_penumbra = !r->params.full_res_penumbra &&
                                                           r->params.shadow_tolerance > 0.0f,
                                      .seed = r->params.seed };
    st->metrics_rays = drift_refine_compute_metrics(drift_hybrid_frame(r->frame), &mp, r->metrics);
    st->metrics_ms = 1000.0 * (drift_time_now() - t);

    t = drift_time_now();
    drift_refine_combine_metrics(r->metrics, r->params.combine, r->params.lambda, &r->combined);
    uint32_t n = (uint32_t)r->width * (uint32_t)r->height;
    for (uint32_t i = 0; i < n; ++i) {
        r->keys[i] = (uint16_t)drift_refine_encode_error(r->combined.pixels[i]);
        st->error_pixels += r->keys[i] != DRIFT_REFINE_ZERO_KEY;
    }
    drift_refine_radix_sort(r->keys, n, r->order, r->scratch);
    r->list_count = r->params.refine_zero_error ? n : (uint32_t)st->error_pixels;
    r->cursor = 0;
    r->incomplete = r->list_count;
    r->error_count = (uint32_t)st->error_pixels;
    r->incomplete_errors = r->error_count;
    r->lacking = (uint64_t)r->list_count * r->params.spp;
    st->requested = r->list_count;
    memset(r->counts, 0, sizeof(uint32_t) * n);
    mark_reflection_only(r);
    memset(r->sums, 0, sizeof(double) * 3 * n);
    drift_pass_copy_rgb(drift_hybrid_image(r->frame), &r->refined);
    memset(r->mask.pixels, 0, sizeof(float) * n);
    memset(r->samples_plane.pixels, 0, sizeof(float) * n);
    st->sort_ms = 1000.0 * (drift_time_now() - t);
    return DRIFT_OK;
}

bool drift_refine_done(const drift_refine *r)
{
    return r->incomplete == 0;
}

typedef struct trace_job {
    drift_refine *refine;
    uint32_t count;
    const atomic_bool *cancel;
} trace_job;

static void trace_requests(size_t begin, size_t end, int thread_index, void *user)
{
    const trace_job *job = user;
    drift_refine *r = job->refine;
    uint64_t *rays = &r->counters[thread_index].rays;
    const drift_image *raster = drift_hybrid_image(r->frame);
    const drift_image *raster_r = &drift_hybrid_frame(r->frame)->reflections;
    uint32_t spp = r->params.spp;
    for (size_t i = begin; i < end; ++i) {
        if (job->cancel && atomic_load(job->cancel)) {
            return;
        }
        const request *q = &r->requests[i];
        int32_t x = (int32_t)(q->pixel % (uint32_t)r->width),
                y = (int32_t)(q->pixel / (uint32_t)r->width);
        double *sum = &r->sums[3 * (size_t)q->pixel];
        uint32_t first = r->counts[q->pixel];
        bool only_r = r->reflection_only[q->pixel];
        // Raster E + D (+ I) with this sample's R: the raster's R taken out.
        drift_vec3 kept =
            drift_vec3_sub(drift_image_get3(raster, x, y), drift_image_get3(raster_r, x, y));
        for (uint32_t s = first; s < first + q->samples; ++s) {
            drift_vec3 l = drift_refine_trace_sample(&r->tracer, x, y, s, only_r, rays);
            if (only_r) {
                l = drift_vec3_add(kept, l);
            }
            sum[0] += (double)l.x;
            sum[1] += (double)l.y;
            sum[2] += (double)l.z;
        }
        uint32_t count = first + q->samples;
        r->counts[q->pixel] = count;
        drift_vec3 mean = { (float)(sum[0] / (double)count), (float)(sum[1] / (double)count),
                            (float)(sum[2] / (double)count) };
        // The blend weight grows with the samples received; with all of them the pixel is
        // the ray-traced mean exactly.
        drift_vec3 out = mean;
        if (count < spp) {
            float w = (float)count / (float)spp;
            out = drift_vec3_add(drift_vec3_scale(drift_image_get3(raster, x, y), 1.0f - w),
                                 drift_vec3_scale(mean, w));
        }
        drift_image_set3(&r->refined, x, y, out);
        drift_image_pixel(&r->samples_plane, x, y)[0] = (float)count;
        drift_image_pixel(&r->mask, x, y)[0] = count >= spp ? 1.0f : 0.0f;
    }
}

drift_result drift_refine_iterate(drift_refine *r, const atomic_bool *cancel)
{
    if (!r) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    double t = drift_time_now();
    uint32_t spp = r->params.spp, budget = r->params.budget;
    // Fill the request buffer: from the cursor down the sorted list, each incomplete pixel
    // gets ceil(visit_spp * error) samples (at least 1, at most what it lacks; everything it
    // lacks when the budget covers all that is left) until the budget is spent. Zero-error
    // pixels wait until every error pixel is complete. One walk never passes the end of the
    // list, so a pixel appears at most once in the buffer.
    uint32_t count = 0, spent = 0;
    bool covers_all = r->lacking <= budget;
    uint32_t end = r->incomplete_errors > 0 && !covers_all ? r->error_count : r->list_count;
    if (r->cursor >= end) {
        r->cursor = 0;
    }
    while (r->cursor < end && spent < budget && r->incomplete > 0) {
        uint32_t pixel = r->order[r->cursor];
        uint32_t lacking = spp - r->counts[pixel];
        if (lacking == 0) {
            r->cursor++;
            continue;
        }
        float e = r->combined.pixels[pixel];
        uint32_t want = covers_all ? lacking : (uint32_t)ceilf((float)r->params.visit_spp * e);
        want = want < 1 ? 1 : (want > lacking ? lacking : want);
        if (want > budget - spent) {
            want = budget - spent;
        }
        r->requests[count++] = (request){ pixel, want };
        spent += want;
        r->lacking -= want;
        if (want == lacking) {
            r->incomplete--;
            r->incomplete_errors -= r->cursor < r->error_count;
        }
        r->cursor++;
    }
    for (int i = 0; i < r->thread_count; ++i) {
        r->counters[i].rays = 0;
    }
    trace_job job = { .refine = r, .count = count, .cancel = cancel };
    drift_parallel_for(r->ctx, count, 16, trace_requests, &job);
    for (int i = 0; i < r->thread_count; ++i) {
        r->stats.rays += r->counters[i].rays;
    }
    r->stats.samples += spent;
    r->stats.iterations++;
    r->stats.refined = r->list_count - r->incomplete;
    r->stats.trace_ms += 1000.0 * (drift_time_now() - t);
    return cancel && atomic_load(cancel) ? DRIFT_ERR_CANCELLED : DRIFT_OK;
}

const drift_image *drift_refine_image(const drift_refine *r)
{
    return &r->refined;
}

const drift_image *drift_refine_error(const drift_refine *r)
{
    return &r->combined;
}

const drift_image *drift_refine_metric_image(const drift_refine *r, drift_refine_metric m)
{
    return (unsigned)m < DRIFT_METRIC_COUNT ? &r->metrics[m] : NULL;
}

drift_refine_stats drift_refine_get_stats(const drift_refine *r)
{
    return r->stats;
}

bool drift_refine_plane(const drift_refine *r, uint32_t index, const char **out_name,
                        const drift_image **out_image)
{
    static const char *const fixed[] = { "refined", "error.combined", "refine.mask",
                                         "refine.samples" };
    static const char *const metric_planes[] = { "error.reflection1", "error.reflection2",
                                                 "error.reflection3", "error.reflection4",
                                                 "error.reflection5", "error.dof",
                                                 "error.shadow",      "error.leak" };
    _Static_assert(sizeof metric_planes / sizeof *metric_planes == DRIFT_METRIC_COUNT, "planes");
    const drift_image *fixed_images[] = { &r->refined, &r->combined, &r->mask, &r->samples_plane };
    if (index < 4) {
        *out_name = fixed[index];
        *out_image = fixed_images[index];
        return true;
    }
    index -= 4;
    if (index < DRIFT_METRIC_COUNT) {
        *out_name = metric_planes[index];
        *out_image = &r->metrics[index];
        return true;
    }
    return false;
}

// --- THE PURE IMAGE ---

typedef struct pure_job {
    drift_refine *refine;
    drift_refine_tracer tracer;
    uint32_t spp;
    drift_image *out;
    const atomic_bool *cancel;
} pure_job;

static void pure_rows(size_t begin, size_t end, int thread_index, void *user)
{
    const pure_job *job = user;
    uint64_t *rays = &job->refine->counters[thread_index].rays;
    for (size_t yy = begin; yy < end; ++yy) {
        if (job->cancel && atomic_load(job->cancel)) {
            return;
        }
        int32_t y = (int32_t)yy;
        for (int32_t x = 0; x < job->out->width; ++x) {
            double sum[3] = { 0.0, 0.0, 0.0 };
            for (uint32_t s = 0; s < job->spp; ++s) {
                drift_vec3 l = drift_refine_trace_sample(&job->tracer, x, y, s, false, rays);
                sum[0] += (double)l.x;
                sum[1] += (double)l.y;
                sum[2] += (double)l.z;
            }
            double n = (double)job->spp;
            drift_image_set3(
                job->out, x, y,
                (drift_vec3){ (float)(sum[0] / n), (float)(sum[1] / n), (float)(sum[2] / n) });
        }
    }
}

drift_result drift_refine_render_pure(drift_refine *r, uint32_t spp, drift_image *out,
                                      uint64_t *rays, const atomic_bool *cancel)
{
    if (!r || !out || spp == 0 || out->width != r->width || out->height != r->height ||
        out->channels < 3) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    for (int i = 0; i < r->thread_count; ++i) {
        r->counters[i].rays = 0;
    }
    pure_job job = {
        .refine = r, .tracer = make_tracer(r), .spp = spp, .out = out, .cancel = cancel
    };
    drift_parallel_for(r->ctx, (size_t)r->height, 1, pure_rows, &job);
    uint64_t total = 0;
    for (int i = 0; i < r->thread_count; ++i) {
        total += r->counters[i].rays;
    }
    if (rays) {
        *rays = total;
    }
    return cancel && atomic_load(cancel) ? DRIFT_ERR_CANCELLED : DRIFT_OK;
}
