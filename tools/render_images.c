// drift render's images: the PNG's tone mapping, glare on the reference image, and the
// reference render's EXR (beauty, --aov layers, spp) and PNG.
#include "cli.h"
#include "drift/accel.h"
#include "drift/denoise.h"
#include "drift/glare.h"
#include "drift/image_io.h"
#include "drift/knobs.h"
#include "drift/pt.h"
#include "drift/reflect_edit.h"
#include "drift/scene_io.h"
#include "render.h"

#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

drift_tonemap_params render_png_tonemap(const render_options *o, const drift_image *image)
{
    float stops = (float)o->exposure;
    if (o->exposure_mode == RENDER_EXPOSURE_AUTO) {
        stops = drift_image_auto_exposure(image);
    } else if (o->exposure_mode == RENDER_EXPOSURE_EV100) {
        stops = drift_exposure_from_ev100((float)o->ev100);
    }
    if (o->exposure_mode != RENDER_EXPOSURE_STOPS && !o->quiet) {
        fprintf(stderr, "drift render: PNG exposure %+.2f stops (%s)\n", (double)stops,
                o->exposure_mode == RENDER_EXPOSURE_AUTO ? "auto" : "EV100");
    }
    return (drift_tonemap_params){ .exposure_stops = stops, .op = o->tonemap };
}

// FILE.exr -> FILE.png
void render_png_path(const char *exr_path, char *out, size_t size)
{
    snprintf(out, size, "%.*s.png", (int)(strlen(exr_path) - 4), exr_path);
}

// The path tracer's image through the eye into *out, a new image (--glare static|dynamic in
// reference mode: one frame, the eye at t = 0). The pt's own image is left as it is.
static drift_result apply_glare(drift_context *ctx, const render_options *o, float fov_y,
                                const drift_image *image, drift_image *out)
{
    // The PSF at the camera's angular pitch, as the hybrid frame's glare pass does.
    double aspect = (double)image->width / (double)image->height;
    double fov_x = 2.0 * atan(aspect * tan(0.5 * (double)fov_y));
    drift_glare *glare = NULL;
    drift_glare_params params = { .mode = o->hybrid.glare == DRIFT_GLARE_DYNAMIC
                                              ? DRIFT_GLARE_MODE_DYNAMIC
                                              : DRIFT_GLARE_MODE_STATIC,
                                  .seed = (uint32_t)o->seed,
                                  .image_fov = fov_x };
    drift_result r = drift_glare_create(ctx, &params, &glare);
    if (r == DRIFT_OK) {
        r = drift_glare_apply(glare, image, 0.0, out);
    }
    drift_glare_destroy(glare);
    return r;
}

// The lowest and highest sample count of the pt's tiles (they differ after an interruption).
void render_spp_range(const drift_pt *pt, uint32_t *lowest, uint32_t *highest)
{
    *lowest = UINT32_MAX;
    *highest = 0;
    for (uint32_t t = 0; t < drift_pt_tile_count(pt); ++t) {
        uint32_t n = drift_pt_tile_sample_count(pt, t);
        *lowest = n < *lowest ? n : *lowest;
        *highest = n > *highest ? n : *highest;
    }
}

// --denoise's filter of the pt's beauty into *out (created here): the feature-guided
// denoiser (on, regression) over the pt's feature planes, or a-trous over its G-buffer planes.
static drift_result denoise_beauty(drift_context *ctx, drift_pt *pt, const render_options *o,
                                   const drift_image *beauty, drift_image *out)
{
    drift_image a, n, z, variance, direct, direct_var, indirect_var;
    drift_result r;
    if (o->denoise >= 2) {
        if ((r = drift_pt_resolve(pt, DRIFT_PT_AOV_VARIANCE, &variance)) != DRIFT_OK ||
            (r = drift_pt_resolve(pt, DRIFT_PT_AOV_FEATURE_ALBEDO, &a)) != DRIFT_OK ||
            (r = drift_pt_resolve(pt, DRIFT_PT_AOV_FEATURE_NORMAL, &n)) != DRIFT_OK ||
            (r = drift_pt_resolve(pt, DRIFT_PT_AOV_FEATURE_DEPTH, &z)) != DRIFT_OK ||
            (r = drift_pt_resolve(pt, DRIFT_PT_AOV_DIRECT, &direct)) != DRIFT_OK ||
            (r = drift_pt_resolve(pt, DRIFT_PT_AOV_DIRECT_VARIANCE, &direct_var)) != DRIFT_OK ||
            (r = drift_pt_resolve(pt, DRIFT_PT_AOV_INDIRECT_VARIANCE, &indirect_var)) != DRIFT_OK) {
            return r;
        }
        uint32_t lowest, highest;
        render_spp_range(pt, &lowest, &highest);
        drift_denoise_inputs in = { beauty, &a,      &n,          &z,           &variance,
                                    lowest, &direct, &direct_var, &indirect_var };
        drift_denoise_feature_params fp = { .method = o->denoise == 3
                                                          ? DRIFT_DENOISE_REGRESSION
                                                          : DRIFT_DENOISE_VARIANCE_GUIDED };
        return drift_denoise_feature(ctx, &in, &fp, out, NULL);
    }
    if ((r = drift_pt_resolve(pt, DRIFT_PT_AOV_ALBEDO, &a)) != DRIFT_OK ||
        (r = drift_pt_resolve(pt, DRIFT_PT_AOV_NORMAL, &n)) != DRIFT_OK ||
        (r = drift_pt_resolve(pt, DRIFT_PT_AOV_DEPTH, &z)) != DRIFT_OK) {
        return r;
    }
    return drift_denoise_atrous(ctx, beauty, &a, &n, &z, NULL, out);
}

double render_denoise_ms(drift_context *ctx, drift_pt *pt, const render_options *o)
{
    drift_image beauty, denoised = { 0 };
    if (!o->denoise || drift_pt_resolve(pt, DRIFT_PT_AOV_BEAUTY, &beauty) != DRIFT_OK) {
        return 0.0;
    }
    double t0 = drift_time_now();
    drift_result r = denoise_beauty(ctx, pt, o, &beauty, &denoised);
    double ms = 1e3 * (drift_time_now() - t0);
    drift_image_destroy(ctx, &denoised);
    return r == DRIFT_OK ? ms : 0.0;
}

// The EXR (beauty, --aov layers; an "spp" layer of each pixel's sample count when the tiles
// hold different counts) and the PNG beside it, to the paths given (staged by the caller).
drift_result render_write_images(drift_context *ctx, drift_pt *pt, const render_options *o,
                                 float fov_y, const char *exr_path, const char *png_path,
                                 double *out_denoise_ms)
{
    drift_image beauty, albedo, normal, depth;
    drift_result r = drift_pt_resolve(pt, DRIFT_PT_AOV_BEAUTY, &beauty);
    if (r != DRIFT_OK) {
        return r;
    }
    drift_image denoised = { 0 }, glared = { 0 }, spp = { 0 };
    drift_image variance = { 0 }, f_albedo = { 0 }, f_normal = { 0 }, f_depth = { 0 };
    drift_image direct = { 0 }, direct_var = { 0 }, indirect_var = { 0 };
    if (o->aov) { // the images stay the pt's until its next render call
        if ((r = drift_pt_resolve(pt, DRIFT_PT_AOV_VARIANCE, &variance)) != DRIFT_OK ||
            (r = drift_pt_resolve(pt, DRIFT_PT_AOV_FEATURE_ALBEDO, &f_albedo)) != DRIFT_OK ||
            (r = drift_pt_resolve(pt, DRIFT_PT_AOV_FEATURE_NORMAL, &f_normal)) != DRIFT_OK ||
            (r = drift_pt_resolve(pt, DRIFT_PT_AOV_FEATURE_DEPTH, &f_depth)) != DRIFT_OK ||
            (r = drift_pt_resolve(pt, DRIFT_PT_AOV_DIRECT, &direct)) != DRIFT_OK ||
            (r = drift_pt_resolve(pt, DRIFT_PT_AOV_DIRECT_VARIANCE, &direct_var)) != DRIFT_OK ||
            (r = drift_pt_resolve(pt, DRIFT_PT_AOV_INDIRECT_VARIANCE, &indirect_var)) != DRIFT_OK) {
            return r;
        }
    }
    if (o->denoise) { // before glare (the last pass)
        double t_denoise = drift_time_now();
        r = denoise_beauty(ctx, pt, o, &beauty, &denoised);
        if (r != DRIFT_OK) {
            return r;
        }
        beauty = denoised; // destroyed below
        *out_denoise_ms = 1e3 * (drift_time_now() - t_denoise);
    }
    drift_image upsampled = { 0 };
    const bool upsample = o->upsample_width > 0 && o->upsample_height > 0;
    if (upsample) { // the chooser's reduced-resolution pick (tools/render_choose.c)
        r = render_upsample_bilinear(ctx, &beauty, (int32_t)o->upsample_width,
                                     (int32_t)o->upsample_height, &upsampled);
        if (r != DRIFT_OK) {
            drift_image_destroy(ctx, &denoised);
            return r;
        }
        beauty = upsampled; // destroyed below
    }
    if (o->hybrid.glare != DRIFT_GLARE_NONE) {
        if ((r = apply_glare(ctx, o, fov_y, &beauty, &glared)) != DRIFT_OK) {
            drift_image_destroy(ctx, &denoised);
            drift_image_destroy(ctx, &upsampled);
            return r;
        }
        beauty = glared; // the glare's copy, destroyed below
    }
    drift_image_layer layers[12] = { { NULL, &beauty } };
    uint32_t layer_count = 1;
    if (o->aov && !upsample) { // the AOVs are at the low resolution: left out
        if ((r = drift_pt_resolve(pt, DRIFT_PT_AOV_ALBEDO, &albedo)) != DRIFT_OK ||
            (r = drift_pt_resolve(pt, DRIFT_PT_AOV_NORMAL, &normal)) != DRIFT_OK ||
            (r = drift_pt_resolve(pt, DRIFT_PT_AOV_DEPTH, &depth)) != DRIFT_OK) {
            drift_image_destroy(ctx, &glared);
            drift_image_destroy(ctx, &denoised);
            return r;
        }
        // The names tev, Nuke and Blender's compositor take as theirs: Z, N.XYZ, albedo.RGB.
        layers[1] = (drift_image_layer){ "albedo", &albedo };
        layers[2] = (drift_image_layer){ o->aov_normal ? "Normal" : "N", &normal };
        layers[3] = (drift_image_layer){ NULL, &depth };
        // The feature-guided denoiser's inputs (drift/pt.h, DRIFT_PT_AOV_VARIANCE on).
        layers[4] = (drift_image_layer){ "variance", &variance };
        layers[5] = (drift_image_layer){ "feature_albedo", &f_albedo };
        layers[6] = (drift_image_layer){ "feature_normal", &f_normal };
        layers[7] = (drift_image_layer){ "feature_depth", &f_depth };
        layers[8] = (drift_image_layer){ "direct", &direct };
        layers[9] = (drift_image_layer){ "direct_variance", &direct_var };
        layers[10] = (drift_image_layer){ "indirect_variance", &indirect_var };
        layer_count = 11;
    }
    uint32_t lowest, highest;
    render_spp_range(pt, &lowest, &highest);
    char spp_text[64], note[256], depth_text[32], seed_text[32];
    snprintf(depth_text, sizeof depth_text, "%d", (int)drift_pt_get_params(pt).max_depth);
    snprintf(seed_text, sizeof seed_text, "%ld", o->seed);
    // The render's settings, for whoever opens the file later (drift.spp_note last: optional).
    drift_image_attribute attributes[5] = {
        { "drift.scene", o->scene_path ? o->scene_path : cli_default_scene_path() },
        { "drift.max_depth", depth_text },
        { "drift.seed", seed_text },
        { "drift.spp", spp_text },
        { "drift.spp_note", note },
    };
    uint32_t attribute_count = 4;
    snprintf(spp_text, sizeof spp_text, "%u", lowest);
    if (lowest != highest && r == DRIFT_OK && !upsample) {
        snprintf(spp_text, sizeof spp_text, "%u..%u", lowest, highest);
        snprintf(note, sizeof note,
                 "interrupted: tiles of %dx%d pixels hold %u to %u samples; the spp layer has "
                 "each pixel's count",
                 DRIFT_PT_TILE_SIZE, DRIFT_PT_TILE_SIZE, lowest, highest);
        attribute_count = 5;
        r = drift_image_create(ctx, beauty.width, beauty.height, 1, &spp);
        for (uint32_t t = 0; r == DRIFT_OK && t < drift_pt_tile_count(pt); ++t) {
            drift_pt_tile rect = drift_pt_tile_rect(pt, t);
            float n = (float)drift_pt_tile_sample_count(pt, t);
            for (int32_t y = rect.y0; y < rect.y1; ++y) {
                for (int32_t x = rect.x0; x < rect.x1; ++x) {
                    *drift_image_pixel(&spp, x, y) = n;
                }
            }
        }
        layers[layer_count++] = (drift_image_layer){ "spp", &spp };
    }
    if (r == DRIFT_OK) {
        // One entry a layer of the --aov file (then the spp layer): beauty, albedo, N, Z,
        // variance, feature_albedo, feature_normal, feature_depth, direct, direct_variance,
        // indirect_variance.
        const char *const channels[12] = { NULL,    NULL, "X,Y,Z", "Z",  NULL, NULL,
                                           "X,Y,Z", NULL, NULL,    NULL, NULL, NULL };
        r = drift_image_save_exr_channels(ctx, exr_path, layers, layer_count,
                                          layer_count > 1 && o->aov ? channels : NULL, attributes,
                                          attribute_count);
    }
    if (r == DRIFT_OK) {
        r = render_save_png(ctx, o, png_path, &beauty);
    }
    drift_image_destroy(ctx, &spp);
    drift_image_destroy(ctx, &glared); // NULL-safe on a zero image
    drift_image_destroy(ctx, &denoised);
    drift_image_destroy(ctx, &upsampled);
    return r;
}
