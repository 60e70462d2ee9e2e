// drift bench cycles: drift's reference path tracer against Blender's Cycles (CPU) on the same
// scene, resolution, spp, depth and threads, measured back to back in one run.
//
// Both renderers run as child processes and are timed whole (fork -> exit, wall and CPU); each
// also reports its own render time: drift's --stats milliseconds.render (no load, accel or write),
// Cycles' render_seconds from bench/cycles/cornell_cycles.py or obj_cycles.py (a JSON of OBJ
// meshes; "Sample 0/N" -> "Sample N/N": no scene sync, BVH or EXR write) or, for a glTF,
// Blender's own " Time: " line (sync included).
// Both images are compared with a higher-spp drift reference (cached, keyed by the scene file,
// size, depth and spp): ꟻLIP and relMSE. The equal-error ratio assumes relMSE ∝ 1/spp and time ∝
// spp for each renderer, so the time to reach a relMSE e is t * relMSE / e and the ratio of the
// two at any e is (t_cycles relMSE_cycles) / (t_drift relMSE_drift); Cycles' relMSE includes its
// bias against drift's reference (light and roulette conventions), which makes it an upper bound.
//
// Exit status: 0, 1 (a render failed), 2 (usage), 77 (Blender is not installed: skipped).
#include "bench.h"
#include "cli.h"
#include "cli_json.h"
#include "drift/image_io.h"
#include "drift/metric.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#define BENCH_CYCLES_SKIP 77

typedef struct cycles_options {
    const char *scene_path[1];
    long size, spp, ref_spp, fit_spp, max_depth, threads;
    const char *blender, *out_dir, *cache_dir;
    bool json;
} cycles_options;

#define O cycles_options
static const cli_option cycles_table[] = {
    CLI_SECTION("options:", 0),
    CLI_INT("--size", "N", O, size, 1, 8192, "image width and height (default 256)"),
    CLI_INT("--spp", "N", O, spp, 1, 1 << 20, "samples a pixel of both renderers (default 64)"),
    CLI_INT("--max-depth", "D", O, max_depth, 1, 1024,
            "drift's --max-depth (scattering vertices); Cycles gets max_bounces D-1 (default 8)"),
    CLI_INT("--ref-spp", "N", O, ref_spp, 1, 1 << 22,
            "spp of drift's reference for FLIP and relMSE (default 4x --spp, at least 256)"),
    CLI_INT("--fit-spp", "N", O, fit_spp, 0, 1 << 20,
            "second, lower spp of both for the error slope (default --spp/4; 0: assume 1/spp)"),
    CLI_STRING("--blender", "BIN", O, blender, "Blender binary (default $BLENDER or blender)"),
    CLI_STRING("--out-dir", "DIR", O, out_dir,
               "where the images and logs go (default a new /tmp/drift-bench-cycles-*)"),
    CLI_STRING("--cache", "DIR", O, cache_dir,
               "reference cache (default $XDG_CACHE_HOME or ~/.cache, then drift/bench-cycles)"),
    CLI_INT("--threads", "T", O, threads, 1, 256, "threads of both renderers (default 2)"),
    BENCH_OPTION_JSON(O),
};
#undef O

static const cli_command cycles_command = {
    .name = "bench cycles",
    .usage = "usage: drift bench cycles [SCENE] [options]\n\n"
             "Renders SCENE (default the Cornell box; a drift .json of OBJ meshes such as the\n"
             "Breakfast Room; or a .gltf/.glb) with drift's path tracer\n"
             "and with Blender's Cycles at the same size, spp, depth and threads, one after the\n"
             "other; prints both whole-process and render-only times, the ratio Cycles / drift,\n"
             "both images' FLIP and relMSE against a cached higher-spp drift reference and the\n"
             "equal-error ratio. Exit status 77 when Blender is not installed (skipped).\n\n",
    CLI_TABLE(cycles_table),
    CLI_POSITIONAL("SCENE", cycles_options, scene_path, 1),
    .help_column = 22,
};

typedef struct child_time {
    double wall_s, cpu_s;
} child_time;

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static double children_cpu_s(void)
{
    struct rusage u;
    getrusage(RUSAGE_CHILDREN, &u);
    return (double)u.ru_utime.tv_sec + 1e-6 * (double)u.ru_utime.tv_usec +
           (double)u.ru_stime.tv_sec + 1e-6 * (double)u.ru_stime.tv_usec;
}

// Runs argv with stdout and stderr into `log` (NULL: /dev/null); its exit status (-1: it could
// not start or died of a signal) and its wall and CPU time.
static int run_child(char *const argv[], const char *log, child_time *t)
{
    double cpu0 = children_cpu_s(), t0 = now_s();
    fflush(stdout);
    fflush(stderr);
    pid_t pid = fork();
    if (pid == 0) {
        int fd = open(log ? log : "/dev/null", O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (fd >= 0) {
            dup2(fd, STDOUT_FILENO);
            dup2(fd, STDERR_FILENO);
            close(fd);
        }
        execvp(argv[0], argv);
        _exit(127);
    }
    int status = 0;
    if (pid < 0 || waitpid(pid, &status, 0) < 0) {
        return -1;
    }
    if (t) {
        t->wall_s = now_s() - t0;
        t->cpu_s = children_cpu_s() - cpu0;
    }
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

static bool ends_with(const char *s, const char *tail)
{
    size_t n = strlen(s), m = strlen(tail);
    return n >= m && strcmp(s + n - m, tail) == 0;
}

static char *read_text(const char *path)
{
    FILE *f = fopen(path, "rb");
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

// drift's --stats milliseconds.render in seconds, and its cpu_milliseconds.render into
// *cpu_s; NAN when absent.
static double drift_render_seconds(const char *stats_path, double *cpu_s)
{
    char *text = read_text(stats_path);
    cJSON *root = text ? cJSON_Parse(text) : NULL;
    free(text);
    cJSON *ms = cJSON_GetObjectItemCaseSensitive(root, "milliseconds");
    cJSON *render = cJSON_GetObjectItemCaseSensitive(ms, "render");
    double s = cJSON_IsNumber(render) ? 1e-3 * render->valuedouble : (double)NAN;
    cJSON *cpu = cJSON_GetObjectItemCaseSensitive(
        cJSON_GetObjectItemCaseSensitive(root, "cpu_milliseconds"), "render");
    *cpu_s = cJSON_IsNumber(cpu) ? 1e-3 * cpu->valuedouble : (double)NAN;
    cJSON_Delete(root);
    return s;
}

// The last "CYCLES_TIME render_seconds=S" of the log (cornell_cycles.py) into *render_s, the
// last "render_cpu_seconds=S" (the same window's CPU time, all threads) into *cpu_s and the
// last Blender " Time: [HH:]MM:SS.ss" (render call, sync included) into *blender_s; NAN if absent.
static void cycles_times(const char *log, double *render_s, double *cpu_s, double *blender_s)
{
    *render_s = *cpu_s = *blender_s = (double)NAN;
    char *text = read_text(log);
    for (char *line = text ? strtok(text, "\n") : NULL; line; line = strtok(NULL, "\n")) {
        double h = 0, m = 0, s = 0;
        const char *cpu = strstr(line, "render_cpu_seconds=");
        if (cpu && strncmp(line, "CYCLES_TIME", 11) == 0) {
            *cpu_s = strtod(cpu + 19, NULL);
        }
        if (strncmp(line, "CYCLES_TIME render_seconds=", 27) == 0) {
            *render_s = strtod(line + 27, NULL);
        } else if (sscanf(line, " Time: %lf:%lf:%lf", &h, &m, &s) == 3) {
            *blender_s = 3600 * h + 60 * m + s;
        } else if (sscanf(line, " Time: %lf:%lf", &m, &s) == 2) {
            *blender_s = 60 * m + s;
        }
    }
    free(text);
}

// A reference's cache file name: FNV-1a of everything that makes it.
static void reference_path(const cycles_options *o, const char *scene, const char *dir, char *out,
                           size_t size)
{
    struct stat st = { 0 };
    stat(scene, &st);
    char key[4352];
    snprintf(key, sizeof key, "%s|%lld|%lld|%ld|%ld|%ld|v1", scene, (long long)st.st_size,
             (long long)st.st_mtime, o->size, o->max_depth, o->ref_spp);
    uint64_t h = 1469598103934665603ull;
    for (const char *c = key; *c; ++c) {
        h = (h ^ (unsigned char)*c) * 1099511628211ull;
    }
    snprintf(out, size, "%s/ref-%016llx.exr", dir, (unsigned long long)h);
}

static void mkdirs(const char *path)
{
    char p[4096];
    snprintf(p, sizeof p, "%s", path);
    for (char *c = p + 1; *c; ++c) {
        if (*c == '/') {
            *c = '\0';
            mkdir(p, 0755);
            *c = '/';
        }
    }
    mkdir(p, 0755);
}

// Both images' metrics against the reference; false (message printed) on a load failure.
static bool compare(drift_context *ctx, const char *ref_path, const char *const *paths, int count,
                    drift_metric_report *out)
{
    drift_image ref = { 0 }, test = { 0 };
    if (drift_image_load(ctx, ref_path, &ref) != DRIFT_OK) {
        fprintf(stderr, "drift bench cycles: cannot read the reference %s\n", ref_path);
        return false;
    }
    bool ok = true;
    for (int i = 0; i < count && ok; ++i) {
        ok = drift_image_load(ctx, paths[i], &test) == DRIFT_OK &&
             drift_metric_compare(ctx, &ref, &test, &(drift_metric_params){ 0 }, &out[i], NULL) ==
                 DRIFT_OK;
        if (!ok) {
            fprintf(stderr, "drift bench cycles: cannot compare %s with %s\n", paths[i], ref_path);
        }
        drift_image_destroy(ctx, &test);
    }
    drift_image_destroy(ctx, &ref);
    return ok;
}

typedef struct cycles_run {
    child_time drift_process, cycles_process;
    double drift_render_s, cycles_render_s, blender_render_s;
    double drift_render_cpu_s, cycles_render_cpu_s; // the same windows' CPU seconds
    // Cycles / drift in CPU seconds: on a shared machine the wall-clock ratios follow who got
    // the cores at the time, CPU time much less.
    double ratio_process_cpu, ratio_render_cpu, equal_error_cpu;
    drift_metric_report drift_q, cycles_q;
    double drift_lo_relmse, cycles_lo_relmse, drift_slope, cycles_slope, ref_noise;
    bool gltf, cornell; // neither: a drift scene JSON of OBJ meshes (obj_cycles.py)
    char scene[4096], dir[4096], ref[4352], drift_exr[4352], cycles_exr[4352], cycles_log[4352];
    char drift_lo_exr[4352], cycles_lo_exr[4352], cycles_lo_log[4352];
} cycles_run;

static void print_json(const cycles_options *o, const cycles_run *r, double ratio_process,
                       double ratio_render, double equal_error)
{
    cJSON *root = cJSON_CreateObject();
    cJSON_AddStringToObject(root, "scene", r->scene);
    cli_json_count(root, "size", (uint64_t)o->size);
    cli_json_count(root, "spp", (uint64_t)o->spp);
    cli_json_count(root, "max_depth", (uint64_t)o->max_depth);
    cli_json_count(root, "threads", (uint64_t)o->threads);
    cli_json_count(root, "ref_spp", (uint64_t)o->ref_spp);

    const struct {
        const char *name;
        const child_time *p;
        double render_s, render_cpu_s;
        const drift_metric_report *q;
        const char *image;
    } rows[2] = { { "drift", &r->drift_process, r->drift_render_s, r->drift_render_cpu_s,
                    &r->drift_q, r->drift_exr },
                  { "cycles", &r->cycles_process, r->cycles_render_s, r->cycles_render_cpu_s,
                    &r->cycles_q, r->cycles_exr } };

    for (int i = 0; i < 2; ++i) {
        cJSON *row = cJSON_AddObjectToObject(root, rows[i].name);
        cli_json_number(row, "process_s", rows[i].p->wall_s, 4);
        cli_json_number(row, "process_cpu_s", rows[i].p->cpu_s, 4);
        cli_json_number(row, "render_s", rows[i].render_s, 4);
        cli_json_number(row, "render_cpu_s", rows[i].render_cpu_s, 4);
        cli_json_number(row, "flip", rows[i].q->flip, 5);
        cli_json_number(row, "relmse", rows[i].q->relmse, 7);
        cJSON_AddStringToObject(row, "image", rows[i].image);
    }
    cli_json_number(cJSON_GetObjectItem(root, "cycles"), "blender_render_s", r->blender_render_s,
                    4);
    cli_json_number(root, "ratio_process", ratio_process, 4);
    cli_json_number(root, "ratio_render", ratio_render, 4);
    cli_json_number(root, "equal_error_ratio", equal_error, 4);
    cli_json_number(root, "ratio_process_cpu", r->ratio_process_cpu, 4);
    cli_json_number(root, "ratio_render_cpu", r->ratio_render_cpu, 4);
    cli_json_number(root, "equal_error_ratio_cpu", r->equal_error_cpu, 4);
    cli_json_count(root, "fit_spp",
                   (uint64_t)(o->fit_spp > 0 && o->fit_spp < o->spp ? o->fit_spp : 0));
    cli_json_number(root, "reference_relmse", r->ref_noise, 7);
    cli_json_number(root, "drift_error_slope", r->drift_slope, 4);
    cli_json_number(root, "cycles_error_slope", r->cycles_slope, 4);
    cJSON_AddStringToObject(root, "reference", r->ref);
    cli_json_write("bench cycles", root, NULL);
}

static void print_text(const cycles_options *o, const cycles_run *r, double ratio_process,
                       double ratio_render, double equal_error)
{
    printf("drift bench cycles: %s, %ldx%ld, %ld spp, max depth %ld (Cycles max_bounces %ld), %ld "
           "thread(s)\n",
           r->scene, o->size, o->size, o->spp, o->max_depth, o->max_depth - 1, o->threads);
    printf("  %-7s %11s %11s %11s %9s %11s\n", "", "process s", "cpu s", "render s", "FLIP",
           "relMSE");
    printf("  %-7s %11.3f %11.3f %11.3f %9.5f %11.3g\n", "drift", r->drift_process.wall_s,
           r->drift_process.cpu_s, r->drift_render_s, r->drift_q.flip, r->drift_q.relmse);
    printf("  %-7s %11.3f %11.3f %11.3f %9.5f %11.3g\n", "cycles", r->cycles_process.wall_s,
           r->cycles_process.cpu_s, r->cycles_render_s, r->cycles_q.flip, r->cycles_q.relmse);
    printf("  Cycles / drift: whole process %.3f, render %.3f, equal relMSE %.3f (>1: drift "
           "faster)\n",
           ratio_process, ratio_render, equal_error);
    printf("  in CPU seconds: whole process %.3f, render %.3f (%.3f / %.3f s), equal relMSE %.3f\n",
           r->ratio_process_cpu, r->ratio_render_cpu, r->cycles_render_cpu_s, r->drift_render_cpu_s,
           r->equal_error_cpu);
    printf("  relMSE ∝ spp^-k, less the reference's own %.3g: k drift %.3f, Cycles %.3f (%s)\n",
           r->ref_noise, r->drift_slope, r->cycles_slope,
           o->fit_spp > 0 && o->fit_spp < o->spp ? "fitted from --fit-spp" : "assumed");
    printf("  reference: drift %ld spp, %s\n  images: %s %s\n", o->ref_spp, r->ref, r->drift_exr,
           r->cycles_exr);
}

// drift render SCENE --mode reference with the bench's size, depth and threads.
static int render_drift(const cycles_options *o, const char *self, const char *scene, long spp,
                        const char *seed, const char *out, const char *stats, const char *log,
                        child_time *t)
{
    char s_spp[32], s_size[32], s_depth[32], s_threads[32];
    snprintf(s_spp, sizeof s_spp, "%ld", spp);
    snprintf(s_size, sizeof s_size, "%ld", o->size);
    snprintf(s_depth, sizeof s_depth, "%ld", o->max_depth);
    snprintf(s_threads, sizeof s_threads, "%ld", o->threads);
    char *argv[] = { (char *)self,  "render",      (char *)scene,
                     "--mode",      "reference",   "--spp",
                     s_spp,         "--max-depth", s_depth,
                     "--threads",   s_threads,     "--width",
                     s_size,        "--height",    s_size,
                     "--seed",      (char *)seed,  "--out",
                     (char *)out,   "--quiet",     stats ? "--stats" : NULL,
                     (char *)stats, NULL };
    return run_child(argv, log, t);
}

static int render_cycles(const cycles_options *o, const cycles_run *r, long spp, char *out,
                         const char *log, child_time *t)
{
    char s_spp[32], s_size[32], s_depth[32], s_bounces[32], s_threads[32], script[4200], obj[4200];
    snprintf(s_spp, sizeof s_spp, "%ld", spp);
    snprintf(s_size, sizeof s_size, "%ld", o->size);
    snprintf(s_depth, sizeof s_depth, "%ld", o->max_depth);
    snprintf(s_bounces, sizeof s_bounces, "%ld", o->max_depth - 1);
    snprintf(s_threads, sizeof s_threads, "%ld", o->threads);
    snprintf(script, sizeof script, "%s/bench/cycles/%s", DRIFT_SOURCE_DIR,
             r->gltf      ? "gltf_cycles.py"
             : r->cornell ? "cornell_cycles.py"
                          : "obj_cycles.py");
    char *blender = (char *)o->blender;
    if (!r->gltf && !r->cornell) {
        // Materials mapped from the MTL as drift reads it, roulette from the 4th vertex.
        char *argv[] = { blender,    "-b",        "--factory-startup",
                         "-noaudio", "--python",  script,
                         "--",       "--scene",   (char *)r->scene,
                         "--spp",    s_spp,       "--max-depth",
                         s_depth,    "--threads", s_threads,
                         "--width",  s_size,      "--height",
                         s_size,     "--out",     out,
                         NULL };
        return run_child(argv, log, t);
    }
    if (r->gltf) {
        char *argv[] = { blender,
                         "-b",
                         "--factory-startup",
                         "-noaudio",
                         "--python",
                         script,
                         "--",
                         "--gltf",
                         (char *)r->scene,
                         "--spp",
                         s_spp,
                         "--width",
                         s_size,
                         "--height",
                         s_size,
                         "--threads",
                         s_threads,
                         "--max-bounces",
                         s_bounces,
                         "--out",
                         out,
                         "--rr-min-bounces",
                         "1", // drift's roulette, no light threshold
                         NULL };
        return run_child(argv, log, t);
    }
    // The Cornell box's OBJ beside its .json, with drift's conventions (run_compare.sh's).
    snprintf(obj, sizeof obj, "%s", r->scene);
    char *slash = strrchr(obj, '/');
    snprintf(slash ? slash + 1 : obj, sizeof obj - (size_t)(slash ? slash + 1 - obj : 0),
             "cornell_box.obj");
    char *argv[] = { blender,
                     "-b",
                     "--factory-startup",
                     "-noaudio",
                     "--python",
                     script,
                     "--",
                     "--obj",
                     obj,
                     "--spp",
                     s_spp,
                     "--max-depth",
                     s_depth,
                     "--bounces-offset",
                     "-1",
                     "--threads",
                     s_threads,
                     "--width",
                     s_size,
                     "--height",
                     s_size,
                     "--out",
                     out,
                     "--rr-min-bounces",
                     "1", // Cycles' +1: roulette from the 4th vertex, as drift's rr_depth 3
                     "--one-sided-light",
                     "--light-diffuse",
                     NULL };
    return run_child(argv, log, t);
}

int drift_bench_cycles(int argc, char **argv)
{
    cycles_options o = { .size = 256, .spp = 64, .fit_spp = -1, .max_depth = 8, .threads = 2 };
    int status = cli_parse(&cycles_command, argc, argv, &o, NULL);
    if (status != CLI_PARSED) {
        return cli_parse_exit(status);
    }
    if (o.fit_spp < 0) {
        o.fit_spp = o.spp / 4;
    }
    if (!o.ref_spp) {
        o.ref_spp = o.spp * 4 > 256 ? o.spp * 4 : 256;
    }
    if (!o.blender) {
        o.blender = getenv("BLENDER") && *getenv("BLENDER") ? getenv("BLENDER") : "blender";
    }
    static cycles_run r;
    memset(&r, 0, sizeof r);
    const char *scene = o.scene_path[0] ? o.scene_path[0] : cli_default_scene_path();
    // An absolute path: the renders run with the same working directory, but the reference's
    // cache key must not depend on it.
    char cwd[2048] = ".";
    if (scene[0] != '/' && !getcwd(cwd, sizeof cwd)) {
        snprintf(cwd, sizeof cwd, ".");
    }
    snprintf(r.scene, sizeof r.scene, "%s%s%s", scene[0] == '/' ? "" : cwd,
             scene[0] == '/' ? "" : "/", scene);
    if (access(r.scene, R_OK) != 0) {
        fprintf(stderr, "drift bench cycles: %s: %s\n", scene, strerror(errno));
        return 2;
    }
    r.gltf = ends_with(r.scene, ".gltf") || ends_with(r.scene, ".glb");
    r.cornell = ends_with(r.scene, "/cornell_box.json");
    if (!r.gltf && !ends_with(r.scene, ".json")) {
        fprintf(stderr,
                "drift bench cycles: %s: Blender reads a drift scene .json of OBJ meshes (the "
                "Cornell box, the Breakfast Room) or a .gltf/.glb\n",
                r.scene);
        return 2;
    }
    char *version[] = { (char *)o.blender, "--version", NULL };
    if (run_child(version, NULL, NULL) != 0) {
        fprintf(stderr,
                "drift bench cycles: skipped: Blender ('%s') is not installed or does not run; "
                "scripts/install-cycles.sh installs it (exit status %d)\n",
                o.blender, BENCH_CYCLES_SKIP);
        return BENCH_CYCLES_SKIP;
    }
    char self[4096];
    ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
    if (n <= 0) {
        fprintf(stderr, "drift bench cycles: cannot find the drift binary (/proc/self/exe)\n");
        return 1;
    }
    self[n] = '\0';
    if (o.out_dir) {
        mkdirs(o.out_dir);
        snprintf(r.dir, sizeof r.dir, "%s", o.out_dir);
    } else {
        snprintf(r.dir, sizeof r.dir, "/tmp/drift-bench-cycles-XXXXXX");
        if (!mkdtemp(r.dir)) {
            fprintf(stderr, "drift bench cycles: cannot make a folder in /tmp: %s\n",
                    strerror(errno));
            return 1;
        }
    }
    char cache[4096], stats[4352], drift_log[4352];
    const char *xdg = getenv("XDG_CACHE_HOME"), *home = getenv("HOME");
    if (o.cache_dir) {
        snprintf(cache, sizeof cache, "%s", o.cache_dir);
    } else if (xdg && *xdg) {
        snprintf(cache, sizeof cache, "%s/drift/bench-cycles", xdg);
    } else {
        snprintf(cache, sizeof cache, "%s/.cache/drift/bench-cycles", home ? home : "/tmp");
    }
    mkdirs(cache);
    reference_path(&o, r.scene, cache, r.ref, sizeof r.ref);
    snprintf(r.drift_exr, sizeof r.drift_exr, "%s/drift.exr", r.dir);
    snprintf(r.cycles_exr, sizeof r.cycles_exr, "%s/cycles.exr", r.dir);
    snprintf(r.drift_lo_exr, sizeof r.drift_lo_exr, "%s/drift-fit.exr", r.dir);
    snprintf(r.cycles_lo_exr, sizeof r.cycles_lo_exr, "%s/cycles-fit.exr", r.dir);
    snprintf(r.cycles_lo_log, sizeof r.cycles_lo_log, "%s/cycles-fit.log", r.dir);
    snprintf(r.cycles_log, sizeof r.cycles_log, "%s/cycles.log", r.dir);
    snprintf(stats, sizeof stats, "%s/drift.json", r.dir);
    snprintf(drift_log, sizeof drift_log, "%s/drift.log", r.dir);

    if (access(r.ref, R_OK) != 0) {
        // Another seed than the timed render's, so the two are independent.
        char tmp[4400];
        snprintf(tmp, sizeof tmp, "%s.%ld.exr", r.ref, (long)getpid());
        if (!o.json) {
            fprintf(stderr, "drift bench cycles: rendering the %ld-spp reference into %s\n",
                    o.ref_spp, r.ref);
        }
        if (render_drift(&o, self, r.scene, o.ref_spp, "1000003", tmp, NULL, drift_log, NULL) !=
                0 ||
            rename(tmp, r.ref) != 0) {
            fprintf(stderr, "drift bench cycles: the reference render failed, see %s\n", drift_log);
            return 1;
        }
    }
    // Cycles first, then drift: the order of run_compare.sh.
    if (render_cycles(&o, &r, o.spp, r.cycles_exr, r.cycles_log, &r.cycles_process) != 0) {
        fprintf(stderr, "drift bench cycles: the Cycles render failed, see %s\n", r.cycles_log);
        return 1;
    }
    cycles_times(r.cycles_log, &r.cycles_render_s, &r.cycles_render_cpu_s, &r.blender_render_s);
    if (!isfinite(r.cycles_render_s)) {
        r.cycles_render_s = r.blender_render_s; // gltf_cycles.py: Blender's own, sync included
    }
    if (render_drift(&o, self, r.scene, o.spp, "0", r.drift_exr, stats, drift_log,
                     &r.drift_process) != 0) {
        fprintf(stderr, "drift bench cycles: the drift render failed, see %s\n", drift_log);
        return 1;
    }
    r.drift_render_s = drift_render_seconds(stats, &r.drift_render_cpu_s);
    if (!isfinite(r.cycles_render_s) || !isfinite(r.drift_render_s)) {
        fprintf(stderr, "drift bench cycles: no render time in %s or %s\n", r.cycles_log, stats);
        return 1;
    }
    // The error slope of each: relMSE ∝ spp^-k from a second, lower spp (k = 1: pure variance).
    r.drift_slope = r.cycles_slope = 1.0;
    const char *images[4] = { r.drift_exr, r.cycles_exr, r.drift_lo_exr, r.cycles_lo_exr };
    bool fit = o.fit_spp > 0 && o.fit_spp < o.spp;
    if (fit && (render_cycles(&o, &r, o.fit_spp, r.cycles_lo_exr, r.cycles_lo_log, NULL) != 0 ||
                render_drift(&o, self, r.scene, o.fit_spp, "0", r.drift_lo_exr, NULL, drift_log,
                             NULL) != 0)) {
        fprintf(stderr, "drift bench cycles: a %ld-spp render failed, see %s and %s\n", o.fit_spp,
                r.cycles_lo_log, drift_log);
        return 1;
    }
    drift_context *ctx = NULL;
    if (drift_context_create(&(drift_context_desc){ .thread_count = (uint32_t)o.threads }, &ctx) !=
        DRIFT_OK) {
        return 1;
    }
    drift_metric_report q[4];
    bool ok = compare(ctx, r.ref, images, fit ? 4 : 2, q);
    drift_context_destroy(ctx);
    if (!ok) {
        return 1;
    }
    r.drift_q = q[0];
    r.cycles_q = q[1];
    // The reference's own noise adds to every relMSE against it: drift's variance at ref_spp,
    // relMSE_drift * spp / ref_spp under 1/spp. Taken off before the slopes and the ratio.
    r.ref_noise = q[0].relmse * (double)o.spp / (double)o.ref_spp;
    double err[4];
    for (int i = 0; i < 4; ++i) {
        err[i] = q[i].relmse - r.ref_noise;
    }
    if (fit) {
        double span = log((double)o.spp / (double)o.fit_spp);
        r.drift_lo_relmse = q[2].relmse;
        r.cycles_lo_relmse = q[3].relmse;
        r.drift_slope = log(err[2] / err[0]) / span;
        r.cycles_slope = log(err[3] / err[1]) / span;
    }
    double ratio_process = r.cycles_process.wall_s / r.drift_process.wall_s;
    double ratio_render = r.cycles_render_s / r.drift_render_s;
    // Each one's render time to reach the larger of the two relMSEs, t (relMSE / e)^(1/k).
    double e = fmax(err[0], err[1]);
    double noise =
        err[0] > 0 && err[1] > 0 && r.drift_slope > 0 && r.cycles_slope > 0
            ? pow(err[1] / e, 1.0 / r.cycles_slope) / pow(err[0] / e, 1.0 / r.drift_slope)
            : (double)NAN;
    double equal_error = ratio_render * noise;
    r.ratio_process_cpu = r.cycles_process.cpu_s / r.drift_process.cpu_s;
    r.ratio_render_cpu = r.cycles_render_cpu_s / r.drift_render_cpu_s; // NAN if either is absent
    r.equal_error_cpu = r.ratio_render_cpu * noise;
    if (o.json) {
        print_json(&o, &r, ratio_process, ratio_render, equal_error);
    } else {
        print_text(&o, &r, ratio_process, ratio_render, equal_error);
    }
    return 0;
}
