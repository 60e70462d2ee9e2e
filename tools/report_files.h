// drift report's guard of its --out folder (tools/report_files.c, docs/reliability.md).
#ifndef DRIFT_TOOLS_REPORT_FILES_H
#define DRIFT_TOOLS_REPORT_FILES_H

#include <stdbool.h>

// --out DIR's manifest.json and index.html may only be files an earlier report wrote: the
// manifest has the "drift" and "renders" members drift report gives it, the page the page
// template's first comment. Anything else there (another program's file, a FIFO) is refused:
// prints "drift report: --out 'DIR' holds NAME, which drift report did not write; ..." and
// returns false (exit status 2). Missing files are fine.
bool report_out_dir_is_ours(const char *out_dir);

#endif
