// drift render --mode hybrid --budget-ms T (issue 40): the techniques chosen for the scene and
// the budget. The model (scenes/corpus/chooser.json, refitted by scripts/chooser/fit_table.py
// from drift bench frontier --corpus --json, docs/corpus.md) holds every candidate row (a
// hybrid combination; the path tracer: plain, through a-trous or the feature denoiser, at
// reduced resolution; or, if fitted with --guided, a hybrid frame guiding the path tracer)
// with its fitted cost, and for each scene it was fitted on its features
// and each row's FLIP over its best. A candidate's predicted FLIP comes from the nearest fitted
// scenes in standardised features, shrunk toward its mean over them all; the pick is the
// lowest predicted FLIP whose calibrated cost fits T (a hybrid row only clearly below the path
// tracer), and the renderer says what it chose. scripts/chooser/pick.py makes the same pick.
#include "cli.h"
#include "drift/knobs.h"
#include "render.h"
#include "scene_features.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

int render_print_features(const cli_session *session)
{
    double f[SCENE_FEATURE_COUNT];
    scene_features(session->ctx, session->scene, session->accel, f);
    printf("{");
    for (int k = 0; k < SCENE_FEATURE_COUNT; ++k) {
        printf("%s\"%s\": %.4f", k ? ", " : "", scene_feature_name(k), f[k]);
    }
    printf("}\n");
    return 0;
}

static char *read_text(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        return NULL;
    }
    size_t cap = 1 << 16, n = 0;
    char *text = malloc(cap + 1);
    size_t got;
    while (text && (got = fread(text + n, 1, cap - n, f)) > 0) {
        n += got;
        if (n == cap) {
            char *more = realloc(text, 2 * cap + 1);
            if (!more) {
                free(text);
                text = NULL;
                break;
            }
            text = more;
            cap *= 2;
        }
    }
    fclose(f);
    if (text) {
        text[n] = '\0';
    }
    return text;
}

static double number(const cJSON *o, const char *key, double otherwise)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
    return cJSON_IsNumber(v) ? v->valuedouble : otherwise;
}

static const char *string(const cJSON *o, const char *key)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
    return cJSON_IsString(v) ? v->valuestring : NULL;
}

// log ms at the model's size of candidate `c` on a scene of features `f`: its alpha plus its
// group's beta . the cost features.
static double predict_log_ms(const cJSON *model, const cJSON *c,
                             const double f[SCENE_FEATURE_COUNT],
                             const int cost_index[SCENE_FEATURE_COUNT], int cost_count)
{
    const cJSON *beta = cJSON_GetObjectItemCaseSensitive(
        cJSON_GetObjectItemCaseSensitive(model, "beta"), string(c, "group"));
    double y = number(c, "alpha", (double)INFINITY);
    for (int k = 0; k < cost_count; ++k) {
        const cJSON *b = cJSON_GetArrayItem(beta, k);
        y += (cJSON_IsNumber(b) ? b->valuedouble : 0.0) * f[cost_index[k]];
    }
    return y;
}

// The fitted ms at the model's size of candidate `c`: exp(its log ms), plus, for a hybrid+pt
// candidate (the guide's hybrid frame and the path tracer's samples through the guided
// filter), the ms of the path-tracer candidate its "plus" names (its n spp and a denoiser pass).
static double candidate_ms(const cJSON *model, const cJSON *c, const double f[SCENE_FEATURE_COUNT],
                           const int cost_index[SCENE_FEATURE_COUNT], int cost_count)
{
    double ms = exp(predict_log_ms(model, c, f, cost_index, cost_count));
    const char *plus = string(c, "plus");
    if (!plus) {
        return ms;
    }
    const cJSON *cands = cJSON_GetObjectItemCaseSensitive(model, "candidates");
    for (const cJSON *o = cands ? cands->child : NULL; o; o = o->next) {
        const char *k = string(o, "key");
        if (o != c && k && strcmp(k, plus) == 0 && !string(o, "plus")) {
            return ms + exp(predict_log_ms(model, o, f, cost_index, cost_count));
        }
    }
    return (double)INFINITY; // a model without the row it adds: never fits
}

// A fitted scene's FLIP ratio for `key` ("family|name"), or for the same row without its
// environment filter (" ef N": the filter has no light to filter on a scene without one).
static double flip_ratio(const cJSON *flips, const char *key)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(flips, key);
    if (cJSON_IsNumber(v)) {
        return v->valuedouble;
    }
    const char *ef = strstr(key, " ef ");
    if (!ef) {
        return (double)NAN;
    }
    char plain[256];
    const char *rest = ef + 4;
    while (*rest >= '0' && *rest <= '9') {
        ++rest;
    }
    snprintf(plain, sizeof plain, "%.*s%s", (int)(ef - key), key, rest);
    v = cJSON_GetObjectItemCaseSensitive(flips, plain);
    return cJSON_IsNumber(v) ? v->valuedouble : (double)NAN;
}

typedef struct neighbour {
    const cJSON *scene;
    double d2, w; // squared standardised distance; kernel weight (the k nearest sum to 1)
} neighbour;

static int compare_neighbour(const void *a, const void *b)
{
    double x = ((const neighbour *)a)->d2, y = ((const neighbour *)b)->d2;
    return (x > y) - (x < y);
}

// The quality model's parameters (the model's "k" and "quality"; without them, session 2's
// chooser: the 2 nearest, inverse-distance weights, no prior, ranked by the mean).
typedef struct quality_params {
    int k;      // nearest scenes (0: all)
    bool gauss; // weights exp(-d^2 / 2 bandwidth^2), else 1 / (d + 0.1)
    double bandwidth, prior, kappa;
} quality_params;

static quality_params read_quality(const cJSON *model)
{
    const cJSON *q = cJSON_GetObjectItemCaseSensitive(model, "quality");
    const char *kernel = string(q, "kernel");
    return (quality_params){ .k = (int)number(model, "k", 2),
                             .gauss = kernel && strcmp(kernel, "gauss") == 0,
                             .bandwidth = number(q, "bandwidth", 1.0),
                             .prior = number(q, "prior", 0.0),
                             .kappa = number(q, "kappa", 0.0) };
}

// The predicted FLIP ratio (over the best row's) of candidate `c`: the mean of the k nearest
// fitted scenes' log ratios (`near`, sorted and weighted), shrunk toward the candidate's prior
// (the mean over every fitted scene, weighing `prior` against the neighbourhood's 1). *rank:
// what the pick ranks by, exp(that mean + kappa x the spread of the log ratios about it): a
// row good on one neighbour and bad on another ranks below one good on both.
// scripts/chooser/fit_table.py's predict() is the same.
static double predict_flip(const neighbour *near, int k, const cJSON *c, const char *key,
                           const quality_params *qp, double *rank)
{
    double num = 0.0, den = 0.0;
    for (int i = 0; i < k; ++i) {
        double v = flip_ratio(cJSON_GetObjectItemCaseSensitive(near[i].scene, "flip"), key);
        if (v > 0.0) {
            num += near[i].w * log(v);
            den += near[i].w;
        }
    }
    const cJSON *prior = cJSON_GetObjectItemCaseSensitive(c, "prior");
    const cJSON *pm = cJSON_GetArrayItem(prior, 0), *pv = cJSON_GetArrayItem(prior, 1);
    double lambda = cJSON_IsNumber(pm) && cJSON_IsNumber(pv) ? qp->prior : 0.0;
    *rank = (double)INFINITY;
    if (!(den + lambda > 0.0)) {
        return (double)INFINITY;
    }
    double mean = lambda > 0.0 ? (num + lambda * pm->valuedouble) / (den + lambda) : num / den;
    double var = 0.0;
    for (int i = 0; i < k; ++i) {
        double v = flip_ratio(cJSON_GetObjectItemCaseSensitive(near[i].scene, "flip"), key);
        if (v > 0.0) {
            var += near[i].w * (log(v) - mean) * (log(v) - mean);
        }
    }
    if (lambda > 0.0) {
        var += lambda * (pv->valuedouble + (pm->valuedouble - mean) * (pm->valuedouble - mean));
    }
    var /= den + lambda;
    *rank = exp(mean + qp->kappa * sqrt(var));
    return exp(mean);
}

typedef struct choice {
    const cJSON *pick;
    double ms, flip, rank; // predicted at the frame's size; FLIP over the best row's; rank
} choice;

enum {
    GROUP_PT,
    GROUP_HYBRID,
    GROUP_COUNT
};

static int group_index(const char *group)
{
    return strcmp(group, "pt") == 0 ? GROUP_PT : GROUP_HYBRID;
}

// How the fitted costs become this run's: a candidate's predicted ms times its group's
// `scale` (1 without probes; else measured over predicted of the probe of its group) plus its
// group's `setup_ms` fits when that times `safety` is within `available_ms`.
typedef struct calibration {
    double scale[GROUP_COUNT], setup_ms[GROUP_COUNT], safety[GROUP_COUNT];
    const cJSON *setup_table; // the model's setup_ms: a hybrid candidate's techniques' set-up
    double setup_scale;       // its ms (at the load it records) to this load's
    double finish_ms;         // what every frame pays after it (the writes), predicted
    double load, cores, frame_cores; // the load average, the cores, the cores a frame gets
    double available_ms;
} calibration;

// The set-up a one-shot frame of hybrid candidate `c` pays for its techniques beyond the base
// row's, from the model's table (0 without one).
static double technique_setup_ms(const cJSON *table, const cJSON *c)
{
    double ms = 0.0;
    const char *effects[] = { "shadows", "indirect" };
    for (int e = 0; table && e < 2; ++e) {
        const char *name = string(c, effects[e]);
        ms += name ? number(cJSON_GetObjectItemCaseSensitive(table, effects[e]), name, 0.0) : 0.0;
    }
    if (table && number(c, "environment_filter", 0.0) > 0.0) {
        ms += number(cJSON_GetObjectItemCaseSensitive(table, "environment_filter"), "4", 0.0);
    }
    return ms;
}

// The model's cost features as indices of the scene's; false when the model is not one this
// build reads.
static bool cost_indices(const cJSON *model, int cost_index[SCENE_FEATURE_COUNT], int *cost_count)
{
    const cJSON *names = cJSON_GetObjectItemCaseSensitive(model, "features");
    const cJSON *cost_names = cJSON_GetObjectItemCaseSensitive(model, "cost_features");
    if (cJSON_GetArraySize(names) != SCENE_FEATURE_COUNT) {
        return false;
    }
    for (int k = 0; k < SCENE_FEATURE_COUNT; ++k) {
        const cJSON *n = cJSON_GetArrayItem(names, k);
        if (!cJSON_IsString(n) || strcmp(n->valuestring, scene_feature_name(k)) != 0) {
            return false;
        }
    }
    *cost_count = 0;
    for (const cJSON *n = cost_names ? cost_names->child : NULL;
         n && *cost_count < SCENE_FEATURE_COUNT; n = n->next) {
        int k = 0;
        while (k < SCENE_FEATURE_COUNT &&
               (!cJSON_IsString(n) || strcmp(n->valuestring, scene_feature_name(k)) != 0)) {
            ++k;
        }
        if (k == SCENE_FEATURE_COUNT) {
            return false;
        }
        cost_index[(*cost_count)++] = k;
    }
    return true;
}

// The fitted prediction of candidate `c`'s ms for a frame of `pixels` (uncalibrated).
static double predict_ms(const cJSON *model, const cJSON *c, const double f[SCENE_FEATURE_COUNT],
                         double pixels)
{
    int cost_index[SCENE_FEATURE_COUNT], cost_count = 0;
    double size = number(model, "size", 400.0);
    if (!cost_indices(model, cost_index, &cost_count)) {
        return (double)INFINITY;
    }
    return candidate_ms(model, c, f, cost_index, cost_count) * pixels / (size * size);
}

// The candidate of `key`, or of the lowest prediction in `group` (key NULL).
static const cJSON *find_candidate(const cJSON *model, const double f[SCENE_FEATURE_COUNT],
                                   const char *key, const char *group)
{
    const cJSON *found = NULL;
    double lowest = (double)INFINITY;
    const cJSON *cands = cJSON_GetObjectItemCaseSensitive(model, "candidates");
    for (const cJSON *c = cands ? cands->child : NULL; c; c = c->next) {
        const char *k = string(c, "key"), *g = string(c, "group");
        if (!k || !g) {
            continue;
        }
        if (key ? strcmp(k, key) == 0 : strcmp(g, group) == 0) {
            double ms = key ? 0.0 : predict_ms(model, c, f, 1.0);
            if (ms < lowest) {
                found = c;
                lowest = ms;
            }
        }
    }
    return found;
}

// Scores every candidate of the model for a scene of features `f` for a frame of `pixels`
// under `cal`; *best_hybrid, *best_guided (hybrid+pt) and *best_pt: the lowest predicted FLIP
// of each family that fits (pick NULL: none), *fastest: the candidate of the lowest predicted
// ms (each ms calibrated). False when the model is not one this build reads.
static bool score(const cJSON *model, const double f[SCENE_FEATURE_COUNT], const calibration *cal,
                  double pixels, choice *best_hybrid, choice *best_guided, choice *best_pt,
                  choice *fastest)
{
    int cost_index[SCENE_FEATURE_COUNT], cost_count = 0;
    if (!cost_indices(model, cost_index, &cost_count)) {
        return false;
    }
    // The k nearest fitted scenes in standardised features.
    const cJSON *scale = cJSON_GetObjectItemCaseSensitive(model, "scale");
    const cJSON *scenes = cJSON_GetObjectItemCaseSensitive(model, "scenes");
    int n_scenes = cJSON_GetArraySize(scenes), n = 0;
    neighbour *near = calloc((size_t)(n_scenes > 0 ? n_scenes : 1), sizeof *near);
    for (const cJSON *s = scenes ? scenes->child : NULL; near && s; s = s->next) {
        const cJSON *sf = cJSON_GetObjectItemCaseSensitive(s, "features");
        if (cJSON_GetArraySize(sf) != SCENE_FEATURE_COUNT) {
            continue;
        }
        double d = 0.0;
        for (int k = 0; k < SCENE_FEATURE_COUNT; ++k) {
            const cJSON *sk = cJSON_GetArrayItem(scale, k);
            double w = cJSON_IsNumber(sk) && sk->valuedouble > 0.0 ? sk->valuedouble : 1.0;
            double x = (cJSON_GetArrayItem(sf, k)->valuedouble - f[k]) / w;
            d += x * x;
        }
        near[n++] = (neighbour){ s, d, 0.0 };
    }
    if (!near || n == 0) {
        free(near);
        return false;
    }
    qsort(near, (size_t)n, sizeof *near, compare_neighbour);
    quality_params qp = read_quality(model);
    int k = qp.k < 1 || qp.k > n ? n : qp.k;
    double total = 0.0;
    for (int i = 0; i < k; ++i) {
        double d = sqrt(near[i].d2);
        near[i].w =
            qp.gauss ? exp(-0.5 * (d / qp.bandwidth) * (d / qp.bandwidth)) : 1.0 / (d + 0.1);
        total += near[i].w;
    }
    for (int i = 0; i < k; ++i) {
        near[i].w = total > 0.0 ? near[i].w / total : 1.0 / k;
    }
    double size = number(model, "size", 400.0);
    *best_hybrid = *best_guided = *best_pt = *fastest =
        (choice){ NULL, (double)INFINITY, (double)INFINITY, (double)INFINITY };
    const cJSON *cands = cJSON_GetObjectItemCaseSensitive(model, "candidates");
    for (const cJSON *c = cands ? cands->child : NULL; c; c = c->next) {
        const char *group = string(c, "group"), *key = string(c, "key");
        if (!group || !key) {
            continue;
        }
        int g = group_index(group);
        double ms =
            candidate_ms(model, c, f, cost_index, cost_count) * pixels / (size * size) *
                cal->scale[g] +
            cal->setup_ms[g] +
            (g == GROUP_HYBRID ? cal->setup_scale * technique_setup_ms(cal->setup_table, c) : 0.0);
        ms += cal->finish_ms;
        double rank, flip = predict_flip(near, k, c, key, &qp, &rank);
        if (ms < fastest->ms) {
            *fastest = (choice){ c, ms, flip, rank };
        }
        if (ms * cal->safety[g] > cal->available_ms) {
            continue;
        }
        const char *kind = string(c, "kind");
        choice *best = g == GROUP_PT                            ? best_pt
                       : kind && strcmp(kind, "hybrid+pt") == 0 ? best_guided
                                                                : best_hybrid;
        if (rank < best->rank) {
            *best = (choice){ c, ms, flip, rank };
        }
    }
    free(near);
    return fastest->pick != NULL;
}

static bool apply_technique(drift_hybrid_params *p, drift_effect effect, const char *name)
{
    int t = name ? drift_technique_parse(effect, name) : -1;
    if (t < 0) {
        return false;
    }
    drift_hybrid_params_set_technique(p, effect, t);
    return true;
}

// The pick into the options: a hybrid combination into o->hybrid (the effects it does not
// name keep their defaults: ISG reflections, post depth of field), the path tracer, or the
// hybrid frame guiding the path tracer (hybrid+pt: --denoise guided --spp n).
static bool apply_pick(render_options *o, const cJSON *pick)
{
    const char *kind = string(pick, "kind");
    if (kind && strcmp(kind, "hybrid+pt") == 0) {
        // The bench's guide (bench/bench_frontier_guided.c): the default hybrid frame, with
        // its indirect off ("direct") or 256 VPLs gathered at 1/2 ("cheap") as the pick says.
        drift_hybrid_params d = drift_hybrid_params_default(), *p = &o->hybrid;
        if (!apply_technique(p, DRIFT_EFFECT_SHADOWS, string(pick, "shadows")) ||
            !apply_technique(p, DRIFT_EFFECT_INDIRECT, string(pick, "indirect"))) {
            return false;
        }
        p->ism.vpls = (uint32_t)number(pick, "vpls", d.ism.vpls);
        p->ism.gather_scale = (int32_t)number(pick, "gather_scale", d.ism.gather_scale);
        p->ism.no_near_field = d.ism.no_near_field;
        p->light_samples = d.light_samples;
        p->environment_filter = d.environment_filter;
        p->environment_scale = d.environment_scale;
        p->aa = d.aa;
        o->denoise = 4;
        o->spp = (long)number(pick, "spp", 1);
        o->max_depth = 8;
        return o->spp >= 1;
    }
    if (kind && strcmp(kind, "pt") == 0) {
        const char *denoise = string(pick, "denoise");
        o->hybrid_mode = false;
        o->spp = (long)number(pick, "spp", 1);
        o->denoise = !denoise || strcmp(denoise, "none") == 0 ? 0
                     : strcmp(denoise, "atrous") == 0         ? 1
                                                              : 2;
        o->max_depth = 8;
        long scale = (long)number(pick, "scale", 1);
        if (scale > 1) { // at 1/scale of the size, upsampled bilinearly as it is written
            o->upsample_width = o->width;
            o->upsample_height = o->height;
            o->width = o->width / scale > 0 ? o->width / scale : 1;
            o->height = o->height / scale > 0 ? o->height / scale : 1;
        }
        return o->spp >= 1 && scale >= 1;
    }
    drift_hybrid_params *p = &o->hybrid;
    if (!kind || strcmp(kind, "hybrid") != 0 ||
        !apply_technique(p, DRIFT_EFFECT_SHADOWS, string(pick, "shadows")) ||
        !apply_technique(p, DRIFT_EFFECT_INDIRECT, string(pick, "indirect"))) {
        return false;
    }
    p->ism.vpls = (uint32_t)number(pick, "vpls", p->ism.vpls);
    p->ism.gather_scale = (int32_t)number(pick, "gather_scale", 1);
    p->ism.no_near_field = cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(pick, "no_near_field"));
    p->light_samples = (uint32_t)number(pick, "light_samples", 8); // the bench's rows' count
    p->environment_filter = (uint32_t)number(pick, "environment_filter", 0);
    p->environment_scale = (uint32_t)number(pick, "environment_scale", 1);
    p->aa = (uint32_t)number(pick, "aa", 1);
    o->spp = (long)number(pick, "spp", 1);
    o->max_depth = 8;
    return true;
}

drift_result render_upsample_bilinear(drift_context *ctx, const drift_image *low, int32_t w,
                                      int32_t h, drift_image *out)
{
    drift_result r = drift_image_create(ctx, w, h, 3, out);
    double fx = (double)w / (double)low->width, fy = (double)h / (double)low->height;
    for (int32_t y = 0; r == DRIFT_OK && y < h; ++y) {
        for (int32_t x = 0; x < w; ++x) {
            double u = fmin(fmax((x + 0.5) / fx - 0.5, 0.0), (double)low->width - 1.0);
            double v = fmin(fmax((y + 0.5) / fy - 0.5, 0.0), (double)low->height - 1.0);
            int32_t x0 = (int32_t)u, y0 = (int32_t)v;
            int32_t x1 = x0 + 1 < low->width ? x0 + 1 : x0;
            int32_t y1 = y0 + 1 < low->height ? y0 + 1 : y0;
            float tx = (float)(u - x0), ty = (float)(v - y0);
            for (int32_t c = 0; c < 3; ++c) {
                float a = drift_image_pixel(low, x0, y0)[c] * (1.0f - tx) +
                          drift_image_pixel(low, x1, y0)[c] * tx;
                float b = drift_image_pixel(low, x0, y1)[c] * (1.0f - tx) +
                          drift_image_pixel(low, x1, y1)[c] * tx;
                drift_image_pixel(out, x, y)[c] = a * (1.0f - ty) + b * ty;
            }
        }
    }
    return r;
}

// The 1-minute load average (Linux's /proc/loadavg; 0 where there is none).
static double load_average(void)
{
    double load = 0.0;
    FILE *f = fopen("/proc/loadavg", "r");
    if (f) {
        if (fscanf(f, "%lf", &load) != 1) {
            load = 0.0;
        }
        fclose(f);
    }
    return load;
}

// The cores a frame of `threads` threads gets on `cores` cores while `load` other threads
// are runnable (the 1-minute load average): the scheduler shares the cores evenly.
static double cores_for(int threads, double cores, double load)
{
    double t = threads > 0 ? threads : 1;
    return fmin(fmin(t, cores), cores * t / (fmax(load, 0.0) + t));
}

// --budget-probe on (the default): what this scene costs on this machine now. The path
// tracer at 1 spp on a small frame is timed in CPU ms; every candidate's fitted cost is scaled
// by that over the fitted cost of the probe (the model's "pt|1 spp" at the probe's size: the
// rows were measured under another load, on other scenes) and divided by the cores the frame
// will get now (cores_for, from the load average: a probe of a few ms runs within a time
// slice and cannot see the load). A hybrid candidate adds its set-up (a one-shot render pays
// it; the bench's rows are warm frames): the base hybrid frame's (hard shadows, no indirect),
// probed where the model's median of it is within 5 % of T, else that median, plus the
// model's set-up of each technique it names (scripts/chooser/measure_setup.py, wall ms at the
// load it records: rescaled to this load). The budget left is T less what was spent since the
// scene was loaded (the accel, the features, the probes); every candidate adds the writes.
static void calibrate(const cJSON *model, const double f[SCENE_FEATURE_COUNT],
                      const render_options *o, const cli_session *session, calibration *cal,
                      render_probe *probe)
{
    const cJSON *pt1 = find_candidate(model, f, "pt|1 spp", NULL);
    double frame_ms =
        pt1 ? predict_ms(model, pt1, f, (double)o->width * (double)o->height) : (double)INFINITY;
    // Each of the three path-tracer probes ~1.5 % of T by the fitted cost, at most 1/4 of the
    // frame's side, at least 16 pixels.
    double side =
        frame_ms > 0.0 && isfinite(frame_ms) ? sqrt(0.015 * o->budget_ms / frame_ms) : 0.25;
    side = fmin(side, 0.25);
    int32_t w = (int32_t)fmax(fmin(16.0, (double)o->width), (double)o->width * side);
    int32_t h = (int32_t)fmax(fmin(16.0, (double)o->height), (double)o->height * side);
    const cJSON *table = cJSON_GetObjectItemCaseSensitive(model, "setup_ms");
    double base = number(table, "base", 0.0);
    drift_hybrid_params hybrid = o->hybrid;
    bool probe_hybrid = table && base <= 0.05 * o->budget_ms &&
                        apply_technique(&hybrid, DRIFT_EFFECT_SHADOWS, "hard") &&
                        apply_technique(&hybrid, DRIFT_EFFECT_INDIRECT, "none");
    hybrid.environment_filter = 0;
    render_choose_probe(session, w, h, probe_hybrid ? &hybrid : NULL, probe);
    cal->load = load_average();
    cal->cores = sysconf(_SC_NPROCESSORS_ONLN) > 0 ? (double)sysconf(_SC_NPROCESSORS_ONLN) : 1.0;
    int threads = drift_context_thread_count(session->ctx);
    cal->frame_cores = cores_for(threads, cal->cores, cal->load);
    double predicted = pt1 ? predict_ms(model, pt1, f, probe->pixels) : 0.0;
    const cJSON *safety = cJSON_GetObjectItemCaseSensitive(model, "calibrated_safety");
    if (probe->pt_ms > 0.0 && predicted > 0.0 && isfinite(predicted)) {
        cal->scale[GROUP_PT] = cal->scale[GROUP_HYBRID] =
            probe->pt_ms / predicted / cal->frame_cores;
        cal->safety[GROUP_PT] = number(safety, "pt", 1.0);
        cal->safety[GROUP_HYBRID] = number(safety, "hybrid", 1.0);
    }
    cal->setup_ms[GROUP_HYBRID] =
        probe->hybrid_ms > 0.0 ? probe->hybrid_ms / cal->frame_cores : base;
    cal->setup_table = table;
    // The writes (and what else the measured frames paid that the rows did not: the model's
    // finish_ms, fitted by scripts/chooser/fit_calibration.py) at the frame's pixels, scaled
    // by the probes as the frames are: encoding is CPU work too, and unscaled it left nothing
    // of T = 100 ms on a machine 3x the fit's (114 ms of writes predicted at 320x180, 24 paid).
    double size = number(model, "size", 400.0);
    cal->finish_ms = number(model, "finish_ms", 0.0) * (double)o->width * (double)o->height /
                     (size * size) * cal->scale[GROUP_PT];
    cal->setup_scale =
        cores_for(threads, number(table, "cores", cal->cores), number(table, "load", cal->load)) /
        cal->frame_cores;
    cal->available_ms = o->budget_ms - 1e3 * (drift_time_now() - session->t_loaded);
}

int render_choose(render_options *o, const cli_session *session)
{
    char fallback[4096];
    snprintf(fallback, sizeof fallback, "%s/scenes/corpus/chooser.json", DRIFT_SOURCE_DIR);
    const char *path = o->chooser_path ? o->chooser_path : fallback;
    char *text = read_text(path);
    cJSON *model = text ? cJSON_Parse(text) : NULL;
    free(text);
    if (!model) {
        fprintf(stderr, "drift render: --budget-ms: cannot read the chooser's model %s\n", path);
        return 1;
    }
    double f[SCENE_FEATURE_COUNT];
    scene_features(session->ctx, session->scene, session->accel, f);
    if (o->width <= 0) {
        o->width = session->scene->camera.width;
    }
    if (o->height <= 0) {
        o->height = session->scene->camera.height;
    }
    // --budget-probe off: the fitted costs times the model's safety factors, within T.
    const cJSON *safety = cJSON_GetObjectItemCaseSensitive(model, "safety");
    calibration cal = { .scale = { 1.0, 1.0 },
                        .setup_scale = 1.0,
                        .safety = { number(safety, "pt", 1.0), number(safety, "hybrid", 1.0) },
                        .available_ms = o->budget_ms };
    render_probe probe = { .pt_ms = -1.0, .write_per_pixel_ms = -1.0 };
    if (!o->no_budget_probe) {
        calibrate(model, f, o, session, &cal, &probe);
    }
    choice hybrid, guided, pt, fastest;
    bool ok = score(model, f, &cal, (double)o->width * (double)o->height, &hybrid, &guided, &pt,
                    &fastest);
    // A hybrid frame only where it is predicted clearly closer than the best path tracer that
    // fits (pt_margin): the chooser must not trade the path tracer's image for a biased one. A
    // hybrid+pt frame is the path tracer's samples plus a guide; its risk is its cost, not a
    // bias, and it has its own margin (guided_margin, else pt_margin). Of the families that
    // clear their margins, the closest.
    double margin = number(model, "pt_margin", 1.0);
    double guided_margin = number(model, "guided_margin", margin);
    bool hybrid_clear = hybrid.pick && (!pt.pick || hybrid.rank < margin * pt.rank);
    bool guided_clear = guided.pick && (!pt.pick || guided.rank < guided_margin * pt.rank);
    const choice *c = !ok                                                             ? NULL
                      : hybrid_clear && (!guided_clear || hybrid.rank <= guided.rank) ? &hybrid
                      : guided_clear                                                  ? &guided
                      : pt.pick                                                       ? &pt
                                                                                      : &fastest;
    // With the probes on, a path-tracer pick fills T (below): its samples follow the time, so
    // the family (resolution, denoiser) is chosen as if its rows cost their fitted ms alone,
    // not times the safety factor that keeps a fixed spp within T; it starts at 1 spp.
    bool fills = ok && !o->no_budget_probe && (c == &pt || c == &fastest);
    // The writes as the probes time them at this frame's size, where the model's finish_ms
    // (fitted at 128² under load, scaled by pixels) would take a tenth of T or more: at 400² it
    // took 317 ms of T where 60 were paid. (Not below: the probe's few ms would cost a small
    // T more than the estimate's error.)
    if (fills && cal.finish_ms > 0.1 * cal.available_ms) {
        render_choose_probe_writes(session, &probe);
        cal.available_ms = o->budget_ms - 1e3 * (drift_time_now() - session->t_loaded);
    }
    calibration bare = cal;
    choice h2, g2, pt_bare, fastest_bare;
    double writes_ms =
        probe.write_per_pixel_ms >= 0.0
            ? probe.write_fixed_ms + probe.write_per_pixel_ms * (double)o->width * (double)o->height
            : cal.finish_ms;
    // Filling needs room: at least half of T left for the frame once the probes and the writes
    // are paid. Below that (400² at T = 100 ms: the writes alone ~65 ms) the pick stays as it
    // is, a few cheap samples within T, as filled it overran T by 40%.
    fills = fills && cal.available_ms - writes_ms > 0.5 * o->budget_ms;
    if (fills) {
        bare.safety[GROUP_PT] = 1.0;
        bare.finish_ms = writes_ms;
        if (score(model, f, &bare, (double)o->width * (double)o->height, &h2, &g2, &pt_bare,
                  &fastest_bare) &&
            pt_bare.pick) {
            pt = pt_bare;
            c = &pt;
        }
    }
    const char *row = c ? string(c->pick, "row") : NULL;
    if (!c || !apply_pick(o, c->pick)) {
        fprintf(stderr,
                "drift render: --budget-ms: %s has no usable pick (refit it: "
                "scripts/chooser/fit_table.py)\n",
                path);
        cJSON_Delete(model);
        return 1;
    }
    // The render adds samples while they and the denoiser's filter end by the deadline, T less
    // the writes (tools/cmd_render.c). A fixed spp carried the safety factors and left most of
    // T unused on a quiet machine (a 320x180 scene at T = 250 ms: 1 spp rendered, 8 fitting).
    if (fills && !o->hybrid_mode) { // 5% of T kept: the last pass's time varies
        // From the end of the scene's load, as T counts: the probes since are inside it.
        o->budget_deadline = session->t_loaded + 1e-3 * (0.95 * o->budget_ms - writes_ms);
        // Filling T, a plain path-tracer pick is denoised: the samples it gets are the time's
        // either way, and the filter costs about one sample (judge scenes at 128²: the three
        // cells where the bare costs picked `pt` over `pt+denoise` came out 0.01-0.04 worse).
        if (o->denoise == 0) {
            o->denoise = 2;
        }
        // The filter's time at this size, from a small frame's: timing it on the render's own
        // image cost a second filter (at 400², the fill overran 100 ms budgets by 44%).
        double per_pixel = render_choose_probe_denoise(session, o);
        o->budget_denoise_ms =
            per_pixel > 0.0 ? per_pixel * (double)o->width * (double)o->height : 0.0;
    }
    if (!o->quiet) {
        char probed[256] = "";
        if (!o->no_budget_probe) {
            snprintf(probed, sizeof probed,
                     "; probes %.1f ms: fitted costs x%.2f (load %.1f on %.0f cores: %.2f "
                     "for the frame), hybrid set-up %.1f ms + its techniques'; %.0f ms of T "
                     "left after the accel and probes",
                     probe.spent_ms, cal.scale[GROUP_PT], cal.load, cal.cores, cal.frame_cores,
                     cal.setup_ms[GROUP_HYBRID], cal.available_ms);
        }
        fprintf(stderr,
                "drift render: --budget-ms %g: %s%s (predicted %.0f ms, FLIP %.2fx the best "
                "row's on the nearest fitted scenes)%s%s%s\n",
                o->budget_ms,
                c == &fastest    ? "nothing is predicted to fit, the fastest: "
                : o->hybrid_mode ? "hybrid "
                                 : "the path tracer is expected to win: ",
                row ? row : "?", c->ms, c->flip,
                c == &pt && (hybrid.pick || guided.pick)
                    ? "; the best hybrid frame was predicted no closer"
                    : "",
                probed, fills ? "; samples from 1 spp while T lasts" : "");
    }
    cJSON_Delete(model);
    return 0;
}
