// The option-table parser and help printer (tools/cli_options.h).
#include "cli_options.h"

#include "cli.h"
#include "drift/hybrid.h"
#include "drift/knobs.h"
#include "drift/scene_io.h"

#include <stdint.h>
#include <stdio.h>
#include <string.h>

cli_suggestion cli_suggestion_begin(const char *given)
{
    return (cli_suggestion){ .given = given, .distance = 1 << 20 };
}

// The optimal-string-alignment distance between a[0 .. n) and b[0 .. m) (both < 64).
static int edit_distance(const char *a, size_t n, const char *b, size_t m)
{
    int d[64][64];
    for (size_t i = 0; i <= n; ++i) {
        d[i][0] = (int)i;
    }
    for (size_t j = 0; j <= m; ++j) {
        d[0][j] = (int)j;
    }
    for (size_t i = 1; i <= n; ++i) {
        for (size_t j = 1; j <= m; ++j) {
            int cost = a[i - 1] != b[j - 1];
            int best = d[i - 1][j - 1] + cost;
            best = d[i - 1][j] + 1 < best ? d[i - 1][j] + 1 : best;
            best = d[i][j - 1] + 1 < best ? d[i][j - 1] + 1 : best;
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] &&
                d[i - 2][j - 2] + 1 < best) {
                best = d[i - 2][j - 2] + 1;
            }
            d[i][j] = best;
        }
    }
    return d[n][m];
}

void cli_suggestion_offer(cli_suggestion *s, const char *candidate, size_t length)
{
    size_t n = strlen(s->given);
    if (n >= 64 || length >= 64 || length == 0) {
        return;
    }
    int d = edit_distance(s->given, n, candidate, length);
    if (d < s->distance) {
        s->distance = d;
        snprintf(s->best, sizeof s->best, "%.*s", (int)length, candidate);
    }
}

const char *cli_suggestion_text(const cli_suggestion *s, char *buffer, size_t size)
{
    int limit = (int)strlen(s->given) / 3;
    limit = limit > 2 ? limit : 2;
    if (s->distance > 0 && s->distance <= limit) {
        snprintf(buffer, size, " (did you mean '%s'?)", s->best);
    } else {
        snprintf(buffer, size, "%s", "");
    }
    return buffer;
}

// Offers each ", "-separated name of `names`.
static void offer_names(cli_suggestion *s, const char *names)
{
    for (const char *p = names; p && *p;) {
        const char *end = strstr(p, ", ");
        cli_suggestion_offer(s, p, end ? (size_t)(end - p) : strlen(p));
        p = end ? end + 2 : NULL;
    }
}

// Offers each "|"-separated choice of `choices`.
static void offer_choices(cli_suggestion *s, const char *choices)
{
    for (const char *p = choices; p;) {
        const char *end = strchr(p, '|');
        cli_suggestion_offer(s, p, end ? (size_t)(end - p) : strlen(p));
        p = end ? end + 1 : NULL;
    }
}

// The nearest option name of the command to `arg` (technique rows: --<effect>).
static const char *suggest_option(const cli_command *c, const char *arg, char *buffer, size_t size)
{
    cli_suggestion s = cli_suggestion_begin(arg);
    for (size_t k = 0; k < c->option_count; ++k) {
        const cli_option *opt = &c->options[k];
        if (opt->kind == CLI_KIND_SECTION || opt->kind == CLI_KIND_NOTE) {
            continue;
        }
        if (opt->kind == CLI_KIND_TECHNIQUES && !opt->name) {
            for (int e = 0; e < DRIFT_EFFECT_COUNT; ++e) {
                char name[64];
                int n = snprintf(name, sizeof name, "--%s", drift_effect_name((drift_effect)e));
                cli_suggestion_offer(&s, name, (size_t)n);
            }
        } else if (opt->name) {
            offer_names(&s, opt->name);
        }
    }
    cli_suggestion_offer(&s, "--help", 6);
    return cli_suggestion_text(&s, buffer, size);
}

// Whether `arg` is one of the ", "-separated names of `names`.
static bool name_matches(const char *names, const char *arg)
{
    size_t len = strlen(arg);
    const char *p = names;
    while (p && *p) {
        const char *end = strstr(p, ", ");
        size_t n = end ? (size_t)(end - p) : strlen(p);
        if (n == len && strncmp(p, arg, n) == 0) {
            return true;
        }
        p = end ? end + 2 : NULL;
    }
    return false;
}

static bool store_long(void *field, cli_store store, long v)
{
    switch (store) {
    case CLI_STORE_LONG:
        *(long *)field = v;
        return true;
    case CLI_STORE_INT:
        *(int *)field = (int)v;
        return true;
    case CLI_STORE_UINT:
        *(unsigned *)field = (unsigned)v;
        return true;
    case CLI_STORE_DOUBLE:
        *(double *)field = (double)v;
        return true;
    case CLI_STORE_FLOAT:
        *(float *)field = (float)v;
        return true;
    case CLI_STORE_BOOL:
        *(bool *)field = v != 0;
        return true;
    case CLI_STORE_NONE:
    case CLI_STORE_STRING:
        break;
    }
    return false;
}

static bool store_double(void *field, cli_store store, double v)
{
    switch (store) {
    case CLI_STORE_DOUBLE:
        *(double *)field = v;
        return true;
    case CLI_STORE_FLOAT:
        *(float *)field = (float)v;
        return true;
    default:
        return false;
    }
}

// The index of `value` in "a|b|c", or -1.
static int choice_index(const char *choices, const char *value)
{
    size_t len = strlen(value);
    int index = 0;
    for (const char *p = choices; p; ++index) {
        const char *end = strchr(p, '|');
        size_t n = end ? (size_t)(end - p) : strlen(p);
        if (n == len && strncmp(p, value, n) == 0) {
            return index;
        }
        p = end ? end + 1 : NULL;
    }
    return -1;
}

// "a, b or c"
static void print_choices(FILE *out, const char *choices)
{
    for (const char *p = choices; p;) {
        const char *end = strchr(p, '|');
        size_t n = end ? (size_t)(end - p) : strlen(p);
        const char *next = end ? strchr(end + 1, '|') : NULL;
        fprintf(out, "%.*s%s", (int)n, p, !end ? "" : next ? ", " : " or ");
        p = end ? end + 1 : NULL;
    }
}

// Parses `value` for row `opt` into opts (the message names cmd, flag and value).
static bool read_value(const char *cmd, const char *flag, const cli_option *opt, int effect,
                       const char *value, void *opts)
{
    void *field = (char *)opts + opt->offset;
    switch (opt->kind) {
    case CLI_KIND_FLAG:
        return store_long(field, opt->store, 1);
    case CLI_KIND_INT: {
        long v = 0;
        return cli_parse_int(cmd, flag, value, (long)opt->lo, (long)opt->hi, &v) &&
               store_long(field, opt->store, v);
    }
    case CLI_KIND_NUMBER: {
        double v = 0.0;
        return cli_parse_float(cmd, flag, value, opt->lo, opt->hi, &v) &&
               store_double(field, opt->store, v);
    }
    case CLI_KIND_STRING:
        *(const char **)field = value;
        return true;
    case CLI_KIND_CHOICE: {
        int index = choice_index(opt->choices, value);
        if (index < 0) {
            fprintf(stderr, "drift %s: %s expects ", cmd, flag);
            print_choices(stderr, opt->choices);
            cli_suggestion s = cli_suggestion_begin(value);
            offer_choices(&s, opt->choices);
            char hint[96];
            fprintf(stderr, ", got '%s'%s\n", value, cli_suggestion_text(&s, hint, sizeof hint));
            return false;
        }
        return store_long(field, opt->store, index);
    }
    case CLI_KIND_TECHNIQUES: {
        int t = 0;
        if (!cli_parse_technique(cmd, (drift_effect)effect, flag, value, &t)) {
            return false;
        }
        drift_hybrid_params_set_technique(field, (drift_effect)effect, t);
        return true;
    }
    case CLI_KIND_KNOBS: {
        const drift_knob *knob = drift_knob_get(effect);
        double v = 0.0;
        if (!drift_knob_parse(knob, value, &v)) {
            char expects[256];
            drift_knob_expects(knob, expects, sizeof expects);
            fprintf(stderr, "drift %s: %s expects %s, got '%s'\n", cmd, flag, expects, value);
            return false;
        }
        return drift_knob_set(field, effect, v);
    }
    case CLI_KIND_CUSTOM:
        return opt->parse(cmd, flag, value, field);
    case CLI_KIND_SECTION:
    case CLI_KIND_NOTE:
        break;
    }
    return false;
}

// The effect `arg` (--shadows, ...) names, or -1.
static int effect_of(const char *arg)
{
    for (int e = 0; e < DRIFT_EFFECT_COUNT; ++e) {
        if (strncmp(arg, "--", 2) == 0 &&
            strcmp(arg + 2, drift_effect_name((drift_effect)e)) == 0) {
            return e;
        }
    }
    return -1;
}

// Whether a CLI_TECHNIQUE row of the command names the effect `e` on its own.
static bool effect_has_own_row(const cli_command *c, int e)
{
    char name[64];
    snprintf(name, sizeof name, "--%s", drift_effect_name((drift_effect)e));
    for (size_t k = 0; k < c->option_count; ++k) {
        const cli_option *opt = &c->options[k];
        if (opt->kind == CLI_KIND_TECHNIQUES && opt->name && strcmp(opt->name, name) == 0) {
            return true;
        }
    }
    return false;
}

// The effect a technique row takes `arg` for, or -1: its own effect (CLI_TECHNIQUE), or any
// effect without a row of its own (CLI_TECHNIQUES).
static int technique_row_effect(const cli_command *c, const cli_option *opt, const char *arg)
{
    int e = effect_of(arg);
    if (e < 0 || opt->kind != CLI_KIND_TECHNIQUES) {
        return -1;
    }
    if (opt->name) {
        return strcmp(opt->name, arg) == 0 ? e : -1;
    }
    return effect_has_own_row(c, e) ? -1 : e;
}

// The knob `arg` (--ism-vpls, ...) names, or -1.
static int knob_of(const char *arg)
{
    return strncmp(arg, "--", 2) == 0 ? drift_knob_find(arg + 2) : -1;
}

// The row for `arg`, the groups of the section it is in and, for technique rows, the effect
// (for the knob row, the knob's index).
static const cli_option *find_option(const cli_command *c, const char *arg, unsigned *groups,
                                     int *effect)
{
    unsigned section = 0;
    for (size_t k = 0; k < c->option_count; ++k) {
        const cli_option *opt = &c->options[k];
        *effect = technique_row_effect(c, opt, arg);
        if (opt->kind == CLI_KIND_SECTION) {
            section = opt->groups;
        } else if (opt->kind == CLI_KIND_KNOBS && knob_of(arg) >= 0) {
            *effect = knob_of(arg);
            *groups = section;
            return opt;
        } else if (*effect >= 0 || (opt->kind != CLI_KIND_TECHNIQUES && opt->name &&
                                    name_matches(opt->name, arg))) {
            *groups = section;
            return opt;
        }
    }
    return NULL;
}

int cli_parse(const cli_command *c, int argc, char **argv, void *opts,
              const char *first_in_group[CLI_GROUP_COUNT])
{
    int positional_count = 0;
    const char **positionals = (const char **)((char *)opts + c->positional_offset);
    for (int i = 1; i < argc; ++i) {
        const char *a = argv[i];
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            cli_print_help(c, stdout);
            return CLI_HELP_SHOWN;
        }
        if (strcmp(a, "--help-markdown") == 0) { // docs/reference/cli.md
            cli_print_markdown(c, stdout);
            return CLI_HELP_SHOWN;
        }
        if (a[0] != '-' || a[1] == '\0') {
            if (!c->positional) {
                fprintf(stderr, "drift %s: unexpected argument '%s' (see drift %s --help)\n",
                        c->name, a, c->name);
                return CLI_USAGE_ERROR;
            }
            if (positional_count == c->positional_max) {
                fprintf(stderr, "drift %s: at most %d %s (got '%s' too; see drift %s --help)\n",
                        c->name, c->positional_max, c->positional, a, c->name);
                return CLI_USAGE_ERROR;
            }
            positionals[positional_count++] = a;
            continue;
        }
        unsigned groups = 0;
        int effect = -1;
        const cli_option *opt = find_option(c, a, &groups, &effect);
        if (!opt) {
            char hint[96];
            fprintf(stderr, "drift %s: unknown option '%s'%s (see drift %s --help)\n", c->name, a,
                    suggest_option(c, a, hint, sizeof hint), c->name);
            return CLI_USAGE_ERROR;
        }
        for (int g = 0; first_in_group && g < CLI_GROUP_COUNT; ++g) {
            if ((groups & (1u << g)) && !first_in_group[g]) {
                first_in_group[g] = a;
            }
        }
        const char *value = NULL;
        if (opt->optional_if) {
            const char *next = i + 1 < argc ? argv[i + 1] : NULL;
            size_t n = next ? strlen(next) : 0, m = strlen(opt->optional_if);
            if (next && next[0] != '-' && n > m && strcmp(next + n - m, opt->optional_if) == 0) {
                value = argv[++i];
            }
        } else if ((opt->arg || opt->kind == CLI_KIND_KNOBS) &&
                   !(value = cli_next_value(c->name, argc, argv, &i))) {
            return CLI_USAGE_ERROR;
        }
        if (!read_value(c->name, a, opt, effect, value, opts)) {
            return CLI_USAGE_ERROR;
        }
    }
    return CLI_PARSED;
}

int cli_parse_exit(int status)
{
    return status == CLI_HELP_SHOWN ? 0 : status == CLI_PARSED ? -1 : CLI_USAGE_ERROR;
}

// Prints `text` with every line after the first indented to `column`.
static void print_indented(FILE *out, const char *text, int column)
{
    for (const char *p = text; *p;) {
        const char *end = strchr(p, '\n');
        int n = end ? (int)(end - p) : (int)strlen(p);
        fprintf(out, "%.*s\n", n, p);
        if (!end) {
            return;
        }
        p = end + 1;
        fprintf(out, "%*s", column, "");
    }
}

// "hard (default), pcf, pcss or aaf": the default is drift_technique_default's.
static void print_techniques(FILE *out, drift_effect effect)
{
    if (drift_technique_count(effect) < 1) {
        fprintf(out, "(none)\n");
        return;
    }
    int count = drift_technique_count(effect);
    for (int t = 0; t < count; ++t) {
        fprintf(out, "%s%s%s",
                t == 0          ? ""
                : t + 1 < count ? ", "
                                : " or ",
                drift_technique_name(effect, t),
                t == drift_technique_default(effect) ? " (default)" : "");
    }
    fprintf(out, "\n");
}

// Every technique with its one-line summary, from the technique table.
static void print_technique_table(FILE *out)
{
    fprintf(out, "\ntechniques (include/drift/techniques.h):\n");
    for (int e = 0; e < DRIFT_EFFECT_COUNT; ++e) {
        for (int t = 0; t < drift_technique_count((drift_effect)e); ++t) {
            char label[64];
            snprintf(label, sizeof label, "%s %s", drift_effect_name((drift_effect)e),
                     drift_technique_name((drift_effect)e, t));
            fprintf(out, "  %-22s%s\n", label, drift_technique_summary((drift_effect)e, t));
        }
    }
}

// "  --spp N" padded to `column` (or followed by two spaces when longer).
static void print_label(FILE *out, const char *name, const char *arg, int column)
{
    char label[128];
    snprintf(label, sizeof label, "%s%s%s", name, arg ? " " : "", arg ? arg : "");
    int len = (int)strlen(label) + 2;
    fprintf(out, "  %s%*s", label, len < column ? column - len : 2, "");
}

// Every knob, under its family's title: the label, the row's help, and its default, unit and
// range.
static void print_knobs(FILE *out, int column)
{
    const char *family = NULL;
    for (int i = 0, n = drift_knob_count(); i < n; ++i) {
        const drift_knob *k = drift_knob_get(i);
        if (!family || strcmp(family, k->family) != 0) {
            family = k->family;
            fprintf(out, "  %s:\n", drift_knob_family_title(family));
        }
        char name[64];
        snprintf(name, sizeof name, "--%s", k->name);
        if ((int)(strlen(name) + strlen(k->arg) + 3) >= column) { // its help on the next line
            fprintf(out, "  %s %s\n%*s", name, k->arg, column, "");
        } else {
            print_label(out, name, k->arg, column);
        }
        print_indented(out, k->help, column);
        char def[64], range[128] = "";
        drift_knob_format(k, k->def, def, sizeof def);
        if (k->type != DRIFT_KNOB_CHOICE) {
            snprintf(range, sizeof range, "; %.9g..%.9g%s%s", k->lo, k->hi, *k->unit ? " " : "",
                     k->unit);
        }
        fprintf(out, "%*s(default %s%s%s%s)\n", column, "", def, k->default_text ? ": " : "",
                k->default_text ? k->default_text : "", range);
    }
}

bool cli_takes_scene(const cli_command *c)
{
    return c->positional && strcmp(c->positional, "SCENE") == 0;
}

void cli_print_scene_formats(FILE *out)
{
    fprintf(out, "SCENE is a file of one of these formats, by its extension:\n");
    for (int i = 0; drift_scene_format_get(i); ++i) {
        const drift_scene_format *f = drift_scene_format_get(i);
        char label[32];
        snprintf(label, sizeof label, ".%s%s", f->extension, f->gz ? "[.gz]" : "");
        fprintf(out, "  %-11s %s\n", label, f->summary);
    }
    fprintf(out, "\n");
}

void cli_print_help(const cli_command *c, FILE *out)
{
    int column = c->help_column > 0 ? c->help_column : 24;
    fputs(c->usage, out);
    if (cli_takes_scene(c)) {
        cli_print_scene_formats(out);
    }
    bool first_section = true;
    for (size_t k = 0; k < c->option_count; ++k) {
        const cli_option *opt = &c->options[k];
        if (opt->kind == CLI_KIND_SECTION) {
            fprintf(out, "%s%s\n", first_section ? "" : "\n", opt->help);
            first_section = false;
            continue;
        }
        if (opt->kind == CLI_KIND_NOTE) {
            fprintf(out, "%*s", column, "");
            print_indented(out, opt->help, column);
            continue;
        }
        if (opt->kind == CLI_KIND_TECHNIQUES && opt->name) {
            print_label(out, opt->name, opt->arg, column);
            print_techniques(out, (drift_effect)effect_of(opt->name));
            if (opt->help) {
                fprintf(out, "%*s", column, "");
                print_indented(out, opt->help, column);
            }
        } else if (opt->kind == CLI_KIND_TECHNIQUES) {
            for (int e = 0; e < DRIFT_EFFECT_COUNT; ++e) {
                if (effect_has_own_row(c, e)) {
                    continue; // printed at its own row
                }
                char name[64];
                snprintf(name, sizeof name, "--%s", drift_effect_name((drift_effect)e));
                print_label(out, name, opt->arg, column);
                print_techniques(out, (drift_effect)e);
            }
        } else if (opt->kind == CLI_KIND_KNOBS) {
            print_knobs(out, column);
        } else if (opt->help) { // no help: a hidden alias
            print_label(out, opt->name, opt->arg, column);
            print_indented(out, opt->help, column);
        }
    }
    print_label(out, "-h, --help", NULL, column);
    fprintf(out, "this text\n");
    for (size_t k = 0; k < c->option_count; ++k) {
        if (c->options[k].kind == CLI_KIND_TECHNIQUES) {
            print_technique_table(out);
            break;
        }
    }
    if (c->more_help) {
        c->more_help(out);
    }
    if (c->epilogue) {
        fputs(c->epilogue, out);
    }
}
