// The command line's references as Markdown, from the same tables as --help: a command's
// option table (cli_print_markdown, `drift COMMAND --help-markdown`) and the knob table of
// drift/knobs.h (cli_print_knobs_markdown, `drift --knobs-markdown`).
// scripts/gen-reference.sh writes docs/reference/cli.md and knobs.md with them, and
// tests/cli/test_reference_docs.sh fails when the committed pages differ.
#include "cli_options.h"
#include "drift/hybrid.h"
#include "drift/knobs.h"

#include <string.h>

// `text` in a table cell: '|', '<', '>', '*', '_' and '\' escaped, a line break and the
// indentation after it as one space.
static void md_cell(FILE *out, const char *text)
{
    for (const char *p = text; p && *p; ++p) {
        if (*p == '\n') {
            fputc(' ', out);
            while (p[1] == ' ') {
                ++p;
            }
        } else if (*p == '<') {
            fputs("&lt;", out);
        } else if (*p == '>') {
            fputs("&gt;", out);
        } else {
            if (strchr("|*_\\", *p)) {
                fputc('\\', out);
            }
            fputc(*p, out);
        }
    }
}

// `text` as code in a table cell ('|' escaped, as GitHub's tables need), or nothing for "".
static void md_code(FILE *out, const char *text)
{
    if (!text || !*text) {
        return;
    }
    fputc('`', out);
    for (const char *p = text; *p; ++p) {
        if (*p == '|') {
            fputc('\\', out);
        }
        fputc(*p, out);
    }
    fputc('`', out);
}

static void md_option_header(FILE *out)
{
    fprintf(out, "| option | argument | description |\n|---|---|---|\n");
}

// "hard (default), pcf, pcss or aaf" (drift_technique_default marks the default).
static void md_techniques(FILE *out, drift_effect effect)
{
    int count = drift_technique_count(effect);
    for (int t = 0; t < count; ++t) {
        fprintf(out, "%s", t == 0 ? "" : t + 1 < count ? ", " : " or ");
        md_code(out, drift_technique_name(effect, t));
        fprintf(out, "%s", t == drift_technique_default(effect) ? " (default)" : "");
    }
    if (count < 1) {
        fprintf(out, "(none)");
    }
}

// Whether the command has a CLI_TECHNIQUE row of its own for effect `e`.
static bool own_row(const cli_command *c, int e)
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

// The effect --<name> names, or -1.
static int effect_named(const char *option)
{
    for (int e = 0; e < DRIFT_EFFECT_COUNT; ++e) {
        if (strcmp(option + 2, drift_effect_name((drift_effect)e)) == 0) {
            return e;
        }
    }
    return -1;
}

// One option's row (a CLI_TECHNIQUES row: one for each effect without a row of its own).
static void md_option(FILE *out, const cli_command *c, const cli_option *opt)
{
    if (opt->kind == CLI_KIND_TECHNIQUES && !opt->name) {
        for (int e = 0; e < DRIFT_EFFECT_COUNT; ++e) {
            if (own_row(c, e)) {
                continue;
            }
            fprintf(out, "| `--%s` | ", drift_effect_name((drift_effect)e));
            md_code(out, opt->arg);
            fprintf(out, " | ");
            md_techniques(out, (drift_effect)e);
            fprintf(out, " |\n");
        }
        return;
    }
    if (opt->kind == CLI_KIND_KNOBS) {
        fprintf(out, "| `--KNOB` | `V` | every technique knob of the "
                     "[knob reference](knobs.md), e.g. `--ism-vpls 2048` |\n");
        return;
    }
    if (!opt->help && opt->kind != CLI_KIND_TECHNIQUES) {
        return; // a hidden alias
    }
    fprintf(out, "| ");
    md_code(out, opt->name);
    fprintf(out, " | ");
    md_code(out, opt->arg);
    fprintf(out, " | ");
    if (opt->kind == CLI_KIND_TECHNIQUES) {
        int e = effect_named(opt->name);
        md_techniques(out, (drift_effect)(e < 0 ? 0 : e));
        fprintf(out, opt->help ? "; " : "");
    }
    md_cell(out, opt->help);
    fprintf(out, " |\n");
}

void cli_print_markdown(const cli_command *c, FILE *out)
{
    fprintf(out, "## drift %s\n\n```text\n", c->name);
    fputs(c->usage, out);
    if (cli_takes_scene(c)) {
        cli_print_scene_formats(out);
    }
    fprintf(out, "```\n\n");
    bool table = false;
    for (size_t k = 0; k < c->option_count; ++k) {
        const cli_option *opt = &c->options[k];
        if (opt->kind == CLI_KIND_NOTE) { // a row of its own, as its own lines in --help
            fprintf(out, "|  |  | ");
            md_cell(out, opt->help);
            fprintf(out, " |\n");
            continue;
        }
        if (opt->kind == CLI_KIND_SECTION) {
            fprintf(out, "%s**", table ? "\n" : "");
            md_cell(out, opt->help);
            fprintf(out, "**\n\n");
            md_option_header(out);
            table = true;
            continue;
        }
        if (!table) {
            md_option_header(out);
            table = true;
        }
        md_option(out, c, opt);
    }
    if (!table) {
        md_option_header(out);
    }
    fprintf(out, "| `-h, --help` |  | this text |\n");
    if (c->more_help || c->epilogue) {
        fprintf(out, "\n```text\n");
        if (c->more_help) {
            c->more_help(out);
        }
        if (c->epilogue) {
            fputs(c->epilogue, out);
        }
        fprintf(out, "```\n");
    }
    fprintf(out, "\n");
}

// The knob's range and unit: "1..65536 texels", or the choices.
static void md_range(FILE *out, const drift_knob *k)
{
    if (k->type == DRIFT_KNOB_CHOICE) {
        md_code(out, k->choices);
        return;
    }
    fprintf(out, "%.9g..%.9g%s", k->lo, k->hi, *k->unit ? " " : "");
    md_cell(out, k->unit);
    if (k->flags & DRIFT_KNOB_SQUARE) {
        fprintf(out, ", perfect squares");
    }
}

void cli_print_knobs_markdown(FILE *out)
{
    fprintf(out, "## Techniques\n\n| effect | technique | what it does |\n|---|---|---|\n");
    for (int e = 0; e < DRIFT_EFFECT_COUNT; ++e) {
        for (int t = 0; t < drift_technique_count((drift_effect)e); ++t) {
            fprintf(out, "| `--%s` | `%s`%s | ", drift_effect_name((drift_effect)e),
                    drift_technique_name((drift_effect)e, t),
                    t == drift_technique_default((drift_effect)e) ? " (default)" : "");
            md_cell(out, drift_technique_summary((drift_effect)e, t));
            fprintf(out, " |\n");
        }
    }
    const char *family = NULL;
    for (int i = 0, n = drift_knob_count(); i < n; ++i) {
        const drift_knob *k = drift_knob_get(i);
        if (!family || strcmp(family, k->family) != 0) {
            family = k->family;
            fprintf(out, "\n<a id=\"%s\"></a>\n\n## ", family);
            md_cell(out, drift_knob_family_title(family));
            fprintf(out, "\n\n| option | value | default | range | effect: techniques | "
                         "description |\n|---|---|---|---|---|---|\n");
        }
        char def[64];
        drift_knob_format(k, k->def, def, sizeof def);
        fprintf(out, "| `--%s` | ", k->name);
        md_code(out, k->arg);
        fprintf(out, " | `%s`", def);
        if (k->default_text) {
            fprintf(out, ": ");
            md_cell(out, k->default_text);
        }
        fprintf(out, " | ");
        md_range(out, k);
        if (k->effect < 0 && !k->techniques) {
            fprintf(out, " | the whole frame");
        } else {
            fprintf(out, " | %s: ",
                    k->effect < 0 ? "every effect" : drift_effect_name((drift_effect)k->effect));
            md_cell(out, k->techniques ? k->techniques : "every technique");
        }
        fprintf(out, " | ");
        md_cell(out, k->help);
        fprintf(out, " |\n");
    }
}
