// The learned part of a guiding field with adaptive directions (issue 30): per region a
// DirTree over the unit square whose leaves hold Q, the running mean of the targets recorded
// in them, and their visits; a region's sampling density puts leaf mass Q x area (x the
// leaf centre's cos(theta) with `cosine`, for hemisphere regions) and mixes in a uniform
// share epsilon. Between passes the records are merged in slot order (slot_merge.h, as
// StrataTable's), the leaves' Q and visits updated, and each region's tree refined where its
// mass concentrates (DirTree::refined: split above splitShare of the region's mass, merge
// below), Q and visits carried into the new leaves (a split leaf's pieces keep its Q until
// their own records replace it; a merged subtree becomes the visit-weighted mean of its
// leaves). Regions start
// as a single leaf (the uniform distribution), so memory follows the regions and directions
// where paths bring light. Points of the square are the owner's to map to directions
// (DirTree's equal-area maps in the region's frame). Standard library, GLM and TBB.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "guiding/dir_tree.h"
#include "guiding/guiding.h"
#include "guiding/slot_merge.h"

namespace rlpbrt::guiding {

class TreeTable {
public:
    struct Settings {
        double init = 1e-3;        // Q of a region that has no visits yet
        double epsilon = 0.1;      // uniform share of every region's density
        double splitShare = 0.01;  // DirTree::refined's threshold
        int maxDepth = 12;         // leaves at most this deep (edge 2^-depth of the square)
        bool cosine = false;       // weigh a leaf's mass by its centre's cos(theta) (= a.x)
        // Prior strength, in visits, of the hierarchical smoothing of the leaves' estimates
        // (as StrataTable::setSmoothing): a node's estimate is (S + smooth x its parent's) /
        // (N + smooth) with S and N the visit-weighted Q and the visits under it, so a leaf
        // with few visits borrows its neighbourhood's light. 0: each leaf its own Q.
        double smooth = 2.0;
    };

    // `regions` single-leaf regions with Q = init, no visits.
    void reset(size_t regions, const Settings& settings);
    size_t regions() const { return regions_.size(); }
    const Settings& settings() const { return settings_; }
    const DirTree& tree(size_t region) const { return regions_[region].tree; }

    // ---- Per vertex: the policy frozen at the last endPass(); const and thread-safe.
    // A point of the square drawn from the region's density: uniform from u if uMix <
    // epsilon, else the tree's from u. *density is the mixture's density over the square at
    // the point (what density() returns for it); *leaf (if given) its leaf.
    glm::vec2 sample(size_t region, glm::vec2 u, float uMix, float* density,
                     uint32_t* leaf = nullptr) const;
    // The mixture's density over the square at a; *leaf (if given) a's leaf.
    float density(size_t region, glm::vec2 a, uint32_t* leaf = nullptr) const;
    // The estimate of a leaf's incident radiance (Q, smoothed), or at a point.
    float radiance(size_t region, uint32_t leaf) const { return regions_[region].est[leaf]; }
    float radianceAt(size_t region, glm::vec2 a) const {
        return radiance(region, regions_[region].tree.leafOf(a));
    }
    // Visits of all the region's leaves, and the confidence visits / (visits + warmup x
    // leaves) that the backends scale the guide's mixture weight by (1 for warmup 0).
    double visits(size_t region) const { return regions_[region].totalVisits; }
    float confidence(size_t region, double warmup) const;

    // ---- Learning.
    void beginPass(int numSlots);
    // One record: the target T (luminance) of a direction at square point a of a region.
    // Without an open pass in `slot` it is ignored; a target that is negative or not finite
    // and a point outside the square are counted as rejected.
    void record(int slot, uint32_t region, glm::vec2 a, float target);
    // Applies the pass's records in slot order, refines and rebuilds the trees.
    void endPass();

    GuidingStats& stats() { return stats_; }
    const GuidingStats& stats() const { return stats_; }
    // Bytes of the trees and their leaves' Q and visits.
    size_t bytes() const;

private:
    struct Record {
        uint32_t region;
        float target;
        glm::vec2 a;
    };
    struct alignas(64) SlotBuffer {
        std::vector<Record> records;
        uint64_t rejectedTargets = 0;
        uint64_t rejectedRecords = 0;
    };
    struct Region {
        DirTree tree;
        std::vector<float> q;          // per node; a leaf's Q (inner entries unused)
        std::vector<float> est;        // per node; the smoothed estimates (Settings::smooth)
        std::vector<double> visits;    // per node; a leaf's visits (fractional after splits)
        double totalVisits = 0.0;
    };
    void applyRegion(Region& region, const Record* begin, const Record* end) const;
    // Sets the estimates from Q and visits, and the tree's leaf masses from them (x area,
    // x cos with settings_.cosine).
    void setMasses(Region& region) const;

    Settings settings_;
    std::vector<Region> regions_;
    std::vector<SlotBuffer> slots_;
    std::vector<uint64_t> regionEnd_;
    MergedRecords<Record> merged_;
    GuidingStats stats_;
};

}  // namespace rlpbrt::guiding
