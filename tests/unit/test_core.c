#include "core/scratch.h"
#include "drift/math.h"
#include "drift_test.h"

#include <stdatomic.h>
#include <string.h>

static void test_core_result_strings(void **state)
{
    (void)state;
    assert_string_equal(drift_result_string(DRIFT_OK), "ok");
    assert_string_equal(drift_result_string(DRIFT_ERR_PARSE), "malformed input");
    assert_string_equal(drift_result_string((drift_result)999), "unknown result");
    assert_string_equal(drift_result_string((drift_result)-1), "unknown result");
}

static void test_core_desc_resolve_fills_defaults(void **state)
{
    (void)state;
    drift_context_desc d = drift_context_desc_resolve(&(drift_context_desc){ 0 });
    assert_true(d.thread_count >= 1);
    d = drift_context_desc_resolve(&(drift_context_desc){ .thread_count = 3 });
    assert_int_equal(d.thread_count, 3);
}

static void test_core_negative_threads_rejected(void **state)
{
    (void)state;
    drift_context *ctx = (drift_context *)1;
    assert_int_equal(drift_context_create(&(drift_context_desc){ .thread_count = -1 }, &ctx),
                     DRIFT_ERR_INVALID_ARGUMENT);
    assert_null(ctx);
}

typedef struct sum_job {
    atomic_uint_fast64_t sum;
    atomic_int calls;
    unsigned char *seen;
} sum_job;

static void sum_range(size_t begin, size_t end, int thread_index, void *user)
{
    sum_job *job = user;
    (void)thread_index;
    for (size_t i = begin; i < end; ++i) {
        atomic_fetch_add(&job->sum, (uint_fast64_t)i);
        job->seen[i]++;
    }
    atomic_fetch_add(&job->calls, 1);
}

static void test_core_parallel_for_visits_each_item_once(void **state)
{
    (void)state;
    for (int threads = 1; threads <= 4; ++threads) {
        drift_context *ctx = test_context(threads, NULL);
        for (int round = 0; round < 50; ++round) {
            size_t n = 1000 + (size_t)round * 37;
            sum_job job = { .seen = test_calloc(n, 1) };
            atomic_init(&job.sum, 0);
            atomic_init(&job.calls, 0);
            drift_parallel_for(ctx, n, 7, sum_range, &job);
            assert_int_equal(atomic_load(&job.sum), (uint64_t)n * (n - 1) / 2);
            for (size_t i = 0; i < n; ++i) {
                assert_int_equal(job.seen[i], 1);
            }
            test_free(job.seen);
        }
        drift_context_destroy(ctx);
    }
}

static void test_core_size_mul_detects_overflow(void **state)
{
    (void)state;
    size_t out = 0;
    assert_true(drift_size_mul(1000, 1000, &out));
    assert_int_equal(out, 1000000);
    assert_false(drift_size_mul(SIZE_MAX / 2 + 1, 2, &out));
    assert_false(drift_size_add(SIZE_MAX, 1, &out));
}

static void test_core_log_reaches_logger(void **state)
{
    (void)state;
    test_log_capture cap = { 0 };
    drift_context *ctx = test_context(1, &cap);
    drift_log(ctx, DRIFT_LOG_WARNING, DRIFT_ERR_PARSE, "x.json", 3, "bad %d", 7);
    assert_int_equal(cap.warnings, 1);
    assert_int_equal(cap.last_code, DRIFT_ERR_PARSE);
    assert_string_equal(cap.last_message, "bad 7");
    drift_context_destroy(ctx);
}

static void test_core_alloc_is_zeroed(void **state)
{
    (void)state;
    drift_context *ctx = test_context(1, NULL);
    unsigned char *p = drift_alloc(ctx, 4096);
    assert_non_null(p);
    for (int i = 0; i < 4096; ++i) {
        assert_int_equal(p[i], 0);
    }
    p = drift_realloc(ctx, p, 4096, 8192);
    assert_non_null(p);
    assert_int_equal(p[8191], 0);
    drift_free(ctx, p);
    drift_context_destroy(ctx);
}

// The scratch block: a take after a give returns the kept block when it is large enough
// (its contents as left), a larger request gets a new zeroed one, two takes never share one,
// and the context keeps the larger of two given back (ASan: nothing leaks or is freed twice).
static void test_core_scratch_is_kept_and_never_shared(void **state)
{
    (void)state;
    drift_context *ctx = test_context(1, NULL);
    size_t have = 0, have2 = 0;
    unsigned char *a = drift__scratch_take(ctx, 1000, &have);
    assert_non_null(a);
    assert_true(have >= 1000);
    a[999] = 7;
    drift__scratch_give(ctx, a, have);
    unsigned char *b = drift__scratch_take(ctx, 500, &have);
    assert_ptr_equal(b, a);
    assert_int_equal(b[999], 7);
    unsigned char *c = drift__scratch_take(ctx, 500, &have2); // the first is out: a new one
    assert_non_null(c);
    assert_ptr_not_equal(c, b);
    assert_int_equal(c[499], 0);
    drift__scratch_give(ctx, c, have2);
    drift__scratch_give(ctx, b, have); // larger: kept, c freed
    unsigned char *d = drift__scratch_take(ctx, 800, &have);
    assert_ptr_equal(d, b);
    unsigned char *e = drift__scratch_take(ctx, 4000, &have2);
    assert_true(have2 >= 4000);
    assert_int_equal(e[3999], 0);
    drift__scratch_give(ctx, d, have);
    drift__scratch_give(ctx, e, have2);
    drift__scratch_give(ctx, NULL, 0);
    drift_context_destroy(ctx); // frees the kept block
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_core_result_strings),
        cmocka_unit_test(test_core_desc_resolve_fills_defaults),
        cmocka_unit_test(test_core_negative_threads_rejected),
        cmocka_unit_test(test_core_parallel_for_visits_each_item_once),
        cmocka_unit_test(test_core_size_mul_detects_overflow),
        cmocka_unit_test(test_core_log_reaches_logger),
        cmocka_unit_test(test_core_alloc_is_zeroed),
        cmocka_unit_test(test_core_scratch_is_kept_and_never_shared),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
