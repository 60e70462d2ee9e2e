// drift render --mode hybrid --budget-ms T (issue 40): the techniques chosen for the scene and
// the budget. The model (scenes/corpus/chooser.json, refitted by scripts/chooser/fit_table.py
// from drift bench frontier --corpus --json) holds, for each scene it was fitted on, its
// features (tools/scene_features.h) and, for each budget, the row that gave the lowest FLIP
// within it: a hybrid combination, or the path tracer (plain or through a-trous). The chooser
// takes the nearest fitted scene in standardised feature space and its row at the largest
// budget <= T (the smallest budget when T is below them all), and says what it chose. T is
// scaled to the model's image size by the ratio of pixels.
#include "cli.h"
#include "render.h"
#include "scene_features.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int render_print_features(const cli_session *session)
{
    double f[SCENE_FEATURE_COUNT];
    scene_features(session->scene, f);
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

// The fitted scene nearest to `f` (standardised by the model's `scale`), or NULL.
static const cJSON *nearest_scene(const cJSON *model, const double f[SCENE_FEATURE_COUNT])
{
    const cJSON *scale = cJSON_GetObjectItemCaseSensitive(model, "scale");
    const cJSON *best = NULL;
    double best_d = (double)INFINITY;
    const cJSON *scenes = cJSON_GetObjectItemCaseSensitive(model, "scenes");
    for (const cJSON *s = scenes ? scenes->child : NULL; s; s = s->next) {
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
        if (d < best_d) {
            best_d = d;
            best = s;
        }
    }
    return best;
}

// The scene's pick at the largest budget <= T (else its smallest budget's).
static const cJSON *pick_for(const cJSON *scene, double budget_ms, double *out_budget)
{
    const cJSON *picks = cJSON_GetObjectItemCaseSensitive(scene, "picks");
    const cJSON *best = NULL, *smallest = NULL;
    double best_b = -1.0, small_b = (double)INFINITY;
    for (const cJSON *p = picks ? picks->child : NULL; p; p = p->next) {
        double b = atof(p->string);
        if (b <= budget_ms && b > best_b) {
            best = p;
            best_b = b;
        }
        if (b < small_b) {
            smallest = p;
            small_b = b;
        }
    }
    *out_budget = best ? best_b : small_b;
    return best ? best : smallest;
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
// name keep their defaults: ISG reflections, post depth of field), or the path tracer.
static bool apply_pick(render_options *o, const cJSON *pick)
{
    const char *kind = string(pick, "kind");
    if (kind && strcmp(kind, "pt") == 0) {
        o->hybrid_mode = false;
        o->spp = (long)number(pick, "spp", 1);
        o->denoise = cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(pick, "denoise"));
        o->max_depth = 8;
        return o->spp >= 1;
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
    p->light_samples = (uint32_t)number(pick, "light_samples", 8);
    p->environment_filter = (uint32_t)number(pick, "environment_filter", 0);
    p->environment_scale = (uint32_t)number(pick, "environment_scale", 1);
    p->aa = (uint32_t)number(pick, "aa", 1);
    o->spp = (long)number(pick, "spp", 1);
    o->max_depth = 8;
    return true;
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
    double f[SCENE_FEATURE_COUNT], budget = 0.0;
    scene_features(session->scene, f);
    // The model's milliseconds are at its bench's size x size: a frame's cost grows with its
    // pixels, so T is taken at that size.
    double w = o->width > 0 ? (double)o->width : (double)session->scene->camera.width;
    double h = o->height > 0 ? (double)o->height : (double)session->scene->camera.height;
    double size = number(model, "size", 400.0);
    double at_model = o->budget_ms * size * size / fmax(w * h, 1.0);
    const cJSON *scene = nearest_scene(model, f);
    const cJSON *pick = scene ? pick_for(scene, at_model, &budget) : NULL;
    const char *row = pick ? string(pick, "row") : NULL;
    if (!pick || !apply_pick(o, pick)) {
        fprintf(stderr,
                "drift render: --budget-ms: %s has no usable pick (refit it: "
                "scripts/chooser/fit_table.py)\n",
                path);
        cJSON_Delete(model);
        return 1;
    }
    if (!o->quiet) {
        fprintf(stderr,
                "drift render: --budget-ms %g (%.0f ms at the model's %.0f^2): %s%s (the nearest "
                "fitted scene, %s, at %g ms: %.1f ms, FLIP %.3f there)\n",
                o->budget_ms, at_model, size,
                o->hybrid_mode ? "hybrid " : "the path tracer is expected to win: ",
                row ? row : "?", string(scene, "name") ? string(scene, "name") : "?", budget,
                number(pick, "ms", (double)NAN), number(pick, "flip", (double)NAN));
    }
    cJSON_Delete(model);
    return 0;
}
