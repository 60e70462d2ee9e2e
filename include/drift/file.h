// Opening input files (docs/reliability.md, "No hangs on odd files").
//
// Every file drift reads goes through one of these: a FIFO, a character device (/dev/zero),
// a socket or a folder is refused at once as "not a regular file" instead of blocking for a
// writer that never comes or reading without end. The FIFO is opened without blocking, so
// the refusal takes no time.
#ifndef DRIFT_FILE_H
#define DRIFT_FILE_H

#include <stddef.h>
#include <stdio.h>

#ifdef __cplusplus
extern "C" {
#endif

// Opens `path` read-only if it is a regular file. Returns the descriptor, or -1 with the
// reason in why[why_cap] ("not a regular file (a FIFO)" or the OS's text) and errno set
// (EINVAL for a file that is not regular).
int drift_input_open(const char *path, char *why, size_t why_cap);

// The same as a stdio stream opened "rb"; NULL with `why` filled on failure.
FILE *drift_input_fopen(const char *path, char *why, size_t why_cap);

#ifdef __cplusplus
}
#endif

#endif
