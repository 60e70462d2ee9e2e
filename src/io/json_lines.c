// The line of every value of a JSON text cJSON parsed. cJSON keeps no source positions, so a
// small scanner records where every JSON value starts. Values appear in the text in the same
// order as a pre-order walk of cJSON's tree, which pairs each cJSON node with its line; scene
// files and edit files name "file:line" for any key their readers complain about.
#include "io/json_lines.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

static bool is_json_space(unsigned char c)
{
    return c <= 32; // what cJSON skips
}

static bool is_json_delimiter(unsigned char c)
{
    return is_json_space(c) || c == ',' || c == ':' || c == '[' || c == ']' || c == '{' ||
           c == '}' || c == '"';
}

// Records (when starts != NULL) the offset of every JSON value in text order; returns how
// many there are. Only run on text cJSON accepted, but bounds-checked for any input.
static size_t scan_value_starts(const char *text, size_t length, size_t *starts, size_t cap)
{
    size_t i = 0, n = 0;
    if (length >= 3 && memcmp(text, "\xEF\xBB\xBF", 3) == 0) {
        i = 3;
    }
    while (i < length) {
        unsigned char c = (unsigned char)text[i];
        if (is_json_space(c) || c == ',' || c == ':' || c == ']' || c == '}') {
            i++;
            continue;
        }
        size_t start = i;
        if (c == '{' || c == '[') {
            i++;
        } else if (c == '"') {
            for (i++; i < length && text[i] != '"'; ++i) {
                if (text[i] == '\\') {
                    i++;
                }
            }
            i++;
            size_t j = i;
            while (j < length && is_json_space((unsigned char)text[j])) {
                j++;
            }
            if (j < length && text[j] == ':') {
                continue; // an object key, not a value
            }
        } else {
            while (i < length && !is_json_delimiter((unsigned char)text[i])) {
                i++;
            }
        }
        if (starts && n < cap) {
            starts[n] = start;
        }
        n++;
    }
    return n;
}

static size_t count_nodes(const cJSON *item)
{
    size_t n = 1;
    for (const cJSON *c = item->child; c; c = c->next) {
        n += count_nodes(c);
    }
    return n;
}

static void collect_nodes(const cJSON *item, drift__json_line *out, size_t *n)
{
    out[(*n)++].node = item;
    for (const cJSON *c = item->child; c; c = c->next) {
        collect_nodes(c, out, n);
    }
}

static int compare_node_line(const void *a, const void *b)
{
    uintptr_t x = (uintptr_t)((const drift__json_line *)a)->node;
    uintptr_t y = (uintptr_t)((const drift__json_line *)b)->node;
    return x < y ? -1 : (x > y ? 1 : 0);
}

drift_result drift__json_lines_build(drift_context *ctx, const cJSON *root, const char *text,
                                     size_t length, drift__json_lines *out)
{
    *out = (drift__json_lines){ 0 };
    size_t node_count = count_nodes(root);
    size_t value_count = scan_value_starts(text, length, NULL, 0);
    if (value_count != node_count) {
        return DRIFT_OK;
    }
    size_t *starts = drift_alloc(ctx, value_count * sizeof(size_t));
    drift__json_line *lines = drift_alloc(ctx, node_count * sizeof(drift__json_line));
    if (!starts || !lines) {
        drift_free(ctx, starts);
        drift_free(ctx, lines);
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    scan_value_starts(text, length, starts, value_count);
    size_t n = 0;
    collect_nodes(root, lines, &n);
    // Starts increase, so one pass over the text numbers them all.
    int line = 1;
    size_t pos = 0;
    for (size_t k = 0; k < n; ++k) {
        for (; pos < starts[k]; ++pos) {
            line += text[pos] == '\n';
        }
        lines[k].line = line;
    }
    drift_free(ctx, starts);
    qsort(lines, n, sizeof(drift__json_line), compare_node_line);
    out->entries = lines;
    out->count = n;
    return DRIFT_OK;
}

int drift__json_lines_find(const drift__json_lines *lines, const cJSON *node)
{
    if (!node || !lines->entries) {
        return 0;
    }
    drift__json_line key = { .node = node };
    const drift__json_line *hit =
        bsearch(&key, lines->entries, lines->count, sizeof(drift__json_line), compare_node_line);
    return hit ? hit->line : 0;
}

void drift__json_lines_free(drift_context *ctx, drift__json_lines *lines)
{
    drift_free(ctx, lines->entries);
    *lines = (drift__json_lines){ 0 };
}
