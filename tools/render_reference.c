// drift render's reference-run steps (begin, checkpoint, finish) and their --stats and
// progress line; tools/cmd_render.c and tools/distributed drive them.
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

static cJSON *reference_stats(const render_reference_run *run, double t_rendered, double t_written)
{
    const render_options *o = run->o;
    const cli_session *session = run->session;
    const drift_pt *pt = run->pt;
    drift_pt_stats s = drift_pt_get_stats(pt);
    drift_pt_params p = drift_pt_get_params(pt);
    cJSON *root = render_stats_begin(o, session, "reference", p.width, p.height);
    uint32_t lowest, highest;
    render_spp_range(pt, &lowest, &highest);
    cli_json_count(root, "spp", lowest);
    if (lowest != highest) { // interrupted: say each tile's count
        cli_json_count(root, "spp_max", highest);
        cJSON_AddNumberToObject(root, "tile_size", DRIFT_PT_TILE_SIZE);
        cJSON *tiles = cJSON_AddArrayToObject(root, "tile_spp");
        for (uint32_t t = 0; t < drift_pt_tile_count(pt); ++t) {
            cJSON_AddItemToArray(tiles, cJSON_CreateNumber(drift_pt_tile_sample_count(pt, t)));
        }
    }
    cli_json_count(root, "resumed_from_spp", run->resumed_spp);
    cli_json_count(root, "seed", p.seed);
    cJSON_AddNumberToObject(root, "max_depth", p.max_depth);
    cJSON_AddNumberToObject(root, "threads", drift_context_thread_count(session->ctx));
    if (run->ranks > 0) {
        cJSON_AddNumberToObject(root, "ranks", run->ranks);
    }
    cli_json_count(root, "nan_samples", s.nan_samples);
    cJSON *rays = cJSON_AddObjectToObject(root, "rays");
    cli_json_count(rays, "camera", s.camera_rays);
    cli_json_count(rays, "shadow", s.shadow_rays);
    cli_json_count(rays, "bounce", s.bounce_rays);
    cli_json_count(rays, "total", s.camera_rays + s.shadow_rays + s.bounce_rays);
    cJSON *ms = cJSON_AddObjectToObject(root, "milliseconds");
    cli_json_number(ms, "load", 1e3 * (session->t_loaded - session->t_start), 3);
    cli_json_number(ms, "accel", 1e3 * (session->t_built - session->t_loaded), 3);
    cli_json_number(ms, "render", 1e3 * (t_rendered - run->t_render), 3);
    cli_json_number(ms, "write", 1e3 * (t_written - t_rendered), 3);
    if (run->o->denoise) {
        // The filter runs as the image is written: part of "write", what a denoised frame adds
        // to "render".
        cli_json_number(ms, "denoise", run->denoise_ms, 3);
    }
    cli_json_number(ms, "total", 1e3 * (t_written - session->t_start), 3);
    if (run->cpu_render > 0.0 && run->cpu_rendered >= run->cpu_render) {
        cJSON *cpu = cJSON_AddObjectToObject(root, "cpu_milliseconds");
        cli_json_number(cpu, "render", 1e3 * (run->cpu_rendered - run->cpu_render), 3);
    }
    return root;
}

cJSON *render_stats_begin(const render_options *o, const cli_session *session, const char *mode,
                          int width, int height)
{
    cJSON *root = cJSON_CreateObject();
    (void)o;
    cJSON_AddStringToObject(root, "scene", session->scene_path);
    cJSON_AddStringToObject(root, "mode", mode);
    cJSON_AddNumberToObject(root, "width", width);
    cJSON_AddNumberToObject(root, "height", height);
    return root;
}

void render_progress(bool tty, uint32_t first, uint32_t done, uint32_t total, double elapsed,
                     bool final)
{
    double fraction = total ? (double)done / (double)total : 1.0;
    double run = total > first ? (double)(done - first) / (double)(total - first) : 1.0;
    double eta = run > 0.0 ? elapsed * (1.0 - run) / run : 0.0;
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

int render_reference_begin(render_reference_run *run)
{
    const render_options *o = run->o;
    const cli_session *session = run->session;
    drift_pt_params params = { .width = (int32_t)o->width,
                               .height = (int32_t)o->height,
                               .seed = (uint32_t)o->seed,
                               .max_depth = (int32_t)o->max_depth,
                               .reflection_edits = o->hybrid.reflection_edits,
                               .texture_filter_spp = (uint32_t)o->spp };
    drift_result r =
        drift_pt_create(session->ctx, session->scene, session->accel, &params, &run->pt);
    if (r != DRIFT_OK) {
        fprintf(stderr, "drift render: %s\n", drift_result_string(r));
        return 1;
    }
    render_checkpoint_path(o->out_path, run->checkpoint_path, sizeof run->checkpoint_path);
    if (o->debug_sample >= 0) {
        return 0;
    }
    if (!render_checkpoint_key(session, run->pt, run->o->edits_path, run->key, sizeof run->key)) {
        return 1;
    }
    // --resume FILE, or the checkpoint beside --out when there is one.
    const char *resume = o->resume_path;
    if (!resume && access(run->checkpoint_path, F_OK) == 0) {
        resume = run->checkpoint_path;
    }
    if (resume) {
        int status = render_checkpoint_read(resume, run->key, run->pt, (uint32_t)o->spp);
        if (status != 0) {
            return status;
        }
        uint32_t highest;
        render_spp_range(run->pt, &run->resumed_spp, &highest);
        if (!o->quiet) {
            fprintf(stderr, "drift render: resuming from %s (tiles at %u to %u spp)\n", resume,
                    run->resumed_spp, highest);
        }
    }
    return 0;
}

// --out, its PNG and --stats (final) or the first two (checkpoint), all or none.
static bool write_outputs(render_reference_run *run, bool final, double t_rendered)
{
    const render_options *o = run->o;
    char png[4096];
    render_png_path(o->out_path, png, sizeof png);
    render_stage stage = { 0 };
    const char *exr_temp = render_stage_add(&stage, o->out_path);
    const char *png_temp = render_stage_add(&stage, png);
    drift_result r =
        render_write_images(run->session->ctx, run->pt, o, run->session->scene->camera.fov_y,
                            exr_temp, png_temp, &run->denoise_ms);
    if (r != DRIFT_OK) {
        fprintf(stderr, "drift render: cannot write %s: %s; nothing written\n", o->out_path,
                drift_result_string(r));
        render_stage_abort(&stage);
        return false;
    }
    if (final && o->stats_path) {
        const char *stats_temp = render_stage_add(&stage, o->stats_path);
        if (!cli_json_write("render", reference_stats(run, t_rendered, drift_time_now()),
                            stats_temp)) {
            fprintf(stderr, "drift render: nothing written\n");
            render_stage_abort(&stage);
            return false;
        }
    }
    return render_stage_commit(&stage);
}

bool render_reference_checkpoint(render_reference_run *run)
{
    bool ok = render_checkpoint_write(run->checkpoint_path, run->key, run->pt);
    return write_outputs(run, false, 0.0) && ok;
}

int render_reference_finish(render_reference_run *run, bool cancelled, double t_rendered)
{
    const render_options *o = run->o;
    run->cpu_rendered = render_cpu_now();
    bool tty = isatty(STDERR_FILENO) != 0;
    uint32_t lowest, highest;
    render_spp_range(run->pt, &lowest, &highest);
    // The samples it set out to take: --spp, or, filling a budget, those the budget held.
    uint32_t target = run->target_spp ? run->target_spp : (uint32_t)o->spp;
    bool complete = lowest >= target;
    if (!complete) {
        bool saved = render_checkpoint_write(run->checkpoint_path, run->key, run->pt);
        fprintf(stderr, "%sdrift render: %s at %u spp%s; writing what was rendered%s%s%s\n",
                tty && !o->quiet ? "\n" : "", cancelled ? "interrupted" : "stopped", lowest,
                lowest != highest ? " (tiles hold different counts, up to the most; the EXR's "
                                    "spp layer has each pixel's)"
                                  : "",
                saved ? "; run the same command to resume from " : "",
                saved ? run->checkpoint_path : "", saved ? "" : "");
    }
    if (!write_outputs(run, true, t_rendered)) {
        // Keep the work (a full disk): the checkpoint a resumed or stopped run has, else one
        // written now; the same command writes the images from it once there is room.
        bool kept = access(run->checkpoint_path, F_OK) == 0 ||
                    render_checkpoint_write(run->checkpoint_path, run->key, run->pt);
        if (kept) {
            fprintf(stderr,
                    "drift render: the render is kept in %s; run the same command to "
                    "write it\n",
                    run->checkpoint_path);
        }
        return 1;
    }
    if (complete && access(run->checkpoint_path, F_OK) == 0 && unlink(run->checkpoint_path) != 0) {
        fprintf(stderr, "drift render: warning: cannot remove the finished checkpoint %s\n",
                run->checkpoint_path);
    }
    drift_pt_stats stats = drift_pt_get_stats(run->pt);
    if (stats.nan_samples > 0) {
        fprintf(stderr, "drift render: warning: %llu samples were not finite and were dropped\n",
                (unsigned long long)stats.nan_samples);
    }
    char png[4096];
    render_png_path(o->out_path, png, sizeof png);
    drift_pt_params params = drift_pt_get_params(run->pt);
    char spp[64];
    snprintf(spp, sizeof spp, lowest == highest ? "%u spp" : "%u..%u spp", lowest, highest);
    char size[96]; // the chooser's reduced-resolution pick is written upsampled
    if (o->upsample_width > 0 && o->upsample_height > 0) {
        snprintf(size, sizeof size, "rendered %dx%d, written %ldx%ld", params.width, params.height,
                 o->upsample_width, o->upsample_height);
    } else {
        snprintf(size, sizeof size, "%dx%d", params.width, params.height);
    }
    printf("wrote %s and %s (%s, %s) in %.2f s (render %.2f s)\n", o->out_path, png, spp, size,
           drift_time_now() - run->session->t_start, t_rendered - run->t_render);
    return cancelled ? render_interrupt_status() : complete ? 0 : 1;
}
