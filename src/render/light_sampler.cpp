#include "render/light_sampler.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "guiding/directional.h"
#include "util/sequence.h"

namespace rlpbrt {

LightSampler::~LightSampler() = default;

namespace {

// Radical inverse of i in the baseIndex-th prime (Halton points inside a voxel).
float haltonCoordinate(int baseIndex, uint32_t i) {
    static const uint32_t primes[] = {2, 3, 5, 7, 11};
    return radicalInverse(i, primes[baseIndex]);
}

// A light's weight for power-proportional selection: the luminance of its power, 0 where
// that is not a positive finite number.
float powerWeight(const Light& light) {
    const float w = luminance(light.power());
    return std::isfinite(w) && w > 0.f ? w : 0.f;
}

class TableLightSampler : public LightSampler {
public:
    explicit TableLightSampler(const std::vector<float>& w) : dist_(w) {}
    int sample(const Vec3&, float u, float* pmf, float* uRemapped = nullptr) const override {
        return dist_.sampleDiscrete(u, pmf, uRemapped);
    }
    float pmf(const Vec3&, int light) const override { return dist_.discretePmf(light); }

private:
    Distribution1D dist_;
};

class NoLightSampler : public LightSampler {
public:
    int sample(const Vec3&, float, float* pmf, float* uRemapped = nullptr) const override {
        *pmf = 0.f;
        if (uRemapped) *uRemapped = 0.f;
        return -1;
    }
    float pmf(const Vec3&, int) const override { return 0.f; }
};

}  // namespace

SpatialLightSampler::SpatialLightSampler(const std::vector<std::unique_ptr<Light>>& lights,
                                         const Vec3& bMin, const Vec3& bMax, int maxVoxels)
    : lights_(lights), bMin_(bMin), bMax_(bMax) {
    Vec3 diag = bMax - bMin;
    float maxExtent = std::max(diag.x, std::max(diag.y, diag.z));
    for (int i = 0; i < 3; ++i) {
        int n = maxExtent > 0.f ? int(std::lround(diag[i] / maxExtent * maxVoxels)) : 1;
        n_[i] = std::max(1, n);
    }
    voxels_ = std::vector<std::atomic<float*>>(size_t(n_[0]) * n_[1] * n_[2]);
    for (auto& v : voxels_) v.store(nullptr);
}

SpatialLightSampler::~SpatialLightSampler() {
    for (auto& v : voxels_) delete[] v.load();
}

float* SpatialLightSampler::compute(int ix, int iy, int iz) const {
    Vec3 diag = bMax_ - bMin_;
    Vec3 lo = bMin_ + diag * Vec3(float(ix) / n_[0], float(iy) / n_[1], float(iz) / n_[2]);
    Vec3 hi = bMin_ + diag * Vec3(float(ix + 1) / n_[0], float(iy + 1) / n_[1],
                                  float(iz + 1) / n_[2]);
    std::vector<float> contrib(lights_.size(), 0.f);
    // pbrt-v3 takes 128 points per voxel; lights with a closed-form estimate are smooth enough
    // for 16 of them (weighted 8x so that both kinds of estimate share one scale).
    constexpr uint32_t kSamples = 128, kApproxSamples = 16;
    constexpr float kApproxWeight = float(kSamples) / kApproxSamples;
    std::vector<int> approxLights, sampledLights;
    for (size_t l = 0; l < lights_.size(); ++l)
        (lights_[l]->approxContribution(lo) >= 0.f ? approxLights : sampledLights)
            .push_back(int(l));
    auto point = [&](uint32_t i) {
        Vec3 t(haltonCoordinate(0, i), haltonCoordinate(1, i), haltonCoordinate(2, i));
        return lo + t * (hi - lo);
    };
    for (uint32_t i = 0; i < kApproxSamples && !approxLights.empty(); ++i) {
        Vec3 p = point(i);
        for (int l : approxLights) {
            float approx = lights_[size_t(l)]->approxContribution(p);
            if (std::isfinite(approx) && approx > 0.f) contrib[size_t(l)] += kApproxWeight * approx;
        }
    }
    for (uint32_t i = 0; i < kSamples && !sampledLights.empty(); ++i) {
        LightSampleContext ctx{point(i), Vec3(0.f)};
        Vec2 u(haltonCoordinate(3, i), haltonCoordinate(4, i));
        for (int l : sampledLights) {
            LightSample ls;
            if (lights_[size_t(l)]->sampleLi(ctx, u, &ls) && ls.pdf > 0.f) {
                float c = luminance(ls.L) / ls.pdf;
                if (std::isfinite(c) && c > 0.f) contrib[size_t(l)] += c;
            }
        }
    }
    double sum = 0;
    for (float c : contrib) sum += c;
    float avg = float(sum / std::max<size_t>(1, contrib.size()));
    float minContrib = avg > 0.f ? 0.001f * avg : 1.f;
    const size_t n = contrib.size();
    float* block = new float[2 * n + 1];
    double total = 0;
    for (float& c : contrib) {
        c = std::max(c, minContrib);
        total += c;
    }
    double acc = 0;
    block[0] = 0.f;
    for (size_t i = 0; i < n; ++i) {
        acc += contrib[i];
        block[i + 1] = float(acc / total);
        block[n + 1 + i] = float(contrib[i] / total);
    }
    block[n] = 1.f;
    return block;
}

const float* SpatialLightSampler::lookup(const Vec3& p) const {
    int idx[3];
    for (int i = 0; i < 3; ++i) {
        float extent = bMax_[i] - bMin_[i];
        float t = extent > 0.f ? (p[i] - bMin_[i]) / extent : 0.f;
        idx[i] = clamp(int(t * n_[i]), 0, n_[i] - 1);
    }
    auto& slot = voxels_[(size_t(idx[2]) * n_[1] + idx[1]) * n_[0] + idx[0]];
    float* d = slot.load(std::memory_order_acquire);
    if (d) return d;
    // Computed deterministically, so a lost race only wastes work.
    float* mine = compute(idx[0], idx[1], idx[2]);
    float* expected = nullptr;
    if (slot.compare_exchange_strong(expected, mine, std::memory_order_acq_rel)) {
        computed_.fetch_add(1);
        return mine;
    }
    delete[] mine;
    return expected;
}

int SpatialLightSampler::sample(const Vec3& p, float u, float* pmf, float* uRemapped) const {
    const float* cdf = lookup(p);
    const int n = int(lights_.size());
    // Largest i with cdf[i] <= u, among pieces of non-zero probability.
    int i = int(std::upper_bound(cdf, cdf + n + 1, u) - cdf) - 1;
    i = clamp(i, 0, n - 1);
    while (i > 0 && cdf[n + 1 + i] == 0.f) --i;
    *pmf = cdf[n + 1 + i];
    if (uRemapped) *uRemapped = remapInInterval(u, cdf[i], cdf[i + 1]);
    return i;
}

float SpatialLightSampler::pmf(const Vec3& p, int light) const {
    return lookup(p)[lights_.size() + 1 + size_t(light)];
}

LightGroups::LightGroups(const std::vector<std::unique_ptr<Light>>& lights,
                         const std::vector<int>& emitter)
    : of_(lights.size()) {
    // Groups numbered by their first light.
    std::unordered_map<int, int> groupOf;  // emitter -> group
    std::vector<std::vector<int>> lightsOf;
    for (size_t l = 0; l < lights.size(); ++l) {
        const int e = emitter[l];
        int g = int(lightsOf.size());
        if (e >= 0) g = groupOf.emplace(e, g).first->second;  // the emitter's, or a new one
        if (g == int(lightsOf.size())) lightsOf.emplace_back();
        of_[l].group = g;
        lightsOf[size_t(g)].push_back(int(l));
    }
    first_.push_back(0);
    std::vector<float> weight(lights.size());
    for (size_t l = 0; l < lights.size(); ++l) weight[l] = powerWeight(*lights[l]);
    for (const std::vector<int>& ls : lightsOf) {
        double total = 0.0;
        for (int l : ls) total += weight[size_t(l)];
        double acc = 0.0;
        for (int l : ls) {
            const double q = total > 0.0 ? weight[size_t(l)] / total : 1.0 / double(ls.size());
            of_[size_t(l)].within = float(q);
            acc += q;
            members_.push_back(l);
            cdf_.push_back(float(acc));
        }
        cdf_.back() = 1.f;
        first_.push_back(int(members_.size()));
    }
}

int LightGroups::sample(int g, float u, float* uRemapped) const {
    const int b = first_[size_t(g)], e = first_[size_t(g) + 1];
    const auto it = std::upper_bound(cdf_.begin() + b, cdf_.begin() + e, u);
    const int k = std::min(int(it - cdf_.begin()), e - 1);
    if (uRemapped)
        *uRemapped = remapInInterval(u, k > b ? cdf_[size_t(k) - 1] : 0.f, cdf_[size_t(k)]);
    return members_[size_t(k)];
}

int MixedLightChoice::sample(const Vec3& p, float u, float* pmfOut, float* uRemapped) const {
    if (!cdf || !(share > 0.f)) return base.sample(p, u, pmfOut, uRemapped);
    float known = -1.f;
    int light;
    if (u < share) {
        const float v = std::min(u / share, OneMinusEpsilon);
        const int g = guiding::sampleStrataCdf(cdf, groups.count(), v);
        light = groups.sample(g, remapInInterval(v, cdf[g], cdf[g + 1]), uRemapped);
    } else {
        light = base.sample(p, std::min((u - share) / (1.f - share), OneMinusEpsilon), &known,
                            uRemapped);
    }
    *pmfOut = light >= 0 ? pmf(p, light, known) : 0.f;
    return *pmfOut > 0.f ? light : -1;
}

std::unique_ptr<LightSampler> createLightSampler(const std::string& strategy,
                                                 const std::vector<std::unique_ptr<Light>>& lights,
                                                 const Vec3& bMin, const Vec3& bMax,
                                                 std::string* note, bool media) {
    if (lights.empty()) return std::make_unique<NoLightSampler>();
    if (strategy == "uniform" || lights.size() == 1)
        return std::make_unique<TableLightSampler>(std::vector<float>(lights.size(), 1.f));
    if (strategy == "power") {
        std::vector<float> w(lights.size());
        double total = 0;
        for (size_t i = 0; i < lights.size(); ++i) {
            w[i] = powerWeight(*lights[i]);
            total += w[i];
        }
        if (!(total > 0)) std::fill(w.begin(), w.end(), 1.f);
        return std::make_unique<TableLightSampler>(w);
    }
    if (strategy != "spatial" && note)
        *note = "unknown light sample strategy \"" + strategy + "\"; using \"spatial\"";
    // pbrt-v3's 64 voxels along the longest axis pay off with many lights; with a few, a
    // coarser grid gives the same error for less time in cache misses (cornell-box, 2 lights:
    // 4.98 s -> 4.31 s at 64 spp, relMSE 0.000821 -> 0.000820; veach-mis, 5 lights:
    // 0.00312 -> 0.00317, within its noise).
    // In media the coarse grid costs variance: a voxel's distribution is an average over
    // its points, and a medium vertex lies anywhere in the volume, e.g. half inside a
    // spot's cone and half outside it (volume-boundary, 2 lights, 64 spp, --guide=none:
    // see docs/MEDIA.md); media scenes keep pbrt-v3's 64.
    const int maxVoxels = lights.size() > 8 || media ? 64 : 16;
    return std::make_unique<SpatialLightSampler>(lights, bMin, bMax, maxVoxels);
}

}  // namespace rlpbrt
