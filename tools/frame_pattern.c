// Numbered frame files (frame_pattern.h).
#include "frame_pattern.h"

#include <stdio.h>

bool frame_pattern_find(const char *s, frame_pattern *out)
{
    int found = 0;
    for (size_t i = 0; s[i]; ++i) {
        if (s[i] != '%') {
            continue;
        }
        if (s[i + 1] == '%') {
            ++i;
            continue;
        }
        size_t j = i + 1;
        int width = 0;
        if (s[j] == '0' && s[j + 1] >= '1' && s[j + 1] <= '9') {
            width = s[j + 1] - '0';
            j += 2;
        }
        if (s[j] != 'd') {
            return false;
        }
        *out = (frame_pattern){ .at = i, .length = j + 1 - i, .width = width };
        ++found;
        i = j;
    }
    return found == 1;
}

void frame_pattern_format(const char *pattern, const frame_pattern *p, long k, char *out,
                          size_t size)
{
    size_t n = 0;
    for (size_t i = 0; pattern[i] && n + 1 < size;) {
        if (i == p->at) {
            int w = snprintf(out + n, size - n, "%0*ld", p->width, k);
            n += w > 0 ? (size_t)w : 0;
            i += p->length;
            continue;
        }
        out[n++] = pattern[i];
        i += pattern[i] == '%' ? 2 : 1;
    }
    out[n < size ? n : size - 1] = '\0';
}

bool frame_range_parse(const char *cmd, const char *flag, const char *v, long *first, long *last)
{
    long a = -1, b = -1;
    char tail;
    if (sscanf(v, "%ld:%ld%c", &a, &b, &tail) != 2 || a < 0 || b < a || b > 1000000) {
        fprintf(stderr,
                "drift %s: %s expects FIRST:LAST frame numbers, 0 <= FIRST <= LAST <= 1000000, "
                "got '%s'\n",
                cmd, flag, v);
        return false;
    }
    *first = a;
    *last = b;
    return true;
}
