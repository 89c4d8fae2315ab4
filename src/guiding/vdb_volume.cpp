#include "guiding/vdb_volume.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <unordered_set>

#include <openvdb/openvdb.h>

namespace rlpbrt::guiding {

struct VdbVolume::Grid {
    openvdb::Int32Grid::Ptr grid;
};

VdbVolume::VdbVolume(const VolumeParams& params, const glm::vec3& boundsMin,
                     const glm::vec3& boundsMax)
    : params_(params), layout_(params.cols, params.rows), origin_(boundsMin),
      grid_(std::make_unique<Grid>()) {
    openvdb::initialize();
    const glm::vec3 extent = glm::max(boundsMax - boundsMin, glm::vec3(0.f));
    const double longest = std::max({double(extent.x), double(extent.y), double(extent.z)});
    voxelSize_ = longest > 0.0 && std::isfinite(longest)
                     ? longest / std::max(params.voxelCount, 1)
                     : 1.0;
    invVoxel_ = float(1.0 / voxelSize_);
    for (int a = 0; a < 3; ++a)
        dims_[a] = std::clamp(int(std::ceil(double(extent[a]) / voxelSize_)), 1, 4096);
    grid_->grid = openvdb::Int32Grid::create(-1);
    if (params_.smooth > 0.0)
        table_.setSmoothing(layout_.sphereQuadtree(), params_.smooth);
    table_.reset(0, 2 * layout_.count(), params_.init, policy());
}

VdbVolume::~VdbVolume() = default;

bool VdbVolume::voxelOf(const glm::vec3& p, glm::ivec3* ijk) const {
    const glm::vec3 c = glm::floor((p - origin_) * invVoxel_);
    // Also rejects NaN; points on the far faces belong to the last voxel.
    if (!(c.x >= 0.f && c.y >= 0.f && c.z >= 0.f && c.x <= float(dims_.x) &&
          c.y <= float(dims_.y) && c.z <= float(dims_.z)))
        return false;
    *ijk = glm::min(glm::ivec3(c), dims_ - 1);
    return true;
}

int VdbVolume::lookup(const glm::vec3& p) const {
    glm::ivec3 ijk;
    if (coords_.empty() || !voxelOf(p, &ijk)) return -1;
    return grid_->grid->tree().getValue(openvdb::Coord(ijk.x, ijk.y, ijk.z));
}

void VdbVolume::request(int slot, const glm::vec3& p) {
    glm::ivec3 ijk;
    if (slot < 0 || size_t(slot) >= requests_.size() || coords_.size() >= params_.maxVoxels ||
        !voxelOf(p, &ijk))
        return;
    const uint64_t key = voxelKey(ijk);
    Requests& r = requests_[size_t(slot)];
    if (r.seen.insert(key).second) r.order.push_back(key);
}

int VdbVolume::stratumOf(const glm::vec3& w) const {
    glm::vec3 unit;
    return unitDirection(w, &unit) ? layout_.sphereStratumOf(unit) : -1;
}

float VdbVolume::pdf(int cell, const glm::vec3& w) const {
    if (cell < 0 || cell >= cells()) return 0.f;
    const int j = stratumOf(w);
    if (j < 0) return 0.f;
    return strataProbability(table_.cdf(size_t(cell)), j) * layout_.density();
}

glm::vec3 VdbVolume::sample(int cell, glm::vec2 u, float* pdfOut) const {
    if (cell < 0 || cell >= cells()) {
        *pdfOut = 0.f;
        return glm::vec3(0.f);
    }
    const float* c = table_.cdf(size_t(cell));
    glm::vec2 pos;
    const int cols = layout_.cols();
    const int j = sampleStrataCdf2D(c, cols, table_.strata() / cols, u, &pos);
    const glm::vec3 w = glm::normalize(layout_.sampleSphereStratum(j, pos));
    // Report exactly pdf(cell, w); on the equator (measure zero) keep the drawn stratum's.
    float p = pdf(cell, w);
    if (!(p > 0.f)) p = strataProbability(c, j) * layout_.density();
    *pdfOut = p;
    return w;
}

float VdbVolume::radiance(int cell, const glm::vec3& w) const {
    if (cell < 0 || cell >= cells()) return 0.f;
    const int j = stratumOf(w);
    return j < 0 ? 0.f : table_.estimates(size_t(cell))[j];
}

float VdbVolume::scatteredEstimate(int cell,
                                   const std::function<float(const glm::vec3&)>& fcos) const {
    if (cell < 0 || cell >= cells()) return 0.f;
    const float* q = table_.estimates(size_t(cell));
    double acc = 0.0;
    for (int j = 0, n = table_.strata(); j < n; ++j) {
        const float f = fcos(layout_.sphereCentre(j));
        if (f > 0.f && std::isfinite(f)) acc += q[j] * double(f);
    }
    return float(std::min(acc * layout_.stratumSolidAngle(), double(FLT_MAX)));
}

StrataTable::PolicyBuilder VdbVolume::policy() const {
    return [this](int cell, const double* q, float* cdf) {
        buildStrataCdf(q, 2 * layout_.count(), params_.epsilon, cdf);
        if (cell >= 0 && size_t(cell) < confidence_.size())
            confidence_[size_t(cell)] = table_.confidence(size_t(cell), params_.warmup);
    };
}

void VdbVolume::beginPass(int numSlots) {
    table_.beginPass(numSlots);
    requests_.resize(size_t(std::max(numSlots, 0)));
    for (Requests& r : requests_) {
        r.order.clear();
        r.seen.clear();
    }
}

void VdbVolume::record(int slot, int cell, const glm::vec3& w, float target) {
    table_.record(slot, cell, target,
                  [&] { return cell >= 0 && cell < cells() ? stratumOf(w) : -1; });
}

void VdbVolume::activate(const glm::ivec3& ijk) {
    const openvdb::Coord c(ijk.x, ijk.y, ijk.z);
    openvdb::Int32Tree& tree = grid_->grid->tree();
    if (tree.getValue(c) >= 0) return;
    tree.setValue(c, int(coords_.size()));
    coords_.push_back(ijk);
}

void VdbVolume::endPass() {
    table_.endPass(params_.alphaVisits, params_.fixedAlpha, policy());
    const size_t before = coords_.size();
    for (Requests& r : requests_) {
        for (uint64_t key : r.order) {
            if (coords_.size() >= params_.maxVoxels) break;
            activate(voxelFromKey(key));
        }
        r.order.clear();
        r.seen.clear();
    }
    if (coords_.size() > before) {
        confidence_.resize(coords_.size(), params_.warmup > 0.0 ? 0.f : 1.f);
        table_.grow(coords_.size(), params_.init, policy());
    }
}

void VdbVolume::endPassShared(const SumAcrossProcesses& sum) {
    table_.endPassShared(params_.alphaVisits, params_.fixedAlpha, policy(), sum);
    // Each slot's requests are one process's (the others' slots are empty): the counts per
    // slot, then the keys at their slot's place, summed, are every process's requests in
    // slot order (keys below 2^53 are exact in doubles; the others add zeros).
    std::vector<double> counts(requests_.size(), 0.0);
    for (size_t s = 0; s < requests_.size(); ++s) counts[s] = double(requests_[s].order.size());
    sum(counts);
    size_t total = 0;
    std::vector<size_t> start(requests_.size());
    for (size_t s = 0; s < requests_.size(); ++s) {
        start[s] = total;
        total += size_t(counts[s]);
    }
    if (total > 0) {
        std::vector<double> keys(total, 0.0);
        for (size_t s = 0; s < requests_.size(); ++s)
            for (size_t i = 0; i < requests_[s].order.size(); ++i)
                keys[start[s] + i] = double(requests_[s].order[i]);
        sum(keys);
        const size_t before = coords_.size();
        for (double k : keys) {
            if (coords_.size() >= params_.maxVoxels) break;
            activate(voxelFromKey(uint64_t(k)));
        }
        if (coords_.size() > before) {
            confidence_.resize(coords_.size(), params_.warmup > 0.0 ? 0.f : 1.f);
            table_.grow(coords_.size(), params_.init, policy());
        }
    }
    for (Requests& r : requests_) {
        r.order.clear();
        r.seen.clear();
    }
}

bool VdbVolume::validCells(const std::vector<glm::ivec3>& coords) const {
    std::unordered_set<uint64_t> seen;
    for (const glm::ivec3& c : coords)
        if (glm::any(glm::lessThan(c, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(c, dims_)) ||
            !seen.insert(voxelKey(c)).second)
            return false;
    return true;
}

void VdbVolume::restore(const std::vector<glm::ivec3>& coords, std::vector<double> q,
                        std::vector<uint64_t> visits, const GuidingStats& stats) {
    grid_->grid = openvdb::Int32Grid::create(-1);
    coords_.clear();
    for (const glm::ivec3& c : coords) activate(c);
    confidence_.assign(coords_.size(), params_.warmup > 0.0 ? 0.f : 1.f);
    table_.reset(coords_.size(), 2 * layout_.count(), params_.init, policy());
    table_.assign(std::move(q), std::move(visits), policy());
    table_.stats() = stats;
}

size_t VdbVolume::bytes() const {
    return table_.bytes() + size_t(grid_->grid->memUsage()) +
           coords_.capacity() * sizeof(glm::ivec3) + confidence_.capacity() * sizeof(float);
}

size_t VdbVolume::scratchBytes() const {
    size_t b = table_.scratchBytes();
    for (const Requests& r : requests_)
        b += r.order.capacity() * sizeof(uint64_t) + r.seen.size() * 2 * sizeof(uint64_t);
    return b;
}

}  // namespace rlpbrt::guiding
