// The paper's pre-process for E_combined2 = sum_i lambda_i E_i: render several views with
// rasterization and ray tracing, draw random lambda tuples, keep the one whose combined
// metric is closest to the real error over all views. The averaged sum is the first
// candidate, so the fit is never worse than it on its own training views.
#include "drift/file.h"
#include "sir/sir.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define DISPLAY_GAMMA (1.0f / 2.2f)

static float display(float v)
{
    return powf(drift_clampf(v, 0.0f, 1.0f), DISPLAY_GAMMA);
}

void drift_refine_real_error(const drift_image *raster, const drift_image *traced, float scale,
                             drift_image *out)
{
    for (int32_t y = 0; y < out->height; ++y) {
        for (int32_t x = 0; x < out->width; ++x) {
            const float *a = drift_image_pixel(raster, x, y), *b = drift_image_pixel(traced, x, y);
            float d = 0.0f;
            for (int c = 0; c < 3; ++c) {
                d = fmaxf(d, fabsf(display(a[c]) - display(b[c])));
            }
            drift_image_pixel(out, x, y)[0] = drift_clampf(d / scale, 0.0f, 1.0f);
        }
    }
}

double drift_refine_lambda_cost(const drift_refine_view *views, uint32_t view_count,
                                const float lambda[DRIFT_METRIC_COUNT])
{
    double sum = 0.0;
    size_t pixels = 0;
    for (uint32_t v = 0; v < view_count; ++v) {
        const drift_image *real = views[v].real_error;
        for (int32_t y = 0; y < real->height; ++y) {
            for (int32_t x = 0; x < real->width; ++x) {
                float e = 0.0f;
                for (int m = 0; m < DRIFT_METRIC_COUNT; ++m) {
                    e += lambda[m] * drift_image_pixel(views[v].metrics[m], x, y)[0];
                }
                sum += fabs((double)fminf(e, 1.0f) - (double)drift_image_pixel(real, x, y)[0]);
                ++pixels;
            }
        }
    }
    return pixels ? sum / (double)pixels : 0.0;
}

void drift_refine_fit_lambda(const drift_refine_view *views, uint32_t view_count, uint32_t trials,
                             uint32_t seed, float out_lambda[DRIFT_METRIC_COUNT], double *out_cost)
{
    float best[DRIFT_METRIC_COUNT];
    for (int m = 0; m < DRIFT_METRIC_COUNT; ++m) {
        best[m] = 1.0f / DRIFT_METRIC_COUNT;
    }
    double best_cost = drift_refine_lambda_cost(views, view_count, best);
    drift_sampler sampler = drift_sampler_make(seed, 0x1a3bd, 0);
    for (uint32_t t = 0; t < trials; ++t) {
        float candidate[DRIFT_METRIC_COUNT];
        for (int m = 0; m < DRIFT_METRIC_COUNT; ++m) {
            candidate[m] = drift_sampler_next1(&sampler);
        }
        double cost = drift_refine_lambda_cost(views, view_count, candidate);
        if (cost < best_cost) {
            best_cost = cost;
            memcpy(best, candidate, sizeof best);
        }
    }
    memcpy(out_lambda, best, sizeof best);
    if (out_cost) {
        *out_cost = best_cost;
    }
}

drift_result drift_refine_lambda_save(drift_context *ctx, const char *path,
                                      const float lambda[DRIFT_METRIC_COUNT])
{
    cJSON *root = cJSON_CreateObject();
    cJSON *weights = cJSON_AddObjectToObject(root, "lambda");
    for (int m = 0; weights && m < DRIFT_METRIC_COUNT; ++m) {
        cJSON_AddNumberToObject(weights, drift_refine_metric_name((drift_refine_metric)m),
                                (double)lambda[m]);
    }
    char *text = weights ? cJSON_Print(root) : NULL;
    cJSON_Delete(root);
    FILE *f = text ? fopen(path, "wb") : NULL;
    bool ok = f && fputs(text, f) >= 0 && fputc('\n', f) != EOF;
    if (f && fclose(f) != 0) {
        ok = false;
    }
    free(text);
    if (!ok) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_IO, path, 0, "could not write the lambda file");
        return DRIFT_ERR_IO;
    }
    return DRIFT_OK;
}

drift_result drift_refine_lambda_load(drift_context *ctx, const char *path,
                                      float out_lambda[DRIFT_METRIC_COUNT])
{
    char why[128];
    FILE *f = drift_input_fopen(path, why, sizeof why);
    if (!f) {
        drift_log(ctx, DRIFT_LOG_ERROR, DRIFT_ERR_IO, path, 0, "could not open the lambda file: %s",
                  why);
        return DRIFT_ERR_IO;
    }
    char text[4096];
    size_t length = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    text[length] = '\0';
    cJSON *root = cJSON_Parse(text);
    const cJSON *weights = cJSON_GetObjectItemCaseSensitive(root, "lambda");
    drift_result r = cJSON_IsObject(weights) ? DRIFT_OK : DRIFT_ERR_PARSE;
    for (int m = 0; r == DRIFT_OK && m < DRIFT_METRIC_COUNT; ++m) {
        const cJSON *v = cJSON_GetObjectItemCaseSensitive(
            weights, drift_refine_metric_name((drift_refine_metric)m));
        if (!v && m == DRIFT_METRIC_LEAK) {
            out_lambda[m] = 1.0f / DRIFT_METRIC_COUNT; // files fitted before the leak metric
        } else if (!cJSON_IsNumber(v) || !(v->valuedouble >= 0.0) || !isfinite(v->valuedouble)) {
            r = DRIFT_ERR_PARSE;
        } else {
            out_lambda[m] = (float)v->valuedouble;
        }
    }
    cJSON_Delete(root);
    if (r != DRIFT_OK) {
        drift_log(ctx, DRIFT_LOG_ERROR, r, path, 0,
                  "lambda file: expected {\"lambda\": {\"reflection1\": number >= 0, ... "
                  "\"shadow\": ..., \"leak\": ...}}");
    }
    return r;
}
