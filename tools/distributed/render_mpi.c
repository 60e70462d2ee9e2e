// mpirun -n N drift render ...: the reference path tracer's tiles over MPI ranks (issue 19,
// docs/distributed.md). Built only with -DDRIFT_MPI=ON; nothing else in drift sees MPI.
//
// Every rank opens the same scene and makes the same path tracer. Rank 0 hands out jobs (a
// few tiles and a number of samples to add) from a queue, keeps two jobs queued at each
// other rank so none waits for it, renders jobs of its own in between, and merges what comes
// back into its pt. A job carries the tiles' sums and counts from rank 0 and brings them back
// with the samples added; a pixel's samples are still summed one by one in index order, so
// the image is the same bits as one process's for any number of ranks and any hand-out
// order. Rank 0 alone writes: progress, checkpoints (FILE.ckpt holds every merged tile),
// the images and the stats, through the same steps as a one-process render (render.h).
#include "drift/pt.h"
#include "render.h"

#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

enum {
    TAG_SETUP = 1, // rank -> 0: its setup status and captured messages
    TAG_JOB,       // 0 -> rank: tiles to render
    TAG_RESULT,    // rank -> 0: the tiles rendered
    TAG_STOP       // 0 -> rank: no more jobs
};

// Jobs kept at each rank: one it renders, one waiting, so it never waits for rank 0.
#define JOBS_QUEUED 2

bool render_mpi_launched(void)
{
    return getenv("OMPI_COMM_WORLD_SIZE") || getenv("PMI_SIZE") || getenv("PMIX_RANK");
}

// --- ONE MESSAGE FOR A FAILED SETUP ---

// Ranks other than 0 write their setup messages (stdout and stderr) to a temporary file; if
// setup fails anywhere, rank 0 prints its own message or the first failing rank's, once.
typedef struct captured_output {
    FILE *file;
    int saved_stdout, saved_stderr;
} captured_output;

static void capture_begin(captured_output *c)
{
    fflush(stdout);
    fflush(stderr);
    c->file = tmpfile();
    c->saved_stdout = dup(STDOUT_FILENO);
    c->saved_stderr = dup(STDERR_FILENO);
    if (c->file) {
        dup2(fileno(c->file), STDOUT_FILENO);
        dup2(fileno(c->file), STDERR_FILENO);
    }
}

// Restores stdout and stderr; returns what was written (malloc'd, NUL-terminated) or NULL.
static char *capture_end(captured_output *c)
{
    fflush(stdout);
    fflush(stderr);
    dup2(c->saved_stdout, STDOUT_FILENO);
    dup2(c->saved_stderr, STDERR_FILENO);
    close(c->saved_stdout);
    close(c->saved_stderr);
    if (!c->file) {
        return NULL;
    }
    long size = ftell(c->file);
    char *text = size >= 0 ? calloc((size_t)size + 1, 1) : NULL;
    rewind(c->file);
    if (text && fread(text, 1, (size_t)size, c->file) != (size_t)size) {
        text[0] = '\0';
    }
    fclose(c->file);
    return text;
}

// Every rank's setup status to rank 0, which prints the first failing rank's messages when
// its own setup went well; all ranks return the same status. Ranks must also render the
// same thing: rank 0 compares each rank's checkpoint key with its own.
static int agree_on_setup(int rank, int ranks, int status, const char *text, const char *key)
{
    if (rank != 0) {
        int header[2] = { status, (int)strlen(text) + 1 };
        MPI_Send(header, 2, MPI_INT, 0, TAG_SETUP, MPI_COMM_WORLD);
        MPI_Send(text, header[1], MPI_CHAR, 0, TAG_SETUP, MPI_COMM_WORLD);
        MPI_Send(key, (int)strlen(key) + 1, MPI_CHAR, 0, TAG_SETUP, MPI_COMM_WORLD);
    } else {
        bool reported = status != 0; // rank 0's own message is already out
        for (int r = 1; r < ranks; ++r) {
            int header[2];
            MPI_Recv(header, 2, MPI_INT, r, TAG_SETUP, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
            char *their = calloc((size_t)header[1] + 1, 1);
            char their_key[1024] = { 0 };
            MPI_Recv(their, header[1], MPI_CHAR, r, TAG_SETUP, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
            MPI_Recv(their_key, sizeof their_key, MPI_CHAR, r, TAG_SETUP, MPI_COMM_WORLD,
                     MPI_STATUS_IGNORE);
            if (header[0] != 0 && !reported) {
                for (char *line = their; line && *line;) {
                    char *end = strchr(line, '\n');
                    fprintf(stderr, "drift render: rank %d: %.*s\n", r,
                            (int)(end ? end - line : (long)strlen(line)), line);
                    line = end ? end + 1 : line + strlen(line);
                }
                reported = true;
            } else if (header[0] == 0 && status == 0 && strcmp(their_key, key) != 0) {
                fprintf(stderr,
                        "drift render: rank %d renders another scene or options than rank 0 "
                        "(checkpoint keys differ: give every rank the same files and "
                        "arguments); nothing written\n",
                        r);
                header[0] = 2;
                reported = true;
            }
            status = header[0] > status ? header[0] : status;
            free(their);
        }
    }
    MPI_Bcast(&status, 1, MPI_INT, 0, MPI_COMM_WORLD);
    return status;
}

// --- JOBS ---

// A job: uint32 add, until, tile count n, the n tiles, then each tile's state (pt.h). The
// result: uint32 n, the ray counters (4 x uint64), the n tiles, their states.
typedef struct byte_buffer {
    uint8_t *data;
    size_t size, cap;
} byte_buffer;

// Room for `size` more bytes; returns where they go (the size grows by them).
static uint8_t *buffer_grow(byte_buffer *b, size_t size)
{
    if (b->size + size > b->cap) {
        size_t cap = b->cap ? b->cap : 1 << 16;
        while (cap < b->size + size) {
            cap *= 2;
        }
        uint8_t *grown = realloc(b->data, cap);
        if (!grown) {
            fprintf(stderr, "drift render: out of memory\n");
            MPI_Abort(MPI_COMM_WORLD, 1);
        }
        b->data = grown;
        b->cap = cap;
    }
    b->size += size;
    return b->data + b->size - size;
}

static void buffer_put(byte_buffer *b, const void *data, size_t size)
{
    memcpy(buffer_grow(b, size), data, size);
}

static void put_tiles(byte_buffer *b, const drift_pt *pt, const uint32_t *tiles, uint32_t n)
{
    buffer_put(b, tiles, n * sizeof *tiles);
    for (uint32_t i = 0; i < n; ++i) {
        drift_pt_tile_get_state(pt, tiles[i],
                                buffer_grow(b, drift_pt_tile_state_size(pt, tiles[i])));
    }
}

// Reads n tiles and their states at `at` into the pt; returns the bytes read.
static size_t take_tiles(drift_pt *pt, const uint8_t *at, uint32_t n, uint32_t *tiles_out)
{
    const uint8_t *p = at;
    memcpy(tiles_out, p, n * sizeof *tiles_out);
    p += n * sizeof *tiles_out;
    for (uint32_t i = 0; i < n; ++i) {
        drift_pt_tile_set_state(pt, tiles_out[i], p);
        p += drift_pt_tile_state_size(pt, tiles_out[i]);
    }
    return (size_t)(p - at);
}

// Waits for a request rank 0 made; false when the job is being stopped (a signal: mpirun
// stops every rank when one dies, and a dead rank's message never completes) or `rank`
// (>= 0) has kept it waiting longer than timeout seconds.
static bool finish_request(MPI_Request *request, const atomic_bool *cancel, double timeout)
{
    double start = drift_time_now();
    for (;;) {
        int done = 0;
        MPI_Test(request, &done, MPI_STATUS_IGNORE);
        if (done) {
            return true;
        }
        if (atomic_load(cancel) || drift_time_now() - start > timeout) {
            return false; // left pending: the job ends without waiting for it
        }
        nanosleep(&(struct timespec){ .tv_nsec = 100000 }, NULL);
    }
}

static byte_buffer receive(int source, int tag, MPI_Status *status)
{
    MPI_Probe(source, tag, MPI_COMM_WORLD, status);
    int count = 0;
    MPI_Get_count(status, MPI_BYTE, &count);
    byte_buffer b = { .data = malloc(count ? (size_t)count : 1), .size = (size_t)count };
    MPI_Recv(b.data, count, MPI_BYTE, status->MPI_SOURCE, status->MPI_TAG, MPI_COMM_WORLD,
             MPI_STATUS_IGNORE);
    return b;
}

// Ranks other than 0: render each job, send it back (while the next one renders).
static void serve_jobs(drift_pt *pt, const atomic_bool *cancel)
{
    byte_buffer out[2] = { { 0 } };
    MPI_Request sent[2] = { MPI_REQUEST_NULL, MPI_REQUEST_NULL };
    uint32_t *tiles = malloc(drift_pt_tile_count(pt) * sizeof *tiles);
    drift_pt_stats before = { 0 };
    for (int which = 0;; which ^= 1) {
        MPI_Status status;
        byte_buffer job = receive(0, MPI_ANY_TAG, &status);
        if (status.MPI_TAG != TAG_JOB) {
            free(job.data);
            break;
        }
        uint32_t head[3];
        memcpy(head, job.data, sizeof head);
        take_tiles(pt, job.data + sizeof head, head[2], tiles);
        free(job.data);
        if (drift_pt_render_tiles(pt, tiles, head[2], head[0], head[1], cancel) != DRIFT_OK) {
            break; // SIGTERM: mpirun is stopping the job; rank 0 keeps what it merged
        }
        drift_pt_stats now = drift_pt_get_stats(pt);
        uint64_t rays[4] = { now.camera_rays - before.camera_rays,
                             now.shadow_rays - before.shadow_rays,
                             now.bounce_rays - before.bounce_rays,
                             now.nan_samples - before.nan_samples };
        before = now;
        MPI_Wait(&sent[which], MPI_STATUS_IGNORE);
        out[which].size = 0;
        buffer_put(&out[which], &head[2], sizeof head[2]);
        buffer_put(&out[which], rays, sizeof rays);
        put_tiles(&out[which], pt, tiles, head[2]);
        MPI_Isend(out[which].data, (int)out[which].size, MPI_BYTE, 0, TAG_RESULT, MPI_COMM_WORLD,
                  &sent[which]);
    }
    MPI_Waitall(2, sent, MPI_STATUSES_IGNORE);
    free(out[0].data);
    free(out[1].data);
    free(tiles);
}

// --- RANK 0 ---

typedef struct coordinator {
    render_reference_run *run;
    int ranks;
    uint32_t tile_count;
    uint32_t *queue; // tiles waiting for a job, a ring of tile_count
    uint32_t head, queued;
    uint32_t pass;      // samples a job adds (doubles while a round of jobs is quick)
    uint32_t handed;    // jobs' tiles handed out since the pass last changed
    double round_start; // when that began
    int *outstanding;   // jobs at each rank
    double *last_heard; // when each rank last sent a result (or got its first job)
    int *threads;       // each rank's worker threads: tiles a job
    uint64_t bytes_sent, bytes_received, tiles_merged;
    double merge_seconds; // rank 0's time unpacking results
    const atomic_bool *cancel;
    int stuck_on; // a rank whose message did not complete (hung or dead, or a signal came)
} coordinator;

static uint32_t take_queued(coordinator *c, uint32_t *tiles, uint32_t most)
{
    uint32_t n = 0;
    while (n < most && c->queued > 0) {
        tiles[n++] = c->queue[c->head];
        c->head = (c->head + 1) % c->tile_count;
        c->queued--;
    }
    c->handed += n;
    if (c->handed >= c->tile_count) { // a round: grow the pass while rounds are short
        double now = drift_time_now();
        if (now - c->round_start < 0.5 && c->pass < (1u << 20)) {
            c->pass *= 2;
        }
        c->handed = 0;
        c->round_start = now;
    }
    return n;
}

static void requeue(coordinator *c, uint32_t tile)
{
    if (drift_pt_tile_sample_count(c->run->pt, tile) < (uint32_t)c->run->o->spp) {
        c->queue[(c->head + c->queued) % c->tile_count] = tile;
        c->queued++;
    }
}

static void send_job(coordinator *c, int rank, uint32_t *scratch)
{
    uint32_t n = take_queued(c, scratch, (uint32_t)c->threads[rank]);
    if (n == 0) {
        return;
    }
    uint32_t head[3] = { c->pass, (uint32_t)c->run->o->spp, n };
    byte_buffer b = { 0 };
    buffer_put(&b, head, sizeof head);
    put_tiles(&b, c->run->pt, scratch, n);
    MPI_Request request;
    MPI_Isend(b.data, (int)b.size, MPI_BYTE, rank, TAG_JOB, MPI_COMM_WORLD, &request);
    if (!finish_request(&request, c->cancel, c->run->o->rank_timeout)) {
        c->stuck_on = rank;
        return; // b.data stays with the pending request
    }
    c->bytes_sent += b.size;
    free(b.data);
    if (c->outstanding[rank]++ == 0) {
        c->last_heard[rank] = drift_time_now();
    }
}

// Merges every result that has arrived; returns how many.
static int merge_results(coordinator *c, uint32_t *scratch)
{
    int merged = 0;
    for (;;) {
        int ready = 0;
        MPI_Status status;
        MPI_Iprobe(MPI_ANY_SOURCE, TAG_RESULT, MPI_COMM_WORLD, &ready, &status);
        if (!ready) {
            return merged;
        }
        int count = 0;
        MPI_Get_count(&status, MPI_BYTE, &count);
        byte_buffer b = { .data = malloc(count ? (size_t)count : 1), .size = (size_t)count };
        MPI_Request request;
        MPI_Irecv(b.data, count, MPI_BYTE, status.MPI_SOURCE, TAG_RESULT, MPI_COMM_WORLD, &request);
        if (!finish_request(&request, c->cancel, c->run->o->rank_timeout)) {
            c->stuck_on = status.MPI_SOURCE; // its tiles keep the state merged before
            return merged;                   // (b.data stays with the pending request)
        }
        double t0 = drift_time_now();
        uint32_t n;
        uint64_t rays[4];
        memcpy(&n, b.data, sizeof n);
        memcpy(rays, b.data + sizeof n, sizeof rays);
        take_tiles(c->run->pt, b.data + sizeof n + sizeof rays, n, scratch);
        drift_pt_add_stats(c->run->pt, &(drift_pt_stats){ .camera_rays = rays[0],
                                                          .shadow_rays = rays[1],
                                                          .bounce_rays = rays[2],
                                                          .nan_samples = rays[3] });
        for (uint32_t i = 0; i < n; ++i) {
            requeue(c, scratch[i]);
        }
        c->merge_seconds += drift_time_now() - t0;
        c->bytes_received += b.size;
        c->tiles_merged += n;
        free(b.data);
        c->outstanding[status.MPI_SOURCE]--;
        c->last_heard[status.MPI_SOURCE] = drift_time_now();
        merged++;
    }
}

// Rank 0's loop; returns the rank found hung (0: none).
static int coordinate(coordinator *c, const atomic_bool *cancel)
{
    const render_options *o = c->run->o;
    drift_pt *pt = c->run->pt;
    uint32_t *scratch = malloc(c->tile_count * sizeof *scratch);
    bool tty = isatty(STDERR_FILENO) != 0;
    double last_report = 0.0, last_checkpoint = c->run->t_render;
    uint32_t shown = UINT32_MAX;
    int hung = 0;
    while (!atomic_load(cancel)) {
        merge_results(c, scratch);
        for (int r = 1; r < c->ranks; ++r) {
            while (c->outstanding[r] < JOBS_QUEUED && c->queued > 0 && !c->stuck_on) {
                send_job(c, r, scratch);
            }
        }
        int in_flight = 0;
        for (int r = 1; r < c->ranks; ++r) {
            in_flight += c->outstanding[r];
            if (c->outstanding[r] > 0 && drift_time_now() - c->last_heard[r] > o->rank_timeout) {
                hung = r;
            }
        }
        if (c->stuck_on && !atomic_load(cancel)) {
            hung = c->stuck_on; // a message to or from it did not complete in time: it, not
        }                       // the others whose results waited meanwhile
        if (hung) {
            break;
        }
        if (c->queued > 0) { // rank 0 renders a job too
            uint32_t n = take_queued(c, scratch, (uint32_t)c->threads[0]);
            drift_pt_render_tiles(pt, scratch, n, c->pass, (uint32_t)o->spp, cancel);
            for (uint32_t i = 0; i < n; ++i) {
                requeue(c, scratch[i]);
            }
        } else if (in_flight == 0) {
            break; // every tile has its samples
        } else {
            nanosleep(&(struct timespec){ .tv_nsec = 1000000 }, NULL);
        }
        uint32_t done = drift_pt_sample_count(pt);
        double now = drift_time_now();
        if (!o->quiet && done != shown &&
            (tty || now - last_report > 5.0 || done == (uint32_t)o->spp)) {
            render_progress(tty, c->run->resumed_spp, done, (uint32_t)o->spp,
                            now - c->run->t_render, done == (uint32_t)o->spp);
            last_report = now;
            shown = done;
        }
        if (o->checkpoint_seconds > 0.0 && now - last_checkpoint > o->checkpoint_seconds &&
            done < (uint32_t)o->spp) {
            if (render_reference_checkpoint(c->run) && !o->quiet) {
                fprintf(stderr, "%sdrift render: checkpoint at %u spp written to %s and %s\n",
                        tty ? "\n" : "", done, o->out_path, c->run->checkpoint_path);
            }
            last_checkpoint = now;
        }
    }
    uint32_t done = drift_pt_sample_count(pt);
    if (!o->quiet && done != shown && done == (uint32_t)o->spp) {
        render_progress(tty, c->run->resumed_spp, done, done, drift_time_now() - c->run->t_render,
                        true);
    }
    free(scratch);
    return hung;
}

static int render_rank0(render_reference_run *run, int ranks, const int *threads,
                        const atomic_bool *cancel)
{
    const render_options *o = run->o;
    coordinator c = { .run = run,
                      .ranks = ranks,
                      .tile_count = drift_pt_tile_count(run->pt),
                      .pass = 1,
                      .outstanding = calloc((size_t)ranks, sizeof(int)),
                      .last_heard = calloc((size_t)ranks, sizeof(double)),
                      .threads = (int *)threads,
                      .cancel = cancel };
    c.queue = malloc(c.tile_count * sizeof *c.queue);
    for (uint32_t t = 0; t < c.tile_count; ++t) {
        requeue(&c, t);
    }
    run->t_render = c.round_start = drift_time_now();
    if (!o->quiet) {
        drift_pt_params p = drift_pt_get_params(run->pt);
        fprintf(stderr, "drift render: %s, %dx%d, %ld spp, depth %d, %d ranks (%u tiles of %d)\n",
                run->session->scene_path, p.width, p.height, o->spp, p.max_depth, ranks,
                c.tile_count, DRIFT_PT_TILE_SIZE);
    }
    int hung = coordinate(&c, cancel);
    double t_rendered = drift_time_now();
    if (hung) {
        fprintf(stderr,
                "drift render: rank %d sent nothing for %.0f s (hung, or its machine is gone); "
                "stopping the job with the tiles merged so far\n",
                hung, o->rank_timeout);
    }
    if (o->verbose) {
        fprintf(stderr,
                "drift render: rank 0 sent %.0f and received %.0f bytes, merged %llu tiles in "
                "%.3f ms (%.0f bytes and %.2f us a tile)\n",
                (double)c.bytes_sent, (double)c.bytes_received, (unsigned long long)c.tiles_merged,
                1e3 * c.merge_seconds,
                c.tiles_merged ? (double)c.bytes_received / (double)c.tiles_merged : 0.0,
                c.tiles_merged ? 1e6 * c.merge_seconds / (double)c.tiles_merged : 0.0);
    }
    run->ranks = ranks;
    int status = render_reference_finish(run, atomic_load(cancel), t_rendered);
    if (hung || atomic_load(cancel)) {
        // A hung rank cannot be waited for, nor a dead one (mpirun stops the job with
        // SIGTERM when a rank dies): the outputs and the checkpoint are written, end here.
        fflush(NULL);
        MPI_Abort(MPI_COMM_WORLD, status ? status : 1);
    }
    for (int r = 1; r < ranks; ++r) {
        MPI_Send(NULL, 0, MPI_BYTE, r, TAG_STOP, MPI_COMM_WORLD);
    }
    free(c.queue);
    free(c.outstanding);
    free(c.last_heard);
    return status;
}

int render_mpi(int argc, char **argv)
{
    int provided = 0, rank = 0, ranks = 1;
    MPI_Init_thread(NULL, NULL, MPI_THREAD_FUNNELED, &provided);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &ranks);

    // Setup: options, scene, accel, pt, checkpoint; every rank, one message.
    captured_output capture = { 0 };
    if (rank != 0) {
        capture_begin(&capture);
    }
    render_options o;
    cli_session session = { 0 };
    render_reference_run run = { .o = &o, .session = &session };
    bool opened = false;
    int status = render_parse_options(argc, argv, &o);
    if (status == 0 && (o.hybrid_mode || o.debug_sample >= 0)) {
        fprintf(stderr, "drift render: under mpirun drift renders the reference path tracer only "
                        "(run --mode hybrid and --debug-sample in one process)\n");
        status = 2;
    }
    if (status == 0) {
        opened = true;
        status = render_open_session(&o, rank == 0, &session);
    }
    if (status == 0) {
        // Rank 0 resumes; the others take tiles from it and never read the checkpoint.
        if (rank != 0) {
            o.resume_path = NULL;
        }
        status = rank == 0 ? render_reference_begin(&run) : 0;
        if (rank != 0) {
            drift_pt_params params = { .width = (int32_t)o.width,
                                       .height = (int32_t)o.height,
                                       .seed = (uint32_t)o.seed,
                                       .max_depth = (int32_t)o.max_depth,
                                       .reflection_edits = o.hybrid.reflection_edits };
            status = drift_pt_create(session.ctx, session.scene, session.accel, &params, &run.pt) ==
                                 DRIFT_OK &&
                             render_checkpoint_key(&session, run.pt, o.edits_path, run.key,
                                                   sizeof run.key)
                         ? 0
                         : 1;
        }
    }
    char *text = rank != 0 ? capture_end(&capture) : NULL;
    status = status < 0 ? 0 : status; // --help: printed by rank 0
    bool help = status == 0 && !opened;
    status = agree_on_setup(rank, ranks, status, text ? text : "", run.key);
    free(text);

    if (status == 0 && !help) {
        const atomic_bool *cancel = render_catch_sigint();
        int mine = drift_context_thread_count(session.ctx);
        int *threads = rank == 0 ? calloc((size_t)ranks, sizeof(int)) : NULL;
        MPI_Gather(&mine, 1, MPI_INT, threads, 1, MPI_INT, 0, MPI_COMM_WORLD);
        if (rank == 0) {
            status = render_rank0(&run, ranks, threads, cancel);
        } else {
            serve_jobs(run.pt, cancel);
        }
        free(threads);
    }
    drift_pt_destroy(run.pt);
    if (opened) {
        render_close_session(&o, &session);
    }
    MPI_Finalize();
    return rank == 0 ? status : (status == 0 ? 0 : status);
}
