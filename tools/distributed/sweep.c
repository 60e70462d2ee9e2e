// The sweep helper of sweep.h: MPI in the MPI build when started by mpirun, one rank otherwise.
#include "distributed/sweep.h"

#include "render.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#ifdef DRIFT_MPI
#    include <mpi.h>

enum {
    TAG_ITEM = 100
};

static int rank_here = 0, rank_count = 1;
static bool joined = false;

// MPI_Allreduce of one int, waiting by sleeping: a rank that finished its items early (or
// has none) leaves its core to the ranks still rendering instead of spinning in MPI.
static int agree(int value, MPI_Op op)
{
    int result = value;
    MPI_Request request;
    MPI_Iallreduce(&value, &result, 1, MPI_INT, op, MPI_COMM_WORLD, &request);
    for (long nap = 20000;; nap = nap < 5000000 ? 2 * nap : nap) { // 20 us, doubling to 5 ms
        int done = 0;
        MPI_Test(&request, &done, MPI_STATUS_IGNORE);
        if (done) {
            return result;
        }
        nanosleep(&(struct timespec){ .tv_nsec = nap }, NULL);
    }
}

void sweep_begin(void)
{
    if (!render_mpi_launched()) {
        return;
    }
    MPI_Init(NULL, NULL);
    joined = true;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_here);
    MPI_Comm_size(MPI_COMM_WORLD, &rank_count);
    if (rank_here != 0) { // rank 0 prints every figure and message once
        fflush(NULL);
        if (!freopen("/dev/null", "w", stdout) || !freopen("/dev/null", "w", stderr)) {
            MPI_Abort(MPI_COMM_WORLD, 1);
        }
    }
}

int sweep_end(int status)
{
    if (!joined) {
        return status;
    }
    int worst = agree(status, MPI_MAX);
    MPI_Finalize();
    joined = false;
    return worst;
}

int sweep_rank(void)
{
    return rank_here;
}

int sweep_ranks(void)
{
    return rank_count;
}

bool sweep_mine(int item)
{
    return item % rank_count == rank_here;
}

bool sweep_gather_owned(void *items, size_t size, int count, const int *owners, bool ok)
{
    if (rank_count == 1) {
        return ok;
    }
    if (!agree(ok ? 1 : 0, MPI_MIN)) { // every rank's message but rank 0's is discarded
        int failed = ok ? rank_count : rank_here, lowest = 0;
        MPI_Reduce(&failed, &lowest, 1, MPI_INT, MPI_MIN, 0, MPI_COMM_WORLD);
        if (rank_here == 0 && lowest != 0) {
            fprintf(stderr,
                    "drift bench: rank %d failed (run the command without mpirun to see "
                    "why)\n",
                    lowest);
        }
        return false;
    }
    uint8_t *bytes = items;
    for (int k = 0; k < count; ++k) {
        if (owners[k] == 0) {
            continue;
        }
        if (rank_here == 0) {
            MPI_Recv(bytes + (size_t)k * size, (int)size, MPI_BYTE, owners[k], TAG_ITEM,
                     MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        } else if (owners[k] == rank_here) {
            MPI_Send(bytes + (size_t)k * size, (int)size, MPI_BYTE, 0, TAG_ITEM, MPI_COMM_WORLD);
        }
    }
    return true;
}

bool sweep_gather(void *items, size_t size, int first, int count, bool ok)
{
    int *owners = malloc((size_t)(count > 0 ? count : 1) * sizeof *owners);
    if (!owners) {
        MPI_Abort(MPI_COMM_WORLD, 1);
    }
    for (int k = 0; k < count; ++k) {
        owners[k] = (first + k) % rank_count;
    }
    bool all = sweep_gather_owned(items, size, count, owners, ok);
    free(owners);
    return all;
}

int sweep_owner_besides(int busy, int index)
{
    return rank_count == 1 ? 0 : (busy + 1 + index % (rank_count - 1)) % rank_count;
}

bool sweep_share(void *data, size_t size, int owner, bool ok)
{
    if (rank_count == 1) {
        return ok;
    }
    if (!agree(ok ? 1 : 0, MPI_MIN)) {
        return false;
    }
    MPI_Request request;
    MPI_Ibcast(data, (int)size, MPI_BYTE, owner, MPI_COMM_WORLD, &request);
    for (long nap = 20000;; nap = nap < 5000000 ? 2 * nap : nap) {
        int done = 0;
        MPI_Test(&request, &done, MPI_STATUS_IGNORE);
        if (done) {
            return true;
        }
        nanosleep(&(struct timespec){ .tv_nsec = nap }, NULL);
    }
}

#else // the plain build: one rank

void sweep_begin(void)
{
}

int sweep_end(int status)
{
    return status;
}

int sweep_rank(void)
{
    return 0;
}

int sweep_ranks(void)
{
    return 1;
}

bool sweep_mine(int item)
{
    (void)item;
    return true;
}

bool sweep_gather(void *items, size_t size, int first, int count, bool ok)
{
    (void)items;
    (void)size;
    (void)first;
    (void)count;
    return ok;
}

bool sweep_gather_owned(void *items, size_t size, int count, const int *owners, bool ok)
{
    (void)items;
    (void)size;
    (void)count;
    (void)owners;
    return ok;
}

int sweep_owner_besides(int busy, int index)
{
    (void)busy;
    (void)index;
    return 0;
}

bool sweep_share(void *data, size_t size, int owner, bool ok)
{
    (void)data;
    (void)size;
    (void)owner;
    return ok;
}

#endif

bool sweep_pt_render(drift_pt *pt, uint32_t spp, bool ok)
{
    if (sweep_ranks() == 1) {
        return ok && drift_pt_render_samples(pt, spp, NULL) == DRIFT_OK;
    }
    bool own = ok;
    if (!sweep_share(NULL, 0, 0, ok)) { // every rank has its pt, or none goes on
        if (own && sweep_rank() == 0) {
            fprintf(stderr, "drift bench: a rank failed (run the command without mpirun to see "
                            "why)\n");
        }
        return false;
    }
    uint32_t tiles = drift_pt_tile_count(pt), count = 0;
    size_t most = 0;
    uint32_t *mine = malloc((size_t)tiles * sizeof *mine);
    for (uint32_t t = 0; mine && t < tiles; ++t) {
        if (sweep_mine((int)t)) {
            mine[count++] = t;
        }
        size_t size = drift_pt_tile_state_size(pt, t);
        most = size > most ? size : most;
    }
    void *state = malloc(most ? most : 1);
    ok = mine && state && drift_pt_render_tiles(pt, mine, count, spp, spp, NULL) == DRIFT_OK;
    own = ok;
    for (uint32_t t = 0; t < tiles; ++t) {
        int owner = (int)(t % (uint32_t)sweep_ranks());
        if (ok && owner == sweep_rank()) {
            drift_pt_tile_get_state(pt, t, state);
        }
        ok = sweep_share(state, ok ? drift_pt_tile_state_size(pt, t) : 0, owner, ok);
        if (ok && owner != sweep_rank()) {
            drift_pt_tile_set_state(pt, t, state);
        }
    }
    free(mine);
    free(state);
    if (!ok && own && sweep_rank() == 0) {
        fprintf(stderr, "drift bench: a rank failed (run the command without mpirun to see why)\n");
    }
    return ok;
}
