#include "guiding/strata_table.h"

#include <algorithm>
#include <cfloat>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace rlpbrt::guiding {

void StrataTable::reset(size_t regions, int strata, double init, const PolicyBuilder& policy,
                        bool lazy) {
    regions_ = regions;
    strata_ = strata;
    init_ = init;
    lazy_ = lazy;
    const size_t n = size_t(strata);
    // Lazy: one block, the prior, shared by every region until it learns. Else one block per
    // region.
    blocks_ = lazy ? (regions > 0 ? 1 : 0) : regions;
    block_.resize(regions);
    for (size_t r = 0; r < regions; ++r) block_[r] = lazy ? 0 : uint32_t(r);
    untrainedBlocks(blocks_);
    // Every region starts with the same Q and no visits: build the first one and copy it.
    if (regions > 0) {
        rebuild(0, policy);
        for (size_t b = 1; b < blocks_; ++b) {
            std::copy(cdf_.begin(), cdf_.begin() + long(n + 1), cdf_.begin() + long(b * (n + 1)));
            std::copy(est_.begin(), est_.begin() + long(n), est_.begin() + long(b * n));
        }
    }
    slots_.clear();
    stats_ = GuidingStats();
    selection_.reset(regions);
}

void StrataTable::untrainedBlocks(size_t blocks) {
    const size_t n = size_t(strata_);
    q_.assign(blocks * n, init_);
    est_.assign(blocks * n, float(std::min(init_, double(FLT_MAX))));
    visits_.assign(blocks * n, 0);
    cdf_.assign(blocks * (n + 1), 0.f);
    q_.shrink_to_fit();
    est_.shrink_to_fit();
    visits_.shrink_to_fit();
    cdf_.shrink_to_fit();
}

void StrataTable::grow(size_t regions, double init, const PolicyBuilder& policy) {
    if (regions <= regions_ || strata_ <= 0) return;
    const size_t n = size_t(strata_), old = regions_;
    regions_ = regions;
    selection_.grow(regions);
    if (lazy_) {
        block_.resize(regions, 0);
        if (blocks_ == 0) {  // the first regions: build the prior block they share
            blocks_ = 1;
            untrainedBlocks(1);
            rebuild(0, policy);
        }
        return;
    }
    block_.resize(regions);
    for (size_t r = old; r < regions; ++r) block_[r] = uint32_t(r);
    blocks_ = regions;
    q_.resize(regions * n, init);
    est_.resize(regions * n, float(std::min(init, double(FLT_MAX))));
    visits_.resize(regions * n, 0);
    cdf_.resize(regions * (n + 1), 0.f);
    for (size_t r = old; r < regions; ++r) rebuild(r, policy);
}

void StrataTable::addBlocks(const std::vector<size_t>& regions,
                            const std::vector<const double*>& q,
                            const std::vector<const uint64_t*>& visits) {
    const size_t n = size_t(strata_), k = regions.size(), total = blocks_ + k;
    // Exact capacities: the tables are the guide's memory, and reported as such.
    q_.reserve(total * n);
    visits_.reserve(total * n);
    est_.reserve(total * n);
    cdf_.reserve(total * (n + 1));
    // The prior block (block 0), copied out: insert() may not read from its own vector.
    const std::vector<double> priorQ(q_.begin(), q_.begin() + long(n));
    const std::vector<uint64_t> priorVisits(visits_.begin(), visits_.begin() + long(n));
    const std::vector<float> priorEst(est_.begin(), est_.begin() + long(n));
    const std::vector<float> priorCdf(cdf_.begin(), cdf_.begin() + long(n + 1));
    for (size_t i = 0; i < k; ++i) {
        // From the given data, or else the prior's.
        const double* qi = q[i] ? q[i] : priorQ.data();
        const uint64_t* vi = visits[i] ? visits[i] : priorVisits.data();
        q_.insert(q_.end(), qi, qi + n);
        visits_.insert(visits_.end(), vi, vi + n);
        est_.insert(est_.end(), priorEst.begin(), priorEst.end());
        cdf_.insert(cdf_.end(), priorCdf.begin(), priorCdf.end());
        block_[regions[i]] = uint32_t(blocks_ + i);
    }
    blocks_ = total;
}

void StrataTable::assign(std::vector<double> q, std::vector<uint64_t> visits,
                         const PolicyBuilder& policy) {
    const size_t n = size_t(strata_);
    if (!lazy_) {
        q_ = std::move(q);
        visits_ = std::move(visits);
    } else if (regions_ > 0) {
        // Keep the prior block; every region that has learned anything gets a block again.
        q_.resize(n);
        visits_.resize(n);
        est_.resize(n);
        cdf_.resize(n + 1);
        blocks_ = 1;
        std::vector<size_t> learned;
        std::vector<const double*> qs;
        std::vector<const uint64_t*> vs;
        for (size_t r = 0; r < regions_; ++r) {
            block_[r] = 0;
            const double* qr = &q[r * n];
            const uint64_t* vr = &visits[r * n];
            bool prior = true;
            for (size_t j = 0; j < n && prior; ++j) prior = vr[j] == 0 && qr[j] == init_;
            if (prior) continue;
            learned.push_back(r);
            qs.push_back(qr);
            vs.push_back(vr);
        }
        q_.shrink_to_fit();
        visits_.shrink_to_fit();
        est_.shrink_to_fit();
        cdf_.shrink_to_fit();
        addBlocks(learned, qs, vs);
    }
    // (A region on the prior block rebuilds the prior, unchanged, and its own policy data.)
    for (size_t r = 0; r < regions_; ++r) rebuild(r, policy);
}

void StrataTable::setSmoothing(std::vector<std::vector<uint32_t>> levels, double prior) {
    parent_.clear();
    nodes_ = 0;
    prior_ = prior > 0.0 && std::isfinite(prior) ? prior : 0.0;
    if (prior_ == 0.0 || levels.empty()) return;
    // Number the nodes above the strata level by level (level 1 first, the root last) and
    // keep one parent index per stratum and node: the strata's parents are nodes, a node's
    // parent is a node of the next level, and the top level's nodes have none.
    std::vector<uint32_t> offset(levels.size() + 1, 0);
    for (size_t l = 0; l < levels.size(); ++l) {
        uint32_t size = 0;
        for (uint32_t parent : levels[l]) size = std::max(size, parent + 1);
        offset[l + 1] = offset[l] + size;
    }
    nodes_ = offset.back();
    parent_.assign(levels[0].begin(), levels[0].end());
    parent_.resize(levels[0].size() + nodes_, kNoParent);
    for (size_t l = 1; l < levels.size(); ++l)
        for (size_t i = 0; i < levels[l].size(); ++i)
            parent_[levels[0].size() + offset[l - 1] + i] = offset[l] + levels[l][i];
}

void StrataTable::estimate(size_t region, double* out, double* scratch) const {
    const double* q = this->q(region);
    if (parent_.empty()) {
        std::copy(q, q + strata_, out);
        return;
    }
    const uint64_t* v = visits(region);
    // Per node above the strata: the visits under it, the sum of their targets and its
    // estimate.
    std::vector<double> local;
    if (!scratch) {
        local.resize(smoothingScratch());
        scratch = local.data();
    }
    const size_t nodes = nodes_, n = size_t(strata_);
    double *sum = scratch, *count = sum + nodes, *est = count + nodes;
    std::fill(scratch, scratch + 2 * nodes, 0.0);
    const uint32_t* up = parent_.data();
    // Bottom-up: the strata into their nodes, then each node (children before parents) into
    // its parent.
    // (Visit counts stay far below 2^63: converted as signed, one instruction.)
    for (size_t j = 0; j < n; ++j) {
        const double c = double(int64_t(v[j]));
        sum[up[j]] += c * q[j];
        count[up[j]] += c;
    }
    const uint32_t* nodeUp = up + n;
    for (size_t k = 0; k < nodes; ++k) {
        if (nodeUp[k] == kNoParent) continue;
        sum[nodeUp[k]] += sum[k];
        count[nodeUp[k]] += count[k];
    }
    // Top-down: each node shrunk towards its parent's estimate. The root takes the mean of
    // all its targets (init before any): a prior of init there would pull every estimate
    // towards a scale unrelated to the scene's radiance.
    for (size_t k = nodes; k-- > 0;) {
        if (nodeUp[k] == kNoParent)
            est[k] = count[k] > 0.0 ? sum[k] / count[k] : init_;
        else
            est[k] = (sum[k] + prior_ * est[nodeUp[k]]) / (count[k] + prior_);
    }
    for (size_t j = 0; j < n; ++j) {
        const double c = double(int64_t(v[j]));
        out[j] = (c * q[j] + prior_ * est[up[j]]) / (c + prior_);
    }
}

void StrataTable::rebuild(size_t region, const PolicyBuilder& policy, double* scratch) {
    std::vector<double> local;
    if (!scratch) {
        local.resize(size_t(strata_) + smoothingScratch());
        scratch = local.data();
    }
    double* e = scratch;
    estimate(region, e, scratch + strata_);
    policy(int(region), e, &cdf_[block_[region] * size_t(strata_ + 1)]);
    float* out = &est_[block_[region] * size_t(strata_)];
    for (int j = 0; j < strata_; ++j) out[j] = float(std::min(e[j], double(FLT_MAX)));
}

void StrataTable::beginPass(int numSlots) {
    numSlots = std::max(numSlots, 0);
    if (slots_.size() != size_t(numSlots)) slots_.resize(size_t(numSlots));
    for (SlotBuffer& s : slots_) {
        s.records.clear();  // keeps the capacity of earlier passes
        s.rejectedTargets = s.rejectedRecords = 0;
    }
    selection_.beginPass(numSlots);
}

void StrataTable::accumulate(const Record* begin, const Record* end, double* sums,
                             uint64_t* counts) const {
    std::fill(sums, sums + strata_, 0.0);
    std::fill(counts, counts + strata_, uint64_t(0));
    for (const Record* r = begin; r != end; ++r) {  // merge order: slot, then record order
        sums[r->stratum] += double(r->target);
        ++counts[r->stratum];
    }
}

void StrataTable::applySums(size_t region, const double* sums, const uint64_t* counts,
                            bool alphaVisits, double fixedAlpha, double* scratch,
                            const PolicyBuilder& policy) {
    double* q = &q_[block_[region] * size_t(strata_)];
    uint64_t* visits = &visits_[block_[region] * size_t(strata_)];
    for (int j = 0; j < strata_; ++j) {
        const uint64_t m = counts[j];
        if (m == 0) continue;
        const double mean = sums[j] / double(m);
        double updated;
        if (alphaVisits) {
            // m sequential updates with alpha = 1/(1 + visits): the running mean of all targets.
            const double nOld = double(visits[j]);
            updated = (nOld * q[j] + sums[j]) / (nOld + double(m));
        } else {
            // m updates with a fixed alpha and the batch mean as target: keep (1 - alpha)^m.
            const double keep = std::exp(double(m) * std::log1p(-fixedAlpha));
            updated = keep * q[j] + (1.0 - keep) * mean;
        }
        q[j] = (std::isfinite(updated) && updated >= 0.0) ? updated : mean;
        visits[j] += m;
    }
    rebuild(region, policy, scratch);
}

void StrataTable::applyRegion(size_t region, const Record* begin, const Record* end,
                              bool alphaVisits, double fixedAlpha, double* sums,
                              uint64_t* counts, double* scratch, const PolicyBuilder& policy) {
    accumulate(begin, end, sums, counts);
    applySums(region, sums, counts, alphaVisits, fixedAlpha, scratch, policy);
}

void StrataTable::addFreshBlocks(const std::vector<size_t>& fresh) {
    if (!fresh.empty())
        addBlocks(fresh, std::vector<const double*>(fresh.size(), nullptr),
                  std::vector<const uint64_t*>(fresh.size(), nullptr));
}

void StrataTable::endPass(bool alphaVisits, double fixedAlpha, const PolicyBuilder& policy) {
    uint64_t total = 0;
    for (const SlotBuffer& s : slots_) {
        total += s.records.size();
        stats_.rejectedTargets += s.rejectedTargets;
        stats_.rejectedRecords += s.rejectedRecords;
    }
    ++stats_.passes;
    stats_.records += total;
    selection_.endPass();
    stats_.selectionRegions = selection_.learnedRegions();
    stats_.selectionMean = selection_.meanSelection();
    if (total > 0 && regions_ > 0) {
        mergeByRegion<Record>(
            slots_, [](const SlotBuffer& s) -> const std::vector<Record>& { return s.records; },
            regions_, &regionStart_, &merged_);
        // regionStart_[r] now holds the end of region r.
        if (lazy_) {
            // Regions learning for the first time leave the prior for blocks of their own,
            // appended in region order (deterministic).
            std::vector<size_t> fresh;
            for (size_t r = 0; r < regions_; ++r) {
                const size_t b = r == 0 ? 0 : regionStart_[r - 1];
                if (regionStart_[r] != b && block_[r] == 0) fresh.push_back(r);
            }
            addFreshBlocks(fresh);
        }
        tbb::parallel_for(tbb::blocked_range<size_t>(0, regions_, 256),
                          [&](const tbb::blocked_range<size_t>& range) {
                              std::vector<double> sums(static_cast<size_t>(strata_));
                              std::vector<uint64_t> counts(static_cast<size_t>(strata_));
                              std::vector<double> scratch(size_t(strata_) +
                                                          smoothingScratch());
                              for (size_t r = range.begin(); r != range.end(); ++r) {
                                  size_t b = r == 0 ? 0 : regionStart_[r - 1];
                                  size_t e = regionStart_[r];
                                  if (b == e) continue;
                                  applyRegion(r, merged_.data() + b, merged_.data() + e,
                                              alphaVisits, fixedAlpha, sums.data(),
                                              counts.data(), scratch.data(), policy);
                              }
                          });
    }
    for (SlotBuffer& s : slots_) {
        s.records.clear();
        s.rejectedTargets = s.rejectedRecords = 0;
    }
}

void StrataTable::endPassShared(bool alphaVisits, double fixedAlpha,
                                const PolicyBuilder& policy, const SumAcrossProcesses& sum) {
    // 1. Counters, then the records per region (this process's, grouped by region).
    std::vector<double> head(4, 0.0);
    uint64_t total = 0;
    for (const SlotBuffer& s : slots_) {
        total += s.records.size();
        head[1] += double(s.rejectedTargets);
        head[2] += double(s.rejectedRecords);
    }
    head[0] = double(total);
    head[3] = double(selection_.pendingSamples());
    if (total > 0 && regions_ > 0)
        mergeByRegion<Record>(
            slots_, [](const SlotBuffer& s) -> const std::vector<Record>& { return s.records; },
            regions_, &regionStart_, &merged_);
    else
        regionStart_.assign(regions_ + 1, 0);
    auto range = [&](size_t r) {
        return std::make_pair(r == 0 ? uint64_t(0) : regionStart_[r - 1], regionStart_[r]);
    };
    sum(head);
    const uint64_t allRecords = uint64_t(head[0]);
    ++stats_.passes;
    stats_.records += allRecords;
    stats_.rejectedTargets += uint64_t(head[1]);
    stats_.rejectedRecords += uint64_t(head[2]);
    selection_.endPassShared(sum, uint64_t(head[3]));
    stats_.selectionRegions = selection_.learnedRegions();
    stats_.selectionMean = selection_.meanSelection();
    if (allRecords > 0 && regions_ > 0) {
        std::vector<uint64_t> perRegion(regions_);
        for (size_t r = 0; r < regions_; ++r) {
            const auto [b, e] = range(r);
            perRegion[r] = e - b;
        }
        sum.sumCounts(perRegion, head[0]);  // no count exceeds the pass's records
        // 2. For the regions that received records anywhere (in region order): per stratum
        // the count of records, then the sum of the targets of the strata that received
        // records anywhere (most strata of a region receive none in a pass).
        std::vector<size_t> touched;
        for (size_t r = 0; r < regions_; ++r)
            if (perRegion[r] > 0) touched.push_back(r);
        const size_t n = size_t(strata_);
        std::vector<double> body(touched.size() * n, 0.0);  // sums, dense
        std::vector<uint64_t> counts(touched.size() * n, 0);
        tbb::parallel_for(tbb::blocked_range<size_t>(0, touched.size(), 256),
                          [&](const tbb::blocked_range<size_t>& rs) {
                              for (size_t i = rs.begin(); i != rs.end(); ++i) {
                                  const auto [b, e] = range(touched[i]);
                                  accumulate(merged_.data() + b, merged_.data() + e,
                                             &body[i * n], &counts[i * n]);
                              }
                          });
        sum.sumCounts(counts, head[0]);
        std::vector<double> sparse;
        for (size_t i = 0; i < counts.size(); ++i)
            if (counts[i] > 0) sparse.push_back(body[i]);
        sum(sparse);
        for (size_t i = 0, k = 0; i < counts.size(); ++i)
            body[i] = counts[i] > 0 ? sparse[k++] : 0.0;
        if (lazy_) {
            std::vector<size_t> fresh;
            for (size_t r : touched)
                if (block_[r] == 0) fresh.push_back(r);
            addFreshBlocks(fresh);
        }
        tbb::parallel_for(tbb::blocked_range<size_t>(0, touched.size(), 256),
                          [&](const tbb::blocked_range<size_t>& rs) {
                              std::vector<double> scratch(n + smoothingScratch());
                              for (size_t i = rs.begin(); i != rs.end(); ++i)
                                  applySums(touched[i], &body[i * n], &counts[i * n],
                                            alphaVisits, fixedAlpha, scratch.data(), policy);
                          });
    }
    for (SlotBuffer& s : slots_) {
        s.records.clear();
        s.rejectedTargets = s.rejectedRecords = 0;
    }
}

std::vector<double> StrataTable::denseQ() const {
    std::vector<double> out;
    out.reserve(regions_ * size_t(strata_));
    for (size_t r = 0; r < regions_; ++r) out.insert(out.end(), q(r), q(r) + strata_);
    return out;
}

std::vector<uint64_t> StrataTable::denseVisits() const {
    std::vector<uint64_t> out;
    out.reserve(regions_ * size_t(strata_));
    for (size_t r = 0; r < regions_; ++r) out.insert(out.end(), visits(r), visits(r) + strata_);
    return out;
}

size_t StrataTable::bytes() const {
    return q_.capacity() * sizeof(double) + est_.capacity() * sizeof(float) +
           visits_.capacity() * sizeof(uint64_t) + cdf_.capacity() * sizeof(float) +
           block_.capacity() * sizeof(uint32_t) + selection_.bytes();
}

size_t StrataTable::scratchBytes() const {
    size_t b = merged_.capacity() * sizeof(Record) + regionStart_.capacity() * sizeof(uint64_t);
    for (const SlotBuffer& s : slots_) b += s.records.capacity() * sizeof(Record);
    return b + selection_.scratchBytes();
}

}  // namespace rlpbrt::guiding
