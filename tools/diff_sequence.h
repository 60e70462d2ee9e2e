// drift diff --frames A:B: a test sequence against a reference sequence (tools/diff_sequence.c).
#ifndef DRIFT_TOOLS_DIFF_SEQUENCE_H
#define DRIFT_TOOLS_DIFF_SEQUENCE_H

#include <stdbool.h>

typedef struct diff_sequence_options {
    const char *ref_pattern, *test_pattern; // frame_pattern.h patterns
    long first, last;
    double ppd;     // 0: the default
    double difftol; // < 0: none; else on the mean FLIP
    bool json, verbose, ignore_nonfinite;
    const char *plot_path; // SVG of FLIP and the temporal error per frame, or NULL
} diff_sequence_options;

// Per-frame FLIP against per-frame references and the temporal error (the frame-to-frame
// change of test - reference); returns the exit status.
int diff_sequence(const diff_sequence_options *o);

#endif
