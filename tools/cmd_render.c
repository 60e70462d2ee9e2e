// drift render: renders a scene with the reference path tracer.
//
// Reads like the API walk-through: load the scene, build the accel, create the path tracer,
// add samples in passes (progress, checkpoints, Ctrl-C), resolve and write the images.
#include "cli.h"
#include "render.h"

#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <unistd.h>

#include "drift/accel.h"
#include "drift/image_io.h"
#include "drift/pt.h"
#include "drift/scene_io.h"

// Set from the SIGINT handler; the render loop polls it between tiles.
static atomic_bool interrupted;

static void on_sigint(int sig)
{
    (void)sig;
    atomic_store(&interrupted, true);
}

const atomic_bool *render_catch_sigint(void)
{
    signal(SIGINT, on_sigint);
    return &interrupted;
}


static void print_help(void)
{
    printf("usage: drift render [SCENE] [options]\n"
           "\n"
           "Renders SCENE (a drift .json scene, or .obj/.gltf/.glb/.ply[.gz]); without SCENE, the\n"
           "built-in Cornell box. Writes a linear EXR and a tone-mapped sRGB PNG beside it.\n"
           "\n"
           "options:\n"
           "  --mode MODE           reference (path tracer, default) or hybrid (the hybrid\n"
           "                        frame: one sample a pixel plus a technique per effect)\n"
           "  --spp N               samples per pixel (default 64)\n"
           "  --seed S              random seed (default 0); same seed, same image, any threads\n"
           "  --threads T           worker threads (default: all cores)\n"
           "  --max-depth D         scattering vertices per path, pbrt's convention: 1 = direct\n"
           "                        light only (default 8)\n"
           "  --width W, --height H image size (default: the scene camera's)\n"
           "  --out FILE.exr        output (default out/render.exr); FILE.png is written too\n"
           "  --aov [FILE.exr]      reference: add albedo, normal and depth layers to the EXR;\n"
           "                        hybrid: write every plane and buffer as layers of FILE.exr\n"
           "  --stats FILE.json     spp, rays traced and milliseconds per phase\n"
           "  --checkpoint SECONDS  write the image so far every SECONDS (default 60; 0 = never)\n"
           "  --exposure STOPS      PNG exposure (default 0)\n"
           "  --tonemap OP          PNG operator: clamp (default) or reinhard\n"
           "  --debug-sample X,Y,S  trace one sample of one pixel and print its radiance\n"
           "  --quiet               no progress output;  --verbose  more log output\n"
           "\n");
    // Split in parts: C99 guarantees string literals of 4095 characters only.
    printf("hybrid mode (docs/hybrid.md):\n"
           "  --shadows T           hard (default), pcf, pcss, reference, isg, blur or aaf\n"
           "  --reflections T       none (default), envmap, sharp, reference, isg, blur or aaf\n"
           "  --dof T               none (default), post, reference or isg\n"
           "  --indirect T          none (default), ambient, reference or aaf\n"
           "                        reference = that effect alone path-traced at --spp\n"
           "                        aaf = axis-aligned filtering (docs/aaf.md), --spp rays a\n"
           "                        pixel on average (shadows: per area light)\n"
           "  --max-depth D         depth of reference reflections and indirect (default 2)\n"
           "  --light-samples N     samples per area light for unshadowed light (default 8)\n"
           "  --shadow-map-size N   texels a cube face (default 512); --pcf-kernel K (3)\n"
           "  --envmap-size N       texels a cube face (default 128)\n"
           "  --probe X,Y,Z|object  environment-map probe: a point, or one per reflective mesh\n"
           "                        (default: the scene's centre)\n"
           "  --ambient R,G,B       ambient radiance (default: the frame's mean direct light)\n"
           "  --aperture R          lens radius in scene units (default: the scene camera's)\n"
           "  --focus-distance F    distance to the plane in focus (default: the camera's)\n"
           "  --isg-search N        image space gathering (docs/isg.md): parameter-search\n"
           "  --isg-gather M        and gather samples, perfect squares (default 25 and 49)\n"
           "  --isg-sigma S         range sigma of eq. 6 and 10, squared scene units\n"
           "                        (default (0.02 x scene diagonal)^2)\n"
           "  --blur-radius R       disk radius in pixels of the blur baselines (default 4)\n"
           "  --isg-layers 1|2      2: a second depth layer behind objects for --dof isg\n"
           "  --isg-range full|plane  l of the range functions: world distance (default, the\n"
           "                        paper) or distance to the centre's tangent plane\n"
           "  --aaf-max-spp N       cap on AAF's adaptive samples a pixel (default 8 x spp)\n"
           "  --aaf-sampling M      adaptive (default) or uniform: spp in every pixel\n"
           "  --aaf-filter on|off   off: AAF's unfiltered estimate (with uniform: plain MC)\n"
           "  --aaf-sampler S       sobol (default: Owen-scrambled Sobol) or random (independent\n"
           "                        uniform numbers, the paper's Monte Carlo)\n"
           "\n");
    printf("smart image refinement (hybrid mode; docs/sir.md):\n"
           "  --refine sir          refine the frame by ray tracing, worst estimated error first\n"
           "  --budget N            samples (primary rays) an iteration (default: all pixels)\n"
           "  --refine-iterations N stop after N iterations;  --refine-time S  after S seconds\n"
           "                        (default: until every error pixel is refined)\n"
           "  --refine-spp N        samples that make a pixel refined (default 16)\n"
           "  --refine-all          refine zero-error pixels too, after all the others\n"
           "  --lambda FILE         combine the metrics with fitted weights (drift refine fit)\n"
           "\n"
           "Ctrl-C stops the render and writes what it has.\n");
}

// Returns 0 on success, 2 on a usage error (message printed).
static int parse_options(int argc, char **argv, render_options *o)
{
    *o = (render_options){ .out_path = "out/render.exr",
                           .mode = "reference",
                           .spp = 64,
                           .checkpoint_seconds = 60.0,
                           .debug_x = -1,
                           .debug_y = -1,
                           .debug_sample = -1,
                           .aperture = -1.0,
                           .focus_distance = -1.0 };
    for (int i = 1; i < argc; ++i) {
        const char *a = argv[i];
        const char *v = NULL;
        bool ok = true;
#define VALUE() (v = cli_next_value("render", argc, argv, &i))
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            print_help();
            return -1;
        } else if (strcmp(a, "--mode") == 0) {
            ok = VALUE() != NULL;
            o->mode = v;
        } else if (strcmp(a, "--spp") == 0) {
            ok = VALUE() && cli_parse_int("render", a, v, 1, 1 << 24, &o->spp);
        } else if (strcmp(a, "--seed") == 0) {
            ok = VALUE() && cli_parse_int("render", a, v, 0, UINT32_MAX, &o->seed);
        } else if (strcmp(a, "--threads") == 0) {
            ok = VALUE() && cli_parse_int("render", a, v, 0, 256, &o->threads);
        } else if (strcmp(a, "--max-depth") == 0) {
            ok = VALUE() && cli_parse_int("render", a, v, 1, 1024, &o->max_depth);
        } else if (strcmp(a, "--width") == 0) {
            ok = VALUE() && cli_parse_int("render", a, v, 1, DRIFT_IMAGE_MAX_DIMENSION, &o->width);
        } else if (strcmp(a, "--height") == 0) {
            ok = VALUE() && cli_parse_int("render", a, v, 1, DRIFT_IMAGE_MAX_DIMENSION, &o->height);
        } else if (strcmp(a, "--out") == 0) {
            ok = VALUE() != NULL;
            o->out_path = v;
        } else if (strcmp(a, "--stats") == 0) {
            ok = VALUE() != NULL;
            o->stats_path = v;
        } else if (strcmp(a, "--checkpoint") == 0) {
            ok = VALUE() && cli_parse_float("render", a, v, 0.0, 1e9, &o->checkpoint_seconds);
        } else if (strcmp(a, "--exposure") == 0) {
            ok = VALUE() && cli_parse_float("render", a, v, -64.0, 64.0, &o->exposure);
        } else if (strcmp(a, "--tonemap") == 0) {
            ok = VALUE() != NULL;
            if (ok && strcmp(v, "clamp") == 0) {
                o->tonemap = DRIFT_TONEMAP_CLAMP;
            } else if (ok && strcmp(v, "reinhard") == 0) {
                o->tonemap = DRIFT_TONEMAP_REINHARD;
            } else if (ok) {
                fprintf(stderr, "drift render: --tonemap expects clamp or reinhard, got '%s'\n", v);
                ok = false;
            }
        } else if (strcmp(a, "--debug-sample") == 0) {
            ok = VALUE() != NULL;
            if (ok && sscanf(v, "%ld,%ld,%ld", &o->debug_x, &o->debug_y, &o->debug_sample) != 3) {
                fprintf(stderr, "drift render: --debug-sample expects X,Y,S, got '%s'\n", v);
                ok = false;
            }
        } else if (strcmp(a, "--aov") == 0) {
            o->aov = true;
            // An optional value: a following argument that names an .exr file.
            const char *next = i + 1 < argc ? argv[i + 1] : NULL;
            size_t next_len = next ? strlen(next) : 0;
            if (next && next[0] != '-' && next_len > 4 && strcmp(next + next_len - 4, ".exr") == 0) {
                o->aov_path = next;
                ++i;
            }
        } else if (render_parse_hybrid_option(argc, argv, &i, o, &ok)) {
            // handled: a hybrid-mode option
        } else if (strcmp(a, "--quiet") == 0) {
            o->quiet = true;
        } else if (strcmp(a, "--verbose") == 0) {
            o->verbose = true;
        } else if (a[0] == '-' && a[1] != '\0') {
            fprintf(stderr, "drift render: unknown option '%s' (see drift render --help)\n", a);
            ok = false;
        } else if (!o->scene_path) {
            o->scene_path = a;
        } else {
            fprintf(stderr, "drift render: more than one scene given ('%s', '%s')\n",
                    o->scene_path, a);
            ok = false;
        }
#undef VALUE
        if (!ok) {
            return 2;
        }
    }
    if (strcmp(o->mode, "reference") != 0 && strcmp(o->mode, "hybrid") != 0) {
        fprintf(stderr, "drift render: unknown --mode '%s' (modes: reference, hybrid)\n", o->mode);
        return 2;
    }
    bool hybrid = strcmp(o->mode, "hybrid") == 0;
    if (!hybrid && o->hybrid_option) {
        fprintf(stderr, "drift render: %s needs --mode hybrid\n", o->hybrid_option);
        return 2;
    }
    if (!hybrid && o->aov_path) {
        fprintf(stderr, "drift render: --aov FILE needs --mode hybrid (reference mode: --aov "
                        "adds layers to --out)\n");
        return 2;
    }
    size_t len = strlen(o->out_path);
    if (len < 5 || strcmp(o->out_path + len - 4, ".exr") != 0) {
        fprintf(stderr, "drift render: --out must name a .exr file, got '%s'\n", o->out_path);
        return 2;
    }
    return 0;
}

// FILE.exr -> FILE.png
void render_png_path(const char *exr_path, char *out, size_t size)
{
    snprintf(out, size, "%.*s.png", (int)(strlen(exr_path) - 4), exr_path);
}

static drift_result write_images(drift_context *ctx, drift_pt *pt, const render_options *o)
{
    drift_image beauty, albedo, normal, depth;
    drift_result r = drift_pt_resolve(pt, DRIFT_PT_AOV_BEAUTY, &beauty);
    if (r != DRIFT_OK) {
        return r;
    }
    drift_image_layer layers[4] = { { NULL, &beauty } };
    uint32_t layer_count = 1;
    if (o->aov) {
        if ((r = drift_pt_resolve(pt, DRIFT_PT_AOV_ALBEDO, &albedo)) != DRIFT_OK ||
            (r = drift_pt_resolve(pt, DRIFT_PT_AOV_NORMAL, &normal)) != DRIFT_OK ||
            (r = drift_pt_resolve(pt, DRIFT_PT_AOV_DEPTH, &depth)) != DRIFT_OK) {
            return r;
        }
        layers[1] = (drift_image_layer){ "albedo", &albedo };
        layers[2] = (drift_image_layer){ "normal", &normal };
        layers[3] = (drift_image_layer){ "depth", &depth };
        layer_count = 4;
    }
    r = drift_image_save_exr(ctx, o->out_path, layers, layer_count);
    if (r != DRIFT_OK) {
        return r;
    }
    char png[4096];
    render_png_path(o->out_path, png, sizeof(png));
    return drift_image_save_png(
        ctx, png, &beauty,
        &(drift_tonemap_params){ .exposure_stops = (float)o->exposure, .op = o->tonemap });
}

static drift_result write_stats(const render_options *o, const drift_pt *pt, double ms_load,
                                double ms_accel, double ms_render, double ms_write, double ms_total,
                                int threads)
{
    char tmp[4096];
    snprintf(tmp, sizeof(tmp), "%s.tmp%ld", o->stats_path, (long)getpid());
    FILE *f = fopen(tmp, "w");
    if (!f) {
        fprintf(stderr, "drift render: cannot write %s\n", o->stats_path);
        return DRIFT_ERR_IO;
    }
    drift_pt_stats s = drift_pt_get_stats(pt);
    drift_pt_params p = drift_pt_get_params(pt);
    fprintf(f,
            "{\n  \"scene\": \"%s\",\n  \"mode\": \"reference\",\n  \"width\": %d,\n"
            "  \"height\": %d,\n  \"spp\": %u,\n  \"seed\": %u,\n  \"max_depth\": %d,\n"
            "  \"threads\": %d,\n  \"nan_samples\": %llu,\n"
            "  \"rays\": { \"camera\": %llu, \"shadow\": %llu, \"bounce\": %llu, \"total\": %llu },\n"
            "  \"milliseconds\": { \"load\": %.3f, \"accel\": %.3f, \"render\": %.3f, "
            "\"write\": %.3f, \"total\": %.3f }\n}\n",
            o->scene_path ? o->scene_path : "(built-in cornell box)", p.width, p.height,
            drift_pt_sample_count(pt), p.seed, p.max_depth, threads,
            (unsigned long long)s.nan_samples, (unsigned long long)s.camera_rays,
            (unsigned long long)s.shadow_rays, (unsigned long long)s.bounce_rays,
            (unsigned long long)(s.camera_rays + s.shadow_rays + s.bounce_rays), ms_load,
            ms_accel, ms_render, ms_write, ms_total);
    bool ok = fclose(f) == 0;
    if (!ok || rename(tmp, o->stats_path) != 0) {
        remove(tmp);
        fprintf(stderr, "drift render: cannot write %s\n", o->stats_path);
        return DRIFT_ERR_IO;
    }
    return DRIFT_OK;
}

static void print_progress(bool tty, uint32_t done, uint32_t total, double elapsed, bool final)
{
    double fraction = total ? (double)done / (double)total : 1.0;
    double eta = fraction > 0.0 ? elapsed * (1.0 - fraction) / fraction : 0.0;
    if (tty) {
        char bar[41];
        int filled = (int)(fraction * 40.0);
        for (int i = 0; i < 40; ++i) {
            bar[i] = i < filled ? '#' : '.';
        }
        bar[40] = '\0';
        fprintf(stderr, "\r[%s] %5.1f%%  %u/%u spp  %.1fs elapsed  ETA %.1fs ", bar,
                100.0 * fraction, done, total, elapsed, eta);
        if (final) {
            fputc('\n', stderr);
        }
    } else {
        fprintf(stderr, "drift render: %u/%u spp (%.0f%%), %.1fs elapsed, ETA %.1fs\n", done, total,
                100.0 * fraction, elapsed, eta);
    }
    fflush(stderr);
}

int drift_cmd_render(int argc, char **argv)
{
    render_options o;
    int status = parse_options(argc, argv, &o);
    if (status != 0) {
        return status < 0 ? 0 : status;
    }
    if (strcmp(o.mode, "hybrid") == 0) {
        return render_hybrid(&o);
    }
    double t_start = drift_time_now();
    drift_context *ctx = cli_open_context("render", (int)o.threads, o.verbose);
    if (!ctx) {
        return 1;
    }
    drift_result r = DRIFT_OK;
    const char *scene_path = o.scene_path ? o.scene_path : cli_default_scene_path();
    drift_scene *scene = NULL;
    drift_accel *accel = NULL;
    drift_pt *pt = NULL;
    int exit_code = 1;

    double t_loaded = 0.0;
    if (!cli_open_scene(ctx, "render", scene_path, &scene, &accel, &t_loaded)) {
        goto done;
    }
    double t_accel = drift_time_now();
    drift_pt_params params = { .width = (int32_t)o.width,
                               .height = (int32_t)o.height,
                               .seed = (uint32_t)o.seed,
                               .max_depth = (int32_t)o.max_depth };
    r = drift_pt_create(ctx, scene, accel, &params, &pt);
    if (r != DRIFT_OK) {
        fprintf(stderr, "drift render: %s\n", drift_result_string(r));
        goto done;
    }
    params = drift_pt_get_params(pt);

    if (o.debug_sample >= 0) {
        if (o.debug_x >= params.width || o.debug_y >= params.height || o.debug_x < 0 ||
            o.debug_y < 0) {
            fprintf(stderr, "drift render: --debug-sample pixel outside the %dx%d image\n",
                    params.width, params.height);
            exit_code = 2;
            goto done;
        }
        drift_vec3 L = drift_pt_trace_sample(pt, (int32_t)o.debug_x, (int32_t)o.debug_y,
                                             (uint32_t)o.debug_sample);
        printf("pixel (%ld, %ld) sample %ld seed %ld: radiance %.9g %.9g %.9g\n", o.debug_x,
               o.debug_y, o.debug_sample, o.seed, (double)L.x, (double)L.y, (double)L.z);
        exit_code = 0;
        goto done;
    }

    // Passes grow until one takes about a second: responsive progress, checkpoints and
    // Ctrl-C, without per-pass overhead dominating small images.
    render_catch_sigint();
    bool tty = isatty(STDERR_FILENO) != 0;
    uint32_t total = (uint32_t)o.spp, done_spp = 0, pass = 1;
    double t_render = drift_time_now(), last_checkpoint = t_render, last_report = 0.0;
    if (!o.quiet) {
        fprintf(stderr, "drift render: %s, %dx%d, %u spp, depth %d, %d threads\n", scene_path,
                params.width, params.height, total, params.max_depth,
                drift_context_thread_count(ctx));
    }
    while (done_spp < total) {
        uint32_t count = pass < total - done_spp ? pass : total - done_spp;
        double t0 = drift_time_now();
        r = drift_pt_render_samples(pt, count, &interrupted);
        double dt = drift_time_now() - t0;
        if (r == DRIFT_ERR_CANCELLED) {
            break;
        }
        done_spp += count;
        if (dt < 0.5 && pass < (1u << 20)) {
            pass *= 2;
        }
        double now = drift_time_now();
        if (!o.quiet && (tty || now - last_report > 5.0 || done_spp == total)) {
            print_progress(tty, done_spp, total, now - t_render, done_spp == total);
            last_report = now;
        }
        if (o.checkpoint_seconds > 0.0 && now - last_checkpoint > o.checkpoint_seconds &&
            done_spp < total) {
            if (write_images(ctx, pt, &o) == DRIFT_OK && !o.quiet) {
                fprintf(stderr, "%sdrift render: checkpoint at %u spp written to %s\n",
                        tty ? "\n" : "", done_spp, o.out_path);
            }
            last_checkpoint = now;
        }
    }
    double t_rendered = drift_time_now();
    bool cancelled = atomic_load(&interrupted);
    if (cancelled) {
        fprintf(stderr, "%sdrift render: interrupted at %u spp; writing what was rendered\n",
                tty ? "\n" : "", drift_pt_sample_count(pt));
    }
    r = write_images(ctx, pt, &o);
    if (r != DRIFT_OK) {
        fprintf(stderr, "drift render: cannot write %s: %s\n", o.out_path, drift_result_string(r));
        goto done;
    }
    double t_written = drift_time_now();
    if (o.stats_path &&
        write_stats(&o, pt, 1e3 * (t_loaded - t_start), 1e3 * (t_accel - t_loaded),
                    1e3 * (t_rendered - t_render), 1e3 * (t_written - t_rendered),
                    1e3 * (t_written - t_start), drift_context_thread_count(ctx)) != DRIFT_OK) {
        goto done;
    }
    drift_pt_stats stats = drift_pt_get_stats(pt);
    if (stats.nan_samples > 0) {
        fprintf(stderr, "drift render: warning: %llu samples were not finite and were dropped\n",
                (unsigned long long)stats.nan_samples);
    }
    char png[4096];
    render_png_path(o.out_path, png, sizeof(png));
    printf("wrote %s and %s (%u spp, %dx%d) in %.2f s (render %.2f s)\n", o.out_path, png,
           drift_pt_sample_count(pt), params.width, params.height, t_written - t_start,
           t_rendered - t_render);
    exit_code = cancelled ? 130 : 0;

done:
    drift_pt_destroy(pt);
    drift_accel_destroy(accel);
    drift_scene_destroy(scene);
    drift_context_destroy(ctx);
    return exit_code;
}
