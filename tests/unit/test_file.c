// drift_input_open (include/drift/file.h): a regular file opens; a FIFO, a device and a folder
// are refused at once with the kind named; a missing file gives the OS's reason. And the
// pool's thread cap that per-thread slots are sized by (DRIFT_MAX_THREADS, issue 43).
#define _DEFAULT_SOURCE // mkdtemp
#include "drift/file.h"
#include "drift_test.h"

#include <errno.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static void test_file_regular_opens(void **state)
{
    (void)state;
    char path[4096], why[128];
    test_out_path(path, "file_regular.txt");
    FILE *w = fopen(path, "wb");
    assert_non_null(w);
    fputs("drift", w);
    fclose(w);
    FILE *f = drift_input_fopen(path, why, sizeof why);
    assert_non_null(f);
    char text[8] = "";
    assert_int_equal(fread(text, 1, sizeof text - 1, f), 5);
    assert_string_equal(text, "drift");
    fclose(f);
    remove(path);
}

static void test_file_special_files_refused(void **state)
{
    (void)state;
    char dir[] = "/tmp/drift-file-XXXXXX", fifo[64], why[128];
    assert_non_null(mkdtemp(dir));
    snprintf(fifo, sizeof fifo, "%s/fifo", dir);
    assert_int_equal(mkfifo(fifo, 0600), 0);
    // A blocking open of a FIFO would wait here for a writer forever.
    errno = 0;
    assert_int_equal(drift_input_open(fifo, why, sizeof why), -1);
    assert_int_equal(errno, EINVAL);
    assert_string_equal(why, "not a regular file (a FIFO)");
    assert_null(drift_input_fopen("/dev/zero", why, sizeof why));
    assert_string_equal(why, "not a regular file (a character device)");
    assert_int_equal(drift_input_open(dir, why, sizeof why), -1);
    assert_string_equal(why, "not a regular file (a folder)");
    unlink(fifo);
    rmdir(dir);
}

static void test_file_missing_gives_reason(void **state)
{
    (void)state;
    char why[128];
    errno = 0;
    assert_int_equal(drift_input_open("/nonexistent/drift/file", why, sizeof why), -1);
    assert_int_equal(errno, ENOENT);
    assert_true(strlen(why) > 0);
}

static void record_thread(size_t begin, size_t end, int thread_index, void *user)
{
    (void)begin;
    (void)end;
    atomic_int *most = user;
    int seen = atomic_load(most);
    while (thread_index > seen && !atomic_compare_exchange_weak(most, &seen, thread_index)) {
    }
}

static void test_file_thread_cap_bounds_indices(void **state)
{
    (void)state;
    drift_context_desc d =
        drift_context_desc_resolve(&(drift_context_desc){ .thread_count = 1000 });
    assert_int_equal(d.thread_count, DRIFT_MAX_THREADS);
    drift_context *ctx = test_context(DRIFT_MAX_THREADS, NULL);
    assert_int_equal(drift_context_thread_count(ctx), DRIFT_MAX_THREADS);
    atomic_int most = -1;
    drift_parallel_for(ctx, 100000, 1, record_thread, &most);
    assert_true(atomic_load(&most) >= 0 && atomic_load(&most) < DRIFT_MAX_THREADS);
    drift_context_destroy(ctx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_file_regular_opens),
        cmocka_unit_test(test_file_special_files_refused),
        cmocka_unit_test(test_file_missing_gives_reason),
        cmocka_unit_test(test_file_thread_cap_bounds_indices),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
