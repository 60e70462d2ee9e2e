// Option tables for the drift command line: one table per command names each option, its
// value's placeholder, its help text and where the value goes; cli_parse reads argv from the
// table and cli_print_help prints --help from the same table, so the two cannot drift apart
// (yocto_cli's idea, with curl's "the tool owns main" errors).
//
//     typedef struct my_options { const char *scene; long spp; bool json; } my_options;
//     static const cli_option my_table[] = {
//         CLI_INT("--spp", "N", my_options, spp, 1, 65536, "samples a pixel (default 4)"),
//         CLI_FLAG("--json", my_options, json, "one JSON object on stdout"),
//     };
//     static const cli_command my_command = {
//         .name = "bench my", .usage = "usage: drift bench my [SCENE] [options]\n",
//         CLI_TABLE(my_table), CLI_POSITIONAL("SCENE", my_options, scene, 1),
//     };
//     my_options o = { .spp = 4 };                // defaults first
//     int status = cli_parse(&my_command, argc, argv, &o, NULL);
//     if (status != CLI_PARSED) return status == CLI_HELP_SHOWN ? 0 : 2;
//
// A new option is one row. Values land through offsetof in the options struct, typed by
// _Generic from the field (long, int, unsigned, double, float, bool, const char *); technique
// flags (--shadows ...) and their help lists come from drift_effect_name and
// drift_technique_count/name (CLI_TECHNIQUES).
// Errors name the option and the bad value ("drift render: --spp expects an integer in [1,
// 16777216], got 'zero'") and make cli_parse return CLI_USAGE_ERROR (exit status 2).
#ifndef DRIFT_TOOLS_CLI_OPTIONS_H
#define DRIFT_TOOLS_CLI_OPTIONS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

typedef enum cli_kind {
    CLI_KIND_FLAG,       // no value: stores true
    CLI_KIND_INT,        // an integer in [lo, hi]
    CLI_KIND_NUMBER,     // a finite number in [lo, hi]
    CLI_KIND_STRING,     // any text
    CLI_KIND_CHOICE,     // one of `choices` ("full|plane"): stores its index
    CLI_KIND_TECHNIQUES, // one row for every effect: --<effect name> T sets that effect's
                         // technique in the drift_hybrid_params at `offset`
    CLI_KIND_KNOBS,      // one row for every knob of the knob table (drift/knobs.h): --<knob
                         // name> V sets that knob in the drift_hybrid_params at `offset`
    CLI_KIND_CUSTOM,     // `parse` reads the value (NULL when the option takes none)
    CLI_KIND_SECTION,    // help only: a heading; the options after it join its `groups`
    CLI_KIND_NOTE,       // help only: a line under the option before it
} cli_kind;

typedef enum cli_store {
    CLI_STORE_NONE,
    CLI_STORE_LONG,
    CLI_STORE_INT,
    CLI_STORE_UINT,
    CLI_STORE_DOUBLE,
    CLI_STORE_FLOAT,
    CLI_STORE_BOOL,
    CLI_STORE_STRING,
} cli_store;

// The store type of a field, from its C type (enums with no negative values are unsigned).
// (clang-format 14 would break _Generic's associations at the colons.)
// clang-format off
#define CLI_STORE_OF(x)                      \
    _Generic((x),                            \
             long: CLI_STORE_LONG,           \
             int: CLI_STORE_INT,             \
             unsigned: CLI_STORE_UINT,       \
             double: CLI_STORE_DOUBLE,       \
             float: CLI_STORE_FLOAT,         \
             bool: CLI_STORE_BOOL,           \
             const char *: CLI_STORE_STRING, \
             default: CLI_STORE_NONE)
// clang-format on

// A custom value reader: `field` is the options struct plus the row's offset. Prints its own
// "drift <cmd>: <flag> expects ..." and returns false on a bad value.
typedef bool (*cli_parse_fn)(const char *cmd, const char *flag, const char *value, void *field);

typedef struct cli_option {
    const char *name; // "--spp"; aliases separated by ", " ("-v, --verbose")
    const char *arg;  // value placeholder ("N"); NULL: the option takes no value
    const char *help; // help text; '\n' continues it on the next line, indented
    cli_kind kind;
    size_t offset; // where the value goes in the options struct
    cli_store store;
    double lo, hi;           // CLI_KIND_INT, CLI_KIND_NUMBER
    const char *choices;     // CLI_KIND_CHOICE: "a|b|c"
    cli_parse_fn parse;      // CLI_KIND_CUSTOM
    const char *optional_if; // CUSTOM: the value is optional, taken when it ends like this
    unsigned groups;         // CLI_KIND_SECTION: bits the following options belong to
} cli_option;

#define CLI_AT(T, f) .offset = offsetof(T, f), .store = CLI_STORE_OF(((T *)0)->f)

#define CLI_FLAG(n, T, f, h)                                          \
    {                                                                 \
        .name = (n), .help = (h), .kind = CLI_KIND_FLAG, CLI_AT(T, f) \
    }
#define CLI_INT(n, a, T, f, l, u, h)                                                   \
    {                                                                                  \
        .name = (n), .arg = (a), .help = (h), .kind = CLI_KIND_INT, .lo = (double)(l), \
        .hi = (double)(u), CLI_AT(T, f)                                                \
    }
#define CLI_NUMBER(n, a, T, f, l, u, h)                                                      \
    {                                                                                        \
        .name = (n), .arg = (a), .help = (h), .kind = CLI_KIND_NUMBER, .lo = (l), .hi = (u), \
        CLI_AT(T, f)                                                                         \
    }
#define CLI_STRING(n, a, T, f, h)                                                   \
    {                                                                               \
        .name = (n), .arg = (a), .help = (h), .kind = CLI_KIND_STRING, CLI_AT(T, f) \
    }
#define CLI_CHOICE(n, a, T, f, c, h)                                                   \
    {                                                                                  \
        .name = (n), .arg = (a), .help = (h), .kind = CLI_KIND_CHOICE, .choices = (c), \
        CLI_AT(T, f)                                                                   \
    }
// --shadows T, --reflections T, ...: one option per drift_effect, named after
// drift_effect_name, with the help generated from drift_technique_count/name (the first, the
// zero default, marked "(default)"). A new technique or effect needs no row of its own.
#define CLI_TECHNIQUES(a, T, f)                                           \
    {                                                                     \
        .arg = (a), .kind = CLI_KIND_TECHNIQUES, .offset = offsetof(T, f) \
    }
// One effect's --name T row on its own (in another section than CLI_TECHNIQUES, e.g. an
// effect both of drift render's modes take); CLI_TECHNIQUES then leaves that effect out.
#define CLI_TECHNIQUE(n, a, T, f, h)                                       \
    {                                                                      \
        .name = (n), .arg = (a), .help = (h), .kind = CLI_KIND_TECHNIQUES, \
        .offset = offsetof(T, f)                                           \
    }
// --shadow-map-size N, --ism-vpls N, ...: one option per row of the knob table
// (include/drift/knobs.h), its help, range, unit and default printed from the row, grouped by
// the family that owns it. A new knob needs no row here.
#define CLI_KNOBS(T, f)                                  \
    {                                                    \
        .kind = CLI_KIND_KNOBS, .offset = offsetof(T, f) \
    }
#define CLI_CUSTOM(n, a, T, f, fn, h)                                                 \
    {                                                                                 \
        .name = (n), .arg = (a), .help = (h), .kind = CLI_KIND_CUSTOM, .parse = (fn), \
        .offset = offsetof(T, f)                                                      \
    }
// A custom reader that sets several fields: `field` is the whole options struct.
#define CLI_CUSTOM_ALL(n, a, fn, h)                                                  \
    {                                                                                \
        .name = (n), .arg = (a), .help = (h), .kind = CLI_KIND_CUSTOM, .parse = (fn) \
    }
#define CLI_SECTION(h, g)                                    \
    {                                                        \
        .help = (h), .kind = CLI_KIND_SECTION, .groups = (g) \
    }
#define CLI_NOTE(h)                        \
    {                                      \
        .help = (h), .kind = CLI_KIND_NOTE \
    }

// A macro's value as a string literal, for defaults in help texts.
#define CLI_STR(x)       CLI_STR_INNER(x)
#define CLI_STR_INNER(x) #x

#define CLI_GROUP_COUNT 8

typedef struct cli_command {
    const char *name;     // "render", "bench isg": in messages and help
    const char *usage;    // printed before the options: the usage line and what the command does
    const char *epilogue; // printed after the options (may be NULL)
    void (*more_help)(FILE *out); // prints what the epilogue cannot hold (may be NULL)
    const cli_option *options;
    size_t option_count;
    const char *positional;   // "SCENE"; NULL: no positional arguments
    size_t positional_offset; // an array of positional_max const char * in the options struct
    int positional_max;
    int help_column; // column of the help texts (0: 24)
} cli_command;

#define CLI_TABLE(t) .options = (t), .option_count = sizeof(t) / sizeof((t)[0])
#define CLI_POSITIONAL(label, T, f, max) \
    .positional = (label), .positional_offset = offsetof(T, f), .positional_max = (max)

enum {
    CLI_PARSED = 0,      // go on
    CLI_USAGE_ERROR = 2, // message printed: exit status 2
    CLI_HELP_SHOWN = -1, // --help printed on stdout: exit status 0
};

// Reads argv[1 ..] (argv[0] is the command's own name) into `opts`, which holds the defaults.
// -h and --help print the help on stdout. `first_in_group` (may be NULL) receives, per group
// bit k, the first option given from a section with that bit (for "--x needs --mode hybrid").
int cli_parse(const cli_command *command, int argc, char **argv, void *opts,
              const char *first_in_group[CLI_GROUP_COUNT]);

// cli_parse's result as an exit status for a command that stops here: 0 after --help, 2
// after a usage error; -1 (go on) after a successful parse.
int cli_parse_exit(int status);

void cli_print_help(const cli_command *command, FILE *out);
// Whether the command's positional argument is a SCENE, and the scene formats it may be (the
// loaders' registry, drift_scene_format_get): --help and --help-markdown print them after
// the usage of every such command.
bool cli_takes_scene(const cli_command *command);
void cli_print_scene_formats(FILE *out);
// The same as Markdown (tools/cli_markdown.c): the usage, one table of options per section
// (option, argument, description); `drift COMMAND --help-markdown` prints it. And the knob
// reference: the techniques, then per knob family a table of its rows (`drift
// --knobs-markdown`). scripts/gen-reference.sh writes docs/reference/ with both.
void cli_print_markdown(const cli_command *command, FILE *out);
void cli_print_knobs_markdown(FILE *out);

// "did you mean ...": the nearest of the candidates offered to what the user typed, by edit
// distance (Damerau: a swap of two letters is one edit), when it is near enough to be a typo
// (at most 2 edits, or a third of the word's length for longer words).
typedef struct cli_suggestion {
    const char *given;
    char best[64];
    int distance; // of `best`; large while there is none
} cli_suggestion;

cli_suggestion cli_suggestion_begin(const char *given);
// Offers the first `length` characters of `candidate`.
void cli_suggestion_offer(cli_suggestion *s, const char *candidate, size_t length);
// " (did you mean '--spp'?)" or "" when no candidate was near enough.
const char *cli_suggestion_text(const cli_suggestion *s, char *buffer, size_t size);

#endif
