// MPI behind render/distributed.h's Ranks: the one file pair of rlpbrt that includes mpi.h.
// A process started by mpirun or srun (Open MPI's, PMI's or PMIx's environment variables)
// initialises MPI; any other process does not touch MPI, so a plain run is unchanged.
#pragma once

#include <memory>

#include "render/distributed.h"

namespace rlpbrt {

// Initialises MPI if this process was launched by mpirun/srun; finalises it when destroyed.
class DistributedSession {
public:
    DistributedSession(int* argc, char*** argv);
    ~DistributedSession();
    DistributedSession(const DistributedSession&) = delete;
    DistributedSession& operator=(const DistributedSession&) = delete;
    // The ranks of a job of two or more processes; null when alone (no MPI, or one rank).
    Ranks* ranks() { return ranks_.get(); }
    // Whether MPI was initialised (also for a job of one rank).
    bool launched() const { return initialised_; }
    // Ends every rank of the job with `code` (a rank that cannot continue while the others
    // wait in a collective).
    [[noreturn]] void abort(int code);

private:
    bool initialised_ = false;
    std::unique_ptr<Ranks> ranks_;
};

}  // namespace rlpbrt
