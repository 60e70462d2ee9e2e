#include "cli.h"
#include "drift/accel.h"
#include "drift/file.h"
#include "drift/image_io.h"
#include "drift/knobs.h"
#include "drift/scene_io.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

bool cli_parse_int(const char *cmd, const char *flag, const char *text, long lo, long hi, long *out)
{
    char *end = NULL;
    errno = 0;
    long v = strtol(text, &end, 10);
    if (errno != 0 || end == text || *end != '\0' || v < lo || v > hi) {
        fprintf(stderr, "drift %s: %s expects an integer in [%ld, %ld], got '%s'\n", cmd, flag, lo,
                hi, text);
        return false;
    }
    *out = v;
    return true;
}

bool cli_parse_float(const char *cmd, const char *flag, const char *text, double lo, double hi,
                     double *out)
{
    char *end = NULL;
    errno = 0;
    double v = strtod(text, &end);
    if (errno != 0 || end == text || *end != '\0' || !isfinite(v) || v < lo || v > hi) {
        fprintf(stderr, "drift %s: %s expects a number in [%g, %g], got '%s'\n", cmd, flag, lo, hi,
                text);
        return false;
    }
    *out = v;
    return true;
}

bool cli_parse_technique(const char *cmd, drift_effect effect, const char *flag, const char *text,
                         int *out)
{
    int t = drift_technique_parse(effect, text);
    if (t >= 0) {
        *out = t;
        return true;
    }
    fprintf(stderr, "drift %s: %s expects one of", cmd, flag);
    for (int i = 0; i < drift_technique_count(effect); ++i) {
        fprintf(stderr, "%s %s", i ? "," : "", drift_technique_name(effect, i));
    }
    cli_suggestion s = cli_suggestion_begin(text);
    for (int i = 0; i < drift_technique_count(effect); ++i) {
        const char *name = drift_technique_name(effect, i);
        cli_suggestion_offer(&s, name, strlen(name));
    }
    char hint[96];
    fprintf(stderr, ", got '%s'%s\n", text, cli_suggestion_text(&s, hint, sizeof hint));
    return false;
}

bool cli_parse_vec3(const char *cmd, const char *flag, const char *text, bool scalar,
                    drift_vec3 *out)
{
    float a, b, c;
    char tail;
    int n = sscanf(text, "%f,%f,%f%c", &a, &b, &c, &tail);
    if (n == 1 && scalar) {
        b = c = a; // one value: grey
    }
    double m = DRIFT_SCENE_COORD_MAX; // fabs(NaN) <= m is false too
    if (!(n == 3 || (n == 1 && scalar)) ||
        !(fabs((double)a) <= m && fabs((double)b) <= m && fabs((double)c) <= m)) {
        fprintf(stderr, "drift %s: %s expects X,Y,Z%s, each within +-%g, got '%s'\n", cmd, flag,
                scalar ? " (or one number)" : "", DRIFT_SCENE_COORD_MAX, text);
        return false;
    }
    *out = drift_vec3_make(a, b, c);
    return true;
}

void cli_knobs_unset(drift_hybrid_params *params)
{
    params->techniques[DRIFT_EFFECT_INDIRECT] = CLI_TECHNIQUE_UNSET;
    params->environment_scale = 0;
}

void cli_knobs_finish(drift_hybrid_params *params, bool refine)
{
    if (params->techniques[DRIFT_EFFECT_INDIRECT] == CLI_TECHNIQUE_UNSET) {
        params->indirect =
            refine ? DRIFT_INDIRECT_NONE
                   : (drift_indirect_technique)drift_technique_default(DRIFT_EFFECT_INDIRECT);
    }
    if (params->environment_scale == 0) {
        params->environment_scale =
            params->environment_interleave ? 1 : drift_hybrid_params_default().environment_scale;
    }
}

bool cli_parse_list(const char *cmd, const char *flag, const char *text, long lo, long hi, int max,
                    long *out, int *count)
{
    long values[64];
    int n = 0;
    bool ok = max > 0 && max <= (int)(sizeof values / sizeof *values);
    for (const char *p = text; ok;) {
        char *end = NULL;
        errno = 0;
        long v = strtol(p, &end, 10);
        ok = end != p && errno == 0 && v >= lo && v <= hi && n < max &&
             (*end == ',' || *end == '\0') && *p != ' ' && *p != '+';
        if (ok) {
            values[n++] = v;
        }
        if (!ok || *end == '\0') {
            break;
        }
        p = end + 1;
    }
    if (!ok) {
        fprintf(stderr,
                "drift %s: %s expects 1 to %d comma-separated integers in [%ld, %ld], got '%s'\n",
                cmd, flag, max, lo, hi, text);
        return false;
    }
    memcpy(out, values, (size_t)n * sizeof *out);
    *count = n;
    return true;
}

bool cli_parse_refine(const char *cmd, const char *flag, const char *value, void *field)
{
    if (strcmp(value, "sir") != 0) {
        fprintf(stderr, "drift %s: %s expects 'sir', got '%s'\n", cmd, flag, value);
        return false;
    }
    *(bool *)field = true;
    return true;
}

const char *cli_next_value(const char *cmd, int argc, char **argv, int *i)
{
    if (*i + 1 >= argc) {
        fprintf(stderr, "drift %s: %s needs a value (see drift %s --help)\n", cmd, argv[*i], cmd);
        return NULL;
    }
    *i += 1;
    return argv[*i];
}

static void stderr_log(drift_log_level level, drift_result code, const char *file, int line,
                       const char *message, void *user)
{
    bool verbose = user != NULL;
    if (level < DRIFT_LOG_WARNING && !verbose) {
        return;
    }
    static const char *const names[] = { "info", "debug", "info", "warning", "error" };
    const char *name = level < DRIFT_LOG_COUNT ? names[level] : "log";
    (void)code;
    if (file && line > 0) {
        fprintf(stderr, "drift: %s:%d: %s: %s\n", file, line, name, message);
    } else if (file) {
        fprintf(stderr, "drift: %s: %s: %s\n", file, name, message);
    } else {
        fprintf(stderr, "drift: %s: %s\n", name, message);
    }
}

drift_logger cli_stderr_logger(bool verbose)
{
    // The user pointer only carries the verbose flag; any non-NULL value means verbose.
    static int verbose_marker;
    return (drift_logger){ .func = stderr_log, .user = verbose ? &verbose_marker : NULL };
}

const char *cli_default_scene_path(void)
{
    const char *env = getenv("DRIFT_DEFAULT_SCENE");
    return env && *env ? env : DRIFT_SOURCE_DIR "/scenes/cornell-box/cornell_box.json";
}

// A file's identity: its device and inode when it exists; else the folder's it would be
// made in and its name. `known` is false when neither can be found (the path is compared as
// text then).
typedef struct file_key {
    bool known, exists;
    dev_t dev;
    ino_t ino;
    const char *name; // !exists: the name in the folder
} file_key;

static file_key file_key_of(const char *path)
{
    file_key k = { 0 };
    struct stat st;
    if (stat(path, &st) == 0) {
        return (file_key){ .known = true, .exists = true, .dev = st.st_dev, .ino = st.st_ino };
    }
    const char *slash = strrchr(path, '/');
    char dir[4096];
    if (!slash) {
        snprintf(dir, sizeof dir, ".");
    } else {
        snprintf(dir, sizeof dir, "%.*s", slash == path ? 1 : (int)(slash - path), path);
    }
    if (stat(dir, &st) == 0) {
        k = (file_key){ .known = true, .dev = st.st_dev, .ino = st.st_ino };
        k.name = slash ? slash + 1 : path;
    }
    return k;
}

static bool same_file(const char *a, const char *b)
{
    file_key ka = file_key_of(a), kb = file_key_of(b);
    if (!ka.known || !kb.known) {
        return strcmp(a, b) == 0;
    }
    if (ka.exists != kb.exists || ka.dev != kb.dev || ka.ino != kb.ino) {
        return false;
    }
    return ka.exists || strcmp(ka.name, kb.name) == 0;
}

bool cli_check_outputs(const char *cmd, const cli_file *inputs, size_t input_count,
                       const cli_file *outputs, size_t output_count)
{
    for (size_t i = 0; i < output_count; ++i) {
        const cli_file *out = &outputs[i];
        if (!out->path) {
            continue;
        }
        for (size_t j = 0; j < input_count; ++j) {
            if (inputs[j].path && same_file(out->path, inputs[j].path)) {
                fprintf(stderr,
                        "drift %s: %s '%s' is the input %s '%s'; refusing to overwrite it, "
                        "nothing written\n",
                        cmd, out->flag, out->path, inputs[j].flag, inputs[j].path);
                return false;
            }
        }
        for (size_t j = 0; j < i; ++j) {
            if (outputs[j].path && same_file(out->path, outputs[j].path)) {
                fprintf(stderr,
                        "drift %s: %s '%s' and %s '%s' are the same file; nothing written\n", cmd,
                        outputs[j].flag, outputs[j].path, out->flag, out->path);
                return false;
            }
        }
    }
    return true;
}

bool cli_check_writable(const char *cmd, const cli_file *outputs, size_t output_count)
{
    for (size_t i = 0; i < output_count; ++i) {
        const char *path = outputs[i].path;
        if (!path) {
            continue;
        }
        const char *slash = strrchr(path, '/');
        char dir[4096];
        snprintf(dir, sizeof dir, "%.*s", slash ? (slash == path ? 1 : (int)(slash - path)) : 1,
                 slash ? path : ".");
        struct stat st;
        const char *why = NULL;
        if (stat(dir, &st) != 0) {
            why = strerror(errno);
        } else if (!S_ISDIR(st.st_mode)) {
            why = strerror(ENOTDIR);
        } else if (access(dir, W_OK) != 0) {
            why = strerror(errno);
        } else if (stat(path, &st) == 0 && S_ISDIR(st.st_mode)) {
            why = strerror(EISDIR);
        }
        if (why) {
            fprintf(stderr, "drift %s: cannot write %s '%s': %s; nothing written\n", cmd,
                    outputs[i].flag, path, why);
            return false;
        }
    }
    return true;
}

static void note_scene_input(const char *path, void *user)
{
    cli_session *s = user;
    char **grown = realloc(s->scene_inputs, (s->scene_input_count + 1) * sizeof *grown);
    char *copy = strdup(path);
    if (!grown || !copy) {
        free(copy);
        if (grown) {
            s->scene_inputs = grown;
        }
        return;
    }
    s->scene_inputs = grown;
    s->scene_inputs[s->scene_input_count++] = copy;
}

static void free_scene_inputs(cli_session *s)
{
    for (size_t i = 0; i < s->scene_input_count; ++i) {
        free(s->scene_inputs[i]);
    }
    free(s->scene_inputs);
    s->scene_inputs = NULL;
    s->scene_input_count = 0;
}

// The session's outputs against the scene's files and the other inputs (cli_session_desc).
static bool check_session_outputs(const cli_session_desc *desc, cli_session *s)
{
    size_t count = s->scene_input_count + desc->input_count;
    cli_file *inputs = calloc(count ? count : 1, sizeof *inputs);
    if (!inputs) {
        fprintf(stderr, "drift %s: out of memory\n", desc->cmd);
        return false;
    }
    for (size_t i = 0; i < s->scene_input_count; ++i) {
        inputs[i] = (cli_file){ i == 0 ? "SCENE" : "file the scene reads", s->scene_inputs[i] };
    }
    for (size_t i = 0; i < desc->input_count; ++i) {
        inputs[s->scene_input_count + i] = desc->inputs[i];
    }
    bool ok = cli_check_outputs(desc->cmd, inputs, count, desc->outputs, desc->output_count);
    free(inputs);
    s->refused = !ok;
    return ok && cli_check_writable(desc->cmd, desc->outputs, desc->output_count);
}

static drift_context *open_context(const char *cmd, int threads, bool verbose)
{
    drift_context *ctx = NULL;
    drift_result r = drift_context_create(
        &(drift_context_desc){ .thread_count = threads, .logger = cli_stderr_logger(verbose) },
        &ctx);
    if (r != DRIFT_OK) {
        fprintf(stderr, "drift %s: %s\n", cmd, drift_result_string(r));
        return NULL;
    }
    return ctx;
}

static bool build_accel(cli_session *s, const char *cmd)
{
    drift_result r = drift_accel_create(s->ctx, s->scene, &(drift_accel_desc){ 0 }, &s->accel);
    if (r != DRIFT_OK) {
        fprintf(stderr, "drift %s: cannot build the ray-tracing structure: %s\n", cmd,
                drift_result_string(r));
        return false;
    }
    s->t_built = drift_time_now();
    return true;
}

// --environment: the scene's environment replaced by a lat-long image or a constant colour
// (times the strength), and the scene committed again (its light table samples it). glTF files
// carry no world, so this is how a Blender user's HDRI comes back.
static bool apply_environment(cli_session *s, const char *cmd)
{
    if (!s->environment) {
        return true;
    }
    double strength = s->environment_strength > 0.0 ? s->environment_strength : 1.0;
    drift_environment env = { .texture = DRIFT_INVALID_INDEX };
    char *end = NULL;
    (void)strtod(s->environment, &end);
    if (end != s->environment) { // starts with a number: a colour
        if (!cli_parse_vec3(cmd, "--environment", s->environment, true, &env.color)) {
            return false;
        }
        if (env.color.x < 0.0f || env.color.y < 0.0f || env.color.z < 0.0f) {
            fprintf(stderr, "drift %s: --environment expects a colour >= 0, got '%s'\n", cmd,
                    s->environment);
            return false;
        }
        env.color = drift_vec3_scale(env.color, (float)strength);
    } else {
        note_scene_input(s->environment, s); // an output may not overwrite it
        drift_image map;
        if (drift_image_load(s->ctx, s->environment, &map) != DRIFT_OK) {
            fprintf(stderr, "drift %s: cannot read --environment %s (see above)\n", cmd,
                    s->environment);
            return false;
        }
        if (drift_scene_add_texture(s->scene, map, &env.texture) != DRIFT_OK) {
            drift_image_destroy(s->ctx, &map);
            fprintf(stderr, "drift %s: --environment %s: out of memory\n", cmd, s->environment);
            return false;
        }
        env.color = drift_vec3_splat((float)strength);
    }
    s->scene->environment = env;
    if (s->scene->default_lights) { // the loader's stand-in sun goes with its environment
        s->scene->light_count = 0;
        s->scene->default_lights = false;
    }
    if (drift_scene_commit(s->scene) != DRIFT_OK) {
        fprintf(stderr, "drift %s: the scene with --environment %s is not valid (see above)\n", cmd,
                s->environment);
        return false;
    }
    return true;
}

bool cli_session_load(cli_session *s, const char *cmd, const char *path, bool no_accel)
{
    drift_accel_destroy(s->accel);
    drift_scene_destroy(s->scene);
    s->accel = NULL;
    s->scene = NULL;
    snprintf(s->path, sizeof s->path, "%s", path);
    s->scene_path = s->path;
    free_scene_inputs(s);
    drift_result r =
        drift_scene_load_camera(s->ctx, s->path, s->camera, note_scene_input, s, &s->scene);
    if (r != DRIFT_OK) {
        fprintf(stderr, "drift %s: cannot load scene %s: %s\n", cmd, s->path,
                drift_result_string(r));
        return false;
    }
    if (!apply_environment(s, cmd)) {
        return false;
    }
    s->t_loaded = drift_time_now();
    return no_accel ? (s->t_built = drift_time_now(), true) : build_accel(s, cmd);
}

bool cli_session_open(const cli_session_desc *desc, cli_session *s)
{
    *s = (cli_session){ .t_start = drift_time_now(),
                        .camera = desc->camera,
                        .environment = desc->environment,
                        .environment_strength = desc->environment_strength };
    s->ctx = open_context(desc->cmd, desc->threads, desc->verbose);
    if (!s->ctx) {
        return false;
    }
    if (desc->no_scene) {
        return true;
    }
    const char *path = desc->scene_path      ? desc->scene_path
                       : desc->default_scene ? desc->default_scene
                                             : cli_default_scene_path();
    if (desc->output_count > 0 || desc->input_count > 0) {
        // The files are known once the scene is read; the accel waits for the check.
        return cli_session_load(s, desc->cmd, path, true) && check_session_outputs(desc, s) &&
               (desc->no_accel || build_accel(s, desc->cmd));
    }
    return cli_session_load(s, desc->cmd, path, desc->no_accel);
}

uint64_t cli_fnv1a(uint64_t h, const void *data, size_t size)
{
    const uint8_t *p = data;
    for (size_t i = 0; i < size; ++i) {
        h = (h ^ p[i]) * 0x100000001b3ull;
    }
    return h;
}

bool cli_hash_files(const char *const *paths, size_t count, uint64_t *out)
{
    uint64_t h = CLI_FNV_BASIS;
    for (size_t i = 0; i < count; ++i) {
        if (!paths[i]) {
            continue;
        }
        char why[128];
        FILE *f = drift_input_fopen(paths[i], why, sizeof why);
        if (!f) {
            return false;
        }
        uint8_t buf[1 << 16];
        size_t n;
        while ((n = fread(buf, 1, sizeof buf, f)) > 0) {
            h = cli_fnv1a(h, buf, n);
        }
        bool ok = !ferror(f);
        fclose(f);
        if (!ok) {
            return false;
        }
        h = cli_fnv1a(h, "\0", 1); // file boundaries count
    }
    *out = h;
    return true;
}

void cli_session_close(cli_session *s)
{
    drift_accel_destroy(s->accel);
    drift_scene_destroy(s->scene);
    drift_context_destroy(s->ctx);
    free_scene_inputs(s);
    *s = (cli_session){ 0 };
}

static void print_subcommands(FILE *out, const char *cmd, const char *heading, const char *footer,
                              const cli_subcommand *table, size_t count)
{
    fprintf(out, "usage: drift %s%s<%s> [options]\n\n%s:\n", cmd ? cmd : "", cmd ? " " : "",
            cmd ? "name" : "command", heading);
    for (size_t i = 0; i < count; ++i) {
        fprintf(out, "  %-10s %s\n", table[i].name, table[i].summary);
    }
    fprintf(out, "\n%s", footer);
}

// --help-markdown: the list as a Markdown table, then each entry's own --help-markdown
// (docs/reference/cli.md, scripts/gen-reference.sh).
static int print_subcommands_markdown(const char *cmd, const char *heading,
                                      const cli_subcommand *table, size_t count)
{
    printf("## drift%s%s\n\n```text\nusage: drift %s%s<%s> [options]\n```\n\n| %s | |\n|---|---|\n",
           cmd ? " " : "", cmd ? cmd : "", cmd ? cmd : "", cmd ? " " : "", cmd ? "name" : "command",
           heading);
    for (size_t i = 0; i < count; ++i) {
        printf("| [`%s`](#drift-%s%s%s) | %s |\n", table[i].name, cmd ? cmd : "", cmd ? "-" : "",
               table[i].name, table[i].summary);
    }
    printf("\n");
    int status = 0;
    for (size_t i = 0; i < count; ++i) {
        char *args[] = { (char *)table[i].name, "--help-markdown", NULL };
        printf("<a id=\"drift-%s%s%s\"></a>\n\n", cmd ? cmd : "", cmd ? "-" : "", table[i].name);
        fflush(stdout);
        status |= table[i].run(2, args);
    }
    return status;
}

int cli_dispatch(const char *cmd, const char *heading, const char *footer,
                 const cli_subcommand *table, size_t count, int argc, char **argv)
{
    if (argc == 2 && strcmp(argv[1], "--help-markdown") == 0) {
        return print_subcommands_markdown(cmd, heading, table, count);
    }
    if (argc == 2 && !cmd && strcmp(argv[1], "--knobs-markdown") == 0) {
        cli_print_knobs_markdown(stdout); // docs/reference/knobs.md
        return 0;
    }
    if (argc == 2 && !cmd && strcmp(argv[1], "--formats-markdown") == 0) {
        drift_scene_formats_markdown(stdout); // docs/reference/scene-formats.md
        return 0;
    }
    if (argc < 2 || strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0) {
        print_subcommands(argc < 2 ? stderr : stdout, cmd, heading, footer, table, count);
        return argc < 2 ? 2 : 0;
    }
    for (size_t i = 0; i < count; ++i) {
        if (strcmp(argv[1], table[i].name) == 0) {
            return table[i].run(argc - 1, argv + 1);
        }
    }
    cli_suggestion s = cli_suggestion_begin(argv[1]);
    for (size_t i = 0; i < count; ++i) {
        cli_suggestion_offer(&s, table[i].name, strlen(table[i].name));
    }
    char hint[96];
    fprintf(stderr, "drift%s%s: unknown %s '%s'%s\n\n", cmd ? " " : "", cmd ? cmd : "",
            cmd ? "benchmark" : "command", argv[1], cli_suggestion_text(&s, hint, sizeof hint));
    print_subcommands(stderr, cmd, heading, footer, table, count);
    return 2;
}
