#include "drift/core.h"

#include <stdlib.h>
#include <string.h>

// The context keeps its desc private; memory.c reaches the allocator through this helper.
drift_allocator drift__context_allocator(const drift_context *ctx);

void *drift_alloc(drift_context *ctx, size_t size)
{
    if (size == 0) {
        size = 1;
    }
    drift_allocator a = drift__context_allocator(ctx);
    void *p = a.alloc ? a.alloc(size, a.user) : malloc(size);
    if (p) {
        memset(p, 0, size);
    }
    return p;
}

void drift_free(drift_context *ctx, void *ptr)
{
    if (!ptr) {
        return;
    }
    drift_allocator a = drift__context_allocator(ctx);
    if (a.free) {
        a.free(ptr, a.user);
    } else {
        free(ptr);
    }
}

void *drift_realloc(drift_context *ctx, void *ptr, size_t old_size, size_t new_size)
{
    void *p = drift_alloc(ctx, new_size);
    if (!p) {
        return NULL;
    }
    if (ptr) {
        memcpy(p, ptr, old_size < new_size ? old_size : new_size);
        drift_free(ctx, ptr);
    }
    return p;
}

bool drift_size_mul(size_t a, size_t b, size_t *out)
{
    return !__builtin_mul_overflow(a, b, out);
}

bool drift_size_add(size_t a, size_t b, size_t *out)
{
    return !__builtin_add_overflow(a, b, out);
}
