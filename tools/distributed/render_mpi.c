// mpirun -n N drift render ...: the reference path tracer's tiles over MPI ranks (issue 19,
// docs/distributed.md). Built only with -DDRIFT_MPI=ON; nothing else in drift sees MPI.
//
// Every rank opens the same scene and makes the same path tracer. Rank 0 hands out jobs (a
// few tiles and a number of samples to add) from a queue, keeps JOBS_QUEUED jobs at each
// other rank so none waits for it (its sends and receives never block: they complete while
// it renders), renders jobs of its own a sample at a time, serving in between, and merges
// what comes back into its pt. A job carries the tiles' sums and counts from rank 0 and
// brings them back with the samples added; a pixel's samples are still summed one by one in
// index order, so the image is the same bits as one process's for any number of ranks and
// any hand-out order. Rank 0 alone writes: progress, checkpoints (FILE.ckpt holds every
// merged tile), the images and the stats, through the same steps as a one-process render
// (render.h). Also here: sweep.c, the benchmark sweeps over ranks (sweep.h).
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

// Jobs kept at each rank: one it renders and three waiting, so it never waits for rank 0
// (a job of a small pass is milliseconds, about a time slice of a loaded machine).
#define JOBS_QUEUED 4
// Sends rank 0 holds a rank: a job's send may still be completing when its result is in.
#define SENDS_HELD (2 * JOBS_QUEUED)

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
// result: uint32 n, the ray counters (4 x uint64), the seconds the rank waited for this job
// (a double), the n tiles, their states.
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

// How often a rank lets MPI move messages while it renders (between samples): often enough
// that no message waits long, rarely enough that it costs nothing next to the samples.
#define SERVE_SECONDS 2e-4

// Lets MPI move the messages under way (a large message needs both sides to enter MPI):
// one test of a pending request runs MPI's progress engine for all of them.
static void progress(MPI_Request *requests, int count)
{
    for (int i = 0; i < count; ++i) {
        if (requests[i] != MPI_REQUEST_NULL) {
            int done = 0;
            MPI_Request_get_status(requests[i], &done, MPI_STATUS_IGNORE);
            return;
        }
    }
}

// Waits for a request sleeping between tests, not spinning as MPI_Wait does: a rank waiting
// for a job leaves its core to the others (more ranks than cores, or a loaded machine); the
// naps grow, so that a long wait (the end of the render) costs few wake-ups.
static void wait_politely(MPI_Request *request, MPI_Status *status)
{
    for (long nap = 20000;; nap = nap < 640000 ? 2 * nap : nap) { // 20 us, doubling to 0.64 ms
        int done = 0;
        MPI_Test(request, &done, status);
        if (done) {
            return;
        }
        nanosleep(&(struct timespec){ .tv_nsec = nap }, NULL);
    }
}

// Ranks other than 0: JOBS_QUEUED receives stay posted for the next jobs, so that a job rank
// 0 sent arrives while this rank renders the one before; each job is rendered a sample at a
// time, letting MPI move messages in between, and sent back while the next one renders.
static void serve_jobs(drift_pt *pt, const atomic_bool *cancel, int threads)
{
    size_t job_size = 3 * sizeof(uint32_t) +
                      (size_t)threads * (sizeof(uint32_t) + drift_pt_tile_state_size(pt, 0));
    uint8_t *in[JOBS_QUEUED];
    byte_buffer out[JOBS_QUEUED] = { { 0 } };
    // [0, JOBS_QUEUED): the receives of the next jobs, matched in that order (a ring);
    // then the results being sent.
    MPI_Request requests[2 * JOBS_QUEUED];
    for (int i = 0; i < JOBS_QUEUED; ++i) {
        in[i] = malloc(job_size);
        MPI_Irecv(in[i], (int)job_size, MPI_BYTE, 0, MPI_ANY_TAG, MPI_COMM_WORLD, &requests[i]);
        requests[JOBS_QUEUED + i] = MPI_REQUEST_NULL;
    }
    uint32_t *tiles = malloc(drift_pt_tile_count(pt) * sizeof *tiles);
    drift_pt_stats before = { 0 };
    for (int which = 0, first = 1;; which = (which + 1) % JOBS_QUEUED, first = 0) {
        MPI_Status status;
        double asked = drift_time_now();
        wait_politely(&requests[which], &status);
        double waited = first ? 0.0 : drift_time_now() - asked; // the first: setup's end
        if (status.MPI_TAG != TAG_JOB) {
            break;
        }
        uint32_t head[3];
        memcpy(head, in[which], sizeof head);
        take_tiles(pt, in[which] + sizeof head, head[2], tiles);
        MPI_Irecv(in[which], (int)job_size, MPI_BYTE, 0, MPI_ANY_TAG, MPI_COMM_WORLD,
                  &requests[which]);
        bool stopped = false;
        double served = drift_time_now();
        for (uint32_t s = 0; s < head[0] && !stopped; ++s) {
            stopped = drift_pt_render_tiles(pt, tiles, head[2], 1, head[1], cancel) != DRIFT_OK;
            if (drift_time_now() - served > SERVE_SECONDS) {
                progress(requests, 2 * JOBS_QUEUED);
                served = drift_time_now();
            }
        }
        if (stopped) {
            break; // SIGTERM: mpirun is stopping the job; rank 0 keeps what it merged
        }
        drift_pt_stats now = drift_pt_get_stats(pt);
        uint64_t rays[4] = { now.camera_rays - before.camera_rays,
                             now.shadow_rays - before.shadow_rays,
                             now.bounce_rays - before.bounce_rays,
                             now.nan_samples - before.nan_samples };
        before = now;
        MPI_Request *sent = &requests[JOBS_QUEUED + which];
        MPI_Wait(sent, MPI_STATUS_IGNORE);
        out[which].size = 0;
        buffer_put(&out[which], &head[2], sizeof head[2]);
        buffer_put(&out[which], rays, sizeof rays);
        buffer_put(&out[which], &waited, sizeof waited);
        put_tiles(&out[which], pt, tiles, head[2]);
        MPI_Isend(out[which].data, (int)out[which].size, MPI_BYTE, 0, TAG_RESULT, MPI_COMM_WORLD,
                  sent);
    }
    for (int i = 0; i < JOBS_QUEUED; ++i) { // the receives left posted
        if (requests[i] != MPI_REQUEST_NULL) {
            MPI_Cancel(&requests[i]);
            MPI_Wait(&requests[i], MPI_STATUS_IGNORE);
        }
        free(in[i]);
    }
    MPI_Waitall(JOBS_QUEUED, requests + JOBS_QUEUED, MPI_STATUSES_IGNORE);
    for (int i = 0; i < JOBS_QUEUED; ++i) {
        free(out[i].data);
    }
    free(tiles);
}

// --- RANK 0 ---

// A job sent and not yet taken in by its rank, or a result being received: its bytes stay
// until the message completes.
typedef struct pending_message {
    MPI_Request request;
    uint8_t *data;
    size_t size;
    int rank;
    double since;
} pending_message;

typedef struct coordinator {
    render_reference_run *run;
    int ranks;
    uint32_t tile_count;
    uint32_t *queue; // tiles waiting for a job, a ring of tile_count
    uint32_t head, queued;
    uint32_t pass;          // samples a job adds (doubles while a round of jobs is quick)
    uint32_t handed;        // jobs' tiles handed out since the pass last changed
    double round_start;     // when that began
    int *outstanding;       // jobs at each rank
    double *last_heard;     // when each rank last sent a result (or got its first job)
    int *threads;           // each rank's worker threads: tiles a job
    pending_message *sends; // at most SENDS_HELD a rank
    pending_message *recvs; // at most JOBS_QUEUED a rank (one a job out)
    int sends_pending, recvs_pending;
    uint32_t *scratch; // tile indices of a job being packed or merged
    uint64_t bytes_sent, bytes_received, tiles_merged;
    double merge_seconds;  // rank 0's time unpacking results
    double serve_seconds;  // rank 0's time in MPI and job handling, merges included
    double served;         // when it last served
    double render_seconds; // rank 0's time rendering its own jobs
    double idle_seconds;   // rank 0 with nothing to render, waiting for the last results
    double workers_waited; // the other ranks' time waiting for a job, summed
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

// Sends a job without waiting for it to arrive: the rank takes it when it next asks, and
// rank 0 goes on rendering meanwhile.
static void send_job(coordinator *c, int rank)
{
    uint32_t n = take_queued(c, c->scratch, (uint32_t)c->threads[rank]);
    if (n == 0) {
        return;
    }
    uint32_t head[3] = { c->pass, (uint32_t)c->run->o->spp, n };
    byte_buffer b = { 0 };
    buffer_put(&b, head, sizeof head);
    put_tiles(&b, c->run->pt, c->scratch, n);
    pending_message *s = &c->sends[c->sends_pending++];
    *s = (pending_message){ .data = b.data, .rank = rank, .since = drift_time_now() };
    MPI_Isend(b.data, (int)b.size, MPI_BYTE, rank, TAG_JOB, MPI_COMM_WORLD, &s->request);
    c->bytes_sent += b.size;
    if (c->outstanding[rank]++ == 0) {
        c->last_heard[rank] = s->since;
    }
}

// Frees the jobs that have arrived; a job that its rank has not taken for --rank-timeout
// seconds marks that rank as stuck.
static void complete_sends(coordinator *c)
{
    double now = drift_time_now();
    for (int i = 0; i < c->sends_pending;) {
        int done = 0;
        MPI_Test(&c->sends[i].request, &done, MPI_STATUS_IGNORE);
        if (done) {
            free(c->sends[i].data);
            c->sends[i] = c->sends[--c->sends_pending];
            continue;
        }
        if (now - c->sends[i].since > c->run->o->rank_timeout && !c->stuck_on) {
            c->stuck_on = c->sends[i].rank; // its data stays with the pending request
        }
        ++i;
    }
}

// Takes in one result: its tiles' state into rank 0's pt, its counters into the stats.
static void take_result(coordinator *c, int rank, const uint8_t *p, size_t size)
{
    double t0 = drift_time_now();
    uint32_t n;
    uint64_t rays[4];
    double waited;
    memcpy(&n, p, sizeof n);
    memcpy(rays, p += sizeof n, sizeof rays);
    memcpy(&waited, p += sizeof rays, sizeof waited);
    take_tiles(c->run->pt, p + sizeof waited, n, c->scratch);
    drift_pt_add_stats(c->run->pt, &(drift_pt_stats){ .camera_rays = rays[0],
                                                      .shadow_rays = rays[1],
                                                      .bounce_rays = rays[2],
                                                      .nan_samples = rays[3] });
    for (uint32_t i = 0; i < n; ++i) {
        requeue(c, c->scratch[i]);
    }
    c->merge_seconds += drift_time_now() - t0;
    c->workers_waited += waited;
    c->bytes_received += size;
    c->tiles_merged += n;
    c->outstanding[rank]--;
    c->last_heard[rank] = drift_time_now();
}

// Starts receiving every result that has arrived and takes in those received, never waiting:
// a receive that has not completed for --rank-timeout seconds marks its rank as stuck.
static void merge_results(coordinator *c)
{
    for (;;) {
        int ready = 0;
        MPI_Status status;
        MPI_Iprobe(MPI_ANY_SOURCE, TAG_RESULT, MPI_COMM_WORLD, &ready, &status);
        if (!ready) {
            break;
        }
        int count = 0;
        MPI_Get_count(&status, MPI_BYTE, &count);
        pending_message *m = &c->recvs[c->recvs_pending++];
        *m = (pending_message){ .data = malloc(count ? (size_t)count : 1),
                                .size = (size_t)count,
                                .rank = status.MPI_SOURCE,
                                .since = drift_time_now() };
        MPI_Irecv(m->data, count, MPI_BYTE, m->rank, TAG_RESULT, MPI_COMM_WORLD, &m->request);
    }
    double now = drift_time_now();
    for (int i = 0; i < c->recvs_pending;) {
        pending_message *m = &c->recvs[i];
        int done = 0;
        MPI_Test(&m->request, &done, MPI_STATUS_IGNORE);
        if (done) {
            take_result(c, m->rank, m->data, m->size);
            free(m->data);
            *m = c->recvs[--c->recvs_pending];
            continue;
        }
        if (now - m->since > c->run->o->rank_timeout && !c->stuck_on) {
            c->stuck_on = m->rank; // its tiles keep the state merged before
        }
        ++i;
    }
}

// Rank 0's answer to the others, between its own samples: merge what came back, free the
// jobs that arrived, top every rank up to JOBS_QUEUED jobs (one near the end, so that the
// last tiles go to whoever is free first, rank 0 included).
static void serve(coordinator *c)
{
    double t0 = drift_time_now();
    merge_results(c);
    complete_sends(c);
    c->served = t0;
    int most = c->queued >= (uint32_t)(JOBS_QUEUED * c->ranks) ? JOBS_QUEUED : 1;
    for (int r = 1; r < c->ranks; ++r) {
        while (c->outstanding[r] < most && c->queued > 0 && !c->stuck_on &&
               c->sends_pending < SENDS_HELD * c->ranks) {
            send_job(c, r);
        }
    }
    c->serve_seconds += drift_time_now() - t0;
}

// Rank 0's loop; returns the rank found hung (0: none).
static int coordinate(coordinator *c, const atomic_bool *cancel)
{
    const render_options *o = c->run->o;
    drift_pt *pt = c->run->pt;
    uint32_t *own = malloc(c->tile_count * sizeof *own);
    bool tty = isatty(STDERR_FILENO) != 0;
    double last_report = 0.0, last_checkpoint = c->run->t_render;
    uint32_t shown = UINT32_MAX;
    int hung = 0;
    while (!atomic_load(cancel)) {
        serve(c);
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
        if (c->queued > 0) { // rank 0 renders a job too, a sample at a time when it serves
            uint32_t add = c->pass, n = take_queued(c, own, (uint32_t)c->threads[0]);
            uint32_t step = c->ranks > 1 ? 1 : add;
            for (uint32_t s = 0; s < add && !atomic_load(cancel) && !c->stuck_on; s += step) {
                double t0 = drift_time_now();
                drift_pt_render_tiles(pt, own, n, step, (uint32_t)o->spp, cancel);
                c->render_seconds += drift_time_now() - t0;
                if (c->ranks > 1 && drift_time_now() - c->served > SERVE_SECONDS) {
                    serve(c);
                }
            }
            for (uint32_t i = 0; i < n; ++i) {
                requeue(c, own[i]);
            }
        } else if (in_flight == 0) {
            break; // every tile has its samples
        } else {
            double t0 = drift_time_now();
            nanosleep(&(struct timespec){ .tv_nsec = 100000 }, NULL);
            c->idle_seconds += drift_time_now() - t0;
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
    free(own);
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
                      .sends = calloc((size_t)ranks * SENDS_HELD, sizeof(pending_message)),
                      .recvs = calloc((size_t)ranks * JOBS_QUEUED, sizeof(pending_message)),
                      .cancel = cancel };
    c.queue = malloc(c.tile_count * sizeof *c.queue);
    c.scratch = malloc(c.tile_count * sizeof *c.scratch);
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
        double wall = t_rendered - run->t_render;
        fprintf(stderr,
                "drift render: rank 0 sent %.0f and received %.0f bytes, merged %llu tiles in "
                "%.3f ms (%.0f bytes and %.2f us a tile)\n"
                "drift render: of %.3f s, rank 0 rendered %.1f%%, served the others %.2f%%, "
                "waited for the last results %.2f%%; the others waited for jobs %.2f%% of "
                "their time\n",
                (double)c.bytes_sent, (double)c.bytes_received, (unsigned long long)c.tiles_merged,
                1e3 * c.merge_seconds,
                c.tiles_merged ? (double)c.bytes_received / (double)c.tiles_merged : 0.0,
                c.tiles_merged ? 1e6 * c.merge_seconds / (double)c.tiles_merged : 0.0, wall,
                100.0 * c.render_seconds / wall, 100.0 * c.serve_seconds / wall,
                100.0 * c.idle_seconds / wall,
                ranks > 1 ? 100.0 * c.workers_waited / (wall * (ranks - 1)) : 0.0);
    }
    run->ranks = ranks;
    int status = render_reference_finish(run, atomic_load(cancel), t_rendered);
    if (hung || atomic_load(cancel)) {
        // A hung rank cannot be waited for, nor a dead one (mpirun stops the job with
        // SIGTERM when a rank dies): the outputs and the checkpoint are written, end here.
        fflush(NULL);
        MPI_Abort(MPI_COMM_WORLD, status ? status : 1);
    }
    // Every job came back, so every send has completed (or completes now).
    for (int i = 0; i < c.sends_pending; ++i) {
        MPI_Wait(&c.sends[i].request, MPI_STATUS_IGNORE);
        free(c.sends[i].data);
    }
    for (int r = 1; r < ranks; ++r) {
        MPI_Send(NULL, 0, MPI_BYTE, r, TAG_STOP, MPI_COMM_WORLD);
    }
    free(c.queue);
    free(c.scratch);
    free(c.sends);
    free(c.recvs);
    free(c.outstanding);
    free(c.last_heard);
    return status;
}

int render_mpi(int argc, char **argv)
{
    int provided = 0, rank = 0, ranks = 1;
    // With more ranks than cores Open MPI yields the core in every MPI call, which costs rank
    // 0 a time slice each time it serves between samples; ranks here wait by sleeping
    // instead (unless the user set it).
    setenv("OMPI_MCA_mpi_yield_when_idle", "0", 0);
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
            serve_jobs(run.pt, cancel, mine);
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
