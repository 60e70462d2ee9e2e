// drift report: one HTML page that shows every technique against the truth (docs/report.md).
//
// For each scene and effect it renders the effect's path-traced reference (the technique
// table's `reference` row at --ref-spp) and every other technique of the effect as hybrid
// frames, the path-traced ones (AAF, and `reference` itself: the path tracer's convergence)
// swept over 1, 2, 4, ... --sweep-spp samples; compares each with the reference through
// drift diff's function (cli_compare_images), and writes DIR/index.html, a page built from
// tools/report/page.html with the data as JSON, beside the images (EXR, PNGs at several
// exposures, FLIP heat maps). Renders are cached in DIR/manifest.json keyed by the scene's
// content, the frame's parameters and drift's version, so a rerun renders only what is
// missing and Ctrl-C keeps what is finished. The `sir` cell is the whole frame refined by
// smart image refinement, against drift bench frontier's whole-frame path-traced truth.
#include "cli.h"
#include "drift/file.h"
#include "drift/image_io.h"
#include "drift/metric.h"
#include "drift/refine.h"
#include "drift/scene.h"
#include "render.h"
#include "report_files.h"

#include <errno.h>
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/utsname.h>
#include <time.h>
#include <unistd.h>

#define REPORT_MAX_SCENES 16
#define REPORT_EXPOSURES  3
#define REPORT_VERSION    DRIFT_VERSION " " DRIFT_COMMIT
#define REPORT_MAX_SIR    8
#define REPORT_SIR_NAME   "sir" // --effects name of the whole-frame SIR cell

extern const char drift_report_page[]; // tools/report/page.html (cmake/embed_text.cmake)

static const int exposure_stops[REPORT_EXPOSURES] = { -2, 0, 2 };

// TERM effects fill a term of the frame; POST effects (depth of field, glare) transform it.
enum {
    REPORT_TERM,
    REPORT_POST
};

#define REPORT_KIND_(ENUM, name, type, TECHNIQUES, kind, plane) \
    [DRIFT_EFFECT_##ENUM] = REPORT_##kind,
static const int effect_kind[DRIFT_EFFECT_COUNT] = { DRIFT_EFFECTS(REPORT_KIND_) };
#undef REPORT_KIND_

typedef struct report_options {
    const char *scenes[REPORT_MAX_SCENES];
    const char *out_dir;
    bool effects[DRIFT_EFFECT_COUNT];
    bool effects_given, sir;
    long sir_iterations[REPORT_MAX_SIR];
    int sir_iteration_count;
    long size, ref_spp, sweep_spp, sir_budget, threads;
    double time_budget; // seconds; 0: none
    bool verbose;
} report_options;

static bool parse_effects(const char *cmd, const char *flag, const char *value, void *field)
{
    report_options *o = field;
    memset(o->effects, 0, sizeof o->effects);
    o->effects_given = true;
    o->sir = false;
    const char *p = value;
    while (*p) {
        size_t n = strcspn(p, ",");
        int found = -1;
        for (int e = 0; e < DRIFT_EFFECT_COUNT; ++e) {
            const char *name = drift_effect_name((drift_effect)e);
            if (strlen(name) == n && strncmp(name, p, n) == 0) {
                found = e;
            }
        }
        bool sir = strlen(REPORT_SIR_NAME) == n && strncmp(REPORT_SIR_NAME, p, n) == 0;
        if (found < 0 && !sir) {
            fprintf(stderr, "drift %s: %s expects effects from", cmd, flag);
            for (int e = 0; e < DRIFT_EFFECT_COUNT; ++e) {
                fprintf(stderr, "%s%s", e ? ", " : " ", drift_effect_name((drift_effect)e));
            }
            fprintf(stderr, ", " REPORT_SIR_NAME " separated by commas, got '%s'\n", value);
            return false;
        }
        if (sir) {
            o->sir = true;
        } else {
            o->effects[found] = true;
        }
        p += n + (p[n] == ',');
    }
    return true;
}

static bool parse_sir_iterations(const char *cmd, const char *flag, const char *value, void *field)
{
    report_options *o = field;
    if (!cli_parse_list(cmd, flag, value, 1, 1 << 20, REPORT_MAX_SIR, o->sir_iterations,
                        &o->sir_iteration_count)) {
        return false;
    }
    for (int i = 1; i < o->sir_iteration_count; ++i) { // ascending: one refinement gives all
        for (int k = i; k > 0 && o->sir_iterations[k - 1] > o->sir_iterations[k]; --k) {
            long t = o->sir_iterations[k];
            o->sir_iterations[k] = o->sir_iterations[k - 1];
            o->sir_iterations[k - 1] = t;
        }
    }
    return true;
}

#define O report_options
static const cli_option report_table[] = {
    CLI_SECTION("options:", 0),
    CLI_STRING("--out", "DIR", O, out_dir,
               "the report's folder: index.html, images, cache (required)"),
    CLI_CUSTOM_ALL(
        "--effects", "LIST", parse_effects,
        "effects to show, e.g. shadows,dof; " REPORT_SIR_NAME ": the whole frame refined by\n"
        "SIR (default: every effect with a path-traced reference, and " REPORT_SIR_NAME ")"),
    CLI_INT("--size", "N", O, size, 8, 4096,
            "frame width in pixels; the height follows the camera (default 256)"),
    CLI_INT("--ref-spp", "N", O, ref_spp, 1, 4096,
            "samples a pixel of the references (default 256)"),
    CLI_INT("--sweep-spp", "N", O, sweep_spp, 1, 1 << 16,
            "path-traced techniques at 1, 2, 4, ... N spp (default 16)"),
    CLI_CUSTOM_ALL("--sir-iterations", "LIST", parse_sir_iterations,
                   "the " REPORT_SIR_NAME " cell refines for these iterations (default 1,2,4,8)"),
    CLI_INT("--sir-budget", "N", O, sir_budget, 0, 1L << 30,
            "samples a SIR iteration (default 0: one a pixel)"),
    CLI_NUMBER("--time-budget", "S", O, time_budget, 0.0, 1e9,
               "start no render after S seconds (0: no limit); a rerun goes on"),
    CLI_INT("--threads", "T", O, threads, 0, 256, "worker threads (default: one a core)"),
    CLI_FLAG("-v, --verbose", O, verbose, "more log output"),
};
#undef O

static const cli_command report_command = {
    .name = "report",
    .usage = "usage: drift report [SCENE...] --out DIR [options]\n\n"
             "Renders, for each scene and effect, every technique drift has for it and the\n"
             "effect's path-traced reference, and writes DIR/index.html: image sliders with\n"
             "FLIP heat maps, a sortable table of ms, rays, FLIP, RMSE, SSIM, an\n"
             "error-versus-time plot with its Pareto front, and the scene's facts. Renders\n"
             "are cached in DIR; a rerun renders only what is missing. SCENE defaults to\n"
             "the built-in Cornell box. docs/report.md describes the page.\n\n",
    .epilogue = "\nexit status: 0 every cell rendered, 1 a scene or reference failed (its cell\n"
                "says why) or --time-budget ran out, 2 usage error, 130 interrupted\n",
    CLI_TABLE(report_table),
    CLI_POSITIONAL("SCENE", report_options, scenes, REPORT_MAX_SCENES),
    .help_column = 19,
};

// --- hashing: the cache key ---

// The scene's content: every file its load read (the scene file first), byte for byte.
static uint64_t scene_hash(const cli_session *s)
{
    uint64_t h = 0; // a file that vanished after the load: the key still differs from a good run's
    cli_hash_files((const char *const *)s->scene_inputs, s->scene_input_count, &h);
    return h;
}

// --- the run ---

typedef struct report_run {
    const report_options *o;
    drift_context *ctx;
    cJSON *renders; // the manifest's renders: key -> { file, ms, frame_ms, rays }
    char manifest_path[4096];
    const atomic_bool *cancel;
    double t_start, render_seconds, units_done, units_total;
    int jobs_done, jobs_total;
    bool interrupted, budget_spent, failed;
} report_run;

// One frame to render: an effect's technique at some spp, with the frame's parameters.
typedef struct report_job {
    drift_effect effect;
    int technique;
    uint32_t spp;
    bool truth; // the effect's reference at --ref-spp
    drift_hybrid_params params;
} report_job;

static bool effect_has_reference(drift_effect e)
{
    return drift_technique_parse(e, "reference") >= 0;
}

static bool frame_path_traced(const drift_hybrid_params *p)
{
    for (int e = 0; e < DRIFT_EFFECT_COUNT; ++e) {
        if (drift_technique_path_traced((drift_effect)e, p->techniques[e])) {
            return true;
        }
    }
    return false;
}

// The work of a job, for the ETA: samples a pixel when it path-traces, else one.
static double job_units(const report_job *j)
{
    return frame_path_traced(&j->params) ? (double)j->params.spp : 1.0;
}

// The frame of `effect` at `technique`: every other effect at its first row (hard shadows,
// nothing else), except that a POST effect (depth of field) sees every term path-traced,
// the light its reference takes through the lens, so that its error is its own
// (docs/hybrid.md).
static report_job make_job(const report_options *o, const drift_scene *scene, drift_effect effect,
                           int technique, uint32_t spp, bool truth)
{
    report_job j = { .effect = effect };
    j.technique = technique;
    j.truth = truth;
    j.params.width = (int32_t)o->size;
    int32_t cw = scene ? scene->camera.width : 1, ch = scene ? scene->camera.height : 1;
    j.params.height = cw > 0 && ch > 0 ? (int32_t)((o->size * ch + cw / 2) / cw) : j.params.width;
    if (j.params.height < 1) {
        j.params.height = 1;
    }
    j.params.techniques[effect] = technique;
    for (int e = 0; e < DRIFT_EFFECT_COUNT && effect_kind[effect] == REPORT_POST; ++e) {
        int reference = drift_technique_parse((drift_effect)e, "reference");
        if (effect_kind[e] == REPORT_TERM && reference >= 0) {
            j.params.techniques[e] = reference;
        }
    }
    bool pt = frame_path_traced(&j.params);
    j.spp = pt ? spp : 1;
    j.params.spp = j.spp;
    return j;
}

// The jobs of one effect: its reference first, then each technique in table order, the
// path-traced ones at 1, 2, 4, ... --sweep-spp (below --ref-spp for `reference`).
static int plan_effect(const report_options *o, const drift_scene *scene, drift_effect e,
                       report_job *jobs, int max)
{
    int n = 0, reference = drift_technique_parse(e, "reference");
    if (reference < 0) {
        return 0;
    }
    jobs[n++] = make_job(o, scene, e, reference, (uint32_t)o->ref_spp, true);
    for (int t = 0; t < drift_technique_count(e); ++t) {
        if (!drift_technique_path_traced(e, t)) {
            if (n < max) {
                jobs[n++] = make_job(o, scene, e, t, (uint32_t)o->ref_spp, false);
            }
            continue;
        }
        for (long spp = 1; spp <= o->sweep_spp && n < max; spp *= 2) {
            if (t == reference && spp >= o->ref_spp) {
                break;
            }
            jobs[n++] = make_job(o, scene, e, t, (uint32_t)spp, false);
        }
    }
    return n;
}

#define MAX_JOBS 256

// The key of a render: the scene's content, the effect it is for (its ms are that effect's),
// the frame's size, techniques and spp (all that make_job sets), the threads (its ms depend
// on them) and drift's version.
static void job_key(const report_job *j, uint64_t scene, int threads, char *out, size_t size)
{
    char text[512];
    int n = snprintf(text, sizeof text, "%016" PRIx64 " %s %dx%d %u spp %d threads", scene,
                     drift_effect_name(j->effect), j->params.width, j->params.height, j->params.spp,
                     threads);
    for (int e = 0; e < DRIFT_EFFECT_COUNT && n < (int)sizeof text; ++e) {
        n += snprintf(text + n, sizeof text - (size_t)n, " %s",
                      drift_technique_name((drift_effect)e, j->params.techniques[e]));
    }
    snprintf(out, size, "%016" PRIx64,
             cli_fnv1a(cli_fnv1a(CLI_FNV_BASIS, text, strlen(text)), REPORT_VERSION,
                       sizeof REPORT_VERSION));
}

// "shadows-pcss-1spp-0123abcd" under the scene's folder.
static void job_name(const report_job *j, const char *key, char *out, size_t size)
{
    snprintf(out, size, "%s-%s-%uspp-%.8s", drift_effect_name(j->effect),
             j->truth ? "truth" : drift_technique_name(j->effect, j->technique), j->spp, key);
}

static void format_seconds(double s, char *out, size_t size)
{
    long t = (long)(s + 0.5);
    if (t >= 3600) {
        snprintf(out, size, "%ld:%02ld:%02ld", t / 3600, t / 60 % 60, t % 60);
    } else {
        snprintf(out, size, "%ld:%02ld", t / 60, t % 60);
    }
}

static void eta_text(const report_run *run, char *eta, size_t size)
{
    snprintf(eta, size, "?");
    if (run->units_done > 0.0 && run->render_seconds > 0.0) {
        double left = run->units_total - run->units_done;
        format_seconds(left > 0.0 ? left * run->render_seconds / run->units_done : 0.0, eta, size);
    }
}

static void progress(report_run *run, const char *scene, const report_job *j, const char *what)
{
    char eta[32];
    eta_text(run, eta, sizeof eta);
    char spp[32] = "";
    if (frame_path_traced(&j->params)) {
        snprintf(spp, sizeof spp, " %u spp", j->spp);
    }
    fprintf(stderr, "drift report: [%d/%d] %s %s %s%s%s: %s, ETA %s\n", run->jobs_done,
            run->jobs_total, scene, drift_effect_name(j->effect),
            drift_technique_name(j->effect, j->technique), j->truth ? " (the truth)" : "", spp,
            what, eta);
}

static char *read_text(const char *path)
{
    char why[128];
    FILE *f = drift_input_fopen(path, why, sizeof why);
    if (!f) {
        return NULL;
    }
    char *text = NULL;
    if (fseek(f, 0, SEEK_END) == 0) {
        long n = ftell(f);
        if (n >= 0 && fseek(f, 0, SEEK_SET) == 0 && (text = malloc((size_t)n + 1))) {
            text[fread(text, 1, (size_t)n, f)] = '\0';
        }
    }
    fclose(f);
    return text;
}

static bool file_exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISREG(st.st_mode);
}

static bool make_dir(const char *path)
{
    return mkdir(path, 0777) == 0 || errno == EEXIST;
}

static bool write_manifest(report_run *run)
{
    cJSON *root = cJSON_CreateObject();
    cJSON_AddStringToObject(root, "drift", REPORT_VERSION);
    cJSON_AddItemToObject(root, "renders", cJSON_Duplicate(run->renders, true));
    return cli_json_write("report", root, run->manifest_path);
}

static drift_result save_pngs(drift_context *ctx, const char *base, const drift_image *image)
{
    drift_result r = DRIFT_OK;
    for (int k = 0; k < REPORT_EXPOSURES && r == DRIFT_OK; ++k) {
        char path[4200];
        snprintf(path, sizeof path, "%s.e%+d.png", base, exposure_stops[k]);
        r = drift_image_save_png(
            ctx, path, image,
            &(drift_tonemap_params){ .exposure_stops = (float)exposure_stops[k] });
    }
    return r;
}

// The job's cached render, or a fresh one; NULL with *why set when there is none.
static const cJSON *render_job(report_run *run, const cli_session *s, const char *scene_label,
                               const char *dir, uint64_t hash, const report_job *j,
                               const char **why)
{
    char key[32], name[256], base[4096], exr[4200];
    job_key(j, hash, drift_context_thread_count(run->ctx), key, sizeof key);
    job_name(j, key, name, sizeof name);
    snprintf(base, sizeof base, "%s/%s", dir, name);
    snprintf(exr, sizeof exr, "%s.exr", base);
    ++run->jobs_done;
    const cJSON *cached = cJSON_GetObjectItemCaseSensitive(run->renders, key);
    if (cached && file_exists(exr)) {
        run->units_total -= job_units(j);
        progress(run, scene_label, j, "cached");
        return cached;
    }
    if (run->interrupted || run->budget_spent) {
        *why = run->interrupted ? "not rendered: interrupted (rerun to finish)"
                                : "not rendered: --time-budget spent (rerun to go on)";
        return NULL;
    }
    drift_hybrid *frame = NULL;
    double t0 = drift_time_now();
    drift_result r = drift_hybrid_create(run->ctx, s->scene, s->accel, &j->params, &frame);
    r = r ? r : drift_hybrid_render(frame, &s->scene->camera, run->cancel);
    // A real-time technique's second frame reuses what it keeps (shadow maps, probes): the
    // interactive cost. Path-traced frames cost the same every time.
    if (r == DRIFT_OK && !frame_path_traced(&j->params)) {
        r = drift_hybrid_render(frame, &s->scene->camera, run->cancel);
    }
    drift_image_layer layer = { NULL, frame ? drift_hybrid_image(frame) : NULL };
    if (r == DRIFT_OK) {
        r = drift_image_save_exr(run->ctx, exr, &layer, 1);
        r = r ? r : save_pngs(run->ctx, base, layer.image);
    }
    const cJSON *entry = NULL;
    if (r == DRIFT_OK) {
        drift_hybrid_stats st = drift_hybrid_get_stats(frame);
        uint64_t rays = 0;
        for (int k = 0; k < DRIFT_PASS_COUNT; ++k) {
            rays += st.rays[k];
        }
        cJSON *item = cJSON_CreateObject();
        cJSON_AddStringToObject(item, "file", name);
        cli_json_number(item, "ms", st.effect_ms[j->effect], 3);
        cli_json_number(item, "frame_ms", st.frame_ms, 3);
        cli_json_count(item, "rays", rays);
        cJSON_DeleteItemFromObjectCaseSensitive(run->renders, key);
        cJSON_AddItemToObject(run->renders, key, item);
        entry = item;
        run->render_seconds += drift_time_now() - t0;
        run->units_done += job_units(j);
        char took[64];
        snprintf(took, sizeof took, "%.2f s", drift_time_now() - t0);
        progress(run, scene_label, j, took);
        if (!write_manifest(run)) {
            r = DRIFT_ERR_IO;
        }
        if (run->o->time_budget > 0.0 && drift_time_now() - run->t_start > run->o->time_budget) {
            run->budget_spent = true;
            fprintf(stderr, "drift report: --time-budget %g s spent; a rerun goes on from here\n",
                    run->o->time_budget);
        }
    } else if (r == DRIFT_ERR_CANCELLED) {
        run->interrupted = true;
        fprintf(stderr, "drift report: interrupted; writing the page with what is finished\n");
        *why = "not rendered: interrupted (rerun to finish)";
    }
    if (r != DRIFT_OK && r != DRIFT_ERR_CANCELLED) {
        fprintf(stderr, "drift report: %s %s %s: %s\n", scene_label, drift_effect_name(j->effect),
                drift_technique_name(j->effect, j->technique), drift_result_string(r));
        *why = "render failed (see the log)";
    }
    drift_hybrid_destroy(frame);
    return r == DRIFT_OK ? entry : NULL;
}

// Loads an image of the report (NAME.exr in dir).
static drift_result load_render(report_run *run, const char *dir, const char *name,
                                drift_image *out)
{
    char path[4200];
    snprintf(path, sizeof path, "%.3800s/%.256s.exr", dir, name);
    return drift_image_load(run->ctx, path, out);
}

// The row's numbers against the truth, read back from the files as drift diff reads them,
// and the FLIP heat map beside the image.
static drift_result add_metrics(report_run *run, const char *dir, const char *truth,
                                const char *name, cJSON *row)
{
    drift_image ref = { 0 }, test = { 0 }, flip_map = { 0 }, heat = { 0 };
    drift_metric_report rep = { 0 };
    size_t nonfinite = 0;
    drift_result r = load_render(run, dir, truth, &ref);
    r = r ? r : load_render(run, dir, name, &test);
    r = r ? r : cli_compare_images(run->ctx, &ref, &test, 0.0, &rep, &flip_map, &nonfinite);
    char path[4200];
    snprintf(path, sizeof path, "%.3800s/%.256s.flip.png", dir, name);
    if (r == DRIFT_OK && !file_exists(path)) {
        r = drift_metric_flip_heatmap(run->ctx, &flip_map, &heat);
        r = r ? r : drift_image_save_png(run->ctx, path, &heat, NULL);
    }
    if (r == DRIFT_OK) {
        const char *const keys[6] = { "mse", "rmse", "relmse", "psnr", "ssim", "flip" };
        const double values[6] = { rep.mse, rep.rmse, rep.relmse, rep.psnr, rep.ssim, rep.flip };
        for (int k = 0; k < 6; ++k) {
            cli_json_number(row, keys[k], values[k], -1);
        }
        cli_json_count(row, "nonfinite", nonfinite);
    }
    drift_image_destroy(run->ctx, &heat);
    drift_image_destroy(run->ctx, &flip_map);
    drift_image_destroy(run->ctx, &test);
    drift_image_destroy(run->ctx, &ref);
    return r;
}

static void copy_render(cJSON *row, const cJSON *entry, const char *slug)
{
    const cJSON *file = cJSON_GetObjectItemCaseSensitive(entry, "file");
    char image[600];
    snprintf(image, sizeof image, "%s/%s", slug, cJSON_GetStringValue(file));
    cJSON_AddStringToObject(row, "image", image);
    const char *const keys[3] = { "ms", "frame_ms", "rays" };
    for (int k = 0; k < 3; ++k) {
        const cJSON *v = cJSON_GetObjectItemCaseSensitive(entry, keys[k]);
        cJSON_AddNumberToObject(row, keys[k], cJSON_IsNumber(v) ? v->valuedouble : 0.0);
    }
}

// One effect's section of the page: its reference and every technique's row.
static cJSON *report_effect(report_run *run, const cli_session *s, const char *label,
                            const char *slug, const char *dir, uint64_t hash, drift_effect e)
{
    cJSON *out = cJSON_CreateObject();
    cJSON_AddStringToObject(out, "effect", drift_effect_name(e));
    cJSON *rows = cJSON_AddArrayToObject(out, "rows");
    if (!effect_has_reference(e)) {
        char why[160];
        snprintf(why, sizeof why, "%s has no path-traced reference: nothing to compare with",
                 drift_effect_name(e));
        cJSON_AddStringToObject(out, "error", why);
        fprintf(stderr, "drift report: %s: %s\n", label, why);
        run->failed = true;
        return out;
    }
    report_job jobs[MAX_JOBS];
    int n = plan_effect(run->o, s->scene, e, jobs, MAX_JOBS);
    const char *why = NULL;
    const cJSON *truth = render_job(run, s, label, dir, hash, &jobs[0], &why);
    if (!truth) {
        cJSON_AddStringToObject(out, "error", why ? why : "the reference failed");
        run->failed = run->failed || !run->interrupted;
        run->jobs_done += n - 1;
        return out;
    }
    cJSON *reference = cJSON_AddObjectToObject(out, "reference");
    copy_render(reference, truth, slug);
    cJSON_AddNumberToObject(reference, "spp", (double)jobs[0].spp);
    const char *truth_name = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(truth, "file"));
    for (int k = 1; k < n; ++k) {
        const report_job *j = &jobs[k];
        cJSON *row = cJSON_CreateObject();
        cJSON_AddItemToArray(rows, row);
        cJSON_AddStringToObject(row, "technique", drift_technique_name(e, j->technique));
        cJSON_AddNumberToObject(row, "spp", (double)j->spp);
        cJSON_AddBoolToObject(row, "path_traced", drift_technique_path_traced(e, j->technique));
        why = NULL;
        const cJSON *entry = render_job(run, s, label, dir, hash, j, &why);
        if (!entry) {
            cJSON_AddStringToObject(row, "error", why ? why : "render failed");
            run->failed = run->failed || !(run->interrupted || run->budget_spent);
            continue;
        }
        copy_render(row, entry, slug);
        const char *name = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(entry, "file"));
        drift_result r = add_metrics(run, dir, truth_name, name, row);
        if (r != DRIFT_OK) {
            fprintf(stderr, "drift report: %s %s %s: cannot compare with the reference: %s\n",
                    label, drift_effect_name(e), drift_technique_name(e, j->technique),
                    drift_result_string(r));
            cJSON_AddStringToObject(row, "error", "cannot compare with the reference");
            run->failed = true;
        }
    }
    return out;
}

// --- the sir cell: the whole frame, refined ---

// The frame SIR refines (drift render --mode hybrid --shadows pcss --reflections envmap --dof
// post --refine sir, docs/sir.md), at the report's size.
static drift_hybrid_params sir_frame_params(const report_options *o, const drift_scene *scene)
{
    drift_hybrid_params p = make_job(o, scene, DRIFT_EFFECT_SHADOWS, 0, 1, false).params;
    p.shadows = DRIFT_SHADOWS_PCSS;
    p.reflections = DRIFT_REFLECTIONS_ENVMAP;
    p.dof = DRIFT_DOF_POST;
    return p;
}

// The whole-frame path tracer's sweep beside SIR's curve: 1, 2, 4, ... --sweep-spp below
// --ref-spp.
static int pt_sweep_count(const report_options *o)
{
    int n = 0;
    for (long spp = 1; spp <= o->sweep_spp && spp < o->ref_spp; spp *= 2) {
        ++n;
    }
    return n;
}

// iterations -1: the whole-frame truth; < -1: the whole-frame path tracer at -1 - iterations
// spp.
static void sir_key(const report_options *o, const drift_hybrid_params *p, uint64_t scene,
                    int threads, long iterations, char *out, size_t size)
{
    char text[256];
    if (iterations < -1) {
        snprintf(text, sizeof text, "%016" PRIx64 " whole-frame pt %dx%d %ld spp %d threads", scene,
                 p->width, p->height, -1 - iterations, threads);
    } else if (iterations < 0) { // the whole-frame truth
        snprintf(text, sizeof text, "%016" PRIx64 " whole-frame truth %dx%d %ld spp", scene,
                 p->width, p->height, o->ref_spp);
    } else {
        snprintf(text, sizeof text, "%016" PRIx64 " sir %dx%d budget %ld %ld iterations %d threads",
                 scene, p->width, p->height, o->sir_budget, iterations, threads);
    }
    snprintf(out, size, "%016" PRIx64,
             cli_fnv1a(cli_fnv1a(CLI_FNV_BASIS, text, strlen(text)), REPORT_VERSION,
                       sizeof REPORT_VERSION));
}

// Writes `image` as DIR/NAME.exr and its PNGs and records it in the manifest under `key`.
static cJSON *store_render(report_run *run, const char *dir, const char *key, const char *name,
                           const drift_image *image, double ms, uint64_t rays)
{
    char base[4096], exr[4200];
    snprintf(base, sizeof base, "%.3800s/%.256s", dir, name);
    snprintf(exr, sizeof exr, "%s.exr", base);
    drift_image_layer layer = { NULL, image };
    drift_result r = drift_image_save_exr(run->ctx, exr, &layer, 1);
    r = r ? r : save_pngs(run->ctx, base, image);
    if (r != DRIFT_OK) {
        fprintf(stderr, "drift report: cannot write %s: %s\n", exr, drift_result_string(r));
        return NULL;
    }
    cJSON *item = cJSON_CreateObject();
    cJSON_AddStringToObject(item, "file", name);
    cli_json_number(item, "ms", ms, 3);
    cli_json_number(item, "frame_ms", ms, 3);
    cli_json_count(item, "rays", rays);
    cJSON_DeleteItemFromObjectCaseSensitive(run->renders, key);
    cJSON_AddItemToObject(run->renders, key, item);
    return write_manifest(run) ? item : NULL;
}

static const cJSON *cached_render(report_run *run, const char *dir, const char *key)
{
    const cJSON *entry = cJSON_GetObjectItemCaseSensitive(run->renders, key);
    const char *file = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(entry, "file"));
    char exr[4200];
    snprintf(exr, sizeof exr, "%.3800s/%.256s.exr", dir, file ? file : "");
    return file && file_exists(exr) ? entry : NULL;
}

static void sir_progress(report_run *run, const char *scene, const char *what, const char *how)
{
    char eta[32];
    eta_text(run, eta, sizeof eta);
    fprintf(stderr, "drift report: [%d/%d] %s " REPORT_SIR_NAME " %s: %s, ETA %s\n", run->jobs_done,
            run->jobs_total, scene, what, how, eta);
}

static bool run_stopped(report_run *run)
{
    if (!run->interrupted && !run->budget_spent && run->o->time_budget > 0.0 &&
        drift_time_now() - run->t_start > run->o->time_budget) {
        run->budget_spent = true;
        fprintf(stderr, "drift report: --time-budget %g s spent; a rerun goes on from here\n",
                run->o->time_budget);
    }
    return run->interrupted || run->budget_spent;
}

// The whole-frame truth: drift bench frontier's (the path tracer at --ref-spp, every effect).
static const cJSON *sir_truth(report_run *run, const cli_session *s, const char *label,
                              const char *dir, uint64_t hash, const drift_hybrid_params *p)
{
    char key[32], name[256];
    sir_key(run->o, p, hash, drift_context_thread_count(run->ctx), -1, key, sizeof key);
    snprintf(name, sizeof name, "sir-truth-%ldspp-%.8s", run->o->ref_spp, key);
    ++run->jobs_done;
    const cJSON *entry = cached_render(run, dir, key);
    if (entry) {
        run->units_total -= (double)run->o->ref_spp;
    }
    if (entry || run_stopped(run)) {
        sir_progress(run, label, "whole-frame truth", entry ? "cached" : "not rendered");
        return entry;
    }
    drift_image truth = { 0 };
    double t0 = drift_time_now();
    drift_result r = render_whole_frame_reference(run->ctx, s->scene, s->accel, p->width, p->height,
                                                  (uint32_t)run->o->ref_spp, &truth);
    double ms = 1e3 * (drift_time_now() - t0);
    run->render_seconds += ms / 1e3;
    run->units_done += (double)run->o->ref_spp;
    entry = r == DRIFT_OK ? store_render(run, dir, key, name, &truth, ms, 0) : NULL;
    drift_image_destroy(run->ctx, &truth);
    char took[64];
    snprintf(took, sizeof took, "%.2f s", ms / 1e3);
    sir_progress(run, label, "whole-frame truth", entry ? took : drift_result_string(r));
    return entry;
}

// The whole frame path-traced at `spp` from another seed than the truth's (as the frontier's
// pt rows): the convergence SIR's curve is measured against.
static const cJSON *sir_pt(report_run *run, const cli_session *s, const char *label,
                           const char *dir, uint64_t hash, const drift_hybrid_params *p, long spp,
                           const char **why)
{
    char key[32], name[256], what[64];
    sir_key(run->o, p, hash, drift_context_thread_count(run->ctx), -1 - spp, key, sizeof key);
    snprintf(name, sizeof name, "sir-pt-%ldspp-%.8s", spp, key);
    snprintf(what, sizeof what, "whole-frame pt %ld spp", spp);
    ++run->jobs_done;
    const cJSON *entry = cached_render(run, dir, key);
    if (entry) {
        run->units_total -= (double)spp;
        sir_progress(run, label, what, "cached");
        return entry;
    }
    if (run_stopped(run)) {
        *why = run->interrupted ? "not rendered: interrupted (rerun to finish)"
                                : "not rendered: --time-budget spent (rerun to go on)";
        return NULL;
    }
    drift_image image = { 0 };
    uint64_t rays = 0;
    double t0 = drift_time_now();
    drift_result r = render_whole_frame_pt(run->ctx, s->scene, s->accel, p->width, p->height,
                                           (uint32_t)spp, 1u, run->cancel, &image, &rays);
    double ms = 1e3 * (drift_time_now() - t0);
    run->render_seconds += ms / 1e3;
    run->units_done += (double)spp;
    entry = r == DRIFT_OK ? store_render(run, dir, key, name, &image, ms, rays) : NULL;
    drift_image_destroy(run->ctx, &image);
    if (r == DRIFT_ERR_CANCELLED) {
        run->interrupted = true;
        fprintf(stderr, "drift report: interrupted; writing the page with what is finished\n");
    }
    *why = r == DRIFT_ERR_CANCELLED ? "not rendered: interrupted (rerun to finish)"
                                    : "render failed (see the log)";
    char took[64];
    snprintf(took, sizeof took, "%.2f s", ms / 1e3);
    sir_progress(run, label, what, entry ? took : drift_result_string(r));
    run_stopped(run);
    return entry;
}

// The raster frame (0 iterations) and the refined frame after each of --sir-iterations,
// from one refinement: a row's ms are the raster frame's and the refinement's so far (its
// metrics, sort and tracing), its rays the frame's, the metrics' and the tracer's. All the
// rows come from one run, so a missing one renders them all again.
static void sir_rows(report_run *run, const cli_session *s, const char *label, const char *dir,
                     uint64_t hash, const drift_hybrid_params *p, const cJSON **entries,
                     const char **why)
{
    const report_options *o = run->o;
    int n = o->sir_iteration_count + 1, threads = drift_context_thread_count(run->ctx);
    char keys[REPORT_MAX_SIR + 1][32];
    bool all = true;
    for (int k = 0; k < n; ++k) {
        sir_key(o, p, hash, threads, k ? o->sir_iterations[k - 1] : 0, keys[k], sizeof keys[k]);
        entries[k] = cached_render(run, dir, keys[k]);
        all = all && entries[k];
    }
    run->jobs_done += n;
    if (all) {
        run->units_total -= n;
        sir_progress(run, label, "iterations", "cached");
        return;
    }
    if (run_stopped(run)) {
        *why = run->interrupted ? "not rendered: interrupted (rerun to finish)"
                                : "not rendered: --time-budget spent (rerun to go on)";
        return;
    }
    memset(entries, 0, sizeof *entries * (size_t)n);
    *why = "render failed (see the log)";
    drift_hybrid *frame = NULL;
    drift_refine *sir = NULL;
    double t0 = drift_time_now();
    drift_result r = drift_hybrid_create(run->ctx, s->scene, s->accel, p, &frame);
    r = r ? r : drift_hybrid_render(frame, &s->scene->camera, run->cancel);
    r = r ? r : drift_hybrid_render(frame, &s->scene->camera, run->cancel); // warm, as above
    double raster_ms = 0.0;
    uint64_t raster_rays = 0;
    char name[256];
    if (r == DRIFT_OK) {
        drift_hybrid_stats st = drift_hybrid_get_stats(frame);
        raster_ms = st.frame_ms;
        for (int k = 0; k < DRIFT_PASS_COUNT; ++k) {
            raster_rays += st.rays[k];
        }
        snprintf(name, sizeof name, "sir-0it-%.8s", keys[0]);
        entries[0] = store_render(run, dir, keys[0], name, drift_hybrid_image(frame), raster_ms,
                                  raster_rays);
        r = entries[0] ? DRIFT_OK : DRIFT_ERR_IO;
    }
    drift_refine_params rp = { .budget = (uint32_t)o->sir_budget };
    r = r ? r : drift_refine_create(run->ctx, frame, &rp, &sir);
    double start = drift_time_now();
    r = r ? r : drift_refine_begin(sir);
    for (int k = 1; k < n && r == DRIFT_OK; ++k) {
        while (r == DRIFT_OK && !drift_refine_done(sir) &&
               drift_refine_get_stats(sir).iterations < (uint32_t)o->sir_iterations[k - 1]) {
            r = drift_refine_iterate(sir, run->cancel);
        }
        if (r != DRIFT_OK) {
            break;
        }
        double now = drift_time_now(), ms = raster_ms + 1e3 * (now - start);
        drift_refine_stats st = drift_refine_get_stats(sir);
        snprintf(name, sizeof name, "sir-%ldit-%.8s", o->sir_iterations[k - 1], keys[k]);
        cJSON *item = store_render(run, dir, keys[k], name, drift_refine_image(sir), ms,
                                   raster_rays + st.metrics_rays + st.rays);
        if (item) { // fewer than asked when every error pixel was refined before
            cli_json_count(item, "iterations_run", st.iterations);
            cli_json_count(item, "refined", st.refined);
            cli_json_count(item, "requested", st.requested);
            entries[k] = item;
        }
        r = item && write_manifest(run) ? DRIFT_OK : DRIFT_ERR_IO;
        start += drift_time_now() - now; // writing the files is not the refinement's time
    }
    if (r == DRIFT_ERR_CANCELLED) {
        run->interrupted = true;
        *why = "not rendered: interrupted (rerun to finish)";
        fprintf(stderr, "drift report: interrupted; writing the page with what is finished\n");
    } else if (r != DRIFT_OK) {
        fprintf(stderr, "drift report: %s " REPORT_SIR_NAME ": %s\n", label,
                drift_result_string(r));
    }
    run->render_seconds += drift_time_now() - t0;
    run->units_done += n;
    char took[64];
    snprintf(took, sizeof took, "%.2f s", drift_time_now() - t0);
    sir_progress(run, label, "iterations", r == DRIFT_OK ? took : drift_result_string(r));
    run_stopped(run);
    drift_refine_destroy(sir);
    drift_hybrid_destroy(frame);
}

// The sir cell: the whole frame, raster and refined, against the whole-frame truth.
static cJSON *report_sir(report_run *run, const cli_session *s, const char *label, const char *slug,
                         const char *dir, uint64_t hash)
{
    const report_options *o = run->o;
    drift_hybrid_params p = sir_frame_params(o, s->scene);
    cJSON *out = cJSON_CreateObject();
    cJSON_AddStringToObject(out, "effect", REPORT_SIR_NAME);
    cJSON_AddBoolToObject(out, "whole_frame", true);
    cJSON *rows = cJSON_AddArrayToObject(out, "rows");
    const cJSON *truth = sir_truth(run, s, label, dir, hash, &p);
    if (!truth) {
        cJSON_AddStringToObject(out, "error",
                                run->interrupted ? "not rendered: interrupted (rerun to finish)"
                                : run->budget_spent
                                    ? "not rendered: --time-budget spent (rerun to go on)"
                                    : "the whole-frame reference failed");
        run->failed = run->failed || !(run->interrupted || run->budget_spent);
        run->jobs_done += o->sir_iteration_count + 1 + pt_sweep_count(o);
        return out;
    }
    cJSON *reference = cJSON_AddObjectToObject(out, "reference");
    copy_render(reference, truth, slug);
    cJSON_AddNumberToObject(reference, "spp", (double)o->ref_spp);
    const char *truth_name = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(truth, "file"));
    const cJSON *entries[REPORT_MAX_SIR + 1] = { 0 };
    const char *why = NULL;
    sir_rows(run, s, label, dir, hash, &p, entries, &why);
    for (int k = 0; k <= o->sir_iteration_count; ++k) {
        cJSON *row = cJSON_CreateObject();
        cJSON_AddItemToArray(rows, row);
        cJSON_AddStringToObject(row, "technique", REPORT_SIR_NAME);
        cJSON_AddNumberToObject(row, "iterations", k ? (double)o->sir_iterations[k - 1] : 0.0);
        cJSON_AddNumberToObject(row, "spp", 1);
        cJSON_AddBoolToObject(row, "path_traced", false);
        if (!entries[k]) {
            cJSON_AddStringToObject(row, "error", why ? why : "render failed");
            run->failed = run->failed || !(run->interrupted || run->budget_spent);
            continue;
        }
        copy_render(row, entries[k], slug);
        const char *const counts[3] = { "iterations_run", "refined", "requested" };
        for (int c = 0; c < 3; ++c) {
            const cJSON *v = cJSON_GetObjectItemCaseSensitive(entries[k], counts[c]);
            if (cJSON_IsNumber(v)) {
                cJSON_AddNumberToObject(row, counts[c], v->valuedouble);
            }
        }
        const char *name =
            cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(entries[k], "file"));
        if (add_metrics(run, dir, truth_name, name, row) != DRIFT_OK) {
            cJSON_AddStringToObject(row, "error", "cannot compare with the reference");
            run->failed = true;
        }
    }
    for (long spp = 1; spp <= o->sweep_spp && spp < o->ref_spp; spp *= 2) {
        cJSON *row = cJSON_CreateObject();
        cJSON_AddItemToArray(rows, row);
        cJSON_AddStringToObject(row, "technique", "pt");
        cJSON_AddNumberToObject(row, "spp", (double)spp);
        cJSON_AddBoolToObject(row, "path_traced", true);
        why = NULL;
        const cJSON *entry = sir_pt(run, s, label, dir, hash, &p, spp, &why);
        if (!entry) {
            cJSON_AddStringToObject(row, "error", why ? why : "render failed");
            run->failed = run->failed || !(run->interrupted || run->budget_spent);
            continue;
        }
        copy_render(row, entry, slug);
        const char *name = cJSON_GetStringValue(cJSON_GetObjectItemCaseSensitive(entry, "file"));
        if (add_metrics(run, dir, truth_name, name, row) != DRIFT_OK) {
            cJSON_AddStringToObject(row, "error", "cannot compare with the reference");
            run->failed = true;
        }
    }
    return out;
}

static void add_facts(cJSON *scene_json, const cli_session *s, uint64_t hash)
{
    const drift_scene *scene = s->scene;
    const drift_camera *c = &scene->camera;
    cJSON *facts = cJSON_AddObjectToObject(scene_json, "facts");
    cli_json_count(facts, "triangles", drift_scene_triangle_count(scene));
    cli_json_count(facts, "meshes", scene->mesh_count);
    cli_json_count(facts, "materials", scene->material_count);
    cli_json_count(facts, "lights", scene->light_count);
    cli_json_count(facts, "textures", scene->texture_count);
    cJSON *camera = cJSON_AddObjectToObject(facts, "camera");
    cli_json_vec3(camera, "position", c->position.x, c->position.y, c->position.z);
    cli_json_vec3(camera, "target", c->target.x, c->target.y, c->target.z);
    cli_json_float(camera, "fov_y_degrees", c->fov_y * 180.0f / DRIFT_PI);
    cli_json_float(camera, "aperture_radius", c->aperture_radius);
    cli_json_float(camera, "focus_distance", c->focus_distance);
    char text[32];
    snprintf(text, sizeof text, "%016" PRIx64, hash);
    cJSON_AddStringToObject(facts, "content_hash", text);
}

// "cornell_box-0123abcd": the scene file's name and its content hash.
static void scene_slug(const char *path, uint64_t hash, char *out, size_t size)
{
    const char *base = strrchr(path, '/');
    base = base ? base + 1 : path;
    size_t n = 0;
    for (const char *p = base; *p && *p != '.' && n + 1 < size && n < 48; ++p) {
        char ch = *p;
        bool ok = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') ||
                  (ch >= '0' && ch <= '9') || ch == '-' || ch == '_';
        out[n++] = ok ? ch : '_';
    }
    snprintf(out + n, size - n, "-%08" PRIx32, (uint32_t)(hash >> 32));
}

static cJSON *report_scene(report_run *run, cli_session *session, const char *path)
{
    cJSON *out = cJSON_CreateObject();
    cJSON_AddStringToObject(out, "path", path);
    if (!cli_session_load(session, "report", path, false)) {
        cJSON_AddStringToObject(out, "error", "the scene failed to load (see the log)");
        run->failed = true;
        report_job jobs[MAX_JOBS];
        for (int e = 0; e < DRIFT_EFFECT_COUNT; ++e) {
            run->jobs_done +=
                run->o->effects[e] ? plan_effect(run->o, NULL, (drift_effect)e, jobs, MAX_JOBS) : 0;
        }
        run->jobs_done +=
            run->o->sir ? run->o->sir_iteration_count + 2 + pt_sweep_count(run->o) : 0;
        return out;
    }
    uint64_t hash = scene_hash(session);
    char slug[80], dir[4200];
    scene_slug(path, hash, slug, sizeof slug);
    cJSON_AddStringToObject(out, "name", slug);
    add_facts(out, session, hash);
    snprintf(dir, sizeof dir, "%s/%s", run->o->out_dir, slug);
    cJSON *list = cJSON_AddArrayToObject(out, "effects");
    if (!make_dir(dir)) {
        fprintf(stderr, "drift report: cannot create %s: %s\n", dir, strerror(errno));
        cJSON_AddStringToObject(out, "error", "cannot create the scene's folder");
        run->failed = true;
        return out;
    }
    for (int e = 0; e < DRIFT_EFFECT_COUNT; ++e) {
        if (run->o->effects[e]) {
            cJSON_AddItemToArray(
                list, report_effect(run, session, slug, slug, dir, hash, (drift_effect)e));
        }
    }
    if (run->o->sir) {
        cJSON_AddItemToArray(list, report_sir(run, session, slug, slug, dir, hash));
    }
    return out;
}

static void add_machine(cJSON *root, drift_context *ctx)
{
    cJSON *m = cJSON_AddObjectToObject(root, "machine");
    char host[256] = "unknown";
    if (gethostname(host, sizeof host) != 0) {
        snprintf(host, sizeof host, "unknown");
    }
    host[sizeof host - 1] = '\0';
    cJSON_AddStringToObject(m, "host", host);
    struct utsname u;
    if (uname(&u) == 0) {
        char os[600];
        snprintf(os, sizeof os, "%s %s %s", u.sysname, u.release, u.machine);
        cJSON_AddStringToObject(m, "os", os);
    }
    char *cpuinfo = read_text("/proc/cpuinfo");
    const char *model = cpuinfo ? strstr(cpuinfo, "model name") : NULL;
    if (model && (model = strchr(model, ':'))) {
        char line[256];
        snprintf(line, sizeof line, "%.*s", (int)strcspn(model + 2, "\n"), model + 2);
        cJSON_AddStringToObject(m, "cpu", line);
    }
    free(cpuinfo);
    cJSON_AddNumberToObject(m, "cores", (double)sysconf(_SC_NPROCESSORS_ONLN));
    cJSON_AddNumberToObject(m, "threads", drift_context_thread_count(ctx));
}

// DIR/index.html: the page template with the data in place of its marker. "</" is written
// "<\/" so that no string of the data can close the script element that holds it.
static bool write_page(const char *out_dir, cJSON *data)
{
    static const char marker[] = "@DRIFT_REPORT_DATA@";
    char *json = cJSON_PrintUnformatted(data);
    const char *at = strstr(drift_report_page, marker);
    char path[4200], tmp[4300];
    snprintf(path, sizeof path, "%s/index.html", out_dir);
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    FILE *f = json && at ? fopen(tmp, "wb") : NULL;
    bool ok = f != NULL;
    if (f) {
        fwrite(drift_report_page, 1, (size_t)(at - drift_report_page), f);
        for (const char *p = json; *p; ++p) {
            if (p[0] == '<' && p[1] == '/') {
                fputs("<\\", f);
            } else {
                fputc(*p, f);
            }
        }
        fputs(at + sizeof marker - 1, f);
        ok = fclose(f) == 0 && rename(tmp, path) == 0;
    }
    if (!ok) {
        fprintf(stderr, "drift report: cannot write %s: %s\n", path, strerror(errno));
    }
    free(json);
    return ok;
}

static void load_manifest(report_run *run)
{
    char *text = read_text(run->manifest_path);
    cJSON *root = text ? cJSON_Parse(text) : NULL;
    free(text);
    cJSON *renders = cJSON_GetObjectItemCaseSensitive(root, "renders");
    run->renders =
        cJSON_IsObject(renders) ? cJSON_DetachItemViaPointer(root, renders) : cJSON_CreateObject();
    cJSON_Delete(root);
}

int drift_cmd_report(int argc, char **argv)
{
    report_options o = { .size = 256,
                         .ref_spp = 256,
                         .sweep_spp = 16,
                         .sir = true,
                         .sir_iterations = { 1, 2, 4, 8 },
                         .sir_iteration_count = 4 };
    int status = cli_parse(&report_command, argc, argv, &o, NULL);
    if (status != CLI_PARSED) {
        return cli_parse_exit(status);
    }
    if (!o.out_dir) {
        fprintf(stderr, "drift report: --out DIR is required (where the page is written)\n");
        return 2;
    }
    if (!o.effects_given) {
        for (int e = 0; e < DRIFT_EFFECT_COUNT; ++e) {
            o.effects[e] = effect_has_reference((drift_effect)e);
        }
    }
    if (!o.scenes[0]) {
        o.scenes[0] = cli_default_scene_path();
    }
    // Before anything is written, so that Ctrl-C from here on writes the page.
    const atomic_bool *cancel = render_catch_sigint();
    if (!make_dir(o.out_dir)) {
        fprintf(stderr, "drift report: cannot create --out '%s': %s\n", o.out_dir, strerror(errno));
        return 1;
    }
    if (!report_out_dir_is_ours(o.out_dir)) {
        return 2;
    }
    cli_session session;
    if (!cli_session_open(&(cli_session_desc){ .cmd = "report",
                                               .threads = (int)o.threads,
                                               .verbose = o.verbose,
                                               .no_scene = true },
                          &session)) {
        cli_session_close(&session);
        return 1;
    }
    report_run run = { .o = &o, .ctx = session.ctx, .t_start = drift_time_now() };
    snprintf(run.manifest_path, sizeof run.manifest_path, "%s/manifest.json", o.out_dir);
    load_manifest(&run);
    run.cancel = cancel;
    int scene_count = 0;
    while (scene_count < REPORT_MAX_SCENES && o.scenes[scene_count]) {
        ++scene_count;
    }
    report_job jobs[MAX_JOBS];
    for (int e = 0; e < DRIFT_EFFECT_COUNT; ++e) {
        if (o.effects[e]) {
            int n = plan_effect(&o, NULL, (drift_effect)e, jobs, MAX_JOBS);
            run.jobs_total += scene_count * n;
            for (int k = 0; k < n; ++k) {
                run.units_total += scene_count * job_units(&jobs[k]);
            }
        }
    }

    if (o.sir) { // the truth, the raster frame, one row an iteration count, the pt sweep
        run.jobs_total += scene_count * (o.sir_iteration_count + 2 + pt_sweep_count(&o));
        run.units_total += scene_count * ((double)o.ref_spp + o.sir_iteration_count + 1);
        for (long spp = 1; spp <= o.sweep_spp && spp < o.ref_spp; spp *= 2) {
            run.units_total += scene_count * (double)spp;
        }
    }

    cJSON *data = cJSON_CreateObject();
    cJSON *drift = cJSON_AddObjectToObject(data, "drift");
    cJSON_AddStringToObject(drift, "version", DRIFT_VERSION);
    cJSON_AddStringToObject(drift, "commit", DRIFT_COMMIT);
    add_machine(data, session.ctx);
    cJSON *options = cJSON_AddObjectToObject(data, "options");
    cJSON_AddNumberToObject(options, "size", (double)o.size);
    cJSON_AddNumberToObject(options, "ref_spp", (double)o.ref_spp);
    cJSON_AddNumberToObject(options, "sweep_spp", (double)o.sweep_spp);
    cJSON_AddNumberToObject(options, "time_budget", o.time_budget);
    cJSON *stops = cJSON_AddArrayToObject(data, "exposures");
    for (int k = 0; k < REPORT_EXPOSURES; ++k) {
        cJSON_AddItemToArray(stops, cJSON_CreateNumber(exposure_stops[k]));
    }
    time_t now = time(NULL);
    char when[64];
    strftime(when, sizeof when, "%Y-%m-%dT%H:%M:%SZ", gmtime(&now));
    cJSON_AddStringToObject(data, "generated", when);
    cJSON *scenes = cJSON_AddArrayToObject(data, "scenes");
    for (int i = 0; i < scene_count; ++i) {
        cJSON_AddItemToArray(scenes, report_scene(&run, &session, o.scenes[i]));
    }
    cJSON_AddStringToObject(data, "status",
                            run.interrupted    ? "interrupted"
                            : run.budget_spent ? "time budget spent"
                            : run.failed       ? "incomplete"
                                               : "complete");
    bool ok = write_manifest(&run) && write_page(o.out_dir, data);
    cJSON_Delete(data);
    cJSON_Delete(run.renders);
    cli_session_close(&session);
    if (ok) {
        printf("wrote %s/index.html (%s) in %.1f s\n", o.out_dir,
               run.interrupted    ? "interrupted"
               : run.budget_spent ? "--time-budget spent"
               : run.failed       ? "with failed cells"
                                  : "complete",
               drift_time_now() - run.t_start);
    }
    if (run.interrupted) {
        return render_interrupt_status();
    }
    return ok && !run.failed && !run.budget_spent ? 0 : 1;
}
