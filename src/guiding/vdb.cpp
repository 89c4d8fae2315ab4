#include "guiding/vdb.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>

#include <sstream>

#include <openvdb/io/File.h>
#include <openvdb/io/Stream.h>
#include <openvdb/openvdb.h>
#include <openvdb/tree/ValueAccessor.h>
#include <tbb/enumerable_thread_specific.h>

#include "guiding/field_io.h"

namespace rlpbrt::guiding {

namespace {

bool finite3(const glm::vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

float longestAxis(const SceneInfo& scene) {
    glm::vec3 d = scene.boundsMax - scene.boundsMin;
    float l = std::max(d.x, std::max(d.y, d.z));
    return std::isfinite(l) && l > 0.f ? l : 0.f;
}

// Coordinates beyond this are treated as outside every grid (and stay far from int overflow
// when the 26 neighbours are formed).
constexpr float kMaxCoord = float(1 << 30);

constexpr const char* kGridName = "rlpbrt_regions";
constexpr int kFileVersion = 1;

// A non-registering accessor: cheap to construct per lookup, read-only, no locking.
using ConstAccessor = openvdb::tree::ValueAccessor<const openvdb::Int32Tree, false>;

}  // namespace

struct VdbField::Grid {
    openvdb::Int32Grid::Ptr grid;
    // Per-thread accessors (Accessor::PerThread), created on first use by each thread.
    mutable tbb::enumerable_thread_specific<std::unique_ptr<ConstAccessor>> accessors;
};

double vdbVoxelSize(const VdbParams& params, const SceneInfo& scene) {
    if (params.voxelSize > 0.0) return params.voxelSize;
    const double longest = longestAxis(scene);
    if (!(longest > 0.0)) return 1.0;
    if (params.voxelCount > 0) return longest / params.voxelCount;
    double h = scene.totalArea > 0.0 && std::isfinite(scene.totalArea)
                   ? std::sqrt(scene.totalArea / 1024.0)
                   : longest / 64.0;
    return std::clamp(h, longest / 1024.0, longest / 4.0);
}

uint64_t vdbPointCount(const VdbParams& params, const SceneInfo& scene, double h) {
    if (params.points > 0) return params.points;
    double n = 16.0 * std::max(scene.totalArea, 0.0) / (h * h);
    if (!std::isfinite(n)) n = double(uint64_t(1) << 24);
    return uint64_t(std::clamp(n, 65536.0, double(uint64_t(1) << 24)));
}

double vdbEstimatedBytes(const VdbParams& params, const SceneInfo& scene) {
    const double h = vdbVoxelSize(params, scene);
    const double points = double(vdbPointCount(params, scene, h));
    // A flat surface crosses about area / h^2 voxels, an oblique one up to ~3x that.
    const double crossed = 3.0 * std::max(scene.totalArea, 0.0) / (h * h) + 1024.0;
    const double voxels = std::min(points, std::isfinite(crossed) ? crossed : points);
    // Most voxels hold one surface orientation; edges and corners hold more (counted as 2).
    const double regionsPerVoxel = params.sphere ? 1.0 : 2.0 * std::min(params.normals, 2);
    const double perRegion =
        StrataTable::regionBytes(params.cols * params.rows * (params.sphere ? 2 : 1)) +
        sizeof(Frame);
    // Per voxel: normals, offsets and about 8 bytes of OpenVDB tree (leaf values and masks).
    return voxels * (regionsPerVoxel * (perRegion + sizeof(int)) + 2 * sizeof(glm::vec3) + 12.0);
}

double vdbMediumCellBytes(const VdbParams& params) {
    // A full-sphere table per cell, and ~64 bytes of grid and index.
    return StrataTable::regionBytes(2 * params.volumeCols * params.volumeRows) + 64.0;
}

VdbField::VdbField(const VdbParams& params, const SceneInfo& scene)
    : params_(params),
      layout_(params.cols, params.rows),
      sceneMin_(scene.boundsMin),
      sceneMax_(scene.boundsMax),
      sceneArea_(scene.totalArea),
      voxelSize_(vdbVoxelSize(params, scene)),
      invVoxel_(float(1.0 / voxelSize_)),
      origin_(scene.boundsMin),
      grid_(std::make_unique<Grid>()),
      cosMaxAngle_(static_cast<float>(std::cos(params.normalAngleDeg * PiDouble / 180.0))) {
    openvdb::initialize();
    const uint64_t wanted = vdbPointCount(params, scene, voxelSize_);
    openvdb::Int32Grid::Ptr grid = openvdb::Int32Grid::create(-1);
    grid->setName(kGridName);
    // Index (i, j, k) covers [origin + (i, j, k) h, origin + (i + 1, j + 1, k + 1) h): OpenVDB
    // puts voxel centres at index coordinates, so the transform is offset by half a voxel.
    // The transform only informs other tools reading a saved .vdb (lookups use origin_ and
    // invVoxel_, and loading reads the voxel size from metadata). OpenVDB refuses scales it
    // considers zero (edges below about 1e-6, a scene at scale 1e-4): keep the identity there.
    try {
        openvdb::math::Transform::Ptr xform =
            openvdb::math::Transform::createLinearTransform(voxelSize_);
        xform->postTranslate(openvdb::Vec3d(origin_.x, origin_.y, origin_.z) + 0.5 * voxelSize_);
        grid->setTransform(xform);
    } catch (const openvdb::Exception&) {
    }

    // Activation: uniform surface samples (Halton sequence through the scene's area sampler).
    // Per voxel, the samples' normals are clustered greedily: a sample joins the cluster
    // whose first normal is closest in angle up to normal-angle (either sign), else opens a
    // new cluster while the voxel has fewer than `normals`, else joins the closest. A
    // cluster's normal is the sign-aligned mean of its members.
    struct Cluster {
        glm::vec3 first;
        glm::dvec3 sum;
    };
    std::vector<std::vector<Cluster>> clusters;
    const int maxClusters = params_.sphere ? 1 : params_.normals;
    const float cosAngle = cosMaxAngle_;
    {
        openvdb::Int32Grid::Accessor acc = grid->getAccessor();
        const uint64_t maxAttempts = 2 * wanted + 64;
        for (uint64_t i = 0; points_ < wanted && i < maxAttempts; ++i) {
            ++attempts_;
            glm::vec3 u(radicalInverse(i, 2), radicalInverse(i, 3), radicalInverse(i, 5));
            glm::vec3 p(0.f), n(0.f);
            if (!scene.samplePoint || !scene.samplePoint(u, &p, &n)) {
                if (points_ == 0 && i >= 63) break;  // the scene has no surface
                continue;
            }
            float len = glm::length(n);
            if (!finite3(p) || !(len > 0.f) || !std::isfinite(len)) continue;
            n /= len;
            glm::vec3 c = glm::floor((p - origin_) * invVoxel_);
            if (!(std::abs(c.x) < kMaxCoord && std::abs(c.y) < kMaxCoord &&
                  std::abs(c.z) < kMaxCoord))
                continue;
            const openvdb::Coord ijk(int(c.x), int(c.y), int(c.z));
            int v = acc.getValue(ijk);
            if (v < 0) {
                v = int(clusters.size());
                acc.setValue(ijk, v);
                clusters.emplace_back();
            }
            std::vector<Cluster>& cl = clusters[size_t(v)];
            int best = -1;
            float bestCos = -1.f;
            for (size_t k = 0; k < cl.size(); ++k) {
                float d = std::abs(glm::dot(n, cl[k].first));
                if (d > bestCos) {
                    bestCos = d;
                    best = int(k);
                }
            }
            if (best < 0 || (bestCos < cosAngle && int(cl.size()) < maxClusters)) {
                cl.push_back(Cluster{n, glm::dvec3(0.0)});
                best = int(cl.size()) - 1;
            }
            Cluster& k = cl[size_t(best)];
            k.sum += glm::dvec3(glm::dot(n, k.first) >= 0.f ? n : -n);
            ++points_;
        }
    }
    // Renumber the voxels in the tree's order, so that neighbours' tables are close in memory.
    clusterStart_.assign(1, 0);
    clusterNormals_.clear();
    for (auto it = grid->beginValueOn(); it; ++it) {
        for (const Cluster& k : clusters[size_t(*it)]) {
            double l = glm::length(k.sum);
            clusterNormals_.push_back(l > 1e-12 ? glm::vec3(k.sum / l) : k.first);
        }
        it.setValue(int(clusterStart_.size()) - 1);
        clusterStart_.push_back(uint32_t(clusterNormals_.size()));
    }
    grid_->grid = grid;
    buildFrames();
    if (params_.smooth > 0.0)
        table_.setSmoothing(params_.sphere ? layout_.sphereQuadtree() : layout_.quadtree(),
                            params_.smooth);
    table_.reset(clusterNormals_.size() * (params_.sphere ? 1 : 2),
                 layout_.count() * (params_.sphere ? 2 : 1), params_.init, policy(),
                 /*lazy=*/true);
    resetConfidence();
    if (params_.volume && scene.hasMedia()) {
        VolumeParams vp;
        vp.voxelCount = params_.volumeVoxels;
        vp.cols = params_.volumeCols;
        vp.rows = params_.volumeRows;
        vp.init = params_.init;
        vp.smooth = params_.smooth;
        vp.epsilon = params_.epsilon;
        vp.warmup = params_.volumeWarmup;
        vp.alphaVisits = params_.alphaVisits;
        vp.fixedAlpha = params_.fixedAlpha;
        vp.maxVoxels = params_.volumeMaxVoxels;
        volume_ = std::make_unique<VdbVolume>(vp, scene.mediaMin, scene.mediaMax);
    }
}

VdbField::~VdbField() = default;

void VdbField::buildFrames() {
    frames_.clear();
    regionVoxel_.clear();
    for (size_t v = 0; v + 1 < clusterStart_.size(); ++v)
        for (uint32_t k = clusterStart_[v]; k < clusterStart_[v + 1]; ++k) {
            const glm::vec3& n = clusterNormals_[k];
            frames_.push_back(Frame::fromZ(n));
            regionVoxel_.push_back(int(v));
            if (!params_.sphere) {
                frames_.push_back(Frame::fromZ(-n));
                regionVoxel_.push_back(int(v));
            }
        }
    const int n = layout_.count();
    const int s = params_.sphere ? 2 * n : n;
    centreX_.resize(size_t(s));
    centreY_.resize(size_t(s));
    centreZ_.resize(size_t(s));
    for (int j = 0; j < s; ++j) {
        glm::vec3 c = layout_.sphereCentre(j);
        centreX_[size_t(j)] = c.x;
        centreY_[size_t(j)] = c.y;
        centreZ_[size_t(j)] = c.z;
    }
}

void VdbField::buildPolicy(const double* q, float* cdf) const {
    const int s = table_.strata() > 0 ? table_.strata() : layout_.count() * (params_.sphere ? 2 : 1);
    if (params_.sphere || !params_.cosine) {
        buildStrataCdf(q, s, params_.epsilon, cdf);
        return;
    }
    double qc[64 * 64];
    for (int j = 0; j < s; ++j) qc[j] = q[j] * double(layout_.centre(j).z);
    buildStrataCdf(qc, s, params_.epsilon, cdf);
}

StrataTable::PolicyBuilder VdbField::policy() const {
    return [this](int region, const double* q, float* cdf) {
        buildPolicy(q, cdf);
        if (region < 0 || size_t(region) >= confidence_.size()) return;
        confidence_[size_t(region)] = table_.confidence(size_t(region), params_.warmup);
        learns_[size_t(region)] = table_.belowCap(size_t(region), params_.learnCap);
        guides_[size_t(region)] =
            params_.sphere ||
            !cosineSamplingSuffices(q, layout_, params_.prune, confidence_[size_t(region)]);
    };
}

void VdbField::resetConfidence() {
    confidence_.assign(table_.regions(), params_.warmup > 0.0 ? 0.f : 1.f);
    learns_.assign(table_.regions(), 1);
    guides_.assign(table_.regions(), 1);
}

bool VdbField::guides(int region) const {
    if (volumeCell(region) >= 0) return true;  // medium cells: never pruned
    return region >= 0 && size_t(region) < guides_.size() && guides_[size_t(region)] != 0;
}

bool VdbField::learns(int region) const {
    if (volumeCell(region) >= 0) return true;  // medium cells: Eq. 1's records, uncapped
    return region >= 0 && size_t(region) < learns_.size() && learns_[size_t(region)] != 0;
}

float VdbField::confidence(int region) const {
    if (const int cell = volumeCell(region); cell >= 0) return volume_->confidence(cell);
    return region >= 0 && size_t(region) < confidence_.size() ? confidence_[size_t(region)] : 0.f;
}

glm::ivec3 VdbField::voxelCoord(const glm::vec3& p) const {
    glm::vec3 c = glm::floor((p - origin_) * invVoxel_);
    return glm::ivec3(int(std::clamp(c.x, -kMaxCoord, kMaxCoord)),
                      int(std::clamp(c.y, -kMaxCoord, kMaxCoord)),
                      int(std::clamp(c.z, -kMaxCoord, kMaxCoord)));
}

int VdbField::voxelIndex(const glm::ivec3& ijk) const {
    return grid_->grid->tree().getValue(openvdb::Coord(ijk.x, ijk.y, ijk.z));
}

int VdbField::lookupSurface(const glm::vec3& p, const glm::vec3& n) const {
    switch (accessor_) {
    case Accessor::PerThread: {
        std::unique_ptr<ConstAccessor>& acc = grid_->accessors.local();
        if (!acc) acc = std::make_unique<ConstAccessor>(grid_->grid->tree());
        return lookupWith(p, n, *acc);
    }
    case Accessor::Uncached:
        return lookupWith(p, n, grid_->grid->tree());
    case Accessor::PerLookup: {
        ConstAccessor acc(grid_->grid->tree());
        return lookupWith(p, n, acc);
    }
    case Accessor::Hybrid:
    default: {
        // Vertices on surfaces almost always hit an active voxel: one uncached probe (no
        // accessor to set up); the neighbour search, 26 nearby probes, goes through an
        // accessor made on demand.
        struct HybridProbe {
            const openvdb::Int32Tree& tree;
            std::optional<ConstAccessor> acc;
            bool first = true;
            int getValue(const openvdb::Coord& c) {
                if (first) {
                    first = false;
                    return tree.getValue(c);
                }
                if (!acc) acc.emplace(tree);
                return acc->getValue(c);
            }
        } probe{grid_->grid->tree(), std::nullopt};
        return lookupWith(p, n, probe);
    }
    }
}

int VdbField::lookupVolume(const glm::vec3& p) const {
    if (!volume_) return -1;
    const int cell = volume_->lookup(p);
    return cell < 0 ? -1 : int(table_.regions()) + cell;
}

void VdbField::requestMedium(int slot, const glm::vec3& p) {
    if (volume_) volume_->request(slot, p);
}

template <class Probe>
int VdbField::lookupWith(const glm::vec3& p, const glm::vec3& n, Probe& probe) const {
    if (clusterNormals_.empty() || !finite3(p)) return -1;
    if (!params_.sphere && !(glm::dot(n, n) > 0.f)) return -1;
    const glm::vec3 c = glm::floor((p - origin_) * invVoxel_);
    if (!(std::abs(c.x) < kMaxCoord && std::abs(c.y) < kMaxCoord && std::abs(c.z) < kMaxCoord))
        return -1;
    const openvdb::Coord ijk(int(c.x), int(c.y), int(c.z));
    int v = probe.getValue(ijk);
    if (v < 0) {
        // The nearest active voxel among the 26 neighbours (distance from p to the voxel's
        // box; ties go to the first in z, y, x order), else no data.
        const glm::vec3 f = (p - origin_) * invVoxel_ - c;  // position inside the voxel, [0,1]
        float best = FLT_MAX;
        for (int dz = -1; dz <= 1; ++dz)
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    if (!(dx | dy | dz)) continue;
                    int vi = probe.getValue(ijk.offsetBy(dx, dy, dz));
                    if (vi < 0) continue;
                    auto axis = [](int d, float t) {
                        return d < 0 ? t : (d > 0 ? 1.f - t : 0.f);
                    };
                    const float ax = axis(dx, f.x), ay = axis(dy, f.y), az = axis(dz, f.z);
                    const float d2 = ax * ax + ay * ay + az * az;
                    if (d2 < best) {
                        best = d2;
                        v = vi;
                    }
                }
        if (v < 0) return -1;
    }
    if (params_.sphere) return v;
    // The voxel's dominant normal closest to n (either side), if within normal-angle.
    const float threshold = cosMaxAngle_ * glm::length(n);
    int best = -1;
    float bestCos = -1.f;
    bool flip = false;
    for (uint32_t k = clusterStart_[size_t(v)], e = clusterStart_[size_t(v) + 1]; k < e; ++k) {
        const float d = glm::dot(n, clusterNormals_[k]);
        if (std::abs(d) > bestCos) {
            bestCos = std::abs(d);
            best = int(k);
            flip = d < 0.f;
        }
    }
    if (best < 0 || !(bestCos >= threshold)) return -1;
    return 2 * best + (flip ? 1 : 0);
}

int VdbField::stratumOf(int region, const glm::vec3& w) const {
    glm::vec3 unit;
    if (!validRegion(region) || !unitDirection(w, &unit)) return -1;
    const glm::vec3 local = frames_[size_t(region)].toLocal(unit);
    return params_.sphere ? layout_.sphereStratumOf(local) : layout_.stratumOf(local);
}

glm::vec3 VdbField::strataCentre(int region, int j) const {
    const size_t k = size_t(j);
    return frames_[size_t(region)].toWorld(glm::vec3(centreX_[k], centreY_[k], centreZ_[k]));
}

float VdbField::pdf(int region, const glm::vec3& w, int* bin) const {
    if (const int cell = volumeCell(region); cell >= 0) {
        if (bin) *bin = -1;  // the volume tables find their bin again
        return volume_->pdf(cell, w);
    }
    const int j = stratumOf(region, w);
    if (bin) *bin = j;
    if (j < 0) return 0.f;
    return strataProbability(table_.cdf(size_t(region)), j) * layout_.density();
}

glm::vec3 VdbField::sample(int region, glm::vec2 u, float /*uPick*/, float* pdfOut,
                           int* bin) const {
    if (bin) *bin = -1;
    if (const int cell = volumeCell(region); cell >= 0)
        return volume_->sample(cell, u, pdfOut);
    if (!validRegion(region)) {
        *pdfOut = 0.f;
        return glm::vec3(0.f);
    }
    const float* c = table_.cdf(size_t(region));
    glm::vec2 cell;
    const int cols = layout_.cols();
    const int j = sampleStrataCdf2D(c, cols, table_.strata() / cols, u, &cell);
    glm::vec3 local = layout_.sampleSphereStratum(j, cell);
    glm::vec3 w = glm::normalize(frames_[size_t(region)].toWorld(local));
    // Report exactly pdf(region, w) (rounding may move w across a stratum edge); on the
    // hemisphere's rim (pdf 0) keep the drawn stratum's density, as hemi does.
    float p = pdf(region, w, bin);
    if (!(p > 0.f)) p = strataProbability(c, j) * layout_.density();
    *pdfOut = p;
    return w;
}

float VdbField::scatteredEstimate(int region,
                                  const std::function<float(const glm::vec3&)>& fcos) const {
    if (const int cell = volumeCell(region); cell >= 0) return volume_->scatteredEstimate(cell, fcos);
    if (!validRegion(region)) return 0.f;
    const float* q = table_.estimates(size_t(region));
    double acc = 0.0;
    for (int j = 0; j < table_.strata(); ++j) {
        float f = fcos(strataCentre(region, j));
        if (f > 0.f && std::isfinite(f)) acc += q[j] * double(f);
    }
    return static_cast<float>(std::min(acc * layout_.stratumSolidAngle(), double(FLT_MAX)));
}

float VdbField::irradianceEstimate(int region, const glm::vec3& n) const {
    if (const int cell = volumeCell(region); cell >= 0)
        return volume_->scatteredEstimate(
            cell, [&n](const glm::vec3& w) { return std::max(0.f, glm::dot(w, n)); });
    if (!validRegion(region) || !finite3(n)) return 0.f;
    const glm::vec3 nl = frames_[size_t(region)].toLocal(n);
    const float* q = table_.estimates(size_t(region));
    const float *cx = centreX_.data(), *cy = centreY_.data(), *cz = centreZ_.data();
    float acc = 0.f;
    for (int j = 0, s = table_.strata(); j < s; ++j) {
        float c = cx[j] * nl.x + cy[j] * nl.y + cz[j] * nl.z;
        acc += q[j] * std::max(c, 0.f);
    }
    return static_cast<float>(
        std::min(double(acc) * layout_.stratumSolidAngle(), double(FLT_MAX)));
}

float VdbField::radiance(int region, const glm::vec3& w, int bin) const {
    if (const int cell = volumeCell(region); cell >= 0) return volume_->radiance(cell, w);
    const int j = stratumOf(region, w, bin);
    return j < 0 ? 0.f : table_.estimates(size_t(region))[j];
}

float VdbField::selection(int region) const {
    if (const int cell = volumeCell(region); cell >= 0)
        return volume_->selection().selection(size_t(cell));
    return validRegion(region) ? table_.selection().selection(size_t(region)) : -1.f;
}

void VdbField::recordSelection(int slot, int region, const SelectionSample& s) {
    if (const int cell = volumeCell(region); cell >= 0)
        return volume_->selection().record(slot, cell, s);
    // A region that stopped learning (learn-cap) keeps its selection as well.
    if (learns(region)) table_.selection().record(slot, region, s);
}

void VdbField::beginPass(int numSlots) {
    table_.beginPass(numSlots);
    if (volume_) volume_->beginPass(numSlots);
}

void VdbField::record(int slot, int region, const glm::vec3& w, float target, int bin) {
    if (const int cell = volumeCell(region); cell >= 0) return volume_->record(slot, cell, w, target);
    if (!learns(region)) return;
    table_.record(slot, region, target, [&] { return stratumOf(region, w, bin); });
}

void VdbField::endPass() {
    table_.endPass(params_.alphaVisits, params_.fixedAlpha, policy());
    if (volume_) volume_->endPass();
}

void VdbField::endPassShared(const SumAcrossProcesses& sum) {
    table_.endPassShared(params_.alphaVisits, params_.fixedAlpha, policy(), sum);
    if (volume_) volume_->endPassShared(sum);
}

size_t VdbField::gridBytes() const { return size_t(grid_->grid->memUsage()); }

size_t VdbField::bytes() const {
    return table_.bytes() + gridBytes() + clusterNormals_.capacity() * sizeof(glm::vec3) +
           clusterStart_.capacity() * sizeof(uint32_t) + regionVoxel_.capacity() * sizeof(int) +
           frames_.capacity() * sizeof(Frame) + confidence_.capacity() * sizeof(float) +
           learns_.capacity() + guides_.capacity() +
           3 * centreX_.capacity() * sizeof(float) + (volume_ ? volume_->bytes() : 0);
}

std::string VdbField::describe() const {
    char alpha[32];
    if (params_.alphaVisits)
        std::snprintf(alpha, sizeof(alpha), "visits");
    else
        std::snprintf(alpha, sizeof(alpha), "%g", params_.fixedAlpha);
    const GuidingStats s = stats();
    char vol[160] = "";
    if (volume_)
        std::snprintf(vol, sizeof(vol), "; media: %d cells of %g (%d strata), %.1f MiB",
                      volume_->cells(), volume_->voxelSize(), volume_->strata(),
                      double(volume_->bytes()) / (1024.0 * 1024.0));
    char buf[800];
    std::snprintf(buf, sizeof(buf),
                  "vdb: %zu active voxels of %g (from %llu points, %llu draws), %zu normals, "
                  "%d regions (%s; %zu with tables of their own), %dx%d strata, alpha=%s, init=%g, epsilon=%g, cosine=%d, %.1f MiB "
                  "(grid %.2f MiB; +%.1f MiB record buffers); passes=%llu, records=%llu, "
                  "rejected targets=%llu, rejected records=%llu%s",
                  activeVoxels(), voxelSize_, (unsigned long long)points_,
                  (unsigned long long)attempts_, clusterCount(), numRegions(),
                  params_.sphere ? "full sphere per voxel" : "two hemispheres per normal",
                  table_.learnedRegions(),
                  params_.cols, params_.rows, alpha, params_.init, params_.epsilon,
                  int(params_.cosine && !params_.sphere), double(bytes()) / (1024.0 * 1024.0),
                  double(gridBytes()) / (1024.0 * 1024.0),
                  double(scratchBytes()) / (1024.0 * 1024.0), (unsigned long long)s.passes,
                  (unsigned long long)s.records, (unsigned long long)s.rejectedTargets,
                  (unsigned long long)s.rejectedRecords, vol);
    return buf;
}

GuidingStats VdbField::stats() const {
    GuidingStats s = table_.stats();
    s.activeVoxels = activeVoxels();
    s.learnedRegions = table_.learnedRegions();
    for (uint8_t l : learns_) s.cappedRegions += l ? 0 : 1;
    for (uint8_t g : guides_) s.prunedRegions += g ? 0 : 1;
    if (volume_) {
        const GuidingStats& v = volume_->stats();
        s.records += v.records;
        s.rejectedTargets += v.rejectedTargets;
        s.rejectedRecords += v.rejectedRecords;
        s.mediumCells = uint64_t(volume_->cells());
    }
    return s;
}

// ---- Save / load: an OpenVDB file with one Int32Grid and the tables as grid metadata ----

std::unique_ptr<VdbField::Grid> VdbField::savedGrid() const {
    openvdb::Int32Grid::Ptr copy =
        openvdb::gridPtrCast<openvdb::Int32Grid>(grid_->grid->copyGrid());  // shares the tree
    copy->insertMeta("rlpbrt:format", openvdb::StringMetadata("rlpbrt guiding field"));
    copy->insertMeta("rlpbrt:version", openvdb::Int32Metadata(kFileVersion));
    copy->insertMeta("rlpbrt:backend", openvdb::StringMetadata("vdb"));
    copy->insertMeta("rlpbrt:dirs", openvdb::StringMetadata(params_.sphere ? "sphere" : "hemi"));
    copy->insertMeta("rlpbrt:bounds_min",
                     openvdb::Vec3SMetadata(openvdb::Vec3s(sceneMin_.x, sceneMin_.y, sceneMin_.z)));
    copy->insertMeta("rlpbrt:bounds_max",
                     openvdb::Vec3SMetadata(openvdb::Vec3s(sceneMax_.x, sceneMax_.y, sceneMax_.z)));
    copy->insertMeta("rlpbrt:area", openvdb::DoubleMetadata(sceneArea_));
    copy->insertMeta("rlpbrt:voxel_size", openvdb::DoubleMetadata(voxelSize_));
    copy->insertMeta("rlpbrt:points", openvdb::Int64Metadata(int64_t(points_)));
    copy->insertMeta("rlpbrt:strata", openvdb::Vec2IMetadata(openvdb::Vec2i(params_.cols, params_.rows)));
    copy->insertMeta("rlpbrt:normals_max", openvdb::Int32Metadata(params_.normals));
    copy->insertMeta("rlpbrt:normal_angle", openvdb::DoubleMetadata(params_.normalAngleDeg));
    fieldio::Writer counts, normals;
    for (size_t v = 0; v + 1 < clusterStart_.size(); ++v)
        counts.u32(clusterStart_[v + 1] - clusterStart_[v]);
    for (const glm::vec3& n : clusterNormals_) normals.vec3(n);
    copy->insertMeta("rlpbrt:clusters", openvdb::StringMetadata(counts.data));
    copy->insertMeta("rlpbrt:normals", openvdb::StringMetadata(normals.data));
    copy->insertMeta("rlpbrt:q", openvdb::StringMetadata(fieldio::packDoubles(table_.denseQ())));
    copy->insertMeta("rlpbrt:visits",
                     openvdb::StringMetadata(fieldio::packU64(table_.denseVisits())));
    const GuidingStats& s = table_.stats();
    copy->insertMeta("rlpbrt:passes", openvdb::Int64Metadata(int64_t(s.passes)));
    copy->insertMeta("rlpbrt:records", openvdb::Int64Metadata(int64_t(s.records)));
    copy->insertMeta("rlpbrt:rejected_targets", openvdb::Int64Metadata(int64_t(s.rejectedTargets)));
    copy->insertMeta("rlpbrt:rejected_records", openvdb::Int64Metadata(int64_t(s.rejectedRecords)));
    if (volume_) {
        fieldio::Writer coords, counters;
        for (const glm::ivec3& c : volume_->cellCoords())
            coords.u32(uint32_t(c.x)), coords.u32(uint32_t(c.y)), coords.u32(uint32_t(c.z));
        const GuidingStats& vs = volume_->stats();
        counters.u64(vs.records), counters.u64(vs.rejectedTargets),
            counters.u64(vs.rejectedRecords);
        copy->insertMeta("rlpbrt:volume_voxel_size", openvdb::DoubleMetadata(volume_->voxelSize()));
        copy->insertMeta("rlpbrt:volume_strata", openvdb::Vec2IMetadata(openvdb::Vec2i(
                                                     params_.volumeCols, params_.volumeRows)));
        copy->insertMeta("rlpbrt:volume_cells", openvdb::StringMetadata(coords.data));
        copy->insertMeta("rlpbrt:volume_q",
                         openvdb::StringMetadata(fieldio::packDoubles(volume_->table().denseQ())));
        copy->insertMeta("rlpbrt:volume_visits",
                         openvdb::StringMetadata(fieldio::packU64(volume_->table().denseVisits())));
        copy->insertMeta("rlpbrt:volume_counters", openvdb::StringMetadata(counters.data));
    }
    auto saved = std::make_unique<Grid>();
    saved->grid = copy;
    return saved;
}

bool VdbField::save(const std::string& path, std::string* error) const {
    try {
        const std::unique_ptr<Grid> saved = savedGrid();
        const std::string tmp = path + ".tmp";
        {
            openvdb::io::File file(tmp);
            file.write(openvdb::GridCPtrVec{saved->grid});
            file.close();
        }
        if (std::rename(tmp.c_str(), path.c_str()) != 0) {
            std::remove(tmp.c_str());
            *error = "cannot rename '" + tmp + "' to '" + path + "'";
            return false;
        }
    } catch (const std::exception& e) {
        *error = "cannot write '" + path + "': " + e.what();
        return false;
    }
    return true;
}

bool VdbField::load(const std::string& path, std::string* error) {
    const std::string kind = fieldio::fileKind(path);
    if (kind.empty()) {
        *error = "'" + path + "' is not a saved guiding field (or cannot be read)";
        return false;
    }
    if (kind != "vdb") {
        *error = "'" + path + "' holds a '" + kind +
                 "' guiding field; the vdb backend loads only fields it saved";
        return false;
    }
    openvdb::Int32Grid::Ptr grid;
    try {
        openvdb::io::File file(path);
        file.open();
        if (!file.hasGrid(kGridName)) {
            *error = "'" + path + "' is an OpenVDB file without an rlpbrt guiding grid";
            return false;
        }
        grid = openvdb::gridPtrCast<openvdb::Int32Grid>(file.readGrid(kGridName));
        file.close();
    } catch (const std::exception& e) {
        *error = "cannot read '" + path + "': " + e.what();
        return false;
    }
    if (!grid) {
        *error = "'" + path + "': the guiding grid is not an Int32Grid";
        return false;
    }
    Grid saved;
    saved.grid = grid;
    return loadGrid(saved, path, error);
}

bool VdbField::loadGrid(Grid& saved, const std::string& name, std::string* error) {
    openvdb::Int32Grid::Ptr grid = saved.grid;
    auto fail = [&](const std::string& why) {
        *error = "'" + name + "': " + why;
        return false;
    };
    try {
        if (grid->metaValue<std::string>("rlpbrt:backend") != "vdb")
            return fail("not a vdb guiding field");
        if (grid->metaValue<int32_t>("rlpbrt:version") != kFileVersion)
            return fail("unsupported version " +
                        std::to_string(grid->metaValue<int32_t>("rlpbrt:version")));
        openvdb::Vec3s bmin = grid->metaValue<openvdb::Vec3s>("rlpbrt:bounds_min");
        openvdb::Vec3s bmax = grid->metaValue<openvdb::Vec3s>("rlpbrt:bounds_max");
        std::string why;
        if (!fieldio::sameScene(glm::vec3(bmin.x(), bmin.y(), bmin.z()),
                                glm::vec3(bmax.x(), bmax.y(), bmax.z()),
                                grid->metaValue<double>("rlpbrt:area"), sceneMin_, sceneMax_,
                                sceneArea_, &why))
            return fail(why);
        const double h = grid->metaValue<double>("rlpbrt:voxel_size");
        const int64_t pts = grid->metaValue<int64_t>("rlpbrt:points");
        if (h != voxelSize_ || uint64_t(pts) != points_) {
            char buf[256];
            std::snprintf(buf, sizeof(buf),
                          "voxel size %.9g with %lld points, this field has %.9g with %llu "
                          "(use the same voxel/voxel-size/points parameters)",
                          h, (long long)pts, voxelSize_, (unsigned long long)points_);
            return fail(buf);
        }
        const openvdb::Vec2i st = grid->metaValue<openvdb::Vec2i>("rlpbrt:strata");
        const std::string dirs = grid->metaValue<std::string>("rlpbrt:dirs");
        if (st.x() != params_.cols || st.y() != params_.rows ||
            dirs != (params_.sphere ? "sphere" : "hemi"))
            return fail("strata " + std::to_string(st.x()) + "x" + std::to_string(st.y()) +
                        " dirs=" + dirs + ", this field has " + std::to_string(params_.cols) +
                        "x" + std::to_string(params_.rows) +
                        " dirs=" + (params_.sphere ? "sphere" : "hemi"));
        const int normalsMax = grid->metaValue<int32_t>("rlpbrt:normals_max");
        const double normalAngle = grid->metaValue<double>("rlpbrt:normal_angle");
        if (!params_.sphere &&
            (normalsMax != params_.normals || normalAngle != params_.normalAngleDeg))
            return fail("normals=" + std::to_string(normalsMax) + " normal-angle=" +
                        std::to_string(normalAngle) + ", this field has normals=" +
                        std::to_string(params_.normals) +
                        " normal-angle=" + std::to_string(params_.normalAngleDeg));
        const size_t voxels = size_t(grid->activeVoxelCount());
        std::vector<char> seen(voxels, 0);
        for (auto it = grid->cbeginValueOn(); it; ++it) {
            const int v = *it;
            if (v < 0 || size_t(v) >= voxels || seen[size_t(v)]) return fail("corrupt voxel indices");
            seen[size_t(v)] = 1;
        }
        const std::string cblob = grid->metaValue<std::string>("rlpbrt:clusters");
        if (cblob.size() != voxels * 4) return fail("corrupt cluster table");
        std::vector<uint32_t> starts(1, 0);
        fieldio::Reader cr(cblob);
        for (size_t v = 0; v < voxels; ++v) {
            const uint32_t c = cr.u32();
            if (c < 1 || c > uint32_t(params_.sphere ? 1 : params_.normals))
                return fail("corrupt cluster table");
            starts.push_back(starts.back() + c);
        }
        const size_t count = starts.back();
        const std::string nblob = grid->metaValue<std::string>("rlpbrt:normals");
        if (nblob.size() != count * 12) return fail("corrupt normals table");
        std::vector<glm::vec3> normals(count);
        fieldio::Reader nr(nblob);
        for (glm::vec3& n : normals) {
            n = nr.vec3();
            if (!finite3(n) || std::abs(glm::length(n) - 1.f) > 1e-3f)
                return fail("corrupt normals table");
        }
        const size_t regions = count * (params_.sphere ? 1 : 2);
        const size_t strata = size_t(layout_.count()) * (params_.sphere ? 2 : 1);
        std::vector<double> q;
        std::vector<uint64_t> visits;
        if (!fieldio::unpackDoubles(grid->metaValue<std::string>("rlpbrt:q"), regions * strata, &q) ||
            !fieldio::unpackU64(grid->metaValue<std::string>("rlpbrt:visits"), regions * strata,
                                &visits))
            return fail("corrupt Q or visit table");
        for (double d : q)
            if (!(d >= 0.0) || !std::isfinite(d)) return fail("corrupt Q table");
        GuidingStats s;
        s.passes = uint64_t(grid->metaValue<int64_t>("rlpbrt:passes"));
        s.records = uint64_t(grid->metaValue<int64_t>("rlpbrt:records"));
        s.rejectedTargets = uint64_t(grid->metaValue<int64_t>("rlpbrt:rejected_targets"));
        s.rejectedRecords = uint64_t(grid->metaValue<int64_t>("rlpbrt:rejected_records"));
        // The medium vertices' tables: present iff this field has them.
        const bool fileVolume = bool(grid->getMetadata<openvdb::StringMetadata>("rlpbrt:volume_cells"));
        if (fileVolume != bool(volume_))
            return fail(fileVolume ? "the file holds medium tables, this field has none (volume=0)"
                                   : "the file has no medium tables, this field has (volume=1)");
        std::vector<glm::ivec3> vcoords;
        std::vector<double> vq;
        std::vector<uint64_t> vvisits;
        GuidingStats vstats;
        if (volume_) {
            const double vh = grid->metaValue<double>("rlpbrt:volume_voxel_size");
            if (vh != volume_->voxelSize())
                return fail("medium voxel size " + std::to_string(vh) + ", this field has " +
                            std::to_string(volume_->voxelSize()) + " (use the same volume-voxel)");
            // (Files without the entry come from versions whose medium tables had the surface
            // tables' strata.)
            const auto vs = grid->getMetadata<openvdb::Vec2IMetadata>("rlpbrt:volume_strata");
            const openvdb::Vec2i fileVs = vs ? vs->value() : st;
            if (fileVs[0] != params_.volumeCols || fileVs[1] != params_.volumeRows)
                return fail("medium strata " + std::to_string(fileVs[0]) + "x" +
                            std::to_string(fileVs[1]) + ", this field has " +
                            std::to_string(params_.volumeCols) + "x" +
                            std::to_string(params_.volumeRows) + " (use the same volume-strata)");
            const std::string cb = grid->metaValue<std::string>("rlpbrt:volume_cells");
            if (cb.size() % 12 != 0) return fail("corrupt medium cell table");
            const size_t cells = cb.size() / 12;
            fieldio::Reader r(cb);
            for (size_t i = 0; i < cells; ++i) {
                const uint32_t x = r.u32(), y = r.u32(), z = r.u32();
                vcoords.emplace_back(int(std::min(x, 1u << 30)), int(std::min(y, 1u << 30)),
                                     int(std::min(z, 1u << 30)));
            }
            if (!volume_->validCells(vcoords)) return fail("corrupt medium cell table");
            const size_t n = cells * size_t(volume_->strata());
            if (!fieldio::unpackDoubles(grid->metaValue<std::string>("rlpbrt:volume_q"), n, &vq) ||
                !fieldio::unpackU64(grid->metaValue<std::string>("rlpbrt:volume_visits"), n,
                                    &vvisits))
                return fail("corrupt medium Q or visit table");
            for (double d : vq)
                if (!(d >= 0.0) || !std::isfinite(d)) return fail("corrupt medium Q table");
            fieldio::Reader cr2(grid->metaValue<std::string>("rlpbrt:volume_counters"));
            vstats.records = cr2.u64();
            vstats.rejectedTargets = cr2.u64();
            vstats.rejectedRecords = cr2.u64();
            vstats.passes = s.passes;
            if (!cr2.ok()) return fail("corrupt medium counters");
        }
        // Commit.
        grid->clearMetadata();
        grid->setName(kGridName);
        grid_->grid = grid;
        grid_->accessors.clear();
        clusterStart_ = std::move(starts);
        clusterNormals_ = std::move(normals);
        buildFrames();
        table_.reset(regions, int(strata), params_.init, policy(), /*lazy=*/true);
        resetConfidence();
        table_.assign(std::move(q), std::move(visits), policy());
        table_.stats() = s;
        if (volume_) volume_->restore(vcoords, std::move(vq), std::move(vvisits), vstats);
    } catch (const std::exception& e) {
        return fail(std::string("missing or bad metadata: ") + e.what());
    }
    return true;
}

// ---- Resume state: the saved field as an OpenVDB stream, then the selection learners ----

bool VdbField::saveState(std::string* state, std::string* error) const {
    fieldio::Writer w;
    try {
        std::ostringstream out(std::ios::binary);
        openvdb::io::Stream(out).write(openvdb::GridCPtrVec{savedGrid()->grid});
        w.blob(out.str());
    } catch (const std::exception& e) {
        *error = std::string("cannot serialise the vdb field: ") + e.what();
        return false;
    }
    table_.selection().saveState(w);
    w.u32(volume_ ? 1u : 0u);
    if (volume_) volume_->selection().saveState(w);
    *state = std::move(w.data);
    return true;
}

bool VdbField::loadState(const std::string& state, std::string* error) {
    fieldio::Reader r(state);
    const std::string stream = r.blob();
    if (!r.ok()) {
        *error = "truncated vdb state";
        return false;
    }
    Grid saved;
    try {
        std::istringstream in(stream, std::ios::binary);
        openvdb::io::Stream vdbStream(in);
        openvdb::GridPtrVecPtr grids = vdbStream.getGrids();
        for (const openvdb::GridBase::Ptr& g : grids ? *grids : openvdb::GridPtrVec())
            if (g && g->getName() == kGridName) saved.grid = openvdb::gridPtrCast<openvdb::Int32Grid>(g);
    } catch (const std::exception& e) {
        *error = std::string("corrupt vdb state: ") + e.what();
        return false;
    }
    if (!saved.grid) {
        *error = "corrupt vdb state: no guiding grid";
        return false;
    }
    if (!loadGrid(saved, "vdb state", error)) return false;
    if (!table_.selection().loadState(r)) {
        *error = "corrupt selection state of the vdb field";
        return false;
    }
    const uint32_t hasVolume = r.u32();
    if (!r.ok() || hasVolume != (volume_ ? 1u : 0u) ||
        (volume_ && !volume_->selection().loadState(r)) || r.remaining() != 0) {
        *error = "corrupt medium selection state of the vdb field";
        return false;
    }
    table_.stats().selectionRegions = table_.selection().learnedRegions();
    table_.stats().selectionMean = table_.selection().meanSelection();
    return true;
}

}  // namespace rlpbrt::guiding
