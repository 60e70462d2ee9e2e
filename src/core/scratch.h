// A block of memory the context keeps between calls, for passes that need large planes every
// frame (the a-trous filter: 16 floats a pixel). Fresh pages cost their first touch (a page
// fault each 4 KiB: 3 ns a byte on the bench machine, as much as the filter's arithmetic), so
// a pass takes the block the last one gave back instead of allocating its own.
#ifndef DRIFT_CORE_SCRATCH_H
#define DRIFT_CORE_SCRATCH_H

#include "drift/core.h"

#include <stddef.h>

// A block of at least `size` bytes, *have its real size: the kept one when it is large enough
// (its contents are whatever its last user left), else a new, zeroed one. NULL when out of
// memory. Thread-safe: two callers never get the same block.
void *drift__scratch_take(drift_context *ctx, size_t size, size_t *have);
// Gives a block back: the context keeps the larger of it and the one it holds, frees the other
// (and keeps the last until drift_context_destroy). NULL-safe.
void drift__scratch_give(drift_context *ctx, void *block, size_t size);

#endif // DRIFT_CORE_SCRATCH_H
