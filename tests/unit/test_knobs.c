// The knob table (drift/knobs.h, the families' knobs.c): every row is consistent, every knob
// takes its bounds and refuses what lies beyond them, and, through the drift binary
// ($DRIFT_BIN, set by ctest), every knob parses at its bounds and is refused beyond them
// naming its option, --help prints the default the renderer really uses, and --stats reports
// every knob so that its values, given back as options, render the same frame.
#include "drift/knobs.h"
#include "drift_test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>

// A value the knob refuses just below its range (or above, when `above`), or NAN for none
// (a choice is refused as a word instead).
static double beyond(const drift_knob *k, bool above)
{
    if (k->type == DRIFT_KNOB_INT) {
        double below = k->lo - 1.0;
        return above ? k->hi + 1.0 : below == 0.0 && (k->flags & DRIFT_KNOB_AUTO) ? -1.0 : below;
    }
    if (k->type == DRIFT_KNOB_NUMBER) {
        return above ? k->hi * 2.0 : (k->lo > 0.0 ? k->lo * 0.5 : k->lo - 1.0);
    }
    return NAN;
}

// A value other than the default, in range and cheap to render: the lower bound, or the one
// above it; a choice other than the default.
static double other_value(const drift_knob *k)
{
    if (k->type == DRIFT_KNOB_CHOICE) {
        double first = k->choice_values ? (double)k->choice_values[0] : 0.0;
        if (first != k->def) {
            return first;
        }
        int n = 1;
        for (const char *p = k->choices; (p = strchr(p, '|')) != NULL; ++p) {
            ++n;
        }
        return k->choice_values ? (double)k->choice_values[n - 1] : (double)(n - 1);
    }
    if (k->lo != k->def) {
        return k->lo;
    }
    return (k->flags & DRIFT_KNOB_SQUARE) ? 4.0 : k->lo + 1.0;
}

static void test_rows_are_consistent(void **state)
{
    (void)state;
    int n = drift_knob_count();
    assert_true(n >= 40);
    assert_null(drift_knob_get(n));
    assert_null(drift_knob_get(-1));
    drift_hybrid_params defaults = drift_hybrid_params_default();
    for (int i = 0; i < n; ++i) {
        const drift_knob *k = drift_knob_get(i);
        assert_non_null(k->name);
        assert_non_null(k->help);
        assert_non_null(k->unit);
        assert_non_null(drift_knob_family_title(k->family));
        assert_int_equal(drift_knob_find(k->name), i); // names are unique
        assert_true(k->effect >= -1 && k->effect < DRIFT_EFFECT_COUNT);
        assert_true(k->offset < sizeof(drift_hybrid_params));
        // The default is in range (AUTO: 0), and it is what the default frame holds.
        drift_hybrid_params p = { 0 };
        assert_true(drift_knob_set(&p, i, k->def));
        assert_true(drift_knob_value(&defaults, i) == k->def);
        assert_true(((k->flags & DRIFT_KNOB_AUTO) != 0) == (k->default_text != NULL));
        // Every row's text round-trips: format, then parse, gives the value back.
        double values[3] = { k->def, other_value(k),
                             k->type == DRIFT_KNOB_CHOICE ? k->def : k->hi };
        for (int v = 0; v < 3; ++v) {
            char text[64];
            drift_knob_format(k, values[v], text, sizeof text);
            double back = -1.0;
            if (!drift_knob_parse(k, text, &back) || back != values[v]) {
                fail_msg("knob %s: '%s' does not parse back to %g", k->name, text, values[v]);
            }
        }
    }
    // The technique defaults the command line prints are the default frame's.
    for (int e = 0; e < DRIFT_EFFECT_COUNT; ++e) {
        assert_int_equal(drift_technique_default((drift_effect)e), defaults.techniques[e]);
    }
    assert_int_equal(defaults.indirect, DRIFT_INDIRECT_ISM);
    drift_hybrid_params recommended = drift_hybrid_params_recommended();
    assert_memory_equal(&recommended, &defaults, sizeof defaults);
}

// Every knob at its bounds is stored and read back; beyond them it is refused and the params
// stay as they were.
static void test_bounds(void **state)
{
    (void)state;
    for (int i = 0; i < drift_knob_count(); ++i) {
        const drift_knob *k = drift_knob_get(i);
        drift_hybrid_params p = drift_hybrid_params_default();
        if (k->type != DRIFT_KNOB_CHOICE) {
            for (int side = 0; side < 2; ++side) {
                double bound = side ? k->hi : k->lo;
                if ((k->flags & DRIFT_KNOB_SQUARE) && side) {
                    bound = floor(sqrt(k->hi)) * floor(sqrt(k->hi));
                }
                assert_true(drift_knob_set(&p, i, bound));
                assert_true(drift_knob_value(&p, i) == (double)(float)bound);
                drift_hybrid_params before = p;
                if (drift_knob_set(&p, i, beyond(k, side != 0))) {
                    fail_msg("knob %s takes %g, outside [%g, %g]", k->name, beyond(k, side != 0),
                             k->lo, k->hi);
                }
                assert_memory_equal(&before, &p, sizeof p);
            }
            double out = 0.0;
            assert_false(drift_knob_parse(k, "x", &out));
            assert_false(drift_knob_set(&p, i, NAN));
        } else {
            double out = 0.0;
            assert_false(drift_knob_parse(k, "bogus", &out));
            assert_false(drift_knob_set(&p, i, 77.0));
        }
        if (k->flags & DRIFT_KNOB_SQUARE) {
            assert_false(drift_knob_set(&p, i, 24.0));
        }
        // The viewer's steps stay in range and move off the default, up or down.
        double up = drift_knob_step(k, k->def, 1), down = drift_knob_step(k, k->def, -1);
        assert_true(drift_knob_set(&p, i, up));
        assert_true(drift_knob_set(&p, i, down));
        assert_true(up != k->def || down != k->def);
        assert_true(drift_knob_step(k, up, -1) <= up && drift_knob_step(k, down, 1) >= down);
    }
    assert_int_equal(drift_knob_find("no-such-knob"), -1);
}

// Runs `command` through the shell; its stdout and stderr into out (size bytes, may be
// NULL). Returns the exit status.
static int run(const char *command, char *out, size_t size)
{
    FILE *pipe = popen(command, "r");
    assert_non_null(pipe);
    size_t n = 0;
    char chunk[4096];
    size_t got;
    while ((got = fread(chunk, 1, sizeof chunk, pipe)) > 0) {
        if (out && n + 1 < size) {
            size_t take = got < size - n - 1 ? got : size - n - 1;
            memcpy(out + n, chunk, take);
            n += take;
        }
    }
    if (out) {
        out[n] = '\0';
    }
    int status = pclose(pipe);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// The value after "name": in a JSON text (a number or a quoted string), or "" when absent.
static void json_value(const char *json, const char *name, char *out, size_t size)
{
    char key[128];
    snprintf(key, sizeof key, "\"%s\":", name);
    const char *p = strstr(json, key);
    out[0] = '\0';
    if (!p) {
        return;
    }
    p += strlen(key);
    while (*p == ' ' || *p == '\t') {
        ++p;
    }
    bool quoted = *p == '"';
    p += quoted;
    size_t n = 0;
    while (p[n] && n + 1 < size && (quoted ? p[n] != '"' : strchr(",}\n\r", p[n]) == NULL)) {
        ++n;
    }
    snprintf(out, size, "%.*s", (int)n, p);
}

static bool read_file(const char *path, char *out, size_t size)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        return false;
    }
    size_t n = fread(out, 1, size - 1, f);
    out[n] = '\0';
    fclose(f);
    return true;
}

static char big[1 << 18], other[1 << 18];

// The options that set every knob to values[k], the way --stats writes them.
static void knob_options(const double *values, char *out, size_t size)
{
    size_t n = 0;
    for (int i = 0; i < drift_knob_count(); ++i) {
        char text[64];
        drift_knob_format(drift_knob_get(i), values[i], text, sizeof text);
        n += (size_t)snprintf(out + n, size - n, " --%s %s", drift_knob_get(i)->name, text);
    }
}

static void test_command_line(void **state)
{
    (void)state;
    const char *bin = getenv("DRIFT_BIN");
    if (!bin || !*bin) {
        skip();
    }
    int n = drift_knob_count();
    char command[16384], text[256];
    // Every knob at its lower bound, then its upper bound, in one command each: parsed.
    for (int side = 0; side < 2; ++side) {
        for (int c = 0; c < 2; ++c) {
            int len = snprintf(command, sizeof command, "%s %s", bin,
                               c ? "view" : "render --mode hybrid");
            for (int i = 0; i < n; ++i) {
                const drift_knob *k = drift_knob_get(i);
                double v = side ? k->hi : k->lo;
                if (k->flags & DRIFT_KNOB_SQUARE) {
                    v = side ? floor(sqrt(k->hi)) * floor(sqrt(k->hi)) : 1.0;
                }
                if (k->type == DRIFT_KNOB_CHOICE) {
                    v = side ? other_value(k) : k->def;
                }
                drift_knob_format(k, v, text, sizeof text);
                len += snprintf(command + len, sizeof command - (size_t)len, " --%s %s", k->name,
                                text);
            }
            snprintf(command + len, sizeof command - (size_t)len, " --help >/dev/null 2>&1");
            assert_int_equal(run(command, NULL, 0), 0);
        }
    }
    // Beyond a bound (or a word no choice has): exit status 2, the option named. One side a
    // knob, alternating (test_bounds checks both sides of the same parser without a process).
    for (int i = 0; i < n; ++i) {
        const drift_knob *k = drift_knob_get(i);
        for (int side = i % 2; side == i % 2; ++side) {
            if (k->type == DRIFT_KNOB_CHOICE) {
                snprintf(text, sizeof text, side ? "bogus" : "2.5");
            } else {
                snprintf(text, sizeof text, "%.9g", beyond(k, side != 0));
            }
            snprintf(command, sizeof command, "%s render --mode hybrid --%s %s 2>&1", bin, k->name,
                     text);
            char message[2048];
            char option[80];
            snprintf(option, sizeof option, "--%s expects", k->name);
            if (run(command, message, sizeof message) != 2 || !strstr(message, option)) {
                fail_msg("--%s %s: not refused naming the option: %s", k->name, text, message);
            }
        }
    }
    // --help of both commands: every knob with the default drift_hybrid_params_default holds.
    drift_hybrid_params defaults = drift_hybrid_params_default();
    for (int c = 0; c < 2; ++c) {
        snprintf(command, sizeof command, "%s %s --help", bin, c ? "view" : "render");
        assert_int_equal(run(command, big, sizeof big), 0);
        for (int i = 0; i < n; ++i) {
            const drift_knob *k = drift_knob_get(i);
            char label[96], def[64], expected[96];
            snprintf(label, sizeof label, "\n  --%s ", k->name);
            const char *at = strstr(big, label);
            if (!at) {
                fail_msg("drift %s --help has no --%s", c ? "view" : "render", k->name);
            }
            drift_knob_format(k, drift_knob_value(&defaults, i), def, sizeof def);
            snprintf(expected, sizeof expected, "(default %s", def);
            const char *next = strstr(at + 1, "\n  --");
            const char *found = strstr(at, expected);
            if (!found || (next && found > next)) {
                fail_msg("--%s: --help does not say '%s'", k->name, expected);
            }
        }
    }
    // What the renderer uses: a default frame's --stats holds every knob at that default
    // (an auto knob: auto, or the value the frame derived).
    char out_dir[1024], exr_a[1100], exr_b[1100], stats_a[1100], stats_b[1100];
    test_out_path(out_dir, "knobs");
    snprintf(exr_a, sizeof exr_a, "%s/a.exr", out_dir);
    snprintf(exr_b, sizeof exr_b, "%s/b.exr", out_dir);
    snprintf(stats_a, sizeof stats_a, "%s/a.json", out_dir);
    snprintf(stats_b, sizeof stats_b, "%s/b.json", out_dir);
    const char *frame = "render --mode hybrid --width 16 --height 16 --spp 1 --threads 2 --quiet";
    snprintf(command, sizeof command, "mkdir -p %s && %s %s --out %s --stats %s 2>&1", out_dir, bin,
             frame, exr_a, stats_a);
    assert_int_equal(run(command, big, sizeof big), 0);
    assert_true(read_file(stats_a, big, sizeof big));
    double *values = calloc((size_t)n, sizeof *values);
    assert_non_null(values);
    for (int i = 0; i < n; ++i) {
        const drift_knob *k = drift_knob_get(i);
        char got[128], def[64];
        json_value(big, k->name, got, sizeof got);
        drift_knob_format(k, drift_knob_value(&defaults, i), def, sizeof def);
        double v = 0.0;
        if (!drift_knob_parse(k, got, &v)) {
            fail_msg("--stats: knob %s is '%s', not a value of the knob", k->name, got);
        }
        if (!(k->flags & DRIFT_KNOB_AUTO) && v != drift_knob_value(&defaults, i)) {
            fail_msg("--stats: knob %s is %s, --help says %s", k->name, got, def);
        }
        values[i] = v;
    }
    // Round trip: the stats' knobs given back as options render the same image and stats.
    int len =
        snprintf(command, sizeof command, "%s %s --out %s --stats %s", bin, frame, exr_b, stats_b);
    knob_options(values, command + len, sizeof command - (size_t)len);
    assert_int_equal(run(command, NULL, 0), 0);
    assert_true(read_file(stats_b, other, sizeof other));
    for (int i = 0; i < n; ++i) {
        char a[128], b[128];
        json_value(big, drift_knob_get(i)->name, a, sizeof a);
        json_value(other, drift_knob_get(i)->name, b, sizeof b);
        assert_string_equal(a, b);
    }
    snprintf(command, sizeof command, "cmp -s %s %s", exr_a, exr_b);
    assert_int_equal(run(command, NULL, 0), 0);
    // Every knob moved off its default: --stats reports the values given.
    for (int i = 0; i < n; ++i) {
        values[i] = other_value(drift_knob_get(i));
    }
    len =
        snprintf(command, sizeof command, "%s %s --out %s --stats %s", bin, frame, exr_b, stats_b);
    knob_options(values, command + len, sizeof command - (size_t)len);
    snprintf(command + strlen(command), sizeof command - strlen(command), " 2>&1");
    if (run(command, other, sizeof other) != 0) {
        fail_msg("every knob off its default: %s", other);
    }
    assert_true(read_file(stats_b, other, sizeof other));
    for (int i = 0; i < n; ++i) {
        const drift_knob *k = drift_knob_get(i);
        char got[128];
        json_value(other, k->name, got, sizeof got);
        double v = -1.0;
        if (!drift_knob_parse(k, got, &v) || v != (double)(float)values[i]) {
            fail_msg("--stats: knob %s is '%s', set to %g", k->name, got, values[i]);
        }
    }
    free(values);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rows_are_consistent),
        cmocka_unit_test(test_bounds),
        cmocka_unit_test(test_command_line),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
