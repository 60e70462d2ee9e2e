#include "core/scratch.h"
#include "drift/core.h"

#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

// Upper bound on pool size: far above any machine we run on, keeps per-thread arrays small.
#define MAX_THREADS DRIFT_MAX_THREADS

typedef struct worker_arg {
    drift_context *ctx;
    int index;
} worker_arg;

typedef struct pool_job {
    drift_range_func fn;
    void *user;
    size_t count;
    size_t grain;
    atomic_size_t next; // next item to hand out
    int busy_count;     // workers inside this job; guarded by the context mutex
} pool_job;

struct drift_context {
    drift_context_desc desc; // resolved: thread_count is the pool size
    pthread_t workers[MAX_THREADS];
    worker_arg worker_args[MAX_THREADS];
    int worker_count;
    pthread_mutex_t mutex;
    pthread_cond_t wake;
    pthread_cond_t done;
    pool_job *job;       // current job, guarded by mutex
    uint64_t job_serial; // bumps once per job so sleeping workers see a new one
    bool shutting_down;
    pthread_mutex_t scratch_mutex; // guards scratch (core/scratch.h)
    void *scratch;
    size_t scratch_size;
};

#define DRIFT__RESULT_TEXT(name, text) text,
static const char *const result_text[] = { DRIFT_RESULT_LIST(DRIFT__RESULT_TEXT) };
#undef DRIFT__RESULT_TEXT

const char *drift_result_string(drift_result r)
{
    if ((int)r < 0 || r >= DRIFT_RESULT_COUNT) {
        return "unknown result";
    }
    return result_text[r];
}

drift_context_desc drift_context_desc_resolve(const drift_context_desc *desc)
{
    drift_context_desc d = desc ? *desc : (drift_context_desc){ 0 };
    if (d.thread_count == 0) {
        long n = sysconf(_SC_NPROCESSORS_ONLN);
        d.thread_count = n > 0 ? (int)n : 1;
    }
    if (d.thread_count > MAX_THREADS) {
        d.thread_count = MAX_THREADS;
    }
    return d;
}

static void run_chunks(pool_job *job, int thread_index)
{
    for (;;) {
        size_t begin = atomic_fetch_add(&job->next, job->grain);
        if (begin >= job->count) {
            return;
        }
        size_t end = begin + job->grain < job->count ? begin + job->grain : job->count;
        job->fn(begin, end, thread_index, job->user);
    }
}

static void *worker_main(void *arg)
{
    drift_context *ctx = ((worker_arg *)arg)->ctx;
    int index = ((worker_arg *)arg)->index;
    uint64_t seen = 0;
    pthread_mutex_lock(&ctx->mutex);
    for (;;) {
        // Joining happens under the mutex, so the caller cannot retire a job that a
        // worker is about to enter.
        while (!ctx->shutting_down && (!ctx->job || ctx->job_serial == seen)) {
            pthread_cond_wait(&ctx->wake, &ctx->mutex);
        }
        if (ctx->shutting_down) {
            break;
        }
        seen = ctx->job_serial;
        pool_job *job = ctx->job;
        job->busy_count++;
        pthread_mutex_unlock(&ctx->mutex);
        run_chunks(job, index);
        pthread_mutex_lock(&ctx->mutex);
        if (--job->busy_count == 0) {
            pthread_cond_broadcast(&ctx->done);
        }
    }
    pthread_mutex_unlock(&ctx->mutex);
    return NULL;
}

drift_result drift_context_create(const drift_context_desc *desc, drift_context **out_ctx)
{
    if (!out_ctx) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    *out_ctx = NULL;
    if (desc && desc->thread_count < 0) {
        return DRIFT_ERR_INVALID_ARGUMENT;
    }
    drift_context_desc d = drift_context_desc_resolve(desc);
    void *mem = d.allocator.alloc ? d.allocator.alloc(sizeof(drift_context), d.allocator.user)
                                  : malloc(sizeof(drift_context));
    if (!mem) {
        return DRIFT_ERR_OUT_OF_MEMORY;
    }
    drift_context *ctx = mem;
    memset(ctx, 0, sizeof(*ctx));
    ctx->desc = d;
    pthread_mutex_init(&ctx->mutex, NULL);
    pthread_mutex_init(&ctx->scratch_mutex, NULL);
    pthread_cond_init(&ctx->wake, NULL);
    pthread_cond_init(&ctx->done, NULL);
    // The calling thread is worker 0; the pool adds thread_count - 1 more.
    for (int i = 1; i < d.thread_count; ++i) {
        ctx->worker_args[i] = (worker_arg){ ctx, i };
        if (pthread_create(&ctx->workers[ctx->worker_count], NULL, worker_main,
                           &ctx->worker_args[i]) != 0) {
            drift_context_destroy(ctx);
            return DRIFT_ERR_OUT_OF_MEMORY;
        }
        ctx->worker_count++;
    }
    *out_ctx = ctx;
    return DRIFT_OK;
}

void drift_context_destroy(drift_context *ctx)
{
    if (!ctx) {
        return;
    }
    pthread_mutex_lock(&ctx->mutex);
    ctx->shutting_down = true;
    pthread_cond_broadcast(&ctx->wake);
    pthread_mutex_unlock(&ctx->mutex);
    for (int i = 0; i < ctx->worker_count; ++i) {
        pthread_join(ctx->workers[i], NULL);
    }
    pthread_mutex_destroy(&ctx->mutex);
    pthread_mutex_destroy(&ctx->scratch_mutex);
    drift_free(ctx, ctx->scratch);
    pthread_cond_destroy(&ctx->wake);
    pthread_cond_destroy(&ctx->done);
    drift_allocator a = ctx->desc.allocator;
    if (a.free) {
        a.free(ctx, a.user);
    } else {
        free(ctx);
    }
}

void *drift__scratch_take(drift_context *ctx, size_t size, size_t *have)
{
    pthread_mutex_lock(&ctx->scratch_mutex);
    void *block = ctx->scratch;
    *have = ctx->scratch_size;
    ctx->scratch = NULL;
    ctx->scratch_size = 0;
    pthread_mutex_unlock(&ctx->scratch_mutex);
    if (block && *have >= size) {
        return block;
    }
    drift_free(ctx, block);
    block = drift_alloc(ctx, size);
    *have = block ? size : 0;
    return block;
}

void drift__scratch_give(drift_context *ctx, void *block, size_t size)
{
    if (!block) {
        return;
    }
    pthread_mutex_lock(&ctx->scratch_mutex);
    if (!ctx->scratch || ctx->scratch_size < size) {
        void *t = ctx->scratch;
        ctx->scratch = block;
        ctx->scratch_size = size;
        block = t;
    }
    pthread_mutex_unlock(&ctx->scratch_mutex);
    drift_free(ctx, block);
}

int drift_context_thread_count(const drift_context *ctx)
{
    return ctx ? ctx->desc.thread_count : 1;
}

drift_logger drift_context_logger(const drift_context *ctx)
{
    return ctx ? ctx->desc.logger : (drift_logger){ 0 };
}

void drift_parallel_for(drift_context *ctx, size_t count, size_t grain, drift_range_func fn,
                        void *user)
{
    if (count == 0) {
        return;
    }
    if (grain == 0) {
        grain = 1;
    }
    pool_job job = { .fn = fn, .user = user, .count = count, .grain = grain };
    atomic_init(&job.next, 0);
    bool parallel = ctx && ctx->worker_count > 0 && count > grain;
    if (parallel) {
        pthread_mutex_lock(&ctx->mutex);
        ctx->job = &job;
        ctx->job_serial++;
        pthread_cond_broadcast(&ctx->wake);
        pthread_mutex_unlock(&ctx->mutex);
    }
    run_chunks(&job, 0);
    if (parallel) {
        // All items are handed out; wait for workers still inside, then retire the job
        // so that a worker waking late does not enter it.
        pthread_mutex_lock(&ctx->mutex);
        while (job.busy_count > 0) {
            pthread_cond_wait(&ctx->done, &ctx->mutex);
        }
        ctx->job = NULL;
        pthread_mutex_unlock(&ctx->mutex);
    }
}

drift_allocator drift__context_allocator(const drift_context *ctx);

drift_allocator drift__context_allocator(const drift_context *ctx)
{
    return ctx ? ctx->desc.allocator : (drift_allocator){ 0 };
}
