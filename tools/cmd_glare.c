// drift glare: temporal glare (Ritschel 2009, thesis ch. 8) on an HDR image or a sequence.
// The options are one cli_options table (tools/cli_options.h): the parser and --help read it.
#include "cli.h"
#include "drift/glare.h"
#include "drift/image.h"
#include "drift/image_io.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define PI 3.14159265358979323846

typedef struct glare_args {
    const char *in; // IN: an image or a frame pattern
    const char *out, *out_pattern, *psf, *aperture;
    long frames, seed, psf_size, supersample, wavelengths, threads;
    long lens_particles, gratings, vitreous, lashes;
    double fps, fresnel_distance, aperture_width, fov_deg, luminance_scale, field_luminance;
    double squint, blink_interval, hippus, exposure, billboard_threshold;
    int mode, diffraction, pupil, method;
    bool verbose;
} glare_args;

// A file name option: any text but the empty one.
static bool parse_file_name(const char *cmd, const char *flag, const char *value, void *field)
{
    if (value[0] == '\0') {
        fprintf(stderr, "drift %s: %s expects a file name, got ''\n", cmd, flag);
        return false;
    }
    *(const char **)field = value;
    return true;
}

#define O glare_args
static const cli_option glare_table[] = {
    CLI_SECTION("options:", 0),
    CLI_CUSTOM("--out", "F.exr|F.png", O, out, parse_file_name, "output image (one frame)"),
    CLI_INT("--frames", "N", O, frames, 1, 100000, "frames to make (default 1)"),
    CLI_NUMBER("--fps", "F", O, fps, 0.1, 1000, "frame rate of a sequence (default 30)"),
    CLI_CUSTOM("--out-pattern", "P", O, out_pattern, parse_file_name,
               "output names of a sequence, one %d (e.g. frame_%04d.exr);\n"
               "IN may be a pattern too"),
    CLI_INT("--seed", "S", O, seed, 0, 4294967295.0, "seed of the eye (default 0)"),
    CLI_CHOICE("--mode", "M", O, mode, "auto|static|dynamic",
               "auto (default: static for 1 frame, dynamic for more), static or\n"
               "dynamic eye"),
    CLI_CUSTOM("--psf", "F.exr|F.png", O, psf, parse_file_name,
               "write the RGB PSF (last frame's; a %d name: every frame's);\n"
               ".png: 5 decades, log"),
    CLI_CUSTOM("--aperture", "F.exr", O, aperture, parse_file_name,
               "write the aperture transmittance and F_575 as layers (last\n"
               "frame or %d)"),
    CLI_INT("--psf-size", "N", O, psf_size, 16, 4096,
            "aperture and PSF size, a power of two (default 256)"),
    CLI_INT("--supersample", "S", O, supersample, 1, 8,
            "aperture samples per pixel per axis (default 2)"),
    CLI_INT("--wavelengths", "N", O, wavelengths, 1, 128,
            "spectral samples over 380-770 nm (default 32)"),
    CLI_CHOICE("--diffraction", "D", O, diffraction, "fresnel|fraunhofer",
               "fresnel (thesis eq. 8.3, default) or fraunhofer (E = 1)"),
    CLI_NUMBER("--fresnel-distance", "MM", O, fresnel_distance, 1e-3, 1e9,
               "d of the Fresnel term E (default 70435: a quarter wave at 9 mm)"),
    CLI_NUMBER("--aperture-width", "MM", O, aperture_width, 0.5, 100,
               "physical width W of the aperture texture (default 12)"),
    CLI_NUMBER("--fov", "DEG", O, fov_deg, 0, 360,
               "horizontal field of view of IN; resamples the PSF to its pitch\n"
               "(default 0: one PSF pixel per image pixel)"),
    CLI_CHOICE("--method", "M", O, method, "convolution|billboard",
               "convolution of the whole image (default) or billboard: paste\n"
               "billboards at bright pixels"),
    CLI_NUMBER("--billboard-threshold", "X", O, billboard_threshold, 0, 1e30,
               "luminance over which a pixel gets a billboard (default 20 x\n"
               "the mean)"),
    CLI_CHOICE("--pupil", "MODEL", O, pupil, "thesis|moon-spencer|watson-yellott",
               "thesis (eq. 8.2, default), moon-spencer or watson-yellott"),
    CLI_NUMBER("--luminance-scale", "X", O, luminance_scale, 1e-12, 1e12,
               "cd/m^2 per image unit (default 1)"),
    CLI_NUMBER("--field-luminance", "L", O, field_luminance, 1e-9, 1e12,
               "fixed field luminance in cd/m^2 (default: the image's mean)"),
    CLI_NUMBER("--squint", "X", O, squint, 0, 0.99, "constant lid closure (0..0.99)"),
    CLI_NUMBER("--blink-interval", "S", O, blink_interval, 0, 1e6,
               "mean seconds between blinks (default 4; 0: none)"),
    CLI_NUMBER("--hippus", "X", O, hippus, 0, 1, "hippus noise scale (default 0.1)"),
    CLI_INT("--lens-particles", "N", O, lens_particles, 0, 100000, "lens particles (default 750)"),
    CLI_INT("--gratings", "N", O, gratings, 0, 100000, "lens fibre gratings (200)"),
    CLI_INT("--vitreous", "N", O, vitreous, 0, 100000, "vitreous particles (200)"),
    CLI_INT("--lashes", "N", O, lashes, 0, 100000, "eyelashes (40)"),
    CLI_NUMBER("--exposure", "STOPS", O, exposure, -64, 64, "exposure of PNG outputs (default 0)"),
    CLI_INT("--threads", "T", O, threads, 0, 1024, "worker threads (default: all)"),
    CLI_FLAG("-v, --verbose", O, verbose, "more log output"),
};
#undef O

static const cli_command glare_command = {
    .name = "glare",
    .usage = "usage: drift glare IN.exr --out OUT.exr [options]\n"
             "       drift glare IN.exr --frames N --fps F --out-pattern frame_%04d.exr\n"
             "\n"
             "Adds temporal glare (Ritschel et al. 2009; thesis ch. 8) to an HDR image (.exr or\n"
             ".hdr): the eye's aperture, its Fresnel diffraction, the chromatic PSF and the\n"
             "convolution of IN with it. docs/glare.md describes the model.\n"
             "\n",
    .epilogue = "\nexit status: 0 ok, 1 failure, 2 usage error or bad input (nothing written)\n",
    CLI_TABLE(glare_table),
    CLI_POSITIONAL("IN", glare_args, in, 1),
    .help_column = 31,
};

// Whether `pattern` holds exactly one integer conversion %d or %0Nd (and only %% otherwise).
static bool is_frame_pattern(const char *pattern)
{
    int conversions = 0;
    for (const char *p = pattern; *p; ++p) {
        if (*p != '%') {
            continue;
        }
        ++p;
        if (*p == '%') {
            continue;
        }
        while (*p >= '0' && *p <= '9') {
            ++p;
        }
        if (*p != 'd') {
            return false;
        }
        ++conversions;
    }
    return conversions == 1;
}

static bool has_extension(const char *path, const char *const *exts)
{
    const char *dot = strrchr(path, '.');
    for (; dot && *exts; ++exts) {
        const char *a = dot, *b = *exts;
        while (*a && *b && (*a | 0x20) == (*b | 0x20)) {
            ++a;
            ++b;
        }
        if (!*a && !*b) {
            return true;
        }
    }
    return false;
}

static const char *const hdr_exts[] = { ".exr", ".hdr", NULL };
static const char *const out_exts[] = { ".exr", ".png", NULL };
static const char *const exr_exts[] = { ".exr", NULL };

// The file name of frame f: `pattern` formatted when it is a frame pattern, else itself.
static const char *frame_name(char *buf, size_t size, const char *pattern, long f)
{
    if (!strchr(pattern, '%')) {
        return pattern;
    }
    // is_frame_pattern() has checked that the pattern has one integer conversion.
#if defined(__GNUC__)
#    pragma GCC diagnostic push
#    pragma GCC diagnostic ignored "-Wformat-nonliteral"
#endif
    int n = snprintf(buf, size, pattern, (int)f);
#if defined(__GNUC__)
#    pragma GCC diagnostic pop
#endif
    return n > 0 && (size_t)n < size ? buf : NULL;
}

// The PSF as a PNG that shows its five decades: 1 + log10(v / max) / 5 per channel, the
// maximum over all channels (so colour is kept), written through the sRGB curve.
static drift_result save_psf_png(drift_context *ctx, const char *path, const drift_image *psf)
{
    drift_image img;
    drift_result r = drift_image_create(ctx, psf->width, psf->height, 3, &img);
    if (r != DRIFT_OK) {
        return r;
    }
    double mx = 0.0;
    for (int32_t y = 0; y < psf->height; ++y) {
        for (int32_t x = 0; x < psf->width; ++x) {
            for (int32_t c = 0; c < 3; ++c) {
                mx = fmax(mx, (double)drift_image_pixel(psf, x, y)[c]);
            }
        }
    }
    for (int32_t y = 0; y < psf->height; ++y) {
        for (int32_t x = 0; x < psf->width; ++x) {
            for (int32_t c = 0; c < 3; ++c) {
                double v = mx > 0.0 ? (double)drift_image_pixel(psf, x, y)[c] / mx : 0.0;
                v = v > 1e-5 ? 1.0 + log10(v) / 5.0 : 0.0;
                drift_image_pixel(&img, x, y)[c] = drift_srgb_to_linear((float)v);
            }
        }
    }
    r = drift_image_save_png(ctx, path, &img, NULL);
    drift_image_destroy(ctx, &img);
    return r;
}

// Whether the folder that `path` would be written into exists and is writable.
static bool folder_writable(const char *path)
{
    char dir[4096];
    const char *slash = strrchr(path, '/');
    if (!slash) {
        return access(".", W_OK) == 0;
    }
    size_t len = (size_t)(slash - path);
    if (len >= sizeof(dir)) {
        return false;
    }
    memcpy(dir, path, len);
    dir[len] = '\0';
    return access(len ? dir : "/", W_OK) == 0;
}

// Every frame's outputs against its input and each other (cli_check_outputs).
static bool check_frame_outputs(const glare_args *a, const char *out_name)
{
    char bufs[4][4096];
    bool patterned = strchr(a->in, '%') || strchr(out_name, '%') ||
                     (a->psf && strchr(a->psf, '%')) || (a->aperture && strchr(a->aperture, '%'));
    for (long f = 0; f < (patterned ? a->frames : 1); ++f) {
        const cli_file in = { "IN", frame_name(bufs[0], sizeof bufs[0], a->in, f) };
        const cli_file outs[3] = {
            { a->out ? "--out" : "--out-pattern",
              frame_name(bufs[1], sizeof bufs[1], out_name, f) },
            { "--psf", a->psf ? frame_name(bufs[2], sizeof bufs[2], a->psf, f) : NULL },
            { "--aperture",
              a->aperture ? frame_name(bufs[3], sizeof bufs[3], a->aperture, f) : NULL },
        };
        if (!cli_check_outputs("glare", &in, 1, outs, 3)) {
            return false;
        }
    }
    return true;
}

static drift_result save_image(drift_context *ctx, const char *path, const drift_image *img,
                               double exposure)
{
    if (has_extension(path, exr_exts)) {
        return drift_image_save_exr(ctx, path, &(drift_image_layer){ NULL, img }, 1);
    }
    return drift_image_save_png(ctx, path, img,
                                &(drift_tonemap_params){ .exposure_stops = (float)exposure });
}

int drift_cmd_glare(int argc, char **argv)
{
    glare_args a = { .frames = 1, .fps = 30.0, .blink_interval = -1.0, .hippus = -1.0 };
    int parsed = cli_parse(&glare_command, argc, argv, &a, NULL);
    if (parsed != CLI_PARSED) {
        return cli_parse_exit(parsed);
    }
    // Check everything that can be checked before anything is read or written.
    const char *in_path = a.in;
    if (!in_path) {
        cli_print_help(&glare_command, stderr);
        return 2;
    }
    bool in_is_pattern = strchr(in_path, '%') != NULL;
    if (in_is_pattern && !is_frame_pattern(in_path)) {
        fprintf(stderr, "drift glare: input pattern '%s' needs exactly one %%d\n", in_path);
        return 2;
    }
    if (!has_extension(in_path, hdr_exts)) {
        fprintf(stderr, "drift glare: '%s' is not an HDR image (.exr or .hdr)\n", in_path);
        return 2;
    }
    if (a.frames == 1 && !a.out && !a.out_pattern) {
        fprintf(stderr, "drift glare: --out F.exr is required\n");
        return 2;
    }
    if (a.frames > 1 && !a.out_pattern) {
        fprintf(stderr, "drift glare: --frames %ld needs --out-pattern (e.g. frame_%%04d.exr)\n",
                a.frames);
        return 2;
    }
    if (a.out && a.out_pattern) {
        fprintf(stderr, "drift glare: give --out or --out-pattern, not both\n");
        return 2;
    }
    if (a.out_pattern && !is_frame_pattern(a.out_pattern)) {
        fprintf(stderr, "drift glare: --out-pattern '%s' needs exactly one %%d (e.g. %%04d)\n",
                a.out_pattern);
        return 2;
    }
    const char *out_name = a.out ? a.out : a.out_pattern;
    if (!has_extension(out_name, out_exts)) {
        fprintf(stderr, "drift glare: %s expects a name ending in .exr or .png, got '%s'\n",
                a.out ? "--out" : "--out-pattern", out_name);
        return 2;
    }
    const char *extras[2] = { a.psf, a.aperture };
    for (int i = 0; i < 2; ++i) {
        if (extras[i] && (!has_extension(extras[i], i == 0 ? out_exts : exr_exts) ||
                          (strchr(extras[i], '%') && !is_frame_pattern(extras[i])))) {
            fprintf(stderr, "drift glare: %s expects an %s name (with at most one %%d), got '%s'\n",
                    i == 0 ? "--psf" : "--aperture", i == 0 ? ".exr or .png" : ".exr", extras[i]);
            return 2;
        }
    }
    const char *outputs[3] = { out_name, a.psf, a.aperture };
    if (!check_frame_outputs(&a, out_name)) {
        return 2;
    }
    for (int i = 0; i < 3; ++i) {
        if (outputs[i] && !folder_writable(outputs[i])) {
            fprintf(stderr, "drift glare: cannot write '%s': its folder is missing or read-only\n",
                    outputs[i]);
            return 1;
        }
    }
    if (a.psf_size && (a.psf_size & (a.psf_size - 1)) != 0) {
        fprintf(stderr, "drift glare: --psf-size %ld is not a power of two\n", a.psf_size);
        return 2;
    }
    drift_glare_params params = {
        .mode = a.mode == 0 ? (a.frames > 1 ? DRIFT_GLARE_MODE_DYNAMIC : DRIFT_GLARE_MODE_STATIC)
                            : (drift_glare_mode)a.mode,
        .seed = (uint32_t)a.seed,
        .psf_size = (int32_t)a.psf_size,
        .supersample = (int32_t)a.supersample,
        .wavelength_count = (int32_t)a.wavelengths,
        .diffraction = (drift_glare_diffraction)(a.diffraction + 1),
        .fresnel_distance_mm = a.fresnel_distance,
        .aperture_width_mm = a.aperture_width,
        .image_fov = a.fov_deg * PI / 180.0,
        .pupil_model = (drift_glare_pupil_model)(a.pupil + 1),
        .luminance_scale = a.luminance_scale,
        .field_luminance = a.field_luminance,
        .squint = a.squint,
        .blink_interval =
            a.blink_interval < 0.0 ? 0.0 : (a.blink_interval == 0.0 ? -1.0 : a.blink_interval),
        .hippus_scale = a.hippus < 0.0 ? 0.0 : (a.hippus == 0.0 ? -1.0 : a.hippus),
        .lens_particle_count = (int32_t)a.lens_particles,
        .grating_count = (int32_t)a.gratings,
        .vitreous_particle_count = (int32_t)a.vitreous,
        .lash_count = (int32_t)a.lashes,
        .method = (drift_glare_method)(a.method + 1),
        .billboard_threshold = a.billboard_threshold,
    };
    cli_session session;
    if (!cli_session_open(
            &(cli_session_desc){
                .cmd = "glare", .threads = (int)a.threads, .verbose = a.verbose, .no_scene = true },
            &session)) {
        return 1;
    }
    drift_context *ctx = session.ctx;
    int status = 1;
    drift_glare *glare = NULL;
    drift_image in = { 0 }, out = { 0 };
    drift_result r = drift_glare_create(ctx, &params, &glare);
    if (r != DRIFT_OK) {
        fprintf(stderr, "drift glare: bad parameters: %s\n", drift_result_string(r));
        status = r == DRIFT_ERR_INVALID_ARGUMENT ? 2 : 1;
        goto done;
    }
    char in_buf[4096], out_buf[4096], psf_buf[4096], ap_buf[4096];
    double total_ms = 0.0;
    // A sequence of inputs is read through once first, so that a missing, corrupt or NaN frame
    // stops the run before any frame is written.
    for (long f = 0; in_is_pattern && f < a.frames; ++f) {
        const char *in_name = frame_name(in_buf, sizeof(in_buf), in_path, f);
        if (!in_name) {
            fprintf(stderr, "drift glare: frame %ld's file name is too long\n", f);
            status = 2;
            goto done;
        }
        if ((r = drift_image_load(ctx, in_name, &in)) != DRIFT_OK) {
            fprintf(stderr, "drift glare: cannot load '%s': %s; nothing written\n", in_name,
                    drift_result_string(r));
            status = 2;
            goto done;
        }
        bool finite = true;
        for (size_t i = 0; finite && i < (size_t)in.width * (size_t)in.height * 3; ++i) {
            finite = isfinite(in.pixels[i]);
        }
        drift_image_destroy(ctx, &in);
        if (!finite) {
            fprintf(stderr, "drift glare: '%s' has NaN or infinite pixels; nothing written\n",
                    in_name);
            status = 2;
            goto done;
        }
    }
    for (long f = 0; f < a.frames; ++f) {
        const char *in_name = frame_name(in_buf, sizeof(in_buf), in_path, f);
        const char *out_frame = frame_name(out_buf, sizeof(out_buf), out_name, f);
        if (!in_name || !out_frame) {
            fprintf(stderr, "drift glare: frame %ld's file name is too long\n", f);
            goto done;
        }
        if (f == 0 || in_is_pattern) {
            drift_image_destroy(ctx, &in);
            if ((r = drift_image_load(ctx, in_name, &in)) != DRIFT_OK) {
                fprintf(stderr, "drift glare: cannot load '%s': %s\n", in_name,
                        drift_result_string(r));
                status = 2;
                goto done;
            }
        }
        double t0 = drift_time_now();
        r = drift_glare_apply(glare, &in, f == 0 ? 0.0 : 1.0 / a.fps, &out);
        double ms = 1e3 * (drift_time_now() - t0);
        if (r != DRIFT_OK) {
            if (r == DRIFT_ERR_INVALID_ARGUMENT) {
                fprintf(stderr,
                        "drift glare: '%s' has NaN or infinite pixels (the first is named "
                        "above); nothing written\n",
                        in_name);
            } else {
                fprintf(stderr, "drift glare: '%s': %s\n", in_name, drift_result_string(r));
            }
            status = r == DRIFT_ERR_INVALID_ARGUMENT ? 2 : 1;
            goto done;
        }
        total_ms += ms;
        bool last = f == a.frames - 1;
        if (a.psf && (last || strchr(a.psf, '%'))) {
            drift_image psf = drift_glare_psf(glare);
            const char *name = frame_name(psf_buf, sizeof(psf_buf), a.psf, f);
            if (name) {
                r = has_extension(name, exr_exts)
                        ? drift_image_save_exr(ctx, name, &(drift_image_layer){ NULL, &psf }, 1)
                        : save_psf_png(ctx, name, &psf);
            }
            if (!name || r != DRIFT_OK) {
                fprintf(stderr, "drift glare: cannot write PSF '%s'\n", name ? name : a.psf);
                goto done;
            }
        }
        if (a.aperture && (last || strchr(a.aperture, '%'))) {
            drift_image ap = drift_glare_aperture(glare), mono = drift_glare_psf_mono(glare);
            drift_image_layer layers[2] = { { NULL, &ap }, { "psf575", &mono } };
            const char *name = frame_name(ap_buf, sizeof(ap_buf), a.aperture, f);
            if (!name || (r = drift_image_save_exr(ctx, name, layers, 2)) != DRIFT_OK) {
                fprintf(stderr, "drift glare: cannot write aperture '%s'\n",
                        name ? name : a.aperture);
                goto done;
            }
        }
        if ((r = save_image(ctx, out_frame, &out, a.exposure)) != DRIFT_OK) {
            fprintf(stderr, "drift glare: cannot write '%s': %s\n", out_frame,
                    drift_result_string(r));
            goto done;
        }
        drift_glare_eye eye = drift_glare_eye_state(glare);
        printf("frame %ld: %s  t %.3f s  pupil %.4f mm (mean %.4f)  field %.4g cd/m^2  blink %.2f  "
               "lens %+.4f mm  vitreous %+.5f %+.5f rad  %.1f ms\n",
               f, out_frame, eye.time, eye.pupil_mm, eye.pupil_mean_mm, eye.field_luminance,
               eye.blink, eye.accommodation, eye.vitreous_angle[0], eye.vitreous_angle[1], ms);
        drift_image_destroy(ctx, &out);
    }
    if (a.frames > 1) {
        printf("%ld frames, %.1f ms a frame\n", a.frames, total_ms / (double)a.frames);
    }
    status = 0;
done:
    drift_image_destroy(ctx, &out);
    drift_image_destroy(ctx, &in);
    drift_glare_destroy(glare);
    cli_session_close(&session);
    return status;
}
