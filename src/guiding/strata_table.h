// The learned part of a guiding field, independent of how regions are placed in space: per
// region a table of strata holding Q (double), visit counts, the float estimates that
// queries read (Q itself, or Q smoothed over a hierarchy of strata) and the frozen sampling
// CDF; per-slot record buffers and the deterministic slot-ordered batch merge of the
// records between passes (a running mean per stratum; docs/ARCHITECTURE.md, step 7). Shared
// by the hemi and vdb backends; standard library and TBB only.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "guiding/guiding.h"
#include "guiding/slot_merge.h"
#include "guiding/selection.h"

namespace rlpbrt::guiding {

class StrataTable {
public:
    // Rebuilds one region's CDF (strata + 1 floats) from its estimates (strata doubles: Q, or
    // Q smoothed, see setSmoothing).
    using PolicyBuilder = std::function<void(int region, const double* q, float* cdf)>;

    // regions x strata entries, every Q = init, no visits; CDFs built with `policy` (which
    // must depend on Q only: the first region's CDF is copied to all). Lazy: the regions share
    // one block of tables (the prior) until their first records, when endPass gives them
    // blocks of their own, so that memory follows the regions a scene's paths reach.
    void reset(size_t regions, int strata, double init, const PolicyBuilder& policy,
               bool lazy = false);
    // Appends regions (up to `regions` in all) with every Q = init and no visits, keeping
    // the existing ones and the counters; the new CDFs are built with `policy`. Not during a
    // pass (between endPass and beginPass only).
    void grow(size_t regions, double init, const PolicyBuilder& policy);

    size_t regions() const { return regions_; }
    int strata() const { return strata_; }
    // Bytes of one region's block of tables with `strata` strata (Q, estimates, visits, CDF)
    // and its learned selection: the per-region term of the backends' memory estimates.
    static double regionBytes(int strata) {
        const double n = strata;
        return n * (sizeof(double) + sizeof(float) + sizeof(uint64_t)) +
               (n + 1) * sizeof(float) + SelectionLearner::kBytesPerRegion;
    }
    const double* q(size_t region) const { return &q_[block_[region] * size_t(strata_)]; }
    // The estimates of a region's strata that queries and the policy use, frozen per pass:
    // Q itself, or with smoothing the shrunken estimates below.
    const float* estimates(size_t region) const {
        return &est_[block_[region] * size_t(strata_)];
    }

    // Hierarchical smoothing of the estimates (Bayesian shrinkage; off until set): the strata
    // are the leaves of a tree whose levels are given by parent maps (levels[0][j] = the node
    // of level 1 that holds stratum j, levels[1][i] = the parent of that node, ..., the last
    // level has a single node, the root). A node's estimate is (S + prior * parent's estimate)
    // / (N + prior), with N the visits under it and S the sum of their targets (visits x Q
    // for a stratum); the root's is S / N (reset()'s `init` while N = 0). A stratum with few
    // visits thus borrows its coarser neighbourhood's mean, one with many keeps its own Q, and a
    // stratum without visits is not taken for dark (which removes the bias of guided passes
    // that continue each pixel's sequence, docs/STABILITY.md). prior 0 or no levels: the
    // estimates are Q. Call before reset()/grow()/assign() build the policy.
    void setSmoothing(std::vector<std::vector<uint32_t>> levels, double prior);
    // The (unrounded) estimates of one region, strata doubles. `scratch` (optional) holds
    // smoothingScratch() doubles.
    void estimate(size_t region, double* out, double* scratch = nullptr) const;
    size_t smoothingScratch() const { return 3 * size_t(nodes_); }
    const uint64_t* visits(size_t region) const {
        return &visits_[block_[region] * size_t(strata_)];
    }
    const float* cdf(size_t region) const { return &cdf_[block_[region] * size_t(strata_ + 1)]; }
    // Regions with tables of their own (all of them unless lazy).
    size_t learnedRegions() const { return lazy_ ? blocks_ - (blocks_ > 0) : blocks_; }

    // Confidence of a region's policy: visits / (visits + warmup * strata) over all its
    // strata (1 for warmup 0), the factor both backends apply to the guide's mixture weight.
    float confidence(size_t region, double warmup) const {
        const double w = warmup * double(strata_);
        if (!(w > 0.0)) return 1.f;
        const double total = visitsTotal(region);
        return float(total / (total + w));
    }
    // Whether a region has fewer than cap records per stratum on average (cap 0: always).
    bool belowCap(size_t region, double cap) const {
        return !(cap > 0.0) || visitsTotal(region) < cap * double(strata_);
    }
    // The records a region has learned, over all its strata.
    double visitsTotal(size_t region) const {
        const uint64_t* v = visits(region);
        double total = 0.0;
        for (int j = 0; j < strata_; ++j) total += double(int64_t(v[j]));  // < 2^63
        return total;
    }

    // Per-pass record buffers (see GuidingField::beginPass/record).
    void beginPass(int numSlots);
    bool slotOpen(int slot) const { return slot >= 0 && size_t(slot) < slots_.size(); }
    // One record of GuidingField::record for a valid region: ignored without an open pass
    // in `slot`; a target that is negative or not finite is counted as rejected, and so is
    // a direction outside the region's strata (stratum < 0). `stratum` is called only for
    // an accepted target.
    template <class StratumOf>
    void record(int slot, int region, float target, StratumOf&& stratum) {
        if (!slotOpen(slot)) return;
        SlotBuffer& buf = slots_[size_t(slot)];
        if (!(target >= 0.f) || !std::isfinite(target)) {
            ++buf.rejectedTargets;
            return;
        }
        const int j = stratum();
        if (j < 0) {
            ++buf.rejectedRecords;
            return;
        }
        buf.records.push_back(Record{uint32_t(region), uint16_t(j), target});
    }
    // Applies the records in slot order (running mean if alphaVisits, else fixed alpha) and
    // rebuilds the CDFs of the regions that received records.
    void endPass(bool alphaVisits, double fixedAlpha, const PolicyBuilder& policy);
    // endPass for a table that several processes learn together (GuidingField::
    // endPassShared): the counters, the selection learner's statistics and each region's
    // number of records are summed first; then, for the regions that received records
    // anywhere, each stratum's count, and the sums of the targets of the strata that received
    // records anywhere (each process adds its own records in slot order, the processes' sums
    // are added in rank order). Counts go as 32-bit integers while the pass has fewer than
    // 2^32 records. The update is endPass's.
    void endPassShared(bool alphaVisits, double fixedAlpha, const PolicyBuilder& policy,
                       const SumAcrossProcesses& sum);

    // Replaces Q and visits (regions x strata, region-major; checked by the caller) and
    // rebuilds every CDF. Lazy: regions whose Q and visits are the prior's share its block.
    void assign(std::vector<double> q, std::vector<uint64_t> visits,
                const PolicyBuilder& policy);

    // The regions' learned selection probabilities (same regions, same passes).
    SelectionLearner& selection() { return selection_; }
    const SelectionLearner& selection() const { return selection_; }

    // Q and visits of every region, region-major (what saved fields hold).
    std::vector<double> denseQ() const;
    std::vector<uint64_t> denseVisits() const;
    // The raw tables, block-major (for bitwise comparisons of fields made alike).
    const std::vector<double>& qTable() const { return q_; }
    const std::vector<uint64_t>& visitTable() const { return visits_; }
    const std::vector<float>& cdfTable() const { return cdf_; }
    GuidingStats& stats() { return stats_; }
    const GuidingStats& stats() const { return stats_; }

    // Learned data (Q, estimates, visits, CDFs) and per-pass scratch, in bytes.
    size_t bytes() const;
    size_t scratchBytes() const;

private:
    struct Record {
        uint32_t region;
        uint16_t stratum;
        float target;
    };
    struct alignas(64) SlotBuffer {
        std::vector<Record> records;
        uint64_t rejectedTargets = 0;
        uint64_t rejectedRecords = 0;
    };
    void applyRegion(size_t region, const Record* begin, const Record* end, bool alphaVisits,
                     double fixedAlpha, double* sums, uint64_t* counts, double* scratch,
                     const PolicyBuilder& policy);
    // The targets' sums and counts per stratum of a region's records (applyRegion's first
    // step), and the update of the region from them (its second).
    void accumulate(const Record* begin, const Record* end, double* sums,
                    uint64_t* counts) const;
    void applySums(size_t region, const double* sums, const uint64_t* counts,
                   bool alphaVisits, double fixedAlpha, double* scratch,
                   const PolicyBuilder& policy);
    // Gives the regions in `fresh` (lazy tables) blocks of their own.
    void addFreshBlocks(const std::vector<size_t>& fresh);
    // Sets the tables to `blocks` blocks of Q = init and no visits (estimates init, CDFs
    // zero until rebuilt), with exact capacities.
    void untrainedBlocks(size_t blocks);
    // Appends a block per region (Q and visits copied from q[i] / visits[i], or from the prior
    // where null; estimates and CDF the prior's until rebuilt). Not during a pass.
    void addBlocks(const std::vector<size_t>& regions, const std::vector<const double*>& q,
                   const std::vector<const uint64_t*>& visits);
    // Rebuilds a region's estimates and its CDF; `scratch` (optional) holds strata +
    // smoothingScratch() doubles.
    void rebuild(size_t region, const PolicyBuilder& policy, double* scratch = nullptr);

    size_t regions_ = 0;
    int strata_ = 0;
    bool lazy_ = false;
    size_t blocks_ = 0;
    std::vector<uint32_t> block_;  // per region: its block of q_, est_, visits_, cdf_
    std::vector<double> q_;
    std::vector<float> est_;
    // setSmoothing's tree, flattened (empty: no smoothing): the parent node of each stratum,
    // then of each of the nodes_ nodes above the strata (level by level, the root last).
    static constexpr uint32_t kNoParent = UINT32_MAX;
    std::vector<uint32_t> parent_;
    uint32_t nodes_ = 0;
    double prior_ = 0.0;
    double init_ = 0.0;  // reset()'s initial Q
    std::vector<uint64_t> visits_;
    std::vector<float> cdf_;
    std::vector<SlotBuffer> slots_;
    std::vector<uint64_t> regionStart_;
    MergedRecords<Record> merged_;
    GuidingStats stats_;
    SelectionLearner selection_;
};

}  // namespace rlpbrt::guiding
