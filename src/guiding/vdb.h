// The `vdb` guiding backend: the hemi backend's learning (Eq. 1 batch updates, frozen CDFs,
// epsilon floor, cosine product) on the active voxels of a sparse OpenVDB grid instead of
// kd-tree points. The grid covers the scene bounds; a voxel is active iff a uniform surface
// sample fell in it, and holds the index of its directional tables. OpenVDB is included only
// by vdb.cpp: this header is plain C++ so that tests and tools need no OpenVDB flags.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "guiding/directional.h"
#include "guiding/guiding.h"
#include "guiding/strata_table.h"
#include "guiding/vdb_volume.h"

namespace rlpbrt::guiding {

// Validated parameters of the vdb backend (see createGuidingField for their meaning).
struct VdbParams {
    bool alphaVisits = true;
    double fixedAlpha = 1.0;
    // Surface strata: 16x16 with warmup 8, as hemi's (HemiParams::cols); against 8x8 with
    // warmup 16 it won on veach-bidir and was within noise elsewhere, at three times the
    // memory (docs/GUIDING.md, `strata`).
    int cols = 16, rows = 16;
    double voxelSize = 0.0;   // world units; 0: from voxelCount or the scene-derived default
    int voxelCount = 0;       // voxels along the longest axis; 0: not given
    uint64_t points = 0;      // surface samples; 0: the scene-derived default
    double init = 1e-3;
    double epsilon = 0.1;
    bool cosine = true;       // hemisphere tables only: sample in proportion to Q cos(theta)
    bool sphere = false;      // one full-sphere table per voxel instead of hemispheres
    int normals = 4;          // at most this many dominant normals (hemisphere pairs) a voxel
    double normalAngleDeg = 30;  // normal clustering angle and lookup's admissible deviation
    double warmup = 8.0;      // confidence = visits / (visits + warmup * strata), as hemi
    double learnCap = 256.0;  // records per stratum after which a region stops, as hemi
    // Hemisphere tables: as hemi's (HemiParams::prune), but 0 by default (hemi's 0.3 was
    // measured with hemi only).
    double prune = 0.0;
    // Hierarchical smoothing of the strata estimates, as hemi's (HemiParams::smooth), for the
    // surface and the volume tables: it removes samples=sequence's bias on a white furnace
    // (docs/STABILITY.md).
    double smooth = 2.0;
    bool volume = true;       // guide at medium vertices (when the scene has media)
    int volumeVoxels = 32;    // volume voxels along the longest axis of the media bounds
    // The medium cells' full-sphere tables: 2 x 8 x 8 strata and warmup 16; the surface
    // tables' 16x16 and warmup 8 grew too large on cloud and lost there (docs/GUIDING.md,
    // `volume-strata`).
    int volumeCols = 8, volumeRows = 8;
    double volumeWarmup = 16.0;
    uint64_t volumeMaxVoxels = uint64_t(1) << 20;  // from max-mb
};

// The voxel edge and surface-sample count the parameters give for a scene.
double vdbVoxelSize(const VdbParams& params, const SceneInfo& scene);
uint64_t vdbPointCount(const VdbParams& params, const SceneInfo& scene, double voxelSize);
// Upper estimate of a vdb field's bytes (every sample in its own voxel, capped by the
// number of voxels a surface of the scene's area can cross).
double vdbEstimatedBytes(const VdbParams& params, const SceneInfo& scene);
// Bytes of one medium cell (its full-sphere tables and CDF, grid share): max-mb's budget left
// after the surface tables, divided by this, caps the medium cells.
double vdbMediumCellBytes(const VdbParams& params);

class VdbField final : public GuidingField {
public:
    VdbField(const VdbParams& params, const SceneInfo& scene);
    ~VdbField() override;
    VdbField(const VdbField&) = delete;
    VdbField& operator=(const VdbField&) = delete;

    // A surface vertex's region: the voxel's dominant normal closest to q.n within
    // normal-angle (lookupSurface); a medium vertex's: the volume cell at q.p.
    int locate(const VertexQuery& q) const override {
        return q.medium ? lookupVolume(q.p) : lookupSurface(q.p, q.n);
    }
    int lookupSurface(const glm::vec3& p, const glm::vec3& n) const;
    int lookupVolume(const glm::vec3& p) const;
    void requestMedium(int slot, const glm::vec3& p) override;
    glm::vec3 sample(int region, glm::vec2 u, float uPick, float* pdf,
                     int* bin = nullptr) const override;
    float pdf(int region, const glm::vec3& w, int* bin = nullptr) const override;
    float scatteredEstimate(int region,
                            const std::function<float(const glm::vec3&)>& fcos) const override;
    float irradianceEstimate(int region, const glm::vec3& n) const override;
    float radiance(int region, const glm::vec3& w, int bin = -1) const override;
    float confidence(int region) const override;
    bool learns(int region) const override;
    bool guides(int region) const override;
    float selection(int region) const override;
    void recordSelection(int slot, int region, const SelectionSample& s) override;
    void beginPass(int numSlots) override;
    void record(int slot, int region, const glm::vec3& w, float target,
                int bin = -1) override;
    void endPass() override;
    void endPassShared(const SumAcrossProcesses& sum) override;
    bool sharesPasses() const override { return true; }
    size_t bytes() const override;
    std::string describe() const override;
    GuidingStats stats() const override;
    bool save(const std::string& path, std::string* error) const override;
    bool load(const std::string& path, std::string* error) override;
    // The saved field (an OpenVDB stream) and the selection learners' states.
    bool saveState(std::string* state, std::string* error) const override;
    bool loadState(const std::string& state, std::string* error) override;

    // Inspection (tests, tools).
    const VdbParams& params() const { return params_; }
    const StrataLayout& layout() const { return layout_; }
    double voxelSize() const { return voxelSize_; }
    uint64_t pointCount() const { return points_; }
    size_t activeVoxels() const { return clusterStart_.empty() ? 0 : clusterStart_.size() - 1; }
    // Dominant normals (hemisphere pairs) of all voxels.
    size_t clusterCount() const { return clusterNormals_.size(); }
    int numRegions() const { return int(table_.regions()); }
    // Strata per region: layout().count(), doubled for full-sphere tables.
    int strataPerRegion() const { return table_.strata(); }
    // Solid angle of one stratum (2 pi / layout().count() in both modes).
    double stratumSolidAngle() const { return layout_.stratumSolidAngle(); }
    // Voxel of a region and the region's frame (z = one of the voxel's dominant normals, or
    // its opposite for the second hemisphere).
    int regionVoxel(int region) const { return regionVoxel_[size_t(region)]; }
    const Frame& regionFrame(int region) const { return frames_[size_t(region)]; }
    // Integer coordinates of the voxel containing p (floor((p - origin) / voxelSize)).
    glm::ivec3 voxelCoord(const glm::vec3& p) const;
    // Index stored in the grid at a voxel, -1 if inactive.
    int voxelIndex(const glm::ivec3& ijk) const;
    // Unit world direction of stratum j's centre in a region.
    glm::vec3 strataCentre(int region, int j) const;
    int stratumOf(int region, const glm::vec3& w) const;
    // The same, given the bin that pdf()/sample() reported for it (-1 or out of range: found
    // from w).
    int stratumOf(int region, const glm::vec3& w, int bin) const {
        return validRegion(region) && bin >= 0 && bin < table_.strata() ? bin
                                                                         : stratumOf(region, w);
    }
    double q(int region, int stratum) const { return table_.q(size_t(region))[stratum]; }
    uint64_t visits(int region, int stratum) const {
        return table_.visits(size_t(region))[stratum];
    }
    const std::vector<double>& qTable() const { return table_.qTable(); }
    const std::vector<uint64_t>& visitTable() const { return table_.visitTable(); }
    const std::vector<float>& cdfTable() const { return table_.cdfTable(); }
    size_t scratchBytes() const { return table_.scratchBytes(); }
    // The medium vertices' tables (nullptr: no media or volume=0); their regions follow the
    // surface regions: region = numRegions() + cell.
    const VdbVolume* volume() const { return volume_.get(); }
    bool guidesMedia() const override { return volume_ != nullptr; }
    // Bytes of the OpenVDB tree alone.
    size_t gridBytes() const;
    // How lookup() reads the grid (benchmarks; not thread-safe against running lookups):
    // a fresh non-registering ValueAccessor per lookup, one cached accessor per thread
    // (tbb::enumerable_thread_specific), the tree's uncached getValue, or (default) the
    // uncached getValue for the vertex's voxel and an accessor only when the 26 neighbours
    // must be searched. Measured in bench/guide_lookup_bench.cpp (docs/BENCHMARKS.md).
    enum class Accessor { PerLookup, PerThread, Uncached, Hybrid };
    void setAccessor(Accessor mode) { accessor_ = mode; }

private:
    struct Grid;  // the OpenVDB grid, defined in vdb.cpp
    bool validRegion(int region) const { return region >= 0 && size_t(region) < table_.regions(); }
    // The volume cell of a region past the surface regions, else -1.
    int volumeCell(int region) const {
        return region >= 0 && volume_ && size_t(region) >= table_.regions() ? region - int(table_.regions()) : -1;
    }
    // save()'s grid: a copy of the regions' grid (sharing its tree) with the tables as
    // metadata; and load()'s reading of such a grid (`name` names it in messages).
    std::unique_ptr<Grid> savedGrid() const;
    bool loadGrid(Grid& saved, const std::string& name, std::string* error);
    void buildPolicy(const double* q, float* cdf) const;
    StrataTable::PolicyBuilder policy() const;
    void buildFrames();

    VdbParams params_;
    StrataLayout layout_;
    glm::vec3 sceneMin_, sceneMax_;
    double sceneArea_;
    double voxelSize_;
    float invVoxel_;
    glm::vec3 origin_;
    uint64_t points_ = 0;    // surface samples accepted
    uint64_t attempts_ = 0;  // samplePoint calls
    std::unique_ptr<Grid> grid_;
    float cosMaxAngle_;
    // Voxel v (the grid's value) owns clusters clusterStart_[v] .. clusterStart_[v + 1] - 1;
    // cluster k owns regions 2k (around its normal) and 2k + 1 (around the opposite), or
    // region k for full-sphere tables.
    std::vector<uint32_t> clusterStart_;
    std::vector<glm::vec3> clusterNormals_;  // unit dominant normal per cluster
    std::vector<int> regionVoxel_;          // per region
    std::vector<Frame> frames_;         // per region
    // Per region: visits / (visits + warmup * strata), refreshed with each CDF build (the
    // policy builder is const, called concurrently for distinct regions).
    mutable std::vector<float> confidence_;
    mutable std::vector<uint8_t> learns_;  // per surface region: below the learn cap
    mutable std::vector<uint8_t> guides_;  // per surface region: not pruned (prune)
    void resetConfidence();
    std::vector<float> centreX_, centreY_, centreZ_;  // local stratum centres (all strata)
    StrataTable table_;
    std::unique_ptr<VdbVolume> volume_;
    Accessor accessor_ = Accessor::Hybrid;
    template <class Probe>
    int lookupWith(const glm::vec3& p, const glm::vec3& n, Probe& probe) const;
};

}  // namespace rlpbrt::guiding
