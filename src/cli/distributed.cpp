#include "cli/distributed.h"

#include <mpi.h>

#include <algorithm>
#include <chrono>
#include <climits>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

namespace rlpbrt {

namespace {

// Whether a launcher started this process as one rank of a job: Open MPI's mpirun, or a PMI
// or PMIx process manager (Slurm's srun, MPICH's hydra).
bool launchedByMpi() {
    for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_SIZE", "PMI_RANK"})
        if (std::getenv(v)) return true;
    return false;
}

// The sum of sumDoubles: declared non-commutative so that MPI combines the ranks' terms in
// rank order (MPI 4.0, section 6.9.5), which makes the result independent of arrival order.
// (a + b == b + a in IEEE arithmetic: only the order of the terms matters.)
void orderedSum(void* in, void* inout, int* len, MPI_Datatype*) {
    const double* a = static_cast<const double*>(in);
    double* b = static_cast<double*>(inout);
    for (int i = 0; i < *len; ++i) b[i] = a[i] + b[i];
}

double now() {
    using namespace std::chrono;
    return duration<double>(steady_clock::now().time_since_epoch()).count();
}

// Adds the wall time of a scope to a counter.
struct Timed {
    explicit Timed(double* total) : total_(total), start_(now()) {}
    ~Timed() { *total_ += now() - start_; }
    double* total_;
    double start_;
};

// Counts above INT_MAX go in chunks.
constexpr size_t kChunk = size_t(1) << 28;

// MPI_Allreduce in place of n elements of `type` (`size` bytes each), chunk by chunk.
void allreduceInPlace(void* data, size_t n, MPI_Datatype type, size_t size, MPI_Op op) {
    char* p = static_cast<char*>(data);
    for (size_t off = 0; off < n; off += kChunk)
        MPI_Allreduce(MPI_IN_PLACE, p + off * size, int(std::min(kChunk, n - off)), type, op,
                      MPI_COMM_WORLD);
}

class MpiRanks final : public Ranks {
public:
    MpiRanks() {
        MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
        MPI_Comm_size(MPI_COMM_WORLD, &size_);
        MPI_Op_create(&orderedSum, /*commute=*/0, &sumOp_);
    }
    ~MpiRanks() override { MPI_Op_free(&sumOp_); }
    int rank() const override { return rank_; }
    int size() const override { return size_; }

    void sumDoubles(double* data, size_t n) override {
        Timed t(&seconds_);
        arrive();
        bytes_ += n * sizeof(double);
        if (size_ == 2) {
            // Two terms: a + b and b + a are the same bits, so one allreduce gives every rank
            // the rank-order sum.
            allreduceInPlace(data, n, MPI_DOUBLE, sizeof(double), MPI_SUM);
            return;
        }
        std::vector<double> out(rank_ == 0 ? std::min(n, kChunk) : 0);
        for (size_t off = 0; off < n; off += kChunk) {
            const int c = int(std::min(kChunk, n - off));
            // Reduce to rank 0 in rank order, then the same bits to everyone.
            MPI_Reduce(data + off, rank_ == 0 ? out.data() : nullptr, c, MPI_DOUBLE, sumOp_, 0,
                       MPI_COMM_WORLD);
            if (rank_ == 0) std::copy(out.begin(), out.begin() + c, data + off);
            MPI_Bcast(data + off, c, MPI_DOUBLE, 0, MPI_COMM_WORLD);
        }
    }

    void sumCounts(uint32_t* data, size_t n) override {
        Timed t(&seconds_);
        arrive();
        bytes_ += n * sizeof(uint32_t);
        allreduceInPlace(data, n, MPI_UINT32_T, sizeof(uint32_t), MPI_SUM);
    }

    void sumDisjointFloats(float* data, size_t n, bool everyone) override {
        Timed t(&seconds_);
        arrive();
        bytes_ += n * sizeof(float);
        if (everyone) {
            allreduceInPlace(data, n, MPI_FLOAT, sizeof(float), MPI_SUM);
            return;
        }
        for (size_t off = 0; off < n; off += kChunk)
            MPI_Reduce(rank_ == 0 ? MPI_IN_PLACE : data + off, rank_ == 0 ? data + off : nullptr,
                       int(std::min(kChunk, n - off)), MPI_FLOAT, MPI_SUM, 0, MPI_COMM_WORLD);
    }

    void gatherBytes(std::string& data) override {
        Timed t(&seconds_);
        arrive();
        bytes_ += data.size();
        // Each rank's length, then the bytes (a rank's share must stay below 2 GiB, and so
        // must the whole: the spot candidates of one pass are far less).
        const long long mine = (long long)data.size();
        std::vector<long long> lengths(size_t(size_), 0);
        MPI_Allgather(&mine, 1, MPI_LONG_LONG, lengths.data(), 1, MPI_LONG_LONG, MPI_COMM_WORLD);
        std::vector<int> counts(static_cast<size_t>(size_), 0), offsets(static_cast<size_t>(size_), 0);
        long long total = 0;
        for (int k = 0; k < size_; ++k) {
            if (lengths[size_t(k)] > INT_MAX || total > INT_MAX - lengths[size_t(k)])
                throw std::runtime_error("gatherBytes: more than 2 GiB");
            counts[size_t(k)] = int(lengths[size_t(k)]);
            offsets[size_t(k)] = int(total);
            total += lengths[size_t(k)];
        }
        std::string all(size_t(total), '\0');
        MPI_Allgatherv(data.data(), int(mine), MPI_BYTE, all.data(), counts.data(),
                       offsets.data(), MPI_BYTE, MPI_COMM_WORLD);
        data = std::move(all);
    }

    void broadcast(void* data, size_t bytes) override {
        Timed t(&seconds_);
        arrive();
        bytes_ += bytes;
        char* p = static_cast<char*>(data);
        for (size_t off = 0; off < bytes; off += kChunk)
            MPI_Bcast(p + off, int(std::min(kChunk, bytes - off)), MPI_BYTE, 0, MPI_COMM_WORLD);
    }

    bool allOk(bool ok) override {
        Timed t(&seconds_);
        arrive();
        int v = ok ? 1 : 0, all = 0;
        bytes_ += sizeof(int);
        MPI_Allreduce(&v, &all, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
        return all == 1;
    }

    uint64_t bytesExchanged() const override { return bytes_; }
    double secondsExchanging() const override { return seconds_; }
    double secondsWaiting() const override { return waiting_; }

private:
    // Waits for every rank at a barrier (timed apart: the wait for the slowest rank, not the
    // transfer; docs/DISTRIBUTED.md).
    void arrive() {
        Timed t(&waiting_);
        MPI_Barrier(MPI_COMM_WORLD);
    }
    int rank_ = 0, size_ = 1;
    MPI_Op sumOp_;
    uint64_t bytes_ = 0;
    double seconds_ = 0.0;
    double waiting_ = 0.0;
};

}  // namespace

DistributedSession::DistributedSession(int* argc, char*** argv) {
    if (!launchedByMpi()) return;
    // Only the main thread calls MPI (the render's worker threads never do).
    int provided = 0;
    MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided);
    initialised_ = true;
    int size = 1;
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    if (size > 1) ranks_ = std::make_unique<MpiRanks>();
}

DistributedSession::~DistributedSession() {
    ranks_.reset();
    if (initialised_) MPI_Finalize();
}

void DistributedSession::abort(int code) {
    if (initialised_) MPI_Abort(MPI_COMM_WORLD, code);
    std::exit(code);
}

}  // namespace rlpbrt
