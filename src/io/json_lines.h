// The source line of every cJSON node (src/io/json_lines.c), for messages that name
// "file:line" in JSON files drift reads: scene files and reflection-edit files.
#ifndef DRIFT_IO_JSON_LINES_H
#define DRIFT_IO_JSON_LINES_H

#include "drift/core.h"

#include <cjson/cJSON.h>
#include <stddef.h>

typedef struct drift__json_line {
    const cJSON *node;
    int line;
} drift__json_line;

typedef struct drift__json_lines {
    drift__json_line *entries; // sorted by node address
    size_t count;
} drift__json_lines;

// Pairs every node of `root` (parsed from text[0..length)) with its line. Leaves *out empty
// (every line reads 0) when the scan and the tree disagree; DRIFT_ERR_OUT_OF_MEMORY.
drift_result drift__json_lines_build(drift_context *ctx, const cJSON *root, const char *text,
                                     size_t length, drift__json_lines *out);
// The line `node` starts on, 0 when unknown (NULL node, empty map).
int drift__json_lines_find(const drift__json_lines *lines, const cJSON *node);
void drift__json_lines_free(drift_context *ctx, drift__json_lines *lines);

#endif
