// Light selection for next-event estimation, pbrt-v3's three strategies:
//  - "uniform": every light equally likely;
//  - "power": proportional to emitted power;
//  - "spatial" (pbrt-v3's default): a voxel grid over the scene bounds (64 voxels along the
//    longest axis as pbrt-v3 with more than 8 lights or with media, 16 otherwise); each voxel, the first
//    time a point in it asks, estimates every light's contribution at 128 points inside it
//    (luminance of Li / pdf, no visibility) and samples lights proportionally, with a floor
//    of 0.1% of the average so that no light has zero probability.
#pragma once

#include <atomic>
#include <memory>
#include <string>
#include <vector>

#include "render/distribution.h"
#include "render/lights.h"

namespace rlpbrt {

class LightSampler {
public:
    virtual ~LightSampler();
    // Chooses a light for a receiving point p: its index and probability (pmf), or -1.
    // uRemapped (if given): u's place within the light's share of [0,1), rescaled to [0,1)
    // (uniform, independent of the choice), for the light's own sampling.
    virtual int sample(const Vec3& p, float u, float* pmf, float* uRemapped = nullptr) const = 0;
    // The probability that sample() at p returns `light`.
    virtual float pmf(const Vec3& p, int light) const = 0;
};

// Creates the sampler for a strategy name; unknown names fall back to "spatial" with a
// message in *note. media: the scene has participating media (medium vertices fill the
// volume between surfaces; "spatial" then keeps pbrt-v3's 64 voxels for any light count).
std::unique_ptr<LightSampler> createLightSampler(const std::string& strategy,
                                                 const std::vector<std::unique_ptr<Light>>& lights,
                                                 const Vec3& boundsMin, const Vec3& boundsMax,
                                                 std::string* note, bool media = false);

// The options of the learned light choice: lights grouped by emitter. The lights one
// AreaLightSource makes on one shape (a mesh's triangles, as pbrt-v3 makes them) form one
// group, every other light a group of its own; within a group a light is chosen in proportion
// to its power. A group is what a region can see or not (one lamp), so the learned choice has
// as many options as emitters: cornell-box's one quad is one group (nothing to learn), not
// two triangles.
class LightGroups {
public:
    LightGroups() = default;
    // emitter[l]: light l's emitter id (lights of one emitter are contiguous or not; ids any
    // ints); lights and emitter have the same size.
    LightGroups(const std::vector<std::unique_ptr<Light>>& lights,
                const std::vector<int>& emitter);
    int count() const { return first_.empty() ? 0 : int(first_.size()) - 1; }
    int group(int light) const { return of_[size_t(light)].group; }
    // The probability of `light` among its group's lights.
    float within(int light) const { return of_[size_t(light)].within; }
    // A light of group g from u in [0,1), with probability within(); uRemapped as
    // LightSampler::sample's.
    int sample(int g, float u, float* uRemapped = nullptr) const;

private:
    // Per light, side by side (both are read for every shadow ray's pmf).
    struct Of {
        int group;
        float within;
    };
    std::vector<Of> of_;
    std::vector<int> first_;       // per group + 1: its range in members_ / cdf_
    std::vector<int> members_;     // lights by group
    std::vector<float> cdf_;       // per member: the within-group CDF after it
};

// A learned light choice mixed into a light sampler (guide parameter lights=learned): with
// probability `share` a group is drawn from `cdf` (count() + 1 floats: a region's learned
// choice, GuidingField::choice) and a light within it by power, else a light from `base`.
// The mixture's pmf is share * (cdf[g+1] - cdf[g]) * within(l) + (1 - share) * base.pmf:
// every light the base sampler can pick keeps a chance, so next-event estimation stays
// unbiased whatever the learned CDF says. cdf null or share 0: the base sampler alone.
struct MixedLightChoice {
    const LightSampler& base;
    const float* cdf;
    const LightGroups& groups;
    float share;
    // A light for the receiving point p from u in [0,1), with its pmf; -1 (pmf 0) for none.
    // uRemapped as LightSampler::sample's.
    int sample(const Vec3& p, float u, float* pmf, float* uRemapped = nullptr) const;
    // The pmf of `light` at p; baseKnown >= 0: base.pmf(p, light), already looked up.
    float pmf(const Vec3& p, int light, float baseKnown = -1.f) const {
        if (!(baseKnown >= 0.f)) baseKnown = base.pmf(p, light);
        if (!cdf || !(share > 0.f)) return baseKnown;
        const int g = groups.group(light);
        return share * (cdf[g + 1] - cdf[g]) * groups.within(light) + (1.f - share) * baseKnown;
    }
};

// The "spatial" strategy, exposed for tests.
class SpatialLightSampler : public LightSampler {
public:
    SpatialLightSampler(const std::vector<std::unique_ptr<Light>>& lights, const Vec3& bMin,
                        const Vec3& bMax, int maxVoxels = 64);
    ~SpatialLightSampler() override;
    int sample(const Vec3& p, float u, float* pmf, float* uRemapped = nullptr) const override;
    float pmf(const Vec3& p, int light) const override;
    int voxelsComputed() const { return computed_.load(); }

private:
    // A voxel's distribution in one block: cdf[0..n] then pmf[0..n-1] (one cache-friendly
    // allocation; looked up at every light sample).
    const float* lookup(const Vec3& p) const;
    float* compute(int ix, int iy, int iz) const;

    const std::vector<std::unique_ptr<Light>>& lights_;
    Vec3 bMin_, bMax_;
    int n_[3];
    mutable std::vector<std::atomic<float*>> voxels_;
    mutable std::atomic<int> computed_{0};
};

}  // namespace rlpbrt
