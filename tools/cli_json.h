// The drift CLI's one JSON writer: `render --stats`, `render --refine sir --stats`,
// `bench ... --json`, `diff --json` and `info --json` build a cJSON tree and write it here,
// so every string is escaped (a scene path with a quote stays valid JSON) and every number
// is finite or null.
#ifndef DRIFT_TOOLS_CLI_JSON_H
#define DRIFT_TOOLS_CLI_JSON_H

#include <cjson/cJSON.h>
#include <stdbool.h>
#include <stdint.h>

// Adds key: value rounded to `decimals` places (< 0: as is); NaN and infinities become null.
// Returns the new item (NULL when out of memory: cli_json_write then fails).
cJSON *cli_json_number(cJSON *object, const char *key, double value, int decimals);
// Adds key: an unsigned count (exact up to 2^53).
cJSON *cli_json_count(cJSON *object, const char *key, uint64_t value);
// Adds key: a float with the nine significant digits it holds.
cJSON *cli_json_float(cJSON *object, const char *key, float value);
// Adds key: [x, y, z] (floats, as cli_json_float).
cJSON *cli_json_vec3(cJSON *object, const char *key, float x, float y, float z);

// Writes `root` and destroys it. path NULL: one line on stdout; otherwise the indented
// document into `path` through a temporary file and a rename, so a reader never sees half a
// file. Prints "drift <cmd>: cannot write <path>" and returns false on failure.
bool cli_json_write(const char *cmd, cJSON *root, const char *path);

#endif
