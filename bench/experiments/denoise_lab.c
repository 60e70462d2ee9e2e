// The denoiser's lab harness (issue 48, docs/lab/2026-12-07-issue-48-s2.md): renders a scene's
// path-traced inputs once and replays denoisers over them, so that a filter change is measured
// on the whole corpus in seconds instead of re-rendering.
//   denoise_lab dump SCENE WIDTH HEIGHT SPP SEED OUT.bin   beauty + every AOV, raw floats
//   denoise_lab eval REF.exr IN.bin [REF.exr IN.bin ...]   ꟻLIP of raw, atrous, on, regression
// Build (after cmake --build build/release --target drift):
//   cc -O2 -std=c11 -Iinclude -Ibuild/release/include bench/experiments/denoise_lab.c \
//     $(sed 's/.*bin\/drift *//' build/release/CMakeFiles/drift_cli.dir/link.txt | sed
//     's/libdrift.a/build\/release\/libdrift.a/') \ -lstdc++ -o /tmp/denoise_lab
#include <drift/drift.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum {
    L_BEAUTY,
    L_ALBEDO,
    L_NORMAL,
    L_DEPTH,
    L_VAR,
    L_FALB,
    L_FNRM,
    L_FDEP,
    L_DIR,
    L_DVAR,
    L_IVAR,
    L_COUNT
};

static const drift_pt_aov aovs[L_COUNT] = {
    DRIFT_PT_AOV_BEAUTY,
    DRIFT_PT_AOV_ALBEDO,
    DRIFT_PT_AOV_NORMAL,
    DRIFT_PT_AOV_DEPTH,
    DRIFT_PT_AOV_VARIANCE,
    DRIFT_PT_AOV_FEATURE_ALBEDO,
    DRIFT_PT_AOV_FEATURE_NORMAL,
    DRIFT_PT_AOV_FEATURE_DEPTH,
    DRIFT_PT_AOV_DIRECT,
    DRIFT_PT_AOV_DIRECT_VARIANCE,
    DRIFT_PT_AOV_INDIRECT_VARIANCE,
};

static int fail(const char *what, drift_result r)
{
    fprintf(stderr, "denoise_lab: %s: %s\n", what, drift_result_string(r));
    return 1;
}

static int write_aovs(drift_pt *pt, uint32_t spp, const char *path)
{
    drift_result r;
    drift_pt_params pp = drift_pt_get_params(pt);
    FILE *f = fopen(path, "wb");
    int32_t head[3] = { pp.width, pp.height, (int32_t)spp };
    fwrite(head, sizeof head, 1, f);
    for (int l = 0; l < L_COUNT; ++l) {
        drift_image im;
        if ((r = drift_pt_resolve(pt, aovs[l], &im)) != DRIFT_OK) {
            return fail("resolve", r);
        }
        int32_t ch = im.channels;
        fwrite(&ch, sizeof ch, 1, f);
        for (int32_t y = 0; y < im.height; ++y) {
            for (int32_t x = 0; x < im.width; ++x) {
                fwrite(drift_image_pixel(&im, x, y), sizeof(float), (size_t)ch, f);
            }
        }
    }
    fclose(f);
    return 0;
}

static int dump(drift_context *ctx, char **a)
{
    drift_scene *scene = NULL;
    drift_accel *accel = NULL;
    drift_pt *pt = NULL;
    drift_result r;
    if ((r = drift_scene_load(ctx, a[0], &scene)) != DRIFT_OK ||
        (r = drift_accel_create(ctx, scene, &(drift_accel_desc){ 0 }, &accel)) != DRIFT_OK) {
        return fail(a[0], r);
    }
    // SPP is a comma list (1,4,16), OUT gets -SPP.bin. Each is its own render, as `drift render
    // --spp N --seed SEED` makes it: the texture filter's ray cone follows the spp
    // (drift_pt_params.texture_filter_spp), so a continued render would differ from the CLI's.
    for (char *s = a[3]; *s;) {
        uint32_t spp = (uint32_t)strtoul(s, &s, 10);
        s += *s == ',';
        drift_pt_params pp = { .width = atoi(a[1]),
                               .height = atoi(a[2]),
                               .seed = (uint32_t)atoi(a[4]),
                               .texture_filter_spp = spp };
        if ((r = drift_pt_create(ctx, scene, accel, &pp, &pt)) != DRIFT_OK) {
            return fail("pt", r);
        }
        if ((r = drift_pt_render_samples(pt, spp, NULL)) != DRIFT_OK) {
            return fail("render", r);
        }
        char path[4096];
        snprintf(path, sizeof path, "%s-%u.bin", a[5], spp);
        if (write_aovs(pt, spp, path)) {
            return 1;
        }
        drift_pt_destroy(pt);
    }
    drift_accel_destroy(accel);
    drift_scene_destroy(scene);
    return 0;
}

static int load(drift_context *ctx, const char *path, drift_image im[L_COUNT], uint32_t *spp)
{
    FILE *f = fopen(path, "rb");
    int32_t head[3];
    if (!f || fread(head, sizeof head, 1, f) != 1) {
        fprintf(stderr, "denoise_lab: cannot read %s\n", path);
        return 0;
    }
    *spp = (uint32_t)head[2];
    for (int l = 0; l < L_COUNT; ++l) {
        int32_t ch;
        if (fread(&ch, sizeof ch, 1, f) != 1 ||
            drift_image_create(ctx, head[0], head[1], ch, &im[l]) != DRIFT_OK) {
            return 0;
        }
        for (int32_t y = 0; y < head[1]; ++y) {
            for (int32_t x = 0; x < head[0]; ++x) {
                if (fread(drift_image_pixel(&im[l], x, y), sizeof(float), (size_t)ch, f) !=
                    (size_t)ch) {
                    return 0;
                }
            }
        }
    }
    fclose(f);
    return 1;
}

static double flip(drift_context *ctx, const drift_image *ref, const drift_image *test)
{
    double v = -1.0;
    drift_metric_flip(ctx, ref, test, NULL, &v, NULL);
    return v;
}

int main(int argc, char **argv)
{
    drift_context *ctx = NULL;
    const char *t = getenv("THREADS");
    drift_context_create(&(drift_context_desc){ .thread_count = t ? atoi(t) : 2 }, &ctx);
    if (argc == 8 && !strcmp(argv[1], "dump")) {
        return dump(ctx, argv + 2);
    }
    if (argc < 4 || strcmp(argv[1], "eval") || argc % 2) {
        fprintf(stderr, "usage: denoise_lab dump SCENE W H SPP SEED OUT.bin | eval REF IN ...\n");
        return 2;
    }
    const char *only = getenv("ONLY"); // "on" to skip atrous and regression
    for (int i = 2; i + 1 < argc; i += 2) {
        drift_image ref, im[L_COUNT], out;
        uint32_t spp;
        if (drift_image_load(ctx, argv[i], &ref) != DRIFT_OK || !load(ctx, argv[i + 1], im, &spp)) {
            return 1;
        }
        double raw = flip(ctx, &ref, &im[L_BEAUTY]), fa = -1, fr = -1;
        if (!only) {
            drift_denoise_atrous(ctx, &im[L_BEAUTY], &im[L_ALBEDO], &im[L_NORMAL], &im[L_DEPTH],
                                 NULL, &out);
            fa = flip(ctx, &ref, &out);
            drift_image_destroy(ctx, &out);
        }
        drift_denoise_inputs in = { &im[L_BEAUTY], &im[L_FALB], &im[L_FNRM],
                                    &im[L_FDEP],   &im[L_VAR],  spp };
        if (!getenv("NOSPLIT")) { // the direct part filtered apart (NOSPLIT=1: as one)
            in.direct = &im[L_DIR];
            in.direct_variance = &im[L_DVAR];
            in.indirect_variance = &im[L_IVAR];
        }
        double t0 = drift_time_now();
        // SIGL1, SIGL, SIGLI, ITER: the params' sigma_luminance (one filter),
        // sigma_luminance_direct, sigma_luminance_indirect, iterations.
        drift_denoise_feature_params fp = { 0 };
        fp.sigma_luminance = getenv("SIGL1") ? (float)atof(getenv("SIGL1")) : 0.0f;
        fp.sigma_luminance_direct = getenv("SIGL") ? (float)atof(getenv("SIGL")) : 0.0f;
        fp.sigma_luminance_indirect = getenv("SIGLI") ? (float)atof(getenv("SIGLI")) : 0.0f;
        fp.iterations = getenv("ITER") ? atoi(getenv("ITER")) : 0;
        fp.no_firefly_clamp = getenv("NOFF") != NULL;
        fp.sigma_albedo = getenv("SIGA") ? (float)atof(getenv("SIGA")) : 0.0f;
        fp.sigma_normal = getenv("SIGN") ? (float)atof(getenv("SIGN")) : 0.0f;
        fp.sigma_depth = getenv("SIGZ") ? (float)atof(getenv("SIGZ")) : 0.0f;
        // INDVG=1: the rest filtered VARIANCE_GUIDED (session 2's filter); RESSIG: the
        // residual's sigma_l; METHOD: the params' method (0 1 2).
        fp.indirect_variance_guided = getenv("INDVG") != NULL;
        fp.sigma_luminance_residual = getenv("RESSIG") ? (float)atof(getenv("RESSIG")) : 0.0f;
        fp.residual_block = getenv("RESBLOCK") ? atoi(getenv("RESBLOCK")) : 0;
        fp.method = getenv("METHOD") ? (drift_denoise_method)atoi(getenv("METHOD")) : 0;
        drift_denoise_feature(ctx, &in, &fp, &out, NULL);
        double ms = 1e3 * (drift_time_now() - t0);
        double fo = flip(ctx, &ref, &out);
        if (getenv("SAVE")) { // SAVE=DIR: the denoised and raw images as DIR/NAME-on.exr, -raw.exr
            char path[4096];
            const char *base = strrchr(argv[i + 1], '/');
            snprintf(path, sizeof path, "%s/%s-on.exr", getenv("SAVE"),
                     base ? base + 1 : argv[i + 1]);
            drift_image_save_exr(ctx, path, &(drift_image_layer){ NULL, &out }, 1);
            strcat(path, ".png");
            drift_image_save_png(ctx, path, &out, NULL);
            snprintf(path, sizeof path, "%s/%s-raw.exr", getenv("SAVE"),
                     base ? base + 1 : argv[i + 1]);
            drift_image_save_exr(ctx, path, &(drift_image_layer){ NULL, &im[L_BEAUTY] }, 1);
        }
        drift_image_destroy(ctx, &out);
        if (!only) {
            drift_denoise_feature(
                ctx, &in, &(drift_denoise_feature_params){ .method = DRIFT_DENOISE_REGRESSION },
                &out, NULL);
            fr = flip(ctx, &ref, &out);
            drift_image_destroy(ctx, &out);
        }
        const char *name = strrchr(argv[i + 1], '/');
        printf("| %s | %u | %.4f | %.4f | %.4f | %.4f | %.2f | %.0f |\n",
               name ? name + 1 : argv[i + 1], spp, raw, fa, fo, fr, fo / raw, ms);
        fflush(stdout);
        drift_image_destroy(ctx, &ref);
        for (int l = 0; l < L_COUNT; ++l) {
            drift_image_destroy(ctx, &im[l]);
        }
    }
    drift_context_destroy(ctx);
    return 0;
}
