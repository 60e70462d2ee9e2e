// Numbered frame files: a path with one %d or %0Nd (N 1..9) where the frame number goes, and
// "%%" for a literal '%' (drift render --animation's --out, drift diff --frames).
#ifndef DRIFT_TOOLS_FRAME_PATTERN_H
#define DRIFT_TOOLS_FRAME_PATTERN_H

#include <stdbool.h>
#include <stddef.h>

typedef struct frame_pattern {
    size_t at, length; // the conversion's offset and length in the pattern
    int width;         // 0: as many digits as the number has
} frame_pattern;

// Whether `s` holds exactly one frame number conversion (and no other '%' but "%%").
bool frame_pattern_find(const char *s, frame_pattern *out);
// The pattern with frame k in place and "%%" as '%'.
void frame_pattern_format(const char *pattern, const frame_pattern *p, long k, char *out,
                          size_t size);
// "A:B" with 0 <= A <= B <= 1000000; prints "drift CMD: FLAG expects ..." when not.
bool frame_range_parse(const char *cmd, const char *flag, const char *v, long *first, long *last);

#endif
