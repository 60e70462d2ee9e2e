// AAF's per-frame buffers, in the family's state (drift_aaf_of): made the first time a frame
// uses AAF (most frames never do), kept until the frame is destroyed; an indirect lobe's only
// when that lobe first runs.
#include "aaf/aaf.h"

#include <stdio.h>
#include <string.h>

drift_result drift_aaf_state_create(drift_frame_state *f, void **out_state)
{
    *out_state = drift_alloc(f->ctx, sizeof(drift_aaf_state));
    return *out_state ? DRIFT_OK : DRIFT_ERR_OUT_OF_MEMORY;
}

// Frees every buffer; the state is then as create made it.
static void free_buffers(drift_context *ctx, drift_aaf_state *s)
{
    for (uint32_t l = 0; s->lights && l < s->light_count; ++l) {
        drift_image_destroy(ctx, &s->lights[l].beta);
        drift_image_destroy(ctx, &s->lights[l].spp);
        drift_image_destroy(ctx, &s->lights[l].unfiltered);
    }
    drift_image *images[] = { &s->footprint,
                              &s->scratch1,
                              &s->scratch3,
                              &s->indirect.beta,
                              &s->indirect.spp,
                              &s->indirect.unfiltered,
                              &s->indirect.radiance,
                              &s->indirect.filtered,
                              &s->specular.beta,
                              &s->specular.spp,
                              &s->specular.unfiltered,
                              &s->specular.radiance,
                              &s->specular.filtered };
    for (size_t i = 0; i < sizeof images / sizeof *images; ++i) {
        drift_image_destroy(ctx, images[i]);
    }
    drift_free(ctx, s->lights);
    drift_free(ctx, s->want);
    drift_free(ctx, s->counts);
    drift_free(ctx, s->aux);
    drift_free(ctx, s->filter_workspace);
    memset(s, 0, sizeof *s);
}

void drift_aaf_state_destroy(drift_frame_state *f, void *state)
{
    drift_aaf_state *s = state;
    if (s) {
        free_buffers(f->ctx, s);
        drift_free(f->ctx, s);
    }
}

drift_result drift_aaf_state_ensure(drift_frame_state *f)
{
    drift_aaf_state *s = drift_aaf_of(f);
    if (s->lights) {
        return DRIFT_OK;
    }
    drift_context *ctx = f->ctx;
    int32_t w = f->params.width, h = f->params.height;
    size_t pixels = (size_t)w * (size_t)h;
    s->width = w;
    s->height = h;
    s->light_count = f->light_count;
    s->lights = drift_alloc(ctx, sizeof(drift_aaf_light) * (f->light_count + 1u));
    s->want = drift_alloc(ctx, sizeof(float) * pixels);
    s->counts = drift_alloc(ctx, sizeof(uint32_t) * pixels);
    s->aux = drift_alloc(ctx, sizeof(float) * DRIFT_AAF_AUX * pixels);
    s->filter_workspace = drift_alloc(ctx, drift_aaf_filter_workspace_bytes(w, h));
    drift_result r = s->lights && s->want && s->counts && s->aux && s->filter_workspace
                         ? DRIFT_OK
                         : DRIFT_ERR_OUT_OF_MEMORY;
    drift_image *ones[] = { &s->footprint, &s->scratch1 };
    drift_image *threes[] = { &s->scratch3 };
    for (size_t i = 0; r == DRIFT_OK && i < sizeof ones / sizeof *ones; ++i) {
        r = drift_image_create(ctx, w, h, 1, ones[i]);
    }
    for (size_t i = 0; r == DRIFT_OK && i < sizeof threes / sizeof *threes; ++i) {
        r = drift_image_create(ctx, w, h, 3, threes[i]);
    }
    for (uint32_t l = 0; r == DRIFT_OK && l < f->light_count; ++l) {
        r = drift_image_create(ctx, w, h, 1, &s->lights[l].beta);
        if (r == DRIFT_OK) {
            r = drift_image_create(ctx, w, h, 1, &s->lights[l].spp);
        }
        if (r == DRIFT_OK) {
            r = drift_image_create(ctx, w, h, 1, &s->lights[l].unfiltered);
        }
    }
    if (r != DRIFT_OK) {
        free_buffers(ctx, s); // the next pass tries again
    }
    return r;
}

drift_result drift_aaf_lobe_buffers_ensure(drift_context *ctx, drift_aaf_lobe_buffers *b,
                                           int32_t width, int32_t height)
{
    if (b->beta.pixels) {
        return DRIFT_OK;
    }
    drift_image *ones[] = { &b->beta, &b->spp };
    drift_image *threes[] = { &b->unfiltered, &b->radiance, &b->filtered };
    drift_result r = DRIFT_OK;
    for (size_t i = 0; r == DRIFT_OK && i < sizeof threes / sizeof *threes; ++i) {
        r = drift_image_create(ctx, width, height, 3, threes[i]);
    }
    // beta last: its pixels say the set is complete.
    for (size_t i = sizeof ones / sizeof *ones; r == DRIFT_OK && i-- > 0;) {
        r = drift_image_create(ctx, width, height, 1, ones[i]);
    }
    if (r != DRIFT_OK) {
        for (size_t i = 0; i < sizeof threes / sizeof *threes; ++i) {
            drift_image_destroy(ctx, threes[i]);
        }
        for (size_t i = 0; i < sizeof ones / sizeof *ones; ++i) {
            drift_image_destroy(ctx, ones[i]);
        }
    }
    return r;
}

// --- SETTINGS ---

void drift_aaf_settings_resolve(drift_aaf_settings *settings, uint32_t spp)
{
    if (settings->max_spp == 0) {
        settings->max_spp = spp > 512 ? 4096 : 8 * spp;
    }
}

const char *drift_aaf_settings_problem(const drift_aaf_settings *settings, uint32_t spp)
{
    if (settings->max_spp < spp || settings->max_spp > 65536) {
        return "aaf max spp below spp or over 65536";
    }
    return (unsigned)settings->denoise > DRIFT_AAF_DENOISE_BOTH ? "aaf denoise not off, on or both"
                                                                : NULL;
}

// --- PLANES ---

static void lobe_planes(const drift_aaf_lobe_buffers *b, const char *lobe, drift_pass_plane_fn add,
                        void *sink)
{
    if (!b->beta.pixels) {
        return; // the lobe has not run
    }
    const char *names[3] = { "beta", "spp", "unfiltered" };
    const drift_image *images[3] = { &b->beta, &b->spp, &b->unfiltered };
    for (int k = 0; k < 3; ++k) {
        char name[DRIFT_FRAME_PLANE_NAME];
        snprintf(name, sizeof name, "%s.aaf.%s", lobe, names[k]);
        add(sink, name, images[k]);
    }
}

void drift_aaf_shadow_planes(const drift_frame_state *f, drift_pass_plane_fn add, void *sink)
{
    const drift_aaf_state *s = drift_aaf_buffers(f);
    for (uint32_t l = 0; s && l < f->light_count; ++l) {
        const char *names[3] = { "beta", "spp", "unfiltered" };
        const drift_image *images[3] = { &s->lights[l].beta, &s->lights[l].spp,
                                         &s->lights[l].unfiltered };
        for (int k = 0; k < 3; ++k) {
            char name[DRIFT_FRAME_PLANE_NAME];
            snprintf(name, sizeof name, "light%u.aaf.%s", l, names[k]);
            add(sink, name, images[k]);
        }
    }
}

void drift_aaf_indirect_planes(const drift_frame_state *f, drift_pass_plane_fn add, void *sink)
{
    const drift_aaf_state *s = drift_aaf_buffers(f);
    if (s) {
        lobe_planes(&s->indirect, "indirect", add, sink);
    }
}

void drift_aaf_specular_planes(const drift_frame_state *f, drift_pass_plane_fn add, void *sink)
{
    const drift_aaf_state *s = drift_aaf_buffers(f);
    if (s) {
        lobe_planes(&s->specular, "reflections", add, sink);
    }
}
