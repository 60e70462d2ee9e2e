// mpirun -n N drift bench ...: a benchmark sweep's independent renders spread over the ranks
// (issue 19, docs/distributed.md). Item k of a sweep is computed by rank k mod N; rank 0
// gathers every item and alone prints and writes files. Without mpirun, or in the plain build
// (-DDRIFT_MPI=OFF), there is one rank and these cost nothing.
#ifndef DRIFT_TOOLS_DISTRIBUTED_SWEEP_H
#define DRIFT_TOOLS_DISTRIBUTED_SWEEP_H

#include "drift/pt.h"

#include <stdbool.h>
#include <stddef.h>

// Joins the ranks when started by mpirun (MPI_Init); the output (stdout and stderr) of ranks
// other than 0 is discarded, so that each message and figure is printed once, by rank 0.
void sweep_begin(void);
// Every rank's exit status to all (the highest), MPI_Finalize; returns that status.
int sweep_end(int status);

int sweep_rank(void);
int sweep_ranks(void);
// Whether this rank computes sweep item `item` (item mod ranks == rank).
bool sweep_mine(int item);
// Rank 0 receives, into items[k] (k in [0, count), `size` bytes each), every item
// first + k computed by another rank; the others send theirs. `ok`: this rank's items all
// succeeded. Every rank must call it with the same first, count and size; returns, on every
// rank, whether all ranks' items succeeded (rank 0 names a rank that failed).
bool sweep_gather(void *items, size_t size, int first, int count, bool ok);

// The same with each item's rank given: owners[k] computed item k.
bool sweep_gather_owned(void *items, size_t size, int count, const int *owners, bool ok);
// The rank of the index-th item of a group whose first rank is busy with something larger
// (a reference): the other ranks in turn, or rank 0 alone when there is one rank.
int sweep_owner_besides(int busy, int index);
// `size` bytes at data from rank `owner` to every rank (every rank calls it). ok: this
// rank's part went well; returns whether every rank's did.
bool sweep_share(void *data, size_t size, int owner, bool ok);

// A reference rendered by every rank together: `spp` samples to every pixel of a fresh pt,
// tile t on rank t mod N, then every tile's state to every rank, so each holds the bits of
// one process's drift_pt_render_samples (pt.h). Every rank calls it (pt may be NULL where
// ok is false); returns whether every rank's part went well.
bool sweep_pt_render(drift_pt *pt, uint32_t spp, bool ok);

#endif // DRIFT_TOOLS_DISTRIBUTED_SWEEP_H
