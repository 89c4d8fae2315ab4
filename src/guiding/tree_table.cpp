#include "guiding/tree_table.h"

#include <algorithm>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace rlpbrt::guiding {

void TreeTable::reset(size_t regions, const Settings& settings) {
    settings_ = settings;
    settings_.epsilon = std::clamp(settings_.epsilon, 0.0, 1.0);
    regions_.assign(regions, Region{});
    for (Region& r : regions_) {
        r.q.assign(1, float(settings_.init));
        r.est = r.q;
        r.visits.assign(1, 0.0);
    }
    stats_ = GuidingStats{};
}

glm::vec2 TreeTable::sample(size_t region, glm::vec2 u, float uMix, float* density,
                            uint32_t* leaf) const {
    const DirTree& t = regions_[region].tree;
    const float eps = float(settings_.epsilon);
    glm::vec2 a;
    uint32_t at = 0;
    float treeDensity = 0.f;
    if (uMix < eps) {
        a = glm::clamp(u, glm::vec2(0.f), glm::vec2(0x1.fffffep-1f));
        treeDensity = t.density(a, &at);
    } else {
        a = t.sample(u, &treeDensity, &at);
    }
    if (density) *density = eps + (1.f - eps) * treeDensity;
    if (leaf) *leaf = at;
    return a;
}

float TreeTable::density(size_t region, glm::vec2 a, uint32_t* leaf) const {
    const float eps = float(settings_.epsilon);
    return eps + (1.f - eps) * regions_[region].tree.density(a, leaf);
}

float TreeTable::confidence(size_t region, double warmup) const {
    const double w = warmup * double(regions_[region].tree.leaves());
    if (!(w > 0.0)) return 1.f;
    const double v = regions_[region].totalVisits;
    return float(v / (v + w));
}

void TreeTable::beginPass(int numSlots) {
    numSlots = std::max(numSlots, 0);
    if (slots_.size() != size_t(numSlots)) slots_.resize(size_t(numSlots));
    for (SlotBuffer& s : slots_) {
        s.records.clear();
        s.rejectedTargets = s.rejectedRecords = 0;
    }
}

void TreeTable::record(int slot, uint32_t region, glm::vec2 a, float target) {
    if (slot < 0 || size_t(slot) >= slots_.size()) return;
    SlotBuffer& buf = slots_[size_t(slot)];
    if (!(target >= 0.f) || !std::isfinite(target)) {
        ++buf.rejectedTargets;
        return;
    }
    if (region >= regions_.size() || !(a.x >= 0.f && a.x <= 1.f && a.y >= 0.f && a.y <= 1.f)) {
        ++buf.rejectedRecords;
        return;
    }
    buf.records.push_back(Record{region, target, a});
}

void TreeTable::setMasses(Region& region) const {
    const DirTree& t = region.tree;
    const size_t n = t.size();
    // Visit-weighted Q and visits under every node (children follow their parents), then the
    // estimates from the root down.
    std::vector<double> s(n, 0.0), v(n, 0.0);
    for (size_t i = n; i-- > 0;) {
        const DirTree::Node& node = t.node(uint32_t(i));
        if (node.leaf()) {
            v[i] = region.visits[i];
            s[i] = v[i] * double(region.q[i]);
        } else {
            for (uint32_t k = 0; k < 4; ++k) {
                s[i] += s[node.child + k];
                v[i] += v[node.child + k];
            }
        }
    }
    region.est.assign(n, 0.f);
    const double prior = settings_.smooth;
    region.est[0] = float(v[0] > 0.0 ? s[0] / v[0] : double(region.q[0]));
    if (t.node(0).leaf() && prior <= 0.0) region.est[0] = region.q[0];
    for (size_t i = 0; i < n; ++i) {
        const DirTree::Node& node = t.node(uint32_t(i));
        if (node.leaf()) continue;
        for (uint32_t k = 0; k < 4; ++k) {
            const size_t c = node.child + k;
            double e;
            if (prior > 0.0)
                e = (s[c] + prior * double(region.est[i])) / (v[c] + prior);
            else
                e = t.node(uint32_t(c)).leaf() ? double(region.q[c])
                                               : (v[c] > 0.0 ? s[c] / v[c] : region.est[i]);
            region.est[c] = std::isfinite(e) && e >= 0.0 ? float(e) : region.est[i];
        }
    }
    const std::vector<glm::vec3> sq = t.squares();
    std::vector<float> mass(n, 0.f);
    for (uint32_t i = 0; i < n; ++i) {
        if (!t.node(i).leaf()) continue;
        float m = region.est[i] * sq[i].z * sq[i].z;
        if (settings_.cosine) m *= sq[i].x + 0.5f * sq[i].z;  // cos(theta) at the centre
        mass[i] = m;
    }
    region.tree.setLeafMasses(mass);
}

void TreeTable::applyRegion(Region& region, const Record* begin, const Record* end) const {
    const DirTree& old = region.tree;
    const size_t n = old.size();
    // The pass's sums and counts per leaf, in merge order (slot, then record order).
    std::vector<double> sums(n, 0.0);
    std::vector<uint64_t> counts(n, 0);
    for (const Record* r = begin; r != end; ++r) {
        const uint32_t leaf = old.leafOf(r->a);
        sums[leaf] += double(r->target);
        ++counts[leaf];
    }
    // Running means: every target recorded in a leaf counts once.
    for (size_t i = 0; i < n; ++i) {
        if (counts[i] == 0) continue;
        const double v = region.visits[i], m = double(counts[i]);
        const double updated = (v * double(region.q[i]) + sums[i]) / (v + m);
        region.q[i] = std::isfinite(updated) && updated >= 0.0 ? float(updated)
                                                                : float(sums[i] / m);
        region.visits[i] = v + m;
        region.totalVisits += m;
    }
    setMasses(region);

    // Per old node: the visits under it, the visit-weighted sum of Q, and the area-weighted
    // sum of Q with its area (for subtrees without visits). Children follow their parents.
    std::vector<double> sumV(n, 0.0), sumQV(n, 0.0), sumQA(n, 0.0), area(n, 0.0);
    const std::vector<glm::vec3> sq = old.squares();
    for (size_t i = n; i-- > 0;) {
        const DirTree::Node& node = old.node(uint32_t(i));
        if (node.leaf()) {
            sumV[i] = region.visits[i];
            sumQV[i] = region.visits[i] * double(region.q[i]);
            area[i] = double(sq[i].z) * sq[i].z;
            sumQA[i] = double(region.q[i]) * area[i];
        } else {
            for (uint32_t k = 0; k < 4; ++k) {
                const size_t c = node.child + k;
                sumV[i] += sumV[c];
                sumQV[i] += sumQV[c];
                sumQA[i] += sumQA[c];
                area[i] += area[c];
            }
        }
    }
    std::vector<DirTree::Source> sources;
    DirTree refined = old.refined(settings_.splitShare, settings_.maxDepth, &sources);
    std::vector<float> q(refined.size(), 0.f);
    std::vector<double> visits(refined.size(), 0.0);
    for (uint32_t i = 0; i < refined.size(); ++i) {
        if (!refined.node(i).leaf()) continue;
        const DirTree::Source s = sources[i];
        if (old.node(s.from).leaf()) {
            // A leaf kept whole keeps its visits. The pieces of a split leaf keep its Q with
            // the weight of at most `smooth` visits (a prior), not its visits: those records
            // fell over the whole leaf, and would hold a piece's mean at the leaf's for long.
            q[i] = region.q[s.from];
            visits[i] = s.fraction == 1.f
                            ? region.visits[s.from]
                            : std::min(region.visits[s.from] * double(s.fraction),
                                       settings_.smooth);
        } else {
            visits[i] = sumV[s.from];
            q[i] = float(sumV[s.from] > 0.0 ? sumQV[s.from] / sumV[s.from]
                                            : sumQA[s.from] / area[s.from]);
        }
    }
    region.tree = std::move(refined);
    region.q = std::move(q);
    region.visits = std::move(visits);
    setMasses(region);
}

void TreeTable::endPass() {
    uint64_t total = 0;
    for (const SlotBuffer& s : slots_) {
        total += s.records.size();
        stats_.rejectedTargets += s.rejectedTargets;
        stats_.rejectedRecords += s.rejectedRecords;
    }
    ++stats_.passes;
    stats_.records += total;
    if (total > 0 && !regions_.empty()) {
        mergeByRegion<Record>(
            slots_, [](const SlotBuffer& s) -> const std::vector<Record>& { return s.records; },
            regions_.size(), &regionEnd_, &merged_);
        tbb::parallel_for(tbb::blocked_range<size_t>(0, regions_.size(), 64),
                          [&](const tbb::blocked_range<size_t>& range) {
                              for (size_t r = range.begin(); r != range.end(); ++r) {
                                  const size_t b = r == 0 ? 0 : regionEnd_[r - 1];
                                  const size_t e = regionEnd_[r];
                                  if (b == e) continue;
                                  applyRegion(regions_[r], merged_.data() + b,
                                              merged_.data() + e);
                              }
                          });
    }
    uint64_t learned = 0;
    for (const Region& r : regions_) learned += r.totalVisits > 0.0;
    stats_.learnedRegions = learned;
}

size_t TreeTable::bytes() const {
    size_t b = regions_.size() * sizeof(Region);
    for (const Region& r : regions_)
        b += r.tree.bytes() + r.q.size() * sizeof(float) + r.visits.size() * sizeof(double);
    return b;
}

}  // namespace rlpbrt::guiding
