// drift core: context, result codes, logging, allocation, thread pool.
//
// The context owns everything mutable that the library shares: the allocator, the
// logger and the thread pool. There are no globals, so two contexts can live in one
// process (tests do this).
//
// STEP BY STEP
//   drift_context *ctx = NULL;
//   drift_result r = drift_context_create(&(drift_context_desc){ .thread_count = 4 }, &ctx);
//   if (r != DRIFT_OK) { fprintf(stderr, "%s\n", drift_result_string(r)); return 1; }
//   drift_parallel_for(ctx, item_count, 64, my_fn, &my_data);
//   drift_context_destroy(ctx);
//
// Threads: drift_context_create/destroy are not thread-safe; drift_parallel_for may not
// be called re-entrantly from inside a worker. Logging and allocation are thread-safe
// when the user's callbacks are.
#ifndef DRIFT_CORE_H
#define DRIFT_CORE_H

#ifdef __cplusplus
// C++ passes a std::atomic_bool where the C API takes an atomic_bool (the same object
// representation; C++23's <stdatomic.h> says the same).
#    include <atomic>
using std::atomic_bool;
#else
#    include <stdatomic.h>
#endif
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define DRIFT_RESULT_LIST(X)                             \
    X(DRIFT_OK, "ok")                                    \
    X(DRIFT_ERR_INVALID_ARGUMENT, "invalid argument")    \
    X(DRIFT_ERR_OUT_OF_MEMORY, "out of memory")          \
    X(DRIFT_ERR_IO, "file could not be read or written") \
    X(DRIFT_ERR_PARSE, "malformed input")                \
    X(DRIFT_ERR_UNSUPPORTED, "unsupported feature")      \
    X(DRIFT_ERR_EMBREE, "embree reported an error")      \
    X(DRIFT_ERR_CANCELLED, "cancelled")

#define DRIFT__RESULT_ENUM(name, text) name,

typedef enum drift_result {
    DRIFT_RESULT_LIST(DRIFT__RESULT_ENUM) DRIFT_RESULT_COUNT
} drift_result;

#undef DRIFT__RESULT_ENUM

// Human text for a result; never NULL ("unknown result" when out of range).
const char *drift_result_string(drift_result r);

typedef enum drift_log_level {
    DRIFT_LOG_DEFAULT = 0, // as DRIFT_LOG_INFO where a level is configured
    DRIFT_LOG_DEBUG,
    DRIFT_LOG_INFO,
    DRIFT_LOG_WARNING,
    DRIFT_LOG_ERROR,
    DRIFT_LOG_COUNT
} drift_log_level;

// Receives every message of the library. `file` and `line` name the input file and line
// where a parser reports (0 when unknown), otherwise the source location.
typedef void (*drift_log_func)(drift_log_level level, drift_result code, const char *file, int line,
                               const char *message, void *user);

typedef struct drift_logger {
    drift_log_func func; // NULL: the library prints nothing
    void *user;
} drift_logger;

typedef struct drift_allocator {
    void *(*alloc)(size_t size, void *user); // NULL: malloc
    void (*free)(void *ptr, void *user);     // NULL: free
    void *user;
} drift_allocator;

// The most threads a context's pool has (a larger thread_count is cut to it). Per-thread
// slots of a parallel job are sized by it: every thread_index is below it, so no two
// threads share a slot.
#define DRIFT_MAX_THREADS 256

// How to create a context. The default configuration is:
//   thread_count = 0   -> one thread per online core (at most DRIFT_MAX_THREADS)
//   logger       = {0} -> silent
//   allocator    = {0} -> malloc/free
typedef struct drift_context_desc {
    int thread_count;
    drift_logger logger;
    drift_allocator allocator;
} drift_context_desc;

typedef struct drift_context drift_context;

drift_context_desc drift_context_desc_resolve(const drift_context_desc *desc);

// Creates a context and its thread pool. Errors: DRIFT_ERR_OUT_OF_MEMORY,
// DRIFT_ERR_INVALID_ARGUMENT (negative thread count). *out_ctx is NULL on failure.
drift_result drift_context_create(const drift_context_desc *desc, drift_context **out_ctx);
void drift_context_destroy(drift_context *ctx); // NULL-safe

int drift_context_thread_count(const drift_context *ctx);
drift_logger drift_context_logger(const drift_context *ctx);

// Allocation through the context's allocator. drift_alloc returns zeroed memory or NULL.
void *drift_alloc(drift_context *ctx, size_t size);
void drift_free(drift_context *ctx, void *ptr); // NULL-safe
// Reallocates through alloc+copy+free (the allocator has no realloc). old_size bytes are kept.
void *drift_realloc(drift_context *ctx, void *ptr, size_t old_size, size_t new_size);

// Overflow-checked size arithmetic: false when the product/sum does not fit.
bool drift_size_mul(size_t a, size_t b, size_t *out);
bool drift_size_add(size_t a, size_t b, size_t *out);

// Logs through the context's logger, printf-style. Safe to call with ctx == NULL (drops).
void drift_log(const drift_context *ctx, drift_log_level level, drift_result code, const char *file,
               int line, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 6, 7)))
#endif
    ;

// Runs fn(begin, end, thread_index, user) over [0, count) in chunks of `grain` items on the
// context's pool; the calling thread works too. thread_index is in [0, thread_count) and
// is stable for the duration of one chunk, so per-thread scratch can be indexed by it.
// Returns when all chunks are done. Chunks are handed out dynamically: results must not
// depend on which thread ran a chunk (drift keys all randomness on pixel and sample).
typedef void (*drift_range_func)(size_t begin, size_t end, int thread_index, void *user);
void drift_parallel_for(drift_context *ctx, size_t count, size_t grain, drift_range_func fn,
                        void *user);

// Monotonic wall clock in seconds.
double drift_time_now(void);

// Misuse checks. DRIFT_ASSERT is compiled out with NDEBUG; DRIFT_CHECK always stays.
void drift__check_failed(const char *expr, const char *file, int line);
#define DRIFT_CHECK(cond)                                   \
    do {                                                    \
        if (!(cond)) {                                      \
            drift__check_failed(#cond, __FILE__, __LINE__); \
        }                                                   \
    } while (0)
#ifdef NDEBUG
#    define DRIFT_ASSERT(cond) ((void)0)
#else
#    define DRIFT_ASSERT(cond) DRIFT_CHECK(cond)
#endif

#ifdef __cplusplus
}
#endif
#endif // DRIFT_CORE_H
