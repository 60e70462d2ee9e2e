// The JSON writer of the drift CLI (tools/cli_json.h).
#include "cli_json.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

cJSON *cli_json_number(cJSON *object, const char *key, double value, int decimals)
{
    if (!isfinite(value)) {
        return cJSON_AddNullToObject(object, key);
    }
    if (decimals >= 0) {
        double scale = pow(10.0, decimals);
        double rounded = round(value * scale) / scale;
        value = isfinite(rounded) ? rounded : value;
    }
    return cJSON_AddNumberToObject(object, key, value);
}

cJSON *cli_json_count(cJSON *object, const char *key, uint64_t value)
{
    return cJSON_AddNumberToObject(object, key, (double)value);
}

// A float widened to double prints all its binary digits (548.79998779296875); nine
// significant digits are what the float holds (548.799988).
static double float_digits(double v)
{
    char text[64];
    snprintf(text, sizeof text, "%.9g", v);
    return strtod(text, NULL);
}

cJSON *cli_json_float(cJSON *object, const char *key, float value)
{
    return cli_json_number(object, key, float_digits((double)value), -1);
}

cJSON *cli_json_vec3(cJSON *object, const char *key, float x, float y, float z)
{
    const double v[3] = { float_digits((double)x), float_digits((double)y),
                          float_digits((double)z) };
    cJSON *array = cJSON_CreateDoubleArray(v, 3);
    if (array && !cJSON_AddItemToObject(object, key, array)) {
        cJSON_Delete(array);
        return NULL;
    }
    return array;
}

// Writes `item` as JSON: on one line with ", " and ": " between items (indent < 0), or one
// member a line indented by `indent` spaces a level. cJSON escapes the strings and prints
// the numbers; only the layout is ours.
static bool print_item(FILE *out, const cJSON *item, int indent, int depth)
{
    bool object = cJSON_IsObject(item);
    if (!object && !cJSON_IsArray(item)) {
        char *text = cJSON_PrintUnformatted(item);
        bool ok = text && fputs(text, out) >= 0;
        cJSON_free(text);
        return ok;
    }
    bool ok = fputc(object ? '{' : '[', out) != EOF;
    bool nested = false; // objects and arrays of objects go one member a line
    for (const cJSON *c = item->child; c; c = c->next) {
        nested |= cJSON_IsObject(c) || object;
    }
    bool lines = indent >= 0 && nested && item->child;
    for (const cJSON *c = item->child; ok && c; c = c->next) {
        if (lines) {
            ok =
                fprintf(out, "%s\n%*s", c == item->child ? "" : ",", indent * (depth + 1), "") >= 0;
        } else if (c != item->child) {
            ok = fputs(", ", out) >= 0;
        }
        if (ok && object) {
            char *key =
                cJSON_PrintUnformatted(&(cJSON){ .type = cJSON_String, .valuestring = c->string });
            ok = key && fprintf(out, "%s: ", key) >= 0;
            cJSON_free(key);
        }
        ok = ok && print_item(out, c, lines ? indent : -1, depth + 1);
    }
    if (ok && lines) {
        ok = fprintf(out, "\n%*s", indent * depth, "") >= 0;
    }
    return ok && fputc(object ? '}' : ']', out) != EOF;
}

bool cli_json_write(const char *cmd, cJSON *root, const char *path)
{
    bool ok = root != NULL;
    int error = 0;
    if (ok && !path) {
        ok = print_item(stdout, root, -1, 0) && fputc('\n', stdout) != EOF && fflush(stdout) == 0;
    } else if (ok) {
        char tmp[4096];
        snprintf(tmp, sizeof tmp, "%s.tmp%ld", path, (long)getpid());
        errno = 0;
        FILE *f = fopen(tmp, "w");
        ok = f && print_item(f, root, 2, 0) && fputc('\n', f) != EOF && fflush(f) == 0;
        error = ok ? 0 : errno;
        if (f && fclose(f) != 0 && ok) {
            ok = false;
            error = errno;
        }
        if (ok && rename(tmp, path) != 0) {
            ok = false;
            error = errno;
        }
        if (!ok) {
            remove(tmp);
        }
    }
    cJSON_Delete(root);
    if (!ok) {
        fprintf(stderr, "drift %s: cannot write %s%s%s\n", cmd, path ? path : "JSON to stdout",
                error ? ": " : "", error ? strerror(error) : "");
    }
    return ok;
}
