// drift report's guard of its --out folder (report_files.h).
#include "report_files.h"

#include "drift/file.h"

#include <cjson/cJSON.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

// The whole of a regular file as a NUL-terminated string (malloc), or NULL with `why` set.
static char *read_input(const char *path, char *why, size_t why_cap)
{
    FILE *f = drift_input_fopen(path, why, why_cap);
    if (!f) {
        return NULL;
    }
    char *text = NULL;
    size_t size = 0, cap = 0;
    for (;;) {
        if (size + 1 >= cap) {
            cap = cap ? cap * 2 : 1 << 16;
            char *grown = realloc(text, cap);
            if (!grown) {
                free(text);
                fclose(f);
                snprintf(why, why_cap, "out of memory");
                return NULL;
            }
            text = grown;
        }
        size_t n = fread(text + size, 1, cap - size - 1, f);
        size += n;
        if (n == 0) {
            break;
        }
    }
    fclose(f);
    text[size] = '\0';
    return text;
}

bool report_out_dir_is_ours(const char *out_dir)
{
    static const char *const names[] = { "manifest.json", "index.html" };
    for (int i = 0; i < 2; ++i) {
        char path[4200], why[128] = "";
        snprintf(path, sizeof path, "%s/%s", out_dir, names[i]);
        struct stat st;
        if (lstat(path, &st) != 0 && errno == ENOENT) {
            continue;
        }
        char *text = read_input(path, why, sizeof why);
        bool ours = false;
        if (text && i == 0) {
            cJSON *root = cJSON_Parse(text);
            ours = cJSON_IsString(cJSON_GetObjectItemCaseSensitive(root, "drift")) &&
                   cJSON_IsObject(cJSON_GetObjectItemCaseSensitive(root, "renders"));
            cJSON_Delete(root);
        } else if (text) {
            ours = strstr(text, "<!-- The drift report page") != NULL;
        }
        free(text);
        if (!ours) {
            fprintf(stderr,
                    "drift report: --out '%s' holds %s, which drift report did not write%s%s; "
                    "refusing to overwrite it, nothing written\n",
                    out_dir, names[i], why[0] ? ": " : "", why);
            return false;
        }
    }
    return true;
}
