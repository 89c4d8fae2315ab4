// Guiding at medium vertices for the vdb backend: full-sphere strata tables (in a fixed world
// frame: the upper hemisphere z > 0 holds strata 0..n-1, the lower one n..2n-1) on the voxels
// of a second sparse OpenVDB grid over the box that bounds the scene's participating media.
// A voxel is activated at the end of the first pass in which a path scattered in it (the
// requests are merged in slot order, so the numbering is deterministic), so memory follows
// where the media scatter light, up to a voxel cap. Learning is the surface tables' (Eq. 1
// batch merge, epsilon floor, warmup confidence) through a StrataTable of its own.
// OpenVDB is included only by vdb_volume.cpp: this header is plain C++.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <unordered_set>
#include <vector>

#include "guiding/directional.h"
#include "guiding/guiding.h"
#include "guiding/strata_table.h"

namespace rlpbrt::guiding {

// Validated parameters of the volume tables (from the vdb backend's parameters).
struct VolumeParams {
    int voxelCount = 32;       // voxels along the longest axis of the media bounds
    int cols = 8, rows = 8;    // strata per hemisphere (2 cols rows per voxel)
    double init = 1e-3;
    double epsilon = 0.1;
    double warmup = 16.0;
    double smooth = 0.0;  // StrataTable::setSmoothing's prior over the sphere quadtree; 0: off
    bool alphaVisits = true;
    double fixedAlpha = 1.0;
    uint64_t maxVoxels = uint64_t(1) << 20;  // activation stops here (memory cap)
};

class VdbVolume {
public:
    // The grid covers [boundsMin, boundsMax] (a non-empty box) with cubic voxels of edge
    // longest / voxelCount; no voxel is active until requested.
    VdbVolume(const VolumeParams& params, const glm::vec3& boundsMin, const glm::vec3& boundsMax);
    ~VdbVolume();
    VdbVolume(const VdbVolume&) = delete;
    VdbVolume& operator=(const VdbVolume&) = delete;

    // Cell (table index) of the active voxel containing p; -1 if none (or p outside the box).
    int lookup(const glm::vec3& p) const;
    // Asks for the voxel containing p to be activated at the next endPass (ignored outside
    // the box, without an open pass in `slot`, or once the cap is reached). Thread-safe
    // across slots.
    void request(int slot, const glm::vec3& p);

    // Stratum of a world direction (need not be unit); -1 for a zero, NaN or equatorial w.
    int stratumOf(const glm::vec3& w) const;
    // The GuidingField operations for a cell in [0, cells()).
    float pdf(int cell, const glm::vec3& w) const;
    glm::vec3 sample(int cell, glm::vec2 u, float* pdf) const;
    float radiance(int cell, const glm::vec3& w) const;
    // (2 pi / n) sum_j Q(cell, j) fcos(centre_j) over all 2n strata (GuidingField's contract).
    float scatteredEstimate(int cell, const std::function<float(const glm::vec3&)>& fcos) const;
    float confidence(int cell) const {
        return cell >= 0 && size_t(cell) < confidence_.size() ? confidence_[size_t(cell)] : 0.f;
    }
    void beginPass(int numSlots);
    void record(int slot, int cell, const glm::vec3& w, float target);
    // Applies the records, then activates the requested voxels (slot order, then request order).
    void endPass();
    // endPass for a volume that several processes learn together (GuidingField::
    // endPassShared): the tables' statistics are summed, and the requests of all slots are
    // gathered in slot order, so every process activates the same voxels in the same order.
    void endPassShared(const SumAcrossProcesses& sum);

    int cells() const { return int(table_.regions()); }
    int strata() const { return table_.strata(); }
    double voxelSize() const { return voxelSize_; }
    // Voxels along each axis of the box (cell coordinates lie in [0, dims)).
    glm::ivec3 dims() const { return dims_; }
    const VolumeParams& params() const { return params_; }
    const StrataTable& table() const { return table_; }
    // The cells' learned selection probabilities (GuidingField::selection).
    SelectionLearner& selection() { return table_.selection(); }
    const SelectionLearner& selection() const { return table_.selection(); }
    // Integer coordinates of the voxel of each cell, in cell order (for saving).
    const std::vector<glm::ivec3>& cellCoords() const { return coords_; }
    // True if every coordinate lies in [0, dims) and none repeats (the cells of a saved field).
    bool validCells(const std::vector<glm::ivec3>& coords) const;
    // Replaces the cells and their learned data (coords.size() cells, q and visits of
    // cells * strata entries; the caller validated the sizes and values).
    void restore(const std::vector<glm::ivec3>& coords, std::vector<double> q,
                 std::vector<uint64_t> visits, const GuidingStats& stats);
    // Learned data, grid and the coordinates, in bytes (not the per-pass buffers).
    size_t bytes() const;
    size_t scratchBytes() const;
    const GuidingStats& stats() const { return table_.stats(); }

private:
    struct Grid;  // the OpenVDB grid, defined in vdb_volume.cpp
    bool voxelOf(const glm::vec3& p, glm::ivec3* ijk) const;
    // A voxel's linear index in the box (the request and duplicate-check key), and back.
    uint64_t voxelKey(const glm::ivec3& ijk) const {
        return uint64_t(ijk.x) +
               uint64_t(dims_.x) * (uint64_t(ijk.y) + uint64_t(dims_.y) * uint64_t(ijk.z));
    }
    glm::ivec3 voxelFromKey(uint64_t key) const {
        const uint64_t dx = uint64_t(dims_.x), dy = uint64_t(dims_.y);
        return glm::ivec3(int(key % dx), int((key / dx) % dy), int(key / (dx * dy)));
    }
    StrataTable::PolicyBuilder policy() const;
    void activate(const glm::ivec3& ijk);

    VolumeParams params_;
    StrataLayout layout_;
    glm::vec3 origin_;
    glm::ivec3 dims_;
    double voxelSize_;
    float invVoxel_;
    std::unique_ptr<Grid> grid_;
    std::vector<glm::ivec3> coords_;
    mutable std::vector<float> confidence_;  // per cell, refreshed with each CDF build
    StrataTable table_;
    struct alignas(64) Requests {
        std::vector<uint64_t> order;          // packed voxel keys in request order
        std::unordered_set<uint64_t> seen;
    };
    std::vector<Requests> requests_;
};

}  // namespace rlpbrt::guiding
