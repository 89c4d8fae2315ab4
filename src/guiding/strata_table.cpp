#include "guiding/strata_table.h"

#include <algorithm>
#include <cfloat>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "guiding/slot_merge.h"

namespace rlpbrt::guiding {

void StrataTable::reset(size_t regions, int strata, double init, const PolicyBuilder& policy) {
    regions_ = regions;
    strata_ = strata;
    init_ = init;
    const size_t n = size_t(strata);
    q_.assign(regions * n, init);
    est_.assign(regions * n, float(std::min(init, double(FLT_MAX))));
    visits_.assign(regions * n, 0);
    cdf_.assign(regions * (n + 1), 0.f);
    // Every region starts with the same Q and no visits: build the first one and copy it.
    if (regions > 0) {
        rebuild(0, policy);
        for (size_t r = 1; r < regions; ++r) {
            std::copy(cdf_.begin(), cdf_.begin() + long(n + 1), cdf_.begin() + long(r * (n + 1)));
            std::copy(est_.begin(), est_.begin() + long(n), est_.begin() + long(r * n));
        }
    }
    slots_.clear();
    stats_ = GuidingStats();
    selection_.reset(regions);
}

void StrataTable::grow(size_t regions, double init, const PolicyBuilder& policy) {
    if (regions <= regions_ || strata_ <= 0) return;
    const size_t n = size_t(strata_), old = regions_;
    regions_ = regions;
    selection_.grow(regions);
    q_.resize(regions * n, init);
    est_.resize(regions * n, float(std::min(init, double(FLT_MAX))));
    visits_.resize(regions * n, 0);
    cdf_.resize(regions * (n + 1), 0.f);
    for (size_t r = old; r < regions; ++r) rebuild(r, policy);
}

void StrataTable::assign(std::vector<double> q, std::vector<uint64_t> visits,
                         const PolicyBuilder& policy) {
    q_ = std::move(q);
    visits_ = std::move(visits);
    for (size_t r = 0; r < regions_; ++r) rebuild(r, policy);
}

void StrataTable::setSmoothing(std::vector<std::vector<uint32_t>> levels, double prior) {
    levels_.clear();
    levelSize_.clear();
    prior_ = prior > 0.0 && std::isfinite(prior) ? prior : 0.0;
    if (prior_ == 0.0) return;
    levels_ = std::move(levels);
    for (const std::vector<uint32_t>& map : levels_) {
        uint32_t size = 0;
        for (uint32_t parent : map) size = std::max(size, parent + 1);
        levelSize_.push_back(size);
    }
}

void StrataTable::estimate(size_t region, double* out) const {
    const double* q = this->q(region);
    if (levels_.empty()) {
        std::copy(q, q + strata_, out);
        return;
    }
    const uint64_t* v = visits(region);
    // Per node above the strata (level by level, offsets into one buffer): the visits under
    // it, the sum of their targets and its estimate.
    const size_t levels = levels_.size();
    std::vector<size_t> offset(levels + 1, 0);
    for (size_t l = 0; l < levels; ++l) offset[l + 1] = offset[l] + levelSize_[l];
    const size_t nodes = offset[levels];
    std::vector<double> buf(3 * nodes, 0.0);
    double *sum = buf.data(), *count = sum + nodes, *est = count + nodes;
    // Bottom-up: strata into level 1, each level into the next.
    for (size_t l = 0; l < levels; ++l) {
        const std::vector<uint32_t>& map = levels_[l];
        for (size_t i = 0; i < map.size(); ++i) {
            const size_t parent = offset[l] + map[i];
            sum[parent] += l == 0 ? double(v[i]) * q[i] : sum[offset[l - 1] + i];
            count[parent] += l == 0 ? double(v[i]) : count[offset[l - 1] + i];
        }
    }
    // Top-down: each node shrunk towards its parent's estimate. The root takes the mean of
    // all its targets (init before any): a prior of init there would pull every estimate
    // towards a scale unrelated to the scene's radiance.
    for (size_t l = levels; l-- > 0;) {
        for (size_t i = 0; i < levelSize_[l]; ++i) {
            const size_t node = offset[l] + i;
            if (l + 1 == levels) {
                est[node] = count[node] > 0.0 ? sum[node] / count[node] : init_;
                continue;
            }
            const double parent = est[offset[l + 1] + levels_[l + 1][i]];
            est[node] = (sum[node] + prior_ * parent) / (count[node] + prior_);
        }
    }
    for (int j = 0; j < strata_; ++j) {
        const double parent = est[levels_[0][size_t(j)]];
        const double n = double(v[j]);
        out[j] = (n * q[j] + prior_ * parent) / (n + prior_);
    }
}

void StrataTable::rebuild(size_t region, const PolicyBuilder& policy) {
    std::vector<double> e(static_cast<size_t>(strata_));
    estimate(region, e.data());
    policy(int(region), e.data(), &cdf_[region * size_t(strata_ + 1)]);
    float* out = &est_[region * size_t(strata_)];
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

void StrataTable::applyRegion(size_t region, const Record* begin, const Record* end,
                              bool alphaVisits, double fixedAlpha, double* sums,
                              uint64_t* counts, const PolicyBuilder& policy) {
    std::fill(sums, sums + strata_, 0.0);
    std::fill(counts, counts + strata_, uint64_t(0));
    for (const Record* r = begin; r != end; ++r) {  // merge order: slot, then record order
        sums[r->stratum] += double(r->target);
        ++counts[r->stratum];
    }
    double* q = &q_[region * size_t(strata_)];
    uint64_t* visits = &visits_[region * size_t(strata_)];
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
    rebuild(region, policy);
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
        tbb::parallel_for(tbb::blocked_range<size_t>(0, regions_, 256),
                          [&](const tbb::blocked_range<size_t>& range) {
                              std::vector<double> sums(static_cast<size_t>(strata_));
                              std::vector<uint64_t> counts(static_cast<size_t>(strata_));
                              for (size_t r = range.begin(); r != range.end(); ++r) {
                                  size_t b = r == 0 ? 0 : regionStart_[r - 1];
                                  size_t e = regionStart_[r];
                                  if (b == e) continue;
                                  applyRegion(r, merged_.data() + b, merged_.data() + e,
                                              alphaVisits, fixedAlpha, sums.data(),
                                              counts.data(), policy);
                              }
                          });
    }
    for (SlotBuffer& s : slots_) {
        s.records.clear();
        s.rejectedTargets = s.rejectedRecords = 0;
    }
}

size_t StrataTable::bytes() const {
    return q_.capacity() * sizeof(double) + est_.capacity() * sizeof(float) +
           visits_.capacity() * sizeof(uint64_t) + cdf_.capacity() * sizeof(float) +
           selection_.bytes();
}

size_t StrataTable::scratchBytes() const {
    size_t b = merged_.capacity() * sizeof(Record) + regionStart_.capacity() * sizeof(uint64_t);
    for (const SlotBuffer& s : slots_) b += s.records.capacity() * sizeof(Record);
    return b + selection_.scratchBytes();
}

}  // namespace rlpbrt::guiding
