// The processes (ranks) of a distributed render as the render loop sees them: collective
// operations on plain buffers. Several ranks render disjoint film tiles of the same passes
// and learn one guiding field; the message-passing library (MPI) stays behind this interface
// (its one implementation is src/cli/distributed.cpp), so the render and guiding layers
// never include it. Every rank must call the same operations, in the same order, with
// buffers of the same sizes. docs/DISTRIBUTED.md.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace rlpbrt {

class Ranks {
public:
    virtual ~Ranks() = default;
    virtual int rank() const = 0;  // 0 .. size() - 1; rank 0 writes the outputs
    virtual int size() const = 0;

    // Element-wise sum over all ranks into every rank's `data`: the same bits on every rank,
    // whatever order the ranks arrive in (the terms are added in rank order).
    virtual void sumDoubles(double* data, size_t n) = 0;
    // Element-wise sum of counts over all ranks into every rank's `data` (exact in any order;
    // each total must be below 2^32).
    virtual void sumCounts(uint32_t* data, size_t n) = 0;
    // Element-wise sum of float buffers in which every element is non-zero on at most one
    // rank (film tiles that one rank rendered): the sum is exact, so any order gives the
    // owner's bits. everyone: the result on every rank, else on rank 0 only (the others'
    // buffers are then unspecified).
    virtual void sumDisjointFloats(float* data, size_t n, bool everyone) = 0;
    // Every rank's bytes, concatenated in rank order, in every rank's `data` (the ranks'
    // strings may differ in length).
    virtual void gatherBytes(std::string& data) = 0;
    // Rank 0's `bytes` bytes at `data` on every rank.
    virtual void broadcast(void* data, size_t bytes) = 0;
    // True on every rank if `ok` is true on every rank (all ranks must call it: an error on
    // one rank then stops all of them at the same point).
    virtual bool allOk(bool ok) = 0;

    // Bytes this rank has sent into collectives so far (its buffers' sizes, the payload).
    virtual uint64_t bytesExchanged() const = 0;
    // Wall seconds this rank has spent in collectives (transfers, and waiting for slower
    // ranks).
    virtual double secondsExchanging() const = 0;
    // Of those, the seconds spent waiting for the slowest rank to arrive (a barrier before
    // each collective), so that the rest is the transfer itself; 0 where not measured.
    virtual double secondsWaiting() const { return 0.0; }
};

// Whether tile `index` of a pass is this rank's (null ranks: a single process renders all).
inline bool ownsTile(const Ranks* ranks, size_t index) {
    return !ranks || int(index % size_t(ranks->size())) == ranks->rank();
}

}  // namespace rlpbrt
