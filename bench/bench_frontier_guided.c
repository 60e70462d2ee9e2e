// drift bench frontier's hybrid+pt rows: a hybrid frame (the guide) and the path tracer at
// n spp combined by drift_denoise_guided (include/drift/denoise.h), each guide and mode a row.
// A row's ms are all paid: the guide's warm frame median, the path tracer's render and the
// filter.
#include "bench_frontier.h"
#include "drift/hybrid.h"
#include "drift/knobs.h"

#include <stdio.h>

static const char *const guide_names[FRONTIER_GUIDES] = { "", "cheap ", "direct " };

static drift_result guide_frame(frontier_state *b, int g)
{
    const frontier_options *o = b->o;
    drift_hybrid_params p = drift_hybrid_params_default();
    p.width = p.height = (int32_t)o->size;
    p.max_depth = FRONTIER_DEPTH;
    p.glare = DRIFT_GLARE_NONE; // the reference has no glare
    if (b->scene->camera.aperture_radius <= 0.0f) {
        drift_hybrid_params_set_technique(&p, DRIFT_EFFECT_DOF,
                                          drift_technique_parse(DRIFT_EFFECT_DOF, "none"));
    }
    if (g == 1) {
        int vpls = drift_knob_find("ism-vpls"), gather = drift_knob_find("ism-gather-scale");
        if (vpls < 0 || gather < 0 || !drift_knob_set(&p, vpls, 256.0) ||
            !drift_knob_set(&p, gather, 2.0)) {
            fprintf(stderr, "drift bench frontier: the cheap guide's knobs are refused\n");
            return DRIFT_ERR_INVALID_ARGUMENT;
        }
    }
    if (g == 2) {
        drift_hybrid_params_set_technique(&p, DRIFT_EFFECT_INDIRECT,
                                          drift_technique_parse(DRIFT_EFFECT_INDIRECT, "none"));
    }
    drift_hybrid *frame = NULL;
    drift_result r = drift_hybrid_create(b->ctx, b->scene, b->accel, &p, &frame);
    r = r ? r : drift_hybrid_render(frame, &b->scene->camera, NULL); // warm-up, as hybrid_row
    double ms[100];
    long n = 0;
    while (r == DRIFT_OK && n < o->runs) {
        r = drift_hybrid_render(frame, &b->scene->camera, NULL);
        ms[n++] = drift_hybrid_get_stats(frame).frame_ms;
    }
    const drift_image *img = r == DRIFT_OK ? drift_hybrid_image(frame) : NULL;
    r = r ? r : drift_image_create(b->ctx, img->width, img->height, 3, &b->guide[g]);
    for (int32_t y = 0; r == DRIFT_OK && y < img->height; ++y) {
        for (int32_t x = 0; x < img->width; ++x) {
            drift_image_set3(&b->guide[g], x, y, drift_image_get3(img, x, y));
        }
    }
    const drift_image *indirect =
        r == DRIFT_OK ? drift_hybrid_plane_named(frame, "indirect") : NULL;
    r = r || !indirect
            ? r
            : drift_image_create(b->ctx, img->width, img->height, 3, &b->guide_indirect[g]);
    for (int32_t y = 0; r == DRIFT_OK && indirect && y < img->height; ++y) {
        for (int32_t x = 0; x < img->width; ++x) {
            drift_image_set3(&b->guide_indirect[g], x, y, drift_image_get3(indirect, x, y));
        }
    }
    if (r == DRIFT_OK) {
        b->guide_ms[g] = frontier_median(ms, n);
        if (!o->json) {
            fprintf(stderr, "  guide: %shybrid frame %.1f ms\n", guide_names[g], b->guide_ms[g]);
        }
    }
    drift_hybrid_destroy(frame);
    return r;
}

drift_result frontier_guide_frame(frontier_state *b)
{
    drift_result r = DRIFT_OK;
    for (int g = 0; g < FRONTIER_GUIDES && r == DRIFT_OK; ++g) {
        r = guide_frame(b, g);
    }
    return r;
}

drift_result frontier_guided_rows(frontier_state *b, long spp, double render_ms,
                                  const drift_denoise_inputs *in)
{
    // residual: the residual filtered variance-guided; residual-rr: by regression + residual;
    // split: the direct part and the rest apart (REGRESSION measured worse than residual at
    // every spp on three fit scenes: not a row, docs/lab/2026-12-07-issue-40-s7-guided.md)
    static const char *const variant_names[3] = { "residual", "residual-rr", "split" };
    drift_result r = DRIFT_OK;
    for (int g = 0; g < FRONTIER_GUIDES && r == DRIFT_OK; ++g) {
        for (int v = 0; v < 3 && r == DRIFT_OK; ++v) {
            drift_denoise_feature_params p = { .method = v == 1 ? DRIFT_DENOISE_REGRESSION_RESIDUAL
                                                                : DRIFT_DENOISE_VARIANCE_GUIDED };
            drift_denoise_inputs part = *in;
            if (v < 2) {
                part.direct = part.direct_variance = part.indirect_variance = NULL;
            }
            const drift_image *gi = b->guide_indirect[g].pixels ? &b->guide_indirect[g] : NULL;
            drift_image out = { 0 };
            double t0 = drift_time_now();
            r = drift_denoise_guided(b->ctx, &part, &b->guide[g], gi, DRIFT_GUIDE_RESIDUAL, &p,
                                     &out, NULL);
            double filter_ms = (drift_time_now() - t0) * 1e3;
            char name[64];
            snprintf(name, sizeof name, "%s%s %ld spp", guide_names[g], variant_names[v], spp);
            r = r ? r
                  : frontier_add_row(b, FAMILY_HYBRID_PT, name,
                                     b->guide_ms[g] + render_ms + filter_ms, &out);
            drift_image_destroy(b->ctx, &out);
        }
    }
    return r;
}
