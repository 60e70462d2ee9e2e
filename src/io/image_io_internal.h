// Private to src/io/image_*.c: whole-file reads, the temp-file-then-rename writer protocol and
// the format back ends; and the errno text every src/io file logs with.
#ifndef DRIFT_IO_IMAGE_IO_INTERNAL_H
#define DRIFT_IO_IMAGE_IO_INTERNAL_H

#include "drift/image_io.h"

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

// strerror_r's text for `err` in buf (plain strerror is not thread-safe); returns buf.
const char *drift__errno_text(int err, char *buf, size_t cap);
// The same for a failed write, said plainly where it is a full disk or a size limit:
// "disk full (No space left on device)". Returns buf.
const char *drift__write_errno_text(int err, char *buf, size_t cap);

// Reads a whole file into memory from drift_alloc (free with drift_free). Logs and returns
// DRIFT_ERR_IO when the file cannot be opened or read.
drift_result drift__image_read_file(drift_context *ctx, const char *path, uint8_t **out_data,
                                    size_t *out_size);

// A file being written: `fd` is open for writing on `temp_path`, a new file in the same
// directory as `path`.
typedef struct drift__image_temp {
    int fd;
    const char *path;
    char temp_path[4096];
} drift__image_temp;

// Creates the temporary file (O_EXCL, mode 0666 less umask). Logs and returns DRIFT_ERR_IO.
drift_result drift__image_temp_open(drift_context *ctx, const char *path, drift__image_temp *out);
// Writes all of `size` bytes at `offset` (pwrite). Returns false on error (errno set).
// DRIFT_TEST_DISK_FULL=N in the environment makes every write past the process's first N
// bytes fail with ENOSPC (the tests' full disk; docs/reliability.md).
bool drift__image_temp_write(drift__image_temp *t, const void *data, size_t size, uint64_t offset);
// Closes the file. When `result` is DRIFT_OK, renames it over the target (a failing close or
// rename is logged and turns the result into DRIFT_ERR_IO); otherwise, or when that fails,
// removes the temporary file. Returns the final result.
drift_result drift__image_temp_close(drift_context *ctx, drift__image_temp *t, drift_result result);

// Format back ends. The EXR loader decodes from memory; `path` is only used in messages.
drift_result drift__image_exr_load(drift_context *ctx, const char *path, const uint8_t *data,
                                   size_t size, drift_image *out_image);

#endif
