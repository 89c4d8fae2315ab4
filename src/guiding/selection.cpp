#include "guiding/selection.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace rlpbrt::guiding {

void SelectionLearner::reset(size_t regions) {
    regions_ = regions;
    sums_.clear();
    weights_.clear();
    selection_.clear();
    slots_.clear();
}

void SelectionLearner::grow(size_t regions) {
    if (regions <= regions_) return;
    regions_ = regions;
    if (selection_.empty()) return;  // nothing learned yet: allocated on the first samples
    sums_.resize(regions * kCandidates, 0.0);
    weights_.resize(regions, 0.0);
    selection_.resize(regions, -1.f);
}

void SelectionLearner::beginPass(int numSlots) {
    const size_t n = size_t(numSlots > 0 ? numSlots : 0);
    if (slots_.size() != n) slots_.resize(n);
    for (SlotBuffer& s : slots_) s.samples.clear();
}

void SelectionLearner::record(int slot, int region, const SelectionSample& s) {
    if (slot < 0 || size_t(slot) >= slots_.size() || region < 0 || size_t(region) >= regions_)
        return;
    const double pi = double(s.integrand);
    const double a = pi * pi / double(s.pdf);
    const float b = s.pOther, d = s.scale * (s.pGuide - s.pOther);
    if (!(pi > 0.0) || !(a > 0.0) || !std::isfinite(a) || !(b >= 0.f) || !std::isfinite(d))
        return;
    slots_[size_t(slot)].samples.push_back(
        Sample{uint32_t(region), float(std::min(a, double(std::numeric_limits<float>::max()))),
               b, d});
}

bool SelectionLearner::allocate(uint64_t total) {
    if (selection_.empty()) {
        if (total == 0) return false;  // memory only once the integrator learns selections
        sums_.assign(regions_ * kCandidates, 0.0);
        weights_.assign(regions_, 0.0);
        selection_.assign(regions_, -1.f);
    }
    return true;
}

void SelectionLearner::candidateSums(size_t b, size_t e, double* add) const {
    for (size_t i = b; i < e; ++i) {
        const Sample& x = merged_[i];
        for (int k = 0; k < kCandidates; ++k) {
            const double p = double(x.b) + double(candidate(k)) * double(x.d);
            add[k] += p > 0.0 ? double(x.a) / p : std::numeric_limits<double>::infinity();
        }
    }
}

void SelectionLearner::update(size_t r, const double* add, double count) {
    double* sums = &sums_[r * kCandidates];
    for (int k = 0; k < kCandidates; ++k) sums[k] = kDecay * sums[k] + add[k];
    weights_[r] = kDecay * weights_[r] + count;
    if (weights_[r] < kMinSamples) return;
    int best = -1;
    for (int k = 0; k < kCandidates; ++k)
        if (std::isfinite(sums[k]) && (best < 0 || sums[k] < sums[best])) best = k;
    selection_[r] = best < 0 ? -1.f : candidate(best);
}

void SelectionLearner::saveState(fieldio::Writer& w) const {
    w.u64(regions_);
    w.u32(selection_.empty() ? 0u : 1u);
    if (selection_.empty()) return;
    for (double v : sums_) w.f64(v);
    for (double v : weights_) w.f64(v);
    for (float v : selection_) w.f32(v);
}

bool SelectionLearner::loadState(fieldio::Reader& r) {
    const uint64_t regions = r.u64();
    const uint32_t allocated = r.u32();
    if (!r.ok() || regions != regions_ || allocated > 1) return false;
    if (allocated == 0) {
        sums_.clear();
        weights_.clear();
        selection_.clear();
        return true;
    }
    if (r.remaining() < regions_ * (kCandidates * 8 + 8 + 4)) return false;
    std::vector<double> sums(regions_ * kCandidates), weights(regions_);
    std::vector<float> selection(regions_);
    for (double& v : sums) v = r.f64();
    for (double& v : weights) v = r.f64();
    for (float& v : selection) {
        v = r.f32();
        if (!(v == -1.f || (v >= 0.f && v < 1.f))) return false;
    }
    if (!r.ok()) return false;
    sums_ = std::move(sums);
    weights_ = std::move(weights);
    selection_ = std::move(selection);
    return true;
}

size_t SelectionLearner::pendingSamples() const {
    size_t total = 0;
    for (const SlotBuffer& s : slots_) total += s.samples.size();
    return total;
}

void SelectionLearner::endPass() {
    if (!allocate(pendingSamples())) return;
    const size_t regions = regions_;
    mergeByRegion<Sample>(
        slots_, [](const SlotBuffer& s) -> const std::vector<Sample>& { return s.samples; },
        regions, &start_, &merged_);
    // start_[r] now holds the end of region r. Every region decays, sampled or not.
    tbb::parallel_for(tbb::blocked_range<size_t>(0, regions, 256),
                      [&](const tbb::blocked_range<size_t>& range) {
        for (size_t r = range.begin(); r != range.end(); ++r) {
            double add[kCandidates] = {};
            const size_t b = r == 0 ? 0 : start_[r - 1], e = start_[r];
            candidateSums(b, e, add);
            update(r, add, double(e - b));
        }
    });
    for (SlotBuffer& s : slots_) s.samples.clear();
}

void SelectionLearner::endPassShared(const SumAcrossProcesses& sum, uint64_t total) {
    if (!allocate(total)) {
        for (SlotBuffer& s : slots_) s.samples.clear();
        return;
    }
    const size_t regions = regions_;
    mergeByRegion<Sample>(
        slots_, [](const SlotBuffer& s) -> const std::vector<Sample>& { return s.samples; },
        regions, &start_, &merged_);
    std::vector<uint64_t> perRegion(regions);
    for (size_t r = 0; r < regions; ++r) perRegion[r] = start_[r] - (r == 0 ? 0 : start_[r - 1]);
    if (total > 0) sum.sumCounts(perRegion, double(total));
    const std::vector<double> counts(perRegion.begin(), perRegion.end());
    std::vector<size_t> touched;
    for (size_t r = 0; r < regions; ++r)
        if (counts[r] > 0.0) touched.push_back(r);
    std::vector<double> add(touched.size() * kCandidates, 0.0);
    for (size_t i = 0; i < touched.size(); ++i) {
        const size_t r = touched[i];
        candidateSums(r == 0 ? 0 : start_[r - 1], start_[r], &add[i * kCandidates]);
    }
    if (!touched.empty()) sum(add);
    // Every region decays, sampled or not.
    tbb::parallel_for(tbb::blocked_range<size_t>(0, regions, 256),
                      [&](const tbb::blocked_range<size_t>& range) {
        const double none[kCandidates] = {};
        for (size_t r = range.begin(); r != range.end(); ++r) {
            const auto it = std::lower_bound(touched.begin(), touched.end(), r);
            const bool has = it != touched.end() && *it == r;
            update(r, has ? &add[size_t(it - touched.begin()) * kCandidates] : none,
                   counts[r]);
        }
    });
    for (SlotBuffer& s : slots_) s.samples.clear();
}

size_t SelectionLearner::learnedRegions() const {
    size_t n = 0;
    for (float s : selection_) n += s >= 0.f;
    return n;
}

double SelectionLearner::meanSelection() const {
    double sum = 0.0;
    size_t n = 0;
    for (float s : selection_)
        if (s >= 0.f) sum += s, ++n;
    return n > 0 ? sum / double(n) : 0.0;
}

size_t SelectionLearner::bytes() const {
    return sums_.capacity() * sizeof(double) + weights_.capacity() * sizeof(double) +
           selection_.capacity() * sizeof(float);
}

size_t SelectionLearner::scratchBytes() const {
    size_t b = merged_.capacity() * sizeof(Sample) + start_.capacity() * sizeof(uint64_t);
    for (const SlotBuffer& s : slots_) b += s.samples.capacity() * sizeof(Sample);
    return b;
}

}  // namespace rlpbrt::guiding
